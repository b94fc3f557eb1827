#!/usr/bin/env python3
"""Four-bar pulsations of a linearised sweep against a reference curve.

Reads the run's linearized_sweep.csv (position = crank angle [deg], omega1_rad_s ... [rad/s]) and a reference CSV
with columns theta1_deg,f1,f2,f3 in rad/s (../shared/reference/fourbar_frequencies*.csv; despite the f, pulsations),
takes the reference at each swept angle (linear interpolation, periodic over 360 deg), and reports the largest
relative deviation of each of the first three pulsations. Exit status 1 if one exceeds --rtol.

  tools/compare_fourbar.py output/fourbar/linearized_sweep.csv REF.csv [--rtol 0.01] [--out comparison.csv]
"""
import argparse
import csv
import sys


def read_reference(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    pts = sorted((float(r["theta1_deg"]), [float(r["f1"]), float(r["f2"]), float(r["f3"])]) for r in rows)
    return pts


def interpolate(pts, angle):
    a = angle % 360.0
    xs = [p[0] for p in pts]
    # periodic: extend with the first point at +360
    ext = pts + [(pts[0][0] + 360.0, pts[0][1])]
    for (x0, y0), (x1, y1) in zip(ext[:-1], ext[1:]):
        if x0 - 1e-9 <= a <= x1 + 1e-9:
            t = 0.0 if x1 == x0 else (a - x0) / (x1 - x0)
            return [u + t * (v - u) for u, v in zip(y0, y1)]
    raise ValueError("angle %g outside the reference %g..%g" % (angle, xs[0], xs[-1]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sweep")
    ap.add_argument("reference")
    ap.add_argument("--rtol", type=float, default=0.01)
    ap.add_argument("--out", help="write angle, computed and reference pulsations, relative deviations")
    ap.add_argument("--label", default="four-bar")
    a = ap.parse_args()
    ref = read_reference(a.reference)
    with open(a.sweep, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit("%s: no configuration" % a.sweep)
    worst = [(0.0, None)] * 3
    maxdev = [0.0] * 3  # the pass/fail test: every angle, 360 deg too
    out = []
    for r in rows:
        ang = float(r["position"])
        w = [float(r["omega%d_rad_s" % (k + 1)]) for k in range(3)]
        wr = interpolate(ref, ang)
        dev = [(w[k] - wr[k]) / wr[k] for k in range(3)]
        out.append([ang] + w + wr + dev)
        # 360 deg repeats the configuration of 0 deg, whose frequencies it matches only to their precision (they move by
        # up to 1.8e-6 with the BLAS kernels: fourbar_link_modes_coupler): it is reported as the worst angle only when it
        # exceeds the worst so far by more than 5e-6 (about three times that); other ties: the first angle
        twin = any(o[0] == ang - 360 for o in out[:-1])
        for k in range(3):
            if abs(dev[k]) > abs(worst[k][0]) * (1 + 1e-9) + (5e-6 if twin else 0.0):
                worst[k] = (dev[k], ang)
            maxdev[k] = max(maxdev[k], abs(dev[k]))
    ok = True
    for k in range(3):
        d, ang = worst[k]
        status = "PASS" if maxdev[k] <= a.rtol else "FAIL"
        ok = ok and status == "PASS"
        print("%s omega%d: max |deviation| %.3f %% at %g deg over %d angles (tolerance %g %%): %s" % (a.label, k + 1, 100 * abs(d), ang if ang is not None else 0, len(rows), 100 * a.rtol, status))
    if a.out:
        with open(a.out, "w", newline="") as f:
            wr = csv.writer(f)
            wr.writerow(["theta1_deg", "omega1", "omega2", "omega3", "ref1", "ref2", "ref3", "dev1", "dev2", "dev3"])
            for row in out:
                wr.writerow(["%.6g" % row[0]] + ["%.8g" % x for x in row[1:]])
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
