/* The part contract (include/private/part.h): the registry of part kinds, the life cycle shared by every part,
   and helpers the kinds share (layout, ports, wrench inputs given in the scene). */
#include <phlex_impl.h>

const char *const PhlexDirectionFrames[] = {"body", "inertial", "PhlexDirectionFrame", "PHLEX_DIRECTION_", NULL};

static PetscFunctionList PhlexPartList       = NULL;
static PetscBool         PhlexPartRegistered = PETSC_FALSE;

static PetscErrorCode PhlexPartFinalizePackage_Private(void)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListDestroy(&PhlexPartList));
  PhlexPartRegistered = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartRegister - adds a part kind: -body<k>_type <name> then calls create on a new part

  Not collective

  Notes:
  A new kind is one file implementing the core table PhlexPartOps (and, for a body with field unknowns or analyses of
  its own, PhlexPartFieldOps or PhlexPartAnalysisOps) and one call of this function.
@*/
PetscErrorCode PhlexPartRegister(const char name[], PetscErrorCode (*create)(PhlexPart))
{
  PetscFunctionBeginUser;
  PetscCall(PetscFunctionListAdd(&PhlexPartList, name, create));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartRegisterAll - registers the part kinds shipped with phlex
@*/
PetscErrorCode PhlexPartRegisterAll(void)
{
  PetscFunctionBeginUser;
  if (PhlexPartRegistered) PetscFunctionReturn(0);
  PhlexPartRegistered = PETSC_TRUE;
  PetscCall(PhlexPartRegister("flexible", PhlexPartCreate_Flexible));
  PetscCall(PhlexPartRegister("rigid", PhlexPartCreate_Rigid));
  PetscCall(PhlexPartRegister("lumped", PhlexPartCreate_Lumped));
  PetscCall(PhlexPartRegister("reduced", PhlexPartCreate_Reduced));
  PetscCall(PetscRegisterFinalize(PhlexPartFinalizePackage_Private));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreate - creates part number index (options prefix "body<index>_"); its kind is read by
  PhlexPartSetFromOptions

  Collective
@*/
PetscErrorCode PhlexPartCreate(MPI_Comm comm, PetscInt index, PhlexPart *part)
{
  PhlexPart p;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&p));
  p->comm  = comm;
  p->index = index;
  p->frame = (PhlexFrameIndex){-1, -1, -1, -1};
  PetscCall(PetscSNPrintf(p->prefix, sizeof(p->prefix), "body%" PetscInt_FMT "_", index));
  PetscCall(PetscSNPrintf(p->name, sizeof(p->name), "body%" PetscInt_FMT, index));
  *part = p;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartSetFromOptions - reads the part's name and kind, then the options of its kind

  Collective

  Options Database Keys (prefix body<k>_):
+ -name <s>                         - name in messages, output files and joint specifications
- -type <flexible,rigid,lumped,reduced> - kind of part (default flexible)
@*/
PetscErrorCode PhlexPartSetFromOptions(PhlexPart p)
{
  char      type[32] = "flexible";
  PetscBool flg, valid;
  PetscErrorCode (*create)(PhlexPart) = NULL;

  PetscFunctionBeginUser;
  PetscCall(PhlexPartRegisterAll());
  PetscOptionsBegin(p->comm, p->prefix, "Part options", NULL);
  PetscCall(PetscOptionsString("-name", "Name of the body (messages, output files, joints)", "PhlexPartSetFromOptions", p->name, p->name, sizeof(p->name), NULL));
  PetscCall(PetscOptionsFList("-type", "Kind of body: flexible (3D FE solid), rigid (mass, inertia, ports at points), lumped (a point mass), reduced (a flexible body reduced to a modal basis: the flexible options plus -reduction_*)", "PhlexPartSetFromOptions", PhlexPartList, type, type, sizeof(type), &flg));
  PetscOptionsEnd();
  PetscCall(PetscStrcmp(p->name, "ground", &flg));
  PetscCheck(!flg, p->comm, PETSC_ERR_USER_INPUT, "body %" PetscInt_FMT ": the name 'ground' is reserved for the fixed inertial frame (option -%sname)", p->index, p->prefix);
  valid = (p->name[0] && !strchr(p->name, ':') && !strchr(p->name, ',') && !strchr(p->name, ' ')) ? PETSC_TRUE : PETSC_FALSE;
  PetscCheck(valid, p->comm, PETSC_ERR_USER_INPUT, "body %" PetscInt_FMT ": option -%sname '%s' must be non-empty without ':', ',' or spaces", p->index, p->prefix, p->name);
  PetscCall(PetscFunctionListFind(PhlexPartList, type, &create));
  PetscCheck(create, p->comm, PETSC_ERR_USER_INPUT, "body %s: unknown option -%stype '%s' (flexible, rigid, lumped, reduced)", p->name, p->prefix, type);
  PetscCall(PetscStrncpy(p->type, type, sizeof(p->type)));
  PetscCall((*create)(p));
  if (p->ops.setfromoptions) PetscCall((*p->ops.setfromoptions)(p));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartView - prints a summary of the part
@*/
PetscErrorCode PhlexPartView(PhlexPart p, PetscViewer viewer)
{
  PetscFunctionBeginUser;
  if (p->ops.view) PetscCall((*p->ops.view)(p, viewer));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartDestroy - destroys a part
@*/
PetscErrorCode PhlexPartDestroy(PhlexPart *part)
{
  PhlexPart p = *part;

  PetscFunctionBeginUser;
  if (!p) PetscFunctionReturn(0);
  if (p->ops.destroy) PetscCall((*p->ops.destroy)(p));
  PetscCall(PetscFree(p->fieldops));
  PetscCall(PetscFree(p->analysisops));
  PetscCall(PetscFree2(p->qkind, p->qname));
  PetscCall(PetscFree3(p->ports, p->wrench, p->port_used));
  PetscCall(ISDestroy(&p->isu));
  PetscCall(ISDestroy(&p->iss));
  PetscCall(ISDestroy(&p->isv));
  PetscCall(PetscFree(*part));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartSetUpLayout - records the sizes of a part's unknowns (called by a kind's setup)

  Input Parameters:
+ p          - the part
. nv, Nv     - local and global size of its velocity field (= displacement field), 0 without a field
. ns, Ns     - local and global size of its stress field
- nq         - number of discrete unknowns (then PhlexPartSetDof names each)
@*/
PetscErrorCode PhlexPartSetUpLayout(PhlexPart p, PetscInt nv, PetscInt Nv, PetscInt ns, PetscInt Ns, PetscInt nq)
{
  PetscFunctionBeginUser;
  PetscCheck(!Nv || p->fieldops, p->comm, PETSC_ERR_PLIB, "part %s of kind %s has field unknowns but no field table (PhlexPartFieldOps)", p->name, p->type);
  p->nu = p->nv = nv;
  p->Nu = p->Nv = Nv;
  p->ns         = ns;
  p->Ns         = Ns;
  p->nq         = nq;
  PetscCall(PetscFree2(p->qkind, p->qname));
  PetscCall(PetscCalloc2(PetscMax(nq, 1), &p->qkind, PetscMax(nq, 1), &p->qname));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartSetDof - names discrete unknown k of a part and says what it is
@*/
PetscErrorCode PhlexPartSetDof(PhlexPart p, PetscInt k, PhlexDofKind kind, const char name[])
{
  PetscFunctionBeginUser;
  PetscCheck(k >= 0 && k < p->nq, PETSC_COMM_SELF, PETSC_ERR_PLIB, "discrete unknown %" PetscInt_FMT " of a part with %" PetscInt_FMT, k, p->nq);
  p->qkind[k] = kind;
  PetscCall(PetscStrncpy(p->qname[k], name, sizeof(p->qname[k])));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartFind - the part of a given name among parts (NULL if none; "ground" is the ground)
@*/
PetscErrorCode PhlexPartFind(PetscInt nparts, const PhlexPart parts[], PhlexPart ground, const char name[], PhlexPart *part)
{
  PetscBool same;

  PetscFunctionBeginUser;
  *part = NULL;
  PetscCall(PetscStrcmp(name, "ground", &same));
  if (same) *part = ground;
  for (PetscInt k = 0; k < nparts; k++) {
    PetscCall(PetscStrcmp(parts[k]->name, name, &same));
    if (same) *part = parts[k];
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartIsElastic - whether a part deforms: field unknowns (a flexible body) or elastic coordinates (a reduced
  body's eta, PHLEX_DOF_ELASTIC); its ports may then move and turn relative to its frame

  Not collective
@*/
PetscBool PhlexPartIsElastic(PhlexPart p)
{
  if (!p || PhlexPartIsGround(p)) return PETSC_FALSE;
  if (p->Nv) return PETSC_TRUE;
  for (PetscInt k = 0; k < p->nq; k++)
    if (p->qkind[k] == PHLEX_DOF_ELASTIC) return PETSC_TRUE;
  return PETSC_FALSE;
}

/*@C
  PhlexPortPlacementFromMean - the inertial position and orientation of a port of a deforming body from its frame and
  the port's mean displacement and rotation: r + R (c + ubar), R exp([theta]x)

  Input Parameters:
+ frame - the frame's r (3) and R (9, row-wise) as in the part's unknowns, or NULL for a fixed body (identity)
. point - the port point c relative to the frame origin, body frame
- ub    - the port's mean displacement (3) and rotation vector (3), body frame

  Not collective
@*/
void PhlexPortPlacementFromMean(const PetscReal *frame, const PetscReal point[3], const PetscReal ub[6], PetscReal x[3], PetscReal Rp[9])
{
  PetscReal R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, c[3], E[9], n;

  if (frame)
    for (PetscInt k = 0; k < 9; k++) R[k] = frame[3 + k];
  for (PetscInt k = 0; k < 3; k++) c[k] = point[k] + ub[k];
  PhlexMatVec3(R, c, x);
  if (frame)
    for (PetscInt k = 0; k < 3; k++) x[k] += frame[k];
  n = PhlexNorm3(ub + 3);
  PhlexAxisAngleToRotation(n > 0 ? ub + 3 : (PetscReal[3]){1, 0, 0}, n, E);
  PhlexMatMat3(R, E, Rp);
}

/*@C
  PhlexPartSetPorts - allocates the port table of a part (names and points filled by the kind)
@*/
PetscErrorCode PhlexPartSetPorts(PhlexPart p, PetscInt n)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree3(p->ports, p->wrench, p->port_used));
  p->nports = n;
  PetscCall(PetscCalloc3(PetscMax(n, 1), &p->ports, PetscMax(n, 1), &p->wrench, PetscMax(n, 1), &p->port_used));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartFindPort - the index of a port by name (-1 if the part has no such port)
@*/
PetscErrorCode PhlexPartFindPort(PhlexPart p, const char name[], PetscInt *port)
{
  PetscBool same;

  PetscFunctionBeginUser;
  *port = -1;
  for (PetscInt k = 0; k < p->nports; k++) {
    PetscCall(PetscStrcmp(p->ports[k].name, name, &same));
    if (same) *port = k;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartGetVec - a part's view of a global vector: sub-vectors of its field blocks and its discrete unknowns
  (q: the replicated discrete values of that vector, see PhlexSystemGather)

  Collective
@*/
PetscErrorCode PhlexPartGetVec(PhlexPart p, Vec X, PetscReal *q, PhlexPartVec *pv)
{
  PetscFunctionBeginUser;
  pv->u = pv->s = pv->v = pv->p = NULL;
  if (p->isu) {
    PetscCall(VecGetSubVector(X, p->isu, &pv->u));
    PetscCall(VecGetSubVector(X, p->iss, &pv->s));
    PetscCall(VecGetSubVector(X, p->isv, &pv->v));
  }
  pv->q = q ? q + p->qoff : NULL;
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexPartRestoreVec(PhlexPart p, Vec X, PhlexPartVec *pv)
{
  PetscFunctionBeginUser;
  if (p->isu) {
    PetscCall(VecRestoreSubVector(X, p->isu, &pv->u));
    PetscCall(VecRestoreSubVector(X, p->iss, &pv->s));
    PetscCall(VecRestoreSubVector(X, p->isv, &pv->v));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPoseSetFromOptions - reads the initial placement and velocity of a moving frame (inside the part's options
  block); 'given' returns the name of the first option given (NULL if none), for kinds or settings that have no
  moving frame to refuse them

  Options Database Keys (prefix body<k>_):
+ -position x,y,z                  - initial position r_P of the frame origin [m] (default: as drawn)
. -orientation_quaternion w,x,y,z  - initial orientation R
. -orientation_axis_angle x,y,z,a  - initial orientation as axis and angle [deg]
. -velocity vx,vy,vz               - initial velocity of P, body frame [m/s]
- -angular_velocity wx,wy,wz       - initial angular velocity, body frame [rad/s]
@*/
PetscErrorCode PhlexPoseSetFromOptions(PetscOptionItems *PetscOptionsObject, PhlexPart p, PhlexPose *pose, const char **given)
{
  PetscReal quat[4] = {1, 0, 0, 0}, aa[5] = {1, 0, 0, 0, 0}; /* room for a fifth number: a wrong count is seen */
  PetscBool fq = PETSC_FALSE, fa = PETSC_FALSE;
  PetscInt  n  = 5;
  char      who[PHLEX_NAME_LEN + 8];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", p->name));
  pose->rotation[0] = pose->rotation[4] = pose->rotation[8] = 1.0;
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, p->comm, who, p->prefix, "-position", "Initial position r_P of the frame origin (default: as drawn) [m]", "PhlexPoseSetFromOptions", 3, pose->position, &pose->position_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, p->comm, who, p->prefix, "-orientation_quaternion", "Initial orientation R as a quaternion w,x,y,z [-]", "PhlexPoseSetFromOptions", 4, quat, &fq));
  PetscCall(PhlexOptionsRealList("-orientation_axis_angle", "Initial orientation R as axis x,y,z and angle [deg]", "PhlexPoseSetFromOptions", aa, &n, &fa, 0));
  PetscCheck(!fa || n == 4, p->comm, PETSC_ERR_USER_INPUT, "body %s: option -%sorientation_axis_angle needs 4 numbers (axis, angle in degrees), got %" PetscInt_FMT, p->name, p->prefix, n);
  PetscCheck(!(fq && fa), p->comm, PETSC_ERR_USER_INPUT, "body %s: give -%sorientation_quaternion or -%sorientation_axis_angle, not both", p->name, p->prefix, p->prefix);
  if (fq) {
    PetscCheck(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3] > 0, p->comm, PETSC_ERR_USER_INPUT, "body %s: -%sorientation_quaternion must not be zero", p->name, p->prefix);
    PhlexQuaternionToRotation(quat, pose->rotation);
  }
  if (fa) {
    PetscCheck(aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2] > 0, p->comm, PETSC_ERR_USER_INPUT, "body %s: the axis of -%sorientation_axis_angle must not be zero", p->name, p->prefix);
    PhlexAxisAngleToRotation(aa, aa[3] * PETSC_PI / 180.0, pose->rotation);
  }
  pose->orientation_given = (fq || fa) ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, p->comm, who, p->prefix, "-velocity", "Initial velocity v_P of the frame origin (body frame) [m/s]", "PhlexPoseSetFromOptions", 3, pose->velocity, &pose->velocity_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, p->comm, who, p->prefix, "-angular_velocity", "Initial angular velocity w_P (body frame) [rad/s]", "PhlexPoseSetFromOptions", 3, pose->omega, &pose->omega_given));
  if (given) *given = pose->position_given ? "position" : fq ? "orientation_quaternion" : fa ? "orientation_axis_angle" : pose->velocity_given ? "velocity" : pose->omega_given ? "angular_velocity" : NULL;
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Wrench inputs of a port given in the scene                                                                    */

/*@C
  PhlexPortLoadSetFromOptions - reads the wrench input of a port

  Collective

  Options Database Keys (prefix -<body>port_<name>_):
+ -force Fx,Fy,Fz      - force amplitude [N]
. -moment Tx,Ty,Tz     - moment amplitude about the port point [N m]
. -traction tx,ty,tz   - uniform traction amplitude [Pa] instead of -force (surface ports)
. -direction <body,inertial> - the amplitudes are fixed in the body frame (follower load) or in the inertial frame
- -profile_type ...    - time profile (PhlexProfileSetFromOptions)
@*/
PetscErrorCode PhlexPortLoadSetFromOptions(PhlexPart part, const char port[], PetscBool surface, PhlexPortLoad *L)
{
  char      prefix[256], what[256];
  PetscBool flg_force = PETSC_FALSE, flg_traction = PETSC_FALSE, flg_moment = PETSC_FALSE;
  PetscReal traction[3] = {0, 0, 0};

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sport_%s_", part->prefix, port));
  PetscCall(PetscSNPrintf(what, sizeof(what), "body %s, port %s", part->name, port));
  PetscOptionsBegin(part->comm, prefix, "Port input options", NULL);
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, what, prefix, "-force", "Force amplitude on the port [N]", "PhlexPortLoadSetFromOptions", 3, L->force, &flg_force));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, what, prefix, "-moment", "Moment amplitude about the port point [N m]", "PhlexPortLoadSetFromOptions", 3, L->moment, &flg_moment));
  if (surface) PetscCall(PhlexOptionsRealN(PetscOptionsObject, part->comm, what, prefix, "-traction", "Uniform traction amplitude [Pa], alternative to -force", "PhlexPortLoadSetFromOptions", 3, traction, &flg_traction));
  PetscCall(PetscOptionsEnum("-direction", "Frame of the force and moment directions: body (follows the body) or inertial (fixed in space)", "PhlexPortLoadSetFromOptions", PhlexDirectionFrames, (PetscEnum)L->frame, (PetscEnum *)&L->frame, NULL));
  PetscOptionsEnd();
  PetscCheck(!(flg_force && flg_traction), part->comm, PETSC_ERR_USER_INPUT, "%s: give either -%sforce or -%straction, not both", what, prefix, prefix);
  if (flg_traction) {
    /* converted to a force once the area is known; kept in force[] meanwhile */
    for (PetscInt d = 0; d < 3; d++) L->force[d] = traction[d];
    L->traction_input = PETSC_TRUE;
  }
  L->loaded = PETSC_FALSE;
  for (PetscInt d = 0; d < 3; d++)
    if (L->force[d] != 0.0 || L->moment[d] != 0.0) L->loaded = PETSC_TRUE;
  PetscCall(PhlexProfileCreate(part->comm, prefix, what, &L->profile));
  PetscCall(PhlexProfileSetFromOptions(L->profile));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPortLoadEvaluate - the non-dimensional wrench w(t) = f(t) [F; T] of a port input in the body frame
  (R: the body's rotation, for inertial directions; NULL means the identity)

  Not collective
@*/
PetscErrorCode PhlexPortLoadEvaluate(PhlexPortLoad *L, PetscReal t, const PhlexUnits *units, const PetscReal *R, PetscReal w[6])
{
  PetscReal f;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) w[k] = 0.0;
  if (!L->loaded) PetscFunctionReturn(0);
  PetscCall(PhlexProfileEvaluate(L->profile, t, &f));
  for (PetscInt d = 0; d < 3; d++) {
    w[d]     = f * L->force[d] / units->force;
    w[3 + d] = f * L->moment[d] / (units->force * units->length);
  }
  if (L->frame == PHLEX_DIRECTION_INERTIAL && R) {
    PhlexMatTVec3(R, w, w);
    PhlexMatTVec3(R, w + 3, w + 3);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPortLoadDerivativeR - d w / d R_ij (entry k = 3 i + j of R) of an input with inertial directions
  ((R^T a)_c depends on R_ij as delta_cj a_i); zero for body directions

  Not collective
@*/
PetscErrorCode PhlexPortLoadDerivativeR(PhlexPortLoad *L, PetscReal t, const PhlexUnits *units, PetscInt k, PetscReal dw[6])
{
  PetscReal a[6];
  PetscInt  i = k / 3, j = k % 3;

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < 6; c++) dw[c] = 0.0;
  if (!L->loaded || L->frame != PHLEX_DIRECTION_INERTIAL) PetscFunctionReturn(0);
  PetscCall(PhlexPortLoadEvaluate(L, t, units, NULL, a));
  dw[j]     = a[i];
  dw[3 + j] = a[3 + i];
  PetscFunctionReturn(0);
}

/*@C
  PhlexPortLoadDescribe - ", force (..) N, moment (..) N m (frame), profile ..." or "" without a load
@*/
PetscErrorCode PhlexPortLoadDescribe(PhlexPortLoad *L, char buf[], size_t len)
{
  char prof[256];

  PetscFunctionBeginUser;
  buf[0] = 0;
  if (!L->loaded) PetscFunctionReturn(0);
  PetscCall(PhlexProfileDescribe(L->profile, prof, sizeof(prof)));
  PetscCall(PetscSNPrintf(buf, len, ", force (%g, %g, %g) N, moment (%g, %g, %g) N m%s, profile %s", (double)L->force[0], (double)L->force[1], (double)L->force[2], (double)L->moment[0], (double)L->moment[1], (double)L->moment[2], L->frame == PHLEX_DIRECTION_INERTIAL ? " (inertial directions)" : "", prof));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexPortLoadDestroy(PhlexPortLoad *L)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexProfileDestroy(&L->profile));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* The ground: the inertial frame, no unknowns. A joint to the ground fixes its other port to a point of space.  */

PetscBool PhlexPartIsGround(PhlexPart p)
{
  return p && p->index < 0 ? PETSC_TRUE : PETSC_FALSE;
}

static PetscErrorCode PartView_Ground(PhlexPart p, PetscViewer viewer)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerASCIIPrintf(viewer, "ground: the inertial frame\n"));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexPartCreate_Ground(PhlexPart p)
{
  PetscFunctionBeginUser;
  p->ops.view = PartView_Ground;
  PetscCall(PetscStrcpy(p->type, "ground"));
  PetscCall(PhlexPartSetUpLayout(p, 0, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreateGround - the ground part of a scene
@*/
PetscErrorCode PhlexPartCreateGround(MPI_Comm comm, PhlexPart *ground)
{
  PetscFunctionBeginUser;
  PetscCall(PetscNew(ground));
  (*ground)->comm  = comm;
  (*ground)->index = -1;
  (*ground)->frame = (PhlexFrameIndex){-1, -1, -1, -1};
  PetscCall(PetscStrcpy((*ground)->name, "ground"));
  PetscCall(PetscStrcpy((*ground)->prefix, "ground_"));
  PetscCall(PhlexPartCreate_Ground(*ground));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* The ports series (<part>_ports.csv) of the parts with ports: per step and port its wrench input and output,     */
/* then the inertial position of each port point                                                                 */

/*@C
  PhlexPortSeriesOpen - opens <part>_ports.csv with its header: for each name (a moving frame's first, then the
  ports) _Fx.._Tz, _vx.._wz, then for each _x,_y,_z (in one piece: a restarted run continues the series without it)

  Collective
@*/
PetscErrorCode PhlexPortSeriesOpen(PhlexOutput out, const char part[], PetscInt n, const char *const names[], PetscViewer *csv)
{
  const size_t len = (size_t)(n * 15 + 1) * (PHLEX_NAME_LEN + 8);
  char        *h, name[PHLEX_NAME_LEN + 16];
  size_t       k;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(len, &h));
  PetscCall(PetscStrcpy(h, "time"));
  for (PetscInt p = 0; p < n; p++) {
    const char *pn = names[p];
    PetscCall(PetscStrlen(h, &k));
    PetscCall(PetscSNPrintf(h + k, len - k, ",%s_Fx,%s_Fy,%s_Fz,%s_Tx,%s_Ty,%s_Tz,%s_vx,%s_vy,%s_vz,%s_wx,%s_wy,%s_wz", pn, pn, pn, pn, pn, pn, pn, pn, pn, pn, pn, pn));
  }
  for (PetscInt p = 0; p < n; p++) {
    PetscCall(PetscStrlen(h, &k));
    PetscCall(PetscSNPrintf(h + k, len - k, ",%s_x,%s_y,%s_z", names[p], names[p], names[p]));
  }
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_ports.csv", part));
  PetscCall(PhlexOutputCSVOpen(out, name, h, csv));
  PetscCall(PetscFree(h));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPortSeriesEntry - one port's wrench (SI when si, else non-dimensional) and output y (non-dimensional) in a
  ports series row
@*/
PetscErrorCode PhlexPortSeriesEntry(PetscViewer csv, const PhlexUnits *u, const PetscReal w[6], PetscBool si, const PetscReal y[6])
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < 3; c++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(si ? w[c] : w[c] * u->force)));
  for (PetscInt c = 3; c < 6; c++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(si ? w[c] : w[c] * u->force * u->length)));
  for (PetscInt c = 0; c < 3; c++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(y[c] * u->velocity)));
  for (PetscInt c = 3; c < 6; c++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(y[c] / u->time)));
  PetscFunctionReturn(0);
}

/*@C
  PhlexPortSeriesPosition - a port point's inertial position (non-dimensional) in a ports series row
@*/
PetscErrorCode PhlexPortSeriesPosition(PetscViewer csv, const PhlexUnits *u, const PetscReal x[3])
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < 3; c++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(x[c] * u->length)));
  PetscFunctionReturn(0);
}
