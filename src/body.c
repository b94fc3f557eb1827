/* One elastic body: options, materials, finite element spaces, and the constant body-frame operators
   (velocity mass, stress compliance mass, Grad coupling, condensed stiffness), assembled once. */
#include <phlex_impl.h>

const char *const PhlexICTypes[] = {"zero", "uniform", "rigid", "beam", "mode", "PhlexICType", "PHLEX_IC_", NULL};
static const char *const PhlexMotionTypes[]  = {"fixed", "floating", "PhlexMotion", "PHLEX_MOTION_", NULL};
static const char *const PhlexInertiaTypes[] = {"full", "frozen", "PhlexInertia", "PHLEX_INERTIA_", NULL};

/*@C
  PhlexBodyCreate - creates body number index (options prefix "body<index>_")

  Collective
@*/
PetscErrorCode PhlexBodyCreate(MPI_Comm comm, PetscInt index, PhlexBody *body)
{
  PhlexBody b;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&b));
  b->comm      = comm;
  b->index     = index;
  b->degree    = 2;
  b->frame_tag = -1;
  PetscCall(PetscSNPrintf(b->prefix, sizeof(b->prefix), "body%" PetscInt_FMT "_", index));
  PetscCall(PetscSNPrintf(b->name, sizeof(b->name), "body%" PetscInt_FMT, index));
  b->ic_velocity.amplitude     = 1.0;
  b->ic_displacement.amplitude = 1.0;
  b->ic_stress.amplitude       = 1.0;
  b->ic_velocity.mode = b->ic_displacement.mode = b->ic_stress.mode = 1;
  b->rotation0[0] = b->rotation0[4] = b->rotation0[8] = 1.0;
  *body                        = b;
  PetscFunctionReturn(0);
}

static PetscErrorCode MaterialCheck(PhlexBody b, const PhlexMaterial *m, const char prefix[])
{
  PetscFunctionBeginUser;
  PetscCheck(m->youngs_modulus > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: Young's modulus must be positive: -%syoungs_modulus %g", b->name, prefix, (double)m->youngs_modulus);
  PetscCheck(m->poissons_ratio > -1.0 && m->poissons_ratio < 0.5, b->comm, PETSC_ERR_USER_INPUT, "body %s: Poisson's ratio must lie in (-1, 0.5): -%spoissons_ratio %g", b->name, prefix, (double)m->poissons_ratio);
  PetscCheck(m->density > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: density must be positive: -%sdensity %g", b->name, prefix, (double)m->density);
  PetscFunctionReturn(0);
}

static PetscErrorCode MaterialSetFromOptions(PhlexBody b, PhlexMaterial *m, const char prefix[], PetscBool required)
{
  PetscBool fE = PETSC_FALSE, fn = PETSC_FALSE, fr = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscOptionsBegin(b->comm, prefix, "Material options", NULL);
  PetscCall(PetscOptionsReal("-youngs_modulus", "Young's modulus E [Pa]", "PhlexBodySetFromOptions", m->youngs_modulus, &m->youngs_modulus, &fE));
  PetscCall(PetscOptionsReal("-poissons_ratio", "Poisson's ratio nu [-]", "PhlexBodySetFromOptions", m->poissons_ratio, &m->poissons_ratio, &fn));
  PetscCall(PetscOptionsReal("-density", "Mass density rho [kg/m^3]", "PhlexBodySetFromOptions", m->density, &m->density, &fr));
  PetscOptionsEnd();
  if (required) {
    PetscCheck(fE, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%syoungs_modulus [Pa]", b->name, prefix);
    PetscCheck(fn, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%spoissons_ratio [-]", b->name, prefix);
    PetscCheck(fr, b->comm, PETSC_ERR_USER_INPUT, "body %s: missing material option -%sdensity [kg/m^3]", b->name, prefix);
  }
  PetscCall(MaterialCheck(b, m, prefix));
  PetscFunctionReturn(0);
}

static PetscErrorCode ICSetFromOptions(PhlexBody b, PhlexIC *ic, const char field[], PetscInt ncomp)
{
  char prefix[128], who[PHLEX_NAME_LEN + 8];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sic_%s_", b->prefix, field));
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", b->name));
  PetscOptionsBegin(b->comm, prefix, "Initial condition options", NULL);
  PetscCall(PetscOptionsEnum("-type", "Initial condition: zero, uniform, rigid (v + w x (x - origin)), beam (Euler-Bernoulli cantilever mode), mode (computed elastic mode)", "PhlexBodySetFromOptions", PhlexICTypes, (PetscEnum)ic->type, (PetscEnum *)&ic->type, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-value", ncomp == 6 ? "uniform: stress components xx,yy,zz,yz,xz,xy [Pa]" : "uniform/rigid: vector [SI]", "PhlexBodySetFromOptions", ncomp, ic->value, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-angular", "rigid: angular velocity [rad/s]", "PhlexBodySetFromOptions", 3, ic->angular, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-origin", "rigid: point of the rotation axis [m]", "PhlexBodySetFromOptions", 3, ic->origin, NULL));
  PetscCall(PetscOptionsInt("-mode", "beam/mode: mode number (1 = lowest)", "PhlexBodySetFromOptions", ic->mode, &ic->mode, NULL));
  PetscCall(PetscOptionsReal("-amplitude", "beam/mode: largest value of the field [SI]", "PhlexBodySetFromOptions", ic->amplitude, &ic->amplitude, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-direction", "beam: deflection direction", "PhlexBodySetFromOptions", 3, ic->direction, NULL));
  PetscOptionsEnd();
  PetscCheck(ic->mode >= 1, b->comm, PETSC_ERR_USER_INPUT, "body %s: option -%smode must be >= 1, got %" PetscInt_FMT, b->name, prefix, ic->mode);
  PetscCheck(ncomp == 3 || (ic->type != PHLEX_IC_RIGID && ic->type != PHLEX_IC_BEAM), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%stype %s is not available for the stress", b->name, prefix, PhlexICTypes[ic->type]);
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodySetFromOptions - reads the body's options

  Collective

  Options Database Keys (prefix body<k>_):
+ -name <s>                 - name used in messages and output files
. -dm_plex_filename <file>  - gmsh mesh (.msh 2.2 or 4.1, ASCII or binary)
. -petscspace_degree <k>    - velocity degree k (1 or 2); the stress is discontinuous of degree k-1
. -frame_patch <group>      - physical surface where u_f = v_f = 0 (clamped patch); empty: free body
. -youngs_modulus, -poissons_ratio, -density - material of the whole body
. -regions r1,r2            - physical volumes with their own material (-region_<r>_youngs_modulus, ...)
. -ports p1,p2              - physical surfaces carrying wrench inputs (-port_<p>_force, ...)
. -body_force fx,fy,fz      - uniform body force density [N/m^3] with -body_force_profile_type ...
- -ic_velocity_type, -ic_displacement_type, -ic_stress_type - initial conditions
@*/
PetscErrorCode PhlexBodySetFromOptions(PhlexBody b)
{
  char      regions[PHLEX_MAX_MATERIALS][PHLEX_NAME_LEN];
  char     *rptr[PHLEX_MAX_MATERIALS], *pptr[PHLEX_MAX_PORTS];
  PetscInt  nregions = PHLEX_MAX_MATERIALS, nports = PHLEX_MAX_PORTS, n;
  PetscBool flg, flg_mesh = PETSC_FALSE, has_body_material;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < PHLEX_MAX_MATERIALS; i++) rptr[i] = NULL;
  for (PetscInt i = 0; i < PHLEX_MAX_PORTS; i++) pptr[i] = NULL;
  PetscOptionsBegin(b->comm, b->prefix, "Body options", NULL);
  PetscCall(PetscOptionsString("-name", "Name of the body (messages, output files)", "PhlexBodySetFromOptions", b->name, b->name, sizeof(b->name), NULL));
  char who[PHLEX_NAME_LEN + 8]; /* "body <name>" in messages */
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", b->name));
  PetscCall(PetscOptionsString("-dm_plex_filename", "gmsh mesh file of the body (.msh 2.2 or 4.1)", "PhlexBodySetFromOptions", b->mesh_file, b->mesh_file, sizeof(b->mesh_file), &flg_mesh));
  PetscCall(PetscOptionsInt("-petscspace_degree", "Velocity degree k (1 or 2); stress: discontinuous degree k-1", "PhlexBodySetFromOptions", b->degree, &b->degree, NULL));
  PetscCall(PetscOptionsString("-frame_patch", "Physical surface where u_f = v_f = 0 (clamped patch, frame origin); empty: free body", "PhlexBodySetFromOptions", b->frame_patch, b->frame_patch, sizeof(b->frame_patch), NULL));
  PetscCall(PetscOptionsStringArray("-regions", "Physical volumes with their own material (-region_<name>_youngs_modulus ...)", "PhlexBodySetFromOptions", rptr, &nregions, &flg));
  if (!flg) nregions = 0;
  PetscCall(PetscOptionsStringArray("-ports", "Physical surfaces carrying wrench inputs (-port_<name>_force ...)", "PhlexBodySetFromOptions", pptr, &nports, &flg));
  if (!flg) nports = 0;
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-body_force", "Uniform body force density (body frame) [N/m^3]", "PhlexBodySetFromOptions", 3, b->body_force, &b->has_body_force));
  {
    PetscInt  motion = b->floating ? 1 : 0, inertia = b->frozen_inertia ? 1 : 0;
    PetscReal quat[4] = {1, 0, 0, 0}, aa[4] = {1, 0, 0, 0};
    PetscBool fq = PETSC_FALSE, fa = PETSC_FALSE, fp = PETSC_FALSE, ff = PETSC_FALSE, fm = PETSC_FALSE, fv = PETSC_FALSE, fw = PETSC_FALSE;
    PetscCall(PetscOptionsEList("-motion", "Rigid motion of the body frame: fixed (clamped patch held) or floating (the frame moves)", "PhlexBodySetFromOptions", PhlexMotionTypes, 2, PhlexMotionTypes[motion], &motion, NULL));
    PetscCall(PetscOptionsEList("-inertia", "Floating body: inertia with x + u_f (full) or at u_f = 0 (frozen, quadratic Hamiltonian)", "PhlexBodySetFromOptions", PhlexInertiaTypes, 2, PhlexInertiaTypes[inertia], &inertia, NULL));
    b->floating       = motion ? PETSC_TRUE : PETSC_FALSE;
    b->frozen_inertia = inertia ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-position", "Floating body: initial position r_P of the frame origin (default: the frame-patch centroid, i.e. the mesh as drawn) [m]", "PhlexBodySetFromOptions", 3, b->position0, &fp));
    b->position_given = fp;
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-orientation_quaternion", "Floating body: initial orientation R as a quaternion w,x,y,z [-]", "PhlexBodySetFromOptions", 4, quat, &fq));
    n = 4;
    PetscCall(PetscOptionsRealArray("-orientation_axis_angle", "Floating body: initial orientation R as axis x,y,z and angle [deg]", "PhlexBodySetFromOptions", aa, &n, &fa));
    PetscCheck(!fa || n == 4, b->comm, PETSC_ERR_USER_INPUT, "body %s: option -%sorientation_axis_angle needs 4 numbers (axis, angle in degrees), got %" PetscInt_FMT, b->name, b->prefix, n);
    PetscCheck(!(fq && fa), b->comm, PETSC_ERR_USER_INPUT, "body %s: give -%sorientation_quaternion or -%sorientation_axis_angle, not both", b->name, b->prefix, b->prefix);
    if (fq) {
      PetscCheck(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3] > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sorientation_quaternion must not be zero", b->name, b->prefix);
      PhlexQuaternionToRotation(quat, b->rotation0);
    }
    if (fa) {
      PetscCheck(aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2] > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: the axis of -%sorientation_axis_angle must not be zero", b->name, b->prefix);
      PhlexAxisAngleToRotation(aa, aa[3] * PETSC_PI / 180.0, b->rotation0);
    }
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-velocity", "Floating body: initial velocity v_P of the frame origin (body frame) [m/s]", "PhlexBodySetFromOptions", 3, b->velocity0, &fv));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-angular_velocity", "Floating body: initial angular velocity w_P (body frame) [rad/s]", "PhlexBodySetFromOptions", 3, b->omega0, &fw));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-frame_force", "Floating body: force on the frame origin (body frame) [N]", "PhlexBodySetFromOptions", 3, b->frame_force, &ff));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, b->prefix, "-frame_moment", "Floating body: moment about the frame origin (body frame) [N m]", "PhlexBodySetFromOptions", 3, b->frame_moment, &fm));
    b->frame_loaded = (ff || fm) ? PETSC_TRUE : PETSC_FALSE;
    /* a fixed body has no rigid state: its rigid options would be silently ignored */
    if (!b->floating) {
      const char *given = fp ? "position" : fq ? "orientation_quaternion" : fa ? "orientation_axis_angle" : fv ? "velocity" : fw ? "angular_velocity" : ff ? "frame_force" : fm ? "frame_moment" : NULL;
      PetscCheck(!given, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%s%s describes the rigid motion of a floating frame; the body is fixed (-%smotion fixed): add -%smotion floating or remove the option", b->name, b->prefix, given, b->prefix, b->prefix);
    }
  }
  PetscOptionsEnd();
  if (b->floating) PetscCheck(b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: a floating body needs a frame patch (-%sframe_patch <surface>): it fixes the body frame and its centroid is the frame origin", b->name, b->prefix);
  if (b->frame_loaded) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sframe_", b->prefix));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, frame wrench", b->name));
    PetscCall(PhlexProfileCreate(b->comm, prefix, what, &b->frame_profile));
    PetscCall(PhlexProfileSetFromOptions(b->frame_profile));
  }

  PetscCheck(flg_mesh && b->mesh_file[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: no mesh: set -%sdm_plex_filename <file.msh>", b->name, b->prefix);
  PetscCheck(b->degree == 1 || b->degree == 2, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%spetscspace_degree must be 1 or 2, got %" PetscInt_FMT, b->name, b->prefix, b->degree);

  /* materials: either one for the whole body, or one per listed region */
  b->nmaterials = nregions ? nregions : 1;
  PetscCall(PetscOptionsHasName(NULL, b->prefix, "-youngs_modulus", &has_body_material));
  if (!nregions) {
    PetscCall(PetscStrcpy(b->materials[0].region, ""));
    b->materials[0].tag = -1;
    PetscCall(MaterialSetFromOptions(b, &b->materials[0], b->prefix, PETSC_TRUE));
  } else {
    PetscCheck(!has_body_material, b->comm, PETSC_ERR_USER_INPUT, "body %s: give the material either for the whole body (-%syoungs_modulus ...) or per region (-%sregions), not both", b->name, b->prefix, b->prefix);
    for (PetscInt r = 0; r < nregions; r++) {
      char prefix[256];
      PetscCall(PetscStrncpy(regions[r], rptr[r], PHLEX_NAME_LEN));
      PetscCall(PetscStrncpy(b->materials[r].region, regions[r], PHLEX_NAME_LEN));
      b->materials[r].tag = -1;
      PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sregion_%s_", b->prefix, regions[r]));
      PetscCall(MaterialSetFromOptions(b, &b->materials[r], prefix, PETSC_TRUE));
    }
  }
  for (PetscInt r = 0; r < nregions; r++) PetscCall(PetscFree(rptr[r]));

  b->nports = nports;
  for (PetscInt p = 0; p < nports; p++) {
    PetscCall(PetscMemzero(&b->ports[p], sizeof(b->ports[p])));
    PetscCall(PetscStrncpy(b->ports[p].name, pptr[p], PHLEX_NAME_LEN));
    PetscCall(PetscFree(pptr[p]));
    PetscCall(PhlexPortSetFromOptions(b, &b->ports[p]));
  }
  if (b->has_body_force) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sbody_force_", b->prefix));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, body force", b->name));
    PetscCall(PhlexProfileCreate(b->comm, prefix, what, &b->body_force_profile));
    PetscCall(PhlexProfileSetFromOptions(b->body_force_profile));
  }
  PetscCall(ICSetFromOptions(b, &b->ic_velocity, "velocity", 3));
  PetscCall(ICSetFromOptions(b, &b->ic_displacement, "displacement", 3));
  PetscCall(ICSetFromOptions(b, &b->ic_stress, "stress", 6));
  PetscFunctionReturn(0);
}

/* Discontinuous P_{k-1} Lagrange element with 6 components (the symmetric stress in Voigt order). */
static PetscErrorCode CreateStressFE(MPI_Comm comm, PetscInt degree, PetscFE *fe)
{
  PetscSpace     P;
  PetscDualSpace Q;
  DM             K;

  PetscFunctionBeginUser;
  PetscCall(PetscSpaceCreate(comm, &P));
  PetscCall(PetscSpaceSetType(P, PETSCSPACEPOLYNOMIAL));
  PetscCall(PetscSpaceSetNumComponents(P, 6));
  PetscCall(PetscSpaceSetNumVariables(P, 3));
  PetscCall(PetscSpaceSetDegree(P, degree, PETSC_DETERMINE));
  PetscCall(PetscSpaceSetUp(P));
  PetscCall(PetscDualSpaceCreate(comm, &Q));
  PetscCall(PetscDualSpaceSetType(Q, PETSCDUALSPACELAGRANGE));
  PetscCall(DMPlexCreateReferenceCell(PETSC_COMM_SELF, DM_POLYTOPE_TETRAHEDRON, &K));
  PetscCall(PetscDualSpaceSetDM(Q, K));
  PetscCall(DMDestroy(&K));
  PetscCall(PetscDualSpaceSetNumComponents(Q, 6));
  PetscCall(PetscDualSpaceSetOrder(Q, degree));
  PetscCall(PetscDualSpaceLagrangeSetContinuity(Q, PETSC_FALSE));
  PetscCall(PetscDualSpaceSetUp(Q));
  PetscCall(PetscFECreate(comm, fe));
  PetscCall(PetscFESetType(*fe, PETSCFEBASIC));
  PetscCall(PetscFESetBasisSpace(*fe, P));
  PetscCall(PetscFESetDualSpace(*fe, Q));
  PetscCall(PetscFESetNumComponents(*fe, 6));
  PetscCall(PetscFESetUp(*fe));
  PetscCall(PetscSpaceDestroy(&P));
  PetscCall(PetscDualSpaceDestroy(&Q));
  PetscFunctionReturn(0);
}

static void ZeroBC(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar bcval[])
{
  for (PetscInt c = 0; c < 3; c++) bcval[c] = 0.0;
}

static PetscErrorCode SetUpSpaces(PhlexBody b)
{
  PetscQuadrature q;
  const char     *vnames[] = {"x", "y", "z"};
  const char     *snames[] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  PetscSection    s;

  PetscFunctionBeginUser;
  PetscCall(DMClone(b->dm, &b->dm_s));
  PetscCall(PetscFECreateLagrange(b->comm, 3, 3, PETSC_TRUE, b->degree, PETSC_DETERMINE, &b->fe_v));
  PetscCall(CreateStressFE(b->comm, b->degree - 1, &b->fe_s));
  /* one rule for both spaces, exact for the P_k mass (degree 2k) and all other integrands */
  PetscCall(PetscDTSimplexQuadrature(3, 2 * b->degree, PETSCDTSIMPLEXQUAD_MINSYM, &q));
  PetscCall(PetscFESetQuadrature(b->fe_v, q));
  PetscCall(PetscFESetQuadrature(b->fe_s, q));
  PetscCall(PetscQuadratureDestroy(&q));
  PetscCall(PetscObjectSetName((PetscObject)b->fe_v, "velocity"));
  PetscCall(PetscObjectSetName((PetscObject)b->fe_s, "stress"));
  PetscCall(DMSetField(b->dm, 0, NULL, (PetscObject)b->fe_v));
  PetscCall(DMCreateDS(b->dm));
  if (b->frame_patch[0]) {
    DMLabel  label;
    char     option[128];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sframe_patch", b->prefix));
    PetscCall(PhlexMeshFindGroup(b, b->frame_patch, 2, option, &b->frame_tag));
    PetscCall(DMGetLabel(b->dm, "Face Sets", &label));
    PetscCall(DMAddBoundary(b->dm, DM_BC_ESSENTIAL, "frame_patch", label, 1, &b->frame_tag, 0, 0, NULL, (void (*)(void))ZeroBC, NULL, NULL, NULL));
    PetscCall(PhlexSurfaceMoments(b, b->frame_tag, &b->frame_area, b->frame_centroid, b->frame_inertia));
  }
  PetscCall(DMSetField(b->dm_s, 0, NULL, (PetscObject)b->fe_s));
  PetscCall(DMCreateDS(b->dm_s));
  PetscCall(DMGetLocalSection(b->dm, &s));
  PetscCall(PetscSectionSetFieldName(s, 0, "velocity"));
  for (PetscInt c = 0; c < 3; c++) PetscCall(PetscSectionSetComponentName(s, 0, c, vnames[c]));
  PetscCall(DMGetLocalSection(b->dm_s, &s));
  PetscCall(PetscSectionSetFieldName(s, 0, "stress"));
  for (PetscInt c = 0; c < 6; c++) PetscCall(PetscSectionSetComponentName(s, 0, c, snames[c]));
  PetscCall(PetscFEGetDimension(b->fe_v, &b->nb_v));
  PetscCall(PetscFEGetDimension(b->fe_s, &b->nb_s));
  PetscCall(DMPlexGetHeightStratum(b->dm, 0, &b->cStart, &b->cEnd));
  {
    Vec v;
    PetscCall(DMGetGlobalVector(b->dm, &v));
    PetscCall(VecGetLocalSize(v, &b->nv_local));
    PetscCall(VecGetSize(v, &b->nv_global));
    PetscCall(DMRestoreGlobalVector(b->dm, &v));
    PetscCall(DMGetGlobalVector(b->dm_s, &v));
    PetscCall(VecGetLocalSize(v, &b->ns_local));
    PetscCall(VecGetSize(v, &b->ns_global));
    PetscCall(DMRestoreGlobalVector(b->dm_s, &v));
  }
  PetscFunctionReturn(0);
}

/* Material index of every local cell from the "Cell Sets" label. */
static PetscErrorCode SetUpMaterials(PhlexBody b)
{
  DMLabel  label;
  PetscInt ncells = b->cEnd - b->cStart, missing = -1, gmissing, val;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(ncells, &b->cell_material));
  if (b->nmaterials == 1 && b->materials[0].tag < 0 && !b->materials[0].region[0]) PetscFunctionReturn(0);
  for (PetscInt r = 0; r < b->nmaterials; r++) {
    char option[128];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sregions", b->prefix));
    PetscCall(PhlexMeshFindGroup(b, b->materials[r].region, 3, option, &b->materials[r].tag));
  }
  PetscCall(DMGetLabel(b->dm, "Cell Sets", &label));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscInt m = -1;
    val        = -1;
    if (label) PetscCall(DMLabelGetValue(label, c, &val));
    for (PetscInt r = 0; r < b->nmaterials; r++)
      if (b->materials[r].tag == val) m = r;
    if (m < 0 && missing < 0) missing = val;
    b->cell_material[c - b->cStart] = m < 0 ? 0 : m;
  }
  PetscCallMPI(MPI_Allreduce(&missing, &gmissing, 1, MPIU_INT, MPI_MAX, b->comm));
  if (gmissing >= 0 || missing != -1) {
    const char *gname = "(no physical volume)";
    for (PetscInt g = 0; g < b->ngroups; g++)
      if (b->groups[g].dim == 3 && b->groups[g].tag == gmissing) gname = b->groups[g].name;
    SETERRQ(b->comm, PETSC_ERR_USER_INPUT, "body %s: cells of physical volume %s (tag %" PetscInt_FMT ") in mesh file '%s' have no material: add it to -%sregions", b->name, gname, gmissing, b->mesh_file, b->prefix);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyGetBasis - tabulates the scalar node shapes of the velocity (stress = PETSC_FALSE) or stress element at
  the quadrature points

  Not collective

  Notes:
  PETSc's vector Lagrange elements are node-major: basis function b is component b % Nc of node b / Nc, with the
  scalar shape of that node. This is checked on the tabulation.
@*/
PetscErrorCode PhlexBodyGetBasis(PhlexBody b, PetscBool stress, PhlexElementBasis *B)
{
  PetscFE         fe = stress ? b->fe_s : b->fe_v;
  PetscQuadrature q;
  PetscTabulation T;
  PetscInt        Nc, dim, Nb;

  PetscFunctionBeginUser;
  PetscCall(PetscFEGetQuadrature(fe, &q));
  PetscCall(PetscQuadratureGetData(q, &dim, NULL, &B->nq, NULL, &B->weights));
  PetscCall(PetscFEGetCellTabulation(fe, 1, &T));
  Nc        = T->Nc;
  Nb        = T->Nb;
  B->nb     = Nb;
  B->nc     = Nc;
  B->nnodes = Nb / Nc;
  PetscCheck(B->nnodes <= PHLEX_MAX_NODES, PETSC_COMM_SELF, PETSC_ERR_SUP, "element with %" PetscInt_FMT " nodes", B->nnodes);
  PetscCall(PetscMalloc2(B->nq * B->nnodes, &B->node_phi, B->nq * B->nnodes * 3, &B->node_dphi));
  for (PetscInt qq = 0; qq < B->nq; qq++)
    for (PetscInt n = 0; n < B->nnodes; n++) {
      B->node_phi[qq * B->nnodes + n] = T->T[0][(qq * Nb + n * Nc) * Nc + 0];
      for (PetscInt d = 0; d < 3; d++) B->node_dphi[(qq * B->nnodes + n) * 3 + d] = T->T[1][((qq * Nb + n * Nc) * Nc + 0) * dim + d];
    }
  /* node-major check: component c of node n has the node's shape in component c and nothing elsewhere */
  for (PetscInt qq = 0; qq < B->nq; qq++)
    for (PetscInt bb = 0; bb < Nb; bb++)
      for (PetscInt c = 0; c < Nc; c++) {
        const PetscReal expect = (c == bb % Nc) ? B->node_phi[qq * B->nnodes + bb / Nc] : 0.0;
        PetscCheck(PetscAbsReal(T->T[0][(qq * Nb + bb) * Nc + c] - expect) < 1e-12, PETSC_COMM_SELF, PETSC_ERR_PLIB, "unexpected layout of the %s basis", stress ? "stress" : "velocity");
      }
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexBodyRestoreBasis(PhlexElementBasis *B)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree2(B->node_phi, B->node_dphi));
  PetscFunctionReturn(0);
}

/* Global dofs of every local cell, cached once: DMPlexGetClosureIndices is the expensive part of an element loop. */
static PetscErrorCode SetUpCellDofs(PhlexBody b)
{
  PetscSection section, gsection, gsec_s;
  PetscInt     ncells = b->cEnd - b->cStart;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalSection(b->dm, &section));
  PetscCall(DMGetGlobalSection(b->dm, &gsection));
  PetscCall(DMGetGlobalSection(b->dm_s, &gsec_s));
  PetscCall(PetscMalloc2(ncells * b->nb_v, &b->cell_vdofs, ncells, &b->cell_soff));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscInt nidx, *idx = NULL;
    PetscCall(DMPlexGetClosureIndices(b->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCheck(nidx == b->nb_v, PETSC_COMM_SELF, PETSC_ERR_PLIB, "closure of cell %" PetscInt_FMT " has %" PetscInt_FMT " dofs, expected %" PetscInt_FMT, c, nidx, b->nb_v);
    PetscCall(PetscArraycpy(&b->cell_vdofs[(c - b->cStart) * b->nb_v], idx, nidx));
    PetscCall(DMPlexRestoreClosureIndices(b->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCall(PetscSectionGetOffset(gsec_s, c, &b->cell_soff[c - b->cStart]));
  }
  PetscFunctionReturn(0);
}

/* Block (node) indices of a cell: velocity dofs come in x, y, z triples, constrained as a whole (-1). */
static inline void CellNodeIndices(PhlexBody b, PetscInt c, PetscInt *nodes)
{
  const PetscInt *idx = &b->cell_vdofs[c * b->nb_v];
  for (PetscInt a = 0; a < b->nb_v / 3; a++) nodes[a] = idx[3 * a] >= 0 ? idx[3 * a] / 3 : -1;
}

/* A velocity-space operator (3 x 3 blocks between nodes sharing a cell) stored as symmetric block matrix SBAIJ
   (upper triangle, block size 3): the format the sparse Cholesky solvers (MUMPS, CHOLMOD) factor directly. The block
   structure is counted from the node graph of the cells in serial and with MATPREALLOCATOR in parallel (which also
   sees the rows of nodes owned by other ranks). */
static PetscErrorCode CreateVelocityMatrix(PhlexBody b, Mat *A)
{
  const PetscInt nn = b->nb_v / 3, ncells = b->cEnd - b->cStart, nloc = b->nv_local / 3;
  PetscMPIInt    size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(b->comm, &size));
  PetscCall(MatCreate(b->comm, A));
  PetscCall(MatSetSizes(*A, b->nv_local, b->nv_local, b->nv_global, b->nv_global));
  PetscCall(MatSetBlockSize(*A, 3));
  PetscCall(MatSetType(*A, MATSBAIJ));
  if (size > 1) {
    Mat      P;
    PetscInt nodes[PHLEX_MAX_NODES];
    PetscCall(MatCreate(b->comm, &P));
    PetscCall(MatSetType(P, MATPREALLOCATOR));
    PetscCall(MatSetSizes(P, b->nv_local, b->nv_local, b->nv_global, b->nv_global));
    PetscCall(MatSetBlockSize(P, 3));
    PetscCall(MatSetUp(P));
    for (PetscInt c = 0; c < ncells; c++) {
      PetscScalar zeros[9 * PHLEX_MAX_NODES * PHLEX_MAX_NODES] = {0};
      CellNodeIndices(b, c, nodes);
      PetscCall(MatSetValuesBlocked(P, nn, nodes, nn, nodes, zeros, INSERT_VALUES));
    }
    PetscCall(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY));
    PetscCall(MatPreallocatorPreallocate(P, PETSC_FALSE, *A));
    PetscCall(MatDestroy(&P));
  } else {
    PetscInt *cnt, *off, *cells, *nbr, *nnz, maxnbr = PHLEX_MAX_NODES * 64;
    /* node -> cells, then the distinct upper neighbours of every node */
    PetscCall(PetscCalloc2(nloc + 1, &cnt, nloc + 1, &off));
    for (PetscInt c = 0; c < ncells; c++)
      for (PetscInt a = 0; a < nn; a++) {
        const PetscInt g = b->cell_vdofs[c * b->nb_v + 3 * a];
        if (g >= 0) cnt[g / 3]++;
      }
    for (PetscInt i = 0; i < nloc; i++) off[i + 1] = off[i] + cnt[i];
    PetscCall(PetscMalloc3(off[nloc] + 1, &cells, maxnbr, &nbr, nloc, &nnz));
    PetscCall(PetscArrayzero(cnt, nloc));
    for (PetscInt c = 0; c < ncells; c++)
      for (PetscInt a = 0; a < nn; a++) {
        const PetscInt g = b->cell_vdofs[c * b->nb_v + 3 * a];
        if (g >= 0) cells[off[g / 3] + cnt[g / 3]++] = c;
      }
    for (PetscInt i = 0; i < nloc; i++) {
      PetscInt n = 0;
      for (PetscInt k = off[i]; k < off[i + 1]; k++)
        for (PetscInt a = 0; a < nn; a++) {
          const PetscInt g = b->cell_vdofs[cells[k] * b->nb_v + 3 * a];
          if (g >= 3 * i) {
            if (n == maxnbr) {
              PetscCall(PetscSortRemoveDupsInt(&n, nbr));
              PetscCheck(n < maxnbr, PETSC_COMM_SELF, PETSC_ERR_SUP, "node with more than %" PetscInt_FMT " neighbours", maxnbr);
            }
            nbr[n++] = g;
          }
        }
      PetscCall(PetscSortRemoveDupsInt(&n, nbr));
      nnz[i] = n;
    }
    PetscCall(MatSeqSBAIJSetPreallocation(*A, 3, 0, nnz));
    PetscCall(PetscFree2(cnt, off));
    PetscCall(PetscFree3(cells, nbr, nnz));
  }
  PetscCall(MatSetOption(*A, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
  PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscFunctionReturn(0);
}

/* Exact preallocation of G (stress rows x velocity columns): each stress row couples to the velocity dofs of its cell. */
static PetscErrorCode CreateCouplingMatrix(PhlexBody b, Mat *G)
{
  PetscInt vstart, vend, rstart, *dnz, *onz;

  PetscFunctionBeginUser;
  {
    Vec v;
    PetscCall(DMGetGlobalVector(b->dm, &v));
    PetscCall(VecGetOwnershipRange(v, &vstart, &vend));
    PetscCall(DMRestoreGlobalVector(b->dm, &v));
    PetscCall(DMGetGlobalVector(b->dm_s, &v));
    PetscCall(VecGetOwnershipRange(v, &rstart, NULL));
    PetscCall(DMRestoreGlobalVector(b->dm_s, &v));
  }
  PetscCall(PetscCalloc2(b->ns_local, &dnz, b->ns_local, &onz));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    PetscInt nd = 0, no = 0;
    for (PetscInt i = 0; i < b->nb_v; i++) {
      const PetscInt g = b->cell_vdofs[c * b->nb_v + i];
      if (g < 0) continue;
      if (g >= vstart && g < vend) nd++;
      else no++;
    }
    for (PetscInt j = 0; j < b->nb_s; j++) {
      dnz[b->cell_soff[c] - rstart + j] = nd;
      onz[b->cell_soff[c] - rstart + j] = no;
    }
  }
  PetscCall(MatCreateAIJ(b->comm, b->ns_local, b->nv_local, b->ns_global, b->nv_global, 0, dnz, 0, onz, G));
  PetscCall(MatSetOption(*G, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscFree2(dnz, onz));
  PetscFunctionReturn(0);
}

/* Non-dimensional affine geometry of every local cell: detJ, invJ (x scaled by the reference length). */
static PetscErrorCode SetUpCellGeometry(PhlexBody b, const PhlexUnits *u)
{
  PetscReal v0[3], J[9], invJ[9], detJ;
  PetscReal vol = 0, mass = 0, mx[3] = {0, 0, 0}, buf[5], gbuf[5];

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(10 * (b->cEnd - b->cStart), &b->cell_geom));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscReal *g = &b->cell_geom[10 * (c - b->cStart)];
    PetscReal  rho = b->materials[b->cell_material[c - b->cStart]].density, xc[3];
    PetscCall(DMPlexComputeCellGeometryAffineFEM(b->dm, c, v0, J, invJ, &detJ));
    g[0] = detJ / (u->length * u->length * u->length);
    for (PetscInt i = 0; i < 9; i++) g[1 + i] = invJ[i] * u->length;
    /* reference tet volume 4/3, centroid at xi = -1/2 in each direction: x = v0 + J (xi + 1) */
    for (PetscInt a = 0; a < 3; a++) xc[a] = v0[a] + 0.5 * (J[3 * a] + J[3 * a + 1] + J[3 * a + 2]);
    vol += detJ * 4.0 / 3.0;
    mass += rho * detJ * 4.0 / 3.0;
    for (PetscInt a = 0; a < 3; a++) mx[a] += rho * detJ * 4.0 / 3.0 * xc[a];
  }
  buf[0] = vol;
  buf[1] = mass;
  for (PetscInt a = 0; a < 3; a++) buf[2 + a] = mx[a];
  PetscCall(MPIU_Allreduce(buf, gbuf, 5, MPIU_REAL, MPI_SUM, b->comm));
  b->volume = gbuf[0];
  b->mass   = gbuf[1];
  for (PetscInt a = 0; a < 3; a++) b->center_of_mass[a] = gbuf[2 + a] / b->mass;
  PetscFunctionReturn(0);
}

/* Element loop assembling the velocity operators Mv, K and the body-force vectors (non-dimensional, once). */
static PetscErrorCode AssembleVelocityOperators(PhlexBody b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, nn = nv / 3;
  PetscReal                            *Me, *Ke, fe[PHLEX_MAX_NODES];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(CreateVelocityMatrix(b, &b->Mv));
  PetscCall(CreateVelocityMatrix(b, &b->K));
  for (PetscInt c = 0; c < 3; c++) {
    PetscCall(DMCreateGlobalVector(b->dm, &b->fvol[c]));
    PetscCall(VecSet(b->fvol[c], 0.0));
  }
  PetscCall(PetscMalloc2(nv * nv, &Me, nv * nv, &Ke));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscInt      *idx = &b->cell_vdofs[c * nv];
    PetscInt             nodes[PHLEX_MAX_NODES];

    PhlexElementMass(R, mat->density / u->density, g[0], Me);
    PhlexElementStiffness(R, mat->youngs_modulus / u->modulus, mat->poissons_ratio, g[0], &g[1], Ke);
    PhlexElementLoad(R, g[0], fe);
    CellNodeIndices(b, c, nodes);
    PetscCall(MatSetValuesBlocked(b->Mv, nn, nodes, nn, nodes, Me, ADD_VALUES));
    PetscCall(MatSetValuesBlocked(b->K, nn, nodes, nn, nodes, Ke, ADD_VALUES));
    for (PetscInt a = 0; a < nv; a++)
      if (idx[a] >= 0) PetscCall(VecSetValue(b->fvol[a % 3], idx[a], fe[a / 3], ADD_VALUES));
  }
  PetscCall(PetscFree2(Me, Ke));
  PetscCall(MatAssemblyBegin(b->Mv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Mv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->K, MAT_FINAL_ASSEMBLY));
  for (PetscInt c = 0; c < 3; c++) {
    PetscCall(VecAssemblyBegin(b->fvol[c]));
    PetscCall(VecAssemblyEnd(b->fvol[c]));
  }
  PetscCall(MatSetOption(b->Mv, MAT_SPD, PETSC_TRUE));
  PetscCall(PetscObjectSetName((PetscObject)b->Mv, "velocity mass"));
  PetscCall(PetscObjectSetName((PetscObject)b->K, "stiffness"));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodySetUpMixed - assembles the stress operators (compliance mass Ms, coupling G) needed by the time
  integration of the mixed system; modal analyses use the condensed velocity operators only and skip them

  Collective
@*/
PetscErrorCode PhlexBodySetUpMixed(PhlexBody b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, ns = b->nb_s;
  PetscReal                            *Ge, *Mse, *work, A[36];
  PetscInt                              perm[3 * PHLEX_MAX_NODES], sidx[3 * PHLEX_MAX_NODES];

  PetscFunctionBeginUser;
  if (b->G) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(CreateCouplingMatrix(b, &b->G));
  PetscCall(MatCreateBAIJ(b->comm, ns, b->ns_local, b->ns_local, b->ns_global, b->ns_global, 1, NULL, 0, NULL, &b->Ms));
  PetscCall(MatSetOption(b->Ms, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscMalloc3(ns * nv, &Ge, ns * ns, &Mse, ns * nv, &work));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscInt      *idx = &b->cell_vdofs[c * nv];
    PetscInt             rows[6 * 4], brow = b->cell_soff[c] / ns;

    PhlexElementCoupling(R, g[0], &g[1], work, Ge);
    PhlexElementCompliance(mat->youngs_modulus / u->modulus, mat->poissons_ratio, A);
    PhlexElementComplianceMass(R, g[0], A, Mse);
    /* G rows belong to this cell only: inserting sorted columns appends to empty rows */
    for (PetscInt a = 0; a < nv; a++) {
      perm[a] = a;
      sidx[a] = idx[a];
    }
    PetscCall(PetscSortIntWithArray(nv, sidx, perm));
    for (PetscInt j = 0; j < ns; j++) {
      rows[j] = b->cell_soff[c] + j;
      for (PetscInt a = 0; a < nv; a++) work[j * nv + a] = Ge[j * nv + perm[a]];
    }
    PetscCall(MatSetValues(b->G, ns, rows, nv, sidx, work, INSERT_VALUES));
    PetscCall(MatSetValuesBlocked(b->Ms, 1, &brow, 1, &brow, Mse, INSERT_VALUES));
  }
  PetscCall(PetscFree3(Ge, Mse, work));
  PetscCall(MatAssemblyBegin(b->G, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->G, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)b->G, "coupling"));
  PetscCall(PetscObjectSetName((PetscObject)b->Ms, "compliance mass"));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* -phlex_check_condensation: the exact element-wise elimination G^T Ms^{-1} G against the stiffness used, on every
   local cell; prints the largest relative difference (DESIGN section 2: equal for constant material on affine cells). */
static PetscErrorCode CheckCondensation(PhlexBody b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, ns = b->nb_s;
  PetscReal                            *Ge, *Mse, *Ke, *Kc, *work, A[36], worst = 0, gworst;
  PetscBool                             check = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-phlex_check_condensation", &check, NULL));
  if (!check) PetscFunctionReturn(0);
  PetscCall(PetscMalloc5(ns * nv, &Ge, ns * ns, &Mse, nv * nv, &Ke, nv * nv, &Kc, ns * nv, &work));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscReal      E = mat->youngs_modulus / u->modulus, nu = mat->poissons_ratio;
    PetscReal            dn = 0, kn = 0;
    PhlexElementStiffness(R, E, nu, g[0], &g[1], Ke);
    PhlexElementCoupling(R, g[0], &g[1], work, Ge);
    PhlexElementCompliance(E, nu, A);
    PhlexElementComplianceMass(R, g[0], A, Mse);
    PetscCheck(!PhlexElementCondense(ns, nv, Mse, Ge, work, Kc), PETSC_COMM_SELF, PETSC_ERR_PLIB, "compliance mass of cell %" PetscInt_FMT " not positive definite", c);
    for (PetscInt i = 0; i < nv * nv; i++) {
      dn += PetscSqr(Kc[i] - Ke[i]);
      kn += PetscSqr(Ke[i]);
    }
    worst = PetscMax(worst, PetscSqrtReal(dn / kn));
  }
  PetscCall(PetscFree5(Ge, Mse, Ke, Kc, work));
  PetscCallMPI(MPI_Allreduce(&worst, &gworst, 1, MPIU_REAL, MPI_MAX, b->comm));
  PetscCall(PetscPrintf(b->comm, "body %s: element stress elimination G^T Ms^-1 G vs stiffness: max relative difference %s\n", b->name, gworst < 1e-13 ? "< 1e-13" : "LARGE"));
  PetscCheck(gworst < 1e-13, b->comm, PETSC_ERR_PLIB, "body %s: element stress elimination differs from the stiffness by %g", b->name, (double)gworst);
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodySetUp - reads and checks the mesh, builds the spaces and assembles the constant operators

  Collective

  Input Parameters:
+ b     - the body
- units - reference scales of the non-dimensionalisation
@*/
PetscErrorCode PhlexBodySetUp(PhlexBody b, const PhlexUnits *units)
{
  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodySetUp, 0, 0, 0, 0));
  if (!b->dm) {
    PetscCall(PhlexMeshLoad(b));
    PetscCall(PhlexMeshCheckGeometry(b, units));
  }
  PetscCall(SetUpSpaces(b));
  PetscCall(SetUpMaterials(b));
  PetscCall(SetUpCellGeometry(b, units));
  PetscCall(SetUpCellDofs(b));
  {
    PhlexElementBasis V, S;
    PetscCall(PhlexBodyGetBasis(b, PETSC_FALSE, &V));
    PetscCall(PhlexBodyGetBasis(b, PETSC_TRUE, &S));
    PhlexElementReference(&V, &S, &b->ref);
    PetscCall(PhlexBodyRestoreBasis(&V));
    PetscCall(PhlexBodyRestoreBasis(&S));
  }
  PetscCall(AssembleVelocityOperators(b, units));
  PetscCall(CheckCondensation(b, units));
  if (b->floating) {
    for (PetscInt d = 0; d < 3; d++) {
      b->origin[d] = b->frame_centroid[d];
      if (!b->position_given) b->position0[d] = b->origin[d];
    }
    PetscCall(PhlexBodySetUpFloating(b, units));
  }
  for (PetscInt p = 0; p < b->nports; p++) PetscCall(PhlexPortSetUp(b, &b->ports[p], units));
  PetscCall(PetscLogEventEnd(PHLEX_BodySetUp, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyEnergy - kinetic and strain energy 1/2 v^T Mv v, 1/2 s^T Ms s (non-dimensional)

  Collective
@*/
PetscErrorCode PhlexBodyEnergy(PhlexBody b, Vec v, Vec s, PetscReal *kinetic, PetscReal *strain)
{
  Vec         wv, ws;
  PetscScalar e;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(v, &wv));
  PetscCall(VecDuplicate(s, &ws));
  PetscCall(MatMult(b->Mv, v, wv));
  PetscCall(VecDot(wv, v, &e));
  *kinetic = 0.5 * PetscRealPart(e);
  PetscCall(MatMult(b->Ms, s, ws));
  PetscCall(VecDot(ws, s, &e));
  *strain = 0.5 * PetscRealPart(e);
  PetscCall(VecDestroy(&wv));
  PetscCall(VecDestroy(&ws));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyLoadVector - the non-dimensional load b(t) = B u(t) of the port wrenches and the body force

  Collective
@*/
PetscErrorCode PhlexBodyLoadVector(PhlexBody b, PetscReal t, const PhlexUnits *units, Vec load)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(load, 0.0));
  for (PetscInt p = 0; p < b->nports; p++) {
    PetscReal u[6];
    if (!b->ports[p].loaded) continue;
    PetscCall(PhlexPortInput(&b->ports[p], t, units, u));
    for (PetscInt k = 0; k < 6; k++)
      if (u[k] != 0.0) PetscCall(VecAXPY(load, u[k], b->ports[p].dist[k]));
  }
  if (b->has_body_force) {
    PetscReal f;
    PetscCall(PhlexProfileEvaluate(b->body_force_profile, t, &f));
    /* force density scale: force / length^3 = E_ref / L */
    for (PetscInt c = 0; c < 3; c++)
      if (b->body_force[c] != 0.0) PetscCall(VecAXPY(load, f * b->body_force[c] * units->length / units->modulus, b->fvol[c]));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyPortOutputs - the collocated outputs y = B^T v of every port (non-dimensional): patch-average velocity
  and patch-average angular velocity

  Collective
@*/
PetscErrorCode PhlexBodyPortOutputs(PhlexBody b, Vec v, PetscReal y[][6])
{
  PetscFunctionBeginUser;
  for (PetscInt p = 0; p < b->nports; p++) {
    PetscScalar d[6];
    PetscCall(VecMDot(v, 6, b->ports[p].dist, d));
    for (PetscInt k = 0; k < 6; k++) y[p][k] = PetscRealPart(d[k]);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyView - prints a summary of the body
@*/
PetscErrorCode PhlexBodyView(PhlexBody b, PetscViewer viewer)
{
  PetscInt ncells, gcells;

  PetscFunctionBeginUser;
  ncells = b->cEnd - b->cStart;
  PetscCallMPI(MPI_Allreduce(&ncells, &gcells, 1, MPIU_INT, MPI_SUM, b->comm));
  PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: mesh %s, %" PetscInt_FMT " tetrahedra, velocity P%" PetscInt_FMT " (%" PetscInt_FMT " dofs), stress P%" PetscInt_FMT " discontinuous (%" PetscInt_FMT " dofs)\n", b->name, b->mesh_file, gcells, b->degree, b->nv_global, b->degree - 1, b->ns_global));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(PetscViewerASCIIPrintf(viewer, "volume %.6g m^3, mass %.6g kg, centre of mass (%.6g, %.6g, %.6g) m\n", (double)b->volume, (double)b->mass, (double)b->center_of_mass[0], (double)b->center_of_mass[1], (double)b->center_of_mass[2]));
  if (b->floating) {
    PetscReal q[4];
    PetscCall(PetscViewerASCIIPrintf(viewer, "floating frame on patch %s (origin P at (%.6g, %.6g, %.6g) m), %s inertia\n", b->frame_patch, (double)b->origin[0], (double)b->origin[1], (double)b->origin[2], b->frozen_inertia ? "frozen (u_f = 0)" : "full"));
    PhlexRotationToQuaternion(b->rotation0, q);
    PetscCall(PetscViewerASCIIPrintf(viewer, "initial r_P (%.6g, %.6g, %.6g) m, orientation quaternion (%.6g, %.6g, %.6g, %.6g), v_P (%.6g, %.6g, %.6g) m/s, w_P (%.6g, %.6g, %.6g) rad/s (body frame)\n", (double)b->position0[0], (double)b->position0[1], (double)b->position0[2], (double)q[0], (double)q[1], (double)q[2], (double)q[3], (double)b->velocity0[0], (double)b->velocity0[1], (double)b->velocity0[2], (double)b->omega0[0], (double)b->omega0[1], (double)b->omega0[2]));
    if (b->frame_loaded) {
      char prof[256];
      PetscCall(PhlexProfileDescribe(b->frame_profile, prof, sizeof(prof)));
      PetscCall(PetscViewerASCIIPrintf(viewer, "frame wrench at P: force (%g, %g, %g) N, moment (%g, %g, %g) N m (body frame), profile %s\n", (double)b->frame_force[0], (double)b->frame_force[1], (double)b->frame_force[2], (double)b->frame_moment[0], (double)b->frame_moment[1], (double)b->frame_moment[2], prof));
    }
  } else if (b->frame_patch[0]) PetscCall(PetscViewerASCIIPrintf(viewer, "clamped patch (frame patch): %s\n", b->frame_patch));
  else PetscCall(PetscViewerASCIIPrintf(viewer, "no clamped patch: free body\n"));
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    const PhlexMaterial *mat = &b->materials[m];
    PetscCall(PetscViewerASCIIPrintf(viewer, "material %s: E = %g Pa, nu = %g, rho = %g kg/m^3\n", mat->region[0] ? mat->region : "(whole body)", (double)mat->youngs_modulus, (double)mat->poissons_ratio, (double)mat->density));
  }
  for (PetscInt p = 0; p < b->nports; p++) {
    const PhlexPort port = &b->ports[p];
    char            load[512] = "";
    if (port->loaded) {
      char prof[256];
      PetscCall(PhlexProfileDescribe(port->profile, prof, sizeof(prof)));
      PetscCall(PetscSNPrintf(load, sizeof(load), ", force (%g, %g, %g) N, moment (%g, %g, %g) N m, profile %s", (double)port->force[0], (double)port->force[1], (double)port->force[2], (double)port->moment[0], (double)port->moment[1], (double)port->moment[2], prof));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "port %s: area %.6g m^2, centroid (%.6g, %.6g, %.6g) m%s\n", port->name, (double)port->area, (double)port->centroid[0], (double)port->centroid[1], (double)port->centroid[2], load));
  }
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyDestroy - destroys a body
@*/
PetscErrorCode PhlexBodyDestroy(PhlexBody *body)
{
  PhlexBody b = *body;

  PetscFunctionBeginUser;
  if (!b) PetscFunctionReturn(0);
  for (PetscInt p = 0; p < b->nports; p++) PetscCall(PhlexPortDestroy(&b->ports[p]));
  PetscCall(PhlexProfileDestroy(&b->body_force_profile));
  PetscCall(PhlexProfileDestroy(&b->frame_profile));
  PetscCall(VecDestroy(&b->tnode));
  PetscCall(VecDestroy(&b->wnode));
  PetscCall(VecDestroy(&b->vnode));
  PetscCall(MatDestroy(&b->Mv));
  PetscCall(MatDestroy(&b->K));
  PetscCall(MatDestroy(&b->G));
  PetscCall(MatDestroy(&b->Ms));
  for (PetscInt c = 0; c < 3; c++) PetscCall(VecDestroy(&b->fvol[c]));
  PetscCall(PetscFEDestroy(&b->fe_v));
  PetscCall(PetscFEDestroy(&b->fe_s));
  PetscCall(DMDestroy(&b->dm_s));
  PetscCall(DMDestroy(&b->dm));
  PetscCall(PetscFree(b->cell_material));
  PetscCall(PetscFree2(b->cell_vdofs, b->cell_soff));
  PetscCall(PetscFree(b->cell_geom));
  PetscCall(PetscFree(b->groups));
  PetscCall(PetscFree(*body));
  PetscFunctionReturn(0);
}
