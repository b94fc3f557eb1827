/* Unused options, judged as soon as every option of the run has been read (before the first time step, before the
   eigensolver): a misspelt option is an error naming the nearest valid one, an option phlex reads in no
   configuration an error naming its file and line, an option of another configuration a warning saying which (an
   error when typed on the command line). The valid names are collected only then, by reading the run's options once
   more with PETSc's help printer turned into a name collector (help.c); those of every configuration by reading a
   catalogue scene likewise, in an options database of its own. Options that PETSc reads only while solving or at the
   end (viewers, converged reasons, factor packages' settings, logging) cannot be judged before the run: they are
   checked at its end, with a warning. */
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

/* PETSc's own options of the whole program that a run may well not read (its graphics, the citations written at the
   end, the MPI solver server): never judged, neither here nor at the end (the others PETSc reads at initialisation,
   or are judged at the end: ReadLate) */
static PetscBool PetscGlobal(const char name[])
{
  static const char *const global[] = {"citations", "nox", "display", "x_virtual", "geometry", "draw_", "mpi_linear_solver_server", "viewfromoptions", "version", "help", NULL};
  for (PetscInt i = 0; global[i]; i++)
    if (!strncasecmp(name, global[i], strlen(global[i]))) return PETSC_TRUE;
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

/* the value of an option as the database holds it, without marking it as read (PetscOptionsGetString would): found
   in the text of PetscOptionsGetAll, the words up to the next option (a value may hold spaces: "7800 kg/m^3"); ""
   if absent or given without a value */
static PetscErrorCode CurrentValueFound(const char name[], char value[], size_t len, PetscBool *found)
{
  char  *all, *tok, *end;
  size_t n;

  PetscFunctionBeginUser;
  value[0] = 0;
  *found   = PETSC_FALSE;
  PetscCall(PetscStrlen(name, &n));
  PetscCall(PetscOptionsGetAll(NULL, &all));
  for (tok = all; *tok; tok = end) {
    while (*tok == ' ') tok++;
    for (end = tok; *end && *end != ' '; end++) {}
    if (tok[0] == '-' && isalpha((unsigned char)tok[1]) && (size_t)(end - tok - 1) == n && !strncasecmp(tok + 1, name, n)) {
      char *v = end, *ve = end;
      *found  = PETSC_TRUE;
      while (*v == ' ') v++;
      for (char *w = v; *w && !(w[0] == '-' && isalpha((unsigned char)w[1]) && (w == v || w[-1] == ' '));) {
        while (*w && *w != ' ') w++;
        ve = w;
        while (*w == ' ') w++;
      }
      if (ve > v) PetscCall(PetscStrncpy(value, v, PetscMin(len, (size_t)(ve - v) + 1)));
      else value[0] = 0;
    }
  }
  PetscCall(PetscFree(all));
  PetscFunctionReturn(0);
}

static PetscErrorCode CurrentValue(const char name[], char value[], size_t len)
{
  PetscBool found;

  PetscFunctionBeginUser;
  PetscCall(CurrentValueFound(name, value, len, &found));
  PetscFunctionReturn(0);
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

/* ------------------------------------------------------------------------------------------------------------------
   Where an unused option belongs. The names phlex reads in any configuration come from a catalogue: a scene of one
   body of each kind (each with the option that switches on a conditional block: a body force, a floating frame's
   wrench, material regions) and three joints (plain, driven, prescribed), read under each analysis and each implicit
   integrator, in an options database of its own, with PETSc's help printer as the name collector (as for the names
   of the run). A body's or joint's names are kept as what follows body<k>_ or joint<k>_, with its port or region
   name replaced by '*'. */

enum { ENTRY_GLOBAL, ENTRY_BODY, ENTRY_JOINT };

typedef struct {
  char    *pattern; /* the name; a body's or joint's: what follows body<k>_ or joint<k>_, '*' for a port or region */
  int      kind;
  unsigned analyses, tstypes, variants; /* bit masks: the runs and the catalogue's bodies or joints that read it */
} Entry;

typedef struct {
  PetscInt n, max;
  Entry   *e;
} Catalogue;

static const char *const cat_analyses[] = {"transient", "modes", "linearized"};
static const char *const cat_tstypes[]  = {"theta", "cn", "beuler", "bdf", "alpha"}; /* the implicit integrators */

/* the catalogue's bodies: the kind, and the option (after body<k>_) that switches its extra block on */
static const struct {
  const char *kind, *trigger;
} cat_bodies[] = {
  {"flexible", NULL},
  {"flexible", "body_force"},
  {"flexible", "frame_force"},
  {"flexible", "regions"},
  {"rigid",    NULL        },
  {"rigid",    "frame_force"},
  {"lumped",   NULL        },
  {"reduced",  NULL        },
};
#define NCATBODIES ((PetscInt)(sizeof(cat_bodies) / sizeof(cat_bodies[0])))
enum { CAT_JOINT_PLAIN, CAT_JOINT_DRIVEN, CAT_JOINT_PRESCRIBED, NCATJOINTS };

/* the catalogue scene (example values where an option has no default; "xport", "xregion" stand for any name) */
static PetscErrorCode CatalogueScene(PetscOptions db)
{
  char name[64];

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsSetValue(db, "-num_bodies", "8"));
  PetscCall(PetscOptionsSetValue(db, "-num_joints", "3"));
  for (PetscInt k = 0; k < NCATBODIES; k++) {
    const char *kind = cat_bodies[k].kind, *trigger = cat_bodies[k].trigger;
#define SET(suffix, value) \
  do { \
    PetscCall(PetscSNPrintf(name, sizeof(name), "-body%" PetscInt_FMT "_%s", k, suffix)); \
    PetscCall(PetscOptionsSetValue(db, name, value)); \
  } while (0)
    SET("type", kind);
    if (!strcmp(kind, "flexible") || !strcmp(kind, "reduced")) {
      SET("dm_plex_filename", "catalogue.msh");
      SET("ports", "xport");
      if (trigger && !strcmp(trigger, "regions")) {
        SET("regions", "xregion");
        SET("region_xregion_youngs_modulus", "2.1e11");
        SET("region_xregion_poissons_ratio", "0.3");
        SET("region_xregion_density", "7800");
      } else {
        SET("youngs_modulus", "2.1e11");
        SET("poissons_ratio", "0.3");
        SET("density", "7800");
      }
      if (trigger && !strcmp(trigger, "body_force")) SET("body_force", "1,0,0");
      if (trigger && !strcmp(trigger, "frame_force")) {
        SET("motion", "floating");
        SET("frame_force", "1,0,0");
      }
      if (!strcmp(kind, "reduced")) SET("frame_patch", "xpatch");
    } else if (!strcmp(kind, "rigid")) {
      SET("mass", "1");
      SET("inertia", "1,1,1");
      SET("ports", "xport");
      SET("port_xport_position", "0,0,0");
      if (trigger) SET("frame_force", "1,0,0");
    } else {
      SET("mass", "1");
      SET("position", "0,0,0");
    }
#undef SET
  }
  PetscCall(PetscOptionsSetValue(db, "-joint0_type", "revolute"));
  PetscCall(PetscOptionsSetValue(db, "-joint0_ports", "body4:xport,ground"));
  PetscCall(PetscOptionsSetValue(db, "-joint0_axis", "0,0,1"));
  PetscCall(PetscOptionsSetValue(db, "-joint1_type", "revolute"));
  PetscCall(PetscOptionsSetValue(db, "-joint1_ports", "body5:xport,ground"));
  PetscCall(PetscOptionsSetValue(db, "-joint1_axis", "0,0,1"));
  PetscCall(PetscOptionsSetValue(db, "-joint1_drive_velocity", "1"));
  PetscCall(PetscOptionsSetValue(db, "-joint2_type", "prescribed"));
  PetscCall(PetscOptionsSetValue(db, "-joint2_ports", "body4:xport"));
  PetscCall(PetscOptionsSetValue(db, "-joint2_velocity", "0,0,0"));
  PetscFunctionReturn(0);
}

/* "body<k>_rest" (or joint): the index and where the rest starts; -1 if the name has no such prefix */
static PetscInt IndexedPrefix(const char name[], const char word[], const char **rest)
{
  const size_t n = strlen(word);
  PetscInt     k = 0;
  const char  *c;

  if (strncasecmp(name, word, n) || !isdigit((unsigned char)name[n])) return -1;
  for (c = name + n; isdigit((unsigned char)*c); c++) k = 10 * k + (*c - '0');
  if (*c != '_' || c - (name + n) > 6) return -1;
  *rest = c + 1;
  return k;
}

/* the catalogue pattern of a collected name: a body's or joint's rest with "port_xport_" and "region_xregion_" made
   "port_*_", "region_*_" */
static void PatternOf(const char rest[], char out[], size_t len)
{
  const char *const from[] = {"port_xport_", "region_xregion_"}, *const to[] = {"port_*_", "region_*_"};
  size_t            o = 0;

  for (const char *c = rest; *c && o + 1 < len;) {
    PetscBool replaced = PETSC_FALSE;
    for (int r = 0; r < 2 && !replaced; r++)
      if (!strncasecmp(c, from[r], strlen(from[r])) && o + strlen(to[r]) + 1 < len) {
        memcpy(out + o, to[r], strlen(to[r]));
        o += strlen(to[r]);
        c += strlen(from[r]);
        replaced = PETSC_TRUE;
      }
    if (!replaced) out[o++] = *c++;
  }
  out[o] = 0;
}

static PetscErrorCode CatalogueAdd(Catalogue *cat, const char name[], PetscInt analysis, PetscInt tstype)
{
  const char *rest = NULL;
  char        pattern[256];
  int         kind = ENTRY_GLOBAL;
  PetscInt    k;
  Entry      *e = NULL;

  PetscFunctionBeginUser;
  if ((k = IndexedPrefix(name, "body", &rest)) >= 0 && k < NCATBODIES) kind = ENTRY_BODY;
  else if ((k = IndexedPrefix(name, "joint", &rest)) >= 0 && k < NCATJOINTS) kind = ENTRY_JOINT;
  if (kind == ENTRY_GLOBAL) PetscCall(PetscStrncpy(pattern, name, sizeof(pattern)));
  else PatternOf(rest, pattern, sizeof(pattern));
  for (PetscInt i = 0; i < cat->n && !e; i++)
    if (cat->e[i].kind == kind && !strcasecmp(cat->e[i].pattern, pattern)) e = &cat->e[i];
  if (!e) {
    if (cat->n == cat->max) {
      cat->max = PetscMax(256, 2 * cat->max);
      PetscCall(PetscRealloc(cat->max * sizeof(Entry), &cat->e));
    }
    e = &cat->e[cat->n++];
    PetscCall(PetscMemzero(e, sizeof(*e)));
    PetscCall(PetscStrallocpy(pattern, &e->pattern));
    e->kind = kind;
  }
  e->analyses |= 1u << analysis;
  if (tstype >= 0) e->tstypes |= 1u << tstype;
  if (kind != ENTRY_GLOBAL) e->variants |= 1u << k;
  PetscFunctionReturn(0);
}

/* the names one reread collects in an options database of its own (the run's database is not touched: nothing of it
   is marked as read); an error of the reread (the catalogue's values should raise none) ends it quietly */
static PetscErrorCode ReadNamesIn(MPI_Comm comm, PetscOptions db, PetscErrorCode (*reread)(void *), PetscInt *n, char ***names)
{
  MPI_Comm c = comm;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsPush(db));
  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  PetscCall(PhlexHelpCaptureBegin());
  (void)(*reread)(&c);
  PetscCall(PhlexHelpCaptureEnd(n, names));
  PetscCall(PetscPopErrorHandler());
  PetscCall(PetscOptionsPop());
  PetscFunctionReturn(0);
}

/* phlex's options read only while a scene is set up or solved, which the rereads do not reach: the analyses (bits of
   cat_analyses) that read them */
static const struct {
  const char *name;
  unsigned    analyses;
} cat_setup[] = {
  {"openblas_coretype",               7}, /* before the scene (blas.c) */
  {"phlex_jacobian_aij",              5}, /* the system's Jacobian (transient, linearized) */
  {"snes_phlexcondensed_balance",     1}, /* SNES phlexcondensed */
  {"snes_phlexcondensed_guess_order", 1},
  {"snes_phlexreduced_forcing",       1}, /* SNES phlexreduced */
  {"snes_phlexreduced_velocity_rtol", 1},
  {"reduced_bordered_block_cg",       1}, /* PC phlexbordered, at its set-up (SNES phlexreduced's, the field split's) */
  {"reduced_bordered_block_cg_check", 1},
  {"fieldsplit_1_bordered_block_cg",  1},
  {"fieldsplit_1_bordered_block_cg_check", 1},
  {"reduced_bordered_block_cg_pc_block",     1},
  {"fieldsplit_1_bordered_block_cg_pc_block", 1},
};

static PetscErrorCode CatalogueBuild(MPI_Comm comm, Catalogue *cat)
{
  PetscFunctionBeginUser;
  cat->n = cat->max = 0;
  cat->e            = NULL;
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt t = 0; t < (a ? 1 : (PetscInt)(sizeof(cat_tstypes) / sizeof(cat_tstypes[0]))); t++) {
      PetscOptions db;
      PetscInt     n;
      char       **names;
      PetscErrorCode (*reread)(void *) = a == 0 ? PhlexTransientRereadOptions : (a == 1 ? PhlexModesRereadOptions : PhlexLinearizedRereadOptions);
      PetscCall(PetscOptionsCreate(&db));
      PetscCall(CatalogueScene(db));
      PetscCall(PetscOptionsSetValue(db, "-analysis", cat_analyses[a]));
      if (!a) PetscCall(PetscOptionsSetValue(db, "-ts_type", cat_tstypes[t]));
      PetscCall(ReadNamesIn(comm, db, reread, &n, &names));
      PetscCall(PetscOptionsDestroy(&db));
      for (PetscInt i = 0; i < n; i++) {
        PetscCall(CatalogueAdd(cat, names[i], a, a ? -1 : t));
        PetscCall(PetscFree(names[i]));
      }
      PetscCall(PetscFree(names));
    }
  for (size_t i = 0; i < sizeof(cat_setup) / sizeof(cat_setup[0]); i++)
    for (PetscInt a = 0; a < 3; a++)
      if (cat_setup[i].analyses & (1u << a)) PetscCall(CatalogueAdd(cat, cat_setup[i].name, a, -1));
  PetscFunctionReturn(0);
}

static PetscErrorCode CatalogueDestroy(Catalogue *cat)
{
  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < cat->n; i++) PetscCall(PetscFree(cat->e[i].pattern));
  PetscCall(PetscFree(cat->e));
  cat->n = cat->max = 0;
  PetscFunctionReturn(0);
}

/* a glob with one '*' at most (one or more characters), case-insensitively; *star gets what the '*' matched */
static PetscBool Glob(const char pattern[], const char name[], char star[], size_t len)
{
  const char *s = strchr(pattern, '*');
  size_t      np = strlen(pattern), nn = strlen(name), head, tail;

  if (!s) return strcasecmp(pattern, name) ? PETSC_FALSE : PETSC_TRUE;
  head = (size_t)(s - pattern);
  tail = np - head - 1;
  if (nn < head + tail + 1 || strncasecmp(pattern, name, head) || strcasecmp(s + 1, name + nn - tail)) return PETSC_FALSE;
  snprintf(star, len, "%.*s", (int)(nn - head - tail), name + head);
  return PETSC_TRUE;
}

/* whether a comma-separated list holds a word */
static PetscBool ListHas(const char list[], const char word[])
{
  const size_t n = strlen(word);

  for (const char *c = list; c && *c;) {
    const char  *e = strchr(c, ',');
    const size_t m = e ? (size_t)(e - c) : strlen(c);
    if (m == n && !strncasecmp(c, word, n)) return PETSC_TRUE;
    c = e ? e + 1 : NULL;
  }
  return PETSC_FALSE;
}

/* how the masks' values read in a message: "theta or cn", "rigid, lumped or reduced" */
static void JoinValues(const char *const values[], PetscInt n, unsigned mask, char out[], size_t len)
{
  PetscInt count = 0, total = 0;
  size_t   o     = 0;

  out[0] = 0;
  for (PetscInt i = 0; i < n; i++)
    if (mask & (1u << i)) total++;
  for (PetscInt i = 0; i < n && o < len; i++)
    if (mask & (1u << i)) {
      PetscBool seen = PETSC_FALSE;
      for (PetscInt j = 0; j < i; j++)
        if ((mask & (1u << j)) && !strcmp(values[j], values[i])) seen = PETSC_TRUE;
      if (seen) {
        total--;
        continue;
      }
      count++;
      o += (size_t)snprintf(out + o, len - o, "%s%s", count == 1 ? "" : (count == total ? " or " : ", "), values[i]);
    }
}

/* where an unused option belongs, for its message: *where says it (empty: nowhere in phlex); *option and *values name
   the configuration option that would read it, if one does (silent when the command line changed it from the value
   a scene gave); *mistake: a port or region name that is none of the body's (an error, not another configuration) */
typedef struct {
  char      where[512];
  char      option[64];   /* without '-' */
  char      fallback[32]; /* its default */
  char      values[8][32];
  PetscInt  nvalues;
  PetscBool known, mistake;
} Belonging;

static PetscErrorCode Classify(const Catalogue *cat, const char name[], Belonging *b)
{
  const char *rest = NULL;
  PetscInt    k;
  int         kind = ENTRY_GLOBAL;
  unsigned    analyses = 0, tstypes = 0, variants = 0;
  char        star[128] = "", value[256], buf[256];
  PetscBool   found, starred = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(b, sizeof(*b)));
  if ((k = IndexedPrefix(name, "body", &rest)) >= 0) kind = ENTRY_BODY;
  else if ((k = IndexedPrefix(name, "joint", &rest)) >= 0) kind = ENTRY_JOINT;
  for (PetscInt i = 0; i < cat->n; i++) {
    char s[128] = "";
    if (cat->e[i].kind != kind || !Glob(cat->e[i].pattern, kind == ENTRY_GLOBAL ? name : rest, s, sizeof(s))) continue;
    analyses |= cat->e[i].analyses;
    tstypes |= cat->e[i].tstypes;
    variants |= cat->e[i].variants;
    if (s[0] && !starred) {
      PetscCall(PetscStrncpy(star, s, sizeof(star)));
      starred = PETSC_TRUE;
    }
  }
  if (!analyses) PetscFunctionReturn(0); /* phlex reads no such option */
  b->known = PETSC_TRUE;
  if (kind == ENTRY_GLOBAL) {
    char current[64] = "transient", list[256];
    PetscCall(CurrentValueFound("analysis", value, sizeof(value), &found));
    if (found && value[0]) PetscCall(PetscStrncpy(current, value, sizeof(current)));
    {
      PetscInt a;
      for (a = 0; a < 3 && strcasecmp(current, cat_analyses[a]); a++) {}
      if (a < 3 && !(analyses & (1u << a))) {
        JoinValues(cat_analyses, 3, analyses, list, sizeof(list));
        PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read by -analysis %s, and this run's analysis is %s", list, current));
        PetscCall(PetscStrcpy(b->option, "analysis"));
        PetscCall(PetscStrcpy(b->fallback, "transient"));
        for (PetscInt i = 0; i < 3; i++)
          if (analyses & (1u << i)) PetscCall(PetscStrncpy(b->values[b->nvalues++], cat_analyses[i], sizeof(b->values[0])));
        PetscFunctionReturn(0);
      }
    }
    if (tstypes && (analyses & 1u)) {
      const PetscInt nt = (PetscInt)(sizeof(cat_tstypes) / sizeof(cat_tstypes[0]));
      char           ts[64] = "theta";
      PetscInt       t;
      PetscCall(CurrentValueFound("ts_type", value, sizeof(value), &found));
      if (found && value[0]) PetscCall(PetscStrncpy(ts, value, sizeof(ts)));
      for (t = 0; t < nt && strcasecmp(ts, cat_tstypes[t]); t++) {}
      if (t == nt || !(tstypes & (1u << t))) {
        JoinValues(cat_tstypes, nt, tstypes, list, sizeof(list));
        if (strcasecmp(current, "transient")) PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read by -analysis transient with -ts_type %s, and this run's analysis is %s", list, current));
        else PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read with -ts_type %s, and this run uses -ts_type %s", list, ts));
        PetscCall(PetscStrcpy(b->option, "ts_type"));
        PetscCall(PetscStrcpy(b->fallback, "theta"));
        for (PetscInt i = 0; i < nt; i++)
          if (tstypes & (1u << i)) PetscCall(PetscStrncpy(b->values[b->nvalues++], cat_tstypes[i], sizeof(b->values[0])));
        PetscFunctionReturn(0);
      }
    }
    PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is an option of phlex that this scene does not read (it takes effect with other settings; bin/phlex -help without a scene lists it)"));
    PetscFunctionReturn(0);
  }
  {
    const char *word = kind == ENTRY_BODY ? "body" : "joint", *count = kind == ENTRY_BODY ? "num_bodies" : "num_joints";
    char        who[160], type[64];
    PetscInt    n = kind == ENTRY_BODY ? 1 : 0;
    PetscCall(CurrentValueFound(count, value, sizeof(value), &found));
    if (found && value[0]) n = (PetscInt)atoi(value);
    if (k >= n) {
      PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is an option of %s%" PetscInt_FMT ", and the scene has %" PetscInt_FMT " %s%s (-%s %" PetscInt_FMT ")", word, k, n, kind == ENTRY_BODY ? "bod" : "joint", kind == ENTRY_BODY ? (n == 1 ? "y" : "ies") : (n == 1 ? "" : "s"), count, n));
      PetscFunctionReturn(0);
    }
    PetscCall(PetscSNPrintf(buf, sizeof(buf), "%s%" PetscInt_FMT "_name", word, k));
    PetscCall(CurrentValueFound(buf, value, sizeof(value), &found));
    if (found && value[0]) PetscCall(PetscSNPrintf(who, sizeof(who), "%s%" PetscInt_FMT " '%s'", word, k, value));
    else PetscCall(PetscSNPrintf(who, sizeof(who), "%s%" PetscInt_FMT, word, k));
    PetscCall(PetscSNPrintf(buf, sizeof(buf), "%s%" PetscInt_FMT "_type", word, k));
    PetscCall(CurrentValueFound(buf, value, sizeof(value), &found));
    PetscCall(PetscStrncpy(type, found && value[0] ? value : (kind == ENTRY_BODY ? "flexible" : "(none)"), sizeof(type)));
    if (kind == ENTRY_BODY) {
      const char *kinds[NCATBODIES];
      unsigned    ofkind = 0;
      char        list[256];
      for (PetscInt v = 0; v < NCATBODIES; v++) {
        kinds[v] = cat_bodies[v].kind;
        if ((variants & (1u << v)) && !strcasecmp(type, cat_bodies[v].kind)) ofkind |= 1u << v;
      }
      if (!ofkind) {
        JoinValues(kinds, NCATBODIES, variants, list, sizeof(list));
        PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read by a body of type %s (-%s%" PetscInt_FMT "_type), and %s is %s", list, word, k, who, type));
        PetscCall(PetscSNPrintf(b->option, sizeof(b->option), "%s%" PetscInt_FMT "_type", word, k));
        PetscCall(PetscStrcpy(b->fallback, "flexible"));
        for (PetscInt v = 0; v < NCATBODIES && b->nvalues < 8; v++)
          if (variants & (1u << v)) {
            PetscBool seen = PETSC_FALSE;
            for (PetscInt i = 0; i < b->nvalues; i++)
              if (!strcmp(b->values[i], cat_bodies[v].kind)) seen = PETSC_TRUE;
            if (!seen) PetscCall(PetscStrncpy(b->values[b->nvalues++], cat_bodies[v].kind, sizeof(b->values[0])));
          }
        PetscFunctionReturn(0);
      }
      if (starred) {
        /* a port's or region's option: the name must be one of the body's */
        const PetscBool region = strncasecmp(rest, "region_", 7) ? PETSC_FALSE : PETSC_TRUE;
        PetscCall(PetscSNPrintf(buf, sizeof(buf), "body%" PetscInt_FMT "_%s", k, region ? "regions" : "ports"));
        PetscCall(CurrentValueFound(buf, value, sizeof(value), &found));
        if (!ListHas(found ? value : "", star)) {
          if (found && value[0]) PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "%s is none of the %ss of %s (-%s %s)", star, region ? "region" : "port", who, buf, value));
          else PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "%s lists no %ss (-%s): %s is none of them", who, region ? "region" : "port", buf, star));
          b->mistake = PETSC_TRUE;
          PetscFunctionReturn(0);
        }
      }
      for (PetscInt v = 0; v < NCATBODIES; v++)
        if ((ofkind & (1u << v)) && !cat_bodies[v].trigger) ofkind = 0; /* read by the plain body of its kind */
      for (PetscInt v = 0; v < NCATBODIES && ofkind; v++)
        if (ofkind & (1u << v)) {
          PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read with -%s%" PetscInt_FMT "_%s%s, which %s does not have", word, k, cat_bodies[v].trigger, !strcmp(cat_bodies[v].trigger, "frame_force") && !strcmp(type, "flexible") ? " (a floating body)" : "", who));
          PetscFunctionReturn(0);
        }
    } else {
      PetscBool driven;
      PetscCall(PetscSNPrintf(buf, sizeof(buf), "joint%" PetscInt_FMT "_drive_velocity", k));
      PetscCall(CurrentValueFound(buf, value, sizeof(value), &driven));
      if (variants == (1u << CAT_JOINT_PRESCRIBED) && strcasecmp(type, "prescribed")) {
        PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read by -joint%" PetscInt_FMT "_type prescribed, and %s is %s", k, who, type));
        PetscCall(PetscSNPrintf(b->option, sizeof(b->option), "joint%" PetscInt_FMT "_type", k));
        PetscCall(PetscStrcpy(b->values[b->nvalues++], "prescribed"));
        PetscFunctionReturn(0);
      }
      if (variants == (1u << CAT_JOINT_DRIVEN) && !driven) {
        PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is read when a joint is driven (-joint%" PetscInt_FMT "_drive_velocity), and %s is not", k, who));
        PetscFunctionReturn(0);
      }
    }
    PetscCall(PetscSNPrintf(b->where, sizeof(b->where), "it is an option of phlex that %s does not read here (it takes effect with other settings; bin/phlex -help without a scene lists it)", who));
  }
  PetscFunctionReturn(0);
}

/* the PETSc/SLEPc object whose options the name has (a prefix such as body0_ or modes_ before it): "KSP", ...; NULL
   if none */
static const char *PetscFamily(const char name[])
{
  static const char *const families[][2] = {
    {"ts_",  "TS"   },
    {"snes_", "SNES" },
    {"ksp_", "KSP"  },
    {"pc_",  "PC"   },
    {"mat_", "Mat"  },
    {"vec_", "Vec"  },
    {"dm_",  "DM"   },
    {"petscspace_", "PetscSpace"},
    {"petscdualspace_", "PetscDualSpace"},
    {"petscfe_", "PetscFE"},
    {"petscpartitioner_", "PetscPartitioner"},
    {"petscds_", "PetscDS"},
    {"eps_", "EPS"  },
    {"st_",  "ST"   },
    {"bv_",  "BV"   },
    {"ds_",  "DS"   },
    {"rg_",  "RG"   },
    {"fn_",  "FN"   },
    {"pep_", "PEP"  },
    {"nep_", "NEP"  },
    {"svd_", "SVD"  },
    {"fieldsplit_", "PC fieldsplit"},
    {"sub_", "PC sub-solver"},
    {"mg_",  "PC mg"},
    {"convest_", "PetscConvEst"},
    {"dmsnes_", "DMSNES"},
    {"dmts_", "DMTS"},
    {"draw_", "PetscDraw"},
    {"viewer_", "PetscViewer"},
    {"sf_",  "PetscSF"},
    {"tao_", "Tao"  },
  };
  for (const char *c = name; *c; c++) {
    if (c != name && c[-1] != '_') continue;
    for (size_t f = 0; f < sizeof(families) / sizeof(families[0]); f++)
      if (!strncasecmp(c, families[f][0], strlen(families[f][0]))) return families[f][1];
  }
  return NULL;
}

/* where a scene or preset gave the option: " (file, line n)" */
static PetscErrorCode OriginText(const char name[], char out[], size_t len)
{
  const char *file;
  int         line;
  PetscBool   preset;

  PetscFunctionBeginUser;
  PetscCall(PhlexOptionsOrigin(name, &file, &line, NULL, &preset));
  if (file) PetscCall(PetscSNPrintf(out, len, " (%s%s, line %d)", preset ? "solver preset " : "", file, line));
  else PetscCall(PetscSNPrintf(out, len, " (from PETSC_OPTIONS or an options file)"));
  PetscFunctionReturn(0);
}

/* the valid name nearest to name among the run's and the catalogue's (a body's or joint's with the name's index) */
static PetscErrorCode NearestKnown(const char name[], PetscInt nvalid, char *const valid[], const Catalogue *cat, char near[], size_t len)
{
  const char *rest = NULL, *best = Nearest(name, nvalid, valid);
  PetscInt    dbest = best ? Distance(name, best) : (PetscInt)strlen(name) / 3 + 1, k;
  int         kind = ENTRY_GLOBAL;
  char        prefix[32] = "";

  PetscFunctionBeginUser;
  near[0] = 0;
  if (best) PetscCall(PetscStrncpy(near, best, len));
  if ((k = IndexedPrefix(name, "body", &rest)) >= 0) kind = ENTRY_BODY;
  else if ((k = IndexedPrefix(name, "joint", &rest)) >= 0) kind = ENTRY_JOINT;
  if (kind != ENTRY_GLOBAL) PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%s%" PetscInt_FMT "_", kind == ENTRY_BODY ? "body" : "joint", k));
  for (PetscInt i = 0; cat && i < cat->n; i++) {
    PetscInt d;
    if (cat->e[i].kind != kind || strchr(cat->e[i].pattern, '*')) continue;
    d = Distance(kind == ENTRY_GLOBAL ? name : rest, cat->e[i].pattern);
    if (d < dbest) {
      dbest = d;
      PetscCall(PetscSNPrintf(near, len, "%s%s", prefix, cat->e[i].pattern));
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsCheckUnused - every option nobody read, judged once every option of the run has been read:

  an option near a valid one (a misspelling) is an error naming the nearest; one that phlex reads in another
  configuration (another analysis, integrator, kind of body, a driven or prescribed joint, a body force, ...) is a
  warning saying which, or an error when typed on the command line; one phlex reads nowhere and that is no PETSc
  solver option is an error naming the file and line that gave it. An option of a configuration that a scene chose
  and the command line changed (the scene's -ts_theta_theta under -ts_type bdf typed on the command line) is dropped
  without a word (-info says it). Options that are read only while solving are left to PhlexOptionsWarnUnused.

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
  char      message[8192] = "";
  size_t    len;
  Catalogue cat = {0, 0, NULL};

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < n; i++)
    if (!ReadLate(names[i]) && !PetscGlobal(names[i])) nunused++;
  if (nunused) {
    if (reread) {
      PetscErrorCode ierr;
      PetscCall(PhlexHelpCaptureBegin());
      ierr = (*reread)(ctx);
      PetscCall(PhlexHelpCaptureEnd(&nvalid, &valid)); /* stdout and -help restored even if the reread failed */
      PetscCall(ierr);
    }
    PetscCall(AddUsedNames(&nvalid, &valid));
    PetscCall(CatalogueBuild(comm, &cat));
  }
  for (PetscInt i = 0; i < n; i++) {
    const char *value = values[i] ? values[i] : "";
    char        near[256] = "", origin[PETSC_MAX_PATH_LEN + 64] = "", option[256];
    PetscBool   given, set;
    Belonging   b;
    if (ReadLate(names[i]) || PetscGlobal(names[i])) continue;
    for (PetscInt k = 0; rename_from && rename_from[k] && !near[0]; k++) {
      /* the same option on the path the run takes, if it reads it */
      const size_t nf = strlen(rename_from[k]);
      char         equivalent[256];
      if (strncasecmp(names[i], rename_from[k], nf)) continue;
      PetscCall(PetscSNPrintf(equivalent, sizeof(equivalent), "%s%s", rename_to[k], names[i] + nf));
      for (PetscInt v = 0; v < nvalid && !near[0]; v++)
        if (!strcasecmp(valid[v], equivalent)) PetscCall(PetscStrncpy(near, valid[v], sizeof(near)));
    }
    PetscCall(OnCommandLine(names[i], &given));
    if (!given) PetscCall(OriginText(names[i], origin, sizeof(origin)));
    PetscCall(PetscSNPrintf(option, sizeof(option), "-%s", names[i]));
    b.known = b.mistake = PETSC_FALSE;
    if (!near[0]) PetscCall(Classify(&cat, names[i], &b));
    if (!near[0] && b.known && !b.mistake) {
      /* an option of another configuration */
      if (!given && b.option[0]) {
        /* of a configuration that a scene chose (or left at its default) and the command line changed: dropped
           without a word */
        const char *file, *was;
        PetscBool   changed, preset, silent = PETSC_FALSE;
        PetscCall(OnCommandLine(b.option, &changed));
        PetscCall(PhlexOptionsOrigin(b.option, &file, NULL, &was, &preset));
        if (!file || preset) was = b.fallback;
        for (PetscInt v = 0; changed && was && was[0] && v < b.nvalues; v++)
          if (!strcasecmp(was, b.values[v])) silent = PETSC_TRUE;
        if (silent) {
          PetscCall(PetscInfo(NULL, "option -%s %s%s is for -%s %s, which the command line changed: not used\n", names[i], value, origin, b.option, was));
          PetscCall(PetscOptionsHasName(NULL, NULL, option, &set)); /* marked as used */
          continue;
        }
      }
      if (!given) {
        /* said once: marked as used, so that the end of the run does not repeat it */
        PetscCall(PetscOptionsHasName(NULL, NULL, option, &set));
        PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s%s is not used: %s\n", names[i], value, origin, b.where));
        continue;
      }
    }
    if (!near[0] && (!b.known || b.mistake)) PetscCall(NearestKnown(names[i], nvalid, valid, &cat, near, sizeof(near)));
    if (!near[0] && !b.known && PetscFamily(names[i]) && !given) {
      /* a PETSc or SLEPc solver option that no solver of this run reads (another type or prefix may) */
      PetscCall(PetscOptionsHasName(NULL, NULL, option, &set));
      PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s%s is not used: no %s object of this run reads it (another type, or another solver's prefix, may)\n", names[i], value, origin, PetscFamily(names[i])));
      continue;
    }
    nbad++;
    PetscCall(PetscStrlen(message, &len));
    if (near[0]) PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s%s: did you mean -%s?", names[i], value, origin, near));
    else if (b.known) PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s%s: %s", names[i], value, origin, b.where));
    else if (PetscFamily(names[i])) PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s%s: no %s object of this run reads it, and no option of this run is near it", names[i], value, origin, PetscFamily(names[i])));
    else PetscCall(PetscSNPrintf(message + len, sizeof(message) - len, "\n  -%s %s%s: phlex has no such option, and none is near it", names[i], value, origin));
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < nvalid; i++) PetscCall(PetscFree(valid[i]));
  PetscCall(PetscFree(valid));
  PetscCall(CatalogueDestroy(&cat));
  PetscCheck(!nbad, comm, PETSC_ERR_USER_INPUT, "%" PetscInt_FMT " option%s not used by this run (misspelt, unknown to phlex, or for another configuration; -help lists the valid ones):%s", nbad, nbad == 1 ? " is" : "s are", message);
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
  PhlexOptionsWarnUnused - at the end of a run, a warning for every option that was never read: one typed on the
  command line may be misspelt; one that a scene or preset file gives passed PhlexOptionsCheckUnused, so phlex knows
  it, and it is for another analysis or configuration (a scene's -solver_options_file or -ts_* options in a
  linearised or reduce run): said with its file and line, not as a misspelling

  Collective
@*/
PetscErrorCode PhlexOptionsWarnUnused(MPI_Comm comm)
{
  PetscInt  n;
  char    **names, **values;
  PetscBool given;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsLeftGet(NULL, &n, &names, &values));
  for (PetscInt i = 0; i < n; i++) {
    const char *value                                 = values[i] ? values[i] : "";
    char        origin[PETSC_MAX_PATH_LEN + 64] = "";
    if (ReadAtFinalize(names[i]) || PetscGlobal(names[i])) continue;
    PetscCall(OnCommandLine(names[i], &given));
    if (given) {
      PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s was never used (misspelt?)\n", names[i], value));
      continue;
    }
    PetscCall(OriginText(names[i], origin, sizeof(origin)));
    PetscCall(PetscFPrintf(comm, PETSC_STDERR, "phlex: warning: option -%s %s%s is not used: this run does not read it (another analysis or configuration does)\n", names[i], value, origin));
  }
  PetscCall(PetscOptionsLeftRestore(NULL, &n, &names, &values));
  PetscFunctionReturn(0);
}
