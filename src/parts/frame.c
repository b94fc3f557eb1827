/* The dynamics of a moving frame (paper Sections 2-4): a flexible body in large rigid motion with the full
   rigid-elastic coupling of its floating frame, or a rigid body (the same equations without an elastic field).

   State (non-dimensional, body frame): the elastic fields u, v (free velocity dofs, one x,y,z triple per node),
   Sigma, and q = [r (3) | R (9, row-wise) | v_P (3) | w (3)]. With y = x + u the position of a material point
   relative to the frame origin P (the centroid of the frame patch), the velocity field is V = v_P + w x y + v and
   the kinetic energy T = 1/2 int rho |V|^2 (paper eq. H). Every integral below is exact for the discrete fields:
     t(l)  = int rho phi_l,   w(l) = int rho x phi_l,   z(l) = w(l) + (Mv u)(l) = int rho y phi_l
     s = int rho y = s0 + sum_l t(l) u(l),  E = int rho y y^T,  J = tr(E) I - E,  L = int rho y x v
   The momenta (paper eq. momenta) p_t = m v_P + w x s + int rho v, p_r = s x v_P + J w + L, p_f = Mv v + t v_P +
   int rho phi (w x y), and the equations are the discrete Hamel equations of T, equivalent to the pH form of eqs.
   ph_mfd_all / MFD_pHDAE (p~_t, p~_r and the coefficient 2 of I_pf appear when the derivative of the mass operator
   is moved to the right-hand side):
     p_t' + w x p_t             = F_ext + R^T m g
     p_r' + w x p_r + v_P x p_t = M_ext + s x R^T g
     p_f' - dT/du + G^T Sigma   = b_ext + t R^T g          (dT/du = int rho phi (V x w))
     u' = v,  Ms Sigma' = G v,  r' = R v_P,  R' = R [w]x
   Two models keep the mass operator at u = 0 (s = s0, E = E0, z = w): the Hamiltonian
   H0 = 1/2 int rho |v_P + w x x + v|^2 + strain is quadratic, the interconnection skew, and the implicit midpoint rule
   conserves H0 to solver tolerance.
   - constant_without_gyroscopic: the Hamel equations of T0 alone. T0 does not depend on u, so the elastic field
     feels the frame's accelerations (t v_P', w' x x) but no velocity-dependent load: no centrifugal, Coriolis or
     transport (w x v_P) term.
   - constant (the paper's constant-inertia model, Section 4.3: "the dependence of the canonical momenta on the
     deformation field is neglected"): the momenta p_t, p_r, p_f of eq. momenta at u = 0, so M(u) = M0, and the
     interconnection J(e) of eq. ph_mfd_all built from them. Derivation: in the full model J(e) holds three things,
       (a) the Hamel (Kirchhoff) terms [p_t]x, [p_r]x and int [p_f]x (.), the rotation of each momentum with the frame;
       (b) the rate of the mass operator moved to the right (M(u) e' = p' - M(u)' e): the modified momenta of eq.
           mod_momenta, p~_t = p_t + int rho v_f, p~_r = p_r + int rho y x v_f, and the rho v_f of eq. mod_momentafl
           (the Coriolis term transported by u' = v_f);
       (c) the coefficient 2 of eq. mod_momentafl, which (the paper's remark after it) compensates -delta_u H = -p_f x w.
     With momenta that do not depend on u, M' = 0 removes (b) and delta_u H_kin = 0 removes what (c) compensates:
     the model is (a) alone, I_pf = int [p_f]x (.) with coefficient 1 and no rho v_f, p_t and p_r unmodified:
       p_t'                                   = p_t x w + F_ext
       p_r'                                   = p_t x v_P + p_r x w + int p_f x v_f + M_ext
       rho (v_P' + w' x x + v_f') - Div Sigma = p_f x w + b_ext,     p_f = rho (v_P + w x x + v_f)
     (M0 e' = p' with p = M0 e.) This is what the paper's beam code computes (its J: skew(M[:n_r] e) in the rigid rows,
     the elastic rows' Jf_om from rho (v_P + w x x + v_f), coefficient 1), and it reproduces the paper's figures (the
     hinged beam here: omega_z 0.030225 rad/s, the paper's 0.0302). The paper's eq. EB_J prints the full model's J at
     u = 0 (p~_t and the 2 of I_pf) beside that constant mass operator: with delta_u H = 0 its elastic rows get
     (2 p_f + rho v_f) x w, twice the centrifugal and transport loads. An independent beam model of the crank-slider in
     the paper's own frame (tools/crankslider_beam_model.py) gives the paper's figure with the model above and a first
     peak of 0.0072 instead of 0.0186 with eq. EB_J as printed: the figure does not come from the printed equation.
     In words: every particle obeys Newton's law in the inertial frame with its momentum R rho (v_P + w x x + v_f),
     held at its undeformed place x (d/dt (R p_f) = R (Div Sigma + b)), and the frame's rows are the sums of these
     (int and int x x): the frame's moment equation keeps int p_f x v_f, which cancels p_r x w's torque about a
     beam's axis as in the full model (without it a beam with a small polar inertia spins about its axis). The field
     feels rho (v_P + w x x + v_f) x w: transport, centrifugal and one of the two Coriolis terms (the other is (b)).
     J stays skew (int p_f x v_f in the moment row and p_f x w in the field rows are each other's adjoints), so H0 is
     conserved; R p_t is conserved (no loads); the angular momentum is not: its rate is R int rho (v_P + w x x) x v_f,
     the moment of the particles' velocities at their undeformed places. In Hamel form (what is implemented) the
     constant model is the model without gyroscopic terms plus, power-neutral in total (residual terms):
       rotation:     - v_P x int rho v - (Wv w - w tr(Wv))   (- int p_f x v_f; Wv = int rho x v^T; int rho v x v = 0)
       field (node l): - (t_l v_P + w x w_l + (Mv v)_l) x w   (-(I_pf)^* w = -p_f x w)
*/
#include <phlex_impl.h>

/* ---------------------------------------------------------------------------------------------------------- */
/* Node-wise reductions over the elastic space (local triples, then one reduction)                             */

/* out_c = sum_l t(l) x(l)_c  (= int rho x_c for x in the elastic space) */
static void LocalTdot(PetscInt nloc, const PetscScalar *t, const PetscScalar *x, PetscReal out[3])
{
  for (PetscInt l = 0; l < nloc; l++)
    for (PetscInt c = 0; c < 3; c++) out[c] += PetscRealPart(t[3 * l] * x[3 * l + c]);
}

/* out[b][c] = sum_l a(l)_b m(l)_c */
static void LocalOuter(PetscInt nloc, const PetscScalar *a, const PetscScalar *m, PetscReal out[9])
{
  for (PetscInt l = 0; l < nloc; l++)
    for (PetscInt bb = 0; bb < 3; bb++)
      for (PetscInt c = 0; c < 3; c++) out[3 * bb + c] += PetscRealPart(a[3 * l + bb] * m[3 * l + c]);
}

static inline void Eps(const PetscReal K[9], PetscReal out[3])
{
  /* out_a = eps_abc K[b][c] */
  out[0] = K[5] - K[7];
  out[1] = K[6] - K[2];
  out[2] = K[1] - K[3];
}

static inline void InertiaFromE(const PetscReal E[9], PetscReal J[9])
{
  const PetscReal tr = E[0] + E[4] + E[8];
  for (PetscInt i = 0; i < 9; i++) J[i] = -E[i];
  J[0] += tr;
  J[4] += tr;
  J[8] += tr;
}

/*@C
  PhlexFrameEvaluate - the inertia quantities and momenta of a moving frame at a state and its rates
  (PhlexFrameEvaluateBegin() and PhlexFrameEvaluateEnd() in one)

  Collective (a frame without a field: not collective)

  Input Parameters:
+ fr     - the frame
. u, v   - elastic displacement and velocity (NULL without a field)
. ud, vd - their rates (non-dimensional time), or NULL (zero)
. q, qd  - rigid state [r | R | v_P | w] and its rate (qd may be NULL)

  Notes:
  The external loads (f->Fext, f->Mext about P, f->bext, f->barm) are set by the caller afterwards, then
  PhlexFrameAddLoadArms adds the u-dependent moment arms of the full model.

  Output Parameter:
. f - the evaluated context (work vectors inside are reused)
@*/
PetscErrorCode PhlexFrameEvaluate(PhlexFrame *fr, Vec u, Vec v, Vec ud, Vec vd, const PetscReal q[18], const PetscReal qd[18], PhlexFrameState *f)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexFrameEvaluateBegin(fr, u, v, ud, vd, f));
  PetscCall(PhlexFrameEvaluateEnd(fr, q, qd, f));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameEvaluateBegin - the first phase of PhlexFrameEvaluate(): the field's products with Mv and this process's
  part of its integrals, whose sum over the processes it starts (split_sum.c: the system begins every part before it
  ends any, so that bodies on different processes form their integrals at the same time)

  Collective (non-blocking; a frame without a field: not collective)
@*/
PetscErrorCode PhlexFrameEvaluateBegin(PhlexFrame *fr, Vec u, Vec v, Vec ud, Vec vd, PhlexFrameState *f)
{
  const PetscBool    full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  const PetscScalar *ta, *wa, *ua, *va, *uda = NULL, *vda = NULL, *Mua, *Mvva, *Mvda = NULL;
  PetscInt           n, nloc;
  PetscReal         *loc = f->sums_loc;
  PetscReal         *U = loc, *Ud = loc + 3, *Vf = loc + 6, *Vfd = loc + 9, *Wu = loc + 12, *Wud = loc + 21, *Wv = loc + 30, *Wvd = loc + 39, *Nuu = loc + 48, *Nudu = loc + 57, *Nuv = loc + 66, *Nuvd = loc + 75;

  PetscFunctionBeginUser;
  PetscCall(PetscArrayzero(loc, 84));
  PetscCall(PetscArrayzero(f->sums, 84));
  f->sums_req = MPI_REQUEST_NULL;
  if (!fr->tnode) PetscFunctionReturn(0);
  if (!f->Mu) {
    PetscCall(VecDuplicate(u, &f->Mu));
    PetscCall(VecDuplicate(u, &f->Mvv));
    PetscCall(VecDuplicate(u, &f->Mud));
    PetscCall(VecDuplicate(u, &f->Mvd));
    PetscCall(VecDuplicate(u, &f->bext));
    PetscCall(VecDuplicate(u, &f->barm));
  }
  /* Mv-products needed by the inertia terms */
  if (full) PetscCall(MatMult(fr->Mv, u, f->Mu));
  else PetscCall(VecSet(f->Mu, 0.0));
  PetscCall(MatMult(fr->Mv, v, f->Mvv));
  if (full && ud == v) PetscCall(VecCopy(f->Mvv, f->Mud)); /* u' = v exactly (the caller eliminated u): one product fewer */
  else if (full && ud) PetscCall(MatMult(fr->Mv, ud, f->Mud));
  else PetscCall(VecSet(f->Mud, 0.0));
  if (vd) PetscCall(MatMult(fr->Mv, vd, f->Mvd));
  else PetscCall(VecSet(f->Mvd, 0.0));

  PetscCall(VecGetLocalSize(u, &n));
  nloc = n / 3;
  PetscCall(VecGetArrayRead(fr->tnode, &ta));
  PetscCall(VecGetArrayRead(fr->wnode, &wa));
  PetscCall(VecGetArrayRead(u, &ua));
  PetscCall(VecGetArrayRead(v, &va));
  if (ud) PetscCall(VecGetArrayRead(ud, &uda));
  if (vd) PetscCall(VecGetArrayRead(vd, &vda));
  PetscCall(VecGetArrayRead(f->Mu, &Mua));
  PetscCall(VecGetArrayRead(f->Mvv, &Mvva));
  PetscCall(VecGetArrayRead(f->Mvd, &Mvda));
  LocalTdot(nloc, ta, ua, U);
  LocalTdot(nloc, ta, va, Vf);
  if (ud) LocalTdot(nloc, ta, uda, Ud);
  if (vd) LocalTdot(nloc, ta, vda, Vfd);
  LocalOuter(nloc, wa, ua, Wu);
  LocalOuter(nloc, wa, va, Wv);
  if (ud) LocalOuter(nloc, wa, uda, Wud);
  if (vd) LocalOuter(nloc, wa, vda, Wvd);
  if (full) {
    LocalOuter(nloc, ua, Mua, Nuu);
    LocalOuter(nloc, ua, Mvva, Nuv);
    if (ud) LocalOuter(nloc, uda, Mua, Nudu); /* int rho ud_b u_c */
    if (vd) LocalOuter(nloc, ua, Mvda, Nuvd);
    /* Nuv collects int rho u_b v_c; the rate of L also needs int rho ud_b v_c: add it into Nuvd */
    if (ud) LocalOuter(nloc, uda, Mvva, Nuvd);
  }
  PetscCall(VecRestoreArrayRead(fr->tnode, &ta));
  PetscCall(VecRestoreArrayRead(fr->wnode, &wa));
  PetscCall(VecRestoreArrayRead(u, &ua));
  PetscCall(VecRestoreArrayRead(v, &va));
  if (ud) PetscCall(VecRestoreArrayRead(ud, &uda));
  if (vd) PetscCall(VecRestoreArrayRead(vd, &vda));
  PetscCall(VecRestoreArrayRead(f->Mu, &Mua));
  PetscCall(VecRestoreArrayRead(f->Mvv, &Mvva));
  PetscCall(VecRestoreArrayRead(f->Mvd, &Mvda));
  PetscCall(PhlexSplitSumBegin(fr->comm, loc, f->sums, 84, &f->sums_req));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameEvaluateEnd - the second phase of PhlexFrameEvaluate(): the rigid state and its rate, and with the
  field's integrals (their sum awaited) the inertia quantities and momenta

  Collective (a frame without a field: not collective)
@*/
PetscErrorCode PhlexFrameEvaluateEnd(PhlexFrame *fr, const PetscReal q[18], const PetscReal qd[18], PhlexFrameState *f)
{
  const PetscBool  full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  const PetscReal *glob = f->sums;
  const PetscReal *U, *Ud, *Vf, *Vfd, *Wu, *Wud, *Wv, *Wvd, *Nuu, *Nudu, *Nuv, *Nuvd;

  PetscFunctionBeginUser;
  PetscCall(PhlexSplitSumEnd(&f->sums_req));
  for (PetscInt k = 0; k < 3; k++) {
    f->r[k]  = q[k];
    f->vP[k] = q[12 + k];
    f->w[k]  = q[15 + k];
    f->rd[k] = qd ? qd[k] : 0.0;
    f->vPd[k] = qd ? qd[12 + k] : 0.0;
    f->wd[k]  = qd ? qd[15 + k] : 0.0;
  }
  for (PetscInt k = 0; k < 9; k++) {
    f->R[k]  = q[3 + k];
    f->Rd[k] = qd ? qd[3 + k] : 0.0;
  }
  U = glob; Ud = glob + 3; Vf = glob + 6; Vfd = glob + 9; Wu = glob + 12; Wud = glob + 21; Wv = glob + 30; Wvd = glob + 39; Nuu = glob + 48; Nudu = glob + 57; Nuv = glob + 66; Nuvd = glob + 75;

  /* s, E, J and rates (paper eq. momenta with s_u, J_u) */
  f->m = fr->inertia.m;
  for (PetscInt k = 0; k < 3; k++) {
    f->s[k]    = fr->inertia.s0[k] + (full ? U[k] : 0.0);
    f->sd[k]   = full ? Ud[k] : 0.0;
    f->Vf[k]   = Vf[k];
    f->Vfd[k]  = Vfd[k];
    f->sgrav[k] = fr->inertia.s0[k] + U[k]; /* gravity acts on the current position in either model */
  }
  for (PetscInt bb = 0; bb < 3; bb++)
    for (PetscInt c = 0; c < 3; c++) {
      const PetscInt k = 3 * bb + c, kt = 3 * c + bb;
      f->E[k]  = fr->inertia.E0[k] + (full ? Wu[k] + Wu[kt] + Nuu[k] : 0.0);
      f->Ed[k] = full ? Wud[k] + Wud[kt] + Nudu[k] + Nudu[kt] : 0.0;
    }
  InertiaFromE(f->E, f->J);
  InertiaFromE(f->Ed, f->Jd);
  {
    PetscReal K[9], Kd[9];
    for (PetscInt k = 0; k < 9; k++) {
      K[k]  = Wv[k] + (full ? Nuv[k] : 0.0);
      Kd[k] = Wvd[k] + (full ? Nuvd[k] : 0.0);
    }
    Eps(K, f->L);
    Eps(Kd, f->Ld);
    Eps(Wv, f->Lx);
    for (PetscInt k = 0; k < 9; k++) f->Wv[k] = Wv[k];
  }
  /* momenta and their rates */
  {
    PetscReal a[3], c[3];
    PhlexCross(f->w, f->s, a);
    for (PetscInt k = 0; k < 3; k++) f->pt[k] = f->m * f->vP[k] + a[k] + f->Vf[k];
    PhlexCross(f->s, f->vP, a);
    PhlexMatVec3(f->J, f->w, c);
    for (PetscInt k = 0; k < 3; k++) f->pr[k] = a[k] + c[k] + f->L[k];
    /* p_t' = m vP' + w' x s + w x s' + int rho v' */
    PhlexCross(f->wd, f->s, a);
    PhlexCross(f->w, f->sd, c);
    for (PetscInt k = 0; k < 3; k++) f->ptd[k] = f->m * f->vPd[k] + a[k] + c[k] + f->Vfd[k];
    /* p_r' = s' x vP + s x vP' + J' w + J w' + L' */
    PhlexCross(f->sd, f->vP, a);
    PhlexCross(f->s, f->vPd, c);
    for (PetscInt k = 0; k < 3; k++) f->prd[k] = a[k] + c[k] + f->Ld[k];
    PhlexMatVec3(f->Jd, f->w, a);
    PhlexMatVec3(f->J, f->wd, c);
    for (PetscInt k = 0; k < 3; k++) f->prd[k] += a[k] + c[k];
  }
  /* gravity in the body frame */
  PhlexMatTVec3(f->R, fr->gravity, f->gbody);
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameAddLoadArms - adds to the moment about P the u-dependent arms of the elastic forces in the full model,
  sum_l u(l) x b_arm(l) (the caller has set f->barm, f->Fext and f->Mext)

  Collective
@*/
PetscErrorCode PhlexFrameAddLoadArms(PhlexFrame *fr, Vec u, PhlexFrameState *f)
{
  PetscReal          Mloc[3] = {0, 0, 0}, Mu[3];
  const PetscScalar *ua, *ba;
  PetscInt           n;

  PetscFunctionBeginUser;
  if (!fr->tnode) PetscFunctionReturn(0);
  if (!fr->frozen) {
    PetscCall(VecGetLocalSize(u, &n));
    PetscCall(VecGetArrayRead(u, &ua));
    PetscCall(VecGetArrayRead(f->barm, &ba));
    for (PetscInt l = 0; l < n / 3; l++) {
      PetscReal x[3], y[3], a[3];
      for (PetscInt k = 0; k < 3; k++) {
        x[k] = PetscRealPart(ua[3 * l + k]);
        y[k] = PetscRealPart(ba[3 * l + k]);
      }
      PhlexCross(x, y, a);
      for (PetscInt k = 0; k < 3; k++) Mloc[k] += a[k];
    }
    PetscCall(VecRestoreArrayRead(u, &ua));
    PetscCall(VecRestoreArrayRead(f->barm, &ba));
    PetscCall(MPIU_Allreduce(Mloc, Mu, 3, MPIU_REAL, MPI_SUM, fr->comm));
    for (PetscInt k = 0; k < 3; k++) f->Mext[k] += Mu[k];
  }
  PetscFunctionReturn(0);
}

/* the moving-frame terms of the elastic momentum rows at one node, from its inputs (t_l, z_l = int rho y phi_l, (Mv u')_l,
   (Mv v)_l): linear in them, with coefficients of the frame's state (C = |w|^2 I - w w^T, vxw = v_P x w) */
static inline void NodeLoad(const PhlexFrame *fr, const PhlexFrameState *f, const PetscReal C[9], const PetscReal vxw[3], PetscReal tl, const PetscReal z[3], const PetscReal Mud_l[3], const PetscReal Mv_l[3], PetscReal acc[3])
{
  const PetscBool full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  PetscReal       tmp[3], tmp2[3];

  /* t vP' + int rho phi (w' x y) = t vP' + w' x z */
  PhlexCross(f->wd, z, acc);
  for (PetscInt k = 0; k < 3; k++) acc[k] += tl * f->vPd[k] - tl * f->gbody[k];
  if (full) {
    /* + Mv (w x ud): node-wise cross commutes with Mv */
    PhlexCross(f->w, Mud_l, tmp);
    /* - dT/du = - [t (vP x w) + C z + Mv v x w]  (C = |w|^2 I - w w^T, (w x y) x w = C y) */
    PhlexMatVec3(C, z, tmp2);
    for (PetscInt k = 0; k < 3; k++) acc[k] += tmp[k] - tl * vxw[k] - tmp2[k];
    PhlexCross(Mv_l, f->w, tmp);
    for (PetscInt k = 0; k < 3; k++) acc[k] -= tmp[k];
  } else if (fr->gyroscopic) {
    /* constant model: - p_f x w = - (t v_P + w x w_l + Mv v) x w  (z = w_l: u = 0; -(I_pf)^* w, coefficient 1) */
    PhlexMatVec3(C, z, tmp2);
    PhlexCross(Mv_l, f->w, tmp);
    for (PetscInt k = 0; k < 3; k++) acc[k] -= tl * vxw[k] + tmp2[k] + tmp[k];
  }
}

/* C = |w|^2 I - w w^T and v_P x w of an evaluated state */
static void NodeLoadFactors(const PhlexFrameState *f, PetscReal C[9], PetscReal vxw[3])
{
  PhlexCross(f->vP, f->w, vxw);
  for (PetscInt i = 0; i < 9; i++) C[i] = -f->w[i / 3] * f->w[i % 3];
  {
    const PetscReal w2 = PhlexDot3(f->w, f->w);
    C[0] += w2;
    C[4] += w2;
    C[8] += w2;
  }
}

/*@C
  PhlexFrameLoadCoefficients - the moving-frame terms of the elastic momentum rows as a linear map of a node's inputs
  (PHLEX_FRAME_IN_*): the load at a node with inputs P_l is sum_i A[c + 3 i] P_l[i] (component c), at the evaluated
  state; the terms PhlexFrameResidual adds node by node

  Not collective

  Notes:
  A body whose elastic field is spanned by a basis Phi (a reduced body) gets its generalized frame loads by contracting
  A with the moments sum_l P_l[i] Phi_k(l, c) of the node inputs with each basis vector (its inertia invariants): the
  Galerkin projection of the full body's rows, term by term. PHLEX_FRAME_IN_B (load arms) and PHLEX_FRAME_IN_W have no
  term here.
@*/
PetscErrorCode PhlexFrameLoadCoefficients(PhlexFrame *fr, PhlexFrameState *f, PetscReal A[3 * PHLEX_FRAME_NIN])
{
  PetscReal C[9], vxw[3];

  PetscFunctionBeginUser;
  NodeLoadFactors(f, C, vxw);
  for (PetscInt i = 0; i < 3 * PHLEX_FRAME_NIN; i++) A[i] = 0.0;
  for (PetscInt i = 0; i < PHLEX_FRAME_IN_B; i++) {
    PetscReal in[PHLEX_FRAME_NIN] = {0}, acc[3];
    in[i] = 1.0;
    NodeLoad(fr, f, C, vxw, in[PHLEX_FRAME_IN_T], in + PHLEX_FRAME_IN_Z, in + PHLEX_FRAME_IN_ZD, in + PHLEX_FRAME_IN_MV, acc);
    for (PetscInt c = 0; c < 3; c++) A[c + 3 * i] = acc[c];
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameResidual - adds the moving-frame terms to the elastic momentum residual Fv (which already holds
  Mv v' + G^T Sigma - b_ext; NULL without a field) and computes the 18 rigid residuals Fq (all in non-dimensional
  time)

  Collective (without a field: not collective)
@*/
PetscErrorCode PhlexFrameResidual(PhlexFrame *fr, PhlexFrameState *f, Vec u, Vec v, Vec ud, Vec Fv, PetscReal Fq[18])
{
  const PetscBool    full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  PetscScalar       *fa;
  const PetscScalar *ta, *wa, *ua, *va, *uda, *Mua, *Mvva, *Muda;
  PetscInt           n;
  PetscReal          C[9], vxw[3], a[3], c[3];

  PetscFunctionBeginUser;
  /* kinematics: r' = R v_P, R' = R [w]x  (Fq rows 0-11) */
  PhlexMatVec3(f->R, f->vP, a);
  for (PetscInt k = 0; k < 3; k++) Fq[k] = f->rd[k] - a[k];
  {
    PetscReal S[9], RS[9];
    PhlexSkew(f->w, S);
    PhlexMatMat3(f->R, S, RS);
    for (PetscInt k = 0; k < 9; k++) Fq[3 + k] = f->Rd[k] - RS[k];
  }
  /* p_t' + w x p_t - F - R^T m g */
  PhlexCross(f->w, f->pt, a);
  for (PetscInt k = 0; k < 3; k++) Fq[12 + k] = f->ptd[k] + a[k] - f->Fext[k] - f->m * f->gbody[k];
  /* p_r' + w x p_r + vP x p_t - M - s x R^T g */
  PhlexCross(f->w, f->pr, a);
  PhlexCross(f->vP, f->pt, c);
  for (PetscInt k = 0; k < 3; k++) Fq[15 + k] = f->prd[k] + a[k] + c[k] - f->Mext[k];
  PhlexCross(f->sgrav, f->gbody, a);
  for (PetscInt k = 0; k < 3; k++) Fq[15 + k] -= a[k];
  if (fr->frozen && fr->gyroscopic) {
    /* constant model, rotation: - int p_f x v = - v_P x int rho v - (Wv w - w tr(Wv))  (int rho (w x x) x v = Wv w - w tr(Wv)) */
    const PetscReal tr = f->Wv[0] + f->Wv[4] + f->Wv[8];
    PhlexCross(f->vP, f->Vf, a);
    for (PetscInt k = 0; k < 3; k++) Fq[15 + k] -= a[k] + (f->Wv[3 * k] * f->w[0] + f->Wv[3 * k + 1] * f->w[1] + f->Wv[3 * k + 2] * f->w[2]) - f->w[k] * tr;
  }

  /* elastic rows: p_f' - Mv v' = t vP' + int rho phi (w' x y) + Mv (w x ud), minus dT/du, minus t R^T g */
  NodeLoadFactors(f, C, vxw);
  if (!fr->tnode) PetscFunctionReturn(0);
  PetscCall(VecGetLocalSize(u, &n));
  PetscCall(VecGetArray(Fv, &fa));
  PetscCall(VecGetArrayRead(fr->tnode, &ta));
  PetscCall(VecGetArrayRead(fr->wnode, &wa));
  PetscCall(VecGetArrayRead(u, &ua));
  PetscCall(VecGetArrayRead(v, &va));
  PetscCall(VecGetArrayRead(f->Mu, &Mua));
  PetscCall(VecGetArrayRead(f->Mvv, &Mvva));
  PetscCall(VecGetArrayRead(f->Mud, &Muda));
  uda = NULL;
  if (ud) PetscCall(VecGetArrayRead(ud, &uda));
  for (PetscInt l = 0; l < n / 3; l++) {
    PetscReal z[3], Mud_l[3] = {0, 0, 0}, Mv_l[3], acc[3];
    for (PetscInt k = 0; k < 3; k++) {
      z[k]    = PetscRealPart(wa[3 * l + k] + Mua[3 * l + k]); /* int rho y phi_l */
      Mv_l[k] = PetscRealPart(Mvva[3 * l + k]);
      if (full) Mud_l[k] = PetscRealPart(Muda[3 * l + k]);
    }
    NodeLoad(fr, f, C, vxw, PetscRealPart(ta[3 * l]), z, Mud_l, Mv_l, acc);
    for (PetscInt k = 0; k < 3; k++) fa[3 * l + k] += acc[k];
  }
  PetscCall(VecRestoreArray(Fv, &fa));
  PetscCall(VecRestoreArrayRead(fr->tnode, &ta));
  PetscCall(VecRestoreArrayRead(fr->wnode, &wa));
  PetscCall(VecRestoreArrayRead(u, &ua));
  PetscCall(VecRestoreArrayRead(v, &va));
  PetscCall(VecRestoreArrayRead(f->Mu, &Mua));
  PetscCall(VecRestoreArrayRead(f->Mvv, &Mvva));
  PetscCall(VecRestoreArrayRead(f->Mud, &Muda));
  if (ud) PetscCall(VecRestoreArrayRead(ud, &uda));
  PetscFunctionReturn(0);
}

/* D[a][e] = d (J(u) w)_a / d u(l)_e = 2 z_e w_a - z_a w_e - delta_ae (z . w), z = int rho y phi_l */
static inline void InertiaDerivative(const PetscReal z[3], const PetscReal w[3], PetscReal D[9])
{
  const PetscReal zw = PhlexDot3(z, w);
  for (PetscInt a = 0; a < 3; a++)
    for (PetscInt e = 0; e < 3; e++) D[3 * a + e] = 2.0 * z[e] * w[a] - z[a] * w[e] - (a == e ? zw : 0.0);
}

/* the field borders at one node (inputs PHLEX_FRAME_IN_*, linear in them): bc[3 j + c] = d(elastic row c)/d(rigid
   unknown j), cu[3 k + e], cv[3 k + e] = d(rigid row k)/d u_e, d v_e */
static void NodeBorders(const PhlexFrame *fr, const PhlexFrameState *f, PetscReal shift, const PetscReal in[PHLEX_FRAME_NIN], PetscReal bc[54], PetscReal cu[54], PetscReal cv[54])
{
  const PetscBool  full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  const PetscReal *w = f->w, *wd = f->wd, *vP = f->vP, *g = fr->gravity;
  const PetscReal  tl = in[PHLEX_FRAME_IN_T], *z = in + PHLEX_FRAME_IN_Z, *zd = in + PHLEX_FRAME_IN_ZD, *Mvl = in + PHLEX_FRAME_IN_MV, *Mvdl = in + PHLEX_FRAME_IN_MVD, *bl = in + PHLEX_FRAME_IN_B;

  for (PetscInt i = 0; i < 54; i++) bc[i] = cu[i] = cv[i] = 0.0;
  /* elastic rows x rigid columns */
  for (PetscInt c = 0; c < 3; c++)
    for (PetscInt i = 0; i < 3; i++) bc[3 * (3 + 3 * i + c) + c] = -tl * g[i]; /* R_ic: gravity -t g_i */
  for (PetscInt j = 0; j < 3; j++) {
    PetscReal ej[3] = {0, 0, 0}, col[3], a3[3];
    ej[j] = 1.0;
    /* vP_j: shift t e_j - t (e_j x w) */
    PhlexCross(ej, w, a3);
    for (PetscInt c = 0; c < 3; c++) bc[3 * (12 + j) + c] = shift * tl * ej[c] - (full || fr->gyroscopic ? tl * a3[c] : 0.0);
    /* w_a (a = j): shift e_a x z + [e_a x Mud - t vP x e_a - dC/dw_a z - Mv v x e_a] */
    PhlexCross(ej, z, col);
    for (PetscInt c = 0; c < 3; c++) col[c] *= shift;
    if (full) {
      PetscReal t1[3], t2[3], t3[3];
      PhlexCross(ej, zd, t1);
      PhlexCross(vP, ej, t2);
      PhlexCross(Mvl, ej, t3);
      for (PetscInt c = 0; c < 3; c++) {
        const PetscReal dCz = 2.0 * w[j] * z[c] - ej[c] * PhlexDot3(w, z) - w[c] * z[j];
        col[c] += t1[c] - tl * t2[c] - dCz - t3[c];
      }
    } else if (fr->gyroscopic) {
      /* constant model: - (t vP x e_a + dC/dw_a z + Mv v x e_a) */
      PetscReal t2[3], t3[3];
      PhlexCross(vP, ej, t2);
      PhlexCross(Mvl, ej, t3);
      for (PetscInt c = 0; c < 3; c++) {
        const PetscReal dCz = 2.0 * w[j] * z[c] - ej[c] * PhlexDot3(w, z) - w[c] * z[j];
        col[c] += -tl * t2[c] - dCz - t3[c];
      }
    }
    for (PetscInt c = 0; c < 3; c++) bc[3 * (15 + j) + c] = col[c];
  }
  /* rigid rows x elastic columns */
  for (PetscInt e = 0; e < 3; e++) {
    PetscReal ee[3] = {0, 0, 0}, a3[3], b3[3], c3[3];
    ee[e] = 1.0;
    /* v: p_t row: t (shift e_e + w x e_e) */
    PhlexCross(w, ee, a3);
    for (PetscInt k = 0; k < 3; k++) cv[3 * (12 + k) + e] = tl * (shift * ee[k] + a3[k]);
    /* v: p_r row: shift (z x e_e) [+ Mud x e_e] + w x (z x e_e) + vP x (t e_e) */
    {
      PetscReal zxe[3], wz[3], r3[3];
      PhlexCross(z, ee, zxe);
      PhlexCross(w, zxe, wz);
      PhlexCross(vP, ee, r3);
      for (PetscInt k = 0; k < 3; k++) cv[3 * (15 + k) + e] = shift * zxe[k] + wz[k] + tl * r3[k];
      if (full) {
        PetscReal mdx[3];
        PhlexCross(zd, ee, mdx);
        for (PetscInt k = 0; k < 3; k++) cv[3 * (15 + k) + e] += mdx[k];
      } else if (fr->gyroscopic) {
        /* constant model, rotation: d/dv(l,e) of - v_P x int rho v - Wv w + w tr(Wv) = - t vP x e_e - z w_e + w z_e (z = w_l) */
        for (PetscInt k = 0; k < 3; k++) cv[3 * (15 + k) + e] += -tl * r3[k] - z[k] * w[e] + w[k] * z[e];
      }
    }
    /* u: sgrav depends on u in both models: p_r row -t (e_e x R^T g) */
    PhlexCross(ee, f->gbody, b3);
    for (PetscInt k = 0; k < 3; k++) cu[3 * (15 + k) + e] = -tl * b3[k];
    if (full) {
      PetscReal D[9], Dd[9], Dwd[9], dpr[3], t1[3], t2[3], wsum[3];
      /* p_t row: t [(w' + shift w) x e_e + w x (w x e_e)] */
      for (PetscInt k = 0; k < 3; k++) wsum[k] = wd[k] + shift * w[k];
      PhlexCross(wsum, ee, a3);
      PhlexCross(w, ee, t1);
      PhlexCross(w, t1, t2);
      for (PetscInt k = 0; k < 3; k++) cu[3 * (12 + k) + e] = tl * (a3[k] + t2[k]);
      /* p_r row */
      InertiaDerivative(z, w, D);
      InertiaDerivative(zd, w, Dd);
      InertiaDerivative(z, wd, Dwd);
      /* dp_r/du(l,e) = t (e_e x vP) + D e_e + e_e x Mv v */
      PhlexCross(ee, vP, t1);
      PhlexCross(ee, Mvl, t2);
      for (PetscInt k = 0; k < 3; k++) dpr[k] = tl * t1[k] + D[3 * k + e] + t2[k];
      PhlexCross(w, dpr, c3); /* w x dp_r/du */
      {
        PetscReal t3[3], t4[3], t5[3], t6[3];
        PhlexCross(ee, vP, t3);     /* shift t (e_e x vP) from s' x vP */
        PhlexCross(ee, f->vPd, t4); /* t (e_e x vP') from s x vP' */
        PhlexCross(ee, Mvl, t5);    /* shift (e_e x Mv v) from L' */
        PhlexCross(ee, Mvdl, t6);   /* e_e x Mv v' from L' */
        PhlexCross(w, ee, t1);
        PhlexCross(vP, t1, t2);     /* vP x (w x e_e) t from vP x p_t */
        PhlexCross(ee, bl, b3);     /* - e_e x b_arm from -M */
        for (PetscInt k = 0; k < 3; k++) cu[3 * (15 + k) + e] += shift * tl * t3[k] + tl * t4[k] + shift * D[3 * k + e] + Dd[3 * k + e] + Dwd[3 * k + e] + shift * t5[k] + t6[k] + c3[k] + tl * t2[k] - b3[k];
      }
    }
  }
}

/*@C
  PhlexFrameJacobian - dF/dX + shift dF/dX' of the floating-frame terms (non-dimensional shift)

  Not collective

  Input Parameter:
. nin - the node inputs of the caller's border representation (at least PHLEX_FRAME_NIN)

  Output Parameters:
+ Bvv, Bvu   - node-wise 3x3 matrices: the elastic-row blocks are shift Mv + Bvv Mv (velocity) and Bvu Mv
               (displacement); they vanish in the frozen model
. Lb, Lu, Lv - the field borders' coefficients (NULL: not wanted), entries (3 j + c) nin + i for i < PHLEX_FRAME_NIN
               and rigid unknowns j < 18: d(elastic row (l, c))/d(rigid unknown j) = sum_i Lb[(3 j + c) nin + i] P[l][i]
               with P the node inputs (PhlexFrameNodeInputs); Lu, Lv likewise d(rigid row j)/d u, d v at (l, c)
- Arr        - 18 x 18 row-major rigid block (meaningful on every rank)

  Notes:
  Rigid unknowns in the order r (0-2), R (3-11, row-wise), v_P (12-14), w (15-17).
  The borders are node-wise: each column is, at every node, the same linear map of the node's inputs (t, its
  position moment w(l) + (Mv u)(l), (Mv u')(l), (Mv v)(l), (Mv v')(l), the load arm). Stored as that map (its
  coefficients are the borders at unit inputs), a product with a border reads 19 inputs per node, about 6 values per
  field unknown, instead of 18 dense columns, and the Jacobian writes no field-sized arrays.
@*/
PetscErrorCode PhlexFrameJacobian(PhlexFrame *fr, PhlexFrameState *f, PetscReal shift, PetscScalar *Lb, PetscScalar *Lu, PetscScalar *Lv, PetscInt nin, PetscReal Bvv[9], PetscReal Bvu[9], PetscReal Arr[324])
{
  const PetscBool  full = fr->frozen ? PETSC_FALSE : PETSC_TRUE;
  const PetscReal *w = f->w, *wd = f->wd, *vP = f->vP, *g = fr->gravity;
  PetscReal        S[9], C[9], sx[9];

  PetscFunctionBeginUser;
  PhlexSkew(w, S);
  for (PetscInt i = 0; i < 9; i++) C[i] = -w[i / 3] * w[i % 3];
  {
    const PetscReal w2 = PhlexDot3(w, w);
    C[0] += w2;
    C[4] += w2;
    C[8] += w2;
  }
  /* node-wise blocks: A_vv = shift Mv + [w]x Mv, A_vu = (shift [w]x + [w']x - C) Mv (full model) */
  {
    PetscReal Sd[9];
    PhlexSkew(wd, Sd);
    const PetscBool gyro = (PetscBool)(!full && fr->gyroscopic);
    for (PetscInt i = 0; i < 9; i++) {
      Bvv[i] = full ? S[i] : (gyro ? S[i] : 0.0); /* constant model: - Mv v x w */
      Bvu[i] = full ? shift * S[i] + Sd[i] - C[i] : 0.0;
    }
  }

  /* rigid block (rows 0-17, columns 0-17) */
  PetscCall(PetscArrayzero(Arr, 324));
#define A(i, j) Arr[18 * (i) + (j)]
  /* r' - R vP */
  for (PetscInt i = 0; i < 3; i++) {
    A(i, i) = shift;
    for (PetscInt j = 0; j < 3; j++) {
      A(i, 3 + 3 * i + j) = -vP[j];
      A(i, 12 + j)        = -f->R[3 * i + j];
    }
  }
  /* R' - R [w]x: d/dR_ik = shift delta_kj - S_kj, d/dw_a = -sum_k R_ik eps_kaj */
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) {
      const PetscInt row = 3 + 3 * i + j;
      for (PetscInt k = 0; k < 3; k++) A(row, 3 + 3 * i + k) = (k == j ? shift : 0.0) - S[3 * k + j];
      for (PetscInt a = 0; a < 3; a++) {
        PetscReal s = 0;
        for (PetscInt k = 0; k < 3; k++) {
          const PetscReal eps = (k == a || a == j || k == j) ? 0.0 : ((k - a + 3) % 3 == 2 ? 1.0 : -1.0); /* eps_kaj */
          s += f->R[3 * i + k] * eps;
        }
        A(row, 15 + a) = -s;
      }
    }
  /* p_t' + w x p_t - F - R^T m g */
  PhlexSkew(f->s, sx);
  {
    PetscReal Spt[9], SwSs[9], Ssd[9];
    PhlexSkew(f->pt, Spt);
    PhlexSkew(f->sd, Ssd);
    PhlexMatMat3(S, sx, SwSs);
    for (PetscInt a = 0; a < 3; a++)
      for (PetscInt c = 0; c < 3; c++) {
        A(12 + a, 12 + c) = (a == c ? shift * f->m : 0.0) + f->m * S[3 * a + c];
        A(12 + a, 15 + c) = -shift * sx[3 * a + c] - Ssd[3 * a + c] - Spt[3 * a + c] - SwSs[3 * a + c];
      }
    for (PetscInt i = 0; i < 3; i++)
      for (PetscInt j = 0; j < 3; j++) A(12 + j, 3 + 3 * i + j) += -f->m * g[i];
  }
  /* p_r' + w x p_r + vP x p_t - M - s x R^T g */
  {
    PetscReal Ssd[9], Spt[9], Spr[9], SvP[9], SwSs[9], SwJ[9], SvPSs[9];
    PhlexSkew(f->sd, Ssd);
    PhlexSkew(f->pt, Spt);
    PhlexSkew(f->pr, Spr);
    PhlexSkew(vP, SvP);
    PhlexMatMat3(S, sx, SwSs);
    PhlexMatMat3(S, f->J, SwJ);
    PhlexMatMat3(SvP, sx, SvPSs);
    for (PetscInt a = 0; a < 3; a++)
      for (PetscInt c = 0; c < 3; c++) {
        const PetscInt k = 3 * a + c;
        A(15 + a, 12 + c) = shift * sx[k] + Ssd[k] + SwSs[k] - Spt[k] + f->m * SvP[k];
        A(15 + a, 15 + c) = shift * f->J[k] + f->Jd[k] - Spr[k] + SwJ[k] - SvPSs[k];
      }
    for (PetscInt i = 0; i < 3; i++)
      for (PetscInt j = 0; j < 3; j++) {
        PetscReal ej[3] = {0, 0, 0}, a3[3];
        ej[j] = 1.0;
        PhlexCross(f->sgrav, ej, a3);
        for (PetscInt a = 0; a < 3; a++) A(15 + a, 3 + 3 * i + j) += -g[i] * a3[a];
      }
  }
  if (!full && fr->gyroscopic) {
    /* constant model, rotation: d(- v_P x Vf)/dv_P = [Vf]x; d(- Wv w + w tr(Wv))/dw = tr(Wv) I - Wv */
    PetscReal SVf[9];
    const PetscReal tr = f->Wv[0] + f->Wv[4] + f->Wv[8];
    PhlexSkew(f->Vf, SVf);
    for (PetscInt a = 0; a < 3; a++)
      for (PetscInt c = 0; c < 3; c++) {
        A(15 + a, 12 + c) += SVf[3 * a + c];
        A(15 + a, 15 + c) += (a == c ? tr : 0.0) - f->Wv[3 * a + c];
      }
  }
#undef A

  /* the field borders: every column is linear in the node inputs, with coefficients the same at every node; they are
     the borders' values at unit inputs */
  if (!Lb) PetscFunctionReturn(0);
  for (PetscInt i = 0; i < PHLEX_FRAME_NIN; i++) {
    PetscReal in[PHLEX_FRAME_NIN] = {0}, bc[54], cu[54], cv[54];
    in[i] = 1.0;
    NodeBorders(fr, f, shift, in, bc, cu, cv);
    for (PetscInt jc = 0; jc < 54; jc++) {
      Lb[jc * nin + i] = bc[jc];
      Lu[jc * nin + i] = cu[jc];
      Lv[jc * nin + i] = cv[jc];
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameNodeInputs - the node inputs of the field borders at the evaluated state (PHLEX_FRAME_IN_*)

  Not collective

  Output Parameter:
. P - n_local/3 x PHLEX_FRAME_NIN, column-major with leading dimension ld (its first PHLEX_FRAME_NIN columns)
@*/
PetscErrorCode PhlexFrameNodeInputs(PhlexFrame *fr, PhlexFrameState *f, PetscScalar *P, PetscInt ld)
{
  const PetscScalar *ta, *wa, *Mua, *Mvva, *Muda, *Mvda, *ba;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(fr->tnode, &n));
  PetscCall(VecGetArrayRead(fr->tnode, &ta));
  PetscCall(VecGetArrayRead(fr->wnode, &wa));
  PetscCall(VecGetArrayRead(f->Mu, &Mua));
  PetscCall(VecGetArrayRead(f->Mvv, &Mvva));
  PetscCall(VecGetArrayRead(f->Mud, &Muda));
  PetscCall(VecGetArrayRead(f->Mvd, &Mvda));
  PetscCall(VecGetArrayRead(f->barm, &ba));
  for (PetscInt l = 0; l < n / 3; l++) {
    P[PHLEX_FRAME_IN_T * ld + l] = PetscRealPart(ta[3 * l]);
    for (PetscInt k = 0; k < 3; k++) {
      P[(PHLEX_FRAME_IN_Z + k) * ld + l]   = PetscRealPart(wa[3 * l + k] + Mua[3 * l + k]);
      P[(PHLEX_FRAME_IN_ZD + k) * ld + l]  = PetscRealPart(Muda[3 * l + k]);
      P[(PHLEX_FRAME_IN_MV + k) * ld + l]  = PetscRealPart(Mvva[3 * l + k]);
      P[(PHLEX_FRAME_IN_MVD + k) * ld + l] = PetscRealPart(Mvda[3 * l + k]);
      P[(PHLEX_FRAME_IN_B + k) * ld + l]   = PetscRealPart(ba[3 * l + k]);
      P[(PHLEX_FRAME_IN_W + k) * ld + l]   = PetscRealPart(wa[3 * l + k]);
    }
  }
  PetscCall(VecRestoreArrayRead(fr->tnode, &ta));
  PetscCall(VecRestoreArrayRead(fr->wnode, &wa));
  PetscCall(VecRestoreArrayRead(f->Mu, &Mua));
  PetscCall(VecRestoreArrayRead(f->Mvv, &Mvva));
  PetscCall(VecRestoreArrayRead(f->Mud, &Muda));
  PetscCall(VecRestoreArrayRead(f->Mvd, &Mvda));
  PetscCall(VecRestoreArrayRead(f->barm, &ba));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameEnergy - kinetic energy T = 1/2 int rho |V|^2 and gravity potential -g . (m r + R s) (non-dimensional),
  given vMv = v^T Mv v of the field at the evaluated state, summed over the processes (0 without a field; the caller
  sums it with its own integrals: split_sum.c)

  Not collective (uses an evaluated state)
@*/
PetscErrorCode PhlexFrameEnergy(PhlexFrame *fr, PhlexFrameState *f, PetscReal vMv, PetscReal *kinetic, PetscReal *potential)
{
  PetscReal a[3], Jw[3], Rs[3];

  PetscFunctionBeginUser;
  PhlexCross(f->w, f->s, a);
  PhlexMatVec3(f->J, f->w, Jw);
  *kinetic = 0.5 * f->m * PhlexDot3(f->vP, f->vP) + PhlexDot3(f->vP, a) + 0.5 * PhlexDot3(f->w, Jw) + PhlexDot3(f->vP, f->Vf) + PhlexDot3(f->w, f->L) + 0.5 * vMv;
  PhlexMatVec3(f->R, f->sgrav, Rs);
  *potential = -(f->m * PhlexDot3(fr->gravity, f->r) + PhlexDot3(fr->gravity, Rs));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameMomenta - inertial linear momentum R p_t and angular momentum about the inertial origin
  R p_r + r x R p_t (non-dimensional)
@*/
PetscErrorCode PhlexFrameMomenta(PhlexFrameState *f, PetscReal P[3], PetscReal L[3])
{
  PetscReal a[3];

  PetscFunctionBeginUser;
  PhlexMatVec3(f->R, f->pt, P);
  PhlexMatVec3(f->R, f->pr, L);
  PhlexCross(f->r, P, a);
  for (PetscInt k = 0; k < 3; k++) L[k] += a[k];
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameStateDestroy - frees the work vectors of an evaluation context
@*/
PetscErrorCode PhlexFrameStateDestroy(PhlexFrameState *f)
{
  PetscFunctionBeginUser;
  PetscCall(VecDestroy(&f->Mu));
  PetscCall(VecDestroy(&f->Mvv));
  PetscCall(VecDestroy(&f->Mud));
  PetscCall(VecDestroy(&f->Mvd));
  PetscCall(VecDestroy(&f->bext));
  PetscCall(VecDestroy(&f->barm));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameRigidMass - the mass matrix of the frame's rigid motion (v_P, w) at u = 0: [[m I, -[s0]x], [[s0]x, J0]]
  (row-major 6 x 6)
@*/
PetscErrorCode PhlexFrameRigidMass(const PhlexInertia *in, PetscReal M[36])
{
  PetscReal S[9], J[9];

  PetscFunctionBeginUser;
  PhlexSkew(in->s0, S);
  InertiaFromE(in->E0, J);
  for (PetscInt i = 0; i < 3; i++)
    for (PetscInt j = 0; j < 3; j++) {
      M[6 * i + j]           = i == j ? in->m : 0.0;
      M[6 * i + 3 + j]       = -S[3 * i + j];
      M[6 * (3 + i) + j]     = S[3 * i + j];
      M[6 * (3 + i) + 3 + j] = J[3 * i + j];
    }
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameWriteHeader - the header of a frame's CSV series (<part>_rigid.csv)
@*/
PetscErrorCode PhlexFrameWriteHeader(char header[], size_t len)
{
  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(header, "time,rx,ry,rz,cx,cy,cz,R11,R12,R13,R21,R22,R23,R31,R32,R33,qw,qx,qy,qz,vPx,vPy,vPz,wx,wy,wz,Px,Py,Pz,Lx,Ly,Lz,orthogonality", len));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFrameWriteRow - one row of a frame's CSV series (SI): position of P and of the centre of mass, rotation (matrix
  and quaternion), v_P, w (body frame), inertial momenta, orthogonality error ||R^T R - I||_F; returns the momenta
  (non-dimensional) for the drift checks
@*/
PetscErrorCode PhlexFrameWriteRow(PetscViewer csv, PetscReal t, PhlexFrameState *f, const PhlexUnits *u, PetscReal P[3], PetscReal L[3])
{
  PetscReal qt[4], Rs[3], orth = PhlexOrthogonalityError(f->R);

  PetscFunctionBeginUser;
  PetscCall(PhlexFrameMomenta(f, P, L));
  PhlexRotationToQuaternion(f->R, qt);
  PhlexMatVec3(f->R, f->sgrav, Rs);
  PetscCall(PhlexCSVPrintf(csv, "%.12e", (double)t));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(f->r[k] * u->length)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)((f->r[k] + Rs[k] / f->m) * u->length)));
  for (PetscInt k = 0; k < 9; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)f->R[k]));
  for (PetscInt k = 0; k < 4; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)qt[k]));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(f->vP[k] * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(f->w[k] / u->time)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(P[k] * u->mass * u->velocity)));
  for (PetscInt k = 0; k < 3; k++) PetscCall(PhlexCSVPrintf(csv, ",%.12e", (double)(L[k] * u->mass * u->velocity * u->length)));
  PetscCall(PhlexCSVPrintf(csv, ",%.12e\n", (double)orth));
  PetscFunctionReturn(0);
}
