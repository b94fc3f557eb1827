/* Joints: transformer interconnections of two ports at velocity level (paper Section 5, DESIGN section 3).

   A joint between port a (of part A) and port b (of part B, or the ground) constrains the velocity of b relative
   to a, Delta = R_ab y~_b - G y~_a (a's body frame; R_ab = R_a^T R_b, G = R_a^T R_a, y~ = the port output moved to the
   joint point),
   along directions s_k fixed in a's joint frame:
       c_k = s_k . Delta - g_k(t) = 0          (g = 0 for a workless joint; a prescribed motion otherwise)
   Its impulses Lambda_k are unknowns; their rates lambda_k are the multipliers. They enter the two parts through the
   same port distributions as wrenches, w_a = -T_a^T G S lambda on port a and w_b = T_b^T R_ab^T S lambda on port b, so
   that w_a . y_a + w_b . y_b = lambda . (c + g): the interconnection is power preserving (lossless for g = 0). */
#ifndef PHLEX_PRIVATE_JOINT_H
#define PHLEX_PRIVATE_JOINT_H

typedef enum {
  PHLEX_JOINT_FIXED,
  PHLEX_JOINT_REVOLUTE,
  PHLEX_JOINT_SPHERICAL,
  PHLEX_JOINT_PRISMATIC,
  PHLEX_JOINT_CYLINDRICAL,
  PHLEX_JOINT_UNIVERSAL,
  PHLEX_JOINT_PLANAR,
  PHLEX_JOINT_PRESCRIBED
} PhlexJointType;
PETSC_EXTERN const char *const PhlexJointTypes[];

/* Generalized directions of a joint row in a's joint frame (e1, e2, e3 = axis). */
typedef enum {
  PHLEX_ROW_T1, PHLEX_ROW_T2, PHLEX_ROW_T3, /* translation of the joint point along e1, e2, e3 */
  PHLEX_ROW_R1, PHLEX_ROW_R2, PHLEX_ROW_R3, /* rotation about e1, e2, e3 */
  PHLEX_ROW_CROSS                           /* universal: rotation about e_a x e_b (both axes rotate with their bodies) */
} PhlexJointRow;

typedef struct {
  char      spec[2 * PHLEX_NAME_LEN + 2]; /* "body:port" or "ground" as given */
  PhlexPart part;                         /* the ground part for the ground */
  PetscInt  port;                         /* port index, -1 for the ground */
  PetscReal offset[3];                    /* joint point relative to the port point, port frame (ground: the inertial point) */
  PetscReal arm[3];                       /* the offset in the body frame: turned by the port's own rotation relative to
                                             the body frame (a flexible port's mean rotation), held over a step (PhlexJointUpdateGeometry) */
  PetscBool rotation;                     /* the side has an orientation (not a point mass, not the ground... ground: yes) */
} PhlexJointSide;

struct _p_PhlexJoint {
  MPI_Comm       comm;
  const PhlexUnits *units; /* the scene's reference scales */
  PetscInt       index;
  char           prefix[32];
  char           name[PHLEX_NAME_LEN];
  char           ports_option[48]; /* the option that named its ports (-joint<k>_ports, or -body<k>_attach) */
  PhlexJointType type;
  PhlexJointSide side[2];

  /* scene input (SI, inertial frame at the drawn configuration) */
  PetscReal axis[3], axis2[3], reference[3], position[3];
  PetscBool axis_given, axis2_given, reference_given, position_given;

  /* constraint rows */
  PetscInt      nc;        /* rows kept */
  PhlexJointRow row[7];
  char          rowname[7][8];
  PetscReal     frame[9];  /* rows e1, e2, e3 of a's joint frame, in a's port frame */
  PetscReal     axis_b[3]; /* universal: second axis in b's port frame */
  PetscReal     dir[9];    /* e1, e2, e3 in a's body frame and */
  PetscReal     eb[3];     /* the second axis in b's body frame, held over a step (PhlexJointUpdateGeometry) */
  PetscReal     Rrel0[9];  /* R~_a^T R~_b at the drawn configuration (port orientations) */
  PetscInt      ndropped;  /* rows removed as redundant */
  char          dropped[7][8];

  /* prescribed motion */
  PetscInt     drive_row;      /* row index of a drive (-1: none) */
  PetscReal    drive_velocity; /* SI (rad/s or m/s) amplitude */
  PetscReal    drive_initial;  /* initial angle [rad] or slide [m] relative to the drawn configuration */
  PhlexProfile drive_profile;
  PetscReal    presc_velocity[3], presc_angular[3]; /* prescribed port velocity (inertial, SI) */
  PetscBool    presc_v, presc_w;

  /* placement among the discrete unknowns (system) */
  PetscInt qoff;

  /* evaluated */
  PetscReal ya[6], yb[6]; /* port outputs moved to the joint point (body frames) */
  PetscReal Ra[9], Rb[9], Rab[9], G[9]; /* G = R_a^T R_a (the identity but at a step's midpoint) */
  PetscReal lambda[7];
  PetscReal c[7];

  /* output */
  PetscViewer csv;
  char        motion_names[6][16];
  PetscInt    nmotion;
  PetscReal   max_gap;    /* largest position-level violation so far (non-dimensional) */
  PetscBool   rot_dropped; /* rotation components dropped: a side is a point mass */
};

PETSC_INTERN PetscErrorCode PhlexJointResolve(PhlexJoint, PetscInt, const PhlexPart[], PhlexPart);
PETSC_INTERN PetscErrorCode PhlexJointSetUp(PhlexJoint, const PhlexPartVec *, const PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexJointUpdateGeometry(PhlexJoint, const PhlexPartVec *, const PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexJointEvaluate(PhlexJoint, PetscReal, const PetscReal *, const PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointApplyWrenches(PhlexJoint);
PETSC_INTERN PetscErrorCode PhlexJointResidual(PhlexJoint, PetscReal, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointJacobian(PhlexJoint, PetscReal, PetscReal *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexJointBorderMult(PhlexJoint, PetscReal, const PetscReal *, PhlexPart, Vec);
/* the field products of a joint's two sides on one part (PhlexJointBorderMultTransposeLocal) */
#define PHLEX_JOINT_BORDER_SUMS (2 * PHLEX_PORT_SUMS)
PETSC_INTERN PetscErrorCode PhlexJointBorderMultTransposeLocal(PhlexJoint, PhlexPart, Vec, PetscReal, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointBorderMultTransposeSummed(PhlexJoint, PhlexPart, Vec, PetscReal, Vec, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointBorderRows(PhlexJoint, PhlexPart, Mat, PetscReal, PetscReal *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexJointBorderCoefficients(PhlexJoint, PhlexPart, PetscReal, PetscReal *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexJointDrivePosition(PhlexJoint, PetscReal, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointGap(PhlexJoint, PetscReal, const PhlexPartVec *, const PhlexPartVec *, PetscReal[7]);
PETSC_INTERN PetscErrorCode PhlexJointRelativeMotion(PhlexJoint, const PhlexPartVec *, const PhlexPartVec *, PetscReal[6], PetscInt *);
PETSC_INTERN PetscErrorCode PhlexJointRigidGradient(PhlexJoint, PetscReal *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexJointDropRow(PhlexJoint, PetscInt);
PETSC_INTERN PetscErrorCode PhlexJointOutputOpen(PhlexJoint, PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexJointOutputStep(PhlexJoint, PetscReal, const PetscReal *, PetscReal, const PhlexPartVec *, const PhlexPartVec *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointPower(PhlexJoint, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointSourcePower(PhlexJoint, PetscReal, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointDissipation(PhlexJoint, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointOutputClose(PhlexJoint);
PETSC_INTERN PetscBool      PhlexJointTouches(PhlexJoint, PhlexPart);

#endif
