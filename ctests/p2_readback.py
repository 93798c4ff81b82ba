#!/usr/bin/env python3
"""Independent readers on the ten-node (quadratic) tet files slivermesh writes: meshio (PyPI) on
the gmsh .msh (ASCII and binary), .vtu (ASCII and binary appended) and Abaqus .inp, and the
gmsh Python module (if importable) on the .msh files and the MEDIT .mesh. For each reader and
file: the node count, the number of 10-node tets (and 6-node boundary triangles where the format
has them), every mid-edge node at the midpoint of the two corners the reader's own node order
names (the files hold straight-sided elements, so this catches a node-order mistake), positive
corner orientation, and with gmsh a positive minimum scaled Jacobian (minSJ) of every tet and the
physical groups (one per region, one per boundary marker). With `tetgen` on PATH, TetGen's own
-o2 node order is read off `tetgen -o2` on one tet and the p2.node/.ele/.face files are checked
against it.

    p2_readback.py DIR
    p2_readback.py --writer P2_SAMPLE --workdir DIR [--slivermesh BIN --input MODEL [--size H]]

DIR holds the files of examples/p2_sample.rs (ascii.msh, binary.msh, ascii.vtu, binary.vtu,
p2.mesh, p2.inp) and its counts.json. The second form runs P2_SAMPLE (the example's binary) to
write them, on the mesh `slivermesh mesh MODEL` makes when --slivermesh is given, else on the
example's own block. Prints what it checks; exits 1 on a mismatch ("FAIL: ..."), 0 otherwise.
"""
import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import meshio
import numpy as np

# meshio's tetra10 (VTK's order): corners, then edges 01, 12, 02, 03, 13, 23.
MESHIO_TET10 = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]
# Gmsh's own tet10 (type 11), as its API returns it: corners, then 01, 12, 20, 30, 32, 31.
GMSH_TET10 = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)]
# Six-node triangles in both.
TRI6 = [(0, 1), (1, 2), (2, 0)]


def bad_midpoints(points, cells, edges):
    """Number of cells whose node 4+k (3+k for triangles) is not the midpoint of edges[k]."""
    cells = np.asarray(cells, dtype=np.int64)
    if len(cells) == 0:
        return 0
    first = cells.shape[1] - len(edges)
    scale = max(1.0, float(np.abs(points).max()))
    bad = np.zeros(len(cells), dtype=bool)
    for k, (i, j) in enumerate(edges):
        mid = 0.5 * (points[cells[:, i]] + points[cells[:, j]])
        bad |= np.abs(points[cells[:, first + k]] - mid).max(axis=1) > 1e-12 * scale
    return int(bad.sum())


def negative_corners(points, cells):
    c = np.asarray(cells, dtype=np.int64)
    a, b, cc, d = (points[c[:, k]] for k in range(4))
    det = np.einsum("ij,ij->i", np.cross(b - a, cc - a), d - a)
    return int((det <= 0).sum())


def check_meshio(path, counts, with_triangles, failures):
    m = meshio.read(path)
    tets = [c.data for c in m.cells if c.type == "tetra10"]
    tets = np.concatenate(tets) if tets else np.zeros((0, 10), dtype=np.int64)
    tris = [c.data for c in m.cells if c.type == "triangle6"]
    tris = np.concatenate(tris) if tris else np.zeros((0, 6), dtype=np.int64)
    others = sorted({c.type for c in m.cells} - {"tetra10", "triangle6"})
    bad = bad_midpoints(m.points, tets, MESHIO_TET10)
    bad_tri = bad_midpoints(m.points, tris, TRI6)
    neg = negative_corners(m.points, tets) if len(tets) else 0
    print(f"  meshio {meshio.__version__} {path.name}: {len(m.points)} points, {len(tets)} "
          f"tetra10, {len(tris)} triangle6, other cell types {others}; {bad} tets and "
          f"{bad_tri} triangles with a mid-edge node off its edge's midpoint, {neg} not "
          f"positively oriented")
    want_tris = counts["triangles"] if with_triangles else 0
    for what, got, want in [("points", len(m.points), counts["nodes"]),
                            ("tetra10", len(tets), counts["tets"]),
                            ("triangle6", len(tris), want_tris),
                            ("misplaced mid-edge nodes of tets", bad, 0),
                            ("misplaced mid-edge nodes of triangles", bad_tri, 0),
                            ("inverted tets", neg, 0),
                            ("other cell types", len(others), 0)]:
        if got != want:
            failures.append(f"{path.name} via meshio: {what} {got}, want {want}")


def check_gmsh(gmsh, path, counts, failures):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(str(path))
        tags, coords, _ = gmsh.model.mesh.getNodes()
        order = np.argsort(tags)
        tags = np.asarray(tags)[order]
        coords = np.asarray(coords).reshape(-1, 3)[order]
        index = {int(t): k for k, t in enumerate(tags)}
        got = {}
        for ty, etags, enodes in zip(*gmsh.model.mesh.getElements()):
            n = {11: 10, 9: 6}.get(int(ty))
            if n is None:
                got.setdefault("other", 0)
                got["other"] += len(etags)
                continue
            cells = np.array([index[int(v)] for v in enodes]).reshape(-1, n)
            got.setdefault(int(ty), []).append((list(etags), cells))
        tet_tags = [t for tags_, _ in got.get(11, []) for t in tags_]
        tets = (np.concatenate([c for _, c in got[11]]) if 11 in got
                else np.zeros((0, 10), dtype=np.int64))
        tris = (np.concatenate([c for _, c in got[9]]) if 9 in got
                else np.zeros((0, 6), dtype=np.int64))
        bad = bad_midpoints(coords, tets, GMSH_TET10)
        bad_tri = bad_midpoints(coords, tris, TRI6)
        q = np.array(gmsh.model.mesh.getElementQualities(tet_tags, "minSJ")) if tet_tags else []
        min_sj = float(np.min(q)) if len(q) else float("nan")
        groups = gmsh.model.getPhysicalGroups()
        n3 = sum(1 for d, _ in groups if d == 3)
        n2 = sum(1 for d, _ in groups if d == 2)
        print(f"  gmsh {gmsh.__version__} {path.name}: {len(tags)} nodes, {len(tets)} type-11 "
              f"tets, {len(tris)} type-9 triangles, {got.get('other', 0)} other elements; "
              f"{bad} tets and {bad_tri} triangles with a mid-edge node off its midpoint; "
              f"minSJ min {min_sj:.4g}; physical groups: {n3} volume, {n2} surface")
        checks = [("nodes", len(tags), counts["nodes"]),
                  ("type-11 tets", len(tets), counts["tets"]),
                  ("type-9 triangles", len(tris), counts["triangles"]),
                  ("misplaced mid-edge nodes of tets", bad, 0),
                  ("misplaced mid-edge nodes of triangles", bad_tri, 0),
                  ("other elements", got.get("other", 0), 0)]
        if path.suffix == ".msh":
            checks += [("volume physical groups", n3, counts["regions"]),
                       ("surface physical groups", n2, counts["markers"])]
        for what, g, want in checks:
            if g != want:
                failures.append(f"{path.name} via gmsh: {what} {g}, want {want}")
        if not len(q) or not min_sj > 0:
            failures.append(f"{path.name} via gmsh: minSJ {min_sj} (every tet10 must be > 0)")
    finally:
        gmsh.finalize()


def read_tetgen(stem):
    """Points, tets and faces (0-based node lists) of TetGen .node/.ele/.face files."""
    def rows(ext):
        lines = Path(f"{stem}.{ext}").read_text().splitlines()
        return [l.split() for l in lines if l.strip() and not l.lstrip().startswith("#")]
    node = rows("node")
    base = int(node[1][0])
    points = np.array([[float(x) for x in r[1:4]] for r in node[1:]])
    ele = rows("ele")
    k = int(ele[0][1])
    tets = np.array([[int(x) - base for x in r[1:1 + k]] for r in ele[1:]])
    face = rows("face")
    faces = [[int(x) - base for x in r[1:-1]] for r in face[1:]]
    return points, tets, np.array(faces)


def tetgen_pairs(points, cells, n_corners):
    """The corner pair whose midpoint each extra node of the first cell is."""
    c = cells[0]
    out = []
    for e in c[n_corners:]:
        for i in range(n_corners):
            for j in range(i + 1, n_corners):
                if np.allclose(points[e], 0.5 * (points[c[i]] + points[c[j]])):
                    out.append((i, j))
    return out


def check_tetgen(exe, d, counts, failures):
    """TetGen's own -o2 order, read off `tetgen -o2` on one tet, and our p2.node/.ele/.face
    against it."""
    with tempfile.TemporaryDirectory() as tmp:
        stem = Path(tmp) / "one"
        stem.with_suffix(".node").write_text("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n")
        subprocess.run([exe, "-o2", "-f", "-z", "-Q", str(stem.with_suffix(".node"))],
                       check=True, stdout=subprocess.DEVNULL)
        pts, tets, faces = read_tetgen(Path(tmp) / "one.1")
        tet_order = [tuple(sorted(p)) for p in tetgen_pairs(pts, tets, 4)]
        face_order = [tuple(sorted(p)) for p in tetgen_pairs(pts, faces, 3)]
    print(f"  {exe} -o2 on one tet: extra tet nodes on edges {tet_order}, face nodes on "
          f"{face_order}")
    pts, tets, faces = read_tetgen(d / "p2")
    bad = bad_midpoints(pts, tets, tet_order)
    bad_tri = bad_midpoints(pts, faces, face_order)
    print(f"  p2.node/.ele/.face: {len(pts)} nodes, {len(tets)} tets of {tets.shape[1]} nodes, "
          f"{len(faces)} faces; {bad} tets and {bad_tri} faces off TetGen's order")
    for what, got, want in [("nodes", len(pts), counts["nodes"]),
                            ("tets", len(tets), counts["tets"]),
                            ("nodes per tet", tets.shape[1], 10),
                            ("faces", len(faces), counts["triangles"]),
                            ("tets off TetGen's -o2 order", bad, 0),
                            ("faces off TetGen's -o2 order", bad_tri, 0)]:
        if got != want:
            failures.append(f"p2.ele vs tetgen: {what} {got}, want {want}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir", nargs="?", help="a directory written by examples/p2_sample.rs")
    ap.add_argument("--writer", help="the p2_sample example's binary, run to write the files")
    ap.add_argument("--workdir", help="where --writer writes them")
    ap.add_argument("--slivermesh", help="mesh --input with this binary first")
    ap.add_argument("--input")
    ap.add_argument("--size")
    a = ap.parse_args()
    if a.writer:
        work = Path(a.workdir)
        work.mkdir(parents=True, exist_ok=True)
        cmd = [a.writer, str(work)]
        if a.slivermesh:
            linear = work / "linear.mesh"
            extra = ["--size", a.size] if a.size else []
            subprocess.run([a.slivermesh, "mesh", a.input, "-o", str(linear)] + extra,
                           check=True, stdout=subprocess.DEVNULL)
            cmd.append(str(linear))
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        d = work
    elif a.dir:
        d = Path(a.dir)
    else:
        ap.error("give DIR or --writer and --workdir")
    counts = json.loads((d / "counts.json").read_text())
    print(f"{d}: expecting {counts}")
    failures = []
    for name, tris in [("ascii.msh", True), ("binary.msh", True), ("ascii.vtu", False),
                       ("binary.vtu", False), ("p2.inp", False)]:
        try:
            check_meshio(d / name, counts, tris, failures)
        except Exception as e:  # a reader error is a failure of the file, reported as such
            failures.append(f"{name} via meshio: {type(e).__name__}: {e}")
    try:
        import gmsh
    except ImportError:
        gmsh = None
        print("  (no gmsh module: python3 -m pip install 'gmsh==4.15.*'; gmsh checks skipped)")
    if gmsh is not None:
        for name in ["ascii.msh", "binary.msh", "p2.mesh"]:
            try:
                check_gmsh(gmsh, d / name, counts, failures)
            except Exception as e:
                failures.append(f"{name} via gmsh: {type(e).__name__}: {e}")
    tetgen = shutil.which("tetgen")
    if tetgen:
        try:
            check_tetgen(tetgen, d, counts, failures)
        except Exception as e:
            failures.append(f"p2.ele vs tetgen: {type(e).__name__}: {e}")
    else:
        print("  (no tetgen on PATH: the TetGen -o2 order check is skipped)")
    for f in failures:
        print(f"FAIL: {f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
