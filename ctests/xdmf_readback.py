#!/usr/bin/env python3
"""The XDMF + HDF5 output of `slivermesh mesh -o X.xdmf` read back independently: the XML with
Python's ElementTree, the arrays with h5py, compared with the medit .mesh of the same run
(nodes, tets, region per tet, boundary triangles, marker per triangle), in the layout DOLFINx
reads (Grid "mesh" of Tetrahedron / XYZ, Grids "mesh_cells" and "mesh_facets" of tags, Int64
topology, Float64 geometry, Int32 values). Where `import dolfinx` works, DOLFINx's own
XDMFFile reads the mesh and both tags too; elsewhere that part is skipped with a message.

    xdmf_readback.py --slivermesh BIN --input MODEL [--size H] [--approximate] --workdir DIR
                     [--require]

Prints what it compares; exits 1 on a mismatch ("FAIL: ..."), 77 (ctest's SKIP_RETURN_CODE)
when h5py is missing or the binary was built without the `hdf5` feature (1 with --require),
0 otherwise.
"""
import argparse
import collections
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

SKIP = 77
XI = "{https://www.w3.org/2001/XInclude}include"


def read_medit(path):
    """Vertices, tets (0-based) with regions, triangles (0-based) with markers of a .mesh."""
    words = Path(path).read_text().split()

    def block(key, width):
        i = words.index(key)
        n = int(words[i + 1])
        return [words[i + 2 + width * k: i + 2 + width * (k + 1)] for k in range(n)]

    vertices = [tuple(float(w) for w in r[:3]) for r in block("Vertices", 4)]
    tets = [(tuple(int(w) - 1 for w in r[:4]), int(r[4])) for r in block("Tetrahedra", 5)]
    tris = [(tuple(int(w) - 1 for w in r[:3]), int(r[3])) for r in block("Triangles", 4)]
    return vertices, tets, tris


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--input", required=True)
    ap.add_argument("--size")
    ap.add_argument("--approximate", action="store_true", help="--surface approximate")
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--require", action="store_true",
                    help="fail instead of skipping without h5py or HDF5 support")
    a = ap.parse_args()
    skip = 1 if a.require else SKIP
    try:
        import h5py
        import numpy as np
    except ImportError as e:
        print(f"{'FAIL' if a.require else 'SKIP'}: h5py is not importable ({e}); "
              "pip install h5py")
        return skip
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    stem = Path(a.input).stem
    extra = (["--size", a.size] if a.size else []) + (
        ["--surface", "approximate"] if a.approximate else [])
    xdmf, h5, medit = (work / f"{stem}.{e}" for e in ["xdmf", "h5", "mesh"])
    for p in [xdmf, h5]:
        p.unlink(missing_ok=True)
    run = subprocess.run([a.slivermesh, "mesh", a.input, "-o", str(xdmf)] + extra,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if run.returncode != 0 and "built without HDF5 support" in run.stderr:
        print(f"{'FAIL' if a.require else 'SKIP'}: {a.slivermesh} was built without the hdf5 "
              f"feature:\n{run.stderr.strip()}")
        return skip
    if run.returncode != 0:
        print(run.stderr, end="")
        print(f"FAIL: slivermesh -o {xdmf.name} exited {run.returncode}")
        return 1
    subprocess.run([a.slivermesh, "mesh", a.input, "-o", str(medit)] + extra, check=True,
                   stdout=subprocess.DEVNULL)
    vertices, tets, tris = read_medit(medit)
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)
        return ok

    # --- the XML
    root = ET.parse(xdmf).getroot()
    check(root.tag == "Xdmf" and root.get("Version") == "3.0", "root is not <Xdmf Version=3.0>")
    domain = root.find("Domain")
    grids = {g.get("Name"): g for g in domain.findall("Grid")}
    print(f"{stem}: .mesh {len(vertices)} vertices, {len(tets)} tets, {len(tris)} triangles; "
          f".xdmf grids {sorted(grids)}")
    if not check(set(grids) == {"mesh", "mesh_cells", "mesh_facets"}, f"grids {sorted(grids)}"):
        for f in failures:
            print(f"FAIL: {f}")
        return 1

    def dataset(item, dtype, shape, what):
        """The array a DataItem names, checked for file name, type and shape."""
        file, _, at = item.text.strip().partition(":")
        check(file == h5.name, f"{what}: DataItem names file '{file}', want '{h5.name}'")
        dims = tuple(int(d) for d in item.get("Dimensions").split())
        check(item.get("Format") == "HDF", f"{what}: Format {item.get('Format')}")
        with h5py.File(h5, "r") as f:
            d = f[at]
            check(d.dtype == np.dtype(dtype), f"{what}: {at} has type {d.dtype}, want {dtype}")
            check(d.shape == dims == shape, f"{what}: {at} shape {d.shape}, Dimensions {dims}, "
                  f"want {shape}")
            print(f"  {what}: {at} {d.dtype} {d.shape}")
            return d[()]

    def topology(grid, kind, n, k, what):
        t = grid.find("Topology")
        check(t.get("TopologyType") == kind, f"{what}: TopologyType {t.get('TopologyType')}")
        check(t.get("NumberOfElements") == str(n) and t.get("NodesPerElement") == str(k),
              f"{what}: NumberOfElements {t.get('NumberOfElements')} NodesPerElement "
              f"{t.get('NodesPerElement')}, want {n} {k}")
        return dataset(t.find("DataItem"), "int64", (n, k), what)

    def values(grid, name, n):
        attr = grid.find("Attribute")
        check(attr.get("Name") == name and attr.get("Center") == "Cell",
              f"{name}: Attribute Name {attr.get('Name')} Center {attr.get('Center')}")
        return dataset(attr.find("DataItem"), "int32", (n, 1), f"{name} values")[:, 0]

    def geometry_ref(grid):
        inc = grid.find(XI)
        check(inc is not None and inc.get("xpointer")
              == "xpointer(/Xdmf/Domain/Grid[@Name='mesh']/Geometry)",
              f"{grid.get('Name')}: no xi:include of the mesh's Geometry")

    mesh = grids["mesh"]
    top = topology(mesh, "Tetrahedron", len(tets), 4, "mesh topology")
    g = mesh.find("Geometry")
    check(g.get("GeometryType") == "XYZ", f"GeometryType {g.get('GeometryType')}")
    x = dataset(g.find("DataItem"), "float64", (len(vertices), 3), "mesh geometry")
    check(np.array_equal(x, np.array(vertices)), "geometry differs from the .mesh vertices")
    check(np.array_equal(top, np.array([t for t, _ in tets])), "tets differ from the .mesh")

    cells = grids["mesh_cells"]
    geometry_ref(cells)
    ctop = topology(cells, "Tetrahedron", len(tets), 4, "mesh_cells topology")
    check(np.array_equal(ctop, top), "mesh_cells topology is not the mesh's")
    regions = values(cells, "mesh_cells", len(tets))
    check(list(regions) == [r for _, r in tets], "cell tags differ from the .mesh regions")
    want = collections.Counter(r for _, r in tets)
    print(f"  regions per tet: {dict(sorted(collections.Counter(regions.tolist()).items()))} "
          f"(want {dict(sorted(want.items()))})")
    check(len(want) > 1, f"the model should give several regions, got {sorted(want)}")

    facets = grids["mesh_facets"]
    geometry_ref(facets)
    ftop = topology(facets, "Triangle", len(tris), 3, "mesh_facets topology")
    check(np.array_equal(ftop, np.array([t for t, _ in tris])),
          "facet tag triangles differ from the .mesh triangles")
    markers = values(facets, "mesh_facets", len(tris))
    check(list(markers) == [m for _, m in tris], "facet tags differ from the .mesh markers")
    faces = {frozenset(f) for t, _ in tets for f in
             [(t[1], t[2], t[3]), (t[0], t[2], t[3]), (t[0], t[1], t[3]), (t[0], t[1], t[2])]}
    check(all(frozenset(f) in faces for f in ftop.tolist()),
          "a facet tag triangle is not a face of any tet")
    print(f"  markers per triangle: {dict(sorted(collections.Counter(markers.tolist()).items()))}")

    # --- DOLFINx itself, where it is installed
    try:
        from mpi4py import MPI
        import dolfinx.io
    except ImportError as e:
        print(f"SKIP (this part only): dolfinx is not importable ({e}); the layout checks above "
              "follow its reader (cpp/dolfinx/io/XDMFFile.cpp, xdmf_mesh.cpp)")
    else:
        with dolfinx.io.XDMFFile(MPI.COMM_WORLD, str(xdmf), "r") as f:
            msh = f.read_mesh(name="mesh")
            msh.topology.create_connectivity(2, 3)
            ct = f.read_meshtags(msh, name="mesh_cells")
            ft = f.read_meshtags(msh, name="mesh_facets")
        n_cells = msh.topology.index_map(3).size_global
        got_ct = collections.Counter(ct.values.tolist())
        got_ft = collections.Counter(ft.values.tolist())
        print(f"  dolfinx {dolfinx.__version__}: {n_cells} cells, cell tags "
              f"{dict(sorted(got_ct.items()))}, facet tags {dict(sorted(got_ft.items()))}")
        check(n_cells == len(tets), f"dolfinx reads {n_cells} cells, want {len(tets)}")
        check(got_ct == want, "dolfinx's cell tags differ")
        check(got_ft == collections.Counter(m for _, m in tris), "dolfinx's facet tags differ")

        # Tag by tag: DOLFINx renumbers cells, facets and nodes, so entities are matched by the
        # exact coordinates of their nodes.
        def by_points(rows):
            return {tuple(sorted(tuple(x[v]) for v in r)): tag for r, tag in rows}

        def dolfinx_tags(tags):
            import dolfinx.mesh
            if hasattr(dolfinx.mesh, "entities_to_geometry"):
                nodes = dolfinx.mesh.entities_to_geometry(msh, tags.dim, tags.indices, False)
            else:  # older DOLFINx: only the C++ function, on the wrapped C++ mesh
                cpp = getattr(msh, "_cpp_object", getattr(msh, "_mesh", msh))
                nodes = dolfinx.cpp.mesh.entities_to_geometry(cpp, tags.dim, tags.indices, False)
            gx = msh.geometry.x
            return {tuple(sorted(tuple(gx[n]) for n in row)): int(v)
                    for row, v in zip(nodes, tags.values)}

        check(dolfinx_tags(ct) == by_points(tets), "dolfinx's cell tags sit on other cells")
        check(dolfinx_tags(ft) == by_points(tris), "dolfinx's facet tags sit on other facets")

    for f in failures:
        print(f"FAIL: {f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
