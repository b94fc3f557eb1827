#!/usr/bin/env python3
"""Numerical damping of a time integrator against its theory, from the energy history of a single-mode free vibration.

For y' = i w y the schemes' amplification factors A(W), W = w dt, are known: the mode's energy decays per step by
|A|^2. This reads energy.csv (total H), fits the decay rate per step over steps >= --skip (after the start-up steps),
and compares the damping 1 - |A| measured with the theory's within --rtol.
  dissipation.py energy.csv --scheme alpha --radius 0.8 --frequency 83.7749 --dt 2.4e-4 [--skip 10] [--rtol 0.05]
  dissipation.py energy.csv --scheme bdf2 --frequency ... --dt ...
Schemes: alpha (PETSc TSALPHA, first-order generalized-alpha of Jansen, Whiting and Hulbert 2000: alpha_m =
(3 - rho)/(2 (1 + rho)), alpha_f = 1/(1 + rho), gamma = 1/2 + alpha_m - alpha_f), bdf2 (fixed step)."""
import argparse
import cmath
import csv
import math
import sys


def amplification(scheme, W, rho):
    z = 1j * W
    if scheme == "bdf2":
        # (3/2 - z) s^2 - 2 s + 1/2 = 0: the principal root (the one near 1)
        a, b, c = 1.5 - z, -2.0, 0.5
        d = cmath.sqrt(b * b - 4 * a * c)
        roots = [(-b + d) / (2 * a), (-b - d) / (2 * a)]
        return max(roots, key=abs)
    am, af = 0.5 * (3 - rho) / (1 + rho), 1.0 / (1 + rho)
    g = 0.5 + am - af
    # x1 - g v1 = x0 + (1 - g) v0 ; am v1 - z af x1 = z (1 - af) x0 - (1 - am) v0   (dt = 1, lambda = z)
    # amplification matrix of (x, v): solve the 2x2 system for the images of (1, 0) and (0, 1)
    def step(x0, v0):
        r1 = x0 + (1 - g) * v0
        r2 = z * (1 - af) * x0 - (1 - am) * v0
        det = am * 1 - (-g) * (-z * af)
        x1 = (r1 * am - (-g) * r2) / det
        v1 = (1 * r2 - (-z * af) * r1) / det
        return x1, v1
    c1, c2 = step(1, 0), step(0, 1)
    tr, dt_ = c1[0] + c2[1], c1[0] * c2[1] - c2[0] * c1[1]
    d = cmath.sqrt(tr * tr - 4 * dt_)
    roots = [(tr + d) / 2, (tr - d) / 2]
    return max(roots, key=abs)  # the principal root (the other one is the spurious, damped one)


ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("csv")
ap.add_argument("--scheme", choices=["alpha", "bdf2"], required=True)
ap.add_argument("--radius", type=float, default=1.0)
ap.add_argument("--frequency", type=float, required=True, help="the mode's frequency [Hz]")
ap.add_argument("--dt", type=float, required=True)
ap.add_argument("--skip", type=int, default=10)
ap.add_argument("--rtol", type=float, default=0.05)
a = ap.parse_args()
H = [float(r["total"]) for r in csv.DictReader(open(a.csv, newline=""))]
if len(H) <= a.skip + 2:
    sys.exit("too few steps")
n = len(H) - 1 - a.skip
rate = math.log(H[-1] / H[a.skip]) / n  # ln |A|^2 per step
measured = 1.0 - math.exp(rate / 2)
A = amplification(a.scheme, 2 * math.pi * a.frequency * a.dt, a.radius)
theory = 1.0 - abs(A)
ok = abs(measured - theory) <= a.rtol * theory
print("%s damping per step 1 - |A| at w dt = %.4f: measured %.4e, theory %.4e (relative difference %.1e, tolerance %g): %s"
      % (a.scheme, 2 * math.pi * a.frequency * a.dt, measured, theory, abs(measured - theory) / theory, a.rtol, "PASS" if ok else "FAIL"))
sys.exit(0 if ok else 1)
