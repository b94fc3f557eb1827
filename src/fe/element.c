/* Element kernels of the mixed velocity-stress discretisation (paper Section 4.1) on affine tetrahedra.
   Pure arithmetic: no PETSc calls, no allocation. All quantities non-dimensional.

   On an affine cell every integrand is a polynomial times constants of the cell (detJ, invJ, material), so the
   kernels contract reference integrals, computed once from the PetscFE tabulations (PhlexElementReference), with
   the cell's geometry. Velocity basis function b = 3 node_b + comp_b (node-major Lagrange P_k); stress basis
   function j = 6 node_j + s_j with s in Voigt order (xx, yy, zz, yz, xz, xy), a shear component holding the tensor
   entry, so that Sigma : eps = sum_normal s e + 2 sum_shear s e. */
#include <phlex_impl.h>

/* Compliance D^{-1} of an isotropic material in this Voigt form: Sigma : D^{-1} Sigma' = s^T A s'.
   Normal block (1/E)[1 -nu -nu; ...], shear diagonal 2(1+nu)/E (= 1/G, because shear entries count twice). */
void PhlexElementCompliance(PetscReal E, PetscReal nu, PetscReal A[36])
{
  for (PetscInt i = 0; i < 36; i++) A[i] = 0.0;
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt b = 0; b < 3; b++) A[a * 6 + b] = (a == b ? 1.0 : -nu) / E;
  for (PetscInt a = 3; a < 6; a++) A[a * 6 + a] = 2.0 * (1.0 + nu) / E;
}

/* Reference integrals (reference cell, PetscFE quadrature):
   mass[a][b]    = sum_q w phi_a phi_b                     (velocity nodes)
   grad[a][b][d][e] = sum_q w dphi_a/dxi_d dphi_b/dxi_e     (velocity nodes)
   smass[i][j]   = sum_q w psi_i psi_j                     (stress nodes)
   coup[i][b][d] = sum_q w psi_i dphi_b/dxi_d              (stress node i, velocity node b)
   load[a]       = sum_q w phi_a */
void PhlexElementReference(const PhlexElementBasis *V, const PhlexElementBasis *S, PhlexElementReferenceIntegrals *R)
{
  const PetscInt nv = V->nnodes, ns = S->nnodes, nq = V->nq;

  R->nv = nv;
  R->ns = ns;
  for (PetscInt i = 0; i < nv * nv; i++) R->mass[i] = 0.0;
  for (PetscInt i = 0; i < nv * nv * 9; i++) R->grad[i] = 0.0;
  for (PetscInt i = 0; i < ns * ns; i++) R->smass[i] = 0.0;
  for (PetscInt i = 0; i < ns * nv * 3; i++) R->coup[i] = 0.0;
  for (PetscInt i = 0; i < nv; i++) R->load[i] = 0.0;
  for (PetscInt q = 0; q < nq; q++) {
    const PetscReal  w   = V->weights[q];
    const PetscReal *phi = &V->node_phi[q * nv], *dphi = &V->node_dphi[q * nv * 3], *psi = &S->node_phi[q * ns];
    for (PetscInt a = 0; a < nv; a++) {
      R->load[a] += w * phi[a];
      for (PetscInt b = 0; b < nv; b++) {
        R->mass[a * nv + b] += w * phi[a] * phi[b];
        for (PetscInt d = 0; d < 3; d++)
          for (PetscInt e = 0; e < 3; e++) R->grad[((a * nv + b) * 3 + d) * 3 + e] += w * dphi[a * 3 + d] * dphi[b * 3 + e];
      }
    }
    for (PetscInt i = 0; i < ns; i++) {
      for (PetscInt j = 0; j < ns; j++) R->smass[i * ns + j] += w * psi[i] * psi[j];
      for (PetscInt b = 0; b < nv; b++)
        for (PetscInt d = 0; d < 3; d++) R->coup[(i * nv + b) * 3 + d] += w * psi[i] * dphi[b * 3 + d];
    }
  }
}

/* Velocity mass Me (3nv x 3nv): rho detJ mass[a][b] delta_cd   (paper eq. eldyn_PDE, the rho block of M) */
void PhlexElementMass(const PhlexElementReferenceIntegrals *R, PetscReal rho, PetscReal detJ, PetscReal *Me)
{
  const PetscInt nv = R->nv, n = 3 * nv;

  for (PetscInt i = 0; i < n * n; i++) Me[i] = 0.0;
  for (PetscInt a = 0; a < nv; a++)
    for (PetscInt b = 0; b < nv; b++) {
      const PetscReal m = rho * detJ * R->mass[a * nv + b];
      for (PetscInt c = 0; c < 3; c++) Me[(3 * a + c) * n + 3 * b + c] = m;
    }
}

/* Load of a unit uniform force density per node: detJ int phi_a */
void PhlexElementLoad(const PhlexElementReferenceIntegrals *R, PetscReal detJ, PetscReal *fe)
{
  for (PetscInt a = 0; a < R->nv; a++) fe[a] = detJ * R->load[a];
}

/* Physical gradient moments P[i][b][x] = detJ sum_d coup[i][b][d] invJ[d][x] = int psi_i dphi_b/dx_x */
static void CouplingMoments(const PhlexElementReferenceIntegrals *R, PetscReal detJ, const PetscReal invJ[9], PetscReal *P)
{
  for (PetscInt i = 0; i < R->ns; i++)
    for (PetscInt b = 0; b < R->nv; b++) {
      const PetscReal *c = &R->coup[(i * R->nv + b) * 3];
      for (PetscInt x = 0; x < 3; x++) P[(i * R->nv + b) * 3 + x] = detJ * (c[0] * invJ[0 * 3 + x] + c[1] * invJ[1 * 3 + x] + c[2] * invJ[2 * 3 + x]);
    }
}

/* Coupling Ge (6ns x 3nv): Ge[(i,s)][(b,c)] = int psi_i E_s : Grad(phi_b e_c)  (the Grad operator kept on the
   velocity: j_Grad after integration by parts of J_Div, paper Section 4.1). E_s : Grad(phi e_c) is g_a for a normal
   component a = c; for a shear component (a,b): g_b if c = a, g_a if c = b. */
void PhlexElementCoupling(const PhlexElementReferenceIntegrals *R, PetscReal detJ, const PetscReal invJ[9], PetscReal *work, PetscReal *Ge)
{
  const PetscInt ns = R->ns, nv = R->nv, ncol = 3 * nv;
  static const PetscInt pair[3][2] = {{1, 2}, {0, 2}, {0, 1}}; /* yz, xz, xy */

  CouplingMoments(R, detJ, invJ, work);
  for (PetscInt i = 0; i < 6 * ns * ncol; i++) Ge[i] = 0.0;
  for (PetscInt i = 0; i < ns; i++)
    for (PetscInt b = 0; b < nv; b++) {
      const PetscReal *g = &work[(i * nv + b) * 3];
      for (PetscInt a = 0; a < 3; a++) Ge[(6 * i + a) * ncol + 3 * b + a] = g[a];
      for (PetscInt k = 0; k < 3; k++) {
        const PetscInt a = pair[k][0], c = pair[k][1];
        Ge[(6 * i + 3 + k) * ncol + 3 * b + a] = g[c];
        Ge[(6 * i + 3 + k) * ncol + 3 * b + c] = g[a];
      }
    }
}

/* Compliance mass Mse (6ns x 6ns): detJ smass[i][j] A[s][t]   (the D^{-1} block of the mass operator) */
void PhlexElementComplianceMass(const PhlexElementReferenceIntegrals *R, PetscReal detJ, const PetscReal A[36], PetscReal *Mse)
{
  const PetscInt ns = R->ns, n = 6 * ns;

  for (PetscInt i = 0; i < ns; i++)
    for (PetscInt j = 0; j < ns; j++)
      for (PetscInt s = 0; s < 6; s++)
        for (PetscInt t = 0; t < 6; t++) Mse[(6 * i + s) * n + 6 * j + t] = detJ * R->smass[i * ns + j] * A[s * 6 + t];
}

/* Stiffness Ke (3nv x 3nv) of the exact element-wise stress elimination G^T Ms^{-1} G. Because the discontinuous
   P_{k-1} stress space contains the strains of P_k velocities (constant material, affine cell), it equals the
   displacement stiffness int eps(phi_a e_c) : D eps(phi_b e_d), evaluated here from D_ab = int grad phi_a (x) grad
   phi_b:  K_ab^{cd} = lambda D_ab[c][d] + mu D_ab[d][c] + mu delta_cd tr D_ab. PhlexElementCondense computes the
   elimination itself; the two agree to round-off (checked by -phlex_check_condensation). */
void PhlexElementStiffness(const PhlexElementReferenceIntegrals *R, PetscReal E, PetscReal nu, PetscReal detJ, const PetscReal invJ[9], PetscReal *Ke)
{
  const PetscInt  nv = R->nv, n = 3 * nv;
  const PetscReal lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));

  for (PetscInt a = 0; a < nv; a++)
    for (PetscInt b = 0; b < nv; b++) {
      const PetscReal *r = &R->grad[(a * nv + b) * 9];
      PetscReal        t[9], D[9], tr;
      /* D = detJ invJ^T r invJ, r[d][e] in reference derivatives */
      for (PetscInt d = 0; d < 3; d++)
        for (PetscInt y = 0; y < 3; y++) t[d * 3 + y] = r[d * 3 + 0] * invJ[0 * 3 + y] + r[d * 3 + 1] * invJ[1 * 3 + y] + r[d * 3 + 2] * invJ[2 * 3 + y];
      for (PetscInt x = 0; x < 3; x++)
        for (PetscInt y = 0; y < 3; y++) D[x * 3 + y] = detJ * (invJ[0 * 3 + x] * t[0 * 3 + y] + invJ[1 * 3 + x] * t[1 * 3 + y] + invJ[2 * 3 + x] * t[2 * 3 + y]);
      tr = D[0] + D[4] + D[8];
      for (PetscInt c = 0; c < 3; c++)
        for (PetscInt d = 0; d < 3; d++) Ke[(3 * a + c) * n + 3 * b + d] = lambda * D[c * 3 + d] + mu * D[d * 3 + c] + (c == d ? mu * tr : 0.0);
    }
}

/* In-place Cholesky factorisation of a dense SPD n x n row-major matrix (lower triangle holds L).
   Returns 0 on success, the failing row + 1 otherwise. */
PetscInt PhlexDenseCholesky(PetscInt n, PetscReal *A)
{
  for (PetscInt j = 0; j < n; j++) {
    PetscReal d = A[j * n + j];
    for (PetscInt k = 0; k < j; k++) d -= A[j * n + k] * A[j * n + k];
    if (!(d > 0.0)) return j + 1;
    d            = PetscSqrtReal(d);
    A[j * n + j] = d;
    for (PetscInt i = j + 1; i < n; i++) {
      PetscReal s = A[i * n + j];
      for (PetscInt k = 0; k < j; k++) s -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = s / d;
    }
  }
  return 0;
}

/* Solves L L^T X = B for the m columns of the row-major n x m matrix B (in place). */
void PhlexDenseCholeskySolve(PetscInt n, const PetscReal *L, PetscInt m, PetscReal *B)
{
  for (PetscInt c = 0; c < m; c++) {
    for (PetscInt i = 0; i < n; i++) {
      PetscReal s = B[i * m + c];
      for (PetscInt k = 0; k < i; k++) s -= L[i * n + k] * B[k * m + c];
      B[i * m + c] = s / L[i * n + i];
    }
    for (PetscInt i = n - 1; i >= 0; i--) {
      PetscReal s = B[i * m + c];
      for (PetscInt k = i + 1; k < n; k++) s -= L[k * n + i] * B[k * m + c];
      B[i * m + c] = s / L[i * n + i];
    }
  }
}

/* Exact element-wise stress elimination Ke = Ge^T Mse^{-1} Ge (Ge: ns x nv). Mse is overwritten by its Cholesky
   factor; work holds ns*nv entries. Returns nonzero if Mse is not positive definite. */
PetscInt PhlexElementCondense(PetscInt ns, PetscInt nv, PetscReal *Mse, const PetscReal *Ge, PetscReal *work, PetscReal *Ke)
{
  PetscInt ierr = PhlexDenseCholesky(ns, Mse);

  if (ierr) return ierr;
  for (PetscInt i = 0; i < ns * nv; i++) work[i] = Ge[i];
  PhlexDenseCholeskySolve(ns, Mse, nv, work);
  for (PetscInt a = 0; a < nv; a++)
    for (PetscInt b = 0; b < nv; b++) {
      PetscReal s = 0.0;
      for (PetscInt j = 0; j < ns; j++) s += Ge[j * nv + a] * work[j * nv + b];
      Ke[a * nv + b] = s;
    }
  return 0;
}
