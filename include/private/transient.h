/* The transient analysis' monitor context, shared by transient.c (the energy monitor) and transient_checkpoint.c
   (what a checkpoint holds besides the outputs: the state, the time, the monitor's accumulators). */
#ifndef PHLEX_PRIVATE_TRANSIENT_H
#define PHLEX_PRIVATE_TRANSIENT_H

typedef struct {
  PhlexScene  scene;
  PhlexSystem sys;
  Vec         Xprev, Xmid; /* the previous state and scratch (NULL where neither the power nor the adaptive check reads them) */
  Vec         Xstage;      /* the theta method's stage (a reference to TSTHETA's vector, its state at the stage kept) */
  PetscObjectState stage_state;
  PetscReal   tstage;
  PetscBool   have_stage;
  PetscReal   H0, Hprev, tprev, work_total, max_drift, max_residual, max_work, Hmax, Emax; /* Emax: largest kinetic + strain energy */
  PetscReal   dissipated_total; /* the energy the dampers dissipated (>= 0); max_work: the largest of it and |work_total| */
  PetscBool   dissipative;      /* a part or joint has dampers (the summary and the monitor show the dissipation) */
  PetscBool   element_tables;   /* a force element has a force table (its discrete gradient needs e_n) or a moving rest (the step's start time) */
  PetscBool   midpoint;         /* the implicit midpoint rule (a moving rest's change is its mean over each step) */
  PetscViewer energy_csv, monitor;
  PetscInt    interval, last_written;
  PetscBool   theta, endpoint;
  PetscBool   history;     /* BDF, alpha: past steps kept inside TS (a changed state restarts them) */
  PetscBool   orth_warned; /* the warning on rotations off SO(3) was given */
  PetscReal   theta_value;
  PetscReal  *qprev, *lambda; /* discrete unknowns of the previous step, multipliers (step averages) */
  PetscReal  *jpower;         /* power through each joint over the step, with the scheme's quadrature */
  PetscReal  *jdiss;          /* power each joint's force elements dissipated over the step (the same quadrature) */
  PetscReal  *jact;           /* power each joint's moving rest supplied over the step (the same quadrature) */
  /* momenta of a free system, rotations */
  PetscBool   free_system;
  PetscReal   P0[3], L0[3], Pscale, Lscale, max_dP, max_dL, max_orth, max_defect;
  /* joints */
  PetscReal   max_gap, project_dH, step_project_dH;
  PetscReal   max_drive; /* the largest error of a drive or prescribed motion against its profile (m or rad) */
  PetscBool   has_drives;
  PetscInt    nprojections;
  /* watchdogs: stop a run whose numbers went wrong (0: off) */
  PetscReal   watch_balance, watch_gap, watch_orth;
  PetscReal   watch_energy;    /* stop when the energy created (H - H0 - W + D) exceeds this times max(E0, the work) */
  PetscReal   expect_drift_max; /* -expect_energy_drift_max (-1: not given): refused at step 0 when H0 is no scale */
  PetscReal   E0abs;           /* |kinetic| + |strain| + |potential| at the start: the energy's scale (H0 may cancel to 0) */
  PetscReal   V0, max_dV;      /* the potential at the start, the largest it exchanged since (a pendulum released at rest) */
  PetscReal   watch_deform;    /* stop when a body's elastic displacement exceeds this times its size */
  PetscBool   lossless_scheme; /* the implicit midpoint rule: the balance holds to solver tolerance */
  PhlexProgress progress;
  /* adaptive steps: a step that breaks a watchdog, or whose Newton fails, is retried with a smaller step */
  PetscBool   adaptive;
  PetscBool   condensed; /* SNES phlexcondensed solves the stages (the preset's field split is not used) */
  PetscBool   reduced;   /* SNES phlexreduced solves the stages (Newton on velocities and discrete unknowns; the preset's field split is not used) */
  char        preset[PETSC_MAX_PATH_LEN]; /* the solver preset file ("": none) */
  char        preset_why[256];            /* why it (the default's reason, or the option) */
  PetscInt    nretries, snes_failures, max_snes_failures; /* retries over the run; Newton failures of this step, the user's bound (-1: none) */
  char        last_retry[256]; /* why the step being taken was retried (cleared when a step is accepted) */
  char        run_retry[256];  /* why the last retried step of the run was retried */
  PetscReal   dt_nominal;      /* -ts_dt */
  PetscReal   profile_t0;          /* the run's start, for the inputs' series (PhlexProfileCheckRange) */
  /* chosen port outputs at a rate (transient_ports.c): ports.csv */
  PetscInt       nports_out;
  PhlexPart     *out_part;
  PetscInt      *out_port;
  char         (*out_names)[2 * PHLEX_NAME_LEN + 2];
  PetscReal      ports_every;     /* the sampling interval [s] (0: every step) */
  PetscInt       ports_next;      /* the next sample, t = ports_next ports_every */
  PetscReal     *out_prev, *out_row, ports_prev_t; /* the last monitored step's row and time, the current row */
  PetscBool      ports_have_prev;
  PetscViewer    ports_csv;
  PetscBool   profile_check_steps; /* the run's end is not known in advance: each step is checked */
  /* checkpoints (transient_checkpoint.c) */
  PetscInt       first_step;   /* the step the run starts from (a restart's checkpoint; 0 otherwise) */
  PetscInt       last_step;    /* the last step monitored (-1: none) */
  PetscInt       ck_interval;  /* every n steps (0: off) */
  PetscReal      ck_wall;      /* every s seconds of wall clock (0: off) */
  PetscLogDouble ck_last;      /* wall clock of the last checkpoint (or of the start) */
  PetscInt       ck_step;      /* step of the last checkpoint written (-1: none) */
  char           ck_file[PETSC_MAX_PATH_LEN];
} MonitorContext;

PETSC_INTERN PetscErrorCode PhlexTransientCheckpointOptions(MPI_Comm, PhlexOutput, MonitorContext *, char[], PetscBool *);
PETSC_INTERN PetscErrorCode PhlexTransientCheckpointDue(MonitorContext *, PetscInt, PetscBool *);
PETSC_INTERN PetscErrorCode PhlexTransientCheckpointWrite(TS, MonitorContext *, Vec);
PETSC_INTERN PetscErrorCode PhlexTransientRestartCheck(TS, MonitorContext *, PetscViewer, const char[], Vec);
PETSC_INTERN PetscErrorCode PhlexTransientRestart(TS, MonitorContext *, PetscViewer, const char[], Vec);
PETSC_INTERN PetscErrorCode PhlexTransientPortsSetUp(MonitorContext *, PetscInt, char *[], PetscReal);
PETSC_INTERN PetscErrorCode PhlexTransientPortsOpen(MonitorContext *);
PETSC_INTERN PetscErrorCode PhlexTransientPortsStep(MonitorContext *, PetscReal, Vec);
PETSC_INTERN PetscErrorCode PhlexTransientPortsSave(MonitorContext *, PetscViewer);
PETSC_INTERN PetscErrorCode PhlexTransientPortsRestart(MonitorContext *, PetscViewer, const char[]);
PETSC_INTERN PetscErrorCode PhlexTransientPortsDestroy(MonitorContext *);

#endif
