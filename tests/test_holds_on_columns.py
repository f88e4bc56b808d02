"""redundancy.holds_on_columns: the part of the held rows' span that contact rows can reach.

Rows holding a piece on its rigid modes are dense over the piece. A row of C depends on
them only through combinations vanishing on every free column that no row of C touches;
those replace them. Checked against the exact ranks (SVD) on two pieces: a single
tetrahedron whose four vertices all carry rows (its six modes count fully) and a piece of
16 vertices of which six carry rows (its modes reach none of them).
"""
import numpy as np
import scipy.sparse as sp

from ngfracture.contact.redundancy import holds_on_columns, independent_rows


def rigid_mode_rows(points, vertices, nv):
    """The six rigid modes of the vertices as rows (layout comp * nv + v)."""
    rows = []
    for k in range(6):
        r = np.zeros(3 * nv)
        for v in vertices:
            if k < 3:
                d = np.eye(3)[k]
            else:
                d = np.cross(np.eye(3)[k - 3], points[v])
            r[[v, nv + v, 2 * nv + v]] = d
        rows.append(r)
    return np.array(rows)


def rows_on(vertices, count, nv, rng):
    """Random rows on the dofs of the given vertices."""
    out = np.zeros((count, 3 * nv))
    for i in range(count):
        vs = rng.choice(vertices, size=2, replace=False)
        for v in vs:
            out[i, [v, nv + v, 2 * nv + v]] = rng.normal(size=3)
    return out


def rank(M):
    s = np.linalg.svd(M, compute_uv=False)
    return int(np.count_nonzero(s > 1e-10 * s.max()))


def test_the_reachable_holds_decide_as_all_of_them():
    rng = np.random.default_rng(1)
    nv = 20
    points = rng.normal(size=(nv, 3))
    G = np.vstack([rigid_mode_rows(points, range(4), nv), rigid_mode_rows(points, range(4, nv), nv)])
    C = np.vstack([rows_on(range(4), 10, nv, rng), rows_on(range(4, 10), 8, nv, rng)])
    fixed = np.array([2 * nv + 19])                   # a fixed dof off the rows
    reduced = holds_on_columns(sp.csr_matrix(G), sp.csr_matrix(C), fixed, rtol=1e-8).toarray()
    # the tetrahedron's six modes stay, the large piece's vanish
    assert reduced.shape[0] == 6
    touched = np.zeros(3 * nv, dtype=bool)
    touched[np.flatnonzero(np.any(C != 0, axis=0))] = True
    touched[fixed] = True
    assert np.all(reduced[:, ~touched] == 0.0)
    assert rank(np.vstack([G, reduced])) == rank(G)                 # within the span of G
    # the rows kept: as many as C adds to the span of G (exact ranks), with either holds
    expected = rank(np.vstack([G, C])) - rank(G)
    assert expected == 12 - 6 + 8
    for holds in (G, reduced):
        kept = independent_rows(sp.csr_matrix(C), G=sp.csr_matrix(holds), rtol=1e-8)
        assert len(kept) == expected


def test_rows_without_untouched_columns_are_kept_and_none_give_none():
    rng = np.random.default_rng(2)
    C = rng.normal(size=(12, 18))                     # every column touched
    G = rng.normal(size=(3, 18))
    reduced = holds_on_columns(sp.csr_matrix(G), sp.csr_matrix(C))
    assert np.allclose(reduced.toarray(), G / np.linalg.norm(G, axis=1)[:, None], rtol=0, atol=1e-15)
    assert holds_on_columns(None, sp.csr_matrix(C)) is None
