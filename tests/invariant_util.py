"""Checks of an accepted state that do not use the engine's own code: the reference area
by numpy and math.fsum, inverted triangles by their deformed signed areas, and overlap
between pieces by rasterising the deformed triangles on a grid (a point covered by two
triangles is overlap; triangles sharing an edge cover its points once, as the grid is
offset from every mesh coordinate by an irrational fraction of its step). In 3D the same
with volumes, and the overlap by exact intersections of the deformed tetrahedra of
different pieces (``ngfracture.output.overlap3d``, which uses no contact code)."""
import math

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def reference_area(points, triangles):
    a, b, c = points[triangles[:, 0]], points[triangles[:, 1]], points[triangles[:, 2]]
    return math.fsum(0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])))


def deformed_areas(points, triangles, U):
    x = points + U
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def raster_overlap(points, triangles, U, pixels=600):
    """Estimated overlap area of the deformed triangles, and the area of one pixel."""
    x = points + U
    lo, hi = x.min(axis=0), x.max(axis=0)
    step = (hi - lo).max() / pixels
    offset = lo + step * np.array([math.sqrt(2) - 1, math.sqrt(3) - 1])   # off every mesh coordinate
    shape = np.ceil((hi - offset) / step).astype(int) + 1
    count = np.zeros(shape, dtype=np.int32)
    for tri in x[triangles]:
        i0, j0 = np.floor((tri.min(axis=0) - offset) / step).astype(int)
        i1, j1 = np.ceil((tri.max(axis=0) - offset) / step).astype(int)
        i0, j0 = max(i0, 0), max(j0, 0)
        gi, gj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1), indexing="ij")
        p = offset + step * np.stack([gi, gj], axis=-1)
        inside = np.ones(gi.shape, dtype=bool)
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            inside &= (b[0] - a[0]) * (p[..., 1] - a[1]) - (b[1] - a[1]) * (p[..., 0] - a[0]) > 0
        count[gi[inside], gj[inside]] += 1
    return float(np.count_nonzero(count > 1)) * step * step, step * step


def pieces(cells, nv):
    """Connected components of the cells (triangles or tetrahedra) through shared vertices."""
    t = np.asarray(cells)
    rows, cols = t[:, :-1].ravel(), t[:, 1:].ravel()          # each cell's vertices chained
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(nv, nv))
    return connected_components(graph, directed=False)[1]


def check_accepted(step, area_initial, pixels=600):
    """Assert the invariants of an ``AcceptedStep`` independently; returns the raster overlap."""
    arrays = step.state.arrays
    nv = len(arrays.points)
    U = np.asarray(step.state.u).reshape(2, -1)[:, :nv].T
    assert reference_area(arrays.points, arrays.triangles) == area_initial, step.state.step
    assert deformed_areas(arrays.points, arrays.triangles, U).min() > 0, step.state.step
    overlap, pixel = raster_overlap(arrays.points, arrays.triangles, U, pixels)
    # a few pixels along an edge are rounding of the raster, not overlap
    assert overlap <= 4 * pixel, (step.state.step, overlap, pixel)
    return overlap


def signed_volumes(points, tets):
    d = points[tets[:, 1:]] - points[tets[:, [0]]]
    return np.einsum("ij,ij->i", d[:, 0], np.cross(d[:, 1], d[:, 2])) / 6.0


def reference_volume(points, tets):
    return math.fsum(signed_volumes(points, tets))


def check_accepted_3d(step, volume_initial, tol=1e-10):
    """Assert the invariants of a 3D ``AcceptedStep`` independently: the reference volume to
    the last bit, no inverted tetrahedron, the overlap between pieces at most ``tol`` of the
    volume; returns the overlap volume."""
    from ngfracture.output.overlap3d import fragment_overlap_volume
    arrays = step.state.arrays
    nv = len(arrays.points)
    x = arrays.points + np.asarray(step.state.u).reshape(3, -1)[:, :nv].T
    assert reference_volume(arrays.points, arrays.tets) == volume_initial, step.state.step
    assert signed_volumes(x, arrays.tets).min() > 0, step.state.step
    piece = pieces(arrays.tets, nv)[arrays.tets[:, 0]]
    overlap = fragment_overlap_volume(x, arrays.tets, piece, body_volume=volume_initial).volume
    assert overlap <= tol * volume_initial, (step.state.step, overlap)
    return overlap
