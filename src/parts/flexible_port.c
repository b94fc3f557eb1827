/* Ports of a flexible body: named boundary surfaces. Their geometry (area, centroid, area inertia), the distribution
   of a wrench over the patch (the columns of B) whose transpose gives the collocated output (DESIGN section 3), and
   the boundary-face integration they use. */
#include <phlex_impl.h>
#include <petscsf.h>

/* 3x3 inverse */
static void Inverse3(const PetscReal A[9], PetscReal B[9], PetscReal *det)
{
  *det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
  B[0] = (A[4] * A[8] - A[5] * A[7]) / *det;
  B[1] = (A[2] * A[7] - A[1] * A[8]) / *det;
  B[2] = (A[1] * A[5] - A[2] * A[4]) / *det;
  B[3] = (A[5] * A[6] - A[3] * A[8]) / *det;
  B[4] = (A[0] * A[8] - A[2] * A[6]) / *det;
  B[5] = (A[2] * A[3] - A[0] * A[5]) / *det;
  B[6] = (A[3] * A[7] - A[4] * A[6]) / *det;
  B[7] = (A[1] * A[6] - A[0] * A[7]) / *det;
  B[8] = (A[0] * A[4] - A[1] * A[3]) / *det;
}

/*@C
  PhlexSurfaceIntegrate - loops over the boundary faces of a body's "Face Sets" stratum and hands each face's
  quadrature (physical points, weights) and the velocity basis of its cell at those points to a callback

  Collective

  Input Parameters:
+ body   - the body
. tag    - the "Face Sets" value of the surface
. degree - polynomial degree integrated exactly on each (affine) face
. func   - callback (ctx, nq, x[nq*3] SI points, w[nq] SI area weights, phi[nq*nb] scalar basis values, comp[nb] their components, idx[nb] global velocity dofs (negative: constrained), nb)
- ctx    - callback context

  Notes:
  Each face is visited on the one rank that owns it.
@*/
PetscErrorCode PhlexSurfaceIntegrate(PhlexFlexible body, PetscInt tag, PetscInt degree, PhlexSurfaceFunc func, void *ctx)
{
  DMLabel          label;
  IS               is;
  const PetscInt  *faces;
  PetscInt         nfaces, nq, nleaves, nb;
  const PetscInt  *leaves;
  PetscSF          sf;
  PetscQuadrature  fq;
  const PetscReal *fpoints, *fweights;
  PetscSection     section, gsection;
  PetscReal       *xq, *xi, *phi, *wq;
  PetscInt        *comp;

  PetscFunctionBeginUser;
  PetscCall(DMGetLabel(body->dm, "Face Sets", &label));
  PetscCall(DMGetPointSF(body->dm, &sf));
  PetscCall(PetscSFGetGraph(sf, NULL, &nleaves, &leaves, NULL));
  PetscCall(DMGetLocalSection(body->dm, &section));
  PetscCall(DMGetGlobalSection(body->dm, &gsection));
  PetscCall(PetscDTSimplexQuadrature(2, degree, PETSCDTSIMPLEXQUAD_MINSYM, &fq));
  PetscCall(PetscQuadratureGetData(fq, NULL, NULL, &nq, &fpoints, &fweights));
  PetscCall(PetscFEGetDimension(body->fe_v, &nb));
  PetscCall(PetscMalloc5(nq * 3, &xq, nq * 3, &xi, nq * nb, &phi, nq, &wq, nb, &comp));
  PetscCall(DMLabelGetStratumIS(label, tag, &is));
  nfaces = 0;
  faces  = NULL;
  if (is) {
    PetscCall(ISGetLocalSize(is, &nfaces));
    PetscCall(ISGetIndices(is, &faces));
  }
  for (PetscInt i = 0; i < nfaces; i++) {
    const PetscInt  f = faces[i];
    const PetscInt *support;
    PetscInt        depth, nsupport, c, loc, ncl, nidx, *idx = NULL;
    PetscReal       v0[3], J[9], invJ[9], detJ, P[3][3], area, n[3], e1[3], e2[3];
    Vec             coords;
    PetscSection    csec;
    PetscScalar    *cc = NULL;
    PetscTabulation T;

    PetscCall(DMPlexGetPointDepth(body->dm, f, &depth));
    if (depth != 2) continue;
    if (nleaves > 0 && leaves) {
      PetscCall(PetscFindInt(f, nleaves, leaves, &loc));
      if (loc >= 0) continue; /* owned by another rank */
    } else if (nleaves > 0) {
      if (f < nleaves) continue; /* contiguous leaves 0..nleaves-1 */
    }
    PetscCall(DMPlexGetSupportSize(body->dm, f, &nsupport));
    PetscCall(DMPlexGetSupport(body->dm, f, &support));
    PetscCheck(nsupport >= 1, PETSC_COMM_SELF, PETSC_ERR_PLIB, "face without cell");
    c = support[0];
    PetscCall(DMPlexComputeCellGeometryAffineFEM(body->dm, c, v0, J, invJ, &detJ));
    /* the face's vertices */
    PetscCall(DMGetCoordinatesLocal(body->dm, &coords));
    PetscCall(DMGetCoordinateSection(body->dm, &csec));
    PetscCall(DMPlexVecGetClosure(body->dm, csec, coords, f, &ncl, &cc));
    PetscCheck(ncl == 9, PETSC_COMM_SELF, PETSC_ERR_SUP, "body %s: boundary face %" PetscInt_FMT " is not a triangle", body->name, f);
    for (PetscInt a = 0; a < 3; a++)
      for (PetscInt d = 0; d < 3; d++) P[a][d] = PetscRealPart(cc[3 * a + d]);
    PetscCall(DMPlexVecRestoreClosure(body->dm, csec, coords, f, &ncl, &cc));
    for (PetscInt d = 0; d < 3; d++) {
      e1[d] = P[1][d] - P[0][d];
      e2[d] = P[2][d] - P[0][d];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    area = 0.5 * PetscSqrtReal(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    /* reference triangle (-1,-1), (1,-1), (-1,1) has area 2 */
    for (PetscInt q = 0; q < nq; q++) {
      const PetscReal l1 = 0.5 * (1.0 + fpoints[2 * q]), l2 = 0.5 * (1.0 + fpoints[2 * q + 1]), l0 = 1.0 - l1 - l2;
      for (PetscInt d = 0; d < 3; d++) xq[3 * q + d] = l0 * P[0][d] + l1 * P[1][d] + l2 * P[2][d];
      wq[q] = fweights[q] * area / 2.0;
      /* cell reference coordinates: x = v0 + J (xi + 1) */
      for (PetscInt a = 0; a < 3; a++) {
        PetscReal s = 0;
        for (PetscInt b = 0; b < 3; b++) s += invJ[a * 3 + b] * (xq[3 * q + b] - v0[b]);
        xi[3 * q + a] = s - 1.0;
      }
    }
    PetscCall(PetscFECreateTabulation(body->fe_v, 1, nq, xi, 0, &T));
    for (PetscInt b = 0; b < nb; b++) {
      PetscReal best = -1;
      comp[b]        = 0;
      for (PetscInt cpt = 0; cpt < 3; cpt++) {
        PetscReal s = 0;
        for (PetscInt q = 0; q < nq; q++) s += PetscAbsReal(T->T[0][(q * nb + b) * 3 + cpt]);
        if (s > best) {
          best    = s;
          comp[b] = cpt;
        }
      }
    }
    for (PetscInt q = 0; q < nq; q++)
      for (PetscInt b = 0; b < nb; b++) phi[q * nb + b] = T->T[0][(q * nb + b) * 3 + comp[b]];
    PetscCall(PetscTabulationDestroy(&T));
    PetscCall(DMPlexGetClosureIndices(body->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
    PetscCheck(nidx == nb, PETSC_COMM_SELF, PETSC_ERR_PLIB, "closure size %" PetscInt_FMT " != basis size %" PetscInt_FMT, nidx, nb);
    PetscCall(func(ctx, nq, xq, wq, phi, comp, idx, nb));
    PetscCall(DMPlexRestoreClosureIndices(body->dm, section, gsection, c, PETSC_TRUE, &nidx, &idx, NULL, NULL));
  }
  if (is) {
    PetscCall(ISRestoreIndices(is, &faces));
    PetscCall(ISDestroy(&is));
  }
  PetscCall(PetscFree5(xq, xi, phi, wq, comp));
  PetscCall(PetscQuadratureDestroy(&fq));
  PetscFunctionReturn(0);
}

typedef struct {
  PetscReal m0, m1[3], m2[9]; /* int 1, int x, int x x^T (SI) */
} PortMoments;

static PetscErrorCode PortMomentsAdd(void *ctx, PetscInt nq, const PetscReal *x, const PetscReal *w, const PetscReal *phi, const PetscInt *comp, const PetscInt *idx, PetscInt nb)
{
  PortMoments *m = (PortMoments *)ctx;

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < nq; q++) {
    m->m0 += w[q];
    for (PetscInt a = 0; a < 3; a++) {
      m->m1[a] += w[q] * x[3 * q + a];
      for (PetscInt b = 0; b < 3; b++) m->m2[3 * a + b] += w[q] * x[3 * q + a] * x[3 * q + b];
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSurfaceMoments - area, centroid and area inertia I_c = int (|r|^2 I - r r^T) dGamma (r = x - c) of a surface (SI)

  Collective
@*/
PetscErrorCode PhlexSurfaceMoments(PhlexFlexible body, PetscInt tag, PetscReal *area, PetscReal centroid[3], PetscReal inertia[9])
{
  PortMoments m;
  PetscReal   buf[13], gbuf[13], S[9], tr;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&m, sizeof(m)));
  PetscCall(PhlexSurfaceIntegrate(body, tag, 2, PortMomentsAdd, &m));
  buf[0] = m.m0;
  for (PetscInt a = 0; a < 3; a++) buf[1 + a] = m.m1[a];
  for (PetscInt a = 0; a < 9; a++) buf[4 + a] = m.m2[a];
  PetscCall(MPIU_Allreduce(buf, gbuf, 13, MPIU_REAL, MPI_SUM, body->comm));
  *area = gbuf[0];
  for (PetscInt a = 0; a < 3; a++) centroid[a] = gbuf[1 + a] / gbuf[0];
  /* int r_a r_b = int x_a x_b - A c_a c_b */
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt b = 0; b < 3; b++) S[3 * a + b] = gbuf[4 + 3 * a + b] - gbuf[0] * centroid[a] * centroid[b];
  tr = S[0] + S[4] + S[8];
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt b = 0; b < 3; b++) inertia[3 * a + b] = (a == b ? tr : 0.0) - S[3 * a + b];
  PetscFunctionReturn(0);
}

typedef struct {
  PhlexFlexPort    *port;
  const PhlexUnits *units;
} PortDistCtx;

/* B columns (non-dimensional): unit force -> traction e_c / A; unit moment -> traction (I_c^{-1} e_m) x (x - c) */
static PetscErrorCode PortDistAdd(void *ctx, PetscInt nq, const PetscReal *x, const PetscReal *w, const PetscReal *phi, const PetscInt *comp, const PetscInt *idx, PetscInt nb)
{
  PortDistCtx     *pc = (PortDistCtx *)ctx;
  PhlexFlexPort   *p  = pc->port;
  const PetscReal  L  = pc->units->length;
  const PetscReal  Ahat = p->area / (L * L);
  PetscReal        Iinv_hat[9];
  PetscScalar      vals[6][64];

  PetscFunctionBeginUser;
  PetscCheck(nb <= 64, PETSC_COMM_SELF, PETSC_ERR_SUP, "too many basis functions");
  for (PetscInt i = 0; i < 9; i++) Iinv_hat[i] = p->inertia_inv[i] * L * L * L * L;
  for (PetscInt k = 0; k < 6; k++)
    for (PetscInt b = 0; b < nb; b++) vals[k][b] = 0.0;
  for (PetscInt q = 0; q < nq; q++) {
    const PetscReal wh = w[q] / (L * L);
    PetscReal       r[3];
    for (PetscInt a = 0; a < 3; a++) r[a] = (x[3 * q + a] - p->centroid[a]) / L;
    for (PetscInt m = 0; m < 3; m++) {
      const PetscReal a0 = Iinv_hat[0 * 3 + m], a1 = Iinv_hat[1 * 3 + m], a2 = Iinv_hat[2 * 3 + m]; /* I^{-1} e_m */
      const PetscReal t[3] = {a1 * r[2] - a2 * r[1], a2 * r[0] - a0 * r[2], a0 * r[1] - a1 * r[0]};
      for (PetscInt b = 0; b < nb; b++) vals[3 + m][b] += wh * phi[q * nb + b] * t[comp[b]];
    }
    for (PetscInt b = 0; b < nb; b++) vals[comp[b]][b] += wh * phi[q * nb + b] / Ahat;
  }
  for (PetscInt k = 0; k < 6; k++)
    for (PetscInt b = 0; b < nb; b++)
      if (idx[b] >= 0 && vals[k][b] != 0.0) PetscCall(VecSetValue(p->dist[k], idx[b], vals[k][b], ADD_VALUES));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexPortSetUp - finds the port's surface, computes its area, centroid and inertia, and assembles the
  distribution vectors (the port's columns of B)

  Collective
@*/
PetscErrorCode PhlexFlexPortSetUp(PhlexFlexible body, PhlexFlexPort *p, const PhlexUnits *units)
{
  PortDistCtx ctx;
  PetscReal   det;
  char        option[256];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_PortDist, 0, 0, 0, 0));
  PetscCall(PetscSNPrintf(option, sizeof(option), "-%sports", body->prefix));
  PetscCall(PhlexMeshFindGroup(body, p->name, 2, option, &p->tag));
  PetscCall(PhlexSurfaceMoments(body, p->tag, &p->area, p->centroid, p->inertia));
  Inverse3(p->inertia, p->inertia_inv, &det);
  PetscCheck(det > 0, body->comm, PETSC_ERR_USER_INPUT, "body %s, port %s: the surface has a singular area inertia", body->name, p->name);
  if (p->load.traction_input)
    for (PetscInt d = 0; d < 3; d++) p->load.force[d] *= p->area;

  ctx.port  = p;
  ctx.units = units;
  for (PetscInt k = 0; k < 6; k++) {
    PetscCall(DMCreateGlobalVector(body->dm, &p->dist[k]));
    PetscCall(VecSet(p->dist[k], 0.0));
  }
  PetscCall(PhlexSurfaceIntegrate(body, p->tag, body->degree + 1, PortDistAdd, &ctx));
  for (PetscInt k = 0; k < 6; k++) {
    PetscCall(VecAssemblyBegin(p->dist[k]));
    PetscCall(VecAssemblyEnd(p->dist[k]));
  }
  PetscCall(PetscLogEventEnd(PHLEX_PortDist, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexPortDestroy - frees a port's vectors and profile
@*/
PetscErrorCode PhlexFlexPortDestroy(PhlexFlexPort *p)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) PetscCall(VecDestroy(&p->dist[k]));
  PetscCall(PhlexPortLoadDestroy(&p->load));
  PetscFunctionReturn(0);
}
