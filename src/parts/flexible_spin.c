/* A fixed flexible body on a hub spinning at a constant rate Omega about an axis through a centre c,
   -<body>_spin wx,wy,wz [rad/s], -<body>_spin_center x,y,z [m]: its frame rotates uniformly (a frame whose motion is
   prescribed, as a rotor blade's). In the rotating frame the momentum rows of the field gain the inertia loads of
   that motion (paper eq. mod_momentafl with w = Omega constant, v_P = Omega x (P - c)):

     Mv v' + G^T Sigma + Cor v + Cen (x - c + u) = b,    Cor = Mv (x) 2 hat(Omega),   Cen = Mv (x) hat(Omega)^2

   Cor is skew (Coriolis: gyroscopic, no work), Cen symmetric negative semi-definite (centrifugal: the potential
   V = 1/2 (x - c + u)^T Cen (x - c + u) = -1/2 int rho |Omega x (x - c + u)|^2, taken relative to the drawn
   geometry). H = T + U + V is the Jacobi integral of the rotating frame: conserved without inputs, and the power
   balance holds with the hub's drive doing the work that keeps Omega constant. Its steady state (v = 0, the
   centrifugal stretch u0 and its stress) is what the linearised analysis linearises about (SteadyState below):
   the spin-softening Cen, the Coriolis coupling Cor and, with -<body>_geometric_stiffening, the stiffening of the
   centrifugal tension (flexible_stiffening.c). */
#include <phlex_impl.h>

typedef struct {
  PetscReal c[3], L;
} SpinCentre;

static PetscErrorCode RelativePosition(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  const SpinCentre *s = (const SpinCentre *)ctx;
  for (PetscInt k = 0; k < 3; k++) u[k] = (x[k] - s->c[k]) / s->L;
  return 0;
}

/* Mv (x) B (3 x 3 node-wise block B), on the condensed operator's pattern */
static PetscErrorCode NodeBlockMass(PhlexFlexible b, const PhlexUnits *u, const PetscReal B[9], Mat *A)
{
  const PetscInt nv = b->nb_v / 3, n = b->nb_v;
  PetscReal     *Me;

  PetscFunctionBeginUser;
  PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, A)); /* Sv's pattern (it holds Mv's): same-pattern sums */
  PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  PetscCall(MatZeroEntries(*A));
  PetscCall(PetscMalloc1(n * n, &Me));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal *g   = &b->cell_geom[10 * c];
    const PetscReal  rho = b->materials[b->cell_material[c]].density / u->density;
    const PetscInt  *idx = &b->cell_vdofs[c * n];
    PetscInt         nodes[PHLEX_MAX_NODES];
    for (PetscInt a = 0; a < nv; a++)
      for (PetscInt bb = 0; bb < nv; bb++) {
        const PetscReal m = rho * g[0] * b->ref.mass[a * nv + bb];
        for (PetscInt i = 0; i < 3; i++)
          for (PetscInt j = 0; j < 3; j++) Me[(3 * a + i) * n + 3 * bb + j] = m * B[3 * i + j];
      }
    for (PetscInt a = 0; a < nv; a++) nodes[a] = idx[3 * a] >= 0 ? idx[3 * a] / 3 : -1;
    PetscCall(MatSetValuesBlocked(*A, nv, nodes, nv, nodes, Me, ADD_VALUES));
  }
  PetscCall(PetscFree(Me));
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

/* Cor, Cen and fcen at the current rate from the unit-rate ones (a sweep over the spin rebuilds nothing) */
static PetscErrorCode SpinScale(PhlexFlexible b)
{
  const PetscReal w = PetscSqrtReal(b->spin[0] * b->spin[0] + b->spin[1] * b->spin[1] + b->spin[2] * b->spin[2]);

  PetscFunctionBeginUser;
  PetscCall(MatCopy(b->Cor1, b->Cor, SAME_NONZERO_PATTERN));
  PetscCall(MatScale(b->Cor, w));
  PetscCall(MatCopy(b->Cen1, b->Cen, SAME_NONZERO_PATTERN));
  PetscCall(MatScale(b->Cen, w * w));
  PetscCall(VecAXPBY(b->fcen, w * w, 0.0, b->fcen1));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSpinSetUp - the Coriolis and centrifugal operators of a spinning fixed body and its centrifugal load
  at the drawn geometry (the clamped nodes' positions included: the consistent mass couples them), built once for a
  unit rate about the spin axis and scaled to the rate

  Collective
@*/
PetscErrorCode PhlexFlexibleSpinSetUp(PhlexFlexible b, const PhlexUnits *u)
{
  PetscReal   W[9], W2[9], Om[3];
  SpinCentre  sc;
  Vec               xloc;
  const PetscScalar *xa;
  PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {RelativePosition};
  void *ctxs[1] = {&sc};
  const PetscInt nv = b->nb_v / 3, n = b->nb_v;

  PetscFunctionBeginUser;
  if (!b->spinning || b->Cor) PetscFunctionReturn(0);
  for (PetscInt k = 0; k < 3; k++) Om[k] = b->spin_axis[k] * u->time; /* 1 rad/s about the axis */
  PhlexSkew(Om, W);
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) W2[3 * i + j] = W[3 * i] * W[j] + W[3 * i + 1] * W[3 + j] + W[3 * i + 2] * W[6 + j];
  for (PetscInt k = 0; k < 9; k++) W[k] *= 2.0;
  PetscCall(NodeBlockMass(b, u, W, &b->Cor1));
  PetscCall(NodeBlockMass(b, u, W2, &b->Cen1));
  PetscCall(MatDuplicate(b->Cor1, MAT_COPY_VALUES, &b->Cor));
  PetscCall(MatDuplicate(b->Cen1, MAT_COPY_VALUES, &b->Cen));
  PetscCall(PetscObjectSetName((PetscObject)b->Cor, "Coriolis"));
  PetscCall(PetscObjectSetName((PetscObject)b->Cen, "centrifugal"));
  /* the centrifugal load Cen (x - c), assembled cell by cell with every node's position */
  for (PetscInt k = 0; k < 3; k++) sc.c[k] = b->spin_center[k];
  sc.L = u->length;
  PetscCall(DMCreateLocalVector(b->dm, &xloc));
  PetscCall(DMProjectFunctionLocal(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, xloc));
  PetscCall(VecDuplicate(b->load, &b->fcen1));
  PetscCall(VecSet(b->fcen1, 0.0));
  PetscCall(VecSetOption(b->fcen1, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  PetscCall(VecGetArrayRead(xloc, &xa));
  {
    PetscSection section;
    PetscInt     nidx, *idx;
    PetscCall(DMGetLocalSection(b->dm, &section));
    for (PetscInt c = b->cStart; c < b->cEnd; c++) {
      const PetscReal *g    = &b->cell_geom[10 * (c - b->cStart)];
      const PetscReal  rho  = b->materials[b->cell_material[c - b->cStart]].density / u->density;
      const PetscInt  *gidx = &b->cell_vdofs[(c - b->cStart) * n];
      PetscReal        xe[3 * PHLEX_MAX_NODES], fe[3 * PHLEX_MAX_NODES];
      idx = NULL;
      PetscCall(DMPlexGetClosureIndices(b->dm, section, section, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
      for (PetscInt i = 0; i < n; i++) xe[i] = PetscRealPart(xa[idx[i] >= 0 ? idx[i] : -(idx[i] + 1)]);
      PetscCall(DMPlexRestoreClosureIndices(b->dm, section, section, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
      for (PetscInt a = 0; a < nv; a++)
        for (PetscInt i = 0; i < 3; i++) {
          fe[3 * a + i] = 0.0;
          for (PetscInt bb = 0; bb < nv; bb++) fe[3 * a + i] += rho * g[0] * b->ref.mass[a * nv + bb] * (W2[3 * i] * xe[3 * bb] + W2[3 * i + 1] * xe[3 * bb + 1] + W2[3 * i + 2] * xe[3 * bb + 2]);
        }
      PetscCall(VecSetValues(b->fcen1, n, gidx, fe, ADD_VALUES)); /* negative indices (clamped nodes) are skipped */
    }
  }
  PetscCall(VecAssemblyBegin(b->fcen1));
  PetscCall(VecAssemblyEnd(b->fcen1));
  PetscCall(VecRestoreArrayRead(xloc, &xa));
  PetscCall(VecDestroy(&xloc));
  PetscCall(VecDuplicate(b->fcen1, &b->fcen));
  PetscCall(SpinScale(b));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSpinRate - gets or sets the rate of a body's prescribed spin about its axis [rad/s] (part contract
  analysisops->spinrate: the linearised analysis sweeps it); -1 on get for a body without -spin

  Collective
@*/
PetscErrorCode PhlexFlexibleSpinRate(PhlexPart part, PetscBool set, PetscReal *rate)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (!set) {
    *rate = b->spinning ? PetscSqrtReal(b->spin[0] * b->spin[0] + b->spin[1] * b->spin[1] + b->spin[2] * b->spin[2]) : -1.0;
    PetscFunctionReturn(0);
  }
  PetscCheck(b->spinning, b->comm, PETSC_ERR_USER_INPUT, "body %s has no prescribed spin (-%sspin) whose rate could be set", b->name, b->prefix);
  PetscCheck(PetscIsNormalReal(*rate) || *rate == 0.0, b->comm, PETSC_ERR_USER_INPUT, "body %s: spin rate %g is not a finite number", b->name, (double)*rate);
  for (PetscInt k = 0; k < 3; k++) b->spin[k] = *rate * b->spin_axis[k];
  if (b->Cor) {
    PetscCall(SpinScale(b));
    b->shift = -1.0; /* the fixed body's Jvv (shift Mv + Cor) is rebuilt at the next Jacobian */
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSpinEnergy - the centrifugal potential relative to the drawn geometry, fcen . u + u^T Cen u / 2

  Collective
@*/
PetscErrorCode PhlexFlexibleSpinEnergy(PhlexFlexible b, Vec u, PetscReal *V)
{
  PetscScalar a, c;

  PetscFunctionBeginUser;
  PetscCall(MatMult(b->Cen, u, b->work));
  PetscCall(VecDot(b->work, u, &a));
  PetscCall(VecDot(b->fcen, u, &c));
  *V = 0.5 * PetscRealPart(a) + PetscRealPart(c);
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSpinSteadyState - the steady state of a spinning body in its rotating frame: v = 0 and the
  displacement u0 the centrifugal load stretches it to, with the stress it holds (Ms Sigma = int psi : E(u0)):
  Newton on r(u) = G(u)^T Sigma(u) + Cen u + fcen, with the tangent G(u)^T Ms^{-1} G(u) + K_sigma + Cen (exact:
  dSigma/du = Ms^{-1} G(u)). Linear without geometric stiffening (one step). The solver: prefix <body>_steady_
  (default LU by MUMPS: the tangent is indefinite beyond the spin rate where the linear model's lagwise bending loses
  its stiffness)

  Collective
@*/
PetscErrorCode PhlexFlexibleSpinSteadyState(PhlexPart part, PhlexPartVec *X)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  Mat           T;
  Vec           r, du;
  PetscReal     rn = 0, fn, dn = 0, un = 0, rate;
  PetscInt      it;
  const PetscInt maxit = 30;

  PetscFunctionBeginUser;
  if (!b->spinning) PetscFunctionReturn(0);
  if (!b->steady_ksp) {
    PC   pc;
    char prefix[256];
    PetscCall(KSPCreate(b->comm, &b->steady_ksp));
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%ssteady_", b->prefix));
    PetscCall(KSPSetOptionsPrefix(b->steady_ksp, prefix));
    PetscCall(KSPSetType(b->steady_ksp, KSPPREONLY));
    PetscCall(KSPGetPC(b->steady_ksp, &pc));
    PetscCall(PCSetType(pc, PCLU));
    if (PetscDefined(HAVE_MUMPS)) PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    PetscCall(KSPSetFromOptions(b->steady_ksp));
  }
  PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, &T));
  PetscCall(VecDuplicate(X->u, &r));
  PetscCall(VecDuplicate(X->u, &du));
  PetscCall(VecSet(X->v, 0.0));
  PetscCall(VecNorm(b->fcen, NORM_INFINITY, &fn));
  rate = PetscSqrtReal(b->spin[0] * b->spin[0] + b->spin[1] * b->spin[1] + b->spin[2] * b->spin[2]);
  for (it = 0; it <= maxit; it++) {
    /* the residual at u */
    PetscCall(PhlexFlexibleStressOfDisplacement(b, X->u, X->s));
    if (b->stiffening) PetscCall(PhlexFlexibleStiffeningJacobian(b, X->u, X->s, X->v)); /* G(u), K_sigma, G(u)^T Ms^-1 G(u) */
    PetscCall(MatMultTranspose(b->stiffening ? b->Gu : b->G, X->s, r));
    PetscCall(MatMultAdd(b->Cen, X->u, r, r));
    PetscCall(VecAXPY(r, 1.0, b->fcen));
    PetscCall(VecNorm(r, NORM_INFINITY, &rn));
    PetscCall(PetscInfo(NULL, "body %s: steady spin, Newton iteration %" PetscInt_FMT ": |r| = %g (centrifugal load %g)\n", b->name, it, (double)rn, (double)fn));
    /* converged: the residual at round-off of the load (the balance of the centrifugal load against the stress holds
       to 1e-12 of it), or a Newton correction below 1e-10 of the stretch (quadratic convergence: the next is at
       round-off) */
    if (rn <= 1e-12 * fn || rn == 0.0 || (it > 0 && (!b->stiffening || dn <= 1e-10 * un))) break; /* linear: one step; Newton: the next step would be at round-off */
    PetscCheck(it < maxit, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: the steady state of the spin at %g rad/s (-%sspin) did not converge in %" PetscInt_FMT " Newton iterations (|r| = %g of the centrifugal load %g): the spin rate is beyond the body's stability (it buckles or flies apart)", b->name, (double)rate, b->prefix, maxit, (double)rn, (double)fn);
    /* the tangent */
    PetscCall(MatZeroEntries(T));
    PetscCall(MatAXPY(T, 1.0, b->Kaij, b->kpattern));
    PetscCall(MatAXPY(T, 1.0, b->Cen, SAME_NONZERO_PATTERN));
    if (b->stiffening) PetscCall(MatAXPY(T, 1.0, b->Ksig, b->kpattern));
    PetscCall(KSPSetOperators(b->steady_ksp, T, T));
    PetscCall(KSPSolve(b->steady_ksp, r, du));
    {
      KSPConvergedReason reason;
      PetscCall(KSPGetConvergedReason(b->steady_ksp, &reason));
      PetscCheck(reason >= 0, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: the steady spin's linear solve at %g rad/s failed (%s): the tangent stiffness is singular at this spin rate (a critical speed)", b->name, (double)rate, KSPConvergedReasons[reason]);
    }
    PetscCall(VecAXPY(X->u, -1.0, du));
    PetscCall(VecNorm(du, NORM_INFINITY, &dn));
    PetscCall(VecNorm(X->u, NORM_INFINITY, &un));
  }
  PetscCall(PetscInfo(NULL, "body %s: steady spin reached in %" PetscInt_FMT " Newton iterations\n", b->name, it));
  PetscCall(MatDestroy(&T));
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&du));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexFlexibleSpinDestroy(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&b->Cor));
  PetscCall(MatDestroy(&b->Cen));
  PetscCall(MatDestroy(&b->Cor1));
  PetscCall(MatDestroy(&b->Cen1));
  PetscCall(VecDestroy(&b->fcen));
  PetscCall(VecDestroy(&b->fcen1));
  PetscCall(KSPDestroy(&b->steady_ksp));
  PetscCall(MatDestroy(&b->Kspin));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSteadySpinStart - -<body>_ic_steady_spin: a floating body's transient starts in the steady state of
  its frame's spin, so that it does not carry the start-up transient (part contract analysisops->steadystart)

  Collective

  Notes:
  Called after the consistent start has put the frame's velocities on the joints (a drive's: its first step's stage
  rate, 2 tan(W dt/2)/dt with the implicit midpoint rule, the rate at which the scheme turns the frame). In the body
  frame that motion (v_P, w) is a uniform rotation about the axis through c = P + w x v_P / |w|^2 (a screw motion if
  v_P has a part along w, which loads nothing). With the frame at that constant motion, the field's equations in the
  body frame are those of a fixed body on a hub spinning at w about c (flexible_spin.c's Cor, Cen, fcen; the full
  inertia's node-wise loads Mv (x) [w]^2 (x - P + u) and the transport of the frame's own velocity are the same
  terms), so its steady state is the linearised analysis' one (PhlexFlexibleSpinSteadyState: Newton on
  G(u)^T Sigma(u) + Cen u + fcen = 0): u0 and its stress. The elastic velocity is set back to the one the initial
  condition gave (-ic_velocity_type: the perturbation; zero: the body stays on its steady state), leaving out what
  the start's impulsive projection put there. The spin's operators are built for the Newton and freed after it:
  the floating body's own equations carry the rotation. *done: whether the body asked for it.
@*/
PetscErrorCode PhlexFlexibleSteadySpinStart(PhlexPart part, PhlexPartVec *X, PetscBool *done)
{
  PhlexFlexible     b  = (PhlexFlexible)part->data;
  const PhlexUnits *un = part->units;
  PetscReal         w[3], vP[3], w2 = 0, c[3], rate, umax;

  PetscFunctionBeginUser;
  *done = PETSC_FALSE;
  if (!b->ic_steady_spin) PetscFunctionReturn(0);
  PetscCheck(b->floating && b->ic_steady_v && b->Sv, b->comm, PETSC_ERR_PLIB, "body %s: steady spin start without a floating body's initial state and operators", b->name);
  for (PetscInt k = 0; k < 3; k++) {
    vP[k] = X->q[part->frame.v + k] * un->velocity; /* SI, body frame */
    w[k]  = X->q[part->frame.w + k] / un->time;
    w2 += w[k] * w[k];
  }
  rate = PetscSqrtReal(w2);
  PetscCheck(rate > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_steady_spin, but its frame does not turn at the start (angular velocity 0 after the consistent start): give it -%sangular_velocity or drive the joint that turns it", b->name, b->prefix, b->prefix);
  PhlexCross(w, vP, c);
  for (PetscInt k = 0; k < 3; k++) c[k] = b->origin[k] + c[k] / w2;
  /* the spin's operators about that axis, the Newton, then the body floats again */
  b->spinning = PETSC_TRUE;
  for (PetscInt k = 0; k < 3; k++) {
    b->spin[k]        = w[k];
    b->spin_axis[k]   = w[k] / rate;
    b->spin_center[k] = c[k];
  }
  PetscCall(PhlexFlexibleSpinSetUp(b, un));
  PetscCall(PhlexFlexibleSpinSteadyState(part, X)); /* u0, Sigma(u0), v = 0 */
  PetscCall(PhlexFlexibleSpinDestroy(b));
  b->spinning = PETSC_FALSE;
  for (PetscInt k = 0; k < 3; k++) b->spin[k] = b->spin_axis[k] = b->spin_center[k] = 0.0;
  PetscCall(VecCopy(b->ic_steady_v, X->v));
  PetscCall(VecDestroy(&b->ic_steady_v));
  PetscCall(VecNorm(X->u, NORM_INFINITY, &umax));
  {
    PetscReal a[3], cc[3];
    /* round-off of the projected velocities left out of the printed axis and centre */
    for (PetscInt k = 0; k < 3; k++) {
      a[k]  = PetscAbsReal(w[k]) < 1e-12 * rate ? 0.0 : w[k] / rate;
      cc[k] = PetscAbsReal(c[k]) < 1e-12 * un->length ? 0.0 : c[k];
    }
    PetscCall(PetscPrintf(b->comm, "Steady spin start: body %s in the steady state of its frame's spin, %.10g rad/s about %.6g,%.6g,%.6g (body frame) through %.6g,%.6g,%.6g m (mesh): largest stretch %.6e m\n", b->name, (double)rate, (double)a[0], (double)a[1], (double)a[2], (double)cc[0], (double)cc[1], (double)cc[2], (double)(umax * un->length)));
  }
  *done = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSteadyDrive - the linearised analysis of a rotor (part contract analysisops->steadydrive): a floating
  body held at its frame patch by a revolute to the ground driven at a constant rate moves steadily, a uniform
  rotation w about the joint's axis. In the co-rotating frame (the body's frame) the state is constant: the field's
  equations are those of a fixed body on a hub spinning at w about that axis (Coriolis, centrifugal load and
  softening: flexible_spin.c's operators, in the floating body's residual and Jacobian while it is so marked), and
  the frame is held by the joint's six rows (the drive's among them), so no perturbation moves it and the frame's
  own inertial terms of the spin do not enter the modes. Its steady state (the centrifugal stretch) and the sweep
  over the rate then come from the spin's analysis ops. Called before the system is built (the field operators
  then carry the spin's). w and c inertial, as drawn [rad/s, m]; mapped to the body frame and the mesh by the
  initial pose.

  Collective
@*/
PetscErrorCode PhlexFlexibleSteadyDrive(PhlexPart part, PetscInt port, const PetscReal w[3], const PetscReal *cgiven)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscReal     rate = PetscSqrtReal(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), c[3];

  PetscFunctionBeginUser;
  if (!b->floating) PetscFunctionReturn(0); /* a fixed body on a joint: nothing turns it */
  PetscCheck(rate > 0 && !b->Cor, b->comm, PETSC_ERR_PLIB, "body %s: a steady drive needs a rate", b->name);
  PetscCheck(b->frame_patch[0] && port == b->nports, b->comm, PETSC_ERR_USER_INPUT, "linearized analysis: body %s turns on a driven revolute at its port %s, not at its frame patch: its frame does not turn steadily with the hub; join the hub at the frame patch (-%sframe_patch %s)", b->name, part->ports[port].name, b->prefix, part->ports[port].name);
  PetscCheck(!b->damped, b->comm, PETSC_ERR_USER_INPUT, "linearized analysis: body %s, a rotor on a driven revolute, with structural damping: not implemented about a spin (as -%sspin)", b->name, b->prefix);
  for (PetscInt k = 0; k < 3; k++) c[k] = cgiven ? cgiven[k] : b->pose.position[k]; /* the frame patch's point: P */
  for (PetscInt k = 0; k < 3; k++) {
    PetscReal wb = 0, cb = 0;
    for (PetscInt i = 0; i < 3; i++) {
      wb += b->pose.rotation[3 * i + k] * w[i];                        /* R^T w */
      cb += b->pose.rotation[3 * i + k] * (c[i] - b->pose.position[i]); /* R^T (c - r_P) */
    }
    b->spin[k]        = wb;
    b->spin_axis[k]   = wb / rate;
    b->spin_center[k] = b->origin[k] + cb;
  }
  b->spinning = PETSC_TRUE;
  PetscFunctionReturn(0);
}
