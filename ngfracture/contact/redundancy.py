"""Removal of redundant contact rows: a maximal linearly independent subset (paper Fig. 5).

Contact rows can depend on each other (exact duplicates found through two triangle pairs,
the three-body node-to-node cycle of the paper's Fig. 5, several rows of one junction) or
on the Dirichlet rows; imposed together as equalities they make the KKT system singular.
:func:`independent_rows` keeps a maximal independent subset by a column-pivoted QR
(C++: ``cpp_ext/independent_rows.cpp``), split into the connected components of the rows'
sparsity graph, and skips the QR where a Cholesky factorisation of the rows' Gram matrix
proves them independent: for all rows at once (here), and per component (C++, components
of at least :data:`GRAM_MIN_ROWS` rows). The QR works on the supports of its vectors, with
the floating-point operations of the QR on dense vectors on their nonzeros, so it picks the
same rows bit for bit. Timings are in ``docs/contact.md``.
"""
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, reverse_cuthill_mckee

from .. import _ngfracture as _ext

__all__ = ["independent_rows", "holds_on_columns", "GRAM_MIN_ROWS", "DENSE_QR_MAX_ENTRIES"]

#: components of more than ``dense_limit`` rows whose dense block (rows x columns touched)
#: has at most this many entries (160 MB) take LAPACK's pivoted QR on that block, BLAS-3
#: (a contact component of the free sphere, 1165 rows and 87 hold rows on 1338 columns:
#: 0.3 s against 8.5 s for the C++ QR on the supports, whose vectors fill in)
DENSE_QR_MAX_ENTRIES = 20_000_000

#: components of at least this many rows, to be decided by the pivoted QR, are first tested
#: by a Cholesky factorisation of their Gram matrix (C++), which keeps them all without the
#: QR where it proves them clearly independent (:func:`independent_rows`)
GRAM_MIN_ROWS = 8


def independent_rows(C, fixed_dofs=None, G=None, rtol=1e-8, method="auto", dense_limit=256):
    """A maximal set of rows of C, linearly independent and independent of the Dirichlet rows.

    Rows are scaled to unit norm, columns fixed by Dirichlet conditions are eliminated
    (``fixed_dofs``) or the span of general Dirichlet rows ``G`` is projected out, and a
    column-pivoted QR of the remaining C^T decides (C++: Businger-Golub pivoting on a
    modified Gram-Schmidt QR with reorthogonalisation; single-threaded, as threaded LAPACK
    is slower on blocks this small). The work splits into the connected components of the
    rows' sparsity graph (rows sharing a dof, through C or G), each a dense QR restricted to
    its nonzero columns; single rows need no QR. Exact duplicates, the three-body
    node-to-node redundancy of the paper's Fig. 5 and rows implied by the Dirichlet rows
    are all removed this way. Cost per component: O(k r n) for k rows, rank r, n columns on
    dense vectors; the QR visits only the supports of its vectors (the nonzeros of a
    contact row and what the orthogonalisation fills in), with the same result bit for
    bit. A component of at least ``GRAM_MIN_ROWS`` rows is first tested by an envelope
    Cholesky factorisation of its Gram matrix, shifted as in the test for all rows below:
    where that proves every row farther than rtol from the span of the others, the QR
    would keep them all, and is skipped.

    Parameters
    ----------
    C : scipy.sparse matrix or array_like, shape (m, ndof)
        Constraint rows.
    fixed_dofs : array_like of int, optional
        Dofs fixed by Dirichlet conditions (rows e_d of the Dirichlet block).
    G : scipy.sparse matrix or array_like, shape (p, ndof), optional
        General Dirichlet / multi-point rows that are kept in any case.
    rtol : float
        Rank threshold on |R_kk| for unit-norm rows: a row within rtol (relative) of the
        span of the kept rows is dropped; its constraint then holds up to about rtol
        times the displacement. Smaller values keep nearly dependent rows and make the
        multipliers blow up like 1 / sigma_min.
    method : {"auto", "pivoted", "banded"}
        "pivoted": the column-pivoted QR on every component. "banded": for components
        without G rows, a sparse alternative: greedy selection in reverse Cuthill-McKee
        order by a banded Givens QR of C^T (|R_jj| > rtol keeps row j). It is not
        pivoted and not rank-revealing: every kept row is > rtol away from the span of
        the rows kept before it, yet the kept set can be nearly singular when singular
        values are spread below ~1e-8 (near-duplicate rows without end snapping, see
        ``docs/contact.md``; with ``xi_snap`` both methods agree). Fine for exact
        duplicates and Fig. 5 cycles. "auto": pivoted for components of at most
        dense_limit rows; above, LAPACK's pivoted QR (dgeqp3, the same pivoting and
        threshold) on the component's dense block where it has at most
        :data:`DENSE_QR_MAX_ENTRIES` entries, else banded (pivoted with G rows).
    dense_limit : int
        Component size up to which "auto" uses the pivoted QR.

    Returns
    -------
    numpy.ndarray of int64
        Indices of the kept rows, ascending. Pivoting picks the largest residual and,
        among residuals equal to 1e-12 relative, the lowest index: duplicates keep their
        first occurrence.

    Raises
    ------
    ValueError
        On shapes that do not match, dof indices out of range, non-finite entries,
        rtol <= 0 or an unknown method.
    """
    C, fixed, G = _checked(C, fixed_dofs, G, rtol, method)
    if C.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    Ca, Gn, lab_c, lab_g, alive = _reduced_rows(C, fixed, G, rtol)
    if _clearly_independent(Ca, Gn, rtol, lab_c, lab_g):
        return alive.astype(np.int64)
    return alive[_pivoted_qr(Ca, Gn, lab_c, lab_g, rtol, method, dense_limit)].astype(np.int64)


def _checked(C, fixed_dofs, G, rtol, method):
    """C and G as float64 CSR matrices and the fixed dofs as an array (None where not
    given), after the checks :func:`independent_rows` documents."""
    C = sp.csr_matrix(C, dtype=np.float64)
    ndof = C.shape[1]
    if not np.isfinite(C.data).all():
        raise ValueError("C contains NaN or inf")
    if not (np.isscalar(rtol) and np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol must be a positive number, got {rtol!r}")
    if G is not None:
        G = sp.csr_matrix(G, dtype=np.float64)
        if G.shape[1] != ndof:
            raise ValueError(f"G must have {ndof} columns like C, got {G.shape[1]}")
        if not np.isfinite(G.data).all():
            raise ValueError("G contains NaN or inf")
    fixed = None
    if fixed_dofs is not None:
        fixed = np.asarray(fixed_dofs, dtype=np.int64).ravel()
        if fixed.size and (fixed.min() < 0 or fixed.max() >= ndof):
            raise ValueError(f"fixed_dofs holds dofs outside [0, {ndof})")
    if method not in ("auto", "pivoted", "banded"):
        raise ValueError(f"method must be 'auto', 'pivoted' or 'banded', got {method!r}")
    return C, fixed, G


def _reduced_rows(C, fixed, G, rtol):
    """The rows of C and G scaled to unit norm, fixed dofs dropped, columns renumbered to
    the ones the rows touch.

    Plain arrays instead of scipy operations, each of which costs about a millisecond:
    this runs in every contact round. Returns the rows of C that survive the elimination
    (farther than rtol from zero) and G, as CSR matrices with sorted indices, their
    component labels (rows of C and G, connected through shared dofs), and the indices of
    the surviving rows of C (rows that vanished depend on the Dirichlet rows).
    """
    m, ndof = C.shape
    C = C.copy()
    C.sum_duplicates()
    row, col, val = _unit_rows(C)
    if fixed is not None and fixed.size:
        is_fixed = np.zeros(ndof, dtype=bool)
        is_fixed[fixed] = True
        keep = ~is_fixed[col]
        row, col, val = row[keep], col[keep], val[keep]               # eliminate fixed dofs
    if G is not None and G.shape[0]:
        G = G.copy()
        G.sum_duplicates()
        grow, gcol, gval = _unit_rows(G)
        p = G.shape[0]
    else:
        grow = gcol = np.zeros(0, dtype=np.int64)
        gval = np.zeros(0)
        p = 0
    # the columns the rows touch, renumbered in increasing order (np.unique's numbering)
    touched = np.zeros(ndof, dtype=bool)
    touched[col] = touched[gcol] = True
    number = np.cumsum(touched) - 1
    col, gcol = number[col], number[gcol]
    n = int(np.count_nonzero(touched))
    # components of the bipartite graph rows (C then G) -- dofs
    nodes = m + p + n
    graph = sp.csr_matrix((np.ones(len(col) + len(gcol), dtype=np.int8),
                           (np.concatenate([row, m + grow]), m + p + np.concatenate([col, gcol]))),
                          shape=(nodes, nodes))
    _, labels = connected_components(graph, directed=False)
    lab_c, lab_g = labels[:m], labels[m:m + p]
    rem_norm = np.sqrt(np.bincount(row, weights=val * val, minlength=m))
    alive = np.flatnonzero(rem_norm > rtol)
    Ca = sp.csr_matrix((val, (row, col)), shape=(m, n))[alive]
    Ca.sort_indices()
    Gn = sp.csr_matrix((gval, (grow, gcol)), shape=(p, n))
    Gn.sort_indices()
    return Ca, Gn, lab_c[alive], lab_g, alive


def _pivoted_qr(Ca, Gn, lab_c, lab_g, rtol, method, dense_limit):
    """Rows of Ca kept by the QR of :func:`independent_rows`, per component: LAPACK's on the
    dense blocks of the large components (:func:`_dense_components`), C++ on the others."""
    dense = _dense_components(Ca, lab_c, dense_limit) if method == "auto" else []
    if not len(dense):
        return _supports_qr(Ca, Gn, lab_c, lab_g, rtol, method, dense_limit)
    kept = []
    for label in dense:
        rows = np.flatnonzero(lab_c == label)
        kept.append(rows[_dense_pivoted_qr(Ca[rows], Gn[lab_g == label], rtol)])
    rest, g_rest = np.flatnonzero(~np.isin(lab_c, dense)), ~np.isin(lab_g, dense)
    kept.append(rest[_supports_qr(Ca[rest], Gn[g_rest], lab_c[rest], lab_g[g_rest], rtol, method, dense_limit)])
    return np.sort(np.concatenate(kept))


def _dense_components(Ca, labels, dense_limit):
    """The components of more than ``dense_limit`` rows whose dense block (rows x the
    columns they touch) has at most :data:`DENSE_QR_MAX_ENTRIES` entries."""
    rows_per = np.bincount(labels) if len(labels) else np.zeros(0, dtype=np.int64)
    large = np.flatnonzero(rows_per > dense_limit)
    if not len(large):
        return large
    columns_per = _columns_per_component(Ca, labels.astype(np.int64), len(rows_per))
    return large[rows_per[large] * columns_per[large] <= DENSE_QR_MAX_ENTRIES]


def _columns_per_component(M, labels, components):
    """The number of distinct columns the rows of each component touch (CSR ``M``, int64
    ``labels`` per row)."""
    pairs = np.unique(np.repeat(labels, np.diff(M.indptr)) * M.shape[1] + M.indices)
    return np.bincount(pairs // M.shape[1], minlength=components)


def _dense_pivoted_qr(Cc, Gc, rtol):
    """Rows of the unit rows Cc kept by LAPACK's column-pivoted QR (dgeqp3, Businger-Golub
    pivoting as the C++ QR) of Cc^T after the span of the rows Gc is projected out (twice,
    for orthogonality to rounding): the leading pivots with |R_kk| > rtol."""
    columns = np.unique(np.concatenate([Cc.indices, Gc.indices]))
    A = Cc[:, columns].toarray().T
    if Gc.shape[0]:
        Qg, Rg, _ = sla.qr(Gc[:, columns].toarray().T, mode="economic", pivoting=True, check_finite=False)
        Qg = Qg[:, np.abs(np.diag(Rg)) > rtol]
        A -= Qg @ (Qg.T @ A)
        A -= Qg @ (Qg.T @ A)
    R, pivots = sla.qr(A, mode="r", pivoting=True, check_finite=False)
    small = np.flatnonzero(np.abs(np.diag(R)) <= rtol)
    rank = small[0] if len(small) else min(R.shape)
    return np.sort(pivots[:rank])


def _supports_qr(Ca, Gn, lab_c, lab_g, rtol, method, dense_limit):
    """Rows of Ca kept by the C++ QR of :func:`independent_rows`, per component."""
    position = np.zeros(Ca.shape[0], dtype=np.int64)
    largest = np.bincount(lab_c).max(initial=0)
    if Ca.shape[0] and (method == "banded" or (method == "auto" and largest >= min(GRAM_MIN_ROWS, dense_limit + 1))):
        # processing order of the rows of a component for the banded QR and the Gram test
        # (its envelope): reverse Cuthill-McKee of the row graph. Smaller components take
        # the pivoted QR in index order, whatever the positions (the C++ sorts them): the
        # ordering would be work for nothing
        pattern = Ca.copy()
        pattern.data = np.ones_like(pattern.data)
        order = reverse_cuthill_mckee(sp.csr_matrix(pattern @ pattern.T), symmetric_mode=True)
        position[order] = np.arange(Ca.shape[0])
    code = {"auto": 0, "pivoted": 1, "banded": 2}[method]
    return _ext.IndependentRowsSparse(
        Ca.shape[1], Ca.indptr.astype(np.int64), Ca.indices.astype(np.int32), Ca.data,
        lab_c.astype(np.int32), position, Gn.indptr.astype(np.int64),
        Gn.indices.astype(np.int32), Gn.data, lab_g.astype(np.int32), float(rtol), code,
        int(dense_limit), int(GRAM_MIN_ROWS))


def _unit_rows(M):
    """(row, column, value) of the nonzeros of a CSR matrix, each row scaled to unit norm."""
    row = np.repeat(np.arange(M.shape[0], dtype=np.int64), np.diff(M.indptr))
    nz = M.data != 0
    row, col, val = row[nz], M.indices[nz].astype(np.int64), M.data[nz]
    norms = np.sqrt(np.bincount(row, weights=val * val, minlength=M.shape[0]))
    return row, col, val / norms[row]


def _clearly_independent(C, G, rtol, labels_c, labels_g, limit=1500):
    """True if every row of [G; C] is farther than rtol from the span of all the others.

    Then any QR of the rows, pivoted or not, has |R_kk| >= sigma_min > rtol and keeps them
    all, so the pivoted QR can be skipped: a Cholesky factorisation of the Gram matrix
    minus (rtol^2 + rounding) I succeeds when sigma_min^2 exceeds that shift. This is the
    usual case in a contact round: one large component of contact rows joined by the hold
    rows of the pieces, whose pivoted QR costs far more than the Cholesky factorisation of
    the Gram matrix (``docs/contact.md``). Rows with a dependence fall through to the QR,
    which decides which to drop. Tried only where the QR would cost more (sum over the
    components of rows^2 x columns above rows^3 of the test: many small components are
    cheap to QR, and there a failed test only adds time), not above ``limit`` rows, and not
    where rtol^2 is within ten times the rounding of the test.
    """
    M = sp.vstack([G, C]).tocsr()
    k = M.shape[0]
    if k == 0 or k > limit:
        return k == 0
    labels = np.concatenate([labels_g, labels_c]).astype(np.int64)
    rows_per = np.bincount(labels).astype(float)
    columns_per = _columns_per_component(M, labels, len(rows_per))
    if np.sum(rows_per ** 2 * columns_per) < float(k) ** 3:
        return False
    gram = (M @ M.T).toarray()
    # backward error of forming and factorising the Gram matrix: a few k eps |Gram|
    rounding = 4 * k * np.finfo(float).eps * np.abs(gram).sum(axis=1).max()
    if rtol ** 2 < 10 * rounding:
        return False
    gram[np.diag_indices(k)] -= rtol ** 2 + rounding
    try:
        sla.cholesky(gram, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        return False
    return True


def holds_on_columns(G, C, fixed_dofs=None, rtol=1e-8, max_group=64):
    """The combinations of the rows of ``G`` that rows of ``C`` can depend on.

    A row of C lies in the span of G and the other rows of C only through combinations of
    G's rows that vanish on every free column no row of C touches. The rows that hold a
    piece on its six rigid modes are dense over the whole piece, and given to
    :func:`independent_rows` as they are they fill every row of C in the QR with the
    piece's dofs (the free sphere: 97 % of a contact solve in that QR). Rows of G are
    grouped through the untouched columns; a group's combinations vanishing there (the
    left null space of its unit rows restricted to them, singular values up to ``rtol``)
    replace it, with those columns set to zero; a group of full rank there is dropped (a
    rigid mode of a piece with three untouched vertices off one line). In exact arithmetic
    the span that rows of C can reach is the same, so :func:`independent_rows` keeps a set
    of the same size; the QR's pivot order, and so which of several dependent rows it
    keeps, can differ. Groups of more than ``max_group`` rows are kept as they are.

    Parameters
    ----------
    G : scipy.sparse matrix or None, shape (p, ndof)
        Rows kept in any case (independent_rows's ``G``).
    C : scipy.sparse matrix, shape (m, ndof)
        The rows to be judged.
    fixed_dofs : array_like of int, optional
        Dofs fixed by Dirichlet conditions (eliminated: no condition there).
    rtol : float
        Rank threshold for unit rows, as in :func:`independent_rows`.
    max_group : int
        Largest group reduced.

    Returns
    -------
    scipy.sparse.csr_matrix or None
        The rows replacing G (unit norm before the combination), None if G is None.
    """
    if G is None:
        return None
    G = sp.csr_matrix(G, dtype=np.float64)
    G.sum_duplicates()
    C = sp.csr_matrix(C)
    ndof = G.shape[1]
    off = np.ones(ndof, dtype=bool)
    off[C.indices] = False
    if fixed_dofs is not None:
        off[np.asarray(fixed_dofs, dtype=np.int64)] = False
    row, col, val = _unit_rows(G)
    G = sp.csr_matrix((val, (row, col)), shape=G.shape)
    G_off = G[:, np.flatnonzero(off)].tocsr()
    touching = np.diff(G_off.indptr) > 0
    if not touching.any():
        return G.tocsr()
    rows = np.flatnonzero(touching)
    pattern = G_off[rows]
    pattern.data = np.ones_like(pattern.data)
    ngroups, group = connected_components(sp.csr_matrix(pattern @ pattern.T), directed=False)
    blocks = [G[np.flatnonzero(~touching)]]
    off_columns = sp.diags(off.astype(np.float64))
    for g in range(ngroups):
        R = rows[group == g]
        if len(R) > max_group:
            blocks.append(G[R])
            continue
        sub = G_off[R]
        U, s, _ = np.linalg.svd(sub[:, np.unique(sub.indices)].toarray(), full_matrices=True)
        null = U[:, int(np.count_nonzero(s > rtol)):]
        if null.shape[1]:
            combined = sp.csr_matrix(null.T) @ G[R]
            blocks.append(sp.csr_matrix(combined - combined @ off_columns))
    return sp.vstack(blocks).tocsr()
