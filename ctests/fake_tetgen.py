#!/usr/bin/env python3
"""A stand-in for tetgen that proves compare_tetgen.py can fail.

Called as `fake_tetgen.py -pq1.414a<V>Q input.poly` in a directory, it ignores the input (it
assumes the unit cube) and writes input.1.node / input.1.ele with the Kuhn subdivision of an
n x n x n grid (6 n^3 tets, about as many as tetgen would make for the volume bound V), whose
smallest dihedral angle is 45 degrees: better than slivermesh's, so the comparison must report
"FAIL: slivermesh's minimum dihedral angle ... is not larger than tetgen's".
"""

import itertools
import re
import sys


def main():
    m = re.search(r"a([0-9.eE+-]+)", sys.argv[1]) if len(sys.argv) == 3 else None
    if not m:
        print("usage: fake_tetgen.py -pq<Q>a<V>Q input.poly", file=sys.stderr)
        return 2
    stem = sys.argv[2].rsplit(".", 1)[0] + ".1"
    n = max(1, round((2.05 / float(m.group(1)) / 6.0) ** (1.0 / 3.0)))

    def vid(i, j, k):
        return (i * (n + 1) + j) * (n + 1) + k + 1

    with open(stem + ".node", "w") as f:
        f.write("%d 3 0 0\n" % (n + 1) ** 3)
        for i, j, k in itertools.product(range(n + 1), repeat=3):
            f.write("%d %.17g %.17g %.17g\n" % (vid(i, j, k), i / n, j / n, k / n))
    tets = []
    for i, j, k in itertools.product(range(n), repeat=3):
        for perm in itertools.permutations(range(3)):
            c = [i, j, k]
            t = [vid(*c)]
            for axis in perm:
                c[axis] += 1
                t.append(vid(*c))
            # Odd permutations give negatively oriented tets: swap two corners.
            inversions = sum(1 for a in range(3) for b in range(a + 1, 3) if perm[a] > perm[b])
            if inversions % 2:
                t[2], t[3] = t[3], t[2]
            tets.append(t)
    with open(stem + ".ele", "w") as f:
        f.write("%d 4 0\n" % len(tets))
        for idx, t in enumerate(tets, 1):
            f.write("%d %d %d %d %d\n" % (idx, t[0], t[1], t[2], t[3]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
