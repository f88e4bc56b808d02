"""Helpers for the crack tests: hand-made meshes and the mesh invariants."""
import numpy as np
import ngsolve
from netgen.meshing import Mesh as NGMesh, FaceDescriptor

from ngfracture._ngfracture import ElementAreas
from ngfracture import fracture


def mesh_from_arrays(points, trigs, material="solid", bcname="outer"):
    """ngsolve.Mesh from points (n, 2) and triangles (m, 3); triangles are made
    counter-clockwise and every boundary edge gets a segment named `bcname`."""
    P = np.asarray(points, dtype=float)
    T = np.array(trigs, dtype=np.int32)
    a = ((P[T[:, 1], 0] - P[T[:, 0], 0]) * (P[T[:, 2], 1] - P[T[:, 0], 1])
         - (P[T[:, 2], 0] - P[T[:, 0], 0]) * (P[T[:, 1], 1] - P[T[:, 0], 1]))
    assert np.all(a != 0), "degenerate triangle"
    T[a < 0] = T[a < 0][:, [0, 2, 1]]
    half = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    key = np.sort(half, axis=1).astype(np.int64)
    _, inv, cnt = np.unique(key[:, 0] * len(P) + key[:, 1], return_inverse=True, return_counts=True)
    segs = half[cnt[inv.reshape(-1)] == 1]   # boundary half-edges: domain on the left
    ng = NGMesh(dim=2)
    ng.AddPoints(np.column_stack([P, np.zeros(len(P))]))
    ng.Add(FaceDescriptor(bc=1, domin=1, surfnr=1))
    ng.AddElements(dim=2, index=1, data=T, base=0)
    ng.AddElements(dim=1, index=1, data=np.ascontiguousarray(segs, dtype=np.int32), base=0)
    ng.SetBCName(0, bcname)
    ng.SetMaterial(1, material)
    return ngsolve.Mesh(ng)


def grid_mesh(nx, ny, hx=1.0, hy=1.0):
    """Structured nx x ny cells, each cut by the diagonal from lower left to upper right.
    Vertex (i, j) has number j * (nx + 1) + i."""
    xs, ys = np.meshgrid(np.arange(nx + 1) * hx, np.arange(ny + 1) * hy)
    P = np.column_stack([xs.ravel(), ys.ravel()])
    T = []
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 2, a + nx + 1
            T += [[a, b, c], [a, c, d]]
    return mesh_from_arrays(P, T)


def vid(nx, i, j):
    return j * (nx + 1) + i


def fan_mesh(angles_deg, outer=True):
    """Vertex 0 at the origin, ring vertices 1..n at radius 1 at the given angles (CCW),
    and, with outer=True, a second ring n+1..2n at radius 2 so the first ring is interior."""
    ang = np.radians(np.asarray(angles_deg, dtype=float))
    n = len(ang)
    ring = np.column_stack([np.cos(ang), np.sin(ang)])
    P = [np.zeros((1, 2)), ring] + ([2 * ring] if outer else [])
    T = [[0, 1 + i, 1 + (i + 1) % n] for i in range(n)]
    if outer:
        for i in range(n):
            a, b = 1 + i, 1 + (i + 1) % n
            A, B = a + n, b + n
            T += [[a, b, B], [a, B, A]]
    return mesh_from_arrays(np.vstack(P), T)


def coords(mesh):
    return mesh.ngmesh.Coordinates()[:, :2].copy()


def triangles(mesh):
    return mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3].astype(np.int64) - 1


def edge_table(T):
    """Unique undirected edges and their triangle counts."""
    e = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    n = int(T.max()) + 1
    k, cnt = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)   # int64 keys: fast
    return np.column_stack([k // n, k % n]), cnt


def fan_defect(T, nv):
    """Per vertex: (#triangles) - (#edges with two triangles). A vertex whose triangles
    form one edge-connected fan has 0 (closed fan) or 1 (open fan); pieces meeting only
    at the vertex give more."""
    k = np.bincount(T.ravel(), minlength=nv)
    e, c = edge_table(T)
    m = np.bincount(e[c == 2].ravel(), minlength=nv)
    return k - m


def check_invariants(old, res):
    """Exact invariants of one splitting pass; returns nothing, asserts everything."""
    new = res.mesh
    rec = res.record
    T0, T1 = triangles(old), triangles(new)
    P0, P1 = coords(old), coords(new)
    # triangle count, vertex count and parent map
    assert new.ne == old.ne
    assert new.nv == old.nv + len(rec["new_vertices"])
    assert len(res.parent) == new.nv
    assert np.array_equal(res.parent[:old.nv], np.arange(old.nv))
    assert np.array_equal(P1, P0[res.parent])                    # copies, bitwise
    # triangles keep their material points: T1 maps back to T0 through parent
    assert np.array_equal(res.parent[T1], T0)
    # areas and orientation identical to the last bit
    a0, a1 = ElementAreas(old), ElementAreas(new)
    assert np.array_equal(a0, a1)
    assert a0.sum() == a1.sum()
    # edge-manifold: every edge has one or two triangles
    _, cnt = edge_table(T1)
    assert cnt.max() <= 2
    # no pieces joined by a single vertex (unless they were before, at the parent)
    d0, d1 = fan_defect(T0, old.nv), fan_defect(T1, new.nv)
    assert np.all((d1 <= 1) | (d1 <= d0[res.parent]))
    # a valid NGSolve mesh: boundaries, regions, integrals
    assert set(old.GetBoundaries()) <= set(new.GetBoundaries())
    assert new.GetMaterials() == old.GetMaterials()
    assert abs(ngsolve.Integrate(1, new) - a0.sum()) < 1e-12 * abs(a0.sum())
    # every boundary edge of the new mesh has exactly one segment, oriented with the
    # triangle on its left
    segs = new.ngmesh.Elements1D().NumPy()["nodes"][:, :2].astype(np.int64) - 1
    e, c = edge_table(T1)
    n = new.nv
    sk = np.sort(segs, axis=1)
    sk = sk[:, 0] * n + sk[:, 1]
    assert len(np.unique(sk)) == len(sk)
    assert np.all(np.isin(e[c == 1][:, 0] * n + e[c == 1][:, 1], sk))
    if len(res.crack_segments):
        assert "crack" in new.GetBoundaries()
        cs = res.crack_segments
        n = new.nv
        half = np.concatenate([T1[:, [0, 1]], T1[:, [1, 2]], T1[:, [2, 0]]])
        assert np.all(np.isin(cs[:, 0].astype(np.int64) * n + cs[:, 1],
                              half[:, 0] * n + half[:, 1]))
