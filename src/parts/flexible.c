/* The flexible body as a part (part kind "flexible"): options, set-up, summary, energy and outputs. Its equations
   (residual, Jacobian, ports) are in flexible_dynamics.c, its spaces and operators in flexible_fe.c. */
#include <phlex_impl.h>

const char *const PhlexICTypes[]         = {"zero", "uniform", "rigid", "beam", "mode", "PhlexICType", "PHLEX_IC_", NULL};
const char *const PhlexFrameConditions[] = {"patch", "mean_axes", "PhlexFrameCondition", "PHLEX_FRAME_", NULL};
static const char *const PhlexMotionTypes[]  = {"fixed", "floating", "PhlexMotion", "PHLEX_MOTION_", NULL};
static const char *const PhlexNodeOrders[]   = {"file", "rcm", "PhlexNodeOrder", "PHLEX_NODE_ORDER_", NULL};
static const char *const PhlexInertiaTypes[] = {"full", "constant", "constant_without_gyroscopic"};

PETSC_INTERN PetscErrorCode PhlexFlexibleSetDynamicsOps(PhlexPart);

static PetscErrorCode MaterialCheck(PhlexFlexible b, const PhlexMaterial *m, const char prefix[])
{
  PetscFunctionBeginUser;
  /* a value beyond the double range (1e400) is read as inf: refused here, not by the factorization */
  PetscCheck(!PetscIsInfOrNanReal(m->youngs_modulus) && !PetscIsInfOrNanReal(m->poissons_ratio) && !PetscIsInfOrNanReal(m->density), b->comm, PETSC_ERR_USER_INPUT, "body %s: a material value is not a finite number (beyond the range of doubles, about 1.8e308): -%syoungs_modulus %g, -%spoissons_ratio %g, -%sdensity %g", b->name, prefix, (double)m->youngs_modulus, prefix, (double)m->poissons_ratio, prefix, (double)m->density);
  PetscCheck(m->youngs_modulus > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: Young's modulus must be positive: -%syoungs_modulus %g", b->name, prefix, (double)m->youngs_modulus);
  PetscCheck(m->poissons_ratio > -1.0 && m->poissons_ratio < 0.5, b->comm, PETSC_ERR_USER_INPUT, "body %s: Poisson's ratio must lie in (-1, 0.5): -%spoissons_ratio %g", b->name, prefix, (double)m->poissons_ratio);
  PetscCheck(m->density > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: density must be positive: -%sdensity %g", b->name, prefix, (double)m->density);
  PetscCheck(m->viscosity >= 0 && !PetscIsInfOrNanReal(m->viscosity), b->comm, PETSC_ERR_USER_INPUT, "body %s: the Kelvin-Voigt viscosity must be >= 0 [Pa s] (a negative one feeds energy in): -%sviscosity %g", b->name, prefix, (double)m->viscosity);
  PetscFunctionReturn(0);
}

static PetscErrorCode MaterialSetFromOptions(PhlexFlexible b, PhlexMaterial *m, const char prefix[])
{
  PetscBool fE = PETSC_FALSE, fn = PETSC_FALSE, fr = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscOptionsBegin(b->comm, prefix, "Material options", NULL);
  PetscCall(PetscOptionsReal("-youngs_modulus", "Young's modulus E [Pa]", "PhlexFlexibleSetFromOptions", m->youngs_modulus, &m->youngs_modulus, &fE));
  PetscCall(PetscOptionsReal("-poissons_ratio", "Poisson's ratio nu [-]", "PhlexFlexibleSetFromOptions", m->poissons_ratio, &m->poissons_ratio, &fn));
  PetscCall(PetscOptionsReal("-density", "Mass density rho [kg/m^3]", "PhlexFlexibleSetFromOptions", m->density, &m->density, &fr));
  PetscCall(PetscOptionsReal("-viscosity", "Kelvin-Voigt viscous modulus eta: a viscous stress (eta/E) D eps(v), the viscous moduli proportional to the elastic ones (damping ratio eta w/(2 E) of a mode of pulsation w); 0: none [Pa s]", "PhlexFlexibleSetFromOptions", m->viscosity, &m->viscosity, NULL));
  PetscOptionsEnd();
  PetscCheck(fE, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%syoungs_modulus [Pa]", b->name, prefix);
  PetscCheck(fn, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%spoissons_ratio [-]", b->name, prefix);
  PetscCheck(fr, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%sdensity [kg/m^3]", b->name, prefix);
  PetscCall(MaterialCheck(b, m, prefix));
  PetscFunctionReturn(0);
}

/* Options of a flexible body (prefix body<k>_):
   -dm_plex_filename <file>  gmsh mesh (.msh 2.2 or 4.1, ASCII or binary)
   -petscspace_degree <k>    velocity degree k (1 or 2); the stress is discontinuous of degree k-1
   -node_order rcm|file      numbering of the mesh's points (and unknowns): reverse Cuthill-McKee, or as read
   -process <r>              the whole body on process r (else split over all, or placed by -whole_bodies)
   -motion fixed|floating    the frame is held (clamped on the frame patch) or moves
   -frame patch|mean_axes    how the frame of a floating body is fixed to it
   -frame_patch <group>      physical surface where u_f = v_f = 0 (fixed: the clamp; floating: the frame)
   -frame_origin x,y,z       mean axes: the frame origin P (default: the centre of mass)
   -inertia full|constant|constant_without_gyroscopic   floating: the inertia model (frame.c)
   -youngs_modulus, -poissons_ratio, -density, -regions, -ports, -body_force, -ic_*: see README */
static PetscErrorCode FlexSetFromOptions(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  char         *rptr[PHLEX_MAX_MATERIALS + 1], **pptr; /* room for one more region: too many are refused, not cut */
  PetscInt      nregions = PHLEX_MAX_MATERIALS + 1, nports;
  PetscBool     flg, flg_mesh = PETSC_FALSE, has_body_material, fcond = PETSC_FALSE, ff = PETSC_FALSE, fm = PETSC_FALSE;
  PetscBool     spin_given = PETSC_FALSE, center_given = PETSC_FALSE, rate_given = PETSC_FALSE, process_given = PETSC_FALSE;
  PetscMPIInt   size;
  PetscInt      motion = 0, inertia = 0, cond = PHLEX_FRAME_PATCH, order = b->rcm ? 1 : 0;
  const char   *given = NULL;
  char          who[PHLEX_NAME_LEN + 8];

  PetscFunctionBeginUser;
  PetscCall(PhlexOptionsListLength(b->prefix, "-ports", &nports));
  PetscCall(PetscMalloc1(nports, &pptr));
  for (PetscInt i = 0; i <= PHLEX_MAX_MATERIALS; i++) rptr[i] = NULL;
  for (PetscInt i = 0; i < nports; i++) pptr[i] = NULL;
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", b->name));
  PetscOptionsBegin(b->comm, b->prefix, "Flexible body options", NULL);
  PetscCall(PetscOptionsString("-dm_plex_filename", "gmsh mesh file of the body (.msh 2.2 or 4.1)", "PhlexFlexibleSetFromOptions", b->mesh_file, b->mesh_file, sizeof(b->mesh_file), &flg_mesh));
  PetscCall(PetscOptionsInt("-petscspace_degree", "Velocity degree k (1 or 2); stress: discontinuous degree k-1", "PhlexFlexibleSetFromOptions", b->degree, &b->degree, NULL));
  /* rcm: the unknowns of neighbouring nodes close in memory; the sparse products gather their vectors from cache
     (a mass matrix times 8 vectors: 2.2 x faster, BENCHMARKS.md section 14), the factorizations order for themselves */
  PetscCall(PetscOptionsEList("-node_order", "Numbering of the mesh's points and so of the unknowns: rcm (reverse Cuthill-McKee, neighbours close in memory: faster sparse products) or file (as read)", "PhlexFlexibleSetFromOptions", PhlexNodeOrders, 2, PhlexNodeOrders[order], &order, NULL));
  PetscCall(PetscOptionsInt("-process", "The process that holds the whole body (its solves sequential there, concurrent with the other processes' bodies in PC phlexbordered); default: split over all processes, or placed by -whole_bodies", "PhlexFlexibleSetFromOptions", b->process, &b->process, &process_given));
  PetscCall(PetscOptionsEList("-motion", "Rigid motion of the body frame: fixed (clamped patch held) or floating (the frame moves)", "PhlexFlexibleSetFromOptions", PhlexMotionTypes, 2, PhlexMotionTypes[motion], &motion, NULL));
  PetscCall(PetscOptionsString("-frame_patch", "Physical surface where u_f = v_f = 0: the clamp of a fixed body, the frame patch of a floating one", "PhlexFlexibleSetFromOptions", b->frame_patch, b->frame_patch, sizeof(b->frame_patch), NULL));
  PetscCall(PetscOptionsEList("-frame", "Floating body: frame fixed by a patch (-frame_patch, a rigid inclusion) or by mean axes (Tisserand: int rho u_f = 0, int rho (x - P) x u_f = 0)", "PhlexFlexibleSetFromOptions", PhlexFrameConditions, 2, PhlexFrameConditions[cond], &cond, &fcond));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-frame_origin", "Floating body with mean axes: frame origin P (default: the centre of mass) [m]", "PhlexFlexibleSetFromOptions", 3, b->origin, &b->origin_given));
  {
    char      name[64] = "full";
    PetscBool set, known = PETSC_FALSE;
    PetscCall(PetscOptionsString("-inertia", "Floating body: inertia model: full (mass operator of x + u_f, every inertia load), constant (the paper's: mass operator at u_f = 0, the gyroscopic loads at the undeformed geometry; quadratic Hamiltonian) or constant_without_gyroscopic (mass operator at u_f = 0, no centrifugal, Coriolis or transport load on the elastic field)", "PhlexFlexibleSetFromOptions", name, name, sizeof(name), &set));
    for (PetscInt k = 0; k < 3 && !known; k++) {
      PetscCall(PetscStrcmp(name, PhlexInertiaTypes[k], &known));
      if (known) inertia = k;
    }
    PetscCheck(!set || known || strcmp(name, "frozen"), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sinertia frozen was renamed: constant_without_gyroscopic is that model (mass operator at u_f = 0, no velocity-dependent load on the elastic field); constant is the paper's constant-inertia model (the same mass operator with the gyroscopic loads kept)", b->name, b->prefix);
    PetscCheck(!set || known, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sinertia %s: unknown; use full, constant or constant_without_gyroscopic", b->name, b->prefix, name);
  }
  PetscCall(PetscOptionsStringArray("-regions", "Physical volumes with their own material (-region_<name>_youngs_modulus ...)", "PhlexFlexibleSetFromOptions", rptr, &nregions, &flg));
  if (!flg) nregions = 0;
  PetscCall(PetscOptionsStringArray("-ports", "Physical surfaces: ports carrying wrench inputs or joints (-port_<name>_force ...)", "PhlexFlexibleSetFromOptions", pptr, &nports, &flg));
  if (!flg) nports = 0;
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-body_force", "Uniform body force density (body frame) [N/m^3]", "PhlexFlexibleSetFromOptions", 3, b->body_force, &b->has_body_force));
  PetscCall(PhlexPoseSetFromOptions(PetscOptionsObject, part, &b->pose, &given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-frame_force", "Floating body: force on the frame origin P (body frame) [N]", "PhlexFlexibleSetFromOptions", 3, b->frame_force, &ff));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-frame_moment", "Floating body: moment about the frame origin P (body frame) [N m]", "PhlexFlexibleSetFromOptions", 3, b->frame_moment, &fm));
  PetscCall(PetscOptionsBool("-geometric_stiffening", "Green-Lagrange strain of the field in its frame (Saint Venant-Kirchhoff): the stress stiffens the field against transverse displacement (centrifugal stiffening of a spinning beam); the power balance still holds exactly", "PhlexFlexibleSetFromOptions", b->stiffening, &b->stiffening, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-spin", "Fixed body: constant angular velocity of its hub; the body's frame rotates uniformly about -spin_center (inertial loads of the rotating frame; the linearised analysis linearises about the steady spin) [rad/s]", "PhlexFlexibleSetFromOptions", 3, b->spin, &spin_given));
  b->pc_rate_tol = 1e-3;
  PetscCall(PetscOptionsReal("-preconditioner_rate_tol", "Floating body: once the Coriolis and centrifugal terms of the frame's angular velocity exceed this share of the step's shift (about w dt), the preconditioner factors them with the condensed operator (not symmetric: LU instead of Cholesky), and again whenever they drift by as much; 0: never (the symmetric operator without them)", "PhlexFlexibleSetFromOptions", b->pc_rate_tol, &b->pc_rate_tol, &rate_given));
  {
    /* issue 42 item 3: the rate of a port's orientation R exp(theta) is w + J_l(theta) theta', not w + theta' */
    static const char *const rates[] = {"first_order", "exact", "PhlexPortRate", "PHLEX_PORT_RATE_", NULL};
    PetscInt                 rate    = 1;
    PetscCall(PetscOptionsEList("-port_rate", "Angular velocity of a port with a joint, whose orientation is R exp(theta) (theta = B_r^T u, the patch-averaged rotation): exact (w + J_l(theta) B_r^T v, J_l the left Jacobian of SO(3) at the step's middle; a moment acts as B_r J_l^T T) or first_order (w + B_r^T v: a joint on a whirling port opens by the geometric phase 1/2 int theta x dtheta)", "PhlexFlexibleSetFromOptions", rates, 2, rates[rate], &rate, &b->port_rate_given));
    b->port_rate_exact = rate ? PETSC_TRUE : PETSC_FALSE;
  }
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-spin_center", "Fixed body with -spin: a point of the spin axis (mesh coordinates) [m]", "PhlexFlexibleSetFromOptions", 3, b->spin_center, &center_given));
  PetscCall(PetscOptionsBool("-ic_steady_spin", "Floating body, transient: start in the steady state of its frame's spin (the centrifugal stretch and its stress, by the linearised analysis' Newton, at the frame's consistent velocities after the start's projection; the elastic velocity of -ic_velocity_type is a perturbation about it)", "PhlexFlexibleSteadySpinStart", b->ic_steady_spin, &b->ic_steady_spin, NULL));
  PetscOptionsEnd();
  /* the self-checks of the element structure (flexible_fe.c, flexible_stress_maps.c), read here so that -help lists them */
  PetscOptionsBegin(b->comm, NULL, "Flexible body checks", NULL);
  PetscCall(PetscOptionsBool("-phlex_check_condensation", "Compare the element-wise stress elimination G^T Ms^-1 G with the stiffness, every cell", "PhlexFlexibleSetFromOptions", b->check_condensation, &b->check_condensation, NULL));
  PetscCall(PetscOptionsBool("-phlex_check_stress_maps", "Compare the cell-by-cell products B = Ms^-1 G, G^T and G^T Ms^-1 G with the assembled G and Ms, for random fields (transient and linearised analyses)", "PhlexFlexibleSetFromOptions", b->check_stress_maps, &b->check_stress_maps, NULL));
  b->modes_budget = 1e13;
  PetscCall(PetscOptionsReal("-modes_budget", "The largest eigensolve of a body's modes a run starts (modal analysis, a mode as initial condition, a reduced body's basis), estimated as 20 (N ncv^2 + 25 ncv^3) flops with ncv twice the modes asked (1e13: about an hour on one core; 0: no limit)", "PhlexFlexibleModesRequestCheck", b->modes_budget, &b->modes_budget, NULL));
  PetscOptionsEnd();
  PetscCheck(b->modes_budget >= 0 && !PetscIsInfOrNanReal(b->modes_budget), b->comm, PETSC_ERR_USER_INPUT, "-modes_budget must be a number of flops >= 0 (0: no limit), got %g", (double)b->modes_budget);
  b->spinning = (PetscBool)(spin_given && (b->spin[0] != 0 || b->spin[1] != 0 || b->spin[2] != 0));
  if (b->spinning) {
    const PetscReal w = PetscSqrtReal(b->spin[0] * b->spin[0] + b->spin[1] * b->spin[1] + b->spin[2] * b->spin[2]);
    for (PetscInt k = 0; k < 3; k++) b->spin_axis[k] = b->spin[k] / w;
  }
  PetscCheck(!spin_given || !motion, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sspin is the prescribed spin of a fixed body's hub; a floating body spins through its frame (-%sangular_velocity, or a driven joint)", b->name, b->prefix, b->prefix);
  PetscCheck(!center_given || spin_given, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sspin_center without -%sspin: give the spin's angular velocity", b->name, b->prefix, b->prefix);
  PetscCheck(!b->ic_steady_spin || motion, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin on a fixed body: it starts a floating body (-%smotion floating) in the steady state of its frame's spin; a fixed body's prescribed spin (-%sspin) has its steady state in the linearised analysis", b->name, b->prefix, b->prefix, b->prefix);
  b->floating       = motion ? PETSC_TRUE : PETSC_FALSE;
  b->rcm            = order ? PETSC_TRUE : PETSC_FALSE;
  b->frozen_inertia = inertia ? PETSC_TRUE : PETSC_FALSE;
  b->gyroscopic     = inertia == 1 ? PETSC_TRUE : PETSC_FALSE;
  b->inertia_model  = PhlexInertiaTypes[inertia];
  b->frame_loaded   = (ff || fm) ? PETSC_TRUE : PETSC_FALSE;
  PetscCallMPI(MPI_Comm_size(b->comm, &size));
  PetscCheck(!process_given || (b->process >= 0 && b->process < size), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sprocess %" PetscInt_FMT ": the run has %d process%s, numbered 0 to %d", b->name, b->prefix, b->process, (int)size, size == 1 ? "" : "es", (int)size - 1);
  PetscCheck(b->pc_rate_tol >= 0 && !PetscIsInfOrNanReal(b->pc_rate_tol), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%spreconditioner_rate_tol must be >= 0 (0: off), got %g", b->name, b->prefix, (double)b->pc_rate_tol);
  /* a fixed body has no rigid state: its rigid options would be silently ignored */
  if (!b->floating) {
    if (!given) given = ff ? "frame_force" : fm ? "frame_moment" : fcond ? "frame" : b->origin_given ? "frame_origin" : (rate_given && b->pc_rate_tol > 0) ? "preconditioner_rate_tol" : NULL;
    PetscCheck(!given, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%s%s describes the rigid motion of a floating frame; the body is fixed (-%smotion fixed): add -%smotion floating or remove the option", b->name, b->prefix, given, b->prefix, b->prefix);
  } else {
    /* the frame condition: as given, else the frame patch if there is one, else mean axes */
    b->frame_condition = fcond ? (PhlexFrameCondition)cond : (b->frame_patch[0] ? PHLEX_FRAME_PATCH : PHLEX_FRAME_MEAN_AXES);
    PetscCheck(b->frame_condition != PHLEX_FRAME_PATCH || b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sframe patch needs a frame patch (-%sframe_patch <surface>): its centroid is the frame origin", b->name, b->prefix, b->prefix);
    PetscCheck(b->frame_condition != PHLEX_FRAME_MEAN_AXES || !b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sframe mean_axes fixes the frame without a patch; remove -%sframe_patch %s (or use -%sframe patch)", b->name, b->prefix, b->prefix, b->frame_patch, b->prefix);
    PetscCheck(b->frame_condition == PHLEX_FRAME_MEAN_AXES || !b->origin_given, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sframe_origin is for mean axes; with a frame patch the origin is the patch's centroid", b->name, b->prefix);
  }
  if (b->frame_loaded) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sframe_", b->prefix));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, frame wrench", b->name));
    PetscCall(PhlexProfileCreate(b->comm, prefix, what, &b->frame_profile));
    PetscCall(PhlexProfileSetFromOptions(b->frame_profile));
  }

  /* -help reads the options of a body without a mesh */
  PetscCheck((flg_mesh && b->mesh_file[0]) || PhlexHelpGetMode() == PHLEX_HELP_OPTIONS, b->comm, PETSC_ERR_USER_INPUT, "body %s: no mesh: set -%sdm_plex_filename <file.msh>", b->name, b->prefix);
  PetscCheck(b->degree == 1 || b->degree == 2, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%spetscspace_degree must be 1 or 2, got %" PetscInt_FMT, b->name, b->prefix, b->degree);

  /* materials: either one for the whole body, or one per listed region */
  PetscCheck(nregions <= PHLEX_MAX_MATERIALS, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sregions lists more than %d regions", b->name, b->prefix, PHLEX_MAX_MATERIALS);
  b->nmaterials = nregions ? nregions : 1;
  PetscCall(PetscOptionsHasName(NULL, b->prefix, "-youngs_modulus", &has_body_material));
  if (!nregions) {
    PetscCall(PetscStrcpy(b->materials[0].region, ""));
    b->materials[0].tag = -1;
    PetscCall(MaterialSetFromOptions(b, &b->materials[0], b->prefix));
  } else {
    PetscCheck(!has_body_material, b->comm, PETSC_ERR_USER_INPUT, "body %s: give the material either for the whole body (-%syoungs_modulus ...) or per region (-%sregions), not both", b->name, b->prefix, b->prefix);
    for (PetscInt r = 0; r < nregions; r++) {
      char prefix[256];
      PetscCall(PetscStrncpy(b->materials[r].region, rptr[r], PHLEX_NAME_LEN));
      b->materials[r].tag = -1;
      PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sregion_%s_", b->prefix, rptr[r]));
      PetscCall(MaterialSetFromOptions(b, &b->materials[r], prefix));
    }
  }
  for (PetscInt r = 0; r < nregions; r++) PetscCall(PetscFree(rptr[r]));

  b->nports = nports;
  PetscCall(PetscCalloc1(PetscMax(nports, 1), &b->ports));
  for (PetscInt p = 0; p < nports; p++) {
    PetscCall(PetscStrncpy(b->ports[p].name, pptr[p], PHLEX_NAME_LEN));
    for (PetscInt q = 0; q < p; q++) {
      PetscCall(PetscStrcmp(b->ports[q].name, pptr[p], &flg));
      PetscCheck(!flg, b->comm, PETSC_ERR_USER_INPUT, "body %s: port '%s' is listed twice in -%sports", b->name, pptr[p], b->prefix);
    }
    PetscCall(PetscStrcmp(b->frame_patch, pptr[p], &flg));
    PetscCheck(!flg || !b->floating, b->comm, PETSC_ERR_USER_INPUT, "body %s: the frame patch %s is a port of the floating body already (joints name it %s:%s; its input is -%sframe_force/-%sframe_moment); remove it from -%sports", b->name, pptr[p], b->name, pptr[p], b->prefix, b->prefix, b->prefix);
    PetscCall(PetscFree(pptr[p]));
    PetscCall(PhlexPortLoadSetFromOptions(part, b->ports[p].name, PETSC_TRUE, &b->ports[p].load));
  }
  PetscCall(PetscFree(pptr));
  if (b->has_body_force) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sbody_force_", b->prefix));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, body force", b->name));
    PetscCall(PhlexProfileCreate(b->comm, prefix, what, &b->body_force_profile));
    PetscCall(PhlexProfileSetFromOptions(b->body_force_profile));
  }
  PetscCall(PhlexFlexibleDampingSetFromOptions(part));
  PetscCall(PhlexFlexibleICSetFromOptions(b, &b->ic_velocity, "velocity", 3));
  PetscCall(PhlexFlexibleICSetFromOptions(b, &b->ic_displacement, "displacement", 3));
  PetscCall(PhlexFlexibleICSetFromOptions(b, &b->ic_stress, "stress", 6));
  if (b->floating) {
    /* a rigid or uniform velocity field is the frame's velocity: it is mapped to v_P and w (flexible_ic.c) */
    const PetscBool rigid_v = (b->ic_velocity.type == PHLEX_IC_UNIFORM || b->ic_velocity.type == PHLEX_IC_RIGID) ? PETSC_TRUE : PETSC_FALSE;
    PetscCheck(!rigid_v || !(b->pose.velocity_given || b->pose.omega_given), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_velocity_type %s describes the rigid motion of the floating frame, and so do -%svelocity/-%sangular_velocity: give one of them", b->name, b->prefix, PhlexICTypes[b->ic_velocity.type], b->prefix, b->prefix);
    PetscCheck(b->ic_displacement.type != PHLEX_IC_UNIFORM && b->ic_displacement.type != PHLEX_IC_RIGID, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_displacement_type %s moves a floating body rigidly: place it with -%sposition and -%sorientation_* instead", b->name, b->prefix, PhlexICTypes[b->ic_displacement.type], b->prefix, b->prefix);
  }
  PetscFunctionReturn(0);
}

/* the mesh, its checks and the scales it suggests */
/* Legal but suspicious values, warned about once when the mesh is read: a wrong unit (a mesh in millimetres, a
   modulus in GPa, a density in g/cm^3) or a material the scheme handles poorly (near incompressibility) runs, but
   its results would mislead. */
static PetscErrorCode WarnSuspicious(PhlexFlexible b)
{
  PetscReal extent = 0;

  PetscFunctionBeginUser;
  for (PetscInt d = 0; d < 3; d++) extent = PetscMax(extent, b->bbox_max[d] - b->bbox_min[d]);
  /* a 0.1 to 1 m part drawn in millimetres is 100 to 1000 units across */
  if (extent >= 100 || extent < 1e-4) PetscCall(PetscFPrintf(b->comm, PETSC_STDERR, "phlex: warning: body %s: the mesh %s is %g m across; mesh coordinates are metres: a mesh drawn in millimetres is 1000 times too large (gmsh: Mesh.ScalingFactor = 0.001)\n", b->name, b->mesh_file, (double)extent));
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    const PhlexMaterial *mat   = &b->materials[m];
    const char          *where = mat->region[0] ? mat->region : "whole body";
    if (mat->poissons_ratio > 0.49 || mat->youngs_modulus < 1e3 || mat->youngs_modulus > 1e15 || mat->density < 10 || mat->density > 1e5) b->part->material_warned = PETSC_TRUE;
    if (mat->poissons_ratio > 0.49) PetscCall(PetscFPrintf(b->comm, PETSC_STDERR, "phlex: warning: body %s (%s): Poisson's ratio %s is nearly incompressible: the condition of the stress block grows like 1/(1 - 2 nu) = %.3g and P1 velocities lock (too stiff); prefer P2 and watch the solver's residuals\n", b->name, where, PhlexFormatReal(mat->poissons_ratio, (char[32]){0}, 32), (double)(1.0 / (1.0 - 2.0 * mat->poissons_ratio))));
    if (mat->youngs_modulus < 1e3 || mat->youngs_modulus > 1e15) PetscCall(PetscFPrintf(b->comm, PETSC_STDERR, "phlex: warning: body %s (%s): Young's modulus %g Pa is outside the range of solids (1e3 to 1e15 Pa, the rigid limit included): is it in Pa?\n", b->name, where, (double)mat->youngs_modulus));
    if (mat->density < 10 || mat->density > 1e5) PetscCall(PetscFPrintf(b->comm, PETSC_STDERR, "phlex: warning: body %s (%s): density %g kg/m^3 is outside the range of solids (10 to 1e5 kg/m^3): is it in kg/m^3 (7.8 g/cm^3 = 7800 kg/m^3)?\n", b->name, where, (double)mat->density));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexGeometry(PhlexPart part, PhlexScaleHints *h)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (!b->dm) {
    PetscCall(PhlexMeshLoad(b));
    PetscCall(PhlexMeshCheckGeometry(b));
    PetscCall(WarnSuspicious(b));
  }
  h->extent = h->density = h->modulus = h->mass = 0;
  for (PetscInt d = 0; d < 3; d++) h->extent = PetscMax(h->extent, b->bbox_max[d] - b->bbox_min[d]);
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    h->density = PetscMax(h->density, b->materials[m].density);
    h->modulus = PetscMax(h->modulus, b->materials[m].youngs_modulus);
  }
  PetscFunctionReturn(0);
}

/* The discrete unknowns of a floating body: its frame (r, R, v_P, w) and, with mean axes, the impulses of the six
   mean-axes multipliers. */
static PetscErrorCode SetUpLayout(PhlexPart part)
{
  PhlexFlexible     b  = (PhlexFlexible)part->data;
  const char *const rn[18] = {"rx", "ry", "rz", "R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33", "vPx", "vPy", "vPz", "wx", "wy", "wz"};
  const char *const mn[6]  = {"mean_tx", "mean_ty", "mean_tz", "mean_rx", "mean_ry", "mean_rz"};
  PetscInt          nq     = 0;

  PetscFunctionBeginUser;
  if (b->floating) nq = 18 + (b->frame_condition == PHLEX_FRAME_MEAN_AXES ? 6 : 0);
  PetscCall(PhlexPartSetUpLayout(part, b->nv_local, b->nv_global, b->ns_local, b->ns_global, nq));
  if (b->floating) {
    for (PetscInt k = 0; k < 18; k++) PetscCall(PhlexPartSetDof(part, k, k < 12 ? PHLEX_DOF_CONFIGURATION : PHLEX_DOF_VELOCITY, rn[k]));
    for (PetscInt k = 18; k < nq; k++) PetscCall(PhlexPartSetDof(part, k, PHLEX_DOF_IMPULSE, mn[k - 18]));
    part->frame               = (PhlexFrameIndex){0, 3, 12, 15};
    part->nonlinear           = PETSC_TRUE;
    part->nonquadratic_energy = b->frozen_inertia ? PETSC_FALSE : PETSC_TRUE;
  }
  if (b->stiffening) part->nonlinear = PETSC_TRUE; /* G(u) */
  PetscFunctionReturn(0);
}

/* The ports: the listed surfaces, and for a floating body with a frame patch the frame patch (its output is the
   frame's motion (v_P, w); its wrench acts on the frame). */
static PetscErrorCode SetUpPorts(PhlexPart part)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *u = part->units;
  const PetscBool   frame_port = (b->floating && b->frame_condition == PHLEX_FRAME_PATCH) ? PETSC_TRUE : PETSC_FALSE;
  const PetscInt    n = b->nports + (frame_port ? 1 : 0);

  PetscFunctionBeginUser;
  /* a load on the clamped patch of a fixed body goes into the support: it would do nothing, without a word */
  for (PetscInt p = 0; p < b->nports; p++) PetscCheck(b->floating || !b->frame_patch[0] || !b->ports[p].load.loaded || strcmp(b->ports[p].name, b->frame_patch), b->comm, PETSC_ERR_USER_INPUT, "body %s: port %s carries a load (-%sport_%s_force/_moment), but it is the clamped patch of the fixed body (-%sframe_patch %s): the support takes it and nothing moves; load another surface", b->name, b->ports[p].name, b->prefix, b->ports[p].name, b->prefix, b->frame_patch);
  for (PetscInt p = 0; p < b->nports; p++) PetscCall(PhlexFlexPortSetUp(b, &b->ports[p], u));
  PetscCall(PhlexPartSetPorts(part, n));
  for (PetscInt p = 0; p < b->nports; p++) {
    PetscCall(PetscStrcpy(part->ports[p].name, b->ports[p].name));
    part->ports[p].dim = 6;
    for (PetscInt d = 0; d < 3; d++) part->ports[p].point[d] = (b->ports[p].centroid[d] - b->origin[d]) / u->length;
  }
  if (frame_port) {
    PetscCall(PetscStrcpy(part->ports[n - 1].name, b->frame_patch));
    part->ports[n - 1].dim = 6;
  }
  PetscCall(PetscCalloc3(PetscMax(n, 1), &b->port_ext, PetscMax(n, 1), &b->port_y, PetscMax(n, 1), &b->port_ubar));
  PetscCall(PetscMalloc1(PetscMax(n, 1), &b->port_rate));
  for (PetscInt p = 0; p < n; p++)
    for (PetscInt k = 0; k < 9; k++) b->port_rate[p][k] = (k % 4 == 0) ? 1.0 : 0.0;
  PetscCall(PetscCalloc1(PetscMax(n, 1), &b->port_basis_col));
  for (PetscInt p = 0; p < n; p++) b->port_basis_col[p] = -1;
  PetscFunctionReturn(0);
}

/* set-up: spaces, constant operators, ports, inertia, layout */
static PetscErrorCode FlexSetUp(PhlexPart part)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleSetUpFE(b, u));
  {
    uint64_t h;
    PetscCall(PhlexFlexiblePlacement(b, &h));
    PetscCall(PetscSNPrintf(part->numbering, sizeof(part->numbering), "%s@%016llx", b->rcm ? "rcm" : "file", (unsigned long long)h));
  }
  if (!b->floating) PetscCall(PhlexFlexibleSetUpInertia(b, u)); /* nodal int rho phi: gravity on a fixed body */
  PetscCall(SetUpPorts(part));
  PetscCall(SetUpLayout(part));
  b->frame.comm    = b->comm;
  b->frame.frozen  = b->frozen_inertia;
  b->frame.gyroscopic = b->gyroscopic;
  b->frame.inertia = (PhlexInertia){0};
  if (b->floating) {
    b->frame.inertia = b->inertia;
    b->frame.tnode   = b->tnode;
    b->frame.wnode   = b->wnode;
    b->frame.Mv      = b->Mv;
  }
  b->frame.gravity = part->gravity;
  if (!b->floating) {
    part->ops.momenta   = NULL; /* held: no momentum of its own, no frame to move */
    part->ops.rigidmass = NULL;
  }
  PetscCall(DMCreateGlobalVector(b->dm, &b->load));
  PetscCall(VecDuplicate(b->load, &b->work));
  if (b->spinning) {
    char w[3][32];
    for (PetscInt k = 0; k < 3; k++) PhlexFormatReal(b->spin[k], w[k], sizeof(w[k]));
    /* the weight would turn in the rotating frame; a prescribed spin is its own world */
    PetscCheck(part->gravity[0] == 0 && part->gravity[1] == 0 && part->gravity[2] == 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sspin %s,%s,%s with gravity: the weight turns in the spinning frame; remove -gravity (a spin much faster than the weight's effect) or model the hub as a driven joint", b->name, b->prefix, w[0], w[1], w[2]);
    PetscCheck(b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sspin %s,%s,%s needs the body clamped to its hub (-%sframe_patch <surface>)", b->name, b->prefix, w[0], w[1], w[2], b->prefix);
    /* a fixed body's port loads are applied in its axes, which turn with the hub */
    for (PetscInt q = 0; q < b->nports; q++)
      PetscCheck(!b->ports[q].load.loaded || b->ports[q].load.frame != PHLEX_DIRECTION_INERTIAL, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sspin %s,%s,%s with -%sport_%s_direction inertial: the body lives in the hub's rotating frame, where a direction fixed in space turns; give the load in body directions (it turns with the hub) or model the hub as a driven joint", b->name, b->prefix, w[0], w[1], w[2], b->prefix, b->ports[q].name);
  }
  if (b->ic_steady_spin) {
    /* the steady stretch is solved as that of a body clamped at its frame patch (K + Cen, the fixed-hub problem):
       with mean axes the field is free and the problem singular along the axis */
    PetscCheck(b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin needs the body clamped to its frame at a patch (-%sframe_patch <surface>, the hub's side): with -%sframe mean_axes the steady stretch is not defined (the field is free along the spin axis)", b->name, b->prefix, b->prefix, b->prefix);
    /* a steady spin has no load that turns in the rotating frame, nor one that does work */
    PetscBool loaded = (PetscBool)(b->has_body_force || b->frame_loaded);
    char      g[3][32];
    for (PetscInt k = 0; k < 3; k++) PhlexFormatReal(part->gravity[k] * part->units->velocity / part->units->time, g[k], sizeof(g[k])); /* SI */
    PetscCheck(part->gravity[0] == 0 && part->gravity[1] == 0 && part->gravity[2] == 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin with -gravity %s,%s,%s: the weight turns in the spinning frame, so the spin has no steady state; remove -gravity or start from rest", b->name, b->prefix, g[0], g[1], g[2]);
    for (PetscInt q = 0; q < b->nports; q++)
      if (b->ports[q].load.loaded) loaded = PETSC_TRUE;
    PetscCheck(b->ic_displacement.type == PHLEX_IC_ZERO, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin with -%sic_displacement_type %s: the steady spin gives the displacement (its centrifugal stretch); perturb it with an initial velocity (-%sic_velocity_type)", b->name, b->prefix, b->prefix, PhlexICTypes[b->ic_displacement.type], b->prefix);
    PetscCheck(b->ic_stress.type == PHLEX_IC_ZERO, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin with -%sic_stress_type uniform: the steady spin gives the stress (its centrifugal tension)", b->name, b->prefix, b->prefix);
    PetscCheck(!loaded, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin with a load on the body (a port, frame or body force): the steady spin is that of the unloaded body; remove the load or start from rest", b->name, b->prefix);
  }
  if (!b->floating && (part->gravity[0] != 0 || part->gravity[1] != 0 || part->gravity[2] != 0)) {
    /* the weight of a fixed body as a nodal load: t(l) g_c on component c (gravity is a potential: no input power) */
    PetscScalar       *ga;
    const PetscScalar *ta;
    PetscCall(VecDuplicate(b->load, &b->bgrav));
    PetscCall(VecGetArrayWrite(b->bgrav, &ga));
    PetscCall(VecGetArrayRead(b->tnode, &ta));
    for (PetscInt i = 0; i < b->nv_local; i++) ga[i] = ta[i] * part->gravity[i % 3];
    PetscCall(VecRestoreArrayRead(b->tnode, &ta));
    PetscCall(VecRestoreArrayWrite(b->bgrav, &ga));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexView(PhlexPart part, PetscViewer viewer)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscInt      ncells, gcells;

  PetscFunctionBeginUser;
  ncells = b->cEnd - b->cStart;
  PetscCallMPI(MPI_Allreduce(&ncells, &gcells, 1, MPIU_INT, MPI_SUM, b->comm));
  PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: mesh %s, %" PetscInt_FMT " tetrahedra, velocity P%" PetscInt_FMT " (%" PetscInt_FMT " dofs), stress P%" PetscInt_FMT " discontinuous (%" PetscInt_FMT " dofs)\n", b->name, b->mesh_file, gcells, b->degree, b->nv_global, b->degree - 1, b->ns_global));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(PetscViewerASCIIPrintf(viewer, "volume %.6g m^3, mass %.6g kg, centre of mass (%.6g, %.6g, %.6g) m\n", (double)b->volume, (double)b->mass, (double)b->center_of_mass[0], (double)b->center_of_mass[1], (double)b->center_of_mass[2]));
  if (b->process >= 0) {
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(b->comm, &size));
    if (size > 1) PetscCall(PetscViewerASCIIPrintf(viewer, "whole on process %" PetscInt_FMT " (of %d)\n", b->process, (int)size));
  }
  if (b->floating) {
    PetscReal q[4];
    if (b->frame_condition == PHLEX_FRAME_PATCH) PetscCall(PetscViewerASCIIPrintf(viewer, "floating frame on patch %s (origin P at (%.6g, %.6g, %.6g) m), %s inertia\n", b->frame_patch, (double)b->origin[0], (double)b->origin[1], (double)b->origin[2], b->inertia_model));
    else PetscCall(PetscViewerASCIIPrintf(viewer, "floating frame on mean axes (origin P at (%.6g, %.6g, %.6g) m), %s inertia\n", (double)b->origin[0], (double)b->origin[1], (double)b->origin[2], b->inertia_model));
    PhlexRotationToQuaternion(b->pose.rotation, q);
    {
      PetscReal       v0[3], w0[3];
      const PetscBool mapped = PhlexFlexibleFrameVelocity(b, v0, w0);
      PetscCall(PetscViewerASCIIPrintf(viewer, "initial r_P (%.6g, %.6g, %.6g) m, orientation quaternion (%.6g, %.6g, %.6g, %.6g), v_P (%.6g, %.6g, %.6g) m/s, w_P (%.6g, %.6g, %.6g) rad/s (body frame%s)\n", (double)b->pose.position[0], (double)b->pose.position[1], (double)b->pose.position[2], (double)q[0], (double)q[1], (double)q[2], (double)q[3], (double)v0[0], (double)v0[1], (double)v0[2], (double)w0[0], (double)w0[1], (double)w0[2], mapped ? "; from the rigid initial velocity field" : ""));
    }
    if (b->frame_loaded) {
      char prof[256];
      PetscCall(PhlexProfileDescribe(b->frame_profile, prof, sizeof(prof)));
      PetscCall(PetscViewerASCIIPrintf(viewer, "frame wrench at P: force (%.15g, %.15g, %.15g) N, moment (%.15g, %.15g, %.15g) N m (body frame), profile %s\n", (double)b->frame_force[0], (double)b->frame_force[1], (double)b->frame_force[2], (double)b->frame_moment[0], (double)b->frame_moment[1], (double)b->frame_moment[2], prof));
    }
  } else if (b->frame_patch[0]) PetscCall(PetscViewerASCIIPrintf(viewer, "clamped patch (frame patch): %s\n", b->frame_patch));
  else PetscCall(PetscViewerASCIIPrintf(viewer, "no clamped patch: free body\n"));
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    const PhlexMaterial *mat = &b->materials[m];
    char                 E[32], nu[32], rho[32];
    PetscCall(PetscViewerASCIIPrintf(viewer, "material %s: E = %s Pa, nu = %s, rho = %s kg/m^3\n", mat->region[0] ? mat->region : "(whole body)", PhlexFormatReal(mat->youngs_modulus, E, sizeof(E)), PhlexFormatReal(mat->poissons_ratio, nu, sizeof(nu)), PhlexFormatReal(mat->density, rho, sizeof(rho))));
  }
  PetscCall(PhlexFlexibleDampingView(b, viewer));
  for (PetscInt p = 0; p < b->nports; p++) {
    const PhlexFlexPort *port = &b->ports[p];
    char                 load[512];
    PetscCall(PhlexPortLoadDescribe((PhlexPortLoad *)&port->load, load, sizeof(load)));
    PetscCall(PetscViewerASCIIPrintf(viewer, "port %s: area %.6g m^2, centroid (%.6g, %.6g, %.6g) m%s\n", port->name, (double)port->area, (double)port->centroid[0], (double)port->centroid[1], (double)port->centroid[2], load));
  }
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexDestroy(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  for (PetscInt p = 0; p < b->nports; p++) PetscCall(PhlexFlexPortDestroy(&b->ports[p]));
  PetscCall(PetscFree(b->ports));
  PetscCall(PhlexProfileDestroy(&b->body_force_profile));
  PetscCall(PhlexProfileDestroy(&b->frame_profile));
  PetscCall(PhlexFrameStateDestroy(&b->fs));
  PetscCall(VecDestroy(&b->ic_mode[0]));
  PetscCall(VecDestroy(&b->ic_mode[1]));
  PetscCall(MatDestroy(&b->Mvaij));
  PetscCall(MatDestroy(&b->Mvp));
  PetscCall(MatDestroy(&b->Kaij));
  PetscCall(MatDestroy(&b->Jvv));
  PetscCall(MatDestroy(&b->Jvu));
  PetscCall(MatDestroy(&b->Jvc));
  PetscCall(MatDestroy(&b->Sv));
  PetscCall(MatDestroy(&b->W));
  PetscCall(PetscFree5(b->border_P, b->border_Lb, b->border_Lu, b->border_Lv, b->border_Lpre));
  PetscCall(PetscFree(b->port_inertial_in));
  PetscCall(PetscFree2(b->gram, b->gram_piv));
  PetscCall(VecDestroy(&b->load));
  PetscCall(VecDestroy(&b->work));
  PetscCall(VecDestroy(&b->ud));
  PetscCall(VecDestroy(&b->ewv));
  PetscCall(VecDestroy(&b->vd));
  PetscCall(VecDestroy(&b->bgrav));
  PetscCall(PetscFree3(b->port_ext, b->port_y, b->port_ubar));
  PetscCall(PetscFree(b->port_rate));
  PetscCall(PetscFree(b->port_basis_col));
  PetscCall(PhlexFlexibleStressMapsDestroy(b));
  PetscCall(PhlexFlexibleStiffeningDestroy(b));
  PetscCall(PhlexFlexibleSpinDestroy(b));
  PetscCall(VecDestroy(&b->ic_steady_v));
  PetscCall(PhlexFlexibleDampingDestroy(b));
  PetscCall(PhlexFlexibleDestroyFE(b));
  PetscCall(PetscFree(part->data));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Energy and outputs                                                                                             */

/* the energy's first phase (split_sum.c): this process's parts of v^T Mv v (a floating body: with the frame's product
   Mv v of the evaluated state), of s^T Ms s and, with gravity on a fixed body, of b_g . u, each formed as VecDot and
   the monitor's strain energy form it, and their sums started */
static PetscErrorCode FlexEnergyBegin(PhlexPart part, const PhlexPartVec *X)
{
  PhlexFlexible b   = (PhlexFlexible)part->data;
  PetscReal    *loc = b->energy_loc;

  PetscFunctionBeginUser;
  loc[0] = loc[1] = loc[2] = 0.0;
  if (b->floating) PetscCall(PhlexLocalDot(X->v, b->fs.Mvv, &loc[0]));
  else {
    /* kept: the monitor calls this every step, and a fresh vector costs its page faults each time */
    if (!b->ewv) PetscCall(VecDuplicate(X->v, &b->ewv));
    PetscCall(MatMult(b->Mvp ? b->Mvp : b->Mv, X->v, b->ewv));
    PetscCall(PhlexLocalDot(b->ewv, X->v, &loc[0]));
    if (!b->spinning && b->bgrav) PetscCall(PhlexLocalDot(b->bgrav, X->u, &loc[2]));
  }
  PetscCall(PhlexFlexibleStrainEnergyLocal(b, X->s, &loc[1]));
  PetscCall(PhlexSplitSumBegin(b->comm, loc, b->energy_sums, 3, &b->energy_req));
  b->energy_begun = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* the largest elastic displacement |u| over the nodes at X and the body's size (its bounding box's largest side), for
   the blow-up watchdog; whether a spin would need geometric stiffening (the linear model is used) */
static PetscErrorCode FlexDeformation(PhlexPart part, const PhlexPartVec *X, PetscReal *umax, PetscReal *size, PetscBool *linear)
{
  PhlexFlexible      b = (PhlexFlexible)part->data;
  const PetscScalar *a;
  PetscInt           n, bs;
  PetscReal          m2 = 0;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(X->u, &n));
  PetscCall(VecGetBlockSize(X->u, &bs));
  PetscCall(VecGetArrayRead(X->u, &a));
  if (bs == 3)
    for (PetscInt i = 0; i + 2 < n; i += 3) m2 = PetscMax(m2, PetscRealPart(a[i] * a[i] + a[i + 1] * a[i + 1] + a[i + 2] * a[i + 2]));
  else
    for (PetscInt i = 0; i < n; i++) m2 = PetscMax(m2, PetscRealPart(a[i] * a[i])); /* a component's largest: a bound within sqrt(3) */
  PetscCall(VecRestoreArrayRead(X->u, &a));
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &m2, 1, MPIU_REAL, MPIU_MAX, b->comm));
  *umax = PetscSqrtReal(m2) * part->units->length;
  *size = 0;
  for (PetscInt d = 0; d < 3; d++) *size = PetscMax(*size, b->bbox_max[d] - b->bbox_min[d]);
  *linear = (PetscBool)!b->stiffening;
  PetscFunctionReturn(0);
}

/* kinetic 1/2 v^T Mv v (floating: the frame's, which holds it), strain 1/2 s^T Ms s, and the potential of gravity or
   of a spin's centrifugal field, at the evaluated state X (non-dimensional) */
static PetscErrorCode FlexEnergy(PhlexPart part, const PhlexPartVec *X, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  PhlexFlexible    b    = (PhlexFlexible)part->data;
  const PetscReal *sums = b->energy_sums;

  PetscFunctionBeginUser;
  if (!b->energy_begun) PetscCall(FlexEnergyBegin(part, X));
  b->energy_begun = PETSC_FALSE;
  PetscCall(PhlexSplitSumEnd(&b->energy_req));
  *kin    = 0.5 * sums[0];
  *strain = 0.5 * sums[1];
  *pot    = 0.0;
  if (b->floating) PetscCall(PhlexFrameEnergy(&b->frame, &b->fs, sums[0], kin, pot));
  else if (b->spinning) PetscCall(PhlexFlexibleSpinEnergy(b, X->u, pot)); /* centrifugal potential */
  else if (b->bgrav) {
    /* V = -g . int rho (x + u) */
    *pot = -(PhlexDot3(part->gravity, b->inertia.s0) + sums[2]);
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexInputPower(PhlexPart part, PetscReal *P)
{
  PetscFunctionBeginUser;
  *P = ((PhlexFlexible)part->data)->power_ext;
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexMomenta(PhlexPart part, PetscReal P[3], PetscReal L[3])
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFrameMomenta(&b->fs, P, L));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexRigidMass(PhlexPart part, PetscReal M[36])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameRigidMass(&((PhlexFlexible)part->data)->frame.inertia, M));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexOutputOpen(PhlexPart part, PhlexOutput out, PetscBool fields)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  char          name[PHLEX_NAME_LEN + 16], header[1024];

  PetscFunctionBeginUser;
  if (fields) {
    PetscCall(PhlexFieldWriterCreate(out, b, b->name, (PhlexFieldWriter *)&b->writer));
    if (b->floating) PetscCall(PhlexFieldWriterSetGeometryField((PhlexFieldWriter)b->writer, "inertial_position"));
  }
  if (b->nports || b->floating) {
    /* the frame of a floating body first (its patch, or "frame" with mean axes), then the ports */
    const char **names;
    PetscInt     n = 0;
    PetscCall(PetscMalloc1(b->nports + 1, &names));
    if (b->floating) names[n++] = b->frame_patch[0] ? b->frame_patch : "frame";
    for (PetscInt p = 0; p < b->nports; p++) names[n++] = b->ports[p].name;
    PetscCall(PhlexPortSeriesOpen(out, b->name, n, names, (PetscViewer *)&b->ports_csv));
    PetscCall(PetscFree(names));
  }
  if (b->floating) {
    PetscCall(PhlexFrameWriteHeader(header, sizeof(header)));
    PetscCall(PetscSNPrintf(name, sizeof(name), "%s_rigid.csv", b->name));
    PetscCall(PhlexOutputCSVOpen(out, name, header, (PetscViewer *)&b->rigid_csv));
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode PhlexFlexiblePortOutputsAll(PhlexPart, const PhlexPartVec *);

/*@C
  PhlexFlexiblePortInput - the wrench input of port q of a flexible body or of the reduced body wrapping it (part is the
  body's own part) at t: its load (body frame, non-dimensional); the frame patch's port: the frame wrench

  Not collective
@*/
PetscErrorCode PhlexFlexiblePortInput(PhlexPart part, PhlexFlexible b, PetscBool floating, const PhlexFrameState *fs, PetscInt q, PetscReal t, PetscReal w[6])
{
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) w[k] = 0.0;
  if (q < b->nports) PetscCall(PhlexPortLoadEvaluate(&b->ports[q].load, t, u, floating ? fs->R : NULL, w));
  else if (b->frame_loaded) {
    PetscReal fr;
    PetscCall(PhlexProfileEvaluate(b->frame_profile, t, &fr));
    for (PetscInt k = 0; k < 3; k++) {
      w[k]     = fr * b->frame_force[k] / u->force;
      w[3 + k] = fr * b->frame_moment[k] / (u->force * u->length);
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePortSeriesRow - one row of <body>_ports.csv of a flexible body or of the reduced body wrapping it (part
  is the body's own part, which places its ports): time; a floating frame's wrench and motion; each port's input
  wrench (body frame) and output port_y; the frame origin's and each port's inertial position

  Not collective
@*/
PetscErrorCode PhlexFlexiblePortSeriesRow(PhlexPart part, PhlexFlexible b, PetscBool floating, const PhlexFrameState *fs, PetscReal (*port_y)[6], PetscReal t, const PhlexPartVec *X, PetscViewer csv)
{
  const PhlexUnits *u  = part->units;
  PetscReal         fr = 0.0;

  PetscFunctionBeginUser;
  PetscCall(PhlexCSVPrintf(csv, "%.12e", (double)t));
  if (b->frame_loaded) PetscCall(PhlexProfileEvaluate(b->frame_profile, t, &fr));
  if (floating) {
    /* the frame: its wrench (SI), its motion (v_P, w) */
    const PetscReal wf[6] = {fr * b->frame_force[0], fr * b->frame_force[1], fr * b->frame_force[2], fr * b->frame_moment[0], fr * b->frame_moment[1], fr * b->frame_moment[2]};
    const PetscReal yf[6] = {fs->vP[0], fs->vP[1], fs->vP[2], fs->w[0], fs->w[1], fs->w[2]};
    PetscCall(PhlexPortSeriesEntry(csv, u, wf, PETSC_TRUE, yf));
  }
  for (PetscInt p = 0; p < b->nports; p++) {
    PetscReal in[6];
    PetscCall(PhlexPortLoadEvaluate(&b->ports[p].load, t, u, floating ? fs->R : NULL, in)); /* body frame */
    PetscCall(PhlexPortSeriesEntry(csv, u, in, PETSC_FALSE, port_y[p]));
  }
  for (PetscInt p = floating ? -1 : 0; p < b->nports; p++) {
    PetscReal x[3], R[9];
    if (p >= 0) PetscCall((*part->ops.portplacement)(part, p, X, x, R));
    else
      for (PetscInt c = 0; c < 3; c++) x[c] = fs->r[c]; /* the frame: its origin P */
    PetscCall(PhlexPortSeriesPosition(csv, u, x));
  }
  PetscCall(PhlexCSVPrintf(csv, "\n"));
  PetscFunctionReturn(0);
}

/* one output step at the evaluated state X: port series, rigid series, fields */
static PetscErrorCode FlexOutputStep(PhlexPart part, PetscInt step, PetscReal t, const PhlexPartVec *X, PetscBool fields)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  if (b->ports_csv && step >= 0) {
    PetscCall(PhlexFlexiblePortOutputsAll(part, X));
    PetscCall(PhlexFlexiblePortSeriesRow(part, b, b->floating, &b->fs, b->port_y, t, X, (PetscViewer)b->ports_csv));
  }
  if (b->rigid_csv && step >= 0) {
    PetscReal P[3], L[3];
    PetscCall(PhlexFrameWriteRow((PetscViewer)b->rigid_csv, t, &b->fs, u, P, L));
  }
  if (fields && b->writer) PetscCall(PhlexFlexibleWriteFields(b, (PhlexFieldWriter)b->writer, &b->fs, t, X->u, X->v, X->s));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleWriteFields - one output step of a flexible body's fields: displacement, a floating body's inertial
  position (the step's geometry), velocity, stress and von Mises stress (a full body's unknowns, or a reduced body's
  fields Phi eta, Phi zeta, Psi eta)

  Collective

  Input Parameters:
+ b       - the flexible body (its mesh and spaces)
. w       - its field writer
. fs      - the frame's state at time t (a floating body: r_P and R place the mesh)
. t       - time [s]
- u, v, s - displacement, velocity and stress (global vectors of its spaces, non-dimensional)
@*/
PetscErrorCode PhlexFlexibleWriteFields(PhlexFlexible b, PhlexFieldWriter w, const PhlexFrameState *fs, PetscReal t, Vec u, Vec v, Vec s)
{
  const PhlexUnits *units = b->part->units;

  PetscFunctionBeginUser;
  PetscCall(PhlexFieldWriterBeginStep(w, t));
  /* displacement first: ParaView makes the first vector the active one ("Warp By Vector") */
  PetscCall(PhlexFieldWriterVertexField(w, "displacement", u, units->length, NULL, NULL, PETSC_FALSE));
  if (b->floating) {
    /* x_inertial = r_P + R (x - P + u_f): the XDMF geometry of the step, so ParaView shows the motion */
    PetscReal rp[3], RP[3];
    PhlexMatVec3(fs->R, b->origin, RP);
    for (PetscInt k = 0; k < 3; k++) rp[k] = fs->r[k] * units->length - RP[k];
    PetscCall(PhlexFieldWriterVertexField(w, "inertial_position", u, units->length, fs->R, rp, PETSC_TRUE));
  }
  PetscCall(PhlexFieldWriterVertexField(w, "velocity", v, units->velocity, NULL, NULL, PETSC_FALSE));
  PetscCall(PhlexFieldWriterStress(w, s, units->modulus));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexOutputClose(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFieldWriterDestroy((PhlexFieldWriter *)&b->writer));
  PetscCall(PetscViewerDestroy((PetscViewer *)&b->ports_csv));
  PetscCall(PetscViewerDestroy((PetscViewer *)&b->rigid_csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreate_Flexible - a flexible FE body (part kind "flexible", the default)
@*/
PetscErrorCode PhlexPartCreate_Flexible(PhlexPart part)
{
  PhlexFlexible b;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&b));
  PetscCall(PetscNew(&part->fieldops));
  PetscCall(PetscNew(&part->analysisops));
  part->data   = b;
  b->comm      = part->comm;
  b->part      = part;
  b->name      = part->name;
  b->prefix    = part->prefix;
  b->degree    = 2;
  b->rcm       = PETSC_TRUE;
  b->process   = -1;
  b->frame_tag = -1;
  b->ic_velocity.amplitude = b->ic_displacement.amplitude = b->ic_stress.amplitude = 1.0;
  b->ic_velocity.mode = b->ic_displacement.mode = b->ic_stress.mode = 1;
  b->pose.rotation[0] = b->pose.rotation[4] = b->pose.rotation[8] = 1.0;
  part->ops.setfromoptions      = FlexSetFromOptions;
  part->ops.geometry            = FlexGeometry;
  part->ops.setup               = FlexSetUp;
  part->ops.view                = FlexView;
  part->ops.destroy             = FlexDestroy;
  part->ops.prepareinitialstate = PhlexFlexiblePrepareInitialState;
  part->ops.initialstate        = PhlexFlexibleInitialState;
  part->ops.energy              = FlexEnergy;
  part->ops.deformation         = FlexDeformation;
  part->ops.inputpower          = FlexInputPower;
  part->ops.momenta             = FlexMomenta;
  part->ops.rigidmass           = FlexRigidMass;
  part->ops.outputopen          = FlexOutputOpen;
  part->ops.outputstep          = FlexOutputStep;
  part->ops.outputclose         = FlexOutputClose;
  part->fieldops->energybegin = FlexEnergyBegin;
  part->analysisops->modes       = PhlexFlexibleModesAnalysis;
  part->analysisops->modesoutput = PhlexFlexibleModesOutput;
  part->analysisops->refine      = PhlexFlexibleRefine;
  part->analysisops->modesorder  = PhlexFlexibleModesOrder;
  part->analysisops->modeskind   = PhlexFlexibleModesKind;
  part->analysisops->steadystate = PhlexFlexibleSpinSteadyState;
  part->analysisops->spinrate    = PhlexFlexibleSpinRate;
  part->analysisops->steadystart = PhlexFlexibleSteadySpinStart;
  part->analysisops->steadydrive = PhlexFlexibleSteadyDrive;
  PetscCall(PhlexFlexibleSetDynamicsOps(part));
  PetscFunctionReturn(0);
}
