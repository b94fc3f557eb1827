/* A sparse matrix whose rows come in runs that share one short list of columns, stored as one dense block per run:
   the stress rows of a cell in G and in B = Ms^{-1} G (24 rows, the cell's 30 velocity columns). MatMult of the AIJ
   form streams 12 bytes per entry (value and column index) and with rows of 30 entries ran at half the machine's
   bandwidth (62 ms per product with the 3.5e7 entries at 2.2e5 velocity DOFs, BENCHMARKS.md section 17); a block
   streams 8 bytes per entry and one column list per run.

   The sums are those of the AIJ products they replace, term by term in the same order: y_i = sum_j a_ij x_j over j
   ascending for MatMult, and y_j = sum_i a_ij x_i over i ascending for MatMultTranspose (as MatMultTranspose of A
   adds them), each started from zero. Where PETSc's MatMult uses inodes (rows of one pattern, as here) it adds the
   terms two at a time, and so do the blocks; MatMultTranspose has no inode variant and adds them one at a time. On
   several processes MatMult pairs the owned columns only and adds the ghost columns' terms one at a time after them,
   as MPIAIJ does, and the transpose adds the ghost sums on their owners as MPIAIJ does: the same bits there too.
   The same bits hold where PETSc was compiled, as Debian's x86-64 build is, without fused multiply-adds (this file
   is compiled with -ffp-contract=off); on a processor where the compiler fuses them by default (aarch64) they may
   differ in the last bits. */
#include <phlex_impl.h>

/* the layout of the blocks: column-major for MatMult (a column of the block times one x, across the rows: the
   compiler vectorizes it), row-major for MatMultTranspose (a row times one x, across the columns) */
typedef struct {
  PetscInt    nb;         /* runs of rows */
  PetscInt   *rstart;     /* nb + 1: first local row of each run */
  PetscInt   *cstart;     /* nb + 1: start of each run's columns in col */
  PetscInt   *col;        /* local columns: owned 0..n-1, ghosts n..n+nghost-1 */
  PetscInt   *nown;       /* nb: each run's owned columns (they come first; MatMult pairs only those) */
  size_t     *vstart;     /* nb + 1: start of each run's block in val */
  MatScalar  *val;        /* the blocks */
  PetscBool   transpose;  /* row-major blocks, laid out for MatMultTranspose */
  PetscBool   pairwise;   /* MatMult: terms added in pairs, as AIJ's MatMult with inodes (never for the transpose) */
  PetscInt    n;          /* owned columns */
  PetscInt    nghost;     /* ghost columns (several processes) */
  Vec         ghost;      /* the ghost columns' values (several processes) */
  VecScatter  toghost;    /* owned vector -> ghost (several processes, NULL on one) */
  PetscScalar *work;      /* n + nghost: x, or y, with its ghosts behind it (several processes) */
  PetscScalar *acc;       /* a block's sums: its longest row or column */
  PetscLogDouble nnz;     /* stored entries (flops of a product: 2 nnz) */
} RowBlocks;

/* y = A x, A column-major blocks; x indexed by the local columns. Pairwise: the owned columns' terms added two at a
   time, as PETSc's AIJ product with inodes does (sum += a_ij x_j + a_ij+1 x_j+1), the ghost columns' one at a time. */
PHLEX_KERNEL_CLONES static void MultKernel(const RowBlocks *rb, const PetscScalar *x, PetscScalar *y, PetscScalar *acc)
{
  const PetscInt step = rb->pairwise ? 2 : 1;
  for (PetscInt b = 0; b < rb->nb; b++) {
    const PetscInt   r0 = rb->rstart[b], nr = rb->rstart[b + 1] - r0, *c = rb->col + rb->cstart[b], nc = rb->cstart[b + 1] - rb->cstart[b];
    const MatScalar *v  = rb->val + rb->vstart[b];
    const PetscInt   nd = rb->nown[b];
    PetscInt         j  = 0;
    for (PetscInt i = 0; i < nr; i++) acc[i] = 0.0;
    for (; step == 2 && j + 1 < nd; j += 2) {
      const PetscScalar x0 = x[c[j]], x1 = x[c[j + 1]];
      const MatScalar  *v0 = v + j * nr, *v1 = v0 + nr;
      for (PetscInt i = 0; i < nr; i++) acc[i] += v0[i] * x0 + v1[i] * x1;
    }
    for (; j < nc; j++) {
      const PetscScalar x0 = x[c[j]];
      const MatScalar  *v0 = v + j * nr;
      for (PetscInt i = 0; i < nr; i++) acc[i] += v0[i] * x0;
    }
    for (PetscInt i = 0; i < nr; i++) y[r0 + i] = acc[i];
  }
}

/* y += A^T x, A row-major blocks; y indexed by the local columns; one row's terms at a time, as AIJ's
   MatMultTranspose adds them */
PHLEX_KERNEL_CLONES static void MultTransposeKernel(const RowBlocks *rb, const PetscScalar *x, PetscScalar *y, PetscScalar *acc)
{
  for (PetscInt b = 0; b < rb->nb; b++) {
    const PetscInt   r0 = rb->rstart[b], nr = rb->rstart[b + 1] - r0, *c = rb->col + rb->cstart[b], nc = rb->cstart[b + 1] - rb->cstart[b];
    const MatScalar *v  = rb->val + rb->vstart[b];
    for (PetscInt j = 0; j < nc; j++) acc[j] = y[c[j]];
    for (PetscInt i = 0; i < nr; i++) {
      const PetscScalar x0 = x[r0 + i];
      const MatScalar  *v0 = v + i * nc;
      for (PetscInt j = 0; j < nc; j++) acc[j] += v0[j] * x0;
    }
    for (PetscInt j = 0; j < nc; j++) y[c[j]] = acc[j];
  }
}

static PetscErrorCode MatMult_RowBlocks(Mat A, Vec x, Vec y)
{
  RowBlocks         *rb;
  const PetscScalar *xa;
  PetscScalar       *ya, *acc;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &rb));
  acc = rb->acc;
  if (rb->toghost) {
    const PetscScalar *ga;
    PetscCall(VecScatterBegin(rb->toghost, x, rb->ghost, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(rb->toghost, x, rb->ghost, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArrayRead(rb->ghost, &ga));
    PetscCall(PetscArraycpy(rb->work, xa, rb->n));
    PetscCall(PetscArraycpy(rb->work + rb->n, ga, rb->nghost));
    PetscCall(VecRestoreArrayRead(rb->ghost, &ga));
    PetscCall(VecRestoreArrayRead(x, &xa));
    xa = rb->work;
  } else PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayWrite(y, &ya));
  MultKernel(rb, xa, ya, acc);
  PetscCall(VecRestoreArrayWrite(y, &ya));
  if (!rb->toghost) PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(PetscLogFlops(2.0 * rb->nnz));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMultTranspose_RowBlocks(Mat A, Vec x, Vec y)
{
  RowBlocks         *rb;
  const PetscScalar *xa;
  PetscScalar       *ya, *acc, *ye;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &rb));
  acc = rb->acc;
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayWrite(y, &ya));
  ye = rb->toghost ? rb->work : ya;
  PetscCall(PetscArrayzero(ye, rb->n + rb->nghost));
  MultTransposeKernel(rb, xa, ye, acc);
  if (rb->toghost) PetscCall(PetscArraycpy(ya, ye, rb->n));
  PetscCall(VecRestoreArrayWrite(y, &ya));
  PetscCall(VecRestoreArrayRead(x, &xa));
  if (rb->toghost) {
    PetscScalar *ga;
    PetscCall(VecGetArrayWrite(rb->ghost, &ga));
    PetscCall(PetscArraycpy(ga, rb->work + rb->n, rb->nghost));
    PetscCall(VecRestoreArrayWrite(rb->ghost, &ga));
    PetscCall(VecScatterBegin(rb->toghost, rb->ghost, y, ADD_VALUES, SCATTER_REVERSE));
    PetscCall(VecScatterEnd(rb->toghost, rb->ghost, y, ADD_VALUES, SCATTER_REVERSE));
  }
  PetscCall(PetscLogFlops(2.0 * rb->nnz));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatDestroy_RowBlocks(Mat A)
{
  RowBlocks *rb;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &rb));
  PetscCall(PetscFree(rb->rstart));
  PetscCall(PetscFree4(rb->cstart, rb->col, rb->vstart, rb->nown));
  PetscCall(PetscFree(rb->val));
  PetscCall(PetscFree2(rb->work, rb->acc));
  PetscCall(VecDestroy(&rb->ghost));
  PetscCall(VecScatterDestroy(&rb->toghost));
  PetscCall(PetscFree(rb));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatView_RowBlocks(Mat A, PetscViewer viewer)
{
  RowBlocks *rb;
  PetscBool  ascii;
  PetscInt   nb;
  PetscLogDouble nnz;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  PetscCall(MatShellGetContext(A, &rb));
  PetscCall(MPIU_Allreduce(&rb->nb, &nb, 1, MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)A)));
  PetscCall(MPIU_Allreduce(&rb->nnz, &nnz, 1, MPI_DOUBLE, MPI_SUM, PetscObjectComm((PetscObject)A)));
  PetscCall(PetscViewerASCIIPrintf(viewer, "dense blocks of rows sharing their columns (phlex): %" PetscInt_FMT " blocks, %.4g entries, laid out for %s\n", nb, (double)nnz, rb->transpose ? "MatMultTranspose" : "MatMult"));
  PetscFunctionReturn(0);
}

/* the local rows of an AIJ matrix: the diagonal part's columns are the owned ones, the off-diagonal part's (several
   processes) the ghosts, numbered after them */
typedef struct {
  const PetscInt    *ia, *ja, *ib, *jb; /* diagonal and off-diagonal parts (ib NULL on one process) */
  const PetscScalar *a, *b;
} RowReader;

/* whether local row i has the columns of row i - 1 */
static PetscBool SameColumnsAsPrevious(const RowReader *r, PetscInt i)
{
  const PetscInt nd = r->ia[i + 1] - r->ia[i], no = r->ib ? r->ib[i + 1] - r->ib[i] : 0;
  if (r->ia[i] - r->ia[i - 1] != nd || (r->ib && r->ib[i] - r->ib[i - 1] != no)) return PETSC_FALSE;
  for (PetscInt k = 0; k < nd; k++)
    if (r->ja[r->ia[i] + k] != r->ja[r->ia[i - 1] + k]) return PETSC_FALSE;
  for (PetscInt k = 0; k < no; k++)
    if (r->jb[r->ib[i] + k] != r->jb[r->ib[i - 1] + k]) return PETSC_FALSE;
  return PETSC_TRUE;
}

/* whether PETSc's MatMult with the AIJ matrix R (its diagonal part on several processes) uses inodes: its inode
   sizes exist when the check at assembly found enough inodes (MAT_USE_INODES turned off after the assembly would
   leave them; phlex never does) */
static PetscErrorCode UsesInodes(Mat R, PetscBool *inodes)
{
  Mat       Rd = R;
  PetscBool mpi;
  PetscInt *sizes = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)R, MATMPIAIJ, &mpi));
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(R, &Rd, NULL, NULL));
  PetscCall(MatInodeGetInodeSizes(Rd, NULL, &sizes, NULL));
  *inodes = sizes ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexMatCreateRowBlocks - the matrix A (AIJ, sequential or MPI) stored as dense blocks, one per run of consecutive
  rows with the same columns, for one product: MatMult, or MatMultTranspose (transpose), with the sums of A's own
  AIJ product (see the top of the file). A is not referenced afterwards.

  Collective
@*/
PetscErrorCode PhlexMatCreateRowBlocks(Mat A, PetscBool transpose, Mat *C)
{
  RowBlocks      *rb;
  RowReader       rr = {0};
  Mat             Ad = A, Ao = NULL;
  const PetscInt *garray = NULL;
  PetscBool       mpi, seq, done;
  PetscInt        m, n, M, N, nrows, ntot = 0, vtot = 0, maxlen = 1;
  MPI_Comm        comm = PetscObjectComm((PetscObject)A);

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATMPIAIJ, &mpi));
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATSEQAIJ, &seq));
  if (!(mpi || seq)) {
    MatType type;
    PetscCall(MatGetType(A, &type));
    SETERRQ(comm, PETSC_ERR_SUP, "row blocks are made from an AIJ matrix, not %s", type);
  }
  PetscCall(MatGetLocalSize(A, &m, &n));
  PetscCall(MatGetSize(A, &M, &N));
  PetscCall(PetscNew(&rb));
  rb->n         = n;
  rb->transpose = transpose;
  if (transpose) rb->pairwise = PETSC_FALSE; /* AIJ's MatMultTranspose has no inode variant */
  else PetscCall(UsesInodes(A, &rb->pairwise));
  if (mpi) PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &garray));
  PetscCall(MatGetRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &rr.ia, &rr.ja, &done));
  PetscCheck(done, comm, PETSC_ERR_PLIB, "MatGetRowIJ failed");
  PetscCall(MatSeqAIJGetArrayRead(Ad, &rr.a));
  if (Ao) {
    PetscInt no;
    PetscCall(MatGetLocalSize(Ao, NULL, &rb->nghost));
    PetscCall(MatGetRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &no, &rr.ib, &rr.jb, &done));
    PetscCheck(done, comm, PETSC_ERR_PLIB, "MatGetRowIJ failed");
    PetscCall(MatSeqAIJGetArrayRead(Ao, &rr.b));
  }
  /* the runs: a row joins the previous one's run when it has the same columns */
  PetscCall(PetscMalloc1(m + 1, &rb->rstart));
  rb->nb = 0;
  for (PetscInt i = 0; i < m; i++) {
    const PetscInt len = rr.ia[i + 1] - rr.ia[i] + (rr.ib ? rr.ib[i + 1] - rr.ib[i] : 0);
    if (i == 0 || !SameColumnsAsPrevious(&rr, i)) {
      rb->rstart[rb->nb++] = i;
      ntot += len;
    }
    vtot += len;
  }
  rb->rstart[rb->nb] = m;
  PetscCall(PetscRealloc((rb->nb + 1) * sizeof(PetscInt), &rb->rstart));
  PetscCall(PetscMalloc4(rb->nb + 1, &rb->cstart, PetscMax(ntot, 1), &rb->col, rb->nb + 1, &rb->vstart, rb->nb + 1, &rb->nown));
  PetscCall(PetscMalloc1(PetscMax(vtot, 1), &rb->val));
  rb->nnz       = (PetscLogDouble)vtot;
  rb->cstart[0] = 0;
  rb->vstart[0] = 0;
  for (PetscInt b = 0; b < rb->nb; b++) {
    const PetscInt r0 = rb->rstart[b], nr = rb->rstart[b + 1] - r0;
    const PetscInt nd = rr.ia[r0 + 1] - rr.ia[r0], no = rr.ib ? rr.ib[r0 + 1] - rr.ib[r0] : 0, nc = nd + no;
    PetscInt      *c = rb->col + rb->cstart[b];
    MatScalar     *v = rb->val + rb->vstart[b];

    rb->cstart[b + 1] = rb->cstart[b] + nc;
    rb->vstart[b + 1] = rb->vstart[b] + (size_t)nr * (size_t)nc;
    maxlen            = PetscMax(maxlen, transpose ? nc : nr);
    rb->nown[b]       = nd;
    for (PetscInt k = 0; k < nd; k++) c[k] = rr.ja[rr.ia[r0] + k];
    for (PetscInt k = 0; k < no; k++) c[nd + k] = n + rr.jb[rr.ib[r0] + k];
    for (PetscInt i = 0; i < nr; i++) {
      const PetscScalar *ad = rr.a + rr.ia[r0 + i], *ao = rr.ib ? rr.b + rr.ib[r0 + i] : NULL;
      if (transpose) {
        PetscCall(PetscArraycpy(v + i * nc, ad, nd));
        if (no) PetscCall(PetscArraycpy(v + i * nc + nd, ao, no));
      } else {
        for (PetscInt k = 0; k < nd; k++) v[k * nr + i] = ad[k];
        for (PetscInt k = 0; k < no; k++) v[(nd + k) * nr + i] = ao[k];
      }
    }
  }
  PetscCall(MatSeqAIJRestoreArrayRead(Ad, &rr.a));
  PetscCall(MatRestoreRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &rr.ia, &rr.ja, &done));
  if (Ao) {
    PetscInt no;
    IS       is;
    Vec      x;
    PetscCall(MatSeqAIJRestoreArrayRead(Ao, &rr.b));
    PetscCall(MatRestoreRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &no, &rr.ib, &rr.jb, &done));
    /* the ghost columns' values from their owners (garray: the global column of each off-diagonal column) */
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, rb->nghost, &rb->ghost));
    PetscCall(ISCreateGeneral(PETSC_COMM_SELF, rb->nghost, garray, PETSC_COPY_VALUES, &is));
    PetscCall(MatCreateVecs(A, &x, NULL));
    PetscCall(VecScatterCreate(x, is, rb->ghost, NULL, &rb->toghost));
    PetscCall(VecDestroy(&x));
    PetscCall(ISDestroy(&is));
  }
  PetscCall(PetscMalloc2(mpi ? n + rb->nghost : 0, &rb->work, maxlen, &rb->acc));
  PetscCall(MatCreateShell(comm, m, n, M, N, rb, C));
  PetscCall(MatShellSetOperation(*C, transpose ? MATOP_MULT_TRANSPOSE : MATOP_MULT, transpose ? (void (*)(void))MatMultTranspose_RowBlocks : (void (*)(void))MatMult_RowBlocks));
  /* only the product offered is advertised (the shell's defaults of the Add variants call it) */
  PetscCall(MatShellSetOperation(*C, transpose ? MATOP_MULT_ADD : MATOP_MULT_TRANSPOSE_ADD, NULL));
  PetscCall(MatShellSetOperation(*C, MATOP_DESTROY, (void (*)(void))MatDestroy_RowBlocks));
  PetscCall(MatShellSetOperation(*C, MATOP_VIEW, (void (*)(void))MatView_RowBlocks));
  PetscFunctionReturn(0);
}
