"""clipped3d.beyond_face: how far a node-to-face row's slave lies beyond the edges of its face.

The active set releases a found row that is active but no longer holds its slave against
the master (ActiveSet3d._beyond_face): the slave outside the master's fragment and beyond
its face's edges. The length is the in-plane part of x_s - q, q the foot with its negative
barycentrics set to 0 and the rest rescaled, as the re-linearisation clips them; the
expected lengths are worked out by hand on the right triangle (0, 0), (1, 0), (0, 1).
"""
import numpy as np

from ngfracture.contact.clipped3d import beyond_face
from ngfracture.contact.rows3d import NodeToFaceRows


def rows_on_unit_face(slaves, nv):
    m = len(slaves)
    return NodeToFaceRows(slave=np.asarray(slaves), master=np.tile([0, 1, 2], (m, 1)), face=np.zeros(m, dtype=np.int64),
                          bary=np.full((m, 3), 1.0 / 3.0), normal=np.tile([0.0, 0.0, 1.0], (m, 1)),
                          dist=np.zeros(m), g=np.zeros(m), nv=nv)


def test_foot_inside_is_zero_and_beyond_an_edge_is_the_distance_in_the_plane():
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
                  [0.25, 0.25, 0.5],        # above the face: foot inside
                  [0.5, -0.5, -0.25],       # foot (0.5, -0.5): q = (1, 0.5, 0) / 1.5 -> (1/3, 0)
                  [-0.5, 0.5, 0.0]])        # foot (-0.5, 0.5): q = (1, 0, 0.5) / 1.5 -> (0, 1/3)
    point = np.arange(len(X))
    out = beyond_face(X, rows_on_unit_face([3, 4, 5], len(X)), np.zeros_like(X), point)
    assert out[0] <= 1e-15
    expected = np.hypot(1.0 / 6.0, 0.5)
    assert abs(out[1] - expected) <= 1e-15 and abs(out[2] - expected) <= 1e-15


def test_displacement_counts_and_rows_at_a_copy_are_zero():
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.2, 0.2, 0.0]])
    U = np.zeros_like(X)
    U[4] = [0.8, -0.4, 0.1]                 # to (1, -0.2, 0.1): q = (0.2, 1, 0) / 1.2 -> (5/6, 0)
    U[3] = [-0.3, -0.3, 0.0]                # the copy of vertex 0, slid off the face
    point = np.array([0, 1, 2, 0, 3])       # vertex 3 is a copy of vertex 0
    out = beyond_face(X, rows_on_unit_face([4, 3], len(X)), U, point)
    assert abs(out[0] - np.hypot(1.0 / 6.0, 0.2)) <= 1e-15
    assert out[1] == 0.0
