/* Y = A X for a block of vectors X (a dense matrix). PETSc 3.18 multiplies a symmetric block matrix (SBAIJ, the
   modal analyses' stiffness and mass) by a dense block through a generic path, 4x slower per column than MatMult,
   and MatMult itself reads the whole matrix once per vector (25 ms per product at 2.2e5 DOFs). For a sequential
   SBAIJ with 3x3 blocks the kernel below reads each block once for all the vectors: the block of rows of X it needs
   is packed row-major (the vectors of one node side by side), so each 3x3 block of A is applied to a 3 x k panel,
   and its transpose (the lower triangle, not stored) in the same pass. Other matrices: one MatMult per column. */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateGet */
#include <stdint.h>

#define PHLEX_PANEL 8 /* vectors per pass: a panel of 8 doubles is one cache line */

/* the kernels are compiled for AVX2 and the baseline where GCC can (PHLEX_KERNEL_CLONES, phlex_impl.h) */

/* Y (row-major, n x w) = A X (row-major, n x w), A upper-triangular 3x3-block storage (blocks column-major). With the
   mesh file's numbering the time went into fetching the rows of X and Y of the node a block couples to: a
   compile-time panel width or -O3 -march=native changed nothing (BENCHMARKS.md section 14), a numbering that keeps
   neighbours close (-body<k>_node_order rcm) made it 2.2 x faster; after that the arithmetic shows (the AVX2 clone
   of the scalar kernel below: 10 % of its time, section 16). */
PHLEX_KERNEL_CLONES static void SBAIJ3Panel(PetscInt mbs, const PetscInt *ai, const PetscInt *aj, const MatScalar *aa, PetscInt w, const PetscScalar *X, PetscScalar *Y)
{
  for (PetscInt k = 0; k < 3 * mbs * w; k++) Y[k] = 0.0;
  for (PetscInt i = 0; i < mbs; i++) {
    const PetscScalar *xi = X + 3 * i * w;
    PetscScalar       *yi = Y + 3 * i * w;
    for (PetscInt p = ai[i]; p < ai[i + 1]; p++) {
      const MatScalar *v = aa + 9 * p;
      const PetscInt   j = aj[p];
      if (j == i) { /* the diagonal block: its upper triangle is the stored part */
        for (PetscInt c = 0; c < w; c++) {
          const PetscScalar x0 = xi[c], x1 = xi[w + c], x2 = xi[2 * w + c];
          yi[c] += v[0] * x0 + v[3] * x1 + v[6] * x2;
          yi[w + c] += v[3] * x0 + v[4] * x1 + v[7] * x2;
          yi[2 * w + c] += v[6] * x0 + v[7] * x1 + v[8] * x2;
        }
      } else { /* A_ij x_j into row i, A_ij^T x_i into row j */
        const PetscScalar *xj = X + 3 * j * w;
        PetscScalar       *yj = Y + 3 * j * w;
        for (PetscInt c = 0; c < w; c++) {
          const PetscScalar a0 = xi[c], a1 = xi[w + c], a2 = xi[2 * w + c];
          const PetscScalar b0 = xj[c], b1 = xj[w + c], b2 = xj[2 * w + c];
          yi[c] += v[0] * b0 + v[3] * b1 + v[6] * b2;
          yi[w + c] += v[1] * b0 + v[4] * b1 + v[7] * b2;
          yi[2 * w + c] += v[2] * b0 + v[5] * b1 + v[8] * b2;
          yj[c] += v[0] * a0 + v[1] * a1 + v[2] * a2;
          yj[w + c] += v[3] * a0 + v[4] * a1 + v[5] * a2;
          yj[2 * w + c] += v[6] * a0 + v[7] * a1 + v[8] * a2;
        }
      }
    }
  }
}

/* The same product for a matrix whose 3x3 blocks are multiples of the identity, M (x) I_3 (a velocity mass: each
   component couples only with itself): the blocks' scalars m (one per stored block, in the matrix's order, copied
   once) and the loops over the 3 x w contiguous values of a node, which vectorize: a ninth of the matrix's bytes and a
   third of its arithmetic. The sums run in the order of SBAIJ3Panel, whose zero entries add exact zeros: the two give
   the same bits as long as no multiply-add is fused (the Makefile gives this file -ffp-contract=off). The node loops
   vectorize with GCC's dynamic cost model (also from the Makefile; -O2's default model leaves them scalar): 0.83 ->
   0.66 s for the 22 block products of the 2.2e5-DOF modes. */
PHLEX_KERNEL_CLONES static void SBAIJ3ScalarPanel(PetscInt mbs, const PetscInt *ai, const PetscInt *aj, const MatScalar *m, PetscInt w, const PetscScalar *X, PetscScalar *Y)
{
  const PetscInt w3 = 3 * w;

  for (PetscInt k = 0; k < w3 * mbs; k++) Y[k] = 0.0;
  for (PetscInt i = 0; i < mbs; i++) {
    const PetscScalar *xi = X + w3 * i;
    PetscScalar       *yi = Y + w3 * i;
    for (PetscInt p = ai[i]; p < ai[i + 1]; p++) {
      const MatScalar mp = m[p];
      const PetscInt  j  = aj[p];
      if (j == i) {
        for (PetscInt c = 0; c < w3; c++) yi[c] += mp * xi[c];
      } else {
        const PetscScalar *xj = X + w3 * j;
        PetscScalar       *yj = Y + w3 * j;
        for (PetscInt c = 0; c < w3; c++) {
          yi[c] += mp * xj[c];
          yj[c] += mp * xi[c];
        }
      }
    }
  }
}

typedef struct {
  PetscObjectState state; /* of the matrix when m was taken */
  MatScalar       *m;     /* the blocks' scalars, or NULL: the matrix is not M (x) I_3 */
} ScalarI3;

static PetscErrorCode ScalarI3Destroy(void *ctx)
{
  ScalarI3 *s = (ScalarI3 *)ctx;

  PetscFunctionBeginUser;
  PetscCall(PetscFree(s->m));
  PetscCall(PetscFree(s));
  PetscFunctionReturn(0);
}

/* the blocks' scalars when every stored 3x3 block is a multiple of the identity, bit for bit (of a diagonal block its
   upper triangle, the stored part), else NULL; kept with the matrix and taken again when its state changes */
static PetscErrorCode ScalarTimesI3(Mat A, PetscInt mbs, const PetscInt *ai, const PetscInt *aj, const MatScalar *aa, const MatScalar **m)
{
  PetscContainer   c;
  ScalarI3        *s;
  PetscObjectState state;
  PetscBool        yes = PETSC_TRUE;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectStateGet((PetscObject)A, &state));
  PetscCall(PetscObjectQuery((PetscObject)A, "phlex_scalar_I3", (PetscObject *)&c));
  if (c) {
    PetscCall(PetscContainerGetPointer(c, (void **)&s));
    if (s->state == state) {
      *m = s->m;
      PetscFunctionReturn(0);
    }
  }
  for (PetscInt i = 0; i < mbs && yes; i++)
    for (PetscInt p = ai[i]; p < ai[i + 1] && yes; p++) {
      const MatScalar *v     = aa + 9 * p;
      const PetscBool  lower = (PetscBool)(aj[p] != i && (v[1] != 0.0 || v[2] != 0.0 || v[5] != 0.0));
      if (lower || v[3] != 0.0 || v[6] != 0.0 || v[7] != 0.0 || v[4] != v[0] || v[8] != v[0]) yes = PETSC_FALSE;
    }
  PetscCall(PetscNew(&s));
  s->state = state;
  if (yes) {
    PetscCall(PetscMalloc1(ai[mbs], &s->m));
    for (PetscInt p = 0; p < ai[mbs]; p++) s->m[p] = aa[9 * p];
  }
  PetscCall(PetscContainerCreate(PetscObjectComm((PetscObject)A), &c));
  PetscCall(PetscContainerSetPointer(c, s));
  PetscCall(PetscContainerSetUserDestroy(c, ScalarI3Destroy));
  PetscCall(PetscObjectCompose((PetscObject)A, "phlex_scalar_I3", (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  *m = s->m;
  PetscFunctionReturn(0);
}

/*@C
  PhlexMatMultBlock - Y = A X for the columns of the dense matrices X and Y (same number of columns)

  Collective
@*/
PetscErrorCode PhlexMatMultBlock(Mat A, Mat X, Mat Y)
{
  PetscBool  seqsbaij;
  PetscInt   bs, k, n;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_MatMultBlock, A, X, Y, 0));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQSBAIJ, &seqsbaij));
  PetscCall(MatGetBlockSize(A, &bs));
  PetscCall(MatGetSize(X, NULL, &k));
  {
    PetscInt ky;
    PetscCall(MatGetSize(Y, NULL, &ky));
    PetscCheck(ky == k, PetscObjectComm((PetscObject)A), PETSC_ERR_ARG_SIZ, "PhlexMatMultBlock: X has %" PetscInt_FMT " columns, Y %" PetscInt_FMT, k, ky);
  }
  PetscCall(MatGetLocalSize(A, &n, NULL));
  if (seqsbaij && bs == 3 && k > 1) {
    const PetscInt    *ai, *aj;
    PetscInt           mbs, ldx, ldy;
    PetscBool          done;
    const MatScalar   *m = NULL;
    MatScalar         *aa;
    const PetscScalar *x;
    PetscScalar       *y, *xbuf, *yp;
    PetscBool          inY;
    PetscCall(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &mbs, &ai, &aj, &done));
    PetscCheck(done, PETSC_COMM_SELF, PETSC_ERR_PLIB, "MatGetRowIJ failed on a SeqSBAIJ matrix");
    PetscCall(MatSeqSBAIJGetArray(A, &aa));
    PetscCall(MatDenseGetLDA(X, &ldx));
    PetscCall(MatDenseGetLDA(Y, &ldy));
    PetscCall(MatDenseGetArrayRead(X, &x));
    PetscCall(MatDenseGetArrayWrite(Y, &y));
    PetscCall(ScalarTimesI3(A, mbs, ai, aj, aa, &m));
    /* the packed panel of X goes into the columns of Y it is the product for, when they are contiguous and apart from
       X (the memory of one panel less: it counts in the modal solve's peak); else into a buffer */
    {
      const uintptr_t x0 = (uintptr_t)x, x1 = x0 + sizeof(PetscScalar) * (size_t)ldx * (size_t)k;
      const uintptr_t y0 = (uintptr_t)y, y1 = y0 + sizeof(PetscScalar) * (size_t)ldy * (size_t)k;
      inY = (PetscBool)(ldy == n && (y1 <= x0 || x1 <= y0));
    }
    PetscCall(PetscMalloc2(inY ? 0 : n * PHLEX_PANEL, &xbuf, n * PHLEX_PANEL, &yp));
    for (PetscInt c0 = 0; c0 < k; c0 += PHLEX_PANEL) {
      const PetscInt w  = PetscMin(PHLEX_PANEL, k - c0);
      PetscScalar   *xp = inY ? y + (size_t)c0 * ldy : xbuf;
      for (PetscInt r = 0; r < n; r++)
        for (PetscInt c = 0; c < w; c++) xp[r * w + c] = x[(c0 + c) * ldx + r];
      if (m) SBAIJ3ScalarPanel(mbs, ai, aj, m, w, xp, yp);
      else SBAIJ3Panel(mbs, ai, aj, aa, w, xp, yp);
      for (PetscInt r = 0; r < n; r++) /* each row of the panel read once, written to w sequential streams */
        for (PetscInt c = 0; c < w; c++) y[(c0 + c) * ldy + r] = yp[r * w + c];
    }
    PetscCall(PetscFree2(xbuf, yp));
    PetscCall(MatDenseRestoreArrayWrite(Y, &y));
    PetscCall(MatDenseRestoreArrayRead(X, &x));
    PetscCall(MatSeqSBAIJRestoreArray(A, &aa));
    PetscCall(PetscLogFlops((m ? 4.0 * 3.0 : 4.0 * 9.0) * (PetscLogDouble)ai[mbs] * (PetscLogDouble)k));
    PetscCall(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_TRUE, &mbs, &ai, &aj, &done));
  } else {
    for (PetscInt c = 0; c < k; c++) {
      Vec xc, yc;
      PetscCall(MatDenseGetColumnVecRead(X, c, &xc));
      PetscCall(MatDenseGetColumnVecWrite(Y, c, &yc));
      PetscCall(MatMult(A, xc, yc));
      PetscCall(MatDenseRestoreColumnVecWrite(Y, c, &yc));
      PetscCall(MatDenseRestoreColumnVecRead(X, c, &xc));
    }
  }
  PetscCall(PetscLogEventEnd(PHLEX_MatMultBlock, A, X, Y, 0));
  PetscFunctionReturn(0);
}
