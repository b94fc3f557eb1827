/* The offline side of a reduced flexible body (paper Section 5.3, DESIGN "Reduced bodies"): a basis of the full
   body's elastic field, the Galerkin projection of its operators and inertia invariants, and the reduced body file.

   Basis (free interface): the body's own lowest normal modes, K phi = lambda Mv phi on its field space (clamped at the
   frame patch of a fixed or patch-framed body; free on mean axes, where the modes are Mv-orthogonal to the rigid
   fields), plus the static attachment modes of each listed port, K psi = B_q e_d for its six unit wrench components
   (on mean axes with inertia relief: the load's rigid resultant removed, psi Mv-orthogonal to the rigid fields, so that
   the basis keeps the mean-axes conditions int rho u = 0, int rho x x u = 0 exactly). The span of the attachment modes
   is that of the ports' rigid-average constraint modes (Craig-Bampton's static modes with phlex's port maps). The
   basis is Mv-orthonormalised and rotated by a Rayleigh-Ritz step so that the reduced mass is I and the reduced
   stiffness diagonal.

   Basis (craig_bampton): the fixed-interface modes (the frame patch clamped and the listed ports' rigid averages
   held, B^T u = 0; FixedInterfaceModes) plus the ports' constraint modes (CraigBamptonVectors); the same
   orthonormalisation and Rayleigh-Ritz step. A body without listed ports gets the free-interface basis.

   Basis (krylov): moment matching of the ports' transfer function (KrylovVectors). With the frame held, the field's
   dynamics under the port wrenches w is Mv u'' + K u = B w (B = [b->ports[q].dist[d]], the load vectors whose
   transposes give the rigid averages, the collocated outputs y = B^T u'), so H(s) = s G(s^2) with the dynamic
   compliance G(mu) = B^T (mu Mv + K)^{-1} B. About an expansion frequency w0 (mu0 = -w0^2, A0 = K - w0^2 Mv),
   G(mu) = sum_j (-(mu - mu0))^j B^T (A0^{-1} Mv)^j A0^{-1} B; the block Krylov space K_r(A0^{-1} Mv, A0^{-1} B) holds
   the vectors of the first r moments, and a Galerkin projection on it (V^T Mv V, V^T K V, V^T B: the same V on the
   input and output sides, the collocation of phlex's ports) matches the first 2 r moments of G at mu0: Bai and Su's
   structure-preserving second-order Arnoldi (SOAR, SIAM J. Sci. Comput. 26 (2005) 1692) and Freund's
   Pade-via-Krylov for symmetric second-order systems (Freund, "Pade-type model reduction of second-order and
   higher-order linear dynamical systems", 2005): a one-sided congruence projection of a symmetric system matches
   twice the moments of the one-sided space. The error H - H_r is then O((s - s0)^{2 r}) about s0 = i w0 (about 0:
   O(s^{4 r + 1}), G being a function of s^2). The default expansion is 0 Hz: the Krylov space of K^{-1} Mv from
   K^{-1} B, whose first block is the ports' static attachment modes. On mean axes (K singular) the loads lose their
   rigid resultant and the fields their rigid content as in AttachmentModes (the frame held on mean axes: the field
   constrained to int rho u = 0, int rho x x u = 0). The projection keeps the pH structure like the other bases.

   Projection: a Galerkin projection keeps the port-Hamiltonian structure (reduced mass Phi^T Mv Phi symmetric positive
   definite, the interconnection skew, the port maps B_q^T Phi and their transposes), so a lossless reduced body keeps
   its quadratic energy under the implicit midpoint rule like the full one. The floating frame needs the inertia
   invariants int rho phi_k, int rho x phi_k^T and int rho phi_i phi_j^T (frame.c's node inputs contracted with the
   basis: PhlexFrameLoadCoefficients). */
#include <phlex_impl.h>
#include <private/reduced.h>
#include <petscviewerhdf5.h>

const char *const PhlexReductionTypes[] = {"free_interface", "craig_bampton", "krylov", "PhlexReductionType", "PHLEX_REDUCTION_", NULL};

/* the rigid fields of the body's velocity space, Mv-orthonormal (mean axes) */
static PetscErrorCode RigidFields(PhlexFlexible b, Vec R[6])
{
  MatNullSpace nsp;
  const Vec   *rig;
  PetscInt     nrig;
  PetscBool    has_const;

  PetscFunctionBeginUser;
  PetscCall(DMPlexCreateRigidBody(b->dm, 0, &nsp));
  PetscCall(MatNullSpaceGetVecs(nsp, &has_const, &nrig, &rig));
  PetscCheck(nrig == 6, b->comm, PETSC_ERR_PLIB, "body %s: %" PetscInt_FMT " rigid fields", b->name, nrig);
  for (PetscInt k = 0; k < 6; k++) PetscCall(VecDuplicate(rig[k], &R[k]));
  for (PetscInt k = 0; k < 6; k++) PetscCall(VecCopy(rig[k], R[k]));
  PetscCall(MatNullSpaceDestroy(&nsp));
  /* Gram-Schmidt in the Mv inner product, twice */
  for (PetscInt pass = 0; pass < 2; pass++)
    for (PetscInt k = 0; k < 6; k++) {
      Vec         Mx;
      PetscScalar d;
      PetscCall(VecDuplicate(R[k], &Mx));
      for (PetscInt j = 0; j < k; j++) {
        PetscCall(MatMult(b->Mv, R[j], Mx));
        PetscCall(VecDot(R[k], Mx, &d));
        PetscCall(VecAXPY(R[k], -d, R[j]));
      }
      PetscCall(MatMult(b->Mv, R[k], Mx));
      PetscCall(VecDot(R[k], Mx, &d));
      PetscCall(VecScale(R[k], 1.0 / PetscSqrtReal(PetscRealPart(d))));
      PetscCall(VecDestroy(&Mx));
    }
  PetscFunctionReturn(0);
}

/* x <- x - R R^T Mv x (R Mv-orthonormal): the rigid content of a field removed */
static PetscErrorCode RemoveRigid(PhlexFlexible b, Vec R[6], Vec x, Vec work)
{
  PetscScalar d[6];

  PetscFunctionBeginUser;
  PetscCall(MatMult(b->Mv, x, work));
  PetscCall(VecMDot(work, 6, R, d));
  for (PetscInt k = 0; k < 6; k++) d[k] = -d[k];
  PetscCall(VecMAXPY(x, 6, d, R));
  PetscFunctionReturn(0);
}

/* A solver of (K - omega^2 Mv) x = f on the field space with the frame held: MUMPS (LDL^T for an indefinite
   matrix, above the first frequency), options prefix <body>reduction_. On mean axes the load loses its rigid
   resultant (f - Mv R R^T f) and the solution its rigid content; at omega = 0 K is singular there and the solve takes
   K + lambda1 Mv with refinements on K (the inertia-relief static solve of the attachment modes). */
typedef struct {
  PhlexFlexible b;
  PetscBool     mean_axes, relief;
  Mat           A;
  KSP           ksp;
  Vec           R[6], f, r, dx, work;
} ShiftedSolver;

static PetscErrorCode ShiftedSolverCreate(PhlexPart part, PetscReal omega2, PetscReal lambda1, ShiftedSolver *s)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PC            pc;
  PetscReal     shift;
  char          prefix[64];

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(s, sizeof(*s)));
  s->b         = b;
  s->mean_axes = (b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES) ? PETSC_TRUE : PETSC_FALSE;
  s->relief    = (s->mean_axes && omega2 == 0.0) ? PETSC_TRUE : PETSC_FALSE;
  shift        = s->relief ? lambda1 : -omega2;
  PetscCall(MatDuplicate(b->K, MAT_COPY_VALUES, &s->A));
  if (shift != 0.0) PetscCall(MatAXPY(s->A, shift, b->Mv, DIFFERENT_NONZERO_PATTERN));
  PetscCall(MatSetOption(s->A, MAT_SYMMETRIC, PETSC_TRUE));
  if (shift < 0.0) PetscCall(MatSetOption(s->A, MAT_SPD, PETSC_FALSE));
  if (s->mean_axes) PetscCall(RigidFields(b, s->R));
  PetscCall(KSPCreate(b->comm, &s->ksp));
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sreduction_", part->prefix));
  PetscCall(KSPSetOptionsPrefix(s->ksp, prefix));
  PetscCall(KSPSetOperators(s->ksp, s->A, s->A));
  PetscCall(KSPSetType(s->ksp, KSPPREONLY));
  PetscCall(KSPGetPC(s->ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(KSPSetFromOptions(s->ksp));
  PetscCall(MatCreateVecs(b->Mv, &s->f, NULL));
  PetscCall(VecDuplicate(s->f, &s->r));
  PetscCall(VecDuplicate(s->f, &s->dx));
  PetscCall(VecDuplicate(s->f, &s->work));
  PetscFunctionReturn(0);
}

static PetscErrorCode ShiftedSolverDestroy(ShiftedSolver *s)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) PetscCall(VecDestroy(&s->R[k]));
  PetscCall(VecDestroy(&s->f));
  PetscCall(VecDestroy(&s->r));
  PetscCall(VecDestroy(&s->dx));
  PetscCall(VecDestroy(&s->work));
  PetscCall(KSPDestroy(&s->ksp));
  PetscCall(MatDestroy(&s->A));
  PetscFunctionReturn(0);
}

/* x = (K - omega^2 Mv)^{-1} rhs (x created), one refinement step. On mean axes at omega = 0: refinements on K (each
   divides the error in mode i by 1 + lambda_i / lambda1 >= 2) until the residual is 1e-12 of the load, or it stops
   falling at round-off (three refinements in a row without falling below 3/4 of the
   smallest so far, 2-norm): the later Krylov blocks' loads Mv x are smooth, their solutions large, and their
   residuals stall above 1e-12 ||f|| (observed on the crank-slider's coupler: the residual halving at each refinement
   down to a normwise backward error ||f - K x|| / (||K|| ||x|| + ||f||) of 5e-17 after 28). Not earlier: a backward
   error of 1e-14 still leaves the lowest mode's error up to ||K|| / lambda1 times larger in the solution (the
   moments were off by 1e-6 so). Refused if the backward error (infinity norms) is then above 1e-13. */
static PetscErrorCode ShiftedSolverSolve(ShiftedSolver *s, Vec rhs, Vec *x)
{
  PhlexFlexible b = s->b;
  Mat           op = s->relief ? b->K : s->A;
  PetscReal     fn, rn = 0.0, kn = 0.0, xn = 0.0, rmin = PETSC_MAX_REAL;
  PetscInt      it, stall = 0;

  PetscFunctionBeginUser;
  if (s->relief) PetscCall(MatNorm(b->K, NORM_INFINITY, &kn));
  PetscCall(VecCopy(rhs, s->f));
  if (s->mean_axes) {
    PetscScalar c[6];
    PetscCall(VecMDot(s->f, 6, s->R, c));
    PetscCall(VecSet(s->work, 0.0));
    PetscCall(VecMAXPY(s->work, 6, c, s->R));
    PetscCall(MatMult(b->Mv, s->work, s->r));
    PetscCall(VecAXPY(s->f, -1.0, s->r)); /* f - Mv R R^T f: no resultant */
  }
  PetscCall(VecDuplicate(s->f, x));
  PetscCall(KSPSolve(s->ksp, s->f, *x));
  PetscCall(VecNorm(s->f, NORM_INFINITY, &fn));
  for (it = 0; it < (s->relief ? 200 : 1); it++) {
    if (s->mean_axes) PetscCall(RemoveRigid(b, s->R, *x, s->work));
    PetscCall(MatMult(op, *x, s->r));
    PetscCall(VecAYPX(s->r, -1.0, s->f));
    PetscCall(VecNorm(s->r, NORM_INFINITY, &rn));
    PetscCall(VecNorm(*x, NORM_INFINITY, &xn));
    if (s->relief) {
      PetscReal r2;
      PetscCall(VecNorm(s->r, NORM_2, &r2));
      stall = r2 > 0.75 * rmin ? stall + 1 : 0;
      rmin  = PetscMin(rmin, r2);
      if (rn <= 1e-12 * fn || stall >= 3) break;
    }
    PetscCall(KSPSolve(s->ksp, s->r, s->dx));
    PetscCall(VecAXPY(*x, 1.0, s->dx));
  }
  PetscCheck(!s->relief || rn <= 1e-12 * fn || rn <= 1e-13 * (kn * xn + fn), b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: a static solve of the reduction (inertia relief) did not converge on mean axes (backward error %g after %" PetscInt_FMT " refinements)", b->name, (double)(rn / (kn * xn + fn)), it);
  if (s->mean_axes) PetscCall(RemoveRigid(b, s->R, *x, s->work));
  PetscFunctionReturn(0);
}

/* the static attachment modes of the listed ports: K psi = B_q e_d (six per port); on mean axes with inertia relief
   (ShiftedSolver at omega = 0: loads without resultant, solutions without rigid content) */
static PetscErrorCode AttachmentModes(PhlexPart part, PetscReal lambda1, Vec **psi, PetscInt *npsi)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  ShiftedSolver solver;

  PetscFunctionBeginUser;
  *npsi = 6 * b->nports;
  *psi  = NULL;
  if (!*npsi) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(*npsi, psi));
  PetscCall(ShiftedSolverCreate(part, 0.0, lambda1, &solver));
  for (PetscInt q = 0; q < b->nports; q++)
    for (PetscInt d = 0; d < 6; d++) PetscCall(ShiftedSolverSolve(&solver, b->ports[q].dist[d], &(*psi)[6 * q + d]));
  PetscCall(ShiftedSolverDestroy(&solver));
  PetscFunctionReturn(0);
}

/* out[k] = (K + shift Mv)^{-1} rhs[k] (MUMPS Cholesky, options prefix <body>reduction_; one refinement step) */
static PetscErrorCode StiffnessSolve(PhlexPart part, PetscReal shift, PetscInt n, Vec rhs[], Vec out[])
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  KSP           ksp;
  PC            pc;
  Mat           A;
  Vec           r, dx;
  char          prefix[64];

  PetscFunctionBeginUser;
  PetscCall(MatDuplicate(b->K, MAT_COPY_VALUES, &A));
  if (shift != 0.0) PetscCall(MatAXPY(A, shift, b->Mv, DIFFERENT_NONZERO_PATTERN));
  PetscCall(KSPCreate(b->comm, &ksp));
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sreduction_", part->prefix));
  PetscCall(KSPSetOptionsPrefix(ksp, prefix));
  PetscCall(KSPSetOperators(ksp, A, A));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(KSPSetFromOptions(ksp));
  PetscCall(VecDuplicate(rhs[0], &r));
  PetscCall(VecDuplicate(rhs[0], &dx));
  for (PetscInt k = 0; k < n; k++) {
    PetscCall(VecDuplicate(rhs[k], &out[k]));
    PetscCall(KSPSolve(ksp, rhs[k], out[k]));
    PetscCall(MatMult(A, out[k], r));
    PetscCall(VecAYPX(r, -1.0, rhs[k]));
    PetscCall(KSPSolve(ksp, r, dx));
    PetscCall(VecAXPY(out[k], 1.0, dx));
  }
  PetscCall(VecDestroy(&r));
  PetscCall(VecDestroy(&dx));
  PetscCall(KSPDestroy(&ksp));
  PetscCall(MatDestroy(&A));
  PetscFunctionReturn(0);
}

/* S = B^T Z (6 nports x ncols, column-major): the ports' rigid averages of the fields Z */
static PetscErrorCode InterfaceValues(PhlexFlexible b, PetscInt ncols, Vec Z[], PetscReal *S)
{
  const PetscInt n = 6 * b->nports;
  PetscScalar   *d;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(n, &d));
  for (PetscInt j = 0; j < ncols; j++) {
    for (PetscInt q = 0; q < b->nports; q++) PetscCall(VecMDot(Z[j], 6, b->ports[q].dist, d + 6 * q));
    for (PetscInt i = 0; i < n; i++) S[i + n * j] = PetscRealPart(d[i]);
  }
  PetscCall(PetscFree(d));
  PetscFunctionReturn(0);
}

/* Craig-Bampton's fixed-interface normal modes: K phi = lambda Mv phi on W = {u : B^T u = 0} (the frame patch clamped
   by the field's space, every listed port's six rigid averages held). With A = K + shift Mv (SPD; shift > 0 only on
   mean axes, where K is singular) and Z = A^{-1} B, W is the A-orthogonal complement of span Z (Z^T A u = B^T u), so the
   constrained problem is the pencil (Mv, A) in the A inner product deflated by Z: SLEPc's Krylov-Schur on A^{-1} Mv
   (EPS_GHEP, B = A, ST shift 0) orthogonalises its basis against the deflation space in the inner product of A, and
   the eigenpairs of the A-orthogonally projected operator are exactly the Galerkin eigenpairs on W (mu = 1/(lambda +
   shift)). No penalty, no multiplier unknowns. Each vector is then projected on W once more (u - Z S^{-1} B^T u, S =
   B^T Z: round-off), its eigenvalue taken as its Rayleigh quotient, and Mv-normalised. */
static PetscErrorCode FixedInterfaceModes(PhlexPart part, PetscInt nmodes, PetscReal shift, PetscInt nz, Vec Z[], const PetscReal *S, PetscReal *lambda, Vec *vecs)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  Mat           A;
  EPS           eps;
  ST            st;
  KSP           ksp;
  PC            pc;
  PetscInt      nconv;
  PetscReal    *Sinv, cmax = 0.0;
  PetscBLASInt  bn, info, *ipiv;
  Vec           w;
  char          prefix[64];

  PetscFunctionBeginUser;
  PetscCall(MatDuplicate(b->K, MAT_COPY_VALUES, &A));
  if (shift != 0.0) PetscCall(MatAXPY(A, shift, b->Mv, DIFFERENT_NONZERO_PATTERN));
  PetscCall(EPSCreate(b->comm, &eps));
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sreduction_", part->prefix));
  PetscCall(EPSSetOptionsPrefix(eps, prefix));
  PetscCall(EPSSetOperators(eps, b->Mv, A));
  PetscCall(EPSSetProblemType(eps, EPS_GHEP));
  PetscCall(EPSSetType(eps, EPSKRYLOVSCHUR));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_LARGEST_MAGNITUDE));
  PetscCall(EPSSetDimensions(eps, nmodes, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(EPSSetTolerances(eps, 1e-12, PETSC_DEFAULT));
  PetscCall(EPSSetDeflationSpace(eps, nz, Z));
  PetscCall(EPSSetPurify(eps, PETSC_FALSE)); /* purification applies A^{-1} Mv, which leaves W */
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, STSHIFT));
  PetscCall(STSetShift(st, 0.0));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(EPSSetFromOptions(eps));
  {
    char what[PHLEX_NAME_LEN + 32];
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s (its reduction)", b->name));
    PetscCall(PhlexProgressEPSSolve(eps, what));
  }
  PetscCall(EPSGetConverged(eps, &nconv));
  PetscCheck(nconv >= nmodes, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: %" PetscInt_FMT " of the %" PetscInt_FMT " fixed-interface modes of the reduction converged (-%sreduction_modes; the eigensolver takes -%sreduction_eps_*)", b->name, nconv, nmodes, b->prefix, b->prefix);
  /* S^{-1} (S symmetric positive definite: B^T A^{-1} B with B of full column rank) */
  PetscCall(PetscMalloc2(nz * nz, &Sinv, nz, &ipiv));
  for (PetscInt i = 0; i < nz * nz; i++) Sinv[i] = 0.0;
  for (PetscInt i = 0; i < nz; i++) Sinv[i + nz * i] = 1.0;
  {
    PetscReal *Sc;
    PetscCall(PetscMalloc1(nz * nz, &Sc));
    PetscCall(PetscArraycpy(Sc, S, nz * nz));
    PetscCall(PetscBLASIntCast(nz, &bn));
    PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&bn, &bn, Sc, &bn, ipiv, Sinv, &bn, &info));
    PetscCheck(!info, b->comm, PETSC_ERR_USER_INPUT, "body %s: the ports' rigid averages are dependent (LAPACK gesv info %d): two listed ports on the same surface?", b->name, (int)info);
    PetscCall(PetscFree(Sc));
  }
  PetscCall(MatCreateVecs(b->K, &w, NULL));
  for (PetscInt k = 0; k < nmodes; k++) {
    PetscScalar  kr, ki, num, den;
    PetscReal   *g, *c, g0 = 0.0, g1 = 0.0;
    PetscScalar *cs;
    PetscCall(MatCreateVecs(b->K, &vecs[k], NULL));
    PetscCall(EPSGetEigenpair(eps, k, &kr, &ki, vecs[k], NULL));
    PetscCall(PetscMalloc3(nz, &g, nz, &c, nz, &cs));
    PetscCall(InterfaceValues(b, 1, &vecs[k], g)); /* nz values: B^T phi (one column) */
    for (PetscInt i = 0; i < nz; i++) {
      c[i] = 0.0;
      for (PetscInt j = 0; j < nz; j++) c[i] += Sinv[i + nz * j] * g[j];
      cs[i] = -c[i];
    }
    PetscCall(VecMAXPY(vecs[k], nz, cs, Z));
    PetscCall(MatMult(b->Mv, vecs[k], w));
    PetscCall(VecDot(vecs[k], w, &den));
    PetscCall(VecScale(vecs[k], 1.0 / PetscSqrtReal(PetscRealPart(den))));
    PetscCall(MatMult(b->K, vecs[k], w));
    PetscCall(VecDot(vecs[k], w, &num));
    lambda[k] = PetscRealPart(num);
    for (PetscInt i = 0; i < nz; i++) g0 = PetscMax(g0, PetscAbsReal(g[i]));
    PetscCall(InterfaceValues(b, 1, &vecs[k], g));
    for (PetscInt i = 0; i < nz; i++) g1 = PetscMax(g1, PetscAbsReal(g[i]));
    cmax = PetscMax(cmax, g1);
    PetscCall(PetscInfo(NULL, "body %s: fixed-interface mode %" PetscInt_FMT ": lambda %.15g (eigensolver %.15g), max |B^T phi| %g before the projection, %g after\n", b->name, k, (double)lambda[k], (double)(1.0 / PetscRealPart(kr) - shift), (double)g0, (double)g1));
    PetscCall(PetscFree3(g, c, cs));
  }
  PetscCall(PetscInfo(NULL, "body %s: %" PetscInt_FMT " fixed-interface modes, max |B^T phi| %g\n", b->name, nmodes, (double)cmax));
  PetscCall(VecDestroy(&w));
  PetscCall(PetscFree2(Sinv, ipiv));
  PetscCall(EPSDestroy(&eps));
  PetscCall(MatDestroy(&A));
  PetscFunctionReturn(0);
}

/* the first free elastic eigenvalue of a body on mean axes (the shift of its static solves), else 0 */
static PetscErrorCode ReliefShift(PhlexPart part, PetscReal *lambda1)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  *lambda1 = 0.0;
  if (!(b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES)) PetscFunctionReturn(0);
  PetscCall(PhlexFlexibleFirstElasticEigenvalue(part, lambda1));
  PetscFunctionReturn(0);
}

/* The Krylov vectors (paper Section 5.3; the moment matching in the comment at the top): at each expansion frequency
   w0 the blocks X_0 = A0^{-1} B, X_j = A0^{-1} Mv X_{j-1} (j < order), each block Mv-orthogonalised against every vector
   kept so far (this point's and the previous points'; classical Gram-Schmidt, twice), the next block formed from the
   orthonormalised one (block Arnoldi: the same space as the powers, without their loss of rank). A vector whose Mv-norm
   falls below 1e-8 of its own before the orthogonalisation is dependent (a port load already spanned, or a converged
   direction: what is left of it is the solves' round-off, relative 1e-12 or less, amplified by the cancellation) and is
   dropped (deflation: the space is the same, the block smaller). */
static PetscErrorCode KrylovVectors(PhlexPart part, const PhlexReduction *red, Vec **Phi, PetscInt *nb)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *u = part->units;
  const PetscInt    nz = 6 * b->nports, nin = nz + (red->krylov_frame_loads ? 6 : 0), cap = nin * red->krylov_order * red->nfrequencies;
  PetscReal         lambda1 = 0.0;
  PetscInt          ndrop = 0;
  Vec              *MPhi, *rhs, R[6] = {NULL};
  PetscScalar      *d;

  PetscFunctionBeginUser;
  PetscCheck(nz > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction krylov matches the transfer function of the listed ports (-%sports): the body has none (the frame patch alone is held, no input)", b->name, b->prefix, b->prefix);
  for (PetscInt i = 0; i < red->nfrequencies; i++)
    if (red->frequencies[i] == 0.0) PetscCall(ReliefShift(part, &lambda1));
  PetscCall(PetscMalloc1(cap, Phi));
  PetscCall(PetscMalloc3(cap, &MPhi, nin, &rhs, cap, &d));
  if (red->krylov_frame_loads) {
    /* the frame's inertia loads on the field (and a fixed body's weight): Mv times the rigid fields, the loads of a
       unit acceleration of the frame; on mean axes they have no elastic response (refused by the options) */
    PetscCheck(!(b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES), b->comm, PETSC_ERR_SUP, "body %s: -%sreduction_krylov_frame_loads: on mean axes the frame's inertia loads have no elastic response", b->name, b->prefix);
    PetscCall(RigidFields(b, R));
    for (PetscInt k = 0; k < 6; k++) {
      Vec x;
      PetscCall(VecDuplicate(R[k], &x));
      PetscCall(MatMult(b->Mv, R[k], x));
      PetscCall(VecDestroy(&R[k]));
      R[k] = x;
    }
  }
  *nb = 0;
  for (PetscInt i = 0; i < red->nfrequencies; i++) {
    const PetscReal omega = 2 * PETSC_PI * red->frequencies[i] * u->time;
    ShiftedSolver   solver;
    PetscInt        nrhs = nin, kept = 0;

    PetscCall(ShiftedSolverCreate(part, omega * omega, lambda1, &solver));
    for (PetscInt q = 0; q < b->nports; q++)
      for (PetscInt c = 0; c < 6; c++) rhs[6 * q + c] = b->ports[q].dist[c];
    for (PetscInt k = nz; k < nin; k++) rhs[k] = R[k - nz];
    for (PetscInt step = 0; step < red->krylov_order && nrhs > 0; step++) {
      const PetscInt first = *nb;
      for (PetscInt j = 0; j < nrhs; j++) {
        Vec       x;
        PetscReal n0, n1;
        PetscCall(ShiftedSolverSolve(&solver, rhs[j], &x));
        PetscCall(MatMult(b->Mv, x, solver.work));
        PetscCall(VecDot(x, solver.work, &d[0]));
        n0 = PetscSqrtReal(PetscRealPart(d[0]));
        for (PetscInt pass = 0; pass < 2 && *nb > 0; pass++) {
          PetscCall(VecMDot(x, *nb, MPhi, d));
          for (PetscInt k = 0; k < *nb; k++) d[k] = -d[k];
          PetscCall(VecMAXPY(x, *nb, d, *Phi));
        }
        PetscCall(MatMult(b->Mv, x, solver.work));
        PetscCall(VecDot(x, solver.work, &d[0]));
        n1 = PetscSqrtReal(PetscRealPart(d[0]));
        if (!(n1 > 1e-8 * n0)) {
          PetscCall(PetscInfo(NULL, "body %s: Krylov vector %" PetscInt_FMT " of block %" PetscInt_FMT " at %.6g Hz dropped (relative norm %g after the orthogonalisation)\n", b->name, j, step, (double)red->frequencies[i], (double)(n1 / n0)));
          PetscCall(VecDestroy(&x));
          ndrop++;
          continue;
        }
        PetscCall(VecScale(x, 1.0 / n1));
        PetscCall(VecDuplicate(x, &MPhi[*nb]));
        PetscCall(MatMult(b->Mv, x, MPhi[*nb]));
        (*Phi)[(*nb)++] = x;
      }
      /* the next block: A0^{-1} Mv applied to this block's orthonormalised vectors */
      nrhs = *nb - first;
      for (PetscInt j = 0; j < nrhs; j++) rhs[j] = MPhi[first + j];
      kept += nrhs;
    }
    PetscCall(PetscInfo(NULL, "body %s: %" PetscInt_FMT " Krylov vectors at %.6g Hz\n", b->name, kept, (double)red->frequencies[i]));
    PetscCall(ShiftedSolverDestroy(&solver));
  }
  PetscCall(PetscInfo(NULL, "body %s: %" PetscInt_FMT " Krylov vectors, %" PetscInt_FMT " dropped\n", b->name, *nb, ndrop));
  for (PetscInt k = 0; k < *nb; k++) PetscCall(VecDestroy(&MPhi[k]));
  for (PetscInt k = 0; k < 6; k++) PetscCall(VecDestroy(&R[k]));
  PetscCall(PetscFree3(MPhi, rhs, d));
  PetscFunctionReturn(0);
}

/* The Craig-Bampton vectors of a body with listed ports: nmodes fixed-interface modes, then the ports' static modes.
   Clamped at the frame patch (K SPD) the static modes are the constraint modes: the field of least strain energy with
   the rigid averages B^T psi = e_j (unit motion of one port component, every other held), psi = Z S^{-1} with
   Z = K^{-1} B, S = B^T Z (K psi = B mu: loads on the ports only). On mean axes K is singular: the fixed-interface
   modes use A = K + lambda1 Mv and lose their rigid content afterwards (the mean-axes conditions), and the static
   modes are the inertia-relief attachment modes of free_interface, whose span holds the rigid-free part of every
   constraint mode (a constraint mode solves K psi = B mu with a self-equilibrated mu) and six more vectors. */
static PetscErrorCode CraigBamptonVectors(PhlexPart part, PetscInt nmodes, Vec *Phi, PetscInt *nb, PetscReal *lambda_full)
{
  PhlexFlexible   b         = (PhlexFlexible)part->data;
  const PetscBool mean_axes = (b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES) ? PETSC_TRUE : PETSC_FALSE;
  PetscReal       lambda1   = 0.0, *S;
  PetscInt        npsi, nz = 6 * b->nports;
  Vec            *psi, *Z, *dist, *vecs;

  PetscFunctionBeginUser;
  /* the shift: the first free elastic eigenvalue (that of the attachment modes' solves) */
  if (mean_axes) PetscCall(PhlexFlexibleFirstElasticEigenvalue(part, &lambda1));
  PetscCall(AttachmentModes(part, lambda1, &psi, &npsi));
  PetscCall(PetscMalloc4(nz, &dist, nz, &Z, nz * nz, &S, PetscMax(nmodes, 1), &vecs));
  for (PetscInt q = 0; q < b->nports; q++)
    for (PetscInt d = 0; d < 6; d++) dist[6 * q + d] = b->ports[q].dist[d];
  if (mean_axes) PetscCall(StiffnessSolve(part, lambda1, nz, dist, Z));
  else
    for (PetscInt k = 0; k < nz; k++) {
      PetscCall(VecDuplicate(psi[k], &Z[k]));
      PetscCall(VecCopy(psi[k], Z[k])); /* K^{-1} B */
    }
  PetscCall(InterfaceValues(b, nz, Z, S));
  for (PetscInt i = 0; i < nz; i++) /* symmetric in exact arithmetic */
    for (PetscInt j = 0; j < i; j++) S[i + nz * j] = S[j + nz * i] = 0.5 * (S[i + nz * j] + S[j + nz * i]);
  if (nmodes) PetscCall(FixedInterfaceModes(part, nmodes, lambda1, nz, Z, S, lambda_full, vecs));
  *nb = 0;
  if (mean_axes && nmodes) {
    Vec R[6], work;
    PetscCall(RigidFields(b, R));
    PetscCall(VecDuplicate(vecs[0], &work));
    for (PetscInt k = 0; k < nmodes; k++) PetscCall(RemoveRigid(b, R, vecs[k], work));
    PetscCall(VecDestroy(&work));
    for (PetscInt j = 0; j < 6; j++) PetscCall(VecDestroy(&R[j]));
  }
  for (PetscInt k = 0; k < nmodes; k++) Phi[(*nb)++] = vecs[k];
  if (!mean_axes) {
    /* the constraint modes psi_j = sum_i Z_i (S^{-1})_ij */
    PetscReal   *Sinv, *Sc;
    PetscBLASInt bn, info, *ipiv;
    PetscCall(PetscMalloc3(nz * nz, &Sinv, nz * nz, &Sc, nz, &ipiv));
    PetscCall(PetscArraycpy(Sc, S, nz * nz));
    for (PetscInt i = 0; i < nz * nz; i++) Sinv[i] = 0.0;
    for (PetscInt i = 0; i < nz; i++) Sinv[i + nz * i] = 1.0;
    PetscCall(PetscBLASIntCast(nz, &bn));
    PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&bn, &bn, Sc, &bn, ipiv, Sinv, &bn, &info));
    PetscCheck(!info, b->comm, PETSC_ERR_USER_INPUT, "body %s: the ports' rigid averages are dependent (LAPACK gesv info %d)", b->name, (int)info);
    for (PetscInt j = 0; j < nz; j++) {
      PetscScalar *c;
      PetscCall(PetscMalloc1(nz, &c));
      for (PetscInt i = 0; i < nz; i++) c[i] = Sinv[i + nz * j];
      PetscCall(VecSet(psi[j], 0.0));
      PetscCall(VecMAXPY(psi[j], nz, c, Z));
      PetscCall(PetscFree(c));
    }
    {
      /* their interface values: the identity to round-off */
      PetscReal dev = 0.0;
      PetscCall(InterfaceValues(b, nz, psi, Sc));
      for (PetscInt i = 0; i < nz; i++)
        for (PetscInt j = 0; j < nz; j++) dev = PetscMax(dev, PetscAbsReal(Sc[i + nz * j] - (i == j ? 1.0 : 0.0)));
      PetscCall(PetscInfo(NULL, "body %s: %" PetscInt_FMT " constraint modes, max |B^T psi - I| %g\n", b->name, nz, (double)dev));
    }
    PetscCall(PetscFree3(Sinv, Sc, ipiv));
  }
  for (PetscInt k = 0; k < npsi; k++) Phi[(*nb)++] = psi[k];
  for (PetscInt k = 0; k < nz; k++) PetscCall(VecDestroy(&Z[k]));
  PetscCall(PetscFree(psi));
  PetscCall(PetscFree4(dist, Z, S, vecs));
  PetscFunctionReturn(0);
}

/*@C
  PhlexReducedBuild - the reduced model of a flexible body (set up, its FE operators assembled): basis, projected
  operators and inertia invariants (non-dimensional, the body's units)

  Collective

  Input Parameters:
+ part    - the full flexible body
- red     - the kind of basis and its parameters (free_interface, craig_bampton: the normal modes in the basis, the
            ports' static modes coming in addition; krylov: the block steps and expansion frequencies)
@*/
PetscErrorCode PhlexReducedBuild(PhlexPart part, const PhlexReduction *red, PhlexReducedModel *model)
{
  const PhlexReductionType type   = red->type;
  const PetscInt           nmodes = red->nmodes;
  PhlexFlexible   b         = (PhlexFlexible)part->data;
  const PetscBool mean_axes = (b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES) ? PETSC_TRUE : PETSC_FALSE;
  PetscInt        nconv, nrigid, npsi, nb = 0, m;
  PetscReal      *lambda, lambda1;
  Vec            *vecs, *psi, *Phi, *MPhi, work;
  PetscBool       floating = b->floating;

  PetscFunctionBeginUser;
  if (type != PHLEX_REDUCTION_KRYLOV) {
    char option[96];
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%sreduction_modes", b->prefix));
    /* the basis's modes are the field's, clamped at the frame patch (or at the ports), free only on mean axes */
    if (!mean_axes) b->floating = PETSC_FALSE;
    PetscCall(PhlexFlexibleModesRequestCheck(part, nmodes, option, nmodes));
    b->floating = floating;
  }
  if (type == PHLEX_REDUCTION_KRYLOV) {
    model->nnormal = 0;
    PetscCall(PetscMalloc1(1, &model->lambda_full));
    PetscCall(KrylovVectors(part, red, &Phi, &nb));
  } else if (type == PHLEX_REDUCTION_CRAIG_BAMPTON && b->nports) {
    /* with no listed port the fixed interface is the frame patch alone (or nothing, on mean axes): free_interface's
       basis, which is then Craig-Bampton's */
    model->nnormal = nmodes;
    PetscCall(PetscMalloc1(PetscMax(nmodes, 1), &model->lambda_full));
    PetscCall(PetscMalloc1(nmodes + 6 * b->nports, &Phi));
    PetscCall(CraigBamptonVectors(part, nmodes, Phi, &nb, model->lambda_full));
  } else {
    /* the normal modes of the field on its own space: clamped at the frame patch (a floating body's frame patch is its
       field's Dirichlet part: the modes of the field, not those of the body with its frame), free on mean axes */
    if (!nmodes) {
      /* no normal mode asked: the attachment modes alone (none without ports: refused below, before any eigensolve,
         which would stop in SLEPc on nev = 0) */
      model->nnormal = 0;
      lambda1        = 1.0; /* as with modes: the attachment modes' shift, non-dimensional */
      PetscCall(PetscMalloc1(1, &model->lambda_full));
      PetscCall(PetscMalloc1(PetscMax(6 * b->nports, 1), &Phi));
    } else {
      if (!mean_axes) b->floating = PETSC_FALSE;
      PetscCall(PhlexFlexibleComputeModes(part, nmodes, &nconv, &nrigid, &lambda, &vecs, NULL, NULL));
      b->floating = floating;
    }
    if (nmodes) {
      const PetscInt r0 = mean_axes ? 6 : 0; /* ComputeModes puts the frame's six rigid modes (zero fields) first */
      PetscCheck(nconv - r0 >= nmodes, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: %" PetscInt_FMT " of the %" PetscInt_FMT " normal modes of the reduction converged (-%sreduction_modes)", b->name, nconv - r0, nmodes, b->prefix);
      model->nnormal = nmodes;
      PetscCall(PetscMalloc1(nmodes, &model->lambda_full));
      for (PetscInt k = 0; k < nmodes; k++) model->lambda_full[k] = lambda[r0 + k];
      lambda1 = nmodes ? lambda[r0] : 1.0;
      if (mean_axes) {
        /* the relief shift must be the lowest elastic eigenvalue: with a target (or another order) the modes above are
           not the lowest */
        PetscBool lowest;
        PetscCall(PhlexModesLowestFirst(&lowest));
        if (!lowest) PetscCall(PhlexFlexibleFirstElasticEigenvalue(part, &lambda1));
      }
      for (PetscInt k = 0; k < r0; k++) PetscCall(VecDestroy(&vecs[k]));
      PetscCall(PetscMalloc1(nmodes + 6 * b->nports, &Phi));
      for (PetscInt k = 0; k < nmodes; k++) Phi[nb++] = vecs[r0 + k];
      for (PetscInt k = r0 + nmodes; k < nconv; k++) PetscCall(VecDestroy(&vecs[k]));
      PetscCall(PetscFree(vecs));
      PetscCall(PetscFree(lambda));
    }
    PetscCall(AttachmentModes(part, lambda1, &psi, &npsi));
    for (PetscInt k = 0; k < npsi; k++) Phi[nb++] = psi[k];
    PetscCall(PetscFree(psi));
  }
  PetscCheck(nb > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: the reduced basis is empty: ask for normal modes (-%sreduction_modes) or list ports", b->name, b->prefix);

  /* Mv-orthonormal, twice (the attachment modes are nearly dependent on the low modes); a vector whose norm falls
     below 1e-8 of its own is in the span of the others and is dropped */
  PetscCall(VecDuplicate(Phi[0], &work));
  PetscCall(PetscMalloc1(nb, &MPhi)); /* Mv times the accepted vectors */
  m = 0;
  for (PetscInt k = 0; k < nb; k++) {
    PetscScalar d;
    PetscReal   n0, n1;
    PetscCall(MatMult(b->Mv, Phi[k], work));
    PetscCall(VecDot(Phi[k], work, &d));
    n0 = PetscSqrtReal(PetscRealPart(d));
    for (PetscInt pass = 0; pass < 2; pass++)
      for (PetscInt j = 0; j < m; j++) {
        PetscCall(VecDot(Phi[k], MPhi[j], &d));
        PetscCall(VecAXPY(Phi[k], -d, Phi[j]));
      }
    PetscCall(MatMult(b->Mv, Phi[k], work));
    PetscCall(VecDot(Phi[k], work, &d));
    n1 = PetscSqrtReal(PetscRealPart(d));
    if (n1 <= 1e-8 * n0) {
      PetscCall(PetscInfo(NULL, "body %s: basis vector %" PetscInt_FMT " dropped (in the span of the others)\n", b->name, k));
      PetscCall(VecDestroy(&Phi[k]));
      continue;
    }
    PetscCall(VecScale(Phi[k], 1.0 / n1));
    PetscCall(VecDuplicate(work, &MPhi[m]));
    PetscCall(MatMult(b->Mv, Phi[k], MPhi[m]));
    Phi[m++] = Phi[k];
  }
  for (PetscInt j = 0; j < m; j++) PetscCall(VecDestroy(&MPhi[j]));
  PetscCall(PetscFree(MPhi));
  model->m = m;

  /* Rayleigh-Ritz: Kr = Phi^T K Phi, rotated to its eigenvectors (the reduced mass stays I) */
  {
    PetscReal   *Kr, *w, *work2;
    PetscBLASInt bm, lwork, info;
    Vec         *rot;
    PetscCall(PetscMalloc3(m * m, &Kr, m, &w, 4 * m * m + 8 * m, &work2));
    for (PetscInt j = 0; j < m; j++) {
      PetscScalar *d;
      PetscCall(PetscMalloc1(m, &d));
      PetscCall(MatMult(b->K, Phi[j], work));
      PetscCall(VecMDot(work, m, Phi, d));
      for (PetscInt i = 0; i < m; i++) Kr[i + m * j] = PetscRealPart(d[i]);
      PetscCall(PetscFree(d));
    }
    for (PetscInt i = 0; i < m; i++)
      for (PetscInt j = 0; j < i; j++) Kr[i + m * j] = Kr[j + m * i] = 0.5 * (Kr[i + m * j] + Kr[j + m * i]);
    PetscCall(PetscBLASIntCast(m, &bm));
    PetscCall(PetscBLASIntCast(4 * m * m + 8 * m, &lwork));
    PetscCallBLAS("LAPACKsyev", LAPACKsyev_("V", "U", &bm, Kr, &bm, w, work2, &lwork, &info));
    PetscCheck(!info, b->comm, PETSC_ERR_LIB, "body %s: LAPACK syev of the reduced stiffness failed (info %d)", b->name, (int)info);
    PetscCall(PetscMalloc1(m, &rot));
    for (PetscInt j = 0; j < m; j++) {
      PetscScalar *c;
      PetscCall(PetscMalloc1(m, &c));
      for (PetscInt i = 0; i < m; i++) c[i] = Kr[i + m * j];
      PetscCall(VecDuplicate(Phi[0], &rot[j]));
      PetscCall(VecSet(rot[j], 0.0));
      PetscCall(VecMAXPY(rot[j], m, c, Phi));
      PetscCall(PetscFree(c));
    }
    for (PetscInt j = 0; j < m; j++) {
      PetscCall(VecDestroy(&Phi[j]));
      Phi[j] = rot[j];
    }
    PetscCall(PetscFree(rot));
    PetscCall(PetscMalloc1(m, &model->lambda));
    for (PetscInt k = 0; k < m; k++) model->lambda[k] = w[k];
    PetscCall(PetscFree3(Kr, w, work2));
  }

  /* the projected operators and the invariants */
  {
    const PetscInt     nports = b->nports;
    PetscReal         *loc, *glob;
    const PetscInt     nsum = 3 * m + 9 * m + 9 * m * m + 3 * m + 6 * m * nports;
    const PetscScalar *ta, *wa, *va;
    PetscInt           n;
    PetscCall(PetscMalloc1(m, &MPhi));
    for (PetscInt j = 0; j < m; j++) {
      PetscCall(VecDuplicate(Phi[0], &MPhi[j]));
      PetscCall(MatMult(b->Mv, Phi[j], MPhi[j]));
    }
    PetscCall(PetscCalloc2(nsum, &loc, nsum, &glob));
    PetscCall(VecGetLocalSize(Phi[0], &n));
    PetscCall(VecGetArrayRead(b->tnode, &ta));
    PetscCall(VecGetArrayRead(b->wnode, &wa));
    PetscCall(VecGetArrayRead(b->vnode, &va));
    {
      PetscReal *S = loc, *W = S + 3 * m, *N = W + 9 * m, *Sv = N + 9 * m * m, *P = Sv + 3 * m;
      for (PetscInt k = 0; k < m; k++) {
        const PetscScalar *pk, *mk;
        PetscCall(VecGetArrayRead(Phi[k], &pk));
        for (PetscInt l = 0; l < n / 3; l++)
          for (PetscInt c = 0; c < 3; c++) {
            const PetscReal phi = PetscRealPart(pk[3 * l + c]);
            S[3 * k + c] += PetscRealPart(ta[3 * l + c]) * phi;
            Sv[3 * k + c] += PetscRealPart(va[3 * l + c]) * phi;
            for (PetscInt bb = 0; bb < 3; bb++) W[9 * k + 3 * bb + c] += PetscRealPart(wa[3 * l + bb]) * phi;
          }
        for (PetscInt j = 0; j < m; j++) {
          PetscCall(VecGetArrayRead(MPhi[j], &mk));
          for (PetscInt l = 0; l < n / 3; l++)
            for (PetscInt bb = 0; bb < 3; bb++)
              for (PetscInt c = 0; c < 3; c++) N[9 * (k * m + j) + 3 * bb + c] += PetscRealPart(pk[3 * l + bb] * mk[3 * l + c]);
          PetscCall(VecRestoreArrayRead(MPhi[j], &mk));
        }
        for (PetscInt q = 0; q < nports; q++)
          for (PetscInt d = 0; d < 6; d++) {
            const PetscScalar *da;
            PetscReal          s = 0;
            PetscCall(VecGetArrayRead(b->ports[q].dist[d], &da));
            for (PetscInt i = 0; i < n; i++) s += PetscRealPart(da[i] * pk[i]);
            PetscCall(VecRestoreArrayRead(b->ports[q].dist[d], &da));
            P[6 * m * q + m * d + k] += s;
          }
        PetscCall(VecRestoreArrayRead(Phi[k], &pk));
      }
    }
    PetscCall(VecRestoreArrayRead(b->tnode, &ta));
    PetscCall(VecRestoreArrayRead(b->wnode, &wa));
    PetscCall(VecRestoreArrayRead(b->vnode, &va));
    PetscCall(MPIU_Allreduce(loc, glob, nsum, MPIU_REAL, MPI_SUM, b->comm));
    PetscCall(PetscMalloc4(m * m, &model->Mr, m * m, &model->Kr, 3 * m, &model->S, 9 * m, &model->W));
    PetscCall(PetscMalloc3(9 * m * m, &model->N, 3 * m, &model->Svol, PetscMax(6 * m * nports, 1), &model->P));
    {
      const PetscReal *S = glob, *W = S + 3 * m, *N = W + 9 * m, *Sv = N + 9 * m * m, *P = Sv + 3 * m;
      /* Mr = Phi^T Mv Phi = the trace of N; Kr diagonal (the Rayleigh-Ritz step) */
      for (PetscInt i = 0; i < m; i++)
        for (PetscInt j = 0; j < m; j++) {
          const PetscReal *Nij = N + 9 * (i * m + j);
          model->Mr[m * i + j] = Nij[0] + Nij[4] + Nij[8];
          model->Kr[m * i + j] = i == j ? model->lambda[i] : 0.0;
        }
      PetscCall(PetscArraycpy(model->S, S, 3 * m));
      PetscCall(PetscArraycpy(model->W, W, 9 * m));
      PetscCall(PetscArraycpy(model->N, N, 9 * m * m));
      PetscCall(PetscArraycpy(model->Svol, Sv, 3 * m));
      PetscCall(PetscArraycpy(model->P, P, 6 * m * nports));
    }
    PetscCall(PetscFree2(loc, glob));
    for (PetscInt j = 0; j < m; j++) PetscCall(VecDestroy(&MPhi[j]));
    PetscCall(PetscFree(MPhi));
  }
  model->nports  = b->nports;
  model->inertia = b->inertia; /* about P (a fixed body: about the inertial origin, its weight's potential) */
  /* the basis kept for the field output, with the stress recovery modes: the stress each basis vector holds,
     Psi_k = Ms^{-1} G phi_k (cell by cell, exact: the stress of the full body's displacement Phi eta is Psi eta) */
  PetscCall(PetscMalloc1(m, &model->Psi));
  for (PetscInt j = 0; j < m; j++) {
    PetscCall(DMCreateGlobalVector(b->dm_s, &model->Psi[j]));
    PetscCall(PhlexFlexibleStressOfDisplacement(b, Phi[j], model->Psi[j]));
  }
  model->Phi = Phi;
  PetscCall(PetscStrncpy(model->numbering, part->numbering, sizeof(model->numbering)));
  PetscCall(VecDestroy(&work));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexReducedModelDestroy(PhlexReducedModel *model)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree4(model->Mr, model->Kr, model->S, model->W));
  PetscCall(PetscFree3(model->N, model->Svol, model->P));
  PetscCall(PetscFree(model->lambda));
  PetscCall(PetscFree(model->lambda_full));
  for (PetscInt k = 0; k < model->m; k++) {
    if (model->Phi) PetscCall(VecDestroy(&model->Phi[k]));
    if (model->Psi) PetscCall(VecDestroy(&model->Psi[k]));
  }
  PetscCall(PetscFree(model->Phi));
  PetscCall(PetscFree(model->Psi));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* The reduced body file: HDF5, SI units, written under a temporary name and renamed                             */

/* FNV-1a, 64 bits, of a file's bytes (rank 0), and its size */
static PetscErrorCode FileHash(MPI_Comm comm, const char path[], unsigned long long *hash, long long *size)
{
  PetscMPIInt rank;
  unsigned long long h = 1469598103934665603ULL;
  long long          n = -1;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    FILE *f = fopen(path, "rb");
    if (f) {
      unsigned char buf[65536];
      size_t        k;
      n = 0;
      while ((k = fread(buf, 1, sizeof(buf), f)) > 0) {
        for (size_t i = 0; i < k; i++) h = (h ^ buf[i]) * 1099511628211ULL;
        n += (long long)k;
      }
      fclose(f);
    }
  }
  PetscCallMPI(MPI_Bcast(&h, 1, MPI_UNSIGNED_LONG_LONG, 0, comm));
  PetscCallMPI(MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm));
  *hash = h;
  *size = n;
  PetscFunctionReturn(0);
}

/*@C
  PhlexReducedProvenance - what a reduced body file is built from: the mesh (its bytes' hash), the discretisation, the
  materials, the frame, the ports and the reduction; "key=value" items separated by "; " (a file is used only for a
  body whose provenance is the same)

  Collective
@*/
PetscErrorCode PhlexReducedProvenance(PhlexPart part, const PhlexReduction *red, char buf[], size_t len)
{
  const PhlexReductionType type   = red->type;
  const PetscInt           nmodes = red->nmodes;
  PhlexFlexible      b = (PhlexFlexible)part->data;
  unsigned long long hash;
  long long          size;
  size_t             n;

  PetscFunctionBeginUser;
  PetscCall(FileHash(b->comm, b->mesh_file, &hash, &size));
  PetscCall(PetscSNPrintf(buf, len, "mesh=%016llx (%lld bytes); velocity=P%" PetscInt_FMT " (%" PetscInt_FMT " dofs); ", hash, size, b->degree, b->nv_global));
  for (PetscInt k = 0; k < b->nmaterials; k++) {
    const PhlexMaterial *mat = &b->materials[k];
    PetscCall(PetscStrlen(buf, &n));
    PetscCall(PetscSNPrintf(buf + n, len - n, "material %s=E %.15g, nu %.15g, rho %.15g; ", mat->region[0] ? mat->region : "body", (double)mat->youngs_modulus, (double)mat->poissons_ratio, (double)mat->density));
  }
  PetscCall(PetscStrlen(buf, &n));
  if (!b->floating) PetscCall(PetscSNPrintf(buf + n, len - n, "frame=fixed, clamped on %s; ", b->frame_patch));
  else if (b->frame_condition == PHLEX_FRAME_PATCH) PetscCall(PetscSNPrintf(buf + n, len - n, "frame=floating on patch %s; ", b->frame_patch));
  else PetscCall(PetscSNPrintf(buf + n, len - n, "frame=floating on mean axes, origin %.15g,%.15g,%.15g; ", (double)b->origin[0], (double)b->origin[1], (double)b->origin[2]));
  PetscCall(PetscStrlen(buf, &n));
  PetscCall(PetscSNPrintf(buf + n, len - n, "ports="));
  for (PetscInt q = 0; q < b->nports; q++) {
    PetscCall(PetscStrlen(buf, &n));
    PetscCall(PetscSNPrintf(buf + n, len - n, "%s%s", q ? "," : "", b->ports[q].name));
  }
  PetscCall(PetscStrlen(buf, &n));
  {
    /* the normal modes are the modal analysis's (-modes_target_frequency chooses which) */
    PetscReal ft  = 0.0;
    PetscBool set = PETSC_FALSE;
    PetscCall(PetscOptionsGetReal(NULL, NULL, "-modes_target_frequency", &ft, &set));
    if (type == PHLEX_REDUCTION_KRYLOV) {
      PetscCall(PetscSNPrintf(buf + n, len - n, "; reduction=%s, %" PetscInt_FMT " block steps at ", PhlexReductionTypes[type], red->krylov_order));
      for (PetscInt i = 0; i < red->nfrequencies; i++) {
        PetscCall(PetscStrlen(buf, &n));
        PetscCall(PetscSNPrintf(buf + n, len - n, "%s%.15g", i ? "," : "", (double)red->frequencies[i]));
      }
      PetscCall(PetscStrlen(buf, &n));
      PetscCall(PetscSNPrintf(buf + n, len - n, " Hz%s", red->krylov_frame_loads ? ", with the frame's inertia loads" : ""));
    } else if (type == PHLEX_REDUCTION_CRAIG_BAMPTON && b->nports) PetscCall(PetscSNPrintf(buf + n, len - n, "; reduction=%s, %" PetscInt_FMT " fixed-interface modes from 0 Hz", PhlexReductionTypes[type], nmodes));
    else PetscCall(PetscSNPrintf(buf + n, len - n, "; reduction=%s, %" PetscInt_FMT " normal modes %s %.15g Hz", PhlexReductionTypes[type], nmodes, set ? "nearest" : "from", set ? (double)ft : 0.0));
  }
  PetscFunctionReturn(0);
}

/* the SI factor of each stored array: value_SI = value * factor */
typedef struct {
  PetscReal M, K, S, W, N, Svol, Pt, Pr, lambda, m, s0, E0, vol, svol;
  PetscReal phi, psi; /* the basis vectors (m of displacement per m of eta: 1) and their stress (Pa per m of eta) */
} ReducedScales;

static void Scales(const PhlexUnits *u, ReducedScales *f)
{
  f->M      = u->mass;
  f->K      = u->force / u->length;
  f->S      = u->mass;
  f->W      = u->mass * u->length;
  f->N      = u->mass;
  f->Svol   = u->length * u->length * u->length;
  f->Pt     = 1.0;
  f->Pr     = 1.0 / u->length;
  f->lambda = 1.0 / (u->time * u->time);
  f->m      = u->mass;
  f->s0     = u->mass * u->length;
  f->E0     = u->mass * u->length * u->length;
  f->vol    = u->length * u->length * u->length;
  f->svol   = f->vol * u->length;
  f->phi    = 1.0;
  f->psi    = u->modulus / u->length;
}

/* the basis vectors or their stress modes (scaled to SI) as datasets <group>/<name>_<k> (k from 1), each in the
   global numbering of the full body's field (a plain vector: a DM's vector would be written as a mesh field) */
static PetscErrorCode WriteVectors(PetscViewer v, const char group[], const char name[], PetscInt m, const Vec *x, PetscReal scale)
{
  Vec      y;
  PetscInt n, N;
  char     dname[64];

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(x[0], &n));
  PetscCall(VecGetSize(x[0], &N));
  PetscCall(VecCreateMPI(PetscObjectComm((PetscObject)x[0]), n, N, &y));
  PetscCall(PetscViewerHDF5PushGroup(v, group));
  for (PetscInt k = 0; k < m; k++) {
    PetscCall(VecCopy(x[k], y));
    PetscCall(VecScale(y, scale));
    PetscCall(PetscSNPrintf(dname, sizeof(dname), "%s_%" PetscInt_FMT, name, k + 1));
    PetscCall(PetscObjectSetName((PetscObject)y, dname));
    PetscCall(VecView(y, v));
  }
  PetscCall(PetscViewerHDF5PopGroup(v));
  PetscCall(VecDestroy(&y));
  PetscFunctionReturn(0);
}

static PetscErrorCode WriteScaled(PetscViewer v, const char name[], PetscInt n, const PetscReal *x, PetscReal scale)
{
  PetscReal *y;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(n, &y));
  for (PetscInt i = 0; i < n; i++) y[i] = x[i] * scale;
  PetscCall(PhlexCheckpointWriteReals(v, "/reduced", name, n, y));
  PetscCall(PetscFree(y));
  PetscFunctionReturn(0);
}

/*@C
  PhlexReducedWrite - writes a reduced model (SI) with its provenance to path (under a temporary name, renamed)

  Collective
@*/
PetscErrorCode PhlexReducedWrite(MPI_Comm comm, const char path[], const char body[], const PhlexReducedModel *md, const PhlexUnits *u, const char provenance[], const PhlexReduction *red)
{
  PetscViewer   v;
  char          tmp[PETSC_MAX_PATH_LEN], when[64];
  ReducedScales f;
  const PetscInt m = md->m, np = md->nports;
  PetscReal    *P;

  PetscFunctionBeginUser;
  Scales(u, &f);
  PetscCall(PhlexCheckpointOpenWrite(comm, path, tmp, &v));
  PetscCall(PhlexCheckpointWriteInt(v, "/", "phlex_reduced_body", 1));
  PetscCall(PhlexCheckpointWriteString(v, "/", "provenance", provenance));
  PetscCall(PhlexCheckpointWriteString(v, "/", "body", body));
  PetscCall(PetscGetDate(when, sizeof(when)));
  PetscCall(PhlexCheckpointWriteString(v, "/", "built", when));
  PetscCall(PhlexCheckpointWriteInt(v, "/reduced", "basis_size", m));
  PetscCall(PhlexCheckpointWriteInt(v, "/reduced", "normal_modes", md->nnormal));
  PetscCall(PhlexCheckpointWriteInt(v, "/reduced", "ports", np));
  PetscCall(PhlexCheckpointWriteString(v, "/reduced", "reduction", PhlexReductionTypes[red->type]));
  if (red->type == PHLEX_REDUCTION_KRYLOV) {
    PetscCall(PhlexCheckpointWriteInt(v, "/reduced", "krylov_order", red->krylov_order));
    PetscCall(PhlexCheckpointWriteReals(v, "/reduced", "krylov_frequencies", red->nfrequencies, red->frequencies)); /* Hz */
  }
  PetscCall(WriteScaled(v, "mass", m * m, md->Mr, f.M));
  PetscCall(WriteScaled(v, "stiffness", m * m, md->Kr, f.K));
  PetscCall(WriteScaled(v, "int_rho_phi", 3 * m, md->S, f.S));
  PetscCall(WriteScaled(v, "int_rho_x_phi", 9 * m, md->W, f.W));
  PetscCall(WriteScaled(v, "int_rho_phi_phi", 9 * m * m, md->N, f.N));
  PetscCall(WriteScaled(v, "int_phi", 3 * m, md->Svol, f.Svol));
  PetscCall(WriteScaled(v, "eigenvalues", m, md->lambda, f.lambda));
  PetscCall(WriteScaled(v, "full_eigenvalues", md->nnormal, md->lambda_full, f.lambda));
  PetscCall(PetscMalloc1(PetscMax(6 * m * np, 1), &P));
  for (PetscInt q = 0; q < np; q++)
    for (PetscInt d = 0; d < 6; d++)
      for (PetscInt k = 0; k < m; k++) P[6 * m * q + m * d + k] = md->P[6 * m * q + m * d + k] * (d < 3 ? f.Pt : f.Pr);
  if (np) PetscCall(PhlexCheckpointWriteReals(v, "/reduced", "port_maps", 6 * m * np, P));
  PetscCall(PetscFree(P));
  {
    const PhlexInertia *in = &md->inertia;
    PetscReal           a[1 + 3 + 9 + 1 + 3];
    a[0] = in->m * f.m;
    for (PetscInt k = 0; k < 3; k++) a[1 + k] = in->s0[k] * f.s0;
    for (PetscInt k = 0; k < 9; k++) a[4 + k] = in->E0[k] * f.E0;
    a[13] = in->vol * f.vol;
    for (PetscInt k = 0; k < 3; k++) a[14 + k] = in->svol[k] * f.svol;
    PetscCall(PhlexCheckpointWriteReals(v, "/reduced", "inertia", 17, a));
  }
  if (md->Phi) {
    /* the fields of the basis, in the numbering of the full body's unknowns of the run that built it */
    PetscInt nv, ns;
    PetscCall(VecGetSize(md->Phi[0], &nv));
    PetscCall(VecGetSize(md->Psi[0], &ns));
    PetscCall(PhlexCheckpointWriteString(v, "/reduced/basis", "numbering", md->numbering));
    PetscCall(PhlexCheckpointWriteInt(v, "/reduced/basis", "velocity_dofs", nv));
    PetscCall(PhlexCheckpointWriteInt(v, "/reduced/basis", "stress_dofs", ns));
    PetscCall(WriteVectors(v, "/reduced/basis", "phi", m, md->Phi, f.phi));
    PetscCall(WriteVectors(v, "/reduced/basis", "psi", m, md->Psi, f.psi));
  }
  PetscCall(PhlexCheckpointCommit(comm, tmp, path, &v));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReadScaled(PetscViewer v, const char path[], const char name[], PetscInt n, PetscReal *x, PetscReal scale)
{
  char      ds[128];
  PetscBool has;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(ds, sizeof(ds), "/reduced/%s", name));
  PetscCall(PetscViewerHDF5HasDataset(v, ds, &has));
  PetscCheck(has, PetscObjectComm((PetscObject)v), PETSC_ERR_FILE_UNEXPECTED, "the reduced body file '%s' lacks %s: not written by this version of phlex; delete it to rebuild", path, ds);
  PetscCall(PhlexCheckpointReadReals(v, "/reduced", name, n, x));
  for (PetscInt i = 0; i < n; i++) x[i] /= scale;
  PetscFunctionReturn(0);
}

/* the first "; "-separated item where two provenances differ */
static void FirstDifference(const char a[], const char b[], char da[], char db[], size_t len)
{
  const char *pa = a, *pb = b;
  while (*pa || *pb) {
    const char *ea = strstr(pa, "; "), *eb = strstr(pb, "; ");
    size_t      la = ea ? (size_t)(ea - pa) : strlen(pa), lb = eb ? (size_t)(eb - pb) : strlen(pb);
    if (la != lb || strncmp(pa, pb, la)) {
      snprintf(da, len, "%.*s", (int)la, pa);
      snprintf(db, len, "%.*s", (int)lb, pb);
      return;
    }
    pa = ea ? ea + 2 : pa + la;
    pb = eb ? eb + 2 : pb + lb;
  }
  da[0] = db[0] = 0;
}

/*@C
  PhlexReducedRead - reads a reduced body file, refused unless it was built for this body (provenance), into the run's
  units

  Collective
@*/
PetscErrorCode PhlexReducedRead(MPI_Comm comm, const char path[], const char who[], const char provenance[], const PhlexUnits *u, PhlexReducedModel *md)
{
  PetscViewer   v;
  PetscBool     has;
  PetscInt      version = 0, m, np, nn;
  char          stored[4096], da[1024], db[1024];
  ReducedScales f;

  PetscFunctionBeginUser;
  PetscCall(PhlexHDF5Readable(comm, path, &has));
  PetscCheck(has, comm, PETSC_ERR_USER_INPUT, "%s: the reduced body file '%s' is not an HDF5 file, or a damaged one: delete it to rebuild", who, path);
  PetscCall(PetscViewerHDF5Open(comm, path, FILE_MODE_READ, &v));
  PetscCall(PetscViewerHDF5HasAttribute(v, "/", "phlex_reduced_body", &has));
  if (has) PetscCall(PetscViewerHDF5ReadAttribute(v, "/", "phlex_reduced_body", PETSC_INT, NULL, &version));
  if (!has || version != 1) PetscCall(PetscViewerDestroy(&v));
  PetscCheck(has, comm, PETSC_ERR_USER_INPUT, "%s: '%s' is an HDF5 file but not a phlex reduced body file", who, path);
  PetscCheck(version == 1, comm, PETSC_ERR_USER_INPUT, "%s: the reduced body file '%s' has format %" PetscInt_FMT "; this phlex reads format 1: delete it to rebuild", who, path, version);
  {
    char *s = NULL;
    PetscCall(PetscViewerHDF5ReadAttribute(v, "/", "provenance", PETSC_STRING, NULL, &s));
    PetscCall(PetscStrncpy(stored, s, sizeof(stored)));
    PetscCall(PetscFree(s));
  }
  FirstDifference(stored, provenance, da, db, sizeof(da));
  if (da[0] || db[0]) PetscCall(PetscViewerDestroy(&v));
  PetscCheck(!da[0] && !db[0], comm, PETSC_ERR_USER_INPUT, "%s: the reduced body file '%s' was built for another body: %s, where the scene has %s; delete the file to rebuild it (or name another with the option -reduced_file)", who, path, da, db);
  PetscCall(PetscViewerHDF5ReadAttribute(v, "/reduced", "basis_size", PETSC_INT, NULL, &m));
  PetscCall(PetscViewerHDF5ReadAttribute(v, "/reduced", "normal_modes", PETSC_INT, NULL, &nn));
  PetscCall(PetscViewerHDF5ReadAttribute(v, "/reduced", "ports", PETSC_INT, NULL, &np));
  md->m       = m;
  md->nnormal = nn;
  md->nports  = np;
  Scales(u, &f);
  PetscCall(PetscMalloc4(m * m, &md->Mr, m * m, &md->Kr, 3 * m, &md->S, 9 * m, &md->W));
  PetscCall(PetscMalloc3(9 * m * m, &md->N, 3 * m, &md->Svol, PetscMax(6 * m * np, 1), &md->P));
  PetscCall(PetscMalloc1(m, &md->lambda));
  PetscCall(PetscMalloc1(PetscMax(nn, 1), &md->lambda_full));
  PetscCall(ReadScaled(v, path, "mass", m * m, md->Mr, f.M));
  PetscCall(ReadScaled(v, path, "stiffness", m * m, md->Kr, f.K));
  PetscCall(ReadScaled(v, path, "int_rho_phi", 3 * m, md->S, f.S));
  PetscCall(ReadScaled(v, path, "int_rho_x_phi", 9 * m, md->W, f.W));
  PetscCall(ReadScaled(v, path, "int_rho_phi_phi", 9 * m * m, md->N, f.N));
  PetscCall(ReadScaled(v, path, "int_phi", 3 * m, md->Svol, f.Svol));
  PetscCall(ReadScaled(v, path, "eigenvalues", m, md->lambda, f.lambda));
  PetscCall(ReadScaled(v, path, "full_eigenvalues", nn, md->lambda_full, f.lambda));
  if (np) {
    PetscCall(ReadScaled(v, path, "port_maps", 6 * m * np, md->P, 1.0));
    for (PetscInt q = 0; q < np; q++)
      for (PetscInt d = 3; d < 6; d++)
        for (PetscInt k = 0; k < m; k++) md->P[6 * m * q + m * d + k] /= f.Pr;
  }
  {
    PetscReal a[17];
    PetscCall(ReadScaled(v, path, "inertia", 17, a, 1.0));
    md->inertia.m = a[0] / f.m;
    for (PetscInt k = 0; k < 3; k++) md->inertia.s0[k] = a[1 + k] / f.s0;
    for (PetscInt k = 0; k < 9; k++) md->inertia.E0[k] = a[4 + k] / f.E0;
    md->inertia.vol = a[13] / f.vol;
    for (PetscInt k = 0; k < 3; k++) md->inertia.svol[k] = a[14 + k] / f.svol;
  }
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

/* the vectors <group>/<name>_<k> into new global vectors of dm, divided by scale */
static PetscErrorCode ReadVectors(PetscViewer v, DM dm, const char group[], const char name[], PetscInt m, PetscReal scale, Vec **x)
{
  Vec      y;
  PetscInt n, N;
  char     dname[64];

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(m, x));
  for (PetscInt k = 0; k < m; k++) PetscCall(DMCreateGlobalVector(dm, &(*x)[k]));
  PetscCall(VecGetLocalSize((*x)[0], &n));
  PetscCall(VecGetSize((*x)[0], &N));
  PetscCall(VecCreateMPI(PetscObjectComm((PetscObject)dm), n, N, &y));
  PetscCall(PetscViewerHDF5PushGroup(v, group));
  for (PetscInt k = 0; k < m; k++) {
    PetscCall(PetscSNPrintf(dname, sizeof(dname), "%s_%" PetscInt_FMT, name, k + 1));
    PetscCall(PetscObjectSetName((PetscObject)y, dname));
    PetscCall(VecLoad(y, v));
    {
      /* divided, as PhlexReducedModelRoundTrip does: a model read takes the bits of one built in memory */
      const PetscScalar *ya;
      PetscScalar       *xa;
      PetscCall(VecGetArrayRead(y, &ya));
      PetscCall(VecGetArray((*x)[k], &xa));
      for (PetscInt i = 0; i < n; i++) xa[i] = PetscRealPart(ya[i]) / scale;
      PetscCall(VecRestoreArray((*x)[k], &xa));
      PetscCall(VecRestoreArrayRead(y, &ya));
    }
  }
  PetscCall(PetscViewerHDF5PopGroup(v));
  PetscCall(VecDestroy(&y));
  PetscFunctionReturn(0);
}

/*@C
  PhlexReducedReadBasis - reads the basis vectors and their stress modes of a reduced body file (field output) into a
  model read from it (PhlexReducedRead), refused unless they are in the full body's numbering of its unknowns

  Collective

  Input Parameters:
+ part - the full flexible body (set up: its spaces and part->numbering)
. path - the reduced body file
- who  - "body <name>" for messages

  Notes:
  The vectors are stored in the global numbering of the run that built the file, which depends on the mesh file's node
  order, -node_order, the partitioner and the number of processes (PhlexFlexiblePlacement); a file built under another
  numbering is refused with a message (its reduced operators, which the motion needs, do not depend on it).
@*/
PetscErrorCode PhlexReducedReadBasis(PhlexPart part, const char path[], const char who[], const PhlexUnits *u, PhlexReducedModel *md)
{
  PhlexFlexible b    = (PhlexFlexible)part->data;
  MPI_Comm      comm = part->comm;
  PetscViewer   v;
  PetscBool     has, same;
  char          numbering[64];
  PetscInt      nv, ns, nv_file, ns_file;
  ReducedScales f;
  Vec           x;

  PetscFunctionBeginUser;
  if (md->Phi) PetscFunctionReturn(0);
  PetscCall(PetscViewerHDF5Open(comm, path, FILE_MODE_READ, &v));
  PetscCall(PetscViewerHDF5HasAttribute(v, "/reduced/basis", "numbering", &has));
  if (!has) PetscCall(PetscViewerDestroy(&v));
  PetscCheck(has, comm, PETSC_ERR_USER_INPUT, "%s: the reduced body file '%s' has no basis vectors (written by an earlier phlex), which the field output needs: delete the file to rebuild it, or run with -output_fields 0", who, path);
  PetscCall(PhlexCheckpointReadString(v, "/reduced/basis", "numbering", numbering, sizeof(numbering)));
  PetscCall(PetscStrcmp(numbering, part->numbering, &same));
  if (!same) PetscCall(PetscViewerDestroy(&v));
  PetscCheck(same, comm, PETSC_ERR_USER_INPUT, "%s: the reduced body file '%s' holds its basis vectors in another numbering of the body's unknowns ('%s', this run '%s'; after '@' a hash of where the unknowns are in the mesh: another number of processes, partitioner, -%snode_order or node order of the mesh file), so its fields cannot be placed on this run's mesh: delete the file to rebuild it in this run's numbering, or run with -output_fields 0 (the motion does not depend on the numbering)", who, path, numbering, part->numbering, part->prefix);
  PetscCall(PhlexCheckpointReadInt(v, "/reduced/basis", "velocity_dofs", &nv_file));
  PetscCall(PhlexCheckpointReadInt(v, "/reduced/basis", "stress_dofs", &ns_file));
  PetscCall(DMGetGlobalVector(b->dm, &x));
  PetscCall(VecGetSize(x, &nv));
  PetscCall(DMRestoreGlobalVector(b->dm, &x));
  PetscCall(DMGetGlobalVector(b->dm_s, &x));
  PetscCall(VecGetSize(x, &ns));
  PetscCall(DMRestoreGlobalVector(b->dm_s, &x));
  if (nv != nv_file || ns != ns_file) PetscCall(PetscViewerDestroy(&v));
  PetscCheck(nv == nv_file && ns == ns_file, comm, PETSC_ERR_FILE_UNEXPECTED, "%s: the reduced body file '%s' holds basis vectors of %" PetscInt_FMT " velocity and %" PetscInt_FMT " stress unknowns, the body has %" PetscInt_FMT " and %" PetscInt_FMT ": delete the file to rebuild it", who, path, nv_file, ns_file, nv, ns);
  Scales(u, &f);
  PetscCall(ReadVectors(v, b->dm, "/reduced/basis", "phi", md->m, f.phi, &md->Phi));
  PetscCall(ReadVectors(v, b->dm_s, "/reduced/basis", "psi", md->m, f.psi, &md->Psi));
  PetscCall(PetscStrncpy(md->numbering, numbering, sizeof(md->numbering)));
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

/* x <- (x scale) / scale, array by array: a model built in this run takes the bits a file written and read again
   would give it (a run that builds the file and one that reads it give the same results) */
static void RoundTrip(PetscInt n, PetscReal *x, PetscReal scale)
{
  for (PetscInt i = 0; i < n; i++) {
    volatile PetscReal y = x[i] * scale; /* stored in SI */
    x[i] = y / scale;
  }
}

/*@C
  PhlexReducedModelRoundTrip - a model built in this run rounded through its SI file values (PhlexReducedWrite, Read)
@*/
PetscErrorCode PhlexReducedModelRoundTrip(PhlexReducedModel *md, const PhlexUnits *u)
{
  ReducedScales  f;
  const PetscInt m = md->m;

  PetscFunctionBeginUser;
  Scales(u, &f);
  RoundTrip(m * m, md->Mr, f.M);
  RoundTrip(m * m, md->Kr, f.K);
  RoundTrip(3 * m, md->S, f.S);
  RoundTrip(9 * m, md->W, f.W);
  RoundTrip(9 * m * m, md->N, f.N);
  RoundTrip(3 * m, md->Svol, f.Svol);
  RoundTrip(m, md->lambda, f.lambda);
  RoundTrip(md->nnormal, md->lambda_full, f.lambda);
  for (PetscInt q = 0; q < md->nports; q++)
    for (PetscInt d = 0; d < 6; d++) RoundTrip(m, md->P + 6 * m * q + m * d, d < 3 ? f.Pt : f.Pr);
  RoundTrip(1, &md->inertia.m, f.m);
  RoundTrip(3, md->inertia.s0, f.s0);
  RoundTrip(9, md->inertia.E0, f.E0);
  RoundTrip(1, &md->inertia.vol, f.vol);
  RoundTrip(3, md->inertia.svol, f.svol);
  for (PetscInt k = 0; md->Psi && k < m; k++) {
    PetscScalar *a;
    PetscInt     n;
    PetscCall(VecGetLocalSize(md->Psi[k], &n));
    PetscCall(VecGetArray(md->Psi[k], &a));
    for (PetscInt i = 0; i < n; i++) {
      volatile PetscReal y = PetscRealPart(a[i]) * f.psi;
      a[i]                 = y / f.psi;
    }
    PetscCall(VecRestoreArray(md->Psi[k], &a));
  }
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Self-checks of the ports' transfer function: the dynamic compliance G(-w^2) = B^T (K - w^2 Mv)^{-1} B (H(i w) =
   i w G: the same relative error for w > 0, and G is H's limit over i w at 0) of the full body (sparse solves) and of
   the reduced one (P (Kr - w^2 Mr)^{-1} P^T, dense), and their moments about the Krylov expansion frequencies.       */

/* C <- (Kr - sigma Mr)^{-1} C (m x nc, column-major) */
static PetscErrorCode ReducedSolve(MPI_Comm comm, const PhlexReducedModel *md, PetscReal sigma, PetscInt nc, PetscReal *C)
{
  const PetscInt m = md->m;
  PetscReal     *A;
  PetscBLASInt   bm, bn, info, *ipiv;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(m * m, &A, m, &ipiv));
  for (PetscInt i = 0; i < m; i++)
    for (PetscInt j = 0; j < m; j++) A[i + m * j] = md->Kr[m * i + j] - sigma * md->Mr[m * i + j];
  PetscCall(PetscBLASIntCast(m, &bm));
  PetscCall(PetscBLASIntCast(nc, &bn));
  PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&bm, &bn, A, &bm, ipiv, C, &bm, &info));
  PetscCheck(!info, comm, PETSC_ERR_LIB, "the reduced dynamic stiffness is singular at this frequency (LAPACK gesv info %d)", (int)info);
  PetscCall(PetscFree2(A, ipiv));
  PetscFunctionReturn(0);
}

/* Gr = P C (nz x nz, column-major) from C (m x nz) */
static void ReducedOutputs(const PhlexReducedModel *md, const PetscReal *C, PetscReal *Gr)
{
  const PetscInt m = md->m, nz = 6 * md->nports;
  for (PetscInt a = 0; a < nz; a++)
    for (PetscInt c = 0; c < nz; c++) {
      PetscReal s = 0.0;
      for (PetscInt k = 0; k < m; k++) s += md->P[m * a + k] * C[k + m * c];
      Gr[a + nz * c] = s;
    }
}

/* max_ab |G_ab - Gr_ab| / sqrt(|G_aa G_bb|): a relative error that the ports' units (forces and moments, lengths and
   angles) do not change (G -> D G D for any diagonal scaling D) */
static PetscReal ScaledError(PetscInt nz, const PetscReal *G, const PetscReal *Gr)
{
  PetscReal e = 0.0;
  for (PetscInt a = 0; a < nz; a++)
    for (PetscInt c = 0; c < nz; c++) {
      const PetscReal s = PetscSqrtReal(PetscAbsReal(G[a + nz * a] * G[c + nz * c]));
      e                 = PetscMax(e, PetscAbsReal(G[a + nz * c] - Gr[a + nz * c]) / PetscMax(s, PETSC_SMALL * PETSC_SMALL));
    }
  return e;
}

/*@C
  PhlexReducedViewTransfer - prints the relative error of the reduced ports' transfer function against the full body's
  at given frequencies (self-check -reduction_view_transfer)

  Collective

  Input Parameters:
+ part - the full flexible body (set up)
. md   - the reduced model
. nf   - number of frequencies
- f    - the frequencies [Hz]
@*/
PetscErrorCode PhlexReducedViewTransfer(PhlexPart part, const PhlexReducedModel *md, PetscInt nf, const PetscReal f[])
{
  PhlexFlexible  b  = (PhlexFlexible)part->data;
  const PetscInt nz = 6 * b->nports, m = md->m;
  PetscReal      lambda1 = 0.0, *G, *Gr, *C;
  Vec           *X;

  PetscFunctionBeginUser;
  PetscCheck(nz > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_view_transfer: the body has no listed ports (-%sports), no transfer function", b->name, b->prefix, b->prefix);
  for (PetscInt i = 0; i < nf; i++)
    if (f[i] == 0.0) PetscCall(ReliefShift(part, &lambda1));
  PetscCall(PetscMalloc4(nz * nz, &G, nz * nz, &Gr, m * nz, &C, nz, &X));
  for (PetscInt i = 0; i < nf; i++) {
    const PetscReal omega = 2 * PETSC_PI * f[i] * part->units->time;
    ShiftedSolver   solver;
    PetscCall(ShiftedSolverCreate(part, omega * omega, lambda1, &solver));
    for (PetscInt q = 0; q < b->nports; q++)
      for (PetscInt d = 0; d < 6; d++) PetscCall(ShiftedSolverSolve(&solver, b->ports[q].dist[d], &X[6 * q + d]));
    PetscCall(InterfaceValues(b, nz, X, G));
    for (PetscInt k = 0; k < nz; k++) PetscCall(VecDestroy(&X[k]));
    PetscCall(ShiftedSolverDestroy(&solver));
    for (PetscInt a = 0; a < nz; a++)
      for (PetscInt k = 0; k < m; k++) C[k + m * a] = md->P[m * a + k];
    PetscCall(ReducedSolve(b->comm, md, omega * omega, nz, C));
    ReducedOutputs(md, C, Gr);
    PetscCall(PetscPrintf(b->comm, "body %s: ports' transfer function at %.6g Hz: reduced against full, rel. error %.2e\n", b->name, (double)f[i], (double)ScaledError(nz, G, Gr)));
  }
  PetscCall(PetscFree4(G, Gr, C, X));
  PetscFunctionReturn(0);
}

/*@C
  PhlexReducedExpectMoments - self-check of a Krylov basis (-reduction_expect_moments_rtol): at each expansion
  frequency w0 the reduced model's moments of the ports' dynamic compliance, B^T (A0^{-1} Mv)^j A0^{-1} B with
  A0 = K - w0^2 Mv (the Taylor coefficients of G in s^2 about -w0^2, up to the sign and j!), equal the full body's for
  j < 2 r (r block steps) within rtol; fails otherwise. Prints the verdict and the relative error of moment 2 r, the
  first that the basis does not match in general.

  Collective
@*/
PetscErrorCode PhlexReducedExpectMoments(PhlexPart part, const PhlexReduction *red, const PhlexReducedModel *md, PetscReal rtol)
{
  PhlexFlexible  b  = (PhlexFlexible)part->data;
  const PetscInt nz = 6 * b->nports, m = md->m, r = red->krylov_order;
  PetscReal      lambda1 = 0.0, *G, *Gr, *C, *C2;
  Vec           *X, *MX;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < red->nfrequencies; i++)
    if (red->frequencies[i] == 0.0) PetscCall(ReliefShift(part, &lambda1));
  PetscCall(PetscMalloc4(nz * nz, &G, nz * nz, &Gr, m * nz, &C, m * nz, &C2));
  PetscCall(PetscMalloc2(nz, &X, nz, &MX));
  for (PetscInt i = 0; i < red->nfrequencies; i++) {
    const PetscReal omega = 2 * PETSC_PI * red->frequencies[i] * part->units->time, sigma = omega * omega;
    ShiftedSolver   solver;
    PetscReal       worst = 0.0, last = 0.0;
    PetscCall(ShiftedSolverCreate(part, sigma, lambda1, &solver));
    for (PetscInt q = 0; q < b->nports; q++)
      for (PetscInt d = 0; d < 6; d++) PetscCall(ShiftedSolverSolve(&solver, b->ports[q].dist[d], &X[6 * q + d]));
    for (PetscInt a = 0; a < nz; a++)
      for (PetscInt k = 0; k < m; k++) C[k + m * a] = md->P[m * a + k];
    PetscCall(ReducedSolve(b->comm, md, sigma, nz, C));
    for (PetscInt j = 0; j <= 2 * r; j++) {
      PetscReal e;
      PetscCall(InterfaceValues(b, nz, X, G));
      ReducedOutputs(md, C, Gr);
      e = ScaledError(nz, G, Gr);
      PetscCall(PetscInfo(NULL, "body %s: moment %" PetscInt_FMT " at %.6g Hz: relative error %g\n", b->name, j, (double)red->frequencies[i], (double)e));
      if (j < 2 * r) {
        PetscCheck(e <= rtol, b->comm, PETSC_ERR_USER, "body %s: FAIL: moment %" PetscInt_FMT " of the ports' transfer function at %.6g Hz: relative error %.3e > tolerance %.3e (-%sreduction_expect_moments_rtol; a Krylov basis of %" PetscInt_FMT " block steps matches moments 0 to %" PetscInt_FMT ")", b->name, j, (double)red->frequencies[i], (double)e, (double)rtol, b->prefix, r, 2 * r - 1);
        worst = PetscMax(worst, e);
      } else last = e;
      if (j == 2 * r) break;
      /* the next moment: X <- A0^{-1} Mv X, C <- (Kr - sigma Mr)^{-1} Mr C */
      for (PetscInt k = 0; k < nz; k++) {
        PetscCall(VecDuplicate(X[k], &MX[k]));
        PetscCall(MatMult(b->Mv, X[k], MX[k]));
        PetscCall(VecDestroy(&X[k]));
        PetscCall(ShiftedSolverSolve(&solver, MX[k], &X[k]));
        PetscCall(VecDestroy(&MX[k]));
      }
      for (PetscInt c = 0; c < nz; c++)
        for (PetscInt a = 0; a < m; a++) {
          PetscReal s = 0.0;
          for (PetscInt k = 0; k < m; k++) s += md->Mr[m * a + k] * C[k + m * c];
          C2[a + m * c] = s;
        }
      PetscCall(PetscArraycpy(C, C2, m * nz));
      PetscCall(ReducedSolve(b->comm, md, sigma, nz, C));
    }
    PetscCall(PetscInfo(NULL, "body %s: moments 0-%" PetscInt_FMT " at %.6g Hz: largest relative error %g\n", b->name, 2 * r - 1, (double)red->frequencies[i], (double)worst));
    PetscCall(PetscPrintf(b->comm, "body %s: moments 0-%" PetscInt_FMT " of the ports' transfer function at %.6g Hz: PASS (rel. error <= %.0e); moment %" PetscInt_FMT ": rel. error %.2e\n", b->name, 2 * r - 1, (double)red->frequencies[i], (double)rtol, 2 * r, (double)last));
    for (PetscInt k = 0; k < nz; k++) PetscCall(VecDestroy(&X[k]));
    PetscCall(ShiftedSolverDestroy(&solver));
  }
  PetscCall(PetscFree4(G, Gr, C, C2));
  PetscCall(PetscFree2(X, MX));
  PetscFunctionReturn(0);
}
