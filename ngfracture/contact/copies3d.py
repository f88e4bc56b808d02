"""Found rows between copies of a point: projected at the copy, one direction per pair.

Where node splitting left several copies of a point (crack lips, the core's vertex at a
crack's mouth on the sphere's hole), the fixed rows (:func:`~ngfracture.contact.rows3d.lip_rows`,
:func:`~ngfracture.contact.junctions3d.fragment_pair_rows` and their partner-face rows) hold
each copy against the faces at the other copies that are coincident with its own faces.
Where three or more copies meet they are not the whole condition: a copy s may slide over
a face at copy t that is coincident with a face of a third copy u (a lip sliding past the
junction line of three cracks), or into the lip of t across the crack that opened between
t and u (the core's vertex at a crack's mouth). Non-penetration there is a union of
conditions (s outside t's wedge through one of its faces or another), which no fixed set
of rows expresses; the detection finds where it fails: s inside a tetrahedron at t, its
master the nearest face at t that opposes s's normal or is coincident with a face at s
(:func:`~ngfracture.contact.collision3d.detect_penetrations_3d`).

:func:`found_rows_at_copies` turns such detected rows into rows of the same form as the
fixed ones, so that they neither conflict with them nor duplicate them reversed:

- **projected at the copy**: a row of s on a face with a corner t at s's reference point
  gets the barycentric 1 at t (g = 0): its gap n . (x_s - x_t) is the same as on any point
  of the face's plane, and all rows of s on faces at t vanish where the copies meet
  (:func:`~ngfracture.contact.rows3d.relinearise_node_to_face` keeps the projection there);
- **the face's normal of the reference configuration**, as the fixed rows start: the
  detection's configuration may be a prediction whose lips overlap and tilt by 1e-3, and
  the gap of copies that meet does not change with the normal, so a row made there kept
  the tilted normal (the re-linearisation keeps rows whose gap did not change), imposed
  beside the fixed row of the pair with the face's true normal: two rows that block the
  slip of the copies. The next round re-linearises a row whose gap the solve changed;
- **one direction per pair**, the fixed rows' (the slave on the higher fragment, on one
  fragment the higher vertex number): a row of the other direction, t found inside s's
  wedge through face f at s, is the row of s on the face at t coincident with f (normals
  opposite: n_f . (x_t - x_s) >= 0 is the same inequality), where there is one; rows of
  both directions on nearly parallel faces, imposed together, block the slip of the copies
  (docs/contact.md, "Crack lips in 3D").

:func:`folded_rows_at_copies` completes such a row where the surface at the copy bends: a
copy s found inside the side of its copy t gets a row on every face at t coincident with
a face at s and off the found row's plane (as the kink rows of lips,
:data:`~ngfracture.contact.kinks3d.KINK`). For two copies that is the whole first-order condition (s out of t's side iff
n_f . (x_s - x_t) >= 0 on every such face f, :mod:`~ngfracture.contact.kinks3d`), which
the fixed rows impose at points of two copies on different fragments only on one face
(more rows there would add to the sphere's stick rows, which tie the core's vertices to
the glass, on all of the faceted interface). Where the lip is folded, one row lets s
slide along its face past the fold into t's side, and once s is deeper than the fold the
detection's master face at t can be one whose plane s is in front of: its row does not
hold s (the coarse confined sphere at x = 2.533e-3, a glass vertex of a piece being cut
off 5.3e-5 deep in the copy it was split from).

:func:`two_sided_rows` makes every row at a copy (fixed or found) hold both vertices of
its pair: the row of s on face f at t and t's condition on the coincident face at s are
rows on the same two vertices with normals that turn apart as the lips deform, and the
row takes the tighter one (the coarse confined sphere at x = 3.012e-3: a vertex 3.5e-10
behind a lip face at its copy, the pair's row holding only the other side).
"""
import numpy as np

from .. import _ngfracture as _ext
from .kinks3d import KINK, CopyIndex
from .rows import take_rows
from .rows3d import NodeToFaceRows, no_face_rows

__all__ = ["found_rows_at_copies", "folded_rows_at_copies", "two_sided_rows", "partner_incidences",
           "behind_partner_rows", "rows_at_copies_of", "rows_at_copy"]


def _partner_at(index, face, vertex):
    """For every (face, vertex): the face on the same three points with ``vertex`` as a corner, or -1."""
    # C++ (cpp_ext/copies3d.cpp): the faces on the face's key in key order, the first with the vertex
    return _ext.PartnerAt(index.faces, index.key_order, index.key_start, index.key_count, face, vertex)


def found_rows_at_copies(points, faces, rows, vertex_fragment, index=None):
    """Detected rows on faces at a copy of the slave: projected there, in the fixed rows' direction.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward (the rows' faces are rows of it).
    rows : NodeToFaceRows
        Rows of detected pairs (:func:`~ngfracture.contact.rows3d.node_to_face_rows`).
    vertex_fragment : numpy.ndarray of int, shape (nv,)
        The fragment of every vertex.
    index : ngfracture.contact.kinks3d.CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    rows : NodeToFaceRows
        The rows in their order; those at a copy projected there and, in the other
        direction, replaced by the row of the copy on the coincident face at the slave
        where it exists; their normal the face's in the reference configuration (``dist``
        kept).
    at_copy : numpy.ndarray of bool
        Which rows are on a face at a copy of their slave.
    """
    if len(rows) == 0:
        return rows, np.zeros(0, dtype=bool)
    X, F = np.asarray(points), np.asarray(faces, dtype=np.int64)
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    if index is None:
        index = CopyIndex(X, F)
    # C++ (cpp_ext/copies3d.cpp), what numpy computed row by row: the first corner of the
    # face at the slave's point, the fixed rows' direction (the copy's row on the partner
    # face at the slave, where there is one), bary 1 at the copy, g 0, the face's unit normal
    slave, master, face, bary, normal, g, at_copy = _ext.FoundRowsAtCopies(
        F, index.point, vf, index.key_order, index.key_start, index.key_count, index.unit, rows.slave,
        rows.master, rows.face, rows.bary, rows.normal, rows.g)
    out = NodeToFaceRows(slave=slave, master=master, face=face, bary=bary, normal=normal, dist=rows.dist.copy(),
                         g=g, nv=rows.nv)
    return out, at_copy


def folded_rows_at_copies(points, faces, rows, pick, vertex_fragment, tied=None, index=None):
    """Rows of the picked found rows' slaves on the faces at their copy where the lip there bends.

    Only pairs of copies on different fragments at points of two copies are completed:
    elsewhere the fixed rows have every such face (lips: the kink rows; three or more
    copies: the partner-face rows), and pairs whose relative motion the scene's own rows
    tie (``tied``: the sphere's stick rows) keep their one row, the others being dependent
    on those rows (the sphere's faceted interface).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward.
    rows : NodeToFaceRows
        Rows of :func:`found_rows_at_copies`.
    pick : numpy.ndarray of bool, shape (len(rows),)
        The rows to complete: rows at a copy of their slave (barycentric 1 there).
    vertex_fragment : numpy.ndarray of int, shape (nv,)
        The fragment of every vertex.
    tied : numpy.ndarray of int or None
        Pairs of vertices tied by other rows, as codes min * nv + max (sorted).
    index : ngfracture.contact.kinks3d.CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    NodeToFaceRows
        For every pair (s, t) of a picked row's slave and copy, the rows of s on the faces
        at t coincident with a face at s whose unit normal differs from that of each picked
        row of the pair by more than :data:`~ngfracture.contact.kinks3d.KINK` (nearly
        parallel rows, imposed together, block the slip of the copies), sorted by pair and
        face: projected at the copy (g = 0), the face's normal of the reference
        configuration, ``dist`` 0 (the copies' points equal).
    """
    X, F = np.asarray(points), np.asarray(faces, dtype=np.int64)
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    if index is None:
        index = CopyIndex(X, F)
    # C++ (cpp_ext/copies3d.cpp), what numpy computed: the picked rows' pairs (s, t), t the
    # corner the row is projected at, kept at points of two copies on different fragments and
    # not tied; the faces at t coincident with a face at s (kinks3d.partner_faces), by pair
    # code and the faces' order at t; an incidence dropped where a picked row of its pair
    # has a normal within KINK of the face's (1 - n_f . n <= KINK)
    tied = np.zeros(0, dtype=np.int64) if tied is None else np.asarray(tied, dtype=np.int64)
    slave, face, corner = _ext.FoldedIncidences(index.faces, index.point, index.copies, vf, index.incident,
                                                index.incidence, index.face_key, index.vertex_keys, index.unit,
                                                np.asarray(pick, dtype=bool), rows.slave, rows.master, rows.bary,
                                                rows.normal, tied, KINK)
    return rows_at_copy(slave, face, corner, np.zeros(len(slave)), index)


def two_sided_rows(rows, points, displacement, index, margin=0.0):
    """Rows at a copy with the normal of the tighter of the pair's two conditions.

    A row of slave s on face f at its copy t (projected at t) is the condition
    n_f . (x_s - x_t) >= 0: s out of f's plane. The coincident face f' at s gives the
    reversed condition, t out of f''s plane: -n_f' . (x_s - x_t) >= 0, the same row while
    the faces are parallel. Once the lips slide by d and the faces turn apart by an angle
    a, the two differ by about |d| a, and a row on one face lets the copy of the other
    side through its plane by that much. Both conditions are rows of the same vertices (s
    and t), differing only in the normal: the row takes the normal whose gap is the
    smaller, so that its one row holds both vertices (two rows on nearly parallel faces,
    imposed together, would block the slip of the copies; docs/contact.md, "Crack lips
    in 3D"). Only a reversed gap below the row's by more than ``margin`` counts: coincident
    faces' normals differ by rounding even where nothing slid, and a difference the solve
    does not see (the active set keeps a row's linearisation while its gap moves by less
    than a hundredth of the penetration tolerance) should not change its rounding.

    Parameters
    ----------
    rows : NodeToFaceRows
        Rows re-linearised at X + U (:func:`~ngfracture.contact.rows3d.relinearise_node_to_face`).
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates X (copies bitwise equal).
    displacement : numpy.ndarray, shape (nv, 3)
        Displacements U.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of ``points`` and the boundary faces.
    margin : float, optional
        How much smaller (a length) the reversed gap must be to replace the row's.

    Returns
    -------
    NodeToFaceRows
        ``rows`` itself where no row changes; else the rows in their order, those at a
        copy whose reversed condition is tighter with the normal -n_f' (unit, at X + U)
        and its ``dist``; ``bary`` and ``g`` (0 at a copy) unchanged.
    """
    if len(rows) == 0:
        return rows
    X = np.asarray(points)
    pid = index.point
    top = np.argmax(rows.bary, axis=1)
    corner = rows.master[np.arange(len(rows)), top]
    at = np.flatnonzero((rows.bary[np.arange(len(rows)), top] == 1.0) & (pid[rows.slave] >= 0)
                        & (pid[corner] == pid[rows.slave]) & (corner != rows.slave))
    if len(at) == 0:
        return rows
    partner = _partner_at(index, rows.face[at], rows.slave[at])
    at, partner = at[partner >= 0], partner[partner >= 0]
    x = X + np.asarray(displacement)
    tri = take_rows(x, take_rows(index.faces, partner))
    area = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(area, axis=1)
    ok = length > 1e-16 * np.linalg.norm(index.area2[partner], axis=1)      # not squeezed flat
    reverse = -area / np.where(ok, length, 1.0)[:, None]
    d = take_rows(x, rows.slave[at]) - take_rows(x, corner[at])
    gap = np.einsum("ij,ij->i", reverse, d)
    tighter = ok & (gap < rows.dist[at] - margin)
    if not tighter.any():
        return rows
    r = at[tighter]
    normal, dist = rows.normal.copy(), rows.dist.copy()
    normal[r], dist[r] = reverse[tighter], gap[tighter]
    return NodeToFaceRows(rows.slave, rows.master, rows.face, rows.bary, normal, dist, rows.g, nv=rows.nv)


def rows_at_copy(slave, face, corner, dist, index):
    """Node-to-face rows of slaves on faces at one of their copies, in the form of every row at a copy.

    Projected at the copy (barycentric 1 at the face's corner ``corner``, ``g`` 0: the
    copies' reference points are equal), with the face's unit normal of the reference
    configuration.

    Parameters
    ----------
    slave, face, corner : numpy.ndarray of int, shape (m,)
        The slaves, their faces and the position of the slave's copy in each face.
    dist : numpy.ndarray, shape (m,)
        The rows' gaps at the configuration that found them.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the reference points and boundary faces.

    Returns
    -------
    NodeToFaceRows
    """
    bary = np.zeros((len(slave), 3))
    bary[np.arange(len(slave)), corner] = 1.0
    return NodeToFaceRows(slave=slave, master=take_rows(index.faces, face), face=face, bary=bary,
                          normal=take_rows(index.unit, face),
                          dist=dist, g=np.zeros(len(slave)), nv=len(index.points))


def _plane_gaps(x, faces, face, slave, copy):
    """n_f . (x_s - x_t) with the faces' unit normals at x; 0 on a face squeezed flat (no plane)."""
    tri = take_rows(x, take_rows(faces, face))
    area = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(area, axis=1)
    return np.where(length > 0, np.einsum("ij,ij->i", area, x[slave] - x[copy]) / np.where(length > 0, length, 1.0),
                    0.0)


def partner_incidences(index, vertex_fragment):
    """Every pair (s, f) of a copy s and a face f at a copy t of s coincident with a face at s, s the slave of the pair.

    One direction per pair of copies, the fixed rows' (:mod:`~ngfracture.contact.junctions3d`,
    :func:`~ngfracture.contact.rows3d.lip_rows`): the slave on the higher fragment, on one
    fragment the higher vertex. The reversed condition on the coincident face is the same
    row while the faces stay parallel, and the re-linearisation takes the tighter of the
    two (:func:`two_sided_rows`).

    Parameters
    ----------
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the mesh's reference points and boundary faces.
    vertex_fragment : numpy.ndarray of int, shape (nv,)
        The fragment of every vertex.

    Returns
    -------
    slave, face, corner : numpy.ndarray of int
        As :func:`~ngfracture.contact.kinks3d.partner_faces` returns them (lips of one
        fragment included).

    Raises
    ------
    ValueError
        If ``vertex_fragment`` is not one number per vertex of the index.
    """
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    if vf.shape != (len(index.points),):
        raise ValueError(f"partner_incidences: vertex_fragment must have shape ({len(index.points)},), got {vf.shape}")
    # C++ (cpp_ext/contact_setup3d.cpp): the pairs (s, t) of copy_pairs with vf[s] > vf[t],
    # on one fragment s > t (the fixed rows' direction), through partner_faces(all_pairs=True,
    # one_way=False); the same arrays (tests/test_contact3d_setup_kernels.py compares)
    return _ext.PartnerIncidences(index.on, index.group, index.incident, index.incidence, index.face_key, vf)


def behind_partner_rows(partners, displacement, tol, index):
    """Rows of copies that lie behind the plane of a partner face at their copy deeper than ``tol``.

    The fixed rows hold a copy s against one face at its copy t, and against the others
    only where they turn away from it by more than :data:`~ngfracture.contact.kinks3d.KINK`.
    Sliding along one face, s goes behind the plane of a partner face turned by less, by
    the slip times the angle; once deeper than ``tol`` that face gets its row (the first-
    order condition of two copies, :mod:`~ngfracture.contact.kinks3d`).

    Parameters
    ----------
    partners : tuple of numpy.ndarray
        :func:`partner_incidences` of the mesh.
    displacement : numpy.ndarray, shape (nv, 3)
        Displacements U: the configuration X + U tested.
    tol : float
        Depth (a length) behind a partner face's plane that makes a row.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the reference points and boundary faces.

    Returns
    -------
    NodeToFaceRows
        For every pair of copies with a partner face that s is behind deeper than ``tol``,
        the rows on all of the pair's partner faces (the active set imposes those that
        bind; found one by one, each held plane lets s slide behind the next), in the
        order of ``partners``: projected at the copy (``g`` 0), the face's unit normal of
        the reference configuration, ``dist`` the gap at X + U.
    """
    slave, face, corner = partners
    X = index.points
    if not len(slave):
        return no_face_rows(len(X))
    x = X + np.asarray(displacement, dtype=np.float64)
    # C++ (cpp_ext/copies3d.cpp): the plane gaps of :func:`_plane_gaps` (0 where the
    # copies meet), bit for bit, and every incidence of a pair with one below -tol
    hit, gap = _ext.BehindPartnerGaps(x, index.faces, slave, face, corner, float(tol))
    if not len(hit):
        return no_face_rows(len(X))
    return rows_at_copy(slave[hit], face[hit], corner[hit], gap, index)


def rows_at_copies_of(slave, face, displacement, index):
    """The rows at copies with the given slaves and faces (keys of an earlier solve): those
    whose face has a corner at the slave's reference point other than the slave.

    A warm start names the rows a solve imposed by their keys; a row at a copy found in
    that solve (a copy behind a partner face, a junction edge in a wedge, a detected copy)
    is no fixed row, and unless the next solve can impose it at once it is found again
    only after a round that lets the copy through.

    Parameters
    ----------
    slave, face : numpy.ndarray of int, shape (m,)
        The keys' slaves and faces.
    displacement : numpy.ndarray, shape (nv, 3)
        Displacements U: ``dist`` is the gap at X + U.
    index : ngfracture.contact.kinks3d.CopyIndex
        The index of the reference points and boundary faces.

    Returns
    -------
    NodeToFaceRows
        The rows of the pairs at a copy, in their order: projected at the copy (``g`` 0),
        the face's unit normal of the reference configuration.
    """
    X, F, pid = index.points, index.faces, index.point
    nv = len(X)
    slave, face = np.asarray(slave, dtype=np.int64), np.asarray(face, dtype=np.int64)
    master = F[face]
    at = (pid[master] == pid[slave][:, None]) & (master != slave[:, None]) & (pid[slave] >= 0)[:, None]
    keep = np.flatnonzero(at.sum(axis=1) == 1)
    if not len(keep):
        return no_face_rows(nv)
    slave, face, corner = slave[keep], face[keep], np.argmax(at[keep], axis=1)
    x = X + np.asarray(displacement, dtype=np.float64)
    gap = _plane_gaps(x, F, face, slave, F[face, corner])
    return rows_at_copy(slave, face, corner, gap, index)
