/* A copy of an AIJ matrix in node blocks (BAIJ). The P2 velocity operators couple the 3 components of two nodes as a
   dense 3 x 3 block, so BAIJ reads one column index per 9 entries: its product is 1.7 x faster than AIJ's with inodes
   at 2.2e5 DOFs (BENCHMARKS.md section 43). PETSc 3.18's MatConvert(AIJ -> BAIJ) sets the entries one by one and took
   49 s at 2.2e5 DOFs (and over 10 minutes at 9.5e5) for a product of 17 ms; here each block row is inserted at once:
   the three AIJ rows of a node, stored one after the other, are the row-oriented values of MatSetValuesBlocked. */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateGet: whether the matrix changed since the last fill */

/* whether the local rows of A come in node blocks of bs: the bs rows of a node hold the same columns, whole nodes
   (bs consecutive columns from a multiple of bs); counts each block row's diagonal and off-diagonal blocks */
static PetscErrorCode BlockPattern(Mat A, PetscInt bs, PetscBool upper, PetscInt dnnz[], PetscInt onnz[], PetscInt *maxrow, PetscBool *blocked)
{
  PetscInt  rstart, rend, cstart, cend, cap = 0, *c0 = NULL;

  PetscFunctionBeginUser;
  *blocked = PETSC_TRUE;
  *maxrow  = 0;
  PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
  PetscCall(MatGetOwnershipRangeColumn(A, &cstart, &cend));
  for (PetscInt row = rstart; row < rend && *blocked; row += bs) {
    PetscInt n0 = 0;
    for (PetscInt r = 0; r < bs && *blocked; r++) { /* one row at a time (MatGetRow of MPIAIJ) */
      PetscInt        n;
      const PetscInt *cols;
      PetscCall(MatGetRow(A, row + r, &n, &cols, NULL));
      if (!r) {
        if (n > cap) {
          PetscCall(PetscFree(c0));
          cap = 2 * n;
          PetscCall(PetscMalloc1(cap, &c0));
        }
        n0      = n;
        *maxrow = PetscMax(*maxrow, n);
        PetscCall(PetscArraycpy(c0, cols, n));
      } else if (n != n0) *blocked = PETSC_FALSE;
      else
        for (PetscInt k = 0; k < n && *blocked; k++)
          if (cols[k] != c0[k]) *blocked = PETSC_FALSE;
      PetscCall(MatRestoreRow(A, row + r, &n, &cols, NULL));
    }
    if (n0 % bs) *blocked = PETSC_FALSE;
    for (PetscInt k = 0; k < n0 && *blocked; k += bs) {
      if (c0[k] % bs) *blocked = PETSC_FALSE;
      for (PetscInt c = 1; c < bs && *blocked; c++)
        if (c0[k + c] != c0[k] + c) *blocked = PETSC_FALSE;
      if (upper && c0[k] < row) continue; /* SBAIJ stores the upper triangle */
      if (c0[k] >= cstart && c0[k] < cend) dnnz[(row - rstart) / bs]++;
      else onnz[(row - rstart) / bs]++;
    }
  }
  PetscCall(PetscFree(c0));
  PetscFunctionReturn(0);
}

/* the largest local row length of A */
static PetscErrorCode MaxRowLength(Mat A, PetscInt *maxrow)
{
  PetscInt rstart, rend;

  PetscFunctionBeginUser;
  *maxrow = 0;
  PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
  for (PetscInt row = rstart; row < rend; row++) {
    PetscInt n;
    PetscCall(MatGetRow(A, row, &n, NULL, NULL));
    *maxrow = PetscMax(*maxrow, n);
    PetscCall(MatRestoreRow(A, row, &n, NULL, NULL));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexMatBlockCopy - a BAIJ (symmetric: SBAIJ, the upper triangle) copy of the AIJ matrix A in blocks of its block
  size, with A's values. MAT_INITIAL_MATRIX: a new matrix, or NULL when A's block size is 1 or its pattern is not
  made of whole blocks on every process (the caller keeps A); MAT_REUSE_MATRIX: A's values into the copy *B made
  before from A with the same pattern (the same object, its state raised: whoever holds it sees the new values)

  Collective
@*/
PetscErrorCode PhlexMatBlockCopy(Mat A, PetscBool symmetric, MatReuse reuse, Mat *B)
{
  PetscInt     bs, m, n, mb, rstart, rend, *bcols, maxrow = 0;
  PetscBool    blocked;
  PetscScalar *vals;

  PetscFunctionBeginUser;
  if (reuse == MAT_INITIAL_MATRIX) *B = NULL;
  PetscCall(MatGetBlockSize(A, &bs));
  if (bs < 2) PetscFunctionReturn(0); /* the same on every process */
  PetscCall(PetscLogEventBegin(PHLEX_MatBlockCopy, A, 0, 0, 0));
  if (reuse == MAT_INITIAL_MATRIX) {
    PetscInt *dnnz, *onnz;
    PetscCall(MatGetLocalSize(A, &m, &n));
    blocked = (PetscBool)(m % bs == 0 && n % bs == 0);
    mb      = m / bs;
    PetscCall(PetscCalloc2(mb, &dnnz, mb, &onnz));
    if (blocked) PetscCall(BlockPattern(A, bs, symmetric, dnnz, onnz, &maxrow, &blocked));
    PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &blocked, 1, MPIU_BOOL, MPI_LAND, PetscObjectComm((PetscObject)A)));
    if (!blocked) {
      PetscCall(PetscFree2(dnnz, onnz));
      PetscCall(PetscInfo(A, "not in whole %" PetscInt_FMT " x %" PetscInt_FMT " blocks: no block copy\n", bs, bs));
      PetscCall(PetscLogEventEnd(PHLEX_MatBlockCopy, A, 0, 0, 0));
      PetscFunctionReturn(0);
    }
    PetscCall(MatCreate(PetscObjectComm((PetscObject)A), B));
    PetscCall(MatSetSizes(*B, m, n, PETSC_DETERMINE, PETSC_DETERMINE));
    PetscCall(MatSetBlockSize(*B, bs));
    PetscCall(MatSetType(*B, symmetric ? MATSBAIJ : MATBAIJ));
    PetscCall(MatXAIJSetPreallocation(*B, bs, dnnz, onnz, dnnz, onnz));
    if (symmetric) PetscCall(MatSetOption(*B, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
    PetscCall(MatSetOption(*B, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    PetscCall(PetscFree2(dnnz, onnz));
  } else PetscCall(MaxRowLength(A, &maxrow));
  PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
  PetscCall(PetscMalloc2(maxrow / bs + 1, &bcols, bs * maxrow + 1, &vals));
  for (PetscInt row = rstart; row < rend; row += bs) {
    PetscInt brow = row / bs, nb = 0;
    for (PetscInt r = 0; r < bs; r++) { /* the node's rows side by side: the row-oriented values of its block row */
      PetscInt           ncols;
      const PetscInt    *cols;
      const PetscScalar *a;
      PetscCall(MatGetRow(A, row + r, &ncols, &cols, &a));
      if (!r) {
        nb = ncols / bs;
        for (PetscInt k = 0; k < nb; k++) bcols[k] = cols[k * bs] / bs;
      }
      PetscCall(PetscArraycpy(vals + r * ncols, a, ncols));
      PetscCall(MatRestoreRow(A, row + r, &ncols, &cols, &a));
    }
    PetscCall(MatSetValuesBlocked(*B, 1, &brow, nb, bcols, vals, INSERT_VALUES));
  }
  PetscCall(PetscFree2(bcols, vals));
  PetscCall(MatAssemblyBegin(*B, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*B, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscLogEventEnd(PHLEX_MatBlockCopy, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexMatWatchCheck - what became of A since the last check: another matrix or nonzero pattern than the one watched
  (PHLEX_MAT_NEW: A is watched from now, referenced), new values (PHLEX_MAT_VALUES: its state moved), or nothing

  Not collective
@*/
PetscErrorCode PhlexMatWatchCheck(PhlexMatWatch *w, Mat A, PhlexMatChange *change)
{
  PetscObjectState nz, state;

  PetscFunctionBeginUser;
  PetscCall(MatGetNonzeroState(A, &nz));
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  if (A != w->src || nz != w->nz) {
    PetscCall(PetscObjectReference((PetscObject)A));
    PetscCall(MatDestroy(&w->src));
    w->src  = A;
    *change = PHLEX_MAT_NEW;
  } else *change = state != w->state ? PHLEX_MAT_VALUES : PHLEX_MAT_SAME;
  w->nz    = nz;
  w->state = state;
  PetscFunctionReturn(0);
}

/*@C
  PhlexMatWatchReset - the watched matrix released (the next check answers PHLEX_MAT_NEW)

  Not collective
@*/
PetscErrorCode PhlexMatWatchReset(PhlexMatWatch *w)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&w->src));
  w->nz = w->state = 0;
  PetscFunctionReturn(0);
}

/*@C
  PhlexBlockCopyUpdate - keep bc->copy the node-block copy of A (PhlexMatBlockCopy): a new copy for another matrix or
  a new nonzero pattern (NULL when A is not in whole blocks: remembered, not tried again until then), A's values
  refilled into the same object when A's state moved since the last fill (whoever holds the copy sees them); the
  copy carries A's known symmetry (an assembly forgets it). upper: the copy as the upper triangle (SBAIJ)

  Collective
@*/
PetscErrorCode PhlexBlockCopyUpdate(PhlexBlockCopy *bc, Mat A, PetscBool upper)
{
  PhlexMatChange change;
  PetscBool      set, flg;

  PetscFunctionBeginUser;
  PetscCall(PhlexMatWatchCheck(&bc->watch, A, &change));
  if (change == PHLEX_MAT_NEW) {
    PetscCall(MatDestroy(&bc->copy));
    PetscCall(PhlexMatBlockCopy(A, upper, MAT_INITIAL_MATRIX, &bc->copy));
  } else if (change == PHLEX_MAT_VALUES && bc->copy) PetscCall(PhlexMatBlockCopy(A, upper, MAT_REUSE_MATRIX, &bc->copy));
  if (!bc->copy) PetscFunctionReturn(0);
  PetscCall(MatIsSymmetricKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(bc->copy, MAT_SYMMETRIC, flg));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBlockCopyDestroy - the copy and the reference to its matrix released

  Not collective
@*/
PetscErrorCode PhlexBlockCopyDestroy(PhlexBlockCopy *bc)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&bc->copy));
  PetscCall(PhlexMatWatchReset(&bc->watch));
  PetscFunctionReturn(0);
}
