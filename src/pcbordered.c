/* PC "phlexbordered": a preconditioner for a bordered system with a large sparse block and a few dense borders,
   the {velocity, rigid} block of a floating body (DESIGN §4: the rigid unknowns must not spoil the sparse solver):

       [ A    B ] [x]   [f]        A  n x n sparse (the condensed velocity operator), factored by an inner KSP
       [ C^T  D ] [y] = [g]        B, C  n x m dense borders, D  m x m dense (m = 18 rigid unknowns)

   The preconditioning matrix is a 2 x 2 MATNEST; a basis W (n x k dense, k small) composed on it as "border_basis"
   spans the borders that do not change with the state. The border B is replaced by its projection W beta,
   beta = (W^T W)^{-1} W^T B. Y = A^{-1} W is computed once (one solve with k right-hand sides) and kept while A
   and W are unchanged, so a new state costs only small dense products:

       S = D - (C^T Y) beta           (m x m, LU)
       x0 = A^{-1} f,  y = S^{-1} (g - C^T x0),  x = x0 - Y (beta y)      (one solve with A per application)

   This is the exact inverse when B lies in span W (a floating body with frozen inertia); otherwise it is a
   preconditioner for an outer Krylov method. Options: -<prefix>bordered_ksp_type, -<prefix>bordered_pc_type, ...
   for the inner solve with A (default: preonly + Cholesky). */
#include <phlex_impl.h>
#include <petsc/private/pcimpl.h>
#include <petscblaslapack.h>

typedef struct {
  KSP              ksp;                /* solves with A */
  Mat              A, Bm, Ct, D;       /* the blocks of the current pmat (borrowed) */
  IS               isx, isy;           /* the nest's row index sets (borrowed) */
  Mat              W, Y;               /* basis and A^{-1} W */
  PetscObjectState Astate, Wstate;     /* of the A and W that Y was computed with */
  PetscInt         n, m, k;            /* sizes: A (global), D, basis */
  PetscScalar     *gram;               /* LU of W^T W (k x k) */
  PetscBLASInt    *gram_piv;
  PetscScalar     *beta;               /* k x m, column-major */
  PetscScalar     *S;                  /* LU of the Schur complement, m x m column-major */
  PetscBLASInt    *S_piv;
  Vec              x0, cty, yseq;      /* work: A-sized, D-sized (distributed), D-sized on every rank */
  VecScatter       toall;
  PetscInt         nfactor;            /* how many times Y was (re)computed */
} PC_Bordered;

/* a distributed m-vector on every rank */
static PetscErrorCode GatherAll(PC_Bordered *bd, Vec v, PetscScalar out[])
{
  const PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecScatterBegin(bd->toall, v, bd->yseq, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(bd->toall, v, bd->yseq, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(bd->yseq, &a));
  PetscCall(PetscArraycpy(out, a, bd->m));
  PetscCall(VecRestoreArrayRead(bd->yseq, &a));
  PetscFunctionReturn(0);
}

/* P = X^T Z (p x q, column-major, on every rank) for dense X (n x p) and Z (n x q) with the same row layout */
static PetscErrorCode DenseTransposeProduct(MPI_Comm comm, Mat X, Mat Z, PetscScalar P[])
{
  const PetscScalar *xa, *za;
  PetscInt           nloc, p, q, ldx, ldz;
  PetscScalar       *loc;

  PetscFunctionBeginUser;
  PetscCall(MatGetLocalSize(X, &nloc, NULL));
  PetscCall(MatGetSize(X, NULL, &p));
  PetscCall(MatGetSize(Z, NULL, &q));
  PetscCall(MatDenseGetLDA(X, &ldx));
  PetscCall(MatDenseGetLDA(Z, &ldz));
  PetscCall(PetscCalloc1(p * q, &loc));
  PetscCall(MatDenseGetArrayRead(X, &xa));
  PetscCall(MatDenseGetArrayRead(Z, &za));
  if (nloc > 0) {
    PetscBLASInt nb, pb, qb, ldxb, ldzb;
    PetscScalar  one = 1.0, zero = 0.0;
    PetscCall(PetscBLASIntCast(nloc, &nb));
    PetscCall(PetscBLASIntCast(p, &pb));
    PetscCall(PetscBLASIntCast(q, &qb));
    PetscCall(PetscBLASIntCast(ldx, &ldxb));
    PetscCall(PetscBLASIntCast(ldz, &ldzb));
    PetscCallBLAS("BLASgemm", BLASgemm_("T", "N", &pb, &qb, &nb, &one, xa, &ldxb, za, &ldzb, &zero, loc, &pb));
  }
  PetscCall(MatDenseRestoreArrayRead(X, &xa));
  PetscCall(MatDenseRestoreArrayRead(Z, &za));
  PetscCall(MPIU_Allreduce(loc, P, p * q, MPIU_SCALAR, MPIU_SUM, comm));
  PetscCall(PetscFree(loc));
  PetscFunctionReturn(0);
}

/* Y = A^{-1} W and the LU of W^T W: only when A or W changed */
static PetscErrorCode BorderedSetUpBasis(PC pc, PC_Bordered *bd)
{
  PetscObjectState sa, sw;
  PetscBLASInt     k, info;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectStateGet((PetscObject)bd->A, &sa));
  PetscCall(PetscObjectStateGet((PetscObject)bd->W, &sw));
  if (bd->Y && sa == bd->Astate && sw == bd->Wstate) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_BorderedBasis, pc, 0, 0, 0));
  PetscCall(KSPSetOperators(bd->ksp, bd->A, bd->A));
  PetscCall(KSPSetUp(bd->ksp));
  PetscCall(MatDestroy(&bd->Y));
  PetscCall(MatDuplicate(bd->W, MAT_DO_NOT_COPY_VALUES, &bd->Y));
  PetscCall(KSPMatSolve(bd->ksp, bd->W, bd->Y));
  /* Gram matrix W^T W */
  PetscCall(DenseTransposeProduct(PetscObjectComm((PetscObject)pc), bd->W, bd->W, bd->gram));
  PetscCall(PetscBLASIntCast(bd->k, &k));
  PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&k, &k, bd->gram, &k, bd->gram_piv, &info));
  PetscCheck(!info, PetscObjectComm((PetscObject)pc), PETSC_ERR_MAT_LU_ZRPVT, "PC phlexbordered: the border basis is rank deficient (LAPACK getrf info %d)", (int)info);
  bd->Astate = sa;
  bd->Wstate = sw;
  bd->nfactor++;
  PetscCall(PetscLogEventEnd(PHLEX_BorderedBasis, pc, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCSetUp_Bordered(PC pc)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;
  Mat          sub[4];
  IS           is[2];
  PetscInt     nr, nc, m;
  PetscBool    isnest;
  PetscBLASInt mb, info;
  PetscScalar *WtB, *CtY, *Dfull;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)pc->pmat, MATNEST, &isnest));
  PetscCheck(isnest, PetscObjectComm((PetscObject)pc), PETSC_ERR_ARG_WRONG, "PC phlexbordered needs a 2 x 2 MATNEST preconditioning matrix");
  PetscCall(MatNestGetSize(pc->pmat, &nr, &nc));
  PetscCheck(nr == 2 && nc == 2, PetscObjectComm((PetscObject)pc), PETSC_ERR_ARG_WRONG, "PC phlexbordered needs a 2 x 2 MATNEST, got %" PetscInt_FMT " x %" PetscInt_FMT, nr, nc);
  PetscCall(MatNestGetSubMat(pc->pmat, 0, 0, &sub[0]));
  PetscCall(MatNestGetSubMat(pc->pmat, 0, 1, &sub[1]));
  PetscCall(MatNestGetSubMat(pc->pmat, 1, 0, &sub[2]));
  PetscCall(MatNestGetSubMat(pc->pmat, 1, 1, &sub[3]));
  PetscCall(MatNestGetISs(pc->pmat, is, NULL));
  PetscCall(PetscObjectQuery((PetscObject)pc->pmat, "border_basis", (PetscObject *)&bd->W));
  PetscCheck(bd->W, PetscObjectComm((PetscObject)pc), PETSC_ERR_ARG_WRONG, "PC phlexbordered: the preconditioning matrix carries no \"border_basis\"");
  bd->A = sub[0], bd->Bm = sub[1], bd->Ct = sub[2], bd->D = sub[3];
  bd->isx = is[0], bd->isy = is[1];
  PetscCall(MatGetSize(bd->D, &m, NULL));
  PetscCall(MatGetSize(bd->W, NULL, &bd->k));
  if (!bd->x0 || m != bd->m) {
    IS isall;
    bd->m = m;
    PetscCall(VecDestroy(&bd->x0));
    PetscCall(VecDestroy(&bd->cty));
    PetscCall(VecDestroy(&bd->yseq));
    PetscCall(VecScatterDestroy(&bd->toall));
    PetscCall(PetscFree5(bd->gram, bd->gram_piv, bd->beta, bd->S, bd->S_piv));
    PetscCall(MatCreateVecs(bd->A, &bd->x0, NULL));
    PetscCall(MatCreateVecs(bd->D, &bd->cty, NULL));
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, m, &bd->yseq));
    PetscCall(ISCreateStride(PETSC_COMM_SELF, m, 0, 1, &isall));
    PetscCall(VecScatterCreate(bd->cty, isall, bd->yseq, NULL, &bd->toall));
    PetscCall(ISDestroy(&isall));
    PetscCall(PetscMalloc5(bd->k * bd->k, &bd->gram, bd->k, &bd->gram_piv, bd->k * m, &bd->beta, m * m, &bd->S, m, &bd->S_piv));
  }
  PetscCall(BorderedSetUpBasis(pc, bd));
  PetscCall(PetscLogEventBegin(PHLEX_BorderedSetUp, pc, 0, 0, 0));

  PetscCall(PetscMalloc3(bd->k * m, &WtB, m * bd->k, &CtY, m * m, &Dfull));
  {
    Mat       C;
    PetscBool istr, isdense;
    PetscCall(PetscObjectTypeCompare((PetscObject)bd->Ct, MATTRANSPOSEVIRTUAL, &istr));
    PetscCheck(istr, PetscObjectComm((PetscObject)pc), PETSC_ERR_SUP, "PC phlexbordered: the lower border must be the transpose of a dense matrix");
    PetscCall(MatTransposeGetMat(bd->Ct, &C));
    PetscCall(PetscObjectTypeCompareAny((PetscObject)bd->Bm, &isdense, MATSEQDENSE, MATMPIDENSE, ""));
    PetscCheck(isdense, PetscObjectComm((PetscObject)pc), PETSC_ERR_SUP, "PC phlexbordered: the upper border must be dense");
    PetscCall(DenseTransposeProduct(PetscObjectComm((PetscObject)pc), bd->W, bd->Bm, WtB)); /* k x m */
    PetscCall(DenseTransposeProduct(PetscObjectComm((PetscObject)pc), C, bd->Y, CtY));      /* m x k */
  }
  /* beta = (W^T W)^{-1} W^T B */
  {
    PetscBLASInt kb, nrhs;
    PetscCall(PetscBLASIntCast(bd->k, &kb));
    PetscCall(PetscBLASIntCast(m, &nrhs));
    PetscCall(PetscArraycpy(bd->beta, WtB, bd->k * m));
    PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &kb, &nrhs, bd->gram, &kb, bd->gram_piv, bd->beta, &kb, &info));
  }
  /* D on every rank (its rows may be anywhere) */
  {
    const PetscScalar *da;
    PetscInt           rstart, rend, lda;
    PetscScalar       *loc;
    PetscCall(PetscCalloc1(m * m, &loc));
    PetscCall(MatGetOwnershipRange(bd->D, &rstart, &rend));
    PetscCall(MatDenseGetLDA(bd->D, &lda));
    PetscCall(MatDenseGetArrayRead(bd->D, &da));
    for (PetscInt i = rstart; i < rend; i++)
      for (PetscInt j = 0; j < m; j++) loc[i + m * j] = da[(i - rstart) + lda * j];
    PetscCall(MatDenseRestoreArrayRead(bd->D, &da));
    PetscCall(MPIU_Allreduce(loc, Dfull, m * m, MPIU_SCALAR, MPIU_SUM, PetscObjectComm((PetscObject)pc)));
    PetscCall(PetscFree(loc));
  }
  /* S = D - (C^T Y) beta */
  for (PetscInt i = 0; i < m; i++)
    for (PetscInt j = 0; j < m; j++) {
      PetscScalar s = Dfull[i + m * j];
      for (PetscInt l = 0; l < bd->k; l++) s -= CtY[i + m * l] * bd->beta[l + bd->k * j];
      bd->S[i + m * j] = s;
    }
  PetscCall(PetscFree3(WtB, CtY, Dfull));
  PetscCall(PetscBLASIntCast(m, &mb));
  PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&mb, &mb, bd->S, &mb, bd->S_piv, &info));
  PetscCheck(!info, PetscObjectComm((PetscObject)pc), PETSC_ERR_MAT_LU_ZRPVT, "PC phlexbordered: singular Schur complement of the border (LAPACK getrf info %d)", (int)info);
  PetscCall(PetscLogEventEnd(PHLEX_BorderedSetUp, pc, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCApply_Bordered(PC pc, Vec r, Vec z)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;
  Vec          f, g, x, y;
  PetscScalar  h[PHLEX_MAX_BORDER], c[PHLEX_MAX_BORDER];
  PetscBLASInt mb, one = 1, info;

  PetscFunctionBeginUser;
  PetscCheck(bd->m <= PHLEX_MAX_BORDER && bd->k <= PHLEX_MAX_BORDER, PetscObjectComm((PetscObject)pc), PETSC_ERR_SUP, "PC phlexbordered: border larger than %d", PHLEX_MAX_BORDER);
  PetscCall(VecGetSubVector(r, bd->isx, &f));
  PetscCall(VecGetSubVector(r, bd->isy, &g));
  PetscCall(VecGetSubVector(z, bd->isx, &x));
  PetscCall(VecGetSubVector(z, bd->isy, &y));
  /* x0 = A^{-1} f */
  PetscCall(KSPSolve(bd->ksp, f, x));
  PetscCall(KSPCheckSolve(bd->ksp, pc, x));
  /* y = S^{-1} (g - C^T x0) */
  PetscCall(MatMult(bd->Ct, x, bd->cty));
  PetscCall(VecAYPX(bd->cty, -1.0, g));
  PetscCall(GatherAll(bd, bd->cty, h));
  PetscCall(PetscBLASIntCast(bd->m, &mb));
  PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &mb, &one, bd->S, &mb, bd->S_piv, h, &mb, &info));
  {
    PetscInt     rstart, rend;
    PetscScalar *ya;
    PetscCall(VecGetOwnershipRange(y, &rstart, &rend));
    PetscCall(VecGetArrayWrite(y, &ya));
    for (PetscInt i = rstart; i < rend; i++) ya[i - rstart] = h[i];
    PetscCall(VecRestoreArrayWrite(y, &ya));
  }
  /* x = x0 - Y (beta y) */
  for (PetscInt l = 0; l < bd->k; l++) {
    c[l] = 0.0;
    for (PetscInt j = 0; j < bd->m; j++) c[l] -= bd->beta[l + bd->k * j] * h[j];
  }
  {
    const PetscScalar *Ya;
    PetscScalar       *xa;
    PetscInt           nloc, ld;
    PetscCall(VecGetLocalSize(x, &nloc));
    PetscCall(MatDenseGetLDA(bd->Y, &ld));
    PetscCall(MatDenseGetArrayRead(bd->Y, &Ya));
    PetscCall(VecGetArray(x, &xa));
    for (PetscInt l = 0; l < bd->k; l++)
      for (PetscInt i = 0; i < nloc; i++) xa[i] += c[l] * Ya[l * ld + i];
    PetscCall(VecRestoreArray(x, &xa));
    PetscCall(MatDenseRestoreArrayRead(bd->Y, &Ya));
  }
  PetscCall(VecRestoreSubVector(r, bd->isx, &f));
  PetscCall(VecRestoreSubVector(r, bd->isy, &g));
  PetscCall(VecRestoreSubVector(z, bd->isx, &x));
  PetscCall(VecRestoreSubVector(z, bd->isy, &y));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCReset_Bordered(PC pc)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;

  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&bd->Y));
  PetscCall(VecDestroy(&bd->x0));
  PetscCall(VecDestroy(&bd->cty));
  PetscCall(VecDestroy(&bd->yseq));
  PetscCall(VecScatterDestroy(&bd->toall));
  PetscCall(PetscFree5(bd->gram, bd->gram_piv, bd->beta, bd->S, bd->S_piv));
  if (bd->ksp) PetscCall(KSPReset(bd->ksp));
  bd->m = 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode PCDestroy_Bordered(PC pc)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;

  PetscFunctionBeginUser;
  PetscCall(PCReset_Bordered(pc));
  PetscCall(KSPDestroy(&bd->ksp));
  PetscCall(PetscFree(pc->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCSetFromOptions_Bordered(PC pc, PetscOptionItems *PetscOptionsObject)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;
  const char  *prefix;

  PetscFunctionBeginUser;
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  PetscCall(KSPSetOptionsPrefix(bd->ksp, prefix));
  PetscCall(KSPAppendOptionsPrefix(bd->ksp, "bordered_"));
  PetscCall(KSPSetFromOptions(bd->ksp));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCView_Bordered(PC pc, PetscViewer viewer)
{
  PC_Bordered *bd = (PC_Bordered *)pc->data;
  PetscBool    ascii;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  border of %" PetscInt_FMT " unknowns, basis of %" PetscInt_FMT " vectors, A^{-1} W computed %" PetscInt_FMT " time(s)\n", bd->m, bd->k, bd->nfactor));
  PetscCall(PetscViewerASCIIPrintf(viewer, "  solver for the sparse block:\n"));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(KSPView(bd->ksp, viewer));
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCCreate_Bordered(PC pc)
{
  PC_Bordered *bd;
  const char  *prefix;
  PC           inner;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&bd));
  pc->data = bd;
  PetscCall(KSPCreate(PetscObjectComm((PetscObject)pc), &bd->ksp));
  PetscCall(PetscObjectIncrementTabLevel((PetscObject)bd->ksp, (PetscObject)pc, 1));
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  PetscCall(KSPSetOptionsPrefix(bd->ksp, prefix));
  PetscCall(KSPAppendOptionsPrefix(bd->ksp, "bordered_"));
  PetscCall(KSPSetType(bd->ksp, KSPPREONLY));
  PetscCall(KSPGetPC(bd->ksp, &inner));
  PetscCall(PCSetType(inner, PCCHOLESKY));
  pc->ops->setup          = PCSetUp_Bordered;
  pc->ops->apply          = PCApply_Bordered;
  pc->ops->reset          = PCReset_Bordered;
  pc->ops->destroy        = PCDestroy_Bordered;
  pc->ops->setfromoptions = PCSetFromOptions_Bordered;
  pc->ops->view           = PCView_Bordered;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPCRegister - registers the PC type "phlexbordered" (selectable by -pc_type in any solver prefix)
@*/
PetscErrorCode PhlexPCRegister(void)
{
  PetscFunctionBeginUser;
  PetscCall(PCRegister("phlexbordered", PCCreate_Bordered));
  PetscFunctionReturn(0);
}
