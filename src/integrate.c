/* Transient analysis: TS set-up (implicit midpoint by default), initial conditions, and the energy / power-balance
   monitor that writes the CSV series and the fields, and checks the -expect_* bounds. */
#include <phlex_impl.h>

/* ---------------------------------------------------------------------------------------------------------- */
/* Initial conditions                                                                                          */

typedef struct {
  const PhlexIC *ic;
  PetscReal      scale;                 /* SI -> non-dimensional */
  PetscReal      axis[3], origin[3], length, beta, sigma, tip;
} ICContext;

/* Euler-Bernoulli cantilever mode n along the body axis from the clamped patch */
static PetscReal BeamShape(const ICContext *c, PetscReal s)
{
  const PetscReal bx = c->beta * s;
  return PetscCoshReal(bx) - PetscCosReal(bx) - c->sigma * (PetscSinhReal(bx) - PetscSinReal(bx));
}

static PetscErrorCode ICFunction(PetscInt dim, PetscReal t, const PetscReal x[], PetscInt Nc, PetscScalar *u, void *ctx)
{
  const ICContext *c  = (const ICContext *)ctx;
  const PhlexIC   *ic = c->ic;

  switch (ic->type) {
  case PHLEX_IC_UNIFORM:
    for (PetscInt d = 0; d < 3; d++) u[d] = c->scale * ic->value[d];
    break;
  case PHLEX_IC_RIGID: {
    const PetscReal r[3] = {x[0] - ic->origin[0], x[1] - ic->origin[1], x[2] - ic->origin[2]};
    const PetscReal *w   = ic->angular;
    u[0]                 = c->scale * (ic->value[0] + w[1] * r[2] - w[2] * r[1]);
    u[1]                 = c->scale * (ic->value[1] + w[2] * r[0] - w[0] * r[2]);
    u[2]                 = c->scale * (ic->value[2] + w[0] * r[1] - w[1] * r[0]);
  } break;
  case PHLEX_IC_BEAM: {
    PetscReal s = 0, f;
    for (PetscInt d = 0; d < 3; d++) s += (x[d] - c->origin[d]) * c->axis[d];
    s = PetscMin(PetscMax(s / c->length, 0.0), 1.0);
    f = BeamShape(c, s) / c->tip;
    for (PetscInt d = 0; d < 3; d++) u[d] = c->scale * ic->amplitude * f * ic->direction[d];
  } break;
  default:
    for (PetscInt d = 0; d < 3; d++) u[d] = 0.0;
  }
  return 0;
}

/* An initial field of the velocity space (velocity or displacement), non-dimensional. */
static PetscErrorCode SetKinematicIC(PhlexScene scene, const PhlexIC *ic, const char field[], PetscReal scale, Vec x)
{
  PhlexBody b = scene->bodies[0];
  ICContext c;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&c, sizeof(c)));
  c.ic    = ic;
  c.scale = scale;
  switch (ic->type) {
  case PHLEX_IC_ZERO:
    PetscCall(VecSet(x, 0.0));
    break;
  case PHLEX_IC_BEAM: {
    /* axis: longest bounding-box direction, from the clamped patch's side */
    const PetscReal betas[4] = {1.875104069, 4.694091133, 7.854757438, 10.99554073};
    PetscInt        axis     = 0;
    PetscReal       nd       = 0;
    PetscCheck(b->frame_patch[0], b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_%s_type beam needs a clamped patch (-%sframe_patch)", b->name, b->prefix, field, b->prefix);
    for (PetscInt d = 0; d < 3; d++)
      if (b->bbox_max[d] - b->bbox_min[d] > b->bbox_max[axis] - b->bbox_min[axis]) axis = d;
    for (PetscInt d = 0; d < 3; d++) nd += PetscSqr(ic->direction[d]);
    PetscCheck(nd > 0, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_%s_direction must be a nonzero vector", b->name, b->prefix, field);
    c.length = b->bbox_max[axis] - b->bbox_min[axis];
    c.beta   = ic->mode <= 4 ? betas[ic->mode - 1] : (2 * ic->mode - 1) * PETSC_PI / 2;
    c.sigma  = (PetscCoshReal(c.beta) + PetscCosReal(c.beta)) / (PetscSinhReal(c.beta) + PetscSinReal(c.beta));
    c.tip    = BeamShape(&c, 1.0);
    /* from the clamped end: the side of the bounding box nearest to the patch centroid */
    for (PetscInt d = 0; d < 3; d++) c.origin[d] = b->frame_centroid[d];
    c.axis[axis] = (b->frame_centroid[axis] - b->bbox_min[axis] <= b->bbox_max[axis] - b->frame_centroid[axis]) ? 1.0 : -1.0;
    {
      PhlexIC icn = *ic;
      for (PetscInt d = 0; d < 3; d++) icn.direction[d] = ic->direction[d] / PetscSqrtReal(nd);
      c.ic = &icn;
      {
        PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ICFunction};
        void *ctxs[1] = {&c};
        PetscCall(DMProjectFunction(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, x));
      }
    }
  } break;
  case PHLEX_IC_MODE: {
    PetscInt   nconv, nrigid;
    PetscReal *lambda, vmax, vmin;
    Vec       *vecs;
    PetscCall(PhlexBodyComputeModes(b, &scene->units, ic->mode, &nconv, &nrigid, &lambda, &vecs, NULL));
    PetscCheck(nconv >= nrigid + ic->mode, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: elastic mode %" PetscInt_FMT " for -%sic_%s_mode was not found (%" PetscInt_FMT " converged)", b->name, ic->mode, b->prefix, field, nconv - nrigid);
    PetscCall(VecCopy(vecs[nrigid + ic->mode - 1], x));
    PetscCall(VecMax(x, NULL, &vmax));
    PetscCall(VecMin(x, NULL, &vmin));
    /* largest component positive, largest magnitude = amplitude: the same field on any number of ranks */
    PetscCall(VecScale(x, (vmax >= -vmin ? 1.0 / vmax : 1.0 / vmin) * ic->amplitude * scale));
    for (PetscInt i = 0; i < nconv; i++) PetscCall(VecDestroy(&vecs[i]));
    PetscCall(PetscFree(vecs));
    PetscCall(PetscFree(lambda));
  } break;
  default: {
    PetscErrorCode (*funcs[1])(PetscInt, PetscReal, const PetscReal[], PetscInt, PetscScalar *, void *) = {ICFunction};
    void *ctxs[1] = {&c};
    PetscCall(DMProjectFunction(b->dm, 0.0, funcs, ctxs, INSERT_ALL_VALUES, x));
  } break;
  }
  PetscFunctionReturn(0);
}

/* Sigma_0 = Ms^{-1} G u_0 (the stress of the initial displacement, exact element by element) + a uniform stress */
static PetscErrorCode SetStressIC(PhlexScene scene, Vec u0, Vec s0)
{
  PhlexBody         b = scene->bodies[0];
  PetscReal         unorm;

  PetscFunctionBeginUser;
  PetscCall(VecSet(s0, 0.0));
  PetscCall(VecNorm(u0, NORM_INFINITY, &unorm));
  if (unorm > 0) {
    KSP ksp;
    PC  pc;
    Vec g;
    PetscCall(VecDuplicate(s0, &g));
    PetscCall(MatMult(b->G, u0, g));
    PetscCall(KSPCreate(b->comm, &ksp));
    PetscCall(KSPSetOperators(ksp, b->Ms, b->Ms));
    PetscCall(KSPSetType(ksp, KSPPREONLY));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCSetType(pc, PCPBJACOBI));
    PetscCall(KSPSolve(ksp, g, s0));
    PetscCall(KSPDestroy(&ksp));
    PetscCall(VecDestroy(&g));
  }
  if (b->ic_stress.type == PHLEX_IC_UNIFORM) {
    PetscScalar *a;
    PetscInt     n;
    /* node-major stress dofs: component i % 6; a uniform field has the same value at every node */
    PetscCall(VecGetLocalSize(s0, &n));
    PetscCall(VecGetArray(s0, &a));
    for (PetscInt i = 0; i < n; i++) a[i] += b->ic_stress.value[i % 6] / scene->units.modulus;
    PetscCall(VecRestoreArray(s0, &a));
  } else PetscCheck(b->ic_stress.type == PHLEX_IC_ZERO, b->comm, PETSC_ERR_USER_INPUT, "body %s: -%sic_stress_type must be zero or uniform (a mode's stress follows from -%sic_displacement_type mode)", b->name, b->prefix, b->prefix);
  PetscFunctionReturn(0);
}

static PetscErrorCode SetInitialCondition(PhlexScene scene, PhlexSystem *sys, Vec X)
{
  PhlexBody b = scene->bodies[0];
  Vec       u, s, v;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(SetKinematicIC(scene, &b->ic_velocity, "velocity", 1.0 / scene->units.velocity, v));
  PetscCall(SetKinematicIC(scene, &b->ic_displacement, "displacement", 1.0 / scene->units.length, u));
  PetscCall(SetStressIC(scene, u, s));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscFunctionReturn(0);
}

/* ---------------------------------------------------------------------------------------------------------- */
/* Energy and power-balance monitor                                                                            */

typedef struct {
  PhlexScene       scene;
  PhlexSystem     *sys;
  Vec              Xprev, vmid, beff, work;
  PetscReal        H0, Hprev, tprev, work_total, max_drift, max_residual, max_work, Hmax;
  PetscViewer      energy_csv, ports_csv, monitor;
  PhlexFieldWriter fields;
  PetscInt         interval, last_written;
  PetscBool        theta, endpoint;
  PetscReal        theta_value;
} MonitorContext;

static PetscErrorCode WriteFields(MonitorContext *m, PetscReal t, Vec X)
{
  PhlexBody        b = m->sys->body;
  const PhlexUnits *u = &m->scene->units;
  Vec              x;

  PetscFunctionBeginUser;
  if (!m->fields) PetscFunctionReturn(0);
  PetscCall(PhlexFieldWriterBeginStep(m->fields, t));
  /* displacement first: ParaView makes the first vector the active one ("Warp By Vector") */
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_DISPLACEMENT], &x));
  PetscCall(PhlexFieldWriterVertexField(m->fields, "displacement", x, u->length, NULL, NULL));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_DISPLACEMENT], &x));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &x));
  PetscCall(PhlexFieldWriterVertexField(m->fields, "velocity", x, u->velocity, NULL, NULL));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &x));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &x));
  PetscCall(PhlexFieldWriterStress(m->fields, x, u->modulus));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &x));
  (void)b;
  PetscFunctionReturn(0);
}

static PetscErrorCode Energy(MonitorContext *m, Vec X, PetscReal *kin, PetscReal *strain)
{
  Vec v, s;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(PhlexBodyEnergy(m->sys->body, v, s, kin, strain));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &s));
  PetscFunctionReturn(0);
}

static PetscErrorCode WritePorts(MonitorContext *m, PetscReal t, Vec X)
{
  PhlexBody        b = m->sys->body;
  const PhlexUnits *u = &m->scene->units;
  PetscReal        y[PHLEX_MAX_PORTS][6];
  Vec              v;

  PetscFunctionBeginUser;
  if (!m->ports_csv) PetscFunctionReturn(0);
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(PhlexBodyPortOutputs(b, v, y));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(PetscViewerASCIIPrintf(m->ports_csv, "%.12e", (double)t));
  for (PetscInt p = 0; p < b->nports; p++) {
    PetscReal in[6];
    PetscCall(PhlexPortInput(&b->ports[p], t, u, in));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(in[k] * u->force)));
    for (PetscInt k = 3; k < 6; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(in[k] * u->force * u->length)));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(y[p][k] * u->velocity)));
    for (PetscInt k = 3; k < 6; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(y[p][k] / u->time)));
  }
  PetscCall(PetscViewerASCIIPrintf(m->ports_csv, "\n"));
  PetscFunctionReturn(0);
}

/* After each step: H_{n+1}, the supplied work dt v_mid^T b_eff (exact discrete power of the theta scheme:
   b at t_n + theta dt, or the theta-average for the endpoint variant) and the residual of the balance. */
static PetscErrorCode MonitorEnergy(TS ts, PetscInt step, PetscReal t, Vec X, void *ctx)
{
  MonitorContext   *m = (MonitorContext *)ctx;
  const PhlexUnits *u = &m->scene->units;
  PetscReal         kin, strain, H, dt, power = 0, residual = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_MonitorEnergy, 0, 0, 0, 0));
  PetscCall(Energy(m, X, &kin, &strain));
  H = kin + strain;
  if (step == 0) {
    m->H0 = m->Hprev = m->Hmax = H;
  } else {
    PhlexBody b = m->sys->body;
    Vec       vn, vp;
    dt = (t - m->tprev) / u->time;
    PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &vn));
    PetscCall(VecGetSubVector(m->Xprev, m->sys->is[PHLEX_FIELD_VELOCITY], &vp));
    PetscCall(VecAXPBYPCZ(m->vmid, 0.5, 0.5, 0.0, vn, vp));
    PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &vn));
    PetscCall(VecRestoreSubVector(m->Xprev, m->sys->is[PHLEX_FIELD_VELOCITY], &vp));
    if (m->theta && m->endpoint) {
      PetscCall(PhlexBodyLoadVector(b, t, u, m->beff));
      PetscCall(PhlexBodyLoadVector(b, m->tprev, u, m->work));
      PetscCall(VecAXPBY(m->beff, 1.0 - m->theta_value, m->theta_value, m->work));
    } else {
      const PetscReal th = m->theta ? m->theta_value : 0.5;
      PetscCall(PhlexBodyLoadVector(b, m->tprev + th * (t - m->tprev), u, m->beff));
    }
    {
      PetscScalar p;
      PetscCall(VecDot(m->vmid, m->beff, &p));
      power = PetscRealPart(p);
    }
    m->work_total += dt * power;
    residual = H - m->Hprev - dt * power;
    m->max_residual = PetscMax(m->max_residual, PetscAbsReal(residual));
    m->max_work     = PetscMax(m->max_work, PetscAbsReal(m->work_total));
    m->max_drift    = PetscMax(m->max_drift, PetscAbsReal(H - m->H0));
    m->Hmax         = PetscMax(m->Hmax, H);
    m->Hprev        = H;
  }
  PetscCall(PetscViewerASCIIPrintf(m->energy_csv, "%" PetscInt_FMT ",%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e\n", step, (double)t, (double)(kin * u->energy), (double)(strain * u->energy), (double)(H * u->energy), (double)(power * u->power), (double)(m->work_total * u->energy), (double)(residual * u->energy)));
  if (m->monitor) PetscCall(PetscViewerASCIIPrintf(m->monitor, "%4" PetscInt_FMT " t %.6e H %.10e J  power %.6e W  balance residual %.3e J\n", step, (double)t, (double)(H * u->energy), (double)(power * u->power), (double)(residual * u->energy)));
  PetscCall(WritePorts(m, t, X));
  if (step == 0 || (m->interval > 0 && step % m->interval == 0)) {
    PetscCall(WriteFields(m, t, X));
    m->last_written = step;
  }
  PetscCall(VecCopy(X, m->Xprev));
  m->tprev = t;
  PetscCall(PetscLogEventEnd(PHLEX_MonitorEnergy, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* The solver preset (-solver_options_file) goes under the scene and the command line: insert it, then insert the
   command line again (with its -options_file scenes) so that they keep precedence. */
static PetscErrorCode InsertSolverPreset(MPI_Comm comm)
{
  char      file[PETSC_MAX_PATH_LEN] = "options/solver/exact.opts";
  PetscBool exists;
  int       argc;
  char    **argv;

  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, NULL, "Solver preset", NULL);
  PetscCall(PetscOptionsString("-solver_options_file", "Solver preset (options file) under the scene and command-line options; empty for none", "PhlexSceneSolveTransient", file, file, sizeof(file), NULL));
  PetscOptionsEnd();
  if (!file[0]) PetscFunctionReturn(0);
  PetscCall(PetscTestFile(file, 'r', &exists));
  PetscCheck(exists, comm, PETSC_ERR_FILE_OPEN, "cannot read the solver preset '%s' (option -solver_options_file; presets are in options/solver/)", file);
  PetscCall(PetscOptionsInsertFile(comm, NULL, file, PETSC_TRUE));
  PetscCall(PetscGetArgs(&argc, &argv));
  PetscCall(PetscOptionsInsert(NULL, &argc, &argv, NULL));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSolveTransient - integrates the scene in time with TS and reports energy and power balance

  Collective

  Options Database Keys:
+ -ts_dt <s>                        - time step (required)
. -ts_max_time <s>, -ts_max_steps   - end of the run
. -ts_type theta -ts_theta_theta 0.5 - implicit midpoint (default); cn, bdf, alpha, ... by option
. -ts_monitor_energy [viewer]       - print energy, power and balance residual every step
. -solver_options_file <file>       - solver preset (default options/solver/exact.opts), under scene and command line
. -expect_energy_drift_max <r>      - self-check: max |H - H0| / H0 (lossless runs)
- -expect_power_balance_rtol <r>    - self-check: max |H_{n+1} - H_n - dt P| / max |supplied work|
@*/
PetscErrorCode PhlexSceneSolveTransient(PhlexScene scene)
{
  PhlexSystem      *sys;
  PhlexBody         b = scene->bodies[0];
  TS                ts;
  Vec               X;
  MonitorContext    m;
  PetscReal         dt = -1, drift_max = -1, balance_rtol = -1, tfinal;
  PetscInt          nsteps;
  PetscBool         flg;
  const PhlexUnits *u = &scene->units;
  char              header[4096] = "time";

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&m, sizeof(m)));
  PetscOptionsBegin(scene->comm, NULL, "Transient analysis options", NULL);
  PetscCall(PetscOptionsReal("-expect_energy_drift_max", "Self-check: bound on max |H - H0| / H0", "PhlexSceneSolveTransient", drift_max, &drift_max, NULL));
  PetscCall(PetscOptionsReal("-expect_power_balance_rtol", "Self-check: bound on max |H_{n+1} - H_n - dt y^T u| / max |supplied work|", "PhlexSceneSolveTransient", balance_rtol, &balance_rtol, NULL));
  PetscCall(PetscOptionsViewer("-ts_monitor_energy", "Print energy, input power and balance residual every step", "PhlexSceneSolveTransient", &m.monitor, NULL, &flg));
  PetscOptionsEnd();

  PetscCall(InsertSolverPreset(scene->comm));
  PetscCall(PhlexSystemCreate(scene, &sys));
  PetscCall(TSCreate(scene->comm, &ts));
  PetscCall(TSSetDM(ts, sys->dm));
  PetscCall(TSSetProblemType(ts, TS_LINEAR));
  PetscCall(TSSetIFunction(ts, NULL, PhlexSystemIFunction, sys));
  PetscCall(TSSetIJacobian(ts, sys->J, sys->J, PhlexSystemIJacobian, sys));
  /* the structure-preserving default: implicit midpoint */
  PetscCall(TSSetType(ts, TSTHETA));
  PetscCall(TSThetaSetTheta(ts, 0.5));
  PetscCall(TSSetTimeStep(ts, -1.0));
  PetscCall(TSSetMaxTime(ts, PETSC_MAX_REAL));
  PetscCall(TSSetMaxSteps(ts, PETSC_MAX_INT));
  PetscCall(TSSetExactFinalTime(ts, TS_EXACTFINALTIME_MATCHSTEP));
  /* adaptive steppers: the unknowns are non-dimensional (velocities ~ 1e-4 of the wave speed), so PETSc's default
     absolute tolerance 1e-4 would accept anything; default to a relative criterion */
  PetscCall(TSSetTolerances(ts, 1e-12, NULL, 1e-6, NULL));
  PetscCall(TSSetFromOptions(ts));
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCheck(dt > 0, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the time step with -ts_dt <s>");
  {
    PetscReal tmax;
    PetscInt  smax;
    PetscCall(TSGetMaxTime(ts, &tmax));
    PetscCall(TSGetMaxSteps(ts, &smax));
    PetscCheck(tmax < PETSC_MAX_REAL || smax < PETSC_MAX_INT, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the end of the run with -ts_max_time <s> or -ts_max_steps <n>");
  }
  if (sys->use_aij) {
    PetscCall(MatConvert(sys->J, MATAIJ, MAT_INITIAL_MATRIX, &sys->Jaij));
    PetscCall(TSSetIJacobian(ts, sys->Jaij, sys->Jaij, PhlexSystemIJacobian, sys));
  }

  PetscCall(DMCreateGlobalVector(sys->dm, &X));
  PetscCall(PetscObjectSetName((PetscObject)X, "state"));
  PetscCall(SetInitialCondition(scene, sys, X));

  /* monitor */
  m.scene    = scene;
  m.sys      = sys;
  m.interval = scene->output->interval;
  PetscCall(VecDuplicate(X, &m.Xprev));
  PetscCall(DMCreateGlobalVector(b->dm, &m.vmid));
  PetscCall(VecDuplicate(m.vmid, &m.beff));
  PetscCall(VecDuplicate(m.vmid, &m.work));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &m.theta, TSTHETA, TSCN, TSBEULER, ""));
  if (m.theta) {
    PetscCall(TSThetaGetTheta(ts, &m.theta_value));
    PetscCall(TSThetaGetEndpoint(ts, &m.endpoint));
  }
  PetscCall(PhlexOutputCSVOpen(scene->output, "energy.csv", "step,time,kinetic,strain,total,input_power,supplied_work,balance_residual", &m.energy_csv));
  if (b->nports) {
    for (PetscInt p = 0; p < b->nports; p++) {
      const char *n = b->ports[p].name;
      char        cols[1024];
      PetscCall(PetscSNPrintf(cols, sizeof(cols), ",%s_Fx,%s_Fy,%s_Fz,%s_Tx,%s_Ty,%s_Tz,%s_vx,%s_vy,%s_vz,%s_wx,%s_wy,%s_wz", n, n, n, n, n, n, n, n, n, n, n, n));
      PetscCall(PetscStrlcat(header, cols, sizeof(header)));
    }
    PetscCall(PhlexOutputCSVOpen(scene->output, "ports.csv", header, &m.ports_csv));
  }
  if (scene->output->fields) PetscCall(PhlexFieldWriterCreate(scene->output, b, b->name, &m.fields));
  PetscCall(TSMonitorSet(ts, MonitorEnergy, &m, NULL));

  PetscCall(PetscLogStagePush(PHLEX_StageTransient));
  PetscCall(TSSolve(ts, X));
  PetscCall(PetscLogStagePop());
  PetscCall(TSGetStepNumber(ts, &nsteps));
  PetscCall(TSGetSolveTime(ts, &tfinal));
  if (m.fields && m.last_written != nsteps) PetscCall(WriteFields(&m, tfinal, X));

  {
    TSType type;
    PetscCall(TSGetType(ts, &type));
    PetscCall(PetscPrintf(scene->comm, "Transient: %" PetscInt_FMT " steps to t = %g s with TS %s", nsteps, (double)tfinal, type));
    if (m.theta) PetscCall(PetscPrintf(scene->comm, " (theta %g%s)", (double)m.theta_value, m.endpoint ? ", endpoint" : ""));
    PetscCall(PetscPrintf(scene->comm, "\n  energy: initial %.8e J, final %.8e J", (double)(m.H0 * u->energy), (double)(m.Hprev * u->energy)));
    if (m.H0 > 0) PetscCall(PetscPrintf(scene->comm, ", max |H - H0| / H0 = %.3e\n", (double)(m.max_drift / m.H0)));
    else PetscCall(PetscPrintf(scene->comm, "\n"));
    PetscCall(PetscPrintf(scene->comm, "  supplied work: %.8e J, max power-balance residual %.3e J\n", (double)(m.work_total * u->energy), (double)(m.max_residual * u->energy)));
  }
  PetscCall(PetscViewerDestroy(&m.energy_csv));
  PetscCall(PetscViewerDestroy(&m.ports_csv));
  PetscCall(PhlexFieldWriterDestroy(&m.fields));
  PetscCall(PhlexOutputCommit(scene->output));

  if (drift_max >= 0) {
    PetscCheck(m.H0 > 0, scene->comm, PETSC_ERR_USER_INPUT, "-expect_energy_drift_max needs a nonzero initial energy");
    PetscCall(PhlexExpectMax(scene->comm, "energy drift (max |H - H0| / H0)", "-expect_energy_drift_max", m.max_drift / m.H0, drift_max, PETSC_TRUE));
  }
  if (balance_rtol >= 0) {
    const PetscReal scale = m.max_work > 0 ? m.max_work : PetscMax(m.Hmax, PETSC_MACHINE_EPSILON);
    PetscCall(PhlexExpectMax(scene->comm, "power balance (max |H_{n+1} - H_n - dt y^T u| / max |supplied work|)", "-expect_power_balance_rtol", m.max_residual / scale, balance_rtol, PETSC_TRUE));
  }

  PetscCall(PetscViewerDestroy(&m.monitor));
  PetscCall(VecDestroy(&m.Xprev));
  PetscCall(VecDestroy(&m.vmid));
  PetscCall(VecDestroy(&m.beff));
  PetscCall(VecDestroy(&m.work));
  PetscCall(VecDestroy(&X));
  PetscCall(TSDestroy(&ts));
  PetscCall(PhlexSystemDestroy(&sys));
  PetscFunctionReturn(0);
}
