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

With several series of the same motion at steps --dt (coarsest first), the convergence instead: the rate error of
each, the observed order of each pair, log(e_coarse / e_fine) / log(dt_coarse / dt_fine), against --order within
--order-tol, and the Richardson extrapolation of the two finest rates with that order against the steady rate within
--extrapolated-rtol (the error's leading term removed, what is left is the next term and the reference's own error).

    python3 tests/tools/top_precession.py a.csv b.csv c.csv --dt 4e-4,2e-4,1e-4 --order 2 --order-tol 0.01
        --extrapolated-rtol 1e-9 --mgl 0.981 --i1 0.016 --i3 0.01 --spin 50 --tilt 30
"""

import argparse
import csv
import math
import sys


def measure(path):
    """The fitted precession rate, the nutation (tilt range) and the azimuth's largest departure from the fit."""
    t, phi, tilt, prev, turns = [], [], [], None, 0.0
    with open(path) as f:
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
    return slope, max(tilt) - min(tilt), dev, t[-1] - t[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="+", help="<body>_rigid.csv; several: the same motion at the steps --dt")
    ap.add_argument("--mgl", type=float, required=True, help="m g l [N m]")
    ap.add_argument("--i1", type=float, required=True, help="transverse inertia about the pivot [kg m^2]")
    ap.add_argument("--i3", type=float, required=True, help="axial inertia [kg m^2]")
    ap.add_argument("--spin", type=float, required=True, help="spin component along the axis w3 [rad/s]")
    ap.add_argument("--tilt", type=float, required=True, help="tilt from the upward vertical [deg]")
    ap.add_argument("--rtol", type=float, default=None, help="bound on the rate error (one series; default 1e-6)")
    ap.add_argument("--nutation", type=float, default=1e-8)
    ap.add_argument("--dt", default="", help="the series' time steps, comma-separated, coarsest first")
    ap.add_argument("--order", type=float, default=2.0, help="expected order of the rate error (several series)")
    ap.add_argument("--order-tol", type=float, default=0.01)
    ap.add_argument("--extrapolated-rtol", type=float, default=1e-9)
    args = ap.parse_args()

    th = math.radians(args.tilt)
    a = args.i1 * math.cos(th)
    b = args.i3 * args.spin
    W = (b - math.sqrt(b * b - 4 * a * args.mgl)) / (2 * a)
    print(f"steady precession {W:.10f} rad/s")
    runs = [measure(path) for path in args.csv]
    if len(runs) == 1:
        slope, nut, dev, span = runs[0]
        rtol = 1e-6 if args.rtol is None else args.rtol
        err = abs(slope - W) / W
        print(f"measured {slope:.10f} rad/s over {span:g} s")
        print(f"nutation (tilt range) {nut:.1e} rad, azimuth off the line by {dev:.1e} rad")
        ok = err <= rtol
        print(f"precession rate (relative error {'<' if ok else '>'} {rtol:g}): {'PASS' if ok else 'FAIL'}")
    else:
        dts = [float(x) for x in args.dt.split(",") if x]
        if len(dts) != len(runs):
            ap.error(f"--dt: {len(runs)} series need {len(runs)} steps, got {len(dts)}")
        errs = [(slope - W) / W for slope, _, _, _ in runs]
        for dt, e in zip(dts, errs):
            print(f"dt {dt:g}: rate error {e:.3e}")
        orders = [math.log(e1 / e2) / math.log(d1 / d2) if e1 * e2 > 0 else float("nan")
                  for e1, e2, d1, d2 in zip(errs, errs[1:], dts, dts[1:])]
        ok = all(abs(p - args.order) <= args.order_tol for p in orders)
        pairs = ", ".join(f"{p:.3f} (dt {d1:g} to {d2:g})" for p, d1, d2 in zip(orders, dts, dts[1:]))
        print(f"observed order {pairs}: {'PASS' if ok else 'FAIL'} ({args.order:g} +- {args.order_tol:g})")
        q = (dts[-2] / dts[-1]) ** args.order
        extrapolated = (q * runs[-1][0] - runs[-2][0]) / (q - 1)
        ex_err = abs(extrapolated - W) / W
        ok_ex = ex_err <= args.extrapolated_rtol
        print(f"extrapolated rate (dt {dts[-2]:g} and {dts[-1]:g}, order {args.order:g}; relative error "
              f"{'<' if ok_ex else '>'} {args.extrapolated_rtol:g}): {'PASS' if ok_ex else 'FAIL'}")
        if args.rtol is not None:
            err = abs(errs[-1])
            ok_r = err <= args.rtol
            print(f"precession rate at dt {dts[-1]:g} (relative error {'<' if ok_r else '>'} {args.rtol:g}): "
                  f"{'PASS' if ok_r else 'FAIL'}")
            ok_ex = ok_ex and ok_r
        ok = ok and ok_ex
        nut = max(r[1] for r in runs)
    ok2 = nut <= args.nutation
    print(f"nutation ({'<' if ok2 else '>'} {args.nutation:g} rad): {'PASS' if ok2 else 'FAIL'}")
    return 0 if ok and ok2 else 1


if __name__ == "__main__":
    sys.exit(main())
