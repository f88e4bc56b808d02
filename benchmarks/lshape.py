"""L-shape benchmark: ngfracture against plain NGSolve, and time to reach an error.

Problem: the L-shape of the paper (section 4.1, eq. 15), linear elasticity,
E = 1e5, nu = 0.3, plane strain, exact Dirichlet data (``Set()``) on the whole
boundary (``--variant traction-free``: free reentrant edges).

For order 1 and 2, on uniform and graded meshes (``ngfracture.studies.lshape``), every
level is solved twice in the same run on the same mesh:

* ``t_ngfracture``: ``ElasticProblem`` + ``add_dirichlet`` + ``solve`` (modified Newton),
* ``t_plain``: VectorH1, linear-elasticity ``BilinearForm``, ``gfu.Set(uex, BND)``,
  sparse Cholesky ``Inverse`` on the free dofs, all inside ``TaskManager``;

each the minimum over ``--repeat`` runs (at least 5 for small cases; the
machine is shared), the two alternating.  ``ratio = t_ngfracture / t_plain``
(wall time); ``ratio_cpu`` is the same for the process CPU time of all
threads, less sensitive to other processes on the machine.

Threads: both solvers run with the same NGSolve thread count, ``--threads``
(default 1), set with ``ngsolve.SetNumThreads`` before every timed solve.
ngfracture factorises on one thread by design (``reproducible_threads``: bitwise
reproducible results); with ``--threads 2`` the plain baseline factorises on two
threads, ngfracture on one, and the ratio then includes that choice, not only the
cost of ngfracture's machinery.

``time_to_error`` gives the ngfracture solve time needed for a relative L2
error of 1e-2, 1e-3, 1e-4, interpolated in log-log between measured levels
(``"extrapolated": true`` when the levels do not bracket the target); the
times per level are first made monotone (a coarse level measured slower
than a finer one gets the finer time).

Floors checked (``"floors"`` in the output, exit status 1 if one fails):
ratio <= 1.15 for every case with >= 90k dofs, and graded meshes reach 1e-4
faster than uniform ones for each order.

Usage::

    PYTHONPATH=. python benchmarks/lshape.py [--json F] [--plot F.png] [--force]
        [--max-level-p1 7] [--max-level-p2 6] [--repeat 2] [--variant dirichlet]
        [--threads 1]

Without ``--json`` the JSON goes to stdout; ``--plot`` writes Fig. 6b of the
paper (relative L2 error against number of vertices, log-log).
"""
import argparse
import gc
import sys
import time

import ngsolve
import numpy as np

import benchmark_json
from ngfracture.studies import lshape
from ngfracture.studies import verify
from ngfracture.cli import _int_at_least

TARGETS = (1e-2, 1e-3, 1e-4)
RATIO_FLOOR = 1.15
RATIO_MIN_DOFS = 90_000


def _timed(threads, fn, *args):
    """Result, wall time and process CPU time (all threads) of ``fn(*args)`` on ``threads``
    NGSolve threads (set before every call: see the module docstring)."""
    ngsolve.SetNumThreads(threads)
    gc.collect()
    c0, t0 = time.process_time(), time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - t0, time.process_time() - c0


def run_cases(max_levels, repeat, variant, threads=1, log=sys.stderr):
    """Solve every (order, mesh, level) case with both solvers.

    Parameters
    ----------
    max_levels : dict
        order -> finest level (levels 0 .. max_levels[order]).
    repeat : int
        Timing repetitions per solver (the minimum is kept).
    variant : {"dirichlet", "traction-free"}
    threads : int
        NGSolve threads of both solvers.
    log : file
        Progress lines go here.

    Returns
    -------
    list of dict
        One dict per case (see the module docstring).
    """
    sol = lshape.LShapeSolution(E=1e5, nu=0.3, plane="strain")
    # Warm-up: the first solves pay one-off costs (thread pool, code generation).
    ngsolve.SetNumThreads(threads)
    for order in max_levels:
        coarse = lshape.lshape_mesh(0)
        verify.solve_ngfracture(coarse, order, sol, variant)
        verify.solve_plain(coarse, order, sol, variant)
    cases = []
    for order, max_level in max_levels.items():
        for mesh_kind in verify.MESHES:
            gamma = 1.0 if mesh_kind == "uniform" else lshape.default_grading(order)
            for level, mesh in enumerate(lshape.mesh_hierarchy(max_level + 1, 0.5, gamma)):
                t_ngf, t_plain, c_ngf, c_plain = [], [], [], []
                # small cases are cheap and the noisiest: repeat them more
                reps = repeat if mesh.nv * order**2 > 20000 else max(repeat, 5)
                for k in range(reps):
                    # alternate which solver runs first, so neither always gets the warm cache
                    runs = ["n", "p"] if k % 2 == 0 else ["p", "n"]
                    for tag in runs:
                        if tag == "n":
                            (u_ngf, status), dt, dc = _timed(threads, verify.solve_ngfracture, mesh, order,
                                                             sol, variant, "linear", True)
                            if not t_ngf or dt < min(t_ngf):
                                phases = {p: round(v, 4) for p, v in status.timings.items()}
                            t_ngf.append(dt)
                            c_ngf.append(dc)
                        else:
                            u_plain, dt, dc = _timed(threads, verify.solve_plain, mesh, order, sol, variant)
                            t_plain.append(dt)
                            c_plain.append(dc)
                rel_l2, rel_energy = lshape.relative_errors(mesh, u_ngf, sol, order)
                plain_l2, _ = lshape.relative_errors(mesh, u_plain, sol, order)
                case = {"order": order, "mesh": mesh_kind, "level": level,
                        "ndof": u_ngf.space.ndof, "nverts": mesh.nv, "rel_l2": rel_l2,
                        "rel_energy": rel_energy, "rel_l2_plain": plain_l2,
                        "t_ngfracture": min(t_ngf), "t_plain": min(t_plain),
                        "ratio": min(t_ngf) / min(t_plain), "repeats": reps,
                        "cpu_ngfracture": min(c_ngf), "cpu_plain": min(c_plain),
                        "ratio_cpu": min(c_ngf) / min(c_plain), "ngfracture_phases": phases}
                cases.append(case)
                print(f"P{order} {mesh_kind:8s} level {level} ndof {case['ndof']:8d} "
                      f"L2 {rel_l2:.3e} t_ngf {case['t_ngfracture']:.3f} "
                      f"t_plain {case['t_plain']:.3f} ratio {case['ratio']:.2f} (cpu {case['ratio_cpu']:.2f})",
                      file=log, flush=True)
    return cases


def time_to_error_table(cases):
    """Time to reach each target error per (order, mesh), from the ngfracture runs."""
    rows = []
    for order in sorted({c["order"] for c in cases}):
        for mesh_kind in verify.MESHES:
            cs = [c for c in cases if c["order"] == order and c["mesh"] == mesh_kind]
            # Monotone envelope: a coarser solve measured slower than a finer one is load
            # noise (other processes), so it gets the time of the fastest finer solve.
            times = np.minimum.accumulate([c["t_ngfracture"] for c in cs][::-1])[::-1]
            errors = [c["rel_l2"] for c in cs]
            for target in TARGETS:
                seconds, extrapolated = verify.time_to_error(times, errors, target)
                rows.append({"order": order, "mesh": mesh_kind, "target": target,
                             "seconds": seconds, "extrapolated": extrapolated})
    return rows


def floors(cases, tte):
    """The performance floors of the benchmark, each with its measured value and verdict."""
    out = []
    for c in cases:
        if c["ndof"] >= RATIO_MIN_DOFS:
            out.append({"name": f"ratio P{c['order']} {c['mesh']} level {c['level']} "
                                f"({c['ndof']} dofs)",
                        "value": c["ratio"], "limit": RATIO_FLOOR, "ok": c["ratio"] <= RATIO_FLOOR})
    for order in sorted({c["order"] for c in cases}):
        t = {r["mesh"]: r for r in tte if r["order"] == order and r["target"] == 1e-4}
        out.append({"name": f"P{order}: graded reaches 1e-4 before uniform",
                    "value": t["graded"]["seconds"], "limit": t["uniform"]["seconds"],
                    "ok": t["graded"]["seconds"] < t["uniform"]["seconds"]})
    return out


def plot_fig6b(cases, path):
    """Fig. 6b of the paper: relative L2 error against the number of vertices (log-log)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for order in sorted({c["order"] for c in cases}):
        for mesh_kind, style in (("uniform", "o-"), ("graded", "s--")):
            cs = [c for c in cases if c["order"] == order and c["mesh"] == mesh_kind]
            ax.loglog([c["nverts"] for c in cs], [c["rel_l2"] for c in cs], style,
                      label=f"P{order}, {mesh_kind}")
    nv = [c["nverts"] for c in cases]
    n0, n1 = min(nv), max(nv)
    e0 = max(c["rel_l2"] for c in cases)
    # reference slopes: N^-1/2 is h^1 (the paper's "linear convergence"), N^-1 is h^2
    ax.loglog([n0, n1], [e0, e0 * (n1 / n0) ** -0.5], "k:", lw=1, label="slope h^1")
    ax.loglog([n0, n1], [e0, e0 * (n1 / n0) ** -1.0], "k-.", lw=1, label="slope h^2")
    ax.set_xlabel("number of vertices")
    ax.set_ylabel("relative L2 displacement error")
    ax.set_title("L-shape (eq. 15): convergence of the displacement")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    benchmark_json.save_figure(fig, path)


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="L-shape benchmark: ngfracture vs plain NGSolve per level, time to reach "
                    "relative L2 errors 1e-2, 1e-3, 1e-4; uniform and graded meshes, order 1 and 2.")
    benchmark_json.add_options(parser, force_help="overwrite existing output files (--json, --plot)")
    parser.add_argument("--plot", metavar="FILE", help="write Fig. 6b (error vs vertices) as PNG")
    parser.add_argument("--max-level-p1", type=_int_at_least(1), default=7,
                        help="finest level for order 1 (default 7: 362k dofs)")
    parser.add_argument("--max-level-p2", type=_int_at_least(1), default=6,
                        help="finest level for order 2 (default 6: 362k dofs)")
    parser.add_argument("--repeat", type=_int_at_least(1), default=3,
                        help="timing repetitions per solver and case, minimum kept (default 3)")
    parser.add_argument("--variant", choices=verify.VARIANTS, default="dirichlet",
                        help="boundary conditions (default dirichlet: exact data everywhere)")
    parser.add_argument("--threads", type=_int_at_least(1), default=1,
                        help="NGSolve threads of both solvers (default 1; ngfracture factorises "
                             "on one thread whatever this is)")
    args = parser.parse_args(argv)
    benchmark_json.refuse_existing(parser, args, args.plot)

    cases = run_cases({1: args.max_level_p1, 2: args.max_level_p2}, args.repeat, args.variant,
                      args.threads)
    tte = time_to_error_table(cases)
    checks = floors(cases, tte)
    result = {"problem": "lshape", "variant": args.variant, "model": "linear",
              "threads": args.threads, "cases": cases, "time_to_error": tte, "floors": checks}
    benchmark_json.write(args, result)
    if args.plot:
        plot_fig6b(cases, args.plot)
    for c in checks:
        print(f"{'ok  ' if c['ok'] else 'FAIL'} {c['name']}: {c['value']:.3g} (limit {c['limit']:.3g})",
              file=sys.stderr)
    return 0 if all(c["ok"] for c in checks) else 1


if __name__ == "__main__":
    sys.exit(main())
