/* A P2 body's P1 coarse space for p-multigrid (src/system/pmg.c, issue 44 item 1).
   The fields linear in each cell (P1 on the same mesh) are a subspace of the P2 velocity space: a P1 field is its
   vertex values, and the P2 field equal to it takes them at the vertices and their mean at the edges' midpoints. The
   interpolation P (P2 rows, P1 columns) is therefore exact, with one entry per vertex row and two per edge row per
   component, and the Galerkin operator P^T A P of the condensed operator shift Mv + K/shift is the P1 discretisation of
   the same mass and stiffness (their integrals are exact on P1), at a seventh of the unknowns and a sixth of the
   entries per row. The frame patch's constrained vertices have no P1 unknown: the P2 field of a P1 one is zero there.
   A body of another degree carries its unknowns to the coarse level unchanged (P the identity). */
#include <phlex_impl.h>
#include <petscsf.h>

/* per point of the chart: the global P1 column of its first component (a free vertex; owners' numbering through
   the point SF for the ghosts), -1 elsewhere; the local count of owned P1 unknowns */
static PetscErrorCode VertexColumns(PhlexFlexible b, PetscInt col0, PetscInt **gcol, PetscInt *n1)
{
  PetscSection    s, gs;
  PetscSF         sf;
  PetscInt        pStart, pEnd, vStart, vEnd, *root, bad = -1, nroots;

  PetscFunctionBeginUser;
  PetscCall(DMGetLocalSection(b->dm, &s));
  PetscCall(DMGetGlobalSection(b->dm, &gs));
  PetscCall(DMPlexGetChart(b->dm, &pStart, &pEnd));
  PetscCall(DMPlexGetDepthStratum(b->dm, 0, &vStart, &vEnd));
  PetscCall(PetscMalloc1(pEnd - pStart, &root));
  PetscCall(PetscMalloc1(pEnd - pStart, gcol));
  *n1 = 0;
  for (PetscInt p = pStart; p < pEnd; p++) {
    PetscInt dof, cdof, goff;
    root[p - pStart] = -1;
    if (p < vStart || p >= vEnd) continue;
    PetscCall(PetscSectionGetDof(s, p, &dof));
    PetscCall(PetscSectionGetConstraintDof(s, p, &cdof));
    PetscCall(PetscSectionGetOffset(gs, p, &goff));
    if (goff < 0 || dof - cdof == 0) continue; /* a ghost, or a vertex of the frame patch */
    if (dof != 3 || cdof != 0) {
      bad = dof != 3 ? 100 + dof : cdof;
      continue;
    }
    root[p - pStart] = col0 + *n1;
    *n1 += 3;
  }
  /* every process learns of a partly constrained vertex before the collective broadcast below */
  PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPIU_INT, MPI_MAX, b->comm));
  PetscCheck(bad < 100, b->comm, PETSC_ERR_SUP, "body %s: p-multigrid's P1 coarse space needs three velocity components at each vertex (a vertex has %" PetscInt_FMT "): use a preset without p-multigrid (options/solver/iterative_gamg.opts, bordered_iterative_gamg.opts; a modal analysis: the default factorization)", b->name, bad - 100);
  PetscCheck(bad < 0, b->comm, PETSC_ERR_SUP, "body %s: p-multigrid's P1 coarse space needs each vertex's three velocity components all free or all constrained (a vertex has %" PetscInt_FMT " of 3 constrained): use a preset without p-multigrid (options/solver/iterative_gamg.opts, bordered_iterative_gamg.opts; a modal analysis: the default factorization)", b->name, bad);
  PetscCall(PetscArraycpy(*gcol, root, pEnd - pStart));
  PetscCall(DMGetPointSF(b->dm, &sf));
  PetscCall(PetscSFGetGraph(sf, &nroots, NULL, NULL, NULL));
  if (nroots >= 0) { /* (a DM never distributed has a point SF without a graph) */
    PetscCall(PetscSFBcastBegin(sf, MPIU_INT, root, *gcol, MPI_REPLACE));
    PetscCall(PetscSFBcastEnd(sf, MPIU_INT, root, *gcol, MPI_REPLACE));
  }
  PetscCall(PetscFree(root));
  PetscFunctionReturn(0);
}

/*@C
  PhlexFlexibleCoarseSpace - the body's rows of p-multigrid's interpolation from its P1 space (see above)

  Collective on the body (also to count: every process calls it, with P or without)

  Input Parameters:
+ b    - the body
. row0 - the global row, in the interpolation's numbering, of the body's first local velocity unknown
. col0 - the global column of the body's first local coarse unknown
- P    - the interpolation to fill (MatSetValue with global indices), or NULL to count

  Output Parameters:
+ n1  - the body's local coarse unknowns
- inj - if not NULL (with P), per local coarse unknown, the body's local velocity row it takes its value from (the
        vertex's own component): the injection that carries a fine field's vertex values (the rigid-body modes)
@*/
PetscErrorCode PhlexFlexibleCoarseSpace(PhlexFlexible b, PetscInt row0, PetscInt col0, Mat P, PetscInt *n1, PetscInt inj[])
{
  PetscSection s, gs;
  PetscInt     pStart, pEnd, vStart, vEnd, eStart, eEnd, *gcol, bstart;

  PetscFunctionBeginUser;
  if (b->degree != 2) {
    /* carried unchanged */
    *n1 = b->nv_local;
    if (!P) PetscFunctionReturn(0);
    for (PetscInt i = 0; i < b->nv_local; i++) {
      PetscCall(MatSetValue(P, row0 + i, col0 + i, 1.0, INSERT_VALUES));
      if (inj) inj[i] = i;
    }
    PetscFunctionReturn(0);
  }
  PetscCall(VertexColumns(b, col0, &gcol, n1));
  /* the body's own global numbering starts at bstart on this process: its local row i is row0 + i */
  PetscCallMPI(MPI_Scan(&b->nv_local, &bstart, 1, MPIU_INT, MPI_SUM, b->comm));
  bstart -= b->nv_local;
  if (!P) {
    PetscCall(PetscFree(gcol));
    PetscFunctionReturn(0);
  }
  PetscCall(DMGetLocalSection(b->dm, &s));
  PetscCall(DMGetGlobalSection(b->dm, &gs));
  PetscCall(DMPlexGetChart(b->dm, &pStart, &pEnd));
  PetscCall(DMPlexGetDepthStratum(b->dm, 0, &vStart, &vEnd));
  PetscCall(DMPlexGetDepthStratum(b->dm, 1, &eStart, &eEnd));
  for (PetscInt v = vStart; v < vEnd; v++) {
    PetscInt goff, g = gcol[v - pStart];
    PetscCall(PetscSectionGetOffset(gs, v, &goff));
    if (goff < 0 || g < 0) continue;
    for (PetscInt c = 0; c < 3; c++) {
      PetscCall(MatSetValue(P, row0 + goff - bstart + c, g + c, 1.0, INSERT_VALUES));
      if (inj) inj[g - col0 + c] = goff - bstart + c;
    }
  }
  for (PetscInt e = eStart; e < eEnd; e++) {
    const PetscInt *cone;
    PetscInt        goff, dof, cdof;
    PetscCall(PetscSectionGetOffset(gs, e, &goff));
    PetscCall(PetscSectionGetDof(s, e, &dof));
    PetscCall(PetscSectionGetConstraintDof(s, e, &cdof));
    if (goff < 0 || dof - cdof <= 0) continue; /* a ghost, or an edge of the frame patch */
    PetscCall(DMPlexGetCone(b->dm, e, &cone));
    for (PetscInt k = 0; k < 2; k++) {
      const PetscInt g = gcol[cone[k] - pStart];
      if (g < 0) continue; /* a constrained vertex: zero */
      for (PetscInt c = 0; c < 3; c++) PetscCall(MatSetValue(P, row0 + goff - bstart + c, g + c, 0.5, INSERT_VALUES));
    }
  }
  PetscCall(PetscFree(gcol));
  PetscFunctionReturn(0);
}
