/* Output of a run: one directory with the CSV series and, per flexible body, HDF5 fields plus an XDMF index for
   ParaView (fields.c). Every file is written under a temporary name and renamed when the run completes, so an
   error never leaves a half-written result under a final name. */
#define _XOPEN_SOURCE 700 /* kill, gethostname, open flags, realpath, truncate, fsync */
#include <phlex_impl.h>
#include <petscviewerhdf5.h>
#include <fcntl.h>
#include <signal.h>
#include <time.h>
#include <sys/stat.h>
#include <errno.h>
#include <unistd.h>
#include <dirent.h>

/*@C
  PhlexOutputCreate - creates the output manager of a run
@*/
PetscErrorCode PhlexOutputCreate(MPI_Comm comm, PhlexOutput *out)
{
  PetscFunctionBeginUser;
  PetscCall(PetscNew(out));
  (*out)->comm     = comm;
  (*out)->interval = 0;
  (*out)->fields   = PETSC_TRUE;
  (*out)->keep_failed = PETSC_TRUE;
  PetscCall(PetscStrcpy((*out)->dir, "output"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputSetFromOptions - reads the output options

  Options Database Keys:
+ -output_dir <dir>        - directory of the run's results (created if missing)
. -output_interval <n>     - write fields every n time steps (0: first and last step only)
. -output_fields <bool>    - write HDF5/XDMF fields
- -output_keep_failed <bool> - a run that fails numerically (exit 3) keeps its series so far in <dir>/failed/
@*/
PetscErrorCode PhlexOutputSetFromOptions(PhlexOutput out)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(out->comm, NULL, "Output options", NULL);
  PetscCall(PetscOptionsString("-output_dir", "Directory of the run's results (created if missing)", "PhlexOutputSetFromOptions", out->dir, out->dir, sizeof(out->dir), NULL));
  PetscCall(PetscOptionsInt("-output_interval", "Write fields every n time steps (0: first and last step only)", "PhlexOutputSetFromOptions", out->interval, &out->interval, NULL));
  PetscCall(PetscOptionsBool("-output_fields", "Write HDF5/XDMF fields for ParaView", "PhlexOutputSetFromOptions", out->fields, &out->fields, NULL));
  PetscCall(PetscOptionsBool("-output_keep_failed", "A run that fails numerically (exit 3: a watchdog, Newton) keeps its CSV series up to the failed step in <output_dir>/failed/ (not results: how the failure grew)", "PhlexOutputSetFromOptions", out->keep_failed, &out->keep_failed, NULL));
  PetscOptionsEnd();
  PetscCheck(out->interval >= 0, out->comm, PETSC_ERR_USER_INPUT, "-output_interval must be >= 0, got %" PetscInt_FMT, out->interval);
  PetscCheck(out->dir[0], out->comm, PETSC_ERR_USER_INPUT, "-output_dir must not be empty");
  PetscFunctionReturn(0);
}

/* mkdir -p on rank 0; *made: the last component was created (not there before) */
static PetscErrorCode MakeDirectory(MPI_Comm comm, const char dir[], PetscBool *made)
{
  PetscMPIInt rank;
  int         err = 0;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) {
    char path[PETSC_MAX_PATH_LEN];
    PetscCall(PetscStrncpy(path, dir, sizeof(path)));
    for (char *p = path + 1; *p && !err; p++)
      if (*p == '/') {
        *p = 0;
        if (mkdir(path, 0775) && errno != EEXIST) err = errno;
        *p = '/';
      }
    if (!err) {
      if (!mkdir(path, 0775)) *made = PETSC_TRUE;
      else if (errno != EEXIST) err = errno;
    }
  }
  PetscCallMPI(MPI_Bcast(&err, 1, MPI_INT, 0, comm));
  PetscCheck(!err, comm, PETSC_ERR_FILE_WRITE, "cannot create output directory '%s' (option -output_dir): %s", dir, strerror(err));
  PetscFunctionReturn(0);
}

/* The lock of the output directory, <dir>/.phlex.lock ("pid host start-time"), made atomically (O_EXCL) by rank 0:
   a second run on the same directory is refused instead of mixing its files with the first one's. A lock left by
   a run that was killed (its process gone, same host) is taken over with a warning. */
static PetscErrorCode Lock(PhlexOutput out)
{
  PetscMPIInt rank;
  int         status = 0; /* 0 locked, 1 in use by another run, 2 cannot write */
  char        holder[256] = "", path[PETSC_MAX_PATH_LEN + 16];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
  PetscCall(PetscSNPrintf(path, sizeof(path), "%s/.phlex.lock", out->dir));
  if (rank == 0) {
    char host[128] = "";
    (void)gethostname(host, sizeof(host) - 1);
    for (int attempt = 0; attempt < 2; attempt++) {
      int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0644);
      if (fd >= 0) {
        char line[256];
        int  n = snprintf(line, sizeof(line), "%ld %s %ld\n", (long)getpid(), host, (long)time(NULL));
        status = (write(fd, line, (size_t)n) == n) ? 0 : 2;
        close(fd);
        break;
      }
      if (errno != EEXIST) {
        status = 2;
        PetscCall(PetscSNPrintf(holder, sizeof(holder), "%s", strerror(errno)));
        break;
      }
      {
        /* someone holds it: alive, or a killed run's leftover? */
        FILE *fp  = fopen(path, "r");
        long  pid = 0, since = 0;
        char  other[128] = "";
        if (fp) {
          if (fscanf(fp, "%ld %127s %ld", &pid, other, &since) != 3) pid = 0;
          fclose(fp);
        }
        if (pid > 0 && !strcmp(other, host) && kill((pid_t)pid, 0) && errno == ESRCH && attempt == 0) {
          fprintf(stderr, "phlex: warning: output directory '%s': removed the lock of run %ld, which ended without releasing it\n", out->dir, pid);
          (void)remove(path);
          continue;
        }
        status = 1;
        if (pid > 0) {
          char      when[64] = "?";
          time_t    t        = (time_t)since;
          struct tm tm;
          if (localtime_r(&t, &tm)) strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", &tm);
          PetscCall(PetscSNPrintf(holder, sizeof(holder), "process %ld on host %s, since %s", pid, other, when));
        } else PetscCall(PetscSNPrintf(holder, sizeof(holder), "unreadable lock"));
        break;
      }
    }
  }
  PetscCallMPI(MPI_Bcast(&status, 1, MPI_INT, 0, out->comm));
  PetscCallMPI(MPI_Bcast(holder, sizeof(holder), MPI_CHAR, 0, out->comm));
  PetscCheck(status != 1, out->comm, PETSC_ERR_FILE_WRITE, "output directory '%s' (option -output_dir) is in use by another run (%s): choose another directory, or remove %s if that run is gone", out->dir, holder, path);
  PetscCheck(status != 2, out->comm, PETSC_ERR_FILE_WRITE, "cannot write the lock file %s of the output directory (option -output_dir): %s", path, holder[0] ? holder : "write failed");
  out->locked = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* releases the lock (rank 0; safe after an error) */
static void Unlock(PhlexOutput out)
{
  PetscMPIInt rank = 0;
  char        path[PETSC_MAX_PATH_LEN + 16];

  if (!out->locked) return;
  MPI_Comm_rank(out->comm, &rank);
  snprintf(path, sizeof(path), "%s/.phlex.lock", out->dir);
  if (rank == 0) (void)remove(path);
  out->locked = PETSC_FALSE;
}

/*@C
  PhlexOutputFile - registers an output file and returns the temporary path to write it to

  Collective

  Input Parameters:
+ out  - output manager
- name - file name inside the output directory

  Output Parameter:
. tmp - temporary path (renamed to the final name by PhlexOutputCommit)
@*/
PetscErrorCode PhlexOutputFile(PhlexOutput out, const char name[], char tmp[])
{
  PetscInt k = out->nfiles;

  PetscFunctionBeginUser;
  if (!out->locked) {
    PetscCall(MakeDirectory(out->comm, out->dir, &out->made_dir));
    PetscCall(Lock(out));
  }
  if (k == out->maxfiles) {
    char(*tmp)[PETSC_MAX_PATH_LEN], (*fin)[PETSC_MAX_PATH_LEN];
    PetscViewer   *csv;
    PetscBool     *had;
    const PetscInt n = PetscMax(16, 2 * out->maxfiles);
    PetscCall(PetscMalloc4(n, &tmp, n, &fin, n, &csv, n, &had));
    if (k) {
      PetscCall(PetscArraycpy(tmp, out->tmp, k));
      PetscCall(PetscArraycpy(fin, out->final, k));
      PetscCall(PetscArraycpy(csv, out->csv, k));
      PetscCall(PetscArraycpy(had, out->had_tmp, k));
    }
    PetscCall(PetscFree4(out->tmp, out->final, out->csv, out->had_tmp));
    out->tmp      = tmp;
    out->final    = fin;
    out->csv      = csv;
    out->had_tmp  = had;
    out->maxfiles = n;
  }
  out->csv[k] = NULL;
  PetscCall(PetscSNPrintf(out->final[k], PETSC_MAX_PATH_LEN, "%s/%s", out->dir, name));
  PetscCall(PetscSNPrintf(out->tmp[k], PETSC_MAX_PATH_LEN, "%s/.%s.tmp", out->dir, name));
  {
    struct stat st;
    out->had_tmp[k] = stat(out->tmp[k], &st) ? PETSC_FALSE : PETSC_TRUE; /* rank 0's answer is the one used */
  }
  PetscCall(PetscStrcpy(tmp, out->tmp[k]));
  out->nfiles++;
  PetscFunctionReturn(0);
}

/* the series a failed run kept in the directory failed (phlex writes nothing but .csv there; anything else stays) */
static void RemoveFailedSeries(const char failed[])
{
  DIR *d = opendir(failed);

  if (!d) return;
  for (struct dirent *e = readdir(d); e; e = readdir(d)) {
    char         old[2 * PETSC_MAX_PATH_LEN];
    const size_t len = strlen(e->d_name);
    if (e->d_name[0] == '.' || len < 5 || strcmp(e->d_name + len - 4, ".csv")) continue;
    (void)snprintf(old, sizeof(old), "%s/%s", failed, e->d_name);
    (void)remove(old);
  }
  closedir(d);
}

/*@C
  PhlexOutputCommit - renames every completed output file to its final name

  Collective
@*/
PetscErrorCode PhlexOutputCommit(PhlexOutput out)
{
  PetscMPIInt rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
  PetscCallMPI(MPI_Barrier(out->comm));
  if (rank == 0)
    for (PetscInt k = 0; k < out->nfiles; k++) PetscCheck(!rename(out->tmp[k], out->final[k]), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot rename '%s' to '%s': %s", out->tmp[k], out->final[k], strerror(errno));
  if (rank == 0 && out->nfiles) {
    /* results supersede the series an earlier failed run of this directory kept in failed/ */
    char failed[PETSC_MAX_PATH_LEN + 16];
    (void)snprintf(failed, sizeof(failed), "%s/failed", out->dir);
    RemoveFailedSeries(failed);
    (void)rmdir(failed); /* fails if anything else is there: left alone */
  }
  PetscCallMPI(MPI_Barrier(out->comm));
  /* where the results are: the directory, then the files in the order they were opened */
  if (out->nfiles) {
    size_t dirlen, col;
    PetscCall(PetscStrlen(out->dir, &dirlen));
    PetscCall(PetscPrintf(out->comm, "Results in %s/:", out->dir));
    col = 12 + dirlen;
    for (PetscInt k = 0; k < out->nfiles; k++) {
      const char *name = out->final[k] + dirlen + 1;
      size_t      len;
      PetscCall(PetscStrlen(name, &len));
      if (col + len + 1 > 110) {
        PetscCall(PetscPrintf(out->comm, "\n "));
        col = 1;
      }
      PetscCall(PetscPrintf(out->comm, " %s", name));
      col += len + 1;
    }
    PetscCall(PetscPrintf(out->comm, "\n"));
  }
  out->ncommitted += out->nfiles;
  out->nfiles   = 0;
  out->keep_tmp = PETSC_FALSE; /* nothing temporary is left */
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputKeepFailed - a run that failed numerically: its CSV series so far (their rows up to the failed step, the
  last one the step that failed) moved to <dir>/failed/ under their names, any older ones there removed first; the
  fields are not kept (PhlexOutputAbort removes them). Nothing when a checkpoint keeps the files for -restart.

  Not collective: rank 0 moves the files; safe to call after an error
@*/
PetscErrorCode PhlexOutputKeepFailed(PhlexOutput out)
{
  PetscMPIInt rank;
  char        failed[PETSC_MAX_PATH_LEN + 16];
  PetscInt    nkept = 0;

  if (!out || !out->keep_failed || out->keep_tmp) return 0;
  MPI_Comm_rank(out->comm, &rank);
  if (rank) return 0;
  for (PetscInt k = 0; k < out->nfiles; k++)
    if (out->csv[k]) nkept++;
  if (!nkept) return 0;
  (void)snprintf(failed, sizeof(failed), "%s/failed", out->dir);
  if (mkdir(failed, 0777) && errno != EEXIST) return 0;
  RemoveFailedSeries(failed); /* an earlier failed run's */
  nkept = 0;
  for (PetscInt k = 0; k < out->nfiles; k++) {
    FILE       *fp   = NULL;
    const char *name = strrchr(out->final[k], '/');
    char        dest[2 * PETSC_MAX_PATH_LEN];
    if (!out->csv[k]) continue;
    if (!PetscViewerASCIIGetPointer(out->csv[k], &fp) && fp) (void)fflush(fp);
    (void)snprintf(dest, sizeof(dest), "%s/%s", failed, name ? name + 1 : out->final[k]);
    if (!rename(out->tmp[k], dest)) nkept++;
  }
  if (nkept) fprintf(stderr, "phlex: the run's %d series up to its last monitored step (a watchdog's: the step that failed) are kept in '%s/' (not results: their last rows show how the failure grew; -output_keep_failed false keeps none)\n", (int)nkept, failed);
  return 0;
}

/*@C
  PhlexOutputAbort - removes the temporary files of an unfinished run (called on error)

  Not collective: each rank removes nothing but rank 0's files; safe to call after an error
@*/
PetscErrorCode PhlexOutputAbort(PhlexOutput out)
{
  PetscMPIInt rank;

  if (!out) return 0;
  MPI_Comm_rank(out->comm, &rank);
  Unlock(out);
  if (rank == 0 && out->keep_tmp && !out->wrote_checkpoint && out->nfiles && PhlexExitCode() == PHLEX_EXIT_INPUT) {
    /* refused input (a restart's checks come after its series were continued into their temporary files): nothing
       of this run stays; the temporary files an interrupted run left for -restart stay as they were */
    for (PetscInt k = 0; k < out->nfiles; k++)
      if (!out->had_tmp[k]) (void)remove(out->tmp[k]);
  } else if (rank == 0 && out->keep_tmp && out->nfiles) {
    /* a checkpoint continues them (-restart) */
    fprintf(stderr, "phlex: the partial series and fields in '%s' were kept for the checkpoint (continue with -restart)\n", out->dir);
  } else if (rank == 0 && !out->keep_tmp) {
    for (PetscInt k = 0; k < out->nfiles; k++) (void)remove(out->tmp[k]);
    /* a directory this run made and left empty would look like a result: removed (rmdir fails if not empty) */
    if (out->made_dir && !out->ncommitted) (void)rmdir(out->dir);
  }
  out->nfiles = 0;
  return 0;
}

/*@C
  PhlexOutputCSVOpen - opens a CSV series in the output directory and writes its header line; with header NULL the
  caller writes the header itself (PetscViewerASCIIPrintf, in pieces: any number of columns), ending it with a newline

  Collective
@*/
PetscErrorCode PhlexOutputCSVOpen(PhlexOutput out, const char name[], const char header[], PetscViewer *viewer)
{
  char tmp[PETSC_MAX_PATH_LEN];

  PetscInt k = -1;

  PetscFunctionBeginUser;
  PetscCall(PhlexOutputFile(out, name, tmp));
  for (PetscInt i = 0; i < out->nrestart_csv; i++) {
    PetscBool same;
    PetscCall(PetscStrcmp(out->restart_csv[i], name, &same));
    if (same) k = i;
  }
  if (k >= 0) out->restart_csv_used[k] = PETSC_TRUE;
  if (k >= 0) {
    PetscCheck(header, out->comm, PETSC_ERR_PLIB, "series '%s' continued by a restart must be opened with its header", name);
    /* a restarted run: the series up to the checkpoint (its header included), then this run's rows appended */
    PetscCall(PhlexOutputRestoreFile(out, name, tmp, out->restart_csv_length[k]));
    PetscCall(PetscViewerCreate(out->comm, viewer));
    PetscCall(PetscViewerSetType(*viewer, PETSCVIEWERASCII));
    PetscCall(PetscViewerFileSetMode(*viewer, FILE_MODE_APPEND));
    PetscCall(PetscViewerFileSetName(*viewer, tmp));
  } else {
    PetscCheck(!out->restart, out->comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) has no series '%s': it was written for another scene or other outputs", name);
    PetscCall(PetscViewerASCIIOpen(out->comm, tmp, viewer));
  }
  PetscCall(PetscViewerPushFormat(*viewer, PETSC_VIEWER_ASCII_CSV));
  if (header && k < 0) PetscCall(PetscViewerASCIIPrintf(*viewer, "%s\n", header));
  out->csv[out->nfiles - 1] = *viewer;
  PetscFunctionReturn(0);
}

/* rank 0: copies the first length bytes (all if length < 0) of src to dst; 0 or an errno, *short_src if src is
   shorter */
static int CopyPrefix(const char src[], const char dst[], PetscReal length, PetscBool *short_src)
{
  FILE  *in = fopen(src, "rb"), *out;
  char   buf[1 << 16];
  double left = length < 0 ? 1e300 : (double)length;
  int    err  = 0;

  *short_src = PETSC_FALSE;
  if (!in) return errno;
  out = fopen(dst, "wb");
  if (!out) {
    err = errno;
    fclose(in);
    return err;
  }
  while (left > 0) {
    size_t want = left < (double)sizeof(buf) ? (size_t)left : sizeof(buf), got = fread(buf, 1, want, in);
    if (got && fwrite(buf, 1, got, out) != got) {
      err = errno ? errno : EIO;
      break;
    }
    left -= (double)got;
    if (got < want) break;
  }
  if (length >= 0 && left > 0 && !err) *short_src = PETSC_TRUE;
  fclose(in);
  if (fclose(out) && !err) err = errno;
  return err;
}

/*@C
  PhlexOutputRestoreFile - the file "name" of the interrupted run a restart continues, up to its length at the
  checkpoint (all of it if length < 0), as this run's temporary file tmp: truncated in place when the restart writes
  to the same directory, copied otherwise. The interrupted run's file is its temporary file, or its final name if
  that run completed.

  Collective
@*/
PetscErrorCode PhlexOutputRestoreFile(PhlexOutput out, const char name[], const char tmp[], PetscReal length)
{
  PetscMPIInt rank;
  int         err = 0;
  PetscBool   short_src = PETSC_FALSE, found = PETSC_TRUE;
  char        src[PETSC_MAX_PATH_LEN + 8];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
  if (rank == 0) {
    char        rsrc[PETSC_MAX_PATH_LEN], rdst[PETSC_MAX_PATH_LEN];
    struct stat st;
    snprintf(src, sizeof(src), "%s/.%s.tmp", out->restart_dir, name);
    if (stat(src, &st)) {
      snprintf(src, sizeof(src), "%s/%s", out->restart_dir, name);
      if (stat(src, &st)) found = PETSC_FALSE;
    }
    if (found && realpath(src, rsrc) && realpath(tmp, rdst) && !strcmp(rsrc, rdst)) {
      /* the same file: cut what the interrupted run wrote after its checkpoint */
      if (length >= 0 && (double)st.st_size < (double)length) short_src = PETSC_TRUE;
      else if (length >= 0 && truncate(tmp, (off_t)length)) err = errno;
    } else if (found) err = CopyPrefix(src, tmp, length, &short_src);
  }
  PetscCallMPI(MPI_Bcast(&err, 1, MPI_INT, 0, out->comm));
  PetscCallMPI(MPI_Bcast(&found, 1, MPIU_BOOL, 0, out->comm));
  PetscCallMPI(MPI_Bcast(&short_src, 1, MPIU_BOOL, 0, out->comm));
  PetscCheck(found, out->comm, PETSC_ERR_FILE_OPEN, "the checkpoint (option -restart) continues '%s' of the run in '%s', but neither %s/.%s.tmp nor %s/%s exists: were the interrupted run's files removed?", name, out->restart_dir, out->restart_dir, name, out->restart_dir, name);
  PetscCheck(!short_src, out->comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) continues '%s' of the run in '%s' at %.0f bytes, but that file is shorter: it is not the file the checkpoint was written with", name, out->restart_dir, (double)length);
  PetscCheck(!err, out->comm, PETSC_ERR_FILE_WRITE, "cannot continue '%s' of the run in '%s' into '%s': %s", name, out->restart_dir, tmp, strerror(err));
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputSaveState - records in a checkpoint where every series stands (flushed to disk, its length) and each
  field writer's snapshots (a field writer closes its current segment); from now on an error keeps the
  temporary files, which the checkpoint continues

  Collective
@*/
PetscErrorCode PhlexOutputSaveState(PhlexOutput out, PetscViewer viewer)
{
  PetscMPIInt rank;
  PetscInt    ncsv = 0;
  char        dir[PETSC_MAX_PATH_LEN] = "", key[32];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
  for (PetscInt k = 0; k < out->nfiles; k++) {
    PetscReal length = 0;
    int       err    = 0;
    if (!out->csv[k]) continue;
    PetscCall(PetscViewerFlush(out->csv[k]));
    if (rank == 0) {
      FILE *fp;
      PetscCall(PetscViewerASCIIGetPointer(out->csv[k], &fp));
      if (fflush(fp) || fsync(fileno(fp))) err = errno ? errno : EIO;
      length = (PetscReal)ftell(fp);
    }
    PetscCallMPI(MPI_Bcast(&err, 1, MPI_INT, 0, out->comm));
    PetscCheck(!err, out->comm, PETSC_ERR_FILE_WRITE, "cannot write '%s' to disk for the checkpoint: %s", out->tmp[k], strerror(err));
    PetscCallMPI(MPI_Bcast(&length, 1, MPIU_REAL, 0, out->comm));
    PetscCall(PetscSNPrintf(key, sizeof(key), "csv_%" PetscInt_FMT, ncsv));
    PetscCall(PhlexCheckpointWriteString(viewer, "/output", key, out->final[k] + strlen(out->dir) + 1));
    PetscCall(PetscSNPrintf(key, sizeof(key), "csv_length_%" PetscInt_FMT, ncsv));
    PetscCall(PhlexCheckpointWriteReals(viewer, "/output", key, 1, &length));
    ncsv++;
  }
  PetscCall(PhlexCheckpointWriteInt(viewer, "/output", "ncsv", ncsv));
  PetscCall(PhlexCheckpointWriteInt(viewer, "/output", "nwriters", out->nwriters));
  if (rank == 0 && !realpath(out->dir, dir)) PetscCall(PetscStrncpy(dir, out->dir, sizeof(dir)));
  PetscCallMPI(MPI_Bcast(dir, sizeof(dir), MPI_CHAR, 0, out->comm));
  PetscCall(PhlexCheckpointWriteString(viewer, "/output", "dir", dir));
  for (PetscInt w = 0; w < out->nwriters; w++) PetscCall((*out->writer_save[w])(out->writer_ctx[w], viewer));
  out->keep_tmp         = PETSC_TRUE;
  out->wrote_checkpoint = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputRestartCheckUsed - after a restarted run has opened its outputs: every series of the checkpoint was
  continued (a series this run does not write means another scene or other outputs)

  Collective
@*/
PetscErrorCode PhlexOutputRestartCheckUsed(PhlexOutput out)
{
  PetscFunctionBeginUser;
  for (PetscInt k = 0; k < out->nrestart_csv; k++) PetscCheck(out->restart_csv_used[k], out->comm, PETSC_ERR_USER_INPUT, "the checkpoint (option -restart) has the series '%s', which this run does not write: it was written for another scene or other outputs", out->restart_csv[k]);
  PetscFunctionReturn(0);
}

/*@C
  PhlexCSVPrintf - writes a piece of a series row to a CSV file of PhlexOutputCSVOpen() (rank 0 of its communicator
  writes): like PetscViewerASCIIPrintf(), through the file's stdio buffer instead of a flush after every piece (which
  cost a system call per number: 13 % of a reduced crank-slider's run); the files are flushed at most a second after a
  row (PhlexOutputFlushSeries, once per output step), at each checkpoint (PhlexOutputSaveState) and when closed

  Not collective
@*/
PetscErrorCode PhlexCSVPrintf(PetscViewer csv, const char format[], ...)
{
  PetscMPIInt rank;
  FILE       *fp;
  va_list     ap;
  int         n;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)csv), &rank));
  if (rank) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIGetPointer(csv, &fp));
  va_start(ap, format);
  n = vfprintf(fp, format, ap);
  va_end(ap);
  PetscCheck(n >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write a series row: %s", strerror(errno));
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputFlushSeries - writes the series' buffered rows to their files if the last flush is a second old or more
  (called after each step's rows: the files, which one may follow during a run, are at most a second behind, and a
  run that fails loses no more than that of the rows it buffered)

  Collective
@*/
PetscErrorCode PhlexOutputFlushSeries(PhlexOutput out)
{
  PetscLogDouble now;
  PetscMPIInt    rank;

  PetscFunctionBeginUser;
  PetscCall(PetscTime(&now));
  PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
  if (!rank && now - out->series_flushed >= 1.0) {
    for (PetscInt k = 0; k < out->nfiles; k++) {
      FILE *fp;
      if (!out->csv[k]) continue;
      PetscCall(PetscViewerASCIIGetPointer(out->csv[k], &fp));
      PetscCheck(!fflush(fp), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write the series '%s': %s", out->tmp[k], strerror(errno));
    }
    out->series_flushed = now;
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputAddWriter - registers a writer of files with a state of its own (a field writer: its segments and
  snapshots), which PhlexOutputSaveState() records in each checkpoint by calling save(ctx, viewer)

  Not collective
@*/
PetscErrorCode PhlexOutputAddWriter(PhlexOutput out, void *ctx, PetscErrorCode (*save)(void *, PetscViewer))
{
  void **ctxs;
  PetscErrorCode (**saves)(void *, PetscViewer);

  PetscFunctionBeginUser;
  PetscCall(PetscMalloc2(out->nwriters + 1, &ctxs, out->nwriters + 1, &saves));
  for (PetscInt w = 0; w < out->nwriters; w++) {
    ctxs[w]  = out->writer_ctx[w];
    saves[w] = out->writer_save[w];
  }
  ctxs[out->nwriters]  = ctx;
  saves[out->nwriters] = save;
  PetscCall(PetscFree2(out->writer_ctx, out->writer_save));
  out->writer_ctx  = ctxs;
  out->writer_save = saves;
  out->nwriters++;
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputSetRestart - a restarted run: its series and field writers continue those recorded in the checkpoint
  (the interrupted run's files are found in the directory it recorded, else next to the checkpoint)

  Collective
@*/
PetscErrorCode PhlexOutputSetRestart(PhlexOutput out, PetscViewer viewer, const char checkpoint[])
{
  PetscBool isdir = PETSC_FALSE;
  char      key[32], mine[PETSC_MAX_PATH_LEN] = "", theirs[PETSC_MAX_PATH_LEN] = "";

  PetscFunctionBeginUser;
  out->restart = viewer;
  PetscCall(PhlexCheckpointReadString(viewer, "/output", "dir", out->restart_dir, sizeof(out->restart_dir)));
  PetscCall(PetscTestDirectory(out->restart_dir, 'r', &isdir));
  if (!isdir) {
    const char *slash = strrchr(checkpoint, '/');
    if (slash) PetscCall(PetscSNPrintf(out->restart_dir, sizeof(out->restart_dir), "%.*s", (int)(slash - checkpoint), checkpoint));
    else PetscCall(PetscStrcpy(out->restart_dir, "."));
  }
  PetscCall(PhlexCheckpointReadInt(viewer, "/output", "ncsv", &out->nrestart_csv));
  PetscCall(PetscCalloc3(out->nrestart_csv, &out->restart_csv, out->nrestart_csv, &out->restart_csv_length, out->nrestart_csv, &out->restart_csv_used));
  for (PetscInt k = 0; k < out->nrestart_csv; k++) {
    PetscCall(PetscSNPrintf(key, sizeof(key), "csv_%" PetscInt_FMT, k));
    PetscCall(PhlexCheckpointReadString(viewer, "/output", key, out->restart_csv[k], sizeof(out->restart_csv[k])));
    PetscCall(PetscSNPrintf(key, sizeof(key), "csv_length_%" PetscInt_FMT, k));
    PetscCall(PhlexCheckpointReadReals(viewer, "/output", key, 1, &out->restart_csv_length[k]));
  }
  /* continuing in place: an error before this run's first checkpoint keeps the files the old one continues */
  {
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(out->comm, &rank));
    if (rank == 0 && realpath(out->dir, mine) && realpath(out->restart_dir, theirs) && !strcmp(mine, theirs)) out->keep_tmp = PETSC_TRUE;
    PetscCallMPI(MPI_Bcast(&out->keep_tmp, 1, MPIU_BOOL, 0, out->comm));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexOutputDestroy - destroys the output manager
@*/
PetscErrorCode PhlexOutputDestroy(PhlexOutput *out)
{
  PetscFunctionBeginUser;
  if (!*out) PetscFunctionReturn(0);
  Unlock(*out);
  PetscCall(PetscFree4((*out)->tmp, (*out)->final, (*out)->csv, (*out)->had_tmp));
  PetscCall(PetscFree2((*out)->writer_ctx, (*out)->writer_save));
  PetscCall(PetscFree3((*out)->restart_csv, (*out)->restart_csv_length, (*out)->restart_csv_used));
  PetscCall(PetscFree(*out));
  PetscFunctionReturn(0);
}
