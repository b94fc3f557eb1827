/* phlex private declarations; included by src/ only. The layers have their own headers in include/private/:
   part.h (the part contract), flexible.h (flexible bodies), joint.h (joints), system.h (the assembled system). */
#ifndef PHLEX_IMPL_H
#define PHLEX_IMPL_H

#include <phlex.h>
#include <petscblaslapack.h>
#include <private/part.h>

/* what became of a matrix since a product was last taken from it: the same, new values, or another matrix or
   pattern (PhlexMatWatchCheck, mat_block_copy.c; the block copy below and p-multigrid's coarse operator) */
typedef enum { PHLEX_MAT_SAME, PHLEX_MAT_VALUES, PHLEX_MAT_NEW } PhlexMatChange;
typedef struct {
  Mat              src;       /* the matrix watched (referenced) */
  PetscObjectState nz, state; /* its nonzero state and state when last checked */
} PhlexMatWatch;
PETSC_INTERN PetscErrorCode PhlexMatWatchCheck(PhlexMatWatch *, Mat, PhlexMatChange *);
PETSC_INTERN PetscErrorCode PhlexMatWatchReset(PhlexMatWatch *);

/* Time profile f(t) multiplying an input amplitude (profile.c). */
typedef enum {
  PHLEX_PROFILE_CONSTANT,
  PHLEX_PROFILE_RAMP,
  PHLEX_PROFILE_SINE,
  PHLEX_PROFILE_TABLE
} PhlexProfileType;
PETSC_EXTERN const char *const PhlexProfileTypes[];

/* What a table profile is outside its points. */
typedef enum {
  PHLEX_EXTRAPOLATE_HOLD,  /* its first and last values */
  PHLEX_EXTRAPOLATE_ZERO,  /* zero */
  PHLEX_EXTRAPOLATE_ERROR  /* a run reaching outside is refused at set-up (PhlexProfileCheckRange) */
} PhlexExtrapolation;
PETSC_EXTERN const char *const PhlexExtrapolations[];

struct _p_PhlexProfile {
  MPI_Comm           comm;
  char               prefix[256];
  char               what[128]; /* used in messages: "body cantilever, port tip" */
  PhlexProfileType   type;
  PetscReal          start_time, ramp_time, frequency, phase, scale;
  PetscInt           ntable;
  PetscReal         *table_t, *table_f;
  PhlexExtrapolation extrapolate;
  char               file[PETSC_MAX_PATH_LEN]; /* the table's CSV file ("": given inline) */
  char               column[160];              /* the file's column f follows, for messages: "2 ('force')" */
  PetscBool          given;                    /* one of its options was given */
};

/* Output of one run: a directory with fields (HDF5 + XDMF per body) and CSV series, written under temporary names
   and renamed when complete (output.c). */
struct _p_PhlexOutput {
  MPI_Comm  comm;
  char      dir[PETSC_MAX_PATH_LEN];
  PetscInt  interval; /* field output every n steps (0: initial and final only) */
  PetscBool fields;   /* write HDF5/XDMF */
  PetscBool keep_failed; /* a numerical failure keeps the series so far in <dir>/failed/ */
  PetscInt  nfiles, maxfiles;
  char    (*tmp)[PETSC_MAX_PATH_LEN], (*final)[PETSC_MAX_PATH_LEN];
  PetscInt  ncommitted; /* files renamed to their final names so far */
  PetscBool made_dir;   /* this run created the directory (rank 0) */
  PetscBool locked;     /* this run holds <dir>/.phlex.lock */
  /* checkpoints (checkpoint.c, output.c): the series and field writers a checkpoint records */
  PetscViewer *csv;                       /* per file: its CSV viewer, or NULL */
  PetscInt     nwriters;                  /* writers of files with a state of their own (the field writers) */
  void       **writer_ctx;
  PetscErrorCode (**writer_save)(void *, PetscViewer); /* records writer k's state in a checkpoint */
  PetscBool    keep_tmp;                  /* a checkpoint refers to the temporary files: an error keeps them */
  PetscBool   *had_tmp;                   /* per file (rank 0): its temporary file existed before this run (a checkpoint's) */
  PetscBool    wrote_checkpoint;          /* this run wrote a checkpoint that refers to its temporary files */
  PetscLogDouble series_flushed;          /* wall time of the series' last flush (PhlexOutputFlushSeries) */
  PetscViewer  restart;                   /* the checkpoint a restarted run continues (HDF5, read), or NULL */
  char         restart_dir[PETSC_MAX_PATH_LEN]; /* where the interrupted run's series and field segments are */
  PetscInt     nrestart_csv;
  char       (*restart_csv)[PETSC_MAX_PATH_LEN];
  PetscReal   *restart_csv_length;        /* bytes of each series at the checkpoint */
  PetscBool   *restart_csv_used;          /* continued by this run */
};

/* What to do with redundant constraint components found at set-up. */
typedef enum {
  PHLEX_REDUNDANT_ERROR,
  PHLEX_REDUNDANT_DROP,
  PHLEX_REDUNDANT_KEEP
} PhlexRedundantPolicy;
PETSC_EXTERN const char *const PhlexRedundantPolicies[];

struct _p_PhlexScene {
  MPI_Comm             comm;
  PhlexAnalysisType    analysis;
  PetscInt             nparts;
  PhlexPart           *parts;
  PhlexPart            ground;
  PetscInt             njoints;
  PhlexJoint          *joints;
  PhlexUnits           units;
  PetscReal            scale_length, scale_density, scale_modulus; /* user overrides (0: automatic) */
  PetscReal            gravity[3];                                 /* m/s^2, inertial frame */
  PhlexOutput          output;
  PetscBool            setup;
  PhlexRedundantPolicy redundant;
  PetscReal            assembly_tol;    /* position-level closure tolerance, relative to the reference length */
  PetscInt             assembly_max_it;
  PetscInt             project_interval; /* drift projection every n steps (0: never) */
  PetscBool            whole_bodies;     /* each flexible body whole on one process (-whole_bodies) */
};

#include <private/flexible.h>
#include <private/joint.h>
#include <private/system.h>

/* rotation.c: 3-vectors, rotations (row-major 3x3), pure functions */
PETSC_INTERN void      PhlexCross(const PetscReal[3], const PetscReal[3], PetscReal[3]);
PETSC_INTERN PetscReal PhlexDot3(const PetscReal[3], const PetscReal[3]);
PETSC_INTERN PetscReal PhlexNorm3(const PetscReal[3]);
PETSC_INTERN void      PhlexSkew(const PetscReal[3], PetscReal[9]);
PETSC_INTERN void      PhlexMatVec3(const PetscReal[9], const PetscReal[3], PetscReal[3]);
PETSC_INTERN void      PhlexMatTVec3(const PetscReal[9], const PetscReal[3], PetscReal[3]);
PETSC_INTERN void      PhlexMatMat3(const PetscReal[9], const PetscReal[9], PetscReal[9]);
PETSC_INTERN void      PhlexMatTMat3(const PetscReal[9], const PetscReal[9], PetscReal[9]);
PETSC_INTERN void      PhlexMatMatT3(const PetscReal[9], const PetscReal[9], PetscReal[9]);
PETSC_INTERN PetscReal PhlexOrthogonalityError(const PetscReal[9]);
PETSC_INTERN void      PhlexOrthonormalize(PetscReal[9]);
PETSC_INTERN void      PhlexRotationToQuaternion(const PetscReal[9], PetscReal[4]);
PETSC_INTERN void      PhlexQuaternionToRotation(const PetscReal[4], PetscReal[9]);
PETSC_INTERN void      PhlexAxisAngleToRotation(const PetscReal[3], PetscReal, PetscReal[9]);
PETSC_INTERN void      PhlexRotationVector(const PetscReal[9], PetscReal[3]);
PETSC_INTERN void      PhlexRotationUpdate(PetscReal[9], const PetscReal[3]);
PETSC_INTERN void      PhlexLeftJacobian(const PetscReal[3], PetscReal[9]);
PETSC_INTERN void      PhlexCompleteFrame(const PetscReal[3], const PetscReal *, PetscReal[9]);

/* output.c and fields.c */
typedef struct _p_PhlexFieldWriter *PhlexFieldWriter;
PETSC_INTERN PetscErrorCode PhlexOutputCreate(MPI_Comm, PhlexOutput *);
PETSC_INTERN PetscErrorCode PhlexOutputSetFromOptions(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputFile(PhlexOutput, const char[], char[]);
PETSC_INTERN PetscErrorCode PhlexOutputCSVOpen(PhlexOutput, const char[], const char[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexCSVPrintf(PetscViewer, const char[], ...) PETSC_ATTRIBUTE_FORMAT(2, 3);
PETSC_INTERN PetscErrorCode PhlexOutputFlushSeries(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputCommit(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputAbort(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputKeepFailed(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputDestroy(PhlexOutput *);
PETSC_INTERN PetscErrorCode PhlexOutputSaveState(PhlexOutput, PetscViewer);
PETSC_INTERN PetscErrorCode PhlexOutputAddWriter(PhlexOutput, void *, PetscErrorCode (*)(void *, PetscViewer));
PETSC_INTERN PetscErrorCode PhlexOutputSetRestart(PhlexOutput, PetscViewer, const char[]);
PETSC_INTERN PetscErrorCode PhlexOutputRestartCheckUsed(PhlexOutput);
PETSC_INTERN PetscErrorCode PhlexOutputRestoreFile(PhlexOutput, const char[], const char[], PetscReal);
PETSC_INTERN PetscErrorCode PhlexFieldWriterCreate(PhlexOutput, PhlexFlexible, const char[], PhlexFieldWriter *);
PETSC_INTERN PetscErrorCode PhlexFieldWriterBeginStep(PhlexFieldWriter, PetscReal);
PETSC_INTERN PetscErrorCode PhlexFieldWriterVertexField(PhlexFieldWriter, const char[], Vec, PetscReal, const PetscReal *, const PetscReal *, PetscBool);
PETSC_INTERN PetscErrorCode PhlexFieldWriterVertexMax(PhlexFieldWriter, Vec, PetscReal, const PetscReal *, const PetscReal *, PetscBool, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexFieldWriterStress(PhlexFieldWriter, Vec, PetscReal);
PETSC_INTERN PetscErrorCode PhlexFieldWriterSetOutputRotation(PhlexFieldWriter, const PetscReal[9]);
PETSC_INTERN PetscErrorCode PhlexFieldWriterSetGeometryField(PhlexFieldWriter, const char[]);
PETSC_INTERN PetscErrorCode PhlexFieldWriterDestroy(PhlexFieldWriter *);
PETSC_INTERN PetscErrorCode PhlexFlexibleWriteFields(PhlexFlexible, PhlexFieldWriter, const PhlexFrameState *, PetscReal, Vec, Vec, Vec); /* flexible.c */

/* checkpoint.c: checkpoint files (HDF5), written atomically */
PETSC_INTERN PetscErrorCode PhlexCheckpointOpenWrite(MPI_Comm, const char[], char[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexCheckpointCommit(MPI_Comm, const char[], const char[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexCheckpointOpenRead(MPI_Comm, const char[], PetscViewer *);
PETSC_INTERN PetscErrorCode PhlexHDF5Readable(MPI_Comm, const char[], PetscBool *);
PETSC_INTERN PetscErrorCode PhlexFileSync(MPI_Comm, const char[]);
PETSC_INTERN PetscErrorCode PhlexCheckpointWriteReals(PetscViewer, const char[], const char[], PetscInt, const PetscReal[]);
PETSC_INTERN PetscErrorCode PhlexCheckpointReadReals(PetscViewer, const char[], const char[], PetscInt, PetscReal[]);
PETSC_INTERN PetscErrorCode PhlexCheckpointWriteInt(PetscViewer, const char[], const char[], PetscInt);
PETSC_INTERN PetscErrorCode PhlexCheckpointReadInt(PetscViewer, const char[], const char[], PetscInt *);
PETSC_INTERN PetscErrorCode PhlexCheckpointWriteString(PetscViewer, const char[], const char[], const char[]);
PETSC_INTERN PetscErrorCode PhlexCheckpointReadString(PetscViewer, const char[], const char[], char[], size_t);

/* the options of each analysis read once more, for the unused-option check (ctx: the MPI_Comm) */
PETSC_INTERN PetscErrorCode PhlexTransientRereadOptions(void *); /* transient.c */
PETSC_INTERN PetscErrorCode PhlexModesRereadOptions(void *);     /* modes.c */
PETSC_INTERN PetscErrorCode PhlexLinearizedRereadOptions(void *); /* linearized.c */

/* error.c: option input with checked length */
PETSC_INTERN PetscErrorCode PhlexOptionsRealList_Private(PetscOptionItems *, const char[], const char[], const char[], PetscReal[], PetscInt *, PetscBool *, PetscInt);
#define PhlexOptionsRealList(opt, text, man, value, n, set, ndefault) PhlexOptionsRealList_Private(PetscOptionsObject, opt, text, man, value, n, set, ndefault)
PETSC_INTERN PetscErrorCode PhlexOptionsRealN(PetscOptionItems *, MPI_Comm, const char[], const char[], const char[], const char[], const char[], PetscInt, PetscReal[], PetscBool *);
PETSC_INTERN PetscErrorCode PhlexOptionsListLength(const char[], const char[], PetscInt *);

/* expect.c: self-verification */
PETSC_INTERN PetscErrorCode PhlexExpectMax(MPI_Comm, const char[], const char[], PetscReal, PetscReal, PetscBool);
PETSC_INTERN PetscErrorCode PhlexExpectValues(MPI_Comm, const char[], const char[], PetscInt, const PetscReal[], PetscInt, const PetscReal[], PetscReal);

/* mat_shell.c: shell matrices without a transpose */
PETSC_INTERN PetscErrorCode PhlexMatCreateShell(MPI_Comm, PetscInt, PetscInt, PetscInt, PetscInt, void *, PetscErrorCode (*)(Mat, Vec, Vec), Mat *);

/* x86-64 with GCC: a kernel marked PHLEX_KERNEL_CLONES is compiled twice, for AVX2 and the baseline (SSE2), the first
   taken where the processor has it (an ifunc, resolved once): its loops then run 4 doubles wide instead of 2. The
   sums are the same (no multiply-add fused, no reduction across a loop's lanes): the same bits either way. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__) && defined(__has_attribute)
  #if __has_attribute(target_clones) /* and glibc's ifunc (musl has none) */
    #define PHLEX_KERNEL_CLONES __attribute__((target_clones("avx2", "default")))
  #endif
#endif
#ifndef PHLEX_KERNEL_CLONES
  #define PHLEX_KERNEL_CLONES
#endif

/* mat_block_mult.c: a matrix times a block of vectors */
PETSC_INTERN PetscErrorCode PhlexMatMultBlock(Mat, Mat, Mat);
/* mat_block_copy.c: an AIJ matrix copied in node blocks (BAIJ) */
PETSC_INTERN PetscErrorCode PhlexMatBlockCopy(Mat, PetscBool, MatReuse, Mat *);
typedef struct {
  Mat           copy;  /* the node-block copy (NULL: none, the matrix not in whole blocks) */
  PhlexMatWatch watch; /* the matrix it was taken from */
} PhlexBlockCopy;
PETSC_INTERN PetscErrorCode PhlexBlockCopyUpdate(PhlexBlockCopy *, Mat, PetscBool);
PETSC_INTERN PetscErrorCode PhlexBlockCopyDestroy(PhlexBlockCopy *);
/* mg_level_products.c: a multigrid hierarchy's transfers and coarse operators in node blocks after its set-up */
typedef struct {
  PetscInt nlevels; /* of the hierarchy copied (0: none) */
  PhlexBlockCopy *P, *A; /* per level: the block copies of its AIJ interpolation and (smoothed coarse levels) operator */
  PetscInt count[5]; /* transfers, by block copies, by stored transposes; smoothed coarse levels, by block copies */
} PhlexMGCopies;
PETSC_INTERN PetscErrorCode PhlexMGCopiesApply(KSP, PetscBool, PetscBool, PhlexMGCopies *);
PETSC_INTERN PetscErrorCode PhlexMGCopiesRestore(KSP, PhlexMGCopies *);
PETSC_INTERN PetscErrorCode PhlexMGCopiesDestroy(PhlexMGCopies *);

/* format.c: numbers echoed to the user at full precision */
PETSC_INTERN const char *PhlexFormatReal(PetscReal, char[], size_t);

/* split_sum.c: sums over a part's communicator in two phases (local sums of every part, then the reductions) */
PETSC_INTERN PetscErrorCode PhlexLocalDot(Vec, Vec, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexLocalMDot(Vec, PetscInt, const Vec[], PetscReal *);
PETSC_INTERN PetscErrorCode PhlexSplitSumBegin(MPI_Comm, const PetscReal *, PetscReal *, PetscInt, MPI_Request *);
PETSC_INTERN PetscErrorCode PhlexSplitSumEnd(MPI_Request *);

/* blas.c: OpenBLAS's kernels where it does not know the processor */
PETSC_INTERN PetscErrorCode PhlexBLASSetFromOptions(MPI_Comm);
PETSC_INTERN PetscErrorCode PhlexBLASView(PetscViewer);

/* memory.c: freed heap memory returned to the operating system */
PETSC_INTERN PetscErrorCode PhlexReturnFreedMemory(void);

/* progress.c: progress lines of long runs (and the interrupt check) */
typedef struct {
  PetscLogDouble start, last; /* wall clock: start of the run, last line */
  PetscReal      done0;       /* the share of the run done at the start (a restart) */
  char           what[64];    /* what the eigensolver solves, e.g. "body arm" */
} PhlexProgress;
PETSC_INTERN PetscErrorCode PhlexProgressSetFromOptions(MPI_Comm);
PETSC_INTERN PetscErrorCode PhlexProgressStart(PhlexProgress *);
PETSC_INTERN PetscErrorCode PhlexProgressStep(PhlexProgress *, MPI_Comm, PetscInt, PetscReal, PetscReal, const char[]);
PETSC_INTERN PetscErrorCode PhlexProgressEPSMonitor(EPS, PetscInt, PetscInt, PetscScalar *, PetscScalar *, PetscReal *, PetscInt, void *);
PETSC_INTERN PetscErrorCode PhlexProgressPEPMonitor(PEP, PetscInt, PetscInt, PetscScalar *, PetscScalar *, PetscReal *, PetscInt, void *);
PETSC_INTERN PetscErrorCode PhlexProgressEPSSolve(EPS, const char[]);
PETSC_INTERN PetscErrorCode PhlexProgressPEPSolve(PEP, const char[]);
PETSC_INTERN PetscErrorCode PhlexProgressPhase(PhlexProgress *, MPI_Comm, const char[], PetscReal);
PETSC_INTERN PetscErrorCode PhlexProgressChunk(PhlexProgress *, MPI_Comm, const char[], PetscInt, PetscInt, PetscInt *);
PETSC_INTERN PetscErrorCode PhlexProgressChunksEnd(PhlexProgress *, MPI_Comm, const char[], PetscInt);
PETSC_INTERN void           PhlexProgressSetInSteps(PetscBool);
PETSC_INTERN PetscBool      PhlexProgressInSteps(void);
PETSC_INTERN PetscErrorCode PhlexProgressCheck(MPI_Comm, const char[]);

/* flexible_modes.c: the eigensolver of the modal analysis with its defaults (also read by -help) */
PETSC_INTERN PetscErrorCode PhlexModesEPSCreate(MPI_Comm, EPS *, PetscReal *, PetscBool *);

/* eps_block.c: EPS "phlexblock", block shift-and-invert Krylov-Schur (the modal analyses' default) */
#define EPSPHLEXBLOCK "phlexblock"
PETSC_INTERN PetscErrorCode PhlexEPSRegister(void);

/* scene.c */
PETSC_INTERN PetscErrorCode PhlexSceneFindPart(PhlexScene, const char[], PhlexPart *);
PETSC_INTERN PetscErrorCode PhlexSceneReadOptions(MPI_Comm);

#endif
