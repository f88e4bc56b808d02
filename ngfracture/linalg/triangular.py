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

from .. import _ngfracture as _ext


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


def reach_solves(lu, arrays, index, C):
    """Per row of C its column of Y = L^-1 Pr C^T and of X = U^-T Pc^T C^T.

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
        return _ext.SparseLowerSolve(n, lp, li, lx, unit, rhs.indptr.astype(np.int64),
                                     rhs.indices.astype(np.int32), rhs.data)

    yp, yi, yx = solve(lower, lu.perm_r, True)
    if upper_t is None:
        xp, xi, xx = yp, yi, yx / pivots[yi]       # U = D L^T
    else:
        xp, xi, xx = solve(upper_t, lu.perm_c, False)
    return [((yi[yp[j]:yp[j + 1]], yx[yp[j]:yp[j + 1]]), (xi[xp[j]:xp[j + 1]], xx[xp[j]:xp[j + 1]]))
            for j in range(C.shape[0])]


def sparse_columns(columns, n):
    """A CSC matrix from per-column (rows, values), as :func:`reach_solves` gives them.

    Parameters
    ----------
    columns : list of (numpy.ndarray of int, numpy.ndarray)
        Row indices and values of every column.
    n : int
        Number of rows.

    Returns
    -------
    scipy.sparse.csc_matrix, shape (n, len(columns))
    """
    lengths = np.array([len(r) for r, _ in columns], dtype=np.int64)
    rows = np.concatenate([r for r, _ in columns]) if columns else np.zeros(0, np.int32)
    values = np.concatenate([v for _, v in columns]) if columns else np.zeros(0)
    return sp.csc_matrix((values, rows, np.concatenate([[0], np.cumsum(lengths)])), shape=(n, len(columns)))
