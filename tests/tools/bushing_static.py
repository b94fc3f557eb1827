#!/usr/bin/env python3
"""Static deflection of a bushing: the last row of <joint>_joint.csv against e = K^-1 f (K the 6 x 6 stiffness in the
joint frame, f the load wrench at the joint point in that frame), and the element's forces against -f. Prints one
verdict line each; exit 1 on failure."""
import argparse
import csv
import sys


def solve(K, f):
    n = len(f)
    A = [row[:] + [f[i]] for i, row in enumerate(K)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(A[r][c]))
        A[c], A[p] = A[p], A[c]
        for r in range(n):
            if r != c:
                m = A[r][c] / A[c][c]
                A[r] = [a - m * b for a, b in zip(A[r], A[c])]
    return [A[i][n] / A[i][i] for i in range(n)]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("--stiffness", required=True, help="36 values, row-major")
    ap.add_argument("--load", required=True, help="Fx,Fy,Fz,Mx,My,Mz in the joint frame")
    ap.add_argument("--rtol", type=float, required=True, help="bound on max|e - K^-1 f| / max|K^-1 f| (and the forces')")
    a = ap.parse_args()
    k = [float(x) for x in a.stiffness.split(",")]
    K = [k[6 * i:6 * i + 6] for i in range(6)]
    f = [float(x) for x in a.load.split(",")]
    e = solve(K, f)
    with open(a.csv) as fh:
        last = list(csv.DictReader(fh))[-1]
    rows = ["t1", "t2", "t3", "r1", "r2", "r3"]
    de = max(abs(float(last["state_" + r]) - e[i]) for i, r in enumerate(rows)) / max(abs(x) for x in e)
    df = max(abs(float(last["force_" + r]) + f[i]) for i, r in enumerate(rows)) / max(abs(x) for x in f)
    ok = True
    for what, d in (("deflection e = K^-1 f", de), ("element force = -f", df)):
        good = d <= a.rtol
        ok = ok and good
        print(f"bushing static {what}: relative error {'<=' if good else '>'} {a.rtol:g}: {'PASS' if good else 'FAIL'}")
        if not good:
            print(f"  relative error {d:.3e}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
