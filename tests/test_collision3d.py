"""Collision detection between fragments in 3D (ngfracture.contact.collision3d, docs/contact.md).

Exact orient3d against rational arithmetic; overlapping, touching and cracked boxes of
structured tetrahedra whose coordinates are dyadic, so depths, projections and
barycentrics are known exactly; the search's cost grows linearly.
"""
import time
from fractions import Fraction

import numpy as np
import pytest

from ngfracture.contact.collision3d import detect_penetrations_3d, orient3d
from ngfracture.fracture import split3d as s3
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.geometry.structured import box_mesh
from split3d_util import cube_bar


def exact_orient3d(a, b, c, d):
    m = [[Fraction(float(p[k])) - Fraction(float(d[k])) for k in range(3)] for p in (a, b, c)]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    return (det > 0) - (det < 0)


def test_orient3d_coplanar_inputs_give_zero():
    rng = np.random.default_rng(1)
    n = 200
    # integer points on the plane x + 2y + 3z = 5, each row scaled by one power of two:
    # exactly coplanar doubles
    scale = 2.0 ** rng.integers(-30, 30, (n, 1))
    pts = []
    for _ in range(4):
        y, z = rng.integers(-10**6, 10**6, n), rng.integers(-10**6, 10**6, n)
        pts.append(np.column_stack([5 - 2 * y - 3 * z, y, z]) * scale)
    assert np.all(orient3d(*pts) == 0)
    assert np.all(orient3d(pts[0], pts[0], pts[1], pts[2]) == 0)   # a repeated point
    t = rng.random((n, 3))                                          # non-dyadic, repeated
    assert np.all(orient3d(t, pts[1], t, pts[2]) == 0)
    # a non-dyadic plane z = 0.1: four points with the same z
    q = [np.column_stack([rng.random((n, 2)), np.full(n, 0.1)]) for _ in range(4)]
    assert np.all(orient3d(*q) == 0)


def test_orient3d_is_exact_one_ulp_from_degenerate():
    rng = np.random.default_rng(7)
    n = 400
    a, b, c = rng.random((n, 3)) * 100, rng.random((n, 3)) * 100, rng.random((n, 3)) * 100
    s, t = rng.random((n, 1)), rng.random((n, 1))
    d = a + s * (b - a) + t * (c - a)                  # coplanar up to rounding
    axis = rng.integers(0, 3, n)
    step = rng.integers(-1, 2, n)                      # -1, 0 or +1 ulp
    rows = np.arange(n)
    d[rows, axis] = np.where(step > 0, np.nextafter(d[rows, axis], np.inf),
                             np.where(step < 0, np.nextafter(d[rows, axis], -np.inf), d[rows, axis]))
    want = np.array([exact_orient3d(a[i], b[i], c[i], d[i]) for i in range(n)])
    got = orient3d(a, b, c, d)
    assert np.array_equal(got, want)
    from ngfracture import _ngfracture as ext
    assert np.array_equal(ext.Orient3d(a, b, c, d, exact_only=True), want)
    naive = np.sign(np.einsum("ij,ij->i", a - d, np.cross(b - d, c - d)))
    assert np.count_nonzero(naive != want) > 0, "the cases are not near-degenerate enough to test anything"
    # convention: a positively oriented tetrahedron gives -1
    assert orient3d([0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1])[0] == -1


def two_bodies(a, b):
    """Two SolidArrays as one mesh, fragment 0 and 1."""
    nv = len(a.points)
    points = np.vstack([a.points, b.points])
    tets = np.vstack([a.tets, b.tets + nv])
    faces = np.vstack([a.faces, b.faces + nv])
    fragment = np.repeat([0, 1], [len(a.tets), len(b.tets)])
    return points, tets, faces, fragment


def test_overlapping_boxes_depth_projection_barycentrics():
    A = box_mesh(np.linspace(0, 1, 5), np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    B = box_mesh([0.75, 1.0, 1.25, 1.5, 1.75], [0.375, 0.5, 0.625], [0.375, 0.5, 0.625])
    points, tets, faces, fragment = two_bodies(A, B)
    r = detect_penetrations_3d(points, tets, faces, fragment)
    nA = len(A.points)
    bverts = np.unique(faces)
    p = points[bverts]
    inA = (bverts >= nA) & np.all((p >= 0) & (p <= 1), axis=1)
    inB = (bverts < nA) & (p[:, 0] >= 0.75) & (p[:, 0] <= 1.75) & np.all((p[:, 1:] >= 0.375) & (p[:, 1:] <= 0.625), axis=1)
    want = bverts[inA | inB]
    assert np.array_equal(r.vertex, want)                    # every one, sorted
    assert np.array_equal(r.fragment, np.where(want < nA, 1, 0))
    assert np.all(r.twin == -1)
    x = points[r.vertex]
    deep = np.where(r.vertex < nA, True, x[:, 0] == 0.75)
    # B's vertices at x = 0.75: 0.25 inside A, master A's xmax face; A's vertex (1, .5, .5):
    # 0.25 inside B, master B's xmin face (B's side faces, 0.125 away, do not oppose it)
    assert np.count_nonzero(deep) == 9 + 1
    assert np.all(np.abs(r.gap[deep] + 0.25) <= 1e-14)
    target = np.where(r.vertex[deep] < nA, 0.75, 1.0)
    assert np.array_equal(r.projection[deep][:, 0], target)
    assert np.array_equal(r.projection[deep][:, 1:], x[deep][:, 1:])
    assert np.array_equal(np.abs(r.normal[deep]), np.tile([1.0, 0, 0], (10, 1)))
    # B's vertices on A's xmax plane touch it: gap exactly 0, projection the point itself
    assert np.all(r.gap[~deep] == 0.0) and np.count_nonzero(~deep) == 8
    assert np.array_equal(r.projection[~deep], x[~deep])
    # barycentrics reproduce the projection, sum to 1 and are >= 0 (dyadic data: exact)
    corners = points[faces[r.face]]
    assert np.all(r.bary >= 0) and np.all(np.abs(r.bary.sum(axis=1) - 1) <= 1e-15)
    assert np.abs(np.einsum("ij,ijk->ik", r.bary, corners) - r.projection).max() <= 1e-15
    # the containing tetrahedron belongs to the other fragment
    assert np.all(fragment[r.tet] == r.fragment)


def test_touching_boxes_are_not_penetrating():
    A = box_mesh(np.linspace(0, 1, 4), np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    B = box_mesh(np.linspace(1, 2, 3), [0.125, 0.5, 0.875], [0.0, 0.25, 0.625, 1.0])   # non-matching
    points, tets, faces, fragment = two_bodies(A, B)
    r = detect_penetrations_3d(points, tets, faces, fragment)
    on_plane = np.unique(faces)[points[np.unique(faces)][:, 0] == 1.0]
    assert len(r) > 0 and np.all(r.gap == 0.0) and not r.penetrating.any()
    assert set(r.vertex) <= set(on_plane)
    # every vertex of B on the plane lies on A's closed xmax face: all reported
    nA = len(A.points)
    assert set(on_plane[on_plane >= nA]) <= set(r.vertex)
    assert np.array_equal(r.projection, points[r.vertex])


def cracked_bar():
    a = cube_bar(2, 2, 8)
    for v in np.flatnonzero(a.points[:, 2] == 4.0):
        a = s3.split_vertices_3d(a, [v], [np.array([0.0, 0.0, 1.0])]).arrays
    fr = FragmentStatistics(a)
    assert fr.count == 2
    return a, fr.fragment


def test_cracked_bar_closed_seam_then_penetration():
    a, frag = cracked_bar()
    r = detect_penetrations_3d(a.points, a.tets, a.faces, frag)
    assert len(r) == 0
    assert r.stats["closed_seams"] == 2 * 9                 # both lips' 3 x 3 copies
    # move the upper fragment down by 1e-3 across the crack
    upper = np.unique(a.tets[frag == frag[np.argmax(a.points[a.tets].mean(axis=1)[:, 2])]])
    u = np.zeros_like(a.points)
    u[upper, 2] = -1e-3
    r = detect_penetrations_3d(a.points, a.tets, a.faces, frag, displacement=u)
    lip = np.unique(a.boundary_faces("crack"))
    # each lip is now 1e-3 inside the other piece: every crack-face vertex of both
    assert np.array_equal(r.vertex, lip)
    assert np.all(np.abs(r.gap + 1e-3) <= 1e-14)
    up = np.isin(r.vertex, upper)
    assert np.all(r.normal[up, 2] == 1.0) and np.all(r.normal[~up, 2] == -1.0)   # the other lip's faces
    assert np.all(r.projection[up, 2] == 4.0) and np.all(r.projection[~up, 2] == 4.0 - 1e-3)
    assert np.all(r.twin >= 0) and np.all(np.all(a.points[r.twin] == a.points[r.vertex], axis=1))


def test_bad_input_is_refused():
    A = box_mesh([0, 1], [0, 1], [0, 1])
    with pytest.raises(ValueError, match="fragment"):
        detect_penetrations_3d(A.points, A.tets, A.faces, np.zeros(3))
    with pytest.raises(ValueError, match="faces"):
        detect_penetrations_3d(A.points, A.tets, A.faces + 100, np.zeros(len(A.tets)))
    with pytest.raises(ValueError, match="fragments"):
        detect_penetrations_3d(A.points, A.tets, A.faces, np.arange(len(A.tets)))
    with pytest.raises(ValueError, match="not a face"):
        detect_penetrations_3d(A.points, A.tets, A.faces[:, [0, 0, 1]], np.zeros(len(A.tets)))


def plates(n):
    """Two plates of n x n x 1 cells (about 4 n^2 boundary faces each), overlapping by 1/8 cell."""
    A = box_mesh(np.arange(n + 1.0), np.arange(n + 1.0), [0.0, 1.0])
    B = box_mesh(np.arange(n + 1.0) + 0.5, np.arange(n + 1.0) + 0.25, [0.875, 1.875])
    return two_bodies(A, B)


def test_cost_grows_linearly():
    times, nfaces = [], []
    for n in (35, 100):
        points, tets, faces, fragment = plates(n)
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            r = detect_penetrations_3d(points, tets, faces, fragment)
            best = min(best, time.perf_counter() - t0)
        # every vertex of B's bottom in A's closed volume, every vertex of A's top in B's
        assert np.count_nonzero(r.gap == -0.125) > 0.9 * 2 * n * n
        times.append(best)
        nfaces.append(len(faces))
    exponent = np.log(times[1] / times[0]) / np.log(nfaces[1] / nfaces[0])
    print(f"boundary faces {nfaces}, detection {times} s, exponent {exponent:.2f}")
    assert exponent < 1.5
