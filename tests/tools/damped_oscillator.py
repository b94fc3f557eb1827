#!/usr/bin/env python3
"""Compares a column of a CSV series (a displacement) with the exact free response of the damped oscillator
m x'' + c x' + k x = 0, x(0) = x0, x'(0) = v0, at given times; fails (exit 1) when an error exceeds the bound.

The bound is stated by the caller (the test's description argues it). Prints one verdict line per column checked,
with the largest error in two significant digits and the bound."""
import argparse
import csv
import math
import sys


def exact(t, m, k, c, x0, v0):
    w0 = math.sqrt(k / m)
    z = c / (2.0 * math.sqrt(k * m))
    if z >= 1.0:
        raise SystemExit("damped_oscillator.py: only the underdamped case (zeta < 1)")
    wd = w0 * math.sqrt(1.0 - z * z)
    a = x0
    b = (v0 + z * w0 * x0) / wd
    return math.exp(-z * w0 * t) * (a * math.cos(wd * t) + b * math.sin(wd * t))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--columns", required=True, help="comma-separated column names")
    ap.add_argument("--mass", type=float, required=True)
    ap.add_argument("--stiffness", type=float, required=True)
    ap.add_argument("--damping", type=float, required=True)
    ap.add_argument("--x0", type=float, required=True)
    ap.add_argument("--v0", type=float, default=0.0)
    ap.add_argument("--times", required=True, help="comma-separated times [s]")
    ap.add_argument("--atol", type=float, required=True, help="the bound on |x - x_exact|")
    ap.add_argument("--sign", type=float, default=1.0, help="the column's sign relative to x")
    ap.add_argument("--unit", default="m", help="the unit printed")
    ap.add_argument("--offset", type=float, default=0.0, help="x = sign * column + offset (a column measured from elsewhere)")
    a = ap.parse_args()
    with open(a.csv) as f:
        rows = list(csv.DictReader(f))
    times = [float(s) for s in a.times.split(",")]
    ok = True
    for col in a.columns.split(","):
        worst = 0.0
        for t in times:
            row = min(rows, key=lambda r: abs(float(r["time"]) - t))
            if abs(float(row["time"]) - t) > 1e-9 * max(1.0, t):
                print(f"damped oscillator: no row at t = {t}")
                return 1
            x = a.sign * float(row[col]) + a.offset
            worst = max(worst, abs(x - exact(t, a.mass, a.stiffness, a.damping, a.x0, a.v0)))
        verdict = "PASS" if worst <= a.atol else "FAIL"
        ok = ok and worst <= a.atol
        print(f"damped oscillator {col}: max |x - x_exact| at {len(times)} times {'<=' if worst <= a.atol else '>'} {a.atol:g} {a.unit}: {verdict}")
        if verdict == "FAIL":
            print(f"  largest error {worst:.2e}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
