/* The joint kinds: which generalized directions of the relative motion each constrains (rows of the joint, in a's
   joint frame e1, e2, e3 = axis). A drive adds the free direction it prescribes. Rotation rows need an orientation
   on both ports: with a point mass on either side they are left out (a point transmits no moment). */
#include <phlex_impl.h>

static const char *const RowNames[] = {"t1", "t2", "t3", "r1", "r2", "r3", "cross"};

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
  PetscCheck(j->nc > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a %s joint between %s and %s constrains nothing (a point mass has no orientation)", j->name, PhlexJointTypes[j->type], j->side[0].spec, j->side[1].spec);
  PetscFunctionReturn(0);
}
