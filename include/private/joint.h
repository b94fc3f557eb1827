/* Joints: transformer interconnections of two ports at velocity level (paper Section 5, DESIGN section 3).

   A joint between port a (of part A) and port b (of part B, or the ground) constrains the velocity of b relative
   to a, Delta = R_ab y~_b - G y~_a (a's body frame; R_ab = R_a^T R_b, G = R_a^T R_a, y~ = the port output moved to the
   joint point),
   along directions s_k fixed in a's joint frame:
       c_k = s_k . Delta - g_k(t) = 0          (g = 0 for a workless joint; a prescribed motion otherwise)
   Its impulses Lambda_k are unknowns; their rates lambda_k are the multipliers. They enter the two parts through the
   same port distributions as wrenches, w_a = -T_a^T G S lambda on port a and w_b = T_b^T R_ab^T S lambda on port b, so
   that w_a . y_a + w_b . y_b = lambda . (c + g): the interconnection is power preserving (lossless for g = 0).
   A flexible port's output is the exact rate of its orientation R exp(theta) (theta its patch-averaged rotation):
   w + J_l(theta) B_r^T v, J_l the left Jacobian of SO(3) held over the step, and its distribution the transpose,
   B_r J_l^T T (PhlexPartOps.portrate, refreshed with the joint frames in PhlexJointUpdateGeometry); with the
   first-order rate w + B_r^T v a joint on a whirling port opens by the geometric phase 1/2 oint theta x dtheta.

   Force elements (issue 45): a joint may also have ne compliant rows s_i (after its nc constraint rows), each a
   small pH system with a state e_i (elongation, angle, relative displacement or rotation; unknown kind
   PHLEX_DOF_ELEMENT) and a force impulse (kind PHLEX_DOF_ELEMENT_FORCE) whose rate lambda_i acts on the ports like a
   multiplier:
       e_i'      = s_i . Delta                              (the element's state follows its ports)
       lambda_i  = -(K e + C S_e^T Delta)_i                 (the element's force on b along s_i)
   stored energy V = 1/2 e^T K e, dissipated power D = (S_e^T Delta)^T C (S_e^T Delta) >= 0 (K, C symmetric
   positive semi-definite). With the implicit midpoint rule V_{n+1} - V_n = dt e_mid^T K e' exactly, so the
   balance H_{n+1} - H_n = dt (P - D) holds to solver tolerance with V in H. The unknowns of a joint: nc constraint
   impulses, ne force impulses, ne states (qoff, qoff + nc, qoff + nc + ne).

   A moving rest (an actuator: a spring_damper's rest length or a torsion spring's rest angle following a profile,
   rest(t) = rest f(t)): the spring acts on a = e - r(t), r(t) = rest(t) - rest, V = 1/2 K a^2, so the actuator supplies
   the power -K a r'(t). With the midpoint rule the stage takes r's mean over the step, (r_n + r_{n+1})/2: then
   V_{n+1} - V_n = K a_mid ((e_{n+1} - e_n) - (r_{n+1} - r_n)) exactly, the port power takes the first term and the
   actuator's work over the step is -K a_mid (r_{n+1} - r_n), so the balance still holds to solver tolerance. */
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
  PHLEX_JOINT_PRESCRIBED,
  PHLEX_JOINT_SPRING_DAMPER, /* force element: a translational spring-damper between the two port points */
  PHLEX_JOINT_BUSHING        /* force element: six compliant rows (6 x 6 stiffness and damping in the joint frame) */
} PhlexJointType;
PETSC_EXTERN const char *const PhlexJointTypes[];

/* Generalized directions of a joint row in a's joint frame (e1, e2, e3 = axis). */
typedef enum {
  PHLEX_ROW_T1, PHLEX_ROW_T2, PHLEX_ROW_T3, /* translation of the joint point along e1, e2, e3 */
  PHLEX_ROW_R1, PHLEX_ROW_R2, PHLEX_ROW_R3, /* rotation about e1, e2, e3 */
  PHLEX_ROW_CROSS,                          /* universal: rotation about e_a x e_b (both axes rotate with their bodies) */
  PHLEX_ROW_AXIS_B                          /* universal's torsion element: rotation about e_b (it turns with b) */
} PhlexJointRow;

#define PHLEX_JOINT_MAX_ROWS 13 /* 7 constraint rows and 6 element rows */

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
  PetscReal lambda[PHLEX_JOINT_MAX_ROWS]; /* constraint multipliers, then the elements' forces */
  PetscReal c[7];

  /* force elements: compliant rows (non-dimensional K, C: ne x ne, row-major, in the element rows' order) */
  PetscInt      ne;
  PhlexJointRow erow[6];
  char          erowname[6][8];
  PetscReal     Ksi[36], Csi[36];       /* bushing: the matrices as given (SI, rows/columns t1 t2 t3 r1 r2 r3) */
  PetscBool     Kgiven, Cgiven;
  PetscReal     stiffness, damping;     /* spring-damper (N/m, N s/m) or rotational (N m/rad, N m s/rad), SI */
  PetscBool     rot_element;            /* revolute, cylindrical, universal: the free rotation(s) a spring-damper */
  PetscBool     slide_element;          /* prismatic, cylindrical: the slide is a spring-damper */
  PetscReal     slide_stiffness, slide_damping, rest_slide; /* its N/m, N s/m and zero-force slide [m], SI */
  PetscReal     rest_length, rest_angle; /* spring-damper [m] (<0: the drawn length); rotational [rad] */
  PetscReal     K[36], C[36];
  PetscReal     e[6], edot[6];          /* evaluated: states and their rates (non-dimensional time) */
  PetscReal     dissipated_work;        /* the energy the element dissipated so far (non-dimensional; the monitor) */
  PetscInt      ntable;                 /* spring_damper: a force-elongation table (0: linear, K) */
  PetscReal     table_e[64], table_f[64]; /* its points (SI as given; non-dimensional after set-up) */
  PetscBool     dg;                     /* the table's force is the discrete gradient over the step (implicit midpoint) */
  PetscReal     e_start[6];             /* the states at the step's start (the discrete gradient's e_n) */
  PhlexProfile  rest_profile;           /* a moving rest: spring_damper L(t) = rest_length f(t), torsion spring
                                           rest_angle f(t) (NULL: fixed); the state e stays relative to the nominal
                                           rest, the spring acts on e - (rest(t) - rest) */
  PetscBool     rest_step;              /* a midpoint step from rest_t0 is under way: its stage takes the mean of the
                                           rest's change at the step's two ends (PhlexJointElementStepStart) */
  PetscReal     rest_t0;
  PetscBool     drive_step;             /* a midpoint step from drive_t0 is under way: a drive's (or a prescribed
                                           motion's) rate at its stage makes the step's increment the prescribed one */
  PetscReal     drive_t0, drive_dt;
  PetscBool     drive_start;            /* the consistent start: the first step's stage rate (drive_dt), whatever t */
  PetscReal     eshift;                 /* evaluated: the rest's change from the nominal (non-dimensional) */
  PetscReal     actuator_work;          /* the work the moving rest did on the element so far (non-dimensional) */

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
PETSC_INTERN PetscErrorCode PhlexJointOutputStep(PhlexJoint, PetscReal, const PetscReal *, PetscReal, PetscReal, PetscReal, const PhlexPartVec *, const PhlexPartVec *, PetscReal *, PetscReal *);
PETSC_INTERN PetscInt       PhlexJointNumUnknowns(PhlexJoint);
PETSC_INTERN PetscBool      PhlexJointDamped(PhlexJoint);
PETSC_INTERN PetscErrorCode PhlexJointElementInitial(PhlexJoint, const PhlexPartVec *, const PhlexPartVec *, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexJointElementEnergy(PhlexJoint, PetscReal, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointElementStepStart(PhlexJoint, PetscReal, const PetscReal *, PetscBool, PetscBool);
PETSC_INTERN PetscErrorCode PhlexJointDriveStepStart(PhlexJoint, PetscReal, PetscReal, PetscBool, PetscBool);
PETSC_INTERN PetscErrorCode PhlexJointActuatorPower(PhlexJoint, PetscReal, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointPortWrench(PhlexJoint, const PetscReal *, PhlexPart, PetscInt, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexJointPower(PhlexJoint, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointSourcePower(PhlexJoint, PetscReal, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointDissipation(PhlexJoint, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexJointOutputClose(PhlexJoint);
PETSC_INTERN PetscBool      PhlexJointTouches(PhlexJoint, PhlexPart);

#endif
