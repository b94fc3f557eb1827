#!/usr/bin/env python3
"""Precession rate of a heavy symmetric top against the steady precession (a test filter).

Reads <body>_rigid.csv of a top pivoting at the origin (columns time, cx, cy, cz: its centre of mass), takes the
azimuth of the centre of mass about z (unwrapped) and its tilt from z, fits the azimuth linearly in time (least
squares) and compares the slope with the slow root of the steady-precession condition
    W (I3 w3 - I1' W cos theta) = m g l
(I1': transverse inertia about the pivot, I3: axial inertia, w3: spin component along the axis, theta: tilt from
the upward vertical). Also reports the nutation (the range of the tilt) and the largest departure of the azimuth
from the fitted line. Prints PASS/FAIL against --rtol (rate) and --nutation (radians). Standard library only.

    python3 tests/tools/top_precession.py top_rigid.csv --mgl 0.981 --i1 0.016 --i3 0.01 --spin 50 --tilt 30
"""

import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--mgl", type=float, required=True, help="m g l [N m]")
    ap.add_argument("--i1", type=float, required=True, help="transverse inertia about the pivot [kg m^2]")
    ap.add_argument("--i3", type=float, required=True, help="axial inertia [kg m^2]")
    ap.add_argument("--spin", type=float, required=True, help="spin component along the axis w3 [rad/s]")
    ap.add_argument("--tilt", type=float, required=True, help="tilt from the upward vertical [deg]")
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--nutation", type=float, default=1e-8)
    args = ap.parse_args()

    th = math.radians(args.tilt)
    a = args.i1 * math.cos(th)
    b = args.i3 * args.spin
    W = (b - math.sqrt(b * b - 4 * a * args.mgl)) / (2 * a)
    t, phi, tilt, prev, turns = [], [], [], None, 0.0
    with open(args.csv) as f:
        for row in csv.DictReader(f):
            x, y, z = float(row["cx"]), float(row["cy"]), float(row["cz"])
            p = math.atan2(y, x)
            if prev is not None and abs(p - prev) > math.pi:
                turns -= math.copysign(2 * math.pi, p - prev)
            prev = p
            t.append(float(row["time"]))
            phi.append(p + turns)
            tilt.append(math.atan2(math.hypot(x, y), z))
    n = len(t)
    tm, pm = sum(t) / n, sum(phi) / n
    slope = sum((ti - tm) * (pi - pm) for ti, pi in zip(t, phi)) / sum((ti - tm) ** 2 for ti in t)
    dev = max(abs(pi - (pm + slope * (ti - tm))) for ti, pi in zip(t, phi))
    nut = max(tilt) - min(tilt)
    err = abs(slope - W) / W
    print(f"steady precession {W:.10f} rad/s")
    print(f"measured {slope:.10f} rad/s over {t[-1] - t[0]:g} s")
    print(f"nutation (tilt range) {nut:.1e} rad, azimuth off the line by {dev:.1e} rad")
    ok = err <= args.rtol
    print(f"precession rate (relative error {'<' if ok else '>'} {args.rtol:g}): {'PASS' if ok else 'FAIL'}")
    ok2 = nut <= args.nutation
    print(f"nutation ({'<' if ok2 else '>'} {args.nutation:g} rad): {'PASS' if ok2 else 'FAIL'}")
    return 0 if ok and ok2 else 1


if __name__ == "__main__":
    sys.exit(main())
