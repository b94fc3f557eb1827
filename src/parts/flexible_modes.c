/* Modal analysis of one flexible body with SLEPc: the symmetric-definite pencil (K, Mv) of the velocity after exact
   stress elimination (K = G^T Ms^{-1} G element by element), shift-and-invert, EPS options under the prefix modes_.
   A floating body is solved on the pencil of its linearisation at rest (the kinetic energy of v_P + w x x + v):
   with a frame patch directly (FloatingPencil); with mean axes on (K, Mv) restricted to the constraint space
   T^T v = 0 (below). */
#include <phlex_impl.h>

/* Lowest free-free bending frequency of a beam with the body's bounding box (non-dimensional, rad per unit time):
   a scale for the shift of free bodies and for telling rigid modes from elastic ones. */
static PetscReal FrequencyScale(PhlexFlexible b, const PhlexUnits *u)
{
  PetscReal L = 0, t = PETSC_MAX_REAL, c = PETSC_MAX_REAL;

  for (PetscInt d = 0; d < 3; d++) {
    L = PetscMax(L, b->bbox_max[d] - b->bbox_min[d]);
    t = PetscMin(t, b->bbox_max[d] - b->bbox_min[d]);
  }
  for (PetscInt m = 0; m < b->nmaterials; m++) c = PetscMin(c, PetscSqrtReal(b->materials[m].youngs_modulus / b->materials[m].density));
  /* (4.730)^2 t / (sqrt(12) L^2) c, in units of 1/T */
  return 22.373 * t / (PetscSqrtReal(12.0) * L * L) * c * u->time;
}

/* The pencil of a floating body linearised at rest (paper: the mass operator of eq. momenta at u_f = 0, w = 0):
   unknowns [v | v_P, w_P] (the six rigid ones on rank 0),
     A = [[K, 0], [0, 0]],   B = [[Mv, Bm], [Bm^T, M6]],   M6 = [[m I, -[s0]x], [[s0]x, J0]],
   Bm = [t e_c | e_a x w] (nodal t = int rho phi, w = int rho x phi): the kinetic energy of v_P + w x x + v. The
   rigid unknowns make six zero eigenvalues; the others are the free-free modes with the frame patch moving
   rigidly. Assembled as AIJ (six dense rows and columns) so that any shift and factorisation apply. */
static PetscErrorCode FloatingPencil(PhlexFlexible b, Mat *A, Mat *B, IS is[2])
{
  MPI_Comm           comm = b->comm;
  PetscMPIInt        rank;
  PetscInt           n = b->nv_local, q, ld;
  Mat                blocks[4], Kaij, Maij, Bm, BmT, M6, Z6, N;
  const PetscScalar *ta, *wa;
  PetscScalar       *ba;
  const PhlexInertia *in = &b->inertia;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  q = rank == 0 ? 6 : 0;
  PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &Kaij));
  PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &Maij));
  PetscCall(MatCreateDense(comm, n, q, PETSC_DETERMINE, 6, NULL, &Bm));
  PetscCall(MatDenseGetLDA(Bm, &ld));
  PetscCall(MatDenseGetArrayWrite(Bm, &ba));
  PetscCall(VecGetArrayRead(b->tnode, &ta));
  PetscCall(VecGetArrayRead(b->wnode, &wa));
  for (PetscInt l = 0; l < n / 3; l++) {
    const PetscReal *w = (const PetscReal *)&wa[3 * l]; /* real build */
    for (PetscInt c = 0; c < 3; c++) {
      for (PetscInt j = 0; j < 3; j++) ba[j * ld + 3 * l + c] = c == j ? ta[3 * l + c] : 0.0;
      /* (e_a x w)_c */
      ba[3 * ld + 3 * l + c] = c == 0 ? 0.0 : (c == 1 ? -w[2] : w[1]);
      ba[4 * ld + 3 * l + c] = c == 0 ? w[2] : (c == 1 ? 0.0 : -w[0]);
      ba[5 * ld + 3 * l + c] = c == 0 ? -w[1] : (c == 1 ? w[0] : 0.0);
    }
  }
  PetscCall(VecRestoreArrayRead(b->tnode, &ta));
  PetscCall(VecRestoreArrayRead(b->wnode, &wa));
  PetscCall(MatDenseRestoreArrayWrite(Bm, &ba));
  PetscCall(MatAssemblyBegin(Bm, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(Bm, MAT_FINAL_ASSEMBLY));
  PetscCall(MatTranspose(Bm, MAT_INITIAL_MATRIX, &BmT));
  PetscCall(MatCreateAIJ(comm, q, q, 6, 6, 6, NULL, 0, NULL, &M6));
  PetscCall(MatCreateAIJ(comm, q, q, 6, 6, 0, NULL, 0, NULL, &Z6));
  if (rank == 0) {
    PetscReal m6[36], S[9], J[9];
    PetscInt  idx[6] = {0, 1, 2, 3, 4, 5};
    const PetscReal tr = in->E0[0] + in->E0[4] + in->E0[8];
    PhlexSkew(in->s0, S);
    for (PetscInt k = 0; k < 9; k++) J[k] = (k % 4 == 0 ? tr : 0.0) - in->E0[k];
    for (PetscInt i = 0; i < 3; i++)
      for (PetscInt j = 0; j < 3; j++) {
        m6[6 * i + j]           = i == j ? in->m : 0.0;
        m6[6 * i + 3 + j]       = -S[3 * i + j];
        m6[6 * (3 + i) + j]     = S[3 * i + j];
        m6[6 * (3 + i) + 3 + j] = J[3 * i + j];
      }
    PetscCall(MatSetValues(M6, 6, idx, 6, idx, m6, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(M6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(M6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(Z6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(Z6, MAT_FINAL_ASSEMBLY));
  blocks[0] = Kaij, blocks[1] = NULL, blocks[2] = NULL, blocks[3] = Z6;
  PetscCall(MatCreateNest(comm, 2, NULL, 2, NULL, blocks, &N));
  PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, A));
  PetscCall(MatNestGetISs(N, is, NULL));
  PetscCall(PetscObjectReference((PetscObject)is[0]));
  PetscCall(PetscObjectReference((PetscObject)is[1]));
  PetscCall(MatDestroy(&N));
  blocks[0] = Maij, blocks[1] = Bm, blocks[2] = BmT, blocks[3] = M6;
  PetscCall(MatCreateNest(comm, 2, NULL, 2, NULL, blocks, &N));
  PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, B));
  PetscCall(MatDestroy(&N));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*B, MAT_SPD, PETSC_TRUE));
  PetscCall(MatDestroy(&Kaij));
  PetscCall(MatDestroy(&Maij));
  PetscCall(MatDestroy(&Bm));
  PetscCall(MatDestroy(&BmT));
  PetscCall(MatDestroy(&M6));
  PetscCall(MatDestroy(&Z6));
  PetscFunctionReturn(0);
}

/*@C
  PhlexModesEPSCreate - the eigensolver of a body's modes with phlex's defaults (block Krylov-Schur phlexblock,
  shift-and-invert, Cholesky by MUMPS, tolerance 1e-12, no purification), options prefix modes_, and the target
  frequency asked for;
  the operators, dimensions and target are the caller's. The modal analysis also creates one without operators to
  read (and check) every eigensolver option before the first solve.

  Collective
@*/
PetscErrorCode PhlexModesEPSCreate(MPI_Comm comm, EPS *eps, PetscReal *ftarget, PetscBool *set)
{
  ST  st;
  KSP ksp;
  PC  pc;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, "modes_", "Modal analysis options", NULL);
  PetscCall(PetscOptionsReal("-target_frequency", "Look for the modes nearest this frequency [Hz] (default: the lowest)", "PhlexFlexibleComputeModes", *ftarget, ftarget, set));
  PetscOptionsEnd();
  PetscCall(EPSCreate(comm, eps));
  PetscCall(EPSSetOptionsPrefix(*eps, "modes_"));
  PetscCall(EPSSetProblemType(*eps, EPS_GHEP));
  PetscCall(EPSSetType(*eps, EPSPHLEXBLOCK));
  PetscCall(EPSSetWhichEigenpairs(*eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSSetTolerances(*eps, 1e-12, PETSC_DEFAULT));
  /* B (the velocity mass, or the body's whole kinetic-energy matrix when floating) is positive definite, so the
     shift-and-invert eigenvectors carry no null-space component to purify; purification costs one more solve per
     eigenvector (a fifth of the run at 2.2e5 dofs, BENCHMARKS.md) and changed no digit. -modes_eps_purify 1 restores it. */
  PetscCall(EPSSetPurify(*eps, PETSC_FALSE));
  PetscCall(EPSGetST(*eps, &st));
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  if (PetscDefined(HAVE_MUMPS)) PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscFunctionReturn(0);
}

/* Where A - sigma B is stored. K and Mv come from the same preallocation and element loop: their patterns are the
   same (compared, on one process), which makes the shifted sum a plain sum of value arrays. In place (A overwritten,
   restored by SLEPc after the solve) saves the copy, 85 MB at 2.2e5 DOFs (BENCHMARKS.md section 14), but only where
   nothing needs A during the solve or bit for bit afterwards: EPS phlexblock reads only B (Krylov-Schur with true
   residuals reads A), the restored K = (K - sigma M) + sigma M differs from K by round-off (a transient whose initial
   condition is this mode builds its operators from K: may_modify_A false), and on one process (on several, PETSc's MPISBAIJ
   sum builds a new matrix anyway); -modes_st_matmode and -modes_st_matstructure, when given, decide. */
static PetscErrorCode ShiftedOperatorStorage(PhlexFlexible b, EPS eps, Mat A, Mat B, PetscBool may_modify_A)
{
  ST          st;
  PetscBool   block, trueres, given;
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCallMPI(MPI_Comm_size(b->comm, &size));
  PetscCall(PetscOptionsHasName(NULL, "modes_", "-st_matstructure", &given));
  if (A == b->K && B == b->Mv && size == 1 && !given) {
    /* compared, not assumed: a wrong claim would add the value arrays of different patterns (on several processes
       the off-process parts of MPISBAIJ are numbered per matrix, and such a claim gave wrong eigenvalues) */
    const PetscInt *ia, *ja, *ib, *jb;
    PetscInt        na, nb;
    PetscBool       da, db, same = PETSC_FALSE;
    PetscCall(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &na, &ia, &ja, &da));
    PetscCall(MatGetRowIJ(B, 0, PETSC_FALSE, PETSC_TRUE, &nb, &ib, &jb, &db));
    if (da && db && na == nb && ia[na] == ib[nb]) {
      same = PETSC_TRUE;
      for (PetscInt k = 0; k <= na && same; k++) same = ia[k] == ib[k] ? PETSC_TRUE : PETSC_FALSE;
      for (PetscInt k = 0; k < ia[na] && same; k++) same = ja[k] == jb[k] ? PETSC_TRUE : PETSC_FALSE;
    }
    PetscCall(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &na, &ia, &ja, &da));
    PetscCall(MatRestoreRowIJ(B, 0, PETSC_FALSE, PETSC_TRUE, &nb, &ib, &jb, &db));
    if (same) PetscCall(STSetMatStructure(st, SAME_NONZERO_PATTERN));
  }
  PetscCall(PetscOptionsHasName(NULL, "modes_", "-st_matmode", &given));
  if (given) PetscFunctionReturn(0);
  PetscCall(PetscObjectTypeCompare((PetscObject)eps, EPSPHLEXBLOCK, &block));
  PetscCall(EPSGetTrueResidual(eps, &trueres));
  if (block && !trueres && size == 1 && (may_modify_A || A != b->K)) PetscCall(STSetMatMode(st, ST_MATMODE_INPLACE));
  PetscFunctionReturn(0);
}

/* With -modes_eps_true_residual Krylov-Schur (and Arnoldi) test ||A x - lambda B x|| / |lambda| of each Ritz pair,
   which a rigid mode (lambda ~ 0, its residual at round-off of ||A||) never passes: a free body's run ended with no
   mode at all. Below rigid_below the test is the backward error ||A x - lambda B x|| / (||A||_inf + |lambda|
   ||B||_inf), what phlex reports for rigid modes; above it SLEPc's relative test. */
typedef struct {
  PetscReal rigid_below, nrma, nrmb;
} ConvergedRigidCtx;

static PetscErrorCode ConvergedRelativeOrBackward(EPS eps, PetscScalar kr, PetscScalar ki, PetscReal res, PetscReal *errest, void *ctx)
{
  ConvergedRigidCtx *c   = (ConvergedRigidCtx *)ctx;
  PetscReal          lam = SlepcAbsEigenvalue(kr, ki);

  PetscFunctionBeginUser;
  *errest = lam < c->rigid_below ? res / (c->nrma + lam * c->nrmb) : res / lam;
  PetscFunctionReturn(0);
}

static PetscErrorCode ConvergedRigidDestroy(void *ctx)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(ctx));
  PetscFunctionReturn(0);
}

/* The residuals of the first n eigenpairs, as EPSComputeError defines them: ||A x - lambda B x||_2 / (|lambda| ||x||_2),
   and for lambda ~ 0 (a rigid mode, |lambda| < rigid_below) the backward error ||A x - lambda B x||_2 /
   ((||A||_inf + |lambda| ||B||_inf) ||x||_2). The eigenvectors go through A and B in panels of at most 8
   (PhlexMatMultBlock: one pass over each matrix per panel, where EPSComputeError passes over both per pair). */
static PetscErrorCode EigenpairResiduals(EPS eps, PetscInt n, PetscReal rigid_below, PetscReal *resid)
{
  Mat       A, B, X, AX, BX;
  PetscInt  nloc, N, npanel, w;
  PetscReal nrma = -1, nrmb = -1;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  PetscCall(EPSGetOperators(eps, &A, &B));
  PetscCall(MatGetLocalSize(A, &nloc, NULL));
  PetscCall(MatGetSize(A, &N, NULL));
  npanel = (n + 7) / 8;
  w      = (n + npanel - 1) / npanel; /* 26 pairs: 7, 7, 7, 5 */
  PetscCall(MatCreateDense(PetscObjectComm((PetscObject)A), nloc, PETSC_DECIDE, N, w, NULL, &X));
  PetscCall(MatDuplicate(X, MAT_DO_NOT_COPY_VALUES, &AX));
  PetscCall(MatDuplicate(X, MAT_DO_NOT_COPY_VALUES, &BX));
  for (PetscInt p = 0; p < n; p += w) {
    const PetscInt k = PetscMin(w, n - p);
    for (PetscInt c = 0; c < w; c++) {
      Vec x;
      PetscCall(MatDenseGetColumnVecWrite(X, c, &x));
      if (c < k) PetscCall(EPSGetEigenvector(eps, p + c, x, NULL));
      else PetscCall(VecSet(x, 0.0)); /* the last panel's unused columns */
      PetscCall(MatDenseRestoreColumnVecWrite(X, c, &x));
    }
    PetscCall(PhlexMatMultBlock(A, X, AX));
    PetscCall(PhlexMatMultBlock(B, X, BX));
    for (PetscInt c = 0; c < k; c++) {
      Vec         x, u, v;
      PetscScalar kr, ki;
      PetscReal   nrm, xnrm, lam;
      PetscCall(EPSGetEigenvalue(eps, p + c, &kr, &ki));
      lam = PetscAbsScalar(kr);
      PetscCall(MatDenseGetColumnVecRead(X, c, &x));
      PetscCall(VecNorm(x, NORM_2, &xnrm));
      PetscCall(MatDenseRestoreColumnVecRead(X, c, &x));
      PetscCall(MatDenseGetColumnVecWrite(AX, c, &u));
      if (lam > PETSC_MACHINE_EPSILON) {
        PetscCall(MatDenseGetColumnVecRead(BX, c, &v));
        PetscCall(VecAXPY(u, -kr, v));
        PetscCall(MatDenseRestoreColumnVecRead(BX, c, &v));
      }
      PetscCall(VecNorm(u, NORM_2, &nrm));
      PetscCall(MatDenseRestoreColumnVecWrite(AX, c, &u));
      if (lam < rigid_below) {
        if (nrma < 0) {
          PetscCall(MatNorm(A, NORM_INFINITY, &nrma));
          PetscCall(MatNorm(B, NORM_INFINITY, &nrmb));
        }
        resid[p + c] = nrm / ((nrma + lam * nrmb) * xnrm);
      } else resid[p + c] = nrm / (lam * xnrm);
    }
  }
  PetscCall(MatDestroy(&X));
  PetscCall(MatDestroy(&AX));
  PetscCall(MatDestroy(&BX));
  PetscFunctionReturn(0);
}

/* p-multigrid's coarse space of a modal pencil (a PhlexCoarseSpaceFn): block 0 the body's velocities (their P1
   space), block 1 a floating pencil's six rigid unknowns (on rank 0), carried to the coarse level */
typedef struct {
  PhlexFlexible b;
  PetscInt      q; /* the rigid unknowns here */
} ModesCoarse;

static PetscErrorCode ModesCoarseSpace(void *ctx, PetscInt i, PetscInt row0, PetscInt col0, Mat P, PetscInt *n1, PetscInt inj[])
{
  ModesCoarse *c = (ModesCoarse *)ctx;

  PetscFunctionBeginUser;
  if (i == 0) {
    PetscCall(PhlexFlexibleCoarseSpace(c->b, row0, col0, P, n1, inj));
    PetscFunctionReturn(0);
  }
  *n1 = c->q;
  for (PetscInt j = 0; P && j < c->q; j++) {
    PetscCall(MatSetValue(P, row0 + j, col0 + j, 1.0, INSERT_VALUES));
    if (inj) inj[j] = j;
  }
  PetscFunctionReturn(0);
}

/* the iterative inner solves of a body's modal analysis: each checked, counted, and a progress line when due (a
   restart cycle of the eigensolver, where its monitor reports, is about 70 inner solves: half an hour at 3e6 DOFs) */
typedef struct {
  PhlexFlexible b;
  PhlexProgress progress;
  PetscInt      solves, its;
} ModesInner;

/* after each inner solve: one that stopped short of its tolerance is an error (the eigenpairs would be silently
   wrong), naming the option to change; the interrupt flag checked, progress reported */
static PetscErrorCode ModesInnerSolveCheck(KSP ksp, Vec rhs, Vec x, void *ctx)
{
  ModesInner        *c = (ModesInner *)ctx;
  PhlexFlexible      b = c->b;
  KSPConvergedReason reason;
  PetscInt           its;
  char               what[PHLEX_NAME_LEN + 128];

  PetscFunctionBeginUser;
  PetscCall(KSPGetConvergedReason(ksp, &reason));
  PetscCall(KSPGetIterationNumber(ksp, &its));
  PetscCheck(reason > 0 || (reason != KSP_DIVERGED_PC_FAILED && reason != KSP_DIVERGED_NANORINF), b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: an inner solve of the modal analysis (-modes_st_ksp_type) failed at iteration %" PetscInt_FMT ": %s: the preconditioner (-modes_st_pc_type; p-multigrid's coarse factorization, -modes_st_mg_coarse_pc_type) failed on the shifted operator K - sigma Mv, singular at a shift on an eigenvalue (-modes_st_shift, -modes_target_frequency)", b->name, its, KSPConvergedReasons[reason]);
  PetscCheck(reason > 0 || (reason != KSP_DIVERGED_INDEFINITE_PC && reason != KSP_DIVERGED_INDEFINITE_MAT), b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: an inner solve of the modal analysis (-modes_st_ksp_type) stopped at iteration %" PetscInt_FMT ": %s. The shifted operator K - sigma Mv is indefinite where the shift lies above the lowest modes (-modes_target_frequency), and CG solves definite systems only: use -modes_st_ksp_type gmres, or the default factorization", b->name, its, KSPConvergedReasons[reason]);
  PetscCheck(reason > 0 && reason != KSP_CONVERGED_ITS, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: an inner solve of the modal analysis (-modes_st_ksp_type) did not reach its tolerance: %s after %" PetscInt_FMT " iterations (-modes_st_ksp_max_it, -modes_st_ksp_rtol%s); the eigenpairs would be wrong", b->name, KSPConvergedReasons[reason], its, reason == KSP_CONVERGED_ITS ? "; -modes_st_ksp_norm_type none tests no residual" : "");
  c->solves++;
  c->its += its;
  PetscCall(PetscSNPrintf(what, sizeof(what), "modes of body %s: %" PetscInt_FMT " inner solves, %" PetscInt_FMT " iterations", b->name, c->solves, c->its));
  PetscCall(PhlexProgressPhase(&c->progress, b->comm, what, -1.0));
  PetscFunctionReturn(0);
}

/* -modes_st_pc_type mg: the shift-and-invert solves by an iterative KSP with p-multigrid (a body too large for a
   factorization, BENCHMARKS.md section 46): the two levels and the coarse operator P^T (A - sigma B) P formed before
   the eigensolver's set-up (the ST forms A - sigma B and sets its KSP up at once), from the shift the ST will use.
*/
static PetscErrorCode ModesPMGSetUp(PhlexFlexible b, EPS eps, Mat A, Mat B, MatNullSpace rigid_fields, PhlexPMG *pm)
{
  ST          st;
  KSP         ksp;
  PetscBool   wanted, sinvert, given;
  PetscScalar shift;
  PetscInt    m, rstart, bs, blocks[2] = {0, 1}, off[2];
  ModesCoarse c;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(PhlexPMGWanted(ksp, &wanted));
  if (!wanted) PetscFunctionReturn(0);
  PetscCall(PetscObjectTypeCompare((PetscObject)st, STSINVERT, &sinvert));
  if (!sinvert) {
    STType type;
    PetscCall(STGetType(st, &type));
    SETERRQ(b->comm, PETSC_ERR_USER_INPUT, "-modes_st_pc_type mg (p-multigrid) solves with the shift-and-invert operator A - sigma B; -modes_st_type %s has another: use -modes_st_type sinvert", type);
  }
  PetscCheck(b->degree == 2, b->comm, PETSC_ERR_USER_INPUT, "-modes_st_pc_type mg (p-multigrid): body %s is of degree %" PetscInt_FMT " (-%spetscspace_degree); its coarse space is the P1 space of a P2 body: use a factorization (the default) or -modes_st_ksp_type cg -modes_st_pc_type gamg", b->name, b->degree, b->prefix);
  {
    /* one V-cycle per "solve" (KSP preonly, richardson) would be an operator other than (K - sigma Mv)^{-1}: the
       eigenpairs silently wrong */
    PetscBool cycle;
    KSPType   type;
    PetscCall(PetscObjectTypeCompareAny((PetscObject)ksp, &cycle, KSPPREONLY, KSPRICHARDSON, ""));
    PetscCall(KSPGetType(ksp, &type));
    PetscCheck(!cycle, b->comm, PETSC_ERR_USER_INPUT, "-modes_st_pc_type mg (p-multigrid) with -modes_st_ksp_type %s: the shift-and-invert needs the solves converged, not single cycles: add -modes_st_ksp_type cg (options/solver/modes_iterative.opts)", type);
  }
  /* the shift the ST will take: the user's, else the eigensolver's target (-modes_target_frequency, or
     -modes_eps_target), set here so that STGetShift reads it before the set-up */
  PetscCall(PetscOptionsHasName(NULL, "modes_", "-st_shift", &given));
  if (!given) {
    PetscScalar target;
    PetscCall(EPSGetTarget(eps, &target));
    PetscCall(STSetShift(st, target));
  }
  PetscCall(STGetShift(st, &shift));
  PetscCall(MatGetOwnershipRange(A, &rstart, NULL));
  PetscCall(MatGetLocalSize(A, &m, NULL));
  PetscCall(MatGetBlockSize(A, &bs));
  c.b    = b;
  c.q    = m - b->nv_local;
  off[0] = 0;
  off[1] = b->nv_local;
  PetscCall(PhlexPMGBuild(ksp, b->comm, m, rstart, bs, A == b->K ? 1 : 2, blocks, off, ModesCoarseSpace, &c, pm));
  {
    /* the rigid-body modes, for a GAMG on the coarse level (-modes_st_mg_coarse_pc_type gamg): the body's rigid
       fields, the deflation's where it made them (a floating pencil's rigid unknowns: carried, left out) */
    MatNullSpace nsp = NULL;
    if (A == b->K && rigid_fields) {
      nsp = rigid_fields;
      PetscCall(PetscObjectReference((PetscObject)nsp));
    } else if (A == b->K) PetscCall(DMPlexCreateRigidBody(b->dm, 0, &nsp));
    PetscCall(PhlexPMGSetUpPencil(ksp, A, B, shift, nsp, pm));
    PetscCall(MatNullSpaceDestroy(&nsp));
  }
  PetscFunctionReturn(0);
}

/* SLEPc's ST makes a KSP that stops short an error of PETSc's, with its traceback, at its set-up: undone before each
   solve, so that ModesInnerSolveCheck tells what to change */
static PetscErrorCode ModesInnerSolveNoPETScError(KSP ksp, Vec rhs, Vec x, void *ctx)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(KSPSetErrorIfNotConverged(ksp, PETSC_FALSE));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetErrorIfFailure(pc, PETSC_FALSE)); /* set by the KSP's set-up inside the ST's */
  PetscFunctionReturn(0);
}

/* an iterative inner solve (any KSP but preonly) checked after each solve by phlex, which names the option to change */
static PetscErrorCode ModesInnerSolvesChecked(PhlexFlexible b, EPS eps, ModesInner *c)
{
  ST        st;
  KSP       ksp;
  PetscBool preonly;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPPREONLY, &preonly));
  if (preonly) {
    /* one application of a preconditioner that is not a direct solve would stand for the inverse: the eigenpairs of
       another operator, silently */
    PC        pc;
    PCType    type;
    PetscBool direct;
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PetscObjectTypeCompareAny((PetscObject)pc, &direct, PCCHOLESKY, PCLU, PCREDUNDANT, PCQR, PCSVD, PCKSP, ""));
    PetscCall(PCGetType(pc, &type));
    PetscCheck(direct, b->comm, PETSC_ERR_USER_INPUT, "-modes_st_pc_type %s with -modes_st_ksp_type preonly: one application of the preconditioner would stand for the shift-and-invert's solve (the eigenpairs of another operator); give a Krylov method (-modes_st_ksp_type cg, options/solver/modes_iterative.opts) or a factorization (-modes_st_pc_type cholesky, the default)", type ? type : "(none)");
    PetscFunctionReturn(0);
  }
  PetscCall(KSPSetPreSolve(ksp, ModesInnerSolveNoPETScError, NULL));
  c->b      = b;
  c->solves = c->its = 0;
  PetscCall(PhlexProgressStart(&c->progress));
  PetscCall(KSPSetPostSolve(ksp, ModesInnerSolveCheck, c));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleModesRequestCheck - refuses, before any work, a request of more eigenpairs than the body's eigensolver
  can give in reason: nev elastic modes (plus a free body's six rigid ones) and the subspace of about twice as many
  vectors the solver builds must fit in the body's velocity unknowns with room (at most a quarter of them asked:
  beyond, the Krylov solver's dense projected problem, of the subspace's size cubed, makes each iteration minutes long
  and deaf to an interrupt: -body0_ic_velocity_mode 1000 on the 2889 unknowns of the cantilever ran 13 minutes), and
  its estimated work, 20 restarts of N ncv^2 + 25 ncv^3 flops (ncv = 2 (nev + rigid)), must stay within -modes_budget
  (1e13 flops: about an hour on one core of these machines; 0: no limit). option and value name what asked
  (-modes_nev 100000, -body0_ic_velocity_mode 1000, -body0_reduction_modes 5000)

  Collective
@*/
PetscErrorCode PhlexFlexibleModesRequestCheck(PhlexPart part, PetscInt nev, const char option[], PetscInt value)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscInt      N, want;
  const PetscReal budget = b->modes_budget;
  PetscReal     ncv, work;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(b->Mv, &N, NULL));
  want = nev + ((!b->frame_patch[0] || b->floating) ? 6 : 0);
  PetscCheck(2 * want <= N, b->comm, PETSC_ERR_USER_INPUT, "body %s: %s %" PetscInt_FMT ": more modes than the body's %" PetscInt_FMT " velocity unknowns allow, at most %" PetscInt_FMT " on this mesh (the eigensolver's subspace holds about twice the pairs asked%s); ask for fewer, or refine the mesh", part->name, option, value, N, PetscMax(N / 2 - (want - nev), 0), want > nev ? ", the six rigid-body modes of a free body among them" : "");
  PetscCheck(4 * want <= N, b->comm, PETSC_ERR_USER_INPUT, "body %s: %s %" PetscInt_FMT ": asks for %.0f %% of the body's %" PetscInt_FMT " velocity unknowns' modes, more than a quarter (at most %" PetscInt_FMT " on this mesh): the eigensolver's subspace, about twice the pairs asked, would be more than half the problem, and its dense projected problem would take minutes per iteration; ask for fewer, or refine the mesh", part->name, option, value, (double)(100.0 * want / N), N, PetscMax(N / 4 - (want - nev), 0));
  ncv  = 2.0 * want;
  work = 20.0 * ((PetscReal)N * ncv * ncv + 25.0 * ncv * ncv * ncv);
  PetscCheck(budget == 0 || work <= budget, b->comm, PETSC_ERR_USER_INPUT, "body %s: %s %" PetscInt_FMT ": the eigensolve of %" PetscInt_FMT " modes on %" PetscInt_FMT " velocity unknowns would take about %.1e flops, more than -modes_budget %g flops (its default 1e13 is about an hour on one core at the 2.5 Gflop/s measured here); ask for fewer modes, or raise -modes_budget (0: no limit) for a long batch run", part->name, option, value, want, N, (double)work, (double)budget);
  PetscFunctionReturn(0);
}

/* the modal analysis's request (-modes_nev), checked, then solved */
PetscErrorCode PhlexFlexibleModesAnalysis(PhlexPart part, PetscInt nev, PetscInt *nconv, PetscInt *nrigid, PetscReal **lambda, Vec **vecs, PetscReal **rigid, PetscReal **resid)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleModesRequestCheck(part, nev, "-modes_nev", nev));
  PetscCall(PhlexFlexibleComputeModes(part, nev, nconv, nrigid, lambda, vecs, rigid, resid));
  PetscFunctionReturn(0);
}

static PetscErrorCode ComputeModes(PhlexPart, PetscBool, PetscInt, PetscInt *, PetscInt *, PetscReal **, Vec **, PetscReal **, PetscReal **);

/*@C
  PhlexFlexibleComputeModes - lowest eigenpairs of K x = lambda Mv x of a flexible body (non-dimensional lambda = omega^2)

  Collective

  Input Parameters:
+ part  - the body
- nev   - number of elastic modes wanted (the six rigid modes of a free body come on top)

  Output Parameters:
+ nconv  - number of eigenpairs returned
. nrigid - how many of them are rigid-body modes (|lambda| below 1e-6 of the elastic frequency scale squared)
. lambda - eigenvalues (ascending; with a target frequency, by their distance to it after the rigid modes)
. vecs   - eigenvectors (Mv-normalised; the elastic part of a floating body's; deflated rigid modes: a free body's
           rigid fields, each Mv-normalised but not Mv-orthogonal to the others, a floating body's zero), may be NULL
. rigid  - floating body: the rigid part (v_P, w_P) of each eigenvector, 6 per mode, on every rank (a deflated rigid
           mode's: e_i); may be NULL
- resid  - relative residual norms ||K x - lambda Mv x|| / (|lambda| ||x||) (rigid modes: the backward error
           ||K x - lambda Mv x|| / ((||K|| + |lambda| ||Mv||) ||x||)), may be NULL: then the caller (a transient's
           initial condition) keeps K bit for bit (the shifted operator is not formed in K's storage)

  Notes:
  A floating body is solved on the pencil of its linearisation at rest (FloatingPencil): six rigid modes, then the
  free-free modes. With mean axes the field's rigid content is constrained away, T^T v = 0 with T = Mv Phi (Phi: the
  six rigid fields; int rho v = 0, int rho (x - P) x v = 0), so the kinetic energy splits into the frame's and the
  field's: the six rigid modes are the frame's own (v = 0), and the elastic ones solve K v = lambda Mv v on the
  Mv-orthogonal complement of Phi (SLEPc's deflation space), i.e. they are the unconstrained free body's. The frame
  modes come first, with zero elastic vectors and unit rigid parts; -modes_eps_nev then counts the elastic modes
  only (with a frame patch it counts all, rigid ones included). With -modes_target_frequency at least a tenth of the
  body's frequency scale (its estimated first bending frequency) a free body's six rigid modes are deflated the same
  way (the rigid fields; a floating pencil's rigid unknowns: v = 0, q = e_i) and listed first; -modes_eps_nev then
  counts the elastic modes only. SLEPc's own -modes_eps_target, the eigenvalue (omega T)^2 in the scene's time unit T,
  is taken the same way.

  Options Database Keys:
+ -modes_eps_nev <n>              - number of eigenpairs (default nev, +6 for a free body whose rigid modes are not deflated)
. -modes_target_frequency <Hz>    - look for modes nearest this frequency (default: lowest)
- -modes_eps_*, -modes_st_*       - any SLEPc EPS/ST option; defaults: phlexblock (block Krylov-Schur), shift-and-invert, Cholesky (MUMPS)
@*/
PetscErrorCode PhlexFlexibleComputeModes(PhlexPart part, PetscInt nev, PetscInt *nconv, PetscInt *nrigid, PetscReal **lambda, Vec **vecs, PetscReal **rigid, PetscReal **resid)
{
  PetscFunctionBeginUser;
  PetscCall(ComputeModes(part, PETSC_TRUE, nev, nconv, nrigid, lambda, vecs, rigid, resid));
  PetscFunctionReturn(0);
}

/*@C
  PhlexModesLowestFirst - whether the modal options leave the eigensolver's default order, the lowest eigenvalues
  first (no -modes_target_frequency, -modes_eps_target, -modes_eps_interval or other choice of which eigenpairs)

  Not collective
@*/
PetscErrorCode PhlexModesLowestFirst(PetscBool *lowest)
{
  const char *const which[] = {"-target_frequency", "-eps_target", "-eps_interval", "-eps_all", "-eps_largest_magnitude", "-eps_smallest_magnitude", "-eps_largest_real", "-eps_smallest_real", "-eps_largest_imaginary", "-eps_smallest_imaginary", "-eps_target_real", "-eps_target_imaginary"};

  PetscFunctionBeginUser;
  *lowest = PETSC_TRUE;
  for (size_t i = 0; i < sizeof(which) / sizeof(which[0]) && *lowest; i++) {
    PetscBool given;
    PetscCall(PetscOptionsHasName(NULL, "modes_", which[i], &given));
    if (given) *lowest = PETSC_FALSE;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleFirstElasticEigenvalue - the lowest elastic eigenvalue of K x = lambda Mv x (non-dimensional), whatever
  target the modal options give (-modes_target_frequency, -modes_eps_target: they choose the modes of a modal analysis
  or a reduction, not this one); the inertia-relief shift of a reduced body on mean axes (reduced_build.c), whose
  refinements divide the error in mode i by 1 + lambda_i / lambda1, at least 2 only with the lowest

  Collective
@*/
PetscErrorCode PhlexFlexibleFirstElasticEigenvalue(PhlexPart part, PetscReal *lambda1)
{
  PetscInt   nconv, nrigid;
  PetscReal *lam;

  PetscFunctionBeginUser;
  PetscCall(ComputeModes(part, PETSC_FALSE, 1, &nconv, &nrigid, &lam, NULL, NULL, NULL));
  PetscCheck(nconv > nrigid, part->comm, PETSC_ERR_NOT_CONVERGED, "body %s: the first elastic mode did not converge", part->name);
  *lambda1 = lam[nrigid];
  PetscCall(PetscFree(lam));
  PetscFunctionReturn(0);
}

/* the eigenpairs of PhlexFlexibleComputeModes(); use_target false: the lowest, whatever target the options give */
static PetscErrorCode ComputeModes(PhlexPart part, PetscBool use_target, PetscInt nev, PetscInt *nconv, PetscInt *nrigid, PetscReal **lambda, Vec **vecs, PetscReal **rigid, PetscReal **resid)
{
  PhlexFlexible     b     = (PhlexFlexible)part->data;
  const PhlexUnits *units = part->units;
  PetscBool         mean_axes = (b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES) ? PETSC_TRUE : PETSC_FALSE;
  EPS           eps;
  PetscReal omega = FrequencyScale(b, units), sigma, ftarget = -1;
  const PetscReal rigid_below = 1e-6 * omega * omega; /* |lambda| below: a rigid mode */
  PetscBool free_body = (!b->frame_patch[0] || b->floating) ? PETSC_TRUE : PETSC_FALSE, flg;
  PetscInt  n, want;
  Mat       A = b->K, B = b->Mv;
  IS        is[2] = {NULL, NULL};
  Vec       x = NULL;
  PhlexPMG  pm = {0};
  ModesInner inner; /* the KSP's post-solve context: lives until the solve's end */
  PetscBool  deflate;
  MatNullSpace rigid_fields = NULL; /* the deflated rigid fields of a free body or mean axes */
  Vec        qmodes[6] = {NULL, NULL, NULL, NULL, NULL, NULL}; /* a floating pencil's deflated rigid unknowns */

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  want  = nev + (free_body ? 6 : 0);
  sigma = free_body ? -PetscSqr(1e-2 * omega) : 0.0;
  PetscCall(PhlexModesEPSCreate(b->comm, &eps, &ftarget, &flg));
  if (!use_target) flg = PETSC_FALSE;
  if (flg) {
    PetscCheck(ftarget >= 0, b->comm, PETSC_ERR_USER_INPUT, "-modes_target_frequency must be >= 0 Hz, got %g", (double)ftarget);
    sigma = PetscSqr(2.0 * PETSC_PI * ftarget * units->time);
    if (sigma == 0 && free_body) sigma = -PetscSqr(1e-2 * omega);
  }
  {
    /* SLEPc's own target, a non-dimensional eigenvalue (omega T)^2, read as -modes_target_frequency's (it wins, as
       EPSSetFromOptions will set it): a free body's rigid modes are then deflated the same way */
    PetscReal target;
    PetscBool given;
    PetscCall(PetscOptionsGetReal(NULL, "modes_", "-eps_target", &target, &given));
    if (given && use_target) {
      sigma = target;
      flg   = PETSC_TRUE;
      if (sigma == 0 && free_body) sigma = -PetscSqr(1e-2 * omega); /* K is singular: as -modes_target_frequency 0 */
    }
  }
  if (b->floating && !mean_axes) PetscCall(FloatingPencil(b, &A, &B, is));
  PetscCall(EPSSetOperators(eps, A, B));
  PetscCall(EPSSetDimensions(eps, want, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(EPSSetTarget(eps, sigma));
  /* the six rigid modes deflated, known exactly: with mean axes (the constraint space, Mv-orthogonal to the rigid
     fields: the frame's own modes), and for a free body's modes nearest a target frequency from a tenth of the
     frequency scale up, where they would be computed to the eigensolver's tolerance times the shift (a few mHz at
     1 kHz, above the rigid threshold: reported as elastic) and only those nearest the target found (a floating
     pencil's rigid unknowns: v = 0, q = e_i). Below a tenth the rigid modes are the pairs nearest the target and come
     out far below rigid_below, and a deflation vector nearly in the null space of A - sigma B would be attached to the
     ST's operator as its null space, which an iterative inner solve projects out. */
  deflate = (PetscBool)(mean_axes || (free_body && flg && sigma >= 1e-2 * omega * omega));
  if (deflate) {
    const Vec *rig;
    PetscInt   nrig;
    PetscBool  has_const;
    if (b->floating && !mean_axes) {
      const PetscInt *qrows;
      PetscInt        nq;
      PetscCall(ISGetLocalSize(is[1], &nq));
      PetscCall(ISGetIndices(is[1], &qrows));
      for (PetscInt i = 0; i < 6; i++) {
        PetscCall(MatCreateVecs(A, &qmodes[i], NULL));
        PetscCall(VecSet(qmodes[i], 0.0));
        if (nq == 6) PetscCall(VecSetValue(qmodes[i], qrows[i], 1.0, INSERT_VALUES));
        PetscCall(VecAssemblyBegin(qmodes[i]));
        PetscCall(VecAssemblyEnd(qmodes[i]));
      }
      PetscCall(ISRestoreIndices(is[1], &qrows));
      PetscCall(EPSSetDeflationSpace(eps, 6, qmodes));
    } else {
      PetscCall(DMPlexCreateRigidBody(b->dm, 0, &rigid_fields));
      PetscCall(MatNullSpaceGetVecs(rigid_fields, &has_const, &nrig, &rig));
      PetscCheck(nrig == 6, b->comm, PETSC_ERR_PLIB, "body %s: %" PetscInt_FMT " rigid-body fields, not 6", b->name, nrig);
      PetscCall(EPSSetDeflationSpace(eps, nrig, (Vec *)rig));
    }
    want -= 6; /* the rigid modes are added below */
    PetscCall(EPSSetDimensions(eps, want, PETSC_DEFAULT, PETSC_DEFAULT));
  }
  PetscCall(EPSSetFromOptions(eps));
  if (flg) PetscCall(EPSSetTarget(eps, sigma)); /* -modes_eps_target 0 on a free body: the substitute above */
  if (!use_target) {
    /* the lowest: the options' target, shift and count undone (-modes_eps_target, -modes_st_shift, -modes_eps_nev,
       which-eigenpairs) */
    ST st;
    PetscCall(EPSSetTarget(eps, sigma));
    PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
    PetscCall(EPSSetDimensions(eps, want, PETSC_DEFAULT, PETSC_DEFAULT));
    PetscCall(EPSGetST(eps, &st));
    PetscCall(STSetShift(st, sigma));
  }
  {
    PetscBool trueres, krylov;
    EPSConv   conv;
    PetscCall(EPSGetTrueResidual(eps, &trueres));
    PetscCall(EPSGetConvergenceTest(eps, &conv));
    /* the types whose convergence loop passes back-transformed eigenvalues with true residuals (others refuse a
       user test, or pass the shift-and-invert Ritz values) */
    PetscCall(PetscObjectTypeCompareAny((PetscObject)eps, &krylov, EPSKRYLOVSCHUR, EPSARNOLDI, ""));
    if (free_body && !deflate && trueres && krylov && conv == EPS_CONV_REL) {
      ConvergedRigidCtx *c;
      PetscCall(PetscNew(&c));
      c->rigid_below = rigid_below;
      PetscCall(MatNorm(A, NORM_INFINITY, &c->nrma));
      PetscCall(MatNorm(B, NORM_INFINITY, &c->nrmb));
      PetscCall(EPSSetConvergenceTestFunction(eps, ConvergedRelativeOrBackward, c, ConvergedRigidDestroy));
    }
  }
  PetscCall(ShiftedOperatorStorage(b, eps, A, B, resid != NULL));
  PetscCall(ModesPMGSetUp(b, eps, A, B, rigid_fields, &pm));
  PetscCall(ModesInnerSolvesChecked(b, eps, &inner));
  {
    char what[PHLEX_NAME_LEN + 8];
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s", part->name));
    PetscCall(PhlexProgressEPSSolve(eps, what));
  }
  PetscCall(EPSGetDimensions(eps, &want, NULL, NULL));
  PetscCall(EPSGetConverged(eps, &n));
  /* a modal analysis that has fewer pairs than asked for says so (a transient's initial mode and the convergence
     study check the modes they need) */
  PetscCheck(!resid || n >= want, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: %" PetscInt_FMT " of the %" PetscInt_FMT " eigenpairs asked of the eigensolver converged (-modes_nev%s, or -modes_eps_nev): raise -modes_eps_max_it or loosen -modes_eps_tol (with -modes_eps_true_residual a relative residual cannot go below the round-off of ||K x|| / lambda, about 1e-11 for a P2 bar)", part->name, n, want, free_body && !deflate ? " plus the 6 rigid-body modes" : "");
  n = PetscMin(n, want);
  {
    /* the deflated rigid modes come first: a floating body's frame modes (v = 0, its rigid part e_i), a free body's
       rigid fields */
    const PetscInt r0 = deflate ? 6 : 0, ntot = n + r0;
    /* the eigenvectors are copied out only for the caller's copies or a floating pencil's rigid parts */
    const PetscBool need_x = (PetscBool)(vecs || (rigid && b->floating && !mean_axes));
    PetscCall(PetscMalloc1(ntot, lambda));
    if (resid) PetscCall(PetscMalloc1(ntot, resid));
    if (vecs) PetscCall(PetscMalloc1(ntot, vecs));
    if (rigid) PetscCall(PetscCalloc1(6 * ntot, rigid));
    for (PetscInt i = 0; i < r0; i++) {
      (*lambda)[i] = 0.0;
      if (resid) (*resid)[i] = 0.0;
      if (vecs) {
        PetscCall(MatCreateVecs(b->K, &(*vecs)[i], NULL));
        if (b->floating) PetscCall(VecSet((*vecs)[i], 0.0));
        else {
          /* the rigid field, Mv-normalised as the eigenvectors */
          const Vec  *rig;
          PetscInt    nrig;
          PetscBool   has_const;
          PetscScalar mm;
          PetscCall(MatNullSpaceGetVecs(rigid_fields, &has_const, &nrig, &rig));
          PetscCall(MatMult(b->Mv, rig[i], (*vecs)[i]));
          PetscCall(VecDot((*vecs)[i], rig[i], &mm));
          PetscCall(VecCopy(rig[i], (*vecs)[i]));
          PetscCall(VecScale((*vecs)[i], 1.0 / PetscSqrtReal(PetscRealPart(mm))));
        }
      }
      if (rigid && b->floating) (*rigid)[6 * i + i] = 1.0;
    }
    *nrigid = r0;
    if (resid) PetscCall(EigenpairResiduals(eps, n, rigid_below, *resid + r0));
    if (need_x) PetscCall(MatCreateVecs(A, &x, NULL));
    for (PetscInt e = 0; e < n; e++) {
      const PetscInt i = r0 + e;
      PetscScalar    kr, ki;
      if (need_x) PetscCall(EPSGetEigenpair(eps, e, &kr, &ki, x, NULL));
      else PetscCall(EPSGetEigenvalue(eps, e, &kr, &ki));
      (*lambda)[i] = PetscRealPart(kr);
      if (PetscAbsReal((*lambda)[i]) < rigid_below) (*nrigid)++; /* its residual is the backward error */
      if (!need_x) continue;
      if (vecs) PetscCall(MatCreateVecs(b->K, &(*vecs)[i], NULL));
      if (!b->floating || mean_axes) {
        if (vecs) PetscCall(VecCopy(x, (*vecs)[i]));
      } else {
        Vec                xv, xq;
        const PetscScalar *qa;
        PetscReal          q6[6] = {0, 0, 0, 0, 0, 0};
        PetscInt           nq;
        PetscCall(VecGetSubVector(x, is[0], &xv));
        if (vecs) PetscCall(VecCopy(xv, (*vecs)[i]));
        PetscCall(VecRestoreSubVector(x, is[0], &xv));
        PetscCall(VecGetSubVector(x, is[1], &xq));
        PetscCall(VecGetLocalSize(xq, &nq));
        PetscCall(VecGetArrayRead(xq, &qa));
        for (PetscInt k = 0; k < nq; k++) q6[k] = PetscRealPart(qa[k]);
        PetscCall(VecRestoreArrayRead(xq, &qa));
        PetscCall(VecRestoreSubVector(x, is[1], &xq));
        PetscCallMPI(MPI_Bcast(q6, 6, MPIU_REAL, 0, b->comm));
        if (rigid) PetscCall(PetscArraycpy(&(*rigid)[6 * i], q6, 6));
      }
    }
    *nconv = ntot;
  }
  PetscCall(VecDestroy(&x));
  if (b->floating && !mean_axes) {
    PetscCall(MatDestroy(&A));
    PetscCall(MatDestroy(&B));
    PetscCall(ISDestroy(&is[0]));
    PetscCall(ISDestroy(&is[1]));
  }
  PetscCall(EPSDestroy(&eps));
  PetscCall(PhlexPMGDestroy(&pm));
  PetscCall(MatNullSpaceDestroy(&rigid_fields));
  for (PetscInt i = 0; i < 6; i++) PetscCall(VecDestroy(&qmodes[i]));
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleModesOutput - writes the mode shapes of a flexible body to <name>_modes.h5/.xmf (normalised to 1; a
  floating body's include the rigid part v_P + w x (x - P), so that the frame patch moves rigidly)

  Collective

  Notes:
  With a placement (r_P non-dimensional, R row-wise: a floating body of an assembly, linearised analysis), the mesh is
  written where the body sits, r_P + R (x - P) (the field inertial_position, the XDMF geometry), and the mode shapes
  in inertial components, scaled as given (the caller normalises the whole assembly alike): the bodies of a mechanism
  then appear assembled in ParaView and warp consistently.
@*/
PetscErrorCode PhlexFlexibleModesOutput(PhlexPart part, PhlexOutput out, PetscInt nconv, PetscInt nrigid, const PetscReal *lambda, Vec *vecs, const PetscReal *rigid, const PetscReal *placement)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *un = part->units;
  PhlexFieldWriter  fw;
  char              name[PHLEX_NAME_LEN + 8];
  PetscReal         rp[3];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_modes", b->name));
  PetscCall(PhlexFieldWriterCreate(out, b, name, &fw));
  if (placement) {
    PetscReal RP[3];
    PhlexMatVec3(&placement[3], b->origin, RP);
    for (PetscInt k = 0; k < 3; k++) rp[k] = placement[k] * un->length - RP[k];
    PetscCall(PhlexFieldWriterSetGeometryField(fw, "inertial_position"));
  }
  for (PetscInt i = 0; i < nconv; i++) {
    PetscReal vmax, A[9] = {0}, r[3] = {0}, *Ap = NULL, *rp0 = NULL;
    if (b->floating) {
      /* the whole velocity field v_P + w x (x - P) + v */
      const PetscReal *q = &rigid[6 * i];
      PetscReal        wP[3];
      PhlexSkew(&q[3], A);
      for (PetscInt k = 0; k < 9; k++) A[k] /= un->length;
      PhlexMatVec3(A, b->origin, wP);
      for (PetscInt k = 0; k < 3; k++) r[k] = q[k] - wP[k];
      Ap = A, rp0 = r;
    }
    /* one body: largest vertex value 1; in an assembly the caller scales all bodies alike (continuous at the joints) */
    if (placement) vmax = 1.0;
    else PetscCall(PhlexFieldWriterVertexMax(fw, vecs[i], 1.0, Ap, rp0, PETSC_FALSE, &vmax));
    if (vmax > 0) {
      for (PetscInt k = 0; k < 9; k++) A[k] /= vmax;
      for (PetscInt k = 0; k < 3; k++) r[k] /= vmax;
    }
    PetscCall(PhlexFieldWriterBeginStep(fw, (PetscReal)(i + 1)));
    if (placement) PetscCall(PhlexFieldWriterSetOutputRotation(fw, &placement[3]));
    PetscCall(PhlexFieldWriterVertexField(fw, "mode_shape", vecs[i], vmax > 0 ? 1.0 / vmax : 1.0, Ap, rp0, PETSC_FALSE));
    if (placement) {
      PetscCall(PhlexFieldWriterSetOutputRotation(fw, NULL));
      PetscCall(PhlexFieldWriterVertexField(fw, "inertial_position", NULL, un->length, &placement[3], rp, PETSC_TRUE));
    }
  }
  PetscCall(PhlexFieldWriterDestroy(&fw));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleRefine - the same body on a mesh refined 'level' more times (convergence studies)

  Collective
@*/
PetscErrorCode PhlexFlexibleRefine(PhlexPart part, PetscInt level, PhlexPart *fine)
{
  PhlexScaleHints h;

  PetscFunctionBeginUser;
  PetscCall(PhlexPartCreate(part->comm, part->index, fine));
  PetscCall(PhlexPartSetFromOptions(*fine));
  ((PhlexFlexible)(*fine)->data)->extra_refinements = level;
  ((PhlexFlexible)(*fine)->data)->process           = ((PhlexFlexible)part->data)->process; /* where -whole_bodies put it */
  (*fine)->units = part->units;
  for (PetscInt k = 0; k < 3; k++) (*fine)->gravity[k] = part->gravity[k];
  PetscCall((*(*fine)->ops.geometry)(*fine, &h));
  PetscCall((*(*fine)->ops.setup)(*fine));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleModesOrder - "P<k> velocity; eigenvalue order expected <2k>" (convergence studies)
@*/
PetscErrorCode PhlexFlexibleModesOrder(PhlexPart part, char buf[], size_t len)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(buf, len, "P%" PetscInt_FMT " velocity; eigenvalue order expected %" PetscInt_FMT, b->degree, 2 * b->degree));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleModesKind - "floating", "clamped" or "free", and the number of rigid-body modes (6 for a free or
  floating body, -1 for a clamped one: not counted)
@*/
PetscErrorCode PhlexFlexibleModesKind(PhlexPart part, char buf[], size_t len, PetscInt *nrigid)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(buf, b->floating ? "floating" : (b->frame_patch[0] ? "clamped" : "free"), len));
  *nrigid = (b->frame_patch[0] && !b->floating) ? -1 : 6;
  PetscFunctionReturn(0);
}
