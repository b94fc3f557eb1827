/* The linearised analysis with force elements and damping (issue 45): the elements eliminated onto the velocities,
   and the quadratic eigenproblem of a damped assembly.

   A force element's rows about rest (joint.h), at the Laplace variable s, with F its force impulses and e its states:
       E_FF s F + A_FE e + A_FV V = 0          (lambda = s F = -(K e + C S^T V))
       E_EE s e + A_EV V = 0                   (e' = S^T V)
   and the velocity rows take its force as a multiplier's, B_VF s F (B_VF = E part of the velocity rows in F's
   columns). Eliminating e = -E_EE^{-1} A_EV V / s and s F, the velocity rows multiplied by s (as the stress's and the
   elastic coordinates' eliminations are) gain
       K_el = B_VF E_FF^{-1} A_FE E_EE^{-1} A_EV     (the springs: B K B^T, symmetric positive semi-definite)
       R_el = -B_VF E_FF^{-1} A_FV                   (the dampers: B C B^T)
   on every velocity the elements' ports move: field and discrete. Everything is read from the system's own Jacobian
   (its E and A parts), nothing of the element's equations is written twice; the symmetry that the power-preserving
   interconnection gives is checked.

   With damping (the bodies' R, a reduced body's modal damping, the elements' C) the pencil is quadratic,
       (A0 + lambda A1 + lambda^2 A2) x = 0,   A0 = the saddle point of K,  A1 = R (+ Coriolis),  A2 = diag(M, 0),
   solved by SLEPc's TOAR with shift-and-invert; a mode is lambda = -zeta w +- i w sqrt(1 - zeta^2): its undamped
   pulsation w = |lambda|, its damping ratio zeta = -Re(lambda) / |lambda|; an overdamped motion is a real lambda < 0. */
#include <phlex_impl.h>
#include <private/linearized.h>

/* the elements' dense algebra on the discrete unknowns: M1 = E_FF^{-1} A_FE E_EE^{-1}, M2 = -E_FF^{-1} (nel x nel,
   row-major), the discrete velocities' columns W_K = M1 A_EV, W_C = M2 A_FV (nel x nqv) and B_VF (nqv x nel) */
static PetscErrorCode ElementAlgebra(Pencil *p, const PetscReal *DE, const PetscReal *DA, PetscReal *M1, PetscReal *M2, PetscReal *WK, PetscReal *WC, PetscReal *BVF)
{
  PhlexSystem    sys = p->sys;
  const PetscInt nq = sys->nq, nel = p->nel, nqv = p->nqv;
  PetscReal     *Ef, *Ee, *X, emax = 0, worst = 0;
  PetscBLASInt   n, nrhs, info, *piv, *piv2;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc5(nel * nel, &Ef, nel * nel, &Ee, nel * nel, &X, nel, &piv, nel, &piv2));
  /* column-major copies for LAPACK: Ef = E_FF, Ee = E_EE; X = A_FE */
  for (PetscInt a = 0; a < nel; a++)
    for (PetscInt b = 0; b < nel; b++) {
      Ef[b * nel + a] = DE[p->elF[a] * nq + p->elF[b]];
      Ee[b * nel + a] = DE[p->elE[a] * nq + p->elE[b]];
      X[b * nel + a]  = DA[p->elF[a] * nq + p->elE[b]];
      emax            = PetscMax(emax, PetscAbsReal(Ef[b * nel + a]));
    }
  /* the element rows have nothing else among the element unknowns and the configuration: no A part in F's columns,
     no E part outside their own block, no A part of the states in the elements' columns */
  for (PetscInt a = 0; a < nel; a++)
    for (PetscInt j = 0; j < nq; j++) {
      const PetscInt f = p->elF[a], e = p->elE[a];
      PetscBool      own_f = PETSC_FALSE, own_e = PETSC_FALSE;
      for (PetscInt b = 0; b < nel; b++) own_f = (PetscBool)(own_f || j == p->elF[b]), own_e = (PetscBool)(own_e || j == p->elE[b]);
      if (!own_f) worst = PetscMax(worst, PetscAbsReal(DE[f * nq + j]));
      if (!own_e) worst = PetscMax(worst, PetscAbsReal(DE[e * nq + j]));
      if (own_f || own_e) worst = PetscMax(worst, PetscAbsReal(DA[e * nq + j]));
      if (own_f) worst = PetscMax(worst, PetscAbsReal(DA[f * nq + j]));
      if (!own_f && !own_e && p->qmap[j] < 0) worst = PetscMax(worst, PetscAbsReal(DA[f * nq + j]) + PetscAbsReal(DA[e * nq + j]));
      if (p->qmap[j] >= p->nqv) worst = PetscMax(worst, PetscAbsReal(DA[f * nq + j]) + PetscAbsReal(DA[e * nq + j]));
    }
  PetscCheck(worst <= 1e-10 * PetscMax(emax, p->scale), sys->comm, PETSC_ERR_USER_INPUT, "linearized analysis: a force element's rows are not those of a spring-damper at rest (a term of relative size %g): the configuration is loaded or moving", (double)(worst / PetscMax(emax, p->scale)));
  PetscCall(PetscBLASIntCast(nel, &n));
  nrhs = n;
  /* X = E_FF^{-1} A_FE, then M1 = X E_EE^{-1}: M1^T = E_EE^{-T} X^T */
  PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&n, &nrhs, Ef, &n, piv, X, &n, &info));
  PetscCheck(!info, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the force elements' rate block is singular (LAPACK gesv info %d)", (int)info);
  {
    PetscReal *Et, *Xt;
    PetscCall(PetscMalloc2(nel * nel, &Et, nel * nel, &Xt));
    for (PetscInt a = 0; a < nel; a++)
      for (PetscInt b = 0; b < nel; b++) Et[b * nel + a] = Ee[a * nel + b], Xt[b * nel + a] = X[a * nel + b];
    PetscCallBLAS("LAPACKgesv", LAPACKgesv_(&n, &nrhs, Et, &n, piv2, Xt, &n, &info)); /* piv keeps E_FF's pivots for getrs below */
    PetscCheck(!info, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the force elements' state block is singular (LAPACK gesv info %d)", (int)info);
    /* Xt (column-major) = M1^T: M1[a][b] = Xt[a * nel + b] */
    for (PetscInt a = 0; a < nel; a++)
      for (PetscInt b = 0; b < nel; b++) M1[a * nel + b] = Xt[a * nel + b];
    PetscCall(PetscFree2(Et, Xt));
  }
  /* M2 = -E_FF^{-1}: Ef holds its LU */
  for (PetscInt a = 0; a < nel; a++)
    for (PetscInt b = 0; b < nel; b++) X[b * nel + a] = a == b ? -1.0 : 0.0;
  PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &n, &nrhs, Ef, &n, piv, X, &n, &info));
  PetscCheck(!info, sys->comm, PETSC_ERR_PLIB, "LAPACK getrs failed (%d)", (int)info);
  for (PetscInt a = 0; a < nel; a++)
    for (PetscInt b = 0; b < nel; b++) M2[a * nel + b] = X[b * nel + a];
  for (PetscInt a = 0; a < nel; a++)
    for (PetscInt jj = 0; jj < nqv; jj++) {
      PetscReal k = 0, c = 0;
      for (PetscInt b = 0; b < nel; b++) {
        k += M1[a * nel + b] * DA[p->elE[b] * nq + p->Qq[jj]];
        c += M2[a * nel + b] * DA[p->elF[b] * nq + p->Qq[jj]];
      }
      WK[a * nqv + jj] = k, WC[a * nqv + jj] = c;
    }
  for (PetscInt ii = 0; ii < nqv; ii++)
    for (PetscInt a = 0; a < nel; a++) BVF[ii * nel + a] = DE[p->Qq[ii] * nq + p->elF[a]];
  PetscCall(PetscFree5(Ef, Ee, X, piv, piv2));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLinearizedElementDiscreteStiffness - the force elements' stiffness among the discrete velocities, K_dd = B_VF
  W_K (nqv x nqv, row-major, replicated): the springs that hold a mechanism's frames (its mechanism modes)

  Not collective
@*/
PetscErrorCode PhlexLinearizedElementDiscreteStiffness(Pencil *p, const PetscReal *DE, const PetscReal *DA, PetscReal *Kdd)
{
  const PetscInt nel = p->nel, nqv = p->nqv;
  PetscReal     *M1, *M2, *WKd, *WCd, *BVd;

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc5(nel * nel, &M1, nel * nel, &M2, PetscMax(nel * nqv, 1), &WKd, PetscMax(nel * nqv, 1), &WCd, PetscMax(nqv * nel, 1), &BVd));
  PetscCall(ElementAlgebra(p, DE, DA, M1, M2, WKd, WCd, BVd));
  for (PetscInt ii = 0; ii < nqv; ii++)
    for (PetscInt jj = 0; jj < nqv; jj++) {
      PetscReal k = 0;
      for (PetscInt a = 0; a < nel; a++) k += BVd[ii * nel + a] * WKd[a * nqv + jj];
      Kdd[ii * nqv + jj] = k;
    }
  PetscCall(PetscFree5(M1, M2, WKd, WCd, BVd));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLinearizedElementOperators - the force elements' stiffness K_el and damping R_el on the pencil's unknowns (AIJ,
  the pencil's layout: field velocities and Q), eliminated from the Jacobian's parts DE, DA (discrete block, replicated),
  BE (the field rows' E part in the discrete columns, dense, local rows) and p->elrows (the elements' rows on the field)

  Collective
@*/
PetscErrorCode PhlexLinearizedElementOperators(Pencil *p, const PetscReal *DE, const PetscReal *DA, Mat BE, Mat *Kel, Mat *Rel)
{
  PhlexSystem        sys = p->sys;
  const PetscInt     nel = p->nel, nqv = p->nqv, nq = sys->nq;
  PetscReal         *M1, *M2, *WKd, *WCd, *BVd, *sendbuf = NULL, *recvbuf = NULL;
  PetscInt           nvl = 0, Ql, nsend = 0, nrecv = 0, *qpen;
  PetscMPIInt        rank, size, *counts = NULL, *displs = NULL;
  const PetscInt    *vpen = NULL;
  const PetscScalar *be = NULL;
  PetscInt           ld = 0;
  Vec               *WKf = NULL, *WCf = NULL;
  const PetscInt     stride = 1 + 2 * nel; /* a gathered field column: its pencil index, W_K's and W_C's values */

  PetscFunctionBeginUser;
  PetscCall(PhlexLinearizedPencilPhase(p, "the force elements' rows", 0.0));
  PetscCallMPI(MPI_Comm_rank(sys->comm, &rank));
  PetscCallMPI(MPI_Comm_size(sys->comm, &size));
  PetscCall(PetscMalloc5(nel * nel, &M1, nel * nel, &M2, PetscMax(nel * nqv, 1), &WKd, PetscMax(nel * nqv, 1), &WCd, PetscMax(nqv * nel, 1), &BVd));
  PetscCall(ElementAlgebra(p, DE, DA, M1, M2, WKd, WCd, BVd));
  /* the pencil's numbering of Q (rank 0's) on every rank */
  PetscCall(PetscMalloc1(PetscMax(p->nQ, 1), &qpen));
  if (rank == 0) {
    const PetscInt *iq;
    PetscCall(ISGetIndices(p->isQ, &iq));
    for (PetscInt k = 0; k < p->nQ; k++) qpen[k] = iq[k];
    PetscCall(ISRestoreIndices(p->isQ, &iq));
  }
  PetscCallMPI(MPI_Bcast(qpen, (PetscMPIInt)p->nQ, MPIU_INT, 0, sys->comm));
  Ql = rank == 0 ? p->nQ : 0;
  if (p->isV) {
    PetscCall(ISGetLocalSize(p->isV, &nvl));
    PetscCall(ISGetIndices(p->isV, &vpen));
  }
  if (p->elrows) {
    /* the field columns W_K = M1 A_EV, W_C = M2 A_FV; their non-zero columns gathered on every rank */
    const PetscScalar **wk, **wc;
    PetscCall(PetscMalloc2(nel, &WKf, nel, &WCf));
    PetscCall(PetscMalloc2(nel, &wk, nel, &wc));
    for (PetscInt a = 0; a < nel; a++) {
      PetscCall(VecDuplicate(p->elrows[0], &WKf[a]));
      PetscCall(VecDuplicate(p->elrows[0], &WCf[a]));
      PetscCall(VecSet(WKf[a], 0.0));
      PetscCall(VecSet(WCf[a], 0.0));
      for (PetscInt b = 0; b < nel; b++) {
        PetscCall(VecAXPY(WKf[a], M1[a * nel + b], p->elrows[nel + b]));
        PetscCall(VecAXPY(WCf[a], M2[a * nel + b], p->elrows[b]));
      }
      PetscCall(VecGetArrayRead(WKf[a], &wk[a]));
      PetscCall(VecGetArrayRead(WCf[a], &wc[a]));
    }
    PetscCall(PetscMalloc1(stride * PetscMax(nvl, 1), &sendbuf));
    for (PetscInt r = 0; r < nvl; r++) {
      PetscBool nz = PETSC_FALSE;
      for (PetscInt a = 0; a < nel; a++) nz = (PetscBool)(nz || wk[a][r] != 0.0 || wc[a][r] != 0.0);
      if (!nz) continue;
      sendbuf[stride * nsend] = (PetscReal)vpen[r];
      for (PetscInt a = 0; a < nel; a++) sendbuf[stride * nsend + 1 + a] = PetscRealPart(wk[a][r]), sendbuf[stride * nsend + 1 + nel + a] = PetscRealPart(wc[a][r]);
      nsend++;
    }
    for (PetscInt a = 0; a < nel; a++) {
      PetscCall(VecRestoreArrayRead(WKf[a], &wk[a]));
      PetscCall(VecRestoreArrayRead(WCf[a], &wc[a]));
    }
    PetscCall(PetscFree2(wk, wc));
    PetscCall(PhlexLinearizedPencilPhase(p, "the force elements' rows", 0.5));
    PetscCall(PetscMalloc2(size, &counts, size, &displs));
    {
      PetscMPIInt mine = (PetscMPIInt)(stride * nsend);
      PetscCallMPI(MPI_Allgather(&mine, 1, MPI_INT, counts, 1, MPI_INT, sys->comm));
    }
    for (PetscMPIInt r = 0; r < size; r++) displs[r] = r ? displs[r - 1] + counts[r - 1] : 0, nrecv += counts[r];
    PetscCall(PetscMalloc1(PetscMax(nrecv, 1), &recvbuf));
    PetscCallMPI(MPI_Allgatherv(sendbuf, (PetscMPIInt)(stride * nsend), MPIU_REAL, recvbuf, counts, displs, MPIU_REAL, sys->comm));
    nrecv /= stride;
  }
  if (BE) {
    PetscCall(MatDenseGetLDA(BE, &ld));
    PetscCall(MatDenseGetArrayRead(BE, &be));
  }
  {
    /* local rows: the field's, then rank 0's Q */
    Mat       Op[2];
    PetscInt *nnz, nlocal = nvl + Ql, ncols = 0;
    /* room only in the rows the elements' forces reach (B_VF non-zero): the gathered field columns and Q's velocities */
    PetscCall(MPIU_Allreduce(&nlocal, &ncols, 1, MPIU_INT, MPI_SUM, sys->comm));
    PetscCall(PetscCalloc1(PetscMax(nlocal, 1), &nnz));
    for (PetscInt r = 0; r < nvl; r++)
      for (PetscInt a = 0; a < nel; a++)
        if (be[p->elF[a] * ld + r] != 0.0) nnz[r] = PetscMin(nrecv + nqv, ncols);
    for (PetscInt ii = 0; ii < Ql && ii < nqv; ii++)
      for (PetscInt a = 0; a < nel; a++)
        if (BVd[ii * nel + a] != 0.0) nnz[nvl + ii] = PetscMin(nrecv + nqv, ncols);
    {
      /* split between the diagonal block (local columns) and the rest, each at most its width */
      PetscInt *dnz, *onz;
      PetscCall(PetscMalloc2(PetscMax(nlocal, 1), &dnz, PetscMax(nlocal, 1), &onz));
      for (PetscInt r = 0; r < nlocal; r++) dnz[r] = PetscMin(nnz[r], nlocal), onz[r] = PetscMin(nnz[r], ncols - nlocal);
      for (PetscInt m = 0; m < 2; m++) {
        PetscCall(MatCreate(sys->comm, &Op[m]));
        PetscCall(MatSetSizes(Op[m], nlocal, nlocal, PETSC_DETERMINE, PETSC_DETERMINE));
        PetscCall(MatSetType(Op[m], MATAIJ));
        PetscCall(MatSeqAIJSetPreallocation(Op[m], 0, dnz));
        PetscCall(MatMPIAIJSetPreallocation(Op[m], 0, dnz, 0, onz));
        PetscCall(MatSetOption(Op[m], MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
      }
      PetscCall(PetscFree2(dnz, onz));
    }
    PetscCall(PetscFree(nnz));
    /* a field row: only those the elements' forces reach (B_VF non-zero) */
    for (PetscInt r = 0; r < nvl; r++) {
      const PetscScalar *b = be;
      PetscBool          nz = PETSC_FALSE;
      for (PetscInt a = 0; a < nel; a++) nz = (PetscBool)(nz || b[p->elF[a] * ld + r] != 0.0);
      if (!nz) continue;
      for (PetscInt c = 0; c < nrecv; c++) {
        PetscReal k = 0, d = 0;
        for (PetscInt a = 0; a < nel; a++) {
          const PetscReal bv = PetscRealPart(b[p->elF[a] * ld + r]);
          k += bv * recvbuf[stride * c + 1 + a];
          d += bv * recvbuf[stride * c + 1 + nel + a];
        }
        PetscCall(MatSetValue(Op[0], vpen[r], (PetscInt)recvbuf[stride * c], k, INSERT_VALUES));
        PetscCall(MatSetValue(Op[1], vpen[r], (PetscInt)recvbuf[stride * c], d, INSERT_VALUES));
      }
      for (PetscInt jj = 0; jj < nqv; jj++) {
        PetscReal k = 0, d = 0;
        for (PetscInt a = 0; a < nel; a++) {
          const PetscReal bv = PetscRealPart(b[p->elF[a] * ld + r]);
          k += bv * WKd[a * nqv + jj];
          d += bv * WCd[a * nqv + jj];
        }
        PetscCall(MatSetValue(Op[0], vpen[r], qpen[jj], k, INSERT_VALUES));
        PetscCall(MatSetValue(Op[1], vpen[r], qpen[jj], d, INSERT_VALUES));
      }
    }
    /* the discrete velocities' rows (rank 0) */
    if (rank == 0)
      for (PetscInt ii = 0; ii < nqv; ii++) {
        PetscBool nz = PETSC_FALSE;
        for (PetscInt a = 0; a < nel; a++) nz = (PetscBool)(nz || BVd[ii * nel + a] != 0.0);
        if (!nz) continue;
        for (PetscInt c = 0; c < nrecv; c++) {
          PetscReal k = 0, d = 0;
          for (PetscInt a = 0; a < nel; a++) k += BVd[ii * nel + a] * recvbuf[stride * c + 1 + a], d += BVd[ii * nel + a] * recvbuf[stride * c + 1 + nel + a];
          PetscCall(MatSetValue(Op[0], qpen[ii], (PetscInt)recvbuf[stride * c], k, INSERT_VALUES));
          PetscCall(MatSetValue(Op[1], qpen[ii], (PetscInt)recvbuf[stride * c], d, INSERT_VALUES));
        }
        for (PetscInt jj = 0; jj < nqv; jj++) {
          PetscReal k = 0, d = 0;
          for (PetscInt a = 0; a < nel; a++) k += BVd[ii * nel + a] * WKd[a * nqv + jj], d += BVd[ii * nel + a] * WCd[a * nqv + jj];
          PetscCall(MatSetValue(Op[0], qpen[ii], qpen[jj], k, INSERT_VALUES));
          PetscCall(MatSetValue(Op[1], qpen[ii], qpen[jj], d, INSERT_VALUES));
        }
      }
    for (PetscInt m = 0; m < 2; m++) {
      PetscCall(MatAssemblyBegin(Op[m], MAT_FINAL_ASSEMBLY));
      PetscCall(MatAssemblyEnd(Op[m], MAT_FINAL_ASSEMBLY));
    }
    /* the power-preserving interconnection makes both symmetric (B K B^T, B C B^T): checked */
    for (PetscInt m = 0; m < 2; m++) {
      Mat       T;
      PetscReal nrm, dev;
      PetscCall(MatTranspose(Op[m], MAT_INITIAL_MATRIX, &T));
      PetscCall(MatAXPY(T, -1.0, Op[m], DIFFERENT_NONZERO_PATTERN));
      PetscCall(MatNorm(T, NORM_FROBENIUS, &dev));
      PetscCall(MatNorm(Op[m], NORM_FROBENIUS, &nrm));
      PetscCall(MatDestroy(&T));
      PetscCheck(dev <= 1e-9 * nrm, sys->comm, PETSC_ERR_PLIB, "linearized analysis: the force elements' %s on the velocities is not symmetric (relative deviation %g): an element breaks the power-preserving interconnection", m ? "damping" : "stiffness", (double)(dev / nrm));
      PetscCall(MatSetOption(Op[m], MAT_SYMMETRIC, PETSC_TRUE));
    }
    *Kel = Op[0], *Rel = Op[1];
  }
  (void)nq;
  if (BE) PetscCall(MatDenseRestoreArrayRead(BE, &be));
  if (p->isV) PetscCall(ISRestoreIndices(p->isV, &vpen));
  for (PetscInt a = 0; WKf && a < nel; a++) {
    PetscCall(VecDestroy(&WKf[a]));
    PetscCall(VecDestroy(&WCf[a]));
  }
  if (WKf) PetscCall(PetscFree2(WKf, WCf));
  PetscCall(PetscFree(sendbuf));
  PetscCall(PetscFree(recvbuf));
  PetscCall(PetscFree2(counts, displs));
  PetscCall(PetscFree(qpen));
  PetscCall(PetscFree5(M1, M2, WKd, WCd, BVd));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLinearizedSolveDamped - the lowest nev modes of the damped pencil (A0 + lambda A1 + lambda^2 A2) x = 0, ascending
  in their undamped pulsation |lambda|: one of each conjugate pair, each real lambda (an overdamped motion) on its own;
  the zero eigenvalues of the mechanism modes (free motions: lambda = 0, nzero of them, double where nothing damps
  them) left out: those below zero_tol (computed, they carry errors of sqrt(tolerance); defective ones may be
  missing or come with spurious copies)

  Collective
@*/
PetscErrorCode PhlexLinearizedSolveDamped(Pencil *p, PEP pep, PetscInt nev, PetscInt nmech, PetscInt nzero, PetscReal zero_tol, PetscBool vectors, Spectrum *s)
{
  Mat        A[3] = {p->A, p->A1, p->B};
  PetscInt   nconv, n = 0;
  Vec        xr, xi;
  PetscReal *mag, *re, *im, *res, lmax = 0;
  PetscInt  *perm, *keep;
  PetscBool  given;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscCall(PEPSetOperators(pep, 3, A));
  /* a conjugate pair per mode and the zero eigenvalues */
  PetscCall(PEPSetDimensions(pep, 2 * nev + nzero, PETSC_DEFAULT, PETSC_DEFAULT));
  /* the target: 0, unless one is given; where the mechanism moves (A0 singular at 0) the caller has set it */
  PetscCall(PetscOptionsHasName(NULL, "linearized_", "-pep_target", &given));
  if (!given && !nmech) PetscCall(PEPSetTarget(pep, 0.0));
  PetscCall(PhlexProgressPEPSolve(pep, "the damped linearized assembly"));
  PetscCall(PEPGetConverged(pep, &nconv));
  PetscCall(PetscMalloc6(nconv, &mag, nconv, &re, nconv, &im, nconv, &res, nconv, &perm, nconv, &keep));
  PetscCall(MatCreateVecs(p->A, &xr, NULL));
  PetscCall(VecDuplicate(xr, &xi));
  for (PetscInt i = 0; i < nconv; i++) {
    PetscScalar kr, ki;
    PetscCall(PEPGetEigenpair(pep, i, &kr, &ki, NULL, NULL));
    re[i] = PetscRealPart(kr), im[i] = PetscRealPart(ki), mag[i] = PetscSqrtReal(re[i] * re[i] + im[i] * im[i]), perm[i] = i;
    lmax = PetscMax(lmax, mag[i]);
  }
  PetscCall(PetscSortRealWithPermutation(nconv, mag, perm));
  for (PetscInt k = 0; k < nconv; k++) {
    const PetscInt i = perm[k];
    if (mag[i] <= zero_tol) continue; /* a mechanism mode (or a spurious copy of its defective eigenvalue) */
    if (im[i] < -1e-10 * lmax) continue; /* the conjugate of a mode kept */
    keep[n++] = i;
  }
  PetscCheck(n >= nev, p->sys->comm, PETSC_ERR_NOT_CONVERGED, "linearized analysis: the quadratic eigensolver of the damped assembly converged %" PetscInt_FMT " of the %" PetscInt_FMT " modes wanted (-linearized_nev); see -linearized_pep_monitor, -linearized_pep_ncv (a small assembly may have fewer)", n, nev);
  s->n     = nev;
  s->nmech = 0; /* the mechanism modes are not in the list (counted from the constraints by the caller) */
  PetscCall(PetscCalloc3(nev, &s->theta, nev, &s->resid, nev, &s->growth));
  PetscCall(PetscCalloc3(nev, &s->zeta, nev, &s->decay, nev, &s->wd));
  if (vectors) PetscCall(PetscCalloc1(nev, &s->x));
  for (PetscInt k = 0; k < nev; k++) {
    const PetscInt  i  = keep[k];
    const PetscReal m  = PetscSqrtReal(re[i] * re[i] + im[i] * im[i]);
    const PetscReal wd = PetscAbsReal(im[i]) > 1e-10 * lmax ? PetscAbsReal(im[i]) : 0.0;
    s->theta[k]  = m * m;
    s->decay[k]  = -re[i];
    s->wd[k]     = wd;
    s->growth[k] = -re[i] < -1e-8 * m ? re[i] : 0.0;
    s->zeta[k]   = wd > 0 ? -re[i] / m : (PetscReal)NAN;
    PetscCall(PEPComputeError(pep, i, PEP_ERROR_BACKWARD, &s->resid[k]));
    if (vectors) {
      /* the real shape at the phase where it is largest (a non-proportionally damped mode is complex) */
      PetscReal nr, ni;
      PetscCall(PEPGetEigenpair(pep, i, NULL, NULL, xr, xi));
      PetscCall(VecNorm(xr, NORM_2, &nr));
      PetscCall(VecNorm(xi, NORM_2, &ni));
      PetscCall(VecDuplicate(xr, &s->x[k]));
      PetscCall(VecCopy(nr >= ni ? xr : xi, s->x[k]));
    }
  }
  PetscCall(PetscFree6(mag, re, im, res, perm, keep));
  PetscCall(VecDestroy(&xr));
  PetscCall(VecDestroy(&xi));
  PetscCall(PetscLogEventEnd(PHLEX_ModesSolve, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}
