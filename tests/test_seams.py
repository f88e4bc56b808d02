"""Junction rows of ngfracture.contact.seams on hand-made junctions (no mesh needed).

A point split into copies, each copy owning a wedge between its outgoing and incoming
boundary segment (domain on the left). The far ends of the lips are twins as well, so
adjacent wedges share a facet.
"""
import numpy as np
import pytest

from ngfracture.contact.seams import DIAGONAL_RIGHT, find_seams, point_ids, seam_constraints


def junction(angles_deg):
    """Copies 0..k-1 of the origin; wedge i from angles[i] to angles[i + 1] (degrees,
    counter-clockwise, the last one closing the circle). Returns points, segments and
    the far vertices of each wedge (out end, in start)."""
    k = len(angles_deg)
    points = [(0.0, 0.0)] * k
    segments, far = [], []
    for i in range(k):
        a, b = np.radians(angles_deg[i]), np.radians(angles_deg[(i + 1) % k])
        out_end, in_start = len(points), len(points) + 1
        points += [(np.cos(a), np.sin(a)), (np.cos(b), np.sin(b))]
        segments += [(i, out_end), (in_start, i)]
        far.append((out_end, in_start))
    return np.array(points), np.array(segments), far


def test_reflex_wedge_keeps_the_other_copies_in_its_complement():
    """Wedge 0 spans 200 degrees: copies 1 and 2 must stay in the 160-degree cone between
    its edges. The facet rows give one edge per pair; the junction rows the other."""
    X, S, far = junction([0.0, 200.0, 280.0])
    seams = find_seams(X, S)
    assert len(seams) == 3
    expected = {(0, 1, 0, far[0][0]),            # copy 1 stays below the 0-degree edge
                (0, 2, far[0][1], 0)}            # copy 2 stays beyond the 200-degree edge
    assert set(map(tuple, seams.edge_rows.tolist())) == expected
    rows, keys = seam_constraints(seams, X, np.zeros_like(X))
    junction_rows = keys[:, 2] <= -3
    assert np.all(rows.dist == 0.0)
    # outward normals of the reflex wedge's edges, from its apex towards the other copy
    normals = {tuple(k[:2]): n for k, n in zip(keys[junction_rows].tolist(), rows.normal[junction_rows])}
    np.testing.assert_allclose(normals[(0, 1)], [0.0, -1.0], atol=1e-15)
    t = np.radians(200.0)
    np.testing.assert_allclose(normals[(0, 2)], [-np.sin(t), np.cos(t)], atol=1e-15)
    assert np.all(rows.a[junction_rows] == 0)


def test_cross_junction_gets_one_row_per_diagonal_pair():
    """Four 90-degree wedges: no wedge is reflex, so no reflex-edge rows; adjacent copies
    share a facet (its row), opposite ones get one row on an edge of K = W_i - W_j."""
    X, S, _ = junction([0.0, 90.0, 180.0, 270.0])
    seams = find_seams(X, S)
    assert len(seams) == 4 and len(seams.edge_rows) == 0
    assert sorted(map(tuple, seams.diagonal[:, :2].tolist())) == [(0, 2), (1, 3)]
    rows, keys = seam_constraints(seams, X, np.zeros_like(X))
    apex = keys[:, 1] < 4                          # rows between copies of the origin
    assert sorted(map(tuple, keys[apex, :2].tolist())) == [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    diagonal = keys[:, 2] <= DIAGONAL_RIGHT
    assert sorted(map(tuple, keys[diagonal, :2].tolist())) == [(0, 2), (1, 3)]
    assert np.all(keys[~diagonal, 2] >= 0)


def cones_overlap(X, x, i, j, far_i, far_j):
    """Whether the wedges of copies i and j, translated to x[i] and x[j], share interior
    points: r = x[j] - x[i] lies in the interior of W_i - W_j, the cone of the four edge
    directions (those of j reversed). A linear programme, independent of seams."""
    from scipy.optimize import linprog
    E = np.column_stack([X[far_i[0]] - X[i], X[far_i[1]] - X[i], X[j] - X[far_j[0]], X[j] - X[far_j[1]]])
    r = x[j] - x[i]
    # strictly inside: r = E c with c >= 1e-9 |r| after scaling (a margin against the boundary)
    res = linprog(np.zeros(4), A_eq=E, b_eq=r, bounds=[(1e-9 * np.linalg.norm(r), None)] * 4, method="highs")
    return res.status == 0


@pytest.mark.parametrize("angles", [[0.0, 90.0, 180.0, 270.0], [10.0, 70.0, 200.0, 250.0], [0.0, 100.0, 135.0, 300.0]],
                         ids=["cross", "skew", "narrow"])
def test_diagonal_row_is_exact_on_the_side_it_is_chosen_for(angles):
    """Copy j (with its wedge) moved rigidly by r relative to copy i: the chosen row's gap
    is >= 0 exactly when the two wedges do not overlap (checked by a linear programme),
    for 200 random directions of r; and a gap < 0 is the distance into the nearer edge."""
    X, S, far = junction(angles)
    seams = find_seams(X, S)
    rng = np.random.default_rng(7)
    for i, j in seams.diagonal[:, :2]:
        wedge_j = [j, *far[j]]
        for phi in rng.uniform(0, 2 * np.pi, 200):
            r = 1e-3 * np.array([np.cos(phi), np.sin(phi)])
            U = np.zeros_like(X)
            U[wedge_j] = r
            rows, keys = seam_constraints(seams, X, U, slip=np.inf)
            k = np.flatnonzero((keys[:, 0] == i) & (keys[:, 1] == j) & (keys[:, 2] <= DIAGONAL_RIGHT))
            assert len(k) == 1
            gap = rows.dist[k[0]]
            if abs(gap) < 1e-12:
                continue                           # on an edge of K: both answers are right
            assert (gap >= 0) == (not cones_overlap(X, X + U, i, j, far[i], far[j])), (phi, gap)


@pytest.mark.parametrize("shear", [1e-3, -1e-3])
def test_cross_junction_slides_both_ways_along_a_crack(shear):
    """The upper half (copies 0, 1) slides along the horizontal crack: every row between
    copies of the origin stays satisfied (gaps >= 0, none is violated by the sliding), so
    the diagonal rows do not lock the crack against shear in either direction."""
    X, S, far = junction([0.0, 90.0, 180.0, 270.0])
    seams = find_seams(X, S)
    U = np.zeros_like(X)
    upper = [0, 1, *far[0], *far[1]]
    U[upper, 0] = shear
    rows, keys = seam_constraints(seams, X, U)
    apex = keys[:, 1] < 4
    assert np.all(rows.dist[apex] >= -1e-18)
    # one diagonal pair slides along the crack (its row is the crack's edge, gap 0), the
    # other moves apart by the shear
    diagonal = keys[:, 2] <= DIAGONAL_RIGHT
    np.testing.assert_allclose(np.sort(rows.dist[diagonal]), [0.0, abs(shear)], atol=1e-18)


def test_relinearised_diagonal_rows_keep_their_edge():
    """Two collinear segments bound K (the straight crack of a cross): which one is
    extreme flips with rounding, the key names the side of K, so the row chosen at the
    prediction is found again, with the same normal, among the rows of both sides."""
    X, S, far = junction([0.0, 90.0, 180.0, 270.0])
    seams = find_seams(X, S)
    U = np.zeros_like(X)
    U[[2, *far[2]], 0] = 1e-3                      # copy 2 slides right under copy 0
    rows, keys = seam_constraints(seams, X, U)
    chosen = {tuple(k): n for k, n in zip(keys.tolist(), rows.normal) if k[2] <= DIAGONAL_RIGHT}
    for tilt in (1e-13, -1e-13):
        V = U.copy()
        V[far[0][0], 1] += tilt                    # the 0-degree edge of copy 0 tilts a little
        both, both_keys = seam_constraints(seams, X, V, choose=False)
        found = {tuple(k): n for k, n in zip(both_keys.tolist(), both.normal)}
        for key, n in chosen.items():
            np.testing.assert_allclose(found[key], n, atol=1e-12)


@pytest.mark.parametrize("turn", [0.3, -1.0, 2.5])
def test_junction_rows_turn_with_the_pieces(turn):
    """A rigid rotation of the whole junction rotates every normal with it (facet and
    junction rows alike) and keeps the gaps at zero."""
    X, S, _ = junction([0.0, 200.0, 280.0])
    seams = find_seams(X, S)
    assert len(seams.edge_rows) == 2
    c, s = np.cos(turn), np.sin(turn)
    Q = np.array([[c, -s], [s, c]])
    rows0, keys0 = seam_constraints(seams, X, np.zeros_like(X), slip=np.inf)
    rows1, keys1 = seam_constraints(seams, X, X @ Q.T - X, slip=np.inf)
    assert np.array_equal(keys0, keys1)
    np.testing.assert_allclose(rows1.normal, rows0.normal @ Q.T, atol=1e-14)
    np.testing.assert_allclose(rows1.dist, 0.0, atol=1e-15)


def test_point_ids_are_the_inverse_of_numpy_unique_rows():
    """Copies share an id, ids in lexicographic (x, y) order as np.unique(axis=0) numbers
    them (-0.0 and 0.0 are one point), for no, one and many points."""
    rng = np.random.default_rng(0)
    X = rng.integers(0, 30, (5000, 2)).astype(float) * 0.1
    X[::7] *= -1.0                     # -0.0 where the coordinate was 0
    for Y in (X, X[:1], np.zeros((0, 2))):
        _, reference = np.unique(Y, axis=0, return_inverse=True)
        assert np.array_equal(point_ids(Y), reference.ravel())
