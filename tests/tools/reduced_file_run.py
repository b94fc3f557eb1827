#!/usr/bin/env python3
"""A reduced body file's life: built and written by a first run, read by a second (the same results), refused when the
scene changes (another number of modes, another material): exit 2, a message naming the file and the difference, and
nothing written. Prints one PASS/FAIL line per check; exit 1 on any failure."""
import argparse
import os
import shutil
import subprocess
import sys

p = argparse.ArgumentParser()
p.add_argument("--bin", default="bin/phlex")
p.add_argument("--outdir", required=True)
p.add_argument("args", nargs=argparse.REMAINDER, help="the scene's arguments (after --)")
a = p.parse_args()
args = [x for x in a.args if x != "--"]
os.makedirs(a.outdir, exist_ok=True)
rfile = os.path.join(a.outdir, "bar_reduced.h5")
ok = True


def run(extra, out):
    shutil.rmtree(out, ignore_errors=True)
    cmd = [a.bin] + args + ["-body0_reduced_file", rfile, "-output_dir", out, "-progress", "0"] + extra
    return subprocess.run(cmd, capture_output=True, text=True)


def check(name, cond, detail=""):
    global ok
    print(f"{name}: {'PASS' if cond else 'FAIL'}{(' (' + detail + ')') if detail and not cond else ''}")
    ok = ok and cond


r1 = run([], os.path.join(a.outdir, "build"))
check("first run builds and writes the file", r1.returncode == 0 and "built and written to" in r1.stdout and os.path.exists(rfile), r1.stderr[-300:])
r2 = run([], os.path.join(a.outdir, "read"))
check("second run reads it", r2.returncode == 0 and "read from" in r2.stdout, r2.stderr[-300:])
e1 = open(os.path.join(a.outdir, "build", "energy.csv")).read() if r1.returncode == 0 else "1"
e2 = open(os.path.join(a.outdir, "read", "energy.csv")).read() if r2.returncode == 0 else "2"
check("the same energy series, byte for byte", e1 == e2)
for extra, what in ((["-body0_reduction_modes", "4"], "4 normal modes"), (["-body0_youngs_modulus", "2.0e11"], "E 200000000000")):
    out = os.path.join(a.outdir, "mismatch")
    r = run(extra, out)
    check(f"a file built for another body is refused ({' '.join(extra)})", r.returncode == 2 and "was built for another body" in r.stderr and rfile in r.stderr and what in r.stderr, f"exit {r.returncode}: {r.stderr[-400:]}")
    check("  and nothing is written", not os.path.exists(out) or not os.listdir(out))
with open(os.path.join(a.outdir, "garbage.h5"), "w") as f:
    f.write("not hdf5\n")
r = subprocess.run([a.bin] + args + ["-body0_reduced_file", os.path.join(a.outdir, "garbage.h5"), "-output_dir", os.path.join(a.outdir, "garbage"), "-progress", "0"], capture_output=True, text=True)
check("a file that is not HDF5 is refused", r.returncode == 2 and "is not an HDF5 file" in r.stderr, f"exit {r.returncode}: {r.stderr[-300:]}")
sys.exit(0 if ok else 1)
