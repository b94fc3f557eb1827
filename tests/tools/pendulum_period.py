#!/usr/bin/env python3
"""Period of a pendulum from a joint series against the complete elliptic integral (a test filter).

Reads <joint>_joint.csv (columns time and angle: the rotation about the joint axis since the drawn configuration,
of the second port relative to the first; --sign -1 when the pendulum is the first port), unwraps it, adds the
release angle theta0, finds the times where the pendulum passes the bottom (theta = 0, linear interpolation
between steps: theta'' = 0 there, so the interpolation error is O(dt^3)) and takes the period as the time between
passes in the same direction (their mean). The physical pendulum released at rest from theta0 has the period
    T = 4 sqrt(I / (m g d)) K(sin(theta0 / 2)),   small-angle limit T0 = 2 pi sqrt(I / (m g d)),
with I the inertia about the pivot and K the complete elliptic integral of the first kind (arithmetic-geometric
mean: K(k) = pi / (2 AGM(1, sqrt(1 - k^2)))). Prints both periods, the measured one and PASS/FAIL against --rtol.
Standard library only.

    python3 tests/tools/pendulum_period.py hinge_joint.csv --theta0 120 --inertia 1.001 --mgd 9.81 --rtol 1e-5
"""

import argparse
import csv
import math
import sys


def agm(a, b):
    for _ in range(64):  # quadratic convergence: a handful of iterations reach round-off
        if abs(a - b) <= 4e-16 * a:
            break
        a, b = (a + b) / 2, math.sqrt(a * b)
    return a


def elliptic_k(k):
    return math.pi / (2 * agm(1.0, math.sqrt(1 - k * k)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--theta0", type=float, required=True, help="release angle from the downward vertical [deg]")
    ap.add_argument("--inertia", type=float, required=True, help="inertia about the pivot [kg m^2]")
    ap.add_argument("--mgd", type=float, required=True, help="m g d: mass x gravity x pivot-to-centre distance [N m]")
    ap.add_argument("--column", default="angle")
    ap.add_argument("--sign", type=float, default=1.0, help="+1 if the angle column grows with theta, -1 otherwise")
    ap.add_argument("--rtol", type=float, default=1e-5)
    args = ap.parse_args()

    th0 = math.radians(args.theta0)
    t, th, prev, turns = [], [], None, 0.0
    with open(args.csv) as f:
        for row in csv.DictReader(f):
            a = float(row[args.column])
            if prev is not None and abs(a - prev) > math.pi:  # the column is wrapped to (-pi, pi]: unwrap it
                turns -= math.copysign(2 * math.pi, a - prev)
            prev = a
            t.append(float(row["time"]))
            th.append(th0 + args.sign * (a + turns))
    passes = []  # (time, direction)
    for i in range(1, len(t)):
        if th[i - 1] == 0.0 or (th[i - 1] > 0) != (th[i] > 0):
            s = th[i - 1] / (th[i - 1] - th[i])
            passes.append((t[i - 1] + s * (t[i] - t[i - 1]), 1 if th[i] > th[i - 1] else -1))
    periods = [passes[i + 2][0] - passes[i][0] for i in range(len(passes) - 2)]
    exact = 4 * math.sqrt(args.inertia / args.mgd) * elliptic_k(math.sin(th0 / 2))
    small = 2 * math.pi * math.sqrt(args.inertia / args.mgd)
    print(f"small-angle period {small:.9f} s, elliptic-integral period at {args.theta0:g} deg {exact:.9f} s")
    if not periods:
        print("pendulum period: FAIL (fewer than three passes through the bottom)")
        return 1
    measured = sum(periods) / len(periods)
    err = abs(measured - exact) / exact
    spread = max(abs(p - measured) for p in periods) / exact
    print(f"measured {measured:.9f} s from {len(periods)} half-period pairs (spread {spread:.1e})")
    ok = err <= args.rtol and spread <= args.rtol
    print(f"pendulum period (relative error {'<' if ok else '>'} {args.rtol:g}): {'PASS' if ok else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
