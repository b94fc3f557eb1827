#!/bin/sh
# Weak scaling of the iterative path: the same bar refined so that each process holds about the same number of
# velocity DOFs (h = H1 * P^(-1/3)), P = 1, 2, 4, ... processes, the clamped bar in its first bending shape with
# options/solver/iterative.opts (SNES phlexcondensed, CG + p-multigrid; PRESET=options/solver/iterative_gamg.opts for
# GAMG), a few steps each.
#
#   bench/weak_scaling.sh [P ...]                 default: 1 2 4
#   H1=0.013 STEPS=4 bench/weak_scaling.sh 1 2 4 8
#
# Environment (all optional):
#   PHLEX=bin/phlex        binary
#   H1=0.013               mesh size on one process (0.013: 1.1e5 P2 velocity DOFs; 0.006: 9.5e5)
#   STEPS=4                steps per run (the first holds the preconditioner's set-up: per step is taken from the log, see below)
#   MPIEXEC="mpiexec"      launcher (e.g. "srun" inside a SLURM allocation, or "mpiexec --hostfile hosts")
#   RESULTS=bench/results  where the logs go (weak_P<p>_h<h>.log)
#   PRESET=options/solver/iterative.opts
#   EXTRA=                 options appended (e.g. -condensed_ksp_rtol 1e-8)
#
# Prints two lines per P: DOFs, DOFs per process, CG iterations per step, KSPSolve per step (the solves only: the
# preconditioner's set-up is PCSetUp's, printed apart), peak RSS of the largest process (/usr/bin/time -v of the launcher is not
# that: phlex's own -memory_view line is used when present), and the efficiency T(1)/T(P) of the solve per step;
# then the communication of a step (the steps less the preconditioner's set-up, from -log_view): global reductions, messages and
# bytes sent per process (counts do not depend on the machine: oversubscribed runs give them too).
# Meshes: meshes/bench/bar_h<h>.msh, made by `make -C meshes bench/bar_h<h>.msh` (gmsh) when missing; each process
# count's mesh is read by rank 0 and distributed (it must fit there once).
# Not measured on the development machine beyond 2 processes (it has 2 cores): see README.md "Running on a cluster".
set -eu
PHLEX=${PHLEX:-bin/phlex}
H1=${H1:-0.013}
STEPS=${STEPS:-4}
MPIEXEC=${MPIEXEC:-mpiexec}
RESULTS=${RESULTS:-bench/results}
PRESET=${PRESET:-options/solver/iterative.opts}
EXTRA=${EXTRA:-}
[ $# -gt 0 ] || set -- 1 2 4
export OMPI_ALLOW_RUN_AS_ROOT=${OMPI_ALLOW_RUN_AS_ROOT:-1} OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}
mkdir -p "$RESULTS"
t1=
for P in "$@"; do
  case $P in ''|*[!0-9]*) echo "weak_scaling.sh: the process count must be a positive integer, got '$P'" >&2; exit 2 ;; esac
  h=$(python3 -c "print('%.4g' % ($H1 * $P ** (-1.0 / 3)))")
  mesh=meshes/bench/bar_h$h.msh
  [ -f "$mesh" ] || make -C meshes "bench/bar_h$h.msh" BENCH_FORMAT="msh41 -bin" >/dev/null
  log=$RESULTS/weak_P${P}_h$h.log
  { echo "# date: $(date -u +%FT%TZ) load: $(cat /proc/loadavg) commit: $(git rev-parse --short HEAD 2>/dev/null || echo -)"
    echo "# command: $MPIEXEC -n $P $PHLEX ... $mesh"; } > "$log"
  # shellcheck disable=SC2086
  $MPIEXEC -n "$P" "$PHLEX" -options_file options/cantilever.yaml -solver_options_file "$PRESET" \
    -body0_dm_plex_filename "$mesh" -body0_ic_velocity_type beam -body0_ic_velocity_direction 0,0,1 -ts_dt 2e-4 \
    -ts_max_steps "$STEPS" -output_fields 0 -progress 0 -output_dir "/tmp/phlex_weak_P$P" -log_view -memory_view \
    -condensed_ksp_converged_reason $EXTRA >> "$log" 2>&1
  python3 - "$log" "$P" "${t1:-0}" <<'PY'
import re, sys
log, P, t1 = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
txt = open(log).read()
its = [int(m) for m in re.findall(r"condensed_ solve converged due to \w+ iterations (\d+)", txt)]
dofs = re.search(r"velocity P\d \((\d+) dofs\)", txt)
ksp = re.search(r"^KSPSolve\s+(\d+)\s+\S+\s+(\S+)", txt, re.M)
pcs = re.search(r"^PCSetUp\s+\d+\s+\S+\s+(\S+)", txt, re.M)
mem = re.search(r"Maximum \(over computational time\) process memory:\s+total\s+\S+\s+max\s+(\S+)", txt)  # -memory_view
n = int(dofs.group(1)) if dofs else 0
per = float(ksp.group(2)) / max(1, int(ksp.group(1))) if ksp else float("nan")
print("P %d | velocity DOFs %d (%d per process) | CG its per step %s | KSPSolve per step %.3g s | PCSetUp %s s | max RSS %s B%s"
      % (P, n, n // P, "%.1f" % (sum(its) / len(its)) if its else "-", per, pcs.group(1) if pcs else "-",
         mem.group(1) if mem else "-", " | efficiency %.2f" % (t1 / per) if t1 > 0 else ""))
# communication per step, from the "Phlex Transient" stage's event lines (-log_view: Mess is the count of messages
# sent by all processes, AvgLen their mean length in bytes, Reduct the global reductions): the events that repeat
# every step (the CG solve, the stress passes, the energy monitor) over the steps; the one-time set-up inside the
# first step (the preconditioner's PCSetUp, the operator's assembly) is left out. One process counts no reductions.
stage = txt.split("--- Event Stage 3: Phlex Transient")[1].split("--- Event Stage")[0] if "--- Event Stage 3: Phlex Transient" in txt else ""
def ev(name):
    m = re.search(r"^%s\s+(\d+)\s+\S+\s+\S+\s+\S+\s+\S+\s+\S+\s+(\S+)\s+(\S+)\s+(\S+)" % name, stage, re.M)
    return (float(m.group(2)), float(m.group(3)), float(m.group(4))) if m else (0.0, 0.0, 0.0)
m = re.search(r"^TSStep\s+(\d+)", stage, re.M)
steps = int(m.group(1)) if m else 0
if steps:
    rows = [ev(e) for e in ("KSPSolve", "PhlexStressMaps", "PhlexMonEnergy")]
    msg = sum(x[0] for x in rows) / steps
    byt = sum(x[0] * x[1] for x in rows) / steps
    red = sum(x[2] for x in rows) / steps
    print("P %d | per step: %.0f reductions (CG %.0f), %.0f messages per process, %.0f kB sent per process (mean %.0f B)"
          % (P, red, rows[0][2] / steps, msg / P, byt / P / 1e3, byt / msg if msg else 0.0))
open("/tmp/phlex_weak_t1", "w").write(repr(per) if P == 1 else repr(t1))
PY
  t1=$(cat /tmp/phlex_weak_t1)
done
