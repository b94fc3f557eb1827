/* PetscPartitioner "phlexmetis": METIS's k-way partition of the cell graph, for distributing a mesh that one rank
   read (gmsh files are read on rank 0). PETSc 3.18 on Debian has PTScotch but not ParMETIS; serial METIS 5.1
   (libmetis-dev) partitions the whole graph where it is. Selected per body: -body<k>_petscpartitioner_type phlexmetis
   (BENCHMARKS.md compares it with PTScotch). */
#include <phlex_impl.h>
#include <petsc/private/partitionerimpl.h>
#include <metis.h>

typedef struct {
  PetscInt seed; /* METIS_OPTION_SEED: the same partition every run */
} PartitionerMetis;

static PetscErrorCode PartitionerView_Metis(PetscPartitioner part, PetscViewer viewer)
{
  PetscBool ascii;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (ascii) {
    PetscCall(PetscViewerASCIIPushTab(viewer));
    PetscCall(PetscViewerASCIIPrintf(viewer, "METIS k-way on one rank, seed %" PetscInt_FMT "\n", ((PartitionerMetis *)part->data)->seed));
    PetscCall(PetscViewerASCIIPopTab(viewer));
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode PartitionerSetFromOptions_Metis(PetscPartitioner part, PetscOptionItems *PetscOptionsObject)
{
  PartitionerMetis *pm = (PartitionerMetis *)part->data;

  PetscFunctionBeginUser;
  PetscOptionsHeadBegin(PetscOptionsObject, "METIS partitioner options");
  PetscCall(PetscOptionsInt("-petscpartitioner_phlexmetis_seed", "METIS random seed (the same seed gives the same partition)", "PetscPartitionerCreate_PhlexMetis", pm->seed, &pm->seed, NULL));
  PetscOptionsHeadEnd();
  PetscFunctionReturn(0);
}

static PetscErrorCode PartitionerDestroy_Metis(PetscPartitioner part)
{
  PetscFunctionBeginUser;
  PetscCall(PetscFree(part->data));
  PetscFunctionReturn(0);
}

/* the graph (CSR: start, adjacency) of this rank's numVertices cells; the partition: partSection (cells per part)
   and the cells grouped by part */
static PetscErrorCode PartitionerPartition_Metis(PetscPartitioner part, PetscInt nparts, PetscInt numVertices, PetscInt start[], PetscInt adjacency[], PetscSection vertSection, PetscSection targetSection, PetscSection partSection, IS *partition)
{
  PartitionerMetis *pm = (PartitionerMetis *)part->data;
  MPI_Comm          comm;
  PetscMPIInt       size;
  PetscInt          total, holders, *points, n = 0;
  idx_t            *assignment;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectGetComm((PetscObject)part, &comm));
  PetscCallMPI(MPI_Comm_size(comm, &size));
  {
    PetscInt mine[2] = {numVertices, numVertices > 0 ? 1 : 0}, all[2];
    PetscCallMPI(MPI_Allreduce(mine, all, 2, MPIU_INT, MPI_SUM, comm));
    total   = all[0];
    holders = all[1];
  }
  if (!total) {
    PetscCall(ISCreateGeneral(comm, 0, NULL, PETSC_OWN_POINTER, partition));
    PetscFunctionReturn(0);
  }
  if (holders != 1) {
    const char *prefix;
    PetscCall(PetscObjectGetOptionsPrefix((PetscObject)part, &prefix));
    SETERRQ(comm, PETSC_ERR_SUP, "partitioner phlexmetis partitions a mesh held by one rank (as read from a file); the cells are on %" PetscInt_FMT " ranks: use -%spetscpartitioner_type ptscotch", holders, prefix ? prefix : "");
  }
  PetscCheck(total < PETSC_MAX_INT / 64 && (!numVertices || start[numVertices] < (PetscInt)2147483647), comm, PETSC_ERR_SUP, "partitioner phlexmetis: the cell graph is too large for METIS's 32-bit indices; use ptscotch");
  PetscCall(PetscMalloc1(numVertices, &assignment));
  if (numVertices && nparts > 1) {
    idx_t   nv = (idx_t)numVertices, ncon = 1, np = (idx_t)nparts, cut = 0, options[METIS_NOPTIONS];
    idx_t  *xadj, *adj, *vwgt = NULL;
    real_t *tpwgts = NULL;
    int     err;
    PetscCall(PetscMalloc2(numVertices + 1, &xadj, start[numVertices], &adj));
    for (PetscInt v = 0; v <= numVertices; v++) xadj[v] = (idx_t)start[v];
    for (PetscInt e = 0; e < start[numVertices]; e++) adj[e] = (idx_t)adjacency[e];
    if (vertSection) {
      PetscCall(PetscMalloc1(numVertices, &vwgt));
      for (PetscInt v = 0; v < numVertices; v++) {
        PetscInt w;
        PetscCall(PetscSectionGetDof(vertSection, v, &w));
        vwgt[v] = (idx_t)PetscMax(w, 1);
      }
    }
    if (targetSection) {
      /* the share of each part (METIS wants them positive, summing to 1) */
      real_t sum = 0;
      PetscCall(PetscMalloc1(nparts, &tpwgts));
      for (PetscInt p = 0; p < nparts; p++) {
        PetscInt d;
        PetscCall(PetscSectionGetDof(targetSection, p, &d));
        tpwgts[p] = (real_t)PetscMax(d, 1e-6);
        sum += tpwgts[p];
      }
      for (PetscInt p = 0; p < nparts; p++) tpwgts[p] /= sum;
    }
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = (idx_t)pm->seed;
    err = METIS_PartGraphKway(&nv, &ncon, xadj, adj, vwgt, NULL, NULL, &np, tpwgts, NULL, options, &cut, assignment);
    PetscCall(PetscFree2(xadj, adj));
    PetscCall(PetscFree(vwgt));
    PetscCall(PetscFree(tpwgts));
    PetscCheck(err == METIS_OK, PETSC_COMM_SELF, PETSC_ERR_LIB, "METIS_PartGraphKway failed (METIS error %d) on a graph of %" PetscInt_FMT " cells into %" PetscInt_FMT " parts", err, numVertices, nparts);
    part->edgeCut = (PetscInt)cut;
  } else
    for (PetscInt v = 0; v < numVertices; v++) assignment[v] = 0;
  /* the cells grouped by part */
  for (PetscInt v = 0; v < numVertices; v++) PetscCall(PetscSectionAddDof(partSection, (PetscInt)assignment[v], 1));
  PetscCall(PetscMalloc1(numVertices, &points));
  for (PetscInt p = 0; p < nparts; p++)
    for (PetscInt v = 0; v < numVertices; v++)
      if ((PetscInt)assignment[v] == p) points[n++] = v;
  PetscCall(PetscFree(assignment));
  PetscCall(ISCreateGeneral(comm, numVertices, points, PETSC_OWN_POINTER, partition));
  PetscFunctionReturn(0);
}

static PetscErrorCode PetscPartitionerCreate_PhlexMetis(PetscPartitioner part)
{
  PartitionerMetis *pm;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&pm));
  pm->seed                  = 4321;
  part->data                = pm;
  part->noGraph             = PETSC_FALSE;
  part->ops->view           = PartitionerView_Metis;
  part->ops->setfromoptions = PartitionerSetFromOptions_Metis;
  part->ops->destroy        = PartitionerDestroy_Metis;
  part->ops->partition      = PartitionerPartition_Metis;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPartitionerRegister - registers the PetscPartitioner type "phlexmetis"
@*/
PetscErrorCode PhlexPartitionerRegister(void)
{
  PetscFunctionBeginUser;
  /* the package first: its finalisation frees the list of types (a run that never makes a DMPlex would leak it) */
  PetscCall(PetscPartitionerInitializePackage());
  PetscCall(PetscPartitionerRegister("phlexmetis", PetscPartitionerCreate_PhlexMetis));
  PetscFunctionReturn(0);
}
