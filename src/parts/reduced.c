/* A reduced flexible body as a part (part kind "reduced", paper Section 5.3): a flexible body whose elastic field is
   spanned by a basis Phi of the full body's field (reduced_build.c), u = Phi eta, v = Phi zeta, with the same
   options, ports and frame as the full body (-body<k>_type reduced instead of flexible). Its unknowns are discrete:
   q = [r | R | v_P | w] (floating) | eta (elastic coordinates) | zeta (their velocities).

   Equations: the Galerkin projection of the full body's (flexible_dynamics.c, frame.c):
     F_q    = the frame's kinematics and Hamel equations (frame.c), with the field's integrals from the invariants
     F_eta  = eta' - zeta
     F_zeta = Mr zeta' + Kr eta + Phi^T (the frame's loads on the field) - sum_q P_q^T w_q - (body force, weight)
   Mr = Phi^T Mv Phi, Kr = Phi^T K Phi (the stress eliminated exactly: Sigma = Ms^{-1} G u), P_q = B_q^T Phi the port
   maps. The frame's loads on the field are linear in the node inputs of frame.c (t, int rho y phi, Mv u', Mv v,
   Mv v'): their generalized forces are the coefficients of PhlexFrameLoadCoefficients contracted with the inputs'
   moments with each basis vector, formed from the invariants int rho phi_k, int rho x phi_k^T, int rho phi_i phi_j^T;
   the Jacobian's borders likewise from PhlexFrameJacobian's node coefficients. Every inertia model of the full body
   is the same projection; with the constant ones the Hamiltonian 1/2 e^T M e + 1/2 eta^T Kr eta is quadratic and
   the implicit midpoint rule keeps it to solver tolerance. */
#include <phlex_impl.h>
#include <private/reduced.h>

typedef struct {
  PhlexPart          full; /* the FE body it reduces: its options, mesh and operators (the offline build) */
  PhlexFlexible      fb;
  PhlexReductionType type;
  PetscInt           nmodes;
  char               file[PETSC_MAX_PATH_LEN];
  PetscBool          built; /* the model was built in this run (else read from the file) */
  PhlexReducedModel  md;
  PetscBool          floating, full_inertia;
  PetscInt           m, ie, iz, nports; /* basis size, offsets of eta and zeta in q, the listed ports */
  PhlexFrame         frame;
  PhlexFrameState    fs;
  PetscReal         *Mom;   /* per basis vector 3 PHLEX_FRAME_NIN: the node inputs' moments at the evaluated state */
  PetscReal         *nmom;  /* 4 x 9 m: the moments of eta, eta', zeta, zeta' with each basis vector (FieldMoments) */
  PetscReal         *xcols; /* 4 m: eta, eta', zeta, zeta' as the columns of FieldMoments' product */
  PetscReal         *gext;  /* m: generalized force of the external inputs (ports, body force, a fixed body's weight) */
  PetscReal         *work;  /* m */
  PetscReal         *etad, *zetad; /* m each: the rates of the evaluated state (non-dimensional time) */
  PetscReal         *Lb, *Lu, *Lv; /* the frame's node-border coefficients (PhlexFrameJacobian), 54 PHLEX_FRAME_NIN each */
  PetscReal        (*port_ext)[6], (*port_y)[6], (*port_ub)[6]; /* per port: input, output, mean displacement and rotation */
  PetscReal          beta[3]; /* body force density at the evaluated time */
  PetscReal          power_ext, t_eval;
  PetscViewer        rigid_csv, ports_csv, modal_csv;
  PhlexFieldWriter   writer;           /* the full body's field output (-output_fields), or NULL */
  Vec                fu, fv, fsig;     /* its fields at an output step: Phi eta, Phi zeta, Psi eta */
  PetscScalar       *fcoef;            /* m: the coordinates of a field */
  PetscReal          expect_held[64], expect_full[64], expect_rtol; /* self-checks of the basis (-reduction_expect_*) */
  PetscInt           nexpect_held, nexpect_full;
  PhlexReduction     red;   /* the kind of basis and its parameters (r->type, r->nmodes repeated in it) */
  PetscReal          view_transfer[64], expect_moments_rtol; /* self-checks of the transfer function */
  PetscInt           nview_transfer;
  /* structural damping (issue 45): per-mode damping ratios on the eigenmodes of (Kr, Mr) and Rayleigh alpha Mr +
     beta Kr on the elastic coordinates; Rr (m x m, row-major, non-dimensional) NULL when undamped */
  PetscReal          modal_zeta[PHLEX_MAX_MODAL_RATIOS];
  PetscInt           nmodal_zeta;
  PetscReal         *Rr;
  PetscReal          diss; /* zeta^T Rr zeta at the evaluated state */
} Reduced;

/* ------------------------------------------------------------------------------------------------------------ */
/* Options, set-up                                                                                                */

static PetscErrorCode ReducedSetFromOptions(PhlexPart part)
{
  Reduced      *r = (Reduced *)part->data;
  PhlexFlexible b;
  PetscInt      type = 0;
  PetscBool     set_zeta = PETSC_FALSE, set_held = PETSC_FALSE, set_full = PETSC_FALSE, set_modes = PETSC_FALSE, set_order = PETSC_FALSE, set_freq = PETSC_FALSE, set_view = PETSC_FALSE, set_fl = PETSC_FALSE;

  PetscFunctionBeginUser;
  /* the full body reads its options under the same prefix: the scene of a reduced body is that of the full one */
  PetscCall(PhlexPartCreate(part->comm, part->index, &r->full));
  PetscCall(PetscStrcpy(r->full->name, part->name));
  PetscCall(PetscStrcpy(r->full->type, "flexible"));
  PetscCall(PhlexPartCreate_Flexible(r->full));
  PetscCall((*r->full->ops.setfromoptions)(r->full));
  r->fb = b  = (PhlexFlexible)r->full->data;
  PetscCheck(!(b->port_rate_given && b->port_rate_exact), part->comm, PETSC_ERR_SUP, "body %s: -%sport_rate exact is not implemented for a reduced body (its ports turn at the first-order rate w + B_r^T v); use -%sport_rate first_order or -%stype flexible", part->name, part->prefix, part->prefix, part->prefix);
  PetscCheck(!b->ic_steady_spin, part->comm, PETSC_ERR_SUP, "body %s: -%sic_steady_spin is not implemented for a reduced body (its steady stretch is solved on the full field); use -%stype flexible, or start it from rest", part->name, part->prefix, part->prefix);
  r->nmodes  = 10;
  r->expect_rtol  = 1e-6;
  r->nexpect_held = r->nexpect_full = 64;
  r->nview_transfer          = 64;
  r->expect_moments_rtol     = 0.0;
  r->red.krylov_order        = 2;
  r->red.nfrequencies        = PHLEX_KRYLOV_MAX_FREQUENCIES;
  r->red.frequencies[0]      = 0.0;
  r->nmodal_zeta             = PHLEX_MAX_MODAL_RATIOS;
  PetscOptionsBegin(part->comm, part->prefix, "Reduced body options", NULL);
  PetscCall(PhlexOptionsRealList("-modal_damping_ratios", "Damping ratios zeta_1,zeta_2,... of the reduced body's modes (the eigenmodes of (Kr, Mr), lowest first; the modes beyond the list take its last value; >= 0, >= 1 over-damped), added to Rayleigh's -rayleigh_alpha, -rayleigh_beta [-]", "ReducedSetFromOptions", r->modal_zeta, &r->nmodal_zeta, &set_zeta, 0));
  PetscCall(PetscOptionsString("-reduced_file", "Reduced body file (HDF5): read if it exists (refused if built for another body), else built and written; empty: built in memory at every run", "ReducedSetFromOptions", r->file, r->file, sizeof(r->file), NULL));
  PetscCall(PetscOptionsEList("-reduction", "Basis of the reduction: free_interface (the body's normal modes with its frame held, plus the static attachment modes of its ports), craig_bampton (the normal modes with its frame and its ports' rigid averages held, plus the static constraint modes of its ports), krylov (moment matching of the ports' transfer function: block Krylov spaces at -reduction_krylov_frequencies)", "ReducedSetFromOptions", PhlexReductionTypes, PHLEX_REDUCTION_NTYPES, PhlexReductionTypes[type], &type, NULL));
  PetscCall(PetscOptionsInt("-reduction_modes", "Normal modes in the basis (craig_bampton: fixed-interface modes; the static modes of the ports, six each, come in addition)", "ReducedSetFromOptions", r->nmodes, &r->nmodes, &set_modes));
  PetscCall(PetscOptionsInt("-reduction_krylov_order", "krylov: block steps per expansion frequency (each a block of 6 vectors per listed port; r steps match 2 r moments of the ports' transfer function)", "ReducedSetFromOptions", r->red.krylov_order, &r->red.krylov_order, &set_order));
  PetscCall(PhlexOptionsRealList("-reduction_krylov_frequencies", "krylov: expansion frequencies [Hz] (0: the static moments, whose first block is the ports' attachment modes)", "ReducedSetFromOptions", r->red.frequencies, &r->red.nfrequencies, &set_freq, 1));
  PetscCall(PetscOptionsBool("-reduction_krylov_frame_loads", "krylov: the frame's inertia loads on the field (Mv times its six rigid fields: a unit acceleration of the frame, gravity) as inputs beside the ports' loads (6 more vectors per block; not on mean axes)", "ReducedSetFromOptions", r->red.krylov_frame_loads, &r->red.krylov_frame_loads, &set_fl));
  PetscCall(PhlexOptionsRealList("-reduction_view_transfer", "Self-check: prints the relative error of the reduced ports' transfer function against the full body's at these frequencies [Hz]", "ReducedSetFromOptions", r->view_transfer, &r->nview_transfer, &set_view, 0));
  PetscCall(PetscOptionsReal("-reduction_expect_moments_rtol", "Self-check (krylov): the first 2 r moments of the ports' transfer function at each expansion frequency equal the full body's within this relative tolerance (0: no check)", "ReducedSetFromOptions", r->expect_moments_rtol, &r->expect_moments_rtol, NULL));
  PetscCall(PhlexOptionsRealList("-reduction_expect_held_frequencies", "Self-check: the full body's frequencies with its frame and ports held [Hz] (craig_bampton: those of its fixed-interface modes, compared within -reduction_expect_rtol)", "ReducedSetFromOptions", r->expect_held, &r->nexpect_held, &set_held, 0));
  PetscCall(PhlexOptionsRealList("-reduction_expect_full_frequencies", "Self-check: the full body's lowest frequencies with its frame held as the basis holds it (clamped at the frame patch, free on mean axes) [Hz]: the reduced ones must bound them from above (Rayleigh-Ritz) and, with free_interface, equal them for the normal modes in the basis; with craig_bampton lie below the held ones, which lie below the reduced ones 6 per port further (interlacing)", "ReducedSetFromOptions", r->expect_full, &r->nexpect_full, &set_full, 0));
  PetscCall(PetscOptionsReal("-reduction_expect_rtol", "Relative tolerance of -reduction_expect_held_frequencies, and the slack of the bounds of -reduction_expect_full_frequencies", "ReducedSetFromOptions", r->expect_rtol, &r->expect_rtol, NULL));
  PetscOptionsEnd();
  if (!set_zeta) r->nmodal_zeta = 0;
  for (PetscInt i = 0; i < r->nmodal_zeta; i++) PetscCheck(r->modal_zeta[i] >= 0 && !PetscIsInfOrNanReal(r->modal_zeta[i]), part->comm, PETSC_ERR_USER_INPUT, "body %s: -%smodal_damping_ratios: ratio %" PetscInt_FMT " is %g, must be >= 0 (a negative one feeds energy in)", part->name, part->prefix, i + 1, (double)r->modal_zeta[i]);
  PetscCheck(!set_zeta || r->nmodal_zeta > 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%smodal_damping_ratios needs at least one value", part->name, part->prefix);
  if (!set_held) r->nexpect_held = 0;
  if (!set_full) r->nexpect_full = 0;
  r->type = (PhlexReductionType)type;
  if (!set_view) r->nview_transfer = 0;
  if (!set_freq) r->red.nfrequencies = 1;
  r->red.type   = r->type;
  r->red.nmodes = r->nmodes;
  if (r->type == PHLEX_REDUCTION_KRYLOV) {
    PetscCheck(!set_modes, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_modes does not apply to -%sreduction krylov: its basis is %" PetscInt_FMT " block steps (-%sreduction_krylov_order) per expansion frequency (-%sreduction_krylov_frequencies)", part->name, part->prefix, part->prefix, r->red.krylov_order, part->prefix, part->prefix);
    PetscCheck(b->nports > 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction krylov matches the transfer function of the listed ports (-%sports): the body has none, and its frame patch alone is held, no input; list a port or choose -%sreduction free_interface", part->name, part->prefix, part->prefix, part->prefix);
    PetscCheck(!r->red.krylov_frame_loads || !(b->floating && b->frame_condition == PHLEX_FRAME_MEAN_AXES), part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_krylov_frame_loads: on mean axes the frame's inertia loads have no elastic response (the field is held Mv-orthogonal to the rigid fields)", part->name, part->prefix);
    PetscCheck(r->red.krylov_order >= 1, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_krylov_order must be >= 1, got %" PetscInt_FMT, part->name, part->prefix, r->red.krylov_order);
    PetscCheck(r->red.nfrequencies >= 1, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_krylov_frequencies: give at least one frequency [Hz]", part->name, part->prefix);
    for (PetscInt i = 0; i < r->red.nfrequencies; i++) PetscCheck(r->red.frequencies[i] >= 0.0, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_krylov_frequencies: frequency %" PetscInt_FMT " is %g Hz, must be >= 0", part->name, part->prefix, i + 1, (double)r->red.frequencies[i]);
  } else {
    PetscCheck(!set_order && !set_freq && !set_fl, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%s%s applies to -%sreduction krylov, not %s", part->name, part->prefix, set_order ? "reduction_krylov_order" : (set_freq ? "reduction_krylov_frequencies" : "reduction_krylov_frame_loads"), part->prefix, PhlexReductionTypes[r->type]);
    PetscCheck(r->expect_moments_rtol == 0.0, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_expect_moments_rtol checks a Krylov basis's moments (-%sreduction krylov), not %s", part->name, part->prefix, part->prefix, PhlexReductionTypes[r->type]);
  }
  PetscCheck(r->nmodes >= 0, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%sreduction_modes must be >= 0, got %" PetscInt_FMT, part->name, part->prefix, r->nmodes);
  PetscCheck(b->floating || b->frame_patch[0], part->comm, PETSC_ERR_USER_INPUT, "body %s: a reduced fixed body needs the clamp of its frame (-%sframe_patch <surface>): a free fixed body has no reduced model", part->name, part->prefix);
  PetscCheck(!b->stiffening && !b->spinning, part->comm, PETSC_ERR_USER_INPUT, "body %s: a reduced body has no %s (its basis is that of the linear body at rest, and the stiffening would need the stress of every basis pair): use the full body (-%stype flexible)", part->name, b->stiffening ? "geometric stiffening (-geometric_stiffening)" : "prescribed spin (-spin)", part->prefix);
  PetscCheck(b->materials[0].viscosity == 0 && (b->nmaterials < 2 || b->materials[1].viscosity == 0), part->comm, PETSC_ERR_SUP, "body %s: a reduced body takes no Kelvin-Voigt viscosity (-%sviscosity, -%sregion_<name>_viscosity): give its damping per mode (-%smodal_damping_ratios) or as Rayleigh's (-%srayleigh_alpha, -%srayleigh_beta), or use the full body (-%stype flexible)", part->name, part->prefix, part->prefix, part->prefix, part->prefix, part->prefix, part->prefix);
  for (PetscInt k = 2; k < b->nmaterials; k++) PetscCheck(b->materials[k].viscosity == 0, part->comm, PETSC_ERR_SUP, "body %s: a reduced body takes no Kelvin-Voigt viscosity (-%sregion_%s_viscosity): give its damping per mode (-%smodal_damping_ratios) or as Rayleigh's (-%srayleigh_alpha, -%srayleigh_beta)", part->name, part->prefix, b->materials[k].region, part->prefix, part->prefix, part->prefix);
  {
    /* the elastic initial state is the basis's: a reduced body starts undeformed, its frame placed and moving as given */
    const PhlexIC *iv = &b->ic_velocity, *iu = &b->ic_displacement, *is = &b->ic_stress;
    const char    *what = NULL;
    if (iu->type != PHLEX_IC_ZERO) what = "ic_displacement_type";
    else if (is->type != PHLEX_IC_ZERO) what = "ic_stress_type";
    else if (iv->type != PHLEX_IC_ZERO && !(b->floating && (iv->type == PHLEX_IC_UNIFORM || iv->type == PHLEX_IC_RIGID))) what = "ic_velocity_type";
    PetscCheck(!what, part->comm, PETSC_ERR_USER_INPUT, "body %s: -%s%s: a reduced body starts with its elastic field at rest and undeformed (its frame placed and moving by -position, -orientation_*, -velocity, -angular_velocity or a rigid -ic_velocity_type); use the full body (-%stype flexible) for an initial elastic field", part->name, part->prefix, what, part->prefix);
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedGeometry(PhlexPart part, PhlexScaleHints *h)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  /* the same scales as the full body: swapping one for the other changes nothing else in the scene */
  r->full->process_cells = part->process_cells;
  PetscCall((*r->full->ops.geometry)(r->full, h));
  PetscFunctionReturn(0);
}

/* the self-checks of the basis: the held frequencies (-reduction_expect_held_frequencies) within a relative tolerance;
   Rayleigh-Ritz's upper bounds of the full body's frequencies (-reduction_expect_full_frequencies), and with
   craig_bampton the interlacing of its held (fixed-interface) frequencies between the reduced ones: the reduced space V
   holds the fixed-interface modes, and V with the 6 p port averages held is exactly their span (a constraint mode's
   interface values are independent), so by Cauchy's interlacing (a constraint of codimension 6 p)
   reduced_k <= held_k <= reduced_{k + 6 p}; all with the slack -reduction_expect_rtol */
static PetscErrorCode ReducedExpectFrequencies(PhlexPart part, Reduced *r)
{
  const PhlexUnits *u = part->units;
  const PetscReal   tol = r->expect_rtol, f0 = 1.0 / (2 * PETSC_PI * u->time);
  const PetscInt    m = r->md.m, nh = r->md.nnormal, shift = 6 * r->nports;
  PetscReal        *fr, *fh;
  char              what[PHLEX_NAME_LEN + 64];

  PetscFunctionBeginUser;
  if (!r->nexpect_held && !r->nexpect_full) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(m, &fr, PetscMax(nh, 1), &fh));
  for (PetscInt k = 0; k < m; k++) fr[k] = PetscSqrtReal(PetscMax(r->md.lambda[k], 0.0)) * f0;
  for (PetscInt k = 0; k < nh; k++) fh[k] = PetscSqrtReal(PetscMax(r->md.lambda_full[k], 0.0)) * f0;
  if (r->nexpect_held) {
    PetscCall(PetscSNPrintf(what, sizeof(what), "body %s: held frequencies", part->name));
    PetscCall(PhlexExpectValues(part->comm, what, "-reduction_expect_held_frequencies", nh, fh, r->nexpect_held, r->expect_held, tol));
  }
  if (r->nexpect_full) {
    const PetscInt n = PetscMin(r->nexpect_full, m);
    PetscReal      worst = 0.0;
    for (PetscInt k = 0; k < n; k++) {
      PetscCheck(fr[k] >= r->expect_full[k] * (1 - tol), part->comm, PETSC_ERR_USER, "body %s: reduced frequency %" PetscInt_FMT ": FAIL: %.10g Hz below the full body's %.10g Hz (Rayleigh-Ritz bounds it from above; slack %.1e, -reduction_expect_full_frequencies)", part->name, k + 1, (double)fr[k], (double)r->expect_full[k], (double)tol);
      worst = PetscMax(worst, fr[k] / r->expect_full[k] - 1);
    }
    PetscCall(PetscInfo(NULL, "body %s: the first %" PetscInt_FMT " reduced frequencies exceed the full body's by %g at most (relative)\n", part->name, n, (double)worst));
    if (r->type != PHLEX_REDUCTION_KRYLOV && !(r->type == PHLEX_REDUCTION_CRAIG_BAMPTON && r->nports) && nh > 0) {
      /* the basis holds the full body's lowest nh normal modes (the frame held as in the full body's modal
         analysis): Rayleigh-Ritz reproduces their frequencies, the lowest nh reduced ones, exactly */
      const PetscInt ne = PetscMin(n, nh);
      PetscReal      dev = 0.0;
      for (PetscInt k = 0; k < ne; k++) dev = PetscMax(dev, PetscAbsReal(fr[k] / r->expect_full[k] - 1));
      PetscCheck(dev <= tol, part->comm, PETSC_ERR_USER, "body %s: FAIL: the reduced frequencies of the %" PetscInt_FMT " normal modes in the basis differ from the full body's by %.2e relative (tolerance %.1e, -reduction_expect_full_frequencies)", part->name, ne, (double)dev, (double)tol);
      PetscCall(PetscPrintf(part->comm, "body %s: reduced frequencies of the %" PetscInt_FMT " normal modes in the basis against the full body's: max relative deviation %.1e (tolerance %.1e): PASS\n", part->name, ne, (double)dev, (double)tol));
    }
    if (r->type == PHLEX_REDUCTION_CRAIG_BAMPTON && r->nports)
      for (PetscInt k = 0; k < nh; k++) {
        PetscCheck(fr[k] <= fh[k] * (1 + tol), part->comm, PETSC_ERR_USER, "body %s: FAIL: reduced frequency %" PetscInt_FMT " %.10g Hz above held frequency %" PetscInt_FMT " %.10g Hz (interlacing)", part->name, k + 1, (double)fr[k], k + 1, (double)fh[k]);
        if (k + shift < m) PetscCheck(fh[k] <= fr[k + shift] * (1 + tol), part->comm, PETSC_ERR_USER, "body %s: FAIL: held frequency %" PetscInt_FMT " %.10g Hz above reduced frequency %" PetscInt_FMT " %.10g Hz (interlacing)", part->name, k + 1, (double)fh[k], k + shift + 1, (double)fr[k + shift]);
      }
    PetscCall(PetscPrintf(part->comm, "body %s: reduced frequencies: PASS (upper bounds of %" PetscInt_FMT " full frequencies%s)\n", part->name, n, r->type == PHLEX_REDUCTION_CRAIG_BAMPTON && r->nports ? ", interlaced with the held ones" : ""));
  }
  PetscCall(PetscFree2(fr, fh));
  PetscFunctionReturn(0);
}

/* the power its dampers dissipate at the evaluated state: zeta^T Rr zeta (the discrete unknowns are replicated) */
static PetscErrorCode ReducedDissipation(PhlexPart part, PetscReal *D)
{
  PetscFunctionBeginUser;
  *D = ((Reduced *)part->data)->diss;
  PetscFunctionReturn(0);
}

/* Rr = Mr V diag(2 zeta_i w_i) V^T Mr + alpha T Mr + beta/T Kr (non-dimensional: the rows Mr zeta' in time T), V the
   Mr-orthonormal eigenvectors of Kr V = Mr V diag(w_i^2), lowest first: symmetric positive semi-definite, each mode
   of the undamped pencil damped with the ratio zeta_i + alpha/(2 w) + beta w/2; modes of zero frequency get no modal
   term. NULL (and no dissipation op) when undamped: an undamped run is the same as before */
static PetscErrorCode ReducedDampingSetUp(PhlexPart part, Reduced *r)
{
  const PetscInt  m = r->md.m;
  const PetscReal T = part->units->time, alpha = r->fb->rayleigh_alpha, beta = r->fb->rayleigh_beta;
  PetscBool       modal = PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < r->nmodal_zeta; i++)
    if (r->modal_zeta[i] > 0) modal = PETSC_TRUE;
  if (!(modal || alpha > 0 || beta > 0) || !m) PetscFunctionReturn(0);
  PetscCall(PetscCalloc1(m * m, &r->Rr));
  for (PetscInt k = 0; k < m * m; k++) r->Rr[k] = alpha * T * r->md.Mr[k] + beta / T * r->md.Kr[k];
  if (modal) {
    PetscReal   *A, *B, *w, *W, *work, work1;
    PetscBLASInt bn, lwork = -1, info, one = 1;
    PetscCall(PetscBLASIntCast(m, &bn));
    PetscCall(PetscMalloc4(m * m, &A, m * m, &B, m, &w, m * m, &W));
    /* symmetric: row-major is column-major */
    PetscCall(PetscArraycpy(A, r->md.Kr, m * m));
    PetscCall(PetscArraycpy(B, r->md.Mr, m * m));
    PetscCallBLAS("LAPACKsygv", LAPACKsygv_(&one, "V", "U", &bn, A, &bn, B, &bn, w, &work1, &lwork, &info));
    PetscCall(PetscBLASIntCast((PetscInt)work1, &lwork));
    PetscCall(PetscMalloc1(lwork, &work));
    PetscCallBLAS("LAPACKsygv", LAPACKsygv_(&one, "V", "U", &bn, A, &bn, B, &bn, w, work, &lwork, &info));
    PetscCall(PetscFree(work));
    PetscCheck(!info, part->comm, PETSC_ERR_LIB, "body %s: the eigenmodes of the reduced pencil for its modal damping: LAPACK sygv info %d", part->name, (int)info);
    /* W = Mr V (column j: Mr v_j), then Rr += sum_j d_j W_j W_j^T */
    for (PetscInt i = 0; i < m; i++)
      for (PetscInt j = 0; j < m; j++) {
        PetscReal s = 0.0;
        for (PetscInt k = 0; k < m; k++) s += r->md.Mr[m * i + k] * A[m * j + k];
        W[m * j + i] = s;
      }
    for (PetscInt j = 0; j < m; j++) {
      const PetscReal z = r->modal_zeta[PetscMin(j, r->nmodal_zeta - 1)], d = 2.0 * z * PetscSqrtReal(PetscMax(w[j], 0.0));
      if (d == 0.0) continue;
      for (PetscInt i = 0; i < m; i++)
        for (PetscInt k = 0; k < m; k++) r->Rr[m * i + k] += d * W[m * j + i] * W[m * j + k];
    }
    PetscCall(PetscFree4(A, B, w, W));
  }
  part->ops.dissipation = ReducedDissipation;
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedSetUp(PhlexPart part)
{
  Reduced      *r = (Reduced *)part->data;
  PhlexFlexible b;
  char          prov[4096], who[PHLEX_NAME_LEN + 8];
  PetscBool     exists = PETSC_FALSE;
  PetscInt      m, nq;

  PetscFunctionBeginUser;
  r->full->units = part->units;
  for (PetscInt k = 0; k < 3; k++) r->full->gravity[k] = part->gravity[k];
  PetscCall((*r->full->ops.setup)(r->full));
  b = r->fb;
  PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", part->name));
  PetscCall(PhlexReducedProvenance(r->full, &r->red, prov, sizeof(prov)));
  if (r->file[0]) {
    /* rank 0 decides, so that every process reads or every process builds */
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(part->comm, &rank));
    if (!rank) PetscCall(PetscTestFile(r->file, 'r', &exists));
    PetscCallMPI(MPI_Bcast(&exists, 1, MPIU_BOOL, 0, part->comm));
  }
  if (!exists && r->file[0]) {
    /* the file will be written after the build: its directory must exist and be writable, checked before the work
       (it ended in HDF5's traceback, exit 1, after the build) */
    char        dir[PETSC_MAX_PATH_LEN], *slash;
    PetscBool   ok = PETSC_TRUE;
    PetscMPIInt rank;
    PetscCall(PetscStrncpy(dir, r->file, sizeof(dir)));
    slash = strrchr(dir, '/');
    if (slash == dir) slash[1] = 0;
    else if (slash) *slash = 0;
    else PetscCall(PetscStrcpy(dir, "."));
    PetscCallMPI(MPI_Comm_rank(part->comm, &rank));
    if (!rank) PetscCall(PetscTestDirectory(dir, 'w', &ok));
    PetscCallMPI(MPI_Bcast(&ok, 1, MPIU_BOOL, 0, part->comm));
    PetscCheck(ok, part->comm, PETSC_ERR_USER_INPUT, "body %s: option -%sreduced_file %s: the directory '%s' does not exist or is not writable (the reduced body file is written there after its build)", part->name, part->prefix, r->file, dir);
  }
  if (exists) PetscCall(PhlexReducedRead(part->comm, r->file, who, prov, part->units, &r->md));
  else {
    PetscCall(PhlexReducedBuild(r->full, &r->red, &r->md));
    PetscCall(PhlexReducedModelRoundTrip(&r->md, part->units));
    r->built = PETSC_TRUE;
    if (r->file[0]) PetscCall(PhlexReducedWrite(part->comm, r->file, part->name, &r->md, part->units, prov, &r->red));
  }
  {
    /* the checkpoint's fingerprint of the part (transient_checkpoint.c): the provenance of its model, so that a restart
       never reads elastic coordinates of another basis (another mesh, material, frame, ports or reduction) */
    unsigned long long h = 1469598103934665603ULL; /* FNV-1a, 64 bits */
    for (const char *c = prov; *c; c++) h = (h ^ (unsigned char)*c) * 1099511628211ULL;
    PetscCall(PetscSNPrintf(part->numbering, sizeof(part->numbering), "model#%016llx", h));
  }
  PetscCheck(r->md.nports == b->nports, part->comm, PETSC_ERR_PLIB, "body %s: the reduced model has %" PetscInt_FMT " ports, the body %" PetscInt_FMT, part->name, r->md.nports, b->nports);
  m = r->m      = r->md.m;
  PetscCall(ReducedDampingSetUp(part, r));
  r->nports     = b->nports;
  PetscCall(ReducedExpectFrequencies(part, r));
  if (r->nview_transfer) PetscCall(PhlexReducedViewTransfer(r->full, &r->md, r->nview_transfer, r->view_transfer));
  if (r->expect_moments_rtol > 0.0) PetscCall(PhlexReducedExpectMoments(r->full, &r->red, &r->md, r->expect_moments_rtol));
  r->floating   = b->floating;
  r->full_inertia = (PetscBool)(b->floating && !b->frozen_inertia);
  r->ie         = r->floating ? 18 : 0;
  r->iz         = r->ie + m;
  nq            = r->iz + m;
  PetscCall(PhlexPartSetUpLayout(part, 0, 0, 0, 0, nq));
  if (r->floating) {
    const char *const rn[18] = {"rx", "ry", "rz", "R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33", "vPx", "vPy", "vPz", "wx", "wy", "wz"};
    for (PetscInt k = 0; k < 18; k++) PetscCall(PhlexPartSetDof(part, k, k < 12 ? PHLEX_DOF_CONFIGURATION : PHLEX_DOF_VELOCITY, rn[k]));
    part->frame               = (PhlexFrameIndex){0, 3, 12, 15};
    part->nonlinear           = PETSC_TRUE;
    part->nonquadratic_energy = r->full_inertia;
  }
  for (PetscInt k = 0; k < m; k++) {
    char name[16];
    PetscCall(PetscSNPrintf(name, sizeof(name), "eta%" PetscInt_FMT, k + 1));
    PetscCall(PhlexPartSetDof(part, r->ie + k, PHLEX_DOF_ELASTIC, name));
    PetscCall(PetscSNPrintf(name, sizeof(name), "zeta%" PetscInt_FMT, k + 1));
    PetscCall(PhlexPartSetDof(part, r->iz + k, PHLEX_DOF_ELASTIC_VELOCITY, name));
  }
  /* the full body's ports: its listed surfaces, and a floating body's frame patch */
  {
    const PhlexUnits *u = part->units;
    const PetscBool   frame_port = (b->floating && b->frame_condition == PHLEX_FRAME_PATCH) ? PETSC_TRUE : PETSC_FALSE;
    const PetscInt    n = b->nports + (frame_port ? 1 : 0);
    PetscCall(PhlexPartSetPorts(part, n));
    for (PetscInt q = 0; q < n; q++) {
      PetscCall(PetscStrcpy(part->ports[q].name, q < b->nports ? b->ports[q].name : b->frame_patch));
      part->ports[q].dim = 6;
      for (PetscInt d = 0; d < 3; d++) part->ports[q].point[d] = q < b->nports ? (b->ports[q].centroid[d] - b->origin[d]) / u->length : 0.0;
    }
    PetscCall(PetscCalloc3(PetscMax(n, 1), &r->port_ext, PetscMax(n, 1), &r->port_y, PetscMax(n, 1), &r->port_ub));
  }
  if (!r->floating) {
    part->ops.momenta   = NULL; /* held: no momentum of its own, no frame to move */
    part->ops.rigidmass = NULL;
  }
  r->frame.comm       = part->comm;
  r->frame.frozen     = b->frozen_inertia;
  r->frame.gyroscopic = b->gyroscopic;
  r->frame.inertia    = r->md.inertia;
  r->frame.gravity    = part->gravity;
  PetscCall(PetscCalloc5(3 * PHLEX_FRAME_NIN * m, &r->Mom, m, &r->gext, m, &r->work, 36 * m, &r->nmom, 4 * m, &r->xcols));
  PetscCall(PetscCalloc2(m, &r->etad, m, &r->zetad));
  if (r->floating) PetscCall(PetscCalloc3(54 * PHLEX_FRAME_NIN, &r->Lb, 54 * PHLEX_FRAME_NIN, &r->Lu, 54 * PHLEX_FRAME_NIN, &r->Lv));
  PetscFunctionReturn(0);
}

/* one line of frequencies [Hz] from non-dimensional eigenvalues (written at once: the viewer indents each call) */
static PetscErrorCode ViewFrequencies(PetscViewer viewer, const char what[], PetscInt n, const PetscReal *lambda, const PhlexUnits *u)
{
  char  *line;
  size_t len = 128 + 16 * (size_t)n, k;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(len, &line));
  PetscCall(PetscStrcpy(line, what));
  for (PetscInt i = 0; i < n; i++) {
    PetscCall(PetscStrlen(line, &k));
    PetscCall(PetscSNPrintf(line + k, len - k, " %.6g", (double)(PetscSqrtReal(PetscMax(lambda[i], 0.0)) / (2 * PETSC_PI * u->time))));
  }
  PetscCall(PetscViewerASCIIPrintf(viewer, "%s\n", line));
  PetscCall(PetscFree(line));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedView(PhlexPart part, PetscViewer viewer)
{
  Reduced  *r = (Reduced *)part->data;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  if (r->type == PHLEX_REDUCTION_KRYLOV) {
    char   at[32 * PHLEX_KRYLOV_MAX_FREQUENCIES] = "";
    size_t n;
    for (PetscInt i = 0; i < r->red.nfrequencies; i++) {
      PetscCall(PetscStrlen(at, &n));
      PetscCall(PetscSNPrintf(at + n, sizeof(at) - n, "%s%.6g", i ? ", " : "", (double)r->red.frequencies[i]));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: reduced flexible body (krylov basis: %" PetscInt_FMT " block steps at %s Hz from the load vectors of %" PetscInt_FMT " ports, %" PetscInt_FMT " coordinates), %s %s\n", part->name, r->red.krylov_order, at, r->nports, r->m, r->built ? (r->file[0] ? "built and written to" : "built in memory") : "read from", r->file[0] ? r->file : ""));
  } else {
    const PetscBool cb = (PetscBool)(r->type == PHLEX_REDUCTION_CRAIG_BAMPTON && r->nports);
    char            statics[96] = "";
    if (r->nports) PetscCall(PetscSNPrintf(statics, sizeof(statics), " and the %s modes of %" PetscInt_FMT " port%s", cb ? "constraint" : "attachment", r->nports, r->nports > 1 ? "s" : ""));
    PetscCall(PetscViewerASCIIPrintf(viewer, "body %s: reduced flexible body (%s basis: %" PetscInt_FMT " %s modes%s, %" PetscInt_FMT " coordinates), %s%s%s\n", part->name, PhlexReductionTypes[r->type], r->md.nnormal, cb ? "fixed-interface" : "normal", statics, r->m, r->built ? (r->file[0] ? "built and written to" : "built in memory") : "read from", r->file[0] ? " " : "", r->file[0] ? r->file : ""));
  }
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(PetscViewerASCIIPrintf(viewer, "the full body it reduces:\n"));
  PetscCall(PetscViewerASCIIPushTab(viewer));
  PetscCall(PhlexPartView(r->full, viewer));
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscCall(ViewFrequencies(viewer, "reduced frequencies [Hz]:", r->m, r->md.lambda, u));
  if (r->type == PHLEX_REDUCTION_CRAIG_BAMPTON && r->nports) PetscCall(ViewFrequencies(viewer, "full body's frequencies with its ports held (the fixed-interface modes in the basis) [Hz]:", r->md.nnormal, r->md.lambda_full, u));
  else if (r->type != PHLEX_REDUCTION_KRYLOV) PetscCall(ViewFrequencies(viewer, "full body's frequencies of the normal modes in the basis [Hz]:", r->md.nnormal, r->md.lambda_full, u));
  if (r->nmodal_zeta) {
    char   list[1024] = "";
    size_t n;
    for (PetscInt i = 0; i < r->nmodal_zeta; i++) {
      PetscCall(PetscStrlen(list, &n));
      PetscCall(PetscSNPrintf(list + n, sizeof(list) - n, "%s%.6g", i ? ", " : "", (double)r->modal_zeta[i]));
    }
    PetscCall(PetscViewerASCIIPrintf(viewer, "modal damping ratios (modes of the reduced pencil, lowest first; the last for the modes beyond): %s\n", list));
  }
  PetscCall(PetscViewerASCIIPopTab(viewer));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedDestroy(PhlexPart part)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexPartDestroy(&r->full));
  if (r->m) PetscCall(PhlexReducedModelDestroy(&r->md));
  PetscCall(PetscFree5(r->Mom, r->gext, r->work, r->nmom, r->xcols));
  PetscCall(PetscFree2(r->etad, r->zetad));
  PetscCall(PetscFree3(r->Lb, r->Lu, r->Lv));
  PetscCall(PetscFree3(r->port_ext, r->port_y, r->port_ub));
  PetscCall(PetscFree(r->Rr));
  PetscCall(PetscFree(part->data));
  PetscFunctionReturn(0);
}

/* the frame placed and moving as the full body's would be (-position, -orientation_*, -velocity, -angular_velocity, a
   rigid initial velocity field); the elastic field at rest and undeformed */
static PetscErrorCode ReducedInitialState(PhlexPart part, PhlexPartVec *X)
{
  Reduced          *r = (Reduced *)part->data;
  PhlexFlexible     b = r->fb;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < part->nq; k++) X->q[k] = 0.0;
  if (r->floating) {
    PetscReal v0[3], w0[3];
    (void)PhlexFlexibleFrameVelocity(b, v0, w0);
    for (PetscInt k = 0; k < 3; k++) {
      X->q[k]      = b->pose.position[k] / u->length;
      X->q[12 + k] = v0[k] / u->velocity;
      X->q[15 + k] = w0[k] * u->time;
    }
    for (PetscInt k = 0; k < 9; k++) X->q[3 + k] = b->pose.rotation[k];
  }
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Evaluation, residual, Jacobian                                                                                 */

/* the frame's integrals of the field (frame.c's sums) from the invariants */
static void FieldSums(const Reduced *r, const PetscReal *eta, const PetscReal *etad, const PetscReal *zeta, const PetscReal *zetad, PetscReal sums[84])
{
  const PetscInt m = r->m;
  PetscReal     *U = sums, *Ud = sums + 3, *Vf = sums + 6, *Vfd = sums + 9, *Wu = sums + 12, *Wud = sums + 21, *Wv = sums + 30, *Wvd = sums + 39, *Nuu = sums + 48, *Nudu = sums + 57, *Nuv = sums + 66, *Nuvd = sums + 75;

  for (PetscInt i = 0; i < 84; i++) sums[i] = 0.0;
  for (PetscInt k = 0; k < m; k++) {
    const PetscReal *S = r->md.S + 3 * k, *W = r->md.W + 9 * k;
    for (PetscInt c = 0; c < 3; c++) {
      U[c] += S[c] * eta[k];
      Ud[c] += S[c] * etad[k];
      Vf[c] += S[c] * zeta[k];
      Vfd[c] += S[c] * zetad[k];
    }
    for (PetscInt i = 0; i < 9; i++) {
      Wu[i] += W[i] * eta[k];
      Wud[i] += W[i] * etad[k];
      Wv[i] += W[i] * zeta[k];
      Wvd[i] += W[i] * zetad[k];
    }
  }
  if (!r->full_inertia) return;
  {
    /* sum_{a,j} x_a y_j N_aj = sum_j y_j (sum_a x_a N_aj): from the moments of FieldMoments, O(m) */
    const PetscReal *nu = r->nmom, *nud = r->nmom + 9 * m;
    for (PetscInt k = 0; k < m; k++)
      for (PetscInt i = 0; i < 9; i++) {
        Nuu[i] += eta[k] * nu[9 * k + i];
        Nudu[i] += eta[k] * nud[9 * k + i];
        Nuv[i] += zeta[k] * nu[9 * k + i];
        Nuvd[i] += zetad[k] * nu[9 * k + i] + zeta[k] * nud[9 * k + i];
      }
  }
}

/* the moments through the mass of eta, eta' (full inertia only), zeta and zeta' with every basis vector k,
   sum_j x_j N_jk[b][c] (9 m values each, in r->nmom): once per evaluation, shared by the frame's sums and the node
   inputs' moments */
static PetscErrorCode FieldMoments(Reduced *r, const PetscReal *eta, const PetscReal *etad, const PetscReal *zeta, const PetscReal *zetad)
{
  const PetscInt m = r->m;
  PetscReal     *X = r->xcols, one = 1.0, zero = 0.0;
  PetscBLASInt   n9, nm, four = 4;

  PetscFunctionBeginUser;
  /* N as a 9m x m column-major matrix (entry (9k + i, j) = N_jk[i]): all moments in one product with [eta eta' zeta zeta'] */
  for (PetscInt k = 0; k < m; k++) {
    X[k]         = r->full_inertia ? eta[k] : 0.0;
    X[m + k]     = r->full_inertia ? etad[k] : 0.0;
    X[2 * m + k] = zeta[k];
    X[3 * m + k] = zetad[k];
  }
  PetscCall(PetscBLASIntCast(9 * m, &n9));
  PetscCall(PetscBLASIntCast(m, &nm));
  PetscCallBLAS("BLASgemm", BLASgemm_("N", "N", &n9, &four, &nm, &one, r->md.N, &n9, X, &nm, &zero, r->nmom, &n9));
  PetscFunctionReturn(0);
}

/* the node inputs' moments with each basis vector (PhlexFrameLoadCoefficients, PhlexFrameJacobian): inputs t, z = int
   rho y phi, Mv u', Mv v, Mv v', the load arm (none here: the reduced body adds its arms itself), int rho x phi */
static void InputMoments(Reduced *r)
{
  const PetscInt   m  = r->m;
  const PetscReal *nu = r->nmom, *nud = nu + 9 * m, *nv = nud + 9 * m, *nvd = nv + 9 * m;
  for (PetscInt k = 0; k < m; k++) {
    PetscReal       *Mom = r->Mom + 3 * PHLEX_FRAME_NIN * k;
    const PetscReal *S = r->md.S + 3 * k, *W = r->md.W + 9 * k;
    for (PetscInt i = 0; i < 3 * PHLEX_FRAME_NIN; i++) Mom[i] = 0.0;
    for (PetscInt c = 0; c < 3; c++) {
      Mom[c + 3 * PHLEX_FRAME_IN_T] = S[c];
      for (PetscInt bb = 0; bb < 3; bb++) {
        Mom[c + 3 * (PHLEX_FRAME_IN_Z + bb)]   = W[3 * bb + c] + nu[9 * k + 3 * bb + c];
        Mom[c + 3 * (PHLEX_FRAME_IN_ZD + bb)]  = nud[9 * k + 3 * bb + c];
        Mom[c + 3 * (PHLEX_FRAME_IN_MV + bb)]  = nv[9 * k + 3 * bb + c];
        Mom[c + 3 * (PHLEX_FRAME_IN_MVD + bb)] = nvd[9 * k + 3 * bb + c];
        Mom[c + 3 * (PHLEX_FRAME_IN_W + bb)]   = W[3 * bb + c];
      }
    }
  }
}

/* the arm of a force on port q from the frame origin P: its point, and with full inertia its mean displacement */
static inline void PortArm(const Reduced *r, PhlexPart part, PetscInt q, PetscReal arm[3])
{
  for (PetscInt k = 0; k < 3; k++) arm[k] = part->ports[q].point[k] + (r->full_inertia && q < r->nports ? r->port_ub[q][k] : 0.0);
}

static PetscErrorCode ReducedEvaluate(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot)
{
  Reduced          *r = (Reduced *)part->data;
  PhlexFlexible     b = r->fb;
  const PhlexUnits *u = part->units;
  const PetscInt    m = r->m;
  const PetscReal   T = u->time, *eta = X->q + r->ie, *zeta = X->q + r->iz;
  PhlexFrameState  *f = &r->fs;
  PetscReal        *etad = r->etad, *zetad = r->zetad, qd[18];

  PetscFunctionBeginUser;
  r->t_eval = t;
  if (r->Rr) {
    r->diss = 0.0;
    for (PetscInt k = 0; k < m; k++)
      for (PetscInt j = 0; j < m; j++) r->diss += zeta[k] * r->Rr[m * k + j] * zeta[j];
  }
  for (PetscInt k = 0; k < m; k++) etad[k] = zetad[k] = 0.0;
  if (Xdot)
    for (PetscInt k = 0; k < m; k++) {
      etad[k]  = T * Xdot->q[r->ie + k];
      zetad[k] = T * Xdot->q[r->iz + k];
    }
  /* the ports' mean displacements and rotations */
  for (PetscInt q = 0; q < r->nports; q++)
    for (PetscInt d = 0; d < 6; d++) {
      const PetscReal *P = r->md.P + 6 * m * q + m * d;
      PetscReal        s = 0.0;
      for (PetscInt k = 0; k < m; k++) s += P[k] * eta[k];
      r->port_ub[q][d] = s;
    }
  if (r->floating) {
    for (PetscInt k = 0; k < 18; k++) qd[k] = Xdot ? T * Xdot->q[k] : 0.0;
    PetscCall(FieldMoments(r, eta, etad, zeta, zetad));
    FieldSums(r, eta, etad, zeta, zetad, f->sums);
    f->sums_req = MPI_REQUEST_NULL;
    PetscCall(PhlexFrameEvaluateEnd(&r->frame, X->q, qd, f));
    InputMoments(r);
  }
  /* the external inputs: generalized forces on the field, resultant about P on the frame, their power */
  for (PetscInt k = 0; k < m; k++) r->gext[k] = 0.0;
  for (PetscInt k = 0; k < 3; k++) f->Fext[k] = f->Mext[k] = 0.0;
  for (PetscInt q = 0; q < r->nports; q++) {
    PetscReal *w = r->port_ext[q], arm[3], a[3];
    PetscCall(PhlexPortLoadEvaluate(&b->ports[q].load, t, u, r->floating ? f->R : NULL, w));
    if (!b->ports[q].load.loaded) continue;
    for (PetscInt d = 0; d < 6; d++)
      for (PetscInt k = 0; k < m; k++) r->gext[k] += r->md.P[6 * m * q + m * d + k] * w[d];
    if (r->floating) {
      PortArm(r, part, q, arm);
      PhlexCross(arm, w, a);
      for (PetscInt k = 0; k < 3; k++) {
        f->Fext[k] += w[k];
        f->Mext[k] += a[k] + w[3 + k];
      }
    }
  }
  for (PetscInt c = 0; c < 3; c++) r->beta[c] = 0.0;
  if (b->has_body_force) {
    PetscReal fr;
    PetscCall(PhlexProfileEvaluate(b->body_force_profile, t, &fr));
    for (PetscInt c = 0; c < 3; c++) r->beta[c] = fr * b->body_force[c] * u->length / u->modulus;
    for (PetscInt k = 0; k < m; k++) r->gext[k] += PhlexDot3(r->md.Svol + 3 * k, r->beta);
  }
  if (!r->floating)
    for (PetscInt k = 0; k < m; k++) r->gext[k] += PhlexDot3(r->md.S + 3 * k, part->gravity); /* the weight of a fixed body */
  /* the ports' outputs */
  for (PetscInt q = 0; q < part->nports; q++) {
    PetscReal *y = r->port_y[q];
    for (PetscInt d = 0; d < 6; d++) {
      y[d] = 0.0;
      if (q < r->nports)
        for (PetscInt k = 0; k < m; k++) y[d] += r->md.P[6 * m * q + m * d + k] * zeta[k];
    }
    if (r->floating) {
      PetscReal arm[3], a[3];
      PortArm(r, part, q, arm);
      PhlexCross(f->w, arm, a);
      for (PetscInt k = 0; k < 3; k++) {
        y[k] += f->vP[k] + a[k];
        y[3 + k] += f->w[k];
      }
    }
  }
  /* the inputs' power: the ports' w . y (their share of the frame's motion included), the body force on the field,
     and on a floating frame the frame wrench and the body force's resultant (both in Fext, Mext from here on) */
  r->power_ext = 0.0;
  for (PetscInt q = 0; q < r->nports; q++)
    if (b->ports[q].load.loaded)
      for (PetscInt d = 0; d < 6; d++) r->power_ext += r->port_ext[q][d] * r->port_y[q][d];
  if (b->has_body_force)
    for (PetscInt k = 0; k < m; k++) r->power_ext += PhlexDot3(r->md.Svol + 3 * k, r->beta) * zeta[k];
  if (r->floating) {
    PetscReal Fb[3] = {0, 0, 0}, Mb[3] = {0, 0, 0};
    if (b->frame_loaded) {
      PetscReal fr;
      PetscCall(PhlexProfileEvaluate(b->frame_profile, t, &fr));
      for (PetscInt k = 0; k < 3; k++) {
        Fb[k] = fr * b->frame_force[k] / u->force;
        Mb[k] = fr * b->frame_moment[k] / (u->force * u->length);
      }
    }
    if (b->has_body_force) {
      /* its resultant vol beta at P and its moment (int x + [full] int u) x beta */
      PetscReal arm[3], a[3];
      for (PetscInt c = 0; c < 3; c++) {
        arm[c] = r->md.inertia.svol[c];
        if (r->full_inertia)
          for (PetscInt k = 0; k < m; k++) arm[c] += r->md.Svol[3 * k + c] * eta[k];
      }
      PhlexCross(arm, r->beta, a);
      for (PetscInt k = 0; k < 3; k++) {
        Fb[k] += r->md.inertia.vol * r->beta[k];
        Mb[k] += a[k];
      }
    }
    r->power_ext += PhlexDot3(Fb, f->vP) + PhlexDot3(Mb, f->w);
    for (PetscInt k = 0; k < 3; k++) {
      f->Fext[k] += Fb[k];
      f->Mext[k] += Mb[k];
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedResidual(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot, PhlexPartVec *F)
{
  Reduced        *r = (Reduced *)part->data;
  const PetscInt  m = r->m;
  const PetscReal T = part->units->time, *eta = X->q + r->ie, *zeta = X->q + r->iz;
  PhlexFrameState f = r->fs; /* the joint wrenches join the inputs in a copy: the evaluation stays as it was */
  PetscReal      *g = r->work;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < m; k++) g[k] = r->gext[k];
  for (PetscInt q = 0; q < part->nports; q++) {
    const PetscReal *w = part->wrench[q];
    if (q < r->nports)
      for (PetscInt d = 0; d < 6; d++)
        if (w[d] != 0.0)
          for (PetscInt k = 0; k < m; k++) g[k] += r->md.P[6 * m * q + m * d + k] * w[d];
    if (r->floating) {
      PetscReal arm[3], a[3];
      PortArm(r, part, q, arm);
      PhlexCross(arm, w, a);
      for (PetscInt k = 0; k < 3; k++) {
        f.Fext[k] += w[k];
        f.Mext[k] += a[k] + w[3 + k];
      }
    }
  }
  if (r->floating) PetscCall(PhlexFrameResidual(&r->frame, &f, NULL, NULL, NULL, NULL, F->q));
  for (PetscInt k = 0; k < m; k++) F->q[r->ie + k] = T * Xdot->q[r->ie + k] - zeta[k];
  for (PetscInt k = 0; k < m; k++) {
    PetscReal s = -g[k];
    for (PetscInt j = 0; j < m; j++) s += r->md.Mr[m * k + j] * T * Xdot->q[r->iz + j] + r->md.Kr[m * k + j] * eta[j];
    if (r->Rr)
      for (PetscInt j = 0; j < m; j++) s += r->Rr[m * k + j] * zeta[j]; /* structural damping */
    F->q[r->iz + k] = s;
  }
  if (r->floating) {
    PetscReal A[3 * PHLEX_FRAME_NIN];
    PetscCall(PhlexFrameLoadCoefficients(&r->frame, &r->fs, A));
    for (PetscInt k = 0; k < m; k++) {
      const PetscReal *Mom = r->Mom + 3 * PHLEX_FRAME_NIN * k;
      PetscReal        s   = 0.0;
      for (PetscInt i = 0; i < 3 * PHLEX_FRAME_NIN; i++) s += A[i] * Mom[i];
      F->q[r->iz + k] += s;
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedJacobian(PhlexPart part, PetscReal shift, const PhlexPartVec *X, PetscReal *D, PetscInt ld)
{
  Reduced        *r = (Reduced *)part->data;
  PhlexFlexible   b = r->fb;
  const PetscInt  m = r->m, ie = r->ie, iz = r->iz, nin = PHLEX_FRAME_NIN;
  PetscReal       Bvv[9] = {0}, Bvu[9] = {0};

#define Dq(i, j) D[ld * (i) + (j)]
  PetscFunctionBeginUser;
  if (r->floating) {
    PetscReal *Lb = r->Lb, *Lu = r->Lu, *Lv = r->Lv, Arr[324];
    PetscCall(PhlexFrameJacobian(&r->frame, &r->fs, shift, Lb, Lu, Lv, nin, Bvv, Bvu, Arr));
    for (PetscInt i = 0; i < 18; i++)
      for (PetscInt j = 0; j < 18; j++) Dq(i, j) = Arr[18 * i + j];
    {
      /* the borders: sum_{c,i} L[(3 j + c) nin + i] Mom_k[c + 3 i], with L reordered once to Mom's layout so that each
         entry is a contiguous dot product */
      PetscReal Lt[3][18 * 3 * PHLEX_FRAME_NIN];
      for (PetscInt j = 0; j < 18; j++)
        for (PetscInt c = 0; c < 3; c++)
          for (PetscInt i = 0; i < nin; i++) {
            Lt[0][3 * nin * j + c + 3 * i] = Lu[(3 * j + c) * nin + i];
            Lt[1][3 * nin * j + c + 3 * i] = Lv[(3 * j + c) * nin + i];
            Lt[2][3 * nin * j + c + 3 * i] = Lb[(3 * j + c) * nin + i];
          }
      for (PetscInt k = 0; k < m; k++) {
        const PetscReal *Mom = r->Mom + 3 * nin * k;
        for (PetscInt j = 0; j < 18; j++) {
          const PetscReal *lu = Lt[0] + 3 * nin * j, *lv = Lt[1] + 3 * nin * j, *lb = Lt[2] + 3 * nin * j;
          PetscReal        su = 0.0, sv = 0.0, sb = 0.0;
          for (PetscInt i = 0; i < 3 * nin; i++) {
            su += lu[i] * Mom[i];
            sv += lv[i] * Mom[i];
            sb += lb[i] * Mom[i];
          }
          Dq(j, ie + k) = su;
          Dq(j, iz + k) = sv;
          Dq(iz + k, j) = sb;
        }
      }
    }
    if (r->full_inertia) {
      /* the arms of the forces move with the ports' mean displacements (and the body force's with int u) */
      for (PetscInt q = 0; q < r->nports; q++) {
        PetscReal F[3];
        for (PetscInt c = 0; c < 3; c++) F[c] = part->wrench[q][c] + (b->ports[q].load.loaded ? r->port_ext[q][c] : 0.0);
        for (PetscInt k = 0; k < m; k++) {
          PetscReal dub[3], a[3];
          for (PetscInt c = 0; c < 3; c++) dub[c] = r->md.P[6 * m * q + m * c + k];
          PhlexCross(dub, F, a);
          for (PetscInt c = 0; c < 3; c++) Dq(15 + c, ie + k) -= a[c];
        }
      }
      if (b->has_body_force)
        for (PetscInt k = 0; k < m; k++) {
          PetscReal a[3];
          PhlexCross(r->md.Svol + 3 * k, r->beta, a);
          for (PetscInt c = 0; c < 3; c++) Dq(15 + c, ie + k) -= a[c];
        }
    }
    /* inputs with directions fixed in the inertial frame turn with R */
    for (PetscInt q = 0; q < r->nports; q++) {
      if (!b->ports[q].load.loaded || b->ports[q].load.frame != PHLEX_DIRECTION_INERTIAL) continue;
      for (PetscInt kk = 0; kk < 9; kk++) {
        PetscReal dw[6], arm[3], a[3];
        PetscCall(PhlexPortLoadDerivativeR(&b->ports[q].load, r->t_eval, part->units, kk, dw));
        PortArm(r, part, q, arm);
        PhlexCross(arm, dw, a);
        for (PetscInt c = 0; c < 3; c++) {
          Dq(12 + c, 3 + kk) -= dw[c];
          Dq(15 + c, 3 + kk) -= a[c] + dw[3 + c];
        }
        for (PetscInt k = 0; k < m; k++)
          for (PetscInt d = 0; d < 6; d++) Dq(iz + k, 3 + kk) -= r->md.P[6 * m * q + m * d + k] * dw[d];
      }
    }
  }
  for (PetscInt k = 0; k < m; k++) {
    Dq(ie + k, ie + k) = shift;
    Dq(ie + k, iz + k) = -1.0;
    for (PetscInt i = 0; i < m; i++) {
      const PetscReal *N  = r->md.N + 9 * (k * m + i);
      PetscReal        sv = 0.0, su = 0.0;
      for (PetscInt j = 0; j < 9; j++) {
        sv += Bvv[j] * N[j];
        su += Bvu[j] * N[j];
      }
      Dq(iz + k, ie + i) = r->md.Kr[m * k + i] + su;
      Dq(iz + k, iz + i) = shift * r->md.Mr[m * k + i] + sv + (r->Rr ? r->Rr[m * k + i] : 0.0);
    }
  }
#undef Dq
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedPostStep(PhlexPart part, PetscReal *q, PetscReal *defect)
{
  PetscFunctionBeginUser;
  *defect = 0.0;
  if (!((Reduced *)part->data)->floating) PetscFunctionReturn(0);
  *defect = PhlexOrthogonalityError(q + 3);
  PhlexOrthonormalize(q + 3);
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Ports                                                                                                          */

static PetscErrorCode ReducedPortInput(PhlexPart part, PetscInt q, PetscReal t, PetscReal w[6])
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexiblePortInput(part, r->fb, r->floating, &r->fs, q, t, w));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedPortOutput(PhlexPart part, PetscInt q, PetscReal y[6])
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) y[k] = ((Reduced *)part->data)->port_y[q][k];
  PetscFunctionReturn(0);
}

/* dy for a change dq of its unknowns (it has no field unknowns) */
static PetscErrorCode ReducedPortLinear(PhlexPart part, PetscInt q, Vec du, PetscReal au, Vec dv, const PetscReal *dq, PetscReal dy[6])
{
  Reduced       *r = (Reduced *)part->data;
  const PetscInt m = r->m;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) dy[k] = 0.0;
  if (!dq) PetscFunctionReturn(0);
  if (q < r->nports)
    for (PetscInt d = 0; d < 6; d++) {
      const PetscReal *P = r->md.P + 6 * m * q + m * d, *dz = dq + r->iz;
      PetscReal        s = 0.0;
      for (PetscInt k = 0; k < m; k++) s += P[k] * dz[k];
      dy[d] = s;
    }
  if (r->floating) {
    PetscReal arm[3], a[3];
    if (r->full_inertia && q < r->nports) {
      /* w x d ubar */
      PetscReal dub[3];
      for (PetscInt c = 0; c < 3; c++) {
        const PetscReal *P = r->md.P + 6 * m * q + m * c, *de = dq + r->ie;
        PetscReal        s = 0.0;
        for (PetscInt k = 0; k < m; k++) s += P[k] * de[k];
        dub[c] = s;
      }
      PhlexCross(r->fs.w, dub, a);
      for (PetscInt c = 0; c < 3; c++) dy[c] += a[c];
    }
    PortArm(r, part, q, arm);
    PhlexCross(dq + 15, arm, a);
    for (PetscInt c = 0; c < 3; c++) {
      dy[c] += dq[12 + c] + a[c];
      dy[3 + c] += dq[15 + c];
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedPortForce(PhlexPart part, PetscInt q, const PetscReal w[6], Vec fv, PetscReal *fq)
{
  Reduced       *r = (Reduced *)part->data;
  const PetscInt m = r->m;

  PetscFunctionBeginUser;
  if (!fq) PetscFunctionReturn(0);
  if (q < r->nports) {
    const PetscReal *P = r->md.P + 6 * m * q;
    for (PetscInt k = 0; k < m; k++) {
      PetscReal s = 0.0;
      for (PetscInt d = 0; d < 6; d++) s += P[m * d + k] * w[d];
      fq[r->iz + k] += s;
    }
  }
  if (r->floating) {
    PetscReal arm[3], a[3];
    PortArm(r, part, q, arm);
    PhlexCross(arm, w, a);
    for (PetscInt c = 0; c < 3; c++) {
      fq[12 + c] += w[c];
      fq[15 + c] += a[c] + w[3 + c];
    }
  }
  PetscFunctionReturn(0);
}

/* inertial position and orientation of port q at the state X: r + R (c - P + ubar), R exp([theta]x) */
static PetscErrorCode ReducedPortPlacement(PhlexPart part, PetscInt q, const PhlexPartVec *X, PetscReal x[3], PetscReal Rp[9])
{
  Reduced       *r     = (Reduced *)part->data;
  const PetscInt m     = r->m;
  PetscReal      ub[6] = {0, 0, 0, 0, 0, 0};

  PetscFunctionBeginUser;
  if (q < r->nports)
    for (PetscInt d = 0; d < 6; d++)
      for (PetscInt k = 0; k < m; k++) ub[d] += r->md.P[6 * m * q + m * d + k] * X->q[r->ie + k];
  PhlexPortPlacementFromMean(r->floating ? X->q : NULL, part->ports[q].point, ub, x, Rp);
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Energy, outputs                                                                                                */

/* x^T A y for an m x m row-major A */
static PetscReal Quadratic(PetscInt m, const PetscReal *A, const PetscReal *x, const PetscReal *y)
{
  PetscReal s = 0.0;
  for (PetscInt i = 0; i < m; i++)
    for (PetscInt j = 0; j < m; j++) s += x[i] * A[m * i + j] * y[j];
  return s;
}

static PetscErrorCode ReducedEnergy(PhlexPart part, const PhlexPartVec *X, PetscReal *kin, PetscReal *strain, PetscReal *pot)
{
  Reduced         *r = (Reduced *)part->data;
  const PetscInt   m = r->m;
  const PetscReal *eta = X->q + r->ie, *zeta = X->q + r->iz, vMv = Quadratic(m, r->md.Mr, zeta, zeta);

  PetscFunctionBeginUser;
  *strain = 0.5 * Quadratic(m, r->md.Kr, eta, eta);
  if (r->floating) PetscCall(PhlexFrameEnergy(&r->frame, &r->fs, vMv, kin, pot));
  else {
    *kin = 0.5 * vMv;
    /* V = -g . int rho (x + u), as the full body's */
    *pot = -PhlexDot3(part->gravity, r->md.inertia.s0);
    for (PetscInt k = 0; k < m; k++) *pot -= PhlexDot3(r->md.S + 3 * k, part->gravity) * eta[k];
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedInputPower(PhlexPart part, PetscReal *P)
{
  PetscFunctionBeginUser;
  *P = ((Reduced *)part->data)->power_ext;
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedMomenta(PhlexPart part, PetscReal P[3], PetscReal L[3])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameMomenta(&((Reduced *)part->data)->fs, P, L));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedRigidMass(PhlexPart part, PetscReal M[36])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameRigidMass(&((Reduced *)part->data)->md.inertia, M));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedOutputOpen(PhlexPart part, PhlexOutput out, PetscBool fields)
{
  Reduced      *r = (Reduced *)part->data;
  PhlexFlexible b = r->fb;
  char          name[PHLEX_NAME_LEN + 16], header[1024];
  const size_t  len = (size_t)(2 * r->m + 1) * 16;
  char         *h;
  size_t        n;

  PetscFunctionBeginUser;
  if (r->nports || r->floating) {
    /* the full body's series: the frame first (its patch, or "frame" with mean axes), then the ports */
    const char **names;
    PetscInt     k = 0;
    PetscCall(PetscMalloc1(r->nports + 1, &names));
    if (r->floating) names[k++] = b->frame_patch[0] ? b->frame_patch : "frame";
    for (PetscInt p = 0; p < r->nports; p++) names[k++] = b->ports[p].name;
    PetscCall(PhlexPortSeriesOpen(out, part->name, k, names, &r->ports_csv));
    PetscCall(PetscFree(names));
  }
  if (r->floating) {
    PetscCall(PhlexFrameWriteHeader(header, sizeof(header)));
    PetscCall(PetscSNPrintf(name, sizeof(name), "%s_rigid.csv", part->name));
    PetscCall(PhlexOutputCSVOpen(out, name, header, &r->rigid_csv));
  }
  /* the elastic coordinates and their velocities (u = sum_k eta_k phi_k: eta in m, zeta in m/s) */
  PetscCall(PetscMalloc1(len, &h));
  PetscCall(PetscStrcpy(h, "time"));
  for (PetscInt k = 0; k < r->m; k++) {
    PetscCall(PetscStrlen(h, &n));
    PetscCall(PetscSNPrintf(h + n, len - n, ",eta%" PetscInt_FMT, k + 1));
  }
  for (PetscInt k = 0; k < r->m; k++) {
    PetscCall(PetscStrlen(h, &n));
    PetscCall(PetscSNPrintf(h + n, len - n, ",zeta%" PetscInt_FMT, k + 1));
  }
  PetscCall(PetscSNPrintf(name, sizeof(name), "%s_modal.csv", part->name));
  PetscCall(PhlexOutputCSVOpen(out, name, h, &r->modal_csv));
  PetscCall(PetscFree(h));
  if (fields) {
    /* the full body's fields, from the basis vectors and their stress modes (read from the file only now: a run
       without field output never needs them) */
    char who[PHLEX_NAME_LEN + 8];
    PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", part->name));
    PetscCall(PhlexReducedReadBasis(r->full, r->file, who, part->units, &r->md));
    PetscCall(PhlexFieldWriterCreate(out, b, part->name, &r->writer));
    if (r->floating) PetscCall(PhlexFieldWriterSetGeometryField(r->writer, "inertial_position"));
    PetscCall(VecDuplicate(r->md.Phi[0], &r->fu));
    PetscCall(VecDuplicate(r->md.Phi[0], &r->fv));
    PetscCall(VecDuplicate(r->md.Psi[0], &r->fsig));
    PetscCall(PetscMalloc1(r->m, &r->fcoef));
  }
  PetscFunctionReturn(0);
}

/* x = sum_k c_k V_k with the coordinates c (m of them, stride 1) */
static PetscErrorCode Combine(Reduced *r, const PetscReal *c, Vec *V, Vec x)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < r->m; k++) r->fcoef[k] = c[k];
  PetscCall(VecSet(x, 0.0));
  PetscCall(VecMAXPY(x, r->m, r->fcoef, V));
  PetscFunctionReturn(0);
}

/* one row of the series (ports, frame, elastic coordinates) at the evaluated state X */
static PetscErrorCode ReducedSeriesStep(PhlexPart part, PetscReal t, const PhlexPartVec *X)
{
  Reduced          *r = (Reduced *)part->data;
  PhlexFlexible     b = r->fb;
  const PhlexUnits *u = part->units;

  PetscFunctionBeginUser;
  if (r->ports_csv) PetscCall(PhlexFlexiblePortSeriesRow(part, b, r->floating, &r->fs, r->port_y, t, X, r->ports_csv));
  if (r->rigid_csv) {
    PetscReal P[3], L[3];
    PetscCall(PhlexFrameWriteRow(r->rigid_csv, t, &r->fs, u, P, L));
  }
  PetscCall(PhlexCSVPrintf(r->modal_csv, "%.12e", (double)t));
  for (PetscInt k = 0; k < r->m; k++) PetscCall(PhlexCSVPrintf(r->modal_csv, ",%.12e", (double)(X->q[r->ie + k] * u->length)));
  for (PetscInt k = 0; k < r->m; k++) PetscCall(PhlexCSVPrintf(r->modal_csv, ",%.12e", (double)(X->q[r->iz + k] * u->velocity)));
  PetscCall(PhlexCSVPrintf(r->modal_csv, "\n"));
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedOutputStep(PhlexPart part, PetscInt step, PetscReal t, const PhlexPartVec *X, PetscBool fields)
{
  Reduced      *r = (Reduced *)part->data;
  PhlexFlexible b = r->fb;

  PetscFunctionBeginUser;
  if (step >= 0) PetscCall(ReducedSeriesStep(part, t, X));
  if (fields && r->writer) {
    /* u = Phi eta, v = Phi zeta, Sigma = Psi eta: the full body's fields of the reduced state */
    const PetscReal *eta = X->q + r->ie, *zeta = X->q + r->iz;
    PetscCall(Combine(r, eta, r->md.Phi, r->fu));
    PetscCall(Combine(r, zeta, r->md.Phi, r->fv));
    PetscCall(Combine(r, eta, r->md.Psi, r->fsig));
    PetscCall(PhlexFlexibleWriteFields(b, r->writer, &r->fs, t, r->fu, r->fv, r->fsig));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode ReducedOutputClose(PhlexPart part)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(&r->ports_csv));
  PetscCall(PetscViewerDestroy(&r->rigid_csv));
  PetscCall(PetscViewerDestroy(&r->modal_csv));
  PetscCall(PhlexFieldWriterDestroy(&r->writer));
  PetscCall(VecDestroy(&r->fu));
  PetscCall(VecDestroy(&r->fv));
  PetscCall(VecDestroy(&r->fsig));
  PetscCall(PetscFree(r->fcoef));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Modal analysis (the analysis table)                                                                            */

/* The body's pencil at rest, the Rayleigh-Ritz projection on [rigid | Phi] of the full body's (flexible_modes.c:
   (K, Mv) of a fixed body, FloatingPencil of a floating one): on (v_P, w | zeta) for a floating body, zeta for a
   fixed one (n x n, symmetric),
     K = diag(0, Kr),   M = [[M6, C], [C^T, Mr]],   C = [int rho phi_k ; int rho x x phi_k] (column k),
   M6 the frame's rigid mass: the kinetic energy of v_P + w x x + Phi zeta. With mean axes the basis is Mv-orthogonal
   to the rigid fields and C vanishes (to round-off). */
static PetscErrorCode ReducedPencil(Reduced *r, PetscInt *n, PetscReal **K, PetscReal **M)
{
  const PetscInt m = r->m, o = r->floating ? 6 : 0, N = o + m;

  PetscFunctionBeginUser;
  *n = N;
  PetscCall(PetscCalloc2(N * N, K, N * N, M));
  for (PetscInt i = 0; i < m; i++)
    for (PetscInt j = 0; j < m; j++) {
      (*K)[N * (o + i) + o + j] = r->md.Kr[m * i + j];
      (*M)[N * (o + i) + o + j] = r->md.Mr[m * i + j];
    }
  if (r->floating) {
    PetscReal M6[36];
    PetscCall(PhlexFrameRigidMass(&r->md.inertia, M6));
    for (PetscInt i = 0; i < 6; i++)
      for (PetscInt j = 0; j < 6; j++) (*M)[N * i + j] = M6[6 * i + j];
    for (PetscInt k = 0; k < m; k++) {
      const PetscReal *S = r->md.S + 3 * k, *W = r->md.W + 9 * k; /* W[3 b + c] = int rho x_b phi_k,c */
      const PetscReal  c[6] = {S[0], S[1], S[2], W[5] - W[7], W[6] - W[2], W[1] - W[3]};
      for (PetscInt i = 0; i < 6; i++) (*M)[N * i + o + k] = (*M)[N * (o + k) + i] = c[i];
    }
  }
  PetscFunctionReturn(0);
}

/* The modes of a reduced body: K x = lambda M x on its pencil at rest (ReducedPencil),
  dense and small, by LAPACK (sygv); a floating body's six rigid modes first, as the full body's

  (every process holds the model and solves the same problem). Rayleigh-Ritz: every eigenvalue bounds the full body's of the same rank from above, and the full body's normal modes
  in the basis (those with the frame held: all of a fixed body's, a floating body's on mean axes) come out exactly.
  At most the basis's m elastic modes exist; nev nearest -modes_target_frequency, else the lowest. The shapes (vecs,
  rigid, when asked) are the full body's fields Phi x of the eigenvectors and their frames' velocities. */
static PetscErrorCode ReducedComputeModes(PhlexPart part, PetscInt nev, PetscInt *nconv, PetscInt *nrigid, PetscReal **lambda, Vec **vecs, PetscReal **rigid, PetscReal **resid)
{
  Reduced     *r = (Reduced *)part->data;
  PetscInt     n, nr, ne, first;
  PetscReal   *K, *M, *A, *B, *w, *work, lmin = PETSC_MAX_REAL, rigid_below, nrmk = 0, nrmm = 0, ftarget = -1, work1;
  PetscBLASInt bn, lwork = -1, info, one = 1;
  PetscBool    target;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscCall(ReducedPencil(r, &n, &K, &M));
  PetscCall(PetscMalloc3(n * n, &A, n * n, &B, n, &w));
  PetscCall(PetscArraycpy(A, K, n * n));
  PetscCall(PetscArraycpy(B, M, n * n));
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCallBLAS("LAPACKsygv", LAPACKsygv_(&one, "V", "U", &bn, A, &bn, B, &bn, w, &work1, &lwork, &info));
  lwork = (PetscBLASInt)work1;
  PetscCall(PetscMalloc1(lwork, &work));
  PetscCallBLAS("LAPACKsygv", LAPACKsygv_(&one, "V", "U", &bn, A, &bn, B, &bn, w, work, &lwork, &info));
  PetscCheck(!info, part->comm, PETSC_ERR_LIB, "body %s: LAPACK sygv failed on the reduced pencil (info %d: the reduced mass is not positive definite if > %d)", part->name, (int)info, (int)n);
  PetscCall(PetscFree(work));
  /* rigid: |lambda| below 1e-6 of the lowest reduced eigenvalue with the frame held (the flexible body's rule with its
     frequency scale) */
  for (PetscInt k = 0; k < r->m; k++)
    if (r->md.lambda[k] > 0) lmin = PetscMin(lmin, r->md.lambda[k]);
  rigid_below = 1e-6 * lmin;
  nr          = 0;
  for (PetscInt k = 0; k < n; k++)
    if (PetscAbsReal(w[k]) < rigid_below) nr++;
  ne = PetscMin(nev, n - nr);
  if (nev > n - nr) PetscCall(PetscPrintf(part->comm, "body %s: its basis has %" PetscInt_FMT " elastic modes, fewer than the %" PetscInt_FMT " asked for (-modes_nev): all are given\n", part->name, n - nr, nev));
  /* the ne elastic eigenvalues nearest the target (a contiguous run of the ascending ones), else the lowest */
  PetscCall(PetscOptionsGetReal(NULL, NULL, "-modes_target_frequency", &ftarget, &target));
  first = nr;
  if (target && ftarget > 0) {
    const PetscReal sigma = PetscSqr(2.0 * PETSC_PI * ftarget * part->units->time);
    while (first + ne < n && PetscAbsReal(w[first + ne] - sigma) < PetscAbsReal(w[first] - sigma)) first++;
  }
  for (PetscInt i = 0; i < n; i++) {
    PetscReal sk = 0, sm = 0; /* the infinity norms */
    for (PetscInt j = 0; j < n; j++) {
      sk += PetscAbsReal(K[n * i + j]);
      sm += PetscAbsReal(M[n * i + j]);
    }
    nrmk = PetscMax(nrmk, sk);
    nrmm = PetscMax(nrmm, sm);
  }
  *nconv  = nr + ne;
  *nrigid = nr;
  PetscCall(PetscMalloc1(*nconv, lambda));
  if (resid) PetscCall(PetscMalloc1(*nconv, resid));
  for (PetscInt i = 0; i < *nconv; i++) {
    const PetscInt   e = i < nr ? i : first + (i - nr);
    const PetscReal *x = A + n * e, lam = w[e];
    PetscReal        res = 0, xn = 0;
    (*lambda)[i] = lam;
    if (!resid) continue;
    /* ||K x - lambda M x||_2 / (|lambda| ||x||_2); a rigid mode's backward error / ((||K|| + |lambda| ||M||) ||x||) */
    for (PetscInt a = 0; a < n; a++) {
      PetscReal s = 0;
      for (PetscInt b = 0; b < n; b++) s += (K[n * a + b] - lam * M[n * a + b]) * x[b];
      res += s * s;
      xn += x[a] * x[a];
    }
    res = PetscSqrtReal(res), xn = PetscSqrtReal(xn);
    (*resid)[i] = i < nr ? res / ((nrmk + PetscAbsReal(lam) * nrmm) * xn) : res / (PetscAbsReal(lam) * xn);
  }
  if (vecs || rigid) {
    /* the shapes: the field Phi x_eta of each mode on the full body's mesh (the basis kept from the build, or read from
       the file) and a floating body's frame velocity (v_P, w) */
    const PetscInt o = r->floating ? 6 : 0;
    if (vecs) {
      char who[PHLEX_NAME_LEN + 8];
      PetscCall(PetscSNPrintf(who, sizeof(who), "body %s", part->name));
      PetscCall(PhlexReducedReadBasis(r->full, r->file, who, part->units, &r->md));
      PetscCall(PetscMalloc1(*nconv, vecs));
    }
    if (rigid) PetscCall(PetscMalloc1(6 * *nconv, rigid));
    for (PetscInt i = 0; i < *nconv; i++) {
      const PetscInt   e = i < nr ? i : first + (i - nr);
      const PetscReal *x = A + n * e;
      if (vecs) {
        PetscCall(VecDuplicate(r->md.Phi[0], &(*vecs)[i]));
        PetscCall(VecSet((*vecs)[i], 0.0));
        PetscCall(VecMAXPY((*vecs)[i], r->m, x + o, r->md.Phi));
      }
      if (rigid)
        for (PetscInt c = 0; c < 6; c++) (*rigid)[6 * i + c] = r->floating ? x[c] : 0.0;
    }
  }
  PetscCall(PetscFree3(A, B, w));
  PetscCall(PetscFree2(K, M));
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* -analysis reduce: its file, built and written at set-up or read there with its provenance checked */
static PetscErrorCode ReducedReduce(PhlexPart part, PetscViewer viewer)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCheck(r->file[0], part->comm, PETSC_ERR_USER_INPUT, "body %s: -analysis reduce writes the reduced body file: give -%sreduced_file <file>", part->name, part->prefix);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  body %s: %s %s (%" PetscInt_FMT " coordinates)\n", part->name, r->built ? "built and written to" : "up to date (its provenance matches the scene):", r->file, r->m));
  PetscFunctionReturn(0);
}

/* the mode shapes on the full body's mesh (<body>_modes.h5, .xmf), written as the full body writes its own */
static PetscErrorCode ReducedModesOutput(PhlexPart part, PhlexOutput out, PetscInt nconv, PetscInt nrigid, const PetscReal *lambda, Vec *vecs, const PetscReal *rigid, const PetscReal *placement)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleModesOutput(r->full, out, nconv, nrigid, lambda, vecs, rigid, placement));
  PetscFunctionReturn(0);
}

/* "clamped" or "floating" (a reduced fixed body is clamped at its frame patch), its coordinates; 6 rigid-body modes
   for a floating body, -1 (not counted) for a clamped one */
static PetscErrorCode ReducedModesKind(PhlexPart part, char buf[], size_t len, PetscInt *nrigid)
{
  Reduced *r = (Reduced *)part->data;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(buf, len, "%s; reduced, %" PetscInt_FMT " elastic coordinates", r->floating ? "floating" : "clamped", r->m));
  *nrigid = r->floating ? 6 : -1;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartCreate_Reduced - a reduced flexible body (part kind "reduced")
@*/
PetscErrorCode PhlexPartCreate_Reduced(PhlexPart part)
{
  Reduced *r;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&r));
  PetscCall(PetscNew(&part->analysisops));
  part->data               = r;
  part->ops.setfromoptions = ReducedSetFromOptions;
  part->ops.geometry       = ReducedGeometry;
  part->ops.setup          = ReducedSetUp;
  part->ops.view           = ReducedView;
  part->ops.destroy        = ReducedDestroy;
  part->ops.initialstate   = ReducedInitialState;
  part->ops.evaluate       = ReducedEvaluate;
  part->ops.residual       = ReducedResidual;
  part->ops.jacobian       = ReducedJacobian;
  part->ops.poststep       = ReducedPostStep;
  part->ops.portoutput     = ReducedPortOutput;
  part->ops.portinput      = ReducedPortInput;
  part->ops.portlinear     = ReducedPortLinear;
  part->ops.portforce      = ReducedPortForce;
  part->ops.portplacement  = ReducedPortPlacement;
  part->ops.energy         = ReducedEnergy;
  part->ops.inputpower     = ReducedInputPower;
  part->ops.momenta        = ReducedMomenta;
  part->ops.rigidmass      = ReducedRigidMass;
  part->ops.outputopen     = ReducedOutputOpen;
  part->ops.outputstep     = ReducedOutputStep;
  part->ops.outputclose    = ReducedOutputClose;
  part->analysisops->modes       = ReducedComputeModes;
  part->analysisops->modeskind   = ReducedModesKind;
  part->analysisops->modesoutput = ReducedModesOutput;
  part->analysisops->reduce      = ReducedReduce;
  PetscFunctionReturn(0);
}
