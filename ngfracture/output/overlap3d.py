"""The overlap volume between fragments of a tetrahedral mesh, from arrays or from a written .vtu.

    ov = fragment_overlap_volume(points + u, tets, fragment)     # deformed configuration
    ov.volume, ov.pairs, ov.volumes
    ov = vtu_overlap_volume("out/run/step_000012.vtu")          # what a run wrote
    ov.volume / ov.body_volume                                   # at most 1e-10 in a sound run

A measure of what the contact code is meant to prevent, computed without any of it: the
pieces of a run must not interpenetrate, so the volume that tetrahedra of different
fragments share in the deformed configuration is the overlap. It is measured exactly up
to rounding (C++ ``cpp_ext/tet_overlap.cpp``):

* **Candidates**: the bounding boxes of the deformed tetrahedra in a uniform grid (cell:
  the mean of the boxes' largest sides); a pair is tested once, in the first cell its two
  boxes share, when its fragments differ and its boxes overlap with positive volume (boxes
  that only touch hold tetrahedra that only touch).
* **Narrow phase**: the intersection of two tetrahedra is convex: one tetrahedron, as a
  polyhedron of outward triangles, is clipped by the four half-spaces of the other, each
  face by Sutherland-Hodgman and the cut closed by a cap polygon (the on-plane vertices in
  angular order about the plane's normal); the volume is the divergence-theorem sum of
  the fan tetrahedra of its faces about one of its vertices. The exact ``orient3d``
  decides on which side of a plane an original corner lies, and two tetrahedra separated
  by a plane through a face of either (all corners of the other on the outer side or on
  it) have intersection exactly 0: bodies that touch on a face, and the two lips of a
  crack that coincide, count nothing. A computed distance to a clipping plane below
  32 ulps of |n| times the polyhedron's reach from the plane's point is rounding and
  counts as on the plane: a face that lies in the plane up to rounding (coincident
  faces of rotated bodies) is then kept whole, not cut in pieces by noise whose kept
  part and cap would cover it twice. The volume this neglects is below that distance
  times the cut's area, about 1e-14 of the tetrahedron.
* **Fragments**: only tetrahedra of different fragments are tested; the lips of a crack
  that does not separate its fragment are faces of one fragment and touch, they do not
  overlap.

The sum runs over the overlapping pairs sorted by tetrahedron numbers: deterministic. The
reading of a .vtu is pyvista's (the file is VTK XML, ``output/vtkxml.py``): reference
points, the point field ``displacement``, the ``VTK_TETRA`` cells and the cell field
``fragment`` that every 3D step file holds (docs/solid.md, "Outputs in 3D").
"""
import math
from dataclasses import dataclass

import numpy as np

from .. import _ngfracture as _ext
from ..geometry.solid import tet_volumes

__all__ = ["Overlap3d", "tet_intersection_volume", "fragment_overlap_volume", "read_step_vtu",
           "vtu_overlap_volume"]

#: VTK's cell type of a linear tetrahedron
VTK_TETRA = 10


@dataclass(frozen=True)
class Overlap3d:
    """The overlap between the fragments of a tetrahedral mesh.

    Parameters
    ----------
    volume : float
        Total intersection volume of the pairs of tetrahedra of different fragments.
    pairs : numpy.ndarray
        Shape (k, 2), int64: the pairs with a positive intersection, first < second, sorted.
    volumes : numpy.ndarray
        Shape (k,): their intersection volumes.
    candidates : int
        Pairs of different fragments whose bounding boxes overlap (tested exactly).
    body_volume : float
        ``math.fsum`` of the reference tetrahedron volumes when known (from a .vtu), else
        of the given configuration's.
    """
    volume: float
    pairs: np.ndarray
    volumes: np.ndarray
    candidates: int
    body_volume: float

    @property
    def relative(self):
        """``volume / body_volume``."""
        return self.volume / self.body_volume


def tet_intersection_volume(a, b):
    """Volume of the intersection of two tetrahedra.

    Parameters
    ----------
    a, b : array_like
        Shape (4, 3): the corners of each tetrahedron, either orientation.

    Returns
    -------
    float
        The volume; 0 for a flat tetrahedron and, exactly, for tetrahedra separated by a
        plane through a face of either.

    Raises
    ------
    ValueError
        A shape other than (4, 3), or a coordinate that is not finite.
    """
    pts = []
    for name, t in (("a", a), ("b", b)):
        t = np.asarray(t, dtype=float)
        if t.shape != (4, 3):
            raise ValueError(f"tet_intersection_volume: {name} must have shape (4, 3), got {t.shape}")
        if not np.all(np.isfinite(t)):
            raise ValueError(f"tet_intersection_volume: {name} has a coordinate that is not finite")
        pts.append(t)
    return float(_ext.TetIntersectionVolume(a=pts[0], b=pts[1]))


def fragment_overlap_volume(points, tets, fragment, body_volume=None):
    """The volume shared by tetrahedra of different fragments.

    Parameters
    ----------
    points : array_like
        Shape (nv, 3): the coordinates to measure in (the deformed configuration, reference
        points plus displacement).
    tets : array_like of int
        Shape (ne, 4): vertex numbers.
    fragment : array_like of int
        Shape (ne,): the fragment of every tetrahedron (any integer labels).
    body_volume : float, optional
        The volume to compare with (``Overlap3d.body_volume``); default ``math.fsum`` of
        the tetrahedron volumes at ``points``.

    Returns
    -------
    Overlap3d

    Raises
    ------
    ValueError
        A shape that does not fit, a coordinate that is not finite, a vertex number out of
        range, or fragment labels that are not integers.
    """
    X = np.asarray(points, dtype=float)
    T = np.asarray(tets)
    f = np.asarray(fragment)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ValueError(f"fragment_overlap_volume: points must have shape (nv, 3), got {X.shape}")
    if not np.all(np.isfinite(X)):
        raise ValueError("fragment_overlap_volume: points has a coordinate that is not finite")
    if T.ndim != 2 or T.shape[1] != 4 or not np.issubdtype(T.dtype, np.integer):
        raise ValueError(f"fragment_overlap_volume: tets must be integers of shape (ne, 4), got {T.dtype} {T.shape}")
    if len(T) and (T.min() < 0 or T.max() >= len(X)):
        raise ValueError(f"fragment_overlap_volume: tets has a vertex number outside [0, {len(X)})")
    if f.shape != (len(T),) or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"fragment_overlap_volume: fragment must be {len(T)} integers, got {f.dtype} {f.shape}")
    _, label = np.unique(f, return_inverse=True)         # any integer labels, as int32
    r = _ext.FragmentOverlap3(points=X, tets=T.astype(np.int32), fragment=label.reshape(-1).astype(np.int32))
    if body_volume is None:
        body_volume = math.fsum(tet_volumes(X, T)) if len(T) else 0.0
    pairs = np.column_stack([r["first"], r["second"]]).astype(np.int64).reshape(-1, 2)
    return Overlap3d(float(r["total"]), pairs, np.asarray(r["volume"], dtype=float), int(r["candidates"]),
                     float(body_volume))


def read_step_vtu(path):
    """The arrays of a 3D step file that the overlap needs.

    Parameters
    ----------
    path : str or os.PathLike
        A ``step_NNNNNN.vtu`` of a 3D run (``VTK_TETRA`` cells).

    Returns
    -------
    points : numpy.ndarray
        (nv, 3) reference coordinates.
    displacement : numpy.ndarray
        (nv, 3) point field ``displacement``.
    tets : numpy.ndarray
        (ne, 4) int64 vertex numbers.
    fragment : numpy.ndarray
        (ne,) int64 cell field ``fragment``.

    Raises
    ------
    ValueError
        A file with cells other than tetrahedra, or without the ``displacement`` or
        ``fragment`` field.
    """
    import pyvista as pv
    g = pv.read(str(path))
    types = np.asarray(g.celltypes)
    if g.n_cells == 0 or not np.all(types == VTK_TETRA):
        raise ValueError(f"read_step_vtu: {path} holds cells other than tetrahedra (or none)")
    for kind, data, name in (("point", g.point_data, "displacement"), ("cell", g.cell_data, "fragment")):
        if name not in data:
            raise ValueError(f"read_step_vtu: {path} has no {kind} field '{name}'")
    tets = np.asarray(g.cell_connectivity, dtype=np.int64).reshape(-1, 4)
    return (np.asarray(g.points, dtype=float), np.asarray(g.point_data["displacement"], dtype=float), tets,
            np.asarray(g.cell_data["fragment"]).astype(np.int64))


def vtu_overlap_volume(path):
    """The overlap between fragments in the deformed configuration a 3D step file holds.

    Parameters
    ----------
    path : str or os.PathLike
        A ``step_NNNNNN.vtu`` of a 3D run.

    Returns
    -------
    Overlap3d
        Measured at the reference points plus the displacement; ``body_volume`` is the
        reference volume (``math.fsum`` of the reference tetrahedra).

    Raises
    ------
    ValueError
        As :func:`read_step_vtu` and :func:`fragment_overlap_volume`.
    """
    X, U, T, f = read_step_vtu(path)
    return fragment_overlap_volume(X + U, T, f, body_volume=math.fsum(tet_volumes(X, T)))
