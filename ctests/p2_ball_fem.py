#!/usr/bin/env python3
"""A real FEM code on our ten-node tets: scikit-fem solves -Laplace(u) = 1 in the unit ball
with u = 0 on the sphere (exact u = (1 - r^2) / 6) with P2 elements, on the curved mesh
(`skfem.MeshTet2.load` of our `--order 2` .msh) and on the same tets with straight edges, and
compares the L2 errors. The curved boundary must make P2 at least MIN_GAIN times more accurate.

Usage: p2_ball_fem.py SLIVERMESH [SIZE]   (meshes a fine icosphere itself)
Exit 0 with a SKIP line when scikit-fem is not installed.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

MIN_GAIN = 10.0
LEVEL = 6  # 20 * 4^6 = 81,920 triangles


def icosphere(level):
    g = (1 + 5 ** 0.5) / 2
    v = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g),
         (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = v[a] + v[b]
                v.append(m / np.linalg.norm(m))
                cache[key] = len(v) - 1
            return cache[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return v, f


def write_off(path, v, f):
    with open(path, "w") as out:
        out.write(f"OFF\n{len(v)} {len(f)} 0\n")
        out.writelines(f"{p[0]:.17g} {p[1]:.17g} {p[2]:.17g}\n" for p in v)
        out.writelines(f"3 {a} {b} {c}\n" for a, b, c in f)


def solve(mesh):
    """L2 error of P2 for -Laplace(u) = 1, u = 0 on the boundary, on `mesh`."""
    from skfem import Basis, BilinearForm, ElementTetP2, Functional, LinearForm, condense, solve
    from skfem.helpers import dot, grad

    @BilinearForm
    def laplace(u, v, _):
        return dot(grad(u), grad(v))

    @LinearForm
    def one(v, _):
        return v

    @Functional
    def error2(w):
        r2 = w.x[0] ** 2 + w.x[1] ** 2 + w.x[2] ** 2
        return (w["uh"] - (1 - r2) / 6) ** 2

    basis = Basis(mesh, ElementTetP2(), intorder=6)
    a, b = laplace.assemble(basis), one.assemble(basis)
    u = solve(*condense(a, b, D=basis.get_dofs()))
    return np.sqrt(error2.assemble(basis, uh=basis.interpolate(u)))


def main():
    try:
        import skfem
    except ImportError:
        print("SKIP: scikit-fem is not installed (pip install scikit-fem)")
        return 0
    binary = sys.argv[1]
    size = sys.argv[2] if len(sys.argv) > 2 else "0.15"
    with tempfile.TemporaryDirectory() as tmp:
        off, msh = os.path.join(tmp, "sphere.off"), os.path.join(tmp, "ball.msh")
        write_off(off, *icosphere(LEVEL))
        run = subprocess.run([binary, "mesh", off, "--order", "2", "--size", size, "-o", msh],
                             capture_output=True, text=True)
        if run.returncode != 0:
            print(run.stdout, run.stderr)
            return 1
        curved = skfem.MeshTet2.load(msh)
    straight = skfem.MeshTet(curved.p, curved.t)
    e_curved, e_straight = solve(curved), solve(straight)
    gain = e_straight / e_curved
    print(f"{curved.t.shape[1]} tets: P2 L2 error {e_curved:.3e} curved, {e_straight:.3e} "
          f"straight: {gain:.1f}x (need {MIN_GAIN}x)")
    return 0 if gain >= MIN_GAIN else 1


if __name__ == "__main__":
    sys.exit(main())
