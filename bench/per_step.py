#!/usr/bin/env python3
"""Time per step of a phlex transient run, by differencing two runs of different lengths.

Runs the same phlex command with -ts_max_steps SHORT and LONG (under /usr/bin/time -v, with -log_view) and prints
    per step = [S(LONG) - S(SHORT)] / (LONG - SHORT),
S = the "Phlex Transient" stage less its one-time events (the factorizations in PCSetUp, the stage solvers' set-up
PhlexCondSetUp / PhlexRedSetUp), so that their run-to-run noise does not enter; with the energy monitor, as a user's
run has it. Also the solves, products and monitor per step, and the peak RSS of the longer run (per process).
Several binaries (--phlex A --phlex B ...) are interleaved run by run, --repeat times, so that a slow spell of a
shared machine hits them alike.

Example (BENCHMARKS.md section 17, the floating bar against the same bar clamped):
    python3 bench/per_step.py --phlex /tmp/phlex_new --phlex /tmp/phlex_old --short 5 --long 15 -- \\
        -options_file options/floating_tumbling.yaml -body0_dm_plex_filename meshes/bench/bar_h0.013.msh
"""
import argparse
import os
import re
import subprocess
import sys

ONE_TIME = ["PCSetUp", "PhlexCondSetUp", "PhlexRedSetUp"]
PER_STEP = ["MatSolve", "MatMult", "MatMultTranspose", "PhlexMonEnergy"]


def stage_events(log):
    """the Phlex Transient stage's time and its events' times, from -log_view"""
    m = re.search(r"^\s*\d+:\s+Phlex Transient:\s+(\S+)", log, re.M)
    if not m:
        raise RuntimeError("no 'Phlex Transient' stage in the log (did the run fail?)")
    start = log.index("--- Event Stage")
    sec = log[log.index("Phlex Transient", log.index("--- Event Stage", start)):]
    sec = sec[: sec.find("\n---", 10)]
    ev = {}
    for line in sec.splitlines():
        f = line.split()
        if len(f) > 4 and re.match(r"^[0-9]", f[1]):
            try:
                ev[f[0]] = float(f[3])
            except ValueError:
                pass
    return float(m.group(1)), ev


def run(phlex, np, steps, args, outdir):
    cmd = ["/usr/bin/time", "-v"]
    if np > 1:
        cmd += ["mpiexec", "-n", str(np)]
    cmd += [phlex] + args + ["-ts_max_steps", str(steps), "-output_fields", "0", "-output_dir", outdir, "-log_view"]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode:
        sys.stderr.write(p.stdout[-2000:] + p.stderr[-2000:])
        raise RuntimeError(f"{' '.join(cmd)} failed with exit code {p.returncode}")
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    st, ev = stage_events(p.stdout)
    return st, ev, int(rss.group(1)) / 1048576 if rss else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--phlex", action="append", help="binary (repeat the option to interleave several)")
    ap.add_argument("--np", type=int, default=1, help="MPI ranks")
    ap.add_argument("--short", type=int, default=20, help="steps of the short run")
    ap.add_argument("--long", type=int, default=40, help="steps of the long run")
    ap.add_argument("--repeat", type=int, default=1, help="rounds")
    ap.add_argument("--outdir", default="/tmp/phlex_per_step", help="scratch output directory")
    ap.add_argument("args", nargs=argparse.REMAINDER, help="-- then the phlex options of the case")
    a = ap.parse_args()
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    if not a.phlex:
        a.phlex = ["bin/phlex"]
    if a.long <= a.short:
        ap.error(f"--long ({a.long}) must be larger than --short ({a.short})")
    for r in range(a.repeat):
        for b in a.phlex:
            res = {}
            for n in (a.short, a.long):
                st, ev, rss = run(b, a.np, n, args, a.outdir)
                res[n] = (st - sum(ev.get(e, 0.0) for e in ONE_TIME), ev, rss)
            d = a.long - a.short
            step = (res[a.long][0] - res[a.short][0]) / d
            parts = ", ".join(f"{e} {(res[a.long][1].get(e, 0) - res[a.short][1].get(e, 0)) / d:.4f}" for e in PER_STEP)
            print(f"round {r} {b} np {a.np}: per step {step:.4f} s ({parts}); peak RSS {res[a.long][2]:.3f} GiB", flush=True)


if __name__ == "__main__":
    main()
