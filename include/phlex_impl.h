/* phlex private structs; included by src/ only. */
#ifndef PHLEX_IMPL_H
#define PHLEX_IMPL_H

#include <phlex.h>

#define PHLEX_NAME_LEN 64
#define PHLEX_MAX_PORTS 16
#define PHLEX_MAX_BORDER 32 /* PC phlexbordered: largest border and basis */
#define PHLEX_MAX_MATERIALS 16

/* Stress components (Voigt order) of the 6-component stress field; shear components hold the tensor entry. */
enum { PHLEX_S_XX, PHLEX_S_YY, PHLEX_S_ZZ, PHLEX_S_YZ, PHLEX_S_XZ, PHLEX_S_XY };

/* Fields of the global unknown vector, each contiguous on every rank (layout.c). */
typedef enum {
  PHLEX_FIELD_DISPLACEMENT,
  PHLEX_FIELD_STRESS,
  PHLEX_FIELD_VELOCITY,
  PHLEX_FIELD_RIGID, /* floating bodies only: r, R, v_P, w_P */
  PHLEX_NUM_FIELDS
} PhlexField;
PETSC_EXTERN const char *const PhlexFieldNames[];

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

/* layout.c: named fields contiguous per rank, exposed as a DMShell for PCFIELDSPLIT */
#define PHLEX_LAYOUT_MAX_FIELDS 8
typedef struct _p_PhlexLayout *PhlexLayout;
typedef PetscErrorCode (*PhlexLayoutPmatFn)(void *, PetscInt, const PetscInt[], Mat *);
PETSC_INTERN PetscErrorCode PhlexLayoutCreateDM(MPI_Comm, PetscInt, const char *const[], const PetscInt[], const PetscInt[], PhlexLayoutPmatFn, void *, DM *);
PETSC_INTERN PetscErrorCode PhlexLayoutGetFieldIS(DM, PetscInt, IS *);

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
} PhlexMaterial;

/* Time profile f(t) multiplying an input amplitude. */
typedef enum {
  PHLEX_PROFILE_CONSTANT,
  PHLEX_PROFILE_RAMP,
  PHLEX_PROFILE_SINE,
  PHLEX_PROFILE_TABLE
} PhlexProfileType;
PETSC_EXTERN const char *const PhlexProfileTypes[];

struct _p_PhlexProfile {
  MPI_Comm         comm;
  char             prefix[256];
  char             what[128]; /* used in messages: "body cantilever, port tip" */
  PhlexProfileType type;
  PetscReal        start_time, ramp_time, frequency, phase, scale;
  PetscInt         ntable;
  PetscReal       *table_t, *table_f;
};

/* A port: a named boundary surface of a body carrying a wrench input (force F, moment T about the patch
   centroid c) distributed as tau = F/A + (I_c^{-1} T) x (x - c) (DESIGN section 3), and the collocated output
   y = B^T v (patch-average velocity, patch-average angular velocity). */
struct _p_PhlexPort {
  char         name[PHLEX_NAME_LEN];
  PetscInt     tag;
  PetscReal    area, centroid[3], inertia[9], inertia_inv[9]; /* SI patch geometry */
  Vec          dist[6];                                      /* B columns: nodal loads of unit wrench components (nondim) */
  PetscReal    force[3], moment[3];                          /* input amplitudes (SI) */
  PetscBool    loaded;                                       /* any nonzero input amplitude */
  PetscBool    traction_input;                               /* amplitude given as a traction [Pa] */
  PhlexProfile profile;
};

/* Inertia invariants of a floating body about its frame origin P (non-dimensional). */
typedef struct {
  PetscReal m, s0[3], E0[9]; /* int rho, int rho x, int rho x x^T */
  PetscReal vol, svol[3];    /* int 1, int x */
} PhlexInertia;

/* A floating body evaluated at a state and its rates (floating.c); all non-dimensional, body frame. */
typedef struct {
  PetscReal r[3], R[9], vP[3], w[3], rd[3], Rd[9], vPd[3], wd[3];
  PetscReal m, s[3], sd[3], sgrav[3], Vf[3], Vfd[3], E[9], Ed[9], J[9], Jd[9], L[3], Ld[3];
  PetscReal pt[3], pr[3], ptd[3], prd[3], gbody[3], Fext[3], Mext[3];
  Vec       Mu, Mvv, Mud, Mvd, bext; /* Mv u, Mv v, Mv u', Mv v', elastic load */
} PhlexFloatingState;

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
  PetscReal   value[6];    /* uniform: velocity (3) or stress (6); rigid: translation velocity */
  PetscReal   angular[3];  /* rigid: angular velocity, about 'origin' */
  PetscReal   origin[3];
  PetscInt    mode;        /* mode number (1-based) for PHLEX_IC_MODE and PHLEX_IC_BEAM */
  PetscReal   amplitude;   /* max |field| for modes, tip value for beam */
  PetscReal   direction[3];/* beam deflection direction */
} PhlexIC;

struct _p_PhlexBody {
  MPI_Comm           comm;
  PetscInt           index;
  char               prefix[32];
  char               name[PHLEX_NAME_LEN];
  char               mesh_file[PETSC_MAX_PATH_LEN];
  PetscInt           ngroups;
  PhlexPhysicalGroup *groups;
  PetscInt           degree;                          /* velocity P_k, stress P_{k-1} discontinuous */
  PetscInt           extra_refinements;               /* uniform refinements on top of -dm_refine (convergence studies) */
  char               frame_patch[PHLEX_NAME_LEN];     /* Dirichlet patch Gamma_D ("" for a free body) */
  PetscInt           frame_tag;
  PetscReal          frame_area, frame_centroid[3], frame_inertia[9]; /* SI geometry of the frame patch */
  PetscInt           nmaterials;
  PhlexMaterial      materials[PHLEX_MAX_MATERIALS];
  PetscInt           nports;
  struct _p_PhlexPort ports[PHLEX_MAX_PORTS];
  PetscReal          body_force[3];                   /* N/m^3, body frame */
  PhlexProfile       body_force_profile;
  PetscBool          has_body_force;
  PhlexIC            ic_velocity, ic_displacement, ic_stress;

  /* floating frame (issue: floating body) */
  PetscBool          floating;                        /* rigid motion of the frame is an unknown */
  PetscBool          frozen_inertia;                  /* inertia terms at u_f = 0 */
  PetscReal          origin[3];                       /* frame origin P (SI mesh coordinates): frame-patch centroid */
  PetscReal          position0[3], rotation0[9];      /* initial r_P [m] and R */
  PetscBool          position_given;
  PetscReal          velocity0[3], omega0[3];         /* initial v_P [m/s], w_P [rad/s] (body frame) */
  PetscReal          frame_force[3], frame_moment[3]; /* wrench at P [N, N m] (body frame) */
  PhlexProfile       frame_profile;
  PetscBool          frame_loaded;
  PetscReal          gravity[3];                      /* non-dimensional, inertial frame */
  PhlexInertia       inertia;
  Vec                tnode, wnode, vnode;             /* per node: int rho phi, int rho x phi, int phi (triples) */

  /* discretisation */
  DM       dm;       /* DMPlex with the velocity field (P_k vector, essential BC on the frame patch) */
  DM       dm_s;     /* clone with the stress field (P_{k-1} discontinuous, 6 components) */
  PetscFE  fe_v, fe_s;
  PetscInt cStart, cEnd;
  PetscInt nb_v, nb_s;            /* basis functions per cell (all components) */
  PetscInt *cell_material;        /* material index per local cell */
  PetscInt *cell_vdofs;           /* per local cell: global velocity dofs of its closure (negative: constrained) */
  PetscInt *cell_soff;            /* per local cell: global offset of its stress dofs */
  PhlexElementReferenceIntegrals ref; /* reference-cell integrals of the two bases */
  PetscReal *cell_geom;           /* per local cell: detJ, invJ[9] (non-dimensional) */
  PetscReal bbox_min[3], bbox_max[3];

  /* constant body-frame operators (non-dimensional), assembled once */
  Mat Mv;   /* velocity mass  int rho phi.phi */
  Mat K;    /* condensed stiffness G^T Ms^{-1} G (exact, element by element) */
  Mat G;    /* coupling int Sigma : Grad(v), stress rows x velocity columns */
  Mat Ms;   /* compliance mass int Sigma : D^{-1} Sigma, block diagonal (BAIJ, one block per cell) */
  Vec fvol[3]; /* int phi e_c dOmega (for uniform body forces) */

  /* sizes and integrals */
  PetscInt  nv_local, ns_local;
  PetscInt  nv_global, ns_global;
  PetscReal volume, mass;          /* SI */
  PetscReal center_of_mass[3];     /* SI */
};

/* Output of one run: a directory with fields (HDF5 + XDMF per body) and CSV series, written under temporary
   names and renamed when complete. */
struct _p_PhlexOutput {
  MPI_Comm  comm;
  char      dir[PETSC_MAX_PATH_LEN];
  PetscInt  interval;                 /* field output every n steps (0: initial and final only) */
  PetscBool fields;                   /* write HDF5/XDMF */
  PetscInt  nfiles;
  char      tmp[32][PETSC_MAX_PATH_LEN], final[32][PETSC_MAX_PATH_LEN];
};

struct _p_PhlexScene {
  MPI_Comm          comm;
  PhlexAnalysisType analysis;
  PetscInt          nbodies;
  PhlexBody        *bodies;
  PhlexUnits        units;
  PetscReal         scale_length, scale_density, scale_modulus; /* user overrides (0: automatic) */
  PetscReal         gravity[3];                                 /* m/s^2, inertial frame */
  PhlexOutput       output;
  PetscBool         setup;
};

/* The discrete system of a scene for time integration (system.c): unknowns [displacement | stress | velocity]
   (+ [rigid] for a floating body), non-dimensional, residual F(t, X, X') and Jacobian dF/dX + shift dF/dX' as a
   MATNEST of the body operators. */
typedef struct {
  PhlexScene         scene;
  PhlexBody          body;
  DM                 dm;                      /* layout DMShell */
  PetscInt           nfields;                 /* 3 (fixed body) or 4 (floating) */
  PetscInt           qlocal;                  /* rigid unknowns on this rank: 18 on rank 0 of a floating body */
  PetscBool          floating;
  IS                 is[PHLEX_NUM_FIELDS];    /* field index sets */
  Mat                J;                       /* MATNEST Jacobian (Amat and Pmat) */
  Mat                Jaij;                    /* the same assembled as AIJ (-phlex_jacobian_aij) */
  PetscBool          use_aij;
  Mat                Juu, Juv, Jss, Jsv, Jvs, Jvv, Jvu, Gt;
  Mat                Mv, K;                   /* the body's velocity mass and stiffness as AIJ */
  Mat                Sv;                      /* shift Mv + K/shift: condensed velocity operator */
  Mat                Ssv;                     /* [[-shift Ms, G], [G^T, shift Mv]] assembled (fixed body) */
  Mat                Bc, Cu, Cv, Cpre, Arr;   /* floating: dense borders and rigid block */
  Mat                CuT, CvT, CpreT;         /* their virtual transposes (rigid rows) */
  Mat                Pvq;                     /* floating: preconditioner of the {velocity, rigid} split */
  Mat                W;                       /* floating: basis of the state-independent borders (n x 12) */
  PetscReal          Bvv[9], Bvu[9];          /* floating: node-wise blocks applied after Mv */
  PhlexFloatingState fs;                      /* floating: last evaluated state */
  Vec                ud, vd;                  /* work: non-dimensional rates */
  PetscReal          shift;                   /* non-dimensional shift of the assembled operators (0: none yet) */
  Vec                load;                    /* work: load vector in the velocity space */
} PhlexSystem;
PETSC_INTERN PetscErrorCode PhlexSystemCreate(PhlexScene, PhlexSystem **);
PETSC_INTERN PetscErrorCode PhlexSystemIFunction(TS, PetscReal, Vec, Vec, Vec, void *);
PETSC_INTERN PetscErrorCode PhlexSystemIJacobian(TS, PetscReal, Vec, Vec, PetscReal, Mat, Mat, void *);
PETSC_INTERN PetscErrorCode PhlexSystemDestroy(PhlexSystem **);
PETSC_INTERN PetscErrorCode PhlexSystemGetRigid(PhlexSystem *, Vec, PetscReal[18]);
PETSC_INTERN PetscErrorCode PhlexSystemEvaluateFloating(PhlexSystem *, PetscReal, Vec, Vec);

/* pcbordered.c */
PETSC_INTERN PetscErrorCode PhlexPCRegister(void);

/* rigid.c */
PETSC_INTERN void      PhlexCross(const PetscReal[3], const PetscReal[3], PetscReal[3]);
PETSC_INTERN PetscReal PhlexDot3(const PetscReal[3], const PetscReal[3]);
PETSC_INTERN void      PhlexSkew(const PetscReal[3], PetscReal[9]);
PETSC_INTERN void      PhlexMatVec3(const PetscReal[9], const PetscReal[3], PetscReal[3]);
PETSC_INTERN void      PhlexMatTVec3(const PetscReal[9], const PetscReal[3], PetscReal[3]);
PETSC_INTERN void      PhlexMatMat3(const PetscReal[9], const PetscReal[9], PetscReal[9]);
PETSC_INTERN PetscReal PhlexOrthogonalityError(const PetscReal[9]);
PETSC_INTERN void      PhlexOrthonormalize(PetscReal[9]);
PETSC_INTERN void      PhlexRotationToQuaternion(const PetscReal[9], PetscReal[4]);
PETSC_INTERN void      PhlexQuaternionToRotation(const PetscReal[4], PetscReal[9]);
PETSC_INTERN void      PhlexAxisAngleToRotation(const PetscReal[3], PetscReal, PetscReal[9]);

/* floating.c */
PETSC_INTERN PetscErrorCode PhlexBodySetUpFloating(PhlexBody, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexFloatingEvaluate(PhlexBody, const PhlexUnits *, PetscReal, Vec, Vec, Vec, Vec, const PetscReal[18], const PetscReal[18], PhlexFloatingState *);
PETSC_INTERN PetscErrorCode PhlexFloatingInputs(PhlexBody, const PhlexUnits *, PetscReal, Vec, PhlexFloatingState *);
PETSC_INTERN PetscErrorCode PhlexFloatingResidual(PhlexBody, PhlexFloatingState *, Vec, Vec, Vec, Vec, PetscReal[18]);
PETSC_INTERN PetscErrorCode PhlexFloatingJacobian(PhlexBody, PhlexFloatingState *, PetscReal, Vec, Vec, PetscScalar *, PetscScalar *, PetscScalar *, PetscInt, PetscReal[9], PetscReal[9], PetscReal[324]);
PETSC_INTERN PetscErrorCode PhlexFloatingPortOutputs(PhlexBody, const PhlexUnits *, const PetscReal[3], const PetscReal[3], Vec, Vec, Vec, PetscReal[][6]);
PETSC_INTERN PetscErrorCode PhlexFloatingEnergy(PhlexBody, PhlexFloatingState *, Vec, PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFloatingMomenta(PhlexFloatingState *, PetscReal[3], PetscReal[3]);
PETSC_INTERN PetscErrorCode PhlexFloatingStateDestroy(PhlexFloatingState *);

/* mesh.c */
PETSC_INTERN PetscErrorCode PhlexMeshReadPhysicalNames(MPI_Comm, const char[], const char[], PetscInt *, PhlexPhysicalGroup **);
PETSC_INTERN PetscErrorCode PhlexMeshLoad(PhlexBody);
PETSC_INTERN PetscErrorCode PhlexMeshFindGroup(PhlexBody, const char[], PetscInt, const char[], PetscInt *);
PETSC_INTERN PetscErrorCode PhlexMeshCheckGeometry(PhlexBody, const PhlexUnits *);

/* body.c */
PETSC_INTERN PetscErrorCode PhlexBodySetUpMixed(PhlexBody, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexBodyGetBasis(PhlexBody, PetscBool, PhlexElementBasis *);
PETSC_INTERN PetscErrorCode PhlexBodyRestoreBasis(PhlexElementBasis *);
PETSC_INTERN PetscErrorCode PhlexBodyEnergy(PhlexBody, Vec, Vec, PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexBodyLoadVector(PhlexBody, PetscReal, const PhlexUnits *, Vec);
PETSC_INTERN PetscErrorCode PhlexBodyPortOutputs(PhlexBody, Vec, PetscReal[][6]);
PETSC_INTERN PetscErrorCode PhlexBodyInputPower(PhlexBody, Vec, PetscReal, const PhlexUnits *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexBodyCellStressAverages(PhlexBody, Vec, Vec);

/* port.c */
PETSC_INTERN PetscErrorCode PhlexPortSetFromOptions(PhlexBody, PhlexPort);
PETSC_INTERN PetscErrorCode PhlexPortSetUp(PhlexBody, PhlexPort, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexPortInput(PhlexPort, PetscReal, const PhlexUnits *, PetscReal[6]);
PETSC_INTERN PetscErrorCode PhlexPortDestroy(PhlexPort);
typedef PetscErrorCode (*PhlexSurfaceFunc)(void *, PetscInt, const PetscReal *, const PetscReal *, const PetscReal *, const PetscInt *, const PetscInt *, PetscInt);
PETSC_INTERN PetscErrorCode PhlexSurfaceIntegrate(PhlexBody, PetscInt, PetscInt, PhlexSurfaceFunc, void *);
PETSC_INTERN PetscErrorCode PhlexSurfaceMoments(PhlexBody, PetscInt, PetscReal *, PetscReal[3], PetscReal[9]);

/* output.c */
typedef struct _p_PhlexFieldWriter *PhlexFieldWriter;
PETSC_INTERN PetscErrorCode PhlexOutputCreate(MPI_Comm, PhlexOutput *);
PETSC_INTERN PetscErrorCode PhlexOutputSetFromOptions(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputFile(PhlexOutput, const char[], char[]);
PETSC_INTERN PetscErrorCode PhlexOutputCSVOpen(PhlexOutput, const char[], const char[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexOutputCommit(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputAbort(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputDestroy(PhlexOutput *);
PETSC_INTERN PetscErrorCode PhlexFieldWriterCreate(PhlexOutput, PhlexBody, const char[], PhlexFieldWriter *);
PETSC_INTERN PetscErrorCode PhlexFieldWriterBeginStep(PhlexFieldWriter, PetscReal);
PETSC_INTERN PetscErrorCode PhlexFieldWriterVertexField(PhlexFieldWriter, const char[], Vec, PetscReal, const PetscReal *, const PetscReal *, PetscBool);
PETSC_INTERN PetscErrorCode PhlexFieldWriterVertexMax(PhlexFieldWriter, Vec, PetscReal, const PetscReal *, const PetscReal *, PetscBool, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFieldWriterStress(PhlexFieldWriter, Vec, PetscReal);
PETSC_INTERN PetscErrorCode PhlexFieldWriterSetGeometryField(PhlexFieldWriter, const char[]);
PETSC_INTERN PetscErrorCode PhlexFieldWriterDestroy(PhlexFieldWriter *);

/* modes.c */
PETSC_INTERN PetscErrorCode PhlexBodyComputeModes(PhlexBody, const PhlexUnits *, PetscInt, PetscInt *, PetscInt *, PetscReal **, Vec **, PetscReal **, PetscReal **);

/* error.c: option input with checked length */
PETSC_INTERN PetscErrorCode PhlexOptionsRealN(PetscOptionItems *, MPI_Comm, const char[], const char[], const char[], const char[], const char[], PetscInt, PetscReal[], PetscBool *);

/* expect.c: self-verification */
PETSC_INTERN PetscErrorCode PhlexExpectMax(MPI_Comm, const char[], const char[], PetscReal, PetscReal, PetscBool);
PETSC_INTERN PetscErrorCode PhlexExpectValues(MPI_Comm, const char[], const char[], PetscInt, const PetscReal[], PetscInt, const PetscReal[], PetscReal);

#endif
