"""Local refinement: bisection of the triangles near given points down to a target size.

The mesh is refined by NGSolve's bisection (``Mesh.SetRefinementFlags`` and ``Refine``) on
a copy rebuilt from its arrays, without geometry: a new vertex is the midpoint of an edge
of the mesh before, on a curved boundary too (its polygon is the body). So

* a P1 field carries over exactly: a new vertex takes the mean of its edge's ends, and
  the field on the finer mesh is the same function (:attr:`Refinement.prolongation`);
* boundary names, regions and crack faces survive (a bisected boundary segment keeps its
  name); the reference area changes only by the rounding of the boundary midpoints,
  checked against :data:`AREA_ROUNDING`;
* the two lips of a crack stay twins, vertex for vertex: where bisection split one lip's
  segment and not its twin, the twin's triangle is bisected in another round (crack tips
  are found by the copies of a vertex at bitwise the same point, and a midpoint of two
  equal segments is bitwise equal).

Which triangles: those whose longest edge exceeds ``h`` and that come within ``radius``
of a centre. Rounds repeat until none is left or :data:`MAX_ROUNDS`.
"""
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .._ngfracture import ElementAreas
from .meshio import mesh_from_arrays, mesh_to_arrays

__all__ = ["MAX_ROUNDS", "AREA_ROUNDING", "Refinement", "refine_near", "sharp_vertices", "reference_area"]

#: bisection rounds at most per refinement (each halves the marked triangles' area)
MAX_ROUNDS = 16
#: the largest change of the reference area a refinement may make, relative (rounding of midpoints)
AREA_ROUNDING = 1e-13
#: the corner angle inside the body from which a boundary vertex is a sharp tip (as the criterion's)
SHARP_ANGLE = math.radians(300.0)


@dataclass
class Refinement:
    """A refined mesh and how vertex fields carry over to it.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The refined mesh; the old vertices keep their numbers, new ones follow.
    prolongation : scipy.sparse.csr_matrix
        (nv_new, nv_old): a vertex field ``f`` is ``prolongation @ f`` on the new mesh.
    rounds : int
        Bisection rounds made.
    area : float
        The refined mesh's reference area (:func:`reference_area`).
    """
    mesh: object
    prolongation: sp.csr_matrix
    rounds: int
    area: float

    def transfer(self, values):
        """A vertex field on the refined mesh: the P1 interpolant, exact for a P1 field.

        Parameters
        ----------
        values : array_like (nv_old, ...)

        Returns
        -------
        numpy.ndarray (nv_new, ...)
        """
        values = np.asarray(values, dtype=float)
        flat = values.reshape(values.shape[0], -1)
        return (self.prolongation @ flat).reshape((self.prolongation.shape[0],) + values.shape[1:])


def reference_area(mesh):
    """``math.fsum`` of the reference triangle areas, as the area invariant measures it
    (:class:`ngfracture.fracture.fragments.FragmentStatistics`).

    Parameters
    ----------
    mesh : ngsolve.Mesh

    Returns
    -------
    float
    """
    return math.fsum(ElementAreas(mesh))


def _edge_keys(triangles, nv):
    """One integer per triangle edge (all three edges of every triangle, in that order):
    the sorted vertex pair as ``low * nv + high``."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    return edges[:, 0].astype(np.int64) * nv + edges[:, 1]


def sharp_vertices(arrays):
    """Boundary vertices whose corner angle inside the body is at least 300 degrees.

    Crack tips (360 degrees) and sharp notch tips: where the criterion measures its
    critical distance from.

    Parameters
    ----------
    arrays : MeshArrays

    Returns
    -------
    numpy.ndarray of int
    """
    p, t = arrays.points, arrays.triangles
    angle = np.zeros(len(p))
    for i in range(3):
        a, b, c = t[:, i], t[:, (i + 1) % 3], t[:, (i + 2) % 3]
        u, v = p[b] - p[a], p[c] - p[a]
        np.add.at(angle, a, np.abs(np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], (u * v).sum(axis=1))))
    # on the boundary: on an edge of one triangle only (an inner named line is no boundary);
    # a 1D unique of integer keys is six times faster than np.unique(axis=0)
    unique, count = np.unique(_edge_keys(t, len(p)), return_counts=True)
    once = unique[count == 1]
    on_boundary = np.zeros(len(p), dtype=bool)
    on_boundary[once // len(p)] = True
    on_boundary[once % len(p)] = True
    return np.flatnonzero(on_boundary & (angle >= SHARP_ANGLE))


def _marked(arrays, tree, radius, h):
    """Triangles longer than h that come within radius of a centre."""
    p, t = arrays.points, arrays.triangles
    edges = np.stack([p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 1]], p[t[:, 0]] - p[t[:, 2]]], axis=1)
    longest = np.hypot(edges[..., 0], edges[..., 1]).max(axis=1)
    distance, _ = tree.query(p[t].mean(axis=1))
    return (longest > h) & (distance - longest <= radius)


def _segment_keys(arrays):
    """Each boundary segment as the unordered pair of its end points' coordinates (x, y, x, y)."""
    p, seg = arrays.points, arrays.segments
    a, b = p[seg[:, 0]], p[seg[:, 1]]
    first = (a[:, 0] < b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] <= b[:, 1]))
    lo, hi = np.where(first[:, None], a, b), np.where(first[:, None], b, a)
    return [tuple(k) for k in np.hstack([lo, hi]).tolist()]


def _twin_keys(arrays):
    """The keys of the boundary segments that have a twin (the two lips of a crack)."""
    seen, twins = set(), set()
    for k in _segment_keys(arrays):
        (twins if k in seen else seen).add(k)
    return twins


def _segment_triangles(arrays):
    """The triangle of every boundary segment."""
    t, seg, nv = arrays.triangles, arrays.segments, len(arrays.points)
    keys = _edge_keys(t, nv)
    owner = np.tile(np.arange(len(t)), 3)
    order = np.argsort(keys, kind="stable")
    wanted = np.sort(seg, axis=1).astype(np.int64) @ np.array([nv, 1])
    return owner[order[np.searchsorted(keys[order], wanted)]]


def _broken_twins(arrays, twins):
    """Flags of the triangles of lip segments whose twin was split and they not."""
    keys = _segment_keys(arrays)
    count = {}
    for k in keys:
        count[k] = count.get(k, 0) + 1
    lone = np.array([k in twins and count[k] == 1 for k in keys], dtype=bool)
    marked = np.zeros(len(arrays.triangles), dtype=bool)
    if lone.any():
        marked[_segment_triangles(arrays)[lone]] = True
    return marked


def refine_near(mesh, centres, radius, h, reach=None, max_rounds=MAX_ROUNDS, arrays=None):
    """Bisect the triangles near some points until none near them is longer than h.

    With ``reach`` < ``radius`` the refinement happens only when a triangle within
    ``reach`` of a centre is too long, and then covers ``radius``: a tip that advances
    triggers it once per ``radius - reach`` of travel, not at every step.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        A 2D triangle mesh (reference configuration).
    centres : array_like (k, 2)
        Points to refine around.
    radius : float
        Triangles that come within this distance of a centre are refined.
    h : float
        Target length of their longest edge.
    reach : float, optional
        Refine only when a triangle within this distance needs it (default: ``radius``).
    max_rounds : int
    arrays : MeshArrays, optional
        The mesh as arrays, if the caller has them.

    Returns
    -------
    Refinement or None
        None when no triangle needs it.

    Raises
    ------
    ValueError
        Bad radius or h; a refinement that changed the reference area by more than rounding.
    """
    if not (np.isfinite(radius) and radius >= 0 and np.isfinite(h) and h > 0):
        raise ValueError(f"refine_near: radius must be >= 0 and h > 0, got radius={radius!r}, h={h!r}")
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    if len(centres) == 0:
        return None
    arrays = mesh_to_arrays(mesh) if arrays is None else arrays
    tree = cKDTree(centres)
    if reach is not None and reach < radius and not _marked(arrays, tree, reach, h).any():
        return None
    area_before = reference_area(mesh)
    prolongation, rounds = None, 0
    current = mesh_from_arrays(arrays)
    for _ in range(max_rounds):
        twins = _twin_keys(arrays)
        flags = _marked(arrays, tree, radius, h)
        if not flags.any():
            break
        nv = current.nv
        current.SetRefinementFlags(flags.tolist())
        current.Refine()
        # lips kept twins: bisect the twin of every lip segment one side split
        arrays = mesh_to_arrays(current)
        for _ in range(max_rounds):
            lone = _broken_twins(arrays, twins)
            if not lone.any():
                break
            current.SetRefinementFlags(lone.tolist())
            current.Refine()
            arrays = mesh_to_arrays(current)
            twins = twins | _twin_keys(arrays)
        step = _midpoint_matrix(current, nv)
        prolongation = step if prolongation is None else step @ prolongation
        rounds += 1
        current = mesh_from_arrays(arrays)      # no refinement hierarchy: a mesh like any other
    if rounds == 0:
        return None
    area = reference_area(current)
    if abs(area - area_before) > AREA_ROUNDING * area_before:
        raise ValueError(f"refine_near: the refinement changed the reference area from {area_before!r} to {area!r}")
    return Refinement(current, prolongation.tocsr(), rounds, area)


def _midpoint_matrix(refined, nv_before):
    """(nv, nv_before): identity on the old vertices, the mean of its two parents for a new one.

    A new vertex's parents may be new vertices of the same refinement: the substitution
    repeats until only old vertices are left (as many times as bisections were nested).
    """
    nv = refined.nv
    parents = np.array([refined.GetParentVertices(v) for v in range(nv_before, nv)], dtype=np.int64).reshape(-1, 2)
    new = np.arange(nv_before, nv)
    rows = np.concatenate([np.arange(nv_before), new, new])
    cols = np.concatenate([np.arange(nv_before), parents[:, 0], parents[:, 1]])
    vals = np.concatenate([np.ones(nv_before), np.full(2 * len(new), 0.5)])
    step = sp.csr_matrix((vals, (rows, cols)), shape=(nv, nv))
    P = step
    while P[:, nv_before:].nnz:
        P = P @ step
    return P[:, :nv_before].tocsr()
