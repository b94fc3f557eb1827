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
static PetscErrorCode SetKinematicIC(PhlexScene scene, const PhlexIC *ic, const char field[], PetscReal scale, Vec x, PetscReal rigid[6])
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
    PetscReal *lambda, *q, vmax, vmin, f;
    Vec       *vecs;
    PetscCall(PhlexBodyComputeModes(b, &scene->units, ic->mode, &nconv, &nrigid, &lambda, &vecs, &q, NULL));
    PetscCheck(nconv >= nrigid + ic->mode, b->comm, PETSC_ERR_NOT_CONVERGED, "body %s: elastic mode %" PetscInt_FMT " for -%sic_%s_mode was not found (%" PetscInt_FMT " converged)", b->name, ic->mode, b->prefix, field, nconv - nrigid);
    PetscCall(VecCopy(vecs[nrigid + ic->mode - 1], x));
    PetscCall(VecMax(x, NULL, &vmax));
    PetscCall(VecMin(x, NULL, &vmin));
    /* largest component positive, largest magnitude = amplitude: the same field on any number of ranks */
    f = (vmax >= -vmin ? 1.0 / vmax : 1.0 / vmin) * ic->amplitude * scale;
    PetscCall(VecScale(x, f));
    /* a floating body's mode carries the rigid motion that keeps its momenta zero */
    if (rigid)
      for (PetscInt k = 0; k < 6; k++) rigid[k] = b->floating ? f * q[6 * (nrigid + ic->mode - 1) + k] : 0.0;
    for (PetscInt i = 0; i < nconv; i++) PetscCall(VecDestroy(&vecs[i]));
    PetscCall(PetscFree(vecs));
    PetscCall(PetscFree(q));
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
  PetscReal mode_rigid[6] = {0, 0, 0, 0, 0, 0};

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(SetKinematicIC(scene, &b->ic_velocity, "velocity", 1.0 / scene->units.velocity, v, mode_rigid));
  PetscCall(SetKinematicIC(scene, &b->ic_displacement, "displacement", 1.0 / scene->units.length, u, NULL));
  PetscCall(SetStressIC(scene, u, s));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  if (sys->floating) {
    const PhlexUnits *un = &scene->units;
    Vec               q;
    PetscScalar      *qa;
    PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_RIGID], &q));
    PetscCall(VecGetArray(q, &qa));
    if (sys->qlocal) {
      for (PetscInt k = 0; k < 3; k++) {
        qa[k]      = b->position0[k] / un->length;
        qa[12 + k] = b->velocity0[k] / un->velocity + mode_rigid[k];
        qa[15 + k] = b->omega0[k] * un->time + mode_rigid[3 + k];
      }
      for (PetscInt k = 0; k < 9; k++) qa[3 + k] = b->rotation0[k];
    }
    PetscCall(VecRestoreArray(q, &qa));
    PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_RIGID], &q));
  }
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
  /* floating body */
  PetscViewer      rigid_csv;
  Vec              Xmid;
  PetscReal        P0[3], L0[3], Pscale, Lscale, max_dP, max_dL, max_orth, max_defect;
} MonitorContext;

/* After each step of a floating body: R back onto SO(3). The implicit midpoint rule maps R by a Cayley factor, which
   is orthogonal, so the per-step defect is the Newton residual and round-off; without this clean-up the round-off
   would accumulate linearly over long runs. The defect removed is recorded (max per step). */
static PetscErrorCode PostStepRigid(TS ts)
{
  MonitorContext *m;
  Vec             X, q;
  PetscScalar    *qa;

  PetscFunctionBeginUser;
  PetscCall(TSGetApplicationContext(ts, &m));
  PetscCall(TSGetSolution(ts, &X));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_RIGID], &q));
  PetscCall(VecGetArray(q, &qa));
  if (m->sys->qlocal) {
    PetscReal R[9], d;
    for (PetscInt k = 0; k < 9; k++) R[k] = PetscRealPart(qa[3 + k]);
    d             = PhlexOrthogonalityError(R);
    m->max_defect = PetscMax(m->max_defect, d);
    PhlexOrthonormalize(R);
    for (PetscInt k = 0; k < 9; k++) qa[3 + k] = R[k];
  }
  PetscCall(VecRestoreArray(q, &qa));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_RIGID], &q));
  PetscFunctionReturn(0);
}

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
  PetscCall(PhlexFieldWriterVertexField(m->fields, "displacement", x, u->length, NULL, NULL, PETSC_FALSE));
  if (m->sys->floating) {
    /* x_inertial = r_P + R (x - P + u_f): the XDMF geometry of the step, so ParaView shows the motion */
    PetscReal q[18], rp[3], RP[3];
    PetscCall(PhlexSystemGetRigid(m->sys, X, q));
    PhlexMatVec3(&q[3], b->origin, RP);
    for (PetscInt k = 0; k < 3; k++) rp[k] = q[k] * u->length - RP[k];
    PetscCall(PhlexFieldWriterVertexField(m->fields, "inertial_position", x, u->length, &q[3], rp, PETSC_TRUE));
  }
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_DISPLACEMENT], &x));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &x));
  PetscCall(PhlexFieldWriterVertexField(m->fields, "velocity", x, u->velocity, NULL, NULL, PETSC_FALSE));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &x));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &x));
  PetscCall(PhlexFieldWriterStress(m->fields, x, u->modulus));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &x));
  PetscFunctionReturn(0);
}

/* kinetic, strain and potential (gravity) energy at a state; a floating body's state is evaluated in sys->fs */
static PetscErrorCode Energy(MonitorContext *m, PetscReal t, Vec X, PetscReal *kin, PetscReal *strain, PetscReal *potential)
{
  Vec v, s;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(PhlexBodyEnergy(m->sys->body, v, s, kin, strain));
  *potential = 0.0;
  if (m->sys->floating) {
    PetscCall(PhlexSystemEvaluateFloating(m->sys, t, X, NULL));
    PetscCall(PhlexFloatingEnergy(m->sys->body, &m->sys->fs, v, kin, potential));
  }
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_STRESS], &s));
  PetscFunctionReturn(0);
}

/* rigid states of a floating body (SI): position of P and of the centre of mass, rotation (matrix and
   quaternion), v_P, w_P (body frame), inertial momenta, orthogonality error; sys->fs holds the evaluated state */
static PetscErrorCode WriteRigid(MonitorContext *m, PetscReal t)
{
  PhlexFloatingState *f = &m->sys->fs;
  const PhlexUnits   *u = &m->scene->units;
  PetscReal           qt[4], P[3], L[3], orth = PhlexOrthogonalityError(f->R);

  PetscFunctionBeginUser;
  PetscCall(PhlexFloatingMomenta(f, P, L));
  PhlexRotationToQuaternion(f->R, qt);
  PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, "%.12e", (double)t));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)(f->r[k] * u->length)));
  {
    /* centre of mass r_P + R s(u) / m */
    PetscReal Rs[3];
    PhlexMatVec3(f->R, f->sgrav, Rs);
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)((f->r[k] + Rs[k] / f->m) * u->length)));
  }
  for (PetscInt k = 0; k < 9; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)f->R[k]));
  for (PetscInt k = 0; k < 4; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)qt[k]));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)(f->vP[k] * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)(f->w[k] / u->time)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)(P[k] * u->mass * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e", (double)(L[k] * u->mass * u->velocity * u->length)));
  PetscCall(PetscViewerASCIIPrintf(m->rigid_csv, ",%.12e\n", (double)orth));
  m->max_orth = PetscMax(m->max_orth, orth);
  for (PetscInt k = 0; k < 3; k++) {
    m->max_dP = PetscMax(m->max_dP, PetscAbsReal(P[k] - m->P0[k]) / m->Pscale);
    m->max_dL = PetscMax(m->max_dL, PetscAbsReal(L[k] - m->L0[k]) / m->Lscale);
  }
  PetscFunctionReturn(0);
}

/* Port inputs (force, moment about the patch centroid) and collocated outputs (patch-average velocity and angular
   velocity), SI. A floating body's outputs add the rigid motion, v_P + w x (c - P + u) and w (u only in the full
   model, as in the moment arms of the inputs), and its frame patch is a port: the frame wrench and (v_P, w). */
static PetscErrorCode WritePorts(MonitorContext *m, PetscReal t, Vec X)
{
  PhlexBody        b = m->sys->body;
  const PhlexUnits *u = &m->scene->units;
  PetscReal        y[PHLEX_MAX_PORTS][6], q[18];
  Vec              v;

  PetscFunctionBeginUser;
  if (!m->ports_csv) PetscFunctionReturn(0);
  PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  if (m->sys->floating) {
    Vec ud;
    PetscCall(PhlexSystemGetRigid(m->sys, X, q));
    PetscCall(VecGetSubVector(X, m->sys->is[PHLEX_FIELD_DISPLACEMENT], &ud));
    PetscCall(PhlexFloatingPortOutputs(b, u, &q[12], &q[15], ud, v, m->work, y));
    PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_DISPLACEMENT], &ud));
  } else PetscCall(PhlexBodyPortOutputs(b, v, y));
  PetscCall(VecRestoreSubVector(X, m->sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(PetscViewerASCIIPrintf(m->ports_csv, "%.12e", (double)t));
  if (m->sys->floating) {
    PetscReal fr = 0.0;
    if (b->frame_loaded) PetscCall(PhlexProfileEvaluate(b->frame_profile, t, &fr));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(fr * b->frame_force[k])));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(fr * b->frame_moment[k])));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(q[12 + k] * u->velocity)));
    for (PetscInt k = 0; k < 3; k++) PetscCall(PetscViewerASCIIPrintf(m->ports_csv, ",%.12e", (double)(q[15 + k] / u->time)));
  }
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
  PetscReal         kin, strain, pot, H, dt, power = 0, residual = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_MonitorEnergy, 0, 0, 0, 0));
  PetscCall(Energy(m, t, X, &kin, &strain, &pot));
  H = kin + strain + pot;
  if (m->sys->floating) {
    if (step == 0) {
      PetscReal J0 = m->sys->fs.J[0] + m->sys->fs.J[4] + m->sys->fs.J[8];
      PetscCall(PhlexFloatingMomenta(&m->sys->fs, m->P0, m->L0));
      /* momentum scales: the momenta themselves, or those of the initial energy */
      m->Pscale = PetscMax(PetscSqrtReal(PhlexDot3(m->P0, m->P0)), PetscSqrtReal(2.0 * m->sys->fs.m * PetscAbsReal(kin)));
      m->Lscale = PetscMax(PetscSqrtReal(PhlexDot3(m->L0, m->L0)), PetscSqrtReal(2.0 * PetscAbsReal(kin) * J0 / 3.0));
      if (m->Pscale == 0) m->Pscale = 1.0;
      if (m->Lscale == 0) m->Lscale = 1.0;
    }
    PetscCall(WriteRigid(m, t));
  }
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
    if (m->sys->floating) {
      /* the power of the inputs at the midpoint state: F . v_P + M . w_P + b . v (M with the u-dependent arms) */
      const PetscReal th = m->theta ? m->theta_value : 0.5;
      PetscScalar     p;
      Vec             vm;
      PetscCall(VecAXPBYPCZ(m->Xmid, 0.5, 0.5, 0.0, X, m->Xprev));
      PetscCall(PhlexSystemEvaluateFloating(m->sys, m->tprev + th * (t - m->tprev), m->Xmid, NULL));
      PetscCall(VecGetSubVector(m->Xmid, m->sys->is[PHLEX_FIELD_VELOCITY], &vm));
      PetscCall(VecDot(vm, m->sys->fs.bext, &p));
      PetscCall(VecRestoreSubVector(m->Xmid, m->sys->is[PHLEX_FIELD_VELOCITY], &vm));
      power = PetscRealPart(p) + PhlexDot3(m->sys->fs.Fext, m->sys->fs.vP) + PhlexDot3(m->sys->fs.Mext, m->sys->fs.w);
    } else {
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
  PetscCall(PetscViewerASCIIPrintf(m->energy_csv, "%" PetscInt_FMT ",%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e,%.12e\n", step, (double)t, (double)(kin * u->energy), (double)(strain * u->energy), (double)(pot * u->energy), (double)(H * u->energy), (double)(power * u->power), (double)(m->work_total * u->energy), (double)(residual * u->energy)));
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

/* Newton convergence of a floating body: PETSc's tests (-snes_rtol, -snes_atol, ...), plus stagnation at the
   round-off floor of the residual. The residual carries shift (X - X_n) terms, so its floor grows with the state
   (the position r_P of a drifting body): a fixed -snes_atol may be out of reach. Newton is accepted as converged
   once the residual no longer decreases (by half) and is below 100 eps shift ||X||. */
typedef struct {
  PhlexSystem *sys;
  PetscReal    fprev;
} NewtonFloorContext;

static PetscErrorCode SNESConvergedFloor(SNES snes, PetscInt it, PetscReal xnorm, PetscReal snorm, PetscReal fnorm, SNESConvergedReason *reason, void *ctx)
{
  NewtonFloorContext *c = (NewtonFloorContext *)ctx;

  PetscFunctionBeginUser;
  PetscCall(SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, NULL));
  if (it == 0) c->fprev = PETSC_MAX_REAL;
  if (it > 0 && (*reason == SNES_CONVERGED_ITERATING || *reason == SNES_DIVERGED_MAX_IT)) {
    const PetscReal floor = 100.0 * PETSC_MACHINE_EPSILON * PetscMax(1.0, c->sys->shift) * xnorm;
    if (fnorm <= floor && fnorm >= 0.5 * c->fprev) *reason = SNES_CONVERGED_FNORM_ABS;
  }
  c->fprev = fnorm;
  PetscFunctionReturn(0);
}

/* The solver preset (-solver_options_file) goes under the scene and the command line: insert it, then insert the
   command line again (with its -options_file scenes) so that they keep precedence. */
static PetscErrorCode InsertSolverPreset(MPI_Comm comm, PetscBool floating)
{
  char      file[PETSC_MAX_PATH_LEN];
  PetscBool exists;
  int       argc;
  char    **argv;

  PetscFunctionBeginUser;
  PetscCall(PetscStrcpy(file, floating ? "options/solver/floating.opts" : "options/solver/exact.opts"));
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
  NewtonFloorContext floor_ctx;
  PetscReal         dt = -1, drift_max = -1, balance_rtol = -1, momentum_max = -1, linear_max = -1, angular_max = -1, orth_max = -1, tfinal;
  PetscInt          nsteps;
  PetscBool         flg;
  const PhlexUnits *u = &scene->units;
  char              header[4096] = "time";

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&m, sizeof(m)));
  PetscOptionsBegin(scene->comm, NULL, "Transient analysis options", NULL);
  PetscCall(PetscOptionsReal("-expect_energy_drift_max", "Self-check: bound on max |H - H0| / H0", "PhlexSceneSolveTransient", drift_max, &drift_max, NULL));
  PetscCall(PetscOptionsReal("-expect_power_balance_rtol", "Self-check: bound on max |H_{n+1} - H_n - dt y^T u| / max |supplied work|", "PhlexSceneSolveTransient", balance_rtol, &balance_rtol, NULL));
  PetscCall(PetscOptionsReal("-expect_momentum_drift_max", "Self-check (floating body, no loads): bound on the drift of the inertial linear and angular momenta, relative to their scale", "PhlexSceneSolveTransient", momentum_max, &momentum_max, NULL));
  PetscCall(PetscOptionsReal("-expect_linear_momentum_drift_max", "Self-check (floating body): bound on the drift of the inertial linear momentum alone, relative to its scale", "PhlexSceneSolveTransient", linear_max, &linear_max, NULL));
  PetscCall(PetscOptionsReal("-expect_angular_momentum_drift_max", "Self-check (floating body): bound on the drift of the inertial angular momentum alone, relative to its scale", "PhlexSceneSolveTransient", angular_max, &angular_max, NULL));
  PetscCall(PetscOptionsReal("-expect_orthogonality_max", "Self-check (floating body): bound on max ||R^T R - I||_F", "PhlexSceneSolveTransient", orth_max, &orth_max, NULL));
  PetscCall(PetscOptionsViewer("-ts_monitor_energy", "Print energy, input power and balance residual every step", "PhlexSceneSolveTransient", &m.monitor, NULL, &flg));
  PetscOptionsEnd();

  PetscCheck(b->floating || (momentum_max < 0 && linear_max < 0 && angular_max < 0 && orth_max < 0), scene->comm, PETSC_ERR_USER_INPUT, "-expect_*momentum_drift_max and -expect_orthogonality_max need a floating body (-%smotion floating)", b->prefix);
  PetscCall(InsertSolverPreset(scene->comm, b->floating));
  PetscCall(PhlexSystemCreate(scene, &sys));
  PetscCall(TSCreate(scene->comm, &ts));
  PetscCall(TSSetDM(ts, sys->dm));
  /* a fixed body is linear (KSP only); the floating frame makes it nonlinear (Newton) */
  PetscCall(TSSetProblemType(ts, b->floating ? TS_NONLINEAR : TS_LINEAR));
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
  if (b->floating) {
    SNES snes;
    PetscCall(TSGetSNES(ts, &snes));
    floor_ctx.sys = sys;
    PetscCall(SNESSetConvergenceTest(snes, SNESConvergedFloor, &floor_ctx, NULL));
  }
  PetscCall(TSGetTimeStep(ts, &dt));
  PetscCheck(dt > 0, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the time step with -ts_dt <s>");
  {
    PetscReal tmax;
    PetscInt  smax;
    PetscCall(TSGetMaxTime(ts, &tmax));
    PetscCall(TSGetMaxSteps(ts, &smax));
    PetscCheck(tmax < PETSC_MAX_REAL || smax < PETSC_MAX_INT, scene->comm, PETSC_ERR_USER_INPUT, "transient analysis: set the end of the run with -ts_max_time <s> or -ts_max_steps <n>");
  }

  PetscCall(DMCreateGlobalVector(sys->dm, &X));
  PetscCall(PetscObjectSetName((PetscObject)X, "state"));
  PetscCall(SetInitialCondition(scene, sys, X));
  if (sys->use_aij) {
    if (sys->floating) {
      /* shells in the nest: build the assembled matrix from a first evaluation at the initial state */
      Vec Xdot;
      PetscCall(VecDuplicate(X, &Xdot));
      PetscCall(VecSet(Xdot, 0.0));
      PetscCall(PhlexSystemIJacobian(ts, 0.0, X, Xdot, 1.0 / dt, sys->J, sys->J, sys));
      PetscCall(VecDestroy(&Xdot));
    } else PetscCall(MatConvert(sys->J, MATAIJ, MAT_INITIAL_MATRIX, &sys->Jaij));
    PetscCall(TSSetIJacobian(ts, sys->Jaij, sys->Jaij, PhlexSystemIJacobian, sys));
  }

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
  PetscCall(PhlexOutputCSVOpen(scene->output, "energy.csv", "step,time,kinetic,strain,potential,total,input_power,supplied_work,balance_residual", &m.energy_csv));
  if (b->nports || b->floating) {
    for (PetscInt p = -1; p < b->nports; p++) {
      const char *n = p < 0 ? b->frame_patch : b->ports[p].name;
      char        cols[1024];
      if (p < 0 && !b->floating) continue;
      PetscCall(PetscSNPrintf(cols, sizeof(cols), ",%s_Fx,%s_Fy,%s_Fz,%s_Tx,%s_Ty,%s_Tz,%s_vx,%s_vy,%s_vz,%s_wx,%s_wy,%s_wz", n, n, n, n, n, n, n, n, n, n, n, n));
      PetscCall(PetscStrlcat(header, cols, sizeof(header)));
    }
    PetscCall(PhlexOutputCSVOpen(scene->output, "ports.csv", header, &m.ports_csv));
  }
  if (sys->floating) {
    PetscCall(VecDuplicate(X, &m.Xmid));
    PetscCall(PhlexOutputCSVOpen(scene->output, "rigid.csv", "time,rx,ry,rz,cx,cy,cz,R11,R12,R13,R21,R22,R23,R31,R32,R33,qw,qx,qy,qz,vPx,vPy,vPz,wx,wy,wz,Px,Py,Pz,Lx,Ly,Lz,orthogonality", &m.rigid_csv));
  }
  if (scene->output->fields) {
    PetscCall(PhlexFieldWriterCreate(scene->output, b, b->name, &m.fields));
    if (sys->floating) PetscCall(PhlexFieldWriterSetGeometryField(m.fields, "inertial_position"));
  }
  PetscCall(TSMonitorSet(ts, MonitorEnergy, &m, NULL));
  if (sys->floating) {
    PetscCall(TSSetApplicationContext(ts, &m));
    PetscCall(TSSetPostStep(ts, PostStepRigid));
  }

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
    if (sys->floating) {
      PetscReal P[3], L[3];
      PetscCall(PhlexSystemEvaluateFloating(sys, tfinal, X, NULL)); /* the final state (the monitor left the midpoint) */
      PetscCall(PhlexFloatingMomenta(&sys->fs, P, L));
      PetscCallMPI(MPI_Bcast(&m.max_defect, 1, MPIU_REAL, 0, scene->comm));
      PetscCall(PetscPrintf(scene->comm, "  rigid motion: final r_P = (%.6e, %.6e, %.6e) m, max ||R^T R - I|| = %.3e (largest per-step defect removed %.3e)\n", (double)(sys->fs.r[0] * u->length), (double)(sys->fs.r[1] * u->length), (double)(sys->fs.r[2] * u->length), (double)m.max_orth, (double)m.max_defect));
      PetscCall(PetscPrintf(scene->comm, "  momenta: max drift of P %.3e, of L %.3e (relative to %.6e kg m/s, %.6e kg m^2/s)\n", (double)m.max_dP, (double)m.max_dL, (double)(m.Pscale * u->mass * u->velocity), (double)(m.Lscale * u->mass * u->velocity * u->length)));
    }
  }
  PetscCall(PetscViewerDestroy(&m.energy_csv));
  PetscCall(PetscViewerDestroy(&m.ports_csv));
  PetscCall(PetscViewerDestroy(&m.rigid_csv));
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

  if (momentum_max >= 0) {
    PetscCall(PhlexExpectMax(scene->comm, "linear momentum drift (max |P - P0| / scale)", "-expect_momentum_drift_max", m.max_dP, momentum_max, PETSC_TRUE));
    PetscCall(PhlexExpectMax(scene->comm, "angular momentum drift (max |L - L0| / scale)", "-expect_momentum_drift_max", m.max_dL, momentum_max, PETSC_TRUE));
  }
  if (linear_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "linear momentum drift (max |P - P0| / scale)", "-expect_linear_momentum_drift_max", m.max_dP, linear_max, PETSC_TRUE));
  if (angular_max >= 0) PetscCall(PhlexExpectMax(scene->comm, "angular momentum drift (max |L - L0| / scale)", "-expect_angular_momentum_drift_max", m.max_dL, angular_max, PETSC_TRUE));
  if (orth_max >= 0) {
    PetscCall(PhlexExpectMax(scene->comm, "rotation orthogonality (max ||R^T R - I||_F)", "-expect_orthogonality_max", m.max_orth, orth_max, PETSC_TRUE));
    PetscCall(PhlexExpectMax(scene->comm, "per-step orthogonality defect of the integrator (max ||R^T R - I||_F after a step)", "-expect_orthogonality_max", m.max_defect, orth_max, PETSC_TRUE));
  }

  PetscCall(PetscViewerDestroy(&m.monitor));
  PetscCall(VecDestroy(&m.Xmid));
  PetscCall(VecDestroy(&m.Xprev));
  PetscCall(VecDestroy(&m.vmid));
  PetscCall(VecDestroy(&m.beff));
  PetscCall(VecDestroy(&m.work));
  PetscCall(VecDestroy(&X));
  PetscCall(TSDestroy(&ts));
  PetscCall(PhlexSystemDestroy(&sys));
  PetscFunctionReturn(0);
}
