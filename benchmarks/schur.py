"""Benchmark of the Schur complement S = C K^-1 C^T of contact rows: kept columns against
sparse triangular solves (linalg.factor.SPARSE_SCHUR_MIN_DOFS).

For the notched plate at mesh factors f (maxh 0.034 / sqrt f), rows like the contact rows
of a crack across the middle (node to node between neighbouring vertices near x = 0.5, unit
normals): one SuperLU factorisation of the uncracked tangent, then S both ways
(``EliminatedFactor.columns`` then C Z; ``EliminatedFactor.schur``), each on a fresh
factorisation, best of three. Reported per case: dofs, rows, seconds of each, their ratio,
and the largest difference of the two S relative to its largest entry. The factorisation
itself is the same for both and not counted.

``--sphere FINE ...``: the sphere scene (``scenes.sphere3d(maxh, fine)``, ``--maxh``, default
the scene's) with its stick rows (the general rows of its first solve): one factorisation
of the tangent and its Schur complement each way a 3D solve can take it, fresh every time,
best of three: "cholesky" (NGSolve's sparse Cholesky, then the columns K^+ C^T and C Z),
"superlu" (SuperLU, then the sparse triangular solves of ``EliminatedFactor.schur``),
"augmented" (SuperLU of the augmented matrix, ``EliminatedFactor.augmented``; no S).
Reported per case: tets, factorised dofs, rows, each one's factorisation and Schur
seconds, their sums and the ratios to "cholesky". ``--hole-rows N`` adds one row (the x
component) at each of the N free vertices nearest the hole (radius 0.25), as the contact
rows of a cracked hole add to the stick rows.

``--g-vertices N ...``: G = K_ff^-1 on the dofs of the N free vertices nearest the plane
z = 0 of the default sphere's tangent (the dofs of a crack's lips, as the Schur
complement by dofs keeps it, ``sparse_schur.DofSchur``): the reach solves of their unit
rows, then the product Y^T D^-1 Y dense over every reached row
(``triangular.weighted_products``) and by groups of rows
(``triangular.grouped_row_products``, one thread), the reach solves on one thread and on
``PRODUCT_THREADS``, best of three; seconds and their ratios to one factorisation + solve
of the tangent (the unit), and the largest difference of the products relative to G's
largest entry. ``--g-vertices 0`` takes every free vertex.

Usage: python benchmarks/schur.py [--factors 1 2 4 8 16] [--sphere FINE ... [--maxh H]
       [--hole-rows N]] [--g-vertices N ...] [--json FILE [--force]]
"""
import argparse
import time

import numpy as np
import scipy.sparse as sp

import benchmark_json
from ngfracture import scenes
from ngfracture.linalg import factor as factor_module
from ngfracture.mechanics.problem import ElasticProblem


def contact_like_rows(mesh, ndof, count=150, width=0.02):
    """Node-to-node rows n . (u_b - u_a) between neighbouring vertices near x = 0.5."""
    X = np.array([v.point for v in mesh.vertices])
    line = np.flatnonzero(np.abs(X[:, 0] - 0.5) < width)[:count]
    half = ndof // 2
    rows, cols, vals = [], [], []
    for r, (b, a) in enumerate(zip(line[:-1], line[1:])):
        for vertex, sign in ((b, 1.0), (a, -1.0)):
            for comp, n in ((0, 0.8), (1, 0.6)):
                rows.append(r)
                cols.append(comp * half + vertex)
                vals.append(sign * n)
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(line) - 1, ndof))


def case(factor, repeat=3):
    scene = scenes.plate(maxh=0.034 / np.sqrt(factor))
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, scene.dx)
    K, fixed = prob.tangent(), prob.assemble_constraints().fixed_dofs
    C = contact_like_rows(scene.mesh, prob.fes.ndof)
    seconds, S = {}, {}
    for name in ("columns", "sparse"):
        best = np.inf
        for _ in range(repeat):
            f = factor_module.EliminatedFactor(K, fixed, inverse="superlu")
            f.factorise()
            t0 = time.perf_counter()
            S[name] = C @ f.columns(C) if name == "columns" else f.schur(C)
            best = min(best, time.perf_counter() - t0)
        seconds[name] = best
    return {"factor": factor, "dofs": prob.fes.ndof, "rows": C.shape[0], "ntri": scene.mesh.ne,
            "columns_s": seconds["columns"], "sparse_s": seconds["sparse"],
            "speedup": seconds["columns"] / seconds["sparse"],
            "relative_difference": float(np.abs(S["sparse"] - S["columns"]).max() / np.abs(S["columns"]).max())}


def hole_rows(mesh, ndof, fixed_dofs, count):
    """One row (the x component) at each of the ``count`` free vertices nearest the hole."""
    X = np.array([v.point for v in mesh.vertices])
    free = np.setdiff1d(np.arange(mesh.nv), fixed_dofs)       # x dofs are the vertex numbers
    nearest = free[np.argsort(np.abs(np.linalg.norm(X[free], axis=1) - 0.25), kind="stable")[:count]]
    return sp.csr_matrix((np.ones(len(nearest)), (np.arange(len(nearest)), nearest)), shape=(len(nearest), ndof))


def sphere_case(fine, maxh=None, extra_rows=0, repeat=3):
    """The three ways of a 3D factorisation with the sphere's stick rows and ``extra_rows``
    rows at the hole (module docstring)."""
    from ngfracture.linalg.sparse import reproducible_threads
    kwargs = {"fine": fine} if maxh is None else {"fine": fine, "maxh": maxh}
    scene = scenes.sphere3d(**kwargs)
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, scene.dx)
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    K, C = prob.tangent(), rows.C
    if extra_rows:
        C = sp.vstack([C, hole_rows(scene.mesh, prob.fes.ndof, rows.fixed_dofs, extra_rows)]).tocsr()
    out = {"fine": fine, "tets": scene.mesh.ne, "rows": C.shape[0], "hole_rows": extra_rows}
    for name in ("cholesky", "superlu", "augmented"):
        best = (np.inf, np.inf)
        for _ in range(repeat):
            f = factor_module.EliminatedFactor(K, rows.fixed_dofs, support.pins,
                                               inverse="sparsecholesky" if name == "cholesky" else "superlu")
            t0 = time.perf_counter()
            if name == "augmented":
                f.augmented(C)
                t1 = time.perf_counter()
            else:
                with reproducible_threads():
                    f.factorise()
                t1 = time.perf_counter()
                S = C @ f.columns(C) if name == "cholesky" else f.schur(C)
                assert np.all(np.isfinite(S))
            t2 = time.perf_counter()
            best = min(best, (t1 - t0, t2 - t1), key=sum)
        out.update({f"{name}_factorise_s": best[0], f"{name}_schur_s": best[1], f"{name}_s": sum(best)})
        out["dofs"] = int(np.count_nonzero(f.factor_free))
    for name in ("superlu", "augmented"):
        out[f"{name}_over_cholesky"] = out[f"{name}_s"] / out["cholesky_s"]
    print(out, flush=True)
    return out


def g_case(vertices, repeat=3):
    """G on the dofs of ``vertices`` free vertices near z = 0, each way (module docstring)."""
    from ngfracture.linalg import triangular
    from ngfracture.linalg.sparse import reproducible_threads, single_threaded_blas
    scene = scenes.sphere3d()
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, scene.dx)
    rows = prob.assemble_constraints()
    f = factor_module.EliminatedFactor(prob.tangent(), rows.fixed_dofs, prob.support(rows).pins, inverse="superlu")
    t0 = time.perf_counter()
    with reproducible_threads():
        f.factorise()
    f.solve(np.ones(f.ndof))
    unit = time.perf_counter() - t0
    nv = f.ndof // 3
    X = np.array([v.point for v in scene.mesh.vertices])
    free = np.flatnonzero(f.factor_free[:nv])
    near = free[np.argsort(np.abs(X[free, 2]), kind="stable")[:vertices or None]]
    dofs = np.concatenate([near, near + nv, near + 2 * nv])
    units = sp.csr_matrix((np.ones(len(dofs)), (np.arange(len(dofs)), dofs)), shape=(len(dofs), f.ndof))
    index = -np.ones(f.ndof, dtype=np.int64)
    index[f.factor_free] = np.arange(f._lu.shape[0])
    arrays, n = f._factor_arrays(), f._lu.shape[0]
    weights = 1.0 / arrays[2]
    out = {"vertices": vertices, "dofs": int(len(dofs)), "factorised_dofs": n, "unit_s": unit}
    G = {}

    def best(name, run):
        seconds = np.inf
        for _ in range(repeat):
            t = time.perf_counter()
            G[name] = run()
            seconds = min(seconds, time.perf_counter() - t)
        out[f"{name}_s"], out[f"{name}_over_unit"] = seconds, seconds / unit

    threads = triangular.PRODUCT_THREADS
    with single_threaded_blas():
        for count in (1, threads):
            triangular.PRODUCT_THREADS = count
            best(f"reach_{count}", lambda: triangular.reach_solves(f._lu, arrays, index, units, f._supernodal()))
        columns = [y for y, _ in G["reach_1"]]
        best("dense", lambda: triangular.weighted_products(columns, weights, n))
        best("grouped", lambda: triangular.grouped_row_products(columns, weights, n))
    triangular.PRODUCT_THREADS = threads
    scale = np.abs(G["dense"]).max()
    out["grouped_difference"] = float(np.abs(G["grouped"] - G["dense"]).max() / scale)
    out["dense_over_grouped"] = out["dense_s"] / out["grouped_s"]
    print(out, flush=True)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--factors", nargs="+", type=float, default=[1, 2, 4, 8, 16])
    parser.add_argument("--sphere", nargs="+", type=float, default=None, metavar="FINE",
                        help="the sphere scene at these values of fine instead (3D ways)")
    parser.add_argument("--maxh", type=float, default=None, help="the sphere's maxh (with --sphere)")
    parser.add_argument("--hole-rows", type=int, default=0,
                        help="rows at this many vertices nearest the hole besides the stick rows (with --sphere)")
    parser.add_argument("--g-vertices", nargs="+", type=int, default=None, metavar="N",
                        help="G of the Schur complement by dofs at N vertices of the default sphere instead")
    benchmark_json.add_options(parser)
    args = parser.parse_args(argv)
    benchmark_json.refuse_existing(parser, args)
    if args.g_vertices:
        benchmark_json.write(args, {"g_cases": [g_case(v) for v in args.g_vertices]})
        return
    if args.sphere:
        cases = [sphere_case(fine, args.maxh, args.hole_rows) for fine in args.sphere]
        benchmark_json.write(args, {"sphere_cases": cases})
        return
    cases = [case(f) for f in args.factors]
    benchmark_json.write(args, {"cases": cases, "sparse_schur_min_dofs": factor_module.SPARSE_SCHUR_MIN_DOFS})


if __name__ == "__main__":
    main()
