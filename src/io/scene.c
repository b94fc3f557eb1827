/* The scene: its parts (bodies), joints, the analysis, the reference scales, gravity and the output directory. */
#include <phlex_impl.h>

const char *const PhlexAnalysisTypes[]     = {"transient", "modes", "linearized", "reduce", "PhlexAnalysisType", "PHLEX_ANALYSIS_", NULL};
const char *const PhlexRedundantPolicies[] = {"error", "drop", "keep", "PhlexRedundantPolicy", "PHLEX_REDUNDANT_", NULL};

/*@C
  PhlexSceneCreate - creates an empty scene

  Collective
@*/
PetscErrorCode PhlexSceneCreate(MPI_Comm comm, PhlexScene *scene)
{
  PhlexScene s;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&s));
  s->comm            = comm;
  s->analysis        = PHLEX_ANALYSIS_TRANSIENT;
  s->nparts          = 1;
  s->assembly_tol    = 1e-10;
  s->assembly_max_it = 50;
  PetscCall(PhlexOutputCreate(comm, &s->output));
  PetscCall(PhlexPartCreateGround(comm, &s->ground));
  *scene = s;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneFindPart - the part of a given name (NULL if none; "ground" is the ground)
@*/
PetscErrorCode PhlexSceneFindPart(PhlexScene s, const char name[], PhlexPart *part)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexPartFind(s->nparts, s->parts, s->ground, name, part));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSetFromOptions - reads the scene options, its bodies and joints

  Collective

  Options Database Keys:
+ -analysis <transient,modes>       - analysis to run
. -num_bodies <n>                   - number of bodies (options body0_, body1_, ...)
. -num_joints <n>                   - number of joints (options joint0_, joint1_, ...)
. -scale_length <m>                 - reference length of the non-dimensionalisation (default: the largest extent of all bodies)
. -scale_density <kg/m^3>           - reference density (default: the largest density of the flexible bodies)
. -scale_modulus <Pa>               - reference modulus (default: the largest Young's modulus)
. -gravity gx,gy,gz                 - gravitational acceleration (inertial frame) [m/s^2]
. -whole_bodies                     - each flexible body whole on one process (its solves sequential, concurrent with the others')
. -joints_redundant <error,drop,keep> - redundant constraint components found at set-up: an error, dropped, or kept
. -assembly_tol <r>                 - tolerance of the position-level closure of the loops (relative to the reference length)
- -joints_project_interval <n>      - project the positions back onto the joints every n steps (0: never)
@*/
PetscErrorCode PhlexSceneSetFromOptions(PhlexScene s)
{
  PetscBool flg;
  PetscInt  policy = s->redundant;

  PetscFunctionBeginUser;
  PetscOptionsBegin(s->comm, NULL, "phlex scene options", NULL);
  PetscCall(PetscOptionsEnum("-analysis", "Analysis to run: transient, modes (each flexible body alone), linearized (the whole assembly about rest), reduce (build the reduced bodies' files and stop)", "PhlexSceneSetFromOptions", PhlexAnalysisTypes, (PetscEnum)s->analysis, (PetscEnum *)&s->analysis, NULL));
  PetscCall(PetscOptionsInt("-num_bodies", "Number of bodies (options prefixed body0_, body1_, ...)", "PhlexSceneSetFromOptions", s->nparts, &s->nparts, NULL));
  PetscCall(PetscOptionsInt("-num_joints", "Number of joints (options prefixed joint0_, joint1_, ...)", "PhlexSceneSetFromOptions", s->njoints, &s->njoints, NULL));
  PetscCall(PetscOptionsReal("-scale_length", "Reference length of the non-dimensionalisation [m] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_length, &s->scale_length, NULL));
  PetscCall(PetscOptionsReal("-scale_density", "Reference density [kg/m^3] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_density, &s->scale_density, NULL));
  PetscCall(PetscOptionsReal("-scale_modulus", "Reference modulus [Pa] (0: automatic)", "PhlexSceneSetFromOptions", s->scale_modulus, &s->scale_modulus, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, s->comm, "scene", "", "-gravity", "Gravitational acceleration (inertial frame) acting on every body [m/s^2]", "PhlexSceneSetFromOptions", 3, s->gravity, NULL));
  PetscCall(PetscOptionsEList("-joints_redundant", "Redundant constraint components (for the rigid motion) found at set-up: error, drop them, or keep them (a flexible body on each such joint takes up the over-constraint)", "PhlexSceneSetFromOptions", PhlexRedundantPolicies, 3, PhlexRedundantPolicies[policy], &policy, NULL));
  PetscCall(PetscOptionsReal("-assembly_tol", "Position-level closure of the joints before the first step, relative to the reference length", "PhlexSceneSetFromOptions", s->assembly_tol, &s->assembly_tol, NULL));
  PetscCall(PetscOptionsInt("-assembly_max_it", "Newton iterations of the position-level closure", "PhlexSceneSetFromOptions", s->assembly_max_it, &s->assembly_max_it, NULL));
  PetscCall(PetscOptionsBool("-whole_bodies", "Each flexible body whole on one process, the next body on the process with the fewest cells so far (-<body>_process places one body): a mechanism's bodies factor and solve concurrently, each with a sequential solver (PC phlexbordered); default: every body split over all processes", "PhlexSceneSetFromOptions", s->whole_bodies, &s->whole_bodies, NULL));
  PetscCall(PetscOptionsInt("-joints_project_interval", "Project the positions back onto the joints every n steps (0: never); the energy change is reported", "PhlexSceneSetFromOptions", s->project_interval, &s->project_interval, NULL));
  PetscOptionsEnd();
  s->redundant = (PhlexRedundantPolicy)policy;
  PetscCheck(s->nparts >= 1, s->comm, PETSC_ERR_USER_INPUT, "-num_bodies must be >= 1, got %" PetscInt_FMT, s->nparts);
  PetscCheck(s->njoints >= 0, s->comm, PETSC_ERR_USER_INPUT, "-num_joints must be >= 0, got %" PetscInt_FMT, s->njoints);
  PetscCheck(s->scale_length >= 0 && s->scale_density >= 0 && s->scale_modulus >= 0, s->comm, PETSC_ERR_USER_INPUT, "-scale_length, -scale_density and -scale_modulus must be positive (or 0 for automatic)");
  PetscCheck(s->assembly_tol > 0, s->comm, PETSC_ERR_USER_INPUT, "-assembly_tol must be positive, got %g", (double)s->assembly_tol);
  PetscCheck(s->assembly_max_it > 0, s->comm, PETSC_ERR_USER_INPUT, "-assembly_max_it must be positive, got %" PetscInt_FMT, s->assembly_max_it);
  PetscCheck(s->project_interval >= 0, s->comm, PETSC_ERR_USER_INPUT, "-joints_project_interval must be 0 (never) or positive, got %" PetscInt_FMT, s->project_interval);
  PetscCall(PetscCalloc1(s->nparts, &s->parts));
  for (PetscInt k = 0; k < s->nparts; k++) {
    PetscCall(PhlexPartCreate(s->comm, k, &s->parts[k]));
    PetscCall(PhlexPartSetFromOptions(s->parts[k]));
    for (PetscInt j = 0; j < k; j++) {
      PetscCall(PetscStrcmp(s->parts[j]->name, s->parts[k]->name, &flg));
      PetscCheck(!flg, s->comm, PETSC_ERR_USER_INPUT, "bodies %" PetscInt_FMT " and %" PetscInt_FMT " have the same name '%s' (option -%sname)", j, k, s->parts[k]->name, s->parts[k]->prefix);
    }
  }
  {
    /* the joints of the scene, then those the parts ask for (a lumped mass attached to a port) */
    PetscInt nauto = 0, n;
    for (PetscInt k = 0; k < s->nparts; k++)
      if (s->parts[k]->attach[0]) nauto++;
    n = s->njoints;
    PetscCall(PetscCalloc1(PetscMax(n + nauto, 1), &s->joints));
    for (PetscInt k = 0; k < n; k++) {
      PetscCall(PhlexJointCreate(s->comm, &s->units, k, &s->joints[k]));
      PetscCall(PhlexJointSetFromOptions(s->joints[k]));
    }
    for (PetscInt k = 0; k < s->nparts; k++) {
      PhlexJoint j;
      if (!s->parts[k]->attach[0]) continue;
      PetscCall(PhlexJointCreate(s->comm, &s->units, s->njoints, &j));
      PetscCall(PetscSNPrintf(j->name, sizeof(j->name), "%s_attach", s->parts[k]->name));
      PetscCall(PetscSNPrintf(j->ports_option, sizeof(j->ports_option), "-%sattach", s->parts[k]->prefix));
      j->type = PHLEX_JOINT_SPHERICAL;
      PetscCall(PetscStrncpy(j->side[0].spec, s->parts[k]->attach, sizeof(j->side[0].spec)));
      PetscCall(PetscSNPrintf(j->side[1].spec, sizeof(j->side[1].spec), "%s:point", s->parts[k]->name));
      s->joints[s->njoints++] = j;
    }
    for (PetscInt k = 0; k < s->njoints; k++)
      for (PetscInt j = 0; j < k; j++) {
        PetscCall(PetscStrcmp(s->joints[j]->name, s->joints[k]->name, &flg));
        PetscCheck(!flg, s->comm, PETSC_ERR_USER_INPUT, "joints %s and %s have the same name '%s' (option -%sname)", s->joints[j]->prefix, s->joints[k]->prefix, s->joints[k]->name, s->joints[k]->prefix);
      }
    for (PetscInt k = 0; k < s->njoints; k++) {
      PhlexPart p;
      PetscCall(PhlexSceneFindPart(s, s->joints[k]->name, &p));
      PetscCheck(!p, s->comm, PETSC_ERR_USER_INPUT, "joint %s has the name of a body (option -%sname): names must be unique (they name the output files)", s->joints[k]->name, s->joints[k]->prefix);
    }
  }
  PetscCall(PhlexOutputSetFromOptions(s->output));
  PetscCall(PhlexProgressSetFromOptions(s->comm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneReadOptions - reads every scene option (bodies, joints, output) into a scene that is then thrown away:
  with PETSc's help printing on, this lists the scene's valid options (PhlexOptionsCheckUnused)

  Collective
@*/
PetscErrorCode PhlexSceneReadOptions(MPI_Comm comm)
{
  PhlexScene scene;

  PetscFunctionBeginUser;
  PetscCall(PhlexSceneCreate(comm, &scene));
  PetscCall(PhlexSceneSetFromOptions(scene));
  PetscCall(PhlexSceneDestroy(&scene));
  PetscFunctionReturn(0);
}

/* Scales for the whole scene unless overridden: L = the largest extent of all bodies, rho_ref and E_ref the largest
   material values of the flexible bodies. A scene without a flexible body: L from its bodies (or 1 m), the mass
   scale its largest mass, and the time scale 1 s. */
static PetscErrorCode SceneSetUnits(PhlexScene s, const PhlexScaleHints *h, PetscInt n)
{
  PhlexUnits *u = &s->units;
  PetscReal   mass = 0;

  PetscFunctionBeginUser;
  u->length = u->density = u->modulus = 0;
  for (PetscInt k = 0; k < n; k++) {
    u->length  = PetscMax(u->length, h[k].extent);
    u->density = PetscMax(u->density, h[k].density);
    u->modulus = PetscMax(u->modulus, h[k].modulus);
    mass       = PetscMax(mass, h[k].mass);
  }
  if (s->scale_length > 0) u->length = s->scale_length;
  if (u->length <= 0) u->length = 1.0;
  if (u->modulus <= 0 && s->scale_modulus <= 0) {
    if (mass <= 0) mass = 1.0;
    if (u->density <= 0) u->density = mass / (u->length * u->length * u->length);
    u->modulus = u->density * u->length * u->length; /* T = 1 s */
  }
  if (u->density <= 0) u->density = u->modulus; /* unreachable: a modulus comes with a density */
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
  PhlexSceneSetUp - loads and checks every mesh, fixes the scales of the whole scene, sets up the bodies and finds
  the joints' ports

  Collective
@*/
PetscErrorCode PhlexSceneSetUp(PhlexScene s)
{
  PhlexScaleHints *h;

  PetscFunctionBeginUser;
  if (s->setup) PetscFunctionReturn(0);
  PetscCall(PetscCalloc1(s->nparts, &h));
  {
    /* -whole_bodies: the meshes are read in turn, each body to the process with the fewest cells so far */
    PetscInt64 *cells = NULL;
    PetscMPIInt size;
    PetscCallMPI(MPI_Comm_size(s->comm, &size));
    if (s->whole_bodies && size > 1) PetscCall(PetscCalloc1(size, &cells));
    for (PetscInt k = 0; k < s->nparts; k++) s->parts[k]->process_cells = cells;
    for (PetscInt k = 0; k < s->nparts; k++) PetscCall((*s->parts[k]->ops.geometry)(s->parts[k], &h[k]));
    for (PetscInt k = 0; k < s->nparts; k++) s->parts[k]->process_cells = NULL;
    PetscCall(PetscFree(cells));
  }
  PetscCall(SceneSetUnits(s, h, s->nparts));
  PetscCall(PetscFree(h));
  for (PetscInt k = 0; k < s->nparts; k++) {
    PhlexPart p = s->parts[k];
    p->units    = &s->units;
    for (PetscInt d = 0; d < 3; d++) p->gravity[d] = s->gravity[d] * s->units.time * s->units.time / s->units.length;
    PetscCall((*p->ops.setup)(p));
  }
  s->ground->units = &s->units;
  for (PetscInt k = 0; k < s->njoints; k++) PetscCall(PhlexJointResolve(s->joints[k], s->nparts, s->parts, s->ground));
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
  PhlexSceneView - prints the scene: analysis, gravity, bodies, joints
@*/
PetscErrorCode PhlexSceneView(PhlexScene s, PetscViewer viewer)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerASCIIPrintf(viewer, "phlex scene: %s analysis, %" PetscInt_FMT " bod%s", PhlexAnalysisTypes[s->analysis], s->nparts, s->nparts == 1 ? "y" : "ies"));
  if (s->njoints) PetscCall(PetscViewerASCIIPrintf(viewer, ", %" PetscInt_FMT " joint%s", s->njoints, s->njoints == 1 ? "" : "s"));
  PetscCall(PetscViewerASCIIPrintf(viewer, "\n"));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(PhlexBLASView(viewer));
  if (s->gravity[0] != 0 || s->gravity[1] != 0 || s->gravity[2] != 0) PetscCall(PetscViewerASCIIPrintf(viewer, "gravity (%.15g, %.15g, %.15g) m/s^2 (inertial frame)\n", (double)s->gravity[0], (double)s->gravity[1], (double)s->gravity[2]));
  for (PetscInt k = 0; k < s->nparts; k++) PetscCall(PhlexPartView(s->parts[k], viewer));
  for (PetscInt k = 0; k < s->njoints; k++) PetscCall(PhlexJointView(s->joints[k], viewer));
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneDestroy - destroys the scene, its bodies and joints
@*/
PetscErrorCode PhlexSceneDestroy(PhlexScene *scene)
{
  PhlexScene s = *scene;

  PetscFunctionBeginUser;
  if (!s) PetscFunctionReturn(0);
  if (s->parts)
    for (PetscInt k = 0; k < s->nparts; k++) PetscCall(PhlexPartDestroy(&s->parts[k]));
  PetscCall(PetscFree(s->parts));
  if (s->joints)
    for (PetscInt k = 0; k < s->njoints; k++) PetscCall(PhlexJointDestroy(&s->joints[k]));
  PetscCall(PetscFree(s->joints));
  PetscCall(PhlexPartDestroy(&s->ground));
  PetscCall(PhlexOutputDestroy(&s->output));
  PetscCall(PetscFree(*scene));
  PetscFunctionReturn(0);
}
