"""Crack a pre-stretched plate with a hole and write the result to VTK.

Domain: the square (0, 1)^2 with a circular hole of radius 0.1 in the middle.
PDE: linear elasticity (E = 1, nu = 0.18), the left and right sides pulled apart by
+-stretch/2 in x, y free (gliding); a tiny zero-order term keeps floating fragments
solvable (a stand-in for the team's fragment constraints).
Crack model: paper section 3 (nodal principal Green-Lagrange strain above the critical
strain splits vertices), repeated solve + split passes at fixed load until no vertex is
overstrained (release of energy through crack formation, paper section 4.2).

It illustrates how to:
- run `ngfracture.fracture.crack_step` in a load step,
- carry the displacement exactly to the split mesh,
- write the cracked mesh with displacement and fragment number to VTK (pyvista).

Run: python examples/crack_plate.py [outdir]
"""
import os
import sys

import numpy as np
import ngsolve
from netgen.geom2d import SplineGeometry

from ngfracture import fracture


def plate_with_hole(maxh):
    geo = SplineGeometry()
    geo.AddRectangle((0, 0), (1, 1), bcs=["bottom", "right", "top", "left"], leftdomain=1)
    geo.AddCircle((0.5, 0.5), 0.1, leftdomain=0, rightdomain=1, bc="hole")
    geo.SetMaterial(1, "glass")
    return ngsolve.Mesh(geo.GenerateMesh(maxh=maxh))


def solve(mesh, stretch, E=1.0, nu=0.18):
    """Displacement as a VectorH1 GridFunction (what ngfracture.fracture expects)."""
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    # gliding: x fixed on left and right, y free; solved in H1 x H1, whose dof layout
    # (component blocks) is that of VectorH1
    X = ngsolve.H1(mesh, order=1, dirichlet="left|right") * ngsolve.H1(mesh, order=1)
    (ux, uy), (vx, vy) = X.TnT()
    u, v = ngsolve.CF((ux, uy)), ngsolve.CF((vx, vy))
    eps = lambda a, b: ngsolve.CF((ngsolve.grad(a)[0], 0.5 * (ngsolve.grad(a)[1] + ngsolve.grad(b)[0]),
                                   0.5 * (ngsolve.grad(a)[1] + ngsolve.grad(b)[0]), ngsolve.grad(b)[1]),
                                  dims=(2, 2))
    eu, ev = eps(ux, uy), eps(vx, vy)
    a = ngsolve.BilinearForm(X, symmetric=True)
    a += (2 * mu * ngsolve.InnerProduct(eu, ev) + lam * ngsolve.Trace(eu) * ngsolve.Trace(ev)
          + 1e-8 * u * v) * ngsolve.dx
    g = ngsolve.GridFunction(X)
    with ngsolve.TaskManager():
        a.Assemble()
        g.components[0].Set(stretch * (ngsolve.x - 0.5), ngsolve.BND)
        r = g.vec.CreateVector()
        r.data = -a.mat * g.vec
        g.vec.data += a.mat.Inverse(X.FreeDofs(), inverse="sparsecholesky") * r
    gfu = ngsolve.GridFunction(ngsolve.VectorH1(mesh, order=1))
    gfu.vec.data = g.vec
    return gfu


def write_vtk(mesh, u, result, path):
    import pyvista as pv
    P = mesh.ngmesh.Coordinates()[:, :2]
    T = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3] - 1
    cells = np.column_stack([np.full(len(T), 3), T]).ravel()
    grid = pv.UnstructuredGrid(cells, np.full(len(T), pv.CellType.TRIANGLE),
                               np.column_stack([P, np.zeros(len(P))]))
    U = fracture.vertex_displacement(u)
    grid.point_data["displacement"] = np.column_stack([U, np.zeros(len(U))])
    grid.cell_data["fragment"] = result.fragment
    grid.save(path)
    return path


def main(outdir=".", maxh=0.03, stretch=4e-3, critical=6.5e-3, max_passes=40):
    """Returns (mesh, displacement, list of split counts per pass, vtk path, last result)."""
    mesh = plate_with_hole(maxh)
    u = solve(mesh, stretch)
    history = []
    result = None
    for _ in range(max_passes):
        new_mesh, new_u, res = fracture.crack_step(mesh, u, critical)
        n = new_mesh.nv - mesh.nv
        if n == 0 and result is not None:
            break
        history.append(n)
        mesh, result = new_mesh, res
        u = solve(mesh, stretch)     # re-equilibrate the cracked plate at the same load
        if n == 0:
            break
    path = write_vtk(mesh, u, result, os.path.join(outdir, "crack_plate.vtu"))
    return mesh, u, history, path, result


if __name__ == "__main__":
    mesh, u, history, path, result = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    L = ngsolve.Integrate(1, mesh, ngsolve.BND, definedon=mesh.Boundaries("crack")) \
        if "crack" in mesh.GetBoundaries() else 0.0
    print(f"passes: {len(history)}, new vertices per pass: {history}")
    print(f"crack faces length: {L:.4f}, fragments: {result.nfragments}, written: {path}")
