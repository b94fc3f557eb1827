/* VecGetSubVector on the state's layout without collective calls. PETSc 3.18's default makes a new parallel vector
   for every call (an MPI_Allreduce to agree that the block is contiguous, an MPI_Allgather for the new vector's
   layout). Each is a point where every process waits for the others, and the system takes a body's blocks once or
   more per body in every residual, product and monitor: with each body whole on one process (-whole_bodies) the
   processes then took their bodies' shares in turn instead of at once. Here the blocks of a stride index set (a
   part's u, Sigma, v; a field) are views kept on the index set and placed on the vector's array: collective only the
   first time a view is made. Other index sets take PETSc's default. */
#include <phlex_impl.h>
#include <petsc/private/vecimpl.h>

typedef struct {
  PetscInt          n, size;
  Vec              *view;
  PetscBool        *used;
  PetscObjectState *state; /* the view's state once placed: a later one means it was written, so X was */
} ViewPool;

static PetscErrorCode ViewPoolDestroy(void *ctx)
{
  ViewPool *p = (ViewPool *)ctx;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < p->n; k++) PetscCall(VecDestroy(&p->view[k]));
  PetscCall(PetscFree3(p->view, p->used, p->state));
  PetscCall(PetscFree(p));
  PetscFunctionReturn(0);
}

static PetscErrorCode ViewGet(Vec X, IS is, Vec *Y);
static PetscErrorCode ViewRestore(Vec X, IS is, Vec *Y);

/* whether the block of is is taken as a view: a stride of step 1 (the same answer on every process), from first */
static PetscErrorCode ViewApplies(IS is, PetscBool *yes, PetscInt *first)
{
  PetscInt step = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)is, ISSTRIDE, yes));
  if (*yes) PetscCall(ISStrideGetInfo(is, first, &step));
  *yes = (PetscBool)(*yes && step == 1);
  PetscFunctionReturn(0);
}

static PetscErrorCode ViewGet(Vec X, IS is, Vec *Y)
{
  PetscContainer     c;
  ViewPool          *p;
  PetscBool          yes;
  PetscInt           first, n, N, rstart, rend, k, bs;
  const PetscScalar *x;

  PetscFunctionBeginUser;
  PetscCall(ViewApplies(is, &yes, &first));
  if (!yes) {
    /* PETSc's default */
    X->ops->getsubvector = NULL;
    PetscCall(VecGetSubVector(X, is, Y));
    X->ops->getsubvector = ViewGet;
    PetscFunctionReturn(0);
  }
  PetscCall(ISGetLocalSize(is, &n));
  PetscCall(ISGetSize(is, &N));
  PetscCall(VecGetOwnershipRange(X, &rstart, &rend));
  PetscCheck(!n || (first >= rstart && first + n <= rend), PETSC_COMM_SELF, PETSC_ERR_PLIB, "a block [%" PetscInt_FMT ", %" PetscInt_FMT ") outside this process's rows [%" PetscInt_FMT ", %" PetscInt_FMT ")", first, first + n, rstart, rend);
  PetscCall(PetscObjectQuery((PetscObject)is, "phlex_view_pool", (PetscObject *)&c));
  if (!c) {
    PetscCall(PetscNew(&p));
    PetscCall(PetscContainerCreate(PETSC_COMM_SELF, &c));
    PetscCall(PetscContainerSetPointer(c, p));
    PetscCall(PetscContainerSetUserDestroy(c, ViewPoolDestroy));
    PetscCall(PetscObjectCompose((PetscObject)is, "phlex_view_pool", (PetscObject)c));
    PetscCall(PetscContainerDestroy(&c)); /* the index set holds it */
  } else PetscCall(PetscContainerGetPointer(c, (void **)&p));
  for (k = 0; k < p->n && p->used[k]; k++) { }
  if (k == p->n) {
    /* every view of this block in use (the block of two vectors at once): one more, made on every process alike */
    if (p->n == p->size) {
      Vec              *view;
      PetscBool        *used;
      PetscObjectState *state;
      p->size = 2 * p->size + 2;
      PetscCall(PetscCalloc3(p->size, &view, p->size, &used, p->size, &state));
      PetscCall(PetscArraycpy(view, p->view, p->n));
      PetscCall(PetscArraycpy(used, p->used, p->n));
      PetscCall(PetscArraycpy(state, p->state, p->n));
      PetscCall(PetscFree3(p->view, p->used, p->state));
      p->view  = view;
      p->used  = used;
      p->state = state;
    }
    PetscMPIInt size;
    PetscCall(ISGetBlockSize(is, &bs));
    PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)X), &size));
    if (size == 1) PetscCall(VecCreateSeqWithArray(PetscObjectComm((PetscObject)X), bs, n, NULL, &p->view[k])); /* as PETSc's */
    else PetscCall(VecCreateMPIWithArray(PetscObjectComm((PetscObject)X), bs, n, N, NULL, &p->view[k]));
    p->n++;
  }
  PetscCall(VecGetArrayRead(X, &x));
  PetscCall(VecPlaceArray(p->view[k], x ? x + (first - rstart) : NULL));
  PetscCall(VecRestoreArrayRead(X, &x));
  PetscCall(PetscObjectStateGet((PetscObject)p->view[k], &p->state[k]));
  p->used[k] = PETSC_TRUE;
  /* a reference for the caller: a view handed back through PETSc's default restore (another vector's) is then only
     dereferenced, never freed under the pool */
  PetscCall(PetscObjectReference((PetscObject)p->view[k]));
  *Y = p->view[k];
  PetscFunctionReturn(0);
}

static PetscErrorCode ViewRestore(Vec X, IS is, Vec *Y)
{
  PetscContainer c;
  ViewPool      *p = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectQuery((PetscObject)is, "phlex_view_pool", (PetscObject *)&c));
  if (c) PetscCall(PetscContainerGetPointer(c, (void **)&p));
  for (PetscInt k = 0; p && k < p->n; k++) {
    PetscObjectState s;
    if (p->view[k] != *Y || !p->used[k]) continue;
    PetscCall(PetscObjectStateGet((PetscObject)*Y, &s));
    if (s != p->state[k]) PetscCall(PetscObjectStateIncrease((PetscObject)X)); /* written through the view */
    PetscCall(VecResetArray(*Y));
    p->used[k] = PETSC_FALSE;
    PetscCall(VecDestroy(Y)); /* the caller's reference */
    PetscFunctionReturn(0);
  }
  /* taken by PETSc's default */
  X->ops->restoresubvector = NULL;
  PetscCall(VecRestoreSubVector(X, is, Y));
  X->ops->restoresubvector = ViewRestore;
  PetscFunctionReturn(0);
}

/*@C
  PhlexVecUseViews - VecGetSubVector() and VecRestoreSubVector() of X (and of its duplicates) take the blocks of stride
  index sets as views kept on the index set, with nothing collective after the first time

  Not Collective
@*/
PetscErrorCode PhlexVecUseViews(Vec X)
{
  PetscFunctionBeginUser;
  X->ops->getsubvector     = ViewGet;
  X->ops->restoresubvector = ViewRestore;
  PetscFunctionReturn(0);
}
