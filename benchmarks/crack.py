"""Benchmark of the crack engine against one linear solve on the same mesh.

For unit-square netgen meshes from 10k to 500k triangles: a stretched plate is solved once
(linear elasticity, VectorH1 order 1, Dirichlet left/right, sparse Cholesky factorise +
solve, assembled in a TaskManager); then one crack pass is timed phase by phase:

  t_strain    nodal strain (P1 element strain + area-weighted vertex average) + principal
  t_select    overstrained vertices in order + the C++ splitting decisions (topology)
  t_rebuild   netgen mesh rebuild in C++ + ngsolve.Mesh(...)
  t_transfer  new VectorH1 space + GridFunction + exact copy through the vertex map
  t_nonlocal  the critical-distance measure instead of the nodal strain (element strain,
              fracture.nonlocal_opening with radius r = 4 h, h the mesh size), not part of
              the pass above; ``nonlocal_ratio`` = t_nonlocal / t_solve

The critical strain is the 99% quantile of the principal strain, so about 1% of the
vertices split. Crack phases are the best of `--repeat` runs. Writes JSON (stdout, or
the file of `--json FILE`):
{"cases": [{"ntri", "t_strain", "t_select", "t_rebuild", "t_transfer", "t_solve", "ratio",
 "t_nonlocal", "nonlocal_ratio"}],
 "exponent": e}  with ratio = crack work / t_solve and e the fitted slope of
log(crack work) over log(ntri).

Usage: python benchmarks/crack.py [--sizes 10000 50000 ...] [--repeat 3] [--threads 2] [--json FILE [--force]]
"""
import argparse
import json
import sys
import time

import numpy as np
import ngsolve
from netgen.geom2d import unit_square

import benchmark_json
from ngfracture import fracture


def maxh_for(ntri):
    # netgen's unit square gives about 2.3 / maxh^2 triangles
    return float(np.sqrt(2.3 / ntri))


def plate(ntri):
    return ngsolve.Mesh(unit_square.GenerateMesh(maxh=maxh_for(ntri)))


def nonlocal_measure(mesh, u, radius):
    """Seconds of the critical-distance measure of every vertex (element strain + rays)."""
    t0 = time.perf_counter()
    fracture.nonlocal_opening(mesh, fracture.element_strain(mesh, u), radius)
    return time.perf_counter() - t0


def solve_stretch(mesh, stretch=1e-3, E=1.0, nu=0.3):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    fes = ngsolve.VectorH1(mesh, order=1, dirichlet="left|right")
    u, v = fes.TnT()
    eps = lambda w: ngsolve.Sym(ngsolve.Grad(w))
    a = ngsolve.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ngsolve.InnerProduct(eps(u), eps(v)) + lam * ngsolve.div(u) * ngsolve.div(v)) * ngsolve.dx
    gfu = ngsolve.GridFunction(fes)
    with ngsolve.TaskManager():
        a.Assemble()
        gfu.Set(ngsolve.CF((stretch * ngsolve.x, 0)), ngsolve.BND)
        r = gfu.vec.CreateVector()
        r.data = -a.mat * gfu.vec
        t0 = time.perf_counter()
        inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
        gfu.vec.data += inv * r
        t_solve = time.perf_counter() - t0
    return gfu, t_solve


def crack_pass(mesh, u):
    t = {}
    t0 = time.perf_counter()
    S = fracture.vertex_strain(mesh, u, "green")
    val, d = fracture.principal(S)
    t["t_strain"] = time.perf_counter() - t0
    critical = float(np.quantile(val, 0.99))
    t0 = time.perf_counter()
    order = fracture.select(val, critical)
    t_sel = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = fracture.split_vertices(mesh, order, d[order])
    t_split_all = time.perf_counter() - t0
    t["t_select"] = t_sel + res.timings["split"]
    t["t_rebuild"] = t_split_all - res.timings["split"]
    t0 = time.perf_counter()
    fracture.transfer(u, res)
    t["t_transfer"] = time.perf_counter() - t0
    return t, res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 50000, 100000, 200000, 500000])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    benchmark_json.add_options(ap)
    args = ap.parse_args(argv)
    benchmark_json.refuse_existing(ap, args)
    ngsolve.SetNumThreads(args.threads)
    cases = []
    for n in args.sizes:
        mesh = plate(n)
        u, t_solve = solve_stretch(mesh)
        best = None
        for _ in range(args.repeat):
            t, res = crack_pass(mesh, u)
            best = t if best is None else {k: min(best[k], t[k]) for k in t}
        work = sum(best.values())
        t_nonlocal = min(nonlocal_measure(mesh, u, 4 * maxh_for(n)) for _ in range(args.repeat))
        case = {"ntri": mesh.ne, **{k: round(v, 6) for k, v in best.items()},
                "t_solve": round(t_solve, 6), "ratio": round(work / t_solve, 5),
                "t_nonlocal": round(t_nonlocal, 6), "nonlocal_ratio": round(t_nonlocal / t_solve, 5)}
        cases.append(case)
        # progress and the size of the pass on stderr; stdout is the JSON of the schema
        print(json.dumps({**case, "processed_vertices": int(len(res.record["vertex"])),
                          "new_vertices": int(res.mesh.nv - mesh.nv)}), file=sys.stderr, flush=True)
    nt = np.array([c["ntri"] for c in cases], dtype=float)
    work = np.array([c["t_strain"] + c["t_select"] + c["t_rebuild"] + c["t_transfer"] for c in cases])
    exponent = float(np.polyfit(np.log(nt), np.log(work), 1)[0]) if len(cases) > 1 else None
    benchmark_json.write(args, {"cases": cases, "exponent": exponent})


if __name__ == "__main__":
    main()
