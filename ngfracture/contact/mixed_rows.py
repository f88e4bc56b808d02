"""Contact rows of several kinds in one table, in any order of the rows.

The active set (:class:`~ngfracture.contact.active_set.ActiveSet`) chooses among candidate
rows through their matrix ``C``, their constant part ``g`` and their distance ``dist``,
selects and stacks them (``subset``, ``stack``); it never looks at what a row is. A 3D solve
has node-to-face rows (:class:`~ngfracture.contact.rows3d.NodeToFaceRows`) and edge-to-edge
rows (:class:`~ngfracture.contact.edge_rows3d.EdgeRows`); :class:`MixedRows` holds one
table of each kind and the kind of every row, so that the rows of the two kinds can be
selected and ordered like the rows of one table, while each kind keeps its own fields and
its own re-linearisation.
"""
import numpy as np
import scipy.sparse as sp

__all__ = ["MixedRows"]


class MixedRows:
    """Rows of several kinds in one order.

    Parameters
    ----------
    parts : sequence of RowTable
        One table per kind, of one mesh (same ``nv``).
    kind : numpy.ndarray of int, optional
        The kind (index into ``parts``) of every row, in the table's order: row i is the
        next row of ``parts[kind[i]]``. Default: the rows of ``parts[0]``, then those of
        ``parts[1]``, ...

    Attributes
    ----------
    parts : tuple of RowTable
    kind : numpy.ndarray of int8
    g, dist : numpy.ndarray
        The rows' constant parts and distances, in the table's order (``dist`` can be
        replaced, as a table's field can; the parts keep the distances they were made with).
    nv : int

    Raises
    ------
    ValueError
        If the parts are of different meshes or ``kind`` does not count their rows.
    """

    def __init__(self, parts, kind=None):
        self.parts = tuple(parts)
        self.nv = self.parts[0].nv
        if any(p.nv != self.nv for p in self.parts):
            raise ValueError(f"MixedRows: parts of meshes with {sorted(set(p.nv for p in self.parts))} vertices")
        sizes = [len(p) for p in self.parts]
        if kind is None:
            kind = np.repeat(np.arange(len(sizes)), sizes)
        self.kind = np.asarray(kind, dtype=np.int8)
        if not np.array_equal(np.bincount(self.kind, minlength=len(sizes)), sizes):
            raise ValueError(f"MixedRows: kind counts {np.bincount(self.kind, minlength=len(sizes)).tolist()} "
                             f"rows of each kind, the parts have {sizes}")
        # a row's place among the rows of its kind, and in the parts stacked in order
        self._rank = np.empty(len(self.kind), dtype=np.int64)
        for k, size in enumerate(sizes):
            self._rank[self.kind == k] = np.arange(size)
        start = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        self._place = start[self.kind] + self._rank
        self.g = np.concatenate([p.g for p in self.parts])[self._place]
        self.dist = np.concatenate([p.dist for p in self.parts])[self._place]
        self._C = None

    def __len__(self):
        return len(self.kind)

    @property
    def C(self):
        """The rows' matrix, shape (m, 3 nv) (the parts' rows in the table's order), built at first use."""
        if self._C is None:
            blocks = [p.C for p in self.parts if len(p)] or [self.parts[0].C]
            C = blocks[0] if len(blocks) == 1 else sp.vstack(blocks, format="csr")
            identity = np.array_equal(self._place, np.arange(len(self._place)))
            self._C = C if identity else C[self._place]
        return self._C

    def subset(self, rows):
        """The rows ``rows`` (an index array or a boolean mask), in that order.

        Parameters
        ----------
        rows : array_like of int or bool

        Returns
        -------
        MixedRows

        Raises
        ------
        ValueError
            On a mask of another length than the table's.
        """
        rows = np.asarray(rows)
        if rows.dtype == bool and rows.shape != (len(self),):
            raise ValueError(f"MixedRows.subset: a mask of shape {rows.shape} for {len(self)} rows")
        rows = np.flatnonzero(rows) if rows.dtype == bool else rows.astype(np.int64)
        kind = self.kind[rows]
        parts = [p.subset(self._rank[rows[kind == k]]) for k, p in enumerate(self.parts)]
        out = MixedRows(parts, kind)
        out.dist = self.dist[rows]
        return out

    @classmethod
    def stack(cls, tables):
        """The rows of several tables of the same kinds, in order.

        Parameters
        ----------
        tables : sequence of MixedRows
            At least one, with the same number of parts of the same classes.

        Returns
        -------
        MixedRows
        """
        parts = [type(ps[0]).stack(list(ps)) for ps in zip(*(t.parts for t in tables))]
        out = cls(parts, np.concatenate([t.kind for t in tables]))
        out.dist = np.concatenate([t.dist for t in tables])
        return out
