"""The fast paths of the 3D contact work give the results of the plain ones, exactly.

Keys as int64 codes (``active_set3d.FaceKeys``, ``active_set.RowKeys``) against key tuples;
the gap rows' CSR arrays against the conversion from coordinates; the detection's pairs,
tetrahedra and master faces against a brute-force search over all pairs (exact orient3d;
the crossed face of the tetrahedron at a copy, or the nearest face by distance to every
face), on a fragmented cube whose blocks overlap.
"""
from collections import Counter

import numpy as np
import pytest
import scipy.sparse as sp

from ngfracture.contact.active_set import Candidates, Geometry, RowKeys
from ngfracture.contact.active_set3d import ActiveSet3d, FaceKeys, fixed_rows_3d
from ngfracture.contact.collision3d import PenetrationDetector3d, detect_penetrations_3d, orient3d
from ngfracture.contact.rows3d import face_gap_rows, node_to_face_rows
from ngfracture.geometry.pieces import fragmented_box

CELLS, PIECES = 5, 2


def _body(seed=0):
    """The fragmented cube, and a displacement where every block overlaps its neighbours:
    each block expanded about its centroid by 0.2 cells across every lip, plus noise."""
    arrays, piece = fragmented_box(CELLS, PIECES)
    X = arrays.points
    vf = np.full(len(X), -1)
    vf[arrays.tets.ravel()] = np.repeat(piece, 4)
    centre = np.stack([np.bincount(vf, weights=X[:, d]) / np.bincount(vf) for d in range(3)], axis=1)
    U = 0.2 / CELLS * PIECES * (X - centre[vf])
    U += np.random.default_rng(seed).normal(scale=0.05 / CELLS, size=U.shape)
    return arrays, piece, vf, U


def _closest_distance(p, A, B, C):
    """Distance from p to every triangle (A, B, C): the plane's foot if inside, else the nearest edge."""
    n = np.cross(B - A, C - A)
    n /= np.linalg.norm(n, axis=1)[:, None]
    foot = p - np.einsum("ij,ij->i", p - A, n)[:, None] * n
    inside = np.all([np.einsum("ij,ij->i", np.cross(Q - P, foot - P), n) >= 0
                     for P, Q in ((A, B), (B, C), (C, A))], axis=0)
    best = np.linalg.norm(p - foot, axis=1)
    edges = []
    for P, Q in ((A, B), (B, C), (C, A)):
        e = Q - P
        t = np.clip(np.einsum("ij,ij->i", p - P, e) / np.einsum("ij,ij->i", e, e), 0.0, 1.0)
        edges.append(np.linalg.norm(p - (P + t[:, None] * e), axis=1))
    return np.where(inside, best, np.min(edges, axis=0))


@pytest.mark.parametrize("still", [False, True])
def test_detection_equals_brute_force(still):
    """With ``still`` half of the blocks do not move: their common lips stay closed, and the
    closed seams the detection decides before its sweep must be the brute force's."""
    arrays, piece, vf, U = _body()
    X, T, F = arrays.points, arrays.tets, arrays.faces
    if still:
        U[vf >= 4] = 0.0
    x = X + U
    pen = detect_penetrations_3d(X, T, F, piece, displacement=U)
    # brute force: every (boundary vertex, tetrahedron of another block), exactly
    bv = np.unique(F)
    v, t = np.repeat(bv, len(T)), np.tile(np.arange(len(T)), len(bv))
    other = vf[v] != piece[t]
    v, t = v[other], t[other]
    corners = [x[T[t, k]] for k in range(4)]
    s = orient3d(*corners).astype(int)
    inside = s != 0
    for k in range(4):
        w = list(corners)
        w[k] = x[v]
        inside &= orient3d(*w) * s >= 0
    v, t = v[inside], t[inside]
    # closed seams: a copy on the block at the same reference and current point
    key = {(tuple(X[u]), int(vf[u])): u for u in bv.tolist()}
    twin = np.array([key.get((tuple(X[a]), int(piece[b])), -1) for a, b in zip(v.tolist(), t.tolist())])
    closed = (twin >= 0) & np.all(x[v] == x[np.maximum(twin, 0)], axis=1)
    assert pen.stats["closed_seams"] == len(np.unique(v[closed] * len(T) + piece[t[closed]]))
    assert (pen.stats["closed_seams"] > 100) == still
    v, t = v[~closed], t[~closed]
    order = np.lexsort((t, piece[t], v))
    v, t = v[order], t[order]
    first = np.r_[True, (v[1:] != v[:-1]) | (piece[t][1:] != piece[t][:-1])]
    assert len(pen) > 100
    assert np.array_equal(pen.vertex, v[first]) and np.array_equal(pen.fragment, piece[t][first])
    assert np.array_equal(pen.tet, t[first])
    # master face (collision3d's docstring): in a tetrahedron at a copy t of the vertex, the
    # face of that tetrahedron at t with the vertex's reference star outside its plane that
    # the vertex is least deep behind; if none passes and three copies of the point lie on
    # the block, the lip of that tetrahedron at t the vertex is least deep behind if it is
    # behind one; else the nearest face of the block
    # opposing the vertex's normal or coincident with one of its faces (partner faces)
    area2 = np.cross(x[F[:, 1]] - x[F[:, 0]], x[F[:, 2]] - x[F[:, 0]])
    ref2 = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    vnormal = np.zeros((len(X), 3))
    np.add.at(vnormal, F.ravel(), np.repeat(area2, 3, axis=0))
    face_block = vf[F[:, 0]]
    points = [frozenset(map(tuple, X[f])) for f in F]
    points_count = Counter(points)                 # a lip: another face on its three points
    star = [np.unique(T[np.any(T == u, axis=1)]) for u in range(len(X))]
    crossed = behind = 0
    for i in range(len(pen)):
        a, f, tet = pen.vertex[i], pen.fragment[i], T[pen.tet[i]]
        t = [u for u in tet if u != a and np.array_equal(X[u], X[a])]
        sep = []
        if t:
            at = np.flatnonzero(np.all(np.isin(F, tet), axis=1) & np.any(F == t[0], axis=1))
            n = ref2[at] / np.linalg.norm(ref2[at], axis=1)[:, None]
            e = X[star[a]] - X[a]
            outside = np.all(n @ e.T >= -1e-9 * np.linalg.norm(e, axis=1), axis=1)
            sep = at[outside]
            lips = at[[points_count[points[g]] > 1 for g in at]]
            on_block = int(np.count_nonzero(np.all(X == X[a], axis=1) & (vf == f)))
            if not len(sep) and len(lips) and on_block >= 3:
                signed = np.einsum("ij,j->i", area2[lips] / np.linalg.norm(area2[lips], axis=1)[:, None],
                                   x[a] - x[t[0]])
                if signed.max() < 0:
                    sep = lips
                    behind += 1
        if len(sep):
            crossed += 1
            signed = np.einsum("ij,j->i", area2[sep] / np.linalg.norm(area2[sep], axis=1)[:, None], x[a] - x[t[0]])
            assert pen.face[i] == sep[np.lexsort((sep, -signed))[0]]
            assert abs(pen.gap[i] + max(0.0, -signed.max())) <= 1e-12 / CELLS
            continue
        mine = {points[g] for g in np.flatnonzero(np.any(F == a, axis=1))}
        partner = np.array([points[g] in mine and bool(np.any(np.all(X[F[g]] == X[a], axis=1)))
                            for g in range(len(F))])
        cand = np.flatnonzero((face_block == f) & ((area2 @ vnormal[a] < 0) | partner) & np.all(F != a, axis=1))
        d = _closest_distance(x[a][None, :], x[F[cand, 0]], x[F[cand, 1]], x[F[cand, 2]])
        assert pen.face[i] in cand
        assert abs(-pen.gap[i] - d.min()) <= 1e-12 / CELLS
        assert d[cand == pen.face[i]][0] <= d.min() + 1e-12 / CELLS
    assert crossed > 0                         # both rules are exercised
    print(f"{len(pen)} pairs, {crossed} on a face at a copy, {behind} of them by the lip rule")


def test_detector_is_the_detection():
    """PenetrationDetector3d does the mesh's work once, on copies of its arrays: every
    detection must equal detect_penetrations_3d's field by field, bit for bit (overlapping
    blocks, half of them still with closed lips, the reference configuration), also after
    the arrays it was made from are overwritten."""
    arrays, piece, vf, U = _body()
    X, T, F = arrays.points.copy(), arrays.tets.copy(), arrays.faces.copy()
    half = np.where((vf >= 4)[:, None], 0.0, U)
    detector = PenetrationDetector3d(X, T, F, piece)
    X[:] = 0.0
    T[:] = 0
    fields = ("vertex", "fragment", "tet", "face", "twin", "projection", "bary", "normal", "gap")
    for displacement in (U, half, None):
        plain = detect_penetrations_3d(arrays.points, arrays.tets, arrays.faces, piece, displacement=displacement)
        fast = detector.detect(displacement)
        for k in fields:
            assert np.array_equal(getattr(fast, k), getattr(plain, k)), k
        assert fast.stats["closed_seams"] == plain.stats["closed_seams"]
    assert len(detector.detect(U)) > 100 and detector.detect().stats["closed_seams"] > 100
    with pytest.raises(ValueError, match="displacement"):
        detector.detect(U[:-1])


def test_face_keys_are_the_key_tuples():
    arrays, piece, vf, U = _body(1)
    X, T, F = arrays.points, arrays.tets, arrays.faces
    fixed, keys = fixed_rows_3d(X, T, F, piece)
    found = node_to_face_rows(X, F, detect_penetrations_3d(X, T, F, piece, displacement=U))
    codec = FaceKeys(F)
    for rows in (fixed, found):
        codes, tuples = codec.codes(rows), rows.keys()
        assert codec.decode(codes) == tuples
        assert np.array_equal(codec.codes_of(tuples), codes)
        # equal codes exactly where the keys are equal
        same_code = codes[:, None] == codes[None, :]
        same_key = np.array([[a == b for b in tuples] for a in tuples[:300]])
        assert np.array_equal(same_code[:300], same_key)
    assert isinstance(keys, RowKeys) and list(keys) == fixed.keys() and len(set(keys)) == len(keys)
    assert codec.codes_of([("f", 0, -1, -2, -3)])[0] == -1


def test_gap_rows_are_the_coordinate_conversion():
    arrays, piece, vf, U = _body(2)
    X, F = arrays.points, arrays.faces
    rows = node_to_face_rows(X, F, detect_penetrations_3d(X, arrays.tets, F, piece, displacement=U))
    # the last row with its slave among its master's vertices: duplicates summed
    slave = rows.slave.copy()
    slave[-1] = rows.master[-1, 1]
    for s in (rows.slave, slave):
        C, _ = face_gap_rows(X, s, rows.master, rows.bary, rows.normal)
        m, nv = len(s), len(X)
        w = np.concatenate([np.ones((m, 1)), -rows.bary], axis=1)
        verts = np.concatenate([s[:, None], rows.master], axis=1)
        cols = np.concatenate([verts + c * nv for c in range(3)], axis=1).ravel()
        vals = np.concatenate([w * rows.normal[:, c:c + 1] for c in range(3)], axis=1).ravel()
        ref = sp.csr_matrix((vals, (np.repeat(np.arange(m), 12), cols)), shape=(m, 3 * nv))
        ref.eliminate_zeros()
        for name in ("indptr", "indices", "data"):
            a, b = getattr(C, name), getattr(ref, name)
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name


def test_codes_choose_as_tuples():
    """Two active sets fed the same candidates, one with RowKeys and one with key tuples."""
    arrays, piece, vf, U = _body(3)
    geometry = Geometry(arrays=arrays, fragment=piece, seams=None, fixed=np.zeros(0, dtype=np.int64))
    coded, plain = ActiveSet3d(geometry, 1e-12), ActiveSet3d(geometry, 1e-12)
    rng = np.random.default_rng(3)
    for rnd, u in enumerate((U, 0.5 * U, np.zeros_like(U)), start=1):
        cand = coded.update(u, {"collision": 0.0})
        assert isinstance(cand.keys, RowKeys)
        tuples = Candidates(cand.rows, list(cand.keys), cand.gap)
        a, b = coded.primal_dual(cand), plain.primal_dual(tuples)
        assert all(np.array_equal(p, q) for p, q in zip(a, b))
        ka, sa = coded.choose(cand, a[0], a[1], rnd, lambda rows, idx: None)
        kb, sb = plain.choose(tuples, b[0], b[1], rnd, lambda rows, idx: None)
        assert np.array_equal(ka, kb) and sa == sb and (rnd > 1 or len(ka) > 100)
        lam = np.where(rng.random(len(ka)) < 0.2, 1.0, -1.0)      # some rows released
        assert coded.record(cand.keys, ka, lam, 1.0) == plain.record(tuples.keys, kb, lam, 1.0)
        assert coded.multipliers == plain.multipliers and len(coded.multipliers) == len(ka)
        assert np.array_equal(np.sort(coded.tried), np.sort(plain.tried)) and coded.imposed == plain.imposed


def test_redundancy_shortcuts_choose_the_plain_rows(monkeypatch):
    """The candidate rows of overlapping blocks at their junctions (components of dependent
    rows) and of the closed body (every row independent): the rows independent_rows keeps
    with its Gram test per component must be those of the pivoted QR alone."""
    from ngfracture.contact import redundancy
    arrays, piece, vf, _ = _body()
    X = arrays.points
    centre = np.stack([np.bincount(vf, weights=X[:, d]) / np.bincount(vf) for d in range(3)], axis=1)
    U = 0.2 / CELLS * PIECES * (X - centre[vf])          # the blocks overlap, without noise
    geometry = Geometry(arrays=arrays, fragment=piece, seams=None, fixed=np.zeros(0, dtype=np.int64))
    active = ActiveSet3d(geometry, 1e-12)
    dropped = []
    for u in (U, np.zeros_like(U)):
        C = active.update(u, {"collision": 0.0}).rows.C
        monkeypatch.setattr(redundancy, "_clearly_independent", lambda *args: False)
        fast = redundancy.independent_rows(C, rtol=1e-5)
        monkeypatch.setattr(redundancy, "GRAM_MIN_ROWS", 10 ** 9)
        plain = redundancy.independent_rows(C, rtol=1e-5)
        monkeypatch.undo()
        assert np.array_equal(fast, plain)
        dropped.append(C.shape[0] - len(plain))
    assert dropped[0] > 10
