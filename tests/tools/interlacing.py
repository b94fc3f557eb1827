#!/usr/bin/env python3
"""The eigenvalues of a system and of the same system with one more constraint interlace (a test filter).

If B is A with one more constraint row (a weld is a revolute plus the rotation about its axis; the same K and M),
the min-max principle gives, for the squared frequencies sorted ascending with A's zero ones counted,
    lambda_k(A) <= lambda_k(B) <= lambda_{k+1}(A),   k = 1 .. n_B
(with one constraint more, B's k-th value cannot fall below A's nor rise above A's next). Reads two
linearized_modes.csv (configuration 0, every mode, mechanism modes at zero frequency), checks the chain with a
relative slack --rtol for the eigensolver's accuracy, and prints the tightest margin and PASS/FAIL. Standard library
only.

    python3 tests/tools/interlacing.py pinned/linearized_modes.csv welded/linearized_modes.csv --rtol 1e-10
"""

import argparse
import csv
import sys


def frequencies(path):
    with open(path) as f:
        return sorted(float(r["frequency_hz"]) for r in csv.DictReader(f) if r["configuration"] == "0")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a", help="the system with one constraint fewer")
    ap.add_argument("b", help="the system with one constraint more")
    ap.add_argument("--rtol", type=float, required=True, help="slack of each inequality, relative")
    ap.add_argument("--label", default="interlacing")
    args = ap.parse_args()
    fa, fb = frequencies(args.a), frequencies(args.b)
    if len(fa) < len(fb) + 1:
        print(f"{args.label}: FAIL (needs {len(fb) + 1} values of the first, got {len(fa)})")
        return 1
    ok, tightest, where = True, float("inf"), ""
    for k, f in enumerate(fb):
        low, high = fa[k], fa[k + 1]
        ok = ok and low <= f * (1 + args.rtol) and f <= high * (1 + args.rtol)
        for margin, text in (((f - low) / f, f"{f:.10g} Hz over {low:.10g}"), ((high - f) / f, f"{f:.10g} Hz under {high:.10g}")):
            if margin < tightest:
                tightest, where = margin, text
    print(f"{args.label}: {len(fb)} values between consecutive values of the first (slack {args.rtol:g}): "
          f"{'PASS' if ok else 'FAIL'}; tightest margin {tightest:.1e} ({where})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
