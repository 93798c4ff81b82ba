#!/usr/bin/env python3
"""Compare slivermesh's quality meshing with `tetgen -pq1.414` at the same number of tets.

Meshes the same .poly (default: the unit cube) with `tetgen -pq1.414a<V>Q` and with
`slivermesh mesh --size H`, choosing V and H so both reach about --tets tets (+-20%, iterated from
a first guess: tetgen gives about 2.05 / V tets per unit volume, slivermesh about 5.1 / H^3).
Each program runs --repeat times at the chosen size and the best wall time (process start to exit,
output files included; both write .node/.ele/.face) is reported. The dihedral angles, radius-edge
ratios and sigma = V/L^3 of BOTH meshes are computed here from their .node/.ele files with plain
floats, so one piece of code judges both; ours must agree with slivermesh's --stats-json.

Checks (exit status 1 with "FAIL: ..." lines when one does not hold; 2 for usage errors):
  * both programs succeed, and slivermesh reports complete: true;
  * the tet counts are within --count-tol (default 20%) of each other;
  * both meshes are consistently oriented, with no flat tet, and fill the same volume;
  * the minimum dihedral angle recomputed from our .ele equals the one in our stats JSON;
  * our minimum dihedral angle is larger than tetgen's.
Speed is printed as ratios, never asserted.

Examples:
  compare_tetgen.py                                  # ~20k tets, the ctest size
  compare_tetgen.py --tets 190000 --repeat 3         # the issue-4 benchmark
"""

import argparse
import json
import math
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from meshcompare import (Failure, check_executable, keep_surface, match_count,  # noqa: E402
                         run_timed, table)

THRESHOLDS_DEG = (5.0, 10.0, 15.0, 20.0)


# --- reading TetGen-format .node/.ele (tetgen's and ours) ---------------------------------------

def _data_lines(path):
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].split()
            if line:
                yield line


def read_node_ele(stem):
    """Points (list of (x, y, z)) and tets (list of 4 indices into it) from stem.node, stem.ele."""
    nodes = _data_lines(stem + ".node")
    try:
        header = next(nodes)
        n = int(header[0])
        first = None
        xyz = []
        for _ in range(n):
            fields = next(nodes)
            if first is None:
                first = int(fields[0])  # 0 or 1: the numbering the .ele uses too
            xyz.append((float(fields[1]), float(fields[2]), float(fields[3])))
    except (StopIteration, ValueError, IndexError) as e:
        raise Failure("%s.node: malformed (%s)" % (stem, e))
    eles = _data_lines(stem + ".ele")
    try:
        header = next(eles)
        m, per = int(header[0]), int(header[1])
        if per != 4:
            raise Failure("%s.ele: %d nodes per tet, only linear tets (4) are handled" % (stem, per))
        tets = []
        for _ in range(m):
            f = next(eles)
            tets.append((int(f[1]) - first, int(f[2]) - first, int(f[3]) - first, int(f[4]) - first))
    except (StopIteration, ValueError, IndexError) as e:
        raise Failure("%s.ele: malformed (%s)" % (stem, e))
    return xyz, tets


def measure(xyz, tets):
    """Quality figures of a tet mesh, plain floats (DESIGN.md's definitions).

    With a = p1-p0, b = p2-p0, c = p3-p0 the cross products b x c, c x a, a x b are the normals of
    the faces opposite p1, p2, p3 and minus their sum the one opposite p0, all pointing the same
    way (all inward or all outward), so the dihedral angle between faces i and j has
    cos = -n_i.n_j / (|n_i| |n_j|); the circumradius is |a^2 (b x c) + b^2 (c x a) + c^2 (a x b)|
    / (2 |det|). The smallest angle of a tet is the one with the largest cosine.
    """
    cos_thr = [math.cos(math.radians(t)) for t in THRESHOLDS_DEG]
    below = [0] * len(THRESHOLDS_DEG)
    cos_min_angle = -1.0   # largest cosine seen: the smallest angle
    cos_max_angle = 1.0    # smallest cosine seen: the largest angle
    max_rho, min_sigma = 0.0, float("inf")
    n_pos = n_neg = n_flat = 0
    volume = 0.0
    for t in tets:
        x0, y0, z0 = xyz[t[0]]
        x1, y1, z1 = xyz[t[1]]
        x2, y2, z2 = xyz[t[2]]
        x3, y3, z3 = xyz[t[3]]
        ax, ay, az = x1 - x0, y1 - y0, z1 - z0
        bx, by, bz = x2 - x0, y2 - y0, z2 - z0
        cx, cy, cz = x3 - x0, y3 - y0, z3 - z0
        # n1 = b x c, n2 = c x a, n3 = a x b, n0 = -(n1 + n2 + n3)
        n1x, n1y, n1z = by * cz - bz * cy, bz * cx - bx * cz, bx * cy - by * cx
        n2x, n2y, n2z = cy * az - cz * ay, cz * ax - cx * az, cx * ay - cy * ax
        n3x, n3y, n3z = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        n0x, n0y, n0z = -(n1x + n2x + n3x), -(n1y + n2y + n3y), -(n1z + n2z + n3z)
        det = ax * n1x + ay * n1y + az * n1z
        if det > 0.0:
            n_pos += 1
        elif det < 0.0:
            n_neg += 1
        else:
            n_flat += 1
            continue
        volume += abs(det) / 6.0
        l0 = math.sqrt(n0x * n0x + n0y * n0y + n0z * n0z)
        l1 = math.sqrt(n1x * n1x + n1y * n1y + n1z * n1z)
        l2 = math.sqrt(n2x * n2x + n2y * n2y + n2z * n2z)
        l3 = math.sqrt(n3x * n3x + n3y * n3y + n3z * n3z)
        cs = (-(n0x * n1x + n0y * n1y + n0z * n1z) / (l0 * l1),
              -(n0x * n2x + n0y * n2y + n0z * n2z) / (l0 * l2),
              -(n0x * n3x + n0y * n3y + n0z * n3z) / (l0 * l3),
              -(n1x * n2x + n1y * n2y + n1z * n2z) / (l1 * l2),
              -(n1x * n3x + n1y * n3y + n1z * n3z) / (l1 * l3),
              -(n2x * n3x + n2y * n3y + n2z * n3z) / (l2 * l3))
        cmax, cmin = max(cs), min(cs)
        if cmax > cos_min_angle:
            cos_min_angle = cmax
        if cmin < cos_max_angle:
            cos_max_angle = cmin
        for i, c in enumerate(cos_thr):
            if cmax > c:
                below[i] += 1
        la, lb, lc = ax * ax + ay * ay + az * az, bx * bx + by * by + bz * bz, cx * cx + cy * cy + cz * cz
        dx, dy, dz = x2 - x1, y2 - y1, z2 - z1
        ex, ey, ez = x3 - x1, y3 - y1, z3 - z1
        fx, fy, fz = x3 - x2, y3 - y2, z3 - z2
        lmin2 = min(la, lb, lc, dx * dx + dy * dy + dz * dz, ex * ex + ey * ey + ez * ez,
                    fx * fx + fy * fy + fz * fz)
        ox = la * n1x + lb * n2x + lc * n3x
        oy = la * n1y + lb * n2y + lc * n3y
        oz = la * n1z + lb * n2z + lc * n3z
        r = math.sqrt(ox * ox + oy * oy + oz * oz) / (2.0 * abs(det))
        lmin = math.sqrt(lmin2)
        rho = r / lmin
        sigma = abs(det) / 6.0 / (lmin2 * lmin)
        if rho > max_rho:
            max_rho = rho
        if sigma < min_sigma:
            min_sigma = sigma

    def deg(c):
        return math.degrees(math.acos(max(-1.0, min(1.0, c))))
    return {
        "n_vertices": len(xyz), "n_tets": len(tets),
        "min_dihedral_deg": deg(cos_min_angle), "max_dihedral_deg": deg(cos_max_angle),
        "max_rho": max_rho, "min_sigma": min_sigma, "tets_below_deg": below,
        "volume": volume, "n_positive": n_pos, "n_negative": n_neg, "n_flat": n_flat,
    }


# --- the two programs ----------------------------------------------------------------------------

def run_tetgen(exe, poly, workdir, volume, quality):
    """tetgen -pq<quality>a<volume>Q on a copy of poly in workdir; returns the result dict."""
    d = os.path.join(workdir, "tetgen")
    os.makedirs(d, exist_ok=True)
    # Keep the extension: tetgen picks its reader by it (.poly, .smesh, .off, .stl, ...).
    name = "input" + os.path.splitext(poly)[1].lower()
    src = os.path.join(d, name)
    if not os.path.exists(src):
        shutil.copyfile(poly, src)
    for ext in ("node", "ele", "face", "edge"):
        try:
            os.remove(os.path.join(d, "input.1." + ext))
        except FileNotFoundError:
            pass
    switches = "-pq%sa%.10gQ" % (quality, volume)
    _, seconds = run_timed([exe, switches, name], cwd=d)
    stem = os.path.join(d, "input.1")
    if not os.path.exists(stem + ".ele"):
        raise Failure("tetgen %s wrote no %s.ele" % (switches, stem))
    with open(stem + ".ele") as f:
        n_tets = int(f.readline().split()[0])
    return {"switches": switches, "volume_bound": volume, "seconds": seconds,
            "n_tets": n_tets, "stem": stem, "complete": True}


def run_ours(exe, poly, workdir, size, extra):
    extra = keep_surface(extra)  # tetgen keeps the input facets: so do we
    d = os.path.join(workdir, "slivermesh")
    os.makedirs(d, exist_ok=True)
    stem = os.path.join(d, "out")
    stats = os.path.join(d, "stats.json")
    cmd = [exe, "mesh", poly, "-o", stem + ".ele", "--size", "%.10g" % size,
           "--stats-json", stats] + extra
    _, seconds = run_timed(cmd)
    with open(stats) as f:
        res = json.load(f)
    res.update({"size": size, "seconds": seconds, "stem": stem,
                "command": " ".join(["slivermesh mesh", os.path.basename(poly), "-o out.ele",
                                     "--size %.6g" % size] + extra)})
    return res


def best_of(runs):
    """The fastest of several runs at the same size."""
    best = dict(min(runs, key=lambda r: r["seconds"]))
    best["all_seconds"] = [round(r["seconds"], 4) for r in runs]
    return best


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slivermesh", default=os.path.join(here, "..", "target", "release", "slivermesh"))
    ap.add_argument("--tetgen", default=shutil.which("tetgen") or "/usr/bin/tetgen")
    ap.add_argument("--input", default=None,
                    help="a .poly (or .off/.stl) both programs read (default: models/poly/cube.poly)")
    ap.add_argument("--tets", type=int, default=20000, help="target number of tets (default 20000)")
    ap.add_argument("--quality", default="1.414", help="tetgen's -q radius-edge bound (default 1.414)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per program, best kept (default 3)")
    ap.add_argument("--tol", type=float, default=0.05,
                    help="stop adjusting a size when within this fraction of --tets (default 0.05)")
    ap.add_argument("--count-tol", type=float, default=0.20,
                    help="fail unless the two tet counts are within this fraction (default 0.20)")
    ap.add_argument("--max-runs", type=int, default=6, help="calibration runs per program (default 6)")
    ap.add_argument("--slivermesh-arg", action="append", default=[],
                    help="extra argument for `slivermesh mesh` (repeatable), e.g. --slivermesh-arg=--min-dihedral=20")
    ap.add_argument("--json-out", help="write both results and the ratios to this JSON file")
    ap.add_argument("--workdir", help="keep the meshes here (default: a temp dir, removed)")
    args = ap.parse_args()

    if args.input is None:
        args.input = os.path.abspath(os.path.join(here, "..", "models", "poly", "cube.poly"))
    if not args.input or not os.path.isfile(args.input):
        print("error: input .poly not found: %s" % args.input, file=sys.stderr)
        return 2
    if not (check_executable("slivermesh", args.slivermesh) and check_executable("tetgen", args.tetgen)):
        return 2
    if args.repeat < 1 or args.tets < 100:
        print("error: --repeat must be >= 1 and --tets >= 100", file=sys.stderr)
        return 2

    own_tmp = args.workdir is None
    workdir = tempfile.mkdtemp(prefix="slivermesh-vs-tetgen-") if own_tmp else args.workdir
    os.makedirs(workdir, exist_ok=True)
    failures = []
    try:
        print("input %s, target %d tets; choosing sizes:" % (args.input, args.tets))
        last = {}  # program -> parameter of its latest run (whose files are on disk)

        def tg_at(v):
            last["tetgen"] = v
            return run_tetgen(args.tetgen, args.input, workdir, v, args.quality)

        def ours_at(h):
            last["slivermesh"] = h
            return run_ours(args.slivermesh, args.input, workdir, h, args.slivermesh_arg)

        v, tg_first = match_count(tg_at, args.tets, 2.05 / args.tets, 1.0, args.tol, args.max_runs, "tetgen")
        h, ours_first = match_count(ours_at, args.tets, (5.1 / args.tets) ** (1.0 / 3.0), 3.0,
                                    args.tol, args.max_runs, "slivermesh")
        # The closest calibration run counts as the first timing, unless a later run overwrote its
        # files. The reruns alternate between the programs so a change in machine load hits both,
        # and leave the chosen sizes' files on disk.
        tg_runs = [tg_first] if last["tetgen"] == v else []
        ours_runs = [ours_first] if last["slivermesh"] == h else []
        while len(tg_runs) < args.repeat or len(ours_runs) < args.repeat or \
                last["tetgen"] != v or last["slivermesh"] != h:
            tg_runs.append(tg_at(v))
            ours_runs.append(ours_at(h))
        tg, ours = best_of(tg_runs), best_of(ours_runs)

        tg_q = measure(*read_node_ele(tg["stem"]))
        ours_q = measure(*read_node_ele(ours["stem"]))
        json_min = ours.get("min_dihedral_deg")
        tg.update(tg_q)
        ours_stats = {k: ours.get(k) for k in ("n_tets", "min_dihedral_deg", "max_dihedral_deg",
                                                "max_rho", "min_sigma", "tets_below_deg")}
        ours.update(ours_q)
        for r in (tg, ours):
            r["tets_per_second"] = r["n_tets"] / r["seconds"] if r["seconds"] > 0 else None

        rows = [
            ("size parameter", "param", "s", False),
            ("vertices", "n_vertices", "d", True),
            ("tets", "n_tets", "d", True),
            ("wall seconds (best)", "seconds", ".3f", True),
            ("tets/s", "tets_per_second", ",.0f", True),
            ("min dihedral (deg)", "min_dihedral_deg", ".2f", True),
            ("max dihedral (deg)", "max_dihedral_deg", ".2f", True),
            ("max radius-edge R/L", "max_rho", ".3f", True),
            ("min sigma V/L^3", "min_sigma", ".4f", True),
            ("tets < 5/10/15/20 deg", "tets_below_deg", "", False),
            ("volume", "volume", ".9f", False),
        ]
        tg["param"], ours["param"] = "-a%.4g" % v, "--size %.4g" % h
        print()
        print("quality meshing of %s, best of %d: tetgen %s vs %s"
              % (os.path.basename(args.input), args.repeat, tg["switches"], ours["command"]))
        print(table(rows, tg, ours, "tetgen"))
        speed = ours["tets_per_second"] / tg["tets_per_second"]
        print("speed: slivermesh %.0f tets/s, tetgen %.0f tets/s, ratio ours/tetgen = %.3f (> 1: slivermesh faster)"
              % (ours["tets_per_second"], tg["tets_per_second"], speed))
        print("min dihedral: slivermesh %.2f deg, tetgen %.2f deg (difference %+.2f deg)"
              % (ours["min_dihedral_deg"], tg["min_dihedral_deg"], ours["min_dihedral_deg"] - tg["min_dihedral_deg"]))
        print("slivermesh's own time (stats JSON seconds_total, no I/O): %.3f s" % ours.get("seconds_total", float("nan")))
        if args.repeat > 1:
            print("all wall seconds: tetgen %s, slivermesh %s" % (tg["all_seconds"], ours["all_seconds"]))

        # --- checks
        if not ours.get("complete"):
            failures.append("slivermesh did not complete: %s" % ours.get("stop_reason"))
        ratio = ours["n_tets"] / tg["n_tets"]
        if abs(ratio - 1.0) > args.count_tol:
            failures.append("tet counts not comparable: slivermesh %d, tetgen %d (ratio %.3f, allowed +-%.0f%%)"
                            % (ours["n_tets"], tg["n_tets"], ratio, 100 * args.count_tol))
        for name, r in (("tetgen", tg), ("slivermesh", ours)):
            if r["n_flat"] or (r["n_positive"] and r["n_negative"]):
                failures.append("%s mesh: %d positive, %d negative, %d flat tets (want one orientation, none flat)"
                                % (name, r["n_positive"], r["n_negative"], r["n_flat"]))
        if abs(tg["volume"] - ours["volume"]) > 1e-9 * max(1.0, tg["volume"]):
            failures.append("volumes differ: tetgen %.12g, slivermesh %.12g" % (tg["volume"], ours["volume"]))
        if ours_stats["n_tets"] != ours["n_tets"]:
            failures.append("slivermesh stats say %s tets, its .ele has %d" % (ours_stats["n_tets"], ours["n_tets"]))
        if json_min is None or abs(json_min - ours["min_dihedral_deg"]) > 1e-6:
            failures.append("slivermesh stats min_dihedral_deg %s, recomputed from its .ele %.9f"
                            % (json_min, ours["min_dihedral_deg"]))
        if not ours["min_dihedral_deg"] > tg["min_dihedral_deg"]:
            failures.append("slivermesh's minimum dihedral angle %.3f deg is not larger than tetgen's %.3f deg"
                            % (ours["min_dihedral_deg"], tg["min_dihedral_deg"]))

        if args.json_out:
            for r in (tg, ours):
                r.pop("stem", None)
            with open(args.json_out, "w") as f:
                json.dump({"input": args.input, "target_tets": args.tets, "tetgen": tg, "slivermesh": ours,
                           "slivermesh_stats": ours_stats,
                           "speed_ratio_ours_over_tetgen": speed,
                           "min_dihedral_difference_deg": ours["min_dihedral_deg"] - tg["min_dihedral_deg"],
                           "failures": failures}, f, indent=2)
                f.write("\n")
    except Failure as e:
        failures.append(str(e))
    finally:
        if own_tmp:
            shutil.rmtree(workdir, ignore_errors=True)
    for msg in failures:
        print("FAIL: " + msg, file=sys.stderr)
    if not failures:
        print("OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
