/* The assembled system of a scene: the index-2 pHDAE of all parts interconnected by the joints (paper Section 5,
   eq. int_beams for N parts), in implicit form F(t, X, X') = 0 for PETSc TS, non-dimensional.

   Unknowns X = [U | Sigma | V | Q], field-major, each field contiguous on every rank:
     U, Sigma, V   the displacement, stress and velocity fields of the flexible bodies, body after body;
     Q             the discrete unknowns on rank 0: each part's (frame states, lumped states, internal impulses)
                   then each joint's impulses Lambda (Lambda' = lambda, the multipliers).
   The multipliers enter as rates of impulses: with the implicit midpoint rule the scheme uses one multiplier per
   step, (Lambda_{n+1} - Lambda_n)/dt, the midpoint value, and the written joint wrenches are these step averages
   (they do not oscillate as end-of-step algebraic values would).

   Residual: every part writes the rows of its unknowns given the wrenches on its ports; every joint sets those
   wrenches from its multipliers and writes its constraint rows. The system never asks what kind a part is.

   Jacobian: a MATNEST. Field blocks are the parts' own matrices (a MATNEST over the bodies when several); the
   borders between fields and Q are shells (border.c) that apply each part's own border and the joints' port maps;
   the Q x Q block is dense (replicated array D, copied to rank 0's rows). */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateIncrease: blocks changed in place */
#include <petsc/private/matimpl.h>   /* the nested Jacobian's nonzero state follows the assembled one's pattern */

const char *const PhlexFieldNames[] = {"displacement", "stress", "velocity", "discrete"};

static PetscErrorCode IdentityMatrix(MPI_Comm comm, PetscInt n, PetscReal value, Mat *A)
{
  Vec d;

  PetscFunctionBeginUser;
  PetscCall(MatCreateAIJ(comm, n, n, PETSC_DETERMINE, PETSC_DETERMINE, 1, NULL, 0, NULL, A));
  PetscCall(MatCreateVecs(*A, &d, NULL));
  PetscCall(VecSet(d, value));
  PetscCall(MatDiagonalSet(*A, d, INSERT_VALUES));
  PetscCall(VecDestroy(&d));
  PetscFunctionReturn(0);
}

/* the block-diagonal matrix of one matrix per field part (rows in field fr, columns in field fc): the part's own
   matrix when it is alone, else a MATNEST (NULL blocks allowed: the index sets give the sizes) */
PetscErrorCode PhlexSystemBlockDiagonal(PhlexSystem sys, Mat *mats, PhlexField fr, PhlexField fc, Mat *A)
{
  const PetscInt n = sys->nfparts;
  Mat           *blocks;
  IS            *isr, *isc;
  PetscBool      any = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < n; i++)
    if (mats[i]) any = PETSC_TRUE;
  *A = NULL;
  if (!any) PetscFunctionReturn(0);
  if (n == 1) {
    *A = mats[0];
    PetscCall(PetscObjectReference((PetscObject)mats[0]));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscCalloc3(n * n, &blocks, n, &isr, n, &isc));
  for (PetscInt i = 0; i < n; i++) {
    blocks[i * n + i] = mats[i];
    isr[i]            = sys->fis[fr][i];
    isc[i]            = sys->fis[fc][i];
  }
  PetscCall(MatCreateNest(sys->comm, n, isr, n, isc, blocks, A));
  PetscCall(PetscFree3(blocks, isr, isc));
  PetscFunctionReturn(0);
}

/* every flexible body's block of field f of x (x NULL: NULL blocks), all taken before the caller works on any: taking a
   block is collective, and between two bodies' local work it would make the processes of the other bodies wait
   (bodies whole on one process; split_sum.c) */
PetscErrorCode PhlexSystemGetFieldBlocks(PhlexSystem sys, PhlexField f, Vec x, Vec blocks[])
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    blocks[i] = NULL;
    if (x) PetscCall(VecGetSubVector(x, sys->fis[f][i], &blocks[i]));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexSystemRestoreFieldBlocks(PhlexSystem sys, PhlexField f, Vec x, Vec blocks[])
{
  PetscFunctionBeginUser;
  if (x)
    for (PetscInt i = 0; i < sys->nfparts; i++) PetscCall(VecRestoreSubVector(x, sys->fis[f][i], &blocks[i]));
  PetscFunctionReturn(0);
}

/* the compliance masses of all bodies in one AIJ matrix, with the per-cell blocks as variable block sizes (so that
   point-block Jacobi inverts them exactly for any mix of element degrees) */
static PetscErrorCode AssembleStressBlock(PhlexSystem sys, PhlexFieldOperators *ops, Mat *Ms)
{
  PetscInt  ns = 0, bs = -1, rstart, nblocks = 0, *bsizes, *nnz;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    ns += sys->fparts[i]->ns;
    nblocks += sys->fparts[i]->ns / ops[i].stress_bs;
    bs = (bs < 0 || bs == ops[i].stress_bs) ? ops[i].stress_bs : 1;
  }
  PetscCall(PetscMalloc2(PetscMax(nblocks, 1), &bsizes, PetscMax(ns, 1), &nnz));
  nblocks = 0;
  for (PetscInt i = 0; i < sys->nfparts; i++)
    for (PetscInt b = 0; b < sys->fparts[i]->ns / ops[i].stress_bs; b++) bsizes[nblocks++] = ops[i].stress_bs;
  {
    PetscInt r = 0;
    for (PetscInt b = 0; b < nblocks; b++)
      for (PetscInt k = 0; k < bsizes[b]; k++) nnz[r++] = bsizes[b];
  }
  PetscCall(MatCreate(sys->comm, Ms));
  PetscCall(MatSetSizes(*Ms, ns, ns, PETSC_DETERMINE, PETSC_DETERMINE));
  PetscCall(MatSetType(*Ms, MATAIJ));
  if (bs > 1) PetscCall(MatSetBlockSize(*Ms, bs));
  PetscCall(MatSeqAIJSetPreallocation(*Ms, 0, nnz));
  PetscCall(MatMPIAIJSetPreallocation(*Ms, 0, nnz, 0, NULL));
  PetscCall(MatGetOwnershipRange(*Ms, &rstart, NULL));
  {
    PetscInt off = rstart;
    for (PetscInt i = 0; i < sys->nfparts; i++) {
      Mat      M = ops[i].Ms;
      PetscInt mstart, mend;
      PetscCall(MatGetOwnershipRange(M, &mstart, &mend));
      for (PetscInt row = mstart; row < mend; row++) {
        const PetscInt    *cols;
        const PetscScalar *vals;
        PetscInt           nc, grow = off + row - mstart, gcols[64];
        PetscCall(MatGetRow(M, row, &nc, &cols, &vals));
        PetscCheck(nc <= 64, sys->comm, PETSC_ERR_PLIB, "stress block row with %" PetscInt_FMT " entries", nc);
        for (PetscInt k = 0; k < nc; k++) gcols[k] = off + cols[k] - mstart;
        PetscCall(MatSetValues(*Ms, 1, &grow, nc, gcols, vals, INSERT_VALUES));
        PetscCall(MatRestoreRow(M, row, &nc, &cols, &vals));
      }
      off += mend - mstart;
    }
  }
  PetscCall(MatAssemblyBegin(*Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(MatSetVariableBlockSizes(*Ms, nblocks, bsizes));
  PetscCall(PetscFree2(bsizes, nnz));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_NotAssembled(Mat A, Vec x, Vec y)
{
  PetscFunctionBeginUser;
  SETERRQ(PetscObjectComm((PetscObject)A), PETSC_ERR_PLIB, "internal: a product with a block of the whole-state Jacobian (stress, resultant or coupling) that PhlexSystemCompleteJacobian() has not built");
}

/* a placeholder of the stress block (Jss), the resultant block (velocity rows, stress columns: Jvs) or the coupling
   block (stress rows, velocity columns: Jsv) */
static PetscErrorCode CreatePlaceholder(PhlexSystem sys, PhlexField rows, PhlexField cols, Mat *A)
{
  PetscInt m, n;

  PetscFunctionBeginUser;
  PetscCall(ISGetLocalSize(sys->is[rows], &m));
  PetscCall(ISGetLocalSize(sys->is[cols], &n));
  PetscCall(PhlexMatCreateShell(sys->comm, m, n, PETSC_DETERMINE, PETSC_DETERMINE, NULL, MatMult_NotAssembled, A));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemReleaseJacobian - frees what only Newton on the whole state multiplies once the stages of SNES
  phlexcondensed or phlexreduced solve the steps (after the initial state and the consistent start): the blocks
  PhlexSystemCompleteJacobian() built, and the coupling block G with the bodies' assembled G and Ms
  (PhlexPartOps mixedoperators); placeholders in their place until PhlexSystemCompleteJacobian() builds them again

  Collective
@*/
PetscErrorCode PhlexSystemReleaseJacobian(PhlexSystem sys)
{
  const PetscInt S = sys->field[PHLEX_FIELD_STRESS], V = sys->field[PHLEX_FIELD_VELOCITY];

  PetscFunctionBeginUser;
  if (!sys->nfparts) PetscFunctionReturn(0);
  if (sys->Ms) {
    PetscCall(MatDestroy(&sys->Ms));
    PetscCall(MatDestroy(&sys->Jss));
    PetscCall(MatDestroy(&sys->Jvs));
    PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_STRESS, PHLEX_FIELD_STRESS, &sys->Jss));
    PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_STRESS, &sys->Jvs));
    PetscCall(MatNestSetSubMat(sys->J, S, S, sys->Jss));
    PetscCall(MatNestSetSubMat(sys->J, V, S, sys->Jvs));
  }
  if (!sys->state_dependent_fields) {
    if (!sys->mixed_released) {
      PetscCall(MatDestroy(&sys->Jsv));
      PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_STRESS, PHLEX_FIELD_VELOCITY, &sys->Jsv));
      PetscCall(MatNestSetSubMat(sys->J, S, V, sys->Jsv));
    }
    /* also when the coupling block was never built: a residual or a displaced initial state may have assembled a
       body's G and Ms since */
    for (PetscInt i = 0; i < sys->nfparts; i++)
      if (sys->fparts[i]->fieldops->mixedoperators) PetscCall((*sys->fparts[i]->fieldops->mixedoperators)(sys->fparts[i], PETSC_FALSE));
    sys->mixed_released = PETSC_TRUE;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemReleaseVelocityBlock - frees the whole-state Jacobian's velocity block (each fixed body's shift Mv: 0.95 kB
  per velocity DOF) once SNES phlexcondensed solves the steps: its stage multiplies the condensed operators only; a
  placeholder in its place (and no border block Jvc) until PhlexSystemCompleteJacobian() builds it again

  Collective
@*/
PetscErrorCode PhlexSystemReleaseVelocityBlock(PhlexSystem sys)
{
  const PetscInt V = sys->field[PHLEX_FIELD_VELOCITY];

  PetscFunctionBeginUser;
  if (!sys->nfparts || sys->vv_released || sys->nq || sys->state_dependent_fields || sys->inexact_schur) PetscFunctionReturn(0);
  for (PetscInt i = 0; i < sys->nfparts; i++)
    if (!sys->fparts[i]->fieldops->velocityblock) PetscFunctionReturn(0);
  PetscCall(MatDestroy(&sys->Jvv));
  PetscCall(MatDestroy(&sys->Jvc));
  for (PetscInt i = 0; i < sys->nfparts; i++) PetscCall((*sys->fparts[i]->fieldops->velocityblock)(sys->fparts[i], PETSC_FALSE));
  PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Jvv));
  PetscCall(MatNestSetSubMat(sys->J, V, V, sys->Jvv));
  sys->vv_released = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* the velocity block, and the border block Jvc that shares it, built again after PhlexSystemReleaseVelocityBlock() */
static PetscErrorCode RestoreVelocityBlock(PhlexSystem sys)
{
  const PetscInt V = sys->field[PHLEX_FIELD_VELOCITY];
  Mat           *m, *c;

  PetscFunctionBeginUser;
  if (!sys->vv_released) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(sys->nfparts, &m, sys->nfparts, &c));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    PetscCall((*sys->fparts[i]->fieldops->velocityblock)(sys->fparts[i], PETSC_TRUE));
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    m[i] = ops.Jvv;
    c[i] = ops.Jvc;
  }
  PetscCall(MatDestroy(&sys->Jvv));
  PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Jvv));
  PetscCall(PhlexSystemBlockDiagonal(sys, c, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Jvc));
  PetscCall(MatNestSetSubMat(sys->J, V, V, sys->Jvv));
  PetscCall(PetscFree2(m, c));
  sys->vv_released = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/* the coupling block G of the bodies (stress rows, velocity columns), assembled again after a release */
static PetscErrorCode RestoreCoupling(PhlexSystem sys)
{
  const PetscInt S = sys->field[PHLEX_FIELD_STRESS], V = sys->field[PHLEX_FIELD_VELOCITY];
  Mat           *m;

  PetscFunctionBeginUser;
  if (!sys->mixed_released) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(sys->nfparts, &m));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    if (sys->fparts[i]->fieldops->mixedoperators) PetscCall((*sys->fparts[i]->fieldops->mixedoperators)(sys->fparts[i], PETSC_TRUE));
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    m[i] = ops.G;
  }
  PetscCall(MatDestroy(&sys->Jsv));
  PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_STRESS, PHLEX_FIELD_VELOCITY, &sys->Jsv));
  PetscCall(MatNestSetSubMat(sys->J, S, V, sys->Jsv));
  PetscCall(PetscFree(m));
  sys->mixed_released = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCompleteJacobian - builds the whole-state Jacobian's blocks that only the generic path multiplies: the
  stress block -shift Ms (all bodies' compliance masses in one AIJ, the cells' blocks as variable block sizes) and the
  resultant block G^T (a body's own, state-dependent one with geometric stiffening, else the transpose of its G);
  once, for Newton on the whole state (the steps, and the consistent start of a mechanism whose steps it solves)

  Collective
@*/
PetscErrorCode PhlexSystemCompleteJacobian(PhlexSystem sys)
{
  PhlexFieldOperators *ops;
  Mat                 *m, Jvs;
  const PetscInt       S = sys->field[PHLEX_FIELD_STRESS], V = sys->field[PHLEX_FIELD_VELOCITY];

  PetscFunctionBeginUser;
  if (!sys->nfparts) PetscFunctionReturn(0);
  PetscCall(RestoreCoupling(sys));
  PetscCall(RestoreVelocityBlock(sys));
  if (sys->Ms) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(sys->nfparts, &ops, sys->nfparts, &m));
  for (PetscInt i = 0; i < sys->nfparts; i++) PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops[i]));
  PetscCall(AssembleStressBlock(sys, ops, &sys->Ms));
  PetscCall(MatDestroy(&sys->Jss));
  PetscCall(MatDuplicate(sys->Ms, MAT_COPY_VALUES, &sys->Jss));
  {
    PetscInt        nb;
    const PetscInt *bsz;
    PetscCall(MatGetVariableBlockSizes(sys->Ms, &nb, &bsz));
    PetscCall(MatSetVariableBlockSizes(sys->Jss, nb, (PetscInt *)bsz));
  }
  if (sys->shift > 0) {
    /* a Jacobian was evaluated already (PhlexSystemIJacobian scales the block at a new shift only) */
    PetscCall(MatScale(sys->Jss, -sys->shift));
    PetscCall(MatAssemblyBegin(sys->Jss, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->Jss, MAT_FINAL_ASSEMBLY));
  }
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    if (ops[i].Gt) PetscCall(PetscObjectReference((PetscObject)ops[i].Gt));
    else PetscCall(MatTranspose(ops[i].G, MAT_INITIAL_MATRIX, &ops[i].Gt));
    m[i] = ops[i].Gt;
  }
  PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_STRESS, &Jvs));
  for (PetscInt i = 0; i < sys->nfparts; i++) PetscCall(MatDestroy(&m[i]));
  PetscCall(MatDestroy(&sys->Jvs));
  sys->Jvs = Jvs;
  PetscCall(MatNestSetSubMat(sys->J, S, S, sys->Jss));
  PetscCall(MatNestSetSubMat(sys->J, V, S, sys->Jvs));
  PetscCall(PetscFree2(ops, m));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCreate - the global unknowns, the Jacobian structure and the border data of a scene

  Collective

  Options Database Key:
. -phlex_jacobian_aij - also assemble the Jacobian as one AIJ matrix (monolithic factorisations, -snes_test_jacobian)
@*/
PetscErrorCode PhlexSystemCreate(PhlexScene scene, PhlexSystem *system)
{
  PhlexSystem          sys;
  PetscMPIInt          rank;
  PhlexFieldOperators *ops;
  PetscInt             nlocal[PHLEX_NUM_FIELDS] = {0, 0, 0, 0}, bs[PHLEX_NUM_FIELDS] = {3, 1, 3, 1};
  const char          *names[PHLEX_NUM_FIELDS];
  PetscInt             lsize[PHLEX_NUM_FIELDS], lbs[PHLEX_NUM_FIELDS], sbs = -1;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&sys));
  sys->eval_id[0] = 0;
  PetscCallMPI(MPI_Comm_rank(scene->comm, &rank));
  sys->scene   = scene;
  sys->comm    = scene->comm;
  sys->units   = &scene->units;
  sys->nparts  = scene->nparts;
  sys->parts   = scene->parts;
  sys->njoints = scene->njoints;
  sys->joints  = scene->joints;

  /* the parts with fields, their operators and places */
  PetscCall(PetscMalloc1(PetscMax(sys->nparts, 1), &sys->fparts));
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    if (p->Nv) sys->fparts[sys->nfparts++] = p;
    if (p->nonlinear) sys->nonlinear = PETSC_TRUE;
  }
  if (sys->njoints) sys->nonlinear = PETSC_TRUE; /* joint directions turn with the bodies */
  /* a body on a prescribed spin lives in its rotating frame: its ports' velocities are not inertial, and a joint to
     another part would join two different frames */
  for (PetscInt k = 0; k < sys->njoints; k++)
    for (PetscInt side = 0; side < 2; side++) {
      PhlexPart p    = sys->joints[k]->side[side].part;
      PetscReal rate = -1.0;
      if (p && PhlexPartAnalysisOp(p, spinrate)) PetscCall((*p->analysisops->spinrate)(p, PETSC_FALSE, &rate));
      if (rate >= 0 && p->frame.w >= 0) continue; /* a rotor in its hub's co-rotating frame (linearised analysis): its drive holds its frame */
      PetscCheck(rate < 0, sys->comm, PETSC_ERR_USER_INPUT, "joint %s: body %s turns on a prescribed spin (-%sspin), in its own rotating frame; it cannot be jointed to other parts (model the hub as a driven revolute joint and the body as floating)", sys->joints[k]->name, p->name, p->prefix);
    }
  PetscCall(PetscCalloc1(PetscMax(sys->nfparts, 1), &ops));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops[i]));
    nlocal[PHLEX_FIELD_DISPLACEMENT] += sys->fparts[i]->nu;
    nlocal[PHLEX_FIELD_STRESS] += sys->fparts[i]->ns;
    nlocal[PHLEX_FIELD_VELOCITY] += sys->fparts[i]->nv;
    sbs = (sbs < 0 || sbs == ops[i].stress_bs) ? ops[i].stress_bs : 1;
  }
  bs[PHLEX_FIELD_STRESS] = sbs > 0 ? sbs : 1;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    sys->parts[i]->qoff = sys->nq;
    sys->nq += sys->parts[i]->nq;
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    sys->joints[k]->qoff = sys->nq;
    sys->nq += PhlexJointNumUnknowns(sys->joints[k]);
  }
  sys->qlocal                     = rank == 0 ? sys->nq : 0;
  nlocal[PHLEX_FIELD_DISCRETE]    = sys->qlocal;
  PetscCall(PetscCalloc5(PetscMax(sys->nq, 1), &sys->q, PetscMax(sys->nq, 1), &sys->qd, PetscMax(sys->nq, 1), &sys->fq, PetscMax(sys->nq * sys->nq, 1), &sys->D, PetscMax(sys->nq, 1), &sys->qkind));
  for (PetscInt i = 0; i < sys->nparts; i++)
    for (PetscInt k = 0; k < sys->parts[i]->nq; k++) sys->qkind[sys->parts[i]->qoff + k] = sys->parts[i]->qkind[k];
  for (PetscInt k = 0; k < sys->njoints; k++) {
    const PhlexJoint j = sys->joints[k];
    for (PetscInt r = 0; r < j->nc; r++) sys->qkind[j->qoff + r] = PHLEX_DOF_IMPULSE;
    for (PetscInt r = 0; r < j->ne; r++) sys->qkind[j->qoff + j->nc + r] = PHLEX_DOF_ELEMENT_FORCE;
    for (PetscInt r = 0; r < j->ne; r++) sys->qkind[j->qoff + j->nc + j->ne + r] = PHLEX_DOF_ELEMENT;
  }

  /* the layout: the fields present */
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++) sys->field[f] = -1;
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++) {
    const PetscBool present = f == PHLEX_FIELD_DISCRETE ? (sys->nq > 0) : (sys->nfparts > 0);
    if (!present) continue;
    sys->field[f]          = sys->nfields;
    names[sys->nfields]    = PhlexFieldNames[f];
    lsize[sys->nfields]    = nlocal[f];
    lbs[sys->nfields]      = bs[f];
    sys->nfields++;
  }
  PetscCheck(sys->nfields, sys->comm, PETSC_ERR_USER_INPUT, "the scene has nothing that moves: no flexible body and no discrete unknowns");
  PetscCall(PhlexLayoutCreateDM(sys->comm, sys->nfields, names, lsize, lbs, PhlexSystemPmat, sys, &sys->dm));
  /* the same layout for auxiliary solvers (the consistent start): a solver's callbacks live on its DM */
  PetscCall(PhlexLayoutCreateDM(sys->comm, sys->nfields, names, lsize, lbs, PhlexSystemPmat, sys, &sys->dm_aux));
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++)
    if (sys->field[f] >= 0) PetscCall(PhlexLayoutGetFieldIS(sys->dm, sys->field[f], &sys->is[f]));

  /* each part's blocks in the global vector */
  {
    PetscInt fstart[PHLEX_NUM_FIELDS];
    for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++)
      if (sys->is[f]) PetscCall(ISGetMinMax(sys->is[f], &fstart[f], NULL));
    for (PetscInt i = 0; i < sys->nfparts; i++) {
      PhlexPart p = sys->fparts[i];
      PetscCall(ISCreateStride(sys->comm, p->nu, fstart[PHLEX_FIELD_DISPLACEMENT], 1, &p->isu));
      PetscCall(ISCreateStride(sys->comm, p->ns, fstart[PHLEX_FIELD_STRESS], 1, &p->iss));
      PetscCall(ISCreateStride(sys->comm, p->nv, fstart[PHLEX_FIELD_VELOCITY], 1, &p->isv));
      fstart[PHLEX_FIELD_DISPLACEMENT] += p->nu;
      fstart[PHLEX_FIELD_STRESS] += p->ns;
      fstart[PHLEX_FIELD_VELOCITY] += p->nv;
    }
  }
  /* and in the numbering of each field (the sub-blocks of the field blocks of the Jacobian) */
  for (PetscInt f = 0; f < 3; f++) {
    PetscInt start = 0, off;
    PetscCall(PetscMalloc1(PetscMax(sys->nfparts, 1), &sys->fis[f]));
    PetscCallMPI(MPI_Exscan(&nlocal[f], &start, 1, MPIU_INT, MPI_SUM, sys->comm));
    if (rank == 0) start = 0;
    off = start;
    for (PetscInt i = 0; i < sys->nfparts; i++) {
      const PetscInt n = f == PHLEX_FIELD_STRESS ? sys->fparts[i]->ns : sys->fparts[i]->nv;
      PetscCall(ISCreateStride(sys->comm, n, off, 1, &sys->fis[f][i]));
      off += n;
    }
  }

  /* the Jacobian */
  if (sys->nfparts) {
    Mat *m;
    PetscCall(PetscMalloc1(sys->nfparts, &m));
    PetscCall(IdentityMatrix(sys->comm, nlocal[PHLEX_FIELD_DISPLACEMENT], 1.0, &sys->Juu));
    PetscCall(IdentityMatrix(sys->comm, nlocal[PHLEX_FIELD_DISPLACEMENT], -1.0, &sys->Juv));
    /* the stress block -shift Ms and the resultant block G^T are multiplied by the generic path only (Newton on the
       whole state, in the steps and then also in the consistent start): until PhlexSystemCompleteJacobian() builds them they are placeholders that
       stop any product (the stages of SNES phlexcondensed and phlexreduced never need them: at 2.2e5 velocity DOFs
       they would hold 1.1 GB) */
    PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_STRESS, PHLEX_FIELD_STRESS, &sys->Jss));
    PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_STRESS, &sys->Jvs));
    /* the coupling block G: the bodies assemble G only when Newton on the whole state (or a displaced initial state)
       asks for it (FlexFieldOperators); until then a placeholder, built by PhlexSystemCompleteJacobian() */
    {
      PetscBool all = PETSC_TRUE;
      for (PetscInt i = 0; i < sys->nfparts; i++)
        if (!ops[i].G) all = PETSC_FALSE;
      if (all) {
        for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = ops[i].G;
        PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_STRESS, PHLEX_FIELD_VELOCITY, &sys->Jsv));
      } else {
        PetscCall(CreatePlaceholder(sys, PHLEX_FIELD_STRESS, PHLEX_FIELD_VELOCITY, &sys->Jsv));
        sys->mixed_released = PETSC_TRUE;
      }
    }
    for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = ops[i].Jvv;
    PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Jvv));
    for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = ops[i].Jvu;
    PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_DISPLACEMENT, &sys->Jvu));
    for (PetscInt i = 0; i < sys->nfparts; i++) m[i] = ops[i].Jvc;
    PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &sys->Jvc));
    /* geometric stiffening: the stress rows depend on u, and the field blocks change with the state */
    for (PetscInt i = 0; i < sys->nfparts; i++) {
      m[i] = ops[i].Jsu;
      if (ops[i].Jsu) sys->state_dependent_fields = PETSC_TRUE;
      if (ops[i].inexact_schur) sys->inexact_schur = PETSC_TRUE;
    }
    PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_STRESS, PHLEX_FIELD_DISPLACEMENT, &sys->Jsu));
    PetscCall(PetscFree(m));
  }
  PetscCall(MatCreateDense(sys->comm, sys->qlocal, sys->qlocal, sys->nq, sys->nq, NULL, &sys->Dq));
  PetscCall(MatZeroEntries(sys->Dq));
  PetscCall(MatAssemblyBegin(sys->Dq, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(sys->Dq, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)sys->Dq, "discrete block"));
  if (sys->nfparts && sys->nq) PetscCall(PhlexBorderCreateShells(sys));
  {
    const PetscInt nf = sys->nfields, U = sys->field[PHLEX_FIELD_DISPLACEMENT], S = sys->field[PHLEX_FIELD_STRESS], V = sys->field[PHLEX_FIELD_VELOCITY], Q = sys->field[PHLEX_FIELD_DISCRETE];
    Mat           *blocks;
    IS             isl[PHLEX_NUM_FIELDS];
    PetscCall(PetscCalloc1(nf * nf, &blocks));
    if (U >= 0) {
      blocks[U * nf + U] = sys->Juu, blocks[U * nf + V] = sys->Juv;
      blocks[S * nf + S] = sys->Jss, blocks[S * nf + V] = sys->Jsv, blocks[S * nf + U] = sys->Jsu;
      blocks[V * nf + U] = sys->Jvu, blocks[V * nf + S] = sys->Jvs, blocks[V * nf + V] = sys->Jvv;
    }
    if (Q >= 0) {
      blocks[Q * nf + Q] = sys->Dq;
      if (U >= 0) blocks[V * nf + Q] = sys->Bvq, blocks[Q * nf + U] = sys->Cqu, blocks[Q * nf + V] = sys->Cqv;
    }
    for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++)
      if (sys->field[f] >= 0) isl[sys->field[f]] = sys->is[f];
    PetscCall(MatCreateNest(sys->comm, nf, isl, nf, isl, blocks, &sys->J));
    PetscCall(PetscFree(blocks));
  }
  PetscCall(PetscObjectSetName((PetscObject)sys->J, "Jacobian"));
  PetscOptionsBegin(sys->comm, NULL, "System options", NULL);
  PetscCall(PetscOptionsBool("-phlex_jacobian_aij", "Also assemble the Jacobian as one AIJ matrix (monolithic factorisations, -snes_test_jacobian)", "PhlexSystemCreate", sys->use_aij, &sys->use_aij, NULL));
  PetscOptionsEnd();
  PetscCall(PetscMalloc2(PetscMax(sys->nfparts, 1), &sys->xu, PetscMax(sys->nfparts, 1), &sys->xv));
  PetscCall(PetscFree(ops));
  PetscCall(PhlexSystemSetUpBorder(sys));
  if (!sys->nfparts) {
    /* no flexible body: PC phlexbordered works on the whole (dense) system */
    PetscContainer c;
    PetscCall(PetscContainerCreate(sys->comm, &c));
    PetscCall(PetscContainerSetPointer(c, &sys->border));
    PetscCall(PetscObjectCompose((PetscObject)sys->J, "phlex_border", (PetscObject)c));
    PetscCall(PetscContainerDestroy(&c));
  }
  *system = sys;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemJacobianPmat - the preconditioning matrix of a Newton solve on the whole state: with -phlex_jacobian_aij
  the assembled Jacobian, unless the preconditioner is a field split, which takes its blocks (and the stress rows'
  cell block sizes that point-block Jacobi needs) from the nested one; else the nested one

  Not collective
@*/
PetscErrorCode PhlexSystemJacobianPmat(PhlexSystem sys, KSP ksp, Mat *P)
{
  PC        pc;
  PetscBool split;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PetscObjectTypeCompare((PetscObject)pc, PCFIELDSPLIT, &split));
  *P = (sys->use_aij && !split) ? sys->Jaij : sys->J;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCreateForScene - the system of a scene, its initial state and the joints' geometry at the drawn
  configuration; redundant constraint components found (and dropped if asked: the layout changes, the initial state
  is carried over). Both the transient and the linearised analysis start here.

  Collective
@*/
PetscErrorCode PhlexSystemCreateForScene(PhlexScene scene, PhlexSystem *sys, Vec *X)
{
  PetscInt ndropped = 0;

  PetscFunctionBeginUser;
  /* eigensolves of the initial state first: their factorizations are freed before the operators are built */
  for (PetscInt i = 0; i < scene->nparts; i++)
    if (scene->parts[i]->ops.prepareinitialstate) PetscCall((*scene->parts[i]->ops.prepareinitialstate)(scene->parts[i]));
  PetscCall(PhlexSystemCreate(scene, sys));
  PetscCall(DMCreateGlobalVector((*sys)->dm, X));
  PetscCall(PetscObjectSetName((PetscObject)*X, "state"));
  PetscCall(PhlexSystemInitialState(*sys, *X));
  if (!(*sys)->njoints) PetscFunctionReturn(0);
  PetscCall(PhlexAssemblyPlaceAttached(*sys, *X));
  for (PetscInt k = 0; k < (*sys)->njoints; k++) {
    PhlexJoint   j = (*sys)->joints[k];
    PhlexPartVec pv[2];
    PetscCall(PhlexSystemJointSides(*sys, j, *X, (*sys)->q, pv));
    PetscCall(PhlexJointSetUp(j, &pv[0], &pv[1]));
    PetscCall(PhlexSystemJointSidesRestore(*sys, j, *X, pv));
  }
  PetscCall(PhlexAssemblyRedundancy(*sys, *X, &ndropped));
  if (ndropped) {
    /* the joints lost rows: a new layout; the fields and the parts' discrete unknowns are carried over (they come
       first among the discrete unknowns and keep their places), the impulses start at zero */
    PhlexSystem old = *sys;
    Vec         fields[3] = {NULL, NULL, NULL};
    PetscReal  *q;
    PetscCall(PetscMalloc1(PetscMax(old->nq, 1), &q));
    PetscCall(PhlexSystemGather(old, *X, q));
    for (PetscInt f = 0; f < 3 && old->nfparts; f++) {
      Vec a;
      PetscCall(VecGetSubVector(*X, old->is[f], &a));
      PetscCall(VecDuplicate(a, &fields[f]));
      PetscCall(VecCopy(a, fields[f]));
      PetscCall(VecRestoreSubVector(*X, old->is[f], &a));
    }
    PetscCall(VecDestroy(X));
    PetscCall(PhlexSystemDestroy(&old));
    PetscCall(PhlexSystemCreate(scene, sys));
    PetscCall(DMCreateGlobalVector((*sys)->dm, X));
    PetscCall(PetscObjectSetName((PetscObject)*X, "state"));
    PetscCall(VecSet(*X, 0.0));
    for (PetscInt f = 0; f < 3 && fields[f]; f++) {
      Vec b;
      PetscCall(VecGetSubVector(*X, (*sys)->is[f], &b));
      PetscCall(VecCopy(fields[f], b));
      PetscCall(VecRestoreSubVector(*X, (*sys)->is[f], &b));
      PetscCall(VecDestroy(&fields[f]));
    }
    for (PetscInt k = 0; k < (*sys)->nq; k++) (*sys)->q[k] = 0.0;
    for (PetscInt i = 0; i < (*sys)->nparts; i++)
      for (PetscInt k = 0; k < (*sys)->parts[i]->nq; k++) (*sys)->q[(*sys)->parts[i]->qoff + k] = q[(*sys)->parts[i]->qoff + k];
    PetscCall(PhlexSystemScatter(*sys, (*sys)->q, *X));
    PetscCall(PetscFree(q));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemGather - the discrete unknowns of a global vector on every rank (they live on rank 0)

  Collective
@*/
PetscErrorCode PhlexSystemGather(PhlexSystem sys, Vec X, PetscReal *q)
{
  Vec                xq;
  const PetscScalar *a;

  PetscFunctionBeginUser;
  if (!sys->nq) PetscFunctionReturn(0);
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscCall(VecGetArrayRead(xq, &a));
  for (PetscInt k = 0; k < sys->qlocal; k++) q[k] = PetscRealPart(a[k]);
  PetscCall(VecRestoreArrayRead(xq, &a));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscCallMPI(MPI_Bcast(q, (PetscMPIInt)sys->nq, MPIU_REAL, 0, sys->comm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemScatter - writes replicated discrete values into a global vector (rank 0's part)

  Collective
@*/
PetscErrorCode PhlexSystemScatter(PhlexSystem sys, const PetscReal *q, Vec X)
{
  Vec          xq;
  PetscScalar *a;

  PetscFunctionBeginUser;
  if (!sys->nq) PetscFunctionReturn(0);
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscCall(VecGetArray(xq, &a));
  for (PetscInt k = 0; k < sys->qlocal; k++) a[k] = q[k];
  PetscCall(VecRestoreArray(xq, &a));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemPartVec - a part's view of a global vector whose discrete values (replicated) are q
@*/
PetscErrorCode PhlexSystemPartVec(PhlexSystem sys, PhlexPart p, Vec X, PetscReal *q, PhlexPartVec *pv)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexPartGetVec(p, X, q, pv));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexSystemPartVecRestore(PhlexSystem sys, PhlexPart p, Vec X, PhlexPartVec *pv)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexPartRestoreVec(p, X, pv));
  PetscFunctionReturn(0);
}

/* evaluate every part at (t, X, X') (X' NULL: rest), then the joints, which set the port wrenches */
static PetscErrorCode EvaluateAll(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot, Vec P, PhlexPartVec *pX, PhlexPartVec *pXd)
{
  PetscFunctionBeginUser;
  sys->eval_id[0] = 0; /* no record while the parts are being evaluated */
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  if (Xdot) PetscCall(PhlexSystemGather(sys, Xdot, sys->qd));
  for (PetscInt i = 0, f = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    for (PetscInt k = 0; k < p->nports; k++)
      for (PetscInt c = 0; c < 6; c++) p->wrench[k][c] = 0.0;
    PetscCall(PhlexPartGetVec(p, X, sys->q, &pX[i]));
    if (Xdot) PetscCall(PhlexPartGetVec(p, Xdot, sys->qd, &pXd[i]));
    if (P && p->Nv) PetscCall(VecGetSubVector(P, sys->fis[PHLEX_FIELD_VELOCITY][f], &pX[i].p));
    if (p->Nv) f++;
  }
  /* every part's local work first, then the sums (split_sum.c): bodies whole on different processes in parallel */
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    if (p->fieldops) PetscCall((*p->fieldops->evaluatebegin)(p, t, &pX[i], Xdot ? &pXd[i] : NULL));
  }
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    PetscCall((*p->ops.evaluate)(p, t, &pX[i], Xdot ? &pXd[i] : NULL));
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PetscCall(PhlexJointEvaluate(sys->joints[k], t, sys->q, Xdot ? sys->qd : NULL));
    PetscCall(PhlexJointApplyWrenches(sys->joints[k]));
  }
  PetscFunctionReturn(0);
}

/* the record of the state the parts were evaluated at (Xdot NULL: none kept, rest is not recorded) */
static PetscErrorCode EvaluationRecord(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot)
{
  PetscFunctionBeginUser;
  sys->eval_id[0] = 0;
  if (!Xdot) PetscFunctionReturn(0);
  PetscCall(PetscObjectGetId((PetscObject)X, &sys->eval_id[0]));
  PetscCall(PetscObjectGetId((PetscObject)Xdot, &sys->eval_id[1]));
  PetscCall(PetscObjectStateGet((PetscObject)X, &sys->eval_state[0]));
  PetscCall(PetscObjectStateGet((PetscObject)Xdot, &sys->eval_state[1]));
  sys->eval_t = t;
  PetscFunctionReturn(0);
}

/* whether the parts are evaluated at (t, X, X') (unchanged since a residual there) */
static PetscErrorCode EvaluatedAt(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot, PetscBool *same)
{
  PetscObjectId    id[2];
  PetscObjectState st[2];

  PetscFunctionBeginUser;
  *same = PETSC_FALSE;
  if (!Xdot || !sys->eval_id[0] || t != sys->eval_t) PetscFunctionReturn(0);
  PetscCall(PetscObjectGetId((PetscObject)X, &id[0]));
  PetscCall(PetscObjectGetId((PetscObject)Xdot, &id[1]));
  PetscCall(PetscObjectStateGet((PetscObject)X, &st[0]));
  PetscCall(PetscObjectStateGet((PetscObject)Xdot, &st[1]));
  *same = (PetscBool)(id[0] == sys->eval_id[0] && id[1] == sys->eval_id[1] && st[0] == sys->eval_state[0] && st[1] == sys->eval_state[1]);
  PetscFunctionReturn(0);
}

static PetscErrorCode RestoreAll(PhlexSystem sys, Vec X, Vec Xdot, Vec P, PhlexPartVec *pX, PhlexPartVec *pXd)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0, f = 0; i < sys->nparts; i++) {
    if (P && sys->parts[i]->Nv) PetscCall(VecRestoreSubVector(P, sys->fis[PHLEX_FIELD_VELOCITY][f], &pX[i].p));
    if (sys->parts[i]->Nv) f++;
    PetscCall(PhlexPartRestoreVec(sys->parts[i], X, &pX[i]));
    if (Xdot) PetscCall(PhlexPartRestoreVec(sys->parts[i], Xdot, &pXd[i]));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemEvaluate - evaluates every part and joint at (t, X, X') (X' NULL: rest); the parts' views of X are
  released afterwards (outputs take them again)

  Collective
@*/
PetscErrorCode PhlexSystemEvaluate(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot)
{
  PhlexPartVec *pX, *pXd;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(PetscMax(sys->nparts, 1), &pX, PetscMax(sys->nparts, 1), &pXd));
  PetscCall(EvaluateAll(sys, t, X, Xdot, NULL, pX, pXd));
  PetscCall(RestoreAll(sys, X, Xdot, NULL, pX, pXd));
  PetscCall(PetscFree2(pX, pXd));
  PetscFunctionReturn(0);
}

/* F(t, X, X'); with P (a velocity field: each body's G^T Sigma) the displacement and stress are eliminated by the
   caller and only the velocity and discrete rows are written */
static PetscErrorCode Residual(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot, Vec P, Vec F)
{
  PhlexPartVec *pX, *pXd, *pF;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_SysIFunction, 0, 0, 0, 0));
  PetscCall(PetscMalloc3(PetscMax(sys->nparts, 1), &pX, PetscMax(sys->nparts, 1), &pXd, PetscMax(sys->nparts, 1), &pF));
  PetscCall(EvaluateAll(sys, t, X, Xdot, P, pX, pXd));
  for (PetscInt k = 0; k < sys->nq; k++) sys->fq[k] = 0.0;
  /* every part's rows of F taken (collective) before any part's residual (local): parts whole on different processes
     compute theirs at the same time (split_sum.c) */
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall(PhlexPartGetVec(sys->parts[i], F, sys->fq, &pF[i]));
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    PetscCall((*p->ops.residual)(p, t, &pX[i], &pXd[i], &pF[i]));
  }
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall(PhlexPartRestoreVec(sys->parts[i], F, &pF[i]));
  PetscCall(PetscLogEventBegin(PHLEX_JointResidual, 0, 0, 0, 0));
  for (PetscInt k = 0; k < sys->njoints; k++) PetscCall(PhlexJointResidual(sys->joints[k], t, sys->fq));
  PetscCall(PetscLogEventEnd(PHLEX_JointResidual, 0, 0, 0, 0));
  PetscCall(PhlexSystemScatter(sys, sys->fq, F));
  PetscCall(RestoreAll(sys, X, Xdot, P, pX, pXd));
  PetscCall(EvaluationRecord(sys, t, X, Xdot));
  PetscCall(PetscFree3(pX, pXd, pF));
  PetscCall(PetscLogEventEnd(PHLEX_SysIFunction, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemIFunction - F(t, X, X') of the scene (TS IFunction; t and X' in SI time)

  Collective
@*/
PetscErrorCode PhlexSystemIFunction(TS ts, PetscReal t, Vec X, Vec Xdot, Vec F, void *ctx)
{
  PetscFunctionBeginUser;
  PetscCall(Residual((PhlexSystem)ctx, t, X, Xdot, NULL, F));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemReducedResidual - the velocity and discrete rows of F(t, X, X') with the displacement and the stress
  eliminated by the caller: P holds each body's stress resultant G^T Sigma (velocity field numbering); the stress block
  of X is not read, the displacement and stress rows of F are not written

  Collective
@*/
PetscErrorCode PhlexSystemReducedResidual(PhlexSystem sys, PetscReal t, Vec X, Vec Xdot, Vec P, Vec F)
{
  PetscFunctionBeginUser;
  PetscCall(Residual(sys, t, X, Xdot, P, F));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCondensedOperator - block diagonal over the bodies of one of their velocity-space operators: which = 0
  the condensed operators shift Mv + K/shift (each part's Sv, at the shift last evaluated), 1 the masses Mv, 2 the
  condensed stiffnesses K, 3 the state's stiffnesses K_sigma + Cen, 4 the gyroscopic (Coriolis) matrices, 5 the
  structural damping R; the part's own matrix for one body, else a MATNEST of them; NULL when no body has one (3-5)

  Collective
@*/
PetscErrorCode PhlexSystemCondensedOperator(PhlexSystem sys, PetscInt which, Mat *N)
{
  Mat *m;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(PetscMax(sys->nfparts, 1), &m));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PhlexFieldOperators ops;
    /* the masses and stiffnesses in AIJ: a fixed body frees its copies at the set-up (FlexFieldOperators) */
    if ((which == 1 || which == 2) && sys->fparts[i]->fieldops->mixedoperators) PetscCall((*sys->fparts[i]->fieldops->mixedoperators)(sys->fparts[i], PETSC_TRUE));
    PetscCall((*sys->fparts[i]->fieldops->fieldoperators)(sys->fparts[i], &ops));
    m[i] = which == 0 ? ops.Sv : (which == 1 ? ops.M : (which == 2 ? ops.K : (which == 3 ? ops.Kstate : (which == 4 ? ops.Gyro : ops.R))));
  }
  PetscCall(PhlexSystemBlockDiagonal(sys, m, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, N));
  PetscCall(PetscFree(m));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexSystemIJacobian(TS ts, PetscReal t, Vec X, Vec Xdot, PetscReal shift, Mat A, Mat P, void *ctx)
{
  PhlexSystem     sys = (PhlexSystem)ctx;
  const PetscReal s   = shift * sys->units->time; /* non-dimensional shift */
  const PetscBool new_shift = PetscAbsReal(s - sys->shift) > 1e-12 * s ? PETSC_TRUE : PETSC_FALSE;
  PhlexPartVec   *pX, *pXd;

  PetscFunctionBeginUser;
  /* multistep methods recompute the shift from the step size: ignore round-off changes */
  if (!sys->nonlinear && !new_shift) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_SysIJacobian, 0, 0, 0, 0));
  if (new_shift) {
    sys->shift = s;
    if (sys->nfparts) {
      PetscCall(MatScale(sys->Juu, 0.0));
      PetscCall(MatShift(sys->Juu, s));
      /* assembling resets the matrices' cached diagonal (block) inverses (point-block Jacobi on the stress block
         would otherwise keep the inverse of the previous shift's block) */
      PetscCall(MatAssemblyBegin(sys->Juu, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(sys->Juu, MAT_FINAL_ASSEMBLY));
      if (sys->Ms) {
        PetscCall(MatCopy(sys->Ms, sys->Jss, SAME_NONZERO_PATTERN));
        PetscCall(MatScale(sys->Jss, -s));
        PetscCall(MatAssemblyBegin(sys->Jss, MAT_FINAL_ASSEMBLY));
        PetscCall(MatAssemblyEnd(sys->Jss, MAT_FINAL_ASSEMBLY));
      }
    }
  }
  PetscCall(PetscMalloc2(PetscMax(sys->nparts, 1), &pX, PetscMax(sys->nparts, 1), &pXd));
  {
    /* a Jacobian right after a residual at the same state (Newton) finds the parts evaluated there */
    PetscBool same;
    PetscCall(EvaluatedAt(sys, t, X, Xdot, &same));
    if (same) {
      PetscCall(PhlexSystemGather(sys, X, sys->q));
      PetscCall(PhlexSystemGather(sys, Xdot, sys->qd));
      for (PetscInt i = 0; i < sys->nparts; i++) {
        PetscCall(PhlexPartGetVec(sys->parts[i], X, sys->q, &pX[i]));
        PetscCall(PhlexPartGetVec(sys->parts[i], Xdot, sys->qd, &pXd[i]));
      }
    } else PetscCall(EvaluateAll(sys, t, X, Xdot, NULL, pX, pXd));
  }
  for (PetscInt k = 0; k < sys->nq * sys->nq; k++) sys->D[k] = 0.0;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    PetscCall((*p->ops.jacobian)(p, s, &pX[i], sys->D + p->qoff * sys->nq + p->qoff, sys->nq));
  }
  for (PetscInt k = 0; k < sys->njoints; k++) PetscCall(PhlexJointJacobian(sys->joints[k], s, sys->D, sys->nq));
  PetscCall(RestoreAll(sys, X, Xdot, NULL, pX, pXd));
  PetscCall(PetscFree2(pX, pXd));
  if (sys->nq) {
    PetscScalar *da;
    PetscInt     lda;
    PetscCall(MatDenseGetLDA(sys->Dq, &lda));
    PetscCall(MatDenseGetArrayWrite(sys->Dq, &da));
    for (PetscInt i = 0; i < sys->qlocal; i++)
      for (PetscInt j = 0; j < sys->nq; j++) da[j * lda + i] = sys->D[sys->nq * i + j];
    PetscCall(MatDenseRestoreArrayWrite(sys->Dq, &da));
  }
  /* the preconditioning matrices of the splits: the condensed velocity operators changed with the shift */
  if ((new_shift || sys->state_dependent_fields) && sys->Sv && sys->nfparts > 1) {
    Mat N;
    PetscCall(PhlexSystemCondensedOperator(sys, 0, &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_REUSE_MATRIX, &sys->Sv));
    PetscCall(MatDestroy(&N));
  }
  if (sys->Ssv && (new_shift || sys->state_dependent_fields)) {
    Mat blocks[4] = {sys->Jss, sys->Jsv, sys->Jvs, sys->Jvv}, N;
    PetscCall(MatCreateNest(sys->comm, 2, NULL, 2, NULL, blocks, &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_REUSE_MATRIX, &sys->Ssv));
    PetscCall(MatDestroy(&N));
  }
  /* the blocks changed in place: raise the nests' states (assembling a nest would also raise the state of every
     block, and the factorisations of the unchanged ones would be redone) */
  if (sys->Bvq) {
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Bvq));
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Cqu));
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Cqv));
  }
  if (sys->Jvv && sys->nfparts > 1) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvv));
  if (sys->Jvu && sys->nfparts > 1) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvu));
  if (sys->Jvc && sys->nfparts > 1) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvc));
  if (sys->state_dependent_fields && sys->nfparts > 1) {
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jsv));
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvs));
    PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jsu));
  }
  PetscCall(PetscObjectStateIncrease((PetscObject)sys->J));
  if (sys->Pvq) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Pvq));
  if (sys->use_aij) {
    Mat Jaij;
    PetscCall(PhlexSystemCompleteJacobian(sys));
    /* shells and virtual blocks: build the operator column by column (small test meshes) */
    PetscCall(MatComputeOperator(sys->J, MATAIJ, &Jaij));
    if (!sys->Jaij) sys->Jaij = Jaij;
    else {
      PetscObjectState before, after;
      PetscCall(MatGetNonzeroState(sys->Jaij, &before));
      PetscCall(MatCopy(Jaij, sys->Jaij, DIFFERENT_NONZERO_PATTERN));
      PetscCall(MatDestroy(&Jaij));
      PetscCall(MatGetNonzeroState(sys->Jaij, &after));
      /* the product's pattern holds the entries that are nonzero at this state: when it changed, a field split on
         the nested operator (PhlexSystemJacobianPmat) must take the assembled operator's blocks anew, which it does
         only for a new nonzero state of its preconditioning matrix */
      if (after != before) sys->J->nonzerostate++;
    }
    if (A != sys->Jaij && A != sys->J) PetscCall(MatCopy(sys->Jaij, A, DIFFERENT_NONZERO_PATTERN));
  }
  PetscCall(PetscLogEventEnd(PHLEX_SysIJacobian, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemInitialState - every part's initial unknowns (impulses zero)

  Collective
@*/
PetscErrorCode PhlexSystemInitialState(PhlexSystem sys, Vec X)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(X, 0.0));
  for (PetscInt k = 0; k < sys->nq; k++) sys->q[k] = 0.0;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart    p = sys->parts[i];
    PhlexPartVec pv;
    PetscCall(PhlexPartGetVec(p, X, sys->q, &pv));
    PetscCall((*p->ops.initialstate)(p, &pv));
    PetscCall(PhlexPartRestoreVec(p, X, &pv));
  }
  PetscCall(PhlexSystemScatter(sys, sys->q, X));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemEnergy - kinetic, strain and potential energy of all parts at (t, X) (non-dimensional); the parts are
  left evaluated at X

  Collective
@*/
PetscErrorCode PhlexSystemEnergy(PhlexSystem sys, PetscReal t, Vec X, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  PhlexPartVec *pv;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemEvaluate(sys, t, X, NULL));
  *kin = *strain = *pot = 0.0;
  PetscCall(PetscMalloc1(PetscMax(sys->nparts, 1), &pv));
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall(PhlexPartGetVec(sys->parts[i], X, sys->q, &pv[i]));
  /* every part's local sums first, then their reductions (split_sum.c) */
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    if (p->fieldops) PetscCall((*p->fieldops->energybegin)(p, &pv[i]));
  }
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    PetscReal k, s, v;
    PetscCall((*p->ops.energy)(p, &pv[i], &k, &s, &v));
    *kin += k, *strain += s, *pot += v;
  }
  /* the energy stored in the joints' force elements (springs) counts as strain energy */
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PetscReal V;
    PetscCall(PhlexJointElementEnergy(sys->joints[k], t, sys->q, &V));
    *strain += V;
  }
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall(PhlexPartRestoreVec(sys->parts[i], X, &pv[i]));
  PetscCall(PetscFree(pv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemInitElements - the initial states of the joints' force elements from the configuration in X (after the
  assembly closed the joints), written into X

  Collective
@*/
PetscErrorCode PhlexSystemInitElements(PhlexSystem sys, Vec X)
{
  PetscBool any = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < sys->njoints; k++)
    if (sys->joints[k]->ne) any = PETSC_TRUE;
  if (!any) PetscFunctionReturn(0);
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint   j = sys->joints[k];
    PhlexPartVec pv[2];
    PetscReal    e0[6];
    if (!j->ne) continue;
    PetscCall(PhlexSystemJointSides(sys, j, X, sys->q, pv));
    PetscCall(PhlexJointElementInitial(j, &pv[0], &pv[1], e0));
    PetscCall(PhlexSystemJointSidesRestore(sys, j, X, pv));
    for (PetscInt i = 0; i < j->ne; i++) sys->q[j->qoff + j->nc + j->ne + i] = e0[i];
  }
  PetscCall(PhlexSystemScatter(sys, sys->q, X));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemJointSides - the part vectors of both sides of joint j at X (q: the replicated discrete unknowns of X);
  the ground's are empty, a joint between two ports of one part shares one view

  Collective
@*/
PetscErrorCode PhlexSystemJointSides(PhlexSystem sys, PhlexJoint j, Vec X, PetscReal *q, PhlexPartVec pv[2])
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    pv[s].u = pv[s].s = pv[s].v = pv[s].p = NULL;
    pv[s].q                     = NULL;
    if (PhlexPartIsGround(p)) continue;
    if (s == 1 && p == j->side[0].part) {
      pv[1] = pv[0];
      continue;
    }
    PetscCall(PhlexPartGetVec(p, X, q, &pv[s]));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexSystemJointSidesRestore(PhlexSystem sys, PhlexJoint j, Vec X, PhlexPartVec pv[2])
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    if (PhlexPartIsGround(p) || (s == 1 && p == j->side[0].part)) continue;
    PetscCall(PhlexPartRestoreVec(p, X, &pv[s]));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemUpdateJoints - the joints' directions and arms for a step of length dt from the accepted state X
  (PhlexJointUpdateGeometry), at the displacements extrapolated to the middle of the step, u + dt/2 u' (u' = v),
  and a reduced body's elastic coordinates likewise, eta + dt/2 eta' (eta' = zeta)

  Collective

  Notes:
  The directions are held over the step (no Jacobian term); taking them at the step's middle instead of its start
  makes their lag behind the ports' elastic rotation second order in dt.
@*/
PetscErrorCode PhlexSystemUpdateJoints(PhlexSystem sys, Vec X, PetscReal dt)
{
  Vec       Xm;
  PetscBool flexible = PETSC_FALSE;

  PetscFunctionBeginUser;
  /* only the port of a deforming part (a flexible body's field, a reduced body's elastic coordinates) turns
     relative to its body frame */
  for (PetscInt k = 0; k < sys->njoints; k++)
    for (PetscInt s = 0; s < 2; s++)
      if (PhlexPartIsElastic(sys->joints[k]->side[s].part)) flexible = PETSC_TRUE;
  if (!flexible) PetscFunctionReturn(0);
  sys->eval_id[0] = 0; /* the joints' geometry changes */
  if (!sys->Xwork) PetscCall(VecDuplicate(X, &sys->Xwork));
  Xm = sys->Xwork;
  PetscCall(VecCopy(X, Xm));
  if (sys->nfparts) {
    Vec um, v;
    PetscCall(VecGetSubVector(Xm, sys->is[PHLEX_FIELD_DISPLACEMENT], &um));
    PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
    PetscCall(VecAXPY(um, 0.5 * dt / sys->scene->units.time, v));
    PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
    PetscCall(VecRestoreSubVector(Xm, sys->is[PHLEX_FIELD_DISPLACEMENT], &um));
  }
  PetscCall(PhlexSystemGather(sys, Xm, sys->q));
  /* elastic coordinates likewise, eta + dt/2 eta' (eta' = zeta: a part's n-th elastic velocity is the rate of its
     n-th elastic coordinate) */
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p  = sys->parts[i];
    PetscInt  iv = 0;
    for (PetscInt ie = 0; ie < p->nq; ie++) {
      if (p->qkind[ie] != PHLEX_DOF_ELASTIC) continue;
      while (iv < p->nq && p->qkind[iv] != PHLEX_DOF_ELASTIC_VELOCITY) iv++;
      PetscCheck(iv < p->nq, sys->comm, PETSC_ERR_PLIB, "body %s: elastic coordinate %s has no velocity", p->name, p->qname[ie]);
      sys->q[p->qoff + ie] += 0.5 * dt / sys->scene->units.time * sys->q[p->qoff + iv];
      iv++;
    }
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexPartVec pv[2];
    PetscCall(PhlexSystemJointSides(sys, sys->joints[k], Xm, sys->q, pv));
    PetscCall(PhlexJointUpdateGeometry(sys->joints[k], &pv[0], &pv[1]));
    PetscCall(PhlexSystemJointSidesRestore(sys, sys->joints[k], Xm, pv));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemPostStep - after a step: every part cleans its discrete unknowns (rotations back onto SO(3));
  returns the largest correction

  Collective
@*/
PetscErrorCode PhlexSystemPostStep(PhlexSystem sys, Vec X, PetscReal *defect)
{
  PetscFunctionBeginUser;
  *defect = 0.0;
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    PetscReal d;
    if (!p->ops.poststep || !p->nq) continue;
    PetscCall((*p->ops.poststep)(p, sys->q + p->qoff, &d));
    *defect = PetscMax(*defect, d);
  }
  PetscCall(PhlexSystemScatter(sys, sys->q, X));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemDestroy - frees the system
@*/
PetscErrorCode PhlexSystemDestroy(PhlexSystem *system)
{
  PhlexSystem sys = *system;

  PetscFunctionBeginUser;
  if (!sys) PetscFunctionReturn(0);
  PetscCall(VecDestroy(&sys->Xwork));
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++) PetscCall(ISDestroy(&sys->is[f]));
  for (PetscInt i = 0; i < sys->nfparts; i++) {
    PetscCall(ISDestroy(&sys->fparts[i]->isu));
    PetscCall(ISDestroy(&sys->fparts[i]->iss));
    PetscCall(ISDestroy(&sys->fparts[i]->isv));
    for (PetscInt f = 0; f < 3; f++)
      if (sys->fis[f]) PetscCall(ISDestroy(&sys->fis[f][i]));
  }
  for (PetscInt f = 0; f < 3; f++) PetscCall(PetscFree(sys->fis[f]));
  PetscCall(MatDestroy(&sys->J));
  PetscCall(MatDestroy(&sys->Jaij));
  PetscCall(MatDestroy(&sys->Juu));
  PetscCall(MatDestroy(&sys->Juv));
  PetscCall(MatDestroy(&sys->Ms));
  PetscCall(MatDestroy(&sys->Jss));
  PetscCall(MatDestroy(&sys->Jsv));
  PetscCall(MatDestroy(&sys->Jvs));
  PetscCall(MatDestroy(&sys->Jvv));
  PetscCall(MatDestroy(&sys->Jvu));
  PetscCall(MatDestroy(&sys->Jvc));
  PetscCall(MatDestroy(&sys->Jsu));
  PetscCall(MatDestroy(&sys->Bvq));
  PetscCall(MatDestroy(&sys->Cqu));
  PetscCall(MatDestroy(&sys->Cqv));
  PetscCall(MatDestroy(&sys->Cpre));
  PetscCall(MatDestroy(&sys->Dq));
  PetscCall(MatDestroy(&sys->Sv));
  PetscCall(MatDestroy(&sys->Pvq));
  PetscCall(MatDestroy(&sys->Ssv));
  PetscCall(MatDestroy(&sys->Abd));
  PetscCall(PetscFree(sys->border.A));
  PetscCall(PetscFree(sys->border.W));
  PetscCall(PetscFree2(sys->border.off, sys->border.n));
  PetscCall(PetscFree5(sys->q, sys->qd, sys->fq, sys->D, sys->qkind));
  PetscCall(PetscFree2(sys->xu, sys->xv));
  PetscCall(PetscFree(sys->fparts));
  PetscCall(DMDestroy(&sys->dm));
  PetscCall(DMDestroy(&sys->dm_aux));
  PetscCall(PetscFree(*system));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemSNESConverged - Newton convergence of a nonlinear scene: PETSc's tests (-snes_rtol, -snes_atol, ...),
  plus stagnation at the round-off floor of the residual. The residual carries shift (X - X_n) terms, so its floor
  grows with the state and the shift (a body far from the origin, a very short step): a fixed -snes_atol may be out
  of reach. Newton is accepted as converged once the residual no longer decreases (by half) and is below
  100 eps shift ||X||.

  Collective
@*/
PetscErrorCode PhlexSystemSNESConverged(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm, SNESConvergedReason *reason, void *ctx)
{
  PhlexSystem sys = (PhlexSystem)ctx;

  PetscFunctionBeginUser;
  PetscCall(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, NULL));
  if (it == 0) sys->fprev = PETSC_MAX_REAL;
  if (it > 0 && (*reason == SNES_CONVERGED_ITERATING || *reason == SNES_DIVERGED_MAX_IT)) {
    const PetscReal floor = 100.0 * PETSC_MACHINE_EPSILON * PetscMax(1.0, sys->shift) * xnorm;
    if (fnorm <= floor && fnorm >= 0.5 * sys->fprev) *reason = SNES_CONVERGED_FNORM_ABS;
  }
  if (sys->jreuse > 0) {
    /* after an iteration that reduced the residual by jreuse or more the next one keeps the Jacobian and its
       factorization (lag -1: SNESComputeJacobian returns at once): the stale Jacobian's contraction is then about
       as strong (modified Newton), at the cost of a residual and a back-substitution. Each step starts with a new
       one, so a run repeats itself across a restart; a slow iteration (a hard step) rebuilds it */
    const PetscBool keep = (*reason == SNES_CONVERGED_ITERATING && it > 0 && fnorm <= sys->jreuse * sys->fprev) ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(SNESSetLagJacobian(snes, keep ? -1 : 1));
  }
  sys->fprev = fnorm;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemSNESConvergedStage - Newton convergence of a stage on the whole state (the generic path: BDF,
  Crank-Nicolson, generalized-alpha, -snes_type newtonls): PhlexSystemSNESConverged, and in a scene with discrete
  unknowns also the velocity rows, below sys->vrtol of their residual at the stage's initial guess, or no longer
  halved by an iteration (stalled: at their round-off, or as far as the linear solves' tolerance takes them). The
  frames' and joints' rows are orders of magnitude larger than the elastic ones (mass-matrix entries times elastic
  velocities), so the whole residual passes -snes_atol while the elastic fields are converged to about 1e-8 only;
  SNES phlexreduced applies the same test to the same rows. An initial guess that passes the whole test is kept.

  Collective
@*/
PetscErrorCode PhlexSystemSNESConvergedStage(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm, SNESConvergedReason *reason, void *ctx)
{
  PhlexSystem sys = (PhlexSystem)ctx;
  Vec         F, Fv;
  PetscReal   fv;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemSNESConverged(snes, it, xnorm, snorm, fnorm, reason, ctx));
  if (!sys->nq || !sys->nfparts || sys->vrtol <= 0) PetscFunctionReturn(0);
  PetscCall(SNESGetFunction(snes, &F, NULL, NULL));
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &Fv));
  PetscCall(VecNorm(Fv, NORM_2, &fv));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &Fv));
  if (it == 0) sys->fv0 = fv;
  PetscCall(PetscInfo(snes, "Newton iteration %" PetscInt_FMT ": velocity rows' residual %g (%g of their initial value)\n", it, (double)fv, (double)(sys->fv0 > 0 ? fv / sys->fv0 : 0.0)));
  if (it > 0 && *reason > 0 && fv > sys->vrtol * sys->fv0 && fv <= 0.5 * sys->fvprev) *reason = SNES_CONVERGED_ITERATING;
  sys->fvprev = fv;
  PetscFunctionReturn(0);
}
