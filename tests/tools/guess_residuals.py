#!/usr/bin/env python3
"""CG's initial residual per step with an initial guess against the zero guess (two runs' -condensed_ksp_monitor):
the first step's must be equal (no increment kept yet); from the third step on the median ratio at most --median and
every ratio below --max (the ratio rises where the zero guess's own residual passes near zero, as the increment turns).
Prints one PASS/FAIL line per check.

usage: guess_residuals.py GUESS_STDOUT ZERO_STDOUT [--median 1e-2] [--max 0.1]
"""
import argparse
import re
import statistics


def first_residuals(path):
    return [float(m) for m in re.findall(r"^\s*0 KSP Residual norm (\S+)", open(path).read(), re.M)]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("guess")
    p.add_argument("zero")
    p.add_argument("--median", type=float, default=1e-2)
    p.add_argument("--max", type=float, default=0.1)
    a = p.parse_args()
    g, z = first_residuals(a.guess), first_residuals(a.zero)
    if not g or len(g) != len(z):
        print("initial residuals: FAIL (%d steps with the guess, %d with the zero guess)" % (len(g), len(z)))
        return
    same = abs(g[0] - z[0]) <= 1e-12 * z[0]
    print("first step, no increment kept: %s" % ("PASS (the zero guess's)" if same else "FAIL (%.6e against %.6e)" % (g[0], z[0])))
    ratios = [gi / zi for gi, zi in zip(g[2:], z[2:])]
    if not ratios:
        print("steps from the third: FAIL (only %d steps)" % len(g))
        return
    med, worst = statistics.median(ratios), max(ratios)
    print("steps 3-%d, median initial residual at most %g of the zero guess's: %s" % (len(g), a.median, "PASS" if med <= a.median else "FAIL (%.3g)" % med))
    print("steps 3-%d, every initial residual below %g of the zero guess's: %s" % (len(g), a.max, "PASS" if worst < a.max else "FAIL (%.3g)" % worst))


if __name__ == "__main__":
    main()
