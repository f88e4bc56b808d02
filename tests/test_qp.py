"""The dense QP behind the contact LCP: exact Kuhn-Tucker points in finitely many steps."""
from pathlib import Path

import numpy as np
import pytest

from ngfracture.linalg.qp import Infeasible, QPError, bound_qp, convex_qp


def kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, x, u_eq, u_in):
    """Largest violation of stationarity, feasibility, sign and complementarity (relative)."""
    scale = np.abs(c).max() + np.abs(H @ x).max()
    s = A_in @ x - b_in
    return max(np.abs(H @ x - c - A_eq.T @ u_eq - A_in.T @ u_in).max() / scale,
               np.abs(A_eq @ x - b_eq).max(initial=0.0), max(0.0, -s.min(initial=0.0)),
               max(0.0, -u_in.min(initial=0.0)) / scale, np.abs(u_in * s).max(initial=0.0) / scale)


@pytest.mark.parametrize("seed", range(20))
def test_random_bound_and_equality_constrained_qps(seed):
    """Sign bounds on some variables plus equalities, as in the contact dual: KT to 1e-10."""
    rng = np.random.default_rng(seed)
    n, p = int(rng.integers(2, 40)), int(rng.integers(0, 3))
    B = rng.standard_normal((n, n))
    H, c = B @ B.T + 1e-3 * np.eye(n), rng.standard_normal(n)
    A_eq, b_eq = rng.standard_normal((p, n)), rng.standard_normal(p)
    A_in = -np.eye(n)[rng.choice(n, int(rng.integers(0, n)), replace=False)]
    b_in = np.zeros(len(A_in))
    x, u_eq, u_in, active = convex_qp(H, c, A_eq, b_eq, A_in, b_in)
    assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, x, u_eq, u_in) < 1e-10
    assert np.all(u_in[~active] == 0.0)


@pytest.mark.parametrize("seed", range(3))
def test_contact_sized_qps_with_updated_factorisations(seed):
    """A few hundred unknowns, as the contact LCP of the disintegrating disk: hundreds of
    working-set changes, entries and drops, each updating the QR by Givens rotations
    (qr_insert / qr_delete) instead of refactorising; Kuhn-Tucker still to 1e-10."""
    rng = np.random.default_rng(100 + seed)
    n = 250
    B = rng.standard_normal((n, n)) / np.sqrt(n)
    H, c = B @ B.T + 1e-2 * np.eye(n), rng.standard_normal(n)
    A_eq, b_eq = rng.standard_normal((6, n)), rng.standard_normal(6)
    A_in, b_in = -np.eye(n), np.zeros(n)
    x, u_eq, u_in, active = convex_qp(H, c, A_eq, b_eq, A_in, b_in)
    assert 20 < active.sum() < n - 20                    # many bounds active, many not
    assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, x, u_eq, u_in) < 1e-10


def test_lcp_matches_enumeration_of_all_active_sets():
    """min 1/2 x^T H x - c^T x, x <= 0 for an SPD H that is no M-matrix (mixed-sign
    coupling, as nearly parallel contact rows give): the unique KT point, found by trying
    all 2^6 active sets, is reproduced to rounding."""
    rng = np.random.default_rng(1)
    B = rng.standard_normal((6, 6))
    H, c = B @ B.T + 0.1 * np.eye(6), rng.standard_normal(6)
    assert (H - np.diag(np.diag(H)) > 0).any()          # not an M-matrix
    x, _, _, _ = convex_qp(H, c, np.zeros((0, 6)), np.zeros(0), -np.eye(6), np.zeros(6))
    found = []
    for mask in range(64):
        free = np.array([(mask >> i) & 1 for i in range(6)], dtype=bool)
        y = np.zeros(6)
        y[free] = np.linalg.solve(H[np.ix_(free, free)], c[free])
        g = c - H @ y                   # >= 0 where x is held at 0 (its multiplier)
        if np.all(y[free] <= 1e-13) and np.all(g[~free] >= -1e-13):
            found.append(y)
    assert len(found) == 1 and np.abs(x - found[0]).max() < 1e-12 * np.abs(found[0]).max()


def test_infeasible_constraints_are_reported():
    """x <= 0 and x = 1 have no common point."""
    with pytest.raises(Infeasible):
        convex_qp(np.eye(1), np.zeros(1), np.ones((1, 1)), np.ones(1), -np.eye(1), np.zeros(1))


if __name__ == "__main__":
    import sys
    sys.exit(pytest.main([__file__, "-q"]))


def test_a_nearly_singular_h_is_an_error_not_a_huge_answer():
    """The complementarity QP of a cracked L-panel's contact rows (79 multipliers, 6 rigid
    modes; H = S + G G^T + 1e-10 I of condition 2e11, its rows dependent): the dual steps
    ran away to 1e157 and the loop's stopping level, relative to the iterate, accepted it.
    Now a QPError (the contact solver records it and takes the primal-dual update)."""
    data = np.load(Path(__file__).parent / "data" / "qp_nearly_singular.npz")
    with pytest.raises(QPError, match="nearly singular"):
        convex_qp(*(data[k] for k in ("H", "c", "A_eq", "b_eq", "A_in", "b_in")))


def bounds_of(n, bounded):
    """The rows -x_i >= 0 of the bounds x_i <= 0 (i in ``bounded``) as convex_qp takes them."""
    return -np.eye(n)[bounded], np.zeros(len(bounded))


@pytest.mark.parametrize("seed", range(4))
def test_a_dual_method_started_from_any_working_set_ends_at_the_same_point(seed):
    """Goldfarb-Idnani from a start set (right, wrong, dependent on the equalities): the
    inequalities with negative multipliers or dependent vectors are dropped, the rest is
    an S-pair, and the method ends at the unique Kuhn-Tucker point of the cold start."""
    rng = np.random.default_rng(200 + seed)
    n, p = 40, 3
    B = rng.standard_normal((n, n))
    H, c = B @ B.T + 1e-2 * np.eye(n), rng.standard_normal(n)
    A_eq, b_eq = rng.standard_normal((p, n)), rng.standard_normal(p)
    bounded = rng.choice(n, 30, replace=False)
    A_in, b_in = bounds_of(n, bounded)
    cold = convex_qp(H, c, A_eq, b_eq, A_in, b_in)
    for start in (np.flatnonzero(cold[3]), np.arange(30), rng.choice(30, 12, replace=False), np.arange(0)):
        x, u_eq, u_in, active = convex_qp(H, c, A_eq, b_eq, A_in, b_in, start=start)
        assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, x, u_eq, u_in) < 1e-10
        assert np.array_equal(active, cold[3])
        assert np.abs(x - cold[0]).max() < 1e-10 * np.abs(cold[0]).max()


def test_primal_dual_sweeps_alone_solve_an_m_matrix_problem():
    """For an M-matrix (a 1D Laplacian plus a shift) the primal-dual sweeps converge
    monotonically, in at most one sweep per bound (Hintermüller, Ito, Kunisch 2003): the
    dual method is not needed, and the point is the Kuhn-Tucker point."""
    n = 800
    H = 2.1 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    c = np.sin(np.linspace(0.0, 25.0, n)) + 0.2
    bounded = np.arange(n)
    answer = bound_qp(H, c, np.zeros((0, n)), np.zeros(0), bounded, max_sweeps=n + 1, stop_early=False)
    assert not answer.dual_steps and answer.sweeps > 1
    A_in, b_in = bounds_of(n, bounded)
    assert kuhn_tucker_error(H, c, np.zeros((0, n)), np.zeros(0), A_in, b_in, answer.x, answer.u_eq,
                             answer.u_bound) < 1e-10
    assert np.array_equal(answer.held, convex_qp(H, c, np.zeros((0, n)), np.zeros(0), A_in, b_in)[3])


def mixed_sign_qp(seed, n):
    """A contact-sized QP with no M-matrix (dense mixed-sign coupling) and six equalities
    for free modes: (H, c, A_eq, b_eq, bounded) and the generator, to draw more from it."""
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n)) / np.sqrt(n)
    H, c = B @ B.T + 1e-2 * np.eye(n), rng.standard_normal(n)
    A_eq, b_eq = rng.standard_normal((6, n)), rng.standard_normal(6)
    return H, c, A_eq, b_eq, np.arange(6, n), rng


@pytest.mark.parametrize("seed", range(2))
def test_sweeps_that_do_not_settle_are_finished_by_the_dual_method(seed):
    """Contact-sized, no M-matrix (dense mixed-sign coupling), six equalities for free
    modes, two sweeps allowed (fewer than these problems need): the dual method finishes
    from the sweeps' best guess, and the answer is the cold dual method's Kuhn-Tucker point
    with its working set."""
    n = 500
    H, c, A_eq, b_eq, bounded, _ = mixed_sign_qp(300 + seed, n)
    answer = bound_qp(H, c, A_eq, b_eq, bounded, max_sweeps=2)
    assert answer.dual_steps and answer.sweeps == 2
    A_in, b_in = bounds_of(n, bounded)
    assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, answer.x, answer.u_eq, answer.u_bound) < 1e-10
    assert np.array_equal(answer.held, convex_qp(H, c, A_eq, b_eq, A_in, b_in)[3])


@pytest.mark.parametrize("seed", range(3))
def test_a_guess_that_releases_every_row_of_free_pieces_is_mended(seed):
    """Many free pieces (three equalities each, as a 2D piece's rigid modes) with their own
    rows, H = S + G G^T as the contact dual's; every row of a third of the pieces has
    c_i > 0, so the sweeps' first guess holds all of them and those pieces' equalities are
    dependent on the free variables. The guess is mended and the answer is the Kuhn-Tucker
    point to rounding (sqrt(n) eps cond(H)) with the cold dual method's working set."""
    rng = np.random.default_rng(400 + seed)
    pieces, rows = 30, 6
    n = pieces * rows
    A_eq = np.zeros((3 * pieces, n))
    for j in range(pieces):
        A_eq[3 * j:3 * j + 3, rows * j:rows * (j + 1)] = rng.standard_normal((3, rows))
    B = rng.standard_normal((n, n)) / np.sqrt(n)
    H = B @ B.T + A_eq.T @ A_eq + 1e-2 * np.eye(n)
    c = rng.standard_normal(n)
    c[:rows * pieces // 3] = np.abs(c[:rows * pieces // 3])     # the released pieces
    b_eq = A_eq @ -np.abs(rng.standard_normal(n))               # feasible with x <= 0
    bounded = np.arange(n)
    answer = bound_qp(H, c, A_eq, b_eq, bounded)
    A_in, b_in = bounds_of(n, bounded)
    rounding = np.sqrt(n) * np.finfo(float).eps * np.linalg.cond(H)
    assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, answer.x, answer.u_eq, answer.u_bound) < rounding
    cold = convex_qp(H, c, A_eq, b_eq, A_in, b_in)
    assert np.array_equal(answer.held, cold[3])
    assert np.abs(answer.x - cold[0]).max() < rounding * np.abs(cold[0]).max()


@pytest.mark.parametrize("seed", range(2))
def test_a_guess_at_the_answer_ends_in_one_sweep_and_any_guess_at_the_same_point(seed):
    """Started from a guess of the held bounds (a contact solve's rounds meet almost the
    same problem): from the answer's own working set one sweep and no dual step; from that
    set with some bounds flipped, and from holding nothing or everything, the same
    Kuhn-Tucker point (1e-10) and working set. A guess of another length is refused."""
    n = 300
    H, c, A_eq, b_eq, bounded, rng = mixed_sign_qp(400 + seed, n)
    A_in, b_in = bounds_of(n, bounded)
    cold = bound_qp(H, c, A_eq, b_eq, bounded)
    warm = bound_qp(H, c, A_eq, b_eq, bounded, guess=cold.held)
    assert warm.sweeps == 1 and not warm.dual_steps
    flipped = cold.held.copy()
    flipped[rng.choice(len(bounded), 12, replace=False)] ^= True
    for guess in (cold.held, flipped, np.zeros(len(bounded), bool), np.ones(len(bounded), bool)):
        answer = bound_qp(H, c, A_eq, b_eq, bounded, guess=guess)
        assert kuhn_tucker_error(H, c, A_eq, b_eq, A_in, b_in, answer.x, answer.u_eq, answer.u_bound) < 1e-10
        assert np.array_equal(answer.held, cold.held)
    with pytest.raises(ValueError, match="guess"):
        bound_qp(H, c, A_eq, b_eq, bounded, guess=cold.held[1:])
