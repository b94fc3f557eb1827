/* Checkpoint files: one HDF5 file per checkpoint, written under a temporary name (.<name>.tmp next to it), flushed
   to disk and renamed over the previous checkpoint, so that a run killed at any moment leaves either the previous
   checkpoint or the new one, never a half-written file. Small helpers name what is stored: real arrays (a dataset
   held by rank 0, the same values on every rank when read), integers and strings (attributes of a group). What a
   checkpoint holds is decided by its writer (the transient analysis, the output manager, the field writers). */
#define _POSIX_C_SOURCE 200809L /* fsync */
#include <phlex_impl.h>
#include <petscviewerhdf5.h>
#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

/* rank 0: the file's data on the disk before the rename makes it the checkpoint (a crash of the node keeps the old
   checkpoint or the new one) */
static int SyncFile(const char path[])
{
  int fd = open(path, O_RDONLY), err = 0;
  if (fd < 0) return errno;
  if (fsync(fd)) err = errno;
  close(fd);
  return err;
}

/*@C
  PhlexFileSync - rank 0 flushes a closed file to the disk (a file a checkpoint refers to)

  Collective
@*/
PetscErrorCode PhlexFileSync(MPI_Comm comm, const char path[])
{
  PetscMPIInt rank;
  int         err = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) err = SyncFile(path);
  PetscCallMPI(MPI_Bcast(&err, 1, MPI_INT, 0, comm));
  PetscCheck(!err, comm, PETSC_ERR_FILE_WRITE, "cannot write '%s' to disk: %s", path, strerror(err));
  PetscFunctionReturn(0);
}

/*@C
  PhlexCheckpointOpenWrite - opens the temporary file of a new checkpoint

  Collective

  Output Parameters:
+ tmp    - its temporary path (PETSC_MAX_PATH_LEN), renamed to path by PhlexCheckpointCommit
- viewer - the HDF5 viewer
@*/
PetscErrorCode PhlexCheckpointOpenWrite(MPI_Comm comm, const char path[], char tmp[], PetscViewer *viewer)
{
  const char *slash;

  PetscFunctionBeginUser;
  slash = strrchr(path, '/');
  if (slash) PetscCall(PetscSNPrintf(tmp, PETSC_MAX_PATH_LEN, "%.*s/.%s.tmp", (int)(slash - path), path, slash + 1));
  else PetscCall(PetscSNPrintf(tmp, PETSC_MAX_PATH_LEN, ".%s.tmp", path));
  PetscCall(PetscViewerHDF5Open(comm, tmp, FILE_MODE_WRITE, viewer));
  PetscFunctionReturn(0);
}

/*@C
  PhlexCheckpointCommit - closes a checkpoint being written, flushes it to disk and renames it to its final path

  Collective
@*/
PetscErrorCode PhlexCheckpointCommit(MPI_Comm comm, const char tmp[], const char path[], PetscViewer *viewer)
{
  PetscMPIInt rank;
  int         err = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(viewer));
  PetscCallMPI(MPI_Barrier(comm));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    err = SyncFile(tmp);
    if (!err && rename(tmp, path)) err = errno;
    if (err) (void)remove(tmp);
    else {
      /* the rename itself on the disk: the directory's entry */
      char        dir[PETSC_MAX_PATH_LEN];
      const char *slash = strrchr(path, '/');
      if (slash) snprintf(dir, sizeof(dir), "%.*s", (int)(slash - path), path);
      else snprintf(dir, sizeof(dir), ".");
      (void)SyncFile(dir);
    }
  }
  PetscCallMPI(MPI_Bcast(&err, 1, MPI_INT, 0, comm));
  PetscCheck(!err, comm, PETSC_ERR_FILE_WRITE, "cannot write the checkpoint '%s' (option -checkpoint_file): %s", path, strerror(err));
  PetscFunctionReturn(0);
}

/*@C
  PhlexHDF5Readable - whether a file opens as HDF5: rank 0 tries it quietly, so that a file that is not HDF5, or a
  truncated one, gets the caller's message instead of HDF5's trace

  Collective
@*/
PetscErrorCode PhlexHDF5Readable(MPI_Comm comm, const char path[], PetscBool *readable)
{
  PetscMPIInt rank;
  int         ok = 1;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    H5E_auto2_t func;
    void       *data;
    hid_t       f;
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) ok = 0;
    else H5Fclose(f);
    H5Eset_auto2(H5E_DEFAULT, func, data);
  }
  PetscCallMPI(MPI_Bcast(&ok, 1, MPI_INT, 0, comm));
  *readable = ok ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexCheckpointOpenRead - opens a checkpoint to restart from, with a clear error if it is not one

  Collective
@*/
PetscErrorCode PhlexCheckpointOpenRead(MPI_Comm comm, const char path[], PetscViewer *viewer)
{
  PetscBool exists, has;
  PetscInt  version = 0;

  PetscFunctionBeginUser;
  PetscCall(PetscTestFile(path, 'r', &exists));
  PetscCheck(exists, comm, PETSC_ERR_FILE_OPEN, "cannot read the checkpoint '%s' (option -restart): no such file", path);
  {
    PetscBool ok;
    PetscCall(PhlexHDF5Readable(comm, path, &ok));
    PetscCheck(ok, comm, PETSC_ERR_FILE_UNEXPECTED, "cannot read the checkpoint '%s' (option -restart): not an HDF5 file, or a damaged one (truncated?)", path);
  }
  PetscCall(PetscViewerHDF5Open(comm, path, FILE_MODE_READ, viewer));
  PetscCall(PetscViewerHDF5HasAttribute(*viewer, "/", "phlex_checkpoint", &has));
  PetscCheck(has, comm, PETSC_ERR_FILE_UNEXPECTED, "'%s' (option -restart) is an HDF5 file but not a phlex checkpoint", path);
  PetscCall(PhlexCheckpointReadInt(*viewer, "/", "phlex_checkpoint", &version));
  PetscCheck(version == 1, comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint '%s' (option -restart) has format %" PetscInt_FMT "; this phlex reads format 1", path, version);
  PetscFunctionReturn(0);
}

/* a vector of n entries, all on rank 0 */
static PetscErrorCode ArrayVec(PetscViewer viewer, const char name[], PetscInt n, Vec *x)
{
  MPI_Comm    comm = PetscObjectComm((PetscObject)viewer);
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  PetscCall(VecCreate(comm, x));
  PetscCall(VecSetSizes(*x, rank ? 0 : n, n));
  PetscCall(VecSetType(*x, VECSTANDARD));
  PetscCall(PetscObjectSetName((PetscObject)*x, name));
  PetscFunctionReturn(0);
}

/*@C
  PhlexCheckpointWriteReals - stores n reals (the same on every rank) as dataset group/name

  Collective
@*/
PetscErrorCode PhlexCheckpointWriteReals(PetscViewer viewer, const char group[], const char name[], PetscInt n, const PetscReal values[])
{
  Vec          x;
  PetscScalar *a;
  PetscInt     nloc;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  PetscCall(ArrayVec(viewer, name, n, &x));
  PetscCall(VecGetLocalSize(x, &nloc));
  PetscCall(VecGetArray(x, &a));
  for (PetscInt i = 0; i < nloc; i++) a[i] = values[i];
  PetscCall(VecRestoreArray(x, &a));
  PetscCall(PetscViewerHDF5PushGroup(viewer, group));
  PetscCall(VecView(x, viewer));
  PetscCall(PetscViewerHDF5PopGroup(viewer));
  PetscCall(VecDestroy(&x));
  PetscFunctionReturn(0);
}

/*@C
  PhlexCheckpointReadReals - reads n reals stored by PhlexCheckpointWriteReals (on every rank)

  Collective
@*/
PetscErrorCode PhlexCheckpointReadReals(PetscViewer viewer, const char group[], const char name[], PetscInt n, PetscReal values[])
{
  MPI_Comm     comm = PetscObjectComm((PetscObject)viewer);
  Vec          x;
  PetscScalar *a;
  PetscInt     nloc, N;
  PetscBool    has;
  char         path[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/%s", group, name));
  PetscCall(PetscViewerHDF5HasDataset(viewer, path, &has));
  PetscCheck(has, comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) lacks %s: not written by this version of phlex", path);
  PetscCall(ArrayVec(viewer, name, n, &x));
  PetscCall(PetscViewerHDF5PushGroup(viewer, group));
  PetscCall(VecLoad(x, viewer));
  PetscCall(PetscViewerHDF5PopGroup(viewer));
  PetscCall(VecGetSize(x, &N));
  PetscCheck(N == n, comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint's %s has %" PetscInt_FMT " values, this run %" PetscInt_FMT, path, N, n);
  PetscCall(VecGetLocalSize(x, &nloc));
  PetscCall(VecGetArray(x, &a));
  for (PetscInt i = 0; i < nloc; i++) values[i] = PetscRealPart(a[i]);
  PetscCall(VecRestoreArray(x, &a));
  PetscCall(VecDestroy(&x));
  PetscCallMPI(MPI_Bcast(values, (PetscMPIInt)n, MPIU_REAL, 0, comm));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexCheckpointWriteInt(PetscViewer viewer, const char group[], const char name[], PetscInt value)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerHDF5WriteGroup(viewer, group));
  PetscCall(PetscViewerHDF5WriteAttribute(viewer, group, name, PETSC_INT, &value));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexCheckpointReadInt(PetscViewer viewer, const char group[], const char name[], PetscInt *value)
{
  PetscBool has;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerHDF5HasAttribute(viewer, group, name, &has));
  PetscCheck(has, PetscObjectComm((PetscObject)viewer), PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) lacks %s/%s: not written by this version of phlex", group, name);
  PetscCall(PetscViewerHDF5ReadAttribute(viewer, group, name, PETSC_INT, NULL, value));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexCheckpointWriteString(PetscViewer viewer, const char group[], const char name[], const char value[])
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerHDF5WriteGroup(viewer, group));
  PetscCall(PetscViewerHDF5WriteAttribute(viewer, group, name, PETSC_STRING, value));
  PetscFunctionReturn(0);
}

PetscErrorCode PhlexCheckpointReadString(PetscViewer viewer, const char group[], const char name[], char value[], size_t len)
{
  PetscBool has;
  char     *s = NULL;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerHDF5HasAttribute(viewer, group, name, &has));
  PetscCheck(has, PetscObjectComm((PetscObject)viewer), PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) lacks %s/%s: not written by this version of phlex", group, name);
  PetscCall(PetscViewerHDF5ReadAttribute(viewer, group, name, PETSC_STRING, NULL, &s));
  PetscCall(PetscStrncpy(value, s, len));
  PetscCall(PetscFree(s));
  PetscFunctionReturn(0);
}
