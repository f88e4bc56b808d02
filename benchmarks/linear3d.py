"""The linear solvers of a 3D problem against its size: NGSolve's sparse Cholesky (time and peak
memory of the factorisation) and CG with AMG (linalg.iterative.AMGFactor).

Each size is a structured 4 x 1 x 1 bar (``geometry.structured.box_mesh``, K cells across,
4K along, 6 tetrahedra per cell) of St Venant-Kirchhoff glass, clamped at x = 0 and pulled
along x at x = 4, in a process of its own (its memory is then its own). Reported per size:

  k, vertices, dofs (factorised), nnz (of K_ff)
  chol_seconds   the sparse Cholesky factorisation, one thread
  chol_peak_bytes  the growth of the resident set (VmRSS, sampled every 5 ms) during the
                 factorisation over its value before: the factor and the factorisation's
                 workspace
  chol_kept_bytes  the growth that remains after it (the factor)
  chol_solve_seconds  one solve with the factor
  amg_setup_seconds, amg_solve_seconds, amg_iterations   the AMG hierarchy, one CG solve
                 (relative residual CG_RTOL) and its iterations, for the same right-hand side
  amg_peak_bytes the resident set's growth during the AMG setup and the solve
  difference     |x_cg - x_chol| / |x_chol|

and the least-squares fit log(chol_peak_bytes) = log(c) + p log(dofs) over the sizes (the
constants of linalg.iterative.cholesky_bytes).

Usage: python benchmarks/linear3d.py [--sizes 10 13 16 20] [--json FILE [--force]]
"""
import argparse
import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmark_json  # noqa: E402


def rss():
    """The resident set of this process in bytes (VmRSS)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


class PeakRSS:
    """The largest resident set seen while the ``with`` block runs (sampled every 5 ms)."""

    def __enter__(self):
        self.before = self.peak = rss()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def _sample(self):
        while not self._stop.wait(0.005):
            self.peak = max(self.peak, rss())

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.after = rss()
        self.peak = max(self.peak, self.after)


def measure(k):
    """The measurements of one size (run in a child process)."""
    from ngfracture.geometry.solid import solid_mesh
    from ngfracture.geometry.structured import box_mesh
    from ngfracture.linalg.factor import EliminatedFactor
    from ngfracture.linalg.iterative import AMGFactor
    from ngfracture.mechanics.materials import StVenantKirchhoff
    from ngfracture.mechanics.problem import ElasticProblem
    arrays = box_mesh(np.linspace(0, 4, 4 * k + 1), np.linspace(0, 1, k + 1), np.linspace(0, 1, k + 1))
    prob = ElasticProblem(solid_mesh(arrays), StVenantKirchhoff(5e9, 0.18))
    prob.add_dirichlet("xmin", 0.0)
    prob.add_dirichlet("xmax", 1e-3, component="x")
    rows = prob.assemble_constraints()
    K = prob.tangent()
    support = prob.support(rows)
    b = np.random.default_rng(0).standard_normal(prob.fes.ndof)
    direct = EliminatedFactor(K, rows.fixed_dofs, support.pins, inverse="sparsecholesky",
                              pattern=prob.tangent_pattern())
    n = int(np.count_nonzero(direct.factor_free))
    with PeakRSS() as chol:
        t0 = time.perf_counter()
        direct.factorise()
        chol_seconds = time.perf_counter() - t0
    t0 = time.perf_counter()
    x_chol = direct.solve(b)
    chol_solve = time.perf_counter() - t0
    del direct
    iterative = AMGFactor(K, rows.fixed_dofs, support.pins, prob.arrays.points)
    with PeakRSS() as amg:
        t0 = time.perf_counter()
        iterative.factorise()
        amg_setup = time.perf_counter() - t0
        t0 = time.perf_counter()
        x_cg = iterative.solve(b)
        amg_solve = time.perf_counter() - t0
    return {"k": k, "vertices": int(prob.mesh.nv), "dofs": n,
            "nnz": int(iterative.K[iterative.factor_free][:, iterative.factor_free].nnz),
            "chol_seconds": chol_seconds, "chol_peak_bytes": chol.peak - chol.before,
            "chol_kept_bytes": chol.after - chol.before, "chol_solve_seconds": chol_solve,
            "amg_setup_seconds": amg_setup, "amg_solve_seconds": amg_solve,
            "amg_iterations": iterative.iterations[-1], "amg_peak_bytes": amg.peak - amg.before,
            "difference": float(np.linalg.norm(x_cg - x_chol) / np.linalg.norm(x_chol))}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 13, 16, 20],
                        help="cells K across the bar (4K along it)")
    parser.add_argument("--child", type=int, help=argparse.SUPPRESS)
    benchmark_json.add_options(parser)
    args = parser.parse_args(argv)
    if args.child is not None:
        print(json.dumps(measure(args.child)))
        return
    benchmark_json.refuse_existing(parser, args)
    cases = []
    for k in args.sizes:
        out = subprocess.run([sys.executable, __file__, "--child", str(k)], capture_output=True, text=True,
                             check=True)
        cases.append(json.loads(out.stdout.strip().splitlines()[-1]))
        print(json.dumps(cases[-1]), file=sys.stderr)
    result = {"cases": cases}
    if len(cases) >= 2:
        n = np.log([c["dofs"] for c in cases])
        m = np.log([c["chol_peak_bytes"] for c in cases])
        p, logc = np.polyfit(n, m, 1)
        result["fit"] = {"exponent": float(p), "coefficient": float(np.exp(logc))}
    benchmark_json.write(args, result)


if __name__ == "__main__":
    main()
