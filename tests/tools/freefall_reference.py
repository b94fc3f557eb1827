#!/usr/bin/env python3
"""Reference of a body in free fall (uniform gravity, no rotation), for tests/cases/floating_gravity_freefall.test.

Writes the frame origin r_P(t) = r0 + v0 t + g t^2 / 2 and the centre of mass c(t) = c0 + v0 t + g t^2 / 2 (columns
time,rx,ry,rz,cx,cy,cz, inertial frame, SI) at t = n*dt, n = 0..steps, in the format of phlex's rigid.csv. The
implicit midpoint rule integrates this motion exactly, so phlex must agree to round-off. Standard library only.

  python3 tests/tools/freefall_reference.py --r0 0,0,0 --c0 0,0.5,0 --v0 0,1,0.5 --g 0,0,-9.81 --dt 1e-3 --steps 100 \\
      -o tests/ref/floating_gravity_freefall_rigid.csv
"""
import argparse


def vec3(text):
    v = [float(s) for s in text.split(",")]
    if len(v) != 3:
        raise argparse.ArgumentTypeError(f"expected three comma-separated numbers, got {text!r}")
    return v


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--r0", type=vec3, required=True, help="initial position of the frame origin P [m]")
    p.add_argument("--c0", type=vec3, required=True, help="initial position of the centre of mass [m]")
    p.add_argument("--v0", type=vec3, required=True, help="initial velocity (inertial frame) [m/s]")
    p.add_argument("--g", type=vec3, required=True, help="gravity [m/s^2]")
    p.add_argument("--dt", type=float, required=True)
    p.add_argument("--steps", type=int, required=True)
    p.add_argument("-o", "--output", required=True)
    a = p.parse_args()
    rows = ["time,rx,ry,rz,cx,cy,cz"]
    for n in range(a.steps + 1):
        t = n * a.dt
        r = [a.r0[i] + a.v0[i] * t + 0.5 * a.g[i] * t * t for i in range(3)]
        c = [a.c0[i] + a.v0[i] * t + 0.5 * a.g[i] * t * t for i in range(3)]
        rows.append(",".join(f"{x:.12e}" for x in [t] + r + c))
    with open(a.output, "w") as f:
        f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
