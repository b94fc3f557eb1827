/* The maps between a body's velocity and stress fields that a linear step applies, cell by cell from the element
   structure instead of assembled matrices:

     B v      = Ms^{-1} G v   the stress rate of a velocity (SNES phlexcondensed: Sigma = Sigma_p + B dv / s),
     G^T Sigma                the stress resultant in the momentum rows.

   On an affine cell the coupling is G_c[(i,s)][(b,c)] = detJ_c int psi_i E_s : Grad(phi_b e_c) (PhlexElementCoupling),
   the physical gradient moments detJ coup[i][b] invJ, and the compliance mass is Ms_c = detJ_c (smass (x) A_m)
   (PhlexElementComplianceMass). So for the stress node i of a cell
     (G v)_i = detJ e_i,  e_i = H_i = sum_b v_b (x) (invJ^T coup[i][b]) in Voigt order, symmetrized
                          (xx, yy, zz, yz, xz, xy; a shear row is H_pq + H_qp),
     (B v)_i = sum_j smass^{-1}_ij D_m e_j   (D_m = A_m^{-1}, detJ cancels),
     (G^T Sigma)_b = detJ sum_i S_i invJ^T coup[i][b]   (S_i the symmetric tensor of Sigma_i).
   A product reads the velocities, the cells' geometry and the stresses (about 25 MB at 2.2e5 velocity DOFs) instead
   of the 280 MB of B's or G's entries, and nothing is assembled or stored beyond two work vectors and the cells'
   local offsets. The condensed stiffness K = G^T Ms^{-1} G (SNES phlexreduced's residual and Jacobian) is the two in
   one pass per cell, the stress kept in the cell; a linear stage's predicted stress with its resultant, and its final
   stress, are one pass each (PhlexStressMapsPredict, PhlexStressMapsCorrect), and the monitor's strain energy 1/2
   Sigma^T Ms Sigma comes from the same structure (PhlexFlexibleStrainEnergyLocal). The kernels run four cells at once
   and move whole vectors where they can (a node's three velocities, four consecutive cells' stresses, by 4 x 4
   transposes; one material's stiffness as scalars), the P2/P1 shape compiled with its sizes as constants: the same
   operations in the same order as cell by cell (BENCHMARKS.md sections 22 and 30). The sums are not those of the assembled
   products: results differ from them in the last bits (BENCHMARKS.md section 18). For the body's undeformed geometry only: geometric stiffening's G(u) is assembled
   (flexible_stiffening.c). */
#include <phlex_impl.h>
#include <petscblaslapack.h>

/* the kernels' whole-vector moves below (4 x 4 transposes with GCC's __builtin_shuffle, lanes of doubles): GCC, real
   double precision; elsewhere entry by entry */
#if defined(__GNUC__) && !defined(__clang__) && !defined(PETSC_USE_COMPLEX) && defined(PETSC_USE_REAL_DOUBLE)
  #define PHLEX_WHOLE_MOVES 1
#else
  #define PHLEX_WHOLE_MOVES 0
#endif

/* A^{-1} of a small dense matrix (row-major n x n), in place, by LAPACK */
static PetscErrorCode InvertSmall(PetscInt n, PetscReal *A, const char *what, const char *body)
{
  PetscBLASInt bn, info, ipiv[6], lwork = 36;
  PetscReal    work[36];

  PetscFunctionBeginUser;
  PetscCheck(n <= 6, PETSC_COMM_SELF, PETSC_ERR_PLIB, "body %s: %s of size %" PetscInt_FMT " > 6", body, what, n);
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&bn, &bn, A, &bn, ipiv, &info));
  PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "body %s: %s is singular (LAPACK getrf info %d)", body, what, (int)info);
  PetscCallBLAS("LAPACKgetri", LAPACKgetri_(&bn, A, &bn, ipiv, work, &lwork, &info));
  PetscCheck(info == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "body %s: %s could not be inverted (LAPACK getri info %d)", body, what, (int)info);
  PetscFunctionReturn(0);
}

/* the stiffness of every material, smass^{-1}, the cells' local velocity offsets and the local work vectors, once */
static PetscErrorCode StressMapsSetUp(PhlexFlexible b)
{
  const PetscInt nn = b->ref.ns;

  PetscFunctionBeginUser;
  if (b->smap_ready) PetscFunctionReturn(0);
  PetscCheck(nn <= 4 && b->ref.nv <= PHLEX_MAX_NODES, b->comm, PETSC_ERR_SUP, "body %s: the cell-by-cell stress maps take at most 4 stress nodes per cell (P1 stress), not %" PetscInt_FMT, b->name, nn);
  /* a transposed inverse is the inverse of the transpose: A and smass are symmetric, so row- or column-major alike */
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    PetscCall(PetscArraycpy(b->stiffness[m], b->compliance[m], 36));
    PetscCall(InvertSmall(6, b->stiffness[m], "a material's compliance", b->name));
  }
  PetscCall(PetscArraycpy(b->smass_inv, b->ref.smass, nn * nn));
  PetscCall(InvertSmall(nn, b->smass_inv, "the stress basis's mass", b->name));
  PetscCall(PhlexFlexibleSetUpLocalDofs(b));
  {
    /* the local velocities in storage one entry longer than the field (zero: the constrained entries stay so), so that
       the kernels may read a node's three velocities as four consecutive entries (the fourth unused); and whether every
       node's three are consecutive */
    Vec      tmpl;
    PetscInt nloc, ncv = (b->cEnd - b->cStart) * b->nb_v;
    PetscCall(DMGetLocalVector(b->dm, &tmpl));
    PetscCall(VecGetLocalSize(tmpl, &nloc));
    PetscCall(DMRestoreLocalVector(b->dm, &tmpl));
    PetscCall(PetscCalloc1(nloc + 1, &b->smap_varray));
    PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, nloc, b->smap_varray, &b->smap_vloc));
    PetscCall(VecDuplicate(b->smap_vloc, &b->smap_floc));
    b->smap_vnodes = PHLEX_WHOLE_MOVES && b->nb_v % 3 == 0 ? PETSC_TRUE : PETSC_FALSE;
    for (PetscInt k = 0; k < ncv && b->smap_vnodes; k += 3)
      if (b->cell_vloc[k + 1] != b->cell_vloc[k] + 1 || b->cell_vloc[k + 2] != b->cell_vloc[k] + 2) b->smap_vnodes = PETSC_FALSE;
    PetscCall(PetscInfo(NULL, "body %s: the stress maps read the velocities %s\n", b->name, b->smap_vnodes ? "node by node" : "entry by entry"));
  }
  b->smap_ready = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* The cell kernels run on PHLEX_LANES cells at once, one cell per lane of a vector of reals (GCC's vector extension;
   one lane without it), so that the arithmetic of four cells shares each instruction. Every lane does the operations
   of the one-cell code in the same order (no multiply-add fused, no sum across lanes): the same bits. The last batch
   of a rank repeats its last cell in the unused lanes and keeps only the used ones. */
#if defined(__GNUC__) && !defined(PETSC_USE_COMPLEX)
  #define PHLEX_LANES 4
typedef PetscReal PhlexLane __attribute__((vector_size(PHLEX_LANES * sizeof(PetscReal))));
  #define LANE(x, l)   ((x)[l])
  #define CELL_INLINE  static inline __attribute__((always_inline))
#else
  #define PHLEX_LANES 1
typedef PetscReal PhlexLane;
  #define LANE(x, l)   (x)
  #define CELL_INLINE  static inline
#endif
#define LANE_ZERO ((PhlexLane){0}) /* +0 in every lane */
/* a loop unrolled n times (wholly where its count is a constant up to n: the P2/P1 kernels below) */
#if defined(__GNUC__) && !defined(__clang__)
  #define PHLEX_PRAGMA(x) _Pragma(#x)
  #define UNROLL(n)       PHLEX_PRAGMA(GCC unroll n)
#else
  #define UNROLL(n)
#endif

/* the cells' geometry, materials and stress offsets, gathered lane by lane for the cells c0, c0 + 1, ... (the last
   cell repeated past ncell), and their material matrices (the stiffness; the compliance for the strain energy) where
   asked for. Where all lanes' cells have one material (most batches), its matrix is read as scalars (Ds) instead of
   gathered into lanes: a product with a scalar is the same in every lane as with its copies. Where the
   four cells' stresses lie one after another (contiguous), they move between the field and the lanes by 4 x 4
   transposes of whole vectors instead of entry by entry: the same values. */
typedef struct {
  PhlexLane        detJ, invJ[9], D[36];
  const PetscReal *Ds;
  PetscInt         cell[PHLEX_LANES], used;
  PetscBool        contiguous;
} CellBatch;

CELL_INLINE void GatherBatch(PhlexFlexible b, PetscInt nn, PetscInt c0, PetscInt ncell, PetscReal (*mats)[36], PetscBool inverse, CellBatch *cb)
{
  const PetscInt ns6 = 6 * nn;
  PetscBool      uniform = PETSC_TRUE;

  cb->used       = PetscMin(PHLEX_LANES, ncell - c0);
  cb->contiguous = cb->used == PHLEX_LANES ? PETSC_TRUE : PETSC_FALSE;
  for (PetscInt l = 0; l < PHLEX_LANES; l++) {
    const PetscInt   c = PetscMin(c0 + l, ncell - 1);
    const PetscReal *g = &b->cell_geom[10 * c];
    cb->cell[l]        = c;
    LANE(cb->detJ, l)  = g[0];
    if (inverse)
      for (PetscInt q = 0; q < 9; q++) LANE(cb->invJ[q], l) = g[1 + q];
    if (b->cell_soff[c] != b->cell_soff[cb->cell[0]] + ns6 * l) cb->contiguous = PETSC_FALSE;
    if (b->cell_material[c] != b->cell_material[cb->cell[0]]) uniform = PETSC_FALSE;
  }
  cb->Ds = NULL;
  if (!mats) return;
  if (uniform) {
    cb->Ds = mats[b->cell_material[cb->cell[0]]];
    return;
  }
  for (PetscInt l = 0; l < PHLEX_LANES; l++) {
    const PetscReal *D = mats[b->cell_material[cb->cell[l]]];
    for (PetscInt q = 0; q < 36; q++) LANE(cb->D[q], l) = D[q];
  }
}

/* entry q of a material matrix (scalars Ds if the batch's cells share it, else lanes D) times x (a macro: a function
   returning a vector would change the baseline clone's ABI) */
#define MaterialTimes(Ds, D, q, x) ((Ds) ? (Ds)[q] * (x) : (D)[q] * (x))

#if PHLEX_WHOLE_MOVES
typedef long long PhlexLaneIndex __attribute__((vector_size(PHLEX_LANES * sizeof(long long))));
/* out[j] = (r[0][j], r[1][j], r[2][j], r[3][j]): a 4 x 4 transpose, its own inverse (vectors passed by address: by
   value they would change the baseline clone's ABI) */
CELL_INLINE void Transpose4(const PhlexLane *r, PhlexLane *out)
{
  const PhlexLane t0 = __builtin_shuffle(r[0], r[1], (PhlexLaneIndex){0, 4, 2, 6});
  const PhlexLane t1 = __builtin_shuffle(r[0], r[1], (PhlexLaneIndex){1, 5, 3, 7});
  const PhlexLane t2 = __builtin_shuffle(r[2], r[3], (PhlexLaneIndex){0, 4, 2, 6});
  const PhlexLane t3 = __builtin_shuffle(r[2], r[3], (PhlexLaneIndex){1, 5, 3, 7});
  out[0]             = __builtin_shuffle(t0, t2, (PhlexLaneIndex){0, 1, 4, 5});
  out[1]             = __builtin_shuffle(t1, t3, (PhlexLaneIndex){0, 1, 4, 5});
  out[2]             = __builtin_shuffle(t0, t2, (PhlexLaneIndex){2, 3, 6, 7});
  out[3]             = __builtin_shuffle(t1, t3, (PhlexLaneIndex){2, 3, 6, 7});
}
/* lanes x[k] = (p[k], p[n + k], p[2 n + k], p[3 n + k]) for k below 4 floor(n / 4), which it returns */
CELL_INLINE PetscInt LoadTransposed(const PetscReal *p, PetscInt n, PhlexLane *x)
{
  PetscInt k = 0;
  for (; k + 4 <= n; k += 4) {
    PhlexLane r[4];
    for (PetscInt l = 0; l < 4; l++) memcpy(&r[l], p + l * n + k, sizeof(r[l]));
    Transpose4(r, x + k);
  }
  return k;
}
/* p[l n + k] = lane l of x[k] for k below 4 floor(n / 4), which it returns */
CELL_INLINE PetscInt StoreTransposed(const PhlexLane *x, PetscInt n, PetscReal *p)
{
  PetscInt k = 0;
  for (; k + 4 <= n; k += 4) {
    PhlexLane r[4];
    Transpose4(x + k, r);
    for (PetscInt l = 0; l < 4; l++) memcpy(p + l * n + k, &r[l], sizeof(r[l]));
  }
  return k;
}
#endif

/* y = B v for the cells' stress blocks: ve the cells' velocities (3 per node), y their stresses (6 per stress node);
   the gradient's nine sums in variables of their own (registers), each summed over the nodes in order */
CELL_INLINE void CellStressRate(PetscInt nv, PetscInt nn, const PetscReal *coup, const PhlexLane *invJ, const PetscReal *Ds, const PhlexLane *D, const PetscReal *smass_inv, const PhlexLane *ve, PhlexLane *y)
{
  PhlexLane e[4][6], De[4][6];

  UNROLL(4)
  for (PetscInt i = 0; i < nn; i++) {
    const PetscReal *ci  = &coup[i * nv * 3];
    PhlexLane        h00 = LANE_ZERO, h01 = LANE_ZERO, h02 = LANE_ZERO, h10 = LANE_ZERO, h11 = LANE_ZERO, h12 = LANE_ZERO, h20 = LANE_ZERO, h21 = LANE_ZERO, h22 = LANE_ZERO;
    PhlexLane        H[3][3];
    UNROLL(10)
    for (PetscInt bnode = 0; bnode < nv; bnode++) {
      const PetscReal c0 = ci[3 * bnode], c1 = ci[3 * bnode + 1], c2 = ci[3 * bnode + 2];
      const PhlexLane v0 = ve[3 * bnode], v1 = ve[3 * bnode + 1], v2 = ve[3 * bnode + 2];
      h00 += v0 * c0;
      h01 += v0 * c1;
      h02 += v0 * c2;
      h10 += v1 * c0;
      h11 += v1 * c1;
      h12 += v1 * c2;
      h20 += v2 * c0;
      h21 += v2 * c1;
      h22 += v2 * c2;
    }
    for (PetscInt x = 0; x < 3; x++) {
      H[0][x] = h00 * invJ[0 * 3 + x] + h01 * invJ[1 * 3 + x] + h02 * invJ[2 * 3 + x];
      H[1][x] = h10 * invJ[0 * 3 + x] + h11 * invJ[1 * 3 + x] + h12 * invJ[2 * 3 + x];
      H[2][x] = h20 * invJ[0 * 3 + x] + h21 * invJ[1 * 3 + x] + h22 * invJ[2 * 3 + x];
    }
    e[i][0] = H[0][0];
    e[i][1] = H[1][1];
    e[i][2] = H[2][2];
    e[i][3] = H[1][2] + H[2][1];
    e[i][4] = H[0][2] + H[2][0];
    e[i][5] = H[0][1] + H[1][0];
    for (PetscInt s = 0; s < 6; s++) De[i][s] = MaterialTimes(Ds, D, s * 6 + 0, e[i][0]) + MaterialTimes(Ds, D, s * 6 + 1, e[i][1]) + MaterialTimes(Ds, D, s * 6 + 2, e[i][2]) + MaterialTimes(Ds, D, s * 6 + 3, e[i][3]) + MaterialTimes(Ds, D, s * 6 + 4, e[i][4]) + MaterialTimes(Ds, D, s * 6 + 5, e[i][5]);
  }
  UNROLL(4)
  for (PetscInt i = 0; i < nn; i++)
    for (PetscInt s = 0; s < 6; s++) {
      PhlexLane sum = LANE_ZERO;
      UNROLL(4)
      for (PetscInt j = 0; j < nn; j++) sum += smass_inv[i * nn + j] * De[j][s];
      y[6 * i + s] = sum;
    }
}

/* fe = G_c^T Sigma_c for the cells: sigma their stresses (6 per stress node), fe their velocity rows (3 per node); each
   row summed over the stress nodes in order, in a variable of its own */
CELL_INLINE void CellResultant(PetscInt nv, PetscInt nn, const PetscReal *coup, const PhlexLane *detJ, const PhlexLane *invJ, const PhlexLane *sigma, PhlexLane *fe)
{
  PhlexLane T[4][3][3]; /* detJ S_i invJ^T per stress node i */

  UNROLL(4)
  for (PetscInt i = 0; i < nn; i++) {
    const PhlexLane *si      = sigma + 6 * i;
    const PhlexLane  S[3][3] = {
      {si[0], si[5], si[4]},
      {si[5], si[1], si[3]},
      {si[4], si[3], si[2]}
    };
    for (PetscInt a = 0; a < 3; a++)
      for (PetscInt y = 0; y < 3; y++) T[i][a][y] = *detJ * (S[a][0] * invJ[y * 3 + 0] + S[a][1] * invJ[y * 3 + 1] + S[a][2] * invJ[y * 3 + 2]);
  }
  UNROLL(10)
  for (PetscInt bnode = 0; bnode < nv; bnode++)
    for (PetscInt a = 0; a < 3; a++) {
      PhlexLane sum = LANE_ZERO;
      UNROLL(4)
      for (PetscInt i = 0; i < nn; i++) {
        const PetscReal *cb = &coup[(i * nv + bnode) * 3];
        sum += T[i][a][0] * cb[0] + T[i][a][1] * cb[1] + T[i][a][2] * cb[2];
      }
      fe[3 * bnode + a] = sum;
    }
}

/* the batch's velocities from the local vector va: node by node, by a 4 x 4 transpose of the four cells' (x, y, z, next)
   where each node's three are consecutive (b->smap_vnodes), else entry by entry. va must be b->smap_vloc's array,
   whose storage has one entry more than the field (the last node's fourth read) */
CELL_INLINE void GatherVelocities(PhlexFlexible b, PetscInt nv, const CellBatch *cb, const PetscScalar *va, PhlexLane *ve)
{
#if PHLEX_WHOLE_MOVES
  if (b->smap_vnodes) {
    const PetscInt *loc[4];
    for (PetscInt l = 0; l < 4; l++) loc[l] = &b->cell_vloc[cb->cell[l] * 3 * nv];
    for (PetscInt bnode = 0; bnode < nv; bnode++) {
      PhlexLane r[4], t[4];
      for (PetscInt l = 0; l < 4; l++) memcpy(&r[l], va + loc[l][3 * bnode], sizeof(r[l]));
      Transpose4(r, t);
      ve[3 * bnode]     = t[0];
      ve[3 * bnode + 1] = t[1];
      ve[3 * bnode + 2] = t[2];
    }
    return;
  }
#endif
  for (PetscInt l = 0; l < PHLEX_LANES; l++) {
    const PetscInt *loc = &b->cell_vloc[cb->cell[l] * 3 * nv];
    for (PetscInt k = 0; k < 3 * nv; k++) LANE(ve[k], l) = PetscRealPart(va[loc[k]]);
  }
}

/* the used lanes' velocity rows added into the local vector fa, cell after cell */
CELL_INLINE void ScatterResultants(PhlexFlexible b, PetscInt nv, const CellBatch *cb, const PhlexLane *fe, PetscScalar *fa)
{
  for (PetscInt l = 0; l < cb->used; l++) {
    const PetscInt *loc = &b->cell_vloc[cb->cell[l] * 3 * nv];
    for (PetscInt k = 0; k < 3 * nv; k++) fa[loc[k]] += LANE(fe[k], l);
  }
}

/* the batch of cells from c0: its geometry, materials and velocities (va local), and its stress rates y = B v */
CELL_INLINE void BatchStressRate(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt c0, PetscInt ncell, const PetscScalar *va, CellBatch *cb, PhlexLane *y)
{
  PhlexLane ve[3 * PHLEX_MAX_NODES];
  GatherBatch(b, nn, c0, ncell, b->stiffness, PETSC_TRUE, cb);
  GatherVelocities(b, nv, cb, va, ve);
  CellStressRate(nv, nn, b->ref.coup, cb->invJ, cb->Ds, cb->D, b->smass_inv, ve, y);
}

/* the batch's stresses from the rank's stress field sa (first entry rstart) */
CELL_INLINE void GatherStresses(PhlexFlexible b, PetscInt nn, const CellBatch *cb, PetscInt rstart, const PetscScalar *sa, PhlexLane *sigma)
{
  const PetscInt n = 6 * nn;
  PetscInt       k0 = 0;

#if PHLEX_WHOLE_MOVES
  if (cb->contiguous) k0 = LoadTransposed(sa + (b->cell_soff[cb->cell[0]] - rstart), n, sigma);
#endif
  for (PetscInt l = 0; l < PHLEX_LANES; l++) {
    const PetscScalar *sc = sa + (b->cell_soff[cb->cell[l]] - rstart);
    for (PetscInt k = k0; k < n; k++) LANE(sigma[k], l) = PetscRealPart(sc[k]);
  }
}

/* the used lanes' stresses into the rank's stress field sa (first entry rstart) */
CELL_INLINE void StoreStresses(PhlexFlexible b, PetscInt nn, const CellBatch *cb, PetscInt rstart, const PhlexLane *sigma, PetscScalar *sa)
{
  const PetscInt n = 6 * nn;
  PetscInt       k0 = 0;

#if PHLEX_WHOLE_MOVES
  if (cb->contiguous) k0 = StoreTransposed(sigma, n, sa + (b->cell_soff[cb->cell[0]] - rstart));
#endif
  for (PetscInt l = 0; l < cb->used; l++) {
    PetscScalar *sc = sa + (b->cell_soff[cb->cell[l]] - rstart);
    for (PetscInt k = k0; k < n; k++) sc[k] = LANE(sigma[k], l);
  }
}

/* the batch's stresses s0 + a B v (s0 from the rank's stress field s0a, first entry rstart; va the local velocities),
   each entry as VecWAXPY forms it from B v */
CELL_INLINE void BatchStressUpdate(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt c0, PetscInt ncell, PetscInt rstart, const PetscScalar *va, const PetscScalar *s0a, PetscReal a, CellBatch *cb, PhlexLane *sigma)
{
  PhlexLane y[24];
  BatchStressRate(b, nv, nn, c0, ncell, va, cb, y);
  GatherStresses(b, nn, cb, rstart, s0a, sigma);
  for (PetscInt k = 0; k < 6 * nn; k++) sigma[k] = sigma[k] + a * y[k];
}

/* The passes over a rank's cells below are written once for the element's shape (nv velocity nodes, nn stress nodes)
   and compiled twice (SHAPE_DISPATCH): for P2 velocity with P1 stress as constants, so that the loops over the nodes
   unroll and the sums stay in registers, and for any shape. The same operations in the same order either way. */
#define SHAPE_DISPATCH(b, call, ...) \
  do { \
    if ((b)->ref.nv == 10 && (b)->ref.ns == 4) call(b, 10, 4, __VA_ARGS__); \
    else call(b, (b)->ref.nv, (b)->ref.ns, __VA_ARGS__); \
  } while (0)

/* ya (the rank's stress field, first entry rstart) = B v over the rank's cells, va the local velocities */
CELL_INLINE void StressRateShape(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt rstart, const PetscScalar *va, PetscScalar *ya)
{
  const PetscInt ncell = b->cEnd - b->cStart;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    CellBatch cb;
    PhlexLane y[24];
    BatchStressRate(b, nv, nn, c0, ncell, va, &cb, y);
    StoreStresses(b, nn, &cb, rstart, y, ya);
  }
}
PHLEX_KERNEL_CLONES static void StressRateCells(PhlexFlexible b, PetscInt rstart, const PetscScalar *va, PetscScalar *ya)
{
  SHAPE_DISPATCH(b, StressRateShape, rstart, va, ya);
}

/* fa (local velocity rows) += G^T Sigma over the rank's cells, sa the rank's stress field (first entry rstart) */
CELL_INLINE void ResultantShape(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt rstart, const PetscScalar *sa, PetscScalar *fa)
{
  const PetscInt ncell = b->cEnd - b->cStart;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    CellBatch cb;
    PhlexLane sigma[24], fe[3 * PHLEX_MAX_NODES];
    GatherBatch(b, nn, c0, ncell, NULL, PETSC_TRUE, &cb);
    GatherStresses(b, nn, &cb, rstart, sa, sigma);
    CellResultant(nv, nn, b->ref.coup, &cb.detJ, cb.invJ, sigma, fe);
    ScatterResultants(b, nv, &cb, fe, fa);
  }
}
PHLEX_KERNEL_CLONES static void ResultantCells(PhlexFlexible b, PetscInt rstart, const PetscScalar *sa, PetscScalar *fa)
{
  SHAPE_DISPATCH(b, ResultantShape, rstart, sa, fa);
}

/* fa (local velocity rows) += G^T Ms^{-1} G v over the rank's cells, va the local velocities */
CELL_INLINE void CondensedStiffnessShape(PhlexFlexible b, PetscInt nv, PetscInt nn, const PetscScalar *va, PetscScalar *fa)
{
  const PetscInt ncell = b->cEnd - b->cStart;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    CellBatch cb;
    PhlexLane sigma[24], fe[3 * PHLEX_MAX_NODES];
    BatchStressRate(b, nv, nn, c0, ncell, va, &cb, sigma);
    CellResultant(nv, nn, b->ref.coup, &cb.detJ, cb.invJ, sigma, fe);
    ScatterResultants(b, nv, &cb, fe, fa);
  }
}
PHLEX_KERNEL_CLONES static void CondensedStiffnessCells(PhlexFlexible b, const PetscScalar *va, PetscScalar *fa)
{
  SHAPE_DISPATCH(b, CondensedStiffnessShape, va, fa);
}

/* spa = s0a + a B v and fa (local velocity rows) += G^T spa over the rank's cells (the stress fields' first entry
   rstart): the stage's predicted stress and its resultant in one pass. Each entry is s0 + a (B v) as VecWAXPY forms it,
   and the resultant reads that entry: the bytes of the three passes B v, VecWAXPY, G^T */
CELL_INLINE void PredictShape(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt rstart, const PetscScalar *va, const PetscScalar *s0a, PetscReal a, PetscScalar *spa, PetscScalar *fa)
{
  const PetscInt ncell = b->cEnd - b->cStart;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    CellBatch cb;
    PhlexLane sigma[24], fe[3 * PHLEX_MAX_NODES];
    BatchStressUpdate(b, nv, nn, c0, ncell, rstart, va, s0a, a, &cb, sigma);
    StoreStresses(b, nn, &cb, rstart, sigma, spa);
    CellResultant(nv, nn, b->ref.coup, &cb.detJ, cb.invJ, sigma, fe);
    ScatterResultants(b, nv, &cb, fe, fa);
  }
}
PHLEX_KERNEL_CLONES static void PredictCells(PhlexFlexible b, PetscInt rstart, const PetscScalar *va, const PetscScalar *s0a, PetscReal a, PetscScalar *spa, PetscScalar *fa)
{
  SHAPE_DISPATCH(b, PredictShape, rstart, va, s0a, a, spa, fa);
}

/* sa = spa + a B v over the rank's cells (the stress fields' first entry rstart), as VecWAXPY forms it from B v: the
   bytes of the two passes */
CELL_INLINE void CorrectShape(PhlexFlexible b, PetscInt nv, PetscInt nn, PetscInt rstart, const PetscScalar *va, const PetscScalar *spa, PetscReal a, PetscScalar *sa)
{
  const PetscInt ncell = b->cEnd - b->cStart;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    CellBatch cb;
    PhlexLane sigma[24];
    BatchStressUpdate(b, nv, nn, c0, ncell, rstart, va, spa, a, &cb, sigma);
    StoreStresses(b, nn, &cb, rstart, sigma, sa);
  }
}
PHLEX_KERNEL_CLONES static void CorrectCells(PhlexFlexible b, PetscInt rstart, const PetscScalar *va, const PetscScalar *spa, PetscReal a, PetscScalar *sa)
{
  SHAPE_DISPATCH(b, CorrectShape, rstart, va, spa, a, sa);
}

/* the energies 1/2 detJ_c sum_ij smass_ij s_i . A_m s_j of the batch's cells (PhlexFlexibleStrainEnergyLocal); the
   compliance A_m as scalars As where the cells share it, else lanes A */
CELL_INLINE void CellStrainEnergy(PetscInt nn, const PetscReal *smass, const PetscReal *As, const PhlexLane *A, const PhlexLane *sc, PhlexLane *e)
{
  *e = LANE_ZERO;
  UNROLL(4)
  for (PetscInt i = 0; i < nn; i++) {
    const PhlexLane *si = sc + 6 * i;
    PhlexLane        t[6]; /* sum_j smass_ij s_j */
    for (PetscInt k = 0; k < 6; k++) t[k] = LANE_ZERO;
    UNROLL(4)
    for (PetscInt j = 0; j < nn; j++)
      for (PetscInt k = 0; k < 6; k++) t[k] += smass[i * nn + j] * sc[6 * j + k];
    for (PetscInt k = 0; k < 6; k++) {
      PhlexLane Asi = LANE_ZERO;
      if (As)
        for (PetscInt l = 0; l < 6; l++) Asi += As[k * 6 + l] * si[l];
      else
        for (PetscInt l = 0; l < 6; l++) Asi += A[k * 6 + l] * si[l];
      *e += t[k] * Asi;
    }
  }
}

/* sum over the rank's cells of detJ_c e_c, added cell after cell (sa the rank's stress field, first entry rstart) */
CELL_INLINE PetscReal StrainEnergyShape(PhlexFlexible b, PetscInt nn, PetscInt rstart, const PetscScalar *sa)
{
  const PetscInt ncell = b->cEnd - b->cStart;
  PetscReal      local = 0;

  for (PetscInt c0 = 0; c0 < ncell; c0 += PHLEX_LANES) {
    PhlexLane sc[24], e, de;
    CellBatch cb;
    GatherBatch(b, nn, c0, ncell, b->compliance, PETSC_FALSE, &cb);
    GatherStresses(b, nn, &cb, rstart, sa, sc);
    CellStrainEnergy(nn, b->ref.smass, cb.Ds, cb.D, sc, &e);
    de = cb.detJ * e;
    for (PetscInt l = 0; l < cb.used; l++) local += LANE(de, l);
  }
  return local;
}
PHLEX_KERNEL_CLONES static PetscReal StrainEnergyCells(PhlexFlexible b, PetscInt rstart, const PetscScalar *sa)
{
  return b->ref.ns == 4 ? StrainEnergyShape(b, 4, rstart, sa) : StrainEnergyShape(b, b->ref.ns, rstart, sa);
}

/* the flops of one cell's stress rate and of one cell's resultant (PetscLogFlops) */
static inline PetscLogDouble RateFlops(PetscInt nv, PetscInt nn)
{
  return (2.0 * 9 * nv + 2.0 * 27 + 3 + 2.0 * 36 + 2.0 * 6 * nn) * nn;
}
static inline PetscLogDouble ResultantFlops(PetscInt nv, PetscInt nn)
{
  return (2.0 * 27 + 2.0 * 9 * nv) * nn;
}

/* a product's start: the body behind the shell, set up, the log event begun */
static PetscErrorCode MapBegin(Mat A, PhlexFlexible *b)
{
  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, b));
  PetscCall(StressMapsSetUp(*b));
  PetscCall(PetscLogEventBegin(PHLEX_StressMaps, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* the velocities of the rank's cells, ghosts included, into b->smap_vloc */
static PetscErrorCode VelocitiesToLocal(PhlexFlexible b, Vec v)
{
  PetscFunctionBeginUser;
  PetscCall(DMGlobalToLocalBegin(b->dm, v, INSERT_VALUES, b->smap_vloc));
  PetscCall(DMGlobalToLocalEnd(b->dm, v, INSERT_VALUES, b->smap_vloc));
  PetscFunctionReturn(0);
}

/* f = the cells' sums in b->smap_floc, added on their owners (the constrained rows of the local vector are not in f) */
static PetscErrorCode ResultantsToGlobal(PhlexFlexible b, Vec f)
{
  PetscFunctionBeginUser;
  PetscCall(VecSet(f, 0.0));
  PetscCall(DMLocalToGlobalBegin(b->dm, b->smap_floc, ADD_VALUES, f));
  PetscCall(DMLocalToGlobalEnd(b->dm, b->smap_floc, ADD_VALUES, f));
  PetscFunctionReturn(0);
}

/* each application of a map is a loop over the rank's cells: outside the time steps (a conversion to AIJ applies it
   once per column, a solver many times) it checks the interrupt flag first (issue 43 item 1; PhlexProgressCheck);
   inside them it costs one test */
static PetscErrorCode StressMapsCheck(PhlexFlexible b)
{
  char what[PHLEX_NAME_LEN + 32];

  PetscFunctionBeginUser;
  if (PhlexProgressInSteps()) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(what, sizeof(what), "stress maps of body %s", b->name));
  PetscCall(PhlexProgressCheck(b->comm, what));
  PetscFunctionReturn(0);
}

/* MatMult of the shell B: y (stress field) = Ms^{-1} G v (v velocity field) */

static PetscErrorCode MatMult_StressRate(Mat A, Vec v, Vec y)
{
  PhlexFlexible      b;
  PetscInt           nv, nn, rstart;
  const PetscScalar *va;
  PetscScalar       *ya;

  PetscFunctionBeginUser;
  PetscCall(MapBegin(A, &b));
  PetscCall(StressMapsCheck(b));
  nv = b->ref.nv;
  nn = b->ref.ns;
  PetscCall(VelocitiesToLocal(b, v));
  PetscCall(VecGetOwnershipRange(y, &rstart, NULL));
  PetscCall(VecGetArrayRead(b->smap_vloc, &va));
  PetscCall(VecGetArrayWrite(y, &ya));
  StressRateCells(b, rstart, va, ya);
  PetscCall(VecRestoreArrayWrite(y, &ya));
  PetscCall(VecRestoreArrayRead(b->smap_vloc, &va));
  PetscCall(PetscLogFlops(RateFlops(nv, nn) * (b->cEnd - b->cStart)));
  PetscCall(PetscLogEventEnd(PHLEX_StressMaps, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* MatMult of the shell G^T: f (velocity field) = G^T Sigma (Sigma stress field) */
static PetscErrorCode MatMult_Resultant(Mat A, Vec sigma, Vec f)
{
  PhlexFlexible      b;
  PetscInt           nv, nn, rstart;
  const PetscScalar *sa;
  PetscScalar       *fa;

  PetscFunctionBeginUser;
  PetscCall(MapBegin(A, &b));
  PetscCall(StressMapsCheck(b));
  nv = b->ref.nv;
  nn = b->ref.ns;
  PetscCall(VecSet(b->smap_floc, 0.0));
  PetscCall(VecGetOwnershipRange(sigma, &rstart, NULL));
  PetscCall(VecGetArrayRead(sigma, &sa));
  PetscCall(VecGetArray(b->smap_floc, &fa));
  ResultantCells(b, rstart, sa, fa);
  PetscCall(VecRestoreArray(b->smap_floc, &fa));
  PetscCall(VecRestoreArrayRead(sigma, &sa));
  PetscCall(ResultantsToGlobal(b, f));
  PetscCall(PetscLogFlops(ResultantFlops(nv, nn) * (b->cEnd - b->cStart)));
  PetscCall(PetscLogEventEnd(PHLEX_StressMaps, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* MatMult of the shell K: y (velocity field) = G^T Ms^{-1} G v, the condensed stiffness, cell by cell (Ms is block
   diagonal per cell, so K v sums G_c^T (B v)_c over the cells): the arithmetic of B then G^T, without the stress
   field in between */
static PetscErrorCode MatMult_CondensedStiffness(Mat A, Vec v, Vec y)
{
  PhlexFlexible      b;
  PetscInt           nv, nn;
  const PetscScalar *va;
  PetscScalar       *fa;

  PetscFunctionBeginUser;
  PetscCall(MapBegin(A, &b));
  PetscCall(StressMapsCheck(b));
  nv = b->ref.nv;
  nn = b->ref.ns;
  PetscCall(VelocitiesToLocal(b, v));
  PetscCall(VecSet(b->smap_floc, 0.0));
  PetscCall(VecGetArrayRead(b->smap_vloc, &va));
  PetscCall(VecGetArray(b->smap_floc, &fa));
  CondensedStiffnessCells(b, va, fa);
  PetscCall(VecRestoreArray(b->smap_floc, &fa));
  PetscCall(VecRestoreArrayRead(b->smap_vloc, &va));
  PetscCall(ResultantsToGlobal(b, y));
  PetscCall(PetscLogFlops((RateFlops(nv, nn) + ResultantFlops(nv, nn)) * (b->cEnd - b->cStart)));
  PetscCall(PetscLogEventEnd(PHLEX_StressMaps, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexStressMapsPredict - with B a body's cell-by-cell stress rate map (PhlexFlexibleCreateStressMaps): the predicted
  stress sp = s0 + a B v and its resultant r = G^T sp in one pass over the cells (the bytes of MatMult with B,
  VecWAXPY and MatMult with the resultant map)

  Collective
@*/
PetscErrorCode PhlexStressMapsPredict(Mat B, Vec v, Vec s0, PetscReal a, Vec sp, Vec r)
{
  PhlexFlexible      b;
  PetscInt           rstart;
  const PetscScalar *va, *s0a;
  PetscScalar       *spa, *fa;

  PetscFunctionBeginUser;
  PetscCall(MapBegin(B, &b));
  PetscCall(VelocitiesToLocal(b, v));
  PetscCall(VecSet(b->smap_floc, 0.0));
  PetscCall(VecGetOwnershipRange(sp, &rstart, NULL));
  PetscCall(VecGetArrayRead(b->smap_vloc, &va));
  PetscCall(VecGetArrayRead(s0, &s0a));
  PetscCall(VecGetArrayWrite(sp, &spa));
  PetscCall(VecGetArray(b->smap_floc, &fa));
  PredictCells(b, rstart, va, s0a, a, spa, fa);
  PetscCall(VecRestoreArray(b->smap_floc, &fa));
  PetscCall(VecRestoreArrayWrite(sp, &spa));
  PetscCall(VecRestoreArrayRead(s0, &s0a));
  PetscCall(VecRestoreArrayRead(b->smap_vloc, &va));
  PetscCall(ResultantsToGlobal(b, r));
  PetscCall(PetscLogFlops((RateFlops(b->ref.nv, b->ref.ns) + 2.0 * 6 * b->ref.ns + ResultantFlops(b->ref.nv, b->ref.ns)) * (b->cEnd - b->cStart)));
  PetscCall(PetscLogEventEnd(PHLEX_StressMaps, B, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexStressMapsCorrect - with B a body's cell-by-cell stress rate map: the stress s = sp + a B v in one pass over the
  cells (the bytes of MatMult with B and VecWAXPY)

  Collective
@*/
PetscErrorCode PhlexStressMapsCorrect(Mat B, Vec v, Vec sp, PetscReal a, Vec s)
{
  PhlexFlexible      b;
  PetscInt           rstart;
  const PetscScalar *va, *spa;
  PetscScalar       *sa;

  PetscFunctionBeginUser;
  PetscCall(MapBegin(B, &b));
  PetscCall(VelocitiesToLocal(b, v));
  PetscCall(VecGetOwnershipRange(s, &rstart, NULL));
  PetscCall(VecGetArrayRead(b->smap_vloc, &va));
  PetscCall(VecGetArrayRead(sp, &spa));
  PetscCall(VecGetArrayWrite(s, &sa));
  CorrectCells(b, rstart, va, spa, a, sa);
  PetscCall(VecRestoreArrayWrite(s, &sa));
  PetscCall(VecRestoreArrayRead(sp, &spa));
  PetscCall(VecRestoreArrayRead(b->smap_vloc, &va));
  PetscCall(PetscLogFlops((RateFlops(b->ref.nv, b->ref.ns) + 2.0 * 6 * b->ref.ns) * (b->cEnd - b->cStart)));
  PetscCall(PetscLogEventEnd(PHLEX_StressMaps, B, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleStrainEnergyLocal - this process's part of s^T Ms s (twice the strain energy, non-dimensional; the
  caller sums it over the processes, split_sum.c), from Ms's structure: the block of cell c is
  detJ_c (smass (x) A_m) (PhlexElementComplianceMass), smass the reference mass of the stress basis, A_m the compliance
  of the cell's material, so a cell's energy is 1/2 detJ_c sum_ij smass_ij s_i . A_m s_j over its stress nodes i, j
  (6 components each). The monitor needs it every step: a product with the assembled Ms streamed its 224 MB at 2.2e5
  velocity DOFs (30-47 ms, one BLAS dgemv call per cell), this reads the stresses and the cells' volumes only
  (BENCHMARKS.md section 18), several cells per instruction where the compiler has vectors (the cells' sum in cell
  order). The sums are not dgemv's: the
  energy differs from 1/2 s^T (Ms s) in its last bits.

  Not collective
@*/
PetscErrorCode PhlexFlexibleStrainEnergyLocal(PhlexFlexible b, Vec s, PetscReal *local)
{
  const PetscInt     nn = b->ref.ns;
  const PetscScalar *sa;
  PetscInt           rstart;

  PetscFunctionBeginUser;
  PetscCheck(nn <= 4, b->comm, PETSC_ERR_SUP, "body %s: the strain energy takes at most 4 stress nodes per cell (P1 stress), not %" PetscInt_FMT, b->name, nn);
  PetscCall(VecGetOwnershipRange(s, &rstart, NULL));
  PetscCall(VecGetArrayRead(s, &sa));
  *local = StrainEnergyCells(b, rstart, sa);
  PetscCall(VecRestoreArrayRead(s, &sa));
  PetscCall(PetscLogFlops((2.0 * 6 * nn * nn + 2.0 * 42 * nn + 1) * (b->cEnd - b->cStart)));
  PetscFunctionReturn(0);
}

/* -phlex_check_stress_maps: the products cell by cell against the assembled operators, for a random velocity v and
   stress Sigma: |Ms (B v) - G v| / |G v|, |Res Sigma - G^T Sigma| / |G^T Sigma| and |Kc v - G^T (B v)| / |G^T (B v)|
   (infinity norms), printed */
static PetscErrorCode CheckStressMaps(PhlexFlexible b, Mat B, Mat Res, Mat Kc)
{
  Vec         v, s, Bv, MsBv, Gv, f, Gts;
  PetscRandom rnd;
  PetscReal   nref, ndiff, worst_b, worst_r, worst_k;

  PetscFunctionBeginUser;
  PetscCall(PetscRandomCreate(b->comm, &rnd));
  PetscCall(PetscRandomSetInterval(rnd, -1.0, 1.0));
  PetscCall(MatCreateVecs(b->G, &v, &s));
  PetscCall(VecDuplicate(s, &Bv));
  PetscCall(VecDuplicate(s, &MsBv));
  PetscCall(VecDuplicate(s, &Gv));
  PetscCall(VecDuplicate(v, &f));
  PetscCall(VecDuplicate(v, &Gts));
  PetscCall(VecSetRandom(v, rnd));
  PetscCall(VecSetRandom(s, rnd));
  /* B: Ms (B v) = G v */
  PetscCall(MatMult(B, v, Bv));
  PetscCall(MatMult(b->Ms, Bv, MsBv));
  PetscCall(MatMult(b->G, v, Gv));
  PetscCall(VecNorm(Gv, NORM_INFINITY, &nref));
  PetscCall(VecAXPY(MsBv, -1.0, Gv));
  PetscCall(VecNorm(MsBv, NORM_INFINITY, &ndiff));
  worst_b = ndiff / nref;
  /* G^T */
  PetscCall(MatMult(Res, s, f));
  PetscCall(MatMultTranspose(b->G, s, Gts));
  PetscCall(VecNorm(Gts, NORM_INFINITY, &nref));
  PetscCall(VecAXPY(f, -1.0, Gts));
  PetscCall(VecNorm(f, NORM_INFINITY, &ndiff));
  worst_r = ndiff / nref;
  /* K: G^T (B v) with the assembled G (B checked above) */
  PetscCall(MatMult(Kc, v, f));
  PetscCall(MatMultTranspose(b->G, Bv, Gts));
  PetscCall(VecNorm(Gts, NORM_INFINITY, &nref));
  PetscCall(VecAXPY(f, -1.0, Gts));
  PetscCall(VecNorm(f, NORM_INFINITY, &ndiff));
  worst_k = ndiff / nref;
  PetscCall(PetscPrintf(b->comm, "body %s: stress maps cell by cell vs assembled G, Ms: Ms B - G %s, G^T %s, K - G^T B %s (relative, infinity norm)\n", b->name, worst_b < 1e-13 ? "< 1e-13" : "LARGE", worst_r < 1e-13 ? "< 1e-13" : "LARGE", worst_k < 1e-13 ? "< 1e-13" : "LARGE"));
  PetscCall(PetscInfo(NULL, "body %s: stress maps: Ms B - G %.3e, G^T %.3e, K - G^T B %.3e\n", b->name, (double)worst_b, (double)worst_r, (double)worst_k));
  if (worst_b >= 1e-13 || worst_r >= 1e-13 || worst_k >= 1e-13) PetscCall(PetscPrintf(b->comm, "body %s: stress maps: Ms B - G %.3e, G^T %.3e, K - G^T B %.3e\n", b->name, (double)worst_b, (double)worst_r, (double)worst_k));
  PetscCall(VecDestroy(&v));
  PetscCall(VecDestroy(&s));
  PetscCall(VecDestroy(&Bv));
  PetscCall(VecDestroy(&MsBv));
  PetscCall(VecDestroy(&Gv));
  PetscCall(VecDestroy(&f));
  PetscCall(VecDestroy(&Gts));
  PetscCall(PetscRandomDestroy(&rnd));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleCreateStressMaps - the body's shells of B = Ms^{-1} G (stress rows, velocity columns), G^T (velocity
  rows, stress columns) and the condensed stiffness K = G^T Ms^{-1} G (velocity rows and columns), applied cell by
  cell (b->smap_B, b->smap_Res, b->smap_K); none for a body with geometric stiffening, whose G(u) is assembled.
  -phlex_check_stress_maps compares them with the assembled operators.

  Collective
@*/
PetscErrorCode PhlexFlexibleCreateStressMaps(PhlexFlexible b)
{
  const PetscBool check = b->check_stress_maps;

  PetscFunctionBeginUser;
  PetscCheck(!check || (b->Ms && b->G), b->comm, PETSC_ERR_ORDER, "body %s: the check of the stress maps needs the mixed operators (PhlexFlexibleSetUpMixed)", b->name);
  if (b->stiffening) {
    if (check) PetscCall(PetscPrintf(b->comm, "body %s: stress maps cell by cell: not used (geometric stiffening assembles G(u))\n", b->name));
    PetscFunctionReturn(0);
  }
  PetscCall(PhlexMatCreateShell(b->comm, b->ns_local, b->nv_local, b->ns_global, b->nv_global, b, MatMult_StressRate, &b->smap_B));
  PetscCall(PhlexMatCreateShell(b->comm, b->nv_local, b->ns_local, b->nv_global, b->ns_global, b, MatMult_Resultant, &b->smap_Res));
  PetscCall(PhlexMatCreateShell(b->comm, b->nv_local, b->nv_local, b->nv_global, b->nv_global, b, MatMult_CondensedStiffness, &b->smap_K));
  PetscCall(PetscObjectSetName((PetscObject)b->smap_B, "stress rate map Ms^-1 G (cell by cell)"));
  PetscCall(PetscObjectSetName((PetscObject)b->smap_Res, "stress resultant map G^T (cell by cell)"));
  PetscCall(PetscObjectSetName((PetscObject)b->smap_K, "condensed stiffness map G^T Ms^-1 G (cell by cell)"));
  if (check) PetscCall(CheckStressMaps(b, b->smap_B, b->smap_Res, b->smap_K));
  PetscFunctionReturn(0);
}

/* the stress maps' shells and work vectors */
PetscErrorCode PhlexFlexibleStressMapsDestroy(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&b->smap_B));
  PetscCall(MatDestroy(&b->smap_Res));
  PetscCall(MatDestroy(&b->smap_K));
  PetscCall(VecDestroy(&b->smap_vloc));
  PetscCall(VecDestroy(&b->smap_floc));
  PetscCall(PetscFree(b->smap_varray));
  b->smap_ready   = PETSC_FALSE;
  b->smap_created = PETSC_FALSE;
  PetscFunctionReturn(0);
}
