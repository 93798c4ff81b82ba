#!/usr/bin/env python3
"""Compare `slivermesh mesh --repair` with fTetWild on dirty surfaces, whole process against whole
process.

The dirty models are built here, deterministically, from models in the repository and written as
.off to the output directory:
  small_hole_bear   models/scans/bear_bis.off with a connected patch of 200 triangles deleted
                    (breadth-first over edge-adjacent triangles from triangle 0): an open surface;
  overlap_fandisk   two copies of models/off/fandisk.off in one file, the second shifted by 1% of
                    the bounding-box diagonal along (1,1,1)/sqrt(3): two overlapping closed shells
                    whose surfaces intersect each other along the shift;
  overlap_sphere    the same with two icospheres of 5120 triangles each (generated here): the
                    ctest's overlapping case (--models small_hole_bear,overlap_sphere; fTetWild
                    takes 135 s on the fandisk pair on one thread here).
For each model:
  1. `slivermesh mesh MODEL.off -o MODEL-slivermesh.mesh --repair --stats-json ...` (a rerun
     with --size: MODEL-slivermesh-size.mesh), timed as a whole process (reading the input to
     the written mesh, the printed report included);
  2. fTetWild through pytetwild (PyPI; fTetWild's C++ behind a Python module) in a child process
     of this script timed as a whole too (`compare_ftetwild.py --ftetwild-worker IN OUT`:
     interpreter start, `import numpy, pytetwild`, reading the .off and writing the .mesh
     included): tetrahedralize(vertices, faces, edge_length_fac=0.05, epsilon=1e-3,
     num_threads=1, vtk_ordering=True), fTetWild's defaults except one thread and
     vtk_ordering (fTetWild's own tets are negatively oriented; VTK's order is the right-handed
     one that medit and our measure use: it only permutes each tet's vertices), written as an
     ASCII medit .mesh MODEL-ftetwild.mesh;
  3. both written files are read back here and measured by the same independent code
     (quality_checks.figures: plain Python floats): tets, boundary triangles, min/max dihedral,
     tets below 5/10/15/20 degrees, inverted and zero-volume tets, volume.
Similar tet counts: fTetWild always runs at its defaults (it is the slow one; its edge length is
5% of the bounding-box diagonal). slivermesh runs at its defaults first; when the two counts
differ by more than a factor --count-factor (1.5), slivermesh is run once more with
`--size H`, H = (5.1 V / N)^(1/3) from the volume V and tet count N of fTetWild's mesh (the
cube-root rule of compare_gmsh.py's first guess), and of the two runs the one whose count is
closer to fTetWild's is compared. (On the two default models the counts stay 2.3x-2.8x apart:
--size bounds the interior spacing, and our boundary, which follows the surface within the same
relative distance, 1e-3 of the diagonal, as fTetWild's envelope, has 2x (bear) and 5x (fandisk
pair, with its intersection curves and sharp edges) fTetWild's boundary triangles; a note says
so. On overlap_sphere the rerun lands within 15%.) --size H fixes the size from the start
instead. fTetWild's counts vary by a few percent from run to run, even on one thread.

Prints a side-by-side table per model, the time ratio fTetWild / slivermesh (whole processes;
fTetWild's in-process time from the call to the return is shown too) and the per-tet throughput
ratio. Checks (exit status 1 with "FAIL: ..." lines; 2 for usage errors): both programs succeed
and write a readable mesh; our mesh has no inverted and no zero-volume tet; our minimum dihedral
angle is >= --require-min-dihedral (20 degrees, the --repair target). Times are printed, never
asserted; fTetWild's figures (including inverted tets, if any) are printed, never asserted.
Without pytetwild (`import pytetwild` fails in --python) the script prints "SKIP: ..." and exits
0 with --skip-ftetwild-missing, 2 otherwise (ctests/CMakeLists.txt does not register the test
then, as for compare_gmsh.py without gmsh).

Examples:
  compare_ftetwild.py                                   # both models (the ctest)
  compare_ftetwild.py --models small_hole_bear --outdir cmp
  compare_ftetwild.py --models overlap_fandisk --size 0.01
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter, deque


# --- the fTetWild child process (`compare_ftetwild.py --ftetwild-worker ...`): kept apart from the
# rest so that the timed process imports nothing but numpy and pytetwild.

def ftetwild_worker(argv):
    ap = argparse.ArgumentParser(prog="compare_ftetwild.py --ftetwild-worker")
    ap.add_argument("input", help=".off surface (triangles)")
    ap.add_argument("output", help="medit .mesh to write")
    ap.add_argument("--edge-length-fac", type=float, default=0.05)
    ap.add_argument("--epsilon", type=float, default=1e-3)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    import numpy as np
    import pytetwild
    t_import = time.perf_counter() - t0
    pts, tris = read_off(a.input)
    vertices = np.array(pts, dtype=np.float64)
    faces = np.array(tris, dtype=np.int32)
    t1 = time.perf_counter()
    v, t = pytetwild.tetrahedralize(vertices, faces, edge_length_fac=a.edge_length_fac,
                                    epsilon=a.epsilon, num_threads=a.threads, vtk_ordering=True)
    t2 = time.perf_counter()
    v = np.asarray(v, dtype=np.float64)
    t = np.asarray(t, dtype=np.int64)
    with open(a.output, "w") as f:
        f.write("MeshVersionFormatted 2\nDimension\n3\n\nVertices\n%d\n" % len(v))
        np.savetxt(f, np.column_stack([v, np.zeros(len(v))]), fmt="%.17g %.17g %.17g %d")
        f.write("\nTetrahedra\n%d\n" % len(t))
        np.savetxt(f, np.column_stack([t + 1, np.ones(len(t), dtype=np.int64)]), fmt="%d")
        f.write("\nEnd\n")
    t3 = time.perf_counter()
    try:
        from importlib.metadata import version
        ver = version("pytetwild")
    except Exception:  # noqa: BLE001 - the version is only printed
        ver = "?"
    print(json.dumps({"program": "fTetWild (pytetwild %s)" % ver, "n_tets": int(len(t)),
                      "n_vertices": int(len(v)), "seconds_import": t_import,
                      "seconds_tetrahedralize": t2 - t1, "seconds_write": t3 - t2,
                      "seconds_in_process": t2 - t1}))
    return 0


# --- .off reading and writing (standard library only; the worker uses it too) --------------------

def read_off(path):
    """Vertices and triangles (fan-triangulated faces, 0-based) of an OFF file."""
    with open(path) as f:
        lines = [ln.split("#", 1)[0].split() for ln in f]
    lines = [ln for ln in lines if ln]
    header = lines[0]
    if not header[0].endswith("OFF"):
        raise ValueError("%s: no OFF header" % path)
    counts = header[1:] if len(header) > 1 else lines[1]
    body = lines[1:] if len(header) > 1 else lines[2:]
    nv, nf = int(counts[0]), int(counts[1])
    pts = [tuple(float(w) for w in ln[:3]) for ln in body[:nv]]
    tris = []
    for ln in body[nv:nv + nf]:
        k = int(ln[0])
        ids = [int(w) for w in ln[1:1 + k]]
        for i in range(1, k - 1):
            tris.append((ids[0], ids[i], ids[i + 1]))
    return pts, tris


if len(sys.argv) > 1 and sys.argv[1] == "--ftetwild-worker":
    sys.exit(ftetwild_worker(sys.argv[2:]))

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_gmsh import read_medit  # noqa: E402
from meshcompare import Failure, check_executable, run_timed, size_args, table  # noqa: E402
from quality_checks import figures  # noqa: E402


def write_off(path, pts, tris):
    """Writes the triangles and only the vertices they use (renumbered in order of first use)."""
    index, used = {}, []
    for t in tris:
        for v in t:
            if v not in index:
                index[v] = len(used)
                used.append(v)
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(used), len(tris)))
        for v in used:
            f.write("%r %r %r\n" % pts[v])
        for t in tris:
            f.write("3 %d %d %d\n" % tuple(index[v] for v in t))


# --- the dirty models ------------------------------------------------------------------------------

def small_hole_bear(models_dir, out):
    """bear_bis.off less a connected patch of 200 triangles: breadth-first from triangle 0 over
    triangles sharing an edge (neighbours visited in the order of the triangle's edges, then of
    their index)."""
    pts, tris = read_off(os.path.join(models_dir, "scans", "bear_bis.off"))
    by_edge = {}
    for i, (a, b, c) in enumerate(tris):
        for e in ((a, b), (b, c), (c, a)):
            by_edge.setdefault((min(e), max(e)), []).append(i)
    removed, queue = {0}, deque([0])
    while queue and len(removed) < 200:
        i = queue.popleft()
        a, b, c = tris[i]
        for e in ((a, b), (b, c), (c, a)):
            for j in sorted(by_edge[(min(e), max(e))]):
                if j not in removed and len(removed) < 200:
                    removed.add(j)
                    queue.append(j)
    if len(removed) != 200:
        raise Failure("bear_bis.off: only %d triangles reachable from triangle 0" % len(removed))
    write_off(out, pts, [t for i, t in enumerate(tris) if i not in removed])
    return "bear_bis.off less 200 edge-connected triangles (BFS from triangle 0): an open surface"


def shifted_pair(pts, tris):
    """The surface and a copy of it shifted by 1% of its bounding-box diagonal along
    (1,1,1)/sqrt(3), in one vertex and triangle list; and the shift's length."""
    lo = [min(p[k] for p in pts) for k in range(3)]
    hi = [max(p[k] for p in pts) for k in range(3)]
    shift = 0.01 * math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3)))
    d = shift / math.sqrt(3.0)
    n = len(pts)
    return (pts + [(p[0] + d, p[1] + d, p[2] + d) for p in pts],
            tris + [(a + n, b + n, c + n) for a, b, c in tris], shift)


def overlap_fandisk(models_dir, out):
    """Two copies of fandisk.off, the second shifted by 1% of the bounding-box diagonal along
    (1,1,1)/sqrt(3)."""
    pts, tris, shift = shifted_pair(*read_off(os.path.join(models_dir, "off", "fandisk.off")))
    write_off(out, pts, tris)
    return ("two copies of fandisk.off, the second shifted by %.4g (1%% of the bounding-box "
            "diagonal) along (1,1,1)/sqrt(3): overlapping, intersecting shells" % shift)


def icosphere(levels):
    """Unit icosphere: the icosahedron with every triangle split in 4, `levels` times, new vertices
    pushed onto the sphere (20 * 4^levels triangles, outward oriented)."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    pts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
           (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    pts = [tuple(c / math.sqrt(1.0 + t * t) for c in p) for p in pts]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
            (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
            (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid, out = {}, []

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = tuple((pts[a][k] + pts[b][k]) / 2.0 for k in range(3))
                r = math.sqrt(sum(c * c for c in p))
                mid[key] = len(pts)
                pts.append(tuple(c / r for c in p))
            return mid[key]
        for a, b, c in tris:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = out
    return pts, tris


def overlap_sphere(models_dir, out):
    """Two unit icospheres of 5120 triangles, the second shifted by 1% of the bounding-box
    diagonal along (1,1,1)/sqrt(3) (a smaller overlapping case; not in the default list)."""
    pts, tris = icosphere(4)
    pts2, tris2, shift = shifted_pair(pts, tris)
    write_off(out, pts2, tris2)
    return ("two unit icospheres of %d triangles, the second shifted by %.4g (1%% of the "
            "bounding-box diagonal) along (1,1,1)/sqrt(3)" % (len(tris), shift))


MODELS = {"small_hole_bear": small_hole_bear, "overlap_fandisk": overlap_fandisk,
          "overlap_sphere": overlap_sphere}
DEFAULT_MODELS = ("small_hole_bear", "overlap_fandisk")


# --- the comparison -------------------------------------------------------------------------------

def measure(path):
    xyz, tets = read_medit(path)
    used = set()
    for t in tets:
        used.update(t)
    faces = Counter()
    for a, b, c, d in tets:
        for f in ((a, b, c), (a, b, d), (a, c, d), (b, c, d)):
            faces[tuple(sorted(f))] += 1
    res = figures(xyz, tets)
    res["n_vertices"] = len(used)
    res["n_boundary_faces"] = sum(1 for k in faces.values() if k == 1)
    return res


def compare(args, name, outdir):
    model = os.path.join(outdir, name + ".off")
    what = MODELS[name](args.models_dir, model)
    ft_mesh = os.path.join(outdir, name + "-ftetwild.mesh")
    print("%s: %s\n  (%s)" % (name, what, model))

    def ours_at(h, stem):
        mesh = os.path.join(outdir, "%s-%s.mesh" % (name, stem))
        stats = os.path.join(outdir, "%s-%s-stats.json" % (name, stem))
        if os.path.exists(stats):
            os.remove(stats)
        cmd = [args.slivermesh, "mesh", model, "-o", mesh, "--repair"] + size_args(h) + \
              ["--stats-json", stats]
        try:
            _, wall = run_timed(cmd)
        except Failure as e:
            raise Failure("slivermesh failed: %s" % e)
        try:
            with open(stats) as f:
                res = json.load(f)
        except (OSError, json.JSONDecodeError) as e:
            raise Failure("slivermesh wrote no readable --stats-json (%s)" % e)
        res.update({"size": h, "wall_seconds": wall, "mesh": mesh,
                    "command": " ".join(["slivermesh", "mesh", os.path.basename(model), "--repair"]
                                        + size_args(h, "%.6g"))})
        print("  %-12s %-22s -> %d tets, %.3f s" % ("slivermesh", " ".join(size_args(h, "%.4g"))
                                                    or "default size", res["n_tets"], wall))
        return res

    def ftetwild():
        cmd = [args.python, os.path.abspath(__file__), "--ftetwild-worker", model, ft_mesh,
               "--edge-length-fac", "%g" % args.edge_length_fac, "--epsilon", "%g" % args.epsilon,
               "--threads", str(args.ftetwild_threads)]
        try:
            out, wall = run_timed(cmd)
        except Failure as e:
            raise Failure("fTetWild failed: %s" % e)
        try:
            res = json.loads(out.strip().splitlines()[-1])
        except (json.JSONDecodeError, IndexError) as e:
            raise Failure("the fTetWild child printed no JSON (%s):\n%s" % (e, out))
        res.update({"wall_seconds": wall,
                    "command": "pytetwild.tetrahedralize(%s, edge_length_fac=%g, epsilon=%g, "
                               "num_threads=%d)" % (os.path.basename(model), args.edge_length_fac,
                                                    args.epsilon, args.ftetwild_threads)})
        print("  %-12s %-22s -> %d tets, %.3f s" % ("fTetWild", "edge_length_fac %g" % args.edge_length_fac,
                                                    res["n_tets"], wall))
        return res

    def off_by(n):  # how far a tet count is from fTetWild's, as a factor >= 1
        return max(n / ft["n_tets"], ft["n_tets"] / n)

    ft = ftetwild()
    ft_m = measure(ft_mesh)
    ours = ours_at(args.size if args.size is not None else 0.0, "slivermesh")
    if args.size is None and off_by(ours["n_tets"]) > args.count_factor and ft_m["volume"] > 0:
        h = (5.1 * ft_m["volume"] / ft_m["n_tets"]) ** (1.0 / 3.0)
        print("  tet counts differ by a factor %.2f (> %g): slivermesh again with --size %.4g "
              "(cube-root rule from fTetWild's count and volume)"
              % (off_by(ours["n_tets"]), args.count_factor, h))
        again = ours_at(h, "slivermesh-size")
        if off_by(again["n_tets"]) < off_by(ours["n_tets"]):
            ours = again
        print("  compared: slivermesh %s (tet counts off by a factor %.2f)"
              % (" ".join(size_args(ours["size"], "%.4g")) or "at its default size",
                 off_by(ours["n_tets"])))
    ours_mesh = ours["mesh"]
    ours_m = measure(ours_mesh)

    for row, run in ((ours_m, ours), (ft_m, ft)):
        row["wall_seconds"] = run["wall_seconds"]
        row["tets_per_second"] = row["n_tets"] / run["wall_seconds"]
        row["n_inverted_zero"] = [row["n_inverted"], row["n_zero_volume"]]
    ours_m["param"] = " ".join(size_args(ours["size"], "%.4g")) or "default size"
    ft_m["param"] = "fac %g eps %g" % (args.edge_length_fac, args.epsilon)
    ft_m["in_process_seconds"] = ft["seconds_in_process"]
    ours_m["in_process_seconds"] = ours.get("seconds_total")
    rows = [
        ("size parameter", "param", "s", False),
        ("vertices", "n_vertices", "d", True),
        ("tets", "n_tets", "d", True),
        ("boundary triangles", "n_boundary_faces", "d", True),
        ("seconds (whole process)", "wall_seconds", ".3f", True),
        ("seconds (in process)", "in_process_seconds", ".3f", True),
        ("tets/s (whole process)", "tets_per_second", ",.0f", True),
        ("min dihedral (deg)", "min_dihedral_deg", ".2f", True),
        ("max dihedral (deg)", "max_dihedral_deg", ".2f", True),
        ("tet min dihedral p1", "min_dihedral_p1_deg", ".2f", True),
        ("tets < 5/10/15/20 deg", "tets_below_deg", "", False),
        ("tets > 160/165/170/175", "tets_above_deg", "", False),
        ("max radius-edge R/L", "max_rho", ".3f", True),
        ("min sigma V/L^3", "min_sigma", ".4f", True),
        ("inverted / zero volume", "n_inverted_zero", "", False),
        ("volume", "volume", ".6g", True),
    ]
    ratio = ft["wall_seconds"] / ours["wall_seconds"]
    per_tet = ours_m["tets_per_second"] / ft_m["tets_per_second"]
    print()
    print("%s: %s\n    vs %s" % (name, ft["command"], ours["command"]))
    print("(both measured from the written files: %s, %s)" % (ft_mesh, ours_mesh))
    print(table(rows, ft_m, ours_m, "fTetWild"))
    print("time ratio fTetWild / slivermesh (whole process): %.3f   (fTetWild %.3f s, slivermesh "
          "%.3f s; fTetWild in process %.3f s)" % (ratio, ft["wall_seconds"], ours["wall_seconds"],
                                                   ft["seconds_in_process"]))
    print("per-tet throughput ratio slivermesh / fTetWild (tets per whole-process second): %.3f"
          % per_tet)
    print("tet counts: slivermesh %d, fTetWild %d (ratio %.3f)"
          % (ours_m["n_tets"], ft_m["n_tets"], ours_m["n_tets"] / ft_m["n_tets"]))
    repair = ours.get("repair")
    if repair is not None:
        print("slivermesh's repair report: %s" % json.dumps(repair, sort_keys=True))
    print()

    failures = []
    if ours_m["n_inverted"] or ours_m["n_zero_volume"]:
        failures.append("%s: slivermesh mesh has %d inverted and %d zero-volume tets"
                        % (name, ours_m["n_inverted"], ours_m["n_zero_volume"]))
    if not ours_m["min_dihedral_deg"] >= args.require_min_dihedral:
        failures.append("%s: slivermesh's minimum dihedral angle %.3f deg is below the required %.3f "
                        "deg (fTetWild's: %.3f deg)" % (name, ours_m["min_dihedral_deg"],
                                                        args.require_min_dihedral,
                                                        ft_m["min_dihedral_deg"]))
    notes = []
    if off_by(ours_m["n_tets"]) > args.count_factor:
        notes.append("the tet counts differ by a factor %.2f (> %g) even so: --size bounds the "
                     "interior spacing, the boundary (%d triangles here, %d in fTetWild's mesh) "
                     "follows the surface distance" % (off_by(ours_m["n_tets"]), args.count_factor,
                                                      ours_m["n_boundary_faces"],
                                                      ft_m["n_boundary_faces"]))
    if ft_m["n_inverted"] or ft_m["n_zero_volume"]:
        notes.append("the fTetWild mesh has %d inverted and %d zero-volume tets"
                     % (ft_m["n_inverted"], ft_m["n_zero_volume"]))
    if ours.get("complete") is False:
        notes.append("slivermesh reports complete: false (%s)" % ours.get("stop_reason"))
    if ours_m["n_tets"] != ours.get("n_tets") or \
            abs(ours_m["min_dihedral_deg"] - (ours.get("min_dihedral_deg") or 0.0)) > 1e-6:
        notes.append("slivermesh reports %s tets, min dihedral %s; measured from its file: %d, %.9f"
                     % (ours.get("n_tets"), ours.get("min_dihedral_deg"), ours_m["n_tets"],
                        ours_m["min_dihedral_deg"]))
    for n in notes:
        print("note: %s: %s" % (name, n))
    return {"model": name, "description": what, "time_ratio_ftetwild_over_slivermesh": ratio,
            "throughput_ratio_slivermesh_over_ftetwild": per_tet, "ftetwild": ft_m,
            "slivermesh": ours_m, "ftetwild_run": ft, "slivermesh_report": ours,
            "notes": notes, "failures": failures}


def pytetwild_importable(python):
    p = subprocess.run([python, "-c", "import numpy, pytetwild"], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    return p.returncode == 0, (p.stderr or "").strip().splitlines()[-1:] or [""]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.split("\n")[1:]))
    ap.add_argument("--slivermesh", default=os.path.join(here, "..", "target", "release", "slivermesh"))
    ap.add_argument("--python", default=sys.executable,
                    help="the Python that runs fTetWild (needs `import pytetwild`; default: this one)")
    ap.add_argument("--models-dir", default=os.path.join(here, "..", "models"),
                    help="the repository's models/ (default: next to ctests/)")
    ap.add_argument("--models", default=",".join(DEFAULT_MODELS),
                    help="comma-separated, among %s (default: %s)" % (", ".join(MODELS),
                                                                      ",".join(DEFAULT_MODELS)))
    ap.add_argument("--size", type=float,
                    help="slivermesh's --size, fixed (0: its default spacing); default: its "
                         "defaults, then one rerun sized from fTetWild's count if the counts differ "
                         "by more than --count-factor")
    ap.add_argument("--count-factor", type=float, default=1.5,
                    help="rerun slivermesh with a --size from fTetWild's count when the tet counts "
                         "differ by more than this factor (default 1.5)")
    ap.add_argument("--edge-length-fac", type=float, default=0.05,
                    help="fTetWild's edge length / bounding-box diagonal (default 0.05, its default)")
    ap.add_argument("--epsilon", type=float, default=1e-3,
                    help="fTetWild's envelope / bounding-box diagonal (default 1e-3, its default)")
    ap.add_argument("--ftetwild-threads", type=int, default=1, help="fTetWild's num_threads (default 1)")
    ap.add_argument("--require-min-dihedral", type=float, default=20.0, metavar="X",
                    help="fail unless our minimum dihedral angle is >= X degrees (default 20, the "
                         "--repair target)")
    ap.add_argument("--skip-ftetwild-missing", action="store_true",
                    help="without pytetwild, print SKIP and exit 0 (default: exit 2)")
    ap.add_argument("--outdir", help="keep the models and meshes here (default: a temp dir, removed)")
    ap.add_argument("--json-out", help="write every figure to this JSON file")
    args = ap.parse_args()

    names = [m for m in args.models.split(",") if m]
    unknown = [m for m in names if m not in MODELS]
    if unknown or not names:
        print("error: unknown model(s) %s; known: %s" % (", ".join(unknown) or "(none given)",
                                                         ", ".join(MODELS)), file=sys.stderr)
        return 2
    args.models_dir = os.path.abspath(args.models_dir)
    if not os.path.isdir(args.models_dir):
        print("error: models directory not found: %s" % args.models_dir, file=sys.stderr)
        return 2
    if not check_executable("slivermesh", args.slivermesh):
        return 2
    if (args.size is not None and not args.size >= 0) or not args.count_factor >= 1.0 \
            or args.ftetwild_threads < 0:
        print("error: --size must be >= 0, --count-factor >= 1, --ftetwild-threads >= 0",
              file=sys.stderr)
        return 2
    ok, why = pytetwild_importable(args.python)
    if not ok:
        msg = ("%s cannot `import numpy, pytetwild` (%s): python3 -m pip install pytetwild"
               % (args.python, why[0]))
        if args.skip_ftetwild_missing:
            print("SKIP: " + msg + "; the fTetWild comparison is not run")
            return 0
        print("error: " + msg, file=sys.stderr)
        return 2

    own_tmp = args.outdir is None
    outdir = tempfile.mkdtemp(prefix="slivermesh-vs-ftetwild-") if own_tmp else args.outdir
    os.makedirs(outdir, exist_ok=True)
    results, failures = [], []
    try:
        for name in names:
            try:
                res = compare(args, name, outdir)
                results.append(res)
                failures += res["failures"]
            except (Failure, OSError, ValueError) as e:
                failures.append("%s: %s" % (name, e))
        if len(results) > 1:
            print("summary (whole-process seconds; ratio fTetWild / slivermesh):")
            print("%-18s %10s %10s %9s %9s %10s %10s %8s" % ("model", "tets ours", "tets fTW", "min ours",
                                                           "min fTW", "s ours", "s fTW", "ratio"))
            for r in results:
                o, f = r["slivermesh"], r["ftetwild"]
                print("%-18s %10d %10d %9.2f %9.2f %10.3f %10.3f %8.2f"
                      % (r["model"], o["n_tets"], f["n_tets"], o["min_dihedral_deg"],
                         f["min_dihedral_deg"], o["wall_seconds"], f["wall_seconds"],
                         r["time_ratio_ftetwild_over_slivermesh"]))
            print()
        if args.json_out:
            with open(args.json_out, "w") as f:
                json.dump({"results": results, "failures": failures}, f, indent=2)
                f.write("\n")
    finally:
        if own_tmp:
            shutil.rmtree(outdir, ignore_errors=True)
    for msg in failures:
        print("FAIL: " + msg, file=sys.stderr)
    if not failures:
        print("OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
