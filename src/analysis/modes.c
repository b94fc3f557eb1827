/* Modal analysis of a scene: the modes of each body that has them (part operation modes: a flexible body's free,
   clamped or floating spectrum), their frequencies, residuals, self-checks, a convergence study under refinement and
   the mode shapes for ParaView. The linearised modes of a whole mechanism are a separate analysis. */
#include <phlex_impl.h>

static PetscReal Frequency(PetscReal lambda, const PhlexUnits *u)
{
  const PetscReal f = PetscSqrtReal(PetscAbsReal(lambda)) / (2.0 * PETSC_PI * u->time);
  return lambda < 0 ? -f : f;
}

/* -modes_convergence_refinements n: the elastic frequencies of a body on n further uniform refinements of its
   discretisation, the observed order of the eigenvalues p = log2((l0 - l1)/(l1 - l2)) over the last three levels
   (2k for P_k elements) and the Richardson-extrapolated frequencies. */
/* the options of the modal analysis (the eigensolver's are read by PhlexModesEPSCreate and EPSSetFromOptions) */
typedef struct {
  PetscInt  nev, nexp, nrefine;
  PetscReal expected[65], rtol, rmax, order_expect, order_tol; /* 64 values and room for one more: a longer list is refused */
  PetscBool has_exp;
} ModesOptions;

static PetscErrorCode ModesSetFromOptions(MPI_Comm comm, ModesOptions *o)
{
  PetscFunctionBeginUser;
  o->nev          = 10;
  o->nexp         = 65;
  o->nrefine      = 0;
  o->rtol         = 1e-6;
  o->rmax         = -1;
  o->order_expect = -1;
  o->order_tol    = 0.25;
  PetscCall(PetscArrayzero(o->expected, 65));
  PetscOptionsBegin(comm, NULL, "Modal analysis options", NULL);
  PetscCall(PetscOptionsInt("-modes_nev", "Number of elastic modes wanted", "PhlexSceneSolveModes", o->nev, &o->nev, NULL));
  PetscCall(PhlexOptionsRealList("-expect_frequencies", "Expected elastic frequencies [Hz] (self-check)", "PhlexSceneSolveModes", o->expected, &o->nexp, &o->has_exp, 0));
  PetscCall(PetscOptionsReal("-expect_frequencies_rtol", "Relative tolerance of -expect_frequencies", "PhlexSceneSolveModes", o->rtol, &o->rtol, NULL));
  PetscCall(PetscOptionsReal("-expect_residual_max", "Bound on the relative eigenpair residuals (self-check)", "PhlexSceneSolveModes", o->rmax, &o->rmax, NULL));
  PetscCall(PetscOptionsInt("-modes_convergence_refinements", "Also solve on this many uniform refinements and report the observed order", "PhlexSceneSolveModes", o->nrefine, &o->nrefine, NULL));
  PetscCall(PetscOptionsReal("-expect_convergence_order", "Self-check: expected observed order of the eigenvalues", "PhlexSceneSolveModes", o->order_expect, &o->order_expect, NULL));
  PetscCall(PetscOptionsReal("-expect_convergence_order_tol", "Tolerance of that check (absolute, on the order)", "PhlexSceneSolveModes", o->order_tol, &o->order_tol, NULL));
  PetscOptionsEnd();
  PetscCheck(o->nev >= 1, comm, PETSC_ERR_USER_INPUT, "-modes_nev must be >= 1, got %" PetscInt_FMT, o->nev);
  if (!o->has_exp) o->nexp = 0;
  PetscCheck(o->nexp <= 64, comm, PETSC_ERR_USER_INPUT, "-expect_frequencies: at most 64 values");
  PetscFunctionReturn(0);
}

/* with p-multigrid in the shift-and-invert solves (-modes_st_pc_type mg), its levels' options (-modes_st_mg_*),
   which PCMG reads only once its levels exist */
static PetscErrorCode ModesPMGLevelsOptions(EPS eps)
{
  ST        st;
  KSP       ksp;
  PetscBool mg;

  PetscFunctionBeginUser;
  PetscCall(EPSGetST(eps, &st));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(PhlexPMGWanted(ksp, &mg));
  if (mg) PetscCall(PhlexPMGSetLevels(ksp));
  PetscFunctionReturn(0);
}

/* every option of a modal run read once more (PhlexOptionsCheckUnused collects the valid names): the scene's, the
   analysis', the eigensolver's */
PetscErrorCode PhlexModesRereadOptions(void *ctx)
{
  MPI_Comm     comm = *(MPI_Comm *)ctx;
  ModesOptions o;
  EPS          eps;
  PetscReal    ftarget = -1;
  PetscBool    flg;

  PetscFunctionBeginUser;
  PetscCall(PhlexSceneReadOptions(comm));
  PetscCall(ModesSetFromOptions(comm, &o));
  PetscCall(PhlexModesEPSCreate(comm, &eps, &ftarget, &flg));
  PetscCall(EPSSetFromOptions(eps));
  PetscCall(ModesPMGLevelsOptions(eps));
  PetscCall(EPSDestroy(&eps));
  PetscFunctionReturn(0);
}

static PetscErrorCode ConvergenceStudy(PhlexScene scene, PhlexPart part, PetscInt nlevels, PetscInt nmodes, const PetscReal *lambda0, PetscInt nrigid0, PetscReal order_expect, PetscReal order_tol)
{
  PetscReal *lam, worst = 0;
  PetscInt   worst_mode = -1;

  PetscFunctionBeginUser;
  PetscCall(PetscCalloc1((nlevels + 1) * nmodes, &lam));
  for (PetscInt m = 0; m < nmodes; m++) lam[m] = lambda0[nrigid0 + m];
  for (PetscInt l = 1; l <= nlevels; l++) {
    PhlexPart  r;
    PetscInt   nconv, nrigid;
    PetscReal *lr;
    PetscCall((*part->analysisops->refine)(part, l, &r));
    PetscCall((*r->analysisops->modes)(r, nmodes, &nconv, &nrigid, &lr, NULL, NULL, NULL));
    PetscCheck(nconv - nrigid >= nmodes, scene->comm, PETSC_ERR_NOT_CONVERGED, "convergence study: only %" PetscInt_FMT " modes on refinement level %" PetscInt_FMT, nconv - nrigid, l);
    for (PetscInt m = 0; m < nmodes; m++) lam[l * nmodes + m] = lr[nrigid + m];
    PetscCall(PetscFree(lr));
    PetscCall(PhlexPartDestroy(&r));
  }
  {
    char what[128] = "";
    if (PhlexPartAnalysisOp(part, modesorder)) PetscCall((*part->analysisops->modesorder)(part, what, sizeof(what)));
    PetscCall(PetscPrintf(scene->comm, "Convergence under uniform refinement (%s):\n  mode", what));
  }
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
  PhlexSceneSolveModes - modal analysis: the modes of every body that has them; prints and writes frequencies,
  residuals, mode shapes; self-checks

  Collective

  Options Database Keys:
+ -modes_nev <n>                        - elastic modes wanted (default 10)
. -modes_convergence_refinements <n>    - also solve on n uniform refinements and report the observed order
. -expect_convergence_order <p>         - self-check of that order (with -expect_convergence_order_tol)
. -expect_frequencies f1,f2,...         - expected elastic frequencies [Hz] (self-check; one body)
. -expect_frequencies_rtol <r>          - relative tolerance of that check (default 1e-6)
- -expect_residual_max <r>              - bound on the relative eigenpair residuals

  Notes:
  modes.csv holds the modes of every body, one row per mode with the body's name in the column body.
@*/
PetscErrorCode PhlexSceneSolveModes(PhlexScene scene)
{
  ModesOptions o;
  PetscInt     nbodies = 0, nfexp = 0, nev, nexp;
  PetscReal    worst = 0, *fexp = NULL;
  PetscViewer  csv;

  PetscFunctionBeginUser;
  PetscCall(ModesSetFromOptions(scene->comm, &o));
  nev  = o.nev;
  nexp = o.nexp;
  {
    /* the eigensolver's options, read (and printed by -help solvers) before any solve */
    EPS       eps;
    PetscReal ftarget = -1;
    PetscBool flg;
    PetscCall(PhlexModesEPSCreate(scene->comm, &eps, &ftarget, &flg));
    if (PhlexHelpGetMode() != PHLEX_HELP_OPTIONS) {
      PetscCall(EPSSetFromOptions(eps));
      PetscCall(ModesPMGLevelsOptions(eps));
    }
    PetscCall(EPSDestroy(&eps));
  }
  if (PhlexHelpGetMode() != PHLEX_HELP_NONE) PetscFunctionReturn(0);
  PetscCall(PhlexOptionsCheckUnused(scene->comm, PhlexModesRereadOptions, &scene->comm));
  {
    /* read with the bodies' options (so that -help lists it), but the stress maps belong to the mixed operators */
    PetscBool check = PETSC_FALSE;
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-phlex_check_stress_maps", &check, NULL));
    PetscCheck(!check, scene->comm, PETSC_ERR_USER_INPUT, "-phlex_check_stress_maps checks the stress maps of a transient or linearised analysis; a modal analysis (stiffness and mass only) does not build them");
  }
  for (PetscInt k = 0; k < scene->nparts; k++) {
    PhlexPart p = scene->parts[k];
    /* a body that deforms but has no modes of its own would be left out silently */
    PetscCheck(PhlexPartAnalysisOp(p, modes) || !PhlexPartIsElastic(p), scene->comm, PETSC_ERR_SUP, "modal analysis: body %s has elastic coordinates (-%stype %s) but no modal analysis of its own", p->name, p->prefix, p->type);
    if (PhlexPartAnalysisOp(p, modes)) nbodies++;
  }
  PetscCheck(nbodies, scene->comm, PETSC_ERR_USER_INPUT, "modal analysis: the scene has no body with elastic modes (a flexible or reduced body)");
  for (PetscInt k = 0; k < scene->nparts; k++) {
    PhlexPart p    = scene->parts[k];
    PetscReal rate = -1;
    if (PhlexPartAnalysisOp(p, spinrate)) PetscCall((*p->analysisops->spinrate)(p, PETSC_FALSE, &rate));
    /* the body's modes about rest would silently ignore its spin */
    PetscCheck(rate < 0, scene->comm, PETSC_ERR_USER_INPUT, "modal analysis: body %s spins (-%sspin, %g rad/s); its modes about the steady spin are the linearised analysis's (-analysis linearized)", p->name, p->prefix, (double)rate);
  }
  PetscCheck(!nexp || nbodies == 1, scene->comm, PETSC_ERR_USER_INPUT, "-expect_frequencies checks the modes of one body; the scene has %" PetscInt_FMT, nbodies);

  PetscCall(PhlexOutputCSVOpen(scene->output, "modes.csv", "mode,frequency_hz,eigenvalue_rad2_s2,relative_residual,rigid,body", &csv));
  for (PetscInt b = 0; b < scene->nparts; b++) {
    PhlexPart  part = scene->parts[b];
    PetscInt   nconv, nrigid, nrigid_expected;
    PetscReal *lambda, *resid, *freq, *rigid = NULL;
    Vec       *vecs = NULL;
    char       kind[64];
    PetscBool  shapes; /* the mode shapes are written: the caller's copies of the eigenvectors are needed (else the
                          eigensolver's are read only for the residuals) */
    if (!PhlexPartAnalysisOp(part, modes)) continue;
    shapes = (PetscBool)(scene->output->fields && PhlexPartAnalysisOp(part, modesoutput));
    PetscCall(PhlexLogStagePush("Phlex Modes", &PHLEX_StageModes));
    if (part->ops.dissipation) PetscCall(PetscPrintf(scene->comm, "phlex: note: body %s has structural damping: these are its undamped modes (K and M; the damping ratio of a mode of pulsation w is alpha/(2 w) + (beta + eta/E) w/2 for Rayleigh and one Kelvin-Voigt viscosity); its damped modes (complex eigenvalues: frequency and damping ratio, any damping) come with -analysis linearized\n", part->name));
    PetscCall((*part->analysisops->modes)(part, nev, &nconv, &nrigid, &lambda, shapes ? &vecs : NULL, shapes ? &rigid : NULL, &resid));
    PetscCall(PetscLogStagePop());
    PetscCall(PetscMalloc1(nconv, &freq));
    for (PetscInt i = 0; i < nconv; i++) freq[i] = Frequency(lambda[i], &scene->units);
    PetscCall((*part->analysisops->modeskind)(part, kind, sizeof(kind), &nrigid_expected));
    PetscCall(PetscPrintf(scene->comm, "Modes of body %s (%s): %" PetscInt_FMT " computed", part->name, kind, nconv));
    if (nrigid_expected >= 0) PetscCall(PetscPrintf(scene->comm, ", %" PetscInt_FMT " rigid-body modes", nrigid));
    PetscCall(PetscPrintf(scene->comm, "\n  mode  frequency [Hz]       kind     rel. residual\n"));
    for (PetscInt i = 0; i < nconv; i++) {
      PetscCall(PetscPrintf(scene->comm, "  %4" PetscInt_FMT "  %-18.10g   %-7s  %.1e\n", i + 1, (double)(i < nrigid ? 0.0 : freq[i]), i < nrigid ? "rigid" : "elastic", (double)resid[i]));
      if (i >= nrigid) worst = PetscMax(worst, resid[i]); /* rigid modes: backward error, not checked */
    }
    PetscCheck(nrigid_expected < 0 || nrigid == nrigid_expected, scene->comm, PETSC_ERR_NOT_CONVERGED, "body %s is free but %" PetscInt_FMT " rigid-body modes were found instead of %" PetscInt_FMT, part->name, nrigid, nrigid_expected);
    for (PetscInt i = 0; i < nconv; i++) {
      const PetscReal lam = lambda[i] / PetscSqr(scene->units.time);
      PetscCall(PetscViewerASCIIPrintf(csv, "%" PetscInt_FMT ",%.12e,%.12e,%.12e,%d,%s\n", i + 1, (double)freq[i], (double)lam, (double)resid[i], i < nrigid ? 1 : 0, part->name));
    }
    if (shapes) PetscCall((*part->analysisops->modesoutput)(part, scene->output, nconv, nrigid, lambda, vecs, rigid, NULL));
    else if (scene->output->fields) PetscCall(PetscPrintf(scene->comm, "  mode shapes of body %s not written: its kind (-%stype %s) draws none\n", part->name, part->prefix, part->type));
    if (o.nrefine > 0) {
      if (PhlexPartAnalysisOp(part, refine)) PetscCall(ConvergenceStudy(scene, part, o.nrefine, PetscMin(nev, nconv - nrigid), lambda, nrigid, o.order_expect, o.order_tol));
      else PetscCall(PetscPrintf(scene->comm, "  no convergence study of body %s: its model (-%stype %s) has no refinement (-modes_convergence_refinements)\n", part->name, part->prefix, part->type));
    }
    if (nexp) {
      nfexp = nconv - nrigid;
      PetscCall(PetscMalloc1(PetscMax(nfexp, 1), &fexp));
      PetscCall(PetscArraycpy(fexp, freq + nrigid, nfexp));
    }
    for (PetscInt i = 0; vecs && i < nconv; i++) PetscCall(VecDestroy(&vecs[i]));
    PetscCall(PetscFree(vecs));
    PetscCall(PetscFree(rigid));
    PetscCall(PetscFree(lambda));
    PetscCall(PetscFree(resid));
    PetscCall(PetscFree(freq));
  }
  PetscCall(PetscViewerDestroy(&csv));
  PetscCall(PhlexOutputCommit(scene->output));
  if (o.rmax > 0) PetscCall(PhlexExpectMax(scene->comm, "eigenpair residuals (max relative)", "-expect_residual_max", worst, o.rmax, PETSC_TRUE));
  if (nexp) PetscCall(PhlexExpectValues(scene->comm, "elastic frequencies", "-expect_frequencies", nfexp, fexp, nexp, o.expected, o.rtol));
  PetscCall(PetscFree(fexp));
  PetscFunctionReturn(0);
}
