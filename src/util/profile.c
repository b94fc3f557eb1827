/* Time profiles f(t) that multiply an input amplitude: constant, ramp, sine, piecewise-linear table (given inline, or
   read from a column of a CSV file: a measured load, a controller's output), with what a table is outside its points. */
#include <phlex_impl.h>
#include <errno.h>

const char *const PhlexProfileTypes[]     = {"constant", "ramp", "sine", "table", "PhlexProfileType", "PHLEX_PROFILE_", NULL};
const char *const PhlexExtrapolations[] = {"hold", "zero", "error", "PhlexExtrapolation", "PHLEX_EXTRAPOLATE_", NULL};

/* Every profile alive: the transient analysis checks the time range of all of them at once before its first step
   (PhlexProfileCheckRangeAll), whichever load, drive or force element owns them, without each kind of owner handing
   its own out. */
static PhlexProfile *alive;
static PetscInt      nalive, maxalive;

static PetscErrorCode AliveAdd(PhlexProfile p)
{
  PetscFunctionBeginUser;
  if (nalive == maxalive) {
    PhlexProfile  *more;
    const PetscInt n = PetscMax(16, 2 * maxalive);
    PetscCall(PetscMalloc1(n, &more));
    if (nalive) PetscCall(PetscArraycpy(more, alive, nalive));
    PetscCall(PetscFree(alive));
    alive    = more;
    maxalive = n;
  }
  alive[nalive++] = p;
  PetscFunctionReturn(0);
}

static PetscErrorCode AliveRemove(PhlexProfile p)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < nalive; k++)
    if (alive[k] == p) {
      alive[k] = alive[--nalive];
      break;
    }
  if (!nalive) { /* the last one gone: nothing left allocated (-malloc_dump) */
    PetscCall(PetscFree(alive));
    maxalive = 0;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileCreate - creates a time profile (default: constant 1)

  Collective

  Input Parameters:
+ comm   - communicator
. prefix - options prefix, e.g. "body0_port_tip_"; options are read as -<prefix>profile_type ...
- what   - description used in error messages, e.g. "body cantilever, port tip"

  Output Parameter:
. profile - the profile
@*/
PetscErrorCode PhlexProfileCreate(MPI_Comm comm, const char prefix[], const char what[], PhlexProfile *profile)
{
  PhlexProfile p;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&p));
  p->comm       = comm;
  p->type       = PHLEX_PROFILE_CONSTANT;
  p->scale      = 1.0;
  p->ramp_time  = 0.0;
  p->start_time = 0.0;
  p->frequency  = 0.0;
  p->phase      = 0.0;
  PetscCall(PetscStrncpy(p->prefix, prefix ? prefix : "", sizeof(p->prefix)));
  PetscCall(PetscStrncpy(p->what, what ? what : "", sizeof(p->what)));
  PetscCall(AliveAdd(p));
  *profile = p;
  PetscFunctionReturn(0);
}

#define PHLEX_CSV_LINE    65536 /* the longest line of a series file */
#define PHLEX_CSV_COLUMNS 1024  /* its most columns */

/* a field trimmed of blanks and of the quotes around it (in place) */
static char *Trim(char *c)
{
  char *e;

  while (*c == ' ' || *c == '\t') c++;
  e = c + strlen(c);
  while (e > c && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\n' || e[-1] == '\r')) *--e = 0;
  if (e - c >= 2 && c[0] == '"' && e[-1] == '"') {
    e[-1] = 0;
    c++;
  }
  return c;
}

/* the fields of a line, cut in place: separated by commas, or by blanks in a line without a comma (the two-column files
   "t f" read before) */
static PetscInt SplitFields(char *line, char *fields[], PetscInt max)
{
  PetscInt n = 0;
  char    *c = line;

  if (strchr(line, ',')) {
    for (;;) {
      char *next = strchr(c, ',');
      if (next) *next = 0;
      if (n < max) fields[n] = Trim(c);
      n++;
      if (!next) break;
      c = next + 1;
    }
  } else {
    c = Trim(c);
    while (*c) {
      if (n < max) fields[n] = c;
      n++;
      while (*c && *c != ' ' && *c != '\t') c++;
      if (*c) *c++ = 0;
      while (*c == ' ' || *c == '\t') c++;
    }
  }
  return n;
}

/* a whole field read as a finite number */
static PetscBool ParseNumber(const char *c, PetscReal *x)
{
  char  *end;
  double v;

  if (!*c) return PETSC_FALSE;
  v = strtod(c, &end);
  if (*end || PetscIsInfOrNanReal((PetscReal)v)) return PETSC_FALSE;
  *x = (PetscReal)v;
  return PETSC_TRUE;
}

/* the 0-based column of f from -profile_column (a header name or a 1-based number; empty: the second of two columns);
   err set on failure */
static void ResolveColumn(PhlexProfile p, const char file[], PetscInt ncol, char *names[], const char spec[], PetscInt *col, char err[], size_t len)
{
  char list[512] = "";

  *col = -1;
  for (PetscInt k = 0; k < ncol && names; k++) {
    size_t have = strlen(list);
    if (have + strlen(names[k]) + 8 >= sizeof(list)) {
      snprintf(list + have, sizeof(list) - have, ", ...");
      break;
    }
    snprintf(list + have, sizeof(list) - have, "%s'%s'", k ? ", " : "", names[k]);
  }
  if (ncol < 2) {
    snprintf(err, len, "%s: the series file '%s' (option -%sprofile_file) has %d column: it needs the time and at least one more", p->what, file, p->prefix, (int)ncol);
    return;
  }
  if (!spec[0]) {
    if (ncol == 2) *col = 1;
    else snprintf(err, len, "%s: the series file '%s' (option -%sprofile_file) has %d columns%s%s%s: choose the one the profile follows with -%sprofile_column <name or number> (the first column is the time)", p->what, file, p->prefix, (int)ncol, names ? " (" : "", list, names ? ")" : "", p->prefix);
    return;
  }
  if (strspn(spec, "0123456789") == strlen(spec)) {
    const long k = strtol(spec, NULL, 10);
    if (k == 1) snprintf(err, len, "%s: -%sprofile_column %s is the time column of '%s': choose a column from 2 to %d", p->what, p->prefix, spec, file, (int)ncol);
    else if (k < 1 || k > ncol) snprintf(err, len, "%s: -%sprofile_column %s: the series file '%s' has %d columns (the first is the time)", p->what, p->prefix, spec, file, (int)ncol);
    else *col = (PetscInt)(k - 1);
    return;
  }
  if (!names) {
    snprintf(err, len, "%s: -%sprofile_column %s names a column, but the series file '%s' has no header line: give the column's number (2 to %d)", p->what, p->prefix, spec, file, (int)ncol);
    return;
  }
  for (PetscInt k = 0; k < ncol; k++)
    if (!strcmp(names[k], spec)) *col = k;
  if (*col == 0) snprintf(err, len, "%s: -%sprofile_column %s is the time column of '%s': choose another of %s", p->what, p->prefix, spec, file, list);
  else if (*col < 0) snprintf(err, len, "%s: -%sprofile_column %s: the series file '%s' has no column of that name (its columns: %s)", p->what, p->prefix, spec, file, list);
}

/* Reads the table of a series file on rank 0 and hands it to every rank: the first column is the time [s], column
   spec (-profile_column) is f; a first line whose first field is not a number is the header naming the columns; blank
   lines and lines starting with '#' are skipped. Errors name the file, the line and the column. */
static PetscErrorCode PhlexProfileReadTableFile(PhlexProfile p, const char file[], const char spec[], PetscInt *n, PetscReal **data)
{
  PetscInt    cap = 64, cnt = 0;
  PetscReal  *buf;
  PetscMPIInt rank;
  PetscInt    nread;
  char        err[PETSC_MAX_PATH_LEN + 1024] = "", desc[sizeof(p->column)] = "";
  int         code = PETSC_ERR_USER_INPUT;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(p->comm, &rank));
  PetscCall(PetscMalloc1(cap, &buf));
  if (rank == 0) {
    FILE *fp = fopen(file, "r");
    if (!fp) {
      snprintf(err, sizeof(err), "%s: cannot open the series file '%s' (option -%sprofile_file): %s", p->what, file, p->prefix, strerror(errno));
      code = PETSC_ERR_FILE_OPEN;
    } else {
      char    *line, *header, **fields, **names = NULL;
      PetscInt lineno = 0, ncol = -1, col = -1, lastline = 0;
      PetscCall(PetscMalloc3(PHLEX_CSV_LINE, &line, PHLEX_CSV_LINE, &header, 2 * PHLEX_CSV_COLUMNS, &fields));
      while (!err[0] && fgets(line, PHLEX_CSV_LINE, fp)) {
        const size_t len = strlen(line);
        const char  *c   = line;
        PetscInt     nf;
        PetscReal    t, f;
        lineno++;
        if (len == PHLEX_CSV_LINE - 1 && line[len - 1] != '\n' && !feof(fp)) {
          snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d: longer than %d characters", p->what, file, p->prefix, (int)lineno, PHLEX_CSV_LINE - 2);
          break;
        }
        while (*c == ' ' || *c == '\t') c++;
        if (*c == '\n' || *c == '\r' || *c == '#' || !*c) continue;
        if (ncol < 0) {
          /* the first line: the header, unless it starts with a number */
          PetscReal x;
          PetscCall(PetscStrcpy(header, line));
          nf = SplitFields(header, fields, PHLEX_CSV_COLUMNS);
          if (nf > PHLEX_CSV_COLUMNS) {
            snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d: more than %d columns", p->what, file, p->prefix, (int)lineno, PHLEX_CSV_COLUMNS);
            break;
          }
          ncol = nf;
          if (!ParseNumber(fields[0], &x)) names = fields;
          ResolveColumn(p, file, ncol, names, spec, &col, err, sizeof(err));
          if (err[0]) break;
          if (names) snprintf(desc, sizeof(desc), "%d ('%s')", (int)(col + 1), names[col]);
          else snprintf(desc, sizeof(desc), "%d", (int)(col + 1));
          if (names) continue;
        }
        nf = SplitFields(line, fields + PHLEX_CSV_COLUMNS, PHLEX_CSV_COLUMNS);
        if (nf != ncol) {
          snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d: %d value%s, but the %s has %d", p->what, file, p->prefix, (int)lineno, (int)nf, nf == 1 ? "" : "s", names ? "header" : "first line", (int)ncol);
          break;
        }
        if (!ParseNumber(fields[PHLEX_CSV_COLUMNS], &t)) {
          snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d, column 1%s%s%s (the time): expected a finite number, got '%s'", p->what, file, p->prefix, (int)lineno, names ? " ('" : "", names ? names[0] : "", names ? "')" : "", fields[PHLEX_CSV_COLUMNS]);
          break;
        }
        if (!ParseNumber(fields[PHLEX_CSV_COLUMNS + col], &f)) {
          snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d, column %s: expected a finite number, got '%s'", p->what, file, p->prefix, (int)lineno, desc, fields[PHLEX_CSV_COLUMNS + col]);
          break;
        }
        if (cnt && t <= buf[cnt - 2]) {
          snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file), line %d: the times must increase strictly; t = %g follows %g (line %d)", p->what, file, p->prefix, (int)lineno, (double)t, (double)buf[cnt - 2], (int)lastline);
          break;
        }
        if (cnt + 2 > cap) {
          PetscReal *nbuf;
          cap *= 2;
          PetscCall(PetscMalloc1(cap, &nbuf));
          PetscCall(PetscArraycpy(nbuf, buf, cnt));
          PetscCall(PetscFree(buf));
          buf = nbuf;
        }
        buf[cnt++] = t;
        buf[cnt++] = f;
        lastline   = lineno;
      }
      if (!err[0] && ferror(fp)) snprintf(err, sizeof(err), "%s: cannot read the series file '%s' (option -%sprofile_file): %s", p->what, file, p->prefix, strerror(errno));
      if (!err[0] && cnt < 4) snprintf(err, sizeof(err), "%s: the series file '%s' (option -%sprofile_file) has %d row%s of values: a table needs at least 2", p->what, file, p->prefix, (int)(cnt / 2), cnt == 2 ? "" : "s");
      fclose(fp);
      PetscCall(PetscFree3(line, header, fields));
    }
  }
  PetscCallMPI(MPI_Bcast(err, sizeof(err), MPI_CHAR, 0, p->comm));
  PetscCallMPI(MPI_Bcast(&code, 1, MPI_INT, 0, p->comm));
  if (err[0]) PetscCall(PetscFree(buf));
  PetscCheck(!err[0], p->comm, code, "%s", err);
  PetscCallMPI(MPI_Bcast(desc, sizeof(desc), MPI_CHAR, 0, p->comm));
  PetscCall(PetscStrncpy(p->column, desc, sizeof(p->column)));
  nread = cnt;
  PetscCallMPI(MPI_Bcast(&nread, 1, MPIU_INT, 0, p->comm));
  if (rank != 0) {
    PetscCall(PetscFree(buf));
    PetscCall(PetscMalloc1(PetscMax(nread, 1), &buf));
  }
  PetscCallMPI(MPI_Bcast(buf, (PetscMPIInt)nread, MPIU_REAL, 0, p->comm));
  *n    = nread;
  *data = buf;
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileSetFromOptions - reads the profile options

  Collective

  Options Database Keys (with the profile's prefix):
+ -profile_type <constant,ramp,sine,table> - shape of f(t)
. -profile_start <s>       - time before which f = 0 [s]
. -profile_ramp_time <s>   - ramp: duration of the linear rise from 0 to 1 [s]
. -profile_frequency <Hz>  - sine: f = sin(2 pi freq (t - start) + phase)
. -profile_phase <rad>     - sine: phase [rad]
. -profile_table t0,f0,... - table: piecewise-linear points (t [s], f [-])
. -profile_file <csv>      - table: the points from a CSV file, time in its first column
. -profile_column <c>      - the file's column f follows: its header name or its number (1: the time)
. -profile_extrapolate <hold,zero,error> - a table outside its points (default: error for a file, hold inline)
- -profile_scale <s>       - factor applied to f [-]

  Notes:
  A table or a file without -profile_type is a table profile.
@*/
PetscErrorCode PhlexProfileSetFromOptions(PhlexProfile p)
{
  PetscReal table[513] = {0};
  PetscInt  ntable = 513; /* 256 points, and room for one more number: a longer table is refused, not cut */
  PetscInt  extrapolate = PHLEX_EXTRAPOLATE_HOLD;
  PetscBool flg_table = PETSC_FALSE, flg_file = PETSC_FALSE, flg_type = PETSC_FALSE, flg_column = PETSC_FALSE, flg_extrapolate = PETSC_FALSE;
  PetscBool flg[5] = {PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE, PETSC_FALSE};
  char      file[PETSC_MAX_PATH_LEN] = "", column[128] = "";
  PetscReal *data = NULL;
  PetscInt  ndata = 0;

  PetscFunctionBeginUser;
  PetscOptionsBegin(p->comm, p->prefix, "Time profile options", NULL);
  PetscCall(PetscOptionsEnum("-profile_type", "Time profile f(t) of the input (a table or a file alone: table)", "PhlexProfileSetFromOptions", PhlexProfileTypes, (PetscEnum)p->type, (PetscEnum *)&p->type, &flg_type));
  PetscCall(PetscOptionsReal("-profile_start", "Time before which the profile is zero [s]", "PhlexProfileSetFromOptions", p->start_time, &p->start_time, &flg[0]));
  PetscCall(PetscOptionsReal("-profile_ramp_time", "Ramp profile: rise time from 0 to 1 [s]", "PhlexProfileSetFromOptions", p->ramp_time, &p->ramp_time, &flg[1]));
  PetscCall(PetscOptionsReal("-profile_frequency", "Sine profile: frequency [Hz]", "PhlexProfileSetFromOptions", p->frequency, &p->frequency, &flg[2]));
  PetscCall(PetscOptionsReal("-profile_phase", "Sine profile: phase [rad]", "PhlexProfileSetFromOptions", p->phase, &p->phase, &flg[3]));
  PetscCall(PetscOptionsReal("-profile_scale", "Factor applied to the profile [-]", "PhlexProfileSetFromOptions", p->scale, &p->scale, &flg[4]));
  PetscCall(PhlexOptionsRealList("-profile_table", "Table profile: points t0,f0,t1,f1,... (t in s)", "PhlexProfileSetFromOptions", table, &ntable, &flg_table, 0));
  PetscCall(PetscOptionsString("-profile_file", "Table profile: a CSV file, the time [s] in its first column, f in another (-profile_column); a header line may name the columns", "PhlexProfileSetFromOptions", file, file, sizeof(file), &flg_file));
  PetscCall(PetscOptionsString("-profile_column", "Table profile from a file: the column f follows, by its header name or its number (1 is the time; default: the second of two columns)", "PhlexProfileSetFromOptions", column, column, sizeof(column), &flg_column));
  PetscCall(PetscOptionsEList("-profile_extrapolate", "Table profile outside its times: hold its end values, zero, or error (a run reaching outside the series is refused before its first step); default: error for a file, hold for -profile_table", "PhlexProfileSetFromOptions", PhlexExtrapolations, 3, PhlexExtrapolations[flg_file ? PHLEX_EXTRAPOLATE_ERROR : PHLEX_EXTRAPOLATE_HOLD], &extrapolate, &flg_extrapolate));
  PetscOptionsEnd();
  p->given = (PetscBool)(flg_type || flg_table || flg_file || flg_column || flg_extrapolate || flg[0] || flg[1] || flg[2] || flg[3] || flg[4]);

  /* points given: a table, unless another shape was asked for */
  if ((flg_table || flg_file) && !flg_type) p->type = PHLEX_PROFILE_TABLE;
  PetscCheck(!(flg_table || flg_file) || p->type == PHLEX_PROFILE_TABLE, p->comm, PETSC_ERR_USER_INPUT, "%s: -%sprofile_%s gives the points of a table profile, but -%sprofile_type is %s", p->what, p->prefix, flg_file ? "file" : "table", p->prefix, PhlexProfileTypes[p->type]);
  PetscCheck(!flg_column || flg_file, p->comm, PETSC_ERR_USER_INPUT, "%s: -%sprofile_column %s chooses a column of a series file: give the file with -%sprofile_file", p->what, p->prefix, column, p->prefix);
  PetscCheck(!flg_extrapolate || p->type == PHLEX_PROFILE_TABLE, p->comm, PETSC_ERR_USER_INPUT, "%s: -%sprofile_extrapolate %s is for a table profile (-%sprofile_table or -%sprofile_file); a %s profile is defined at every time", p->what, p->prefix, PhlexExtrapolations[extrapolate], p->prefix, p->prefix, PhlexProfileTypes[p->type]);
  p->extrapolate = flg_extrapolate ? (PhlexExtrapolation)extrapolate : (flg_file ? PHLEX_EXTRAPOLATE_ERROR : PHLEX_EXTRAPOLATE_HOLD);
  PetscCheck(!PetscIsInfOrNanReal(p->scale), p->comm, PETSC_ERR_USER_INPUT, "%s: -%sprofile_scale must be a finite number, got %g", p->what, p->prefix, (double)p->scale);
  switch (p->type) {
  case PHLEX_PROFILE_RAMP:
    PetscCheck(p->ramp_time > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: ramp profile needs -%sprofile_ramp_time > 0, got %g", p->what, p->prefix, (double)p->ramp_time);
    break;
  case PHLEX_PROFILE_SINE:
    PetscCheck(p->frequency > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: sine profile needs -%sprofile_frequency > 0, got %g", p->what, p->prefix, (double)p->frequency);
    break;
  case PHLEX_PROFILE_TABLE:
    PetscCheck(flg_table != flg_file, p->comm, PETSC_ERR_USER_INPUT, "%s: table profile needs exactly one of -%sprofile_table or -%sprofile_file", p->what, p->prefix, p->prefix);
    p->file[0]   = 0;
    p->column[0] = 0;
    if (flg_file) {
      PetscCall(PhlexProfileReadTableFile(p, file, column, &ndata, &data));
      PetscCall(PetscStrncpy(p->file, file, sizeof(p->file)));
    } else {
      ndata = ntable;
      PetscCheck(ndata <= 512, p->comm, PETSC_ERR_USER_INPUT, "%s: -%sprofile_table holds at most 256 points; give longer tables with -%sprofile_file", p->what, p->prefix, p->prefix);
      PetscCall(PetscMalloc1(ndata, &data));
      PetscCall(PetscArraycpy(data, table, ndata));
    }
    PetscCheck(ndata % 2 == 0, p->comm, PETSC_ERR_USER_INPUT, "%s: profile table needs pairs t,f; got %" PetscInt_FMT " numbers", p->what, ndata);
    PetscCheck(ndata >= 4, p->comm, PETSC_ERR_USER_INPUT, "%s: profile table needs at least 2 points, got %" PetscInt_FMT, p->what, ndata / 2);
    PetscCall(PetscFree2(p->table_t, p->table_f));
    p->ntable = ndata / 2;
    PetscCall(PetscMalloc2(p->ntable, &p->table_t, p->ntable, &p->table_f));
    for (PetscInt i = 0; i < p->ntable; i++) {
      p->table_t[i] = data[2 * i];
      p->table_f[i] = data[2 * i + 1];
      PetscCheck(i == 0 || p->table_t[i] > p->table_t[i - 1], p->comm, PETSC_ERR_USER_INPUT, "%s: profile table times must increase strictly; t[%" PetscInt_FMT "] = %g follows %g", p->what, i, (double)p->table_t[i], (double)p->table_t[i - 1]);
    }
    PetscCall(PetscFree(data));
    break;
  default:
    break;
  }
  PetscFunctionReturn(0);
}

/* a table's segment holding t (t within its points): i with t_i <= t <= t_{i+1} */
static PetscInt TableSegment(PhlexProfile p, PetscReal t)
{
  PetscInt lo = 0, hi = p->ntable - 1;

  while (hi - lo > 1) { /* bisection: a measured series has many points */
    const PetscInt mid = (lo + hi) / 2;
    if (p->table_t[mid] <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}

/*@C
  PhlexProfileEvaluate - evaluates f(t)

  Not collective

  Input Parameters:
+ p - the profile
- t - time [s]

  Output Parameter:
. f - profile value
@*/
PetscErrorCode PhlexProfileEvaluate(PhlexProfile p, PetscReal t, PetscReal *f)
{
  PetscReal s = t - p->start_time;

  PetscFunctionBeginUser;
  *f = 0.0;
  switch (p->type) {
  case PHLEX_PROFILE_CONSTANT:
    *f = s >= 0 ? 1.0 : 0.0;
    break;
  case PHLEX_PROFILE_RAMP:
    *f = s <= 0 ? 0.0 : (s >= p->ramp_time ? 1.0 : s / p->ramp_time);
    break;
  case PHLEX_PROFILE_SINE:
    *f = s >= 0 ? PetscSinReal(2.0 * PETSC_PI * p->frequency * s + p->phase) : 0.0;
    break;
  case PHLEX_PROFILE_TABLE: {
    const PetscInt n = p->ntable;
    /* outside the points: held, or zero (error: refused at set-up, so reached only within round-off, and held) */
    if (t < p->table_t[0]) *f = p->extrapolate == PHLEX_EXTRAPOLATE_ZERO ? 0.0 : p->table_f[0];
    else if (t > p->table_t[n - 1]) *f = p->extrapolate == PHLEX_EXTRAPOLATE_ZERO ? 0.0 : p->table_f[n - 1];
    else {
      const PetscInt i = TableSegment(p, t);
      *f = p->table_f[i] + (p->table_f[i + 1] - p->table_f[i]) * (t - p->table_t[i]) / (p->table_t[i + 1] - p->table_t[i]);
    }
  } break;
  }
  *f *= p->scale;
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileDerivative - df/dt at t (a table's slope on the segment holding t; zero at the jumps of constant and
  ramp)

  Not collective
@*/
PetscErrorCode PhlexProfileDerivative(PhlexProfile p, PetscReal t, PetscReal *df)
{
  const PetscReal s = t - p->start_time;

  PetscFunctionBeginUser;
  *df = 0.0;
  switch (p->type) {
  case PHLEX_PROFILE_CONSTANT:
    break;
  case PHLEX_PROFILE_RAMP:
    *df = (s > 0 && s < p->ramp_time) ? 1.0 / p->ramp_time : 0.0;
    break;
  case PHLEX_PROFILE_SINE:
    *df = s >= 0 ? 2.0 * PETSC_PI * p->frequency * PetscCosReal(2.0 * PETSC_PI * p->frequency * s + p->phase) : 0.0;
    break;
  case PHLEX_PROFILE_TABLE:
    if (t >= p->table_t[0] && t <= p->table_t[p->ntable - 1]) {
      const PetscInt i = TableSegment(p, t);
      *df = (p->table_f[i + 1] - p->table_f[i]) / (p->table_t[i + 1] - p->table_t[i]);
    }
    break;
  }
  *df *= p->scale;
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileBounds - the least and the largest value f takes at any time (0 included before a start, and outside a
  table extended by zero)

  Not collective
@*/
PetscErrorCode PhlexProfileBounds(PhlexProfile p, PetscReal *fmin, PetscReal *fmax)
{
  PetscReal lo = 0.0, hi = 0.0;

  PetscFunctionBeginUser;
  switch (p->type) {
  case PHLEX_PROFILE_CONSTANT:
  case PHLEX_PROFILE_RAMP:
    lo = 0.0, hi = 1.0;
    break;
  case PHLEX_PROFILE_SINE:
    lo = -1.0, hi = 1.0;
    break;
  case PHLEX_PROFILE_TABLE:
    lo = hi = p->table_f[0];
    for (PetscInt i = 1; i < p->ntable; i++) lo = PetscMin(lo, p->table_f[i]), hi = PetscMax(hi, p->table_f[i]);
    if (p->extrapolate == PHLEX_EXTRAPOLATE_ZERO) lo = PetscMin(lo, 0.0), hi = PetscMax(hi, 0.0);
    break;
  }
  *fmin = PetscMin(lo * p->scale, hi * p->scale);
  *fmax = PetscMax(lo * p->scale, hi * p->scale);
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileGiven - whether any option of the profile with this prefix is in the options database

  Not collective
@*/
PetscErrorCode PhlexProfileGiven(const char prefix[], PetscBool *given)
{
  const char *const names[] = {"-profile_type", "-profile_start", "-profile_ramp_time", "-profile_frequency", "-profile_phase", "-profile_scale", "-profile_table", "-profile_file", "-profile_column", "-profile_extrapolate"};

  PetscFunctionBeginUser;
  *given = PETSC_FALSE;
  for (size_t k = 0; k < sizeof(names) / sizeof(names[0]) && !*given; k++) PetscCall(PetscOptionsHasName(NULL, prefix, names[k], given));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileCheckRange - refuses a run over [t0, tf] that reaches outside the times of a table profile whose
  extrapolation is error (a series read from a file, by default); how: what sets the run's end, for the message

  Collective
@*/
PetscErrorCode PhlexProfileCheckRange(PhlexProfile p, PetscReal t0, PetscReal tf, const char how[])
{
  PetscReal a, b, tol;
  char      src[PETSC_MAX_PATH_LEN + 256];

  PetscFunctionBeginUser;
  if (p->type != PHLEX_PROFILE_TABLE || p->extrapolate != PHLEX_EXTRAPOLATE_ERROR) PetscFunctionReturn(0);
  a   = p->table_t[0];
  b   = p->table_t[p->ntable - 1];
  tol = 1e-10 * PetscMax(PetscAbsReal(tf - t0), b - a); /* the run's end summed from its steps */
  if (t0 >= a - tol && tf <= b + tol) PetscFunctionReturn(0);
  if (p->file[0]) PetscCall(PetscSNPrintf(src, sizeof(src), "the series -%sprofile_file %s, column %s,", p->prefix, p->file, p->column));
  else PetscCall(PetscSNPrintf(src, sizeof(src), "the table -%sprofile_table", p->prefix));
  SETERRQ(p->comm, PETSC_ERR_USER_INPUT, "%s: %s covers t in [%g, %g] s, but the run spans [%g, %g] s (%s): %s; extend the series, shorten the run, or say what the profile is outside the series with -%sprofile_extrapolate hold|zero", p->what, src, (double)a, (double)b, (double)t0, (double)tf, how, t0 < a - tol ? (tf > b + tol ? "it starts before the series and ends after it" : "it starts before the series") : "it ends after the series", p->prefix);
}

/*@C
  PhlexProfileCheckRangeAll - PhlexProfileCheckRange on every profile alive (every load, drive and force element of
  the scene)

  Collective
@*/
PetscErrorCode PhlexProfileCheckRangeAll(PetscReal t0, PetscReal tf, const char how[])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < nalive; k++) PetscCall(PhlexProfileCheckRange(alive[k], t0, tf, how));
  PetscFunctionReturn(0);
}

/* int_{t_0}^{x} f of a table (unscaled): its trapezoids up to x, outside its points f_0 or f_n held, or zero */
static PetscReal TableIntegral(PhlexProfile p, PetscReal x)
{
  const PetscInt  n    = p->ntable;
  const PetscBool zero = p->extrapolate == PHLEX_EXTRAPOLATE_ZERO ? PETSC_TRUE : PETSC_FALSE;
  PetscReal       A    = 0.0, f;
  PetscInt        i;

  if (x <= p->table_t[0]) return zero ? 0.0 : p->table_f[0] * (x - p->table_t[0]);
  i = x >= p->table_t[n - 1] ? n - 1 : TableSegment(p, x);
  for (PetscInt k = 0; k < i; k++) A += 0.5 * (p->table_f[k] + p->table_f[k + 1]) * (p->table_t[k + 1] - p->table_t[k]);
  if (i == n - 1) return A + (zero ? 0.0 : p->table_f[n - 1] * (x - p->table_t[n - 1]));
  f = p->table_f[i] + (p->table_f[i + 1] - p->table_f[i]) * (x - p->table_t[i]) / (p->table_t[i + 1] - p->table_t[i]);
  return A + 0.5 * (p->table_f[i] + f) * (x - p->table_t[i]);
}

/*@C
  PhlexProfileIntegrate - the integral F(t) = int_0^t f(s) ds (the position of a prescribed velocity)

  Not collective
@*/
PetscErrorCode PhlexProfileIntegrate(PhlexProfile p, PetscReal t, PetscReal *F)
{
  const PetscReal t0 = PetscMax(p->start_time, 0.0), s = t - p->start_time;

  PetscFunctionBeginUser;
  *F = 0.0;
  switch (p->type) {
  case PHLEX_PROFILE_CONSTANT:
    *F = t > t0 ? t - t0 : 0.0;
    break;
  case PHLEX_PROFILE_RAMP: {
    /* f = s / ramp on (0, ramp), 1 after: int = s^2 / (2 ramp), then ramp / 2 + (s - ramp) */
    const PetscReal a = PetscMax(0.0, -p->start_time); /* the part of the ramp before t = 0 */
    PetscReal       Fa = a <= 0 ? 0.0 : (a >= p->ramp_time ? p->ramp_time / 2 + (a - p->ramp_time) : a * a / (2 * p->ramp_time));
    PetscReal       Fs = s <= 0 ? 0.0 : (s >= p->ramp_time ? p->ramp_time / 2 + (s - p->ramp_time) : s * s / (2 * p->ramp_time));
    *F                 = t > t0 ? Fs - Fa : 0.0;
  } break;
  case PHLEX_PROFILE_SINE: {
    const PetscReal w = 2.0 * PETSC_PI * p->frequency, a = t0 - p->start_time;
    *F                = t > t0 ? (PetscCosReal(w * a + p->phase) - PetscCosReal(w * s + p->phase)) / w : 0.0;
  } break;
  case PHLEX_PROFILE_TABLE:
    *F = TableIntegral(p, t) - TableIntegral(p, 0.0);
    break;
  }
  *F *= p->scale;
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileDescribe - a one-line description of the profile, e.g. "sine 120 Hz, phase 0 rad, from t = 0 s"
@*/
PetscErrorCode PhlexProfileDescribe(PhlexProfile p, char buf[], size_t len)
{
  PetscFunctionBeginUser;
  switch (p->type) {
  case PHLEX_PROFILE_CONSTANT:
    PetscCall(PetscSNPrintf(buf, len, "constant from t = %g s", (double)p->start_time));
    break;
  case PHLEX_PROFILE_RAMP:
    PetscCall(PetscSNPrintf(buf, len, "ramp from t = %g s over %g s", (double)p->start_time, (double)p->ramp_time));
    break;
  case PHLEX_PROFILE_SINE:
    PetscCall(PetscSNPrintf(buf, len, "sine %g Hz, phase %g rad, from t = %g s", (double)p->frequency, (double)p->phase, (double)p->start_time));
    break;
  case PHLEX_PROFILE_TABLE:
    PetscCall(PetscSNPrintf(buf, len, "table of %" PetscInt_FMT " points on [%g, %g] s", p->ntable, (double)p->table_t[0], (double)p->table_t[p->ntable - 1]));
    if (p->file[0] || p->extrapolate != PHLEX_EXTRAPOLATE_HOLD) {
      char s[PETSC_MAX_PATH_LEN + 256] = "";
      if (p->file[0]) PetscCall(PetscSNPrintf(s, sizeof(s), " from %s, column %s", p->file, p->column));
      PetscCall(PetscStrlcat(buf, s, len));
      PetscCall(PetscStrlcat(buf, p->extrapolate == PHLEX_EXTRAPOLATE_HOLD ? ", held outside" : (p->extrapolate == PHLEX_EXTRAPOLATE_ZERO ? ", zero outside" : ", no run outside"), len));
    }
    break;
  }
  if (p->scale != 1.0) {
    char s[64];
    PetscCall(PetscSNPrintf(s, sizeof(s), ", scaled by %g", (double)p->scale));
    PetscCall(PetscStrlcat(buf, s, len));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileView - prints the one-line description of the profile
@*/
PetscErrorCode PhlexProfileView(PhlexProfile p, PetscViewer viewer)
{
  char buf[256];

  PetscFunctionBeginUser;
  PetscCall(PhlexProfileDescribe(p, buf, sizeof(buf)));
  PetscCall(PetscViewerASCIIPrintf(viewer, "%s", buf));
  PetscFunctionReturn(0);
}

/*@C
  PhlexProfileDestroy - destroys a profile
@*/
PetscErrorCode PhlexProfileDestroy(PhlexProfile *p)
{
  PetscFunctionBeginUser;
  if (!*p) PetscFunctionReturn(0);
  PetscCall(AliveRemove(*p));
  PetscCall(PetscFree2((*p)->table_t, (*p)->table_f));
  PetscCall(PetscFree(*p));
  PetscFunctionReturn(0);
}
