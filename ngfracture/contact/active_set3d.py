"""The active set of a contact solve on a tetrahedral mesh: the 3D candidates.

:class:`ActiveSet3d` is :class:`~ngfracture.contact.active_set.ActiveSet` with the candidate
rows of 3D: node-to-face rows (:mod:`ngfracture.contact.rows3d`) and edge-to-edge rows
(:mod:`ngfracture.contact.edge_rows3d`) instead of seam and node-to-segment rows. The choice of the set (primal-dual update, complementarity problem
where it cycles), the redundancy removal and the records are the 2D ones, unchanged; only
where the candidates come from and how they are re-linearised differ.

Candidates, each identified by its key ("f", slave, master vertices sorted; "e", edge a, edge b):

- *fixed* rows, made at the first update of a solve and kept (re-linearised) for the whole
  solve:

  * the pairs that :func:`~ngfracture.contact.collision3d.detect_penetrations_3d` finds in
    the reference configuration: vertices of bodies meshed apart that touch another body
    exactly (gap 0). This is the 3D detection's tolerance for rounding. The detection has
    no precision threshold; a vertex exactly on another body's face can be moved out of it
    by rounding of a solve (1e-18 on the patch test's perimeter) and would be lost, but in
    the reference configuration touching is exact. A length threshold would instead add
    rows for vertices near but off a face, whose rows then fail the patch test;
  * twin rows (:func:`~ngfracture.contact.junctions3d.fragment_pair_rows`), for every vertex
    that has a copy on another fragment at the bitwise-equal reference point: across the
    matched faces of coincident lips one row per (copy, neighbouring copy), one
    direction per pair of fragments, so that a junction of several fragments gets a row
    towards each face neighbour; the corners of a common face of two bodies meshed apart
    (no matched face) get the rows of :func:`~ngfracture.contact.rows3d.fragment_twin_rows`.
    They are the 3D form of the 2D seam rows: the detection leaves closed seams out (their
    master face would depend on rounding), and with a row identified by its key the
    candidate set of a seam is the same in every round;
  * lip rows (:func:`~ngfracture.contact.rows3d.lip_rows`), one per pair of copies on one
    fragment: the two lips of a crack that does not cut its fragment through; both kinds
    with the partner-face rows (:mod:`~ngfracture.contact.kinks3d`) where the surface at the
    copy is not one plane;

- *found* rows: the pairs the detection finds at the configuration of the last solve
  (touching or penetrating), in two passes (every boundary vertex of every fragment a
  slave: the pass that passes the patch test, rows3d's docstring). A found pair whose
  vertex has a twin row to the master fragment (either copy the slave:
  :func:`~ngfracture.contact.junctions3d.covered_pairs`) talks to it through that row only
  (a diagonal neighbour at a junction has none, and its overlap is a found row); a lip
  vertex found in its own fragment, through the lip row of its pair of copies. A found
  row stays a candidate while it is active or found again, as in 2D, and once the
  complementarity problem chooses the set, while it has been wanted or imposed in the
  solve (a row the problem released must stay visible to the next problem); but a found
  row whose slave the detection no longer finds in the master's fragment and which lies
  beyond the edges of its face by more than ``penetration_tol`` leaves the candidates,
  active or not (:meth:`ActiveSet3d._beyond_face`: it holds the slave on the face's plane
  where the master's surface has turned away). Found the
  same way, from the planes at copies of a point: a copy behind the plane of a partner
  face at its copy, the ends of a junction edge inside the wedge of a diagonal
  neighbour's copy of it, and the ends of an edge copy behind a face of another copy's
  reflex wedge, deeper than ``copy_tol``
  (:meth:`ActiveSet3d._with_rows_at_copies`; docs/contact.md, "Rows at copies found by
  their planes").

- *edge* rows (:mod:`~ngfracture.contact.edge_rows3d`): pairs of boundary edges of two
  fragments that cross at the configuration of the last solve deeper than ``edge_tol``
  where no end of either edge lies deeper than ``penetration_tol`` in the other's fragment
  (:meth:`ActiveSet3d._edge_to_edge`), kept as found rows are; and node-to-edge rows
  (:mod:`~ngfracture.contact.clipped3d`, edge rows of a degenerate edge (v, v)): a vertex
  found deeper than ``penetration_tol`` whose projection on its master face is clipped to
  an edge or corner, where the node-to-face candidates of the pair all hold and fall short
  of its depth (:meth:`ActiveSet3d._with_node_to_edge`), kept as found rows are, a pair
  found again taking the new row.

The candidates of a round are a :class:`~ngfracture.contact.mixed_rows.MixedRows` table:
the node-to-face rows (fixed, then found), then the edge rows.

Every round re-linearises all candidates at the configuration of the last solve
(:func:`~ngfracture.contact.rows3d.relinearise_node_to_face`; a row at a copy takes the
normal of the tighter of its pair's two conditions,
:func:`~ngfracture.contact.copies3d.two_sided_rows`), and rows whose gap does not
change by more than a hundredth of ``penetration_tol`` keep their old linearisation bit for
bit (:func:`~ngfracture.contact.active_set.refreshed`), as in 2D.

Keys as codes. A row's key ("f", slave, master vertices sorted) is held as the int64 code
slave * n + i, with i the number of the master's vertex set among the distinct vertex sets
of the boundary faces (:class:`FaceKeys`; a row's master is the vertices of its face, which
the code checks); an edge row's key ("e", edge a, edge b) as the negative code
-1 - (i nE + j) of its edges' numbers i < j among the nE boundary edges. Codes are equal exactly where keys are, so the candidate bookkeeping
(which found rows are new, which stay, which vertices a twin row covers) and the choice of
the set (:class:`~ngfracture.contact.active_set.ActiveSet`) are array operations
(``numpy.isin``, sorting), with the same results as with tuples; the tuples are made only
where a caller reads them (:class:`~ngfracture.contact.row_keys.RowKeys`).
"""
import functools
import time

import numpy as np
import scipy.sparse as sp

from .active_set import ActiveSet, Candidates, refreshed
from .row_keys import RowKeys
from .clipped3d import beyond_face, node_edge_rows, unseen_pairs
from .copies3d import (behind_partner_rows, folded_rows_at_copies, found_rows_at_copies, rows_at_copies_of,
                       two_sided_rows)
from .edge_rows3d import EdgeRows, edge_rows, no_edge_rows, relinearise_edge_rows
from .intsets import isin_ints, union_ints, unique_ints
from .mixed_rows import MixedRows
from .redundancy import holds_on_columns
from .rows3d import NodeToFaceRows, no_face_rows, node_to_face_rows, relinearise_node_to_face
from .setup3d import FaceKeys, MeshSetup3d
from .wedges3d import reflex_wedge_rows, wedge_rows

__all__ = ["ActiveSet3d", "FaceKeys", "fixed_rows_3d"]


def fixed_rows_3d(points, tets, faces, fragment):
    """The rows a 3D contact solve keeps as candidates throughout: touching pairs and twins.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates.
    tets : numpy.ndarray of int, shape (ne, 4)
        Tetrahedra.
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward.
    fragment : numpy.ndarray of int, shape (ne,)
        Fragment number per tetrahedron.

    Returns
    -------
    rows : NodeToFaceRows
        The pairs touching in the reference configuration (sorted by vertex and fragment),
        then the twin rows of every fragment's vertices (fragment by fragment, by slave),
        then the lip rows (by slave and copy).
    keys : RowKeys
        Their keys (a sequence of tuples), without repeats (a repeated key keeps its
        first row).

    Raises
    ------
    ValueError
        On inconsistent arrays (see :func:`~ngfracture.contact.collision3d.detect_penetrations_3d`).
    """
    setup = MeshSetup3d(points, tets, faces, fragment)         # checks the arrays
    return setup.rows, setup.keys


def tied_pairs(holds, nv):
    """The pairs of vertices that one row of ``holds`` (P1 layout, comp * nv + v) ties together.

    Parameters
    ----------
    holds : scipy.sparse.spmatrix or None
        General rows (the scene's own, the holds of free pieces).
    nv : int
        Number of vertices.

    Returns
    -------
    numpy.ndarray of int64
        Codes min * nv + max of the pairs of distinct vertices in one row, sorted, unique;
        rows on more than two vertices (the holds of a piece's rigid modes) tie none.
    """
    if holds is None or holds.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    H = sp.csr_matrix(holds)
    H.eliminate_zeros()
    row = np.repeat(np.arange(H.shape[0]), np.diff(H.indptr))
    v = unique_ints(row * nv + H.indices % nv)                  # (row, vertex), each once
    row, v = v // nv, v % nv
    count = np.bincount(row, minlength=H.shape[0])
    two = count[row] == 2
    row, v = row[two], v[two]
    return unique_ints(v[0::2] * nv + v[1::2])                  # sorted within a row: min first


class ActiveSet3d(ActiveSet):
    """The active set of a contact solve on a tetrahedral mesh (see the module docstring).

    Parameters
    ----------
    geometry : ngfracture.contact.active_set.Geometry
        ``arrays`` a :class:`~ngfracture.geometry.solid.SolidArrays`, ``fragment`` per
        tetrahedron, ``seams`` unused (None), ``fixed`` and ``holds`` in the P1 layout
        (comp * nv + v, three components).
    penetration_tol : float
        Penetration depth (a length) that makes an inactive row enter, and that a settled
        set may leave.
    setups : ngfracture.contact.setup3d.MeshSetups, optional
        Where to take the work on the mesh alone from (the set-up of an earlier solve on
        these arrays, bitwise); without it that work is done here. The results are the same.
    edge_tol : float, optional
        Depth (a length) of a crossing of two edges that makes an edge-to-edge row
        (default ``penetration_tol``); once a row, it is judged by ``penetration_tol``.
    copy_tol : float, optional
        Depth (a length) of a copy behind a partner face's plane at its copy, of a
        junction edge in a diagonal neighbour's wedge, or of an edge copy behind a face of
        another copy's reflex wedge, that makes a row
        (:meth:`_with_rows_at_copies`; default ``penetration_tol``).
    **options
        ``rank_tol``, ``pdas_rounds``, ``max_updates``, ``warm`` of ActiveSet (``tol`` and
        ``kink_angle`` have no role in 3D).
    """

    def __init__(self, geometry, penetration_tol, setups=None, edge_tol=None, copy_tol=None, **options):
        super().__init__(geometry, 0.0, penetration_tol, **options)
        self.edge_tol = penetration_tol if edge_tol is None else edge_tol
        self.copy_tol = penetration_tol if copy_tol is None else copy_tol
        a = geometry.arrays
        # the work on the mesh alone (codec, detector, copy index, fixed rows): made here or
        # taken from the set-up of the solve before on the same mesh
        mesh = (a.points, a.tets, a.faces, geometry.fragment)
        self.setup = MeshSetup3d(*mesh) if setups is None else setups.setup(*mesh)
        self.codec = self.setup.codec
        self.n2s = no_face_rows(len(a.points))
        self.n2s_keys = RowKeys(np.zeros(0, dtype=np.int64), self.codec)
        self.edges = no_edge_rows(len(a.points))
        self.edge_keys = RowKeys(np.zeros(0, dtype=np.int64), self.codec)

    @functools.cached_property
    def tied(self):
        """The vertex pairs the scene's own rows tie (:func:`tied_pairs` of the holds, made at
        first use: the holds of free pieces are dense); their copies keep the fixed rows alone."""
        return tied_pairs(self.geometry.holds, len(self.geometry.arrays.points))

    def update(self, U, timings):
        """The candidate rows at X + U, the configuration of the last solve.

        The first call takes the fixed rows of the mesh's set-up; later calls re-linearise every candidate at
        U (while the rows move). Rows found at U join; found rows of the last update stay
        while they are active or found again.

        Parameters
        ----------
        U : numpy.ndarray, shape (nv, 3)
            Vertex displacements.
        timings : dict
            Its "collision" entry gets the seconds of the collision detection.

        Returns
        -------
        ngfracture.contact.active_set.Candidates
        """
        relinearised = None
        limit = 0.01 * self.penetration_tol
        if self.seam_rows is None:
            self.seam_rows, self.seam_keys = self.setup.rows, self.setup.keys
        elif self.moving:
            old = NodeToFaceRows.stack([self.seam_rows, self.n2s])
            relinearised = self._relinearise(old, U)
            self.seam_rows, self.n2s = self._split(refreshed(old, relinearised, U, limit))
            self.edges = refreshed(self.edges, relinearise_edge_rows(self.edges, self.geometry.arrays.points, U),
                                   U, limit)
        t0 = time.perf_counter()
        pen = self.setup.detector.detect(U)
        timings["collision"] += time.perf_counter() - t0
        found, found_codes = self._node_to_face(pen)
        found, found_codes = self._with_rows_at_copies(found, found_codes, U, pen)
        n2s_codes = self.n2s_keys.codes
        retained = self._retained(n2s_codes, found_codes)
        retained = retained[~self._beyond_face(retained, found_codes, U, pen)]
        new = np.flatnonzero(~isin_ints(found_codes, np.concatenate([n2s_codes, self.seam_keys.codes])))
        self.n2s = NodeToFaceRows.stack([self.n2s.subset(retained), found.subset(new)])
        self.n2s_keys = RowKeys(np.concatenate([n2s_codes[retained], found_codes[new]]), self.codec)
        found, found_codes = self._edge_to_edge(U, pen, timings)
        found, found_codes = self._with_node_to_edge(found, found_codes, U, pen)
        edge_codes = self.edge_keys.codes
        kept = self._retained(edge_codes, found_codes)
        # a node-to-edge row found again takes the detection's direction (its re-linearisation
        # keeps the old one, which the solve may have left behind)
        kept = kept[~(isin_ints(edge_codes[kept], found_codes) & self.codec.is_node_edge(edge_codes[kept]))]
        fresh = np.flatnonzero(~isin_ints(found_codes, edge_codes[kept]))
        self.edges = EdgeRows.stack([self.edges.subset(kept), found.subset(fresh)])
        self.edge_keys = RowKeys(np.concatenate([edge_codes[kept], found_codes[fresh]]), self.codec)
        rows = MixedRows([NodeToFaceRows.stack([self.seam_rows, self.n2s]), self.edges])
        if relinearised is not None:
            n_fixed = len(self.seam_keys)
            relinearised = relinearised.subset(np.concatenate([np.arange(n_fixed), n_fixed + retained]))
        return Candidates(rows, self.seam_keys + self.n2s_keys + self.edge_keys, rows.C @ U.T.ravel() + rows.g,
                          relinearised)

    def _retained(self, codes, found_codes):
        """Which found rows of the last update (their ``codes``) stay candidates: those active,
        found again (``found_codes``) or, once the complementarity problem chooses, tried."""
        retain = self._has_multiplier(codes)[0] | isin_ints(codes, found_codes)
        if self.exact:
            # the complementarity problem chooses among the rows wanted or imposed in the
            # solve; one it released stays a candidate, or the next problem cannot see the
            # penetration that releasing it lets happen
            retain |= isin_ints(codes, union_ints(self.tried, self.wanted))
        return np.flatnonzero(retain)

    def _beyond_face(self, retained, found_codes, U, pen):
        """Which found rows ``retained`` (indices into the found rows of the last update) no
        longer hold their slave against the master: not found again (``found_codes``), the
        slave not detected in the master's fragment at X + U (``pen``), and beyond the edges
        of its face by more than ``penetration_tol``
        (:func:`~ngfracture.contact.clipped3d.beyond_face`). Such a row holds the slave on
        the face's plane where the master's surface has turned away; active, it pins the
        slave against nothing (docs/contact.md, "Rows beyond their face")."""
        a, setup = self.geometry.arrays, self.setup
        nv = len(a.points)
        stale = ~isin_ints(self.n2s_keys.codes[retained], found_codes)
        if not stale.any():
            return stale
        inside = np.asarray(pen.fragment, dtype=np.int64) * nv + np.asarray(pen.vertex, dtype=np.int64)
        slave, master = self.n2s.slave[retained], self.n2s.master[retained, 0]
        stale &= ~isin_ints(setup.vertex_fragment[master].astype(np.int64) * nv + slave, inside)
        if not stale.any():
            return stale
        at = np.flatnonzero(stale)
        rows = self.n2s.subset(retained[at])
        stale[at] = beyond_face(a.points, rows, U, setup.copy_index.point) > self.penetration_tol
        return stale

    def _key_codes(self, keys):
        """The codes of keys given as tuples (:meth:`FaceKeys.codes_of`)."""
        return self.codec.codes_of(keys)

    def _holds_for(self, C):
        """The holds that rows ``C`` can depend on (:func:`~ngfracture.contact.redundancy.holds_on_columns`):
        the rows that hold a piece on its rigid modes are dense over the piece, and the
        pieces of a 3D body are large."""
        return holds_on_columns(self.geometry.holds, C, self.geometry.fixed, self.rank_tol)

    def _fresh_rows(self, candidates, U):
        """The candidate rows re-linearised at X + U, in their order (settle's judgement).

        The rows that :meth:`update` re-linearised at this U (``candidates.relinearised``,
        the first ones) are taken from there: a row's re-linearisation depends on the row
        only through its vertices, its face and the side of its normal (and, at a copy or
        on a squeezed face, its barycentrics and normal, which the re-linearisation keeps),
        so re-linearising a row again at the same U gives it bit for bit. Only the rows
        found new in this round are re-linearised here.
        """
        faces, edges = candidates.rows.parts
        done = candidates.relinearised
        if done is None:
            fresh = self._relinearise(faces, U)
        else:
            fresh = NodeToFaceRows.stack([done, self._relinearise(faces.subset(np.arange(len(done), len(faces))), U)])
        edges = relinearise_edge_rows(edges, self.geometry.arrays.points, U)
        return MixedRows([fresh, edges], candidates.rows.kind)

    def _keep_rows(self, rows):
        """Keep the candidate rows ``rows`` (re-linearised) for the next update."""
        faces, self.edges = rows.parts
        self.seam_rows, self.n2s = self._split(faces)

    def _relinearise(self, rows, U):
        """``rows`` re-linearised at X + U, those at a copy on the tighter side of their pair
        (:func:`~ngfracture.contact.copies3d.two_sided_rows`)."""
        X = self.geometry.arrays.points
        return two_sided_rows(relinearise_node_to_face(rows, X, U), X, U, self.setup.copy_index,
                              0.01 * self.penetration_tol)

    def _edge_to_edge(self, U, pen, timings):
        """The pairs of boundary edges of two fragments crossed at X + U deeper than
        ``edge_tol``, whose crossing no vertex explains, as rows with their key codes.

        The detector of the set-up searches pairs of different fragments that share no
        point (:class:`~ngfracture.contact.edge_crossings3d.EdgeCrossingDetector`, copies
        of a point counting as that point).

        A pair where an end of one edge lies deeper than ``penetration_tol`` in the other
        edge's fragment (``pen``, the node-to-face detection at U) gets no row: that
        vertex's row holds it. In a solve's prediction whole lips pass through each other
        and their edges cross everywhere; a row linearised there would hold a line far
        from the surface that the vertex rows bring back. At copies of a point the rows at
        copies hold the pieces: an edge row beside them, nearly parallel to a copy's row on
        the same vertices, turns a small difference of their gaps into a large motion. The
        lips of a crack inside one fragment are held by their vertices' rows only
        (docs/contact.md, "Edge-to-edge rows in 3D").
        """
        X = self.geometry.arrays.points
        t0 = time.perf_counter()
        detector = self.setup.edge_detector
        deep = pen.gap < -self.penetration_tol
        # edges at a deep vertex are not swept: their pairs with the piece it lies in are
        # dropped below, their others are found from the other edge (pairs of two such
        # edges are not: vertex rows move both)
        skip = np.zeros(len(X), dtype=bool)
        skip[np.asarray(pen.vertex)[deep]] = True
        pairs = detector.detect(U, skip)
        timings["collision"] += time.perf_counter() - t0
        vf, edges = self.setup.vertex_fragment, detector.edges
        if len(pairs):
            n = np.int64(vf.max() + 1)
            inside = unique_ints(np.asarray(pen.vertex, dtype=np.int64)[deep] * n
                                 + np.asarray(pen.fragment, dtype=np.int64)[deep])
            a, b = edges[pairs[:, 0]], edges[pairs[:, 1]]
            explained = (isin_ints(a * n + vf[b[:, :1]], inside).any(axis=1)
                         | isin_ints(b * n + vf[a[:, :1]], inside).any(axis=1))
            pairs = pairs[~explained]
        rows, kept = edge_rows(X, self.geometry.arrays.faces, edges, self.setup.faces_at_edge, pairs, U)
        deep = np.flatnonzero(rows.dist < -self.edge_tol)
        return rows.subset(deep), self.codec.edge_codes(pairs[kept[deep]])

    def _with_node_to_edge(self, found, codes, U, pen):
        """The edge rows ``found`` and their key ``codes`` with the node-to-edge rows of the
        detected pairs (``pen``, at X + U) whose projection is clipped to an edge or corner of
        the master face and whose node-to-face candidates all hold and fall short of its depth
        by more than ``penetration_tol`` (:mod:`~ngfracture.contact.clipped3d`)."""
        a = self.geometry.arrays
        pick = unseen_pairs(pen, a.faces, (self.seam_rows, self.n2s), a.points, U, self.setup.vertex_fragment,
                            self.penetration_tol)
        if not len(pick):
            return found, codes
        more = node_edge_rows(a.points, a.faces, pen, pick, U)
        return (EdgeRows.stack([found, more]),
                np.concatenate([codes, self.codec.node_edge_codes(more.edge_a[:, 0], more.edge_b)]))

    def _with_rows_at_copies(self, found, codes, U, pen):
        """The found rows and their key codes with the rows at copies that X + U violates
        deeper than ``copy_tol`` and they lack: a copy behind a partner face's plane
        at its copy (:func:`~ngfracture.contact.copies3d.behind_partner_rows`), junction
        edges in a diagonal neighbour's wedge (:func:`~ngfracture.contact.wedges3d.wedge_rows`)
        and edge copies behind a face of another copy's reflex wedge
        (:func:`~ngfracture.contact.wedges3d.reflex_wedge_rows`);
        in the first round, also the rows at copies that the warm start names
        (:func:`~ngfracture.contact.copies3d.rows_at_copies_of`). None for a pair of
        copies the scene's rows tie (:attr:`tied`), but for the warm rows: the solve
        before imposed them beside the tie (the sphere's normal row of a core vertex on a
        face at its glass copy), and without them the pair has no normal row in the first
        round. A slave that the detection
        (``pen``) finds deeper than ``penetration_tol`` gets none: its detected row holds it
        (in a prediction whole lips pass through each other, and rows linearised there
        would hold planes far from where the lips come back to). The reflex-wedge rows
        are kept for such a slave: inside a reflex wedge the detected row, on one face at
        the copy, can be satisfied while the slave is behind the other face (the coarse
        free sphere: a copy on the plane of the face its detected row holds, 1.0e-5 deep
        in the other fragment, 1.3e-5 behind the wedge's other face)."""
        a, setup = self.geometry.arrays, self.setup
        nv = len(a.points)
        # each kind of row at copies with its name: the warm and the reflex-wedge rows
        # take their own rules below
        parts = [(behind_partner_rows(setup.partners, U, self.copy_tol, setup.copy_index), "partner"),
                 (wedge_rows(setup.diagonal_edges, U, self.copy_tol, setup.copy_index, setup.vertex_fragment),
                  "wedge"),
                 (reflex_wedge_rows(setup.edge_copies, U, self.copy_tol, setup.copy_index), "reflex")]
        if self.warm:
            # the rows at copies the solve before imposed, which the warm start names
            warm = self._key_codes(sorted(self.warm))
            parts.append((rows_at_copies_of(*self.codec.faces_of(warm[warm >= 0]), U, setup.copy_index), "warm"))
        more = NodeToFaceRows.stack([rows for rows, _ in parts])
        if not len(more):
            return found, codes
        kind = np.repeat([name for _, name in parts], [len(rows) for rows, _ in parts])
        copy = more.master[np.arange(len(more)), np.argmax(more.bary, axis=1)]
        deep = unique_ints(np.asarray(pen.vertex, dtype=np.int64)[pen.gap < -self.penetration_tol])
        # the warm rows were imposed beside the tie in the solve before: a pair's one row
        # there (the detection finds it only once the copy is deep again)
        keep = (kind == "warm") | ~isin_ints(np.minimum(more.slave, copy) * nv + np.maximum(more.slave, copy), self.tied)
        exempt = kind == "reflex"
        return self._with_new(found, codes,
                              more.subset(np.flatnonzero(keep & (exempt | ~isin_ints(more.slave, deep)))))

    def _with_new(self, rows, codes, more):
        """``rows`` and their key ``codes`` followed by the rows of ``more`` whose keys they
        lack, each key once (its first row)."""
        more_codes = self.codec.codes(more)
        first = np.sort(np.unique(more_codes, return_index=True)[1])
        first = first[~isin_ints(more_codes[first], codes)]
        return NodeToFaceRows.stack([rows, more.subset(first)]), np.concatenate([codes, more_codes[first]])

    def _node_to_face(self, pen):
        """The pairs detected (``pen``, the detection at X + U) that no twin row covers, as
        rows with their key codes."""
        a = self.geometry.arrays
        setup = self.setup
        rows, at_copy = found_rows_at_copies(a.points, a.faces, node_to_face_rows(a.points, a.faces, pen),
                                             setup.vertex_fragment, index=setup.copy_index)
        # a vertex with a twin on the master fragment talks to it through its twin row; a
        # lip vertex in its own fragment, through the lip row of its pair of copies; but
        # one inside the wedge of a copy (master face at the copy) gets that face's row
        # (copies3d: where several copies meet the fixed rows are not the whole condition)
        twin = np.asarray(pen.twin, dtype=np.int64)
        deep_at_copy = at_copy & (pen.gap < -self.penetration_tol)
        keep = (twin < 0) | deep_at_copy
        if not keep.all():
            own = pen.fragment == setup.vertex_fragment[pen.vertex]
            keep |= ~own & ~isin_ints(np.asarray(pen.fragment, dtype=np.int64) * len(a.points) + pen.vertex,
                                      setup.covered)
        rows = rows.subset(np.flatnonzero(keep))
        codes = self.codec.codes(rows)
        if deep_at_copy.any():
            # and, where the lip at the copy is folded, a row on every coincident face there
            folded = folded_rows_at_copies(a.points, a.faces, rows, deep_at_copy[keep],
                                           setup.vertex_fragment, self.tied,
                                           index=setup.copy_index)
            rows, codes = self._with_new(rows, codes, folded)
        return rows, codes
