"""The keys of contact rows as int64 codes (3D candidates), their tuples made on first use."""
from collections.abc import Sequence

import numpy as np

__all__ = ["RowKeys"]


class RowKeys(Sequence):
    """The keys of rows as int64 codes; the key tuples are made on first use.

    Parameters
    ----------
    codes : numpy.ndarray of int
        One code per row: equal codes for equal keys.
    codec : object
        Its ``decode(codes)`` gives the list of key tuples. Keys of one codec concatenate
        (``+``) into keys of that codec.
    """

    def __init__(self, codes, codec):
        self.codes = np.asarray(codes, dtype=np.int64)
        self.codec = codec
        self._tuples = None

    def _list(self):
        if self._tuples is None:
            self._tuples = self.codec.decode(self.codes)
        return self._tuples

    def __len__(self):
        return len(self.codes)

    def __getitem__(self, i):
        return self._list()[i]

    def __iter__(self):
        return iter(self._list())

    def __add__(self, other):
        if isinstance(other, RowKeys) and other.codec is self.codec:
            return RowKeys(np.concatenate([self.codes, other.codes]), self.codec)
        return self._list() + list(other)

    def __eq__(self, other):
        return isinstance(other, Sequence) and list(self) == list(other)

    __hash__ = None
