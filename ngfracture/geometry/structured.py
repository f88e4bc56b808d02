"""Structured tetrahedral meshes of boxes, in numpy: every grid cell split into 6 tets.

:func:`box_mesh` meshes the box spanned by three increasing coordinate lists (graded grids
allowed) with the Kuhn split (each cell into the 6 tets along its diagonal from the lowest to
the highest corner; the same split in every cell makes the mesh conforming). Every grid plane
is a union of tet faces, so cracks on a grid plane (:func:`ngfracture.geometry.internal_crack.open_internal_surface`)
and faces exactly on a plane come out exactly. Boundary faces are named ``xmin``, ``xmax``,
``ymin``, ``ymax``, ``zmin``, ``zmax``.
"""
from itertools import permutations

import numpy as np

from .solid import SolidArrays

__all__ = ["box_mesh", "BOX_FACES"]

#: the boundary names of :func:`box_mesh`, in bc number order
BOX_FACES = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]


def _grid(c, name):
    c = np.asarray(c, dtype=float)
    if c.ndim != 1 or len(c) < 2 or not np.all(np.isfinite(c)) or not np.all(np.diff(c) > 0):
        raise ValueError(f"ngfracture.geometry.structured: {name} must be at least 2 increasing finite numbers")
    return c


def _boundary(points, tets):
    """Faces of one tet, oriented out of it, and their boundary names' numbers."""
    opp = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    tri = tets[:, opp].reshape(-1, 3)
    apex = tets.ravel()
    key = np.sort(tri, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    one = counts[inv.ravel()] == 1
    tri, apex = tri[one], apex[one]
    x = points
    n = np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]])
    inward = np.einsum("ij,ij->i", n, x[apex] - x[tri[:, 0]]) > 0
    tri[inward] = tri[inward][:, [0, 2, 1]]
    n[inward] *= -1
    axis = np.argmax(np.abs(n), axis=1)
    bc = 2 * axis + (n[np.arange(len(n)), axis] > 0) + 1
    return tri, bc


def box_mesh(xs, ys, zs, region="body"):
    """The box xs x ys x zs as a structured tet mesh (6 tets per grid cell).

    Parameters
    ----------
    xs, ys, zs : sequence of float
        Increasing grid coordinates along x, y, z (at least two each).
    region : str
        The material name of every tet.

    Returns
    -------
    SolidArrays
        Point (i, j, k) is number ``(i * len(ys) + j) * len(zs) + k``; tets positively
        oriented; boundary faces named as in :data:`BOX_FACES`.

    Raises
    ------
    ValueError
        If a coordinate list is not increasing or has fewer than two entries.
    """
    xs, ys, zs = _grid(xs, "xs"), _grid(ys, "ys"), _grid(zs, "zs")
    nx, ny, nz = len(xs), len(ys), len(zs)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    points = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    I, J, K = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1), indexing="ij")
    base = ((I * ny + J) * nz + K).ravel()
    step = np.array([ny * nz, nz, 1])
    tets = []
    for perm in permutations(range(3)):
        corner = np.zeros(3, dtype=np.int64)
        path = [0]
        for axis in perm:
            corner[axis] = 1
            path.append(int(corner @ step))
        tets.append(base[:, None] + np.array(path)[None, :])
    tets = np.concatenate(tets).astype(np.int64)
    x = points[tets]
    vol = np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))
    tets[vol < 0] = tets[vol < 0][:, [0, 1, 3, 2]]
    faces, face_bc = _boundary(points, tets)
    return SolidArrays(points=points, tets=tets, regions=np.ones(len(tets), dtype=np.int64),
                       region_names=[region], faces=faces, face_bc=face_bc.astype(np.int64),
                       bc_names=list(BOX_FACES))
