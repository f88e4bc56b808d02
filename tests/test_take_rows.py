"""contact.rows.take_rows: the rows a[rows] of numpy's fancy indexing, byte for byte."""
import numpy as np
import pytest

from ngfracture.contact.rows import take_rows


def _same(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("a", [np.random.default_rng(0).random((50, 3)),
                               np.random.default_rng(1).integers(-9, 9, (50, 3)),
                               np.random.default_rng(2).random((50, 3))[:, ::-1],      # not contiguous
                               np.random.default_rng(3).random((50, 2, 3)),
                               np.arange(50)])
def test_rows_as_fancy_indexing(a):
    rng = np.random.default_rng(4)
    for rows in (rng.integers(0, 50, 80), rng.integers(-50, 50, 30), np.zeros(0, dtype=np.int64),
                 rng.integers(0, 50, (7, 3)), rng.integers(0, 50, 20).astype(np.int32),
                 rng.random(50) < 0.5, np.zeros(50, dtype=bool)):
        assert _same(take_rows(a, rows), a[rows])


def test_errors_as_fancy_indexing():
    a = np.zeros((5, 3))
    for rows in (np.array([5]), np.array([-6]), np.ones(4, dtype=bool), np.array([0.0])):
        with pytest.raises(IndexError):
            a[rows]
        with pytest.raises(IndexError):
            take_rows(a, rows)
