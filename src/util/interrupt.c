/* SIGINT and SIGTERM end a run cleanly: the signal only sets a flag, the time-step and eigensolver monitors check
   it (collectively) and raise an error that unwinds like any other (temporary output files removed), with the
   exit code 128 + signal. A second signal before that ends the process at once. PETSc catches neither (SIGINT
   never, SIGTERM not with Open MPI), so the handler is installed here; a SIGINT ignored at start (a background job
   of a script) stays ignored. Every other signal keeps PETSc's handling (a crash report). */
#define _POSIX_C_SOURCE 200809L
#include <phlex_impl.h>
#include <signal.h>
#include <unistd.h>

static volatile sig_atomic_t phlex_signal = 0; /* the signal received (0: none) */

static void InterruptHandler(int sig)
{
  if (phlex_signal) _exit(128 + sig); /* impatient: a second signal */
  phlex_signal = sig;
}

/*@C
  PhlexInterruptPush - installs the handler that turns SIGINT/SIGTERM into a clean stop at the next step

  Not collective
@*/
PetscErrorCode PhlexInterruptPush(void)
{
  const int signals[] = {SIGINT, SIGTERM};

  PetscFunctionBeginUser;
  for (size_t i = 0; i < sizeof(signals) / sizeof(signals[0]); i++) {
    struct sigaction action, old;
    PetscCheck(!sigaction(signals[i], NULL, &old), PETSC_COMM_SELF, PETSC_ERR_SYS, "cannot read the handler of signal %d", signals[i]);
    if (signals[i] == SIGINT && old.sa_handler == SIG_IGN) continue;
    memset(&action, 0, sizeof(action));
    action.sa_handler = InterruptHandler;
    sigemptyset(&action.sa_mask);
    PetscCheck(!sigaction(signals[i], &action, NULL), PETSC_COMM_SELF, PETSC_ERR_SYS, "cannot install the handler of signal %d", signals[i]);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexInterruptCheck - raises PETSC_ERR_SIG on every rank when any rank received SIGINT or SIGTERM

  Collective

  Input Parameters:
+ comm  - the run's communicator
- where - where the run stands, for the message (e.g. "at step 12, t = 0.01 s")
@*/
PetscErrorCode PhlexInterruptCheck(MPI_Comm comm, const char where[])
{
  int sig = (int)phlex_signal, any;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&sig, &any, 1, MPI_INT, MPI_MAX, comm));
  if (any) phlex_signal = any;
  PetscCheck(!any, comm, PETSC_ERR_SIG, "interrupted by %s %s: the run stopped, its temporary output files were removed", any == SIGINT ? "SIGINT" : "SIGTERM", where);
  PetscFunctionReturn(0);
}

/*@C
  PhlexInterruptPending - the signal (SIGINT or SIGTERM) any rank received, 0 if none, on every rank; the run then
  stops at PhlexInterruptCheck (or raises PETSC_ERR_SIG itself after saving what it can: a checkpoint)

  Collective
@*/
PetscErrorCode PhlexInterruptPending(MPI_Comm comm, int *sig)
{
  int mine = (int)phlex_signal;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Allreduce(&mine, sig, 1, MPI_INT, MPI_MAX, comm));
  if (*sig) phlex_signal = *sig;
  PetscFunctionReturn(0);
}

/*@C
  PhlexInterruptExitCode - 128 + the signal that interrupted the run (130 for SIGINT, 143 for SIGTERM)
@*/
int PhlexInterruptExitCode(void)
{
  return 128 + (phlex_signal ? (int)phlex_signal : SIGINT);
}

/*@C
  PhlexInterruptLocal - whether this process received SIGINT or SIGTERM (not collective: a loop over local work
  breaks out on it, then every process meets at PhlexInterruptCheck)
@*/
PetscBool PhlexInterruptLocal(void)
{
  return phlex_signal ? PETSC_TRUE : PETSC_FALSE;
}
