#!/usr/bin/env python3
"""Compare two runs' energy.csv (an iterative preset against a direct one) column by column.

    compare_energy.py ITERATIVE.csv DIRECT.csv --columns kinetic,strain,total --tol 1e-8

For each column, the largest difference over the rows, relative to the column's largest |value| in the direct run
(not to each row's value: an energy that passes through zero is not divided by its small values; nor to the total:
a floating body's strain energy is 1e-10 of its kinetic energy). Prints one PASS/FAIL line
per column (numbers only on failure, so that the stored output does not depend on the machine's round-off); the
measured differences go to stderr. Exit status 0 either way (the runner compares the lines), 2 on bad input."""
import argparse
import csv
import sys


def read(path):
    try:
        with open(path) as f:
            return list(csv.DictReader(f))
    except OSError as e:
        sys.exit("compare_energy.py: cannot read %s: %s" % (path, e.strerror))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("iterative")
    ap.add_argument("direct")
    ap.add_argument("--columns", default="kinetic,strain,total")
    ap.add_argument("--tol", type=float, required=True)
    ap.add_argument("--against", default="the direct preset", help="what the second file is, for the verdict lines")
    a = ap.parse_args()
    it, di = read(a.iterative), read(a.direct)
    if len(it) != len(di) or not di:
        print("compare_energy.py: %s has %d rows, %s %d" % (a.iterative, len(it), a.direct, len(di)), file=sys.stderr)
        sys.exit(2)
    for col in a.columns.split(","):
        if col not in di[0] or col not in it[0]:
            print("compare_energy.py: no column %s" % col, file=sys.stderr)
            sys.exit(2)
        scale = max(abs(float(r[col])) for r in di) or 1.0
        d = max(abs(float(x[col]) - float(y[col])) for x, y in zip(it, di)) / scale
        print("energy column %s against %s: %s" % (col, a.against, "PASS" if d <= a.tol else "FAIL %.3g > %.3g" % (d, a.tol)))
        print("  %s: max difference %.3g of its max %.6g" % (col, d, scale), file=sys.stderr)


main()
