"""Benchmark: fragment contact (collision + rows + QR) against one linear elasticity solve.

Scene ("fractured" mesh without the crack engine): the unit square is meshed by netgen
as k x k glued square pieces, so the mesh has edges along the k - 1 vertical and k - 1
horizontal cut lines. Every vertex is duplicated per piece (numpy), which turns the
pieces into separate fragments with crack surfaces along all cut lines. Each fragment is
then expanded about its own centroid by a factor 1 + delta, delta chosen so that the
overlap across a cut is about 0.2 h (h the mesh size): all cut lines are in contact,
two-sided, with 4-piece junctions (Fig. 5 situations).

Measured per case (seconds, wall clock, best of `repeat`):
  t_collision  detect_collisions: candidate mask from the boundary/crack edges, grid
               broad phase, exact narrow phase;
  t_assembly   select_contacts: rules 1-4, gap rows C (CSR) and g;
  t_qr         independent_rows(C, fixed_dofs=...) with the left edge clamped;
  t_solve      one sparse direct factorise + solve of linear elasticity on the uncut
               mesh: ngsolve VectorH1 order 1, left edge clamped,
               a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") and one apply,
               inside TaskManager (assembly not included);
  ratio        (t_collision + t_assembly + t_qr) / t_solve.
no_crack_overhead_s: contact_constraints on the uncut 100k mesh with no crack edges
(no candidates): input validation only, no collision work.

Run:  PYTHONPATH=. python benchmarks/contact.py [--quick] [--json FILE [--force]]
(JSON on stdout, or in FILE)
"""
import argparse
import json
import sys
import time

import numpy as np
import ngsolve
from netgen.occ import Glue, MoveTo, OCCGeometry

import benchmark_json
from ngfracture.contact import collision
from ngfracture.contact import rows as contact


def pieces_mesh(ntri_target, k):
    """netgen mesh of the unit square made of k x k glued square pieces."""
    faces = []
    for i in range(k):
        for j in range(k):
            f = MoveTo(i / k, j / k).Rectangle(1 / k, 1 / k).Face()
            f.mat(f"p{i}_{j}")
            faces.append(f)
    maxh = np.sqrt(2.3 / ntri_target)        # about 2.3 / maxh^2 triangles per unit area
    ngmesh = OCCGeometry(Glue(faces), dim=2).GenerateMesh(maxh=maxh)
    return ngmesh, maxh


def arrays(ngmesh):
    X = np.array(ngmesh.Coordinates())
    el = ngmesh.Elements2D().NumPy()
    T = np.array(el["nodes"][:, :3], dtype=np.int64) - 1
    frag = np.array(el["index"], dtype=np.int32) - 1
    P = X[T]
    area2 = ((P[:, 1, 0] - P[:, 0, 0]) * (P[:, 2, 1] - P[:, 0, 1])
             - (P[:, 1, 1] - P[:, 0, 1]) * (P[:, 2, 0] - P[:, 0, 0]))
    T[area2 < 0] = T[area2 < 0][:, [0, 2, 1]]            # counter-clockwise
    return X, T, frag


def boundary_edges(T):
    e = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    n = e.max() + 1
    return e[~np.isin(e[:, 0] * n + e[:, 1], e[:, 1] * n + e[:, 0])]


def cut(X, T, frag):
    """Duplicate every vertex per fragment: the pieces become separate bodies."""
    key = T * (frag.max() + 1) + frag[:, None]
    uniq, inv = np.unique(key.ravel(), return_inverse=True)
    Xc = X[uniq // (frag.max() + 1)]
    return Xc, inv.reshape(T.shape).astype(np.int32)


def best_of(f, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def elasticity_solve_time(ngmesh, repeat):
    mesh = ngsolve.Mesh(ngmesh)
    fes = ngsolve.VectorH1(mesh, order=1)
    u, v = fes.TnT()
    E, nu = 1.0, 0.3
    mu, lam = E / 2 / (1 + nu), E * nu / (1 + nu) / (1 - 2 * nu)
    eps = lambda w: ngsolve.Sym(ngsolve.Grad(w))  # noqa: E731
    free = fes.FreeDofs()
    nv = mesh.nv
    for vtx in np.flatnonzero(np.array(ngmesh.Coordinates())[:, 0] < 1e-12):
        free.Clear(int(vtx))
        free.Clear(int(vtx) + nv)                   # component-blocked VectorH1 dofs
    with ngsolve.TaskManager():
        a = ngsolve.BilinearForm(fes, symmetric=True)
        a += (2 * mu * ngsolve.InnerProduct(eps(u), eps(v))
              + lam * ngsolve.Trace(eps(u)) * ngsolve.Trace(eps(v))) * ngsolve.dx
        a.Assemble()
        f = ngsolve.LinearForm(fes)
        f += -1e-3 * v[1] * ngsolve.dx
        f.Assemble()
        gfu = ngsolve.GridFunction(fes)

        def solve():
            inv = a.mat.Inverse(free, inverse="sparsecholesky")
            gfu.vec.data = inv * f.vec
        t, _ = best_of(solve, repeat)
    return t, fes.ndof


def run_case(ntri, k, repeat):
    ngmesh, h = pieces_mesh(ntri, k)
    X0, T0, frag = arrays(ngmesh)
    X, T = cut(X0, T0, frag)
    E = boundary_edges(T)
    # expand every piece about its centroid: overlap about 0.2 h across each cut
    delta = 0.2 * h / (1.0 / k)
    cen = np.stack([np.bincount(frag, weights=X[T][:, :, d].mean(axis=1)) / np.bincount(frag)
                    for d in range(2)], axis=1)
    vfrag = np.zeros(len(X), dtype=np.int64)
    vfrag[T.ravel()] = np.repeat(frag, 3)
    U = delta * (X - cen[vfrag])
    nv = len(X)
    left = np.flatnonzero(X[:, 0] < 1e-12)
    fixed = np.concatenate([left, left + nv])

    t_col, pairs = best_of(lambda: collision.detect_collisions(
        X, U, T, boundary_edges=E, fragment=frag), repeat)
    t_asm, cs = best_of(lambda: contact.select_contacts(X, U, T, E, pairs), repeat)
    t_qr, keep = best_of(lambda: contact.independent_rows(cs.C, fixed_dofs=fixed), repeat)
    t_solve, ndof = elasticity_solve_time(ngmesh, repeat)
    cand = collision.candidate_mask(T, E)
    return {
        "ntri": int(len(T)), "n_candidates": int(cand.sum()), "n_pairs": int(len(pairs)),
        "n_constraints": int(len(keep)), "n_constraints_before_qr": int(len(cs)),
        "t_collision": t_col, "t_assembly": t_asm, "t_qr": t_qr, "t_solve": t_solve,
        "ndof_solve": int(ndof), "ratio": (t_col + t_asm + t_qr) / t_solve,
    }, (X0, T0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="only the 10k case")
    parser.add_argument("--pieces", type=int, default=4, help="k: k x k pieces")
    parser.add_argument("--repeat", type=int, default=3)
    benchmark_json.add_options(parser)
    args = parser.parse_args(argv)
    benchmark_json.refuse_existing(parser, args)
    sizes = [10_000] if args.quick else [10_000, 30_000, 100_000]
    cases, last = [], None
    for n in sizes:
        case, last = run_case(n, args.pieces, args.repeat)
        cases.append(case)
        print(json.dumps(case), file=sys.stderr)
    X0, T0 = last
    no_edges = np.zeros((0, 2), dtype=np.int64)
    t_none, cs = best_of(lambda: contact.contact_constraints(X0, None, T0, no_edges),
                         args.repeat)
    assert len(cs) == 0
    benchmark_json.write(args, {"cases": cases, "no_crack_overhead_s": t_none,
                                "no_crack_ntri": int(len(T0))})


if __name__ == "__main__":
    main()
