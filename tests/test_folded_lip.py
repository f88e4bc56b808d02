"""Found rows at a folded lip between two fragments at points of two copies (contact/copies3d.py).

A crack cut a body into fragment 0 below and fragment 1 above the roof z = -a |x| (a ridge
along the y axis, folded by the angle 2 atan(a) between its slopes). Near the ridge point
O = 0 the lower side B = {z <= -a |x|} is convex and the upper side A its complement. Every
point of the roof has two copies, one per fragment (vertices 0..4 on fragment 0, 5..9 on
fragment 1, bitwise-equal points): fragment 0's faces point up (out of B), fragment 1's
the other way.

The exact first-order condition for the copies s = 5 (on 1) and t = 0 (on 0) of O to stay
apart, for a relative displacement d = x_s - x_t: A + d and B do not overlap iff
x_t - x_s lies in B, i.e. d_z >= a |d_x| (docs/contact.md, "Crack lips in 3D",
partner-face rows). The fixed rows (``fragment_pair_rows``) hold s on one face at t only
(points of two copies); a detected row of s on a face at t (as the detection reports s
found inside B) is completed by ``folded_rows_at_copies`` with the rows on the faces at t
off its plane. Checked, with rows C d + g >= 0 (g = 0, the copies coincide):

* folded (a = 1, 90 degrees): the found row with its completion holds exactly the d with
  d_z >= a |d_x|, on 2000 random directions away from the boundary of that set, and the
  ray d = (1, 0, 0) that the one fixed row let through (s's side slides along one slope
  past the fold and reaches across t; the coarse sphere's failure at x = 2.533e-3); no row
  on the face coplanar with the found one (nearly parallel rows block the slip);
* flat (a = 0): nothing is added; nor where the copies are tied by the scene's rows
  (``tied``) or are lips of one fragment (the fixed kink rows have those faces).
"""
import numpy as np

from ngfracture.contact.copies3d import folded_rows_at_copies
from ngfracture.contact.junctions3d import fragment_pair_rows
from ngfracture.contact.rows3d import NodeToFaceRows, face_gap_rows


def roof(a):
    """Points, faces and vertex fragments of the two coincident sides of the folded lip."""
    P = np.array([[0.0, 0, 0], [0.0, 1, 0], [0.0, -1, 0], [-1.0, 0, -a], [1.0, 0, -a]])
    O, Q1, Q2, L, R = range(5)
    lower = np.array([[O, R, Q1], [O, Q1, L], [O, L, Q2], [O, Q2, R]])     # normals up
    points = np.vstack([P, P])
    faces = np.vstack([lower, lower[:, ::-1] + 5])
    fragment = np.repeat([0, 1], 5)
    return points, faces, fragment


def found_row(points, faces, slave, face):
    """The row of ``slave`` on ``face`` projected at its copy, corner 0 (as found_rows_at_copies makes it)."""
    master = faces[[face]]
    p = points[master[0]]
    n = np.cross(p[1] - p[0], p[2] - p[0])
    normal = (n / np.linalg.norm(n))[None, :]
    bary = np.array([[1.0, 0.0, 0.0]])
    slaves = np.array([slave])
    _, g = face_gap_rows(points, slaves, master, bary, normal)
    return NodeToFaceRows(slave=slaves, master=master, face=np.array([face]), bary=bary, normal=normal,
                          dist=g.copy(), g=g, nv=len(points))


def gaps_of(rows, slave, d):
    """The gaps C u + g of the rows where ``slave`` moved by d, everything else at rest."""
    u = np.zeros(3 * rows.nv)
    u[slave + rows.nv * np.arange(3)] = d
    return rows.C @ u + rows.g


def test_folded_lip_rows_are_the_exact_condition():
    a = 1.0
    points, faces, fragment = roof(a)
    fixed = fragment_pair_rows(points, faces, fragment)
    assert np.count_nonzero(fixed.slave == 5) == 1                         # one fixed row at two copies
    found = found_row(points, faces, 5, 0)                                 # s on the right slope [O, R, Q1]
    folded = folded_rows_at_copies(points, faces, found, np.array([True]), fragment)
    assert folded.slave.tolist() == [5, 5] and folded.face.tolist() == [1, 2]    # the left slope; not 3
    assert np.all(folded.g == 0.0) and np.all(folded.bary[:, 0] == 1.0)
    rows = NodeToFaceRows.stack([found, folded])
    rng = np.random.default_rng(7)
    d = rng.normal(size=(2000, 3))
    margin = d[:, 2] - a * np.abs(d[:, 0])
    d = d[np.abs(margin) > 1e-3 * np.linalg.norm(d, axis=1)]
    for di in d:
        assert np.all(gaps_of(rows, 5, di) >= 0) == (di[2] >= a * abs(di[0])), di
    slide = np.array([1.0, 0, 0])
    assert np.all(gaps_of(fixed, 5, slide)[fixed.slave == 5] >= 0)           # one row lets it through
    assert abs(gaps_of(rows, 5, slide).min() + np.sqrt(0.5)) <= 1e-15       # the left slope's row does not


def test_flat_lip_adds_nothing():
    points, faces, fragment = roof(0.0)
    folded = folded_rows_at_copies(points, faces, found_row(points, faces, 5, 0), np.array([True]), fragment)
    assert len(folded) == 0
    points, faces, fragment = roof(1.0)
    found = found_row(points, faces, 5, 0)
    assert len(folded_rows_at_copies(points, faces, found, np.array([False]), fragment)) == 0
    # copies tied by the scene's own rows (the sphere's stick rows) keep their one row
    assert len(folded_rows_at_copies(points, faces, found, np.array([True]), fragment, tied=np.array([0 * 10 + 5]))) == 0
    # lips of one fragment have their kink rows among the fixed rows
    assert len(folded_rows_at_copies(points, faces, found, np.array([True]), np.zeros(10, dtype=np.int64))) == 0


def test_tied_pairs_of_two_vertex_rows_only():
    from scipy.sparse import csr_matrix
    from ngfracture.contact.active_set3d import tied_pairs
    nv = 4
    # a stick-like row on vertices 3 and 1 (components x and y), a mode row on 0, 1, 2
    H = csr_matrix(([1.0, -1.0, 1.0, 1.0, 1.0, 1.0], ([0, 0, 0, 1, 1, 1], [3, nv + 1, 2 * nv + 3, 0, 1, 2])),
                   shape=(2, 3 * nv))
    assert tied_pairs(H, nv).tolist() == [1 * nv + 3]
    assert len(tied_pairs(None, nv)) == 0
