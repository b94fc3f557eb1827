/* Split-phase sums over a part's communicator. A body placed whole on one process (-whole_bodies) still reduces its
   integrals over the communicator of all processes; if each body summed and reduced in turn, the process of the next
   body would wait at the first body's reduction while that body's process summed, and the bodies' local work would
   run one after the other. So the system loops over its parts twice: first every part forms its local sums and
   starts their reduction (PhlexSplitSumBegin), then every part waits for its sums (PhlexSplitSumEnd) and uses them.
   The sums are MPI's, the same on every process; with two processes a sum of two values is the same whichever order
   it takes, so the results are those of MPI_Allreduce bit for bit (on more, the non-blocking reduction may add in
   another order: round-off). */
#include <phlex_impl.h>
#include <petsc/private/vecimpl.h>
#include <petscblaslapack.h>

/*@C
  PhlexLocalDot - this process's part of VecDot(x, y), formed as PETSc's VecDot_Seq forms it (so that its sum over
  the processes is VecDot's)

  Not collective
@*/
PetscErrorCode PhlexLocalDot(Vec x, Vec y, PetscReal *d)
{
  const PetscScalar *xa, *ya;
  PetscBLASInt       one = 1, bn = 0;
  PetscInt           n;

  PetscFunctionBeginUser;
  PetscCall(VecGetLocalSize(x, &n));
  PetscCall(PetscBLASIntCast(n, &bn));
  PetscCall(VecGetArrayRead(x, &xa));
  PetscCall(VecGetArrayRead(y, &ya));
  /* VecDot_Seq's argument order: BLAS conjugates its first argument, PETSc the second */
  PetscCallBLAS("BLASdot", *d = PetscRealPart(BLASdot_(&bn, ya, &one, xa, &one)));
  PetscCall(VecRestoreArrayRead(x, &xa));
  PetscCall(VecRestoreArrayRead(y, &ya));
  if (n > 0) PetscCall(PetscLogFlops(2.0 * n - 1));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLocalMDot - this process's parts of VecMDot(x, nv, y), formed by the Vec's own local kernel (its private
  mdot_local, the one VecMDotBegin() uses, VecMDot_Seq for standard vectors: VecMDot's sums over the processes are of
  these values); logged as VecMDot

  Not collective
@*/
PetscErrorCode PhlexLocalMDot(Vec x, PetscInt nv, const Vec y[], PetscReal *d)
{
  PetscScalar dd[16];

  PetscFunctionBeginUser;
  PetscCheck(nv <= 16, PETSC_COMM_SELF, PETSC_ERR_PLIB, "PhlexLocalMDot: %" PetscInt_FMT " > 16 vectors", nv);
  for (PetscInt k = 0; k < nv; k++) {
    PetscCheckSameTypeAndComm(x, 1, y[k], 3);
    VecCheckSameSize(x, 1, y[k], 3);
  }
  PetscCall(VecLockReadPush(x));
  for (PetscInt k = 0; k < nv; k++) PetscCall(VecLockReadPush(y[k]));
  PetscCall(PetscLogEventBegin(VEC_MDot, x, *y, 0, 0));
  PetscUseTypeMethod(x, mdot_local, nv, y, dd);
  PetscCall(PetscLogEventEnd(VEC_MDot, x, *y, 0, 0));
  for (PetscInt k = 0; k < nv; k++) PetscCall(VecLockReadPop(y[k]));
  PetscCall(VecLockReadPop(x));
  for (PetscInt k = 0; k < nv; k++) d[k] = PetscRealPart(dd[k]);
  PetscFunctionReturn(0);
}

/*@C
  PhlexSplitSumBegin - starts the sum over comm of n local values (loc; glob receives the sums once
  PhlexSplitSumEnd() has returned; neither may be touched before)

  Collective (non-blocking: every process starts its parts' sums in the same order)
@*/
PetscErrorCode PhlexSplitSumBegin(MPI_Comm comm, const PetscReal *loc, PetscReal *glob, PetscInt n, MPI_Request *req)
{
  PetscMPIInt size, nn;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  if (size == 1) {
    /* one process: the sums are the local values, as MPI_Allreduce leaves them */
    PetscCall(PetscArraycpy(glob, loc, n));
    *req = MPI_REQUEST_NULL;
    PetscFunctionReturn(0);
  }
  PetscCall(PetscMPIIntCast(n, &nn));
  PetscCallMPI(MPI_Iallreduce(loc, glob, nn, MPIU_REAL, MPI_SUM, comm, req));
  PetscFunctionReturn(0);
}

/*@C
  PhlexSplitSumEnd - waits for the sums started by PhlexSplitSumBegin() (a null request: nothing to wait for)

  Collective
@*/
PetscErrorCode PhlexSplitSumEnd(MPI_Request *req)
{
  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Wait(req, MPI_STATUS_IGNORE));
  PetscFunctionReturn(0);
}
