/* Geometric (centrifugal) stiffening of a flexible body, -<body>_geometric_stiffening.

   The linear floating-frame model (paper Section 4) keeps the strain of the elastic field linear, eps = sym Grad u:
   a stress already in the body (the centrifugal tension of a spinning beam) then does no work on a transverse
   displacement, and a fast-spinning beam wrongly softens. The option takes the strain as the Green-Lagrange strain
   of the displacement in the body frame, E(u) = sym(H) + H^T H / 2, H = Grad u_f, F = I + H, with the same linear
   material (Sigma = D E: Saint Venant-Kirchhoff). In the mixed form of paper eq. eldyn_PDE this changes one
   operator: the differential operator Grad acting on the velocity becomes sym(F^T Grad v), the rate of E(u),

     Ms Sigma' = G(u) v                        (compatibility: Sigma' = D dE/dt)
     Mv v'     = -G(u)^T Sigma + ...           (momentum: the first Piola stress F Sigma; its H Sigma part is the
                                                prestress Sigma acting on the displacement gradient)
     G(u) = int Sigma : sym(F^T Grad v) = G + G1(u)

   G(u) is modulated by the state but enters both rows, once and transposed: the interconnection J(u) stays skew
   and the Hamiltonian (kinetic + compliance energy, quadratic) is unchanged. The power balance therefore holds
   exactly, and the implicit midpoint rule keeps it to solver tolerance (H quadratic, J(u) skew at the midpoint).
   Linearised about a stressed state (Sigma0, u0), the momentum rows gain K_sigma du = d(G(u)^T Sigma0)/du du,
   the initial-stress matrix int (Grad du Sigma0) : Grad w: the centrifugal stiffening of a spinning beam.

   Assumptions: small strains (linear material), the large rotation carried by the frame (floating) or the hub
   (fixed, spinning), the field's own rotations moderate (H^T H kept, so an elastic rotation of the field relative
   to its frame is strain-free to second order); Saint Venant-Kirchhoff softens under large compression.
   The stress a displacement holds is Ms Sigma = int psi : E(u) (PhlexFlexibleStressOfDisplacement), whose rate
   is G(u) v: an initial displacement and its stress stay consistent.

   Costs: one element loop per residual (G(u)) and one more per Jacobian (K_sigma, d(G(u) v)/du and the condensed
   operator of the preconditioner, refactored each Newton iteration): only for bodies with the option. A fixed
   body's condensed operator is the exact Schur complement of u and Sigma, G(u)^T Ms^{-1} d(G(u) v)/du / shift^2
   included (not symmetric: LU, options/solver/exact_krylov.opts); without that term FGMRES needed from 4 to over 200
   iterations as a bending cantilever's velocity gradient grew (a 1 m steel bar, 5 cm tip deflection, 15 steps). */
#include <phlex_impl.h>

/* the element bases, the cells' local dof offsets and a local displacement vector, once */
static PetscErrorCode SetUpWorkspace(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  if (!b->have_basis) {
    PetscCall(PhlexFlexibleGetBasis(b, PETSC_FALSE, &b->basis_v));
    PetscCall(PhlexFlexibleGetBasis(b, PETSC_TRUE, &b->basis_s));
    b->have_basis = PETSC_TRUE;
  }
  PetscCall(PhlexFlexibleSetUpLocalDofs(b));
  if (!b->uloc) PetscCall(DMCreateLocalVector(b->dm, &b->uloc));
  PetscFunctionReturn(0);
}

/* the local (ghosted) copy of a velocity-space vector; constrained dofs (the clamp, the frame patch) are zero */
static PetscErrorCode ToLocal(PhlexFlexible b, Vec x, Vec xloc, const PetscScalar **a)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(xloc, 0.0));
  PetscCall(DMGlobalToLocalBegin(b->dm, x, INSERT_VALUES, xloc));
  PetscCall(DMGlobalToLocalEnd(b->dm, x, INSERT_VALUES, xloc));
  PetscCall(VecGetArrayRead(xloc, a));
  PetscFunctionReturn(0);
}

static inline void CellValues(PhlexFlexible b, PetscInt c, const PetscScalar *a, PetscReal *xe)
{
  for (PetscInt i = 0; i < b->nb_v; i++) xe[i] = PetscRealPart(a[b->cell_vloc[c * b->nb_v + i]]);
}

/* node (block) indices of a cell, -1 for constrained nodes */
static inline void CellNodes(PhlexFlexible b, PetscInt c, PetscInt *nodes)
{
  const PetscInt *idx = &b->cell_vdofs[c * b->nb_v];
  for (PetscInt a = 0; a < b->nb_v / 3; a++) nodes[a] = idx[3 * a] >= 0 ? idx[3 * a] / 3 : -1;
}

/* a cell's coupling-pattern block (ns x nv) into a matrix of G's pattern, columns sorted */
static PetscErrorCode SetCouplingBlock(PhlexFlexible b, Mat A, PetscInt c, const PetscReal *Ge, PetscReal *work)
{
  const PetscInt *idx = &b->cell_vdofs[c * b->nb_v];
  PetscInt        perm[3 * PHLEX_MAX_NODES], sidx[3 * PHLEX_MAX_NODES], rows[6 * 4];

  PetscFunctionBeginUser;
  for (PetscInt a = 0; a < b->nb_v; a++) perm[a] = a, sidx[a] = idx[a];
  PetscCall(PetscSortIntWithArray(b->nb_v, sidx, perm));
  for (PetscInt j = 0; j < b->nb_s; j++) {
    rows[j] = b->cell_soff[c] + j;
    for (PetscInt a = 0; a < b->nb_v; a++) work[j * b->nb_v + a] = Ge[j * b->nb_v + perm[a]];
  }
  PetscCall(MatSetValues(A, b->nb_s, rows, b->nb_v, sidx, work, INSERT_VALUES));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleStiffeningSetUp - the matrices of the Green-Lagrange coupling (after the field operators exist)

  Collective
@*/
PetscErrorCode PhlexFlexibleStiffeningSetUp(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  if (b->Gu) PetscFunctionReturn(0);
  PetscCall(SetUpWorkspace(b));
  if (!b->vloc) PetscCall(DMCreateLocalVector(b->dm, &b->vloc));
  PetscCall(MatDuplicate(b->G, MAT_COPY_VALUES, &b->Gu));
  PetscCall(MatDuplicate(b->G, MAT_COPY_VALUES, &b->Gres));
  PetscCall(MatTranspose(b->Gu, MAT_INITIAL_MATRIX, &b->Gut));
  PetscCall(MatDuplicate(b->G, MAT_DO_NOT_COPY_VALUES, &b->Jsu));
  PetscCall(MatDuplicate(b->Kaij, MAT_DO_NOT_COPY_VALUES, &b->Ksig));
  PetscCall(MatSetOption(b->Ksig, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PetscCall(MatDuplicate(b->Kaij, MAT_DO_NOT_COPY_VALUES, &b->Nsu));
  PetscCall(PetscObjectSetName((PetscObject)b->Gu, "Green-Lagrange coupling G(u)"));
  PetscCall(PetscObjectSetName((PetscObject)b->Ksig, "initial-stress stiffness"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleCouplingUpdate - G(u) at the displacement u, into the residual's own matrix Gres

  Collective
@*/
PetscErrorCode PhlexFlexibleCouplingUpdate(PhlexFlexible b, Vec u)
{
  const PetscInt     nv = b->nb_v, ns = b->nb_s;
  const PetscScalar *ua;
  PetscReal         *Ge, *work, ue[3 * PHLEX_MAX_NODES];
  PhlexProgress      progress;
  PetscInt           chunk = 0;
  char               what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(PetscMalloc2(ns * nv, &Ge, ns * nv, &work));
  PetscCall(ToLocal(b, u, b->uloc, &ua));
  /* outside the time steps (the steady state of a linearised analysis): checks the interrupt flag, reports progress */
  PetscCall(PetscSNPrintf(what, sizeof(what), "stiffening of body %s (G(u))", b->name));
  PetscCall(PhlexProgressStart(&progress));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal *g = &b->cell_geom[10 * c];
    CellValues(b, c, ua, ue);
    PhlexElementCouplingDeformed(&b->basis_v, &b->basis_s, g[0], &g[1], ue, Ge);
    PetscCall(SetCouplingBlock(b, b->Gres, c, Ge, work));
    PetscCall(PhlexProgressChunk(&progress, b->comm, what, c, b->cEnd - b->cStart, &chunk));
  }
  PetscCall(PhlexProgressChunksEnd(&progress, b->comm, what, chunk));
  PetscCall(VecRestoreArrayRead(b->uloc, &ua));
  PetscCall(PetscFree2(Ge, work));
  PetscCall(MatAssemblyBegin(b->Gres, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Gres, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleStiffeningJacobian - the Jacobian's pieces at the state (u, Sigma, v): G(u) and its transpose, the
  initial-stress stiffness K_sigma(Sigma), d(G(u) v)/du, and the condensed stiffness G(u)^T Ms^{-1} G(u) (Kaij:
  the preconditioner's and the linearised analysis's K)

  Collective
@*/
PetscErrorCode PhlexFlexibleStiffeningJacobian(PhlexFlexible b, Vec u, Vec s, Vec v)
{
  const PhlexUnits  *units = b->part->units;
  const PetscInt     nv = b->nb_v, ns = b->nb_s, nn = nv / 3;
  const PetscScalar *ua, *va, *sa;
  PetscReal         *Ge, *Je, *Ke, *Kc, *Nc, *W, *C, *Mse, *work, A[36], ue[3 * PHLEX_MAX_NODES], ve[3 * PHLEX_MAX_NODES];
  PetscInt           rstart, chunk = 0;
  PhlexProgress      progress;
  char               what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscCall(PetscMalloc6(ns * nv, &Ge, ns * nv, &Je, nv * nv, &Ke, nv * nv, &Kc, ns * ns, &Mse, ns * nv, &work));
  PetscCall(PetscMalloc3(nv * nv, &Nc, 2 * ns * nv, &W, 2 * nv * nv, &C));
  PetscCall(MatZeroEntries(b->Ksig));
  PetscCall(MatZeroEntries(b->Nsu));
  PetscCall(MatZeroEntries(b->Kaij));
  PetscCall(VecGetOwnershipRange(s, &rstart, NULL));
  PetscCall(ToLocal(b, u, b->uloc, &ua));
  PetscCall(ToLocal(b, v, b->vloc, &va));
  PetscCall(VecGetArrayRead(s, &sa));
  PetscCall(PetscSNPrintf(what, sizeof(what), "stiffening of body %s (K_sigma, the Jacobian's blocks)", b->name));
  PetscCall(PhlexProgressStart(&progress));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    PetscReal            se[6 * 4];
    PetscInt             nodes[PHLEX_MAX_NODES];
    CellValues(b, c, ua, ue);
    CellValues(b, c, va, ve);
    for (PetscInt j = 0; j < ns; j++) se[j] = PetscRealPart(sa[b->cell_soff[c] - rstart + j]);
    PhlexElementCouplingDeformed(&b->basis_v, &b->basis_s, g[0], &g[1], ue, Ge);
    PhlexElementCouplingDerivative(&b->basis_v, &b->basis_s, g[0], &g[1], ve, Je);
    PhlexElementGeometricStiffness(&b->basis_v, &b->basis_s, g[0], &g[1], se, Ke);
    PhlexElementCompliance(mat->youngs_modulus / units->modulus, mat->poissons_ratio, A);
    PhlexElementComplianceMass(&b->ref, g[0], A, Mse);
    {
      /* [Kc | Nc] = Ge^T Mse^{-1} [Ge | Je] by LAPACK/BLAS: W = Mse^{-1} [Ge | Je] (column-major ns x 2nv), then
         C = Ge^T W (nv x 2nv); Ge row-major ns x nv is Ge^T column-major with leading dimension nv */
      PetscBLASInt bns = (PetscBLASInt)ns, bnv = (PetscBLASInt)nv, b2nv = (PetscBLASInt)(2 * nv), info;
      const PetscReal one = 1.0, zero = 0.0;
      for (PetscInt j = 0; j < ns; j++)
        for (PetscInt a = 0; a < nv; a++) {
          W[a * ns + j]        = Ge[j * nv + a];
          W[(nv + a) * ns + j] = Je[j * nv + a];
        }
      PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("L", &bns, Mse, &bns, &info));
      PetscCheck(!info, PETSC_COMM_SELF, PETSC_ERR_PLIB, "body %s: compliance mass of cell %" PetscInt_FMT " is not positive definite", b->name, c);
      PetscCallBLAS("LAPACKpotrs", LAPACKpotrs_("L", &bns, &b2nv, Mse, &bns, W, &bns, &info));
      PetscCallBLAS("BLASgemm", BLASgemm_("N", "N", &bnv, &b2nv, &bns, &one, Ge, &bnv, W, &bns, &zero, C, &bnv));
      for (PetscInt a = 0; a < nv; a++)
        for (PetscInt bb = 0; bb < nv; bb++) {
          Kc[a * nv + bb] = C[bb * nv + a];
          Nc[a * nv + bb] = C[(nv + bb) * nv + a];
        }
    }
    PetscCall(SetCouplingBlock(b, b->Gu, c, Ge, work));
    PetscCall(SetCouplingBlock(b, b->Jsu, c, Je, work));
    CellNodes(b, c, nodes);
    PetscCall(MatSetValuesBlocked(b->Ksig, nn, nodes, nn, nodes, Ke, ADD_VALUES));
    PetscCall(MatSetValuesBlocked(b->Kaij, nn, nodes, nn, nodes, Kc, ADD_VALUES));
    PetscCall(MatSetValuesBlocked(b->Nsu, nn, nodes, nn, nodes, Nc, ADD_VALUES));
    PetscCall(PhlexProgressChunk(&progress, b->comm, what, c, b->cEnd - b->cStart, &chunk));
  }
  PetscCall(PhlexProgressChunksEnd(&progress, b->comm, what, chunk));
  PetscCall(VecRestoreArrayRead(s, &sa));
  PetscCall(VecRestoreArrayRead(b->uloc, &ua));
  PetscCall(VecRestoreArrayRead(b->vloc, &va));
  PetscCall(PetscFree6(Ge, Je, Ke, Kc, Mse, work));
  PetscCall(PetscFree3(Nc, W, C));
  PetscCall(MatAssemblyBegin(b->Gu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Gu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Jsu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Jsu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Ksig, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Ksig, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Kaij, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Kaij, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(b->Nsu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Nsu, MAT_FINAL_ASSEMBLY));
  PetscCall(MatTranspose(b->Gu, MAT_REUSE_MATRIX, &b->Gut));
  PetscCall(PetscLogEventEnd(PHLEX_BodyAssemble, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleStressOfDisplacement - the stress a displacement holds: Ms Sigma = int psi : E(u), cell by cell
  (E the Green-Lagrange strain with the option, sym Grad u without)

  Collective
@*/
PetscErrorCode PhlexFlexibleStressOfDisplacement(PhlexFlexible b, Vec u, Vec s)
{
  const PhlexUnits  *units = b->part->units;
  const PetscInt     ns = b->nb_s;
  const PetscScalar *ua;
  PetscScalar       *sa;
  PetscReal         *Mse, be[6 * 4], A[36], ue[3 * PHLEX_MAX_NODES];
  PetscInt           rstart, chunk = 0;
  PhlexProgress      progress;
  char               what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  PetscCall(SetUpWorkspace(b));
  PetscCall(PetscSNPrintf(what, sizeof(what), "the stress of a displacement of body %s", b->name));
  PetscCall(PhlexProgressStart(&progress));
  PetscCall(PetscMalloc1(ns * ns, &Mse));
  PetscCall(VecGetOwnershipRange(s, &rstart, NULL));
  PetscCall(ToLocal(b, u, b->uloc, &ua));
  PetscCall(VecGetArray(s, &sa));
  for (PetscInt c = 0; c < b->cEnd - b->cStart; c++) {
    const PetscReal     *g   = &b->cell_geom[10 * c];
    const PhlexMaterial *mat = &b->materials[b->cell_material[c]];
    CellValues(b, c, ua, ue);
    PhlexElementGreenLagrange(&b->basis_v, &b->basis_s, g[0], &g[1], b->stiffening, ue, be);
    PhlexElementCompliance(mat->youngs_modulus / units->modulus, mat->poissons_ratio, A);
    PhlexElementComplianceMass(&b->ref, g[0], A, Mse);
    PetscCheck(!PhlexDenseCholesky(ns, Mse), PETSC_COMM_SELF, PETSC_ERR_PLIB, "body %s: compliance mass of cell %" PetscInt_FMT " is not positive definite", b->name, c);
    PhlexDenseCholeskySolve(ns, Mse, 1, be);
    for (PetscInt j = 0; j < ns; j++) sa[b->cell_soff[c] - rstart + j] = be[j];
    PetscCall(PhlexProgressChunk(&progress, b->comm, what, c, b->cEnd - b->cStart, &chunk));
  }
  PetscCall(PhlexProgressChunksEnd(&progress, b->comm, what, chunk));
  PetscCall(VecRestoreArray(s, &sa));
  PetscCall(VecRestoreArrayRead(b->uloc, &ua));
  PetscCall(PetscFree(Mse));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexFlexibleStiffeningDestroy(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&b->Gu));
  PetscCall(MatDestroy(&b->Gres));
  PetscCall(MatDestroy(&b->Gut));
  PetscCall(MatDestroy(&b->Ksig));
  PetscCall(MatDestroy(&b->Jsu));
  PetscCall(MatDestroy(&b->Nsu));
  PetscCall(MatDestroy(&b->Mvs));
  PetscCall(VecDestroy(&b->uloc));
  PetscCall(VecDestroy(&b->vloc));
  if (b->have_basis) {
    PetscCall(PhlexFlexibleRestoreBasis(&b->basis_v));
    PetscCall(PhlexFlexibleRestoreBasis(&b->basis_s));
    b->have_basis = PETSC_FALSE;
  }
  PetscFunctionReturn(0);
}
