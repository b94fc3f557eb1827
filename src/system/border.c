/* The borders of the system's Jacobian between the field unknowns of the flexible bodies and the discrete unknowns
   (rigid states, impulses): never one dense global block (DESIGN section 4), but per body its own border (its frame's,
   node-wise: frame.c) and the joints' port maps applied on the fly. Shells for the Jacobian, and the callbacks of PC
   phlexbordered, which eliminates the fields body by body (one sparse solve each) and the discrete unknowns through
   a small dense Schur complement. Also the preconditioning matrices of the field splits. */
#include <phlex_impl.h>

/* the discrete part of a vector of the discrete field, on every rank */
static PetscErrorCode GatherQ(PhlexSystem sys, Vec x, PetscReal *q)
{
  const PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecGetArrayRead(x, &a));
  for (PetscInt k = 0; k < sys->qlocal; k++) q[k] = PetscRealPart(a[k]);
  PetscCall(VecRestoreArrayRead(x, &a));
  PetscCallMPI(MPI_Bcast(q, (PetscMPIInt)sys->nq, MPIU_REAL, 0, sys->comm));
  PetscFunctionReturn(0);
}

static PetscErrorCode ScatterQ(PhlexSystem sys, const PetscReal *q, Vec y)
{
  PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecGetArrayWrite(y, &a));
  for (PetscInt k = 0; k < sys->qlocal; k++) a[k] = q[k];
  PetscCall(VecRestoreArrayWrite(y, &a));
  PetscFunctionReturn(0);
}

/* y_V = B x_Q: each body's own border columns and the field forces of the joints on its ports */
static PetscErrorCode MatMult_Bvq(Mat A, Vec x, Vec y)
{
  PhlexSystem sys;
  PetscReal  *xq;
  Vec        *yi;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(PetscMalloc1(PetscMax(sys->nq, 1), &xq));
  PetscCall(GatherQ(sys, x, xq));
  PetscCall(VecSet(y, 0.0));
  PetscCall(PetscMalloc1(PetscMax(sys->nfparts, 1), &yi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_VELOCITY, y, yi));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexPart p = sys->fparts[i];
    PetscCall((*p->fieldops->bordermult)(p, xq + p->qoff, yi[i]));
    for (PetscInt k = 0; k < sys->njoints; k++)
      if (PhlexJointTouches(sys->joints[k], p)) PetscCall(PhlexJointBorderMult(sys->joints[k], sys->shift, xq, p, yi[i]));
  }
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_VELOCITY, y, yi));
  PetscCall(PetscFree(yi));
  PetscCall(PetscFree(xq));
  PetscFunctionReturn(0);
}

/* y_Q += the discrete rows of the bodies i0 <= i < i1 applied to their field blocks, a Cu^T u[i - i0] + Cv^T v[i - i0]
   (NULL blocks: zero). Every body's and every joint's products are formed on each process first and summed over the
   processes in one reduction, then added up in the order of the bodies and their joints: with the bodies whole on
   different processes, a reduction per body and joint side would make each process wait while another forms its
   body's products. The same sums element by element as a reduction each (on two processes, bit for bit). */
static PetscErrorCode BorderRowsSum(PhlexSystem sys, PetscInt i0, PetscInt i1, Vec u[], PetscReal au, Vec v[], PetscReal *yq)
{
  PetscReal *loc, *sums;
  PetscInt   n = 0, off = 0;

  PetscFunctionBeginUser;
  /* the sums' slots: per body its own rows, then the products of each joint on it */
  for (PetscInt i = i0; i < i1; i++) {
    n += sys->fparts[i]->nq;
    for (PetscInt k = 0; k < sys->njoints; k++)
      if (PhlexJointTouches(sys->joints[k], sys->fparts[i])) n += PHLEX_JOINT_BORDER_SUMS;
  }
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(n, &loc, n, &sums));
  for (PetscInt i = i0; i < i1; i++) {
    PhlexPart p = sys->fparts[i];
    PetscCall((*p->fieldops->bordermulttransposelocal)(p, u[i - i0], au, v[i - i0], loc + off));
    off += p->nq;
    for (PetscInt k = 0; k < sys->njoints; k++) {
      if (!PhlexJointTouches(sys->joints[k], p)) continue;
      PetscCall(PhlexJointBorderMultTransposeLocal(sys->joints[k], p, u[i - i0], au, v[i - i0], loc + off));
      off += PHLEX_JOINT_BORDER_SUMS;
    }
  }
  PetscCall(MPIU_Allreduce(loc, sums, n, MPIU_REAL, MPI_SUM, sys->comm));
  off = 0;
  for (PetscInt i = i0; i < i1; i++) {
    PhlexPart p = sys->fparts[i];
    for (PetscInt r = 0; r < p->nq; r++) yq[p->qoff + r] += sums[off + r];
    off += p->nq;
    for (PetscInt k = 0; k < sys->njoints; k++) {
      if (!PhlexJointTouches(sys->joints[k], p)) continue;
      PetscCall(PhlexJointBorderMultTransposeSummed(sys->joints[k], p, u[i - i0], au, v[i - i0], sums + off, yq));
      off += PHLEX_JOINT_BORDER_SUMS;
    }
  }
  PetscCall(PetscFree2(loc, sums));
  PetscFunctionReturn(0);
}

/* y_Q = a Cu^T x_U + Cv^T x_V (x_U or x_V NULL: zero): the discrete rows applied to field vectors */
static PetscErrorCode BorderRowsApply(PhlexSystem sys, Vec xU, PetscReal au, Vec xV, Vec y)
{
  PetscReal *yq;
  Vec       *ui, *vi;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(PetscMax(sys->nq, 1), &yq));
  PetscCall(PetscMalloc2(PetscMax(sys->nfparts, 1), &ui, PetscMax(sys->nfparts, 1), &vi));
  PetscCall(PhlexSystemGetFieldBlocks(sys, xV ? PHLEX_FIELD_VELOCITY : PHLEX_FIELD_DISPLACEMENT, xU, ui));
  PetscCall(PhlexSystemGetFieldBlocks(sys, PHLEX_FIELD_VELOCITY, xV == xU ? NULL : xV, vi));
  if (xV == xU)
    for (PetscInt i = 0; i < sys->nfparts; i++) vi[i] = ui[i];
  PetscCall(BorderRowsSum(sys, 0, sys->nfparts, ui, au, vi, yq));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, PHLEX_FIELD_VELOCITY, xV == xU ? NULL : xV, vi));
  PetscCall(PhlexSystemRestoreFieldBlocks(sys, xV ? PHLEX_FIELD_VELOCITY : PHLEX_FIELD_DISPLACEMENT, xU, ui));
  PetscCall(PetscFree2(ui, vi));
  PetscCall(ScatterQ(sys, yq, y));
  PetscCall(PetscFree(yq));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_Cqu(Mat A, Vec x, Vec y)
{
  PhlexSystem sys;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(BorderRowsApply(sys, x, 1.0, NULL, y));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_Cqv(Mat A, Vec x, Vec y)
{
  PhlexSystem sys;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(BorderRowsApply(sys, NULL, 0.0, x, y));
  PetscFunctionReturn(0);
}

/* the discrete rows after eliminating the displacement (u = v / shift): Cv^T + Cu^T / shift */
static PetscErrorCode MatMult_Cpre(Mat A, Vec x, Vec y)
{
  PhlexSystem sys;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(BorderRowsApply(sys, x, 1.0 / sys->shift, x, y));
  PetscFunctionReturn(0);
}

static PetscErrorCode CreateShell(PhlexSystem sys, PetscInt m, PetscInt n, PetscInt M, PetscInt N, PetscErrorCode (*mult)(Mat, Vec, Vec), const char name[], Mat *A)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexMatCreateShell(sys->comm, m, n, M, N, sys, mult, A));
  PetscCall(PetscObjectSetName((PetscObject)*A, name));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBorderCreateShells - the border blocks of the Jacobian: [V, Q], [Q, U], [Q, V] (and the preconditioner's)

  Collective
@*/
PetscErrorCode PhlexBorderCreateShells(PhlexSystem sys)
{
  PetscInt nv = 0, Nv = 0;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    nv += sys->fparts[i]->nv;
    Nv += sys->fparts[i]->Nv;
  }
  PetscCall(CreateShell(sys, nv, sys->qlocal, Nv, sys->nq, MatMult_Bvq, "border (velocity rows)", &sys->Bvq));
  PetscCall(CreateShell(sys, sys->qlocal, nv, sys->nq, Nv, MatMult_Cqu, "border (displacement columns)", &sys->Cqu));
  PetscCall(CreateShell(sys, sys->qlocal, nv, sys->nq, Nv, MatMult_Cqv, "border (velocity columns)", &sys->Cqv));
  PetscCall(CreateShell(sys, sys->qlocal, nv, sys->nq, Nv, MatMult_Cpre, "border (condensed)", &sys->Cpre));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* PC phlexbordered callbacks                                                                                    */

/* C_i Y: every discrete row applied to the columns of Y (a field block of body i): m x k, column-major */
static PetscErrorCode BorderRows(void *ctx, PetscInt i, Mat Y, PetscReal *out)
{
  PhlexSystem sys = (PhlexSystem)ctx;
  PhlexPart   p   = sys->fparts[i];
  PetscInt    k;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(Y, NULL, &k));
  for (PetscInt r = 0; r < sys->nq * k; r++) out[r] = 0.0;
  PetscCall((*p->fieldops->borderrows)(p, Y, out + p->qoff, sys->nq));
  for (PetscInt j = 0; j < sys->njoints; j++)
    if (PhlexJointTouches(sys->joints[j], p)) PetscCall(PhlexJointBorderRows(sys->joints[j], p, Y, 1.0 / sys->shift, out, sys->nq));
  PetscFunctionReturn(0);
}

/* beta_i: the coefficients of body i's border columns on its basis W_i (k x m, column-major) */
static PetscErrorCode BorderCoefficients(void *ctx, PetscInt i, PetscReal *beta)
{
  PhlexSystem sys = (PhlexSystem)ctx;
  PhlexPart   p   = sys->fparts[i];
  PetscInt    k;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(sys->border.W[i], NULL, &k));
  for (PetscInt r = 0; r < sys->nq * k; r++) beta[r] = 0.0;
  PetscCall((*p->fieldops->bordercoefficients)(p, beta + k * p->qoff, k));
  for (PetscInt j = 0; j < sys->njoints; j++)
    if (PhlexJointTouches(sys->joints[j], p)) PetscCall(PhlexJointBorderCoefficients(sys->joints[j], p, sys->shift, beta, k));
  PetscFunctionReturn(0);
}

/* y += C_i x for a field vector x of body i (m values on every rank) */
static PetscErrorCode BorderRowsVec(void *ctx, PetscInt i, Vec x, PetscReal *y)
{
  PhlexSystem sys = (PhlexSystem)ctx;

  PetscFunctionBeginUser;
  PetscCall(BorderRowsSum(sys, i, i + 1, &x, 1.0 / sys->shift, &x, y));
  PetscFunctionReturn(0);
}

static PetscErrorCode BlockPrefix(void *ctx, PetscInt i, const char **name)
{
  PetscFunctionBeginUser;
  *name = ((PhlexSystem)ctx)->fparts[i]->name;
  PetscFunctionReturn(0);
}

static PetscErrorCode BlockOptions(void *ctx, PetscInt i, const char **prefix)
{
  PetscFunctionBeginUser;
  *prefix = ((PhlexSystem)ctx)->fparts[i]->prefix;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCoarseSpace - block i's rows of p-multigrid's interpolation (pmg.c, a PhlexCoarseSpaceFn on the system):
  its part's own coarse space, or its unknowns carried to the coarse level unchanged (a part without one)

  Collective on the part (every process calls it, with P or without)
@*/
PetscErrorCode PhlexSystemCoarseSpace(void *ctx, PetscInt i, PetscInt row0, PetscInt col0, Mat P, PetscInt *n1, PetscInt inj[])
{
  PhlexSystem sys = (PhlexSystem)ctx;
  PhlexPart   p   = sys->fparts[i];

  PetscFunctionBeginUser;
  if (p->fieldops->coarsespace) {
    PetscCall((*p->fieldops->coarsespace)(p, row0, col0, P, n1, inj));
    PetscFunctionReturn(0);
  }
  *n1 = sys->border.n[i];
  if (!P) PetscFunctionReturn(0);
  for (PetscInt j = 0; j < *n1; j++) {
    PetscCall(MatSetValue(P, row0 + j, col0 + j, 1.0, INSERT_VALUES));
    if (inj) inj[j] = j;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemSetUpBorder - the data of PC phlexbordered: the sparse blocks (condensed velocity operators), their
  border bases, the dense discrete block and the callbacks

  Collective
@*/
PetscErrorCode PhlexSystemSetUpBorder(PhlexSystem sys)
{
  PhlexBorderedData *bd = &sys->border;
  PetscInt           off = 0;

  PetscFunctionBeginUser;
  bd->nblocks = sys->nfparts;
  bd->m       = sys->nq;
  bd->D       = sys->D;
  bd->ctx     = sys;
  bd->rows         = BorderRows;
  bd->coefficients = BorderCoefficients;
  bd->rowsvec      = BorderRowsVec;
  bd->blockprefix  = BlockPrefix;
  bd->blockoptions = BlockOptions;
  bd->coarsespace  = PhlexSystemCoarseSpace;
  PetscCall(PetscCalloc1(PetscMax(sys->nfparts, 1), &bd->A));
  PetscCall(PetscCalloc1(PetscMax(sys->nfparts, 1), &bd->W));
  PetscCall(PetscCalloc2(PetscMax(sys->nfparts, 1), &bd->off, PetscMax(sys->nfparts, 1), &bd->n));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexPart           p = sys->fparts[i];
    PhlexFieldOperators ops;
    PetscCall((*p->fieldops->fieldoperators)(p, &ops));
    bd->A[i]   = ops.Sv;
    bd->off[i] = off;
    bd->n[i]   = p->nv;
    off += p->nv;
    PetscCall((*p->fieldops->borderbasis)(p, &bd->W[i]));
  }
  bd->qoff = off;
  PetscFunctionReturn(0);
}

static PetscErrorCode ComposeBorder(PhlexSystem sys, Mat P)
{
  PetscContainer c;

  PetscFunctionBeginUser;
  PetscCall(PetscContainerCreate(sys->comm, &c));
  PetscCall(PetscContainerSetPointer(c, &sys->border));
  PetscCall(PetscObjectCompose((PetscObject)P, "phlex_border", (PetscObject)c));
  PetscCall(PetscContainerDestroy(&c));
  PetscFunctionReturn(0);
}

/* The assembled block diagonal of several bodies' condensed operators loses what each body's carries: the node
   blocks (block size 3) and the rigid-body modes (the near-null space GAMG coarsens by). Without them two clamped
   bars took 115 CG iterations per step with the iterative preset, against 9 for one (GAMG saw scalar unknowns and
   constants). The block size is set when every body has the same one; the near-null space is the union of the
   bodies' (each body's vectors on its own rows, zero on the others': orthonormal as each body's are), when every
   body has one. */
static PetscErrorCode CarryBlocksAndRigidModes(PhlexSystem sys, Mat m[])
{
  PetscInt     bs = -1, nvec = 0, k = 0, fits = 1;
  PetscBool    same = PETSC_TRUE;
  Vec         *vecs;
  MatNullSpace nsp;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PetscInt     b, n;
    PetscBool    has_const;
    const Vec   *v;
    MatNullSpace ni;
    PetscCall(MatGetBlockSize(m[i], &b));
    if (bs < 0) bs = b;
    else if (b != bs) same = PETSC_FALSE;
    PetscCall(MatGetNearNullSpace(m[i], &ni));
    if (!ni) fits = 0;
    else {
      PetscCall(MatNullSpaceGetVecs(ni, &has_const, &n, &v));
      if (has_const) fits = 0; /* (a constant would need its own embedding: not what phlex attaches) */
      for (PetscInt j = 0; j < n; j++) {
        PetscInt nl;
        PetscCall(VecGetLocalSize(v[j], &nl));
        if (nl != sys->border.n[i]) fits = 0;
      }
      nvec += n;
    }
  }
  if (same && bs > 1) PetscCall(MatSetBlockSize(sys->Sv, bs));
  PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &fits, 1, MPIU_INT, MPI_MIN, sys->comm));
  if (!fits || !nvec) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(nvec, &vecs));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PetscInt     n;
    PetscBool    has_const;
    const Vec   *v;
    MatNullSpace ni;
    PetscCall(MatGetNearNullSpace(m[i], &ni));
    PetscCall(MatNullSpaceGetVecs(ni, &has_const, &n, &v));
    for (PetscInt j = 0; j < n; j++, k++) {
      PetscScalar       *a;
      const PetscScalar *b;
      PetscCall(MatCreateVecs(sys->Sv, &vecs[k], NULL));
      PetscCall(VecZeroEntries(vecs[k]));
      PetscCall(VecGetArray(vecs[k], &a));
      PetscCall(VecGetArrayRead(v[j], &b));
      PetscCall(PetscArraycpy(a + sys->border.off[i], b, sys->border.n[i]));
      PetscCall(VecRestoreArrayRead(v[j], &b));
      PetscCall(VecRestoreArray(vecs[k], &a));
    }
  }
  PetscCall(MatNullSpaceCreate(sys->comm, PETSC_FALSE, nvec, vecs, &nsp));
  PetscCall(MatSetNearNullSpace(sys->Sv, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  for (k = 0; k < nvec; k++) PetscCall(VecDestroy(&vecs[k]));
  PetscCall(PetscFree(vecs));
  PetscFunctionReturn(0);
}

/* the condensed velocity operators of all bodies: the body's own, or the block diagonal assembled */
static PetscErrorCode VelocityPmat(PhlexSystem sys)
{
  Mat *m, N;

  PetscFunctionBeginUser;
  if (sys->Sv) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(sys->nfparts, &m));
  for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = sys->border.A[i];
  PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &N));
  if (sys->nfparts == 1) sys->Sv = N;
  else {
    PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &sys->Sv));
    PetscCall(MatDestroy(&N));
    PetscCall(CarryBlocksAndRigidModes(sys, m));
  }
  PetscCall(PetscFree(m));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemVelocityOperator - the condensed velocity operators shift Mv + K/shift of all bodies (block diagonal, at
  the shift of the last Jacobian); owned by the system

  Collective
@*/
PetscErrorCode PhlexSystemVelocityOperator(PhlexSystem sys, Mat *Sv)
{
  PetscFunctionBeginUser;
  PetscCall(VelocityPmat(sys));
  *Sv = sys->Sv;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemPmat - the preconditioning matrix of a set of fields, assembled when PCFIELDSPLIT asks for a split
  (layout.c): {velocity}: the condensed velocity operators shift Mv + K/shift (the exact Schur complement of the
  displacement and stress of a fixed body; of a floating one up to its node-wise inertial terms); {velocity,
  discrete}: [[A, B], [C, D]] for PC phlexbordered, with its data composed; {stress, velocity}: the assembled
  (Sigma, v) block of one body (LDL^T preset); {discrete} alone (no flexible body): the dense block
@*/
PetscErrorCode PhlexSystemPmat(void *ctx, PetscInt n, const PetscInt fields[], Mat *P)
{
  PhlexSystem sys = (PhlexSystem)ctx;
  PhlexField  f[PHLEX_NUM_FIELDS];

  PetscFunctionBeginUser;
  *P = NULL;
  PetscCheck(sys->shift > 0, sys->comm, PETSC_ERR_ORDER, "preconditioner requested before the Jacobian");
  for (PetscInt k = 0; k < n; k++)
    for (PetscInt g = 0; g < PHLEX_NUM_FIELDS; g++)
      if (sys->field[g] == fields[k]) f[k] = (PhlexField)g;
  if (n == 1 && f[0] == PHLEX_FIELD_VELOCITY) {
    PetscCall(VelocityPmat(sys));
    *P = sys->Sv;
  } else if (n == 2 && f[0] == PHLEX_FIELD_VELOCITY && f[1] == PHLEX_FIELD_DISCRETE) {
    if (!sys->Pvq) {
      Mat blocks[4], *m;
      PetscCall(PetscMalloc1(sys->nfparts, &m));
      for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = sys->border.A[i];
      PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Abd));
      PetscCall(PetscFree(m));
      blocks[0] = sys->Abd, blocks[1] = sys->Bvq, blocks[2] = sys->Cpre, blocks[3] = sys->Dq;
      PetscCall(MatCreateNest(sys->comm, 2, NULL, 2, NULL, blocks, &sys->Pvq));
      PetscCall(PetscObjectSetName((PetscObject)sys->Pvq, "condensed velocity-discrete operator"));
      PetscCall(ComposeBorder(sys, sys->Pvq));
    }
    *P = sys->Pvq;
  } else if (n == 1 && f[0] == PHLEX_FIELD_DISCRETE && !sys->nfparts) {
    PetscCall(ComposeBorder(sys, sys->Dq));
    *P = sys->Dq;
  } else if (n == 2 && f[0] == PHLEX_FIELD_STRESS && f[1] == PHLEX_FIELD_VELOCITY && sys->nfparts == 1 && !sys->nq) {
    if (!sys->Ssv) {
      Mat blocks[4] = {sys->Jss, sys->Jsv, sys->Jvs, sys->Jvv}, N;
      PetscCall(MatCreateNest(sys->comm, 2, NULL, 2, NULL, blocks, &N));
      PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &sys->Ssv));
      PetscCall(MatDestroy(&N));
      PetscCall(MatSetOption(sys->Ssv, MAT_SYMMETRIC, PETSC_TRUE));
      PetscCall(PetscObjectSetName((PetscObject)sys->Ssv, "stress-velocity operator"));
    }
    *P = sys->Ssv;
  }
  PetscFunctionReturn(0);
}
