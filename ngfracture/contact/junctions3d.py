"""Rows between the copies of a point on several fragments: one row per pair of fragments.

Node splitting leaves coincident lips: every vertex on a lip has one copy per fragment at
its point, bitwise equal, and the faces of two fragments' lips coincide (the same three
points, opposite orientation): *matched faces*. Where several fragments meet (a line where
two cut planes cross: 4 copies; a point where three cross: 8 copies) a copy touches every
neighbouring fragment across its own lip, and the non-penetration of the copies needs a
row towards each neighbour.

:func:`fragment_pair_rows` gives, for every copy s on fragment F and every copy t of its
point on another fragment G with a face matched to one of F's, one node-to-face row: slave
s, master t, on a matched face of G at t (projection at t, barycentric 1 there). A
fragment has one copy of a point unless a crack of its own reaches the point (the core's
vertex at the mouth of a crack in the glass around it has a copy on each lip): then s has
a row on each. At points of three or more copies, where the surface at t bends (matched
faces whose normals differ from the chosen one's by more than
:data:`~ngfracture.contact.kinks3d.KINK`), every such face gets its row as well. Of
the matched faces of G at t it takes the one whose unit normal is nearest to their
area-weighted mean normal (the lip's normal between F and G at that point; ties: the
smaller face), so the row's direction is that of the lip between the two fragments, not of
s's vertex normal (which at a junction is diagonal, and would pick one neighbour at
random). Only one direction per pair of fragments exists: the slave is on the
higher-numbered fragment. The lips are matching meshes, so one pass transmits a uniform
pressure exactly (as :func:`~ngfracture.contact.rows3d.lip_rows`); the reversed row on a
face at s is the same row only while the two faces stay parallel, and as the lips deform
the two directions become nearly, but not exactly, dependent (normals 1e-4 apart pass the
redundancy removal's rank tolerance 1e-5), then they hold the copies against sliding
and the imposed set has near-singular multipliers of both signs.

Copies on two fragments without a matched face (the diagonal neighbours of a junction:
they share only an edge or the point) get no row: the rows to the face neighbours bound
their relative motion where the neighbours stay together, and a diagonal overlap that
does occur is found by the detection (a vertex penetrating a fragment towards which it has
no row is not left to any twin row, see
:func:`~ngfracture.contact.active_set3d.ActiveSet3d`). Copies without any matched face (the
corners of a common face of two bodies meshed apart with non-matching cells) keep the rows
of :func:`~ngfracture.contact.rows3d.fragment_twin_rows` (both passes, on the face at the
twin opposing the slave's vertex normal), which the patch test needs.
"""
import numpy as np

from .. import _ngfracture as _ext
from .kinks3d import KINK, CopyIndex
from .rows import take_rows
from .rows3d import NodeToFaceRows, face_gap_rows, fragment_twin_rows, no_face_rows

__all__ = ["fragment_pair_rows", "covered_pairs"]


def _on_several_fragments(pid, vf):
    """Per vertex: its reference point has copies on more than one fragment."""
    on = np.flatnonzero(pid >= 0)
    out = np.zeros(len(pid), dtype=bool)
    if not len(on):
        return out
    point, fragment = pid[on], vf[on]
    some = np.zeros(pid.max() + 1, dtype=np.int64)
    some[point] = fragment                    # the fragment of one copy of each point (any)
    several = np.zeros(len(some), dtype=bool)
    several[point[fragment != some[point]]] = True          # another copy on another fragment
    out[on] = several[point]
    return out


def _checked(points, faces, vertex_fragment):
    """The arrays as float coordinates, int faces and int fragments, or ValueError naming the bad one."""
    X = np.asarray(points, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3 or not np.isfinite(X).all():
        raise ValueError(f"points must be finite numbers of shape (nv, 3), got shape {X.shape}")
    nv = len(X)
    F = np.asarray(faces)
    if F.ndim != 2 or F.shape[1] != 3 or (F.size and not np.issubdtype(F.dtype, np.integer)):
        raise ValueError(f"faces must be integers of shape (nf, 3), got {F.dtype} {F.shape}")
    F = F.astype(np.int64)
    if F.size and (F.min() < 0 or F.max() >= nv):
        raise ValueError(f"faces hold vertex numbers outside [0, {nv})")
    vf = np.asarray(vertex_fragment)
    if vf.shape != (nv,) or (vf.size and not np.issubdtype(vf.dtype, np.integer)):
        raise ValueError(f"vertex_fragment must be integers of shape ({nv},), got {vf.dtype} {vf.shape}")
    return X, F, vf.astype(np.int64)


def fragment_pair_rows(points, faces, vertex_fragment, index=None):
    """Twin rows of fragmented bodies: one row per (copy, neighbouring copy), one direction per pair.

    See the module docstring for the rule and why.

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : array_like of int, shape (nf, 3)
        Boundary faces, outward (the crack lips among them).
    vertex_fragment : array_like of int, shape (nv,)
        The fragment of every vertex.
    index : ngfracture.contact.kinks3d.CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    NodeToFaceRows
        First the rows across matched faces, sorted by the slave's fragment, the slave and
        the master's fragment; then the rows of
        :func:`~ngfracture.contact.rows3d.fragment_twin_rows` whose slave lies on no matched
        face, in their order. ``dist`` is the gap at the reference configuration.

    Raises
    ------
    ValueError
        On wrong shapes, non-finite coordinates or vertex numbers out of range.
    """
    X, F, vf = _checked(points, faces, vertex_fragment)
    nv = len(X)
    index = CopyIndex(X, F) if index is None else index
    pid = index.point
    # C++ (cpp_ext/contact_setup3d.cpp; tests/test_fragment_pair_kernel.py keeps the numpy
    # computation and compares): for every pair of matched faces a, b on fragments F > G
    # and every corner t of b, the copy s of t's point on a; per (s, t) the face at t whose
    # unit normal is nearest to the area-weighted mean normal of the matched faces at t
    # (ties: the smaller face), and where three or more copies meet every face off its
    # plane by more than KINK; sorted by (s's fragment, s, G, face), stably
    slave, face, k, matched = _ext.FragmentPairEntries(F, vf, pid, index.key_order, index.key_sorted, index.area2,
                                                       index.unit, index.copies, KINK)
    fallback = no_face_rows(nv)
    if np.any(_on_several_fragments(pid, vf) & ~matched):      # else every fallback row is dropped
        fallback = fragment_twin_rows(X, F, vf, index=index)
        fallback = fallback.subset(np.flatnonzero(~matched[fallback.slave]))
    if not len(slave):
        return fallback
    bary = np.zeros((len(slave), 3))
    bary[np.arange(len(slave)), k] = 1.0
    master, normal = take_rows(F, face), take_rows(index.unit, face)
    _, g = face_gap_rows(X, slave, master, bary, normal)
    rows = NodeToFaceRows(slave=slave, master=master, face=face, bary=bary, normal=normal, dist=g.copy(), g=g, nv=nv)
    return NodeToFaceRows.stack([rows, fallback]) if len(fallback) else rows


def covered_pairs(points, rows, vertex_fragment):
    """The (vertex, fragment) pairs whose contact a set of rows covers, both ways.

    A row of slave s on a face of fragment G covers (s, G); where the master face has the
    copy t of s (bitwise-equal reference point, on fragment F of s), it covers (t, F) as
    well: the row is the non-penetration of the pair of copies, whichever is the slave.

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates.
    rows : NodeToFaceRows
        The rows.
    vertex_fragment : array_like of int, shape (nv,)
        The fragment of every vertex.

    Returns
    -------
    numpy.ndarray of int64
        The pairs as codes fragment * nv + vertex (nv = len(points)), sorted, unique.

    Raises
    ------
    ValueError
        If the rows do not fit the arrays (vertex numbers out of range, wrong shapes).
    """
    X = np.asarray(points, dtype=np.float64)
    vf = np.asarray(vertex_fragment)
    if X.ndim != 2 or X.shape[1] != 3 or vf.shape != (len(X),) or rows.nv != len(X):
        raise ValueError(f"covered_pairs: points {X.shape}, vertex_fragment {vf.shape} and rows of "
                         f"{rows.nv} vertices do not fit")
    # C++ (cpp_ext/contact_setup3d.cpp): the codes of every row's (s, G), then of (t, F)
    # where the master has a copy t of s (the first such corner) on another fragment,
    # sorted and unique (tests/test_contact3d_setup_pairs.py keeps the numpy computation)
    return _ext.CoveredPairs(X, vf.astype(np.int64), np.asarray(rows.slave, dtype=np.int64),
                             np.asarray(rows.master, dtype=np.int64).reshape(-1, 3))

