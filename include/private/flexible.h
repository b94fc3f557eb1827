/* A flexible body: a 3D elastic solid discretised with mixed P_k velocity / discontinuous P_{k-1} stress elements
   (paper Section 4), either fixed (clamped on its frame patch) or floating (its frame translates and rotates). */
#ifndef PHLEX_PRIVATE_FLEXIBLE_H
#define PHLEX_PRIVATE_FLEXIBLE_H

#include <stdint.h> /* uint64_t */

#define PHLEX_MAX_MATERIALS 16

/* Stress components (Voigt order) of the 6-component stress field; shear components hold the tensor entry. */
enum { PHLEX_S_XX, PHLEX_S_YY, PHLEX_S_ZZ, PHLEX_S_YZ, PHLEX_S_XZ, PHLEX_S_XY };

/* A gmsh physical group: name, topological dimension, tag. */
typedef struct {
  char     name[PHLEX_NAME_LEN];
  PetscInt dim, tag;
} PhlexPhysicalGroup;

/* Isotropic linear elastic material of one volume region (or of the whole body). SI units. */
typedef struct {
  char      region[PHLEX_NAME_LEN]; /* physical volume name, empty for the whole body */
  PetscInt  tag;                    /* "Cell Sets" value, -1 for the whole body */
  PetscReal youngs_modulus, poissons_ratio, density;
  PetscReal viscosity; /* Kelvin-Voigt viscous modulus eta [Pa s]: viscous stress (eta / E) D eps(v), D the elastic
                          moduli (the viscous tensor has the elastic Poisson's ratio); 0: none */
} PhlexMaterial;

/* A port of a flexible body: a named boundary surface. Its wrench (force F, moment T about the patch centroid c) is
   distributed as the traction tau = F/A + (I_c^{-1} T) x (x - c) (DESIGN section 3); the columns dist[k] of B are
   the nodal loads of unit wrench components, and its collocated output is B^T v (patch-average velocity and angular
   velocity). */
typedef struct {
  char          name[PHLEX_NAME_LEN];
  PetscInt      tag;
  PetscReal     area, centroid[3], inertia[9], inertia_inv[9]; /* SI patch geometry */
  Vec           dist[6];                                      /* B columns (non-dimensional) */
  PhlexPortLoad load;
} PhlexFlexPort;

/* Inertia invariants of a moving frame about its origin P (non-dimensional). */
typedef struct {
  PetscReal m, s0[3], E0[9]; /* int rho, int rho x, int rho x x^T */
  PetscReal vol, svol[3];    /* int 1, int x (uniform body force) */
} PhlexInertia;

/* The dynamics of a moving frame carrying an optional elastic field (frame.c): a floating flexible body, or a rigid
   body (no field). */
typedef struct {
  MPI_Comm         comm;
  PetscBool        frozen;     /* inertia terms at u_f = 0 (constant mass operator) */
  PetscBool        gyroscopic; /* with frozen: the gyroscopic loads kept, at the undeformed geometry (the constant
                                  model, frame.c); without: none on the elastic field */
  PhlexInertia     inertia;
  Vec              tnode, wnode; /* per node: int rho phi, int rho x phi (NULL: no field) */
  Mat              Mv;           /* velocity mass of the field (NULL: no field) */
  const PetscReal *gravity;      /* non-dimensional, inertial frame */
} PhlexFrame;

/* A frame evaluated at a state and its rates (frame.c); all non-dimensional, body frame. */
typedef struct {
  PetscReal r[3], R[9], vP[3], w[3], rd[3], Rd[9], vPd[3], wd[3];
  PetscReal m, s[3], sd[3], sgrav[3], Vf[3], Vfd[3], E[9], Ed[9], J[9], Jd[9], L[3], Ld[3];
  PetscReal pt[3], pr[3], ptd[3], prd[3], gbody[3], Fext[3], Mext[3];
  PetscReal Lx[3]; /* int rho (x - P) x v (the mean-axes rotation constraint) */
  PetscReal Wv[9]; /* int rho (x - P)_b v_c, row-major */
  Vec       Mu, Mvv, Mud, Mvd;      /* Mv u, Mv v, Mv u', Mv v' (field only) */
  Vec       bext, barm;             /* elastic load; its part whose moment arm about P moves with u (forces, not the
                                       moment distributions of ports: a port turns by its mean rotation) */
  PetscReal   sums_loc[84], sums[84]; /* the field's integrals: this process's part, their sums over the processes */
  MPI_Request sums_req;               /* the sums' reduction between PhlexFrameEvaluateBegin and End */
} PhlexFrameState;

PETSC_INTERN PetscErrorCode PhlexFrameEvaluate(PhlexFrame *, Vec, Vec, Vec, Vec, const PetscReal[18], const PetscReal[18], PhlexFrameState *);
PETSC_INTERN PetscErrorCode PhlexFrameEvaluateBegin(PhlexFrame *, Vec, Vec, Vec, Vec, PhlexFrameState *);
PETSC_INTERN PetscErrorCode PhlexFrameEvaluateEnd(PhlexFrame *, const PetscReal[18], const PetscReal[18], PhlexFrameState *);
PETSC_INTERN PetscErrorCode PhlexFrameAddLoadArms(PhlexFrame *, Vec, PhlexFrameState *);
PETSC_INTERN PetscErrorCode PhlexFrameResidual(PhlexFrame *, PhlexFrameState *, Vec, Vec, Vec, Vec, PetscReal[18]);
/* The node inputs of a frame's field borders (PhlexFrameJacobian): t(l), z(l) = w(l) + (Mv u)(l), (Mv u')(l), (Mv v)(l),
   (Mv v')(l), the load arm b(l), w(l) = int rho x phi_l; the columns of the node-input matrix P, in this order */
enum {
  PHLEX_FRAME_IN_T   = 0,
  PHLEX_FRAME_IN_Z   = 1,
  PHLEX_FRAME_IN_ZD  = 4,
  PHLEX_FRAME_IN_MV  = 7,
  PHLEX_FRAME_IN_MVD = 10,
  PHLEX_FRAME_IN_B   = 13,
  PHLEX_FRAME_IN_W   = 16,
  PHLEX_FRAME_NIN    = 19
};
PETSC_INTERN PetscErrorCode PhlexFrameJacobian(PhlexFrame *, PhlexFrameState *, PetscReal, PetscScalar *, PetscScalar *, PetscScalar *, PetscInt, PetscReal[9], PetscReal[9], PetscReal[324]);
PETSC_INTERN PetscErrorCode PhlexFrameNodeInputs(PhlexFrame *, PhlexFrameState *, PetscScalar *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexFrameLoadCoefficients(PhlexFrame *, PhlexFrameState *, PetscReal[3 * PHLEX_FRAME_NIN]);
PETSC_INTERN PetscErrorCode PhlexFrameEnergy(PhlexFrame *, PhlexFrameState *, PetscReal, PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFrameMomenta(PhlexFrameState *, PetscReal[3], PetscReal[3]);
PETSC_INTERN PetscErrorCode PhlexFrameStateDestroy(PhlexFrameState *);
PETSC_INTERN PetscErrorCode PhlexFrameRigidMass(const PhlexInertia *, PetscReal[36]);
PETSC_INTERN PetscErrorCode PhlexFrameWriteHeader(char[], size_t);
PETSC_INTERN PetscErrorCode PhlexFrameWriteRow(PetscViewer, PetscReal, PhlexFrameState *, const PhlexUnits *, PetscReal[3], PetscReal[3]);

/* Initial condition of a field. */
typedef enum {
  PHLEX_IC_ZERO,
  PHLEX_IC_UNIFORM,
  PHLEX_IC_RIGID,
  PHLEX_IC_BEAM,
  PHLEX_IC_MODE
} PhlexICType;
PETSC_EXTERN const char *const PhlexICTypes[];

typedef struct {
  PhlexICType type;
  PetscReal   value[6];     /* uniform: velocity (3) or stress (6); rigid: translation velocity */
  PetscReal   angular[3];   /* rigid: angular velocity, about 'origin' */
  PetscReal   origin[3];
  PetscInt    mode;         /* mode number (1-based) for PHLEX_IC_MODE and PHLEX_IC_BEAM */
  PetscReal   amplitude;    /* max |field| for modes, tip value for beam */
  PetscReal   direction[3]; /* beam deflection direction */
} PhlexIC;

/* How the body frame is fixed to a floating body. */
typedef enum {
  PHLEX_FRAME_PATCH,     /* u_f = v_f = 0 on a surface (the paper's Gamma_D): a rigid inclusion */
  PHLEX_FRAME_MEAN_AXES  /* Tisserand/Buckens: int rho u_f = 0, int rho (x - P) x u_f = 0 (six multipliers) */
} PhlexFrameCondition;
PETSC_EXTERN const char *const PhlexFrameConditions[];

typedef struct _p_PhlexFlexible *PhlexFlexible;

/* element.c: element kernels on PetscFE tabulations (pure arithmetic) */
#define PHLEX_MAX_NODES 10 /* P2 tetrahedron */
typedef struct {
  PetscInt         nq, nb, nc, nnodes; /* quadrature points, basis functions (all components), components, nodes */
  const PetscReal *weights;            /* [nq] reference weights */
  PetscReal       *node_phi;           /* [nq][nnodes] scalar shape of each node */
  PetscReal       *node_dphi;          /* [nq][nnodes][3] its reference gradient */
} PhlexElementBasis;
typedef struct {
  PetscInt  nv, ns; /* velocity and stress nodes */
  PetscReal mass[PHLEX_MAX_NODES * PHLEX_MAX_NODES], grad[PHLEX_MAX_NODES * PHLEX_MAX_NODES * 9];
  PetscReal smass[16], coup[4 * PHLEX_MAX_NODES * 3], load[PHLEX_MAX_NODES];
} PhlexElementReferenceIntegrals;
PETSC_INTERN void     PhlexElementReference(const PhlexElementBasis *, const PhlexElementBasis *, PhlexElementReferenceIntegrals *);
PETSC_INTERN void     PhlexElementCompliance(PetscReal, PetscReal, PetscReal[36]);
PETSC_INTERN void     PhlexElementMass(const PhlexElementReferenceIntegrals *, PetscReal, PetscReal, PetscReal *);
PETSC_INTERN void     PhlexElementLoad(const PhlexElementReferenceIntegrals *, PetscReal, PetscReal *);
PETSC_INTERN void     PhlexElementCoupling(const PhlexElementReferenceIntegrals *, PetscReal, const PetscReal[9], PetscReal *, PetscReal *);
PETSC_INTERN void     PhlexElementComplianceMass(const PhlexElementReferenceIntegrals *, PetscReal, const PetscReal[36], PetscReal *);
PETSC_INTERN void     PhlexElementStiffness(const PhlexElementReferenceIntegrals *, PetscReal, PetscReal, PetscReal, const PetscReal[9], PetscReal *);
PETSC_INTERN PetscInt PhlexElementCondense(PetscInt, PetscInt, PetscReal *, const PetscReal *, PetscReal *, PetscReal *);
PETSC_INTERN PetscInt PhlexDenseCholesky(PetscInt, PetscReal *);
PETSC_INTERN void     PhlexDenseCholeskySolve(PetscInt, const PetscReal *, PetscInt, PetscReal *);
/* element_stiffening.c: the Green-Lagrange coupling and its derivatives (quadrature) */
PETSC_INTERN void PhlexElementCouplingDeformed(const PhlexElementBasis *, const PhlexElementBasis *, PetscReal, const PetscReal[9], const PetscReal *, PetscReal *);
PETSC_INTERN void PhlexElementGreenLagrange(const PhlexElementBasis *, const PhlexElementBasis *, PetscReal, const PetscReal[9], PetscBool, const PetscReal *, PetscReal *);
PETSC_INTERN void PhlexElementGeometricStiffness(const PhlexElementBasis *, const PhlexElementBasis *, PetscReal, const PetscReal[9], const PetscReal *, PetscReal *);
PETSC_INTERN void PhlexElementCouplingDerivative(const PhlexElementBasis *, const PhlexElementBasis *, PetscReal, const PetscReal[9], const PetscReal *, PetscReal *);

struct _p_PhlexFlexible {
  MPI_Comm            comm;
  PhlexPart           part; /* the part it implements */
  const char         *name, *prefix;
  char                mesh_file[PETSC_MAX_PATH_LEN];
  PetscInt            ngroups;
  PhlexPhysicalGroup *groups;
  PetscInt            degree;            /* velocity P_k, stress P_{k-1} discontinuous */
  PetscBool           rcm;               /* the mesh's points renumbered by reverse Cuthill-McKee (-node_order rcm) */
  PetscInt            extra_refinements; /* uniform refinements on top of -dm_refine (convergence studies) */
  PetscInt            process;           /* the process that holds the whole body (-process, -whole_bodies); -1: its
                                            cells are split over all processes */
  char                frame_patch[PHLEX_NAME_LEN]; /* Dirichlet patch Gamma_D ("" for none) */
  PetscInt            frame_tag;
  PetscReal           frame_area, frame_centroid[3], frame_inertia[9]; /* SI geometry of the frame patch */
  PetscInt            nmaterials;
  PhlexMaterial       materials[PHLEX_MAX_MATERIALS];
  PetscInt            nports;
  PhlexFlexPort      *ports;
  PetscReal           body_force[3]; /* N/m^3, body frame */
  PhlexProfile        body_force_profile;
  PetscBool           has_body_force;
  PhlexIC             ic_velocity, ic_displacement, ic_stress;
  Vec                 ic_mode[2];          /* a mode IC's eigenvector (velocity, displacement), computed ahead (PhlexFlexiblePrepareInitialState) */
  PetscReal           ic_mode_rigid[2][6]; /* and its rigid-motion row */

  /* floating frame */
  PetscBool           floating;         /* rigid motion of the frame is an unknown */
  PhlexFrameCondition frame_condition;  /* patch or mean axes */
  PetscBool           frozen_inertia;   /* mass operator at u_f = 0 (models constant, constant_without_gyroscopic) */
  PetscReal           pc_rate_tol;      /* > 0: the factored condensed operator takes the node-wise inertia terms of the
                                           frame's rate once they exceed this share of the shift, and again whenever they
                                           drift by as much (0: never) */
  PetscReal           pc_rate_B[9];     /* the node-wise block Bvv + Bvu / shift in the factored operator (0: none) */
  PetscInt            pc_rate_count;    /* refactorizations for the rate */
  PetscReal           pc_rate_B_restart[9]; /* a restart's pc_rate_B, put in at its first Jacobian (checkpoint) */
  PetscBool           pc_rate_restart;      /* pc_rate_B_restart is pending */
  PetscBool           gyroscopic;       /* with it: the gyroscopic loads kept (constant) */
  const char         *inertia_model;    /* full, constant, constant_without_gyroscopic */
  PetscReal           origin[3];        /* frame origin P (SI mesh coordinates) */
  PetscBool           origin_given;
  PhlexPose           pose;             /* initial r_P, R, v_P, w */
  PetscReal           frame_force[3], frame_moment[3]; /* wrench at P [N, N m] (body frame) */
  PhlexProfile        frame_profile;
  PetscBool           frame_loaded;
  PhlexInertia        inertia;     /* about the frame origin (fixed body: about the inertial origin) */
  PhlexFrame          frame;       /* the frame dynamics (floating) */
  PhlexFrameState     fs;          /* its last evaluation */
  Vec                 tnode, wnode, vnode; /* per node: int rho phi, int rho x phi, int phi (triples) */

  /* discretisation */
  DM        dm;   /* DMPlex with the velocity field (P_k vector, essential BC on the frame patch) */
  DM        dm_s; /* clone with the stress field (P_{k-1} discontinuous, 6 components) */
  PetscFE   fe_v, fe_s;
  PetscInt  cStart, cEnd;
  PetscInt  nb_v, nb_s;      /* basis functions per cell (all components) */
  PetscInt *cell_material;   /* material index per local cell */
  PetscInt *cell_vdofs;      /* per local cell: global velocity dofs of its closure (negative: constrained) */
  PetscInt *cell_soff;       /* per local cell: global offset of its stress dofs */
  PhlexElementReferenceIntegrals ref;
  PetscReal *cell_geom;      /* per local cell: detJ, invJ[9] (non-dimensional) */
  PetscReal  bbox_min[3], bbox_max[3];
  PetscReal  modes_budget; /* -modes_budget: the largest eigensolve started [flops] (0: no limit) */

  /* constant body-frame operators (non-dimensional), assembled once */
  Mat Mv;      /* velocity mass int rho phi.phi (SBAIJ) */
  Mat K;       /* condensed stiffness G^T Ms^{-1} G (SBAIJ) */
  Mat G;       /* coupling int Sigma : Grad(v), stress rows x velocity columns */
  Mat Ms;      /* compliance mass, block diagonal (BAIJ, one block per cell) */
  PetscReal compliance[PHLEX_MAX_MATERIALS][36]; /* each material's compliance A (non-dimensional): Ms's block of a cell
                                                    is detJ (smass (x) A), PhlexElementComplianceMass */

  /* the stress maps B = Ms^{-1} G, G^T and G^T Ms^{-1} G cell by cell (flexible_stress_maps.c), set up at their first product */
  Mat       smap_B, smap_Res, smap_K;           /* the shells handed out as PhlexFieldOperators' B, Res and Kc */
  PetscBool smap_ready;
  PetscBool smap_created;                       /* PhlexFlexibleCreateStressMaps was called (the shells, or none with stiffening) */
  PetscBool check_stress_maps, check_condensation; /* -phlex_check_stress_maps, -phlex_check_condensation */
  PetscReal stiffness[PHLEX_MAX_MATERIALS][36]; /* each material's A^{-1} */
  PetscReal smass_inv[16];                      /* the stress basis's reference mass, inverted */
  Vec       smap_vloc, smap_floc;               /* local (ghosted) velocity field: the product's input, G^T's sums */
  PetscScalar *smap_varray;                     /* smap_vloc's storage, one entry longer: a node's 3 velocities read as 4 */
  PetscBool    smap_vnodes;                     /* each node's 3 velocities consecutive in smap_vloc (read node by node) */
  Vec fvol[3]; /* int phi e_c dOmega (uniform body forces) */

  /* Jacobian pieces (transient), updated by the part */
  PetscReal shift;          /* non-dimensional shift of the assembled blocks (0: none yet) */
  Mat       Mvaij, Kaij, Jvv, Jvu, Jvc, Sv;
  Mat       Mvp; /* the products with Mv: the scalar mass times I_3 (MAIJ), a ninth of Mv's entries */
  /* floating: the borders of its own discrete unknowns, node-wise (PhlexFrameJacobian): border[(l, c), j] =
     sum_i L[(3 j + c) nin + i] P[i nnode + l], for Lb (velocity rows), Lu, Lv (the discrete rows' displacement and
     velocity columns) and Lpre = Lv + Lu / shift (the rows with the displacement eliminated) */
  PetscInt   border_nin;      /* node inputs: the frame's PHLEX_FRAME_NIN, then 18 per port with inertial loads */
  PetscScalar *border_P;      /* n_local/3 x border_nin, column-major: the node inputs at the Jacobian's state */
  PetscScalar *border_Lb, *border_Lu, *border_Lv, *border_Lpre; /* 3 nq x border_nin each */
  PetscInt  *port_inertial_in; /* first node input of each port's distributions (-1: no inertial load) */
  PetscReal Bvv[9], Bvu[9];   /* floating: node-wise blocks applied after Mv */
  Mat       W;                /* border basis: frame (12 columns) and the ports with joints (6 each) */
  PetscInt *port_basis_col;   /* first column of each port's distribution in W (-1: not in W) */
  Vec       load, work;       /* velocity-space work vectors */
  Vec       ud, vd;           /* non-dimensional rates (floating) */
  Vec       ewv;              /* the kinetic energy's work vector, made at its first call */
  PetscBool   frame_begun;    /* FlexEvaluateBegin has started the frame's integrals of the state being evaluated */
  PetscBool   energy_begun;   /* FlexEnergyBegin has started the energy's sums */
  PetscReal   energy_loc[3], energy_sums[3]; /* v^T Mv v, s^T Ms s, b_g . u: this process's parts, their sums */
  MPI_Request energy_req;
  PetscReal (*port_ext)[6];   /* external port wrenches at the evaluated time (body frame) */
  PetscReal (*port_y)[6];     /* port outputs at the evaluated state */
  PetscReal (*port_ubar)[3];  /* full model: mean displacement of each port (the arm of its force beyond the drawn point) */
  PetscReal (*port_rate)[9];  /* per port: A, the rate map of its mean rotation theta = B_r^T u, held over a step: the port
                                 turns at w + A B_r^T v and a moment T on it acts as B_r A^T T on the field (-port_rate
                                 exact: A = J_l(theta) at the step's extrapolated middle, PhlexJointUpdateGeometry;
                                 first_order: A = I); the identity but on a port with a joint */
  PetscBool  port_rate_exact, port_rate_given; /* -port_rate exact (the default) or first_order; given */
  PetscReal  t_eval, power_ext;
  PetscBool  joints_added;    /* the joint wrenches are in the loads of the evaluated state */
  Vec        bgrav;           /* fixed body: nodal gravity load */
  PetscScalar *gram;          /* LU of W^T W */
  PetscBLASInt *gram_piv;
  PetscInt   kW;              /* columns of W */

  /* geometric stiffening (flexible_stiffening.c): the Green-Lagrange coupling G(u) */
  PetscBool         stiffening;
  Mat               Gu, Gut;   /* G(u) (G's pattern) and its transpose at the Jacobian's state: its blocks Jsv, Jvs */
  Mat               Gres;      /* G(u) at the residual's state (its own matrix: a residual never changes the Jacobian) */
  Mat               Ksig, Jsu; /* d(G(u)^T Sigma)/du (initial-stress stiffness, Kaij's pattern), d(G(u) v)/du (G's) */
  Mat               Nsu;       /* G(u)^T Ms^{-1} d(G(u) v)/du (Kaij's pattern, not symmetric): its term in the exact Schur complement */
  Mat               Mvs;       /* Mv on Sv's pattern (stiffening or spin: Sv is rebuilt every Jacobian by fast same-pattern sums) */
  MatStructure      kpattern;  /* SAME_NONZERO_PATTERN if Kaij (and Ksig, Nsu) have Sv's pattern, else SUBSET */
  Vec               uloc, vloc; /* local (ghosted) displacement and velocity */
  PetscInt         *cell_vloc;  /* per local cell: local-vector offsets of its velocity closure (PhlexFlexibleSetUpLocalDofs) */
  PhlexElementBasis basis_v, basis_s;
  PetscBool         have_basis;

  /* a uniformly rotating body frame (flexible_spin.c): a fixed body on a hub spinning at a constant rate */
  PetscBool spinning;
  PetscReal spin[3], spin_axis[3], spin_center[3]; /* rad/s, unit vector and m (mesh coordinates) */
  Mat       Cor, Cen;   /* Mv x 2 hat(Omega) (Coriolis) and Mv x hat(Omega)^2 (centrifugal), non-dimensional AIJ */
  Mat       Cor1, Cen1; /* the same at 1 rad/s about the axis (a sweep over the rate scales them) */
  Vec       fcen, fcen1; /* Cen (x - c): the centrifugal load at the drawn geometry; at 1 rad/s */
  KSP       steady_ksp; /* the steady spin's Newton (linearised analysis) */
  PetscBool ic_steady_spin; /* floating: start a transient in the steady state of the frame's spin (PhlexFlexibleSteadySpinStart) */
  Vec       ic_steady_v;    /* its elastic velocity perturbation as the initial condition gave it (the consistent start's projection left out) */
  Mat       Kspin;          /* floating, in its drive's co-rotating frame (linearised analysis, PhlexFlexibleSteadyDrive): K_sigma + Cen */

  /* structural damping (flexible_damping.c): R = alpha Mv + sum over regions of (beta E + eta) / E K_region on the
     velocity rows (symmetric positive semi-definite), assembled once */
  PetscReal rayleigh_alpha, rayleigh_beta; /* SI: 1/s, s */
  PetscBool damped;                        /* alpha, beta or a viscosity > 0 */
  Mat       Rd;                            /* R (AIJ, non-dimensional: velocity rows in time T), NULL until needed: the
                                              sums into the condensed operator and the fixed body's Jvv */
  Mat       Rsb;                           /* R as assembled (SBAIJ, 3x3 blocks, upper triangle): the products R v, about
                                              half the time of the AIJ copy's */
  Vec       veval, rv;                     /* the evaluated state's velocity (a copy), R veval (formed when asked for) */
  PetscReal diss_loc;                      /* this process's part of veval^T R veval */
  PetscBool evaluated, rv_valid;           /* veval holds the evaluated state's v; rv and diss_loc are its */

  /* output */
  void *writer, *rigid_csv, *ports_csv;

  /* sizes and integrals */
  PetscInt  nv_local, ns_local;
  PetscInt  nv_global, ns_global;
  PetscReal volume, mass;      /* SI */
  PetscReal center_of_mass[3]; /* SI */
};

/* mesh.c */
PETSC_INTERN PetscErrorCode PhlexMeshReadPhysicalNames(MPI_Comm, const char[], const char[], PetscInt *, PhlexPhysicalGroup **);
PETSC_INTERN PetscErrorCode PhlexMeshLoad(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexMeshFindGroup(PhlexFlexible, const char[], PetscInt, const char[], PetscInt *);
PETSC_INTERN PetscErrorCode PhlexMeshCheckGeometry(PhlexFlexible);

/* partition_metis.c: PetscPartitioner "phlexmetis" */
PETSC_INTERN PetscErrorCode PhlexPartitionerRegister(void);

/* flexible_fe.c: spaces and constant operators */
PETSC_INTERN PetscErrorCode PhlexFlexibleSetUpFE(PhlexFlexible, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFlexiblePreconditionerRateGet(PhlexPart, PetscReal[10]);
PETSC_INTERN PetscErrorCode PhlexFlexiblePreconditionerRateSet(PhlexPart, const PetscReal[10]);
PETSC_INTERN PetscErrorCode PhlexFlexibleSetUpMixed(PhlexFlexible, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSetUpInertia(PhlexFlexible, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFlexibleGetBasis(PhlexFlexible, PetscBool, PhlexElementBasis *);
PETSC_INTERN PetscErrorCode PhlexFlexibleRestoreBasis(PhlexElementBasis *);
PETSC_INTERN PetscErrorCode PhlexFlexibleDestroyFE(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexiblePlacement(PhlexFlexible, uint64_t *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSetUpLocalDofs(PhlexFlexible);
/* flexible_p1.c: the P1 coarse space of p-multigrid */
PETSC_INTERN PetscErrorCode PhlexFlexibleCoarseSpace(PhlexFlexible, PetscInt, PetscInt, Mat, PetscInt *, PetscInt[]);

/* flexible_stress_maps.c: B = Ms^{-1} G, G^T and K cell by cell, a linear stage's fused stress passes, the strain energy */
PETSC_INTERN PetscErrorCode PhlexFlexibleCreateStressMaps(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexibleStressMapsDestroy(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexibleStrainEnergyLocal(PhlexFlexible, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexStressMapsPredict(Mat, Vec, Vec, PetscReal, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexStressMapsCorrect(Mat, Vec, Vec, PetscReal, Vec);

/* flexible_port.c */
typedef PetscErrorCode (*PhlexSurfaceFunc)(void *, PetscInt, const PetscReal *, const PetscReal *, const PetscReal *, const PetscInt *, const PetscInt *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexSurfaceIntegrate(PhlexFlexible, PetscInt, PetscInt, PhlexSurfaceFunc, void *);
PETSC_INTERN PetscErrorCode PhlexSurfaceMoments(PhlexFlexible, PetscInt, PetscReal *, PetscReal[3], PetscReal[9]);
PETSC_INTERN PetscErrorCode PhlexFlexPortSetUp(PhlexFlexible, PhlexFlexPort *, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFlexPortDestroy(PhlexFlexPort *);

/* flexible_damping.c */
PETSC_INTERN PetscErrorCode PhlexFlexibleAssembleDamping(PhlexFlexible, const PhlexUnits *, Mat *);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingSetFromOptions(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingSetUp(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingEvaluate(PhlexPart, Vec);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingForce(PhlexPart);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingView(PhlexFlexible, PetscViewer);
PETSC_INTERN PetscErrorCode PhlexFlexibleDampingDestroy(PhlexFlexible);

/* flexible_ic.c */
PETSC_INTERN PetscErrorCode PhlexFlexibleICSetFromOptions(PhlexFlexible, PhlexIC *, const char[], PetscInt);
PETSC_INTERN PetscErrorCode PhlexFlexiblePrepareInitialState(PhlexPart);
PETSC_INTERN PetscBool      PhlexFlexibleFrameVelocity(PhlexFlexible, PetscReal[3], PetscReal[3]);
PETSC_INTERN PetscErrorCode PhlexFlexibleInitialState(PhlexPart, PhlexPartVec *);

/* flexible_stiffening.c, flexible_spin.c */
PETSC_INTERN PetscErrorCode PhlexFlexibleStiffeningSetUp(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexibleCouplingUpdate(PhlexFlexible, Vec);
PETSC_INTERN PetscErrorCode PhlexFlexibleStiffeningJacobian(PhlexFlexible, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexFlexibleStressOfDisplacement(PhlexFlexible, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexFlexibleStiffeningDestroy(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexibleSpinSetUp(PhlexFlexible, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSpinEnergy(PhlexFlexible, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSpinSteadyState(PhlexPart, PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSpinRate(PhlexPart, PetscBool, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSpinDestroy(PhlexFlexible);
PETSC_INTERN PetscErrorCode PhlexFlexibleSteadySpinStart(PhlexPart, PhlexPartVec *, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexFlexibleSteadyDrive(PhlexPart, PetscInt, const PetscReal[3], const PetscReal *);

/* flexible_modes.c */
PETSC_INTERN PetscErrorCode PhlexFlexibleComputeModes(PhlexPart, PetscInt, PetscInt *, PetscInt *, PetscReal **, Vec **, PetscReal **, PetscReal **);
PETSC_INTERN PetscErrorCode PhlexFlexibleFirstElasticEigenvalue(PhlexPart, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexModesLowestFirst(PetscBool *);
PETSC_INTERN PetscErrorCode PhlexFlexibleModesAnalysis(PhlexPart, PetscInt, PetscInt *, PetscInt *, PetscReal **, Vec **, PetscReal **, PetscReal **);
PETSC_INTERN PetscErrorCode PhlexFlexibleModesRequestCheck(PhlexPart, PetscInt, const char[], PetscInt);
PETSC_INTERN PetscErrorCode PhlexFlexiblePortInput(PhlexPart, PhlexFlexible, PetscBool, const PhlexFrameState *, PetscInt, PetscReal, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexFlexiblePortSeriesRow(PhlexPart, PhlexFlexible, PetscBool, const PhlexFrameState *, PetscReal (*)[6], PetscReal, const PhlexPartVec *, PetscViewer);
PETSC_INTERN PetscErrorCode PhlexFlexibleModesOutput(PhlexPart, PhlexOutput, PetscInt, PetscInt, const PetscReal *, Vec *, const PetscReal *, const PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFlexibleRefine(PhlexPart, PetscInt, PhlexPart *);
PETSC_INTERN PetscErrorCode PhlexFlexibleModesOrder(PhlexPart, char[], size_t);
PETSC_INTERN PetscErrorCode PhlexFlexibleModesKind(PhlexPart, char[], size_t, PetscInt *);

#endif
