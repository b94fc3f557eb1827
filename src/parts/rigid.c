/* A rigid body as a part (part kind "rigid"): mass, centre of mass, inertia tensor, ports at given points; no mesh.
   Its frame origin P is the centre of mass. The equations are those of a moving frame without an elastic field
   (frame.c: the Newton-Euler equations on SE(3), paper Remark after eq. ph_mfd_all), unknowns q = [r | R | v | w]. */
#include <phlex_impl.h>

typedef struct {
  PetscReal       mass, com[3], inertia[9]; /* SI: kg, m (drawing coordinates), kg m^2 about the centre of mass */
  PetscInt        nports;
  char          (*port_name)[PHLEX_NAME_LEN];
  PetscReal     (*port_position)[3];        /* SI, drawing coordinates */
  PhlexPortLoad  *load;
  PetscReal       frame_force[3], frame_moment[3];
  PhlexProfile    frame_profile;
  PetscBool       frame_loaded;
  PhlexPose       pose;
  PhlexFrame      frame;
  PhlexFrameState fs;
  PetscReal     (*port_ext)[6];
  PetscReal       power_ext, t_eval;
  PetscViewer     rigid_csv, ports_csv;
} Rigid;

static PetscErrorCode RigidSetFromOptions(PhlexPart part)
{
  Rigid    *r = (Rigid *)part->data;
  char      who[PHLEX_NAME_LEN + 8], **names;
  PetscInt  n = 7, nports; /* room for a seventh number: a wrong count is seen */
  PetscReal J[7] = {0, 0, 0, 0, 0, 0, 0};
  PetscBool fm = PETSC_FALSE, fJ = PETSC_FALSE, ff = PETSC_FALSE, fmo = PETSC_FALSE, flg;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", part->name));
  PetscCall(PhlexOptionsListLength(part->prefix, "-ports", &nports));
  PetscCall(PetscMalloc1(nports, &names));
  PetscOptionsBegin(part->comm, part->prefix, "Rigid body options", NULL);
  PetscCall(PetscOptionsReal("-mass", "Mass [kg]", "RigidSetFromOptions", r->mass, &r->mass, &fm));
  PetscCall(PhlexOptionsRealList("-inertia", "Inertia tensor about the centre of mass, body axes: Ixx,Iyy,Izz or Ixx,Iyy,Izz,Iyz,Ixz,Ixy [kg m^2]", "RigidSetFromOptions", J, &n, &fJ, 0));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, who, part->prefix, "-center_of_mass", "Centre of mass in the drawing coordinates of the body's points [m]", "RigidSetFromOptions", 3, r->com, NULL));
  PetscCall(PetscOptionsStringArray("-ports", "Ports: named points of the body (-port_<name>_position, loads -port_<name>_force ...)", "RigidSetFromOptions", names, &nports, &flg));
  if (!flg) nports = 0;
  PetscCall(PhlexPoseSetFromOptions(PetscOptionsObject, part, &r->pose, NULL));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, who, part->prefix, "-frame_force", "Force on the centre of mass (body frame) [N]", "RigidSetFromOptions", 3, r->frame_force, &ff));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, who, part->prefix, "-frame_moment", "Moment about the centre of mass (body frame) [N m]", "RigidSetFromOptions", 3, r->frame_moment, &fmo));
  PetscOptionsEnd();
  PetscCheck(fm, part->comm, PETSC_ERR_USER_INPUT, "body %s: a rigid body needs its mass: -%smass [kg]", part->name, part->prefix);
  PetscCheck(r->mass > 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: the mass must be positive: -%smass %g", part->name, part->prefix, (double)r->mass);
  PetscCheck(fJ, part->comm, PETSC_ERR_USER_INPUT, "body %s: a rigid body needs its inertia tensor about the centre of mass: -%sinertia Ixx,Iyy,Izz[,Iyz,Ixz,Ixy] [kg m^2]", part->name, part->prefix);
  PetscCheck(n == 3 || n == 6, part->comm, PETSC_ERR_USER_INPUT, "body %s: option -%sinertia needs 3 (principal) or 6 components, got %" PetscInt_FMT, part->name, part->prefix, n);
  r->inertia[0] = J[0], r->inertia[4] = J[1], r->inertia[8] = J[2];
  r->inertia[5] = r->inertia[7] = J[3];
  r->inertia[2] = r->inertia[6] = J[4];
  r->inertia[1] = r->inertia[3] = J[5];
  {
    /* positive definite, and the principal moments obey the triangle inequalities (a real mass distribution) */
    PetscReal    w[3], A[9], work[9];
    PetscBLASInt three = 3, lwork = 9, info;
    for (PetscInt k = 0; k < 9; k++) A[k] = r->inertia[k];
    PetscCallBLAS("LAPACKsyev", LAPACKsyev_("N", "U", &three, A, &three, w, work, &lwork, &info));
    PetscCheck(!info && w[0] > 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: the inertia tensor -%sinertia must be positive definite (principal moments %g, %g, %g kg m^2)", part->name, part->prefix, (double)w[0], (double)w[1], (double)w[2]);
    PetscCheck(w[0] + w[1] >= w[2] * (1 - 1e-12), part->comm, PETSC_ERR_USER_INPUT, "body %s: principal moments %g, %g, %g kg m^2 of -%sinertia violate I1 + I2 >= I3: no mass distribution has them", part->name, (double)w[0], (double)w[1], (double)w[2], part->prefix);
  }
  r->frame_loaded = (ff || fmo) ? PETSC_TRUE : PETSC_FALSE;
  if (r->frame_loaded) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sframe_", part->prefix));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, wrench at the centre of mass", part->name));
    PetscCall(PhlexProfileCreate(part->comm, prefix, what, &r->frame_profile));
    PetscCall(PhlexProfileSetFromOptions(r->frame_profile));
  }
  r->nports = nports;
  PetscCall(PetscCalloc3(PetscMax(nports, 1), &r->port_name, PetscMax(nports, 1), &r->port_position, PetscMax(nports, 1), &r->load));
  for (PetscInt p = 0; p < nports; p++) {
    char      prefix[256], what[256];
    PetscBool given;
    PetscCall(PetscStrncpy(r->port_name[p], names[p], PHLEX_NAME_LEN));
    for (PetscInt q = 0; q < p; q++) {
      PetscCall(PetscStrcmp(r->port_name[q], names[p], &flg));
      PetscCheck(!flg, part->comm, PETSC_ERR_USER_INPUT, "body %s: port '%s' is listed twice in -%sports", part->name, names[p], part->prefix);
    }
    PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sport_%s_", part->prefix, names[p]));
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, port %s", part->name, names[p]));
    PetscOptionsBegin(part->comm, prefix, "Rigid body port", NULL);
    PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, what, prefix, "-position", "Port point in the drawing coordinates of the body [m]", "RigidSetFromOptions", 3, r->port_position[p], &given));
    PetscOptionsEnd();
    PetscCheck(given, part->comm, PETSC_ERR_USER_INPUT, "%s: a port of a rigid body needs its point: -%sposition x,y,z [m]", what, prefix);
    PetscCall(PhlexPortLoadSetFromOptions(part, names[p], PETSC_FALSE, &r->load[p]));
    PetscCall(PetscFree(names[p]));
  }
  PetscCall(PetscFree(names));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidGeometry(PhlexPart part, PhlexScaleHints *h)
{
  Rigid *r = (Rigid *)part->data;

  PetscFunctionBeginUser;
  h->extent = h->density = h->modulus = 0;
  h->mass   = r->mass;
  for (PetscInt p = 0; p < r->nports; p++) {
    PetscReal d[3];
    for (PetscInt k = 0; k < 3; k++) d[k] = r->port_position[p][k] - r->com[k];
    h->extent = PetscMax(h->extent, 2 * PhlexNorm3(d));
  }
  /* a body without ports: the size of a uniform sphere of its inertia */
  if (h->extent == 0) h->extent = 2 * PetscSqrtReal(2.5 * (r->inertia[0] + r->inertia[4] + r->inertia[8]) / 3 / r->mass);
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidSetUp(PhlexPart part)
{
  Rigid            *r = (Rigid *)part->data;
  const PhlexUnits *u = part->units;
  const char *const names[18] = {"rx", "ry", "rz", "R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33", "vx", "vy", "vz", "wx", "wy", "wz"};
  PetscReal         J[9], tr;

  PetscFunctionBeginUser;
  PetscCall(PhlexPartSetUpLayout(part, 0, 0, 0, 0, 18));
  for (PetscInt k = 0; k < 18; k++) PetscCall(PhlexPartSetDof(part, k, k < 12 ? PHLEX_DOF_CONFIGURATION : PHLEX_DOF_VELOCITY, names[k]));
  part->frame     = (PhlexFrameIndex){0, 3, 12, 15};
  part->nonlinear = PETSC_TRUE;
  PetscCall(PhlexPartSetPorts(part, r->nports));
  for (PetscInt p = 0; p < r->nports; p++) {
    PetscCall(PetscStrcpy(part->ports[p].name, r->port_name[p]));
    part->ports[p].dim = 6;
    for (PetscInt k = 0; k < 3; k++) part->ports[p].point[k] = (r->port_position[p][k] - r->com[k]) / u->length;
  }
  PetscCall(PetscCalloc1(PetscMax(r->nports, 1), &r->port_ext));
  /* inertia invariants about P = the centre of mass: s0 = 0, E0 = tr(J)/2 I - J (J = tr(E) I - E) */
  for (PetscInt k = 0; k < 9; k++) J[k] = r->inertia[k] / (u->mass * u->length * u->length);
  tr                = J[0] + J[4] + J[8];
  r->frame.comm     = part->comm;
  r->frame.frozen   = PETSC_TRUE;
  r->frame.gravity  = part->gravity;
  r->frame.inertia.m = r->mass / u->mass;
  for (PetscInt k = 0; k < 9; k++) r->frame.inertia.E0[k] = (k % 4 == 0 ? tr / 2 : 0.0) - J[k];
  if (!r->pose.position_given)
    for (PetscInt k = 0; k < 3; k++) r->pose.position[k] = r->com[k];
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidView(PhlexPart part, PetscViewer viewer)
{
  Rigid    *r = (Rigid *)part->data;
  PetscReal q[4];

  PetscFunctionBeginUser;
  PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: rigid, mass %.15g kg, inertia about the centre of mass [[%.15g, %.15g, %.15g], [%.15g, %.15g, %.15g], [%.15g, %.15g, %.15g]] kg m^2\n", part->name, (double)r->mass, (double)r->inertia[0], (double)r->inertia[1], (double)r->inertia[2], (double)r->inertia[3], (double)r->inertia[4], (double)r->inertia[5], (double)r->inertia[6], (double)r->inertia[7], (double)r->inertia[8]));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PhlexRotationToQuaternion(r->pose.rotation, q);
  PetscCall(PetscViewerASCIIPrintf(viewer, "centre of mass (%.15g, %.15g, %.15g) m as drawn; initial position (%.15g, %.15g, %.15g) m, orientation quaternion (%.15g, %.15g, %.15g, %.15g), velocity (%.15g, %.15g, %.15g) m/s, angular velocity (%.15g, %.15g, %.15g) rad/s (body frame)\n", (double)r->com[0], (double)r->com[1], (double)r->com[2], (double)r->pose.position[0], (double)r->pose.position[1], (double)r->pose.position[2], (double)q[0], (double)q[1], (double)q[2], (double)q[3], (double)r->pose.velocity[0], (double)r->pose.velocity[1], (double)r->pose.velocity[2], (double)r->pose.omega[0], (double)r->pose.omega[1], (double)r->pose.omega[2]));
  for (PetscInt p = 0; p < r->nports; p++) {
    char load[512];
    PetscCall(PhlexPortLoadDescribe(&r->load[p], load, sizeof(load)));
    PetscCall(PetscViewerASCIIPrintf(viewer, "port %s at (%.15g, %.15g, %.15g) m%s\n", r->port_name[p], (double)r->port_position[p][0], (double)r->port_position[p][1], (double)r->port_position[p][2], load));
  }
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidDestroy(PhlexPart part)
{
  Rigid *r = (Rigid *)part->data;

  PetscFunctionBeginUser;
  for (PetscInt p = 0; p < r->nports; p++) PetscCall(PhlexPortLoadDestroy(&r->load[p]));
  PetscCall(PetscFree3(r->port_name, r->port_position, r->load));
  PetscCall(PetscFree(r->port_ext));
  PetscCall(PhlexProfileDestroy(&r->frame_profile));
  PetscCall(PetscFree(part->data));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidInitialState(PhlexPart part, PhlexPartVec *X)
{
  Rigid            *r = (Rigid *)part->data;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 3; k++) {
    X->q[k]      = r->pose.position[k] / u->length;
    X->q[12 + k] = r->pose.velocity[k] / u->velocity;
    X->q[15 + k] = r->pose.omega[k] * u->time;
  }
  for (PetscInt k = 0; k < 9; k++) X->q[3 + k] = r->pose.rotation[k];
  PetscFunctionReturn(0);
}

/* the external loads at t (ports, wrench at P) as a resultant about P, and their power */
static PetscErrorCode RigidEvaluate(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot)
{
  Rigid            *r = (Rigid *)part->data;
  const PhlexUnits *u = part->units;
  PhlexFrameState  *f = &r->fs;
  PetscReal         qd[18];

  PetscFunctionBeginUser;
  r->t_eval = t;
  for (PetscInt k = 0; k < 18; k++) qd[k] = Xdot ? u->time * Xdot->q[k] : 0.0;
  PetscCall(PhlexFrameEvaluate(&r->frame, NULL, NULL, NULL, NULL, X->q, qd, f));
  for (PetscInt k = 0; k < 3; k++) f->Fext[k] = f->Mext[k] = 0.0;
  for (PetscInt p = 0; p < r->nports; p++) {
    PetscReal *w = r->port_ext[p], a[3];
    PetscCall(PhlexPortLoadEvaluate(&r->load[p], t, u, f->R, w));
    PhlexCross(part->ports[p].point, w, a);
    for (PetscInt k = 0; k < 3; k++) {
      f->Fext[k] += w[k];
      f->Mext[k] += a[k] + w[3 + k];
    }
  }
  if (r->frame_loaded) {
    PetscReal fr;
    PetscCall(PhlexProfileEvaluate(r->frame_profile, t, &fr));
    for (PetscInt k = 0; k < 3; k++) {
      f->Fext[k] += fr * r->frame_force[k] / u->force;
      f->Mext[k] += fr * r->frame_moment[k] / (u->force * u->length);
    }
  }
  r->power_ext = PhlexDot3(f->Fext, f->vP) + PhlexDot3(f->Mext, f->w);
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidResidual(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot, PhlexPartVec *F)
{
  Rigid          *r = (Rigid *)part->data;
  PhlexFrameState f = r->fs; /* the joint wrenches join the inputs in a copy: the evaluation stays as it was */

  PetscFunctionBeginUser;
  for (PetscInt p = 0; p < part->nports; p++) {
    const PetscReal *w = part->wrench[p];
    PetscReal        a[3];
    PhlexCross(part->ports[p].point, w, a);
    for (PetscInt k = 0; k < 3; k++) {
      f.Fext[k] += w[k];
      f.Mext[k] += a[k] + w[3 + k];
    }
  }
  PetscCall(PhlexFrameResidual(&r->frame, &f, NULL, NULL, NULL, NULL, F->q));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidJacobian(PhlexPart part, PetscReal shift, const PhlexPartVec *X, PetscReal *D, PetscInt ld)
{
  Rigid    *r = (Rigid *)part->data;
  PetscReal Arr[324], Bvv[9], Bvu[9];

  PetscFunctionBeginUser;
  PetscCall(PhlexFrameJacobian(&r->frame, &r->fs, shift, NULL, NULL, NULL, 0, Bvv, Bvu, Arr));
  /* inputs with inertial directions: -d(F, M)/dR */
  for (PetscInt p = 0; p < r->nports; p++) {
    if (!r->load[p].loaded || r->load[p].frame != PHLEX_DIRECTION_INERTIAL) continue;
    for (PetscInt k = 0; k < 9; k++) {
      PetscReal dw[6], a[3];
      PetscCall(PhlexPortLoadDerivativeR(&r->load[p], r->t_eval, part->units, k, dw));
      PhlexCross(part->ports[p].point, dw, a);
      for (PetscInt c = 0; c < 3; c++) {
        Arr[18 * (12 + c) + 3 + k] -= dw[c];
        Arr[18 * (15 + c) + 3 + k] -= a[c] + dw[3 + c];
      }
    }
  }
  for (PetscInt i = 0; i < 18; i++)
    for (PetscInt j = 0; j < 18; j++) D[ld * i + j] = Arr[18 * i + j];
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidPostStep(PhlexPart part, PetscReal *q, PetscReal *defect)
{
  PetscFunctionBeginUser;
  *defect = PhlexOrthogonalityError(q + 3);
  PhlexOrthonormalize(q + 3);
  PetscFunctionReturn(0);
}

/* port p: y = (v + w x c, w); its wrench (F, T at c) acts as (F, c x F + T) on (v, w) */
static PetscErrorCode RigidPortInput(PhlexPart part, PetscInt p, PetscReal t, PetscReal w[6])
{
  Rigid *r = (Rigid *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexPortLoadEvaluate(&r->load[p], t, part->units, r->fs.R, w)); /* body frame */
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidPortOutput(PhlexPart part, PetscInt p, PetscReal y[6])
{
  Rigid    *r = (Rigid *)part->data;
  PetscReal a[3];

  PetscFunctionBeginUser;
  PhlexCross(r->fs.w, part->ports[p].point, a);
  for (PetscInt k = 0; k < 3; k++) {
    y[k]     = r->fs.vP[k] + a[k];
    y[3 + k] = r->fs.w[k];
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidPortLinear(PhlexPart part, PetscInt p, Vec du, PetscReal au, Vec dv, const PetscReal *dq, PetscReal dy[6])
{
  PetscReal a[3];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) dy[k] = 0.0;
  if (!dq) PetscFunctionReturn(0);
  PhlexCross(dq + 15, part->ports[p].point, a);
  for (PetscInt k = 0; k < 3; k++) {
    dy[k]     = dq[12 + k] + a[k];
    dy[3 + k] = dq[15 + k];
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidPortForce(PhlexPart part, PetscInt p, const PetscReal w[6], Vec fv, PetscReal *fq)
{
  PetscReal a[3];

  PetscFunctionBeginUser;
  if (!fq) PetscFunctionReturn(0);
  PhlexCross(part->ports[p].point, w, a);
  for (PetscInt k = 0; k < 3; k++) {
    fq[12 + k] += w[k];
    fq[15 + k] += a[k] + w[3 + k];
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidPortPlacement(PhlexPart part, PetscInt p, const PhlexPartVec *X, PetscReal x[3], PetscReal R[9])
{
  PetscFunctionBeginUser;
  PhlexMatVec3(X->q + 3, part->ports[p].point, x);
  for (PetscInt k = 0; k < 3; k++) x[k] += X->q[k];
  for (PetscInt k = 0; k < 9; k++) R[k] = X->q[3 + k];
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidEnergy(PhlexPart part, const PhlexPartVec *X, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  Rigid *r = (Rigid *)part->data;

  PetscFunctionBeginUser;
  *strain = 0.0;
  PetscCall(PhlexFrameEnergy(&r->frame, &r->fs, 0.0, kin, pot));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidInputPower(PhlexPart part, PetscReal *P)
{
  PetscFunctionBeginUser;
  *P = ((Rigid *)part->data)->power_ext;
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidMomenta(PhlexPart part, PetscReal P[3], PetscReal L[3])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameMomenta(&((Rigid *)part->data)->fs, P, L));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidRigidMass(PhlexPart part, PetscReal M[36])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameRigidMass(&((Rigid *)part->data)->frame.inertia, M));
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidOutputOpen(PhlexPart part, PhlexOutput out, PetscBool fields)
{
  Rigid *r = (Rigid *)part->data;
  char   name[PHLEX_NAME_LEN + 16], header[1024];

  PetscFunctionBeginUser;
  PetscCall(PhlexFrameWriteHeader(header, sizeof(header)));
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_rigid.csv", part->name));
  PetscCall(PhlexOutputCSVOpen(out, name, header, &r->rigid_csv));
  if (r->nports) {
    const char **names;
    PetscCall(PetscMalloc1(r->nports, &names));
    for (PetscInt p = 0; p < r->nports; p++) names[p] = r->port_name[p];
    PetscCall(PhlexPortSeriesOpen(out, part->name, r->nports, names, &r->ports_csv));
    PetscCall(PetscFree(names));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidOutputStep(PhlexPart part, PetscInt step, PetscReal t, const PhlexPartVec *X, PetscBool fields)
{
  Rigid            *r = (Rigid *)part->data;
  const PhlexUnits *u = part->units;
  PetscReal         P[3], L[3];

  PetscFunctionBeginUser;
  if (step < 0) PetscFunctionReturn(0); /* fields only: a rigid body has none */
  PetscCall(PhlexFrameWriteRow(r->rigid_csv, t, &r->fs, u, P, L));
  if (r->ports_csv) {
    PetscCall(PhlexCSVPrintf(r->ports_csv, "%.12e", (double)t));
    for (PetscInt p = 0; p < r->nports; p++) {
      PetscReal in[6], y[6];
      PetscCall(PhlexPortLoadEvaluate(&r->load[p], t, u, r->fs.R, in)); /* body frame */
      PetscCall(RigidPortOutput(part, p, y));
      PetscCall(PhlexPortSeriesEntry(r->ports_csv, u, in, PETSC_FALSE, y));
    }
    for (PetscInt p = 0; p < r->nports; p++) {
      PetscReal x[3], R[9];
      PetscCall((*part->ops.portplacement)(part, p, X, x, R));
      PetscCall(PhlexPortSeriesPosition(r->ports_csv, u, x));
    }
    PetscCall(PhlexCSVPrintf(r->ports_csv, "\n"));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RigidOutputClose(PhlexPart part)
{
  Rigid *r = (Rigid *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(&r->rigid_csv));
  PetscCall(PetscViewerDestroy(&r->ports_csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreate_Rigid - a rigid body (part kind "rigid")
@*/
PetscErrorCode PhlexPartCreate_Rigid(PhlexPart part)
{
  Rigid *r;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&r));
  part->data              = r;
  r->pose.rotation[0]     = r->pose.rotation[4] = r->pose.rotation[8] = 1.0;
  part->ops.setfromoptions = RigidSetFromOptions;
  part->ops.geometry       = RigidGeometry;
  part->ops.setup          = RigidSetUp;
  part->ops.view           = RigidView;
  part->ops.destroy        = RigidDestroy;
  part->ops.initialstate   = RigidInitialState;
  part->ops.evaluate       = RigidEvaluate;
  part->ops.residual       = RigidResidual;
  part->ops.jacobian       = RigidJacobian;
  part->ops.poststep       = RigidPostStep;
  part->ops.portoutput     = RigidPortOutput;
  part->ops.portinput      = RigidPortInput;
  part->ops.portlinear     = RigidPortLinear;
  part->ops.portforce      = RigidPortForce;
  part->ops.portplacement  = RigidPortPlacement;
  part->ops.energy         = RigidEnergy;
  part->ops.inputpower     = RigidInputPower;
  part->ops.momenta        = RigidMomenta;
  part->ops.rigidmass      = RigidRigidMass;
  part->ops.outputopen     = RigidOutputOpen;
  part->ops.outputstep     = RigidOutputStep;
  part->ops.outputclose    = RigidOutputClose;
  PetscFunctionReturn(0);
}
