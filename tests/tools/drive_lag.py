#!/usr/bin/env python3
"""A revolute drive's angle gap against the Cayley map's lag, step by step (a test filter).

A drive at constant rate W imposed at velocity level turns its joint by 2 atan(W dt / 2) per step (the Cayley map of
the rotation increment: generalized-alpha with radius 1; the midpoint rule imposes the increment itself since issue
42 item 2) where the prescribed angle grows by W dt, so the drive's gap (column gap_drive of <joint>_joint.csv)
falls by the lag W dt - 2 atan(W dt / 2) every step. With -joints_project_interval n
the positions are projected back onto the joints after every n-th step, so after step s the gap is
    -(s mod n) (W dt - 2 atan(W dt / 2))
(n = 0: no projection, -s times the lag). Reads the series, compares every row with that prediction (--atol, rad),
checks that the joint's other gaps stay below --gap, and prints PASS/FAIL lines. Standard library only.

    python3 tests/tools/drive_lag.py hinge_joint.csv --omega 3 --dt 1e-3 --interval 100 --atol 1e-13 --gap 1e-12
"""

import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--omega", type=float, required=True, help="the drive's rate [rad/s]")
    ap.add_argument("--dt", type=float, required=True, help="the time step [s]")
    ap.add_argument("--interval", type=int, default=0, help="-joints_project_interval (0: no projection)")
    ap.add_argument("--atol", type=float, required=True, help="bound on |gap_drive - prediction| [rad]")
    ap.add_argument("--gap", type=float, default=1e-12, help="bound on the other gap_* columns [m or rad]")
    args = ap.parse_args()

    lag = args.omega * args.dt - 2 * math.atan(args.omega * args.dt / 2)
    with open(args.csv) as f:
        rows = list(csv.DictReader(f))
    others = [c for c in rows[0] if c.startswith("gap_") and c != "gap_drive"]
    worst, worst_other, largest, largest_steps = 0.0, 0.0, 0.0, 0
    for row in rows:
        step = round(float(row["time"]) / args.dt)
        k = step % args.interval if args.interval > 0 else step
        gap = float(row["gap_drive"])
        worst = max(worst, abs(gap + k * lag))
        if abs(gap) > largest:
            largest, largest_steps = abs(gap), k
        worst_other = max([worst_other] + [abs(float(row[c])) for c in others])
    ok = worst <= args.atol
    print(f"drive lag per step W dt - 2 atan(W dt/2) = {lag:.6e} rad; largest gap {largest:.4e} rad after "
          f"{largest_steps} steps without projection")
    print(f"drive gap = -(steps since the last projection) x lag, every step (abs. error < {args.atol:g} rad): "
          f"{'PASS' if ok else 'FAIL (%.2e)' % worst}")
    ok2 = worst_other <= args.gap
    print(f"other rows ({', '.join(c[4:] for c in others)}) closed (< {args.gap:g}): "
          f"{'PASS' if ok2 else 'FAIL (%.2e)' % worst_other}")
    return 0 if ok and ok2 else 1


if __name__ == "__main__":
    sys.exit(main())
