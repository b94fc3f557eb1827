/* Joints (include/private/joint.h): the transformer interconnection of two ports at velocity level (paper Section
   5.1, eq. int_hinge generalised to 3D: the relative velocity of the ports, rotated by R_ab = R_a^T R_b, is
   constrained along the joint's directions; the multipliers act on both ports through their distributions). The
   joint kinds differ only in the directions they constrain (joint_types.c). */
#include <phlex_impl.h>

const char *const PhlexJointTypes[] = {"fixed", "revolute", "spherical", "prismatic", "cylindrical", "universal", "planar", "prescribed", "spring_damper", "bushing", "PhlexJointType", "PHLEX_JOINT_", NULL};

PETSC_INTERN PetscErrorCode PhlexJointSelectRows(PhlexJoint);
static PetscErrorCode Placements(PhlexJoint, const PhlexPartVec *, const PhlexPartVec *, PetscReal[3], PetscReal[9]);

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

/* the joint's rows with a force: its constraint rows, then its force elements' rows */
static inline PetscInt NumRows(PhlexJoint j)
{
  return j->nc + j->ne;
}

/* A spring's force-elongation table (non-dimensional): f(e) piecewise linear through the points, extended linearly
   beyond its ends; segment s of e (0 .. n-2) */
static PetscInt TableSegment(PhlexJoint j, PetscReal e)
{
  PetscInt s = 0;
  while (s < j->ntable - 2 && e > j->table_e[s + 1]) s++;
  return s;
}

/* f(e) and its slope */
static void TableForce(PhlexJoint j, PetscReal e, PetscReal *f, PetscReal *slope)
{
  const PetscInt  s = TableSegment(j, e);
  const PetscReal k = (j->table_f[s + 1] - j->table_f[s]) / (j->table_e[s + 1] - j->table_e[s]);

  *f = j->table_f[s] + k * (e - j->table_e[s]);
  if (slope) *slope = k;
}

/* the antiderivative A(e) = int_{e_0}^{e} f (exact: f is linear on each segment) */
static PetscReal TableAntiderivative(PhlexJoint j, PetscReal e)
{
  const PetscInt s = TableSegment(j, e);
  PetscReal      A = 0.0, f;

  for (PetscInt i = 0; i < s; i++) A += 0.5 * (j->table_f[i] + j->table_f[i + 1]) * (j->table_e[i + 1] - j->table_e[i]);
  TableForce(j, e, &f, NULL);
  return A + 0.5 * (j->table_f[s] + f) * (e - j->table_e[s]);
}

/* the spring's energy V(e) = int_0^e f */
static PetscReal TablePotential(PhlexJoint j, PetscReal e)
{
  return TableAntiderivative(j, e) - TableAntiderivative(j, 0.0);
}

/* the spring force of a table over a step and its derivative with respect to the stage state e: with the implicit
   midpoint rule (j->dg) the discrete gradient (V(e1) - V(e0)) / (e1 - e0), e0 the state at the step's start and
   e1 = 2 e - e0 its end, so that the spring's energy changes by exactly the work of the force; within one segment
   (V quadratic) that is f(e) itself; otherwise f(e) */
static void TableStepForce(PhlexJoint j, PetscInt i, PetscReal e, PetscReal *f, PetscReal *dfde)
{
  const PetscReal e0 = j->e_start[i], e1 = 2.0 * e - e0, h = e1 - e0;

  if (!j->dg || TableSegment(j, e0) == TableSegment(j, e1) || PetscAbsReal(h) < 1e-12) {
    TableForce(j, e, f, dfde);
    return;
  }
  {
    const PetscReal dV = TablePotential(j, e1) - TablePotential(j, e0);
    PetscReal       f1;
    TableForce(j, e1, &f1, NULL);
    *f = dV / h;
    if (dfde) *dfde = 2.0 * (f1 * h - dV) / (h * h);
  }
}

/* row k's direction turns with R_ab (the universal's cross row, its torsion element about b's axis) */
static PetscBool RowTurns(PhlexJoint j, PetscInt k)
{
  const PhlexJointRow row = k < j->nc ? j->row[k] : j->erow[k - j->nc];
  return (row == PHLEX_ROW_CROSS || row == PHLEX_ROW_AXIS_B) ? PETSC_TRUE : PETSC_FALSE;
}

/* the nominal rest of a joint's moving element (non-dimensional): the spring_damper's rest length, the torsion spring's
   rest angle */
static PetscReal RestNominal(PhlexJoint j)
{
  return j->type == PHLEX_JOINT_SPRING_DAMPER ? j->rest_length / j->units->length : j->rest_angle;
}

/* r(t) = rest(t) - rest = rest (f(t) - 1), the moving rest's change from the nominal (non-dimensional; 0: none) */
static PetscErrorCode RestShift(PhlexJoint j, PetscReal t, PetscReal *r)
{
  PetscReal f;

  PetscFunctionBeginUser;
  *r = 0.0;
  if (!j->rest_profile) PetscFunctionReturn(0);
  PetscCall(PhlexProfileEvaluate(j->rest_profile, t, &f));
  *r = RestNominal(j) * (f - 1.0);
  PetscFunctionReturn(0);
}

/* what the spring of element row i acts on at the evaluated state: its state less the moving rest's change */
static inline PetscReal ElementArg(PhlexJoint j, PetscInt i)
{
  return j->e[i] - (i == 0 ? j->eshift : 0.0);
}

/* the direction (6-vector, a's body frame) of row k (k >= nc: element row k - nc), and its change for a change dRab
   of R_ab (universal only) */
static void RowDirection(PhlexJoint j, PetscInt k, const PetscReal Rab[9], const PetscReal *dRab, PetscReal s[6])
{
  const PhlexJointRow row = k < j->nc ? j->row[k] : j->erow[k - j->nc];

  for (PetscInt c = 0; c < 6; c++) s[c] = 0.0;
  switch (row) {
  case PHLEX_ROW_T1:
  case PHLEX_ROW_T2:
  case PHLEX_ROW_T3:
    if (!dRab)
      for (PetscInt c = 0; c < 3; c++) s[c] = j->dir[3 * (row - PHLEX_ROW_T1) + c];
    break;
  case PHLEX_ROW_R1:
  case PHLEX_ROW_R2:
  case PHLEX_ROW_R3:
    if (!dRab)
      for (PetscInt c = 0; c < 3; c++) s[3 + c] = j->dir[3 * (row - PHLEX_ROW_R1) + c];
    break;
  case PHLEX_ROW_CROSS: {
    /* n = e_a x (R_ab e_b): both axes turn with their bodies */
    PetscReal eb[3];
    PhlexMatVec3(dRab ? dRab : Rab, j->eb, eb);
    PhlexCross(j->dir + 6, eb, s + 3);
  } break;
  case PHLEX_ROW_AXIS_B:
    /* R_ab e_b: the universal's second axis turns with b */
    PhlexMatVec3(dRab ? dRab : Rab, j->eb, s + 3);
    break;
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

/* a 6 x 6 matrix option of a bushing: 36 finite values, symmetric, positive semi-definite (checked on the matrix scaled
   by its diagonal, D^{-1/2} A D^{-1/2}, so that the mixed units of its blocks do not matter) */
static PetscErrorCode CheckElementMatrix(PhlexJoint j, const char opt[], const PetscReal A[], PetscInt n)
{
  PetscReal    amax = 0.0, S[36], w[6], work[64];
  PetscBLASInt nb = 6, lwork = 64, info;
  PetscInt     idx[6], m = 0;

  PetscFunctionBeginUser;
  PetscCheck(n == 36, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s needs 36 values (a 6 x 6 matrix, row-major), got %s%" PetscInt_FMT, j->name, j->prefix, opt, n > 36 ? "more than " : "", n > 36 ? (PetscInt)36 : n);
  for (PetscInt i = 0; i < 36; i++) {
    PetscCheck(!PetscIsInfOrNanReal(A[i]), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s: value %" PetscInt_FMT " is not a finite number", j->name, j->prefix, opt, i + 1);
    amax = PetscMax(amax, PetscAbsReal(A[i]));
  }
  for (PetscInt r = 0; r < 6; r++)
    for (PetscInt c = r + 1; c < 6; c++)
      PetscCheck(PetscAbsReal(A[6 * r + c] - A[6 * c + r]) <= 1e-12 * amax, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s is not symmetric: entry (%" PetscInt_FMT ",%" PetscInt_FMT ") = %g, entry (%" PetscInt_FMT ",%" PetscInt_FMT ") = %g", j->name, j->prefix, opt, r + 1, c + 1, (double)A[6 * r + c], c + 1, r + 1, (double)A[6 * c + r]);
  for (PetscInt r = 0; r < 6; r++) {
    PetscCheck(A[7 * r] >= 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s is not positive semi-definite: diagonal entry %" PetscInt_FMT " is %g", j->name, j->prefix, opt, r + 1, (double)A[7 * r]);
    if (A[7 * r] > 0) idx[m++] = r;
    else
      for (PetscInt c = 0; c < 6; c++) PetscCheck(A[6 * r + c] == 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s is not positive semi-definite: diagonal entry %" PetscInt_FMT " is 0 but entry (%" PetscInt_FMT ",%" PetscInt_FMT ") is %g", j->name, j->prefix, opt, r + 1, r + 1, c + 1, (double)A[6 * r + c]);
  }
  if (!m) PetscFunctionReturn(0);
  for (PetscInt r = 0; r < m; r++)
    for (PetscInt c = 0; c < m; c++) S[m * r + c] = A[6 * idx[r] + idx[c]] / PetscSqrtReal(A[7 * idx[r]] * A[7 * idx[c]]);
  nb = (PetscBLASInt)m;
  PetscCallBLAS("LAPACKsyev", LAPACKsyev_("N", "U", &nb, S, &nb, w, work, &lwork, &info));
  PetscCheck(info == 0, j->comm, PETSC_ERR_LIB, "joint %s: -%s%s: LAPACK syev failed (info %d)", j->name, j->prefix, opt, (int)info);
  PetscCheck(w[0] >= -1e-10, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s is not positive semi-definite (indefinite: smallest eigenvalue %.3g of the matrix scaled to a unit diagonal)", j->name, j->prefix, opt, (double)w[0]);
  PetscFunctionReturn(0);
}

/* a spring-damper's force-elongation table: pairs, at least two points, finite, elongations strictly increasing; not
   with -stiffness */
static PetscErrorCode ForceTableCheck(PhlexJoint j, const PetscReal tab[], PetscInt n, PhlexJointType type, PetscBool stiffness)
{
  PetscFunctionBeginUser;
  PetscCheck(type == PHLEX_JOINT_SPRING_DAMPER, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table is for a spring_damper joint, not %s", j->name, j->prefix, PhlexJointTypes[type]);
  PetscCheck(!stiffness, j->comm, PETSC_ERR_USER_INPUT, "joint %s: give the spring as -%sstiffness or as -%sforce_table, not both", j->name, j->prefix, j->prefix);
  PetscCheck(n <= 128, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table holds at most 64 points (128 numbers: pairs elongation, force); got more", j->name, j->prefix);
  PetscCheck(n % 2 == 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table needs pairs elongation,force [m, N]; got %" PetscInt_FMT " numbers", j->name, j->prefix, n);
  PetscCheck(n >= 4, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table needs at least 2 points, got %" PetscInt_FMT, j->name, j->prefix, n / 2);
  for (PetscInt i = 0; i < n; i++) PetscCheck(!PetscIsInfOrNanReal(tab[i]), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table: value %" PetscInt_FMT " is not a finite number", j->name, j->prefix, i + 1);
  for (PetscInt i = 1; i < n / 2; i++) PetscCheck(tab[2 * i] > tab[2 * i - 2], j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sforce_table: the elongations must increase strictly; point %" PetscInt_FMT " has %g m after %g m", j->name, j->prefix, i + 1, (double)tab[2 * i], (double)tab[2 * i - 2]);
  j->ntable = n / 2;
  for (PetscInt i = 0; i < j->ntable; i++) j->table_e[i] = tab[2 * i], j->table_f[i] = tab[2 * i + 1];
  PetscFunctionReturn(0);
}

/* the force-element options of a joint: each refused on a kind it does not belong to, values checked */
static PetscErrorCode ElementOptionsCheck(PhlexJoint j, PhlexJointType type, PetscBool spring_opts, PetscBool rot_opts, const PetscReal K[], PetscInt nK, const PetscReal C[], PetscInt nC)
{
  PetscFunctionBeginUser;
  if (type == PHLEX_JOINT_SPRING_DAMPER) {
    PetscCheck(!rot_opts, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srotational_stiffness, -%srotational_damping and -%srest_angle are for a revolute or cylindrical joint; a spring_damper takes -%sstiffness, -%sdamping, -%srest_length", j->name, j->prefix, j->prefix, j->prefix, j->prefix, j->prefix, j->prefix);
    PetscCheck(j->stiffness > 0 || j->damping > 0 || j->ntable, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a spring_damper needs -%sstiffness [N/m] (or -%sforce_table) and/or -%sdamping [N s/m]", j->name, j->prefix, j->prefix, j->prefix);
  } else PetscCheck(!spring_opts, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sstiffness, -%sdamping and -%srest_length are for a spring_damper joint, not %s (a revolute or cylindrical joint takes -%srotational_stiffness, -%srotational_damping)", j->name, j->prefix, j->prefix, j->prefix, PhlexJointTypes[type], j->prefix, j->prefix);
  if (type == PHLEX_JOINT_SPRING_DAMPER || rot_opts) {
    const char *ks = type == PHLEX_JOINT_SPRING_DAMPER ? "stiffness" : "rotational_stiffness", *cs = type == PHLEX_JOINT_SPRING_DAMPER ? "damping" : "rotational_damping";
    PetscCheck(j->stiffness >= 0 && !PetscIsInfOrNanReal(j->stiffness), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s must be a finite number >= 0 [%s], got %g", j->name, j->prefix, ks, type == PHLEX_JOINT_SPRING_DAMPER ? "N/m" : "N m/rad", (double)j->stiffness);
    PetscCheck(j->damping >= 0 && !PetscIsInfOrNanReal(j->damping), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%s%s must be a finite number >= 0 [%s], got %g", j->name, j->prefix, cs, type == PHLEX_JOINT_SPRING_DAMPER ? "N s/m" : "N m s/rad", (double)j->damping);
  }
  if (type == PHLEX_JOINT_SPRING_DAMPER && j->rest_length != -1.0) PetscCheck(j->rest_length >= 0 && !PetscIsInfOrNanReal(j->rest_length), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_length must be a finite length >= 0 [m], got %g", j->name, j->prefix, (double)j->rest_length);
  if (rot_opts) {
    PetscCheck(type == PHLEX_JOINT_REVOLUTE || type == PHLEX_JOINT_CYLINDRICAL || type == PHLEX_JOINT_UNIVERSAL, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srotational_stiffness, -%srotational_damping and -%srest_angle act on a free rotation (a revolute, cylindrical or universal joint); a %s joint has none", j->name, j->prefix, j->prefix, j->prefix, PhlexJointTypes[type]);
    PetscCheck(!PetscIsInfOrNanReal(j->rest_angle), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_angle must be a finite angle [deg], got %g", j->name, j->prefix, (double)j->rest_angle);
    j->rot_element = PETSC_TRUE;
    j->rest_angle *= PETSC_PI / 180.0;
  }
  if (type == PHLEX_JOINT_BUSHING) {
    PetscCheck(nK >= 0 || nC >= 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a bushing needs -%sstiffness_matrix and/or -%sdamping_matrix (36 values each)", j->name, j->prefix, j->prefix);
    if (nK >= 0) PetscCall(CheckElementMatrix(j, "stiffness_matrix", K, nK));
    if (nC >= 0) PetscCall(CheckElementMatrix(j, "damping_matrix", C, nC));
    for (PetscInt i = 0; i < 36; i++) {
      j->Ksi[i] = nK >= 0 ? K[i] : 0.0;
      j->Csi[i] = nC >= 0 ? C[i] : 0.0;
    }
  } else PetscCheck(nK < 0 && nC < 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sstiffness_matrix and -%sdamping_matrix are for a bushing (-%stype bushing), not %s", j->name, j->prefix, j->prefix, j->prefix, PhlexJointTypes[type]);
  PetscFunctionReturn(0);
}

/* A moving rest (an actuator a controller commands): -rest_length_profile_* of a spring_damper, L(t) = rest_length f(t);
   -rest_angle_profile_* of a torsion spring, rest_angle f(t). Refused on an element that has no such rest. */
static PetscErrorCode RestProfileSetFromOptions(PhlexJoint j)
{
  char      lprefix[256], aprefix[256], what[256];
  PetscBool lgiven, agiven;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(lprefix, sizeof(lprefix), "%srest_length_", j->prefix));
  PetscCall(PetscSNPrintf(aprefix, sizeof(aprefix), "%srest_angle_", j->prefix));
  PetscCall(PhlexProfileGiven(lprefix, &lgiven));
  PetscCall(PhlexProfileGiven(aprefix, &agiven));
  PetscCheck(!lgiven || j->type == PHLEX_JOINT_SPRING_DAMPER, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_length_profile_* moves the rest length of a spring_damper; a %s joint has none%s", j->name, j->prefix, PhlexJointTypes[j->type], j->rot_element ? " (its torsion spring's rest angle moves with -rest_angle_profile_*)" : "");
  PetscCheck(!agiven || j->rot_element, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_angle_profile_* moves the rest angle of a torsion spring (-%srotational_stiffness on a revolute or cylindrical joint); this %s joint has none", j->name, j->prefix, j->prefix, PhlexJointTypes[j->type]);
  PetscCheck(!agiven || j->type != PHLEX_JOINT_UNIVERSAL, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_angle_profile_* moves one torsion spring's rest angle; a universal joint has two (not implemented: use a revolute or cylindrical joint's)", j->name, j->prefix);
  if (j->type != PHLEX_JOINT_SPRING_DAMPER && !j->rot_element) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(what, sizeof(what), "joint %s, %s", j->name, j->rot_element ? "rest angle" : "rest length"));
  PetscCall(PhlexProfileCreate(j->comm, j->rot_element ? aprefix : lprefix, what, &j->rest_profile));
  PetscCall(PhlexProfileSetFromOptions(j->rest_profile)); /* listed by -help on every such element */
  if (!j->rest_profile->given) {
    PetscCall(PhlexProfileDestroy(&j->rest_profile));
    PetscFunctionReturn(0);
  }
  PetscCheck(!j->rot_element || j->rest_angle != 0.0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_angle_profile_* multiplies the rest angle, which is 0: give the angle it scales with -%srest_angle (-%srest_angle 1 reads the profile in degrees)", j->name, j->prefix, j->prefix, j->prefix);
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
. -profile_*                  - prescribed: time profile of those
. -stiffness k                - spring_damper: axial stiffness [N/m]
. -damping c                  - spring_damper: axial damping [N s/m]
. -rest_length l              - spring_damper: length at zero force [m] (default: the drawn distance of the ports)
. -rotational_stiffness k     - revolute, cylindrical: a torsion spring on the free rotation [N m/rad]
. -rotational_damping c       - revolute, cylindrical: viscous friction on the free rotation [N m s/rad]
. -rest_angle a               - revolute, cylindrical: the torsion spring's zero-moment angle [deg] (default 0: drawn)
. -rest_length_profile_*      - spring_damper: a moving rest length L(t) = rest_length f(t) (an actuator)
. -rest_angle_profile_*       - torsion spring: a moving rest angle rest_angle f(t)
. -stiffness_matrix k11,...   - bushing: 6 x 6 stiffness, row-major, rows/columns t1 t2 t3 r1 r2 r3 of the joint frame
- -damping_matrix c11,...     - bushing: 6 x 6 damping, the same layout (SI: N/m, N/rad, N m/m, N m/rad; N s/m, ...)
@*/
PetscErrorCode PhlexJointSetFromOptions(PhlexJoint j)
{
  char    **ports;
  PetscInt  nports, nalloc, type = PHLEX_JOINT_REVOLUTE, comp = 0;
  PetscBool ftype = PETSC_FALSE, fports = PETSC_FALSE, fdrive = PETSC_FALSE, fcomp = PETSC_FALSE, fdi = PETSC_FALSE;
  PetscBool fk = PETSC_FALSE, fc = PETSC_FALSE, fl = PETSC_FALSE, frk = PETSC_FALSE, frc = PETSC_FALSE, fra = PETSC_FALSE;
  PetscBool fsk = PETSC_FALSE, fsc = PETSC_FALSE, frs = PETSC_FALSE;
  PetscReal Kbuf[37], Cbuf[37];
  PetscInt  nK = 37, nC = 37;
  char      who[PHLEX_NAME_LEN + 16];
  const char *const comps[] = {"rotation", "translation", "PhlexDriveComponent", "", NULL};

  PetscFunctionBeginUser;
  PetscCall(PhlexOptionsListLength(j->prefix, "-ports", &nalloc)); /* the count a wrong list really has */
  nports = nalloc;
  PetscCall(PetscCalloc1(nalloc, &ports));
  PetscOptionsBegin(j->comm, j->prefix, "Joint options", NULL);
  PetscCall(PetscOptionsString("-name", "Name of the joint (messages, output files)", "PhlexJointSetFromOptions", j->name, j->name, sizeof(j->name), NULL));
  PetscCall(PetscSNPrintf(who, sizeof(who), "joint %s", j->name));
  PetscCall(PetscOptionsEList("-type", "Joint kind: fixed, revolute, spherical, prismatic, cylindrical, universal, planar, prescribed (a port's motion); force elements: spring_damper (between the two port points), bushing (6 x 6 stiffness and damping)", "PhlexJointSetFromOptions", PhlexJointTypes, 10, PhlexJointTypes[type], &type, &ftype));
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
  j->rest_length = -1.0;
  PetscCall(PetscOptionsReal("-stiffness", "Spring-damper: axial stiffness [N/m] (force on the second port -k (length - rest length) along the line)", "PhlexJointSetFromOptions", j->stiffness, &j->stiffness, &fk));
  PetscCall(PetscOptionsReal("-damping", "Spring-damper: axial damping [N s/m]", "PhlexJointSetFromOptions", j->damping, &j->damping, &fc));
  PetscCall(PetscOptionsReal("-rest_length", "Spring-damper: length at zero spring force [m] (default: the drawn distance of the two port points)", "PhlexJointSetFromOptions", j->rest_length, &j->rest_length, &fl));
  /* -1 marks "as drawn" (set up later): a typed -1 is refused like any negative length */
  PetscCheck(!fl || (j->rest_length >= 0 && !PetscIsInfOrNanReal(j->rest_length)), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_length must be a finite length >= 0 [m], got %g", j->name, j->prefix, (double)j->rest_length);
  PetscCall(PetscOptionsReal("-rotational_stiffness", "Revolute, cylindrical: torsion spring on the free rotation; universal: on each of its two [N m/rad]", "PhlexJointSetFromOptions", j->stiffness, &j->stiffness, &frk));
  PetscCall(PetscOptionsReal("-rotational_damping", "Revolute, cylindrical: viscous friction (a rotational damper) on the free rotation; universal: on each of its two [N m s/rad]", "PhlexJointSetFromOptions", j->damping, &j->damping, &frc));
  PetscCall(PetscOptionsReal("-rest_angle", "Revolute, cylindrical (universal: both angles): the torsion spring's zero-moment angle relative to the drawn configuration [deg]", "PhlexJointSetFromOptions", j->rest_angle, &j->rest_angle, &fra));
  PetscCall(PetscOptionsReal("-slide_stiffness", "Prismatic, cylindrical: a spring on the slide (force on the second port -k (slide - rest slide) along the axis) [N/m]", "PhlexJointSetFromOptions", j->slide_stiffness, &j->slide_stiffness, &fsk));
  PetscCall(PetscOptionsReal("-slide_damping", "Prismatic, cylindrical: viscous friction on the slide [N s/m]", "PhlexJointSetFromOptions", j->slide_damping, &j->slide_damping, &fsc));
  PetscCall(PetscOptionsReal("-rest_slide", "Prismatic, cylindrical: the slide spring's zero-force slide relative to the drawn configuration [m]", "PhlexJointSetFromOptions", j->rest_slide, &j->rest_slide, &frs));
  {
    PetscReal tab[129];
    PetscInt  ntab = 129;
    PetscBool ftab = PETSC_FALSE;
    PetscCall(PhlexOptionsRealList("-force_table", "Spring-damper: force-elongation table e0,f0,e1,f1,... [m, N] (the tension f(e): the force on the second port is -f along the line; elongation = length - rest length, strictly increasing; piecewise linear, extended linearly beyond its ends), instead of -stiffness", "PhlexJointSetFromOptions", tab, &ntab, &ftab, 0));
    if (ftab && ftype) PetscCall(ForceTableCheck(j, tab, ntab, (PhlexJointType)type, fk && j->stiffness != 0));
    fl = (PetscBool)(fl || ftab);
  }
  PetscCall(PetscArrayzero(Kbuf, 37));
  PetscCall(PetscArrayzero(Cbuf, 37));
  PetscCall(PhlexOptionsRealList("-stiffness_matrix", "Bushing: 6 x 6 stiffness, row-major, rows and columns t1,t2,t3,r1,r2,r3 of the joint frame [N/m, N/rad; N m/m, N m/rad] (symmetric positive semi-definite)", "PhlexJointSetFromOptions", Kbuf, &nK, &j->Kgiven, 0));
  PetscCall(PhlexOptionsRealList("-damping_matrix", "Bushing: 6 x 6 damping, the same layout [N s/m, N s/rad; N m s/m, N m s/rad] (symmetric positive semi-definite)", "PhlexJointSetFromOptions", Cbuf, &nC, &j->Cgiven, 0));
  PetscOptionsEnd();
  /* a rest angle alone would make a torsion element of nothing */
  PetscCheck(!fra || frk || frc, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_angle %g is the zero-moment angle of a torsion spring: give -%srotational_stiffness (and/or -%srotational_damping) too", j->name, j->prefix, (double)j->rest_angle, j->prefix, j->prefix);
  if (ftype) PetscCall(ElementOptionsCheck(j, (PhlexJointType)type, fk || fc || fl, frk || frc || fra, Kbuf, j->Kgiven ? nK : -1, Cbuf, j->Cgiven ? nC : -1));
  if (fsk || fsc || frs) {
    /* a spring-damper on the slide of a prismatic or cylindrical joint */
    PetscCheck(!ftype || type == PHLEX_JOINT_PRISMATIC || type == PHLEX_JOINT_CYLINDRICAL, j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sslide_stiffness, -%sslide_damping and -%srest_slide act on a slide (a prismatic or cylindrical joint); a %s joint has none", j->name, j->prefix, j->prefix, j->prefix, ftype ? PhlexJointTypes[type] : "joint of no kind");
    PetscCheck(j->slide_stiffness >= 0 && !PetscIsInfOrNanReal(j->slide_stiffness), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sslide_stiffness must be a finite number >= 0 [N/m], got %g", j->name, j->prefix, (double)j->slide_stiffness);
    PetscCheck(j->slide_damping >= 0 && !PetscIsInfOrNanReal(j->slide_damping), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%sslide_damping must be a finite number >= 0 [N s/m], got %g", j->name, j->prefix, (double)j->slide_damping);
    PetscCheck(!PetscIsInfOrNanReal(j->rest_slide), j->comm, PETSC_ERR_USER_INPUT, "joint %s: -%srest_slide must be a finite length [m], got %g", j->name, j->prefix, (double)j->rest_slide);
    PetscCheck(j->slide_stiffness > 0 || j->slide_damping > 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a slide spring-damper needs -%sslide_stiffness [N/m] > 0 and/or -%sslide_damping [N s/m] > 0 (-%srest_slide alone is the rest of nothing)", j->name, j->prefix, j->prefix, j->prefix);
    j->slide_element = PETSC_TRUE;
  }
  PetscCheck(ftype, j->comm, PETSC_ERR_USER_INPUT, "joint %s: give its kind: -%stype fixed|revolute|spherical|prismatic|cylindrical|universal|planar|prescribed|spring_damper|bushing", j->name, j->prefix);
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
    PetscCheck(needs_axis || j->type == PHLEX_JOINT_BUSHING || !j->axis_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a %s joint has no axis (-%saxis)", j->name, PhlexJointTypes[j->type], j->prefix);
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
  PetscCheck(!(j->slide_element && j->drive_row == PHLEX_ROW_T3), j->comm, PETSC_ERR_USER_INPUT, "joint %s: its slide is driven (-%sdrive_velocity): it cannot also carry a slide spring-damper (-%sslide_stiffness, -%sslide_damping)", j->name, j->prefix, j->prefix, j->prefix);
  PetscCheck(!(j->rot_element && j->drive_row == PHLEX_ROW_R3), j->comm, PETSC_ERR_USER_INPUT, "joint %s: its free rotation is driven (-%sdrive_velocity): it cannot also carry a rotational spring-damper (-%srotational_stiffness, -%srotational_damping)", j->name, j->prefix, j->prefix, j->prefix);

  if (j->type == PHLEX_JOINT_PRESCRIBED) {
    char prefix[256], what[256];
    PetscCall(PetscSNPrintf(what, sizeof(what), "joint %s, prescribed motion", j->name));
    PetscCall(PhlexProfileCreate(j->comm, j->prefix, what, &j->drive_profile));
    PetscCall(PhlexProfileSetFromOptions(j->drive_profile));
    (void)prefix;
  }
  PetscCall(RestProfileSetFromOptions(j));
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
  if (j->type == PHLEX_JOINT_SPRING_DAMPER) {
    const PetscBool ground = (PhlexPartIsGround(j->side[0].part) || PhlexPartIsGround(j->side[1].part)) ? PETSC_TRUE : PETSC_FALSE;
    PetscCheck(!ground || j->position_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a spring_damper to the ground needs its ground end: -%sposition x,y,z [m]", j->name, j->prefix);
    PetscCheck(ground || !j->position_given, j->comm, PETSC_ERR_USER_INPUT, "joint %s: a spring_damper between two bodies acts between their port points; -%sposition is only for its end on the ground", j->name, j->prefix);
  }
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
    } else if (j->position_given || j->type == PHLEX_JOINT_BUSHING) {
      /* a bushing closes no gap (no constraint rows): each side reaches the joint point from its own port, so the
         drawn pose is its rest (zero deflection) */
      PetscReal d[3];
      for (PetscInt k = 0; k < 3; k++) d[k] = xJ[k] - xp[s][k];
      PhlexMatTVec3(Rp[s], d, side->offset);
    } else
      for (PetscInt k = 0; k < 3; k++) side->offset[k] = 0.0; /* the port points must meet: the assembly closes a gap */
    if (j->type == PHLEX_JOINT_SPRING_DAMPER && !PhlexPartIsGround(side->part))
      for (PetscInt k = 0; k < 3; k++) side->offset[k] = 0.0; /* a spring-damper's ends are its port points */
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
  if (j->type == PHLEX_JOINT_SPRING_DAMPER) {
    PetscReal dx[3], E[9], len;
    PetscCall(Placements(j, Xa, Xb, dx, E));
    len = PhlexNorm3(dx);
    PetscCheck(len > 1e-12, j->comm, PETSC_ERR_USER_INPUT, "joint %s: the ends of the spring_damper (%s and %s) coincide as drawn: its line of action has no direction", j->name, j->side[0].spec, j->side[1].spec);
    if (j->rest_length < 0) j->rest_length = len * u->length;
    if (j->rest_profile) {
      /* L(t) = rest_length f(t) must stay a length */
      PetscReal fmin, fmax;
      PetscCall(PhlexProfileBounds(j->rest_profile, &fmin, &fmax));
      PetscCheck(fmin >= 0, j->comm, PETSC_ERR_USER_INPUT, "joint %s: the rest length %g m times its profile (-%srest_length_profile_*) would be negative: the profile's least value is %g; a rest length is rest_length x f(t) >= 0", j->name, (double)j->rest_length, j->prefix, (double)fmin);
    }
  }
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
  rotation up to a lag of second order in the step. A flexible port's rate map (the left Jacobian of its mean rotation, by which its
  output is the exact rate of its orientation R exp(theta), and its transpose on the moment it takes) is taken here
  too, at the same state, and held likewise (PhlexPartOps.portrate). A step retried with a smaller step size (adaptive steps,
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
    if (!PhlexPartIsGround(side->part) && side->part->ops.portrate) {
      PetscReal A[9];
      PetscCall((*side->part->ops.portrate)(side->part, side->port, X[s], A)); /* the port's rate map, held likewise */
    }
    if (PhlexPartIsGround(side->part))
      for (PetscInt k = 0; k < 3; k++) side->arm[k] = side->offset[k];
    else PhlexMatVec3(P[s], side->offset, side->arm);
  }
  if (j->type == PHLEX_JOINT_SPRING_DAMPER) {
    /* the line of action between the two ends (e3 of the joint frame), held over the step like every joint direction */
    PetscReal dx[3], E[9];
    PetscCall(Placements(j, Xa, Xb, dx, E));
    if (PhlexNorm3(dx) > 1e-12) {
      PetscReal e1[3] = {j->frame[0], j->frame[1], j->frame[2]}; /* e1 kept as close as it can stay */
      PhlexCompleteFrame(dx, e1, j->frame);
    }
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
  for (PetscInt k = 0; k < NumRows(j); k++) j->lambda[k] = qd ? T * qd[j->qoff + k] : 0.0;
  for (PetscInt i = 0; i < j->ne; i++) {
    j->e[i]    = q[j->qoff + NumRows(j) + i];
    j->edot[i] = qd ? T * qd[j->qoff + NumRows(j) + i] : 0.0;
  }
  j->eshift = 0.0;
  if (j->rest_profile && j->rest_step && t > j->rest_t0) {
    /* a midpoint stage at t: the mean of r at the step's ends t0 and 2 t - t0 (a retried step keeps t0) */
    PetscReal r0, r1;
    PetscCall(RestShift(j, j->rest_t0, &r0));
    PetscCall(RestShift(j, 2.0 * t - j->rest_t0, &r1));
    j->eshift = 0.5 * (r0 + r1);
  } else PetscCall(RestShift(j, t, &j->eshift));
  PetscFunctionReturn(0);
}

/* the joint's wrench on b at the joint point, a's body frame: w_J = sum_k lambda_k s_k (constraint rows and force
   elements) */
static void JointWrench(PhlexJoint j, const PetscReal *lambda, const PetscReal *dRab, PetscReal w[6])
{
  for (PetscInt c = 0; c < 6; c++) w[c] = 0.0;
  for (PetscInt k = 0; k < NumRows(j); k++) {
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
  for (PetscInt k = 0; k < NumRows(j); k++) /* the directions that turn with b: the cross row, b's axis */
    if (RowTurns(j, k)) {
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
  if (j->drive_step && (j->drive_start || t > j->drive_t0) && (j->type == PHLEX_JOINT_PRESCRIBED || (j->drive_row >= 0 && k == j->nc - 1))) {
    /* at the stage of a midpoint step: the rate whose step the scheme maps onto the prescribed increment. A position
       moves by dt v_m (exact for the step's mean rate); a rotation by the Cayley factor of dt w_m, an angle
       2 atan(|w_m| dt/2): w_m = 2 tan(phi/2)/dt along the increment phi (the mean rate alone lags by n (w dt -
       2 atan(w dt/2)) after n steps: 1e-2 rad in 100 steps of w dt = 0.5). The work is still exactly lambda . c. */
    /* the stage of the step from drive_t0 (t - t0 = dt/2), or the consistent start before it (t at t0, or its two short
       steps): the first step's stage rate, so that the velocities start at the rate the steps keep (with the mean rate
       a constant-speed drive's velocity alternated by (w dt)^2/6 every step) */
    const PetscReal dt = j->drive_start ? j->drive_dt : 2.0 * (t - j->drive_t0), dtn = dt / u->time;
    PetscReal       F0, F1, dF;
    PetscCall(PhlexProfileIntegrate(j->drive_profile, j->drive_t0, &F0));
    PetscCall(PhlexProfileIntegrate(j->drive_profile, j->drive_t0 + dt, &F1));
    dF = F1 - F0; /* [s] times the profile */
    if (j->type == PHLEX_JOINT_PRESCRIBED) {
      if (j->row[k] <= PHLEX_ROW_T3) *g = j->presc_velocity[j->row[k] - PHLEX_ROW_T1] * dF / dt / u->velocity;
      else {
        const PetscReal phi = PhlexNorm3(j->presc_angular) * PetscAbsReal(dF);
        const PetscReal scale = phi > 0 ? 2.0 * PetscTanReal(0.5 * phi) / phi : 1.0;
        PetscCheck(phi < 0.5 * PETSC_PI, j->comm, PETSC_ERR_USER_INPUT, "joint %s: its prescribed rotation turns the port by %g rad in a step of %g s, more than pi/2: the step cannot follow it; reduce -ts_dt", j->name, (double)phi, (double)dt);
        *g = j->presc_angular[j->row[k] - PHLEX_ROW_R1] * dF * scale / dtn;
      }
    } else if (j->row[k] == PHLEX_ROW_R3) {
      /* past a half turn per step tan(phi/2) changes sign: the body would turn backwards (aliasing) */
      if (PetscAbsReal(j->drive_velocity * dF) >= 0.5 * PETSC_PI) {
        char turn[32], step[32], most[32];
        SETERRQ(j->comm, PETSC_ERR_USER_INPUT, "joint %s: its drive turns it by %s rad in a step of %s s, more than pi/2: the step cannot follow it (a rotation's discrete map aliases past a half turn); reduce -ts_dt below %s s", j->name, PhlexFormatReal(j->drive_velocity * dF, turn, sizeof(turn)), PhlexFormatReal(dt, step, sizeof(step)), PhlexFormatReal(0.5 * PETSC_PI * dt / PetscAbsReal(j->drive_velocity * dF), most, sizeof(most)));
      }
      *g = 2.0 * PetscTanReal(0.5 * j->drive_velocity * dF) / dtn;
    }
    else *g = j->drive_velocity * dF / dt / u->velocity;
    PetscFunctionReturn(0);
  }
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
  if (j->ne) {
    PetscReal sD[6];
    for (PetscInt i = 0; i < j->ne; i++) {
      PetscReal s[6];
      RowDirection(j, j->nc + i, j->Rab, NULL, s);
      sD[i] = Dot6(s, D);
    }
    for (PetscInt i = 0; i < j->ne; i++) {
      PetscReal F = j->lambda[j->nc + i];
      for (PetscInt l = 0; l < j->ne; l++) F += j->K[j->ne * i + l] * ElementArg(j, l) + j->C[j->ne * i + l] * sD[l];
      if (j->ntable) {
        PetscReal ft;
        TableStepForce(j, i, ElementArg(j, i), &ft, NULL);
        F += ft;
      }
      f[j->qoff + j->nc + i]     = F;                 /* lambda = -(K e + C s.Delta) */
      f[j->qoff + NumRows(j) + i] = j->edot[i] - sD[i]; /* e' = s.Delta */
    }
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
  PetscReal Dl[6], sD[6];

  PetscFunctionBeginUser;
  (void)lambda;
  *D = 0.0;
  if (!j->ne) PetscFunctionReturn(0);
  Relative(j, Dl);
  for (PetscInt i = 0; i < j->ne; i++) {
    PetscReal s[6];
    RowDirection(j, j->nc + i, j->Rab, NULL, s);
    sD[i] = Dot6(s, Dl);
  }
  /* the force elements' dampers: (S^T Delta)^T C (S^T Delta) >= 0 */
  for (PetscInt i = 0; i < j->ne; i++)
    for (PetscInt l = 0; l < j->ne; l++) *D += sD[i] * j->C[j->ne * i + l] * sD[l];
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointNumUnknowns - the joint's discrete unknowns: its constraint impulses, its force elements' force impulses and
  their states
@*/
PetscInt PhlexJointNumUnknowns(PhlexJoint j)
{
  return j->nc + 2 * j->ne;
}

/*@C
  PhlexJointDamped - whether the joint's force elements have dampers (it dissipates)
@*/
PetscBool PhlexJointDamped(PhlexJoint j)
{
  for (PetscInt k = 0; k < j->ne * j->ne; k++)
    if (j->C[k] != 0) return PETSC_TRUE;
  return PETSC_FALSE;
}

/*@C
  PhlexJointElementEnergy - the energy stored in the joint's force elements, 1/2 a^T K a (non-dimensional), at the
  discrete unknowns q (replicated) and the time t: a = e, less a moving rest's change r(t)
@*/
PetscErrorCode PhlexJointElementEnergy(PhlexJoint j, PetscReal t, const PetscReal *q, PetscReal *V)
{
  PetscReal e[6], r;

  PetscFunctionBeginUser;
  *V = 0.0;
  PetscCall(RestShift(j, t, &r)); /* a moving rest: the spring's length at t less the rest at t */
  for (PetscInt i = 0; i < j->ne; i++) e[i] = q[j->qoff + NumRows(j) + i] - (i == 0 ? r : 0.0);
  for (PetscInt i = 0; i < j->ne; i++)
    for (PetscInt l = 0; l < j->ne; l++) *V += 0.5 * e[i] * j->K[j->ne * i + l] * e[l];
  if (j->ntable) *V += TablePotential(j, e[0]);
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointElementStepStart - before a step from t0: the force elements' states at its start (q: replicated; the
  argument of their springs, less a moving rest's change at t0), whether the scheme keeps the power balance (lossless:
  a table spring's force is then the discrete gradient over the step) and whether it is the implicit midpoint rule (a
  moving rest's change is then the mean of its values at the step's ends)
@*/
PetscErrorCode PhlexJointElementStepStart(PhlexJoint j, PetscReal t0, const PetscReal *q, PetscBool lossless, PetscBool midpoint)
{
  PetscReal r0;

  PetscFunctionBeginUser;
  PetscCall(RestShift(j, t0, &r0));
  for (PetscInt i = 0; i < j->ne; i++) j->e_start[i] = q[j->qoff + NumRows(j) + i] - (i == 0 ? r0 : 0.0);
  j->dg        = (PetscBool)(lossless && j->ntable > 0);
  j->rest_step = (PetscBool)(midpoint && j->rest_profile);
  j->rest_t0   = t0;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointDriveStepStart - before a step from t0 of length dt (and before the consistent start, with the first
  step's): whether it is a midpoint step, whose stage then takes the rate of a drive or a prescribed motion that makes
  the step's increment the prescribed one (Source); exact where the joint's other side does not rotate (a drive from
  the ground), else to the midpoint rule's error of composing two rotations

  Not collective
@*/
PetscErrorCode PhlexJointDriveStepStart(PhlexJoint j, PetscReal t0, PetscReal dt, PetscBool midpoint, PetscBool start)
{
  PetscFunctionBeginUser;
  j->drive_start = start;
  j->drive_step = (PetscBool)(midpoint && (j->drive_row >= 0 || j->type == PHLEX_JOINT_PRESCRIBED) && j->drive_profile);
  j->drive_t0   = t0;
  j->drive_dt   = dt;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointActuatorPower - the power a moving rest supplies to the element at the evaluated state (t: the evaluation's
  time; non-dimensional): -F r'(t), F the spring's tension (K a, or a table's force); at a midpoint stage the step's
  exact work over the step's length, -F (r_{n+1} - r_n) / dt

  Not collective
@*/
PetscErrorCode PhlexJointActuatorPower(PhlexJoint j, PetscReal t, PetscReal *P)
{
  PetscReal F = 0.0, rate;

  PetscFunctionBeginUser;
  *P = 0.0;
  if (!j->rest_profile) PetscFunctionReturn(0);
  for (PetscInt l = 0; l < j->ne; l++) F += j->K[l] * ElementArg(j, l); /* row 0: the moving one */
  if (j->ntable) {
    PetscReal ft;
    TableStepForce(j, 0, ElementArg(j, 0), &ft, NULL);
    F += ft;
  }
  if (j->rest_step && t > j->rest_t0) {
    const PetscReal dt = 2.0 * (t - j->rest_t0);
    PetscReal       r0, r1;
    PetscCall(RestShift(j, j->rest_t0, &r0));
    PetscCall(RestShift(j, j->rest_t0 + dt, &r1));
    rate = (r1 - r0) / (dt / j->units->time);
  } else {
    PetscReal df;
    PetscCall(PhlexProfileDerivative(j->rest_profile, t, &df));
    rate = RestNominal(j) * df * j->units->time;
  }
  *P = -F * rate;
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointPortWrench - the wrench (body frame, non-dimensional, at the port point) the joint applies to port `port`
  of `part` with the multipliers lambda, at the evaluated state; zero if it does not act there

  Not collective
@*/
PetscErrorCode PhlexJointPortWrench(PhlexJoint j, const PetscReal *lambda, PhlexPart part, PetscInt port, PetscReal w[6])
{
  PetscReal wJ[6], ws[2][6];

  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < 6; c++) w[c] = 0.0;
  JointWrench(j, lambda, NULL, wJ);
  PortWrenches(j, wJ, NULL, NULL, NULL, ws[0], ws[1]);
  for (PetscInt s = 0; s < 2; s++)
    if (j->side[s].part == part && j->side[s].port == port)
      for (PetscInt c = 0; c < 6; c++) w[c] += ws[s][c];
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
  for (PetscInt k = 0; k < NumRows(j); k++) {
    PetscReal sk[6];
    RowDirection(j, k, j->Rab, NULL, sk);
    rows[k] = Dot6(sk, r);
  }
  PetscFunctionReturn(0);
}

/* out[stride * row] += the change of the joint's residual rows for changes rows[k] = s_k . dDelta (k < nc + ne): a
   constraint row takes its own, an element's force row C rows_e, its state row -rows_e */
static void AddRows(PhlexJoint j, const PetscReal rows[], PetscReal *out, PetscInt stride)
{
  for (PetscInt k = 0; k < j->nc; k++) out[stride * (j->qoff + k)] += rows[k];
  for (PetscInt i = 0; i < j->ne; i++) {
    PetscReal F = 0.0;
    for (PetscInt l = 0; l < j->ne; l++) F += j->C[j->ne * i + l] * rows[j->nc + l];
    out[stride * (j->qoff + j->nc + i)] += F;
    out[stride * (j->qoff + NumRows(j) + i)] -= rows[j->nc + i];
  }
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
      PetscReal dy[6], rows[PHLEX_JOINT_MAX_ROWS];
      work[m] = 1.0;
      PetscCall((*p->ops.portlinear)(p, j->side[s].port, NULL, 0.0, NULL, work, dy));
      work[m] = 0.0;
      PetscCall(RowsFromPortChange(j, s, dy, rows));
      AddRows(j, rows, D + p->qoff + m, ld);
    }
    /* the part's rows x the impulses (constraints' and elements'): -shift (generalized force of d w / d lambda_k) */
    for (PetscInt k = 0; k < NumRows(j); k++) {
      PetscReal e[PHLEX_JOINT_MAX_ROWS] = {0}, wk[6], w[2][6];
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
      {
        PetscReal dc[PHLEX_JOINT_MAX_ROWS];
        for (PetscInt k = 0; k < NumRows(j); k++) {
          PetscReal sk[6], dsk[6];
          RowDirection(j, k, j->Rab, NULL, sk);
          RowDirection(j, k, j->Rab, dRab, dsk);
          dc[k] = Dot6(sk, r) + (RowTurns(j, k) ? Dot6(dsk, Dl) : 0.0);
        }
        AddRows(j, dc, D + col, ld);
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
  /* the force elements' own entries: lambda_i = T Lambda_i' and e_i' (shift), the springs K */
  for (PetscInt i = 0; i < j->ne; i++) {
    const PetscInt fi = j->qoff + j->nc + i, ei = j->qoff + NumRows(j) + i;
    D[ld * fi + fi] += shift;
    D[ld * ei + ei] += shift;
    for (PetscInt l = 0; l < j->ne; l++) D[ld * fi + j->qoff + NumRows(j) + l] += j->K[j->ne * i + l];
    if (j->ntable) {
      PetscReal ft, dft;
      TableStepForce(j, i, ElementArg(j, i), &ft, &dft);
      D[ld * fi + ei] += dft;
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
  PetscReal dl[PHLEX_JOINT_MAX_ROWS], wk[6], w[2][6], wJ[6];

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < NumRows(j); k++) dl[k] = shift * x[j->qoff + k];
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
    PetscReal dy[6], rows[PHLEX_JOINT_MAX_ROWS];
    if (j->side[s].part != part) continue;
    PetscCall((*part->fieldops->portlinearsummed)(part, j->side[s].port, xu, au, xv, sums + s * PHLEX_PORT_SUMS, NULL, dy));
    PetscCall(RowsFromPortChange(j, s, dy, rows));
    AddRows(j, rows, y, 1);
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
      PetscReal rows[PHLEX_JOINT_MAX_ROWS];
      PetscCall(RowsFromPortChange(j, s, dy + 6 * col, rows));
      AddRows(j, rows, out + ld * col, 1);
    }
    PetscCall(PetscFree(dy));
  }
  PetscFunctionReturn(0);
}

/* a port wrench w as coefficients on the port's distribution vectors (its columns of W): (F, A^T T), A the port's
   rate map (PhlexPartOps.portrate) */
static void PortCoefficients(const PetscReal A[9], PetscReal w[6])
{
  const PetscReal T[3] = {w[3], w[4], w[5]};

  PhlexMatTVec3(A, T, w + 3);
}

/*@C
  PhlexJointBorderCoefficients - beta += the coefficients on the part's border basis W of the joint's columns (the
  field force of the joint wrench lies in the span of the port's distribution: exact)
@*/
PetscErrorCode PhlexJointBorderCoefficients(PhlexJoint j, PhlexPart part, PetscReal shift, PetscReal *beta, PetscInt ld)
{
  PetscReal wJ[6], A[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

  PetscFunctionBeginUser;
  JointWrench(j, j->lambda, NULL, wJ);
  for (PetscInt s = 0; s < 2; s++) {
    PetscInt c0;
    if (j->side[s].part != part) continue;
    PetscCall((*part->fieldops->portbasiscolumn)(part, j->side[s].port, &c0));
    if (c0 < 0) continue; /* no field force on this port (a frame patch) */
    if (part->ops.portrate) PetscCall((*part->ops.portrate)(part, j->side[s].port, NULL, A));
    for (PetscInt k = 0; k < NumRows(j); k++) {
      PetscReal e[PHLEX_JOINT_MAX_ROWS] = {0}, wk[6], w[2][6];
      e[k] = 1.0;
      JointWrench(j, e, NULL, wk);
      PortWrenches(j, wk, NULL, NULL, NULL, w[0], w[1]);
      PortCoefficients(A, w[s]);
      for (PetscInt c = 0; c < 6; c++) beta[c0 + c + ld * (j->qoff + k)] -= shift * w[s][c];
    }
    for (PetscInt t = 0; t < 2; t++) {
      PhlexPart p = j->side[t].part;
      if (PhlexPartIsGround(p) || p->frame.R < 0) continue;
      for (PetscInt m = 0; m < 9; m++) {
        PetscReal dRab[9], dG[9], w[2][6];
        WrenchesRDerivative(j, t, m, wJ, dRab, dG, w);
        PortCoefficients(A, w[s]);
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
      PetscReal *dq, dy[6], rows[PHLEX_JOINT_MAX_ROWS];
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

/* a universal's angles from the drawn configuration, E = Rot(e_a, t1) Rot(e_b0, t2) (a's joint frame; e_b0 = b's axis
   as drawn): t1 = atan2(E e_b0 . (e_a x e_b0), E e_b0 . e_b0), t2 = atan2(E^T e_a . (e_a x e_b0), E^T e_a . e_a); the
   rates of the torsion elements' rows (about e_a, and about b's axis as it turns) are their derivatives */
static PetscReal UniversalAngle(PhlexJoint j, const PetscReal E[9], PetscBool second)
{
  const PetscReal *ea = j->frame + 6;
  PetscReal        eb0[3], n[3], v[3];

  PhlexMatVec3(j->Rrel0, j->axis_b, eb0);
  PhlexCross(ea, eb0, n);
  if (!second) {
    PhlexMatVec3(E, eb0, v);
    return PetscAtan2Real(PhlexDot3(v, n), PhlexDot3(v, eb0));
  }
  PhlexMatTVec3(E, ea, v);
  return PetscAtan2Real(PhlexDot3(v, n), PhlexDot3(v, ea));
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
  if (j->nc) PetscCall(PetscViewerASCIIPrintf(viewer, "joint %s: %s between %s and %s, constrains %s", j->name, PhlexJointTypes[j->type], j->side[0].spec, j->side[1].spec, rows));
  else PetscCall(PetscViewerASCIIPrintf(viewer, "joint %s: %s between %s and %s", j->name, PhlexJointTypes[j->type], j->side[0].spec, j->side[1].spec));
  PetscCall(PetscViewerASCIIUseTabs(viewer, PETSC_FALSE)); /* the rest of the line: no indentation before each piece */
  if (j->ne) {
    char line[384] = "; force element on", more[160];
    for (PetscInt i = 0; i < j->ne; i++) {
      PetscCall(PetscStrlcat(line, " ", sizeof(line)));
      PetscCall(PetscStrlcat(line, j->erowname[i], sizeof(line)));
    }
    more[0] = 0;
    if (j->type == PHLEX_JOINT_SPRING_DAMPER && j->ntable && j->rest_length >= 0) PetscCall(PetscSNPrintf(more, sizeof(more), " (force table of %" PetscInt_FMT " points, c %.6g N s/m, rest length %.6g m)", j->ntable, (double)j->damping, (double)j->rest_length));
    else if (j->type == PHLEX_JOINT_SPRING_DAMPER && j->ntable) PetscCall(PetscSNPrintf(more, sizeof(more), " (force table of %" PetscInt_FMT " points, c %.6g N s/m, rest length as drawn)", j->ntable, (double)j->damping));
    else if (j->type == PHLEX_JOINT_SPRING_DAMPER && j->rest_length >= 0) PetscCall(PetscSNPrintf(more, sizeof(more), " (k %.6g N/m, c %.6g N s/m, rest length %.6g m)", (double)j->stiffness, (double)j->damping, (double)j->rest_length));
    else if (j->type == PHLEX_JOINT_SPRING_DAMPER) PetscCall(PetscSNPrintf(more, sizeof(more), " (k %.6g N/m, c %.6g N s/m, rest length as drawn)", (double)j->stiffness, (double)j->damping));
    else if (j->rot_element) PetscCall(PetscSNPrintf(more, sizeof(more), " (k %.6g N m/rad, c %.6g N m s/rad, rest angle %.6g deg)", (double)j->stiffness, (double)j->damping, (double)(j->rest_angle * 180.0 / PETSC_PI)));
    PetscCall(PetscStrlcat(line, more, sizeof(line)));
    if (j->slide_element) {
      PetscCall(PetscSNPrintf(more, sizeof(more), " (slide: k %.6g N/m, c %.6g N s/m, rest slide %.6g m)", (double)j->slide_stiffness, (double)j->slide_damping, (double)j->rest_slide));
      PetscCall(PetscStrlcat(line, more, sizeof(line)));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "%s", line));
    if (j->rest_profile) {
      char prof[PETSC_MAX_PATH_LEN + 512];
      PetscCall(PhlexProfileDescribe(j->rest_profile, prof, sizeof(prof)));
      PetscCall(PetscViewerASCIIPrintf(viewer, "; the rest %s times the profile %s", j->rot_element ? "angle" : "length", prof));
    }
  }
  if (j->drive_row >= 0) PetscCall(PetscViewerASCIIPrintf(viewer, " (%s driven at %.15g %s)", j->rowname[j->nc - 1], (double)j->drive_velocity, j->row[j->nc - 1] == PHLEX_ROW_R3 ? "rad/s" : "m/s"));
  if (j->rot_dropped) PetscCall(PetscViewerASCIIPrintf(viewer, "; rotations free (a point mass has no orientation)"));
  if (j->ndropped) {
    PetscCall(PetscViewerASCIIPrintf(viewer, "; redundant, dropped:"));
    for (PetscInt k = 0; k < j->ndropped; k++) PetscCall(PetscViewerASCIIPrintf(viewer, " %s", j->dropped[k]));
  }
  PetscCall(PetscViewerASCIIPrintf(viewer, "\n"));
  PetscCall(PetscViewerASCIIUseTabs(viewer, PETSC_TRUE));
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
  if (j->ne) {
    for (PetscInt i = 0; i < j->ne; i++) {
      char col[48];
      PetscCall(PetscSNPrintf(col, sizeof(col), ",state_%s,force_%s", j->erowname[i], j->erowname[i]));
      PetscCall(PetscStrlcat(header, col, sizeof(header)));
    }
    if (j->type == PHLEX_JOINT_SPRING_DAMPER) PetscCall(PetscStrlcat(header, ",length_minus_rest", sizeof(header)));
    if (j->type == PHLEX_JOINT_UNIVERSAL) PetscCall(PetscStrlcat(header, ",angle_a_minus_rest,angle_b_minus_rest", sizeof(header)));
    PetscCall(PetscStrlcat(header, ",stored_energy,dissipated_power,dissipated_work", sizeof(header)));
    if (j->rest_profile) PetscCall(PetscStrlcat(header, j->rot_element ? ",rest_angle,actuator_power,actuator_work" : ",rest_length,actuator_power,actuator_work", sizeof(header)));
  }
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_joint.csv", j->name));
  PetscCall(PhlexOutputCSVOpen(out, name, header, &j->csv));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointOutputStep - one row of the joint's series (SI): the multipliers lambda of the step and the power P
  through the joint over the step (non-dimensional, from the monitor: at the state where the scheme enforces the
  constraints), the relative motion and the violations at the state X; with force elements their states and forces, the
  stored energy at X (the joint evaluated at X), the power Dstep its dampers dissipated over the step and their work so
  far; returns the largest violation of the constraint rows and the largest error of the driven ones against their
  profiles (a drive's row, a prescribed motion's; SI: m or rad)

  Collective
@*/
PetscErrorCode PhlexJointOutputStep(PhlexJoint j, PetscReal t, const PetscReal *lambda, PetscReal P, PetscReal Dstep, PetscReal Astep, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal *gapmax, PetscReal *drivemax)
{
  const PhlexUnits *u = j->units;
  PetscReal         wJ[6], mo[6], gap[7], r;
  PetscInt          nm;

  PetscFunctionBeginUser;
  JointWrench(j, lambda, NULL, wJ);
  PetscCall(PhlexJointRelativeMotion(j, Xa, Xb, mo, &nm));
  PetscCall(PhlexJointGap(j, t, Xa, Xb, gap));
  *gapmax = *drivemax = 0.0;
  for (PetscInt k = 0; k < j->nc; k++) {
    const PetscReal g     = PetscAbsReal(gap[k]) * (j->row[k] <= PHLEX_ROW_T3 ? u->length : 1.0);
    const PetscBool drive = (PetscBool)(j->type == PHLEX_JOINT_PRESCRIBED || (j->drive_row >= 0 && k == j->nc - 1));
    if (drive) *drivemax = PetscMax(*drivemax, g);
    else *gapmax = PetscMax(*gapmax, g);
  }
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
  PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)(P * u->power)));
  if (j->ne) {
    PetscReal V = 0.0, a[6];
    PetscCall(RestShift(j, t, &r)); /* the states are relative to the nominal rest; the spring acts on a = e - r(t) */
    for (PetscInt i = 0; i < j->ne; i++) a[i] = j->e[i] - (i == 0 ? r : 0.0);
    for (PetscInt i = 0; i < j->ne; i++) {
      const PetscBool length = j->erow[i] <= PHLEX_ROW_T3 ? PETSC_TRUE : PETSC_FALSE;
      PetscCall(PhlexCSVPrintf(j->csv, ",%.12e,%.12e", (double)(length ? j->e[i] * u->length : j->e[i]), (double)(lambda[j->nc + i] * u->force * (length ? 1.0 : u->length))));
      for (PetscInt l = 0; l < j->ne; l++) V += 0.5 * a[i] * j->K[j->ne * i + l] * a[l];
    }
    if (j->ntable) V += TablePotential(j, a[0]);
    if (j->type == PHLEX_JOINT_SPRING_DAMPER) {
      PetscReal dx[3], E[9];
      PetscCall(Placements(j, Xa, Xb, dx, E));
      PetscCall(PhlexCSVPrintf(j->csv, ",%.12e", (double)((PhlexNorm3(dx) - r) * u->length - j->rest_length)));
    }
    if (j->type == PHLEX_JOINT_UNIVERSAL) {
      /* the geometric angles of the universal, to compare with the torsion elements' states */
      PetscReal dx[3], E[9];
      PetscCall(Placements(j, Xa, Xb, dx, E));
      PetscCall(PhlexCSVPrintf(j->csv, ",%.12e,%.12e", (double)(UniversalAngle(j, E, PETSC_FALSE) - j->rest_angle), (double)(UniversalAngle(j, E, PETSC_TRUE) - j->rest_angle)));
    }
    PetscCall(PhlexCSVPrintf(j->csv, ",%.12e,%.12e,%.12e", (double)(V * u->energy), (double)(Dstep * u->power), (double)(j->dissipated_work * u->energy)));
    if (j->rest_profile) PetscCall(PhlexCSVPrintf(j->csv, ",%.12e,%.12e,%.12e", (double)(j->rot_element ? j->rest_angle + r : (RestNominal(j) + r) * u->length), (double)(Astep * u->power), (double)(j->actuator_work * u->energy)));
  }
  PetscCall(PhlexCSVPrintf(j->csv, "\n"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexJointElementInitial - the initial states of the joint's force elements from the placements of its ports: the
  spring-damper's length minus its rest length, the torsion spring's angle minus its rest angle, the bushing's
  relative displacement and rotation vector in its joint frame (non-dimensional)

  Collective
@*/
PetscErrorCode PhlexJointElementInitial(PhlexJoint j, const PhlexPartVec *Xa, const PhlexPartVec *Xb, PetscReal e0[6])
{
  PetscReal dx[3], E[9], phi[3];

  PetscFunctionBeginUser;
  if (!j->ne) PetscFunctionReturn(0);
  PetscCall(Placements(j, Xa, Xb, dx, E));
  PhlexRotationVector(E, phi);
  for (PetscInt i = 0; i < j->ne; i++) {
    const PhlexJointRow r = j->erow[i];
    if (j->type == PHLEX_JOINT_SPRING_DAMPER) e0[i] = PhlexNorm3(dx) - j->rest_length / j->units->length;
    else if (j->rot_element && j->type == PHLEX_JOINT_UNIVERSAL) e0[i] = UniversalAngle(j, E, r == PHLEX_ROW_AXIS_B) - j->rest_angle;
    else if (j->rot_element && r == PHLEX_ROW_R3) e0[i] = AngleAboutAxis(j, E) - j->rest_angle;
    else if (j->slide_element && j->type != PHLEX_JOINT_BUSHING && r == PHLEX_ROW_T3) e0[i] = PhlexDot3(j->frame + 6, dx) - j->rest_slide / j->units->length;
    else if (r <= PHLEX_ROW_T3) e0[i] = PhlexDot3(j->frame + 3 * (r - PHLEX_ROW_T1), dx);
    else e0[i] = PhlexDot3(j->frame + 3 * (r - PHLEX_ROW_R1), phi);
  }
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
  PetscCall(PhlexProfileDestroy(&(*joint)->rest_profile));
  PetscCall(PetscViewerDestroy(&(*joint)->csv));
  PetscCall(PetscFree(*joint));
  PetscFunctionReturn(0);
}
