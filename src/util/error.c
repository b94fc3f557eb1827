/* Error reporting and exit codes. Errors raised by phlex itself (bad input, numerical failures, failed self-checks,
   unwritable output), and PETSc's errors of kind "user input" (option values), are printed as one clear line (which
   file, option, body and value); any other error keeps PETSc's full traceback. The first error of a run fixes the
   exit code (PhlexExitCode): one small documented set, the same on every rank. */
#include <phlex_impl.h>
#include <ctype.h>

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
  case PETSC_ERR_ARG_WRONG:
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
  case PETSC_ERR_ARG_WRONG:
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

/* PETSc's parsing of a malformed value ("Input string abc has no numeric value") does not say which option held it:
   the options whose value it is are found in the database and named */
static void NameMalformedOption(const char *mess, char *out, size_t len)
{
  const char *value = NULL, *kind = NULL, *end;
  char        v[256], *all = NULL, *tok, names[512] = "", kindbuf[128], given[512] = "", *name = NULL;
  size_t      nv;

  out[0] = 0;
  if (!mess) return;
  if (!strncmp(mess, "Input string ", 13)) {
    value = mess + 13;
    end   = strstr(value, " has no ");
    kind  = strstr(mess, "integer") ? "not an integer (no '.', no exponent)" : "not a number";
  } else if (!strncmp(mess, "Unknown logical value: ", 23)) {
    value = mess + 23;
    end   = value + strlen(value);
    kind  = "not a boolean (true/false, yes/no, 1/0)";
  } else if (!strncmp(mess, "Newly set value ", 16)) {
    /* a bounded integer option (PetscOptionsBoundedInt, PetscOptionsRangeInt) */
    const char *bound = strstr(mess, " than allowed bound ");
    value = mess + 16;
    end   = strchr(value, ' ');
    if (bound) {
      snprintf(kindbuf, sizeof(kindbuf), "%s %s", strstr(mess, " less than ") ? "below the smallest allowed value," : "above the largest allowed value,", bound + 20);
      kind = kindbuf;
    }
  }
  if (!value || !end) return;
  nv = PetscMin((size_t)(end - value), sizeof(v) - 1);
  memcpy(v, value, nv);
  v[nv] = 0;
  if (PetscOptionsGetAll(NULL, &all)) return;
  /* "-name value -name value ...": a name is a '-' and a letter, its value the tokens up to the next name (a value
     may hold spaces: "7800 kg/m^3") */
  for (tok = strtok(all, " "); ; tok = strtok(NULL, " ")) {
    const PetscBool is_name = (!tok || (tok[0] == '-' && isalpha((unsigned char)tok[1]))) ? PETSC_TRUE : PETSC_FALSE;
    if (is_name) {
      if (name && !strcmp(given, v)) {
        size_t n = strlen(names);
        snprintf(names + n, sizeof(names) - n, "%s%s", n ? ", " : "", name);
      }
      if (!tok) break;
      name     = tok;
      given[0] = 0;
    } else if (name) {
      size_t n = strlen(given);
      snprintf(given + n, sizeof(given) - n, "%s%s", n ? " " : "", tok);
    }
  }
  (void)PetscFree(all);
  if (names[0]) snprintf(out, len, "option %s: '%s' is %s", names, v, kind);
}

/* PETSc's "MatSolverType X does not support [factorization type F for] matrix type Y" (a package that cannot factor
   the operator: a one-process package on several processes, where PETSc's matrices are mpiaij or mpisbaij, or an
   LU-only package asked for Cholesky) names neither the option that chose the package nor the way out: the options
   naming it are found in the database (phlex's per-body copies of a preset option among them) */
static void NameFactorPackage(const char *mess, char *out, size_t len)
{
  char        package[64], type[64], kind[64], what[160], *all = NULL, *tok, *next, names[1024] = "", pctype[256] = "";
  int         count = 0, cut = 0;
  const char *suffix = "pc_factor_mat_solver_type";

  out[0] = 0;
  if (!mess) return;
  if (sscanf(mess, "MatSolverType %63s does not support factorization type %63s for matrix type %63s", package, kind, type) == 3) snprintf(what, sizeof(what), "no %s factorization of matrix type %s", kind, type);
  else if (sscanf(mess, "MatSolverType %63s does not support matrix type %63s", package, type) == 2) snprintf(what, sizeof(what), "no factorization of matrix type %s", type);
  else return;
  if (PetscOptionsGetAll(NULL, &all)) return;
  for (tok = strtok(all, " "); tok; tok = next) {
    size_t nt = strlen(tok), ns = strlen(suffix);
    next = strtok(NULL, " ");
    if (tok[0] == '-' && nt > ns && !strcmp(tok + nt - ns, suffix) && next && !strcmp(next, package)) {
      size_t n = strlen(names);
      if (n + nt + strlen(next) + 8 >= sizeof(names)) {
        cut++;
        continue;
      }
      snprintf(names + n, sizeof(names) - n, "%s%s %s", n ? ", " : "", tok, next);
      if (!count) snprintf(pctype, sizeof(pctype), "%.*spc_type", (int)(nt - ns), tok); /* the first one's factorization */
      count++;
    }
  }
  (void)PetscFree(all);
  if (!names[0]) return;
  if (cut) {
    size_t n = strlen(names);
    snprintf(names + n, sizeof(names) - n, " and %d more", cut);
  }
  if (strncmp(type, "mpi", 3)) {
    snprintf(out, len, "option%s %s: the package has %s; choose another package (mumps has LU and Cholesky) or factorization (%s)", count + cut > 1 ? "s" : "", names, what, pctype);
    return;
  }
  /* PC phlexbordered factors a body whole on one process with a sequential solver there (-whole_bodies) */
  snprintf(out, len, "option%s %s: the package has %s (it factors on one process only); on several processes use mumps (options/solver/exact.opts, bordered.opts; exact_serial.opts and bordered_serial.opts are for one process)%s", count + cut > 1 ? "s" : "", names, what, strstr(names, "bordered_") ? ", or put each body whole on one process (-whole_bodies), where its solver is sequential" : "");
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
    /* an unknown value of a list option (PetscOptionsEnum, PetscOptionsList: "Unknown option x for -y") is bad input,
       not a failed self-check */
    if (!phlex_exit) phlex_exit = (options && n == PETSC_ERR_USER) ? PHLEX_EXIT_INPUT : ExitCodeOf(n, (ours || options) ? PETSC_TRUE : PETSC_FALSE);
    if (n == PETSC_ERR_MISSING_FACTOR && !phlex_traceback) {
      char named[2048];
      NameFactorPackage(mess, named, sizeof(named));
      if (named[0]) {
        /* the options named are input; the first error fixes the exit code */
        if (phlex_exit == PHLEX_EXIT_INTERNAL && ExitCodeOf(n, PETSC_FALSE) == PHLEX_EXIT_INTERNAL) phlex_exit = PHLEX_EXIT_INPUT;
        phlex_short = PETSC_TRUE;
        if (rank == 0) {
          fprintf(stderr, "phlex: error: %s\n", named);
          fflush(stderr);
        }
        return n;
      }
    }
    if ((ours || options) && IsOneLineError(n) && !phlex_traceback) {
      phlex_short = PETSC_TRUE;
      if (rank == 0) {
        char named[1024] = "";
        if (options) NameMalformedOption(mess, named, sizeof(named));
        fprintf(stderr, "phlex: error: %s\n", named[0] ? named : (mess ? mess : "(no message)"));
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

/*@C
  PhlexErrorHandlerPop - removes phlex's error handler (before PetscFinalize, so that -malloc_dump finds nothing)
@*/
PetscErrorCode PhlexErrorHandlerPop(void)
{
  PetscFunctionBeginUser;
  PetscCall(PetscPopErrorHandler());
  PetscFunctionReturn(0);
}

/* numbers joined by commas as PETSc prints them ("0.,-9.81,0."); "none" for no number */
static PetscErrorCode JoinReals(const PetscReal v[], PetscInt n, char out[], size_t len)
{
  size_t o = 0;

  PetscFunctionBeginUser;
  out[0] = 0;
  if (!n) PetscCall(PetscStrncpy(out, "none", len));
  for (PetscInt i = 0; i < n && o + 1 < len; i++) {
    PetscCall(PetscSNPrintf(out + o, len - o, "%s%g", i ? "," : "", (double)v[i]));
    PetscCall(PetscStrlen(out, &o));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsRealList_Private - PetscOptionsRealArray with the whole value and default in -help (PETSc 3.18 prints
  only the first number of a list not given: -gravity <0.>): "<now v1,v2,v3 : formerly d1,d2,d3>", which the help
  filter shows as "<v1,v2,v3; default d1,d2,d3>"; ndefault: how many of value[] are the default (0: none). Use the
  macro PhlexOptionsRealList inside PetscOptionsBegin/End.
@*/
PetscErrorCode PhlexOptionsRealList_Private(PetscOptionItems *PetscOptionsObject, const char opt[], const char text[], const char man[], PetscReal value[], PetscInt *n, PetscBool *set, PetscInt ndefault)
{
  const PetscBool help = (PetscOptionsObject->printhelp && PetscOptionsObject->count == 1 && !PetscOptionsObject->alreadyprinted) ? PETSC_TRUE : PETSC_FALSE;
  const PetscBool printhelp = PetscOptionsObject->printhelp;
  PetscReal       def[16];
  const PetscInt  nd = PetscMin(PetscMin(ndefault, *n), 16);
  PetscBool       flg = PETSC_FALSE;
  PetscErrorCode  ierr;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < nd; i++) def[i] = value[i];
  PetscOptionsObject->printhelp = PETSC_FALSE; /* PETSc's line is replaced by the one below */
  ierr                          = PetscOptionsRealArray(opt, text, man, value, n, &flg);
  PetscOptionsObject->printhelp = printhelp;
  PetscCall(ierr);
  if (help) {
    char now[1024], was[1024];
    PetscCall(JoinReals(flg ? value : def, flg ? *n : nd, now, sizeof(now)));
    PetscCall(JoinReals(def, nd, was, sizeof(was)));
    PetscCall((*PetscHelpPrintf)(PetscOptionsObject->comm, "  -%s%s <now %s : formerly %s>: %s (%s)\n", PetscOptionsObject->prefix ? PetscOptionsObject->prefix : "", opt + 1, now, was, text, man));
  }
  if (set) *set = flg;
  PetscFunctionReturn(0);
}

/* A real-array option that must have exactly n numbers when given (inside PetscOptionsBegin/End, whose
   PetscOptionsObject is passed on). A wrong count is an input error naming what it belongs to and the option. */
PetscErrorCode PhlexOptionsRealN(PetscOptionItems *PetscOptionsObject, MPI_Comm comm, const char what[], const char prefix[], const char opt[], const char text[], const char man[], PetscInt n, PetscReal value[], PetscBool *set)
{
  PetscReal buf[17];
  PetscInt  got = n + 1; /* one more than needed: PETSc drops the values beyond the room given */
  PetscBool flg = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCheck(n <= 16, comm, PETSC_ERR_PLIB, "PhlexOptionsRealN: at most 16 components");
  PetscCall(PetscArraycpy(buf, value, n));
  buf[n] = 0;
  PetscCall(PhlexOptionsRealList(opt, text, man, buf, &got, &flg, n));
  PetscCheck(!flg || got == n, comm, PETSC_ERR_USER_INPUT, "%s: option -%s%s needs %" PetscInt_FMT " components, got %s%" PetscInt_FMT, what, prefix, opt + 1, n, got > n ? "more than " : "", got > n ? n : got);
  for (PetscInt i = 0; flg && i < n; i++) {
    char v[32];
    PetscCheck(!PetscIsInfOrNanReal(buf[i]), comm, PETSC_ERR_USER_INPUT, "%s: option -%s%s: component %" PetscInt_FMT " is %s, not a finite number", what, prefix, opt + 1, i + 1, PhlexFormatReal(buf[i], v, sizeof(v)));
  }
  if (flg) PetscCall(PetscArraycpy(value, buf, n));
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
