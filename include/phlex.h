/* phlex: flexible multibody dynamics of 3D elastic bodies in port-Hamiltonian form (PETSc/SLEPc).
   Public handles, enums and prototypes. The structs live in phlex_impl.h and include/private/. */
#ifndef PHLEX_H
#define PHLEX_H

#include <petscts.h>
#include <petscdmplex.h>
#include <slepceps.h>
#include <slepcpep.h>

typedef struct _p_PhlexScene   *PhlexScene;
typedef struct _p_PhlexPart    *PhlexPart;  /* any part of a mechanism: flexible body, rigid body, lumped mass, ground */
typedef struct _p_PhlexJoint   *PhlexJoint; /* a transformer interconnection between two ports */
typedef struct _p_PhlexProfile *PhlexProfile;
typedef struct _p_PhlexOutput  *PhlexOutput;

typedef enum {
  PHLEX_ANALYSIS_TRANSIENT,
  PHLEX_ANALYSIS_MODES,
  PHLEX_ANALYSIS_LINEARIZED,
  PHLEX_ANALYSIS_REDUCE
} PhlexAnalysisType;
PETSC_EXTERN const char *const PhlexAnalysisTypes[];

/* Reference scales of the non-dimensionalisation (SI), one set for the whole scene. Every internal quantity is
   divided by its scale. */
typedef struct {
  PetscReal length;   /* L [m] */
  PetscReal density;  /* rho_ref [kg/m^3] */
  PetscReal modulus;  /* E_ref [Pa], also the stress scale */
  PetscReal time;     /* T = L sqrt(rho_ref/E_ref) [s] */
  PetscReal velocity; /* L/T [m/s] */
  PetscReal mass;     /* rho_ref L^3 [kg] */
  PetscReal force;    /* E_ref L^2 [N] */
  PetscReal energy;   /* E_ref L^3 [J] */
  PetscReal power;    /* energy/T [W] */
} PhlexUnits;

/* log.c */
PETSC_EXTERN PetscClassId  PHLEX_CLASSID;
PETSC_EXTERN PetscLogEvent PHLEX_BodySetUp, PHLEX_BodyAssemble, PHLEX_SysIFunction, PHLEX_SysIJacobian, PHLEX_MonitorEnergy, PHLEX_ModesSolve, PHLEX_Output, PHLEX_PortDist, PHLEX_FloatResidual, PHLEX_FloatJacobian, PHLEX_BorderedBasis, PHLEX_BorderedSetUp, PHLEX_JointResidual, PHLEX_JointJacobian, PHLEX_Assembly, PHLEX_CondensedStage, PHLEX_CondensedSetUp, PHLEX_ReducedStage, PHLEX_ReducedSetUp, PHLEX_ReducedJacobianMult, PHLEX_MatMultBlock, PHLEX_StressMaps, PHLEX_BlockCG, PHLEX_MatBlockCopy, PHLEX_PMGCoarse;
PETSC_EXTERN PetscLogStage PHLEX_StageSetup, PHLEX_StageTransient, PHLEX_StageModes;
PETSC_EXTERN PetscErrorCode PhlexLogRegister(void);
PETSC_EXTERN PetscErrorCode PhlexLogStagePush(const char[], PetscLogStage *);

/* error.c: exit codes of bin/phlex (README "Exit codes"), the same on every rank */
enum {
  PHLEX_EXIT_SUCCESS   = 0,
  PHLEX_EXIT_INTERNAL  = 1,   /* an unexpected error (a library failure, out of memory, a bug): PETSc's traceback */
  PHLEX_EXIT_INPUT     = 2,   /* bad input: options, scene, mesh, joints, unused (misspelt) options */
  PHLEX_EXIT_NUMERICAL = 3,   /* a numerical failure: Newton or the linear solver diverged, NaN/Inf */
  PHLEX_EXIT_IO        = 4,   /* the output could not be written */
  PHLEX_EXIT_SELFCHECK = 5,   /* a -expect_* self-check failed (the results were written) */
  PHLEX_EXIT_SIGINT    = 130, /* interrupted by SIGINT (128 + 2), SIGTERM gives 143 (128 + 15) */
};
PETSC_EXTERN PetscErrorCode PhlexErrorHandlerPush(void);
PETSC_EXTERN PetscErrorCode PhlexErrorHandlerPop(void);
PETSC_EXTERN int            PhlexExitCode(void);

/* help.c: -help prints the options and runs nothing */
typedef enum {
  PHLEX_HELP_NONE,
  PHLEX_HELP_OPTIONS,
  PHLEX_HELP_SOLVERS
} PhlexHelpMode;
PETSC_EXTERN const char     PhlexUsage[];
PETSC_EXTERN PhlexHelpMode  PhlexHelpParseArgs(int *, char **);
PETSC_EXTERN PhlexHelpMode  PhlexHelpGetMode(void);
PETSC_EXTERN PetscErrorCode PhlexHelpActivate(MPI_Comm);
PETSC_EXTERN PetscErrorCode PhlexHelpEnd(MPI_Comm, PetscBool, const char[]);
PETSC_EXTERN PetscErrorCode PhlexHelpCaptureBegin(void);
PETSC_EXTERN PetscErrorCode PhlexHelpCaptureEnd(PetscInt *, char ***);

/* options_check.c: misspelt options fail before the run */
PETSC_EXTERN PetscErrorCode PhlexOptionsCheckUnused(MPI_Comm, PetscErrorCode (*)(void *), void *);
PETSC_EXTERN PetscErrorCode PhlexOptionsWarnUnused(MPI_Comm);
PETSC_EXTERN PetscErrorCode PhlexOptionsSetUsedFromFile(const char[], const char *const[]);
PETSC_EXTERN PetscErrorCode PhlexOptionsSetUsedOverridden(const char[]);
PETSC_EXTERN PetscErrorCode PhlexOptionsCommandLineHasPrefix(const char *const[], PetscBool *);
PETSC_EXTERN PetscErrorCode PhlexOptionsSetPathRenames(const char *const[], const char *const[]);

/* scene_file.c: the YAML syntax of the scene files, before PETSc reads them; where each option of a file comes from */
PETSC_EXTERN int            PhlexSceneFilesCheck(int, char **);
PETSC_EXTERN PetscErrorCode PhlexOptionsOriginAddFile(const char[]);
PETSC_EXTERN PetscErrorCode PhlexOptionsOrigin(const char[], const char **, int *, const char **, PetscBool *);
PETSC_EXTERN void           PhlexOptionsOriginFree(void);

/* interrupt.c: SIGINT/SIGTERM end the run at the next step */
PETSC_EXTERN PetscErrorCode PhlexInterruptPush(void);
PETSC_EXTERN PetscErrorCode PhlexInterruptCheck(MPI_Comm, const char[]);
PETSC_EXTERN PetscErrorCode PhlexInterruptPending(MPI_Comm, int *);
PETSC_EXTERN PetscBool      PhlexInterruptLocal(void);
PETSC_EXTERN int            PhlexInterruptExitCode(void);

/* profile.c: scalar time profiles f(t) multiplying an input */
PETSC_EXTERN PetscErrorCode PhlexProfileCreate(MPI_Comm, const char[], const char[], PhlexProfile *);
PETSC_EXTERN PetscErrorCode PhlexProfileSetFromOptions(PhlexProfile);
PETSC_EXTERN PetscErrorCode PhlexProfileEvaluate(PhlexProfile, PetscReal, PetscReal *);
PETSC_EXTERN PetscErrorCode PhlexProfileIntegrate(PhlexProfile, PetscReal, PetscReal *);
PETSC_EXTERN PetscErrorCode PhlexProfileView(PhlexProfile, PetscViewer);
PETSC_EXTERN PetscErrorCode PhlexProfileDescribe(PhlexProfile, char[], size_t);
PETSC_EXTERN PetscErrorCode PhlexProfileDerivative(PhlexProfile, PetscReal, PetscReal *);
PETSC_EXTERN PetscErrorCode PhlexProfileBounds(PhlexProfile, PetscReal *, PetscReal *);
PETSC_EXTERN PetscErrorCode PhlexProfileGiven(const char[], PetscBool *);
PETSC_EXTERN PetscErrorCode PhlexProfileCheckRange(PhlexProfile, PetscReal, PetscReal, const char[]);
PETSC_EXTERN PetscErrorCode PhlexProfileCheckRangeAll(PetscReal, PetscReal, const char[]);
PETSC_EXTERN PetscErrorCode PhlexProfileDestroy(PhlexProfile *);

/* scene.c */
PETSC_EXTERN PetscErrorCode PhlexSceneCreate(MPI_Comm, PhlexScene *);
PETSC_EXTERN PetscErrorCode PhlexSceneSetFromOptions(PhlexScene);
PETSC_EXTERN PetscErrorCode PhlexSceneSetUp(PhlexScene);
PETSC_EXTERN PetscErrorCode PhlexSceneGetAnalysis(PhlexScene, PhlexAnalysisType *);
PETSC_EXTERN PetscErrorCode PhlexSceneView(PhlexScene, PetscViewer);
PETSC_EXTERN PetscErrorCode PhlexSceneDestroy(PhlexScene *);

/* part.c: the part contract (life cycle; the operations are in include/private/part.h) */
PETSC_EXTERN PetscErrorCode PhlexPartRegisterAll(void);
PETSC_EXTERN PetscErrorCode PhlexPartRegister(const char[], PetscErrorCode (*)(PhlexPart));
PETSC_EXTERN PetscErrorCode PhlexPartCreate(MPI_Comm, PetscInt, PhlexPart *);
PETSC_EXTERN PetscErrorCode PhlexPartSetFromOptions(PhlexPart);
PETSC_EXTERN PetscErrorCode PhlexPartView(PhlexPart, PetscViewer);
PETSC_EXTERN PetscErrorCode PhlexPartDestroy(PhlexPart *);

/* joint.c */
PETSC_EXTERN PetscErrorCode PhlexJointCreate(MPI_Comm, const PhlexUnits *, PetscInt, PhlexJoint *);
PETSC_EXTERN PetscErrorCode PhlexJointSetFromOptions(PhlexJoint);
PETSC_EXTERN PetscErrorCode PhlexJointView(PhlexJoint, PetscViewer);
PETSC_EXTERN PetscErrorCode PhlexJointDestroy(PhlexJoint *);

/* modes.c and transient.c: the analyses */
PETSC_EXTERN PetscErrorCode PhlexSceneSolveModes(PhlexScene);
PETSC_EXTERN PetscErrorCode PhlexSceneSolveLinearized(PhlexScene);
PETSC_EXTERN PetscErrorCode PhlexSceneReduce(PhlexScene);
PETSC_EXTERN PetscErrorCode PhlexSceneSolveTransient(PhlexScene);

#endif
