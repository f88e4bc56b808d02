"""The supernodal L D L^T solve with SuperLU's factors (_ngfracture.SupernodalLDL, linalg.factor).

Checked against SuperLU's own solve and against the matrix: a backward error at rounding
level (|A x - b| below 1e-14 (|A| |x| + |b|), infinity norms), the same solution as
SuperLU's (1e-10), for single vectors and blocks of every width, bit for bit
the same on every call; bad factors and right-hand sides are refused (ValueError) with a message.
"""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ngfracture import _ngfracture as ext
from ngfracture import scenes
from ngfracture.linalg import factor as factor_module, sparse_schur as sparse_schur_module, triangular
from ngfracture.mechanics.problem import ElasticProblem


def random_rows(factor, k, rng):
    """k rows of three random entries each on the factorised dofs."""
    cols = rng.choice(np.flatnonzero(factor.factor_free), size=(k, 3))
    return sp.csr_matrix((rng.standard_normal(3 * k), (np.repeat(np.arange(k), 3), cols.ravel())),
                         shape=(k, factor.ndof))


def plate_factor(schur_by_dofs=False, grouped_products=False):
    """The default plate's tangent at its first increment, factorised as the simulation does."""
    scene = scenes.plate()
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, scene.dx)
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    factor = factor_module.EliminatedFactor(prob.tangent(), rows.fixed_dofs, support.pins,
                                            schur_by_dofs=schur_by_dofs, grouped_products=grouped_products)
    factor.factorise()
    return factor


def supernodal(lu):
    lower, _, pivots = triangular.factor_arrays(lu)
    return ext.SupernodalLDL(lu.shape[0], *lower, pivots, lu.perm_r.astype(np.int64))


def backward_error(A, x, b):
    """The normwise backward error |A x - b| / (|A| |x| + |b|), infinity norms."""
    return np.abs(A @ x - b).max() / (spla.norm(A, np.inf) * np.abs(x).max() + np.abs(b).max())


@pytest.mark.parametrize("k", [0, 1, 2, 3, 4, 5, 9])
def test_solves_like_superlu_with_a_rounding_level_backward_error(k):
    factor = plate_factor()
    lu = factor._lu
    assert np.array_equal(lu.perm_r, lu.perm_c)            # diagonal pivots: U = D L^T
    ldl = supernodal(lu)
    n = lu.shape[0]
    assert n >= factor_module.SUPERNODAL_MIN_DOFS and 0 < ldl.supernodes < n / 2   # real supernodes
    A = factor._factorised_block()
    rng = np.random.default_rng(k)
    B = rng.standard_normal(n) if k == 1 else np.asfortranarray(rng.standard_normal((n, k)))
    X = ldl.solve(B)
    assert X.shape == B.shape
    X_ref = lu.solve(np.asfortranarray(B))
    for j in range(k):
        x, x_ref, b = (X[:, j], X_ref[:, j], B[:, j]) if k > 1 else (X, X_ref, B)
        # backward stable: a few units of rounding (SuperLU's own solve: 2e-16); the same
        # solution as SuperLU's to the tolerance of the package's other direct-solve checks
        assert backward_error(A, x, b) < 1e-14
        assert np.linalg.norm(x - x_ref) <= 1e-10 * np.linalg.norm(x_ref)
    assert np.array_equal(ldl.solve(B), X)                  # deterministic


def test_a_block_solves_each_column_as_the_column_alone_to_rounding():
    factor = plate_factor()
    ldl = supernodal(factor._lu)
    B = np.asfortranarray(np.random.default_rng(7).standard_normal((factor._lu.shape[0], 4)))
    X = ldl.solve(B)
    for j in range(4):
        x = ldl.solve(np.ascontiguousarray(B[:, j]))
        assert np.linalg.norm(X[:, j] - x) <= 1e-12 * np.linalg.norm(x)


def test_the_factor_takes_the_supernodal_solve_from_its_size_on(monkeypatch):
    factor = plate_factor()
    x = factor.solve(np.ones(factor.ndof))
    assert isinstance(factor._ldl, ext.SupernodalLDL)
    monkeypatch.setattr(factor_module, "SUPERNODAL_MIN_DOFS", 10 ** 9)
    own = plate_factor()
    x_ref = own.solve(np.ones(own.ndof))
    assert own._ldl is False
    assert np.linalg.norm(x - x_ref) <= 1e-10 * np.linalg.norm(x_ref)


def test_the_sparse_schur_complement_after_a_supernodal_solve_is_that_of_full_solves(monkeypatch):
    """The sparse Schur path (Gilbert-Peierls on L) and the supernodal solve read the same
    factor arrays: a Schur complement made before a solve, and one of new rows after it,
    equal C K^+ C^T from full solves to rounding."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    factor = plate_factor()
    rng = np.random.default_rng(2)
    rows = lambda k: random_rows(factor, k, rng)

    for C in (rows(5), rows(5)):
        S = factor.schur(C)
        factor.solve(np.ones(factor.ndof))
        assert isinstance(factor._ldl, ext.SupernodalLDL)
        reference = C @ factor.solve(C.T.toarray())
        assert np.abs(S - reference).max() <= 1e-12 * np.abs(reference).max()


def test_a_small_spd_matrix_with_a_permutation():
    """A 2D Laplacian plus a random SPD perturbation, ordered by SuperLU: x = A^-1 b."""
    m = 30
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    A = (sp.kron(sp.eye(m), T) + sp.kron(T, sp.eye(m))).tocsc()
    rng = np.random.default_rng(1)
    A = (A + sp.diags(rng.uniform(0.1, 1.0, m * m))).tocsc()
    lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01, options={"SymmetricMode": True})
    assert np.array_equal(lu.perm_r, lu.perm_c)
    b = rng.standard_normal(m * m)
    x = supernodal(lu).solve(b)
    assert backward_error(A, x, b) < 1e-14


def test_bad_factors_are_refused():
    L = sp.csc_matrix(np.array([[1.0, 0.0], [0.5, 1.0]]))
    lp, li = L.indptr.astype(np.int64), L.indices.astype(np.int32)
    with pytest.raises(ValueError, match="permutation"):
        ext.SupernodalLDL(2, lp, li, L.data, np.ones(2), np.array([0, 0], dtype=np.int64))
    with pytest.raises(ValueError, match="pivot"):
        ext.SupernodalLDL(2, lp, li, L.data, np.array([1.0, 0.0]), np.array([0, 1], dtype=np.int64))
    U = sp.csc_matrix(np.array([[1.0, 0.5], [0.0, 1.0]]))       # an entry above the diagonal
    with pytest.raises(ValueError, match="below its diagonal"):
        ext.SupernodalLDL(2, U.indptr.astype(np.int64), U.indices.astype(np.int32), U.data, np.ones(2),
                          np.array([0, 1], dtype=np.int64))
    ldl = ext.SupernodalLDL(2, lp, li, L.data, np.ones(2), np.array([0, 1], dtype=np.int64))
    with pytest.raises(ValueError, match="rows"):
        ldl.solve(np.ones(3))


@pytest.mark.parametrize("block_bytes", [triangular.PRODUCT_BLOCK_BYTES, 8 * 5])
def test_the_product_of_sparse_columns_is_the_dense_product(block_bytes, monkeypatch):
    """X^T Y from per-column (rows, values), in one block and in blocks of a few columns,
    equals the dense product to rounding (1e-14 of the largest term): rows only one side
    reaches, empty columns and columns of one entry included."""
    monkeypatch.setattr(triangular, "PRODUCT_BLOCK_BYTES", block_bytes)
    rng = np.random.default_rng(11)
    n = 40

    def columns(count, reach):
        out = []
        for j in range(count):
            size = 0 if j == 3 else 1 if j == 4 else int(rng.integers(2, reach))
            rows = rng.permutation(n)[:size]          # unsorted, as a reach solve leaves them
            out.append((rows, rng.standard_normal(size)))
        return out

    xs, ys = columns(9, n), columns(7, n // 2)
    dense = [np.zeros((n, len(c))) for c in (xs, ys)]
    for D, cols in zip(dense, (xs, ys)):
        for j, (r, v) in enumerate(cols):
            D[r, j] = v
    expected = dense[0].T @ dense[1]
    scale = (np.abs(dense[0]).T @ np.abs(dense[1])).max()
    S = triangular.column_products(xs, ys, n)
    assert S.shape == (9, 7)
    assert np.abs(S - expected).max() <= 1e-14 * scale
    assert np.all(S[3] == 0.0)
    assert triangular.column_products([], ys, n).shape == (0, 7)


def test_the_supernodal_sparse_forward_solve_is_the_entrywise_one():
    """Y = L^-1 B through the supernodes a sparse B reaches equals Gilbert-Peierls'
    (SparseLowerSolve) and the dense solve to rounding (1e-13 of Y's largest entry), with
    the rows of whole supernodes, increasing, the same on any number of threads; a row
    out of range is refused."""
    factor = plate_factor()
    factor.solve(np.ones(factor.ndof))
    ldl, (lower, _, _) = factor._ldl, factor._factor_arrays()
    n = factor._lu.shape[0]
    rng = np.random.default_rng(4)
    k = 12
    cols = np.concatenate([rng.choice(n, size=3, replace=False) for _ in range(k)])
    B = sp.csc_matrix((rng.standard_normal(3 * k), (cols, np.repeat(np.arange(k), 3))), shape=(n, k))
    B[:, 5] = 0.0                                               # an empty column
    B.eliminate_zeros()
    bp, bi = B.indptr.astype(np.int64), B.indices.astype(np.int32)
    yp, yi, yx = ldl.forward_sparse(bp, bi, B.data)
    gp = ext.SparseLowerSolve(n, *lower, True, bp, bi, B.data)
    Y, Y_gp = (sp.csc_matrix((x, i, p), shape=(n, k)).toarray() for p, i, x in ((yp, yi, yx), gp))
    L = sp.csc_matrix((lower[2], lower[1], lower[0]), shape=(n, n)).toarray()
    np.fill_diagonal(L, 1.0)
    Y_dense = np.linalg.solve(L, B.toarray())
    assert np.abs(Y - Y_gp).max() <= 1e-13 * np.abs(Y_gp).max()
    assert np.abs(Y - Y_dense).max() <= 1e-13 * np.abs(Y_dense).max()
    assert yp[6] == yp[5]
    for j in range(k):
        rows = yi[yp[j]:yp[j + 1]]
        assert np.all(np.diff(rows) > 0)
        assert set(np.flatnonzero(Y_gp[:, j])) <= set(rows.tolist())
    with pytest.raises(ValueError, match="out of range"):
        ldl.forward_sparse(np.array([0, 1], dtype=np.int64), np.array([n], dtype=np.int32), np.ones(1))
    # many columns on several threads in contiguous ranges: the same arrays, bit for bit
    many = 300
    cols = np.concatenate([rng.choice(n, size=3, replace=False) for _ in range(many)])
    B = sp.csc_matrix((rng.standard_normal(3 * many), (cols, np.repeat(np.arange(many), 3))), shape=(n, many))
    bp, bi = B.indptr.astype(np.int64), B.indices.astype(np.int32)
    one = ldl.forward_sparse(bp, bi, B.data, 1)
    for threads in (2, 3, 8):
        assert all(np.array_equal(a, b) for a, b in zip(ldl.forward_sparse(bp, bi, B.data, threads), one))


@pytest.mark.parametrize("case", ["syrk", "negative weight", "small blocks"])
def test_the_weighted_product_of_sparse_columns_is_symmetric_and_the_dense_one(case, monkeypatch):
    """Y^T diag(w) Y (the Schur complement where U = D L^T) equals the dense product to
    rounding (1e-14 of the largest term) and is exactly symmetric: by the symmetric rank-k
    product, in column blocks where the dense copy is too big (the blocks above the diagonal
    by a product), and where a weight is not positive by the general one."""
    if case == "small blocks":
        monkeypatch.setattr(triangular, "PRODUCT_BLOCK_BYTES", 8 * 5)
    rng = np.random.default_rng(12)
    n, m = 30, 8
    ys = []
    for j in range(m):
        size = 0 if j == 2 else int(rng.integers(1, n))
        ys.append((rng.permutation(n)[:size], rng.standard_normal(size)))
    w = rng.uniform(0.5, 2.0, n)
    if case == "negative weight":
        w[ys[0][0][0]] = -1.0
    Y = np.zeros((n, m))
    for j, (r, v) in enumerate(ys):
        Y[r, j] = v
    expected = Y.T @ (w[:, None] * Y)
    scale = (np.abs(Y).T @ (np.abs(w)[:, None] * np.abs(Y))).max()
    S = triangular.weighted_products(ys, w, n)
    assert np.array_equal(S, S.T)
    assert np.abs(S - expected).max() <= 1e-14 * scale
    assert np.all(S[2] == 0.0)


@pytest.mark.parametrize("top_columns", [8, 1024])
def test_the_grouped_row_product_is_the_dense_one_whatever_the_groups(top_columns, monkeypatch, capfd):
    """Y^T diag(w) Y by a dense block of the rows most columns reach and groups of the others
    (G of the Schur complement by dofs) equals the dense product to rounding (1e-14 of the
    largest term) and is exactly symmetric, with the top block in one product or in many,
    in a new array or in the one given; a column that reaches nothing has zero entries, a
    product without a top block makes no BLAS call on it, and a weight that is not positive
    takes the general product. The columns are paths to a common root, as in a factor: a
    few top rows that all reach, and rows below reached by runs of columns."""
    rng = np.random.default_rng(13)
    n, m = 80, 41
    ys = []
    for j in range(m):
        start = int(rng.integers(0, n - 10))
        below = np.unique(np.concatenate([[start], rng.integers(start, n - 10, 8)]))
        rows = np.concatenate([below, np.arange(n - 10, n)]) if j != 5 else np.zeros(0, int)
        ys.append((rows, rng.standard_normal(len(rows))))
    w = rng.uniform(0.5, 2.0, n)
    Y = np.zeros((n, m))
    for j, (r, v) in enumerate(ys):
        Y[r, j] = v
    expected = Y.T @ (w[:, None] * Y)
    scale = (np.abs(Y).T @ (w[:, None] * np.abs(Y))).max()
    monkeypatch.setattr(triangular, "TOP_BLOCK_COLUMNS", top_columns)
    monkeypatch.setattr(triangular, "GROUP_ROWS", 3)
    S = triangular.grouped_row_products(ys, w, n)
    room = np.full(m * m + 7, np.nan)
    into = triangular.grouped_row_products(ys, w, n, out=room[:m * m].reshape(m, m))
    assert np.shares_memory(into, room) and np.array_equal(into, S)      # written where asked
    assert np.array_equal(S, S.T)
    assert np.abs(S - expected).max() <= 1e-14 * scale
    assert np.all(S[5] == 0.0)
    reaching = np.count_nonzero(Y, axis=1)
    groups = triangular._row_groups(reaching, triangular.TOP_ROW_SHARE * m)
    assert np.all(reaching[n - 10:] >= triangular.TOP_ROW_SHARE * m)      # the top block is used
    assert len(groups) >= 2 and max(b - a for a, b in groups) <= 3
    assert sum(b - a for a, b in groups) == np.count_nonzero((reaching > 0) & (reaching < triangular.TOP_ROW_SHARE * m))
    few = [(r[r < n - 10], v[r < n - 10]) for r, v in ys]       # no row that half the columns reach
    Y[n - 10:] = 0.0
    assert np.count_nonzero(Y, axis=1).max() < triangular.TOP_ROW_SHARE * m
    assert np.abs(triangular.grouped_row_products(few, w, n) - Y.T @ (w[:, None] * Y)).max() <= 1e-14 * scale
    w[ys[0][0][0]] = -1.0
    expected = Y.T @ (w[:, None] * Y)
    assert np.abs(triangular.grouped_row_products(few, w, n) - expected).max() <= 1e-14 * scale
    assert "DSYRK" not in "".join(capfd.readouterr())             # no BLAS call on an empty block


def test_a_block_is_added_into_the_upper_triangle_in_place_and_bad_places_are_refused():
    """``AddLowerBlock`` adds a symmetric block's lower triangle at increasing places into
    the upper triangle of S, in S itself; places that do not increase, or an S it would
    have to copy (Fortran-ordered, float32), are refused before anything changes."""
    S = np.zeros((6, 6))
    B = np.asfortranarray(np.arange(16.0).reshape(4, 4))
    at = np.array([0, 2, 3, 5])
    ext.AddLowerBlock(S, at, B)
    expected = np.zeros((6, 6))
    for i in range(4):
        for j in range(i, 4):
            expected[at[i], at[j]] = B[j, i]
    assert np.array_equal(S, expected)
    with pytest.raises(ValueError, match="places must increase"):
        ext.AddLowerBlock(S, np.array([0, 3, 2, 5]), B)
    for other in (np.zeros((6, 6)).T, np.zeros((6, 6), dtype=np.float32)):
        with pytest.raises(TypeError):
            ext.AddLowerBlock(other, at, B)
    assert np.array_equal(S, expected)


def test_the_rows_product_is_c_g_ct_exactly_symmetric_on_any_number_of_threads():
    """S = C G C^T of sparse rows and a dense symmetric G (the Schur complement by dofs, in
    C++) equals the dense product to rounding (1e-14 of the largest term), is exactly
    symmetric and the same to the last bit on 1, 2 and 5 threads (more threads than
    blocks of rows too); an empty row gives zeros, a column outside G is refused."""
    rng = np.random.default_rng(14)
    p, m = 40, 37
    A = rng.standard_normal((p, p))
    G = A @ A.T
    G = 0.5 * (G + G.T)
    C = sp.random(m, p, density=0.2, random_state=15, format="csr")
    C[3] = 0.0
    C.eliminate_zeros()
    expected = C.toarray() @ G @ C.toarray().T
    scale = (np.abs(C.toarray()) @ np.abs(G) @ np.abs(C.toarray()).T).max()
    one = ext.RowsProduct(C.indptr.astype(np.int64), C.indices, C.data, G, 1)
    assert np.abs(one - expected).max() <= 1e-14 * scale
    assert np.array_equal(one, one.T) and np.all(one[3] == 0.0)
    for threads in (2, 5):
        assert np.array_equal(ext.RowsProduct(C.indptr.astype(np.int64), C.indices, C.data, G, threads), one)
    with pytest.raises(ValueError, match="outside G"):
        ext.RowsProduct(C.indptr.astype(np.int64), C.indices, C.data, G[:5, :5], 1)


def test_the_schur_complement_of_rows_met_before_keeps_their_entries(monkeypatch):
    """A call whose rows are partly the last call's (reordered) and partly new solves only
    the new rows, takes the known entries from the last call (bit for bit) and equals
    C K^+ C^T from full solves to rounding (1e-12), exactly symmetric."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    factor = plate_factor()
    rng = np.random.default_rng(8)
    rows = lambda k: random_rows(factor, k, rng)

    first = rows(12)
    S1 = factor.schur(first)
    keep = np.array([7, 2, 9, 0, 4])
    second = sp.vstack([first[keep], rows(6)]).tocsr()
    solves = []
    monkeypatch.setattr(sparse_schur_module, "reach_solves",
                        lambda *a, _f=sparse_schur_module.reach_solves: solves.append(a[3].shape[0]) or _f(*a))
    S2 = factor.schur(second)
    assert solves == [6]
    assert np.array_equal(S2[:5, :5], S1[np.ix_(keep, keep)])
    assert np.array_equal(S2, S2.T)
    reference = second @ factor.solve(second.T.toarray())
    assert np.abs(S2 - reference).max() <= 1e-12 * np.abs(reference).max()


def test_the_row_by_row_schur_complement_by_grouped_products_is_the_plain_one(monkeypatch):
    """With ``grouped_products`` (3D) the row-by-row S takes its new rows' products by
    groups of the factor's rows: the same S as the one product to rounding (1e-14 of its
    largest entry) and as full solves (1e-12), exactly symmetric, on a first call and on a
    call that keeps some rows of it and adds others."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    monkeypatch.setattr(triangular, "TOP_BLOCK_COLUMNS", 8)
    plain, grouped = plate_factor(), plate_factor(grouped_products=True)
    rng = np.random.default_rng(16)
    first = random_rows(plain, 40, rng)
    second = sp.vstack([first[::3], random_rows(plain, 25, rng)]).tocsr()
    for C in (first, second):
        S, reference = grouped.schur(C), plain.schur(C)
        assert np.array_equal(S, S.T)
        assert np.abs(S - reference).max() <= 1e-14 * np.abs(reference).max()
        solved = C @ plain.solve(C.T.toarray())
        assert np.abs(S - solved).max() <= 1e-12 * np.abs(solved).max()


def test_the_schur_complement_by_dofs_solves_no_row_whose_dofs_were_met(monkeypatch):
    """By dofs (3D contact rows, re-linearised every call): rows with new values on dofs met
    before cost no triangular solve, rows on new dofs grow G by those dofs alone (one solve
    each, no reach solve); S equals C K^+ C^T from full solves to rounding (1e-12) and is
    exactly symmetric; entries at dofs that are not factorised are ignored."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    factor = plate_factor(schur_by_dofs=True)
    rng = np.random.default_rng(9)
    first = random_rows(factor, 10, rng)
    solves = []
    monkeypatch.setattr(sparse_schur_module, "reach_solves",
                        lambda *a, _f=sparse_schur_module.reach_solves: solves.append(a[3].shape[0]) or _f(*a))
    relinearised = first.copy()
    relinearised.data = rng.standard_normal(relinearised.nnz)     # same dofs, other values
    fixed = sp.csr_matrix(([1.0], ([0], [factor.fixed_dofs[0]])), shape=(1, factor.ndof))
    more = random_rows(factor, 2, rng)
    for C in (first, relinearised, sp.vstack([relinearised, fixed, more]).tocsr()):
        S = factor.schur(C)
        assert np.array_equal(S, S.T)
        reference = C @ factor.solve(C.T.toarray())
        assert np.abs(S - reference).max() <= 1e-12 * np.abs(reference).max()
    dofs_first = len(np.unique(first.indices))
    dofs_more = len(np.setdiff1d(more.indices, first.indices))
    assert solves == [dofs_first]
    assert len(factor._sparse._dofs) == dofs_first + dofs_more


def test_g_grows_in_its_room_with_the_numbers_of_a_fresh_array(monkeypatch):
    """G grown call after call by new dofs lives at the start of an array with room to grow
    and moves within it (the rows overlapping their new places included): bit for bit the
    G of a DofSchur that takes a fresh array at every growth, exactly symmetric, and K^-1
    on the dofs from full solves to rounding (1e-12); the room is made once while it lasts."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    rng = np.random.default_rng(11)
    roomy, tight = plate_factor(schur_by_dofs=True), plate_factor(schur_by_dofs=True)
    calls = [random_rows(roomy, 6, rng)] + [random_rows(roomy, 1, rng) for _ in range(4)]
    rooms, sizes = set(), set()
    for k, C in enumerate(calls):
        monkeypatch.setattr(sparse_schur_module, "GROWTH_ROOM", 400)
        roomy.schur(sp.vstack(calls[:k + 1]).tocsr())
        monkeypatch.setattr(sparse_schur_module, "GROWTH_ROOM", 0)
        if tight._sparse is not None:
            tight._sparse._room = None                       # a fresh array at every growth
        tight.schur(sp.vstack(calls[:k + 1]).tocsr())
        G, dofs = roomy._sparse._G, roomy._sparse._dofs
        assert np.array_equal(G, tight._sparse._G) and np.array_equal(G, G.T)
        E = sp.csr_matrix((np.ones(len(dofs)), (np.arange(len(dofs)), dofs)), shape=(len(dofs), roomy.ndof))
        reference = E @ roomy.solve(E.T.toarray())
        assert np.abs(G - reference).max() <= 1e-12 * np.abs(reference).max()
        sizes.add(len(dofs))
        if roomy._sparse._room is not None:
            rooms.add(id(roomy._sparse._room))
    assert len(rooms) == 1 and len(sizes) >= 4          # grown three times or more in one room


def test_the_schur_complement_by_dofs_of_rows_met_in_the_last_product_is_its_own_numbers(monkeypatch):
    """A call whose rows (bitwise) are all rows of the last product, reordered and fewer
    (a contact round's equations after the complementarity problem over all its candidates),
    takes S from that product without multiplying: bit for bit what the whole product of
    its rows gives (a DofSchur that meets them after the same growth of G, with no product
    kept). A call with a row of new values multiplies again."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    rng = np.random.default_rng(10)
    factor, fresh_factor = plate_factor(schur_by_dofs=True), plate_factor(schur_by_dofs=True)
    first = random_rows(factor, 14, rng)
    subset = first[[12, 0, 5, 9, 1, 7, 2]]
    for f in (factor, fresh_factor):
        f.schur(first)
    kept = factor._sparse._made[1]
    S = factor.schur(subset)
    assert factor._sparse._made[1] is kept                      # no product made
    fresh_factor._sparse._made = ({}, None)                    # the same G, no product kept
    assert np.array_equal(S, fresh_factor.schur(subset))
    assert np.array_equal(S, S.T)
    reference = subset @ factor.solve(subset.T.toarray())
    assert np.abs(S - reference).max() <= 1e-12 * np.abs(reference).max()
    changed = subset.copy()
    changed.data[:3] = rng.standard_normal(3)
    factor.schur(changed)
    assert factor._sparse._made[1] is not kept


def test_a_3d_tangent_factorised_for_one_system_takes_the_schur_complement_by_rows(monkeypatch):
    """Full Newton factorises every iterate for the solves of one system: in 3D its Schur
    complement is built from the rows (one triangular solve per row), not from K^-1 on their
    dofs, which a kept tangent (modified Newton) builds once for the rows of many rounds
    (the coarse sphere's stick rows touch three times as many dofs as they are rows).
    Both Newton variants end at the same equilibrium (to the Newton tolerance, 1e-10)."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    monkeypatch.setattr(factor_module, "AUGMENTED_MAX_DOFS", 0)     # the Schur path, as at the default mesh
    solved = []
    monkeypatch.setattr(sparse_schur_module, "reach_solves",
                        lambda *a, _f=sparse_schur_module.reach_solves: solved.append(a[3].shape[0]) or _f(*a))
    scene = scenes.sphere3d(maxh=0.4, fine=0.15)
    results = {}
    for method in ("full", "modified"):
        prob = ElasticProblem(scene.mesh, scene.material)
        scene.apply_load(prob, scene.dx)
        m = prob.assemble_constraints().C.shape[0]
        solved.clear()
        status = prob.solve(method=method, inverse="superlu", fix_free_modes=True)
        assert status.converged
        results[method] = (status.iterations, list(solved), prob.u.vec.FV().NumPy().copy())
    iterations, calls, u = results["full"]
    assert iterations >= 2 and len(calls) >= iterations and max(calls) <= m
    assert max(results["modified"][1]) > 2 * m
    reference = results["modified"][2]
    assert np.abs(u - reference).max() <= 1e-10 * np.abs(reference).max()
