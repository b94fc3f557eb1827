/* The part contract (DESIGN section 3): every part of a mechanism -- flexible FE body (fixed or floating), rigid
   body, lumped mass, ground, reduced (modal) body -- implements a core table of operations (PhlexPartOps); a part
   with field unknowns adds the field table (PhlexPartFieldOps), a part with analyses of its own the analysis table
   (PhlexPartAnalysisOps), as PETSc objects compose their ops. The system, the joints, the integrator and the outputs
   call parts only through these tables; none of them knows what kind a part is.

   Unknowns of a part, in the global vector (system.c):
     field blocks   u (displacement), Sigma (stress), v (velocity): distributed over all ranks, flexible bodies only;
     discrete ones  q: a few unknowns (rigid frame, lumped position, internal multipliers, modal coordinates), on
                    rank 0 in the global vector and handed to the part on every rank.
   A part's residual rows are those of its unknowns. Its coupling to other parts goes through its ports: the velocity
   of a port (its collocated output y = (translational velocity of the port point, angular velocity), body frame
   components) and the distribution of a wrench w = (force, moment about the port point, body frame) over the part's
   equations, which is the transpose of the output map (power w . y, paper Section 5). Joints set the wrenches.

   All quantities are non-dimensional (PhlexUnits) except rates handed to evaluate/residual: time derivatives are in
   SI time (TS); a part multiplies them by units->time. */
#ifndef PHLEX_PRIVATE_PART_H
#define PHLEX_PRIVATE_PART_H

#define PHLEX_NAME_LEN 64

/* Fields of the global unknown vector, each contiguous on every rank. */
typedef enum {
  PHLEX_FIELD_DISPLACEMENT,
  PHLEX_FIELD_STRESS,
  PHLEX_FIELD_VELOCITY,
  PHLEX_FIELD_DISCRETE, /* rigid states, lumped states, multiplier impulses of joints and internal constraints */
  PHLEX_NUM_FIELDS
} PhlexField;
PETSC_EXTERN const char *const PhlexFieldNames[];

/* What a discrete unknown is: checkpoints name it, adaptive steps leave impulses out of the error norm, the
   consistent start replaces velocities (a frame's and elastic ones) only, the redundancy check and the loop closure
   move frames only (configuration and velocity of a frame), the linearised analysis keeps velocities (elastic ones
   too) and impulses and eliminates elastic coordinates onto their velocities (their stiffness). Elastic coordinates (a reduced body's eta, u = Phi eta) and their velocities (zeta) are a body's
   deformation, not its frame's motion. */
typedef enum {
  PHLEX_DOF_CONFIGURATION,   /* a frame's position and rotation, a point mass's position */
  PHLEX_DOF_VELOCITY,        /* a frame's or point mass's velocity */
  PHLEX_DOF_IMPULSE,         /* a multiplier's impulse */
  PHLEX_DOF_ELASTIC,         /* an elastic coordinate (non-dimensional displacement) */
  PHLEX_DOF_ELASTIC_VELOCITY, /* its rate: a part's n-th elastic velocity is the rate of its n-th elastic coordinate */
  PHLEX_DOF_ELEMENT,          /* a force element's state (elongation, angle): not a constraint, not a frame's motion */
  PHLEX_DOF_ELEMENT_FORCE     /* a force element's force impulse: its rate is the element's force, like a multiplier's */
} PhlexDofKind;

/* the unknowns whose rate is a force on the ports (a multiplier or a force element's force) */
static inline PetscBool PhlexDofIsImpulse(PhlexDofKind kind)
{
  return (kind == PHLEX_DOF_IMPULSE || kind == PHLEX_DOF_ELEMENT_FORCE) ? PETSC_TRUE : PETSC_FALSE;
}

/* Offsets of a moving frame's unknowns among a part's discrete unknowns (-1: absent): position r of the frame
   origin P (inertial), rotation R (row-wise, body to inertial), velocity v_P and angular velocity w (body frame). */
typedef struct {
  PetscInt r, R, v, w;
} PhlexFrameIndex;

/* A part's view of a global vector: its field blocks and its discrete unknowns (an array valid on every rank).
   p, when set (state vectors handed to residual by SNES phlexreduced), is the stress resultant G^T Sigma in velocity
   space: the displacement and the stress are eliminated by the caller, and residual writes the velocity and discrete
   rows only, with p in place of G^T s. */
typedef struct {
  Vec        u, s, v;
  PetscReal *q;
  Vec        p;
} PhlexPartVec;

/* Matrices of a part's field blocks, referenced by the system's Jacobian (owned and updated by the part). */
typedef struct {
  Mat      G, Gt;    /* coupling (stress rows x velocity columns) and its transpose, or NULL when constant (the system
                        transposes G if it needs G^T assembled) */
  Mat      Ms;       /* compliance mass, block diagonal per cell */
  Mat      B, Res;   /* stress rate B = Ms^{-1} G (stress rows) and stress resultant G^T (velocity rows) as products
                        cell by cell (shells, nothing stored), or NULL (geometric stiffening: G(u) is assembled) */
  Mat      Kc;       /* the condensed stiffness G^T Ms^{-1} G as a product cell by cell (shell), or NULL like B */
  PetscInt stress_bs; /* stress unknowns per cell (block size of Ms) */
  Mat      Jvv, Jvu; /* velocity rows: d/dv (shift Mv [+ node-wise terms]) and d/du (node-wise terms, or NULL) */
  Mat      Jvc;      /* Jvv + Jvu / shift: the velocity rows' own block once u = u0 + v / shift is eliminated (one product) */
  Mat      Sv;       /* preconditioner: condensed velocity operator shift Mv + K/shift (AIJ, rigid modes attached) */
  Mat      M, K;     /* the velocity mass Mv and the condensed stiffness K = G^T Ms^{-1} G (AIJ; the linearised analysis) */
  Mat      Jsu;      /* stress rows: d(G(u) v)/du (geometric stiffening), or NULL */
  Mat      Kstate;   /* velocity rows' displacement columns of a stressed or spinning state, K_sigma + Cen (AIJ, symmetric), or NULL */
  Mat      Gyro;     /* velocity rows' velocity terms besides shift Mv: the Coriolis matrix of a spin (AIJ, skew), or NULL */
  PetscBool inexact_schur; /* Sv is not the exact Schur complement of u and Sigma (spin, stiffening): a Krylov method is needed */
  Vec      load;     /* a fixed body's applied load b of the velocity rows at the last evaluation (T Mv v' + G^T Sigma = b), or NULL */
  Mat      R;        /* structural damping R of the velocity rows (T Mv v' + G^T Sigma + R v = b; symmetric positive
                        semi-definite, constant), or NULL: undamped */
} PhlexFieldOperators;

/* Reference scales a part suggests before set-up (the scene takes the largest of each). */
typedef struct {
  PetscReal extent;  /* geometric size [m] */
  PetscReal density; /* [kg/m^3], 0 if none */
  PetscReal modulus; /* [Pa], 0 if none */
  PetscReal mass;    /* [kg], 0 if none */
} PhlexScaleHints;

/* A port of a part. */
typedef struct {
  char      name[PHLEX_NAME_LEN];
  PetscInt  dim;      /* 6 (force and moment) or 3 (a point: force only, no orientation) */
  PetscReal point[3]; /* port point relative to the frame origin P, body frame, non-dimensional */
} PhlexPortInfo;

/* the field products behind a port's linearized output: the six velocity moments and three displacement moments */
#define PHLEX_PORT_SUMS 9

/* The core table: what every part implements (NULL where noted). A part with only discrete unknowns (rigid body,
   point mass, reduced modal body) needs nothing else. */
typedef struct {
  /* life cycle */
  PetscErrorCode (*setfromoptions)(PhlexPart);
  PetscErrorCode (*geometry)(PhlexPart, PhlexScaleHints *); /* read meshes, suggest scales */
  PetscErrorCode (*setup)(PhlexPart);                       /* operators, sizes, ports (part->units is set) */
  PetscErrorCode (*view)(PhlexPart, PetscViewer);
  PetscErrorCode (*destroy)(PhlexPart);
  /* state */
  PetscErrorCode (*prepareinitialstate)(PhlexPart); /* the heavy part of initialstate (an eigensolve), before the system's operators exist; NULL: none */
  PetscErrorCode (*initialstate)(PhlexPart, PhlexPartVec *);
  PetscErrorCode (*place)(PhlexPart, const PetscReal[3], PetscReal *); /* put its port at a point (an attached part given no position); NULL: never attached */
  /* residual and Jacobian */
  PetscErrorCode (*evaluate)(PhlexPart, PetscReal, const PhlexPartVec *, const PhlexPartVec *); /* t, X, X' (or NULL: rest) */
  PetscErrorCode (*residual)(PhlexPart, PetscReal, const PhlexPartVec *, const PhlexPartVec *, PhlexPartVec *);
  PetscErrorCode (*jacobian)(PhlexPart, PetscReal, const PhlexPartVec *, PetscReal *, PetscInt); /* shift, X, its block of the dense discrete Jacobian (row-major, leading dim) */
  PetscErrorCode (*poststep)(PhlexPart, PetscReal *, PetscReal *);         /* its discrete unknowns after a step; largest correction; NULL: none */
  /* ports */
  PetscErrorCode (*portoutput)(PhlexPart, PetscInt, PetscReal[6]);                           /* y at the evaluated state */
  PetscErrorCode (*portinput)(PhlexPart, PetscInt, PetscReal, PetscReal[6]);                 /* u: the wrench its load applies at t, evaluated state (body frame); NULL: none */
  PetscErrorCode (*portlinear)(PhlexPart, PetscInt, Vec, PetscReal, Vec, const PetscReal *, PetscReal[6]); /* dy for (a du, dv, dq); NULL: zero */
  PetscErrorCode (*portforce)(PhlexPart, PetscInt, const PetscReal[6], Vec, PetscReal *);      /* += generalized force of w (fv may be NULL) */
  PetscErrorCode (*portplacement)(PhlexPart, PetscInt, const PhlexPartVec *, PetscReal[3], PetscReal[9]); /* inertial position, orientation */
  PetscErrorCode (*portrate)(PhlexPart, PetscInt, const PhlexPartVec *, PetscReal[9]); /* a deforming port: holds (X given) and returns the map A of its elastic rotation's rate, the port's angular velocity w + A B_r^T v (PhlexJointUpdateGeometry, once per step); NULL: none (A = I) */
  /* energy, inputs, outputs */
  PetscErrorCode (*energy)(PhlexPart, const PhlexPartVec *, PetscReal *, PetscReal *, PetscReal *); /* kinetic, strain, potential at the evaluated state X */
  PetscErrorCode (*momenta)(PhlexPart, PetscReal[3], PetscReal[3]);         /* inertial linear and angular momentum (about the origin), evaluated state; NULL: held */
  PetscErrorCode (*inputpower)(PhlexPart, PetscReal *);                       /* power of its external inputs at the evaluated state */
  PetscErrorCode (*dissipation)(PhlexPart, PetscReal *);                      /* power its dampers dissipate at the evaluated state (>= 0); NULL: none */
  PetscErrorCode (*deformation)(PhlexPart, const PhlexPartVec *, PetscReal *, PetscReal *, PetscBool *); /* largest elastic displacement and its size [m] at X, whether a spin would need -geometric_stiffening (the blow-up watchdog); NULL: none */
  PetscErrorCode (*rigidmass)(PhlexPart, PetscReal[36]);                      /* mass matrix of its frame motion (v_P, w), body frame; NULL: held */
  PetscErrorCode (*outputopen)(PhlexPart, PhlexOutput, PetscBool);
  PetscErrorCode (*outputstep)(PhlexPart, PetscInt, PetscReal, const PhlexPartVec *, PetscBool); /* series rows (step >= 0), fields if asked */
  PetscErrorCode (*outputclose)(PhlexPart);
} PhlexPartOps;

/* The field table: a part with field unknowns (nv > 0, a finite-element body) implements all of it; NULL for every
   other part (the system collects the parts with fields and calls this table on them only). */
typedef struct {
  /* split phases (border.c, system.c): the system calls evaluatebegin (energybegin) of every part with fields, with
     the arguments of its evaluate (energy), before the evaluate (energy) of any, so that parts on different
     processes do their local work at the same time */
  PetscErrorCode (*evaluatebegin)(PhlexPart, PetscReal, const PhlexPartVec *, const PhlexPartVec *);
  PetscErrorCode (*energybegin)(PhlexPart, const PhlexPartVec *);
  /* Jacobian pieces of the field blocks and of the border between fields and discrete unknowns */
  PetscErrorCode (*fieldoperators)(PhlexPart, PhlexFieldOperators *);
  PetscErrorCode (*mixedoperators)(PhlexPart, PetscBool); /* PETSC_FALSE: free what only Newton on the whole state
                                                             multiplies, the assembled G and Ms (and a fixed body's
                                                             AIJ M and K): fieldoperators then hands out NULL for them;
                                                             PETSC_TRUE: assemble them again if freed. NULL: the part
                                                             keeps what it has */
  PetscErrorCode (*velocityblock)(PhlexPart, PetscBool); /* PETSC_FALSE: free the whole-state Jacobian's velocity
                                                            block (a fixed body's shift Mv), which SNES phlexcondensed's
                                                            stage never multiplies; fieldoperators then hands out NULL
                                                            for Jvv and Jvc; PETSC_TRUE: build it again at the current
                                                            shift. NULL: the part keeps it */
  PetscErrorCode (*bordermult)(PhlexPart, const PetscReal *, Vec);               /* y_v += B x_q (its own columns) */
  /* the discrete rows applied to field vectors in two phases (border.c sums every part's and joint's products over
     the processes in one reduction): this process's parts of a Cu^T x_u + Cv^T x_v, its own rows (nq values, set;
     NULL vectors are zero), and of portlinear's field products (PHLEX_PORT_SUMS values, set), then portlinear from the
     summed products */
  PetscErrorCode (*bordermulttransposelocal)(PhlexPart, Vec, PetscReal, Vec, PetscReal *);
  PetscErrorCode (*portlinearlocal)(PhlexPart, PetscInt, Vec, PetscReal, Vec, PetscReal[PHLEX_PORT_SUMS]);
  PetscErrorCode (*portlinearsummed)(PhlexPart, PetscInt, Vec, PetscReal, Vec, const PetscReal[PHLEX_PORT_SUMS], const PetscReal *, PetscReal[6]);
  PetscErrorCode (*borderbasis)(PhlexPart, Mat *);                               /* W: state-independent span of its borders */
  PetscErrorCode (*borderrows)(PhlexPart, Mat, PetscReal *, PetscInt);           /* (Cv + Cu/shift)^T Y, nq x k column-major, ld */
  PetscErrorCode (*bordercoefficients)(PhlexPart, PetscReal *, PetscInt);        /* beta: own border columns ~ W beta (k x nq, ld) */
  PetscErrorCode (*portlinearblock)(PhlexPart, PetscInt, Mat, PetscReal, PetscReal *); /* dy for dv = columns of Y, du = Y/shift: 6 x k */
  PetscErrorCode (*portbasiscolumn)(PhlexPart, PetscInt, PetscInt *);                  /* first of the 6 columns of W spanning its field force */
  PetscErrorCode (*coarsespace)(PhlexPart, PetscInt, PetscInt, Mat, PetscInt *, PetscInt[]); /* p-multigrid (pmg.c): its rows of the interpolation from its coarse space (PhlexFlexibleCoarseSpace's arguments); NULL: its unknowns carried to the coarse level */
} PhlexPartFieldOps;

/* The analysis table: what the modal and linearised analyses ask of a body beyond the core (its own eigenproblem,
   refinement, a prescribed spin); NULL for parts without, each entry may be NULL too (PhlexPartAnalysisOp). */
typedef struct {
  PetscErrorCode (*modes)(PhlexPart, PetscInt, PetscInt *, PetscInt *, PetscReal **, Vec **, PetscReal **, PetscReal **);
  PetscErrorCode (*modesoutput)(PhlexPart, PhlexOutput, PetscInt, PetscInt, const PetscReal *, Vec *, const PetscReal *, const PetscReal *); /* ..., placement: r_P (non-dimensional) and R of a floating body in an assembly, or NULL (body frame) */
  PetscErrorCode (*refine)(PhlexPart, PetscInt, PhlexPart *); /* the same part on a finer discretisation */
  PetscErrorCode (*modesorder)(PhlexPart, char[], size_t);      /* its discretisation and the order of its eigenvalues under refinement */
  PetscErrorCode (*modeskind)(PhlexPart, char[], size_t, PetscInt *); /* "free", "clamped", ...; how many rigid-body modes it has (-1: none counted) */
  PetscErrorCode (*steadystate)(PhlexPart, PhlexPartVec *); /* its fields in the steady state of a prescribed uniform spin (NULL: at rest) */
  PetscErrorCode (*spinrate)(PhlexPart, PetscBool, PetscReal *); /* get (PETSC_FALSE) or set (PETSC_TRUE) the rate of its prescribed spin [rad/s]; -1 on get: it has none */
  PetscErrorCode (*reduce)(PhlexPart, PetscViewer);               /* -analysis reduce: its reduced model's file (built or checked at set-up), reported */
  PetscErrorCode (*steadydrive)(PhlexPart, PetscInt, const PetscReal[3], const PetscReal *); /* linearised analysis, before the system is built: a floating body held at a port by a drive at constant rate lives in the drive's co-rotating frame (the port, angular velocity [rad/s] and a point of the axis [m] or NULL: the port's point; inertial, as drawn) */
  PetscErrorCode (*steadystart)(PhlexPart, PhlexPartVec *, PetscBool *); /* transient: a floating body asked to start in the steady state of its frame's spin (-ic_steady_spin) takes it, from the frame's consistent velocities; PETSC_FALSE: not asked */
} PhlexPartAnalysisOps;

/* an entry of a part's analysis table, NULL when it has no such table or entry */
#define PhlexPartAnalysisOp(p, op) ((p)->analysisops ? (p)->analysisops->op : NULL)

struct _p_PhlexPart {
  MPI_Comm          comm;
  PetscInt          index; /* k of the prefix body<k>_; -1 for the ground */
  char              prefix[32];
  char              name[PHLEX_NAME_LEN];
  char              type[32];
  char              numbering[48]; /* how its field unknowns are numbered ("rcm" or "file", and "@" a hash of where
                                      they are, PhlexFlexiblePlacement; "": no field unknowns), part of a checkpoint's
                                      fingerprint */
  PhlexPartOps          ops;
  PhlexPartFieldOps    *fieldops;    /* NULL: no field unknowns */
  PhlexPartAnalysisOps *analysisops; /* NULL: no analysis of its own */
  void             *data;
  PetscInt64       *process_cells; /* with -whole_bodies: the scene's count of cells per process of the bodies placed
                                      so far (a flexible body goes whole to the process with the fewest); else NULL */
  const PhlexUnits *units;
  PetscReal         gravity[3]; /* non-dimensional, inertial frame */

  /* layout: set by setup */
  PetscInt        nu, ns, nv; /* local sizes of the field blocks (nu = nv), 0 without a field */
  PetscInt        Nu, Ns, Nv; /* global sizes */
  PetscInt        nq;         /* discrete unknowns */
  PhlexDofKind   *qkind;
  char          (*qname)[16];
  PhlexFrameIndex frame;
  PetscBool       nonlinear; /* its residual is not linear in its unknowns (a moving frame) */
  PetscBool       material_warned;     /* a warning said its material is suspicious (units, near incompressibility): the
                                          watchdogs' advice points at it */
  PetscBool       nonquadratic_energy; /* its Hamiltonian is not quadratic in its energy variables (a floating body's
                                          full inertia): the implicit midpoint rule conserves it to O(dt^2) only */

  /* ports: set by setup; the wrench on each port from the joints (body frame, non-dimensional) is set by the
     system before residual and jacobian */
  PetscInt       nports;
  PhlexPortInfo *ports;
  PetscReal    (*wrench)[6];
  PetscBool     *port_used; /* a joint acts on the port (its force distribution enters the border basis) */

  char attach[2 * PHLEX_NAME_LEN + 2]; /* "body:port" this part asks to be joined to by a spherical joint ("" none) */

  /* placement in the global unknowns: set by the system */
  PetscInt qoff;          /* offset of q in the discrete field */
  IS       isu, iss, isv; /* field blocks in the global vector */
};

/* part.c helpers */
PETSC_INTERN PetscErrorCode PhlexPartSetUpLayout(PhlexPart, PetscInt, PetscInt, PetscInt, PetscInt, PetscInt);
PETSC_INTERN PetscErrorCode PhlexPartSetDof(PhlexPart, PetscInt, PhlexDofKind, const char[]);
PETSC_INTERN PetscErrorCode PhlexPartSetPorts(PhlexPart, PetscInt);
PETSC_INTERN PetscErrorCode PhlexPartFind(PetscInt, const PhlexPart[], PhlexPart, const char[], PhlexPart *);
PETSC_INTERN PetscErrorCode PhlexPartFindPort(PhlexPart, const char[], PetscInt *);
PETSC_INTERN PetscErrorCode PhlexPartGetVec(PhlexPart, Vec, PetscReal *, PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexPartRestoreVec(PhlexPart, Vec, PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexPartCreateGround(MPI_Comm, PhlexPart *);
PETSC_INTERN PetscBool      PhlexPartIsGround(PhlexPart);
PETSC_INTERN PetscBool      PhlexPartIsElastic(PhlexPart);
PETSC_INTERN void           PhlexPortPlacementFromMean(const PetscReal *, const PetscReal[3], const PetscReal[6], PetscReal[3], PetscReal[9]);
PETSC_INTERN PetscErrorCode PhlexPortSeriesOpen(PhlexOutput, const char[], PetscInt, const char *const[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexPortSeriesEntry(PetscViewer, const PhlexUnits *, const PetscReal[6], PetscBool, const PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexPortSeriesPosition(PetscViewer, const PhlexUnits *, const PetscReal[3]);

/* Wrench inputs of a port given in the scene (flexible and rigid bodies): amplitudes with a time profile, directions
   fixed in the body frame or in the inertial frame. */
typedef enum {
  PHLEX_DIRECTION_BODY,
  PHLEX_DIRECTION_INERTIAL
} PhlexDirectionFrame;
PETSC_EXTERN const char *const PhlexDirectionFrames[];

typedef struct {
  PetscReal           force[3], moment[3]; /* amplitudes (SI) */
  PetscBool           loaded;
  PetscBool           traction_input; /* amplitude given as a traction [Pa] (flexible ports) */
  PhlexDirectionFrame frame;
  PhlexProfile        profile;
} PhlexPortLoad;
PETSC_INTERN PetscErrorCode PhlexPortLoadSetFromOptions(PhlexPart, const char[], PetscBool, PhlexPortLoad *);
PETSC_INTERN PetscErrorCode PhlexPortLoadEvaluate(PhlexPortLoad *, PetscReal, const PhlexUnits *, const PetscReal *, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexPortLoadDerivativeR(PhlexPortLoad *, PetscReal, const PhlexUnits *, PetscInt, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexPortLoadDescribe(PhlexPortLoad *, char[], size_t);
PETSC_INTERN PetscErrorCode PhlexPortLoadDestroy(PhlexPortLoad *);

/* Initial placement and velocity of a moving frame (floating flexible body, rigid body). */
typedef struct {
  PetscReal position[3], rotation[9]; /* r_P [m], R */
  PetscReal velocity[3], omega[3];    /* v_P [m/s], w [rad/s], body frame */
  PetscBool position_given, orientation_given, velocity_given, omega_given;
} PhlexPose;
PETSC_INTERN PetscErrorCode PhlexPoseSetFromOptions(PetscOptionItems *, PhlexPart, PhlexPose *, const char **);

/* the kinds (each one file) */
PETSC_INTERN PetscErrorCode PhlexPartCreate_Flexible(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexPartCreate_Rigid(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexPartCreate_Lumped(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexPartCreate_Reduced(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexPartCreate_Ground(PhlexPart);

#endif
