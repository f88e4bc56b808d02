"""Meshes and checks shared by the 3D splitting tests."""
import itertools
import math

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, maximum_flow

from ngfracture.geometry.solid import SolidArrays, tet_volumes

#: the face opposite local vertex c, outward for a positively oriented tetrahedron
OUT = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
SIDES = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]


def cube_bar(nx, ny, nz):
    """nx*ny*nz unit cubes of 6 tetrahedra each (all on the path from a cube's lowest corner),
    faces named by the side they lie on."""
    idx = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k
    g = np.stack(np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1), indexing="ij"), -1)
    pts = g.reshape(-1, 3).astype(float)
    tets = []
    for c in itertools.product(range(nx), range(ny), range(nz)):
        for perm in itertools.permutations(range(3)):
            v, path = np.array(c), [idx(*c)]
            for a in perm:
                v = v + np.eye(3, dtype=int)[a]
                path.append(idx(*v))
            tets.append(path)
    tets = np.array(tets, dtype=np.int64)
    neg = tet_volumes(pts, tets) < 0
    tets[neg] = tets[neg][:, [0, 1, 3, 2]]
    f = tets[:, OUT].reshape(-1, 3)
    _, inv, cnt = np.unique(np.sort(f, axis=1), axis=0, return_inverse=True, return_counts=True)
    f = f[cnt[inv.reshape(-1)] == 1]
    x = pts[f]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    ax = np.argmax(np.abs(n), axis=1)
    bc = 1 + 2 * ax + (n[np.arange(len(n)), ax] > 0)
    return SolidArrays(pts, tets, np.ones(len(tets), dtype=np.int64), ["solid"], f, bc.astype(np.int64), list(SIDES))


def crack_area(arrays):
    """Area of the crack (both lips' faces summed, halved), math.fsum."""
    x = arrays.points[arrays.boundary_faces("crack")]
    return math.fsum(np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1) / 4)


def check_twins(arrays):
    """Every crack face has a coincident twin: the same points in the opposite orientation,
    other vertex numbers (those of the crack front may be shared)."""
    f = arrays.boundary_faces("crack")
    x = arrays.points[f]
    own = {x[i].tobytes(): i for i in range(len(f))}
    for i in range(len(f)):
        twins = [own.get(x[i][list(p)].tobytes()) for p in ([0, 2, 1], [2, 1, 0], [1, 0, 2])]
        twins = [t for t in twins if t is not None]
        assert len(twins) == 1, f"crack face {i} has {len(twins)} twins"
        assert not np.array_equal(np.sort(f[twins[0]]), np.sort(f[i])), f"crack face {i} is its own twin"


def crack_pieces(arrays):
    """Number of crack sheets: crack faces connected through shared points."""
    f = arrays.boundary_faces("crack")
    if not len(f):
        return 0
    _, pid = np.unique(arrays.points, axis=0, return_inverse=True)
    pid = pid.reshape(-1)[f]
    n = len(f)
    rows = np.repeat(np.arange(n), 3)
    g = sp.coo_matrix((np.ones(3 * n), (rows, n + pid.ravel())), shape=(n + pid.max() + 1,) * 2)
    _, lab = connected_components(g, directed=False)
    return len(np.unique(lab[:n]))


def min_face_surface(arrays, normal, centre, band):
    """Smallest area of a surface of mesh faces that separates the tetrahedra lying wholly
    more than band above the plane (normal, through centre) from those wholly more than
    band below: a global minimum cut over the shared faces (scipy's maximum flow on areas
    in units of 1e-7, so to about 1e-7 per face). No crack made of mesh faces within band
    of the plane can have less area."""
    n = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    d = (arrays.points - centre) @ n
    ne = len(arrays.tets)
    f = arrays.tets[:, OUT].reshape(-1, 3)
    _, inv = np.unique(np.sort(f, axis=1), axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    o = np.argsort(inv, kind="stable")
    pair = np.flatnonzero(inv[o][1:] == inv[o][:-1])
    t1, t2 = o[pair] // 4, o[pair + 1] // 4
    x = arrays.points[f[o[pair]]]
    cap = np.round(np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1) / 2 * 1e7)
    dt = d[arrays.tets]
    src, snk = np.flatnonzero(dt.min(axis=1) > band), np.flatnonzero(dt.max(axis=1) < -band)
    big = np.full(len(src) + len(snk), 2 ** 30)
    rows = np.concatenate([t1, t2, np.full(len(src), ne), snk])
    cols = np.concatenate([t2, t1, src, np.full(len(snk), ne + 1)])
    g = sp.csr_matrix((np.concatenate([cap, cap, big]).astype(np.int32), (rows, cols)), shape=(ne + 2, ne + 2))
    return maximum_flow(g, ne, ne + 1).flow_value / 1e7
