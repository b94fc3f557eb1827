#!/usr/bin/env python3
"""A reduced body against the full one in the same scene: runs the scene with the body reduced on a growing number of
normal modes (--modes; --option names another option of the body that grows the basis, e.g. reduction_krylov_order),
compares chosen series with the full body's run (--ref, already made), and checks that every
column's error (max over time of |reduced - full| / max |full|) falls strictly as the modes grow and that the largest
number of modes meets the stated tolerance (--tol column=bound). Prints one PASS/FAIL line per check (with the errors
on failure, or always with --verbose); exit 1 on any failure. With --no-run it runs nothing and compares the runs a
test made itself (its args2, args3, ...: the runner then checks each) in OUTDIR/modes<n>."""
import argparse
import csv
import os
import shutil
import subprocess
import sys

p = argparse.ArgumentParser()
p.add_argument("--bin", default="bin/phlex")
p.add_argument("--outdir", required=True)
p.add_argument("--ref", required=True, help="the full body's output directory")
p.add_argument("--body", default="body0")
p.add_argument("--modes", required=True, help="comma-separated numbers of normal modes, ascending")
p.add_argument("--option", default="reduction_modes", help="the body's option that --modes sets (default reduction_modes)")
p.add_argument("--series", required=True, help="file:column,column;file:column... compared")
p.add_argument("--tol", required=True, help="column=bound,... for the largest number of modes")
p.add_argument("--verbose", action="store_true")
p.add_argument("--no-run", action="store_true", help="compare the runs already in OUTDIR/modes<n>")
p.add_argument("args", nargs=argparse.REMAINDER, help="the scene's arguments (after --)")
a = p.parse_args()
args = [x for x in a.args if x != "--"]
modes = [int(x) for x in a.modes.split(",")]
series = [(s.split(":")[0], s.split(":")[1].split(",")) for s in a.series.split(";")]
tol = {k: float(v) for k, v in (t.split("=") for t in a.tol.split(","))}
ok = True
what = "modes" if a.option == "reduction_modes" else a.option


def load(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def check(name, cond, detail=""):
    global ok
    print(f"{name}: {'PASS' if cond else 'FAIL'}{(' (' + detail + ')') if detail and (a.verbose or not cond) else ''}")
    ok = ok and cond


errors = []
for n in modes:
    out = os.path.join(a.outdir, f"modes{n}")
    if not a.no_run:
        shutil.rmtree(out, ignore_errors=True)
        cmd = [a.bin] + args + ["-output_dir", out, "-progress", "0", f"-{a.body}_type", "reduced", f"-{a.body}_{a.option}", str(n)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode:
            check(f"{what} {n}: run", False, r.stderr[-300:])
            sys.exit(1)
    e = {}
    for fname, cols in series:
        ref, run = load(os.path.join(a.ref, fname)), load(os.path.join(out, fname))
        if len(ref) != len(run):
            check(f"{what} {n}: {fname} rows", False, f"{len(run)} against {len(ref)}")
            sys.exit(1)
        for c in cols:
            scale = max(abs(float(x[c])) for x in ref)
            e[c] = max(abs(float(x[c]) - float(y[c])) for x, y in zip(ref, run)) / scale
    errors.append(e)

cols = [c for _, cs in series for c in cs]
table = "; ".join(f"{n}: " + " ".join(f"{c} {errors[i][c]:.2e}" for c in cols) for i, n in enumerate(modes))
falls = all(errors[i + 1][c] < errors[i][c] for i in range(len(modes) - 1) for c in cols)
check(f"errors fall as the {what} grow{'s' if what != 'modes' else ''} ({a.modes})", falls, table)
last = errors[-1]
within = all(last[c] <= tol[c] for c in tol)
check(f"{what} {modes[-1]} within the tolerances" if what != "modes" else f"{modes[-1]} modes within the tolerances", within, " ".join(f"{c} {last[c]:.2e} (<= {tol[c]:g})" for c in tol))
sys.exit(0 if ok else 1)
