#!/usr/bin/env python3
"""Compares the damped modes of a linearised analysis (linearized_modes.csv: undamped natural frequency |lambda|/2pi
and damping ratio -Re(lambda)/|lambda| per mode) with the eigenvalues of a small lumped system
M x'' + C x' + K x = 0 given on the command line (row-major matrices), computed here independently: the roots of
det(lambda^2 M + lambda C + K), a polynomial of degree 2n, by Durand-Kerner iteration polished by Newton's method
in complex arithmetic (no numpy). Fails (exit 1) when a frequency or a ratio deviates by more than --rtol."""
import argparse
import cmath
import csv
import math
import sys


def det(a):
    """determinant of a small complex matrix (Laplace expansion: n <= 4)"""
    n = len(a)
    if n == 1:
        return a[0][0]
    return sum((-1) ** j * a[0][j] * det([row[:j] + row[j + 1:] for row in a[1:]]) for j in range(n))


def char(lam, M, C, K):
    n = len(M)
    return det([[lam * lam * M[i][j] + lam * C[i][j] + K[i][j] for j in range(n)] for i in range(n)])


def roots(M, C, K):
    n = len(M)
    deg = 2 * n
    lead = det(M)
    f = lambda z: char(z, M, C, K) / lead
    z = [(0.4 + 0.9j) ** k * 10 for k in range(deg)]
    for _ in range(2000):
        zn = []
        for i, zi in enumerate(z):
            d = 1
            for j, zj in enumerate(z):
                if i != j:
                    d *= zi - zj
            zn.append(zi - f(zi) / d)
        if max(abs(a - b) for a, b in zip(z, zn)) < 1e-14 * max(abs(a) for a in zn):
            z = zn
            break
        z = zn
    out = []
    for zi in z:
        for _ in range(20):  # Newton on f with a central difference
            h = 1e-7 * max(abs(zi), 1.0)
            df = (f(zi + h) - f(zi - h)) / (2 * h)
            if df == 0:
                break
            zi = zi - f(zi) / df
        out.append(zi)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--mass", required=True, help="M, row-major, comma-separated")
    ap.add_argument("--damping", required=True, help="C, row-major")
    ap.add_argument("--stiffness", required=True, help="K, row-major")
    ap.add_argument("--rtol", type=float, required=True)
    a = ap.parse_args()
    mats = []
    for s in (a.mass, a.damping, a.stiffness):
        v = [float(x) for x in s.split(",")]
        n = int(round(math.sqrt(len(v))))
        if n * n != len(v):
            sys.exit("damped_modes.py: a matrix needs n^2 values, got %d" % len(v))
        mats.append([v[i * n:(i + 1) * n] for i in range(n)])
    lam = [z for z in roots(*mats) if z.imag > 1e-9 * abs(z)]
    lam.sort(key=abs)
    with open(a.csv) as fh:
        rows = [r for r in csv.DictReader(fh) if r["kind"] != "mechanism"]
    if len(rows) > len(lam):
        sys.exit("damped_modes.py: %d modes in %s, the lumped system has %d oscillating ones" % (len(rows), a.csv, len(lam)))
    worst = 0.0
    ok = True
    for r, z in zip(rows, lam):
        f, zeta = abs(z) / (2 * math.pi), -z.real / abs(z)
        df = abs(float(r["frequency_hz"]) - f) / f
        dz = abs(float(r["damping_ratio"]) - zeta) / zeta
        worst = max(worst, df, dz)
        print("mode %s: f %.10g Hz (exact %.10g), zeta %.10g (exact %.10g)" % (r["mode"], float(r["frequency_hz"]), f, float(r["damping_ratio"]), zeta))
        if df > a.rtol or dz > a.rtol:
            ok = False
    print("damped modes against the lumped system's eigenvalues: %s (rel. deviation %s %g)" % ("PASS" if ok else "FAIL", "<=" if ok else ">", a.rtol))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
