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

static int HasAVX512(void)
{
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
}
static int HasAVX2(void)
{
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
static int HasAVX(void)
{
  return __builtin_cpu_supports("avx");
}
static int HasFMA4(void)
{
  return __builtin_cpu_supports("fma4");
}
static int HasSSE42(void)
{
  return __builtin_cpu_supports("sse4.2");
}

/* the kernels to use where OpenBLAS fell back to Prescott's (NULL: keep them): as its own choice by features for a
   processor it does not know, except SkylakeX's for Cooperlake's (the same double-precision kernels: dgemm 64 against
   62 GFlop/s here; Cooperlake's add bfloat16), which 0.3.21 cannot be given by name (its force_coretype stops one
   short of Cooperlake in its table) */
static const char *AutoCore(void)
{
  __builtin_cpu_init();
  if (HasAVX512()) return "SkylakeX";
  if (HasAVX2()) return "Haswell";
  if (HasAVX()) return "Sandybridge";
  return NULL;
}

/* whether this processor runs the named kernels: OpenBLAS does not check, and kernels forced on a processor without
   their instructions stop phlex with SIGILL at the first product. Names not listed (older x86 kernels, up to SSE4.1;
   names a newer OpenBLAS adds) are left to OpenBLAS */
static PetscBool CoreRuns(const char *name, const char **needs)
{
  static const struct {
    const char *names, *needs;
    int (*has)(void);
  } cores[] = {
    {" skylakex cooperlake sapphirerapids ", "AVX-512 (F, DQ, BW, VL)", HasAVX512},
    {" haswell zen ", "AVX2 and FMA", HasAVX2},
    {" sandybridge ", "AVX", HasAVX},
    {" bulldozer piledriver steamroller excavator ", "AMD's FMA4", HasFMA4},
    {" nehalem ", "SSE4.2", HasSSE42},
  };
  char key[40];

  __builtin_cpu_init();
  snprintf(key, sizeof(key), " %.36s ", name);
  for (char *c = key; *c; c++) *c = (char)tolower((unsigned char)*c);
  for (size_t i = 0; i < sizeof(cores) / sizeof(cores[0]); i++)
    if (strstr(cores[i].names, key)) {
      *needs = cores[i].needs;
      return cores[i].has() ? PETSC_TRUE : PETSC_FALSE;
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
  PetscBool   isauto, iskeep, same;
  CoreNameFn  corename = (CoreNameFn)dlsym(RTLD_DEFAULT, "openblas_get_corename");
  DynamicFn   quit     = (DynamicFn)dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit");
  DynamicFn   init     = (DynamicFn)dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init");

  PetscFunctionBeginUser;
  blas_note[0] = 0;
  PetscOptionsBegin(comm, NULL, "BLAS options", NULL);
  PetscCall(PetscOptionsString("-openblas_coretype", "OpenBLAS kernels: auto (where OpenBLAS fell back to its Prescott kernels on a processor with AVX-512, AVX2 or AVX, as 0.3.21 does on processors newer than it: those it chooses by the CPU's features, SkylakeX, Haswell or Sandybridge), keep (OpenBLAS's choice), or a name as in OPENBLAS_CORETYPE (SkylakeX, Haswell, Zen, ...)", "PhlexBLASSetFromOptions", value, value, sizeof(value), NULL));
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
  /* a name OpenBLAS does not know leaves it to choose by the CPU's features; some it maps to other kernels (0.3.21:
     Penryn's are Core2's; Cooperlake it cannot be given, and reaches only by features) */
  PetscCheck(same, comm, PETSC_ERR_USER_INPUT, "-openblas_coretype %s: OpenBLAS runs %s's kernels, not %s's (a name this OpenBLAS does not know, or one it maps to other kernels); names as in its TargetList.txt, e.g. SkylakeX, Haswell, Zen, Sandybridge", value, corename(), value);
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
