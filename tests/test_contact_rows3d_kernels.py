"""The C++ kernels of the 3D node-to-face rows against their numpy reference, bit for bit.

``rows3d._gap_matrix`` (``GapMatrixCsr3d``), ``rows3d._gap_offset`` (``GapOffsets3d``) and
``rows3d.relinearise_node_to_face`` (``RelineariseRows3d``) compute in C++ what the numpy code below computes; the rows,
gaps and C matrices of every contact round go through them, so they must agree to the
last bit (and in the sign of zeros) on rows of every kind: projections inside a face,
on an edge or at a vertex (exact zeros), squeezed faces, rows anchored at a copy of the
slave, flipped normals.
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ngfracture import _ngfracture as ext
from ngfracture.contact.rows3d import NodeToFaceRows, face_gap_rows, relinearise_node_to_face


def reference_gap_matrix(slave, master, bary, normal, nv):
    """The numpy assembly of C (rows of four distinct vertices), as rows3d had it."""
    m = len(slave)
    w = np.concatenate([np.ones((m, 1)), -bary], axis=1)
    verts = np.concatenate([slave[:, None], master], axis=1).astype(np.int64)
    order = np.argsort(verts, axis=1, kind="stable")
    vs = np.take_along_axis(verts, order, axis=1)
    assert not np.any(vs[:, 1:] == vs[:, :-1])
    ws = np.take_along_axis(w, order, axis=1)
    cols = np.concatenate([vs + comp * nv for comp in range(3)], axis=1).ravel().astype(np.int32)
    vals = np.concatenate([ws * normal[:, comp:comp + 1] for comp in range(3)], axis=1).ravel()
    C = sp.csr_matrix((vals, cols, np.arange(0, 12 * m + 1, 12, dtype=np.int32)), shape=(m, 3 * nv))
    C.eliminate_zeros()
    return C


def reference_relinearise(rows, X, x):
    """The numpy re-linearisation, as rows3d had it: (bary, normal, dist, g)."""
    p = x[rows.master]
    area2 = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = np.linalg.norm(area2, axis=1)
    P = X[rows.master]
    reference = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    degenerate = ~(length > 1e-16 * reference)
    face_normal = area2 / np.where(degenerate, 1.0, length)[:, None]
    q = x[rows.slave]
    b = np.stack([np.einsum("ij,ij->i", np.cross(p[:, (l + 1) % 3] - q, p[:, (l + 2) % 3] - q), face_normal)
                  for l in range(3)], axis=1) / np.where(degenerate, 1.0, length)[:, None]
    n = face_normal * np.where(np.einsum("ij,ij->i", face_normal, rows.normal) < 0, -1.0, 1.0)[:, None]
    n[degenerate] = rows.normal[degenerate]
    b = np.clip(b, 0.0, None)
    b /= np.where(b.sum(axis=1) > 0, b.sum(axis=1), 1.0)[:, None]
    corner = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    keep = degenerate | ((rows.bary.max(axis=1) == 1.0) & np.all(X[corner] == X[rows.slave], axis=1))
    b[keep] = rows.bary[keep]
    dist = np.einsum("ij,ij->i", q - np.einsum("ij,ijk->ik", b, p), n)
    pos = X[rows.slave] - np.einsum("ij,ijk->ik", b, X[rows.master])
    return b, n, dist, np.einsum("ij,ij->i", pos, n)


def reference_gap_offset(X, slave, master, bary, normal):
    """The numpy gaps n . (X_s - sum_l b_l X_l), as rows3d had them."""
    pos = X[slave] - np.einsum("ij,ijk->ik", bary, X[master])
    return np.einsum("ij,ij->i", pos, normal)


def random_rows(seed, m=4000, nv=3000):
    """Rows of every kind on random points: (X, U, rows)."""
    rng = np.random.default_rng(seed)
    X = rng.standard_normal((nv, 3)) * 10.0 ** rng.integers(-3, 3, (nv, 1))
    X[nv // 2:nv // 2 + 50] = X[:50]                               # copies: bitwise-equal points
    U = rng.standard_normal((nv, 3)) * 1e-2
    U[100:190] = -X[100:190] + X[200]                              # squeezed faces (all at one point)
    verts = np.stack([rng.choice(nv, 4, replace=False) for _ in range(m)])
    slave, master = verts[:, 0], verts[:, 1:]
    master[:30] = np.arange(100, 190).reshape(30, 3)               # degenerate at x
    bary = rng.dirichlet(np.ones(3), m)
    bary[30:400] = np.eye(3)[rng.integers(0, 3, 370)]              # at a vertex: exact zeros
    bary[400:700, rng.integers(0, 3)] = 0.0                        # on an edge
    bary[400:700] /= bary[400:700].sum(axis=1, keepdims=True)
    slave[30:80] = np.arange(nv // 2, nv // 2 + 50)                # anchored at a copy of the slave
    master[30:80, 0] = np.arange(50)
    bary[30:80] = [1.0, 0.0, 0.0]
    normal = rng.standard_normal((m, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    normal[700:900, 1] = -0.0
    g = np.zeros(m)
    rows = NodeToFaceRows(slave=slave, master=master, face=np.arange(m), bary=bary, normal=normal, dist=g, g=g,
                          nv=nv)
    return X, U, rows


def same_bits(a, b):
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_relinearise_equals_numpy(seed):
    X, U, rows = random_rows(seed)
    x = X + U
    new = relinearise_node_to_face(rows, X, U)
    ref = reference_relinearise(rows, X, x)
    for got, want in zip((new.bary, new.normal, new.dist, new.g), ref):
        assert same_bits(got, want)
    assert np.all(new.bary[30:80] == rows.bary[30:80])             # anchored rows kept theirs
    assert np.all(new.bary[:30] == rows.bary[:30]) and np.all(new.normal[:30] == rows.normal[:30])
    assert np.count_nonzero(new.bary == 0.0) > 100                 # clipped weights were met


@pytest.mark.parametrize("seed", [0, 3])
def test_gap_matrix_equals_numpy(seed):
    X, _, rows = random_rows(seed)
    C, g = face_gap_rows(X, rows.slave, rows.master, rows.bary, rows.normal)
    ref = reference_gap_matrix(rows.slave, rows.master, rows.bary, rows.normal, len(X))
    for f in ("indptr", "indices", "data"):
        assert same_bits(getattr(C, f), getattr(ref, f))
    assert C.nnz < 12 * len(rows)                                   # exact zeros were left out
    assert C.has_sorted_indices
    assert same_bits(g, reference_gap_offset(X, rows.slave, rows.master, rows.bary, rows.normal))
    assert np.count_nonzero(g == 0.0) >= 50                          # the rows anchored at a copy


def test_gap_matrix_repeated_vertex_sums():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    slave, master = np.array([0, 3]), np.array([[1, 2, 3], [0, 1, 3]])
    bary, normal = np.array([[0.2, 0.3, 0.5], [0.25, 0.25, 0.5]]), np.array([[0.0, 0, 1], [0, 0, 1]])
    assert ext.GapMatrixCsr3d(slave, master, bary, normal, 4) is None
    C, _ = face_gap_rows(X, slave, master, bary, normal)
    dense = C.toarray()
    assert dense[1, 2 * 4 + 3] == 1.0 - 0.5 and dense[0, 2 * 4 + 3] == -0.5
    assert dense[1, 2 * 4 + 0] == -0.25


def test_kernels_reject_bad_input():
    X, U, rows = random_rows(0)
    with pytest.raises(ValueError, match="outside"):
        ext.RelineariseRows3d(X, X + U, rows.slave + 100, rows.master, rows.bary, rows.normal)
    with pytest.raises(ValueError, match="outside"):
        ext.GapOffsets3d(X, rows.slave, rows.master - len(X), rows.bary, rows.normal)
    with pytest.raises(ValueError, match="bary"):
        ext.GapMatrixCsr3d(rows.slave, rows.master, rows.bary[:5], rows.normal, len(X))
