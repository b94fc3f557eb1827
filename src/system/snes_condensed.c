/* SNES "phlexcondensed": the stage of the theta method for scenes of fixed linear flexible bodies, computed from the
   start of the step by exact elimination instead of a residual and a field-split Newton step.

   A fixed body's equations (paper eq. (ph-mixed), the rows of FlexResidual in SI time t, non-dimensional fields) are
       T u' = v,    T Ms Sigma' = G v,    T Mv v' = -G^T Sigma + b(t),
   and TSTHETA's stage X = X0 + theta dt X' (shift a = 1 / (theta dt), s = a T) solves
       s (u - u0) = v,   s Ms (Sigma - Sigma0) = G v,   s Mv (v - v0) + G^T Sigma = b(t0 + theta dt).
   With B = Ms^{-1} G (applied cell by cell: Ms is block diagonal per cell) and the
   predicted stress Sigma_p = Sigma0 + B v0 / s, eliminating u and Sigma and solving for the increment dv = v - v0:
       (s Mv + K / s) dv = b - G^T Sigma_p,                                             (the condensed right-hand side)
   (with structural damping T Mv v' + G^T Sigma + R v = b: (s Mv + K / s + R) dv = b - G^T Sigma_p - R v0)
       Sigma = Sigma_p + B dv / s  (= Sigma0 + B v / s),   u = u0 + v / s.
   The factored operator s Mv + K / s is the exact preset's (each body's Sv, its K assembled by the elements); as on
   the generic path, its difference from G^T Ms^{-1} G (about 1e-11 relative on smooth fields) enters the increment
   only. Measured on the cantilever, the formulas must be taken as written to keep the power balance at round-off
   (4e-13 J per step over 200 steps) and the tip velocities at 5e-15 to 3e-12 of their 0.35 m/s scale from a fully
   converged solve (the generic path: 2e-15 to 2e-12):
     - solving for v instead of dv puts the solve's error on v itself (3e-11 J);
     - b - G^T Sigma0 - K v0 / s, with the element-assembled K (1e-11 J) or with the product G^T B (5e-12 J): the
       momentum rows must see G^T of the very stress whose change the stress rows see;
     - Sigma0 + B v / s computed as such, or B v0 carried over from the previous step's B v_{n+1} (saving a
       product): the tip velocities moved by 1e-12 to 2e-11 of their scale.
   A step costs one solve, two products with B and one with G^T, against a residual (G, G^T, Ms, Mv) and a
   field-split Newton step (Ms^{-1} twice, G, G^T, copies of the five-times-larger stress field) on the generic path.
   B and G^T are applied cell by cell from the element structure (flexible_stress_maps.c): nothing assembled; and in
   two passes over the cells (PhlexSystemStressPredict: Sigma_p with G^T Sigma_p, PhlexSystemStressCorrect: Sigma),
   each stress entry formed as the separate products and VecWAXPY formed it (the same bytes, fewer passes over the
   stress field).

   Used when every part is a fixed flexible body with constant operators (no frame, joint, spin or stiffening) and
   the integrator is the theta method without endpoint (the default implicit midpoint, backward Euler). The presets
   exact and iterative ask for it (-snes_type phlexcondensed); where it does not apply the transient analysis takes
   their field split instead, unless -snes_type phlexcondensed was typed on the command line (then an error says
   why). The condensed solve is KSP "condensed_" (the presets configure it). */
#include <phlex_impl.h>
#include <petsc/private/snesimpl.h>

typedef struct {
  PhlexSystem sys;
  TS          ts;
  KSP         ksp;   /* the condensed velocity operator s Mv + K / s (the bodies' Sv, block diagonal) */
  PhlexStressMaps maps; /* per body B = Ms^{-1} G and G^T, cell by cell (the parts' shells) */
  Vec         r;     /* the condensed right-hand side */
  Vec         sp;    /* stress field: Sigma_p */
  Vec        *Rv;    /* per damped body: R v0 (NULL for an undamped one) */
  PetscReal   shift; /* non-dimensional shift of the operator last handed to the KSP (0: none) */
  PetscInt    guess_order; /* initial guess of an iterative solve from the last increments: 0 none, 1 the last, 2 linear, 3 quadratic */
  PetscInt    nhist;       /* increments kept (since the start or the last change of the step size) */
  Vec         dv[3];       /* the last increments dv_{n-1}, dv_{n-2}, dv_{n-3} (newest first) */
  PetscBool   balance;     /* correct an iterative solve's increment so that its residual does no work on the stage velocity */
  Vec         p, Ap;       /* work: the stage velocity v0 + dv and its product with the operator */
  PetscBool   block_products;   /* an iterative solve's products with the operator by a node-block (BAIJ) copy of it */
  PetscBool   block_levels;     /* multigrid's transfers and coarse operators by node-block copies (mg_level_products.c) */
  PetscBool   explicit_restrict; /* multigrid's restrictions by stored transposes of its interpolations (those without a block copy) */
  PetscBool   block_symmetric; /* the block copy as its upper triangle (SBAIJ) */
  PhlexPMG    pmg;         /* p-multigrid's interpolation and coarse operator (pmg.c), where the PC is PCMG */
  PhlexMGCopies mg;        /* multigrid's transfers and coarse operators as block copies (mg_level_products.c) */
  PhlexBlockCopy Ablock;   /* the node-block copy of the operator (copy NULL: the products use the operator itself) */
  PetscObjectState svstate;   /* the state of the operator the copy was taken from */
} SNES_Condensed;

/* why a scene or an integrator cannot use the condensed stage (empty: it can) */
static PetscErrorCode Eligibility(PhlexSystem sys, TS ts, char why[], size_t len)
{
  PetscBool theta, beuler, endpoint = PETSC_FALSE;

  PetscFunctionBeginUser;
  why[0] = 0;
  PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSTHETA, &theta));
  PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSBEULER, &beuler));
  if (theta) PetscCall(TSThetaGetEndpoint(ts, &endpoint));
  if (!sys->nfparts) PetscCall(PetscSNPrintf(why, len, "the scene has no flexible body"));
  else if (sys->nq || sys->njoints) PetscCall(PetscSNPrintf(why, len, "the scene has rigid, lumped or floating parts or joints (discrete unknowns)"));
  else if (sys->nonlinear || sys->state_dependent_fields || sys->inexact_schur) PetscCall(PetscSNPrintf(why, len, "a body is nonlinear or spinning (geometric stiffening, spin)"));
  else if (!(theta || beuler) || endpoint) {
    TSType type;
    PetscCall(TSGetType(ts, &type));
    PetscCall(PetscSNPrintf(why, len, "the integrator is %s%s; the condensed stage is that of the theta method without endpoint (-ts_type theta, the default implicit midpoint, or beuler)", type, endpoint ? " with endpoint (Crank-Nicolson)" : ""));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESCondensedApplicable - whether the scene and the integrator admit SNES phlexcondensed

  Collective
@*/
PetscErrorCode PhlexSNESCondensedApplicable(PhlexSystem sys, TS ts, PetscBool *ok)
{
  char why[256];

  PetscFunctionBeginUser;
  PetscCall(Eligibility(sys, ts, why, sizeof(why)));
  *ok = why[0] ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESCondensedSetSystem - hands SNES phlexcondensed the scene's system and the TS whose stages it solves; an
  error names what the scene or the integrator lacks

  Collective
@*/
PetscErrorCode PhlexSNESCondensedSetSystem(SNES snes, PhlexSystem sys, TS ts)
{
  SNES_Condensed *c = (SNES_Condensed *)snes->data;
  char            why[256];

  PetscFunctionBeginUser;
  PetscCall(Eligibility(sys, ts, why, sizeof(why)));
  PetscCheck(!why[0], sys->comm, PETSC_ERR_USER_INPUT, "-snes_type phlexcondensed cannot solve this scene's steps: %s; use -snes_type ksponly (linear) or newtonls", why);
  c->sys = sys;
  c->ts  = ts;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemGetStressMaps - references each body's cell-by-cell products (PhlexFieldOperators B and Kc) in
  arrays the caller frees with PhlexSystemStressMapsDestroy(); an error names the SNES type (who) if a body has none
  (geometric stiffening assembles G(u): the stages that use these maps are not chosen for it)

  Collective
@*/
PetscErrorCode PhlexSystemGetStressMaps(PhlexSystem sys, const char *who, PhlexStressMaps *maps)
{
  PetscFunctionBeginUser;
  PetscCall(PetscCalloc2(sys->nfparts, &maps->B, sys->nfparts, &maps->K));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    PetscCheck(ops.B && ops.Kc, sys->comm, PETSC_ERR_PLIB, "SNES %s: part %" PetscInt_FMT " has no cell-by-cell stress maps", who, i);
    PetscCall(PetscObjectReference((PetscObject)ops.B));
    PetscCall(PetscObjectReference((PetscObject)ops.Kc));
    maps->B[i] = ops.B;
    maps->K[i] = ops.Kc;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemStressMapsDestroy - releases the references of PhlexSystemGetStressMaps()
@*/
PetscErrorCode PhlexSystemStressMapsDestroy(PhlexSystem sys, PhlexStressMaps *maps)
{
  PetscFunctionBeginUser;
  if (!maps->B) PetscFunctionReturn(0);
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PetscCall(MatDestroy(&maps->B[i]));
    PetscCall(MatDestroy(&maps->K[i]));
  }
  PetscCall(PetscFree2(maps->B, maps->K));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemStressPredict - over the bodies, the predicted stress sp = s0 + a B v and its resultant r = G^T sp
  (v, r velocity field vectors; s0, sp stress field vectors), one pass over each body's cells

  Collective
@*/
PetscErrorCode PhlexSystemStressPredict(PhlexSystem sys, PhlexStressMaps *maps, Vec v, Vec s0, PetscReal a, Vec sp, Vec r)
{
  const PetscInt n = sys->nfparts;
  Vec           *vi, *s0i, *spi, *ri;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc4(n, &vi, n, &s0i, n, &spi, n, &ri));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_VELOCITY, v, vi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_STRESS, s0, s0i));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_STRESS, sp, spi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_VELOCITY, r, ri));
  for (PetscInt i = 0; i < n; i++) PetscCall(PhlexStressMapsPredict(maps->B[i], vi[i], s0i[i], a, spi[i], ri[i]));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_VELOCITY, r, ri));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_STRESS, sp, spi));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_STRESS, s0, s0i));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_VELOCITY, v, vi));
  PetscCall(PetscFree4(vi, s0i, spi, ri));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemStressCorrect - over the bodies, the stress s = sp + a B v (v a velocity field vector, sp and s stress
  field vectors), one pass over each body's cells

  Collective
@*/
PetscErrorCode PhlexSystemStressCorrect(PhlexSystem sys, PhlexStressMaps *maps, Vec v, Vec sp, PetscReal a, Vec s)
{
  const PetscInt n = sys->nfparts;
  Vec           *vi, *spi, *si;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(n, &vi, n, &spi, n, &si));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_VELOCITY, v, vi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_STRESS, sp, spi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_STRESS, s, si));
  for (PetscInt i = 0; i < n; i++) PetscCall(PhlexStressMapsCorrect(maps->B[i], vi[i], spi[i], a, si[i]));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_STRESS, s, si));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_STRESS, sp, spi));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_VELOCITY, v, vi));
  PetscCall(PetscFree3(vi, spi, si));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSetUp_Condensed(SNES snes)
{
  SNES_Condensed *c = (SNES_Condensed *)snes->data;
  PhlexSystem     sys;
  const char     *prefix;

  PetscFunctionBeginUser;
  PetscCheck(c->sys, PetscObjectComm((PetscObject)snes), PETSC_ERR_ORDER, "SNES phlexcondensed: PhlexSNESCondensedSetSystem() was not called");
  if (c->ksp) PetscFunctionReturn(0);
  sys = c->sys;
  PetscCall(PetscLogEventBegin(PHLEX_CondensedSetUp, 0, 0, 0, 0));
  PetscCall(KSPCreate(sys->comm, &c->ksp));
  PetscCall(PetscObjectIncrementTabLevel((PetscObject)c->ksp, (PetscObject)snes, 1));
  PetscCall(SNESGetOptionsPrefix(snes, &prefix));
  PetscCall(KSPSetOptionsPrefix(c->ksp, prefix));
  PetscCall(KSPAppendOptionsPrefix(c->ksp, "condensed_"));
  {
    /* defaults for a run without preset: the operator is symmetric positive definite, and an inexact solve breaks the
       power balance (the presets choose MUMPS or CG + GAMG) */
    PC pc;
    PetscCall(KSPSetType(c->ksp, KSPPREONLY));
    PetscCall(KSPGetPC(c->ksp, &pc));
    PetscCall(PCSetType(pc, PCCHOLESKY));
  }
  PetscCall(KSPSetFromOptions(c->ksp));
  /* the step's products with B and G^T, cell by cell from the element structure (two passes): nothing assembled */
  PetscCall(PhlexSystemGetStressMaps(sys, "phlexcondensed", &c->maps));
  PetscCall(MatCreateVecs(sys->Jvs, &c->sp, &c->r)); /* stress columns, velocity rows */
  PetscCall(PetscCalloc1(sys->nfparts, &c->Rv));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    if (ops.R) PetscCall(MatCreateVecs(ops.R, NULL, &c->Rv[i]));
  }
  PetscCall(PetscLogEventEnd(PHLEX_CondensedSetUp, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* a factorization preconditioner of the condensed KSP needs a solver package that factors the operator's matrix type:
   a sequential package (CHOLMOD, UMFPACK, ...) on several processes is named with the option that chose it */
static PetscErrorCode CheckFactorPackage(KSP ksp, Mat A)
{
  PC            pc;
  PetscBool     factor, lu, available = PETSC_TRUE;
  MatSolverType package;
  MatType       type;
  const char   *prefix;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &factor, PCCHOLESKY, PCLU, ""));
  if (!factor) PetscFunctionReturn(0);
  PetscCall(PCFactorGetMatSolverType(pc, &package));
  if (!package) PetscFunctionReturn(0);
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCLU, &lu));
  PetscCall(MatGetFactorAvailable(A, package, lu ? MAT_FACTOR_LU : MAT_FACTOR_CHOLESKY, &available));
  if (available) PetscFunctionReturn(0);
  PetscCall(MatGetType(A, &type));
  PetscCall(KSPGetOptionsPrefix(ksp, &prefix));
  SETERRQ(PetscObjectComm((PetscObject)ksp), PETSC_ERR_USER_INPUT, "-%spc_factor_mat_solver_type %s: the package has no %s factorization of the condensed operator's matrix type %s (-%spc_type %s)%s", prefix ? prefix : "", package, lu ? "LU" : "Cholesky", type, prefix ? prefix : "", lu ? "lu" : "cholesky", strstr(type, "mpi") ? "; on several processes use mumps (options/solver/exact.opts; exact_serial.opts is for one process)" : "");
}

/* the initial guess of an iterative condensed solve (a direct one, KSP preonly, takes none): the increments
   dv_n = theta dt v'(t_n + theta dt) of the last steps are samples of a smooth function of time, so the polynomial through
   the last guess_order of them, taken one step on, predicts dv with an error O((omega dt)^order) in a mode of angular
   frequency omega: 1 dv_{n-1}; 2 2 dv_{n-1} - dv_{n-2}; 3 3 dv_{n-1} - 3 dv_{n-2} + dv_{n-3} (fewer while fewer are kept) */
static PetscErrorCode InitialGuess(SNES_Condensed *c, Vec x)
{
  PetscBool preonly;
  PetscInt  k;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)c->ksp, KSPPREONLY, &preonly));
  k = preonly ? 0 : PetscMin(c->guess_order, c->nhist);
  PetscCall(KSPSetInitialGuessNonzero(c->ksp, k ? PETSC_TRUE : PETSC_FALSE));
  if (k == 1) PetscCall(VecCopy(c->dv[0], x));
  else if (k == 2) PetscCall(VecAXPBYPCZ(x, 2.0, -1.0, 0.0, c->dv[0], c->dv[1]));
  else if (k == 3) {
    PetscCall(VecAXPBYPCZ(x, 3.0, -3.0, 0.0, c->dv[0], c->dv[1]));
    PetscCall(VecAXPY(x, 1.0, c->dv[2]));
  }
  PetscFunctionReturn(0);
}

/* the power balance of an inexact solve. The stage's energy balance (paper eq. (ph-mixed) under the theta method)
   holds exactly when the momentum rows do; a solve that leaves the residual e = r - A dv adds the work e . v of e on
   the stage velocity v = v0 + dv, so the balance is only as good as the Krylov tolerance (rtol 1e-8: 7e-10 of H0
   after 3 steps on the cantilever at 1.1e5 DOFs, against 3e-13 at 1e-12). One Galerkin step along p = v removes it:
   dv += alpha p with alpha = e.p / p.A p leaves e' = e - alpha A p orthogonal to p, and the new stage velocity
   (1 + alpha) p too, so e' does no work on it, whatever the tolerance. A is symmetric (s Mv + K / s + R), so
   e.p = r.p - dv.(A p): one product with A and three dot products; alpha is of the order of the tolerance. */
static PetscErrorCode BalanceCorrection(SNES_Condensed *c, Vec v0, Vec dv)
{
  PetscBool   preonly; /* a direct solve (preonly with a factorization) needs none; preonly with another PC does */
  Mat         A;
  PetscScalar rp, dAp, pAp;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)c->ksp, KSPPREONLY, &preonly));
  if (preonly) { /* one application of the PC: exact only if it is a factorization */
    PC        pc;
    PetscBool factor;
    PetscCall(KSPGetPC(c->ksp, &pc));
    PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &factor, PCLU, PCCHOLESKY, PCQR, PCSVD, ""));
    if (factor) PetscFunctionReturn(0);
  }
  if (!c->balance) PetscFunctionReturn(0);
  if (!c->p) {
    PetscCall(VecDuplicate(dv, &c->p));
    PetscCall(VecDuplicate(dv, &c->Ap));
  }
  PetscCall(KSPGetOperators(c->ksp, &A, NULL));
  PetscCall(VecWAXPY(c->p, 1.0, v0, dv));
  PetscCall(MatMult(A, c->p, c->Ap));
  PetscCall(VecDot(c->r, c->p, &rp));
  PetscCall(VecDot(dv, c->Ap, &dAp));
  PetscCall(VecDot(c->p, c->Ap, &pAp));
  if (PetscRealPart(pAp) > 0) PetscCall(VecAXPY(dv, (rp - dAp) / pAp, c->p));
  PetscFunctionReturn(0);
}

/* keeps the increment just solved for as dv_{n-1} (only when a guess takes it) */
static PetscErrorCode KeepIncrement(SNES_Condensed *c, Vec x)
{
  Vec oldest;

  PetscFunctionBeginUser;
  if (!c->guess_order) PetscFunctionReturn(0);
  if (!c->dv[0])
    for (PetscInt j = 0; j < c->guess_order; j++) PetscCall(VecDuplicate(x, &c->dv[j]));
  oldest = c->dv[c->guess_order - 1];
  for (PetscInt j = c->guess_order - 1; j > 0; j--) c->dv[j] = c->dv[j - 1];
  c->dv[0] = oldest;
  PetscCall(VecCopy(x, c->dv[0]));
  c->nhist = PetscMin(c->nhist + 1, c->guess_order);
  PetscFunctionReturn(0);
}

/* The operator handed to the condensed KSP. An iterative solve spends its time in products with the operator: CG's
   and multigrid's fine-level smoothing and residual. Its P2 velocity unknowns come in node blocks of 3 that couple
   as dense 3 x 3 blocks, so a BAIJ copy reads one column index per block instead of one per entry (or per inode row):
   1.7 x faster products at 2.2e5 DOFs (BENCHMARKS.md section 43). The preconditioner is still built from the AIJ
   operator (GAMG coarsens AIJ). A direct solve (preonly) makes no product, and a matrix not in whole node blocks
   gains nothing: neither takes the copy. The copy is one object for the run, its values refilled in place whenever
   Sv's change (a new step size; Sv's state is kept): GAMG re-set up on the same pattern keeps its hierarchy and the
   fine level's residual matrix it was first given, so a new object would leave that residual on the old values
   (CG then diverged after a change of the step size). A new pattern makes a new copy (and GAMG starts afresh). */
static PetscErrorCode SetOperators(SNES_Condensed *c, Mat Sv)
{
  PetscBool        preonly;
  PetscInt         bs;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)c->ksp, KSPPREONLY, &preonly));
  PetscCall(MatGetBlockSize(Sv, &bs));
  if (c->block_products && !preonly && bs > 1) {
    PetscCall(PhlexBlockCopyUpdate(&c->Ablock, Sv, c->block_symmetric));
    if (!c->Ablock.copy) PetscCall(PetscInfo(c->ksp, "the condensed operator is not in whole %" PetscInt_FMT " x %" PetscInt_FMT " blocks: its products use it as it is\n", bs, bs));
  } else PetscCall(PhlexBlockCopyDestroy(&c->Ablock));
  PetscCall(PhlexMGCopiesRestore(c->ksp, &c->mg)); /* GAMG's interpolations back for its set-up */
  PetscCall(KSPSetOperators(c->ksp, c->Ablock.copy ? c->Ablock.copy : Sv, Sv));
  {
    /* p-multigrid (pmg.c) where the PC is PCMG: its levels once, its coarse operator at every new operator */
    PetscBool pmg;
    PetscCall(PhlexPMGWanted(c->ksp, &pmg));
    if (pmg && !c->pmg.P) {
      PetscInt rstart, m, *blocks;
      PetscCall(MatGetOwnershipRange(Sv, &rstart, NULL));
      PetscCall(MatGetLocalSize(Sv, &m, NULL));
      PetscCall(PetscMalloc1(PetscMax(c->sys->nfparts, 1), &blocks));
      for (PetscInt i = 0; i < c->sys->nfparts; i++) blocks[i] = i;
      PetscCall(PhlexPMGBuild(c->ksp, c->sys->comm, m, rstart, bs, c->sys->nfparts, blocks, c->sys->border.off, PhlexSystemCoarseSpace, c->sys, &c->pmg));
      PetscCall(PetscFree(blocks));
    }
    if (pmg) PetscCall(PhlexPMGSetUp(c->ksp, Sv, &c->pmg));
  }
  if (!preonly) PetscCall(PhlexMGCopiesApply(c->ksp, c->block_levels, c->explicit_restrict, &c->mg));
  PetscCall(PetscObjectStateGet((PetscObject)Sv, &c->svstate)); /* after the set-up (it may mark Sv) */
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSolve_Condensed(SNES snes)
{
  SNES_Condensed    *c   = (SNES_Condensed *)snes->data;
  PhlexSystem        sys = c->sys;
  Vec                X   = snes->vec_sol, X0, u0, s0, v0, xu, xs, xv;
  PetscReal          t, dt, theta, a, s, tstage;
  PetscInt           its;
  KSPConvergedReason kreason;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_CondensedStage, 0, 0, 0, 0));
  snes->reason = SNES_CONVERGED_ITERATING;
  snes->iter   = 0;
  snes->norm   = 0.0;
  PetscCall(TSGetSolution(c->ts, &X0));
  PetscCall(TSGetTime(c->ts, &t));
  PetscCall(TSGetTimeStep(c->ts, &dt));
  PetscCall(TSThetaGetTheta(c->ts, &theta));
  a      = 1.0 / (theta * dt);
  s      = a * sys->units->time;
  tstage = t + theta * dt;
  if (PetscAbsReal(s - c->shift) > 1e-12 * s) {
    /* a new step size: the parts rebuild their condensed operators (the KSP refactors) */
    Mat Sv;
    PetscCall(PhlexSystemIJacobian(c->ts, tstage, X0, NULL, a, sys->J, sys->J, sys));
    PetscCall(PhlexSystemVelocityOperator(sys, &Sv));
    /* the rebuild's AIJ copies of Mv and K (freed) back to the system before the preconditioner's set-up allocates
       (GAMG's hierarchy, a factor): else the resident size keeps them beside it (BENCHMARKS.md sections 20, 40) */
    PetscCall(PhlexReturnFreedMemory());
    PetscCall(CheckFactorPackage(c->ksp, Sv));
    PetscCall(SetOperators(c, Sv));
    c->shift = s;
    c->nhist = 0; /* the increments scale with the step: the guess starts again */
  } else if (c->Ablock.copy || c->block_levels || c->explicit_restrict || c->pmg.P) {
    Mat              Sv;
    PetscObjectState state;
    PetscCall(KSPGetOperators(c->ksp, NULL, &Sv));
    PetscCall(PetscObjectStateGet((PetscObject)Sv, &state));
    if (state != c->svstate) PetscCall(SetOperators(c, Sv)); /* Sv's values changed in place: the copies and the coarse operator made again */
  }
  /* the loads b at the stage time (those of a fixed body depend on t only) */
  PetscCall(PhlexSystemEvaluate(sys, tstage, X0, NULL));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_STRESS], &s0));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_VELOCITY], &v0));
  /* Sigma_p = Sigma0 + B v0 / s and G^T Sigma_p in one pass; per body r = b - G^T Sigma_p */
  PetscCall(PhlexSystemStressPredict(sys, &c->maps, v0, s0, 1.0 / s, c->sp, c->r));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    Vec                 ri;
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    PetscCall(VecGetSubVector(c->r, sys->fis[PHLEX_FIELD_VELOCITY][i], &ri));
    PetscCall(VecAYPX(ri, -1.0, ops.load));
    if (ops.R) {
      /* structural damping: r = b - G^T Sigma_p - R v0, the operator holding R (T Mv v' + G^T Sigma + R v = b) */
      Vec v0i;
      PetscCall(VecGetSubVector(v0, sys->fis[PHLEX_FIELD_VELOCITY][i], &v0i));
      PetscCall(MatMult(ops.R, v0i, c->Rv[i]));
      PetscCall(VecRestoreSubVector(v0, sys->fis[PHLEX_FIELD_VELOCITY][i], &v0i));
      PetscCall(VecAXPY(ri, -1.0, c->Rv[i]));
    }
    PetscCall(VecRestoreSubVector(c->r, sys->fis[PHLEX_FIELD_VELOCITY][i], &ri));
  }
  /* dv: the condensed solve, straight into the stage's velocity block; v = v0 + dv */
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
  PetscCall(InitialGuess(c, xv));
  PetscCall(KSPSolve(c->ksp, c->r, xv));
  PetscCall(BalanceCorrection(c, v0, xv));
  PetscCall(KeepIncrement(c, xv));
  PetscCall(KSPGetIterationNumber(c->ksp, &its));
  PetscCall(KSPGetConvergedReason(c->ksp, &kreason));
  snes->linear_its += its;
  /* Sigma = Sigma_p + B dv / s (not Sigma0 + B v / s: the momentum rows saw G^T Sigma_p); v = v0 + dv; u = u0 + v / s */
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  PetscCall(PhlexSystemStressCorrect(sys, &c->maps, xv, c->sp, 1.0 / s, xs));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  PetscCall(VecAXPY(xv, 1.0, v0));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecWAXPY(xu, 1.0 / s, xv, u0));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_STRESS], &s0));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_VELOCITY], &v0));
  snes->iter   = 1;
  snes->reason = kreason < 0 ? SNES_DIVERGED_LINEAR_SOLVE : SNES_CONVERGED_ITS;
  if (kreason < 0) snes->numLinearSolveFailures++;
  PetscCall(PetscLogEventEnd(PHLEX_CondensedStage, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESReset_Condensed(SNES snes)
{
  SNES_Condensed *c = (SNES_Condensed *)snes->data;

  PetscFunctionBeginUser;
  PetscCall(KSPDestroy(&c->ksp));
  if (c->sys) PetscCall(PhlexSystemStressMapsDestroy(c->sys, &c->maps));
  if (c->Rv) {
    for (PetscInt i = 0; i < c->sys->nfparts; i++) PetscCall(VecDestroy(&c->Rv[i]));
    PetscCall(PetscFree(c->Rv));
  }
  PetscCall(VecDestroy(&c->r));
  PetscCall(VecDestroy(&c->sp));
  for (PetscInt j = 0; j < 3; j++) PetscCall(VecDestroy(&c->dv[j]));
  PetscCall(VecDestroy(&c->p));
  PetscCall(VecDestroy(&c->Ap));
  PetscCall(PhlexBlockCopyDestroy(&c->Ablock));
  PetscCall(PhlexMGCopiesDestroy(&c->mg));
  PetscCall(PhlexPMGDestroy(&c->pmg));
  c->nhist = 0;
  c->shift = 0.0;
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESDestroy_Condensed(SNES snes)
{
  PetscFunctionBeginUser;
  PetscCall(SNESReset_Condensed(snes));
  PetscCall(PetscFree(snes->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSetFromOptions_Condensed(SNES snes, PetscOptionItems *PetscOptionsObject)
{
  SNES_Condensed *c = (SNES_Condensed *)snes->data;
  PetscInt        order = c->guess_order;

  PetscFunctionBeginUser;
  PetscOptionsHeadBegin(PetscOptionsObject, "SNES phlexcondensed options");
  PetscCall(PetscOptionsInt("-snes_phlexcondensed_guess_order", "Initial guess of an iterative condensed solve: the polynomial through this many of the last steps' velocity increments, one step on (0: zero guess, 1: the last increment, 2: linear, 3: quadratic extrapolation); a direct solve takes none", "SNESPHLEXCONDENSED", order, &order, NULL));
  PetscCall(PetscOptionsBool("-snes_phlexcondensed_block_products", "An iterative condensed solve's products with the operator by a copy in 3 x 3 node blocks (BAIJ; the preconditioner is built from the AIJ operator): faster products for more memory; a direct solve takes none", "SNESPHLEXCONDENSED", c->block_products, &c->block_products, NULL));
  PetscCall(PetscOptionsBool("-snes_phlexcondensed_block_products_symmetric", "With -snes_phlexcondensed_block_products: the block copy stores the upper triangle only (SBAIJ; less memory, on several processes two halo exchanges per product)", "SNESPHLEXCONDENSED", c->block_symmetric, &c->block_symmetric, NULL));
  PetscCall(PetscOptionsBool("-snes_phlexcondensed_block_levels", "Multigrid preconditioners of an iterative condensed solve (GAMG) transfer by a node-block (BAIJ) copy of each interpolation, in both directions, and smooth each coarse level with a BAIJ copy of its operator: faster products", "SNESPHLEXCONDENSED", c->block_levels, &c->block_levels, NULL));
  PetscCall(PetscOptionsBool("-snes_phlexcondensed_explicit_restriction", "Multigrid preconditioners of an iterative condensed solve restrict by stored transposes of their interpolations (faster than products with the transposes; for interpolations without a block copy)", "SNESPHLEXCONDENSED", c->explicit_restrict, &c->explicit_restrict, NULL));
  PetscCall(PetscOptionsBool("-snes_phlexcondensed_balance", "Correct an iterative condensed solve's velocity increment along the stage velocity so that its residual does no work (the power balance to round-off whatever the Krylov tolerance); a direct solve takes none", "SNESPHLEXCONDENSED", c->balance, &c->balance, NULL));
  PetscOptionsHeadEnd();
  PetscCheck(order >= 0 && order <= 3, PetscObjectComm((PetscObject)snes), PETSC_ERR_USER_INPUT, "-snes_phlexcondensed_guess_order must be 0, 1, 2 or 3, got %" PetscInt_FMT, order);
  if (order != c->guess_order) {
    for (PetscInt j = 0; j < 3; j++) PetscCall(VecDestroy(&c->dv[j]));
    c->nhist       = 0;
    c->guess_order = order;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESView_Condensed(SNES snes, PetscViewer viewer)
{
  SNES_Condensed *c = (SNES_Condensed *)snes->data;
  PetscBool       ascii;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  theta-method stage by exact elimination of displacement and stress; condensed velocity solve:\n"));
  if (c->ksp) {
    PetscBool preonly;
    PetscCall(PetscObjectTypeCompare((PetscObject)c->ksp, KSPPREONLY, &preonly));
    if (!preonly) PetscCall(PetscViewerASCIIPrintf(viewer, "  products with the operator: %s\n", c->Ablock.copy ? "its node-block copy" : "itself"));
    PetscCall(PhlexPMGView(&c->pmg, viewer));
    if (c->mg.count[0]) PetscCall(PetscViewerASCIIPrintf(viewer, "  multigrid: of %" PetscInt_FMT " transfers %" PetscInt_FMT " by node-block copies, %" PetscInt_FMT " restricting by stored transposes; of %" PetscInt_FMT " smoothed coarse levels %" PetscInt_FMT " by node-block copies\n", c->mg.count[0], c->mg.count[1], c->mg.count[2], c->mg.count[3], c->mg.count[4]));
  }
  if (c->ksp) {
    PetscCall(PetscViewerASCIIPushTab(viewer));
    PetscCall(KSPView(c->ksp, viewer));
    PetscCall(PetscViewerASCIIPopTab(viewer));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESCreate_Condensed(SNES snes)
{
  SNES_Condensed *c;

  PetscFunctionBeginUser;
  snes->ops->setup            = SNESSetUp_Condensed;
  snes->ops->solve            = SNESSolve_Condensed;
  snes->ops->reset            = SNESReset_Condensed;
  snes->ops->destroy          = SNESDestroy_Condensed;
  snes->ops->view             = SNESView_Condensed;
  snes->ops->setfromoptions   = SNESSetFromOptions_Condensed;
  snes->usesksp               = PETSC_FALSE; /* its own KSP, prefix condensed_ (the presets configure SNES's for the generic path) */
  snes->usesnpc               = PETSC_FALSE;
  snes->alwayscomputesfinalresidual = PETSC_FALSE;
  PetscCall(PetscNew(&c));
  c->guess_order = 0; /* measured: no gain (section 37), so off */
  c->balance     = PETSC_TRUE;
  snes->data = (void *)c;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESRegister - registers the SNES type "phlexcondensed"
@*/
PetscErrorCode PhlexSNESRegister(void)
{
  PetscFunctionBeginUser;
  PetscCall(SNESRegister("phlexcondensed", SNESCreate_Condensed));
  PetscFunctionReturn(0);
}
