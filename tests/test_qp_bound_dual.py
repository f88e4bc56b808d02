"""The dual active-set method on sign bounds with the free block's Cholesky factor updated
(C++ BoundDualActiveSet behind bound_qp): the same working sets as the QR form of
convex_qp, the same Kuhn-Tucker point, and a recorded fallback when rounding stops it."""
import numpy as np
import pytest

from ngfracture import _ngfracture as ext
from ngfracture.linalg import qp as qp_module
from ngfracture.linalg.qp import GROWTH_LIMIT, Infeasible, bound_qp, convex_qp
from test_qp import bounds_of, kuhn_tucker_error


def contact_like(seed, n, p):
    """An SPD H with dense mixed-sign coupling (no M-matrix), p equalities as free modes."""
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n)) / np.sqrt(n)
    H, c = B @ B.T + 1e-2 * np.eye(n), rng.standard_normal(n)
    return H, c, rng.standard_normal((p, n)), rng.standard_normal(p), rng


def bound_dual(H, c, E, e, bounded, held):
    """BoundDualActiveSet from the start ``held`` (bool per variable), its data as bound_qp
    prepares them."""
    n = len(c)
    is_bound = np.zeros(n, dtype=np.int8)
    is_bound[bounded] = 1
    free = np.flatnonzero(~held)
    L0 = np.linalg.cholesky(H[np.ix_(free, free)])
    norm, extra, data = qp_module._start_metric(H, c, E, e, held, L0)
    return ext.BoundDualActiveSet(H, c, E, e, is_bound, norm, extra, held.astype(np.int8), L0, 1e-12, data,
                                  GROWTH_LIMIT, 10 * n + 100)


@pytest.mark.parametrize("held_fraction", [0.0, 0.1, 0.9, 1.0])
def test_the_start_metric_is_that_of_the_inverse_of_H(held_fraction):
    """The bounds' lengths |L^-1 e_i| = sqrt((H^-1)_ii) and the data's size sqrt(c^T H^-1 c)
    (and |e_q| / sqrt(E_q H^-1 E_q^T)), made from the start's factor of H_FF and the Schur
    complement of its held variables, are those of the dense inverse of H to rounding
    (n eps cond(H)); the free variables' first term |L0^-1 e_r|^2, which the C++ steps
    compute, is taken here from the inverse of L0."""
    n, p = 200, 6
    H, c, E, e, rng = contact_like(42, n, p)
    held = rng.random(n) < held_fraction
    free = np.flatnonzero(~held)
    L0 = np.linalg.cholesky(H[np.ix_(free, free)]) if len(free) else np.zeros((0, 0))
    norm, extra, data = qp_module._start_metric(H, c, E, e, held, L0)
    lengths = norm.copy()
    lengths[free] = np.sqrt(np.sum(np.linalg.inv(L0) ** 2, axis=0) + extra[free]) if len(free) else 0.0
    inverse = np.linalg.inv(H)
    rounding = n * np.finfo(float).eps * np.linalg.cond(H)
    assert np.all(norm[free] == 0.0) and np.all(extra[held] == 0.0)
    assert np.abs(lengths / np.sqrt(np.diag(inverse)) - 1).max() <= rounding
    expected = max(np.sqrt(c @ inverse @ c), np.max(np.abs(e) / np.sqrt(np.diag(E @ inverse @ E.T))))
    assert abs(data / expected - 1) <= rounding


@pytest.mark.parametrize("seed,p", [(0, 0), (1, 6), (2, 6), (3, 9)])
def test_updated_factor_walks_the_working_sets_of_the_qr_method(seed, p, monkeypatch):
    """From a start that holds every bound (most of them wrongly) and from a random half:
    the start's negative multipliers are freed, then bounds enter and leave (the rank-one
    update of a removed row and column, the appended row of a freed variable). The answer
    is convex_qp's from the same start: as many bounds entered, the same working set, x to
    rounding (sqrt(n) eps cond(H)), Kuhn-Tucker to 1e-10."""
    n = 300
    H, c, E, e, rng = contact_like(500 + seed, n, p)
    bounded = np.sort(rng.choice(n, n - 10, replace=False))
    A_in, b_in = bounds_of(n, bounded)
    entered = []
    enter = qp_module._enter
    monkeypatch.setattr(qp_module, "_enter", lambda *a: entered.append(1) or enter(*a))
    rounding = np.sqrt(n) * np.finfo(float).eps * np.linalg.cond(H)
    for start in (np.arange(len(bounded)), np.sort(rng.choice(len(bounded), len(bounded) // 2, replace=False))):
        held = np.zeros(n, dtype=bool)
        held[bounded[start]] = True
        x, mu, u, held_out, steps, dropped, status, reason = bound_dual(H, c, E, e, bounded, held)
        assert status == 0 and reason == ""
        assert steps > 10 and dropped > 0
        entered.clear()
        ref = convex_qp(H, c, E, e, A_in, b_in, start=start)
        assert steps == len(entered)
        assert np.array_equal(held_out[bounded].astype(bool), ref[3])
        assert np.abs(x - ref[0]).max() <= rounding * np.abs(ref[0]).max()
        assert kuhn_tucker_error(H, c, E, e, A_in, b_in, x, mu, u[bounded]) < 1e-10


def test_a_start_that_leaves_the_equalities_dependent_is_mended():
    """20 equalities and 10 unbounded variables, c > 0: the guess (the bounds with c_i > 0
    held, no sweep) holds every bound and leaves the equalities dependent on the free
    variables. bound_qp frees bounds to span them and ends at the cold QR method's point
    with its working set, without a fallback."""
    n = 300
    H, c, E, e, rng = contact_like(800, n, 20)
    c = np.abs(c)
    bounded = np.sort(rng.choice(n, n - 10, replace=False))
    answer = bound_qp(H, c, E, e, bounded, max_sweeps=0)
    assert answer.dual_steps and answer.fallback == ""
    cold = convex_qp(H, c, E, e, *bounds_of(n, bounded))
    assert np.array_equal(answer.held, cold[3])
    assert kuhn_tucker_error(H, c, E, e, *bounds_of(n, bounded), answer.x, answer.u_eq, answer.u_bound) < 1e-10


def test_bound_qp_takes_the_updated_factor_and_records_no_fallback():
    """Two sweeps (fewer than the problem needs): the dual method finishes from the sweeps'
    guess through the updated factor, with no fallback, at the cold QR method's point."""
    n = 400
    H, c, E, e, _ = contact_like(600, n, 6)
    bounded = np.arange(n)
    answer = bound_qp(H, c, E, e, bounded, max_sweeps=2)
    assert answer.dual_steps and answer.fallback == ""
    cold = convex_qp(H, c, E, e, *bounds_of(n, bounded))
    assert np.array_equal(answer.held, cold[3])
    assert kuhn_tucker_error(H, c, E, e, *bounds_of(n, bounded), answer.x, answer.u_eq, answer.u_bound) < 1e-10


def test_a_failure_of_the_updated_factor_is_recorded_and_the_qr_method_answers(monkeypatch):
    """When rounding stops the updated factor (here forced), bound_qp answers by the QR
    method from the same start and says why in ``fallback``."""
    n = 200
    H, c, E, e, _ = contact_like(700, n, 3)
    monkeypatch.setattr(qp_module._ext, "BoundDualActiveSet",
                        lambda *a: (None, None, None, None, 0, 0, 2, "H lost definiteness to rounding"))
    answer = bound_qp(H, c, E, e, np.arange(n), max_sweeps=1)
    assert answer.dual_steps and "H lost definiteness to rounding" in answer.fallback
    cold = convex_qp(H, c, E, e, *bounds_of(n, np.arange(n)))
    assert np.array_equal(answer.held, cold[3])


def test_an_answer_that_is_not_finite_is_a_recorded_fallback(monkeypatch):
    """A solved status with a NaN in x is no answer: bound_qp falls back to the QR method
    and says so, instead of returning the NaN."""
    n = 200
    H, c, E, e, _ = contact_like(900, n, 3)
    solve = qp_module._ext.BoundDualActiveSet

    def with_nan(*args):
        x, mu, u, held, entered, dropped, status, reason = solve(*args)
        x[0] = np.nan
        return x, mu, u, held, entered, dropped, status, reason

    monkeypatch.setattr(qp_module._ext, "BoundDualActiveSet", with_nan)
    answer = bound_qp(H, c, E, e, np.arange(n), max_sweeps=1)
    assert "not finite" in answer.fallback and np.all(np.isfinite(answer.x))
    cold = convex_qp(H, c, E, e, *bounds_of(n, np.arange(n)))
    assert np.array_equal(answer.held, cold[3])


def test_bounds_that_contradict_the_equalities_are_infeasible():
    """x_i <= 0 for all i and x_0 + x_1 + x_2 = 1 have no common point."""
    H = np.diag([1.0, 2.0, 3.0]) + 0.1
    with pytest.raises(Infeasible):
        bound_qp(H, np.array([1.0, -1.0, 0.5]), np.ones((1, 3)), np.ones(1), np.arange(3), max_sweeps=1)


def test_the_binding_names_a_wrong_shape():
    n = 4
    H = np.eye(n)
    args = dict(H=H, c=np.zeros(n), E=np.zeros((1, n)), e=np.zeros(1), bounded=np.ones(n, np.int8),
                norm=np.ones(n), extra=np.zeros(n), held=np.zeros(n, np.int8), L0=np.eye(n), tol=1e-12, data=1.0,
                growth_limit=1e8, max_steps=100)
    with pytest.raises(ValueError, match="L0 must be f x f"):
        ext.BoundDualActiveSet(**{**args, "L0": np.eye(n - 1)})
    with pytest.raises(ValueError, match="extra and held must have length n"):
        ext.BoundDualActiveSet(**{**args, "extra": np.zeros(n - 1)})
    with pytest.raises(ValueError, match="held variable is not bounded"):
        ext.BoundDualActiveSet(**{**args, "bounded": np.zeros(n, np.int8), "held": np.ones(n, np.int8),
                                  "L0": np.zeros((0, 0))})


def test_sweeps_stop_once_the_dual_steps_are_cheaper():
    """An M-matrix problem whose sweeps converge by themselves (tests/test_qp.py): with
    ``stop_early`` they stop once fewer bounds are violated than a third of the free
    variables, and the dual method ends at the same Kuhn-Tucker point with the same held
    bounds as the sweeps alone."""
    n = 800
    H = 2.1 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    c = np.sin(np.linspace(0.0, 25.0, n)) + 0.2
    bounded, none = np.arange(n), np.zeros((0, n))
    alone = bound_qp(H, c, none, np.zeros(0), bounded, max_sweeps=n + 1, stop_early=False)
    early = bound_qp(H, c, none, np.zeros(0), bounded, max_sweeps=n + 1)
    assert not alone.dual_steps and early.dual_steps and early.sweeps < alone.sweeps
    assert early.fallback == ""
    assert np.array_equal(early.held, alone.held)
    assert np.abs(early.x - alone.x).max() <= 1e-12 * np.abs(alone.x).max()


@pytest.mark.parametrize("seed,p", [(1, 0), (2, 6)])
def test_the_dual_method_starts_from_the_last_sweeps_factor(seed, p, monkeypatch):
    """Where the dual method starts from the bounds the last primal-dual sweep held, it
    takes that sweep's factorisation of the free block instead of factorising it again:
    the same answer to the last bit as with a fresh factorisation, one Cholesky
    factorisation of a free block fewer."""
    H, c, E, e, _ = contact_like(seed, 300, p)
    bounded = np.arange(300)

    def solve(reuse):
        fresh = []
        sweeps = qp_module._primal_dual_sweeps

        def sweeps_keeping(*args):
            solved, starts, count, factored = sweeps(*args)
            return solved, starts, count, factored if reuse else None

        monkeypatch.setattr(qp_module, "_primal_dual_sweeps", sweeps_keeping)
        cholesky, metric, in_metric = qp_module.sla.cholesky, qp_module._start_metric, []

        def start_metric(*args):         # its Cholesky factor is of the held variables' block
            in_metric.append(1)
            try:
                return metric(*args)
            finally:
                in_metric.pop()

        monkeypatch.setattr(qp_module, "_start_metric", start_metric)
        monkeypatch.setattr(qp_module.sla, "cholesky",
                            lambda a, **k: (None if in_metric else fresh.append(a.shape[0])) or cholesky(a, **k))
        answer = bound_qp(H, c, E, e, bounded)
        monkeypatch.undo()
        return answer, [size for size in fresh if size < len(c)]

    reused, free_blocks_reused = solve(True)
    fresh, free_blocks_fresh = solve(False)
    assert reused.dual_steps and fresh.dual_steps
    assert free_blocks_reused == [] and len(free_blocks_fresh) == 1
    assert np.array_equal(reused.x, fresh.x) and np.array_equal(reused.held, fresh.held)
    assert np.array_equal(reused.u_eq, fresh.u_eq)
