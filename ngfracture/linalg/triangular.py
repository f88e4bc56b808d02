"""Triangular solves with SuperLU's factors Pr K_ff Pc = L U, in the C++ kernels.

Two kernels of the extension solve with the factors of linalg.factor.EliminatedFactor
faster than SuperLU's own solve where it matters (docs/solvers.md, items 2 and 5):

- ``_ext.SupernodalLDL``: where every pivot was diagonal (Pr = Pc^T), the symmetric K_ff
  has U = D L^T; L is packed once into dense supernodal panels, and a solve runs forward
  through them, scales by D^-1 and runs back through their transposes
  (:func:`supernodal_solver`).
- ``_ext.SparseLowerSolve``: a Gilbert-Peierls solve of right-hand sides with few nonzeros
  (constraint rows) that touches only the columns of the factor their nonzeros reach, for
  the Schur complement S = C K_ff^-1 C^T = X^T Y, Y = L^-1 Pr C^T, X = U^-T Pc^T C^T
  (X = D^-1 Y where U = D L^T) (:func:`reach_solves`).

Both read the factors as the arrays of :func:`factor_arrays`.
"""
import numpy as np
import scipy.sparse as sp
from scipy.linalg import blas

from .. import _ngfracture as _ext
from .sparse import single_threaded_blas

#: rows reached by at least this share of the columns form the dense top block of
#: :func:`grouped_row_products` (the separators near the root of the elimination tree) ...
TOP_ROW_SHARE = 0.5
#: ... multiplied by pairs of blocks of this many columns, each written into G as it is made
#: (one product of all columns would be a second m x m array)
TOP_BLOCK_COLUMNS = 1024
#: below the top, consecutive rows form a group while each is reached by at most this factor
#: more columns than the first (the groups' work then within 1 % of the sum over their rows
#: of the square of the columns reaching each, on the default sphere's G of 7099 dofs) ...
GROUP_GROWTH = 1.1
#: ... and at most this many rows
GROUP_ROWS = 256
#: threads of the supernodal reach solves and of the product S = C_d G C_d^T of the Schur
#: complement (``_ngfracture.RowsProduct``): every column or entry
#: is computed the same way whichever thread takes it, so the result does not depend on how
#: many there are
PRODUCT_THREADS = 2


def factor_arrays(lu):
    """SuperLU's factors Pr K_ff Pc = L U as the arrays of the C++ triangular solves.

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU

    Returns
    -------
    lower : (numpy.ndarray int64, numpy.ndarray int32, numpy.ndarray)
        L as CSC (pointers, rows sorted within each column, values; its unit diagonal stored).
    upper_t : same as lower, or None
        U^T as CSC (the CSR of U); None where every pivot was diagonal (Pr = Pc^T): the
        symmetric K_ff then has U = D L^T.
    pivots : numpy.ndarray or None
        D where U = D L^T, else None.
    """
    L = lu.L.tocsc()
    L.sort_indices()
    lower = (L.indptr.astype(np.int64), L.indices.astype(np.int32), L.data)
    if np.array_equal(lu.perm_r, lu.perm_c):
        return lower, None, lu.U.diagonal()
    Ut = lu.U.tocsr()
    return lower, (Ut.indptr.astype(np.int64), Ut.indices.astype(np.int32), Ut.data), None


def supernodal_solver(lu, arrays):
    """The supernodal L D L^T solver of SuperLU's factors, where every pivot was diagonal.

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU
    arrays : tuple
        :func:`factor_arrays` of ``lu``.

    Returns
    -------
    _ngfracture.SupernodalLDL or None
        None where a pivot was off the diagonal (no U = D L^T).

    Raises
    ------
    ValueError
        From the kernel, on a zero or non-finite pivot (a singular K_ff).
    """
    lower, _, pivots = arrays
    if pivots is None:
        return None
    return _ext.SupernodalLDL(lu.shape[0], *lower, pivots, lu.perm_r.astype(np.int64))


def reach_solves(lu, arrays, index, C, supernodal=None):
    """Per row of C its column of Y = L^-1 Pr C^T and of X = U^-T Pc^T C^T.

    Where every pivot was diagonal (U = D L^T, X = D^-1 Y) and a supernodal solver of the
    factors is given, Y comes from its panels, supernode by supernode
    (``SupernodalLDL.forward_sparse``: dense updates, one row index per panel row); else
    from a Gilbert-Peierls solve entry by entry (``SparseLowerSolve``).

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU
    arrays : tuple
        :func:`factor_arrays` of ``lu``.
    index : numpy.ndarray of int, shape (ndof,)
        The row of K_ff of every dof, -1 where a dof is not factorised (entries of C there
        are ignored).
    C : scipy.sparse matrix, shape (m, ndof)
        Constraint rows.
    supernodal : _ngfracture.SupernodalLDL, optional
        :func:`supernodal_solver` of the same factors.

    Returns
    -------
    list of ((numpy.ndarray, numpy.ndarray), (numpy.ndarray, numpy.ndarray))
        For every row: (rows, values) of its column of Y, the same of X.

    Raises
    ------
    RuntimeError
        From the kernel (a zero pivot of U).
    """
    n = lu.shape[0]
    lower, upper_t, pivots = arrays
    B = C.tocoo()
    rows = index[B.col]
    keep = rows >= 0

    def solve(factor, perm, unit):
        lp, li, lx = factor
        rhs = sp.csc_matrix((B.data[keep], (perm[rows[keep]], B.row[keep])), shape=(n, C.shape[0]))
        pointers, indices = rhs.indptr.astype(np.int64), rhs.indices.astype(np.int32)
        if unit and upper_t is None and supernodal is not None:
            return supernodal.forward_sparse(pointers, indices, rhs.data, PRODUCT_THREADS)
        return _ext.SparseLowerSolve(n, lp, li, lx, unit, pointers, indices, rhs.data)

    yp, yi, yx = solve(lower, lu.perm_r, True)
    if upper_t is None:
        xp, xi, xx = yp, yi, yx / pivots[yi]       # U = D L^T
    else:
        xp, xi, xx = solve(upper_t, lu.perm_c, False)
    return [((yi[yp[j]:yp[j + 1]], yx[yp[j]:yp[j + 1]]), (xi[xp[j]:xp[j + 1]], xx[xp[j]:xp[j + 1]]))
            for j in range(C.shape[0])]


#: the dense blocks of :func:`column_products` take at most this many bytes each
PRODUCT_BLOCK_BYTES = 2 ** 26


def column_products(x_columns, y_columns, n):
    """X^T Y of two matrices given by their sparse columns, as a dense array.

    The columns of the Schur complement's solves reach a part of the rows each, the
    separators of the ordering in all of them: a sparse product pays its index work on
    every pair of entries, while a dense product (BLAS) on the rows both reach pays none.
    The columns go in blocks whose dense copies take at most ``PRODUCT_BLOCK_BYTES``.

    Parameters
    ----------
    x_columns, y_columns : list of (numpy.ndarray of int, numpy.ndarray)
        Row indices (distinct within a column) and values of every column of X and of Y,
        as :func:`reach_solves` gives them.
    n : int
        Number of rows of X and Y.

    Returns
    -------
    numpy.ndarray, shape (len(x_columns), len(y_columns))
    """
    x, y = _stacked(x_columns), _stacked(y_columns)
    rows = np.flatnonzero(_reached(x, n) & _reached(y, n))
    place = -np.ones(n, dtype=np.int64)
    place[rows] = np.arange(len(rows))
    width = max(1, PRODUCT_BLOCK_BYTES // (8 * max(len(rows), 1)))
    S = np.zeros((len(x_columns), len(y_columns)))
    for i in range(0, len(x_columns), width):
        X = _dense_block(x, place, len(rows), i, i + width)
        for j in range(0, len(y_columns), width):
            S[i:i + width, j:j + width] = X.T @ _dense_block(y, place, len(rows), j, j + width)
    return S


def schur_product(solved, pivots, n):
    """S = X^T Y of the columns :func:`reach_solves` gives, or Y^T D^-1 Y where U = D L^T.

    Parameters
    ----------
    solved : list of ((numpy.ndarray, numpy.ndarray), (numpy.ndarray, numpy.ndarray))
        Per row its column of Y and of X, as :func:`reach_solves` gives them.
    pivots : numpy.ndarray or None
        D where U = D L^T (:func:`factor_arrays`), else None.
    n : int
        Number of rows of X and Y.

    Returns
    -------
    numpy.ndarray, shape (len(solved), len(solved))
    """
    if pivots is None:
        return column_products([x for _, x in solved], [y for y, _ in solved], n)
    return weighted_products([y for y, _ in solved], 1.0 / pivots, n)


def weighted_products(y_columns, weights, n):
    """Y^T diag(w) Y of a matrix given by its sparse columns (the Schur complement where
    U = D L^T: X = D^-1 Y, w = 1 / D), exactly symmetric.

    With every weight on the rows Y reaches positive: symmetric products of W = diag(sqrt(w)) Y
    in column blocks whose dense copies take at most ``PRODUCT_BLOCK_BYTES``, the diagonal
    blocks by BLAS syrk and only the blocks above them by a product (half the work of
    :func:`column_products`, every dense block made once per block row); else
    :func:`column_products` of diag(w) Y and Y, symmetrised.

    Parameters
    ----------
    y_columns : list of (numpy.ndarray of int, numpy.ndarray)
        As for :func:`column_products`.
    weights : numpy.ndarray, shape (n,)
    n : int

    Returns
    -------
    numpy.ndarray, shape (len(y_columns), len(y_columns))
    """
    y = _stacked(y_columns)
    rows = np.flatnonzero(_reached(y, n))
    m = len(y_columns)
    if np.any(weights[rows] <= 0):
        S = column_products([(r, v * weights[r]) for r, v in y_columns], y_columns, n)
        return 0.5 * (S + S.T)
    place = -np.ones(n, dtype=np.int64)
    place[rows] = np.arange(len(rows))
    scale = np.sqrt(weights[rows])[:, None]
    width = max(1, PRODUCT_BLOCK_BYTES // (8 * max(len(rows), 1)))
    S = np.zeros((m, m))
    for i in range(0, m, width):
        W = _dense_block(y, place, len(rows), i, i + width) * scale
        S[i:i + width, i:i + width] = _gram(W)
        for j in range(i + width, m, width):
            block = W.T @ (_dense_block(y, place, len(rows), j, j + width) * scale)
            S[i:i + width, j:j + width], S[j:j + width, i:i + width] = block, block.T
    return S


def grouped_row_products(y_columns, weights, n, out=None):
    """Y^T diag(w) Y for columns that reach few rows each (w > 0 on them), exactly symmetric,
    as a sum over groups of rows, each group one dense product over the columns it reaches.

    The columns of L^-1 at unit vectors reach the paths of the elimination tree from their
    first row to the root. The rows near the root (the top separators), reached by at least
    ``TOP_ROW_SHARE`` of the columns, carry most of the work: they are one dense block,
    multiplied by pairs of ``TOP_BLOCK_COLUMNS`` columns (syrk on the diagonal). Every
    other row is reached by few columns, and consecutive rows of a supernode by nearly the
    same ones: such rows form a group (each reaching at most ``GROUP_GROWTH`` times the
    columns of the first, at most ``GROUP_ROWS`` rows), whose product over the columns it
    reaches is added into them. The least work is the sum over rows of the square of the
    columns reaching each; this takes 1.3 times it on the default sphere's G of 7099 dofs
    (the top block counts every column), against 4.4 times by pairs of column blocks
    (docs/solvers.md, "Sparse Schur complement").
    The products run on one thread, one after the other: the two cores of the machine it
    was measured on make dense products no faster on two (1.6 to 2.4 s for the default
    sphere's G of 7099 dofs, the top block's products on a second thread, against 1.2 s).

    Parameters
    ----------
    y_columns : list of (numpy.ndarray of int, numpy.ndarray)
        Increasing row indices and values of every column, as :func:`reach_solves` gives them.
    weights : numpy.ndarray, shape (n,)
        Where one is not positive on a row a column reaches: :func:`weighted_products`.
    n : int
    out : numpy.ndarray, shape (len(y_columns), len(y_columns)), optional
        C-ordered array to write the result into (G in the room it grows in,
        ``sparse_schur.DofSchur``); a new one without it.

    Returns
    -------
    numpy.ndarray, shape (len(y_columns), len(y_columns))
        ``out`` where given.
    """
    m = len(y_columns)
    rows, values, column, _ = _stacked(y_columns)
    S = np.empty((m, m)) if out is None else out
    if np.any(weights[rows] <= 0):
        S[...] = weighted_products(y_columns, weights, n)
        return S
    Y = sp.csr_matrix((values * np.sqrt(weights[rows]), (rows, column)), shape=(n, m))
    Y.sort_indices()
    reaching = np.diff(Y.indptr)
    top = np.flatnonzero(reaching >= TOP_ROW_SHARE * m)
    W = np.asfortranarray(Y[top].toarray())
    cuts = list(range(0, m, TOP_BLOCK_COLUMNS)) + [m]
    pairs = [(i, j) for i in range(len(cuts) - 1) for j in range(i, len(cuts) - 1)] if len(top) else []

    def top_product(pair):
        a, b = W[:, cuts[pair[0]]:cuts[pair[0] + 1]], W[:, cuts[pair[1]]:cuts[pair[1] + 1]]
        return blas.dsyrk(1.0, a, trans=1, lower=1).T if pair[0] == pair[1] else a.T @ b

    def group_product(group):
        start, stop = Y.indptr[group[0]], Y.indptr[group[1]]
        reached = np.unique(Y.indices[start:stop])
        V = np.zeros((group[1] - group[0], len(reached)), order="F")
        V[np.repeat(np.arange(len(V)), reaching[group[0]:group[1]]),
          np.searchsorted(reached, Y.indices[start:stop])] = Y.data[start:stop]
        return reached.astype(np.int64), blas.dsyrk(1.0, V, trans=1, lower=1)

    S[...] = 0.0
    with single_threaded_blas():
        for i, j in pairs:
            S[cuts[i]:cuts[i + 1], cuts[j]:cuts[j + 1]] = top_product((i, j))
        for group in _row_groups(reaching, TOP_ROW_SHARE * m):
            _ext.AddLowerBlock(S, *group_product(group))
    _mirror_upper(S)
    return S


def _row_groups(reaching, top):
    """(first, stop) of the groups of :func:`grouped_row_products`: runs of consecutive rows
    reached by fewer than ``top`` columns, each row by as many as the first or more, at most
    ``GROUP_GROWTH`` times as many, and at most ``GROUP_ROWS`` rows."""
    below = (reaching > 0) & (reaching < top)
    counts = reaching.tolist()
    groups = []
    for r in np.flatnonzero(below).tolist():
        if groups:
            first, stop = groups[-1]
            if r == stop and r - first < GROUP_ROWS and counts[first] <= counts[r] <= GROUP_GROWTH * counts[first]:
                groups[-1] = (first, r + 1)
                continue
        groups.append((r, r + 1))
    return groups


def _mirror_upper(S, width=512):
    """Copy S's upper triangle onto its lower one, in blocks of ``width`` rows: exactly symmetric."""
    m = S.shape[0]
    for a in range(0, m, width):
        b = min(a + width, m)
        D = S[a:b, a:b]
        S[a:b, a:b] = np.triu(D) + np.triu(D, 1).T
        S[b:, a:b] = S[a:b, b:].T


def _gram(W):
    """W^T W of a C-ordered W by the symmetric rank-k product (BLAS syrk on W.T, which is
    Fortran-ordered: no copy), its lower triangle the upper's mirror: exactly symmetric."""
    upper = blas.dsyrk(1.0, W.T)
    return np.triu(upper) + np.triu(upper, 1).T


def _stacked(columns):
    """(rows, values, column, number of columns) of every entry of the columns."""
    if not columns:
        return np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0, dtype=np.int64), 0
    lengths = np.fromiter((len(r) for r, _ in columns), dtype=np.int64, count=len(columns))
    return (np.concatenate([r for r, _ in columns]), np.concatenate([v for _, v in columns]),
            np.repeat(np.arange(len(columns)), lengths), len(columns))


def _reached(stacked, n):
    """Mask of the rows where a stacked column has an entry (no sort of the entries)."""
    mask = np.zeros(n, dtype=bool)
    mask[stacked[0]] = True
    return mask


def _dense_block(stacked, place, size, start, stop):
    """Columns start .. stop - 1 of the stacked entries as a dense (size, count) array, row
    r at place[r] (entries at rows with place -1 dropped: the other factor is zero there)."""
    rows, values, column, m = stacked
    block = np.zeros((size, max(min(stop, m) - start, 0)))
    at = place[rows]
    keep = (at >= 0) & (column >= start) & (column < stop)
    block[at[keep], column[keep] - start] = values[keep]
    return block
