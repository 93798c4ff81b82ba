#!/usr/bin/env python3
"""Does the thread count change the mesh? Meshes every shared model in both surface modes with
`--threads 1` and `--threads 2` and compares the written .mesh files byte for byte; prints each
run's peak memory in bytes a tet (`bytes_per_tet` of --stats-json, whole process).

Usage: threads_identical.py --slivermesh EXE --models DIR [--quick]

Models as scripts/compare-binaries takes them: keep mode on DIR/poly/*.poly, off/cube.off and
off/cross.off; approximate mode on DIR/off/*.off and DIR/scans/*.off (--quick leaves out the two
slowest scans, cheese and dino, as the ctest does). Exit status 1 when any pair differs or a run
fails. Standard library only.
"""

import argparse
import glob
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time


def runs(models, quick):
    keep = sorted(glob.glob(os.path.join(models, "poly", "*.poly")))
    keep += [os.path.join(models, "off", m) for m in ("cube.off", "cross.off")]
    approximate = sorted(glob.glob(os.path.join(models, "off", "*.off")))
    approximate += sorted(glob.glob(os.path.join(models, "scans", "*.off")))
    if quick:
        approximate = [m for m in approximate
                       if os.path.basename(m) not in ("cheese.off", "dino.off")]
    return [("keep", m) for m in keep] + [("approximate", m) for m in approximate]


def mesh(exe, model, mode, threads, tmp):
    out = os.path.join(tmp, "t%d.mesh" % threads)
    stats = os.path.join(tmp, "t%d.json" % threads)
    for path in (out, stats):
        if os.path.exists(path):
            os.remove(path)
    start = time.time()
    p = subprocess.run([exe, "mesh", model, "-o", out, "--surface", mode,
                        "--threads", str(threads), "--stats-json", stats],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seconds = time.time() - start
    if p.returncode != 0:
        return None, None, seconds, p.stderr.strip().splitlines()[-1:] or ["(no message)"]
    with open(out, "rb") as f:
        digest = hashlib.md5(f.read()).hexdigest()
    with open(stats) as f:
        per_tet = json.load(f).get("bytes_per_tet")
    return digest, per_tet, seconds, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--models", required=True)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    failures = 0
    print("%-6s %-11s %-28s %-10s %-15s %s" % ("", "mode", "model", "md5", "bytes/tet 1|2",
                                              "seconds 1|2"))
    with tempfile.TemporaryDirectory() as tmp:
        for mode, model in runs(args.models, args.quick):
            one = mesh(args.slivermesh, model, mode, 1, tmp)
            two = mesh(args.slivermesh, model, mode, 2, tmp)
            name = os.path.relpath(model, args.models)
            if one[3] or two[3]:
                print("FAIL   %-11s %-28s run failed: %s" % (mode, name, one[3] or two[3]))
                failures += 1
                continue
            same = one[0] == two[0]
            failures += not same
            print("%-6s %-11s %-28s %-10s %6.0f | %-6.0f %6.1f | %.1f" % (
                "same" if same else "DIFFER", mode, name, one[0][:8], one[1] or 0, two[1] or 0,
                one[2], two[2]))
    print("%d of %d runs differ or failed" % (failures, len(runs(args.models, args.quick))))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
