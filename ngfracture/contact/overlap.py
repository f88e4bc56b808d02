"""Overlap area between the triangles of the current configuration (a measure of penetration).

Contact keeps the pieces apart at the nodes of its rows; what overlap remains is that of
the polygonal lips between them. :func:`fragment_overlap_area` measures it exactly for
straight-sided triangles: the colliding pairs of :func:`ngfracture.contact.collision.detect_collisions`
with tol = 0, intersected by convex clipping (:func:`overlap_area`). A run's summary reports
it for the final state (``max_overlap_area``).
"""
import numpy as np

from .collision import detect_collisions
from ..fracture.strain import vertex_displacement
from ..geometry.meshio import boundary_only

__all__ = ["overlap_area", "fragment_overlap_area"]


def overlap_area(x, triangles, pairs):
    """Total area of the intersections of the given triangle pairs (convex clipping).

    Parameters
    ----------
    x : numpy.ndarray (nv, 2)
        Current vertex positions.
    triangles : numpy.ndarray (ne, 3)
        Counter-clockwise triangles.
    pairs : numpy.ndarray (k, 2)
        Triangle pairs to intersect.

    Returns
    -------
    float
    """
    total = 0.0
    for i, j in np.asarray(pairs, dtype=np.int64).reshape(-1, 2):
        # relative to a vertex of the pair: areas from coordinates far from the origin
        # would carry the rounding of their products (2e-8 at 1e4), not of the overlap
        origin = x[triangles[j][0]]
        poly = [tuple(p) for p in x[triangles[i]] - origin]
        clip = x[triangles[j]] - origin
        if _signed_area(clip) < 0:
            clip = clip[::-1]
        for k in range(3):
            a, b = clip[k], clip[(k + 1) % 3]
            poly = _clip_half_plane(poly, a, b)
            if not poly:
                break
        if len(poly) >= 3:
            total += abs(_signed_area(np.array(poly)))
    return total


def _signed_area(p):
    p = np.asarray(p)
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def _clip_half_plane(poly, a, b):
    """Sutherland-Hodgman: the part of poly left of the directed line a -> b."""
    def side(p):
        return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    out = []
    for k in range(len(poly)):
        p, q = poly[k], poly[(k + 1) % len(poly)]
        sp_, sq = side(p), side(q)
        if sp_ >= 0:
            out.append(p)
        if sp_ * sq < 0:
            t = sp_ / (sp_ - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def fragment_overlap_area(problem):
    """Total overlap area between triangles of the current configuration (0 if none).

    Pairs are those of ``detect_collisions`` with tol = 0 on the true boundary segments
    (interiors overlapping; mesh neighbours in one fragment excepted), their intersection
    areas summed by :func:`overlap_area`.

    Parameters
    ----------
    problem : ElasticProblem
        Its mesh, fragments and displacement; only the vertex values of the displacement
        count (straight-sided triangles).

    Returns
    -------
    float
        Area, in the square of the mesh's length unit.
    """
    arrays = boundary_only(problem.arrays)
    U = vertex_displacement(problem.u)
    _, comp = problem.fragments()
    fragment = comp[arrays.triangles[:, 0]]
    pairs = detect_collisions(arrays.points, U, arrays.triangles, boundary_edges=arrays.segments,
                              fragment=fragment, tol=0.0)
    if len(pairs) == 0:
        return 0.0
    return overlap_area(arrays.points + U, arrays.triangles, pairs)
