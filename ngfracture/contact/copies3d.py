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

from .kinks3d import KINK, CopyIndex, expand_ranges, isin_ints, partner_faces, unique_ints
from .rows3d import NodeToFaceRows

__all__ = ["found_rows_at_copies", "folded_rows_at_copies", "two_sided_rows"]


def _partner_at(index, face, vertex):
    """For every (face, vertex): the face on the same three points with ``vertex`` as a corner, or -1."""
    F, order = index.faces, index.key_order
    start, count = index.key_start[face], index.key_count[face]
    out = np.full(len(face), -1, dtype=np.int64)
    for shift in range(int(count.max(initial=0))):            # the faces on the same points: a few at most
        slot = np.minimum(start + shift, len(order) - 1)
        cand = order[slot]
        hit = (shift < count) & (out < 0) & np.any(F[cand] == vertex[:, None], axis=1)
        out[hit] = cand[hit]
    return out


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
    pid = index.point
    same = pid[rows.master] == pid[rows.slave][:, None]                  # [row, corner]
    at_copy = same.any(axis=1) & (pid[rows.slave] >= 0)
    slave, face, normal = rows.slave.copy(), rows.face.copy(), rows.normal.copy()
    copy = rows.master[np.arange(len(rows)), same.argmax(axis=1)]
    reverse = at_copy & ((vf[slave] < vf[copy]) | ((vf[slave] == vf[copy]) & (slave < copy)))
    r = np.flatnonzero(reverse)
    partner = _partner_at(index, face[r], slave[r])
    r, partner = r[partner >= 0], partner[partner >= 0]
    slave[r], copy[r], face[r] = copy[r], slave[r], partner
    master = F[face]
    normal[at_copy] = index.unit[face[at_copy]]          # the face's unit normal, computed as here
    bary = rows.bary.copy()
    bary[at_copy] = (master[at_copy] == copy[at_copy, None]).astype(np.float64)
    g = rows.g.copy()
    g[at_copy] = 0.0                                      # n . (X_s - X_t), the copies' points equal
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
    nv = rows.nv
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    if index is None:
        index = CopyIndex(X, F)
    pid = index.point
    s = rows.slave
    t = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    two = index.copies[np.maximum(pid[s], 0)] == 2
    ok = np.asarray(pick, dtype=bool) & two & (pid[s] >= 0) & (vf[s] != vf[t])
    if tied is not None and len(tied):
        ok &= ~isin_ints(np.minimum(s, t) * nv + np.maximum(s, t), tied)
    r = np.flatnonzero(ok)
    s, t = s[r], t[r]
    code = s * nv + t
    pair = unique_ints(code)
    slave, face, corner = partner_faces(X, F, pair // nv, pair % nv, all_pairs=True, one_way=False,
                                        index=index)
    master = F[face]
    normal = index.unit[face]                             # the faces' unit normals
    # an incidence is dropped where a picked row of its pair has a parallel face
    order = np.argsort(code, kind="stable")
    incidence_code = slave * nv + master[np.arange(len(face)), corner]
    start = np.searchsorted(code[order], incidence_code)
    incidence, slot = expand_ranges(start, np.searchsorted(code[order], incidence_code, side="right") - start)
    picked = r[order[slot]]
    parallel = 1.0 - np.sum(normal[incidence] * rows.normal[picked], axis=1) <= KINK
    keep = np.ones(len(face), dtype=bool)
    keep[incidence[parallel]] = False
    slave, face, corner, master, normal = slave[keep], face[keep], corner[keep], master[keep], normal[keep]
    bary = np.zeros((len(face), 3))
    bary[np.arange(len(face)), corner] = 1.0
    zero = np.zeros(len(face))
    return NodeToFaceRows(slave=slave, master=master, face=face, bary=bary, normal=normal, dist=zero,
                          g=zero.copy(), nv=nv)


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
    tri = x[index.faces[partner]]
    area = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(area, axis=1)
    ok = length > 1e-16 * np.linalg.norm(index.area2[partner], axis=1)      # not squeezed flat
    reverse = -area / np.where(ok, length, 1.0)[:, None]
    d = x[rows.slave[at]] - x[corner[at]]
    gap = np.einsum("ij,ij->i", reverse, d)
    tighter = ok & (gap < rows.dist[at] - margin)
    if not tighter.any():
        return rows
    r = at[tighter]
    normal, dist = rows.normal.copy(), rows.dist.copy()
    normal[r], dist[r] = reverse[tighter], gap[tighter]
    return NodeToFaceRows(rows.slave, rows.master, rows.face, rows.bary, normal, dist, rows.g, nv=rows.nv)
