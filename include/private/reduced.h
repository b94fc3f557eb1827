/* A reduced flexible body (paper Section 5.3): its elastic field in the span of a basis Phi of the full body's
   velocity space, u = Phi eta, v = Phi zeta; what the online model (src/parts/reduced.c) needs of the full body is
   the Galerkin projection of its operators and its inertia invariants (src/parts/reduced_build.c builds them, and
   reads and writes the reduced body file). All non-dimensional (the scene's units) in memory, SI in the file. */
#ifndef PHLEX_PRIVATE_REDUCED_H
#define PHLEX_PRIVATE_REDUCED_H

#define PHLEX_MAX_MODAL_RATIOS 256 /* -modal_damping_ratios values */

typedef enum {
  PHLEX_REDUCTION_FREE_INTERFACE, /* the body's own normal modes (clamped at its frame patch, or free on mean axes)
                                     plus the static attachment modes of its ports */
  PHLEX_REDUCTION_CRAIG_BAMPTON,  /* the fixed-interface normal modes (frame patch clamped and every listed port's six
                                     rigid-average motions held, B_q^T u = 0) plus the static constraint modes of the
                                     ports (unit rigid-average motion of one, the others held, least strain energy) */
  PHLEX_REDUCTION_KRYLOV          /* moment matching of the ports' transfer function: block Krylov spaces
                                     K_r((K - w^2 Mv)^{-1} Mv, (K - w^2 Mv)^{-1} B) at given expansion frequencies */
} PhlexReductionType;
#define PHLEX_REDUCTION_NTYPES 3
PETSC_EXTERN const char *const PhlexReductionTypes[];

#define PHLEX_KRYLOV_MAX_FREQUENCIES 16

/* the kind of basis and its parameters (what the provenance records) */
typedef struct {
  PhlexReductionType type;
  PetscInt           nmodes;        /* free_interface, craig_bampton: normal modes in the basis */
  PetscInt           krylov_order;  /* krylov: block steps per expansion frequency */
  PetscInt           nfrequencies;  /* krylov: expansion frequencies */
  PetscBool          krylov_frame_loads; /* krylov: the frame's inertia loads Mv R (and the weight) as inputs too */
  PetscReal          frequencies[PHLEX_KRYLOV_MAX_FREQUENCIES]; /* [Hz] (SI) */
} PhlexReduction;

typedef struct {
  PetscInt   m;        /* basis size */
  PetscInt   nnormal;  /* normal modes among the basis vectors' span (krylov: none) */
  PetscInt   nports;   /* the full body's listed ports (its port maps follow their order) */
  PetscReal *Mr, *Kr;  /* Phi^T Mv Phi, Phi^T K Phi (m x m, row-major; the basis makes them I and diagonal) */
  PetscReal *S;        /* 3 m: int rho phi_k (component c at 3 k + c) */
  PetscReal *W;        /* 9 m: int rho x_b phi_k,c at 9 k + 3 b + c (x relative to the frame origin P) */
  PetscReal *N;        /* 9 m^2: int rho phi_i,b phi_j,c at 9 (i m + j) + 3 b + c */
  PetscReal *Svol;     /* 3 m: int phi_k (uniform body forces) */
  PetscReal *P;        /* 6 m per port: its output map B_q^T Phi, row d (translation 0-2, rotation 3-5) at 6 m q + m d + k */
  PetscReal *lambda;   /* the reduced eigenvalues (diagonal of Kr) */
  PetscReal *lambda_full; /* nnormal: the full body's eigenvalues of the normal modes in the basis (craig_bampton: of
                             the body with its ports held) */
  PhlexInertia inertia; /* the whole body about P: m, s0, E0, vol, svol */
  /* the fields of the basis (field output only): NULL until built, or read from the file (PhlexReducedReadBasis) */
  Vec      *Phi;             /* m: the basis vectors in the full body's velocity space (u = Phi eta, v = Phi zeta) */
  Vec      *Psi;             /* m: their stress recovery modes Ms^{-1} G phi_k in its stress space (Sigma = Psi eta) */
  char      numbering[48];   /* the full body's numbering of its unknowns the vectors are in (part->numbering) */
} PhlexReducedModel;

PETSC_INTERN PetscErrorCode PhlexReducedBuild(PhlexPart, const PhlexReduction *, PhlexReducedModel *);
PETSC_INTERN PetscErrorCode PhlexReducedModelDestroy(PhlexReducedModel *);
PETSC_INTERN PetscErrorCode PhlexReducedWrite(MPI_Comm, const char[], const char[], const PhlexReducedModel *, const PhlexUnits *, const char[], const PhlexReduction *);
PETSC_INTERN PetscErrorCode PhlexReducedRead(MPI_Comm, const char[], const char[], const char[], const PhlexUnits *, PhlexReducedModel *);
PETSC_INTERN PetscErrorCode PhlexReducedReadBasis(PhlexPart, const char[], const char[], const PhlexUnits *, PhlexReducedModel *);
PETSC_INTERN PetscErrorCode PhlexReducedModelRoundTrip(PhlexReducedModel *, const PhlexUnits *);
PETSC_INTERN PetscErrorCode PhlexReducedProvenance(PhlexPart, const PhlexReduction *, char[], size_t);
PETSC_INTERN PetscErrorCode PhlexReducedViewTransfer(PhlexPart, const PhlexReducedModel *, PetscInt, const PetscReal[]);
PETSC_INTERN PetscErrorCode PhlexReducedExpectMoments(PhlexPart, const PhlexReduction *, const PhlexReducedModel *, PetscReal);

#endif
