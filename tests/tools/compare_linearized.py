#!/usr/bin/env python3
"""Compares two linearised analyses (their linearized_modes.csv; a configuration of the first, the second's first) mode by mode: the frequencies of every mode (an overdamped motion's decay rate) and,
for the modes listed with --ratios (1-based), the damping ratios, within a relative tolerance. Prints one verdict
line (the label given) and fails (exit 1) beyond the tolerance or when the mode counts differ."""
import argparse
import csv
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--label", required=True)
    ap.add_argument("--rtol", type=float, required=True)
    ap.add_argument("--ratios", default="", help="modes (1-based, comma-separated) whose damping ratios are compared")
    ap.add_argument("--min-ratio", type=float, default=0.0, help="those ratios must exceed this (the damping acts)")
    ap.add_argument("--configuration-a", default="0", help="the configuration of the first file compared (0-based)")
    a = ap.parse_args()
    ra = [r for r in csv.DictReader(open(a.a)) if r["configuration"] == a.configuration_a]
    rb = [r for r in csv.DictReader(open(a.b)) if r["configuration"] == "0"]
    if len(ra) != len(rb) or not ra:
        print("%s: FAIL (%d modes against %d)" % (a.label, len(ra), len(rb)))
        return 1
    def size(r):
        """a mode's frequency, or an overdamped motion's decay rate"""
        f = float(r["frequency_hz"])
        return f if f != 0 or "decay_rate_1_s" not in r else float(r["decay_rate_1_s"])

    df = max(abs(size(x) / size(y) - 1) for x, y in zip(ra, rb))
    dz, zmin = 0.0, float("inf")
    for m in [int(k) for k in a.ratios.split(",") if k]:
        za, zb = float(ra[m - 1]["damping_ratio"]), float(rb[m - 1]["damping_ratio"])
        dz = max(dz, abs(za / zb - 1))
        zmin = min(zmin, za)
    ok = df <= a.rtol and dz <= a.rtol and (not a.ratios or zmin > a.min_ratio)
    print("%s: %s" % (a.label, "PASS" if ok else "FAIL (frequencies %.2g, ratios %.2g, smallest ratio %.3g)" % (df, dz, zmin)))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
