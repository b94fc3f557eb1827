#!/usr/bin/env python3
"""Observed order of a scheme from two runs at steps dt and dt/2: the largest |total - total_0| of energy.csv and
the largest 'orthogonality' (||R^T R - I||) of the <body>_rigid.csv series, each ratio against 2^order.

Usage: python3 tests/tools/drift_order.py DIR_DT DIR_HALF --order 2 [--tol 0.3] [--no-energy]
Prints one line per quantity: the two values, the observed order, PASS or FAIL (|observed - order| <= tol).
"""

import argparse
import csv
import glob
import math
import os
import sys


def column_max(path, name, relative_to_first=False):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    values = [float(r[name]) for r in rows]
    if relative_to_first:
        values = [v - values[0] for v in values]
    return max(abs(v) for v in values)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("coarse")
    parser.add_argument("fine")
    parser.add_argument("--order", type=float, required=True)
    parser.add_argument("--tol", type=float, default=0.3)
    parser.add_argument("--no-energy", action="store_true", help="the rotations' drift only")
    args = parser.parse_args()
    quantities = [] if args.no_energy else [("energy drift max |H - H0|", "energy.csv", "total", True)]
    for path in sorted(glob.glob(os.path.join(args.coarse, "*_rigid.csv"))):
        quantities.append(("orthogonality of " + os.path.basename(path)[:-10], os.path.basename(path), "orthogonality", False))
    for label, name, col, rel in quantities:
        a = column_max(os.path.join(args.coarse, name), col, rel)
        b = column_max(os.path.join(args.fine, name), col, rel)
        order = math.log2(a / b) if a > 0 and b > 0 else float("nan")
        ok = abs(order - args.order) <= args.tol
        print("%s: %.3e at dt, %.3e at dt/2, order %.2f: %s" % (label, a, b, order,
              "PASS (expected %g +- %g)" % (args.order, args.tol) if ok else "FAIL (expected %g +- %g)" % (args.order, args.tol)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
