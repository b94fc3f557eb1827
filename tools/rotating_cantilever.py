#!/usr/bin/env python3
"""Flapwise and lagwise bending frequencies of a spinning cantilever against the beam reference.

Reads the linearised analysis's linearized_modes.csv of a spin sweep (position = spin rate [rad/s]; the scene
options/rotating_cantilever.yaml) and the reference rotating_cantilever_frequencies.csv (cases.md section 4:
columns Omega_bar,flap1,flap2,flap3,lag1,lag2,lag3, non-dimensional lambda = omega / omega_ref). omega_ref =
sqrt(EI / (rho A L^4)) is given (--omega-ref, rad/s). At every swept rate the lowest four modes are, in ascending
order, lag1 < flap1 < lag2 < flap2 (true of the reference from Omega_bar = 1 to 12: the spin softens the lag below
the flap, and flap1 stays below lag2; at rest the square section makes the pairs equal); a divergence (kind
'unstable') is a lag mode. Two models:

  --model stiffened (default): each lambda against the reference at that Omega_bar (--rtol), and the ratio
      omega(Omega) / omega(0) against the reference's ratio (--ratio-rtol): the ratio takes out the 3D beam's error
      at rest (cases.md: 'compare the non-rotating 3D value first').
  --model linear: the linear floating-frame model without stiffening (cases.md: 'keeps the flapwise frequency at
      its rest value and softens the lagwise one as sqrt(lambda0^2 - Omega_bar^2)'): flap within --rtol of the 3D
      rest value, lag within --rtol of sqrt(lambda0^2 - Omega_bar^2), and unstable beyond Omega_bar = lambda0 with
      the growth rate sqrt(Omega_bar^2 - lambda0^2) omega_ref (within --rtol).

Prints one line per rate and the largest deviations; exit status 1 if a check fails.

  tools/rotating_cantilever.py output/rotating_cantilever/linearized_modes.csv REF.csv --omega-ref 29.95723
      [--model stiffened|linear] [--rtol 0.01] [--ratio-rtol 0.01] [--out comparison.csv]
"""
import argparse
import csv
import math
import sys

NAMES = ["lag1", "flap1", "lag2", "flap2"]


def read_modes(path):
    """{spin rate: [(omega, growth), ...] ascending in the run's order}"""
    configs = {}
    order = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["kind"] == "mechanism":
                continue
            w = float(r["position"])
            if w not in configs:
                configs[w] = []
                order.append(w)
            configs[w].append((float(r["omega_rad_s"]), float(r.get("growth_rate_1_s") or 0.0), r["kind"]))
    return [(w, configs[w]) for w in order]


def read_reference(path):
    with open(path, newline="") as f:
        return {round(float(r["Omega_bar"]), 6): r for r in csv.DictReader(f)}


def classify(modes):
    """lag1, flap1, lag2, flap2 from the lowest modes of one rate: unstable ones are lags, the rest ascending"""
    unstable = [m for m in modes if m[2] == "unstable"]
    stable = sorted(m for m in modes if m[2] != "unstable")
    if len(unstable) > 1:
        raise ValueError("%d unstable modes: only the first lag can diverge in this sweep" % len(unstable))
    if unstable:
        return [unstable[0]] + stable[:3]
    return stable[:4]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("modes")
    ap.add_argument("reference")
    ap.add_argument("--omega-ref", type=float, required=True, help="sqrt(EI / (rho A L^4)) [rad/s]")
    ap.add_argument("--model", choices=["stiffened", "linear"], default="stiffened")
    ap.add_argument("--rtol", type=float, default=0.01)
    ap.add_argument("--ratio-rtol", type=float, default=0.01)
    ap.add_argument("--out", help="write Omega_bar, the computed and reference lambdas and the deviations")
    a = ap.parse_args()
    try:
        runs = read_modes(a.modes)
        ref = read_reference(a.reference)
    except (OSError, KeyError, ValueError) as e:
        sys.exit("rotating_cantilever.py: %s" % e)
    if not runs:
        sys.exit("%s: no mode" % a.modes)
    rest = [m for w, m in runs if w == 0.0]
    if not rest:
        sys.exit("%s: the sweep has no rate 0 (the rest values that the ratios and the linear model need)" % a.modes)
    lam0 = [m[0] / a.omega_ref for m in sorted(rest[0])[:4]]  # at rest: the pairs (lag, flap) equal
    lam0 = {"lag1": lam0[0], "flap1": lam0[1], "lag2": lam0[2], "flap2": lam0[3]}
    ok = True
    worst = {}
    rows = []
    print("%8s  %s" % ("Omega_bar", "  ".join("%-26s" % n for n in NAMES)))
    for w, modes in runs:
        ob = w / a.omega_ref
        key = round(ob, 6)
        if len(modes) < 4:
            sys.exit("%s: %d modes at %g rad/s; 4 needed (-linearized_nev 4)" % (a.modes, len(modes), w))
        try:
            cls = classify(modes)
        except ValueError as e:
            sys.exit("%s at %g rad/s: %s" % (a.modes, w, e))
        cells = []
        for name, (om, gr, kind) in zip(NAMES, cls):
            lam = om / a.omega_ref
            if a.model == "stiffened":
                if key not in ref:
                    sys.exit("%s: Omega_bar %g is not in the reference (0, 1, ..., 12)" % (a.modes, ob))
                lr = float(ref[key][name])
                l0r = float(ref[0.0][name])
                if kind == "unstable":
                    dev = ratio_dev = float("inf")
                else:
                    dev = (lam - lr) / lr
                    ratio_dev = (lam / lam0[name]) / (lr / l0r) - 1.0
                checks = [("lambda", dev, a.rtol), ("ratio", ratio_dev, a.ratio_rtol)]
                cells.append("%-26s" % ("%.5f (ref %.4f, %+.3f%%)" % (lam, lr, 100 * dev)))
                rows.append([ob, name, lam, lr, dev, ratio_dev])
            else:
                l0 = lam0[name]
                if name.startswith("flap"):
                    expect, got = l0, lam
                    what = "flap"
                else:
                    d = l0 * l0 - ob * ob
                    if d > 0:
                        expect, got = math.sqrt(d), (lam if kind != "unstable" else float("nan"))
                        what = "lag"
                    else:
                        expect, got = math.sqrt(-d), (gr / a.omega_ref if kind == "unstable" else float("nan"))
                        what = "growth"
                dev = (got - expect) / expect if expect > 0 and not math.isnan(got) else float("inf")
                checks = [(what, dev, a.rtol)]
                cells.append("%-26s" % ("%s %.5f (%.5f, %+.3f%%)" % (what, got, expect, 100 * dev)))
                rows.append([ob, name, got, expect, dev, ""])
            for label, d, tol in checks:
                k = (name, label)
                if k not in worst or abs(d) > abs(worst[k][0]):
                    worst[k] = (d, ob)
                if not abs(d) <= tol:
                    ok = False
        print("%8.3f  %s" % (ob, "  ".join(cells)))
    for (name, label), (d, ob) in sorted(worst.items()):
        tol = a.ratio_rtol if label == "ratio" else a.rtol
        # a deviation that prints as 0.0000 % is round-off: where it is largest moves with the BLAS kernels
        where = "at Omega_bar %.3g" % ob if abs(100 * d) >= 5e-5 else "at every Omega_bar"
        print("largest deviation %-5s %-6s %+.4f %% %s (tolerance %g %%): %s"
              % (name, label, 100 * d, where, 100 * tol, "PASS" if abs(d) <= tol else "FAIL"))
    if a.out:
        with open(a.out, "w", newline="") as f:
            wr = csv.writer(f)
            wr.writerow(["Omega_bar", "mode", "lambda", "lambda_expected", "deviation", "ratio_deviation"])
            wr.writerows(rows)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
