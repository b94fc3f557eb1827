/* The scene: bodies, analysis choice, reference scales, output directory. */
#include <phlex_impl.h>

const char *const PhlexAnalysisTypes[] = {"transient", "modes", "PhlexAnalysisType", "PHLEX_ANALYSIS_", NULL};

/*@C
  PhlexSceneCreate - creates an empty scene

  Collective
@*/
PetscErrorCode PhlexSceneCreate(MPI_Comm comm, PhlexScene *scene)
{
  PhlexScene s;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&s));
  s->comm     = comm;
  s->analysis = PHLEX_ANALYSIS_TRANSIENT;
  s->nbodies  = 1;
  PetscCall(PhlexOutputCreate(comm, &s->output));
  *scene = s;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSetFromOptions - reads the scene options and those of its bodies

  Collective

  Options Database Keys:
+ -analysis <transient,modes> - analysis to run
. -num_bodies <n>             - number of bodies (options body0_, body1_, ...)
. -scale_length <m>           - reference length of the non-dimensionalisation (default: largest extent of body0)
. -scale_density <kg/m^3>     - reference density (default: largest density of body0)
- -scale_modulus <Pa>         - reference modulus (default: largest Young's modulus of body0)
@*/
PetscErrorCode PhlexSceneSetFromOptions(PhlexScene s)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(s->comm, NULL, "phlex scene options", NULL);
  PetscCall(PetscOptionsEnum("-analysis", "Analysis to run", "PhlexSceneSetFromOptions", PhlexAnalysisTypes, (PetscEnum)s->analysis, (PetscEnum *)&s->analysis, NULL));
  PetscCall(PetscOptionsInt("-num_bodies", "Number of bodies (options prefixed body0_, body1_, ...)", "PhlexSceneSetFromOptions", s->nbodies, &s->nbodies, NULL));
  PetscCall(PetscOptionsReal("-scale_length", "Reference length of the non-dimensionalisation [m] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_length, &s->scale_length, NULL));
  PetscCall(PetscOptionsReal("-scale_density", "Reference density [kg/m^3] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_density, &s->scale_density, NULL));
  PetscCall(PetscOptionsReal("-scale_modulus", "Reference modulus [Pa] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_modulus, &s->scale_modulus, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, s->comm, "scene", "", "-gravity", "Gravitational acceleration (inertial frame) acting on floating bodies [m/s^2]", "PhlexSceneSetFromOptions", 3, s->gravity, NULL));
  PetscOptionsEnd();
  PetscCheck(s->nbodies == 1, s->comm, PETSC_ERR_SUP, "-num_bodies %" PetscInt_FMT ": this version simulates one body per scene", s->nbodies);
  PetscCheck(s->scale_length >= 0 && s->scale_density >= 0 && s->scale_modulus >= 0, s->comm, PETSC_ERR_USER_INPUT, "-scale_length, -scale_density and -scale_modulus must be positive (or 0 for automatic)");
  PetscCall(PetscMalloc1(s->nbodies, &s->bodies));
  for (PetscInt k = 0; k < s->nbodies; k++) {
    PetscCall(PhlexBodyCreate(s->comm, k, &s->bodies[k]));
    PetscCall(PhlexBodySetFromOptions(s->bodies[k]));
  }
  PetscCall(PhlexOutputSetFromOptions(s->output));
  PetscFunctionReturn(0);
}

/* Scales from body0 unless overridden: L = largest bounding-box extent, rho_ref and E_ref the largest material values. */
static PetscErrorCode SceneSetUnits(PhlexScene s)
{
  PhlexBody   b = s->bodies[0];
  PhlexUnits *u = &s->units;

  PetscFunctionBeginUser;
  u->length  = 0;
  u->density = 0;
  u->modulus = 0;
  for (PetscInt d = 0; d < 3; d++) u->length = PetscMax(u->length, b->bbox_max[d] - b->bbox_min[d]);
  for (PetscInt m = 0; m < b->nmaterials; m++) {
    u->density = PetscMax(u->density, b->materials[m].density);
    u->modulus = PetscMax(u->modulus, b->materials[m].youngs_modulus);
  }
  if (s->scale_length > 0) u->length = s->scale_length;
  if (s->scale_density > 0) u->density = s->scale_density;
  if (s->scale_modulus > 0) u->modulus = s->scale_modulus;
  u->time     = u->length * PetscSqrtReal(u->density / u->modulus);
  u->velocity = u->length / u->time;
  u->mass     = u->density * u->length * u->length * u->length;
  u->force    = u->modulus * u->length * u->length;
  u->energy   = u->force * u->length;
  u->power    = u->energy / u->time;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSetUp - loads and checks every mesh, fixes the scales, assembles the bodies' operators

  Collective
@*/
PetscErrorCode PhlexSceneSetUp(PhlexScene s)
{
  PetscFunctionBeginUser;
  if (s->setup) PetscFunctionReturn(0);
  for (PetscInt k = 0; k < s->nbodies; k++) {
    PetscCall(PhlexMeshLoad(s->bodies[k]));
    PetscCall(PhlexMeshCheckGeometry(s->bodies[k], NULL));
  }
  PetscCall(SceneSetUnits(s));
  for (PetscInt k = 0; k < s->nbodies; k++) {
    PhlexBody b = s->bodies[k];
    for (PetscInt d = 0; d < 3; d++) b->gravity[d] = s->gravity[d] * s->units.time * s->units.time / s->units.length;
    PetscCheck(b->floating || (s->gravity[0] == 0 && s->gravity[1] == 0 && s->gravity[2] == 0), s->comm, PETSC_ERR_USER_INPUT, "-gravity acts on floating bodies; body %s is fixed (use -%sbody_force for its weight)", b->name, b->prefix);
    PetscCall(PhlexBodySetUp(b, &s->units));
  }
  s->setup = PETSC_TRUE;
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexSceneGetAnalysis(PhlexScene s, PhlexAnalysisType *a)
{
  PetscFunctionBeginUser;
  *a = s->analysis;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneView - prints the scene: analysis, scales, bodies
@*/
PetscErrorCode PhlexSceneView(PhlexScene s, PetscViewer viewer)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerASCIIPrintf(viewer, "phlex scene: %s analysis, %" PetscInt_FMT " body\n", PhlexAnalysisTypes[s->analysis], s->nbodies));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  if (s->gravity[0] != 0 || s->gravity[1] != 0 || s->gravity[2] != 0) PetscCall(PetscViewerASCIIPrintf(viewer, "gravity (%g, %g, %g) m/s^2 (inertial frame)\n", (double)s->gravity[0], (double)s->gravity[1], (double)s->gravity[2]));
  for (PetscInt k = 0; k < s->nbodies; k++) PetscCall(PhlexBodyView(s->bodies[k], viewer));
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneDestroy - destroys the scene and its bodies
@*/
PetscErrorCode PhlexSceneDestroy(PhlexScene *scene)
{
  PhlexScene s = *scene;

  PetscFunctionBeginUser;
  if (!s) PetscFunctionReturn(0);
  for (PetscInt k = 0; k < s->nbodies; k++)
    if (s->bodies) PetscCall(PhlexBodyDestroy(&s->bodies[k]));
  PetscCall(PetscFree(s->bodies));
  PetscCall(PhlexOutputDestroy(&s->output));
  PetscCall(PetscFree(*scene));
  PetscFunctionReturn(0);
}
