"""Edge-to-edge contact rows on tetrahedral meshes: two boundary edges that must not cross.

Node-to-face rows (:mod:`ngfracture.contact.rows3d`) keep every boundary vertex out of the
other fragments, but two polyhedral surfaces can interpenetrate with no vertex inside the
other: two convex edges (ridges) that cross, or a ridge pushed through a flat face between
its vertices. Where the detection
(:class:`~ngfracture.contact.edge_crossings3d.EdgeCrossingDetector`) finds two boundary
edges a = (a0, a1) and b = (b0, b1) interlocked, this module gives them one row,

    g_E(u) = n . ( x_a(s) - x_b(t) ),    x_a(s) = (1 - s) x_a0 + s x_a1,
                                         x_b(t) = (1 - t) x_b0 + t x_b1,

with s, t the parameters of the closest points of the two edges' lines and n the unit
normal of both lines (a x b normalised) at the configuration of the detection, on the side
that makes the interlocked pair's gap negative: g_E >= 0 is "a has not passed through b".
The derivatives of s, t and n do not enter the first-order change of g_E (n is orthogonal
to both edges, and x_a(s) - x_b(t) is parallel to n), so with them frozen

    g_E(u) = C u + g,    C u = n . ( u_a(s) - u_b(t) ),    g = n . ( X_a(s) - X_b(t) ),

the linearisation at the detection, exact to first order, in the layout and sign
convention of the node-to-face rows (dof comp * nv + v; an active row imposes C u + g = 0;
a compressive multiplier is <= 0). A row's key is ("e", a0, a1, b0, b1), a the edge of the
lower number among the mesh's sorted boundary edges.

A re-linearisation (:func:`relinearise_edge_rows`) recomputes s, t and n at the current
configuration; n keeps its side (the sign that agrees with the old n), and s and t are
clipped to [0, 1]: beyond an edge's end the row holds the end point, as a node-to-face row
clipped to its triangle holds the triangle's edge. Nearly parallel edges (the sine of their
angle below :data:`PARALLEL`) have no well-defined common normal: the detection makes no row
for them (where parallel edges overlap, the vertex of one lies inside the other's fragment
and a node-to-face row holds it), and a re-linearisation keeps the old s, t and n.

A row whose edge a is a vertex twice, a = (v, v), is a node-to-edge row
(:mod:`~ngfracture.contact.clipped3d`): g = n . (x_v - x_b(t)), key ("n", v, b0, b1), b a
corner twice for a node-to-corner row. Its re-linearisation keeps t and n, the
detection's: the direction from v to the edge is defined while v is off the edge, not
once the row holds v on it (where v is found deep again, the active set takes the new
detection's row, :meth:`~ngfracture.contact.active_set3d.ActiveSet3d.update`).
"""
from dataclasses import dataclass
import functools
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from .. import _ngfracture as _ext
from .rows import RowTable

__all__ = ["EdgeRows", "PARALLEL", "no_edge_rows", "two_faces", "edge_rows", "relinearise_edge_rows"]

#: edges whose directions' sine is below this have no common normal to rely on
PARALLEL = 1e-6


@dataclass
class EdgeRows(RowTable):
    """Edge-to-edge rows, one entry per row of C.

    Parameters
    ----------
    edge_a, edge_b : numpy.ndarray of int, shape (m, 2)
        The vertices of the two edges (a sorted edge of the mesh's boundary each).
    st : numpy.ndarray, shape (m, 2)
        The parameters s (along a) and t (along b) of the closest points.
    normal : numpy.ndarray, shape (m, 3)
        Unit normal of both edges, from b towards a where they are apart.
    dist : numpy.ndarray, shape (m,)
        Signed distance at the configuration of the linearisation (negative: crossed).
    g : numpy.ndarray, shape (m,)
        Constant part: C u + g is the linearised signed gap.
    nv : int
        Number of vertices (C has 3 nv columns).
    """
    edge_a: np.ndarray
    edge_b: np.ndarray
    st: np.ndarray
    normal: np.ndarray
    dist: np.ndarray
    g: np.ndarray
    nv: int
    FIELDS: ClassVar[tuple] = ("edge_a", "edge_b", "st", "normal", "dist", "g")

    @functools.cached_property
    def C(self):
        """The gap rows as a sparse matrix, shape (m, 3 nv), built at first use."""
        m, nv = len(self.g), self.nv
        verts, w = _vertices_weights(self)
        rows = np.repeat(np.arange(m), 12)
        cols = np.concatenate([verts + comp * nv for comp in range(3)], axis=1).ravel()
        vals = np.concatenate([w * self.normal[:, comp:comp + 1] for comp in range(3)], axis=1).ravel()
        C = sp.csr_matrix((vals, (rows, cols)), shape=(m, 3 * nv))        # sorted columns per row
        C.eliminate_zeros()                                                # s or t at an end
        return C

    def keys(self):
        """The key of every row, ("e", a0, a1, b0, b1); ("n", v, b0, b1) for a node-to-edge row
        (a = (v, v), :mod:`~ngfracture.contact.clipped3d`).

        Returns
        -------
        list of tuple
        """
        return [("n", a0, b0, b1) if a0 == a1 else ("e", a0, a1, b0, b1)
                for (a0, a1), (b0, b1) in zip(self.edge_a.tolist(), self.edge_b.tolist())]


def _vertices_weights(rows):
    """The four vertices of every row and their weights (1 - s, s, -(1 - t), -t)."""
    s, t = rows.st[:, 0:1], rows.st[:, 1:2]
    verts = np.concatenate([rows.edge_a, rows.edge_b], axis=1).astype(np.int64)
    return verts, np.concatenate([1.0 - s, s, t - 1.0, -t], axis=1)


def no_edge_rows(nv):
    """No rows, for a mesh of nv vertices.

    Parameters
    ----------
    nv : int

    Returns
    -------
    EdgeRows
    """
    z = np.zeros(0)
    return EdgeRows(np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2)),
                    np.zeros((0, 3)), z, z.copy(), nv=nv)


def _closest(xa0, xa1, xb0, xb1, clip=True):
    """Parameters s, t of the closest points of the two lines, their unit normal and its
    sine (|a x b| / (|a| |b|)), per row; s and t clipped to [0, 1] if ``clip``."""
    da, db, r = xa1 - xa0, xb1 - xb0, xa0 - xb0
    cross = np.cross(da, db)
    la, lb, lc = np.linalg.norm(da, axis=1), np.linalg.norm(db, axis=1), np.linalg.norm(cross, axis=1)
    sine = lc / np.maximum(la * lb, np.finfo(float).tiny)
    n = cross / np.where(lc > 0, lc, 1.0)[:, None]
    # the closest points of the lines: (r + s da - t db) is orthogonal to da and db
    aa, bb, ab = (da * da).sum(1), (db * db).sum(1), (da * db).sum(1)
    ra, rb = (r * da).sum(1), (r * db).sum(1)
    det = np.where(aa * bb - ab * ab > 0, aa * bb - ab * ab, 1.0)
    s = (ab * rb - bb * ra) / det
    t = (aa * rb - ab * ra) / det
    if clip:
        s, t = np.clip(s, 0.0, 1.0), np.clip(t, 0.0, 1.0)
    return s, t, n, sine


def _gaps(X, x, edge_a, edge_b, st, normal):
    """dist = n . (x_a(s) - x_b(t)) and g = n . (X_a(s) - X_b(t)) per row."""
    def point(P, e, w):
        return (1.0 - w)[:, None] * P[e[:, 0]] + w[:, None] * P[e[:, 1]]
    s, t = st[:, 0], st[:, 1]
    dist = (normal * (point(x, edge_a, s) - point(x, edge_b, t))).sum(1)
    g = (normal * (point(X, edge_a, s) - point(X, edge_b, t))).sum(1)
    return dist, g


def two_faces(edge_face_ptr, edge_faces):
    """The two boundary faces at every boundary edge, from the faces at each edge.

    Parameters
    ----------
    edge_face_ptr, edge_faces : numpy.ndarray of int
        The faces at edge e are ``edge_faces[edge_face_ptr[e]:edge_face_ptr[e + 1]]``
        (:class:`~ngfracture.contact.edge_crossings3d.EdgeCrossingDetector`).

    Returns
    -------
    numpy.ndarray of int64, shape (nE, 2)
        The two faces at each edge in increasing order; -1 and -1 at an edge with other
        than two faces.

    Raises
    ------
    ValueError
        If ``edge_face_ptr`` is empty, decreases or leaves ``edge_faces``.
    """
    # C++ (cpp_ext/contact_setup3d.cpp), the numpy computation's array
    # (tests/test_contact3d_setup_kernels.py compares)
    return _ext.TwoFaces(np.asarray(edge_face_ptr, dtype=np.int64), np.asarray(edge_faces, dtype=np.int64))


def _locally_inside(x, faces, edge, at, p):
    """Whether points p lie inside the body near its boundary edge ``edge`` (vertices,
    shape (m, 2)) with faces ``at`` (shape (m, 2)): behind both faces' planes where the edge
    is convex (or flat), behind either where it is concave."""
    e0 = x[edge[:, 0]]
    F1, F2 = faces[at[:, 0]], faces[at[:, 1]]
    n1 = np.cross(x[F1[:, 1]] - x[F1[:, 0]], x[F1[:, 2]] - x[F1[:, 0]])
    n2 = np.cross(x[F2[:, 1]] - x[F2[:, 0]], x[F2[:, 2]] - x[F2[:, 0]])
    on_edge = (F2[:, :, None] == edge[:, None, :]).any(axis=2)
    opposite2 = F2[np.arange(len(F2)), np.argmin(on_edge, axis=1)]
    convex = (n1 * (x[opposite2] - e0)).sum(1) <= 0
    behind1, behind2 = (n1 * (p - e0)).sum(1) < 0, (n2 * (p - e0)).sum(1) < 0
    return np.where(convex, behind1 & behind2, behind1 | behind2)


def edge_rows(points, faces, edges, at_edge, pairs, displacement):
    """The rows of crossed pairs of boundary edges, linearised at X + U.

    A pair of the detection is a crossing where the closest points of the two edges' lines
    lie inside both edges (0 < s, t < 1) and each lies inside the other edge's body near
    that edge (behind its faces' planes: both where the edge is convex, either where it is
    concave). An interlock found far from the closest points (an edge through a face near
    the face's far corner, which is a crossing of other edges) is not this pair's crossing,
    and the lines' distance does not measure it.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates X.
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward.
    edges : numpy.ndarray of int, shape (nE, 2)
        The mesh's sorted boundary edges.
    at_edge : numpy.ndarray of int, shape (nE, 2)
        :func:`two_faces`.
    pairs : numpy.ndarray of int, shape (m, 2)
        Interlocked pairs (i, j), i < j, of edge numbers
        (:meth:`~ngfracture.contact.edge_crossings3d.EdgeCrossingDetector.detect`).
    displacement : numpy.ndarray, shape (nv, 3)
        U.

    Returns
    -------
    rows : EdgeRows
        One row per crossing, a = edges[i], b = edges[j], n on the side of the negative
        gap; pairs of nearly parallel edges (sine below :data:`PARALLEL`) and pairs with an
        edge of other than two faces left out.
    kept : numpy.ndarray of int
        The pairs that have a row (indices into ``pairs``).
    """
    X = np.asarray(points, dtype=np.float64)
    x = X + np.asarray(displacement, dtype=np.float64)
    F, E = np.asarray(faces, dtype=np.int64), np.asarray(edges, dtype=np.int64)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    at_a, at_b = np.asarray(at_edge)[pairs[:, 0]], np.asarray(at_edge)[pairs[:, 1]]
    two = (at_a >= 0).all(axis=1) & (at_b >= 0).all(axis=1)   # an edge of two faces each
    at_a, at_b = np.where(two[:, None], at_a, 0), np.where(two[:, None], at_b, 0)
    a, b = E[pairs[:, 0]], E[pairs[:, 1]]
    s, t, n, sine = _closest(x[a[:, 0]], x[a[:, 1]], x[b[:, 0]], x[b[:, 1]], clip=False)
    pa = (1.0 - s)[:, None] * x[a[:, 0]] + s[:, None] * x[a[:, 1]]
    pb = (1.0 - t)[:, None] * x[b[:, 0]] + t[:, None] * x[b[:, 1]]
    crossing = (two & (sine >= PARALLEL) & (s > 0) & (s < 1) & (t > 0) & (t < 1)
                & _locally_inside(x, F, b, at_b, pa) & _locally_inside(x, F, a, at_a, pb))
    st = np.stack([s, t], axis=1)
    dist, g = _gaps(X, x, a, b, st, n)
    side = np.where(dist > 0, -1.0, 1.0)                         # crossed: the gap is negative
    n, dist, g = n * side[:, None], dist * side, g * side         # negation is exact
    kept = np.flatnonzero(crossing & (dist < 0))
    return EdgeRows(a[kept], b[kept], st[kept], n[kept], dist[kept], g[kept], nv=len(X)), kept


def relinearise_edge_rows(rows, points, displacement):
    """The rows with s, t and n recomputed at X + U (n on its side; see the module docstring).

    Parameters
    ----------
    rows : EdgeRows
    points, displacement : numpy.ndarray, shape (nv, 3)
        Reference coordinates X and displacements U.

    Returns
    -------
    EdgeRows
        The same rows in the same order; ``rows`` itself when empty.
    """
    if len(rows) == 0:
        return rows
    X = np.asarray(points, dtype=np.float64)
    x = X + np.asarray(displacement, dtype=np.float64)
    a, b = rows.edge_a, rows.edge_b
    s, t, n, sine = _closest(x[a[:, 0]], x[a[:, 1]], x[b[:, 0]], x[b[:, 1]])
    n = np.where(((n * rows.normal).sum(1) < 0)[:, None], -n, n)
    well = (sine >= PARALLEL) & (a[:, 0] != a[:, 1])          # node-to-edge rows keep theirs
    st = np.where(well[:, None], np.stack([s, t], axis=1), rows.st)
    n = np.where(well[:, None], n, rows.normal)
    dist, g = _gaps(X, x, a, b, st, n)
    return EdgeRows(a, b, st, n, dist, g, nv=rows.nv)
