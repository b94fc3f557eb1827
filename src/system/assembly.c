/* The consistent start of a mechanism and its position-level upkeep:
   - attached point masses placed on their ports;
   - redundant constraint components found (rank-revealing orthogonalisation of the joints' rows with respect to the
     bodies' frame motions, in scene order) and reported by joint and component: an error, or dropped;
   - the loops closed at position level (Newton on the frames' positions and orientations with the smallest
     mass-weighted change, the drives at their given positions), also used to project the drift during a run;
   - the velocities projected onto the constraints with the smallest kinetic-energy change and the initial
     multipliers solved, both by a vanishingly short implicit Euler step of the system itself (an impulsive
     projection: M (z - z0) = G^T Lambda, G z = g). */
#include <phlex_impl.h>

/*@C
  PhlexAssemblyPlaceAttached - a part attached to a port (a lumped mass) given no position of its own is put on the
  port at the drawn configuration

  Collective
@*/
PetscErrorCode PhlexAssemblyPlaceAttached(PhlexSystem sys, Vec X)
{
  PetscFunctionBeginUser;
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint   j = sys->joints[k];
    PhlexPart    p = j->side[1].part, a = j->side[0].part;
    PhlexPartVec pv;
    PetscReal    x[3], R[9];
    if (PhlexPartIsGround(p) || !p->attach[0] || !p->ops.place || PhlexPartIsGround(a)) continue;
    {
      char name[PHLEX_NAME_LEN + 8];
      PetscBool same;
      PetscCall(PetscSNPrintf(name, sizeof(name), "%s_attach", p->name));
      PetscCall(PetscStrcmp(name, j->name, &same));
      if (!same) continue;
    }
    PetscCall(PhlexPartGetVec(a, X, sys->q, &pv));
    PetscCall((*a->ops.portplacement)(a, j->side[0].port, &pv, x, R));
    PetscCall(PhlexPartRestoreVec(a, X, &pv));
    PetscCall((*p->ops.place)(p, x, sys->q + p->qoff));
  }
  PetscCall(PhlexSystemScatter(sys, sys->q, X));
  PetscFunctionReturn(0);
}

/* the rows of every joint with respect to the frames' velocity unknowns: a row-major (sum nc) x nq matrix */
static PetscErrorCode RigidGradient(PhlexSystem sys, PetscInt *nrows, PetscReal **G)
{
  PetscInt n = 0;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < sys->njoints; k++) n += sys->joints[k]->nc;
  PetscCall(PetscCalloc1(PetscMax(n * sys->nq, 1), G));
  n = 0;
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PetscCall(PhlexJointRigidGradient(sys->joints[k], *G + n * sys->nq, sys->nq));
    n += sys->joints[k]->nc;
  }
  *nrows = n;
  PetscFunctionReturn(0);
}

/*@C
  PhlexAssemblyRedundancy - finds constraint components that depend on others (at the drawn configuration, for the
  rigid motion of the bodies' frames; a component that no frame motion can change is carried by elasticity and not
  checked), reports them by joint and component, and drops them when -joints_redundant drop (the others stay), or keeps
  them when -joints_redundant keep (a flexible body on each such joint takes up the over-constraint)

  Collective

  Notes:
  The rows are orthogonalised in scene order (drives and prescribed motions last): a row whose part orthogonal to
  the earlier ones is below 1e-8 of its norm is redundant. A redundant drive or prescribed motion over-constrains
  its port: always an error.
@*/
PetscErrorCode PhlexAssemblyRedundancy(PhlexSystem sys, Vec X, PetscInt *ndropped)
{
  PetscReal *G, *Q;
  PetscInt   n, nq = sys->nq, nkept = 0, *order, *jidx, *ridx, cnt = 0;
  PetscBool *redundant;
  char       report[2048] = "";

  PetscFunctionBeginUser;
  *ndropped = 0;
  PetscCall(PhlexSystemEvaluate(sys, 0.0, X, NULL));
  PetscCall(RigidGradient(sys, &n, &G));
  PetscCall(PetscMalloc5(PetscMax(n * nq, 1), &Q, PetscMax(n, 1), &order, PetscMax(n, 1), &jidx, PetscMax(n, 1), &ridx, PetscMax(n, 1), &redundant));
  /* the order: plain rows first, drives and prescribed motions last */
  for (PetscInt pass = 0; pass < 2; pass++) {
    PetscInt r = 0;
    for (PetscInt k = 0; k < sys->njoints; k++) {
      PhlexJoint j = sys->joints[k];
      for (PetscInt c = 0; c < j->nc; c++, r++) {
        const PetscBool source = (j->type == PHLEX_JOINT_PRESCRIBED || (j->drive_row >= 0 && c == j->drive_row)) ? PETSC_TRUE : PETSC_FALSE;
        if ((pass == 0) == source) continue;
        order[cnt] = r;
        jidx[cnt]  = k;
        ridx[cnt]  = c;
        cnt++;
      }
    }
  }
  for (PetscInt i = 0; i < n; i++) {
    const PetscReal *g = G + order[i] * nq;
    PetscReal        v[4096], n0 = 0, n1 = 0;
    PetscCheck(nq <= 4096, sys->comm, PETSC_ERR_SUP, "redundancy check of more than 4096 discrete unknowns");
    for (PetscInt c = 0; c < nq; c++) {
      v[c] = g[c];
      n0 += g[c] * g[c];
    }
    redundant[i] = PETSC_FALSE;
    if (n0 == 0) continue; /* carried by elasticity */
    for (PetscInt pass = 0; pass < 2; pass++) /* Gram-Schmidt twice */
      for (PetscInt l = 0; l < nkept; l++) {
        PetscReal d = 0;
        for (PetscInt c = 0; c < nq; c++) d += Q[l * nq + c] * v[c];
        for (PetscInt c = 0; c < nq; c++) v[c] -= d * Q[l * nq + c];
      }
    for (PetscInt c = 0; c < nq; c++) n1 += v[c] * v[c];
    if (n1 <= 1e-16 * n0) {
      redundant[i] = PETSC_TRUE;
      continue;
    }
    for (PetscInt c = 0; c < nq; c++) Q[nkept * nq + c] = v[c] / PetscSqrtReal(n1);
    nkept++;
  }
  for (PetscInt i = 0; i < n; i++) {
    PhlexJoint j = sys->joints[jidx[i]];
    char       item[128];
    if (!redundant[i]) continue;
    PetscCheck(!(j->type == PHLEX_JOINT_PRESCRIBED || (j->drive_row >= 0 && ridx[i] == j->drive_row)), sys->comm, PETSC_ERR_USER_INPUT, "joint %s: its prescribed motion (component %s) acts on an over-constrained port: the other joints already fix that motion", j->name, j->rowname[ridx[i]]);
    PetscCall(PetscSNPrintf(item, sizeof(item), "%sjoint %s component %s", report[0] ? ", " : "", j->name, j->rowname[ridx[i]]));
    PetscCall(PetscStrlcat(report, item, sizeof(report)));
    (*ndropped)++;
  }
  if (*ndropped && sys->scene->redundant == PHLEX_REDUNDANT_KEEP) {
    /* kept: the over-constraint goes into the elasticity of a flexible body on each such joint */
    for (PetscInt i = 0; i < n; i++) {
      PhlexJoint j = sys->joints[jidx[i]];
      if (!redundant[i]) continue;
      PetscCheck(PhlexPartIsElastic(j->side[0].part) || PhlexPartIsElastic(j->side[1].part), sys->comm, PETSC_ERR_USER_INPUT, "joint %s: its component %s is redundant for the rigid motion and neither of its bodies is flexible: -joints_redundant keep needs a flexible body to take up the over-constraint (use drop)", j->name, j->rowname[ridx[i]]);
    }
    PetscCall(PetscPrintf(sys->comm, "Redundant constraints for the rigid motion kept (-joints_redundant keep; the flexible bodies take them up): %s\n", report));
    *ndropped = 0;
  }
  if (*ndropped) {
    PetscCheck(sys->scene->redundant != PHLEX_REDUNDANT_ERROR, sys->comm, PETSC_ERR_USER_INPUT, "redundant constraints: %s depend on the other joints' constraints (for the bodies' rigid motion); remove them, use joints that constrain less (e.g. cylindrical or spherical instead of revolute), drop them with -joints_redundant drop, or keep them with -joints_redundant keep when a flexible body on each such joint takes them up", report);
    PetscCall(PetscPrintf(sys->comm, "Redundant constraints dropped (-joints_redundant drop): %s\n", report));
    /* drop from the last row of each joint backwards, so that the row indices stay valid */
    for (PetscInt i = n - 1; i >= 0; i--) {
      PhlexJoint j = sys->joints[jidx[i]];
      if (!redundant[i]) continue;
      if (j->drive_row > ridx[i]) j->drive_row--;
      PetscCall(PhlexJointDropRow(j, ridx[i]));
    }
    for (PetscInt k = 0; k < sys->njoints; k++) PetscCheck(sys->joints[k]->nc > 0 || sys->joints[k]->ne > 0, sys->comm, PETSC_ERR_USER_INPUT, "joint %s: every component is redundant: remove the joint", sys->joints[k]->name);
  }
  PetscCall(PetscFree(G));
  PetscCall(PetscFree5(Q, order, jidx, ridx, redundant));
  PetscFunctionReturn(0);
}

/* the position-level violation of every joint row at X (non-dimensional), and the largest in SI (m or rad) */
static PetscErrorCode Gaps(PhlexSystem sys, PetscReal t, Vec X, PetscReal *gap, PetscReal *gmax, PetscInt *worst)
{
  PetscInt n = 0;

  PetscFunctionBeginUser;
  *gmax  = 0.0;
  *worst = -1;
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  for (PetscInt k = 0; k < sys->njoints; k++) {
    PhlexJoint   j = sys->joints[k];
    PhlexPartVec pv[2];
    PetscCall(PhlexSystemJointSides(sys, j, X, sys->q, pv));
    PetscCall(PhlexJointGap(j, t, &pv[0], &pv[1], gap + n));
    PetscCall(PhlexSystemJointSidesRestore(sys, j, X, pv));
    for (PetscInt c = 0; c < j->nc; c++) {
      const PetscReal g = PetscAbsReal(gap[n + c]) * (j->row[c] <= PHLEX_ROW_T3 ? sys->units->length : 1.0);
      if (g > *gmax) {
        *gmax  = g;
        *worst = n + c;
      }
    }
    n += j->nc;
  }
  PetscFunctionReturn(0);
}

/* the total energy at X (non-dimensional) */
static PetscErrorCode Energy(PhlexSystem sys, PetscReal t, Vec X, PetscReal *H, PetscReal *kin)
{
  PetscReal s, v;

  PetscFunctionBeginUser;
  PetscCall(PhlexSystemEnergy(sys, t, X, kin, &s, &v));
  *H = *kin + s + v;
  PetscFunctionReturn(0);
}

/* the row, joint and component of row r of the stacked joints */
static void RowName(PhlexSystem sys, PetscInt r, PhlexJoint *j, PetscInt *c)
{
  for (PetscInt k = 0; k < sys->njoints; k++) {
    if (r < sys->joints[k]->nc) {
      *j = sys->joints[k];
      *c = r;
      return;
    }
    r -= sys->joints[k]->nc;
  }
}

/*@C
  PhlexAssemblyClose - closes the joints at position level at time t (the drives at their positions): Newton on the
  frames' positions and orientations, each step the smallest change in the metric of the frames' rigid masses;
  report: print what it did (before the first step); dH: the change of the energy (NULL: not needed)

  Collective

  Notes:
  The frames move along their velocity unknowns (v_P, w: r += R dv, R <- R exp([dw]x); a point mass r += dv), so the
  position Jacobian is the joints' velocity rows with respect to those unknowns. Components no frame motion changes
  (between held flexible bodies) keep their violation, which elasticity carries.
@*/
PetscErrorCode PhlexAssemblyClose(PhlexSystem sys, PetscReal t, Vec X, PetscBool report, PetscReal *dH)
{
  const PetscReal tol = sys->scene->assembly_tol * sys->units->length;
  PetscInt        n = 0, nq = sys->nq, it, worst, nv = 0, *vidx;
  PetscReal      *gap, g0, g, H0 = 0, H1, kin;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_Assembly, 0, 0, 0, 0));
  for (PetscInt k = 0; k < sys->njoints; k++) n += sys->joints[k]->nc;
  PetscCall(PetscMalloc2(PetscMax(n, 1), &gap, PetscMax(nq, 1), &vidx));
  /* the frames' velocity unknowns: the directions of motion */
  for (PetscInt i = 0; i < sys->nparts; i++) {
    PhlexPart p = sys->parts[i];
    if (p->frame.v >= 0)
      for (PetscInt c = 0; c < 3; c++) vidx[nv++] = p->qoff + p->frame.v + c;
    if (p->frame.w >= 0)
      for (PetscInt c = 0; c < 3; c++) vidx[nv++] = p->qoff + p->frame.w + c;
  }
  if (dH) PetscCall(Energy(sys, t, X, &H0, &kin));
  PetscCall(Gaps(sys, t, X, gap, &g0, &worst));
  g = g0;
  for (it = 0; it < sys->scene->assembly_max_it && g > tol && nv; it++) {
    PetscReal   *G, *A, *L, *z, *s, work[8192], rcond = 1e-10;
    PetscBLASInt m, nn, one = 1, lwork = 8192, info, rank, ld;
    PetscInt     nr;
    PetscCall(PhlexInterruptCheck(sys->comm, "while closing the joints' loops (the assembly's Newton iterations)"));
    PetscCall(PhlexSystemEvaluate(sys, t, X, NULL));
    PetscCall(RigidGradient(sys, &nr, &G));
    /* the mass metric: a Cholesky factor L of each frame's rigid mass; A = G_v L^{-T} */
    PetscCall(PetscCalloc4(nr * nv, &A, nv * nv, &L, PetscMax(nr, nv), &z, PetscMax(PetscMin(nr, nv), 1), &s));
    for (PetscInt i = 0, c0 = 0; i < sys->nparts; i++) {
      PhlexPart    p  = sys->parts[i];
      PetscInt     nb = (p->frame.v >= 0 ? 3 : 0) + (p->frame.w >= 0 ? 3 : 0);
      PetscReal    M[36], Mb[36];
      PetscBLASInt nbb = nb;
      if (!nb) continue;
      PetscCall((*p->ops.rigidmass)(p, M));
      for (PetscInt a = 0; a < nb; a++)
        for (PetscInt b = 0; b < nb; b++) Mb[a * nb + b] = M[a * 6 + b];
      PetscCallBLAS("LAPACKpotrf", LAPACKpotrf_("L", &nbb, Mb, &nbb, &info));
      PetscCheck(!info, sys->comm, PETSC_ERR_PLIB, "body %s: rigid mass not positive definite", p->name);
      for (PetscInt a = 0; a < nb; a++)
        for (PetscInt b = 0; b <= a; b++) L[(c0 + a) * nv + c0 + b] = Mb[b * nb + a]; /* column-major lower -> row-major */
      c0 += nb;
    }
    /* A = G_v L^{-T}: solve L X^T = G_v^T row by row (L block lower triangular, row-major) */
    for (PetscInt r = 0; r < nr; r++) {
      PetscReal *a = A + r * nv;
      for (PetscInt c = 0; c < nv; c++) a[c] = G[r * nq + vidx[c]];
      for (PetscInt c = 0; c < nv; c++) {
        for (PetscInt b = 0; b < c; b++) a[c] -= L[c * nv + b] * a[b];
        a[c] /= L[c * nv + c];
      }
    }
    /* min |z| with A z = -gap (SVD, rank-revealing: redundant rows kept under -joints_redundant keep are harmless) */
    {
      PetscReal *Ac;
      PetscCall(PetscMalloc1(nr * nv, &Ac));
      for (PetscInt r = 0; r < nr; r++)
        for (PetscInt c = 0; c < nv; c++) Ac[c * nr + r] = A[r * nv + c];
      for (PetscInt r = 0; r < nr; r++) z[r] = -gap[r];
      m  = (PetscBLASInt)nr;
      nn = (PetscBLASInt)nv;
      ld = (PetscBLASInt)PetscMax(nr, nv);
      PetscCallBLAS("LAPACKgelss", LAPACKgelss_(&m, &nn, &one, Ac, &m, z, &ld, s, &rcond, &rank, work, &lwork, &info));
      PetscCheck(!info, sys->comm, PETSC_ERR_LIB, "assembly: LAPACK gelss failed (info %d)", (int)info);
      PetscCall(PetscFree(Ac));
    }
    /* the change of the frames' positions dv = L^{-T} z (back substitution) */
    for (PetscInt c = nv - 1; c >= 0; c--) {
      for (PetscInt b = c + 1; b < nv; b++) z[c] -= L[b * nv + c] * z[b];
      z[c] /= L[c * nv + c];
    }
    PetscCall(PhlexSystemGather(sys, X, sys->q));
    for (PetscInt i = 0, c0 = 0; i < sys->nparts; i++) {
      PhlexPart  p = sys->parts[i];
      PetscReal *q = sys->q + p->qoff, d[3];
      if (p->frame.v >= 0) {
        if (p->frame.R >= 0) PhlexMatVec3(q + p->frame.R, z + c0, d);
        else
          for (PetscInt c = 0; c < 3; c++) d[c] = z[c0 + c];
        for (PetscInt c = 0; c < 3; c++) q[p->frame.r + c] += d[c];
        c0 += 3;
      }
      if (p->frame.w >= 0) {
        PhlexRotationUpdate(q + p->frame.R, z + c0);
        c0 += 3;
      }
    }
    PetscCall(PhlexSystemScatter(sys, sys->q, X));
    PetscCall(PetscFree4(A, L, z, s));
    PetscCall(PetscFree(G));
    PetscCall(Gaps(sys, t, X, gap, &g, &worst));
  }
  if (g > tol) {
    PhlexJoint j = NULL;
    PetscInt   c = 0;
    RowName(sys, worst, &j, &c);
    SETERRQ(sys->comm, PETSC_ERR_USER_INPUT, "the assembly cannot close: joint %s component %s is still violated by %.3e (m or rad) after %" PetscInt_FMT " Newton iterations (start %.3e); check the bodies' positions and orientations, the ports joined and the drives' initial values", j->name, j->rowname[c], (double)g, it, (double)g0);
  }
  if (dH) {
    PetscCall(Energy(sys, t, X, &H1, &kin));
    *dH = H1 - H0;
  }
  if (report) {
    if (it) PetscCall(PetscPrintf(sys->comm, "Assembly: the joints closed in %" PetscInt_FMT " Newton iteration%s, largest violation %.3e -> %.3e (m or rad)\n", it, it == 1 ? "" : "s", (double)g0, (double)g));
    else PetscCall(PetscPrintf(sys->comm, "Assembly: the joints are closed as drawn (largest violation %.3e, m or rad)\n", (double)g0));
  }
  PetscCall(PetscFree2(gap, vidx));
  PetscCall(PetscLogEventEnd(PHLEX_Assembly, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/* the residual and Jacobian of a vanishingly short implicit Euler step from X0: F(t0 + eps, Y, (Y - X0)/eps) */
typedef struct {
  PhlexSystem sys;
  Vec         X0, Ydot;
  PetscReal   t, eps;
} ShortStep;

static PetscErrorCode ShortStepFunction(SNES snes, Vec Y, Vec F, void *ctx)
{
  ShortStep *c = (ShortStep *)ctx;

  PetscFunctionBeginUser;
  PetscCall(VecWAXPY(c->Ydot, -1.0, c->X0, Y));
  PetscCall(VecScale(c->Ydot, 1.0 / c->eps));
  PetscCall(PhlexSystemIFunction(NULL, c->t, Y, c->Ydot, F, c->sys));
  PetscFunctionReturn(0);
}

static PetscErrorCode ShortStepJacobian(SNES snes, Vec Y, Mat A, Mat P, void *ctx)
{
  ShortStep *c = (ShortStep *)ctx;

  PetscFunctionBeginUser;
  PetscCall(VecWAXPY(c->Ydot, -1.0, c->X0, Y));
  PetscCall(VecScale(c->Ydot, 1.0 / c->eps));
  PetscCall(PhlexSystemIJacobian(NULL, c->t, Y, c->Ydot, 1.0 / c->eps, A, P, c->sys));
  PetscFunctionReturn(0);
}

/* the consistent start's Newton iterations: a clean stop on SIGINT/SIGTERM (issue 43 item 1) */
static PetscErrorCode ConsistentStartMonitor(SNES snes, PetscInt it, PetscReal fnorm, void *ctx)
{
  char where[96];

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(where, sizeof(where), "in the consistent start (Newton iteration %" PetscInt_FMT ")", it));
  PetscCall(PhlexInterruptCheck(PetscObjectComm((PetscObject)snes), where));
  PetscFunctionReturn(0);
}

/*@C
  PhlexAssemblyConsistentStart - projects the initial velocities onto the constraints (the smallest change of the
  kinetic energy) when they violate them, and solves the initial multipliers lambda0 (non-dimensional, per discrete
  unknown, zero but for the impulses)

  Collective

  Notes:
  Both come from implicit Euler steps of length eps = 1e-6 dt with the solver of the time steps (SNES phlexreduced,
  these steps as stages without a TS, when it solves the time steps; else Newton on the whole state with the preset's
  field split): from X0, M (z - z0) =
  eps f + G^T Lambda, G(q) z = g, so as eps -> 0 the step is the impulsive projection z - z0 = M^{-1} G^T Lambda,
  the smallest M-norm change that satisfies the constraints; the configuration and the stress are kept. A second
  step from the projected state gives lambda0 = Lambda(eps)/eps.
@*/
PetscErrorCode PhlexAssemblyConsistentStart(PhlexSystem sys, TS ts, PetscReal t0, PetscReal dt, Vec X, PetscReal *lambda0)
{
  const PhlexUnits *u = sys->units;
  SNES              snes;
  ShortStep         c;
  Vec               Y, F;
  PetscReal         cmax = 0, zmax = 0, H0, K0, H1, K1;
  PetscBool         impulses = PETSC_FALSE, reduced;

  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < sys->nq; k++)
    if (PhlexDofIsImpulse(sys->qkind[k])) impulses = PETSC_TRUE; /* the forces of force elements are solved too */
  if (!impulses) PetscFunctionReturn(0);
  PetscCall(PetscLogEventBegin(PHLEX_Assembly, 0, 0, 0, 0));
  c.sys = sys;
  c.t   = t0 + 1e-6 * dt;
  c.eps = 1e-6 * dt;
  PetscCall(VecDuplicate(X, &c.X0));
  PetscCall(VecDuplicate(X, &c.Ydot));
  PetscCall(VecDuplicate(X, &Y));
  PetscCall(VecDuplicate(X, &F));
  /* the constraint residual of the initial velocities, and their scale */
  PetscCall(VecSet(c.Ydot, 0.0));
  PetscCall(PhlexSystemIFunction(NULL, t0, X, c.Ydot, F, sys));
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_IMPULSE) cmax = PetscMax(cmax, PetscAbsReal(sys->fq[k]));
  PetscCall(PhlexSystemGather(sys, X, sys->q));
  for (PetscInt k = 0; k < sys->nq; k++)
    if (sys->qkind[k] == PHLEX_DOF_VELOCITY || sys->qkind[k] == PHLEX_DOF_ELASTIC_VELOCITY) zmax = PetscMax(zmax, PetscAbsReal(sys->q[k]));
  if (sys->nfparts) {
    Vec       v;
    PetscReal vmax;
    PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
    PetscCall(VecNorm(v, NORM_INFINITY, &vmax));
    PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &v));
    zmax = PetscMax(zmax, vmax);
  }

  PetscCall(SNESCreate(sys->comm, &snes));
  PetscCall(SNESSetDM(snes, sys->dm_aux));
  PetscCall(SNESSetFunction(snes, F, ShortStepFunction, &c));
  PetscCall(SNESSetTolerances(snes, 1e-50, 1e-12, 0.0, 20, PETSC_DEFAULT));
  {
    SNESLineSearch ls;
    /* full Newton steps: a line search cannot improve on the residual's round-off floor */
    PetscCall(SNESGetLineSearch(snes, &ls));
    PetscCall(SNESLineSearchSetType(ls, SNESLINESEARCHBASIC));
  }
  PetscCall(SNESSetFromOptions(snes));
  {
    /* the solver of the steps solves the start: SNES phlexreduced takes these steps as stages without a TS */
    SNES tsnes;
    PetscCall(TSGetSNES(ts, &tsnes));
    PetscCall(PetscObjectTypeCompare((PetscObject)tsnes, "phlexreduced", &reduced));
    if (reduced) PetscCall(PetscObjectTypeCompare((PetscObject)snes, "phlexreduced", &reduced));
  }
  if (reduced) {
    /* Newton on the velocities and the discrete unknowns (KSP reduced_, the steps' options), displacement and stress
       eliminated; the whole state's Jacobian is not needed */
    PetscCall(PhlexSNESReducedSetStage(snes, sys, c.X0, t0, c.eps, 1.0));
  } else {
    KSP  ksp;
    Mat  P;
    PetscBool stage;
    /* Newton on the whole state with the preset's field split, as the steps (SNES phlexcondensed solves theta-method
       stages of fixed bodies only) */
    PetscCall(PhlexSystemCompleteJacobian(sys));
    PetscCall(PetscObjectTypeCompareAny((PetscObject)snes, &stage, "phlexcondensed", "phlexreduced", ""));
    if (stage) {
      SNESLineSearch ls;
      PetscCall(SNESSetType(snes, SNESNEWTONLS));
      PetscCall(SNESGetKSP(snes, &ksp));
      PetscCall(KSPSetFromOptions(ksp));
      PetscCall(SNESGetLineSearch(snes, &ls));
      PetscCall(SNESLineSearchSetType(ls, SNESLINESEARCHBASIC));
      PetscCall(SNESLineSearchSetFromOptions(ls));
    }
    /* with -phlex_jacobian_aij the assembled Jacobian, but a field split takes its blocks from the nested one */
    PetscCall(SNESGetKSP(snes, &ksp));
    PetscCall(PhlexSystemJacobianPmat(sys, ksp, &P));
    PetscCall(SNESSetJacobian(snes, sys->use_aij ? sys->Jaij : sys->J, P, ShortStepJacobian, &c));
  }
  PetscCall(SNESSetConvergenceTest(snes, PhlexSystemSNESConverged, sys, NULL));
  PetscCall(SNESMonitorSet(snes, ConsistentStartMonitor, NULL, NULL)); /* SIGINT/SIGTERM stop it at a Newton iteration */

  PetscCall(Energy(sys, t0, X, &H0, &K0));
  if (cmax > 1e-12 * PetscMax(zmax, 1e-300)) {
    /* the impulsive projection: keep the configuration and the stress, take the velocities */
    SNESConvergedReason reason;
    PetscCall(VecCopy(X, c.X0));
    PetscCall(VecCopy(X, Y));
    PetscCall(SNESSolve(snes, NULL, Y));
    PetscCall(SNESGetConvergedReason(snes, &reason));
    PetscCheck(reason > 0, sys->comm, PETSC_ERR_NOT_CONVERGED, "consistent start: the projection of the initial velocities onto the constraints did not converge (SNES reason %s)", SNESConvergedReasons[reason]);
    if (sys->nfparts) {
      Vec a, b;
      PetscCall(VecGetSubVector(Y, sys->is[PHLEX_FIELD_VELOCITY], &a));
      PetscCall(VecGetSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &b));
      PetscCall(VecCopy(a, b));
      PetscCall(VecRestoreSubVector(Y, sys->is[PHLEX_FIELD_VELOCITY], &a));
      PetscCall(VecRestoreSubVector(X, sys->is[PHLEX_FIELD_VELOCITY], &b));
    }
    {
      PetscReal *qy;
      PetscCall(PetscMalloc1(sys->nq, &qy));
      PetscCall(PhlexSystemGather(sys, Y, qy));
      PetscCall(PhlexSystemGather(sys, X, sys->q));
      for (PetscInt k = 0; k < sys->nq; k++)
        if (sys->qkind[k] == PHLEX_DOF_VELOCITY || sys->qkind[k] == PHLEX_DOF_ELASTIC_VELOCITY) sys->q[k] = qy[k]; /* frames' and elastic velocities */
      PetscCall(PhlexSystemScatter(sys, sys->q, X));
      PetscCall(PetscFree(qy));
    }
    PetscCall(Energy(sys, t0, X, &H1, &K1));
    PetscCall(PetscPrintf(sys->comm, "Consistent start: initial velocities projected onto the constraints (residual %.3e m/s or rad/s), kinetic energy %.6e -> %.6e J\n", (double)(cmax * u->velocity), (double)(K0 * u->energy), (double)(K1 * u->energy)));
  } else PetscCall(PetscPrintf(sys->comm, "Consistent start: the initial velocities satisfy the constraints\n"));
  /* the initial multipliers */
  {
    SNESConvergedReason reason;
    PetscReal          *q0;
    PetscCall(VecCopy(X, c.X0));
    PetscCall(VecCopy(X, Y));
    PetscCall(SNESSolve(snes, NULL, Y));
    PetscCall(SNESGetConvergedReason(snes, &reason));
    PetscCheck(reason > 0, sys->comm, PETSC_ERR_NOT_CONVERGED, "consistent start: the initial multipliers could not be solved (SNES reason %s)", SNESConvergedReasons[reason]);
    PetscCall(PetscMalloc1(sys->nq, &q0));
    PetscCall(PhlexSystemGather(sys, X, q0));
    PetscCall(PhlexSystemGather(sys, Y, sys->q));
    for (PetscInt k = 0; k < sys->nq; k++) lambda0[k] = PhlexDofIsImpulse(sys->qkind[k]) ? (sys->q[k] - q0[k]) / (c.eps / u->time) : 0.0;
    PetscCall(PetscFree(q0));
  }
  PetscCall(SNESDestroy(&snes));
  PetscCall(VecDestroy(&c.X0));
  PetscCall(VecDestroy(&c.Ydot));
  PetscCall(VecDestroy(&Y));
  PetscCall(VecDestroy(&F));
  PetscCall(PetscLogEventEnd(PHLEX_Assembly, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}
