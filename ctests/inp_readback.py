#!/usr/bin/env python3
"""meshio (PyPI), an independent reader, on the Abaqus .inp that `slivermesh mesh` writes: the
same node and element counts as the medit .mesh of the same run, one element set per region
with that region's tets, and one surface per boundary marker.

    inp_readback.py --slivermesh BIN --input MODEL [--size H] [--approximate] --workdir DIR

Prints what it compares; exits 1 on a mismatch ("FAIL: ..."), 0 otherwise.
"""
import argparse
import collections
import subprocess
import sys
from pathlib import Path

import meshio


def read_medit(path):
    """Vertex count, tet regions and triangle markers of a medit .mesh (our own writer's)."""
    words = Path(path).read_text().split()
    i = words.index("Vertices")
    n_vertices = int(words[i + 1])
    j = words.index("Tetrahedra")
    n_tets = int(words[j + 1])
    regions = [int(words[j + 2 + 5 * k + 4]) for k in range(n_tets)]
    k = words.index("Triangles")
    n_tris = int(words[k + 1])
    markers = [int(words[k + 2 + 4 * m + 3]) for m in range(n_tris)]
    return n_vertices, regions, markers


def set_name(prefix, value):
    return f"{prefix}_M{-value}" if value < 0 else f"{prefix}_{value}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--input", required=True)
    ap.add_argument("--size")
    ap.add_argument("--approximate", action="store_true", help="--surface approximate")
    ap.add_argument("--workdir", required=True)
    a = ap.parse_args()
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    stem = Path(a.input).stem
    extra = (["--size", a.size] if a.size else []) + (
        ["--surface", "approximate"] if a.approximate else [])
    outs = {}
    for ext in ["inp", "mesh"]:
        out = work / f"{stem}.{ext}"
        subprocess.run([a.slivermesh, "mesh", a.input, "-o", str(out)] + extra, check=True,
                       stdout=subprocess.DEVNULL)
        outs[ext] = out
    n_vertices, regions, markers = read_medit(outs["mesh"])
    m = meshio.read(outs["inp"])
    tets = sum(len(c.data) for c in m.cells if c.type == "tetra")
    print(f"{stem}: .mesh {n_vertices} vertices, {len(regions)} tets, {len(markers)} "
          f"triangles; .inp via meshio {meshio.__version__}: {len(m.points)} points, {tets} tetra")
    failures = []
    if len(m.points) != n_vertices:
        failures.append(f"points {len(m.points)} != {n_vertices}")
    if tets != len(regions):
        failures.append(f"tetra {tets} != {len(regions)}")
    want = collections.Counter(regions)
    for r, count in sorted(want.items()):
        name = set_name("REGION", r)
        got = sum(len(ids) for ids in m.cell_sets.get(name, []))
        print(f"  element set {name}: {got} (want {count})")
        if got != count:
            failures.append(f"element set {name} has {got} tets, want {count}")
    text = outs["inp"].read_text()
    for mk, count in sorted(collections.Counter(markers).items()):
        name = set_name("MARKER", mk)
        parts = text.split(f"*SURFACE, TYPE=ELEMENT, NAME={name}\n")
        got = len(parts[1].split("*", 1)[0].strip().splitlines()) if len(parts) == 2 else 0
        print(f"  surface {name}: {got} faces (want {count})")
        if got != count:
            failures.append(f"surface {name} has {got} faces, want {count}")
    for f in failures:
        print(f"FAIL: {f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
