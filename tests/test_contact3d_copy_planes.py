"""Rows at copies found by their planes: copies behind a partner face at their copy
(``contact/copies3d.py``, ``behind_partner_rows``) and junction edges pushed into the wedge
of a diagonal neighbour (``contact/wedges3d.py``).

Two blocks meshed apart on an interface bent by a slope a on either side of the line
x = 1/2 (faces 2 a apart, less than the partner-face rows' KINK): the fixed rows hold
each copy against one face at its copy.

- The upper block moved along the left slope, (s, 0, -a s): its copies at x >= 1/2 go
  behind the planes of the lower block's right faces at their copies by 2 a s / sqrt(1 +
  a^2) (exact); each such copy gets a row on every partner face at its copy (those on the
  left, which it slid along, with gap 0), in the fixed rows' direction only (slaves on the
  upper block), projected at the copy, and the row's linearisation C u + g is its gap (a
  translation turns no normal).
- Moved along the right slope, (s, 0, a s): nothing is behind a plane; no row.

Four blocks around the line x = y = 1/2 (quadrants Q1 .. Q4 counter-clockwise from
x, y < 1/2), meshed apart: the line's edges have a copy on every block, Q1 and Q3 (and Q2
and Q4) are diagonal neighbours there, sharing the edge but no face.

- The pairs: every edge of the line gives the four ordered diagonal pairs and no pair of
  face neighbours.
- Q1 moved by (d, d, 0) as a whole: its copy of the line lies in Q3's wedge (behind both of
  Q3's faces there by d), and Q3's in Q1's, one condition: the ends of Q3's edges (the
  higher fragment) get a row on a face of Q1's wedge, its gap -d at the moved
  configuration, exactly the row's linearisation C u + g (a translation turns no normal).
- Q1 moved by (d, -d, 0): its line is behind one of Q3's faces only, out of the wedge: no
  row; nor for d below the tolerance.
"""
import numpy as np
import pytest

from ngfracture.contact.copies3d import behind_partner_rows
from ngfracture.contact.kinks3d import KINK
from ngfracture.contact.setup3d import MeshSetup3d
from ngfracture.contact.wedges3d import diagonal_edges, wedge_rows
from ngfracture.geometry.solid import merge_bodies
from ngfracture.geometry.structured import box_mesh
from ngfracture.output.overlap3d import fragment_overlap_volume

LOW, HIGH, Z = np.linspace(0.0, 0.5, 3), np.linspace(0.5, 1.0, 3), np.linspace(0.0, 0.5, 3)


SLOPE = 0.01


@pytest.fixture(scope="module")
def bent():
    """Two blocks on the interface z = 1/2 + SLOPE |x - 1/2| (all points moved so, copies equal)."""
    grid = np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 3)
    arrays = merge_bodies([("lower", box_mesh(*grid, [0.0, 0.25, 0.5])), ("upper", box_mesh(*grid, [0.5, 0.75, 1.0]))])
    P = arrays.points.copy()
    P[:, 2] += SLOPE * np.abs(P[:, 0] - 0.5)
    arrays.points = P
    fragment = (arrays.regions - 1).astype(np.int64)
    return arrays, MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)


def test_the_bend_is_below_the_kink_rows_angle(bent):
    assert 1.0 - (1.0 - SLOPE ** 2) / (1.0 + SLOPE ** 2) < KINK


@pytest.mark.parametrize("rise", [-1.0, 1.0])
def test_copies_behind_a_partner_plane_get_rows_with_their_gap(bent, rise):
    arrays, setup = bent
    s = 1e-3
    U = np.zeros_like(arrays.points)
    upper = setup.vertex_fragment == 1
    U[upper] = (s, 0.0, rise * SLOPE * s)
    rows = behind_partner_rows(setup.partners, U, 1e-9, setup.copy_index)
    if rise > 0:
        assert len(rows) == 0
        return
    X = arrays.points
    on_interface = upper & np.isin(np.arange(len(X)), setup.partners[0])
    right = on_interface & (X[:, 0] >= 0.5)
    assert set(rows.slave.tolist()) == set(np.flatnonzero(right).tolist())
    # every partner face of a pair hit gets its row; those behind are the right faces
    depth = 2 * SLOPE * s / np.sqrt(1 + SLOPE ** 2)
    on_right = np.all(X[rows.master][:, :, 0] >= 0.5, axis=1)
    assert np.allclose(rows.dist[on_right], -depth, rtol=1e-9, atol=0)
    assert np.all(np.abs(rows.dist[~on_right]) <= 1e-15)              # slid along their plane
    slave, face, corner = setup.partners
    hit = np.isin(slave, rows.slave)
    assert len(rows) == hit.sum()
    assert np.allclose(rows.C @ U.T.ravel() + rows.g, rows.dist, rtol=1e-9, atol=1e-16)   # rounding at gap 0
    corner = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    assert np.array_equal(X[corner], X[rows.slave]) and np.all(rows.bary.max(axis=1) == 1.0)


@pytest.fixture(scope="module")
def quadrants():
    arrays = merge_bodies([("q1", box_mesh(LOW, LOW, Z)), ("q2", box_mesh(HIGH, LOW, Z)),
                           ("q3", box_mesh(HIGH, HIGH, Z)), ("q4", box_mesh(LOW, HIGH, Z))])
    fragment = (arrays.regions - 1).astype(np.int64)
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)
    return arrays, setup


def moved(arrays, setup, shift):
    """Displacements moving Q1 (fragment 0) by ``shift``, the others not."""
    U = np.zeros_like(arrays.points)
    U[setup.vertex_fragment == 0] = shift
    return U


def test_pairs_are_the_diagonal_copies_of_the_line(quadrants):
    arrays, setup = quadrants
    pairs = setup.diagonal_edges
    X, vf = arrays.points, setup.vertex_fragment
    on_line = np.all(X[pairs.a][:, :, :2] == 0.5, axis=(1, 2))
    assert on_line.all()
    line_edges = len(Z) - 1
    assert len(pairs) == 4 * line_edges
    fa, fb = vf[pairs.a[:, 0]], vf[pairs.b[:, 0]]
    assert set(zip(fa.tolist(), fb.tolist())) == {(0, 2), (2, 0), (1, 3), (3, 1)}
    assert np.array_equal(X[pairs.a], X[pairs.b])                 # ends matched to their copies
    again = diagonal_edges(setup.edge_detector.edges, setup.faces_at_edge, vf, setup.copy_index)
    assert np.array_equal(again.a, pairs.a) and np.array_equal(again.b_faces, pairs.b_faces)


def test_edge_in_the_wedge_gets_rows_with_its_gap(quadrants):
    arrays, setup = quadrants
    d = 1e-3
    U = moved(arrays, setup, (d, d, 0.0))
    rows = wedge_rows(setup.diagonal_edges, U, 1e-6, setup.copy_index, setup.vertex_fragment)
    vf = setup.vertex_fragment
    line_edges = len(Z) - 1
    # Q1's edge in Q3's wedge and Q3's in Q1's: one condition, the rows of Q3's ends (the
    # higher fragment, the fixed rows' direction)
    assert len(rows) == 2 * line_edges
    assert np.all(vf[rows.slave] == 2) and np.all(vf[rows.master[:, 0]] == 0)
    assert np.allclose(rows.dist, -d, rtol=0, atol=1e-15)
    linear = rows.C @ U.T.ravel() + rows.g
    assert np.allclose(linear, rows.dist, rtol=0, atol=1e-15)
    # projected at the copy: the slave's copy is the master corner with barycentric 1
    corner = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    assert np.array_equal(arrays.points[corner], arrays.points[rows.slave])


@pytest.mark.parametrize("shift, tol", [((1e-3, -1e-3, 0.0), 1e-6), ((1e-7, 1e-7, 0.0), 1e-6)])
def test_no_rows_out_of_the_wedge_or_below_the_tolerance(quadrants, shift, tol):
    arrays, setup = quadrants
    U = moved(arrays, setup, shift)
    rows = wedge_rows(setup.diagonal_edges, U, tol, setup.copy_index, setup.vertex_fragment)
    assert len(rows) == 0


def test_an_edge_inside_the_wedge_towards_one_end_only_gets_the_row_of_that_end(quadrants):
    """Q1's line moved by u(z), linear in z: (d, d, 0) at the top z = 1/2 (behind both of
    Q3's faces there by d) and (3d, -3d, 0) at z = 1/4 (behind the plane x = 1/2 by 3d, in
    front of y = 1/2 by 3d). The gaps are linear along the upper edge, its midpoint out of
    the wedge (behind x = 1/2 by 2d, in front of y = 1/2 by d), the part above z = 3/8 in
    it. Out through the plane y = 1/2 only the top end has to move (by d; through x = 1/2
    both, by up to 3d): the top end gets the row of the face on y = 1/2, gap -d (less the
    face's turn); the lower
    edge (z <= 1/4, in front of y = 1/2 all along) gets none. As for the moves above, the
    row is the higher fragment's end on Q1's face."""
    arrays, setup = quadrants
    X = arrays.points
    d = 1e-4
    U = np.zeros_like(X)
    q1 = setup.vertex_fragment == 0
    w = (X[q1, 2] - 0.25) / 0.25                        # 0 at z = 1/4, 1 at z = 1/2
    U[q1] = np.stack([3 * d - 2 * d * w, -3 * d + 4 * d * w, 0 * w], axis=1)
    rows = wedge_rows(setup.diagonal_edges, U, 1e-9, setup.copy_index, setup.vertex_fragment)
    assert len(rows) == 1
    vf = setup.vertex_fragment
    assert vf[rows.slave[0]] == 2 and np.array_equal(X[rows.slave[0]], [0.5, 0.5, 0.5])
    master = rows.master[0]
    assert np.all(vf[master] == 0) and np.all(X[master, 1] == 0.5)   # Q1's face on y = 1/2
    # Q1's face turns with u_y(z): unit normal (0, 1, -16 d) / sqrt(1 + 256 d^2)
    assert abs(rows.dist[0] + d / np.sqrt(1 + 256 * d * d)) <= 1e-12 * d
    # its linearisation, with the face's reference normal (0, 1, 0): -d
    assert abs(rows.C[0] @ U.T.ravel() + rows.g[0] + d) <= 1e-12 * d


def _unit(degrees):
    t = np.radians(degrees)
    return np.array([np.cos(t), np.sin(t), 0.0])


@pytest.fixture(scope="module")
def surface_blocks():
    """Three blocks around the line x = y = 0 meshed apart, quadrants mapped linearly onto the
    sectors A [0, 60] (fragment 0), C [60, 120] (1) and B [120, 180] (2), the outside below
    y = 0: A's and B's wedges at the line are both bounded by the plane y = 0 (as two
    pieces' faces on a flat outer surface) and share no face."""
    neg, pos, zs = np.linspace(-0.5, 0.0, 3), np.linspace(0.0, 0.5, 3), [0.0, 0.25, 0.5]
    arrays = merge_bodies([("a", box_mesh(pos, pos, zs)), ("c", box_mesh(neg, pos, zs)), ("b", box_mesh(neg, neg, zs))])
    P = arrays.points
    x, y = P[:, :1], P[:, 1:2]
    q1 = x * _unit(0) + y * _unit(60)
    q2 = y * _unit(60) - x * _unit(120)
    q3 = -x * _unit(120) - y * _unit(180)
    mapped = np.where((x >= 0) & (y >= 0), q1, np.where(y >= 0, q2, q3)) + 0.0   # one formula per point
    mapped[:, 2] = P[:, 2]
    arrays.points = mapped
    fragment = (arrays.regions - 1).astype(np.int64)
    return arrays, MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)


def test_wedges_on_one_plane_overlap_exactly_where_their_rows_read_a_penetration(surface_blocks):
    """A moved by random in-plane translations d (|d_x|, |d_y| <= 1e-3): A and B overlap
    (exact clipping of their tetrahedra) exactly where the wedge rows of the line read a
    negative gap. The planes that can separate them are B's face at 120 degrees and A's at
    60 (the plane y = 0 has the other wedge behind it), with the gaps n_B . d and -n_A . d;
    a translation along y = 0 towards B, which B's planes read as on one (gap 0) and behind
    the other, overlaps: the midpoint rule alone, behind both of B's planes, misses it.
    Every row is on one of the two separating planes, never on y = 0."""
    arrays, setup = surface_blocks
    X, T = arrays.points, arrays.tets
    vf = setup.vertex_fragment
    piece = vf[T[:, 0]]
    n_b, n_a = _unit(30), _unit(150)                       # outward normals of B at 120, A at 60
    rng = np.random.default_rng(3)
    moves = [np.array([-1e-3, 0.0])] + [1e-3 * rng.uniform(-1, 1, 2) for _ in range(60)]
    checked = missed_by_middle = 0
    for d in moves:
        separating = np.array([n_b[:2] @ d, -(n_a[:2] @ d)])
        if np.abs(separating).min() < 1e-6:
            continue                                        # on a boundary of the allowed set
        U = np.zeros_like(X)
        U[vf == 0, :2] = d
        rows = wedge_rows(setup.diagonal_edges, U, 0.0, setup.copy_index, vf)
        overlap = fragment_overlap_volume(X + U, T, piece)
        ab = sum(v for (s, t), v in zip(overlap.pairs, overlap.volumes) if {piece[s], piece[t]} == {0, 2})
        assert (ab > 0) == (len(rows) > 0), (d, ab, rows.dist)
        if len(rows):
            assert separating.max() < 0
            # every row on a plane that separates the wedges (B's at 120, A's at 60), with its gap
            plane = np.abs(rows.normal @ n_b) > 1 - 1e-12
            assert np.all(plane | (np.abs(rows.normal @ n_a) > 1 - 1e-12))
            assert np.allclose(rows.dist, np.where(plane, separating[0], separating[1]), rtol=1e-12, atol=0)
            missed_by_middle += max(-d[1], separating[0]) >= 0      # B's plane y = 0 reads -d_y
        checked += 1
    assert checked >= 50 and missed_by_middle >= 1
