#!/usr/bin/env python3
"""Writes a gmsh 2.2 ASCII mesh with its nodes in reverse order (renumbered 1..n, the elements' node lists mapped):
the same mesh, another numbering of its points. Used by the restart tests: a checkpoint of one numbering must not be
read into the other.

    python3 tests/tools/permute_msh2.py IN.msh OUT.msh
"""
import sys


def main(src, dst):
    lines = open(src).read().splitlines()
    if lines[0] != "$MeshFormat" or not lines[1].startswith("2.2 0 "):
        sys.exit(f"{src}: not a gmsh 2.2 ASCII mesh")
    i = lines.index("$Nodes")
    n = int(lines[i + 1])
    nodes = [ln.split(maxsplit=1) for ln in lines[i + 2:i + 2 + n]]
    newid = {old: str(n - k) for k, (old, _) in enumerate(nodes)}  # reversed
    out = lines[:i + 2] + [f"{newid[old]} {xyz}" for old, xyz in reversed(nodes)] + lines[i + 2 + n:]
    j = out.index("$Elements")
    m = int(out[j + 1])
    for k in range(j + 2, j + 2 + m):
        f = out[k].split()
        ntags = int(f[2])
        head, conn = f[:3 + ntags], f[3 + ntags:]
        out[k] = " ".join(head + [newid[c] for c in conn])
    open(dst, "w").write("\n".join(out) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
