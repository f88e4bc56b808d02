"""Boundary edges of the fragments of a tetrahedral mesh that cross each other (3D).

Node-to-face detection (:mod:`ngfracture.contact.collision3d`) finds a vertex of one
fragment inside another. Two fragments can also interpenetrate with no vertex inside the
other: two convex edges (ridges) pushed across each other, or a ridge pushed into a flat
face. This module finds the pairs of boundary edges that did so, for edge-to-edge rows.
Everything works on the boundary faces in the convention of
:mod:`ngfracture.geometry.solid` (outward triangles; crack lips are coincident faces whose
vertices are distinct copies at bitwise-equal reference points) and a fragment number per
face. Fragments share no vertex (a vertex on faces of two fragments is refused).

Definitions (exact ``orient3d``, no tolerance):

- Edge e *pierces* face f when f shares no point with e (a vertex, or a copy of one at the
  bitwise-equal reference point), e's endpoints lie strictly on opposite sides of f's
  plane, and e's line passes strictly inside the triangle: ``orient3d(e0, e1, f_k,
  f_k+1)`` has the same nonzero sign for the three edges of f.
- Edges a and b *interlock* when a pierces a face f that has b as an edge, b pierces a
  face g that has a as an edge, and f and g are of different fragments or, on one fragment
  (the two lips of a crack that does not cut its fragment through), share no point.
  With ``across``, only pairs of different fragments are searched.

Copies of a point count as one point: an edge and a face at copies of one point meet there
as an edge and a face at one vertex do, and where the lips slid along each other their
crossing next to that point is the business of the rows at copies, not of edge rows
(docs/contact.md, "Edge-to-edge rows in 3D").

The pairs reported are these, but those of two edges that are not swept (below). Two
convex ridges that crossed pierce the faces at each other; a flat face pushed onto a
ridge: the ridge's edge and an edge of the face interlock. A fragment's corner poked into
the interior of another's face is no such pair (its edges pierce the face, but the face's
edges pierce none of the corner's faces): node-to-face rows hold it. Coincident lips never
pierce (the signs are strict), so an intact body or a closed crack reports nothing, and
nor do faces that slide over each other in their common plane.

Search, O(n) expected (``cpp_ext/edge_crossings3d.cpp``). The cells are those of the faces'
bounding boxes: the mean largest extent of a box (doubled while the boxes would fill more
than 32 n + 2^20 cells, so that a few huge faces among small ones cost time, not memory).
The boxes of the edges swept are hashed into them (a spatial hash: a counting sort of the
cells' hashes) and every face visits the cells its box overlaps; a pair (edge, face) is
tested once, in the first cell the two boxes share, when they share no point and their
boxes overlap strictly (a
pierce point lies strictly inside both: boxes that only touch cannot hold one). Then the
exact pierce test, and for every piercing (a, f) the three edges b of f against the faces
at a. A pair is found from the sweep of either of its edges (a pierces a face at b and b
one at a), so edges whose two ends lie bitwise at the current position of a copy (closed
lips) and edges at ``skip`` vertices are not swept; a pair of two such edges is not found.
The edges and the faces at each are made once per mesh. Output: sorted, unique pairs,
deterministic.
"""
import numpy as np

from .. import _ngfracture as _ext
from .kinks3d import point_ids

__all__ = ["EdgeCrossingDetector", "segment_pierces_triangle"]


def _coordinates(p, name, nv=None):
    p = np.asarray(p)
    if p.ndim != 2 or p.shape[1] != 3 or (nv is not None and p.shape[0] != nv):
        rows = "n" if nv is None else str(nv)
        raise ValueError(f"{name} must have shape ({rows}, 3), got {p.shape}")
    if not np.issubdtype(p.dtype, np.number) or np.iscomplexobj(p):
        raise ValueError(f"{name} must hold real numbers, got dtype {p.dtype}")
    p = np.ascontiguousarray(p, dtype=np.float64)
    if not np.isfinite(p).all():
        raise ValueError(f"{name} contains NaN or inf")
    return p


def _integers(a, name, shape):
    a = np.asarray(a)
    if a.ndim != len(shape) or any(s is not None and a.shape[k] != s for k, s in enumerate(shape)):
        want = ", ".join("n" if s is None else str(s) for s in shape)
        raise ValueError(f"{name} must have shape ({want}{',' if len(shape) == 1 else ''}), got {a.shape}")
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{name} must hold integers, got dtype {a.dtype}")
    if a.size and (a.min() < np.iinfo(np.int32).min or a.max() > np.iinfo(np.int32).max):
        raise ValueError(f"{name} holds numbers outside the int32 range")
    return np.ascontiguousarray(a, dtype=np.int32)


def segment_pierces_triangle(p, q, a, b, c):
    """Exact test: the segment pq pierces the triangle abc.

    Parameters
    ----------
    p, q : array_like, shape (3,)
        The segment's endpoints.
    a, b, c : array_like, shape (3,)
        The triangle's corners.

    Returns
    -------
    bool
        p and q lie strictly on opposite sides of the triangle's plane and the line pq
        passes strictly inside the triangle (exact ``orient3d``).

    Raises
    ------
    ValueError
        If a point is not 3 finite numbers.
    """
    pts = [_coordinates(np.reshape(v, (1, -1)), name)[0] for name, v in zip("pqabc", (p, q, a, b, c))]
    return bool(_ext.SegmentPiercesTriangle(*pts))


class EdgeCrossingDetector:
    """Pairs of boundary edges of a tetrahedral mesh's fragments that interlock (cross).

    The boundary edges and the faces at each are made once, in C++, on copies of the
    arrays given here (later changes to them do not reach the detector); :meth:`detect`
    finds the interlocking pairs at any displacement (module docstring: the rules).

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates.
    faces : array_like of int, shape (nf, 3)
        Boundary triangles, outward (outer boundary and crack lips).
    face_fragment : array_like of int, shape (nf,)
        The fragment of every face.
    across : bool
        Only pairs of edges of different fragments (no lips of one fragment's crack).
    point : array_like of int, shape (nv,), optional
        :func:`~ngfracture.contact.kinks3d.point_ids` of these points and faces, where the
        caller has them.

    Attributes
    ----------
    edges : numpy.ndarray of int64, shape (nE, 2)
        The distinct boundary edges, each row increasing, rows in lexicographic order.
    edge_face_ptr, edge_faces : numpy.ndarray of int64
        CSR of the faces at every edge: the faces at edge e are
        ``edge_faces[edge_face_ptr[e]:edge_face_ptr[e + 1]]``, increasing.
    face_edges : numpy.ndarray of int64, shape (nf, 3)
        The edges (f0, f1), (f1, f2), (f2, f0) of every face, as rows of ``edges``.

    Raises
    ------
    ValueError
        Naming the array: a wrong shape or type, non-finite points, a vertex number out of
        range, a face that repeats a vertex, a vertex on faces of two fragments.
    """

    def __init__(self, points, faces, face_fragment, across=False, point=None):
        X = _coordinates(points, "points")
        F = _integers(faces, "faces", (None, 3))
        frag = _integers(face_fragment, "face_fragment", (len(F),))
        self._points = X.copy()
        if len(F) and (F.min() < 0 or F.max() >= len(X)):
            raise ValueError(f"faces holds vertex numbers outside [0, {len(X)})")
        # copies of a point count as that point
        point = (point_ids(X, F) if point is None else _integers(point, "point", (len(X),))).astype(np.int32)
        self._kernel = _ext.EdgeCrossingDetector3d(len(X), F, frag, point, bool(across))
        self.edges = self._kernel.edges
        self.edge_face_ptr = self._kernel.edge_face_ptr
        self.edge_faces = self._kernel.edge_faces
        self.face_edges = self._kernel.face_edges

    def detect_counted(self, displacement=None, skip=None):
        """The interlocking pairs at points + displacement, with the search's counts.

        Parameters
        ----------
        displacement : array_like, shape (nv, 3), optional
            Zero if omitted.
        skip : array_like of bool, shape (nv,), optional
            As for :meth:`detect`.

        Returns
        -------
        pairs : numpy.ndarray of int64, shape (m, 2)
            As :meth:`detect`.
        stats : dict
            ``cell`` (grid cell size), ``box_tests`` (pairs (edge, face) without a shared
            vertex in a common cell), ``exact_tests`` (past the strict box test),
            ``pierces`` (pairs (edge, face) that pierce), ``closed_edges`` (edges not swept:
            both ends bitwise at the current position of a copy), ``skipped_edges`` (not
            swept: an end in ``skip``).

        Raises
        ------
        ValueError
            On a displacement of the wrong shape or with non-finite entries.
        """
        x = self._points
        if displacement is not None:
            x = np.ascontiguousarray(x + _coordinates(displacement, "displacement", len(x)))
            if not np.isfinite(x).all():
                raise ValueError("points + displacement overflows")
        if skip is not None:
            skip = np.asarray(skip)
            if skip.shape != (len(x),) or skip.dtype != bool:
                raise ValueError(f"skip must be booleans of shape ({len(x)},), got {skip.dtype} {skip.shape}")
            skip = skip.view(np.uint8)
        return self._kernel.detect(x, skip)

    def detect(self, displacement=None, skip=None):
        """The pairs of edges that interlock at points + displacement.

        Parameters
        ----------
        displacement : array_like, shape (nv, 3), optional
            Zero if omitted.
        skip : array_like of bool, shape (nv,), optional
            Vertices whose edges are not swept. Every pair is found from either edge's
            sweep, and an edge whose two ends lie bitwise at the current position of a copy
            (a closed lip) is never swept: a pair of two edges not swept (at ``skip``
            vertices or on closed lips) is not found.

        Returns
        -------
        numpy.ndarray of int64, shape (m, 2)
            Pairs (i, j), i < j, of rows of :attr:`edges`; unique, in lexicographic order.

        Raises
        ------
        ValueError
            On a displacement of the wrong shape or with non-finite entries.
        """
        return self.detect_counted(displacement, skip)[0]
