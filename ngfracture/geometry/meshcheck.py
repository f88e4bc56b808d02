"""Is a mesh fit for ngfracture?  Bad meshes become a clear error before any work.

``validate_mesh(mesh)`` raises :class:`MeshError` (a ValueError) naming the first
offending vertex, edge or triangle, and warns (:class:`MeshQualityWarning`) about
poor but usable triangles.  ElasticProblem and crack_step call it on every mesh they
are given, so it is vectorised numpy, O(ne log ne): about 3% of one linear solve at
100k triangles (``benchmarks/meshcheck.py``).

What counts as a bad mesh
-------------------------
* not 2D (a 3D mesh, points with three coordinates), no vertices, no triangles,
  NaN or infinite coordinates;
* an unused vertex: no triangle refers to it (its dofs would have no stiffness);
* a triangle with zero area to rounding (``2|T| <= 16 eps * longest edge^2``, the sign of
  the area is then meaningless) or with clockwise vertices;
* non-manifold: an edge shared by more than two triangles, or a bow-tie vertex, whose
  triangles form two or more fans that meet only at that vertex (node splitting exists
  to remove them: the crack engine never makes one);
* two vertices at the same point, unless both lie on boundary segments.  Node splitting
  copies vertices (crack lips coincide in the reference configuration) and merged
  bodies may touch: both are boundaries with segments.  Coincident vertices off the
  boundary mean a body stitched from parts that do not share their vertices.

Not detected: triangles that overlap without sharing vertices (a fan folded over
itself), and near-coincident vertices (they make slivers, which are warned about).

A triangle whose aspect ratio (longest edge over smallest height, 1.15 for an equilateral
one) exceeds ``SLIVER_ASPECT`` gets a :class:`MeshQualityWarning`: assembly stays finite
but the stiffness is ill-conditioned.
"""
import warnings

import numpy as np
import ngsolve as ng

from .meshio import MeshArrays, mesh_to_arrays
from .solid import SolidArrays, is_solid, solid_to_arrays

#: aspect ratio (longest edge / smallest height) above which a triangle is warned about
SLIVER_ASPECT = 1e3


class MeshError(ValueError):
    """The mesh cannot be used: the message names the offending vertex, edge or triangle."""


class MeshQualityWarning(UserWarning):
    """The mesh is usable, but some triangles are so thin that the stiffness is ill-conditioned."""


def validate_mesh(mesh):
    """Check a 2D triangle mesh (or a 3D tetrahedral one, :func:`validate_solid`); return its arrays.

    Parameters
    ----------
    mesh : ngsolve.Mesh, MeshArrays or SolidArrays

    Returns
    -------
    MeshArrays or SolidArrays
        The arrays of the mesh (reused by the caller, so the check costs no extra copy).

    Raises
    ------
    MeshError
        On the first defect found (see the module docstring), naming it.

    Warns
    -----
    MeshQualityWarning
        If triangles have an aspect ratio above ``SLIVER_ASPECT``; names the worst ones.
    """
    if isinstance(mesh, SolidArrays) or (isinstance(mesh, ng.Mesh) and is_solid(mesh)):
        return validate_solid(mesh)
    arrays = _arrays(mesh)
    P = np.asarray(arrays.points, dtype=float)
    T = np.asarray(arrays.triangles, dtype=np.int64)
    S = np.asarray(arrays.segments, dtype=np.int64).reshape(-1, 2)
    if P.ndim != 2 or P.shape[1] != 2:
        raise MeshError(f"mesh: points must have 2 coordinates (a 2D mesh), got shape {P.shape}")
    nv = P.shape[0]
    if nv == 0:
        raise MeshError("mesh: the mesh is empty (no vertices)")
    if T.size == 0:
        raise MeshError(f"mesh: the mesh has {nv} vertices but no triangles")
    if T.ndim != 2 or T.shape[1] != 3:
        raise MeshError(f"mesh: triangles must be an (ne, 3) array, got shape {T.shape}")
    if T.min() < 0 or T.max() >= nv:
        i = int(np.flatnonzero((T < 0) | (T >= nv))[0] // 3)
        raise MeshError(f"mesh: triangle {i} has vertices {T[i].tolist()}, outside [0, {nv})")
    if S.size and (S.min() < 0 or S.max() >= nv):
        raise MeshError(f"mesh: a boundary segment has vertices outside [0, {nv})")
    bad = np.flatnonzero(~np.all(np.isfinite(P), axis=1))
    if bad.size:
        raise MeshError(f"mesh: vertex {bad[0]} has coordinates {P[bad[0]].tolist()}" + _more(bad))

    count = np.bincount(T.ravel(), minlength=nv)
    bad = np.flatnonzero(count == 0)
    if bad.size:
        raise MeshError(f"mesh: vertex {bad[0]} at {_xy(P[bad[0]])} belongs to no triangle" + _more(bad))

    cross, longest2 = cross_and_longest(P, T)
    zero = np.abs(cross) <= 16 * np.finfo(float).eps * longest2
    bad = np.flatnonzero(zero)
    if bad.size:
        raise MeshError(f"mesh: triangle {bad[0]} (vertices {_vs(T[bad[0]])}) has zero area" + _more(bad))
    bad = np.flatnonzero(cross < 0)
    if bad.size:
        raise MeshError(f"mesh: triangle {bad[0]} (vertices {_vs(T[bad[0]])}) is clockwise "
                        f"(negative area); triangles must be counter-clockwise" + _more(bad))

    _check_manifold(P, T, count)
    _check_coincident(P, S)

    aspect = longest2 / cross
    thin = np.flatnonzero(aspect > SLIVER_ASPECT)
    if thin.size:
        worst = thin[np.argsort(-aspect[thin], kind="stable")[:3]]
        named = ", ".join(f"triangle {i} (vertices {_vs(T[i])}, aspect ratio {aspect[i]:.2e})" for i in worst)
        warnings.warn(f"mesh: {thin.size} triangle(s) with aspect ratio above {SLIVER_ASPECT:g}, "
                      f"the stiffness is ill-conditioned; worst: {named}", MeshQualityWarning, stacklevel=3)
    return arrays


def _arrays(mesh):
    if isinstance(mesh, MeshArrays):
        return mesh
    if not isinstance(mesh, ng.Mesh):
        raise MeshError(f"mesh must be an ngsolve.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2:
        raise MeshError(f"ngfracture works on 2D meshes; this mesh has dimension {mesh.dim}")
    npoints = len(mesh.ngmesh.Points())
    if npoints == 0:
        raise MeshError("mesh: the mesh is empty (no vertices)")
    if mesh.ne == 0:
        raise MeshError(f"mesh: the mesh has {npoints} vertices but no triangles")
    try:
        return mesh_to_arrays(mesh)
    except ValueError as err:          # quadrilaterals
        raise MeshError(str(err)) from None


def cross_and_longest(P, T):
    """Twice the signed area of every triangle and its longest squared edge length.

    Parameters
    ----------
    P : numpy.ndarray (nv, 2)
        Vertex coordinates.
    T : numpy.ndarray of int (ne, 3)
        Triangles.

    Returns
    -------
    (numpy.ndarray (ne,), numpy.ndarray (ne,))
    """
    X, Y = P[:, 0][T], P[:, 1][T]
    ux, uy = X[:, 1] - X[:, 0], Y[:, 1] - Y[:, 0]
    vx, vy = X[:, 2] - X[:, 0], Y[:, 2] - Y[:, 0]
    wx, wy = X[:, 2] - X[:, 1], Y[:, 2] - Y[:, 1]
    cross = ux * vy - uy * vx
    longest2 = np.maximum(np.maximum(ux * ux + uy * uy, vx * vx + vy * vy), wx * wx + wy * wy)
    return cross, longest2


def _check_manifold(P, T, count):
    """Every edge in at most two triangles; every vertex's triangles one edge-connected fan.

    With edges in at most two triangles, the fan of a vertex is a set of chains (open) and
    rings (closed).  Triangles minus edges shared by two triangles counts the chains, so a
    vertex with two or more is a bow-tie (a ring plus a chain needs overlapping triangles).
    """
    nv = P.shape[0]
    a, b = T.ravel(), T[:, [1, 2, 0]].ravel()
    keys = np.sort(np.minimum(a, b) * nv + np.maximum(a, b))     # every edge once per triangle
    same = keys[1:] == keys[:-1]
    bad = np.unique(keys[1:-1][same[1:] & same[:-1]])             # edges in three or more
    if bad.size:
        k = bad[0]
        n = int(np.sum(keys == k))
        raise MeshError(f"mesh: edge ({k // nv}, {k % nv}) is shared by {n} triangles (non-manifold)" + _more(bad))
    inner = keys[1:][same]                                      # edges shared by two triangles
    shared = np.bincount(inner // nv, minlength=nv) + np.bincount(inner % nv, minlength=nv)
    chains = count - shared
    bad = np.flatnonzero(chains >= 2)
    if bad.size:
        v = bad[0]
        raise MeshError(f"mesh: vertex {v} at {_xy(P[v])} is a bow-tie (non-manifold): its triangles form "
                        f"{chains[v]} fans that meet only at this vertex" + _more(bad))


def _check_coincident(P, S):
    """Vertices at the same point are an error unless both lie on boundary segments."""
    order = np.lexsort((P[:, 1], P[:, 0]))
    same = np.all(P[order[1:]] == P[order[:-1]], axis=1)
    if not np.any(same):
        return
    first, second = order[:-1][same], order[1:][same]
    on_boundary = np.zeros(P.shape[0], dtype=bool)
    on_boundary[S.ravel()] = True
    bad = np.flatnonzero(~(on_boundary[first] & on_boundary[second]))
    if bad.size:
        i, j = sorted((int(first[bad[0]]), int(second[bad[0]])))
        raise MeshError(f"mesh: vertices {i} and {j} coincide at {_xy(P[i])} and are not both on boundary "
                        f"segments (only crack lips and touching bodies may share a point)" + _more(bad))


def _xy(p):
    return f"({p[0]:.17g}, {p[1]:.17g})"


def _vs(tri):
    return ", ".join(str(int(v)) for v in tri)


def _more(bad):
    return f" ({bad.size - 1} more like it)" if bad.size > 1 else ""


def validate_solid(mesh):
    """Check a 3D tetrahedral mesh; return its arrays.

    Refused: no tetrahedra, non-finite coordinates, vertex numbers out of range, a vertex in
    no tetrahedron, a tetrahedron of zero volume to rounding (``6|T| <= 64 eps * longest
    edge^3``) or of negative orientation, a boundary face that is no face of a tetrahedron.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays

    Returns
    -------
    SolidArrays

    Raises
    ------
    MeshError
        On the first defect found, naming it.
    """
    a = mesh if isinstance(mesh, SolidArrays) else solid_to_arrays(mesh)
    P, T = np.asarray(a.points, dtype=float), np.asarray(a.tets, dtype=np.int64)
    nv = P.shape[0]
    if T.ndim != 2 or T.shape[1] != 4 or T.size == 0:
        raise MeshError(f"mesh: the mesh has {nv} vertices but no tetrahedra")
    if T.min() < 0 or T.max() >= nv:
        i = int(np.flatnonzero((T < 0) | (T >= nv))[0] // 4)
        raise MeshError(f"mesh: tetrahedron {i} has vertices {T[i].tolist()}, outside [0, {nv})")
    bad = np.flatnonzero(~np.all(np.isfinite(P), axis=1))
    if bad.size:
        raise MeshError(f"mesh: vertex {bad[0]} has coordinates {P[bad[0]].tolist()}" + _more(bad))
    bad = np.flatnonzero(np.bincount(T.ravel(), minlength=nv) == 0)
    if bad.size:
        raise MeshError(f"mesh: vertex {bad[0]} at {P[bad[0]].tolist()} belongs to no tetrahedron" + _more(bad))
    x = P[T]
    e = x[:, 1:] - x[:, :1]
    det = np.einsum("ij,ij->i", e[:, 0], np.cross(e[:, 1], e[:, 2]))
    edges = x[:, [0, 0, 0, 1, 1, 2]] - x[:, [1, 2, 3, 2, 3, 3]]
    longest = np.sqrt(np.einsum("ijk,ijk->ij", edges, edges).max(axis=1))
    bad = np.flatnonzero(np.abs(det) <= 64 * np.finfo(float).eps * longest ** 3)
    if bad.size:
        raise MeshError(f"mesh: tetrahedron {bad[0]} (vertices {_vs(T[bad[0]])}) has zero volume" + _more(bad))
    bad = np.flatnonzero(det < 0)
    if bad.size:
        raise MeshError(f"mesh: tetrahedron {bad[0]} (vertices {_vs(T[bad[0]])}) is negatively oriented" + _more(bad))
    F = np.sort(np.asarray(a.faces, dtype=np.int64).reshape(-1, 3), axis=1)
    if F.size:
        own = np.sort(T[:, [1, 2, 3, 0, 2, 3, 0, 1, 3, 0, 1, 2]].reshape(-1, 3), axis=1)
        key = np.array([nv * nv, nv, 1], dtype=np.int64)
        bad = np.flatnonzero(~np.isin(F @ key, own @ key))
        if bad.size:
            raise MeshError(f"mesh: boundary face {bad[0]} (vertices {_vs(F[bad[0]])}) is no face of a tetrahedron"
                            + _more(bad))
    return a
