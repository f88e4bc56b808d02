"""The overlap volume between fragments (ngfracture.output.overlap3d, C++ tet_overlap.cpp)
against exact values: two tetrahedra whose intersection is known in closed form, two cubes
meshed apart overlapping by a box, the same rotated, a cracked bar pushed into itself, and
bodies that touch (exactly 0). Rounding tolerances: a volume made of n clipped pieces,
each with a relative rounding error of a few ulps, is exact to ~1e-13 of it; touching
bodies give 0 to the last bit (exact predicates).
"""
import math

import numpy as np
import pytest

from ngfracture.fracture import split3d as s3
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.geometry.solid import merge_bodies, tet_volumes
from ngfracture.geometry.structured import box_mesh
from ngfracture.output.overlap3d import (fragment_overlap_volume, read_step_vtu, tet_intersection_volume,
                                         vtu_overlap_volume)
from ngfracture.output.timeseries import TimeSeriesWriter
from split3d_util import cube_bar

UNIT = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
#: the unit tetrahedron reflected through (1/4, 1/4, 1/4) + (1/4, 1/4, 1/4): the cube [0, 1/2]^3
#: between the planes x + y + z = 1/2 and 1, volume 1/8 - 2/48 = 1/12
REFLECTED = np.array([0.5, 0.5, 0.5]) - UNIT
ROUND = 1e-13


def rotation(axis=(1.0, 2.0, 3.0), angle=0.7):
    """A rotation matrix (Rodrigues), not aligned with any axis."""
    k = np.asarray(axis) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


@pytest.mark.parametrize("b, exact", [
    (UNIT, 1 / 6),                                   # itself
    (UNIT * 0.5, 1 / 48),                            # a corner of it
    (UNIT[[0, 2, 1, 3]], 1 / 6),                     # itself, the other orientation
    (UNIT + [0.5, 0, 0], 1 / 48),                    # shifted by half: the corner tet of side 1/2
    (REFLECTED, 1 / 12),
    (UNIT * [-1, 1, 1], 0.0),                        # mirrored on x = 0: touches on a face
    (UNIT + [1, 0, 0], 0.0),                         # touches at the vertex (1, 0, 0)
    (UNIT + [0.5, 0.5, 0], 0.0),                     # touches along an edge x + y = 1
    (UNIT + [2, 2, 2], 0.0),                         # apart
    (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]), 0.0),   # flat
])
def test_two_tetrahedra_with_known_intersection(b, exact):
    v = tet_intersection_volume(UNIT, b)
    assert abs(v - exact) <= 4 * np.finfo(float).eps * max(exact, 1e-300), (v, exact)
    assert tet_intersection_volume(b, UNIT) == pytest.approx(exact, rel=4e-16, abs=0.0)
    if exact == 0.0:
        assert v == 0.0


def test_rotated_tetrahedra_keep_their_intersection():
    R = rotation()
    shift = np.array([0.3, -0.2, 0.1])
    a, b = UNIT @ R.T + shift, REFLECTED @ R.T + shift
    assert tet_intersection_volume(a, b) == pytest.approx(1 / 12, rel=ROUND)
    # mirrored on the rotated plane of a face: touching, exactly 0 by the exact predicates
    assert tet_intersection_volume(UNIT @ R.T, (UNIT * [-1, 1, 1]) @ R.T) == 0.0


def two_cubes(shift, lower=(0.0, 0.5, 1.0), upper=(0.0, 0.3, 0.65, 1.0)):
    """Unit cubes meshed apart with different grids, the second shifted; fragments 0 and 1."""
    a = merge_bodies([("a", box_mesh(lower, lower, lower)), ("b", box_mesh(upper, upper, upper))])
    X = a.points.copy()
    second = np.zeros(len(X), dtype=bool)
    second[np.unique(a.tets[a.regions == 2])] = True
    X[second] += shift
    return X, a.tets, a.regions - 1


@pytest.mark.parametrize("shift", [(0.5, 0.25, 0.125), (-0.75, 0.5, 0.0), (0.0, 0.0, 0.0)])
def test_two_cubes_overlap_by_a_box(shift):
    X, T, f = two_cubes(shift)
    ov = fragment_overlap_volume(X, T, f)
    exact = math.prod(1 - abs(s) for s in shift)
    assert abs(ov.volume - exact) <= ROUND * exact, (ov.volume, exact)
    assert ov.body_volume == 2.0 and len(ov.pairs) > 0 and np.all(ov.volumes > 0)
    assert np.all(f[ov.pairs[:, 0]] != f[ov.pairs[:, 1]]) and ov.candidates >= len(ov.pairs)
    assert math.fsum(ov.volumes) == pytest.approx(ov.volume, rel=1e-15)
    # rotated together: the same overlap
    R = rotation()
    assert fragment_overlap_volume(X @ R.T, T, f).volume == pytest.approx(exact, rel=ROUND)
    # one fragment: nothing to measure
    assert fragment_overlap_volume(X, T, np.zeros_like(f)).volume == 0.0


@pytest.mark.parametrize("shift", [(1.0, 0.0, 0.0), (1.0, 0.3, 0.2), (0.0, -1.0, 0.45), (0.2, 0.35, 1.0)])
def test_touching_cubes_overlap_by_exactly_zero(shift):
    X, T, f = two_cubes(shift)
    ov = fragment_overlap_volume(X, T, f)
    assert ov.volume == 0.0 and len(ov.pairs) == 0


def test_touching_rotated_cubes_on_one_grid_overlap_by_exactly_zero():
    """Rotated coordinates are rounded, but the contact plane holds faces of both cubes made of
    the same rounded points: the exact predicates see them touch."""
    a = box_mesh([0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 0.5, 1.0], [0.0, 1.0])
    f = (a.points[a.tets].mean(axis=1)[:, 0] > 1.0).astype(np.int64)    # two halves sharing x = 1
    X = a.points @ rotation().T
    ov = fragment_overlap_volume(X, a.tets, f)
    assert ov.candidates > 0 and ov.volume == 0.0


def cracked_bar():
    a = cube_bar(2, 2, 8)
    for v in np.flatnonzero(a.points[:, 2] == 4.0):
        a = s3.split_vertices_3d(a, [v], [np.array([0.0, 0.0, 1.0])]).arrays
    return a, FragmentStatistics(a)


@pytest.mark.parametrize("d", [0.0, 0.25, 1.5])
def test_cracked_bar_pushed_into_itself(d):
    """A 2 x 2 x 8 bar cracked through on z = 4: its lips coincide (0 exactly); the upper
    half pushed down by d overlaps the lower by 2 x 2 x d."""
    a, st = cracked_bar()
    assert st.count == 2
    upper = st.fragment == st.fragment[np.argmax(a.points[a.tets].mean(axis=1)[:, 2])]
    X = a.points.copy()
    X[np.unique(a.tets[upper])] -= [0.0, 0.0, d]
    ov = fragment_overlap_volume(X, a.tets, st.fragment)
    assert abs(ov.volume - 4 * d) <= ROUND * 4 * d
    if d == 0.0:
        assert ov.volume == 0.0 and len(ov.pairs) == 0
    else:
        assert ov.candidates > 0 and np.all(st.fragment[ov.pairs[:, 0]] != st.fragment[ov.pairs[:, 1]])


def test_lips_of_a_partial_crack_in_one_fragment_are_no_overlap():
    a = cube_bar(2, 2, 8)
    a = s3.split_vertices_3d(a, [int(np.flatnonzero(np.all(a.points == [0.0, 0.0, 4.0], axis=1))[0])],
                             [np.array([0.0, 0.0, 1.0])]).arrays
    st = FragmentStatistics(a)
    assert st.count == 1 and len(a.boundary_faces("crack"))
    assert fragment_overlap_volume(a.points, a.tets, st.fragment).volume == 0.0


def test_the_written_file_gives_the_same_overlap(tmp_path):
    X, T, f = two_cubes((0.5, 0.25, 0.125))
    a = merge_bodies([("a", box_mesh(*3 * [(0.0, 0.5, 1.0)])), ("b", box_mesh(*3 * [(0.0, 0.3, 0.65, 1.0)]))])
    u = X - a.points
    TimeSeriesWriter(tmp_path).write(0, 0.0, a, u, f)
    P, U, tets, frag = read_step_vtu(tmp_path / "step_000000.vtu")
    assert np.array_equal(P, a.points) and np.array_equal(U, u) and np.array_equal(tets, a.tets)
    ov = vtu_overlap_volume(tmp_path / "step_000000.vtu")
    want = fragment_overlap_volume(a.points + u, a.tets, f)
    assert ov.volume == want.volume and np.array_equal(ov.pairs, want.pairs)
    assert ov.body_volume == math.fsum(tet_volumes(a.points, a.tets)) == 2.0


@pytest.mark.parametrize("call, message", [
    (lambda: tet_intersection_volume(UNIT[:3], UNIT), "shape"),
    (lambda: tet_intersection_volume(UNIT, UNIT * np.nan), "finite"),
    (lambda: fragment_overlap_volume(UNIT, [[0, 1, 2, 4]], [0]), "vertex number"),
    (lambda: fragment_overlap_volume(UNIT, [[0, 1, 2, 3]], [0, 1]), "fragment"),
    (lambda: fragment_overlap_volume(UNIT, [[0, 1, 2, 3]], [0.5]), "fragment"),
    (lambda: fragment_overlap_volume(UNIT[:, :2], [[0, 1, 2, 3]], [0]), "points"),
])
def test_bad_input_is_refused(call, message):
    with pytest.raises(ValueError, match=message):
        call()
