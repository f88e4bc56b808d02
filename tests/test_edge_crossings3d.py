"""Crossing boundary edges between fragments (ngfracture.contact.edge_crossings3d).

Numbers from geometry: two tetrahedra whose ridges cross (the pair appears exactly when
they pass each other by 1e-12 of their size), a corner poked into a face (no pair: its
edges pierce the face, the face's edges pierce nothing), coincident and sliding lips
(nothing), and a fragmented cube under random rigid motions of a block against a
brute-force evaluation of the same definition with the Python ``orient3d``.
"""
import numpy as np
import pytest

from ngfracture.contact.collision3d import detect_penetrations_3d, orient3d
from ngfracture.contact.edge_crossings3d import EdgeCrossingDetector, segment_pierces_triangle
from ngfracture.contact.kinks3d import point_ids
from ngfracture.geometry.pieces import fragmented_box

# outward faces of a positively oriented tetrahedron (0, 1, 2, 3)
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def positive(tet_points):
    """The corner order (0, 1, 2, 3) or (1, 0, 2, 3) that makes det[x1-x0, x2-x0, x3-x0] > 0."""
    P = np.asarray(tet_points)
    return [0, 1, 2, 3] if np.linalg.det(P[1:] - P[0]) > 0 else [1, 0, 2, 3]


def two_tets(A, B):
    """points, tets, outward faces and fragment per face of two tetrahedra (fragments 0, 1)."""
    points = np.vstack([A, B]).astype(float)
    tets = np.array([positive(A), [4 + k for k in positive(B)]])
    faces = np.vstack([t[TET_FACES] for t in tets])
    return points, tets, faces, np.repeat([0, 1], 4)


def edge_row(det, u, v):
    """Row of ``det.edges`` holding the edge (u, v)."""
    (row,) = np.flatnonzero((det.edges == sorted((u, v))).all(axis=1))
    return row


def face_fragment_of(tets, faces, fragment):
    """The fragment of the tetrahedron that holds every boundary face."""
    owner = {tuple(sorted(f)): t for t, tet in enumerate(tets) for f in tet[TET_FACES]}
    return np.array([fragment[owner[tuple(sorted(f))]] for f in faces])


# -- two ridges -----------------------------------------------------------------------------
RIDGE_A = [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, -1.0, -1.0), (0.0, 1.0, -1.0)]   # ridge 0-1 on top


def ridge_b(s):
    """Ridge 4-5 along y at the bottom, at height s (touching A's ridge at the origin for s = 0)."""
    return [(0.0, -1.0, s), (0.0, 1.0, s), (-1.0, 0.0, 1.0 + s), (1.0, 0.0, 1.0 + s)]


@pytest.mark.parametrize("s, crossed", [(-2e-12, True), (0.0, False), (2e-12, False), (-0.3, True)])
def test_two_ridges_cross_exactly_when_they_pass_each_other(s, crossed):
    points, _, faces, ff = two_tets(RIDGE_A, ridge_b(0.0))
    det = EdgeCrossingDetector(points, faces, ff)
    U = np.zeros_like(points)
    U[4:] = np.array(ridge_b(s)) - np.array(ridge_b(0.0))      # size 2: s = -+2e-12 is 1e-12 of it
    pairs, stats = det.detect_counted(U)
    expected = [[edge_row(det, 0, 1), edge_row(det, 4, 5)]] if crossed else np.zeros((0, 2))
    np.testing.assert_array_equal(pairs, expected)
    assert pairs.dtype == np.int64 and pairs.shape[1] == 2
    # each ridge pierces both faces at the other (and nothing else does, for the small moves)
    if crossed and s > -0.1:
        assert stats["pierces"] == 4


def test_a_corner_poked_into_a_face_is_no_edge_pair():
    A = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.25, 0.25, -1.0)]   # top face z = 0
    B = [(0.3, 0.3, -0.1), (-0.7, -0.7, 1.0), (1.8, 0.3, 1.0), (0.3, 1.8, 1.0)]    # corner 0.1 deep
    points, tets, faces, ff = two_tets(A, B)
    pairs, stats = EdgeCrossingDetector(points, faces, ff).detect_counted()
    assert len(pairs) == 0
    assert stats["pierces"] == 3                   # B's three edges at the corner pierce A's top face
    pen = detect_penetrations_3d(points, tets, faces, [0, 1])
    assert list(pen.vertex[pen.penetrating]) == [4]   # node-to-face holds it: the corner is in A


def test_segment_pierces_triangle_strictly():
    a, b, c = (0, 0, 0), (1, 0, 0), (0, 1, 0)
    assert segment_pierces_triangle((0.2, 0.2, -1), (0.2, 0.2, 1), a, b, c)
    assert not segment_pierces_triangle((0.5, 0.0, -1), (0.5, 0.0, 1), a, b, c)    # through an edge
    assert not segment_pierces_triangle((0.0, 0.0, -1), (0.0, 0.0, 1), a, b, c)    # through a corner
    assert not segment_pierces_triangle((0.2, 0.2, 0), (0.2, 0.2, 1), a, b, c)     # ends on the plane
    assert not segment_pierces_triangle((0.2, 0.2, 2), (0.2, 0.2, 1), a, b, c)     # one side
    assert not segment_pierces_triangle((0.2, 0.2, -1), (0.2, 0.2, 1), a, a, c)    # degenerate triangle


# -- blocks -----------------------------------------------------------------------------------
def blocks(cells, pieces):
    """A fragmented cube: points, tets, faces, fragment per tet, fragment per face."""
    arrays, piece = fragmented_box(cells, pieces)
    ff = face_fragment_of(arrays.tets, arrays.faces, piece)
    return arrays.points, arrays.tets, arrays.faces, piece, ff


@pytest.mark.parametrize("shift", [(0.0, 0.0, 0.0), (0.0, 0.3137, 0.0271), (0.0, -0.25, 0.5)])
def test_coincident_and_sliding_lips_report_nothing(shift):
    X, tets, faces, piece, ff = blocks(4, (2, 1, 1))      # cut at x = 1/2
    U = np.zeros_like(X)
    moved = np.unique(tets[piece == 1])
    U[moved] = shift                                      # along the interface: coplanar
    det = EdgeCrossingDetector(X, faces, ff)
    pairs, stats = det.detect_counted(U)
    assert len(pairs) == 0 and stats["pierces"] == 0


def brute_force_pairs(X, faces, ff, edges, U):
    """The interlocking pairs by the definition, every (edge, face) tested, Python orient3d."""
    x = X + U
    E, F = np.repeat(np.arange(len(edges)), len(faces)), np.tile(np.arange(len(faces)), len(edges))
    p, q = x[edges[E, 0]], x[edges[E, 1]]
    a, b, c = (x[faces[F, k]] for k in range(3))
    pid = point_ids(X, faces)                             # copies of a point count as that point
    shared = (pid[faces[F]][:, :, None] == pid[edges[E]][:, None, :]).any(axis=(1, 2))
    o_p, o_q = orient3d(a, b, c, p), orient3d(a, b, c, q)
    s = [orient3d(p, q, u, v) for u, v in ((a, b), (b, c), (c, a))]
    pierce = ~shared & (o_p * o_q < 0) & (s[0] != 0) & (s[0] == s[1]) & (s[1] == s[2])
    pierced = set(zip(E[pierce].tolist(), F[pierce].tolist()))
    key = {tuple(sorted(e)): i for i, e in enumerate(edges.tolist())}
    at_edge = {i: [] for i in range(len(edges))}
    for f, t in enumerate(faces.tolist()):
        for k in range(3):
            at_edge[key[tuple(sorted((t[k], t[(k + 1) % 3])))]].append(f)
    found = set()
    for e, f in pierced:
        t = faces[f].tolist()
        for k in range(3):
            other = key[tuple(sorted((t[k], t[(k + 1) % 3])))]
            if any((other, g) in pierced and (ff[g] != ff[f] or not set(pid[faces[g]]) & set(pid[t]))
                   for g in at_edge[e]):
                found.add((min(e, other), max(e, other)))
    return np.array(sorted(found), dtype=np.int64).reshape(-1, 2)


def rotation(axis, angle):
    """Rotation matrix about a unit axis (Rodrigues)."""
    k = np.asarray(axis) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def block_moved(X, tets, piece, seed, which=None):
    """Displacements moving one random block (or the blocks ``which``) rigidly: turned 0.05
    to 0.15 rad, shifted about 0.2."""
    rng = np.random.default_rng(seed)
    block = rng.integers(4)
    moved = np.unique(tets[np.isin(piece, [block] if which is None else which)])
    centre = X[moved].mean(axis=0)
    R = rotation(rng.normal(size=3), rng.uniform(0.05, 0.15))
    U = np.zeros_like(X)
    U[moved] = (X[moved] - centre) @ R.T + centre + rng.normal(scale=0.2, size=3) - X[moved]
    return U


@pytest.mark.parametrize("seed, merged", [(1, False), (2, False), (3, False), (6, False), (3, True), (7, True)])
def test_rigid_motion_of_a_block_matches_brute_force(seed, merged):
    X, tets, faces, piece, ff = blocks(4, (2, 2, 1))      # 4 blocks, 384 tets
    if merged:                                            # blocks 0, 1 and 2, 3: the lip between is a crack
        ff = ff // 2
    U = block_moved(X, tets, piece, seed)
    det = EdgeCrossingDetector(X, faces, ff)
    expected = brute_force_pairs(X, faces, ff, det.edges, U)
    assert len(faces) > 200 and len(expected) > 0         # edges cross away from copies of a point
    if merged:                                            # some pairs on one fragment (its crack's lips)
        first = ff[det.edge_faces[det.edge_face_ptr[expected[:, 0]]]]
        assert (first == ff[det.edge_faces[det.edge_face_ptr[expected[:, 1]]]]).any()
    np.testing.assert_array_equal(det.detect(U), expected)


def test_edges_and_the_faces_at_them():
    X, _, faces, _, ff = blocks(3, (2, 1, 1))
    det = EdgeCrossingDetector(X, faces, ff)
    all_edges = np.sort(faces[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)   # face by face
    np.testing.assert_array_equal(det.edges, np.unique(all_edges, axis=0))
    np.testing.assert_array_equal(np.sort(det.edges[det.face_edges].reshape(-1, 2), axis=1), all_edges)
    # closed surfaces: every edge on exactly two faces, and those hold it
    assert np.array_equal(np.diff(det.edge_face_ptr), np.full(len(det.edges), 2))
    at = det.edge_faces.reshape(-1, 2)
    for k in range(2):
        assert (det.face_edges[at[:, k]] == np.arange(len(det.edges))[:, None]).any(axis=1).all()


def test_same_answer_twice_and_from_a_second_detector():
    X, tets, faces, piece, ff = blocks(3, (2, 2, 1))
    U = np.zeros_like(X)
    moved = np.unique(tets[piece == 0])
    U[moved] = (X[moved] - 0.25) @ (rotation((1, 2, 3), 0.4).T - np.eye(3)) + 0.15
    first = EdgeCrossingDetector(X, faces, ff)
    a, b = first.detect(U), first.detect(U)
    c = EdgeCrossingDetector(X.copy(), faces.copy(), ff.copy()).detect(U)
    assert len(a) > 0
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, c)


@pytest.mark.parametrize("change, name", [
    (lambda X, F, f: (X[:, :2], F, f), "points"),
    (lambda X, F, f: (np.where(X == X.max(), np.nan, X), F, f), "points"),
    (lambda X, F, f: (X, F[:, :2], f), "faces"),
    (lambda X, F, f: (X, F + len(X), f), "faces"),
    (lambda X, F, f: (X, F.astype(float), f), "faces"),
    (lambda X, F, f: (X, np.vstack([F, [[0, 0, 1]]]), np.append(f, 0)), "faces"),
    (lambda X, F, f: (X, F, f[:-1]), "face_fragment"),
    (lambda X, F, f: (X, F, np.where(np.arange(len(f)) == 0, f + 7, f)), "face_fragment"),
])
def test_bad_input_names_the_array(change, name):
    points, _, faces, ff = two_tets(RIDGE_A, ridge_b(0.0))
    with pytest.raises(ValueError, match=name):
        EdgeCrossingDetector(*change(points, faces, ff))


@pytest.mark.parametrize("U", [np.zeros((7, 3)), np.full((8, 3), np.inf), np.zeros((8, 2))])
def test_bad_displacement_is_named(U):
    points, _, faces, ff = two_tets(RIDGE_A, ridge_b(0.0))
    with pytest.raises(ValueError, match="displacement"):
        EdgeCrossingDetector(points, faces, ff).detect(U)


def test_across_leaves_out_the_lips_of_one_fragment():
    X, tets, faces, piece, ff = blocks(4, (2, 2, 1))
    ff = ff // 2                                          # blocks 0, 1 and 2, 3: one fragment each
    U = block_moved(X, tets, piece, 3)
    every = EdgeCrossingDetector(X, faces, ff)
    pairs = every.detect(U)
    fragment_of = ff[every.edge_faces[every.edge_face_ptr[:-1]]]
    apart = fragment_of[pairs[:, 0]] != fragment_of[pairs[:, 1]]
    assert apart.any() and not apart.all()
    np.testing.assert_array_equal(EdgeCrossingDetector(X, faces, ff, across=True).detect(U), pairs[apart])


def test_edges_at_copies_of_a_point_are_no_pair():
    """Two ridges from one point P, of two fragments (P a copy on each), one slid sideways
    by 1e-3 and pushed 1e-3 into the other: they cross 2.5e-3 from P, next to the copies,
    which the rows at copies hold. Started 1e-3 apart instead, the same ridges are a pair."""
    def ridges(start_b):
        A = [(0.0, 0.0, 0.0), (1.0, 0.2, 0.0), (0.5, -1.0, -1.0), (0.5, 1.0, -1.0)]   # ridge on top
        B = [start_b, (1.0, -0.2, 0.0), (0.5, -1.0, 1.0), (0.5, 1.0, 1.0)]            # ridge below
        X, tets, faces, ff = two_tets(A, B)
        U = np.zeros_like(X)
        U[4:] = (0.0, 1e-3, -1e-3)
        return EdgeCrossingDetector(X, faces, ff), U
    det, U = ridges((0.0, 0.0, 0.0))
    assert len(det.detect(np.zeros_like(U))) == 0 and len(det.detect(U)) == 0
    det, U = ridges((-1e-3, 0.0, 0.0))
    pairs = det.detect(U).tolist()                        # B's ridge with A's edges at P
    ridge_b = edge_row(det, 4, 5)
    assert [edge_row(det, 0, 1), ridge_b] in pairs and all(b == ridge_b for _, b in pairs)


def test_skipped_vertices_leave_a_pair_to_the_other_edge():
    X, tets, faces, ff = two_tets(RIDGE_A, ridge_b(-2e-12))
    det = EdgeCrossingDetector(X, faces, ff)
    U = np.zeros_like(X)
    expected = [[edge_row(det, 0, 1), edge_row(det, 4, 5)]]
    one, both = np.zeros(len(X), dtype=bool), np.zeros(len(X), dtype=bool)
    one[[0, 1]] = True                                    # A's ridge not swept: found from B's
    both[[0, 1, 4, 5]] = True                             # neither swept: not found
    assert det.detect(U).tolist() == expected and det.detect(U, one).tolist() == expected
    pairs, stats = det.detect_counted(U, both)
    assert len(pairs) == 0 and stats["skipped_edges"] > 0
    with pytest.raises(ValueError, match="skip"):
        det.detect(U, np.zeros(3, dtype=bool))


def test_two_edges_on_closed_lips_are_no_pair():
    """Blocks 0 and 1 moved together keep their lip closed (copies bitwise together) and push
    into blocks 2 and 3, whose lip is closed too: the detection is the definition's pairs but
    those of two edges each with both ends on closed lips, which no sweep visits."""
    X, tets, faces, piece, ff = blocks(4, (2, 2, 1))
    U = block_moved(X, tets, piece, 14, which=(0, 1))
    det = EdgeCrossingDetector(X, faces, ff)
    expected = brute_force_pairs(X, faces, ff, det.edges, U)
    x, pid = X + U, point_ids(X, faces)
    closed = np.zeros(len(X), dtype=bool)
    for v in np.flatnonzero(pid >= 0):
        closed[v] = any((x[w] == x[v]).all() for w in np.flatnonzero(pid == pid[v]) if w != v)
    on_closed = closed[det.edges].all(axis=1)
    both = on_closed[expected[:, 0]] & on_closed[expected[:, 1]]
    assert both.any() and not both.all()
    np.testing.assert_array_equal(det.detect(U), expected[~both])
