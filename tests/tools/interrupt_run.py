#!/usr/bin/env python3
"""Interrupts a phlex run with a signal once it has taken steps, and checks the clean stop.

Runs bin/phlex with the given arguments (plus -progress_interval 0, so that a progress line marks each step),
sends the signal after the first progress line, and checks: the exit status is 128 + signal, stderr names the
signal, and the output directory holds no file (the temporary files were removed). Prints one verdict line.

--first PREFIX sends it after the first line starting with PREFIX instead (a phase's progress line), --where TEXT
checks that the message names the phase it stopped in.

Usage: python3 tests/tools/interrupt_run.py --signal TERM --outdir DIR [--first P] [--where T] -- <phlex arguments>
"""

import argparse
import os
import signal
import subprocess
import sys


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--signal", choices=["INT", "TERM"], required=True)
    parser.add_argument("--outdir", required=True)
    parser.add_argument("--first", default="progress:",
                        help="send the signal after the first stdout line that starts with this (default: any progress line)")
    parser.add_argument("--where", help="text the interruption message must hold (the phase it stopped in)")
    parser.add_argument("phlex_args", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    phlex_args = [a for a in args.phlex_args if a != "--"]
    sig = getattr(signal, "SIG" + args.signal)
    # the default SIGINT disposition for phlex: a test suite started in the background by a non-interactive shell
    # ignores SIGINT, phlex then keeps it ignored (by design), and the run would go on to its end
    proc = subprocess.Popen(["bin/phlex"] + phlex_args + ["-output_dir", args.outdir, "-progress_interval", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    for line in proc.stdout:
        if line.startswith(args.first):
            proc.send_signal(sig)
            break
    proc.stdout.read()
    err = proc.stderr.read()
    rc = proc.wait(timeout=120)
    left = os.listdir(args.outdir) if os.path.isdir(args.outdir) else []
    problems = []
    if rc != 128 + sig:
        problems.append(f"exit status {rc}, expected {128 + sig}")
    if f"interrupted by SIG{args.signal}" not in err:
        problems.append("stderr does not name the signal: " + err.strip()[-200:])
    if args.where and args.where not in err:
        problems.append("the message does not say '%s': " % args.where + err.strip()[-200:])
    if left:
        problems.append("left in the output directory: " + ", ".join(sorted(left)))
    print(f"interrupted by SIG{args.signal}: " + ("PASS (exit status %d, nothing left)" % rc if not problems else "FAIL: " + "; ".join(problems)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
