/* Time profiles f(t) that multiply an input amplitude: constant, ramp, sine, piecewise-linear table. */
#include <phlex_impl.h>

const char *const PhlexProfileTypes[] = {"constant", "ramp", "sine", "table", "PhlexProfileType", "PHLEX_PROFILE_", NULL};

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
  *profile = p;
  PetscFunctionReturn(0);
}

/* Reads a two-column (t, f) CSV file; a first line that does not start with a number is a header. */
static PetscErrorCode PhlexProfileReadTableFile(PhlexProfile p, const char file[], PetscInt *n, PetscReal **data)
{
  FILE       *fp;
  char        line[1024];
  PetscInt    cap = 64, cnt = 0, lineno = 0;
  PetscReal  *buf;
  PetscMPIInt rank;
  PetscInt    nread;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(p->comm, &rank));
  PetscCall(PetscMalloc1(cap, &buf));
  if (rank == 0) {
    fp = fopen(file, "r");
    PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "%s: cannot open profile table file '%s' (option -%sprofile_file)", p->what, file, p->prefix);
    while (fgets(line, sizeof(line), fp)) {
      double t, f;
      lineno++;
      if (sscanf(line, " %lf , %lf", &t, &f) != 2 && sscanf(line, " %lf %lf", &t, &f) != 2) {
        const char *c = line;
        while (*c == ' ' || *c == '\t') c++;
        PetscCheck(lineno == 1 || *c == '\n' || *c == '\r' || *c == '#' || *c == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "%s: profile table file '%s', line %" PetscInt_FMT ": expected two numbers 't, f', got '%s'", p->what, file, lineno, line);
        continue;
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
    }
    fclose(fp);
  }
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
. -profile_file <csv>      - table: the same points from a two-column CSV file
- -profile_scale <s>       - factor applied to f [-]
@*/
PetscErrorCode PhlexProfileSetFromOptions(PhlexProfile p)
{
  PetscReal table[513] = {0};
  PetscInt  ntable = 513; /* 256 points, and room for one more number: a longer table is refused, not cut */
  PetscBool flg_table = PETSC_FALSE, flg_file = PETSC_FALSE;
  char      file[PETSC_MAX_PATH_LEN] = "";
  PetscReal *data = NULL;
  PetscInt  ndata = 0;

  PetscFunctionBeginUser;
  PetscOptionsBegin(p->comm, p->prefix, "Time profile options", NULL);
  PetscCall(PetscOptionsEnum("-profile_type", "Time profile f(t) of the input", "PhlexProfileSetFromOptions", PhlexProfileTypes, (PetscEnum)p->type, (PetscEnum *)&p->type, NULL));
  PetscCall(PetscOptionsReal("-profile_start", "Time before which the profile is zero [s]", "PhlexProfileSetFromOptions", p->start_time, &p->start_time, NULL));
  PetscCall(PetscOptionsReal("-profile_ramp_time", "Ramp profile: rise time from 0 to 1 [s]", "PhlexProfileSetFromOptions", p->ramp_time, &p->ramp_time, NULL));
  PetscCall(PetscOptionsReal("-profile_frequency", "Sine profile: frequency [Hz]", "PhlexProfileSetFromOptions", p->frequency, &p->frequency, NULL));
  PetscCall(PetscOptionsReal("-profile_phase", "Sine profile: phase [rad]", "PhlexProfileSetFromOptions", p->phase, &p->phase, NULL));
  PetscCall(PetscOptionsReal("-profile_scale", "Factor applied to the profile [-]", "PhlexProfileSetFromOptions", p->scale, &p->scale, NULL));
  PetscCall(PhlexOptionsRealList("-profile_table", "Table profile: points t0,f0,t1,f1,... (t in s)", "PhlexProfileSetFromOptions", table, &ntable, &flg_table, 0));
  PetscCall(PetscOptionsString("-profile_file", "Table profile: two-column CSV file t,f (t in s)", "PhlexProfileSetFromOptions", file, file, sizeof(file), &flg_file));
  PetscOptionsEnd();

  switch (p->type) {
  case PHLEX_PROFILE_RAMP:
    PetscCheck(p->ramp_time > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: ramp profile needs -%sprofile_ramp_time > 0, got %g", p->what, p->prefix, (double)p->ramp_time);
    break;
  case PHLEX_PROFILE_SINE:
    PetscCheck(p->frequency > 0, p->comm, PETSC_ERR_USER_INPUT, "%s: sine profile needs -%sprofile_frequency > 0, got %g", p->what, p->prefix, (double)p->frequency);
    break;
  case PHLEX_PROFILE_TABLE:
    PetscCheck(flg_table != flg_file, p->comm, PETSC_ERR_USER_INPUT, "%s: table profile needs exactly one of -%sprofile_table or -%sprofile_file", p->what, p->prefix, p->prefix);
    if (flg_file) PetscCall(PhlexProfileReadTableFile(p, file, &ndata, &data));
    else {
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
    PetscInt i = 0, n = p->ntable;
    if (t <= p->table_t[0]) *f = p->table_f[0];
    else if (t >= p->table_t[n - 1]) *f = p->table_f[n - 1];
    else {
      while (p->table_t[i + 1] < t) i++;
      *f = p->table_f[i] + (p->table_f[i + 1] - p->table_f[i]) * (t - p->table_t[i]) / (p->table_t[i + 1] - p->table_t[i]);
    }
  } break;
  }
  *f *= p->scale;
  PetscFunctionReturn(0);
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
  case PHLEX_PROFILE_TABLE: {
    /* trapezoids of the piecewise-linear table over [0, t], constant extension outside */
    const PetscInt n = p->ntable;
    PetscReal      a = 0.0, fa, fb, b;
    PetscCall(PhlexProfileEvaluate(p, 0.0, &fa));
    fa /= p->scale;
    for (PetscInt i = 0; i <= n && a < t; i++) {
      b = i < n ? PetscMin(p->table_t[i], t) : t;
      if (b <= a) continue;
      PetscCall(PhlexProfileEvaluate(p, b, &fb));
      fb /= p->scale;
      *F += 0.5 * (fa + fb) * (b - a);
      a  = b;
      fa = fb;
    }
  } break;
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
  PetscCall(PetscFree2((*p)->table_t, (*p)->table_f));
  PetscCall(PetscFree(*p));
  PetscFunctionReturn(0);
}
