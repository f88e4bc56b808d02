"""The fast paths of the 3D contact work give the results of the plain ones, exactly.

Keys as int64 codes (``active_set3d.FaceKeys``, ``row_keys.RowKeys``) against key tuples;
the gap rows' CSR arrays against the conversion from coordinates; the detection's pairs,
tetrahedra and master faces against a brute-force search over all pairs (exact orient3d;
the crossed face of the tetrahedron at a copy, or the nearest face by distance to every
face), on a fragmented cube whose blocks overlap.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ngfracture.contact.active_set import Candidates
from ngfracture.contact.row_keys import RowKeys
from ngfracture.contact.active_set3d import ActiveSet3d, FaceKeys, fixed_rows_3d
from ngfracture.contact.collision3d import PenetrationDetector3d, detect_penetrations_3d
from ngfracture.contact.rows3d import face_gap_rows, node_to_face_rows

from blocks3d import block_geometry, overlapping_blocks
from detection3d_util import MasterReference, brute_force_pairs

CELLS, PIECES = 5, 2


def _body(seed=0):
    """The fragmented cube, and a displacement where every block overlaps its neighbours:
    each block expanded about its centroid by 0.2 cells across every lip, plus noise."""
    return overlapping_blocks(CELLS, PIECES, 0.2 / CELLS * PIECES, noise=0.05 / CELLS, seed=seed)


@pytest.mark.parametrize("still", [False, True])
def test_detection_equals_brute_force(still):
    """With ``still`` half of the blocks do not move: their common lips stay closed, and the
    closed seams the detection decides before its sweep must be the brute force's
    (``detection3d_util``: pairs by exact tests of every (vertex, tetrahedron), master
    faces by the rules of collision3d's docstring)."""
    arrays, piece, vf, U = _body()
    X, T, F = arrays.points, arrays.tets, arrays.faces
    if still:
        U[vf >= 4] = 0.0
    pen = detect_penetrations_3d(X, T, F, piece, displacement=U)
    vertex, fragment, tet, closed = brute_force_pairs(X, T, F, piece, U)
    assert pen.stats["closed_seams"] == closed
    assert (closed > 100) == still
    assert len(pen) > 100
    assert np.array_equal(pen.vertex, vertex) and np.array_equal(pen.fragment, fragment)
    assert np.array_equal(pen.tet, tet)
    crossed, behind = MasterReference(X, U, T, F, piece).check(pen, 1e-12 / CELLS)
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
    geometry = block_geometry(arrays, piece)
    coded, plain = ActiveSet3d(geometry, 1e-12), ActiveSet3d(geometry, 1e-12)
    rng = np.random.default_rng(3)
    for rnd, u in enumerate((U, 0.5 * U, np.zeros_like(U)), start=1):
        cand = coded.update(u, {"collision": 0.0})
        assert isinstance(cand.keys, RowKeys)
        tuples = Candidates(cand.rows, list(cand.keys), cand.gap)
        a, b = coded.primal_dual(cand), plain.primal_dual(tuples)
        assert all(np.array_equal(p, q) for p, q in zip(a, b))
        ka, sa = coded.choose(cand, a[0], a[1], rnd, lambda rows, idx, released=None: None)
        kb, sb = plain.choose(tuples, b[0], b[1], rnd, lambda rows, idx, released=None: None)
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
    arrays, piece, _, U = overlapping_blocks(CELLS, PIECES, 0.2 / CELLS * PIECES)     # without noise
    geometry = block_geometry(arrays, piece)
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
