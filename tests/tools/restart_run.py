#!/usr/bin/env python3
"""Kills a checkpointed phlex run mid-way, restarts it, and compares it with an uninterrupted run.

1. runs bin/phlex with the given arguments into DIR/uninterrupted;
2. runs it again into DIR/interrupted with -progress_interval 0 and sends the signal once the progress line of step
   --after (past a checkpoint) has appeared; checks how it ended: SIGKILL leaves the process killed; SIGTERM and
   SIGINT exit with 128 + signal, naming the checkpoint;
3. restarts it: the same arguments plus -restart DIR/interrupted/checkpoint.h5, into DIR/interrupted;
4. compares every CSV series of both directories (the same header, the same number of rows: continued, not
   duplicated; every value within --rtol of its column's largest magnitude, at least 1e-6 of the series' largest
   value), the field snapshots' times in the XDMF
   indexes, and checks that nothing temporary is left.

With --signal NONE the first part of the interrupted run simply ends at step --after (-ts_max_steps) and the
restart continues it: a run extended from its final checkpoint, and the way to test restarts under mpiexec
(--launcher), whose handling of signals is its own. Such a test is better written as three runs of the spec (the
runner then checks each: exit status, time, unused options) and this tool's step 4 alone, --compare-only, on
DIR/uninterrupted and DIR/interrupted.

Prints deterministic verdict lines (not the step at which the signal landed, which depends on the machine's speed).

Usage: python3 tests/tools/restart_run.py --signal KILL --after 120 --outdir DIR -- <phlex arguments>
       python3 tests/tools/restart_run.py --signal NONE --after 150 --launcher "mpiexec -n 2" --outdir DIR -- <args>
       python3 tests/tools/restart_run.py --compare-only --outdir DIR
"""

import argparse
import csv
import shlex
import os
import re
import signal
import subprocess
import sys


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


def xdmf_times(path):
    with open(path) as f:
        return re.findall(r'<Time Value="([^"]+)"', f.read())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--signal", choices=["KILL", "TERM", "INT", "NONE"])
    parser.add_argument("--compare-only", action="store_true",
                        help="run nothing: compare DIR/interrupted (restarted) with DIR/uninterrupted")
    parser.add_argument("--launcher", default="", help="e.g. 'mpiexec --oversubscribe -n 2' (with --signal NONE)")
    parser.add_argument("--after", type=int, help="send the signal once this step is done")
    parser.add_argument("--outdir", required=True)
    parser.add_argument("--rtol", type=float, default=1e-10)
    parser.add_argument("phlex_args", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    if args.compare_only:
        return compare_dirs(args, os.path.join(args.outdir, "uninterrupted"), os.path.join(args.outdir, "interrupted"),
                            [])
    if args.signal is None or args.after is None:
        parser.error("--signal and --after are required (or --compare-only)")
    # as tests/run.py runs its MPI tests (root in a container, more ranks than cores)
    os.environ.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                      OMPI_MCA_rmaps_base_oversubscribe="1")
    phlex = shlex.split(args.launcher) + ["bin/phlex"] + [a for a in args.phlex_args if a != "--"]
    full, part = os.path.join(args.outdir, "uninterrupted"), os.path.join(args.outdir, "interrupted")
    problems = []

    run = subprocess.run(phlex + ["-output_dir", full], capture_output=True, text=True, timeout=600)
    if run.returncode:
        print("uninterrupted run: FAIL (exit %d): %s" % (run.returncode, run.stderr.strip()[-300:]))
        return 0

    if args.signal == "NONE":
        first = subprocess.run(phlex + ["-output_dir", part, "-ts_max_steps", str(args.after)], capture_output=True,
                               text=True, timeout=600)
        print("first part, %d steps: %s" % (args.after, "exit 0" if not first.returncode else
                                            "FAIL (exit %d): %s" % (first.returncode, first.stderr.strip()[-300:])))
        if first.returncode:
            return 0
        return compare(args, phlex, full, part, [])
    sig = getattr(signal, "SIG" + args.signal)
    proc = subprocess.Popen(phlex + ["-output_dir", part, "-progress_interval", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    signalled = False
    for line in proc.stdout:
        m = re.match(r"progress: step (\d+)", line)
        if m and int(m.group(1)) >= args.after:
            proc.send_signal(sig)
            signalled = True
            break
    proc.stdout.read()
    err = proc.stderr.read()
    rc = proc.wait(timeout=120)
    if not signalled:
        problems.append("the run ended (exit %d) before step %d: make it longer" % (rc, args.after))
    elif args.signal == "KILL":
        if rc != -sig:
            problems.append("exit status %d after SIGKILL" % rc)
    else:
        if rc != 128 + sig:
            problems.append("exit status %d, expected %d" % (rc, 128 + sig))
        if not re.search(r"interrupted by SIG%s at step \d+.*checkpoint written to" % args.signal, err):
            problems.append("stderr does not name the checkpoint: " + err.strip()[-300:])
    print("interrupted by SIG%s past step %d: %s" % (args.signal, args.after, "; ".join(problems) or "stopped as expected"))
    if problems:
        return 0
    return compare(args, phlex, full, part, problems)


def compare(args, phlex, full, part, problems) -> int:
    """restarts the interrupted run and compares both"""
    restart = subprocess.run(phlex + ["-output_dir", part, "-restart", os.path.join(part, "checkpoint.h5")],
                             capture_output=True, text=True, timeout=600)
    if restart.returncode:
        print("restart: FAIL (exit %d): %s" % (restart.returncode, restart.stderr.strip()[-400:]))
        return 0
    if not re.search(r"^Restart from .*: step \d+", restart.stdout, re.M):
        problems.append("no 'Restart from' line")
    return compare_dirs(args, full, part, problems)


def compare_dirs(args, full, part, problems) -> int:
    """compares the restarted run's directory with the uninterrupted run's"""
    series = sorted(f for f in os.listdir(full) if f.endswith(".csv"))
    worst = 0.0
    for name in series:
        p = os.path.join(part, name)
        if not os.path.exists(p):
            problems.append(name + " missing after the restart")
            continue
        h1, r1 = read_csv(os.path.join(full, name))
        h2, r2 = read_csv(p)
        if h1 != h2:
            problems.append(name + ": header differs")
            continue
        if len(r1) != len(r2):
            problems.append("%s: %d rows, the uninterrupted run %d" % (name, len(r2), len(r1)))
            continue
        # a column's scale, floored at 1e-6 of the series' largest value: a column of round-off (balance_residual)
        # is compared with the quantities it is the round-off of (parallel runs repeat to round-off only)
        floor = 1e-6 * max(abs(v) for r in r1 for v in r)
        for c in range(len(h1)):
            scale = max(max(abs(r[c]) for r in r1), floor) or 1.0
            for a, b in zip(r1, r2):
                worst = max(worst, abs(a[c] - b[c]) / scale)
    if worst > args.rtol:
        problems.append("largest difference %.3e of a column's scale, more than %g" % (worst, args.rtol))
    snapshots = 0
    for name in sorted(f for f in os.listdir(full) if f.endswith(".xmf")):
        t1, t2 = xdmf_times(os.path.join(full, name)), xdmf_times(os.path.join(part, name))
        if t1 != t2:
            problems.append("%s: snapshots at %s, the uninterrupted run at %s" % (name, t2, t1))
        snapshots += len(t1)
        for ref in set(re.findall(r">([^<>:]+\.h5):", open(os.path.join(part, name)).read())):
            if not os.path.exists(os.path.join(part, ref)):
                problems.append("%s refers to %s, which is missing" % (name, ref))
    left = sorted(f for f in os.listdir(part) if f.startswith("."))
    if left:
        problems.append("left in the output directory: " + ", ".join(left))
    print("restart: %d series continued, %d field snapshots: %s" % (len(series), snapshots,
          "FAIL: " + "; ".join(problems) if problems else "PASS (the same as the uninterrupted run to %g)" % args.rtol))
    return 0


if __name__ == "__main__":
    sys.exit(main())
