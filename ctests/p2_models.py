#!/usr/bin/env python3
"""Ten-node tets on real models, checked by Gmsh: `slivermesh mesh MODEL --order 2 -o M.msh`
(ASCII and binary), opened with the gmsh module; every element's `minSJ` (Gmsh's Jacobian-based
validity measure of curved elements) must be above 0, and the element count must match the
run's report. Prints the smallest minSJ next to the report's own bound.

Usage: p2_models.py --slivermesh EXE --workdir DIR MODEL [MODEL ...]
Exit 0 with a SKIP line when the gmsh module is not installed.
"""
import argparse
import json
import os
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("models", nargs="+")
    a = ap.parse_args()
    try:
        import gmsh
    except ImportError:
        print("SKIP: the gmsh python module is not installed (pip install gmsh)")
        return 0
    import numpy as np

    os.makedirs(a.workdir, exist_ok=True)
    failures = []
    gmsh.initialize()
    gmsh.option.setNumber("General.Verbosity", 1)
    for model in a.models:
        name = os.path.splitext(os.path.basename(model))[0]
        for binary in (False, True):
            msh = os.path.join(a.workdir, f"{name}{'_bin' if binary else ''}.msh")
            stats = msh + ".json"
            cmd = [a.slivermesh, "mesh", model, "--order", "2", "-o", msh, "--stats-json", stats]
            run = subprocess.run(cmd + (["--binary"] if binary else []),
                                 capture_output=True, text=True)
            if run.returncode != 0:
                failures.append(f"{name}: slivermesh failed: {run.stderr.strip()[-400:]}")
                continue
            report = json.load(open(stats))
            gmsh.clear()
            gmsh.open(msh)
            types, tags, _ = gmsh.model.mesh.getElements(3)
            if list(types) != [11]:
                failures.append(f"{name}: element types {list(types)}, want [11] (10-node tets)")
                continue
            quality = np.asarray(gmsh.model.mesh.getElementQualities(tags[0], "minSJ"))
            q = report["quadratic"]
            print(f"{name}{' (binary)' if binary else ''}: {len(tags[0])} tets, gmsh minSJ min "
                  f"{quality.min():.4f}, elements <= 0: {(quality <= 0).sum()}; report: "
                  f"{q['n_curved_edges']} curved edges, {q['n_straightened_edges']} "
                  f"straightened, {q['n_moved_interior_nodes']} interior nodes moved, "
                  f"Jacobian ratio bound {q['min_jacobian_ratio']:.4f}")
            if len(tags[0]) != report["n_tets"]:
                failures.append(f"{name}: gmsh read {len(tags[0])} tets, report {report['n_tets']}")
            if not quality.min() > 0:
                failures.append(f"{name}: {(quality <= 0).sum()} elements with minSJ <= 0")
    gmsh.finalize()
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
