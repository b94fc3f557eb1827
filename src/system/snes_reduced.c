/* SNES "phlexreduced": the stage of the theta method for scenes with discrete unknowns (floating flexible bodies,
   mechanisms: frames, joints, rigid bodies, lumped masses) by Newton on the velocities and discrete unknowns only,
   the displacement and the stress eliminated exactly.

   Each flexible body's field rows (paper eq. (ph-mixed); frame.c for a moving frame) are, in non-dimensional time,
       T u' = v,    T Ms Sigma' = G v,    F_v(u, v, v', q, q') + G^T Sigma = 0,
   and the stage X = X0 + theta dt X' (shift a = 1 / (theta dt), s = a T) satisfies the first two exactly for any v
   when
       u = u0 + v / s,    Sigma = Sigma_p + B (v - v0) / s,    Sigma_p = Sigma0 + B v0 / s,    B = Ms^{-1} G,
   so Newton runs on the rows of v and of the discrete unknowns q (frames, impulses) alone, with
       G^T Sigma = G^T Sigma_p + K (v - v0) / s
   (K = G^T B applied cell by cell, G^T (B v) summed in each cell, so that the residual's stress term is that of the
   final Sigma; the element-assembled condensed stiffness differs from it by about 1e-11 relative, which the velocity
   rows, held to 1e-10 of their scale, would see). The Jacobian of these rows is
       [ Jvv + Jvu / s + K / s    Bvq ]      Jvv, Jvu  the velocity rows' own blocks (shift Mv + node-wise inertia),
       [ Cqv + Cqu / s            D   ]      Bvq, Cq*  the borders (frames, joints' port maps), D the discrete block,
   applied as a shell, and its preconditioner is PC phlexbordered on [[shift Mv + K/shift, B], [C, D]]: the factored
   condensed operators (once per step size), the border bases solved once, a small dense Schur complement per Newton
   step (pcbordered.c).

   A Newton iteration costs one residual (products with Mv and K: velocity sized, no pass over the stress field; the
   first of a stage skips K when it starts at v = v0) and a few Krylov iterations, each one product with the shell and
   one sparse solve per body; a step adds two passes over the cells: Sigma_p = Sigma0 + B v0 / s with G^T Sigma_p
   before Newton (PhlexSystemStressPredict), Sigma after it (PhlexSystemStressCorrect). The generic path (Newton on the
   whole state with a Schur field split) pays two products with G, one with G^T and one with Ms per residual, and
   several per Krylov iteration.

   The linear solve of a Newton iteration that is not the stage's last need not be more accurate than the residual
   that Newton leaves after it: -snes_phlexreduced_forcing (1e-2) asks it for that share of the next residual, as
   predicted by the contraction of the same iteration in the last stage of the same length (an inexact Newton method,
   Eisenstat and Walker's forcing term proportional to the contraction, taken from the last stage instead of the last
   iteration, since a stage takes two or three). A mechanism's first Newton iteration then takes one Krylov iteration
   instead of two (its preconditioner lacks the borders' state-dependent gyroscopic terms, whose error a second
   iteration removes), which saves a fifth of the double pendulum's sparse solves. The iteration predicted to be the
   last is solved to -reduced_ksp_rtol, and Newton never stops right after a looser solve (one more iteration, at
   -reduced_ksp_rtol, follows): the multipliers' accuracy, which the residual's norm does not show, is that of the last
   solve. Where a looser solve cost a Newton iteration (the tumbling bar without its rate in the preconditioner: the
   bilinear gyroscopic terms turn the error of the first iteration's velocity rows into a larger quadratic residual),
   the stages keep the tolerance for 50 stages, then for twice as many each time it costs again. Stages without a TS
   (the consistent start) and stages whose length changed (adaptive steps) solve every iteration to the tolerance. A
   checkpoint keeps the contractions, so that a restart repeats the run that wrote it.

   Used when the scene has discrete unknowns and flexible bodies with constant operators (no geometric stiffening,
   no prescribed spin) and the integrator is the theta method without endpoint (the default implicit midpoint,
   backward Euler). The preset bordered.opts asks for it (-snes_type phlexreduced); where it does not apply the
   transient analysis takes the preset's field split, unless -snes_type phlexreduced was typed on the command line
   (then an error says why). The linear solve is KSP "reduced_" (the preset configures it). The consistent start of a
   mechanism solves its vanishing implicit Euler steps with it too, as stages without a TS (PhlexSNESReducedSetStage). */
#include <phlex_impl.h>
#include <petsc/private/snesimpl.h>

typedef struct {
  PhlexSystem sys;
  TS          ts;
  KSP         ksp;      /* reduced_: Krylov on Jred, PC phlexbordered on the system's {velocity, discrete} operator */
  Mat         Jred;     /* shell: the Jacobian of the velocity and discrete rows, u and Sigma eliminated */
  Mat         K;        /* the bodies' condensed stiffnesses G^T Ms^{-1} G cell by cell (block diagonal, velocity field) */
  PhlexStressMaps maps; /* per body B = Ms^{-1} G, G^T and K, cell by cell (the parts' shells) */
  Vec         Xd, F;    /* whole state: rate, residual */
  Vec         sp;       /* stress field: Sigma_p */
  Vec         P, Pp, dv, wv; /* velocity field: G^T Sigma at the iterate and at Sigma_p, v - v0, work */
  Vec         Z, Dz;    /* {velocity, discrete}: residual, Newton correction */
  IS          isv, isq; /* the blocks of the {velocity, discrete} vectors */
  PetscReal   shift;    /* non-dimensional shift of the Jacobian (0: none yet) */
  Vec         X0;       /* a stage without a TS (PhlexSNESReducedSetStage): its start, time, length and theta */
  PetscReal   t0, dt, theta;
  PetscReal   vrtol;    /* the velocity rows' convergence, relative to their residual at the initial guess */
  PetscReal   forcing;  /* a linear solve that is not Newton's last stops at this share of the next residual */
  PetscReal   ksp_rtol; /* KSP reduced_'s own relative tolerance (the options'), that of a last Newton iteration */
  /* the contractions of the last stage's Newton iterations (residual after / before, the whole and the velocity rows),
     which predict the next stage's when it has the same length */
  PetscReal   rho[PHLEX_REDUCED_HISTORY], rhov[PHLEX_REDUCED_HISTORY], rho_dt, rho_theta;
  PetscInt    niter;    /* the last stage's Newton iterations (0: none to predict from); its first contractions are kept */
  PetscBool   forcing_off; /* paused: at this step size a stage with looser solves took more Newton iterations */
  PetscInt    off_stages, off_wait; /* stages since, and stages until the looser solves are tried again */
} SNES_Reduced;

/* why a scene or an integrator (NULL: a stage without a TS) cannot use the reduced Newton (empty: it can) */
static PetscErrorCode Eligibility(PhlexSystem sys, TS ts, char why[], size_t len)
{
  PetscBool theta = PETSC_TRUE, beuler = PETSC_FALSE, endpoint = PETSC_FALSE;

  PetscFunctionBeginUser;
  why[0] = 0;
  if (ts) {
    PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSTHETA, &theta));
    PetscCall(PetscObjectTypeCompare((PetscObject)ts, TSBEULER, &beuler));
    if (theta) PetscCall(TSThetaGetEndpoint(ts, &endpoint));
  }
  if (!sys->nfparts) PetscCall(PetscSNPrintf(why, len, "the scene has no flexible body"));
  else if (!sys->nq) PetscCall(PetscSNPrintf(why, len, "the scene has no discrete unknowns (no frame, joint, rigid or lumped part: SNES phlexcondensed solves fixed bodies)"));
  else if (sys->state_dependent_fields || sys->inexact_schur) PetscCall(PetscSNPrintf(why, len, "a body's field operators change with the state (geometric stiffening, spin)"));
  else if (!(theta || beuler) || endpoint) {
    TSType type;
    PetscCall(TSGetType(ts, &type));
    PetscCall(PetscSNPrintf(why, len, "the integrator is %s%s; the reduced stage is that of the theta method without endpoint (-ts_type theta, the default implicit midpoint, or beuler)", type, endpoint ? " with endpoint (Crank-Nicolson)" : ""));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedApplicable - whether the scene and the integrator (NULL: a stage without a TS) admit SNES
  phlexreduced

  Collective
@*/
PetscErrorCode PhlexSNESReducedApplicable(PhlexSystem sys, TS ts, PetscBool *ok)
{
  char why[256];

  PetscFunctionBeginUser;
  PetscCall(Eligibility(sys, ts, why, sizeof(why)));
  *ok = why[0] ? PETSC_FALSE : PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedSetSystem - hands SNES phlexreduced the scene's system and the TS whose stages it solves; an error
  names what the scene or the integrator lacks

  Collective
@*/
PetscErrorCode PhlexSNESReducedSetSystem(SNES snes, PhlexSystem sys, TS ts)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;
  char          why[256];

  PetscFunctionBeginUser;
  PetscCall(Eligibility(sys, ts, why, sizeof(why)));
  PetscCheck(!why[0], sys->comm, PETSC_ERR_USER_INPUT, "-snes_type phlexreduced cannot solve this scene's steps: %s; use -snes_type newtonls", why);
  c->sys = sys;
  c->ts  = ts;
  c->X0  = NULL;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedSetStage - hands SNES phlexreduced a theta-method stage without a TS: X = X0 + theta dt X' at time
  t0 + theta dt (the consistent start's vanishing implicit Euler steps); X0 is referenced, not copied, and is read at
  every solve. An error names what the scene lacks.

  Collective
@*/
PetscErrorCode PhlexSNESReducedSetStage(SNES snes, PhlexSystem sys, Vec X0, PetscReal t0, PetscReal dt, PetscReal theta)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;
  char          why[256];

  PetscFunctionBeginUser;
  PetscCall(Eligibility(sys, NULL, why, sizeof(why)));
  PetscCheck(!why[0], sys->comm, PETSC_ERR_USER_INPUT, "-snes_type phlexreduced cannot solve this stage: %s; use -snes_type newtonls", why);
  PetscCheck(dt > 0 && theta > 0 && theta <= 1, sys->comm, PETSC_ERR_ARG_OUTOFRANGE, "SNES phlexreduced: a stage needs dt > 0 and theta in (0, 1], got dt %g, theta %g", (double)dt, (double)theta);
  c->sys   = sys;
  c->ts    = NULL;
  c->X0    = X0;
  c->t0    = t0;
  c->dt    = dt;
  c->theta = theta;
  PetscFunctionReturn(0);
}

/* y = Jred x: velocity rows (Jvv + Jvu / s) xv + K xv / s + Bvq xq, discrete rows (Cqv + Cqu / s) xv + D xq */
static PetscErrorCode MatMult_Reduced(Mat A, Vec x, Vec y)
{
  SNES_Reduced *c;
  PhlexSystem   sys;
  Vec           xv, xq, yv, yq;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ReducedJacobianMult, A, 0, 0, 0));
  PetscCall(MatShellGetContext(A, &c));
  sys = c->sys;
  PetscCall(VecGetSubVector(x, c->isv, &xv));
  PetscCall(VecGetSubVector(x, c->isq, &xq));
  PetscCall(VecGetSubVector(y, c->isv, &yv));
  PetscCall(VecGetSubVector(y, c->isq, &yq));
  PetscCall(MatMult(c->K, xv, yv));
  PetscCall(VecScale(yv, 1.0 / c->shift));
  PetscCall(MatMultAdd(sys->Jvc, xv, yv, yv));
  PetscCall(MatMult(sys->Bvq, xq, c->wv));
  PetscCall(VecAXPY(yv, 1.0, c->wv));
  PetscCall(MatMult(sys->Cpre, xv, yq)); /* Cv^T + Cu^T / shift, the joints' rows included */
  PetscCall(MatMultAdd(sys->Dq, xq, yq, yq));
  PetscCall(VecRestoreSubVector(y, c->isq, &yq));
  PetscCall(VecRestoreSubVector(y, c->isv, &yv));
  PetscCall(VecRestoreSubVector(x, c->isq, &xq));
  PetscCall(VecRestoreSubVector(x, c->isv, &xv));
  PetscCall(PetscLogEventEnd(PHLEX_ReducedJacobianMult, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSetUp_Reduced(SNES snes)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;
  PhlexSystem   sys;
  const char   *prefix;
  PC            pc;

  PetscFunctionBeginUser;
  PetscCheck(c->sys, PetscObjectComm((PetscObject)snes), PETSC_ERR_ORDER, "SNES phlexreduced: neither PhlexSNESReducedSetSystem() nor PhlexSNESReducedSetStage() was called");
  if (c->ksp) PetscFunctionReturn(0);
  sys = c->sys;
  PetscCheck(sys->Jvc, sys->comm, PETSC_ERR_PLIB, "SNES phlexreduced: a body has no velocity block with the displacement eliminated");
  PetscCall(PetscLogEventBegin(PHLEX_ReducedSetUp, 0, 0, 0, 0));
  PetscCall(KSPCreate(sys->comm, &c->ksp));
  PetscCall(PetscObjectIncrementTabLevel((PetscObject)c->ksp, (PetscObject)snes, 1));
  PetscCall(SNESGetOptionsPrefix(snes, &prefix));
  PetscCall(KSPSetOptionsPrefix(c->ksp, prefix));
  PetscCall(KSPAppendOptionsPrefix(c->ksp, "reduced_"));
  /* defaults for a run without preset (the preset bordered.opts gives the same): the preconditioner is exact but for
     the state-dependent inertia terms, so a few iterations of a Krylov method that accepts it converge */
  PetscCall(KSPSetType(c->ksp, KSPFGMRES));
  PetscCall(KSPSetTolerances(c->ksp, 1e-12, 0.0, PETSC_DEFAULT, 200));
  PetscCall(KSPGetPC(c->ksp, &pc));
  PetscCall(PCSetType(pc, "phlexbordered"));
  PetscCall(KSPSetFromOptions(c->ksp));
  PetscCall(KSPGetTolerances(c->ksp, &c->ksp_rtol, NULL, NULL, NULL));
  /* B, G^T and K = G^T B per body, cell by cell from the element structure (nothing assembled). K is the stress rows'
     elimination as the final Sigma = Sigma_p + B (v - v0) / s sees it: the same cell sums as G^T (B v) (the
     element-assembled condensed stiffness differs from it by about 1e-11 relative, which the velocity rows, held to
     1e-10 of their scale, would see) */
  PetscCall(PhlexSystemGetStressMaps(sys, "phlexreduced", &c->maps));
  PetscCall(PhlexSystemBlockDiagonal(sys, c->maps.K, PHLEX_FIELD_VELOCITY, PHLEX_FIELD_VELOCITY, &c->K));
  PetscCall(VecDuplicate(snes->vec_sol, &c->Xd));
  PetscCall(VecDuplicate(snes->vec_sol, &c->F));
  PetscCall(MatCreateVecs(sys->Jvs, &c->sp, &c->P)); /* stress columns, velocity rows */
  PetscCall(VecDuplicate(c->P, &c->Pp));
  PetscCall(VecDuplicate(c->P, &c->dv));
  PetscCall(VecDuplicate(c->P, &c->wv));
  PetscCall(PetscLogEventEnd(PHLEX_ReducedSetUp, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* the {velocity, discrete} operator of PC phlexbordered and the shell on its layout (once the first Jacobian has set
   the shift: the preconditioning matrix needs it) */
static PetscErrorCode SetUpOperators(SNES_Reduced *c)
{
  PhlexSystem sys = c->sys;
  Mat         Pvq;
  PetscInt    fields[2] = {sys->field[PHLEX_FIELD_VELOCITY], sys->field[PHLEX_FIELD_DISCRETE]}, m, M;
  IS          rows[2];

  PetscFunctionBeginUser;
  if (c->Jred) PetscFunctionReturn(0);
  PetscCall(PhlexSystemPmat(sys, 2, fields, &Pvq));
  PetscCall(MatNestGetISs(Pvq, rows, NULL));
  PetscCall(PetscObjectReference((PetscObject)rows[0]));
  PetscCall(PetscObjectReference((PetscObject)rows[1]));
  c->isv = rows[0];
  c->isq = rows[1];
  PetscCall(MatGetLocalSize(Pvq, &m, NULL));
  PetscCall(MatGetSize(Pvq, &M, NULL));
  PetscCall(PhlexMatCreateShell(sys->comm, m, m, M, M, c, MatMult_Reduced, &c->Jred));
  PetscCall(PetscObjectSetName((PetscObject)c->Jred, "reduced Jacobian"));
  PetscCall(MatCreateVecs(Pvq, &c->Z, &c->Dz));
  PetscCall(KSPSetOperators(c->ksp, c->Jred, Pvq));
  PetscFunctionReturn(0);
}

/* Z = [F_v; F_q] of the whole-state residual F (both blocks contiguous on every rank, in that order) */
static PetscErrorCode GatherReduced(SNES_Reduced *c, Vec F, Vec Z)
{
  PhlexSystem sys = c->sys;
  Vec         fv, fq, zv, zq;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &fv));
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_DISCRETE], &fq));
  PetscCall(VecGetSubVector(Z, c->isv, &zv));
  PetscCall(VecGetSubVector(Z, c->isq, &zq));
  PetscCall(VecCopy(fv, zv));
  PetscCall(VecCopy(fq, zq));
  PetscCall(VecRestoreSubVector(Z, c->isq, &zq));
  PetscCall(VecRestoreSubVector(Z, c->isv, &zv));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_DISCRETE], &fq));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &fv));
  PetscFunctionReturn(0);
}

/* X_v -= Dz_v, X_q -= Dz_q, X_u = u0 + X_v / s */
static PetscErrorCode Update(SNES_Reduced *c, Vec X, Vec X0, PetscReal s)
{
  PhlexSystem sys = c->sys;
  Vec         xv, xq, xu, u0, dv, dq;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(c->Dz, c->isv, &dv));
  PetscCall(VecGetSubVector(c->Dz, c->isq, &dq));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscCall(VecAXPY(xv, -1.0, dv));
  PetscCall(VecAXPY(xq, -1.0, dq));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecWAXPY(xu, 1.0 / s, xv, u0));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISCRETE], &xq));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
  PetscCall(VecRestoreSubVector(c->Dz, c->isq, &dq));
  PetscCall(VecRestoreSubVector(c->Dz, c->isv, &dv));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSolve_Reduced(SNES snes)
{
  SNES_Reduced      *c   = (SNES_Reduced *)snes->data;
  PhlexSystem        sys = c->sys;
  Vec                X   = snes->vec_sol, X0, s0, v0, xs, xv, xu, u0;
  PetscReal          t, dt, theta, a, s, tstage, fnorm, xnorm, snorm = 0.0, fv, fv0, fvprev = 0.0, f0 = 0.0, fprev = 0.0;
  PetscReal          rho[PHLEX_REDUCED_HISTORY], rhov[PHLEX_REDUCED_HISTORY];
  PetscInt           its = 0;
  PetscBool          loose = PETSC_FALSE, loosened = PETSC_FALSE, history, kept;
  KSPConvergedReason kreason;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ReducedStage, 0, 0, 0, 0));
  snes->reason = SNES_CONVERGED_ITERATING;
  snes->iter   = 0;
  snes->norm   = 0.0;
  if (c->ts) {
    PetscCall(TSGetSolution(c->ts, &X0));
    PetscCall(TSGetTime(c->ts, &t));
    PetscCall(TSGetTimeStep(c->ts, &dt));
    PetscCall(TSThetaGetTheta(c->ts, &theta));
  } else {
    X0    = c->X0;
    t     = c->t0;
    dt    = c->dt;
    theta = c->theta;
  }
  a      = 1.0 / (theta * dt);
  s      = a * sys->units->time;
  /* the last stage's contractions predict this one's if it has the same length (not across the consistent start's
     vanishing steps and the steps, nor a change of step size) */
  history = (PetscBool)(c->niter > 0 && c->rho_dt == dt && c->rho_theta == theta);
  if (!(c->rho_dt == dt && c->rho_theta == theta)) {
    c->forcing_off = PETSC_FALSE;
    c->off_wait    = 0;
  }
  tstage = t + theta * dt;
  c->shift = s;

  /* Sigma_p = Sigma0 + B v0 / s and its resultant G^T Sigma_p; the stage's stress block holds Sigma_p during Newton
     (the residual does not read it; the norm of the state does) */
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_STRESS], &s0));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_VELOCITY], &v0));
  PetscCall(PhlexSystemStressPredict(sys, &c->maps, v0, s0, 1.0 / s, c->sp, c->Pp));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_STRESS], &s0));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  PetscCall(VecCopy(c->sp, xs));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  /* the initial guess's displacement consistent with its velocity */
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecGetSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecWAXPY(xu, 1.0 / s, xv, u0));
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_DISPLACEMENT], &u0));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &xu));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));

  fv0 = -1.0;
  for (;;) {
    /* the residual at the iterate: X' = a (X - X0), G^T Sigma = G^T Sigma_p + K (v - v0) / s */
    PetscCall(VecWAXPY(c->Xd, -1.0, X0, X));
    PetscCall(VecScale(c->Xd, a));
    PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
    PetscCall(VecWAXPY(c->dv, -1.0, v0, xv));
    PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &xv));
    {
      /* the initial guess is mostly the step's start (TSTHETA without extrapolation): v = v0, and K 0 would be a pass
         over the cells for nothing */
      PetscReal dvmax = 1.0;
      if (!snes->iter) PetscCall(VecNorm(c->dv, NORM_INFINITY, &dvmax));
      if (dvmax == 0.0) PetscCall(VecCopy(c->Pp, c->P));
      else {
        PetscCall(MatMult(c->K, c->dv, c->P));
        PetscCall(VecAYPX(c->P, 1.0 / s, c->Pp));
      }
    }
    PetscCall(PhlexSystemReducedResidual(sys, tstage, X, c->Xd, c->P, c->F));
    if (!c->Jred) {
      /* the first Jacobian sets the shift the preconditioning matrix needs */
      PetscCall(PhlexSystemIJacobian(c->ts, tstage, X, c->Xd, a, sys->J, sys->J, sys));
      PetscCall(SetUpOperators(c));
    }
    PetscCall(GatherReduced(c, c->F, c->Z));
    PetscCall(VecNorm(c->Z, NORM_2, &fnorm));
    {
      Vec zv;
      PetscCall(VecGetSubVector(c->Z, c->isv, &zv));
      PetscCall(VecNorm(zv, NORM_2, &fv));
      PetscCall(VecRestoreSubVector(c->Z, c->isv, &zv));
      if (fv0 < 0) {
        fv0 = fv;
        f0  = fnorm;
      }
    }
    if (snes->iter > 0 && snes->iter <= PHLEX_REDUCED_HISTORY) {
      rho[snes->iter - 1]  = fprev > 0 ? fnorm / fprev : 0.0;
      rhov[snes->iter - 1] = fvprev > 0 ? fv / fvprev : 0.0;
    }
    PetscCall(PetscInfo(snes, "Newton iteration %" PetscInt_FMT ": residual %g, of its velocity rows %g (%g of their initial value)\n", snes->iter, (double)fnorm, (double)fv, (double)(fv0 > 0 ? fv / fv0 : 0.0)));
    PetscCall(VecNorm(X, NORM_2, &xnorm));
    if (PetscIsInfOrNanReal(fnorm)) {
      snes->reason = SNES_DIVERGED_FNORM_NAN;
      break;
    }
    snes->norm  = fnorm;
    snes->xnorm = xnorm;
    snes->ynorm = snorm;
    PetscCall(SNESLogConvergenceHistory(snes, fnorm, snes->iter ? its : 0));
    PetscCall(SNESMonitor(snes, snes->iter, fnorm));
    PetscUseTypeMethod(snes, converged, snes->iter, xnorm, snorm, fnorm, &snes->reason, snes->cnvP);
    /* the velocity rows are orders of magnitude smaller than the discrete ones (mass-matrix entries, elastic
       velocities): the norm of the whole residual does not see them, so they are also held to their own scale */
    if (snes->reason > 0 && fv > c->vrtol * fv0 && !(snes->iter > 0 && fv > 0.5 * fvprev)) snes->reason = SNES_CONVERGED_ITERATING;
    /* Newton's last step is always solved to the linear tolerance: the multipliers' accuracy, which the residual's
       norm does not show, is that step's; so a looser step is followed by one more (kept to the tolerance) */
    kept = (PetscBool)(snes->reason > 0 && loose && snes->iter < snes->max_its);
    if (kept) snes->reason = SNES_CONVERGED_ITERATING;
    if (!snes->reason && snes->iter >= snes->max_its) snes->reason = SNES_DIVERGED_MAX_IT;
    fvprev = fv;
    fprev  = fnorm;
    if (snes->reason) break;
    /* the Newton step: Jred dz = Z, to the linear tolerance, or to a share of the next residual when the last stage's
       contraction says that another Newton iteration follows anyway */
    {
      PetscReal rtol = c->ksp_rtol;
      loose          = PETSC_FALSE;
      /* not in a stage without a TS (the consistent start: its two stages are different problems), not at the
         iteration that ended the last stage, nor at one whose successor max_its would end */
      if (c->forcing > 0 && c->ts && history && !c->forcing_off && !kept && snes->iter < PHLEX_REDUCED_HISTORY && snes->iter + 1 < c->niter && snes->iter + 1 < snes->max_its) {
        const PetscReal fnext = c->rho[snes->iter] * fnorm, fvnext = c->rhov[snes->iter] * fv;
        const PetscReal ftarget = PetscMax(snes->abstol, snes->rtol * f0);
        if (fnext > 100.0 * ftarget || fvnext > 100.0 * c->vrtol * fv0) {
          /* a share of the whole residual's predicted contraction; one that is not clearly looser saves nothing */
          const PetscReal share = c->forcing * PetscMin(c->rho[snes->iter], 1.0);
          if (share >= 10.0 * c->ksp_rtol) {
            rtol     = share;
            loose    = PETSC_TRUE;
            loosened = PETSC_TRUE;
          }
        }
      }
      PetscCall(KSPSetTolerances(c->ksp, rtol, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT));
    }
    PetscCall(PhlexSystemIJacobian(c->ts, tstage, X, c->Xd, a, sys->J, sys->J, sys));
    PetscCall(KSPSolve(c->ksp, c->Z, c->Dz));
    PetscCall(KSPGetIterationNumber(c->ksp, &its));
    PetscCall(KSPGetConvergedReason(c->ksp, &kreason));
    snes->linear_its += its;
    if (kreason < 0) {
      snes->numLinearSolveFailures++;
      snes->reason = SNES_DIVERGED_LINEAR_SOLVE;
      break;
    }
    PetscCall(VecNorm(c->Dz, NORM_2, &snorm));
    PetscCall(Update(c, X, X0, s));
    snes->iter++;
  }
  /* a looser solve whose error the next Newton step could not absorb (the bilinear gyroscopic terms turn it into a
     larger quadratic residual) cost a Newton iteration, more than it saved: the looser solves pause, and are tried
     again after 50 stages, then after twice as many each time they cost again (the motion changes) */
  if (loosened && (snes->reason <= 0 || snes->iter > c->niter)) {
    c->forcing_off = PETSC_TRUE;
    c->off_stages  = 0;
    c->off_wait    = c->off_wait ? 2 * c->off_wait : 50;
  } else if (c->forcing_off && ++c->off_stages >= c->off_wait) c->forcing_off = PETSC_FALSE;
  if (snes->reason > 0) {
    for (PetscInt k = 0; k < PetscMin(snes->iter, PHLEX_REDUCED_HISTORY); k++) {
      c->rho[k]  = rho[k];
      c->rhov[k] = rhov[k];
    }
    c->niter     = snes->iter;
    c->rho_dt    = dt;
    c->rho_theta = theta;
  } else c->niter = 0;
  PetscCall(VecRestoreSubVector(X0, sys->is[PHLEX_FIELD_VELOCITY], &v0));
  /* Sigma = Sigma_p + B (v - v0) / s: the stress whose resultant the momentum rows saw (through K) */
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  PetscCall(PhlexSystemStressCorrect(sys, &c->maps, c->dv, c->sp, 1.0 / s, xs));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &xs));
  PetscCall(PetscLogEventEnd(PHLEX_ReducedStage, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESReset_Reduced(SNES snes)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;

  PetscFunctionBeginUser;
  PetscCall(KSPDestroy(&c->ksp));
  PetscCall(MatDestroy(&c->Jred));
  PetscCall(MatDestroy(&c->K));
  if (c->sys) PetscCall(PhlexSystemStressMapsDestroy(c->sys, &c->maps));
  PetscCall(VecDestroy(&c->Xd));
  PetscCall(VecDestroy(&c->F));
  PetscCall(VecDestroy(&c->sp));
  PetscCall(VecDestroy(&c->P));
  PetscCall(VecDestroy(&c->Pp));
  PetscCall(VecDestroy(&c->dv));
  PetscCall(VecDestroy(&c->wv));
  PetscCall(VecDestroy(&c->Z));
  PetscCall(VecDestroy(&c->Dz));
  PetscCall(ISDestroy(&c->isv));
  PetscCall(ISDestroy(&c->isq));
  c->shift = 0.0;
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESDestroy_Reduced(SNES snes)
{
  PetscFunctionBeginUser;
  PetscCall(SNESReset_Reduced(snes));
  PetscCall(PetscFree(snes->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESSetFromOptions_Reduced(SNES snes, PetscOptionItems *PetscOptionsObject)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;

  PetscFunctionBeginUser;
  PetscOptionsHeadBegin(PetscOptionsObject, "SNES phlexreduced options");
  PetscCall(PetscOptionsReal("-snes_phlexreduced_velocity_rtol", "Newton converges when also the velocity rows' residual is below this share of its value at the initial guess", "SNESPHLEXREDUCED", c->vrtol, &c->vrtol, NULL));
  PetscCall(PetscOptionsReal("-snes_phlexreduced_forcing", "A Newton step that the last stage's contraction says is not the last is solved to this share of the predicted next residual (0: every step to -reduced_ksp_rtol)", "SNESPHLEXREDUCED", c->forcing, &c->forcing, NULL));
  PetscOptionsHeadEnd();
  PetscCheck(c->vrtol > 0 && c->vrtol < 1, PetscObjectComm((PetscObject)snes), PETSC_ERR_USER_INPUT, "-snes_phlexreduced_velocity_rtol must be in (0, 1), got %g", (double)c->vrtol);
  PetscCheck(c->forcing >= 0 && c->forcing < 1, PetscObjectComm((PetscObject)snes), PETSC_ERR_USER_INPUT, "-snes_phlexreduced_forcing must be in [0, 1), got %g", (double)c->forcing);
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESView_Reduced(SNES snes, PetscViewer viewer)
{
  SNES_Reduced *c = (SNES_Reduced *)snes->data;
  PetscBool     ascii;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  Newton on the velocities and discrete unknowns of a theta-method stage, displacement and stress eliminated exactly; linear solve:\n"));
  if (c->ksp) {
    PetscCall(PetscViewerASCIIPushTab(viewer));
    PetscCall(KSPView(c->ksp, viewer));
    PetscCall(PetscViewerASCIIPopTab(viewer));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode SNESCreate_Reduced(SNES snes)
{
  SNES_Reduced *c;

  PetscFunctionBeginUser;
  snes->ops->setup                  = SNESSetUp_Reduced;
  snes->ops->solve                  = SNESSolve_Reduced;
  snes->ops->reset                  = SNESReset_Reduced;
  snes->ops->destroy                = SNESDestroy_Reduced;
  snes->ops->view                   = SNESView_Reduced;
  snes->ops->setfromoptions         = SNESSetFromOptions_Reduced;
  snes->usesksp                     = PETSC_FALSE; /* its own KSP, prefix reduced_ (the preset configures SNES's for the generic path) */
  snes->usesnpc                     = PETSC_FALSE;
  snes->alwayscomputesfinalresidual = PETSC_FALSE;
  PetscCall(PetscNew(&c));
  c->vrtol   = 1e-10;
  c->forcing = 1e-2;
  snes->data = (void *)c;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedGetContractions - the contractions of the last stage's Newton iterations, which set the next
  stage's linear tolerances (-snes_phlexreduced_forcing): a checkpoint keeps them so that a restart repeats the run
  that wrote it; all zero for another SNES type

  Not collective
@*/
PetscErrorCode PhlexSNESReducedGetContractions(SNES snes, PetscReal rec[PHLEX_REDUCED_NCONTRACTIONS])
{
  PetscBool reduced;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < PHLEX_REDUCED_NCONTRACTIONS; i++) rec[i] = 0.0;
  PetscCall(PetscObjectTypeCompare((PetscObject)snes, "phlexreduced", &reduced));
  if (reduced) {
    SNES_Reduced *c = (SNES_Reduced *)snes->data;
    rec[0]          = (PetscReal)c->niter;
    rec[1]          = c->rho_dt;
    rec[2]          = c->rho_theta;
    rec[3]          = c->forcing_off ? 1.0 : 0.0;
    rec[4]          = (PetscReal)c->off_stages;
    rec[5]          = (PetscReal)c->off_wait;
    for (PetscInt k = 0; k < PetscMin(c->niter, PHLEX_REDUCED_HISTORY); k++) {
      rec[6 + k]                         = c->rho[k];
      rec[6 + PHLEX_REDUCED_HISTORY + k] = c->rhov[k];
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedSetContractions - restores what PhlexSNESReducedGetContractions gave (nothing for another SNES type)

  Not collective
@*/
PetscErrorCode PhlexSNESReducedSetContractions(SNES snes, const PetscReal rec[PHLEX_REDUCED_NCONTRACTIONS])
{
  PetscBool reduced;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)snes, "phlexreduced", &reduced));
  if (reduced) {
    SNES_Reduced *c = (SNES_Reduced *)snes->data;
    c->niter        = PetscMax((PetscInt)rec[0], 0);
    c->rho_dt       = rec[1];
    c->rho_theta    = rec[2];
    c->forcing_off  = rec[3] != 0.0 ? PETSC_TRUE : PETSC_FALSE;
    c->off_stages   = PetscMax((PetscInt)rec[4], 0);
    c->off_wait     = PetscMax((PetscInt)rec[5], 0);
    for (PetscInt k = 0; k < PetscMin(c->niter, PHLEX_REDUCED_HISTORY); k++) {
      c->rho[k]  = rec[6 + k];
      c->rhov[k] = rec[6 + PHLEX_REDUCED_HISTORY + k];
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSNESReducedRegister - registers the SNES type "phlexreduced"
@*/
PetscErrorCode PhlexSNESReducedRegister(void)
{
  PetscFunctionBeginUser;
  PetscCall(SNESRegister("phlexreduced", SNESCreate_Reduced));
  PetscFunctionReturn(0);
}
