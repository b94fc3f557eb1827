# phlex: GNU make build for Debian's PETSc 3.18 / SLEPc 3.18.
#   make            build bin/phlex
#   make run        build (installing missing packages first; every core, JOBS=n to choose) and run the default scene
#   make check      build (installing missing packages first) and run the regression suite
#   make deps       install the Debian packages phlex needs (only those missing)
#   make meshes     regenerate the committed meshes from their .geo sources
#   make memcheck   small runs under valgrind and with PETSc's -malloc_dump (a few minutes)
#   make print      show the compiler and flags

PKGS      := slepc petsc hdf5-mpi yaml-0.1
SCENE     ?= options/cantilever.yaml
MPIEXEC   ?= mpiexec
NP        ?= 1
RUN_ARGS  ?=
# the build under run, check and validate uses every core (JOBS=n to choose), unless make itself was given -j
JOBS      ?= $(shell nproc 2>/dev/null || echo 1)
PARALLEL   = $(if $(findstring -j,$(MAKEFLAGS))$(findstring jobserver,$(MAKEFLAGS)),,-j$(JOBS))

# Flags are looked up lazily, so that 'make check' on a machine without PETSc can first install it.
CC        = $(shell pkg-config --variable=ccompiler petsc 2>/dev/null || echo mpicc)
CPPFLAGS  = -Iinclude $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
CFLAGS    ?= -O2 -g
# the language, warnings and header dependencies: a variable of their own, so that make CFLAGS=... keeps them
STDFLAGS  = -std=c99 -Wall -Wextra -Wno-unused-parameter -MMD -MP
LDLIBS    = $(shell pkg-config --libs $(PKGS) 2>/dev/null) -lmetis -llapack -lblas -lm

SRC       := $(sort $(wildcard src/*.c src/*/*.c))
OBJ       := $(patsubst src/%.c,build/%.o,$(SRC))
BIN       := bin/phlex

# The dependency probe: PETSc, SLEPc and gmsh present means nothing has to be installed.
HAVE_DEPS = $(shell pkg-config --exists $(PKGS) 2>/dev/null && command -v gmsh >/dev/null 2>&1 && command -v $(firstword $(MPIEXEC)) >/dev/null 2>&1 && echo yes)

.PHONY: all run check check-update deps deps-if-missing meshes format clean print bench memcheck validate

all: $(BIN)

$(BIN): $(OBJ) | bin
	$(CC) $(CFLAGS) $(STDFLAGS) -o $@ $(OBJ) $(LDLIBS)

build/%.o: src/%.c
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(STDFLAGS) $(VECFLAGS) -c $< -o $@

# the block kernels' loops vectorize only with GCC's dynamic cost model (-O2's leaves them scalar); no fused
# multiply-add there (with -march flags that have it), so that their clones give the same bits
build/util/mat_block_mult.o: VECFLAGS = -fvect-cost-model=dynamic -ffp-contract=off
build/parts/flexible_stress_maps.o: VECFLAGS = -ffp-contract=off

bin:
	@mkdir -p $@

deps:
	@tools/install-deps.sh

deps-if-missing:
	@$(if $(HAVE_DEPS),true,tools/install-deps.sh)

run: deps-if-missing
	@$(MAKE) --no-print-directory $(PARALLEL) $(BIN)
	$(MPIEXEC) -n $(NP) $(BIN) -options_file $(SCENE) $(RUN_ARGS)

check: deps-if-missing
	@$(MAKE) --no-print-directory $(PARALLEL) $(BIN)
	python3 tests/run.py $(TEST_ARGS)

check-update: $(BIN)
	python3 tests/run.py --update $(TEST_ARGS)

meshes:
	@$(MAKE) --no-print-directory -C meshes

memcheck: $(BIN)
	tests/memcheck.sh

validate: deps-if-missing
	@$(MAKE) --no-print-directory $(PARALLEL) $(BIN)
	python3 tools/validate.py $(VALIDATE_ARGS)

bench: $(BIN)
	@$(MAKE) --no-print-directory -C bench

format:
	clang-format -i src/*.c src/*/*.c include/*.h include/private/*.h

clean:
	rm -rf build bin

print:
	@echo "CC       = $(CC)"
	@echo "CPPFLAGS = $(CPPFLAGS)"
	@echo "CFLAGS   = $(CFLAGS) $(STDFLAGS)"
	@echo "LDLIBS   = $(LDLIBS)"

-include $(OBJ:.o=.d)
