/* PC "phlexbordered": the preconditioner of the {velocity, discrete} block of a mechanism (DESIGN section 4: the
   rigid unknowns and multipliers must not spoil the sparse solvers):

       [ A_1          B_1 ] [x_1]   [f_1]      A_i  the condensed velocity operator of body i, factored by its own KSP
       [      ...     ... ] [...] = [...]      B_i  body i's rows x the discrete columns (its frame, its joints)
       [ C_1  ...     D   ] [ y ]   [ g ]      D    m x m dense (the discrete unknowns: frames, impulses)

   Each border B_i is replaced by its projection on a state-independent basis W_i (the frame's nodal fields and the
   force distributions of the ports with joints): B_i ~ W_i beta_i. Y_i = A_i^{-1} W_i is computed once per factorisation
   (KSPMatSolve), so a new state costs only small dense products:

       S  = D - sum_i (C_i Y_i) beta_i                                         (m x m, LU)
       x0_i = A_i^{-1} f_i,  y = S^{-1} (g - sum_i C_i x0_i),  x_i = x0_i - Y_i (beta_i y)   (one solve per body)

   This is the exact inverse when every border lies in its basis (-inertia constant_without_gyroscopic: the joints' and the frames' forces; not the other models, whose gyroscopic borders depend on the state);
   with full inertia (u-dependent borders, node-wise gyroscopic terms) it preconditions an outer Krylov method.
   The system composes what the PC needs on the preconditioning matrix ("phlex_border", system.h). Options of the
   solves with A_i: -<prefix>bordered_ksp_type, -<prefix>bordered_pc_type, ... (default preonly + Cholesky), and
   per body -<prefix>bordered_<body>_ksp_type ...; a body whose A_i is not symmetric (its frame's rate factored with
   it) takes LU where Cholesky was asked, with the package of -<prefix>bordered_[<body>_]lu_mat_solver_type (default
   the Cholesky's; CHOLMOD has none).
   A body whole on one process (-whole_bodies, -<body>_process) is solved by a sequential KSP there, on the rows of its
   MPIAIJ operator's diagonal block (no copy): the processes factor and solve their bodies concurrently, and with a
   sequential package (CHOLMOD) as well. Between those solves nothing is collective. */
#include <phlex_impl.h>
#include <petsc/private/pcimpl.h>

typedef struct {
  PhlexBorderedData *bd;
  PetscInt           nb, m;
  KSP               *ksp;    /* per block */
  Mat               *Y;      /* per block: A_i^{-1} W_i */
  PetscObjectState  *Astate, *Wstate;
  PetscReal        **beta;   /* per block: k_i x m, column-major */
  PetscScalar       *S;      /* LU of the Schur complement, m x m column-major */
  PetscBLASInt      *S_piv;
  IS                *is;     /* per block: its rows in the PC's vector */
  PetscMPIInt       *owner;  /* per block: the process that holds all its rows (-whole_bodies), whose solver is
                                sequential there (the same KSP on every process, set up and used on the owner only);
                                -1: its rows are split, its solver on the PC's communicator */
  Mat               *Aseq;   /* per block on its owner: A_i's rows there, the diagonal block of its MPIAIJ matrix */
  Vec               *fseq, *xseq; /* per block on its owner: sequential vectors placed on the rows of r and z */
  char             (*lu_package)[64]; /* per block: -<prefix>bordered_[<body>_]lu_mat_solver_type (empty: the Cholesky's) */
  PetscBool         *block_cg;   /* per block: -<prefix>bordered_[<body>_]block_cg, the basis by block CG (blockcg.c) where its KSP is CG */
  PetscBool         *block_pc;   /* per block: -<prefix>bordered_[<body>_]block_cg_pc_block, its preconditioner applied to the block (PCMatApply) */
  PetscReal         *block_check; /* per block: -<prefix>bordered_[<body>_]block_cg_check (0: off) */
  PetscInt          *bcg_its, *bcg_colits, *seq_its; /* per block, the last basis: block CG iterations, column iterations; sequential CG iterations (check) */
  PetscBool         *block_products; /* per block: -<prefix>bordered_[<body>_]block_products, an iterative solve's products by node-block copies */
  PhlexBlockCopy    *Ablock;  /* per block: the node-block (BAIJ) copy of its operator */
  PhlexMGCopies     *mgc;     /* per block: its multigrid's transfers and coarse levels as block copies */
  PhlexPMG          *pmg;     /* per block: p-multigrid's interpolation and coarse operator (pmg.c), where its PC is PCMG */
  PetscInt           nfactor;
  PetscInt           ncopy;  /* common options copied to the bodies' prefixes (BorderedCopyCommonOptions) */
  char             **copy_from, **copy_to;
} PC_Bordered;

/* PETSc 3.18's SuperLU_DIST interface keeps one process grid per communicator for "the" factorization on it; with
   the factors of two bodies on one communicator a run crashed (segmentation fault in pdgssvx's Allgather, abort, or
   MPI_Comm_free at PetscFinalize; on several processes once the consistent start's factors were destroyed and the
   steps' made, on one process at once); one body on SuperLU_DIST (the others on MUMPS) ran. The bodies split over
   the processes share the PC's communicator, those whole on one process (-whole_bodies) that process's
   PETSC_COMM_SELF. Refused with the alternatives rather than left to crash. */
static PetscErrorCode RefuseSharedSuperLUDist(PC pc, PC_Bordered *pb)
{
  PetscMPIInt size;
  const char *prefix;

  PetscFunctionBeginUser;
  if (pb->nb < 2) PetscFunctionReturn(0);
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)pc), &size));
  /* the communicators: -1 the PC's, r >= 0 process r's own */
  for (PetscMPIInt key = -1; key < size; key++) {
    PetscInt count = 0;
    char     names[256] = "";
    for (PetscInt i = 0; i < pb->nb; i++) {
      PC            inner;
      PetscBool     factor, sld = PETSC_FALSE;
      MatSolverType type = NULL;
      const char   *name;
      if (pb->owner[i] != key) continue;
      PetscCall(KSPGetPC(pb->ksp[i], &inner));
      PetscCall(PetscObjectTypeCompareAny((PetscObject)inner, &factor, PCLU, PCCHOLESKY, ""));
      if (factor) PetscCall(PCFactorGetMatSolverType(inner, &type));
      if (type) PetscCall(PetscStrcmp(type, MATSOLVERSUPERLU_DIST, &sld));
      if (!sld) continue;
      PetscCall((*pb->bd->blockprefix)(pb->bd->ctx, i, &name));
      if (count++) PetscCall(PetscStrlcat(names, ", ", sizeof(names)));
      PetscCall(PetscStrlcat(names, name, sizeof(names)));
    }
    if (count < 2) continue;
    PetscCall(PCGetOptionsPrefix(pc, &prefix));
    if (key < 0)
      SETERRQ(PetscObjectComm((PetscObject)pc), PETSC_ERR_USER_INPUT,
              "-%sbordered_[<body>_]pc_factor_mat_solver_type superlu_dist for %" PetscInt_FMT " bodies (%s) on %d process%s: SuperLU_DIST cannot hold the factors of two bodies at once (PETSc 3.18 shares one SuperLU_DIST process grid per communicator and crashes); use mumps (the preset's) for all but one, or -%sbordered_pc_type redundant for a sequential solver per body",
              prefix ? prefix : "", count, names, (int)size, size == 1 ? "" : "es", prefix ? prefix : "");
    SETERRQ(PetscObjectComm((PetscObject)pc), PETSC_ERR_USER_INPUT,
            "-%sbordered_[<body>_]pc_factor_mat_solver_type superlu_dist for %" PetscInt_FMT " bodies (%s) whole on process %d: SuperLU_DIST cannot hold the factors of two bodies at once on one process (PETSc 3.18 shares one SuperLU_DIST process grid per communicator and crashes); use mumps (the preset's) for all but one, or put the bodies on different processes (-<body>_process)",
            prefix ? prefix : "", count, names, (int)key);
  }
  PetscFunctionReturn(0);
}

/* An option under the common prefix (-<prefix>bordered_...) reaches a body's solver through the first
   KSPSetFromOptions only; the objects that solver creates later read the body's full prefix alone (the factor's
   -..._mat_mumps_icntl_*, GAMG's -..._mg_levels_*), so such options never arrived. Each common option is copied to
   every body that does not give its own (the body's value wins); BorderedCopiesUsed then counts the common option as
   used when a copy was, so that the never-used warning names what the user typed. */
static PetscErrorCode BorderedCopyCommonOptions(PC_Bordered *pb, const char *common)
{
  PhlexBorderedData *bd = pb->bd;
  PetscInt           nleft;
  char             **names, **values, *all;
  size_t             lc;

  PetscFunctionBeginUser;
  PetscCall(PetscStrlen(common, &lc));
  /* the options not read yet, with their values as given (spaces, leading '-'); the common ones are among them: this
     runs before the first KSPSetFromOptions reads them */
  PetscCall(PetscOptionsLeftGet(NULL, &nleft, &names, &values));
  PetscCall(PetscOptionsGetAll(NULL, &all)); /* to see whether a body gives an option itself (read or not) */
  for (PetscInt k = 0; k < nleft; k++) {
    const char *name = names[k][0] == '-' ? names[k] + 1 : names[k], *rest;
    PetscBool   match, of_body = PETSC_FALSE;
    PetscCall(PetscStrncmp(name, common, lc, &match));
    if (!match) continue;
    rest = name + lc;
    for (PetscInt i = 0; i < pb->nb && !of_body; i++) {
      const char *body;
      size_t      ln;
      PetscCall((*bd->blockprefix)(bd->ctx, i, &body));
      PetscCall(PetscStrlen(body, &ln));
      PetscCall(PetscStrncmp(rest, body, ln, &of_body));
      of_body = (PetscBool)(of_body && rest[ln] == '_');
    }
    if (of_body) continue; /* a body's own option */
    for (PetscInt i = 0; i < pb->nb; i++) {
      const char *body;
      char        to[512], *found = all;
      PetscBool   given = PETSC_FALSE;
      size_t      lt;
      PetscCall((*bd->blockprefix)(bd->ctx, i, &body));
      PetscCall(PetscSNPrintf(to, sizeof(to), "-%s%s_%s", common, body, rest));
      PetscCall(PetscStrlen(to, &lt));
      /* "-name " or "-name" at the end of the list of every option given */
      while (!given && found) {
        PetscCall(PetscStrstr(found, to, &found));
        if (found) {
          given = (PetscBool)((found == all || found[-1] == ' ') && (found[lt] == ' ' || found[lt] == 0));
          found += lt;
        }
      }
      if (given) continue;
      PetscCall(PetscOptionsSetValue(NULL, to, values[k] && values[k][0] ? values[k] : NULL));
      if (!pb->copy_from) PetscCall(PetscCalloc2(nleft * pb->nb, &pb->copy_from, nleft * pb->nb, &pb->copy_to));
      {
        char from[512];
        PetscCall(PetscSNPrintf(from, sizeof(from), "-%s", name));
        PetscCall(PetscStrallocpy(from, &pb->copy_from[pb->ncopy]));
      }
      PetscCall(PetscStrallocpy(to, &pb->copy_to[pb->ncopy]));
      pb->ncopy++;
    }
  }
  PetscCall(PetscFree(all));
  PetscCall(PetscOptionsLeftRestore(NULL, &nleft, &names, &values));
  PetscFunctionReturn(0);
}

static PetscErrorCode BorderedCopiesFree(PC_Bordered *pb)
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < pb->ncopy; c++) {
    PetscCall(PetscFree(pb->copy_from[c]));
    PetscCall(PetscFree(pb->copy_to[c]));
  }
  PetscCall(PetscFree2(pb->copy_from, pb->copy_to));
  pb->ncopy = 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode BorderedCopiesUsed(PC_Bordered *pb)
{
  PetscFunctionBeginUser;
  for (PetscInt c = 0; c < pb->ncopy; c++) {
    PetscBool used, flg;
    PetscCall(PetscOptionsUsed(NULL, pb->copy_to[c] + 1, &used));
    if (used) PetscCall(PetscOptionsHasName(NULL, NULL, pb->copy_from[c], &flg));
  }
  for (PetscInt c = 0; c < pb->ncopy; c++) {
    PetscBool flg;
    PetscCall(PetscOptionsHasName(NULL, NULL, pb->copy_to[c], &flg));
  }
  PetscCall(BorderedCopiesFree(pb));
  PetscFunctionReturn(0);
}

/* which blocks have all their rows on one process (several processes only, and an MPIAIJ operator) */
static PetscErrorCode BorderedOwners(PC pc, PC_Bordered *pb)
{
  PhlexBorderedData *bd = pb->bd;
  PetscMPIInt        size, rank;
  PetscInt          *mine, *all;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_size(PetscObjectComm((PetscObject)pc), &size));
  PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)pc), &rank));
  for (PetscInt i = 0; i < pb->nb; i++) pb->owner[i] = -1;
  if (size == 1) PetscFunctionReturn(0);
  PetscCall(PetscMalloc2(2 * pb->nb, &mine, 2 * pb->nb, &all));
  for (PetscInt i = 0; i < pb->nb; i++) {
    PetscBool aij;
    PetscCall(PetscObjectTypeCompare((PetscObject)bd->A[i], MATMPIAIJ, &aij));
    mine[2 * i]     = bd->n[i] > 0 ? 1 : 0;                    /* processes with rows */
    mine[2 * i + 1] = (bd->n[i] > 0 && aij) ? rank + 1 : 0;   /* the one that has them, if one */
  }
  PetscCallMPI(MPI_Allreduce(mine, all, (PetscMPIInt)(2 * pb->nb), MPIU_INT, MPI_SUM, PetscObjectComm((PetscObject)pc)));
  for (PetscInt i = 0; i < pb->nb; i++)
    if (all[2 * i] == 1 && all[2 * i + 1] > 0) pb->owner[i] = (PetscMPIInt)(all[2 * i + 1] - 1);
  PetscCall(PetscFree2(mine, all));
  PetscFunctionReturn(0);
}

/* Block i's sequential operator on its owner: the diagonal block of the MPIAIJ matrix A (all of A's rows and columns
   are there), with A's symmetry flags, which the factorizations read (CHOLMOD needs them). The same object while A
   keeps its pattern; a new one (or a new pattern) gets a new symbolic factorization. 'changed': A's values changed
   since the last factorization (not only W) */
static PetscErrorCode BlockSequentialOperator(PC_Bordered *pb, PetscInt i, Mat A, PetscBool changed)
{
  Mat       Ad;
  PetscBool set, flg;

  PetscFunctionBeginUser;
  PetscCall(MatMPIAIJGetSeqAIJ(A, &Ad, NULL, NULL));
  if (pb->Aseq[i] && pb->Aseq[i] != Ad) PetscCall(KSPReset(pb->ksp[i]));
  pb->Aseq[i] = Ad;
  PetscCall(MatIsSPDKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(Ad, MAT_SPD, flg));
  PetscCall(MatIsSymmetricKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(Ad, MAT_SYMMETRIC, flg));
  PetscCall(MatIsHermitianKnown(A, &set, &flg));
  if (set) PetscCall(MatSetOption(Ad, MAT_HERMITIAN, flg));
  {
    /* A's near null space (the rigid motions, for GAMG: bordered_iterative.opts) on the rows there: sequential
       vectors on the parallel ones' arrays, which live as long as A */
    MatNullSpace nsp, snsp;
    PetscCall(MatGetNearNullSpace(A, &nsp));
    PetscCall(MatGetNearNullSpace(Ad, &snsp));
    if (nsp && !snsp) {
      PetscBool          has_const;
      PetscInt           n, nloc;
      const Vec         *vecs;
      Vec               *svecs;
      const PetscScalar *a;
      PetscCall(MatNullSpaceGetVecs(nsp, &has_const, &n, &vecs));
      PetscCall(MatGetLocalSize(Ad, &nloc, NULL));
      PetscCall(PetscMalloc1(PetscMax(n, 1), &svecs));
      for (PetscInt k = 0; k < n; k++) {
        PetscCall(VecGetArrayRead(vecs[k], &a));
        PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, nloc, a, &svecs[k]));
        PetscCall(VecRestoreArrayRead(vecs[k], &a));
      }
      PetscCall(MatNullSpaceCreate(PETSC_COMM_SELF, has_const, n, svecs, &snsp));
      PetscCall(MatSetNearNullSpace(Ad, snsp));
      PetscCall(MatNullSpaceDestroy(&snsp));
      for (PetscInt k = 0; k < n; k++) PetscCall(VecDestroy(&svecs[k]));
      PetscCall(PetscFree(svecs));
    }
  }
  if (changed) PetscCall(PetscObjectStateIncrease((PetscObject)Ad)); /* A's values changed: the KSP refactors */
  PetscCall(KSPSetOperators(pb->ksp[i], Ad, Ad));
  PetscFunctionReturn(0);
}

/* under prefix: -lu_mat_solver_type, the package of the LU that a body's operator takes where Cholesky was asked for
   and the operator is not symmetric (BlockFactorType); -block_cg and -block_cg_check, how its border basis is solved
   for with an iterative (CG) inner solver */
static PetscErrorCode ReadBodyOptions(MPI_Comm comm, const char prefix[], const char title[], char package[], size_t len, PetscBool *block_cg, PetscBool *block_pc, PetscReal *check, PetscBool *block_products)
{
  PetscFunctionBeginUser;
  PetscOptionsBegin(comm, prefix, title, NULL);
  PetscCall(PetscOptionsBool("-block_products", "With an iterative inner solve: its products with the body's operator by a copy in 3 x 3 node blocks (BAIJ), and a multigrid preconditioner's transfers and coarse levels by node-block copies after each of its set-ups (as -snes_phlexcondensed_block_products and _block_levels): faster products for more memory", "PCPHLEXBORDERED", *block_products, block_products, NULL));
  PetscCall(PetscOptionsString("-lu_mat_solver_type", "Solver package of the LU that the body's condensed operator takes where Cholesky was asked for and the operator is not symmetric (its frame's rate factored with it); default: the Cholesky's package, which then needs an LU (cholmod has none: give mumps)", "PCPHLEXBORDERED", package, package, len, NULL));
  PetscCall(PetscOptionsBool("-block_cg", "With an inner CG (ksp_type cg): solve for the border basis A^{-1} W (12 columns for a floating frame, 6 per jointed port) by block CG, all columns at once (one sparse product and one block preconditioner application per iteration), instead of one CG solve per column (KSPMatSolve); each column to the KSP's tolerance against its own right-hand side", "PCPHLEXBORDERED", *block_cg, block_cg, NULL));
  PetscCall(PetscOptionsBool("-block_cg_pc_block", "With block CG: apply the inner preconditioner to the block at once (PCMatApply; GAMG and MG: the grid transfers as block products, the smoothers column by column) instead of column by column (PCApply)", "PCPHLEXBORDERED", *block_pc, block_pc, NULL));
  PetscCall(PetscOptionsReal("-block_cg_check", "With block CG: also solve for the basis column by column (KSPMatSolve), print the largest relative difference of a column and stop (exit code 2) when it exceeds this value (0: no check; a test's option)", "PCPHLEXBORDERED", *check, check, NULL));
  PetscCheck(*check >= 0, comm, PETSC_ERR_USER_INPUT, "-%sblock_cg_check must be >= 0 (0: no check), got %g", prefix ? prefix : "", (double)*check);
  PetscOptionsEnd();
  PetscFunctionReturn(0);
}

static PetscErrorCode BorderedSetUpBlocks(PC pc, PC_Bordered *pb)
{
  PhlexBorderedData *bd = pb->bd;
  const char        *prefix;
  PetscInt           rstart;

  PetscFunctionBeginUser;
  pb->nb = bd->nblocks;
  pb->m  = bd->m;
  PetscCall(PetscCalloc5(PetscMax(pb->nb, 1), &pb->ksp, PetscMax(pb->nb, 1), &pb->Y, PetscMax(pb->nb, 1), &pb->Astate, PetscMax(pb->nb, 1), &pb->Wstate, PetscMax(pb->nb, 1), &pb->beta));
  PetscCall(PetscCalloc1(PetscMax(pb->nb, 1), &pb->is));
  PetscCall(PetscCalloc1(PetscMax(pb->nb, 1), &pb->lu_package));
  PetscCall(PetscCalloc1(PetscMax(pb->nb, 1), &pb->block_pc));
  PetscCall(PetscCalloc4(PetscMax(pb->nb, 1), &pb->block_products, PetscMax(pb->nb, 1), &pb->Ablock, PetscMax(pb->nb, 1), &pb->mgc, PetscMax(pb->nb, 1), &pb->pmg));
  PetscCall(PetscCalloc5(PetscMax(pb->nb, 1), &pb->block_cg, PetscMax(pb->nb, 1), &pb->block_check, PetscMax(pb->nb, 1), &pb->bcg_its, PetscMax(pb->nb, 1), &pb->bcg_colits, PetscMax(pb->nb, 1), &pb->seq_its));
  PetscCall(PetscCalloc4(PetscMax(pb->nb, 1), &pb->owner, PetscMax(pb->nb, 1), &pb->Aseq, PetscMax(pb->nb, 1), &pb->fseq, PetscMax(pb->nb, 1), &pb->xseq));
  PetscCall(BorderedOwners(pc, pb));
  PetscCall(PetscMalloc2(PetscMax(pb->m * pb->m, 1), &pb->S, PetscMax(pb->m, 1), &pb->S_piv));
  PetscCall(MatGetOwnershipRange(pc->pmat, &rstart, NULL));
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  {
    char common[256];
    PetscCall(PetscSNPrintf(common, sizeof(common), "%sbordered_", prefix ? prefix : ""));
    PetscCall(BorderedCopyCommonOptions(pb, common));
  }
  for (PetscInt i = 0; i < pb->nb; i++) {
    const char *name;
    char        bprefix[256];
    PC          inner;
    PetscCall(ISCreateStride(PetscObjectComm((PetscObject)pc), bd->n[i], rstart + bd->off[i], 1, &pb->is[i]));
    PetscCall(KSPCreate(pb->owner[i] >= 0 ? PETSC_COMM_SELF : PetscObjectComm((PetscObject)pc), &pb->ksp[i]));
    PetscCall(PetscObjectIncrementTabLevel((PetscObject)pb->ksp[i], (PetscObject)pc, 1));
    PetscCall(KSPSetType(pb->ksp[i], KSPPREONLY));
    PetscCall(KSPGetPC(pb->ksp[i], &inner));
    PetscCall(PCSetType(inner, PCCHOLESKY));
    /* the options common to every body, then those of this body */
    PetscCall(KSPSetOptionsPrefix(pb->ksp[i], prefix));
    PetscCall(KSPAppendOptionsPrefix(pb->ksp[i], "bordered_"));
    PetscCall(KSPSetFromOptions(pb->ksp[i]));
    PetscCall((*bd->blockprefix)(bd->ctx, i, &name));
    PetscCall(PetscSNPrintf(bprefix, sizeof(bprefix), "%s_", name));
    PetscCall(KSPAppendOptionsPrefix(pb->ksp[i], bprefix));
    PetscCall(KSPSetFromOptions(pb->ksp[i]));
    /* the package of the LU that a Cholesky takes where the body's operator is not symmetric (BlockFactorType),
       read whatever was asked, so that a preset's value is used where its Cholesky is replaced */
    {
      const char *kprefix;
      PetscCall(KSPGetOptionsPrefix(pb->ksp[i], &kprefix));
      pb->block_cg[i] = PETSC_TRUE;
      pb->block_pc[i] = PETSC_TRUE;
      char        common[256];
      /* the options common to every body first (a preset's, read even where the body gives its own: not left
         unused), then the body's */
      PetscCall(PetscSNPrintf(common, sizeof(common), "%sbordered_", prefix ? prefix : ""));
      PetscCall(ReadBodyOptions(PetscObjectComm((PetscObject)pc), common, "PC phlexbordered: the factorization of a body's condensed operator", pb->lu_package[i], sizeof(pb->lu_package[i]), &pb->block_cg[i], &pb->block_pc[i], &pb->block_check[i], &pb->block_products[i]));
      PetscCall(ReadBodyOptions(PetscObjectComm((PetscObject)pc), kprefix, "PC phlexbordered: the factorization of a body's condensed operator", pb->lu_package[i], sizeof(pb->lu_package[i]), &pb->block_cg[i], &pb->block_pc[i], &pb->block_check[i], &pb->block_products[i]));
    }
  }
  PetscCall(RefuseSharedSuperLUDist(pc, pb));
  PetscFunctionReturn(0);
}

/* Block i's factorization for its operator A: where Cholesky was asked for, LU from the first time A is known not to
   be symmetric (a body's condensed operator with the node-wise inertia of its frame's rate), with the package of
   -<prefix>bordered_[<body>_]lu_mat_solver_type or else the Cholesky's. An LU package that cannot factor A is named
   with the options (CHOLMOD, the Cholesky of the one-process preset bordered_serial.opts, has no LU) */
static PetscErrorCode BlockFactorType(PC pc, PC_Bordered *pb, PetscInt i, Mat A)
{
  PC            inner;
  PetscBool     chol, set, symm, avail = PETSC_TRUE;
  MatSolverType asked;
  char          package[64] = "";
  const char   *name;

  PetscFunctionBeginUser;
  PetscCall(KSPGetPC(pb->ksp[i], &inner));
  PetscCall(PetscObjectTypeCompare((PetscObject)inner, PCCHOLESKY, &chol));
  PetscCall(MatIsSymmetricKnown(A, &set, &symm));
  if (!chol || !set || symm) PetscFunctionReturn(0);
  PetscCall(PCFactorGetMatSolverType(inner, &asked));
  if (pb->lu_package[i][0]) PetscCall(PetscStrncpy(package, pb->lu_package[i], sizeof(package)));
  else if (asked) PetscCall(PetscStrncpy(package, asked, sizeof(package))); /* copied: PCSetType frees it */
  PetscCall((*pb->bd->blockprefix)(pb->bd->ctx, i, &name));
  if (pb->owner[i] >= 0) PetscCall(MatMPIAIJGetSeqAIJ(A, &A, NULL, NULL)); /* its solver's matrix type (every process has one) */
  if (package[0]) PetscCall(MatGetFactorAvailable(A, package, MAT_FACTOR_LU, &avail));
  if (!avail) {
    const char *prefix, *body;
    MatType     type;
    PetscCall(PCGetOptionsPrefix(pc, &prefix));
    PetscCall((*pb->bd->blockoptions)(pb->bd->ctx, i, &body));
    PetscCall(MatGetType(A, &type));
    PetscCheck(!pb->lu_package[i][0], PetscObjectComm((PetscObject)pc), PETSC_ERR_USER_INPUT, "body %s: its condensed operator is not symmetric (its frame's rate is factored with it, -%spreconditioner_rate_tol), and -%sbordered_[%s_]lu_mat_solver_type %s has no LU of its matrix type %s: use mumps, or keep the rate out of the factorization with -%spreconditioner_rate_tol 0", name, body, prefix ? prefix : "", name, package, type, body);
    SETERRQ(PetscObjectComm((PetscObject)pc), PETSC_ERR_USER_INPUT, "body %s: its condensed operator is not symmetric (its frame's rate is factored with it, -%spreconditioner_rate_tol), and %s, the package of its Cholesky (-%sbordered_[%s_]pc_factor_mat_solver_type), has no LU of its matrix type %s: give -%sbordered_lu_mat_solver_type mumps (as options/solver/bordered_serial.opts does), or keep the rate out of the factorization with -%spreconditioner_rate_tol 0", name, body, package, prefix ? prefix : "", name, type, prefix ? prefix : "", body);
  }
  PetscCall(PCSetType(inner, PCLU));
  if (package[0]) PetscCall(PCFactorSetMatSolverType(inner, package));
  PetscCall(PetscInfo(pc, "block %s: not symmetric, LU instead of Cholesky, with %s\n", name, package[0] ? package : "PETSc's default package"));
  PetscFunctionReturn(0);
}

/* Y = A_i^{-1} W for block i's basis (Wl, Yl: the local matrices of a block whole on its process): block CG
   (blockcg.c) where its KSP is CG and -<prefix>bordered_[<body>_]block_cg is on, else KSPMatSolve (one MatMatSolve
   for preonly + a factorization; PETSc 3.18 solves column by column for a Krylov method). With
   -..._block_cg_check tol, the columns solved one by one too and compared */
static PetscErrorCode BlockBasis(PC pc, PC_Bordered *pb, PetscInt i, Mat Wl, Mat Yl)
{
  PetscBool applies = PETSC_FALSE;
  KSP       ksp = pb->ksp[i];

  PetscFunctionBeginUser;
  if (pb->block_cg[i]) PetscCall(PhlexBlockCGApplies(ksp, &applies));
  if (!applies) {
    PetscCall(KSPMatSolve(ksp, Wl, Yl));
    PetscFunctionReturn(0);
  }
  {
    const char *bname;
    char        what[128];
    PetscCall((*pb->bd->blockprefix)(pb->bd->ctx, i, &bname));
    PetscCall(PetscSNPrintf(what, sizeof(what), "border basis of body %s", bname));
    PetscCall(PhlexBlockCG(ksp, Wl, Yl, (PetscBool)(pb->owner[i] < 0), pb->block_pc[i], what, &pb->bcg_its[i], &pb->bcg_colits[i]));
  }
  /* a body split over the processes enters the collective comparison on every process (block CG checked the signal
     collectively); one whole on its process skips it when interrupted (the check after the factorizations stops) */
  if (pb->block_check[i] > 0 && (pb->owner[i] < 0 || !PhlexInterruptLocal())) {
    Mat                Ys;
    PetscInt           k, nloc, lda, lds, before, after;
    PetscReal         *d, dmax = 0;
    const PetscScalar *ya, *sa;
    const char        *name;
    MPI_Comm           comm = PetscObjectComm((PetscObject)ksp);
    PetscCall(MatDuplicate(Yl, MAT_DO_NOT_COPY_VALUES, &Ys));
    PetscCall(KSPGetTotalIterations(ksp, &before));
    PetscCall(KSPMatSolve(ksp, Wl, Ys));
    PetscCall(KSPGetTotalIterations(ksp, &after));
    pb->seq_its[i] = after - before;
    PetscCall(MatGetSize(Yl, NULL, &k));
    PetscCall(MatGetLocalSize(Yl, &nloc, NULL));
    PetscCall(MatDenseGetLDA(Yl, &lda));
    PetscCall(MatDenseGetLDA(Ys, &lds));
    PetscCall(PetscCalloc1(2 * k, &d));
    PetscCall(MatDenseGetArrayRead(Yl, &ya));
    PetscCall(MatDenseGetArrayRead(Ys, &sa));
    for (PetscInt j = 0; j < k; j++)
      for (PetscInt n = 0; n < nloc; n++) {
        const PetscReal e = PetscAbsScalar(ya[lda * j + n] - sa[lds * j + n]), r = PetscAbsScalar(sa[lds * j + n]);
        d[j] += e * e;
        d[k + j] += r * r;
      }
    PetscCall(MatDenseRestoreArrayRead(Ys, &sa));
    PetscCall(MatDenseRestoreArrayRead(Yl, &ya));
    PetscCall(MPIU_Allreduce(MPI_IN_PLACE, d, (PetscMPIInt)(2 * k), MPIU_REAL, MPIU_SUM, comm));
    for (PetscInt j = 0; j < k; j++) dmax = PetscMax(dmax, d[k + j] > 0 ? PetscSqrtReal(d[j] / d[k + j]) : PetscSqrtReal(d[j]));
    PetscCall(PetscFree(d));
    PetscCall(MatDestroy(&Ys));
    PetscCall((*pb->bd->blockprefix)(pb->bd->ctx, i, &name));
    PetscCall(PetscPrintf(comm, "border basis of %s: %" PetscInt_FMT " columns by block CG in %" PetscInt_FMT " iterations (%" PetscInt_FMT " column iterations), by sequential CG in %" PetscInt_FMT "; largest relative difference of a column %.2e\n", name, k, pb->bcg_its[i], pb->bcg_colits[i], pb->seq_its[i], (double)dmax));
    PetscCall(PetscPrintf(comm, "border basis of %s: block CG against sequential CG within %g: %s\n", name, (double)pb->block_check[i], dmax <= pb->block_check[i] ? "PASS" : "FAIL"));
    PetscCheck(dmax <= pb->block_check[i], comm, PETSC_ERR_USER, "body %s: the border basis by block CG differs from the sequential CG's by %.3e of a column, more than -block_cg_check %g", name, (double)dmax, (double)pb->block_check[i]);
  }
  PetscFunctionReturn(0);
}

/* An iterative inner solve's products with block i's operator by its node-block copy (-block_products; BAIJ reads
   one column index per 3 x 3 block: SNES phlexcondensed's block products, BENCHMARKS.md sections 43, 44), the KSP's
   operators then (copy, AIJ): its preconditioner is built from the AIJ one. Called after the KSP was given the AIJ
   operator, before its set-up: the copy made or refilled in place (PhlexBlockCopyUpdate: one object, which GAMG's
   fine level keeps), and a multigrid preconditioner's interpolations put back for its set-up (PhlexMGCopiesApply
   copies them again after it). A direct solve (preonly) takes no copy. */
static PetscErrorCode BlockProductsBefore(PC_Bordered *pb, PetscInt i)
{
  KSP       ksp = pb->ksp[i];
  Mat       A;
  PetscBool preonly;

  PetscFunctionBeginUser;
  if (!pb->block_products[i]) PetscFunctionReturn(0);
  PetscCall(PetscObjectTypeCompare((PetscObject)ksp, KSPPREONLY, &preonly));
  if (preonly) PetscFunctionReturn(0);
  PetscCall(KSPGetOperators(ksp, NULL, &A));
  PetscCall(PhlexBlockCopyUpdate(&pb->Ablock[i], A, PETSC_FALSE));
  if (!pb->Ablock[i].copy) { /* not in whole node blocks: its products use it as it is (GAMG starts afresh on a new pattern) */
    PetscCall(PhlexMGCopiesDestroy(&pb->mgc[i]));
    PetscFunctionReturn(0);
  }
  PetscCall(PhlexMGCopiesRestore(ksp, &pb->mgc[i]));
  PetscCall(KSPSetOperators(ksp, pb->Ablock[i].copy, A));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCSetUp_Bordered(PC pc)
{
  PC_Bordered       *pb = (PC_Bordered *)pc->data;
  PhlexBorderedData *bd;
  PetscContainer     c;
  PetscReal         *CtY;
  PetscBLASInt       mb, info;
  PetscMPIInt        rank;
  PetscBool         *renew, *Achanged;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectQuery((PetscObject)pc->pmat, "phlex_border", (PetscObject *)&c));
  if (!c) {
    const char *prefix;
    PetscCall(PCGetOptionsPrefix(pc, &prefix));
    SETERRQ(PetscObjectComm((PetscObject)pc), PETSC_ERR_ARG_WRONG, "-%spc_type phlexbordered: PC phlexbordered works on phlex's {velocity, discrete} split (or the whole system without a flexible body); this preconditioning matrix carries no border data", prefix ? prefix : "");
  }
  PetscCall(PetscContainerGetPointer(c, (void **)&bd));
  if (!pb->bd) {
    pb->bd = bd;
    PetscCall(BorderedSetUpBlocks(pc, pb));
  }
  /* Y_i = A_i^{-1} W_i: only when A_i or W_i changed. First what is collective (the factorization's kind, Y_i's
     storage), then the factorizations and solves: those of the blocks whole on one process each there, concurrently,
     then those on the PC's communicator */
  PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)pc), &rank));
  PetscCall(PetscCalloc2(PetscMax(pb->nb, 1), &renew, PetscMax(pb->nb, 1), &Achanged));
  for (PetscInt i = 0; i < pb->nb; i++) {
    PetscObjectState sa, sw = 0;
    PetscCall(PetscObjectStateGet((PetscObject)bd->A[i], &sa));
    if (bd->W[i]) PetscCall(PetscObjectStateGet((PetscObject)bd->W[i], &sw));
    if (pb->Astate[i] == sa && pb->Wstate[i] == sw && (pb->Y[i] || !bd->W[i])) continue;
    renew[i]    = PETSC_TRUE;
    Achanged[i] = (PetscBool)(pb->Astate[i] != sa);
    PetscCall(BlockFactorType(pc, pb, i, bd->A[i]));
    PetscCall(MatDestroy(&pb->Y[i]));
    if (bd->W[i]) {
      PetscInt k;
      PetscCall(MatDuplicate(bd->W[i], MAT_DO_NOT_COPY_VALUES, &pb->Y[i]));
      PetscCall(MatGetSize(bd->W[i], NULL, &k));
      PetscCall(PetscFree(pb->beta[i]));
      PetscCall(PetscMalloc1(PetscMax(k * pb->m, 1), &pb->beta[i]));
    }
    pb->Astate[i] = sa;
    pb->Wstate[i] = sw;
    pb->nfactor++;
    {
      /* p-multigrid's interpolation, once: collective on the body (a body whole on one process: every process takes
         part, the owner's the rows) */
      PetscBool pmg;
      PetscCall(PhlexPMGWanted(pb->ksp[i], &pmg));
      if (pmg && bd->coarsespace && !pb->pmg[i].P) {
        PetscInt m, rstart = 0, bs, off = 0;
        PetscCall(MatGetLocalSize(bd->A[i], &m, NULL));
        if (pb->owner[i] < 0) PetscCall(MatGetOwnershipRange(bd->A[i], &rstart, NULL));
        PetscCall(MatGetBlockSize(bd->A[i], &bs));
        PetscCall(PhlexPMGBuild(pb->ksp[i], pb->owner[i] < 0 ? PetscObjectComm((PetscObject)pc) : PETSC_COMM_SELF, m, rstart, bs, 1, &i, &off, bd->coarsespace, bd->ctx, &pb->pmg[i]));
      }
    }
  }
  for (PetscInt pass = 0; pass < 2; pass++)
    for (PetscInt i = 0; i < pb->nb; i++) {
      const PetscBool mine = (PetscBool)(pb->owner[i] == rank);
      /* SIGINT/SIGTERM between the factorizations (a sparse factorization itself cannot be interrupted: MUMPS,
         CHOLMOD): before each one on the PC's communicator, the blocks whole on one process all done (renew[] is
         the same on every process, so every process checks as often; issue 43 item 1) */
      if (renew[i] && pass == 1 && pb->owner[i] < 0) PetscCall(PhlexInterruptCheck(PetscObjectComm((PetscObject)pc), "between the factorizations of the bodies' operators"));
      if (!renew[i] || (pass == 0) != (pb->owner[i] >= 0) || (pb->owner[i] >= 0 && !mine)) continue;
      /* logged on the solver's communicator (-log_sync: a barrier there, on one process for a body whole on it) */
      PetscCall(PetscLogEventBegin(PHLEX_BorderedBasis, pb->ksp[i], 0, 0, 0));
      if (mine) PetscCall(BlockSequentialOperator(pb, i, bd->A[i], Achanged[i]));
      else PetscCall(KSPSetOperators(pb->ksp[i], bd->A[i], bd->A[i]));
      PetscCall(BlockProductsBefore(pb, i));
      if (pb->pmg[i].P) PetscCall(PhlexPMGSetUp(pb->ksp[i], mine ? pb->Aseq[i] : bd->A[i], &pb->pmg[i]));
      PetscCall(KSPSetUp(pb->ksp[i]));
      if (pb->Ablock[i].copy) PetscCall(PhlexMGCopiesApply(pb->ksp[i], PETSC_TRUE, PETSC_TRUE, &pb->mgc[i]));
      if (pb->Y[i]) {
        Mat Wl = bd->W[i], Yl = pb->Y[i];
        if (mine) {
          PetscCall(MatDenseGetLocalMatrix(bd->W[i], &Wl));
          PetscCall(MatDenseGetLocalMatrix(pb->Y[i], &Yl));
        }
        PetscCall(BlockBasis(pc, pb, i, Wl, Yl));
      }
      PetscCall(PetscLogEventEnd(PHLEX_BorderedBasis, pb->ksp[i], 0, 0, 0));
    }
  {
    PetscBool any = PETSC_FALSE;
    for (PetscInt i = 0; i < pb->nb; i++) any = (PetscBool)(any || renew[i]);
    if (any) PetscCall(PhlexInterruptCheck(PetscObjectComm((PetscObject)pc), "after the factorizations of the bodies' operators"));
  }
  PetscCall(PetscFree2(renew, Achanged));
  if (pb->ncopy) PetscCall(BorderedCopiesUsed(pb));
  if (!pb->m) PetscFunctionReturn(0);
  /* S = D - sum_i (C_i Y_i) beta_i */
  PetscCall(PetscLogEventBegin(PHLEX_BorderedSetUp, pc, 0, 0, 0));
  for (PetscInt i = 0; i < pb->m; i++)
    for (PetscInt j = 0; j < pb->m; j++) pb->S[i + pb->m * j] = bd->D[pb->m * i + j];
  for (PetscInt b = 0; b < pb->nb; b++) {
    PetscInt k;
    if (!bd->W[b]) continue;
    PetscCall(MatGetSize(bd->W[b], NULL, &k));
    PetscCall(PetscMalloc1(pb->m * k, &CtY));
    PetscCall((*bd->rows)(bd->ctx, b, pb->Y[b], CtY));
    PetscCall((*bd->coefficients)(bd->ctx, b, pb->beta[b]));
    for (PetscInt i = 0; i < pb->m; i++)
      for (PetscInt j = 0; j < pb->m; j++) {
        PetscScalar s = 0;
        for (PetscInt l = 0; l < k; l++) s += CtY[i + pb->m * l] * pb->beta[b][l + k * j];
        pb->S[i + pb->m * j] -= s;
      }
    PetscCall(PetscFree(CtY));
  }
  PetscCall(PetscBLASIntCast(pb->m, &mb));
  PetscCallBLAS("LAPACKgetrf", LAPACKgetrf_(&mb, &mb, pb->S, &mb, pb->S_piv, &info));
  PetscCheck(!info, PetscObjectComm((PetscObject)pc), PETSC_ERR_NOT_CONVERGED, "PC phlexbordered: the discrete Schur complement is singular (LAPACK getrf info %d): dependent constraints (redundant joint components?) or a body free to move in a constrained direction", (int)info);
  PetscCall(PetscLogEventEnd(PHLEX_BorderedSetUp, pc, 0, 0, 0));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCApply_Bordered(PC pc, Vec r, Vec z)
{
  PC_Bordered       *pb = (PC_Bordered *)pc->data;
  PhlexBorderedData *bd = pb->bd;
  PetscReal         *h;
  PetscBLASInt       mb, one = 1, info;
  PetscMPIInt        rank;

  PetscFunctionBeginUser;
  PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)pc), &rank));
  PetscCall(PetscCalloc1(PetscMax(pb->m, 1), &h));
  /* x0_i = A_i^{-1} f_i, into z: first the blocks whole on one process, each there on the rows of r and z (nothing
     collective in between, so that the processes solve concurrently), then those split over the processes */
  {
    const PetscScalar *ra;
    PetscScalar       *za;
    PetscCall(VecGetArrayRead(r, &ra));
    PetscCall(VecGetArray(z, &za));
    for (PetscInt i = 0; i < pb->nb; i++) {
      if (pb->owner[i] != rank) continue;
      if (!pb->fseq[i]) {
        PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, bd->n[i], NULL, &pb->fseq[i]));
        PetscCall(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, bd->n[i], NULL, &pb->xseq[i]));
      }
      PetscCall(VecPlaceArray(pb->fseq[i], ra + bd->off[i]));
      PetscCall(VecPlaceArray(pb->xseq[i], za + bd->off[i]));
      PetscCall(KSPSolve(pb->ksp[i], pb->fseq[i], pb->xseq[i]));
      PetscCall(KSPCheckSolve(pb->ksp[i], pc, pb->xseq[i]));
      PetscCall(VecResetArray(pb->fseq[i]));
      PetscCall(VecResetArray(pb->xseq[i]));
    }
    PetscCall(VecRestoreArray(z, &za));
    PetscCall(VecRestoreArrayRead(r, &ra));
  }
  for (PetscInt i = 0; i < pb->nb; i++) {
    Vec f, x;
    if (pb->owner[i] >= 0) continue;
    PetscCall(VecGetSubVector(r, pb->is[i], &f));
    PetscCall(VecGetSubVector(z, pb->is[i], &x));
    PetscCall(KSPSolve(pb->ksp[i], f, x));
    PetscCall(KSPCheckSolve(pb->ksp[i], pc, x));
    PetscCall(VecRestoreSubVector(r, pb->is[i], &f));
    PetscCall(VecRestoreSubVector(z, pb->is[i], &x));
  }
  if (pb->m) {
    const PetscScalar *ra;
    PetscScalar       *za;
    PetscReal         *c;
    Vec               *xb;
    /* h = g - sum_i C_i x0_i; every block taken (collective) before any block's local work, here and below: blocks
       whole on different processes are worked on at the same time */
    PetscCall(PetscMalloc1(pb->nb, &xb));
    for (PetscInt i = 0; i < pb->nb; i++) PetscCall(VecGetSubVector(z, pb->is[i], &xb[i]));
    for (PetscInt i = 0; i < pb->nb; i++) PetscCall((*bd->rowsvec)(bd->ctx, i, xb[i], h));
    PetscCall(VecGetArrayRead(r, &ra));
    {
      PetscReal *g;
      PetscCall(PetscCalloc1(pb->m, &g));
      if (rank == 0)
        for (PetscInt k = 0; k < pb->m; k++) g[k] = PetscRealPart(ra[bd->qoff + k]);
      PetscCallMPI(MPI_Bcast(g, (PetscMPIInt)pb->m, MPIU_REAL, 0, PetscObjectComm((PetscObject)pc)));
      for (PetscInt k = 0; k < pb->m; k++) h[k] = g[k] - h[k];
      PetscCall(PetscFree(g));
    }
    PetscCall(VecRestoreArrayRead(r, &ra));
    /* y = S^{-1} h */
    PetscCall(PetscBLASIntCast(pb->m, &mb));
    PetscCallBLAS("LAPACKgetrs", LAPACKgetrs_("N", &mb, &one, pb->S, &mb, pb->S_piv, h, &mb, &info));
    PetscCall(VecGetArray(z, &za));
    if (rank == 0)
      for (PetscInt k = 0; k < pb->m; k++) za[bd->qoff + k] = h[k];
    PetscCall(VecRestoreArray(z, &za));
    /* x_i = x0_i - Y_i (beta_i y) */
    for (PetscInt i = 0; i < pb->nb; i++) {
      const PetscScalar *Ya;
      PetscScalar       *xa;
      PetscInt           k, nloc, ld;
      if (!pb->Y[i]) continue;
      PetscCall(MatGetSize(pb->Y[i], NULL, &k));
      PetscCall(PetscCalloc1(k, &c));
      for (PetscInt l = 0; l < k; l++)
        for (PetscInt j = 0; j < pb->m; j++) c[l] -= pb->beta[i][l + k * j] * h[j];
      PetscCall(VecGetLocalSize(xb[i], &nloc));
      PetscCall(MatDenseGetLDA(pb->Y[i], &ld));
      PetscCall(MatDenseGetArrayRead(pb->Y[i], &Ya));
      PetscCall(VecGetArray(xb[i], &xa));
      for (PetscInt l = 0; l < k; l++)
        if (c[l] != 0.0)
          for (PetscInt n = 0; n < nloc; n++) xa[n] += c[l] * Ya[l * ld + n];
      PetscCall(VecRestoreArray(xb[i], &xa));
      PetscCall(MatDenseRestoreArrayRead(pb->Y[i], &Ya));
      PetscCall(PetscFree(c));
    }
    for (PetscInt i = 0; i < pb->nb; i++) PetscCall(VecRestoreSubVector(z, pb->is[i], &xb[i]));
    PetscCall(PetscFree(xb));
  }
  PetscCall(PetscFree(h));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCReset_Bordered(PC pc)
{
  PC_Bordered *pb = (PC_Bordered *)pc->data;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < pb->nb; i++) {
    PetscCall(KSPDestroy(&pb->ksp[i]));
    PetscCall(PhlexBlockCopyDestroy(&pb->Ablock[i]));
    PetscCall(PhlexMGCopiesDestroy(&pb->mgc[i]));
    PetscCall(PhlexPMGDestroy(&pb->pmg[i]));
    PetscCall(MatDestroy(&pb->Y[i]));
    PetscCall(PetscFree(pb->beta[i]));
    PetscCall(ISDestroy(&pb->is[i]));
    if (pb->fseq) {
      PetscCall(VecDestroy(&pb->fseq[i]));
      PetscCall(VecDestroy(&pb->xseq[i]));
    }
  }
  PetscCall(PetscFree4(pb->owner, pb->Aseq, pb->fseq, pb->xseq));
  PetscCall(PetscFree5(pb->ksp, pb->Y, pb->Astate, pb->Wstate, pb->beta));
  PetscCall(PetscFree(pb->is));
  PetscCall(PetscFree(pb->lu_package));
  PetscCall(PetscFree(pb->block_pc));
  PetscCall(PetscFree4(pb->block_products, pb->Ablock, pb->mgc, pb->pmg));
  PetscCall(PetscFree5(pb->block_cg, pb->block_check, pb->bcg_its, pb->bcg_colits, pb->seq_its));
  PetscCall(PetscFree2(pb->S, pb->S_piv));
  PetscCall(BorderedCopiesFree(pb));
  pb->bd = NULL;
  pb->nb = pb->m = 0;
  PetscFunctionReturn(0);
}

static PetscErrorCode PCDestroy_Bordered(PC pc)
{
  PetscFunctionBeginUser;
  PetscCall(PCReset_Bordered(pc));
  PetscCall(PetscFree(pc->data));
  PetscFunctionReturn(0);
}

/* what block i's products use (-block_products): its operator or a copy, its multigrid's transfers and levels */
static PetscErrorCode BlockProductsView(PC_Bordered *pb, PetscInt i, PetscViewer viewer)
{
  const PetscInt *n = pb->mgc[i].count;

  PetscFunctionBeginUser;
  PetscCall(PhlexPMGView(&pb->pmg[i], viewer));
  if (!pb->block_products[i]) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  its products with the operator: %s\n", pb->Ablock[i].copy ? "its node-block copy" : "itself"));
  if (n[0]) PetscCall(PetscViewerASCIIPrintf(viewer, "  its multigrid: of %" PetscInt_FMT " transfers %" PetscInt_FMT " by node-block copies, %" PetscInt_FMT " restricting by stored transposes; of %" PetscInt_FMT " smoothed coarse levels %" PetscInt_FMT " by node-block copies\n", n[0], n[1], n[2], n[3], n[4]));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCView_Bordered(PC pc, PetscViewer viewer)
{
  PC_Bordered *pb = (PC_Bordered *)pc->data;
  PetscBool    ascii;
  PetscMPIInt  rank;

  PetscFunctionBeginUser;
  PetscCall(PetscObjectTypeCompare((PetscObject)viewer, PETSCVIEWERASCII, &ascii));
  if (!ascii) PetscFunctionReturn(0);
  PetscCall(PetscViewerASCIIPrintf(viewer, "  %" PetscInt_FMT " sparse block(s), %" PetscInt_FMT " discrete unknowns, A^{-1} W computed %" PetscInt_FMT " time(s)\n", pb->nb, pb->m, pb->nfactor));
  PetscCallMPI(MPI_Comm_rank(PetscObjectComm((PetscObject)pc), &rank));
  for (PetscInt i = 0; i < pb->nb; i++) {
    const char *name;
    PetscCall((*pb->bd->blockprefix)(pb->bd->ctx, i, &name));
    if (pb->owner[i] < 0) {
      PetscCall(PetscViewerASCIIPrintf(viewer, "  solver for the sparse block of %s:\n", name));
      if (pb->bcg_its[i]) PetscCall(PetscViewerASCIIPrintf(viewer, "  its border basis (last computed) by block CG: %" PetscInt_FMT " iterations, %" PetscInt_FMT " column iterations\n", pb->bcg_its[i], pb->bcg_colits[i]));
      PetscCall(BlockProductsView(pb, i, viewer));
      PetscCall(PetscViewerASCIIPushTab(viewer));
      PetscCall(KSPView(pb->ksp[i], viewer));
      PetscCall(PetscViewerASCIIPopTab(viewer));
    } else {
      /* a sequential solver on its process: printed from there */
      PetscViewer sub;
      PetscCall(PetscViewerASCIIPrintf(viewer, "  solver for the sparse block of %s, on process %d:\n", name, (int)pb->owner[i]));
      PetscCall(PetscViewerASCIIPushTab(viewer));
      PetscCall(PetscViewerASCIIPushSynchronized(viewer));
      PetscCall(PetscViewerGetSubViewer(viewer, PETSC_COMM_SELF, &sub));
      if (rank == pb->owner[i]) {
        PetscCall(BlockProductsView(pb, i, sub));
        PetscCall(KSPView(pb->ksp[i], sub));
      }
      PetscCall(PetscViewerRestoreSubViewer(viewer, PETSC_COMM_SELF, &sub));
      PetscCall(PetscViewerFlush(viewer));
      PetscCall(PetscViewerASCIIPopSynchronized(viewer));
      PetscCall(PetscViewerASCIIPopTab(viewer));
    }
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexPCBorderedHelp - lists, for -help solvers, the options of the bodies' solvers of a PC phlexbordered (they are
  made at its first set-up, which needs the operator and which a help run does not reach): a solver with their
  common prefix reads them here; names are the flexible bodies' names (each also has -<prefix>bordered_<name>_...)

  Not collective (every process lists; PETSc prints from the first)
@*/
PetscErrorCode PhlexPCBorderedHelp(PC pc, PetscInt nnames, const char *const names[])
{
  KSP         ksp;
  PC          inner;
  const char *prefix;
  char        common[256], title[512], lu_package[64] = "";
  PetscBool   block_cg = PETSC_TRUE, block_pc = PETSC_TRUE, block_products = PETSC_FALSE;
  PetscReal   check    = 0;

  PetscFunctionBeginUser;
  PetscCall(PCGetOptionsPrefix(pc, &prefix));
  PetscCall(PetscSNPrintf(common, sizeof(common), "%sbordered_", prefix ? prefix : ""));
  PetscCall(KSPCreate(PETSC_COMM_SELF, &ksp));
  PetscCall(KSPSetType(ksp, KSPPREONLY));
  PetscCall(KSPGetPC(ksp, &inner));
  PetscCall(PCSetType(inner, PCCHOLESKY));
  PetscCall(KSPSetOptionsPrefix(ksp, common));
  PetscCall(KSPSetFromOptions(ksp));
  PetscCall(PetscSNPrintf(title, sizeof(title), "PC phlexbordered: the factorization of each flexible body's condensed operator (the same options per body under -%s<body>_, <body> one of", common));
  for (PetscInt i = 0; i < nnames; i++) {
    PetscCall(PetscStrlcat(title, i ? ", " : " ", sizeof(title)));
    PetscCall(PetscStrlcat(title, names[i], sizeof(title)));
  }
  PetscCall(PetscStrlcat(title, ")", sizeof(title)));
  PetscCall(ReadBodyOptions(PETSC_COMM_SELF, common, title, lu_package, sizeof(lu_package), &block_cg, &block_pc, &check, &block_products));
  PetscCall(KSPDestroy(&ksp));
  PetscFunctionReturn(0);
}

static PetscErrorCode PCCreate_Bordered(PC pc)
{
  PC_Bordered *pb;

  PetscFunctionBeginUser;
  PetscCall(PetscNew(&pb));
  pc->data         = pb;
  pc->ops->setup   = PCSetUp_Bordered;
  pc->ops->apply   = PCApply_Bordered;
  pc->ops->reset   = PCReset_Bordered;
  pc->ops->destroy = PCDestroy_Bordered;
  pc->ops->view    = PCView_Bordered;
  PetscFunctionReturn(0);
}

/*@C
  PhlexPCRegister - registers the PC type "phlexbordered" (selectable by -pc_type in the {velocity, discrete} split)
@*/
PetscErrorCode PhlexPCRegister(void)
{
  PetscFunctionBeginUser;
  PetscCall(PCRegister("phlexbordered", PCCreate_Bordered));
  PetscFunctionReturn(0);
}
