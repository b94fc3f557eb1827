#!/usr/bin/env python3
"""Generate phlex's deliberately bad mesh inputs (meshes/bad_*.msh).

Each file is a reader/validation test case for which phlex must stop with a clear
error message.  Everything is deterministic: the same inputs give byte-identical
outputs.  Called from meshes/Makefile; standard library only.

  bad_2d.msh            2D triangle mesh (highest dimension 2), from meshes/bad_2d.geo
  bad_hex.msh           hexahedral bar (transfinite + Recombine), from meshes/bad_hex.geo
  bad_prism.msh         the bar in prisms (a triangulated end face extruded in 4 layers), from meshes/bad_prism.geo
  bad_physical_names.msh  a msh 4.1 header whose $PhysicalNames entry has no quoted name (the reader stops there)
  bad_inverted.msh      bar_h0.05.msh with the last two nodes of one tetrahedron swapped
  bad_degenerate.msh    hand-made msh 4.1 cube of 6 tets + 1 zero-volume (flat) tet
  bad_empty_group.msh   bar_h0.05.msh plus $PhysicalNames entry 2 9 "empty" (no elements)
  bad_not_a_mesh.msh    a few lines of prose
  bad_truncated.msh     bar_h0.05.msh cut halfway through its $Elements section
  stress_sliver.msh     bar_h0.05.msh with five interior nodes moved so that five tetrahedra become slivers
                        (flatness 1e-3; legal input, a stress test of poorly shaped elements)

Usage:
  tools/make_bad_meshes.py [--meshdir DIR] [--gmsh GMSH] [NAME ...]

NAME is e.g. bad_inverted or bad_inverted.msh; without names, all files are made.
Information about what was changed is printed as '#' comments on stdout only.
"""

import argparse
import os
import subprocess
import sys

SOURCE = "bar_h0.05.msh"  # the good mesh the edited variants derive from (msh 4.1 ASCII)


# ---------------------------------------------------------------------------------------
# helpers


def write_file(path, text):
    """Write text atomically ('\n' line ends), so make never sees a half-written file."""
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="ascii", newline="\n") as f:
        f.write(text)
    os.replace(tmp, path)


def read_lines(path):
    with open(path, "r", encoding="ascii", newline="\n") as f:
        text = f.read()
    if not text.startswith("$MeshFormat\n4.1 0 "):
        sys.exit("make_bad_meshes: %s is not a msh 4.1 ASCII file" % path)
    return text.split("\n")  # last item is '' (file ends with a newline)


def section(lines, name):
    """Index of the '$name' line and of the '$Endname' line."""
    try:
        begin = lines.index("$" + name)
        end = lines.index("$End" + name, begin)
    except ValueError:
        sys.exit("make_bad_meshes: no $%s section" % name)
    return begin, end


def signed_volume(p0, p1, p2, p3):
    u = [p1[k] - p0[k] for k in range(3)]
    v = [p2[k] - p0[k] for k in range(3)]
    w = [p3[k] - p0[k] for k in range(3)]
    det = (u[0] * (v[1] * w[2] - v[2] * w[1])
           - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]))
    return det / 6.0


def read_nodes(lines):
    """Node coordinates of a msh 4.1 ASCII file: {tag: (x, y, z)}."""
    begin, end = section(lines, "Nodes")
    num_blocks = int(lines[begin + 1].split()[0])
    nodes = {}
    i = begin + 2
    for _ in range(num_blocks):
        _dim, _tag, parametric, count = map(int, lines[i].split())
        if parametric:
            sys.exit("make_bad_meshes: parametric nodes are not supported")
        tags = [int(lines[i + 1 + k]) for k in range(count)]
        for k, tag in enumerate(tags):
            nodes[tag] = tuple(float(x) for x in lines[i + 1 + count + k].split())
        i += 1 + 2 * count
    assert i == end, "malformed $Nodes section"
    return nodes


def tetrahedra(lines):
    """(line index, element tag, node tags) of every 4-node tetrahedron (type 4)."""
    begin, end = section(lines, "Elements")
    num_blocks = int(lines[begin + 1].split()[0])
    tets = []
    i = begin + 2
    for _ in range(num_blocks):
        _dim, _tag, etype, count = map(int, lines[i].split())
        for k in range(count):
            if etype == 4:
                fields = [int(x) for x in lines[i + 1 + k].split()]
                tets.append((i + 1 + k, fields[0], fields[1:]))
        i += 1 + count
    assert i == end, "malformed $Elements section"
    return tets


def run_gmsh(gmsh, meshdir, geo, dim, params, out):
    cmd = [gmsh, geo, "-%d" % dim]
    for name, value in params:
        cmd += ["-setnumber", name, str(value)]
    cmd += ["-format", "msh41", "-v", "2", "-o", out + ".tmp"]
    print("# " + " ".join(cmd))
    subprocess.run(cmd, cwd=meshdir, check=True)
    os.replace(os.path.join(meshdir, out + ".tmp"), os.path.join(meshdir, out))


# ---------------------------------------------------------------------------------------
# the bad meshes


def make_bad_2d(meshdir, gmsh):
    run_gmsh(gmsh, meshdir, "bad_2d.geo", 2, [("h", 0.05)], "bad_2d.msh")


def make_bad_hex(meshdir, gmsh):
    run_gmsh(gmsh, meshdir, "bad_hex.geo", 3, [("nx", 10), ("n", 2)], "bad_hex.msh")


def make_bad_prism(meshdir, gmsh):
    run_gmsh(gmsh, meshdir, "bad_prism.geo", 3, [], "bad_prism.msh")


def make_bad_physical_names(meshdir, gmsh):
    text = ("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"clamp\"\n3 1 bar\n"
            "$EndPhysicalNames\n")
    write_file(os.path.join(meshdir, "bad_physical_names.msh"), text)
    print("# bad_physical_names.msh: $PhysicalNames entry '3 1 bar' without quotes")


def make_bad_inverted(meshdir, gmsh):
    lines = read_lines(os.path.join(meshdir, SOURCE))
    nodes = read_nodes(lines)
    tets = tetrahedra(lines)
    # Deterministic choice: the tetrahedron whose centroid is nearest the bar's centre.
    centre = (0.5, 0.0, 0.0)

    def key(tet):
        c = [sum(nodes[n][k] for n in tet[2]) / 4.0 for k in range(3)]
        return (sum((c[k] - centre[k]) ** 2 for k in range(3)), tet[1])

    index, tag, conn = min(tets, key=key)
    before = signed_volume(*(nodes[n] for n in conn))
    swapped = conn[:2] + [conn[3], conn[2]]
    after = signed_volume(*(nodes[n] for n in swapped))
    others = [signed_volume(*(nodes[n] for n in t[2])) for t in tets if t[1] != tag]
    assert before > 0 and after < 0 and all(v > 0 for v in others), "unexpected orientation"
    lines[index] = " ".join(str(x) for x in [tag] + swapped) + " "  # gmsh's own line format
    write_file(os.path.join(meshdir, "bad_inverted.msh"), "\n".join(lines))
    print("# bad_inverted.msh: element %d nodes %s -> %s (last two swapped), "
          "signed volume %.6g -> %.6g; the other %d tets are positive"
          % (tag, " ".join(map(str, conn)), " ".join(map(str, swapped)), before, after,
             len(others)))


def make_bad_degenerate(meshdir, gmsh):
    """A 0.1 m cube slice of the bar, x in [0, 0.1], y, z in [-0.05, 0.05]: 6 tetrahedra
    (Kuhn split along the diagonal v000-v111) plus one flat tetrahedron made of the four
    coplanar corners of the face x = 0.1.  The flat tet shares the two triangles of that
    face with the cube's tets, so the mesh is topologically valid (each face in at most
    two cells); its two other faces, also in the plane x = 0.1, become the "tip"."""
    a = 0.1
    coords = {}
    tag_of = {}
    for k in range(2):
        for j in range(2):
            for i in range(2):
                t = len(coords) + 1
                tag_of[(i, j, k)] = t
                coords[t] = (i * a, j * a - a / 2, k * a - a / 2)

    def v(i, j, k):
        return tag_of[(i, j, k)]

    tets = []
    for order in [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
        p = [0, 0, 0]
        path = [v(*p)]
        for axis in order:
            p[axis] = 1
            path.append(v(*p))
        if signed_volume(*(coords[n] for n in path)) < 0:
            path[2], path[3] = path[3], path[2]
        tets.append(path)
    flat = [v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)]
    assert signed_volume(*(coords[n] for n in flat)) == 0.0
    tets.append(flat)

    # Boundary triangles: faces in exactly one cell, grouped by plane, oriented outward.
    count = {}
    for t in tets:
        for f in ([t[0], t[1], t[2]], [t[0], t[1], t[3]], [t[0], t[2], t[3]], [t[1], t[2], t[3]]):
            key = tuple(sorted(f))
            count[key] = count.get(key, 0) + 1
    groups = {1: [], 2: [], 3: []}  # clamp, tip, lateral
    for f in sorted(k for k, c in count.items() if c == 1):
        p = [coords[n] for n in f]
        normal = None
        for axis in range(3):
            vals = [q[axis] for q in p]
            if max(vals) == min(vals):
                lo = 0.0 if axis == 0 else -a / 2
                normal = [0.0, 0.0, 0.0]
                normal[axis] = -1.0 if vals[0] == lo else 1.0
                surf = 3 if axis else (1 if vals[0] == 0.0 else 2)
        assert normal is not None
        u = [p[1][k] - p[0][k] for k in range(3)]
        w = [p[2][k] - p[0][k] for k in range(3)]
        cross = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        f = list(f)
        if sum(cross[k] * normal[k] for k in range(3)) < 0:
            f[1], f[2] = f[2], f[1]
        groups[surf].append(f)
    assert [len(groups[s]) for s in (1, 2, 3)] == [2, 2, 8]

    def num(x):
        return format(x, ".16g")

    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat",
           "$PhysicalNames", "4",
           '2 1 "clamp"', '2 2 "tip"', '2 3 "lateral"', '3 1 "bar"',
           "$EndPhysicalNames",
           "$Entities", "0 0 3 1"]
    boxes = {1: (0, -a / 2, -a / 2, 0, a / 2, a / 2),
             2: (a, -a / 2, -a / 2, a, a / 2, a / 2),
             3: (0, -a / 2, -a / 2, a, a / 2, a / 2)}
    for s in (1, 2, 3):
        out.append("%d %s 1 %d 0 " % (s, " ".join(num(x) for x in boxes[s]), s))
    out.append("1 %s 1 1 3 -1 2 3 " % " ".join(num(x) for x in boxes[3]))
    out += ["$EndEntities", "$Nodes", "1 8 1 8", "3 1 0 8"]
    out += [str(t) for t in sorted(coords)]
    out += [" ".join(num(x) for x in coords[t]) for t in sorted(coords)]
    out += ["$EndNodes", "$Elements"]
    num_tri = sum(len(g) for g in groups.values())
    total = num_tri + len(tets)
    out.append("4 %d 1 %d" % (total, total))
    elem = 1
    for s in (1, 2, 3):
        out.append("2 %d 2 %d" % (s, len(groups[s])))
        for f in groups[s]:
            out.append("%d %s " % (elem, " ".join(map(str, f))))
            elem += 1
    out.append("3 1 4 %d" % len(tets))
    for t in tets:
        out.append("%d %s " % (elem, " ".join(map(str, t))))
        elem += 1
    out.append("$EndElements")
    write_file(os.path.join(meshdir, "bad_degenerate.msh"), "\n".join(out) + "\n")
    print("# bad_degenerate.msh: 8 nodes, 7 tets; element %d (nodes %s, the corners of the "
          "face x = 0.1) has zero volume" % (elem - 1, " ".join(map(str, flat))))


def make_bad_empty_group(meshdir, gmsh):
    lines = read_lines(os.path.join(meshdir, SOURCE))
    begin, end = section(lines, "PhysicalNames")
    entries = lines[begin + 2:end]
    assert int(lines[begin + 1]) == len(entries)
    assert not any(e.split()[:2] == ["2", "9"] for e in entries)
    # Keep gmsh's ordering (by dimension, then tag): after the last 2D entry.
    pos = begin + 2 + max(k for k, e in enumerate(entries) if int(e.split()[0]) <= 2) + 1
    lines.insert(pos, '2 9 "empty"')
    lines[begin + 1] = str(len(entries) + 1)
    write_file(os.path.join(meshdir, "bad_empty_group.msh"), "\n".join(lines))
    print('# bad_empty_group.msh: %s plus $PhysicalNames entry 2 9 "empty" (%d names)'
          % (SOURCE, len(entries) + 1))


def make_bad_not_a_mesh(meshdir, gmsh):
    text = ("This is not a gmsh mesh.\n"
            "It is a few lines of prose in a file whose name ends in .msh, so that phlex's\n"
            "mesh reader can be tested on input that has no $MeshFormat section at all.\n"
            "The reader must fail with a clear message naming this file.\n")
    write_file(os.path.join(meshdir, "bad_not_a_mesh.msh"), text)
    print("# bad_not_a_mesh.msh: %d lines of prose" % text.count("\n"))


def make_bad_truncated(meshdir, gmsh):
    lines = read_lines(os.path.join(meshdir, SOURCE))
    begin, end = section(lines, "Elements")
    cut = (begin + end) // 2  # keep lines[:cut]: ends halfway through the element lines
    write_file(os.path.join(meshdir, "bad_truncated.msh"), "\n".join(lines[:cut]) + "\n")
    print("# bad_truncated.msh: %s cut after line %d of %d ($Elements is lines %d-%d)"
          % (SOURCE, cut, len(lines) - 1, begin + 1, end + 1))


def interior_nodes(lines):
    """Tags of the nodes of volume entities (dim 3): moving them keeps the boundary."""
    begin, end = section(lines, "Nodes")
    num_blocks = int(lines[begin + 1].split()[0])
    tags = set()
    i = begin + 2
    for _ in range(num_blocks):
        dim, _tag, _parametric, count = map(int, lines[i].split())
        if dim == 3:
            tags.update(int(lines[i + 1 + k]) for k in range(count))
        i += 1 + 2 * count
    return tags


def flatness(p):
    """Smallest altitude over shortest edge, 1 for the regular tetrahedron (phlex warns below 0.02)."""
    def area(a, b, c):
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        cr = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        return 0.5 * sum(x * x for x in cr) ** 0.5
    faces = [area(p[1], p[2], p[3]), area(p[0], p[2], p[3]), area(p[0], p[1], p[3]), area(p[0], p[1], p[2])]
    hmin = min(sum((p[i][k] - p[j][k]) ** 2 for k in range(3)) ** 0.5 for i in range(4) for j in range(i + 1, 4))
    return 3 * abs(signed_volume(*p)) / max(faces) / (hmin * (2.0 / 3.0) ** 0.5)


def make_stress_sliver(meshdir, gmsh, target=1e-3, count=5):
    lines = read_lines(os.path.join(meshdir, SOURCE))
    nodes = read_nodes(lines)
    tets = tetrahedra(lines)
    lo_box = [min(p[k] for p in nodes.values()) for k in range(3)]
    hi_box = [max(p[k] for p in nodes.values()) for k in range(3)]
    around = {}
    for t in tets:
        for n in t[2]:
            around.setdefault(n, []).append(t)
    moved, used = [], set()
    for node in sorted(around):
        if len(moved) == count or node in used:
            continue
        p = nodes[node]
        # a node on a face of the box stays on it: it moves only along the face
        fixed = [k for k in range(3) if p[k] in (lo_box[k], hi_box[k])]
        for t in sorted(around[node], key=lambda t: t[1]):
            # move the node towards the plane of its opposite face, until that tet's flatness is the target
            others = [nodes[n] for n in t[2] if n != node]
            u = [others[1][k] - others[0][k] for k in range(3)]
            v = [others[2][k] - others[0][k] for k in range(3)]
            nrm = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            ln = sum(x * x for x in nrm) ** 0.5
            nrm = [x / ln for x in nrm]
            h = sum((p[k] - others[0][k]) * nrm[k] for k in range(3))  # signed height over the plane
            d = [0.0 if k in fixed else -h * nrm[k] for k in range(3)]  # towards the plane, along the faces
            rate = -sum(d[k] * nrm[k] for k in range(3)) / h if h else 0.0  # share of the height removed per unit step
            if rate < 0.3:
                continue
            reach = min(1.0 / rate, 1.0 / (rate + 1e-300) * 0.999)
            a, b = 0.0, reach
            for _ in range(60):  # bisection on the step
                f = 0.5 * (a + b)
                q = [p[k] + f * d[k] for k in range(3)]
                pts = [q if n == node else nodes[n] for n in t[2]]
                a, b = (f, b) if flatness(pts) > target else (a, f)
            q = tuple(p[k] + a * d[k] for k in range(3))
            trial = dict(nodes)
            trial[node] = q
            ok = flatness([trial[n] for n in t[2]]) < 1.5 * target
            ok = ok and all(signed_volume(*(trial[n] for n in s[2])) > 0 for s in around[node])
            ok = ok and all(flatness([trial[n] for n in s[2]]) > 0.02 for s in around[node] if s[1] != t[1])
            if ok:
                nodes[node] = q
                moved.append((node, t[1], flatness([q if n == node else nodes[n] for n in t[2]])))
                used.update(n for s in around[node] for n in s[2])
                break
    assert len(moved) == count, "found %d slivers" % len(moved)
    # rewrite the moved nodes' coordinate lines
    begin, end = section(lines, "Nodes")
    num_blocks = int(lines[begin + 1].split()[0])
    i = begin + 2
    for _ in range(num_blocks):
        _dim, _tag, _parametric, n = map(int, lines[i].split())
        tags = [int(lines[i + 1 + k]) for k in range(n)]
        for k, tag in enumerate(tags):
            if tag in {m[0] for m in moved}:
                lines[i + 1 + n + k] = " ".join("%.17g" % x for x in nodes[tag])
        i += 1 + 2 * n
    write_file(os.path.join(meshdir, "stress_sliver.msh"), "\n".join(lines))
    for node, tag, q in moved:
        print("# stress_sliver.msh: node %d moved, element %d flatness %.3g" % (node, tag, q))


MAKERS = {
    "bad_2d": make_bad_2d,
    "bad_hex": make_bad_hex,
    "bad_prism": make_bad_prism,
    "bad_physical_names": make_bad_physical_names,
    "bad_inverted": make_bad_inverted,
    "bad_degenerate": make_bad_degenerate,
    "bad_empty_group": make_bad_empty_group,
    "bad_not_a_mesh": make_bad_not_a_mesh,
    "bad_truncated": make_bad_truncated,
    "stress_sliver": make_stress_sliver,
}


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--meshdir", default=os.path.join(here, os.pardir, "meshes"),
                        help="directory with the .geo files and %s (default: meshes/)" % SOURCE)
    parser.add_argument("--gmsh", default=os.environ.get("GMSH", "gmsh"),
                        help="gmsh executable (default: $GMSH or gmsh)")
    parser.add_argument("names", nargs="*", help="files to make (default: all)")
    args = parser.parse_args()
    names = [n[:-4] if n.endswith(".msh") else n for n in args.names] or list(MAKERS)
    for n in names:
        if n not in MAKERS:
            parser.error("unknown bad mesh '%s' (known: %s)" % (n, ", ".join(MAKERS)))
    for n in names:
        MAKERS[n](os.path.normpath(args.meshdir), args.gmsh)


if __name__ == "__main__":
    main()
