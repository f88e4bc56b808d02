"""Node-to-edge rows for a vertex whose detected depth no candidate row reads.

The detection (:func:`~ngfracture.contact.collision3d.detect_penetrations_3d`) measures a
penetrating vertex v against its master face f as the distance to the closed triangle:
gap = -|x_v - p|, p the nearest point of f. Where the foot of v on f's plane lies inside
the triangle, p is that foot, and the node-to-face row n_f . (x_v - x_p) reads the gap.
Where the foot lies outside, p is clipped to an edge or a corner of f, and a row with f's
normal reads only the distance to f's plane, which is smaller; a row at a copy
(:mod:`~ngfracture.contact.copies3d`, projected at the copy, the plane's distance as well)
reads the same. The vertex can then lie on the plane of its row (gap 0) and still inside
the master piece: the coarse free sphere had a vertex of one piece slid along the plane of
a crack lip inside another piece past the crack's front edge, into the tetrahedron ahead
of the front, 7.2e-7 from the lip triangle (the distance to the front edge) and on the
lip's plane to 1e-17; its rows read 0, and three attempts of a load step failed on that
depth (docs/solid.md, "The sphere scenes").

The row here is the linearisation of the detection's own measure. The distance
|x_v - p| to the triangle has the gradient (x_v - p) / |x_v - p| in x_v wherever v is
off the triangle; with p moving with the edge (or corner) it lies on, the signed gap
-|x_v - p| of a penetrating vertex is, to first order,

    g(u) = n . (x_v - x_p),    n = (p - x_v) / |p - x_v|,    x_p = (1 - t) x_b0 + t x_b1,

with t the parameter of p on the edge (b0, b1) (b0 = b1 for a corner). It reads the
detected gap at the detection's configuration, and g >= 0 moves v along n, towards the
nearest point of the master's boundary that its triangle has and past it: out of the
master piece where that edge bounds it (a crack's front edge, where the piece's
tetrahedra fill 360 degrees around the edge and the only way out is back across the
edge; a reflex edge, where the piece is the union of the half-spaces behind its two
faces and neither face's row holds v). The rows of the face's plane keep their part
(v's distance from the plane); this row adds the motion across the edge that they do
not see.

Which pairs get one: a detected pair (v, F) deeper than ``tol`` (the penetration
tolerance) whose projection is clipped (a barycentric coordinate 0), where no candidate
node-to-face row of the pair (slave v with its master on F, or a slave on F projected at
v, the pair's row in the other direction) reads a violation beyond ``tol`` and all read a
gap above the detected one by more than ``tol`` (a row reading the depth to ``tol`` sees
it). The active set
moves a vertex only through rows it violates by more than ``tol``; where all rows of the
pair hold and the detection still measures v deeper than ``tol``, no round moves it, and
the solve ends there with v inside. Where a row reads part of the depth (on the default
sphere's first steps, copies behind a face at their copy with the foot just outside the
triangle, their rows reading 57 to 99.9 % of the depth), that row moves v first, and the
pair gets a node-to-edge row only if v is left deep once its rows hold; a trigger on any
shortfall changed that run. A solve that never meets such a stall has the candidates it
had without this module, bit for bit. Left out: a nearest point at a corner that is a
copy of v (same reference point). There the master's boundary around the point is the
wedge of that copy's faces, which the rows at copies hold; a row towards the copy would
hold v at the point the copies share and block their slip along the faces.

Form. The row is an edge-to-edge row (:class:`~ngfracture.contact.edge_rows3d.EdgeRows`)
of the degenerate edge a = (v, v) and the edge b = (b0, b1) (sorted; (w, w) for a corner
w), parameters (0, t): the same C, g and dist. Its key is ("n", v, b0, b1)
(:class:`~ngfracture.contact.setup3d.FaceKeys`). The re-linearisation
(:func:`~ngfracture.contact.edge_rows3d.relinearise_edge_rows`) keeps n and t: the
direction is that of the detection, defined where v is off the edge, not once the row
holds v on it. A pair found again (still deep, its rows holding) takes the new
detection's row (:meth:`~ngfracture.contact.active_set3d.ActiveSet3d.update`).
"""
import numpy as np

from .edge_rows3d import EdgeRows, no_edge_rows
from .intsets import isin_ints
from .rows import take_rows
from .rows3d import relinearise_node_to_face

__all__ = ["unseen_pairs", "node_edge_rows", "beyond_face"]


def _row_values(rows, x):
    """n . (x_s - sum_l b_l x_l) per node-to-face row at the positions x."""
    p = np.einsum("ij,ijk->ik", rows.bary, x[rows.master])
    return np.einsum("ij,ij->i", rows.normal, x[rows.slave] - p)


def _lower(seen, rows, codes, order, x, vertex_fragment):
    """Lower ``seen`` (per pair code of ``codes``, sorted by ``order``) to the gaps at x of the
    rows of those pairs: slave v on a face of fragment F, or a slave on F projected at v."""
    if not len(rows):
        return
    nv = len(x)
    projected = rows.bary.max(axis=1) == 1.0
    at = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    pair = np.stack([rows.slave * nv + vertex_fragment[rows.master[:, 0]],
                     np.where(projected, at * nv + vertex_fragment[rows.slave], -1)], axis=1)
    mine = np.flatnonzero(isin_ints(pair, codes).any(axis=1))
    if not len(mine):
        return
    value = _row_values(rows.subset(mine), x)
    for k in range(2):
        slot = np.minimum(np.searchsorted(codes[order], pair[mine, k]), len(codes) - 1)
        hit = codes[order][slot] == pair[mine, k]
        np.minimum.at(seen, order[slot[hit]], value[hit])


def unseen_pairs(pen, faces, rows, points, displacement, vertex_fragment, tol):
    """The detected pairs whose depth, on a clipped projection, no candidate row reads.

    Parameters
    ----------
    pen : ngfracture.contact.collision3d.Penetrations3d
        The detection at X + U.
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces (``pen.face`` indexes them).
    rows : sequence of ngfracture.contact.rows3d.NodeToFaceRows
        The node-to-face candidates of the round (the fixed rows, the found ones).
    points, displacement : numpy.ndarray, shape (nv, 3)
        Reference coordinates X (copies bitwise equal) and displacements U.
    vertex_fragment : numpy.ndarray of int64, shape (nv,)
        The fragment of every vertex.
    tol : float
        The penetration tolerance (a length): pairs deeper than it whose rows read no
        violation beyond it and a gap above the detected one by more than it.

    Returns
    -------
    numpy.ndarray of int64
        Indices into ``pen`` (increasing): pairs deeper than ``tol`` with a barycentric
        coordinate 0, whose nearest point is no corner at a copy of the vertex, and whose
        rows at X + U all read more than ``-tol`` and more than the detected gap plus
        ``tol`` (or that have none).
    """
    X = np.asarray(points)
    gap, bary = np.asarray(pen.gap), np.asarray(pen.bary).reshape(-1, 3)
    pick = np.flatnonzero((gap < -tol) & (bary.min(axis=1, initial=1.0) == 0.0))
    if not len(pick):
        return pick.astype(np.int64)
    v = np.asarray(pen.vertex, dtype=np.int64)[pick]
    corner = take_rows(np.asarray(faces, dtype=np.int64), np.asarray(pen.face, dtype=np.int64)[pick])
    corner = corner[np.arange(len(pick)), np.argmax(bary[pick], axis=1)]
    at_copy = ((bary[pick] > 0.0).sum(axis=1) == 1) & np.all(X[corner] == X[v], axis=1)
    pick, v = pick[~at_copy], v[~at_copy]
    nv = len(X)
    codes = v * nv + np.asarray(pen.fragment, dtype=np.int64)[pick]       # (vertex, fragment), distinct
    seen = np.full(len(pick), np.inf)
    order = np.argsort(codes)
    for part in rows if len(pick) else ():
        _lower(seen, part, codes, order, X + np.asarray(displacement), vertex_fragment)
    # the rows hold (none violated beyond tol) and fall short of the depth by more than tol
    return pick[(seen > -tol) & (seen > gap[pick] + tol)]


def node_edge_rows(points, faces, pen, pick, displacement):
    """The node-to-edge rows of the picked detected pairs (see the module docstring).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates X (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces (``pen.face`` indexes them).
    pen : ngfracture.contact.collision3d.Penetrations3d
        The detection at X + U.
    pick : numpy.ndarray of int
        Pairs of ``pen`` (:func:`unseen_pairs`).
    displacement : numpy.ndarray, shape (nv, 3)
        U.

    Returns
    -------
    EdgeRows
        One row per picked pair, in ``pick``'s order: edge a = (v, v), edge b the sorted
        edge (or the corner twice) the nearest point lies on, st = (0, t), n from the
        vertex to that point, dist and g of :class:`EdgeRows`.
    """
    X = np.asarray(points, dtype=np.float64)
    nv = len(X)
    pick = np.asarray(pick, dtype=np.int64)
    if not len(pick):
        return no_edge_rows(nv)
    x = X + np.asarray(displacement, dtype=np.float64)
    v = np.asarray(pen.vertex, dtype=np.int64)[pick]
    corners = take_rows(np.asarray(faces, dtype=np.int64), np.asarray(pen.face, dtype=np.int64)[pick])
    bary = take_rows(np.asarray(pen.bary), pick)
    on = bary > 0.0
    # the two corners with weight (a corner twice at a vertex), in increasing vertex order
    big = np.argsort(-bary, axis=1, kind="stable")[:, :2]
    b = np.take_along_axis(corners, big, axis=1)
    w = np.take_along_axis(bary, big, axis=1)
    b = np.where(on.sum(axis=1)[:, None] == 1, b[:, :1], b)
    swap = b[:, 0] > b[:, 1]
    b = np.where(swap[:, None], b[:, ::-1], b)
    t = np.where(on.sum(axis=1) == 1, 0.0, np.where(swap, w[:, 0], w[:, 1]))
    p = take_rows(np.asarray(pen.projection), pick)
    d = p - x[v]
    n = d / np.linalg.norm(d, axis=1)[:, None]
    a = np.stack([v, v], axis=1)
    st = np.stack([np.zeros(len(v)), t], axis=1)
    xp = (1.0 - t)[:, None] * x[b[:, 0]] + t[:, None] * x[b[:, 1]]
    Xp = (1.0 - t)[:, None] * X[b[:, 0]] + t[:, None] * X[b[:, 1]]
    dist = (n * (x[v] - xp)).sum(1)
    g = (n * (X[v] - Xp)).sum(1)
    return EdgeRows(a, b, st, n, dist, g, nv=nv)


def beyond_face(points, rows, displacement, point):
    """How far each node-to-face row's slave lies beyond the edges of its master face at X + U.

    A row reads the slave's distance to its face's plane. Where the slave's foot on that
    plane lies outside the triangle the plane is not the master's surface: beyond a convex
    edge the master's surface turns away from it, and a slave held on the plane there is
    held against nothing of the master. The length returned is |t|, t the part in the
    face's plane of x_s - q, q the foot clipped to the triangle as the rows are
    re-linearised (:func:`~ngfracture.contact.rows3d.relinearise_node_to_face`: negative
    barycentrics set to 0 and the rest rescaled): 0 up to rounding where the foot is inside.
    Rows at a copy of their slave (a corner of the face with the slave's reference point)
    get 0: they are held at the copy by design.

    Parameters
    ----------
    points, displacement : numpy.ndarray, shape (nv, 3)
        Reference coordinates X and displacements U.
    rows : ngfracture.contact.rows3d.NodeToFaceRows
        The rows.
    point : numpy.ndarray of int, shape (nv,)
        The point id of each vertex (:class:`~ngfracture.contact.kinks3d.CopyIndex`,
        ``point``; equal ids for copies, -1 for a vertex without copies).

    Returns
    -------
    numpy.ndarray, shape (len(rows),)
    """
    if len(rows) == 0:
        return np.zeros(0)
    # the clipped foot and the face's normal at X + U, as the rows are re-linearised
    fresh = relinearise_node_to_face(rows, points, displacement)
    x = np.asarray(points) + np.asarray(displacement)
    t = x[rows.slave] - np.einsum("ij,ijk->ik", fresh.bary, x[rows.master])
    t -= np.einsum("ij,ij->i", t, fresh.normal)[:, None] * fresh.normal
    out = np.linalg.norm(t, axis=1)
    pid = np.asarray(point)
    at_copy = ((pid[rows.master] == pid[rows.slave][:, None]) & (pid[rows.slave][:, None] >= 0)).any(axis=1)
    out[at_copy] = 0.0
    return out
