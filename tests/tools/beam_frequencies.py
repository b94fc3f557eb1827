#!/usr/bin/env python3
"""Bending frequencies of a Timoshenko beam, against the modes of a linearised analysis (a test filter).

A straight beam of rectangular section (length L, width b in the bending plane's normal, height h in the bending
plane), Young's modulus E, Poisson's ratio nu, density rho, free at x = L and, at x = 0, clamped (w = 0, psi = 0) or
pinned (w = 0, M = EI psi' = 0). Timoshenko's equations
    kGA (w'' - psi') + rho A w^2 w = 0,    EI psi'' + kGA (w' - psi) + rho I w^2 psi = 0
(shear coefficient k = 10 (1 + nu) / (12 + 11 nu), Cowper's for a rectangle, unless --shear-coefficient) have below
the cut-off pulsation sqrt(kGA / (rho I)) the solutions cosh, sinh (a) and cos, sin (b) with
    a^2, -b^2 = roots of kGA EI q^2 + rho w^2 (EI A + kGA I) q + rho A w^2 (rho I w^2 - kGA) = 0;
the four boundary conditions (free end: M = 0, Q = kGA (w' - psi) = 0) make a 4x4 determinant whose sign changes in
w are bracketed on a grid and bisected. Euler-Bernoulli's (beta L)^2 sqrt(EI / (rho A)) / L^2 is printed beside.
The solver reproduces the closed form of the pinned-pinned beam to 1e-14 and Euler-Bernoulli for a slender one.

Reads linearized_modes.csv (configuration 0, elastic modes), takes the phlex frequency nearest each beam frequency,
and prints its relative deviation and PASS/FAIL against --rtol (one per mode, or one for all). Standard library
only.

    python3 tests/tools/beam_frequencies.py linearized_modes.csv --support pinned --length 1 --width 0.1 --height 0.1
        --youngs 2.1e11 --poisson 0.3 --density 7800 --modes 2 --rtol 2e-3,6e-3
"""

import argparse
import csv
import math
import sys

EB_ROOTS = {"clamped": [1.8751040687, 4.6940911330, 7.8547574382],
            "pinned": [3.9266023120, 7.0685827459, 10.2101761242]}


def det4(m):
    """Determinant by Gaussian elimination with partial pivoting."""
    m = [row[:] for row in m]
    d = 1.0
    for c in range(4):
        p = max(range(c, 4), key=lambda r: abs(m[r][c]))
        if m[p][c] == 0:
            return 0.0
        if p != c:
            m[c], m[p] = m[p], m[c]
            d = -d
        d *= m[c][c]
        for r in range(c + 1, 4):
            f = m[r][c] / m[c][c]
            for k in range(c, 4):
                m[r][k] -= f * m[c][k]
    return d


class Beam:
    def __init__(self, a):
        self.L, self.E, self.rho = a.length, a.youngs, a.density
        self.G = a.youngs / (2 * (1 + a.poisson))
        self.A = a.width * a.height
        self.I = a.width * a.height ** 3 / 12
        self.k = a.shear_coefficient if a.shear_coefficient else 10 * (1 + a.poisson) / (12 + 11 * a.poisson)
        self.support = a.support

    def determinant(self, w):
        kGA, EI, rA, rI = self.k * self.G * self.A, self.E * self.I, self.rho * self.A, self.rho * self.I
        qa, qb, qc = kGA * EI, w * w * (EI * rA + kGA * rI), rA * w * w * (rI * w * w - kGA)
        disc = math.sqrt(qb * qb - 4 * qa * qc)
        al, be = math.sqrt((-qb + disc) / (2 * qa)), math.sqrt((qb + disc) / (2 * qa))
        ra, rb = al + rA * w * w / (kGA * al), be - rA * w * w / (kGA * be)

        def basis(x):
            ch, sh, c, s = math.cosh(al * x), math.sinh(al * x), math.cos(be * x), math.sin(be * x)
            return ([ch, sh, c, s],                                         # w
                    [ra * sh, ra * ch, -rb * s, rb * c],                    # psi
                    [al * sh, al * ch, -be * s, be * c],                    # w'
                    [ra * al * ch, ra * al * sh, -rb * be * c, -rb * be * s])  # psi'
        w0, p0, _, dp0 = basis(0.0)
        _, pL, dwL, dpL = basis(self.L)
        return det4([w0, p0 if self.support == "clamped" else dp0, dpL, [dwL[i] - pL[i] for i in range(4)]])

    def frequencies(self, n):
        """The n lowest pulsations (the pinned beam's rigid rotation at 0 left out)."""
        eb = math.sqrt(self.E * self.I / (self.rho * self.A)) / self.L ** 2
        top = 1.5 * EB_ROOTS[self.support][n - 1] ** 2 * eb
        steps = 4000 * n
        out, prev, wprev = [], None, None
        for i in range(1, steps + 1):
            w = top * i / steps
            d = self.determinant(w)
            if prev is not None and d * prev < 0:
                lo, hi, dlo = wprev, w, prev
                for _ in range(200):
                    mid = 0.5 * (lo + hi)
                    dm = self.determinant(mid)
                    if dm * dlo <= 0:
                        hi = mid
                    else:
                        lo, dlo = mid, dm
                out.append(0.5 * (lo + hi))
                if len(out) == n:
                    break
            prev, wprev = d, w
        if len(out) < n:
            sys.exit(f"beam_frequencies.py: found {len(out)} of {n} roots below {top:g} rad/s")
        return out, [r * r * eb for r in EB_ROOTS[self.support][:n]]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", help="linearized_modes.csv")
    ap.add_argument("--support", choices=["clamped", "pinned"], required=True, help="the end x = 0 (x = L is free)")
    ap.add_argument("--length", type=float, required=True)
    ap.add_argument("--width", type=float, required=True, help="section size normal to the bending plane [m]")
    ap.add_argument("--height", type=float, required=True, help="section size in the bending plane [m]")
    ap.add_argument("--youngs", type=float, required=True)
    ap.add_argument("--poisson", type=float, required=True)
    ap.add_argument("--density", type=float, required=True)
    ap.add_argument("--shear-coefficient", type=float, default=0.0, help="default: Cowper's for a rectangle")
    ap.add_argument("--modes", type=int, default=2)
    ap.add_argument("--rtol", required=True, help="bound on the relative deviation: one, or one per mode")
    a = ap.parse_args()
    rtols = [float(x) for x in a.rtol.split(",")]
    if len(rtols) == 1:
        rtols *= a.modes
    if len(rtols) != a.modes:
        ap.error(f"--rtol: {a.modes} modes need 1 or {a.modes} bounds")
    beam = Beam(a)
    tim, eb = beam.frequencies(a.modes)
    with open(a.csv) as f:
        fe = [float(r["frequency_hz"]) for r in csv.DictReader(f) if r["configuration"] == "0" and r["kind"] == "elastic"]
    hz = 1 / (2 * math.pi)
    print(f"Timoshenko {a.support}-free beam (shear coefficient {beam.k:.4f}): "
          + ", ".join(f"{w * hz:.2f}" for w in tim) + " Hz; Euler-Bernoulli " + ", ".join(f"{w * hz:.2f}" for w in eb)
          + " Hz")
    ok = True
    for i, (w, rtol) in enumerate(zip(tim, rtols), start=1):
        f = min(fe, key=lambda x: abs(x - w * hz))
        dev = f / (w * hz) - 1
        good = abs(dev) <= rtol
        ok = ok and good
        print(f"bending mode {i}: phlex {f:.4f} Hz, {100 * dev:+.3f} % of Timoshenko's: "
              f"{'PASS' if good else 'FAIL'} (|deviation| {'<' if good else '>'} {100 * rtol:g} %)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
