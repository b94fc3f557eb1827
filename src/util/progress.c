/* Progress of a long run: one compact line every -progress_interval seconds of wall time (time steps: step, time,
   share done, elapsed, estimated time left, energy and joint drift; eigensolver: converged pairs). Both monitors
   also stop the run when SIGINT or SIGTERM arrived (interrupt.c). */
#include <phlex_impl.h>

static PetscBool progress_on       = PETSC_TRUE;
static PetscReal progress_interval = 5.0; /* s of wall time */

/*@C
  PhlexProgressSetFromOptions - reads the progress options

  Collective

  Options Database Keys:
+ -progress <bool>           - print progress lines during the run
- -progress_interval <s>     - wall time between two lines (0: every step)
@*/
PetscErrorCode PhlexProgressSetFromOptions(MPI_Comm comm)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, NULL, "Progress options", NULL);
  PetscCall(PetscOptionsBool("-progress", "Print a progress line during the run (step, time, share done, elapsed, time left, drift)", "PhlexProgressSetFromOptions", progress_on, &progress_on, NULL));
  PetscCall(PetscOptionsReal("-progress_interval", "Wall time between two progress lines [s] (0: every step)", "PhlexProgressSetFromOptions", progress_interval, &progress_interval, NULL));
  PetscOptionsEnd();
  PetscCheck(progress_interval >= 0 && !PetscIsInfOrNanReal(progress_interval), comm, PETSC_ERR_USER_INPUT, "-progress_interval must be >= 0 s, got %g", (double)progress_interval);
  PetscFunctionReturn(0);
}

/* "1 h 02 min", "3 min 05 s", "12.3 s" */
static void FormatDuration(PetscReal s, char buf[], size_t len)
{
  if (s >= 3600) snprintf(buf, len, "%d h %02d min", (int)(s / 3600), (int)(PetscFmodReal(s, 3600) / 60));
  else if (s >= 60) snprintf(buf, len, "%d min %02d s", (int)(s / 60), (int)PetscFmodReal(s, 60));
  else snprintf(buf, len, "%.1f s", (double)s);
}

/*@C
  PhlexProgressStart - starts the clock of a progress report

  Not collective
@*/
PetscErrorCode PhlexProgressStart(PhlexProgress *p)
{
  PetscFunctionBeginUser;
  PetscCall(PetscTime(&p->start));
  p->last  = p->start;
  p->done0 = 0;
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressStep - after a time step: stops the run if interrupted, prints a progress line when due

  Collective

  Input Parameters:
+ p        - the progress clock
. comm     - the run's communicator
. step, t  - the step just taken and the time reached [s]
. done     - the share of the run done (0..1)
- drift    - what to say about the invariants (e.g. "|H - H0|/H0 3.1e-13"), or NULL
@*/
PetscErrorCode PhlexProgressStep(PhlexProgress *p, MPI_Comm comm, PetscInt step, PetscReal t, PetscReal done, const char drift[])
{
  PetscLogDouble now;
  char           where[128], elapsed[32], left[32];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(where, sizeof(where), "at step %" PetscInt_FMT ", t = %g s", step, (double)t));
  PetscCall(PhlexInterruptCheck(comm, where));
  if (!progress_on) PetscFunctionReturn(0);
  PetscCall(PetscTime(&now));
  if (now - p->last < progress_interval) PetscFunctionReturn(0);
  p->last = now;
  FormatDuration((PetscReal)(now - p->start), elapsed, sizeof(elapsed));
  /* the time left from the pace since this process started (a restart starts at done0) */
  if (done > p->done0) FormatDuration((PetscReal)(now - p->start) * (1 - done) / (done - p->done0), left, sizeof(left));
  else PetscCall(PetscStrcpy(left, "?"));
  PetscCall(PetscPrintf(comm, "progress: step %" PetscInt_FMT ", t = %.6g s (%.0f%%), elapsed %s, left ~%s%s%s\n", step, (double)t, (double)(100 * done), elapsed, left, drift ? ", " : "", drift ? drift : ""));
  PetscFunctionReturn(0);
}

/* an eigensolver's iteration (EPS or PEP): stop if interrupted, a progress line when due */
static PetscErrorCode EigenIteration(PhlexProgress *p, MPI_Comm comm, PetscInt its, PetscInt nconv, PetscInt nev)
{
  PetscLogDouble now;
  char           where[128], elapsed[32];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(where, sizeof(where), "in the eigensolver of %s (iteration %" PetscInt_FMT ")", p->what, its));
  PetscCall(PhlexInterruptCheck(comm, where));
  if (!progress_on) PetscFunctionReturn(0);
  PetscCall(PetscTime(&now));
  if (now - p->last < progress_interval) PetscFunctionReturn(0);
  p->last = now;
  FormatDuration((PetscReal)(now - p->start), elapsed, sizeof(elapsed));
  PetscCall(PetscPrintf(comm, "progress: modes of %s: %" PetscInt_FMT " of %" PetscInt_FMT " converged after %" PetscInt_FMT " iterations, elapsed %s\n", p->what, PetscMin(nconv, nev), nev, its, elapsed));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressEPSMonitor - EPS monitor: the converged eigenpairs of the body being solved, when due; stops the run
  if interrupted (context: a PhlexProgress whose what names the body)
@*/
PetscErrorCode PhlexProgressEPSMonitor(EPS eps, PetscInt its, PetscInt nconv, PetscScalar *eigr, PetscScalar *eigi, PetscReal *errest, PetscInt nest, void *ctx)
{
  MPI_Comm comm;
  PetscInt nev;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)eps, &comm));
  PetscCall(EPSGetDimensions(eps, &nev, NULL, NULL));
  PetscCall(EigenIteration((PhlexProgress *)ctx, comm, its, nconv, nev));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressPEPMonitor - PEP monitor (the damped linearized analysis): as PhlexProgressEPSMonitor
@*/
PetscErrorCode PhlexProgressPEPMonitor(PEP pep, PetscInt its, PetscInt nconv, PetscScalar *eigr, PetscScalar *eigi, PetscReal *errest, PetscInt nest, void *ctx)
{
  MPI_Comm comm;
  PetscInt nev;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)pep, &comm));
  PetscCall(PEPGetDimensions(pep, &nev, NULL, NULL));
  PetscCall(EigenIteration((PhlexProgress *)ctx, comm, its, nconv, nev));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressEPSSolve - EPSSolve with progress lines and a clean stop on SIGINT/SIGTERM (issue 43 item 1); what names
  the problem in the lines ("body bar", "the linearized assembly")

  Collective
@*/
PetscErrorCode PhlexProgressEPSSolve(EPS eps, const char what[])
{
  PhlexProgress progress;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(progress.what, what, sizeof(progress.what)));
  PetscCall(PhlexProgressStart(&progress));
  PetscCall(EPSMonitorSet(eps, PhlexProgressEPSMonitor, &progress, NULL));
  PetscCall(EPSSolve(eps));
  PetscCall(EPSMonitorCancel(eps)); /* the context lives on this stack */
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressPEPSolve - PEPSolve as PhlexProgressEPSSolve

  Collective
@*/
PetscErrorCode PhlexProgressPEPSolve(PEP pep, const char what[])
{
  PhlexProgress progress;

  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(progress.what, what, sizeof(progress.what)));
  PetscCall(PhlexProgressStart(&progress));
  PetscCall(PEPMonitorSet(pep, PhlexProgressPEPMonitor, &progress, NULL));
  PetscCall(PEPSolve(pep));
  PetscCall(PEPMonitorCancel(pep));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressPhase - in a long phase that is not a time step or an eigensolver iteration (the assembly of a large
  body, the consistent start, a body's reduction): stops the run if interrupted, prints a progress line when due

  Collective (every process must call it as often: in a loop over local cells, break out on PhlexInterruptLocal()
  and call this after the loop)

  Input Parameters:
+ p    - the progress clock (PhlexProgressStart)
. comm - the communicator of the phase
. what - the phase, e.g. "assembly of body arm"
- done - the share done (0..1), or a negative number when unknown
@*/
PetscErrorCode PhlexProgressPhase(PhlexProgress *p, MPI_Comm comm, const char what[], PetscReal done)
{
  PetscLogDouble now;
  char           where[160], elapsed[32];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(where, sizeof(where), "in the %s", what));
  PetscCall(PhlexInterruptCheck(comm, where));
  if (!progress_on) PetscFunctionReturn(0);
  PetscCall(PetscTime(&now));
  if (now - p->last < progress_interval) PetscFunctionReturn(0);
  p->last = now;
  FormatDuration((PetscReal)(now - p->start), elapsed, sizeof(elapsed));
  if (done >= 0) PetscCall(PetscPrintf(comm, "progress: %s: %.0f%%, elapsed %s\n", what, (double)(100 * done), elapsed));
  else PetscCall(PetscPrintf(comm, "progress: %s, elapsed %s\n", what, elapsed));
  PetscFunctionReturn(0);
}

/* Loops over the local cells of a long phase outside the time steps (the assembly's element loops, the stiffening's
   and the stress maps', the linearised pencil's rows) check the interrupt flag and report progress: every process
   splits its n local items into PHLEX_PROGRESS_CHUNKS equal chunks and meets the others after each (PhlexProgressPhase:
   one reduction), so that the processes check the same number of times whatever their counts; a process that
   received the signal skips nothing, it stops at the next chunk. Inside the time steps (TSSolve) these loops run in
   every Newton iteration and do not check: a run stops at the end of its step (README, exit codes 130/143), where a
   checkpoint can be written. */
#define PHLEX_PROGRESS_CHUNKS 8
static PetscBool in_steps = PETSC_FALSE;

/*@C
  PhlexProgressSetInSteps - marks the time steps (TSSolve): the loops' chunk checks are then off

  Not collective
@*/
void PhlexProgressSetInSteps(PetscBool flg)
{
  in_steps = flg;
}

/*@C
  PhlexProgressInSteps - whether the time steps are running (PhlexProgressSetInSteps): checks inside a step are left
  to the step's end, where the monitor writes the checkpoint before it stops the run

  Not collective
@*/
PetscBool PhlexProgressInSteps(void)
{
  return in_steps;
}

/*@C
  PhlexProgressChunk - after item i of n local items of a long loop: at the end of a chunk, the collective check
  (PhlexProgressPhase) with the share done

  Collective (every process calls PhlexProgressChunksEnd after its loop, which makes the checks it has not made)
@*/
PetscErrorCode PhlexProgressChunk(PhlexProgress *p, MPI_Comm comm, const char what[], PetscInt i, PetscInt n, PetscInt *chunk)
{
  PetscFunctionBeginUser;
  if (in_steps) PetscFunctionReturn(0);
  while (*chunk < PHLEX_PROGRESS_CHUNKS - 1 && (i + 1) * PHLEX_PROGRESS_CHUNKS >= (*chunk + 1) * n) {
    (*chunk)++;
    PetscCall(PhlexProgressPhase(p, comm, what, (PetscReal)*chunk / PHLEX_PROGRESS_CHUNKS));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressChunksEnd - after a loop of PhlexProgressChunk: the checks a process with fewer items (or none) has not
  made yet, then the last (100 %)

  Collective
@*/
PetscErrorCode PhlexProgressChunksEnd(PhlexProgress *p, MPI_Comm comm, const char what[], PetscInt chunk)
{
  PetscFunctionBeginUser;
  if (in_steps) PetscFunctionReturn(0);
  for (; chunk < PHLEX_PROGRESS_CHUNKS - 1; chunk++) PetscCall(PhlexProgressPhase(p, comm, what, (PetscReal)(chunk + 1) / PHLEX_PROGRESS_CHUNKS));
  PetscCall(PhlexProgressPhase(p, comm, what, 1.0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProgressCheck - outside the time steps: stops the run if interrupted ("in the <what>"); for a loop that is
  one application of an operator (the stress maps' cell kernels, applied many times by a conversion or a solver)

  Collective
@*/
PetscErrorCode PhlexProgressCheck(MPI_Comm comm, const char what[])
{
  char where[160];

  PetscFunctionBeginUser;
  if (in_steps) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(where, sizeof(where), "in the %s", what));
  PetscCall(PhlexInterruptCheck(comm, where));
  PetscFunctionReturn(0);
}
