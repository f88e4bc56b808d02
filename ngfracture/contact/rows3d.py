"""Node-to-face contact rows on tetrahedral meshes (paper section 3.2, eq. 12-14, in 3D).

The 3D form of the node-to-segment rows of :mod:`ngfracture.contact.rows`, built from the
pairs that :func:`ngfracture.contact.collision3d.detect_penetrations_3d` finds: for a slave
vertex s and its master boundary triangle (i, j, k) of another fragment, with the
barycentric coordinates b of the slave's projection on the master face and the face's unit
outward normal n both frozen at the configuration of the detection (eq. 13),

    g_N(u) = n . ( (X_s + u_s) - sum_l b_l (X_l + u_l) ) = C u + g,

the signed distance of the slave from the master face's plane: positive = separated,
negative = penetration. The non-penetration condition is g_N >= 0 (frictionless); an
active row imposes C u + g = 0, i.e. the problem's constraint rows get ``C`` and ``-g``.
g is the row applied to the reference coordinates, so for an interface flat in the
reference configuration g = 0 exactly and C u is the whole gap.

Layout and signs are those of the 2D rows, with a third component: the dof of component
``comp`` (0 = x, 1 = y, 2 = z) of vertex ``v`` is ``comp * nv + v`` (P1 ``VectorH1``,
component-blocked), and in [[K, G^T, C^T], [G, 0, 0], [C, 0, 0]] [u; lambda_D; lambda_c]
= [f; b; -g] a compressive contact has lambda_c <= 0: the force the row puts on the slave
node is -lambda_c n, along the master's outward normal, i.e. pushing the slave out. The
rows have the fields the active set of :mod:`ngfracture.contact.active_set` consumes
(``C``, ``g``, ``dist``, ``subset``, ``stack``, ``len``), so its primal-dual update, its
redundancy removal and its records take them unchanged.

Slave and master. A pair (v, F) of the detection gives one row, with v the slave; the
caller chooses the slaves with ``slave`` (a vertex mask). On a flat interface between
non-matching meshes the exact linear field of a uniform pressure satisfies every row of
either pass, but equilibrium decides which passes reproduce it:

- one pass (one side the slaves) does not. The slave's force reaches the master nodes
  through the barycentrics, sum_i lambda_i b_ij, and for lambda_i = p A_i (A_i the slave's
  consistent nodal area) that is p A_j of the master node j only where the meshes match
  (Taylor and Papadopoulos' failure of node-to-segment contact). Measured on the test's
  blocks (3 x 3 against 4 x 4 uneven cells): displacement error 3.4e-2 of the load
  displacement, nodal pressures 0.51 to 1.23 of the exact one;
- two passes (both sides slaves) do: the multipliers of the rows at a node are no longer
  its pressure alone, but for the exact field the interface equations
  lambda_j + sum_i lambda_i b_ij = p A_j (both sides) have a solution, and the solve finds
  the exact field (1.5e-15 of the load displacement) and the force of all rows at every
  interface node over its consistent nodal area is the exact pressure (1.4e-14 relative).

Vertices whose copy on the other fragment sits at the same reference point (corners of a
common face of two bodies meshed apart, closed seams of a crack) are left out by the
detection; :func:`twin_rows` gives them a node-to-face row on a face at the twin. Rows of
both passes at such a twin are the same row reversed, and the redundancy removal keeps one.
Where the surface at the copy is not one plane (a point with three or more copies, a kinked
crack lip) a slave also gets a row on every coincident face at the copy (partner-face rows,
:mod:`ngfracture.contact.kinks3d`).
The tributary area of a node, by which a force is a pressure, is the consistent nodal area
of the surface: the integral of its hat function, a third of the area of every face at
the node (:func:`ngfracture.geometry.solid.nodal_areas`).

Where the candidates come from (touching pairs of the reference configuration, fixed rows,
found rows) is :mod:`ngfracture.contact.active_set3d`'s business.
"""
from dataclasses import dataclass
import functools
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from .. import _ngfracture as _ext
from .kinks3d import KINK, CopyIndex, copy_pairs, expand_ranges, isin_ints, partner_faces
from .rows import RowTable, take_rows

__all__ = ["NodeToFaceRows", "no_face_rows", "node_to_face_rows", "twin_rows", "fragment_twin_rows", "lip_rows", "face_gap_rows",
           "relinearise_node_to_face"]


@dataclass
class NodeToFaceRows(RowTable):
    """Node-to-face rows, one entry per row of C.

    Parameters
    ----------
    slave : numpy.ndarray of int, shape (m,)
        Slave vertex.
    master : numpy.ndarray of int, shape (m, 3)
        Vertices of the master face, in the face's order.
    face : numpy.ndarray of int, shape (m,)
        The master face (row of the mesh's boundary faces).
    bary : numpy.ndarray, shape (m, 3)
        Barycentric coordinates of the slave's projection on the master face.
    normal : numpy.ndarray, shape (m, 3)
        Unit outward normal of the master face.
    dist : numpy.ndarray, shape (m,)
        Signed distance at the configuration of the detection (negative = penetration).
    g : numpy.ndarray, shape (m,)
        Constant part: C u + g is the linearised signed gap.
    nv : int
        Number of vertices (C has 3 nv columns).

    Attributes
    ----------
    C : scipy.sparse.csr_matrix, shape (m, 3 nv)
        The gap rows (component-blocked dofs), built at first use and kept.
    """
    slave: np.ndarray
    master: np.ndarray
    face: np.ndarray
    bary: np.ndarray
    normal: np.ndarray
    dist: np.ndarray
    g: np.ndarray
    nv: int
    FIELDS: ClassVar[tuple] = ("slave", "master", "face", "bary", "normal", "dist", "g")

    @functools.cached_property
    def C(self):
        """The gap rows as a sparse matrix, shape (m, 3 nv), built at first use."""
        return _gap_matrix(self.slave, self.master, self.bary, self.normal, self.nv)

    @classmethod
    def stack(cls, parts):
        """The rows of several row sets of one mesh, in order (``RowTable.stack``).

        Where every part has built its ``C``, the stack's is theirs stacked: a row of C
        depends on its own row's fields only, so it is the one :attr:`C` would build.

        Parameters
        ----------
        parts : list of NodeToFaceRows

        Returns
        -------
        NodeToFaceRows
        """
        out = super().stack(parts)
        if len(parts) > 1 and all("C" in p.__dict__ for p in parts):
            out.__dict__["C"] = sp.vstack([p.C for p in parts], format="csr")
        elif len(parts) == 1 and "C" in parts[0].__dict__:
            out.__dict__["C"] = parts[0].C
        return out

    def subset(self, rows):
        """The rows ``rows`` (``RowTable.subset``), with their rows of ``C`` where it is built.

        Parameters
        ----------
        rows : array_like of int or bool

        Returns
        -------
        NodeToFaceRows
        """
        out = super().subset(rows)
        if "C" in self.__dict__:
            out.__dict__["C"] = self.C[np.asarray(rows)]
        return out

    def keys(self):
        """The key of every row, ("f", slave, master vertices sorted): a row's identity for the active set.

        Returns
        -------
        list of tuple
        """
        master = np.sort(self.master, axis=1).tolist()
        return [("f", s, a, b, c) for s, (a, b, c) in zip(self.slave.tolist(), master)]


def no_face_rows(nv):
    """No rows, for a mesh of nv vertices.

    Parameters
    ----------
    nv : int
        Number of vertices (C has 3 nv columns).

    Returns
    -------
    NodeToFaceRows
        Zero rows.
    """
    e = np.zeros(0, dtype=np.int64)
    return NodeToFaceRows(slave=e, master=np.zeros((0, 3), np.int64), face=e, bary=np.zeros((0, 3)),
                          normal=np.zeros((0, 3)), dist=np.zeros(0), g=np.zeros(0), nv=nv)


def _gap_matrix(slave, master, bary, normal, nv):
    """C of :func:`face_gap_rows`, for arrays already checked.

    Rows of four distinct vertices (every row of a detection): the CSR arrays in C++
    (``cpp_ext/contact_rows3d.cpp``), columns sorted per row, exact zeros left out, what the
    conversion from coordinates gives; a row with a repeated vertex: that conversion, which
    sums the duplicates.
    """
    m = len(slave)
    if 3 * nv < 2 ** 31 and 12 * m < 2 ** 31:
        csr = _ext.GapMatrixCsr3d(slave, master, bary, normal, nv)
        if csr is not None:
            return sp.csr_matrix(csr, shape=(m, 3 * nv))
    w = np.concatenate([np.ones((m, 1)), -bary], axis=1)                  # weights of s, i, j, k
    verts = np.concatenate([slave[:, None], master], axis=1).astype(np.int64)
    rows = np.repeat(np.arange(m), 12)
    cols = np.concatenate([verts + comp * nv for comp in range(3)], axis=1).ravel()
    vals = np.concatenate([w * normal[:, comp:comp + 1] for comp in range(3)], axis=1).ravel()
    C = sp.csr_matrix((vals, (rows, cols)), shape=(m, 3 * nv))        # duplicates summed
    C.eliminate_zeros()                                                # projection on an edge or vertex
    return C


def _gap_offset(X, slave, master, bary, normal):
    """n . (X_s - sum_l b_l X_l) per row, in C++ (the numpy einsums' sums, bit for bit)."""
    return _ext.GapOffsets3d(X, slave, master, bary, normal)


def _vertices(v, name, nv, shape):
    v = np.asarray(v)
    if v.shape != shape or (v.size and not np.issubdtype(v.dtype, np.integer)):
        raise ValueError(f"{name} must be integers of shape {shape}, got {v.dtype} {v.shape}")
    v = v.astype(np.int64)
    if v.size and (v.min() < 0 or v.max() >= nv):
        raise ValueError(f"{name} holds vertex numbers outside [0, {nv})")
    return v


def _coordinates(p, name, nv=None):
    p = np.asarray(p, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or (nv is not None and p.shape[0] != nv):
        raise ValueError(f"{name} must have shape ({'nv' if nv is None else nv}, 3), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError(f"{name} contains NaN or inf")
    return p


def face_gap_rows(points, slave, master, bary, normal):
    """Rows of the linearised gap: C u + g = n . (x_s - sum_l b_l x_l).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference vertex coordinates X.
    slave : array_like of int, shape (m,)
        Slave vertices.
    master : array_like of int, shape (m, 3)
        Master face vertices.
    bary : array_like, shape (m, 3)
        Barycentric weights of the projection point on the master face.
    normal : array_like, shape (m, 3)
        Unit normals (outward from the master, towards the slave).

    Returns
    -------
    C : scipy.sparse.csr_matrix, shape (m, 3 nv)
        Component-blocked dofs: dof(v, comp) = comp * nv + v.
    g : numpy.ndarray, shape (m,)
        n . (X_s - sum_l b_l X_l).

    Raises
    ------
    ValueError
        On inconsistent shapes, non-finite numbers or vertex numbers out of range.
    """
    X = _coordinates(points, "points")
    nv = len(X)
    slave = _vertices(np.ravel(slave), "slave", nv, (np.size(slave),))
    m = len(slave)
    master = _vertices(master, "master", nv, (m, 3))
    bary, normal = _coordinates(bary, "bary", m), _coordinates(normal, "normal", m)
    return _gap_matrix(slave, master, bary, normal, nv), _gap_offset(X, slave, master, bary, normal)


def node_to_face_rows(points, faces, penetrations, slave=None):
    """The node-to-face rows of detected pairs (one per pair, its vertex the slave).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (those the detection had).
    faces : array_like of int, shape (nf, 3)
        The boundary faces the detection had.
    penetrations : ngfracture.contact.collision3d.Penetrations3d
        Pairs at the configuration of the detection, with master face, barycentrics,
        normal and gap.
    slave : array_like of bool, shape (nv,), optional
        Vertices that may be slaves (single-pass contact, see the module docstring);
        all if omitted.

    Returns
    -------
    NodeToFaceRows
        In the order of the pairs; ``dist`` is the detected gap.

    Raises
    ------
    ValueError
        On wrong shapes, or face or vertex numbers out of range.
    """
    X = _coordinates(points, "points")
    nv = len(X)
    F = np.asarray(faces)
    F = _vertices(F, "faces", nv, (F.shape[0] if F.ndim == 2 else -1, 3))
    pen = penetrations
    keep = np.ones(len(pen), dtype=bool)
    if slave is not None:
        mask = np.asarray(slave)
        if mask.shape != (nv,) or mask.dtype != bool:
            raise ValueError(f"slave must be a boolean mask of shape ({nv},), got {mask.dtype} {mask.shape}")
        vertex = _vertices(pen.vertex, "penetrations.vertex", nv, (len(pen),))
        keep = mask[vertex]
    face = np.asarray(pen.face, dtype=np.int64)[keep]
    if face.size and (face.min() < 0 or face.max() >= len(F)):
        raise ValueError(f"penetrations.face holds face numbers outside [0, {len(F)})")
    s = _vertices(np.asarray(pen.vertex)[keep], "penetrations.vertex", nv, (len(face),))
    bary = _coordinates(take_rows(np.asarray(pen.bary), keep), "penetrations.bary", len(face))
    normal = _coordinates(take_rows(np.asarray(pen.normal), keep), "penetrations.normal", len(face))
    master = take_rows(F, face)
    return NodeToFaceRows(slave=s, master=master, face=face, bary=bary.copy(), normal=normal.copy(),
                          dist=np.asarray(pen.gap, dtype=np.float64)[keep].copy(),
                          g=_gap_offset(X, s, master, bary, normal), nv=nv)


def twin_rows(points, faces, slave):
    """Rows for slave vertices whose copy on another fragment sits at the same reference point.

    :func:`~ngfracture.contact.collision3d.detect_penetrations_3d` leaves such pairs out while
    they coincide (closed seams), and two bodies meshed apart share the corners of a common
    face in the same way. The row of slave s with twin t is a node-to-face row on the face
    of t's fragment at t whose unit outward normal opposes s's normal most (s's normal: the
    area-weighted sum of the normals of its own boundary faces), with the projection at t
    (barycentric 1 there): at a flat interface the interface's normal. Slaves whose faces at
    the twin all face along their normal (dot >= 0) get no row. Ties go to the smaller face.
    At points with three or more copies, s > t also gets a row on every face at t coincident
    with a face at s (:func:`~ngfracture.contact.kinks3d.partner_faces`).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : array_like of int, shape (nf, 3)
        Boundary faces, outward.
    slave : array_like of bool, shape (nv,)
        Vertices that may be slaves (one side of the contact); a twin of a slave is any
        boundary vertex at the same reference point that is not in ``slave``.

    Returns
    -------
    NodeToFaceRows
        Sorted by slave vertex, then face; ``dist`` is the gap at the reference configuration (0).

    Raises
    ------
    ValueError
        On wrong shapes or vertex numbers out of range.
    """
    X = _coordinates(points, "points")
    nv = len(X)
    F = np.asarray(faces)
    F = _vertices(F, "faces", nv, (F.shape[0] if F.ndim == 2 else -1, 3))
    mask = np.asarray(slave)
    if mask.shape != (nv,) or mask.dtype != bool:
        raise ValueError(f"slave must be a boolean mask of shape ({nv},), got {mask.dtype} {mask.shape}")
    index = CopyIndex(X, F)
    s, t = copy_pairs(index)
    pick = mask[s] & ~mask[t]
    rows = _with_junction_rows(index, _rows_at_copies(index, s[pick], t[pick], s[pick]), s[pick], t[pick], False)
    return rows.subset(np.lexsort((rows.face, rows.slave)))


def fragment_twin_rows(points, faces, vertex_fragment, index=None):
    """The twin rows of every fragment's vertices as slaves, all fragments in one pass.

    The rows of ``twin_rows(points, faces, vertex_fragment == f)`` for every fragment f in
    increasing order, stacked, bit for bit: a slave's twins are the vertices of other
    fragments at its reference point. One sort of the boundary vertices serves all
    fragments (a call per fragment sorts them once per fragment).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : array_like of int, shape (nf, 3)
        Boundary faces, outward.
    vertex_fragment : array_like of int, shape (nv,)
        The fragment of every vertex (vertices of one fragment never have twins among
        themselves).
    index : ngfracture.contact.kinks3d.CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    NodeToFaceRows
        Sorted by the slave's fragment, then by slave vertex, then face.

    Raises
    ------
    ValueError
        On wrong shapes or vertex numbers out of range.
    """
    X, F, vf = _fragment_arrays(points, faces, vertex_fragment)
    index = CopyIndex(X, F) if index is None else index
    s, t = copy_pairs(index)
    pick = vf[s] != vf[t]
    rows = _with_junction_rows(index, _rows_at_copies(index, s[pick], t[pick], s[pick]), s[pick], t[pick], False)
    return rows.subset(np.lexsort((rows.face, rows.slave, vf[rows.slave])))


def lip_rows(points, faces, vertex_fragment, index=None):
    """Rows between the coincident lips of a crack inside one fragment, one per pair of copies.

    The lips of a crack that does not cut its fragment through are on one fragment: every
    lip vertex has a copy on its own fragment at the same reference point, and
    :func:`twin_rows` (copies on other fragments) gives them nothing. For copies t < s the
    row is the node-to-face row of :func:`twin_rows` with s the slave: on the face at t
    whose unit outward normal opposes s's normal most, projection at t. One row per pair,
    as the 2D seams have one row per twin pair: the lips are matching meshes, so one pass
    transmits a uniform pressure exactly, and a second row of the pair (on a face at s) is
    the same row only while the two faces stay parallel; once the lips deform their
    normals differ, the pair of rows is no longer dependent and imposed together they
    block the slip between the copies. At a junction of three or more copies every pair
    has its row. Where the crack surface is kinked, s also gets a row on every face at t
    coincident with a face at s whose normal differs from the row's by more than
    :data:`~ngfracture.contact.kinks3d.KINK`.

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (copies bitwise equal).
    faces : array_like of int, shape (nf, 3)
        Boundary faces, outward (the crack faces among them).
    vertex_fragment : array_like of int, shape (nv,)
        Fragment of every vertex.
    index : ngfracture.contact.kinks3d.CopyIndex, optional
        The index of ``points`` and ``faces`` (made here if not given).

    Returns
    -------
    NodeToFaceRows
        Sorted by (slave, copy, face), the slave the higher-numbered copy; ``dist`` is the gap at
        the reference configuration (0).

    Raises
    ------
    ValueError
        On wrong shapes or vertex numbers out of range.
    """
    X, F, frag = _fragment_arrays(points, faces, vertex_fragment)
    nv = len(X)
    index = CopyIndex(X, F) if index is None else index
    s, t = copy_pairs(index)
    pick = (frag[s] == frag[t]) & (s > t)
    s, t = s[pick], t[pick]
    if not len(s):              # no crack inside a fragment
        return no_face_rows(nv)
    rows = _with_junction_rows(index, _rows_at_copies(index, s, t, s * nv + t), s, t, True)
    copy = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)] if len(rows) else rows.slave
    return rows.subset(np.lexsort((rows.face, copy, rows.slave)))


def _fragment_arrays(points, faces, vertex_fragment):
    """Coordinates, faces and the fragment of every vertex, checked (ValueError naming the bad one)."""
    X = _coordinates(points, "points")
    nv = len(X)
    F = np.asarray(faces)
    F = _vertices(F, "faces", nv, (F.shape[0] if F.ndim == 2 else -1, 3))
    vf = np.asarray(vertex_fragment)
    if vf.shape != (nv,) or (vf.size and not np.issubdtype(vf.dtype, np.integer)):
        raise ValueError(f"vertex_fragment must be integers of shape ({nv},), got {vf.dtype} {vf.shape}")
    return X, F, vf


def _rows_at_copies(index, s, t, per):
    """Rows of slaves s on the face at their copy t opposing s's normal most, one per value of ``per``."""
    X, F = index.points, index.faces
    nv = len(X)
    if not len(s):
        return no_face_rows(nv)
    area2, unit = index.area2, index.unit
    # the faces' area normals summed at their vertices, in face order (as np.add.at sums)
    vnormal = np.stack([np.bincount(F.ravel(), weights=np.repeat(area2[:, d], 3), minlength=nv)
                        for d in range(3)], axis=1)
    # candidate faces: every face at the copy
    start = np.searchsorted(index.incident, t)
    count = np.searchsorted(index.incident, t, side="right") - start
    pair, slot = expand_ranges(start, count)
    face, k = np.divmod(index.incidence[slot], 3)
    s, per = s[pair], per[pair]
    dots = np.einsum("ij,ij->i", unit[face], vnormal[s])
    best = np.lexsort((face, dots, per))                                   # per group: most opposed, smaller face
    best = best[np.r_[True, per[best][1:] != per[best][:-1]]] if len(best) else best
    best = best[dots[best] < 0]
    if not len(best):
        return no_face_rows(nv)
    s, face, k = s[best], face[best], k[best]
    bary = np.zeros((len(s), 3))
    bary[np.arange(len(s)), k] = 1.0
    master, normal = F[face], unit[face]
    g = _gap_offset(X, s, master, bary, normal)
    return NodeToFaceRows(slave=s, master=master, face=face, bary=bary, normal=normal, dist=g.copy(), g=g, nv=nv)


def _with_junction_rows(index, rows, s, t, lips):
    """``rows`` and rows on the partner faces of :func:`~ngfracture.contact.kinks3d.partner_faces` it lacks."""
    X, F = index.points, index.faces
    slave, face, k = partner_faces(X, F, s, t, all_pairs=lips, index=index)
    bary = np.zeros((len(slave), 3))
    bary[np.arange(len(slave)), k] = 1.0
    normal = index.unit[face]
    keep = ~isin_ints(slave * len(F) + face, rows.slave * len(F) + rows.face)
    if lips and len(rows):        # only faces at a kink against the pair's row (kinks3d.KINK)
        pair = rows.slave * len(X) + rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
        want = slave * len(X) + F[face, k]
        own = np.minimum(np.searchsorted(pair, want), len(rows) - 1)        # rows are sorted by pair
        keep &= (pair[own] != want) | (1.0 - np.einsum("ij,ij->i", normal, rows.normal[own]) > KINK)
    slave, face, bary, normal = slave[keep], face[keep], bary[keep], normal[keep]
    g = _gap_offset(X, slave, F[face], bary, normal)
    extra = NodeToFaceRows(slave=slave, master=F[face], face=face, bary=bary, normal=normal, dist=g.copy(), g=g,
                           nv=len(X))
    return NodeToFaceRows.stack([rows, extra])


def relinearise_node_to_face(rows, points, displacement):
    """The rows with the master face's normal and the slave's projection at X + U.

    The projection is onto the face's plane, its barycentrics clipped to the triangle
    (negative weights set to 0 and the rest rescaled to sum 1); the normal keeps its
    side. A master face squeezed below 1e-16 of its reference area keeps its previous
    normal and barycentrics. A row projected at a copy of the slave (twin, lip and
    partner-face rows: barycentric 1 at a corner whose reference point is the slave's) keeps its
    projection there: the rows of one slave on several faces at a copy t then all vanish
    where the copies meet (docs/contact.md, "Points of several copies").

    Parameters
    ----------
    rows : NodeToFaceRows
        The rows to re-linearise.
    points, displacement : array_like, shape (nv, 3)
        Reference coordinates X and displacements U.

    Returns
    -------
    NodeToFaceRows
        The same rows in the same order with bary, normal, dist (signed distance at
        X + U) and g recomputed; ``rows`` itself when empty.

    Raises
    ------
    ValueError
        On shapes that do not match the rows' vertices, or non-finite numbers.

    Notes
    -----
    Computed in C++ (``cpp_ext/contact_rows3d.cpp``) in numpy's operations and order: bit
    for bit the numpy computation (``tests/test_contact_rows3d_kernels.py``).
    """
    if len(rows) == 0:
        return rows
    X = _coordinates(points, "points", rows.nv)
    x = X + _coordinates(displacement, "displacement", rows.nv)
    b, n, dist, g = _ext.RelineariseRows3d(X, x, rows.slave, rows.master, rows.bary, rows.normal)
    return NodeToFaceRows(rows.slave, rows.master, rows.face, b, n, dist, g, nv=rows.nv)
