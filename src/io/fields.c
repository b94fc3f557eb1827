/* Fields of one flexible body for ParaView: P1 vertex fields and cell fields on the body's mesh, one HDF5 file plus
   an XDMF index, written under temporary names (output.c). */
#include <phlex_impl.h>
#include <petscviewerhdf5.h>

struct _p_PhlexFieldWriter {
  PhlexOutput out;
  PhlexFlexible body;
  char        name[PHLEX_NAME_LEN];
  char        h5tmp[PETSC_MAX_PATH_LEN], xmftmp[PETSC_MAX_PATH_LEN];
  PetscViewer viewer;
  DM          dm_vertex, dm_cell6, dm_cell1; /* P1 vector, P0 6-component, P0 scalar */
  Vec         lv;                          /* local work vector of the body's velocity space */
  PetscInt    nsteps, nvertex, ncells;
  PetscReal  *times;
  PetscInt    nvfields, ncfields;
  char        vfields[8][PHLEX_NAME_LEN], cfields[8][PHLEX_NAME_LEN];
  PetscInt    cfield_nc[8];
  char        geometry_field[PHLEX_NAME_LEN];   /* vertex field holding time-dependent coordinates, or "" */
  PetscBool   rotate_out;                       /* vertex fields are turned by Rout after composing (inertial components) */
  PetscReal   Rout[9];
  /* segments: each checkpoint closes the HDF5 file being written (a closed file stays valid whatever happens to
     the run); the next snapshot opens segment seg, <name>_seg<seg>.h5 (segment 0: <name>.h5, with the mesh) */
  PetscInt    seg, seg_first;                   /* the current segment, its first snapshot */
  PetscInt   *snap_seg;                         /* segment of each snapshot */
};

static PetscErrorCode SegmentName(PhlexFieldWriter w, PetscInt seg, char name[], size_t len)
{
  PetscFunctionBeginUser;
  if (seg) PetscCall(PetscSNPrintf(name, len, "%s_seg%" PetscInt_FMT ".h5", w->name, seg));
  else PetscCall(PetscSNPrintf(name, len, "%s.h5", w->name));
  PetscFunctionReturn(0);
}

/* opens the HDF5 file of the current segment (the first one holds the mesh, which the XDMF index of every snapshot
   refers to) */
static PetscErrorCode OpenSegment(PhlexFieldWriter w)
{
  char file[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCall(SegmentName(w, w->seg, file, sizeof(file)));
  PetscCall(PhlexOutputFile(w->out, file, w->h5tmp));
  PetscCall(PetscViewerHDF5Open(w->out->comm, w->h5tmp, FILE_MODE_WRITE, &w->viewer));
  if (!w->seg) {
    PetscCall(PetscViewerPushFormat(w->viewer, PETSC_VIEWER_HDF5_VIZ));
    PetscCall(DMView(w->body->dm, w->viewer));
    PetscCall(PetscViewerPopFormat(w->viewer));
  }
  w->seg_first = w->nsteps;
  PetscFunctionReturn(0);
}

/* a restarted run: the snapshots and segments the checkpoint records (the segments copied or kept, PhlexOutputRestoreFile) */
static PetscErrorCode RestoreState(PhlexFieldWriter w)
{
  PetscViewer v = w->out->restart;
  char        group[PETSC_MAX_PATH_LEN], list[8 * (PHLEX_NAME_LEN + 8)], file[PETSC_MAX_PATH_LEN], tmp[PETSC_MAX_PATH_LEN];
  PetscBool   has;
  PetscReal  *buf;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(group, sizeof(group), "/output/fields_%s", w->name));
  PetscCall(PetscViewerHDF5HasGroup(v, group, &has));
  PetscCheck(has, w->out->comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint (option -restart) has no fields of body %s: it was written for another scene, or with -output_fields 0", w->name);
  PetscCall(PhlexCheckpointReadInt(v, group, "nsteps", &w->nsteps));
  PetscCall(PhlexCheckpointReadInt(v, group, "nseg", &w->seg));
  PetscCall(PetscMalloc2(w->nsteps + 1, &w->times, w->nsteps + 1, &w->snap_seg));
  PetscCall(PetscMalloc1(w->nsteps + 1, &buf));
  PetscCall(PhlexCheckpointReadReals(v, group, "times", w->nsteps, w->times));
  PetscCall(PhlexCheckpointReadReals(v, group, "segments", w->nsteps, buf));
  for (PetscInt k = 0; k < w->nsteps; k++) w->snap_seg[k] = (PetscInt)buf[k];
  PetscCall(PetscFree(buf));
  PetscCall(PhlexCheckpointReadString(v, group, "vertex_fields", list, sizeof(list)));
  for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
    PetscCheck(w->nvfields < 8, w->out->comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint's vertex fields of body %s are malformed", w->name);
    PetscCall(PetscStrncpy(w->vfields[w->nvfields++], tok, PHLEX_NAME_LEN));
  }
  PetscCall(PhlexCheckpointReadString(v, group, "cell_fields", list, sizeof(list)));
  for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
    char *colon = strchr(tok, ':');
    PetscCheck(colon && w->ncfields < 8, w->out->comm, PETSC_ERR_FILE_UNEXPECTED, "the checkpoint's cell fields of body %s are malformed", w->name);
    *colon                    = 0;
    w->cfield_nc[w->ncfields] = atoi(colon + 1);
    PetscCall(PetscStrncpy(w->cfields[w->ncfields++], tok, PHLEX_NAME_LEN));
  }
  for (PetscInt s = 0; s < w->seg; s++) {
    PetscCall(SegmentName(w, s, file, sizeof(file)));
    PetscCall(PhlexOutputFile(w->out, file, tmp));
    PetscCall(PhlexOutputRestoreFile(w->out, file, tmp, -1));
  }
  PetscFunctionReturn(0);
}

/* the writer's state for a checkpoint (registered with PhlexOutputAddWriter, called by PhlexOutputSaveState): closes
   the current segment (the snapshots written so far stay valid whatever happens to the run) and records the
   snapshots and segments (collective) */
static PetscErrorCode SaveState(void *ctx, PetscViewer v)
{
  PhlexFieldWriter w = (PhlexFieldWriter)ctx;
  char             group[PETSC_MAX_PATH_LEN], list[8 * (PHLEX_NAME_LEN + 8)] = "";
  PetscReal       *buf;
  size_t           len;

  PetscFunctionBeginUser;
  if (w->viewer) {
    PetscCall(PetscViewerDestroy(&w->viewer));
    PetscCall(PhlexFileSync(w->out->comm, w->h5tmp));
    w->seg++;
  }
  PetscCall(PetscSNPrintf(group, sizeof(group), "/output/fields_%s", w->name));
  PetscCall(PhlexCheckpointWriteInt(v, group, "nsteps", w->nsteps));
  PetscCall(PhlexCheckpointWriteInt(v, group, "nseg", w->seg));
  PetscCall(PetscMalloc1(w->nsteps + 1, &buf));
  for (PetscInt k = 0; k < w->nsteps; k++) buf[k] = (PetscReal)w->snap_seg[k];
  PetscCall(PhlexCheckpointWriteReals(v, group, "times", w->nsteps, w->times));
  PetscCall(PhlexCheckpointWriteReals(v, group, "segments", w->nsteps, buf));
  PetscCall(PetscFree(buf));
  for (PetscInt f = 0; f < w->nvfields; f++) {
    PetscCall(PetscStrlen(list, &len));
    PetscCall(PetscSNPrintf(list + len, sizeof(list) - len, "%s%s", f ? "," : "", w->vfields[f]));
  }
  PetscCall(PhlexCheckpointWriteString(v, group, "vertex_fields", list));
  list[0] = 0;
  for (PetscInt f = 0; f < w->ncfields; f++) {
    PetscCall(PetscStrlen(list, &len));
    PetscCall(PetscSNPrintf(list + len, sizeof(list) - len, "%s%s:%d", f ? "," : "", w->cfields[f], (int)w->cfield_nc[f]));
  }
  PetscCall(PhlexCheckpointWriteString(v, group, "cell_fields", list));
  PetscFunctionReturn(0);
}

static PetscErrorCode CreateOutputDM(DM dm, PetscInt degree, PetscInt nc, const char name[], DM *odm)
{
  PetscFE      fe;
  PetscSection s;

  PetscFunctionBeginUser;
  PetscCall(DMClone(dm, odm));
  PetscCall(PetscFECreateLagrange(PetscObjectComm((PetscObject)dm), 3, nc, PETSC_TRUE, degree, PETSC_DETERMINE, &fe));
  PetscCall(PetscObjectSetName((PetscObject)fe, name));
  PetscCall(DMSetField(*odm, 0, NULL, (PetscObject)fe));
  PetscCall(DMCreateDS(*odm));
  PetscCall(PetscFEDestroy(&fe));
  PetscCall(DMGetLocalSection(*odm, &s));
  PetscCall(PetscSectionSetFieldName(s, 0, name));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterCreate - opens <name>.h5 for a body's fields and writes its mesh

  Collective
@*/
PetscErrorCode PhlexFieldWriterCreate(PhlexOutput out, PhlexFlexible body, const char name[], PhlexFieldWriter *writer)
{
  PhlexFieldWriter w;
  char             file[PETSC_MAX_PATH_LEN];
  PetscInt         vStart, vEnd, cStart, cEnd, loc[2], glob[2];

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&w));
  w->out  = out;
  w->body = body;
  PetscCall(PetscStrncpy(w->name, name, sizeof(w->name)));
  PetscCall(PhlexOutputAddWriter(out, w, SaveState));
  /* the HDF5 file(s) first, then the index (the order of the list of results) */
  if (out->restart) PetscCall(RestoreState(w));
  else PetscCall(OpenSegment(w));
  PetscCall(PetscSNPrintf(file, sizeof(file), "%s.xmf", name));
  PetscCall(PhlexOutputFile(out, file, w->xmftmp));
  PetscCall(CreateOutputDM(body->dm, 1, 3, "vertex", &w->dm_vertex));
  PetscCall(CreateOutputDM(body->dm, 0, 6, "cell", &w->dm_cell6));
  {
    PetscSection     cs;
    const char *const names[] = {"xx", "yy", "zz", "xy", "yz", "xz"};
    PetscCall(DMGetLocalSection(w->dm_cell6, &cs));
    for (PetscInt c = 0; c < 6; c++) PetscCall(PetscSectionSetComponentName(cs, 0, c, names[c]));
  }
  PetscCall(CreateOutputDM(body->dm, 0, 1, "scalar", &w->dm_cell1));
  PetscCall(DMCreateLocalVector(body->dm, &w->lv));
  PetscCall(DMPlexGetDepthStratum(body->dm, 0, &vStart, &vEnd));
  PetscCall(DMPlexGetHeightStratum(body->dm, 0, &cStart, &cEnd));
  {
    Vec v;
    PetscCall(DMGetGlobalVector(w->dm_vertex, &v));
    PetscCall(VecGetSize(v, &loc[0]));
    PetscCall(DMRestoreGlobalVector(w->dm_vertex, &v));
    PetscCall(DMGetGlobalVector(w->dm_cell1, &v));
    PetscCall(VecGetSize(v, &loc[1]));
    PetscCall(DMRestoreGlobalVector(w->dm_cell1, &v));
  }
  glob[0]    = loc[0] / 3;
  glob[1]    = loc[1];
  w->nvertex = glob[0];
  w->ncells  = glob[1];
  *writer    = w;
  PetscFunctionReturn(0);
}

/* One snapshot of a field into the open segment, by HDF5 directly: PETSc's VecView flushes the file after every
   dataset (H5Fflush, with the MPI-IO driver an fsync), which made the output of a small run cost more than its steps
   (the tip-load cantilever: 12 ms per dataset, 73 % of the transient stage; issue 43). The layout is the one PETSc's
   visualisation format gave and the XDMF index reads: <group>/<dataset> of shape (snapshots, entities[, components]),
   one chunk per snapshot, each process writing its rows (the global vector's ownership range, PETSc's order); a
   dataset of one snapshot only (step < 0: the moving geometry's step_<k>) has no snapshot dimension. The file is
   flushed when the segment is closed (a checkpoint, the end). */
static PetscErrorCode WriteSlab(PhlexFieldWriter w, const char group[], const char dataset[], Vec out, PetscInt nc, PetscInt step)
{
  hid_t              file, grp, dset, fspace, mspace, plist, xfer;
  hsize_t            dims[3], maxdims[3], chunk[3], start[3], count[3];
  const int          rank = (step < 0 ? 1 : 2) + (nc > 1 ? 1 : 0);
  const PetscScalar *a;
  PetscInt           rstart, n, N;
  htri_t             has;

  PetscFunctionBeginUser;
  PetscCall(PetscViewerHDF5GetFileId(w->viewer, &file));
  PetscCall(VecGetOwnershipRange(out, &rstart, NULL));
  PetscCall(VecGetLocalSize(out, &n));
  PetscCall(VecGetSize(out, &N));
  {
    int d = 0;
    if (step >= 0) {
      dims[d] = (hsize_t)step + 1, maxdims[d] = H5S_UNLIMITED, chunk[d] = 1, start[d] = (hsize_t)step, count[d] = 1;
      d++;
    }
    dims[d] = maxdims[d] = chunk[d] = (hsize_t)(N / nc), start[d] = (hsize_t)(rstart / nc), count[d] = (hsize_t)(n / nc);
    d++;
    if (nc > 1) dims[d] = maxdims[d] = chunk[d] = count[d] = (hsize_t)nc, start[d] = 0;
  }
  has = group[0] == '/' && !group[1] ? 1 : H5Lexists(file, group, H5P_DEFAULT); /* the root group always exists */
  PetscCheck(has >= 0, w->out->comm, PETSC_ERR_LIB, "HDF5: cannot read the group %s of '%s'", group, w->h5tmp);
  grp = has ? H5Gopen2(file, group, H5P_DEFAULT) : H5Gcreate2(file, group, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  PetscCheck(grp >= 0, w->out->comm, PETSC_ERR_FILE_WRITE, "HDF5: cannot create the group %s in '%s'", group, w->h5tmp);
  has = H5Lexists(grp, dataset, H5P_DEFAULT);
  if (has > 0) {
    dset = H5Dopen2(grp, dataset, H5P_DEFAULT);
    PetscCheck(dset >= 0 && H5Dset_extent(dset, dims) >= 0, w->out->comm, PETSC_ERR_FILE_WRITE, "HDF5: cannot extend %s/%s in '%s'", group, dataset, w->h5tmp);
  } else {
    hid_t space = H5Screate_simple(rank, dims, maxdims);
    plist       = H5Pcreate(H5P_DATASET_CREATE);
    if (step >= 0) PetscCheck(H5Pset_chunk(plist, rank, chunk) >= 0, w->out->comm, PETSC_ERR_LIB, "HDF5: cannot chunk %s/%s", group, dataset);
    dset = H5Dcreate2(grp, dataset, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, plist, H5P_DEFAULT);
    PetscCheck(dset >= 0, w->out->comm, PETSC_ERR_FILE_WRITE, "HDF5: cannot create %s/%s in '%s'", group, dataset, w->h5tmp);
    H5Pclose(plist);
    H5Sclose(space);
  }
  fspace = H5Dget_space(dset);
  PetscCheck(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, NULL, count, NULL) >= 0, w->out->comm, PETSC_ERR_LIB, "HDF5: cannot select the rows of %s/%s", group, dataset);
  mspace = H5Screate_simple(rank, count, NULL);
  xfer   = H5Pcreate(H5P_DATASET_XFER);
#if defined(H5_HAVE_PARALLEL)
  PetscCheck(H5Pset_dxpl_mpio(xfer, H5FD_MPIO_COLLECTIVE) >= 0, w->out->comm, PETSC_ERR_LIB, "HDF5: cannot set a collective transfer");
#endif
  PetscCall(VecGetArrayRead(out, &a));
  PetscCheck(H5Dwrite(dset, H5T_NATIVE_DOUBLE, mspace, fspace, xfer, a) >= 0, w->out->comm, PETSC_ERR_FILE_WRITE, "HDF5: cannot write %s/%s to '%s'", group, dataset, w->h5tmp);
  PetscCall(VecRestoreArrayRead(out, &a));
  H5Pclose(xfer);
  H5Sclose(mspace);
  H5Sclose(fspace);
  H5Dclose(dset);
  H5Gclose(grp);
  PetscFunctionReturn(0);
}

/* the snapshot's index in its segment's datasets */
static PetscInt SlabIndex(PhlexFieldWriter w)
{
  return w->nsteps - 1 - w->seg_first;
}

/*@C
  PhlexFieldWriterBeginStep - starts output step k at time t [s] (or a mode number)
@*/
PetscErrorCode PhlexFieldWriterBeginStep(PhlexFieldWriter w, PetscReal t)
{
  PetscReal *times;
  PetscInt  *seg;

  PetscFunctionBeginUser;
  if (!w->viewer) PetscCall(OpenSegment(w));
  PetscCall(PetscMalloc2(w->nsteps + 1, &times, w->nsteps + 1, &seg));
  if (w->nsteps) PetscCall(PetscArraycpy(times, w->times, w->nsteps));
  if (w->nsteps) PetscCall(PetscArraycpy(seg, w->snap_seg, w->nsteps));
  times[w->nsteps] = t;
  seg[w->nsteps]   = w->seg;
  PetscCall(PetscFree2(w->times, w->snap_seg));
  w->times    = times;
  w->snap_seg = seg;
  w->nsteps++;
  { /* /time (snapshots x 1), as PETSc's format had it, for scripts that read the file without the index */
    Vec         tv;
    PetscMPIInt rank;
    PetscCallMPI(MPI_Comm_rank(w->out->comm, &rank));
    PetscCall(VecCreateMPI(w->out->comm, rank ? 0 : 1, 1, &tv));
    if (!rank) PetscCall(VecSetValue(tv, 0, t, INSERT_VALUES));
    PetscCall(VecAssemblyBegin(tv));
    PetscCall(VecAssemblyEnd(tv));
    PetscCall(WriteSlab(w, "/", "time", tv, 1, SlabIndex(w)));
    PetscCall(VecDestroy(&tv));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode RegisterField(PhlexFieldWriter w, PetscBool vertex, const char name[], PetscInt nc)
{
  PetscBool same;

  PetscFunctionBeginUser;
  if (vertex) {
    for (PetscInt i = 0; i < w->nvfields; i++) {
      PetscCall(PetscStrcmp(w->vfields[i], name, &same));
      if (same) PetscFunctionReturn(0);
    }
    PetscCheck(w->nvfields < 8, PETSC_COMM_SELF, PETSC_ERR_SUP, "too many vertex fields");
    PetscCall(PetscStrcpy(w->vfields[w->nvfields++], name));
  } else {
    for (PetscInt i = 0; i < w->ncfields; i++) {
      PetscCall(PetscStrcmp(w->cfields[i], name, &same));
      if (same) PetscFunctionReturn(0);
    }
    PetscCheck(w->ncfields < 8, PETSC_COMM_SELF, PETSC_ERR_SUP, "too many cell fields");
    w->cfield_nc[w->ncfields] = nc;
    PetscCall(PetscStrcpy(w->cfields[w->ncfields++], name));
  }
  PetscFunctionReturn(0);
}

/* the vertex values r + A x + Q (scale v) (see PhlexFieldWriterVertexField) in a local vector of dm_vertex */
static PetscErrorCode VertexValues(PhlexFieldWriter w, Vec v, PetscReal scale, const PetscReal *A, const PetscReal *r, PetscBool rotate, Vec lout)
{
  PetscSection       s, so, cs;
  PetscInt           vStart, vEnd;
  const PetscScalar *lv, *xc;
  PetscScalar       *lo;
  Vec                coords;

  PetscFunctionBeginUser;
  PetscCall(VecSet(w->lv, 0.0));
  if (v) {
    PetscCall(DMGlobalToLocalBegin(w->body->dm, v, INSERT_VALUES, w->lv));
    PetscCall(DMGlobalToLocalEnd(w->body->dm, v, INSERT_VALUES, w->lv));
  }
  PetscCall(DMGetLocalSection(w->body->dm, &s));
  PetscCall(DMGetLocalSection(w->dm_vertex, &so));
  PetscCall(DMPlexGetDepthStratum(w->body->dm, 0, &vStart, &vEnd));
  PetscCall(VecGetArrayRead(w->lv, &lv));
  PetscCall(VecGetArray(lout, &lo));
  PetscCall(DMGetCoordinatesLocal(w->body->dm, &coords));
  PetscCall(DMGetCoordinateSection(w->body->dm, &cs));
  PetscCall(VecGetArrayRead(coords, &xc));
  for (PetscInt p = vStart; p < vEnd; p++) {
    PetscInt off, oo, co;
    PetscCall(PetscSectionGetOffset(s, p, &off));
    PetscCall(PetscSectionGetOffset(so, p, &oo));
    for (PetscInt c = 0; c < 3; c++) lo[oo + c] = scale * lv[off + c];
    if (A) {
      PetscReal x[3], f[3];
      PetscCall(PetscSectionGetOffset(cs, p, &co));
      for (PetscInt c = 0; c < 3; c++) {
        f[c] = PetscRealPart(lo[oo + c]);
        x[c] = PetscRealPart(xc[co + c]) + (rotate ? f[c] : 0.0);
      }
      for (PetscInt c = 0; c < 3; c++) lo[oo + c] = r[c] + A[3 * c] * x[0] + A[3 * c + 1] * x[1] + A[3 * c + 2] * x[2] + (rotate ? 0.0 : f[c]);
    }
    if (w->rotate_out) {
      PetscReal f[3];
      for (PetscInt c = 0; c < 3; c++) f[c] = PetscRealPart(lo[oo + c]);
      for (PetscInt c = 0; c < 3; c++) lo[oo + c] = w->Rout[3 * c] * f[0] + w->Rout[3 * c + 1] * f[1] + w->Rout[3 * c + 2] * f[2];
    }
  }
  PetscCall(VecRestoreArrayRead(coords, &xc));
  PetscCall(VecRestoreArrayRead(w->lv, &lv));
  PetscCall(VecRestoreArray(lout, &lo));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterVertexField - writes a field of the body's velocity space at the vertices (P1), scaled to SI

  Collective

  Input Parameters:
+ w      - the writer
. name   - field name shown in ParaView
. v      - global vector of the body's velocity space (non-dimensional), or NULL for zero
. scale  - factor to SI
. A, r   - optional affine part (SI, A row-major): the field written is r + A x + Q (scale v) with x the vertex
           coordinates; NULL for none
- rotate - Q = A (a placement x -> r + A (x + u)) if true, else Q = I (a rigid velocity field r + A x plus v)
@*/
PetscErrorCode PhlexFieldWriterVertexField(PhlexFieldWriter w, const char name[], Vec v, PetscReal scale, const PetscReal *A, const PetscReal *r, PetscBool rotate)
{
  Vec out, lout;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_Output, 0, 0, 0, 0));
  PetscCall(DMGetLocalVector(w->dm_vertex, &lout));
  PetscCall(VertexValues(w, v, scale, A, r, rotate, lout));
  PetscCall(DMGetGlobalVector(w->dm_vertex, &out));
  PetscCall(DMLocalToGlobalBegin(w->dm_vertex, lout, INSERT_VALUES, out));
  PetscCall(DMLocalToGlobalEnd(w->dm_vertex, lout, INSERT_VALUES, out));
  {
    char dataset[PHLEX_NAME_LEN + 16];
    PetscCall(PetscSNPrintf(dataset, sizeof(dataset), "%s_vertex", name));
    PetscCall(WriteSlab(w, "/vertex_fields", dataset, out, 3, SlabIndex(w)));
  }
  {
    PetscBool geometry;
    PetscCall(PetscStrcmp(name, w->geometry_field, &geometry));
    if (geometry) {
      /* also as a plain (vertices x 3) dataset per step, the XDMF geometry of that step: ParaView's XDMF reader cannot
         cache a hyperslab geometry and complains at every step */
      char gname[64];
      PetscCall(PetscSNPrintf(gname, sizeof(gname), "step_%" PetscInt_FMT, w->nsteps - 1));
      PetscCall(WriteSlab(w, "/moving_geometry", gname, out, 3, -1));
    }
  }
  PetscCall(DMRestoreGlobalVector(w->dm_vertex, &out));
  PetscCall(DMRestoreLocalVector(w->dm_vertex, &lout));
  PetscCall(RegisterField(w, PETSC_TRUE, name, 3));
  PetscCall(PetscLogEventEnd(PHLEX_Output, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterVertexMax - the largest vertex magnitude of a field as PhlexFieldWriterVertexField would write it

  Collective
@*/
PetscErrorCode PhlexFieldWriterVertexMax(PhlexFieldWriter w, Vec v, PetscReal scale, const PetscReal *A, const PetscReal *r, PetscBool rotate, PetscReal *vmax)
{
  Vec                lout;
  const PetscScalar *lo;
  PetscInt           n;
  PetscReal          loc = 0;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalVector(w->dm_vertex, &lout));
  PetscCall(VertexValues(w, v, scale, A, r, rotate, lout));
  PetscCall(VecGetLocalSize(lout, &n));
  PetscCall(VecGetArrayRead(lout, &lo));
  for (PetscInt i = 0; i < n / 3; i++) loc = PetscMax(loc, PetscSqrtReal(PetscSqr(PetscRealPart(lo[3 * i])) + PetscSqr(PetscRealPart(lo[3 * i + 1])) + PetscSqr(PetscRealPart(lo[3 * i + 2]))));
  PetscCall(VecRestoreArrayRead(lout, &lo));
  PetscCall(DMRestoreLocalVector(w->dm_vertex, &lout));
  PetscCall(MPIU_Allreduce(&loc, vmax, 1, MPIU_REAL, MPIU_MAX, PetscObjectComm((PetscObject)w->dm_vertex)));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterStress - writes the cell averages of the stress [Pa] and their von Mises stress

  Collective
@*/
PetscErrorCode PhlexFieldWriterStress(PhlexFieldWriter w, Vec stress, PetscReal scale)
{
  Vec                avg, vm;
  PetscScalar       *a, *m;
  const PetscScalar *s;
  PetscSection       gs;
  PetscInt           nbs = w->body->nb_s, rstart;

  PetscFunctionBeginUser;
  PetscCall(PetscLogEventBegin(PHLEX_Output, 0, 0, 0, 0));
  PetscCall(DMGetGlobalVector(w->dm_cell6, &avg));
  PetscCall(DMGetGlobalVector(w->dm_cell1, &vm));
  PetscCall(DMGetGlobalSection(w->body->dm_s, &gs));
  PetscCall(VecGetOwnershipRange(stress, &rstart, NULL));
  PetscCall(VecGetArrayRead(stress, &s));
  PetscCall(VecGetArray(avg, &a));
  PetscCall(VecGetArray(vm, &m));
  for (PetscInt c = w->body->cStart; c < w->body->cEnd; c++) {
    PetscInt  off, i = c - w->body->cStart;
    PetscReal sig[6] = {0, 0, 0, 0, 0, 0};
    PetscCall(PetscSectionGetOffset(gs, c, &off));
    /* node-major Lagrange P_{k-1} (P0 or P1 at the vertices): the mean of the nodal values is the cell average */
    for (PetscInt j = 0; j < nbs; j++) sig[j % 6] += PetscRealPart(s[off - rstart + j]) * 6.0 / nbs * scale;
    /* stored in ParaView's order of 6-component arrays, XX YY ZZ XY YZ XZ */
    a[6 * i + 0] = sig[PHLEX_S_XX];
    a[6 * i + 1] = sig[PHLEX_S_YY];
    a[6 * i + 2] = sig[PHLEX_S_ZZ];
    a[6 * i + 3] = sig[PHLEX_S_XY];
    a[6 * i + 4] = sig[PHLEX_S_YZ];
    a[6 * i + 5] = sig[PHLEX_S_XZ];
    m[i] = PetscSqrtReal(0.5 * (PetscSqr(sig[0] - sig[1]) + PetscSqr(sig[1] - sig[2]) + PetscSqr(sig[2] - sig[0])) + 3.0 * (sig[3] * sig[3] + sig[4] * sig[4] + sig[5] * sig[5]));
  }
  PetscCall(VecRestoreArrayRead(stress, &s));
  PetscCall(VecRestoreArray(avg, &a));
  PetscCall(VecRestoreArray(vm, &m));
  PetscCall(WriteSlab(w, "/cell_fields", "stress_cell", avg, 6, SlabIndex(w)));
  PetscCall(WriteSlab(w, "/cell_fields", "von_mises_scalar", vm, 1, SlabIndex(w)));
  PetscCall(DMRestoreGlobalVector(w->dm_cell6, &avg));
  PetscCall(DMRestoreGlobalVector(w->dm_cell1, &vm));
  PetscCall(RegisterField(w, PETSC_FALSE, "stress", 6));
  PetscCall(RegisterField(w, PETSC_FALSE, "von_mises", 1));
  PetscCall(PetscLogEventEnd(PHLEX_Output, 0, 0, 0, 0));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterSetOutputRotation - turns every vertex field written from now on by R (row-major; body to inertial
  components), or stops doing so (R NULL)

  Not collective
@*/
PetscErrorCode PhlexFieldWriterSetOutputRotation(PhlexFieldWriter w, const PetscReal R[9])
{
  PetscFunctionBeginUser;
  w->rotate_out = R ? PETSC_TRUE : PETSC_FALSE;
  for (PetscInt k = 0; k < 9 && R; k++) w->Rout[k] = R[k];
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterSetGeometryField - uses a vertex field (written each step) as the time-dependent coordinates
@*/
PetscErrorCode PhlexFieldWriterSetGeometryField(PhlexFieldWriter w, const char name[])
{
  PetscFunctionBeginUser;
  PetscCall(PetscStrncpy(w->geometry_field, name, sizeof(w->geometry_field)));
  PetscFunctionReturn(0);
}

/* XDMF 2 index: a temporal collection of uniform grids, each attribute a hyperslab of the (step, entity, comp) datasets.
   Read by ParaView's "XDMF Reader" (the Xdmf3 readers drop hyperslab attributes). Precision 8: XDMF defaults to float32. */
static PetscErrorCode WriteXDMF(PhlexFieldWriter w)
{
  FILE       *fp;
  PetscMPIInt rank;
  char        h5name[PETSC_MAX_PATH_LEN], mesh[PETSC_MAX_PATH_LEN];

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(w->out->comm, &rank));
  if (rank) PetscFunctionReturn(0);
  PetscCall(SegmentName(w, 0, mesh, sizeof(mesh)));
  fp = fopen(w->xmftmp, "w");
  PetscCheck(fp, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot write '%s'", w->xmftmp);
  fprintf(fp, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n <Domain>\n");
  fprintf(fp, "  <Grid Name=\"%s\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", w->name);
  for (PetscInt k = 0; k < w->nsteps; k++) {
    /* the snapshot's segment, its index there and the segment's number of snapshots */
    PetscInt first = k, count = 0, i;
    while (first > 0 && w->snap_seg[first - 1] == w->snap_seg[k]) first--;
    while (first + count < w->nsteps && w->snap_seg[first + count] == w->snap_seg[k]) count++;
    i = k - first;
    PetscCall(SegmentName(w, w->snap_seg[k], h5name, sizeof(h5name)));
    fprintf(fp, "   <Grid Name=\"%s_%d\" GridType=\"Uniform\">\n    <Time Value=\"%.12g\"/>\n", w->name, (int)k, (double)w->times[k]);
    fprintf(fp, "    <Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"%d\">\n     <DataItem Dimensions=\"%d 4\" NumberType=\"Int\" Format=\"HDF\">%s:/viz/topology/cells</DataItem>\n    </Topology>\n", (int)w->ncells, (int)w->ncells, mesh);
    if (w->geometry_field[0]) {
      fprintf(fp, "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"%d 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/moving_geometry/step_%d</DataItem>\n    </Geometry>\n", (int)w->nvertex, h5name, (int)k);
    } else {
      fprintf(fp, "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"%d 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/geometry/vertices</DataItem>\n    </Geometry>\n", (int)w->nvertex, mesh);
    }
    for (PetscInt f = 0; f < w->nvfields; f++) {
      fprintf(fp, "    <Attribute Name=\"%s\" AttributeType=\"Vector\" Center=\"Node\">\n     <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 %d 3\" Type=\"HyperSlab\">\n", w->vfields[f], (int)w->nvertex);
      fprintf(fp, "      <DataItem Dimensions=\"3 3\" Format=\"XML\">%d 0 0 1 1 1 1 %d 3</DataItem>\n", (int)i, (int)w->nvertex);
      fprintf(fp, "      <DataItem Dimensions=\"%d %d 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/vertex_fields/%s_vertex</DataItem>\n     </DataItem>\n    </Attribute>\n", (int)count, (int)w->nvertex, h5name, w->vfields[f]);
    }
    for (PetscInt f = 0; f < w->ncfields; f++) {
      const PetscInt nc = w->cfield_nc[f];
      if (nc == 1) { /* PETSc stores one-component cell fields as (step, cell) */
        fprintf(fp, "    <Attribute Name=\"%s\" AttributeType=\"Scalar\" Center=\"Cell\">\n     <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 %d\" Type=\"HyperSlab\">\n", w->cfields[f], (int)w->ncells);
        fprintf(fp, "      <DataItem Dimensions=\"3 2\" Format=\"XML\">%d 0 1 1 1 %d</DataItem>\n", (int)i, (int)w->ncells);
        fprintf(fp, "      <DataItem Dimensions=\"%d %d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/cell_fields/%s_scalar</DataItem>\n     </DataItem>\n    </Attribute>\n", (int)count, (int)w->ncells, h5name, w->cfields[f]);
      } else {
        fprintf(fp, "    <Attribute Name=\"%s\" AttributeType=\"Matrix\" Center=\"Cell\">\n     <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 %d %d\" Type=\"HyperSlab\">\n", w->cfields[f], (int)w->ncells, (int)nc);
        fprintf(fp, "      <DataItem Dimensions=\"3 3\" Format=\"XML\">%d 0 0 1 1 1 1 %d %d</DataItem>\n", (int)i, (int)w->ncells, (int)nc);
        fprintf(fp, "      <DataItem Dimensions=\"%d %d %d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/cell_fields/%s_cell</DataItem>\n     </DataItem>\n    </Attribute>\n", (int)count, (int)w->ncells, (int)nc, h5name, w->cfields[f]);
      }
    }
    fprintf(fp, "   </Grid>\n");
  }
  fprintf(fp, "  </Grid>\n </Domain>\n</Xdmf>\n");
  PetscCheck(!fclose(fp), PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "cannot write '%s'", w->xmftmp);
  PetscFunctionReturn(0);
}

/*@C
  PhlexFieldWriterDestroy - closes the HDF5 file and writes the XDMF index (both renamed by PhlexOutputCommit)

  Collective
@*/
PetscErrorCode PhlexFieldWriterDestroy(PhlexFieldWriter *writer)
{
  PhlexFieldWriter w = *writer;

  PetscFunctionBeginUser;
  if (!w) PetscFunctionReturn(0);
  PetscCall(PetscViewerDestroy(&w->viewer));
  PetscCall(WriteXDMF(w));
  PetscCall(DMDestroy(&w->dm_vertex));
  PetscCall(DMDestroy(&w->dm_cell6));
  PetscCall(DMDestroy(&w->dm_cell1));
  PetscCall(VecDestroy(&w->lv));
  PetscCall(PetscFree2(w->times, w->snap_seg));
  PetscCall(PetscFree(*writer));
  PetscFunctionReturn(0);
}
