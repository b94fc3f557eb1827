#!/usr/bin/env python3
"""Checks the dissipation bookkeeping of a run with force elements (issue 45):
  * energy.csv: dissipated_power >= 0 at every step, dissipated_work non-decreasing, |balance_residual| <= --balance-atol;
  * every <joint>_joint.csv given: the same for its dissipated_power and dissipated_work, and its stored_energy >= 0;
  * the joints' dissipated work adds up to the total of energy.csv (to --sum-rtol), when every damper is a joint's.
Prints one verdict line per check; exit 1 on any failure."""
import argparse
import csv
import sys


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def monotone(rows, power, work, name):
    bad = []
    if any(float(r[power]) < 0 for r in rows):
        bad.append(f"{name}: {power} < 0 at some step")
    w = [float(r[work]) for r in rows]
    if any(b < a for a, b in zip(w, w[1:])) or w[0] < 0:
        bad.append(f"{name}: {work} negative or decreasing")
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("energy")
    ap.add_argument("joints", nargs="*")
    ap.add_argument("--balance-atol", type=float, required=True, help="bound on |balance_residual| [J]")
    ap.add_argument("--sum-rtol", type=float, default=-1.0, help="the joints' dissipated work against the total (<0: not checked)")
    a = ap.parse_args()
    energy = read(a.energy)
    fails = monotone(energy, "dissipated_power", "dissipated_work", "energy.csv")
    worst = max(abs(float(r["balance_residual"])) for r in energy)
    print(f"balance residual: max |H_n+1 - H_n - supplied + dissipated| {'<=' if worst <= a.balance_atol else '>'} {a.balance_atol:g} J: {'PASS' if worst <= a.balance_atol else 'FAIL'}")
    if worst > a.balance_atol:
        fails.append(f"balance residual {worst:.3e} J")
    total = 0.0
    for path in a.joints:
        rows = read(path)
        name = path.split("/")[-1]
        fails += monotone(rows, "dissipated_power", "dissipated_work", name)
        if any(float(r["stored_energy"]) < 0 for r in rows):
            fails.append(f"{name}: stored_energy < 0")
        total += float(rows[-1]["dissipated_work"])
    if a.sum_rtol >= 0:
        ref = float(energy[-1]["dissipated_work"])
        ok = abs(total - ref) <= a.sum_rtol * abs(ref)
        print(f"the joints' dissipated work adds up to energy.csv's (rtol {a.sum_rtol:g}): {'PASS' if ok else 'FAIL'}")
        if not ok:
            fails.append(f"joints {total:.12e} J, energy.csv {ref:.12e} J")
    print(f"dissipated power >= 0 and dissipated work non-decreasing ({1 + len(a.joints)} files): {'FAIL' if any('decreasing' in f or '< 0' in f for f in fails) else 'PASS'}")
    for f in fails:
        print("  " + f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
