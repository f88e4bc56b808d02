"""A fragmented cube whose blocks overlap: the common body of the 3D contact tests, and
the bit-for-bit comparison of their node-to-face rows.

Used by ``test_contact3d_keys.py`` (with noise), ``test_active_set_settle.py`` (without),
``test_contact3d_reuse.py`` and ``test_contact3d_setup.py``; import with
``PYTHONPATH=.:tests``.
"""
import numpy as np

from ngfracture.contact.active_set import Geometry
from ngfracture.contact.mixed_rows import MixedRows
from ngfracture.contact.rows3d import NodeToFaceRows
from ngfracture.geometry.pieces import fragmented_box


def overlapping_blocks(cells, pieces, expansion, noise=0.0, seed=0):
    """The cube of ``pieces``^3 blocks (``cells`` a side), each expanded about its centroid.

    Parameters
    ----------
    cells, pieces : int
        Cells a side of the unit cube and blocks a side (``geometry.pieces.fragmented_box``).
    expansion : float
        The displacement of a vertex is ``expansion`` times its offset from its block's
        centroid: every lip overlaps its neighbour by ``expansion`` times the block size.
    noise : float
        Standard deviation of a normal noise added to every component (0: none).
    seed : int
        Seed of the noise (``numpy.random.default_rng``).

    Returns
    -------
    arrays : ngfracture.geometry.solid.SolidArrays
        The mesh (the blocks' lips are coincident faces on bitwise-equal copies).
    piece : numpy.ndarray of int64, shape (ne,)
        The block of every tetrahedron.
    vf : numpy.ndarray of int64, shape (nv,)
        The block of every vertex.
    U : numpy.ndarray, shape (nv, 3)
        The displacement.
    """
    arrays, piece = fragmented_box(cells, pieces)
    X = arrays.points
    vf = np.full(len(X), -1)
    vf[arrays.tets.ravel()] = np.repeat(piece, 4)
    centre = np.stack([np.bincount(vf, weights=X[:, d]) / np.bincount(vf) for d in range(3)], axis=1)
    U = expansion * (X - centre[vf])
    if noise:
        U += np.random.default_rng(seed).normal(scale=noise, size=U.shape)
    return arrays, piece, vf, U


def block_geometry(arrays, piece):
    """The ``active_set.Geometry`` of the blocks: no seams, no fixed vertex."""
    return Geometry(arrays=arrays, fragment=piece, seams=None, fixed=np.zeros(0, dtype=np.int64))


def assert_same_rows(a, b):
    """Two ``NodeToFaceRows`` (or ``MixedRows`` of them and edge rows) equal bit for bit: their
    length, every field and the CSR arrays of C."""
    assert len(a) == len(b)
    if isinstance(a, MixedRows):
        assert isinstance(b, MixedRows) and np.array_equal(a.kind, b.kind)
        assert np.array_equal(a.g, b.g) and np.array_equal(a.dist, b.dist)
        for pa, pb in zip(a.parts, b.parts):
            for f in type(pa).FIELDS:
                assert np.array_equal(getattr(pa, f), getattr(pb, f)), f
    else:
        for f in NodeToFaceRows.FIELDS:
            assert np.array_equal(getattr(a, f), getattr(b, f)), f
    ca, cb = a.C.tocsr(), b.C.tocsr()
    assert ca.shape == cb.shape
    for f in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(ca, f), getattr(cb, f)), f
