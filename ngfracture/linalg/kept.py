"""The Schur columns K^+ c a factorisation keeps per constraint row (linalg.factor).

A row c is recognised by its stored column indices and values, bitwise (:func:`row_keys`).
:class:`KeptColumns` keeps the column of every row met, or only those of the latest call,
as the factorisation's solves allow (``FactorBase.columns_independent``; docs/solvers.md,
"Kept columns").
"""

#: the kept columns take at most this many bytes; beyond, the columns met longest ago are
#: dropped. docs/solvers.md, "Kept columns"
KEPT_COLUMNS_BYTES = 2 ** 28


def row_keys(C):
    """One key per row of a CSR matrix: its column indices and values as bytes.

    Parameters
    ----------
    C : scipy.sparse.csr_matrix

    Returns
    -------
    list of bytes
    """
    return [C.indices[s:e].tobytes() + C.data[s:e].tobytes() for s, e in zip(C.indptr[:-1], C.indptr[1:])]


class KeptColumns:
    """Columns by row key, for one factorisation.

    Parameters
    ----------
    items : dict of bytes -> numpy.ndarray, optional
        Columns to start with (shared, not copied).
    """

    def __init__(self, items=None):
        self._items = {} if items is None else dict(items)

    def copy(self):
        """Another KeptColumns with the same columns (shared, read only).

        Returns
        -------
        KeptColumns
        """
        return KeptColumns(self._items)

    def fill(self, keys, Z):
        """Copy the kept column of every key into Z's column of the same place.

        Parameters
        ----------
        keys : list of bytes
        Z : numpy.ndarray, shape (ndof, len(keys))

        Returns
        -------
        list of int
            The places of the keys without a kept column (Z left as it is there).
        """
        new = []
        for i, key in enumerate(keys):
            if key in self._items:
                Z[:, i] = self._items[key]
            else:
                new.append(i)
        return new

    def keep(self, keys, Z, every):
        """Keep Z's columns for the keys: with ``every``, besides those kept already (the
        keys met last go to the end; beyond ``KEPT_COLUMNS_BYTES`` the columns met longest
        ago are dropped), else instead of them.

        Parameters
        ----------
        keys : list of bytes
        Z : numpy.ndarray, shape (ndof, len(keys))
        every : bool
        """
        if not every:
            self._items = {key: Z[:, i] for i, key in enumerate(keys)}
            return
        for i, key in enumerate(keys):
            self._items[key] = self._items.pop(key) if key in self._items else Z[:, i].copy()
        room = max(KEPT_COLUMNS_BYTES // (8 * max(Z.shape[0], 1)), len(keys))
        for key in list(self._items)[:max(len(self._items) - room, 0)]:
            del self._items[key]

    def __len__(self):
        return len(self._items)


__all__ = ["KEPT_COLUMNS_BYTES", "KeptColumns", "row_keys"]
