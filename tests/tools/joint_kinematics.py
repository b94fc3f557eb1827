#!/usr/bin/env python3
"""What a joint allows and forbids, from its series <joint>_joint.csv (a test filter).

Forbidden: every gap_* column (the position-level violation of each constrained direction) stays below --gap.
Allowed: every column named in --moves (angle, slide, rot1, ...) changes over the run by more than --min.
Prints one PASS/FAIL line for each. Standard library only.

    python3 tests/tools/joint_kinematics.py j_joint.csv --moves angle --min 0.1 --gap 1e-12
"""

import argparse
import csv
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--moves", default="", help="comma-separated motion columns that must change")
    ap.add_argument("--min", type=float, default=0.1, help="smallest range of an allowed motion [rad or m]")
    ap.add_argument("--gap", type=float, default=1e-12, help="largest violation of a forbidden motion [rad or m]")
    args = ap.parse_args()

    with open(args.csv) as f:
        rows = list(csv.DictReader(f))
    cols = rows[0].keys()
    gaps = [c for c in cols if c.startswith("gap_")]
    worst = max((abs(float(r[c])) for r in rows for c in gaps), default=0.0)
    ok = worst <= args.gap
    print(f"forbidden ({', '.join(g[4:] for g in gaps)}) below {args.gap:g}: {'PASS' if ok else 'FAIL (' + format(worst, '.1e') + ')'}")
    allok = ok
    for c in [m for m in args.moves.split(",") if m]:
        if c not in cols:
            print(f"allowed {c}: FAIL (no such column)")
            allok = False
            continue
        vals = [float(r[c]) for r in rows]
        rng = max(vals) - min(vals)
        ok = rng >= args.min
        allok = allok and ok
        print(f"allowed {c} moves by more than {args.min:g}: {'PASS' if ok else 'FAIL (' + format(rng, '.1e') + ')'}")
    return 0 if allok else 1


if __name__ == "__main__":
    sys.exit(main())
