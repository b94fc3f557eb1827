#!/usr/bin/env python3
"""The P1 unknowns of a first-order gmsh 4.1 ASCII mesh with one face group clamped, counted from the file alone
(independently of phlex): 3 x (the mesh's nodes - the nodes on the clamped physical surface).

    mesh_vertices.py MESH.msh --clamped clamp

Prints "P1 unknowns: N (V vertices, C on <group>)". Exit status 2 on a file it cannot read."""
import argparse
import sys


def sections(lines):
    out, name, body = {}, None, []
    for line in lines:
        s = line.strip()
        if s.startswith("$End"):
            out[name] = body
            name, body = None, []
        elif s.startswith("$"):
            name, body = s[1:], []
        elif name:
            body.append(s)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh")
    ap.add_argument("--clamped", required=True, help="the physical surface whose nodes are constrained")
    a = ap.parse_args()
    try:
        with open(a.mesh) as f:
            sec = sections(f)
    except OSError as e:
        sys.exit("mesh_vertices.py: cannot read %s: %s" % (a.mesh, e.strerror))
    if not sec.get("MeshFormat") or not sec["MeshFormat"][0].startswith("4.1 0"):
        sys.exit("mesh_vertices.py: %s is not a gmsh 4.1 ASCII mesh" % a.mesh)
    tag = None
    for line in sec["PhysicalNames"][1:]:
        dim, t, name = line.split(None, 2)
        if dim == "2" and name.strip('"') == a.clamped:
            tag = int(t)
    if tag is None:
        sys.exit("mesh_vertices.py: %s has no physical surface %s" % (a.mesh, a.clamped))
    # the surface entities carrying the physical tag
    ent = sec["Entities"]
    np_, nc, ns, nv = (int(x) for x in ent[0].split())
    surfaces = set()
    for line in ent[1 + np_ + nc:1 + np_ + nc + ns]:
        f = line.split()
        nphys = int(f[7])
        if tag in (int(x) for x in f[8:8 + nphys]):
            surfaces.add(int(f[0]))
    # the surface elements of those entities: their nodes
    el = sec["Elements"]
    nblocks = int(el[0].split()[0])
    i, clamped = 1, set()
    for _ in range(nblocks):
        edim, etag, etype, n = (int(x) for x in el[i].split())
        if edim == 2 and etag in surfaces:
            for line in el[i + 1:i + 1 + n]:
                clamped.update(int(x) for x in line.split()[1:])
        i += 1 + n
    nodes = sec["Nodes"]
    vertices = int(nodes[0].split()[1])
    print("P1 unknowns: %d (%d vertices, %d on %s)" % (3 * (vertices - len(clamped)), vertices, len(clamped), a.clamped))


if __name__ == "__main__":
    main()
