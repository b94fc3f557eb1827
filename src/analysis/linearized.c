/* Linearised analysis of an assembly (paper Section 5.3): the whole mechanism's pHDAE linearised about a
   configuration at rest, its lowest frequencies and mode shapes, swept over configurations in one run.

   The system's residual F(t, X, X') is linearised from its own Jacobian, jj(s) = s E + A (s the shift, E = dF/dX',
   A = dF/dX), taken at two shifts: nothing of a part's or a joint's equations is written twice. About a state at rest
   without loads (velocities and multipliers zero) the configuration unknowns (displacements, frame positions and
   rotations, point positions) do not act on the dynamics: they are dropped, and the remaining pencil on the stress
   Sigma, the velocities V (field v and discrete ones: frame v_P, w, point velocities) and the joints' impulses is
       s E_ss Sigma + A_sv V = 0,      s (M V - B Lambda) + A_vs Sigma = 0,      C V = 0
   with M the kinetic-energy matrix, C the constraint rows and B = -C^T their force distribution (the power-preserving
   interconnection of the ports: lambda . (C V) = w . y). The stress is eliminated exactly (K = -A_vs E_ss^{-1} A_sv
   = G^T Ms^{-1} G, cell by cell: the bodies' condensed operators), which also removes the self-equilibrated stresses
   (the Casimirs of the mixed form, each a zero eigenvalue), and with s = i omega, nu = s^2 Lambda:
       [K  C^T] [V ]          [M  0] [V ]
       [C   0 ] [nu] = w^2    [0  0] [nu]
   a symmetric generalized eigenproblem with the constraints kept in a saddle point, solved by SLEPc with
   shift-and-invert (an indefinite factorisation). Mechanism modes (zero frequency: the constrained rigid motions)
   are counted from the rank of C on the frames' velocities, reported and deflated from the frequency list.

   Elastic coordinates (a reduced body's eta, u = Phi eta) are a body's displacement on discrete unknowns: their rows
   s E_ee eta + A_ez zeta = 0 (eta' = zeta) eliminate them like the field's displacement, and their stiffness, the
   A part of the elastic velocities' rows in their columns (Kr eta), becomes K_zz = -A_ze E_ee^{-1} A_ez on the
   elastic velocities zeta, which are kept with the frames' velocities.

   Force elements and damping (linearized_damped.c): an element's force impulses and states are eliminated onto the
   velocities (its springs on K, its dampers on R); with damping (the bodies' R, a reduced body's modal damping, the
   dampers) the pencil is quadratic, (K + lambda R + lambda^2 M) with the constraints' saddle point, solved by SLEPc PEP
   and reported as undamped natural frequency and damping ratio per mode.

   Everything that does not depend on the configuration is built once: K and M of the field (body frame), the
   eigensolver and the symbolic factorisation; per configuration only the constraint rows and the frame couplings are
   rebuilt (the joints turn), and the loop is closed by the assembly's Newton at the swept drive position. */
#include <phlex_impl.h>
#include <private/linearized.h>

typedef struct {
  PetscInt  nev;
  char      joint[PHLEX_NAME_LEN];
  PetscReal values[1025];
  PetscInt  nvalues;
  PetscReal range[3];
  PetscBool has_values, has_range;
  PetscInt  fields_configuration;
  PetscReal expected[65], rtol, rmax;
  PetscInt  nexp;
  PetscBool has_exp;
  PetscReal zexpected[65], zrtol; /* damping ratios expected (self-check) */
  PetscInt  nzexp;
  PetscBool has_zexp;
  PetscReal spins[1025];    /* spin rates of the configurations [rad/s] (a sweep over a body's -spin) */
  PetscInt  nspins;
  PetscBool coriolis;       /* keep the Coriolis (gyroscopic) terms of a spin: a quadratic eigenproblem */
} LinearizedOptions;

static PetscErrorCode LinearizedSetFromOptions(MPI_Comm comm, LinearizedOptions *o)
{
  PetscInt  nrange = 3, nsrange = 3;
  PetscReal srange[3] = {0, 0, 0};
  PetscBool has_spins = PETSC_FALSE, has_srange = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(o, sizeof(*o)));
  o->nev                  = 6;
  o->nvalues              = 1025;
  o->nexp                 = 65;
  o->rtol                 = 1e-6;
  o->nzexp                = 65;
  o->zrtol                = 1e-6;
  o->rmax                 = -1;
  o->fields_configuration = 0;
  o->nspins               = 1025;
  o->coriolis             = PETSC_TRUE;
  PetscOptionsBegin(comm, NULL, "Linearised analysis of the assembly options", NULL);
  PetscCall(PetscOptionsInt("-linearized_nev", "Number of elastic (non-zero) frequencies wanted per configuration", "PhlexSceneSolveLinearized", o->nev, &o->nev, NULL));
  PetscCall(PetscOptionsString("-linearized_sweep_joint", "Driven joint whose position is swept (default: the scene's only driven joint)", "PhlexSceneSolveLinearized", o->joint, o->joint, sizeof(o->joint), NULL));
  PetscCall(PhlexOptionsRealList("-linearized_sweep", "Drive positions of the configurations, as -drive_initial: angles [deg] or slides [m] relative to the drawn configuration", "PhlexSceneSolveLinearized", o->values, &o->nvalues, &o->has_values, 0));
  PetscCall(PhlexOptionsRealList("-linearized_sweep_range", "Drive positions start,stop,step (stop included) [deg or m]", "PhlexSceneSolveLinearized", o->range, &nrange, &o->has_range, 0));
  PetscCall(PhlexOptionsRealList("-linearized_spin_sweep", "Spin rates of the configurations, for the body with -spin (its axis kept) [rad/s]", "PhlexSceneSolveLinearized", o->spins, &o->nspins, &has_spins, 0));
  PetscCall(PhlexOptionsRealList("-linearized_spin_sweep_range", "Spin rates start,stop,step (stop included) [rad/s]", "PhlexSceneSolveLinearized", srange, &nsrange, &has_srange, 0));
  PetscCall(PetscOptionsBool("-linearized_coriolis", "About a spin: keep the Coriolis (gyroscopic) coupling, a quadratic eigenproblem (false: the symmetric problem of the stiffness and the spin softening alone, as beam tables do)", "PhlexSceneSolveLinearized", o->coriolis, &o->coriolis, NULL));
  PetscCall(PetscOptionsInt("-linearized_fields_configuration", "Write the mode shapes of this configuration (0-based index; -1: none)", "PhlexSceneSolveLinearized", o->fields_configuration, &o->fields_configuration, NULL));
  PetscCall(PhlexOptionsRealList("-expect_frequencies", "Expected elastic frequencies [Hz] of the first configuration (self-check)", "PhlexSceneSolveLinearized", o->expected, &o->nexp, &o->has_exp, 0));
  PetscCall(PetscOptionsReal("-expect_frequencies_rtol", "Relative tolerance of -expect_frequencies", "PhlexSceneSolveLinearized", o->rtol, &o->rtol, NULL));
  PetscCall(PetscOptionsReal("-expect_residual_max", "Bound on the relative eigenpair residuals (self-check)", "PhlexSceneSolveLinearized", o->rmax, &o->rmax, NULL));
  PetscCall(PhlexOptionsRealList("-expect_damping_ratios", "Expected damping ratios [-] of the first configuration's modes (self-check of a damped assembly)", "PhlexSceneSolveLinearized", o->zexpected, &o->nzexp, &o->has_zexp, 0));
  PetscCall(PetscOptionsReal("-expect_damping_ratios_rtol", "Relative tolerance of -expect_damping_ratios", "PhlexSceneSolveLinearized", o->zrtol, &o->zrtol, NULL));
  PetscOptionsEnd();
  PetscCheck(o->nev >= 1, comm, PETSC_ERR_USER_INPUT, "-linearized_nev must be >= 1, got %" PetscInt_FMT, o->nev);
  if (!o->has_zexp) o->nzexp = 0;
  PetscCheck(o->nzexp <= 64, comm, PETSC_ERR_USER_INPUT, "-expect_damping_ratios: at most 64 values");
  PetscCheck(!(o->has_values && o->has_range), comm, PETSC_ERR_USER_INPUT, "give either -linearized_sweep or -linearized_sweep_range, not both");
  PetscCheck(!o->has_values || o->nvalues <= 1024, comm, PETSC_ERR_USER_INPUT, "-linearized_sweep: at most 1024 values (use -linearized_sweep_range)");
  if (!o->has_values) o->nvalues = 0;
  if (o->has_range) {
    PetscInt n;
    PetscCheck(nrange == 3, comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_range needs start,stop,step (3 numbers), got %" PetscInt_FMT, nrange);
    char a[32], b[32], c[32];
    PhlexFormatReal(o->range[0], a, sizeof(a));
    PhlexFormatReal(o->range[1], b, sizeof(b));
    PhlexFormatReal(o->range[2], c, sizeof(c));
    PetscCheck(o->range[2] != 0 && (o->range[1] - o->range[0]) / o->range[2] >= 0, comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_range %s,%s,%s: the step must be non-zero and go from start towards stop", a, b, c);
    PetscCheck((o->range[1] - o->range[0]) / o->range[2] < 1024, comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_range %s,%s,%s gives more than 1024 configurations", a, b, c);
    n = (PetscInt)PetscFloorReal((o->range[1] - o->range[0]) / o->range[2] + 1e-9) + 1;
    PetscCheck(n <= 1024, comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_range %s,%s,%s gives %" PetscInt_FMT " configurations; at most 1024", a, b, c, n);
    for (PetscInt k = 0; k < n; k++) o->values[k] = o->range[0] + k * o->range[2];
    o->nvalues = n;
  }
  PetscCheck(!((o->has_values || o->has_range) && (has_spins || has_srange)), comm, PETSC_ERR_USER_INPUT, "a sweep moves either a driven joint (-linearized_sweep*) or a spin rate (-linearized_spin_sweep*), not both");
  PetscCheck(!(has_spins && has_srange), comm, PETSC_ERR_USER_INPUT, "give either -linearized_spin_sweep or -linearized_spin_sweep_range, not both");
  PetscCheck(!has_spins || o->nspins <= 1024, comm, PETSC_ERR_USER_INPUT, "-linearized_spin_sweep: at most 1024 values (use -linearized_spin_sweep_range)");
  if (!has_spins) o->nspins = 0;
  if (has_srange) {
    char a[32], b[32], c[32];
    PetscInt n;
    PhlexFormatReal(srange[0], a, sizeof(a));
    PhlexFormatReal(srange[1], b, sizeof(b));
    PhlexFormatReal(srange[2], c, sizeof(c));
    PetscCheck(nsrange == 3, comm, PETSC_ERR_USER_INPUT, "-linearized_spin_sweep_range needs start,stop,step (3 numbers), got %" PetscInt_FMT, nsrange);
    PetscCheck(srange[2] != 0 && (srange[1] - srange[0]) / srange[2] >= 0, comm, PETSC_ERR_USER_INPUT, "-linearized_spin_sweep_range %s,%s,%s: the step must be non-zero and go from start towards stop", a, b, c);
    PetscCheck((srange[1] - srange[0]) / srange[2] < 1024, comm, PETSC_ERR_USER_INPUT, "-linearized_spin_sweep_range %s,%s,%s gives more than 1024 configurations", a, b, c);
    n = (PetscInt)PetscFloorReal((srange[1] - srange[0]) / srange[2] + 1e-9) + 1;
    for (PetscInt k = 0; k < n; k++) o->spins[k] = srange[0] + k * srange[2];
    o->nspins = n;
  }
  for (PetscInt k = 0; k < o->nspins; k++) {
    char a[32];
    PhlexFormatReal(o->spins[k], a, sizeof(a));
    PetscCheck(o->spins[k] >= 0 && !PetscIsInfOrNanReal(o->spins[k]), comm, PETSC_ERR_USER_INPUT, "%s: spin rate %s is not a finite rate >= 0 [rad/s] (the axis is the body's -spin: reverse it there)", has_srange ? "-linearized_spin_sweep_range" : "-linearized_spin_sweep", a);
  }
  if (!o->has_exp) o->nexp = 0;
  PetscCheck(o->nexp <= 64, comm, PETSC_ERR_USER_INPUT, "-expect_frequencies: at most 64 values");
  PetscFunctionReturn(0);
}

/* shift-and-invert by a direct factorisation of the given type, MUMPS where available (options prefix linearized_st_) */
static PetscErrorCode ShiftInvertDirect(ST st, PCType type)
{
  KSP ksp;
  PC  pc;

  PetscFunctionBeginUser;
  PetscCall(STSetType(st, STSINVERT));
  PetscCall(STGetKSP(st, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &pc));
  PetscCall(PCSetType(pc, type));
  if (PetscDefined(HAVE_MUMPS)) {
    /* the saddle point's delayed pivots outgrow MUMPS's default workspace (INFOG(1) = -9 on the four-bar with 16
       cells per link): 200 % more, unless given */
    char      solver[64] = "mumps";
    PetscBool set, other;
    PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    PetscCall(PetscOptionsGetString(NULL, NULL, "-linearized_st_pc_factor_mat_solver_type", solver, sizeof(solver), NULL));
    PetscCall(PetscStrcmp(solver, "mumps", &other));
    other = (PetscBool)!other;
    PetscCall(PetscOptionsHasName(NULL, NULL, "-linearized_st_mat_mumps_icntl_14", &set));
    if (!set && !other) PetscCall(PetscOptionsSetValue(NULL, "-linearized_st_mat_mumps_icntl_14", "200"));
  }
  PetscFunctionReturn(0);
}

/* the eigensolver with phlex's defaults (Krylov-Schur, shift-and-invert, an indefinite LDL^T by MUMPS: the pencil
   is a saddle point), options prefix linearized_ */
static PetscErrorCode LinearizedEPSCreate(MPI_Comm comm, EPS *eps)
{
  ST st;

  PetscFunctionBeginUser;
  PetscCall(EPSCreate(comm, eps));
  PetscCall(EPSSetOptionsPrefix(*eps, "linearized_"));
  PetscCall(EPSSetProblemType(*eps, EPS_GHEP)); /* B = diag(M, 0): positive semi-definite; purification (default) removes its null-space components */
  PetscCall(EPSSetType(*eps, EPSKRYLOVSCHUR));
  PetscCall(EPSSetWhichEigenpairs(*eps, EPS_TARGET_MAGNITUDE));
  PetscCall(EPSSetTolerances(*eps, 1e-12, PETSC_DEFAULT));
  PetscCall(EPSGetST(*eps, &st));
  PetscCall(ShiftInvertDirect(st, PCCHOLESKY));
  PetscFunctionReturn(0);
}

/* the quadratic eigensolver of a spinning state (Coriolis kept): TOAR, shift-and-invert about 0 (the same saddle
   point factored), the same prefix linearized_ (-linearized_pep_*, -linearized_st_*) */
static PetscErrorCode LinearizedPEPCreate(MPI_Comm comm, PEP *pep)
{
  ST st;

  PetscFunctionBeginUser;
  PetscCall(PEPCreate(comm, pep));
  PetscCall(PEPSetOptionsPrefix(*pep, "linearized_"));
  PetscCall(PEPSetProblemType(*pep, PEP_GYROSCOPIC)); /* A0, A2 symmetric, A1 skew: eigenvalues in pairs +-lambda */
  PetscCall(PEPSetType(*pep, PEPTOAR));
  PetscCall(PEPSetWhichEigenpairs(*pep, PEP_TARGET_MAGNITUDE));
  PetscCall(PEPSetTarget(*pep, 0.0));
  PetscCall(PEPSetTolerances(*pep, 1e-12, PETSC_DEFAULT));
  PetscCall(PEPGetST(*pep, &st));
  PetscCall(ShiftInvertDirect(st, PCLU)); /* A0 + sigma A1 + sigma^2 A2 is not symmetric for a sigma other than 0 */
  PetscFunctionReturn(0);
}

/* every option of a linearised run read once more (PhlexOptionsCheckUnused collects the valid names): the scene's,
   the analysis', the eigensolvers' */
PetscErrorCode PhlexLinearizedRereadOptions(void *ctx)
{
  MPI_Comm          comm = *(MPI_Comm *)ctx;
  LinearizedOptions o;
  EPS               eps;

  PetscFunctionBeginUser;
  PetscCall(PhlexSceneReadOptions(comm));
  PetscCall(LinearizedSetFromOptions(comm, &o));
  PetscCall(LinearizedEPSCreate(comm, &eps));
  PetscCall(EPSSetFromOptions(eps));
  PetscCall(EPSDestroy(&eps));
  if (o.coriolis) {
    PEP pep;
    PetscCall(LinearizedPEPCreate(comm, &pep));
    PetscCall(PEPSetFromOptions(pep));
    PetscCall(PEPDestroy(&pep));
  }
  PetscFunctionReturn(0);
}

/* the n values of a vector that lives on rank 0, on every rank */
static PetscErrorCode RootValues(MPI_Comm comm, Vec x, PetscInt n, PetscReal *out)
{
  const PetscScalar *a;
  PetscInt           nl;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(x, &nl));
  PetscCall(VecGetArrayRead(x, &a));
  for (PetscInt k = 0; k < nl && k < n; k++) out[k] = PetscRealPart(a[k]);
  PetscCall(VecRestoreArrayRead(x, &a));
  PetscCallMPI(MPI_Bcast(out, (PetscMPIInt)n, MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}

/* Jacobian at the non-dimensional shift s, at rest (X' = 0): the system's own IJacobian */
static PetscErrorCode EvaluateJacobian(Pencil *p, PetscReal s)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexSystemIJacobian(NULL, 0.0, p->X, p->Xdot, s / p->sys->units->time, p->sys->J, p->sys->J, p->sys));
  PetscFunctionReturn(0);
}

/* an AIJ copy (a nest's blocks converted one by one: MatConvert of a nest needs MatGetRow of every block) */
static PetscErrorCode ToAIJ(Mat A, Mat *B)
{
  PetscBool nest;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)A, MATNEST, &nest));
  if (nest) {
    PetscInt nr, nc;
    Mat    **sub, *blocks, N;
    IS      *isr, *isc;
    PetscCall(MatNestGetSubMats(A, &nr, &nc, &sub));
    PetscCall(PetscCalloc3(nr * nc, &blocks, nr, &isr, nc, &isc));
    PetscCall(MatNestGetISs(A, isr, isc));
    for (PetscInt i = 0; i < nr; i++)
      for (PetscInt j = 0; j < nc; j++)
        if (sub[i][j]) PetscCall(ToAIJ(sub[i][j], &blocks[i * nc + j]));
    PetscCall(MatCreateNest(PetscObjectComm((PetscObject)A), nr, isr, nc, isc, blocks, &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, B));
    PetscCall(MatDestroy(&N));
    for (PetscInt k = 0; k < nr * nc; k++) PetscCall(MatDestroy(&blocks[k]));
    PetscCall(PetscFree3(blocks, isr, isc));
  } else PetscCall(MatConvert(A, MATAIJ, MAT_INITIAL_MATRIX, B));
  PetscFunctionReturn(0);
}

/* E and A parts of a matrix taken at shifts 1 and 2: E = J2 - J1, A = 2 J1 - J2 (in place: J1 <- A, J2 <- E) */
static PetscErrorCode SplitShift(Mat J1, Mat J2)
{
  PetscFunctionBeginUser;
  PetscCall(MatAXPY(J2, -1.0, J1, DIFFERENT_NONZERO_PATTERN));
  PetscCall(MatAXPY(J1, -1.0, J2, DIFFERENT_NONZERO_PATTERN));
  PetscFunctionReturn(0);
}

/* a block-diagonal operator of the bodies' velocity spaces (PhlexSystemCondensedOperator) as one AIJ matrix */
static PetscErrorCode BodiesOperator(PhlexSystem sys, PetscInt which, Mat *S)
{
  Mat N;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemCondensedOperator(sys, which, &N));
  PetscCall(ToAIJ(N, S));
  PetscCall(MatDestroy(&N));
  PetscFunctionReturn(0);
}

/* The pencil's build (the field operators, the borders, the discrete rows) takes seconds to minutes on a large body:
   each of its steps checks the interrupt flag and reports progress (issue 43 item 1), as the assembly's element
   loops do; what it is in names the step */
PetscErrorCode PhlexLinearizedPencilPhase(Pencil *p, const char step[], PetscReal done)
{
  char what[128];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(what, sizeof(what), "assembly of the linearized pencil (%s)", step));
  PetscCall(PhlexProgressPhase(&p->progress, p->sys->comm, what, done));
  PetscFunctionReturn(0);
}

/* The field operators: the bodies' velocity masses M and condensed stiffnesses K = G^T Ms^{-1} G (the stress
   eliminated cell by cell, so that the self-equilibrated stresses of the mixed form, each a zero eigenvalue, are
   gone), from the part contract; about a stressed or spinning steady state (a body with -spin, or with
   -geometric_stiffening and a stress), K gains the state's stiffness K_sigma + Cen (initial stress, spin softening)
   and G(u0) replaces G, and the Coriolis matrix is the pencil's gyroscopic part. Checks on a random vector that the
   velocity rows have no other term in v or u at the linearisation point (at rest: no other gyroscopic load, no
   preload) and that the velocity block of the system's Jacobian is s M + Coriolis + R there (R: the structural
   damping, the pencil's damping part). Rebuilt per configuration of a spin sweep (the state and its stress change);
   built once otherwise. */
static PetscErrorCode BuildFieldOperators(Pencil *p)
{
  PhlexSystem sys = p->sys;
  Vec         x, y1, y2, yu1, yu2, xu = NULL, g = NULL;
  PetscReal   rel, dev, nm;
  Mat         Kst = NULL, Gyr = NULL, Rd = NULL;

  PetscFunctionBeginUser;
  PetscCall(PhlexProgressStart(&p->progress));
  PetscCall(PhlexLinearizedPencilPhase(p, "the field operators", 0.0));
  PetscCall(MatCreateVecs(sys->Jvv, &x, &y1));
  PetscCall(VecDuplicate(y1, &y2));
  PetscCall(VecDuplicate(y1, &yu1));
  PetscCall(VecDuplicate(y1, &yu2));
  PetscCall(VecSetRandom(x, NULL));
  if (sys->Jvu) {
    PetscCall(MatCreateVecs(sys->Jvu, &xu, NULL));
    PetscCall(VecSetRandom(xu, NULL));
  }
  PetscCall(EvaluateJacobian(p, 1.0));
  PetscCall(MatMult(sys->Jvv, x, y1));
  if (xu) PetscCall(MatMult(sys->Jvu, xu, yu1));
  PetscCall(EvaluateJacobian(p, 2.0));
  PetscCall(MatMult(sys->Jvv, x, y2));
  if (xu) PetscCall(MatMult(sys->Jvu, xu, yu2));
  PetscCall(PhlexLinearizedPencilPhase(p, "the Jacobian at the linearisation point", 0.2));
  /* the bodies' own mass and condensed stiffness (taken apart they would lose digits to cancellation), at the state */
  PetscCall(MatDestroy(&p->Mvv));
  PetscCall(MatDestroy(&p->K));
  PetscCall(MatDestroy(&p->Gyr));
  PetscCall(MatDestroy(&p->Rf));
  PetscCall(BodiesOperator(sys, 1, &p->Mvv));
  PetscCall(PhlexLinearizedPencilPhase(p, "the bodies' mass", 0.4));
  PetscCall(BodiesOperator(sys, 2, &p->K));
  PetscCall(PhlexLinearizedPencilPhase(p, "the bodies' stiffness", 0.6));
  PetscCall(PhlexSystemCondensedOperator(sys, 3, &Kst));
  PetscCall(PhlexSystemCondensedOperator(sys, 4, &Gyr));
  if (Kst) {
    Mat Ka;
    PetscCall(ToAIJ(Kst, &Ka));
    PetscCall(MatAXPY(p->K, 1.0, Ka, DIFFERENT_NONZERO_PATTERN));
    PetscCall(MatDestroy(&Ka));
  }
  if (Gyr) PetscCall(ToAIJ(Gyr, &p->Gyr));
  PetscCall(PhlexSystemCondensedOperator(sys, 5, &Rd));
  if (Rd) PetscCall(ToAIJ(Rd, &p->Rf));
  PetscCall(PhlexLinearizedPencilPhase(p, "the stiffening, spin and damping operators", 0.8));
  PetscCall(MatSetOption(p->K, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatNorm(p->Mvv, NORM_FROBENIUS, &nm));
  p->scale = nm;
  /* at rest or in a steady spin: the velocity block of the Jacobian is s M + Coriolis + R, nothing else */
  PetscCall(VecDuplicate(y1, &g));
  PetscCall(VecAXPBYPCZ(g, 2.0, -1.0, 0.0, y1, y2)); /* its A part */
  for (PetscInt k = 0; k < 2; k++) {
    Mat O = k ? Rd : Gyr;
    Vec gx;
    if (!O) continue;
    PetscCall(VecDuplicate(y1, &gx));
    PetscCall(MatMult(O, x, gx));
    PetscCall(VecAXPY(g, -1.0, gx)); /* less the Coriolis term, the damping */
    PetscCall(VecDestroy(&gx));
  }
  {
    PetscReal na, ne;
    Vec       e;
    PetscCall(VecNorm(g, NORM_2, &na));
    PetscCall(VecDuplicate(y1, &e));
    PetscCall(VecAXPBYPCZ(e, -1.0, 1.0, 0.0, y1, y2));
    PetscCall(VecNorm(e, NORM_2, &ne));
    PetscCall(VecDestroy(&e));
    rel = na / PetscMax(ne, PETSC_SMALL);
  }
  PetscCheck(rel <= 1e-10, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the velocity equations have terms in v at the linearisation point (relative size %g): the bodies are not at rest (a spinning frame); the analysis linearises about rest or about a body's prescribed steady spin (-<body>_spin)", (double)rel);
  PetscCall(VecDestroy(&g));
  {
    Vec mx;
    PetscCall(VecDuplicate(y1, &mx));
    PetscCall(MatMult(p->Mvv, x, mx));
    PetscCall(VecAXPBYPCZ(mx, -1.0, 1.0, 1.0, y2, y1)); /* M x - (y2 - y1) */
    PetscCall(VecNorm(mx, NORM_2, &dev));
    PetscCall(VecAXPBYPCZ(mx, -1.0, 1.0, 0.0, y1, y2));
    PetscCall(VecNorm(mx, NORM_2, &rel));
    PetscCall(VecDestroy(&mx));
    PetscCheck(dev <= 1e-10 * rel, sys->comm, PETSC_ERR_PLIB, "linearized analysis: a body's condensed operator does not match its Jacobian's velocity block (relative deviation %g)", (double)(dev / rel));
  }
  if (xu) {
    PetscReal n1, n2, ns = 0;
    if (Kst) {
      Vec k;
      PetscCall(VecDuplicate(yu1, &k));
      PetscCall(MatMult(Kst, xu, k));
      PetscCall(VecNorm(k, NORM_2, &ns));
      PetscCall(VecAXPY(yu1, -1.0, k));
      PetscCall(VecAXPY(yu2, -1.0, k));
      PetscCall(VecDestroy(&k));
    }
    PetscCall(VecNorm(yu1, NORM_2, &n1));
    PetscCall(VecNorm(yu2, NORM_2, &n2));
    /* (a fixed body's velocity-displacement block is its Kstate itself: the check bites on floating bodies) */
    PetscCheck(PetscMax(n1, n2) <= 1e-10 * PetscMax(rel, ns), sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the displacement acts on the velocity equations at the linearisation point (relative size %g): a loaded or moving state; linearise about an unloaded configuration at rest or a prescribed steady spin", (double)(PetscMax(n1, n2) / PetscMax(rel, ns)));
  }
  PetscCall(MatDestroy(&Kst));
  PetscCall(MatDestroy(&Gyr));
  PetscCall(MatDestroy(&Rd));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&xu));
  PetscCall(VecDestroy(&y1));
  PetscCall(VecDestroy(&y2));
  PetscCall(VecDestroy(&yu1));
  PetscCall(VecDestroy(&yu2));
  PetscFunctionReturn(0);
}

/* the discrete unknowns kept (velocities of frames and points, elastic velocities, impulses), eliminated (elastic
   coordinates) and dropped (configuration) */
static PetscErrorCode BuildDiscreteMap(Pencil *p)
{
  PhlexSystem sys = p->sys;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(PetscMax(sys->nq, 1), &p->qmap, PetscMax(sys->nq, 1), &p->Qq, PetscMax(sys->nq, 1), &p->Ee));
  for (PetscInt k = 0; k < sys->nq; k++) p->qmap[k] = -1;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_VELOCITY || sys->qkind[k] == PHLEX_DOF_ELASTIC_VELOCITY) p->Qq[p->nqv] = k, p->qmap[k] = p->nqv++;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_ELASTIC) p->Ee[p->ne++] = k;
  p->nQ = p->nqv;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_IMPULSE) p->Qq[p->nQ] = k, p->qmap[k] = p->nQ++;
  p->nqi = p->nQ - p->nqv;
  /* the force elements' rows, force impulse i and state i of each joint in turn (eliminated like the stress) */
  for (PetscInt k = 0; k < sys->njoints; k++) p->nel += sys->joints[k]->ne;
  PetscCall(PetscMalloc3(PetscMax(p->nel, 1), &p->elF, PetscMax(p->nel, 1), &p->elE, PetscMax(sys->nq, 1), &p->qdamped));
  p->nel = 0;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_ELEMENT_FORCE) p->elF[p->nel++] = k;
  p->nel = 0;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_ELEMENT) p->elE[p->nel++] = k;
  for (PetscInt k = 0; k < sys->nq; k++) p->qdamped[k] = PETSC_FALSE;
  for (PetscInt i = 0; i < sys->nparts; i++)
    if (sys->parts[i]->ops.dissipation)
      for (PetscInt m = 0; m < sys->parts[i]->nq; m++) p->qdamped[sys->parts[i]->qoff + m] = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* The state at rest: velocities and impulses zero (the configuration, the elastic coordinates and the stress as they are) */
static PetscErrorCode SetRest(Pencil *p)
{
  PhlexSystem sys = p->sys;

  PetscFunctionBeginUser;
  if (sys->nfparts) {
    Vec v;
    PetscCall(VecGetSubVector(p->X, sys->is[PHLEX_FIELD_VELOCITY], &v));
    PetscCall(VecSet(v, 0.0));
    PetscCall(VecRestoreSubVector(p->X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  }
  PetscCall(PhlexSystemGather(sys, p->X, sys->q));
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_VELOCITY || sys->qkind[k] == PHLEX_DOF_ELASTIC_VELOCITY || sys->qkind[k] == PHLEX_DOF_IMPULSE) sys->q[k] = 0.0;
  PetscCall(PhlexSystemScatter(sys, sys->q, p->X));
  PetscFunctionReturn(0);
}

/* The force elements' rows on the velocity field (A parts; at rest they have no rate of the field): from the power-
   preserving interconnection, the state rows e' = S^T V give A_EV = B_VF^T and the force rows lambda = -(K e + C S^T V)
   give A_FV = -C B_VF^T, with B_VF = the field rows' E part in the force impulses' columns (-S, the force distribution,
   BE's columns). The discrete rows of the system (Cqv, a product only) are checked against them on a random vector. */
static PetscErrorCode ElementFieldRows(Pencil *p, Mat BE)
{
  PhlexSystem        sys = p->sys;
  const PetscInt     nel = p->nel;
  PetscReal         *C, *yq, diff = 0, ref = 0;
  const PetscScalar *be;
  PetscInt           ld, nvl;
  Vec                x, y;

  PetscFunctionBeginUser;
  /* the elements' dampers, joint by joint (non-dimensional, as the Jacobian's) */
  PetscCall(PetscCalloc2(nel * nel, &C, PetscMax(sys->nq, 1), &yq));
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint j = sys->joints[k];
    for (PetscInt i = 0; i < j->ne; i++)
      for (PetscInt l = 0; l < j->ne; l++) {
        PetscInt a = -1, b = -1;
        for (PetscInt m = 0; m < nel; m++) {
          if (p->elF[m] == j->qoff + j->nc + i) a = m;
          if (p->elF[m] == j->qoff + j->nc + l) b = m;
        }
        C[a * nel + b] = j->C[j->ne * i + l];
      }
  }
  PetscCall(MatDenseGetLDA(BE, &ld));
  PetscCall(MatGetLocalSize(BE, &nvl, NULL));
  PetscCall(MatDenseGetArrayRead(BE, &be));
  for (PetscInt a = 0; a < 2 * nel; a++)
    if (!p->elrows[a]) PetscCall(MatCreateVecs(sys->Cqv, &p->elrows[a], NULL));
  for (PetscInt a = 0; a < nel; a++) {
    PetscScalar *rf, *re;
    PetscCall(VecGetArray(p->elrows[a], &rf));
    PetscCall(VecGetArray(p->elrows[nel + a], &re));
    for (PetscInt r = 0; r < nvl; r++) {
      PetscReal f = 0;
      for (PetscInt b = 0; b < nel; b++) f -= C[a * nel + b] * PetscRealPart(be[p->elF[b] * ld + r]);
      re[r] = be[p->elF[a] * ld + r];
      rf[r] = f;
    }
    PetscCall(VecRestoreArray(p->elrows[a], &rf));
    PetscCall(VecRestoreArray(p->elrows[nel + a], &re));
  }
  PetscCall(MatDenseRestoreArrayRead(BE, &be));
  /* the check: the system's element rows (at the last shift: no rate of the field in them) on a random field vector */
  PetscCall(MatCreateVecs(sys->Cqv, &x, &y));
  PetscCall(VecSetRandom(x, NULL));
  PetscCall(MatMult(sys->Cqv, x, y));
  PetscCall(RootValues(sys->comm, y, sys->nq, yq));
  for (PetscInt a = 0; a < 2 * nel; a++) {
    const PetscInt q = a < nel ? p->elF[a] : p->elE[a - nel];
    PetscScalar    d;
    PetscCall(VecDot(p->elrows[a], x, &d));
    diff = PetscMax(diff, PetscAbsReal(PetscRealPart(d) - yq[q]));
    ref  = PetscMax(ref, PetscAbsReal(yq[q]));
  }
  PetscCheck(diff <= 1e-9 * PetscMax(ref, 1e-300), sys->comm, PETSC_ERR_PLIB, "linearized analysis: the force elements' rows on the velocity field differ from their transposed force distribution by %g (relative): an element breaks the power-preserving interconnection", (double)(diff / PetscMax(ref, 1e-300)));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&y));
  PetscCall(PetscFree2(C, yq));
  PetscFunctionReturn(0);
}

/* The border between the velocity field and the discrete unknowns at the current configuration, E and A parts
   (n_v x nq dense, from nq products with the Jacobian's border), and the dense discrete block's; the force elements'
   rows on the field (p->elrows, their A parts: at rest they have no rate of the field) */
static PetscErrorCode Borders(Pencil *p, Mat *BE, Mat *BA, PetscReal *DE, PetscReal *DA)
{
  PhlexSystem     sys = p->sys;
  const PetscInt  nq2 = sys->nq * sys->nq;

  PetscFunctionBeginUser;
  *BE = *BA = NULL;
  PetscCall(EvaluateJacobian(p, 1.0));
  if (sys->Bvq) PetscCall(MatComputeOperator(sys->Bvq, MATDENSE, BA));
  PetscCall(PetscArraycpy(DA, sys->D, nq2));
  PetscCall(EvaluateJacobian(p, 2.0));
  if (sys->Bvq) {
    PetscCall(MatComputeOperator(sys->Bvq, MATDENSE, BE));
    PetscCall(SplitShift(*BA, *BE));
  }
  if (p->nel && *BE) {
    if (!p->elrows) PetscCall(PetscCalloc1(2 * p->nel, &p->elrows));
    PetscCall(ElementFieldRows(p, *BE));
  }
  for (PetscInt k = 0; k < nq2; k++) {
    const PetscReal j1 = DA[k], j2 = sys->D[k];
    DE[k] = j2 - j1;
    DA[k] = 2.0 * j1 - j2;
  }
  PetscFunctionReturn(0);
}

/* The stiffness of the elastic coordinates on the kept velocities: their rows s E_ee eta + A_eQ x_Q = 0 (eta' =
   zeta) give eta = -E_ee^{-1} A_eQ x_Q / s, and the velocities' rows' A part in their columns, A_Qe eta, multiplied
   by s as the velocity rows are (the field's K likewise), K_QQ = -A_Qe E_ee^{-1} A_eQ (nqv x nqv, row-major; the
   symmetric Kr of a reduced body). Checks that the elastic rows have no other terms (no A part among elastic
   coordinates or in the configuration or impulse columns, no E part outside E_ee) and that K_QQ is symmetric. */
static PetscErrorCode ElasticStiffness(Pencil *p, const PetscReal *DE, const PetscReal *DA, PetscReal dmax, PetscReal *Kq)
{
  PhlexSystem    sys = p->sys;
  const PetscInt nq = sys->nq, ne = p->ne, nqv = p->nqv;
  PetscReal     *E, *X, worst = 0, kmax = 0, asym = 0;
  PetscBLASInt   n, nrhs, info, *piv;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc3(ne * ne, &E, ne * nqv, &X, ne, &piv));
  for (PetscInt a = 0; a < ne; a++) {
    const PetscInt i = p->Ee[a];
    for (PetscInt j = 0; j < nq; j++) {
      const PetscInt jj = p->qmap[j];
      if (sys->qkind[j] == PHLEX_DOF_ELASTIC) worst = PetscMax(worst, PetscAbsReal(DA[i * nq + j]));
      else worst = PetscMax(worst, PetscAbsReal(DE[i * nq + j]) + (jj >= 0 && jj < nqv ? 0.0 : PetscAbsReal(DA[i * nq + j])));
    }
    for (PetscInt b = 0; b < ne; b++) E[b * ne + a] = DE[i * nq + p->Ee[b]];       /* column-major */
    for (PetscInt jj = 0; jj < nqv; jj++) X[jj * ne + a] = DA[i * nq + p->Qq[jj]]; /* column-major */
  }
  PetscCheck(worst <= 1e-10 * dmax, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the elastic coordinates' rows are not eta' = zeta at the linearisation point (a term of relative size %g): the configuration is not at rest", (double)(worst / dmax));
  PetscCall(PetscBLASIntCast(ne, &n));
  PetscCall(PetscBLASIntCast(nqv, &nrhs));
  PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&n, &nrhs, E, &n, piv, X, &n, &info));
  PetscCheck(!info, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the elastic coordinates' rate block is singular (LAPACK gesv info %d)", (int)info);
  for (PetscInt ii = 0; ii < nqv; ii++)
    for (PetscInt jj = 0; jj < nqv; jj++) {
      PetscReal k = 0;
      for (PetscInt a = 0; a < ne; a++) k -= DA[p->Qq[ii] * nq + p->Ee[a]] * X[jj * ne + a];
      Kq[ii * nqv + jj] = k;
      kmax              = PetscMax(kmax, PetscAbsReal(k));
    }
  for (PetscInt ii = 0; ii < nqv; ii++)
    for (PetscInt jj = 0; jj < ii; jj++) asym = PetscMax(asym, PetscAbsReal(Kq[ii * nqv + jj] - Kq[jj * nqv + ii]));
  PetscCheck(asym <= 1e-10 * kmax, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the stiffness of the elastic coordinates is not symmetric (relative deviation %g)", (double)(asym / PetscMax(kmax, PETSC_SMALL)));
  PetscCall(PetscFree3(E, X, piv));
  PetscFunctionReturn(0);
}

/* The pencil at the current configuration:
     A = [[K, Cv^T], [Cv, [[0, Cq^T], [Cq, 0]]]],   B = [[M, Mvq], [Mqv, [[Mqq, 0], [0, 0]]]]
   on (v | discrete velocities, impulses); Cv = -E_{v,imp}^T (the force distribution of the impulses, transposed),
   Mvq = E_{v,vel}, Cq = A_{imp,vel}, Mqq = E_{vel,vel}; the velocities' own block of A is the elastic coordinates'
   stiffness (ElasticStiffness), zero without them. Checks: at rest (no A part among velocities), the discrete
   rows of the system against these (the power-preserving structure), the configuration unknowns inert. */
static PetscErrorCode BuildPencil(Pencil *p, PetscInt *nmech)
{
  PhlexSystem        sys = p->sys;
  const PetscInt     nq = sys->nq, nQ = p->nQ, nqv = p->nqv;
  PetscMPIInt        rank;
  PetscInt           nvl = 0, Ql;
  PetscReal         *DE, *DA, *Kq = NULL, *Rq = NULL, dmax = 0, worst = 0, rmax = 0, rasym = 0;
  Mat                BE = NULL, BA = NULL, AvQ = NULL, BvQ = NULL, AQv = NULL, BQv = NULL, AQQ, BQQ, RQQ = NULL, N, blocks[4];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(sys->comm, &rank));
  Ql = rank == 0 ? nQ : 0;
  PetscCall(PetscMalloc2(PetscMax(nq * nq, 1), &DE, PetscMax(nq * nq, 1), &DA));
  if (p->ne) PetscCall(PetscCalloc1(nqv * nqv, &Kq));
  PetscCall(PetscCalloc1(PetscMax(nqv * nqv, 1), &Rq));
  PetscCall(PhlexProgressStart(&p->progress));
  PetscCall(PhlexLinearizedPencilPhase(p, "the borders", 0.0));
  PetscCall(Borders(p, &BE, &BA, DE, DA));
  PetscCall(PhlexLinearizedPencilPhase(p, "the borders", 1.0));
  for (PetscInt k = 0; k < nq * nq; k++) dmax = PetscMax(dmax, PetscAbsReal(DE[k]));
  dmax = PetscMax(dmax, p->scale);
  /* at rest: no A part among the velocities but the damping of a part that dissipates (a reduced body's), no
     coupling of the configuration into the kept rows (of the elastic coordinates only their stiffness, the A part of
     the velocities' rows; of the force elements' force impulses only their force distribution, like a multiplier's) */
  for (PetscInt i = 0; i < nq; i++)
    for (PetscInt j = 0; j < nq; j++) {
      const PetscInt ii = p->qmap[i], jj = p->qmap[j];
      if (ii < 0) continue;
      if (jj < 0 && sys->qkind[j] == PHLEX_DOF_ELASTIC) worst = PetscMax(worst, PetscAbsReal(DE[i * nq + j]) + (ii < nqv ? 0.0 : PetscAbsReal(DA[i * nq + j])));
      else if (jj < 0 && sys->qkind[j] == PHLEX_DOF_ELEMENT_FORCE && ii < nqv) worst = PetscMax(worst, PetscAbsReal(DA[i * nq + j]));
      else if (jj < 0) worst = PetscMax(worst, PetscAbsReal(DA[i * nq + j]) + PetscAbsReal(DE[i * nq + j]));
      else if (ii < nqv && jj < nqv && p->qdamped[i] && p->qdamped[j]) Rq[ii * nqv + jj] = DA[i * nq + j], rmax = PetscMax(rmax, PetscAbsReal(DA[i * nq + j]));
      else if (ii < nqv && jj < nqv) worst = PetscMax(worst, PetscAbsReal(DA[i * nq + j]));
    }
  for (PetscInt ii = 0; ii < nqv; ii++)
    for (PetscInt jj = 0; jj < ii; jj++) rasym = PetscMax(rasym, PetscAbsReal(Rq[ii * nqv + jj] - Rq[jj * nqv + ii]));
  PetscCheck(rasym <= 1e-10 * rmax, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the velocity terms of the discrete velocities' equations are not symmetric (relative deviation %g): not a damping, a motion (gyroscopic terms); linearise about rest", (double)(rasym / rmax));
  PetscCheck(worst <= 1e-10 * dmax, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the configuration is not at rest or is loaded (a term of relative size %g couples the frames' positions or velocities into their equations: gravity, a preload, a spinning body); linearise about an unloaded configuration at rest", (double)(worst / dmax));
  /* the power-preserving structure: the impulse columns of the velocity rows are minus the transposed constraint
     rows; the frame couplings symmetric */
  for (PetscInt ii = 0; ii < nQ; ii++)
    for (PetscInt jj = 0; jj < nqv; jj++) {
      const PetscInt i = p->Qq[ii], j = p->Qq[jj];
      if (ii < nqv) worst = PetscMax(worst, PetscAbsReal(DE[i * nq + j] - DE[j * nq + i]));
      else worst = PetscMax(worst, PetscAbsReal(DA[i * nq + j] + DE[j * nq + i]));
    }
  PetscCheck(worst <= 1e-9 * dmax, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the discrete block is not of the symmetric saddle-point form (deviation %g): a part or joint breaks the power-preserving structure", (double)(worst / dmax));
  if (p->ne) PetscCall(ElasticStiffness(p, DE, DA, dmax, Kq));

  /* field couplings: columns of the border, in Q order, and their transposes (AIJ) */
  if (BE) {
    PetscInt           rs, re, ld;
    const PetscScalar *be, *ba;
    PetscReal          amax = 0, emax = 0;
    PetscInt           chunk = 0;
    PetscCall(MatGetOwnershipRange(BE, &rs, &re));
    nvl = re - rs;
    PetscCall(MatCreateAIJ(sys->comm, nvl, Ql, PETSC_DETERMINE, nQ, nQ, NULL, nQ, NULL, &AvQ));
    PetscCall(MatCreateAIJ(sys->comm, nvl, Ql, PETSC_DETERMINE, nQ, nQ, NULL, nQ, NULL, &BvQ));
    PetscCall(MatSetOption(AvQ, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
    PetscCall(MatSetOption(BvQ, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
    PetscCall(MatDenseGetLDA(BE, &ld));
    PetscCall(MatDenseGetArrayRead(BE, &be));
    PetscCall(MatDenseGetArrayRead(BA, &ba));
    for (PetscInt r = 0; r < nvl; r++) {
      PetscCall(PhlexProgressChunk(&p->progress, sys->comm, "assembly of the linearized pencil (the discrete unknowns' columns)", r, nvl, &chunk));
      for (PetscInt j = 0; j < nq; j++) {
        const PetscInt  jj = p->qmap[j];
        const PetscReal e = PetscRealPart(be[j * ld + r]), a = PetscRealPart(ba[j * ld + r]);
        PetscInt        row = rs + r;
        emax = PetscMax(emax, PetscAbsReal(e));
        if (jj < 0 || jj < nqv) amax = PetscMax(amax, PetscAbsReal(a) + (jj < 0 && sys->qkind[j] != PHLEX_DOF_ELEMENT_FORCE ? PetscAbsReal(e) : 0.0));
        if (jj < 0) continue;
        /* every entry, zeros included: the same pattern in every configuration (the factorisation's analysis is reused) */
        if (jj < nqv) {
          PetscCall(MatSetValue(BvQ, row, jj, e, INSERT_VALUES));
          PetscCall(MatSetValue(AvQ, row, jj, 0.0, INSERT_VALUES));
        } else {
          PetscCall(MatSetValue(AvQ, row, jj, -e, INSERT_VALUES));
          PetscCall(MatSetValue(BvQ, row, jj, 0.0, INSERT_VALUES));
        }
      }
    }
    PetscCall(MatDenseRestoreArrayRead(BE, &be));
    PetscCall(MatDenseRestoreArrayRead(BA, &ba));
    PetscCall(PhlexProgressChunksEnd(&p->progress, sys->comm, "assembly of the linearized pencil (the discrete unknowns' columns)", chunk));
    PetscCall(MatAssemblyBegin(AvQ, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyBegin(BvQ, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(AvQ, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(BvQ, MAT_FINAL_ASSEMBLY));
    PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &amax, 1, MPIU_REAL, MPIU_MAX, sys->comm));
    PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &emax, 1, MPIU_REAL, MPIU_MAX, sys->comm));
    PetscCheck(amax <= 1e-10 * PetscMax(emax, dmax), sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the configuration is not at rest or is loaded (the frames' velocities or positions act on the field's equations with relative size %g); linearise about an unloaded configuration at rest", (double)(amax / PetscMax(emax, dmax)));
    PetscCall(MatTranspose(AvQ, MAT_INITIAL_MATRIX, &AQv));
    PetscCall(MatTranspose(BvQ, MAT_INITIAL_MATRIX, &BQv));
    {
      /* the system's own discrete rows applied to a field vector against the transposed columns */
      Vec       xv, yq, yQ;
      PetscReal *yfull, diff = 0, ref = 0;
      PetscCall(MatCreateVecs(sys->Cqv, &xv, &yq));
      PetscCall(VecSetRandom(xv, NULL));
      PetscCall(MatMult(sys->Cqv, xv, yq)); /* at shift 2: 2 E + A */
      PetscCall(PetscMalloc1(PetscMax(nq, 1), &yfull));
      PetscCall(RootValues(sys->comm, yq, nq, yfull));
      PetscCall(MatCreateVecs(AQv, NULL, &yQ));
      PetscCall(MatMult(AQv, xv, yQ));
      PetscCall(VecScale(yQ, 0.5));
      PetscCall(MatMultAdd(BQv, xv, yQ, yQ));
      {
        PetscReal *yQa;
        PetscCall(PetscMalloc1(PetscMax(nQ, 1), &yQa));
        PetscCall(RootValues(sys->comm, yQ, nQ, yQa));
        for (PetscInt ii = 0; ii < nQ; ii++) {
          diff = PetscMax(diff, PetscAbsReal(2.0 * yQa[ii] - yfull[p->Qq[ii]]));
          ref  = PetscMax(ref, PetscAbsReal(yfull[p->Qq[ii]]));
        }
        PetscCall(PetscFree(yQa));
      }
      PetscCheck(diff <= 1e-9 * PetscMax(ref, 1e-300), sys->comm, PETSC_ERR_PLIB, "linearized analysis: the discrete rows of the system differ from the transposed force distribution by %g (relative): a part or joint breaks the power-preserving structure", (double)(diff / PetscMax(ref, 1e-300)));
      PetscCall(PetscFree(yfull));
      PetscCall(VecDestroy(&xv));
      PetscCall(VecDestroy(&yq));
      PetscCall(VecDestroy(&yQ));
    }
  }
  /* the discrete block (on rank 0), all entries of the kept pattern */
  PetscCall(MatCreateAIJ(sys->comm, Ql, Ql, nQ, nQ, nQ, NULL, 0, NULL, &AQQ));
  PetscCall(MatCreateAIJ(sys->comm, Ql, Ql, nQ, nQ, nQ, NULL, 0, NULL, &BQQ));
  if (rank == 0) {
    for (PetscInt ii = 0; ii < nQ; ii++)
      for (PetscInt jj = 0; jj < nQ; jj++) {
        const PetscInt i = p->Qq[ii], j = p->Qq[jj];
        PetscReal      a = 0, b = 0;
        if (ii < nqv && jj < nqv) b = DE[i * nq + j], a = Kq ? Kq[ii * nqv + jj] : 0.0;
        else if (ii >= nqv && jj < nqv) a = DA[i * nq + j];
        else if (ii < nqv && jj >= nqv) a = DA[j * nq + i];
        PetscCall(MatSetValue(AQQ, ii, jj, a, INSERT_VALUES));
        PetscCall(MatSetValue(BQQ, ii, jj, b, INSERT_VALUES));
      }
  }
  PetscCall(MatAssemblyBegin(AQQ, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyBegin(BQQ, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(AQQ, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(BQQ, MAT_FINAL_ASSEMBLY));
  if (p->damped) {
    /* the discrete velocities' damping (a reduced body's modal or Rayleigh damping), on the same pattern */
    PetscCall(MatCreateAIJ(sys->comm, Ql, Ql, nQ, nQ, nQ, NULL, 0, NULL, &RQQ));
    if (rank == 0)
      for (PetscInt ii = 0; ii < nQ; ii++)
        for (PetscInt jj = 0; jj < nQ; jj++) PetscCall(MatSetValue(RQQ, ii, jj, ii < nqv && jj < nqv ? Rq[ii * nqv + jj] : 0.0, INSERT_VALUES));
    PetscCall(MatAssemblyBegin(RQQ, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(RQQ, MAT_FINAL_ASSEMBLY));
  }

  /* mechanism modes: the frames' and points' velocities the constraints and the force elements' springs leave free,
     nf - rank([Cq; K_el]) on them (their field is zero: a frame patch clamps it, mean axes constrain its rigid
     content; elastic velocities have stiffness); each block scaled to its largest entry */
  {
    PetscReal   *C, *s, work[1], *Kdd = NULL, cmax = 0, kmax = 0;
    PetscInt     nf = 0, *fcol, mk = p->nel ? nqv : 0;
    PetscBLASInt m = (PetscBLASInt)(p->nqi + mk), n, lwork = -1, info, one = 1;
    PetscInt     rnk = 0;
    PetscCall(PetscMalloc1(PetscMax(nqv, 1), &fcol));
    for (PetscInt jj = 0; jj < nqv; jj++)
      if (sys->qkind[p->Qq[jj]] == PHLEX_DOF_VELOCITY) fcol[nf++] = jj;
    n      = (PetscBLASInt)nf;
    *nmech = nf;
    if (mk) {
      PetscCall(PetscMalloc1(nqv * nqv, &Kdd));
      PetscCall(PhlexLinearizedElementDiscreteStiffness(p, DE, DA, Kdd));
      for (PetscInt k = 0; k < nqv * nqv; k++) kmax = PetscMax(kmax, PetscAbsReal(Kdd[k]));
    }
    if (m && n) {
      PetscReal *w;
      PetscCall(PetscMalloc2(m * n, &C, PetscMin(m, n), &s));
      for (PetscInt ii = 0; ii < p->nqi; ii++)
        for (PetscInt jj = 0; jj < n; jj++) cmax = PetscMax(cmax, PetscAbsReal(DA[p->Qq[nqv + ii] * nq + p->Qq[fcol[jj]]]));
      for (PetscInt ii = 0; ii < p->nqi; ii++)
        for (PetscInt jj = 0; jj < n; jj++) C[jj * m + ii] = DA[p->Qq[nqv + ii] * nq + p->Qq[fcol[jj]]] / (cmax > 0 ? cmax : 1.0); /* column-major */
      for (PetscInt ii = 0; ii < mk; ii++)
        for (PetscInt jj = 0; jj < n; jj++) C[jj * m + p->nqi + ii] = Kdd[ii * nqv + fcol[jj]] / (kmax > 0 ? kmax : 1.0);
      PetscCallBLAS("LAPACKgesvd", LAPACKgesvd_("N", "N", &m, &n, C, &m, s, NULL, &one, NULL, &one, work, &lwork, &info));
      lwork = (PetscBLASInt)work[0];
      PetscCall(PetscMalloc1(lwork, &w));
      PetscCallBLAS("LAPACKgesvd", LAPACKgesvd_("N", "N", &m, &n, C, &m, s, NULL, &one, NULL, &one, w, &lwork, &info));
      PetscCheck(!info, sys->comm, PETSC_ERR_LIB, "LAPACK gesvd failed (%d)", (int)info);
      for (PetscInt k = 0; k < PetscMin(m, n); k++)
        if (s[k] > 1e-10 * s[0]) rnk++;
      *nmech = nf - rnk;
      PetscCall(PetscFree(w));
      PetscCall(PetscFree2(C, s));
    }
    PetscCall(PetscFree(Kdd));
    PetscCall(PetscFree(fcol));
  }
  /* a fixed body without a clamp moves rigidly inside its field: six more zero modes (joints on it are not counted) */
  for (PetscInt f = 0; f < sys->nfparts; f++) {
    PhlexPart part = sys->fparts[f];
    char      kind[64];
    PetscInt  nrig = -1;
    if (part->frame.R >= 0 || !PhlexPartAnalysisOp(part, modeskind)) continue;
    PetscCall((*part->analysisops->modeskind)(part, kind, sizeof(kind), &nrig));
    if (nrig > 0) *nmech += nrig;
  }

  /* the pencil: [[K, AvQ], [AQv, AQQ]] and [[M, BvQ], [BQv, BQQ]] (and the force elements' stiffness) */
  {
    Mat A, B, Kel = NULL, Rel = NULL;
    blocks[0] = p->K, blocks[1] = AvQ, blocks[2] = AQv, blocks[3] = AQQ;
    PetscCall(MatCreateNest(sys->comm, sys->nfparts ? 2 : 1, NULL, sys->nfparts ? 2 : 1, NULL, sys->nfparts ? blocks : &blocks[3], &N));
    if (!p->isV && sys->nfparts) {
      IS is[2];
      PetscCall(MatNestGetISs(N, is, NULL));
      PetscCall(ISDuplicate(is[0], &p->isV));
      PetscCall(ISDuplicate(is[1], &p->isQ));
    } else if (!p->isQ) {
      IS is[1];
      PetscCall(MatNestGetISs(N, is, NULL));
      PetscCall(ISDuplicate(is[0], &p->isQ));
    }
    PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &A));
    PetscCall(MatDestroy(&N));
    blocks[0] = p->Mvv, blocks[1] = BvQ, blocks[2] = BQv, blocks[3] = BQQ;
    PetscCall(MatCreateNest(sys->comm, sys->nfparts ? 2 : 1, NULL, sys->nfparts ? 2 : 1, NULL, sys->nfparts ? blocks : &blocks[3], &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &B));
    PetscCall(MatDestroy(&N));
    if (p->nel) {
      PetscCall(PhlexLinearizedElementOperators(p, DE, DA, BE, &Kel, &Rel));
      PetscCall(MatAXPY(A, 1.0, Kel, DIFFERENT_NONZERO_PATTERN));
    }
    if (!p->A || p->nel) {
      /* with force elements the pattern follows their lines of action: new matrices (a new symbolic factorisation) */
      PetscCall(MatDestroy(&p->A));
      PetscCall(MatDestroy(&p->B));
      p->A = A, p->B = B;
      PetscCall(MatSetOption(p->A, MAT_SYMMETRIC, PETSC_TRUE));
      PetscCall(MatSetOption(p->B, MAT_SYMMETRIC, PETSC_TRUE));
    } else {
      /* the same pattern: the eigensolver's factorisation keeps its symbolic analysis */
      PetscCall(MatCopy(A, p->A, SAME_NONZERO_PATTERN));
      PetscCall(MatCopy(B, p->B, SAME_NONZERO_PATTERN));
      PetscCall(MatDestroy(&A));
      PetscCall(MatDestroy(&B));
    }
    if ((p->Gyr && p->coriolis) || p->damped) {
      /* the part proportional to the rate: [[Gyr + R, 0], [0, R_QQ]] and the force elements' dampers */
      Mat F = NULL, A1, G[4] = {NULL, NULL, NULL, RQQ};
      IS  is[2] = {p->isV, p->isQ};
      if (sys->nfparts) {
        PetscCall(MatDuplicate(p->Mvv, MAT_DO_NOT_COPY_VALUES, &F)); /* zero on M's pattern: a body with neither */
        if (p->Gyr && p->coriolis) PetscCall(MatAXPY(F, 1.0, p->Gyr, DIFFERENT_NONZERO_PATTERN));
        if (p->Rf) PetscCall(MatAXPY(F, 1.0, p->Rf, DIFFERENT_NONZERO_PATTERN));
        G[0] = F;
      }
      if (!RQQ) {
        PetscCall(MatCreateAIJ(sys->comm, Ql, Ql, nQ, nQ, 0, NULL, 0, NULL, &RQQ));
        PetscCall(MatAssemblyBegin(RQQ, MAT_FINAL_ASSEMBLY));
        PetscCall(MatAssemblyEnd(RQQ, MAT_FINAL_ASSEMBLY));
        G[3] = RQQ;
      }
      PetscCall(MatCreateNest(sys->comm, sys->nfparts ? 2 : 1, sys->nfparts ? is : &is[1], sys->nfparts ? 2 : 1, sys->nfparts ? is : &is[1], sys->nfparts ? G : &G[3], &N));
      PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &A1));
      PetscCall(MatDestroy(&N));
      PetscCall(MatDestroy(&F));
      if (Rel) PetscCall(MatAXPY(A1, 1.0, Rel, DIFFERENT_NONZERO_PATTERN));
      if (!p->A1 || p->nel) {
        PetscCall(MatDestroy(&p->A1));
        p->A1 = A1;
      } else {
        PetscCall(MatCopy(A1, p->A1, SAME_NONZERO_PATTERN));
        PetscCall(MatDestroy(&A1));
      }
    }
    PetscCall(MatDestroy(&Kel));
    PetscCall(MatDestroy(&Rel));
  }
  PetscCall(MatDestroy(&AvQ));
  PetscCall(MatDestroy(&BvQ));
  PetscCall(MatDestroy(&AQv));
  PetscCall(MatDestroy(&BQv));
  PetscCall(MatDestroy(&AQQ));
  PetscCall(MatDestroy(&BQQ));
  PetscCall(MatDestroy(&RQQ));
  PetscCall(MatDestroy(&BE));
  PetscCall(MatDestroy(&BA));
  PetscCall(PetscFree2(DE, DA));
  PetscCall(PetscFree(Kq));
  PetscCall(PetscFree(Rq));
  PetscFunctionReturn(0);
}

/* The state must be an equilibrium at rest: the residual of the velocity equations (the fields' and the discrete
   velocities') vanishes with no rate. A load set at t = 0 (port, frame or body forces), an initial stress or
   displacement that the joints hold, gravity: each leaves a residual, and the linearisation about rest would then
   silently drop it. (Loads whose profile starts later do not act on the state at t = 0.) */
static PetscErrorCode CheckEquilibrium(Pencil *p)
{
  PhlexSystem sys = p->sys;
  Vec         F;
  PetscReal   fv = 0, fq = 0;

  PetscFunctionBeginUser;
  PetscCall(VecDuplicate(p->X, &F));
  PetscCall(PhlexSystemIFunction(NULL, 0.0, p->X, p->Xdot, F, sys));
  if (sys->nfparts) {
    Vec f;
    PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &f));
    PetscCall(VecNorm(f, NORM_INFINITY, &fv));
    PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &f));
  }
  PetscCall(PhlexSystemGather(sys, F, sys->fq));
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_VELOCITY || sys->qkind[k] == PHLEX_DOF_ELASTIC_VELOCITY) fq = PetscMax(fq, PetscAbsReal(sys->fq[k]));
  PetscCall(VecDestroy(&F));
  /* a force element's spring at rest holds no force (its force row K e + f(e) = 0 with the rate zero): a preloaded
     spring would be a load the linearisation drops */
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint j = sys->joints[k];
    for (PetscInt i = 0; i < j->ne; i++) {
      const PetscReal f = PetscAbsReal(sys->fq[j->qoff + j->nc + i]);
      PetscCheck(f <= 1e-12, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: joint %s: its force element (row %s) holds a force at the linearisation point (%g, non-dimensional): its spring is not at its rest (-%srest_length, -%srest_angle, -%srest_slide) there; the analysis linearises about an unloaded configuration at rest", j->name, j->erowname[i], (double)f, j->prefix, j->prefix, j->prefix);
    }
  }
  PetscCheck(fv <= 1e-12 && fq <= 1e-12, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the configuration is not an equilibrium at rest (the momentum equations are off by %g in the fields, %g in the frames, points and elastic coordinates, non-dimensional): a load acts at t = 0 (a port, frame or body force) or the initial displacement or stress is not free of load; the analysis linearises about an unloaded configuration at rest", (double)fv, (double)fq);
  PetscFunctionReturn(0);
}

/* the driven joint of the sweep: named, or the scene's only driven joint */
static PetscErrorCode SweepJoint(PhlexSystem sys, const char name[], PhlexJoint *joint)
{
  PetscInt ndriven = 0;

  PetscFunctionBeginUser;
  *joint = NULL;
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint j = sys->joints[k];
    PetscBool  same;
    if (name[0]) {
      PetscCall(PetscStrcmp(name, j->name, &same));
      if (!same) continue;
      PetscCheck(j->drive_row >= 0, sys->comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_joint %s: the joint has no drive (-%sdrive_velocity): only a driven joint's position is swept", name, j->prefix);
      *joint = j;
      PetscFunctionReturn(0);
    }
    if (j->drive_row >= 0) {
      ndriven++;
      *joint = j;
    }
  }
  PetscCheck(!name[0], sys->comm, PETSC_ERR_USER_INPUT, "-linearized_sweep_joint %s: no joint of that name", name);
  PetscCheck(ndriven == 1, sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: a sweep moves a driven joint; the scene has %" PetscInt_FMT " driven joints: name one with -linearized_sweep_joint", ndriven);
  PetscFunctionReturn(0);
}

/* the mechanism moved to the drive position 'to' (rad or m) from 'from': the loops closed by the assembly's Newton
   in steps of at most 5 degrees (or 5 % of the reference length), so that it follows the assembly branch */
static PetscErrorCode MoveTo(Pencil *p, PhlexJoint j, PetscReal from, PetscReal to)
{
  PhlexSystem     sys  = p->sys;
  const PetscBool turn = j->drive_row == PHLEX_ROW_R3 ? PETSC_TRUE : PETSC_FALSE;
  const PetscReal step = turn ? 5.0 * PETSC_PI / 180.0 : 0.05 * sys->units->length;
  const PetscInt  n    = PetscMax(1, (PetscInt)PetscCeilReal(PetscAbsReal(to - from) / step - 1e-9));

  PetscFunctionBeginUser;
  for (PetscInt k = 1; k <= n; k++) {
    j->drive_initial = from + (to - from) * (PetscReal)k / (PetscReal)n;
    PetscCall(PhlexAssemblyClose(sys, 0.0, p->X, PETSC_FALSE, NULL));
  }
  PetscCall(PhlexAssemblyPlaceAttached(sys, p->X));
  PetscCall(PhlexSystemUpdateJoints(sys, p->X, 0.0));
  PetscFunctionReturn(0);
}

static PetscErrorCode SpectrumDestroy(Spectrum *s)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; s->x && i < s->n; i++) PetscCall(VecDestroy(&s->x[i]));
  PetscCall(PetscFree(s->x));
  PetscCall(PetscFree3(s->theta, s->resid, s->growth));
  PetscCall(PetscFree3(s->zeta, s->decay, s->wd));
  PetscCall(PetscMemzero(s, sizeof(*s)));
  PetscFunctionReturn(0);
}

/* the lowest nev non-zero eigenvalues and the nmech zero ones of the current pencil */
static PetscErrorCode SolvePencil(Pencil *p, EPS eps, PetscInt nev, PetscInt nmech, PetscBool vectors, Spectrum *s)
{
  PetscInt  want, nconv, nzero = 0;
  Vec       x;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscCall(EPSSetOperators(eps, p->A, p->B));
  want = nev + nmech;
  PetscCall(EPSSetDimensions(eps, want, PETSC_DEFAULT, PETSC_DEFAULT));
  /* a target just below zero: the saddle point is singular at 0 when the mechanism moves (unless one is given) */
  {
    PetscBool given;
    PetscCall(PetscOptionsHasName(NULL, "linearized_", "-eps_target", &given));
    if (!given) PetscCall(EPSSetTarget(eps, nmech ? -1e-6 : 0.0));
  }
  PetscCall(PhlexProgressEPSSolve(eps, "the linearized assembly"));
  PetscCall(EPSGetConverged(eps, &nconv));
  if (nconv < want) {
    PetscInt N;
    PetscCall(MatGetSize(p->A, &N, NULL));
    /* a small pencil (reduced bodies of few coordinates) may have fewer finite eigenvalues than wanted */
    PetscCheck(want <= N - 2 * p->nqi, p->sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: %" PetscInt_FMT " modes wanted (%" PetscInt_FMT " mechanism modes + -linearized_nev %" PetscInt_FMT "), but the pencil has %" PetscInt_FMT " velocities and %" PetscInt_FMT " constraint rows, at most %" PetscInt_FMT " modes: lower -linearized_nev (or give the reduced bodies more coordinates)", want, nmech, nev, N - p->nqi, p->nqi, N - 2 * p->nqi);
    SETERRQ(p->sys->comm, PETSC_ERR_NOT_CONVERGED, "linearized analysis: the eigensolver converged %" PetscInt_FMT " of the %" PetscInt_FMT " eigenpairs wanted (%" PetscInt_FMT " mechanism modes + -linearized_nev %" PetscInt_FMT "); see -linearized_eps_monitor, -linearized_eps_ncv", nconv, want, nmech, nev);
  }
  s->n = want;
  PetscCall(PetscCalloc3(want, &s->theta, want, &s->resid, want, &s->growth));
  if (vectors) PetscCall(PetscCalloc1(want, &s->x));
  {
    /* the want eigenvalues nearest the target (the solver's order; beyond them it may have converged spurious ones
       of the infinite eigenvalues of the singular B), ascending; a zero one (|omega^2| below 1e-8 of the largest of
       them) is a mechanism mode */
    PetscReal *th, thmax;
    PetscInt  *perm;
    PetscCall(PetscMalloc2(nconv, &th, nconv, &perm));
    for (PetscInt i = 0; i < nconv; i++) {
      PetscScalar kr, ki;
      PetscCall(EPSGetEigenvalue(eps, i, &kr, &ki));
      th[i]   = PetscRealPart(kr);
      perm[i] = i;
    }
    PetscCall(PetscSortRealWithPermutation(want, th, perm));
    thmax = 0; /* zero: relative to the spectrum computed (the time scale is arbitrary) */
    for (PetscInt i = 0; i < want; i++) thmax = PetscMax(thmax, PetscAbsReal(th[i]));
    PetscCall(MatCreateVecs(p->A, &x, NULL));
    for (PetscInt i = 0; i < want; i++) {
      const PetscInt e = perm[i];
      PetscScalar    kr, ki;
      PetscCall(EPSGetEigenpair(eps, e, &kr, &ki, x, NULL));
      s->theta[i] = PetscRealPart(kr);
      if (s->theta[i] < -1e-8 * thmax) s->growth[i] = PetscSqrtReal(-s->theta[i]), s->theta[i] = 0.0; /* divergence: K indefinite (a spin beyond a critical speed) */
      if (PetscAbsReal(s->theta[i]) <= 1e-8 * thmax && !s->growth[i]) {
        nzero++;
        /* the relative residual divides by the eigenvalue: the backward error instead */
        PetscCall(EPSComputeError(eps, e, EPS_ERROR_BACKWARD, &s->resid[i]));
      } else PetscCall(EPSComputeError(eps, e, EPS_ERROR_RELATIVE, &s->resid[i]));
      if (vectors) {
        PetscCall(VecDuplicate(x, &s->x[i]));
        PetscCall(VecCopy(x, s->x[i]));
      }
    }
    PetscCall(PetscFree2(th, perm));
  }
  PetscCall(VecDestroy(&x));
  s->nmech = nzero;
  PetscCheck(nzero == nmech, p->sys->comm, PETSC_ERR_NOT_CONVERGED, "linearized analysis: %" PetscInt_FMT " zero-frequency modes found where the constraints leave %" PetscInt_FMT " mechanism modes: a body's rigid motion is free without a frame (a fixed body without a clamp), or the spectrum is badly scaled (-scale_length)", nzero, nmech);
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* A damped assembly whose mechanism moves: its nmech mechanism modes N (the undamped pencil's zero modes) are zero
   eigenvalues of the quadratic pencil, semisimple where the damping acts on them and double (defective) where it does
   not, nzero = 2 nmech - rank(N^T A1 N) in all. Those computed carry errors of sqrt(tolerance) (1e-6 of the spectrum)
   and defective ones may not converge or come with spurious copies: the eigenvalues below 1e-4 of the undamped
   pencil's lowest pulsation (100 times their error at the tolerance 1e-12) are taken for them (an overdamped motion
   slower than that is taken for a mechanism's). The shift goes to the undamped pencil's lowest
   pulsation on the negative real axis (unless -linearized_pep_target is given): about 0 the defective eigenvalues
   would take the Krylov space (modes to 1e-9). */
static PetscErrorCode DampedMechanism(Pencil *p, EPS eps, PEP pep, PetscInt nmech, PetscInt *nzero, PetscReal *zero_tol)
{
  Spectrum     u;
  PetscBool    given;
  PetscReal   *G, *sv, work[1], *w, a1, gmax = 0;
  PetscBLASInt n = (PetscBLASInt)nmech, lwork = -1, info, one = 1;
  PetscInt     rank = 0;
  Vec          y;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&u, sizeof(u)));
  PetscCall(SolvePencil(p, eps, 1, nmech, PETSC_TRUE, &u));
  PetscCall(PetscOptionsHasName(NULL, "linearized_", "-pep_target", &given));
  if (!given) PetscCall(PEPSetTarget(pep, -PetscSqrtReal(PetscAbsReal(u.theta[nmech]))));
  *zero_tol = 1e-4 * PetscSqrtReal(PetscAbsReal(u.theta[nmech]));
  PetscCall(MatNorm(p->A1, NORM_FROBENIUS, &a1));
  PetscCall(PetscMalloc2(nmech * nmech, &G, nmech, &sv));
  PetscCall(VecDuplicate(u.x[0], &y));
  for (PetscInt j = 0; j < nmech; j++) {
    PetscReal nj;
    PetscCall(MatMult(p->A1, u.x[j], y));
    PetscCall(VecNorm(u.x[j], NORM_2, &nj));
    for (PetscInt i = 0; i < nmech; i++) {
      PetscScalar d;
      PetscReal   ni;
      PetscCall(VecDot(y, u.x[i], &d));
      PetscCall(VecNorm(u.x[i], NORM_2, &ni));
      G[j * nmech + i] = PetscRealPart(d) / (ni * nj * PetscMax(a1, PETSC_SMALL));
    }
  }
  PetscCall(VecDestroy(&y));
  PetscCallBLAS("LAPACKgesvd", LAPACKgesvd_("N", "N", &n, &n, G, &n, sv, NULL, &one, NULL, &one, work, &lwork, &info));
  lwork = (PetscBLASInt)work[0];
  PetscCall(PetscMalloc1(lwork, &w));
  PetscCallBLAS("LAPACKgesvd", LAPACKgesvd_("N", "N", &n, &n, G, &n, sv, NULL, &one, NULL, &one, w, &lwork, &info));
  PetscCheck(!info, p->sys->comm, PETSC_ERR_LIB, "LAPACK gesvd failed (%d)", (int)info);
  for (PetscInt k = 0; k < nmech; k++) gmax = PetscMax(gmax, sv[k]);
  for (PetscInt k = 0; k < nmech; k++)
    if (sv[k] > 1e-10) rank++; /* relative to |A1|: a damper on a mechanism's motion, however light */
  *nzero = 2 * nmech - rank;
  PetscCall(PetscFree(w));
  PetscCall(PetscFree2(G, sv));
  PetscCall(SpectrumDestroy(&u));
  PetscFunctionReturn(0);
}

/* About a spin with the Coriolis coupling kept: (A0 + lambda A1 + lambda^2 A2) x = 0 with A0 the saddle point of K,
   A1 the Coriolis part, A2 = diag(M, 0) and lambda = s the Laplace variable. The gyroscopic structure gives the
   eigenvalues in pairs +-lambda (and their conjugates): a stable mode is lambda = +-i omega, a divergence +-sigma
   real, a flutter sigma +- i omega. The lowest nev modes (one of each pair), ascending in |lambda|. */
static PetscErrorCode SolveGyroscopic(Pencil *p, PEP pep, PetscInt nev, PetscInt nmech, PetscBool vectors, Spectrum *s)
{
  Mat       A[3] = {p->A, p->A1, p->B};
  PetscInt  nconv, n = 0;
  Vec       xr, xi;
  PetscReal *mag, *om, *gr, *res, lmax = 0;
  PetscInt  *idx, *perm;

  PetscFunctionBeginUser;
  PetscCheck(!nmech, p->sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the configuration has %" PetscInt_FMT " mechanism modes; with the Coriolis coupling of a spin (a quadratic eigenproblem) a zero eigenvalue is defective: give -linearized_coriolis false, or hold the mechanism", nmech);
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscCall(PEPSetOperators(pep, 3, A));
  PetscCall(PEPSetDimensions(pep, 2 * nev, PETSC_DEFAULT, PETSC_DEFAULT));
  PetscCall(PhlexProgressPEPSolve(pep, "the linearized assembly"));
  PetscCall(PEPGetConverged(pep, &nconv));
  PetscCall(PetscMalloc6(nconv, &mag, nconv, &om, nconv, &gr, nconv, &res, nconv, &idx, nconv, &perm));
  PetscCall(MatCreateVecs(p->A, &xr, NULL));
  PetscCall(VecDuplicate(xr, &xi));
  for (PetscInt i = 0; i < nconv; i++) {
    PetscScalar kr, ki;
    PetscCall(PEPGetEigenpair(pep, i, &kr, &ki, NULL, NULL));
    lmax = PetscMax(lmax, PetscSqrtReal(PetscRealPart(kr) * PetscRealPart(kr) + PetscRealPart(ki) * PetscRealPart(ki)));
  }
  for (PetscInt i = 0; i < nconv; i++) {
    PetscScalar     kr, ki;
    PetscReal       re, im, m;
    PetscCall(PEPGetEigenpair(pep, i, &kr, &ki, NULL, NULL));
    re = PetscRealPart(kr), im = PetscRealPart(ki), m = PetscSqrtReal(re * re + im * im);
    /* one of each pair: the one with im > 0, or the growing one of a real pair (re > 0); of a flutter quadruple
       +-sigma +- i omega the growing one with im > 0 */
    if (im < -1e-10 * lmax || (PetscAbsReal(im) <= 1e-10 * lmax && re < 0)) continue;
    if (im > 1e-10 * lmax && re < -1e-8 * m) continue;
    mag[n] = m, om[n] = PetscMax(im, 0.0), gr[n] = PetscAbsReal(re) > 1e-8 * m ? PetscAbsReal(re) : 0.0, idx[n] = i, perm[n] = n;
    PetscCall(PEPComputeError(pep, i, PEP_ERROR_BACKWARD, &res[n]));
    n++;
  }
  PetscCheck(n >= nev, p->sys->comm, PETSC_ERR_NOT_CONVERGED, "linearized analysis: the quadratic eigensolver converged %" PetscInt_FMT " of the %" PetscInt_FMT " modes wanted (-linearized_nev); see -linearized_pep_monitor, -linearized_pep_ncv", n, nev);
  PetscCall(PetscSortRealWithPermutation(n, mag, perm));
  s->n     = nev;
  s->nmech = 0;
  PetscCall(PetscCalloc3(nev, &s->theta, nev, &s->resid, nev, &s->growth));
  if (vectors) PetscCall(PetscCalloc1(nev, &s->x));
  for (PetscInt k = 0; k < nev; k++) {
    const PetscInt j = perm[k];
    s->theta[k]  = om[j] * om[j];
    s->growth[k] = gr[j];
    s->resid[k]  = res[j];
    if (vectors) {
      /* the real shape at the phase where it is largest (a gyroscopic mode is complex: a travelling or elliptic motion) */
      PetscReal nr, ni;
      PetscCall(PEPGetEigenpair(pep, idx[j], NULL, NULL, xr, xi));
      PetscCall(VecNorm(xr, NORM_2, &nr));
      PetscCall(VecNorm(xi, NORM_2, &ni));
      PetscCall(VecDuplicate(xr, &s->x[k]));
      PetscCall(VecCopy(nr >= ni ? xr : xi, s->x[k]));
    }
  }
  PetscCall(PetscFree6(mag, om, gr, res, idx, perm));
  PetscCall(VecDestroy(&xr));
  PetscCall(VecDestroy(&xi));
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* mode shapes of every flexible body at one configuration: <body>_modes.h5/.xmf (the whole velocity, frame motion
   included, normalised to 1), each body placed where it sits and its shapes in inertial components */
static PetscErrorCode WriteShapes(Pencil *p, PhlexOutput out, const Spectrum *s)
{
  PhlexSystem sys = p->sys;
  PetscReal  *qv, *rigid, *lambda, *scale;
  Vec        *vecs;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc4(PetscMax(p->nQ, 1), &qv, 6 * s->n, &rigid, s->n, &lambda, s->n, &vecs));
  PetscCall(PhlexSystemGather(sys, p->X, sys->q)); /* the configuration (placements) */
  for (PetscInt i = 0; i < s->n; i++) lambda[i] = s->theta[i];
  /* one scale per mode for the whole assembly: its largest nodal field or frame velocity is 1 (so the bodies' shapes
     meet at the joints; elastic velocities are modal amplitudes, not velocities of points) */
  PetscCall(PetscMalloc1(s->n, &scale));
  for (PetscInt i = 0; i < s->n; i++) {
    Vec       xV, xQ;
    PetscReal m = 0;
    PetscCall(VecGetSubVector(s->x[i], p->isV, &xV));
    PetscCall(VecNorm(xV, NORM_INFINITY, &m));
    PetscCall(VecRestoreSubVector(s->x[i], p->isV, &xV));
    PetscCall(VecGetSubVector(s->x[i], p->isQ, &xQ));
    PetscCall(RootValues(sys->comm, xQ, p->nQ, qv));
    PetscCall(VecRestoreSubVector(s->x[i], p->isQ, &xQ));
    for (PetscInt k = 0; k < p->nqv; k++)
      if (sys->qkind[p->Qq[k]] == PHLEX_DOF_VELOCITY) m = PetscMax(m, PetscAbsReal(qv[k]));
    scale[i] = m > 0 ? 1.0 / m : 1.0;
  }
  for (PetscInt f = 0; f < sys->nfparts; f++) {
    PhlexPart part = sys->fparts[f];
    if (!PhlexPartAnalysisOp(part, modesoutput)) continue;
    for (PetscInt i = 0; i < s->n; i++) {
      Vec xV, xQ, xi;
      PetscCall(VecGetSubVector(s->x[i], p->isV, &xV));
      PetscCall(VecGetSubVector(xV, sys->fis[PHLEX_FIELD_VELOCITY][f], &xi));
      PetscCall(VecDuplicate(xi, &vecs[i]));
      PetscCall(VecCopy(xi, vecs[i]));
      PetscCall(VecScale(vecs[i], scale[i]));
      PetscCall(VecRestoreSubVector(xV, sys->fis[PHLEX_FIELD_VELOCITY][f], &xi));
      PetscCall(VecRestoreSubVector(s->x[i], p->isV, &xV));
      PetscCall(VecGetSubVector(s->x[i], p->isQ, &xQ));
      PetscCall(RootValues(sys->comm, xQ, p->nQ, qv));
      PetscCall(VecRestoreSubVector(s->x[i], p->isQ, &xQ));
      for (PetscInt c = 0; c < 6; c++) rigid[6 * i + c] = 0.0;
      for (PetscInt c = 0; c < 3; c++) {
        if (part->frame.v >= 0) rigid[6 * i + c] = scale[i] * qv[p->qmap[part->qoff + part->frame.v + c]];
        if (part->frame.w >= 0) rigid[6 * i + 3 + c] = scale[i] * qv[p->qmap[part->qoff + part->frame.w + c]];
      }
    }
    {
      /* where the body sits in this configuration: its frame's r_P and R */
      PetscReal place[12], *pl = NULL;
      if (part->frame.r >= 0 && part->frame.R >= 0) {
        for (PetscInt k = 0; k < 3; k++) place[k] = sys->q[part->qoff + part->frame.r + k];
        for (PetscInt k = 0; k < 9; k++) place[3 + k] = sys->q[part->qoff + part->frame.R + k];
        pl = place;
      }
      PetscCall((*part->analysisops->modesoutput)(part, out, s->n, s->nmech, lambda, vecs, rigid, pl));
    }
    for (PetscInt i = 0; i < s->n; i++) PetscCall(VecDestroy(&vecs[i]));
  }
  for (PetscInt i = 0; i < sys->nparts; i++)
    if (!sys->parts[i]->fieldops && PhlexPartIsElastic(sys->parts[i])) PetscCall(PetscPrintf(sys->comm, "  mode shapes of body %s not written: the linearised analysis draws the fields of full bodies only (-%stype %s: its own modes' shapes come with -analysis modes)\n", sys->parts[i]->name, sys->parts[i]->prefix, sys->parts[i]->type));
  PetscCall(PetscFree4(qv, rigid, lambda, vecs));
  PetscCall(PetscFree(scale));
  PetscFunctionReturn(0);
}

/* the parts' steady states (a prescribed spin's centrifugal stretch and its stress; at rest nothing moves) */
static PetscErrorCode SteadyStates(Pencil *p)
{
  PhlexSystem sys = p->sys;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemGather(sys, p->X, sys->q));
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart    part = sys->parts[i];
    PhlexPartVec pv;
    if (!PhlexPartAnalysisOp(part, steadystate)) continue;
    PetscCall(PhlexSystemPartVec(sys, part, p->X, sys->q, &pv));
    PetscCall((*part->analysisops->steadystate)(part, &pv));
    PetscCall(PhlexSystemPartVecRestore(sys, part, p->X, &pv));
  }
  PetscFunctionReturn(0);
}

/* Rotors: a floating body held at one port by a revolute to the ground whose drive turns at a constant rate, and by
   nothing else, moves steadily (a uniform rotation): it is linearised in its drive's co-rotating frame, where its
   state is constant (analysisops->steadydrive, before the system is built). A driven joint of a mechanism (the
   four-bar's crank) is held at its position, as before: its bodies do not move steadily. Refused: a rotor whose drive's
   rate varies, and a body that turns at the start (-angular_velocity) without such a drive (a free revolute: nothing
   makes the spin steady, and the analysis about rest would silently drop it). */
static PetscErrorCode SteadyDrives(PhlexScene scene)
{
  PetscInt nrot = 0;
  char     rotors[256] = ""; /* "body on joint, ..." for the refusal of several */

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < scene->njoints; k++) {
    PhlexJoint j = scene->joints[k];
    PetscInt   s, others = 0;
    PhlexPart  body;
    PetscReal  e3[3], n = 0, w[3], fmax;
    char       rate[32];
    if (j->drive_row < 0 || j->drive_velocity == 0 || j->type != PHLEX_JOINT_REVOLUTE) continue;
    if (j->side[0].port >= 0 && j->side[1].port < 0) s = 0;
    else if (j->side[1].port >= 0 && j->side[0].port < 0) s = 1;
    else continue; /* between two bodies */
    body = j->side[s].part;
    if (!PhlexPartAnalysisOp(body, steadydrive)) continue;
    for (PetscInt l = 0; l < scene->njoints; l++)
      if (l != k && (scene->joints[l]->side[0].part == body || scene->joints[l]->side[1].part == body)) others++;
    if (others) continue; /* in a mechanism: the drive is held */
    PhlexFormatReal(j->drive_velocity, rate, sizeof(rate));
    /* steady: a constant profile from t = 0 (its value the scale) */
    fmax = j->drive_profile->scale;
    PetscCheck(j->drive_profile->type == PHLEX_PROFILE_CONSTANT && j->drive_profile->start_time <= 0 && fmax != 0, scene->comm, PETSC_ERR_USER_INPUT, "linearized analysis: body %s turns on joint %s, whose drive (-%sdrive_velocity %s) follows a profile that varies (-%sdrive_profile_*): not a steady motion; linearise about a constant rate (or at rest: -%sdrive_velocity 0)", body->name, j->name, j->prefix, rate, j->prefix, j->prefix);
    for (PetscInt i = 0; i < 3; i++) n += j->axis[i] * j->axis[i];
    for (PetscInt i = 0; i < 3; i++) {
      e3[i] = j->axis[i] / PetscSqrtReal(n);
      /* the drive turns b relative to a about e3: the body is b (+) or a, the ground b (-) */
      w[i] = (s == 1 ? 1.0 : -1.0) * j->drive_velocity * fmax * e3[i];
    }
    if (nrot) PetscCall(PetscStrlcat(rotors, ", ", sizeof(rotors)));
    PetscCall(PetscStrlcat(rotors, body->name, sizeof(rotors)));
    PetscCall(PetscStrlcat(rotors, " on joint ", sizeof(rotors)));
    PetscCall(PetscStrlcat(rotors, j->name, sizeof(rotors)));
    nrot++;
    PetscCheck(nrot <= 1, scene->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the scene has several rotors on driven revolutes (%s); the analysis linearises about one steady spin (its co-rotating frame): one rotor per scene", rotors);
    PetscCall((*body->analysisops->steadydrive)(body, j->side[s].port, w, j->position_given ? j->position : NULL));
  }
  PetscFunctionReturn(0);
}

/* the part on a prescribed spin (a spin sweep needs exactly one) */
static PetscErrorCode SpinningPart(PhlexSystem sys, PhlexPart *spun, PetscInt *nspun)
{
  PetscFunctionBeginUser;
  *spun  = NULL;
  *nspun = 0;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PetscReal rate = -1;
    if (PhlexPartAnalysisOp(sys->parts[i], spinrate)) PetscCall((*sys->parts[i]->analysisops->spinrate)(sys->parts[i], PETSC_FALSE, &rate));
    if (rate >= 0) *spun = sys->parts[i], (*nspun)++;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSolveLinearized - linearised analysis of the assembly: the lowest frequencies and mode shapes of the
  whole mechanism linearised about configurations at rest, swept over a driven joint's position in one run

  Collective

  Options Database Keys:
+ -linearized_nev <n>                     - elastic frequencies wanted per configuration (default 6)
. -linearized_sweep_joint <name>          - the driven joint whose position is swept (default: the only driven joint)
. -linearized_sweep a,b,...               - its positions [deg or m, as -drive_initial]
. -linearized_sweep_range start,stop,step - the same as a range (stop included)
. -linearized_spin_sweep w1,w2,...       - spin rates [rad/s] of the body with -spin (its steady state for each)
. -linearized_spin_sweep_range start,stop,step - the same as a range
. -linearized_coriolis <bool>             - about a spin, keep the Coriolis coupling (default true: quadratic eigenproblem)
. -linearized_fields_configuration <k>    - the configuration whose mode shapes are written (default 0; -1 none)
. -expect_frequencies f1,f2,...           - self-check: elastic frequencies [Hz] of the first configuration
. -expect_frequencies_rtol <r>            - its relative tolerance (default 1e-6)
. -expect_residual_max <r>                - bound on the relative eigenpair residuals
- -linearized_eps_*, -linearized_st_*     - SLEPc options (defaults: Krylov-Schur, shift-and-invert, LDL^T by MUMPS)

  Notes:
  A driven joint is held at its position (its drive row is a constraint: a clamped crank), but for a rotor (a
  floating body held at its frame patch by a revolute to the ground driven at a constant rate, and by nothing else:
  SteadyDrives), which is linearised about its steady spin in the co-rotating frame as a body with -spin. A body with -spin is
  linearised about its steady spin in its rotating frame: the centrifugal stretch u0 and its stress (Newton with
  -geometric_stiffening), the stiffness G(u0)^T Ms^{-1} G(u0) + K_sigma + Cen and the Coriolis coupling. Writes
  linearized_modes.csv (every mode of every configuration), linearized_sweep.csv (one row per configuration) and the
  mode shapes of one configuration.
@*/
PetscErrorCode PhlexSceneSolveLinearized(PhlexScene scene)
{
  LinearizedOptions o;
  Pencil            p;
  PhlexJoint        joint = NULL;
  EPS               eps;
  PEP               pep = NULL;
  PhlexPart         spun = NULL;
  PetscInt          nspun = 0;
  PetscViewer       csv, sweep;
  PetscReal         here = 0, worst = 0, *fexp = NULL, *zexp = NULL, unit = 1;
  PetscInt          nconfig, nfexp = 0, nzexp = 0, Nd;
  const char       *uname = "";
  PetscLogDouble    t0, t1, tbuild = 0, tsolve = 0;

  PetscFunctionBeginUser;
  PetscCall(LinearizedSetFromOptions(scene->comm, &o));
  PetscCall(LinearizedEPSCreate(scene->comm, &eps));
  if (PhlexHelpGetMode() != PHLEX_HELP_OPTIONS) PetscCall(EPSSetFromOptions(eps));
  /* the quadratic eigensolver's options read before the check of unused options (it runs about a spin or with damping) */
  PetscCall(LinearizedPEPCreate(scene->comm, &pep));
  if (PhlexHelpGetMode() == PHLEX_HELP_NONE) PetscCall(PEPSetFromOptions(pep));
  if (PhlexHelpGetMode() != PHLEX_HELP_NONE) {
    PetscCall(EPSDestroy(&eps));
    PetscCall(PEPDestroy(&pep));
    PetscFunctionReturn(0);
  }
  PetscCall(PhlexOptionsCheckUnused(scene->comm, PhlexLinearizedRereadOptions, &scene->comm));
  if (scene->gravity[0] != 0 || scene->gravity[1] != 0 || scene->gravity[2] != 0) {
    char g[3][32];
    for (PetscInt k = 0; k < 3; k++) PhlexFormatReal(scene->gravity[k], g[k], sizeof(g[k]));
    SETERRQ(scene->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the scene has gravity (-gravity %s,%s,%s): the analysis linearises about an unloaded configuration at rest", g[0], g[1], g[2]);
  }
  {
    PetscBool flexible = PETSC_FALSE;
    for (PetscInt k = 0; k < scene->nparts; k++)
      if (PhlexPartAnalysisOp(scene->parts[k], modes)) flexible = PETSC_TRUE;
    for (PetscInt k = 0; k < scene->njoints; k++)
      if (scene->joints[k]->type == PHLEX_JOINT_SPRING_DAMPER || scene->joints[k]->type == PHLEX_JOINT_BUSHING || scene->joints[k]->rot_element || scene->joints[k]->slide_element) flexible = PETSC_TRUE;
    PetscCheck(flexible, scene->comm, PETSC_ERR_USER_INPUT, "linearized analysis: the scene has no flexible body (nor a reduced one) and no force element; rigid bodies and point masses on joints alone have no modes about rest but their mechanism's");
  }
  PetscCall(PetscMemzero(&p, sizeof(p)));
  p.coriolis = o.coriolis;
  PetscCall(PhlexLogStagePush("Phlex Modes", &PHLEX_StageModes));
  PetscCall(PetscTime(&t0));
  PetscCall(SteadyDrives(scene));
  PetscCall(PhlexSystemCreateForScene(scene, &p.sys, &p.X));
  {
    /* a body that turns at the start without a drive that makes it steady (a free revolute, a body of a mechanism
       whose drive the analysis holds): the analysis about rest drops its spin, and says so (a scene of a transient
       linearised about its drawn configuration: tests/scenes/force_elements.yaml) */
    PetscCall(PhlexSystemGather(p.sys, p.X, p.sys->q));
    for (PetscInt i = 0; i < p.sys->nparts; i++) {
      PhlexPart part = p.sys->parts[i];
      PetscReal rate = -1, w = 0;
      PetscBool jointed = PETSC_FALSE;
      if (part->frame.w < 0) continue;
      if (PhlexPartAnalysisOp(part, spinrate)) PetscCall((*part->analysisops->spinrate)(part, PETSC_FALSE, &rate));
      if (rate >= 0) continue; /* the rotor, in its hub's co-rotating frame */
      for (PetscInt k = 0; k < 3; k++) w += PetscSqr(p.sys->q[part->qoff + part->frame.w + k] / p.sys->units->time);
      for (PetscInt k = 0; k < p.sys->njoints; k++)
        if (p.sys->joints[k]->side[0].part == part || p.sys->joints[k]->side[1].part == part) jointed = PETSC_TRUE;
      if (w > 0 && jointed) {
        char a[32];
        PhlexFormatReal(PetscSqrtReal(w), a, sizeof(a));
        PetscCall(PetscFPrintf(scene->comm, PETSC_STDERR, "phlex: warning: linearized analysis: body %s turns at the start (%s rad/s: -%sangular_velocity or its initial velocity field), but no drive makes the motion steady: it is linearised about rest, its spin left out (the analysis linearises about rest, where its joints' drives are held, or about the steady spin of one floating body held at its frame patch by a revolute to the ground driven at a constant rate and by nothing else)\n", part->name, a, part->prefix));
      }
    }
  }
  /* a body's damping or an element's damper: the quadratic eigenproblem of the damped assembly */
  for (PetscInt i = 0; i < p.sys->nparts; i++)
    if (p.sys->parts[i]->ops.dissipation) p.damped = PETSC_TRUE;
  for (PetscInt k = 0; k < p.sys->njoints; k++)
    if (PhlexJointDamped(p.sys->joints[k])) p.damped = PETSC_TRUE;
  PetscCheck(p.damped || !o.nzexp, scene->comm, PETSC_ERR_USER_INPUT, "-expect_damping_ratios: the assembly has no damping (no body's -rayleigh_alpha, -rayleigh_beta, -viscosity or -modal_damping_ratios, no force element's damper)");
  PetscCall(VecDuplicate(p.X, &p.Xdot));
  PetscCall(VecSet(p.Xdot, 0.0));
  PetscCall(BuildDiscreteMap(&p));
  if (p.sys->njoints) PetscCall(PhlexAssemblyClose(p.sys, 0.0, p.X, PETSC_TRUE, NULL));
  PetscCall(PhlexSystemInitElements(p.sys, p.X)); /* the force elements' states from the placements (a preload is refused) */
  if (p.sys->njoints) PetscCall(PhlexSystemUpdateJoints(p.sys, p.X, 0.0));
  PetscCall(SetRest(&p));
  PetscCall(SpinningPart(p.sys, &spun, &nspun));
  if (o.nspins) {
    PetscCheck(nspun == 1, scene->comm, PETSC_ERR_USER_INPUT, "-linearized_spin_sweep: sweeps the rate of the body with -<body>_spin; the scene has %" PetscInt_FMT " such bodies", nspun);
    PetscCall((*spun->analysisops->spinrate)(spun, PETSC_TRUE, &o.spins[0]));
  }
  PetscCall(SteadyStates(&p));
  PetscCall(CheckEquilibrium(&p));
  if (p.sys->nfparts) PetscCall(BuildFieldOperators(&p));
  else p.scale = 1.0;
  if ((p.Gyr && p.coriolis) || p.damped) {
    if (p.damped) PetscCall(PEPSetProblemType(pep, PEP_GENERAL)); /* A1 = R (+ Coriolis): no pairs +-lambda */
    PetscCall(PEPSetFromOptions(pep));
  } else PetscCall(PEPDestroy(&pep));
  PetscCall(PetscTime(&t1));
  tbuild += t1 - t0;

  /* the configurations */
  nconfig = PetscMax(PetscMax(o.nvalues, o.nspins), 1);
  if (o.nvalues || o.joint[0]) {
    PetscCall(SweepJoint(p.sys, o.joint, &joint));
    unit  = joint->drive_row == PHLEX_ROW_R3 ? PETSC_PI / 180.0 : 1.0;
    uname = joint->drive_row == PHLEX_ROW_R3 ? "deg" : "m";
    here  = joint->drive_initial;
  }
  PetscCheck(o.fields_configuration < nconfig, scene->comm, PETSC_ERR_USER_INPUT, "-linearized_fields_configuration %" PetscInt_FMT ": the run has %" PetscInt_FMT " configurations (0-based)", o.fields_configuration, nconfig);
  Nd = 0;
  if (p.sys->nfparts) PetscCall(MatGetSize(p.Mvv, &Nd, NULL));
  if (spun) {
    char      w[32];
    PetscReal rate;
    PetscCall((*spun->analysisops->spinrate)(spun, PETSC_FALSE, &rate));
    PhlexFormatReal(rate, w, sizeof(w));
    PetscCall(PetscPrintf(scene->comm, "Linearised analysis about the steady spin of body %s (%s rad/s%s; Coriolis coupling %s): %" PetscInt_FMT " configuration%s", spun->name, w, o.nspins > 1 ? " first" : "", pep ? "kept, quadratic eigenproblem" : (p.Gyr ? "left out" : "none"), nconfig, nconfig == 1 ? "" : "s"));
    if (o.nspins > 1) {
      char a[32], b[32];
      PhlexFormatReal(o.spins[0], a, sizeof(a));
      PhlexFormatReal(o.spins[o.nspins - 1], b, sizeof(b));
      PetscCall(PetscPrintf(scene->comm, " of spin rate %s to %s rad/s", a, b));
    }
  } else PetscCall(PetscPrintf(scene->comm, "Linearised analysis of the assembly about rest: %" PetscInt_FMT " configuration%s", nconfig, nconfig == 1 ? "" : "s"));
  if (joint) {
    char a[32], b[32];
    PhlexFormatReal(o.nvalues ? o.values[0] : here / unit, a, sizeof(a));
    PhlexFormatReal(o.nvalues ? o.values[o.nvalues - 1] : here / unit, b, sizeof(b));
    PetscCall(PetscPrintf(scene->comm, " of joint %s (drive position %s to %s %s)", joint->name, a, b, uname));
  }
  PetscCall(PetscPrintf(scene->comm, ", %" PetscInt_FMT " elastic frequencies each\n", o.nev));
  if (p.ne) PetscCall(PetscPrintf(scene->comm, "  pencil: %" PetscInt_FMT " field velocities, %" PetscInt_FMT " discrete velocities (%" PetscInt_FMT " elastic), %" PetscInt_FMT " constraint rows (stress and elastic coordinates eliminated, positions at rest dropped)\n", Nd, p.nqv, p.ne, p.nqi));
  else PetscCall(PetscPrintf(scene->comm, "  pencil: %" PetscInt_FMT " field velocities, %" PetscInt_FMT " discrete velocities, %" PetscInt_FMT " constraint rows (stress eliminated, positions at rest dropped)\n", Nd, p.nqv, p.nqi));

  PetscCall(PhlexOutputCSVOpen(scene->output, "linearized_modes.csv", "configuration,position,mode,kind,frequency_hz,omega_rad_s,relative_residual,growth_rate_1_s,damping_ratio,damped_frequency_hz,decay_rate_1_s", &csv));
  PetscCall(PhlexOutputCSVOpen(scene->output, "linearized_sweep.csv", NULL, &sweep));
  PetscCall(PetscViewerASCIIPrintf(sweep, "configuration,position,mechanism_modes"));
  for (PetscInt m = 0; m < o.nev; m++) PetscCall(PetscViewerASCIIPrintf(sweep, ",omega%" PetscInt_FMT "_rad_s", m + 1));
  PetscCall(PetscViewerASCIIPrintf(sweep, "\n"));
  if (nconfig > 1) {
    PetscCall(PetscPrintf(scene->comm, "  %6s %12s  %4s", "config", joint ? (joint->drive_row == PHLEX_ROW_R3 ? "angle [deg]" : "slide [m]") : (o.nspins ? "spin [rad/s]" : ""), "mech"));
    for (PetscInt m = 0; m < o.nev; m++) PetscCall(PetscPrintf(scene->comm, "   f%-2" PetscInt_FMT " [Hz]    ", m + 1));
    PetscCall(PetscPrintf(scene->comm, "\n"));
  }
  for (PetscInt c = 0; c < nconfig; c++) {
    PetscReal pos = o.nvalues ? o.values[c] : (o.nspins ? o.spins[c] : here / unit);
    const PetscBool shapes = (PetscBool)(c == o.fields_configuration && scene->output->fields);
    if (spun && !o.nspins && !joint) PetscCall((*spun->analysisops->spinrate)(spun, PETSC_FALSE, &pos)); /* the scene's spin rate */
    PetscInt        nmech, nzero = 0;
    PetscReal       zero_tol = 0;
    Spectrum        s;
    PetscCall(PetscTime(&t0));
    if (joint && o.nvalues) {
      PetscCall(MoveTo(&p, joint, here, pos * unit));
      PetscCall(PhlexSystemInitElements(p.sys, p.X)); /* a spring the move loads is refused below */
      here = pos * unit;
      PetscCall(SetRest(&p));
      PetscCall(CheckEquilibrium(&p));
    }
    if (o.nspins && c > 0) {
      /* the next spin rate: its steady state from the previous one, and the field operators about it */
      PetscCall((*spun->analysisops->spinrate)(spun, PETSC_TRUE, &o.spins[c]));
      PetscCall(SteadyStates(&p));
      PetscCall(CheckEquilibrium(&p));
      PetscCall(BuildFieldOperators(&p));
    }
    PetscCall(BuildPencil(&p, &nmech));
    PetscCall(PetscTime(&t1));
    tbuild += t1 - t0;
    t0 = t1;
    PetscCall(PetscMemzero(&s, sizeof(s)));
    if (p.damped && nmech) PetscCall(DampedMechanism(&p, eps, pep, nmech, &nzero, &zero_tol));
    if (p.damped) PetscCall(PhlexLinearizedSolveDamped(&p, pep, o.nev, nmech, nzero, zero_tol, shapes, &s));
    else if (pep) PetscCall(SolveGyroscopic(&p, pep, o.nev, nmech, shapes, &s));
    else PetscCall(SolvePencil(&p, eps, o.nev, nmech, shapes, &s));
    PetscCall(PetscTime(&t1));
    tsolve += t1 - t0;
    /* a damped assembly's mechanism modes (zero eigenvalues, defective where nothing damps them) are counted, not listed */
    const PetscInt nmech_shown = p.damped ? nmech : s.nmech;
    if (nconfig == 1) {
      if (p.damped) PetscCall(PetscPrintf(scene->comm, "  %" PetscInt_FMT " mechanism mode%s (zero eigenvalue, not listed); damped modes lambda = -zeta omega +- i omega_d\n  mode  frequency [Hz]       omega [rad/s]        damping ratio   damped freq. [Hz]    kind        backward err.\n", nmech_shown, nmech_shown == 1 ? "" : "s"));
      else PetscCall(PetscPrintf(scene->comm, "  %" PetscInt_FMT " mechanism mode%s (zero frequency)\n  mode  frequency [Hz]       omega [rad/s]        kind       %s\n", s.nmech, s.nmech == 1 ? "" : "s", pep ? "backward err." : "rel. residual"));
    } else PetscCall(PetscPrintf(scene->comm, "  %6" PetscInt_FMT " %12.6g  %4" PetscInt_FMT, c, (double)pos, nmech_shown));
    PetscCall(PetscViewerASCIIPrintf(sweep, "%" PetscInt_FMT ",%.12g,%" PetscInt_FMT, c, (double)pos, nmech_shown));
    for (PetscInt i = 0; i < s.n; i++) {
      const PetscBool mech  = (PetscBool)(i < s.nmech);
      const PetscBool over  = (PetscBool)(s.zeta && PetscIsNanReal(s.zeta[i])); /* a real eigenvalue: no oscillation */
      const PetscReal omega = mech || over ? 0.0 : PetscSqrtReal(PetscAbsReal(s.theta[i])) / scene->units.time;
      const PetscReal f     = omega / (2.0 * PETSC_PI);
      const PetscReal grow  = s.growth[i] / scene->units.time; /* 1/s */
      const PetscReal zeta  = s.zeta ? s.zeta[i] : 0.0;
      const PetscReal fd    = s.wd ? s.wd[i] / scene->units.time / (2.0 * PETSC_PI) : f;
      const PetscReal decay = s.decay ? s.decay[i] / scene->units.time : 0.0;
      const char     *kind  = mech ? "mechanism" : (grow > 0 ? "unstable" : (over ? "overdamped" : (p.damped ? "damped" : "elastic")));
      if (nconfig == 1 && p.damped) {
        PetscCall(PetscPrintf(scene->comm, "  %4" PetscInt_FMT "  %-18.10g   %-18.10g   %-14.8g  %-18.10g   %-10s  %.1e", i + 1, (double)f, (double)omega, (double)zeta, (double)fd, kind, (double)s.resid[i]));
        if (grow > 0) PetscCall(PetscPrintf(scene->comm, "  (grows as exp(%.6g t))", (double)grow));
        else if (over) PetscCall(PetscPrintf(scene->comm, "  (decays as exp(-%.10g t))", (double)decay));
        PetscCall(PetscPrintf(scene->comm, "\n"));
      } else if (nconfig == 1) {
        PetscCall(PetscPrintf(scene->comm, "  %4" PetscInt_FMT "  %-18.10g   %-18.10g   %-9s  %.1e", i + 1, (double)f, (double)omega, kind, (double)s.resid[i]));
        if (grow > 0) PetscCall(PetscPrintf(scene->comm, "  (grows as exp(%.6g t))", (double)grow));
        PetscCall(PetscPrintf(scene->comm, "\n"));
      } else if (!mech && i - s.nmech < o.nev) {
        if (grow > 0) PetscCall(PetscPrintf(scene->comm, "  %-14s", "unstable"));
        else if (over) PetscCall(PetscPrintf(scene->comm, "  %-14s", "overdamped"));
        else PetscCall(PetscPrintf(scene->comm, "  %-14.8g", (double)f));
      }
      PetscCall(PetscViewerASCIIPrintf(csv, "%" PetscInt_FMT ",%.12g,%" PetscInt_FMT ",%s,%.12e,%.12e,%.3e,%.12e,%.12e,%.12e,%.12e\n", c, (double)pos, i + 1, kind, (double)f, (double)omega, (double)s.resid[i], (double)grow, (double)zeta, (double)fd, (double)decay));
      if (!mech && i - s.nmech < o.nev) PetscCall(PetscViewerASCIIPrintf(sweep, ",%.12e", (double)omega));
      if (!mech) worst = PetscMax(worst, s.resid[i]);
      if (c == 0 && o.nexp && !mech && !over) { /* the oscillating modes (an overdamped motion has no frequency) */
        if (!fexp) PetscCall(PetscMalloc1(s.n, &fexp));
        fexp[nfexp++] = f;
      }
      if (c == 0 && o.nzexp && !mech && !over) {
        if (!zexp) PetscCall(PetscMalloc1(s.n, &zexp));
        zexp[nzexp++] = zeta;
      }
    }
    if (nconfig > 1) PetscCall(PetscPrintf(scene->comm, "\n"));
    PetscCall(PetscViewerASCIIPrintf(sweep, "\n"));
    if (shapes && p.sys->nfparts) PetscCall(WriteShapes(&p, scene->output, &s)); /* (the shapes drawn are the fields') */
    PetscCall(SpectrumDestroy(&s));
    PetscCall(PhlexInterruptCheck(scene->comm, "linearized analysis"));
  }
  PetscCall(PetscPrintf(scene->comm, "  time: %.3g s building the pencils (%s), %.3g s in the eigensolver (%.3g s per configuration)\n", tbuild, o.nspins ? "the steady state and K per spin rate, M once" : "K and M once, the constraint rows per configuration", tsolve, tsolve / nconfig));
  PetscCall(PetscLogStagePop());
  PetscCall(PetscViewerDestroy(&csv));
  PetscCall(PetscViewerDestroy(&sweep));
  PetscCall(PhlexOutputCommit(scene->output));
  if (o.rmax > 0) PetscCall(PhlexExpectMax(scene->comm, "eigenpair residuals (max relative)", "-expect_residual_max", worst, o.rmax, PETSC_TRUE));
  if (o.nexp) PetscCall(PhlexExpectValues(scene->comm, p.damped ? "undamped natural frequencies" : "elastic frequencies", "-expect_frequencies", nfexp, fexp, o.nexp, o.expected, o.rtol));
  if (o.nzexp) {
    PetscCall(PhlexExpectValues(scene->comm, "damping ratios", "-expect_damping_ratios", nzexp, zexp, o.nzexp, o.zexpected, o.zrtol));
  }
  PetscCall(PetscFree(fexp));
  PetscCall(PetscFree(zexp));
  PetscCall(EPSDestroy(&eps));
  PetscCall(PEPDestroy(&pep));
  PetscCall(MatDestroy(&p.A));
  PetscCall(MatDestroy(&p.B));
  PetscCall(MatDestroy(&p.A1));
  PetscCall(MatDestroy(&p.Gyr));
  PetscCall(MatDestroy(&p.Rf));
  for (PetscInt k = 0; p.elrows && k < 2 * p.nel; k++) PetscCall(VecDestroy(&p.elrows[k]));
  PetscCall(PetscFree(p.elrows));
  PetscCall(PetscFree3(p.elF, p.elE, p.qdamped));
  PetscCall(MatDestroy(&p.K));
  PetscCall(MatDestroy(&p.Mvv));
  PetscCall(ISDestroy(&p.isV));
  PetscCall(ISDestroy(&p.isQ));
  PetscCall(PetscFree3(p.qmap, p.Qq, p.Ee));
  PetscCall(VecDestroy(&p.X));
  PetscCall(VecDestroy(&p.Xdot));
  PetscCall(PhlexSystemDestroy(&p.sys));
  PetscFunctionReturn(0);
}
