"""Meshes, fields and solves shared by tests/test_criterion3d.py and benchmarks/criterion3d.py."""
import math

import ngsolve as ng
import numpy as np

from ngfracture.geometry.internal_crack import open_internal_surface
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh


def graded(half, h, core, ratio=1.3):
    """Symmetric grid coordinates on [-half, half]: spacing h within |x| <= core, then growing
    geometrically by ``ratio`` to the ends (the last cell stretched to land on them)."""
    inner = np.arange(h, core + 0.5 * h, h)
    out, step, x = [], h, inner[-1]
    while x < half - 1e-12:
        step *= ratio
        x = min(x + step, half)
        if half - x < 0.5 * step:
            x = half
        out.append(x)
    pos = np.concatenate([inner, out])
    return np.concatenate([-pos[::-1], [0.0], pos])


def plane_faces(arrays, axis, value, select):
    """The tet faces lying on the plane x[axis] = value whose three vertices pass ``select``
    (a function of the points (k, 3) -> bool (k,)), oriented with the normal along +axis."""
    opp = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    tri = np.unique(np.sort(arrays.tets[:, opp].reshape(-1, 3), axis=1), axis=0)
    P = arrays.points
    on = np.all(P[tri][:, :, axis] == value, axis=1)
    tri = tri[on]
    ok = np.all(select(P[tri.ravel()]).reshape(-1, 3), axis=1)
    tri = tri[ok]
    n = np.cross(P[tri[:, 1]] - P[tri[:, 0]], P[tri[:, 2]] - P[tri[:, 0]])
    flip = n[:, axis] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return tri


def through_crack_slab(half, thickness, h, core, nz):
    """A slab [-half, half]^2 x [0, thickness] with a crack on y = 0 for x <= 0 (front on the
    z axis), graded grid with spacing h within |x|, |y| <= core; nz cells through the thickness."""
    g = graded(half, h, core)
    box = box_mesh(g, g, np.linspace(0.0, thickness, nz + 1))
    faces = plane_faces(box, 1, 0.0, lambda p: p[:, 0] <= 0.0)
    return open_internal_surface(box, faces), len(box.points)


def williams_mode1(points, K, E, nu, lower):
    """Plane-strain mode-I displacement (K term) about the z axis, crack along x < 0;
    ``lower`` (bool per point) puts a point of the crack plane on the lower lip (theta = -pi)."""
    mu, kappa = E / (2 * (1 + nu)), 3 - 4 * nu
    x, y = points[:, 0], points[:, 1]
    rho = np.hypot(x, y)
    theta = np.arctan2(y, x)
    theta = np.where(lower & (y == 0) & (x < 0), -math.pi, theta)
    f = K / (2 * mu) * np.sqrt(rho / (2 * math.pi))
    ux = f * np.cos(theta / 2) * (kappa - 1 + 2 * np.sin(theta / 2) ** 2)
    uy = f * np.sin(theta / 2) * (kappa + 1 - 2 * np.cos(theta / 2) ** 2)
    return np.stack([ux, uy, np.zeros_like(ux)], axis=1)


def elasticity(arrays, E, nu, values=None, traction=None, **dirichlet):
    """Linear elasticity on the mesh (VectorH1 order 1, 3D Hooke), sparse Cholesky.

    dirichlet: VectorH1's flags (dirichlet="a|b", dirichletx=..., ...); values: (nv, 3)
    vertex values imposed on those boundaries (else 0); traction: dict boundary name ->
    normal stress sigma (pulling out of the body). Returns the vertex displacements (nv, 3) and the seconds of the
    factorisation and solve."""
    mesh = solid_mesh(arrays)
    fes = ng.VectorH1(mesh, order=1, **dirichlet)
    u, v = fes.TnT()
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    eps_u, eps_v = ng.Sym(ng.Grad(u)), ng.Sym(ng.Grad(v))
    a = ng.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ng.InnerProduct(eps_u, eps_v) + lam * ng.Trace(eps_u) * ng.Trace(eps_v)) * ng.dx
    f = ng.LinearForm(fes)
    for name, sigma in (traction or {}).items():
        f += sigma * (ng.specialcf.normal(3) * v) * ng.ds(name)
    a.Assemble()
    f.Assemble()
    gf = ng.GridFunction(fes)
    nv = mesh.nv
    if values is not None:
        gf.vec.FV().NumPy()[:] = np.asarray(values, dtype=float).T.ravel()
    r = f.vec.CreateVector()
    r.data = f.vec - a.mat * gf.vec
    import time
    t0 = time.perf_counter()
    inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
    gf.vec.data += inv * r
    seconds = time.perf_counter() - t0
    return gf.vec.FV().NumPy().reshape(3, -1)[:, :nv].T.copy(), seconds
