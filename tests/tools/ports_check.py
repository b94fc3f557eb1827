#!/usr/bin/env python3
"""Checks ports.csv (-output_ports, -output_ports_interval) against the bodies' own series. A test filter.

For the ports named in --ports (body:port,...):
  - the header: time, then per port body:port_ Fx Fy Fz Tx Ty Tz vx vy vz wx wy wz x y z joint_Fx .. joint_Tz;
  - the sample times: k h for k = 0, 1, ... up to --end (h = --interval; 0: every step of <body>_ports.csv);
  - the input wrench, the output velocities and the position: equal to <body>_ports.csv's <port>_ columns, linearly
    interpolated between its steps around each sample (a sample on a step: that step's row), within --rtol of each
    column's largest magnitude;
  - the joint wrench: for --joint body:port=joint, its force and moment magnitudes equal those of <joint>_joint.csv
    (a joint frame there, the body frame here), interpolated likewise; for a port without a joint, zero.
Prints one verdict line per check.

    python3 tests/tools/ports_check.py OUTDIR --ports bob:tip,bob:pivot --interval 0.0035 --end 0.1
        --joint bob:pivot=hinge
"""
import argparse
import csv
import math
import os
import sys

QUANTITIES = ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz", "vx", "vy", "vz", "wx", "wy", "wz", "x", "y", "z",
              "joint_Fx", "joint_Fy", "joint_Fz", "joint_Tx", "joint_Ty", "joint_Tz"]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = [h.strip() for h in rows[0]]
    return header, [dict(zip(header, (float(x) for x in r))) for r in rows[1:] if r]


def interpolate(rows, t, key):
    """rows' column key at time t, linear between the rows around it (exact on a row)"""
    times = [r["time"] for r in rows]
    tol = 1e-9 * (times[1] - times[0]) if len(times) > 1 else 0.0
    for i, ti in enumerate(times):
        if abs(ti - t) <= tol:
            return key(rows[i])
        if ti > t:
            a, b = rows[i - 1], rows[i]
            s = (t - a["time"]) / (b["time"] - a["time"])
            return (1 - s) * key(a) + s * key(b)
    raise ValueError("t = %g past the series' end %g" % (t, times[-1]))


def verdict(name, problems):
    print("%s: %s" % (name, "PASS" if not problems else "FAIL (" + problems[0] + (", ..." if len(problems) > 1 else "") + ")"))
    return not problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir")
    ap.add_argument("--ports", required=True)
    ap.add_argument("--interval", type=float, required=True)
    ap.add_argument("--end", type=float, required=True)
    ap.add_argument("--joint", action="append", default=[], help="body:port=joint")
    ap.add_argument("--rtol", type=float, default=1e-9)
    a = ap.parse_args()
    ports = a.ports.split(",")
    joints = dict(j.split("=") for j in a.joint)
    header, rows = read(os.path.join(a.outdir, "ports.csv"))
    ok = True

    expected = ["time"] + ["%s_%s" % (p, q) for p in ports for q in QUANTITIES]
    ok &= verdict("columns", [] if header == expected else ["header %s" % ",".join(header[:4])])

    bodies = {}
    for p in ports:
        body = p.split(":")[0]
        if body not in bodies:
            bodies[body] = read(os.path.join(a.outdir, body + "_ports.csv"))[1]
    steps = [r["time"] for r in next(iter(bodies.values()))]
    if a.interval > 0:
        want = [k * a.interval for k in range(int(math.floor(a.end / a.interval + 1e-9)) + 1)]
    else:
        want = steps
    got = [r["time"] for r in rows]
    problems = []
    if len(got) != len(want):
        problems.append("%d samples, expected %d" % (len(got), len(want)))
    else:
        problems += ["sample %d at t = %.12g, expected %.12g" % (k, g, w) for k, (g, w) in enumerate(zip(got, want))
                     if abs(g - w) > 1e-12 * max(1.0, abs(w))]
    ok &= verdict("sample times (%d, %s)" % (len(want), "every step" if a.interval == 0 else "k h"), problems)

    problems = []
    for p in ports:
        body, port = p.split(":")
        series = bodies[body]
        for q in QUANTITIES[:15]:
            col = "%s_%s" % (port, q)
            scale = max(abs(r[col]) for r in series) or 1.0
            for r in rows:
                ref = interpolate(series, r["time"], lambda s: s[col])
                if abs(r["%s_%s" % (p, q)] - ref) > a.rtol * scale:
                    problems.append("%s_%s at t = %g: %.12g, %s_ports.csv %.12g" % (p, q, r["time"], r["%s_%s" % (p, q)], body, ref))
    ok &= verdict("input wrench, output velocities and position = the bodies' series (interpolated)", problems)

    problems = []
    for p in ports:
        if p in joints:
            jrows = read(os.path.join(a.outdir, joints[p] + "_joint.csv"))[1]
            for part, keys, mine in (("force", ("Fx", "Fy", "Fz"), ("joint_Fx", "joint_Fy", "joint_Fz")),
                                     ("moment", ("Mx", "My", "Mz"), ("joint_Tx", "joint_Ty", "joint_Tz"))):
                scale = max(math.sqrt(sum(r[k] ** 2 for k in keys)) for r in jrows) or 1.0
                for r in rows:
                    ref = interpolate(jrows, r["time"], lambda s: math.sqrt(sum(s[k] ** 2 for k in keys)))
                    # the joint series' magnitude is that of the interpolated vector only on a step
                    val = math.sqrt(sum(r["%s_%s" % (p, k)] ** 2 for k in mine))
                    on_step = min(abs(r["time"] - t) for t in steps) <= 1e-9 * (steps[1] - steps[0])
                    if on_step and abs(val - ref) > a.rtol * scale:
                        problems.append("|%s| of %s at t = %g: %.12g, %s_joint.csv %.12g" % (part, p, r["time"], val, joints[p], ref))
        else:
            problems += ["%s_%s nonzero at t = %g" % (p, q, r["time"]) for r in rows for q in QUANTITIES[15:]
                         if r["%s_%s" % (p, q)] != 0.0]
    ok &= verdict("joint wrench = the joint series' (magnitudes, at the steps), zero without a joint", problems)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
