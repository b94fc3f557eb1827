/* p-multigrid for an iterative solve with the condensed velocity operator A = shift Mv + K/shift (issue 44 item 1):
   PCMG (-<prefix>pc_type mg) with two levels, the bodies' P2 velocities and their P1 coarse space
   (PhlexFlexibleCoarseSpace: P exact, P^T A P the P1 discretisation of the same operator), below which the coarse
   solver (-<prefix>mg_coarse_ksp_type, _pc_type: GAMG, or a factorization of the P1 problem) takes over. Against GAMG
   on the P2 operator: its Galerkin product, the most of its set-up (BENCHMARKS.md section 44), is here one with an
   interpolation of one or two entries per row, and the transfers of each cycle read those few entries.
   The coarse operator carries the bodies' rigid-body modes (the fine operator's near-null space at the vertices,
   exact in P1) for a GAMG below. It is formed again, in place, when the fine operator's values change. */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* the PC's options database (whether -pc_mg_levels was given) */

/*@C
  PhlexPMGSetLevels - ksp's PCMG given phlex's two levels, the P2 velocities and their P1 space, and the levels'
  options read now (the coarse solver's once: PCMG's first set-up would read them again and undo the LU that
  PhlexPMGSetUp chooses for a non-symmetric operator); also where the KSP is another process's (a body whole on one
  process: PCMG reads them at its first set-up, which only the owner makes), and where a run's options are checked
  before its solve (the levels' options are read only once the levels exist). An explicit -pc_mg_levels is refused.

  Collective on the KSP
@*/
PetscErrorCode PhlexPMGSetLevels(KSP ksp)
{
  PC          pc;
  PetscInt    nlevels;
  const char *prefix;
  char        name[256];
  PetscBool   given;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  PetscCall(PetscSNPrintf(name, sizeof(name), "-%spc_mg_levels", prefix ? prefix : ""));
  PetscCall(PetscOptionsHasName(((PetscObject)pc)->options, NULL, name, &given));
  PetscCall(PCMGGetLevels(pc, &nlevels));
  /* phlex sets the levels: a level count from the options would have made PCMG's levels before a body's own
     prefix was set (their options then not read) */
  PetscCheck(!given, PetscObjectComm((PetscObject)pc), PETSC_ERR_USER_INPUT, "%s %" PetscInt_FMT ": phlex's p-multigrid sets its two levels itself, the P2 velocities and their P1 space (a coarser hierarchy comes from the coarse solver, -%smg_coarse_pc_type gamg): remove the option", name, nlevels, prefix ? prefix : "");
  if (nlevels != 2) {
    /* PCMG's one level: two, and PCMG's own options read again for them (-pc_mg_log, ...) */
    PetscCall(PCMGSetLevels(pc, 2, NULL));
    PetscCall(PCSetFromOptions(pc));
  }
  PetscCall(PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE));
  for (PetscInt l = 0; l < 2; l++) {
    KSP smoother;
    PetscCall(PCMGGetSmoother(pc, l, &smoother));
    PetscCall(KSPSetFromOptions(smoother));
    /* the coarse solver's options are read now: PCMG's first set-up would read them again and undo the LU that
       PhlexPMGSetUp chooses for a non-symmetric operator (factoring its Cholesky first) */
    if (!l) PetscCall(KSPSetSkipPCSetFromOptions(smoother, PETSC_TRUE));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPMGBuild - for ksp's PCMG: two levels, and the interpolation from the coarse unknowns of the blocks of an operator's rows (each block's own
  coarse space, from fn), and per local coarse unknown its local fine row; once (kept until PhlexPMGDestroy)

  Collective on the bodies (fn's): every process of the system calls it, also where the operator is another
  process's (a body whole on one process: comm PETSC_COMM_SELF, no rows here)

  Input Parameters:
+ ksp     - the KSP (its PC: PCMG, PhlexPMGWanted)
. comm    - the operator's (and the interpolation's) communicator
. m       - the operator's local rows
. rstart  - the operator's first local row (global)
. bs      - the operator's block size (the interpolation takes 3 x 3 blocks where every block's rows and coarse
            unknowns come in threes)
. nblocks - the blocks of rows
. blocks  - their indices for fn
. off     - their first local rows
- fn, ctx - a block's coarse space: fn(ctx, block, row0, col0, P, &n1, inj), P NULL to count (PhlexFlexibleCoarseSpace)
@*/
PetscErrorCode PhlexPMGBuild(KSP ksp, MPI_Comm comm, PetscInt m, PetscInt rstart, PetscInt bs, PetscInt nblocks, const PetscInt blocks[], const PetscInt off[], PhlexCoarseSpaceFn fn, void *ctx, PhlexPMG *pm)
{
  PetscInt    nc = 0, col0 = 0, *n1;
  PetscInt    threes = (m % 3 == 0);
  PetscMPIInt size;

  PetscFunctionBeginUser;
  if (pm->P) PetscFunctionReturn(0);
  PetscCall(PhlexPMGSetLevels(ksp));
  PetscCall(PetscMalloc1(PetscMax(nblocks, 1), &n1));
  for (PetscInt i = 0; i < nblocks; i++) {
    PetscCall((*fn)(ctx, blocks[i], 0, 0, NULL, &n1[i], NULL));
    nc += n1[i];
    if (n1[i] % 3) threes = 0;
  }
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &threes, 1, MPIU_INT, MPI_MIN, comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (size > 1) {
    PetscCallMPI(MPI_Scan(&nc, &col0, 1, MPIU_INT, MPI_SUM, comm));
    col0 -= nc;
  }
  PetscCall(MatCreateAIJ(comm, m, nc, PETSC_DETERMINE, PETSC_DETERMINE, 2, NULL, 2, NULL, &pm->P));
  PetscCall(MatSetOption(pm->P, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  if (threes && bs == 3) PetscCall(MatSetBlockSizes(pm->P, 3, 3));
  PetscCall(PetscMalloc1(PetscMax(nc, 1), &pm->inj));
  pm->nc = nc;
  for (PetscInt i = 0, c0 = col0, k = 0; i < nblocks; i++) {
    PetscInt n;
    PetscCall((*fn)(ctx, blocks[i], rstart + off[i], c0, pm->P, &n, pm->inj + k));
    for (PetscInt j = 0; j < n; j++) pm->inj[k + j] += off[i];
    c0 += n;
    k += n;
  }
  PetscCall(PetscFree(n1));
  PetscCall(MatAssemblyBegin(pm->P, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(pm->P, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)pm->P, "P1 to P2 interpolation"));
  PetscFunctionReturn(0);
}

/* a fine near-null space (the rigid-body modes) at the coarse unknowns (injection), orthonormalised, as the coarse
   operator's (for a GAMG below) */
static PetscErrorCode CoarseRigidModes(PhlexPMG *pm, MatNullSpace nsp)
{
  PetscBool          has_const;
  PetscInt           n;
  const Vec         *v;
  Vec               *vc;

  PetscFunctionBeginUser;
  if (!nsp) PetscFunctionReturn(0);
  PetscCall(MatNullSpaceGetVecs(nsp, &has_const, &n, &v));
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(n, &vc));
  for (PetscInt j = 0; j < n; j++) {
    const PetscScalar *a;
    PetscScalar       *c;
    PetscCall(MatCreateVecs(pm->Ac, &vc[j], NULL));
    PetscCall(VecGetArrayRead(v[j], &a));
    PetscCall(VecGetArray(vc[j], &c));
    for (PetscInt k = 0; k < pm->nc; k++) c[k] = a[pm->inj[k]];
    PetscCall(VecRestoreArray(vc[j], &c));
    PetscCall(VecRestoreArrayRead(v[j], &a));
    /* Gram-Schmidt, twice */
    for (PetscInt pass = 0; pass < 2; pass++)
      for (PetscInt i = 0; i < j; i++) {
        PetscScalar d;
        PetscCall(VecDot(vc[j], vc[i], &d));
        PetscCall(VecAXPY(vc[j], -d, vc[i]));
      }
    PetscCall(VecNormalize(vc[j], NULL));
  }
  PetscCall(MatNullSpaceCreate(PetscObjectComm((PetscObject)pm->Ac), PETSC_FALSE, n, vc, &nsp));
  PetscCall(MatSetNearNullSpace(pm->Ac, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  for (PetscInt j = 0; j < n; j++) PetscCall(VecDestroy(&vc[j]));
  PetscCall(PetscFree(vc));
  PetscFunctionReturn(0);
}

/* P^T A P is symmetric (positive definite) where A is known to be; the flags again after every product (an
   assembly clears them) */
static PetscErrorCode CoarseSymmetry(PhlexPMG *pm, Mat A)
{
  PetscBool set, flg;

  PetscFunctionBeginUser;
  PetscCall(MatIsSPDKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(pm->Ac, MAT_SPD, flg));
  PetscCall(MatIsSymmetricKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(pm->Ac, MAT_SYMMETRIC, flg));
  PetscFunctionReturn(0);
}

/* A body with its frame's rate in its operator (-<body>_preconditioner_rate_tol) makes A, and so P^T A P, not
   symmetric: a coarse Cholesky would factor one triangle of it. Its LU instead, with the same package where it has
   one (MUMPS), else MUMPS's or PETSc's (CHOLMOD has no LU), as PC phlexbordered does on the fine operator. Once LU,
   it stays LU (an operator symmetric again is factored by LU too) */
static PetscErrorCode CoarseFactorType(KSP coarse, Mat A)
{
  PC            pc;
  PetscBool     chol, set, symm, avail = PETSC_FALSE;
  MatSolverType asked;
  char          package[64] = "";

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(coarse, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCCHOLESKY, &chol));
  PetscCall(MatIsSymmetricKnown(A, &set, &symm));
  if (!chol || !set || symm) PetscFunctionReturn(0);
  PetscCall(PCFactorGetMatSolverType(pc, &asked));
  if (asked) PetscCall(PetscStrncpy(package, asked, sizeof(package))); /* copied: PCSetType frees it */
  if (package[0]) PetscCall(MatGetFactorAvailable(A, package, MAT_FACTOR_LU, &avail));
  if (!avail) {
    PetscCall(PetscStrncpy(package, MATSOLVERMUMPS, sizeof(package)));
    PetscCall(MatGetFactorAvailable(A, package, MAT_FACTOR_LU, &avail));
    if (!avail) package[0] = 0;
  }
  PetscCall(PCSetType(pc, PCLU));
  if (package[0]) PetscCall(PCFactorSetMatSolverType(pc, package));
  PetscCall(PetscInfo(coarse, "p-multigrid: the operator is not symmetric, the coarse level by LU instead of Cholesky, with %s\n", package[0] ? package : "PETSc's default package"));
  PetscFunctionReturn(0);
}

/* ksp's PCMG with the interpolation PhlexPMGBuild made (NULL: another preconditioner) */
static PetscErrorCode BuiltPMG(KSP ksp, PhlexPMG *pm, PC *mgpc)
{
  PC        pc;
  PetscBool mg;
  Mat       Pnow;

  PetscFunctionBeginUser;
  *mgpc = NULL;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, &mg));
  if (!mg) PetscFunctionReturn(0);
  PetscCheck(pm->P, PetscObjectComm((PetscObject)ksp), PETSC_ERR_ORDER, "p-multigrid: PhlexPMGBuild was not called");
  PetscCall(PCMGGetInterpolation(pc, 1, &Pnow));
  if (Pnow != pm->P) PetscCall(PCMGSetInterpolation(pc, 1, pm->P));
  *mgpc = pc;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPMGSetUp - where ksp's preconditioner is PCMG (not GAMG): the interpolation PhlexPMGBuild made and the coarse
  operator P^T A P, formed again when A's values changed. Call after KSPSetOperators, before the KSP's set-up. Other
  preconditioners: nothing.

  Collective on the KSP

  Input Parameters:
+ ksp - the KSP
- A   - the assembled (AIJ) operator (its near-null space: the rigid modes)
@*/
PetscErrorCode PhlexPMGSetUp(KSP ksp, Mat A, PhlexPMG *pm)
{
  PC             pc;
  PhlexMatChange change;
  KSP            coarse;

  PetscFunctionBeginUser;
  PetscCall(BuiltPMG(ksp, pm, &pc));
  if (!pc) PetscFunctionReturn(0);
  PetscCall(PhlexMatWatchCheck(&pm->A, A, &change));
  if (!pm->Ac || change == PHLEX_MAT_NEW) {
    PetscCall(MatDestroy(&pm->Ac));
    PetscCall(PetscLogEventBegin(PHLEX_PMGCoarse, 0, 0, 0, 0));
    PetscCall(MatPtAP(A, pm->P, MAT_INITIAL_MATRIX, 2.0, &pm->Ac));
    PetscCall(PetscLogEventEnd(PHLEX_PMGCoarse, 0, 0, 0, 0));
    PetscCall(PetscObjectSetName((PetscObject)pm->Ac, "coarse operator"));
    {
      MatNullSpace nsp;
      PetscCall(MatGetNearNullSpace(A, &nsp));
      PetscCall(CoarseRigidModes(pm, nsp));
    }
  } else if (change == PHLEX_MAT_VALUES) {
    PetscCall(PetscLogEventBegin(PHLEX_PMGCoarse, 0, 0, 0, 0));
    PetscCall(MatPtAP(A, pm->P, MAT_REUSE_MATRIX, 2.0, &pm->Ac));
    PetscCall(PetscLogEventEnd(PHLEX_PMGCoarse, 0, 0, 0, 0));
  }
  PetscCall(CoarseSymmetry(pm, A));
  PetscCall(PCMGGetCoarseSolve(pc, &coarse));
  PetscCall(CoarseFactorType(coarse, A));
  PetscCall(KSPSetOperators(coarse, pm->Ac, pm->Ac));
  PetscFunctionReturn(0);
}

/* P^T X P of an operator of any storage (a modal analysis's K and Mv are SBAIJ, which MatPtAP does not take: an AIJ
   copy for the product only) */
static PetscErrorCode CoarseProduct(Mat X, Mat P, Mat *C)
{
  PetscBool aij;
  Mat       Xa = X;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectBaseTypeCompareAny((PetscObject)X, &aij, MATSEQAIJ, MATMPIAIJ, ""));
  if (!aij) PetscCall(MatConvert(X, MATAIJ, MAT_INITIAL_MATRIX, &Xa));
  PetscCall(MatPtAP(Xa, P, MAT_INITIAL_MATRIX, 2.0, C));
  if (!aij) PetscCall(MatDestroy(&Xa));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPMGSetUpPencil - where ksp's preconditioner is PCMG: the interpolation PhlexPMGBuild made and the coarse
  operator P^T A P - sigma P^T B P of a shift-and-invert solve with A - sigma B (a modal analysis's ST, whose set-up
  forms the shifted operator and sets its KSP up at once, so the coarse level is formed from the pencil before it).
  Call once, before the eigensolver's set-up. Other preconditioners: nothing.

  Collective on the KSP

  Input Parameters:
+ ksp   - the ST's KSP
. A, B  - the pencil (any storage; both symmetric: the coarse operator is flagged so)
. sigma - the ST's shift
- nsp   - the rigid-body modes in A's layout (the coarse operator's near-null space, for a GAMG below), or NULL
@*/
PetscErrorCode PhlexPMGSetUpPencil(KSP ksp, Mat A, Mat B, PetscScalar sigma, MatNullSpace nsp, PhlexPMG *pm)
{
  PC  pc;
  KSP coarse;
  Mat Bc;

  PetscFunctionBeginUser;
  PetscCall(BuiltPMG(ksp, pm, &pc));
  if (!pc) PetscFunctionReturn(0);
  PetscCheck(!pm->Ac, PetscObjectComm((PetscObject)ksp), PETSC_ERR_ORDER, "p-multigrid: the pencil's coarse operator is formed once");
  PetscCall(PetscLogEventBegin(PHLEX_PMGCoarse, 0, 0, 0, 0));
  PetscCall(CoarseProduct(A, pm->P, &pm->Ac));
  if (sigma != 0.0) {
    PetscCall(CoarseProduct(B, pm->P, &Bc));
    PetscCall(MatAXPY(pm->Ac, -sigma, Bc, UNKNOWN_NONZERO_PATTERN));
    PetscCall(MatDestroy(&Bc));
  }
  PetscCall(PetscLogEventEnd(PHLEX_PMGCoarse, 0, 0, 0, 0));
  PetscCall(PetscObjectSetName((PetscObject)pm->Ac, "coarse operator"));
  PetscCall(MatSetOption(pm->Ac, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(CoarseRigidModes(pm, nsp));
  PetscCall(PCMGGetCoarseSolve(pc, &coarse));
  PetscCall(KSPSetOperators(coarse, pm->Ac, pm->Ac));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPMGWanted - whether ksp's preconditioner is PCMG (exactly: GAMG is one too, with its own hierarchy)

  Not collective
@*/
PetscErrorCode PhlexPMGWanted(KSP ksp, PetscBool *wanted)
{
  PC pc;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCMG, wanted));
  PetscFunctionReturn(0);
}

/* a line for a view: the coarse space's size (nothing without p-multigrid) */
PetscErrorCode PhlexPMGView(PhlexPMG *pm, PetscViewer viewer)
{
  PetscInt M, N;

  PetscFunctionBeginUser;
  if (!pm->P) PetscFunctionReturn(0);
  PetscCall(MatGetSize(pm->P, &M, &N));
  PetscCall(PetscViewerASCIIPrintf(viewer, "  p-multigrid: the P1 coarse space, %" PetscInt_FMT " unknowns below %" PetscInt_FMT "%s\n", N, M, pm->Ac ? "" : " (coarse operator not formed yet)"));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexPMGDestroy(PhlexPMG *pm)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&pm->P));
  PetscCall(MatDestroy(&pm->Ac));
  PetscCall(PhlexMatWatchReset(&pm->A));
  PetscCall(PetscFree(pm->inj));
  PetscFunctionReturn(0);
}
