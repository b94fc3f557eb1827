/* Structural damping of a flexible body in port-Hamiltonian form (issue 45): a dissipative term R v on the velocity
   rows of the mixed velocity-stress equations (paper eq. (ph-mixed), (ph_mfd_all) with J - R),

       T Mv v' = -G^T Sigma - R v + b,      R = alpha T Mv + K_eta / T      (non-dimensional),

   R symmetric positive semi-definite, so the dissipated power v^T R v >= 0. Three sources, summed into one matrix:
     - Kelvin-Voigt: a viscous stress Sigma_v = (eta / E) D eps(v) per material region (viscous moduli proportional to
       the elastic ones, the elastic Poisson's ratio; -viscosity, -region_<name>_viscosity [Pa s]); eliminated cell by
       cell like the elastic stress it is the stiffness of the viscous moduli applied to v;
     - Rayleigh beta K: Kelvin-Voigt with eta = beta E in every region (-rayleigh_beta [s]);
     - Rayleigh alpha Mv (-rayleigh_alpha [1/s]) on the velocity field: for a floating body the elastic velocity
       relative to its frame, so the frame's rows, whose sums are the momenta, see no damping force (a tumbling damped
       body keeps its momenta and loses only elastic energy).
   A mode of pulsation w of the undamped body decays with the damping ratio zeta = alpha / (2 w) + (beta + eta/E) w / 2.

   R is assembled once (flexible_fe.c, PhlexFlexibleAssembleDamping) and costs one sparse product per residual (R v)
   and one for the dissipated power at the monitor's evaluation point; SNES phlexcondensed forms R v0 for its
   right-hand side itself (PhlexFieldOperators' R). The evaluations for the energy and the outputs form none. It enters every
   velocity block: the fixed body's Jvv = shift Mv + R, the floating body's shells (shift + Bvv) Mv + R, and the
   preconditioners' condensed operator Sv = shift Mv + K / shift + R (flexible_dynamics.c). With the implicit
   midpoint rule the power balance H_{n+1} - H_n = dt (P - v_m^T R v_m) holds to solver tolerance. */
#include <phlex_impl.h>

/* the power its dampers dissipate at the evaluated state: v^T R v (non-dimensional) */
static PetscErrorCode FlexDissipation(PhlexPart part, PetscReal *D)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleDampingForce(part));
  PetscCall(MPIU_Allreduce(&b->diss_loc, D, 1, MPIU_REAL, MPI_SUM, b->comm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingSetFromOptions - reads the body's Rayleigh coefficients (the viscosities are read with the
  materials) and checks them; a damped body gets the part's dissipation op

  Collective

  Options Database Keys:
+ -body<k>_rayleigh_alpha <a> - Rayleigh mass coefficient [1/s] (>= 0)
- -body<k>_rayleigh_beta <b>  - Rayleigh stiffness coefficient [s] (>= 0)
@*/
PetscErrorCode PhlexFlexibleDampingSetFromOptions(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscBool     viscous = PETSC_FALSE;

  PetscFunctionBeginUser;
  PetscOptionsBegin(b->comm, b->prefix, "Structural damping", NULL);
  PetscCall(PetscOptionsReal("-rayleigh_alpha", "Rayleigh damping alpha Mv on the elastic velocity field (relative to a floating frame): damping ratio alpha/(2 w) of a mode of pulsation w [1/s]", "PhlexFlexibleDampingSetFromOptions", b->rayleigh_alpha, &b->rayleigh_alpha, NULL));
  PetscCall(PetscOptionsReal("-rayleigh_beta", "Rayleigh damping beta K (Kelvin-Voigt with the viscous moduli beta times the elastic ones, every region): damping ratio beta w/2 [s]", "PhlexFlexibleDampingSetFromOptions", b->rayleigh_beta, &b->rayleigh_beta, NULL));
  PetscOptionsEnd();
  PetscCheck(b->rayleigh_alpha >= 0 && !PetscIsInfOrNanReal(b->rayleigh_alpha), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%srayleigh_alpha must be >= 0 [1/s] (a negative damping feeds energy in), got %g", b->name, b->prefix, (double)b->rayleigh_alpha);
  PetscCheck(b->rayleigh_beta >= 0 && !PetscIsInfOrNanReal(b->rayleigh_beta), b->comm, PETSC_ERR_USER_INPUT, "body %s: -%srayleigh_beta must be >= 0 [s] (a negative damping feeds energy in), got %g", b->name, b->prefix, (double)b->rayleigh_beta);
  for (PetscInt m = 0; m < b->nmaterials; m++)
    if (b->materials[m].viscosity > 0) viscous = PETSC_TRUE;
  b->damped = (PetscBool)(b->rayleigh_alpha > 0 || b->rayleigh_beta > 0 || viscous);
  if (!b->damped) PetscFunctionReturn(0);
  PetscCheck(!b->stiffening && !b->spinning, b->comm, PETSC_ERR_SUP, "body %s: structural damping (-%srayleigh_alpha, -%srayleigh_beta, -%sviscosity) is not implemented with %s: remove the damping or that option", b->name, b->prefix, b->prefix, b->prefix, b->stiffening ? "geometric stiffening (-geometric_stiffening)" : "a prescribed spin (-spin)");
  part->ops.dissipation = FlexDissipation;
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingSetUp - the damping matrix R (AIJ) and its product's vector, once, if the body is damped

  Collective
@*/
PetscErrorCode PhlexFlexibleDampingSetUp(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  Mat           Rs;

  PetscFunctionBeginUser;
  if (!b->damped || b->Rd) PetscFunctionReturn(0);
  PetscCall(PhlexFlexibleAssembleDamping(b, part->units, &Rs));
  PetscCall(MatConvert(Rs, MATAIJ, MAT_INITIAL_MATRIX, &b->Rd));
  b->Rsb = Rs;
  PetscCall(MatSetOption(b->Rd, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(PetscObjectSetName((PetscObject)b->Rd, "structural damping"));
  PetscCall(MatCreateVecs(b->Rd, &b->rv, &b->veval));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingEvaluate - keeps the evaluated state's velocity (a copy: the product R v is formed only when a
  residual or the dissipated power asks for it, not for the evaluations of the energy and the outputs)

  Collective
@*/
PetscErrorCode PhlexFlexibleDampingEvaluate(PhlexPart part, Vec v)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (!b->damped) PetscFunctionReturn(0);
  PetscCall(PhlexFlexibleDampingSetUp(part));
  PetscCall(VecCopy(v, b->veval));
  b->evaluated = PETSC_TRUE;
  b->rv_valid  = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingForce - R v at the evaluated state (b->rv) and this process's part of v^T R v, formed once per
  evaluation

  Collective
@*/
PetscErrorCode PhlexFlexibleDampingForce(PhlexPart part)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCheck(b->evaluated, b->comm, PETSC_ERR_ORDER, "body %s: its damping force was asked for before an evaluation", b->name);
  if (b->rv_valid) PetscFunctionReturn(0);
  PetscCall(MatMult(b->Rsb, b->veval, b->rv));
  PetscCall(PhlexLocalDot(b->rv, b->veval, &b->diss_loc));
  b->rv_valid = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingView - the summary's line of a damped body (nothing for an undamped one)
@*/
PetscErrorCode PhlexFlexibleDampingView(PhlexFlexible b, PetscViewer viewer)
{
  char a[32], be[32], eta[32];

  PetscFunctionBeginUser;
  if (!b->damped) PetscFunctionReturn(0);
  if (b->rayleigh_alpha > 0 || b->rayleigh_beta > 0) PetscCall(PetscViewerASCIIPrintf(viewer, "structural damping: Rayleigh alpha = %s 1/s, beta = %s s (elastic field only)\n", PhlexFormatReal(b->rayleigh_alpha, a, sizeof(a)), PhlexFormatReal(b->rayleigh_beta, be, sizeof(be))));
  for (PetscInt m = 0; m < b->nmaterials; m++)
    if (b->materials[m].viscosity > 0) PetscCall(PetscViewerASCIIPrintf(viewer, "Kelvin-Voigt viscosity %s: eta = %s Pa s\n", b->materials[m].region[0] ? b->materials[m].region : "(whole body)", PhlexFormatReal(b->materials[m].viscosity, eta, sizeof(eta))));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleDampingDestroy - frees R and its vector
@*/
PetscErrorCode PhlexFlexibleDampingDestroy(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  PetscCall(MatDestroy(&b->Rd));
  PetscCall(MatDestroy(&b->Rsb));
  PetscCall(VecDestroy(&b->rv));
  PetscCall(VecDestroy(&b->veval));
  PetscFunctionReturn(0);
}
