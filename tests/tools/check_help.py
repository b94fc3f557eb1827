#!/usr/bin/env python3
"""Checks bin/phlex -help output read from stdin and prints the lines to compare.

The help must be clean text (printable ASCII only), in phlex's form (no PETSc "formerly"), with every option line
once, and must say that nothing was run. Prints one verdict line per property, then the option lines whose names
match --show (a regular expression), for comparison with the stored output.

Usage: bin/phlex -help | python3 tests/tools/check_help.py --show 'youngs_modulus|drive_velocity'
"""

import argparse
import re
import sys


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--show", default="^$", help="regular expression: option names whose lines are printed")
    args = parser.parse_args()
    data = sys.stdin.buffer.read()
    bad = sorted({b for b in data if not (32 <= b < 127 or b in (9, 10))})
    print("printable: " + ("PASS" if not bad else "FAIL (bytes " + " ".join(f"0x{b:02x}" for b in bad) + ")"))
    text = data.decode("ascii", errors="replace")
    lines = text.splitlines()
    raw = [ln for ln in lines if " : formerly " in ln or "<now " in ln]
    print("phlex form: " + ("FAIL: " + raw[0].strip() if raw else "PASS"))
    options = [ln for ln in lines if re.match(r"^ +-[A-Za-z]", ln)]
    repeated = sorted({ln for ln in options if options.count(ln) > 1})
    print("each option once: " + ("PASS" if not repeated else "FAIL: " + repeated[0]))
    print("help only: " + ("PASS" if lines and lines[-1] == "Nothing was run (help only)." else "FAIL"))
    show = re.compile(args.show)
    for ln in options:
        name = ln.split()[0]
        if show.search(name):
            print(ln.strip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
