/* The products a multigrid V-cycle makes below its fine level, made cheaper after each set-up of the preconditioner.
   GAMG's hierarchy is AIJ. Two things cost more than they need to (BENCHMARKS.md sections 43, 44):
   - the transfers: PCMG restricts with its restriction matrix (the interpolation P unless another is set: a product
     with the transpose, which scatters and runs at a third to half the speed of a product) and prolongs with P;
   - the coarse levels' smoothing and residual: their operators come in aggregate blocks of 6 (3 translations, 3
     rotations) that couple as dense 6 x 6 blocks, read by AIJ one column index per entry.
   Node-block (BAIJ) copies fix both: a BAIJ transpose product runs at the speed of its product, so one BAIJ copy of
   P serves as interpolation and restriction, and each smoothed coarse level's products use a BAIJ copy of its
   operator (the smoother's preconditioner, point Jacobi, still reads the AIJ one). An interpolation not in whole
   blocks may instead get a stored transpose as its restriction (the gain is the restriction's).
   GAMG set up again on the same pattern (a new step size) keeps its interpolations by default and forms the coarse
   operators again as Galerkin products with them, which need the AIJ P: PhlexMGCopiesRestore puts them back before
   a set-up; after it, PhlexMGCopiesApply puts the copies of the same P back and refills the coarse operators' copies
   (the levels' residuals, which GAMG leaves on the matrices they were given, are these copies). Only the smoothers
   of PCMG's levels are given the copies: up-smoothers distinct from them (-pc_mg_distinct_smoothup) as well. A
   smoother whose Chebyshev bounds are estimated (not GAMG's, -pc_gamg_use_sa_esteig 0 or a preconditioner other
   than Jacobi) estimates them again on the copy: the same values, a few products more per set-up. */
#include <phlex_impl.h>
#include <petsc/private/pcmgimpl.h> /* whether the preconditioner is set up (after a KSPReset its levels have no transfers); a level's smoothers */

/* whether level l has an up-smoother of its own (-pc_mg_distinct_smoothup, PCMGSetDistinctSmoothUp): asked of the
   level, since PCMGGetSmootherUp would make one */
static PetscErrorCode DistinctSmoothUp(PC pc, PetscInt l, PetscBool *distinct)
{
  PC_MG *mg = (PC_MG *)pc->data;

  PetscFunctionBeginUser;
  *distinct = (PetscBool)(mg->levels && mg->levels[l]->smoothu && mg->levels[l]->smoothu != mg->levels[l]->smoothd);
  PetscFunctionReturn(0);
}

static PetscErrorCode IsMG(KSP ksp, PC *pc, PetscBool *mg)
{
  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(ksp, pc));
  PetscCall(PetscObjectTypeCompareAny((PetscObject)*pc, mg, PCMG, PCGAMG, ""));
  PetscFunctionReturn(0);
}

/*@C
  PhlexMGCopiesApply - after a set-up of the multigrid preconditioner of ksp (PCMG, PCGAMG; others: nothing),
  replace its transfers and coarse-level operators by copies whose products are faster: blocks: BAIJ copies (see
  above); transposes: an AIJ interpolation left without a block copy gets its stored transpose as restriction.
  Call after every set-up (KSPSetUp after KSPSetOperators), and PhlexMGCopiesRestore before the next; the fine
  level's operator is the caller's. m->count: [0] the transfers between levels, [1] those by block copies, [2]
  those restricting by stored transposes, [3] the smoothed coarse levels, [4] those whose products use block copies.

  Collective
@*/
PetscErrorCode PhlexMGCopiesApply(KSP ksp, PetscBool blocks, PetscBool transposes, PhlexMGCopies *m)
{
  PC        pc;
  PetscBool mg, distinct;
  PetscInt  nlevels;

  PetscFunctionBeginUser;
  PetscCall(PetscArrayzero(m->count, 5));
  if (!blocks && !transposes) PetscFunctionReturn(0);
  PetscCall(IsMG(ksp, &pc, &mg));
  if (!mg) PetscFunctionReturn(0);
  PetscCall(KSPSetUp(ksp));
  PetscCall(PCMGGetLevels(pc, &nlevels));
  if (nlevels != m->nlevels) { /* a new hierarchy: the copies of the old one's go */
    PetscCall(PhlexMGCopiesDestroy(m));
    m->nlevels = nlevels;
    PetscCall(PetscCalloc2(nlevels, &m->P, nlevels, &m->A));
  }
  m->count[0] = nlevels - 1;
  m->count[3] = PetscMax(nlevels - 2, 0);
  for (PetscInt l = 1; l < nlevels; l++) {
    Mat       P, R;
    PetscBool aij;

    /* the transfer between levels l - 1 and l: a block copy of P in both roles (the same copy while P is the same) */
    PetscCall(PCMGGetInterpolation(pc, l, &P));
    PetscCall(PCMGGetRestriction(pc, l, &R));
    if (P != m->P[l].copy) { /* (P the copy: applied before, no set-up since) */
      PetscCall(PetscObjectBaseTypeCompareAny((PetscObject)P, &aij, MATSEQAIJ, MATMPIAIJ, ""));
      if (aij && blocks) PetscCall(PhlexBlockCopyUpdate(&m->P[l], P, PETSC_FALSE));
      else PetscCall(PhlexBlockCopyDestroy(&m->P[l]));
    }
    if (m->P[l].copy) {
      PetscCall(PCMGSetInterpolation(pc, l, m->P[l].copy));
      PetscCall(PCMGSetRestriction(pc, l, m->P[l].copy));
      m->count[1]++;
    } else if (transposes && R == P) {
      PetscCall(PetscObjectBaseTypeCompareAny((PetscObject)P, &aij, MATSEQAIJ, MATMPIAIJ, ""));
      if (aij) {
        PetscCall(MatTranspose(P, MAT_INITIAL_MATRIX, &R));
        PetscCall(PCMGSetRestriction(pc, l, R));
        PetscCall(MatDestroy(&R));
        m->count[2]++;
      }
    } else if (R != P) m->count[2]++; /* a stored transpose from an earlier set-up, kept by GAMG with P */
    /* level l's smoothing and residual (the finest level's operator is the KSP's own) */
    if (blocks && l < nlevels - 1) {
      KSP smoother;
      Mat B;
      PetscCall(PCMGGetSmoother(pc, l, &smoother));
      PetscCall(KSPGetOperators(smoother, NULL, &B));
      PetscCall(PetscObjectBaseTypeCompareAny((PetscObject)B, &aij, MATSEQAIJ, MATMPIAIJ, ""));
      if (!aij) continue;
      PetscCall(PhlexBlockCopyUpdate(&m->A[l], B, PETSC_FALSE)); /* refilled when GAMG formed B again in place */
      if (!m->A[l].copy) continue;
      PetscCall(KSPSetOperators(smoother, m->A[l].copy, B));
      PetscCall(DistinctSmoothUp(pc, l, &distinct));
      if (distinct) {
        KSP up;
        PetscCall(PCMGGetSmootherUp(pc, l, &up));
        PetscCall(KSPSetOperators(up, m->A[l].copy, B));
      }
      PetscCall(PCMGSetResidual(pc, l, PCMGResidualDefault, m->A[l].copy));
      m->count[4]++;
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexMGCopiesRestore - before a new set-up of the multigrid preconditioner of ksp: its interpolations back to the
  AIJ matrices PhlexMGCopiesApply copied (GAMG's Galerkin products read them)

  Collective
@*/
PetscErrorCode PhlexMGCopiesRestore(KSP ksp, PhlexMGCopies *m)
{
  PC        pc;
  PetscBool mg;
  PetscInt  nlevels;

  PetscFunctionBeginUser;
  if (!m->nlevels) PetscFunctionReturn(0);
  PetscCall(IsMG(ksp, &pc, &mg));
  if (!mg || !pc->setupcalled) PetscFunctionReturn(0); /* reset: GAMG starts afresh */
  PetscCall(PCMGGetLevels(pc, &nlevels));
  if (nlevels != m->nlevels) PetscFunctionReturn(0);
  for (PetscInt l = 1; l < nlevels; l++) {
    Mat P;
    PetscCall(PCMGGetInterpolation(pc, l, &P));
    if (!m->P[l].copy || P != m->P[l].copy) continue;
    PetscCall(PCMGSetInterpolation(pc, l, m->P[l].watch.src));
    PetscCall(PCMGSetRestriction(pc, l, m->P[l].watch.src));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexMGCopiesDestroy - the copies of the interpolations and coarse operators and the AIJ matrices they were taken
  from, released

  Not collective
@*/
PetscErrorCode PhlexMGCopiesDestroy(PhlexMGCopies *m)
{
  PetscFunctionBeginUser;
  for (PetscInt l = 0; l < m->nlevels; l++) {
    PetscCall(PhlexBlockCopyDestroy(&m->P[l]));
    PetscCall(PhlexBlockCopyDestroy(&m->A[l]));
  }
  PetscCall(PetscFree2(m->P, m->A));
  m->nlevels = 0;
  PetscCall(PetscArrayzero(m->count, 5));
  PetscFunctionReturn(0);
}
