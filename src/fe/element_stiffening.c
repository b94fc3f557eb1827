/* Element kernels of the geometric stiffening option (-<body>_geometric_stiffening), on affine tetrahedra, by
   quadrature (the integrands are products of three polynomials: the rule of degree 2k is exact for k = 1, 2).
   Pure arithmetic, non-dimensional, the Voigt conventions of element.c.

   The option makes the strain of the elastic field the Green-Lagrange strain of its displacement in the body frame,
   E(u) = sym(H) + H^T H / 2 with H = Grad u and F = I + H. The stress rows become the rate of E (compatibility) and
   the velocity rows take the first Piola stress F Sigma: the coupling G(u) = int Sigma : sym(F^T Grad v) appears in
   both, once and transposed, so the interconnection stays skew and the Hamiltonian (kinetic + compliance energy)
   is unchanged: the power balance holds exactly (flexible_stiffening.c). */
#include <phlex_impl.h>

static const PetscInt VoigtPair[3][2] = {{1, 2}, {0, 2}, {0, 1}}; /* shear components yz, xz, xy */

/* physical gradients g[a][x] of the velocity nodes at quadrature point q */
static void NodeGradients(const PhlexElementBasis *V, PetscInt q, const PetscReal invJ[9], PetscReal *g)
{
  const PetscReal *d = &V->node_dphi[q * V->nnodes * 3];
  for (PetscInt a = 0; a < V->nnodes; a++)
    for (PetscInt x = 0; x < 3; x++) g[3 * a + x] = d[3 * a + 0] * invJ[0 * 3 + x] + d[3 * a + 1] * invJ[1 * 3 + x] + d[3 * a + 2] * invJ[2 * 3 + x];
}

/* H[c][x] = d w_c / d x_x of a nodal field w (3 per node) */
static void FieldGradient(PetscInt nn, const PetscReal *g, const PetscReal *w, PetscReal H[9])
{
  for (PetscInt i = 0; i < 9; i++) H[i] = 0.0;
  for (PetscInt a = 0; a < nn; a++)
    for (PetscInt c = 0; c < 3; c++)
      for (PetscInt x = 0; x < 3; x++) H[3 * c + x] += w[3 * a + c] * g[3 * a + x];
}

/* Ce (6ns x 3nv) = int psi_i E_s : sym(A^T Grad(phi_b e_c)) for the 3 x 3 field A = identity + Grad w (w NULL: A = I)
   or A = Grad w alone. The Voigt row of a normal component a is A_ca g_a, of a shear (a, e) A_ca g_e + A_ce g_a
   (twice the tensor entry, as the shear stress holds the tensor entry: Sigma : eps = sum_normal s e + 2 sum_shear s e).
   With A = F = I + Grad u it is the coupling G(u); with A = Grad v, d(G(u) v)/du (sym(Grad(du)^T Grad v)). */
static void CouplingWith(const PhlexElementBasis *V, const PhlexElementBasis *S, PetscReal detJ, const PetscReal invJ[9], const PetscReal *we, PetscBool identity, PetscReal *Ce)
{
  const PetscInt nv = V->nnodes, ns = S->nnodes, ncol = 3 * nv;
  PetscReal      g[3 * PHLEX_MAX_NODES], F[9];

  for (PetscInt i = 0; i < 6 * ns * ncol; i++) Ce[i] = 0.0;
  for (PetscInt q = 0; q < V->nq; q++) {
    const PetscReal  w   = V->weights[q] * detJ;
    const PetscReal *psi = &S->node_phi[q * ns];
    NodeGradients(V, q, invJ, g);
    if (we) FieldGradient(nv, g, we, F);
    else
      for (PetscInt k = 0; k < 9; k++) F[k] = 0.0;
    if (identity)
      for (PetscInt k = 0; k < 3; k++) F[4 * k] += 1.0;
    for (PetscInt i = 0; i < ns; i++) {
      const PetscReal wp = w * psi[i];
      for (PetscInt b = 0; b < nv; b++) {
        const PetscReal *gb = &g[3 * b];
        for (PetscInt c = 0; c < 3; c++) {
          const PetscInt col = 3 * b + c;
          for (PetscInt a = 0; a < 3; a++) Ce[(6 * i + a) * ncol + col] += wp * F[3 * c + a] * gb[a];
          for (PetscInt k = 0; k < 3; k++) {
            const PetscInt a = VoigtPair[k][0], e = VoigtPair[k][1];
            Ce[(6 * i + 3 + k) * ncol + col] += wp * (F[3 * c + a] * gb[e] + F[3 * c + e] * gb[a]);
          }
        }
      }
    }
  }
}

/* Ge (6ns x 3nv) = int psi_i E_s : sym(F^T Grad(phi_b e_c)), F = I + Grad u (u NULL: F = I, the linear coupling) */
void PhlexElementCouplingDeformed(const PhlexElementBasis *V, const PhlexElementBasis *S, PetscReal detJ, const PetscReal invJ[9], const PetscReal *ue, PetscReal *Ge)
{
  CouplingWith(V, S, detJ, invJ, ue, PETSC_TRUE, Ge);
}

/* be (6ns) = int psi_i E_s-pairing of the Green-Lagrange strain E(u) (nonlinear; else the linear strain sym H):
   normal E_aa, shear 2 E_ae. Its rate is Ge(u) v, so that Ms Sigma = be(u) is the stress a displacement u holds
   (flexible_stiffening.c). */
void PhlexElementGreenLagrange(const PhlexElementBasis *V, const PhlexElementBasis *S, PetscReal detJ, const PetscReal invJ[9], PetscBool nonlinear, const PetscReal *ue, PetscReal *be)
{
  const PetscInt nv = V->nnodes, ns = S->nnodes;
  PetscReal      g[3 * PHLEX_MAX_NODES], H[9], E[9];

  for (PetscInt i = 0; i < 6 * ns; i++) be[i] = 0.0;
  for (PetscInt q = 0; q < V->nq; q++) {
    const PetscReal  w   = V->weights[q] * detJ;
    const PetscReal *psi = &S->node_phi[q * ns];
    PetscReal        ev[6];
    NodeGradients(V, q, invJ, g);
    FieldGradient(nv, g, ue, H);
    for (PetscInt x = 0; x < 3; x++)
      for (PetscInt y = 0; y < 3; y++) {
        E[3 * x + y] = 0.5 * (H[3 * x + y] + H[3 * y + x]);
        if (nonlinear)
          for (PetscInt c = 0; c < 3; c++) E[3 * x + y] += 0.5 * H[3 * c + x] * H[3 * c + y];
      }
    for (PetscInt a = 0; a < 3; a++) ev[a] = E[4 * a];
    for (PetscInt k = 0; k < 3; k++) ev[3 + k] = 2.0 * E[3 * VoigtPair[k][0] + VoigtPair[k][1]];
    for (PetscInt i = 0; i < ns; i++)
      for (PetscInt s = 0; s < 6; s++) be[6 * i + s] += w * psi[i] * ev[s];
  }
}

/* Geometric stiffness Ke (3nv x 3nv) of a stress field se (6ns): d/du of Ge(u)^T Sigma,
   Ke[(a,c)][(b,d)] = delta_cd int g_a . Sigma g_b (the initial-stress matrix). Symmetric. */
void PhlexElementGeometricStiffness(const PhlexElementBasis *V, const PhlexElementBasis *S, PetscReal detJ, const PetscReal invJ[9], const PetscReal *se, PetscReal *Ke)
{
  const PetscInt nv = V->nnodes, ns = S->nnodes, n = 3 * nv;
  PetscReal      g[3 * PHLEX_MAX_NODES];

  for (PetscInt i = 0; i < n * n; i++) Ke[i] = 0.0;
  for (PetscInt q = 0; q < V->nq; q++) {
    const PetscReal  w   = V->weights[q] * detJ;
    const PetscReal *psi = &S->node_phi[q * ns];
    PetscReal        sv[6] = {0, 0, 0, 0, 0, 0}, T[9];
    NodeGradients(V, q, invJ, g);
    for (PetscInt i = 0; i < ns; i++)
      for (PetscInt s = 0; s < 6; s++) sv[s] += psi[i] * se[6 * i + s];
    for (PetscInt a = 0; a < 3; a++) T[4 * a] = sv[a];
    for (PetscInt k = 0; k < 3; k++) {
      const PetscInt a = VoigtPair[k][0], e = VoigtPair[k][1];
      T[3 * a + e] = T[3 * e + a] = sv[3 + k];
    }
    for (PetscInt a = 0; a < nv; a++) {
      PetscReal Tg[3];
      for (PetscInt x = 0; x < 3; x++) Tg[x] = T[3 * x + 0] * g[3 * a + 0] + T[3 * x + 1] * g[3 * a + 1] + T[3 * x + 2] * g[3 * a + 2];
      for (PetscInt b = 0; b < nv; b++) {
        const PetscReal k = w * (Tg[0] * g[3 * b + 0] + Tg[1] * g[3 * b + 1] + Tg[2] * g[3 * b + 2]);
        for (PetscInt c = 0; c < 3; c++) Ke[(3 * a + c) * n + 3 * b + c] += k;
      }
    }
  }
}

/* Je (6ns x 3nv) = d/du of Ge(u) v for a velocity field ve: the coupling of sym(Grad(du)^T Grad v), i.e. CouplingWith
   A = Grad v: normal a: g_a (Grad v)_ca, shear (a, e): g_a (Grad v)_ce + g_e (Grad v)_ca, for du = phi_b e_c, g = g_b */
void PhlexElementCouplingDerivative(const PhlexElementBasis *V, const PhlexElementBasis *S, PetscReal detJ, const PetscReal invJ[9], const PetscReal *ve, PetscReal *Je)
{
  CouplingWith(V, S, detJ, invJ, ve, PETSC_FALSE, Je);
}
