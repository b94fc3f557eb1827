#!/usr/bin/env python3
"""The work a drive supplies over a run (energy.csv's supplied_work): its largest magnitude, and a bound checked
(--below W: bounded, the spin stable; --above W: the drive pours energy into a diverging mode). A test filter.

    python3 tests/tools/drive_work.py OUTDIR --below 100
"""
import argparse
import csv
import os
import sys

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("outdir")
ap.add_argument("--below", type=float)
ap.add_argument("--above", type=float)
a = ap.parse_args()
with open(os.path.join(a.outdir, "energy.csv"), newline="") as f:
    w = [abs(float(r["supplied_work"])) for r in csv.DictReader(f)]
if not w:
    sys.exit("drive_work.py: no row in energy.csv")
m = max(w)
if a.below is not None:
    print("max |supplied work| %.3g J below %g J (bounded): %s" % (m, a.below, "PASS" if m < a.below else "FAIL"))
if a.above is not None:
    print("max |supplied work| %.3g J above %g J (diverging): %s" % (m, a.above, "PASS" if m > a.above else "FAIL"))
