"""The active set of a contact solve on a tetrahedral mesh: the 3D candidates.

:class:`ActiveSet3d` is :class:`~ngfracture.contact.active_set.ActiveSet` with the candidate
rows of 3D: node-to-face rows (:mod:`ngfracture.contact.rows3d`) instead of seam and
node-to-segment rows. The choice of the set (primal-dual update, complementarity problem
where it cycles), the redundancy removal and the records are the 2D ones, unchanged; only
where the candidates come from and how they are re-linearised differ.

Candidates, each identified by its key ("f", slave, master vertices sorted):

- *fixed* rows, made at the first update of a solve and kept (re-linearised) for the whole
  solve:

  * the pairs that :func:`~ngfracture.contact.collision3d.detect_penetrations_3d` finds in
    the reference configuration: vertices of bodies meshed apart that touch another body
    exactly (gap 0). This is the 3D detection's tolerance for rounding. The detection has
    no precision threshold; a vertex exactly on another body's face can be moved out of it
    by rounding of a solve (1e-18 on the patch test's perimeter) and would be lost, but in
    the reference configuration touching is exact. A length threshold would instead add
    rows for vertices near but off a face, whose rows then fail the patch test;
  * twin rows (:func:`~ngfracture.contact.rows3d.twin_rows`), for every vertex that has a
    copy on another fragment at the bitwise-equal reference point: the corners of a common
    face of two bodies meshed apart, and the coincident lips of cracks. They are the 3D
    form of the 2D seam rows: the detection leaves closed seams out (their master face
    would depend on rounding), and with a row identified by its key the candidate set of
    a seam is the same in every round;
  * lip rows (:func:`~ngfracture.contact.rows3d.lip_rows`), one per pair of copies on one
    fragment: the two lips of a crack that does not cut its fragment through; both kinds
    with the junction rows (:mod:`~ngfracture.contact.junction3d`) where the surface at the
    copy is not one plane;

- *found* rows: the pairs the detection finds at the configuration of the last solve
  (touching or penetrating), in two passes (every boundary vertex of every fragment a
  slave: the pass that passes the patch test, rows3d's docstring). A found pair whose
  vertex has a twin on the master fragment talks to it through its twin row only; a lip
  vertex found in its own fragment, through the lip row of its pair of copies. A found
  row stays a candidate while it is active or found again, as in 2D.

Every round re-linearises all candidates at the configuration of the last solve
(:func:`~ngfracture.contact.rows3d.relinearise_node_to_face`), and rows whose gap does not
change by more than a hundredth of ``penetration_tol`` keep their old linearisation bit for
bit (:func:`~ngfracture.contact.active_set.refreshed`), as in 2D.
"""
import time

import numpy as np

from .active_set import ActiveSet, Candidates, refreshed
from .collision3d import detect_penetrations_3d
from .rows3d import (NodeToFaceRows, fragment_twin_rows, lip_rows, no_face_rows, node_to_face_rows,
                     relinearise_node_to_face)

__all__ = ["ActiveSet3d", "fixed_rows_3d"]


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
    keys : list of tuple
        Their keys, without repeats (a repeated key keeps its first row).

    Raises
    ------
    ValueError
        On inconsistent arrays (see :func:`detect_penetrations_3d`).
    """
    nv = len(points)
    touching = node_to_face_rows(points, faces, detect_penetrations_3d(points, tets, faces, fragment))
    vertex_fragment = _vertex_fragment(nv, tets, fragment)
    rows = NodeToFaceRows.stack([touching, fragment_twin_rows(points, faces, vertex_fragment),
                                 lip_rows(points, faces, vertex_fragment)])
    keys = rows.keys()
    first = sorted({k: i for i, k in reversed(list(enumerate(keys)))}.values())
    return rows.subset(np.array(first, dtype=np.int64)), [keys[i] for i in first]


def _vertex_fragment(nv, tets, fragment):
    """The fragment of every vertex (-1: in no tetrahedron)."""
    vertex_fragment = np.full(nv, -1, dtype=np.int64)
    vertex_fragment[np.asarray(tets).ravel()] = np.repeat(np.asarray(fragment, dtype=np.int64), 4)
    return vertex_fragment


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
    **options
        ``rank_tol``, ``pdas_rounds``, ``max_updates``, ``warm`` of ActiveSet (``tol`` and
        ``kink_angle`` have no role in 3D).
    """

    def __init__(self, geometry, penetration_tol, **options):
        super().__init__(geometry, 0.0, penetration_tol, **options)
        self.n2s = no_face_rows(len(geometry.arrays.points))
        self.vertex_fragment = None

    def update(self, U, timings):
        """The candidate rows at X + U, the configuration of the last solve.

        The first call builds the fixed rows; later calls re-linearise every candidate at
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
        a = self.geometry.arrays
        relinearised = None
        if self.seam_rows is None:
            t0 = time.perf_counter()
            self.seam_rows, self.seam_keys = fixed_rows_3d(a.points, a.tets, a.faces, self.geometry.fragment)
            timings["collision"] += time.perf_counter() - t0
            self.vertex_fragment = _vertex_fragment(len(a.points), a.tets, self.geometry.fragment)
        elif self.moving:
            old = NodeToFaceRows.stack([self.seam_rows, self.n2s])
            relinearised = relinearise_node_to_face(old, a.points, U)
            self.seam_rows, self.n2s = self._split(refreshed(old, relinearised, U, 0.01 * self.penetration_tol))
        found, found_keys = self._node_to_face(U, timings)
        known, found_set = set(self.n2s_keys) | set(self.seam_keys), set(found_keys)
        retained = [i for i, k in enumerate(self.n2s_keys) if k in self.multipliers or k in found_set]
        new = [i for i, k in enumerate(found_keys) if k not in known]
        self.n2s = NodeToFaceRows.stack([self.n2s.subset(np.array(retained, dtype=np.int64)),
                                         found.subset(np.array(new, dtype=np.int64))])
        self.n2s_keys = [self.n2s_keys[i] for i in retained] + [found_keys[i] for i in new]
        rows = NodeToFaceRows.stack([self.seam_rows, self.n2s])
        if relinearised is not None:
            n_fixed = len(self.seam_keys)
            relinearised = relinearised.subset(np.concatenate([np.arange(n_fixed),
                                                               n_fixed + np.array(retained, dtype=np.int64)]))
        return Candidates(rows, self.seam_keys + self.n2s_keys, rows.C @ U.T.ravel() + rows.g, relinearised)

    def _fresh_rows(self, candidates, U):
        """The candidate rows re-linearised at X + U (all of them: settle's judgement)."""
        return relinearise_node_to_face(candidates.rows, self.geometry.arrays.points, U)

    def _node_to_face(self, U, timings):
        """The pairs detected at X + U that no twin row covers, as rows with their keys."""
        a = self.geometry.arrays
        t0 = time.perf_counter()
        pen = detect_penetrations_3d(a.points, a.tets, a.faces, self.geometry.fragment, displacement=U)
        timings["collision"] += time.perf_counter() - t0
        rows = node_to_face_rows(a.points, a.faces, pen)
        # a vertex with a twin on the master fragment talks to it through its twin row; a
        # lip vertex in its own fragment, through the lip row of its pair of copies
        twin = np.asarray(pen.twin, dtype=np.int64)
        keep = twin < 0
        if not keep.all():
            covered = {(k[1], int(self.vertex_fragment[k[2]])) for k in self.seam_keys}
            own = pen.fragment == self.vertex_fragment[pen.vertex]
            keep |= ~own & np.array([(int(v), int(f)) not in covered
                                     for v, f in zip(pen.vertex.tolist(), pen.fragment.tolist())], dtype=bool)
        rows = rows.subset(np.flatnonzero(keep))
        return rows, rows.keys()
