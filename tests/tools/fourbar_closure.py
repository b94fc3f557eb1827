#!/usr/bin/env python3
"""The four-bar's assembled configuration against the loop closure, solved here by hand (a test filter).

Reads the first row (t = 0, after phlex's assembly) of crank_rigid.csv, coupler_rigid.csv and follower_rigid.csv
of a run of options/fourbar.yaml: each link's frame origin r_P (its start face P) and orientation quaternion. From
the crank angle theta1 (the crank's rotation about z) it places B = L1 (cos theta1, sin theta1), intersects the
circles |C - B| = L2 and |C - D| = L3 (D = (L0, 0)) on the branch of cases.md section 1 (C on the left of the
directed line B -> D) and compares: the coupler's P with B, the follower's P with C, the coupler's direction with
C - B and the follower's with D - C (the links lie along their body x axis). PASS when the largest position [m] and
angle [rad] deviations are within --atol, else FAIL with both. Standard library only.

    python3 tests/tools/fourbar_closure.py build/tests/fourbar_scene_assembles --atol 1e-12
"""

import argparse
import csv
import math
import os
import sys

L0, L1, L2, L3 = 0.254, 0.108, 0.2794, 0.2705  # ground, crank, coupler, follower [m] (cases.md Table 1.1)


def first_row(directory, body):
    with open(os.path.join(directory, body + "_rigid.csv"), newline="") as f:
        row = next(csv.DictReader(f))
    return [float(row[k]) for k in ("rx", "ry", "rz")], [float(row[k]) for k in ("qw", "qx", "qy", "qz")]


def planar_angle(q):
    """the rotation about z of a quaternion that turns about z only (checked: its x and y parts are ~0)"""
    return 2.0 * math.atan2(q[3], q[0]), max(abs(q[1]), abs(q[2]))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir")
    ap.add_argument("--atol", type=float, default=1e-12)
    a = ap.parse_args()
    try:
        (rc, qc), (r2, q2), (r3, q3) = (first_row(a.outdir, b) for b in ("crank", "coupler", "follower"))
    except (OSError, KeyError, StopIteration, ValueError) as e:
        print("fourbar closure: cannot read the rigid series in %s: %s" % (a.outdir, e))
        return 1
    theta1, tilt1 = planar_angle(qc)
    B = (L1 * math.cos(theta1), L1 * math.sin(theta1))
    dx, dy = L0 - B[0], -B[1]
    d = math.hypot(dx, dy)
    along = (L2 * L2 - L3 * L3 + d * d) / (2 * d)
    across = math.sqrt(L2 * L2 - along * along)
    ux, uy = dx / d, dy / d
    C = (B[0] + along * ux - across * uy, B[1] + along * uy + across * ux)  # left of B -> D
    a2, tilt2 = planar_angle(q2)
    a3, tilt3 = planar_angle(q3)
    dpos = max(math.hypot(rc[0], rc[1]), abs(rc[2]),
               math.hypot(r2[0] - B[0], r2[1] - B[1]), abs(r2[2]),
               math.hypot(r3[0] - C[0], r3[1] - C[1]), abs(r3[2]))
    dang = max(abs(wrap(a2 - math.atan2(C[1] - B[1], C[0] - B[0]))), abs(wrap(a3 - math.atan2(-C[1], L0 - C[0]))),
               2 * tilt1, 2 * tilt2, 2 * tilt3)
    ok = dpos <= a.atol and dang <= a.atol
    degrees = round(math.degrees(theta1), 6) + 0.0  # no "-0.000000"
    head = "fourbar closure at theta1 = %.6f deg: C = (%.10f, %.10f) m;" % (degrees, C[0], C[1])
    if ok:
        print("%s the assembled frames within %.0e m and rad: PASS" % (head, a.atol))
    else:
        print("%s the assembled frames off by %.3e m and %.3e rad, more than %.0e: FAIL" % (head, dpos, dang, a.atol))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
