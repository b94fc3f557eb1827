/* The discrete pH system of one elastic body in implicit form (paper Section 4.1, eq. eldyn_PDE after integration by
   parts of J_Div; Section 4.2 for the floating frame), non-dimensional, with unknowns
   X = [u | Sigma | v] for a fixed body and [u | Sigma | v | q] for a floating one (q = r, R, v_P, w_P):

     F_u     = u' - v                         (kinematics u_f' = v_f)
     F_Sigma = G v - Ms Sigma'                (compatibility, rows negated so that the (Sigma, v) block is symmetric)
     F_v     = Mv v' + G^T Sigma - B u(t)     (momentum balance; B u(t): port wrenches and body force)
              [+ the floating-frame terms of floating.c]
     F_q     = rigid kinematics and Hamel equations (floating.c)

   The operators Mv, Ms, G are constant in the body frame and assembled once (body.c); the residual is a few sparse
   mat-vecs. The time derivative from TS is in seconds (options stay in SI): X'_nondim = T X'_SI.

   Jacobian: a MATNEST of these blocks. The floating terms add node-wise 3x3 blocks applied after Mv (shells), and
   dense borders between the elastic space and the 18 rigid unknowns (dense matrices, kept out of the sparse ones). */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateIncrease: blocks changed in place */

const char *const PhlexFieldNames[] = {"displacement", "stress", "velocity", "rigid"};

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

/* y = (a I + B) Mv x with B a node-wise 3x3 matrix: the elastic blocks of the floating frame */
static PetscErrorCode NodeMassMult(PhlexSystem *sys, PetscReal a, const PetscReal B[9], Vec x, Vec y)
{
  PetscScalar *ya;
  PetscInt     n;

  PetscFunctionBeginUser;
  PetscCall(MatMult(sys->body->Mv, x, y));
  PetscCall(VecGetLocalSize(y, &n));
  PetscCall(VecGetArray(y, &ya));
  for (PetscInt l = 0; l < n / 3; l++) {
    PetscReal z[3], r[3];
    for (PetscInt k = 0; k < 3; k++) z[k] = PetscRealPart(ya[3 * l + k]);
    PhlexMatVec3(B, z, r);
    for (PetscInt k = 0; k < 3; k++) ya[3 * l + k] = a * z[k] + r[k];
  }
  PetscCall(VecRestoreArray(y, &ya));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_Avv(Mat A, Vec x, Vec y)
{
  PhlexSystem *sys;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(NodeMassMult(sys, sys->shift, sys->Bvv, x, y));
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_Avu(Mat A, Vec x, Vec y)
{
  PhlexSystem *sys;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &sys));
  PetscCall(NodeMassMult(sys, 0.0, sys->Bvu, x, y));
  PetscFunctionReturn(0);
}

/* Preconditioning matrices of field subsets, assembled on demand when PCFIELDSPLIT asks for a split:
   {velocity}: shift Mv + K/shift, the exact Schur complement of the displacement and stress (element-wise) of a
   fixed body, and of a floating one up to the node-wise inertial terms;
   {velocity, rigid}: [[shift Mv + K/shift, B_vq], [B_qv + B_qu/shift, A_qq]] (floating), the Schur complement of
   the displacement and stress with that same approximation;
   {stress, velocity}: the assembled (Sigma, v) block, the exact Schur complement of the displacement. */
static PetscErrorCode SystemUpdatePmats(PhlexSystem *sys)
{
  const PetscReal s = sys->shift;
  PhlexBody       b = sys->body;

  PetscFunctionBeginUser;
  if (sys->Sv) {
    PetscCall(MatCopy(sys->K, sys->Sv, SUBSET_NONZERO_PATTERN));
    PetscCall(MatScale(sys->Sv, 1.0 / s));
    PetscCall(MatAXPY(sys->Sv, s, sys->Mv, SUBSET_NONZERO_PATTERN));
  }
  if (sys->Ssv) {
    Mat blocks[4] = {sys->Jss, sys->Jsv, sys->Jvs, sys->Jvv}, N;
    PetscCall(MatCreateNest(b->comm, 2, NULL, 2, NULL, blocks, &N));
    PetscCall(MatConvert(N, MATAIJ, MAT_REUSE_MATRIX, &sys->Ssv));
    PetscCall(MatDestroy(&N));
  }
  if (sys->Pvq) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Pvq));
  PetscFunctionReturn(0);
}

/* The borders of a floating body that do not depend on the state, nodal fields t e_c (3) and w_b e_c (9):
   t(l) = int rho phi_l and w(l) = int rho x phi_l. With frozen inertia every elastic-rigid border lies in their
   span (translation: t e_c; rotation: e_a x w; gravity: t e_c); the full model adds u-dependent parts. */
static PetscErrorCode CreateBorderBasis(PhlexSystem *sys)
{
  PhlexBody          b = sys->body;
  const PetscScalar *ta, *wa;
  PetscScalar       *Wa;
  PetscInt           n = b->nv_local, ld;

  PetscFunctionBeginUser;
  PetscCall(MatCreateDense(b->comm, n, PETSC_DECIDE, PETSC_DETERMINE, 12, NULL, &sys->W));
  PetscCall(MatDenseGetLDA(sys->W, &ld));
  PetscCall(MatDenseGetArrayWrite(sys->W, &Wa));
  PetscCall(VecGetArrayRead(b->tnode, &ta));
  PetscCall(VecGetArrayRead(b->wnode, &wa));
  for (PetscInt col = 0; col < 12; col++)
    for (PetscInt i = 0; i < n; i++) Wa[col * ld + i] = 0.0;
  for (PetscInt l = 0; l < n / 3; l++)
    for (PetscInt c = 0; c < 3; c++) {
      Wa[c * ld + 3 * l + c] = ta[3 * l + c];
      for (PetscInt bb = 0; bb < 3; bb++) Wa[(3 + 3 * c + bb) * ld + 3 * l + c] = wa[3 * l + bb];
    }
  PetscCall(VecRestoreArrayRead(b->tnode, &ta));
  PetscCall(VecRestoreArrayRead(b->wnode, &wa));
  PetscCall(MatDenseRestoreArrayWrite(sys->W, &Wa));
  PetscCall(MatAssemblyBegin(sys->W, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(sys->W, MAT_FINAL_ASSEMBLY));
  PetscCall(PetscObjectSetName((PetscObject)sys->W, "border basis"));
  PetscFunctionReturn(0);
}

static PetscErrorCode CreateSv(PhlexSystem *sys)
{
  MatNullSpace nsp;
  PhlexBody    b = sys->body;

  PetscFunctionBeginUser;
  if (sys->Sv) PetscFunctionReturn(0);
  /* AIJ: taken by every factorisation and by GAMG; its pattern is the union of those of K and Mv */
  PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &sys->K));
  PetscCall(MatDuplicate(sys->K, MAT_COPY_VALUES, &sys->Sv));
  PetscCall(MatAXPY(sys->Sv, 1.0, sys->Mv, DIFFERENT_NONZERO_PATTERN));
  PetscCall(MatSetOption(sys->Sv, MAT_SPD, PETSC_TRUE));
  PetscCall(DMPlexCreateRigidBody(b->dm, 0, &nsp));
  PetscCall(MatSetNearNullSpace(sys->Sv, nsp));
  PetscCall(MatNullSpaceDestroy(&nsp));
  PetscCall(PetscObjectSetName((PetscObject)sys->Sv, "condensed velocity operator"));
  PetscCall(SystemUpdatePmats(sys));
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
    PetscCall(CreateSv(sys));
    *P = sys->Sv;
  } else if (n == 2 && fields[0] == PHLEX_FIELD_VELOCITY && fields[1] == PHLEX_FIELD_RIGID && sys->floating) {
    if (!sys->Pvq) {
      Mat blocks[4];
      PetscCall(CreateSv(sys));
      blocks[0] = sys->Sv;
      blocks[1] = sys->Bc;
      blocks[2] = sys->CpreT;
      blocks[3] = sys->Arr;
      PetscCall(MatCreateNest(b->comm, 2, NULL, 2, NULL, blocks, &sys->Pvq));
      PetscCall(PetscObjectSetName((PetscObject)sys->Pvq, "condensed velocity-rigid operator"));
      /* for PC phlexbordered */
      if (!sys->W) PetscCall(CreateBorderBasis(sys));
      PetscCall(PetscObjectCompose((PetscObject)sys->Pvq, "border_basis", (PetscObject)sys->W));
    }
    *P = sys->Pvq;
  } else if (n == 2 && fields[0] == PHLEX_FIELD_STRESS && fields[1] == PHLEX_FIELD_VELOCITY && !sys->floating) {
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

static PetscErrorCode CreateDense(MPI_Comm comm, PetscInt mloc, PetscInt nloc, Mat *A)
{
  PetscFunctionBeginUser;
  PetscCall(MatCreateDense(comm, mloc, nloc, PETSC_DETERMINE, PETSC_DETERMINE, NULL, A));
  PetscCall(MatZeroEntries(*A));
  PetscCall(MatAssemblyBegin(*A, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*A, MAT_FINAL_ASSEMBLY));
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
  PetscMPIInt  rank;

  PetscFunctionBeginUser;
  PetscCall(PhlexBodySetUpMixed(b, &scene->units));
  PetscCall(PetscNew(&sys));
  PetscCallMPI(MPI_Comm_rank(scene->comm, &rank));
  sys->scene    = scene;
  sys->body     = b;
  sys->floating = b->floating;
  sys->nfields  = b->floating ? 4 : 3;
  sys->qlocal   = (b->floating && rank == 0) ? 18 : 0;
  nlocal[PHLEX_FIELD_DISPLACEMENT] = b->nv_local;
  nlocal[PHLEX_FIELD_STRESS]       = b->ns_local;
  nlocal[PHLEX_FIELD_VELOCITY]     = b->nv_local;
  nlocal[PHLEX_FIELD_RIGID]        = sys->qlocal;
  bs[PHLEX_FIELD_DISPLACEMENT]     = 3;
  bs[PHLEX_FIELD_STRESS]           = b->nb_s;
  bs[PHLEX_FIELD_VELOCITY]         = 3;
  bs[PHLEX_FIELD_RIGID]            = 1;
  PetscCall(PhlexLayoutCreateDM(scene->comm, sys->nfields, PhlexFieldNames, nlocal, bs, SystemPmat, sys, &sys->dm));
  for (PetscInt f = 0; f < sys->nfields; f++) PetscCall(PhlexLayoutGetFieldIS(sys->dm, f, &sys->is[f]));

  PetscCall(IdentityMatrix(scene->comm, b->nv_local, 1.0, &sys->Juu));
  PetscCall(IdentityMatrix(scene->comm, b->nv_local, -1.0, &sys->Juv));
  PetscCall(MatDuplicate(b->Ms, MAT_COPY_VALUES, &sys->Jss));
  PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &sys->Mv));
  PetscCall(MatTranspose(b->G, MAT_INITIAL_MATRIX, &sys->Gt));
  sys->Jsv = b->G;
  sys->Jvs = sys->Gt;
  PetscCall(PetscObjectReference((PetscObject)b->G));
  if (!sys->floating) {
    Mat blocks[9];
    PetscCall(MatDuplicate(sys->Mv, MAT_COPY_VALUES, &sys->Jvv));
    blocks[0] = sys->Juu, blocks[1] = NULL, blocks[2] = sys->Juv;
    blocks[3] = NULL, blocks[4] = sys->Jss, blocks[5] = sys->Jsv;
    blocks[6] = NULL, blocks[7] = sys->Jvs, blocks[8] = sys->Jvv;
    PetscCall(MatCreateNest(scene->comm, 3, sys->is, 3, sys->is, blocks, &sys->J));
  } else {
    Mat      blocks[16];
    PetscInt nv = b->nv_local, N = b->nv_global;
    PetscCall(MatCreateShell(scene->comm, nv, nv, N, N, sys, &sys->Jvv));
    PetscCall(MatShellSetOperation(sys->Jvv, MATOP_MULT, (void (*)(void))MatMult_Avv));
    PetscCall(MatCreateShell(scene->comm, nv, nv, N, N, sys, &sys->Jvu));
    PetscCall(MatShellSetOperation(sys->Jvu, MATOP_MULT, (void (*)(void))MatMult_Avu));
    PetscCall(CreateDense(scene->comm, nv, sys->qlocal, &sys->Bc));
    PetscCall(CreateDense(scene->comm, nv, sys->qlocal, &sys->Cu));
    PetscCall(CreateDense(scene->comm, nv, sys->qlocal, &sys->Cv));
    PetscCall(CreateDense(scene->comm, nv, sys->qlocal, &sys->Cpre));
    PetscCall(CreateDense(scene->comm, sys->qlocal, sys->qlocal, &sys->Arr));
    PetscCall(MatCreateTranspose(sys->Cu, &sys->CuT));
    PetscCall(MatCreateTranspose(sys->Cv, &sys->CvT));
    PetscCall(MatCreateTranspose(sys->Cpre, &sys->CpreT));
    for (PetscInt k = 0; k < 16; k++) blocks[k] = NULL;
    blocks[0]  = sys->Juu, blocks[2] = sys->Juv;
    blocks[5]  = sys->Jss, blocks[6] = sys->Jsv;
    blocks[8]  = sys->Jvu, blocks[9] = sys->Jvs, blocks[10] = sys->Jvv, blocks[11] = sys->Bc;
    blocks[12] = sys->CuT, blocks[14] = sys->CvT, blocks[15] = sys->Arr;
    PetscCall(MatCreateNest(scene->comm, 4, sys->is, 4, sys->is, blocks, &sys->J));
    PetscCall(VecDuplicate(b->fvol[0], &sys->ud));
    PetscCall(VecDuplicate(b->fvol[0], &sys->vd));
  }
  PetscCall(PetscObjectSetName((PetscObject)sys->J, "Jacobian"));
  PetscCall(PetscOptionsGetBool(NULL, NULL, "-phlex_jacobian_aij", &sys->use_aij, NULL));
  PetscCall(DMCreateGlobalVector(b->dm, &sys->load));
  *system = sys;
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemGetRigid - the 18 rigid unknowns (and optionally their rates) of a floating body on every rank

  Collective
@*/
PetscErrorCode PhlexSystemGetRigid(PhlexSystem *sys, Vec X, PetscReal q[18])
{
  Vec                xq;
  const PetscScalar *a;

  PetscFunctionBeginUser;
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_RIGID], &xq));
  PetscCall(VecGetArrayRead(xq, &a));
  for (PetscInt k = 0; k < sys->qlocal; k++) q[k] = PetscRealPart(a[k]);
  PetscCall(VecRestoreArrayRead(xq, &a));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_RIGID], &xq));
  PetscCallMPI(MPI_Bcast(q, 18, MPIU_REAL, 0, sys->scene->comm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemEvaluateFloating - the floating-body context at (t, X, X') (X' in SI time, or NULL for rest)

  Collective
@*/
PetscErrorCode PhlexSystemEvaluateFloating(PhlexSystem *sys, PetscReal t, Vec X, Vec Xdot)
{
  const PetscReal T = sys->scene->units.time;
  PetscReal       q[18], qd[18];
  Vec             u, v, ut, vt;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemGetRigid(sys, X, q));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  if (Xdot) {
    PetscCall(PhlexSystemGetRigid(sys, Xdot, qd));
    for (PetscInt k = 0; k < 18; k++) qd[k] *= T;
    PetscCall(VecGetSubVector(Xdot, sys->is[PHLEX_FIELD_DISPLACEMENT], &ut));
    PetscCall(VecGetSubVector(Xdot, sys->is[PHLEX_FIELD_VELOCITY], &vt));
    PetscCall(VecAXPBY(sys->ud, T, 0.0, ut));
    PetscCall(VecAXPBY(sys->vd, T, 0.0, vt));
    PetscCall(VecRestoreSubVector(Xdot, sys->is[PHLEX_FIELD_DISPLACEMENT], &ut));
    PetscCall(VecRestoreSubVector(Xdot, sys->is[PHLEX_FIELD_VELOCITY], &vt));
  } else {
    for (PetscInt k = 0; k < 18; k++) qd[k] = 0.0;
    PetscCall(VecSet(sys->ud, 0.0));
    PetscCall(VecSet(sys->vd, 0.0));
  }
  PetscCall(PhlexFloatingEvaluate(sys->body, &sys->scene->units, t, u, v, sys->ud, sys->vd, q, qd, &sys->fs));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemIFunction - F(t, X, X') of the body (TS IFunction, t and X' in SI time)

  Collective
@*/
PetscErrorCode PhlexSystemIFunction(TS ts, PetscReal t, Vec X, Vec Xdot, Vec F, void *ctx)
{
  PhlexSystem    *sys = (PhlexSystem *)ctx;
  PhlexBody       b   = sys->body;
  const PetscReal T   = sys->scene->units.time;
  Vec             u, u_t, s, s_t, v, v_t, Fu, Fs, Fv;

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
  if (!sys->floating) {
    PetscCall(PhlexBodyLoadVector(b, t, &sys->scene->units, sys->load));
    PetscCall(VecAXPY(Fv, -1.0, sys->load));
  } else {
    PetscReal    Fq[18];
    Vec          Fqv;
    PetscScalar *fa;
    PetscCall(PetscLogEventBegin(PHLEX_FloatResidual, 0, 0, 0, 0));
    PetscCall(PhlexSystemEvaluateFloating(sys, t, X, Xdot));
    PetscCall(VecAXPY(Fv, -1.0, sys->fs.bext));
    PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
    PetscCall(PhlexFloatingResidual(b, &sys->fs, u, v, sys->ud, Fv, Fq));
    PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
    PetscCall(VecGetSubVector(F, sys->is[PHLEX_FIELD_RIGID], &Fqv));
    PetscCall(VecGetArray(Fqv, &fa));
    for (PetscInt k = 0; k < sys->qlocal; k++) fa[k] = Fq[k];
    PetscCall(VecRestoreArray(Fqv, &fa));
    PetscCall(VecRestoreSubVector(F, sys->is[PHLEX_FIELD_RIGID], &Fqv));
    PetscCall(PetscLogEventEnd(PHLEX_FloatResidual, 0, 0, 0, 0));
  }

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

/* The state-dependent blocks of a floating body: node-wise 3x3 matrices, dense borders, rigid block. */
static PetscErrorCode SystemFloatingJacobian(PhlexSystem *sys, PetscReal t, Vec X, Vec Xdot)
{
  PhlexBody    b = sys->body;
  PetscScalar *Bc, *Cu, *Cv, *Cp, *Ar;
  PetscReal    Arr[324];
  PetscInt     ld;
  Vec          u, v;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_FloatJacobian, 0, 0, 0, 0));
  PetscCall(PhlexSystemEvaluateFloating(sys, t, X, Xdot));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  PetscCall(MatDenseGetLDA(sys->Bc, &ld));
  PetscCall(MatDenseGetArrayWrite(sys->Bc, &Bc));
  PetscCall(MatDenseGetArrayWrite(sys->Cu, &Cu));
  PetscCall(MatDenseGetArrayWrite(sys->Cv, &Cv));
  PetscCall(PhlexFloatingJacobian(b, &sys->fs, sys->shift, u, v, Bc, Cu, Cv, ld, sys->Bvv, sys->Bvu, Arr));
  /* the border of the velocity-rigid preconditioner: rigid rows after eliminating u (u = v / shift) */
  PetscCall(MatDenseGetArrayWrite(sys->Cpre, &Cp));
  for (PetscInt col = 0; col < 18; col++)
    for (PetscInt i = 0; i < b->nv_local; i++) Cp[col * ld + i] = Cv[col * ld + i] + Cu[col * ld + i] / sys->shift;
  PetscCall(MatDenseRestoreArrayWrite(sys->Cpre, &Cp));
  PetscCall(MatDenseRestoreArrayWrite(sys->Bc, &Bc));
  PetscCall(MatDenseRestoreArrayWrite(sys->Cu, &Cu));
  PetscCall(MatDenseRestoreArrayWrite(sys->Cv, &Cv));
  PetscCall(MatDenseGetArrayWrite(sys->Arr, &Ar));
  if (sys->qlocal) {
    PetscInt lda;
    PetscCall(MatDenseGetLDA(sys->Arr, &lda));
    for (PetscInt i = 0; i < 18; i++)
      for (PetscInt j = 0; j < 18; j++) Ar[j * lda + i] = Arr[18 * i + j];
  }
  PetscCall(MatDenseRestoreArrayWrite(sys->Arr, &Ar));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_DISPLACEMENT], &u));
  PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
  /* the shells' values changed (the dense blocks' states were raised by their array access) */
  PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvv));
  PetscCall(PetscObjectStateIncrease((PetscObject)sys->Jvu));
  PetscCall(PetscLogEventEnd(PHLEX_FloatJacobian, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSystemIJacobian - dF/dX + shift dF/dX' (TS IJacobian). The body operators are constant, so their blocks are
  only rescaled when the shift changes; the floating-frame blocks are recomputed at every call.

  Collective
@*/
PetscErrorCode PhlexSystemIJacobian(TS ts, PetscReal t, Vec X, Vec Xdot, PetscReal shift, Mat A, Mat P, void *ctx)
{
  PhlexSystem    *sys = (PhlexSystem *)ctx;
  PhlexBody       b   = sys->body;
  const PetscReal s   = shift * sys->scene->units.time; /* non-dimensional shift */

  PetscFunctionBeginUser;
  /* multistep methods recompute the shift from the step size: ignore round-off changes */
  if (!sys->floating && PetscAbsReal(s - sys->shift) <= 1e-12 * s) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_SysIJacobian, 0, 0, 0, 0));
  if (PetscAbsReal(s - sys->shift) > 1e-12 * s) {
    sys->shift = s;
    PetscCall(MatScale(sys->Juu, 0.0));
    PetscCall(MatShift(sys->Juu, s));
    PetscCall(MatCopy(b->Ms, sys->Jss, SAME_NONZERO_PATTERN));
    PetscCall(MatScale(sys->Jss, -s));
    if (!sys->floating) {
      PetscCall(MatCopy(sys->Mv, sys->Jvv, SAME_NONZERO_PATTERN));
      PetscCall(MatScale(sys->Jvv, s));
    }
    /* assembling resets the matrices' cached diagonal (block) inverses (point-block Jacobi on the stress block would
       otherwise keep the inverse of the previous shift's block): only the changed blocks, not the whole nest */
    PetscCall(MatAssemblyBegin(sys->Juu, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->Juu, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyBegin(sys->Jss, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(sys->Jss, MAT_FINAL_ASSEMBLY));
    if (!sys->floating) {
      PetscCall(MatAssemblyBegin(sys->Jvv, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(sys->Jvv, MAT_FINAL_ASSEMBLY));
    }
    PetscCall(SystemUpdatePmats(sys));
  }
  if (sys->floating) PetscCall(SystemFloatingJacobian(sys, t, X, Xdot));
  /* the blocks changed in place: raise the nests' states (assembling a nest would also raise the state of every
     block, and the factorisations of the unchanged ones would be redone) */
  PetscCall(PetscObjectStateIncrease((PetscObject)sys->J));
  if (sys->Pvq) PetscCall(PetscObjectStateIncrease((PetscObject)sys->Pvq));
  if (sys->use_aij) {
    Mat Jaij;
    /* shells and virtual transposes: build the operator column by column (small test meshes) */
    if (sys->floating) PetscCall(MatComputeOperator(sys->J, MATAIJ, &Jaij));
    else PetscCall(MatConvert(sys->J, MATAIJ, MAT_INITIAL_MATRIX, &Jaij));
    if (!sys->Jaij) {
      sys->Jaij = Jaij;
    } else {
      PetscCall(MatCopy(Jaij, sys->Jaij, DIFFERENT_NONZERO_PATTERN));
      PetscCall(MatDestroy(&Jaij));
    }
    if (A != sys->Jaij && A != sys->J) PetscCall(MatCopy(sys->Jaij, A, DIFFERENT_NONZERO_PATTERN));
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
  for (PetscInt f = 0; f < sys->nfields; f++) PetscCall(ISDestroy(&sys->is[f]));
  PetscCall(MatDestroy(&sys->J));
  PetscCall(MatDestroy(&sys->Jaij));
  PetscCall(MatDestroy(&sys->Juu));
  PetscCall(MatDestroy(&sys->Juv));
  PetscCall(MatDestroy(&sys->Jss));
  PetscCall(MatDestroy(&sys->Jsv));
  PetscCall(MatDestroy(&sys->Jvv));
  PetscCall(MatDestroy(&sys->Jvu));
  PetscCall(MatDestroy(&sys->Mv));
  PetscCall(MatDestroy(&sys->K));
  PetscCall(MatDestroy(&sys->Gt));
  PetscCall(MatDestroy(&sys->Sv));
  PetscCall(MatDestroy(&sys->Ssv));
  PetscCall(MatDestroy(&sys->Pvq));
  PetscCall(MatDestroy(&sys->W));
  PetscCall(MatDestroy(&sys->Bc));
  PetscCall(MatDestroy(&sys->Cu));
  PetscCall(MatDestroy(&sys->Cv));
  PetscCall(MatDestroy(&sys->Cpre));
  PetscCall(MatDestroy(&sys->CuT));
  PetscCall(MatDestroy(&sys->CvT));
  PetscCall(MatDestroy(&sys->CpreT));
  PetscCall(MatDestroy(&sys->Arr));
  PetscCall(VecDestroy(&sys->ud));
  PetscCall(VecDestroy(&sys->vd));
  PetscCall(PhlexFloatingStateDestroy(&sys->fs));
  PetscCall(VecDestroy(&sys->load));
  PetscCall(DMDestroy(&sys->dm));
  PetscCall(PetscFree(*system));
  PetscFunctionReturn(0);
}
