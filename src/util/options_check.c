/* Unused options: a misspelt option is an error as soon as every option of the run has been read (before the first
   time step, before the eigensolver), naming the option and the nearest valid one. The valid names are collected
   only then, by reading the run's options once more with PETSc's help printer turned into a name collector
   (help.c). Options that PETSc reads only while solving or at the end (viewers, converged reasons, factor
   packages' settings, logging) cannot be judged before the run: they are checked at its end, with a warning. */
#include <phlex_impl.h>
#include <ctype.h>
#include <strings.h>

/* options read only during the solve or at the end of the run */
static PetscBool ReadLate(const char name[])
{
  static const char *const late[] = {"_view", "view_", "converged_reason", "mat_mumps_", "mat_superlu", "mat_cholmod_", "mat_umfpack_", "mat_strumpack_", "log", "malloc", "memory_", "objects_dump", "options_", "info", "history", "check_pointer_intensity", "fp_trap", "error_output_", NULL};
  for (PetscInt i = 0; late[i]; i++)
    if (strstr(name, late[i])) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* options PETSc reads only in PetscFinalize */
static PetscBool ReadAtFinalize(const char name[])
{
  static const char *const fin[] = {"options_left", "options_view", "log_view", "log_summary", "log_trace", "log_all", "log_mpe", "log_perfstubs", "malloc_dump", "malloc_view", "malloc_debug", "malloc_test", "memory_view", "objects_dump", "saws_options", NULL};
  for (PetscInt i = 0; fin[i]; i++)
    if (!strncmp(name, fin[i], strlen(fin[i]))) return PETSC_TRUE;
  return PETSC_FALSE;
}

/* edit distance, for the suggestion */
static PetscInt Distance(const char *a, const char *b)
{
  const size_t na = strlen(a), nb = strlen(b);
  PetscInt     row[256], d = (PetscInt)PetscMax(na, nb);

  if (nb >= 256) return d;
  for (size_t j = 0; j <= nb; j++) row[j] = (PetscInt)j;
  for (size_t i = 1; i <= na; i++) {
    PetscInt diag = row[0];
    row[0]        = (PetscInt)i;
    for (size_t j = 1; j <= nb; j++) {
      const PetscInt up = row[j];
      row[j]            = PetscMin(PetscMin(row[j] + 1, row[j - 1] + 1), diag + (a[i - 1] == b[j - 1] ? 0 : 1));
      diag              = up;
    }
  }
  return row[nb];
}

/* the solver paths a run did not take, and the prefixes of their equivalents on the path it took (a NULL-terminated
   pair of lists, PhlexOptionsSetPathRenames) */
static const char *const *rename_from, *const *rename_to;

/*@C
  PhlexOptionsSetPathRenames - prefixes of solver options whose equivalents on the path the run takes have other
  prefixes (-fieldsplit_1_bordered_* of the field split against -reduced_bordered_* of SNES phlexreduced): an unused
  option with one is answered with its equivalent, when the run reads that. The lists are NULL-terminated and must
  outlive the check (static arrays).

  Not collective
@*/
PetscErrorCode PhlexOptionsSetPathRenames(const char *const from[], const char *const to[])
{
  PetscFunctionBeginUser;
  rename_from = from;
  rename_to   = to;
  PetscFunctionReturn(0);
}

/* the valid name nearest to name (NULL when nothing is close: more than a third of the name differs) */
static const char *Nearest(const char name[], PetscInt n, char *const valid[])
{
  const char *best  = NULL;
  PetscInt    dbest = (PetscInt)strlen(name) / 3 + 1;

  for (PetscInt i = 0; i < n; i++) {
    const PetscInt d = Distance(name, valid[i]);
    if (d < dbest) {
      dbest = d;
      best  = valid[i];
    }
  }
  return best;
}

/* the options given that were read are valid names too (those of solver blocks read only when set up, e.g.) */
static PetscErrorCode AddUsedNames(PetscInt *n, char ***names)
{
  char *all, *tok, *end;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetAll(NULL, &all));
  for (tok = all; *tok; tok = end) {
    PetscBool used, last;
    while (*tok == ' ') tok++;
    for (end = tok; *end && *end != ' '; end++) {}
    last = *end ? PETSC_FALSE : PETSC_TRUE;
    *end = 0;
    if (tok[0] == '-' && isalpha((unsigned char)tok[1])) {
      PetscCall(PetscOptionsUsed(NULL, tok + 1, &used)); /* the database holds names without the dash */
      if (used) {
        PetscCall(PetscRealloc((*n + 1) * sizeof(char *), names));
        PetscCall(PetscStrallocpy(tok + 1, &(*names)[(*n)++]));
      }
    }
    if (!last) end++;
  }
  PetscCall(PetscFree(all));
  PetscFunctionReturn(0);
}

/* the option was given on the command line (not by a scene or preset file) */
static PetscErrorCode OnCommandLine(const char name[], PetscBool *found)
{
  int    argc;
  char **args;

  PetscFunctionBeginUser;
  *found = PETSC_FALSE;
  PetscCall(PetscGetArgs(&argc, &args));
  for (int i = 1; i < argc && !*found; i++)
    if (args[i][0] == '-' && !strcasecmp(args[i] + 1, name)) *found = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsCheckUnused - an option nobody read is an error when it was given on the command line or is near a
  valid option (a misspelling; the nearest is suggested). One that a scene or preset file gives for another
  configuration (the other analysis, another time stepper, another kind of body) and that is near no valid option
  gets a warning. Options that are read only while solving are left to PhlexOptionsWarnUnused.

  Collective

  Input Parameters:
+ comm   - the run's communicator
. reread - reads every option of the run once more (called only when an option is unused, to collect the valid
           names for the suggestion)
- ctx    - its context
@*/
PetscErrorCode PhlexOptionsCheckUnused(MPI_Comm comm, PetscErrorCode (*reread)(void *), void *ctx)
{
  PetscInt  n, nunused = 0, nbad = 0, nvalid = 0;
  char    **names, **values, **valid = NULL;
  char      message[4096] = "";
  size_t    len;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < n; i++)
    if (!ReadLate(names[i])) nunused++;
  if (nunused) {
    if (reread) {
      PetscErrorCode ierr;
      PetscCall(PhlexHelpCaptureBegin());
      ierr = (*reread)(ctx);
      PetscCall(PhlexHelpCaptureEnd(&nvalid, &valid)); /* stdout and -help restored even if the reread failed */
      PetscCall(ierr);
    }
    PetscCall(AddUsedNames(&nvalid, &valid));
  }
  for (PetscInt i = 0; i < n; i++) {
    const char *near = NULL, *value = values[i] ? values[i] : "";
    PetscBool   given;
    if (ReadLate(names[i])) continue;
    for (PetscInt k = 0; rename_from && rename_from[k] && !near; k++) {
      /* the same option on the path the run takes, if it reads it */
      const size_t nf = strlen(rename_from[k]);
      char         equivalent[256];
      if (strncasecmp(names[i], rename_from[k], nf)) continue;
      PetscCall(PetscSNPrintf(equivalent, sizeof(equivalent), "%s%s", rename_to[k], names[i] + nf));
      for (PetscInt v = 0; v < nvalid && !near; v++)
        if (!strcasecmp(valid[v], equivalent)) near = valid[v];
    }
    if (!near) near = Nearest(names[i], nvalid, valid);
    PetscCall(OnCommandLine(names[i], &given));
    if (!given && !near) {
      char      option[256];
      PetscBool set;
      /* said once: marked as used, so that the end of the run does not repeat it */
      PetscCall(PetscSNPrintf(option, sizeof(option), "-%s", names[i]));
      PetscCall(PetscOptionsHasName(NULL, NULL, option, &set));
      PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s (from the scene or solver preset) is not used by this run: it is for another analysis, time stepper or kind of body\n", names[i], value));
      continue;
    }
    nbad++;
    PetscCall(PetscStrlen(message, &len));
    if (near) PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s: did you mean -%s?", names[i], value, near));
    else PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s: no option of this run is near it", names[i], value));
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < nvalid; i++) PetscCall(PetscFree(valid[i]));
  PetscCall(PetscFree(valid));
  PetscCheck(!nbad, comm, PETSC_ERR_USER_INPUT, "%" PetscInt_FMT " option%s not used by this run (misspelt, or for another kind of body, joint or analysis; -help lists the valid ones):%s", nbad, nbad == 1 ? " is" : "s are", message);
  PetscFunctionReturn(0);
}

/* the option name (without '-') starts with one of the NULL-terminated prefixes, case-insensitively as PETSc compares
   option names (PETSc 3.18's PetscStrbeginswith looks for the last occurrence: "fieldsplit_0_fieldsplit_..." would
   not match "fieldsplit_") */
static PetscBool HasPrefix(const char name[], const char *const prefixes[])
{
  for (PetscInt k = 0; prefixes[k]; k++)
    if (!strncasecmp(name, prefixes[k], strlen(prefixes[k]))) return PETSC_TRUE;
  return PETSC_FALSE;
}

/*@C
  PhlexOptionsCommandLineHasPrefix - whether the command line gives an option that starts with one of the
  NULL-terminated prefixes

  Not Collective
@*/
PetscErrorCode PhlexOptionsCommandLineHasPrefix(const char *const prefixes[], PetscBool *found)
{
  int    argc;
  char **args;

  PetscFunctionBeginUser;
  *found = PETSC_FALSE;
  PetscCall(PetscGetArgs(&argc, &args));
  for (int i = 1; i < argc && !*found; i++)
    if (args[i][0] == '-' && HasPrefix(args[i] + 1, prefixes)) *found = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsSetUsedFromFile - marks as read the options of an options file (a solver preset) that start with one of
  the NULL-terminated prefixes and are not on the command line: a preset configures two solver paths, and the one this
  run does not take is not the user's mistake (the same options from the command line, a scene or PETSC_OPTIONS are
  still checked)

  Not Collective
@*/
PetscErrorCode PhlexOptionsSetUsedFromFile(const char file[], const char *const prefixes[])
{
  FILE *f;
  char  line[1024];

  PetscFunctionBeginUser;
  if (!file || !file[0]) PetscFunctionReturn(0);
  f = fopen(file, "r");
  if (!f) PetscFunctionReturn(0); /* read when the preset was inserted; nothing to mark */
  while (fgets(line, sizeof(line), f)) {
    char     *name = line, *end;
    PetscBool given, set;
    while (*name == ' ' || *name == '\t') name++;
    if (name[0] != '-') continue;
    name++;
    for (end = name; *end && !isspace((unsigned char)*end) && *end != '#'; end++) {}
    *end = 0;
    if (!HasPrefix(name, prefixes)) continue;
    PetscCall(OnCommandLine(name, &given));
    if (given) continue;
    name[-1] = '-';
    PetscCall(PetscOptionsHasName(NULL, NULL, name - 1, &set)); /* a query marks the option as read */
  }
  fclose(f);
  PetscFunctionReturn(0);
}

/* the value of an option as the database holds it, without marking it as read (PetscOptionsGetString would): found
   in the text of PetscOptionsGetAll; "" if absent */
static PetscErrorCode CurrentValue(const char name[], char value[], size_t len)
{
  char  *all, *tok, *end;
  size_t n;

  PetscFunctionBeginUser;
  value[0] = 0;
  PetscCall(PetscStrlen(name, &n));
  PetscCall(PetscOptionsGetAll(NULL, &all));
  for (tok = all; *tok; tok = end) {
    while (*tok == ' ') tok++;
    for (end = tok; *end && *end != ' '; end++) {}
    if (tok[0] == '-' && (size_t)(end - tok - 1) == n && !strncasecmp(tok + 1, name, n)) {
      char *v = end, *ve;
      while (*v == ' ') v++;
      for (ve = v; *ve && *ve != ' '; ve++) {}
      if (*v != '-' || isdigit((unsigned char)v[1])) PetscCall(PetscStrncpy(value, v, PetscMin(len, (size_t)(ve - v) + 1)));
      else value[0] = 0;
    }
  }
  PetscCall(PetscFree(all));
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsSetUsedOverridden - marks as read a solver preset's factorization settings (-<prefix>pc_factor_*) of a
  preconditioner whose type (-<prefix>pc_type) a scene or another options file changed: with PC redundant or an
  iterative solver in place of the preset's Cholesky, the preset's factorization package is not the user's mistake.
  Neither the type itself nor any option typed on the command line is marked: those are still checked.

  Not Collective
@*/
PetscErrorCode PhlexOptionsSetUsedOverridden(const char file[])
{
  FILE *f;
  char  line[1024];

  PetscFunctionBeginUser;
  if (!file || !file[0]) PetscFunctionReturn(0);
  f = fopen(file, "r");
  if (!f) PetscFunctionReturn(0);
  while (fgets(line, sizeof(line), f)) {
    char     *name = line, *end, *value, *suffix, option[256], now[256];
    PetscBool set, given;
    while (*name == ' ' || *name == '\t') name++;
    if (name[0] != '-') continue;
    for (end = name; *end && !isspace((unsigned char)*end) && *end != '#'; end++) {}
    if (!*end) continue;
    *end = 0;
    for (value = end + 1; *value == ' ' || *value == '\t'; value++) {}
    for (end = value; *end && !isspace((unsigned char)*end) && *end != '#'; end++) {}
    *end   = 0;
    suffix = strstr(name, "pc_type");
    if (!suffix || strcmp(suffix, "pc_type") || !value[0]) continue;
    PetscCall(CurrentValue(name + 1, now, sizeof(now)));
    if (!now[0] || !strcasecmp(now, value)) continue;
    /* the type was changed: the preset's -<prefix>pc_factor_* of this prefix are the other solver's */
    *suffix = 0;
    {
      FILE *g = fopen(file, "r");
      char  other[1024];
      if (!g) continue;
      PetscCall(PetscSNPrintf(option, sizeof(option), "%spc_factor_", name));
      while (fgets(other, sizeof(other), g)) {
        char *o = other, *oe;
        while (*o == ' ' || *o == '\t') o++;
        if (strncasecmp(o, option, strlen(option))) continue;
        for (oe = o; *oe && !isspace((unsigned char)*oe) && *oe != '#'; oe++) {}
        *oe = 0;
        PetscCall(OnCommandLine(o + 1, &given));
        if (given) continue;
        PetscCall(PetscOptionsHasName(NULL, NULL, o, &set)); /* a query marks the option as read */
      }
      fclose(g);
    }
  }
  fclose(f);
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsWarnUnused - at the end of a run, a warning for every option that was never read

  Collective
@*/
PetscErrorCode PhlexOptionsWarnUnused(MPI_Comm comm)
{
  PetscInt n;
  char   **names, **values;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < n; i++)
    if (!ReadAtFinalize(names[i])) PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s was never used (misspelt?)\n", names[i], values[i] ? values[i] : ""));
  PetscCall(PetscOptionsLeftRestore(NULL, &n, &names, &values));
  PetscFunctionReturn(0);
}
