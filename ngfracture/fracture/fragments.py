"""Fragment statistics in 2D and 3D: a post-processing object on top of a mesh (cf. Akantu's FragmentManager).

    stats = FragmentStatistics(result.mesh, result.fragment)   # after split.split_by_tensor / crack_step
    stats.count, stats.areas, stats.centroids, stats.total_area
    stats = FragmentStatistics(split3d_result.arrays)          # 3D: SolidArrays or a tetrahedral mesh
    stats.count, stats.volumes, stats.centroids, stats.total_volume

One class for both dimensions: the measure of an element is its area (triangles, C++
``ElementAreas``) or its volume (tetrahedra, :func:`ngfracture.geometry.solid.tet_volumes`);
``volumes`` and ``total_volume`` are the 3D names of ``areas`` and ``total_area``.

Everything is measured in the reference configuration (the mesh coordinates): splitting
never moves material, so fragment measures are exact pieces of the domain's. The total is
``math.fsum`` of the element measures, so it equals the domain's up to the rounding of each
element measure; each fragment's measure is ``math.fsum`` of its elements' too (correctly
rounded sums: a fragment's measure does not depend on the order of its elements).
Centroids in the deformed configuration are available by passing the vertex displacement.

Fragments are the connected pieces of the mesh: through shared vertices for triangles,
through shared faces for tetrahedra (C++ ``TetComponents``; the 3D crack engine never
leaves two pieces joined by a single vertex or edge, so on its meshes both notions agree),
numbered by their smallest element.
"""
import math

import numpy as np

from .. import _ngfracture as _ext
from ..mechanics import rigid
from ..geometry.meshio import check_mesh, element_vertices
from ..geometry.solid import SolidArrays, solid_to_arrays, tet_volumes

__all__ = ["FragmentStatistics", "fragment_ids"]


def _elements(mesh):
    """(dimension, reference points (nv, dim), element vertex numbers) of a mesh or SolidArrays."""
    if isinstance(mesh, SolidArrays):
        return 3, np.asarray(mesh.points, dtype=float), np.asarray(mesh.tets)
    if getattr(mesh, "dim", None) == 3:
        a = solid_to_arrays(mesh)
        return 3, a.points, a.tets
    check_mesh(mesh)
    return 2, mesh.ngmesh.Coordinates()[:, :2], element_vertices(mesh)


def _by_smallest_element(labels):
    """Labels renumbered 0, 1, ... in the order of their smallest element."""
    _, first = np.unique(labels, return_index=True)
    order = np.argsort(first)
    relabel = np.empty(len(first), dtype=np.int64)
    relabel[labels[first[order]]] = np.arange(len(first))
    return relabel[labels]


def fragment_ids(mesh):
    """Fragment number of every element: its connected piece of the mesh.

    Triangles are connected through shared vertices, tetrahedra through shared faces.
    Numbered by their smallest element (fragment 0 holds element 0), as in
    :class:`ngfracture.fracture.split.SplitResult`.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays
        2D triangle mesh, or 3D tetrahedral mesh (an ``ngsolve.Mesh`` or its arrays).

    Returns
    -------
    numpy.ndarray
        Shape (ne,), int64, values 0 .. count-1.

    Raises
    ------
    ValueError
        A mesh that is neither (see :func:`ngfracture.geometry.meshio.check_mesh`).
    """
    dim, X, T = _elements(mesh)
    if dim == 3:
        _, frag = _ext.TetComponents(T, len(X))
        return _by_smallest_element(np.asarray(frag, dtype=np.int64))
    # pieces of the vertex graph; a triangle belongs to the piece of any of its vertices
    _, comp = rigid.pieces(T, len(X))
    return _by_smallest_element(comp[T[:, 0]])


class FragmentStatistics:
    """Count, areas (volumes in 3D) and centroids of the fragments of a cracked mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays
        2D triangle mesh, or 3D tetrahedral mesh (``ngsolve.Mesh`` or SolidArrays), in the
        reference configuration.
    fragment : array_like of int, optional
        Fragment id per element (shape (ne,)), e.g. ``SplitResult.fragment``. Any
        integer labels are accepted; they are kept in ``ids``. If omitted they are
        computed with :func:`fragment_ids`.
    u : array_like, optional
        Vertex displacement (nv, dim); if given, ``deformed_centroids`` is filled.

    Attributes
    ----------
    dim : int
        2 (triangles) or 3 (tetrahedra).
    ids : numpy.ndarray
        The distinct fragment labels, increasing; row i of every per-fragment array
        belongs to ``ids[i]``.
    count : int
    fragment : numpy.ndarray
        The fragment label of every element.
    areas : numpy.ndarray
        Reference area (3D: volume) of each fragment, ``math.fsum`` of its elements'.
    volumes : numpy.ndarray
        ``areas`` under its 3D name.
    ntriangles : numpy.ndarray
        Elements (triangles or tetrahedra) per fragment.
    centroids : numpy.ndarray
        (count, dim) area (volume) centroids in the reference configuration.
    deformed_centroids : numpy.ndarray or None
        (count, dim) centroids of the P1-deformed elements, weighted by reference measure
        (the centre of mass for a uniform density), when ``u`` is given.
    total_area : float
        ``math.fsum`` of the element measures: the domain area (3D: volume).
    total_volume : float
        ``total_area`` under its 3D name.
    element_areas : numpy.ndarray
        Area (3D: volume) of every element.

    Raises
    ------
    ValueError
        A fragment array of the wrong shape or not integer, a displacement of the wrong
        shape, or a mesh that is neither a triangle nor a tetrahedral mesh.
    """

    def __init__(self, mesh, fragment=None, u=None):
        d, X, T = _elements(mesh)
        ne, nv = len(T), len(X)
        if fragment is None:
            frag = fragment_ids(mesh)
        else:
            frag = np.asarray(fragment)
            if frag.shape != (ne,):
                raise ValueError(f"FragmentStatistics: fragment ids must have shape ({ne},) "
                                 f"(one per {'tetrahedron' if d == 3 else 'triangle'}), got {frag.shape}")
            if not np.issubdtype(frag.dtype, np.integer):
                raise ValueError(f"FragmentStatistics: fragment ids must be integers, got dtype {frag.dtype}")
        self.dim = d
        self.ids, index = np.unique(frag, return_inverse=True)
        index = index.reshape(-1)
        self.count = len(self.ids)
        self.fragment = frag
        self.element_areas = tet_volumes(X, T) if d == 3 else np.asarray(_ext.ElementAreas(mesh))
        a = self.element_areas
        self.total_area = math.fsum(a)
        order = np.argsort(index, kind="stable")
        cuts = np.searchsorted(index[order], np.arange(1, self.count))
        self.areas = np.array([math.fsum(p) for p in np.split(a[order], cuts)], dtype=float)
        self.ntriangles = np.bincount(index, minlength=self.count)
        self.centroids = self._centroids(X[T].mean(axis=1), a, index)
        self.deformed_centroids = None
        if u is not None:
            U = np.asarray(u, dtype=float)
            if U.shape != (nv, d):
                raise ValueError(f"FragmentStatistics: displacement must have shape ({nv}, {d}), got {U.shape}")
            self.deformed_centroids = self._centroids((X + U)[T].mean(axis=1), a, index)

    @property
    def volumes(self):
        """``areas``: the fragment volumes of a tetrahedral mesh."""
        return self.areas

    @property
    def total_volume(self):
        """``total_area``: the volume of a tetrahedral mesh."""
        return self.total_area

    def _centroids(self, element_centres, a, index):
        c = np.column_stack([np.bincount(index, weights=a * element_centres[:, k], minlength=self.count)
                             for k in range(element_centres.shape[1])])
        return c / self.areas[:, None]

    def summary(self):
        """Plain numbers for a JSON summary: count, total area, min/mean/max fragment area.

        Returns
        -------
        dict
            ``fragments``, ``total_area``, ``min_area``, ``mean_area``, ``max_area`` and
            ``single_triangle_fragments`` (fragments of one element), as Python numbers
            (areas are volumes in 3D).
        """
        return {"fragments": self.count, "total_area": self.total_area,
                "min_area": float(self.areas.min()), "mean_area": float(self.areas.mean()),
                "max_area": float(self.areas.max()),
                "single_triangle_fragments": int(np.sum(self.ntriangles == 1))}

    def __repr__(self):
        return f"FragmentStatistics(dim={self.dim}, count={self.count}, total_area={self.total_area!r})"
