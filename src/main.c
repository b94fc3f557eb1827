/* phlex: flexible multibody dynamics of 3D elastic bodies in port-Hamiltonian form.
   Scene create -> set from options -> set up -> analysis -> destroy. */
#include <phlex_impl.h>

static const char help[] = "phlex: flexible multibody dynamics of 3D elastic bodies in port-Hamiltonian form (PETSc/SLEPc).\n"
                           "  bin/phlex -options_file options/<scene>.yaml [-solver_options_file options/solver/<preset>.opts] [options]\n"
                           "  -help lists every option with its unit; README.md has the option tables.\n";

static PetscErrorCode Run(PhlexScene *scene)
{
  PhlexAnalysisType analysis;

  PetscFunctionBeginUser;
  PetscCall(PetscLogStagePush(PHLEX_StageSetup));
  PetscCall(PhlexSceneCreate(PETSC_COMM_WORLD, scene));
  PetscCall(PhlexSceneSetFromOptions(*scene));
  PetscCall(PhlexSceneSetUp(*scene));
  PetscCall(PhlexSceneView(*scene, PETSC_VIEWER_STDOUT_WORLD));
  PetscCall(PetscLogStagePop());
  PetscCall(PhlexSceneGetAnalysis(*scene, &analysis));
  switch (analysis) {
  case PHLEX_ANALYSIS_MODES:
    PetscCall(PhlexSceneSolveModes(*scene));
    break;
  case PHLEX_ANALYSIS_TRANSIENT:
    PetscCall(PhlexSceneSolveTransient(*scene));
    break;
  }
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PhlexScene     scene = NULL;
  PetscErrorCode ierr;
  PetscMPIInt    size;

  PetscCall(SlepcInitialize(&argc, &argv, NULL, help));
  PetscCall(PhlexErrorHandlerPush());
  PetscCall(PhlexLogRegister());
  PetscCall(PhlexPCRegister());
  PetscCall(PhlexPartRegisterAll());
  ierr = Run(&scene);
  if (ierr) {
    /* no half-written result: remove the run's temporary files; an input error was printed by the handler */
    if (scene) (void)PhlexOutputAbort(scene->output);
    /* the options a failed run did not reach are not misspelt: no -options_left report */
    (void)PetscOptionsSetValue(NULL, "-options_left", "0");
    MPI_Comm_size(PETSC_COMM_WORLD, &size);
    if (size > 1) MPI_Abort(PETSC_COMM_WORLD, (int)ierr);
    (void)PhlexSceneDestroy(&scene);
    (void)SlepcFinalize();
    return (int)ierr;
  }
  PetscCall(PhlexSceneDestroy(&scene));
  PetscCall(SlepcFinalize());
  return 0;
}
