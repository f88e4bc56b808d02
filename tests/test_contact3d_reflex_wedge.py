"""Edge copies behind a face of another copy's reflex wedge (``contact/wedges3d.py``,
``edge_copies`` and ``reflex_wedge_rows``).

Three blocks around the line x = y = 0, z in [0, H], meshed apart (``sector_blocks``): A on
the angles [0, 60] degrees, C on [60, 120], B on [120, 360], a reflex wedge of 240 degrees.
A shares its face at 0 degrees with B and its face at 60 with C; B's face at 120 is shared
with C, no partner face of A. The line's one edge has a copy on each block.

- A moved by eps (-1, 1/2) and stretched along the line (its ends out of the blocks'
  z range), C by eps (-1, 2), B held: every partner face holds (A in front of B's face at
  0 by eps / 2, of C's by 3 eps / 4, C in front of B's face at 120 by (1 - sqrt 3 / 2) eps),
  no vertex lies in another block, yet A's edge has entered B's wedge behind its face at
  120: the blocks overlap by the triangle of A's translated wedge in B's sector [120, 180]
  times H (exact clipping). Both ends of A's edge get a row on that face, with the gap
  (-sqrt 3 / 2 + 1/4) eps, equal to the row's linearisation; nothing else gives a row.
- Random motions of A and C (B held): the blocks overlap exactly where a partner row or a
  reflex row is violated; without the reflex rows, motions that overlap pass all rows
  (A's edge moved into B's sector [120, 180] with C out of its way).
- The row re-linearised where the copies meet, against its gap n_f(x) . (x_a - x_b) at
  configurations h away: the difference falls as h^2 (the frozen normal is the exact
  linearisation there).
- A's edge shortened instead (its ends inside B, found deep by the node-to-face detection
  on a face at their copy whose plane they are on): the active set's candidates still have
  the two rows on B's face at 120 (the other rows at copies leave such a slave to its
  detected row, which holds it only in front of one face of the wedge).
"""
import numpy as np
import pytest

from ngfracture.contact.active_set import Geometry
from ngfracture.contact.active_set3d import ActiveSet3d
from ngfracture.contact.copies3d import behind_partner_rows
from ngfracture.contact.rows3d import relinearise_node_to_face
from ngfracture.contact.setup3d import MeshSetup3d
from ngfracture.contact.wedges3d import edge_copies, reflex_wedge_rows, wedge_rows
from ngfracture.output.overlap3d import fragment_overlap_volume
from sector_blocks import sector_blocks, unit

H = 0.5
EPS = 1e-3
@pytest.fixture(scope="module")
def blocks():
    arrays, fragment = sector_blocks(2, [0.0, H])                # A 0, C 1, B 2; one edge on the line
    return arrays, MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)


def motion(arrays, setup, d_a, d_c, stretch=EPS):
    """A moved by d_a and stretched along z by ``stretch`` (ends out of [0, H]), C by d_c."""
    U = np.zeros_like(arrays.points)
    vf = setup.vertex_fragment
    U[vf == 0, :2] = d_a
    U[vf == 0, 2] = stretch * (arrays.points[vf == 0, 2] / H - 0.5)
    U[vf == 1, :2] = d_c
    return U


def test_tets_positive_and_copies_of_the_line(blocks):
    arrays, setup = blocks
    p = arrays.points[arrays.tets]
    vol = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
    assert vol.min() > 0
    pairs = setup.edge_copies
    X = arrays.points
    line = np.all(X[pairs.a][:, :, :2] == 0.0, axis=(1, 2))
    vf = setup.vertex_fragment
    fa, fb = vf[pairs.a[line, 0]], vf[pairs.b[line, 0]]
    # the line's edge: all six ordered pairs, each with one face of b a partner of a
    assert sorted(zip(fa.tolist(), fb.tolist())) == [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]
    assert np.array_equal(pairs.partner[line].sum(axis=1), np.ones(6, dtype=np.int64))
    assert np.array_equal(X[pairs.a], X[pairs.b])                # ends matched to their copies
    assert not np.any(pairs.partner.all(axis=1))
    again = edge_copies(setup.edge_detector.edges, setup.faces_at_edge, setup.copy_index)
    assert np.array_equal(again.a, pairs.a) and np.array_equal(again.partner, pairs.partner)


def overlap_triangle(d):
    """Area of A's wedge [0, 60] moved by d inside B's sector [120, 180] (d in that sector)."""
    def meet(p, direction):
        # p + t direction on the line through 0 along unit(120): cross(unit(120), p + t dir) = 0
        u = unit(120)[:2]
        t = -(u[0] * p[1] - u[1] * p[0]) / (u[0] * direction[1] - u[1] * direction[0])
        return p + t * direction
    p1, p2 = meet(d, unit(0)[:2]), meet(d, unit(60)[:2])
    e1, e2 = p1 - d, p2 - d
    return abs(e1[0] * e2[1] - e1[1] * e2[0]) / 2


def test_edge_in_the_reflex_wedge_gets_rows_nothing_else_does(blocks):
    arrays, setup = blocks
    d_a, d_c = EPS * np.array([-1.0, 0.5]), EPS * np.array([-1.0, 2.0])
    U = motion(arrays, setup, d_a, d_c)
    X, vf = arrays.points, setup.vertex_fragment
    # the overlap is A's translated wedge in B's sector [120, 180], along the whole edge
    ov = fragment_overlap_volume(X + U, arrays.tets, vf[arrays.tets[:, 0]])
    assert ov.volume == pytest.approx(overlap_triangle(d_a) * H, rel=1e-9)
    # the other rules see nothing: no vertex in another block, no copy behind a partner
    # plane, no diagonal wedge
    pen = setup.detector.detect(U)
    assert not np.any(pen.gap < 0)
    assert len(behind_partner_rows(setup.partners, U, 0.0, setup.copy_index)) == 0
    assert len(wedge_rows(setup.diagonal_edges, U, 0.0, setup.copy_index, vf)) == 0
    rows = reflex_wedge_rows(setup.edge_copies, U, 1e-9, setup.copy_index)
    assert len(rows) == 2
    assert np.all(vf[rows.slave] == 0) and np.all(vf[rows.master] == 2)
    assert np.all(X[rows.slave][:, :2] == 0.0)                    # both ends of A's edge
    assert np.allclose(rows.normal, unit(30), rtol=0, atol=1e-15)  # B's face at 120, outward
    gap = (-np.sqrt(3) / 2 + 0.25) * EPS
    assert np.allclose(rows.dist, gap, rtol=1e-12, atol=0)
    assert np.allclose(rows.C @ U.T.ravel() + rows.g, rows.dist, rtol=1e-12, atol=0)
    corner = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    assert np.array_equal(X[corner], X[rows.slave]) and np.all(rows.bary.max(axis=1) == 1.0)
    # below the tolerance: none
    assert len(reflex_wedge_rows(setup.edge_copies, U, -gap * 1.001, setup.copy_index)) == 0


def partner_gaps(d_a, d_c):
    """The gaps of the partner faces' rows: A on B's face at 0, A on C's at 60, C on B's at 120."""
    return np.array([unit(90)[:2] @ d_a, unit(-30)[:2] @ (d_a - d_c), unit(30)[:2] @ d_c])


def test_overlap_exactly_where_a_row_is_violated(blocks):
    arrays, setup = blocks
    X, vf = arrays.points, setup.vertex_fragment
    rng = np.random.default_rng(7)
    passed_partner_rows, n = 0, 0
    while n < 120:
        # C mostly moved up and to the left, out of A's way into B's wedge
        d_a, d_c = EPS * rng.uniform(-1, 1, 2), EPS * rng.uniform((-1, -0.5), (0.5, 2))
        U = motion(arrays, setup, d_a, d_c)
        rows = reflex_wedge_rows(setup.edge_copies, U, 0.0, setup.copy_index)
        gaps = np.concatenate([partner_gaps(d_a, d_c), rows.dist])
        if np.abs(gaps).min() < 1e-3 * EPS:
            continue                              # a motion on a boundary of the allowed set
        n += 1
        volume = fragment_overlap_volume(X + U, arrays.tets, vf[arrays.tets[:, 0]]).volume
        assert (volume > 0) == (gaps.min() < 0), (d_a, d_c, volume, gaps)
        passed_partner_rows += volume > 0 and partner_gaps(d_a, d_c).min() > 0
    assert passed_partner_rows >= 5               # the reflex rows are needed


@pytest.mark.parametrize("seed", [0, 1])
def test_linearisation_error_is_second_order(blocks, seed):
    arrays, setup = blocks
    X = arrays.points
    U1 = motion(arrays, setup, EPS * np.array([-1.0, 0.5]), EPS * np.array([-1.0, 2.0]))
    rows = reflex_wedge_rows(setup.edge_copies, U1, 1e-9, setup.copy_index)
    rng = np.random.default_rng(seed)
    # where the copies meet: a smooth field of the reference points (bitwise the same on copies)
    U0 = 0.05 * np.stack([np.sin(3 * X[:, 1]), X[:, 0] * X[:, 2], np.cos(2 * X[:, 0]) - 1], axis=1)
    row = relinearise_node_to_face(rows, X, U0)
    V = rng.standard_normal(X.shape)
    corner = row.master[np.arange(len(row)), np.argmax(row.bary, axis=1)]

    def gap(U):
        x = X + U
        tri = x[row.master]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        n /= np.linalg.norm(n, axis=1)[:, None]
        return np.einsum("ij,ij->i", n, x[row.slave] - x[corner])

    assert np.allclose(row.C @ U0.T.ravel() + row.g, 0.0, rtol=0, atol=1e-16)
    errors = []
    for h in (1e-3, 5e-4, 2.5e-4):
        U = U0 + h * V
        errors.append(np.abs(gap(U) - (row.C @ U.T.ravel() + row.g)))
    ratio = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratio > 3.5) & (ratio < 4.5)), ratio


def test_rows_kept_for_ends_found_deep(blocks):
    arrays, setup = blocks
    U = motion(arrays, setup, EPS * np.array([-1.0, 0.5]), EPS * np.array([-1.0, 2.0]), stretch=-2 * EPS)
    vf = setup.vertex_fragment
    rows = reflex_wedge_rows(setup.edge_copies, U, 1e-9, setup.copy_index)
    assert len(rows) == 2
    pen = setup.detector.detect(U)
    deep = set(np.asarray(pen.vertex)[pen.gap < -1e-9].tolist())
    assert set(rows.slave.tolist()) <= deep                     # both ends inside B
    geometry = Geometry(arrays=arrays, fragment=vf[arrays.tets[:, 0]], seams=None,
                        fixed=np.zeros(0, dtype=np.int64))
    active = ActiveSet3d(geometry, 1e-12, copy_tol=1e-9)
    candidates = active.update(U, {"collision": 0.0})
    assert set(active.codec.codes(rows).tolist()) <= set(candidates.keys.codes.tolist())
