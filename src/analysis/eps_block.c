/* EPS "phlexblock": block shift-and-invert Krylov-Schur for the symmetric-definite pencils of the modal analyses.

   SLEPc's Krylov-Schur applies the shift-and-invert operator Op = (A - sigma B)^{-1} B to one vector at a time, so a
   modal run is dominated by single-right-hand-side solves with the factor (52 % of the 2.2e5-DOF run, BENCHMARKS.md
   section 11). A solve with many right-hand sides streams the factor once for all of them (MUMPS: 26 right-hand
   sides cost 0.035 s each against 0.26 s for one). This solver builds the Krylov space of Op a block at a time:

     V = [X, Op X, Op^2 X, ...]   (B-orthonormal; the block X of bs vectors random, or the user's initial space)

   with one solve with bs right-hand sides (KSPMatSolve: MatMatSolve of the factor) and one product with B per
   block, keeping the block Arnoldi relation

     Op V[:, 0:j] = V[:, 0:j+bs] H[0:j+bs, 0:j]

   from the orthogonalization coefficients (block classical Gram-Schmidt twice against V, Cholesky QR inside the
   block, a shifted Cholesky QR where the block is numerically rank deficient). B V is kept beside V and carried
   through the same recurrences: it gives the next right-hand sides and the B-inner products without more products
   with B (Krylov-Schur: about three per vector with its B inner product). Without it (-eps_phlexblock_keep_bv 0:
   ncv vectors less memory, a sixth of a 2.2e5-DOF modal run's peak without the factor) B Z is computed again after
   each projection that removed more than round-off, about three products per block. The Ritz pairs (theta, y) of the
   symmetric part of H[0:j, 0:j] give the eigenpairs lambda = sigma + 1/theta, and the Arnoldi relation gives their
   residuals in the transformed problem without another product:

     || Op x - theta x ||_B = || H[j:j+bs, 0:j] y ||.

   This is the residual Krylov-Schur tests, so -eps_tol means the same for both solvers. When the basis is full,
   the search restarts as Krylov-Schur does, with thick restarts: it keeps the best ncv - 2 bs Ritz vectors and the
   last block, with H in arrow form (diagonal of the kept theta, the last block's row), and locks the converged
   ones (out of the later Rayleigh-Ritz problems).

   Works with ST sinvert (the operator's KSP decides the solve: -st_ksp_type, -st_pc_factor_mat_solver_type), for
   Hermitian problems (HEP, GHEP) and the eigenvalues nearest the target, with deflation spaces (EPSSetDeflationSpace)
   and initial spaces. The converged eigenvalues are the Rayleigh quotients of their vectors (one more block solve).
   Options: -eps_phlexblock_block_size <bs> (default: nev, at most 8), -eps_ncv (default the larger of 2 nev + 3 bs
   and nev + 15; at least nev + 3 bs, so that nev must stay 3 below the problem's dimension), -eps_max_it (restart
   cycles; after the first, a cycle is one block step: the default is Krylov-Schur's, times the blocks of half a
   basis), -eps_phlexblock_rayleigh_quotient, -eps_phlexblock_keep_bv. Real scalars only; -eps_true_residual is not
   supported. */
#include <phlex_impl.h>
#include <slepc/private/epsimpl.h>
#include <petscblaslapack.h>

typedef struct {
  PetscInt     bsopt;      /* the block size asked for (-eps_phlexblock_block_size; 0: default) */
  PetscInt     bs;         /* the block size of the current set-up */
  PetscScalar *H;          /* ncv x ncv, column major: the block Arnoldi coefficients */
  PetscInt     keepbvopt;  /* -eps_phlexblock_keep_bv: 1, 0, or -1: decided by the cost of the products with B */
  PetscBool    keepbv;     /* B V kept beside V in this set-up: one product with B per block, else about three */
  BV           BV;         /* B V, column by column (kept through the recurrences, no product with B), or NULL */
  BV           W, Z, BZ;   /* one block: B times the last block of V (the next right-hand sides), the block being
                              orthonormalized and B times it (in W's storage); allocated for a solve only */
  BV           C, BC;      /* the deflation space (constraints of eps->V) and B C, NULL without */
  Mat          Cv, Cc;     /* coefficients against V (ncv x bs), against the constraints (nds x bs) */
  Mat          G, Rm;      /* bs x bs: Gram matrix, inverse of a triangular factor */
  PetscScalar *Rtot;       /* bs x bs: the accumulated triangular factor of a block's orthonormalization */
  PetscScalar *Rf, *Rt;    /* bs x bs work: one triangular factor, a product */
  PetscReal   *cn2;        /* bs: squared norms of the coefficients a projection removed */
  PetscReal   *lock, *lockerr; /* ncv: theta and error estimate of the locked eigenpairs */
  PetscInt     nBexact;    /* products with B beyond one per block (monitoring) */
  PetscBool    refine;     /* the converged eigenvalues from the Rayleigh quotients of their vectors */
} EPS_PhlexBlock;

/* the loss of norm beyond which the projected B Z is recomputed rather than taken from the recurrence: the
   recurrence's round-off relative to the projected block grows with the loss, 1e4 keeps it near 1e-12 */
#define PHLEX_EPS_BLOCK_LOSS 1e4
/* without B V: the relative size of B V C (C the coefficients a projection removed) below which B Z is not computed
   again after it (a few units of round-off) */
#define PHLEX_EPS_BLOCK_STALE 1e-15

/* the eigenvalues nearest the target: in the transformed space, the largest |theta| first */
static PetscErrorCode EPSSetUpSort_PhlexBlock(EPS eps)
{
  PetscFunctionBegin;
  eps->sc->comparison    = SlepcCompareTargetMagnitude;
  eps->sc->comparisonctx = &eps->target;
  eps->sc->map           = NULL;
  eps->sc->mapobj        = NULL;
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSSetDefaultST_PhlexBlock(EPS eps)
{
  PetscFunctionBegin;
  if (!((PetscObject)eps->st)->type_name) PetscCall(STSetType(eps->st, STSINVERT));
  PetscFunctionReturn(0);
}

/* PETSc multiplies SBAIJ by a dense block through a generic path, 4x slower per column (2.2e5 DOFs) than its
   MatMult: V's B-inner products (set at the end, for the normalization) one column at a time. The solver's own
   products with B go through PhlexMatMultBlock. */
static PetscErrorCode SetMatMultMethod(EPS eps, BV bv)
{
  Mat       B;
  PetscBool sbaij;

  PetscFunctionBegin;
  if (!eps->isgeneralized) PetscFunctionReturn(0);
  PetscCall(STGetMatrix(eps->st, 1, &B));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)B, &sbaij, MATSEQSBAIJ, MATMPISBAIJ, ""));
  if (sbaij) PetscCall(BVSetMatMultMethod(bv, BV_MATMULT_VECS));
  PetscFunctionReturn(0);
}

/* a work BV like eps->V with k columns and the Euclidean inner product (the B products are explicit) */
static PetscErrorCode WorkBV(EPS eps, PetscInt k, BV *bv)
{
  PetscFunctionBegin;
  PetscCall(BVDestroy(bv));
  PetscCall(BVDuplicateResize(eps->V, k, bv));
  PetscCall(BVSetMatrix(*bv, NULL, PETSC_FALSE));
  PetscFunctionReturn(0);
}

/* the solve's work space, B V (when kept) and two blocks (B Z in W's storage), exists during the solve only: what follows it (the
   eigenvectors' residuals, the caller's copies of them) then does not add to the peak memory */
static PetscErrorCode AllocateWork(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;

  PetscFunctionBegin;
  if (ctx->keepbv) PetscCall(WorkBV(eps, eps->ncv, &ctx->BV));
  PetscCall(WorkBV(eps, ctx->bs, &ctx->W));
  PetscCall(WorkBV(eps, ctx->bs, &ctx->Z));
  /* B Z shares W's storage: W (the right-hand sides) is read by the solve that makes Z, B Z is formed after it and
     is the next W (SaveBZ) */
  PetscCall(PetscObjectReference((PetscObject)ctx->W));
  ctx->BZ = ctx->W;
  PetscFunctionReturn(0);
}

static PetscErrorCode FreeWork(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;

  PetscFunctionBegin;
  PetscCall(BVDestroy(&ctx->BV));
  PetscCall(BVDestroy(&ctx->W));
  PetscCall(BVDestroy(&ctx->Z));
  PetscCall(BVDestroy(&ctx->BZ));
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSSetUp_PhlexBlock(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  PetscBool       sinvert;
  PetscInt        bs, room;
  const char     *prefix;

  PetscFunctionBegin;
  PetscCheck(!PetscDefined(USE_COMPLEX), PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "EPS phlexblock is written for real scalars");
  PetscCall(EPSGetOptionsPrefix(eps, &prefix));
  if (!prefix) prefix = "";
  EPSCheckHermitianDefinite(eps);
  PetscCall(PetscObjectTypeCompare((PetscObject)eps->st, STSINVERT, &sinvert));
  PetscCheck(sinvert, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "EPS phlexblock applies the shift-and-invert operator: -%sst_type must be sinvert (or -%seps_type another solver)", prefix, prefix);
  if (!eps->which) eps->which = EPS_TARGET_MAGNITUDE;
  PetscCheck(eps->which == EPS_TARGET_MAGNITUDE || eps->which == EPS_TARGET_REAL, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "EPS phlexblock computes the eigenvalues nearest the target (-%seps_target_magnitude); -%seps_type another solver for other parts of the spectrum", prefix, prefix);
  EPSCheckUnsupported(eps, EPS_FEATURE_ARBITRARY | EPS_FEATURE_REGION | EPS_FEATURE_EXTRACTION | EPS_FEATURE_TWOSIDED);
  EPSCheckIgnored(eps, EPS_FEATURE_BALANCE);
  PetscCheck(!eps->trueres, PetscObjectComm((PetscObject)eps), PETSC_ERR_SUP, "EPS phlexblock estimates the residuals from its Arnoldi relation: -%seps_true_residual is not supported", prefix);
  if (eps->nev < 1) eps->nev = 1;
  /* default block size 8: from 6 to 13 the 2.2e5-DOF free-free bar (26 pairs, BENCHMARKS.md) costs the same, more
     vectors in all balancing the cheaper solve per vector of a larger block */
  bs   = ctx->bsopt > 0 ? ctx->bsopt : PetscMin(eps->nev, 8);
  room = eps->n - PetscAbs(eps->nds); /* dimension of the space searched (a deflation space not yet inserted: nds < 0) */
  PetscCheck(room > eps->nev, PetscObjectComm((PetscObject)eps), PETSC_ERR_USER_INPUT, "EPS phlexblock: %" PetscInt_FMT " eigenpairs asked of a problem of dimension %" PetscInt_FMT, eps->nev, room);
  /* small problems: a basis of nev + 3 bs vectors must fit */
  if (eps->nev + 3 * bs > room) bs = PetscMax(1, (room - eps->nev) / 3);
  /* the default basis: 2 nev + 3 bs took 13 block steps against 14 for 2 nev + bs (2.2e5 DOFs, 26 pairs) */
  if (eps->ncv == PETSC_DEFAULT || eps->ncv == PETSC_DECIDE) eps->ncv = PetscMax(2 * eps->nev + 3 * bs, eps->nev + 15);
  eps->ncv = PetscMin(eps->ncv, room);
  PetscCheck(eps->ncv >= eps->nev + 3 * bs, PetscObjectComm((PetscObject)eps), PETSC_ERR_USER_INPUT, "EPS phlexblock: -%seps_ncv %" PetscInt_FMT " is too small for %" PetscInt_FMT " eigenpairs and block size %" PetscInt_FMT " (at least eigenpairs + 3 x block size = %" PetscInt_FMT ")", prefix, eps->ncv, eps->nev, bs, eps->nev + 3 * bs);
  ctx->bs  = bs;
  eps->mpd = eps->ncv;
  /* B V: a product with a block of vectors of the mass (PhlexMatMultBlock on a SeqSBAIJ with 3x3 blocks) costs a few
     sweeps over the vectors: the two more per block cost no time at 2.2e5 DOFs and ncv vectors less memory
     (BENCHMARKS.md section 16); other B go one MatMult per column, and a standard problem's B V is V */
  if (ctx->keepbvopt >= 0) ctx->keepbv = ctx->keepbvopt ? PETSC_TRUE : PETSC_FALSE;
  else if (!eps->isgeneralized) ctx->keepbv = PETSC_FALSE;
  else {
    Mat       B;
    PetscBool seqsbaij;
    PetscInt  bsB;
    PetscCall(STGetMatrix(eps->st, 1, &B));
    PetscCall(PetscObjectTypeCompare((PetscObject)B, MATSEQSBAIJ, &seqsbaij));
    PetscCall(MatGetBlockSize(B, &bsB));
    ctx->keepbv = (PetscBool)!(seqsbaij && bsB == 3);
  }
  /* after the first cycle a cycle is one block step: Krylov-Schur's default restarts, times the blocks of half a
     basis (the vectors one of its restarts adds) */
  if (eps->max_it == PETSC_DEFAULT || eps->max_it == PETSC_DECIDE) eps->max_it = PetscMax(100, 2 * eps->n / eps->ncv) * ((eps->ncv + 2 * bs - 1) / (2 * bs));
  PetscCall(EPSAllocateSolution(eps, 0));
  PetscCall(EPS_SetInnerProduct(eps));
  PetscCall(SetMatMultMethod(eps, eps->V));
  PetscCall(PetscFree(ctx->H));
  PetscCall(PetscCalloc1(eps->ncv * eps->ncv, &ctx->H));
  PetscCall(PetscFree2(ctx->lock, ctx->lockerr));
  PetscCall(PetscMalloc2(eps->ncv, &ctx->lock, eps->ncv, &ctx->lockerr));
  PetscCall(FreeWork(eps)); /* allocated by the solve */
  PetscCall(MatDestroy(&ctx->Cv));
  PetscCall(MatDestroy(&ctx->G));
  PetscCall(MatDestroy(&ctx->Rm));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, eps->ncv, bs, NULL, &ctx->Cv));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, bs, bs, NULL, &ctx->G));
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, bs, bs, NULL, &ctx->Rm));
  PetscCall(PetscFree4(ctx->Rtot, ctx->Rf, ctx->Rt, ctx->cn2));
  PetscCall(PetscMalloc4(bs * bs, &ctx->Rtot, bs * bs, &ctx->Rf, bs * bs, &ctx->Rt, bs, &ctx->cn2));
  PetscFunctionReturn(0);
}

/* BX = B X (a copy for standard problems) */
static PetscErrorCode ApplyB(EPS eps, BV X, BV BX)
{
  PetscFunctionBegin;
  if (eps->isgeneralized) {
    Mat B;
    Mat Xm, Ym;
    PetscCall(STGetMatrix(eps->st, 1, &B));
    PetscCall(BVGetMat(X, &Xm));
    PetscCall(BVGetMat(BX, &Ym));
    PetscCall(PhlexMatMultBlock(B, Xm, Ym));
    PetscCall(BVRestoreMat(BX, &Ym));
    PetscCall(BVRestoreMat(X, &Xm));
  } else PetscCall(BVCopy(X, BX));
  PetscFunctionReturn(0);
}

/* Z = Op W = (A - sigma B)^{-1} B W: one product with B, one solve with bs right-hand sides (KSPMatSolve: MatMatSolve
   of the factor; SLEPc 3.18's sinvert has no STApplyMat); BW is B W when known (NULL: B W is computed and
   overwrites W) */
static PetscErrorCode ApplyOp(EPS eps, BV W, BV BW, BV Z)
{
  Mat X, Y;

  PetscFunctionBegin;
  if (!BW) {
    PetscCall(ApplyB(eps, W, Z));
    PetscCall(BVCopy(Z, W));
    BW = W;
  }
  PetscCall(BVGetMat(BW, &X));
  PetscCall(BVGetMat(Z, &Y));
  PetscCall(STMatMatSolve(eps->st, X, Y));
  PetscCall(BVRestoreMat(Z, &Y));
  PetscCall(BVRestoreMat(BW, &X));
  PetscFunctionReturn(0);
}

/* inverse of the bs x bs upper triangular R (column major) into Rinv (column major) */
static void UpperInverse(PetscInt n, const PetscScalar *R, PetscScalar *Rinv)
{
  for (PetscInt k = 0; k < n * n; k++) Rinv[k] = 0.0;
  for (PetscInt j = 0; j < n; j++) {
    /* solve R x = e_j by back substitution */
    for (PetscInt i = j; i >= 0; i--) {
      PetscScalar s = (i == j) ? 1.0 : 0.0;
      for (PetscInt k = i + 1; k <= j; k++) s -= R[i + k * n] * Rinv[k + j * n];
      Rinv[i + j * n] = s / R[i + i * n];
    }
  }
}

/* Z = Q R with Q B-orthonormal, BZ = (B Q) R alongside (Cholesky QR; shifted by the size of round-off when the Gram
   matrix is numerically singular, Fukaya et al. 2020, so that it never breaks down: then Q's columns are orthonormal
   only to about the square root of the shift and another pass restores it). R (bs x bs, upper) multiplies into
   Rtot. loss: the largest ratio of a column's B-norm before the last projection (its coefficients' squared norms in
   cn2) to its norm after. */
static PetscErrorCode CholQR(EPS eps, PetscScalar *Rtot, PetscBool *shifted, PetscReal *loss)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs  = ctx->bs;
  PetscScalar    *g, *ri, *R = ctx->Rf, *T = ctx->Rt;
  PetscBLASInt    n, lda, info;
  PetscReal       trace = 0;

  PetscFunctionBegin;
  PetscCall(BVDot(ctx->BZ, ctx->Z, ctx->G));
  PetscCall(MatDenseGetArray(ctx->G, &g));
  *loss = 1.0;
  for (PetscInt i = 0; i < bs; i++) {
    const PetscReal gii = PetscRealPart(g[i + i * bs]);
    trace += gii;
    *loss = PetscMax(*loss, gii > 0 ? PetscSqrtReal(1.0 + ctx->cn2[i] / gii) : PETSC_MAX_REAL);
  }
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i <= j; i++) R[i + j * bs] = 0.5 * (g[i + j * bs] + g[j + i * bs]);
  PetscCall(PetscBLASIntCast(bs, &n));
  lda = n;
  PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("U", &n, R, &lda, &info));
  *shifted = PETSC_FALSE;
  if (info) {
    /* Fukaya et al.: s = 11 (m n + n (n + 1)) u ||Z||^2 makes G + s I numerically positive definite */
    const PetscReal s = 11.0 * ((PetscReal)eps->n * bs + bs * (bs + 1)) * PETSC_MACHINE_EPSILON * trace;
    for (PetscInt j = 0; j < bs; j++)
      for (PetscInt i = 0; i <= j; i++) R[i + j * bs] = 0.5 * (g[i + j * bs] + g[j + i * bs]) + (i == j ? s : 0.0);
    PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("U", &n, R, &lda, &info));
    PetscCheck(!info, PetscObjectComm((PetscObject)eps), PETSC_ERR_LIB, "EPS phlexblock: the shifted Cholesky QR of a block failed (LAPACK potrf info %d)", (int)info);
    *shifted = PETSC_TRUE;
  }
  PetscCall(MatDenseRestoreArray(ctx->G, &g));
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = j + 1; i < bs; i++) R[i + j * bs] = 0.0;
  PetscCall(MatDenseGetArray(ctx->Rm, &ri));
  UpperInverse(bs, R, ri);
  PetscCall(MatDenseRestoreArray(ctx->Rm, &ri));
  PetscCall(BVMultInPlace(ctx->Z, ctx->Rm, 0, bs));
  PetscCall(BVMultInPlace(ctx->BZ, ctx->Rm, 0, bs));
  /* Rtot = R Rtot */
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i < bs; i++) {
      PetscScalar s = 0;
      for (PetscInt k = i; k < bs; k++) s += R[i + k * bs] * Rtot[k + j * bs];
      T[i + j * bs] = s;
    }
  for (PetscInt k = 0; k < bs * bs; k++) Rtot[k] = T[k];
  PetscFunctionReturn(0);
}

/* removes from Z (and from BZ: along V only with B V kept) its components along the constraints and V[:, 0:nv],
   B-orthogonally; when j0 >= 0 adds the coefficients against V, times Rtot (bs x bs, NULL for the identity), to
   H[0:nv, j0:j0+bs]. The squared norms of the coefficients removed go to cn2. */
static PetscErrorCode ProjectOut(EPS eps, PetscInt nv, PetscInt j0, const PetscScalar *Rtot)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs = ctx->bs, ld = eps->ncv;
  PetscScalar    *c;

  PetscFunctionBegin;
  for (PetscInt k = 0; k < bs; k++) ctx->cn2[k] = 0;
  if (ctx->C) {
    PetscCall(BVDot(ctx->BZ, ctx->C, ctx->Cc));
    PetscCall(BVMult(ctx->Z, -1.0, 1.0, ctx->C, ctx->Cc));
    PetscCall(BVMult(ctx->BZ, -1.0, 1.0, ctx->BC, ctx->Cc));
    PetscCall(MatDenseGetArray(ctx->Cc, &c));
    for (PetscInt j = 0; j < bs; j++)
      for (PetscInt i = 0; i < eps->nds; i++) ctx->cn2[j] += PetscRealPart(c[i + j * eps->nds] * PetscConj(c[i + j * eps->nds]));
    PetscCall(MatDenseRestoreArray(ctx->Cc, &c));
  }
  if (!nv) PetscFunctionReturn(0);
  PetscCall(BVSetActiveColumns(eps->V, 0, nv));
  PetscCall(BVDot(ctx->BZ, eps->V, ctx->Cv));
  PetscCall(BVMult(ctx->Z, -1.0, 1.0, eps->V, ctx->Cv));
  if (ctx->BV) { /* else BZ is left stale: RefreshBZ */
    PetscCall(BVSetActiveColumns(ctx->BV, 0, nv));
    PetscCall(BVMult(ctx->BZ, -1.0, 1.0, ctx->BV, ctx->Cv));
  }
  PetscCall(MatDenseGetArray(ctx->Cv, &c));
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i < nv; i++) ctx->cn2[j] += PetscRealPart(c[i + j * ld] * PetscConj(c[i + j * ld]));
  if (j0 >= 0)
    for (PetscInt j = 0; j < bs; j++)
      for (PetscInt i = 0; i < nv; i++) {
        PetscScalar s = 0;
        if (Rtot)
          for (PetscInt k = 0; k <= j; k++) s += c[i + k * ld] * Rtot[k + j * bs];
        else s = c[i + j * ld];
        ctx->H[i + (j0 + j) * ld] += s;
      }
  PetscCall(MatDenseRestoreArray(ctx->Cv, &c));
  PetscFunctionReturn(0);
}

/* Without B V, a projection against V leaves BZ as B times the block before it, off by B V C (C the coefficients
   removed, their squared norms in cn2, with those against the constraints, whose B C is applied: a conservative
   test). B Z is computed again unless that is below round-off of what is left of each column (the first projection
   of a Krylov block always removes more; the second, after a small loss, may not). */
static PetscErrorCode RefreshBZ(EPS eps)
{
  EPS_PhlexBlock    *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt     bs  = ctx->bs;
  const PetscScalar *g;
  PetscBool          stale = PETSC_FALSE;

  PetscFunctionBegin;
  PetscCall(BVDot(ctx->BZ, ctx->Z, ctx->G));
  PetscCall(MatDenseGetArrayRead(ctx->G, &g));
  for (PetscInt i = 0; i < bs && !stale; i++) {
    const PetscReal gii = PetscRealPart(g[i + i * bs]);
    if (!(gii > 0) || ctx->cn2[i] > PetscSqr(PHLEX_EPS_BLOCK_STALE) * gii) stale = PETSC_TRUE;
  }
  PetscCall(MatDenseRestoreArrayRead(ctx->G, &g));
  if (stale) {
    PetscCall(ApplyB(eps, ctx->Z, ctx->BZ));
    ctx->nBexact++;
  }
  PetscFunctionReturn(0);
}

/* Z (with BZ = B Z) made B-orthonormal to the constraints and to V[:, 0:nv] (block classical Gram-Schmidt twice,
   more passes while a Cholesky QR needs its shift): Z_in = V[:, 0:nv] H[0:nv, j0:j0+bs] + Z_out Rtot. B Z is carried
   along by the same operations (without B V: computed again after a projection, RefreshBZ), and recomputed where
   the projection cancelled most of a column (its round-off would then be large relative to what is left) or the
   block was numerically rank deficient. */
static PetscErrorCode OrthonormalizeBlock(EPS eps, PetscInt nv, PetscInt j0, PetscScalar *Rtot)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs  = ctx->bs;
  PetscBool       shifted = PETSC_FALSE;
  PetscReal       loss    = 1.0;

  PetscFunctionBegin;
  for (PetscInt k = 0; k < bs * bs; k++) Rtot[k] = (k % bs == k / bs) ? 1.0 : 0.0;
  for (PetscInt pass = 0;; pass++) {
    PetscBool exact;
    PetscCheck(pass < 5, PetscObjectComm((PetscObject)eps), PETSC_ERR_CONV_FAILED, "EPS phlexblock: a block stays numerically dependent on the basis after %" PetscInt_FMT " orthogonalizations", pass);
    PetscCall(ProjectOut(eps, nv, j0, pass ? Rtot : NULL));
    if (!ctx->BV && nv) PetscCall(RefreshBZ(eps));
    PetscCall(CholQR(eps, Rtot, &shifted, &loss));
    exact = (PetscBool)(shifted || loss > PHLEX_EPS_BLOCK_LOSS);
    /* (without B V, B Z was computed after the projection: a large loss needs another pass, not another product) */
    if ((shifted || (exact && ctx->BV)) && eps->isgeneralized) {
      PetscCall(ApplyB(eps, ctx->Z, ctx->BZ));
      ctx->nBexact++;
    }
    if (pass >= 1 && !exact) break;
  }
  PetscFunctionReturn(0);
}

/* B times the new block V[:, nv:nv+bs], BZ, to B V when kept; BZ is W, the next right-hand sides (the last block
   stays the last through a restart) */
static PetscErrorCode SaveBZ(EPS eps, PetscInt nv)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;

  PetscFunctionBegin;
  if (ctx->BV) {
    PetscCall(BVSetActiveColumns(ctx->BV, nv, nv + ctx->bs));
    PetscCall(BVCopy(ctx->BZ, ctx->BV));
  }
  PetscFunctionReturn(0);
}

/* one block step: V[:, nv:nv+bs] from Op V[:, j0:j0+bs], with H[0:nv+bs, j0:j0+bs] */
static PetscErrorCode Expand(EPS eps, PetscInt j0, PetscInt nv)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs = ctx->bs, ld = eps->ncv;

  PetscFunctionBegin;
  /* Z = Op V[:, j0:j0+bs] from W = B V[:, j0:j0+bs], the last block's (one solve), then B Z (one product) */
  PetscCall(ApplyOp(eps, NULL, ctx->W, ctx->Z));
  PetscCall(ApplyB(eps, ctx->Z, ctx->BZ));
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i < nv; i++) ctx->H[i + (j0 + j) * ld] = 0.0;
  PetscCall(OrthonormalizeBlock(eps, nv, j0, ctx->Rtot));
  for (PetscInt j = 0; j < bs; j++)
    for (PetscInt i = 0; i < bs; i++) ctx->H[nv + i + (j0 + j) * ld] = ctx->Rtot[i + j * bs];
  PetscCall(BVSetActiveColumns(eps->V, nv, nv + bs));
  PetscCall(BVCopy(ctx->Z, eps->V));
  PetscCall(SaveBZ(eps, nv));
  PetscCall(BVSetActiveColumns(eps->V, 0, nv + bs));
  PetscFunctionReturn(0);
}

/* Rayleigh-Ritz on the symmetric part of the active H[nlock:j, nlock:j] (the first nlock columns of V are locked
   eigenvectors, their theta in ctx->lock): theta sorted by decreasing |theta| (the eigenvalues nearest the target
   first) after the locked ones, Y (j x j, column major) the Ritz vectors in the basis (the identity on the locked
   ones), res the residual norms || H[j:j+bs, nlock:j] y || of the transformed problem (0 for the locked ones) */
static PetscErrorCode RayleighRitz(EPS eps, PetscInt nlock, PetscInt j, PetscReal *theta, PetscScalar *Y, PetscReal *res)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs = ctx->bs, ld = eps->ncv, m = j - nlock;
  const PetscScalar *H = ctx->H + nlock + nlock * ld; /* the active block */
  PetscScalar    *S, *work;
  PetscReal      *w;
  PetscInt       *order;
  PetscBLASInt    n, lwork, info;

  PetscFunctionBegin;
  PetscCall(PetscArrayzero(Y, j * j));
  for (PetscInt i = 0; i < nlock; i++) {
    theta[i]         = ctx->lock[i];
    Y[i + i * j]     = 1.0;
    res[i]           = 0.0;
  }
  if (!m) PetscFunctionReturn(0);
  PetscCall(PetscMalloc4(m * m, &S, m, &w, 66 * m, &work, m, &order));
  for (PetscInt c = 0; c < m; c++)
    for (PetscInt r = 0; r < m; r++) S[r + c * m] = 0.5 * (H[r + c * ld] + H[c + r * ld]);
  PetscCall(PetscBLASIntCast(m, &n));
  PetscCall(PetscBLASIntCast(66 * m, &lwork));
  PetscCall(PetscFPTrapPush(PETSC_FP_TRAP_OFF));
  PetscCallBLAS("LAPACKsyev", LAPACKsyev_("V", "U", &n, S, &n, w, work, &lwork, &info));
  PetscCall(PetscFPTrapPop());
  PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "EPS phlexblock: LAPACK syev failed (info %d)", (int)info);
  for (PetscInt i = 0; i < m; i++) order[i] = i;
  /* insertion sort by decreasing |w| (m is at most ncv) */
  for (PetscInt i = 1; i < m; i++) {
    PetscInt o = order[i], k = i - 1;
    while (k >= 0 && PetscAbsReal(w[order[k]]) < PetscAbsReal(w[o])) {
      order[k + 1] = order[k];
      k--;
    }
    order[k + 1] = o;
  }
  for (PetscInt i = 0; i < m; i++) {
    PetscReal    r2 = 0;
    PetscScalar *y  = Y + nlock + (nlock + i) * j;
    theta[nlock + i] = w[order[i]];
    for (PetscInt r = 0; r < m; r++) y[r] = S[r + order[i] * m];
    for (PetscInt r = m; r < m + bs; r++) {
      PetscScalar s = 0;
      for (PetscInt k = 0; k < m; k++) s += H[r + k * ld] * y[k];
      r2 += PetscRealPart(s * s);
    }
    res[nlock + i] = PetscSqrtReal(r2);
  }
  PetscCall(PetscFree4(S, w, work, order));
  PetscFunctionReturn(0);
}

/* V[:, 0:k] = V[:, 0:j] Y[:, 0:k] and, on a restart, the last block V[:, j:j+bs] to V[:, k:k+bs], with B V alongside
   (on a restart only: after the final rotation B V is stale, and RefineRitzValues overwrites it) */
static PetscErrorCode Rotate(EPS eps, PetscInt j, const PetscScalar *Y, PetscInt k, PetscBool restart)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs = ctx->bs, nv = restart ? j + bs : j, m = restart ? k + bs : k;
  Mat             Q;
  PetscScalar    *q;

  PetscFunctionBegin;
  PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, nv, nv, NULL, &Q));
  PetscCall(MatDenseGetArray(Q, &q));
  for (PetscInt c = 0; c < k; c++)
    for (PetscInt r = 0; r < j; r++) q[r + c * nv] = Y[r + c * j];
  if (restart)
    for (PetscInt i = 0; i < bs; i++) q[j + i + (k + i) * nv] = 1.0;
  PetscCall(MatDenseRestoreArray(Q, &q));
  PetscCall(BVSetActiveColumns(eps->V, 0, nv));
  PetscCall(BVMultInPlace(eps->V, Q, 0, m));
  if (restart && ctx->BV) {
    PetscCall(BVSetActiveColumns(ctx->BV, 0, nv));
    PetscCall(BVMultInPlace(ctx->BV, Q, 0, m));
  }
  PetscCall(MatDestroy(&Q));
  PetscFunctionReturn(0);
}

/* the first block: the initial space completed by random vectors, B-orthonormal to the deflation space. For
   generalized problems it is first mapped by Op (as SLEPc's EPSGetStartVector does): a random block's high
   frequencies would stay in every Ritz vector at round-off level, and (A - sigma B) amplifies them in the true
   residual (1e-8 instead of 1e-11 on a clamped 432-DOF link) */
static PetscErrorCode FirstBlock(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs  = ctx->bs;

  PetscFunctionBegin;
  if (eps->nini > bs) PetscCall(PetscInfo(eps, "the first %" PetscInt_FMT " of %" PetscInt_FMT " initial vectors start the search (the block size)\n", bs, eps->nini));
  for (PetscInt k = eps->nini; k < bs; k++) PetscCall(BVSetRandomColumn(eps->V, k));
  PetscCall(BVSetActiveColumns(eps->V, 0, bs));
  if (eps->isgeneralized) {
    PetscCall(BVCopy(eps->V, ctx->W));
    PetscCall(ApplyOp(eps, ctx->W, NULL, ctx->Z));
  } else PetscCall(BVCopy(eps->V, ctx->Z));
  PetscCall(ApplyB(eps, ctx->Z, ctx->BZ));
  PetscCall(OrthonormalizeBlock(eps, 0, -1, ctx->Rtot));
  PetscCall(BVCopy(ctx->Z, eps->V));
  PetscCall(SaveBZ(eps, 0));
  PetscFunctionReturn(0);
}

/* theta = (Op x)^T B x / x^T B x for the n converged Ritz vectors in V[:, 0:n] (one product with B, one solve with n
   right-hand sides). The Ritz values of H are accurate only to round-off of its norm, the largest active |theta|:
   before the rigid modes of a free body (theta = 1/|sigma|) are locked at a restart, the elastic ones are off by up
   to 5e-10 (free bar, P2, 2889 DOFs); after, block sizes 2, 4 and 8 agree to 5e-11, as two Krylov-Schur runs (ncv
   32 and 40) do to 3e-11. The Rayleigh quotient of each vector is accurate relative to its own theta: block sizes
   4 and 8 and 2 ranks then agree to 13 digits. -eps_phlexblock_rayleigh_quotient 0 skips it. */
static PetscErrorCode RefineRitzValues(EPS eps, PetscInt n)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  BV              BX = NULL, Z = NULL;
  Vec             x, bx, z;
  PetscInt        m;

  PetscFunctionBegin;
  if (!n) PetscFunctionReturn(0);
  /* B X into B V when kept (no longer needed), else new; Op B X into V's columns n..2n when they exist (free after
     the final rotation; V itself, not a split of it: SLEPc keeps a split's view of the storage, which a later
     BVResize frees), else new: no more memory than the iterations took */
  PetscCall(BVDestroy(&ctx->W));
  PetscCall(BVDestroy(&ctx->Z));
  PetscCall(BVDestroy(&ctx->BZ));
  if (ctx->BV) BX = ctx->BV;
  else PetscCall(WorkBV(eps, n, &BX));
  PetscCall(BVSetActiveColumns(eps->V, 0, n));
  PetscCall(BVSetActiveColumns(BX, 0, n));
  PetscCall(ApplyB(eps, eps->V, BX));
  PetscCall(BVGetSizes(eps->V, NULL, NULL, &m));
  if (2 * n <= m) PetscCall(BVSetActiveColumns(eps->V, n, 2 * n));
  else PetscCall(WorkBV(eps, n, &Z));
  PetscCall(ApplyOp(eps, NULL, BX, Z ? Z : eps->V));
  for (PetscInt i = 0; i < n; i++) {
    PetscScalar num, den;
    PetscCall(BVGetColumn(eps->V, i, &x));
    PetscCall(BVGetColumn(BX, i, &bx));
    PetscCall(BVGetColumn(Z ? Z : eps->V, Z ? i : n + i, &z));
    PetscCall(VecDot(z, bx, &num));
    PetscCall(VecDot(x, bx, &den));
    eps->eigr[i] = num / den;
    PetscCall(BVRestoreColumn(Z ? Z : eps->V, Z ? i : n + i, &z));
    PetscCall(BVRestoreColumn(BX, i, &bx));
    PetscCall(BVRestoreColumn(eps->V, i, &x));
  }
  PetscCall(BVSetActiveColumns(eps->V, 0, n));
  PetscCall(BVDestroy(&Z));
  if (BX != ctx->BV) PetscCall(BVDestroy(&BX));
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSSolve_PhlexBlock(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  const PetscInt  bs = ctx->bs, ncv = eps->ncv, ld = ncv;
  PetscInt        j0 = 0, nv = bs, nconv = 0, nlock = 0, its = 0, steps = 0;
  PetscReal      *theta, *res;
  PetscScalar    *Y;
  Mat             B;
  PetscBool       indef;

  PetscFunctionBegin;
  PetscCall(PetscMalloc3(ncv, &theta, ncv, &res, ncv * ncv, &Y));
  PetscCall(AllocateWork(eps));
  /* the B products are explicit: V's inner product is the Euclidean one during the solve */
  PetscCall(BVGetMatrix(eps->V, &B, &indef));
  PetscCall(PetscObjectReference((PetscObject)B));
  PetscCall(BVSetMatrix(eps->V, NULL, PETSC_FALSE));
  ctx->nBexact = 0;
  /* the deflation space and B times it, as BVs of their own for the block products (none left from a solve that
     failed) */
  PetscCall(BVDestroy(&ctx->C));
  PetscCall(BVDestroy(&ctx->BC));
  if (eps->nds) {
    PetscCall(WorkBV(eps, eps->nds, &ctx->C));
    PetscCall(WorkBV(eps, eps->nds, &ctx->BC));
    for (PetscInt i = 0; i < eps->nds; i++) {
      Vec v;
      PetscCall(BVGetColumn(eps->V, -eps->nds + i, &v));
      PetscCall(BVInsertVec(ctx->C, i, v));
      PetscCall(BVRestoreColumn(eps->V, -eps->nds + i, &v));
    }
    PetscCall(ApplyB(eps, ctx->C, ctx->BC));
    PetscCall(MatDestroy(&ctx->Cc));
    PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, eps->nds, bs, NULL, &ctx->Cc));
  }
  PetscCall(FirstBlock(eps));
  PetscCall(PetscArrayzero(ctx->H, ld * ld));
  while (eps->reason == EPS_CONVERGED_ITERATING) {
    PetscBool full;
    PetscCall(Expand(eps, j0, nv));
    j0 += bs;
    nv += bs;
    steps++;
    PetscCall(RayleighRitz(eps, nlock, j0, theta, Y, res));
    nconv = nlock;
    for (PetscInt i = 0; i < j0; i++) {
      eps->eigr[i] = theta[i];
      eps->eigi[i] = 0.0;
      if (i < nlock) eps->errest[i] = ctx->lockerr[i];
      else {
        PetscScalar re = theta[i], im = 0.0;
        /* as EPSKrylovConvergence: the eigenvalue of the problem for the norm-relative test */
        if (eps->conv == EPS_CONV_NORM) PetscCall(STBackTransform(eps->st, 1, &re, &im));
        PetscCall((*eps->converged)(eps, re, im, res[i], &eps->errest[i], eps->convergedctx));
        if (nconv == i && eps->errest[i] < eps->tol) nconv++;
      }
    }
    /* an iteration is a restart cycle, as in Krylov-Schur (-eps_max_it, the monitors): it ends when the basis is
       full or the wanted pairs have converged */
    full = (PetscBool)(nv + bs > ncv);
    if (!full && nconv < eps->nev) continue;
    eps->its = its + 1;
    PetscCall(EPSMonitor(eps, eps->its, nconv, eps->eigr, eps->eigi, eps->errest, j0));
    PetscCall((*eps->stopping)(eps, eps->its, eps->max_it, nconv, eps->nev, &eps->reason, eps->stoppingctx));
    if (eps->reason != EPS_CONVERGED_ITERATING) break;
    if (full) {
      /* restart (thick, as Krylov-Schur): keep the best ncv - 2 bs Ritz vectors (at least bs beyond the wanted
         ones, for a cluster split at nev) and the last block, so that one new block fits. Keeping half of the
         unconverged ones, as Krylov-Schur does, took 16 block steps against 14 (2.2e5 DOFs, 26 pairs, ncv 60), a
         quarter 47 against 12 (2889 DOFs, ncv 56). The converged ones are locked: out of the
         Rayleigh-Ritz problems from now on (their coupling to the rest, below the tolerance, dropped), so that the
         others' Ritz values and vectors are no longer limited by round-off of the locked theta (the rigid modes'
         1/|sigma|): without locking, the free bar with nev + 2 bs columns stalled at errors of 2e-12 */
      const PetscInt keep = ncv - 2 * bs;
      PetscScalar   *Hn;
      PetscCall(Rotate(eps, j0, Y, keep, PETSC_TRUE));
      /* (nconv < nev <= keep with the default stopping test; a user's test may go on past nev) */
      for (PetscInt i = nlock; i < PetscMin(nconv, keep); i++) {
        ctx->lock[i]    = theta[i];
        ctx->lockerr[i] = eps->errest[i];
      }
      nlock = PetscMin(nconv, keep);
      PetscCall(PetscCalloc1(ld * ld, &Hn));
      for (PetscInt i = 0; i < keep; i++) Hn[i + i * ld] = theta[i];
      for (PetscInt r = 0; r < bs; r++)
        for (PetscInt i = nlock; i < keep; i++) {
          PetscScalar s = 0;
          for (PetscInt k = 0; k < j0; k++) s += ctx->H[j0 + r + k * ld] * Y[k + i * j0];
          Hn[keep + r + i * ld] = s;
        }
      PetscCall(PetscArraycpy(ctx->H, Hn, ld * ld));
      PetscCall(PetscFree(Hn));
      j0 = keep;
      nv = keep + bs;
      its++;
    }
  }
  /* the converged Ritz vectors into the first columns of V (eigenvalues of the transformed problem in eigr) */
  PetscCall(Rotate(eps, j0, Y, nconv, PETSC_FALSE));
  if (ctx->refine) PetscCall(RefineRitzValues(eps, nconv));
  eps->nconv = nconv;
  PetscCall(BVSetMatrix(eps->V, B, indef));
  PetscCall(MatDestroy(&B));
  PetscCall(PetscInfo(eps, "%" PetscInt_FMT " restart cycles, %" PetscInt_FMT " block steps of %" PetscInt_FMT " vectors, %" PetscInt_FMT " products with B beyond one per block%s\n", eps->its, steps, bs, ctx->nBexact, ctx->keepbv ? "" : " (B V not kept)"));
  PetscCall(PetscFree3(theta, res, Y));
  PetscCall(FreeWork(eps));
  PetscCall(BVDestroy(&ctx->C));
  PetscCall(BVDestroy(&ctx->BC));
  PetscCall(MatDestroy(&ctx->Cc));
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSBackTransform_PhlexBlock(EPS eps)
{
  PetscFunctionBegin;
  PetscCall(STBackTransform(eps->st, eps->nconv, eps->eigr, eps->eigi));
  PetscFunctionReturn(0);
}

/* the Ritz vectors are the eigenvectors (B-orthonormal); purification on request (SLEPc's, one solve per vector;
   the modal analyses turn it off) */
static PetscErrorCode EPSComputeVectors_PhlexBlock(EPS eps)
{
  PetscFunctionBegin;
  if (eps->purify) {
    PetscCall(EPS_Purify(eps, eps->nconv));
    PetscCall(BVNormalize(eps->V, NULL));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSSetFromOptions_PhlexBlock(EPS eps, PetscOptionItems *PetscOptionsObject)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  PetscInt        bs  = ctx->bsopt;
  PetscBool       flg;

  PetscFunctionBegin;
  PetscOptionsHeadBegin(PetscOptionsObject, "EPS phlexblock options");
  PetscCall(PetscOptionsInt("-eps_phlexblock_block_size", "Vectors the shift-and-invert operator is applied to at once (default: nev, at most 8)", "EPSPhlexBlock", bs, &bs, &flg));
  if (flg) {
    const char *prefix;
    PetscCall(EPSGetOptionsPrefix(eps, &prefix));
    PetscCheck(bs >= 1, PetscObjectComm((PetscObject)eps), PETSC_ERR_USER_INPUT, "-%seps_phlexblock_block_size must be >= 1, got %" PetscInt_FMT, prefix ? prefix : "", bs);
    ctx->bsopt = bs;
  }
  {
    PetscBool keep = ctx->keepbvopt == 1 ? PETSC_TRUE : PETSC_FALSE, set;
    PetscCall(PetscOptionsBool("-eps_phlexblock_keep_bv", "Keep B V beside the basis V: one product with B per block, else about three and ncv vectors less memory (not given: auto, kept unless B is a sequential 3x3-block SBAIJ, whose block products are cheap; -eps_view says which)", "EPSPhlexBlock", keep, &keep, &set));
    if (set) ctx->keepbvopt = keep ? 1 : 0;
  }
  PetscCall(PetscOptionsBool("-eps_phlexblock_rayleigh_quotient", "Converged eigenvalues from the Rayleigh quotients of their vectors (one more block solve; accurate to 13 digits where the Ritz values agree to about 11)", "EPSPhlexBlock", ctx->refine, &ctx->refine, NULL));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSView_PhlexBlock(EPS eps, PetscViewer viewer)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;
  PetscBool       ascii;

  PetscFunctionBegin;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (ascii) {
    PetscCall(PetscViewerASCIIPrintf(viewer, "  block shift-and-invert Krylov-Schur, block size %" PetscInt_FMT ", eigenvalues from %s\n", ctx->bs, ctx->refine ? "Rayleigh quotients" : "Ritz values"));
    PetscCall(PetscViewerASCIIPrintf(viewer, "  B V %s\n", ctx->keepbv ? "kept beside the basis" : "not kept (B Z computed again after each projection)"));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSReset_PhlexBlock(EPS eps)
{
  EPS_PhlexBlock *ctx = (EPS_PhlexBlock *)eps->data;

  PetscFunctionBegin;
  PetscCall(PetscFree(ctx->H));
  PetscCall(PetscFree2(ctx->lock, ctx->lockerr));
  PetscCall(FreeWork(eps));
  PetscCall(BVDestroy(&ctx->C));
  PetscCall(BVDestroy(&ctx->BC));
  PetscCall(MatDestroy(&ctx->Cv));
  PetscCall(MatDestroy(&ctx->Cc));
  PetscCall(MatDestroy(&ctx->G));
  PetscCall(MatDestroy(&ctx->Rm));
  PetscCall(PetscFree4(ctx->Rtot, ctx->Rf, ctx->Rt, ctx->cn2));
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSDestroy_PhlexBlock(EPS eps)
{
  PetscFunctionBegin;
  PetscCall(EPSReset_PhlexBlock(eps)); /* EPSSetType calls only destroy */
  PetscCall(PetscFree(eps->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode EPSCreate_PhlexBlock(EPS eps)
{
  EPS_PhlexBlock *ctx;

  PetscFunctionBegin;
  PetscCall(PetscNew(&ctx));
  ctx->refine              = PETSC_TRUE;
  ctx->keepbvopt           = -1;
  eps->data                = (void *)ctx;
  eps->categ               = EPS_CATEGORY_KRYLOV;
  eps->useds               = PETSC_FALSE;
  eps->ops->solve          = EPSSolve_PhlexBlock;
  eps->ops->setup          = EPSSetUp_PhlexBlock;
  eps->ops->setupsort      = EPSSetUpSort_PhlexBlock;
  eps->ops->setfromoptions = EPSSetFromOptions_PhlexBlock;
  eps->ops->destroy        = EPSDestroy_PhlexBlock;
  eps->ops->reset          = EPSReset_PhlexBlock;
  eps->ops->view           = EPSView_PhlexBlock;
  eps->ops->backtransform  = EPSBackTransform_PhlexBlock;
  eps->ops->computevectors = EPSComputeVectors_PhlexBlock;
  eps->ops->setdefaultst   = EPSSetDefaultST_PhlexBlock;
  PetscFunctionReturn(0);
}

/*@C
  PhlexEPSRegister - registers EPS "phlexblock" (block shift-and-invert Krylov-Schur)

  Not Collective
@*/
PetscErrorCode PhlexEPSRegister(void)
{
  PetscFunctionBegin;
  PetscCall(EPSRegister(EPSPHLEXBLOCK, EPSCreate_PhlexBlock));
  PetscFunctionReturn(0);
}
