/* The discrete pH system of a clamped (body-fixed frame) elastic body in implicit form (paper Section 4.1, eq.
   eldyn_PDE after integration by parts of J_Div), non-dimensional, with unknowns X = [u | Sigma | v]:

     F_u     = u' - v                         (kinematics u_f' = v_f)
     F_Sigma = G v - Ms Sigma'                (compatibility, rows negated so that the (Sigma, v) block is symmetric)
     F_v     = Mv v' + G^T Sigma - B u(t)     (momentum balance; B u(t): port wrenches and body force)

   The operators Mv, Ms, G are constant in the body frame and assembled once (body.c); the residual is a few
   sparse mat-vecs. The time derivative from TS is in seconds (options stay in SI): X'_nondim = T X'_SI. */
#include <phlex_impl.h>

const char *const PhlexFieldNames[] = {"displacement", "stress", "velocity"};

static PetscErrorCode IdentityMatrix(MPI_Comm comm, PetscInt n, PetscReal value, Mat *A)
{
  Vec d;

  PetscFunctionBeginUser;
  PetscCall(MatCreateAIJ(comm, n, n, PETSC_DETERMINE, PETSC_DETERMINE, 1, NULL, 0, NULL, A));
  PetscCall(MatCreateVecs(*A, &d, NULL));
  PetscCall(VecSet(d, value));
  PetscCall(MatDiagonalSet(*A, d, INSERT_VALUES));
  PetscCall(VecDestroy(&d));
  PetscFunctionReturn(0);
}

/* Preconditioning matrices of field subsets, assembled on demand when PCFIELDSPLIT asks for a split:
   {velocity}: shift Mv + K/shift, the exact Schur complement of the displacement and stress (element-wise);
   {stress, velocity}: the assembled (Sigma, v) block, the exact Schur complement of the displacement. */
static PetscErrorCode SystemUpdatePmats(PhlexSystem *sys)
{
  const PetscReal s = sys->shift;
  PhlexBody       b = sys->body;

  PetscFunctionBeginUser;
  if (sys->Sv) {
    PetscCall(MatCopy(sys->K, sys->Sv, SUBSET_NONZERO_PATTERN));
    PetscCall(MatScale(sys->Sv, 1.0 / s));
    PetscCall(MatAXPY(sys->Sv, 1.0, sys->Jvv, SUBSET_NONZERO_PATTERN));
  }
  if (sys->Ssv) {
    Mat blocks[4] = {sys->Jss, sys->Jsv, sys->Jvs, sys->Jvv}, N;
    PetscCall(MatCreateNest(b->comm, 2, NULL, 2, NULL, blocks, &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_REUSE_MATRIX, &sys->Ssv));
    PetscCall(MatDestroy(&N));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode SystemPmat(void *ctx, PetscInt n, const PetscInt fields[], Mat *P)
{
  PhlexSystem *sys = (PhlexSystem *)ctx;
  PhlexBody    b   = sys->body;

  PetscFunctionBeginUser;
  *P = NULL;
  PetscCheck(sys->shift > 0, b->comm, PETSC_ERR_ORDER, "preconditioner requested before the Jacobian");
  if (n == 1 && fields[0] == PHLEX_FIELD_VELOCITY) {
    if (!sys->Sv) {
      MatNullSpace nsp;
      /* AIJ: taken by every factorisation and by GAMG; its pattern is the union of those of K and Mv */
      PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &sys->K));
      PetscCall(MatDuplicate(sys->K, MAT_COPY_VALUES, &sys->Sv));
      PetscCall(MatAXPY(sys->Sv, 1.0, sys->Jvv, DIFFERENT_NONZERO_PATTERN));
      PetscCall(MatSetOption(sys->Sv, MAT_SPD, PETSC_TRUE));
      PetscCall(DMPlexCreateRigidBody(b->dm, 0, &nsp));
      PetscCall(MatSetNearNullSpace(sys->Sv, nsp));
      PetscCall(MatNullSpaceDestroy(&nsp));
      PetscCall(PetscObjectSetName((PetscObject)sys->Sv, "condensed velocity operator"));
      PetscCall(SystemUpdatePmats(sys));
    }
    *P = sys->Sv;
  } else if (n == 2 && fields[0] == PHLEX_FIELD_STRESS && fields[1] == PHLEX_FIELD_VELOCITY) {
    if (!sys->Ssv) {
      Mat blocks[4] = {sys->Jss, sys->Jsv, sys->Jvs, sys->Jvv}, N;
      PetscCall(MatCreateNest(b->comm, 2, NULL, 2, NULL, blocks, &N));
      PetscCall(MatConvert(N, MATAIJ, MAT_INITIAL_MATRIX, &sys->Ssv));
      PetscCall(MatDestroy(&N));
      PetscCall(MatSetOption(sys->Ssv, MAT_SYMMETRIC, PETSC_TRUE));
      PetscCall(PetscObjectSetName((PetscObject)sys->Ssv, "stress-velocity operator"));
    }
    *P = sys->Ssv;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemCreate - builds the unknown layout and the Jacobian structure of a scene

  Collective

  Options Database Key:
. -phlex_jacobian_aij - also assemble the Jacobian as one AIJ matrix (for monolithic factorisations and -snes_test_jacobian)
@*/
PetscErrorCode PhlexSystemCreate(PhlexScene scene, PhlexSystem **system)
{
  PhlexSystem *sys;
  PhlexBody    b = scene->bodies[0];
  PetscInt     nlocal[PHLEX_NUM_FIELDS], bs[PHLEX_NUM_FIELDS];

  PetscFunctionBeginUser;
  PetscCall(PhlexBodySetUpMixed(b, &scene->units));
  PetscCall(PetscNew(&sys));
  sys->scene = scene;
  sys->body  = b;
  nlocal[PHLEX_FIELD_DISPLACEMENT] = b->nv_local;
  nlocal[PHLEX_FIELD_STRESS]       = b->ns_local;
  nlocal[PHLEX_FIELD_VELOCITY]     = b->nv_local;
  bs[PHLEX_FIELD_DISPLACEMENT]     = 3;
  bs[PHLEX_FIELD_STRESS]           = b->nb_s;
  bs[PHLEX_FIELD_VELOCITY]         = 3;
  PetscCall(PhlexLayoutCreateDM(scene->comm, PHLEX_NUM_FIELDS, PhlexFieldNames, nlocal, bs, SystemPmat, sys, &sys->dm));
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++) PetscCall(PhlexLayoutGetFieldIS(sys->dm, f, &sys->is[f]));

  PetscCall(IdentityMatrix(scene->comm, b->nv_local, 1.0, &sys->Juu));
  PetscCall(IdentityMatrix(scene->comm, b->nv_local, -1.0, &sys->Juv));
  PetscCall(MatDuplicate(b->Ms, MAT_COPY_VALUES, &sys->Jss));
  PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &sys->Mv));
  PetscCall(MatDuplicate(sys->Mv, MAT_COPY_VALUES, &sys->Jvv));
  PetscCall(MatTranspose(b->G, MAT_INITIAL_MATRIX, &sys->Gt));
  sys->Jsv = b->G;
  sys->Jvs = sys->Gt;
  PetscCall(PetscObjectReference((PetscObject)b->G));
  {
    Mat blocks[9] = {sys->Juu, NULL, sys->Juv, NULL, sys->Jss, sys->Jsv, NULL, sys->Jvs, sys->Jvv};
    PetscCall(MatCreateNest(scene->comm, PHLEX_NUM_FIELDS, sys->is, PHLEX_NUM_FIELDS, sys->is, blocks, &sys->J));
  }
  PetscCall(PetscObjectSetName((PetscObject)sys->J, "Jacobian"));
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-phlex_jacobian_aij", &sys->use_aij, NULL));
  PetscCall(DMCreateGlobalVector(b->dm, &sys->load));
  *system = sys;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemIFunction - F(t, X, X') of the body (TS IFunction, t and X' in SI time)

  Collective
@*/
PetscErrorCode PhlexSystemIFunction(TS ts, PetscReal t, Vec X, Vec Xdot, Vec F, void *ctx)
{
  PhlexSystem     *sys = (PhlexSystem *)ctx;
  PhlexBody        b   = sys->body;
  const PetscReal  T   = sys->scene->units.time;
  Vec              u_t, s, s_t, v, v_t, Fu, Fs, Fv;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_SysIFunction, 0, 0, 0, 0));
  PetscCall(VecGetSubVector(Xdot, sys->is[PHLEX_FIELD_DISPLACEMENT], &u_t));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecGetSubVector(Xdot, sys->is[PHLEX_FIELD_STRESS], &s_t));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecGetSubVector(Xdot, sys->is[PHLEX_FIELD_VELOCITY], &v_t));
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_DISPLACEMENT], &Fu));
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_STRESS], &Fs));
  PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &Fv));

  /* F_u = T u' - v */
  PetscCall(VecAXPBYPCZ(Fu, T, -1.0, 0.0, u_t, v));
  /* F_Sigma = G v - T Ms Sigma' */
  PetscCall(MatMult(b->Ms, s_t, Fs));
  PetscCall(VecScale(Fs, -T));
  PetscCall(MatMultAdd(b->G, v, Fs, Fs));
  /* F_v = T Mv v' + G^T Sigma - b(t) */
  PetscCall(MatMultTranspose(b->G, s, Fv));
  PetscCall(VecScale(Fv, 1.0 / T));
  PetscCall(MatMultAdd(b->Mv, v_t, Fv, Fv));
  PetscCall(VecScale(Fv, T));
  PetscCall(PhlexBodyLoadVector(b, t, &sys->scene->units, sys->load));
  PetscCall(VecAXPY(Fv, -1.0, sys->load));

  PetscCall(VecRestoreSubVector(Xdot, sys->is[PHLEX_FIELD_DISPLACEMENT], &u_t));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_STRESS], &s));
  PetscCall(VecRestoreSubVector(Xdot, sys->is[PHLEX_FIELD_STRESS], &s_t));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(VecRestoreSubVector(Xdot, sys->is[PHLEX_FIELD_VELOCITY], &v_t));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_DISPLACEMENT], &Fu));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_STRESS], &Fs));
  PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_VELOCITY], &Fv));
  PetscCall(PetscLogEventEnd(PHLEX_SysIFunction, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemIJacobian - dF/dX + shift dF/dX' (TS IJacobian); the operators are constant, so the matrices are
  only rescaled when the shift changes

  Collective
@*/
PetscErrorCode PhlexSystemIJacobian(TS ts, PetscReal t, Vec X, Vec Xdot, PetscReal shift, Mat A, Mat P, void *ctx)
{
  PhlexSystem    *sys = (PhlexSystem *)ctx;
  PhlexBody       b   = sys->body;
  const PetscReal s   = shift * sys->scene->units.time; /* non-dimensional shift */

  PetscFunctionBeginUser;
  /* multistep methods recompute the shift from the step size: ignore round-off changes */
  if (PetscAbsReal(s - sys->shift) <= 1e-12 * s) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_SysIJacobian, 0, 0, 0, 0));
  sys->shift = s;
  PetscCall(MatScale(sys->Juu, 0.0));
  PetscCall(MatShift(sys->Juu, s));
  PetscCall(MatCopy(b->Ms, sys->Jss, SAME_NONZERO_PATTERN));
  PetscCall(MatScale(sys->Jss, -s));
  PetscCall(MatCopy(sys->Mv, sys->Jvv, SAME_NONZERO_PATTERN));
  PetscCall(MatScale(sys->Jvv, s));
  PetscCall(MatAssemblyBegin(sys->J, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(sys->J, MAT_FINAL_ASSEMBLY));
  PetscCall(SystemUpdatePmats(sys));
  if (sys->use_aij) {
    PetscCall(MatConvert(sys->J, MATAIJ, sys->Jaij ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, &sys->Jaij));
    if (A != sys->Jaij) PetscCall(MatCopy(sys->Jaij, A, DIFFERENT_NONZERO_PATTERN));
  }
  PetscCall(PetscLogEventEnd(PHLEX_SysIJacobian, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemDestroy - frees the system
@*/
PetscErrorCode PhlexSystemDestroy(PhlexSystem **system)
{
  PhlexSystem *sys = *system;

  PetscFunctionBeginUser;
  if (!sys) PetscFunctionReturn(0);
  for (PetscInt f = 0; f < PHLEX_NUM_FIELDS; f++) PetscCall(ISDestroy(&sys->is[f]));
  PetscCall(MatDestroy(&sys->J));
  PetscCall(MatDestroy(&sys->Jaij));
  PetscCall(MatDestroy(&sys->Juu));
  PetscCall(MatDestroy(&sys->Juv));
  PetscCall(MatDestroy(&sys->Jss));
  PetscCall(MatDestroy(&sys->Jsv));
  PetscCall(MatDestroy(&sys->Jvv));
  PetscCall(MatDestroy(&sys->Mv));
  PetscCall(MatDestroy(&sys->K));
  PetscCall(MatDestroy(&sys->Gt));
  PetscCall(MatDestroy(&sys->Sv));
  PetscCall(MatDestroy(&sys->Ssv));
  PetscCall(VecDestroy(&sys->load));
  PetscCall(DMDestroy(&sys->dm));
  PetscCall(PetscFree(*system));
  PetscFunctionReturn(0);
}
