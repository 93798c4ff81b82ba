#!/usr/bin/env python3
"""Gmsh 4.15 (PyPI) reads the binary .msh that `slivermesh mesh --binary` writes as it reads the
ASCII one of the same run: the same nodes (count and coordinate sum), the same element counts
per type, and the same physical groups (name and element count).

    msh_binary_readback.py --slivermesh BIN --input MODEL [--size H] --workdir DIR
"""
import argparse
import subprocess
import sys
from pathlib import Path

import gmsh


def summary(path):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(str(path))
        tags, coords, _ = gmsh.model.mesh.getNodes()
        types, etags, _ = gmsh.model.mesh.getElements()
        counts = {int(t): len(e) for t, e in zip(types, etags)}
        groups = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            n = 0
            for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                n += sum(len(e) for e in gmsh.model.mesh.getElements(dim, ent)[1])
            groups[gmsh.model.getPhysicalName(dim, tag)] = n
        return len(tags), round(float(sum(coords)), 9), counts, groups
    finally:
        gmsh.finalize()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--input", required=True)
    ap.add_argument("--size")
    ap.add_argument("--workdir", required=True)
    a = ap.parse_args()
    work = Path(a.workdir)
    work.mkdir(parents=True, exist_ok=True)
    extra = ["--size", a.size] if a.size else []
    got = {}
    for form, flags in [("ascii", []), ("binary", ["--binary"])]:
        out = work / f"{Path(a.input).stem}-{form}.msh"
        subprocess.run([a.slivermesh, "mesh", a.input, "-o", str(out)] + extra + flags,
                       check=True, stdout=subprocess.DEVNULL)
        got[form] = summary(out)
        print(f"{form}: {got[form]}")
    if got["ascii"] != got["binary"] or got["binary"][0] == 0:
        print("FAIL: gmsh reads the binary file differently from the ASCII one")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
