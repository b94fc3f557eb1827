#!/usr/bin/env python3
"""A reduced body's frequencies against the full body's (Rayleigh-Ritz): reads the modes.csv (modal analysis) or
linearized_modes.csv (linearised analysis, first configuration) of a run with the full body (--full) and of one with
the body reduced (--reduced), and checks that both have the same number of zero-frequency modes (rigid or mechanism),
that the first --equal elastic frequencies agree within --rtol (the modes in the basis, or the reduction's accuracy),
and that every reduced elastic frequency is an upper bound of the full one of the same rank (slack --slack: the
eigensolvers' accuracy). Prints one PASS/FAIL line per check (the observed numbers on failure, or always with
--verbose); exit 1 on any failure."""
import argparse
import csv
import sys

p = argparse.ArgumentParser()
p.add_argument("--full", required=True, help="the full body's CSV")
p.add_argument("--reduced", required=True, help="the reduced body's CSV")
p.add_argument("--full-body", help="modes.csv: the rows of this body only (the full body in a scene of several)")
p.add_argument("--reduced-body", help="modes.csv: the rows of this body only")
p.add_argument("--label", default="reduced frequencies")
p.add_argument("--equal", type=int, default=0, help="how many of the lowest elastic frequencies must agree")
p.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance of that agreement")
p.add_argument("--slack", type=float, default=1e-9, help="relative slack of the upper bounds")
p.add_argument("--verbose", action="store_true")
a = p.parse_args()
ok = True


def load(path, body):
    """(number of zero-frequency modes, elastic frequencies [Hz] ascending)"""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if body:
        rows = [r for r in rows if r["body"] == body]
    if rows and "rigid" in rows[0]:
        zero = [r for r in rows if r["rigid"] == "1"]
        elastic = [r for r in rows if r["rigid"] == "0"]
    else:
        rows = [r for r in rows if r["configuration"] == "0"]
        zero = [r for r in rows if r["kind"] == "mechanism"]
        elastic = [r for r in rows if r["kind"] != "mechanism"]
    return len(zero), sorted(float(r["frequency_hz"]) for r in elastic)


def check(name, cond, detail=""):
    global ok
    print(f"{a.label}: {name}: {'PASS' if cond else 'FAIL'}{(' (' + detail + ')') if detail and (a.verbose or not cond) else ''}")
    ok = ok and cond


zf, ff = load(a.full, a.full_body)
zr, fr = load(a.reduced, a.reduced_body)
check("zero-frequency modes", zf == zr, f"full {zf}, reduced {zr}")
n = min(len(ff), len(fr))
if a.equal:
    errs = [abs(fr[i] - ff[i]) / ff[i] for i in range(min(a.equal, n))]
    worst = max(errs) if errs else float("inf")
    check(f"the lowest {a.equal} equal the full body's within rtol {a.rtol:g}", len(errs) == a.equal and worst <= a.rtol,
          f"max relative difference {worst:.3e}" + ("" if len(errs) == a.equal else f", only {len(errs)} compared"))
margins = [fr[i] / ff[i] - 1 for i in range(n)]
check(f"upper bounds of the full body's ({n} frequencies, slack {a.slack:g})", n > 0 and min(margins) >= -a.slack,
      "relative excess " + ", ".join(f"{m:.3e}" for m in margins))
sys.exit(0 if ok else 1)
