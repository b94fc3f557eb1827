/* Rotation algebra and 3x3 helpers of moving frames and joints (paper Section 3: R stored row-wise, R' = R [w]x).
   Pure functions on arrays: no PETSc objects. Matrices are row-major 3x3. */
#include <phlex_impl.h>

/* c = a x b */
void PhlexCross(const PetscReal a[3], const PetscReal b[3], PetscReal c[3])
{
  const PetscReal c0 = a[1] * b[2] - a[2] * b[1], c1 = a[2] * b[0] - a[0] * b[2], c2 = a[0] * b[1] - a[1] * b[0];
  c[0] = c0;
  c[1] = c1;
  c[2] = c2;
}

PetscReal PhlexDot3(const PetscReal a[3], const PetscReal b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

PetscReal PhlexNorm3(const PetscReal a[3])
{
  return PetscSqrtReal(PhlexDot3(a, a));
}

/* S = [a]x, the matrix with S b = a x b */
void PhlexSkew(const PetscReal a[3], PetscReal S[9])
{
  S[0] = 0;
  S[1] = -a[2];
  S[2] = a[1];
  S[3] = a[2];
  S[4] = 0;
  S[5] = -a[0];
  S[6] = -a[1];
  S[7] = a[0];
  S[8] = 0;
}

/* y = A x (y may alias x) */
void PhlexMatVec3(const PetscReal A[9], const PetscReal x[3], PetscReal y[3])
{
  const PetscReal y0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2], y1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2], y2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
  y[0] = y0;
  y[1] = y1;
  y[2] = y2;
}

/* y = A^T x (y may alias x) */
void PhlexMatTVec3(const PetscReal A[9], const PetscReal x[3], PetscReal y[3])
{
  const PetscReal y0 = A[0] * x[0] + A[3] * x[1] + A[6] * x[2], y1 = A[1] * x[0] + A[4] * x[1] + A[7] * x[2], y2 = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
  y[0] = y0;
  y[1] = y1;
  y[2] = y2;
}

/* C = A B (C must not alias A or B) */
void PhlexMatMat3(const PetscReal A[9], const PetscReal B[9], PetscReal C[9])
{
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* C = A^T B (C must not alias A or B) */
void PhlexMatTMat3(const PetscReal A[9], const PetscReal B[9], PetscReal C[9])
{
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
}

/* C = A B^T (C must not alias A or B) */
void PhlexMatMatT3(const PetscReal A[9], const PetscReal B[9], PetscReal C[9])
{
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
}

/* ||R^T R - I||_F */
PetscReal PhlexOrthogonalityError(const PetscReal R[9])
{
  PetscReal e = 0;

  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) {
      const PetscReal d = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j] - (i == j ? 1.0 : 0.0);
      e += d * d;
    }
  return PetscSqrtReal(e);
}

/* Nearest rotation to a nearly orthogonal R (orthogonal polar factor) by Newton-Schulz steps
   R <- R (3 I - R^T R) / 2, quadratically convergent for ||R^T R - I|| < 1 */
void PhlexOrthonormalize(PetscReal R[9])
{
  for (PetscInt it = 0; it < 4 && PhlexOrthogonalityError(R) > 10 * PETSC_MACHINE_EPSILON; it++) {
    PetscReal A[9], N[9];
    for (PetscInt i = 0; i < 3; i++)
      for (PetscInt j = 0; j < 3; j++) A[3 * i + j] = 0.5 * ((i == j ? 3.0 : 0.0) - (R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j]));
    PhlexMatMat3(R, A, N);
    for (PetscInt k = 0; k < 9; k++) R[k] = N[k];
  }
}

/* Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method); w >= 0 */
void PhlexRotationToQuaternion(const PetscReal R[9], PetscReal q[4])
{
  const PetscReal tr = R[0] + R[4] + R[8];
  PetscReal       n;

  if (tr > R[0] && tr > R[4] && tr > R[8]) {
    const PetscReal s = 2.0 * PetscSqrtReal(1.0 + tr);
    q[0]              = 0.25 * s;
    q[1]              = (R[7] - R[5]) / s;
    q[2]              = (R[2] - R[6]) / s;
    q[3]              = (R[3] - R[1]) / s;
  } else if (R[0] >= R[4] && R[0] >= R[8]) {
    const PetscReal s = 2.0 * PetscSqrtReal(1.0 + R[0] - R[4] - R[8]);
    q[0]              = (R[7] - R[5]) / s;
    q[1]              = 0.25 * s;
    q[2]              = (R[1] + R[3]) / s;
    q[3]              = (R[2] + R[6]) / s;
  } else if (R[4] >= R[8]) {
    const PetscReal s = 2.0 * PetscSqrtReal(1.0 + R[4] - R[0] - R[8]);
    q[0]              = (R[2] - R[6]) / s;
    q[1]              = (R[1] + R[3]) / s;
    q[2]              = 0.25 * s;
    q[3]              = (R[5] + R[7]) / s;
  } else {
    const PetscReal s = 2.0 * PetscSqrtReal(1.0 + R[8] - R[0] - R[4]);
    q[0]              = (R[3] - R[1]) / s;
    q[1]              = (R[2] + R[6]) / s;
    q[2]              = (R[5] + R[7]) / s;
    q[3]              = 0.25 * s;
  }
  if (q[0] < 0)
    for (PetscInt k = 0; k < 4; k++) q[k] = -q[k];
  n = PetscSqrtReal(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (PetscInt k = 0; k < 4; k++) q[k] /= n;
}

/* Rotation matrix of a quaternion (w, x, y, z), normalised first */
void PhlexQuaternionToRotation(const PetscReal qin[4], PetscReal R[9])
{
  const PetscReal n = PetscSqrtReal(qin[0] * qin[0] + qin[1] * qin[1] + qin[2] * qin[2] + qin[3] * qin[3]);
  const PetscReal w = qin[0] / n, x = qin[1] / n, y = qin[2] / n, z = qin[3] / n;

  R[0] = 1 - 2 * (y * y + z * z);
  R[1] = 2 * (x * y - w * z);
  R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z);
  R[4] = 1 - 2 * (x * x + z * z);
  R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y);
  R[7] = 2 * (y * z + w * x);
  R[8] = 1 - 2 * (x * x + y * y);
}

/* Rotation of an axis (normalised) and an angle [rad] */
void PhlexAxisAngleToRotation(const PetscReal axis[3], PetscReal angle, PetscReal R[9])
{
  const PetscReal n = PetscSqrtReal(PhlexDot3(axis, axis));
  PetscReal       q[4];

  q[0] = PetscCosReal(0.5 * angle);
  for (PetscInt k = 0; k < 3; k++) q[1 + k] = (n > 0 ? axis[k] / n : 0.0) * PetscSinReal(0.5 * angle);
  PhlexQuaternionToRotation(q, R);
}

/* Rotation vector phi (axis times angle in [0, pi]) of a rotation matrix: R = exp([phi]x) */
void PhlexRotationVector(const PetscReal R[9], PetscReal phi[3])
{
  PetscReal q[4], s, angle;

  PhlexRotationToQuaternion(R, q); /* w >= 0: angle in [0, pi] */
  s     = PetscSqrtReal(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  angle = 2.0 * PetscAtan2Real(s, q[0]);
  for (PetscInt k = 0; k < 3; k++) phi[k] = s > 0 ? q[1 + k] / s * angle : 2.0 * q[1 + k]; /* small angles: 2 q_v */
}

/* The left Jacobian of SO(3) at the rotation vector theta: d/dt exp([theta]x) = [J_l(theta) theta']x exp([theta]x),
   J_l = I + (1 - cos a)/a^2 [theta]x + (a - sin a)/a^3 [theta]x^2 (a = |theta|), the first coefficient as
   2 sin^2(a/2)/a^2 (1 - cos a cancels); below a = 1e-2 both by their series to a^4 (error below 1e-15: a - sin a
   cancels to 1e-11 relative there). exp(theta) turns with the angular velocity J_l theta' in the frame it
   is applied in (a flexible port's orientation R exp(theta): w + J_l theta' in the body frame) */
void PhlexLeftJacobian(const PetscReal theta[3], PetscReal J[9])
{
  const PetscReal a = PhlexNorm3(theta);
  PetscReal       S[9], S2[9], c1, c2;

  if (a < 1e-2) {
    const PetscReal a2 = a * a;
    c1 = 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
    c2 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0;
  } else {
    const PetscReal s = PetscSinReal(0.5 * a);
    c1 = 2.0 * s * s / (a * a);
    c2 = (a - PetscSinReal(a)) / (a * a * a);
  }
  PhlexSkew(theta, S);
  PhlexMatMat3(S, S, S2);
  for (PetscInt k = 0; k < 9; k++) J[k] = (k % 4 == 0 ? 1.0 : 0.0) + c1 * S[k] + c2 * S2[k];
}

/* R <- R exp([theta]x): a rotation by the body-frame rotation vector theta (assembly and drift corrections) */
void PhlexRotationUpdate(PetscReal R[9], const PetscReal theta[3])
{
  PetscReal E[9], N[9], a = PhlexNorm3(theta);

  PhlexAxisAngleToRotation(a > 0 ? theta : (PetscReal[3]){1, 0, 0}, a, E);
  PhlexMatMat3(R, E, N);
  for (PetscInt k = 0; k < 9; k++) R[k] = N[k];
  PhlexOrthonormalize(R);
}

/* An orthonormal frame (rows e1, e2, e3) with e3 along 'axis' and e1 along the part of 'reference' orthogonal to it
   (reference NULL or parallel to the axis: the coordinate axis least aligned with e3) */
void PhlexCompleteFrame(const PetscReal axis[3], const PetscReal *reference, PetscReal F[9])
{
  PetscReal e3[3], e1[3], e2[3], n = PhlexNorm3(axis), r[3], d, rn;

  for (PetscInt k = 0; k < 3; k++) e3[k] = axis[k] / n;
  rn = 0;
  if (reference) {
    d = PhlexDot3(reference, e3);
    for (PetscInt k = 0; k < 3; k++) r[k] = reference[k] - d * e3[k];
    rn = PhlexNorm3(r);
  }
  if (!reference || rn < 1e-8 * PhlexNorm3(reference)) {
    PetscInt  imin = 0;
    PetscReal amin = PetscAbsReal(e3[0]);
    for (PetscInt k = 1; k < 3; k++)
      if (PetscAbsReal(e3[k]) < amin - 1e-12) {
        amin = PetscAbsReal(e3[k]);
        imin = k;
      }
    for (PetscInt k = 0; k < 3; k++) r[k] = (k == imin ? 1.0 : 0.0) - e3[imin] * e3[k];
    rn = PhlexNorm3(r);
  }
  for (PetscInt k = 0; k < 3; k++) e1[k] = r[k] / rn;
  PhlexCross(e3, e1, e2);
  for (PetscInt k = 0; k < 3; k++) {
    F[k]     = e1[k];
    F[3 + k] = e2[k];
    F[6 + k] = e3[k];
  }
}
