#!/usr/bin/env python3
"""Before/after table of the refinement on every model at its default spacing (surface files
in keep mode: `--surface keep` when the binary has that flag).

    scripts/refine-table.py MODELS_DIR BINARY OUT_DIR [--runs N] [--only NAME,...]

MODELS_DIR holds poly/ and off/ (the shared test models); BINARY is a release `slivermesh`;
OUT_DIR receives one .mesh and one .json per model (the meshes to diff against another run).
Prints a markdown table: tets, wall time (median of N runs), max rho, min dihedral, tets below
5 and 15 degrees, and tets left missing a bound near small angles (n_bad_near_acute). Time is
the process's CPU time (user + sys), less sensitive than wall time to a loaded machine; the
median wall time is printed too.
Timings are only comparable between binaries measured in the same invocation of this script
on the same machine load, so pass several binaries to compare them run by run:

    scripts/refine-table.py MODELS_DIR OLD_BIN,NEW_BIN OUT_OLD,OUT_NEW
"""

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path


def models(root: Path, only):
    found = sorted(root.glob("poly/*.poly")) + sorted(root.glob("off/*.off"))
    if only:
        found = [m for m in found if f"{m.parent.name}/{m.stem}" in only or m.stem in only]
    return found


def keep_args(binary: str):
    """`--surface keep` when the binary has it (the refinement of the input facets as given;
    its default for .off files is the approximate mode), nothing for an older binary."""
    help_text = subprocess.run(
        [binary, "mesh", "--help"], capture_output=True, text=True, check=True
    ).stdout
    return ["--surface", "keep"] if "--surface <MODE>" in help_text else []


def run_once(binary: str, model: Path, out: Path):
    mesh = out / f"{model.parent.name}-{model.stem}.mesh"
    stats = out / f"{model.parent.name}-{model.stem}.json"
    extra = keep_args(binary)
    t0 = time.perf_counter()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(
        [binary, "mesh", str(model), "-o", str(mesh), "--stats-json", str(stats)] + extra,
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return wall, cpu, json.loads(stats.read_text())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models_dir", type=Path)
    ap.add_argument("binaries", help="one binary, or several separated by commas")
    ap.add_argument("out_dirs", help="one output directory per binary, separated by commas")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--only", default="", help="comma-separated model names")
    a = ap.parse_args()
    bins = a.binaries.split(",")
    outs = [Path(o) for o in a.out_dirs.split(",")]
    if len(bins) != len(outs):
        sys.exit("need one output directory per binary")
    for o in outs:
        o.mkdir(parents=True, exist_ok=True)
    only = set(filter(None, a.only.split(",")))
    cols = "model | " + " | ".join(
        f"{k}{'' if len(bins) == 1 else f' [{i}]'}"
        for i in range(len(bins))
        for k in ["tets", "cpu s", "wall s", "max rho", "min dih", "<5", "<15", "bad near acute"]
    )
    if len(bins) > 1:
        cols += " | mesh = [0]"
    print("| " + cols + " |")
    print("|" + "---|" * (1 + 8 * len(bins) + (len(bins) > 1)))
    for m in models(a.models_dir, only):
        times = [[] for _ in bins]
        walls = [[] for _ in bins]
        reports = [None for _ in bins]
        # Interleaved runs: each binary sees the same machine load, run by run.
        for _ in range(a.runs):
            for i, (b, o) in enumerate(zip(bins, outs)):
                w, t, r = run_once(b, m, o)
                times[i].append(t)
                walls[i].append(w)
                reports[i] = r
        cells = [f"{m.parent.name}/{m.stem}"]
        for i, r in enumerate(reports):
            cells += [
                str(r["n_tets"]),
                f"{statistics.median(times[i]):.3f}",
                f"{statistics.median(walls[i]):.3f}",
                f"{r['max_rho']:.3f}",
                f"{r['min_dihedral_deg']:.2f}",
                str(r["tets_below_deg"][0]),
                str(r["tets_below_deg"][2]),
                str(r["n_bad_near_acute"]),
            ]
        if len(bins) > 1:
            name = f"{m.parent.name}-{m.stem}.mesh"
            first = (outs[0] / name).read_bytes()
            cells.append(
                ",".join("yes" if (o / name).read_bytes() == first else "no" for o in outs[1:])
            )
        print("| " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
