/* Initial state of a flexible body: velocity and displacement fields (analytic, a beam mode, a computed mode), the
   stress of the initial displacement, the frame of a floating body. A rigid velocity field given to a floating body
   is the frame's velocity; with mean axes the rigid content of any initial elastic field moves to the frame. */
#include <phlex_impl.h>

typedef struct {
  const PhlexIC *ic;
  PetscReal      scale; /* SI -> non-dimensional */
  PetscReal      axis[3], origin[3], length, beta, sigma, tip;
} ICContext;

/*@C
  PhlexFlexibleICSetFromOptions - reads the initial condition of a field (prefix body<k>_ic_<field>_)
@*/
PetscErrorCode PhlexFlexibleICSetFromOptions(PhlexFlexible b, PhlexIC *ic, const char field[], PetscInt ncomp)
{
  char      prefix[128], who[PHLEX_NAME_LEN + 8];
  PetscBool given = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sic_%s_", b->prefix, field));
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", b->name));
  PetscOptionsBegin(b->comm, prefix, "Initial condition options", NULL);
  if (ncomp == 6) {
    /* the stress: zero or uniform (a mode's stress follows from the displacement's mode) */
    const char *const stress_types[] = {"zero", "uniform"};
    PetscInt          t              = ic->type == PHLEX_IC_UNIFORM ? 1 : 0;
    PetscBool         set            = PETSC_FALSE;
    PetscCall(PetscOptionsEList("-type", "Initial stress: zero or uniform (-value); a mode's stress follows from -ic_displacement_type mode", "PhlexFlexibleICSetFromOptions", stress_types, 2, stress_types[t], &t, &set));
    if (set) ic->type = t ? PHLEX_IC_UNIFORM : PHLEX_IC_ZERO;
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-value", "uniform: stress components xx,yy,zz,xy,yz,xz [Pa] (the order of the output fields)", "PhlexFlexibleICSetFromOptions", ncomp, ic->value, &given));
  } else {
    const PetscBool velocity = strcmp(field, "velocity") ? PETSC_FALSE : PETSC_TRUE;
    PetscCall(PetscOptionsEnum("-type", velocity ? "Initial velocity: zero, uniform (-value), rigid (v + w x (x - origin): -value, -angular, -origin), beam (Euler-Bernoulli cantilever mode: -mode, -amplitude, -direction), mode (computed elastic mode: -mode, -amplitude)" : "Initial displacement: zero, uniform (-value), rigid (u + w x (x - origin), w a small rotation: -value, -angular, -origin), beam (Euler-Bernoulli cantilever mode: -mode, -amplitude, -direction), mode (computed elastic mode: -mode, -amplitude)", "PhlexFlexibleICSetFromOptions", PhlexICTypes, (PetscEnum)ic->type, (PetscEnum *)&ic->type, NULL));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-value", velocity ? "uniform/rigid: velocity [m/s]" : "uniform/rigid: displacement [m]", "PhlexFlexibleICSetFromOptions", ncomp, ic->value, &given));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-angular", velocity ? "rigid: angular velocity [rad/s]" : "rigid: small rotation vector [rad]", "PhlexFlexibleICSetFromOptions", 3, ic->angular, NULL));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-origin", "rigid: point of the rotation axis [m]", "PhlexFlexibleICSetFromOptions", 3, ic->origin, NULL));
    PetscCall(PetscOptionsInt("-mode", "beam/mode: mode number (1 = lowest)", "PhlexFlexibleICSetFromOptions", ic->mode, &ic->mode, NULL));
    PetscCall(PetscOptionsReal("-amplitude", velocity ? "beam/mode: largest value of the field [m/s]" : "beam/mode: largest value of the field [m]", "PhlexFlexibleICSetFromOptions", ic->amplitude, &ic->amplitude, NULL));
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, b->comm, who, prefix, "-direction", "beam: deflection direction", "PhlexFlexibleICSetFromOptions", 3, ic->direction, NULL));
  }
  PetscOptionsEnd();
  if (ncomp == 6 && given) {
    /* one order for users, on input and output (ParaView's for symmetric tensors): xx,yy,zz,xy,yz,xz; stored in the
       Voigt order of the stress unknowns, xx,yy,zz,yz,xz,xy */
    const PetscReal xy = ic->value[3], yz = ic->value[4], xz = ic->value[5];
    ic->value[PHLEX_S_YZ] = yz;
    ic->value[PHLEX_S_XZ] = xz;
    ic->value[PHLEX_S_XY] = xy;
  }
  PetscCheck(ic->mode >= 1, b->comm, PETSC_ERR_USER_INPUT, "body %s: option -%smode must be >= 1, got %" PetscInt_FMT, b->name, prefix, ic->mode);
  PetscCheck(ncomp == 3 || (ic->type != PHLEX_IC_RIGID && ic->type != PHLEX_IC_BEAM), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%stype %s is not available for the stress", b->name, prefix, PhlexICTypes[ic->type]);
  PetscFunctionReturn(0);
}

/* Euler-Bernoulli cantilever mode n along the body axis from the clamped patch */
static PetscReal BeamShape(const ICContext *c, PetscReal s)
{
  const PetscReal bx = c->beta * s;
  return PetscCoshReal(bx) - PetscCosReal(bx) - c->sigma * (PetscSinhReal(bx) - PetscSinReal(bx));
}

static PetscErrorCode ICFunction(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  const ICContext *c  = (const ICContext *)ctx;
  const PhlexIC   *ic = c->ic;

  switch (ic->type) {
  case PHLEX_IC_UNIFORM:
    for (PetscInt d = 0; d < 3; d++) u[d] = c->scale * ic->value[d];
    break;
  case PHLEX_IC_RIGID: {
    const PetscReal r[3] = {x[0] - ic->origin[0], x[1] - ic->origin[1], x[2] - ic->origin[2]};
    const PetscReal *w   = ic->angular;
    u[0]                 = c->scale * (ic->value[0] + w[1] * r[2] - w[2] * r[1]);
    u[1]                 = c->scale * (ic->value[1] + w[2] * r[0] - w[0] * r[2]);
    u[2]                 = c->scale * (ic->value[2] + w[0] * r[1] - w[1] * r[0]);
  } break;
  case PHLEX_IC_BEAM: {
    PetscReal s = 0, f;
    for (PetscInt d = 0; d < 3; d++) s += (x[d] - c->origin[d]) * c->axis[d];
    s = PetscMin(PetscMax(s / c->length, 0.0), 1.0);
    f = BeamShape(c, s) / c->tip;
    for (PetscInt d = 0; d < 3; d++) u[d] = c->scale * ic->amplitude * f * ic->direction[d];
  } break;
  default:
    for (PetscInt d = 0; d < 3; d++) u[d] = 0.0;
  }
  return 0;
}

/* a mode initial condition's eigenvector (as the eigensolver gives it) and its rigid-motion row (floating body) */
static PetscErrorCode ModeField(PhlexPart part, const PhlexIC *ic, const char field[], Vec *mode, PetscReal rigid[6])
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscInt      nconv, nrigid;
  PetscReal    *lambda, *q;
  Vec          *vecs;

  PetscFunctionBeginUser;
  {
    char option[96];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sic_%s_mode", b->prefix, field));
    PetscCall(PhlexFlexibleModesRequestCheck(part, ic->mode, option, ic->mode));
  }
  PetscCall(PhlexFlexibleComputeModes(part, ic->mode, &nconv, &nrigid, &lambda, &vecs, &q, NULL));
  PetscCheck(nconv >= nrigid + ic->mode, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: elastic mode %" PetscInt_FMT " for -%sic_%s_mode was not found (%" PetscInt_FMT " converged)", b->name, ic->mode, b->prefix, field, nconv - nrigid);
  PetscCall(VecDuplicate(vecs[nrigid + ic->mode - 1], mode));
  PetscCall(VecCopy(vecs[nrigid + ic->mode - 1], *mode));
  for (PetscInt k = 0; k < 6; k++) rigid[k] = q[6 * (nrigid + ic->mode - 1) + k];
  for (PetscInt i = 0; i < nconv; i++) PetscCall(VecDestroy(&vecs[i]));
  PetscCall(PetscFree(vecs));
  PetscCall(PetscFree(q));
  PetscCall(PetscFree(lambda));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePrepareInitialState - the eigensolves of mode initial conditions, before the system builds its
  operators: the eigensolver's factorization then does not come on top of them (at 2.2e5 velocity DOFs the
  cantilever's first-mode start peaked at 3.5 GB against 2.9 GB for an analytic start); PhlexFlexibleInitialState
  takes the fields

  Collective
@*/
PetscErrorCode PhlexFlexiblePrepareInitialState(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (b->ic_velocity.type == PHLEX_IC_MODE && !b->ic_mode[0]) PetscCall(ModeField(part, &b->ic_velocity, "velocity", &b->ic_mode[0], b->ic_mode_rigid[0]));
  if (b->ic_displacement.type == PHLEX_IC_MODE && !b->ic_mode[1]) PetscCall(ModeField(part, &b->ic_displacement, "displacement", &b->ic_mode[1], b->ic_mode_rigid[1]));
  PetscFunctionReturn(0);
}

/* An initial field of the velocity space (velocity or displacement), non-dimensional. */
static PetscErrorCode SetKinematicIC(PhlexPart part, const PhlexIC *ic, const char field[], PetscReal scale, Vec x, PetscReal rigid[6])
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  ICContext c;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&c, sizeof(c)));
  c.ic    = ic;
  c.scale = scale;
  switch (ic->type) {
  case PHLEX_IC_ZERO:
    PetscCall(VecSet(x, 0.0));
    break;
  case PHLEX_IC_BEAM: {
    /* axis: longest bounding-box direction, from the clamped patch's side */
    const PetscReal betas[4] = {1.875104069, 4.694091133, 7.854757438, 10.99554073};
    PetscInt        axis     = 0;
    PetscReal       nd       = 0;
    PetscCheck(b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_%s_type beam needs a clamped patch (-%sframe_patch)", b->name, b->prefix, field, b->prefix);
    for (PetscInt d = 0; d < 3; d++)
      if (b->bbox_max[d] - b->bbox_min[d] > b->bbox_max[axis] - b->bbox_min[axis]) axis = d;
    for (PetscInt d = 0; d < 3; d++) nd += PetscSqr(ic->direction[d]);
    PetscCheck(nd > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_%s_direction must be a nonzero vector", b->name, b->prefix, field);
    c.length = b->bbox_max[axis] - b->bbox_min[axis];
    c.beta   = ic->mode <= 4 ? betas[ic->mode - 1] : (2 * ic->mode - 1) * PETSC_PI / 2;
    c.sigma  = (PetscCoshReal(c.beta) + PetscCosReal(c.beta)) / (PetscSinhReal(c.beta) + PetscSinReal(c.beta));
    c.tip    = BeamShape(&c, 1.0);
    /* from the clamped end: the side of the bounding box nearest to the patch centroid */
    for (PetscInt d = 0; d < 3; d++) c.origin[d] = b->frame_centroid[d];
    c.axis[axis] = (b->frame_centroid[axis] - b->bbox_min[axis] <= b->bbox_max[axis] - b->frame_centroid[axis]) ? 1.0 : -1.0;
    {
      PhlexIC icn = *ic;
      for (PetscInt d = 0; d < 3; d++) icn.direction[d] = ic->direction[d] / PetscSqrtReal(nd);
      c.ic = &icn;
      {
        PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ICFunction};
        void *ctxs[1] = {&c};
        PetscCall(DMProjectFunction(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, x));
      }
    }
  } break;
  case PHLEX_IC_MODE: {
    const PetscInt which = ic == &b->ic_velocity ? 0 : 1;
    PetscReal      vmax, vmin, f;
    /* computed before the system's operators (PhlexFlexiblePrepareInitialState), or now */
    if (!b->ic_mode[which]) PetscCall(ModeField(part, ic, field, &b->ic_mode[which], b->ic_mode_rigid[which]));
    PetscCall(VecCopy(b->ic_mode[which], x));
    PetscCall(VecDestroy(&b->ic_mode[which]));
    PetscCall(VecMax(x, NULL, &vmax));
    PetscCall(VecMin(x, NULL, &vmin));
    /* largest component positive, largest magnitude = amplitude: the same field on any number of ranks */
    f = (vmax >= -vmin ? 1.0 / vmax : 1.0 / vmin) * ic->amplitude * scale;
    PetscCall(VecScale(x, f));
    /* a floating body's mode carries the rigid motion that keeps its momenta zero */
    if (rigid)
      for (PetscInt k = 0; k < 6; k++) rigid[k] = b->floating ? f * b->ic_mode_rigid[which][k] : 0.0;
  } break;
  default: {
    PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ICFunction};
    void *ctxs[1] = {&c};
    PetscCall(DMProjectFunction(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, x));
  } break;
  }
  PetscFunctionReturn(0);
}

/* Sigma_0 = Ms^{-1} G u_0 (the stress of the initial displacement, exact element by element; with geometric stiffening
   that of its Green-Lagrange strain) + a uniform stress */
static PetscErrorCode SetStressIC(PhlexPart part, Vec u0, Vec s0)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  PetscReal         unorm;

  PetscFunctionBeginUser;
  PetscCall(VecSet(s0, 0.0));
  PetscCall(VecNorm(u0, NORM_INFINITY, &unorm));
  if (unorm > 0 && b->stiffening) {
    /* the Green-Lagrange strain's stress, Ms Sigma_0 = int psi : E(u_0) (flexible_stiffening.c) */
    PetscCall(PhlexFlexibleStressOfDisplacement(b, u0, s0));
  } else if (unorm > 0) {
    KSP ksp;
    PC  pc;
    Vec g;
    PetscCall(PhlexFlexibleSetUpMixed(b, part->units)); /* deferred at set-up (FlexFieldOperators); freed with the release */
    PetscCall(VecDuplicate(s0, &g));
    PetscCall(MatMult(b->G, u0, g));
    PetscCall(KSPCreate(b->comm, &ksp));
    PetscCall(KSPSetOperators(ksp, b->Ms, b->Ms));
    PetscCall(KSPSetType(ksp, KSPPREONLY));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCSetType(pc, PCPBJACOBI));
    PetscCall(KSPSolve(ksp, g, s0));
    PetscCall(KSPDestroy(&ksp));
    PetscCall(VecDestroy(&g));
  }
  if (b->ic_stress.type == PHLEX_IC_UNIFORM) {
    PetscScalar *a;
    PetscInt     n;
    /* node-major stress dofs: component i % 6; a uniform field has the same value at every node */
    PetscCall(VecGetLocalSize(s0, &n));
    PetscCall(VecGetArray(s0, &a));
    for (PetscInt i = 0; i < n; i++) a[i] += b->ic_stress.value[i % 6] / part->units->modulus;
    PetscCall(VecRestoreArray(s0, &a));
  } else PetscCheck(b->ic_stress.type == PHLEX_IC_ZERO, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_stress_type must be zero or uniform (a mode's stress follows from -%sic_displacement_type mode)", b->name, b->prefix, b->prefix);
  PetscFunctionReturn(0);
}

/* a rigid velocity (or displacement) field a_v + a_w x (x - P) on the body's velocity space (non-dimensional) */
static PetscErrorCode RigidField(PhlexFlexible b, const PetscReal a[6], PetscReal length, Vec x)
{
  PhlexIC   ic;
  ICContext c;
  PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ICFunction};
  void *ctxs[1] = {&c};

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&ic, sizeof(ic)));
  PetscCall(PetscMemzero(&c, sizeof(c)));
  ic.type = PHLEX_IC_RIGID;
  for (PetscInt k = 0; k < 3; k++) {
    ic.value[k]   = a[k];
    ic.angular[k] = a[3 + k] / length; /* the mesh is in metres */
    ic.origin[k]  = b->origin[k];
  }
  c.ic    = &ic;
  c.scale = 1.0;
  PetscCall(DMProjectFunction(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, x));
  PetscFunctionReturn(0);
}

/* mean axes: the rigid content a (a_v, a_w, non-dimensional) of a field x, M6 a = [int rho x; int rho (x - P) x x],
   removed from x */
static PetscErrorCode RemoveRigidContent(PhlexPart part, Vec x, PetscReal a[6])
{
  PhlexFlexible      b = (PhlexFlexible)part->data;
  const PetscScalar *ta, *wa, *xa;
  PetscReal          loc[6] = {0, 0, 0, 0, 0, 0}, M[36];
  PetscBLASInt       n6 = 6, one = 1, piv[6], info;
  PetscInt           n;
  Vec                r;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(x, &n));
  PetscCall(VecGetArrayRead(b->tnode, &ta));
  PetscCall(VecGetArrayRead(b->wnode, &wa));
  PetscCall(VecGetArrayRead(x, &xa));
  for (PetscInt l = 0; l < n / 3; l++) {
    PetscReal w[3], v[3], c[3];
    for (PetscInt k = 0; k < 3; k++) {
      w[k] = PetscRealPart(wa[3 * l + k]);
      v[k] = PetscRealPart(xa[3 * l + k]);
      loc[k] += PetscRealPart(ta[3 * l]) * v[k];
    }
    PhlexCross(w, v, c);
    for (PetscInt k = 0; k < 3; k++) loc[3 + k] += c[k];
  }
  PetscCall(VecRestoreArrayRead(b->tnode, &ta));
  PetscCall(VecRestoreArrayRead(b->wnode, &wa));
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(MPIU_Allreduce(loc, a, 6, MPIU_REAL, MPI_SUM, b->comm));
  PetscCall(PhlexFrameRigidMass(&b->inertia, M));
  /* M is symmetric: its row-major array is its column-major one */
  PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&n6, &one, M, &n6, piv, a, &n6, &info));
  PetscCheck(!info, b->comm, PETSC_ERR_PLIB, "body %s: singular rigid mass matrix", b->name);
  PetscCall(VecDuplicate(x, &r));
  PetscCall(RigidField(b, a, part->units->length, r));
  PetscCall(VecAXPY(x, -1.0, r));
  PetscCall(VecDestroy(&r));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleFrameVelocity - the initial velocity of a floating body's frame (SI, body frame): -velocity and
  -angular_velocity, or the rigid ("rigid", "uniform") initial velocity field mapped to the frame, v_P = value +
  angular x (P - origin), w = angular; returns whether the field was mapped
@*/
PetscBool PhlexFlexibleFrameVelocity(PhlexFlexible b, PetscReal v0[3], PetscReal w0[3])
{
  const PhlexIC *ic = &b->ic_velocity;

  for (PetscInt k = 0; k < 3; k++) {
    v0[k] = b->pose.velocity[k];
    w0[k] = b->pose.omega[k];
  }
  if (!b->floating || !(ic->type == PHLEX_IC_UNIFORM || ic->type == PHLEX_IC_RIGID)) return PETSC_FALSE;
  {
    PetscReal d[3], a[3] = {0, 0, 0};
    for (PetscInt k = 0; k < 3; k++) d[k] = b->origin[k] - ic->origin[k];
    if (ic->type == PHLEX_IC_RIGID) PhlexCross(ic->angular, d, a);
    for (PetscInt k = 0; k < 3; k++) {
      v0[k] = ic->value[k] + a[k];
      w0[k] = ic->type == PHLEX_IC_RIGID ? ic->angular[k] : 0.0;
    }
  }
  return PETSC_TRUE;
}

/*@C
  PhlexFlexibleInitialState - the initial fields of a flexible body and, floating, its frame's state

  Collective

  Notes:
  A floating body's rigid ("rigid", "uniform") initial velocity field is the velocity of its frame: v_P = value +
  angular x (P - origin), w = angular (body frame), and the elastic velocity is zero. With mean axes the rigid
  content of any initial elastic field (a beam shape, say) is moved to the frame: the velocity's to (v_P, w), the
  displacement's to (r_P, R).
@*/
PetscErrorCode PhlexFlexibleInitialState(PhlexPart part, PhlexPartVec *X)
{
  PhlexFlexible     b  = (PhlexFlexible)part->data;
  const PhlexUnits *un = part->units;
  PetscReal         mode_rigid[6] = {0, 0, 0, 0, 0, 0}, av[6] = {0, 0, 0, 0, 0, 0}, au[6] = {0, 0, 0, 0, 0, 0};
  PetscReal         v0[3], w0[3], r0[3], R0[9];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) r0[k] = b->pose.position[k];
  for (PetscInt k = 0; k < 9; k++) R0[k] = b->pose.rotation[k];
  if (PhlexFlexibleFrameVelocity(b, v0, w0)) PetscCall(VecSet(X->v, 0.0));
  else PetscCall(SetKinematicIC(part, &b->ic_velocity, "velocity", 1.0 / un->velocity, X->v, mode_rigid));
  PetscCall(SetKinematicIC(part, &b->ic_displacement, "displacement", 1.0 / un->length, X->u, NULL));
  if (b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES) {
    PetscCall(RemoveRigidContent(part, X->v, av));
    PetscCall(RemoveRigidContent(part, X->u, au));
  }
  PetscCall(SetStressIC(part, X->u, X->s));
  if (b->ic_steady_spin) {
    /* the perturbation about the steady spin, kept as given (PhlexFlexibleSteadySpinStart) */
    PetscCall(VecDestroy(&b->ic_steady_v));
    PetscCall(VecDuplicate(X->v, &b->ic_steady_v));
    PetscCall(VecCopy(X->v, b->ic_steady_v));
  }
  if (b->floating) {
    PetscReal *q = X->q, Ra[3];
    PhlexMatVec3(R0, au, Ra);
    for (PetscInt k = 0; k < 3; k++) {
      q[k]      = r0[k] / un->length + Ra[k];
      q[12 + k] = v0[k] / un->velocity + mode_rigid[k] + av[k];
      q[15 + k] = w0[k] * un->time + mode_rigid[3 + k] + av[3 + k];
    }
    for (PetscInt k = 0; k < 9; k++) q[3 + k] = R0[k];
    PhlexRotationUpdate(q + 3, au + 3);
    for (PetscInt k = 18; k < part->nq; k++) q[k] = 0.0;
  }
  PetscFunctionReturn(0);
}
