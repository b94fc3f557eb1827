#!/usr/bin/env python3
"""Step-to-step smoothness of a joint's written wrench (a test filter).

A multiplier that oscillates from step to step (the end-of-step multipliers of the midpoint rule do: they are
determined only as a two-step average) shows as second differences |F_{n+1} - 2 F_n + F_{n-1}| of the order of
the force itself; a smooth series has second differences ~ dt^2 |F''|. Reads <joint>_joint.csv, skips the first
row (the consistent start), and reports for the chosen columns max |second difference| / max |F| against --max.
Standard library only.

    python3 tests/tools/wrench_smoothness.py hinge_joint.csv --columns Fx,Fy --max 1e-3
"""

import argparse
import csv
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--columns", default="Fx,Fy,Fz,Mx,My,Mz")
    ap.add_argument("--max", type=float, default=1e-3)
    args = ap.parse_args()
    with open(args.csv) as f:
        rows = list(csv.DictReader(f))[1:]
    cols = [c for c in args.columns.split(",") if c]
    scale = max(abs(float(r[c])) for r in rows for c in cols)
    worst = 0.0
    for c in cols:
        x = [float(r[c]) for r in rows]
        for i in range(1, len(x) - 1):
            worst = max(worst, abs(x[i + 1] - 2 * x[i] + x[i - 1]))
    ratio = worst / scale if scale > 0 else 0.0
    ok = ratio <= args.max
    print(f"joint wrench second differences ({','.join(cols)}) / max |wrench| {'<' if ok else '>'} {args.max:g}: {'PASS' if ok else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
