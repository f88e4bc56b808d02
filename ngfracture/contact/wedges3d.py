"""Edges at a junction of fragments pushed into the wedge of a diagonal neighbour.

Where three or more cut surfaces meet along a line, every fragment around the line has a
copy of its edges there, and two fragments opposite each other across the line (diagonal
neighbours) share the edge but no face along it: each is held by its rows to the fragments
between them (:mod:`ngfracture.contact.junctions3d`), which stay between them only while
those stay together. Once the middle pieces open, fragment A's copy of the junction edge can
slide into fragment B's wedge at its copy: the edge line of A behind both planes of B's two
faces at B's edge. Near the edge's ends the corners of B are bounded by more faces, so
neither end of A's edge need lie inside B, and the node-to-face detection (a vertex inside
a tetrahedron) finds nothing; the edge-to-edge rows leave pairs at copies of a point alone
(their normals lie within about 1e-3 rad of the rows at the copy).

:func:`diagonal_edges` lists, once per mesh, every ordered pair (edge a on A, edge b on B)
of boundary edges on the same two reference points on different fragments with no face of
A at a coincident with a face of B at b. :func:`wedge_rows` tests them at a configuration:
where B's wedge at b is convex and the midpoint of a lies behind both of its faces' planes
deeper than ``tol`` (measured from b's midpoint), the ends of a behind the plane of the
less deep face, where A's wedge lies in front of that plane, get the row of that face,
projected at their copy on b (barycentric 1 there), with the face's unit normal of the
reference configuration: the rows at copies' form
(:func:`~ngfracture.contact.copies3d.found_rows_at_copies`), so that the active set
re-linearises them as it does those. Out of B's wedge, the edge line keeps out of it
through one face or the other: a union, of which the row keeps the one nearer to hold.
Elsewhere, both wedges convex, the wedges overlap where every plane that can separate
them (a face of B with A's wedge in front of it, a face of A with B's in front) reads a
gap below ``-tol`` at one point of the edge (the gaps are linear along it), and the rows
are those of the separating plane that the deepest end behind it is least deep behind:
a's ends on B's face or b's ends on A's face (docs/contact.md, "Rows at copies found by
their planes").

Where B's wedge at b is reflex (wider than pi) its complement is convex: the intersection of
the half-spaces in front of its two faces, and every other copy a of the edge must keep out
of B through both. Where a and B share a face at the edge, the rows at copies hold a
against it (partner faces); the other face of B there is coincident with a face of a third
copy, and nothing holds a in front of it. :func:`edge_copies` lists, once per mesh, every
ordered pair of copies (a, b) of a boundary edge with a face of b that is no partner face
of a; :func:`reflex_wedge_rows` gives, where B's wedge at b is reflex and an end of a lies
behind the plane of such a face deeper than ``tol``, both ends of a a row on every such
face: the exact first-order condition along the edge, as the gap n . (x_a(s) - x_b(s)) is
linear along it.
"""
from dataclasses import dataclass

import numpy as np

from .. import _ngfracture as _ext
from .copies3d import rows_at_copy
from .intsets import isin_ints
from .rows import take_rows
from .rows3d import no_face_rows

__all__ = ["DiagonalEdges", "EdgeCopies", "diagonal_edges", "edge_copies", "wedge_rows", "reflex_wedge_rows"]


@dataclass(frozen=True)
class DiagonalEdges:
    """Ordered pairs of copies of a junction edge on diagonal fragments.

    Parameters
    ----------
    a : numpy.ndarray of int64, shape (m, 2)
        The ends of edge a (on fragment A).
    b : numpy.ndarray of int64, shape (m, 2)
        Their copies on edge b (on fragment B): ``b[:, k]`` at the reference point of ``a[:, k]``.
    b_faces : numpy.ndarray of int64, shape (m, 2)
        The two boundary faces of B at edge b.
    edge_a, edge_b : numpy.ndarray of int64, shape (m,)
        The numbers of edges a and b among the boundary edges.
    a_faces : numpy.ndarray of int64, shape (m, 2)
        The two boundary faces of A at edge a.
    """
    a: np.ndarray
    b: np.ndarray
    b_faces: np.ndarray
    edge_a: np.ndarray
    edge_b: np.ndarray
    a_faces: np.ndarray

    def __len__(self):
        return len(self.a)


def diagonal_edges(edges, faces_at_edge, vertex_fragment, index):
    """The ordered pairs of copies of one boundary edge on two fragments that share no face there.

    Parameters
    ----------
    edges : numpy.ndarray of int, shape (nE, 2)
        Boundary edges.
    faces_at_edge : numpy.ndarray of int, shape (nE, 2)
        The two boundary faces at every edge (-1 where an edge has other than two,
        :func:`~ngfracture.contact.edge_rows3d.two_faces`).
    vertex_fragment : numpy.ndarray of int, shape (nv,)
        The fragment of every vertex.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the mesh's reference points and boundary faces.

    Returns
    -------
    DiagonalEdges
        Sorted by edge a, then edge b.

    Raises
    ------
    ValueError
        Naming the array: a wrong shape, a vertex or face number out of range, an edge
        with a vertex on no boundary face (no reference point in ``index``).
    """
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    at = np.asarray(faces_at_edge, dtype=np.int64).reshape(-1, 2)
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    pid = index.point
    none = DiagonalEdges(*(np.zeros((0, 2), np.int64) for _ in range(3)), *(np.zeros(0, np.int64) for _ in range(2)),
                         np.zeros((0, 2), np.int64))
    if not len(E):
        return none
    # C++ (cpp_ext/contact_setup3d.cpp): the edges on the same two points pairwise, on two
    # fragments, each with two faces, no face key shared; b's ends flipped to a's points;
    # sorted by (a, b). The same arrays as the numpy computation that
    # tests/test_contact3d_setup_kernels.py keeps and compares
    a, b, ends_b = _ext.DiagonalEdgePairs(E, at, vf, pid, index.face_key)
    return DiagonalEdges(take_rows(E, a), ends_b, take_rows(at, b), a, b, take_rows(at, a))


def wedge_rows(pairs, displacement, tol, index, vertex_fragment):
    """Rows for the ends of junction edges whose wedge overlaps a diagonal neighbour's deeper than ``tol``.

    Parameters
    ----------
    pairs : DiagonalEdges
        :func:`diagonal_edges` of the mesh.
    displacement : numpy.ndarray, shape (nv, 3)
        Displacements U: the configuration X + U tested.
    tol : float
        Depth (a length) of the overlap that makes rows: of the midpoint of a behind both of
        B's planes, or of a point of the edge behind every separating plane.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the mesh's reference points X and boundary faces.
    vertex_fragment : numpy.ndarray of int, shape (nv,)
        The fragment of every vertex.

    Returns
    -------
    NodeToFaceRows
        For every such pair the rows of the slaves behind the chosen face's plane, on that
        face, projected at the slave's copy (``g`` 0, ``dist`` the slave's gap at X + U),
        in the order of the pairs. The face: where the midpoint of a is that deep, the face
        of B it is less deep behind if that face separates (a's ends the slaves); else
        the separating plane whose deepest end behind it is least deep behind, so that the
        rows move the edges apart by the least: a face of B (a's ends the slaves) or of A
        (b's ends). Where both orders of two edges are inside, only the one
        with a on the higher fragment gives rows (the fixed rows' direction): for opposite
        wedges the two are one condition, and rows of both, on different faces, would
        hold the copies out of both half-spaces instead of one.
    """
    X, F = index.points, index.faces
    nv = len(X)
    if not len(pairs):
        return no_face_rows(nv)
    x = X + np.asarray(displacement, dtype=np.float64)
    # C++ (cpp_ext/copies3d.cpp), bit for bit the numpy computation that
    # tests/test_copies3d_kernels.py keeps: per pair both wedges' unit normals at x (a face
    # squeezed flat has no plane: no rows), each wedge convex or flat (the corner of its
    # second face off the edge behind or on the first's plane, as edge_rows3d judges an
    # edge), the gaps of a's ends to B's planes and of b's ends to A's (from their copies,
    # linear along the edge), which planes separate, and the pairs that overlap
    inside, nearer, gap = _ext.WedgeInside(x, F, pairs.a, pairs.b, pairs.b_faces, pairs.a_faces, float(tol))
    keep = ~_reverse_also_inside(pairs, inside, vertex_fragment)
    inside, nearer, gap = inside[keep], nearer[keep], gap[keep]
    pair, end = np.nonzero(gap < 0)                                   # the ends behind that face's plane
    if not len(pair):
        return no_face_rows(nv)
    p, k = inside[pair], nearer[pair]
    on_b = k < 2                                  # a face of B, a's ends the slaves; else one of A, b's ends
    slave = np.where(on_b, pairs.a[p, end], pairs.b[p, end])
    copy = np.where(on_b, pairs.b[p, end], pairs.a[p, end])
    face = np.where(on_b, pairs.b_faces[p, k % 2], pairs.a_faces[p, k % 2])
    corner = np.argmax(F[face] == copy[:, None], axis=1)
    return rows_at_copy(slave, face, corner, gap[pair, end], index)


def _reverse_also_inside(pairs, inside, vertex_fragment):
    """Per pair inside (``inside``: their numbers among ``pairs``): the reversed pair (b, a)
    is inside too and a lies on the lower fragment."""
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    n = np.int64(max(int(pairs.edge_a.max(initial=0)), int(pairs.edge_b.max(initial=0))) + 1)
    code = pairs.edge_a[inside] * n + pairs.edge_b[inside]
    reverse = pairs.edge_b[inside] * n + pairs.edge_a[inside]
    return isin_ints(reverse, code) & (vf[pairs.a[inside, 0]] < vf[pairs.b[inside, 0]])


@dataclass(frozen=True)
class EdgeCopies:
    """Ordered pairs of copies of a boundary edge where b has a face that is no partner face of a.

    Parameters
    ----------
    a : numpy.ndarray of int64, shape (m, 2)
        The ends of edge a.
    b : numpy.ndarray of int64, shape (m, 2)
        Their copies on edge b: ``b[:, k]`` at the reference point of ``a[:, k]``.
    b_faces : numpy.ndarray of int64, shape (m, 2)
        The two boundary faces of b's fragment at edge b.
    partner : numpy.ndarray of bool, shape (m, 2)
        Whether ``b_faces[:, k]`` is coincident with a face at edge a (at most one is).
    """
    a: np.ndarray
    b: np.ndarray
    b_faces: np.ndarray
    partner: np.ndarray

    def __len__(self):
        return len(self.a)


def edge_copies(edges, faces_at_edge, index):
    """The ordered pairs of copies of one boundary edge with a face of b that is no partner face of a.

    Copies on one fragment count (the lips of a crack inside it). Pairs where both faces
    of b are coincident with faces at a are left out: the partner-face rows there are the
    whole condition.

    Parameters
    ----------
    edges : numpy.ndarray of int, shape (nE, 2)
        Boundary edges.
    faces_at_edge : numpy.ndarray of int, shape (nE, 2)
        The two boundary faces at every edge (-1 where an edge has other than two).
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the mesh's reference points and boundary faces.

    Returns
    -------
    EdgeCopies
        Sorted by edge a, then edge b.

    Raises
    ------
    ValueError
        Naming the array: a wrong shape, a face number out of range, an edge with a vertex
        on no boundary face (no reference point in ``index``).
    """
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    at = np.asarray(faces_at_edge, dtype=np.int64).reshape(-1, 2)
    if not len(E):
        return EdgeCopies(*(np.zeros((0, 2), np.int64) for _ in range(3)), np.zeros((0, 2), dtype=bool))
    # C++ (cpp_ext/contact_setup3d.cpp): the edges on the same two points pairwise (runs of
    # diagonal_edges' sort), each with two faces, not both of b's faces' keys among a's
    a, b, ends_b, partner = _ext.EdgeCopyPairs(E, at, index.point, index.face_key)
    return EdgeCopies(take_rows(E, a), ends_b, take_rows(at, b), partner)


def reflex_wedge_rows(pairs, displacement, tol, index):
    """Rows for the ends of edge copies behind a face of another copy's reflex wedge deeper than ``tol``.

    Parameters
    ----------
    pairs : EdgeCopies
        :func:`edge_copies` of the mesh.
    displacement : numpy.ndarray, shape (nv, 3)
        Displacements U: the configuration X + U tested.
    tol : float
        Depth (a length) of an end of a behind the plane of a face of b that is no partner
        face of a, where B's wedge at b is reflex, that makes rows.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the mesh's reference points X and boundary faces.

    Returns
    -------
    NodeToFaceRows
        For every such pair, the rows of both ends of a on every face of b that is no
        partner face of a (the complement of a reflex wedge is the intersection of the
        half-spaces in front of its faces; the active set imposes those that bind), by
        pair, face, end: projected at the end's copy on b (``g`` 0, ``dist`` the end's gap
        at X + U), the face's unit normal of the reference configuration.
    """
    X, F = index.points, index.faces
    nv = len(X)
    if not len(pairs):
        return no_face_rows(nv)
    x = X + np.asarray(displacement, dtype=np.float64)
    # C++ (cpp_ext/copies3d.cpp): per pair B's two unit normals at x (a face squeezed flat
    # has no plane: no rows), B's wedge reflex (the corner of its second face off the edge
    # strictly in front of the first's plane), the gaps of a's ends to both planes measured
    # from their copies on b, and the pairs with one below -tol on a face no partner of a
    hit, gap = _ext.ReflexWedgeGaps(x, F, pairs.a, pairs.b, pairs.b_faces, pairs.partner, float(tol))
    if not len(hit):
        return no_face_rows(nv)
    new = ~pairs.partner[hit]                                       # (k, 2): b's faces that are no partner
    pair, side = np.nonzero(new)
    pair, side, end = np.repeat(pair, 2), np.repeat(side, 2), np.tile([0, 1], len(pair))
    p = hit[pair]
    face = pairs.b_faces[p, side]
    corner = np.argmax(F[face] == pairs.b[p, end][:, None], axis=1)
    return rows_at_copy(pairs.a[p, end], face, corner, gap[pair, 2 * side + end], index)
