/* Joints (include/private/joint.h): the transformer interconnection of two ports at velocity level (paper Section
   5.1, eq. int_hinge generalised to 3D: the relative velocity of the ports, rotated by R_ab = R_a^T R_b, is
   constrained along the joint's directions; the multipliers act on both ports through their distributions). The
   joint kinds differ only in the directions they constrain (joint_types.c). */
#include <phlex_impl.h>

const char *const PhlexJointTypes[] = {"fixed", "revolute", "spherical", "prismatic", "cylindrical", "universal", "planar", "prescribed", "PhlexJointType", "PHLEX_JOINT_", NULL};

PETSC_INTERN PetscErrorCode PhlexJointSelectRows(PhlexJoint);

/* ------------------------------------------------------------------------------------------------------------ */
/* Small helpers                                                                                                 */

/* the rotation of a side's body frame (identity for the ground and for a point mass) */
static void SideRotation(PhlexJoint j, PetscInt s, const PetscReal *q, PetscReal R[9])
{
  PhlexPart p = j->side[s].part;

  for (PetscInt k = 0; k < 9; k++) R[k] = (k % 4 == 0) ? 1.0 : 0.0;
  if (!PhlexPartIsGround(p) && p->frame.R >= 0)
    for (PetscInt k = 0; k < 9; k++) R[k] = q[p->qoff + p->frame.R + k];
}

/* a port's output moved to the joint point d (body frame): (y_v + y_w x d, y_w) */
static void MoveToJoint(const PetscReal d[3], const PetscReal y[6], PetscReal yt[6])
{
  PetscReal a[3];

  PhlexCross(y + 3, d, a);
  for (PetscInt k = 0; k < 3; k++) {
    yt[k]     = y[k] + a[k];
    yt[3 + k] = y[3 + k];
  }
}

/* the transpose: a wrench at the joint point as a wrench at the port point (F, T + d x F) */
static void MoveToPort(const PetscReal d[3], const PetscReal w[6], PetscReal wp[6])
{
  PetscReal a[3];

  PhlexCross(d, w, a);
  for (PetscInt k = 0; k < 3; k++) {
    wp[k]     = w[k];
    wp[3 + k] = w[3 + k] + a[k];
  }
}

/* y = blockdiag(R, R) x (transpose: R^T) */
static void Rotate6(const PetscReal R[9], PetscBool transpose, const PetscReal x[6], PetscReal y[6])
{
  if (transpose) {
    PhlexMatTVec3(R, x, y);
    PhlexMatTVec3(R, x + 3, y + 3);
  } else {
    PhlexMatVec3(R, x, y);
    PhlexMatVec3(R, x + 3, y + 3);
  }
}

static PetscReal Dot6(const PetscReal a[6], const PetscReal b[6])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

/* the direction (6-vector, a's body frame) of row k, and its change for a change dRab of R_ab (universal only) */
static void RowDirection(PhlexJoint j, PetscInt k, const PetscReal Rab[9], const PetscReal *dRab, PetscReal s[6])
{
  for (PetscInt c = 0; c < 6; c++) s[c] = 0.0;
  switch (j->row[k]) {
  case PHLEX_ROW_T1:
  case PHLEX_ROW_T2:
  case PHLEX_ROW_T3:
    if (!dRab)
      for (PetscInt c = 0; c < 3; c++) s[c] = j->dir[3 * (j->row[k] - PHLEX_ROW_T1) + c];
    break;
  case PHLEX_ROW_R1:
  case PHLEX_ROW_R2:
  case PHLEX_ROW_R3:
    if (!dRab)
      for (PetscInt c = 0; c < 3; c++) s[3 + c] = j->dir[3 * (j->row[k] - PHLEX_ROW_R1) + c];
    break;
  case PHLEX_ROW_CROSS: {
    /* n = e_a x (R_ab e_b): both axes turn with their bodies */
    PetscReal eb[3];
    PhlexMatVec3(dRab ? dRab : Rab, j->eb, eb);
    PhlexCross(j->dir + 6, eb, s + 3);
  } break;
  }
}

/* dR_ab and dG for the entry m of R of side s (R_ab = R_a^T R_b, G = R_a^T R_a) */
static void RabDerivative(PetscInt s, PetscInt m, const PetscReal Ra[9], const PetscReal Rb[9], PetscReal dRab[9], PetscReal dG[9])
{
  const PetscInt i = m / 3, jj = m % 3;

  for (PetscInt k = 0; k < 9; k++) dRab[k] = dG[k] = 0.0;
  for (PetscInt k = 0; k < 3; k++)
    for (PetscInt l = 0; l < 3; l++) {
      if (s == 0 && k == jj) dRab[3 * k + l] = Rb[3 * i + l]; /* d(R_a)_ij: delta_kj (R_b)_il */
      if (s == 1 && l == jj) dRab[3 * k + l] = Ra[3 * i + k]; /* d(R_b)_ij: (R_a)_ik delta_lj */
      if (s == 0) dG[3 * k + l] = (k == jj ? Ra[3 * i + l] : 0.0) + (l == jj ? Ra[3 * i + k] : 0.0);
    }
}

PetscBool PhlexJointTouches(PhlexJoint j, PhlexPart p)
{
  return (j->side[0].part == p || j->side[1].part == p) ? PETSC_TRUE : PETSC_FALSE;
}

/* the part's global index of discrete unknown k, or -1 */
static PetscInt QIndex(PhlexPart p, PetscInt k)
{
  return PhlexPartIsGround(p) || k < 0 ? -1 : p->qoff + k;
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Creation and options                                                                                          */

/*@C
  PhlexJointCreate - creates joint number index (options prefix "joint<index>_") of a scene whose reference scales
  are units (read when the joint is set up, filled by the scene before)

  Collective
@*/
PetscErrorCode PhlexJointCreate(MPI_Comm comm, const PhlexUnits *units, PetscInt index, PhlexJoint *joint)
{
  PhlexJoint j;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&j));
  j->comm      = comm;
  j->units     = units;
  j->index     = index;
  j->drive_row = -1;
  PetscCall(PetscSNPrintf(j->prefix, sizeof(j->prefix), "joint%" PetscInt_FMT "_", index));
  PetscCall(PetscSNPrintf(j->ports_option, sizeof(j->ports_option), "-%sports", j->prefix));
  PetscCall(PetscSNPrintf(j->name, sizeof(j->name), "joint%" PetscInt_FMT, index));
  *joint = j;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointSetFromOptions - reads a joint

  Collective

  Options Database Keys (prefix joint<k>_):
+ -name <s>                   - name in messages and output files
. -type <fixed,revolute,spherical,prismatic,cylindrical,universal,planar,prescribed> - what it constrains
. -ports a:p,b:q              - the two ports (body:port, or ground); prescribed: one port
. -axis x,y,z                 - revolute, prismatic, cylindrical: the axis; universal: the axis on a; planar: the normal
. -axis2 x,y,z                - universal: the axis on b (orthogonal to -axis)
. -reference_direction x,y,z  - first axis e1 of the joint frame (output components)
. -position x,y,z             - joint point (default: the first port's point) [m]
. -drive_velocity v           - drive the free rotation (revolute, cylindrical) [rad/s] or slide (prismatic) [m/s]
. -drive_initial a            - its initial angle [deg] or slide [m] relative to the drawn configuration
. -drive_component <rotation,translation> - cylindrical: which one is driven
. -drive_profile_*            - time profile of the drive velocity
. -velocity vx,vy,vz          - prescribed: the port point's velocity (inertial) [m/s]
. -angular_velocity wx,wy,wz  - prescribed: the port's angular velocity (inertial) [rad/s]
- -profile_*                  - prescribed: time profile of those
@*/
PetscErrorCode PhlexJointSetFromOptions(PhlexJoint j)
{
  char    **ports;
  PetscInt  nports, nalloc, type = PHLEX_JOINT_REVOLUTE, comp = 0;
  PetscBool ftype = PETSC_FALSE, fports = PETSC_FALSE, fdrive = PETSC_FALSE, fcomp = PETSC_FALSE, fdi = PETSC_FALSE;
  char      who[PHLEX_NAME_LEN + 16];
  const char *const comps[] = {"rotation", "translation", "PhlexDriveComponent", "", NULL};

  PetscFunctionBeginUser;
  PetscCall(PhlexOptionsListLength(j->prefix, "-ports", &nalloc)); /* the count a wrong list really has */
  nports = nalloc;
  PetscCall(PetscCalloc1(nalloc, &ports));
  PetscOptionsBegin(j->comm, j->prefix, "Joint options", NULL);
  PetscCall(PetscOptionsString("-name", "Name of the joint (messages, output files)", "PhlexJointSetFromOptions", j->name, j->name, sizeof(j->name), NULL));
  PetscCall(PetscSNPrintf(who, sizeof(who), "joint %s", j->name));
  PetscCall(PetscOptionsEList("-type", "Joint kind: fixed, revolute, spherical, prismatic, cylindrical, universal, planar, prescribed (a port's motion)", "PhlexJointSetFromOptions", PhlexJointTypes, 8, PhlexJointTypes[type], &type, &ftype));
  PetscCall(PetscOptionsStringArray("-ports", "The two ports joined: body:port,body:port or body:port,ground (prescribed: body:port)", "PhlexJointSetFromOptions", ports, &nports, &fports));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-axis", "Axis (inertial, drawn configuration): revolute, prismatic, cylindrical, universal (on the first port), planar (normal)", "PhlexJointSetFromOptions", 3, j->axis, &j->axis_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-axis2", "Universal joint: the axis on the second port (orthogonal to -axis)", "PhlexJointSetFromOptions", 3, j->axis2, &j->axis2_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-reference_direction", "First axis e1 of the joint frame (the components of the output) (inertial)", "PhlexJointSetFromOptions", 3, j->reference, &j->reference_given));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-position", "Joint point (inertial, drawn configuration; default: the first port's point) [m]", "PhlexJointSetFromOptions", 3, j->position, &j->position_given));
  PetscCall(PetscOptionsReal("-drive_velocity", "Drive: prescribed relative angular velocity [rad/s] (revolute, cylindrical) or sliding velocity [m/s] (prismatic)", "PhlexJointSetFromOptions", j->drive_velocity, &j->drive_velocity, &fdrive));
  PetscCall(PetscOptionsReal("-drive_initial", "Drive: initial angle [deg] or slide [m] relative to the drawn configuration", "PhlexJointSetFromOptions", j->drive_initial, &j->drive_initial, &fdi));
  PetscCall(PetscOptionsEList("-drive_component", "Cylindrical joint: the driven motion", "PhlexJointSetFromOptions", comps, 2, comps[comp], &comp, &fcomp));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-velocity", "Prescribed motion: velocity of the port point (inertial) [m/s]", "PhlexJointSetFromOptions", 3, j->presc_velocity, &j->presc_v));
  PetscCall(PhlexOptionsRealN(PetscOptionsObject, j->comm, who, j->prefix, "-angular_velocity", "Prescribed motion: angular velocity of the port (inertial) [rad/s]", "PhlexJointSetFromOptions", 3, j->presc_angular, &j->presc_w));
  PetscOptionsEnd();
  PetscCheck(ftype, j->comm, PETSC_ERR_USER_INPUT, "joint %s: give its kind: -%stype fixed|revolute|spherical|prismatic|cylindrical|universal|planar|prescribed", j->name, j->prefix);
  j->type = (PhlexJointType)type;
  PetscCheck(fports, j->comm, PETSC_ERR_USER_INPUT, "joint %s: give its ports: -%sports body:port,body:port (or body:port,ground)", j->name, j->prefix);
  if (j->type == PHLEX_JOINT_PRESCRIBED) {
    PetscCheck(nports == 1, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a prescribed motion acts on one port: -%sports body:port (got %" PetscInt_FMT ")", j->name, j->prefix, nports);
    PetscCheck(j->presc_v || j->presc_w, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a prescribed motion needs -%svelocity and/or -%sangular_velocity", j->name, j->prefix, j->prefix);
    PetscCall(PetscStrcpy(j->side[0].spec, "ground"));
    PetscCall(PetscStrncpy(j->side[1].spec, ports[0], sizeof(j->side[1].spec)));
  } else {
    PetscCheck(nports == 2, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sports needs two ports (body:port,body:port or body:port,ground), got %" PetscInt_FMT, j->name, j->prefix, nports);
    PetscCall(PetscStrncpy(j->side[0].spec, ports[0], sizeof(j->side[0].spec)));
    PetscCall(PetscStrncpy(j->side[1].spec, ports[1], sizeof(j->side[1].spec)));
    PetscCheck(!j->presc_v && !j->presc_w, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%svelocity and -%sangular_velocity belong to a prescribed motion (-%stype prescribed)", j->name, j->prefix, j->prefix, j->prefix);
  }
  for (PetscInt k = 0; k < nports; k++) PetscCall(PetscFree(ports[k]));
  PetscCall(PetscFree(ports));
  {
    const PetscBool needs_axis = (j->type == PHLEX_JOINT_REVOLUTE || j->type == PHLEX_JOINT_PRISMATIC || j->type == PHLEX_JOINT_CYLINDRICAL || j->type == PHLEX_JOINT_UNIVERSAL || j->type == PHLEX_JOINT_PLANAR) ? PETSC_TRUE : PETSC_FALSE;
    PetscCheck(!needs_axis || j->axis_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a %s joint needs its axis: -%saxis x,y,z", j->name, PhlexJointTypes[j->type], j->prefix);
    PetscCheck(needs_axis || !j->axis_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a %s joint has no axis (-%saxis)", j->name, PhlexJointTypes[j->type], j->prefix);
    PetscCheck(!j->axis_given || PhlexNorm3(j->axis) > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%saxis must not be the zero vector", j->name, j->prefix);
    PetscCheck(j->type == PHLEX_JOINT_UNIVERSAL || !j->axis2_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%saxis2 is for a universal joint", j->name, j->prefix);
    PetscCheck(j->type != PHLEX_JOINT_UNIVERSAL || j->axis2_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a universal joint needs the axis on its second port: -%saxis2 x,y,z", j->name, j->prefix);
    if (j->type == PHLEX_JOINT_UNIVERSAL) {
      const PetscReal na = PhlexNorm3(j->axis), nb = PhlexNorm3(j->axis2);
      PetscCheck(nb > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%saxis2 must not be the zero vector", j->name, j->prefix);
      PetscCheck(PetscAbsReal(PhlexDot3(j->axis, j->axis2)) <= 1e-8 * na * nb, j->comm, PETSC_ERR_USER_INPUT, "joint %s: the axes of a universal joint must be orthogonal: -%saxis (%g, %g, %g) and -%saxis2 (%g, %g, %g)", j->name, j->prefix, (double)j->axis[0], (double)j->axis[1], (double)j->axis[2], j->prefix, (double)j->axis2[0], (double)j->axis2[1], (double)j->axis2[2]);
    }
    PetscCheck(!j->reference_given || PhlexNorm3(j->reference) > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sreference_direction must not be the zero vector", j->name, j->prefix);
  }
  if (fdrive || fdi || fcomp) {
    PetscCheck(j->type == PHLEX_JOINT_REVOLUTE || j->type == PHLEX_JOINT_PRISMATIC || j->type == PHLEX_JOINT_CYLINDRICAL, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a drive (-%sdrive_*) needs a revolute, prismatic or cylindrical joint, not %s", j->name, j->prefix, PhlexJointTypes[j->type]);
    PetscCheck(fdrive, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a drive needs its velocity -%sdrive_velocity", j->name, j->prefix);
    PetscCheck(!fcomp || j->type == PHLEX_JOINT_CYLINDRICAL, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sdrive_component is for a cylindrical joint", j->name, j->prefix);
    {
      char prefix[256], what[256];
      PetscCall(PetscSNPrintf(prefix, sizeof(prefix), "%sdrive_", j->prefix));
      PetscCall(PetscSNPrintf(what, sizeof(what), "joint %s, drive", j->name));
      PetscCall(PhlexProfileCreate(j->comm, prefix, what, &j->drive_profile));
      PetscCall(PhlexProfileSetFromOptions(j->drive_profile));
    }
    /* the driven row is appended by PhlexJointSelectRows: mark the component */
    j->drive_row = (j->type == PHLEX_JOINT_PRISMATIC || (j->type == PHLEX_JOINT_CYLINDRICAL && comp == 1)) ? PHLEX_ROW_T3 : PHLEX_ROW_R3;
    if (j->drive_row == PHLEX_ROW_R3) j->drive_initial *= PETSC_PI / 180.0;
  }
  if (j->type == PHLEX_JOINT_PRESCRIBED) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(what, sizeof(what), "joint %s, prescribed motion", j->name));
    PetscCall(PhlexProfileCreate(j->comm, j->prefix, what, &j->drive_profile));
    PetscCall(PhlexProfileSetFromOptions(j->drive_profile));
    (void)prefix;
  }
  PetscFunctionReturn(0);
}

/* "body:port" or "ground" to a part and a port */
static PetscErrorCode ResolveSide(PhlexJoint j, PetscInt s, PetscInt nparts, const PhlexPart parts[], PhlexPart ground)
{
  PhlexJointSide *side = &j->side[s];
  char            body[PHLEX_NAME_LEN * 2], *colon;
  PetscBool       is_ground;

  PetscFunctionBeginUser;
  PetscCall(PetscStrcmp(side->spec, "ground", &is_ground));
  if (is_ground) {
    side->part     = ground;
    side->port     = -1;
    side->rotation = PETSC_TRUE;
    PetscFunctionReturn(0);
  }
  PetscCall(PetscStrncpy(body, side->spec, sizeof(body)));
  colon = strchr(body, ':');
  PetscCheck(colon, j->comm, PETSC_ERR_USER_INPUT, "joint %s: option %s: '%s' is not body:port or ground", j->name, j->ports_option, side->spec);
  *colon = 0;
  PetscCall(PhlexPartFind(nparts, parts, ground, body, &side->part));
  PetscCheck(side->part, j->comm, PETSC_ERR_USER_INPUT, "joint %s: option %s: no body named '%s'", j->name, j->ports_option, body);
  PetscCall(PhlexPartFindPort(side->part, colon + 1, &side->port));
  if (side->port < 0) {
    char avail[1024] = "";
    for (PetscInt k = 0; k < side->part->nports; k++) {
      size_t have, more;
      PetscCall(PetscStrlen(avail, &have));
      PetscCall(PetscStrlen(side->part->ports[k].name, &more));
      if (have + more + 8 >= sizeof(avail)) { /* a long list: the first ones */
        PetscCall(PetscStrlcat(avail, ", ...", sizeof(avail)));
        break;
      }
      PetscCall(PetscStrlcat(avail, k ? ", " : "", sizeof(avail)));
      PetscCall(PetscStrlcat(avail, side->part->ports[k].name, sizeof(avail)));
    }
    SETERRQ(j->comm, PETSC_ERR_USER_INPUT, "joint %s: option %s: body %s has no port '%s' (its ports: %s)", j->name, j->ports_option, body, colon + 1, side->part->nports ? avail : "none");
  }
  side->rotation = side->part->ports[side->port].dim == 6 ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointResolve - finds the joint's parts and ports among the scene's parts (after their set-up) and selects its
  rows

  Collective
@*/
PetscErrorCode PhlexJointResolve(PhlexJoint j, PetscInt nparts, const PhlexPart parts[], PhlexPart ground)
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) PetscCall(ResolveSide(j, s, nparts, parts, ground));
  PetscCheck(!(PhlexPartIsGround(j->side[0].part) && PhlexPartIsGround(j->side[1].part)), j->comm, PETSC_ERR_USER_INPUT, "joint %s: both ports are the ground (-%sports)", j->name, j->prefix);
  PetscCheck(!(j->side[0].part == j->side[1].part && j->side[0].port == j->side[1].port), j->comm, PETSC_ERR_USER_INPUT, "joint %s: a port cannot be joined to itself (-%sports %s,%s)", j->name, j->prefix, j->side[0].spec, j->side[1].spec);
  for (PetscInt s = 0; s < 2; s++)
    if (!PhlexPartIsGround(j->side[s].part)) j->side[s].part->port_used[j->side[s].port] = PETSC_TRUE;
  PetscCall(PhlexJointSelectRows(j));
  PetscFunctionReturn(0);
}

/* a side's port orientation Rp (inertial) and its body frame R_f at X (the ground: identity) */
static PetscErrorCode SidePlacement(PhlexJoint j, PetscInt s, const PhlexPartVec *X, PetscReal xp[3], PetscReal Rp[9], PetscReal Rf[9])
{
  PhlexJointSide *side = &j->side[s];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 9; k++) Rf[k] = Rp[k] = (k % 4 == 0) ? 1.0 : 0.0;
  for (PetscInt k = 0; k < 3; k++) xp[k] = 0.0;
  if (PhlexPartIsGround(side->part)) PetscFunctionReturn(0);
  PetscCall((*side->part->ops.portplacement)(side->part, side->port, X, xp, Rp));
  if (side->part->frame.R >= 0)
    for (PetscInt k = 0; k < 9; k++) Rf[k] = X->q[side->part->frame.R + k];
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointSetUp - the joint's geometry from the drawn configuration (the initial state): joint point offsets
  on both ports, the joint frame and the universal's second axis in the port frames, the reference relative
  orientation

  Collective

  Notes:
  The joint frame is attached to port a (offsets and the second axis to their ports): it turns with the body and,
  on a flexible body, with the port's mean rotation relative to the body frame.
@*/
PetscErrorCode PhlexJointSetUp(PhlexJoint j, const PhlexPartVec *Xa, const PhlexPartVec *Xb)
{
  const PhlexUnits   *u = j->units;
  const PhlexPartVec *X[2] = {Xa, Xb};
  PetscReal           xp[2][3], Rp[2][9], Rf[2][9], xJ[3];

  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) PetscCall(SidePlacement(j, s, X[s], xp[s], Rp[s], Rf[s]));
  /* the joint point: as given, else the first port's point (the other one if that is the ground) */
  if (j->position_given)
    for (PetscInt k = 0; k < 3; k++) xJ[k] = j->position[k] / u->length;
  else
    for (PetscInt k = 0; k < 3; k++) xJ[k] = PhlexPartIsGround(j->side[0].part) ? xp[1][k] : xp[0][k];
  for (PetscInt s = 0; s < 2; s++) {
    PhlexJointSide *side = &j->side[s];
    if (PhlexPartIsGround(side->part)) {
      for (PetscInt k = 0; k < 3; k++) side->offset[k] = xJ[k];
    } else if (j->position_given) {
      PetscReal d[3];
      for (PetscInt k = 0; k < 3; k++) d[k] = xJ[k] - xp[s][k];
      PhlexMatTVec3(Rp[s], d, side->offset);
    } else
      for (PetscInt k = 0; k < 3; k++) side->offset[k] = 0.0; /* the port points must meet: the assembly closes a gap */
  }
  /* the joint frame (rows e1, e2, e3) in a's port frame */
  {
    PetscReal F[9];
    if (j->axis_given) PhlexCompleteFrame(j->axis, j->reference_given ? j->reference : NULL, F);
    else if (j->reference_given) PhlexCompleteFrame((PetscReal[3]){0, 0, 1}, j->reference, F);
    else
      for (PetscInt k = 0; k < 9; k++) F[k] = (k % 4 == 0) ? 1.0 : 0.0;
    for (PetscInt r = 0; r < 3; r++) PhlexMatTVec3(Rp[0], F + 3 * r, j->frame + 3 * r);
    if (j->type == PHLEX_JOINT_UNIVERSAL) {
      PetscReal n = PhlexNorm3(j->axis2), a2[3];
      for (PetscInt k = 0; k < 3; k++) a2[k] = j->axis2[k] / n;
      PhlexMatTVec3(Rp[1], a2, j->axis_b);
    }
  }
  PhlexMatTMat3(Rp[0], Rp[1], j->Rrel0);
  PetscCall(PhlexJointUpdateGeometry(j, Xa, Xb));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointUpdateGeometry - the joint's directions and arms in the body frames at a state X: the port frame
  relative to the body frame, P = R_f^T Rp (identity but on a flexible port: its mean rotation), turns the joint
  frame, the universal's second axis and the offsets

  Collective

  Notes:
  Called at set-up and before every step, at the displacements extrapolated to the middle of the step
  (PhlexSystemUpdateJoints). Within a step P is held: the rows and the wrenches use the same directions, so the
  joint stays exactly workless, and the Jacobian has no term from P; the joint frame follows the port's elastic
  rotation up to a lag of second order in the step. A step retried with a smaller step size (adaptive steps,
  Newton failure) keeps the directions of the first try.
@*/
PetscErrorCode PhlexJointUpdateGeometry(PhlexJoint j, const PhlexPartVec *Xa, const PhlexPartVec *Xb)
{
  const PhlexPartVec *X[2] = {Xa, Xb};
  PetscReal           P[2][9];

  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexJointSide *side = &j->side[s];
    PetscReal       xp[3], Rp[9], Rf[9];
    PetscCall(SidePlacement(j, s, X[s], xp, Rp, Rf));
    PhlexMatTMat3(Rf, Rp, P[s]);
    if (PhlexPartIsGround(side->part))
      for (PetscInt k = 0; k < 3; k++) side->arm[k] = side->offset[k];
    else PhlexMatVec3(P[s], side->offset, side->arm);
  }
  for (PetscInt r = 0; r < 3; r++) PhlexMatVec3(P[0], j->frame + 3 * r, j->dir + 3 * r);
  PhlexMatVec3(P[1], j->axis_b, j->eb);
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Evaluation, residual                                                                                          */

/*@C
  PhlexJointEvaluate - the joint at the parts' evaluated state: port outputs at the joint point, rotations, and the
  multipliers lambda = Lambda' (non-dimensional) from the rates of the impulses (qd: SI time, NULL: zero)
@*/
PetscErrorCode PhlexJointEvaluate(PhlexJoint j, PetscReal t, const PetscReal *q, const PetscReal *qd)
{
  const PetscReal T = j->units->time;
  PetscReal       y[6];

  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexJointSide *side = &j->side[s];
    PetscReal      *yt   = s ? j->yb : j->ya;
    for (PetscInt k = 0; k < 6; k++) yt[k] = 0.0;
    if (PhlexPartIsGround(side->part)) continue;
    PetscCall((*side->part->ops.portoutput)(side->part, side->port, y));
    MoveToJoint(side->arm, y, yt);
  }
  SideRotation(j, 0, q, j->Ra);
  SideRotation(j, 1, q, j->Rb);
  PhlexMatTMat3(j->Ra, j->Rb, j->Rab);
  PhlexMatTMat3(j->Ra, j->Ra, j->G);
  for (PetscInt k = 0; k < j->nc; k++) j->lambda[k] = qd ? T * qd[j->qoff + k] : 0.0;
  PetscFunctionReturn(0);
}

/* the joint's wrench on b at the joint point, a's body frame: w_J = sum_k lambda_k s_k */
static void JointWrench(PhlexJoint j, const PetscReal *lambda, const PetscReal *dRab, PetscReal w[6])
{
  for (PetscInt c = 0; c < 6; c++) w[c] = 0.0;
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscReal s[6];
    RowDirection(j, k, j->Rab, dRab, s);
    for (PetscInt c = 0; c < 6; c++) w[c] += lambda[k] * s[c];
  }
}

/* the port wrenches of a joint wrench w_J (and of its change dw_J with dRab, dG): a gets -G w_J, b gets R_ab^T w_J */
static void PortWrenches(PhlexJoint j, const PetscReal wJ[6], const PetscReal *dwJ, const PetscReal *dRab, const PetscReal *dG, PetscReal wa[6], PetscReal wb[6])
{
  PetscReal na[6], wbJ[6], t[6];

  if (dRab) {
    /* d(G w_J) = dG w_J + G dw_J, d(R_ab^T w_J) = dR_ab^T w_J + R_ab^T dw_J */
    Rotate6(dG, PETSC_FALSE, wJ, na);
    Rotate6(j->G, PETSC_FALSE, dwJ, t);
    for (PetscInt c = 0; c < 6; c++) na[c] = -(na[c] + t[c]);
    Rotate6(dRab, PETSC_TRUE, wJ, wbJ);
    Rotate6(j->Rab, PETSC_TRUE, dwJ, t);
    for (PetscInt c = 0; c < 6; c++) wbJ[c] += t[c];
  } else {
    Rotate6(j->G, PETSC_FALSE, wJ, na);
    for (PetscInt c = 0; c < 6; c++) na[c] = -na[c];
    Rotate6(j->Rab, PETSC_TRUE, wJ, wbJ);
  }
  MoveToPort(j->side[0].arm, na, wa);
  MoveToPort(j->side[1].arm, wbJ, wb);
}

/* the change of both port wrenches for a unit change of the entry m of side t's R (R_ab and G turn with it, and
   so does the universal's cross direction); also returns dR_ab and dG */
static void WrenchesRDerivative(PhlexJoint j, PetscInt t, PetscInt m, const PetscReal wJ[6], PetscReal dRab[9], PetscReal dG[9], PetscReal w[2][6])
{
  PetscReal dwJ[6] = {0, 0, 0, 0, 0, 0};

  RabDerivative(t, m, j->Ra, j->Rb, dRab, dG);
  for (PetscInt k = 0; k < j->nc; k++)
    if (j->row[k] == PHLEX_ROW_CROSS) {
      PetscReal dsk[6];
      RowDirection(j, k, j->Rab, dRab, dsk);
      for (PetscInt c = 0; c < 6; c++) dwJ[c] += j->lambda[k] * dsk[c];
    }
  PortWrenches(j, wJ, dwJ, dRab, dG, w[0], w[1]);
}

/*@C
  PhlexJointApplyWrenches - adds the joint's wrenches to its two ports (part->wrench)
@*/
PetscErrorCode PhlexJointApplyWrenches(PhlexJoint j)
{
  PetscReal wJ[6], w[2][6];

  PetscFunctionBeginUser;
  JointWrench(j, j->lambda, NULL, wJ);
  PortWrenches(j, wJ, NULL, NULL, NULL, w[0], w[1]);
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    if (PhlexPartIsGround(p)) continue;
    for (PetscInt c = 0; c < 6; c++) p->wrench[j->side[s].port][c] += w[s][c];
  }
  PetscFunctionReturn(0);
}

/* Delta = R_a^T (R_b y~_b - R_a y~_a) = R_ab y~_b - G y~_a, the relative velocity (a's body frame). The metric
   G = R_a^T R_a is the identity for an orthogonal R_a, but not at the midpoint of a step (the mean of two
   rotations): written this way, a joint that holds the whole translation keeps the inertial velocities of its
   points equal, so the midpoint rule moves them alike and the joint does not drift. */
static void Relative(PhlexJoint j, PetscReal D[6])
{
  PetscReal r[6], a[6];

  Rotate6(j->Rab, PETSC_FALSE, j->yb, r);
  Rotate6(j->G, PETSC_FALSE, j->ya, a);
  for (PetscInt c = 0; c < 6; c++) D[c] = r[c] - a[c];
}

/* g_k(t): the prescribed relative velocity of row k (non-dimensional) */
static PetscErrorCode Source(PhlexJoint j, PetscInt k, PetscReal t, PetscReal *g)
{
  const PhlexUnits *u = j->units;
  PetscReal         f;

  PetscFunctionBeginUser;
  *g = 0.0;
  if (j->type == PHLEX_JOINT_PRESCRIBED) {
    PetscCall(PhlexProfileEvaluate(j->drive_profile, t, &f));
    if (j->row[k] <= PHLEX_ROW_T3) *g = f * j->presc_velocity[j->row[k] - PHLEX_ROW_T1] / u->velocity;
    else *g = f * j->presc_angular[j->row[k] - PHLEX_ROW_R1] * u->time;
  } else if (j->drive_row >= 0 && k == j->nc - 1) {
    PetscCall(PhlexProfileEvaluate(j->drive_profile, t, &f));
    *g = f * j->drive_velocity * (j->row[k] == PHLEX_ROW_R3 ? u->time : 1.0 / u->velocity);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointResidual - the joint's rows c_k = s_k . Delta - g_k(t) in the discrete residual (f: replicated array)
@*/
PetscErrorCode PhlexJointResidual(PhlexJoint j, PetscReal t, PetscReal *f)
{
  PetscReal D[6];

  PetscFunctionBeginUser;
  Relative(j, D);
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscReal s[6], g;
    RowDirection(j, k, j->Rab, NULL, s);
    PetscCall(Source(j, k, t, &g));
    j->c[k]           = Dot6(s, D);
    f[j->qoff + k]    = j->c[k] - g;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointPower - the power through the joint, lambda . (c + g) = sum of w . y over its two ports (zero for a
  workless joint, the drive's power otherwise), with the given multipliers (non-dimensional)
@*/
PetscErrorCode PhlexJointPower(PhlexJoint j, const PetscReal *lambda, PetscReal *P)
{
  PetscReal D[6];

  PetscFunctionBeginUser;
  Relative(j, D);
  *P = 0.0;
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscReal s[6];
    RowDirection(j, k, j->Rab, NULL, s);
    *P += lambda[k] * Dot6(s, D);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointDissipation - the power the joint dissipates at the evaluated state (>= 0), with the given multipliers:
  zero for the constraint rows, which are workless (a drive's power is supplied, PhlexJointPower)
@*/
PetscErrorCode PhlexJointDissipation(PhlexJoint j, const PetscReal *lambda, PetscReal *D)
{
  PetscFunctionBeginUser;
  (void)lambda;
  *D = 0.0;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointSourcePower - the power the joint supplies, lambda . g(t): its drive's or prescribed motion's (zero for a
  workless joint), given that the scheme holds c = g at its stage (for the schemes whose stage state the monitor does
  not see)
@*/
PetscErrorCode PhlexJointSourcePower(PhlexJoint j, PetscReal t, const PetscReal *lambda, PetscReal *P)
{
  PetscFunctionBeginUser;
  *P = 0.0;
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscReal g;
    PetscCall(Source(j, k, t, &g));
    *P += lambda[k] * g;
  }
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Jacobian                                                                                                      */

/* the row-k gradient of the joint's constraint with respect to the discrete unknown dq of side s (via the port) */
static PetscErrorCode RowsFromPortChange(PhlexJoint j, PetscInt s, const PetscReal dy[6], PetscReal *rows)
{
  PetscReal dyt[6], r[6];

  PetscFunctionBeginUser;
  MoveToJoint(j->side[s].arm, dy, dyt);
  if (s == 1) Rotate6(j->Rab, PETSC_FALSE, dyt, r);
  else {
    Rotate6(j->G, PETSC_FALSE, dyt, r);
    for (PetscInt c = 0; c < 6; c++) r[c] = -r[c];
  }
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscReal sk[6];
    RowDirection(j, k, j->Rab, NULL, sk);
    rows[k] = Dot6(sk, r);
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointJacobian - the joint's entries of the dense discrete Jacobian: its rows with respect to the discrete
  unknowns of its parts (through their ports, and through R_ab), and the parts' frame rows with respect to its
  impulses (shift-scaled) and to R_a, R_b (the joint wrench turns with R_ab)

  Not collective (the parts' port maps of discrete unknowns need no communication)
@*/
PetscErrorCode PhlexJointJacobian(PhlexJoint j, PetscReal shift, PetscReal *D, PetscInt ld)
{
  PetscReal wJ[6], Dl[6], *work;
  PetscInt  nw = 1;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_JointJacobian, 0, 0, 0, 0));
  /* one work array for the unit changes and generalized forces of both sides (allocated once, not per column) */
  for (PetscInt s = 0; s < 2; s++) nw = PetscMax(nw, j->side[s].part->nq);
  PetscCall(PetscCalloc1(nw, &work));
  JointWrench(j, j->lambda, NULL, wJ);
  Relative(j, Dl);
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    if (PhlexPartIsGround(p)) continue;
    /* rows x the part's discrete unknowns, through its port */
    for (PetscInt m = 0; m < p->nq; m++) {
      PetscReal dy[6], rows[7];
      work[m] = 1.0;
      PetscCall((*p->ops.portlinear)(p, j->side[s].port, NULL, 0.0, NULL, work, dy));
      work[m] = 0.0;
      PetscCall(RowsFromPortChange(j, s, dy, rows));
      for (PetscInt k = 0; k < j->nc; k++) D[ld * (j->qoff + k) + p->qoff + m] += rows[k];
    }
    /* the part's rows x the impulses: -shift (generalized force of d w / d lambda_k) */
    for (PetscInt k = 0; k < j->nc; k++) {
      PetscReal e[7] = {0, 0, 0, 0, 0, 0, 0}, wk[6], w[2][6];
      e[k] = 1.0;
      JointWrench(j, e, NULL, wk);
      PortWrenches(j, wk, NULL, NULL, NULL, w[0], w[1]);
      PetscCall(PetscArrayzero(work, p->nq));
      PetscCall((*p->ops.portforce)(p, j->side[s].port, w[s], NULL, work));
      for (PetscInt m = 0; m < p->nq; m++) D[ld * (p->qoff + m) + j->qoff + k] -= shift * work[m];
      PetscCall(PetscArrayzero(work, p->nq));
    }
  }
  /* R_ab = R_a^T R_b: the rows (R_ab y_b, and the universal's cross direction) and the wrenches turn with it */
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    if (PhlexPartIsGround(p) || p->frame.R < 0) continue;
    for (PetscInt m = 0; m < 9; m++) {
      const PetscInt col = QIndex(p, p->frame.R + m);
      PetscReal      dRab[9], dG[9], r[6], ra[6], w[2][6];
      WrenchesRDerivative(j, s, m, wJ, dRab, dG, w);
      Rotate6(dRab, PETSC_FALSE, j->yb, r);
      Rotate6(dG, PETSC_FALSE, j->ya, ra);
      for (PetscInt c = 0; c < 6; c++) r[c] -= ra[c];
      for (PetscInt k = 0; k < j->nc; k++) {
        PetscReal sk[6], dsk[6];
        RowDirection(j, k, j->Rab, NULL, sk);
        RowDirection(j, k, j->Rab, dRab, dsk);
        D[ld * (j->qoff + k) + col] += Dot6(sk, r) + (j->row[k] == PHLEX_ROW_CROSS ? Dot6(dsk, Dl) : 0.0);
      }
      for (PetscInt t = 0; t < 2; t++) {
        PhlexPart pt = j->side[t].part;
        if (PhlexPartIsGround(pt)) continue;
        PetscCall((*pt->ops.portforce)(pt, j->side[t].port, w[t], NULL, work));
        for (PetscInt i = 0; i < pt->nq; i++) D[ld * (pt->qoff + i) + col] -= work[i];
        PetscCall(PetscArrayzero(work, pt->nq));
      }
    }
  }
  PetscCall(PetscFree(work));
  PetscCall(PetscLogEventEnd(PHLEX_JointJacobian, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* the change of the wrench on side s's port for a change x of the discrete unknowns: x_Lambda (times shift) and
   x_R of both sides */
static PetscErrorCode WrenchChange(PhlexJoint j, PetscInt s, PetscReal shift, const PetscReal *x, PetscReal dw[6])
{
  PetscReal dl[7], wk[6], w[2][6], wJ[6];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < j->nc; k++) dl[k] = shift * x[j->qoff + k];
  JointWrench(j, dl, NULL, wk);
  PortWrenches(j, wk, NULL, NULL, NULL, w[0], w[1]);
  for (PetscInt c = 0; c < 6; c++) dw[c] = w[s][c];
  JointWrench(j, j->lambda, NULL, wJ);
  for (PetscInt t = 0; t < 2; t++) {
    PhlexPart p = j->side[t].part;
    if (PhlexPartIsGround(p) || p->frame.R < 0) continue;
    for (PetscInt m = 0; m < 9; m++) {
      const PetscReal xm = x[QIndex(p, p->frame.R + m)];
      PetscReal       dRab[9], dG[9];
      if (xm == 0.0) continue;
      WrenchesRDerivative(j, t, m, wJ, dRab, dG, w);
      for (PetscInt c = 0; c < 6; c++) dw[c] += xm * w[s][c];
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointBorderMult - y_v += (field rows of part) x (joint's columns) x: the field force of the wrench change

  Collective on the part
@*/
PetscErrorCode PhlexJointBorderMult(PhlexJoint j, PetscReal shift, const PetscReal *x, PhlexPart part, Vec yv)
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PetscReal dw[6];
    if (j->side[s].part != part) continue;
    PetscCall(WrenchChange(j, s, shift, x, dw));
    for (PetscInt c = 0; c < 6; c++) dw[c] = -dw[c];
    PetscCall((*part->ops.portforce)(part, j->side[s].port, dw, yv, NULL));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointBorderMultTransposeLocal - the joint's rows applied to field vectors of part (a xu, xv), first phase:
  this process's parts of the field products of the part's ports on the joint's sides (PHLEX_JOINT_BORDER_SUMS
  values in loc, set), which the caller sums over the processes and hands to PhlexJointBorderMultTransposeSummed()

  Not collective
@*/
PetscErrorCode PhlexJointBorderMultTransposeLocal(PhlexJoint j, PhlexPart part, Vec xu, PetscReal au, Vec xv, PetscReal *loc)
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PetscReal *ls = loc + s * PHLEX_PORT_SUMS;
    if (j->side[s].part != part) {
      for (PetscInt k = 0; k < PHLEX_PORT_SUMS; k++) ls[k] = 0.0;
      continue;
    }
    PetscCall((*part->fieldops->portlinearlocal)(part, j->side[s].port, xu, au, xv, ls));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointBorderMultTransposeSummed - the second phase: y_q += (joint rows) x (field columns of part) (a xu, xv),
  from the summed products of the first phase (the same xu, au, xv; the vectors are not read)

  Not collective
@*/
PetscErrorCode PhlexJointBorderMultTransposeSummed(PhlexJoint j, PhlexPart part, Vec xu, PetscReal au, Vec xv, const PetscReal *sums, PetscReal *y)
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PetscReal dy[6], rows[7];
    if (j->side[s].part != part) continue;
    PetscCall((*part->fieldops->portlinearsummed)(part, j->side[s].port, xu, au, xv, sums + s * PHLEX_PORT_SUMS, NULL, dy));
    PetscCall(RowsFromPortChange(j, s, dy, rows));
    for (PetscInt k = 0; k < j->nc; k++) y[j->qoff + k] += rows[k];
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointBorderRows - out += the joint's rows applied to the columns of Y (field of part, the displacement
  eliminated as Y/shift): m x k column-major

  Collective on the part
@*/
PetscErrorCode PhlexJointBorderRows(PhlexJoint j, PhlexPart part, Mat Y, PetscReal shiftinv, PetscReal *out, PetscInt ld)
{
  PetscInt k;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(Y, NULL, &k));
  for (PetscInt s = 0; s < 2; s++) {
    PetscReal *dy;
    if (j->side[s].part != part) continue;
    PetscCall(PetscMalloc1(6 * k, &dy));
    PetscCall((*part->fieldops->portlinearblock)(part, j->side[s].port, Y, shiftinv, dy));
    for (PetscInt col = 0; col < k; col++) {
      PetscReal rows[7];
      PetscCall(RowsFromPortChange(j, s, dy + 6 * col, rows));
      for (PetscInt r = 0; r < j->nc; r++) out[j->qoff + r + ld * col] += rows[r];
    }
    PetscCall(PetscFree(dy));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointBorderCoefficients - beta += the coefficients on the part's border basis W of the joint's columns (the
  field force of the joint wrench lies in the span of the port's distribution: exact)
@*/
PetscErrorCode PhlexJointBorderCoefficients(PhlexJoint j, PhlexPart part, PetscReal shift, PetscReal *beta, PetscInt ld)
{
  PetscReal wJ[6];

  PetscFunctionBeginUser;
  JointWrench(j, j->lambda, NULL, wJ);
  for (PetscInt s = 0; s < 2; s++) {
    PetscInt c0;
    if (j->side[s].part != part) continue;
    PetscCall((*part->fieldops->portbasiscolumn)(part, j->side[s].port, &c0));
    if (c0 < 0) continue; /* no field force on this port (a frame patch) */
    for (PetscInt k = 0; k < j->nc; k++) {
      PetscReal e[7] = {0, 0, 0, 0, 0, 0, 0}, wk[6], w[2][6];
      e[k] = 1.0;
      JointWrench(j, e, NULL, wk);
      PortWrenches(j, wk, NULL, NULL, NULL, w[0], w[1]);
      for (PetscInt c = 0; c < 6; c++) beta[c0 + c + ld * (j->qoff + k)] -= shift * w[s][c];
    }
    for (PetscInt t = 0; t < 2; t++) {
      PhlexPart p = j->side[t].part;
      if (PhlexPartIsGround(p) || p->frame.R < 0) continue;
      for (PetscInt m = 0; m < 9; m++) {
        PetscReal dRab[9], dG[9], w[2][6];
        WrenchesRDerivative(j, t, m, wJ, dRab, dG, w);
        for (PetscInt c = 0; c < 6; c++) beta[c0 + c + ld * QIndex(p, p->frame.R + m)] -= w[s][c];
      }
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointRigidGradient - the joint's rows with respect to the velocity unknowns of its parts' frames (a row-major
  nc x nq block, ld): the position-level constraint Jacobian of the assembly and of the redundancy check
@*/
PetscErrorCode PhlexJointRigidGradient(PhlexJoint j, PetscReal *G, PetscInt ld)
{
  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexPart p = j->side[s].part;
    if (PhlexPartIsGround(p)) continue;
    for (PetscInt m = 0; m < p->nq; m++) {
      PetscReal *dq, dy[6], rows[7];
      if (p->qkind[m] != PHLEX_DOF_VELOCITY) continue;
      PetscCall(PetscCalloc1(p->nq, &dq));
      dq[m] = 1.0;
      PetscCall((*p->ops.portlinear)(p, j->side[s].port, NULL, 0.0, NULL, dq, dy));
      PetscCall(PetscFree(dq));
      PetscCall(RowsFromPortChange(j, s, dy, rows));
      for (PetscInt k = 0; k < j->nc; k++) G[ld * k + p->qoff + m] += rows[k];
    }
  }
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Position level: violation, relative motion, drive positions                                                   */

/*@C
  PhlexJointDrivePosition - the prescribed position of the driven row at t: the initial angle [rad] or slide plus
  the integral of the drive velocity (non-dimensional: slides in units of length)
@*/
PetscErrorCode PhlexJointDrivePosition(PhlexJoint j, PetscReal t, PetscReal *x)
{
  const PhlexUnits *u = j->units;
  PetscReal         F;

  PetscFunctionBeginUser;
  *x = 0.0;
  if (j->drive_row < 0) PetscFunctionReturn(0);
  PetscCall(PhlexProfileIntegrate(j->drive_profile, t, &F));
  if (j->drive_row == PHLEX_ROW_R3) *x = j->drive_initial + j->drive_velocity * F;
  else *x = (j->drive_initial + j->drive_velocity * F) / u->length;
  PetscFunctionReturn(0);
}

/* the joint points from the placements of both ports (inertial): Delta x = Rp_a^T (x_b - x_a) and the rotation E of
   b's port relative to a's since the drawn configuration, both in a's port frame (where the joint frame lives) */
static PetscErrorCode Placements(PhlexJoint j, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal dx[3], PetscReal E[9])
{
  const PhlexPartVec *X[2] = {Xa, Xb};
  PetscReal           x[2][3], Rp[2][9], Rrel[9];

  PetscFunctionBeginUser;
  for (PetscInt s = 0; s < 2; s++) {
    PhlexJointSide *side = &j->side[s];
    PetscReal       d[3];
    if (PhlexPartIsGround(side->part)) {
      for (PetscInt k = 0; k < 3; k++) x[s][k] = side->offset[k];
      for (PetscInt k = 0; k < 9; k++) Rp[s][k] = (k % 4 == 0) ? 1.0 : 0.0;
    } else {
      PetscCall((*side->part->ops.portplacement)(side->part, side->port, X[s], x[s], Rp[s]));
      PhlexMatVec3(Rp[s], side->offset, d);
      for (PetscInt k = 0; k < 3; k++) x[s][k] += d[k];
    }
  }
  {
    PetscReal d[3];
    for (PetscInt k = 0; k < 3; k++) d[k] = x[1][k] - x[0][k];
    PhlexMatTVec3(Rp[0], d, dx);
  }
  PhlexMatTMat3(Rp[0], Rp[1], Rrel);
  PhlexMatMatT3(Rrel, j->Rrel0, E);
  PetscFunctionReturn(0);
}

/* the relative angle about e3 (a's joint frame) of the rotation E */
static PetscReal AngleAboutAxis(PhlexJoint j, const PetscReal E[9])
{
  PetscReal Ee1[3];

  PhlexMatVec3(E, j->frame, Ee1);
  return PetscAtan2Real(PhlexDot3(j->frame + 3, Ee1), PhlexDot3(j->frame, Ee1));
}

/*@C
  PhlexJointGap - the position-level violation of each row at the state of its parts (non-dimensional: lengths and
  radians), consistent with the velocity rows (d gap/dt = c at a satisfied configuration)

  Collective
@*/
PetscErrorCode PhlexJointGap(PhlexJoint j, PetscReal t, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal gap[7])
{
  PetscReal dx[3], E[9], phi[3], Ee3[3], perp[3];

  PetscFunctionBeginUser;
  PetscCall(Placements(j, Xa, Xb, dx, E));
  PhlexRotationVector(E, phi);
  PhlexMatVec3(E, j->frame + 6, Ee3);
  PhlexCross(j->frame + 6, Ee3, perp); /* the misalignment of the axis: e3 x (E e3) */
  if (j->type == PHLEX_JOINT_PRESCRIBED) {
    /* the port point and orientation against their prescribed paths x0 + v F(t), rotation vector w F(t) */
    const PhlexUnits *u = j->units;
    PetscReal         F;
    PetscCall(PhlexProfileIntegrate(j->drive_profile, t, &F));
    for (PetscInt k = 0; k < 3; k++) {
      dx[k] -= j->presc_velocity[k] * F / u->length;
      phi[k] -= j->presc_angular[k] * F;
    }
  }
  for (PetscInt k = 0; k < j->nc; k++) {
    const PhlexJointRow r     = j->row[k];
    const PetscBool     free3 = (j->type == PHLEX_JOINT_REVOLUTE || j->type == PHLEX_JOINT_CYLINDRICAL || j->type == PHLEX_JOINT_PLANAR) ? PETSC_TRUE : PETSC_FALSE;
    if (r <= PHLEX_ROW_T3) gap[k] = PhlexDot3(j->frame + 3 * (r - PHLEX_ROW_T1), dx);
    else if (r == PHLEX_ROW_CROSS) {
      PetscReal eb0[3], Eeb[3];
      PhlexMatVec3(j->Rrel0, j->axis_b, eb0);
      PhlexMatVec3(E, eb0, Eeb);
      gap[k] = -PhlexDot3(j->frame + 6, Eeb);
    } else if (r == PHLEX_ROW_R3 && free3) gap[k] = AngleAboutAxis(j, E); /* the driven angle (compared below) */
    else if (free3) gap[k] = PhlexDot3(j->frame + 3 * (r - PHLEX_ROW_R1), perp);
    else gap[k] = PhlexDot3(j->frame + 3 * (r - PHLEX_ROW_R1), phi);
    if (j->drive_row >= 0 && k == j->nc - 1) {
      PetscReal xd;
      PetscCall(PhlexJointDrivePosition(j, t, &xd));
      gap[k] -= xd;
      if (r == PHLEX_ROW_R3) gap[k] = PetscAtan2Real(PetscSinReal(gap[k]), PetscCosReal(gap[k])); /* wrapped */
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointRelativeMotion - the free relative motion of a joint for the output: angle [rad] about the axis
  (revolute, cylindrical, planar), slide along it (prismatic, cylindrical), in-plane displacement (planar), the
  rotation vector (spherical, universal)
@*/
PetscErrorCode PhlexJointRelativeMotion(PhlexJoint j, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal m[6], PetscInt *n)
{
  PetscReal dx[3], E[9];

  PetscFunctionBeginUser;
  PetscCall(Placements(j, Xa, Xb, dx, E));
  *n = 0;
  switch (j->type) {
  case PHLEX_JOINT_REVOLUTE:
    m[(*n)++] = AngleAboutAxis(j, E);
    break;
  case PHLEX_JOINT_PRISMATIC:
    m[(*n)++] = PhlexDot3(j->frame + 6, dx);
    break;
  case PHLEX_JOINT_CYLINDRICAL:
    m[(*n)++] = AngleAboutAxis(j, E);
    m[(*n)++] = PhlexDot3(j->frame + 6, dx);
    break;
  case PHLEX_JOINT_PLANAR:
    m[(*n)++] = PhlexDot3(j->frame, dx);
    m[(*n)++] = PhlexDot3(j->frame + 3, dx);
    m[(*n)++] = AngleAboutAxis(j, E);
    break;
  case PHLEX_JOINT_SPHERICAL:
  case PHLEX_JOINT_UNIVERSAL: {
    PetscReal phi[3];
    PhlexRotationVector(E, phi);
    for (PetscInt k = 0; k < 3; k++) m[(*n)++] = PhlexDot3(j->frame + 3 * k, phi);
  } break;
  default:
    break;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointDropRow - removes row k (a redundant constraint component)
@*/
PetscErrorCode PhlexJointDropRow(PhlexJoint j, PetscInt k)
{
  PetscFunctionBeginUser;
  PetscCall(PetscStrcpy(j->dropped[j->ndropped++], j->rowname[k]));
  for (PetscInt r = k; r < j->nc - 1; r++) {
    j->row[r] = j->row[r + 1];
    PetscCall(PetscStrcpy(j->rowname[r], j->rowname[r + 1]));
  }
  j->nc--;
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Output                                                                                                        */

/*@C
  PhlexJointView - one line per joint: kind, ports, rows, drive
@*/
PetscErrorCode PhlexJointView(PhlexJoint j, PetscViewer viewer)
{
  char rows[128] = "";

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < j->nc; k++) {
    PetscCall(PetscStrlcat(rows, k ? " " : "", sizeof(rows)));
    PetscCall(PetscStrlcat(rows, j->rowname[k], sizeof(rows)));
  }
  PetscCall(PetscViewerASCIIPrintf(viewer, "joint %s: %s between %s and %s, constrains %s", j->name, PhlexJointTypes[j->type], j->side[0].spec, j->side[1].spec, rows));
  if (j->drive_row >= 0) PetscCall(PetscViewerASCIIPrintf(viewer, " (%s driven at %.15g %s)", j->rowname[j->nc - 1], (double)j->drive_velocity, j->row[j->nc - 1] == PHLEX_ROW_R3 ? "rad/s" : "m/s"));
  if (j->rot_dropped) PetscCall(PetscViewerASCIIPrintf(viewer, "; rotations free (a point mass has no orientation)"));
  if (j->ndropped) {
    PetscCall(PetscViewerASCIIPrintf(viewer, "; redundant, dropped:"));
    for (PetscInt k = 0; k < j->ndropped; k++) PetscCall(PetscViewerASCIIPrintf(viewer, " %s", j->dropped[k]));
  }
  PetscCall(PetscViewerASCIIPrintf(viewer, "\n"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointOutputOpen - opens <name>_joint.csv: time, the joint wrench on the second port at the joint point in
  the joint frame (force, moment), the relative motion, the position-level violation of each row, the power
@*/
PetscErrorCode PhlexJointOutputOpen(PhlexJoint j, PhlexOutput out)
{
  char      name[PHLEX_NAME_LEN + 16], header[2048] = "time,Fx,Fy,Fz,Mx,My,Mz";
  PetscReal m[6];

  PetscFunctionBeginUser;
  switch (j->type) {
  case PHLEX_JOINT_REVOLUTE:
    PetscCall(PetscStrlcat(header, ",angle", sizeof(header)));
    break;
  case PHLEX_JOINT_PRISMATIC:
    PetscCall(PetscStrlcat(header, ",slide", sizeof(header)));
    break;
  case PHLEX_JOINT_CYLINDRICAL:
    PetscCall(PetscStrlcat(header, ",angle,slide", sizeof(header)));
    break;
  case PHLEX_JOINT_PLANAR:
    PetscCall(PetscStrlcat(header, ",slide1,slide2,angle", sizeof(header)));
    break;
  case PHLEX_JOINT_SPHERICAL:
  case PHLEX_JOINT_UNIVERSAL:
    PetscCall(PetscStrlcat(header, ",rot1,rot2,rot3", sizeof(header)));
    break;
  default:
    break;
  }
  (void)m;
  for (PetscInt k = 0; k < j->nc; k++) {
    char col[32];
    PetscCall(PetscSNPrintf(col, sizeof(col), ",gap_%s", j->rowname[k]));
    PetscCall(PetscStrlcat(header, col, sizeof(header)));
  }
  PetscCall(PetscStrlcat(header, ",power", sizeof(header)));
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_joint.csv", j->name));
  PetscCall(PhlexOutputCSVOpen(out, name, header, &j->csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointOutputStep - one row of the joint's series (SI): the multipliers lambda of the step and the power P
  through the joint over the step (non-dimensional, from the monitor: at the state where the scheme enforces the
  constraints), the relative motion and the violations at the state X; returns the largest violation (SI: m or rad)

  Collective
@*/
PetscErrorCode PhlexJointOutputStep(PhlexJoint j, PetscReal t, const PetscReal *lambda, PetscReal P, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal *gapmax)
{
  const PhlexUnits *u = j->units;
  PetscReal         wJ[6], mo[6], gap[7];
  PetscInt          nm;

  PetscFunctionBeginUser;
  JointWrench(j, lambda, NULL, wJ);
  PetscCall(PhlexJointRelativeMotion(j, Xa, Xb, mo, &nm));
  PetscCall(PhlexJointGap(j, t, Xa, Xb, gap));
  *gapmax = 0.0;
  for (PetscInt k = 0; k < j->nc; k++) *gapmax = PetscMax(*gapmax, PetscAbsReal(gap[k]) * (j->row[k] <= PHLEX_ROW_T3 ? u->length : 1.0));
  if (!j->csv) PetscFunctionReturn(0);
  PetscCall(PhlexCSVPrintf(j->csv, "%.12e", (double)t));
  for (PetscInt r = 0; r < 3; r++) PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)(PhlexDot3(j->dir + 3 * r, wJ) * u->force)));
  for (PetscInt r = 0; r < 3; r++) PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)(PhlexDot3(j->dir + 3 * r, wJ + 3) * u->force * u->length)));
  for (PetscInt k = 0; k < nm; k++) {
    const PetscBool length = (j->type == PHLEX_JOINT_PRISMATIC || (j->type == PHLEX_JOINT_CYLINDRICAL && k == 1) || (j->type == PHLEX_JOINT_PLANAR && k < 2)) ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)(length ? mo[k] * u->length : mo[k])));
  }
  for (PetscInt k = 0; k < j->nc; k++) {
    const PetscBool length = j->row[k] <= PHLEX_ROW_T3 ? PETSC_TRUE : PETSC_FALSE;
    PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)(length ? gap[k] * u->length : gap[k])));
  }
  PetscCall(PhlexCSVPrintf(j->csv, ",%.12e\n", (double)(P * u->power)));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexJointOutputClose(PhlexJoint j)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(&j->csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointDestroy - destroys a joint
@*/
PetscErrorCode PhlexJointDestroy(PhlexJoint *joint)
{
  PetscFunctionBeginUser;
  if (!*joint) PetscFunctionReturn(0);
  PetscCall(PhlexProfileDestroy(&(*joint)->drive_profile));
  PetscCall(PetscViewerDestroy(&(*joint)->csv));
  PetscCall(PetscFree(*joint));
  PetscFunctionReturn(0);
}
