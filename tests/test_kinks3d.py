"""Partner faces of the junction rows (ngfracture.contact.kinks3d) and their rows (rows3d).

A point O with copies 0, 1, 2 (a crack reaching an interface: the core's vertex and two
lip copies) and a point Q with copies 3, 4 (two copies only). Faces: [0, a, b] at copy 0
and its coincident partner [1, b', a'] at copy 1 (same reference points, opposite
orientation); [2, c, a''] at copy 2, coincident with nothing at 1; [3, a, c] and its
partner [4, c', a'] at Q.
"""
import numpy as np
import pytest

from ngfracture.contact.kinks3d import partner_faces, point_groups
from ngfracture.contact.rows3d import twin_rows


def configuration():
    O, A, B, C, Q = [0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0], [0.0, 0, 1], [1.0, 1, 1]
    points = np.array([O, O, O, Q, Q, A, B, A, B, C, A, C, A], dtype=float)
    #                  0  1  2  3  4  5  6  7  8  9 10 11 12
    faces = np.array([[0, 5, 6], [1, 8, 7], [2, 9, 10], [3, 5, 11], [4, 11, 12]])
    return points, faces


def test_point_groups_number_equal_points_alike():
    points, faces = configuration()
    vertex, group = point_groups(points, faces)
    assert sorted(vertex.tolist()) == list(range(13))
    ids = dict(zip(vertex.tolist(), group.tolist()))
    assert ids[0] == ids[1] == ids[2] and ids[3] == ids[4] and ids[5] == ids[7] == ids[10] == ids[12]
    assert len(set(ids.values())) == 5


def test_partner_faces_at_three_copies_only_higher_slave():
    points, faces = configuration()
    s, t = np.array([1, 2, 0, 4]), np.array([0, 0, 1, 3])
    slave, face, corner = partner_faces(points, faces, s, t, all_pairs=False)
    # 1 on [0, 5, 6] (its partner), 2 has no face coincident with one at 0, 0 < 1 is no slave,
    # Q has two copies only
    assert slave.tolist() == [1] and face.tolist() == [0] and corner.tolist() == [0]
    slave, face, corner = partner_faces(points, faces, s, t, all_pairs=True)
    assert slave.tolist() == [1, 4] and face.tolist() == [0, 3] and corner.tolist() == [0, 0]


def test_twin_rows_keep_one_row_where_the_partner_is_the_most_opposed_face():
    points, faces = configuration()
    slave = np.zeros(len(points), dtype=bool)
    slave[1] = True
    rows = twin_rows(points, faces, slave)
    # the most opposed face at the copies of 1 is its partner [0, 5, 6]: one row, not two
    assert rows.slave.tolist() == [1] and rows.face.tolist() == [0]
    np.testing.assert_array_equal(rows.normal, [[0.0, 0.0, 1.0]])
    assert np.all(rows.g == 0.0) and rows.bary.tolist() == [[1.0, 0.0, 0.0]]


def test_lengths_must_match():
    points, faces = configuration()
    with pytest.raises(IndexError):
        partner_faces(points, faces, np.array([1, 2]), np.array([0]), all_pairs=True)
