/* -analysis reduce: the offline step of model reduction on its own. The scene's set-up has built every reduced body's
   model (its basis from the full body's mesh, material and ports, SLEPc) and written its file, or read the file and
   checked its provenance; this analysis reports the files and runs nothing else, so that a sweep of runs reads them. */
#include <phlex_impl.h>

/*@C
  PhlexSceneReduce - reports the reduced body files of a scene (built, or found up to date, at set-up)

  Collective

  Notes:
  A scene without a reduced body, or a reduced body without a file (-body<k>_reduced_file), is an input error: there
  would be nothing to keep.
@*/
PetscErrorCode PhlexSceneReduce(PhlexScene scene)
{
  PetscInt n = 0;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < scene->nparts; k++)
    if (PhlexPartAnalysisOp(scene->parts[k], reduce)) n++;
  PetscCheck(n, scene->comm, PETSC_ERR_USER_INPUT, "-analysis reduce: the scene has no reduced body (-body<k>_type reduced with -body<k>_reduced_file <file>)");
  PetscCall(PetscPrintf(scene->comm, "Reduced body files:\n"));
  for (PetscInt k = 0; k < scene->nparts; k++) {
    PhlexPart p = scene->parts[k];
    if (PhlexPartAnalysisOp(p, reduce)) PetscCall((*p->analysisops->reduce)(p, PETSC_VIEWER_STDOUT_(scene->comm)));
  }
  PetscFunctionReturn(0);
}
