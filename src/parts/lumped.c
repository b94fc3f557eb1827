/* A lumped mass as a part (part kind "lumped"): a point mass m with position r and velocity v (inertial frame),
   r' = v, m v' = F + m g, and one port "point" (force only: a point has no orientation). Attached to a port of
   another body (-attach body:port) it is joined to it by a spherical joint created by the scene. */
#include <phlex_impl.h>

typedef struct {
  PetscReal     mass, position[3], velocity[3]; /* SI, inertial */
  PetscBool     position_given;
  PhlexPortLoad load;
  PetscReal     r[3], v[3], vd[3], wext[6], power_ext;
  PetscViewer   csv;
} Lumped;

static PetscErrorCode LumpedSetFromOptions(PhlexPart part)
{
  Lumped   *m = (Lumped *)part->data;
  char      who[PHLEX_NAME_LEN + 8];
  PetscBool fm = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", part->name));
  PetscOptionsBegin(part->comm, part->prefix, "Lumped mass options", NULL);
  PetscCall(PetscOptionsReal("-mass", "Mass [kg]", "LumpedSetFromOptions", m->mass, &m->mass, &fm));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, who, part->prefix, "-position", "Initial position (inertial) [m]; default with -attach: the port's point", "LumpedSetFromOptions", 3, m->position, &m->position_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, who, part->prefix, "-velocity", "Initial velocity (inertial) [m/s]", "LumpedSetFromOptions", 3, m->velocity, NULL));
  PetscCall(PetscOptionsString("-attach", "Port body:port the mass sits on (a spherical joint <name>_attach is created)", "LumpedSetFromOptions", part->attach, part->attach, sizeof(part->attach), NULL));
  PetscOptionsEnd();
  PetscCheck(fm, part->comm, PETSC_ERR_USER_INPUT, "body %s: a lumped mass needs its mass: -%smass [kg]", part->name, part->prefix);
  PetscCheck(m->mass > 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: the mass must be positive: -%smass %g", part->name, part->prefix, (double)m->mass);
  PetscCheck(m->position_given || part->attach[0], part->comm, PETSC_ERR_USER_INPUT, "body %s: a lumped mass needs -%sposition x,y,z [m] or -%sattach body:port", part->name, part->prefix, part->prefix);
  PetscCall(PhlexPortLoadSetFromOptions(part, "point", PETSC_FALSE, &m->load));
  PetscCheck(m->load.moment[0] == 0 && m->load.moment[1] == 0 && m->load.moment[2] == 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: a point mass takes no moment (-%sport_point_moment)", part->name, part->prefix);
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedGeometry(PhlexPart part, PhlexScaleHints *h)
{
  PetscFunctionBeginUser;
  h->extent = h->density = h->modulus = 0;
  h->mass   = ((Lumped *)part->data)->mass;
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedSetUp(PhlexPart part)
{
  const char *const names[6] = {"rx", "ry", "rz", "vx", "vy", "vz"};

  PetscFunctionBeginUser;
  PetscCall(PhlexPartSetUpLayout(part, 0, 0, 0, 0, 6));
  for (PetscInt k = 0; k < 6; k++) PetscCall(PhlexPartSetDof(part, k, k < 3 ? PHLEX_DOF_CONFIGURATION : PHLEX_DOF_VELOCITY, names[k]));
  part->frame = (PhlexFrameIndex){0, -1, 3, -1};
  PetscCall(PhlexPartSetPorts(part, 1));
  PetscCall(PetscStrcpy(part->ports[0].name, "point"));
  part->ports[0].dim = 3;
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedView(PhlexPart part, PetscViewer viewer)
{
  Lumped *m = (Lumped *)part->data;
  char    load[512];

  PetscFunctionBeginUser;
  PetscCall(PhlexPortLoadDescribe(&m->load, load, sizeof(load)));
  if (m->position_given) PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: lumped mass %.15g kg at (%.15g, %.15g, %.15g) m, velocity (%.15g, %.15g, %.15g) m/s%s%s%s\n", part->name, (double)m->mass, (double)m->position[0], (double)m->position[1], (double)m->position[2], (double)m->velocity[0], (double)m->velocity[1], (double)m->velocity[2], part->attach[0] ? ", attached to " : "", part->attach, load));
  else PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: lumped mass %.15g kg on port %s, velocity (%.15g, %.15g, %.15g) m/s%s\n", part->name, (double)m->mass, part->attach, (double)m->velocity[0], (double)m->velocity[1], (double)m->velocity[2], load));
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedDestroy(PhlexPart part)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexPortLoadDestroy(&((Lumped *)part->data)->load));
  PetscCall(PetscFree(part->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedInitialState(PhlexPart part, PhlexPartVec *X)
{
  Lumped *m = (Lumped *)part->data;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    X->q[k]     = m->position[k] / part->units->length;
    X->q[3 + k] = m->velocity[k] / part->units->velocity;
  }
  PetscFunctionReturn(0);
}

/* the assembly places an attached mass given no position on its port (assembly.c) */
static PetscErrorCode LumpedPlace(PhlexPart part, const PetscReal x[3], PetscReal *q)
{
  Lumped *m = (Lumped *)part->data;

  PetscFunctionBeginUser;
  if (m->position_given) PetscFunctionReturn(0);
  for (PetscInt k = 0; k < 3; k++) {
    q[k]           = x[k];
    m->position[k] = x[k] * part->units->length;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedEvaluate(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot)
{
  Lumped *m = (Lumped *)part->data;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    m->r[k]  = X->q[k];
    m->v[k]  = X->q[3 + k];
    m->vd[k] = Xdot ? part->units->time * Xdot->q[3 + k] : 0.0;
  }
  PetscCall(PhlexPortLoadEvaluate(&m->load, t, part->units, NULL, m->wext));
  m->power_ext = PhlexDot3(m->wext, m->v);
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedResidual(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot, PhlexPartVec *F)
{
  Lumped         *m  = (Lumped *)part->data;
  const PetscReal mn = m->mass / part->units->mass, T = part->units->time;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    F->q[k]     = T * Xdot->q[k] - m->v[k];
    F->q[3 + k] = mn * (m->vd[k] - part->gravity[k]) - m->wext[k] - part->wrench[0][k];
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedJacobian(PhlexPart part, PetscReal shift, const PhlexPartVec *X, PetscReal *D, PetscInt ld)
{
  const PetscReal mn = ((Lumped *)part->data)->mass / part->units->mass;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < 6; i++)
    for (PetscInt j = 0; j < 6; j++) D[ld * i + j] = 0.0;
  for (PetscInt k = 0; k < 3; k++) {
    D[ld * k + k]           = shift;
    D[ld * k + 3 + k]       = -1.0;
    D[ld * (3 + k) + 3 + k] = shift * mn;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedPortInput(PhlexPart part, PetscInt p, PetscReal t, PetscReal w[6])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexPortLoadEvaluate(&((Lumped *)part->data)->load, t, part->units, NULL, w));
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedPortOutput(PhlexPart part, PetscInt p, PetscReal y[6])
{
  Lumped *m = (Lumped *)part->data;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    y[k]     = m->v[k];
    y[3 + k] = 0.0;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedPortLinear(PhlexPart part, PetscInt p, Vec du, PetscReal au, Vec dv, const PetscReal *dq, PetscReal dy[6])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    dy[k]     = dq ? dq[3 + k] : 0.0;
    dy[3 + k] = 0.0;
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedPortForce(PhlexPart part, PetscInt p, const PetscReal w[6], Vec fv, PetscReal *fq)
{
  PetscFunctionBeginUser;
  if (fq)
    for (PetscInt k = 0; k < 3; k++) fq[3 + k] += w[k];
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedPortPlacement(PhlexPart part, PetscInt p, const PhlexPartVec *X, PetscReal x[3], PetscReal R[9])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) x[k] = X->q[k];
  for (PetscInt k = 0; k < 9; k++) R[k] = (k % 4 == 0) ? 1.0 : 0.0;
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedEnergy(PhlexPart part, const PhlexPartVec *X, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  Lumped         *m  = (Lumped *)part->data;
  const PetscReal mn = m->mass / part->units->mass;

  PetscFunctionBeginUser;
  *kin    = 0.5 * mn * PhlexDot3(m->v, m->v);
  *strain = 0.0;
  *pot    = -mn * PhlexDot3(part->gravity, m->r);
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedInputPower(PhlexPart part, PetscReal *P)
{
  PetscFunctionBeginUser;
  *P = ((Lumped *)part->data)->power_ext;
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedMomenta(PhlexPart part, PetscReal P[3], PetscReal L[3])
{
  Lumped         *m  = (Lumped *)part->data;
  const PetscReal mn = m->mass / part->units->mass;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) P[k] = mn * m->v[k];
  PhlexCross(m->r, P, L);
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedRigidMass(PhlexPart part, PetscReal M[36])
{
  const PetscReal mn = ((Lumped *)part->data)->mass / part->units->mass;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 36; k++) M[k] = 0.0;
  for (PetscInt k = 0; k < 3; k++) M[7 * k] = mn;
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedOutputOpen(PhlexPart part, PhlexOutput out, PetscBool fields)
{
  char name[PHLEX_NAME_LEN + 16];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_rigid.csv", part->name));
  PetscCall(PhlexOutputCSVOpen(out, name, "time,rx,ry,rz,vx,vy,vz,Fx,Fy,Fz,Px,Py,Pz,Lx,Ly,Lz", &((Lumped *)part->data)->csv));
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedOutputStep(PhlexPart part, PetscInt step, PetscReal t, const PhlexPartVec *X, PetscBool fields)
{
  Lumped           *m = (Lumped *)part->data;
  const PhlexUnits *u = part->units;
  PetscReal         P[3], L[3];

  PetscFunctionBeginUser;
  if (step < 0) PetscFunctionReturn(0);
  PetscCall(LumpedMomenta(part, P, L));
  PetscCall(PhlexCSVPrintf(m->csv, "%.12e", (double)t));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(m->csv, ",%.12e", (double)(m->r[k] * u->length)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(m->csv, ",%.12e", (double)(m->v[k] * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(m->csv, ",%.12e", (double)(m->wext[k] * u->force)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(m->csv, ",%.12e", (double)(P[k] * u->mass * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(m->csv, ",%.12e", (double)(L[k] * u->mass * u->velocity * u->length)));
  PetscCall(PhlexCSVPrintf(m->csv, "\n"));
  PetscFunctionReturn(0);
}

static PetscErrorCode LumpedOutputClose(PhlexPart part)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(&((Lumped *)part->data)->csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreate_Lumped - a lumped (point) mass (part kind "lumped")
@*/
PetscErrorCode PhlexPartCreate_Lumped(PhlexPart part)
{
  PetscFunctionBeginUser;
  PetscCall(PetscNew((Lumped **)&part->data));
  part->ops.setfromoptions = LumpedSetFromOptions;
  part->ops.geometry       = LumpedGeometry;
  part->ops.setup          = LumpedSetUp;
  part->ops.view           = LumpedView;
  part->ops.destroy        = LumpedDestroy;
  part->ops.initialstate   = LumpedInitialState;
  part->ops.place          = LumpedPlace;
  part->ops.evaluate       = LumpedEvaluate;
  part->ops.residual       = LumpedResidual;
  part->ops.jacobian       = LumpedJacobian;
  part->ops.portoutput     = LumpedPortOutput;
  part->ops.portinput      = LumpedPortInput;
  part->ops.portlinear     = LumpedPortLinear;
  part->ops.portforce      = LumpedPortForce;
  part->ops.portplacement  = LumpedPortPlacement;
  part->ops.energy         = LumpedEnergy;
  part->ops.inputpower     = LumpedInputPower;
  part->ops.momenta        = LumpedMomenta;
  part->ops.rigidmass      = LumpedRigidMass;
  part->ops.outputopen     = LumpedOutputOpen;
  part->ops.outputstep     = LumpedOutputStep;
  part->ops.outputclose    = LumpedOutputClose;
  PetscFunctionReturn(0);
}
