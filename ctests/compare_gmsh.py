#!/usr/bin/env python3
"""Compare slivermesh's surface-remeshing volume meshing with Gmsh (classify + remesh + HXT) at
comparable tet counts, whole process against whole process (issue 11).

For one .off model:
  1. `slivermesh mesh MODEL -o MODEL-slivermesh.mesh --size H --stats-json ... SLIVERMESH_ARGS`
     (SLIVERMESH_ARGS defaults to "--surface approximate"; --tets N chooses H instead), timed as
     a whole process: reading the input to the written mesh, the printed report included;
  2. Gmsh through its Python API (pip package gmsh), in a child process of this script timed as a
     whole too (interpreter start and `import gmsh` included): merge the .off,
     classifySurfaces(feature angle 40 deg, boundary, forReparametrization, curveAngle pi),
     createGeometry(), a surface loop and a volume, Mesh.Algorithm3D = 10 (HXT),
     General.NumThreads = 1, Mesh.MeshSizeMax = S, generate(3), write MODEL-gmsh.msh (4.1 ASCII).
     S is calibrated until Gmsh's tet count is close to ours: a first guess from the volume, then
     S *= (n / target)^(1/3) (exponent re-fitted from the last two runs), at most --max-runs runs;
  3. both written files are read back here and measured by the same independent code
     (quality_checks.figures: plain Python floats, face-normal cosines + acos): tets, min/max
     dihedral, tets below 5/10/15/20 degrees, inverted and zero-volume tets by the sign of the
     orientation determinant, volume.
Prints the side-by-side table and the time ratio Gmsh / slivermesh (whole processes; Gmsh's
in-process time from merge to write is shown too).

Checks (exit status 1 with "FAIL: ..." lines; 2 for usage errors): both programs succeed;
slivermesh reports complete: true and the same tet count and minimum dihedral angle as the
independent measure of its file; our mesh has no inverted and no zero-volume tet; its volume is
within --volume-tol of the polyhedron's; the tet counts are within --count-tol (20%); with
--require-min-dihedral X our minimum dihedral angle is >= X. Times are printed, never asserted.

Examples:
  compare_gmsh.py --input models/off/fandisk.off --size 0.03             # ctest size
  compare_gmsh.py --input models/off/fandisk.off --size 0.03 --slivermesh-args= \\
      --require-min-dihedral 0                                            # keep mode (today)
  compare_gmsh.py --input models/off/fandisk.off --tets 200000 --repeat 3 --outdir cmp
"""

import argparse
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time


# --- the Gmsh child process (`compare_gmsh.py --gmsh-worker ...`): kept apart from the rest so
# that the timed process imports nothing but gmsh.

def gmsh_worker(argv):
    ap = argparse.ArgumentParser(prog="compare_gmsh.py --gmsh-worker")
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--mesh-size", type=float, required=True)
    ap.add_argument("--feature-angle", type=float, default=40.0)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    import gmsh
    t_import = time.perf_counter() - t0
    gmsh.initialize(["gmsh"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", a.threads)
        gmsh.option.setNumber("Mesh.MaxNumThreads1D", a.threads)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", a.threads)
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", a.threads)
        t1 = time.perf_counter()
        gmsh.merge(a.input)
        gmsh.model.mesh.classifySurfaces(a.feature_angle * math.pi / 180.0, True, True, math.pi)
        gmsh.model.mesh.createGeometry()
        surfaces = gmsh.model.getEntities(2)
        loop = gmsh.model.geo.addSurfaceLoop([s[1] for s in surfaces])
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        gmsh.option.setNumber("Mesh.Algorithm3D", 10)  # HXT
        gmsh.option.setNumber("Mesh.MeshSizeMax", a.mesh_size)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 0)
        t2 = time.perf_counter()
        gmsh.model.mesh.generate(3)
        t3 = time.perf_counter()
        gmsh.write(a.output)
        t4 = time.perf_counter()
        n_tets = sum(len(t) for t in gmsh.model.mesh.getElements(3)[1])
        version = gmsh.__version__
    finally:
        gmsh.finalize()
    print(json.dumps({"program": "Gmsh " + version, "n_tets": n_tets, "n_surfaces": len(surfaces),
                      "seconds_import": t_import, "seconds_geometry": t2 - t1,
                      "seconds_mesh": t3 - t2, "seconds_write": t4 - t3,
                      "seconds_in_process": t4 - t1}))
    return 0


if len(sys.argv) > 1 and sys.argv[1] == "--gmsh-worker":
    sys.exit(gmsh_worker(sys.argv[2:]))

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_mesh3 import off_volume  # noqa: E402
from meshcompare import Failure, check_executable, match_count, run_timed, size_args, table  # noqa: E402
from quality_checks import figures  # noqa: E402


# --- reading the written meshes (independent of slivermesh's readers) ---------------------------

def _tokens(path):
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0]
            for w in line.split():
                yield w


def read_medit(path):
    """Vertices and tetrahedra (0-based) of an ASCII medit .mesh."""
    xyz, tets = [], []
    it = _tokens(path)
    try:
        for w in it:
            if w == "Vertices":
                n = int(next(it))
                for _ in range(n):
                    xyz.append((float(next(it)), float(next(it)), float(next(it))))
                    next(it)  # reference
            elif w == "Tetrahedra":
                n = int(next(it))
                for _ in range(n):
                    t = tuple(int(next(it)) - 1 for _ in range(4))
                    next(it)
                    tets.append(t)
            elif w in ("Triangles", "Edges", "Corners", "Ridges", "RequiredVertices",
                       "RequiredEdges", "Quadrilaterals", "Hexahedra"):
                per = {"Triangles": 4, "Edges": 3, "Corners": 1, "Ridges": 1,
                       "RequiredVertices": 1, "RequiredEdges": 1, "Quadrilaterals": 5,
                       "Hexahedra": 9}[w]
                n = int(next(it))
                for _ in range(n * per):
                    next(it)
            elif w == "End":
                break
    except (StopIteration, ValueError) as e:
        raise Failure("%s: cannot read as medit .mesh (%s)" % (path, e))
    if not tets:
        raise Failure("%s: no tetrahedra" % path)
    _check_ids(path, xyz, tets)
    return xyz, tets


def read_msh41(path):
    """Nodes and 4-node tetrahedra (type 4, 0-based) of an ASCII Gmsh .msh 4.1."""
    xyz, tets, index = [], [], {}
    with open(path) as f:
        lines = iter(f.read().splitlines())
    try:
        for line in lines:
            s = line.strip()
            if s == "$MeshFormat":
                version, ftype = next(lines).split()[:2]
                if not version.startswith("4") or ftype != "0":
                    raise ValueError("only ASCII format 4.x is read, got %s %s" % (version, ftype))
            elif s == "$Nodes":
                n_blocks = int(next(lines).split()[0])
                for _ in range(n_blocks):
                    _dim, _tag, _parametric, n = (int(x) for x in next(lines).split())
                    tags = [int(next(lines)) for _ in range(n)]
                    for tag in tags:
                        c = next(lines).split()  # x y z, then parametric coordinates if any
                        index[tag] = len(xyz)
                        xyz.append((float(c[0]), float(c[1]), float(c[2])))
            elif s == "$Elements":
                n_blocks = int(next(lines).split()[0])
                for _ in range(n_blocks):
                    _dim, _tag, etype, n = (int(x) for x in next(lines).split())
                    for _ in range(n):
                        w = next(lines).split()
                        if etype == 4:
                            tets.append(tuple(index[int(v)] for v in w[1:5]))
    except (StopIteration, ValueError, KeyError) as e:
        raise Failure("%s: cannot read as Gmsh .msh 4.1 (%s)" % (path, e))
    if not tets:
        raise Failure("%s: no tetrahedra" % path)
    return xyz, tets


def _check_ids(path, xyz, tets):
    n = len(xyz)
    for t in tets:
        for v in t:
            if not 0 <= v < n:
                raise Failure("%s: vertex id %d out of range (%d vertices)" % (path, v + 1, n))


def measure(path):
    xyz, tets = read_msh41(path) if path.endswith(".msh") else read_medit(path)
    used = set()
    for t in tets:
        used.update(t)
    res = figures(xyz, tets)
    res["n_vertices"] = len(used)
    return res


# --- the comparison -------------------------------------------------------------------------------

def compare(args, outdir):
    model = args.input
    name = os.path.splitext(os.path.basename(model))[0]
    volume = off_volume(model)
    ours_mesh = os.path.join(outdir, name + "-slivermesh.mesh")
    stats = os.path.join(outdir, name + "-slivermesh-stats.json")
    gmsh_msh = os.path.join(outdir, name + "-gmsh.msh")
    extra = shlex.split(args.slivermesh_args)
    last = {}

    def ours_at(h):
        last["ours"] = h
        if os.path.exists(stats):
            os.remove(stats)
        cmd = [args.slivermesh, "mesh", model, "-o", ours_mesh] + size_args(h) + \
              ["--stats-json", stats] + extra
        _, wall = run_timed(cmd)
        with open(stats) as f:
            res = json.load(f)
        res.update({"size": h, "wall_seconds": wall,
                    "command": " ".join(["slivermesh", "mesh", os.path.basename(model)] +
                                        size_args(h, "%.6g") + extra)})
        return res

    def gmsh_at(s):
        last["gmsh"] = s
        cmd = [args.python, os.path.abspath(__file__), "--gmsh-worker", model, gmsh_msh,
               "--mesh-size", "%.10g" % s, "--feature-angle", "%g" % args.feature_angle,
               "--threads", str(args.gmsh_threads)]
        out, wall = run_timed(cmd)
        try:
            res = json.loads(out.strip().splitlines()[-1])
        except (json.JSONDecodeError, IndexError) as e:
            raise Failure("the Gmsh child printed no JSON (%s):\n%s" % (e, out))
        res.update({"size": s, "wall_seconds": wall,
                    "command": "gmsh (Python API) %s, classifySurfaces %g deg, HXT, %d thread(s), "
                               "MeshSizeMax %.6g" % (os.path.basename(model), args.feature_angle,
                                                     args.gmsh_threads, s)})
        return res

    print("%s (volume %.6g); choosing sizes:" % (model, volume))
    if args.size is not None:
        h = args.size
        ours = ours_at(h)
        print("  %-12s param %.6g -> %d tets" % ("slivermesh", h, ours["n_tets"]))
    else:
        h, ours = match_count(ours_at, args.tets, (5.1 * volume / args.tets) ** (1.0 / 3.0), 3.0,
                              args.tol, 6, "slivermesh")
        if last["ours"] != h:
            ours = ours_at(h)  # leave the chosen mesh's files on disk
    s, gm = match_count(gmsh_at, ours["n_tets"], (5.5 * volume / ours["n_tets"]) ** (1.0 / 3.0),
                        3.0, args.tol, args.max_runs, "Gmsh")
    if last["gmsh"] != s:
        gm = gmsh_at(s)
    for _ in range(args.repeat - 1):  # timing reruns, the fastest kept
        o, g = ours_at(h), gmsh_at(s)
        if o["wall_seconds"] < ours["wall_seconds"]:
            ours = o
        if g["wall_seconds"] < gm["wall_seconds"]:
            gm = g

    ours_m, gmsh_m = measure(ours_mesh), measure(gmsh_msh)
    for row, run in ((ours_m, ours), (gmsh_m, gm)):
        row["wall_seconds"] = run["wall_seconds"]
        row["tets_per_second"] = row["n_tets"] / run["wall_seconds"]
        row["param"] = (" ".join(size_args(run["size"], "%.4g")) or "default size") \
            if run is ours else "size %.4g" % run["size"]
        row["volume_rel_error"] = (row["volume"] - volume) / volume
        row["n_inverted_zero"] = [row["n_inverted"], row["n_zero_volume"]]
    gmsh_m["in_process_seconds"] = gm["seconds_in_process"]
    ours_m["in_process_seconds"] = ours.get("seconds_total")
    rows = [
        ("size parameter", "param", "s", False),
        ("vertices", "n_vertices", "d", True),
        ("tets", "n_tets", "d", True),
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
        ("volume", "volume", ".9g", False),
        ("volume vs polyhedron (rel)", "volume_rel_error", "+.2e", False),
    ]
    ratio = gm["wall_seconds"] / ours["wall_seconds"]
    ratio_in = gm["seconds_in_process"] / ours["seconds_total"] if ours.get("seconds_total") else None
    print()
    print("%s: %s\n    vs %s" % (os.path.basename(model), gm["command"], ours["command"]))
    print("(both measured from the written files: %s, %s)" % (gmsh_msh, ours_mesh))
    print(table(rows, gmsh_m, ours_m, "Gmsh"))
    print("time ratio Gmsh / slivermesh (whole process): %.3f   (Gmsh %.3f s, slivermesh %.3f s; "
          "in process %s)" % (ratio, gm["wall_seconds"], ours["wall_seconds"],
                              "%.3f" % ratio_in if ratio_in else "n/a"))
    print("tet counts: slivermesh %d, Gmsh %d (ratio %.3f)"
          % (ours_m["n_tets"], gmsh_m["n_tets"], ours_m["n_tets"] / gmsh_m["n_tets"]))
    print()

    failures = []
    if not ours.get("complete"):
        msg = "%s: slivermesh did not complete: %s" % (name, ours.get("stop_reason"))
        if args.allow_incomplete:
            print("note: " + msg)
        else:
            failures.append(msg)
    if ours_m["n_inverted"] or ours_m["n_zero_volume"]:
        failures.append("%s: slivermesh mesh has %d inverted and %d zero-volume tets"
                        % (name, ours_m["n_inverted"], ours_m["n_zero_volume"]))
    if gmsh_m["n_inverted"] or gmsh_m["n_zero_volume"]:
        print("note: the Gmsh mesh has %d inverted and %d zero-volume tets"
              % (gmsh_m["n_inverted"], gmsh_m["n_zero_volume"]))
    count_ratio = ours_m["n_tets"] / gmsh_m["n_tets"]
    if abs(count_ratio - 1.0) > args.count_tol:
        failures.append("%s: tet counts not comparable: slivermesh %d, Gmsh %d (ratio %.3f, allowed "
                        "+-%.0f%%)" % (name, ours_m["n_tets"], gmsh_m["n_tets"], count_ratio,
                                       100 * args.count_tol))
    if abs(ours_m["volume_rel_error"]) > args.volume_tol:
        failures.append("%s: slivermesh mesh volume %.9g differs from the polyhedron's %.9g by %.2e "
                        "(allowed %.2e)" % (name, ours_m["volume"], volume, ours_m["volume_rel_error"],
                                            args.volume_tol))
    if (ours_m["n_tets"] != ours["n_tets"]
            or abs(ours_m["min_dihedral_deg"] - ours["min_dihedral_deg"]) > 1e-6):
        failures.append("%s: slivermesh reports %d tets, min dihedral %.9f; measured from its file: "
                        "%d, %.9f" % (name, ours["n_tets"], ours["min_dihedral_deg"],
                                      ours_m["n_tets"], ours_m["min_dihedral_deg"]))
    if args.require_min_dihedral is not None and not ours_m["min_dihedral_deg"] >= args.require_min_dihedral:
        failures.append("%s: slivermesh's minimum dihedral angle %.3f deg is below the required %.3f "
                        "deg (Gmsh's: %.3f deg)" % (name, ours_m["min_dihedral_deg"],
                                                    args.require_min_dihedral,
                                                    gmsh_m["min_dihedral_deg"]))
    return {"model": model, "volume": volume, "time_ratio_gmsh_over_slivermesh": ratio,
            "time_ratio_in_process": ratio_in, "gmsh": gmsh_m, "slivermesh": ours_m,
            "gmsh_run": gm, "slivermesh_report": ours, "failures": failures}


def gmsh_importable(python):
    p = subprocess.run([python, "-c", "import gmsh"], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    return p.returncode == 0, (p.stderr or "").strip().splitlines()[-1:] or [""]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.split("\n")[1:]))
    ap.add_argument("--slivermesh", default=os.path.join(here, "..", "target", "release", "slivermesh"))
    ap.add_argument("--python", default=sys.executable,
                    help="the Python that runs Gmsh (needs `import gmsh`; default: this one)")
    ap.add_argument("--input", required=True, help="an .off model (e.g. models/off/fandisk.off)")
    size = ap.add_mutually_exclusive_group(required=True)
    size.add_argument("--size", type=float,
                      help="slivermesh's --size (fixed; 0: its default spacing, no --size)")
    size.add_argument("--tets", type=int, help="instead of --size: adjust slivermesh's --size to about this many tets")
    ap.add_argument("--allow-incomplete", action="store_true",
                    help="report an incomplete slivermesh run (a bound missed by a few tets) "
                         "instead of failing; the angle, validity and volume checks still apply")
    ap.add_argument("--slivermesh-args", default="--surface approximate",
                    help="extra arguments for `slivermesh mesh`, one shell-quoted string "
                         "(default '--surface approximate'; '' for the keep mode); write it "
                         "--slivermesh-args='...'")
    ap.add_argument("--feature-angle", type=float, default=40.0,
                    help="Gmsh's classifySurfaces angle in degrees (default 40, the issue's)")
    ap.add_argument("--gmsh-threads", type=int, default=1, help="Gmsh's General.NumThreads (default 1)")
    ap.add_argument("--require-min-dihedral", type=float, metavar="X",
                    help="fail unless our minimum dihedral angle is >= X degrees (default: no check)")
    ap.add_argument("--repeat", type=int, default=1, help="timed runs per program, fastest kept (default 1)")
    ap.add_argument("--tol", type=float, default=0.05,
                    help="stop calibrating Gmsh's size when within this fraction of our count (default 0.05)")
    ap.add_argument("--max-runs", type=int, default=3, help="Gmsh calibration runs (default 3)")
    ap.add_argument("--count-tol", type=float, default=0.20,
                    help="fail unless the two tet counts are within this fraction (default 0.20)")
    ap.add_argument("--volume-tol", type=float, default=0.01,
                    help="fail unless our volume is within this fraction of the polyhedron's (default 0.01)")
    ap.add_argument("--outdir", help="keep the meshes here (default: a temp dir, removed)")
    ap.add_argument("--json-out", help="write every figure to this JSON file")
    args = ap.parse_args()

    if not os.path.isfile(args.input):
        print("error: input model not found: %s" % args.input, file=sys.stderr)
        return 2
    args.input = os.path.abspath(args.input)
    if not check_executable("slivermesh", args.slivermesh):
        return 2
    if args.repeat < 1 or args.max_runs < 1 or (args.tets is not None and args.tets < 50) \
            or (args.size is not None and not args.size >= 0):
        print("error: --repeat and --max-runs must be >= 1, --tets >= 50, --size >= 0", file=sys.stderr)
        return 2
    try:
        shlex.split(args.slivermesh_args)
    except ValueError as e:
        print("error: --slivermesh-args: %s" % e, file=sys.stderr)
        return 2
    ok, why = gmsh_importable(args.python)
    if not ok:
        print("error: %s cannot `import gmsh` (%s): python3 -m pip install 'gmsh==4.15.*' and the "
              "system libraries it needs (scripts/test-all installs both)" % (args.python, why[0]),
              file=sys.stderr)
        return 2

    own_tmp = args.outdir is None
    outdir = tempfile.mkdtemp(prefix="slivermesh-vs-gmsh-") if own_tmp else args.outdir
    os.makedirs(outdir, exist_ok=True)
    result, failures = None, []
    try:
        try:
            result = compare(args, outdir)
            failures = result["failures"]
        except Failure as e:
            failures.append("%s: %s" % (os.path.basename(args.input), e))
        if args.json_out:
            with open(args.json_out, "w") as f:
                json.dump({"slivermesh_args": args.slivermesh_args, "result": result,
                           "failures": failures}, f, indent=2)
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
