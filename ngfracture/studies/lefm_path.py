"""A crack path by linear elastic fracture mechanics: the reference for mixed-mode paths.

Independent of the crack criterion: at each increment the body is meshed with the crack
as a polyline of the geometry (fine at its tip), the polyline opened into two lips by
vertex splitting along itself (no criterion involved), solved linear elastic, K_I and
K_II read from the lips' relative displacement behind the tip (displacement correlation,
``u+ - u- = (kappa + 1) / mu K sqrt(d / (2 pi))`` at distance d, extrapolated linearly to
d = 0 from 8 h to 20 h: closer to the tip the P1 solution is polluted by the singularity),
and the crack extended by ``da`` in the direction of maximum hoop stress (Erdogan and Sih):

    theta = 2 atan((K_I - sqrt(K_I^2 + 8 K_II^2)) / (4 K_II))

from the crack's direction, counter-clockwise positive. The body is a polygon whose edge
crack starts at one of its corners; plane stress.
"""
import math
from dataclasses import dataclass

import numpy as np
import ngsolve as ng
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters

from ..fracture.split import split_vertices
from ..mechanics.materials import LinearElastic
from ..mechanics.problem import ElasticProblem

__all__ = ["LefmPath", "edge_crack_path", "kink_angle", "cracked_rectangle", "cracked_polygon"]


@dataclass
class LefmPath:
    """A crack path and the SIFs at each tip on the way.

    Parameters
    ----------
    points : numpy.ndarray (k, 2)
        The path, mouth first.
    k1, k2 : numpy.ndarray
        K_I and K_II at each tip the path was extended from.
    """
    points: np.ndarray
    k1: np.ndarray
    k2: np.ndarray


def kink_angle(k1, k2):
    """The maximum-hoop-stress kink angle (radians, counter-clockwise from the crack).

    Parameters
    ----------
    k1, k2 : float

    Returns
    -------
    float
    """
    if k2 == 0:
        return 0.0
    return 2 * math.atan((k1 - math.sqrt(k1 * k1 + 8 * k2 * k2)) / (4 * k2))


def cracked_rectangle(width, height, path, maxh, h_path, refine=()):
    """A rectangle with an edge crack from its left side, see :func:`cracked_polygon`.

    Parameters
    ----------
    width, height : float
    path : array_like (k, 2)
        The crack's points; the first on the left side, strictly inside it.
    maxh, h_path : float
    refine : iterable of (x, y, h)

    Returns
    -------
    ngsolve.Mesh
        Boundaries bottom, right, top, left; the lips "crack" and "path".
    """
    corners = [(0.0, 0.0), (width, 0.0), (width, height), (0.0, height), tuple(np.asarray(path, dtype=float)[0])]
    return cracked_polygon(corners, ["bottom", "right", "top", "left", "left"], path, maxh, h_path, refine)


def cracked_polygon(corners, names, path, maxh, h_path, refine=(), holes=()):
    """A polygon with an edge crack along a polyline from one of its corners, opened into lips.

    Parameters
    ----------
    corners : sequence of (x, y)
        Counter-clockwise; the crack's mouth ``path[0]`` is one of them.
    names : sequence of str
        The boundary name of the side from each corner to the next.
    path : array_like (k, 2)
        The crack's points, mouth first.
    maxh, h_path : float
        Mesh size away from and along the crack (the tip too).
    refine : iterable of (x, y, h)
        More local mesh sizes.
    holes : iterable of (x, y, radius)
        Circular holes (boundary "hole"), clear of the crack.

    Returns
    -------
    ngsolve.Mesh
        The sides' boundary names; the lips "crack" and "path".

    Raises
    ------
    ValueError
        A mouth that is not a corner.
    """
    path = np.asarray(path, dtype=float)
    geo = SplineGeometry()
    pts = [geo.AppendPoint(*c) for c in corners]
    for i, name in enumerate(names):
        geo.Append(["line", pts[i], pts[(i + 1) % len(pts)]], bc=name, leftdomain=1, rightdomain=0)
    mouth = [k for k, c in enumerate(corners) if np.allclose(c, path[0], rtol=0, atol=0)]
    if not mouth:
        raise ValueError(f"cracked_polygon: the crack's mouth {tuple(path[0])} is not a corner")
    prev = pts[mouth[0]]
    for p in path[1:]:
        here = geo.AppendPoint(*p, maxh=h_path)
        geo.Append(["line", prev, here], bc="path", leftdomain=1, rightdomain=1, maxh=h_path)
        prev = here
    for x, y, r in holes:
        geo.AddCircle((x, y), r, leftdomain=0, rightdomain=1, bc="hole")
    mp = MeshingParameters(maxh=maxh)
    for x, y, h in refine:
        mp.RestrictH(x=x, y=y, z=0, h=h)
    mesh = ng.Mesh(geo.GenerateMesh(mp=mp))
    X = mesh.ngmesh.Coordinates()[:, :2]
    on_path, normals = [], []
    for a, b in zip(path[:-1], path[1:]):
        t = (b - a) / np.linalg.norm(b - a)
        s = (X - a) @ t
        off = np.abs((X - a) @ np.array([-t[1], t[0]]))
        hit = np.flatnonzero((off < 1e-9) & (s > -1e-9) & (s < np.linalg.norm(b - a) - 1e-9))
        on_path += hit.tolist()
        normals += [[-t[1], t[0]]] * len(hit)
    order = np.unique(on_path, return_index=True)[1]
    vertices = np.asarray(on_path)[order]
    by_distance = np.argsort(np.hypot(*(X[vertices] - path[0]).T), kind="stable")
    return split_vertices(mesh, vertices[by_distance], np.asarray(normals)[order][by_distance]).mesh


def _inside(corners, point):
    """Whether a point lies inside a polygon (ray casting)."""
    c = np.asarray(corners, dtype=float)
    a, b = c, np.roll(c, -1, axis=0)
    crosses = ((a[:, 1] > point[1]) != (b[:, 1] > point[1]))
    x_at = a[:, 0] + (point[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / np.where(b[:, 1] != a[:, 1], b[:, 1] - a[:, 1], 1.0)
    return bool(np.count_nonzero(crosses & (point[0] < x_at)) % 2)


def _sifs(prob, points, h, material):
    """K_I, K_II at the tip from the lips' nodal displacements 8 h to 20 h behind it, the
    distance measured along the crack, the jumps in the frame of its last segment."""
    tip = points[-1]
    t = (tip - points[-2]) / np.linalg.norm(tip - points[-2])
    n = np.array([-t[1], t[0]])
    mu = material.E / (2 * (1 + material.nu))
    kappa = (3 - material.nu) / (1 + material.nu)
    X, tri = prob.arrays.points, prob.arrays.triangles
    U = prob.u.vec.FV().NumPy().reshape(2, -1)[:, :len(X)].T
    # the side of a lip vertex: where its triangles' centroids lie from its segment
    centroid = X[tri].mean(axis=1)
    d, k1, k2, walked = [], [], [], 0.0
    for a, b in zip(points[-2::-1], points[:0:-1]):          # segments from the tip backwards
        length = float(np.linalg.norm(b - a))
        ts = (b - a) / length
        ns = np.array([-ts[1], ts[0]])
        back = (b - X) @ ts
        on = np.flatnonzero((np.abs((X - b) @ ns) < 1e-9) & (back > 1e-9) & (back < length - 1e-9))
        for key in np.unique(np.round(back[on] / h, 6)):
            dist = walked + float(back[on][np.round(back[on] / h, 6) == key][0])
            pair = on[np.round(back[on] / h, 6) == key]
            if len(pair) != 2 or not 7.5 * h < dist < 20.5 * h:
                continue
            side = [((centroid[(tri == v).any(axis=1)] - X[v]) @ ns).sum() for v in pair]
            upper, lower = pair if side[0] > side[1] else pair[::-1]
            jump = U[upper] - U[lower]
            scale = mu / (kappa + 1) * math.sqrt(2 * math.pi / dist)
            d.append(dist)
            k1.append(scale * jump @ n)
            k2.append(scale * jump @ t)
        walked += length
        if walked > 20.5 * h:
            break
    if len(d) < 3:
        raise RuntimeError("edge_crack_path: too few lip vertices behind the tip to read the SIFs")
    return float(np.polyfit(d, k1, 1)[1]), float(np.polyfit(d, k2, 1)[1])


def edge_crack_path(corners, names, path, apply_load, E, nu, da, steps, maxh, h_tip, holes=()):
    """The LEFM path of an edge crack grown by ``steps`` increments of ``da``.

    Parameters
    ----------
    corners, names : sequences
        The body, a polygon (:func:`cracked_polygon`); the crack's mouth is a corner.
    path : array_like (k, 2)
        The initial crack, mouth first.
    apply_load : callable(ElasticProblem)
        Adds the constraints and loads (linear: the load's size does not matter); rigid
        modes they leave free are held (``solve(fix_free_modes=True)``).
    E, nu : float
        Plane stress.
    da : float
        Crack increment.
    steps : int
    maxh, h_tip : float
        Mesh sizes away from and at the crack (h_tip within 24 h_tip of the tip).
    holes : iterable of (x, y, radius)
        Circular holes in the body.

    Returns
    -------
    LefmPath
        Stops early where the next tip would leave the body or come within 2 ``da`` of a hole.

    Raises
    ------
    RuntimeError
        A solve that failed, or too few lip vertices behind a tip to read its SIFs.
    """
    material = LinearElastic(E, nu, plane="stress")
    points, k1s, k2s = [np.asarray(p, dtype=float) for p in path], [], []
    for _ in range(steps):
        tip, before = points[-1], points[-2]
        t = (tip - before) / np.linalg.norm(tip - before)
        around = [(tip[0] + i * h_tip, tip[1] + j * h_tip, h_tip) for i in range(-24, 25, 3) for j in range(-24, 25, 3)]
        mesh = cracked_polygon(corners, names, np.array(points), maxh, h_tip, around, holes)
        prob = ElasticProblem(mesh, material)
        apply_load(prob)
        status = prob.solve(fix_free_modes=True)
        if not status.converged:
            raise RuntimeError(f"edge_crack_path: the solve failed ({status.message})")
        k1, k2 = _sifs(prob, np.array(points), h_tip, material)
        k1s.append(k1)
        k2s.append(k2)
        theta = kink_angle(k1, k2)
        c, s = math.cos(theta), math.sin(theta)
        nxt = tip + da * np.array([c * t[0] - s * t[1], s * t[0] + c * t[1]])
        if not _inside(corners, nxt) or any(math.hypot(nxt[0] - x, nxt[1] - y) < r + 2 * da for x, y, r in holes):
            break
        points.append(nxt)
    return LefmPath(np.array(points), np.array(k1s), np.array(k2s))
