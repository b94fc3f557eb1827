/* A flexible body's finite element spaces and its constant body-frame operators (velocity mass, stress compliance
   mass, Grad coupling, condensed stiffness, inertia invariants), assembled once (paper Section 4). */
#include <phlex_impl.h>
#include <stdint.h>
#include <string.h> /* memcpy */


/* Discontinuous P_{k-1} Lagrange element with 6 components (the symmetric stress in Voigt order). */
static PetscErrorCode CreateStressFE(MPI_Comm comm, PetscInt degree, PetscFE *fe)
{
  PetscSpace     P;
  PetscDualSpace Q;
  DM             K;

  PetscFunctionBeginUser;
  PetscCall(PetscSpaceCreate(comm, &P));
  PetscCall(PetscSpaceSetType(P, PETSCSPACEPOLYNOMIAL));
  PetscCall(PetscSpaceSetNumComponents(P, 6));
  PetscCall(PetscSpaceSetNumVariables(P, 3));
  PetscCall(PetscSpaceSetDegree(P, degree, PETSC_DETERMINE));
  PetscCall(PetscSpaceSetUp(P));
  PetscCall(PetscDualSpaceCreate(comm, &Q));
  PetscCall(PetscDualSpaceSetType(Q, PETSCDUALSPACELAGRANGE));
  PetscCall(DMPlexCreateReferenceCell(PETSC_COMM_SELF, DM_POLYTOPE_TETRAHEDRON, &K));
  PetscCall(PetscDualSpaceSetDM(Q, K));
  PetscCall(DMDestroy(&K));
  PetscCall(PetscDualSpaceSetNumComponents(Q, 6));
  PetscCall(PetscDualSpaceSetOrder(Q, degree));
  PetscCall(PetscDualSpaceLagrangeSetContinuity(Q, PETSC_FALSE));
  PetscCall(PetscDualSpaceSetUp(Q));
  PetscCall(PetscFECreate(comm, fe));
  PetscCall(PetscFESetType(*fe, PETSCFEBASIC));
  PetscCall(PetscFESetBasisSpace(*fe, P));
  PetscCall(PetscFESetDualSpace(*fe, Q));
  PetscCall(PetscFESetNumComponents(*fe, 6));
  PetscCall(PetscFESetUp(*fe));
  PetscCall(PetscSpaceDestroy(&P));
  PetscCall(PetscDualSpaceDestroy(&Q));
  PetscFunctionReturn(0);
}

static void ZeroBC(PetscInt dim, PetscInt Nf, PetscInt NfAux, const PetscInt uOff[], const PetscInt uOff_x[], const PetscScalar u[], const PetscScalar u_t[], const PetscScalar u_x[], const PetscInt aOff[], const PetscInt aOff_x[], const PetscScalar a[], const PetscScalar a_t[], const PetscScalar a_x[], PetscReal t, const PetscReal x[], PetscInt numConstants, const PetscScalar constants[], PetscScalar bcval[])
{
  for (PetscInt c = 0; c < 3; c++) bcval[c] = 0.0;
}

static PetscErrorCode SetUpSpaces(PhlexFlexible b)
{
  PetscQuadrature q;
  const char     *vnames[] = {"x", "y", "z"};
  const char     *snames[] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  PetscSection    s;

  PetscFunctionBeginUser;
  PetscCall(DMClone(b->dm, &b->dm_s));
  PetscCall(PetscFECreateLagrange(b->comm, 3, 3, PETSC_TRUE, b->degree, PETSC_DETERMINE, &b->fe_v));
  PetscCall(CreateStressFE(b->comm, b->degree - 1, &b->fe_s));
  /* one rule for both spaces, exact for the P_k mass (degree 2k) and all other integrands */
  PetscCall(PetscDTSimplexQuadrature(3, 2 * b->degree, PETSCDTSIMPLEXQUAD_MINSYM, &q));
  PetscCall(PetscFESetQuadrature(b->fe_v, q));
  PetscCall(PetscFESetQuadrature(b->fe_s, q));
  PetscCall(PetscQuadratureDestroy(&q));
  PetscCall(PetscObjectSetName((PetscObject)b->fe_v, "velocity"));
  PetscCall(PetscObjectSetName((PetscObject)b->fe_s, "stress"));
  PetscCall(DMSetField(b->dm, 0, NULL, (PetscObject)b->fe_v));
  PetscCall(DMCreateDS(b->dm));
  if (b->frame_patch[0]) {
    DMLabel  label;
    char     option[128];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sframe_patch", b->prefix));
    PetscCall(PhlexMeshFindGroup(b, b->frame_patch, 2, option, &b->frame_tag));
    PetscCall(DMGetLabel(b->dm, "Face Sets", &label));
    PetscCall(DMAddBoundary(b->dm, DM_BC_ESSENTIAL, "frame_patch", label, 1, &b->frame_tag, 0, 0, NULL, (void (*)(void))ZeroBC, NULL, NULL, NULL));
    PetscCall(PhlexSurfaceMoments(b, b->frame_tag, &b->frame_area, b->frame_centroid, b->frame_inertia));
  }
  PetscCall(DMSetField(b->dm_s, 0, NULL, (PetscObject)b->fe_s));
  PetscCall(DMCreateDS(b->dm_s));
  PetscCall(DMGetLocalSection(b->dm, &s));
  PetscCall(PetscSectionSetFieldName(s, 0, "velocity"));
  for (PetscInt c = 0; c < 3; c++) PetscCall(PetscSectionSetComponentName(s, 0, c, vnames[c]));
  PetscCall(DMGetLocalSection(b->dm_s, &s));
  PetscCall(PetscSectionSetFieldName(s, 0, "stress"));
  for (PetscInt c = 0; c < 6; c++) PetscCall(PetscSectionSetComponentName(s, 0, c, snames[c]));
  PetscCall(PetscFEGetDimension(b->fe_v, &b->nb_v));
  PetscCall(PetscFEGetDimension(b->fe_s, &b->nb_s));
  PetscCall(DMPlexGetHeightStratum(b->dm, 0, &b->cStart, &b->cEnd));
  {
    Vec v;
    PetscCall(DMGetGlobalVector(b->dm, &v));
    PetscCall(VecGetLocalSize(v, &b->nv_local));
    PetscCall(VecGetSize(v, &b->nv_global));
    PetscCall(DMRestoreGlobalVector(b->dm, &v));
    PetscCall(DMGetGlobalVector(b->dm_s, &v));
    PetscCall(VecGetLocalSize(v, &b->ns_local));
    PetscCall(VecGetSize(v, &b->ns_global));
    PetscCall(DMRestoreGlobalVector(b->dm_s, &v));
  }
  PetscFunctionReturn(0);
}

/* Material index of every local cell from the "Cell Sets" label. */
static PetscErrorCode SetUpMaterials(PhlexFlexible b)
{
  DMLabel  label;
  PetscInt ncells = b->cEnd - b->cStart, missing = -1, gmissing, val;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1(ncells, &b->cell_material));
  if (b->nmaterials == 1 && b->materials[0].tag < 0 && !b->materials[0].region[0]) PetscFunctionReturn(0);
  for (PetscInt r = 0; r < b->nmaterials; r++) {
    char option[128];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sregions", b->prefix));
    PetscCall(PhlexMeshFindGroup(b, b->materials[r].region, 3, option, &b->materials[r].tag));
  }
  PetscCall(DMGetLabel(b->dm, "Cell Sets", &label));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscInt m = -1;
    val        = -1;
    if (label) PetscCall(DMLabelGetValue(label, c, &val));
    for (PetscInt r = 0; r < b->nmaterials; r++)
      if (b->materials[r].tag == val) m = r;
    if (m < 0 && missing < 0) missing = val;
    b->cell_material[c - b->cStart] = m < 0 ? 0 : m;
  }
  PetscCallMPI(MPI_Allreduce(&missing, &gmissing, 1, MPIU_INT, MPI_MAX, b->comm));
  if (gmissing >= 0 || missing != -1) {
    const char *gname = "(no physical volume)";
    for (PetscInt g = 0; g < b->ngroups; g++)
      if (b->groups[g].dim == 3 && b->groups[g].tag == gmissing) gname = b->groups[g].name;
    SETERRQ(b->comm, PETSC_ERR_USER_INPUT, "body %s: cells of physical volume %s (tag %" PetscInt_FMT ") in mesh file '%s' have no material: add it to -%sregions", b->name, gname, gmissing, b->mesh_file, b->prefix);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleGetBasis - tabulates the scalar node shapes of the velocity (stress = PETSC_FALSE) or stress element at
  the quadrature points

  Not collective

  Notes:
  PETSc's vector Lagrange elements are node-major: basis function b is component b % Nc of node b / Nc, with the
  scalar shape of that node. This is checked on the tabulation.
@*/
PetscErrorCode PhlexFlexibleGetBasis(PhlexFlexible b, PetscBool stress, PhlexElementBasis *B)
{
  PetscFE         fe = stress ? b->fe_s : b->fe_v;
  PetscQuadrature q;
  PetscTabulation T;
  PetscInt        Nc, dim, Nb;

  PetscFunctionBeginUser;
  PetscCall(PetscFEGetQuadrature(fe, &q));
  PetscCall(PetscQuadratureGetData(q, &dim, NULL, &B->nq, NULL, &B->weights));
  PetscCall(PetscFEGetCellTabulation(fe, 1, &T));
  Nc        = T->Nc;
  Nb        = T->Nb;
  B->nb     = Nb;
  B->nc     = Nc;
  B->nnodes = Nb / Nc;
  PetscCheck(B->nnodes <= PHLEX_MAX_NODES, PETSC_COMM_SELF, PETSC_ERR_SUP, "element with %" PetscInt_FMT " nodes", B->nnodes);
  PetscCall(PetscMalloc2(B->nq * B->nnodes, &B->node_phi, B->nq * B->nnodes * 3, &B->node_dphi));
  for (PetscInt qq = 0; qq < B->nq; qq++)
    for (PetscInt n = 0; n < B->nnodes; n++) {
      B->node_phi[qq * B->nnodes + n] = T->T[0][(qq * Nb + n * Nc) * Nc + 0];
      for (PetscInt d = 0; d < 3; d++) B->node_dphi[(qq * B->nnodes + n) * 3 + d] = T->T[1][((qq * Nb + n * Nc) * Nc + 0) * dim + d];
    }
  /* node-major check: component c of node n has the node's shape in component c and nothing elsewhere */
  for (PetscInt qq = 0; qq < B->nq; qq++)
    for (PetscInt bb = 0; bb < Nb; bb++)
      for (PetscInt c = 0; c < Nc; c++) {
        const PetscReal expect = (c == bb % Nc) ? B->node_phi[qq * B->nnodes + bb / Nc] : 0.0;
        PetscCheck(PetscAbsReal(T->T[0][(qq * Nb + bb) * Nc + c] - expect) < 1e-12, PETSC_COMM_SELF, PETSC_ERR_PLIB, "unexpected layout of the %s basis", stress ? "stress" : "velocity");
      }
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexFlexibleRestoreBasis(PhlexElementBasis *B)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree2(B->node_phi, B->node_dphi));
  PetscFunctionReturn(0);
}

/* Global dofs of every local cell, cached once: DMPlexGetClosureIndices is the expensive part of an element loop. */
static PetscErrorCode SetUpCellDofs(PhlexFlexible b)
{
  PetscSection section, gsection, gsec_s;
  PetscInt     ncells = b->cEnd - b->cStart;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalSection(b->dm, &section));
  PetscCall(DMGetGlobalSection(b->dm, &gsection));
  PetscCall(DMGetGlobalSection(b->dm_s, &gsec_s));
  PetscCall(PetscMalloc2(ncells * b->nb_v, &b->cell_vdofs, ncells, &b->cell_soff));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscInt nidx, *idx = NULL;
    PetscCall(DMPlexGetClosureIndices(b->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCheck(nidx == b->nb_v, PETSC_COMM_SELF, PETSC_ERR_PLIB, "closure of cell %" PetscInt_FMT " has %" PetscInt_FMT " dofs, expected %" PetscInt_FMT, c, nidx, b->nb_v);
    PetscCall(PetscArraycpy(&b->cell_vdofs[(c - b->cStart) * b->nb_v], idx, nidx));
    PetscCall(DMPlexRestoreClosureIndices(b->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCall(PetscSectionGetOffset(gsec_s, c, &b->cell_soff[c - b->cStart]));
  }
  PetscFunctionReturn(0);
}

/* Block (node) indices of a cell: velocity dofs come in x, y, z triples, constrained as a whole (-1). */
static inline void CellNodeIndices(PhlexFlexible b, PetscInt c, PetscInt *nodes)
{
  const PetscInt *idx = &b->cell_vdofs[c * b->nb_v];
  for (PetscInt a = 0; a < b->nb_v / 3; a++) nodes[a] = idx[3 * a] >= 0 ? idx[3 * a] / 3 : -1;
}

/* A velocity-space operator (3 x 3 blocks between nodes sharing a cell) stored as symmetric block matrix SBAIJ
   (upper triangle, block size 3): the format the sparse Cholesky solvers (MUMPS, CHOLMOD) factor directly. The block
   structure is counted from the node graph of the cells in serial and with MATPREALLOCATOR in parallel (which also
   sees the rows of nodes owned by other ranks). */
static PetscErrorCode CreateVelocityMatrix(PhlexFlexible b, Mat *A)
{
  const PetscInt nn = b->nb_v / 3, ncells = b->cEnd - b->cStart, nloc = b->nv_local / 3;
  PetscMPIInt    size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(b->comm, &size));
  PetscCall(MatCreate(b->comm, A));
  PetscCall(MatSetSizes(*A, b->nv_local, b->nv_local, b->nv_global, b->nv_global));
  PetscCall(MatSetBlockSize(*A, 3));
  PetscCall(MatSetType(*A, MATSBAIJ));
  if (size > 1) {
    Mat      P;
    PetscInt nodes[PHLEX_MAX_NODES];
    PetscCall(MatCreate(b->comm, &P));
    PetscCall(MatSetType(P, MATPREALLOCATOR));
    PetscCall(MatSetSizes(P, b->nv_local, b->nv_local, b->nv_global, b->nv_global));
    PetscCall(MatSetBlockSize(P, 3));
    PetscCall(MatSetUp(P));
    for (PetscInt c = 0; c < ncells; c++) {
      PetscScalar zeros[9 * PHLEX_MAX_NODES * PHLEX_MAX_NODES] = {0};
      CellNodeIndices(b, c, nodes);
      PetscCall(MatSetValuesBlocked(P, nn, nodes, nn, nodes, zeros, INSERT_VALUES));
    }
    PetscCall(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY));
    PetscCall(MatPreallocatorPreallocate(P, PETSC_FALSE, *A));
    PetscCall(MatDestroy(&P));
  } else {
    PetscInt *cnt, *off, *cells, *nbr, *nnz, maxnbr = PHLEX_MAX_NODES * 64;
    /* node -> cells, then the distinct upper neighbours of every node */
    PetscCall(PetscCalloc2(nloc + 1, &cnt, nloc + 1, &off));
    for (PetscInt c = 0; c < ncells; c++)
      for (PetscInt a = 0; a < nn; a++) {
        const PetscInt g = b->cell_vdofs[c * b->nb_v + 3 * a];
        if (g >= 0) cnt[g / 3]++;
      }
    for (PetscInt i = 0; i < nloc; i++) off[i + 1] = off[i] + cnt[i];
    PetscCall(PetscMalloc3(off[nloc] + 1, &cells, maxnbr, &nbr, nloc, &nnz));
    PetscCall(PetscArrayzero(cnt, nloc));
    for (PetscInt c = 0; c < ncells; c++)
      for (PetscInt a = 0; a < nn; a++) {
        const PetscInt g = b->cell_vdofs[c * b->nb_v + 3 * a];
        if (g >= 0) cells[off[g / 3] + cnt[g / 3]++] = c;
      }
    for (PetscInt i = 0; i < nloc; i++) {
      PetscInt n = 0;
      for (PetscInt k = off[i]; k < off[i + 1]; k++)
        for (PetscInt a = 0; a < nn; a++) {
          const PetscInt g = b->cell_vdofs[cells[k] * b->nb_v + 3 * a];
          if (g >= 3 * i) {
            if (n == maxnbr) {
              PetscCall(PetscSortRemoveDupsInt(&n, nbr));
              PetscCheck(n < maxnbr, PETSC_COMM_SELF, PETSC_ERR_SUP, "node with more than %" PetscInt_FMT " neighbours", maxnbr);
            }
            nbr[n++] = g;
          }
        }
      PetscCall(PetscSortRemoveDupsInt(&n, nbr));
      nnz[i] = n;
    }
    PetscCall(MatSeqSBAIJSetPreallocation(*A, 3, 0, nnz));
    PetscCall(PetscFree2(cnt, off));
    PetscCall(PetscFree3(cells, nbr, nnz));
  }
  PetscCall(MatSetOption(*A, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
  PetscCall(MatSetOption(*A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscFunctionReturn(0);
}

/* Exact preallocation of G (stress rows x velocity columns): each stress row couples to the velocity dofs of its cell. */
static PetscErrorCode CreateCouplingMatrix(PhlexFlexible b, Mat *G)
{
  PetscInt vstart, vend, rstart, *dnz, *onz;

  PetscFunctionBeginUser;
  {
    Vec v;
    PetscCall(DMGetGlobalVector(b->dm, &v));
    PetscCall(VecGetOwnershipRange(v, &vstart, &vend));
    PetscCall(DMRestoreGlobalVector(b->dm, &v));
    PetscCall(DMGetGlobalVector(b->dm_s, &v));
    PetscCall(VecGetOwnershipRange(v, &rstart, NULL));
    PetscCall(DMRestoreGlobalVector(b->dm_s, &v));
  }
  PetscCall(PetscCalloc2(b->ns_local, &dnz, b->ns_local, &onz));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    PetscInt nd = 0, no = 0;
    for (PetscInt i = 0; i < b->nb_v; i++) {
      const PetscInt g = b->cell_vdofs[c * b->nb_v + i];
      if (g < 0) continue;
      if (g >= vstart && g < vend) nd++;
      else no++;
    }
    for (PetscInt j = 0; j < b->nb_s; j++) {
      dnz[b->cell_soff[c] - rstart + j] = nd;
      onz[b->cell_soff[c] - rstart + j] = no;
    }
  }
  PetscCall(MatCreateAIJ(b->comm, b->ns_local, b->nv_local, b->ns_global, b->nv_global, 0, dnz, 0, onz, G));
  PetscCall(MatSetOption(*G, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscFree2(dnz, onz));
  PetscFunctionReturn(0);
}

/* Non-dimensional affine geometry of every local cell: detJ, invJ (x scaled by the reference length). */
static PetscErrorCode SetUpCellGeometry(PhlexFlexible b, const PhlexUnits *u)
{
  PetscReal v0[3], J[9], invJ[9], detJ;
  PetscReal vol = 0, mass = 0, mx[3] = {0, 0, 0}, buf[5], gbuf[5];

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(10 * (b->cEnd - b->cStart), &b->cell_geom));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscReal *g = &b->cell_geom[10 * (c - b->cStart)];
    PetscReal  rho = b->materials[b->cell_material[c - b->cStart]].density, xc[3];
    PetscCall(DMPlexComputeCellGeometryAffineFEM(b->dm, c, v0, J, invJ, &detJ));
    g[0] = detJ / (u->length * u->length * u->length);
    for (PetscInt i = 0; i < 9; i++) g[1 + i] = invJ[i] * u->length;
    /* reference tet volume 4/3, centroid at xi = -1/2 in each direction: x = v0 + J (xi + 1) */
    for (PetscInt a = 0; a < 3; a++) xc[a] = v0[a] + 0.5 * (J[3 * a] + J[3 * a + 1] + J[3 * a + 2]);
    vol += detJ * 4.0 / 3.0;
    mass += rho * detJ * 4.0 / 3.0;
    for (PetscInt a = 0; a < 3; a++) mx[a] += rho * detJ * 4.0 / 3.0 * xc[a];
  }
  buf[0] = vol;
  buf[1] = mass;
  for (PetscInt a = 0; a < 3; a++) buf[2 + a] = mx[a];
  PetscCall(MPIU_Allreduce(buf, gbuf, 5, MPIU_REAL, MPI_SUM, b->comm));
  b->volume = gbuf[0];
  b->mass   = gbuf[1];
  for (PetscInt a = 0; a < 3; a++) b->center_of_mass[a] = gbuf[2 + a] / b->mass;
  PetscFunctionReturn(0);
}

/* Element loop assembling the velocity operators Mv, K and the body-force vectors (non-dimensional, once). */
/* The element loops of a large body's assembly take seconds to minutes: they report progress and stop on SIGINT or
   SIGTERM (issue 43 item 1), in eight chunks of the local cells (PhlexProgressChunk, progress.c) */
#define AssemblyChunk(b, p, what, c, chunk) PhlexProgressChunk(p, (b)->comm, what, c, (b)->cEnd - (b)->cStart, chunk)
#define AssemblyChunksEnd(b, p, what, chunk) PhlexProgressChunksEnd(p, (b)->comm, what, chunk)

static PetscErrorCode AssembleVelocityOperators(PhlexFlexible b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, nn = nv / 3;
  PetscReal                            *Me, *Ke, fe[PHLEX_MAX_NODES];
  PhlexProgress                         progress;
  PetscInt                              chunk = 0;
  char                                  what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(CreateVelocityMatrix(b, &b->Mv));
  PetscCall(CreateVelocityMatrix(b, &b->K));
  for (PetscInt c = 0; c < 3; c++) {
    PetscCall(DMCreateGlobalVector(b->dm, &b->fvol[c]));
    PetscCall(VecSet(b->fvol[c], 0.0));
  }
  PetscCall(PetscMalloc2(nv * nv, &Me, nv * nv, &Ke));
  PetscCall(PetscSNPrintf(what, sizeof(what), "assembly of body %s (mass, stiffness)", b->name));
  PetscCall(PhlexProgressStart(&progress));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscInt      *idx = &b->cell_vdofs[c * nv];
    PetscInt             nodes[PHLEX_MAX_NODES];

    PhlexElementMass(R, mat->density / u->density, g[0], Me);
    PhlexElementStiffness(R, mat->youngs_modulus / u->modulus, mat->poissons_ratio, g[0], &g[1], Ke);
    PhlexElementLoad(R, g[0], fe);
    CellNodeIndices(b, c, nodes);
    PetscCall(MatSetValuesBlocked(b->Mv, nn, nodes, nn, nodes, Me, ADD_VALUES));
    PetscCall(MatSetValuesBlocked(b->K, nn, nodes, nn, nodes, Ke, ADD_VALUES));
    for (PetscInt a = 0; a < nv; a++)
      if (idx[a] >= 0) PetscCall(VecSetValue(b->fvol[a % 3], idx[a], fe[a / 3], ADD_VALUES));
    PetscCall(AssemblyChunk(b, &progress, what, c, &chunk));
  }
  PetscCall(AssemblyChunksEnd(b, &progress, what, chunk));
  PetscCall(PetscFree2(Me, Ke));
  PetscCall(MatAssemblyBegin(b->Mv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->K, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Mv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->K, MAT_FINAL_ASSEMBLY));
  for (PetscInt c = 0; c < 3; c++) {
    PetscCall(VecAssemblyBegin(b->fvol[c]));
    PetscCall(VecAssemblyEnd(b->fvol[c]));
  }
  PetscCall(MatSetOption(b->Mv, MAT_SPD, PETSC_TRUE));
  PetscCall(PetscObjectSetName((PetscObject)b->Mv, "velocity mass"));
  PetscCall(PetscObjectSetName((PetscObject)b->K, "stiffness"));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleAssembleDamping - assembles the body's structural damping matrix on its velocity field (non-dimensional,
  the velocity rows in time T), SBAIJ with the stiffness's pattern

  Collective

  Input Parameters:
+ b - the flexible body (its spaces and cells set up)
- u - the reference scales

  Output Parameter:
. R - alpha T Mv + sum over the cells of K_e with the Young's modulus (beta E + eta) / (E_ref T) (eta the cell's
      Kelvin-Voigt viscosity, the elastic Poisson's ratio): symmetric positive semi-definite

  Notes:
  The viscous stress Sigma_v = (beta + eta / E) D eps(v) adds G_v^T Sigma_v to the momentum rows of eq. (ph-mixed);
  eliminated cell by cell like the elastic stress, it is R_K v with R_K the stiffness of the viscous moduli (the
  element stiffness is linear in E). Rayleigh's alpha Mv acts on the velocity field, which for a floating body is the
  elastic velocity relative to its frame: the frame's rows (its momenta) are untouched.
@*/
PetscErrorCode PhlexFlexibleAssembleDamping(PhlexFlexible b, const PhlexUnits *u, Mat *R)
{
  const PhlexElementReferenceIntegrals *ref = &b->ref;
  const PetscInt                        nv = b->nb_v, nn = nv / 3;
  PetscReal                            *Me, *Ke;
  PhlexProgress                         progress;
  PetscInt                              chunk = 0;
  char                                  what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  PetscCall(CreateVelocityMatrix(b, R));
  PetscCall(PetscMalloc2(nv * nv, &Me, nv * nv, &Ke));
  PetscCall(PetscSNPrintf(what, sizeof(what), "assembly of body %s (structural damping)", b->name));
  PetscCall(PhlexProgressStart(&progress));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscReal      Ev  = (b->rayleigh_beta * mat->youngs_modulus + mat->viscosity) / (u->modulus * u->time);
    PetscInt             nodes[PHLEX_MAX_NODES];

    PhlexElementMass(ref, b->rayleigh_alpha * u->time * mat->density / u->density, g[0], Me);
    PhlexElementStiffness(ref, Ev, mat->poissons_ratio, g[0], &g[1], Ke);
    for (PetscInt k = 0; k < 9 * nn * nn; k++) Ke[k] += Me[k];
    CellNodeIndices(b, c, nodes);
    PetscCall(MatSetValuesBlocked(*R, nn, nodes, nn, nodes, Ke, ADD_VALUES));
    PetscCall(AssemblyChunk(b, &progress, what, c, &chunk));
  }
  PetscCall(AssemblyChunksEnd(b, &progress, what, chunk));
  PetscCall(PetscFree2(Me, Ke));
  PetscCall(MatAssemblyBegin(*R, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*R, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)*R, "structural damping"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSetUpLocalDofs - the local-vector offsets of every local cell's velocity closure (the order of
  cell_vdofs; a constrained dof's offset is that of its place in the local vector), once

  Not collective
@*/
PetscErrorCode PhlexFlexibleSetUpLocalDofs(PhlexFlexible b)
{
  PetscSection section;
  PetscInt     ncells = b->cEnd - b->cStart;

  PetscFunctionBeginUser;
  if (b->cell_vloc) PetscFunctionReturn(0);
  PetscCall(DMGetLocalSection(b->dm, &section));
  PetscCall(PetscMalloc1(ncells * b->nb_v, &b->cell_vloc));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    PetscInt nidx, *idx = NULL;
    PetscCall(DMPlexGetClosureIndices(b->dm, section, section, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCheck(nidx == b->nb_v, PETSC_COMM_SELF, PETSC_ERR_PLIB, "closure of cell %" PetscInt_FMT " has %" PetscInt_FMT " dofs, expected %" PetscInt_FMT, c, nidx, b->nb_v);
    for (PetscInt i = 0; i < nidx; i++) b->cell_vloc[(c - b->cStart) * b->nb_v + i] = idx[i] >= 0 ? idx[i] : -(idx[i] + 1);
    PetscCall(DMPlexRestoreClosureIndices(b->dm, section, section, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSetUpMixed - assembles the stress operators (compliance mass Ms, coupling G) needed by the time
  integration of the mixed system; modal analyses use the condensed velocity operators only and skip them

  Collective
@*/
PetscErrorCode PhlexFlexibleSetUpMixed(PhlexFlexible b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, ns = b->nb_s;
  PetscReal                            *Ge, *Mse, *work;
  PetscInt                              perm[3 * PHLEX_MAX_NODES], sidx[3 * PHLEX_MAX_NODES];
  PhlexProgress                         progress;
  PetscInt                              chunk = 0;
  char                                  what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  if (b->G) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(what, sizeof(what), "assembly of body %s (coupling, compliance)", b->name));
  PetscCall(PhlexProgressStart(&progress));
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(CreateCouplingMatrix(b, &b->G));
  PetscCall(MatCreateBAIJ(b->comm, ns, b->ns_local, b->ns_local, b->ns_global, b->ns_global, 1, NULL, 0, NULL, &b->Ms));
  PetscCall(MatSetOption(b->Ms, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(PetscMalloc3(ns * nv, &Ge, ns * ns, &Mse, ns * nv, &work));
  for (PetscInt m = 0; m < b->nmaterials; m++) PhlexElementCompliance(b->materials[m].youngs_modulus / u->modulus, b->materials[m].poissons_ratio, b->compliance[m]);
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal *g   = &b->cell_geom[10 * c];
    const PetscInt  *idx = &b->cell_vdofs[c * nv];
    PetscInt         rows[6 * 4], brow = b->cell_soff[c] / ns;

    PhlexElementCoupling(R, g[0], &g[1], work, Ge);
    PhlexElementComplianceMass(R, g[0], b->compliance[b->cell_material[c]], Mse);
    /* G rows belong to this cell only: inserting sorted columns appends to empty rows */
    for (PetscInt a = 0; a < nv; a++) {
      perm[a] = a;
      sidx[a] = idx[a];
    }
    PetscCall(PetscSortIntWithArray(nv, sidx, perm));
    for (PetscInt j = 0; j < ns; j++) {
      rows[j] = b->cell_soff[c] + j;
      for (PetscInt a = 0; a < nv; a++) work[j * nv + a] = Ge[j * nv + perm[a]];
    }
    PetscCall(MatSetValues(b->G, ns, rows, nv, sidx, work, INSERT_VALUES));
    PetscCall(MatSetValuesBlocked(b->Ms, 1, &brow, 1, &brow, Mse, INSERT_VALUES));
    PetscCall(AssemblyChunk(b, &progress, what, c, &chunk));
  }
  PetscCall(AssemblyChunksEnd(b, &progress, what, chunk));
  PetscCall(PetscFree3(Ge, Mse, work));
  PetscCall(MatAssemblyBegin(b->G, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->G, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Ms, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)b->G, "coupling"));
  PetscCall(PetscObjectSetName((PetscObject)b->Ms, "compliance mass"));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  /* the step's maps between velocity and stress, cell by cell (shells: nothing is stored until their first product);
     once: G and Ms may be assembled again after FlexMixedOperators freed them, the maps live on */
  if (!b->smap_created) PetscCall(PhlexFlexibleCreateStressMaps(b));
  b->smap_created = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* -phlex_check_condensation: the exact element-wise elimination G^T Ms^{-1} G against the stiffness used, on every
   local cell; prints the largest relative difference (DESIGN section 2: equal for constant material on affine cells). */
static PetscErrorCode CheckCondensation(PhlexFlexible b, const PhlexUnits *u)
{
  const PhlexElementReferenceIntegrals *R = &b->ref;
  const PetscInt                        nv = b->nb_v, ns = b->nb_s;
  PetscReal                            *Ge, *Mse, *Ke, *Kc, *work, A[36], worst = 0, gworst;

  PetscFunctionBeginUser;
  if (!b->check_condensation) PetscFunctionReturn(0);
  PetscCall(PetscMalloc5(ns * nv, &Ge, ns * ns, &Mse, nv * nv, &Ke, nv * nv, &Kc, ns * nv, &work));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    const PetscReal      E = mat->youngs_modulus / u->modulus, nu = mat->poissons_ratio;
    PetscReal            dn = 0, kn = 0;
    PhlexElementStiffness(R, E, nu, g[0], &g[1], Ke);
    PhlexElementCoupling(R, g[0], &g[1], work, Ge);
    PhlexElementCompliance(E, nu, A);
    PhlexElementComplianceMass(R, g[0], A, Mse);
    PetscCheck(!PhlexElementCondense(ns, nv, Mse, Ge, work, Kc), PETSC_COMM_SELF, PETSC_ERR_PLIB, "compliance mass of cell %" PetscInt_FMT " not positive definite", c);
    for (PetscInt i = 0; i < nv * nv; i++) {
      dn += PetscSqr(Kc[i] - Ke[i]);
      kn += PetscSqr(Ke[i]);
    }
    worst = PetscMax(worst, PetscSqrtReal(dn / kn));
  }
  PetscCall(PetscFree5(Ge, Mse, Ke, Kc, work));
  PetscCallMPI(MPI_Allreduce(&worst, &gworst, 1, MPIU_REAL, MPI_MAX, b->comm));
  PetscCall(PetscPrintf(b->comm, "body %s: element stress elimination G^T Ms^-1 G vs stiffness: max relative difference %s\n", b->name, gworst < 1e-13 ? "< 1e-13" : "LARGE"));
  PetscCheck(gworst < 1e-13, b->comm, PETSC_ERR_PLIB, "body %s: element stress elimination differs from the stiffness by %g", b->name, (double)gworst);
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSetUpFE - builds the spaces of a loaded mesh and assembles the constant operators; a floating body
  also gets its frame origin and inertia invariants

  Collective

  Input Parameters:
+ b     - the body (mesh loaded and checked)
- units - reference scales of the non-dimensionalisation
@*/
PetscErrorCode PhlexFlexibleSetUpFE(PhlexFlexible b, const PhlexUnits *units)
{
  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodySetUp, 0, 0, 0, 0));
  PetscCall(SetUpSpaces(b));
  PetscCall(SetUpMaterials(b));
  PetscCall(SetUpCellGeometry(b, units));
  PetscCall(SetUpCellDofs(b));
  /* the materials' compliances (non-dimensional): the cell-by-cell stress maps need them without G and Ms */
  for (PetscInt m = 0; m < b->nmaterials; m++) PhlexElementCompliance(b->materials[m].youngs_modulus / units->modulus, b->materials[m].poissons_ratio, b->compliance[m]);
  {
    PhlexElementBasis V, S;
    PetscCall(PhlexFlexibleGetBasis(b, PETSC_FALSE, &V));
    PetscCall(PhlexFlexibleGetBasis(b, PETSC_TRUE, &S));
    PhlexElementReference(&V, &S, &b->ref);
    PetscCall(PhlexFlexibleRestoreBasis(&V));
    PetscCall(PhlexFlexibleRestoreBasis(&S));
  }
  PetscCall(AssembleVelocityOperators(b, units));
  PetscCall(CheckCondensation(b, units));
  /* the frame origin P: the frame patch's centroid, or the centre of mass with mean axes (or as given); a fixed
     body's frame is the inertial one */
  if (b->floating && !b->origin_given) {
    for (PetscInt d = 0; d < 3; d++) b->origin[d] = b->frame_condition == PHLEX_FRAME_PATCH ? b->frame_centroid[d] : b->center_of_mass[d];
  }
  if (!b->floating)
    for (PetscInt d = 0; d < 3; d++) b->origin[d] = 0.0;
  if (b->floating && !b->pose.position_given)
    for (PetscInt d = 0; d < 3; d++) b->pose.position[d] = b->origin[d];
  if (b->floating) PetscCall(PhlexFlexibleSetUpInertia(b, units));
  PetscCall(PetscLogEventEnd(PHLEX_BodySetUp, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleSetUpInertia - inertia invariants of a floating body about its frame origin P (non-dimensional):
  m, s0 = int rho x, E0 = int rho x x^T, the volume, int x dV, and the nodal vectors t, w of the elastic space

  Collective
@*/
PetscErrorCode PhlexFlexibleSetUpInertia(PhlexFlexible b, const PhlexUnits *u)
{
  PhlexElementBasis V;
  PetscQuadrature   q;
  const PetscReal  *qpoints;
  PetscInt          nq, nn = b->nb_v / 3;
  PetscReal         loc[1 + 3 + 9 + 1 + 3] = {0}, glob[17];

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleGetBasis(b, PETSC_FALSE, &V));
  PetscCall(PetscFEGetQuadrature(b->fe_v, &q));
  PetscCall(PetscQuadratureGetData(q, NULL, NULL, &nq, &qpoints, NULL));
  PetscCall(DMCreateGlobalVector(b->dm, &b->tnode));
  PetscCall(VecDuplicate(b->tnode, &b->wnode));
  PetscCall(VecDuplicate(b->tnode, &b->vnode));
  PetscCall(VecSet(b->tnode, 0.0));
  PetscCall(VecSet(b->wnode, 0.0));
  PetscCall(VecSet(b->vnode, 0.0));
  /* closure indices of the frame-patch dofs are negative (constrained): drop them */
  PetscCall(VecSetOption(b->tnode, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  PetscCall(VecSetOption(b->wnode, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  PetscCall(VecSetOption(b->vnode, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  for (PetscInt c = b->cStart; c < b->cEnd; c++) {
    const PetscInt      ci  = c - b->cStart;
    const PhlexMaterial *mat = &b->materials[b->cell_material[ci]];
    const PetscReal      rho = mat->density / u->density;
    const PetscInt      *idx = &b->cell_vdofs[ci * b->nb_v];
    PetscReal            v0[3], J[9], invJ[9], detJ, dV;
    PetscScalar          te[3 * PHLEX_MAX_NODES], we[3 * PHLEX_MAX_NODES], ve[3 * PHLEX_MAX_NODES];

    PetscCall(DMPlexComputeCellGeometryAffineFEM(b->dm, c, v0, J, invJ, &detJ));
    for (PetscInt i = 0; i < 3 * nn; i++) te[i] = we[i] = ve[i] = 0.0;
    for (PetscInt qq = 0; qq < nq; qq++) {
      PetscReal x[3];
      /* x relative to P, non-dimensional: x = v0 + J (xi + 1) */
      for (PetscInt d = 0; d < 3; d++) x[d] = (v0[d] + J[3 * d] * (qpoints[3 * qq] + 1) + J[3 * d + 1] * (qpoints[3 * qq + 1] + 1) + J[3 * d + 2] * (qpoints[3 * qq + 2] + 1) - b->origin[d]) / u->length;
      dV = V.weights[qq] * detJ / (u->length * u->length * u->length);
      loc[0] += rho * dV;
      for (PetscInt d = 0; d < 3; d++) {
        loc[1 + d] += rho * dV * x[d];
        loc[14 + d] += dV * x[d];
        for (PetscInt e = 0; e < 3; e++) loc[4 + 3 * d + e] += rho * dV * x[d] * x[e];
      }
      loc[13] += dV;
      for (PetscInt a = 0; a < nn; a++) {
        const PetscReal phi = V.node_phi[qq * V.nnodes + a];
        for (PetscInt d = 0; d < 3; d++) {
          te[3 * a + d] += rho * dV * phi;
          we[3 * a + d] += rho * dV * phi * x[d];
          ve[3 * a + d] += dV * phi;
        }
      }
    }
    PetscCall(VecSetValues(b->tnode, 3 * nn, idx, te, ADD_VALUES));
    PetscCall(VecSetValues(b->wnode, 3 * nn, idx, we, ADD_VALUES));
    PetscCall(VecSetValues(b->vnode, 3 * nn, idx, ve, ADD_VALUES));
  }
  PetscCall(PhlexFlexibleRestoreBasis(&V));
  PetscCall(VecAssemblyBegin(b->tnode));
  PetscCall(VecAssemblyEnd(b->tnode));
  PetscCall(VecAssemblyBegin(b->wnode));
  PetscCall(VecAssemblyEnd(b->wnode));
  PetscCall(VecAssemblyBegin(b->vnode));
  PetscCall(VecAssemblyEnd(b->vnode));
  PetscCall(MPIU_Allreduce(loc, glob, 17, MPIU_REAL, MPI_SUM, b->comm));
  b->inertia.m = glob[0];
  for (PetscInt d = 0; d < 3; d++) {
    b->inertia.s0[d]   = glob[1 + d];
    b->inertia.svol[d] = glob[14 + d];
  }
  for (PetscInt k = 0; k < 9; k++) b->inertia.E0[k] = glob[4 + k];
  b->inertia.vol = glob[13];
  PetscFunctionReturn(0);
}

/* splitmix64's finalizer: a 64-bit mix in which every input bit reaches every output bit */
static inline uint64_t Mix64(uint64_t x)
{
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

/* XOR over the points of dm's global section that this process owns and that carry unknowns: their first global
   number mixed with their place, the XOR of their closure's vertices' coordinate bits (order-free, no arithmetic on
   them: a point gets the same key on any process count and in any numbering) */
static PetscErrorCode PlacementOfSection(DM dm, uint64_t *h)
{
  PetscSection       gs, cs;
  Vec                coords;
  const PetscScalar *x;
  PetscInt           pStart, pEnd, vStart, vEnd, dim;

  PetscFunctionBeginUser;
  PetscCall(DMGetGlobalSection(dm, &gs));
  PetscCall(DMGetCoordinateSection(dm, &cs));
  PetscCall(DMGetCoordinatesLocal(dm, &coords));
  PetscCall(DMGetCoordinateDim(dm, &dim));
  PetscCall(DMPlexGetDepthStratum(dm, 0, &vStart, &vEnd));
  PetscCall(PetscSectionGetChart(gs, &pStart, &pEnd));
  PetscCall(VecGetArrayRead(coords, &x));
  for (PetscInt p = pStart; p < pEnd; p++) {
    PetscInt dof, off, npts, *pts = NULL;
    uint64_t key = 0;
    PetscCall(PetscSectionGetDof(gs, p, &dof));
    PetscCall(PetscSectionGetOffset(gs, p, &off));
    if (dof <= 0 || off < 0) continue; /* no unknowns, or another process's */
    PetscCall(DMPlexGetTransitiveClosure(dm, p, PETSC_TRUE, &npts, &pts));
    for (PetscInt k = 0; k < npts; k++) {
      const PetscInt v = pts[2 * k];
      PetscInt       coff;
      uint64_t       kv = 0x9e3779b97f4a7c15ULL;
      if (v < vStart || v >= vEnd) continue;
      PetscCall(PetscSectionGetOffset(cs, v, &coff));
      for (PetscInt d = 0; d < dim; d++) {
        uint64_t bits;
        memcpy(&bits, &x[coff + d], sizeof(bits));
        kv = Mix64(kv ^ bits);
      }
      key ^= kv;
    }
    PetscCall(DMPlexRestoreTransitiveClosure(dm, p, PETSC_TRUE, &npts, &pts));
    *h ^= Mix64(key ^ Mix64((uint64_t)off + 1));
  }
  PetscCall(VecRestoreArrayRead(coords, &x));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePlacement - a 64-bit hash of where the body's unknowns are: each velocity node's and each cell's stress
  unknowns' first global number with the coordinates of its place, over the processes. The same mesh, node order and
  partition give the same hash on any machine; another order of the mesh file's nodes, -node_order, partitioner or
  RCM implementation another: a checkpoint's fingerprint holds it, so that a restart never reads a state into
  unknowns numbered otherwise.

  Collective
@*/
PetscErrorCode PhlexFlexiblePlacement(PhlexFlexible b, uint64_t *hash)
{
  uint64_t h = 0;

  PetscFunctionBeginUser;
  PetscCall(PlacementOfSection(b->dm, &h));
  PetscCall(PlacementOfSection(b->dm_s, &h));
  PetscCallMPI(MPI_Allreduce(&h, hash, 1, MPI_UINT64_T, MPI_BXOR, b->comm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDestroyFE - frees the spaces, operators and mesh of a flexible body
@*/
PetscErrorCode PhlexFlexibleDestroyFE(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&b->tnode));
  PetscCall(VecDestroy(&b->wnode));
  PetscCall(VecDestroy(&b->vnode));
  PetscCall(MatDestroy(&b->Mv));
  PetscCall(MatDestroy(&b->K));
  PetscCall(MatDestroy(&b->G));
  PetscCall(MatDestroy(&b->Ms));
  for (PetscInt c = 0; c < 3; c++) PetscCall(VecDestroy(&b->fvol[c]));
  PetscCall(PetscFEDestroy(&b->fe_v));
  PetscCall(PetscFEDestroy(&b->fe_s));
  PetscCall(DMDestroy(&b->dm_s));
  PetscCall(DMDestroy(&b->dm));
  PetscCall(PetscFree(b->cell_material));
  PetscCall(PetscFree2(b->cell_vdofs, b->cell_soff));
  PetscCall(PetscFree(b->cell_vloc));
  PetscCall(PetscFree(b->cell_geom));
  PetscCall(PetscFree(b->groups));
  PetscFunctionReturn(0);
}
