#!/usr/bin/env python3
"""Compare slivermesh's Delaunay kernel with CGAL's Delaunay_triangulation_3 on the same points.

Generates a point set with `slivermesh gen-points` (or takes --points FILE), triangulates it with
`slivermesh delaunay --stats-json` and with `cgal_delaunay --checksum`, prints a side-by-side
table with ratios, and checks correctness:

* both must report the same number of vertices;
* for inputs in general position (every kind but `grid`, whose cospherical points admit many
  Delaunay triangulations) the Delaunay triangulation is unique, so both must report the same
  number of finite tets and the same order-independent checksum of the tet set.

Exit status 0 when every check passes, 1 otherwise (2 for usage errors). Standard library only.

Examples:
  compare_delaunay.py --slivermesh target/release/slivermesh --cgal build/ctests/cgal_delaunay
  compare_delaunay.py ... --n 1000000 --repeat 3          # the speed/memory benchmark
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile


def run(cmd, capture=True):
    """Runs cmd; returns stdout. Raises SystemExit(1) with its stderr on failure."""
    proc = subprocess.run(cmd, stdout=subprocess.PIPE if capture else None,
                          stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stderr)
        raise SystemExit("FAIL: command exited with status %d: %s"
                         % (proc.returncode, " ".join(cmd)))
    return proc.stdout


def run_ours(exe, points, workdir, tag):
    stats = os.path.join(workdir, "slivermesh-%s.json" % tag)
    run([exe, "delaunay", points, "--stats-json", stats])
    with open(stats) as f:
        return json.load(f)


def run_cgal(exe, points, checksum):
    cmd = [exe, points] + (["--checksum"] if checksum else [])
    out = run(cmd)
    try:
        return json.loads(out)
    except json.JSONDecodeError as e:
        raise SystemExit("FAIL: cgal_delaunay printed invalid JSON (%s):\n%s" % (e, out))


def best_of(runs):
    """The run with the smallest time; peak memory is the largest seen (it is per process)."""
    best = dict(min(runs, key=lambda r: r["seconds"]))
    peaks = [r.get("peak_rss_mb") for r in runs if r.get("peak_rss_mb") is not None]
    if peaks:
        best["peak_rss_mb"] = max(peaks)
        if best.get("n_tets"):
            best["bytes_per_tet"] = best["peak_rss_mb"] * 1e6 / best["n_tets"]
    best["all_seconds"] = [r["seconds"] for r in runs]
    return best


def fmt(v, spec):
    if v is None:
        return "n/a"
    return format(v, spec)


def table(ours, cgal):
    rows = [
        ("points", "n_points", "d"),
        ("vertices", "n_vertices", "d"),
        ("finite tets", "n_tets", "d"),
        ("seconds", "seconds", ".3f"),
        ("points/s", "points_per_second", ",.0f"),
        ("peak RSS MB", "peak_rss_mb", ".1f"),
        ("bytes/tet (peak RSS)", "bytes_per_tet", ".1f"),
    ]
    lines = ["%-22s %16s %16s %10s" % ("", "slivermesh", "CGAL", "CGAL/ours")]
    for label, key, spec in rows:
        a, b = ours.get(key), cgal.get(key)
        ratio = ""
        # No ratio for points/s: it would read inverted next to the seconds ratio.
        if key != "points_per_second" and isinstance(a, (int, float)) and isinstance(b, (int, float)) and a:
            ratio = "%.3f" % (b / a)
        lines.append("%-22s %16s %16s %10s" % (label, fmt(a, spec), fmt(b, spec), ratio))
    if "kernel_bytes_per_tet" in ours:
        lines.append("%-22s %16s" % ("kernel arrays B/tet", fmt(ours["kernel_bytes_per_tet"], ".1f")))
    return "\n".join(lines)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slivermesh", default=os.path.join(here, "..", "target", "release", "slivermesh"),
                    help="slivermesh binary (default: ../target/release/slivermesh)")
    ap.add_argument("--cgal", default=os.path.join(here, "..", "build", "ctests", "cgal_delaunay"),
                    help="cgal_delaunay binary (default: ../build/ctests/cgal_delaunay)")
    ap.add_argument("--n", type=int, default=100000, help="number of points (default 100000)")
    ap.add_argument("--kind", default="uniform", choices=["uniform", "grid", "sphere", "clustered"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--points", help="use this point file instead of generating one")
    ap.add_argument("--general-position", action="store_true",
                    help="with --points: the file is in general position (e.g. written by "
                         "gen-points --kind uniform), so check tet counts and checksums too")
    ap.add_argument("--repeat", type=int, default=1, help="runs per program; the fastest is reported")
    ap.add_argument("--no-checksum", action="store_true",
                    help="skip CGAL's second (untimed) triangulation that computes the tet checksum")
    ap.add_argument("--min-speed-ratio", type=float, default=None,
                    help="also fail unless CGAL seconds / slivermesh seconds >= this")
    ap.add_argument("--max-bytes-per-tet", type=float, default=None,
                    help="also fail unless slivermesh's peak RSS bytes per tet <= this")
    ap.add_argument("--json-out", help="write both results and the ratios to this JSON file")
    ap.add_argument("--workdir", help="directory for the points and stats files (default: a temp dir, removed)")
    args = ap.parse_args()

    for name, exe in (("slivermesh", args.slivermesh), ("cgal_delaunay", args.cgal)):
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
            print("error: %s binary not found or not executable: %s" % (name, exe), file=sys.stderr)
            return 2
    if args.repeat < 1 or args.n < 1:
        print("error: --repeat and --n must be >= 1", file=sys.stderr)
        return 2

    own_tmp = args.workdir is None
    workdir = tempfile.mkdtemp(prefix="slivermesh-compare-") if own_tmp else args.workdir
    os.makedirs(workdir, exist_ok=True)
    try:
        if args.points:
            points = args.points
            label = os.path.basename(points)
        else:
            points = os.path.join(workdir, "%s-%d-seed%d.xyz" % (args.kind, args.n, args.seed))
            run([args.slivermesh, "gen-points", "--kind", args.kind, "--n", str(args.n),
                 "--seed", str(args.seed), "-o", points])
            label = "%s n=%d seed=%d" % (args.kind, args.n, args.seed)

        ours_runs, cgal_runs = [], []
        for i in range(args.repeat):
            ours_runs.append(run_ours(args.slivermesh, points, workdir, str(i)))
            # The checksum needs a second CGAL triangulation: do it on the first run only.
            cgal_runs.append(run_cgal(args.cgal, points, checksum=(i == 0 and not args.no_checksum)))
        ours, cgal = best_of(ours_runs), best_of(cgal_runs)
        cgal_checksum = cgal_runs[0].get("tets_checksum")

        print("Delaunay tetrahedralization: %s" % label)
        print(table(ours, cgal))
        speed = cgal["seconds"] / ours["seconds"] if ours["seconds"] > 0 else float("inf")
        mem = (ours["bytes_per_tet"] / cgal["bytes_per_tet"]
               if ours.get("bytes_per_tet") and cgal.get("bytes_per_tet") else None)
        print("speed ratio CGAL time / slivermesh time = %.3f (> 1: slivermesh faster)" % speed)
        if mem is not None:
            print("memory ratio slivermesh / CGAL bytes per tet = %.3f (< 1: slivermesh smaller)" % mem)
        if args.repeat > 1:
            print("all seconds: slivermesh %s, CGAL %s" % (ours["all_seconds"], cgal["all_seconds"]))

        failures = []
        if ours["n_points"] != cgal["n_points"]:
            failures.append("point counts differ: %d vs %d" % (ours["n_points"], cgal["n_points"]))
        if ours["n_vertices"] != cgal["n_vertices"]:
            failures.append("vertex counts differ: slivermesh %d, CGAL %d"
                            % (ours["n_vertices"], cgal["n_vertices"]))
        general_position = (args.general_position if args.points
                            else args.kind != "grid")
        if general_position:
            if ours["n_tets"] != cgal["n_tets"]:
                failures.append("finite tet counts differ: slivermesh %d, CGAL %d "
                                "(the Delaunay triangulation of points in general position is unique)"
                                % (ours["n_tets"], cgal["n_tets"]))
            if cgal_checksum is not None and ours.get("tets_checksum") != cgal_checksum:
                failures.append("tet sets differ: checksum slivermesh %s, CGAL %s"
                                % (ours.get("tets_checksum"), cgal_checksum))
            elif cgal_checksum is not None:
                print("tet sets identical (checksum %s)" % cgal_checksum)
        else:
            print("(tet counts not compared: input may be degenerate, Delaunay not unique)")
        if args.min_speed_ratio is not None and speed < args.min_speed_ratio:
            failures.append("speed ratio %.3f below the required %.3f" % (speed, args.min_speed_ratio))
        if args.max_bytes_per_tet is not None and (ours.get("bytes_per_tet") or 0) > args.max_bytes_per_tet:
            failures.append("slivermesh bytes per tet %.1f above the allowed %.1f"
                            % (ours.get("bytes_per_tet") or 0, args.max_bytes_per_tet))

        if args.json_out:
            with open(args.json_out, "w") as f:
                json.dump({"input": label, "slivermesh": ours, "cgal": cgal,
                           "speed_ratio_cgal_over_ours": speed,
                           "memory_ratio_ours_over_cgal": mem,
                           "failures": failures}, f, indent=2)
                f.write("\n")
        for msg in failures:
            print("FAIL: " + msg, file=sys.stderr)
        if not failures:
            print("OK")
        return 1 if failures else 0
    finally:
        if own_tmp:
            shutil.rmtree(workdir, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
