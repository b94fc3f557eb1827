/* The linearised analysis' pencil (src/analysis/linearized.c builds it; linearized_damped.c adds the force elements
   and solves the damped problem). */
#ifndef PHLEX_PRIVATE_LINEARIZED_H
#define PHLEX_PRIVATE_LINEARIZED_H

#include <slepcpep.h>

/* The pencil's pieces that do not change with the configuration, the index maps of the discrete unknowns, and the
   per-configuration matrices. Q numbers the kept discrete unknowns: the velocities first, then the impulses. */
typedef struct {
  PhlexSystem sys;
  Vec         X, Xdot;
  PetscInt    nqv, nqi, nQ; /* discrete velocities, impulses, both */
  PetscInt   *qmap;         /* discrete unknown -> Q index (-1: a configuration unknown, dropped) */
  PetscInt   *Qq;           /* Q index -> discrete unknown */
  PetscInt    ne;           /* elastic coordinates (eliminated: their stiffness goes onto their velocities) */
  PetscInt   *Ee;           /* their discrete unknowns */
  PetscInt    nel;          /* force elements' rows (eliminated: their stiffness and damping go onto the velocities) */
  PetscInt   *elF, *elE;    /* their force impulses and states (discrete unknowns), row by row */
  PetscBool  *qdamped;      /* discrete unknown of a part that dissipates (its velocities may have a damping term) */
  Mat         K, Mvv;       /* field stiffness (stress eliminated; with a stressed or spinning state's K_sigma + Cen) and mass */
  Mat         Gyr;          /* the fields' gyroscopic (Coriolis) matrix about a spin, or NULL */
  Mat         Rf;           /* the fields' structural damping R (AIJ), or NULL */
  Vec        *elrows;       /* the force elements' rows on the velocity field (A parts: 2 nel, forces then states), or NULL */
  Mat         A, B, A1;     /* the saddle-point pencil (the same nonzero pattern in every configuration without force
                               elements); A1 its part proportional to the rate: Coriolis and damping */
  IS          isV, isQ;     /* the velocity field and Q in the pencil's numbering */
  PetscReal   scale;        /* |M| (the at-rest checks are relative to it) */
  PetscBool   coriolis;     /* -linearized_coriolis: the Coriolis part kept (a quadratic eigenproblem) */
  PetscBool   damped;       /* a body or a force element dissipates: a quadratic eigenproblem with damping */
  PhlexProgress progress;   /* the clock of the pencil's build: its steps check the interrupt flag, report progress */
} Pencil;
PETSC_INTERN PetscErrorCode PhlexLinearizedPencilPhase(Pencil *, const char[], PetscReal);

typedef struct {
  PetscInt   n, nmech;
  PetscReal *theta, *resid; /* non-dimensional omega^2 (the undamped natural pulsation |lambda| when damped), ascending; residuals */
  PetscReal *growth;        /* non-dimensional growth rate of an unstable mode (0: stable) */
  PetscReal *zeta;          /* damped: the mode's damping ratio -Re(lambda)/|lambda| (NaN for an overdamped, real lambda) */
  PetscReal *decay;         /* damped: its decay rate -Re(lambda) (non-dimensional) */
  PetscReal *wd;            /* damped: its damped pulsation Im(lambda) (non-dimensional) */
  Vec       *x;             /* eigenvectors (pencil numbering), when asked */
} Spectrum;

PETSC_INTERN PetscErrorCode PhlexLinearizedElementDiscreteStiffness(Pencil *, const PetscReal *, const PetscReal *, PetscReal *);
PETSC_INTERN PetscErrorCode PhlexLinearizedElementOperators(Pencil *, const PetscReal *, const PetscReal *, Mat, Mat *, Mat *);
PETSC_INTERN PetscErrorCode PhlexLinearizedSolveDamped(Pencil *, PEP, PetscInt, PetscInt, PetscInt, PetscReal, PetscBool, Spectrum *);

#endif
