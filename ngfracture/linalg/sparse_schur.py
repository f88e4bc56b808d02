"""The Schur complement S = C K_ff^-1 C^T of constraint rows from SuperLU's factors, for a
factorisation that meets mostly the same rows call after call (contact rounds, Newton
iterations with a kept tangent).

A row's triangular solves (:func:`linalg.triangular.reach_solves`) are kept from one call
to the next, and so are the entries of S between rows met in the last call: where every
pivot was diagonal (U = D L^T, S = Y^T D^-1 Y) a call computes only the entries of its new
rows, against all rows. Rows are recognised by their stored indices and values, bitwise
(:func:`linalg.kept.row_keys`). docs/solvers.md, "Sparse Schur complement".

Rows whose values change from call to call on the same dofs (3D contact rows, re-linearised
at every round of the active set: a call meets a quarter of its rows with new values) are
not recognised by their keys. For them S is built from the dofs instead (:class:`DofSchur`):
G = E^T K_ff^-1 E on the factorised dofs the rows touch (E their unit columns), made from
the reach solves of those dofs' unit rows, kept and grown with the dofs a call adds;
then S = C_d G C_d^T costs a sparse product per call and no triangular solve. A call whose
rows are all among those of the last call that made the product (bitwise: a contact round's
equations after its complementarity problem over all candidates) takes its S from that
product's, entry for entry the same numbers.
"""
import numpy as np
import scipy.sparse as sp

from .. import _ngfracture as _ext
from .kept import row_keys
from . import triangular
from .triangular import column_products, grouped_row_products, reach_solves, schur_product


class SparseSchur:
    """S = C K_ff^-1 C^T by sparse triangular solves with SuperLU's factors of K_ff.

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU
        The factorisation of K_ff.
    arrays : tuple
        :func:`linalg.triangular.factor_arrays` of ``lu``.
    supernodal : _ngfracture.SupernodalLDL or None
        The supernodal solver of the same factors (reach solves through its panels).
    index : numpy.ndarray of int, shape (ndof,)
        The row of K_ff of every dof, -1 where a dof is not factorised.
    grouped : bool
        Where U = D L^T, the symmetric products of new rows by groups of the rows of the
        factor they reach (:func:`linalg.triangular.grouped_row_products`) instead of one
        over every row they reach.
    """

    def __init__(self, lu, arrays, supernodal, index, grouped=False):
        self._lu, self._arrays, self._supernodal, self._index = lu, arrays, supernodal, index
        self._grouped = grouped
        self._solved = {}         # row key -> its columns of Y and X, the last call's rows
        self._last = ([], None)   # the last call's row keys and S

    def complement(self, C):
        """S for the rows C; the rows of the last call cost no solve, and their entries of S
        are taken from it where U = D L^T.

        Parameters
        ----------
        C : scipy.sparse matrix, shape (m, ndof)
            Constraint rows (entries at dofs that are not factorised are ignored).

        Returns
        -------
        numpy.ndarray, shape (m, m)

        Raises
        ------
        RuntimeError, ValueError
            From the triangular solves (a zero pivot, a row out of range).
        """
        C = sp.csr_matrix(C)
        keys = row_keys(C)
        new = [i for i, key in enumerate(keys) if key not in self._solved]
        solved = dict(zip((keys[i] for i in new),
                          reach_solves(self._lu, self._arrays, self._index, C[new], self._supernodal)
                          if new else []))
        self._solved = {key: self._solved[key] if key in self._solved else solved[key] for key in keys}
        columns = [self._solved[key] for key in keys]
        pivots = self._arrays[2]
        last_keys, last_S = self._last
        place = {key: i for i, key in enumerate(last_keys)}
        known = [i for i, key in enumerate(keys) if key in place]
        if pivots is None or not known:
            S = self._product(columns)
        else:
            S = self._updated(columns, keys, known, place, last_S, pivots)
        self._last = (keys, S)
        return S

    def _product(self, columns):
        """S of the rows of these columns: :func:`schur_product`, or by groups of rows (``grouped``)."""
        n, pivots = self._lu.shape[0], self._arrays[2]
        if self._grouped and pivots is not None:
            return grouped_row_products([y for y, _ in columns], 1.0 / pivots, n)
        return schur_product(columns, pivots, n)

    def _updated(self, columns, keys, known, place, last_S, pivots):
        """S from the last call's entries between known rows, the new rows' entries computed:
        among themselves symmetric (schur_product), against the known ones by one product."""
        n, weights = self._lu.shape[0], 1.0 / pivots
        fresh = np.setdiff1d(np.arange(len(keys)), known)
        known = np.asarray(known)
        at = np.array([place[keys[i]] for i in known])
        S = np.empty((len(keys), len(keys)))
        k = len(known)
        # DofSchur's unit rows grow at the end: the last call's rows come first, in its order,
        # and its entries are one block (a copy instead of a gather of k^2 indices)
        prefix = np.array_equal(known, np.arange(k)) and np.array_equal(at, np.arange(k))
        if prefix:
            S[:k, :k] = last_S[:k, :k]
        else:
            S[np.ix_(known, known)] = last_S[np.ix_(at, at)]
        if len(fresh):
            S[np.ix_(fresh, fresh)] = self._product([columns[i] for i in fresh])
            weighted = [(y[0], y[1] * weights[y[0]]) for y, _ in (columns[i] for i in fresh)]
            block = column_products(weighted, [columns[i][0] for i in known], n)
            if prefix:
                S[k:, :k] = block
                S[:k, k:] = block.T
            else:
                S[np.ix_(fresh, known)] = block
                S[np.ix_(known, fresh)] = block.T
        return S


class DofSchur:
    """S = C K_ff^-1 C^T as C_d G C_d^T, G = K_ff^-1 on the factorised dofs the rows touch.

    For rows whose values change from call to call on the same dofs (see the module
    docstring): G is kept and grown by the dofs a call adds; a call then costs a sparse
    product and no triangular solve. Where every pivot was diagonal (U = D L^T), G is made
    from the reach solves of the dofs' unit rows by the products over groups of rows
    (:func:`linalg.triangular.grouped_row_products`) and grown by one solve of K_ff per new
    dof (a few dofs against thousands: their columns of K_ff^-1 directly, instead of their
    products against every column met before); else it is the :class:`SparseSchur` of the
    unit rows.

    Parameters
    ----------
    lu, arrays, supernodal, index
        As for :class:`SparseSchur`.
    """

    def __init__(self, lu, arrays, supernodal, index):
        self._lu, self._arrays, self._supernodal = lu, arrays, supernodal
        self._units = SparseSchur(lu, arrays, supernodal, index)
        self._index, self._symmetric = index, arrays[2] is not None     # U = D L^T: G symmetric
        self._dofs, self._order, self._G = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), None
        self._made = ({}, None)   # the last product's rows (key -> position) and S
        self._room = None         # the array G lives at the start of, with room to grow (_moved)

    def complement(self, C):
        """S for the rows C (entries at dofs that are not factorised are ignored).

        Parameters
        ----------
        C : scipy.sparse matrix, shape (m, ndof)

        Returns
        -------
        numpy.ndarray, shape (m, m)
            Exactly symmetric where U = D L^T, as :class:`SparseSchur`'s.

        Raises
        ------
        RuntimeError, ValueError
            From the triangular solves of new dofs.
        """
        C = sp.csr_matrix(C)
        factorised = self._index[C.indices] >= 0
        need = np.unique(C.indices[factorised])
        fresh = need[~np.isin(need, self._dofs)]
        if fresh.size or self._G is None:
            # new dofs join at the end: G's block of the others stays as it was
            known = len(self._dofs)
            self._dofs = np.concatenate([self._dofs, fresh])
            self._order = np.argsort(self._dofs, kind="stable")
            self._G = self._grown(known, C.shape[1])
        at = self._order[np.searchsorted(self._dofs, C.indices[factorised], sorter=self._order)]
        rows = np.repeat(np.arange(C.shape[0]), np.diff(C.indptr))[factorised]
        Cd = sp.csr_matrix((C.data[factorised], (rows, at)), shape=(C.shape[0], len(self._dofs)))
        keys = row_keys(Cd)
        place, made = self._made
        if keys and all(key in place for key in keys):
            # an entry of S depends on its two rows and G alone (G's block of these rows'
            # dofs has not changed since: new dofs join at the end), so the gather is the
            # product's own numbers
            positions = np.array([place[key] for key in keys], dtype=np.int64)
            return made[np.ix_(positions, positions)]
        if self._symmetric:      # C++: exactly symmetric, the same bits on any number of threads
            S = _ext.RowsProduct(Cd.indptr.astype(np.int64), Cd.indices, Cd.data, self._G,
                                 triangular.PRODUCT_THREADS)
        else:
            S = (Cd @ (Cd @ self._G).T).T
        self._made = ({key: i for i, key in enumerate(keys)}, S)
        return S

    def _grown(self, known, ndof):
        """G on ``self._dofs``, of which the first ``known`` are those of the G before."""
        p = len(self._dofs)
        units = sp.csr_matrix((np.ones(p), (np.arange(p), self._dofs)), shape=(p, ndof))
        if not self._symmetric:
            return self._units.complement(units)
        at = self._index[self._dofs]
        if self._G is None:
            solved = reach_solves(self._lu, self._arrays, self._index, units, self._supernodal)
            return grouped_row_products([y for y, _ in solved], 1.0 / self._arrays[2], self._lu.shape[0],
                                        out=self._new_room(p))
        E = np.zeros((self._lu.shape[0], len(at) - known), order="F")
        E[at[known:], np.arange(len(at) - known)] = 1.0
        B = (self._supernodal.solve(E) if self._supernodal is not None else self._lu.solve(E))[at]
        G = self._moved(known, len(at))
        G[:known, known:], G[known:, :known] = B[:known], B[:known].T
        G[known:, known:] = 0.5 * (B[known:] + B[known:].T)
        return G

    def _moved(self, known, p):
        """A p x p array (C-ordered) whose first ``known`` rows and columns are G's.

        G grows by a few dofs at a time. A fresh p x p array at every growth is fresh memory,
        faulted in page by page as G is copied into it (1.3 s for the late default sphere's 400 MB
        against 0.05 s for the copy), so G lives at the start of an array with room for
        ``GROWTH_ROOM`` more rows (or a sixteenth more) and moves within it, row by row from
        the last: a row's new place lies past the old places of all rows before it."""
        if self._room is None or self._room.size < p * p:
            G = self._new_room(p)
            G[:known, :known] = self._G
            return G
        flat = self._room
        for i in range(known - 1, 0, -1):
            row = flat[i * known:(i + 1) * known]
            # a row that overlaps its own new place is copied first (no copy may run over its source)
            flat[i * p:i * p + known] = row.copy() if i * p < (i + 1) * known else row
        return flat[:p * p].reshape(p, p)

    def _new_room(self, p):
        """A new array with room for G to grow in, and its first p x p entries as a C-ordered view."""
        size = p + max(GROWTH_ROOM, p // 16)
        self._room = np.empty(size * size)
        return self._room[:p * p].reshape(p, p)


#: rows of room for G to grow in (:meth:`DofSchur._moved`), at least
GROWTH_ROOM = 256


def schur_of(kind, lu, arrays, supernodal, index):
    """The Schur complement of one factorisation.

    Parameters
    ----------
    kind : {"rows", "grouped", "dofs"}
        :class:`SparseSchur`, the same with the products by groups of rows, or :class:`DofSchur`.
    lu, arrays, supernodal, index
        As for :class:`SparseSchur`.

    Returns
    -------
    SparseSchur or DofSchur
    """
    if kind == "dofs":
        return DofSchur(lu, arrays, supernodal, index)
    return SparseSchur(lu, arrays, supernodal, index, grouped=kind == "grouped")


__all__ = ["DofSchur", "SparseSchur", "schur_of"]
