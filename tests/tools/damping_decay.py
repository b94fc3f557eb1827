#!/usr/bin/env python3
"""The free decay of one damped mode against its damping ratio, and the power balance with dissipation.

A body started in one undamped mode (-body<k>_ic_velocity_type mode) with proportional damping (Rayleigh
alpha Mv + beta K, or a Kelvin-Voigt viscosity eta with eta/E the same in every region) stays in that mode: the
velocity of a port is then y_n = Re(c z^n), and it obeys the two-term recurrence y_(n+1) = a y_n + b y_(n-1) with
a = 2 Re z, b = -|z|^2 exactly. A least-squares fit of (a, b) over the series gives z; the implicit midpoint rule maps
the semi-discrete eigenvalue lambda to z = (1 + h lambda/2) / (1 - h lambda/2) (Cayley), so
lambda = (2/h) (z - 1) / (z + 1) is recovered exactly, and with it the mode's undamped pulsation w = |lambda| and its
damping ratio zeta = -Re(lambda) / |lambda|: compared with [zeta_i +] alpha/(2 w) + (beta + eta/E) w/2 (the continuous model's
per-mode ratio, which the spatial discretisation keeps exactly for proportional damping). The time-discrete series'
own logarithmic decrement per period, delta_h = -2 pi ln|z| / arg z, differs from the continuous
delta = 2 pi zeta / sqrt(1 - zeta^2) by the midpoint rule's O((w h)^2) error: checked within --raw-rtol.

energy.csv: max |balance_residual| (H_(n+1) - H_n - dt (P - D)) against --balance-rtol times max |H|; the dissipated power
never negative, the dissipated work never decreasing.

Prints verdict lines with few digits; exits 1 with observed, expected and tolerance on a failure.
Standard library only.
"""
import argparse
import cmath
import csv
import math
import os
import sys


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("outdir")
    p.add_argument("--series", default=None, help="the CSV with the port velocities (relative to outdir); none: energy.csv only")
    p.add_argument("--columns", default="tip_vx,tip_vy,tip_vz", help="candidate columns: the one of largest amplitude is fitted")
    p.add_argument("--after", type=float, default=None, help="fit only the rows after this time [s] (the end of a load)")
    p.add_argument("--alpha", type=float, default=0.0, help="Rayleigh alpha [1/s]")
    p.add_argument("--beta", type=float, default=0.0, help="Rayleigh beta plus eta/E [s]")
    p.add_argument("--zeta", type=float, default=0.0, help="the mode's own damping ratio (a reduced body's -modal_damping_ratios), added to alpha's and beta's")
    p.add_argument("--zeta-rtol", type=float, default=1e-6)
    p.add_argument("--frequency", type=float, default=None, help="expected undamped frequency [Hz]")
    p.add_argument("--frequency-rtol", type=float, default=1e-6)
    p.add_argument("--raw-rtol", type=float, default=None, help="the time-discrete log decrement against the continuous one")
    p.add_argument("--fit-rtol", type=float, default=1e-7, help="the recurrence's residual relative to the series (one mode)")
    p.add_argument("--balance-rtol", type=float, default=None, help="max |balance_residual| / max |H|")
    a = p.parse_args()
    failed = []

    if a.series:
        decay(a, failed)
    energy(a, failed)
    for m in failed:
        print("FAIL: " + m)
    return 1 if failed else 0


def decay(a, failed):
    rows = read(os.path.join(a.outdir, a.series))
    if a.after is not None:
        rows = [r for r in rows if float(r["time"]) > a.after]
    t = [float(r["time"]) for r in rows]
    h = t[1] - t[0]
    for k in range(2, len(t)):
        if abs((t[k] - t[k - 1]) - h) > 1e-9 * h:
            sys.exit("damping_decay: the series' steps are not uniform")
    best = None
    for c in a.columns.split(","):
        y = [float(r[c]) for r in rows]
        amp = max(abs(v) for v in y)
        if best is None or amp > best[0]:
            best = (amp, c, y)
    amp, col, y = best
    s11 = s12 = s22 = r1 = r2 = 0.0
    for n in range(1, len(y) - 1):
        s11 += y[n] * y[n]
        s12 += y[n] * y[n - 1]
        s22 += y[n - 1] * y[n - 1]
        r1 += y[n + 1] * y[n]
        r2 += y[n + 1] * y[n - 1]
    det = s11 * s22 - s12 * s12
    ca = (r1 * s22 - r2 * s12) / det
    cb = (s11 * r2 - s12 * r1) / det
    res = max(abs(y[n + 1] - ca * y[n] - cb * y[n - 1]) for n in range(1, len(y) - 1)) / amp
    if res > a.fit_rtol:
        failed.append("one mode: the recurrence's residual %.3g of the amplitude > %.3g (not a single damped mode)" % (res, a.fit_rtol))
    rho = math.sqrt(-cb)
    theta = math.acos(max(-1.0, min(1.0, ca / (2.0 * rho))))
    z = cmath.rect(rho, theta)
    lam = (2.0 / h) * (z - 1.0) / (z + 1.0)
    w = abs(lam)
    zeta = -lam.real / w
    f = w / (2.0 * math.pi)
    expected = a.zeta + a.alpha / (2.0 * w) + a.beta * w / 2.0
    print("damped mode (%s): f = %.6g Hz, zeta = %.6g" % (col, f, zeta))
    if a.frequency is not None:
        dev = abs(f - a.frequency) / a.frequency
        if dev > a.frequency_rtol:
            failed.append("undamped frequency %.10g Hz, expected %.10g Hz: rel. deviation %.3g > %.3g" % (f, a.frequency, dev, a.frequency_rtol))
        else:
            print("undamped frequency: PASS (rel. deviation < %.0e)" % a.frequency_rtol)
    dev = abs(zeta - expected) / expected
    if dev > a.zeta_rtol:
        failed.append("damping ratio %.10g, expected %.10g: rel. deviation %.3g > %.3g" % (zeta, expected, dev, a.zeta_rtol))
    else:
        print("damping ratio: PASS (zeta = %.4g within %.0e of the expected ratio)" % (expected, a.zeta_rtol))
    if a.raw_rtol is not None:
        delta = 2.0 * math.pi * expected / math.sqrt(1.0 - expected * expected)
        delta_h = -2.0 * math.pi * math.log(rho) / theta
        dev = abs(delta_h - delta) / delta
        if dev > a.raw_rtol:
            failed.append("time-discrete log decrement %.8g, continuous %.8g: rel. deviation %.3g > %.3g" % (delta_h, delta, dev, a.raw_rtol))
        else:
            print("log decrement per period: PASS (%.4g, the continuous one within %.0e)" % (delta, a.raw_rtol))


def energy(a, failed):
    e = read(os.path.join(a.outdir, "energy.csv"))
    H0 = max(abs(float(r["total"])) for r in e)
    Dp = [float(r["dissipated_power"]) for r in e]
    Dw = [float(r["dissipated_work"]) for r in e]
    if min(Dp) < 0:
        failed.append("dissipated power negative: %.3g W" % min(Dp))
    if min(Dw) < 0 or any(Dw[k] < Dw[k - 1] for k in range(1, len(Dw))):
        failed.append("dissipated work negative or decreasing")
    else:
        print("dissipated work: PASS (>= 0, never decreasing)")
    if a.balance_rtol is not None:
        worst = max(abs(float(r["balance_residual"])) for r in e) / H0
        if worst > a.balance_rtol:
            failed.append("power balance: max |H_(n+1) - H_n - dt (P - D)| %.3g of max |H| > %.3g" % (worst, a.balance_rtol))
        else:
            print("power balance with dissipation: PASS (max residual < %.0e of max |H|)" % a.balance_rtol)


if __name__ == "__main__":
    sys.exit(main())
