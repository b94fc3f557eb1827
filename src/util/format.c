/* Numbers echoed back to the user (run summaries): every digit the user gave, nothing more — the shortest %g that
   reads back to the same double, in fixed notation for ordinary magnitudes (7800, not 7.8e+03; 0.4999999, not 0.5). */
#include <phlex_impl.h>

/*@C
  PhlexFormatReal - the shortest decimal text of x that reads back as x

  Not collective
@*/
const char *PhlexFormatReal(PetscReal x, char buf[], size_t len)
{
  int p;

  for (p = 1; p < 17; p++) {
    snprintf(buf, len, "%.*g", p, (double)x);
    if (strtod(buf, NULL) == (double)x) break;
  }
  if (x != 0 && PetscAbsReal(x) >= 1 && PetscAbsReal(x) < 1e7) {
    const int digits = (int)PetscFloorReal(PetscLog10Real(PetscAbsReal(x))) + 1;
    if (digits > p) snprintf(buf, len, "%.*g", digits, (double)x);
  }
  return buf;
}
