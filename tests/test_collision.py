"""Collision detection: exact orient2d, grid broad phase = brute force, exact narrow phase."""
from fractions import Fraction

import numpy as np
import pytest

import ngfracture  # noqa: F401  (loads NGSolve's libraries first)
from ngfracture import _ngfracture as ext
from ngfracture.contact import collision


def exact_sign(a, b, c):
    """Sign of orient2d in rational arithmetic (Fractions represent doubles exactly)."""
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    d = (ax - cx) * (by - cy) - (ay - cy) * (bx - cx)
    return (d > 0) - (d < 0)


def ulp_grid(base, b, c, k=128):
    """Points base + (i, j) ulps, i, j < k, with the fixed points b and c."""
    base = np.broadcast_to(np.asarray(base, float), (2,))
    u = np.spacing(base)
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    a = np.stack([base[0] + i.ravel() * u[0], base[1] + j.ravel() * u[1]], axis=1)
    return a, np.tile(b, (len(a), 1)), np.tile(c, (len(a), 1))


# --------------------------------------------------------------------- predicates
@pytest.mark.parametrize("base,b,c,k", [
    (0.5, [12.0, 12.0], [24.0, 24.0], 128),     # Shewchuk's classic near-collinear grid
    ((0.5, 1.0), [12.0, 24.0], [24.0, 48.0], 64),
    (1.0 / 3.0, [7.0 / 3.0, 7.0 / 3.0], [-11.0 / 3.0, -11.0 / 3.0], 64),
    ((0.1, 0.3), [12.1, 36.3], [24.1, 72.3], 128),  # inexact differences: stage C
    pytest.param(0.5, [12.0, 12.0], [24.0, 24.0], 256, marks=pytest.mark.slow),
    pytest.param((0.1, 0.3), [12.1, 36.3], [24.1, 72.3], 256, marks=pytest.mark.slow),
])
def test_orient2d_near_collinear_zero_sign_errors(base, b, c, k):
    a, B, Cc = ulp_grid(base, np.array(b), np.array(c), k)
    exact = np.array([exact_sign(p, b, c) for p in a])
    robust = collision.orient2d(a, B, Cc)
    expansion_only = ext.Orient2d(a, B, Cc, True)
    naive = np.sign((a[:, 0] - Cc[:, 0]) * (B[:, 1] - Cc[:, 1])
                    - (a[:, 1] - Cc[:, 1]) * (B[:, 0] - Cc[:, 0]))
    assert np.count_nonzero(robust != exact) == 0
    assert np.count_nonzero(expansion_only != exact) == 0
    # the grid is hard: the plain determinant gets many signs wrong
    assert np.count_nonzero(naive != exact) > k
    assert np.count_nonzero(exact > 0) > 0 and np.count_nonzero(exact < 0) > 0


def test_orient2d_random_near_collinear_against_fractions():
    rng = np.random.default_rng(1)
    n = 3000
    b = rng.uniform(-1e3, 1e3, (n, 2))
    c = rng.uniform(-1e3, 1e3, (n, 2))
    t = rng.uniform(-2, 3, (n, 1))
    a = c + t * (b - c)                                   # on the line up to rounding
    a += rng.integers(-3, 4, (n, 2)) * np.spacing(a)      # a few ulps off
    # and exactly collinear triples (integers, exact in double precision)
    bi, ci = rng.integers(-1000, 1000, (2, n, 2)).astype(float)
    ai = ci + rng.integers(-3, 4, (n, 1)) * (bi - ci)
    a, b, c = (np.concatenate(p) for p in ((a, ai), (b, bi), (c, ci)))
    n = len(a)
    exact = np.array([exact_sign(a[i], b[i], c[i]) for i in range(n)])
    assert np.count_nonzero(collision.orient2d(a, b, c) != exact) == 0
    assert np.count_nonzero(exact == 0) > 0


@pytest.mark.parametrize("shift", [0.25, -0.5, 2.0 ** -3])
def test_orient2d_translation_invariant(shift):
    a, B, Cc = ulp_grid(0.5, np.array([12.0, 12.0]), np.array([24.0, 24.0]), k=64)
    s0 = collision.orient2d(a, B, Cc)
    moved = [p + shift for p in (a, B, Cc)]
    # only translations that are exact in double precision preserve the geometry
    for p, q in zip((a, B, Cc), moved):
        assert all(Fraction(float(x)) + Fraction(shift) == Fraction(float(y))
                   for x, y in zip(p.ravel(), q.ravel()))
    assert np.array_equal(collision.orient2d(*moved), s0)


@pytest.mark.parametrize("k", [-60, -20, 1, 30, 90])
def test_orient2d_power_of_two_scaling_invariant(k):
    a, B, Cc = ulp_grid(0.5, np.array([12.0, 12.0]), np.array([24.0, 24.0]), k=64)
    s0 = collision.orient2d(a, B, Cc)
    f = 2.0 ** k
    assert np.array_equal(collision.orient2d(a * f, B * f, Cc * f), s0)
    assert np.array_equal(collision.orient2d(a * -f, B * -f, Cc * -f), s0)  # point reflection


# ------------------------------------------------------------------- broad phase
def random_soup(n, rng, smin=0.002, smax=0.01, share=True):
    """n random small triangles in the unit square; with share, pairs share a vertex."""
    if share:
        m = n // 2
        p = rng.uniform(0, 1, (m, 2))
        s = rng.uniform(smin, smax, (m, 1))
        ang = rng.uniform(0, 2 * np.pi, (m, 4))
        q = p[:, None, :] + s[:, :, None] * np.stack([np.cos(ang), np.sin(ang)], axis=2)
        X = np.concatenate([p, q.reshape(-1, 2)])
        base = m + 4 * np.arange(m)
        T = np.concatenate([np.stack([np.arange(m), base, base + 1], 1),
                            np.stack([np.arange(m), base + 2, base + 3], 1)])
    else:
        cen = rng.uniform(0, 1, (n, 1, 2))
        X = (cen + rng.uniform(-smax, smax, (n, 3, 2))).reshape(-1, 2)
        T = np.arange(3 * n).reshape(n, 3)
    return X, T.astype(np.int32)


def brute_force_box_pairs(x, T, cand, frag, tol):
    P = x[T]
    lo = P.min(axis=1) - tol / 2
    hi = P.max(axis=1) + tol / 2
    idx = np.flatnonzero(cand)
    out = []
    for s in range(0, len(idx), 500):
        I = idx[s:s + 500]
        ov = ((lo[I, None, 0] <= hi[None, idx, 0]) & (lo[None, idx, 0] <= hi[I, None, 0])
              & (lo[I, None, 1] <= hi[None, idx, 1]) & (lo[None, idx, 1] <= hi[I, None, 1]))
        ii, jj = np.nonzero(ov)
        i, j = I[ii], idx[jj]
        keep = i < j
        out.append(np.stack([i[keep], j[keep]], 1))
    pairs = np.concatenate(out)
    shared = (T[pairs[:, 0]][:, :, None] == T[pairs[:, 1]][:, None, :]).any(axis=(1, 2))
    same = frag[pairs[:, 0]] == frag[pairs[:, 1]]
    pairs = pairs[~(shared & same)]
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


@pytest.mark.parametrize("tol", [0.0, 0.003])
def test_broad_phase_equals_brute_force_1e4(tol):
    rng = np.random.default_rng(7)
    X, T = random_soup(10_000, rng)
    cand = rng.uniform(size=len(T)) < 0.9
    frag = rng.integers(0, 2, len(T)).astype(np.int32)
    grid = collision.broad_phase_pairs(X, None, T, cand, fragment=frag, tol=tol)
    brute = brute_force_box_pairs(X, T, cand, frag, tol)
    assert len(brute) > 1000
    assert grid.shape == brute.shape
    assert np.array_equal(grid, brute)
    # The anti-diagonal neighbour matters: pairs whose centroid bins are (ix, iy) and
    # (ix + 1, iy - 1) exist, and the paper's three neighbours would miss them.
    _, h = ext.CollisionPairs(X, T, cand.view(np.uint8), frag, tol, False)
    cen = X[T].mean(axis=1)
    b = np.floor((cen - cen[cand].min(axis=0)) / h).astype(int)
    d = b[brute[:, 1]] - b[brute[:, 0]]
    anti = ((d[:, 0] == 1) & (d[:, 1] == -1)) | ((d[:, 0] == -1) & (d[:, 1] == 1))
    assert np.count_nonzero(anti) > 0
    assert np.abs(d).max() <= 1


def test_broad_phase_without_fragment_ids_excludes_all_neighbours():
    rng = np.random.default_rng(3)
    X, T = random_soup(2000, rng)
    cand = np.ones(len(T), bool)
    grid = collision.broad_phase_pairs(X, None, T, cand)
    brute = brute_force_box_pairs(X, T, cand, np.zeros(len(T), int), 0.0)
    assert np.array_equal(grid, brute)


# ------------------------------------------------------------------ narrow phase
def exact_interiors_overlap(p, q):
    """Separating-axis test in exact integer arithmetic (coordinates are integers)."""
    def orient(a, b, c):
        d = (a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0])
        return (d > 0) - (d < 0)
    p, q = [[tuple(int(v) for v in row) for row in t] for t in (p, q)]
    for t in (p, q):
        o = orient(*t)
        if o == 0:
            return False
        if o < 0:
            t[1], t[2] = t[2], t[1]
    for t, o in ((p, q), (q, p)):
        for i in range(3):
            if all(orient(t[i], t[(i + 1) % 3], v) <= 0 for v in o):
                return False
    return True


def test_narrow_phase_matches_exact_reference_on_lattice_triangles():
    # Integer lattice vertices: touching, collinear and coincident cases are frequent.
    rng = np.random.default_rng(11)
    n = 1000
    cen = rng.integers(0, 40, (n, 1, 2))
    Xi = (cen + rng.integers(-3, 4, (n, 3, 2))).reshape(-1, 2)
    T = np.arange(3 * n).reshape(n, 3).astype(np.int32)
    X = Xi.astype(float)
    cand = np.ones(n, bool)
    boxes = collision.broad_phase_pairs(X, None, T, cand)
    found = collision.detect_collisions(X, None, T, candidates=cand)
    ref = np.array([exact_interiors_overlap(Xi[T[i]], Xi[T[j]]) for i, j in boxes])
    assert np.array_equal(found, boxes[ref])
    # degenerate cases really occur: box pairs that touch without overlapping
    assert np.count_nonzero(~ref) > 100 and np.count_nonzero(ref) > 100
    # the overlap test is exact under scaling by 2^-30 and translation by 2^10
    found2 = collision.detect_collisions(X * 2.0 ** -30 + 1024.0, None, T, candidates=cand)
    assert np.array_equal(found2, found)


def collide(p, q, tol=0.0):
    X = np.array(list(p) + list(q), float)
    T = np.array([[0, 1, 2], [3, 4, 5]], np.int32)
    return bool(collision.triangles_collide(X, T, [[0, 1]], tol)[0])


UNIT = [(0, 0), (1, 0), (0, 1)]


@pytest.mark.parametrize("q,tol,expected", [
    ([(0.2, 0.2), (2, 0.2), (0.2, 2)], 0.0, True),           # vertex inside
    ([(0, 0), (1, 0), (0, 1)], 0.0, True),                   # identical
    ([(0, 0), (0, 1), (1, 0)], 0.0, True),                   # identical, clockwise copy
    ([(0.5, 0), (0.5, 0.5), (0, 0.5)], 0.0, True),           # inscribed: vertices on edges
    ([(-0.1, 0.3), (1.2, 0.3), (-0.1, 0.4)], 0.0, True),     # edges cross, no vertex inside
    ([(1, 0), (1, 1), (0, 1)], 0.0, False),                  # shares the hypotenuse
    ([(1, 0), (1, 1), (0, 1)], 1e-12, True),                 # ... touching within tol
    ([(1, 0), (2, 0), (1, 1)], 0.0, False),                  # touches at a vertex
    ([(0.5, 0), (1.5, 0), (0.5, -1)], 0.0, False),           # collinear edges, other side
    ([(0.5, 0.5), (1.5, 0.5), (0.5, 1.5)], 0.0, False),      # vertex on the hypotenuse
    ([(0.7, 0.7), (2, 0.7), (0.7, 2)], 0.0, False),          # separated by 0.2 sqrt(2)
    ([(0.7, 0.7), (2, 0.7), (0.7, 2)], 0.28, False),         # distance 0.2828 > tol
    ([(0.7, 0.7), (2, 0.7), (0.7, 2)], 0.29, True),          # distance 0.2828 <= tol
    ([(0.5, 0.5 + 1e-17), (1.5, 0.5), (0.5, 1.5)], 0.0, False),
    ([(0.5, 0.5 - 2 ** -53), (1.5, 0.5), (0.5, 1.5)], 0.0, True),   # one ulp inside
])
def test_narrow_phase_hand_made(q, tol, expected):
    assert collide(UNIT, q, tol) is expected
    assert collide(q, UNIT, tol) is expected          # symmetric


def test_degenerate_triangle_has_no_interior():
    assert collide(UNIT, [(0.1, 0.1), (0.2, 0.2), (0.3, 0.3)]) is False
    assert collide(UNIT, [(0.1, 0.1), (0.2, 0.2), (0.3, 0.3)], tol=1e-3) is True


# ------------------------------------------------------------------ mesh scenes
def grid_mesh(nx, ny, x0=0.0, y0=0.0, h=1.0):
    """Structured CCW triangulation of [x0, x0 + nx h] x [y0, y0 + ny h]."""
    xs, ys = np.meshgrid(x0 + h * np.arange(nx + 1), y0 + h * np.arange(ny + 1), indexing="ij")
    X = np.stack([xs.ravel(), ys.ravel()], 1)
    v = lambda i, j: i * (ny + 1) + j  # noqa: E731
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    i, j = i.ravel(), j.ravel()
    T = np.concatenate([np.stack([v(i, j), v(i + 1, j), v(i + 1, j + 1)], 1),
                        np.stack([v(i, j), v(i + 1, j + 1), v(i, j + 1)], 1)])
    return X, T.astype(np.int32)


def boundary_edges_of(T):
    """Directed edges used by exactly one triangle (their triangle is on the left)."""
    e = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]).astype(np.int64)
    n = e.max() + 1
    key, rev = e[:, 0] * n + e[:, 1], e[:, 1] * n + e[:, 0]
    return e[~np.isin(key, rev)]


def two_blocks(n=8, overlap=0.01):
    """Blocks [0,1]^2 and [1,2]x[0,1], the second moved left by overlap."""
    X1, T1 = grid_mesh(n, n, h=1.0 / n)
    X2, T2 = grid_mesh(n, n, x0=1.0, h=1.0 / n)
    X = np.concatenate([X1, X2])
    T = np.concatenate([T1, T2 + len(X1)]).astype(np.int32)
    U = np.zeros_like(X)
    U[len(X1):, 0] = -overlap
    frag = np.repeat([0, 1], len(T1)).astype(np.int32)
    return X, U, T, frag


def test_uncut_mesh_has_no_collisions_even_with_tolerance():
    X, T = grid_mesh(20, 20, h=0.05)
    cand = np.ones(len(T), bool)                        # every element takes part
    for tol in (0.0, 1e-6, 0.01):
        assert len(collision.detect_collisions(X, None, T, candidates=cand, tol=tol)) == 0
    assert len(collision.broad_phase_pairs(X, None, T, cand, tol=0.0)) > 0


def test_pressed_blocks_collide_only_across_the_interface():
    X, U, T, frag = two_blocks(n=8, overlap=0.01)
    E = boundary_edges_of(T)
    pairs = collision.detect_collisions(X, U, T, boundary_edges=E, fragment=frag)
    assert len(pairs) > 0
    assert np.all(frag[pairs[:, 0]] != frag[pairs[:, 1]])
    # elements with an edge on the interface all take part; all others touch it
    x = (X + U)[T][:, :, 0]
    on_iface = np.abs(x - np.where(frag[:, None] == 0, 1.0, 0.99)) < 1e-12
    in_pairs = np.isin(np.arange(len(T)), pairs)
    assert np.all(in_pairs[on_iface.sum(axis=1) == 2])
    assert np.all(on_iface[in_pairs].any(axis=1))
    # separated by 0.01 instead: nothing at tol 0, the interface again at tol 0.02
    assert len(collision.detect_collisions(X, -U, T, boundary_edges=E, fragment=frag)) == 0
    far = collision.detect_collisions(X, -U, T, boundary_edges=E, fragment=frag, tol=0.02)
    assert len(far) > 0 and np.all(frag[far[:, 0]] != frag[far[:, 1]])
    assert len(collision.detect_collisions(X, -U, T, boundary_edges=E, fragment=frag,
                                           tol=0.0099)) == 0


# -------------------------------------------------------- no work, bad input
def test_empty_candidates_do_no_work(monkeypatch):
    X, T = grid_mesh(50, 50, h=0.02)
    def forbidden(*args, **kwargs):
        raise AssertionError("the C++ sweep must not run without candidates")
    monkeypatch.setattr(collision._ext, "CollisionPairs", forbidden)
    for cand in (np.zeros(len(T), bool), np.eye(1, len(T), 5, dtype=bool).ravel()):
        out = collision.detect_collisions(X, None, T, candidates=cand)
        assert out.shape == (0, 2)
    E = np.zeros((0, 2), int)                           # no boundary / crack edges
    assert collision.detect_collisions(X, None, T, boundary_edges=E).shape == (0, 2)


def test_bad_input_raises_clear_errors():
    X, T = grid_mesh(2, 2)
    cand = np.ones(len(T), bool)
    Xn = X.copy()
    Xn[3, 1] = np.nan
    with pytest.raises(ValueError, match="coords"):
        collision.detect_collisions(Xn, None, T, candidates=cand)
    with pytest.raises(ValueError, match="displacement"):
        collision.detect_collisions(X, np.full_like(X, np.inf), T, candidates=cand)
    with pytest.raises(ValueError, match="displacement"):
        collision.detect_collisions(X, np.zeros((3, 2)), T, candidates=cand)
    with pytest.raises(ValueError, match="tol"):
        collision.detect_collisions(X, None, T, candidates=cand, tol=-1e-3)
    with pytest.raises(ValueError, match="tol"):
        collision.detect_collisions(X, None, T, candidates=cand, tol=np.nan)
    with pytest.raises(ValueError, match="tris"):
        collision.detect_collisions(X, None, T[:, :2], candidates=cand)
    with pytest.raises(ValueError, match="tris"):
        collision.detect_collisions(X, None, T + 100, candidates=cand)
    with pytest.raises(ValueError, match="candidates"):
        collision.detect_collisions(X, None, T, candidates=cand[:-1])
    with pytest.raises(TypeError, match="candidates"):
        collision.detect_collisions(X, None, T, candidates=cand.astype(int))
    with pytest.raises(ValueError, match="fragment"):
        collision.detect_collisions(X, None, T, candidates=cand, fragment=[0, 1])
    with pytest.raises(ValueError, match="boundary edge"):
        collision.boundary_edge_mask(T, [[3, 0]])      # reversed: triangle on the right
    with pytest.raises(ValueError, match="candidates or boundary_edges"):
        collision.detect_collisions(X, None, T)
    # the no-work path still checks shapes
    with pytest.raises(ValueError, match="tris"):
        collision.detect_collisions(X, None, T[:, :2], boundary_edges=np.zeros((0, 2), int))
    with pytest.raises(ValueError, match="candidates"):
        collision.detect_collisions(X, None, T, candidates=np.zeros(3, bool))
    with pytest.raises(ValueError, match="a, b and c"):
        collision.orient2d(np.zeros((2, 2)), np.zeros((3, 2)), np.zeros((2, 2)))


if __name__ == "__main__":
    import sys
    sys.exit(pytest.main([__file__, "-q"]))
