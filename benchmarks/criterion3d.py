"""Benchmark of the crack criterion on tetrahedral meshes against one linear solve of the same mesh.

Structured slabs [-1, 1]^2 x [0, 1] (6 tets per cube, ``geometry.structured.box_mesh``) with
a through crack on y = 0, x <= 0 (``geometry.internal_crack.open_internal_surface``), pulled
apart (u = (0, +-1e-3, 0) on ymin / ymax); linear elasticity, VectorH1 order 1, NGSolve's
sparse Cholesky on one thread (``ngsolve.SetNumThreads(1)``). Timed, best of ``--repeat``:

  t_solve     factorisation + solve (assembly not included)
  t_strain    tet strain + stress over E (``tet_strain``, ``stress_over_E``)
  t_nonlocal  the measure of every vertex, r = 4 h (``nonlocal_opening_3d``: averaging,
              topology, sharp front vertices, hot spots, rays)
  t_crack     all crack work: ``overstrain_3d`` with the radius, E and nu (the two above)
  ratio       t_crack / t_solve

and ``exponent``, the slope of log(t_crack) over log(tets). JSON to stdout or ``--json FILE``.

Usage: cd benchmarks && PYTHONPATH=.. OMP_NUM_THREADS=1 python criterion3d.py [--cells 26 40] [--repeat 2] [--json FILE [--force]]
"""
import argparse
import time

import numpy as np
import ngsolve

import benchmark_json
from ngfracture.fracture import solid_criterion as sc
from ngfracture.geometry.internal_crack import open_internal_surface
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh

E, NU = 1.0, 0.3


def cracked_slab(n):
    """n x n x n/2 cubes (6 tets each), the crack faces on y = 0 with x <= 0."""
    g = np.linspace(-1, 1, n + 1)
    box = box_mesh(g, g, np.linspace(0, 1, n // 2 + 1))
    opp = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    tri = np.unique(np.sort(box.tets[:, opp].reshape(-1, 3), axis=1), axis=0)
    P = box.points[tri]
    tri = tri[np.all(P[:, :, 1] == 0, axis=1) & np.all(P[:, :, 0] <= 0, axis=1)]
    x = box.points
    nrm = np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]])
    tri[nrm[:, 1] < 0] = tri[nrm[:, 1] < 0][:, [0, 2, 1]]
    return open_internal_surface(box, tri), 2.0 / n


def solve(arrays, repeat):
    """Vertex displacements and the best seconds of factorisation + solve."""
    mesh = solid_mesh(arrays)
    fes = ngsolve.VectorH1(mesh, order=1, dirichlet="ymin|ymax")
    u, v = fes.TnT()
    mu, lam = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))
    eu, ev = ngsolve.Sym(ngsolve.Grad(u)), ngsolve.Sym(ngsolve.Grad(v))
    a = ngsolve.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ngsolve.InnerProduct(eu, ev) + lam * ngsolve.Trace(eu) * ngsolve.Trace(ev)) * ngsolve.dx
    a.Assemble()
    gf = ngsolve.GridFunction(fes)
    gf.Set(ngsolve.CF((0, 1e-3 * ngsolve.IfPos(ngsolve.y, 1, -1), 0)), ngsolve.BND)
    best = np.inf
    for _ in range(repeat):
        r = gf.vec.CreateVector()
        r.data = -(a.mat * gf.vec)
        t0 = time.perf_counter()
        inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
        du = (inv * r).Evaluate()
        best = min(best, time.perf_counter() - t0)
    gf.vec.data += du
    return gf.vec.FV().NumPy().reshape(3, -1)[:, :mesh.nv].T.copy(), best


def timed(repeat, f):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def case(n, repeat):
    arrays, h = cracked_slab(n)
    u, t_solve = solve(arrays, repeat)
    r = 4 * h
    t_strain, S = timed(repeat, lambda: sc.stress_over_E(sc.tet_strain(arrays, u, "linear"), E, NU))
    t_nonlocal, res = timed(repeat, lambda: sc.nonlocal_opening_3d(arrays, S, r))
    t_crack, _ = timed(repeat, lambda: sc.overstrain_3d(arrays, u, 1e-3, radius=r, E=E, nu=NU, measure="linear"))
    values, _ = sc.principal_3d(res)
    return {"cells": n, "tets": int(len(arrays.tets)), "vertices": int(len(arrays.points)), "radius": r,
            "judged": int(np.count_nonzero(values)), "sharp": int(len(sc.sharp_vertices_3d(arrays))),
            "t_solve": t_solve, "t_strain": t_strain, "t_nonlocal": t_nonlocal, "t_crack": t_crack,
            "ratio": t_crack / t_solve}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cells", type=int, nargs="+", default=[26, 40],
                   help="cubes along x and y (z: half); 26 -> 53k tets, 40 -> 192k")
    p.add_argument("--repeat", type=int, default=2)
    benchmark_json.add_options(p)
    args = p.parse_args()
    benchmark_json.refuse_existing(p, args)
    ngsolve.SetNumThreads(1)
    cases = [case(n, args.repeat) for n in args.cells]
    tets = np.log([c["tets"] for c in cases])
    exponent = float(np.polyfit(tets, np.log([c["t_crack"] for c in cases]), 1)[0]) if len(cases) > 1 else None
    benchmark_json.write(args, {"cases": cases, "exponent": exponent})


if __name__ == "__main__":
    main()
