#!/usr/bin/env python3
"""Flapwise and lagwise frequencies of a spinning floating beam measured from transients, against the fixed-hub
linearised analysis of the same beam (issue 42 item 5).

Each transient (--run W:DIR, W the drive's rate in rad/s) is the beam of tests/scenes/rotating_floating.yaml on its driven revolute,
started in its steady spin (-body0_ic_steady_spin) with a small velocity perturbation, with a port on its tip face
(-body0_ports C). The tip's deflection in the body frame, R^T (x_C - r_P) from <body>_ports.csv and <body>_rigid.csv,
has a flapwise (z, out of the plane of rotation) and a lagwise (y) component, which the beam's symmetry decouples.
Each is fitted by linear prediction (Prony, least squares by Householder QR, --order coefficients) on every
--stride-th sample; the roots of its polynomial (Durand-Kerner, then Newton) are the discrete modes z_k, and the mode of
largest amplitude (a second least-squares fit of the amplitudes) is the one the perturbation put in (the first:
the start is the Euler-Bernoulli first mode). Its angle per step theta is the implicit midpoint rule's map of the
pulsation, theta = 2 atan(omega dt / 2), inverted exactly: omega = 2 tan(theta / 2) / dt, so the period error of the
scheme (omega^2 dt^2 / 12) is not in the comparison. The hub of the transient turns at the drive's stage rate
W_d = 2 tan(W dt/2)/dt (the rate whose Cayley map turns it by W dt per step: the field's equations see W_d), so the
reference is the linearised analysis at W_d (a configuration of --linearized, found by its spin rate), compared
within --rtol; with --nominal-rtol also the forward map of the analysis at the nominal rate W,
2 atan(omega(W) dt/2)/dt, against the measured angle per step (what the issue's check states: the scheme's and the
drive's discrete effects both in the deviation).

The linearised modes are, at every rate > 0, in ascending order lag1 < flap1 (tools/rotating_cantilever.py); at
rest the square section makes them equal.

  spin_frequencies.py --linearized LIN/linearized_modes.csv --dt 1e-3 --omega-ref 29.95723 --body beam --port C
      --run 59.91446:DIR2 --run 179.734:DIR6 [--rtol 1e-4] [--nominal-rtol 2e-3] [--order 12] [--out table.csv]

  spin_frequencies.py --steady DIR [--steady-rtol 1e-10] [--steady-tip-rtol 1e-8]: a run started in its steady spin without a perturbation:
      its strain energy and its tip's place in the body frame stay as they started (within rtol of the energy and of
      the tip's stretch).

Prints one line per run and direction and the largest deviations; exit status 1 if a check fails.
"""
import argparse
import cmath
import csv
import math
import sys


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def tip_deflection(run, body, port):
    """the tip's position in the body frame, per step: (y, z) lists"""
    ports = read_csv("%s/%s_ports.csv" % (run, body))
    rigid = read_csv("%s/%s_rigid.csv" % (run, body))
    if len(ports) != len(rigid):
        raise SystemExit("%s: %s_ports.csv and %s_rigid.csv have different numbers of rows" % (run, body, body))
    ys, zs = [], []
    for p, r in zip(ports, rigid):
        d = [float(p["%s_%s" % (port, c)]) - float(r["r" + c]) for c in "xyz"]
        R = [[float(r["R%d%d" % (i, j)]) for j in (1, 2, 3)] for i in (1, 2, 3)]
        b = [sum(R[i][k] * d[i] for i in range(3)) for k in range(3)]  # R^T d
        ys.append(b[1])
        zs.append(b[2])
    return ys, zs


def lstsq(A, b):
    """least squares by Householder QR (real or complex), A list of rows"""
    m, n = len(A), len(A[0])
    A = [list(r) for r in A]
    b = list(b)
    for k in range(n):
        nrm = math.sqrt(sum(abs(A[i][k]) ** 2 for i in range(k, m)))
        if nrm == 0:
            continue
        a = A[k][k]
        alpha = -nrm * (a / abs(a) if a != 0 else 1)
        v = [0] * m
        v[k] = a - alpha
        for i in range(k + 1, m):
            v[i] = A[i][k]
        vn = sum(abs(v[i]) ** 2 for i in range(k, m))
        if vn == 0:
            continue
        for j in range(k, n):
            s = sum(v[i].conjugate() * A[i][j] if isinstance(v[i], complex) else v[i] * A[i][j] for i in range(k, m))
            f = 2 * s / vn
            for i in range(k, m):
                A[i][j] -= f * v[i]
        s = sum(v[i].conjugate() * b[i] if isinstance(v[i], complex) else v[i] * b[i] for i in range(k, m))
        f = 2 * s / vn
        for i in range(k, m):
            b[i] -= f * v[i]
    x = [0] * n
    for k in range(n - 1, -1, -1):
        s = b[k] - sum(A[k][j] * x[j] for j in range(k + 1, n))
        x[k] = s / A[k][k] if A[k][k] != 0 else 0
    return x


def roots(c):
    """roots of z^p + c[0] z^(p-1) + ... + c[p-1] (Durand-Kerner, Newton polish)"""
    p = len(c)
    poly = [1.0] + list(c)

    def ev(z):
        v, d = 0j, 0j
        for a in poly:
            d = d * z + v
            v = v * z + a
        return v, d

    z = [(0.4 + 0.9j) ** k for k in range(p)]
    for _ in range(2000):
        delta = 0
        new = []
        for i in range(p):
            den = 1
            for j in range(p):
                if j != i:
                    den *= z[i] - z[j]
            w = z[i] - ev(z[i])[0] / den
            delta = max(delta, abs(w - z[i]))
            new.append(w)
        z = new
        if delta < 1e-15:
            break
    out = []
    for r in z:
        for _ in range(5):
            v, d = ev(r)
            if d == 0:
                break
            r = r - v / d
        out.append(r)
    return out


def dominant_angle(x, order, stride=1):
    """the angle per sample of the largest-amplitude oscillating mode of x (linear prediction on every stride-th
    sample: densely sampled, consecutive samples are nearly collinear and the prediction ill-conditioned; the modes are
    the same, their angles times stride, which must stay below pi for the dominant one)"""
    x = x[::stride]
    n = len(x)
    A = [[x[k - j] for j in range(1, order + 1)] for k in range(order, n)]
    b = [x[k] for k in range(order, n)]
    a = lstsq(A, b)  # x_k = sum a_j x_{k-j}
    zs = roots([-v for v in a])
    # amplitudes: x_k = sum c_i z_i^k
    V = [[z ** k for z in zs] for k in range(n)]
    c = lstsq(V, [complex(v) for v in x])
    best = None
    for z, ci in zip(zs, c):
        th = cmath.phase(z)
        if th <= 1e-9:  # one of each conjugate pair; the constant (z = 1) and real roots left out
            continue
        amp = abs(ci) * max(1.0, abs(z) ** (n - 1))
        if best is None or amp > best[0]:
            best = (amp, th, abs(z))
    if best is None:
        return None
    return (best[0], best[1] / stride, best[2] ** (1.0 / stride))


def read_linearized(path):
    """{spin rate: [omega ascending]} of the elastic modes"""
    out = {}
    for r in read_csv(path):
        if r["kind"] == "mechanism":
            continue
        out.setdefault(float(r["position"]), []).append(float(r["omega_rad_s"]))
    for k in out:
        out[k].sort()
    return out


def find_rate(lin, w, what):
    best = min(lin, key=lambda k: abs(k - w))
    if abs(best - w) > 1e-7 * max(w, 1.0):
        raise SystemExit("the linearised analysis has no configuration at the %s spin rate %.10g rad/s (nearest %.10g)" % (what, w, best))
    return lin[best]


def steady(run, body, port, rtol, tip_rtol):
    """--steady DIR: a run started in its steady spin without perturbation stays there: the strain energy and the
    tip's deflection in the body frame (from its first value) vary by at most rtol of themselves"""
    e = [float(r["strain"]) for r in read_csv("%s/energy.csv" % run)]
    ys, zs = tip_deflection(run, body, port)
    rows = read_csv("%s/%s_ports.csv" % (run, body))
    xs = []
    for p, r in zip(rows, read_csv("%s/%s_rigid.csv" % (run, body))):
        d = [float(p["%s_%s" % (port, c)]) - float(r["r" + c]) for c in "xyz"]
        R = [[float(r["R%d%d" % (i, j)]) for j in (1, 2, 3)] for i in (1, 2, 3)]
        xs.append(sum(R[i][0] * d[i] for i in range(3)))
    de = max(abs(v - e[0]) for v in e) / max(abs(v) for v in e)
    stretch = max(abs(v - 1.0) for v in xs)  # the tip's stretch along the beam (drawn at x = 1 m), the largest
    dx = max(max(abs(v - xs[0]) for v in xs), max(abs(v - ys[0]) for v in ys), max(abs(v - zs[0]) for v in zs)) / stretch
    ok = de <= rtol and dx <= tip_rtol
    print("steady spin over %d steps: the strain energy (%.6e J at the start) varies by %.1e of its largest (tolerance %g), the tip (stretched %.4e m at most) moves by %.1e of its stretch (tolerance %g): %s" % (len(e) - 1, e[0], de, rtol, stretch, dx, tip_rtol, "PASS" if ok else "FAIL"))
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steady", default=None, help="DIR: check a run that must stay on its steady spin (no perturbation)")
    ap.add_argument("--steady-rtol", type=float, default=1e-10, help="of the strain energy")
    ap.add_argument("--steady-tip-rtol", type=float, default=1e-8, help="of the tip's stretch (the CSV's 13 digits of a 1 m position resolve 1e-12 m)")
    ap.add_argument("--linearized")
    ap.add_argument("--run", action="append", help="W:DIR, the drive's rate [rad/s] and the run's output")
    ap.add_argument("--dt", type=float)
    ap.add_argument("--omega-ref", type=float)
    ap.add_argument("--body", default="beam")
    ap.add_argument("--port", default="C")
    ap.add_argument("--order", type=int, default=12)
    ap.add_argument("--stride", type=int, default=1, help="fit every stride-th sample (keep the dominant mode's angle per fitted sample below pi)")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--nominal-rtol", type=float, default=None)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.steady:
        return steady(a.steady, a.body, a.port, a.steady_rtol, a.steady_tip_rtol)
    if not a.linearized or not a.run or not a.dt or not a.omega_ref:
        ap.error("give --linearized, --run, --dt and --omega-ref (or --steady)")
    lin = read_linearized(a.linearized)
    dt = a.dt
    ok = True
    worst = {}
    rows = []
    for spec in a.run:
        W, run = spec.split(":", 1)
        W = float(W)
        ob = W / a.omega_ref
        Wd = 2 * math.tan(W * dt / 2) / dt
        ref_d = find_rate(lin, Wd, "stage")
        ref_n = find_rate(lin, W, "nominal") if a.nominal_rtol is not None else None
        ys, zs = tip_deflection(run, a.body, a.port)
        for name, sig, idx in (("flap1", zs, 1), ("lag1", ys, 0)):
            if W == 0:
                idx = 0  # at rest flap and lag are the same pair
            fit = dominant_angle(sig, a.order, a.stride)
            if fit is None:
                print("Omega_bar %.4g %s: no oscillating mode found in the tip deflection: FAIL" % (ob, name))
                ok = False
                continue
            amp, th, mod = fit
            om = 2 * math.tan(th / 2) / dt
            dev = om / ref_d[idx] - 1
            line = "Omega_bar %.4g %-5s measured %.6f rad/s (|z| - 1 = %.1e) linearised at the stage rate %.6f: %+.2e" % (ob, name, om, mod - 1, ref_d[idx], dev)
            good = abs(dev) <= a.rtol
            row = {"omega_bar": ob, "mode": name, "measured_rad_s": om, "linearized_stage_rad_s": ref_d[idx], "deviation": dev}
            if ref_n is not None:
                thn = 2 * math.atan(ref_n[idx] * dt / 2)
                devn = th / thn - 1
                line += "; at the nominal rate %.6f, mapped %.6f: %+.2e" % (ref_n[idx], thn / dt, devn)
                good = good and abs(devn) <= a.nominal_rtol
                row["linearized_nominal_rad_s"] = ref_n[idx]
                row["deviation_nominal"] = devn
                worst["nominal"] = max(worst.get("nominal", 0), abs(devn))
            worst["stage"] = max(worst.get("stage", 0), abs(dev))
            print(line + (": PASS" if good else ": FAIL"))
            ok = ok and good
            rows.append(row)
    print("largest deviation from the linearised analysis at the stage rate %.1e (tolerance %g): %s" % (worst.get("stage", 0), a.rtol, "PASS" if worst.get("stage", 0) <= a.rtol else "FAIL"))
    if a.nominal_rtol is not None:
        print("largest deviation from the nominal rate's, mapped by the midpoint rule %.1e (tolerance %g): %s" % (worst["nominal"], a.nominal_rtol, "PASS" if worst["nominal"] <= a.nominal_rtol else "FAIL"))
    if a.out:
        keys = list(rows[0].keys()) if rows else []
        for r in rows:
            for k in r:
                if k not in keys:
                    keys.append(k)
        with open(a.out, "w", newline="") as f:
            w = csv.DictWriter(f, keys)
            w.writeheader()
            w.writerows(rows)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
