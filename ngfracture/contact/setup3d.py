"""The part of a 3D contact solve that depends on the mesh only, made once per mesh.

A run solves many times on one mesh (every load step without a new crack; the mesh changes
only where a crack pass splits it), and every solve's active set
(:class:`~ngfracture.contact.active_set3d.ActiveSet3d`) starts from the same work on the
mesh alone: the keys' codec, the set-ups of the detectors (vertices in other fragments,
crossing edges), the boundary's copy index, the vertices' fragments, and the fixed rows in the reference configuration (the touching
pairs of the reference detection, the twin rows, the lip rows and partner-face rows) with
the (vertex, fragment) pairs they cover. :class:`MeshSetup3d` is that work, made from
copies of the arrays; :class:`MeshSetups` keeps the one of the last mesh and gives it to a
solve whose arrays are bitwise those it was made from, else makes a new one. The set-up is
a function of those arrays alone, so a solve with a set-up from the cache is the solve
with one made afresh, bit for bit (``tests/test_contact3d_setup.py``).
"""
import numpy as np

from .. import _ngfracture as _ext
from .row_keys import RowKeys
from .collision3d import PenetrationDetector3d
from .copies3d import partner_incidences
from .edge_crossings3d import EdgeCrossingDetector
from .edge_rows3d import two_faces
from .junctions3d import covered_pairs, fragment_pair_rows
from .kinks3d import CopyIndex
from .rows import take_rows
from .rows3d import NodeToFaceRows, lip_rows, node_to_face_rows
from .wedges3d import diagonal_edges, edge_copies

__all__ = ["FaceKeys", "MeshSetup3d", "MeshSetups", "fixed_rows", "vertex_fragments"]


class FaceKeys:
    """The int64 codes of node-to-face keys on one mesh.

    A row's key ("f", slave, master vertices sorted) is the code slave * n + i, with i the
    number of the master's vertex set among the distinct vertex sets of the boundary faces
    (codes are equal exactly where keys are; :mod:`ngfracture.contact.active_set3d`). An
    edge-to-edge row's key ("e", a0, a1, b0, b1) (:mod:`ngfracture.contact.edge_rows3d`) is
    the negative code -1 - (i * nE + j), with i < j the numbers of its edges among the nE
    sorted boundary edges. A node-to-edge row's key ("n", v, b0, b1)
    (:mod:`ngfracture.contact.clipped3d`; b0 = b1 for a corner) is the code
    -2 - nE^2 - (v (nE + nb) + j), with j the number of the edge (b0, b1) among the
    boundary edges, or nE + b0 for a corner, and nb one more than the largest vertex of a
    face: below every edge code (>= -nE^2 + nE). Codes of the three kinds never meet, and
    -1 is no key.

    Parameters
    ----------
    faces : array_like of int, shape (nf, 3)
        The mesh's boundary faces.
    edges : array_like of int, shape (nE, 2), optional
        The mesh's sorted boundary edges, for edge keys.

    Raises
    ------
    ValueError
        If ``faces`` is not of shape (nf, 3) with vertex numbers >= 0.
    """

    def __init__(self, faces, edges=None):
        F = np.asarray(faces)
        if F.ndim != 2 or F.shape[1] != 3 or (F.size and (not np.issubdtype(F.dtype, np.integer) or F.min() < 0)):
            raise ValueError(f"faces must be vertex numbers >= 0 of shape (nf, 3), got {F.dtype} {F.shape}")
        F = F.astype(np.int64)
        # the distinct sorted triples in order and every face's number among them (C++,
        # cpp_ext/contact_setup3d.cpp: np.sort, np.lexsort and a cumsum of the first of
        # every run, bit for bit; tests/test_contact3d_setup_kernels.py compares)
        _, self.face_set, self.triples = _ext.SortedTripleRanks(F, int(F.max(initial=-1)) + 1)
        self.n = max(len(self.triples), 1)
        self.nb = int(F.max(initial=-1)) + 1
        self._lookup = None
        self._face_of_set = None
        self.edges = np.zeros((0, 2), dtype=np.int64) if edges is None else np.asarray(edges, dtype=np.int64)
        self._edge_lookup = None

    def codes(self, rows):
        """The codes of the keys of some rows.

        Parameters
        ----------
        rows : ngfracture.contact.rows3d.NodeToFaceRows
            Rows of this mesh (their master the vertices of their face).

        Returns
        -------
        numpy.ndarray of int64

        Raises
        ------
        ValueError
            If a row's master is not the vertex set of its face.
        """
        sets = self.face_set[np.asarray(rows.face, dtype=np.int64)]
        if not np.array_equal(take_rows(self.triples, sets), np.sort(rows.master, axis=1)):
            raise ValueError("FaceKeys.codes: a row's master is not the vertex set of its face")
        return np.asarray(rows.slave, dtype=np.int64) * self.n + sets

    def codes_of(self, keys):
        """The codes of keys given as tuples ("f", slave, a, b, c), ("e", a0, a1, b0, b1) or
        ("n", v, b0, b1); -1 for a key of no face, edges or edge (corner).

        Parameters
        ----------
        keys : sequence of tuple

        Returns
        -------
        numpy.ndarray of int64
        """
        if self._lookup is None:
            self._lookup = {tuple(t): i for i, t in enumerate(self.triples.tolist())}
            self._edge_lookup = {tuple(e): i for i, e in enumerate(self.edges.tolist())}
        look, edge, ne = self._lookup, self._edge_lookup, len(self.edges)

        def code(k):
            if k[0] == "e":
                i, j = edge.get(k[1:3], -1), edge.get(k[3:5], -1)
                return -1 - (i * ne + j) if 0 <= i < j else -1
            if k[0] == "n":
                return int(self.node_edge_codes([k[1]], [k[2:4]])[0])
            return (k[1] * self.n + look[k[2:]]) if k[2:] in look else -1
        return np.fromiter((code(k) for k in keys), dtype=np.int64, count=len(keys))

    def faces_of(self, codes):
        """The slave and a face of the node-to-face keys of codes (>= 0).

        Parameters
        ----------
        codes : numpy.ndarray of int64
            Codes of node-to-face keys.

        Returns
        -------
        slave, face : numpy.ndarray of int64
            The key's slave and the boundary face on its master's vertices.

        Raises
        ------
        ValueError
            On a negative code (an edge key, or -1: no key).
        """
        codes = np.asarray(codes, dtype=np.int64)
        if np.any(codes < 0):
            raise ValueError("FaceKeys.faces_of: a negative code is no node-to-face key")
        if self._face_of_set is None:
            self._face_of_set = np.zeros(self.n, dtype=np.int64)
            self._face_of_set[self.face_set] = np.arange(len(self.face_set))
        slave, sets = np.divmod(codes, self.n)
        return slave, self._face_of_set[sets]

    def edge_codes(self, pairs):
        """The codes of edge-to-edge keys given as pairs (i, j), i < j, of edge numbers.

        Parameters
        ----------
        pairs : numpy.ndarray of int, shape (m, 2)

        Returns
        -------
        numpy.ndarray of int64
        """
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        return -1 - (pairs[:, 0] * len(self.edges) + pairs[:, 1])

    def node_edge_codes(self, slave, edge):
        """The codes of node-to-edge keys ("n", v, b0, b1).

        Parameters
        ----------
        slave : array_like of int, shape (m,)
            The vertices v.
        edge : array_like of int, shape (m, 2)
            Their edges (b0, b1), sorted boundary edges of the mesh or a corner twice.

        Returns
        -------
        numpy.ndarray of int64
            -1 where ``edge`` is neither.
        """
        slave = np.asarray(slave, dtype=np.int64)
        b = np.asarray(edge, dtype=np.int64).reshape(-1, 2)
        ne, nb = len(self.edges), self.nb
        # the edges are sorted (rows increasing): their codes b0 nb + b1 increase
        key = self.edges[:, 0] * nb + self.edges[:, 1]
        at = np.minimum(np.searchsorted(key, b[:, 0] * nb + b[:, 1]), max(ne - 1, 0))
        found = (key[at] == b[:, 0] * nb + b[:, 1]) if ne else np.zeros(len(b), dtype=bool)
        j = np.where(b[:, 0] == b[:, 1], ne + b[:, 0], np.where(found, at, -1))
        valid = (j >= 0) & (b.min(axis=1, initial=0) >= 0) & (b.max(axis=1, initial=0) < nb) \
            & (slave >= 0) & (slave < nb)
        return np.where(valid, -2 - ne * ne - (slave * (ne + nb) + j), -1)

    def is_node_edge(self, codes):
        """Which codes are of node-to-edge keys.

        Parameters
        ----------
        codes : numpy.ndarray of int64

        Returns
        -------
        numpy.ndarray of bool
        """
        return np.asarray(codes, dtype=np.int64) <= -2 - len(self.edges) ** 2

    def decode(self, codes):
        """The key tuples ("f", slave, master vertices sorted; "e", edge a, edge b; "n", vertex,
        edge) of codes.

        Parameters
        ----------
        codes : numpy.ndarray of int64

        Returns
        -------
        list of tuple

        Raises
        ------
        ValueError
            On a negative code that is no pair of edges i < j (such as -1, no key).
        """
        codes = np.asarray(codes, dtype=np.int64)
        slave, sets = np.divmod(np.maximum(codes, 0), self.n)
        keys = [("f", s, a, b, c) for s, (a, b, c) in zip(slave.tolist(), self.triples[sets].tolist())]
        ne = len(self.edges)
        node = np.flatnonzero(self.is_node_edge(codes))
        if len(node):
            v, j = np.divmod(-2 - ne * ne - codes[node], ne + self.nb)
            b = np.repeat((j - ne)[:, None], 2, axis=1)                 # a corner twice
            b[j < ne] = self.edges[j[j < ne]]
            for r, s, (b0, b1) in zip(node.tolist(), v.tolist(), b.tolist()):
                keys[r] = ("n", s, b0, b1)
        edge = np.flatnonzero((codes < 0) & (codes > -2 - ne * ne))
        if len(edge):
            i, j = np.divmod(-1 - codes[edge], max(len(self.edges), 1))
            if not np.all((i < j) & (j < len(self.edges))):
                raise ValueError("FaceKeys.decode: a negative code that is no pair of edges (-1 is no key)")
            for r, a, b in zip(edge.tolist(), self.edges[i].tolist(), self.edges[j].tolist()):
                keys[r] = ("e", a[0], a[1], b[0], b[1])
        return keys


def vertex_fragments(nv, tets, fragment):
    """The fragment of every vertex (-1: in no tetrahedron).

    Parameters
    ----------
    nv : int
        Number of vertices.
    tets : numpy.ndarray of int, shape (ne, 4)
    fragment : numpy.ndarray of int, shape (ne,)

    Returns
    -------
    numpy.ndarray of int64, shape (nv,)
        A vertex in tetrahedra of several fragments gets the last one's.

    Raises
    ------
    ValueError
        Naming ``tets`` (not of shape (ne, 4), a vertex number outside [0, nv)) or
        ``fragment`` (not one per tetrahedron).
    """
    # C++ (cpp_ext/contact_setup3d.cpp): the numpy scatter
    # full(nv, -1)[tets.ravel()] = repeat(fragment, 4), the last tetrahedron's fragment
    # kept (tests/test_contact3d_setup_pairs.py compares)
    return _ext.VertexFragments(int(nv), np.asarray(tets, dtype=np.int64).reshape(-1, 4),
                                np.asarray(fragment, dtype=np.int64))


def fixed_rows(points, faces, vertex_fragment, codec, detector, index):
    """The rows a 3D contact solve keeps as candidates throughout, from the mesh's set-up.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates.
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary faces, outward.
    vertex_fragment : numpy.ndarray of int64, shape (nv,)
        :func:`vertex_fragments`.
    codec : FaceKeys
    detector : ngfracture.contact.collision3d.PenetrationDetector3d
    index : ngfracture.contact.kinks3d.CopyIndex

    Returns
    -------
    rows : NodeToFaceRows
        The pairs touching in the reference configuration (sorted by vertex and fragment),
        then the twin rows of every fragment's vertices, then the lip rows.
    keys : RowKeys
        Their keys, without repeats (a repeated key keeps its first row).
    """
    touching = node_to_face_rows(points, faces, detector.detect())
    rows = NodeToFaceRows.stack([touching, fragment_pair_rows(points, faces, vertex_fragment, index=index),
                                 lip_rows(points, faces, vertex_fragment, index=index)])
    codes = codec.codes(rows)
    first = np.sort(np.unique(codes, return_index=True)[1])
    return rows.subset(first), RowKeys(codes[first], codec)


class MeshSetup3d:
    """The mesh-only work of a 3D contact solve (see the module docstring).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates.
    tets : array_like of int, shape (ne, 4)
    faces : array_like of int, shape (nf, 3)
        Boundary faces, outward.
    fragment : array_like of int, shape (ne,)
        Fragment number per tetrahedron.

    Attributes
    ----------
    points, tets, faces, fragment : numpy.ndarray
        Copies of the arrays (their dtypes kept), which :meth:`fits` compares with.
    codec : FaceKeys
    detector : ngfracture.contact.collision3d.PenetrationDetector3d
    edge_detector : ngfracture.contact.edge_crossings3d.EdgeCrossingDetector
    faces_at_edge : numpy.ndarray of int64, shape (nE, 2)
        The two faces at every boundary edge (:func:`~ngfracture.contact.edge_rows3d.two_faces`).
    partners : tuple of numpy.ndarray
        Every copy's partner faces at its other copies
        (:func:`~ngfracture.contact.copies3d.partner_incidences`).
    diagonal_edges : ngfracture.contact.wedges3d.DiagonalEdges
        The copies of junction edges on fragments that share no face there
        (:func:`~ngfracture.contact.wedges3d.diagonal_edges`).
    edge_copies : ngfracture.contact.wedges3d.EdgeCopies
        The pairs of copies of a boundary edge with a face of one that is no partner face
        of the other (:func:`~ngfracture.contact.wedges3d.edge_copies`).
    copy_index : ngfracture.contact.kinks3d.CopyIndex
    vertex_fragment : numpy.ndarray of int64
    rows : NodeToFaceRows
        The fixed rows in the reference configuration (:func:`fixed_rows`).
    keys : RowKeys
        Their keys.
    covered : numpy.ndarray of int64
        The (vertex, fragment) pairs they cover (:func:`~ngfracture.contact.junctions3d.covered_pairs`).

    Raises
    ------
    ValueError
        On inconsistent arrays (see :func:`~ngfracture.contact.collision3d.detect_penetrations_3d`).
    """

    def __init__(self, points, tets, faces, fragment):
        self.points, self.tets, self.faces, self.fragment = (np.array(a) for a in (points, tets, faces, fragment))
        self.detector = PenetrationDetector3d(self.points, self.tets, self.faces, self.fragment)   # checks
        self.vertex_fragment = vertex_fragments(len(self.points), self.tets, self.fragment)
        self.copy_index = CopyIndex(self.points, self.faces)
        self.edge_detector = EdgeCrossingDetector(self.points, self.faces,
                                                  self.vertex_fragment[np.asarray(self.faces, dtype=np.int64)[:, 0]],
                                                  across=True, point=self.copy_index.point)
        self.faces_at_edge = two_faces(self.edge_detector.edge_face_ptr, self.edge_detector.edge_faces)
        self.partners = partner_incidences(self.copy_index, self.vertex_fragment)
        self.diagonal_edges = diagonal_edges(self.edge_detector.edges, self.faces_at_edge, self.vertex_fragment,
                                             self.copy_index)
        self.edge_copies = edge_copies(self.edge_detector.edges, self.faces_at_edge, self.copy_index)
        self.codec = FaceKeys(self.faces, self.edge_detector.edges)
        self.rows, self.keys = fixed_rows(self.points, self.faces, self.vertex_fragment, self.codec,
                                          self.detector, self.copy_index)
        self.covered = covered_pairs(self.points, self.rows, self.vertex_fragment)

    def fits(self, points, tets, faces, fragment):
        """Whether the arrays are bitwise those this set-up was made from.

        Dtypes, shapes and bytes are compared (a -0.0 for a 0.0 differs).

        Parameters
        ----------
        points, tets, faces, fragment : array_like
            As for the constructor.

        Returns
        -------
        bool
        """
        return all(_same_bits(np.asarray(a), b) for a, b in ((points, self.points), (tets, self.tets),
                                                             (faces, self.faces), (fragment, self.fragment)))


def _same_bits(a, b):
    """Whether two arrays have one dtype, one shape and the same bytes."""
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    a, b = np.ascontiguousarray(a).reshape(-1).view(np.uint8), np.ascontiguousarray(b).reshape(-1).view(np.uint8)
    if len(a) % 8 == 0:                 # the same bytes, compared 8 at a time
        a, b = a.view(np.int64), b.view(np.int64)
    return np.array_equal(a, b)


class MeshSetups:
    """The :class:`MeshSetup3d` of the last mesh a solve asked for, reused while it fits.

    The owner of the solves of a run (``run.step.LoadStep``) keeps one and gives it to every
    contact solve (``ContactSolver(..., setups=...)``): solves on one mesh share one set-up,
    a solve on another mesh (or on arrays changed in place) gets a new one, which replaces
    the old. Results do not depend on whether the set-up came from here.

    Attributes
    ----------
    made : int
        Set-ups made so far (a solve whose set-up was reused adds none).
    """

    def __init__(self):
        self._last = None
        self.made = 0

    def setup(self, points, tets, faces, fragment):
        """The set-up of these arrays: the last one where it fits them, else a new one.

        Parameters
        ----------
        points, tets, faces, fragment : array_like
            As for :class:`MeshSetup3d`.

        Returns
        -------
        MeshSetup3d
        """
        last = self._last
        if last is None or not last.fits(points, tets, faces, fragment):
            last = MeshSetup3d(points, tets, faces, fragment)
            self._last = last
            self.made += 1
        return last
