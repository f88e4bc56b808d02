"""Fragment statistics: a post-processing object on top of a mesh (cf. Akantu's FragmentManager).

    stats = FragmentStatistics(result.mesh, result.fragment)   # after split.split_by_tensor / crack_step
    stats.count, stats.areas, stats.centroids, stats.total_area

Everything is measured in the reference configuration (the mesh coordinates): splitting
never moves material, so fragment areas are exact pieces of the domain area. Element areas
come from the C++ ``ElementAreas``; the total is ``math.fsum`` of them, so it equals the
domain area up to the rounding of each element area. Centroids in the deformed
configuration are available by passing the vertex displacement.
"""
import math

import numpy as np

from ..mechanics import rigid
from .._ngfracture import ElementAreas
from ..geometry.meshio import check_mesh, element_vertices
from ..geometry.solid import solid_to_arrays, tet_volumes

__all__ = ["FragmentStatistics", "fragment_ids"]


def _elements(mesh):
    """The elements' vertex numbers: triangles, or tetrahedra of a 3D mesh."""
    if getattr(mesh, "dim", None) == 3:
        return solid_to_arrays(mesh).tets
    check_mesh(mesh)
    return element_vertices(mesh)


def fragment_ids(mesh):
    """Fragment number of every triangle: connected components through shared vertices.

    Numbered by their smallest triangle (fragment 0 holds triangle 0), as in
    :class:`ngfracture.fracture.split.SplitResult`.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, or 3D tetrahedral mesh.

    Returns
    -------
    numpy.ndarray
        Shape (ne,), int64, values 0 .. count-1.
    """
    T = _elements(mesh)
    # pieces of the vertex graph; a triangle belongs to the piece of any of its vertices
    _, comp = rigid.pieces(T, mesh.nv)
    labels = comp[T[:, 0]]
    _, first = np.unique(labels, return_index=True)
    # relabel by smallest triangle: order components by the first triangle they contain
    order = np.argsort(first)
    relabel = np.empty(len(first), dtype=np.int64)
    relabel[labels[first[order]]] = np.arange(len(first))
    return relabel[labels]


class FragmentStatistics:
    """Count, areas and centroids of the fragments of a cracked mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh (or 3D tetrahedral mesh: areas are then volumes) in the reference
        configuration.
    fragment : array_like of int, optional
        Fragment id per triangle (shape (ne,)), e.g. ``SplitResult.fragment``. Any
        integer labels are accepted; they are kept in ``ids``. If omitted they are
        computed with :func:`fragment_ids`.
    u : array_like, optional
        Vertex displacement (nv, dim); if given, ``deformed_centroids`` is filled.

    Attributes
    ----------
    ids : numpy.ndarray
        The distinct fragment labels, increasing; row i of every per-fragment array
        belongs to ``ids[i]``.
    count : int
    areas : numpy.ndarray
        Reference area of each fragment.
    ntriangles : numpy.ndarray
        Triangles per fragment.
    centroids : numpy.ndarray
        (count, 2) area centroids in the reference configuration.
    deformed_centroids : numpy.ndarray or None
        (count, 2) area centroids of the P1-deformed triangles, weighted by reference area
        (the centre of mass for a uniform density), when ``u`` is given.
    total_area : float
        ``math.fsum`` of the element areas: the domain area.
    element_areas : numpy.ndarray

    Raises
    ------
    ValueError
        A fragment array of the wrong shape or not integer, a displacement of the wrong
        shape, or a mesh that is not 2D.
    """

    def __init__(self, mesh, fragment=None, u=None):
        T = _elements(mesh)
        ne, d = mesh.ne, mesh.dim
        if fragment is None:
            frag = fragment_ids(mesh)
        else:
            frag = np.asarray(fragment)
            if frag.shape != (ne,):
                raise ValueError(f"FragmentStatistics: fragment ids must have shape ({ne},) "
                                 f"(one per triangle), got {frag.shape}")
            if not np.issubdtype(frag.dtype, np.integer):
                raise ValueError(f"FragmentStatistics: fragment ids must be integers, got dtype {frag.dtype}")
        self.ids, index = np.unique(frag, return_inverse=True)
        index = index.reshape(-1)
        self.count = len(self.ids)
        self.fragment = frag
        X = mesh.ngmesh.Coordinates()[:, :d]
        self.element_areas = tet_volumes(X, T) if d == 3 else np.asarray(ElementAreas(mesh))
        a = self.element_areas
        self.total_area = math.fsum(a)
        self.areas = np.bincount(index, weights=a, minlength=self.count)
        self.ntriangles = np.bincount(index, minlength=self.count)
        self.centroids = self._centroids(X[T].mean(axis=1), a, index)
        self.deformed_centroids = None
        if u is not None:
            U = np.asarray(u, dtype=float)
            if U.shape != (mesh.nv, d):
                raise ValueError(f"FragmentStatistics: displacement must have shape ({mesh.nv}, {d}), got {U.shape}")
            self.deformed_centroids = self._centroids((X + U)[T].mean(axis=1), a, index)

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
            ``single_triangle_fragments`` (fragments of one triangle), as Python numbers.
        """
        return {"fragments": self.count, "total_area": self.total_area,
                "min_area": float(self.areas.min()), "mean_area": float(self.areas.mean()),
                "max_area": float(self.areas.max()),
                "single_triangle_fragments": int(np.sum(self.ntriangles == 1))}

    def __repr__(self):
        return f"FragmentStatistics(count={self.count}, total_area={self.total_area!r})"
