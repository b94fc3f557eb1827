/* Error reporting and exit codes. Errors raised by phlex itself (bad input, numerical failures, failed self-checks,
   unwritable output), and PETSc's errors of kind "user input" (option values), are printed as one clear line (which
   file, option, body and value); any other error keeps PETSc's full traceback. The first error of a run fixes the
   exit code (PhlexExitCode): one small documented set, the same on every rank. */
#include <phlex_impl.h>

static PetscBool phlex_traceback = PETSC_FALSE;
static PetscBool phlex_short     = PETSC_FALSE; /* the error being propagated was printed as one line */
static int       phlex_exit      = 0;           /* exit code of the first error (0: none yet) */

/* the kinds of error that phlex explains in one line when it raises them (input, numerical failure, self-check,
   output, interruption) */
static PetscBool IsOneLineError(PetscErrorCode n)
{
  switch (n) {
  case PETSC_ERR_USER_INPUT:
  case PETSC_ERR_USER:
  case PETSC_ERR_FILE_OPEN:
  case PETSC_ERR_FILE_READ:
  case PETSC_ERR_FILE_WRITE:
  case PETSC_ERR_FILE_UNEXPECTED:
  case PETSC_ERR_SUP:
  case PETSC_ERR_ARG_OUTOFRANGE:
  case PETSC_ERR_NOT_CONVERGED:
  case PETSC_ERR_CONV_FAILED:
  case PETSC_ERR_SIG:
    return PETSC_TRUE;
  default:
    return PETSC_FALSE;
  }
}

/* the exit code of an error: its kind, and whether phlex or PETSc's option parsing raised it (an out-of-range or
   unsupported argument deep inside PETSc is a bug, not bad input) */
static int ExitCodeOf(PetscErrorCode n, PetscBool ours)
{
  switch (n) {
  case PETSC_ERR_USER_INPUT:
  case PETSC_ERR_FILE_OPEN:
  case PETSC_ERR_FILE_READ:
  case PETSC_ERR_FILE_UNEXPECTED:
    return PHLEX_EXIT_INPUT;
  case PETSC_ERR_ARG_OUTOFRANGE:
  case PETSC_ERR_SUP:
    return ours ? PHLEX_EXIT_INPUT : PHLEX_EXIT_INTERNAL;
  case PETSC_ERR_FILE_WRITE:
    return PHLEX_EXIT_IO;
  case PETSC_ERR_NOT_CONVERGED:
  case PETSC_ERR_CONV_FAILED:
  case PETSC_ERR_FP:
    return PHLEX_EXIT_NUMERICAL;
  case PETSC_ERR_USER:
    return ours ? PHLEX_EXIT_SELFCHECK : PHLEX_EXIT_INTERNAL;
  case PETSC_ERR_SIG:
    return PhlexInterruptExitCode();
  default:
    return PHLEX_EXIT_INTERNAL;
  }
}

static PetscErrorCode PhlexErrorHandler(MPI_Comm comm, int line, const char *fun, const char *file, PetscErrorCode n, PetscErrorType p, const char *mess, void *ctx)
{
  PetscBool ours = (file && !strncmp(file, "src/", 4)) ? PETSC_TRUE : PETSC_FALSE;

  if (p == PETSC_ERROR_INITIAL) {
    PetscMPIInt rank = 0;
    phlex_short      = PETSC_FALSE;
    /* collective checks raise the same error on every rank: print it once */
    if (comm != MPI_COMM_NULL) MPI_Comm_rank(comm, &rank);
    /* PETSc's own option parsing (an unknown value of a list option, a malformed number) is input too */
    const PetscBool options = (file && (strstr(file, "sys/objects/options.c") || strstr(file, "sys/objects/aoptions.c"))) ? PETSC_TRUE : PETSC_FALSE;
    if (!phlex_exit) phlex_exit = ExitCodeOf(n, (ours || options) ? PETSC_TRUE : PETSC_FALSE);
    if ((ours || options) && IsOneLineError(n) && !phlex_traceback) {
      phlex_short = PETSC_TRUE;
      if (rank == 0) {
        fprintf(stderr, "phlex: error: %s\n", mess ? mess : "(no message)");
        fflush(stderr);
      }
      return n;
    }
  } else if (phlex_short) {
    return n; /* the one-line message was printed */
  }
  return PetscTraceBackErrorHandler(comm, line, fun, file, n, p, mess, ctx);
}

/*@C
  PhlexExitCode - the exit code of the run's first error: PHLEX_EXIT_INPUT, _NUMERICAL, _IO, _SELFCHECK, the
  interrupt codes, or PHLEX_EXIT_INTERNAL (also for an error that bypassed the handler)
@*/
int PhlexExitCode(void)
{
  return phlex_exit ? phlex_exit : PHLEX_EXIT_INTERNAL;
}

/*@C
  PhlexErrorHandlerPush - installs phlex's error handler

  Options Database Key:
. -phlex_error_traceback - print PETSc's full traceback also for input errors
@*/
PetscErrorCode PhlexErrorHandlerPush(void)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(PETSC_COMM_WORLD, NULL, "Error reporting", NULL);
  PetscCall(PetscOptionsBool("-phlex_error_traceback", "Print PETSc's full traceback also for input errors", "PhlexErrorHandlerPush", phlex_traceback, &phlex_traceback, NULL));
  PetscOptionsEnd();
  PetscCall(PetscPushErrorHandler(PhlexErrorHandler, NULL));
  PetscFunctionReturn(0);
}

/* A real-array option that must have exactly n numbers when given (inside PetscOptionsBegin/End, whose
   PetscOptionsObject is passed on). A wrong count is an input error naming what it belongs to and the option. */
PetscErrorCode PhlexOptionsRealN(PetscOptionItems *PetscOptionsObject, MPI_Comm comm, const char what[], const char prefix[], const char opt[], const char text[], const char man[], PetscInt n, PetscReal value[], PetscBool *set)
{
  PetscInt  got = n;
  PetscBool flg = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsRealArray(opt, text, man, value, &got, &flg));
  PetscCheck(!flg || got == n, comm, PETSC_ERR_USER_INPUT, "%s: option -%s%s needs %" PetscInt_FMT " components, got %" PetscInt_FMT, what, prefix, opt + 1, n, got);
  if (set) *set = flg;
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsListLength - the number of entries of a comma-separated option value (at least 1; 1 when unset), to
  size the array handed to PetscOptionsStringArray (no fixed cap on the number of ports)
@*/
PetscErrorCode PhlexOptionsListLength(const char prefix[], const char name[], PetscInt *n)
{
  const char *value = NULL;
  PetscBool   set;

  PetscFunctionBeginUser;
  *n = 1;
  PetscCall(PetscOptionsFindPair(NULL, prefix, name, &value, &set));
  if (set && value)
    for (const char *c = value; *c; c++)
      if (*c == ',') (*n)++;
  PetscFunctionReturn(0);
}
