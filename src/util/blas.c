/* The BLAS kernels OpenBLAS runs on this processor.

   OpenBLAS built for many processors (DYNAMIC_ARCH, as Debian's libopenblas0 is) picks its kernels from the CPU's
   family and model at load time. Debian bookworm's OpenBLAS 0.3.21 does not list Intel's Emerald Rapids (family 6
   model 207) and, where a family-6 model is missing from its table, falls through to the kernels of the Prescott
   Pentium 4 (SSE3) instead of choosing by the CPU's features as it does for other unknown processors; its dgemm then
   runs at 14 instead of 62-64 GFlop/s, and CHOLMOD's and MUMPS's factorizations take 1.6-2.1 x as long (BENCHMARKS.md
   section 47). OpenBLAS's remedy is OPENBLAS_CORETYPE, read when the library loads, before phlex runs: phlex sets it
   and has OpenBLAS choose again (its own gotoblas_dynamic_quit and gotoblas_dynamic_init) before the first BLAS call.
   Automatic only where OpenBLAS fell back to Prescott on a processor with AVX-512, AVX2 or AVX (a real Prescott has
   none) and OPENBLAS_CORETYPE is not set; -openblas_coretype names kernels or keeps OpenBLAS's choice. Nothing
   happens with another BLAS. */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include <phlex_impl.h>
#include <dlfcn.h>
#include <ctype.h>

static char blas_note[256]; /* what was changed, for the scene's summary ("" if nothing) */

typedef char *(*CoreNameFn)(void);
typedef void (*DynamicFn)(void);

/* the kernels to use where OpenBLAS fell back to Prescott's (NULL: keep them): as its own choice by features for a
   processor it does not know, except SkylakeX's for Cooperlake's (the same double-precision kernels: dgemm 64 against
   62 GFlop/s here; Cooperlake's add bfloat16), which 0.3.21 cannot be given by name (its force_coretype stops one
   short of Cooperlake in its table) */
static const char *AutoCore(void)
{
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")) return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
  if (__builtin_cpu_supports("avx")) return "Sandybridge";
  return NULL;
}

/* whether this processor runs the named kernels (a name OpenBLAS has, forced on a processor without its instructions,
   would stop phlex with SIGILL at the first product); names it does not list here are left to OpenBLAS */
static PetscBool CoreRuns(const char *name, const char **needs)
{
  static const struct {
    const char *names, *needs;
    int         level; /* 3: AVX-512 (F, DQ, BW, VL), 2: AVX2 and FMA, 1: AVX, 0: SSE4.2 */
  } cores[] = {
    {" skylakex cooperlake sapphirerapids ", "AVX-512", 3},
    {" haswell zen ", "AVX2 and FMA", 2},
    {" sandybridge ", "AVX", 1},
    {" nehalem ", "SSE4.2", 0},
  };
  char key[40];
  int  level;

  __builtin_cpu_init();
  level = (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")) ? 3 : (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) ? 2 : __builtin_cpu_supports("avx") ? 1 : __builtin_cpu_supports("sse4.2") ? 0 : -1;
  snprintf(key, sizeof(key), " %.36s ", name);
  for (char *c = key; *c; c++) *c = (char)tolower((unsigned char)*c);
  for (size_t i = 0; i < sizeof(cores) / sizeof(cores[0]); i++)
    if (strstr(cores[i].names, key)) {
      *needs = cores[i].needs;
      return level >= cores[i].level ? PETSC_TRUE : PETSC_FALSE;
    }
  return PETSC_TRUE;
}

/*@C
  PhlexBLASSetFromOptions - chooses OpenBLAS's kernels where it does not know the processor; before any BLAS call

  Collective

  Options Database Keys:
. -openblas_coretype <auto|keep|name> - auto: where OpenBLAS fell back to its Prescott kernels on a processor with
                                        AVX-512, AVX2 or AVX, the kernels it chooses by the CPU's features for processors
                                        it does not know (SkylakeX, Haswell, Sandybridge); keep: OpenBLAS's choice; or
                                        the name of OpenBLAS kernels (as OPENBLAS_CORETYPE)
@*/
PetscErrorCode PhlexBLASSetFromOptions(MPI_Comm comm)
{
  char        value[64] = "auto", was[32];
  const char *env       = getenv("OPENBLAS_CORETYPE"), *want = NULL;
  PetscBool   set, isauto, iskeep, same;
  CoreNameFn  corename = (CoreNameFn)dlsym(RTLD_DEFAULT, "openblas_get_corename");
  DynamicFn   quit     = (DynamicFn)dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit");
  DynamicFn   init     = (DynamicFn)dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init");

  PetscFunctionBeginUser;
  blas_note[0] = 0;
  PetscOptionsBegin(comm, NULL, "BLAS options", NULL);
  PetscCall(PetscOptionsString("-openblas_coretype", "OpenBLAS kernels: auto (where OpenBLAS fell back to its Prescott kernels on a processor with AVX-512, AVX2 or AVX, as 0.3.21 does on processors newer than it: those it chooses by the CPU's features, SkylakeX, Haswell or Sandybridge), keep (OpenBLAS's choice), or a name as in OPENBLAS_CORETYPE (SkylakeX, Haswell, Zen, ...)", "PhlexBLASSetFromOptions", value, value, sizeof(value), &set));
  PetscOptionsEnd();
  PetscCheck(value[0], comm, PETSC_ERR_USER_INPUT, "-openblas_coretype needs a value: auto, keep or the name of OpenBLAS kernels");
  PetscCall(PetscStrcasecmp(value, "auto", &isauto));
  PetscCall(PetscStrcasecmp(value, "keep", &iskeep));
  if (iskeep || (isauto && env)) PetscFunctionReturn(0); /* OpenBLAS read OPENBLAS_CORETYPE itself */
  if (!corename || !quit || !init) {
    PetscCheck(isauto, comm, PETSC_ERR_USER_INPUT, "-openblas_coretype %s: the BLAS phlex runs with is not OpenBLAS with kernels for several processors (DYNAMIC_ARCH); use auto or keep", value);
    PetscFunctionReturn(0);
  }
  PetscCall(PetscStrncpy(was, corename(), sizeof(was)));
  if (isauto) {
    PetscCall(PetscStrcasecmp(was, "Prescott", &same));
    if (!same || !(want = AutoCore())) PetscFunctionReturn(0);
  } else {
    const char *needs = NULL;
    want = value;
    PetscCheck(CoreRuns(want, &needs), comm, PETSC_ERR_USER_INPUT, "-openblas_coretype %s: those kernels need %s, which this processor lacks", value, needs);
  }
  PetscCall(PetscStrcasecmp(was, want, &same));
  if (same) {
    if (!isauto) PetscCall(PetscSNPrintf(blas_note, sizeof(blas_note), "BLAS: OpenBLAS's %s kernels (-openblas_coretype; OpenBLAS's own choice)\n", was));
    PetscFunctionReturn(0);
  }
  PetscCheck(!setenv("OPENBLAS_CORETYPE", want, 1), PETSC_COMM_SELF, PETSC_ERR_SYS, "setenv OPENBLAS_CORETYPE failed");
  quit();
  init();
  PetscCall(PetscStrcasecmp(corename(), want, &same));
  /* a name OpenBLAS does not take (unknown, or Cooperlake in 0.3.21) leaves it to choose by the CPU's features */
  PetscCheck(same, comm, PETSC_ERR_USER_INPUT, "-openblas_coretype %s: this OpenBLAS does not take that name (it chose %s by the processor's features); names as in its TargetList.txt, e.g. SkylakeX, Haswell, Zen, Sandybridge", value, corename());
  if (isauto) PetscCall(PetscSNPrintf(blas_note, sizeof(blas_note), "BLAS: OpenBLAS's %s kernels (OpenBLAS did not know this processor and chose %s's; -openblas_coretype keep to leave them)\n", want, was));
  else PetscCall(PetscSNPrintf(blas_note, sizeof(blas_note), "BLAS: OpenBLAS's %s kernels (-openblas_coretype; OpenBLAS chose %s's)\n", corename(), was));
  PetscFunctionReturn(0);
}

/*@C
  PhlexBLASView - one line of the scene's summary if phlex changed OpenBLAS's kernels (nothing otherwise)
@*/
PetscErrorCode PhlexBLASView(PetscViewer viewer)
{
  PetscFunctionBeginUser;
  if (blas_note[0]) PetscCall(PetscViewerASCIIPrintf(viewer, "%s", blas_note));
  PetscFunctionReturn(0);
}
