/* The joint kinds: which generalized directions of the relative motion each constrains (rows of the joint, in a's
   joint frame e1, e2, e3 = axis). A drive adds the free direction it prescribes. Rotation rows need an orientation
   on both ports: with a point mass on either side they are left out (a point transmits no moment). */
#include <phlex_impl.h>

static const char *const RowNames[] = {"t1", "t2", "t3", "r1", "r2", "r3", "cross", "rb"};

/* The force elements' rows (after the constraint rows) and their non-dimensional stiffness and damping. Row i of K
   is a force (translation row, unit units->force) or a moment (rotation row, force x length); column l multiplies a
   length (translation state, units->length) or an angle. So K*_il = K_il c_i c_l / (F L) with c = L for a translation
   row and 1 for a rotation row (a congruence: K* stays symmetric positive semi-definite), and C*_il likewise with
   the rates' scales (L/T, 1/T): C*_il = C_il c_i c_l / (F L T). */
static PetscErrorCode SelectElementRows(PhlexJoint j)
{
  const PhlexUnits *u = j->units;
  PetscInt          idx[6];
  PetscReal         kd[6], cd[6]; /* the springs and dampers of uncoupled rows (SI) */

  PetscFunctionBeginUser;
  j->ne = 0;
  if (j->type == PHLEX_JOINT_SPRING_DAMPER) {
    j->erow[0] = PHLEX_ROW_T3, idx[0] = 0;
    j->ne      = 1;
  } else if (j->type == PHLEX_JOINT_BUSHING) {
    const PetscBool rot = (j->side[0].rotation && j->side[1].rotation) ? PETSC_TRUE : PETSC_FALSE;
    for (PetscInt k = PHLEX_ROW_T1; k <= (rot ? PHLEX_ROW_R3 : PHLEX_ROW_T3); k++) j->erow[j->ne] = (PhlexJointRow)k, idx[j->ne] = k, j->ne++;
    if (!rot) j->rot_dropped = PETSC_TRUE;
  } else if (j->rot_element) {
    PetscCheck(j->side[0].rotation && j->side[1].rotation, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a rotational spring-damper (-%srotational_stiffness, -%srotational_damping) needs ports with an orientation; %s is a point", j->name, j->prefix, j->prefix, j->side[j->side[0].rotation ? 1 : 0].spec);
    j->erow[0] = PHLEX_ROW_R3, idx[0] = 5;
    j->ne      = 1;
    /* a universal's second free rotation, about b's axis: the same spring and damper (uncoupled) */
    if (j->type == PHLEX_JOINT_UNIVERSAL) j->erow[1] = PHLEX_ROW_AXIS_B, idx[1] = 5, j->ne = 2;
  }
  for (PetscInt i = 0; i < j->ne; i++) kd[i] = j->stiffness, cd[i] = j->damping;
  if (j->slide_element) {
    /* the slide along e3 (prismatic, cylindrical): its own spring and damper */
    j->erow[j->ne] = PHLEX_ROW_T3, idx[j->ne] = 2;
    kd[j->ne] = j->slide_stiffness, cd[j->ne] = j->slide_damping;
    j->ne++;
  }
  for (PetscInt i = 0; i < j->ntable; i++) {
    j->table_e[i] /= u->length;
    j->table_f[i] /= u->force;
  }
  for (PetscInt i = 0; i < j->ne; i++) {
    const PetscReal ci = j->erow[i] <= PHLEX_ROW_T3 ? u->length : 1.0;
    PetscCall(PetscStrcpy(j->erowname[i], RowNames[j->erow[i]]));
    for (PetscInt l = 0; l < j->ne; l++) {
      const PetscReal cl = j->erow[l] <= PHLEX_ROW_T3 ? u->length : 1.0;
      PetscReal       k, c;
      if (j->type == PHLEX_JOINT_BUSHING) k = j->Ksi[6 * idx[i] + idx[l]], c = j->Csi[6 * idx[i] + idx[l]];
      else k = i == l ? kd[i] : 0.0, c = i == l ? cd[i] : 0.0;
      j->K[j->ne * i + l] = k * ci * cl / (u->force * u->length);
      j->C[j->ne * i + l] = c * ci * cl / (u->force * u->length * u->time);
    }
  }
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode PhlexJointSelectRows(PhlexJoint j)
{
  PhlexJointRow rows[7];
  PetscInt      n = 0;

  PetscFunctionBeginUser;
  switch (j->type) {
  case PHLEX_JOINT_FIXED: /* a weld: nothing moves */
    for (PetscInt k = PHLEX_ROW_T1; k <= PHLEX_ROW_R3; k++) rows[n++] = (PhlexJointRow)k;
    break;
  case PHLEX_JOINT_REVOLUTE: /* rotation about e3 free */
    for (PetscInt k = PHLEX_ROW_T1; k <= PHLEX_ROW_R2; k++) rows[n++] = (PhlexJointRow)k;
    break;
  case PHLEX_JOINT_SPHERICAL: /* every rotation free */
    for (PetscInt k = PHLEX_ROW_T1; k <= PHLEX_ROW_T3; k++) rows[n++] = (PhlexJointRow)k;
    break;
  case PHLEX_JOINT_PRISMATIC: /* sliding along e3 free */
    rows[n++] = PHLEX_ROW_T1, rows[n++] = PHLEX_ROW_T2;
    for (PetscInt k = PHLEX_ROW_R1; k <= PHLEX_ROW_R3; k++) rows[n++] = (PhlexJointRow)k;
    break;
  case PHLEX_JOINT_CYLINDRICAL: /* sliding along and rotation about e3 free */
    rows[n++] = PHLEX_ROW_T1, rows[n++] = PHLEX_ROW_T2, rows[n++] = PHLEX_ROW_R1, rows[n++] = PHLEX_ROW_R2;
    break;
  case PHLEX_JOINT_UNIVERSAL: /* rotations about e_a (on a) and e_b (on b) free */
    for (PetscInt k = PHLEX_ROW_T1; k <= PHLEX_ROW_T3; k++) rows[n++] = (PhlexJointRow)k;
    rows[n++] = PHLEX_ROW_CROSS;
    break;
  case PHLEX_JOINT_PLANAR: /* sliding in the plane normal to e3 and rotation about e3 free */
    rows[n++] = PHLEX_ROW_T3, rows[n++] = PHLEX_ROW_R1, rows[n++] = PHLEX_ROW_R2;
    break;
  case PHLEX_JOINT_SPRING_DAMPER: /* no constraint: one element row along the line of action (e3) */
  case PHLEX_JOINT_BUSHING:       /* no constraint: six element rows */
    break;
  case PHLEX_JOINT_PRESCRIBED: /* the given velocities of the port (inertial frame: a is the ground) */
    if (j->presc_v)
      for (PetscInt k = PHLEX_ROW_T1; k <= PHLEX_ROW_T3; k++) rows[n++] = (PhlexJointRow)k;
    if (j->presc_w)
      for (PetscInt k = PHLEX_ROW_R1; k <= PHLEX_ROW_R3; k++) rows[n++] = (PhlexJointRow)k;
    break;
  }
  if (j->drive_row >= 0) rows[n++] = (PhlexJointRow)j->drive_row;
  j->nc = 0;
  for (PetscInt k = 0; k < n; k++) {
    const PetscBool rotation = rows[k] >= PHLEX_ROW_R1 ? PETSC_TRUE : PETSC_FALSE;
    const PetscBool drive    = (j->drive_row >= 0 && k == n - 1) || j->type == PHLEX_JOINT_PRESCRIBED ? PETSC_TRUE : PETSC_FALSE;
    if (rotation && !(j->side[0].rotation && j->side[1].rotation)) {
      PetscCheck(!drive, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a prescribed rotation needs ports with an orientation; %s is a point", j->name, j->side[j->side[0].rotation ? 1 : 0].spec);
      j->rot_dropped = PETSC_TRUE;
      continue;
    }
    j->row[j->nc] = rows[k];
    PetscCall(PetscStrcpy(j->rowname[j->nc], drive && j->type != PHLEX_JOINT_PRESCRIBED ? "drive" : RowNames[rows[k]]));
    j->nc++;
  }
  if (j->drive_row >= 0) j->drive_row = j->nc - 1;
  PetscCall(SelectElementRows(j));
  PetscCheck(j->nc > 0 || j->ne > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a %s joint between %s and %s constrains nothing (a point mass has no orientation)", j->name, PhlexJointTypes[j->type], j->side[0].spec, j->side[1].spec);
  PetscFunctionReturn(0);
}
