/* The equations of a flexible body as a part of the index-2 pHDAE (paper Sections 4 and 5), non-dimensional, with
   unknowns u, Sigma, v (fields) and, floating, q = [r | R | v_P | w] (+ six mean-axes impulses):

     F_u     = u' - v                          (kinematics u_f' = v_f)
     F_Sigma = G v - Ms Sigma'                 (compatibility; rows negated so that the (Sigma, v) block is symmetric)
     F_v     = Mv v' + G^T Sigma - b           (momentum balance; b: port wrenches (inputs and joints), body force)
               [+ the moving-frame terms of frame.c]  [- T mu' (mean axes)]
     F_q     = rigid kinematics and Hamel equations of the frame (frame.c); mean axes: T^T v = 0

   The operators Mv, Ms, G are constant in the body frame and assembled once (flexible_fe.c); the residual is a few
   sparse mat-vecs. Time derivatives arrive in SI time (X'_nondim = T X'_SI).

   Port p: output y = (B_t^T v, A_p B_r^T v) (+ (v_P + w x (c - P + ubar_p), w) floating), wrench distribution
   B_t F + B_r A_p^T T on the elastic rows and (F, (c - P + ubar_p) x F + T) on the frame rows: the transposes of each
   other, so that the port power is w . y (ubar_p = B_t^T u, the port's mean displacement: full-inertia model only,
   as the inertia terms). A_p is the port's rate map (FlexPortRate): on a port with a joint, the left Jacobian
   J_l(theta_p) of its mean rotation theta_p = B_r^T u at the step's middle, so that w + A_p theta_p' is the exact
   angular velocity of its orientation R exp(theta_p) (issue 42 item 3), held over the step; I elsewhere (and with
   -port_rate first_order). */
#include <phlex_impl.h>
#include <petsc/private/petscimpl.h> /* PetscObjectStateIncrease: blocks changed in place */

/* ------------------------------------------------------------------------------------------------------------ */
/* Loads                                                                                                          */

/* the port wrenches of the scene's inputs at t and the external loads on the body: the elastic load vector, and for
   a floating body the resultant force and moment about P (frame.c adds the u arms of the forces), and their power */
static PetscErrorCode ExternalLoads(PhlexPart part, PetscReal t, const PhlexPartVec *X)
{
  PhlexFlexible     b = (PhlexFlexible)part->data;
  const PhlexUnits *u = part->units;
  PhlexFrameState  *f = &b->fs;
  Vec               bext = b->floating ? f->bext : b->load, barm = b->floating ? f->barm : b->load;
  PetscScalar       p;

  PetscFunctionBeginUser;
  PetscCall(VecSet(bext, 0.0));
  if (barm != bext) PetscCall(VecSet(barm, 0.0));
  for (PetscInt k = 0; k < 3; k++) f->Fext[k] = f->Mext[k] = 0.0;
  for (PetscInt q = 0; q < b->nports; q++) {
    PetscReal *w = b->port_ext[q];
    PetscCall(PhlexPortLoadEvaluate(&b->ports[q].load, t, u, b->floating ? f->R : NULL, w));
    if (!b->ports[q].load.loaded) continue;
    /* forces into barm (their arms move with u); the moment distributions (self-equilibrated) into bext */
    for (PetscInt k = 0; k < 6; k++)
      if (w[k] != 0.0) PetscCall(VecAXPY(k < 3 ? barm : bext, w[k], b->ports[q].dist[k]));
    if (b->floating) {
      PetscReal a[3];
      PhlexCross(part->ports[q].point, w, a);
      for (PetscInt k = 0; k < 3; k++) {
        f->Fext[k] += w[k];
        f->Mext[k] += a[k] + w[3 + k];
      }
    }
  }
  if (b->floating && b->frame_loaded) {
    PetscReal fr;
    PetscCall(PhlexProfileEvaluate(b->frame_profile, t, &fr));
    for (PetscInt k = 0; k < 3; k++) {
      f->Fext[k] += fr * b->frame_force[k] / u->force;
      f->Mext[k] += fr * b->frame_moment[k] / (u->force * u->length);
    }
  }
  if (b->has_body_force) {
    PetscReal fr, beta[3];
    PetscCall(PhlexProfileEvaluate(b->body_force_profile, t, &fr));
    /* force density scale: force / length^3 = E_ref / L */
    for (PetscInt c = 0; c < 3; c++) beta[c] = fr * b->body_force[c] * u->length / u->modulus;
    for (PetscInt c = 0; c < 3; c++)
      if (beta[c] != 0.0) PetscCall(VecAXPY(barm, beta[c], b->fvol[c]));
    if (b->floating) {
      PetscReal a[3];
      PhlexCross(b->inertia.svol, beta, a);
      for (PetscInt k = 0; k < 3; k++) {
        f->Fext[k] += b->inertia.vol * beta[k];
        f->Mext[k] += a[k];
      }
    }
  }
  if (b->floating) {
    PetscCall(PhlexFrameAddLoadArms(&b->frame, X->u, f));
    PetscCall(VecAXPY(bext, 1.0, barm));
    /* power of the inputs: b . v + F . v_P + M . w (M with the u arms of the forces, full model) */
    PetscCall(VecDot(X->v, bext, &p));
    b->power_ext = PetscRealPart(p) + PhlexDot3(f->Fext, f->vP) + PhlexDot3(f->Mext, f->w);
  } else {
    PetscCall(VecDot(X->v, bext, &p));
    b->power_ext = PetscRealPart(p);
    /* the weight is a potential (energy), not an input */
    if (b->bgrav) PetscCall(VecAXPY(bext, 1.0, b->bgrav));
  }
  PetscFunctionReturn(0);
}

/* the coefficients on port q's distribution vectors of a wrench w on it: (F, A^T T), A its rate map (the transpose of
   the output's w + A B_r^T v, so that the power is w . y) */
static void PortDistribution(PhlexFlexible b, PetscInt q, const PetscReal w[6], PetscReal wd[6])
{
  for (PetscInt k = 0; k < 3; k++) wd[k] = w[k];
  PhlexMatTVec3(b->port_rate[q], w + 3, wd + 3);
}

/* the joint wrenches on the ports join the loads (once per evaluation) */
static PetscErrorCode AddJointLoads(PhlexPart part)
{
  PhlexFlexible    b = (PhlexFlexible)part->data;
  PhlexFrameState *f = &b->fs;
  Vec              bext = b->floating ? f->bext : b->load;

  PetscFunctionBeginUser;
  if (b->joints_added) PetscFunctionReturn(0);
  b->joints_added = PETSC_TRUE;
  for (PetscInt q = 0; q < part->nports; q++) {
    const PetscReal *w = part->wrench[q];
    PetscBool        zero = PETSC_TRUE;
    for (PetscInt k = 0; k < 6; k++)
      if (w[k] != 0.0) zero = PETSC_FALSE;
    if (zero) continue;
    if (q < b->nports) {
      PetscReal wd[6];
      PortDistribution(b, q, w, wd); /* the moment through the port's rate map: B_r A^T T */
      for (PetscInt k = 0; k < 6; k++) {
        if (wd[k] == 0.0) continue;
        PetscCall(VecAXPY(bext, wd[k], b->ports[q].dist[k]));
        if (b->floating && !b->frozen_inertia && k < 3) PetscCall(VecAXPY(f->barm, wd[k], b->ports[q].dist[k])); /* the Jacobian's arms */
      }
    }
    if (b->floating) {
      PetscReal a[3], c[3];
      PhlexCross(part->ports[q].point, w, a);
      if (!b->frozen_inertia && q < b->nports) PhlexCross(b->port_ubar[q], w, c);
      else c[0] = c[1] = c[2] = 0.0;
      for (PetscInt k = 0; k < 3; k++) {
        f->Fext[k] += w[k];
        f->Mext[k] += a[k] + c[k] + w[3 + k];
      }
    }
  }
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Ports                                                                                                          */

/* Port q's output, the velocity of its mean motion (body frame): translation B_t^T V of the material velocity
   V = v [+ v_P + w x (x - P + u)], rotation w + A B_r^T v. A port turns with its mean rotation theta = B_r^T u, its
   orientation R exp(theta), so its angular velocity has no w x u term: it is w + J_l(theta) theta' exactly (A = J_l
   held over the step on a port with a joint: FlexPortRate; A = I, the first-order rate, elsewhere); its position r + R (c - P + ubar) has exactly the
   rate of the translation (full inertia), so a joint's position-level gap follows its velocity constraint (midpoint
   rule: exactly for translations). With a constant-inertia model the kinematics are those at u = 0 (no w x ubar): a joint on
   such a port drifts at |w x ubar|, the model's own approximation. The wrench distribution is the transpose: B w on the elastic rows; F and
   (c - P + ubar) x F + T on the frame. The ubar terms appear in the full-inertia model only (as the inertia terms). */

/* the mean displacements of the ports (full model; the ports with joints or loads: the arms of their forces) and the
   outputs of the ports (all, or those a joint uses) at the evaluated state */
static PetscErrorCode PortOutputs(PhlexPart part, const PhlexPartVec *X, PetscBool all)
{
  PhlexFlexible b    = (PhlexFlexible)part->data;
  PetscBool     full = (b->floating && !b->frozen_inertia) ? PETSC_TRUE : PETSC_FALSE;

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < part->nports; q++) {
    PetscScalar d[6] = {0, 0, 0, 0, 0, 0}, du[3] = {0, 0, 0};
    PetscReal   ub[3] = {0, 0, 0};
    if (full && q < b->nports && (part->port_used[q] || b->ports[q].load.loaded)) {
      PetscCall(VecMDot(X->u, 3, b->ports[q].dist, du));
      for (PetscInt k = 0; k < 3; k++) ub[k] = b->port_ubar[q][k] = PetscRealPart(du[k]);
    }
    if (!(all || part->port_used[q])) continue;
    if (q < b->nports) PetscCall(VecMDot(X->v, 6, b->ports[q].dist, d));
    for (PetscInt k = 0; k < 6; k++) b->port_y[q][k] = PetscRealPart(d[k]);
    if (q < b->nports) {
      /* the elastic rotation's rate through the port's rate map: A theta' (exact: J_l(theta) theta') */
      const PetscReal th[3] = {PetscRealPart(d[3]), PetscRealPart(d[4]), PetscRealPart(d[5])};
      PhlexMatVec3(b->port_rate[q], th, b->port_y[q] + 3);
    }
    if (b->floating) {
      PetscReal arm[3], a[3];
      for (PetscInt k = 0; k < 3; k++) arm[k] = part->ports[q].point[k] + ub[k];
      PhlexCross(b->fs.w, arm, a);
      for (PetscInt k = 0; k < 3; k++) {
        b->port_y[q][k] += b->fs.vP[k] + a[k];
        b->port_y[q][3 + k] += b->fs.w[k];
      }
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePortOutputsAll - the outputs of every port at the evaluated state X (for the output series)

  Collective
@*/
PetscErrorCode PhlexFlexiblePortOutputsAll(PhlexPart part, const PhlexPartVec *X)
{
  PetscFunctionBeginUser;
  PetscCall(PortOutputs(part, X, PETSC_TRUE));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexPortInput(PhlexPart part, PetscInt q, PetscReal t, PetscReal w[6])
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  PetscCall(PhlexFlexiblePortInput(part, b, b->floating, &b->fs, q, t, w));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexPortOutput(PhlexPart part, PetscInt q, PetscReal y[6])
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 6; k++) y[k] = b->port_y[q][k];
  PetscFunctionReturn(0);
}

/* which field terms of dy = d y_q a change (a du, dv) has: the port's velocity moments of dv, and for a frame with
   full inertia w x (its displacement moments of a du) */
static void PortLinearTerms(PhlexFlexible b, PetscInt q, Vec du, PetscReal au, Vec dv, PetscBool *with_v, PetscBool *with_u)
{
  const PetscBool full = (b->floating && !b->frozen_inertia) ? PETSC_TRUE : PETSC_FALSE;

  *with_v = (q < b->nports && dv) ? PETSC_TRUE : PETSC_FALSE;
  *with_u = (q < b->nports && du && full && au != 0.0) ? PETSC_TRUE : PETSC_FALSE;
}

/* the first phase of FlexPortLinear: this process's parts of its field products (PHLEX_PORT_SUMS values: the six
   moments of dv, the three of du), formed as VecMDot forms them (zero where the change has no such term) */
static PetscErrorCode FlexPortLinearLocal(PhlexPart part, PetscInt q, Vec du, PetscReal au, Vec dv, PetscReal loc[PHLEX_PORT_SUMS])
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscBool     with_v, with_u;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < PHLEX_PORT_SUMS; k++) loc[k] = 0.0;
  PortLinearTerms(b, q, du, au, dv, &with_v, &with_u);
  if (with_v) PetscCall(PhlexLocalMDot(dv, 6, b->ports[q].dist, loc));
  if (with_u) PetscCall(PhlexLocalMDot(du, 3, b->ports[q].dist, loc + 6));
  PetscFunctionReturn(0);
}

/* the second phase: dy from the summed field products (sums; the arguments as in the first phase, du and dv only say
   which terms there are) and the discrete change dq */
static PetscErrorCode FlexPortLinearSummed(PhlexPart part, PetscInt q, Vec du, PetscReal au, Vec dv, const PetscReal sums[PHLEX_PORT_SUMS], const PetscReal *dq, PetscReal dy[6])
{
  PhlexFlexible b    = (PhlexFlexible)part->data;
  PetscBool     full = (b->floating && !b->frozen_inertia) ? PETSC_TRUE : PETSC_FALSE, with_v, with_u;

  PetscFunctionBeginUser;
  PortLinearTerms(b, q, du, au, dv, &with_v, &with_u);
  for (PetscInt k = 0; k < 6; k++) dy[k] = with_v ? sums[k] : 0.0;
  if (with_v) PhlexMatVec3(b->port_rate[q], sums + 3, dy + 3); /* A B_r^T dv (A held over the step) */
  if (with_u) {
    /* w x d ubar */
    PetscReal dub[3], a[3];
    for (PetscInt k = 0; k < 3; k++) dub[k] = au * sums[6 + k];
    PhlexCross(b->fs.w, dub, a);
    for (PetscInt k = 0; k < 3; k++) dy[k] += a[k];
  }
  if (b->floating && dq) {
    const PetscReal *dvP = dq + 12, *dw = dq + 15;
    PetscReal        arm[3], a[3];
    for (PetscInt k = 0; k < 3; k++) arm[k] = part->ports[q].point[k] + (full && q < b->nports ? b->port_ubar[q][k] : 0.0);
    PhlexCross(dw, arm, a);
    for (PetscInt k = 0; k < 3; k++) {
      dy[k] += dvP[k] + a[k];
      dy[3 + k] += dw[k];
    }
  }
  PetscFunctionReturn(0);
}

/* dy = d y_q for a change (a du, dv, dq) of the state: both phases, its field products summed on their own */
static PetscErrorCode FlexPortLinear(PhlexPart part, PetscInt q, Vec du, PetscReal au, Vec dv, const PetscReal *dq, PetscReal dy[6])
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscReal     loc[PHLEX_PORT_SUMS], sums[PHLEX_PORT_SUMS] = {0};
  PetscBool     with_v, with_u;

  PetscFunctionBeginUser;
  PortLinearTerms(b, q, du, au, dv, &with_v, &with_u);
  if (with_v || with_u) {
    PetscCall(FlexPortLinearLocal(part, q, du, au, dv, loc));
    PetscCall(MPIU_Allreduce(loc, sums, PHLEX_PORT_SUMS, MPIU_REAL, MPI_SUM, b->comm));
  }
  PetscCall(FlexPortLinearSummed(part, q, du, au, dv, sums, dq, dy));
  PetscFunctionReturn(0);
}

/* dy for the columns of Y as velocity changes with du = Y/shift (the displacement eliminated): 6 x k */
static PetscErrorCode FlexPortLinearBlock(PhlexPart part, PetscInt q, Mat Y, PetscReal ainv, PetscReal *out)
{
  PhlexFlexible      b    = (PhlexFlexible)part->data;
  PetscBool          full = (b->floating && !b->frozen_inertia) ? PETSC_TRUE : PETSC_FALSE;
  const PetscScalar *Ya, *da[6];
  PetscReal         *loc;
  PetscInt           n, k, ld;

  PetscFunctionBeginUser;
  PetscCall(MatGetSize(Y, NULL, &k));
  PetscCall(PetscCalloc1(6 * k, &loc));
  if (q < b->nports) {
    PetscCall(MatGetLocalSize(Y, &n, NULL));
    PetscCall(MatDenseGetLDA(Y, &ld));
    PetscCall(MatDenseGetArrayRead(Y, &Ya));
    if (n > 0) {
      /* loc = D^T Y (6 x k), D the port's six distribution vectors (n x 6): one BLAS product; D is a block of the
         border basis W when a joint uses the port */
      const PetscScalar *Wa = NULL;
      PetscScalar       *D  = NULL;
      PetscInt           ldd = n;
      PetscBLASInt       bn, bk, bld, bldd, six = 6;
      PetscScalar        one = 1.0, zero = 0.0;
      if (b->W && b->port_basis_col[q] >= 0) {
        PetscCall(MatDenseGetLDA(b->W, &ldd));
        PetscCall(MatDenseGetArrayRead(b->W, &Wa));
      } else {
        PetscCall(PetscMalloc1(6 * n, &D));
        for (PetscInt c = 0; c < 6; c++) {
          PetscCall(VecGetArrayRead(b->ports[q].dist[c], &da[c]));
          PetscCall(PetscArraycpy(D + c * n, da[c], n));
          PetscCall(VecRestoreArrayRead(b->ports[q].dist[c], &da[c]));
        }
      }
      PetscCall(PetscBLASIntCast(n, &bn));
      PetscCall(PetscBLASIntCast(k, &bk));
      PetscCall(PetscBLASIntCast(ld, &bld));
      PetscCall(PetscBLASIntCast(ldd, &bldd));
      PetscCallBLAS("BLASgemm", BLASgemm_("T", "N", &six, &bk, &bn, &one, Wa ? Wa + b->port_basis_col[q] * ldd : D, &bldd, Ya, &bld, &zero, loc, &six));
      if (Wa) PetscCall(MatDenseRestoreArrayRead(b->W, &Wa));
      PetscCall(PetscFree(D));
    }
    PetscCall(MatDenseRestoreArrayRead(Y, &Ya));
  }
  PetscCall(MPIU_Allreduce(loc, out, 6 * k, MPIU_REAL, MPI_SUM, b->comm));
  if (q < b->nports)
    for (PetscInt j = 0; j < k; j++) {
      /* rotation: A B_r^T Y (the port's rate map) */
      PetscReal th[3] = {out[6 * j + 3], out[6 * j + 4], out[6 * j + 5]};
      PhlexMatVec3(b->port_rate[q], th, out + 6 * j + 3);
    }
  if (full)
    for (PetscInt j = 0; j < k; j++) {
      /* translation: + w x (mean of Y/shift) */
      PetscReal a[3];
      PhlexCross(b->fs.w, out + 6 * j, a);
      for (PetscInt c = 0; c < 3; c++) out[6 * j + c] += ainv * a[c];
    }
  PetscCall(PetscFree(loc));
  PetscFunctionReturn(0);
}

/* += generalized force of a wrench w on port q: B_q w on the elastic rows, (F, (c - P [+ ubar]) x F + T) on the frame */
static PetscErrorCode FlexPortForce(PhlexPart part, PetscInt q, const PetscReal w[6], Vec fv, PetscReal *fq)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (fv && q < b->nports) {
    PetscReal wd[6];
    PortDistribution(b, q, w, wd);
    for (PetscInt k = 0; k < 6; k++)
      if (wd[k] != 0.0) PetscCall(VecAXPY(fv, wd[k], b->ports[q].dist[k]));
  }
  if (b->floating && fq) {
    PetscReal arm[3], a[3];
    for (PetscInt k = 0; k < 3; k++) arm[k] = part->ports[q].point[k] + (!b->frozen_inertia && q < b->nports ? b->port_ubar[q][k] : 0.0);
    PhlexCross(arm, w, a);
    for (PetscInt k = 0; k < 3; k++) {
      fq[12 + k] += w[k];
      fq[15 + k] += a[k] + w[3 + k];
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexPortBasisColumn(PhlexPart part, PetscInt q, PetscInt *col)
{
  PetscFunctionBeginUser;
  *col = ((PhlexFlexible)part->data)->port_basis_col[q];
  PetscFunctionReturn(0);
}

/* inertial position and orientation of port q at the state X: r + R (c - P + u_avg), R exp([theta_avg]x) */
static PetscErrorCode FlexPortPlacement(PhlexPart part, PetscInt q, const PhlexPartVec *X, PetscReal x[3], PetscReal Rp[9])
{
  PhlexFlexible b     = (PhlexFlexible)part->data;
  PetscReal     ub[6] = {0, 0, 0, 0, 0, 0};

  PetscFunctionBeginUser;
  if (q < b->nports) {
    PetscScalar d[6];
    PetscCall(VecMDot(X->u, 6, b->ports[q].dist, d));
    for (PetscInt k = 0; k < 6; k++) ub[k] = PetscRealPart(d[k]);
  }
  PhlexPortPlacementFromMean(b->floating ? X->q : NULL, part->ports[q].point, ub, x, Rp);
  PetscFunctionReturn(0);
}

/* port q's rate map A (PhlexPartOps.portrate): with X, held at X's mean rotation theta = B_r^T u of the port (the
   left Jacobian J_l(theta) with -port_rate exact, else I); returned in A. The port's orientation is R exp([theta]x),
   whose angular velocity (body frame) is w + J_l(theta) theta' exactly; w + theta' is its first-order part, and the
   difference (1/2 theta x theta' + O(theta^2) theta') integrates over a closed whirl of theta to the geometric phase
   1/2 oint theta x dtheta, by which a joint on the port would open at each turn. Held over a step (taken at the step's
   extrapolated middle, as the joint frames are: PhlexSystemUpdateJoints): the output and the distribution then use the
   same A, so the joint stays exactly workless and the Jacobian has no term from A's change within the step. */
static PetscErrorCode FlexPortRate(PhlexPart part, PetscInt q, const PhlexPartVec *X, PetscReal A[9])
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (X && q < b->nports && b->port_rate_exact) {
    PetscScalar d[3];
    PetscReal   th[3];
    PetscCall(VecMDot(X->u, 3, b->ports[q].dist + 3, d));
    for (PetscInt k = 0; k < 3; k++) th[k] = PetscRealPart(d[k]);
    PhlexLeftJacobian(th, b->port_rate[q]);
  }
  for (PetscInt k = 0; k < 9; k++) A[k] = b->port_rate[q][k];
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* State, residual                                                                                                */

/* the evaluation's first phase (split_sum.c): a floating body's rates and its frame's integrals, their sums started */
static PetscErrorCode FlexEvaluateBegin(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot)
{
  PhlexFlexible   b = (PhlexFlexible)part->data;
  const PetscReal T = part->units->time;

  PetscFunctionBeginUser;
  if (!b->floating) PetscFunctionReturn(0);
  if (Xdot) {
    PetscCall(VecAXPBY(b->ud, T, 0.0, Xdot->u));
    PetscCall(VecAXPBY(b->vd, T, 0.0, Xdot->v));
  }
  /* a reduced state (X->p) has T u' = v exactly: the frame takes v as u' and saves a product with Mv */
  PetscCall(PhlexFrameEvaluateBegin(&b->frame, X->u, X->v, Xdot ? (X->p ? X->v : b->ud) : NULL, Xdot ? b->vd : NULL, &b->fs));
  b->frame_begun = PETSC_TRUE;
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexEvaluate(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot)
{
  PhlexFlexible   b = (PhlexFlexible)part->data;
  const PetscReal T = part->units->time;

  PetscFunctionBeginUser;
  b->t_eval       = t;
  b->joints_added = PETSC_FALSE;
  if (b->floating) {
    PetscReal qd[18];
    for (PetscInt k = 0; k < 18; k++) qd[k] = Xdot ? T * Xdot->q[k] : 0.0;
    if (!b->frame_begun) PetscCall(FlexEvaluateBegin(part, t, X, Xdot));
    b->frame_begun = PETSC_FALSE;
    PetscCall(PhlexFrameEvaluateEnd(&b->frame, X->q, qd, &b->fs));
  }
  PetscCall(ExternalLoads(part, t, X));
  if (b->damped) PetscCall(PhlexFlexibleDampingEvaluate(part, X->v)); /* R v formed when asked for (flexible_damping.c) */
  PetscCall(PortOutputs(part, X, PETSC_FALSE));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexResidual(PhlexPart part, PetscReal t, const PhlexPartVec *X, const PhlexPartVec *Xdot, PhlexPartVec *F)
{
  PhlexFlexible   b = (PhlexFlexible)part->data;
  const PetscReal T = part->units->time;

  Mat             G = b->G;

  PetscFunctionBeginUser;
  PetscCall(AddJointLoads(part));
  PetscCheck(!(X->p && b->stiffening), b->comm, PETSC_ERR_PLIB, "body %s: geometric stiffening has no reduced residual", b->name);
  if (b->stiffening) {
    /* the Green-Lagrange coupling G(u) in both rows (flexible_stiffening.c) */
    PetscCall(PhlexFlexibleCouplingUpdate(b, X->u));
    G = b->Gres;
  }
  if (!X->p && !b->G) {
    /* the generic path's first residual: G and Ms, deferred at set-up (FlexFieldOperators) */
    PetscCall(PhlexFlexibleSetUpMixed(b, part->units));
    G = b->G;
  }
  if (!X->p) {
    /* F_u = T u' - v */
    PetscCall(VecAXPBYPCZ(F->u, T, -1.0, 0.0, Xdot->u, X->v));
    /* F_Sigma = G v - T Ms Sigma' */
    PetscCall(MatMult(b->Ms, Xdot->s, F->s));
    PetscCall(VecScale(F->s, -T));
    PetscCall(MatMultAdd(G, X->v, F->s, F->s));
  }
  /* F_v = T Mv v' + G^T Sigma - b (reduced: the caller's G^T Sigma, displacement and stress rows not written); a
     moving frame has Mv (T v') already */
  if (X->p) PetscCall(VecCopy(X->p, F->v));
  else PetscCall(MatMultTranspose(G, X->s, F->v));
  if (b->floating) PetscCall(VecAXPY(F->v, 1.0, b->fs.Mvd));
  else {
    PetscCall(VecScale(F->v, 1.0 / T));
    PetscCall(MatMultAdd(b->Mvp ? b->Mvp : b->Mv, Xdot->v, F->v, F->v));
    PetscCall(VecScale(F->v, T));
  }
  if (!b->floating) {
    PetscCall(VecAXPY(F->v, -1.0, b->load));
    if (b->damped) {
      /* + R v (flexible_damping.c) */
      PetscCall(PhlexFlexibleDampingForce(part));
      PetscCall(VecAXPY(F->v, 1.0, b->rv));
    }
    if (b->spinning) {
      /* the hub's uniform spin: + Cor v + Cen (x - c + u) (flexible_spin.c) */
      PetscCall(MatMultAdd(b->Cor, X->v, F->v, F->v));
      PetscCall(MatMultAdd(b->Cen, X->u, F->v, F->v));
      PetscCall(VecAXPY(F->v, 1.0, b->fcen));
    }
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(PHLEX_FloatResidual, 0, 0, 0, 0));
  PetscCall(VecAXPY(F->v, -1.0, b->fs.bext));
  if (b->damped) {
    /* + R v_f: the elastic rows only, the frame's rows undamped */
    PetscCall(PhlexFlexibleDampingForce(part));
    PetscCall(VecAXPY(F->v, 1.0, b->rv));
  }
  if (b->spinning) {
    /* a rotor's co-rotating frame in the linearised analysis (PhlexFlexibleSteadyDrive): the field's rows as a fixed
       body's on a spinning hub, + Cor v + Cen (x - c + u); the frame is held there */
    PetscCall(MatMultAdd(b->Cor, X->v, F->v, F->v));
    PetscCall(MatMultAdd(b->Cen, X->u, F->v, F->v));
    PetscCall(VecAXPY(F->v, 1.0, b->fcen));
  }
  PetscCall(PhlexFrameResidual(&b->frame, &b->fs, X->u, X->v, b->ud, F->v, F->q));
  if (b->frame_condition == PHLEX_FRAME_MEAN_AXES) {
    /* the multipliers of int rho v = 0, int rho (x - P) x v = 0 enter through the transposed map (paper Section 5:
       a power-preserving interconnection with the ground of the elastic field's rigid content) */
    const PetscScalar *ta, *wa;
    PetscScalar       *fa;
    PetscReal          mt[3], mr[3];
    PetscInt           n;
    for (PetscInt k = 0; k < 3; k++) {
      mt[k] = T * Xdot->q[18 + k];
      mr[k] = T * Xdot->q[21 + k];
    }
    PetscCall(VecGetLocalSize(F->v, &n));
    PetscCall(VecGetArray(F->v, &fa));
    PetscCall(VecGetArrayRead(b->tnode, &ta));
    PetscCall(VecGetArrayRead(b->wnode, &wa));
    for (PetscInt l = 0; l < n / 3; l++) {
      PetscReal wl[3], a[3];
      for (PetscInt k = 0; k < 3; k++) wl[k] = PetscRealPart(wa[3 * l + k]);
      PhlexCross(mr, wl, a);
      for (PetscInt k = 0; k < 3; k++) fa[3 * l + k] -= PetscRealPart(ta[3 * l]) * mt[k] + a[k];
    }
    PetscCall(VecRestoreArray(F->v, &fa));
    PetscCall(VecRestoreArrayRead(b->tnode, &ta));
    PetscCall(VecRestoreArrayRead(b->wnode, &wa));
    for (PetscInt k = 0; k < 3; k++) {
      F->q[18 + k] = b->fs.Vf[k];
      F->q[21 + k] = b->fs.Lx[k];
    }
  }
  PetscCall(PetscLogEventEnd(PHLEX_FloatResidual, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexPostStep(PhlexPart part, PetscReal *q, PetscReal *defect)
{
  PetscFunctionBeginUser;
  *defect = 0.0;
  if (!((PhlexFlexible)part->data)->floating) PetscFunctionReturn(0);
  *defect = PhlexOrthogonalityError(q + 3);
  PhlexOrthonormalize(q + 3);
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Jacobian                                                                                                       */

/* Mv = M (x) I_3 (the mass couples each velocity component only with itself): its products go through the scalar
   mass M in a MAIJ matrix, which reads a ninth of Mv's entries (Mv's 3x3 blocks are diagonal, SBAIJ stores them
   whole); M is Mv's rows and columns of the x components */
static PetscErrorCode MassProductSetUp(PhlexFlexible b)
{
  IS       isx;
  Mat      M;
  PetscInt rstart, rend;

  PetscFunctionBeginUser;
  PetscCall(MatGetOwnershipRange(b->Mvaij, &rstart, &rend));
  PetscCall(ISCreateStride(b->comm, (rend - rstart) / 3, rstart, 3, &isx));
  PetscCall(MatCreateSubMatrix(b->Mvaij, isx, isx, MAT_INITIAL_MATRIX, &M));
  PetscCall(ISDestroy(&isx));
  PetscCall(MatCreateMAIJ(M, 3, &b->Mvp));
  PetscCall(MatDestroy(&M));
  PetscCall(PetscObjectSetName((PetscObject)b->Mvp, "velocity mass (products)"));
  if (b->floating) b->frame.Mv = b->Mvp;
  PetscFunctionReturn(0);
}

/* y = (a I + B) Mv x with B a node-wise 3x3 matrix: the elastic blocks of the moving frame */
static PetscErrorCode NodeMassMult(PhlexFlexible b, PetscReal a, const PetscReal B[9], Vec x, Vec y)
{
  PetscScalar *ya;
  PetscInt     n;

  PetscFunctionBeginUser;
  PetscCall(MatMult(b->Mvp, x, y));
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
  PhlexFlexible b;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &b));
  PetscCall(NodeMassMult(b, b->shift, b->Bvv, x, y));
  if (b->Rsb) PetscCall(MatMultAdd(b->Rsb, x, y, y)); /* structural damping */
  if (b->spinning) PetscCall(MatMultAdd(b->Cor, x, y, y)); /* a rotor's co-rotating frame (linearised analysis) */
  PetscFunctionReturn(0);
}

/* (shift + Bvv + Bvu / shift) Mv x: the velocity block with u = u0 + v / shift eliminated, one product with Mv */
static PetscErrorCode MatMult_Avc(Mat A, Vec x, Vec y)
{
  PhlexFlexible b;
  PetscReal     B[9];

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &b));
  for (PetscInt k = 0; k < 9; k++) B[k] = b->Bvv[k] + b->Bvu[k] / b->shift;
  PetscCall(NodeMassMult(b, b->shift, B, x, y));
  if (b->Rsb) PetscCall(MatMultAdd(b->Rsb, x, y, y)); /* structural damping */
  if (b->spinning) {
    /* a rotor's co-rotating frame (linearised analysis): Cor + Cen / shift */
    PetscCall(MatMultAdd(b->Cor, x, y, y));
    PetscCall(MatMult(b->Cen, x, b->work));
    PetscCall(VecAXPY(y, 1.0 / b->shift, b->work));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode MatMult_Avu(Mat A, Vec x, Vec y)
{
  PhlexFlexible b;

  PetscFunctionBeginUser;
  PetscCall(MatShellGetContext(A, &b));
  PetscCall(NodeMassMult(b, 0.0, b->Bvu, x, y));
  if (b->stiffening) PetscCall(MatMultAdd(b->Ksig, x, y, y)); /* the initial-stress stiffness */
  if (b->spinning) PetscCall(MatMultAdd(b->Cen, x, y, y));   /* a rotor's co-rotating frame (linearised analysis) */
  PetscFunctionReturn(0);
}

/* the AIJ copies of Mv and K (from the SBAIJ ones), if absent */
static PetscErrorCode AIJCopies(PhlexFlexible b)
{
  PetscFunctionBeginUser;
  if (!b->Mvaij) PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &b->Mvaij));
  if (!b->Kaij) PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &b->Kaij));
  PetscFunctionReturn(0);
}

/* the node-wise borders (PhlexFrameJacobian): the node inputs (a port's distributions with inertial loads copied once,
   they do not change) and room for the coefficients */
static PetscErrorCode BorderSetUp(PhlexPart part)
{
  PhlexFlexible  b = (PhlexFlexible)part->data;
  const PetscInt nnode = b->nv_local / 3, nq = part->nq;
  PetscInt       nin = PHLEX_FRAME_NIN;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc1(PetscMax(b->nports, 1), &b->port_inertial_in));
  for (PetscInt q = 0; q < b->nports; q++) {
    b->port_inertial_in[q] = -1;
    if (!b->ports[q].load.loaded || b->ports[q].load.frame != PHLEX_DIRECTION_INERTIAL) continue;
    b->port_inertial_in[q] = nin;
    nin += 18;
  }
  b->border_nin = nin;
  PetscCall(PetscCalloc5(PetscMax(nnode * nin, 1), &b->border_P, 3 * nq * nin, &b->border_Lb, 3 * nq * nin, &b->border_Lu, 3 * nq * nin, &b->border_Lv, 3 * nq * nin, &b->border_Lpre));
  for (PetscInt q = 0; q < b->nports; q++) {
    if (b->port_inertial_in[q] < 0) continue;
    for (PetscInt c = 0; c < 6; c++) {
      const PetscScalar *da;
      PetscCall(VecGetArrayRead(b->ports[q].dist[c], &da));
      for (PetscInt l = 0; l < nnode; l++)
        for (PetscInt e = 0; e < 3; e++) b->border_P[(b->port_inertial_in[q] + 3 * c + e) * nnode + l] = da[3 * l + e];
      PetscCall(VecRestoreArrayRead(b->ports[q].dist[c], &da));
    }
  }
  PetscFunctionReturn(0);
}

/* the matrices of the field blocks, built at the first request (a modal analysis never needs them) */
static PetscErrorCode FlexFieldOperators(PhlexPart part, PhlexFieldOperators *ops)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (!b->Sv) {
    MatNullSpace   nsp;
    const PetscInt n = b->nv_local, N = b->nv_global;
    /* the assembled coupling G and compliance mass Ms (3.0 kB per velocity DOF) multiply only Newton on the whole state
       and a displaced initial state: assembled when one of them asks (FlexMixedOperators, FlexResidual, the stress
       initial condition), not here, so that they never coexist with the AIJ copies below on the stages of SNES
       phlexcondensed and phlexreduced, which apply B, G^T and K cell by cell (BENCHMARKS.md section 40: the set-up's
       peak). A body with geometric stiffening or spin builds on G; -phlex_check_stress_maps compares with it. */
    if (b->stiffening || b->spinning || b->check_stress_maps) PetscCall(PhlexFlexibleSetUpMixed(b, part->units));
    else if (!b->smap_created) {
      PetscCall(PhlexFlexibleCreateStressMaps(b));
      b->smap_created = PETSC_TRUE;
    }
    /* AIJ: taken by every factorisation and by GAMG; its pattern is the union of those of K and Mv. A fixed body
       without stiffening or spin keeps neither AIJ copy (below): K's is freed once Sv holds it, before Mv's is made */
    const PetscBool lean = (PetscBool)(!b->floating && !b->stiffening && !b->spinning && !b->check_stress_maps);
    if (lean) {
      PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &b->Kaij));
      PetscCall(MatDuplicate(b->Kaij, MAT_COPY_VALUES, &b->Sv));
      PetscCall(MatDestroy(&b->Kaij));
      PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &b->Mvaij));
    } else {
      PetscCall(AIJCopies(b));
      PetscCall(MatDuplicate(b->Kaij, MAT_COPY_VALUES, &b->Sv));
    }
    PetscCall(MassProductSetUp(b));
    /* K and Mv have the same pattern (the P2 node couplings, full 3 x 3 blocks): PETSc finds it and adds in place;
       DIFFERENT_NONZERO_PATTERN built the sum as a new matrix beside Sv (0.95 kB per velocity DOF at the set-up's peak,
       BENCHMARKS.md section 40) */
    PetscCall(MatAXPY(b->Sv, 1.0, b->Mvaij, UNKNOWN_NONZERO_PATTERN));
    PetscCall(MatSetOption(b->Sv, MAT_SPD, PETSC_TRUE));
    PetscCall(DMPlexCreateRigidBody(b->dm, 0, &nsp));
    PetscCall(MatSetNearNullSpace(b->Sv, nsp));
    PetscCall(MatNullSpaceDestroy(&nsp));
    PetscCall(PetscObjectSetName((PetscObject)b->Sv, "condensed velocity operator"));
    PetscCall(PhlexFlexibleDampingSetUp(part)); /* R, in Sv and Jvv below and at every new shift (FlexJacobian) */
    if (!b->floating) {
      /* shift Mv, or shift Mv + R on Sv's pattern (R has K's) */
      if (b->damped) PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, &b->Jvv));
      else PetscCall(MatDuplicate(b->Mvaij, MAT_COPY_VALUES, &b->Jvv));
    } else {
      PetscCall(PhlexMatCreateShell(b->comm, n, n, N, N, b, MatMult_Avv, &b->Jvv));
      PetscCall(PhlexMatCreateShell(b->comm, n, n, N, N, b, MatMult_Avu, &b->Jvu));
      PetscCall(PhlexMatCreateShell(b->comm, n, n, N, N, b, MatMult_Avc, &b->Jvc));
      PetscCall(VecDuplicate(b->load, &b->ud));
      PetscCall(VecDuplicate(b->load, &b->vd));
      PetscCall(BorderSetUp(part));
    }
    b->kpattern = SUBSET_NONZERO_PATTERN;
    if (b->spinning || b->stiffening) {
      MatInfo ik, is;
      /* Sv is rebuilt at every Jacobian from K (G(u)), K_sigma, ...: same-pattern sums are fast, subset ones go row by
         row through MatSetValues */
      PetscCall(MatGetInfo(b->Kaij, MAT_LOCAL, &ik));
      PetscCall(MatGetInfo(b->Sv, MAT_LOCAL, &is));
      PetscInt same = ik.nz_used == is.nz_used ? 1 : 0; /* Sv holds Kaij's pattern: equal counts, equal patterns */
      PetscCall(MPIU_Allreduce(MPI_IN_PLACE, &same, 1, MPIU_INT, MPI_MIN, b->comm));
      b->kpattern = same ? SAME_NONZERO_PATTERN : SUBSET_NONZERO_PATTERN;
      PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, &b->Mvs));
      PetscCall(MatZeroEntries(b->Mvs));
      PetscCall(MatAXPY(b->Mvs, 1.0, b->Mvaij, SUBSET_NONZERO_PATTERN));
    }
    if (b->spinning) {
      /* the spin's operators (on Sv's pattern), and room for them in the fixed body's Jvv */
      PetscCall(PhlexFlexibleSpinSetUp(b, part->units));
      if (!b->floating) PetscCall(MatAXPY(b->Jvv, 0.0, b->Cor, DIFFERENT_NONZERO_PATTERN));
    }
    if (b->stiffening) PetscCall(PhlexFlexibleStiffeningSetUp(b));
    if (!b->floating && (b->spinning || b->stiffening)) {
      /* the exact Schur complement is not symmetric (Coriolis, d(G(u) v)/du); the displacement columns Cen + K_sigma */
      PetscCall(MatSetOption(b->Sv, MAT_SPD, PETSC_FALSE));
      PetscCall(MatSetOption(b->Sv, MAT_SYMMETRIC, PETSC_FALSE));
      PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, &b->Jvu));
      PetscCall(MatZeroEntries(b->Jvu));
      if (b->spinning) PetscCall(MatAXPY(b->Jvu, 1.0, b->Cen, SAME_NONZERO_PATTERN));
      PetscCall(PetscObjectSetName((PetscObject)b->Jvu, "velocity-displacement block"));
    }
    if (lean) {
      /* a fixed body's AIJ copies of Mv and K (0.95 kB per velocity DOF each): Sv, Jvv and Mvp hold what the steps
         multiply. Converted again, one at a time, for the rebuild at a new step size (FlexJacobian), and kept from
         Newton on the whole state or a linearised analysis's operators on (FlexMixedOperators; ops.M, ops.K are NULL
         until then): not beside the rest of the set-up (BENCHMARKS.md section 40) */
      PetscCall(MatDestroy(&b->Mvaij));
      PetscCall(MatDestroy(&b->Kaij));
    }
  }
  ops->G         = b->stiffening ? b->Gu : b->G;
  ops->Gt        = b->stiffening ? b->Gut : NULL; /* NULL: the system transposes G if the generic path needs G^T */
  ops->Jsu       = b->stiffening ? b->Jsu : NULL;
  if (b->floating && b->spinning) {
    /* a rotor's co-rotating frame (linearised analysis): K_sigma + Cen at the state, refreshed at every request */
    if (!b->Kspin) PetscCall(MatDuplicate(b->Cen, MAT_COPY_VALUES, &b->Kspin));
    else PetscCall(MatCopy(b->Cen, b->Kspin, SAME_NONZERO_PATTERN));
    if (b->stiffening) PetscCall(MatAXPY(b->Kspin, 1.0, b->Ksig, SUBSET_NONZERO_PATTERN));
  }
  ops->Kstate    = b->floating ? (b->spinning ? b->Kspin : (b->stiffening ? b->Ksig : NULL)) : ((b->stiffening || b->spinning) ? b->Jvu : NULL);
  ops->Gyro      = b->spinning ? b->Cor : NULL;
  ops->inexact_schur = (PetscBool)(b->stiffening || b->spinning);
  ops->Ms        = b->Ms;
  ops->B         = b->smap_B; /* NULL with geometric stiffening */
  ops->Res       = b->smap_Res;
  ops->Kc        = b->smap_K;
  ops->stress_bs = b->nb_s;
  ops->Jvv       = b->Jvv;
  ops->Jvu       = b->Jvu;
  ops->Jvc       = b->floating ? b->Jvc : (b->Jvu ? NULL : b->Jvv); /* a fixed body with a Jvu (spin, stiffening): none */
  ops->Sv        = b->Sv;
  ops->M         = b->Mvaij;
  ops->K         = b->Kaij;
  ops->load      = b->floating ? NULL : b->load;
  ops->R         = b->Rsb;
  PetscFunctionReturn(0);
}

/* the assembled coupling G and compliance mass Ms multiply only the generic path (Newton on the whole state: its
   residual and Jacobian) and the initial stress; the stages of SNES phlexcondensed and phlexreduced apply B, G^T and
   K cell by cell. Freed once those stages solve the steps (at 2.2e5 velocity DOFs they hold 0.9 GB), assembled again
   from the element structure if the generic path is asked for later. A body with geometric stiffening or a
   prescribed spin keeps them (its G(u), and the generic path it always takes, build on G). */
static PetscErrorCode FlexMixedOperators(PhlexPart part, PetscBool keep)
{
  PhlexFlexible b = (PhlexFlexible)part->data;

  PetscFunctionBeginUser;
  if (b->stiffening || b->spinning) PetscFunctionReturn(0);
  if (keep) {
    PetscCall(PhlexFlexibleSetUpMixed(b, part->units));
    PetscCall(AIJCopies(b));
  } else {
    PetscCall(MatDestroy(&b->G));
    PetscCall(MatDestroy(&b->Ms));
    /* a fixed body's AIJ copies of Mv and K serve the rebuild of Sv and Jvv at a new step size only (FlexJacobian
       converts them for that and frees them again); a floating body's also the preconditioner's rate terms */
    if (!b->floating) {
      PetscCall(MatDestroy(&b->Mvaij));
      PetscCall(MatDestroy(&b->Kaij));
    }
  }
  PetscFunctionReturn(0);
}

/* Sv = K / shift + (shift I + B) Mv with B node-wise (3x3): the condensed operator with the node-wise inertia terms
   of the frame's rate (Coriolis, centrifugal), on Sv's pattern (full 3x3 blocks, those of K); not symmetric */
static PetscErrorCode RateOperator(PhlexFlexible b, PetscReal shift, const PetscReal B[9])
{
  PetscInt rstart, rend;

  PetscFunctionBeginUser;
  PetscCall(MatCopy(b->Kaij, b->Sv, b->kpattern));
  PetscCall(MatScale(b->Sv, 1.0 / shift));
  PetscCall(MatGetOwnershipRange(b->Mvaij, &rstart, &rend));
  for (PetscInt row = rstart; row < rend; row++) {
    const PetscInt    *cols;
    const PetscScalar *vals;
    PetscInt           nc, n = 0, c = row % 3, *idx;
    PetscScalar       *v;
    PetscCall(MatGetRow(b->Mvaij, row, &nc, &cols, &vals));
    PetscCall(PetscMalloc2(3 * nc, &idx, 3 * nc, &v));
    for (PetscInt k = 0; k < nc; k++) {
      if (cols[k] % 3 != c || vals[k] == 0.0) continue; /* Mv couples equal components only */
      for (PetscInt d = 0; d < 3; d++) {
        idx[n] = cols[k] - c + d;
        v[n++] = vals[k] * ((c == d ? shift : 0.0) + B[3 * c + d]);
      }
    }
    PetscCall(MatRestoreRow(b->Mvaij, row, &nc, &cols, &vals));
    PetscCall(MatSetValues(b->Sv, 1, &row, n, idx, v, ADD_VALUES));
    PetscCall(PetscFree2(idx, v));
  }
  PetscCall(MatAssemblyBegin(b->Sv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Sv, MAT_FINAL_ASSEMBLY));
  if (b->damped) PetscCall(MatAXPY(b->Sv, 1.0, b->Rd, SUBSET_NONZERO_PATTERN)); /* structural damping */
  PetscCall(MatSetOption(b->Sv, MAT_SPD, PETSC_FALSE));
  PetscCall(MatSetOption(b->Sv, MAT_SYMMETRIC, PETSC_FALSE));
  PetscFunctionReturn(0);
}

/* the derivatives of the inputs with directions fixed in the inertial frame with respect to R (own columns) */
static PetscErrorCode InertialLoadsJacobian(PhlexPart part, PetscReal Arr[324])
{
  PhlexFlexible  b   = (PhlexFlexible)part->data;
  const PetscInt nin = b->border_nin;

  PetscFunctionBeginUser;
  for (PetscInt q = 0; q < b->nports; q++) {
    if (b->port_inertial_in[q] < 0) continue;
    for (PetscInt k = 0; k < 9; k++) {
      PetscReal dw[6], fq[18] = {0};
      PetscCall(PhlexPortLoadDerivativeR(&b->ports[q].load, b->t_eval, part->units, k, dw));
      /* F_v = ... - B w, F_q = ... - (F, M): the derivative enters with a minus sign; column 3 + k of the velocity
         rows' border is - sum_c dw_c dist_c, node by node the identity on the distributions' node inputs */
      for (PetscInt c = 0; c < 6; c++)
        for (PetscInt e = 0; e < 3; e++) b->border_Lb[(3 * (3 + k) + e) * nin + b->port_inertial_in[q] + 3 * c + e] -= dw[c];
      PetscCall(FlexPortForce(part, q, dw, NULL, fq));
      for (PetscInt i = 12; i < 18; i++) Arr[18 * i + 3 + k] -= fq[i];
    }
  }
  PetscFunctionReturn(0);
}

/* a fixed body's velocity block of the whole-state Jacobian without spin: shift Mv (+ R), from the AIJ copy of Mv */
static PetscErrorCode ShiftedMass(PhlexFlexible b, PetscReal shift)
{
  PetscFunctionBeginUser;
  PetscCall(MatCopy(b->Mvaij, b->Jvv, b->damped ? SUBSET_NONZERO_PATTERN : SAME_NONZERO_PATTERN));
  PetscCall(MatScale(b->Jvv, shift));
  if (b->damped) PetscCall(MatAXPY(b->Jvv, 1.0, b->Rd, SUBSET_NONZERO_PATTERN));
  PetscCall(MatAssemblyBegin(b->Jvv, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(b->Jvv, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

/* the whole-state Jacobian's velocity block shift Mv (+ R) of a fixed body without spin or stiffening (0.95 kB per
   velocity DOF): SNES phlexcondensed's stage never multiplies it (its operator is Sv), so the transient analysis frees
   it once that stage solves the steps; built again at the current shift if Newton on the whole state is asked for
   later (PhlexSystemCompleteJacobian) */
static PetscErrorCode FlexVelocityBlock(PhlexPart part, PetscBool keep)
{
  PhlexFlexible b = (PhlexFlexible)part->data;
  PetscBool     converted = PETSC_FALSE;

  PetscFunctionBeginUser;
  if (b->floating || b->stiffening || b->spinning || !b->Sv) PetscFunctionReturn(0);
  if (!keep) {
    PetscCall(MatDestroy(&b->Jvv));
    PetscFunctionReturn(0);
  }
  if (b->Jvv) PetscFunctionReturn(0);
  if (!b->Mvaij) {
    PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &b->Mvaij));
    converted = PETSC_TRUE;
  }
  /* as FlexFieldOperators made it, then as FlexJacobian fills it at the shift last seen */
  if (b->damped) PetscCall(MatDuplicate(b->Sv, MAT_DO_NOT_COPY_VALUES, &b->Jvv));
  else PetscCall(MatDuplicate(b->Mvaij, MAT_COPY_VALUES, &b->Jvv));
  if (b->shift > 0) PetscCall(ShiftedMass(b, b->shift));
  if (converted) PetscCall(MatDestroy(&b->Mvaij));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexJacobian(PhlexPart part, PetscReal shift, const PhlexPartVec *X, PetscReal *D, PetscInt ldD)
{
  PhlexFlexible  b = (PhlexFlexible)part->data;
  const PetscInt n = b->nv_local, nq = part->nq, nin = b->border_nin;
  PetscReal      Arr[324];

  PetscBool      new_shift = (PetscBool)(PetscAbsReal(shift - b->shift) > 1e-12 * shift);

  PetscFunctionBeginUser;
  if (new_shift && !b->Mvaij) {
    /* released (FlexMixedOperators: a fixed body without stiffening or spin): K and Mv converted to AIJ for this
       rebuild only, one after the other (the operations and their order as below), so that one AIJ copy exists at a
       time beside Sv and Jvv (BENCHMARKS.md section 40) */
    PetscCheck(!b->floating && !b->stiffening && !b->spinning, b->comm, PETSC_ERR_PLIB, "body %s: AIJ copies released", b->name);
    b->shift = shift;
    PetscCall(MatConvert(b->K, MATAIJ, MAT_INITIAL_MATRIX, &b->Kaij));
    PetscCall(MatCopy(b->Kaij, b->Sv, b->kpattern));
    PetscCall(MatDestroy(&b->Kaij));
    PetscCall(MatConvert(b->Mv, MATAIJ, MAT_INITIAL_MATRIX, &b->Mvaij));
    if (b->Jvv) PetscCall(ShiftedMass(b, shift)); /* NULL: released (FlexVelocityBlock) */
    PetscCall(MatScale(b->Sv, 1.0 / shift));
    PetscCall(MatAXPY(b->Sv, shift, b->Mvaij, SUBSET_NONZERO_PATTERN));
    if (b->damped) PetscCall(MatAXPY(b->Sv, 1.0, b->Rd, SUBSET_NONZERO_PATTERN)); /* shift Mv + K / shift + R */
    PetscCall(MatDestroy(&b->Mvaij));
    PetscFunctionReturn(0);
  }
  if (new_shift) {
    b->shift = shift;
    if (!b->floating && b->Jvv) {
      PetscCall(MatCopy(b->Mvaij, b->Jvv, (b->spinning || b->damped) ? SUBSET_NONZERO_PATTERN : SAME_NONZERO_PATTERN));
      PetscCall(MatScale(b->Jvv, shift));
      if (b->spinning) PetscCall(MatAXPY(b->Jvv, 1.0, b->Cor, SUBSET_NONZERO_PATTERN));
      if (b->damped) PetscCall(MatAXPY(b->Jvv, 1.0, b->Rd, SUBSET_NONZERO_PATTERN));
      PetscCall(MatAssemblyBegin(b->Jvv, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(b->Jvv, MAT_FINAL_ASSEMBLY));
    }
  }
  /* geometric stiffening: G(u), K_sigma, d(G(u) v)/du and the condensed stiffness at this state */
  if (b->stiffening) PetscCall(PhlexFlexibleStiffeningJacobian(b, X->u, X->s, X->v));
  if (new_shift || b->stiffening) {
    /* the preconditioner's condensed operator shift Mv + (K [+ K_sigma + Cen])/shift; a fixed body's also with the
       Coriolis term and G(u)^T Ms^{-1} d(G(u) v)/du / shift^2: the exact Schur complement of u and Sigma (not
       symmetric, LU). A floating body's stays symmetric (its bordered preconditioner factors it by Cholesky): there
       FGMRES takes care of those terms. */
    PetscCall(MatCopy(b->Kaij, b->Sv, b->kpattern));
    if (b->stiffening) PetscCall(MatAXPY(b->Sv, 1.0, b->Ksig, b->kpattern));
    if (b->spinning) PetscCall(MatAXPY(b->Sv, 1.0, b->Cen, SAME_NONZERO_PATTERN));
    if (b->stiffening && !b->floating) PetscCall(MatAXPY(b->Sv, 1.0 / shift, b->Nsu, b->kpattern));
    PetscCall(MatScale(b->Sv, 1.0 / shift));
    PetscCall(MatAXPY(b->Sv, shift, b->Mvs ? b->Mvs : b->Mvaij, b->Mvs ? SAME_NONZERO_PATTERN : SUBSET_NONZERO_PATTERN));
    if (b->spinning) PetscCall(MatAXPY(b->Sv, 1.0, b->Cor, SAME_NONZERO_PATTERN));
    if (b->damped) PetscCall(MatAXPY(b->Sv, 1.0, b->Rd, SUBSET_NONZERO_PATTERN)); /* shift Mv + K / shift + R */
  }
  if (!b->floating) {
    /* the displacement columns K_sigma + Cen: K_sigma changes with the state, Cen with the spin rate (which resets
       the shift) */
    if (b->stiffening || (b->spinning && new_shift)) {
      PetscCall(MatZeroEntries(b->Jvu));
      if (b->stiffening) PetscCall(MatAXPY(b->Jvu, 1.0, b->Ksig, b->kpattern));
      if (b->spinning) PetscCall(MatAXPY(b->Jvu, 1.0, b->Cen, SAME_NONZERO_PATTERN));
    }
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(PHLEX_FloatJacobian, 0, 0, 0, 0));
  PetscCall(AddJointLoads(part));
  PetscCall(PetscArrayzero(b->border_Lb, 3 * nq * nin));
  PetscCall(PetscArrayzero(b->border_Lu, 3 * nq * nin));
  PetscCall(PetscArrayzero(b->border_Lv, 3 * nq * nin));
  PetscCall(PhlexFrameJacobian(&b->frame, &b->fs, shift, b->border_Lb, b->border_Lu, b->border_Lv, nin, b->Bvv, b->Bvu, Arr));
  PetscCall(PhlexFrameNodeInputs(&b->frame, &b->fs, b->border_P, n / 3));
  if (new_shift || b->stiffening)
    for (PetscInt k = 0; k < 9; k++) b->pc_rate_B[k] = 0.0; /* Sv was rebuilt above without the rate's terms */
  if (b->pc_rate_restart) {
    /* a restart: the operator the checkpoint's run had factored, with the rate of its last refactorization (not the
       rate of this state), so that the lagged preconditioner, and with it the Krylov iterates, are those of the run
       that wrote the checkpoint (issue 43 item 9: without this the restarted run's steps differed at round-off from
       its first step on, 1e-9 J of 2967 J on the tumbling bar) */
    PetscReal nz = 0.0;
    b->pc_rate_restart = PETSC_FALSE;
    for (PetscInt k = 0; k < 9; k++) nz += PetscAbsReal(b->pc_rate_B_restart[k]);
    if (new_shift && nz > 0 && b->pc_rate_tol > 0 && !b->stiffening) {
      PetscCall(RateOperator(b, shift, b->pc_rate_B_restart));
      for (PetscInt k = 0; k < 9; k++) b->pc_rate_B[k] = b->pc_rate_B_restart[k];
    }
  }
  if (b->pc_rate_tol > 0 && !b->stiffening) {
    /* the preconditioner's operator with the node-wise terms of the rate once they exceed the tolerance, refactored
       when they drift by as much again (not with geometric stiffening: its operator is rebuilt at every Jacobian,
       and LU would double that) */
    PetscReal B[9], d = 0.0;
    for (PetscInt k = 0; k < 9; k++) {
      B[k] = b->Bvv[k] + b->Bvu[k] / shift;
      d += PetscSqr(B[k] - b->pc_rate_B[k]);
    }
    if (PetscSqrtReal(d) > b->pc_rate_tol * shift) {
      PetscCall(RateOperator(b, shift, B));
      for (PetscInt k = 0; k < 9; k++) b->pc_rate_B[k] = B[k];
      b->pc_rate_count++;
      PetscCall(PetscInfo(NULL, "body %s: condensed operator refactored with the frame's rate (%" PetscInt_FMT " time(s))\n", b->name, b->pc_rate_count));
    }
  }
  PetscCall(InertialLoadsJacobian(part, Arr));
  if (b->frame_condition == PHLEX_FRAME_MEAN_AXES) {
    /* rows T^T v and the force -T mu': column c (translation) t(l) e_c, column a (rotation) e_a x w(l) */
    for (PetscInt c = 0; c < 3; c++) {
      PetscReal ec[3] = {0, 0, 0};
      ec[c] = 1.0;
      b->border_Lv[(3 * (18 + c) + c) * nin + PHLEX_FRAME_IN_T] = 1.0;
      for (PetscInt m = 0; m < 3; m++) {
        PetscReal em[3] = {0, 0, 0}, a[3];
        em[m] = 1.0;
        PhlexCross(ec, em, a);
        for (PetscInt k = 0; k < 3; k++) b->border_Lv[(3 * (21 + c) + k) * nin + PHLEX_FRAME_IN_W + m] = a[k];
      }
    }
    for (PetscInt i = 3 * 18 * nin; i < 3 * 24 * nin; i++) b->border_Lb[i] = -shift * b->border_Lv[i];
  }
  for (PetscInt i = 0; i < 18; i++)
    for (PetscInt j = 0; j < 18; j++) D[ldD * i + j] = Arr[18 * i + j];
  for (PetscInt i = 18; i < nq; i++)
    for (PetscInt j = 0; j < nq; j++) D[ldD * i + j] = D[ldD * j + i] = 0.0;
  /* the border of the preconditioner: rigid rows after eliminating u (u = v / shift) */
  for (PetscInt i = 0; i < 3 * nq * nin; i++) b->border_Lpre[i] = b->border_Lv[i] + b->border_Lu[i] / shift;
  PetscCall(PetscObjectStateIncrease((PetscObject)b->Jvv));
  PetscCall(PetscObjectStateIncrease((PetscObject)b->Jvu));
  PetscCall(PetscObjectStateIncrease((PetscObject)b->Jvc));
  PetscCall(PetscLogEventEnd(PHLEX_FloatJacobian, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* ------------------------------------------------------------------------------------------------------------ */
/* Borders between the field and the body's own discrete unknowns                                                 */

static PetscErrorCode FlexBorderMult(PhlexPart part, const PetscReal *x, Vec y)
{
  PhlexFlexible  b = (PhlexFlexible)part->data;
  const PetscInt n = b->nv_local, nin = b->border_nin;
  PetscScalar   *ya, *A;
  PetscBLASInt   bnode, bnin, three = 3;
  PetscScalar    one = 1.0;

  PetscFunctionBeginUser;
  if (!part->nq || !n) PetscFunctionReturn(0);
  /* y_(l,c) += sum_i A[c][i] P[l][i], A[c][i] = sum_j x_j Lb[(3 j + c) nin + i]: one product with the node inputs */
  PetscCall(PetscCalloc1(3 * nin, &A));
  for (PetscInt j = 0; j < part->nq; j++) {
    if (x[j] == 0.0) continue;
    for (PetscInt c = 0; c < 3; c++)
      for (PetscInt i = 0; i < nin; i++) A[c + 3 * i] += x[j] * b->border_Lb[(3 * j + c) * nin + i];
  }
  PetscCall(PetscBLASIntCast(n / 3, &bnode));
  PetscCall(PetscBLASIntCast(nin, &bnin));
  PetscCall(VecGetArray(y, &ya));
  PetscCallBLAS("BLASgemm", BLASgemm_("N", "T", &three, &bnode, &bnin, &one, A, &three, b->border_P, &bnode, &one, ya, &three));
  PetscCall(VecRestoreArray(y, &ya));
  PetscCall(PetscFree(A));
  PetscFunctionReturn(0);
}

/* Mom_j (3 x nin, column-major, at Mom + 3 nin j) = sum_l Y_j(l) P_l^T: the moments with the node inputs of the k
   columns Y_j (3 values per node) of a dense matrix (leading dimension ldy; k = 1: a vector), node block by node block
   so that the block of node inputs stays in cache (one pass over the inputs instead of one per column). Several
   columns are packed node-major first (3k x block), so that one product with 3k rows takes the moments of all of them:
   with a product of 3 rows per column, PC phlexbordered's set-up at every Newton step took 2.2 times as long */
static PetscErrorCode BorderMomentsColumns(PhlexFlexible b, const PetscScalar *Y, PetscInt ldy, PetscInt k, PetscScalar *Mom)
{
  const PetscInt nnode = b->nv_local / 3, nin = b->border_nin, chunk = 1024;
  PetscBLASInt   bnode, bnin, blen, bm;
  PetscScalar    one = 1.0, *pack = NULL, *acc;

  PetscFunctionBeginUser;
  if (k < 1) PetscFunctionReturn(0);
  PetscCall(PetscBLASIntCast(nnode, &bnode));
  PetscCall(PetscBLASIntCast(nin, &bnin));
  PetscCall(PetscBLASIntCast(3 * k, &bm));
  if (k > 1) PetscCall(PetscMalloc2(3 * k * PetscMin(chunk, nnode), &pack, 3 * k * nin, &acc));
  else acc = Mom;
  PetscCall(PetscArrayzero(acc, 3 * nin * k));
  for (PetscInt l0 = 0; l0 < nnode; l0 += chunk) {
    const PetscInt len = PetscMin(chunk, nnode - l0);
    PetscCall(PetscBLASIntCast(len, &blen));
    if (k > 1) {
      /* pack[3 j + c + 3 k l] = Y_j(3 (l0 + l) + c) */
      for (PetscInt j = 0; j < k; j++) {
        const PetscScalar *y = Y + j * ldy + 3 * l0;
        for (PetscInt l = 0; l < len; l++)
          for (PetscInt c = 0; c < 3; c++) pack[3 * j + c + 3 * k * l] = y[3 * l + c];
      }
      PetscCallBLAS("BLASgemm", BLASgemm_("N", "N", &bm, &bnin, &blen, &one, pack, &bm, b->border_P + l0, &bnode, &one, acc, &bm));
    } else PetscCallBLAS("BLASgemm", BLASgemm_("N", "N", &bm, &bnin, &blen, &one, Y + 3 * l0, &bm, b->border_P + l0, &bnode, &one, acc, &bm));
  }
  if (k > 1) {
    /* acc (3k x nin, column-major) to Mom_j (3 x nin each) */
    for (PetscInt j = 0; j < k; j++)
      for (PetscInt i = 0; i < nin; i++)
        for (PetscInt c = 0; c < 3; c++) Mom[3 * nin * j + c + 3 * i] = acc[3 * j + c + 3 * k * i];
    PetscCall(PetscFree2(pack, acc));
  }
  PetscFunctionReturn(0);
}

/* y_j += a sum_{c,i} L[(3 j + c) nin + i] Mom[c + 3 i], j < nq: the border rows applied to a vector, from its moments */
static void BorderRowsOfMoments(PetscInt nq, PetscInt nin, const PetscScalar *L, const PetscScalar *Mom, PetscReal a, PetscReal *y)
{
  for (PetscInt j = 0; j < nq; j++) {
    PetscScalar s = 0.0;
    for (PetscInt c = 0; c < 3; c++)
      for (PetscInt i = 0; i < nin; i++) s += L[(3 * j + c) * nin + i] * Mom[c + 3 * i];
    y[j] += a * PetscRealPart(s);
  }
}

/* this process's parts of its own discrete rows applied to field vectors, a Cu^T xu + Cv^T xv (nq values in loc,
   set; NULL vectors are zero): the system sums them over the processes (border.c) */
static PetscErrorCode FlexBorderMultTransposeLocal(PhlexPart part, Vec xu, PetscReal au, Vec xv, PetscReal *loc)
{
  PhlexFlexible      b = (PhlexFlexible)part->data;
  const PetscInt     nq = part->nq, nin = b->border_nin;
  const PetscScalar *xa;
  PetscScalar       *Mom;

  PetscFunctionBeginUser;
  for (PetscInt j = 0; j < nq; j++) loc[j] = 0.0;
  if (!nq) PetscFunctionReturn(0);
  PetscCall(PetscMalloc1(3 * nin, &Mom));
  if (xu && xu == xv && au != 0.0) {
    /* the condensed rows Cv^T + au Cu^T from one pass over the vector */
    PetscCall(VecGetArrayRead(xu, &xa));
    PetscCall(BorderMomentsColumns(b, xa, 0, 1, Mom));
    PetscCall(VecRestoreArrayRead(xu, &xa));
    BorderRowsOfMoments(nq, nin, b->border_Lu, Mom, au, loc);
    BorderRowsOfMoments(nq, nin, b->border_Lv, Mom, 1.0, loc);
  } else {
    if (xu && au != 0.0) {
      PetscCall(VecGetArrayRead(xu, &xa));
      PetscCall(BorderMomentsColumns(b, xa, 0, 1, Mom));
      PetscCall(VecRestoreArrayRead(xu, &xa));
      BorderRowsOfMoments(nq, nin, b->border_Lu, Mom, au, loc);
    }
    if (xv) {
      PetscCall(VecGetArrayRead(xv, &xa));
      PetscCall(BorderMomentsColumns(b, xa, 0, 1, Mom));
      PetscCall(VecRestoreArrayRead(xv, &xa));
      BorderRowsOfMoments(nq, nin, b->border_Lv, Mom, 1.0, loc);
    }
  }
  PetscCall(PetscFree(Mom));
  PetscFunctionReturn(0);
}

static PetscErrorCode FlexCoarseSpace(PhlexPart part, PetscInt row0, PetscInt col0, Mat P, PetscInt *n1, PetscInt inj[])
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFlexibleCoarseSpace((PhlexFlexible)part->data, row0, col0, P, n1, inj));
  PetscFunctionReturn(0);
}

/* W: the state-independent span of the borders: the frame's 12 nodal fields t e_c and w_b e_c (floating; with constant_without_gyroscopic
   inertia every frame border lies in their span, gravity too) and the force distributions of the ports with joints */
static PetscErrorCode FlexBorderBasis(PhlexPart part, Mat *W)
{
  PhlexFlexible  b = (PhlexFlexible)part->data;
  const PetscInt n = b->nv_local;
  PetscInt       k = b->floating ? 12 : 0, ld;
  PetscScalar   *Wa;

  PetscFunctionBeginUser;
  if (!b->W) {
    for (PetscInt q = 0; q < b->nports; q++)
      if (part->port_used[q]) {
        b->port_basis_col[q] = k;
        k += 6;
      }
    b->kW = k;
    if (k) {
      PetscCall(MatCreateDense(b->comm, n, PETSC_DECIDE, PETSC_DETERMINE, k, NULL, &b->W));
      PetscCall(MatDenseGetLDA(b->W, &ld));
      PetscCall(MatDenseGetArrayWrite(b->W, &Wa));
      for (PetscInt col = 0; col < k; col++)
        for (PetscInt i = 0; i < n; i++) Wa[col * ld + i] = 0.0;
      if (b->floating) {
        const PetscScalar *ta, *wa;
        PetscCall(VecGetArrayRead(b->tnode, &ta));
        PetscCall(VecGetArrayRead(b->wnode, &wa));
        for (PetscInt l = 0; l < n / 3; l++)
          for (PetscInt c = 0; c < 3; c++) {
            Wa[c * ld + 3 * l + c] = ta[3 * l + c];
            for (PetscInt bb = 0; bb < 3; bb++) Wa[(3 + 3 * c + bb) * ld + 3 * l + c] = wa[3 * l + bb];
          }
        PetscCall(VecRestoreArrayRead(b->tnode, &ta));
        PetscCall(VecRestoreArrayRead(b->wnode, &wa));
      }
      for (PetscInt q = 0; q < b->nports; q++) {
        if (b->port_basis_col[q] < 0) continue;
        for (PetscInt c = 0; c < 6; c++) {
          const PetscScalar *da;
          PetscCall(VecGetArrayRead(b->ports[q].dist[c], &da));
          for (PetscInt i = 0; i < n; i++) Wa[(b->port_basis_col[q] + c) * ld + i] = da[i];
          PetscCall(VecRestoreArrayRead(b->ports[q].dist[c], &da));
        }
      }
      PetscCall(MatDenseRestoreArrayWrite(b->W, &Wa));
      PetscCall(MatAssemblyBegin(b->W, MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(b->W, MAT_FINAL_ASSEMBLY));
      PetscCall(PetscObjectSetName((PetscObject)b->W, "border basis"));
      if (b->floating) {
        /* LU of the Gram matrix W^T W, for the projection of the body's own borders */
        const PetscScalar *Wr;
        PetscScalar       *loc;
        PetscBLASInt       kb, info;
        PetscCall(PetscMalloc2(k * k, &b->gram, k, &b->gram_piv));
        PetscCall(PetscCalloc1(k * k, &loc));
        PetscCall(MatDenseGetArrayRead(b->W, &Wr));
        for (PetscInt i = 0; i < k; i++)
          for (PetscInt j = 0; j < k; j++)
            for (PetscInt r = 0; r < n; r++) loc[i + k * j] += Wr[i * ld + r] * Wr[j * ld + r];
        PetscCall(MatDenseRestoreArrayRead(b->W, &Wr));
        PetscCall(MPIU_Allreduce(loc, b->gram, k * k, MPIU_SCALAR, MPIU_SUM, b->comm));
        PetscCall(PetscFree(loc));
        PetscCall(PetscBLASIntCast(k, &kb));
        PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&kb, &kb, b->gram, &kb, b->gram_piv, &info));
        PetscCheck(!info, b->comm, PETSC_ERR_PLIB, "body %s: the border basis is rank deficient (LAPACK getrf info %d): two ports with joints share their surface?", b->name, (int)info);
      }
    }
  }
  *W = b->W;
  PetscFunctionReturn(0);
}

/* (Cv + Cu/shift)^T Y for the body's own rows: nq x k, column-major */
static PetscErrorCode FlexBorderRows(PhlexPart part, Mat Y, PetscReal *out, PetscInt ld)
{
  PhlexFlexible      b = (PhlexFlexible)part->data;
  const PetscInt     nq = part->nq, nin = b->border_nin;
  const PetscScalar *Ya;
  PetscInt           k, ldy;
  PetscScalar       *Mom;
  PetscReal         *loc, *glob;

  PetscFunctionBeginUser;
  if (!nq) PetscFunctionReturn(0);
  PetscCall(MatGetSize(Y, NULL, &k));
  PetscCall(MatDenseGetLDA(Y, &ldy));
  PetscCall(PetscCalloc2(nq * k, &loc, nq * k, &glob));
  PetscCall(PetscMalloc1(3 * nin * PetscMax(k, 1), &Mom));
  PetscCall(MatDenseGetArrayRead(Y, &Ya));
  PetscCall(BorderMomentsColumns(b, Ya, ldy, k, Mom));
  PetscCall(MatDenseRestoreArrayRead(Y, &Ya));
  for (PetscInt j = 0; j < k; j++) BorderRowsOfMoments(nq, nin, b->border_Lpre, Mom + 3 * nin * j, 1.0, loc + nq * j);
  PetscCall(PetscFree(Mom));
  PetscCall(MPIU_Allreduce(loc, glob, nq * k, MPIU_REAL, MPI_SUM, b->comm));
  for (PetscInt j = 0; j < k; j++)
    for (PetscInt i = 0; i < nq; i++) out[i + ld * j] = glob[i + nq * j];
  PetscCall(PetscFree2(loc, glob));
  PetscFunctionReturn(0);
}

/* beta with the body's own border columns ~ W beta: (W^T W)^{-1} W^T Bc, k x nq column-major (exact for constant_without_gyroscopic
   inertia; otherwise the projection used by the preconditioner) */
static PetscErrorCode FlexBorderCoefficients(PhlexPart part, PetscReal *beta, PetscInt ld)
{
  PhlexFlexible      b = (PhlexFlexible)part->data;
  const PetscInt     nq = part->nq, k = b->kW, nin = b->border_nin;
  const PetscScalar *Wa;
  PetscInt           ldw;
  PetscScalar       *Mom, *loc, *glob;
  PetscReal         *row;
  PetscBLASInt       kb, nrhs, info;

  PetscFunctionBeginUser;
  if (!nq || !k) PetscFunctionReturn(0);
  PetscCall(MatDenseGetLDA(b->W, &ldw));
  PetscCall(PetscCalloc4(k * nq, &loc, k * nq, &glob, 3 * nin * k, &Mom, nq, &row));
  /* loc = W^T Bc (k x nq): the moments of W's columns with the node inputs */
  PetscCall(MatDenseGetArrayRead(b->W, &Wa));
  PetscCall(BorderMomentsColumns(b, Wa, ldw, k, Mom));
  PetscCall(MatDenseRestoreArrayRead(b->W, &Wa));
  for (PetscInt i = 0; i < k; i++) {
    PetscCall(PetscArrayzero(row, nq));
    BorderRowsOfMoments(nq, nin, b->border_Lb, Mom + 3 * nin * i, 1.0, row);
    for (PetscInt j = 0; j < nq; j++) loc[i + k * j] = row[j];
  }
  PetscCall(MPIU_Allreduce(loc, glob, k * nq, MPIU_SCALAR, MPIU_SUM, b->comm));
  PetscCall(PetscBLASIntCast(k, &kb));
  PetscCall(PetscBLASIntCast(nq, &nrhs));
  PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &kb, &nrhs, b->gram, &kb, b->gram_piv, glob, &kb, &info));
  for (PetscInt j = 0; j < nq; j++)
    for (PetscInt i = 0; i < k; i++) beta[i + ld * j] = PetscRealPart(glob[i + k * j]);
  PetscCall(PetscFree4(loc, glob, Mom, row));
  PetscFunctionReturn(0);
}

PETSC_INTERN PetscErrorCode PhlexFlexibleSetDynamicsOps(PhlexPart part)
{
  PetscFunctionBeginUser;
  part->ops.evaluate      = FlexEvaluate;
  part->ops.residual      = FlexResidual;
  part->ops.jacobian      = FlexJacobian;
  part->ops.poststep      = FlexPostStep;
  part->ops.portoutput    = FlexPortOutput;
  part->ops.portinput     = FlexPortInput;
  part->ops.portlinear    = FlexPortLinear;
  part->ops.portforce     = FlexPortForce;
  part->ops.portplacement = FlexPortPlacement;
  part->ops.portrate      = FlexPortRate;
  part->fieldops->evaluatebegin            = FlexEvaluateBegin;
  part->fieldops->fieldoperators           = FlexFieldOperators;
  part->fieldops->mixedoperators           = FlexMixedOperators;
  part->fieldops->velocityblock            = FlexVelocityBlock;
  part->fieldops->bordermult               = FlexBorderMult;
  part->fieldops->bordermulttransposelocal = FlexBorderMultTransposeLocal;
  part->fieldops->borderbasis              = FlexBorderBasis;
  part->fieldops->borderrows               = FlexBorderRows;
  part->fieldops->bordercoefficients       = FlexBorderCoefficients;
  part->fieldops->portlinearlocal          = FlexPortLinearLocal;
  part->fieldops->portlinearsummed         = FlexPortLinearSummed;
  part->fieldops->portlinearblock          = FlexPortLinearBlock;
  part->fieldops->portbasiscolumn          = FlexPortBasisColumn;
  part->fieldops->coarsespace              = FlexCoarseSpace;
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePreconditionerRateGet - the frame's rate in the preconditioner's factored operator (the node-wise block
  Bvv + Bvu / shift of its last refactorization, -preconditioner_rate_tol) and the refactorizations so far: a
  checkpoint keeps them, so that a restart factors the very operator of the run that wrote it; zeros for another kind
  of part, or a body without the rate in its preconditioner

  Not collective
@*/
PetscErrorCode PhlexFlexiblePreconditionerRateGet(PhlexPart part, PetscReal rec[10])
{
  PetscBool flexible;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < 10; k++) rec[k] = 0.0;
  PetscCall(PetscStrcmp(part->type, "flexible", &flexible));
  if (flexible) {
    PhlexFlexible b = (PhlexFlexible)part->data;
    for (PetscInt k = 0; k < 9; k++) rec[k] = b->pc_rate_B[k];
    rec[9] = (PetscReal)b->pc_rate_count;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexiblePreconditionerRateSet - a restart: the rate PhlexFlexiblePreconditionerRateGet gave, put into the
  operator at the first Jacobian (nothing for another kind of part)

  Not collective
@*/
PetscErrorCode PhlexFlexiblePreconditionerRateSet(PhlexPart part, const PetscReal rec[10])
{
  PetscBool flexible;

  PetscFunctionBeginUser;
  PetscCall(PetscStrcmp(part->type, "flexible", &flexible));
  if (flexible) {
    PhlexFlexible b = (PhlexFlexible)part->data;
    for (PetscInt k = 0; k < 9; k++) b->pc_rate_B_restart[k] = rec[k];
    b->pc_rate_restart = PETSC_TRUE;
    b->pc_rate_count   = (PetscInt)rec[9];
  }
  PetscFunctionReturn(0);
}
