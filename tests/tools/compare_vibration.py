#!/usr/bin/env python3
"""Compare two free vibrations about a static deflection (a test filter).

Reads one column (e.g. tip_y, a port's inertial position) of two CSV series with the same time steps, subtracts the
initial value, and compares: the mean deflection over whole periods (the static deflection: the vibration averages
out), the frequency of the oscillation about it (mean spacing of the upward crossings of the mean,
interpolated between steps), and the largest pointwise difference relative to the largest deflection. Prints the
three relative differences and PASS/FAIL against their bounds. Standard library only.

    python3 tests/tools/compare_vibration.py a.csv b.csv --column tip_y --mean 5e-3 --frequency 2e-3 --series 3e-2
"""

import argparse
import csv
import sys


def load(path, col):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time"]) for r in rows]
    y = [float(r[col]) for r in rows]
    return t, [v - y[0] for v in y]


def crossings(t, y, m):
    c = []
    for i in range(1, len(y)):
        a, b = y[i - 1] - m, y[i] - m
        if a < 0 <= b:
            c.append(t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a))
    return c


def mean_and_frequency(t, y):
    """The mean over whole periods (between the first and last upward crossings of the mean, trapezoid rule; twice,
    starting from the mean of the whole run) and the frequency of those crossings."""
    m = sum(y) / len(y)
    for _ in range(2):
        c = crossings(t, y, m)
        if len(c) < 2:
            return m, float("nan")
        s = w = 0.0
        for i in range(1, len(t)):
            lo, hi = max(t[i - 1], c[0]), min(t[i], c[-1])
            if hi <= lo:
                continue
            f = lambda x: y[i - 1] + (y[i] - y[i - 1]) * (x - t[i - 1]) / (t[i] - t[i - 1])
            s += 0.5 * (f(lo) + f(hi)) * (hi - lo)
            w += hi - lo
        m = s / w
    c = crossings(t, y, m)
    return m, (len(c) - 1) / (c[-1] - c[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--column", required=True)
    ap.add_argument("--mean", type=float, required=True)
    ap.add_argument("--frequency", type=float, required=True)
    ap.add_argument("--series", type=float, required=True)
    args = ap.parse_args()
    ta, ya = load(args.a, args.column)
    tb, yb = load(args.b, args.column)
    if len(ta) != len(tb):
        print(f"FAIL: the series have {len(ta)} and {len(tb)} rows")
        return 1
    ma, fa = mean_and_frequency(ta, ya)
    mb, fb = mean_and_frequency(tb, yb)
    dm = abs(mb - ma) / abs(ma)
    df = abs(fb - fa) / fa
    ds = max(abs(p - q) for p, q in zip(ya, yb)) / max(abs(p) for p in ya)
    ok = dm <= args.mean and df <= args.frequency and ds <= args.series
    print(f"{args.column}: mean {ma:.6e} and {mb:.6e}, frequency {fa:.6g} and {fb:.6g} Hz, largest difference {ds:.2e} of the largest deflection")
    for name, v, bound in (("mean deflection", dm, args.mean), ("frequency", df, args.frequency), ("series", ds, args.series)):
        print(f"{args.column} {name}: relative difference {'<' if v <= bound else '>'} {bound:g}: {'PASS' if v <= bound else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
