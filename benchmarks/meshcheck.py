"""Cost of the mesh checks (meshcheck.validate_mesh) against one linear solve on the same mesh.

ElasticProblem and crack_step validate every mesh they get, so the check must stay a small
fraction of a solve. For unit-square netgen meshes: t_solve is the sparse Cholesky
factorisation + solve of linear elasticity (as in benchmarks/crack.py, assembly not counted,
so the ratio is pessimistic); t_check is validate_mesh on the mesh, t_check_cracked on the
same mesh after one crack pass that splits about 1% of the vertices (crack lips coincide:
the coincident-vertex check has work to do). Checks are the best of `--repeat` runs.
Writes JSON (stdout, or the file of `--json FILE`) {"cases": [{"ntri", "t_check", "t_check_cracked", "t_solve", "ratio"}]} with
ratio = t_check / t_solve.

Usage: python benchmarks/meshcheck.py [--sizes 10000 100000 ...] [--repeat 5] [--threads 2] [--json FILE [--force]]
"""
import argparse
import time

import ngsolve

import benchmark_json
from ngfracture.geometry.meshcheck import validate_mesh
from crack import crack_pass, plate, solve_stretch     # the sibling benchmark's mesh and solve


def best_time(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 100000])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    benchmark_json.add_options(ap)
    args = ap.parse_args(argv)
    benchmark_json.refuse_existing(ap, args)
    ngsolve.SetNumThreads(args.threads)
    cases = []
    for n in args.sizes:
        mesh = plate(n)
        u, t_solve = solve_stretch(mesh)
        cracked = crack_pass(mesh, u)[1].mesh
        t_check = best_time(lambda: validate_mesh(mesh), args.repeat)
        t_cracked = best_time(lambda: validate_mesh(cracked), args.repeat)
        cases.append({"ntri": mesh.ne, "t_check": round(t_check, 6), "t_check_cracked": round(t_cracked, 6),
                      "t_solve": round(t_solve, 6), "ratio": round(t_check / t_solve, 5)})
    benchmark_json.write(args, {"cases": cases})


if __name__ == "__main__":
    main()
