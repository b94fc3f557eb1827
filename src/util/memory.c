/* Memory that phlex freed given back to the operating system. glibc keeps freed heap memory for later allocations
   and returns only what lies at the top of the heap: after the set-up frees its large matrices (the initial
   condition's eigensolve, the assembled operators only Newton on the whole state needs), the resident size stayed
   at its set-up value, 1.2 GB above what was in use at 2.2e5 velocity DOFs, and the first factorization came on top
   of it (BENCHMARKS.md section 20). With another C library this does nothing. */
#include <phlex_impl.h>
#if defined(__GLIBC__)
  #include <malloc.h>
#endif

/*@C
  PhlexReturnFreedMemory - returns the process's freed heap memory to the operating system (glibc's malloc_trim),
  before a phase that allocates much (a factorization)

  Not collective
@*/
PetscErrorCode PhlexReturnFreedMemory(void)
{
  PetscFunctionBeginUser;
#if defined(__GLIBC__)
  (void)malloc_trim(0);
#endif
  PetscFunctionReturn(0);
}
