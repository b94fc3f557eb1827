/* phlex: flexible multibody dynamics of 3D elastic bodies in port-Hamiltonian form.
   Scene create -> set from options -> set up -> analysis -> destroy; -help reads the options and stops; the exit
   code says what went wrong (phlex.h, README "Exit codes"). */
#include <phlex_impl.h>

static const char help[] = "phlex: flexible multibody dynamics of 3D elastic bodies in port-Hamiltonian form (PETSc/SLEPc).\n";

/* without a scene, -help shows one body of each type and one driven joint, with example values for the options that
   have no default (options already given are kept) */
static PetscErrorCode SetHelpCatalogue(PetscBool *catalogue)
{
  const char *const defaults[][2] = {
    {"-num_bodies", "3"},
    {"-body0_name", "flexible_body"},
    {"-body0_youngs_modulus", "2.1e11"},
    {"-body0_poissons_ratio", "0.3"},
    {"-body0_density", "7800"},
    {"-body0_ports", "tip"},
    {"-body1_type", "rigid"},
    {"-body1_name", "rigid_body"},
    {"-body1_mass", "1"},
    {"-body1_inertia", "0.1,0.1,0.1"},
    {"-body1_ports", "hinge"},
    {"-body1_port_hinge_position", "0,0,0"},
    {"-body2_type", "lumped"},
    {"-body2_name", "point_mass"},
    {"-body2_mass", "1"},
    {"-body2_attach", "flexible_body:tip"},
    {"-num_joints", "1"},
    {"-joint0_name", "hinge"},
    {"-joint0_type", "revolute"},
    {"-joint0_ports", "rigid_body:hinge,ground"},
    {"-joint0_axis", "0,0,1"},
    {"-joint0_drive_velocity", "1"},
  };
  PetscBool scene = PETSC_FALSE, set;

  PetscFunctionBeginUser;
  for (const char *const *o = (const char *const[]){"-num_bodies", "-body0_type", "-body0_dm_plex_filename", "-analysis", NULL}; *o; o++) {
    PetscCall(PetscOptionsHasName(NULL, NULL, *o, &set));
    scene = (PetscBool)(scene || set);
  }
  *catalogue = (PetscBool)!scene;
  if (scene) PetscFunctionReturn(0);
  for (size_t i = 0; i < sizeof(defaults) / sizeof(defaults[0]); i++) {
    PetscCall(PetscOptionsHasName(NULL, NULL, defaults[i][0], &set));
    if (!set) PetscCall(PetscOptionsSetValue(NULL, defaults[i][0], defaults[i][1]));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode Run(PhlexScene *scene)
{
  PhlexAnalysisType   analysis;
  const PhlexHelpMode help_mode = PhlexHelpGetMode();
  PetscBool           catalogue = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PhlexLogStagePush("Phlex Setup", &PHLEX_StageSetup));
  if (help_mode == PHLEX_HELP_OPTIONS) PetscCall(SetHelpCatalogue(&catalogue));
  PetscCall(PhlexBLASSetFromOptions(PETSC_COMM_WORLD)); /* before the first BLAS call */
  PetscCall(PhlexSceneCreate(PETSC_COMM_WORLD, scene));
  PetscCall(PhlexSceneSetFromOptions(*scene));
  if (help_mode != PHLEX_HELP_OPTIONS) {
    PetscCall(PhlexSceneSetUp(*scene));
    PetscCall(PhlexSceneView(*scene, PETSC_VIEWER_STDOUT_WORLD));
  }
  PetscCall(PetscLogStagePop());
  PetscCall(PhlexSceneGetAnalysis(*scene, &analysis));
  /* -help: the options of the scene's analysis (it returns once it has read them); without a scene, of every analysis */
  if (catalogue || analysis == PHLEX_ANALYSIS_MODES) PetscCall(PhlexSceneSolveModes(*scene));
  if (catalogue || analysis == PHLEX_ANALYSIS_TRANSIENT) PetscCall(PhlexSceneSolveTransient(*scene));
  if (catalogue || analysis == PHLEX_ANALYSIS_LINEARIZED) PetscCall(PhlexSceneSolveLinearized(*scene));
  if (help_mode == PHLEX_HELP_NONE && analysis == PHLEX_ANALYSIS_REDUCE) PetscCall(PhlexSceneReduce(*scene));
  if (help_mode != PHLEX_HELP_NONE) PetscCall(PhlexHelpEnd(PETSC_COMM_WORLD, catalogue, PhlexAnalysisTypes[analysis]));
  else PetscCall(PhlexOptionsWarnUnused(PETSC_COMM_WORLD));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PhlexScene     scene = NULL;
  PetscErrorCode ierr;
  PetscMPIInt    size;
  int            code;

  if (argc == 1) {
    /* nothing to run: the usage, and the input-error code (a script that forgot its arguments must not pass) */
    fputs(PhlexUsage, stdout);
    return PHLEX_EXIT_INPUT;
  }
  (void)PhlexHelpParseArgs(&argc, argv);
  code = PhlexSceneFilesCheck(argc, argv);
  if (code) {
    PhlexOptionsOriginFree();
    return code;
  }
  PetscCall(SlepcInitialize(&argc, &argv, NULL, help));
  PetscCall(PhlexHelpActivate(PETSC_COMM_WORLD));
  PetscCall(PhlexErrorHandlerPush());
  PetscCall(PhlexInterruptPush());
  PetscCall(PhlexLogRegister());
  PetscCall(PhlexPCRegister());
  PetscCall(PhlexSNESRegister());
  PetscCall(PhlexSNESReducedRegister());
  PetscCall(PhlexEPSRegister());
  PetscCall(PhlexPartitionerRegister());
  PetscCall(PhlexPartRegisterAll());
  ierr = Run(&scene);
  if (ierr) {
    /* no half-written result: remove the run's temporary files (and its directory if the run made it and it is
       empty); the error was printed by the handler */
    code = PhlexExitCode();
    /* a numerical failure keeps the series so far, to show how it grew (in <dir>/failed/, apart from results) */
    if (scene && code == PHLEX_EXIT_NUMERICAL) (void)PhlexOutputKeepFailed(scene->output);
    if (scene) (void)PhlexOutputAbort(scene->output);
    /* the options a failed run did not reach are not misspelt: no -options_left report */
    (void)PetscOptionsSetValue(NULL, "-options_left", "0");
    code = PhlexExitCode();
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    if (size > 1 && code == PHLEX_EXIT_NUMERICAL) {
      /* a numerical failure is every rank's: let rank 0 finish moving the series to failed/ before the abort (a
         non-blocking barrier, given up after 10 s in case some rank is elsewhere) */
      MPI_Request req;
      int         done = 0;
      double      t0   = MPI_Wtime();
      if (MPI_Ibarrier(PETSC_COMM_WORLD, &req) == MPI_SUCCESS)
        while (!done && MPI_Wtime() - t0 < 10.0) (void)MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    }
    /* an error on some ranks only would leave the others waiting: every rank ends with the same code */
    if (size > 1) MPI_Abort(PETSC_COMM_WORLD, code);
    (void)PhlexSceneDestroy(&scene);
    (void)SlepcFinalize();
    PhlexOptionsOriginFree();
    return code;
  }
  PetscCall(PhlexSceneDestroy(&scene));
  PetscCall(PhlexErrorHandlerPop());
  PetscCall(SlepcFinalize());
  PhlexOptionsOriginFree();
  return 0;
}
