"""Coincident faces at copies of a point: the master faces of the partner-face rows of 3D contact.

Where the splitting made copies of a vertex, the faces around one copy t and those around
another copy s come in coincident pairs: faces with their three vertices at the same three
reference points, the two sides of an interface or of a crack (a *partner* face of s at t).
:mod:`ngfracture.contact.rows3d` holds a slave s against one face at t, the one most
opposed to s's normal; where the surface at t is not one plane that is not enough, and
:func:`partner_faces` gives every partner face at t, from which rows3d makes one row each
(docs/contact.md, "Crack lips in 3D", partner-face rows):

- at points with three or more copies (a crack reaching an interface: the core's vertex and
  the two glass lip copies), for every pair of copies s > t;
- between the lips of one fragment, for every pair s > t, but only faces whose normal
  differs from the normal of s's one row by more than :data:`KINK` (a kink of the crack
  surface): nearly parallel faces would give nearly dependent rows, which together block
  the slip of the copies (rows3d.lip_rows).

A vertex on one side of matched faces stays out of the other side, to first order in the
relative displacement d = x_s - x_t, if and only if n_f . d >= 0 for every partner face f
at t (n_f its outward normal): of the two sides at the point one is convex and must keep
the other's vertex behind all of its planes, and with the normals of partner faces
opposite the conditions of both vertices are these. The rows are inequalities: the active
set imposes the ones that bind.
"""
import numpy as np

from .. import _ngfracture as _ext
from .intsets import isin_ints, sorted_members, unique_ints

__all__ = ["KINK", "CopyIndex", "point_groups", "point_ids", "face_point_keys", "partner_faces", "copy_pairs",
           "expand_ranges",
           "sorted_members", "unique_ints", "isin_ints"]

#: 1 - cos of the smallest angle between a lip's face and the face of its one row for which
#: the face gets a row of its own (about 2.6 degrees)
KINK = 1e-3


def point_groups(points, faces):
    """The boundary vertices sorted by reference point, and the number of each one's point.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces.

    Returns
    -------
    vertex : numpy.ndarray of int
        The vertices of the faces, sorted by their point (x, then y, then z; stable).
    group : numpy.ndarray of int
        The number of each one's point, 0, 1, ... in that order.
    """
    on = np.flatnonzero(np.bincount(np.asarray(faces).ravel(), minlength=len(points)))   # increasing
    P = points[on]
    order = np.lexsort((P[:, 2], P[:, 1], P[:, 0]))                     # equal points together, stable
    on, P = on[order], P[order]
    return on, np.cumsum(np.r_[False, np.any(P[1:] != P[:-1], axis=1)])


def point_ids(points, faces):
    """Per vertex the number of its reference point among the boundary vertices (-1 elsewhere).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces.

    Returns
    -------
    numpy.ndarray of int64, shape (nv,)
        The ``group`` of :func:`point_groups` at every boundary vertex, -1 elsewhere.
    """
    on, group = point_groups(points, faces)
    pid = np.full(len(points), -1, dtype=np.int64)
    pid[on] = group
    return pid


def face_point_keys(faces, pid):
    """Per face a number that is equal exactly for faces on the same three reference points.

    Parameters
    ----------
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces.
    pid : numpy.ndarray of int, shape (nv,)
        :func:`point_ids` of the same faces.

    Returns
    -------
    numpy.ndarray of int, shape (nf,)
        The number of the face's sorted point triple among the distinct ones.
    """
    K = np.sort(pid[faces], axis=1)
    n = int(K.max(initial=-1)) + 1
    if K.size and K.min() >= 0 and n < 2 ** 21:
        # the triples as int64 codes (a n + b) n + c, ordered as the triples are: the same numbers
        _, key = np.unique((K[:, 0] * n + K[:, 1]) * n + K[:, 2], return_inverse=True)
    else:
        _, key = np.unique(K, axis=0, return_inverse=True)
    return key.ravel()


class CopyIndex:
    """The arrays of a mesh's boundary that the rows at copies of a point look up.

    Made once per mesh (:class:`~ngfracture.contact.setup3d.MeshSetup3d`) from copies of
    the arrays, so it cannot go stale, and passed to :func:`partner_faces` and the functions of rows3d, junctions3d and
    copies3d that take ``index``; each array is the one those functions compute without it.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces.

    Attributes
    ----------
    points, faces : numpy.ndarray
        Copies of the arrays (float64, int64).
    on, group : numpy.ndarray of int64
        :func:`point_groups`.
    point : numpy.ndarray of int64, shape (nv,)
        :func:`point_ids`.
    copies : numpy.ndarray of int64
        The number of boundary vertices at each point.
    face_key : numpy.ndarray of int64, shape (nf,)
        :func:`face_point_keys`; ``key_order`` its stable argsort, ``key_sorted`` the keys
        in that order.
    key_start, key_count : numpy.ndarray of int64, shape (nf,)
        Where every face's key begins in ``key_sorted`` and how often it occurs there (the
        faces on the same three points: ``key_order[key_start[f]:key_start[f] + key_count[f]]``).
    incidence : numpy.ndarray of int64, shape (3 nf,)
        ``faces.ravel()`` argsorted (stable); ``incident`` its vertices in that order.
    area2, unit : numpy.ndarray, shape (nf, 3)
        Every face's area normal (cross product of its edges from corner 0) and unit normal.
    vertex_keys : numpy.ndarray of int64
        The codes v (nf + 1) + face_key of every (vertex, face) incidence, sorted, unique.

    Raises
    ------
    ValueError
        On points not finite or not of shape (nv, 3), faces not of shape (nf, 3) or with
        vertex numbers outside [0, nv).
    """

    def __init__(self, points, faces):
        self.points = np.array(points, dtype=np.float64)
        self.faces = np.array(faces, dtype=np.int64).reshape(-1, 3)
        if self.points.ndim != 2 or self.points.shape[1] != 3 or not np.isfinite(self.points).all():
            raise ValueError(f"CopyIndex: points must be finite numbers of shape (nv, 3), got shape {self.points.shape}")
        # C++ (cpp_ext/contact_setup3d.cpp), bit for bit the numpy computation of the
        # attributes' descriptions (tests/test_copy_index.py keeps it and compares)
        (self.on, self.group, self.face_key, self.key_order, self.incidence, self.area2, self.unit,
         self.vertex_keys) = _ext.CopyIndexArrays(self.points, self.faces)
        self.point = np.full(len(self.points), -1, dtype=np.int64)
        self.point[self.on] = self.group
        self.copies = np.bincount(self.group, minlength=1)
        self.key_sorted = self.face_key[self.key_order]
        self.key_start, self.key_count = _key_runs(self.key_sorted, self.key_order)
        self.incident = self.faces.ravel()[self.incidence]


def _key_runs(key_sorted, key_order):
    """For every face (``key_order`` sorts the faces by key): the start of its key's run in
    ``key_sorted`` and the run's length, what two searchsorted calls per face give."""
    first = np.ones(len(key_sorted), dtype=bool)
    first[1:] = key_sorted[1:] != key_sorted[:-1]
    starts = np.flatnonzero(first)
    run = np.cumsum(first) - 1
    counts = np.diff(np.append(starts, len(key_sorted)))
    start, count = np.empty(len(key_order), dtype=np.int64), np.empty(len(key_order), dtype=np.int64)
    start[key_order], count[key_order] = starts[run], counts[run]
    return start, count


def partner_faces(points, faces, slave, copy, all_pairs, one_way=True, index=None):
    """The faces at copy t coincident with a face at slave s, for pairs of copies s > t.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward.
    slave, copy : numpy.ndarray of int, shape (m,)
        Pairs (s, t) of vertices at the same reference point.
    all_pairs : bool
        Every pair s > t (True) or only those at points with three or more copies.
    one_way : bool
        Only pairs with s > t (True), or every given pair (False: the caller chose the
        direction).
    index : CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    slave : numpy.ndarray of int
        The slave s of every incidence, sorted by pair, then face.
    face : numpy.ndarray of int
        A face at t coincident with a face at s.
    corner : numpy.ndarray of int
        The position of t in that face (0, 1 or 2).
    """
    if index is None:
        index = CopyIndex(points, faces)
    point = index.point
    pick = slave > copy if one_way else np.ones(len(slave), dtype=bool)
    if not all_pairs:
        pick &= index.copies[point[slave]] >= 3
    s, t = slave[pick], copy[pick]
    start = np.searchsorted(index.incident, t)
    count = np.searchsorted(index.incident, t, side="right") - start
    pair, slot = expand_ranges(start, count)
    face, corner = np.divmod(index.incidence[slot], 3)
    s = s[pair]
    nk = len(index.faces) + 1                                              # more than the number of keys
    keep = sorted_members(index.vertex_keys, s * nk + index.face_key[face])   # f's key is that of a face at s
    return s[keep], face[keep], corner[keep]


def copy_pairs(index):
    """Every ordered pair (s, t) of boundary vertices at the bitwise-equal reference point, s == t included.

    Parameters
    ----------
    index : CopyIndex

    Returns
    -------
    s, t : numpy.ndarray of int64
        The pairs, point by point in the index's order.
    """
    # C++ (cpp_ext/contact_setup3d.cpp): index.on at every ordered pair of positions in a run
    # of equal groups, the same arrays (tests/test_contact3d_setup_pairs.py keeps the numpy
    # computation and compares)
    return _ext.CopyPairs(index.on, index.group)


def expand_ranges(start, count):
    """For entries e with ranges [start_e, start_e + count_e): (e, index) for every index of every range.

    Parameters
    ----------
    start, count : numpy.ndarray of int, shape (m,)

    Returns
    -------
    owner, index : numpy.ndarray of int
        The entry and the index, entry by entry, indices increasing.
    """
    owner = np.repeat(np.arange(len(start)), count)
    offset = np.arange(len(owner)) - np.repeat(np.cumsum(count) - count, count)
    return owner, np.repeat(start, count) + offset
