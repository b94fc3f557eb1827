/* Checkpoint and restart of a transient run.

   A checkpoint (HDF5, written atomically by checkpoint.c) holds everything the run needs to go on as if it had not
   stopped: the global state X (every part's fields and discrete unknowns: rigid frames, lumped states, the joints'
   impulses), the time, the step number and the next step size, the multipliers of the last step, the energy
   monitor's accumulators (H0, the supplied work, the largest drifts ...), and where the outputs stand: the length of
   every CSV series and the field snapshots written (output.c, fields.c). A restarted run continues the series (they
   are cut at the checkpoint, never duplicated) and the field index.

   The default scheme, the implicit midpoint rule (and every theta method, Crank-Nicolson included), is a one-step
   method: the state is its whole history, and a restarted run takes the very same steps as an uninterrupted one.
   BDF and generalized-alpha keep a history of past steps inside PETSc's TS, which PETSc 3.18 gives no access to: a
   restart starts them again (BDF at first order, alpha with its start-up step), which is said at restart; the
   difference is of the order of the scheme's local error. An adaptive step's first error estimate after a restart
   likewise lacks the previous step. */
#include <phlex_impl.h>
#include <string.h> /* strchr */
#include <private/transient.h>
#include <petscviewerhdf5.h>

#define CHECKPOINT_NMONITOR 31 /* the accumulators of PackMonitor */

/* the energy monitor's accumulators, in a fixed order; returns how many */
static PetscInt PackMonitor(const MonitorContext *m, PetscReal a[CHECKPOINT_NMONITOR])
{
  PetscInt k = 0;
  a[k++] = m->H0, a[k++] = m->Hprev, a[k++] = m->tprev, a[k++] = m->work_total, a[k++] = m->max_drift;
  a[k++] = m->max_residual, a[k++] = m->max_work, a[k++] = m->Hmax, a[k++] = m->Emax;
  for (PetscInt c = 0; c < 3; c++) a[k++] = m->P0[c];
  for (PetscInt c = 0; c < 3; c++) a[k++] = m->L0[c];
  a[k++] = m->Pscale, a[k++] = m->Lscale, a[k++] = m->max_dP, a[k++] = m->max_dL, a[k++] = m->max_orth;
  a[k++] = m->max_defect, a[k++] = m->max_gap, a[k++] = m->project_dH, a[k++] = (PetscReal)m->nprojections;
  a[k++] = (PetscReal)m->last_written, a[k++] = (PetscReal)m->nretries, a[k++] = m->dissipated_total;
  a[k++] = m->max_drive, a[k++] = m->E0abs, a[k++] = m->V0, a[k++] = m->max_dV;
  return k;
}

static void UnpackMonitor(MonitorContext *m, const PetscReal a[CHECKPOINT_NMONITOR])
{
  PetscInt k = 0;
  m->H0 = a[k++], m->Hprev = a[k++], m->tprev = a[k++], m->work_total = a[k++], m->max_drift = a[k++];
  m->max_residual = a[k++], m->max_work = a[k++], m->Hmax = a[k++], m->Emax = a[k++];
  for (PetscInt c = 0; c < 3; c++) m->P0[c] = a[k++];
  for (PetscInt c = 0; c < 3; c++) m->L0[c] = a[k++];
  m->Pscale = a[k++], m->Lscale = a[k++], m->max_dP = a[k++], m->max_dL = a[k++], m->max_orth = a[k++];
  m->max_defect = a[k++], m->max_gap = a[k++], m->project_dH = a[k++], m->nprojections = (PetscInt)a[k++];
  m->last_written = (PetscInt)a[k++], m->nretries = (PetscInt)a[k++], m->dissipated_total = a[k++];
  m->max_drive = a[k++], m->E0abs = a[k++], m->V0 = a[k++], m->max_dV = a[k++];
}

/* removes the hashes after marker from a fingerprint: '@' and 16 hex digits, the placement hashes of
   PhlexFlexiblePlacement; '#' and hex digits, the model hashes of reduced bodies ("model#...", reduced.c) */
static void StripHashes(char *s, char marker)
{
  char *w = s;
  for (const char *r = s; *r;) {
    if (*r == marker) {
      r++;
      while ((*r >= '0' && *r <= '9') || (*r >= 'a' && *r <= 'f')) r++;
    } else *w++ = *r++;
  }
  *w = 0;
}

/* the first space-separated entry where two fingerprints differ, and its part's name (up to its first ':') */
static void FirstDifferentEntry(const char a[], const char b[], char name[], char ea[], char eb[], size_t len)
{
  const char *pa = a, *pb = b;
  name[0] = ea[0] = eb[0] = 0;
  while (*pa || *pb) {
    size_t la = strcspn(pa, " "), lb = strcspn(pb, " ");
    if (la != lb || strncmp(pa, pb, la)) {
      snprintf(ea, len, "%.*s", (int)la, pa);
      snprintf(eb, len, "%.*s", (int)lb, pb);
      snprintf(name, len, "%.*s", (int)strcspn(eb, ":"), eb);
      return;
    }
    pa += la + (pa[la] ? 1 : 0);
    pb += lb + (pb[lb] ? 1 : 0);
  }
}

/* what the state vector means: the parts and joints by name and kind, the sizes, the scales; a restart checks that
   its own run has the same */
static PetscErrorCode Fingerprint(MonitorContext *m, char **fingerprint, PetscReal units[4])
{
  PhlexSystem  sys = m->sys;
  const size_t len = (size_t)(sys->nparts + sys->njoints + 1) * (2 * PHLEX_NAME_LEN + 64);
  char        *parts;
  size_t       n;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(len, &parts));
  parts[0]     = 0;
  *fingerprint = parts;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PetscCall(PetscStrlen(parts, &n));
    PetscCall(PetscSNPrintf(parts + n, len - n, "%s%s:%s:%" PetscInt_FMT ":%" PetscInt_FMT "%s%s", i ? " " : "", sys->parts[i]->name, sys->parts[i]->type, sys->parts[i]->Nu + sys->parts[i]->Ns + sys->parts[i]->Nv, sys->parts[i]->nq, sys->parts[i]->numbering[0] ? ":" : "", sys->parts[i]->numbering));
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PetscCall(PetscStrlen(parts, &n));
    PetscCall(PetscSNPrintf(parts + n, len - n, " joint %s:%" PetscInt_FMT, sys->joints[k]->name, sys->joints[k]->nc));
    if (sys->joints[k]->ne) {
      PetscCall(PetscStrlen(parts, &n));
      PetscCall(PetscSNPrintf(parts + n, len - n, "+%" PetscInt_FMT " elements", sys->joints[k]->ne));
    }
  }
  units[0] = m->scene->units.length, units[1] = m->scene->units.density, units[2] = m->scene->units.modulus, units[3] = m->scene->units.mass;
  PetscFunctionReturn(0);
}

/* the time integrator and its parameters, as text: a restart needs the same */
static PetscErrorCode Scheme(TS ts, char scheme[], size_t len)
{
  TSType    type;
  PetscBool theta, bdf, alpha;

  PetscFunctionBeginUser;
  PetscCall(TSGetType(ts, &type));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &theta, TSTHETA, TSCN, TSBEULER, ""));
  PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSBDF, &bdf));
  PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSALPHA, &alpha));
  if (theta) {
    PetscReal th;
    PetscBool endpoint;
    PetscCall(TSThetaGetTheta(ts, &th));
    PetscCall(TSThetaGetEndpoint(ts, &endpoint));
    PetscCall(PetscSNPrintf(scheme, len, "-ts_type %s, theta %.17g%s", type, (double)th, endpoint ? ", endpoint" : ""));
  } else if (bdf) {
    PetscInt order;
    PetscCall(TSBDFGetOrder(ts, &order));
    PetscCall(PetscSNPrintf(scheme, len, "-ts_type %s, order %" PetscInt_FMT, type, order));
  } else if (alpha) {
    PetscReal am, af, g;
    PetscCall(TSAlphaGetParams(ts, &am, &af, &g));
    PetscCall(PetscSNPrintf(scheme, len, "-ts_type %s, alpha_m %.17g, alpha_f %.17g, gamma %.17g", type, (double)am, (double)af, (double)g));
  } else PetscCall(PetscSNPrintf(scheme, len, "-ts_type %s", type));
  PetscFunctionReturn(0);
}

/* X as a plain vector with the same layout (a DM's vector would be viewed by its DM) */
static PetscErrorCode PlainVec(Vec X, Vec *P)
{
  PetscInt n, N;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(X, &n));
  PetscCall(VecGetSize(X, &N));
  PetscCall(VecCreateMPI(PetscObjectComm((PetscObject)X), n, N, P));
  PetscCall(PetscObjectSetName((PetscObject)*P, "X"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientCheckpointOptions - reads the checkpoint and restart options

  Collective

  Options Database Keys:
+ -checkpoint_interval <n>        - write a checkpoint every n steps (0: off)
. -checkpoint_wall_interval <s>   - write a checkpoint every s seconds of wall-clock time (0: off)
. -checkpoint_file <file>         - the checkpoint (default <output_dir>/checkpoint.h5), overwritten atomically
- -restart <file>                 - continue the run a checkpoint was written by
@*/
PetscErrorCode PhlexTransientCheckpointOptions(MPI_Comm comm, PhlexOutput out, MonitorContext *m, char restart[], PetscBool *restarting)
{
  PetscFunctionBeginUser;
  m->ck_interval = 0;
  m->ck_wall     = 0;
  m->ck_step     = -1;
  PetscCall(PetscSNPrintf(m->ck_file, sizeof(m->ck_file), "%s/checkpoint.h5", out ? out->dir : "output"));
  restart[0] = 0;
  PetscOptionsBegin(comm, NULL, "Checkpoint and restart", NULL);
  PetscCall(PetscOptionsInt("-checkpoint_interval", "Write a checkpoint every n steps (0: off); SIGINT/SIGTERM then also write one before stopping", "PhlexSceneSolveTransient", m->ck_interval, &m->ck_interval, NULL));
  PetscCall(PetscOptionsReal("-checkpoint_wall_interval", "Write a checkpoint every s seconds of wall-clock time (0: off)", "PhlexSceneSolveTransient", m->ck_wall, &m->ck_wall, NULL));
  PetscCall(PetscOptionsString("-checkpoint_file", "The checkpoint, overwritten atomically each time (default <output_dir>/checkpoint.h5)", "PhlexSceneSolveTransient", m->ck_file, m->ck_file, sizeof(m->ck_file), NULL));
  PetscCall(PetscOptionsString("-restart", "Continue the run that wrote this checkpoint (same scene, same number of processes)", "PhlexSceneSolveTransient", restart, restart, PETSC_MAX_PATH_LEN, restarting));
  PetscOptionsEnd();
  PetscCheck(m->ck_interval >= 0, comm, PETSC_ERR_USER_INPUT, "-checkpoint_interval must be >= 0 steps (0: off), got %" PetscInt_FMT, m->ck_interval);
  PetscCheck(m->ck_wall >= 0 && !PetscIsInfOrNanReal(m->ck_wall), comm, PETSC_ERR_USER_INPUT, "-checkpoint_wall_interval must be a finite number of seconds >= 0 (0: off), got %g", (double)m->ck_wall);
  PetscCheck(m->ck_file[0], comm, PETSC_ERR_USER_INPUT, "-checkpoint_file must not be empty");
  PetscCheck(!*restarting || restart[0], comm, PETSC_ERR_USER_INPUT, "-restart needs the checkpoint file to continue from");
  if ((m->ck_interval > 0 || m->ck_wall > 0) && out) {
    /* a checkpoint elsewhere than the output directory (created when the run writes): its directory must exist */
    char        dir[PETSC_MAX_PATH_LEN];
    const char *slash = strrchr(m->ck_file, '/');
    PetscBool   same, ok;
    if (slash) PetscCall(PetscSNPrintf(dir, sizeof(dir), "%.*s", (int)(slash - m->ck_file), m->ck_file));
    else PetscCall(PetscStrcpy(dir, "."));
    PetscCall(PetscStrcmp(dir, out->dir, &same));
    if (!same) {
      PetscCall(PetscTestDirectory(dir, 'w', &ok));
      PetscCheck(ok, comm, PETSC_ERR_USER_INPUT, "-checkpoint_file '%s': the directory '%s' does not exist or is not writable", m->ck_file, dir);
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientCheckpointDue - whether a checkpoint is due after this step (the interval in steps or in wall time;
  the same answer on every rank)

  Collective
@*/
PetscErrorCode PhlexTransientCheckpointDue(MonitorContext *m, PetscInt step, PetscBool *due)
{
  PetscFunctionBeginUser;
  *due = PETSC_FALSE;
  if (step <= m->first_step) PetscFunctionReturn(0);
  if (m->ck_interval > 0 && step % m->ck_interval == 0) *due = PETSC_TRUE;
  if (m->ck_wall > 0) {
    PetscLogDouble now;
    PetscCall(PetscTime(&now));
    if (now - m->ck_last >= m->ck_wall) *due = PETSC_TRUE;
    /* the clocks of the ranks differ: rank 0 decides */
    PetscCallMPI(MPI_Bcast(due, 1, MPIU_BOOL, 0, m->scene->comm));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientCheckpointWrite - writes the checkpoint of the step just completed (after the monitor)

  Collective
@*/
PetscErrorCode PhlexTransientCheckpointWrite(TS ts, MonitorContext *m, Vec X)
{
  MPI_Comm    comm = m->scene->comm;
  PhlexSystem sys  = m->sys;
  PetscViewer v;
  Vec         P;
  PetscInt    step, n;
  PetscReal   t, dt, mon[CHECKPOINT_NMONITOR], units[4];
  PetscMPIInt size;
  char        tmp[PETSC_MAX_PATH_LEN], *parts, scheme[256];

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_Output, 0, 0, 0, 0));
  PetscCall(TSGetStepNumber(ts, &step));
  PetscCall(TSGetTime(ts, &t));
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(Fingerprint(m, &parts, units));
  PetscCall(Scheme(ts, scheme, sizeof(scheme)));
  PetscCall(PhlexCheckpointOpenWrite(comm, m->ck_file, tmp, &v));
  PetscCall(PhlexCheckpointWriteInt(v, "/", "phlex_checkpoint", 1));
  PetscCall(PhlexCheckpointWriteInt(v, "/run", "step", step));
  PetscCall(PhlexCheckpointWriteReals(v, "/run", "time", 1, &t));
  PetscCall(PhlexCheckpointWriteReals(v, "/run", "dt", 1, &dt));
  PetscCall(PhlexCheckpointWriteReals(v, "/run", "dt_nominal", 1, &m->dt_nominal));
  PetscCall(PhlexCheckpointWriteString(v, "/run", "scheme", scheme));
  PetscCall(PhlexCheckpointWriteReals(v, "/run", "units", 4, units));
  PetscCall(PhlexCheckpointWriteString(v, "/run", "parts", parts));
  PetscCall(PetscFree(parts));
  PetscCall(PhlexCheckpointWriteInt(v, "/run", "nranks", size));
  {
    /* the layout of X over the ranks: a restart needs the same */
    PetscReal *sizes;
    PetscInt   nloc;
    PetscCall(VecGetLocalSize(X, &nloc));
    PetscCall(PetscMalloc1(size, &sizes));
    {
      PetscReal mine = (PetscReal)nloc;
      PetscCallMPI(MPI_Allgather(&mine, 1, MPIU_REAL, sizes, 1, MPIU_REAL, comm));
    }
    PetscCall(PhlexCheckpointWriteReals(v, "/run", "local_sizes", size, sizes));
    PetscCall(PetscFree(sizes));
  }
  PetscCall(PlainVec(X, &P));
  PetscCall(VecCopy(X, P));
  PetscCall(PetscViewerHDF5PushGroup(v, "/state"));
  PetscCall(VecView(P, v));
  PetscCall(PetscViewerHDF5PopGroup(v));
  PetscCall(VecDestroy(&P));
  n = sys->nq;
  PetscCall(PhlexCheckpointWriteInt(v, "/state", "nq", n));
  PetscCall(PhlexCheckpointWriteReals(v, "/state", "q_previous", n, m->qprev));
  PetscCall(PhlexCheckpointWriteReals(v, "/state", "multipliers", n, m->lambda));
  PetscCheck(PackMonitor(m, mon) == CHECKPOINT_NMONITOR, comm, PETSC_ERR_PLIB, "the checkpoint's list of accumulators is out of date");
  PetscCall(PhlexCheckpointWriteReals(v, "/monitor", "accumulators", CHECKPOINT_NMONITOR, mon));
  if (sys->njoints) {
    /* the work each joint's force elements dissipated so far (its series continues it) */
    PetscReal *w;
    PetscCall(PetscMalloc1(sys->njoints, &w));
    for (PetscInt k = 0; k < sys->njoints; k++) w[k] = sys->joints[k]->dissipated_work;
    PetscCall(PhlexCheckpointWriteReals(v, "/monitor", "joint_dissipated_work", sys->njoints, w));
    for (PetscInt k = 0; k < sys->njoints; k++) w[k] = sys->joints[k]->actuator_work; /* and a moving rest's work */
    PetscCall(PhlexCheckpointWriteReals(v, "/monitor", "joint_actuator_work", sys->njoints, w));
    PetscCall(PetscFree(w));
  }
  {
    /* SNES phlexreduced's last Newton contractions set the next stage's linear tolerances: a restart repeats them */
    SNES      snes;
    PetscReal rec[PHLEX_REDUCED_NCONTRACTIONS];
    PetscCall(TSGetSNES(ts, &snes));
    PetscCall(PhlexSNESReducedGetContractions(snes, rec));
    PetscCall(PhlexCheckpointWriteReals(v, "/solver", "newton_contractions", PHLEX_REDUCED_NCONTRACTIONS, rec));
  }
  if (sys->nfparts) {
    /* the frame's rate in each body's factored preconditioner (lagged: refactored when it drifts), so that a restart
       factors the same operator */
    PetscReal *r;
    PetscCall(PetscMalloc1(10 * sys->nfparts, &r));
    for (PetscInt k = 0; k < sys->nfparts; k++) PetscCall(PhlexFlexiblePreconditionerRateGet(sys->fparts[k], r + 10 * k));
    PetscCall(PhlexCheckpointWriteReals(v, "/solver", "preconditioner_rate", 10 * sys->nfparts, r));
    PetscCall(PetscFree(r));
  }
  PetscCall(PhlexTransientPortsSave(m, v)); /* the sampler of ports.csv */
  PetscCall(PhlexOutputSaveState(m->scene->output, v));
  PetscCall(PhlexCheckpointCommit(comm, tmp, m->ck_file, &v));
  m->ck_step = step;
  PetscCall(PetscTime(&m->ck_last));
  PetscCall(PetscLogEventEnd(PHLEX_Output, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientRestartCheck - before anything is written: the checkpoint was written for this scene, on this many
  processes, with this scheme, and its run is not already at the end of this one

  Collective
@*/
PetscErrorCode PhlexTransientRestartCheck(TS ts, MonitorContext *m, PetscViewer v, const char file[], Vec X)
{
  MPI_Comm    comm = m->scene->comm;
  PetscInt    step, nranks, fields;
  PetscReal   t, units[4], ck_units[4], tmax;
  PetscMPIInt size;
  PetscBool   same;
  char       *parts, *ck_parts, scheme[256], ck_scheme[256];
  size_t      len;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PhlexCheckpointReadInt(v, "/run", "nranks", &nranks));
  PetscCheck(nranks == size, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written by a run on %" PetscInt_FMT " processes: restart it on as many (mpiexec -n %" PetscInt_FMT "), not %d", file, nranks, nranks, (int)size);
  PetscCall(Fingerprint(m, &parts, units));
  PetscCall(PetscStrlen(parts, &len));
  PetscCall(PetscMalloc1(2 * len + 64, &ck_parts));
  PetscCall(PhlexCheckpointReadString(v, "/run", "parts", ck_parts, 2 * len + 64));
  PetscCall(PetscStrcmp(parts, ck_parts, &same));
  if (!same) {
    char msg[PETSC_MAX_PATH_LEN];
    char *a, *c;
    PetscBool numbering;
    /* the same scene but its field unknowns placed otherwise (the hashes after '@' differ) */
    PetscCall(PetscStrallocpy(parts, &a));
    PetscCall(PetscStrallocpy(ck_parts, &c));
    StripHashes(a, '@');
    StripHashes(c, '@');
    PetscCall(PetscStrcmp(a, c, &numbering));
    PetscCall(PetscFree(a));
    PetscCall(PetscFree(c));
    if (numbering && !strchr(ck_parts, '@')) {
      PetscCall(PetscSNPrintf(msg, sizeof(msg), "the checkpoint '%s' (option -restart) was written by an earlier phlex, which did not record where the bodies' unknowns are in their meshes ('%s'; this run '%s'): it cannot be checked against this run's numbering; continue that run with the phlex that wrote it", file, ck_parts, parts));
      PetscCall(PetscFree(parts));
      PetscCall(PetscFree(ck_parts));
      SETERRQ(comm, PETSC_ERR_USER_INPUT, "%s", msg);
    }
    if (numbering) {
      PetscCall(PetscSNPrintf(msg, sizeof(msg), "the checkpoint '%s' (option -restart) was written for this scene with its field unknowns numbered otherwise (its parts '%s', this scene's '%s'; after '@' a hash of where each body's unknowns are in its mesh): restart with the same mesh files, their nodes in the same order, the same -body<k>_node_order and partitioner (-body<k>_petscpartitioner_type, -whole_bodies, -body<k>_process)", file, ck_parts, parts));
      PetscCall(PetscFree(parts));
      PetscCall(PetscFree(ck_parts));
      SETERRQ(comm, PETSC_ERR_USER_INPUT, "%s", msg);
    }
    {
      /* the same scene but a reduced body's model built otherwise: its elastic coordinates are in another basis */
      PetscBool model;
      PetscCall(PetscStrallocpy(parts, &a));
      PetscCall(PetscStrallocpy(ck_parts, &c));
      StripHashes(a, '#');
      StripHashes(c, '#');
      PetscCall(PetscStrcmp(a, c, &model));
      PetscCall(PetscFree(a));
      PetscCall(PetscFree(c));
      if (model) {
        char name[PHLEX_NAME_LEN + 128], ea[PHLEX_NAME_LEN + 128], eb[PHLEX_NAME_LEN + 128];
        FirstDifferentEntry(ck_parts, parts, name, ea, eb, sizeof(ea));
        PetscCall(PetscSNPrintf(msg, sizeof(msg), "the checkpoint '%s' (option -restart) was written with another reduced model of body %s ('%s', this run '%s'; after '#' a hash of the model's provenance: the mesh file, the discretisation, the materials, the frame, the ports and the reduction): its elastic coordinates belong to another basis; restart with the same body (its mesh, options and -reduced_file) as the run that wrote it", file, name, ea, eb));
        PetscCall(PetscFree(parts));
        PetscCall(PetscFree(ck_parts));
        SETERRQ(comm, PETSC_ERR_USER_INPUT, "%s", msg);
      }
    }
    PetscCall(PetscSNPrintf(msg, sizeof(msg), "the checkpoint '%s' (option -restart) was written for another scene: its parts and joints (name:kind:field unknowns:discrete unknowns[:numbering of the unknowns, -body<k>_node_order]) are '%s', this scene's '%s'", file, ck_parts, parts));
    PetscCall(PetscFree(parts));
    PetscCall(PetscFree(ck_parts));
    SETERRQ(comm, PETSC_ERR_USER_INPUT, "%s", msg);
  }
  PetscCall(PetscFree(parts));
  PetscCall(PetscFree(ck_parts));
  PetscCall(PhlexCheckpointReadReals(v, "/run", "units", 4, ck_units));
  for (PetscInt k = 0; k < 4; k++) PetscCheck(PetscAbsReal(units[k] - ck_units[k]) <= 1e-14 * PetscAbsReal(units[k]), comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written with other reference scales (length %g m, density %g kg/m^3, modulus %g Pa, mass %g kg; this run %g, %g, %g, %g): use the same -scale_* options and materials", file, (double)ck_units[0], (double)ck_units[1], (double)ck_units[2], (double)ck_units[3], (double)units[0], (double)units[1], (double)units[2], (double)units[3]);
  {
    PetscReal  *sizes, mine;
    PetscInt    nloc;
    PetscBool   ok;
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(comm, &rank));
    PetscCall(VecGetLocalSize(X, &nloc));
    mine = (PetscReal)nloc;
    PetscCall(PetscMalloc1(size, &sizes));
    PetscCall(PhlexCheckpointReadReals(v, "/run", "local_sizes", size, sizes));
    ok = sizes[rank] == mine ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PetscFree(sizes));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPIU_BOOL, MPI_LAND, comm));
    PetscCheck(ok, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written with another distribution of the meshes over the processes: restart with the same meshes, partitioner and number of processes", file);
  }
  PetscCall(Scheme(ts, scheme, sizeof(scheme)));
  PetscCall(PhlexCheckpointReadString(v, "/run", "scheme", ck_scheme, sizeof(ck_scheme)));
  PetscCall(PetscStrcmp(scheme, ck_scheme, &same));
  PetscCheck(same, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written with the time integrator '%s', this run has '%s': restart with the same scheme", file, ck_scheme, scheme);
  if (!m->theta) {
    TSType type;
    PetscCall(TSGetType(ts, &type));
    PetscCall(PetscPrintf(comm, "Restart: TS %s keeps a history of past steps that PETSc does not checkpoint: it starts again from the checkpoint's state (the first steps differ from an uninterrupted run by the scheme's local error)\n", type));
  }
  /* fields written or not: the same as the run that wrote the checkpoint (its field segments continue) */
  PetscCall(PhlexCheckpointReadInt(v, "/output", "nwriters", &fields));
  {
    PetscInt mine = 0;
    for (PetscInt i = 0; i < m->sys->nparts; i++)
      if (PhlexPartIsElastic(m->sys->parts[i])) mine++; /* a field writer each: flexible and reduced bodies */
    if (!m->scene->output->fields) mine = 0;
    PetscCheck(mine == fields, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written %s field output (-output_fields %d): restart with the same", file, fields ? "with" : "without", fields ? 1 : 0);
  }
  PetscCall(PhlexCheckpointReadInt(v, "/run", "step", &step));
  PetscCall(PhlexCheckpointReadReals(v, "/run", "time", 1, &t));
  PetscCall(TSGetMaxTime(ts, &tmax));
  {
    PetscInt smax;
    PetscCall(TSGetMaxSteps(ts, &smax));
    PetscCheck(t < tmax && step < smax, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) is at step %" PetscInt_FMT ", t = %g s: the run is already there (-ts_max_time %g s, -ts_max_steps %" PetscInt_FMT "); raise them to continue it", file, step, (double)t, (double)tmax, smax);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientRestart - continues from a checkpoint (checked by PhlexTransientRestartCheck): sets the state X, the
  time, the step and the step size, the multipliers and the monitor's accumulators (the outputs were opened
  continuing the checkpoint's, PhlexOutputSetRestart)

  Collective
@*/
PetscErrorCode PhlexTransientRestart(TS ts, MonitorContext *m, PetscViewer v, const char file[], Vec X)
{
  MPI_Comm    comm = m->scene->comm;
  PhlexSystem sys  = m->sys;
  Vec         P;
  PetscInt    step, nq;
  PetscReal   t, dt, mon[CHECKPOINT_NMONITOR];

  PetscFunctionBeginUser;
  PetscCall(PhlexCheckpointReadInt(v, "/run", "step", &step));
  PetscCall(PhlexCheckpointReadReals(v, "/run", "time", 1, &t));
  PetscCall(PhlexCheckpointReadReals(v, "/run", "dt", 1, &dt));
  PetscCall(PlainVec(X, &P));
  PetscCall(PetscViewerHDF5PushGroup(v, "/state"));
  PetscCall(VecLoad(P, v));
  PetscCall(PetscViewerHDF5PopGroup(v));
  PetscCall(VecCopy(P, X));
  PetscCall(VecDestroy(&P));
  PetscCall(PhlexCheckpointReadInt(v, "/state", "nq", &nq));
  PetscCheck(nq == sys->nq, comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) has %" PetscInt_FMT " discrete unknowns, this scene %" PetscInt_FMT, file, nq, sys->nq);
  PetscCall(PhlexCheckpointReadReals(v, "/state", "q_previous", nq, m->qprev));
  PetscCall(PhlexCheckpointReadReals(v, "/state", "multipliers", nq, m->lambda));
  PetscCall(PhlexCheckpointReadReals(v, "/monitor", "accumulators", CHECKPOINT_NMONITOR, mon));
  UnpackMonitor(m, mon);
  if (sys->njoints) {
    /* absent from the checkpoints of earlier versions (no force elements then: zero) */
    PetscBool has;
    PetscCall(PetscViewerHDF5HasDataset(v, "/monitor/joint_dissipated_work", &has));
    if (has) {
      PetscReal *w;
      PetscCall(PetscMalloc1(sys->njoints, &w));
      PetscCall(PhlexCheckpointReadReals(v, "/monitor", "joint_dissipated_work", sys->njoints, w));
      for (PetscInt k = 0; k < sys->njoints; k++) sys->joints[k]->dissipated_work = w[k];
      PetscCall(PetscFree(w));
    }
    PetscCall(PetscViewerHDF5HasDataset(v, "/monitor/joint_actuator_work", &has));
    if (has) {
      PetscReal *w;
      PetscCall(PetscMalloc1(sys->njoints, &w));
      PetscCall(PhlexCheckpointReadReals(v, "/monitor", "joint_actuator_work", sys->njoints, w));
      for (PetscInt k = 0; k < sys->njoints; k++) sys->joints[k]->actuator_work = w[k];
      PetscCall(PetscFree(w));
    }
  }
  {
    /* absent from the checkpoints of earlier versions: the first stage then solves every Newton step to the linear
       tolerance (the same solution to Newton's tolerance, not the same bytes) */
    SNES      snes;
    PetscReal rec[PHLEX_REDUCED_NCONTRACTIONS];
    PetscBool has;
    PetscCall(PetscViewerHDF5HasDataset(v, "/solver/newton_contractions", &has));
    if (has) {
      PetscCall(PhlexCheckpointReadReals(v, "/solver", "newton_contractions", PHLEX_REDUCED_NCONTRACTIONS, rec));
      PetscCall(TSGetSNES(ts, &snes));
      PetscCall(PhlexSNESReducedSetContractions(snes, rec));
    }
  }
  if (sys->nfparts) {
    /* absent from the checkpoints of earlier versions: the restart then factors the operator at its own state's rate
       (the same solution to Newton's tolerance, not the same bytes) */
    PetscBool has;
    PetscCall(PetscViewerHDF5HasDataset(v, "/solver/preconditioner_rate", &has));
    if (has) {
      PetscReal *r;
      PetscCall(PetscMalloc1(10 * sys->nfparts, &r));
      PetscCall(PhlexCheckpointReadReals(v, "/solver", "preconditioner_rate", 10 * sys->nfparts, r));
      for (PetscInt k = 0; k < sys->nfparts; k++) PetscCall(PhlexFlexiblePreconditionerRateSet(sys->fparts[k], r + 10 * k));
      PetscCall(PetscFree(r));
    }
  }
  PetscCall(PhlexTransientPortsRestart(m, v, file));
  PetscCall(TSSetTime(ts, t));
  PetscCall(TSSetStepNumber(ts, step));
  if (m->adaptive) PetscCall(TSSetTimeStep(ts, dt)); /* the controller's next step */
  else {
    /* fixed steps: -ts_dt (the checkpoint's current step may have been cut to land on its run's end) */
    PetscReal nominal;
    PetscCall(PhlexCheckpointReadReals(v, "/run", "dt_nominal", 1, &nominal));
    PetscCall(TSGetTimeStep(ts, &dt));
    if (PetscAbsReal(dt - nominal) > 1e-14 * nominal) PetscCall(PetscPrintf(comm, "Restart: time step %g s (-ts_dt), the run that wrote the checkpoint had %g s\n", (double)dt, (double)nominal));
  }
  if (m->Xprev) PetscCall(VecCopy(X, m->Xprev));
  m->first_step = step;
  m->last_step  = step;
  m->ck_step    = step;
  PetscCall(PetscPrintf(comm, "Restart from %s: step %" PetscInt_FMT ", t = %g s, time step %g s\n", file, step, (double)t, (double)dt));
  PetscFunctionReturn(0);
}
