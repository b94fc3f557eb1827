/* Self-verification switched on by -expect_* options (CONVENTIONS section 5): a violated bound makes the run fail
   with observed, expected and tolerance; a satisfied one prints one stable verdict line. */
#include <phlex_impl.h>

/*@C
  PhlexExpectMax - checks observed <= bound

  Collective

  Input Parameters:
+ comm     - communicator
. what     - quantity, e.g. "energy drift (max |H - H0| / H0)"
. option   - the option that set the bound
. observed - observed value
. bound    - the bound
- print    - print the PASS verdict
@*/
PetscErrorCode PhlexExpectMax(MPI_Comm comm, const char what[], const char option[], PetscReal observed, PetscReal bound, PetscBool print)
{
  PetscFunctionBeginUser;
  PetscCheck(observed <= bound, comm, PETSC_ERR_USER, "%s: FAIL: observed %.6e, expected <= %.3e (%s)", what, (double)observed, (double)bound, option);
  if (print) PetscCall(PetscPrintf(comm, "%s: PASS (< %g)\n", what, (double)bound));
  PetscFunctionReturn(0);
}

/*@C
  PhlexExpectValues - compares observed values with expected ones within a relative tolerance

  Collective

  Input Parameters:
+ comm     - communicator
. what     - quantity name, e.g. "frequency [Hz]"
. option   - option holding the expected values
. n        - number of observed values available
. observed - observed values
. nexp     - number of expected values
. expected - expected values
- rtol     - relative tolerance
@*/
PetscErrorCode PhlexExpectValues(MPI_Comm comm, const char what[], const char option[], PetscInt n, const PetscReal observed[], PetscInt nexp, const PetscReal expected[], PetscReal rtol)
{
  PetscReal worst = 0;
  PetscInt  iworst = -1;

  PetscFunctionBeginUser;
  PetscCheck(n >= nexp, comm, PETSC_ERR_USER, "%s: FAIL: %" PetscInt_FMT " values expected (%s), only %" PetscInt_FMT " computed", what, nexp, option, n);
  for (PetscInt i = 0; i < nexp; i++) {
    const PetscReal err = PetscAbsReal(observed[i] - expected[i]) / PetscMax(PetscAbsReal(expected[i]), PETSC_MACHINE_EPSILON);
    if (err > worst) {
      worst  = err;
      iworst = i;
    }
  }
  PetscCheck(worst <= rtol, comm, PETSC_ERR_USER, "%s: FAIL: value %" PetscInt_FMT " observed %.10g, expected %.10g, relative error %.3e > tolerance %.3e (%s)", what, iworst + 1, (double)observed[iworst], (double)expected[iworst], (double)worst, (double)rtol, option);
  PetscCall(PetscPrintf(comm, "%s: PASS (%" PetscInt_FMT " values within rel. tol. %g)\n", what, nexp, (double)rtol));
  PetscFunctionReturn(0);
}
