/* bin/phlex -help: the usage, then every option the scene reads (with its value, default and unit), as clean text,
   and the run ends before the analysis. PETSc prints the options of each PetscOptionsBegin block when -help is in
   the database; phlex strips -help from the command line (so that PETSc does not print its own banner and the
   options of every PETSc program), sets it after initialisation, and filters what goes to stdout (PETSc's
   PetscVFPrintf, through which every PETSc print passes): one line per option, "<value; default d>" instead of
   "<now v : formerly d>", no bytes that are not printable and an empty value for -dm_plex_boundary_label (PETSc
   3.18 prints an uninitialised buffer as its value), no repeated option line, no man-page reference ("(TSSetType)").
   "-help solvers" also sets the scene up and reads the solver objects' options (TS, SNES, KSP, PC, EPS, ST), still
   without a step.
   The same filter collects the names of the valid options for the unused-option check (capture mode). */
#include <phlex_impl.h>
#include <ctype.h>

static PhlexHelpMode help_mode = PHLEX_HELP_NONE;
static PetscBool     capturing; /* collecting option names (PhlexHelpCaptureBegin), printing nothing */
static PetscBool     capture_had_help;
static PetscBool     bool_line; /* the line being printed is PETSc 3.18's bool option line, "<default : value>" */
static char         *pending; /* the current line of stdout, built from several printf calls */
static size_t        npending, maxpending;
static char        **lines; /* help: the option lines printed so far (a repeated one is skipped); capture: names */
static char          boundary_head[512]; /* a -dm_plex_boundary_label line whose garbage value held a newline: its start, up to '<' */
static int           boundary_dropped;   /* the lines of its garbage dropped so far */
static PetscBool     separator_held;     /* a "-----" line, printed unless the title after it is a viewer's */
static char          viewer_name[256];   /* a viewer option (PETSc's lines of its viewer types): one line for it, */
static char          viewer_line[512];   /* printed unless the option's own line follows */
static PetscInt      nlines, maxlines;
static PetscErrorCode (*vfprintf_default)(FILE *, const char[], va_list);

const char PhlexUsage[] = "Usage: bin/phlex -options_file <scene>.yaml [options]\n"
                          "       mpiexec -n <ranks> bin/phlex -options_file <scene>.yaml [options]\n"
                          "\n"
                          "phlex simulates flexible multibody systems of 3D elastic bodies in port-Hamiltonian form:\n"
                          "the scene file (YAML, options/*.yaml) describes the bodies, joints, loads and the analysis\n"
                          "(transient, modes of each body, or the linearized assembly); any option of the scene can be given or\n"
                          "overridden on the command line.\n"
                          "\n"
                          "  -help                  the options this scene reads, with value, default and unit; no run\n"
                          "  -help solvers          also the solver options (TS, SNES, KSP, PC, EPS, ST) after set-up\n"
                          "  -solver_options_file   a solver preset of options/solver/ (exact, exact_serial, exact_krylov,\n"
                          "                         ldlt, iterative, bordered, bordered_serial, bordered_iterative, rigid);\n"
                          "                         the default follows the scene and the process count (the fastest:\n"
                          "                         CHOLMOD on one process, MUMPS on several; the run's summary names it;\n"
                          "                         modes: -options_file options/solver/modes_fast.opts)\n"
                          "  -output_dir <dir>      where the results go (CSV series, HDF5/XDMF fields for ParaView)\n"
                          "  -progress 0            no progress lines; -progress_interval <s> sets their interval\n"
                          "\n"
                          "Exit codes: 0 success, 1 internal error, 2 bad input, 3 numerical failure, 4 output not written,\n"
                          "5 a -expect_* self-check failed, 130/143 interrupted by SIGINT/SIGTERM. README.md has the\n"
                          "option tables, the scenes and how to plot and render the results.\n";

static PetscBool IsHelpArg(const char *a)
{
  return (!strcmp(a, "-help") || !strcmp(a, "--help") || !strcmp(a, "-h")) ? PETSC_TRUE : PETSC_FALSE;
}

/*@C
  PhlexHelpParseArgs - finds -help, --help or -h (optionally followed by "solvers") in the command line and removes
  them, before PETSc is initialised

  Not collective
@*/
PhlexHelpMode PhlexHelpParseArgs(int *argc, char **argv)
{
  int n = 1;

  for (int i = 1; i < *argc; i++) {
    if (IsHelpArg(argv[i])) {
      if (help_mode == PHLEX_HELP_NONE) help_mode = PHLEX_HELP_OPTIONS;
      if (i + 1 < *argc && !strcmp(argv[i + 1], "solvers")) {
        help_mode = PHLEX_HELP_SOLVERS;
        i++;
      } else if (i + 1 < *argc && (!strcmp(argv[i + 1], "intro") || !strcmp(argv[i + 1], "options"))) i++;
      continue;
    }
    argv[n++] = argv[i];
  }
  *argc   = n;
  argv[n] = NULL;
  return help_mode;
}

/*@C
  PhlexHelpGetMode - PHLEX_HELP_NONE (a run), PHLEX_HELP_OPTIONS (-help: read the options, set nothing up) or
  PHLEX_HELP_SOLVERS (-help solvers: set up, read the solvers' options, take no step)
@*/
PhlexHelpMode PhlexHelpGetMode(void)
{
  return help_mode;
}

/* the value field of an option line, "<now v : formerly d>" or "<v : d>", as "<v>" or "<v; default d>" */
static PetscErrorCode RewriteValue(const char *line, char *out, size_t len)
{
  const char *open = strchr(line, '<'), *close = open ? strchr(open, '>') : NULL, *sep = NULL, *def = NULL, *now;
  size_t      nnow, ndef;

  PetscFunctionBeginUser;
  if (open && close) {
    now = open + 1;
    if (!strncmp(now, "now ", 4)) now += 4;
    for (const char *c = now; c + 2 < close && !sep; c++)
      if (!strncmp(c, " : ", 3)) sep = c;
    if (sep) {
      def = sep + 3;
      if (!strncmp(def, "formerly ", 9)) def += 9;
    }
  }
  if (!sep || def > close) {
    PetscCall(PetscStrncpy(out, line, len));
    PetscFunctionReturn(0);
  }
  nnow = (size_t)(sep - now);
  ndef = (size_t)(close - def);
  if (bool_line) {
    /* PETSc 3.18 prints a bool's default first and its value second (other types: value, then default) */
    const char *t = now;
    size_t      nt = nnow;
    now = def, nnow = ndef, def = t, ndef = nt;
  }
  if (nnow == ndef && !strncmp(now, def, nnow)) PetscCall(PetscSNPrintf(out, len, "%.*s<%.*s>%s", (int)(open - line), line, (int)nnow, now, close + 1));
  else PetscCall(PetscSNPrintf(out, len, "%.*s<%.*s; default %.*s>%s", (int)(open - line), line, (int)nnow, now, (int)ndef, def, close + 1));
  PetscFunctionReturn(0);
}

static PetscErrorCode Remember(const char *text, size_t n)
{
  PetscFunctionBeginUser;
  if (nlines == maxlines) {
    maxlines = PetscMax(64, 2 * maxlines);
    PetscCall(PetscRealloc(maxlines * sizeof(char *), &lines));
  }
  PetscCall(PetscMalloc1(n + 1, &lines[nlines]));
  PetscCall(PetscStrncpy(lines[nlines], text, n + 1));
  nlines++;
  PetscFunctionReturn(0);
}

static PetscErrorCode WriteOut(const char format[], ...)
{
  va_list args;

  PetscFunctionBeginUser;
  va_start(args, format);
  PetscCall((*vfprintf_default)(stdout, format, args));
  va_end(args);
  PetscFunctionReturn(0);
}

/* one complete line of stdout. Capture: the name of an option line ("  -name ..."), nothing printed. Help: the
   line cleaned and rewritten, printed unless it is an option line printed before. */
static PetscErrorCode EmitLine(const char *line)
{
  const char *c = line;
  char       *clean, *out, *end;
  size_t      n = 0, len = strlen(line) + 64;
  PetscBool   option;

  PetscFunctionBeginUser;
  if (!capturing) {
    /* -dm_plex_boundary_label's garbage value (below) may hold newlines: the line is cut, and its pieces come as lines
       of their own. They are dropped up to the one that ends the option's line, which is printed with an empty value */
    const char *tail = strstr(line, ">: Label to mark the mesh boundary"), *head = strstr(line, "dm_plex_boundary_label <");
    char        rebuilt[1024];
    if (boundary_head[0]) {
      /* its garbage spans a few lines at most; should the tail's text ever change, the held line is given back with
         an empty value after 8 lines, and nothing else of the help is lost beyond those */
      if (!tail && ++boundary_dropped <= 8) PetscFunctionReturn(0);
      PetscCall(PetscSNPrintf(rebuilt, sizeof(rebuilt), "%s%s", boundary_head, tail ? tail : ">\n"));
      boundary_dropped = 0;
      boundary_head[0] = 0;
      PetscCall(EmitLine(rebuilt));
      if (tail) PetscFunctionReturn(0); /* else this line is the help's own again: printed below */
    }
    if (head && !tail) {
      PetscCall(PetscSNPrintf(boundary_head, sizeof(boundary_head), "%.*s", (int)(head - line) + 24, line));
      boundary_dropped = 0;
      PetscFunctionReturn(0);
    }
  }
  if (!capturing) {
    /* a viewer option (PetscOptionsViewer, PETSc's monitors) comes with PETSc's lines of every viewer type under a
       title of its own ("Viewer (-ts_monitor) options:", "  -ts_monitor ascii[:[filename]...]: ...", binary, draw,
       socket, saws): one line instead, in the block it belongs to, and none when the option has a line of its own */
    static const char *const types[] = {" ascii[", " binary[", " draw[", " socket[", " saws[", " hdf5[", " vtk[", " glvis[", " matlab[", NULL};
    const char              *name = line + strspn(line, " "), *end;
    size_t                   nname;
    PetscBool                viewer_type = PETSC_FALSE;
    nname = name[0] == '-' ? strcspn(name, " <:\n") : 0;
    end   = name + nname;
    for (PetscInt t = 0; nname && types[t] && !viewer_type; t++)
      if (!strncmp(end, types[t], strlen(types[t]))) viewer_type = PETSC_TRUE;
    if (viewer_type) {
      if (!viewer_name[0]) {
        PetscCall(PetscSNPrintf(viewer_name, sizeof(viewer_name), "%.*s", (int)nname, name));
        PetscCall(PetscSNPrintf(viewer_line, sizeof(viewer_line), "  %s <viewer>: a PETSc viewer: ascii[:file[:format[:append]]] (stdout without a file), binary[:file], draw, socket, saws\n", viewer_name));
      }
      PetscFunctionReturn(0);
    }
    if (viewer_name[0]) {
      const PetscBool own = (nname == strlen(viewer_name) && !strncmp(name, viewer_name, nname)) ? PETSC_TRUE : PETSC_FALSE;
      char            held[512];
      PetscCall(PetscStrncpy(held, viewer_line, sizeof(held)));
      viewer_name[0] = 0;
      if (!own) PetscCall(EmitLine(held));
    }
    if (!strcmp(line, "----------------------------------------\n") && !separator_held) {
      separator_held = PETSC_TRUE;
      PetscFunctionReturn(0);
    }
    if (separator_held) {
      separator_held = PETSC_FALSE;
      if (!strncmp(line, "Viewer (-", 9) && strstr(line, ") options:")) PetscFunctionReturn(0);
      PetscCall(WriteOut("----------------------------------------\n"));
    }
  }
  while (*c == ' ') c++;
  option = (c > line && c[0] == '-' && isalpha((unsigned char)c[1])) ? PETSC_TRUE : PETSC_FALSE;
  if (capturing) {
    if (option) PetscCall(Remember(c + 1, strcspn(c + 1, " <:\n")));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscMalloc2(len, &clean, len, &out));
  for (c = line; *c; c++)
    if ((*c >= 0x20 && *c < 0x7f) || *c == '\t' || *c == '\n') clean[n++] = *c;
  clean[n] = 0;
  if (option && strstr(clean, "dm_plex_boundary_label <now ")) {
    /* PETSc 3.18 prints this option's uninitialised value buffer as its value (now and formerly): whatever an earlier
       call left on the stack, text of another option's line included; unless given, its value is empty */
    const char *name  = clean + strspn(clean, " ");
    char       *open  = strchr(clean, '<'), *close = strstr(clean, ">: Label to mark the mesh boundary"), opt[256];
    PetscBool   given = PETSC_FALSE;
    PetscCall(PetscSNPrintf(opt, sizeof(opt), "%.*s", (int)strcspn(name, " <"), name));
    PetscCall(PetscOptionsHasName(NULL, NULL, opt, &given));
    if (!given && open && close > open) memmove(open + 1, close, strlen(close) + 1);
  }
  PetscCall(RewriteValue(clean, out, len));
  /* the man-page reference at the end of an option line, " (PhlexFlexibleSetFromOptions)", means nothing to a user */
  n   = strlen(out);
  end = n >= 3 && !strcmp(out + n - 2, ")\n") ? out + n - 3 : NULL;
  while (end && end > out && (isalnum((unsigned char)*end) || *end == '_')) end--;
  if (option && end && end > out + 1 && end[0] == '(' && end[-1] == ' ') PetscCall(PetscStrcpy(end - 1, "\n"));
  for (PetscInt i = 0; option && i < nlines; i++)
    if (!strcmp(lines[i], out)) {
      PetscCall(PetscFree2(clean, out));
      PetscFunctionReturn(0);
    }
  if (option) PetscCall(Remember(out, strlen(out)));
  PetscCall(WriteOut("%s", out));
  PetscCall(PetscFree2(clean, out));
  PetscFunctionReturn(0);
}

/* PETSc's PetscVFPrintf in help and capture modes: stdout goes line by line through EmitLine */
static PetscErrorCode FilterVFPrintf(FILE *fd, const char format[], va_list args)
{
  char   piece[8192];
  size_t len;

  PetscFunctionBeginUser;
  if (fd != stdout) {
    PetscCall((*vfprintf_default)(fd, format, args));
    PetscFunctionReturn(0);
  }
  PetscCall(PetscVSNPrintf(piece, sizeof(piece), format, &len, args));
  len = strlen(piece);
  if (strstr(format, ": <%s : %s> ")) bool_line = PETSC_TRUE; /* PetscOptionsBool's line (one call, one line) */
  if (npending + len + 1 > maxpending) {
    maxpending = PetscMax(2 * maxpending, npending + len + 256);
    PetscCall(PetscRealloc(maxpending, &pending));
  }
  for (size_t i = 0; i < len; i++) {
    pending[npending++] = piece[i];
    if (piece[i] == '\n') {
      pending[npending] = 0;
      PetscCall(EmitLine(pending));
      npending  = 0;
      bool_line = PETSC_FALSE;
    }
  }
  PetscFunctionReturn(0);
}

static void FilterPush(void)
{
  if (!vfprintf_default) vfprintf_default = PetscVFPrintf;
  PetscVFPrintf = FilterVFPrintf;
}

static PetscErrorCode FilterPop(void)
{
  PetscFunctionBeginUser;
  if (npending) {
    pending[npending] = 0;
    PetscCall(EmitLine(pending));
  }
  npending = 0;
  if (!capturing && viewer_name[0]) {
    char held[512];
    PetscCall(PetscStrncpy(held, viewer_line, sizeof(held)));
    viewer_name[0] = 0;
    PetscCall(EmitLine(held));
  }
  if (!capturing && separator_held) {
    separator_held = PETSC_FALSE;
    PetscCall(WriteOut("----------------------------------------\n"));
  }
  separator_held = PETSC_FALSE;
  viewer_name[0] = 0;
  PetscVFPrintf = vfprintf_default;
  for (PetscInt i = 0; i < nlines; i++) PetscCall(PetscFree(lines[i]));
  PetscCall(PetscFree(lines));
  PetscCall(PetscFree(pending));
  nlines = maxlines = 0;
  maxpending        = 0;
  PetscFunctionReturn(0);
}

/*@C
  PhlexHelpCaptureBegin - the options read from now on are collected (their names), nothing is printed; options
  blocks already read print again, but not those of PETSc objects already set from options (use new objects)

  Not collective
@*/
PetscErrorCode PhlexHelpCaptureBegin(void)
{
  PetscFunctionBeginUser;
  PetscCheck(help_mode == PHLEX_HELP_NONE, PETSC_COMM_SELF, PETSC_ERR_ORDER, "option names are not collected in help mode");
  PetscCall(PetscOptionsHasName(NULL, NULL, "-help", &capture_had_help));
  if (!capture_had_help) PetscCall(PetscOptionsSetValue(NULL, "-help", NULL));
  /* PETSc prints each options block once per run: forget which were printed, so that they print again */
  PetscCall(PetscOptionsHelpPrintedDestroy(&PetscOptionsHelpPrintedSingleton));
  capturing = PETSC_TRUE;
  FilterPush();
  PetscFunctionReturn(0);
}

/*@C
  PhlexHelpCaptureEnd - the names collected since PhlexHelpCaptureBegin (the caller frees each and the array)

  Not collective
@*/
PetscErrorCode PhlexHelpCaptureEnd(PetscInt *n, char ***names)
{
  PetscFunctionBeginUser;
  if (!capture_had_help) PetscCall(PetscOptionsClearValue(NULL, "-help"));
  PetscCall(PetscOptionsHelpPrintedDestroy(&PetscOptionsHelpPrintedSingleton));
  *n     = nlines;
  *names = lines;
  lines  = NULL;
  nlines = maxlines = 0;
  PetscCall(FilterPop());
  capturing = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexHelpActivate - in help mode, after PETSc is initialised: -help into the options database, stdout filtered,
  the usage printed

  Collective
@*/
PetscErrorCode PhlexHelpActivate(MPI_Comm comm)
{
  PetscFunctionBeginUser;
  if (help_mode == PHLEX_HELP_NONE) PetscFunctionReturn(0);
  PetscCall(PetscOptionsSetValue(NULL, "-help", NULL));
  FilterPush();
  PetscCall(PetscPrintf(comm, "%s", PhlexUsage));
  PetscFunctionReturn(0);
}

/*@C
  PhlexHelpEnd - prints the closing lines of the help and restores stdout

  Collective

  Input Parameters:
+ comm      - the communicator
. catalogue - no scene was given: the options of one body of each type and of every analysis were listed
- analysis  - the scene's analysis (its options alone were listed)
@*/
PetscErrorCode PhlexHelpEnd(MPI_Comm comm, PetscBool catalogue, const char analysis[])
{
  PetscFunctionBeginUser;
  if (help_mode == PHLEX_HELP_NONE) PetscFunctionReturn(0);
  PetscCall(PetscPrintf(comm, "----------------------------------------\n"));
  if (catalogue) PetscCall(PetscPrintf(comm, "No scene was given: the options above are those of one body of each type (flexible, rigid, lumped)\nand one driven joint, with example values where an option has no default (materials, masses, ports,\njoint), and those of every analysis; with -options_file <scene>.yaml they are the scene's, with its values.\n"));
  else {
    const char *const all[] = {"transient", "modes", "linearized"};
    char              others[64] = "";
    for (int i = 0; i < 3; i++) {
      size_t n;
      if (!strcmp(all[i], analysis)) continue;
      PetscCall(PetscStrlen(others, &n));
      PetscCall(PetscSNPrintf(others + n, sizeof(others) - n, "%s%s", n ? "|" : "", all[i]));
    }
    PetscCall(PetscPrintf(comm, "The analysis options above are those of this scene's analysis (-analysis %s); add -analysis %s for\nanother's.\n", analysis, others));
  }
  if (help_mode == PHLEX_HELP_OPTIONS) PetscCall(PetscPrintf(comm, "Solver options (-ts_*, -snes_*, -ksp_*, -pc_*, -modes_eps_*, -modes_st_*, -linearized_eps_*, -linearized_st_*): add\n\"-help solvers\" to list those this scene reads (the scene is then set up, no step is taken); the presets are in options/solver/.\n"));
  PetscCall(PetscPrintf(comm, "Nothing was run (help only).\n"));
  PetscCall(FilterPop());
  /* PETSc's finalisation prints the options it reads (-log_view, ...) while -help is set */
  PetscCall(PetscOptionsClearValue(NULL, "-help"));
  PetscFunctionReturn(0);
}
