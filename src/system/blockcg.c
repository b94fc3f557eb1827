/* Block conjugate gradients for PC phlexbordered's border basis Y = A^{-1} W (issue 44 item 2): all the columns of
   W at once, where PETSc 3.18's KSPMatSolve with KSPCG solves them one by one (its block CG is KSPHPDDM's, absent
   from Debian's build). Each iteration reads A once for the whole block (MatMatMult of the AIJ operator with a dense
   block), applies the KSP's preconditioner to the block (PCMatApply: PCMG/PCGAMG apply a block natively, their
   Chebyshev smoothers column by column) and forms small dense Gram matrices.

   Breakdown-free block CG (Ji and Li, "A breakdown-free block conjugate gradient method", BIT 57 (2017)) with
   deflation of converged columns: the search block P is an orthonormalised basis of the span of Z_J + P beta (the
   preconditioned residuals of the active columns J and the previous directions), from the eigendecomposition of its
   Gram matrix with the columns scaled to unit length; directions below 1e-12 of the largest eigenvalue (1e-6 in
   singular values) are dropped, so a rank-deficient residual block (columns converging together, dependent columns
   of W) shrinks the block instead of blowing it up. A column leaves J when it meets the KSP's own test against its
   own right-hand side: its residual norm (the KSP's norm type: preconditioned for CG by default, unpreconditioned,
   natural) at most max(rtol * its initial norm, atol), as the sequential CG solves it replaces. Then

       Q = A P,  G = P^T Q,  alpha = G^{-1} P^T R_J,  X_J += P alpha,  R_J -= Q alpha,  Z_J = M R_J,
       beta = -G^{-1} Q^T Z_J,  P = orth(Z_J + P beta)

   G is factored by LU: with a body's frame rate in its preconditioner (-body<k>_preconditioner_rate_tol) A is
   slightly non-symmetric, where the sequential CG also runs as an inexact solve. */
#include <phlex_impl.h>
#include <petscblaslapack.h>
#include <petsc/private/kspimpl.h>
#include <petsc/private/pcimpl.h>

/* a dense matrix on the first s columns of a column-major array with nloc local rows */
static PetscErrorCode DenseOn(MPI_Comm comm, PetscInt nloc, PetscInt N, PetscInt s, PetscScalar *a, Mat *M)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(M));
  PetscCall(MatCreateDense(comm, nloc, PETSC_DECIDE, N, s, a, M));
  PetscFunctionReturn(0);
}

/* C (m x n, ldc) = alpha op(A) op(B) + beta C, a local product */
static PetscErrorCode Gemm(const char ta[], const char tb[], PetscInt m, PetscInt n, PetscInt k, PetscScalar alpha, const PetscScalar *A, PetscInt lda, const PetscScalar *B, PetscInt ldb, PetscScalar beta, PetscScalar *C, PetscInt ldc)
{
  PetscBLASInt bm, bn, bk, la, lb, lc;

  PetscFunctionBeginUser;
  if (!m || !n) PetscFunctionReturn(0);
  PetscCall(PetscBLASIntCast(m, &bm));
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCall(PetscBLASIntCast(k, &bk));
  PetscCall(PetscBLASIntCast(PetscMax(lda, 1), &la));
  PetscCall(PetscBLASIntCast(PetscMax(ldb, 1), &lb));
  PetscCall(PetscBLASIntCast(PetscMax(ldc, 1), &lc));
  if (!k) {
    for (PetscInt j = 0; j < n; j++)
      for (PetscInt i = 0; i < m; i++) C[i + ldc * j] = beta == 0.0 ? 0.0 : beta * C[i + ldc * j];
    PetscFunctionReturn(0);
  }
  PetscCallBLAS("BLASgemm", BLASgemm_(ta, tb, &bm, &bn, &bk, &alpha, A, &la, B, &lb, &beta, C, &lc));
  PetscCall(PetscLogFlops(2.0 * m * n * k));
  PetscFunctionReturn(0);
}

/* G (m x n) = A^T B over the processes: A (nloc x m, lda), B (nloc x n, ldb) */
static PetscErrorCode Gram(MPI_Comm comm, PetscInt nloc, PetscInt m, PetscInt n, const PetscScalar *A, PetscInt lda, const PetscScalar *B, PetscInt ldb, PetscScalar *G)
{
  PetscFunctionBeginUser;
  PetscCall(Gemm("T", "N", m, n, nloc, 1.0, A, lda, B, ldb, 0.0, G, m));
  if (m && n) PetscCall(MPIU_Allreduce(MPI_IN_PLACE, G, (PetscMPIInt)(m * n), MPIU_SCALAR, MPIU_SUM, comm));
  PetscFunctionReturn(0);
}

/* P (nloc x s) = an orthonormal basis of the span of Praw's n columns (rank-revealing; s <= n) */
static PetscErrorCode Orthonormalise(MPI_Comm comm, PetscInt nloc, PetscInt n, const PetscScalar *Praw, PetscScalar *P, PetscInt *s)
{
  PetscScalar *H, *T, *work;
  PetscReal   *d, *lambda, lmax;
  PetscBLASInt bn, lwork, info;
  PetscInt     keep = 0;

  PetscFunctionBeginUser;
  *s = 0;
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscMalloc5(n * n, &H, n * n, &T, n, &d, n, &lambda, 8 * n + 8, &work));
  PetscCall(Gram(comm, nloc, n, n, Praw, nloc, Praw, nloc, H));
  for (PetscInt j = 0; j < n; j++) d[j] = PetscRealPart(H[j + n * j]) > 0 ? 1.0 / PetscSqrtReal(PetscRealPart(H[j + n * j])) : 0.0;
  for (PetscInt j = 0; j < n; j++)
    for (PetscInt i = 0; i < n; i++) H[i + n * j] *= d[i] * d[j];
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCall(PetscBLASIntCast(8 * n + 8, &lwork));
  PetscCallBLAS("LAPACKsyev", LAPACKsyev_("V", "U", &bn, H, &bn, lambda, work, &lwork, &info)); /* ascending */
  PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_LIB, "block CG: LAPACK syev of the search block's Gram matrix failed (info %d)", (int)info);
  lmax = lambda[n - 1];
  /* T = D V_keep Lambda_keep^{-1/2}, the kept eigenvectors from the largest down */
  for (PetscInt j = n - 1; j >= 0 && lmax > 0; j--) {
    if (lambda[j] <= 1e-12 * lmax) break;
    for (PetscInt i = 0; i < n; i++) T[i + n * keep] = d[i] * H[i + n * j] / PetscSqrtReal(lambda[j]);
    keep++;
  }
  PetscCall(Gemm("N", "N", nloc, keep, n, 1.0, Praw, nloc, T, n, 0.0, P, nloc));
  *s = keep;
  PetscCall(PetscFree5(H, T, d, lambda, work));
  PetscFunctionReturn(0);
}

/* in place: F <- G^{-1} F, G (s x s) LU-factored in Gf/piv, F (s x n) */
static PetscErrorCode SmallSolve(PetscInt s, PetscScalar *Gf, PetscBLASInt *piv, PetscInt n, PetscScalar *F)
{
  PetscBLASInt bs, bn, info;

  PetscFunctionBeginUser;
  if (!s || !n) PetscFunctionReturn(0);
  PetscCall(PetscBLASIntCast(s, &bs));
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &bs, &bn, Gf, &bs, piv, F, &bs, &info));
  PetscCall(PetscLogFlops(2.0 * s * s * n));
  PetscFunctionReturn(0);
}

/* the KSP's norm of each of the n columns of R and Z = M R (nloc rows each) */
static PetscErrorCode ColumnNorms(MPI_Comm comm, KSPNormType type, PetscInt nloc, PetscInt n, const PetscScalar *R, const PetscScalar *Z, PetscReal *nrm)
{
  PetscFunctionBeginUser;
  for (PetscInt j = 0; j < n; j++) {
    const PetscScalar *r = R + nloc * j, *z = Z + nloc * j;
    PetscReal          sum = 0;
    if (type == KSP_NORM_UNPRECONDITIONED)
      for (PetscInt i = 0; i < nloc; i++) sum += PetscRealPart(r[i] * PetscConj(r[i]));
    else if (type == KSP_NORM_NATURAL)
      for (PetscInt i = 0; i < nloc; i++) sum += PetscRealPart(r[i] * PetscConj(z[i]));
    else
      for (PetscInt i = 0; i < nloc; i++) sum += PetscRealPart(z[i] * PetscConj(z[i]));
    nrm[j] = sum;
  }
  PetscCall(PetscLogFlops(2.0 * nloc * n));
  if (n) PetscCall(MPIU_Allreduce(MPI_IN_PLACE, nrm, (PetscMPIInt)n, MPIU_REAL, MPIU_SUM, comm));
  for (PetscInt j = 0; j < n; j++) nrm[j] = PetscSqrtReal(PetscAbsReal(nrm[j]));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBlockCGApplies - whether PhlexBlockCG can replace KSPMatSolve for this KSP: CG (any variant) with a norm to
  test (not KSP_NORM_NONE) and a zero initial guess

  Not collective
@*/
PetscErrorCode PhlexBlockCGApplies(KSP ksp, PetscBool *applies)
{
  KSPNormType type;
  PetscBool   cg, guess;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPCG, &cg));
  PetscCall(KSPGetNormType(ksp, &type));
  PetscCall(KSPGetInitialGuessNonzero(ksp, &guess));
  *applies = (PetscBool)(cg && type != KSP_NORM_NONE && !guess);
  PetscFunctionReturn(0);
}

/*@C
  PhlexBlockCG - X = A^{-1} B for all the columns of B at once by block CG with the KSP's operator, preconditioner
  and tolerances (rtol, atol, max_it, norm type), each column to the KSP's test against its own right-hand side

  Collective on the KSP's communicator when collective is true; else (a sequential solver of one process, with
  nothing collective between the processes) an interrupt stops the iterations locally and leaves X incomplete, for
  the caller's collective PhlexInterruptCheck

  Input Parameters:
+ ksp        - a set-up KSPCG (PhlexBlockCGApplies)
. B          - dense, the right-hand sides
. collective - see above
. matapply   - the preconditioner applied to the block by PCMatApply (else by PCApply column by column)
- what       - what is solved for, for the progress lines and the interrupt message ("border basis of body bar")

  Output Parameters:
+ X          - dense, the solutions (same layout as B)
. its        - the block iterations
- colits     - the sum over the columns of the iterations each took to converge (the column iterations done as a
               block; the sequential solves' total is comparable)
@*/
PetscErrorCode PhlexBlockCG(KSP ksp, Mat B, Mat X, PetscBool collective, PetscBool matapply, const char what[], PetscInt *its, PetscInt *colits)
{
  MPI_Comm           comm;
  Mat                A, Apc, Pm = NULL, Qm = NULL, Rm = NULL, Zm = NULL;
  PC                 pc;
  KSPNormType        ntype;
  PetscReal          rtol, atol, dtol, *nrm, *tol;
  PetscInt           maxit, nloc, N, k, ldb, ldx, nJ, s = 0, sQ = -1, nR = -1, *J, ldq, smax = 0;
  PetscScalar       *Xj, *Rj, *Zj, *P, *Praw, *G, *Gf, *alpha, *beta, *xa;
  const PetscScalar *ba, *qa;
  PetscBLASInt      *piv;
  PetscBool          converged = PETSC_FALSE, stopped = PETSC_FALSE;
  PhlexProgress      progress;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BlockCG, ksp, 0, 0, 0));
  comm = PetscObjectComm((PetscObject)ksp);
  PetscCall(KSPGetOperators(ksp, &A, &Apc));
  {
    /* a node-block (BAIJ) operator on several processes has no product with a dense block in PETSc 3.18 (it would
       multiply column by column, reading the operator once per column): the block product then by the
       preconditioning matrix, which PC phlexbordered (the only caller) makes the AIJ matrix the copy was taken from */
    PetscBool mpibaij;
    PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIBAIJ, &mpibaij));
    if (mpibaij) A = Apc;
  }
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(KSPGetTolerances(ksp, &rtol, &atol, &dtol, &maxit));
  PetscCall(KSPGetNormType(ksp, &ntype));
  PetscCall(MatGetLocalSize(B, &nloc, NULL));
  PetscCall(MatGetSize(B, &N, &k));
  *its = *colits = 0;
  PetscCall(PhlexProgressStart(&progress));
  {
    PCType type;
    PetscCall(PCGetType(pc, &type));
    PetscCall(PetscInfo(ksp, "block CG: preconditioner %s applied to a block %s\n", type, !matapply ? "column by column (PCApply: -block_cg_pc_block 0)" : (pc->ops->matapply ? "natively (PCMatApply)" : "column by column (PCMatApply: none of its own)")));
  }
  PetscCall(PetscMalloc5(nloc * k, &Xj, nloc * k, &Rj, nloc * k, &Zj, nloc * k, &P, nloc * k, &Praw));
  PetscCall(PetscMalloc5(k * k, &G, k * k, &Gf, k * k, &alpha, k * k, &beta, k, &piv));
  PetscCall(PetscMalloc3(k, &nrm, k, &tol, k, &J));
  /* X_J = 0, R_J = B, J all columns */
  PetscCall(MatDenseGetLDA(B, &ldb));
  PetscCall(MatDenseGetArrayRead(B, &ba));
  for (PetscInt j = 0; j < k; j++) {
    PetscCall(PetscArraycpy(Rj + nloc * j, ba + ldb * j, nloc));
    J[j] = j;
  }
  PetscCall(MatDenseRestoreArrayRead(B, &ba));
  PetscCall(PetscArrayzero(Xj, nloc * k));
  nJ = k;
  PetscCall(MatDenseGetLDA(X, &ldx));
  PetscCall(MatDenseGetArrayWrite(X, &xa));
  for (PetscInt it = 0;; it++) {
    PetscInt c, keep;
    /* Z_J = M R_J and the norms; the tolerances from the first */
    if (nR != nJ) {
      PetscCall(DenseOn(comm, nloc, N, nJ, Rj, &Rm));
      PetscCall(DenseOn(comm, nloc, N, nJ, Zj, &Zm));
      nR = nJ;
    }
    if (matapply) PetscCall(PCMatApply(pc, Rm, Zm));
    else {
      /* column by column, on vectors placed on the columns */
      Vec r, z;
      PetscCall(MatCreateVecs(A, &z, &r));
      for (c = 0; c < nJ; c++) {
        PetscCall(VecPlaceArray(r, Rj + nloc * c));
        PetscCall(VecPlaceArray(z, Zj + nloc * c));
        PetscCall(PCApply(pc, r, z));
        PetscCall(VecResetArray(r));
        PetscCall(VecResetArray(z));
      }
      PetscCall(VecDestroy(&r));
      PetscCall(VecDestroy(&z));
    }
    PetscCall(ColumnNorms(comm, ntype, nloc, nJ, Rj, Zj, nrm));
    for (c = 0; c < nJ; c++) PetscCheck(!PetscIsInfOrNanReal(nrm[c]), comm, PETSC_ERR_NOT_CONVERGED, "block CG of the %s: the residual norm of column %" PetscInt_FMT " is not a number at iteration %" PetscInt_FMT, what, J[c], it);
    if (!it)
      for (c = 0; c < nJ; c++) tol[c] = PetscMax(rtol * nrm[c], atol);
    /* beta = -G^{-1} Q^T Z_J, before the converged columns leave */
    if (it) {
      PetscCall(MatDenseGetArrayRead(Qm, &qa));
      PetscCall(MatDenseGetLDA(Qm, &ldq));
      PetscCall(Gram(comm, nloc, s, nJ, qa, ldq, Zj, nloc, beta));
      PetscCall(MatDenseRestoreArrayRead(Qm, &qa));
      for (PetscInt l = 0; l < s * nJ; l++) beta[l] = -beta[l];
      PetscCall(SmallSolve(s, Gf, piv, nJ, beta));
    }
    /* the converged columns leave J (their solution to X); J, X_J, R_J, Z_J, beta compacted */
    keep = 0;
    for (c = 0; c < nJ; c++) {
      const PetscInt j = J[c];
      if (nrm[c] <= tol[J[c]] || nrm[c] == 0.0) {
        PetscCall(PetscArraycpy(xa + ldx * j, Xj + nloc * c, nloc));
        *colits += it;
        continue;
      }
      if (keep != c) {
        J[keep] = j;
        PetscCall(PetscArraycpy(Xj + nloc * keep, Xj + nloc * c, nloc));
        PetscCall(PetscArraycpy(Rj + nloc * keep, Rj + nloc * c, nloc));
        PetscCall(PetscArraycpy(Zj + nloc * keep, Zj + nloc * c, nloc));
        if (it) PetscCall(PetscArraycpy(beta + s * keep, beta + s * c, s));
      }
      keep++;
    }
    if (keep != nJ) PetscCall(PetscInfo(ksp, "block CG iteration %" PetscInt_FMT ": %" PetscInt_FMT " of %" PetscInt_FMT " columns converged\n", it, k - keep, k));
    nJ = keep;
    if (!nJ) {
      converged = PETSC_TRUE;
      break;
    }
    if (it >= maxit) break;
    /* SIGINT/SIGTERM between the iterations (issue 43 item 1), a progress line when due */
    /* also inside a time step (the first step's set-up, or the basis renewed with the operator): a basis can take
       minutes on a large body; a signal here stops the run without a checkpoint of this step (README) */
    if (collective) {
      char phase[192];
      PetscCall(PetscSNPrintf(phase, sizeof(phase), "block CG of the %s (iteration %" PetscInt_FMT ", %" PetscInt_FMT " of %" PetscInt_FMT " columns converged)", what, it, k - nJ, k));
      PetscCall(PhlexProgressPhase(&progress, comm, phase, -1));
    } else if (PhlexInterruptLocal()) {
      stopped = PETSC_TRUE;
      break;
    }
    /* P = orth(Z_J + P beta) */
    PetscCall(PetscArraycpy(Praw, Zj, nloc * nJ));
    if (it) PetscCall(Gemm("N", "N", nloc, nJ, s, 1.0, P, nloc, beta, s, 1.0, Praw, nloc));
    PetscCall(Orthonormalise(comm, nloc, nJ, Praw, P, &s));
    smax = PetscMax(smax, s);
    PetscCheck(s > 0, comm, PETSC_ERR_NOT_CONVERGED, "block CG of the border basis: the search block vanished at iteration %" PetscInt_FMT " with %" PetscInt_FMT " columns not converged (a zero preconditioned residual)", it, nJ);
    /* Q = A P: A read once for the block */
    if (s != sQ) {
      PetscCall(DenseOn(comm, nloc, N, s, P, &Pm));
      PetscCall(MatDestroy(&Qm));
      PetscCall(MatMatMult(A, Pm, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Qm));
      sQ = s;
    } else PetscCall(MatMatMult(A, Pm, MAT_REUSE_MATRIX, PETSC_DEFAULT, &Qm));
    /* G = P^T Q (LU), alpha = G^{-1} P^T R_J; X_J += P alpha, R_J -= Q alpha */
    PetscCall(MatDenseGetArrayRead(Qm, &qa));
    PetscCall(MatDenseGetLDA(Qm, &ldq));
    PetscCall(Gram(comm, nloc, s, s, P, nloc, qa, ldq, G));
    PetscCall(PetscArraycpy(Gf, G, s * s));
    {
      PetscBLASInt bs, info;
      PetscCall(PetscBLASIntCast(s, &bs));
      PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&bs, &bs, Gf, &bs, piv, &info));
      PetscCheck(!info, comm, PETSC_ERR_NOT_CONVERGED, "block CG of the border basis: P^T A P is singular at iteration %" PetscInt_FMT " (LAPACK getrf info %d): the operator is not positive definite on the search block", it, (int)info);
      PetscCall(PetscLogFlops(2.0 * s * s * s / 3.0));
    }
    PetscCall(Gram(comm, nloc, s, nJ, P, nloc, Rj, nloc, alpha));
    PetscCall(SmallSolve(s, Gf, piv, nJ, alpha));
    PetscCall(Gemm("N", "N", nloc, nJ, s, 1.0, P, nloc, alpha, s, 1.0, Xj, nloc));
    PetscCall(Gemm("N", "N", nloc, nJ, s, -1.0, qa, ldq, alpha, s, 1.0, Rj, nloc));
    PetscCall(MatDenseRestoreArrayRead(Qm, &qa));
    (*its)++;
  }
  /* the columns left (not converged, or stopped) */
  for (PetscInt c = 0; c < nJ; c++) {
    PetscCall(PetscArraycpy(xa + ldx * J[c], Xj + nloc * c, nloc));
    *colits += *its;
  }
  PetscCall(MatDenseRestoreArrayWrite(X, &xa));
  PetscCall(PetscInfo(ksp, "block CG: %" PetscInt_FMT " columns, %s after %" PetscInt_FMT " block iterations (%" PetscInt_FMT " column iterations, search block at most %" PetscInt_FMT " wide), rtol %g atol %g\n", k, converged ? "converged" : (stopped ? "interrupted" : "NOT converged"), *its, *colits, smax, (double)rtol, (double)atol));
  PetscCall(MatDestroy(&Pm));
  PetscCall(MatDestroy(&Qm));
  PetscCall(MatDestroy(&Rm));
  PetscCall(MatDestroy(&Zm));
  PetscCall(PetscFree5(Xj, Rj, Zj, P, Praw));
  PetscCall(PetscFree5(G, Gf, alpha, beta, piv));
  PetscCall(PetscFree3(nrm, tol, J));
  PetscCall(PetscLogEventEnd(PHLEX_BlockCG, ksp, 0, 0, 0));
  /* what KSPGetConvergedReason and KSPGetIterationNumber answer after it, as after a KSPSolve */
  ksp->its    = *its;
  ksp->reason = converged ? KSP_CONVERGED_RTOL : (stopped ? KSP_CONVERGED_ITERATING : KSP_DIVERGED_ITS);
  if (!converged && !stopped && ksp->errorifnotconverged) {
    const char *prefix;
    PetscCall(KSPGetOptionsPrefix(ksp, &prefix));
    SETERRQ(comm, PETSC_ERR_NOT_CONVERGED, "block CG of the %s: %" PetscInt_FMT " of %" PetscInt_FMT " columns not converged in %" PetscInt_FMT " iterations (-%sksp_max_it)", what, nJ, k, *its, prefix ? prefix : "");
  }
  PetscFunctionReturn(0);
}
