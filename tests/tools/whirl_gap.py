#!/usr/bin/env python3
"""A joint on a whirling elastic port: its rotation gap with the exact port rate against a bound, and with the
first-order rate against the geometric phase it should grow by (issue 42 item 3).

  whirl_gap.py --exact DIR --first DIR --joint weld --port bar:tip --bound 2e-5

DIR/<joint>_joint.csv: gap_r1, gap_r2, gap_r3 (the rotation vector of the relative rotation since the drawn
configuration, in the joint frame; here the joint frame is the identity, so the components are inertial). The
first-order run's port output is w + theta' = theta' (a fixed body: w = 0), so its own series
(DIR/<body>_ports.csv, <port>_wx, _wy, _wz) integrates to theta (trapezoidal rule) and gives, independently of the
joint, the geometric phase phi = 1/2 int theta x theta' dt by which the other side (which turns at theta') lags the
port's orientation exp(theta) (which turns at J_l(theta) theta' = theta' + 1/2 theta x theta' + O(theta^2) theta'):
the gap should be -phi to O(|theta|) of |phi| and the scheme's O(dt^2).

Checks (each one line, PASS/FAIL): the exact run's largest rotation gap <= bound; the first-order run's gap grows
(its largest in the last tenth of the run more than 5 times that of the first tenth, and above the bound); its final
gap equals -phi within --phase-rtol of |phi|. Exit status 1 if any check fails. Standard library only.
"""
import argparse
import csv
import math
import os
import sys


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def gaps(d, joint):
    r = rows(os.path.join(d, joint + "_joint.csv"))
    return [float(x["time"]) for x in r], [[float(x["gap_r%d" % k]) for k in (1, 2, 3)] for x in r]


def norm(v):
    return math.sqrt(sum(c * c for c in v))


def tenth_max(g, which):
    n = len(g)
    seg = g[: max(1, n // 10)] if which == "first" else g[n - max(1, n // 10):]
    return max(norm(v) for v in seg)


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exact", required=True)
    ap.add_argument("--first", required=True)
    ap.add_argument("--joint", required=True)
    ap.add_argument("--port", required=True, help="body:port of the whirling port")
    ap.add_argument("--bound", type=float, required=True, help="the exact run's largest rotation gap [rad]")
    ap.add_argument("--growth", type=float, default=5.0)
    ap.add_argument("--phase-rtol", type=float, default=0.05)
    a = ap.parse_args()
    ok = True

    _, ge = gaps(a.exact, a.joint)
    emax = max(norm(v) for v in ge)
    good = emax <= a.bound
    ok &= good
    print("exact rate: largest rotation gap %.3e rad over %d steps, bound %.0e: %s" % (emax, len(ge) - 1, a.bound, "PASS" if good else "FAIL"))

    tf, gf = gaps(a.first, a.joint)
    f0, f1 = tenth_max(gf, "first"), tenth_max(gf, "last")
    good = f1 > a.growth * f0 and f1 > a.bound
    ok &= good
    print("first-order rate: largest rotation gap %.3e rad in the first tenth, %.3e in the last (grows %.1f times): %s" % (f0, f1, f1 / f0, "PASS" if good else "FAIL"))

    body, port = a.port.split(":")
    pr = rows(os.path.join(a.first, body + "_ports.csv"))
    t = [float(x["time"]) for x in pr]
    w = [[float(x["%s_w%s" % (port, c)]) for c in "xyz"] for x in pr]
    theta, phi = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    thmax = 0.0
    for i in range(1, len(t)):
        h = t[i] - t[i - 1]
        th1 = [theta[k] + 0.5 * h * (w[i - 1][k] + w[i][k]) for k in range(3)]
        c0, c1 = cross(theta, w[i - 1]), cross(th1, w[i])
        phi = [phi[k] + 0.25 * h * (c0[k] + c1[k]) for k in range(3)]
        theta = th1
        thmax = max(thmax, norm(theta))
    gend = gf[-1]
    err = norm([gend[k] + phi[k] for k in range(3)]) / norm(phi)
    good = err <= a.phase_rtol
    ok &= good
    print("first-order rate: final gap (%.3e, %.3e, %.3e) rad, -1/2 int theta x dtheta (%.3e, %.3e, %.3e) rad from the port's own output (|theta| up to %.2e rad), differ by %.1e of it (tolerance %.0e): %s"
          % (gend[0], gend[1], gend[2], -phi[0], -phi[1], -phi[2], thmax, err, a.phase_rtol, "PASS" if good else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
