#!/usr/bin/env python3
"""A spring-damper whose rest length follows a ramp (an actuator) pulling a point mass, against the hand solution. A
test filter.

The mass m on a spring k and a damper c to the ground (the damper on the mass's velocity), its rest length L(t)
ramped at speed V from t = 0 to --ramp-time T, the mass starting at rest at the rest length. With z = x - L + cV/k,
m z'' + c z' + k z = 0 during the ramp, z(0) = cV/k, z'(0) = -V; once z has decayed the mass moves at V, the spring
is shorter than its rest by cV/k and the actuator supplies P = -F L' = c V^2 (the damper's power). Integrating the
ODE of z over the ramp (z, z' -> 0) gives the actuator's work W = int k (L - x) V dt = c V^2 T - c^2 V^2 / k + m V^2.
Checks <joint>_joint.csv (actuator_work at the end; actuator_power, length_minus_rest and rest_length at --times),
<body>_rigid.csv (the mass's speed) and energy.csv (the supplied work is the actuator's).

    python3 tests/tools/actuator_work.py OUTDIR --joint spring --body mass --mass 2 --stiffness 2e4 --damping 400
        --speed 0.1 --ramp-time 1 --rest0 1 --times 0.6,0.8,1.0 --rtol 1e-8
"""
import argparse
import csv
import os
import sys


def rows(path):
    with open(path, newline="") as f:
        return [{k.strip(): float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def at(series, t):
    return min(series, key=lambda r: abs(r["time"] - t))


def check(name, got, want, rtol, scale=None):
    err = abs(got - want) / (scale if scale else abs(want))
    print("%s: %s" % (name, "PASS" if err <= rtol else "FAIL (%.12g, expected %.12g)" % (got, want)))
    return err <= rtol


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir")
    ap.add_argument("--joint", required=True)
    ap.add_argument("--body", required=True)
    for k in ("mass", "stiffness", "damping", "speed", "ramp-time", "rest0"):
        ap.add_argument("--" + k, type=float, required=True)
    ap.add_argument("--times", required=True)
    ap.add_argument("--rtol", type=float, default=1e-8)
    a = ap.parse_args()
    m, k, c, V, T = a.mass, a.stiffness, a.damping, a.speed, a.ramp_time
    joint = rows(os.path.join(a.outdir, a.joint + "_joint.csv"))
    body = rows(os.path.join(a.outdir, a.body + "_rigid.csv"))
    energy = rows(os.path.join(a.outdir, "energy.csv"))
    ok = True
    W = c * V * V * T - c * c * V * V / k + m * V * V
    print("hand: actuator work c V^2 T - c^2 V^2/k + m V^2 = %.6g J, steady power c V^2 = %.6g W, lag c V/k = %.6g m"
          % (W, c * V * V, c * V / k))
    ok &= check("actuator work at the end", joint[-1]["actuator_work"], W, a.rtol)
    ok &= check("supplied work (energy.csv) = the actuator's", energy[-1]["supplied_work"], joint[-1]["actuator_work"], 1e-12)
    for t in (float(x) for x in a.times.split(",")):
        r = at(joint, t)
        ok &= check("actuator power at t = %g s" % t, r["actuator_power"], c * V * V, a.rtol)
        ok &= check("length - rest length at t = %g s" % t, r["length_minus_rest"], -c * V / k, a.rtol)
        ok &= check("rest length at t = %g s" % t, r["rest_length"], a.rest0 + V * min(t, T), 1e-12)
        ok &= check("mass speed at t = %g s" % t, at(body, t)["vx"], V, a.rtol)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
