"""Collision detection between the fragments of a tetrahedral mesh (3D, paper section 3.1).

The 3D analogue of :mod:`ngfracture.contact.collision`, and the first building block of
3D contact: it finds the slave vertices and their master triangles; the contact rows are
not built here. Everything works on plain arrays in the convention of
:mod:`ngfracture.geometry.solid` (tets positively oriented, boundary faces pointing out of
the body, crack lips as coincident faces whose vertices are bitwise-equal copies), plus a
fragment number per tetrahedron (:func:`ngfracture.fracture.fragments.fragment_ids`).

What is found. A *penetration* is a pair (boundary vertex v of fragment A, fragment
F != A) with v, at its current position, in the closed volume of F: in some closed
tetrahedron of F; or F = A for a lip vertex (below). The closed test makes touching (a vertex on F's surface) a candidate
with gap 0 instead of nothing, so contact can be activated at zero gap, as the 2D
precision threshold does; pairs with gap < 0 are the penetrations proper. Fragments must
not share vertices (a vertex in tetrahedra of two fragments is refused).

Self-contact across a crack. The lips of a crack that does not cut its fragment through
are on one fragment. A *lip vertex* (a boundary vertex with a copy, at the bitwise-equal
reference point, on its own fragment) is also tested against the tetrahedra of its own
fragment that are not at the vertex, and the pair (v, own fragment) is reported like a
pair across fragments, its masters the faces of the fragment not at v. A lip vertex of a
closed crack lies in such a tetrahedron only on the other lip at its copy (a closed seam,
left out below), so an intact or closed body reports nothing. Other boundary vertices are
not tested against their own fragment: they lie in no tetrahedron of it but their own
while the tetrahedra stay positive, unless the body folds onto itself (not searched).

Predicate. Point-in-tetrahedron uses the exact ``orient3d`` (sign of det[a-d, b-d, c-d];
a positively oriented tetrahedron gives -1): the point is in the closed tetrahedron iff
replacing any vertex by the point never flips the tetrahedron's sign. ``orient3d`` is
adaptive like ``orient2d``: a floating-point filter with Shewchuk's bound (7 + 56 eps) eps
times the permanent decides almost every call; then, if the nine coordinate differences
are exact, the 24 exact triple products of the differences; else the 96-term expansion of
the 4 x 4 determinant [[a, 1], [b, 1], [c, 1], [d, 1]]. Exact barring overflow and
underflow of products (coordinates in about [1e-100, 1e100] or zero). "On a face" is
exact too: orient3d = 0 and, in a coordinate plane where the triangle is not degenerate
(dropping a coordinate keeps orientation signs of coplanar points), three orient2d >= 0.

Search, O(n) expected. One cell size h, the mean largest extent of a tetrahedron's
bounding box. The boundary vertices are hashed into cells of h; every tetrahedron sweeps
the cells its bounding box overlaps (about 8 for h of the element size) and the vertices
there of other fragments that pass the box test get the exact test. Memory and time are
linear in the numbers of tetrahedra and boundary vertices for bounded cell occupancy
(a few huge tetrahedra among small ones make them sweep many cells, correctly but slowly).
Up to 2^22 cells the grid is an array of ranges over all cells, filled by a counting sort
(a lookup is an index); beyond, a hash map of the occupied cells. The tetrahedra are
swept in increasing order, so the first one holding a pair (vertex, fragment) is the
smallest, and later tetrahedra of that fragment do not test the pair again. Closed seams
are decided before the sweep; a cell whose vertices are all decided for the fragments
of its vertices (and none is a lip vertex) is skipped by the tetrahedra of those fragments,
and a tetrahedron whose cells all lie in blocks of 2 x 2 x 2 cells closed for its fragment
(every non-empty cell there so skipped) is not swept cell by cell; its cells are read from
its vertices' cells (the cell of a coordinate does not decrease with it). A fragment
whose box of cells holds only empty cells and cells closed for it is not swept at all.

Master face. For a pair whose vertex lies in a tetrahedron at its copy t on F (a crack
lip, or where several cracks meet): among the boundary faces of that tetrahedron at t,
those whose plane has v's reference star (the vertices of v's tetrahedra) on its outer
side, the one v is least deep behind (largest signed distance n . (x_v - x_t)); gap minus
that depth (0 if v is not behind it), the projection the nearest point of the face. These
are the faces v's wedge can have crossed: the lip between the two copies, or, where three
or more copies meet, the lip of t towards a third copy that v slid past; not a face of t
that v's wedge lies across (the side face that the edge of a lip pushed across the crack
lies on). If no face passes that test and two or more copies of the point lie on F (a
crack inside F, or a junction of cracks inside F), the lip of that tetrahedron at t (a
face with another boundary face on its three points) that v is least deep behind, if v is
behind one: there v's wedge can lie across the plane of the lip it crossed into t's
wedge, and the nearest face is the coincident lip at another copy, which v is in front of
(the coarse confined sphere at x = 2.70e-3: v 1.4e-5 behind the lip at t, reported
2.35e-5 deep on the lip at the third copy, whose row did not hold it; the coarse free
sphere's step after x = 1.931e-3, two copies on F: v 8.85e-6 behind the crack face at
t). Where t is F's only copy of the point, the same for the lips whose other side is on F
too: a crack of F that ends at t (its front through the point), into whose slit v can
slide and on across its other lip (the coarse random box of ``random_solids.draw(2,
coarse=True)``: a copy 1.8e-4 behind such a lip, the nearest face its coincident lip,
which v was in front of). If neither gives a face, the holding
tetrahedron has no boundary face at t and three or more copies lie on F (v slid past the
faces of the tetrahedra at t deeper into t's star where several cracks meet): the lip at
t, of any tetrahedron, that v is least deep behind, if v is behind one; the nearest face
of F can be one that v is in front of (the coarse free sphere at x = 1.660e-3: a copy at
a point of five copies on one fragment, 2.7e-5 in front of the nearest face, reported
3.6e-5 deep on it, and 2.2e-5 to 2.7e-5 behind faces at its copy; the row on the nearest
face did not hold it).
Else, in this order:

1. touching: a boundary face of F that holds v exactly (closed triangle, exact
   predicates) and whose outward normal does not point along v's normal (dot <= 0; v's
   normal is the area-weighted sum of the normals of its own boundary faces) or that is
   a *partner* face (at a copy of v on F, on the three points of one of v's own faces):
   gap 0 exactly, projection x_v itself;
2. else the boundary face of F nearest to v (Euclidean distance to the closed triangle)
   among those whose normal opposes v's (dot < 0) and the partner faces;
3. else the nearest face of F of any orientation.

Where several cracks meet, a copy's wedge can be bounded by faces that the averaged normal
of a neighbouring copy does not oppose: measured on the sphere scene, a lip copy within
5e-16 of the crack face of a small three-face wedge it had slid onto was reported 1.0e-5
deep, the distance to a face at another copy (docs/contact.md, "Points of several copies").

The orientation filter is the 3D form of the 2D rule 3 (angle between master and slave):
a vertex at the edge of a crack lip, pushed across the crack, lies exactly on the other
piece's side face (distance 0) but its master is the opposite lip, at the depth of the
penetration; a vertex of a box pushed 1/4 into another one is pushed back along the
overlap direction, not through side faces that are nearer but perpendicular to it. Faces
are hashed into the same cells (every cell their box overlaps) and searched ring by ring
of cells around v, until the best distance is at most r h after ring r (faces not seen
are farther). A cell farther from v than the best face so far is not searched: a face's
nearest point lies in its box, so in a cell it is hashed to, and a nearer face is in a
nearer cell (the bound is lowered by 1e-6 h for the rounding of the cell walls and
compared with a relative margin of 1e-9, so ties are still seen). Ties go to the smaller
face number. The gap is -|x_v - p| with p the
nearest point (0 in case 1); p, its barycentric coordinates on the face and the face's
unit normal are returned.

Seams. Where the splitting made copies of a vertex, v has a *twin* on F: a vertex with
the bitwise-equal reference point. A closed seam (twin at the bitwise-equal current
point) is not reported at all: as in 2D (:mod:`ngfracture.contact.seams`), coincident
lips are the business of node-to-node rows between twins, not of the node-to-face search
(whose master choice there would depend on rounding). Once the twins have moved apart and
v lies in F, the pair is reported with its twin, so the rows can use either.

Output order is deterministic: sorted by (vertex, fragment).
"""
from dataclasses import dataclass

import numpy as np

from .. import _ngfracture as _ext

__all__ = ["orient3d", "Penetrations3d", "detect_penetrations_3d", "PenetrationDetector3d"]


def _points(p, name):
    p = np.atleast_2d(np.asarray(p, dtype=np.float64))
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {p.shape}")
    if not np.isfinite(p).all():
        raise ValueError(f"{name} contains NaN or inf")
    return np.ascontiguousarray(p)


def orient3d(a, b, c, d):
    """Exact sign of det[a_i - d_i, b_i - d_i, c_i - d_i] for rows of points.

    Parameters
    ----------
    a, b, c, d : array_like, shape (n, 3) or (3,)
        Points.

    Returns
    -------
    numpy.ndarray of int8, shape (n,)
        +1, -1, or 0 if the four points are coplanar. A positively oriented tetrahedron
        (det[x1-x0, x2-x0, x3-x0] > 0) gives -1.

    Raises
    ------
    ValueError
        If shapes differ or a coordinate is not finite.
    """
    pts = [_points(p, name) for name, p in (("a", a), ("b", b), ("c", c), ("d", d))]
    if not all(p.shape == pts[0].shape for p in pts):
        raise ValueError("a, b, c and d must have the same shape")
    return _ext.Orient3d(*pts)


@dataclass
class Penetrations3d:
    """Boundary vertices in the closed volume of another fragment (one row per pair).

    Parameters
    ----------
    vertex : numpy.ndarray of int, shape (k,)
        The slave vertex.
    fragment : numpy.ndarray of int, shape (k,)
        The fragment it is in.
    tet : numpy.ndarray of int, shape (k,)
        The smallest-numbered tetrahedron of that fragment holding it (closed).
    face : numpy.ndarray of int, shape (k,)
        The master boundary face (row of ``faces``).
    twin : numpy.ndarray of int, shape (k,)
        The vertex's copy on that fragment (bitwise-equal reference point), or -1.
    projection : numpy.ndarray, shape (k, 3)
        The nearest point of the master face.
    bary : numpy.ndarray, shape (k, 3)
        Its barycentric coordinates on the face's vertices (in the face's order).
    normal : numpy.ndarray, shape (k, 3)
        The master face's unit outward normal.
    gap : numpy.ndarray, shape (k,)
        Minus the distance to the master face: 0 exactly for a vertex on it, < 0 inside.
    stats : dict
        Search counts: ``cell`` (cell size), ``boundary_vertices``, ``box_tests``,
        ``exact_tests``, ``closed_seams`` (pairs left out as closed seams).
    """
    vertex: np.ndarray
    fragment: np.ndarray
    tet: np.ndarray
    face: np.ndarray
    twin: np.ndarray
    projection: np.ndarray
    bary: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    stats: dict

    def __len__(self):
        return len(self.vertex)

    @property
    def penetrating(self):
        """Rows with a negative gap (touching vertices, gap 0, excluded).

        Returns
        -------
        numpy.ndarray of bool, shape (k,)
        """
        return self.gap < 0


def _indices(a, name, cols, n):
    a = np.asarray(a)
    if a.ndim != 2 or a.shape[1] != cols:
        raise ValueError(f"{name} must have shape (m, {cols}), got {a.shape}")
    if a.size and (a.min() < 0 or a.max() >= n):
        raise ValueError(f"{name} holds vertex numbers outside [0, {n})")
    return np.ascontiguousarray(a, dtype=np.int32)


def _mesh_arrays(points, tets, faces, fragment):
    """The mesh's arrays as the C++ detection takes them, after the checks of
    :func:`detect_penetrations_3d`."""
    X = _points(points, "points")
    T = _indices(tets, "tets", 4, len(X))
    F = _indices(faces, "faces", 3, len(X))
    frag = np.ascontiguousarray(fragment, dtype=np.int32)
    if frag.shape != (len(T),):
        raise ValueError(f"fragment must have shape ({len(T)},), got {frag.shape}")
    return X, T, F, frag


def _current(X, displacement):
    """The current positions X + displacement (X itself without a displacement)."""
    if displacement is None:
        return X
    U = _points(displacement, "displacement")
    if U.shape != X.shape:
        raise ValueError(f"displacement must have the shape of points {X.shape}, got {U.shape}")
    return np.ascontiguousarray(X + U)


def _penetrations(ids, geo, stats):
    """Penetrations3d of the C++ detection's output."""
    ids = np.asarray(ids, dtype=np.int64).reshape(-1, 5)
    geo = np.asarray(geo, dtype=np.float64).reshape(-1, 10)
    return Penetrations3d(vertex=ids[:, 0], fragment=ids[:, 1], tet=ids[:, 2], face=ids[:, 3],
                          twin=ids[:, 4], projection=geo[:, 0:3], bary=geo[:, 3:6],
                          normal=geo[:, 6:9], gap=geo[:, 9], stats=dict(stats))


def detect_penetrations_3d(points, tets, faces, fragment, displacement=None):
    """Boundary vertices of each fragment in the closed volume of another, with master faces.

    Lip vertices (with a copy on their own fragment) are also tested against the
    tetrahedra of their own fragment that are not at them: self-contact across a crack.

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Reference coordinates (copies made by splitting are bitwise equal).
    tets : array_like of int, shape (ne, 4)
        Tetrahedra (positively oriented in the reference configuration; inverted ones in
        the current configuration are tested with their own orientation, flat ones never
        hold a point).
    faces : array_like of int, shape (nf, 3)
        Boundary triangles, outward (outer boundary and crack lips).
    fragment : array_like of int, shape (ne,)
        Fragment number per tetrahedron.
    displacement : array_like, shape (nv, 3), optional
        Current position = points + displacement; zero if omitted.

    Returns
    -------
    Penetrations3d
        Sorted by (vertex, fragment); see the module docstring for the rules.

    Raises
    ------
    ValueError
        On wrong shapes, non-finite coordinates, vertex numbers out of range, a face that
        is no face of a tetrahedron, or a vertex in tetrahedra of two fragments.
    """
    X, T, F, frag = _mesh_arrays(points, tets, faces, fragment)
    return _penetrations(*_ext.DetectPenetrations3d(X, _current(X, displacement), T, F, frag))


class PenetrationDetector3d:
    """:func:`detect_penetrations_3d` for one mesh at many configurations.

    What depends only on the mesh (the fragment of every vertex and face, the boundary
    vertices, the tetrahedra at every vertex, the copies of every boundary vertex and the
    lip flags) is computed once, in C++, on copies of the arrays given here: later changes
    to those arrays do not reach it, so it cannot go stale. One is made per mesh
    (:class:`~ngfracture.contact.setup3d.MeshSetup3d`) and every round of every contact
    solve on the mesh detects with it. :meth:`detect` returns what :func:`detect_penetrations_3d` returns for the
    same arrays, bit for bit.

    Parameters
    ----------
    points, tets, faces, fragment
        As for :func:`detect_penetrations_3d`.

    Raises
    ------
    ValueError
        As :func:`detect_penetrations_3d` does for the mesh's arrays.
    """

    def __init__(self, points, tets, faces, fragment):
        X, T, F, frag = _mesh_arrays(points, tets, faces, fragment)
        self._points = X.copy()
        self._kernel = _ext.PenetrationDetector3d(X, T, F, frag)

    def detect(self, displacement=None):
        """The penetrations at points + displacement (:func:`detect_penetrations_3d`).

        Parameters
        ----------
        displacement : array_like, shape (nv, 3), optional
            Zero if omitted.

        Returns
        -------
        Penetrations3d

        Raises
        ------
        ValueError
            On a displacement of the wrong shape or with non-finite entries.
        """
        return _penetrations(*self._kernel.detect(_current(self._points, displacement)))
