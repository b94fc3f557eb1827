#!/usr/bin/env python3
"""A dissipative scheme's energy never rises: checks energy.csv's total H(t) is non-increasing (within --jitter of
H0, the CSV's rounding) and that the total loss stays below --max-loss (relative to H0). Prints PASS/FAIL lines;
exit status 1 on a FAIL.   energy_monotone.py <dir>/energy.csv [--jitter 1e-11] [--max-loss 1e-4]"""
import argparse
import csv
import sys

ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("--jitter", type=float, default=1e-11)
ap.add_argument("--max-loss", type=float, default=1e-4)
a = ap.parse_args()
H = [float(r["total"]) for r in csv.DictReader(open(a.csv, newline=""))]
rise = max((h1 - h0 for h0, h1 in zip(H[:-1], H[1:])), default=0.0) / abs(H[0])
loss = (H[0] - H[-1]) / abs(H[0])
ok1, ok2 = rise <= a.jitter, 0.0 <= loss <= a.max_loss
print("energy never rises (largest step-to-step rise %.1e of H0, tolerance %g): %s" % (max(rise, 0.0), a.jitter, "PASS" if ok1 else "FAIL"))
print("energy loss over the run %.2e of H0 (tolerance %g): %s" % (loss, a.max_loss, "PASS" if ok2 else "FAIL"))
sys.exit(0 if ok1 and ok2 else 1)
