/* gmsh -> DMPlex: file checks, physical names, distribution, cell and group validation. */
#include <phlex_impl.h>
#include <petscsf.h>

/* The physical names of a gmsh file ($PhysicalNames is ASCII text in ASCII and binary files of versions 2.2
   and 4.1). Rank 0 reads and checks the file, then broadcasts the table, so that a bad file gives the same clear
   error on every rank before PETSc's reader runs. */
typedef struct {
  PetscInt  status; /* 0 ok, >0 error code below */
  PetscInt  ngroups;
  PetscReal version;
  PetscInt  binary;
  char      detail[256];
} PhlexMeshHeader;

enum { MESH_OK, MESH_NO_FILE, MESH_NOT_GMSH, MESH_BAD_VERSION, MESH_TRUNCATED, MESH_BAD_NAMES, MESH_IS_DIR, MESH_HIGH_ORDER };

/* the number of nodes of gmsh's first-order element types (line, triangle, quadrangle, tetrahedron, hexahedron,
   prism, pyramid, point); 0: any other type, which is of order 2 or more (tet10 is 11, tet20 29, ...) */
static int FirstOrderNodes(int type)
{
  switch (type) {
  case 1: return 2;
  case 2: return 3;
  case 3: return 4;
  case 4: return 4;
  case 5: return 8;
  case 6: return 6;
  case 7: return 5;
  case 15: return 1;
  default: return 0;
  }
}

/* the first element type of order 2 or more in the $Elements section (0: none, -1: the section could not be read,
   which PETSc's reader then reports). PETSc 3.18's gmsh reader keeps only the corner nodes of a 10-node
   tetrahedron (its -dm_plex_gmsh_highorder gives a P1 coordinate field), so the file itself is read: ASCII and
   binary, versions 2.2 and 4.1; with first-order elements only, a binary block is skipped by its size. */
static int HighOrderElementType(FILE *fp, double version, int binary)
{
  char line[1024];
  while (fgets(line, sizeof(line), fp))
    if (!strncmp(line, "$Elements", 9)) break;
  if (feof(fp)) return -1;
  if (version >= 4.0) {
    unsigned long long nblocks, nelem, tmin, tmax;
    if (!binary) {
      if (!fgets(line, sizeof(line), fp) || sscanf(line, "%llu %llu %llu %llu", &nblocks, &nelem, &tmin, &tmax) != 4) return -1;
    } else {
      size_t hd[4];
      if (fread(hd, sizeof(size_t), 4, fp) != 4) return -1;
      nblocks = hd[0];
    }
    for (unsigned long long b = 0; b < nblocks; b++) {
      int                dim, tag, type, nn;
      unsigned long long n;
      if (!binary) {
        if (!fgets(line, sizeof(line), fp) || sscanf(line, "%d %d %d %llu", &dim, &tag, &type, &n) != 4) return -1;
      } else {
        int    it[3];
        size_t sn;
        if (fread(it, sizeof(int), 3, fp) != 3 || fread(&sn, sizeof(size_t), 1, fp) != 1) return -1;
        type = it[2];
        n    = sn;
      }
      nn = FirstOrderNodes(type);
      if (!nn) return type;
      if (!binary) {
        for (unsigned long long e = 0; e < n; e++)
          if (!fgets(line, sizeof(line), fp)) return -1;
      } else if (fseek(fp, (long)(n * (unsigned long long)(1 + nn) * sizeof(size_t)), SEEK_CUR)) return -1;
    }
    return 0;
  }
  {
    long long nelem;
    if (!fgets(line, sizeof(line), fp) || sscanf(line, "%lld", &nelem) != 1) return -1;
    if (!binary) {
      for (long long e = 0; e < nelem; e++) {
        int num, type;
        if (!fgets(line, sizeof(line), fp) || sscanf(line, "%d %d", &num, &type) != 2) return -1;
        if (!FirstOrderNodes(type)) return type;
      }
      return 0;
    }
    for (long long e = 0; e < nelem;) {
      int hd[3], nn;
      if (fread(hd, sizeof(int), 3, fp) != 3 || hd[1] <= 0) return -1;
      nn = FirstOrderNodes(hd[0]);
      if (!nn) return hd[0];
      if (fseek(fp, (long)hd[1] * (1 + hd[2] + nn) * (long)sizeof(int), SEEK_CUR)) return -1;
      e += hd[1];
    }
    return 0;
  }
}

static void ReadHeaderRank0(const char file[], PhlexMeshHeader *h, PhlexPhysicalGroup **groups)
{
  FILE *fp;
  char  line[1024];
  int   cnt = 0, ngroups = 0;
  long  size;

  h->status  = MESH_OK;
  h->ngroups = 0;
  *groups    = NULL;
  fp         = fopen(file, "rb");
  if (!fp) {
    h->status = MESH_NO_FILE;
    return;
  }
  /* a directory can be opened on Linux, but not read */
  if (!fgets(line, sizeof(line), fp)) {
    h->status = ferror(fp) ? MESH_IS_DIR : MESH_NOT_GMSH;
    fclose(fp);
    return;
  }
  if (strncmp(line, "$MeshFormat", 11)) {
    /* gmsh's format 1 has no $MeshFormat section: it starts with $NOD (or $PhysicalNames) */
    if (!strncmp(line, "$NOD", 4) || !strncmp(line, "$PhysicalNames", 14)) {
      h->status = MESH_BAD_VERSION;
      snprintf(h->detail, sizeof(h->detail), "1 (it starts with $NOD)");
    } else h->status = MESH_NOT_GMSH;
    fclose(fp);
    return;
  }
  {
    double v;
    int    bin = 0, ds = 0;
    if (!fgets(line, sizeof(line), fp) || sscanf(line, "%lf %d %d", &v, &bin, &ds) != 3) {
      h->status = MESH_NOT_GMSH;
      fclose(fp);
      return;
    }
    h->version = v;
    h->binary  = bin;
    if (!((v >= 2.0 && v < 3.0) || (v >= 4.1 && v < 4.2))) {
      h->status = MESH_BAD_VERSION;
      snprintf(h->detail, sizeof(h->detail), "%g", v);
      fclose(fp);
      return;
    }
  }
  /* physical names: between $PhysicalNames and $EndPhysicalNames, before the (possibly binary) data */
  while (fgets(line, sizeof(line), fp)) {
    if (!strncmp(line, "$PhysicalNames", 14)) {
      if (!fgets(line, sizeof(line), fp) || sscanf(line, "%d", &ngroups) != 1 || ngroups < 0) {
        h->status = MESH_BAD_NAMES;
        line[strcspn(line, "\r\n")] = 0;
        snprintf(h->detail, sizeof(h->detail), "its count '%.200s' is not a number of names", feof(fp) ? "" : line);
        fclose(fp);
        return;
      }
      *groups = (PhlexPhysicalGroup *)calloc((size_t)(ngroups > 0 ? ngroups : 1), sizeof(PhlexPhysicalGroup));
      for (cnt = 0; cnt < ngroups; cnt++) {
        int   dim, tag;
        char *q0, *q1;
        if (!fgets(line, sizeof(line), fp) || sscanf(line, "%d %d", &dim, &tag) != 2 || !(q0 = strchr(line, '"')) || !(q1 = strchr(q0 + 1, '"'))) {
          h->status = MESH_BAD_NAMES;
          line[strcspn(line, "\r\n")] = 0; /* the entry in the one-line message, without its line end */
          snprintf(h->detail, sizeof(h->detail), "entry '%.200s'", line);
          fclose(fp);
          return;
        }
        *q1 = 0;
        snprintf((*groups)[cnt].name, PHLEX_NAME_LEN, "%s", q0 + 1);
        (*groups)[cnt].dim = dim;
        (*groups)[cnt].tag = tag;
      }
      h->ngroups = ngroups;
      break;
    }
    if (!strncmp(line, "$Nodes", 6) || !strncmp(line, "$Entities", 9)) break;
  }
  /* a complete file has an $EndElements marker near its end */
  fseek(fp, 0, SEEK_END);
  size = ftell(fp);
  {
    long  n   = size < 65536 ? size : 65536;
    char *buf = (char *)malloc((size_t)n + 1);
    int   found = 0;
    fseek(fp, size - n, SEEK_SET);
    if (buf && fread(buf, 1, (size_t)n, fp) == (size_t)n) {
      for (long i = 0; i + 12 <= n; i++)
        if (!memcmp(buf + i, "$EndElements", 12)) {
          found = 1;
          break;
        }
    }
    free(buf);
    if (!found) h->status = MESH_TRUNCATED;
  }
  if (h->status == MESH_OK) {
    int type;
    fseek(fp, 0, SEEK_SET);
    type = HighOrderElementType(fp, h->version, h->binary);
    if (type > 0) {
      h->status = MESH_HIGH_ORDER;
      snprintf(h->detail, sizeof(h->detail), "%d%s", type, type == 8 ? ", the 3-node line" : type == 9 ? ", the 6-node triangle" : type == 11 ? ", the 10-node tetrahedron" : type == 29 ? ", the 20-node tetrahedron" : "");
    }
  }
  fclose(fp);
}

/*@C
  PhlexMeshReadPhysicalNames - checks that a file is a complete gmsh 2.2/4.1 mesh and returns its physical groups

  Collective

  Input Parameters:
+ comm - communicator
. file - gmsh file name
- what - object named in error messages (e.g. "body cantilever (option -body0_dm_plex_filename)")

  Output Parameters:
+ ngroups - number of physical groups
- groups  - the groups (free with PetscFree())
@*/
PetscErrorCode PhlexMeshReadPhysicalNames(MPI_Comm comm, const char file[], const char what[], PetscInt *ngroups, PhlexPhysicalGroup **groups)
{
  PhlexMeshHeader     h;
  PhlexPhysicalGroup *g0 = NULL;
  PetscMPIInt         rank;

  PetscFunctionBeginUser;
  PetscCall(PetscMemzero(&h, sizeof(h)));
  PetscCallMPI(MPI_Comm_rank(comm, &rank));
  if (rank == 0) ReadHeaderRank0(file, &h, &g0);
  PetscCallMPI(MPI_Bcast(&h, (PetscMPIInt)sizeof(h), MPI_BYTE, 0, comm));
  switch (h.status) {
  case MESH_NO_FILE:
    SETERRQ(comm, PETSC_ERR_FILE_OPEN, "%s: cannot open mesh file '%s' (missing or unreadable)", what, file);
  case MESH_IS_DIR:
    SETERRQ(comm, PETSC_ERR_FILE_READ, "%s: cannot read mesh file '%s' (is it a directory?)", what, file);
  case MESH_NOT_GMSH:
    SETERRQ(comm, PETSC_ERR_FILE_UNEXPECTED, "%s: '%s' is not a gmsh mesh file (it does not start with $MeshFormat)", what, file);
  case MESH_BAD_VERSION:
    SETERRQ(comm, PETSC_ERR_SUP, "%s: mesh file '%s' has gmsh format version %s; supported are 2.2 and 4.1 (gmsh -format msh41 or msh22)", what, file, h.detail);
  case MESH_BAD_NAMES:
    SETERRQ(comm, PETSC_ERR_FILE_UNEXPECTED, "%s: mesh file '%s' has a malformed $PhysicalNames section (%s)", what, file, h.detail);
  case MESH_TRUNCATED:
    SETERRQ(comm, PETSC_ERR_FILE_UNEXPECTED, "%s: mesh file '%s' is incomplete (no $EndElements section): was it truncated?", what, file);
  case MESH_HIGH_ORDER:
    /* phlex's tetrahedra are affine (one Jacobian per cell: element.c, the stress elimination, the frame integrals);
       PETSc 3.18's reader would keep the corner nodes only and drop the curved geometry without a word */
    SETERRQ(comm, PETSC_ERR_SUP, "%s: mesh file '%s' has elements of order 2 or more (gmsh element type %s): phlex's tetrahedra are straight-sided (affine), and the reader would keep their corner nodes only, dropping the curved geometry; mesh with order 1 (gmsh -3 -order 1, Mesh.ElementOrder = 1) and raise the velocity degree instead (-<body>_petscspace_degree 2)", what, file, h.detail);
  default:
    break;
  }
  *ngroups = h.ngroups;
  PetscCall(PetscCalloc1(PetscMax(h.ngroups, 1), groups));
  if (rank == 0 && h.ngroups) PetscCall(PetscArraycpy(*groups, g0, h.ngroups));
  free(g0);
  if (h.ngroups) PetscCallMPI(MPI_Bcast(*groups, (PetscMPIInt)(h.ngroups * sizeof(PhlexPhysicalGroup)), MPI_BYTE, 0, comm));
  PetscFunctionReturn(0);
}

static const char *DimName(PetscInt dim)
{
  switch (dim) {
  case 0:
    return "point";
  case 1:
    return "curve";
  case 2:
    return "surface";
  case 3:
    return "volume";
  default:
    return "?";
  }
}

/*@C
  PhlexMeshFindGroup - finds a physical group of a body's mesh by name, checks its dimension and that it is not empty

  Collective

  Input Parameters:
+ body   - the body (mesh loaded)
. name   - the physical name
. dim    - the required dimension (2 surface, 3 volume)
- option - the option that named the group (for messages)

  Output Parameter:
. tag - the physical tag (value of "Face Sets" or "Cell Sets")
@*/
PetscErrorCode PhlexMeshFindGroup(PhlexFlexible body, const char name[], PetscInt dim, const char option[], PetscInt *tag)
{
  char      avail[1024] = "";
  PetscInt  found = -1, count = 0, gcount = 0;
  DMLabel   label;
  PetscBool same;

  PetscFunctionBeginUser;
  for (PetscInt g = 0; g < body->ngroups; g++) {
    PetscCall(PetscStrcmp(body->groups[g].name, name, &same));
    if (same && body->groups[g].dim == dim) found = g;
    else if (same && found < 0) found = -2 - g;
  }
  if (found < 0) {
    for (PetscInt g = 0; g < body->ngroups; g++) {
      char item[128];
      PetscCall(PetscSNPrintf(item, sizeof(item), "%s%s (%s)", g ? ", " : "", body->groups[g].name, DimName(body->groups[g].dim)));
      PetscCall(PetscStrlcat(avail, item, sizeof(avail)));
    }
    PetscCheck(found != -1, body->comm, PETSC_ERR_USER_INPUT, "body %s: option %s: physical group '%s' not found in mesh file '%s' (groups in the file: %s)", body->name, option, name, body->mesh_file, body->ngroups ? avail : "none");
    SETERRQ(body->comm, PETSC_ERR_USER_INPUT, "body %s: option %s: physical group '%s' in mesh file '%s' is a %s, but a %s is required", body->name, option, name, body->mesh_file, DimName(body->groups[-2 - found].dim), DimName(dim));
  }
  *tag = body->groups[found].tag;
  PetscCall(DMGetLabel(body->dm, dim == 3 ? "Cell Sets" : "Face Sets", &label));
  if (label) {
    IS is;
    PetscCall(DMLabelGetStratumIS(label, *tag, &is));
    if (is) {
      const PetscInt *pts;
      PetscInt        n, depth;
      PetscCall(ISGetLocalSize(is, &n));
      PetscCall(ISGetIndices(is, &pts));
      for (PetscInt i = 0; i < n; i++) {
        PetscCall(DMPlexGetPointDepth(body->dm, pts[i], &depth));
        if (depth == dim) count++;
      }
      PetscCall(ISRestoreIndices(is, &pts));
      PetscCall(ISDestroy(&is));
    }
  }
  PetscCallMPI(MPI_Allreduce(&count, &gcount, 1, MPIU_INT, MPI_SUM, body->comm));
  PetscCheck(gcount > 0, body->comm, PETSC_ERR_USER_INPUT, "body %s: option %s: physical group '%s' (%s, tag %" PetscInt_FMT ") in mesh file '%s' has no elements", body->name, option, name, DimName(dim), *tag, body->mesh_file);
  PetscFunctionReturn(0);
}

/* The whole body on one process (-<prefix>process, or -whole_bodies: the process with the fewest cells of the bodies
   placed so far, the lowest such): a shell partition that sends every cell of the reading rank there. The body's
   sparse solves can then be sequential and run concurrently with the other processes' bodies (PC phlexbordered). */
static PetscErrorCode PlaceWhole(PhlexFlexible body, DM dm, PetscPartitioner part)
{
  PetscInt   *sizes, *points, cStart, cEnd, n;
  PetscInt64  total, local;
  PetscMPIInt size;
  PetscBool   given;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(body->comm, &size));
  PetscCall(PetscOptionsHasName(NULL, body->prefix, "-petscpartitioner_type", &given));
  PetscCheck(!given, body->comm, PETSC_ERR_USER_INPUT, "body %s: -%spetscpartitioner_type splits the body's cells over the processes, while %s%s puts the whole body on one process: give one of them", body->name, body->prefix, body->process >= 0 ? "-" : "-whole_bodies", body->process >= 0 ? body->prefix : "");
  if (body->process < 0) { /* -whole_bodies (a given -process was checked with the body's options) */
    body->process = 0;
    for (PetscMPIInt r = 1; r < size; r++)
      if (body->part->process_cells[r] < body->part->process_cells[body->process]) body->process = r;
  }
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  n     = cEnd - cStart;
  local = n;
  PetscCallMPI(MPI_Allreduce(&local, &total, 1, MPIU_INT64, MPI_SUM, body->comm));
  if (body->part->process_cells) body->part->process_cells[body->process] += total;
  PetscCall(PetscCalloc1(size, &sizes));
  PetscCall(PetscMalloc1(PetscMax(n, 1), &points));
  sizes[body->process] = n;
  for (PetscInt c = 0; c < n; c++) points[c] = c;
  PetscCall(PetscPartitionerSetType(part, PETSCPARTITIONERSHELL));
  PetscCall(PetscPartitionerShellSetPartition(part, size, sizes, points));
  PetscCall(PetscFree(sizes));
  PetscCall(PetscFree(points));
  PetscFunctionReturn(0);
}

/*@C
  PhlexMeshLoad - reads the body's gmsh file into a distributed, interpolated DMPlex and checks its cells

  Collective

  Input Parameter:
. body - the body (mesh_file set)

  Options Database Keys (body prefix):
+ -dm_refine <n>          - uniform refinements after distribution
. -dm_plex_check_all      - DMPlex consistency checks
. -petscpartitioner_type  - partitioner: phlexmetis (default), ptscotch
- -process <r>            - the whole body on process r (also -whole_bodies, scene.c)

  Notes:
  Tetrahedra only. Hexahedra are refused: with discontinuous Q_{k-1} stress the stress space does not contain the
  strains of the Q_k velocity, so the element-wise stress elimination is not the displacement stiffness and Q1/Q0
  has hourglass (zero-energy) modes.
@*/
PetscErrorCode PhlexMeshLoad(PhlexFlexible body)
{
  DM               dm, dmdist = NULL;
  PetscPartitioner part;
  PetscInt         dim, cStart, cEnd, bad = -1, gbad;
  DMPolytopeType   ct, badtype = DM_POLYTOPE_UNKNOWN;
  char             what[512];
  PetscMPIInt      size;

  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(what, sizeof(what), "body %s (option -%sdm_plex_filename)", body->name, body->prefix));
  PetscCall(PhlexMeshReadPhysicalNames(body->comm, body->mesh_file, what, &body->ngroups, &body->groups));
  PetscCall(DMPlexCreateFromFile(body->comm, body->mesh_file, body->name, PETSC_TRUE, &dm));
  PetscCall(PetscObjectSetName((PetscObject)dm, body->name));
  PetscCall(DMGetDimension(dm, &dim));
  PetscCheck(dim == 3, body->comm, PETSC_ERR_SUP, "body %s: mesh file '%s' is %" PetscInt_FMT "D; phlex needs a 3D volume mesh (gmsh -3)", body->name, body->mesh_file, dim);

  /* all cells must be tetrahedra (checked before distribution, on the reading rank) */
  PetscCall(DMPlexGetHeightStratum(dm, 0, &cStart, &cEnd));
  for (PetscInt c = cStart; c < cEnd; c++) {
    PetscCall(DMPlexGetCellType(dm, c, &ct));
    if (ct != DM_POLYTOPE_TETRAHEDRON) {
      bad     = c;
      badtype = ct;
      break;
    }
  }
  {
    PetscInt loc[2] = {bad >= 0 ? 1 : 0, (PetscInt)badtype}, glob[2];
    PetscCallMPI(MPI_Allreduce(loc, glob, 2, MPIU_INT, MPI_MAX, body->comm));
    gbad = glob[0];
    if (gbad) {
      PetscCheck(glob[1] != DM_POLYTOPE_HEXAHEDRON, body->comm, PETSC_ERR_SUP,
                 "body %s: mesh file '%s' has hexahedra; phlex supports tetrahedra only: with discontinuous Q_{k-1} stress the stress space does not contain the strains of Q_k velocities, so the element-wise stress elimination is not the displacement stiffness (Q1/Q0 has hourglass modes). Mesh the body with tetrahedra (no Recombine)",
                 body->name, body->mesh_file);
      SETERRQ(body->comm, PETSC_ERR_SUP, "body %s: mesh file '%s' has cells of type %s; phlex supports tetrahedra only", body->name, body->mesh_file, DMPolytopeTypes[glob[1]]);
    }
  }

  PetscCallMPI(MPI_Comm_size(body->comm, &size));
  {
    PetscBool reorder;
    PetscCall(PetscOptionsHasName(NULL, body->prefix, "-dm_plex_reorder", &reorder));
    PetscCheck(!reorder, body->comm, PETSC_ERR_USER_INPUT, "body %s: -%sdm_plex_reorder: phlex numbers the mesh before distributing it (PETSc's reordering comes after, and breaks a distributed mesh); use -%snode_order rcm (the default) or file", body->name, body->prefix, body->prefix);
  }
  if (body->rcm) {
    /* on the reading rank, before the distribution (DMPlexPermute ignores a distributed mesh's star forest); the
       labels (physical groups) follow their points */
    IS perm;
    DM pdm;
    PetscCall(DMPlexGetOrdering(dm, MATORDERINGRCM, NULL, &perm));
    PetscCall(DMPlexPermute(dm, perm, &pdm));
    PetscCall(ISDestroy(&perm));
    PetscCall(DMDestroy(&dm));
    dm = pdm;
    PetscCall(PetscObjectSetName((PetscObject)dm, body->name));
  }
  PetscCall(DMSetOptionsPrefix(dm, body->prefix));
  PetscCall(DMPlexGetPartitioner(dm, &part));
  PetscCall(PetscObjectSetOptionsPrefix((PetscObject)part, body->prefix));
  /* METIS by default: as fast as PTScotch on the bar (BENCHMARKS.md), and the same partition at every run (PTScotch's
     varies), so that a checkpoint's layout is found again at restart */
  PetscCall(PetscPartitionerSetType(part, "phlexmetis"));
  PetscCall(PetscPartitionerSetFromOptions(part));
  if (size > 1 && (body->process >= 0 || body->part->process_cells)) PetscCall(PlaceWhole(body, dm, part));
  if (size > 1) {
    PetscCall(DMPlexDistribute(dm, 0, NULL, &dmdist));
    if (dmdist) {
      PetscCall(DMDestroy(&dm));
      dm = dmdist;
      /* the distributed DM does not inherit the prefix: without it -<prefix>dm_refine, -<prefix>dm_view ... would be
         ignored in parallel */
      PetscCall(DMSetOptionsPrefix(dm, body->prefix));
    }
  }
  /* distributed above: DMSetFromOptions would distribute it again (PETSc's default -dm_distribute), with the default
     partitioner of the new DM, which changed the partition from run to run */
  PetscCall(DMPlexDistributeSetDefault(dm, PETSC_FALSE));
  {
    PetscBool again = PETSC_FALSE, overlap;
    PetscCall(PetscOptionsGetBool(NULL, body->prefix, "-dm_distribute", &again, NULL));
    PetscCall(PetscOptionsHasName(NULL, body->prefix, "-dm_distribute_overlap", &overlap));
    PetscCheck(!overlap, body->comm, PETSC_ERR_USER_INPUT, "body %s: -%sdm_distribute_overlap: phlex needs non-overlapping parts (every cell on one process: the operators sum over the local cells)", body->name, body->prefix);
    PetscCheck(!again, body->comm, PETSC_ERR_USER_INPUT, "body %s: -%sdm_distribute: phlex distributes the mesh itself (-%spetscpartitioner_type chooses how); a second distribution is not supported", body->name, body->prefix, body->prefix);
  }
  PetscCall(DMSetFromOptions(dm)); /* -<prefix>dm_refine, -<prefix>dm_plex_check_all, ... */
  /* extra uniform refinements requested by a convergence study */
  for (PetscInt r = 0; r < body->extra_refinements; r++) {
    DM rdm;
    PetscCall(DMRefine(dm, body->comm, &rdm));
    PetscCall(DMDestroy(&dm));
    dm = rdm;
  }
  {
    /* overlapping cells would be assembled twice (the operators sum over the local cells) */
    PetscInt overlap;
    PetscCall(DMPlexGetOverlap(dm, &overlap));
    PetscCheck(overlap == 0, body->comm, PETSC_ERR_USER_INPUT, "body %s: a distributed mesh with overlap %" PetscInt_FMT " (option -%sdm_distribute_overlap): phlex needs non-overlapping parts (every cell on one process)", body->name, overlap, body->prefix);
  }
  PetscCall(DMViewFromOptions(dm, NULL, "-dm_view"));
  body->dm = dm;
  PetscFunctionReturn(0);
}

/*@C
  PhlexMeshCheckGeometry - refuses inverted or degenerate cells and computes the bounding box

  Collective

  Notes:
  PETSc reorients gmsh tetrahedra to its own convention; a cell whose Jacobian determinant is then negative was
  inverted in the file, and one with a volume below 1e-10 of the cube of its longest edge is degenerate.
@*/
PetscErrorCode PhlexMeshCheckGeometry(PhlexFlexible body)
{
  PetscInt     cStart, cEnd, info[2] = {-1, 0}, ginfo[2];
  PetscReal    v0[3], J[9], invJ[9], detJ, loc[6], glob[6];
  PetscReal    bad_centroid[3] = {0, 0, 0};
  Vec          coords;
  const PetscScalar *x;
  PetscInt     n;
  PetscMPIInt  rank;

  PetscReal    worst[4] = {PETSC_MAX_REAL, 0, 0, 0}; /* the flattest cell: flatness, centroid */
  PetscInt     nflat = 0;

  PetscFunctionBeginUser;
  PetscCall(DMPlexGetHeightStratum(body->dm, 0, &cStart, &cEnd));
  for (PetscInt c = cStart; c < cEnd && info[0] < 0; c++) {
    PetscReal          hmax = 0, hmin = PETSC_MAX_REAL, amax = 0, flat, xs[4][3];
    PetscInt           nc;
    PetscBool          isDG;
    const PetscScalar *array;
    PetscScalar       *cc = NULL;
    PetscCall(DMPlexComputeCellGeometryAffineFEM(body->dm, c, v0, J, invJ, &detJ));
    PetscCall(DMPlexGetCellCoordinates(body->dm, c, &isDG, &nc, &array, &cc));
    for (PetscInt i = 0; i < 4; i++)
      for (PetscInt d = 0; d < 3; d++) xs[i][d] = PetscRealPart(cc[3 * i + d]);
    PetscCall(DMPlexRestoreCellCoordinates(body->dm, c, &isDG, &nc, &array, &cc));
    for (PetscInt i = 0; i < 4; i++)
      for (PetscInt j = i + 1; j < 4; j++) {
        PetscReal e = 0;
        for (PetscInt d = 0; d < 3; d++) e += PetscSqr(xs[i][d] - xs[j][d]);
        hmax = PetscMax(hmax, PetscSqrtReal(e));
        hmin = PetscMin(hmin, PetscSqrtReal(e));
      }
    for (PetscInt f = 0; f < 4; f++) {
      /* the face opposite vertex f */
      const PetscInt a = (f + 1) % 4, b = (f + 2) % 4, o = (f + 3) % 4;
      PetscReal      u[3], v[3], w[3];
      for (PetscInt d = 0; d < 3; d++) u[d] = xs[b][d] - xs[a][d], v[d] = xs[o][d] - xs[a][d];
      PhlexCross(u, v, w);
      amax = PetscMax(amax, 0.5 * PhlexNorm3(w));
    }
    /* flatness: the smallest altitude 3V/A_max over the shortest edge, 1 for the regular tetrahedron (a sliver has
       comparable edges and almost no volume; long thin cells of a beam are not flat) */
    flat = 3.0 * PetscAbsReal(detJ) * 4.0 / 3.0 / amax / (hmin * PetscSqrtReal(2.0 / 3.0));
    if (flat < 0.02) nflat++;
    if (flat < worst[0]) {
      worst[0] = flat;
      for (PetscInt d = 0; d < 3; d++) worst[1 + d] = 0.25 * (xs[0][d] + xs[1][d] + xs[2][d] + xs[3][d]);
    }
    /* the reference tetrahedron has volume 4/3, so the cell volume is detJ 4/3 */
    if (PetscAbsReal(detJ) * 4.0 / 3.0 <= 1e-10 * hmax * hmax * hmax) info[0] = 1;
    else if (detJ < 0) info[0] = 2;
    if (info[0] > 0) {
      info[1] = c;
      for (PetscInt d = 0; d < 3; d++) bad_centroid[d] = 0.25 * (xs[0][d] + xs[1][d] + xs[2][d] + xs[3][d]);
    }
  }
  PetscCallMPI(MPI_Comm_rank(body->comm, &rank));
  {
    PetscInt in[2] = {info[0], rank}, out[2];
    PetscCallMPI(MPI_Allreduce(in, out, 1, MPIU_2INT, MPI_MAXLOC, body->comm));
    ginfo[0] = out[0];
    if (ginfo[0] > 0) {
      PetscCallMPI(MPI_Bcast(bad_centroid, 3, MPIU_REAL, (PetscMPIInt)out[1], body->comm));
      PetscCallMPI(MPI_Bcast(&info[1], 1, MPIU_INT, (PetscMPIInt)out[1], body->comm));
    }
  }
  PetscCheck(ginfo[0] != 1, body->comm, PETSC_ERR_USER_INPUT, "body %s: mesh file '%s' has a degenerate (zero-volume) tetrahedron near (%g, %g, %g)", body->name, body->mesh_file, (double)bad_centroid[0], (double)bad_centroid[1], (double)bad_centroid[2]);
  PetscCheck(ginfo[0] != 2, body->comm, PETSC_ERR_USER_INPUT, "body %s: mesh file '%s' has an inverted tetrahedron (negative volume, node order reversed) near (%g, %g, %g)", body->name, body->mesh_file, (double)bad_centroid[0], (double)bad_centroid[1], (double)bad_centroid[2]);
  {
    /* slivers are legal but suspicious: a warning with the count, the worst one and where it is */
    PetscInt gflat;
    struct {
      PetscReal   v;
      PetscMPIInt r;
    } in = {worst[0], rank}, out;
    PetscCallMPI(MPI_Allreduce(&nflat, &gflat, 1, MPIU_INT, MPI_SUM, body->comm));
    if (gflat) {
      PetscCallMPI(MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MINLOC, body->comm));
      PetscCallMPI(MPI_Bcast(worst, 4, MPIU_REAL, out.r, body->comm));
      PetscCall(PetscFPrintf(body->comm, PETSC_STDERR, "phlex: warning: body %s: mesh file '%s' has %" PetscInt_FMT " flat tetrahedra (slivers: smallest altitude below 0.02 of the shortest edge, 1 for a regular tetrahedron), the flattest %.2g near (%g, %g, %g) m: they degrade the stress near them and the conditioning of the solves; remesh (gmsh -optimize_netgen) where the results matter\n", body->name, body->mesh_file, gflat, (double)worst[0], (double)worst[1], (double)worst[2], (double)worst[3]));
    }
  }

  /* bounding box */
  for (PetscInt d = 0; d < 3; d++) {
    loc[d]     = PETSC_MAX_REAL;
    loc[3 + d] = PETSC_MAX_REAL;
  }
  PetscCall(DMGetCoordinatesLocal(body->dm, &coords));
  PetscCall(VecGetLocalSize(coords, &n));
  PetscCall(VecGetArrayRead(coords, &x));
  for (PetscInt i = 0; i < n / 3; i++)
    for (PetscInt d = 0; d < 3; d++) {
      loc[d]     = PetscMin(loc[d], PetscRealPart(x[3 * i + d]));
      loc[3 + d] = PetscMin(loc[3 + d], -PetscRealPart(x[3 * i + d]));
    }
  PetscCall(VecRestoreArrayRead(coords, &x));
  PetscCallMPI(MPI_Allreduce(loc, glob, 6, MPIU_REAL, MPI_MIN, body->comm));
  for (PetscInt d = 0; d < 3; d++) {
    body->bbox_min[d] = glob[d];
    body->bbox_max[d] = -glob[3 + d];
  }
  PetscFunctionReturn(0);
}
