/* The assembled system of a scene (system.c): the global unknowns, the index-2 pHDAE residual F(t, X, X') and its
   Jacobian over all parts and joints, and the border data of PC phlexbordered. */
#ifndef PHLEX_PRIVATE_SYSTEM_H
#define PHLEX_PRIVATE_SYSTEM_H

/* layout.c: named fields contiguous per rank, exposed as a DMShell for PCFIELDSPLIT */
#define PHLEX_LAYOUT_MAX_FIELDS 8
typedef struct _p_PhlexLayout *PhlexLayout;
typedef PetscErrorCode (*PhlexLayoutPmatFn)(void *, PetscInt, const PetscInt[], Mat *);
PETSC_INTERN PetscErrorCode PhlexLayoutCreateDM(MPI_Comm, PetscInt, const char *const[], const PetscInt[], const PetscInt[], PhlexLayoutPmatFn, void *, DM *);
PETSC_INTERN PetscErrorCode PhlexLayoutGetFieldIS(DM, PetscInt, IS *);

/* What PC phlexbordered needs of a bordered system [[A, B], [C, D]] with A block diagonal (one sparse block per
   flexible body) and D dense (the discrete unknowns); composed on its preconditioning matrix as "phlex_border". */
typedef struct {
  PetscInt         nblocks;
  Mat             *A;    /* the sparse blocks (condensed velocity operators) */
  Mat             *W;    /* per block: basis of the state-independent border span (n_i x k_i dense), or NULL */
  PetscInt        *off;  /* per block: first local row in the preconditioner's vector */
  PetscInt        *n;    /* per block: local rows */
  PetscInt         qoff; /* first local row of the discrete unknowns in the preconditioner's vector */
  PetscInt         m;    /* discrete unknowns */
  const PetscReal *D;    /* m x m, row-major, on every rank */
  void            *ctx;
  PetscErrorCode (*rows)(void *, PetscInt, Mat, PetscReal *);       /* C_i Y: m x k column-major */
  PetscErrorCode (*coefficients)(void *, PetscInt, PetscReal *);    /* beta_i with B_i ~ W_i beta_i: k x m column-major */
  PetscErrorCode (*rowsvec)(void *, PetscInt, Vec, PetscReal *);    /* y += C_i x (m values) */
  PetscErrorCode (*blockprefix)(void *, PetscInt, const char **);  /* name used in the options of block i */
  PetscErrorCode (*blockoptions)(void *, PetscInt, const char **); /* options prefix of block i's body (body<k>_) */
  PetscErrorCode (*coarsespace)(void *, PetscInt, PetscInt, PetscInt, Mat, PetscInt *, PetscInt[]); /* block i's coarse space for p-multigrid (PhlexCoarseSpaceFn) */
} PhlexBorderedData;

typedef struct _p_PhlexSystem *PhlexSystem;
struct _p_PhlexSystem {
  PhlexScene        scene;
  MPI_Comm          comm;
  const PhlexUnits *units;
  PetscInt          nparts;
  PhlexPart        *parts;  /* the scene's parts (the ground has no unknowns and is not listed) */
  PetscInt          nfparts;
  PhlexPart        *fparts; /* parts with field blocks */
  PetscInt          njoints;
  PhlexJoint       *joints;
  PetscBool         nonlinear;

  /* layout */
  DM       dm, dm_aux; /* the layout; the same for auxiliary solvers */
  PetscInt nfields;
  PetscInt field[PHLEX_NUM_FIELDS]; /* index of each field in the layout (-1: absent) */
  IS       is[PHLEX_NUM_FIELDS];
  PetscInt nq;                      /* discrete unknowns (all on rank 0) */
  PetscInt qlocal;
  PhlexDofKind *qkind;              /* of every discrete unknown */

  /* replicated discrete values: state, rate (SI time), residual; dense discrete Jacobian (row-major) */
  PetscReal *q, *qd, *fq, *D;

  /* Jacobian: a MATNEST of the field blocks (MATNEST over the flexible bodies when several), shells for the borders
     and the dense discrete block */
  PetscReal shift;
  Mat       J, Jaij;
  PetscBool use_aij;
  Mat       Juu, Juv, Ms, Jss, Jsv, Jvs, Jvv, Jvu, Jsu, Bvq, Cqu, Cqv, Dq;
  Mat       Jvc; /* Jvv + Jvu / shift (block diagonal over the bodies): the velocity block with the displacement eliminated */
  PetscBool state_dependent_fields, inexact_schur; /* a body with geometric stiffening: G(u) and its blocks change with the state */
  PetscBool mixed_released; /* Jsv is a placeholder and the bodies' assembled G and Ms are freed (PhlexSystemReleaseJacobian) */
  PetscBool vv_released;    /* Jvv is a placeholder, Jvc NULL: the fixed bodies' shift Mv freed (PhlexSystemReleaseVelocityBlock) */

  Mat       Sv, Pvq, Ssv, Abd, Cpre;
  IS       *fis[3]; /* per field part: its block in the numbering of the displacement, stress, velocity fields */
  PhlexBorderedData border;
  Vec       *xu, *xv; /* work: per field part */
  Vec        Xwork;    /* work: a whole state (the joints' mid-step geometry) */
  PetscReal  fprev;    /* Newton: the previous residual norm (round-off floor test) */
  PetscReal  jreuse;   /* Newton: the Jacobian is kept for the next iteration after a reduction of the residual below this (0: never) */
  PetscReal  vrtol;    /* Newton on the whole state of a scene with discrete unknowns: the velocity rows' tolerance */
  PetscReal  fv0, fvprev; /* ... their residual at the stage's initial guess and at the previous iterate */
  /* the state the parts and joints were last evaluated at (a Jacobian right after a residual at the same state
     skips the evaluation): the vectors' ids and object states, and the time */
  PetscObjectId    eval_id[2];
  PetscObjectState eval_state[2];
  PetscReal        eval_t;
};

PETSC_INTERN PetscErrorCode PhlexSystemCreate(PhlexScene, PhlexSystem *);
PETSC_INTERN PetscErrorCode PhlexSystemDestroy(PhlexSystem *);
PETSC_INTERN PetscErrorCode PhlexSystemCreateForScene(PhlexScene, PhlexSystem *, Vec *);
PETSC_INTERN PetscErrorCode PhlexSystemIFunction(TS, PetscReal, Vec, Vec, Vec, void *);
PETSC_INTERN PetscErrorCode PhlexSystemReducedResidual(PhlexSystem, PetscReal, Vec, Vec, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemIJacobian(TS, PetscReal, Vec, Vec, PetscReal, Mat, Mat, void *);
PETSC_INTERN PetscErrorCode PhlexSystemGather(PhlexSystem, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexSystemScatter(PhlexSystem, const PetscReal *, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemEvaluate(PhlexSystem, PetscReal, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemPartVec(PhlexSystem, PhlexPart, Vec, PetscReal *, PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexSystemPartVecRestore(PhlexSystem, PhlexPart, Vec, PhlexPartVec *);
PETSC_INTERN PetscErrorCode PhlexSystemInitialState(PhlexSystem, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemPostStep(PhlexSystem, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexSystemJointSides(PhlexSystem, PhlexJoint, Vec, PetscReal *, PhlexPartVec[2]);
PETSC_INTERN PetscErrorCode PhlexSystemJointSidesRestore(PhlexSystem, PhlexJoint, Vec, PhlexPartVec[2]);
PETSC_INTERN PetscErrorCode PhlexSystemEnergy(PhlexSystem, PetscReal, Vec, PetscReal *, PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexSystemUpdateJoints(PhlexSystem, Vec, PetscReal);
PETSC_INTERN PetscErrorCode PhlexSystemInitElements(PhlexSystem, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemSetUpBorder(PhlexSystem);
PETSC_INTERN PetscErrorCode PhlexSystemSNESConverged(SNES, PetscInt, PetscReal, PetscReal, PetscReal, SNESConvergedReason *, void *);
PETSC_INTERN PetscErrorCode PhlexSystemSNESConvergedStage(SNES, PetscInt, PetscReal, PetscReal, PetscReal, SNESConvergedReason *, void *);
PETSC_INTERN PetscErrorCode PhlexSystemBlockDiagonal(PhlexSystem, Mat *, PhlexField, PhlexField, Mat *);
PETSC_INTERN PetscErrorCode PhlexSystemGetFieldBlocks(PhlexSystem, PhlexField, Vec, Vec[]);
PETSC_INTERN PetscErrorCode PhlexSystemRestoreFieldBlocks(PhlexSystem, PhlexField, Vec, Vec[]);
PETSC_INTERN PetscErrorCode PhlexSystemCompleteJacobian(PhlexSystem);
PETSC_INTERN PetscErrorCode PhlexSystemReleaseJacobian(PhlexSystem);
PETSC_INTERN PetscErrorCode PhlexSystemReleaseVelocityBlock(PhlexSystem);
PETSC_INTERN PetscErrorCode PhlexSystemJacobianPmat(PhlexSystem, KSP, Mat *);
PETSC_INTERN PetscErrorCode PhlexSystemCondensedOperator(PhlexSystem, PetscInt, Mat *);
PETSC_INTERN PetscErrorCode PhlexSystemPmat(void *, PetscInt, const PetscInt[], Mat *);

/* border.c: the shells of the border blocks and the callbacks of PC phlexbordered */
PETSC_INTERN PetscErrorCode PhlexBorderCreateShells(PhlexSystem);

/* pcbordered.c */
PETSC_INTERN PetscErrorCode PhlexPCRegister(void);
PETSC_INTERN PetscErrorCode PhlexPCBorderedHelp(PC, PetscInt, const char *const[]);
PETSC_INTERN PetscErrorCode PhlexBlockCGApplies(KSP, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexBlockCG(KSP, Mat, Mat, PetscBool, PetscBool, const char[], PetscInt *, PetscInt *);
PETSC_INTERN PetscErrorCode PhlexSystemVelocityOperator(PhlexSystem, Mat *);
/* pmg.c: p-multigrid (PCMG) with the bodies' P1 coarse space under an iterative solve with the velocity operator */
typedef struct {
  Mat              P;     /* the interpolation from the coarse unknowns (AIJ; built once) */
  Mat              Ac;    /* the coarse operator P^T A P, with the rigid modes as near-null space */
  PhlexMatWatch    A;     /* the operator it was formed from */
  PetscInt         nc;    /* local coarse unknowns */
  PetscInt        *inj;   /* per local coarse unknown: its local fine row */
} PhlexPMG;
typedef PetscErrorCode (*PhlexCoarseSpaceFn)(void *, PetscInt, PetscInt, PetscInt, Mat, PetscInt *, PetscInt[]);
PETSC_INTERN PetscErrorCode PhlexPMGWanted(KSP, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexPMGSetLevels(KSP);
PETSC_INTERN PetscErrorCode PhlexPMGBuild(KSP, MPI_Comm, PetscInt, PetscInt, PetscInt, PetscInt, const PetscInt[], const PetscInt[], PhlexCoarseSpaceFn, void *, PhlexPMG *);
PETSC_INTERN PetscErrorCode PhlexPMGSetUp(KSP, Mat, PhlexPMG *);
PETSC_INTERN PetscErrorCode PhlexPMGSetUpPencil(KSP, Mat, Mat, PetscScalar, MatNullSpace, PhlexPMG *);
/* border.c: block i's coarse space (a part's own, or its unknowns carried): a PhlexCoarseSpaceFn on the system */
PETSC_INTERN PetscErrorCode PhlexSystemCoarseSpace(void *, PetscInt, PetscInt, PetscInt, Mat, PetscInt *, PetscInt[]);
PETSC_INTERN PetscErrorCode PhlexPMGView(PhlexPMG *, PetscViewer);
PETSC_INTERN PetscErrorCode PhlexPMGDestroy(PhlexPMG *);
/* snes_condensed.c: SNES phlexcondensed, the theta-method stage of fixed linear bodies by exact elimination */
PETSC_INTERN PetscErrorCode PhlexSNESRegister(void);
PETSC_INTERN PetscErrorCode PhlexSNESCondensedApplicable(PhlexSystem, TS, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexSNESCondensedSetSystem(SNES, PhlexSystem, TS);
/* the bodies' cell-by-cell products (PhlexFieldOperators B, Kc), referenced per body */
typedef struct {
  Mat *B, *K;
} PhlexStressMaps;
PETSC_INTERN PetscErrorCode PhlexSystemGetStressMaps(PhlexSystem, const char *, PhlexStressMaps *);
PETSC_INTERN PetscErrorCode PhlexSystemStressMapsDestroy(PhlexSystem, PhlexStressMaps *);
PETSC_INTERN PetscErrorCode PhlexSystemStressPredict(PhlexSystem, PhlexStressMaps *, Vec, Vec, PetscReal, Vec, Vec);
PETSC_INTERN PetscErrorCode PhlexSystemStressCorrect(PhlexSystem, PhlexStressMaps *, Vec, Vec, PetscReal, Vec);
/* snes_reduced.c: SNES phlexreduced, Newton on the velocities and discrete unknowns of a theta-method stage */
PETSC_INTERN PetscErrorCode PhlexSNESReducedRegister(void);
PETSC_INTERN PetscErrorCode PhlexSNESReducedApplicable(PhlexSystem, TS, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexSNESReducedSetSystem(SNES, PhlexSystem, TS);
PETSC_INTERN PetscErrorCode PhlexSNESReducedSetStage(SNES, PhlexSystem, Vec, PetscReal, PetscReal, PetscReal);
#define PHLEX_REDUCED_HISTORY 8                                  /* Newton iterations whose contraction a stage keeps */
#define PHLEX_REDUCED_NCONTRACTIONS (6 + 2 * PHLEX_REDUCED_HISTORY) /* their record: iterations, dt, theta, the looser solves' state (off, stages off, wait), two ratios each */
PETSC_INTERN PetscErrorCode PhlexSNESReducedGetContractions(SNES, PetscReal[PHLEX_REDUCED_NCONTRACTIONS]);
PETSC_INTERN PetscErrorCode PhlexSNESReducedSetContractions(SNES, const PetscReal[PHLEX_REDUCED_NCONTRACTIONS]);

/* assembly.c: consistent configuration and velocities, redundancy, drift */
PETSC_INTERN PetscErrorCode PhlexAssemblyPlaceAttached(PhlexSystem, Vec);
PETSC_INTERN PetscErrorCode PhlexAssemblyRedundancy(PhlexSystem, Vec, PetscInt *);
PETSC_INTERN PetscErrorCode PhlexAssemblyClose(PhlexSystem, PetscReal, Vec, PetscBool, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexAssemblyConsistentStart(PhlexSystem, TS, PetscReal, PetscReal, Vec, PetscReal *);

#endif
