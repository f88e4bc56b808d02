"""Junction rows of ngfracture.seams on hand-made junctions (no mesh needed).

A point split into copies, each copy owning a wedge between its outgoing and incoming
boundary segment (domain on the left). The far ends of the lips are twins as well, so
adjacent wedges share a facet.
"""
import numpy as np
import pytest

from ngfracture.seams import find_seams, seam_constraints


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


def test_cross_junction_has_facet_rows_only():
    """Four 90-degree wedges: no wedge is reflex, so no junction rows; opposite copies
    share no facet and have no row (their exact condition is not convex, see seams)."""
    X, S, _ = junction([0.0, 90.0, 180.0, 270.0])
    seams = find_seams(X, S)
    assert len(seams) == 4 and len(seams.edge_rows) == 0
    rows, keys = seam_constraints(seams, X, np.zeros_like(X))
    apex = keys[:, 1] < 4                          # rows between copies of the origin
    assert sorted(map(tuple, keys[apex, :2].tolist())) == [(0, 1), (0, 3), (1, 2), (2, 3)]
    assert np.all(keys[:, 2] >= 0)


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
