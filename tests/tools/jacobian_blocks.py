#!/usr/bin/env python3
"""Block-wise check of phlex's Jacobian against finite differences (a test filter).

Reads the stdout of a phlex run with
    -phlex_jacobian_aij -snes_test_jacobian 1e-14 -snes_test_jacobian_view
from stdin (only the first test printed, i.e. the first Newton iteration), splits the matrices into the blocks of
the unknowns [displacement | stress | velocity | rigid (r, R, v_P, w)] and prints, for every block where the
hand-coded or the finite-difference Jacobian is nonzero, the largest entry of each and the largest entry of their
difference relative to the block's largest entry, with PASS or FAIL against --rtol.

PETSc's own summary (||J - Jfd||_F / ||J||_F) is dominated by the largest blocks; the rigid-elastic borders are
orders of magnitude smaller, so an error there would hide in it. Standard library only.

    bin/phlex ... | python3 tests/tools/jacobian_blocks.py --nv 120 --ns 360 [--rtol 1e-6]
    bin/phlex ... | python3 tests/tools/jacobian_blocks.py --blocks u:120,s:360,v:120,bob:18,hinge:5

--nv/--ns: one flexible body (and its floating frame); --blocks: any layout, the unknowns in order as name:count
(the fields of all flexible bodies first, then the discrete unknowns of the parts and the joints' impulses).
"""

import argparse
import re
import sys


def parse(lines, last=False):
    """The three matrices (hand-coded, finite difference, difference) of the first test (or of the last one), as
    {row: {col: value}}."""
    names = {"Hand-coded Jacobian": "J", "Finite difference Jacobian": "F", "Hand-coded minus finite-difference": "D"}
    if last:
        starts = [i for i, line in enumerate(lines) if "Hand-coded Jacobian" in line and "----" in line]
        if starts:
            lines = lines[starts[-1]:]
    mats, current = {}, None
    entry = re.compile(r"\((\d+), ([-+0-9.eEinfa]+)\)")
    for line in lines:
        started = [k for k in names if k in line and "----" in line]
        if started:
            key = names[started[0]]
            if key in mats:  # a second Newton iteration: stop at the first test
                break
            current = mats.setdefault(key, {})
            continue
        if current is None:
            continue
        m = re.match(r"\s*row (\d+):(.*)", line)
        if m:
            row = current.setdefault(int(m.group(1)), {})
            for col, val in entry.findall(m.group(2)):
                row[int(col)] = float(val)
        elif "Testing Jacobian" in line or "||J - Jfd||" in line:
            if current is mats.get("D"):
                break
    return mats


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nv", type=int, help="velocity (and displacement) unknowns")
    ap.add_argument("--ns", type=int, help="stress unknowns")
    ap.add_argument("--blocks", help="the layout as name:count,name:count,... (instead of --nv/--ns)")
    ap.add_argument("--rtol", type=float, default=1e-6, help="bound on max|J - Jfd| / max|J| per block")
    ap.add_argument("--floor", type=float, default=0.0,
                    help="differences below this share of the largest entry of the whole Jacobian pass: finite "
                         "differences do not resolve entries that small (default 0: off)")
    ap.add_argument("--last", action="store_true", help="check the last test printed (the last Newton iteration) instead of the first")
    args = ap.parse_args()
    mats = parse(sys.stdin.read().splitlines(), args.last)
    for key in "JFD":
        if key not in mats:
            print(f"FAIL: no {'hand-coded finite-difference difference'.split()[('JFD').index(key)]} matrix in the input")
            return 1
    n = max(max(mats["J"]), max(mats["F"])) + 1
    if args.blocks:
        fields, start = [], 0
        for item in args.blocks.split(","):
            name, count = item.rsplit(":", 1)
            fields.append((name, start, start + int(count)))
            start += int(count)
        if n > start:
            print(f"FAIL: the matrix has {n} rows, the blocks {start}")
            return 1
    else:
        nv, ns = args.nv, args.ns
        q0 = 2 * nv + ns
        fields = [("u", 0, nv), ("s", nv, nv + ns), ("v", nv + ns, q0),
                  ("r", q0, q0 + 3), ("R", q0 + 3, q0 + 12), ("vP", q0 + 12, q0 + 15), ("w", q0 + 15, q0 + 18)]
        if n not in (q0, q0 + 18):
            print(f"FAIL: the matrix has {n} rows, expected {q0} or {q0 + 18} for --nv {nv} --ns {ns}")
            return 1
        if n == q0:
            fields = fields[:3]
    failed = 0
    floor = args.floor * max((abs(v) for r in mats["J"].values() for v in r.values()), default=0.0)
    print(f"{'block':>16} {'max|J|':>10} {'max|Jfd|':>10} {'rel diff':>10}")
    for rname, r0, r1 in fields:
        for cname, c0, c1 in fields:
            def bmax(mat):
                return max((abs(v) for r in range(r0, r1) for c, v in mat.get(r, {}).items() if c0 <= c < c1), default=0.0)
            jm, fm, dm = bmax(mats["J"]), bmax(mats["F"]), bmax(mats["D"])
            if jm == 0.0 and fm == 0.0:
                continue
            rel = dm / max(jm, fm)
            ok = rel <= args.rtol or dm <= floor
            failed += not ok
            print(f"{rname + ' x ' + cname:>16} {jm:10.3e} {fm:10.3e} {rel:10.1e} {'PASS' if ok else 'FAIL'}")
    print(f"Jacobian blocks: {'PASS' if not failed else 'FAIL'} ({failed} blocks above rtol {args.rtol:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
