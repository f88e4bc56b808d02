"""Contact selection, linearised gap rows (eq. 13/14) and redundancy removal by pivoted QR."""
import numpy as np
import pytest
import scipy.sparse as sp

import ngfracture  # noqa: F401
from ngfracture.contact import collision
from ngfracture.contact import redundancy
from ngfracture.contact import rows as contact

from test_collision import boundary_edges_of, two_blocks


def signed_distance(p, a, c, n_out):
    """Exact signed distance of p from the line through a, c (outward normal n_out)."""
    t = (c - a) / np.linalg.norm(c - a)
    n = np.array([t[1], -t[0]])
    assert np.allclose(n, n_out)
    return (p - a) @ n


# Master triangle (a, c, o) has a -> c on its boundary with itself on the left
# (below); the slave triangle pokes its vertex b = (0.3, -0.05) into it.
XM = np.array([[1.0, 0.0], [0.0, 0.0], [0.5, -0.8]])
XS = np.array([[0.3, -0.05], [0.6, 0.5], [0.1, 0.6]])
X2 = np.concatenate([XM, XS])
T2 = np.array([[0, 1, 2], [3, 4, 5]], np.int32)
E2 = np.array([[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3]])


def test_selection_node_to_segment_geometry():
    pairs = collision.detect_collisions(X2, None, T2, boundary_edges=E2)
    assert pairs.tolist() == [[0, 1]]
    cs = contact.select_contacts(X2, None, T2, E2, pairs)
    assert len(cs) == 1                                # no master vertex is inside the slave
    assert (cs.slave[0], cs.a[0], cs.c[0]) == (3, 0, 1)
    assert (cs.master_tri[0], cs.slave_tri[0]) == (0, 1)
    assert cs.xi[0] == pytest.approx(0.3, abs=1e-15)   # x'_b = 0.3 x_a + 0.7 x_c = (0.3, 0)
    assert np.allclose(cs.normal[0], [0.0, 1.0], atol=1e-15)
    assert cs.dist[0] == pytest.approx(-0.05, abs=1e-15)
    assert cs.g[0] == pytest.approx(-0.05, abs=1e-15)
    # the row: +n at b, -xi n at a, -(1 - xi) n at c, y dofs only (dof = comp * nv + v)
    nv = 6
    expected = np.zeros(2 * nv)
    expected[nv + 3], expected[nv + 0], expected[nv + 1] = 1.0, -0.3, -0.7
    assert np.allclose(cs.C.toarray()[0], expected, atol=1e-15)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gap_rows_exact_for_translations(seed):
    rng = np.random.default_rng(seed)
    # predicted state: the whole scene rotated by some angle and moved
    th = rng.uniform(0, 2 * np.pi)
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    U = X2 @ R.T + rng.uniform(-1, 1, 2) - X2
    pairs = collision.detect_collisions(X2, U, T2, boundary_edges=E2)
    cs = contact.select_contacts(X2, U, T2, E2, pairs)
    assert len(cs) == 1 and (cs.slave[0], cs.a[0], cs.c[0]) == (3, 0, 1)
    x = X2 + U
    u = U.T.ravel()                                       # component-blocked dofs
    assert (cs.C @ u + cs.g)[0] == pytest.approx(
        signed_distance(x[3], x[0], x[1], cs.normal[0]), abs=1e-14)
    assert (cs.C @ u + cs.g)[0] == pytest.approx(-0.05, abs=1e-14)
    for _ in range(10):
        ts, tm = rng.uniform(-0.3, 0.3, (2, 2))          # slave and master translations
        V = U.copy()
        V[3:] += ts
        V[:3] += tm
        xv = X2 + V
        gap = (cs.C @ V.T.ravel() + cs.g)[0]
        assert gap == pytest.approx(signed_distance(xv[3], xv[0], xv[1], cs.normal[0]),
                                    abs=1e-14)
        # sign: positive = separated, negative = penetration
        assert np.sign(gap) == np.sign((xv[3] - xv[0]) @ cs.normal[0])
    # a rigid translation of everything leaves C u unchanged
    t = rng.uniform(-1, 1, 2)
    assert (cs.C @ (U + t).T.ravel())[0] == pytest.approx((cs.C @ u)[0], abs=1e-14)


def test_threshold_and_angle_rules():
    # slave vertex outside by 0.05: no constraint at tol 0.04, one at tol 0.06
    XS_out = XS + [0.0, 0.1]
    X = np.concatenate([XM, XS_out])
    pairs = np.array([[0, 1]])
    assert len(contact.select_contacts(X, None, T2, E2, pairs, tol=0.04)) == 0
    cs = contact.select_contacts(X, None, T2, E2, pairs, tol=0.06)
    assert len(cs) == 1 and cs.dist[0] == pytest.approx(0.05, abs=1e-15)
    # rule 3 threshold: the slave's edges make ~61 degrees with the master edge
    assert cs.angle[0] == pytest.approx(np.arctan2(0.55, 0.3), abs=1e-12)
    assert len(contact.select_contacts(X2, None, T2, E2, pairs, angle_tol=1.0)) == 0
    assert len(contact.select_contacts(X2, None, T2, E2, pairs, angle_tol=1.1)) == 1
    # the master segment must be a boundary edge: no boundary edges, no constraint
    E_slave_only = E2[3:]
    assert len(contact.select_contacts(X2, None, T2, E_slave_only, pairs)) == 0
    with pytest.raises(ValueError, match="angle_tol"):
        contact.select_contacts(X2, None, T2, E2, pairs, angle_tol=2.0)
    with pytest.raises(ValueError, match="tol"):
        contact.select_contacts(X2, None, T2, E2, pairs, tol=-1.0)
    with pytest.raises(ValueError, match="different triangles"):
        contact.select_contacts(X2, None, T2, E2, [[1, 1]])
    with pytest.raises(ValueError, match="pairs"):
        contact.select_contacts(X2, None, T2, E2, [[0, 2]])
    with pytest.raises(ValueError, match="displacement"):
        contact.select_contacts(X2, np.full((6, 2), np.nan), T2, E2, pairs)
    with pytest.raises(ValueError, match="finite"):
        contact.gap_rows(X2, [3], [0], [1], [np.nan], [[0.0, 1.0]])


def test_pressed_blocks_rows():
    X, U, T, frag = two_blocks(n=8, overlap=0.01)
    E = boundary_edges_of(T)
    pairs = collision.detect_collisions(X, U, T, boundary_edges=E, fragment=frag)
    cs = contact.select_contacts(X, U, T, E, pairs)
    assert len(cs) > 0
    # rule 1: at most two constraints per pair, one per direction
    assert np.bincount(cs.pair).max() <= 2
    assert len(np.unique(np.stack([cs.pair, cs.master_tri], 1), axis=0)) == len(cs)
    # masters and slaves on different blocks; across the interface (normal +-x) the
    # penetration is 0.01; the corner nodes of the overlap lie on the extension of the
    # outer bottom/top edge of the other block: nearest exit there, gap 0, normal +-y
    assert np.all(frag[cs.master_tri] != frag[cs.slave_tri])
    across = np.abs(cs.normal[:, 0]) == 1.0
    assert np.allclose(cs.dist[across], -0.01, atol=1e-13)
    assert np.count_nonzero(across) >= 2 * 8 - 2
    x = X + U
    assert np.allclose(np.abs(cs.normal[~across, 1]), 1.0, atol=1e-14)
    assert np.allclose(cs.dist[~across], 0.0, atol=1e-14)
    assert np.all((x[cs.slave[~across], 1] == 0.0) | (x[cs.slave[~across], 1] == 1.0))
    u = U.T.ravel()
    assert np.allclose(cs.C @ u + cs.g, cs.dist, atol=1e-14)
    # at the reference (undisplaced, touching) state every gap vanishes
    assert np.allclose(cs.g, 0.0, atol=1e-14)
    # the node-to-node duplicates at coincident interface nodes are redundant: the kept
    # rows are independent and span the same space
    keep = contact.independent_rows(cs.C)
    A = cs.C.toarray()
    assert np.linalg.matrix_rank(A[keep]) == len(keep) == np.linalg.matrix_rank(A)
    assert len(keep) < len(cs)
    keep_b = contact.independent_rows(cs.C, method="banded")
    assert len(keep_b) == len(keep) == np.linalg.matrix_rank(A[keep_b])


def test_selected_and_stacked_rows_carry_their_own_matrix():
    """subset and stack never touch C; the C built afterwards is that of gap_rows for the
    same rows, entry for entry, in the order of the rows."""
    X, U, T, frag = two_blocks(n=8, overlap=0.01)
    E = boundary_edges_of(T)
    cs = contact.select_contacts(X, U, T, E, collision.detect_collisions(X, U, T, boundary_edges=E, fragment=frag))
    rows = np.array([5, 0, 3, 3, len(cs) - 1])
    picked = contact.ContactConstraints.stack([cs.subset(rows), cs.subset(cs.xi == 1.0)])
    expected = sp.vstack([cs.C[rows], cs.C[np.flatnonzero(cs.xi == 1.0)]]).tocsr()
    C_ref, g_ref = contact.gap_rows(X, picked.slave, picked.a, picked.c, picked.xi, picked.normal)
    for C in (expected, C_ref):
        assert C.shape == picked.C.shape and (C != picked.C).nnz == 0
    assert np.array_equal(picked.g, g_ref)
    with pytest.raises(ValueError, match="different numbers|vertices"):
        contact.ContactConstraints.stack([cs, contact.no_constraints(len(X) + 1)])


def test_banded_and_pivoted_agree_on_long_chains():
    # 3-node rows along a chain of vertices, with duplicates and Fig. 5 style cycles
    rng = np.random.default_rng(9)
    nv, m = 160, 200
    b = rng.integers(0, nv - 2, m)
    a, c = b + 1, b + 2
    n = rng.normal(size=(m, 2))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    C, _ = contact.gap_rows(np.zeros((nv, 2)), b, a, c, rng.uniform(0, 1, m), n)
    dup = rng.integers(0, m, 40)
    C = sp.vstack([C, C[dup] * 2.0]).tocsr()
    rank = np.linalg.matrix_rank(C.toarray())
    for method in ("pivoted", "banded", "auto"):
        keep = contact.independent_rows(C, method=method)
        assert len(keep) == rank
        assert np.linalg.matrix_rank(C[keep].toarray()) == rank


@pytest.mark.parametrize("method", ["pivoted", "banded", "auto"])
def test_rows_on_fixed_dofs_only_are_all_dropped_beside_general_rows(method):
    # every row of C vanishes on the fixed dofs; the Dirichlet-like rows G stay: no row is
    # independent of them, whatever the method (no ordering of an empty set of rows)
    C = sp.csr_matrix(np.array([[1.0, 0, 0], [0, 1.0, 0]]))
    G = sp.csr_matrix(np.array([[0, 0, 1.0]]))
    assert len(contact.independent_rows(C, fixed_dofs=[0, 1], G=G, method=method)) == 0


@pytest.mark.parametrize("distance", [None, 0.5e-5, 2e-5, 1e-3])
def test_gram_shortcut_agrees_with_the_pivoted_qr(monkeypatch, distance):
    """Rows that are clearly independent skip the pivoted QR (redundancy._clearly_independent)
    and the answer must be the QR's. 150 sparse rows, 20 fixed dofs and 6 dense hold rows G
    (one component, like the contact solver's rigid-mode holds); with `distance` the last
    row is a combination of two others moved off by that much (rtol = 1e-5): at 0.5 rtol
    the QR drops a row, so the shortcut must have declined; without it, it must answer."""
    rng = np.random.default_rng(3)
    ndof, m, rtol = 400, 150, 1e-5
    C = np.zeros((m, ndof))
    for i in range(m):
        C[i, rng.choice(np.arange(20, ndof), 4, replace=False)] = rng.uniform(-1, 1, 4)
    fixed = np.arange(20)                             # C rows do not touch them, G rows do
    G = sp.csr_matrix(rng.normal(size=(6, ndof)))
    if distance is not None:
        combo = C[0] / np.linalg.norm(C[0]) + C[1] / np.linalg.norm(C[1])
        kick = np.zeros(ndof)
        kick[np.setdiff1d(np.arange(20, ndof), np.flatnonzero(C[:-1].any(axis=0)))[0]] = 1.0
        C[-1] = combo / np.linalg.norm(combo) + distance * kick
    C = sp.csr_matrix(C)
    answered = []
    shortcut = redundancy._clearly_independent

    def spy(*args):
        answered.append(shortcut(*args))
        return answered[-1]
    monkeypatch.setattr(redundancy, "_clearly_independent", spy)
    fast = contact.independent_rows(C, fixed_dofs=fixed, G=G, rtol=rtol)
    monkeypatch.setattr(redundancy, "_clearly_independent", lambda *args: False)
    qr = contact.independent_rows(C, fixed_dofs=fixed, G=G, rtol=rtol)
    assert np.array_equal(fast, qr)
    if distance is None:
        assert answered == [True] and len(qr) == m
    if distance == 0.5e-5:
        assert answered == [False] and len(qr) == m - 1


def contact_like_rows(rng, nv, m):
    """m unit rows of gaps along the axes on nv vertices (3 dofs each, component-major):
    node-to-node rows (slave, one master) and node-to-face rows (slave, three masters with
    barycentric weights), each within a window of 8 consecutive vertices, so that they form
    cycles of the Fig. 5 kind."""
    C = np.zeros((m, 3 * nv))
    for i in range(m):
        axis, centre = rng.integers(3), rng.integers(nv - 8)
        v = centre + rng.choice(8, rng.choice([2, 4]), replace=False)
        w = np.ones(1) if len(v) == 2 else rng.dirichlet(np.ones(3))
        C[i, axis * nv + v] = np.concatenate([[1.0], -w])
    return C / np.linalg.norm(C, axis=1)[:, None]


@pytest.mark.parametrize("seed", range(4))
def test_support_qr_is_the_dense_qr_bit_for_bit(seed):
    """The pivoted QR works on the supports of its vectors (cpp_ext/independent_rows.cpp):
    it must pick the rows the same QR on dense vectors picks, in the same order. Rows like
    a 3D contact component, plus exact and negated duplicates and combinations of two rows
    moved off by 0.5, 1 and 2 rtol; odd seeds with hold rows G (dense and a unit row)."""
    rng = np.random.default_rng(seed)
    nv, m, rtol = 30, 90, 1e-5
    A = contact_like_rows(rng, nv, m)
    i, j = rng.integers(0, m, (2, 12))
    extra = [A[i[:4]], -A[j[:4]]]
    for d, a, b in zip([0.5 * rtol, rtol, 2 * rtol] * 3, i[4:], j[4:]):
        combo = (A[a] + A[b]) / np.linalg.norm(A[a] + A[b])
        extra.append((combo + d * rng.normal(size=3 * nv) / np.sqrt(3 * nv))[None])
    A = np.vstack([A] + extra)
    A = A[rng.permutation(len(A))]
    G = np.zeros((0, 3 * nv))
    if seed % 2:
        G = np.vstack([rng.normal(size=(2, 3 * nv)), np.eye(1, 3 * nv, 5)])
    support = ngfracture._ngfracture.IndependentRows(A, G, rtol)
    dense = ngfracture._ngfracture.IndependentRows(A, G, rtol, dense=True)
    assert np.array_equal(support, dense)
    assert len(support) < len(A) - 8            # the duplicates at least are dropped


@pytest.mark.parametrize("distance", [None, 0.5e-5, 2e-5])
def test_component_gram_test_agrees_with_the_qr(monkeypatch, distance):
    """A component of at least redundancy.GRAM_MIN_ROWS rows is kept whole without the QR
    where a Cholesky factorisation of its Gram matrix proves it clearly independent (C++);
    the answer must be the QR's (GRAM_MIN_ROWS above any component: the plain computation).
    Five components of 30 contact-like rows; with `distance` the last row of the first is a
    combination of two others moved off by that much along a dof of its own (rtol = 1e-5):
    at 0.5 rtol the QR drops it, so the test must have declined."""
    rng = np.random.default_rng(7)
    nv, rtol = 30, 1e-5
    C = sp.block_diag([contact_like_rows(rng, nv, 30) for _ in range(5)]).toarray()
    if distance is not None:
        used = np.flatnonzero(np.any(C[:29] != 0, axis=0) | np.any(C[30:] != 0, axis=0))
        free = np.setdiff1d(np.arange(C.shape[1]), used)[0]
        combo = (C[0] + C[1]) / np.linalg.norm(C[0] + C[1])
        C[29] = combo
        C[29, free] = distance
    monkeypatch.setattr(redundancy, "_clearly_independent", lambda *args: False)
    fast = contact.independent_rows(sp.csr_matrix(C), rtol=rtol)
    monkeypatch.setattr(redundancy, "GRAM_MIN_ROWS", 10 ** 9)
    qr = contact.independent_rows(sp.csr_matrix(C), rtol=rtol)
    assert np.array_equal(fast, qr)
    if distance == 0.5e-5:
        assert 29 not in qr.tolist()
    if distance == 2e-5:
        assert 29 in qr.tolist()


# ------------------------------------------------------------------ redundancy
@pytest.mark.parametrize("method", ["pivoted", "banded", "auto"])
def test_2000_coincident_rows_rank_r_and_kkt(method):
    rng = np.random.default_rng(5)
    ndof, r, m = 300, 40, 2000
    # r independent node-to-segment-like rows on a cluster of 80 dofs
    base = np.zeros((r, ndof))
    for i in range(r):
        cols = rng.choice(80, 6, replace=False)
        base[i, cols] = rng.uniform(-1, 1, 6)
    assert np.linalg.matrix_rank(base) == r
    # 2000 rows: scaled copies of base rows (coincident constraints) and combinations
    which = rng.integers(0, r, m)
    rows = base[which] * rng.choice([-2.0, -1.0, 0.5, 1.0, 3.0], (m, 1))
    combo = rng.uniform(size=m) < 0.3
    rows[combo] += base[rng.integers(0, r, combo.sum())]
    rows[:r] = base                                    # every base row occurs
    C = sp.csr_matrix(rows)
    # rank r by construction: combinations of the base rows, which all occur
    keep = contact.independent_rows(C, method=method)
    assert len(keep) == r
    assert np.linalg.matrix_rank(rows[keep]) == r
    # consistent gaps: g = -C u* for some u*, so the full system is solvable
    u_star = rng.normal(size=ndof)
    g = -rows @ u_star
    Q = rng.normal(size=(ndof, ndof))
    K = Q @ Q.T + ndof * np.eye(ndof)                  # random SPD
    f = rng.normal(size=ndof)
    Ck = rows[keep]
    KKT = np.block([[K, Ck.T], [Ck, np.zeros((r, r))]])
    rhs = np.concatenate([f, -g[keep]])
    sol = np.linalg.solve(KKT, rhs)
    u, lam = sol[:ndof], sol[ndof:]
    assert np.linalg.norm(KKT @ sol - rhs) / np.linalg.norm(rhs) < 1e-10
    # load balance: external load = internal force + constraint forces
    assert np.linalg.norm(f - K @ u - Ck.T @ lam) / np.linalg.norm(f) < 1e-10
    # all 2000 constraints hold, not only the kept ones
    assert np.abs(rows @ u + g).max() < 1e-10 * np.abs(g).max()


def node_to_node(nv, b, a, n):
    """gap n . (x_b - x_a) as a degenerate node-to-segment row (xi = 1)."""
    C, g = contact.gap_rows(np.zeros((nv, 2)), [b], [a], [(a + 1) % nv], [1.0], [n])
    return C


def test_three_body_redundancy_fig5_and_duplicates():
    # Vertices 0, 1, 2 are the coincident corners of three fragments meeting at a point;
    # node-to-node contacts 0-1, 1-2 and 0-2 along the same normal: rank 2 (Fig. 5).
    nv = 6
    n = np.array([0.6, 0.8])
    r01, r12, r02 = (node_to_node(nv, b, a, n) for b, a in ((1, 0), (2, 1), (2, 0)))
    C = sp.vstack([r01, r12, r02, r01, r12]).tocsr()   # plus two exact duplicates
    keep = contact.independent_rows(C)
    assert keep.tolist() == [0, 1]
    assert len(contact.independent_rows(C, method="banded")) == 2
    assert np.linalg.matrix_rank(C.toarray()[keep]) == 2
    # different normals: the three node-to-node rows are independent in 2D
    r02b = node_to_node(nv, 2, 0, np.array([1.0, 0.0]))
    assert contact.independent_rows(sp.vstack([r01, r12, r02b])).tolist() == [0, 1, 2]
    # a near duplicate (1e-14 off) counts as a duplicate; the first occurrence is kept
    C2 = sp.vstack([r01, r01 * (1 + 1e-14) + 1e-14 * r12]).tocsr()
    assert contact.independent_rows(C2).tolist() == [0]
    C3 = sp.vstack([r01 * (1 + 1e-14) + 1e-14 * r12, r01]).tocsr()
    assert contact.independent_rows(C3).tolist() == [0]


def test_rows_independent_of_dirichlet_rows():
    nv = 6
    n = np.array([0.6, 0.8])
    r01, r12, r02 = (node_to_node(nv, b, a, n) for b, a in ((1, 0), (2, 1), (2, 0)))
    C = sp.vstack([r01, r12, r02]).tocsr()
    dof = lambda v, comp: comp * nv + v  # noqa: E731
    # vertex 0 clamped: still rank 2 among the contact rows
    fixed0 = [dof(0, 0), dof(0, 1)]
    assert len(contact.independent_rows(C, fixed_dofs=fixed0)) == 2
    # vertices 0 and 1 clamped: only the row touching vertex 2 adds anything
    fixed01 = fixed0 + [dof(1, 0), dof(1, 1)]
    keep = contact.independent_rows(C, fixed_dofs=fixed01)
    assert len(keep) == 1
    # everything clamped: every contact row is implied by the Dirichlet rows
    all_fixed = np.arange(2 * nv)
    assert len(contact.independent_rows(C, fixed_dofs=all_fixed)) == 0
    # the same through general Dirichlet rows G (unit rows of the fixed dofs)
    G = sp.csr_matrix((np.ones(4), (np.arange(4), fixed01)), shape=(4, 2 * nv))
    assert contact.independent_rows(C, G=G).tolist() == keep.tolist()
    # a gliding condition n . u_1 = 0 and a clamp of vertex 0 make row 0-1 redundant
    glide = sp.csr_matrix((n, ([0, 0], [dof(1, 0), dof(1, 1)])), shape=(1, 2 * nv))
    clamp = sp.csr_matrix((np.ones(2), ([0, 1], fixed0)), shape=(2, 2 * nv))
    Gg = sp.vstack([glide, clamp]).tocsr()
    keep = contact.independent_rows(C, G=Gg)
    stacked = sp.vstack([Gg, C[keep]]).toarray()
    assert np.linalg.matrix_rank(stacked) == 3 + len(keep)               # independent
    assert len(keep) == np.linalg.matrix_rank(sp.vstack([Gg, C]).toarray()) - 3  # maximal
    assert 0 not in keep.tolist()


def test_a_large_component_with_hold_rows_takes_the_dense_qr(monkeypatch):
    """A component of more rows than ``dense_limit``, joined by rows kept in any case (the
    holds of a piece on its rigid modes, dense over its dofs), as a junction of the free
    sphere has: LAPACK's pivoted QR on the dense block keeps a maximal independent set
    (the rank of [G; C] less that of G, by the SVD), as the C++ QR on the supports does."""
    rng = np.random.default_rng(11)
    ndof, r, m = 240, 90, 400
    base = np.zeros((r, ndof))
    for i in range(r):
        base[i, rng.choice(ndof, 9, replace=False)] = rng.uniform(-1, 1, 9)
    rows = base[rng.integers(0, r, m)] * rng.choice([-2.0, 0.5, 1.0], (m, 1))
    combo = rng.uniform(size=m) < 0.3
    rows[combo] += base[rng.integers(0, r, combo.sum())]
    rows[:r] = base
    G = rng.standard_normal((6, ndof))
    C = sp.csr_matrix(rows)
    dense = []
    original = redundancy._dense_pivoted_qr
    monkeypatch.setattr(redundancy, "_dense_pivoted_qr", lambda *a: dense.append(1) or original(*a))
    keep = contact.independent_rows(C, G=G, dense_limit=256)
    assert dense == [1]
    rank = np.linalg.matrix_rank(np.vstack([G, rows])) - np.linalg.matrix_rank(G)
    assert len(keep) == rank
    assert np.linalg.matrix_rank(np.vstack([G, rows[keep]])) == 6 + rank
    assert len(contact.independent_rows(C, G=G, method="pivoted")) == rank
    monkeypatch.setattr(redundancy, "DENSE_QR_MAX_ENTRIES", 0)       # too large a block: C++
    assert len(contact.independent_rows(C, G=G, dense_limit=256)) == rank and dense == [1]


def test_independent_rows_validation_and_empty():
    assert contact.independent_rows(sp.csr_matrix((0, 10))).shape == (0,)
    C = sp.csr_matrix(np.eye(3, 10))
    with pytest.raises(ValueError, match="fixed_dofs"):
        contact.independent_rows(C, fixed_dofs=[10])
    with pytest.raises(ValueError, match="G must have"):
        contact.independent_rows(C, G=np.eye(2, 9))
    with pytest.raises(ValueError, match="rtol"):
        contact.independent_rows(C, rtol=0.0)
    bad = C.copy()
    bad.data[0] = np.nan
    with pytest.raises(ValueError, match="C contains"):
        contact.independent_rows(bad)


def test_contact_constraints_pipeline_and_no_work_without_candidates():
    X, U, T, frag = two_blocks(n=6, overlap=0.02)
    E = boundary_edges_of(T)
    cs = contact.contact_constraints(X, U, T, E, fragment=frag)
    A = cs.C.toarray()
    assert len(cs) > 0 and np.linalg.matrix_rank(A) == len(cs)
    gap = cs.C @ U.T.ravel() + cs.g
    across = np.abs(cs.normal[:, 0]) == 1.0
    assert np.allclose(gap[across], -0.02, atol=1e-13) and np.allclose(gap[~across], 0.0)
    assert np.count_nonzero(across) >= 6 - 1       # node-to-node pairs both ways are one row
    empty = contact.contact_constraints(X, U, T, E, candidates=np.zeros(len(T), bool))
    assert len(empty) == 0 and empty.C.shape == (0, 2 * len(X))



def graph_laplacian_K(T, nv, mass=1.0):
    """SPD stand-in for a stiffness matrix: mass + graph Laplacian per component."""
    e = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    A = sp.csr_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(nv, nv))
    A = ((A + A.T) > 0).astype(float)
    L = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A
    K1 = mass * sp.identity(nv) + L
    return sp.block_diag([K1, K1]).tocsc()             # component-blocked dofs


def test_kkt_with_contact_rows_separates_pressed_blocks():
    import scipy.sparse.linalg as spla
    X, U, T, frag = two_blocks(n=8, overlap=0.01)
    E = boundary_edges_of(T)
    nv = len(X)
    cs = contact.contact_constraints(X, U, T, E, fragment=frag)
    K = graph_laplacian_K(T, nv)
    u_pred = U.T.ravel()
    f = K @ u_pred                                     # without contact: u = u_pred
    m = len(cs)
    KKT = sp.bmat([[K, cs.C.T], [cs.C, None]], format="csc")
    rhs = np.concatenate([f, -cs.g])
    sol = spla.spsolve(KKT, rhs)
    u, lam = sol[:2 * nv], sol[2 * nv:]
    assert np.linalg.norm(KKT @ sol - rhs) / np.linalg.norm(rhs) < 1e-10
    assert np.abs(cs.C @ u + cs.g).max() < 1e-12
    # sign convention: compressive contact gives lambda <= 0 (the paper's p_N <= 0)
    across = np.abs(cs.normal[:, 0]) == 1.0
    assert lam[across].max() < 0
    assert np.all(lam <= 1e-12)
    # load balance: f = K u + C^T lambda
    assert np.linalg.norm(f - K @ u - cs.C.T @ lam) <= 1e-10 * np.linalg.norm(f)
    # all selected rows before redundancy removal hold as well (consistent g)
    pairs = collision.detect_collisions(X, U, T, boundary_edges=E, fragment=frag)
    full = contact.select_contacts(X, U, T, E, pairs)
    assert np.abs(full.C @ u + full.g).max() < 1e-12
    # and the blocks no longer overlap: the ranking of rule 3 (nodes not yet in contact
    # first) covers all n + 1 interface node pairs with the n cell pairs
    Uc = u.reshape(2, nv).T
    assert len(pairs) == 10
    assert len(collision.detect_collisions(X, Uc, T, boundary_edges=E, fragment=frag)) == 0
    on_iface = np.flatnonzero(X[:, 0] == 1.0)
    assert np.all(np.isin(on_iface, np.concatenate([full.slave, full.a[full.xi == 1],
                                                    full.c[full.xi == 0]])))


def test_xi_snap_turns_near_duplicates_into_duplicates():
    X, U, T, frag = two_blocks(n=8, overlap=0.01)
    U[frag_vertices(T, frag, 1), 1] += 1e-7            # tiny tangential slip of block 2
    E = boundary_edges_of(T)
    pairs = collision.detect_collisions(X, U, T, boundary_edges=E, fragment=frag)
    raw = contact.select_contacts(X, U, T, E, pairs, xi_snap=0.0)
    snapped = contact.select_contacts(X, U, T, E, pairs)
    assert np.array_equal(raw.slave, snapped.slave)
    near_end = np.minimum(raw.xi, 1 - raw.xi) < 1e-3
    assert np.count_nonzero((raw.xi > 0) & (raw.xi < 1) & near_end) > 0
    assert np.all((snapped.xi[near_end] == 0) | (snapped.xi[near_end] == 1))
    # the gap at the predicted state does not change: C u_pred + g = dist either way
    u = U.T.ravel()
    assert np.allclose(raw.C @ u + raw.g, snapped.C @ u + snapped.g, atol=1e-15, rtol=0)
    # unsnapped: opposite rows are independent only at the 1e-6 level
    k_raw = contact.independent_rows(raw.C)
    s_raw = np.linalg.svd(raw.C[k_raw].toarray(), compute_uv=False)
    assert s_raw[-1] < 1e-5
    # snapped: they are exact duplicates, removed, and the rest is well conditioned
    k_snap = contact.independent_rows(snapped.C)
    s_snap = np.linalg.svd(snapped.C[k_snap].toarray(), compute_uv=False)
    assert len(k_snap) < len(k_raw) and s_snap[-1] > 1e-3
    with pytest.raises(ValueError, match="xi_snap"):
        contact.select_contacts(X, U, T, E, pairs, xi_snap=0.5)


def frag_vertices(T, frag, f):
    return np.unique(T[frag == f])


def netgen_pieces(ntri, k):
    """Unit square meshed by netgen as k x k glued pieces, cut apart (vertices per piece)."""
    from netgen.occ import Glue, MoveTo, OCCGeometry
    faces = []
    for i in range(k):
        for j in range(k):
            f = MoveTo(i / k, j / k).Rectangle(1 / k, 1 / k).Face()
            f.mat(f"p{i}{j}")
            faces.append(f)
    h = np.sqrt(2.3 / ntri)
    ngmesh = OCCGeometry(Glue(faces), dim=2).GenerateMesh(maxh=h)
    X = np.array(ngmesh.Coordinates())
    el = ngmesh.Elements2D().NumPy()
    T = np.array(el["nodes"][:, :3], dtype=np.int64) - 1
    frag = np.array(el["index"], dtype=np.int32) - 1
    P = X[T]
    neg = ((P[:, 1, 0] - P[:, 0, 0]) * (P[:, 2, 1] - P[:, 0, 1])
           - (P[:, 1, 1] - P[:, 0, 1]) * (P[:, 2, 0] - P[:, 0, 0])) < 0
    T[neg] = T[neg][:, [0, 2, 1]]
    key = T * k * k + frag[:, None]
    uniq, inv = np.unique(key.ravel(), return_inverse=True)
    return X[uniq // (k * k)], inv.reshape(T.shape).astype(np.int32), frag, h


def test_repeated_linearised_solves_converge_on_netgen_pieces():
    # Four netgen pieces, each expanded about its centroid: overlap 0.2 h on both cuts,
    # a four-piece junction in the middle. Detect, select, reduce and solve the KKT
    # system (SPD stand-in K) repeatedly, re-linearising at the last solution, with the
    # precision threshold 0.1 h so that closed contacts stay detected.
    import scipy.sparse.linalg as spla
    X, T, frag, h = netgen_pieces(2000, 2)
    E = boundary_edges_of(T)
    nv = len(X)
    cen = np.stack([np.bincount(frag, weights=X[T][:, :, d].mean(axis=1))
                    / np.bincount(frag) for d in range(2)], axis=1)
    vf = np.zeros(nv, dtype=np.int64)
    vf[T.ravel()] = np.repeat(frag, 3)
    U = 0.4 * h * (X - cen[vf])
    K = graph_laplacian_K(T, nv)
    f = K @ U.T.ravel()
    Uk, depth = U.copy(), []
    for _ in range(4):
        cs = contact.contact_constraints(X, Uk, T, E, fragment=frag, tol=0.1 * h)
        depth.append(-cs.dist.min() / h)
        assert np.linalg.svd(cs.C.toarray(), compute_uv=False)[-1] > 1e-8
        KKT = sp.bmat([[K, cs.C.T], [cs.C, None]], format="csc")
        rhs = np.concatenate([f, -cs.g])
        sol = spla.spsolve(KKT, rhs)
        assert np.linalg.norm(KKT @ sol - rhs) <= 1e-10 * np.linalg.norm(rhs)
        Uk = sol[:2 * nv].reshape(2, nv).T
    assert depth[0] == pytest.approx(0.2, rel=0.05)
    assert depth[1] < 1e-3 and max(depth[2:]) < 1e-10


if __name__ == "__main__":
    import sys
    sys.exit(pytest.main([__file__, "-q"]))
