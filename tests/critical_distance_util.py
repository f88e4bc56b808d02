"""Linear-elastic set-ups for the critical-distance criterion tests and benchmark.

Every helper solves one linear problem at unit load; the criterion's measure is linear in
the load, so the initiation load is the critical strain over the largest measure.
"""
import math

import numpy as np
import ngsolve as ng
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters

from ngfracture.fracture import Criterion, principal, split_vertices
from ngfracture.mechanics.materials import LinearElastic


def solve_linear(mesh, material, dirichlet, value, tractions=()):
    """Small-strain solve; value is a 2-vector CF on the Dirichlet boundaries (or None: zero).

    ``dirichlet`` may also be a pair (names_x, names_y) for componentwise (gliding) conditions.
    """
    lam, mu = material.lam, material.mu
    if isinstance(dirichlet, tuple):
        fes = ng.VectorH1(mesh, order=1, dirichletx=dirichlet[0], dirichlety=dirichlet[1])
    else:
        fes = ng.VectorH1(mesh, order=1, dirichlet=dirichlet)
    u, v = fes.TnT()
    eps = lambda w: ng.Sym(ng.Grad(w))
    a = ng.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ng.InnerProduct(eps(u), eps(v)) + lam * ng.Trace(eps(u)) * ng.Trace(eps(v))) * ng.dx
    f = ng.LinearForm(fes)
    for name, t in tractions:
        f += ng.InnerProduct(ng.CF(t), v) * ng.ds(name)
    a.Assemble()
    f.Assemble()
    gfu = ng.GridFunction(fes)
    if value is not None:
        names = dirichlet if isinstance(dirichlet, str) else "|".join(n for n in dirichlet if n)
        gfu.Set(value, definedon=mesh.Boundaries(names))
    r = f.vec.CreateVector()
    r.data = f.vec - a.mat * gfu.vec
    gfu.vec.data += a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") * r
    return gfu


def glass_plane_stress():
    """The plate's glass, small strain, plane stress."""
    return LinearElastic(5e9, 0.18, plane="stress")


def plate_initiation(notch_h, radius, maxh=0.034, critical=1.3817e-4, notch_zone=0.0):
    """Extension x at which the plate's first vertex reaches the critical measure.

    radius None: the one-ring nodal strain (the paper's); else the critical distance.
    Returns (x_init, the mesh, the vertex).
    """
    from ngfracture.scenes import notched_plate_mesh
    mesh = notched_plate_mesh(maxh=maxh, notch_maxh=notch_h, notch_zone=notch_zone)
    mat = glass_plane_stress()
    u = solve_linear(mesh, mat, ("left|right", ""), ng.CF((ng.IfPos(ng.x - 0.5, 0.5, -0.5), 0)))
    crit = Criterion(critical, radius=radius, material=mat if radius else None, measure="linear")
    values, _ = principal(crit.overstrain(mesh, u))     # overstrain: 1 at the critical measure
    k = int(np.argmax(values))
    return 1.0 / values[k], mesh, k


def tada_centre_crack(a, b):
    """Geometry factor F of a centre crack 2a in a strip of width 2b: K = sigma sqrt(pi a) F.

    Tada, Paris, Irwin, The Stress Analysis of Cracks Handbook, 2.1 (0.1 % for any a/b).
    """
    s = a / b
    return (1 - 0.025 * s**2 + 0.06 * s**4) * math.sqrt(1 / math.cos(math.pi * s / 2))


def centre_crack_mesh(a, tip_h, b=0.5, height=1.0, maxh=0.06, zone=0.0):
    """A 2b x 2height plate with a straight crack from (-a, 0) to (a, 0), cut by node splitting.

    The crack line is an interior edge of the geometry, refined to tip_h within 2a of
    each tip (at most halfway to the edge) and to tip_h in disks of radius ``zone``
    around the tips; its inner vertices are split with the direction (0, 1), so the crack faces
    run along the mesh edges. Returns (mesh, tip vertex at (a, 0), tip vertex at (-a, 0)).
    """
    geo = SplineGeometry()
    c = [geo.AppendPoint(x, y) for x, y in ((-b, -height), (b, -height), (b, height), (-b, height))]
    for i, bc in enumerate(("bottom", "right", "top", "left")):
        geo.Append(["line", c[i], c[(i + 1) % 4]], bc=bc, leftdomain=1, rightdomain=0)
    reach = min(3 * a, (a + b) / 2)       # the refined line ends inside the plate
    ends = [geo.AppendPoint(-reach, 0), geo.AppendPoint(-a, 0, maxh=tip_h),
            geo.AppendPoint(a, 0, maxh=tip_h), geo.AppendPoint(reach, 0)]
    for i in range(3):
        geo.Append(["line", ends[i], ends[i + 1]], bc="line", leftdomain=1, rightdomain=1, maxh=tip_h if i != 1 else 4 * tip_h)
    mp = MeshingParameters(maxh=maxh)
    n = int(math.ceil(zone / tip_h))
    for tip_x in (-a, a):                  # mesh size tip_h in the disks of radius zone
        for i in range(-n, n + 1):
            for j in range(-n, n + 1):
                if (i * i + j * j) * tip_h ** 2 <= zone ** 2:
                    mp.RestrictH(x=tip_x + i * tip_h, y=j * tip_h, z=0, h=tip_h)
    mesh = ng.Mesh(geo.GenerateMesh(mp=mp))
    pts = mesh.ngmesh.Coordinates()[:, :2]
    on_line = np.abs(pts[:, 1]) < 1e-12
    inner = np.flatnonzero(on_line & (np.abs(pts[:, 0]) < a - 1e-12))
    inner = inner[np.argsort(pts[inner, 0])]
    res = split_vertices(mesh, inner, np.tile([0.0, 1.0], (len(inner), 1)))
    tips = [int(np.flatnonzero(on_line & (np.abs(pts[:, 0] - s * a) < 1e-12))[0]) for s in (1, -1)]
    return res.mesh, tips[0], tips[1]
