#!/usr/bin/env python3
"""The crank-slider's coupler midpoint deflection (cases.md section 2) from a run of options/crankslider.yaml.

The deflection relative to the chord: with P, C, M the inertial positions of the coupler's pin face (its frame
patch), end face and mid-section (means of the displaced points, <body>_ports.csv), d = (C - P)/|C - P| and n the
in-plane normal (z x d),
    u_y / L = (M - P) . n / L,    u_x / L = ((M - P) . d - L/2) / L,      crank angle = omega t.
Checks (exit status 1 on a FAIL):
  - the first peak of u_y/L (largest value for crank angles 0.5-1.2 rad): 0.0186 +- 0.0005 (near 0.845 rad),
  - the global minimum (if the run reaches 6.5 rad): -0.014 +- 0.001 (near 5.8 rad),
  - the whole curve within 2e-3 of the converged FFRF check (--reference), interpolated at the run's samples.

  tools/crankslider_midpoint.py output/crankslider [--reference validation/reference/crankslider_midpoint_ffrf_check.csv]
                                [--out midpoint.csv] [--body coupler] [--omega 150] [--length 0.3]
"""
import argparse
import bisect
import csv
import math
import os
import sys


def interp(xs, ys, x):
    i = bisect.bisect_left(xs, x)
    if i <= 0:
        return ys[0]
    if i >= len(xs):
        return ys[-1]
    t = (x - xs[i - 1]) / (xs[i] - xs[i - 1])
    return ys[i - 1] + t * (ys[i] - ys[i - 1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--body", default="coupler")
    ap.add_argument("--frame", default="P", help="the frame patch's port name")
    ap.add_argument("--omega", type=float, default=150.0)
    ap.add_argument("--length", type=float, default=0.3)
    ap.add_argument("--reference", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "validation", "reference", "crankslider_midpoint_ffrf_check.csv"))
    ap.add_argument("--curve_tol", type=float, default=2e-3)
    ap.add_argument("--label", default="the FFRF check", help="what --reference is (another run's --out CSV serves too)")
    ap.add_argument("--out")
    a = ap.parse_args()
    with open(os.path.join(a.dir, a.body + "_ports.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    ang, uy, ux = [], [], []
    for r in rows:
        P = [float(r["%s_%s" % (a.frame, c)]) for c in "xy"]
        C = [float(r["C_" + c]) for c in "xy"]
        M = [float(r["M_" + c]) for c in "xy"]
        dx, dy = C[0] - P[0], C[1] - P[1]
        n = math.hypot(dx, dy)
        d = (dx / n, dy / n)
        nn = (-d[1], d[0])
        mp = (M[0] - P[0], M[1] - P[1])
        ang.append(a.omega * float(r["time"]))
        uy.append((mp[0] * nn[0] + mp[1] * nn[1]) / a.length)
        ux.append(((mp[0] * d[0] + mp[1] * d[1]) - a.length / 2) / a.length)
    ok = True
    window = [(x, y) for x, y in zip(ang, uy) if 0.5 <= x <= 1.2]
    if window:
        xp, yp = max(window, key=lambda p: p[1])
        good = abs(yp - 0.0186) <= 0.0005
        ok = ok and good
        print("crank-slider first peak of u_y/L: %.5f at %.3f rad (reference 0.0186 +- 0.0005 near 0.845 rad): %s" % (yp, xp, "PASS" if good else "FAIL"))
    if ang[-1] >= 6.5:
        xm, ym = min(zip(ang, uy), key=lambda p: p[1])
        good = abs(ym + 0.014) <= 0.001
        ok = ok and good
        print("crank-slider global minimum of u_y/L: %.5f at %.3f rad (reference -0.014 +- 0.001 near 5.8 rad): %s" % (ym, xm, "PASS" if good else "FAIL"))
    with open(a.reference, newline="") as f:
        ref = list(csv.DictReader(f))
    rx = [float(r["crank_angle_rad"]) for r in ref]
    ry = [float(r["uy_over_L"]) for r in ref]
    pairs = [(x, y) for x, y in zip(ang, uy) if rx[0] <= x <= rx[-1]]
    dev, at = max(((abs(y - interp(rx, ry, x)), x) for x, y in pairs), default=(0.0, 0.0))
    good = dev <= a.curve_tol
    ok = ok and good
    print("crank-slider u_y/L against %s over 0-%.2f rad: max deviation %.2e at %.3f rad (tolerance %g): %s" % (a.label, pairs[-1][0] if pairs else 0, dev, at, a.curve_tol, "PASS" if good else "FAIL"))
    print("crank-slider u_x/L: between %.2e and %.2e (reference: small, between -5.3e-5 and 6.9e-5; qualitative)" % (min(ux), max(ux)))
    if a.out:
        with open(a.out, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["crank_angle_rad", "uy_over_L", "ux_over_L", "uy_reference"])
            for x, y, z in zip(ang, uy, ux):
                w.writerow(["%.6g" % x, "%.6e" % y, "%.6e" % z, "%.6e" % interp(rx, ry, x)])
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
