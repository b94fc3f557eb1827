/* Shell matrices that apply only themselves. A MATSHELL offers MatMultTransposeAdd even without a transpose (its
   default calls MatMultTranspose), so a MATNEST holding it claims a transpose it cannot apply, and SNES newtonls's
   check of J^T F under -info aborted on every jointed scene. Clearing it lets MatHasOperation answer honestly. */
#include <phlex_impl.h>

/*@C
  PhlexMatCreateShell - a shell matrix with the product mult and nothing else (no transpose advertised)

  Collective
@*/
PetscErrorCode PhlexMatCreateShell(MPI_Comm comm, PetscInt m, PetscInt n, PetscInt M, PetscInt N, void *ctx, PetscErrorCode (*mult)(Mat, Vec, Vec), Mat *A)
{
  PetscFunctionBeginUser;
  PetscCall(MatCreateShell(comm, m, n, M, N, ctx, A));
  PetscCall(MatShellSetOperation(*A, MATOP_MULT, (void (*)(void))mult));
  PetscCall(MatShellSetOperation(*A, MATOP_MULT_TRANSPOSE_ADD, NULL));
  PetscFunctionReturn(0);
}
