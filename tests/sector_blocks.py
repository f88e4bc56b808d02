"""Three blocks around the line x = y = 0 on the sectors [0, 60], [60, 120] and [120, 360] degrees.

Quadrant blocks meshed apart, every quadrant mapped linearly onto a sector (faces through
the line stay planes; one formula per point, chosen by its coordinates, so that copies stay
bitwise equal): A on [0, 60] (fragment 0), C on [60, 120] (fragment 1), B on [120, 360]
(fragment 2), a reflex wedge of 240 degrees at the line.
"""
import numpy as np

from ngfracture.geometry.solid import merge_bodies
from ngfracture.geometry.structured import box_mesh


def unit(degrees):
    """The unit vector at ``degrees`` from x in the plane z = 0."""
    t = np.radians(degrees)
    return np.array([np.cos(t), np.sin(t), 0.0])


def sectors(P):
    """The quadrants onto the sectors [0, 60], [60, 120], [120, 240], [240, 360]."""
    x, y = P[:, :1], P[:, 1:2]
    q1 = x * unit(0) + y * unit(60)
    q2 = y * unit(60) - x * unit(120)
    q3 = -x * unit(120) - y * unit(240)
    q4 = x * unit(0) - y * unit(240)
    out = np.where((x >= 0) & (y >= 0), q1, np.where(y >= 0, q2, np.where(x <= 0, q3, q4))) + 0.0
    out[:, 2] = P[:, 2]
    return out


def sector_blocks(cells, zs):
    """The three blocks, ``cells`` cells across each quadrant of half-width 1/2, the grid ``zs``
    along the line: the mesh's arrays and the fragment of every tetrahedron."""
    neg, pos = np.linspace(-0.5, 0.0, cells + 1), np.linspace(0.0, 0.5, cells + 1)
    arrays = merge_bodies([("a", box_mesh(pos, pos, zs)), ("c", box_mesh(neg, pos, zs)),
                           ("b", box_mesh(np.concatenate([neg, pos[1:]]), neg, zs))])
    arrays.points = sectors(arrays.points)
    return arrays, (arrays.regions - 1).astype(np.int64)
