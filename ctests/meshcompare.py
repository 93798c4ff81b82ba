"""Shared helpers of the quality-meshing comparisons (compare_tetgen.py, compare_mesh3.py).

Standard library only: running a program with a wall-clock time, matching a tet count by
adjusting a size parameter, and the side-by-side table.
"""

import math
import os
import subprocess
import sys
import time


class Failure(Exception):
    """A check or a program run failed; the message says which and why."""


def run_timed(cmd, cwd=None):
    """Runs cmd, returns (stdout, wall seconds). Raises Failure with its stderr on a non-zero exit."""
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        tail = "\n".join((proc.stderr or proc.stdout).strip().splitlines()[-15:])
        raise Failure("command exited with status %d: %s\n%s"
                      % (proc.returncode, " ".join(map(str, cmd)), tail))
    return proc.stdout, seconds


def keep_surface(extra):
    """`slivermesh mesh` arguments that keep the input facets as given (`--surface keep`: the
    comparisons mesh the same facets as the other program; the CLI's default for .off/.stl/.ply/
    .obj is the approximate mode), unless `extra` chooses a surface mode itself."""
    if any(a == "--surface" or a.startswith("--surface=") for a in extra):
        return list(extra)
    return ["--surface", "keep"] + list(extra)


def check_executable(name, path):
    if not (path and os.path.isfile(path) and os.access(path, os.X_OK)):
        print("error: %s not found or not executable: %s" % (name, path), file=sys.stderr)
        return False
    return True


def match_count(run_at, target, start, exponent, tol, max_runs, label, log=print):
    """Finds a size parameter whose run gives about `target` tets.

    run_at(param) -> result dict with "n_tets". The tet count is modelled as param**(-exponent)
    (3 for a length, 1 for a volume); each step rescales param by (n / target)**(1 / exponent),
    with the exponent re-fitted from the last two runs when they differ enough. Stops when
    |n / target - 1| <= tol or after max_runs runs. Returns (param, result) of the closest run.
    """
    param, runs = start, []
    for _ in range(max_runs):
        res = run_at(param)
        n = res["n_tets"]
        runs.append((param, res))
        log("  %-12s param %.6g -> %d tets (target %d)" % (label, param, n, target))
        if abs(n / target - 1.0) <= tol:
            break
        e = exponent
        if len(runs) >= 2:
            (p0, r0), (p1, r1) = runs[-2], runs[-1]
            n0, n1 = r0["n_tets"], r1["n_tets"]
            if p0 != p1 and n0 > 0 and n1 > 0 and n0 != n1:
                fit = -math.log(n1 / n0) / math.log(p1 / p0)
                if 0.3 * exponent <= fit <= 3.0 * exponent:
                    e = fit
        param *= (n / target) ** (1.0 / e)
    return min(runs, key=lambda pr: abs(pr[1]["n_tets"] / target - 1.0))


def size_args(h, spec="%.10g"):
    """slivermesh's size arguments for size h: `--size h`, or none for h = 0 (its default,
    graded spacing)."""
    return ["--size", spec % h] if h else []


def fmt(v, spec):
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, (list, tuple)):
        return "/".join(str(x) for x in v)
    return format(v, spec)


def table(rows, ref, ours, ref_name, ours_name="slivermesh"):
    """Side-by-side rows (label, key, format spec, ratio?): the reference program left, ours right,
    and where ratio is true the column ours / reference."""
    out = ["%-26s %16s %16s %12s" % ("", ref_name, ours_name, "%s/%s" % ("ours", ref_name))]
    for label, key, spec, ratio in rows:
        a, b = ref.get(key), ours.get(key)
        r = ""
        if ratio and isinstance(a, (int, float)) and isinstance(b, (int, float)) and a:
            r = "%.3f" % (b / a)
        out.append("%-26s %16s %16s %12s" % (label, fmt(a, spec), fmt(b, spec), r))
    return "\n".join(out)
