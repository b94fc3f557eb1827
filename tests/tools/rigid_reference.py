#!/usr/bin/env python3
"""Reference angular velocities of a torque-free rigid body, for the floating-body regression tests.

Writes a CSV with the columns time,wx,wy,wz (w in rad/s, body axes = principal axes at the centre of
mass), one row per output step t = n*dt, n = 0..steps, in the format of phlex's rigid.csv, so that
tests/run.py can compare it row by row with phlex's rigid.csv.

Euler's equations (torque free, principal axes, I1, I2, I3 the principal central moments):
    I1 w1' = (I2 - I3) w2 w3
    I2 w2' = (I3 - I1) w3 w1
    I3 w3' = (I1 - I2) w1 w2
Only ratios of the moments matter, so the mass cancels: a homogeneous box a x b x c has
I ~ (b^2 + c^2, a^2 + c^2, a^2 + b^2).

Two modes:
  precession   axisymmetric body (I2 = I3): the closed-form solution
                   w1 = const, w2 = A cos(l t) + B sin(l t), w3 = -A sin(l t) + B cos(l t),
                   l = (I2 - I1)/I2 * w1,  A = w2(0), B = w3(0)
               (from the equations above: w2' = l w3, w3' = -l w2).
  euler        any body: classical RK4 with `substeps` steps per output step (default 1000, i.e. a
               step of dt/1000; RK4's error ~ (|w| h)^4 is then far below any tolerance used).
               The script also integrates with half the substeps and prints the difference (an
               estimate of the reference's own error) and the drift of the two invariants
               (kinetic energy and |L|^2).

Standard library only. Regenerate the committed references with:
  python3 tests/tools/rigid_reference.py precession --box 1.0,0.1,0.1 --w0 10,1,0 --dt 2.5e-3 --steps 256 \
      -o tests/ref/floating_rigid_precession_rigid.csv
  python3 tests/tools/rigid_reference.py euler --box 0.3,0.2,0.1 --w0 0.1,10,0.1 --dt 5e-3 --steps 400 \
      -o tests/ref/floating_rigid_intermediate_axis_rigid.csv
(the exact command of each reference is also in its test spec, tests/cases/floating_rigid_*.test).
"""

import argparse
import math
import sys


def vec3(text):
    parts = [float(s) for s in text.split(",")]
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected three comma-separated numbers, got {text!r}")
    return parts


def box_inertia(a, b, c):
    """Principal central moments of a homogeneous box per unit mass."""
    return [(b * b + c * c) / 12.0, (a * a + c * c) / 12.0, (a * a + b * b) / 12.0]


def precession(inertia, w0, times):
    i1, i2, i3 = inertia
    if abs(i2 - i3) > 1e-14 * max(abs(i2), abs(i3)):
        sys.exit(f"precession: needs I2 = I3 (symmetry axis x), got I = {inertia}")
    lam = (i2 - i1) / i2 * w0[0]
    a, b = w0[1], w0[2]
    return [(w0[0], a * math.cos(lam * t) + b * math.sin(lam * t),
             -a * math.sin(lam * t) + b * math.cos(lam * t)) for t in times]


def euler_rhs(inertia, w):
    i1, i2, i3 = inertia
    return ((i2 - i3) / i1 * w[1] * w[2],
            (i3 - i1) / i2 * w[2] * w[0],
            (i1 - i2) / i3 * w[0] * w[1])


def rk4(inertia, w0, dt, steps, substeps):
    """w at t = n*dt, n = 0..steps, with `substeps` RK4 steps of dt/substeps in between."""
    h = dt / substeps
    w = tuple(w0)
    out = [w]
    for _ in range(steps):
        for _ in range(substeps):
            k1 = euler_rhs(inertia, w)
            k2 = euler_rhs(inertia, [w[i] + 0.5 * h * k1[i] for i in range(3)])
            k3 = euler_rhs(inertia, [w[i] + 0.5 * h * k2[i] for i in range(3)])
            k4 = euler_rhs(inertia, [w[i] + h * k3[i] for i in range(3)])
            w = tuple(w[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) for i in range(3))
        out.append(w)
    return out


def invariants(inertia, w):
    energy = 0.5 * sum(inertia[i] * w[i] * w[i] for i in range(3))
    l2 = sum((inertia[i] * w[i]) ** 2 for i in range(3))
    return energy, l2


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("mode", choices=("precession", "euler"))
    p.add_argument("--box", type=vec3, help="box dimensions a,b,c along the body axes x,y,z [m]")
    p.add_argument("--inertia", type=vec3, help="principal central moments I1,I2,I3 (any unit; instead of --box)")
    p.add_argument("--w0", type=vec3, required=True, help="initial angular velocity, body axes [rad/s]")
    p.add_argument("--dt", type=float, required=True, help="output interval [s] (phlex's -ts_dt)")
    p.add_argument("--steps", type=int, required=True, help="number of output intervals (phlex's -ts_max_steps)")
    p.add_argument("--substeps", type=int, default=1000, help="euler: RK4 steps per output interval")
    p.add_argument("-o", "--output", required=True, help="CSV file to write ('-': stdout)")
    args = p.parse_args()

    if (args.box is None) == (args.inertia is None):
        p.error("give exactly one of --box and --inertia")
    inertia = box_inertia(*args.box) if args.box else args.inertia
    times = [n * args.dt for n in range(args.steps + 1)]

    if args.mode == "precession":
        ws = precession(inertia, args.w0, times)
    else:
        ws = rk4(inertia, args.w0, args.dt, args.steps, args.substeps)
        coarse = rk4(inertia, args.w0, args.dt, args.steps, max(1, args.substeps // 2))
        self_err = max(abs(a[i] - b[i]) for a, b in zip(ws, coarse) for i in range(3))
        e0, l0 = invariants(inertia, ws[0])
        drift = max(max(abs(e - e0) / e0, abs(l - l0) / l0) for e, l in (invariants(inertia, w) for w in ws))
        print(f"rk4: h = dt/{args.substeps}; max |w(h) - w(2h)| = {self_err:.3e} rad/s; "
              f"max relative drift of energy, |L|^2 = {drift:.3e}", file=sys.stderr)

    lines = ["time,wx,wy,wz"]
    lines += [f"{t:.12e},{w[0]:.12e},{w[1]:.12e},{w[2]:.12e}" for t, w in zip(times, ws)]
    text = "\n".join(lines) + "\n"
    if args.output == "-":
        sys.stdout.write(text)
    else:
        with open(args.output, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
