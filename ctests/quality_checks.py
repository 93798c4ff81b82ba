#!/usr/bin/env python3
"""End-to-end checks of `slivermesh quality` (and `mesh --quality-svg`) against an independent
computation in plain Python floats.

Usage: quality_checks.py --slivermesh EXE [--tetgen EXE] [--model FILE.poly]

  * a tetgen -pq1.414 mesh of --model (skipped, with a message, without --tetgen): every
    figure of `quality --stats-json` equals this script's own (face-normal cosines + acos for
    the angles, not the library's sine form; nearest-rank percentiles);
  * the same mesh with 5 tets inverted and 1 of zero volume, as .node/.ele, and rewritten here as
    medit .mesh, gmsh .msh 4.1 and 2.2 and VTK .vtu (another writer than ours): the readers accept it
    and every format gives the same figures, inverted 5 and zero-volume 1;
  * the SVG parses as XML and holds the bars (one per non-empty 1-degree bin) and the four
    threshold lines; --compare shows both meshes; the text has two-decimal angles;
  * bad input (missing file, unknown extension, out-of-range vertex id, a surface-only mesh):
    exit status 1, `error: ` naming the file (and line), never a panic;
  * `slivermesh mesh --quality-svg` writes a well-formed picture and prints the table.
Each check prints PASS/FAIL; exit status 1 when any failed. Standard library only.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_tetgen import read_node_ele  # noqa: E402

FAILURES = []
SVG_NS = "{http://www.w3.org/2000/svg}"
BELOW = (5.0, 10.0, 15.0, 20.0)
ABOVE = (160.0, 165.0, 170.0, 175.0)


def check(name, cond, detail=""):
    print("%s  %s%s" % ("PASS" if cond else "FAIL", name, "" if cond else ": " + detail))
    if not cond:
        FAILURES.append(name)


def run(cmd, cwd=None):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd)
    return p.returncode, p.stdout, p.stderr


# --- the independent measure ----------------------------------------------------------------------

def sub(p, q):
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(a):
    return math.sqrt(dot(a, a))


def tet_measures(p):
    """(det, min dihedral, max dihedral, rho, sigma, aspect) of one tet, or flat values."""
    a, b, c = sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])
    det = dot(a, cross(b, c))
    lens = [norm(sub(p[i], p[j])) for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))]
    if det == 0.0:
        return det, 0.0, 180.0, math.inf, 0.0, math.inf
    # Face normals opposite vertex k, all pointing the same way; dihedral angle at the edge
    # shared by faces k and l: acos(-n_k.n_l / |n_k||n_l|).
    n1, n2, n3 = cross(b, c), cross(c, a), cross(a, b)
    n0 = (-(n1[0] + n2[0] + n3[0]), -(n1[1] + n2[1] + n3[1]), -(n1[2] + n2[2] + n3[2]))
    ns = (n0, n1, n2, n3)
    angles = []
    for k in range(4):
        for m in range(k + 1, 4):
            cs = -dot(ns[k], ns[m]) / (norm(ns[k]) * norm(ns[m]))
            angles.append(math.degrees(math.acos(max(-1.0, min(1.0, cs)))))
    vol = abs(det) / 6.0
    lmin = min(lens)
    la, lb, lc = dot(a, a), dot(b, b), dot(c, c)
    o = tuple(la * n1[i] + lb * n2[i] + lc * n3[i] for i in range(3))
    r_big = norm(o) / (2.0 * abs(det))
    area = sum(norm(n) for n in ns) / 2.0
    r_in = 3.0 * vol / area
    return det, min(angles), max(angles), r_big / lmin, vol / lmin ** 3, r_big / (3.0 * r_in)


def nearest_rank(sorted_values, pct):
    n = len(sorted_values)
    return sorted_values[min(n, max(1, math.ceil(pct / 100.0 * n))) - 1]


def figures(xyz, tets):
    per = [tet_measures([xyz[v] for v in t]) for t in tets]
    mins = sorted(m[1] for m in per)
    maxs = sorted(m[2] for m in per)
    rhos = sorted(m[3] for m in per)
    sigmas = sorted(m[4] for m in per)
    aspects = sorted(m[5] for m in per)
    return {
        "n_tets": len(tets),
        "n_inverted": sum(1 for m in per if m[0] < 0.0),
        "n_zero_volume": sum(1 for m in per if m[0] == 0.0),
        "volume": sum(m[0] for m in per) / 6.0,
        "min_dihedral_deg": mins[0], "max_dihedral_deg": maxs[-1],
        "min_dihedral_p1_deg": nearest_rank(mins, 1), "min_dihedral_p5_deg": nearest_rank(mins, 5),
        "min_dihedral_median_deg": nearest_rank(mins, 50),
        "max_dihedral_median_deg": nearest_rank(maxs, 50),
        "max_dihedral_p95_deg": nearest_rank(maxs, 95), "max_dihedral_p99_deg": nearest_rank(maxs, 99),
        "tets_below_deg": [sum(1 for x in mins if x < t) for t in BELOW],
        "tets_above_deg": [sum(1 for x in maxs if x > t) for t in ABOVE],
        "max_rho": rhos[-1], "median_rho": nearest_rank(rhos, 50),
        "min_sigma": sigmas[0], "median_sigma": nearest_rank(sigmas, 50),
        "max_aspect": aspects[-1], "median_aspect": nearest_rank(aspects, 50),
        "min_dihedral_histogram": [sum(1 for x in mins if 5 * k <= x < 5 * (k + 1)) for k in range(14)]
                                  + [sum(1 for x in mins if x >= 70)],
    }


def compare_figures(label, got, want, tol=1e-7):
    """Every key of want equals got's (floats within tol relative to max(1, |want|); serde
    writes +inf as null)."""
    for k, w in want.items():
        g = got.get(k)
        if isinstance(w, float):
            if math.isinf(w):
                ok = g is None
            else:
                ok = isinstance(g, (int, float)) and abs(g - w) <= tol * max(1.0, abs(w))
        else:
            ok = g == w
        check("%s: %s" % (label, k), ok, "slivermesh %r, independent %r" % (g, w))


# --- writing the same mesh in the other formats (another writer than the library's) ---------------

def write_medit(path, xyz, tets):
    with open(path, "w") as f:
        f.write("MeshVersionFormatted 2\nDimension\n3\n\nVertices\n%d\n" % len(xyz))
        for p in xyz:
            f.write("%r %r %r 0\n" % p)
        f.write("\nTetrahedra\n%d\n" % len(tets))
        for t in tets:
            f.write("%d %d %d %d 1\n" % tuple(v + 1 for v in t))
        f.write("\nEnd\n")


def write_msh41(path, xyz, tets):
    with open(path, "w") as f:
        f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        f.write("$Entities\n1 0 0 1\n1 0 0 0 0\n1 0 0 0 1 1 1 1 7 0\n$EndEntities\n")
        n = len(xyz)
        # Nodes in two blocks (one on the point entity), tags not in vertex order.
        f.write("$Nodes\n2 %d 1 %d\n0 1 0 1\n%d\n%r %r %r\n3 1 0 %d\n" % (n, n, n, *xyz[-1], n - 1))
        for i in range(n - 1):
            f.write("%d\n" % (i + 1))
        for p in xyz[:-1]:
            f.write("%r %r %r\n" % p)
        f.write("$EndNodes\n")
        f.write("$Elements\n2 %d 1 %d\n0 1 15 1\n%d %d\n3 1 4 %d\n" % (len(tets) + 1, len(tets) + 1,
                                                                     len(tets) + 1, n, len(tets)))
        for i, t in enumerate(tets):
            f.write("%d %d %d %d %d\n" % (i + 1, *(v + 1 for v in t)))
        f.write("$EndElements\n")


def write_msh22(path, xyz, tets):
    with open(path, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(xyz))
        for i, p in enumerate(xyz):
            f.write("%d %r %r %r\n" % (i + 1, *p))
        f.write("$EndNodes\n$Elements\n%d\n" % len(tets))
        for i, t in enumerate(tets):
            f.write("%d 4 2 7 1 %d %d %d %d\n" % (i + 1, *(v + 1 for v in t)))
        f.write("$EndElements\n")


def write_vtu(path, xyz, tets):
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" '
                'byte_order="LittleEndian">\n<UnstructuredGrid>\n<Piece NumberOfPoints="%d" '
                'NumberOfCells="%d">\n<Points>\n<DataArray type="Float64" NumberOfComponents="3" '
                'format="ascii">\n' % (len(xyz), len(tets)))
        f.write("\n".join("%r %r %r" % p for p in xyz))
        f.write('\n</DataArray>\n</Points>\n<Cells>\n<DataArray type="Int32" Name="connectivity" '
                'format="ascii">\n')
        f.write("\n".join("%d %d %d %d" % t for t in tets))
        f.write('\n</DataArray>\n<DataArray type="Int32" Name="offsets" format="ascii">\n')
        f.write(" ".join(str(4 * (i + 1)) for i in range(len(tets))))
        f.write('\n</DataArray>\n<DataArray type="UInt8" Name="types" format="ascii">\n')
        f.write(" ".join("10" for _ in tets))
        f.write("\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def write_node_ele(stem, xyz, tets):
    with open(stem + ".node", "w") as f:
        f.write("%d 3 0 0\n" % len(xyz))
        for i, p in enumerate(xyz):
            f.write("%d %r %r %r\n" % (i + 1, *p))
    with open(stem + ".ele", "w") as f:
        f.write("%d 4 0\n" % len(tets))
        for i, t in enumerate(tets):
            f.write("%d %d %d %d %d\n" % (i + 1, *(v + 1 for v in t)))


# --- the checks ------------------------------------------------------------------------------------

def quality_json(exe, path, tmp, extra=()):
    js = os.path.join(tmp, "q.json")
    if os.path.exists(js):
        os.remove(js)
    code, out, err = run([exe, "quality", path, "--stats-json", js] + list(extra))
    check("quality %s: exit 0" % os.path.basename(path), code == 0, err)
    if code != 0:
        return None, out
    with open(js) as f:
        return json.load(f), out


def check_svg(label, path, n_series):
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        check("%s: SVG is well-formed XML" % label, False, str(e))
        return
    check("%s: SVG is well-formed XML" % label, root.tag == SVG_NS + "svg", root.tag)
    bars = [e for e in root.iter() if e.get("class") == "bar"]
    lines = [e for e in root.iter() if e.get("class") == "threshold"]
    check("%s: SVG has histogram bars" % label, len(bars) > 20, str(len(bars)))
    check("%s: SVG has the four threshold lines" % label, len(lines) == 4, str(len(lines)))
    labels = [e.text for e in root.iter(SVG_NS + "text") if e.text and e.text[:-1].isdigit() and e.text.endswith("\u00b0")]
    check("%s: lines labelled 5/10/15/20" % label, labels == ["5\u00b0", "10\u00b0", "15\u00b0", "20\u00b0"],
          repr(labels))
    outline = [e for e in root.iter() if e.get("id") == "outline"]
    check("%s: %d mesh(es) drawn" % (label, n_series), len(outline) == n_series - 1, str(len(outline)))
    return bars


def error_case(exe, name, args, must_contain):
    code, out, err = run([exe] + args)
    check("%s: exit status 1" % name, code == 1, "got %d, stderr %r" % (code, err))
    check("%s: no panic" % name, "panicked" not in err, repr(err))
    for needle in must_contain:
        check("%s: message mentions %r" % (name, needle), needle in err, repr(err))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--tetgen")
    ap.add_argument("--model", help="a .poly for tetgen and `slivermesh mesh`")
    ap.add_argument("--fudge", type=float, default=0.0,
                    help="add this many degrees to the independent minimum dihedral angle (a "
                         "ctest checks that 1e-4 is caught)")
    args = ap.parse_args()
    exe = args.slivermesh
    if not os.access(exe, os.X_OK):
        print("error: slivermesh binary not found: %s" % exe, file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="slivermesh-quality-") as tmp:
        tetgen = args.tetgen and shutil.which(args.tetgen)
        if not tetgen or not args.model:
            print("SKIP  tetgen checks: no tetgen (apt-get install tetgen) or no --model")
        else:
            d = os.path.join(tmp, "tg")
            os.makedirs(d)
            shutil.copyfile(args.model, os.path.join(d, "in.poly"))
            code, _, err = run([tetgen, "-pq1.414a0.02Q", "in.poly"], cwd=d)
            check("tetgen ran", code == 0, err)
            stem = os.path.join(d, "in.1")
            xyz, tets = read_node_ele(stem)
            want = figures(xyz, tets)
            want["min_dihedral_deg"] += args.fudge
            got, out = quality_json(exe, stem + ".ele", tmp)
            if got:
                compare_figures("tetgen mesh", got, want)
                row = [l for l in out.splitlines() if "dihedral min / max" in l]
                check("text: dihedral min/max with two decimals",
                      row and "%.2f / %.2f" % (want["min_dihedral_deg"], want["max_dihedral_deg"]) in row[0],
                      repr(row))
                check("text: histogram printed", "tets by minimum dihedral angle" in out, out)
            # Inverted and zero-volume tets, in every format we read.
            bad = list(tets)
            for i in range(5):
                t = bad[10 * i]
                bad[10 * i] = (t[1], t[0], t[2], t[3])
            bad[7] = (bad[7][0], bad[7][0], bad[7][2], bad[7][3])
            want_bad = figures(xyz, bad)
            check("independent: 5 inverted, 1 zero volume",
                  (want_bad["n_inverted"], want_bad["n_zero_volume"]) == (5, 1), str(want_bad))
            paths = [os.path.join(tmp, "bad.ele"), os.path.join(tmp, "bad.mesh"),
                     os.path.join(tmp, "bad.msh"), os.path.join(tmp, "bad.vtu"),
                     os.path.join(tmp, "bad22.msh")]
            write_node_ele(paths[0][:-4], xyz, bad)
            write_medit(paths[1], xyz, bad)
            write_msh41(paths[2], xyz, bad)
            write_vtu(paths[3], xyz, bad)
            write_msh22(paths[4], xyz, bad)
            for p in paths:
                got, out = quality_json(exe, p, tmp)
                if got:
                    compare_figures("inverted mesh " + os.path.basename(p), got, want_bad)
                    check("%s: note about invalid tets" % os.path.basename(p),
                          "5 inverted and 1 zero-volume" in out, out)
            # The picture and the comparison.
            svg = os.path.join(tmp, "tg.svg")
            got, out = quality_json(exe, stem + ".ele", tmp, ["--svg", svg, "--compare", paths[1]])
            if got:
                check("compare JSON has both meshes", "mesh" in got and "other" in got, str(list(got)))
                compare_figures("compare: mesh", got.get("mesh", {}), {"n_tets": want["n_tets"]})
                compare_figures("compare: other", got.get("other", {}), {"n_inverted": 5})
                head = out.splitlines()[0] if out else ""
                check("compare table heads both names", stem + ".ele" in head and paths[1] in head, head)
                inv = [l for l in out.splitlines() if "inverted / zero-volume" in l]
                check("compare row shows both", inv and inv[0].split()[-3:] == ["5", "/", "1"], repr(inv))
                check_svg("compare", svg, 2)
            svg1 = os.path.join(tmp, "one.svg")
            code, _, err = run([exe, "quality", stem + ".ele", "--svg", svg1])
            bars = check_svg("tetgen", svg1, 1)
            if bars is not None:
                nonempty = set()
                for t in tets:
                    p = [xyz[v] for v in t]
                    a, b, c = sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])
                    n1, n2, n3 = cross(b, c), cross(c, a), cross(a, b)
                    n0 = tuple(-(n1[i] + n2[i] + n3[i]) for i in range(3))
                    ns = (n0, n1, n2, n3)
                    for k in range(4):
                        for m in range(k + 1, 4):
                            cs = -dot(ns[k], ns[m]) / (norm(ns[k]) * norm(ns[m]))
                            nonempty.add(min(179, int(math.degrees(math.acos(max(-1.0, min(1.0, cs)))))))
                # A bin edge can flip one angle between neighbouring bins: allow a couple.
                check("tetgen: one bar per non-empty 1-degree bin",
                      abs(len(bars) - len(nonempty)) <= 2, "%d bars, %d bins" % (len(bars), len(nonempty)))

        # --- bad input
        error_case(exe, "missing file", ["quality", os.path.join(tmp, "nope.mesh")],
                   ["nope.mesh", "cannot read"])
        error_case(exe, "unknown extension", ["quality", os.path.join(tmp, "x.obj")],
                   ["x.obj", "unsupported mesh format"])
        stem = os.path.join(tmp, "range")
        write_node_ele(stem, [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)],
                       [(0, 1, 2, 3), (0, 1, 2, 7)])
        error_case(exe, "out-of-range vertex id (.ele)", ["quality", stem + ".ele"], [stem + ".ele:3:"])
        mesh = os.path.join(tmp, "range.mesh")
        write_medit(mesh, [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)],
                    [(0, 1, 2, 4)])
        error_case(exe, "out-of-range vertex id (.mesh)", ["quality", mesh], [mesh + ":"])
        surf = os.path.join(tmp, "surface.mesh")
        with open(surf, "w") as f:
            f.write("MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
                    "Triangles\n1\n1 2 3 0\nEnd\n")
        error_case(exe, "surface-only mesh", ["quality", surf], [surf, "no tetrahedra"])
        error_case(exe, "bad --compare", ["quality", mesh.replace("range", "nope"), "--compare", mesh],
                   ["nope.mesh"])

        # --- mesh --quality-svg
        if args.model:
            svg = os.path.join(tmp, "mesh.svg")
            out_mesh = os.path.join(tmp, "m.mesh")
            code, out, err = run([exe, "mesh", args.model, "--size", "0.3", "-o", out_mesh,
                                  "--quality-svg", svg])
            check("mesh --quality-svg: exit 0", code == 0, err)
            check("mesh prints the quality table of its output", "quality of %s" % out_mesh in out
                  and "tet min dihedral p1/p5/p50" in out, out)
            check_svg("mesh --quality-svg", svg, 1)
            got, qout = quality_json(exe, out_mesh, tmp)
            head = "quality of %s\n" % out_mesh
            ours = out.split(head)[-1].split("\nwrote ")[0].strip()
            theirs = qout.split(head)[-1].split("tets by")[0].strip()
            check("mesh's table = quality's table of the written file",
                  head in out and ours == theirs, "mesh:\n%s\nquality:\n%s" % (ours, theirs))
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
