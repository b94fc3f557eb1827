/* Transient analysis: TS set-up (implicit midpoint by default), the consistent start of a mechanism, and the
   energy / power-balance monitor that writes the CSV series and the fields and checks the -expect_* bounds.

   Where the multipliers live: the joints' impulses Lambda are unknowns and the scheme sees only their rates. With a
   one-step scheme the multiplier it uses over a step is (Lambda_{n+1} - Lambda_n)/dt: for the implicit midpoint rule
   exactly the midpoint multiplier, for the others the step average of lambda (for BDF the average of the
   backward-difference rate, converging to lambda(t_{n+1/2})). The joint series write this step average (time t_{n+1}),
   which has no step-to-step oscillation. The power through a joint is lambda . (c + g) measured at the stage of the
   theta methods (where the scheme enforces the constraints); for the other schemes lambda . g(t), the scheme holding
   c = g. */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateGet: the stage vector unchanged since the stage */
#include <private/transient.h>


static PetscErrorCode TransientProgress(TS, MonitorContext *, PetscInt, PetscReal);
static PetscErrorCode ReportRetry(TS, MonitorContext *, const char[]);
static PetscErrorCode InputPower(MonitorContext *, PetscReal, Vec, PetscReal, PetscBool, PetscReal *, PetscReal *);
static PetscErrorCode Watchdogs(MonitorContext *, PetscInt, PetscReal, PetscReal, PetscReal);
static PetscErrorCode WatchDeformation(MonitorContext *, PetscInt, PetscReal, Vec);

/* ---------------------------------------------------------------------------------------------------------- */
/* Energy and power-balance monitor                                                                            */

/* the power of the inputs at (t, X): external inputs of every part and the drives of the joints (multipliers
   m->lambda); the joints' share, times weight, is added to m->jpower. At the stage of a theta method (X: the state
   where the constraints hold) a joint's power is measured from its ports, lambda . (c + g), zero to solver
   tolerance for a workless joint; for the other schemes it is lambda . g(t), the scheme holding c = g. D: the power
   the parts' and joints' dampers dissipate at (t, X), >= 0; the balance is dH/dt = P - D. */
static PetscErrorCode InputPower(MonitorContext *m, PetscReal t, Vec X, PetscReal weight, PetscBool stage, PetscReal *P, PetscReal *D)
{
  PhlexSystem sys = m->sys;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemEvaluate(sys, t, X, NULL));
  *P = *D = 0.0;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PetscReal p = 0.0, d = 0.0;
    if (sys->parts[i]->ops.inputpower) PetscCall((*sys->parts[i]->ops.inputpower)(sys->parts[i], &p));
    if (sys->parts[i]->ops.dissipation) PetscCall((*sys->parts[i]->ops.dissipation)(sys->parts[i], &d));
    *P += p;
    *D += d;
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PetscReal p, d, a;
    if (stage) PetscCall(PhlexJointPower(sys->joints[k], m->lambda + sys->joints[k]->qoff, &p));
    else PetscCall(PhlexJointSourcePower(sys->joints[k], t, m->lambda + sys->joints[k]->qoff, &p));
    PetscCall(PhlexJointDissipation(sys->joints[k], m->lambda + sys->joints[k]->qoff, &d));
    PetscCall(PhlexJointActuatorPower(sys->joints[k], t, &a)); /* a moving rest's */
    *P += p + a;
    *D += d;
    m->jpower[k] += weight * p;
    m->jdiss[k] += weight * d;
    m->jact[k] += weight * a;
  }
  PetscFunctionReturn(0);
}

/* kinetic, strain and potential energy at (t, X), and the parts' output series; fields if asked */
static PetscErrorCode EnergyAndOutputs(MonitorContext *m, PetscInt step, PetscReal t, Vec X, PetscBool fields, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  PhlexSystem sys = m->sys;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemEnergy(sys, t, X, kin, strain, pot));
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart    p = sys->parts[i];
    PhlexPartVec pv;
    PetscCall(PhlexPartGetVec(p, X, sys->q, &pv));
    PetscCall((*p->ops.outputstep)(p, step, t, &pv, fields));
    PetscCall(PhlexPartRestoreVec(p, X, &pv));
    if (p->frame.R >= 0) m->max_orth = PetscMax(m->max_orth, PhlexOrthogonalityError(sys->q + p->qoff + p->frame.R));
  }
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint   j = sys->joints[k];
    PhlexPartVec pv[2];
    PetscReal    gmax, dmax;
    PetscCall(PhlexSystemJointSides(sys, j, X, sys->q, pv));
    PetscCall(PhlexJointOutputStep(j, t, m->lambda + j->qoff, m->jpower[k], m->jdiss[k], m->jact[k], &pv[0], &pv[1], &gmax, &dmax));
    PetscCall(PhlexSystemJointSidesRestore(sys, j, X, pv));
    m->max_gap   = PetscMax(m->max_gap, gmax);
    m->max_drive = PetscMax(m->max_drive, dmax);
  }
  PetscCall(PhlexTransientPortsStep(m, t, X)); /* after the parts' outputs: every port's output is then computed */
  PetscCall(PhlexOutputFlushSeries(sys->scene->output));
  if (m->free_system) {
    PetscReal P[3] = {0, 0, 0}, L[3] = {0, 0, 0};
    for (PetscInt i = 0; i < sys->nparts; i++) {
      PetscReal Pi[3], Li[3];
      PetscCall((*sys->parts[i]->ops.momenta)(sys->parts[i], Pi, Li));
      for (PetscInt c = 0; c < 3; c++) P[c] += Pi[c], L[c] += Li[c];
    }
    if (step == 0) {
      PetscReal m6[36], mass = 0, Jtr = 0;
      for (PetscInt i = 0; i < sys->nparts; i++) {
        PetscCall((*sys->parts[i]->ops.rigidmass)(sys->parts[i], m6));
        mass += m6[0];
        Jtr += m6[21] + m6[28] + m6[35];
      }
      for (PetscInt c = 0; c < 3; c++) m->P0[c] = P[c], m->L0[c] = L[c];
      /* momentum scales: the momenta themselves, or those of the initial energy */
      m->Pscale = PetscMax(PhlexNorm3(P), PetscSqrtReal(2.0 * mass * PetscAbsReal(*kin)));
      m->Lscale = PetscMax(PhlexNorm3(L), PetscSqrtReal(2.0 * PetscAbsReal(*kin) * Jtr / 3.0));
      if (m->Pscale == 0) m->Pscale = 1.0;
      if (m->Lscale == 0) m->Lscale = 1.0;
    }
    for (PetscInt c = 0; c < 3; c++) {
      m->max_dP = PetscMax(m->max_dP, PetscAbsReal(P[c] - m->P0[c]) / m->Pscale);
      m->max_dL = PetscMax(m->max_dL, PetscAbsReal(L[c] - m->L0[c]) / m->Lscale);
    }
  }
  PetscFunctionReturn(0);
}

/* the stage of the step: the state at which the scheme enforces its equations (the constraints included) */
static PetscErrorCode PostStage(TS ts, PetscReal t, PetscInt index, Vec *Y)
{
  MonitorContext *m;

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &m));
  if (m->theta && !m->endpoint && m->Xstage != Y[0]) {
    /* the power of the step is taken at its stage: TSTHETA's own stage vector, which the step leaves as it is until
       the next step starts, so a reference and no copy of the state per step */
    PetscCall(PetscObjectReference((PetscObject)Y[0]));
    PetscCall(VecDestroy(&m->Xstage));
    m->Xstage = Y[0];
  }
  if (m->Xstage) PetscCall(PetscObjectStateGet((PetscObject)m->Xstage, &m->stage_state)); /* checked by the monitor */
  m->tstage     = t;
  m->have_stage = PETSC_TRUE;
  if (m->adaptive) {
    /* a Newton failure: TS retries the step with a smaller one (TSAdaptCheckStage) */
    SNES                snes;
    SNESConvergedReason reason;
    PetscCall(TSGetSNES(ts, &snes));
    PetscCall(SNESGetConvergedReason(snes, &reason));
    if (reason < 0) {
      char why[64];
      PetscCall(PetscSNPrintf(why, sizeof(why), "%s did not converge (%s)", m->condensed ? "the condensed solve" : "Newton", SNESConvergedReasons[reason]));
      /* TS gives up when a user's -ts_max_snes_failures is reached: then it is no retry */
      if (m->max_snes_failures > 0 && ++m->snes_failures >= m->max_snes_failures) PetscCall(PetscSNPrintf(m->last_retry, sizeof(m->last_retry), "%s", why));
      else PetscCall(ReportRetry(ts, m, why));
    }
  }
  PetscFunctionReturn(0);
}

/* a step about to be retried with a smaller one: one line, and the reason kept for the message if retries run out */
static PetscErrorCode ReportRetry(TS ts, MonitorContext *m, const char why[])
{
  PetscInt  step;
  PetscReal t, dt;

  PetscFunctionBeginUser;
  PetscCall(TSGetStepNumber(ts, &step));
  PetscCall(TSGetTime(ts, &t));
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCall(PetscSNPrintf(m->last_retry, sizeof(m->last_retry), "%s", why));
  PetscCall(PetscSNPrintf(m->run_retry, sizeof(m->run_retry), "%s", why));
  m->nretries++;
  PetscCall(PetscPrintf(m->scene->comm, "retry: step %" PetscInt_FMT " from t = %g s with time step %g s: %s; the step is retried with a smaller one\n", step + 1, (double)t, (double)dt, why));
  PetscFunctionReturn(0);
}

/* Adaptive steps (TSAdapt's stage check): a step whose state holds NaN/Inf or whose power balance would break the
   watchdog is rejected before it is accepted, and TS retries it with dt x -ts_adapt_scale_solve_failed (at most
   -ts_max_reject times in a row), instead of the run stopping. These are the step's own failures, which a smaller
   step cures; the joint drift and the rotations' drift accumulate over many steps, and stop the run in Watchdogs.
   Checked on the state the step would end at (the midpoint rule's stage Y is the step's middle:
   X_{n+1} = X_n + (Y - X_n)/theta), with the rotations cleaned as PostStep will. */
static PetscErrorCode CheckStage(TSAdapt adapt, TS ts, PetscReal t, Vec Y, PetscBool *accept)
{
  MonitorContext   *m;
  PhlexSystem       sys;
  const PhlexUnits *u;
  PetscReal         dt, norm;
  Vec               Xe;
  char              why[200] = "";

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &m));
  sys     = m->sys;
  u       = &m->scene->units;
  *accept = PETSC_TRUE;
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCall(VecNorm(Y, NORM_INFINITY, &norm));
  if (PetscIsInfOrNanReal(norm)) PetscCall(PetscSNPrintf(why, sizeof(why), "the state holds NaN or Inf"));
  else if (m->lossless_scheme && m->watch_balance > 0) {
    /* the implicit midpoint rule: the step's power balance at its end state, cleaned as PostStep will */
    const PetscReal dtn = dt / u->time;
    PetscReal       P, D, kin, strain, pot, residual, scale, defect;
    Xe = m->Xmid; /* scratch: the monitor sets it before using it */
    PetscCall(VecAXPBYPCZ(Xe, 1.0 / m->theta_value, 1.0 - 1.0 / m->theta_value, 0.0, Y, m->Xprev));
    PetscCall(PhlexSystemPostStep(sys, Xe, &defect));
    PetscCall(PhlexSystemGather(sys, Xe, sys->q));
    for (PetscInt k = 0; k < sys->nq; k++) m->lambda[k] = PhlexDofIsImpulse(sys->qkind[k]) ? (sys->q[k] - m->qprev[k]) / dtn : 0.0;
    PetscCall(InputPower(m, t, Y, 1.0, PETSC_TRUE, &P, &D));
    PetscCall(PhlexSystemEnergy(sys, m->tprev + dt, Xe, &kin, &strain, &pot));
    residual = kin + strain + pot - m->Hprev - dtn * (P - D);
    scale    = PetscMax(PetscMax(m->Emax, kin + strain), PetscAbsReal(m->H0));
    if (PetscIsInfOrNanReal(residual)) PetscCall(PetscSNPrintf(why, sizeof(why), "the power balance of the step is not a number"));
    else if (PetscAbsReal(residual) > m->watch_balance * scale) PetscCall(PetscSNPrintf(why, sizeof(why), "watchdog: the power balance of the step is off by %.3e J, %.2e of the energy (bound -watchdog_balance_rtol %g)", (double)(residual * u->energy), (double)(PetscAbsReal(residual) / scale), (double)m->watch_balance));
  }
  if (why[0]) {
    *accept = PETSC_FALSE;
    PetscCall(ReportRetry(ts, m, why));
  }
  PetscFunctionReturn(0);
}

/* Before each step: the joints' directions follow the ports' rotations, extrapolated from the state the step starts
   from to its middle (after the monitor has taken the power of the previous step with the directions that step
   used) */
static PetscErrorCode PreStep(TS ts)
{
  MonitorContext *m;
  Vec             X;
  PetscReal       dt;

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &m));
  PetscCall(TSGetSolution(ts, &X));
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCall(PhlexSystemUpdateJoints(m->sys, X, dt));
  if (m->profile_check_steps) {
    /* adaptive steps with no end time: each step's end against the series */
    PetscReal t;
    PetscCall(TSGetTime(ts, &t));
    PetscCall(PhlexProfileCheckRangeAll(m->profile_t0, t + dt, "adaptive steps bounded by -ts_max_steps alone: this step's end"));
  }
  /* the force elements' states at the step's start (a table spring's discrete gradient) and its time (a moving rest's
     mean over a midpoint step); only these need them */
  {
    PetscReal t0;
    PetscCall(TSGetTime(ts, &t0));
    if (m->element_tables) {
      PetscCall(PhlexSystemGather(m->sys, X, m->sys->q));
      for (PetscInt k = 0; k < m->sys->njoints; k++) PetscCall(PhlexJointElementStepStart(m->sys->joints[k], t0, m->sys->q, m->lossless_scheme, m->midpoint));
    }
    /* drives and prescribed motions: the step's start (a midpoint step's increment is the prescribed one) */
    for (PetscInt k = 0; k < m->sys->njoints; k++) PetscCall(PhlexJointDriveStepStart(m->sys->joints[k], t0, dt, m->midpoint, PETSC_FALSE));
  }
  PetscFunctionReturn(0);
}

/* After each step: every part's discrete unknowns cleaned (R back onto SO(3): the midpoint rule maps R by a
   Cayley factor, so the defect is the Newton residual and round-off, which would otherwise accumulate); every
   -joints_project_interval steps the positions are projected back onto the joints. */
static PetscErrorCode PostStep(TS ts)
{
  MonitorContext *m;
  Vec             X;
  PetscReal       defect;
  PetscInt        step;

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &m));
  PetscCall(TSGetSolution(ts, &X));
  if (!m->history) {
    /* PETSc restarts a scheme whose post-step changed the solution (TSPostStep): harmless for the one-step methods,
       but BDF would fall back to first order and generalized-alpha to its start-up step at every step. Their
       rotations are left as the scheme makes them (the drift of R^T R - I is reported). */
    PetscCall(PhlexSystemPostStep(m->sys, X, &defect));
    m->max_defect = PetscMax(m->max_defect, defect);
  }
  PetscCall(TSGetStepNumber(ts, &step));
  if (m->scene->project_interval > 0 && m->sys->njoints && step % m->scene->project_interval == 0) {
    PetscReal t, dH;
    PetscCall(TSGetTime(ts, &t));
    PetscCall(PhlexAssemblyClose(m->sys, t, X, PETSC_FALSE, &dH));
    m->project_dH += dH;
    m->step_project_dH = dH;
    m->nprojections++;
  }
  PetscFunctionReturn(0);
}

/* After each step: H_{n+1}, the work supplied over the step with the scheme's own quadrature, the balance residual
   H_{n+1} - H_n - W, the multipliers of the step, the series and fields:
     theta (midpoint rule and others): W = dt P(t_n + theta dt, X_stage), exact for a quadratic H;
     theta endpoint (Crank-Nicolson): W = dt (theta P(t_{n+1}) + (1 - theta) P(t_n)) at the midpoint velocities;
     any other scheme (BDF, generalized-alpha): W = dt (P(t_n, X_n) + P(t_{n+1}, X_{n+1})) / 2, and the residual is
     then the scheme's numerical dissipation (plus the O(dt^3) error of that quadrature). */
static PetscErrorCode MonitorEnergy(TS ts, PetscInt step, PetscReal t, Vec X, void *ctx)
{
  MonitorContext   *m   = (MonitorContext *)ctx;
  PhlexSystem       sys = m->sys;
  const PhlexUnits *u   = &m->scene->units;
  PetscReal         kin = 0, strain = 0, pot = 0, H, dt = 0, power = 0, dissipated = 0, residual = 0;
  PetscBool         fields;

  PetscFunctionBeginUser;
  /* once per step: TSSolve monitors the last step again after a failed one, and a restarted run's first step is the
     checkpoint's, which the run that wrote it monitored */
  if (step == m->last_step) PetscFunctionReturn(0);
  /* -ts_exact_final_time interpolate: the state interpolated to the end time (step -1) is no step of the scheme, and
     has no power balance; the series end at the last step */
  if (step < 0) PetscFunctionReturn(0);
  m->last_step = step;
  /* a step was accepted: the retries of the next one start afresh */
  m->last_retry[0] = 0;
  m->snes_failures = 0;
  PetscCall(PetscLogEventBegin(PHLEX_MonitorEnergy, 0, 0, 0, 0));
  for (PetscInt k = 0; k < sys->njoints; k++) m->jpower[k] = m->jdiss[k] = m->jact[k] = 0.0;
  if (step == 0 && sys->njoints) {
    /* the joints' power at the consistent start */
    PetscReal P0, D0;
    PetscCall(InputPower(m, t, X, 1.0, PETSC_TRUE, &P0, &D0));
  }
  if (step > 0) {
    dt = (t - m->tprev) / u->time;
    /* the multipliers of the step: (Lambda_{n+1} - Lambda_n)/dt */
    PetscCall(PhlexSystemGather(sys, X, sys->q));
    for (PetscInt k = 0; k < sys->nq; k++) m->lambda[k] = PhlexDofIsImpulse(sys->qkind[k]) ? (sys->q[k] - m->qprev[k]) / dt : 0.0;
    if (m->theta && !m->endpoint) {
      PetscObjectState state;
      PetscCheck(m->have_stage, m->scene->comm, PETSC_ERR_PLIB, "step %" PetscInt_FMT ": the theta method's step has no stage", step);
      PetscCall(PetscObjectStateGet((PetscObject)m->Xstage, &state));
      PetscCheck(state == m->stage_state, m->scene->comm, PETSC_ERR_PLIB, "step %" PetscInt_FMT ": TS changed the theta method's stage vector after the stage", step);
      PetscCall(InputPower(m, m->tstage, m->Xstage, 1.0, PETSC_TRUE, &power, &dissipated));
    } else if (m->theta && m->endpoint) {
      PetscReal P1, P0, D1, D0;
      PetscCall(VecAXPBYPCZ(m->Xmid, 0.5, 0.5, 0.0, X, m->Xprev));
      PetscCall(InputPower(m, t, m->Xmid, m->theta_value, PETSC_FALSE, &P1, &D1));
      PetscCall(InputPower(m, m->tprev, m->Xmid, 1.0 - m->theta_value, PETSC_FALSE, &P0, &D0));
      power      = m->theta_value * P1 + (1.0 - m->theta_value) * P0;
      dissipated = m->theta_value * D1 + (1.0 - m->theta_value) * D0;
    } else {
      PetscReal P1, P0, D1, D0;
      PetscCall(InputPower(m, t, X, 0.5, PETSC_FALSE, &P1, &D1));
      PetscCall(InputPower(m, m->tprev, m->Xprev, 0.5, PETSC_FALSE, &P0, &D0));
      power      = 0.5 * (P0 + P1);
      dissipated = 0.5 * (D0 + D1);
    }
  }
  /* the work each joint's force elements dissipated (its series reports it with the step) */
  for (PetscInt k = 0; k < sys->njoints && step > 0; k++) {
    sys->joints[k]->dissipated_work += dt * m->jdiss[k];
    sys->joints[k]->actuator_work += dt * m->jact[k]; /* and the work of a moving rest */
  }
  fields = (step == 0 || (m->interval > 0 && step % m->interval == 0)) ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(EnergyAndOutputs(m, step, t, X, fields, &kin, &strain, &pot));
  if (fields) m->last_written = step;
  H       = kin + strain + pot;
  m->Emax = PetscMax(m->Emax, kin + strain);
  if (step == 0) {
    m->H0 = m->Hprev = m->Hmax = H;
    m->E0abs = PetscAbsReal(kin) + PetscAbsReal(strain) + PetscAbsReal(pot);
    m->V0    = pot;
    /* a relative drift needs H0 > 0: refused here, before any step and before anything is committed */
    if (m->expect_drift_max >= 0 && !(H > 0)) {
      char v[32];
      PhlexFormatReal(m->expect_drift_max, v, sizeof(v));
      SETERRQ(m->scene->comm, PETSC_ERR_USER_INPUT, "-expect_energy_drift_max %s needs a nonzero initial energy (H0 = %g J, no scale for a relative drift): bound the drift in joules with -expect_energy_drift_abs_max", v, (double)(H * m->scene->units.energy));
    }
  } else {
    m->work_total += dt * power;
    m->dissipated_total += dt * dissipated;
    residual        = H - m->Hprev - dt * (power - dissipated);
    m->max_residual = PetscMax(m->max_residual, PetscAbsReal(residual));
    m->max_work     = PetscMax(m->max_work, PetscMax(PetscAbsReal(m->work_total), m->dissipated_total));
    m->max_drift    = PetscMax(m->max_drift, PetscAbsReal(H - m->H0));
    m->Hmax         = PetscMax(m->Hmax, H);
    m->max_dV       = PetscMax(m->max_dV, PetscAbsReal(pot - m->V0));
    m->Hprev        = H;
  }
  PetscCall(PhlexCSVPrintf(m->energy_csv, "%" PetscInt_FMT ",%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e\n", step, (double)t, (double)(kin * u->energy), (double)(strain * u->energy), (double)(pot * u->energy), (double)(H * u->energy), (double)(power * u->power), (double)(m->work_total * u->energy), (double)(residual * u->energy), (double)(dissipated * u->power), (double)(m->dissipated_total * u->energy)));
  if (m->monitor && m->dissipative) PetscCall(PetscViewerASCIIPrintf(m->monitor, "%4" PetscInt_FMT " t %.6e H %.10e J  power %.6e W  dissipated %.6e W  balance residual %.3e J\n", step, (double)t, (double)(H * u->energy), (double)(power * u->power), (double)(dissipated * u->power), (double)(residual * u->energy)));
  else if (m->monitor) PetscCall(PetscViewerASCIIPrintf(m->monitor, "%4" PetscInt_FMT " t %.6e H %.10e J  power %.6e W  balance residual %.3e J\n", step, (double)t, (double)(H * u->energy), (double)(power * u->power), (double)(residual * u->energy)));
  PetscCall(Watchdogs(m, step, t, H, residual - m->step_project_dH));
  if (step > 0 && m->watch_deform > 0) PetscCall(WatchDeformation(m, step, t, X));
  m->step_project_dH = 0;
  if (m->Xprev) PetscCall(VecCopy(X, m->Xprev));
  PetscCall(PhlexSystemGather(sys, X, m->qprev));
  m->tprev      = t;
  m->have_stage = PETSC_FALSE;
  PetscCall(PetscLogEventEnd(PHLEX_MonitorEnergy, 0, 0, 0, 0));
  if (step > 0 && (m->ck_interval > 0 || m->ck_wall > 0)) {
    /* a checkpoint when due, and before stopping on SIGINT/SIGTERM */
    PetscBool due;
    int       sig;
    PetscCall(PhlexTransientCheckpointDue(m, step, &due));
    PetscCall(PhlexInterruptPending(m->scene->comm, &sig));
    if (due || sig) PetscCall(PhlexTransientCheckpointWrite(ts, m, X));
    PetscCheck(!sig, m->scene->comm, PETSC_ERR_SIG, "interrupted by %s at step %" PetscInt_FMT ", t = %g s: checkpoint written to %s; continue the run with -restart %s", sig == 2 ? "SIGINT" : "SIGTERM", step, (double)t, m->ck_file, m->ck_file);
  }
  if (step > 0) PetscCall(TransientProgress(ts, m, step, t));
  PetscFunctionReturn(0);
}

/* the deformation watchdog: a body whose elastic displacement exceeds -watchdog_deformation times its size has left
   the range of its elastic model (a linear model spun past its first bending frequency diverges: spin softening) */
static PetscErrorCode WatchDeformation(MonitorContext *m, PetscInt step, PetscReal t, Vec X)
{
  PhlexSystem sys = m->sys;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart    part = sys->parts[i];
    PhlexPartVec pv;
    PetscReal    umax, size;
    PetscBool    stiffen;
    if (!part->ops.deformation) continue;
    PetscCall(PhlexSystemPartVec(sys, part, X, sys->q, &pv));
    PetscCall((*part->ops.deformation)(part, &pv, &umax, &size, &stiffen));
    PetscCall(PhlexSystemPartVecRestore(sys, part, X, &pv));
    if (umax > m->watch_deform * size || PetscIsInfOrNanReal(umax)) {
      char advice[256], f[32];
      if (stiffen) PetscCall(PetscSNPrintf(advice, sizeof(advice), "its elastic model is linear: if it spins or is driven fast, the rotation softens it and past its first bending frequency it diverges (add -%sgeometric_stiffening, the centrifugal stiffening); else reduce the loads or -ts_dt, or check the material's units", part->prefix));
      else PetscCall(PetscSNPrintf(advice, sizeof(advice), "reduce the loads or -ts_dt, or check the material's units"));
      SETERRQ(m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): body %s's elastic displacement reached %.4e m, more than -watchdog_deformation %s times its size %.4g m: the run blew up; %s (-watchdog_deformation 0 turns this check off); no result was written", step, (double)t, part->name, (double)umax, PhlexFormatReal(m->watch_deform, f, sizeof(f)), (double)size, advice);
    }
  }
  PetscFunctionReturn(0);
}

/* Watchdogs after each step: the state is finite; with the implicit midpoint rule and a quadratic Hamiltonian (no
   floating body with full inertia: the discrete power balance then holds to solver tolerance) the step's balance residual stays below -watchdog_balance_rtol of the largest
   kinetic + strain energy; every joint stays closed within -watchdog_joint_drift x min(L, 1 m) (m or rad). A run
   that breaks one has gone wrong (Newton converged to a wrong solution, a step too large, a drift out of control):
   it stops with exit code 3 and writes nothing. */
static PetscErrorCode Watchdogs(MonitorContext *m, PetscInt step, PetscReal t, PetscReal H, PetscReal residual)
{
  const PhlexUnits *u = &m->scene->units;

  PetscFunctionBeginUser;
  if (PetscIsInfOrNanReal(H)) {
    char e[32];
    SETERRQ(m->scene->comm, PETSC_ERR_NOT_CONVERGED, "at step %" PetscInt_FMT " (t = %g s) the energy is %s: the state holds NaN or Inf; reduce -ts_dt, or check the inputs' magnitudes; no result was written", step, (double)t, PhlexFormatReal(H * u->energy, e, sizeof(e)));
  }
  /* the energy holds no multiplier: a NaN there shows in the step's power balance */
  PetscCheck(!PetscIsInfOrNanReal(residual), m->scene->comm, PETSC_ERR_NOT_CONVERGED, "at step %" PetscInt_FMT " (t = %g s) the power balance of the step is not a number: the state (a multiplier, an input) holds NaN or Inf; reduce -ts_dt, or check the inputs' magnitudes; no result was written", step, (double)t);
  if (step > 0 && m->lossless_scheme && m->watch_balance > 0) {
    const PetscReal scale = PetscMax(m->Emax, PetscAbsReal(m->H0));
    char            material[PHLEX_NAME_LEN + 160] = "";
    /* a material warned about at the start (units, near incompressibility) conditions the solves badly: say so first */
    for (PetscInt i = 0; i < m->sys->nparts && !material[0]; i++)
      if (m->sys->parts[i]->material_warned) PetscCall(PetscSNPrintf(material, sizeof(material), "; first check body %s's material, warned about at the start (its units, or near incompressibility): it conditions the solves badly", m->sys->parts[i]->name));
    PetscCheck(PetscAbsReal(residual) <= m->watch_balance * scale, m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): the power balance of the step is off by %.3e J, %.2e of the energy %.3e J (bound -watchdog_balance_rtol %g): the midpoint rule holds it to solver tolerance, so Newton or the linear solver failed silently%s; tighten %s or reduce -ts_dt (-watchdog_balance_rtol 0 turns this check off); no result was written",
               step, (double)t, (double)(residual * u->energy), (double)(PetscAbsReal(residual) / scale), (double)(scale * u->energy), (double)m->watch_balance, material, m->condensed ? "-condensed_ksp_rtol" : (m->reduced ? "-snes_rtol/-reduced_ksp_rtol" : "-snes_rtol/-ksp_rtol"));
  }
  if (step > 0 && m->watch_energy > 0) {
    /* energy created from nothing: H_n - H0 - W_n + D_n (less the projections' removals) beyond its scale, the initial
       energy or the work supplied or dissipated: an unstable scheme or a solver gone wrong; with the midpoint rule it
       stays at solver tolerance (a spinning body's indefinite energy can also fall without bound: the deformation
       watchdog catches that) */
    const PetscReal created = H - m->H0 - m->work_total + m->dissipated_total - m->project_dH;
    /* the energy's scale: the initial energies' magnitudes, the work, the potential energy exchanged so far (a
       mechanism released at rest under gravity starts at 0), a floor of 1e-12 of the scene's energy unit (round-off) */
    const PetscReal scale   = PetscMax(PetscMax(PetscMax(m->E0abs, m->max_work), m->max_dV), 1e-12);
    if (created > m->watch_energy * scale) {
      char advice[256], f[32];
      if (m->theta && m->theta_value < 0.5) PetscCall(PetscSNPrintf(advice, sizeof(advice), "-ts_theta_theta %g < 0.5 amplifies every mode the step does not resolve: use 0.5 (the implicit midpoint rule) or more", (double)m->theta_value));
      else if (m->midpoint) PetscCall(PetscSNPrintf(advice, sizeof(advice), "the implicit midpoint rule keeps the balance to solver tolerance where the energy is quadratic: tighten Newton's and the linear solver's tolerances, or reduce -ts_dt (a floating body with full inertia: O(dt^2))"));
      else PetscCall(PetscSNPrintf(advice, sizeof(advice), "reduce -ts_dt, use the implicit midpoint rule, or tighten the solver's tolerances"));
      for (PetscInt i = 0; i < m->sys->nparts; i++)
        if (m->sys->parts[i]->material_warned) {
          PetscCall(PetscSNPrintf(advice, sizeof(advice), "first check body %s's material, warned about at the start (its units, or near incompressibility)", m->sys->parts[i]->name));
          break;
        }
      SETERRQ(m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): the energy is %.4e J, %.3e J more than the initial energy %.4e J plus the work supplied %.4e J less the work dissipated %.4e J, more than -watchdog_energy_factor %s times the energy's scale %.3e J (the largest of the initial energies' magnitudes summed, the work and the potential energy exchanged): the run blew up; %s (-watchdog_energy_factor 0 turns this check off); no result was written",
              step, (double)t, (double)(H * u->energy), (double)(created * u->energy), (double)(m->H0 * u->energy), (double)(m->work_total * u->energy), (double)(m->dissipated_total * u->energy), PhlexFormatReal(m->watch_energy, f, sizeof(f)), (double)(scale * u->energy), advice);
    }
  }
  /* a scheme whose rotations are not re-orthonormalised (BDF, alpha): R^T R - I drifts with the scheme's error */
  if (m->history && !m->orth_warned && m->max_orth > 1e-2 && (m->watch_orth <= 0 || m->max_orth <= m->watch_orth)) {
    m->orth_warned = PETSC_TRUE;
    PetscCall(PetscFPrintf(m->scene->comm, PETSC_STDERR, "phlex: warning: at step %" PetscInt_FMT " (t = %g s) a rotation matrix is off SO(3) by ||R^T R - I||_F = %.3e: this scheme does not keep rotations orthogonal; the run goes on (it stops past -watchdog_orthogonality %g); the implicit midpoint rule or smaller steps keep them\n", step, (double)t, (double)m->max_orth, (double)m->watch_orth));
  }
  PetscCheck(!m->history || m->watch_orth <= 0 || m->max_orth <= m->watch_orth, m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): a rotation matrix is off SO(3) by ||R^T R - I||_F = %.3e, more than -watchdog_orthogonality %g: this scheme does not keep rotations orthogonal (re-orthonormalising them would restart it at every step); use the implicit midpoint rule or smaller steps (-watchdog_orthogonality 0 turns this check off); no result was written", step, (double)t, (double)m->max_orth, (double)m->watch_orth);
  if (m->sys->njoints && m->watch_gap > 0) {
    const PetscReal bound = m->watch_gap * PetscMin(u->length, 1.0);
    PetscCheck(m->max_gap <= bound, m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): a joint is open by %.3e (m or rad), more than %.3e (-watchdog_joint_drift %g x min(L, 1 m)): the constraints drift (a dissipative scheme with large steps?); use the implicit midpoint rule, smaller steps or -joints_project_interval (-watchdog_joint_drift 0 turns this check off); no result was written",
               step, (double)t, (double)m->max_gap, (double)bound, (double)m->watch_gap);
    PetscCheck(m->max_drive <= bound, m->scene->comm, PETSC_ERR_NOT_CONVERGED, "watchdog at step %" PetscInt_FMT " (t = %g s): a drive or prescribed motion is off its profile by %.3e (m or rad), more than %.3e (-watchdog_joint_drift %g x min(L, 1 m)); the joints' other rows are closed to %.3e: %s (-watchdog_joint_drift 0 turns this check off); no result was written",
               step, (double)t, (double)m->max_drive, (double)bound, (double)m->watch_gap, (double)m->max_gap, m->midpoint ? "the implicit midpoint rule follows a drive from the ground to round-off, a drive between two rotating bodies to its error of composing their rotations (O(dt^2) per unit of both angles); use smaller steps or -joints_project_interval, or check Newton's and the linear solver's tolerances" : "this scheme follows a drive only to its error (the midpoint rule follows one from the ground exactly); use the implicit midpoint rule (the default) or smaller steps");
  }
  PetscFunctionReturn(0);
}

/* The solver preset (-solver_options_file) goes under the scene and the command line: insert it, then insert the
   command line again (with its -options_file scenes) so that they keep precedence. */
#define PRESET_RULE "chosen for the scene and process count: exact_serial.opts (CHOLMOD) for fixed bodies on one process, exact.opts on several, exact_krylov.opts with spin or stiffening; bordered_serial.opts with discrete unknowns on one process or bodies whole on one process each, bordered.opts otherwise; rigid.opts without flexible body"

static PetscErrorCode SolverPresetOption(MPI_Comm comm, const char dflt[], char file[], PetscBool *set)
{
  char help[1024];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(help, sizeof(help), "Solver preset (options file) under the scene and command-line options; empty for none (default %s)", dflt));
  PetscOptionsBegin(comm, NULL, "Solver preset", NULL);
  PetscCall(PetscOptionsString("-solver_options_file", help, "PhlexSceneSolveTransient", file, file, PETSC_MAX_PATH_LEN, set));
  PetscOptionsEnd();
  PetscFunctionReturn(0);
}

/* every flexible body's field unknowns on one process (-whole_bodies, -<body>_process): their solvers are sequential */
static PetscErrorCode BodiesWhole(PhlexSystem sys, PetscBool *whole)
{
  PetscInt    nf = sys->nfparts;
  PetscInt   *mine, *all;
  PetscMPIInt size;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(sys->comm, &size));
  *whole = PETSC_TRUE;
  if (size == 1 || !nf) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(nf, &mine, nf, &all));
  for (PetscInt i = 0; i < nf; i++) mine[i] = sys->fparts[i]->nv > 0 ? 1 : 0;
  PetscCallMPI(MPI_Allreduce(mine, all, (PetscMPIInt)nf, MPIU_INT, MPI_SUM, sys->comm));
  for (PetscInt i = 0; i < nf; i++)
    if (all[i] > 1) *whole = PETSC_FALSE;
  PetscCall(PetscFree2(mine, all));
  PetscFunctionReturn(0);
}

/* The default preset: the fastest correct one for the scene on its processes (issue 43, BENCHMARKS.md section 38).
   No flexible body: rigid.opts. Fixed flexible bodies alone (no discrete unknowns): exact_krylov.opts with spin or
   stiffening (its condensed operator is not symmetric: LU), else exact_serial.opts on one process (CHOLMOD: its
   triangular solves run near the bandwidth bound, a step about 1.25-1.7 x faster than MUMPS's, section 19) and
   exact.opts (MUMPS) on several. With discrete unknowns (frames, joints, rigid parts): bordered_serial.opts where
   every flexible body is whole on one process (one process, or -whole_bodies: CHOLMOD per body, section 25, 26),
   else bordered.opts. Without SuiteSparse in the PETSc build the MUMPS presets. */
static PetscErrorCode DefaultSolverPreset(PhlexSystem sys, char file[], char why[], size_t len)
{
  PetscMPIInt size;
  PetscBool   whole = PETSC_TRUE, cholmod = PETSC_FALSE;

  PetscFunctionBeginUser;
#if defined(PETSC_HAVE_SUITESPARSE)
  cholmod = PETSC_TRUE;
#endif
  PetscCallMPI(MPI_Comm_size(sys->comm, &size));
  PetscCall(BodiesWhole(sys, &whole));
  if (!sys->nfparts) {
    PetscCall(PetscStrcpy(file, "options/solver/rigid.opts"));
    PetscCall(PetscSNPrintf(why, len, "default without field unknowns (rigid, lumped and reduced parts): dense LU of the discrete unknowns"));
  } else if (!sys->nq && sys->inexact_schur) {
    PetscCall(PetscStrcpy(file, "options/solver/exact_krylov.opts"));
    PetscCall(PetscSNPrintf(why, len, "default for a fixed body with spin or geometric stiffening: its condensed operator is not symmetric"));
  } else if (!sys->nq) {
    PetscCall(PetscStrcpy(file, size == 1 && cholmod ? "options/solver/exact_serial.opts" : "options/solver/exact.opts"));
    PetscCall(PetscSNPrintf(why, len, "default for fixed bodies on %s: %s", size == 1 ? "one process" : "several processes", size == 1 && cholmod ? "CHOLMOD, the fastest steps" : (cholmod ? "MUMPS, parallel" : "MUMPS (this PETSc has no SuiteSparse)")));
  } else {
    PetscCall(PetscStrcpy(file, whole && cholmod ? "options/solver/bordered_serial.opts" : "options/solver/bordered.opts"));
    PetscCall(PetscSNPrintf(why, len, "default with discrete unknowns%s: %s", size == 1 ? " on one process" : (whole ? ", each flexible body whole on one process" : " on several processes"), whole && cholmod ? "CHOLMOD per body, the fastest steps" : (cholmod ? "MUMPS, parallel" : "MUMPS (this PETSc has no SuiteSparse)")));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode InsertSolverPreset(MPI_Comm comm, PhlexSystem sys, char file[], char why[], size_t len)
{
  PetscBool exists;
  int       argc;
  char    **argv;
  char      dflt[PETSC_MAX_PATH_LEN];
  PetscBool set;

  PetscFunctionBeginUser;
  PetscCall(DefaultSolverPreset(sys, dflt, why, len));
  PetscCall(PetscStrcpy(file, dflt));
  PetscCall(SolverPresetOption(comm, dflt, file, &set));
  if (set) PetscCall(PetscSNPrintf(why, len, "-solver_options_file"));
  if (!file[0]) PetscFunctionReturn(0);
  PetscCall(PetscTestFile(file, 'r', &exists));
  PetscCheck(exists, comm, PETSC_ERR_FILE_OPEN, "cannot read the solver preset '%s' (option -solver_options_file; presets are in options/solver/)", file);
  PetscCall(PetscOptionsInsertFile(comm, NULL, file, PETSC_TRUE));
  PetscCall(PhlexOptionsOriginAddFile(file)); /* its options' file and line, for the messages about them */
  PetscCall(PetscGetArgs(&argc, &argv));
  PetscCall(PetscOptionsInsert(NULL, &argc, &argv, NULL));
  PetscFunctionReturn(0);
}

/* the options of the transient analysis (the self-checks and the energy monitor; TS, SNES and KSP read theirs) */
typedef struct {
  PetscReal   drift_max, drift_abs_max, balance_rtol, momentum_max, linear_max, angular_max, orth_max, gap_max;
  PetscReal   watch_balance, watch_gap, watch_orth, watch_energy, watch_deform;
  PetscReal   velocity_rtol; /* Newton on the whole state: the velocity rows' tolerance (scenes with discrete unknowns) */
  PetscBool   velocity_rtol_set;
  PetscViewer monitor;
  char      **ports; /* -output_ports: body:port names (nports) */
  PetscInt    nports;
  PetscReal   ports_interval;
} TransientOptions;

static PetscErrorCode TransientSetFromOptions(MPI_Comm comm, TransientOptions *o)
{
  PetscBool flg;

  PetscFunctionBeginUser;
  o->drift_max = o->drift_abs_max = o->balance_rtol = o->momentum_max = o->linear_max = o->angular_max = o->orth_max = o->gap_max = -1;
  o->monitor                                                                                                             = NULL;
  o->watch_balance                                                                                                       = 1e-6;
  o->watch_gap                                                                                                           = 1e-2;
  o->watch_orth                                                                                                          = 0.1;
  o->watch_energy                                                                                                        = 1.0;
  o->watch_deform                                                                                                        = 1.0;
  o->velocity_rtol                                                                                                       = 1e-10;
  o->ports_interval                                                                                                      = 0.0;
  PetscCall(PhlexOptionsListLength(NULL, "-output_ports", &o->nports));
  PetscCall(PetscCalloc1(o->nports, &o->ports));
  PetscOptionsBegin(comm, NULL, "Transient analysis options", NULL);
  PetscCall(PetscOptionsStringArray("-output_ports", "Chosen ports body:port,... whose input wrench, output velocities, position and joint wrench go to ports.csv at -output_ports_interval (a controller's or a co-simulation's input)", "PhlexSceneSolveTransient", o->ports, &o->nports, &flg));
  if (!flg) o->nports = 0;
  PetscCall(PetscOptionsReal("-output_ports_interval", "Sampling interval of ports.csv [s]: samples at t = k h, linearly interpolated between the steps around them (0: every step)", "PhlexSceneSolveTransient", o->ports_interval, &o->ports_interval, NULL));
  PetscCall(PetscOptionsReal("-expect_energy_drift_max", "Self-check: bound on max |H - H0| / H0", "PhlexSceneSolveTransient", o->drift_max, &o->drift_max, NULL));
  PetscCall(PetscOptionsReal("-expect_energy_drift_abs_max", "Self-check: bound on max |H - H0| [J] (when H0 is no scale: a mechanism starting at rest)", "PhlexSceneSolveTransient", o->drift_abs_max, &o->drift_abs_max, NULL));
  PetscCall(PetscOptionsReal("-expect_power_balance_rtol", "Self-check: bound on max |H_{n+1} - H_n - W_step| / max |supplied work|", "PhlexSceneSolveTransient", o->balance_rtol, &o->balance_rtol, NULL));
  PetscCall(PetscOptionsReal("-expect_momentum_drift_max", "Self-check (a free system, no loads): bound on the drift of the inertial linear and angular momenta, relative to their scale", "PhlexSceneSolveTransient", o->momentum_max, &o->momentum_max, NULL));
  PetscCall(PetscOptionsReal("-expect_linear_momentum_drift_max", "Self-check (a free system): bound on the drift of the inertial linear momentum alone, relative to its scale", "PhlexSceneSolveTransient", o->linear_max, &o->linear_max, NULL));
  PetscCall(PetscOptionsReal("-expect_angular_momentum_drift_max", "Self-check (a free system): bound on the drift of the inertial angular momentum alone, relative to its scale", "PhlexSceneSolveTransient", o->angular_max, &o->angular_max, NULL));
  PetscCall(PetscOptionsReal("-expect_orthogonality_max", "Self-check (moving frames): bound on max ||R^T R - I||_F", "PhlexSceneSolveTransient", o->orth_max, &o->orth_max, NULL));
  PetscCall(PetscOptionsReal("-expect_joint_drift_max", "Self-check (joints): bound on the largest position-level violation of any joint [m, rad]", "PhlexSceneSolveTransient", o->gap_max, &o->gap_max, NULL));
  PetscCall(PetscOptionsReal("-watchdog_balance_rtol", "Watchdog (implicit midpoint rule): stop when a step's power-balance residual exceeds this share of the energy (0: off)", "PhlexSceneSolveTransient", o->watch_balance, &o->watch_balance, NULL));
  PetscCall(PetscOptionsReal("-watchdog_orthogonality", "Watchdog (BDF, alpha: rotations not re-orthonormalised): stop when ||R^T R - I||_F of a frame exceeds this (0: off; a warning past 1e-2)", "PhlexSceneSolveTransient", o->watch_orth, &o->watch_orth, NULL));
  PetscCall(PetscOptionsReal("-watchdog_joint_drift", "Watchdog: stop when a joint opens by more than this times min(L, 1 m) [m or rad] (0: off)", "PhlexSceneSolveTransient", o->watch_gap, &o->watch_gap, NULL));
  PetscCall(PetscOptionsReal("-watchdog_energy_factor", "Watchdog: stop when the energy created, H - H0 - supplied + dissipated, exceeds this times the energy's scale: the largest of |kinetic| + |strain| + |potential| at the start, the work and the potential energy exchanged (0: off)", "PhlexSceneSolveTransient", o->watch_energy, &o->watch_energy, NULL));
  PetscCall(PetscOptionsReal("-watchdog_deformation", "Watchdog: stop when a flexible body's elastic displacement exceeds this times its size (0: off)", "PhlexSceneSolveTransient", o->watch_deform, &o->watch_deform, NULL));
  PetscCall(PetscOptionsReal("-snes_velocity_rtol", "Newton on the whole state (SNES newtonls: BDF, Crank-Nicolson, generalized-alpha) of a scene with discrete unknowns converges when also the velocity rows' residual is below this share of its value at the stage's initial guess (0: off; not given: 1e-10 in a scene with joints, off without)", "PhlexSystemSNESConvergedStage", o->velocity_rtol, &o->velocity_rtol, &o->velocity_rtol_set));
  PetscCall(PetscOptionsViewer("-ts_monitor_energy", "Print energy, input power and balance residual every step: a PETSc viewer, ascii:<file>.csv:ascii_csv for a CSV file, empty for stdout", "PhlexSceneSolveTransient", &o->monitor, NULL, &flg));
  PetscOptionsEnd();
  PetscCheck(o->velocity_rtol >= 0 && o->velocity_rtol < 1, comm, PETSC_ERR_USER_INPUT, "-snes_velocity_rtol must be in [0, 1) (0: off), got %g", (double)o->velocity_rtol);
  PetscCheck(o->watch_energy >= 0 && !PetscIsInfOrNanReal(o->watch_energy), comm, PETSC_ERR_USER_INPUT, "-watchdog_energy_factor must be a finite number >= 0 (0: off), got %g", (double)o->watch_energy);
  PetscCheck(o->watch_deform >= 0 && !PetscIsInfOrNanReal(o->watch_deform), comm, PETSC_ERR_USER_INPUT, "-watchdog_deformation must be a finite number >= 0 (0: off), got %g", (double)o->watch_deform);
  PetscCheck(o->watch_balance >= 0 && o->watch_gap >= 0 && o->watch_orth >= 0, comm, PETSC_ERR_USER_INPUT, "-watchdog_balance_rtol, -watchdog_joint_drift and -watchdog_orthogonality must be >= 0 (0: off), got %g, %g and %g", (double)o->watch_balance, (double)o->watch_gap, (double)o->watch_orth);
  PetscFunctionReturn(0);
}

/* the option strings TransientSetFromOptions allocated */
static PetscErrorCode TransientOptionsFree(TransientOptions *o)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < o->nports; k++) PetscCall(PetscFree(o->ports[k]));
  PetscCall(PetscFree(o->ports));
  o->nports = 0;
  PetscFunctionReturn(0);
}

/* Newton's Jacobian reuse within a step (PhlexSystemSNESConverged): read after the solver preset, which sets it */
static PetscErrorCode JacobianReuseOption(MPI_Comm comm, PetscReal *rate, PetscBool *set)
{
  PetscFunctionBeginUser;
  *rate = 0.0;
  PetscOptionsBegin(comm, NULL, "Transient analysis: Newton", NULL);
  PetscCall(PetscOptionsReal("-snes_reuse_jacobian_below", "Newton (SNES newtonls) keeps the Jacobian and its factorization for the next iteration of a step when the last iteration reduced the residual norm by at least this factor (a stale Jacobian then contracts about as fast, at the cost of a residual); 0: a new Jacobian every iteration (options/solver/rigid.opts: 0.1)", "PhlexSystemSNESConverged", *rate, rate, set));
  PetscOptionsEnd();
  PetscCheck(*rate >= 0 && *rate < 1, comm, PETSC_ERR_USER_INPUT, "-snes_reuse_jacobian_below must be in [0, 1) (0: off), got %g", (double)*rate);
  PetscFunctionReturn(0);
}

/* every option of a transient run read once more (PhlexOptionsCheckUnused collects the valid names): the scene's,
   the analysis', the solver preset's, and those of TS, SNES, KSP and PC */
PetscErrorCode PhlexTransientRereadOptions(void *ctx)
{
  MPI_Comm         comm = *(MPI_Comm *)ctx;
  TransientOptions o;
  char             file[PETSC_MAX_PATH_LEN] = "";
  TS               ts;

  PetscFunctionBeginUser;
  PetscCall(PhlexSceneReadOptions(comm));
  PetscCall(TransientSetFromOptions(comm, &o));
  PetscCall(PetscViewerDestroy(&o.monitor));
  PetscCall(TransientOptionsFree(&o));
  PetscCall(SolverPresetOption(comm, PRESET_RULE, file, NULL));
  {
    PetscReal rate;
    PetscBool set;
    PetscCall(JacobianReuseOption(comm, &rate, &set));
  }
  {
    MonitorContext m;
    char           restart[PETSC_MAX_PATH_LEN];
    PetscBool      restarting;
    PetscCall(PhlexTransientCheckpointOptions(comm, NULL, &m, restart, &restarting));
  }
  /* a new TS: the run's own prints its options once only */
  PetscCall(TSCreate(comm, &ts));
  PetscCall(TSSetFromOptions(ts));
  PetscCall(TSDestroy(&ts));
  PetscFunctionReturn(0);
}

/* after the first step, every option has been read, the solvers' included (a field split reads its blocks' options
   when it is set up): a misspelt one stops the run here; the time and energy drift of a progress line */
static PetscErrorCode TransientProgress(TS ts, MonitorContext *m, PetscInt step, PetscReal t)
{
  PetscReal tmax, done;
  PetscInt  smax;
  char      drift[96] = "";

  PetscFunctionBeginUser;
  if (step == m->first_step + 1) {
    /* the preset's own options of the solver path not taken (a preset configures both) */
    const char *const generic[] = {"ksp_", "pc_", "fieldsplit_", NULL}, *const stage[] = {"condensed_", "reduced_", "snes_phlexreduced_", NULL};
    const char *const newton[]  = {"ksp_", "pc_", "fieldsplit_", "snes_linesearch_", NULL}; /* phlexreduced takes full steps */
    /* a body's solver options on the path not taken, answered with their equivalents on the path taken */
    static const char *const split_solve[] = {"fieldsplit_1_bordered_", "fieldsplit_velocity_", NULL};
    static const char *const stage_solve[] = {"reduced_bordered_", "condensed_", NULL};
    PetscBool                typed;
    PetscCall(PhlexOptionsSetUsedFromFile(m->preset, m->reduced ? newton : (m->condensed ? generic : stage)));
    PetscCall(PhlexOptionsSetUsedOverridden(m->preset));
    PetscCall(PhlexOptionsCommandLineHasPrefix(generic, &typed));
    if (m->condensed && typed)
      PetscCall(PetscFPrintf(m->scene->comm, PETSC_STDERR, "phlex: note: the steps are solved by SNES phlexcondensed (fixed linear bodies, theta method): its linear solve reads -condensed_ksp_* and -condensed_pc_*; -snes_type ksponly takes the preset's field split, which reads -ksp_*, -pc_*, -fieldsplit_*\n"));
    if (m->reduced && typed)
      PetscCall(PetscFPrintf(m->scene->comm, PETSC_STDERR, "phlex: note: the steps are solved by SNES phlexreduced (Newton on the velocities and discrete unknowns, theta method; a mechanism's consistent start too): its linear solve reads -reduced_ksp_*, -reduced_pc_* and -reduced_bordered_*; -snes_type newtonls takes the preset's field split, which reads -ksp_*, -pc_*, -fieldsplit_*\n"));
    if (m->reduced || m->condensed) PetscCall(PhlexOptionsSetPathRenames(split_solve, stage_solve));
    else PetscCall(PhlexOptionsSetPathRenames(stage_solve, split_solve));
    PetscCall(PhlexOptionsCheckUnused(m->scene->comm, PhlexTransientRereadOptions, &m->scene->comm));
    PetscCall(PhlexOptionsSetPathRenames(NULL, NULL));
  }
  PetscCall(TSGetMaxTime(ts, &tmax));
  PetscCall(TSGetMaxSteps(ts, &smax));
  done = PetscMax(tmax < PETSC_MAX_REAL ? t / tmax : 0.0, smax < PETSC_MAX_INT ? (PetscReal)step / smax : 0.0);
  /* with work supplied or dissipated H - H0 is no error: the step's balance residual is */
  if (m->max_work > 1e-12 * m->Emax) PetscCall(PetscSNPrintf(drift, sizeof(drift), "balance max %.1e J", (double)(m->max_residual * m->scene->units.energy)));
  else if (m->H0 > 1e-6 * m->Emax) PetscCall(PetscSNPrintf(drift, sizeof(drift), "max |H - H0|/H0 %.1e", (double)(m->max_drift / m->H0)));
  else PetscCall(PetscSNPrintf(drift, sizeof(drift), "max |H - H0| %.1e J", (double)(m->max_drift * m->scene->units.energy)));
  if (m->sys->njoints) {
    size_t len;
    PetscCall(PetscStrlen(drift, &len));
    PetscCall(PetscSNPrintf(drift + len, sizeof(drift) - len, ", joints %.1e", (double)m->max_gap));
  }
  PetscCall(PhlexProgressStep(&m->progress, m->scene->comm, step, t, PetscMin(done, 1.0), drift));
  PetscFunctionReturn(0);
}

/* The time step and the end of the run, checked as given (before anything is set up): a run that would do nothing,
   never end or jump to its end in one step is a mistake. */
static PetscErrorCode CheckTimeOptions(MPI_Comm comm)
{
  PetscReal dt = -1, tmax = PETSC_MAX_REAL;
  PetscInt  smax = PETSC_MAX_INT;
  PetscBool fdt, ftmax, fsmax;

  PetscFunctionBeginUser;
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-ts_dt", &dt, &fdt));
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-ts_max_time", &tmax, &ftmax));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-ts_max_steps", &smax, &fsmax));
  PetscCheck(fdt, comm, PETSC_ERR_USER_INPUT, "transient analysis: set the time step with -ts_dt <s>");
  PetscCheck(dt > 0 && !PetscIsInfOrNanReal(dt), comm, PETSC_ERR_USER_INPUT, "-ts_dt must be a positive, finite time step [s], got %g", (double)dt);
  PetscCheck(ftmax || fsmax, comm, PETSC_ERR_USER_INPUT, "transient analysis: set the end of the run with -ts_max_time <s> or -ts_max_steps <n>");
  PetscCheck(!ftmax || (tmax > 0 && !PetscIsInfOrNanReal(tmax)), comm, PETSC_ERR_USER_INPUT, "-ts_max_time must be a positive, finite end time [s], got %g", (double)tmax);
  PetscCheck(!fsmax || smax >= 1, comm, PETSC_ERR_USER_INPUT, "-ts_max_steps must be at least 1, got %" PetscInt_FMT, smax);
  if (ftmax) {
    const PetscReal nsteps = PetscMin(tmax / dt, fsmax ? (PetscReal)smax : PETSC_MAX_REAL);
    PetscCheck(nsteps <= 1e9, comm, PETSC_ERR_USER_INPUT, "-ts_dt %g s to -ts_max_time %g s is %.3g steps, more than 1e9: is -ts_dt in seconds? (bound the run with -ts_max_steps)", (double)dt, (double)tmax, (double)nsteps);
  }
  PetscFunctionReturn(0);
}

/* The span of the run, [t0, tf], against every table profile that may not be extended (PhlexProfileCheckRange): t0 is
   0, or a restart's checkpoint time; tf is -ts_max_time, or the -ts_max_steps steps of -ts_dt (fixed steps), whichever
   comes first, and one step more where TS may step past -ts_max_time (-ts_exact_final_time interpolate or stepover).
   Adaptive steps bounded by a step count alone have no end known in advance: PreStep then checks each step's end. */
static PetscErrorCode CheckProfileRanges(TS ts, MonitorContext *m, const char restart[])
{
  PetscReal              t0 = 0.0, dt, tmax, tf = PETSC_MAX_REAL;
  PetscInt               s0 = 0, smax;
  TSExactFinalTimeOption eft;
  char                   how[256] = "";

  PetscFunctionBeginUser;
  if (restart) {
    PetscViewer v;
    PetscCall(PhlexCheckpointOpenRead(m->scene->comm, restart, &v));
    PetscCall(PhlexCheckpointReadReals(v, "/run", "time", 1, &t0));
    PetscCall(PhlexCheckpointReadInt(v, "/run", "step", &s0));
    PetscCall(PetscViewerDestroy(&v));
  }
  m->profile_t0 = t0;
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCall(TSGetMaxTime(ts, &tmax));
  PetscCall(TSGetMaxSteps(ts, &smax));
  PetscCall(TSGetExactFinalTime(ts, &eft));
  if (tmax < PETSC_MAX_REAL) {
    tf = tmax + (eft == TS_EXACTFINALTIME_MATCHSTEP ? 0.0 : dt);
    PetscCall(PetscSNPrintf(how, sizeof(how), "-ts_max_time %g s%s", (double)tmax, eft == TS_EXACTFINALTIME_MATCHSTEP ? "" : " and a step past it"));
  }
  if (!m->adaptive && smax < PETSC_MAX_INT && t0 + (smax - s0) * dt < tf) {
    tf = t0 + (smax - s0) * dt;
    PetscCall(PetscSNPrintf(how, sizeof(how), "-ts_max_steps %" PetscInt_FMT " of -ts_dt %g s", smax, (double)dt));
  }
  if (restart) {
    size_t len;
    PetscCall(PetscStrlen(how, &len));
    PetscCall(PetscSNPrintf(how + len, sizeof(how) - len, ", restarted at t = %g s", (double)t0));
  }
  m->profile_check_steps = tf == PETSC_MAX_REAL ? PETSC_TRUE : PETSC_FALSE;
  if (!m->profile_check_steps) PetscCall(PhlexProfileCheckRangeAll(t0, tf, how));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSceneSolveTransient - integrates the scene in time with TS and reports energy, power balance and joints

  Collective

  Options Database Keys:
+ -ts_dt <s>                        - time step (required)
. -ts_max_time <s>, -ts_max_steps   - end of the run
. -ts_type theta -ts_theta_theta 0.5 - implicit midpoint (default); cn, bdf, alpha, ... by option
. -ts_monitor_energy [viewer]       - print energy, power and balance residual every step
. -solver_options_file <file>       - solver preset, under scene and command line
. -expect_energy_drift_max <r>      - self-check: max |H - H0| / H0 (lossless runs)
. -expect_energy_drift_abs_max <J> - self-check: max |H - H0| in joules
. -expect_power_balance_rtol <r>    - self-check: max |H_{n+1} - H_n - W| / max |supplied work|
. -expect_momentum_drift_max <r>    - self-check (free system): drift of the inertial momenta, relative to their scale
. -expect_orthogonality_max <r>     - self-check: ||R^T R - I||_F of every frame, and the per-step defect
. -expect_joint_drift_max <r>       - self-check: the largest position-level violation of the joints [m, rad]
. -output_ports body:port,...       - ports.csv: the chosen ports' inputs, outputs, positions and joint wrenches
- -output_ports_interval <s>        - its sampling interval (0: every step)

  Notes:
  Before the first step every table profile that may not be extended (a series read from a file, by default) is
  checked against the run's span (PhlexProfileCheckRange).
@*/
PetscErrorCode PhlexSceneSolveTransient(PhlexScene scene)
{
  PhlexSystem        sys;
  TS                 ts;
  Vec                X;
  MonitorContext     m;
  TransientOptions   o;
  PetscReal          dt = -1, dtlast, tfinal;
  PetscInt           nsteps;
  TSConvergedReason  reason;
  const PhlexUnits  *u = &scene->units;
  PetscViewer        checkpoint = NULL; /* the checkpoint a restart continues */
  char               restart[PETSC_MAX_PATH_LEN];
  PetscBool          restarting = PETSC_FALSE, checkpointing;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&m, sizeof(m)));
  m.last_step = -1;
  PetscCall(TransientSetFromOptions(scene->comm, &o));
  PetscCall(PhlexTransientCheckpointOptions(scene->comm, scene->output, &m, restart, &restarting));
  m.monitor = o.monitor;
  if (PhlexHelpGetMode() == PHLEX_HELP_OPTIONS) {
    char file[PETSC_MAX_PATH_LEN] = "";
    PetscCall(SolverPresetOption(scene->comm, PRESET_RULE, file, NULL));
    PetscCall(PetscViewerDestroy(&m.monitor));
    PetscCall(TransientOptionsFree(&o));
    PetscFunctionReturn(0);
  }
  if (PhlexHelpGetMode() == PHLEX_HELP_NONE) PetscCall(CheckTimeOptions(scene->comm));

  PetscCall(PhlexSystemCreateForScene(scene, &sys, &X));
  m.scene = scene;
  m.sys   = sys;
  /* a free system: every part has momenta, none is held, no joint to the ground, no gravity */
  m.free_system = (scene->gravity[0] == 0.0 && scene->gravity[1] == 0.0 && scene->gravity[2] == 0.0) ? PETSC_TRUE : PETSC_FALSE;
  for (PetscInt i = 0; i < sys->nparts; i++)
    if (!sys->parts[i]->ops.momenta) m.free_system = PETSC_FALSE;
  for (PetscInt k = 0; k < sys->njoints; k++)
    if (PhlexPartIsGround(sys->joints[k]->side[0].part) || PhlexPartIsGround(sys->joints[k]->side[1].part)) m.free_system = PETSC_FALSE;
  PetscCheck(m.free_system || (o.momentum_max < 0 && o.linear_max < 0 && o.angular_max < 0), scene->comm, PETSC_ERR_USER_INPUT, "-expect_*momentum_drift_max needs a free system: floating, rigid or lumped bodies only, none joined to the ground, no gravity");
  {
    PetscBool frames = PETSC_FALSE;
    for (PetscInt i = 0; i < sys->nparts; i++)
      if (sys->parts[i]->frame.R >= 0) frames = PETSC_TRUE;
    PetscCheck(frames || o.orth_max < 0, scene->comm, PETSC_ERR_USER_INPUT, "-expect_orthogonality_max needs a moving frame (a floating or rigid body)");
  }
  PetscCheck(sys->njoints || o.gap_max < 0, scene->comm, PETSC_ERR_USER_INPUT, "-expect_joint_drift_max needs joints");
  PetscCall(InsertSolverPreset(scene->comm, sys, m.preset, m.preset_why, sizeof(m.preset_why)));
  PetscCall(TSCreate(scene->comm, &ts));
  PetscCall(TSSetDM(ts, sys->dm));
  /* linear fields (KSP only); moving frames and joints make it nonlinear (Newton) */
  PetscCall(TSSetProblemType(ts, sys->nonlinear ? TS_NONLINEAR : TS_LINEAR));
  PetscCall(TSSetIFunction(ts, NULL, PhlexSystemIFunction, sys));
  PetscCall(TSSetIJacobian(ts, sys->J, sys->J, PhlexSystemIJacobian, sys));
  /* the structure-preserving default: implicit midpoint */
  PetscCall(TSSetType(ts, TSTHETA));
  PetscCall(TSThetaSetTheta(ts, 0.5));
  PetscCall(TSSetTimeStep(ts, -1.0));
  PetscCall(TSSetMaxTime(ts, PETSC_MAX_REAL));
  PetscCall(TSSetMaxSteps(ts, PETSC_MAX_INT));
  PetscCall(TSSetExactFinalTime(ts, TS_EXACTFINALTIME_MATCHSTEP));
  /* Adaptive steppers (-ts_adapt_type basic, the default of BDF): weights atol + rtol |x| per unknown, rtol from
     -ts_rtol (1e-6). The fields are non-dimensional (velocities ~ 1e-4 of the wave speed), so PETSc's default absolute
     tolerance 1e-4 would accept anything: atol from -ts_atol (1e-12). The frames' positions and rotations are O(1)
     (lengths in L, rotation entries, some of which start at 0): atol = rtol. Their velocities: rtol times the largest
     of the initial speeds, the drives' and prescribed speeds and sqrt(|g| L) (1e-3 if all are zero). The impulses (whose rates are the multipliers of an index-2 system) are
     left out of the error norm. PETSc takes vector tolerances over -ts_rtol/-ts_atol, hence they are read here. */
  {
    Vec        vatol, vrtol;
    PetscReal  vchar = PetscSqrtReal(PhlexNorm3(sys->scene->gravity) * sys->scene->units.length) / sys->scene->units.velocity;
    PetscReal  rtol = 1e-6, atol = 1e-12;
    PetscCall(PetscOptionsGetReal(NULL, NULL, "-ts_rtol", &rtol, NULL));
    PetscCall(PetscOptionsGetReal(NULL, NULL, "-ts_atol", &atol, NULL));
    PetscCheck(rtol > 0 && atol >= 0, scene->comm, PETSC_ERR_USER_INPUT, "-ts_rtol must be positive and -ts_atol non-negative, got %g and %g", (double)rtol, (double)atol);
    PetscCall(VecDuplicate(X, &vatol));
    PetscCall(VecDuplicate(X, &vrtol));
    PetscCall(VecSet(vatol, atol));
    PetscCall(VecSet(vrtol, rtol));
    if (sys->nq) {
      PetscReal *a;
      PetscCall(PhlexSystemGather(sys, X, sys->q));
      for (PetscInt k = 0; k < sys->nq; k++)
        if (sys->qkind[k] == PHLEX_DOF_VELOCITY) vchar = PetscMax(vchar, PetscAbsReal(sys->q[k]));
      for (PetscInt k = 0; k < sys->njoints; k++) {
        const PhlexJoint j = sys->joints[k];
        vchar = PetscMax(vchar, PetscMax(PetscAbsReal(j->drive_velocity) * (j->drive_row >= 0 && j->row[j->drive_row] == PHLEX_ROW_R3 ? scene->units.length : 1.0), PetscMax(PhlexNorm3(j->presc_velocity), PhlexNorm3(j->presc_angular) * scene->units.length)) / scene->units.velocity);
      }
      if (vchar == 0) vchar = 1e-3; /* a scene at rest moved by loads only */
      PetscCall(PetscMalloc1(sys->nq, &a));
      for (PetscInt k = 0; k < sys->nq; k++) {
        const PhlexDofKind kind = sys->qkind[k];
        /* elastic coordinates and their rates: the fields' absolute tolerance (a reduced body's share of the field) */
        a[k] = PhlexDofIsImpulse(kind) ? 1e300 : (kind == PHLEX_DOF_VELOCITY ? rtol * vchar : ((kind == PHLEX_DOF_ELASTIC || kind == PHLEX_DOF_ELASTIC_VELOCITY) ? atol : rtol));
      }
      PetscCall(PhlexSystemScatter(sys, a, vatol));
      for (PetscInt k = 0; k < sys->nq; k++) a[k] = PhlexDofIsImpulse(sys->qkind[k]) ? 0.0 : rtol;
      PetscCall(PhlexSystemScatter(sys, a, vrtol));
      PetscCall(PetscFree(a));
    }
    PetscCall(TSSetTolerances(ts, atol, vatol, rtol, vrtol));
    PetscCall(VecDestroy(&vatol));
    PetscCall(VecDestroy(&vrtol));
  }
  PetscCall(TSSetFromOptions(ts));
  {
    /* the scene's equations are implicit (an index-2 DAE with constraints, a mass matrix, algebraic rows): an
       explicit integrator cannot take them (PETSc refuses it at the first step with a traceback) */
    PetscBool explicit_ts;
    TSType    type;
    PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &explicit_ts, TSEULER, TSRK, TSSSP, TSMPRK, TSGLEE, TSBASICSYMPLECTIC, ""));
    PetscCall(TSGetType(ts, &type));
    PetscCheck(!explicit_ts, scene->comm, PETSC_ERR_USER_INPUT, "-ts_type %s: an explicit integrator cannot take phlex's implicit equations (mass matrices, constraints, algebraic rows); use theta (the implicit midpoint rule, the default), cn, beuler, bdf or alpha", type);
  }
  {
    /* SNES phlexcondensed (the presets exact and iterative ask for it): the theta-method stage of fixed linear bodies by
       exact elimination (snes_condensed.c). Where it does not apply the preset's field split takes over (SNES ksponly, or
       Newton for a nonlinear scene), unless -snes_type phlexcondensed was typed on the command line: then an error
       says why */
    SNES              snes;
    PetscBool         applicable, typed;
    const char *const snestype[] = {"snes_type", NULL};
    PetscCall(TSGetSNES(ts, &snes));
    PetscCall(PetscObjectTypeCompare((PetscObject)snes, "phlexcondensed", &m.condensed));
    if (m.condensed) {
      PetscCall(PhlexSNESCondensedApplicable(sys, ts, &applicable));
      PetscCall(PhlexOptionsCommandLineHasPrefix(snestype, &typed));
      if (applicable || typed) PetscCall(PhlexSNESCondensedSetSystem(snes, sys, ts));
      else {
        KSP ksp;
        /* the field split of the presets for fixed bodies (exact, iterative, ...) splits the fields only: with frames,
           joints or other parts it has no split for their unknowns (PETSc failed with "Could not find index set") */
        PetscCheck(!sys->nq, scene->comm, PETSC_ERR_USER_INPUT, "the solver preset %s is for fixed flexible bodies alone (SNES phlexcondensed, and a field split of their fields only): this scene also has %" PetscInt_FMT " discrete unknowns (frames, rigid bodies, point masses, joints or force elements); use options/solver/bordered.opts (bordered_iterative.opts, bordered_serial.opts), or no -solver_options_file: the default chooses", m.preset[0] ? m.preset : "(-snes_type phlexcondensed)", sys->nq);
        PetscCall(SNESSetType(snes, (sys->nonlinear || sys->inexact_schur) ? SNESNEWTONLS : SNESKSPONLY));
        PetscCall(SNESGetKSP(snes, &ksp));
        PetscCall(KSPSetFromOptions(ksp));
        if (sys->nonlinear || sys->inexact_schur) {
          SNESLineSearch ls;
          PetscBool      preonly;
          PetscCall(SNESGetLineSearch(snes, &ls));
          PetscCall(SNESLineSearchSetFromOptions(ls));
          /* the preset for linear bodies (exact.opts) applies its field split once: with spin or stiffening its
             condensed operator is not the Schur complement, and Newton converges slowly or stops off the balance */
          PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPPREONLY, &preonly));
          if (preonly && sys->inexact_schur) PetscCall(PetscFPrintf(scene->comm, PETSC_STDERR, "phlex: note: a body has geometric stiffening or spin, and the solver preset applies its field split once (-ksp_type preonly, as options/solver/exact.opts does): its condensed operator is then not the exact Schur complement, and Newton may converge slowly or stop off the power balance; options/solver/exact_krylov.opts is the preset for such bodies (the default without -solver_options_file)\n"));
        }
        m.condensed = PETSC_FALSE;
      }
    }
    /* SNES phlexreduced (the preset bordered asks for it): Newton on the velocities and the discrete unknowns of scenes
       with frames and joints, displacement and stress eliminated exactly (snes_reduced.c); the same fall-back */
    PetscCall(PetscObjectTypeCompare((PetscObject)snes, "phlexreduced", &m.reduced));
    if (m.reduced) {
      PetscCall(PhlexSNESReducedApplicable(sys, ts, &applicable));
      PetscCall(PhlexOptionsCommandLineHasPrefix(snestype, &typed));
      if (applicable || typed) PetscCall(PhlexSNESReducedSetSystem(snes, sys, ts));
      else {
        KSP               ksp;
        SNESLineSearch    ls;
        const char *const own[] = {"snes_phlexreduced_", NULL};
        PetscBool         given;
        PetscCall(PhlexOptionsCommandLineHasPrefix(own, &given));
        PetscCheck(!given, scene->comm, PETSC_ERR_USER_INPUT, "-snes_phlexreduced_* options have no effect on this run: its steps are solved by Newton with the field split (SNES newtonls), since the reduced Newton does not apply (a body with geometric stiffening or spin, or an integrator other than the theta method without endpoint)");
        PetscCall(SNESSetType(snes, SNESNEWTONLS));
        PetscCall(SNESGetKSP(snes, &ksp));
        PetscCall(KSPSetFromOptions(ksp));
        PetscCall(SNESGetLineSearch(snes, &ls));
        PetscCall(SNESLineSearchSetFromOptions(ls));
        m.reduced = PETSC_FALSE;
      }
    }
    /* Newton on the whole state multiplies the Jacobian's stress blocks (the stages of phlexcondensed and phlexreduced
       do not, nor does the consistent start of a mechanism, which takes the steps' solver) */
    if (!m.condensed && !m.reduced) PetscCall(PhlexSystemCompleteJacobian(sys));
    if ((m.condensed || m.reduced) && PhlexHelpGetMode() == PHLEX_HELP_SOLVERS) {
      /* what the stage's own solve will read (it is made at the first step) */
      KSP       ksp;
      PC        pc;
      PetscBool bordered;
      PetscCall(KSPCreate(scene->comm, &ksp));
      PetscCall(KSPSetOptionsPrefix(ksp, m.condensed ? "condensed_" : "reduced_"));
      PetscCall(KSPSetFromOptions(ksp));
      PetscCall(KSPGetPC(ksp, &pc));
      PetscCall(PetscObjectTypeCompare((PetscObject)pc, "phlexbordered", &bordered));
      if (bordered && sys->nfparts) {
        /* and the bodies' solvers inside PC phlexbordered, made at its first set-up */
        const char **names;
        PetscCall(PetscMalloc1(sys->nfparts, &names));
        for (PetscInt i = 0; i < sys->nfparts; i++) names[i] = sys->fparts[i]->name;
        PetscCall(PhlexPCBorderedHelp(pc, sys->nfparts, names));
        PetscCall(PetscFree(names));
      }
      PetscCall(KSPDestroy(&ksp));
    }
  }
  if (PhlexHelpGetMode() == PHLEX_HELP_SOLVERS) {
    PetscReal rate;
    PetscBool set;
    PetscCall(JacobianReuseOption(scene->comm, &rate, &set)); /* the solver preset's Newton option, listed too */
    PetscCall(PetscViewerDestroy(&m.monitor));
    PetscCall(TransientOptionsFree(&o));
    PetscCall(VecDestroy(&X));
    PetscCall(TSDestroy(&ts));
    PetscCall(PhlexSystemDestroy(&sys));
    PetscFunctionReturn(0);
  }
  /* a failed step is reported below with the time, the step and what to try */
  PetscCall(TSSetErrorIfStepFails(ts, PETSC_FALSE));
  {
    /* adaptive steps retry a step whose Newton fails or that breaks a watchdog, with a smaller one (PETSc's default
       stops at the first Newton failure; -ts_max_snes_failures keeps a user's bound) */
    TSAdapt   adapt;
    PetscBool none, bound;
    PetscCall(TSGetAdapt(ts, &adapt));
    PetscCall(PetscObjectTypeCompare((PetscObject)adapt, TSADAPTNONE, &none));
    m.adaptive = none ? PETSC_FALSE : PETSC_TRUE;
    if (m.adaptive) {
      PetscCall(TSAdaptSetCheckStage(adapt, CheckStage));
      PetscCall(PetscOptionsHasName(NULL, NULL, "-ts_max_snes_failures", &bound));
      if (!bound) PetscCall(TSSetMaxSNESFailures(ts, -1));
      else PetscCall(PetscOptionsGetInt(NULL, NULL, "-ts_max_snes_failures", &m.max_snes_failures, NULL));
    }
  }
  /* the inputs' series cover the run (a file's, unless told what it is outside): refused before anything is solved */
  PetscCall(CheckProfileRanges(ts, &m, restarting ? restart : NULL));
  PetscCall(PhlexTransientPortsSetUp(&m, o.nports, o.ports, o.ports_interval)); /* -output_ports: the names checked */
  {
    /* PETSc 3.18's generalized-alpha keeps the rate V_{n+1} it computed in the last function evaluation of the step;
       SNES ksponly (the linear presets) evaluates the function only before its solve, so V_{n+1} would be the
       initial guess's and the scheme a different, dissipative one (the cantilever lost 25 % of its energy in 200
       steps at w dt = 0.13, where the scheme's theory says 3e-5). Newton with a basic line search evaluates it at the
       solution: one more residual per step, and the scheme is generalized-alpha (tests/tools/dissipation.py). */
    SNES      snes;
    SNESLineSearch ls;
    PetscBool alpha, ksponly;
    PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSALPHA, &alpha));
    PetscCall(TSGetSNES(ts, &snes));
    PetscCall(PetscObjectTypeCompare((PetscObject)snes, SNESKSPONLY, &ksponly));
    if (alpha && ksponly) {
      PetscCall(SNESSetType(snes, SNESNEWTONLS));
      PetscCall(SNESGetLineSearch(snes, &ls));
      PetscCall(SNESLineSearchSetType(ls, SNESLINESEARCHBASIC));
      PetscCall(PetscPrintf(scene->comm, "Generalized-alpha: SNES newtonls (basic line search) instead of ksponly, so that the scheme's rate is taken at the solution\n"));
    }
  }
  if (sys->nonlinear || sys->inexact_schur) {
    /* Newton (a preset's newtonls also on a linear spinning body: its tolerances are below the round-off floor,
       options/solver/exact_krylov.opts) stops at that floor */
    SNES snes;
    PetscCall(TSGetSNES(ts, &snes));
    /* on the whole state (not phlexreduced, which tests the velocity rows itself) the velocity rows too; by default
       in a scene with joints, whose forces and power moved by 1e-8 of their scale without it (test
       fieldsplit_velocity_rows), not on a single floating body, whose energies it left at the same distance from
       a fully converged solve with 1.5 x the Newton iterations (floating_stiffening_lossless) */
    sys->vrtol = o.velocity_rtol_set ? o.velocity_rtol : (sys->njoints ? o.velocity_rtol : 0.0);
    PetscCall(SNESSetConvergenceTest(snes, m.reduced ? PhlexSystemSNESConverged : PhlexSystemSNESConvergedStage, sys, NULL));
  }
  {
    /* the Jacobian kept for the next Newton iteration of a step after a fast one (a preset's choice: rigid.opts) */
    SNES              snes;
    PetscBool         set, newtonls, lag, typed;
    PetscReal         rate;
    const char *const reuse[] = {"snes_reuse_jacobian_below", NULL};
    PetscCall(JacobianReuseOption(scene->comm, &rate, &set));
    PetscCall(TSGetSNES(ts, &snes));
    PetscCall(PetscObjectTypeCompare((PetscObject)snes, SNESNEWTONLS, &newtonls));
    PetscCall(PetscOptionsHasName(NULL, NULL, "-snes_lag_jacobian", &lag));
    PetscCheck(!(rate > 0 && lag), scene->comm, PETSC_ERR_USER_INPUT, "-snes_reuse_jacobian_below %g and -snes_lag_jacobian both decide when Newton rebuilds its Jacobian: give one (-snes_reuse_jacobian_below 0 turns the first off)", (double)rate);
    PetscCall(PhlexOptionsCommandLineHasPrefix(reuse, &typed));
    PetscCheck(!(typed && rate > 0) || (newtonls && (sys->nonlinear || sys->inexact_schur)), scene->comm, PETSC_ERR_USER_INPUT, "-snes_reuse_jacobian_below has no effect on this run: it applies to Newton on the whole state (SNES newtonls) of a nonlinear scene%s", m.reduced ? "; its steps are solved by SNES phlexreduced" : (m.condensed ? "; its steps are solved by SNES phlexcondensed" : ""));
    sys->jreuse = (newtonls && (sys->nonlinear || sys->inexact_schur)) ? rate : 0.0;
  }
  PetscCheck(!o.velocity_rtol_set || (!m.reduced && !m.condensed && sys->nq && (sys->nonlinear || sys->inexact_schur)), scene->comm, PETSC_ERR_USER_INPUT, "-snes_velocity_rtol has no effect on this run: it applies to Newton on the whole state (SNES newtonls: BDF, Crank-Nicolson, generalized-alpha) of a scene with discrete unknowns; %s", m.reduced ? "its steps are solved by SNES phlexreduced, whose test is -snes_phlexreduced_velocity_rtol" : (m.condensed ? "its steps are solved by SNES phlexcondensed (no Newton)" : (sys->nq ? "the scene is linear (no Newton)" : "the scene has none")));
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCheck(dt > 0, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the time step with -ts_dt <s>");
  m.dt_nominal = dt;
  {
    PetscReal tmax;
    PetscInt  smax;
    PetscCall(TSGetMaxTime(ts, &tmax));
    PetscCall(TSGetMaxSteps(ts, &smax));
    PetscCheck(tmax < PETSC_MAX_REAL || smax < PETSC_MAX_INT, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the end of the run with -ts_max_time <s> or -ts_max_steps <n>");
    /* with adaptive steps (BDF's default) the first step is shortened: then the run is not one step */
    if (!m.adaptive && tmax < PETSC_MAX_REAL && dt >= tmax && smax != 1) PetscCall(PetscFPrintf(scene->comm, PETSC_STDERR, "phlex: warning: -ts_dt %g s is not smaller than -ts_max_time %g s: the run is one step\n", (double)dt, (double)tmax));
  }
  PetscCall(PetscMalloc5(PetscMax(sys->nq, 1), &m.qprev, PetscMax(sys->nq, 1), &m.lambda, PetscMax(sys->njoints, 1), &m.jpower, PetscMax(sys->njoints, 1), &m.jdiss, PetscMax(sys->njoints, 1), &m.jact));
  for (PetscInt k = 0; k < sys->nq; k++) m.lambda[k] = 0.0;
  if (sys->use_aij) {
    /* the assembled operator from a first evaluation at the initial state */
    Vec Xdot;
    PetscCall(VecDuplicate(X, &Xdot));
    PetscCall(VecSet(Xdot, 0.0));
    PetscCall(PhlexSystemIJacobian(ts, 0.0, X, Xdot, 1.0 / dt, sys->J, sys->J, sys));
    PetscCall(VecDestroy(&Xdot));
    {
      /* the assembled operator is the Krylov operator (and -snes_test_jacobian's); a field split takes its blocks
         from the nested one */
      SNES snes;
      KSP  ksp;
      Mat  P;
      PetscCall(TSGetSNES(ts, &snes));
      PetscCall(SNESGetKSP(snes, &ksp));
      PetscCall(PhlexSystemJacobianPmat(sys, ksp, &P));
      PetscCall(TSSetIJacobian(ts, sys->Jaij, P, PhlexSystemIJacobian, sys));
    }
  }
  /* a mechanism starts consistent: loops closed, velocities on the constraints, multipliers solved (a restart
     continues a consistent state) */
  if (sys->njoints && !restarting) PetscCall(PhlexAssemblyClose(sys, 0.0, X, PETSC_TRUE, NULL));
  if (sys->njoints && !restarting) PetscCall(PhlexSystemInitElements(sys, X)); /* the force elements' states from the closed configuration */
  /* drives: the consistent start takes the first step's stage rate (Source) */
  {
    /* (m.midpoint is set below, with the monitor: until issue 42 item 5 this call read it unset, so the consistent
       start took a drive's mean rate W and the steps its stage rate 2 tan(W dt/2)/dt, and a constant-speed drive's
       velocity alternated between the two step by step) */
    PetscBool theta, endpoint = PETSC_FALSE, midpoint;
    PetscReal theta_value = 0;
    PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &theta, TSTHETA, TSCN, TSBEULER, ""));
    if (theta) {
      PetscCall(TSThetaGetTheta(ts, &theta_value));
      PetscCall(TSThetaGetEndpoint(ts, &endpoint));
    }
    midpoint = (theta && !endpoint && theta_value == 0.5) ? PETSC_TRUE : PETSC_FALSE;
    for (PetscInt k = 0; k < sys->njoints && !restarting; k++) PetscCall(PhlexJointDriveStepStart(sys->joints[k], 0.0, dt, midpoint, PETSC_TRUE));
  }
  if (sys->nq && !restarting) PetscCall(PhlexAssemblyConsistentStart(sys, ts, 0.0, dt, X, m.lambda));
  if (!restarting) {
    /* -<body>_ic_steady_spin: the steady state of the frame's spin at the consistent velocities (a drive's stage rate),
       then the multipliers that hold it */
    PetscBool steady = PETSC_FALSE;
    PetscCall(PhlexSystemGather(sys, X, sys->q));
    for (PetscInt i = 0; i < sys->nparts; i++) {
      PhlexPart    part = sys->parts[i];
      PhlexPartVec pv;
      PetscBool    done;
      if (!PhlexPartAnalysisOp(part, steadystart)) continue;
      PetscCall(PhlexSystemPartVec(sys, part, X, sys->q, &pv));
      PetscCall((*part->analysisops->steadystart)(part, &pv, &done));
      PetscCall(PhlexSystemPartVecRestore(sys, part, X, &pv));
      if (done) steady = PETSC_TRUE;
    }
    if (steady && sys->nq) PetscCall(PhlexAssemblyConsistentStart(sys, ts, 0.0, dt, X, m.lambda));
  }
  /* the stages need neither the whole state's stress blocks nor the assembled G and Ms (the initial state did) */
  if (m.reduced || m.condensed) PetscCall(PhlexSystemReleaseJacobian(sys));
  if (m.condensed) PetscCall(PhlexSystemReleaseVelocityBlock(sys)); /* nor the fixed bodies' shift Mv */
  /* what the set-up freed (the initial condition's eigensolve, the operators released above) back to the system
     before the first factorization: else the resident size keeps it, and the factor comes on top */
  PetscCall(PhlexReturnFreedMemory());
  checkpointing = (m.ck_interval > 0 || m.ck_wall > 0) ? PETSC_TRUE : PETSC_FALSE;

  /* monitor and outputs */
  m.scene    = scene;
  m.expect_drift_max = o.drift_max;
  m.sys      = sys;
  m.interval = scene->output->interval;
  PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &m.theta, TSTHETA, TSCN, TSBEULER, ""));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)ts, &m.history, TSBDF, TSALPHA, ""));
  if (m.theta) {
    PetscCall(TSThetaGetTheta(ts, &m.theta_value));
    PetscCall(TSThetaGetEndpoint(ts, &m.endpoint));
  }
  /* the implicit midpoint rule keeps the power balance to solver tolerance for a quadratic Hamiltonian */
  m.lossless_scheme = (m.theta && !m.endpoint && m.theta_value == 0.5) ? PETSC_TRUE : PETSC_FALSE;
  /* a part with dampers: the summary and the monitor say what was dissipated */
  for (PetscInt i = 0; i < sys->nparts; i++)
    if (sys->parts[i]->ops.dissipation) m.dissipative = PETSC_TRUE;
  m.midpoint = (m.theta && !m.endpoint && m.theta_value == 0.5) ? PETSC_TRUE : PETSC_FALSE;
  for (PetscInt k = 0; k < sys->njoints; k++)
    if (sys->joints[k]->drive_row >= 0 || sys->joints[k]->type == PHLEX_JOINT_PRESCRIBED) m.has_drives = PETSC_TRUE;
  for (PetscInt k = 0; k < sys->njoints; k++) {
    if (PhlexJointDamped(sys->joints[k])) m.dissipative = PETSC_TRUE;
    /* PreStep keeps their states and time at a step's start */
    if (sys->joints[k]->ntable > 0 || sys->joints[k]->rest_profile) m.element_tables = PETSC_TRUE;
  }
  for (PetscInt i = 0; i < sys->nparts; i++)
    if (sys->parts[i]->nonquadratic_energy) m.lossless_scheme = PETSC_FALSE;
  m.watch_balance   = o.watch_balance;
  if (!m.theta || m.endpoint || (m.adaptive && m.lossless_scheme && m.watch_balance > 0)) {
    /* the previous state, for the power at the ends of the step (a scheme without a stage to take it at) or for the
       adaptive steps' balance check of the state a step would end at (CheckStage); the theta method's stage needs
       neither */
    PetscCall(VecDuplicate(X, &m.Xprev));
    PetscCall(VecDuplicate(X, &m.Xmid));
  }
  m.watch_gap       = o.watch_gap;
  m.watch_orth      = o.watch_orth;
  m.watch_energy    = o.watch_energy;
  m.watch_deform    = o.watch_deform;
  if (restarting) {
    /* the checkpoint belongs to this run; the outputs continue its */
    PetscCall(PhlexCheckpointOpenRead(scene->comm, restart, &checkpoint));
    PetscCall(PhlexTransientRestartCheck(ts, &m, checkpoint, restart, X));
    PetscCall(PhlexOutputSetRestart(scene->output, checkpoint, restart));
  }
  PetscCall(PhlexOutputCSVOpen(scene->output, "energy.csv", "step,time,kinetic,strain,potential,total,input_power,supplied_work,balance_residual,dissipated_power,dissipated_work", &m.energy_csv));
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall((*sys->parts[i]->ops.outputopen)(sys->parts[i], scene->output, scene->output->fields));
  for (PetscInt k = 0; k < sys->njoints; k++) PetscCall(PhlexJointOutputOpen(sys->joints[k], scene->output));
  PetscCall(PhlexTransientPortsOpen(&m));
  PetscCall(TSMonitorSet(ts, MonitorEnergy, &m, NULL));
  PetscCall(TSSetApplicationContext(ts, &m));
  PetscCall(TSSetPreStep(ts, PreStep));
  PetscCall(TSSetPostStep(ts, PostStep));
  PetscCall(TSSetPostStage(ts, PostStage));
  if (restarting) {
    PetscCall(PhlexOutputRestartCheckUsed(scene->output));
    PetscCall(PhlexTransientRestart(ts, &m, checkpoint, restart, X));
    PetscCall(PetscViewerDestroy(&checkpoint));
    scene->output->restart = NULL;
    /* the H0 the checkpoint carries (the first run's step 0, where the check is made without -restart) */
    PetscCheck(o.drift_max < 0 || m.H0 > 0, scene->comm, PETSC_ERR_USER_INPUT, "-expect_energy_drift_max needs a nonzero initial energy: the run continued from '%s' (option -restart) started with H0 = %g J; bound the drift in joules with -expect_energy_drift_abs_max", restart, (double)(m.H0 * scene->units.energy));
  }
  PetscCall(PetscTime(&m.ck_last));

  PetscCall(PhlexLogStagePush("Phlex Transient", &PHLEX_StageTransient));
  PetscCall(PhlexProgressStart(&m.progress));
  if (restarting) {
    PetscReal tmax, t0;
    PetscInt  smax, s0;
    PetscCall(TSGetMaxTime(ts, &tmax));
    PetscCall(TSGetMaxSteps(ts, &smax));
    PetscCall(TSGetTime(ts, &t0));
    PetscCall(TSGetStepNumber(ts, &s0));
    m.progress.done0 = PetscMin(1.0, PetscMax(tmax < PETSC_MAX_REAL ? t0 / tmax : 0.0, smax < PETSC_MAX_INT ? (PetscReal)s0 / smax : 0.0));
  }
  {
    PetscErrorCode ierr;
    PhlexProgressSetInSteps(PETSC_TRUE); /* the loops inside the steps do not check: a run stops between steps */
    ierr = TSSolve(ts, X);
    PhlexProgressSetInSteps(PETSC_FALSE); /* also when TSSolve failed */
    PetscCall(ierr);
  }
  PetscCall(PetscLogStagePop());
  PetscCall(TSGetStepNumber(ts, &nsteps));
  PetscCall(TSGetSolveTime(ts, &tfinal));
  PetscCall(TSGetConvergedReason(ts, &reason));
  PetscCall(TSGetTimeStep(ts, &dtlast));
  if (reason < 0 && m.last_retry[0]) {
    PetscInt  maxrej = 10; /* PETSc's default; TS has no getter */
    PetscBool snes   = reason == TS_DIVERGED_NONLINEAR_SOLVE ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PetscOptionsGetInt(NULL, NULL, "-ts_max_reject", &maxrej, NULL));
    SETERRQ(scene->comm, PETSC_ERR_NOT_CONVERGED, "transient analysis: step %" PetscInt_FMT " from t = %g s failed (%s), the last try with a time step of %g s because: %s; allow more retries (%s, now %" PetscInt_FMT ") or a smaller step (-ts_adapt_dt_min), tighten the solvers, or check the inputs; no result was written", nsteps + 1, (double)tfinal, TSConvergedReasons[reason], (double)dtlast, m.last_retry, snes ? "-ts_max_snes_failures" : "-ts_max_reject", snes ? m.max_snes_failures : maxrej);
  }
  PetscCheck(reason >= 0, scene->comm, PETSC_ERR_NOT_CONVERGED, "transient analysis: step %" PetscInt_FMT " from t = %g s failed (%s, time step %g s): %s; no result was written", nsteps + 1, (double)tfinal, TSConvergedReasons[reason], (double)dtlast,
             reason == TS_DIVERGED_NONLINEAR_SOLVE ? (m.condensed ? "the condensed solve (SNES phlexcondensed) did not converge: see why with -condensed_ksp_converged_reason, or try a smaller -ts_dt" : m.reduced ? "Newton (SNES phlexreduced) did not converge: try a smaller -ts_dt, adaptive steps (-ts_adapt_type basic: a failed step is then retried with a smaller one), or see why with -snes_converged_reason -reduced_ksp_converged_reason" : "Newton did not converge: try a smaller -ts_dt, adaptive steps (-ts_adapt_type basic: a failed step is then retried with a smaller one), or see why with -snes_converged_reason -ksp_converged_reason") : "too many rejected steps: loosen -ts_rtol/-ts_atol or allow a smaller -ts_adapt_dt_min");
  /* the final state's checkpoint: the run can be continued further (-restart with a later -ts_max_time); written
     before the end-of-run snapshot below, which a longer run would not have */
  if (checkpointing) PetscCall(PhlexTransientCheckpointWrite(ts, &m, X));
  if (m.last_written != nsteps && scene->output->fields) {
    /* the last state's fields (the monitor wrote its series) */
    for (PetscInt i = 0; i < sys->nparts; i++) {
      PhlexPart    p = sys->parts[i];
      PhlexPartVec pv;
      PetscCall(PhlexSystemEvaluate(sys, tfinal, X, NULL));
      PetscCall(PhlexPartGetVec(p, X, sys->q, &pv));
      PetscCall((*p->ops.outputstep)(p, -1, tfinal, &pv, PETSC_TRUE));
      PetscCall(PhlexPartRestoreVec(p, X, &pv));
    }
  }

  {
    TSType type;
    PetscCall(TSGetType(ts, &type));
    PetscCall(PetscPrintf(scene->comm, "Transient: %" PetscInt_FMT " steps to t = %g s with TS %s", nsteps, (double)tfinal, type));
    if (m.theta) PetscCall(PetscPrintf(scene->comm, " (theta %g%s)", (double)m.theta_value, m.endpoint ? ", endpoint" : ""));
    PetscCall(PetscPrintf(scene->comm, "\n  solver preset: %s (%s)", m.preset[0] ? m.preset : "none", m.preset_why));
    PetscCall(PetscPrintf(scene->comm, "\n  energy: initial %.8e J, final %.8e J", (double)(m.H0 * u->energy), (double)(m.Hprev * u->energy)));
    PetscCall(PetscPrintf(scene->comm, ", max |H - H0| %.3e J", (double)(m.max_drift * u->energy)));
    if (m.H0 > 1e-6 * m.Emax) PetscCall(PetscPrintf(scene->comm, " (%.3e of H0)", (double)(m.max_drift / m.H0)));
    PetscCall(PetscPrintf(scene->comm, "\n"));
    if (m.dissipative) PetscCall(PetscPrintf(scene->comm, "  supplied work: %.8e J, dissipated %.8e J, max power-balance residual %.3e J (H_{n+1} - H_n - supplied + dissipated)\n", (double)(m.work_total * u->energy), (double)(m.dissipated_total * u->energy), (double)(m.max_residual * u->energy)));
    else PetscCall(PetscPrintf(scene->comm, "  supplied work: %.8e J, max power-balance residual %.3e J\n", (double)(m.work_total * u->energy), (double)(m.max_residual * u->energy)));
    for (PetscInt i = 0; i < sys->nparts; i++)
      if (sys->parts[i]->frame.R >= 0) {
        if (!m.history) PetscCall(PetscPrintf(scene->comm, "  rotations: max ||R^T R - I||_F = %.3e (largest per-step defect removed %.3e, same norm)\n", (double)m.max_orth, (double)m.max_defect));
        else {
          TSType type;
          PetscCall(TSGetType(ts, &type));
          PetscCall(PetscPrintf(scene->comm, "  rotations: max ||R^T R - I||_F = %.3e (not re-orthonormalised after a step: that would restart TS %s)\n", (double)m.max_orth, type));
        }
        break;
      }
    if (m.free_system) PetscCall(PetscPrintf(scene->comm, "  momenta: max drift of P %.3e, of L %.3e (largest component of P - P0, L - L0, relative to %.6e kg m/s, %.6e kg m^2/s)\n", (double)m.max_dP, (double)m.max_dL, (double)(m.Pscale * u->mass * u->velocity), (double)(m.Lscale * u->mass * u->velocity * u->length)));
    if (m.nretries) PetscCall(PetscPrintf(scene->comm, "  retried steps: %" PetscInt_FMT " (adaptive steps; the last because: %s)\n", m.nretries, m.run_retry));
    if (checkpointing) PetscCall(PetscPrintf(scene->comm, "  checkpoint: %s (step %" PetscInt_FMT ")\n", m.ck_file, m.ck_step));
    if (m.first_step) PetscCall(PetscPrintf(scene->comm, "  restarted at step %" PetscInt_FMT "\n", m.first_step));
    if (sys->njoints) {
      PetscCall(PetscPrintf(scene->comm, "  joints: max position-level violation %.3e (m or rad)", (double)m.max_gap));
      if (m.has_drives) PetscCall(PetscPrintf(scene->comm, "; drives: max error against their profiles %.3e (m or rad)", (double)m.max_drive));
      if (m.nprojections) PetscCall(PetscPrintf(scene->comm, "; %" PetscInt_FMT " projections changed the energy by %.3e J", m.nprojections, (double)(m.project_dH * u->energy)));
      PetscCall(PetscPrintf(scene->comm, "\n"));
    }
  }
  PetscCall(PetscViewerDestroy(&m.energy_csv));
  PetscCall(PhlexTransientPortsDestroy(&m));
  for (PetscInt i = 0; i < sys->nparts; i++) PetscCall((*sys->parts[i]->ops.outputclose)(sys->parts[i]));
  for (PetscInt k = 0; k < sys->njoints; k++) PetscCall(PhlexJointOutputClose(sys->joints[k]));
  PetscCall(PhlexOutputCommit(scene->output));

  if (o.drift_max >= 0) {
    PetscCall(PhlexExpectMax(scene->comm, "energy drift (max |H - H0| / H0)", "-expect_energy_drift_max", m.max_drift / m.H0, o.drift_max, PETSC_TRUE));
  }
  if (o.drift_abs_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "energy drift (max |H - H0|, J)", "-expect_energy_drift_abs_max", m.max_drift * u->energy, o.drift_abs_max, PETSC_TRUE));
  if (o.balance_rtol >= 0) {
    /* no work supplied (round-off only): the largest kinetic + strain energy is the scale */
    const PetscReal scale = m.max_work > 1e-12 * m.Emax ? m.max_work : PetscMax(m.Emax, PETSC_MACHINE_EPSILON);
    PetscCall(PhlexExpectMax(scene->comm, "power balance (max |H_{n+1} - H_n - dt y^T u| / max |supplied work|)", "-expect_power_balance_rtol", m.max_residual / scale, o.balance_rtol, PETSC_TRUE));
  }
  if (o.momentum_max >= 0) {
    PetscCall(PhlexExpectMax(scene->comm, "linear momentum drift (max |P - P0| / scale)", "-expect_momentum_drift_max", m.max_dP, o.momentum_max, PETSC_TRUE));
    PetscCall(PhlexExpectMax(scene->comm, "angular momentum drift (max |L - L0| / scale)", "-expect_momentum_drift_max", m.max_dL, o.momentum_max, PETSC_TRUE));
  }
  if (o.linear_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "linear momentum drift (max |P - P0| / scale)", "-expect_linear_momentum_drift_max", m.max_dP, o.linear_max, PETSC_TRUE));
  if (o.angular_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "angular momentum drift (max |L - L0| / scale)", "-expect_angular_momentum_drift_max", m.max_dL, o.angular_max, PETSC_TRUE));
  if (o.orth_max >= 0) {
    PetscCall(PhlexExpectMax(scene->comm, "rotation orthogonality (max ||R^T R - I||_F)", "-expect_orthogonality_max", m.max_orth, o.orth_max, PETSC_TRUE));
    PetscCall(PhlexExpectMax(scene->comm, "per-step orthogonality defect of the integrator (max ||R^T R - I||_F after a step)", "-expect_orthogonality_max", m.max_defect, o.orth_max, PETSC_TRUE));
  }
  if (o.gap_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "joint drift (max position-level violation, m or rad)", "-expect_joint_drift_max", PetscMax(m.max_gap, m.max_drive), o.gap_max, PETSC_TRUE));

  PetscCall(PetscViewerDestroy(&m.monitor));
  PetscCall(TransientOptionsFree(&o));
  PetscCall(VecDestroy(&m.Xmid));
  PetscCall(VecDestroy(&m.Xprev));
  PetscCall(VecDestroy(&m.Xstage));
  PetscCall(PetscFree5(m.qprev, m.lambda, m.jpower, m.jdiss, m.jact));
  PetscCall(VecDestroy(&X));
  PetscCall(TSDestroy(&ts));
  PetscCall(PhlexSystemDestroy(&sys));
  PetscFunctionReturn(0);
}
