#!/usr/bin/env python3
"""Quality against `tetgen -pq1.414` on whole models (issue 12), measured on the written meshes.

For each model: `slivermesh mesh MODEL -o out.ele --surface keep` with the default (automatic)
spacing, then `tetgen -pq1.414a<V>` with V chosen so tetgen's tet count is within --count-tol of
ours. Both meshes are measured here from their .node/.ele with the same code
(compare_tetgen.measure). Checks, per model (exit status 1 with FAIL lines otherwise):
  * our mesh has no flat or inverted tet (float determinant; the library checks it exactly);
  * we have no more tets below 5 degrees than tetgen;
  * our minimum dihedral angle is at least tetgen's;
  * with --max-dihedral: our maximum dihedral angle is at most tetgen's;
  * with --acute-free: our minimum is >= 25 and our maximum <= 160 degrees.
Times (best of one run each) and the improvement's share are printed, never asserted.

  compare_tetgen_models.py --slivermesh target/release/slivermesh MODELS...
"""

import argparse
import json
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_tetgen import measure, read_node_ele, run_tetgen  # noqa: E402
from meshcompare import Failure, keep_surface, match_count, run_timed  # noqa: E402


def ours(exe, model, workdir):
    d = os.path.join(workdir, "slivermesh")
    os.makedirs(d, exist_ok=True)
    stem = os.path.join(d, "out")
    stats = os.path.join(d, "stats.json")
    _, seconds = run_timed([exe, "mesh", model, "-o", stem + ".ele", "--stats-json", stats]
                           + keep_surface([]))
    with open(stats) as f:
        rep = json.load(f)
    xyz, tets = read_node_ele(stem)
    m = measure(xyz, tets)
    m.update({"seconds": seconds, "report": rep})
    return m


def compare(args, model, workdir):
    fails = []
    name = os.path.basename(model)
    a = ours(args.slivermesh, model, workdir)
    target = a["n_tets"]
    # tetgen: about 2.05 tets per unit of the volume bound on the unit cube.
    start = 2.05 * a["volume"] / max(target, 1)

    def at(v):
        r = run_tetgen(args.tetgen, model, workdir, v, args.quality)
        xyz, tets = read_node_ele(r["stem"])
        r.update(measure(xyz, tets))
        return r

    _, b = match_count(at, target, start, 1.0, args.count_tol / 2, 6, "tetgen",
                       log=lambda s: None)
    rep = a["report"]
    share = rep.get("seconds_improvement", 0.0) / max(rep.get("seconds_total", 0.0), 1e-12)
    print("%-22s ours %7d tets min/max %6.2f/%6.2f below5 %5d flat/inv %d/%d  improve %4.0f%% of %.2fs"
          " | tetgen %7d tets min/max %6.2f/%6.2f below5 %5d"
          % (name, a["n_tets"], a["min_dihedral_deg"], a["max_dihedral_deg"],
             a["tets_below_deg"][0], a["n_flat"], a["n_negative"], 100 * share,
             rep.get("seconds_total", 0.0), b["n_tets"], b["min_dihedral_deg"],
             b["max_dihedral_deg"], b["tets_below_deg"][0]))
    if abs(b["n_tets"] / target - 1) > args.count_tol:
        fails.append("%s: tet counts differ: ours %d, tetgen %d" % (name, target, b["n_tets"]))
    if a["n_flat"] or a["n_negative"]:
        fails.append("%s: %d flat and %d inverted tets" % (name, a["n_flat"], a["n_negative"]))
    if a["tets_below_deg"][0] > b["tets_below_deg"][0]:
        fails.append("%s: %d tets below 5 degrees, tetgen %d"
                     % (name, a["tets_below_deg"][0], b["tets_below_deg"][0]))
    if a["min_dihedral_deg"] < b["min_dihedral_deg"]:
        fails.append("%s: min dihedral %.3f below tetgen's %.3f"
                     % (name, a["min_dihedral_deg"], b["min_dihedral_deg"]))
    if args.max_dihedral and a["max_dihedral_deg"] > b["max_dihedral_deg"]:
        fails.append("%s: max dihedral %.3f above tetgen's %.3f"
                     % (name, a["max_dihedral_deg"], b["max_dihedral_deg"]))
    if args.acute_free and not (a["min_dihedral_deg"] >= 25.0 and a["max_dihedral_deg"] <= 160.0):
        fails.append("%s: dihedral range %.3f / %.3f outside [25, 160]"
                     % (name, a["min_dihedral_deg"], a["max_dihedral_deg"]))
    return fails


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="+")
    ap.add_argument("--slivermesh", default=os.path.join(here, "..", "target", "release", "slivermesh"))
    ap.add_argument("--tetgen", default=shutil.which("tetgen") or "tetgen")
    ap.add_argument("--quality", default="1.414")
    ap.add_argument("--count-tol", type=float, default=0.25)
    ap.add_argument("--max-dihedral", action="store_true",
                    help="also require our largest dihedral angle to be at most tetgen's")
    ap.add_argument("--acute-free", action="store_true",
                    help="also require min dihedral >= 25 and max <= 160 degrees")
    args = ap.parse_args()
    fails = []
    for model in args.models:
        with tempfile.TemporaryDirectory(prefix="sm-vs-tetgen-") as wd:
            try:
                fails += compare(args, model, wd)
            except Failure as e:
                fails.append("%s: %s" % (os.path.basename(model), e))
    for f in fails:
        print("FAIL: " + f)
    print("models compared: %d, failing: %d" % (len(args.models),
                                                   len({f.split(":")[0] for f in fails})))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
