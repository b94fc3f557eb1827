#!/usr/bin/env python3
"""Checks of the field files (<body>.h5 + <body>.xmf) a body writes, read with h5dump (Debian's hdf5-tools).

  compare_fields.py compare A.h5 B.h5 [--fields displacement,stress] [--step -1] [--rtol R] [--up-to-sign]
      the arrays of the named fields at one output step of two runs of the same mesh: vertices matched by their
      coordinates and cells by their vertices' (so two process counts, whose numberings differ, compare too);
      PASS when max |A - B| <= R max |B| for each field, over its entities and components (R = 0: the same doubles);
      --up-to-sign: A against B or -B, whichever is closer (mode shapes, whose sign is arbitrary)

  compare_fields.py modal FIELDS.h5 MODAL.csv REDUCED.h5 [--step -1] [--rtol R]
      a reduced body's fields are its basis times its elastic coordinates: displacement = Phi eta, velocity = Phi
      zeta, stress = Psi eta, with Phi and Psi read from the reduced body file (SI: m per m, Pa per m) and eta, zeta
      from <body>_modal.csv at the step's time (the .xmf beside FIELDS.h5); one process, P1 velocity (the vertex
      values are the unknowns; the vertices of the frame patch, zero at every step, are those without unknowns)

Prints one verdict line per field (observed numbers on stderr); exit 1 on a failure, 2 on bad input.
Standard library only."""
import argparse
import csv
import os
import re
import subprocess
import sys


def fail(msg):
    print(f"compare_fields: {msg}", file=sys.stderr)
    sys.exit(2)


def h5read(path, dataset):
    """(shape, flat list of floats) of a dataset, all digits (%.17g)"""
    try:
        out = subprocess.run(["h5dump", "-y", "-w", "0", "-m", "%.17g", "-d", dataset, path],
                             capture_output=True, text=True, check=False)
    except FileNotFoundError:
        fail("h5dump not found: install Debian's hdf5-tools (tools/install-deps.sh)")
    if out.returncode:
        fail(f"h5dump cannot read {dataset} of {path}: {out.stderr.strip()[:300]}")
    m = re.search(r"DATASPACE\s+SIMPLE\s*\{\s*\(([^)]*)\)", out.stdout)
    if not m:
        fail(f"{path}:{dataset}: no dataspace in h5dump's output")
    shape = [int(x) for x in m.group(1).split(",")]
    body = out.stdout[out.stdout.index("DATA {") + len("DATA {"):]
    body = body[:body.index("}")]
    values = [float(x) for x in re.split(r"[,\s]+", body) if x]
    n = 1
    for s in shape:
        n *= s
    if len(values) != n:
        fail(f"{path}:{dataset}: {len(values)} values for shape {shape}")
    return shape, values


def step_rows(path, dataset, step, ncomp):
    """the rows (entities x ncomp) of one step of a (step, entity[, comp]) dataset"""
    shape, v = h5read(path, dataset)
    nsteps, nent = shape[0], shape[1]
    k = step if step >= 0 else nsteps + step
    if not 0 <= k < nsteps:
        fail(f"{path}:{dataset}: no step {step} (it has {nsteps})")
    base = k * nent * ncomp
    return [v[base + ncomp * i: base + ncomp * (i + 1)] for i in range(nent)]


def mesh_keys(path):
    """a key per vertex (its coordinates, rounded) and per cell (its vertices' keys)"""
    shape, x = h5read(path, "/geometry/vertices")
    span = max(abs(c) for c in x) or 1.0
    q = 1e-9 * span
    vkeys = [tuple(round(x[3 * i + c] / q) for c in range(3)) for i in range(shape[0])]
    if len(set(vkeys)) != len(vkeys):
        fail(f"{path}: two vertices at the same place")
    shape, cells = h5read(path, "/viz/topology/cells")
    nv = shape[1]
    ckeys = [tuple(sorted(vkeys[int(cells[nv * i + j])] for j in range(nv))) for i in range(shape[0])]
    return vkeys, ckeys


FIELDS = {  # name -> (dataset, components, vertex field)
    "displacement": ("/vertex_fields/displacement_vertex", 3, True),
    "velocity": ("/vertex_fields/velocity_vertex", 3, True),
    "inertial_position": ("/vertex_fields/inertial_position_vertex", 3, True),
    "stress": ("/cell_fields/stress_cell", 6, False),
    "von_mises": ("/cell_fields/von_mises_scalar", 1, False),
    "mode_shape": ("/vertex_fields/mode_shape_vertex", 3, True),
}


def verdict(name, diff, scale, rtol, what):
    ok = diff <= rtol * scale
    print(f"  {name}: observed max |difference| {diff:.3e}, max |{what}| {scale:.3e}", file=sys.stderr)
    tol = "the same doubles" if rtol == 0 else f"max difference <= {rtol:.0e} of max |{what}|"
    print(f"field {name}: {'PASS' if ok else 'FAIL'} ({tol})")
    return ok


def compare(args):
    a_v, a_c = mesh_keys(args.a)
    b_v, b_c = mesh_keys(args.b)
    if sorted(a_v) != sorted(b_v) or sorted(a_c) != sorted(b_c):
        fail(f"{args.a} and {args.b} are not on the same mesh")
    ok = True
    for name in args.fields.split(","):
        if name not in FIELDS:
            fail(f"unknown field {name} (known: {', '.join(FIELDS)})")
        ds, nc, vertex = FIELDS[name]
        ra = step_rows(args.a, ds, args.step, nc)
        rb = step_rows(args.b, ds, args.step, nc)
        ka, kb = (a_v, b_v) if vertex else (a_c, b_c)
        index_b = {k: i for i, k in enumerate(kb)}
        best = None
        for sign in ([1.0, -1.0] if args.up_to_sign else [1.0]):
            diff = scale = 0.0
            for i, k in enumerate(ka):
                for c in range(nc):
                    x, y = ra[i][c], sign * rb[index_b[k]][c]
                    diff = max(diff, abs(x - y))
                    scale = max(scale, abs(y))
            if best is None or diff < best[0]:
                best = (diff, scale)
        ok = verdict(name, best[0], best[1], args.rtol, "B") and ok
    return ok


def xdmf_times(h5path):
    xmf = os.path.splitext(h5path)[0] + ".xmf"
    try:
        with open(xmf, encoding="utf-8") as fh:
            return [float(t) for t in re.findall(r'<Time Value="([^"]+)"', fh.read())]
    except OSError as err:
        fail(f"cannot read {xmf}: {err}")


def modal(args):
    times = xdmf_times(args.fields)
    k = args.step if args.step >= 0 else len(times) + args.step
    t = times[k]
    with open(args.modal, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    row = min(rows, key=lambda r: abs(float(r["time"]) - t))
    if abs(float(row["time"]) - t) > 1e-9 * max(1.0, abs(t)):
        fail(f"{args.modal} has no row at the fields' time {t}")
    m = sum(1 for key in row if re.fullmatch(r"eta\d+", key))
    eta = [float(row[f"eta{j + 1}"]) for j in range(m)]
    zeta = [float(row[f"zeta{j + 1}"]) for j in range(m)]
    phi = [h5read(args.reduced, f"/reduced/basis/phi_{j + 1}")[1] for j in range(m)]
    psi = [h5read(args.reduced, f"/reduced/basis/psi_{j + 1}")[1] for j in range(m)]
    u = step_rows(args.fields, FIELDS["displacement"][0], args.step, 3)
    v = step_rows(args.fields, FIELDS["velocity"][0], args.step, 3)
    s = step_rows(args.fields, FIELDS["stress"][0], args.step, 6)
    # the vertices with unknowns: all but those zero at every step (the frame patch)
    shape, allu = h5read(args.fields, FIELDS["displacement"][0])
    nsteps, nvert = shape[0], shape[1]
    held = [all(allu[3 * (st * nvert + i) + c] == 0.0 for st in range(nsteps) for c in range(3)) for i in range(nvert)]
    free = [i for i in range(nvert) if not held[i]]
    if 3 * len(free) != len(phi[0]):
        fail(f"{len(free)} vertices move, the basis has {len(phi[0])} velocity unknowns: not one process with P1 velocity?")
    if 6 * len(s) != len(psi[0]):
        fail(f"{len(s)} cells, the stress modes have {len(psi[0])} unknowns: not P1 velocity (P0 stress)?")

    def field(coef, basis, i):
        return sum(coef[j] * basis[j][i] for j in range(m))

    ok = True
    for name, rows, coef in (("displacement", u, eta), ("velocity", v, zeta)):
        diff = scale = 0.0
        for n, i in enumerate(free):
            for c in range(3):
                x = field(coef, phi, 3 * n + c)
                diff = max(diff, abs(rows[i][c] - x))
                scale = max(scale, abs(x))
        for i in range(nvert):
            if held[i]:
                diff = max(diff, max(abs(x) for x in rows[i]))
        ok = verdict(name, diff, scale, args.rtol, "Phi " + ("eta" if coef is eta else "zeta")) and ok
    # the stress modes in Voigt order xx yy zz yz xz xy, the file's 6-component arrays in xx yy zz xy yz xz
    order = (0, 1, 2, 5, 3, 4)
    diff = scale = 0.0
    for i, row in enumerate(s):
        for c in range(6):
            x = field(eta, psi, 6 * i + order[c])
            diff = max(diff, abs(row[c] - x))
            scale = max(scale, abs(x))
    ok = verdict("stress", diff, scale, args.rtol, "Psi eta") and ok
    return ok


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    c.add_argument("--fields", default="displacement,stress")
    c.add_argument("--step", type=int, default=-1)
    c.add_argument("--rtol", type=float, default=0.0)
    c.add_argument("--up-to-sign", action="store_true", help="A against B or -B, the closer (mode shapes)")
    md = sub.add_parser("modal")
    md.add_argument("fields")
    md.add_argument("modal")
    md.add_argument("reduced")
    md.add_argument("--step", type=int, default=-1)
    md.add_argument("--rtol", type=float, default=1e-10)
    args = p.parse_args()
    ok = compare(args) if args.cmd == "compare" else modal(args)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
