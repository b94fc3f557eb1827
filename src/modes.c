/* Modal analysis with SLEPc: the symmetric-definite pencil (K, Mv) of the velocity after exact stress elimination
   (K = G^T Ms^{-1} G element by element), shift-and-invert, EPS options under the prefix modes_. */
#include <phlex_impl.h>

/* Lowest free-free bending frequency of a beam with the body's bounding box (non-dimensional, rad per unit time):
   a scale for the shift of free bodies and for telling rigid modes from elastic ones. */
static PetscReal FrequencyScale(PhlexBody b, const PhlexUnits *u)
{
  PetscReal L = 0, t = PETSC_MAX_REAL, c = PETSC_MAX_REAL;

  for (PetscInt d = 0; d < 3; d++) {
    L = PetscMax(L, b->bbox_max[d] - b->bbox_min[d]);
    t = PetscMin(t, b->bbox_max[d] - b->bbox_min[d]);
  }
  for (PetscInt m = 0; m < b->nmaterials; m++) c = PetscMin(c, PetscSqrtReal(b->materials[m].youngs_modulus / b->materials[m].density));
  /* (4.730)^2 t / (sqrt(12) L^2) c, in units of 1/T */
  return 22.373 * t / (PetscSqrtReal(12.0) * L * L) * c * u->time;
}

/* The pencil of a floating body linearised at rest (paper: the mass operator of eq. momenta at u_f = 0, w = 0):
   unknowns [v | v_P, w_P] (the six rigid ones on rank 0),
     A = [[K, 0], [0, 0]],   B = [[Mv, Bm], [Bm^T, M6]],   M6 = [[m I, -[s0]x], [[s0]x, J0]],
   Bm = [t e_c | e_a x w] (nodal t = int rho phi, w = int rho x phi): the kinetic energy of v_P + w x x + v. The
   rigid unknowns make six zero eigenvalues; the others are the free-free modes with the frame patch moving
   rigidly. Assembled as AIJ (six dense rows and columns) so that any shift and factorisation apply. */
static PetscErrorCode FloatingPencil(PhlexBody b, Mat *A, Mat *B, IS is[2])
{
  MPI_Comm           comm = b->comm;
  PetscMPIInt        rank;
  PetscInt           n = b->nv_local, q, ld;
  Mat                blocks[4], Kaij, Maij, Bm, BmT, M6, Z6, N;
  const PetscScalar *ta, *wa;
  PetscScalar       *ba;
  const PhlexInertia *in = &b->inertia;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  q = rank == 0 ? 6 : 0;
  PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &Kaij));
  PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &Maij));
  PetscCall(MatCreateDense(comm, n, q, PETSC_DETERMINE, 6, NULL, &Bm));
  PetscCall(MatDenseGetLDA(Bm, &ld));
  PetscCall(MatDenseGetArrayWrite(Bm, &ba));
  PetscCall(VecGetArrayRead(b->tnode, &ta));
  PetscCall(VecGetArrayRead(b->wnode, &wa));
  for (PetscInt l = 0; l < n / 3; l++) {
    const PetscReal *w = (const PetscReal *)&wa[3 * l]; /* real build */
    for (PetscInt c = 0; c < 3; c++) {
      for (PetscInt j = 0; j < 3; j++) ba[j * ld + 3 * l + c] = c == j ? ta[3 * l + c] : 0.0;
      /* (e_a x w)_c */
      ba[3 * ld + 3 * l + c] = c == 0 ? 0.0 : (c == 1 ? -w[2] : w[1]);
      ba[4 * ld + 3 * l + c] = c == 0 ? w[2] : (c == 1 ? 0.0 : -w[0]);
      ba[5 * ld + 3 * l + c] = c == 0 ? -w[1] : (c == 1 ? w[0] : 0.0);
    }
  }
  PetscCall(VecRestoreArrayRead(b->tnode, &ta));
  PetscCall(VecRestoreArrayRead(b->wnode, &wa));
  PetscCall(MatDenseRestoreArrayWrite(Bm, &ba));
  PetscCall(MatAssemblyBegin(Bm, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(Bm, MAT_FINAL_ASSEMBLY));
  PetscCall(MatTranspose(Bm, MAT_INITIAL_MATRIX, &BmT));
  PetscCall(MatCreateAIJ(comm, q, q, 6, 6, 6, NULL, 0, NULL, &M6));
  PetscCall(MatCreateAIJ(comm, q, q, 6, 6, 0, NULL, 0, NULL, &Z6));
  if (rank == 0) {
    PetscReal m6[36], S[9], J[9];
    PetscInt  idx[6] = {0, 1, 2, 3, 4, 5};
    const PetscReal tr = in->E0[0] + in->E0[4] + in->E0[8];
    PhlexSkew(in->s0, S);
    for (PetscInt k = 0; k < 9; k++) J[k] = (k % 4 == 0 ? tr : 0.0) - in->E0[k];
    for (PetscInt i = 0; i < 3; i++)
      for (PetscInt j = 0; j < 3; j++) {
        m6[6 * i + j]           = i == j ? in->m : 0.0;
        m6[6 * i + 3 + j]       = -S[3 * i + j];
        m6[6 * (3 + i) + j]     = S[3 * i + j];
        m6[6 * (3 + i) + 3 + j] = J[3 * i + j];
      }
    PetscCall(MatSetValues(M6, 6, idx, 6, idx, m6, INSERT_VALUES));
  }
  PetscCall(MatAssemblyBegin(M6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(M6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(Z6, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(Z6, MAT_FINAL_ASSEMBLY));
  blocks[0] = Kaij, blocks[1] = NULL, blocks[2] = NULL, blocks[3] = Z6;
  PetscCall(MatCreateNest(comm, 2, NULL, 2, NULL, blocks, &N));
  PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, A));
  PetscCall(MatNestGetISs(N, is, NULL));
  PetscCall(PetscObjectReference((PetscObject)is[0]));
  PetscCall(PetscObjectReference((PetscObject)is[1]));
  PetscCall(MatDestroy(&N));
  blocks[0] = Maij, blocks[1] = Bm, blocks[2] = BmT, blocks[3] = M6;
  PetscCall(MatCreateNest(comm, 2, NULL, 2, NULL, blocks, &N));
  PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, B));
  PetscCall(MatDestroy(&N));
  PetscCall(MatSetOption(*A, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(*B, MAT_SPD, PETSC_TRUE));
  PetscCall(MatDestroy(&Kaij));
  PetscCall(MatDestroy(&Maij));
  PetscCall(MatDestroy(&Bm));
  PetscCall(MatDestroy(&BmT));
  PetscCall(MatDestroy(&M6));
  PetscCall(MatDestroy(&Z6));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBodyComputeModes - lowest eigenpairs of K x = lambda Mv x of a body (non-dimensional lambda = omega^2)

  Collective

  Input Parameters:
+ b     - the body
. units - scales
- nev   - number of elastic modes wanted (the six rigid modes of a free body come on top)

  Output Parameters:
+ nconv  - number of eigenpairs returned
. nrigid - how many of them are rigid-body modes (|lambda| below 1e-6 of the elastic frequency scale squared)
. lambda - eigenvalues (ascending)
. vecs   - eigenvectors (Mv-normalised; the elastic part of a floating body's), may be NULL
. rigid  - floating body: the rigid part (v_P, w_P) of each eigenvector, 6 per mode, on every rank; may be NULL
- resid  - relative residual norms ||K x - lambda Mv x|| / (|lambda| ||x||) (rigid modes: the backward error
           ||K x - lambda Mv x|| / ((||K|| + |lambda| ||Mv||) ||x||)), may be NULL

  Notes:
  A floating body is solved on the pencil of its linearisation at rest (FloatingPencil): six rigid modes, then the
  free-free modes.

  Options Database Keys:
+ -modes_eps_nev <n>              - number of eigenpairs (default nev, +6 for a free body)
. -modes_target_frequency <Hz>    - look for modes nearest this frequency (default: lowest)
- -modes_eps_*, -modes_st_*       - any SLEPc EPS/ST option; defaults: Krylov-Schur, shift-and-invert, Cholesky (MUMPS)
@*/
PetscErrorCode PhlexBodyComputeModes(PhlexBody b, const PhlexUnits *units, PetscInt nev, PetscInt *nconv, PetscInt *nrigid, PetscReal **lambda, Vec **vecs, PetscReal **rigid, PetscReal **resid)
{
  EPS       eps;
  ST        st;
  KSP       ksp;
  PC        pc;
  PetscReal omega = FrequencyScale(b, units), sigma, ftarget = -1;
  PetscBool free_body = (!b->frame_patch[0] || b->floating) ? PETSC_TRUE : PETSC_FALSE, flg;
  PetscInt  n, want;
  Mat       A = b->K, B = b->Mv;
  IS        is[2] = {NULL, NULL};
  Vec       x = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  want  = nev + (free_body ? 6 : 0);
  sigma = free_body ? -PetscSqr(1e-2 * omega) : 0.0;
  PetscCall(PetscOptionsGetReal(NULL, "modes_", "-target_frequency", &ftarget, &flg));
  if (flg) {
    PetscCheck(ftarget >= 0, b->comm, PETSC_ERR_USER_INPUT, "-modes_target_frequency must be >= 0 Hz, got %g", (double)ftarget);
    sigma = PetscSqr(2.0 * PETSC_PI * ftarget * units->time);
    if (sigma == 0 && free_body) sigma = -PetscSqr(1e-2 * omega);
  }
  PetscCall(EPSCreate(b->comm, &eps));
  PetscCall(EPSSetOptionsPrefix(eps, "modes_"));
  if (b->floating) PetscCall(FloatingPencil(b, &A, &B, is));
  PetscCall(EPSSetOperators(eps, A, B));
  PetscCall(EPSSetProblemType(eps, EPS_GHEP));
  PetscCall(EPSSetType(eps, EPSKRYLOVSCHUR));
  PetscCall(EPSSetDimensions(eps, want, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSSetTarget(eps, sigma));
  PetscCall(EPSSetTolerances(eps, 1e-12, PETSC_DEFAULT));
  /* B (the velocity mass, or the body's whole kinetic-energy matrix when floating) is positive definite, so the
     shift-and-invert eigenvectors carry no null-space component to purify; purification costs one more solve per
     eigenvector (a fifth of the run at 2.2e5 dofs, BENCHMARKS.md) and changed no digit. -modes_eps_purify 1 restores it. */
  PetscCall(EPSSetPurify(eps, PETSC_FALSE));
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, PCCHOLESKY));
  if (PetscDefined(HAVE_MUMPS)) PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  PetscCall(EPSSetFromOptions(eps));
  PetscCall(EPSSolve(eps));
  PetscCall(EPSGetDimensions(eps, &want, NULL, NULL));
  PetscCall(EPSGetConverged(eps, &n));
  n = PetscMin(n, want);
  PetscCall(PetscMalloc1(n, lambda));
  if (resid) PetscCall(PetscMalloc1(n, resid));
  if (vecs) PetscCall(PetscMalloc1(n, vecs));
  if (rigid) PetscCall(PetscCalloc1(6 * n, rigid));
  PetscCall(MatCreateVecs(A, &x, NULL));
  *nrigid = 0;
  for (PetscInt i = 0; i < n; i++) {
    PetscScalar kr, ki;
    PetscCall(EPSGetEigenpair(eps, i, &kr, &ki, x, NULL));
    (*lambda)[i] = PetscRealPart(kr);
    if (PetscAbsReal((*lambda)[i]) < 1e-6 * omega * omega) {
      (*nrigid)++;
      /* lambda ~ 0: the relative residual divides by |lambda|; report the backward error instead */
      if (resid) PetscCall(EPSComputeError(eps, i, EPS_ERROR_BACKWARD, &(*resid)[i]));
    } else if (resid) PetscCall(EPSComputeError(eps, i, EPS_ERROR_RELATIVE, &(*resid)[i]));
    if (vecs) PetscCall(MatCreateVecs(b->K, &(*vecs)[i], NULL));
    if (!b->floating) {
      if (vecs) PetscCall(VecCopy(x, (*vecs)[i]));
    } else {
      Vec                xv, xq;
      const PetscScalar *qa;
      PetscReal          q6[6] = {0, 0, 0, 0, 0, 0};
      PetscInt           nq;
      PetscCall(VecGetSubVector(x, is[0], &xv));
      if (vecs) PetscCall(VecCopy(xv, (*vecs)[i]));
      PetscCall(VecRestoreSubVector(x, is[0], &xv));
      PetscCall(VecGetSubVector(x, is[1], &xq));
      PetscCall(VecGetLocalSize(xq, &nq));
      PetscCall(VecGetArrayRead(xq, &qa));
      for (PetscInt k = 0; k < nq; k++) q6[k] = PetscRealPart(qa[k]);
      PetscCall(VecRestoreArrayRead(xq, &qa));
      PetscCall(VecRestoreSubVector(x, is[1], &xq));
      PetscCallMPI(MPI_Bcast(q6, 6, MPIU_REAL, 0, b->comm));
      if (rigid) PetscCall(PetscArraycpy(&(*rigid)[6 * i], q6, 6));
    }
  }
  PetscCall(VecDestroy(&x));
  if (b->floating) {
    PetscCall(MatDestroy(&A));
    PetscCall(MatDestroy(&B));
    PetscCall(ISDestroy(&is[0]));
    PetscCall(ISDestroy(&is[1]));
  }
  *nconv = n;
  PetscCall(EPSDestroy(&eps));
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscReal Frequency(PetscReal lambda, const PhlexUnits *u)
{
  const PetscReal f = PetscSqrtReal(PetscAbsReal(lambda)) / (2.0 * PETSC_PI * u->time);
  return lambda < 0 ? -f : f;
}

/* -modes_convergence_refinements n: the elastic frequencies of the scene's body on n further uniform refinements
   of its mesh, the observed order of the eigenvalues p = log2((l0 - l1)/(l1 - l2)) over the last three levels
   (expected 2k for P_k) and the Richardson-extrapolated frequencies. */
static PetscErrorCode ConvergenceStudy(PhlexScene scene, PetscInt nlevels, PetscInt nmodes, const PetscReal *lambda0, PetscInt nrigid0)
{
  PhlexBody  b = scene->bodies[0];
  PetscReal *lam, order_expect = -1, order_tol = 0.25, worst = 0;
  PetscInt   worst_mode = -1;

  PetscFunctionBeginUser;
  PetscOptionsBegin(scene->comm, NULL, "Convergence study options", NULL);
  PetscCall(PetscOptionsReal("-expect_convergence_order", "Self-check: expected observed order of the eigenvalues", "PhlexSceneSolveModes", order_expect, &order_expect, NULL));
  PetscCall(PetscOptionsReal("-expect_convergence_order_tol", "Tolerance of that check (absolute, on the order)", "PhlexSceneSolveModes", order_tol, &order_tol, NULL));
  PetscOptionsEnd();
  PetscCall(PetscCalloc1((nlevels + 1) * nmodes, &lam));
  for (PetscInt m = 0; m < nmodes; m++) lam[m] = lambda0[nrigid0 + m];
  for (PetscInt l = 1; l <= nlevels; l++) {
    PhlexBody  r;
    PetscInt   nconv, nrigid;
    PetscReal *lr;
    PetscCall(PhlexBodyCreate(scene->comm, b->index, &r));
    PetscCall(PhlexBodySetFromOptions(r));
    r->extra_refinements = l;
    PetscCall(PhlexBodySetUp(r, &scene->units));
    PetscCall(PhlexBodyComputeModes(r, &scene->units, nmodes, &nconv, &nrigid, &lr, NULL, NULL, NULL));
    PetscCheck(nconv - nrigid >= nmodes, scene->comm, PETSC_ERR_NOT_CONVERGED, "convergence study: only %" PetscInt_FMT " modes on refinement level %" PetscInt_FMT, nconv - nrigid, l);
    for (PetscInt m = 0; m < nmodes; m++) lam[l * nmodes + m] = lr[nrigid + m];
    PetscCall(PetscFree(lr));
    PetscCall(PhlexBodyDestroy(&r));
  }
  PetscCall(PetscPrintf(scene->comm, "Convergence under uniform refinement (P%" PetscInt_FMT " velocity; eigenvalue order expected %" PetscInt_FMT "):\n  mode", b->degree, 2 * b->degree));
  for (PetscInt l = 0; l <= nlevels; l++) PetscCall(PetscPrintf(scene->comm, "   level %" PetscInt_FMT " [Hz]", l));
  PetscCall(PetscPrintf(scene->comm, "   order   extrapolated [Hz]\n"));
  for (PetscInt m = 0; m < nmodes; m++) {
    PetscReal order = 0, ext;
    PetscCall(PetscPrintf(scene->comm, "  %4" PetscInt_FMT, m + 1));
    for (PetscInt l = 0; l <= nlevels; l++) PetscCall(PetscPrintf(scene->comm, "  %13.8g", (double)Frequency(lam[l * nmodes + m], &scene->units)));
    if (nlevels >= 2) {
      const PetscReal l0 = lam[(nlevels - 2) * nmodes + m], l1 = lam[(nlevels - 1) * nmodes + m], l2 = lam[nlevels * nmodes + m];
      order = PetscLog2Real((l0 - l1) / (l1 - l2));
      ext   = l2 - (l1 - l2) / (PetscPowReal(2.0, order) - 1.0);
      PetscCall(PetscPrintf(scene->comm, "  %6.2f  %13.8g\n", (double)order, (double)Frequency(ext, &scene->units)));
      if (PetscAbsReal(order - order_expect) > worst) {
        worst      = PetscAbsReal(order - order_expect);
        worst_mode = m;
      }
    } else PetscCall(PetscPrintf(scene->comm, "\n"));
  }
  if (order_expect > 0) {
    PetscCheck(nlevels >= 2, scene->comm, PETSC_ERR_USER_INPUT, "-expect_convergence_order needs -modes_convergence_refinements >= 2");
    PetscCheck(worst <= order_tol, scene->comm, PETSC_ERR_USER, "convergence order: FAIL: mode %" PetscInt_FMT " has observed order differing from %g by %.3g > %g (-expect_convergence_order_tol)", worst_mode + 1, (double)order_expect, (double)worst, (double)order_tol);
    PetscCall(PetscPrintf(scene->comm, "convergence order: PASS (%" PetscInt_FMT " modes within %g of %g)\n", nmodes, (double)order_tol, (double)order_expect));
  }
  PetscCall(PetscFree(lam));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSolveModes - modal analysis of the scene's body: prints and writes frequencies, residuals, mode shapes

  Collective

  Options Database Keys:
+ -modes_nev <n>                        - elastic modes wanted (default 10)
. -modes_convergence_refinements <n>    - also solve on n uniform refinements and report the observed order
. -expect_convergence_order <p>         - self-check of that order (with -expect_convergence_order_tol)
. -expect_frequencies f1,f2,...         - expected elastic frequencies [Hz] (self-check)
. -expect_frequencies_rtol <r>          - relative tolerance of that check (default 1e-6)
- -expect_residual_max <r>              - bound on the relative eigenpair residuals
@*/
PetscErrorCode PhlexSceneSolveModes(PhlexScene scene)
{
  PhlexBody        b = scene->bodies[0];
  PetscInt         nev = 10, nconv, nrigid, nexp = 64, nrefine = 0;
  PetscReal       *lambda, *resid, *freq, *rigid, expected[64], rtol = 1e-6, rmax = -1, worst = 0;
  Vec             *vecs;
  PetscBool        has_exp;
  PetscViewer      csv;
  PhlexFieldWriter fw = NULL;

  PetscFunctionBeginUser;
  PetscOptionsBegin(scene->comm, NULL, "Modal analysis options", NULL);
  PetscCall(PetscOptionsInt("-modes_nev", "Number of elastic modes wanted", "PhlexSceneSolveModes", nev, &nev, NULL));
  PetscCall(PetscOptionsRealArray("-expect_frequencies", "Expected elastic frequencies [Hz] (self-check)", "PhlexSceneSolveModes", expected, &nexp, &has_exp));
  PetscCall(PetscOptionsReal("-expect_frequencies_rtol", "Relative tolerance of -expect_frequencies", "PhlexSceneSolveModes", rtol, &rtol, NULL));
  PetscCall(PetscOptionsReal("-expect_residual_max", "Bound on the relative eigenpair residuals (self-check)", "PhlexSceneSolveModes", rmax, &rmax, NULL));
  PetscCall(PetscOptionsInt("-modes_convergence_refinements", "Also solve on this many uniform refinements and report the observed order", "PhlexSceneSolveModes", nrefine, &nrefine, NULL));
  PetscOptionsEnd();
  PetscCheck(nev >= 1, scene->comm, PETSC_ERR_USER_INPUT, "-modes_nev must be >= 1, got %" PetscInt_FMT, nev);
  if (!has_exp) nexp = 0;

  PetscCall(PetscLogStagePush(PHLEX_StageModes));
  PetscCall(PhlexBodyComputeModes(b, &scene->units, nev, &nconv, &nrigid, &lambda, &vecs, &rigid, &resid));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscMalloc1(nconv, &freq));
  for (PetscInt i = 0; i < nconv; i++) freq[i] = Frequency(lambda[i], &scene->units);

  PetscCall(PetscPrintf(scene->comm, "Modes of body %s (%s): %" PetscInt_FMT " computed", b->name, b->floating ? "floating" : (b->frame_patch[0] ? "clamped" : "free"), nconv));
  if (!b->frame_patch[0] || b->floating) PetscCall(PetscPrintf(scene->comm, ", %" PetscInt_FMT " rigid-body modes", nrigid));
  PetscCall(PetscPrintf(scene->comm, "\n  mode  frequency [Hz]       kind     rel. residual\n"));
  for (PetscInt i = 0; i < nconv; i++) {
    PetscCall(PetscPrintf(scene->comm, "  %4" PetscInt_FMT "  %-18.10g   %-7s  %.1e\n", i + 1, (double)(i < nrigid ? 0.0 : freq[i]), i < nrigid ? "rigid" : "elastic", (double)resid[i]));
    if (i >= nrigid) worst = PetscMax(worst, resid[i]); /* rigid modes: backward error, not checked */
  }
  PetscCheck((b->frame_patch[0] && !b->floating) || nrigid == 6, scene->comm, PETSC_ERR_NOT_CONVERGED, "body %s is free but %" PetscInt_FMT " rigid-body modes were found instead of 6", b->name, nrigid);

  PetscCall(PhlexOutputCSVOpen(scene->output, "modes.csv", "mode,frequency_hz,eigenvalue_rad2_s2,relative_residual,rigid", &csv));
  for (PetscInt i = 0; i < nconv; i++) {
    const PetscReal lam = lambda[i] / PetscSqr(scene->units.time);
    PetscCall(PetscViewerASCIIPrintf(csv, "%" PetscInt_FMT ",%.12e,%.12e,%.12e,%d\n", i + 1, (double)freq[i], (double)lam, (double)resid[i], i < nrigid ? 1 : 0));
  }
  PetscCall(PetscViewerDestroy(&csv));
  if (scene->output->fields) {
    char name[PHLEX_NAME_LEN + 8];
    PetscCall(PetscSNPrintf(name, sizeof(name), "%s_modes", b->name));
    PetscCall(PhlexFieldWriterCreate(scene->output, b, name, &fw));
    for (PetscInt i = 0; i < nconv; i++) {
      PetscReal vmax, A[9] = {0}, r[3] = {0}, *Ap = NULL, *rp = NULL;
      if (b->floating) {
        /* the whole velocity field v_P + w x (x - P) + v: the frame patch moves rigidly */
        const PetscReal *q = &rigid[6 * i];
        PetscReal        wP[3];
        PhlexSkew(&q[3], A);
        for (PetscInt k = 0; k < 9; k++) A[k] /= scene->units.length;
        PhlexMatVec3(A, b->origin, wP);
        for (PetscInt k = 0; k < 3; k++) r[k] = q[k] - wP[k];
        Ap = A, rp = r;
      }
      PetscCall(PhlexFieldWriterVertexMax(fw, vecs[i], 1.0, Ap, rp, PETSC_FALSE, &vmax));
      if (vmax > 0) {
        for (PetscInt k = 0; k < 9; k++) A[k] /= vmax;
        for (PetscInt k = 0; k < 3; k++) r[k] /= vmax;
      }
      PetscCall(PhlexFieldWriterBeginStep(fw, (PetscReal)(i + 1)));
      PetscCall(PhlexFieldWriterVertexField(fw, "mode_shape", vecs[i], vmax > 0 ? 1.0 / vmax : 1.0, Ap, rp, PETSC_FALSE));
    }
    PetscCall(PhlexFieldWriterDestroy(&fw));
  }
  PetscCall(PhlexOutputCommit(scene->output));

  if (nrefine > 0) PetscCall(ConvergenceStudy(scene, nrefine, PetscMin(nev, nconv - nrigid), lambda, nrigid));
  if (rmax > 0) PetscCall(PhlexExpectMax(scene->comm, "eigenpair residuals (max relative)", "-expect_residual_max", worst, rmax, PETSC_TRUE));
  if (nexp) PetscCall(PhlexExpectValues(scene->comm, "elastic frequencies", "-expect_frequencies", nconv - nrigid, freq + nrigid, nexp, expected, rtol));

  for (PetscInt i = 0; i < nconv; i++) PetscCall(VecDestroy(&vecs[i]));
  PetscCall(PetscFree(vecs));
  PetscCall(PetscFree(rigid));
  PetscCall(PetscFree(lambda));
  PetscCall(PetscFree(resid));
  PetscCall(PetscFree(freq));
  PetscFunctionReturn(0);
}
