#!/bin/sh
# phlex benchmarks: run named cases, keep the raw logs.
#
#   bench/run.sh list                 print the case names
#   bench/run.sh CASE [CASE ...]      run cases (globs allowed: 'modes_*')
#   bench/run.sh all                  every case except the large mesh (modes_h0.007)
#   NAME=x NP=1 ARGS='-analysis modes ...' bench/run.sh custom
#
# Environment (all optional):
#   PHLEX=bin/phlex      binary; copy it first (cp bin/phlex /tmp/phlex_bench) to time one fixed build
#   REPEAT=2             runs per case; the report takes the fastest
#   FIRST=1              number of the first run (FIRST=3 REPEAT=1 adds a third run r3 to existing logs)
#   RESULTS=bench/results  where the logs go (<case>.r<i>.log, <case>.r<i>.modes.csv)
#   MESHDIR=meshes/bench benchmark meshes (make -C meshes bench BENCH_H="0.02 0.01 0.007" BENCH_FORMAT="msh41 -bin")
#   MPIEXEC=mpiexec      launcher for NP > 1
#   TAG=                 suffix of the log names (e.g. TAG=_refblas when running with the reference BLAS)
#   EXTRA=               options appended to every case
#   OUTROOT=/tmp/bench   output directories of the runs (<OUTROOT>_modes/<case>, <OUTROOT>_tr/<case>, <OUTROOT>_fl/<case>)
#   QUIET_WAIT=0         before each run, wait up to this many seconds until the other processes use less
#                        than a quarter of one CPU (for 2-rank cases on a shared 2-core machine)
#
# Each log holds: a header (date, commit, binary checksum, BLAS in use, load), the command, phlex's output
# with -log_view, the samples of /proc/loadavg taken during the run, and /usr/bin/time -v.
# For NP > 1 it also holds one "phlex-rank r maxrss_kb ..." line per rank (peak RSS of each rank).
# Run from the repository root; the cases name meshes and presets by relative paths.
set -eu

PHLEX=${PHLEX:-bin/phlex}
REPEAT=${REPEAT:-2}
FIRST=${FIRST:-1}
RESULTS=${RESULTS:-bench/results}
MESHDIR=${MESHDIR:-meshes/bench}
MPIEXEC=${MPIEXEC:-mpiexec}
TAG=${TAG:-}
EXTRA=${EXTRA:-}
OUTROOT=${OUTROOT:-/tmp/bench}
QUIET_WAIT=${QUIET_WAIT:-0}
NP_CUSTOM=${NP:-1}

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_ess_singleton_isolated=1

STEEL="-body0_youngs_modulus 2.1e11 -body0_poissons_ratio 0.3 -body0_density 7800"

# case_args NAME: sets NP and ARGS for a named case; returns 1 if unknown.
case_args() {
  NP=1
  case $1 in
  # --- modal analysis: free-free bar, 20 elastic modes (+ 6 rigid), P2
  modes_h*)
    rest=${1#modes_h}          # 0.01, 0.01_np2, 0.01_amf, ...
    h=${rest%%_*}
    variant=
    [ "$h" = "$rest" ] || variant=${rest#*_}
    ARGS="-analysis modes -body0_dm_plex_filename $MESHDIR/bar_h$h.msh $STEEL -body0_petscspace_degree 2 -modes_nev 20 -output_dir ${OUTROOT}_modes/$1$TAG -output_fields 0 -log_view"
    case $variant in
    '') ;;
    np2) NP=2 ;;
    clamp) ARGS="$ARGS -body0_frame_patch clamp" ;;
    view) ARGS="$ARGS -modes_eps_view" ;;
    amf) ARGS="$ARGS -modes_st_mat_mumps_icntl_7 2 -modes_eps_view" ;;
    amd) ARGS="$ARGS -modes_st_mat_mumps_icntl_7 0 -modes_eps_view" ;;
    pord) ARGS="$ARGS -modes_st_mat_mumps_icntl_7 4 -modes_eps_view" ;;
    tol1e-8) ARGS="$ARGS -modes_eps_tol 1e-8" ;;
    nopurify) ARGS="$ARGS -modes_eps_purify 0" ;;
    ncv80) ARGS="$ARGS -modes_eps_ncv 80" ;;
    *) return 1 ;;
    esac
    ;;
  # --- transient: clamped cantilever, first bending mode (beam shape), implicit midpoint
  #     tr_<preset>_h<h>_s<steps>[_np2]
  tr_*)
    rest=${1#tr_}
    preset=${rest%%_*}
    rest=${rest#*_h}
    h=${rest%%_*}
    rest=${rest#*_s}
    steps=${rest%%_*}
    [ "$steps" = "$rest" ] || { [ "${rest#*_}" = np2 ] && NP=2 || return 1; }
    [ -f "options/solver/$preset.opts" ] || return 1
    ARGS="-options_file options/cantilever.yaml -solver_options_file options/solver/$preset.opts -body0_dm_plex_filename $MESHDIR/bar_h$h.msh -body0_ic_velocity_type beam -body0_ic_velocity_direction 0,0,1 -ts_max_steps $steps -output_fields 0 -output_dir ${OUTROOT}_tr/$1$TAG -log_view"
    ;;
  # --- floating body against the same body clamped: fl_<variant>_h<h>_s<steps>
  #     full, frozen: options/floating_tumbling.yaml (full or frozen inertia), preset bordered.opts
  #     full_iterative, frozen_iterative: the same with options/solver/bordered_iterative.opts
  #     clamped_<preset>: options/cantilever.yaml (beam-shaped initial velocity), preset <preset>.opts
  #     all with P2 velocity and dt = 2e-4 s
  fl_*)
    rest=${1#fl_}
    variant=${rest%%_h*}
    rest=${rest#*_h}
    h=${rest%%_*}
    steps=${rest#*_s}
    mesh="-body0_dm_plex_filename $MESHDIR/bar_h$h.msh"
    common="-ts_max_steps $steps -output_fields 0 -output_dir ${OUTROOT}_fl/$1$TAG -log_view"
    case $variant in
    full) ARGS="-options_file options/floating_tumbling.yaml $mesh $common" ;;
    frozen) ARGS="-options_file options/floating_tumbling.yaml -body0_inertia constant_without_gyroscopic $mesh $common" ;;
    full_iterative|frozen_iterative)
      inertia=${variant%_iterative}
      ARGS="-options_file options/floating_tumbling.yaml -body0_inertia $inertia -solver_options_file options/solver/bordered_iterative.opts $mesh $common" ;;
    clamped_*)
      preset=${variant#clamped_}
      [ -f "options/solver/$preset.opts" ] || return 1
      ARGS="-options_file options/cantilever.yaml -solver_options_file options/solver/$preset.opts $mesh -body0_ic_velocity_type beam -body0_ic_velocity_direction 0,0,1 -ts_dt 2e-4 $common" ;;
    *) return 1 ;;
    esac
    ;;
  # --- mechanism: two floating flexible bars, the flexible double pendulum (options/flexible_double_pendulum.yaml),
  #     against each bar alone: mb_<variant>_h<h>_s<steps>
  #     pair: both bars, shoulder and elbow revolutes; pinned: the upper bar alone on its shoulder revolute (a
  #     flexible pendulum); free: the upper bar alone, falling freely (no joint). P2, dt = 2e-4 s, preset bordered.opts
  mb_*)
    rest=${1#mb_}
    variant=${rest%%_h*}
    rest=${rest#*_h}
    h=${rest%%_*}
    steps=${rest#*_s}
    mesh="-body0_dm_plex_filename $MESHDIR/bar_h$h.msh -body1_dm_plex_filename $MESHDIR/bar_h$h.msh"
    common="-options_file options/flexible_double_pendulum.yaml $mesh -ts_max_steps $steps -output_fields 0 -output_dir ${OUTROOT}_mb/$1$TAG -log_view"
    case $variant in
    pair) ARGS="$common" ;;
    pinned) ARGS="$common -num_bodies 1 -num_joints 1" ;;
    free) ARGS="$common -num_bodies 1 -num_joints 0" ;;
    *) return 1 ;;
    esac
    ;;
  custom)
    [ -n "${NAME:-}" ] && [ -n "${ARGS:-}" ] || { echo "custom needs NAME and ARGS" >&2; return 1; }
    NP=$NP_CUSTOM
    ;;
  *) return 1 ;;
  esac
  return 0
}

ALL_CASES="modes_h0.02 modes_h0.01 modes_h0.01_np2 modes_h0.01_clamp modes_h0.01_amf modes_h0.01_amd modes_h0.01_tol1e-8"
for p in exact ldlt iterative; do
  for h in 0.02 0.01; do
    ALL_CASES="$ALL_CASES tr_${p}_h${h}_s20 tr_${p}_h${h}_s40"
  done
done
ALL_CASES="$ALL_CASES tr_exact_h0.01_s20_np2 tr_exact_h0.01_s40_np2"
FLOAT_CASES="fl_clamped_exact_h0.013_s10 fl_clamped_exact_h0.013_s20 fl_frozen_h0.013_s10 fl_frozen_h0.013_s20 fl_full_h0.013_s10 fl_full_h0.013_s20 fl_clamped_iterative_h0.006_s2 fl_full_iterative_h0.006_s2"
MB_CASES="mb_pair_h0.02_s5 mb_pinned_h0.02_s5 mb_free_h0.02_s5 mb_pair_h0.02_s15 mb_pinned_h0.02_s15 mb_free_h0.02_s15 mb_pair_h0.013_s3 mb_pinned_h0.013_s3 mb_free_h0.013_s3 mb_pair_h0.013_s8 mb_pinned_h0.013_s8 mb_free_h0.013_s8"
EXTRA_CASES="$FLOAT_CASES $MB_CASES modes_h0.007 modes_h0.01_view modes_h0.01_pord modes_h0.01_nopurify modes_h0.01_ncv80"

# busy CPU time of the whole machine so far, in clock ticks (user + nice + system + irq + softirq + steal)
cpu_busy() { awk '/^cpu /{print $2 + $3 + $4 + $7 + $8 + $9; exit}' /proc/stat; }
TICKS=$(getconf CLK_TCK)

# wait until the machine is nearly idle (other processes below 0.25 CPU over 3 s), at most QUIET_WAIT s
wait_quiet() {
  [ "$QUIET_WAIT" -gt 0 ] || return 0
  waited=0
  while [ "$waited" -lt "$QUIET_WAIT" ]; do
    b0=$(cpu_busy); sleep 3; b1=$(cpu_busy)
    [ $(( (b1 - b0) * 100 / (3 * TICKS) )) -lt 25 ] && { echo "# waited ${waited} s for a quiet machine"; return 0; }
    waited=$((waited + 3))
  done
  echo "# machine still busy after ${QUIET_WAIT} s; running anyway"
}

blas_in_use() {
  b=$(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null || echo '?')
  l=$(readlink -f /usr/lib/x86_64-linux-gnu/liblapack.so.3 2>/dev/null || echo '?')
  echo "libblas.so.3 -> $b; liblapack.so.3 -> $l"
}

run_case() {
  name=$1
  if [ "$name" = custom ]; then
    case_args custom || exit 2
    name=$NAME
  else
    case_args "$name" || { echo "unknown case: $name (bench/run.sh list)" >&2; exit 2; }
  fi
  ARGS="$ARGS $EXTRA"
  mkdir -p "$RESULTS"
  i=$FIRST
  while [ "$i" -lt $((FIRST + REPEAT)) ]; do
    log=$RESULTS/$name$TAG.r$i.log
    tmp=$RESULTS/.$name$TAG.r$i
    rm -f "$tmp".*
    if [ "$NP" -gt 1 ]; then
      # one /usr/bin/time per rank: the peak RSS of each rank
      set -- "$MPIEXEC" -n "$NP" sh -c 'exec /usr/bin/time -f "phlex-rank $OMPI_COMM_WORLD_RANK maxrss_kb %M wall_s %e" -o "$0.rank$OMPI_COMM_WORLD_RANK" "$@"' "$tmp" "$PHLEX"
    else
      set -- "$PHLEX"
    fi
    quiet=$(wait_quiet)
    {
      echo "# bench case: $name$TAG run $i (runs $FIRST..$((FIRST + REPEAT - 1)))"
      [ -z "$quiet" ] || echo "$quiet"
      echo "# date: $(date -Is)"
      echo "# host: $(hostname) nproc $(nproc) cpu $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
      echo "# commit: $(git log -1 --format=%h 2>/dev/null || echo '?') (worktree $(git status --porcelain -- src include 2>/dev/null | wc -l | tr -d ' ') changed files under src/ include/)"
      echo "# binary: $PHLEX md5 $(md5sum < "$PHLEX" | cut -c1-12) mtime $(date -r "$PHLEX" -Is)"
      echo "# blas: $(blas_in_use)"
      echo "# np: $NP"
      echo "# loadavg before: $(cat /proc/loadavg)"
      echo "# command: $* $ARGS"
    } > "$log"
    echo "== $name$TAG run $i: $* $ARGS" >&2
    # sample the load every 5 s while the run lasts
    ( while :; do echo "# loadavg during: $(cat /proc/loadavg)"; sleep 5; done ) > "$tmp.load" &
    sampler=$!
    status=0
    busy0=$(cpu_busy)
    # shellcheck disable=SC2086
    /usr/bin/time -v -o "$tmp.time" "$@" $ARGS >> "$log" 2>&1 || status=$?
    busy1=$(cpu_busy)
    kill "$sampler" 2>/dev/null || true
    wait "$sampler" 2>/dev/null || true
    {
      cat "$tmp.load"
      echo "# loadavg after: $(cat /proc/loadavg)"
      echo "# machine busy CPU during the run: $(awk -v a="$busy0" -v b="$busy1" -v t="$TICKS" 'BEGIN { printf "%.1f", (b - a) / t }') s (all processes; compare with user + system below)"
      for f in "$tmp".rank*; do [ -f "$f" ] && cat "$f"; done
      echo "# exit status: $status"
      cat "$tmp.time"
    } >> "$log"
    rm -f "$tmp".*
    # keep the modal frequencies (full precision)
    out=$(echo "$ARGS" | sed -n 's/.*-output_dir \([^ ]*\).*/\1/p')
    [ -n "$out" ] && [ -f "$out/modes.csv" ] && cp "$out/modes.csv" "$RESULTS/$name$TAG.r$i.modes.csv"
    [ -n "$out" ] && rm -rf "$out"
    grep -E '^[[:space:]]*(Elapsed \(wall clock\)|Maximum resident)' "$log" | sed 's/^[[:space:]]*/   /' >&2
    [ "$status" -eq 0 ] || echo "   exit status $status (see $log)" >&2
    i=$((i + 1))
  done
}

[ $# -ge 1 ] || { sed -n '2,22p' "$0"; exit 2; }
[ -x "$PHLEX" ] || { echo "no binary $PHLEX (make, or set PHLEX)" >&2; exit 2; }

for arg in "$@"; do
  case $arg in
  list) for c in $ALL_CASES $EXTRA_CASES; do echo "$c"; done ;;
  all) for c in $ALL_CASES; do run_case "$c"; done ;;
  *[*?]*)
    matched=0
    for c in $ALL_CASES $EXTRA_CASES; do
      # shellcheck disable=SC2254
      case $c in $arg) run_case "$c"; matched=1 ;; esac
    done
    [ $matched -eq 1 ] || { echo "no case matches $arg" >&2; exit 2; } ;;
  *) run_case "$arg" ;;
  esac
done
