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

__all__ = ["KINK", "point_groups", "point_ids", "face_point_keys", "partner_faces", "expand_ranges"]

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
    _, key = np.unique(np.sort(pid[faces], axis=1), axis=0, return_inverse=True)
    return key.ravel()


def partner_faces(points, faces, slave, copy, all_pairs, one_way=True):
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

    Returns
    -------
    slave : numpy.ndarray of int
        The slave s of every incidence, sorted by pair, then face.
    face : numpy.ndarray of int
        A face at t coincident with a face at s.
    corner : numpy.ndarray of int
        The position of t in that face (0, 1 or 2).
    """
    point = point_ids(points, faces)
    pick = slave > copy if one_way else np.ones(len(slave), dtype=bool)
    if not all_pairs:
        pick &= np.bincount(point[point >= 0], minlength=1)[point[slave]] >= 3
    s, t = slave[pick], copy[pick]
    key, flat = face_point_keys(faces, point), faces.ravel()
    inc = np.argsort(flat, kind="stable")
    start = np.searchsorted(flat[inc], t)
    count = np.searchsorted(flat[inc], t, side="right") - start
    pair, slot = expand_ranges(start, count)
    face, corner = np.divmod(inc[slot], 3)
    s = s[pair]
    nk = len(faces) + 1                                                    # more than the number of keys
    keep = np.isin(s * nk + key[face], flat * nk + np.repeat(key, 3))     # f's key is that of a face at s
    return s[keep], face[keep], corner[keep]


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
