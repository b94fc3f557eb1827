/* Global unknown layout: named fields, each contiguous on every rank, exposed through a DMShell whose field
   decomposition and sub-DMs drive PCFIELDSPLIT from the options database (nested splits included).

   Index sets carry the block size of their field (the stress field: nodes per cell x 6, so that point-block
   Jacobi inverts the element blocks exactly). A sub-DM may compose a preconditioning matrix on its index set
   ("pmat", used by PCFIELDSPLIT as the split's matrix and as a user Schur-complement matrix), provided lazily by
   the layout's owner: the exactly condensed operator of that field subset. */
#include <phlex_impl.h>
#include <petscdmshell.h>

struct _p_PhlexLayout {
  MPI_Comm          comm;
  PetscInt          nf;
  char              names[PHLEX_LAYOUT_MAX_FIELDS][PHLEX_NAME_LEN];
  PetscInt          nlocal[PHLEX_LAYOUT_MAX_FIELDS], bs[PHLEX_LAYOUT_MAX_FIELDS];
  PetscInt          root_field[PHLEX_LAYOUT_MAX_FIELDS]; /* index of each field in the root layout */
  PhlexLayoutPmatFn pmat;
  void             *pmat_ctx;
  PetscInt          refct;
};

static PetscErrorCode LayoutCreateDM(PhlexLayout L, DM *dm);

static PetscErrorCode LayoutLocalSize(PhlexLayout L, PetscInt *n)
{
  PetscFunctionBeginUser;
  *n = 0;
  for (PetscInt f = 0; f < L->nf; f++) *n += L->nlocal[f];
  PetscFunctionReturn(0);
}

/* the index set of field f in the numbering of layout L (rstart: first global index of this rank) */
static PetscErrorCode LayoutFieldIS(PhlexLayout L, PetscInt rstart, PetscInt f, IS *is)
{
  PetscInt off = 0;

  PetscFunctionBeginUser;
  for (PetscInt g = 0; g < f; g++) off += L->nlocal[g];
  PetscCall(ISCreateStride(L->comm, L->nlocal[f], rstart + off, 1, is));
  PetscCall(ISSetBlockSize(*is, L->bs[f]));
  PetscFunctionReturn(0);
}

static PetscErrorCode LayoutSub(PhlexLayout L, PetscInt n, const PetscInt fields[], PhlexLayout *S)
{
  PhlexLayout s;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&s));
  s->comm     = L->comm;
  s->nf       = n;
  s->pmat     = L->pmat;
  s->pmat_ctx = L->pmat_ctx;
  s->refct    = 1;
  for (PetscInt i = 0; i < n; i++) {
    /* a field split from the solver options (a preset for scenes with field unknowns, say) */
    PetscCheck(fields[i] >= 0 && fields[i] < L->nf, L->comm, PETSC_ERR_USER_INPUT, "the solver options split the unknowns by field %" PetscInt_FMT ", but this scene's unknowns have %" PetscInt_FMT " field%s (the first: %s): is -solver_options_file a preset for other kinds of bodies? (a scene of rigid, lumped and reduced parts only takes options/solver/rigid.opts)", fields[i], L->nf, L->nf == 1 ? "" : "s", L->names[0]);
    PetscCheck(i == 0 || fields[i] > fields[i - 1], L->comm, PETSC_ERR_ARG_WRONG, "the solver options split the unknowns by field %" PetscInt_FMT " after field %" PetscInt_FMT ": the fields of a split (-[<prefix>]pc_fieldsplit_<k>_fields) must be listed in increasing order", fields[i], fields[i - 1]);
    PetscCall(PetscStrcpy(s->names[i], L->names[fields[i]]));
    s->nlocal[i]     = L->nlocal[fields[i]];
    s->bs[i]         = L->bs[fields[i]];
    s->root_field[i] = L->root_field[fields[i]];
  }
  *S = s;
  PetscFunctionReturn(0);
}

static PetscErrorCode ComposePmat(PhlexLayout L, PetscInt n, const PetscInt fields[], IS is)
{
  PetscInt root[PHLEX_LAYOUT_MAX_FIELDS];
  Mat      P = NULL;

  PetscFunctionBeginUser;
  if (!L->pmat) PetscFunctionReturn(0);
  for (PetscInt i = 0; i < n; i++) root[i] = L->root_field[fields[i]];
  PetscCall(L->pmat(L->pmat_ctx, n, root, &P));
  if (P) PetscCall(PetscObjectCompose((PetscObject)is, "pmat", (PetscObject)P));
  PetscFunctionReturn(0);
}

static PetscErrorCode DMRStart(DM dm, PetscInt *rstart)
{
  Vec X;

  PetscFunctionBeginUser;
  PetscCall(DMGetGlobalVector(dm, &X));
  PetscCall(VecGetOwnershipRange(X, rstart, NULL));
  PetscCall(DMRestoreGlobalVector(dm, &X));
  PetscFunctionReturn(0);
}

static PetscErrorCode LayoutCreateFieldDecomposition(DM dm, PetscInt *nf, char ***names, IS **is, DM **dms)
{
  PhlexLayout L;
  PetscInt    rstart;

  PetscFunctionBeginUser;
  PetscCall(DMShellGetContext(dm, &L));
  PetscCall(DMRStart(dm, &rstart));
  *nf = L->nf;
  if (names) {
    PetscCall(PetscMalloc1(L->nf, names));
    for (PetscInt f = 0; f < L->nf; f++) PetscCall(PetscStrallocpy(L->names[f], &(*names)[f]));
  }
  if (is) {
    PetscCall(PetscMalloc1(L->nf, is));
    for (PetscInt f = 0; f < L->nf; f++) {
      PetscCall(LayoutFieldIS(L, rstart, f, &(*is)[f]));
      PetscCall(ComposePmat(L, 1, &f, (*is)[f]));
    }
  }
  if (dms) {
    PetscCall(PetscMalloc1(L->nf, dms));
    for (PetscInt f = 0; f < L->nf; f++) {
      PhlexLayout S;
      PetscCall(LayoutSub(L, 1, &f, &S));
      PetscCall(LayoutCreateDM(S, &(*dms)[f]));
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LayoutCreateSubDM(DM dm, PetscInt n, const PetscInt fields[], IS *is, DM *subdm)
{
  PhlexLayout L, S;
  PetscInt    rstart, cnt = 0, k = 0, *idx, bs = 1;

  PetscFunctionBeginUser;
  PetscCall(DMShellGetContext(dm, &L));
  PetscCall(LayoutSub(L, n, fields, &S));
  if (is) {
    PetscCall(DMRStart(dm, &rstart));
    for (PetscInt i = 0; i < n; i++) cnt += L->nlocal[fields[i]];
    PetscCall(PetscMalloc1(cnt, &idx));
    for (PetscInt i = 0; i < n; i++) {
      PetscInt off = 0;
      for (PetscInt g = 0; g < fields[i]; g++) off += L->nlocal[g];
      for (PetscInt j = 0; j < L->nlocal[fields[i]]; j++) idx[k++] = rstart + off + j;
    }
    PetscCall(ISCreateGeneral(L->comm, cnt, idx, PETSC_OWN_POINTER, is));
    if (n == 1) bs = L->bs[fields[0]];
    PetscCall(ISSetBlockSize(*is, bs));
    PetscCall(ComposePmat(L, n, fields, *is));
  }
  if (subdm) PetscCall(LayoutCreateDM(S, subdm));
  else PetscCall(PetscFree(S));
  PetscFunctionReturn(0);
}

static PetscErrorCode LayoutDestroyContext(void *ctx)
{
  PhlexLayout L = (PhlexLayout)ctx;

  PetscFunctionBeginUser;
  if (--L->refct == 0) PetscCall(PetscFree(L));
  PetscFunctionReturn(0);
}

static PetscErrorCode LayoutCreateDM(PhlexLayout L, DM *dm)
{
  Vec      X;
  PetscInt n;

  PetscFunctionBeginUser;
  PetscCall(LayoutLocalSize(L, &n));
  PetscCall(DMShellCreate(L->comm, dm));
  PetscCall(DMShellSetContext(*dm, L));
  PetscCall(DMShellSetDestroyContext(*dm, LayoutDestroyContext));
  PetscCall(VecCreateMPI(L->comm, n, PETSC_DETERMINE, &X));
  PetscCall(DMShellSetGlobalVector(*dm, X));
  PetscCall(VecDestroy(&X));
  PetscCall(DMShellSetCreateFieldDecomposition(*dm, LayoutCreateFieldDecomposition));
  PetscCall(DMShellSetCreateSubDM(*dm, LayoutCreateSubDM));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLayoutCreateDM - creates the DMShell of a layout of named fields

  Collective

  Input Parameters:
+ comm     - communicator
. nf       - number of fields
. names    - field names (PCFIELDSPLIT prefixes fieldsplit_<name>_)
. nlocal   - local size of each field on this rank
. bs       - block size of each field
. pmat     - callback returning the preconditioning matrix of a field subset, or NULL
- pmat_ctx - its context

  Output Parameter:
. dm - the DMShell; its field decomposition and sub-DMs follow the layout
@*/
PetscErrorCode PhlexLayoutCreateDM(MPI_Comm comm, PetscInt nf, const char *const names[], const PetscInt nlocal[], const PetscInt bs[], PhlexLayoutPmatFn pmat, void *pmat_ctx, DM *dm)
{
  PhlexLayout L;

  PetscFunctionBeginUser;
  PetscCheck(nf <= PHLEX_LAYOUT_MAX_FIELDS, comm, PETSC_ERR_SUP, "too many fields");
  PetscCall(PetscNew(&L));
  L->comm     = comm;
  L->nf       = nf;
  L->pmat     = pmat;
  L->pmat_ctx = pmat_ctx;
  L->refct    = 1;
  for (PetscInt f = 0; f < nf; f++) {
    PetscCall(PetscStrncpy(L->names[f], names[f], PHLEX_NAME_LEN));
    L->nlocal[f]     = nlocal[f];
    L->bs[f]         = bs[f];
    L->root_field[f] = f;
  }
  PetscCall(LayoutCreateDM(L, dm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLayoutGetFieldIS - the index set of field f of a layout DM (caller destroys it)
@*/
PetscErrorCode PhlexLayoutGetFieldIS(DM dm, PetscInt f, IS *is)
{
  PhlexLayout L;
  PetscInt    rstart;

  PetscFunctionBeginUser;
  PetscCall(DMShellGetContext(dm, &L));
  PetscCall(DMRStart(dm, &rstart));
  PetscCall(LayoutFieldIS(L, rstart, f, is));
  PetscFunctionReturn(0);
}
