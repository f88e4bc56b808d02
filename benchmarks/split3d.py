"""Node splitting on tetrahedral meshes: cost of k splits and the netgen rebuild.

For netgen bars 1 x 1 x 4 at about 50k and 200k tetrahedra: the time to split the k vertices
nearest the mid-plane's centre across z in one pass (C++), to rebuild the mesh through netgen
(``solid_mesh``) and to count the fragments, as a ratio to one NGSolve sparsecholesky
factorise + solve of the same mesh's linear elasticity (P1, one thread), and the growth
exponent of the crack work in the number of tetrahedra. Target: the crack work at most 0.2
of a factorise + solve at 200k tetrahedra, growth at most N^1.15.

    python benchmarks/split3d.py [--k 20] [--maxh 0.073 0.046] [--json FILE]
"""
import argparse
import math
import time

import numpy as np
import ngsolve
from netgen.csg import CSGeometry, OrthoBrick, Pnt

import benchmark_json
from ngfracture.fracture import split3d as s3
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.geometry.solid import solid_mesh, solid_to_arrays


def factorise_solve(mesh):
    """Seconds of one sparsecholesky factorisation and solve of P1 linear elasticity."""
    fes = ngsolve.VectorH1(mesh, order=1, dirichlet=".*")
    u, v = fes.TnT()
    mu, lam = 1.0, 1.0
    eps = lambda w: ngsolve.Sym(ngsolve.Grad(w))
    a = ngsolve.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ngsolve.InnerProduct(eps(u), eps(v)) + lam * ngsolve.div(u) * ngsolve.div(v)) * ngsolve.dx
    a.Assemble()
    f = ngsolve.LinearForm(fes)
    f += ngsolve.CF((0, 0, 1)) * v * ngsolve.dx
    f.Assemble()
    t0 = time.perf_counter()
    inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
    x = f.vec.CreateVector()
    x.data = inv * f.vec
    return time.perf_counter() - t0, fes.ndof


def crack_work(arrays, k):
    """Seconds of the split of k vertices, the rebuild and the fragment count."""
    c = np.array([0.5, 0.5, 2.0])
    order = np.argsort(np.linalg.norm((arrays.points - c) * [1, 1, 20], axis=1), kind="stable")[:k]
    t0 = time.perf_counter()
    r = s3.split_vertices_3d(arrays, order, np.tile([0.0, 0.0, 1.0], (k, 1)))
    t1 = time.perf_counter()
    mesh = solid_mesh(r.arrays)
    t2 = time.perf_counter()
    frag = FragmentStatistics(r.arrays)
    t3 = time.perf_counter()
    return {"split": t1 - t0, "rebuild": t2 - t1, "fragments": t3 - t2, "total": t3 - t0,
            "nsplit": r.nsplit, "fragment_count": frag.count, "nv_new": mesh.nv}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, default=20, help="vertices split in the pass")
    parser.add_argument("--maxh", type=float, nargs="+", default=[0.073, 0.046])
    benchmark_json.add_options(parser)
    args = parser.parse_args()
    benchmark_json.refuse_existing(parser, args)
    ngsolve.SetNumThreads(1)
    rows = []
    for h in args.maxh:
        geo = CSGeometry()
        geo.Add(OrthoBrick(Pnt(0, 0, 0), Pnt(1, 1, 4)))
        with ngsolve.TaskManager():
            mesh = ngsolve.Mesh(geo.GenerateMesh(maxh=h))
        arrays = solid_to_arrays(mesh)
        work = min((crack_work(arrays, args.k) for _ in range(3)), key=lambda w: w["total"])
        t_fs, ndof = factorise_solve(mesh)
        rows.append({"maxh": h, "tets": len(arrays.tets), "dofs": ndof, "factorise_solve": t_fs,
                     "crack": work, "ratio": work["total"] / t_fs})
    result = {"k": args.k, "rows": rows}
    if len(rows) >= 2:
        a, b = rows[0], rows[-1]
        result["growth_exponent"] = math.log(b["crack"]["total"] / a["crack"]["total"]) / math.log(b["tets"] / a["tets"])
    benchmark_json.write(args, result)


if __name__ == "__main__":
    main()
