"""Benchmark of the contact complementarity QP's dual steps: the free block's Cholesky factor
updated (C++, what ``qp.bound_qp`` takes) against the QR of the working set updated
(``qp.convex_qp``), from the same start.

The problems are contact-sized duals: n multipliers, all bounded above by 0, p equalities
(free modes), H = B B^T / n + E^T E + 1e-6 I with a dense mixed-sign B (no M-matrix, as
nearly parallel contact rows give), seeded. Both codes start from the bounds with c_i > 0
held (the primal-dual sweeps' first guess; ``bound_qp(max_sweeps=0)``) and walk the same
working sets. The baseline, measured in the same run, is one dense Cholesky factorisation
and solve of H (scipy). Reported per case: n, p, held bounds at the end, CPU seconds of each
code and of the baseline, their ratios, whether the working sets agree, the largest
difference of x relative to |x| and both Kuhn-Tucker residuals (relative to the force).

Usage: python benchmarks/contact_qp.py [--sizes 500 1000 2000] [--equalities 22]
       [--json FILE [--force]]
"""
import argparse
import time

import numpy as np
import scipy.linalg as sla

import benchmark_json
from ngfracture.linalg.qp import bound_qp, convex_qp


def problem(n, p, seed):
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n)) / np.sqrt(n)
    E = rng.standard_normal((p, n)) / np.sqrt(n)
    H = B @ B.T + E.T @ E + 1e-6 * np.eye(n)
    return H, rng.standard_normal(n), E, E @ -np.abs(rng.standard_normal(n))


def stationarity(H, c, E, x, u_eq, u_bound):
    """|H x - c - E^T u_eq + u| relative to the force (u the multipliers of the bounds, every
    variable bounded)."""
    g = H @ x - c - E.T @ u_eq + u_bound
    return float(np.abs(g).max() / max(np.abs(c).max(), np.abs(H @ x).max()))


def cpu(f):
    t = time.process_time()
    out = f()
    return out, time.process_time() - t


def case(n, p, seed=0):
    H, c, E, e = problem(n, p, seed)
    bounded = np.arange(n)
    _, t_base = cpu(lambda: sla.cho_solve(sla.cho_factor(H, lower=True), c))
    new, t_new = cpu(lambda: bound_qp(H, c, E, e, bounded, max_sweeps=0))
    if new.fallback:
        raise RuntimeError(f"n={n}: the updated factor fell back: {new.fallback}")
    old, t_old = cpu(lambda: convex_qp(H, c, E, e, -np.eye(n), np.zeros(n), start=np.flatnonzero(c > 0)))
    x_old = old[0]
    return {"n": n, "p": p, "held": int(new.held.sum()), "t_updated_factor": t_new, "t_qr": t_old,
            "t_baseline": t_base, "updated_factor_per_baseline": t_new / t_base,
            "qr_per_baseline": t_old / t_base, "qr_per_updated_factor": t_old / t_new,
            "same_working_set": bool(np.array_equal(new.held, old[3])),
            "x_difference": float(np.abs(new.x - x_old).max() / np.abs(x_old).max()),
            "stationarity_updated_factor": stationarity(H, c, E, new.x, new.u_eq, new.u_bound),
            "stationarity_qr": stationarity(H, c, E, x_old, old[1], old[2])}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[500, 1000, 2000])
    parser.add_argument("--equalities", type=int, default=22)
    benchmark_json.add_options(parser)
    args = parser.parse_args()
    benchmark_json.refuse_existing(parser, args)
    if any(n < 2 * args.equalities for n in args.sizes) or args.equalities < 0:
        parser.error("--sizes must be at least twice --equalities, and --equalities at least 0")
    cases = [case(n, args.equalities) for n in args.sizes]
    benchmark_json.write(args, {"benchmark": "contact_qp", "baseline": "dense Cholesky factorisation and solve of H",
                                "cases": cases})


if __name__ == "__main__":
    main()
