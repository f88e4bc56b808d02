"""Small dense strictly convex quadratic programs, solved exactly in finitely many steps.

    minimise 1/2 x^T H x - c^T x   subject to   A_eq x = b_eq,   A_in x >= b_in

by the dual active-set method of Goldfarb and Idnani (Math. Programming 27, 1983). It
starts at the unconstrained minimiser and adds one violated constraint at a time; every
step raises the dual objective, so no working set repeats and the method ends after
finitely many steps (unlike the primal-dual active set, which can cycle when the
constraint response is not an M-matrix). No feasible start is needed.

Used by the contact solver for the linear complementarity problem of one linearisation
(:meth:`ngfracture.linalg.kkt.ConstrainedSolver.solve_unilateral`), through
:func:`bound_qp`: hundreds of unknowns in 2D, thousands in 3D. The QR factorisation of the
working set is updated by Givens rotations when a constraint enters or leaves
(scipy.linalg.qr_insert / qr_delete), O(n k) per step for k active constraints, instead of
a factorisation per step. :func:`bound_qp` starts the method from a working set guessed by
primal-dual sweeps, so that it takes a few steps instead of one per active bound, and takes
its steps on the sign bounds with the Cholesky factor of the free block updated instead
(C++, O(f^2 + f k) a step for f free and k held variables; convex_qp is its recorded
fallback) (docs/solvers.md, "The contact QP").
"""
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from .. import _ngfracture as _ext

__all__ = ["QPError", "Infeasible", "convex_qp", "bound_qp", "BoundQP", "GROWTH_LIMIT"]

#: the iterate's size in the metric of H may exceed the data's (the unconstrained minimiser's
#: and the constraints' offsets) by this factor at most: beyond it rounding in a nearly
#: singular H drives the dual steps, and the loop's stopping level (relative to the iterate)
#: would accept any miss (measured: an H of condition 2e11 reached 1e157)
GROWTH_LIMIT = 1e8


class QPError(ValueError):
    """No solution of the QP was found."""


class Infeasible(QPError):
    """The constraints of the QP have no common point."""


def convex_qp(H, c, A_eq, b_eq, A_in, b_in, tol=1e-12, max_steps=None, start=None):
    """Goldfarb-Idnani dual active-set method.

    Parameters
    ----------
    H : numpy.ndarray (n, n)
        Symmetric positive definite.
    c : numpy.ndarray (n,)
    A_eq, b_eq : numpy.ndarray (p, n), (p,)
        Equality constraints (linearly independent).
    A_in, b_in : numpy.ndarray (q, n), (q,)
        Inequality constraints A_in x >= b_in.
    tol : float
        A constraint is violated when it misses by more than tol times the largest of |c|,
        |b|, |x| in the metric of H (a relative rounding threshold).
    max_steps : int, optional
        Safety stop (default 10 (n + p + q) + 100).
    start : numpy.ndarray of int, optional
        Inequalities (rows of A_in) to begin the working set with (:func:`_warm_start`):
        from a good guess a few steps instead of one per active inequality.

    Returns
    -------
    x : numpy.ndarray (n,)
    u_eq, u_in : numpy.ndarray (p,), (q,)
        Multipliers: H x - c = A_eq^T u_eq + A_in^T u_in, u_in >= 0, u_in = 0 where the
        inequality is not active.
    active_in : numpy.ndarray of bool (q,)
        The inequalities in the final working set (they hold with equality).

    Raises
    ------
    numpy.linalg.LinAlgError
        If H is not positive definite.
    Infeasible
        If the constraints cannot all hold.
    QPError
        If max_steps did not suffice (rounding: the method is finite in exact arithmetic), the
        iterate grew beyond GROWTH_LIMIT times the data (H nearly singular) or no start.
    """
    H = np.asarray(H, dtype=float)
    n = H.shape[0]
    A, b, p = _stacked(A_eq, b_eq, A_in, b_in, n)
    L = sla.cholesky(H, lower=True)
    x = sla.cho_solve((L, True), c)
    # in the metric of H: constraint j is the vector L^-1 a_j, the step z = L^-T w
    N = sla.solve_triangular(L, A.T, lower=True)
    norm = np.maximum(np.linalg.norm(N, axis=0), 1e-300)
    sign = np.ones(len(b))              # equalities are entered from the side they miss
    x, active, u, Q, R = _warm_start(start, x, A, b, N, L, p)  # Q R: the active columns sign_j N[:, j]
    u = np.asarray(u, dtype=float)
    # the data's size in the metric of H (the unconstrained minimiser's, the constraints' offsets)
    data = max(np.abs(b / norm).max(initial=0.0), np.linalg.norm(sla.solve_triangular(L, c, lower=True)))
    size = np.linalg.norm(L.T @ x)      # the iterate's
    bounds = _bound_rows(A, b, p)
    max_steps = 10 * (n + len(b)) + 100 if max_steps is None else max_steps
    for _ in range(max_steps):
        j_new = _next_constraint(A, b, p, x, norm, active, sign, bounds, tol * max(data, size, 1e-300))
        if j_new < 0:
            break
        x, u, Q, R = _enter(j_new, sign[j_new] * N[:, j_new], sign[j_new] * (A[j_new] @ x - b[j_new]),
                            x, u, active, Q, R, L, p)
        size = np.linalg.norm(L.T @ x) if np.all(np.isfinite(x)) else np.inf
        if not size <= GROWTH_LIMIT * max(data, 1e-300):
            raise QPError(f"convex_qp: the iterate grew to {size:.3g} in the metric of H against data of "
                          f"{data:.3g} (H nearly singular)")
    else:
        raise QPError(f"convex_qp: no solution in {max_steps} steps")
    mult = np.zeros(len(b))
    mult[active] = np.array(u) * sign[active]
    active_in = np.zeros(len(b) - p, dtype=bool)
    active_in[[j - p for j in active if j >= p]] = True
    return x, mult[:p], mult[p:], active_in


def _stacked(A_eq, b_eq, A_in, b_in, n):
    """The constraints as one system A x (=, >=) b, the p equalities first."""
    A = np.vstack([np.asarray(A_eq, dtype=float).reshape(-1, n), np.asarray(A_in, dtype=float).reshape(-1, n)])
    b = np.concatenate([np.asarray(b_eq, dtype=float).ravel(), np.asarray(b_in, dtype=float).ravel()])
    return A, b, len(b) - len(np.asarray(b_in).ravel())


def _enter(j_new, n_new, miss_new, x, u, active, Q, R, L, p):
    """Dual steps until constraint ``j_new`` (its vector n_new in the metric of H, its miss)
    enters the working set, dropping the inequalities whose multipliers reach zero on the
    way. ``active`` is changed in place; ``u`` holds the multipliers of ``active`` (an
    array); returns the new (x, u, Q, R).

    Raises Infeasible if the constraint cannot hold together with the working set."""
    u_new = 0.0
    while True:
        if active:
            projection = Q.T @ n_new
            r = sla.solve_triangular(R, projection, check_finite=False)
            w = n_new - Q @ projection
        else:
            r, w = np.zeros(0), n_new
        # the largest dual step before an active inequality's multiplier reaches zero (the
        # first of equal ratios, as a loop with a strict comparison takes it)
        t_dual, k_drop = np.inf, -1
        droppable = (np.asarray(active, dtype=np.int64) >= p) & (r > 0)
        if droppable.any():
            ratio = np.full(len(r), np.inf)
            ratio[droppable] = u[droppable] / r[droppable]
            ratio[np.isnan(ratio)] = np.inf
            k = int(np.argmin(ratio))
            if ratio[k] < np.inf:
                t_dual, k_drop = float(ratio[k]), k
        ww = float(w @ w)
        t_full = -miss_new / ww if ww > (1e-14 * np.linalg.norm(n_new)) ** 2 else np.inf
        t = min(t_dual, t_full)
        if not np.isfinite(t):
            raise Infeasible(f"constraint {j_new} cannot hold together with the working set")
        if np.isfinite(t_full):
            x = x + t * sla.solve_triangular(L.T, w, lower=False, check_finite=False)
            miss_new += t * ww
        u = u - t * r
        u_new += t
        if t == t_full:
            Q, R = _append_column(Q, R, n_new)
            active.append(j_new)
            return x, np.append(u, u_new), Q, R
        Q, R = sla.qr_delete(Q, R, k_drop, 1, which="col", check_finite=False)
        Q, R = Q[:, :R.shape[1]], R[:R.shape[1]]    # thin again after a full (n columns) set
        del active[k_drop]
        u = np.delete(u, k_drop)


def _next_constraint(A, b, p, x, norm, active, sign, bounds, level):
    """The constraint to enter next: the first equality not in the working set ``active``
    (its ``sign`` set to the side it misses), else the inequality missed most in the
    metric of H, if by more than ``level``; -1 for none (``bounds`` as
    :func:`_bound_rows`)."""
    in_set = np.zeros(len(b), dtype=bool)
    in_set[active] = True
    todo = np.flatnonzero(~in_set[:p])
    if len(todo):
        s = (A @ x - b) / norm          # signed misses, scaled to the metric of H
        j_new = int(todo[0])
        sign[j_new] = -1.0 if s[j_new] > 0 else 1.0
        return j_new
    miss = np.full(len(b), np.inf)
    miss[p:] = _inequality_misses(A, b, p, x, bounds) / norm[p:]
    miss[in_set] = np.inf
    j_new = int(np.argmin(miss)) if len(miss) else -1
    return -1 if j_new < 0 or miss[j_new] >= -level else j_new


def _bound_rows(A, b, p):
    """Where every inequality row of A (after the p equalities) is -e_i with b = 0 (the
    bounds x_i <= 0 of :func:`bound_qp`): the i per row, else None."""
    rows, offsets = A[p:], b[p:]
    if not len(rows) or np.any(offsets != 0.0):
        return None
    at = np.argmin(rows, axis=1)
    picked = rows[np.arange(len(rows)), at]
    if np.any(picked != -1.0) or np.count_nonzero(rows) != len(rows):
        return None
    return at


def _inequality_misses(A, b, p, x, bounds):
    """A_in x - b_in, unscaled. For bound rows (``bounds``, from :func:`_bound_rows`) the
    product is -x_i itself, which the dense product gives exactly (its other terms are
    zeros) for a finite x: O(q) instead of O(q n) a step."""
    if bounds is None or not np.all(np.isfinite(x)):
        return A[p:] @ x - b[p:]
    return -x[bounds] - b[p:]


def _warm_start(start, x, A, b, N, L, p):
    """The minimiser x with the p equalities and the inequalities ``start`` holding, their
    multipliers u >= 0 for the inequalities, and the thin QR of their vectors in the
    metric of H: a start of the dual method (Goldfarb and Idnani's S-pair). Inequalities
    with a negative multiplier or a vector dependent on the earlier ones are dropped and the
    rest solved again. Returns (x, active, u, Q, R); x unchanged and nothing active without
    a start or if the equalities alone are dependent."""
    cold = x, [], [], np.zeros((len(x), 0)), np.zeros((0, 0))
    if start is None or not len(start):
        return cold
    working = list(range(p)) + sorted(p + np.asarray(start, dtype=int).ravel())
    for _ in range(len(working) + 1):
        Q, R = sla.qr(N[:, working], mode="economic", check_finite=False)
        pivot = np.zeros(len(working))     # more vectors than dimensions: the last ones dependent
        pivot[:min(R.shape)] = np.abs(np.diag(R))
        dependent = pivot <= 1e-10 * pivot.max(initial=0.0)
        if dependent[:p].any():
            return cold
        if dependent.any():
            working = [j for j, d in zip(working, dependent) if not d]
            continue
        # v = L^T x moves by N_W lam with N_W^T N_W lam = R^T R lam = b_W - A_W x
        lam = sla.solve_triangular(R, sla.solve_triangular(R, b[working] - A[working] @ x, trans="T"))
        negative = lam[p:] < 0.0
        if not negative.any():
            step = sla.solve_triangular(L.T, N[:, working] @ lam, lower=False, check_finite=False)
            return x + step, list(working), list(lam), Q, R
        working = working[:p] + [j for j, drop in zip(working[p:], negative) if not drop]
    raise QPError("convex_qp: no start from the given working set")


def _append_column(Q, R, column):
    """The thin QR factorisation of [Q R, column] (column independent of Q's span)."""
    if Q.shape[1] == 0:
        size = np.linalg.norm(column)
        return (column / size)[:, None], np.array([[size]])
    return sla.qr_insert(Q, R, column, Q.shape[1], which="col", check_finite=False)


class BoundQP(NamedTuple):
    """The answer of :func:`bound_qp`."""

    x: np.ndarray           #: the minimiser
    u_eq: np.ndarray        #: multipliers of the equalities
    u_bound: np.ndarray     #: multipliers of the bounds: >= 0, and 0 where the bound is not held
    held: np.ndarray        #: bool per bound: x_i held at 0 (the final working set)
    sweeps: int             #: primal-dual sweeps done
    dual_steps: bool        #: the dual active-set method finished the solve
    fallback: str = ""      #: why the updated free-block factor gave way to convex_qp's QR, if it did


def bound_qp(H, c, A_eq, b_eq, bounded, tol=1e-12, max_sweeps=8, stop_early=True, guess=None):
    """minimise 1/2 x^T H x - c^T x  subject to  A_eq x = b_eq,  x_i <= 0 for i in ``bounded``.

    The contact dual has this form (sign bounds on the multipliers, a few equalities for
    the free modes). The dual active-set method (:func:`convex_qp`) adds one bound per step
    from the unconstrained minimiser, each step O(n k): with thousands of candidate rows,
    most of them open at the end, that is thousands of steps (50 s at 2551 multipliers,
    1520 held bounds). Primal-dual active-set sweeps (Hintermüller, Ito, Kunisch, SIAM J.
    Optim. 13, 2003: the minimiser on the free variables, then hold the bounded ones that
    came out positive and free the held ones whose multiplier came out negative) guess the
    working set; a sweep that changes nothing is the solution. These sweeps need not end
    when H is no M-matrix (nearly dependent contact rows cycle), so after ``max_sweeps``,
    or as soon as fewer bounds are violated than a third of the free variables (a sweep's
    factorisation costs about that many dual steps), the dual method starts from the guess
    with the fewest violations: finite, and a few steps from a good guess. Its steps update
    the Cholesky factor of the free block (:func:`_dual_steps_on_bounds`); if rounding
    stops them, :func:`convex_qp` takes the same start and ``fallback`` says why. A guess
    that holds every row of a free piece is mended (:func:`_spanning`); if the dual method
    stops with QPError from the best guess, it starts again from the best guess before the
    first mending.

    Parameters
    ----------
    H : numpy.ndarray (n, n)
        Symmetric positive definite.
    c : numpy.ndarray (n,)
    A_eq, b_eq : numpy.ndarray (p, n), (p,)
        Equality constraints (linearly independent).
    bounded : numpy.ndarray of int
        The variables bounded above by 0.
    tol : float
        For the sweeps: a bound counts as violated when x_i exceeds tol times max |x| (a
        multiplier when it is below -sqrt(n) eps times the largest of |c| and |H x|: to
        rounding, as the dual method keeps them); for the dual method as in
        :func:`convex_qp`.
    max_sweeps : int
    stop_early : bool
        Stop the sweeps as soon as fewer bounds are violated than a third of the free
        variables; False: sweep until a solution or ``max_sweeps``.
    guess : numpy.ndarray of bool, optional
        Per bound (in the order of ``bounded``), whether the first sweep holds it: the
        solution of a problem met before with almost the same data ends in one sweep
        (a contact solve's rounds). Default: the bounds with c_i > 0.

    Returns
    -------
    BoundQP
        ``held`` and ``u_bound`` in the order of ``bounded``.

    Raises
    ------
    numpy.linalg.LinAlgError, Infeasible, QPError
        As :func:`convex_qp`.
    """
    H = np.asarray(H, dtype=float)
    n = H.shape[0]
    c = np.asarray(c, dtype=float)
    E, e = np.asarray(A_eq, dtype=float).reshape(-1, n), np.asarray(b_eq, dtype=float).ravel()
    bounded = np.asarray(bounded, dtype=int).ravel()
    if guess is not None and np.shape(guess) != bounded.shape:
        raise ValueError(f"bound_qp: guess has shape {np.shape(guess)}, bounded {bounded.shape}")
    solved, starts, sweeps, factored = _primal_dual_sweeps(H, c, E, e, bounded, tol, max_sweeps, stop_early, guess)
    if solved is not None:
        return BoundQP(*solved, sweeps, False)
    fallback = ""
    for k, start in enumerate(starts):
        try:
            try:
                x, u_eq, u_in, held = _dual_steps_on_bounds(H, c, E, e, bounded, start, tol, factored)
            except Infeasible:
                raise
            except QPError as err:      # rounding in the updated factor: the QR of the working set
                fallback = f"{fallback}; {err}" if fallback else str(err)
                x, u_eq, u_in, held = convex_qp(H, c, E, e, -np.eye(n)[bounded], np.zeros(len(bounded)),
                                                tol=tol, start=start)
        except QPError:                  # rounding led the steps astray: the other start, if any
            if k == len(starts) - 1:
                raise
            continue
        return BoundQP(x, u_eq, u_in, held, sweeps, True, fallback)


def _dual_steps_on_bounds(H, c, E, e, bounded, start, tol, factored=None):
    """The dual active-set method of :func:`convex_qp` for the bounds of :func:`bound_qp`,
    from the S-pair of ``start`` (positions in ``bounded``), with the Cholesky factor of the
    free block updated as bounds enter and leave (C++, ``BoundDualActiveSet``): O(f^2 + f k)
    a step for f free and k held variables, where the QR of the working set's vectors costs
    O(n k) and a copy of its n x k factor. The same choices as convex_qp (the bound missed
    most in the metric of H, the first of equal ratios), so the same working sets to
    rounding. A start whose held bounds leave the equalities dependent on the free
    variables is mended first (:func:`_spanning`; convex_qp drops the dependent bounds).
    ``factored`` (held, factor): a factorisation of the free block that the primal-dual
    sweeps made (:func:`_minimiser_on`), taken where the start holds the same bounds (the
    same LAPACK factor as a fresh one, to the last bit).
    Returns (x, u_eq, u_bound, held) in the form of BoundQP.

    Raises
    ------
    Infeasible
        If the bounds and the equalities have no common point.
    QPError
        If rounding stops the method (a free block that is no longer positive definite,
        equalities dependent on the free variables of the start, the step limit, growth,
        an answer that is not finite).
    """
    n = len(c)
    is_bound = np.zeros(n, dtype=np.int8)
    is_bound[bounded] = 1
    held = np.zeros(n, dtype=bool)
    held[bounded[np.asarray(start, dtype=int)]] = True
    if len(e):
        held = _spanning(E, held)
    if factored is not None and np.array_equal(factored[0], held):
        L0 = np.tril(factored[1][0])
    else:
        free = np.flatnonzero(~held)
        L0 = sla.cholesky(H[np.ix_(free, free)], lower=True) if len(free) else np.zeros((0, 0))
    norm, extra, data = _start_metric(H, c, E, e, held, L0)
    held = held.astype(np.int8)
    x, u_eq, u, held, _, _, status, reason = _ext.BoundDualActiveSet(
        H, c, E, e, is_bound, norm, extra, held, L0, tol, data, GROWTH_LIMIT, 10 * (n + len(e) + len(bounded)) + 100)
    if status == 1:
        raise Infeasible(f"bound_qp: {reason}")
    if status != 0:
        raise QPError(f"bound_qp: {reason}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(u_eq)) and np.all(np.isfinite(u))):
        raise QPError("bound_qp: the dual steps ended on a value that is not finite")
    return x, u_eq, u[bounded], held[bounded].astype(bool)


def _start_metric(H, c, E, e, held, L0):
    """The metric of the dual steps from the start's factor L0 of H_FF (F: not ``held``).

    A bound's length |L^-1 e_i| in the metric of H = L L^T is sqrt((H^-1)_ii), and the
    data's size |L^-1 c| is sqrt(c^T H^-1 c) (the equalities' offsets alike). By the Schur
    complement S_A = H_AA - H_AF H_FF^-1 H_FA = M M^T of the held variables A (a few
    against thousands of free ones in a contact solve's rounds):

        (H^-1)_ii = |L0^-1 e_i|^2 + |M^-1 (H_AF H_FF^-1)_{:, i}|^2    (i in F),
        (H^-1)_ii = |M^-1 e_i|^2                                     (i in A),
        b^T H^-1 b = |L0^-1 b_F|^2 + |M^-1 (b_A - H_AF H_FF^-1 b_F)|^2,

    which takes triangular solves with |A| columns instead of a factorisation of all of H and
    the inverse of its factor (2 n^3 / 3 flops; 0.5 s at 3000 rows). The first term of a free
    variable's length costs (f - r)^2 / 2 for its position r in F: the C++ dual steps
    compute it for the few bounds they consider (``BoundDualActiveSet``).

    Returns (norm, extra, data): norm the lengths of the held variables (0 for the free
    ones, computed in C++), extra the second term of the free ones' squares (0 for the held).

    Raises
    ------
    numpy.linalg.LinAlgError
        If H is not positive definite (S_A is not).
    """
    n = len(c)
    free, hold = np.flatnonzero(~held), np.flatnonzero(held)
    norm, extra = np.zeros(n), np.zeros(n)
    B = np.column_stack([c, E.T])                     # the data: c and the equalities' rows
    B_F = sla.solve_triangular(L0, B[free], lower=True, check_finite=False) if len(free) else B[free]
    sizes = np.einsum("ij,ij->j", B_F, B_F)
    if len(hold):
        Y = (sla.solve_triangular(L0, H[np.ix_(free, hold)], lower=True, check_finite=False)
             if len(free) else np.zeros((0, len(hold))))                          # L0^-1 H_FA
        M = sla.cholesky(H[np.ix_(hold, hold)] - Y.T @ Y, lower=True, check_finite=False)
        M_inv, info = lapack.dtrtri(M, lower=1)
        if info != 0:
            raise np.linalg.LinAlgError("bound_qp: the Schur complement of the held variables is singular")
        norm[hold] = np.sqrt(np.einsum("ij,ij->j", M_inv, M_inv))
        if len(free):
            X = sla.solve_triangular(L0, Y, lower=True, trans="T", check_finite=False)    # H_FF^-1 H_FA
            Z = X @ M_inv.T
            extra[free] = np.einsum("ij,ij->i", Z, Z)
            A_B = M_inv @ (B[hold] - Y.T @ B_F)
        else:
            A_B = M_inv @ B[hold]
        sizes = sizes + np.einsum("ij,ij->j", A_B, A_B)
    data = np.sqrt(sizes[0])
    if len(e):
        data = max(data, np.max(np.abs(e) / np.maximum(np.sqrt(sizes[1:]), 1e-300)))
    return norm, extra, data


def _primal_dual_sweeps(H, c, E, e, bounded, tol, max_sweeps, stop_early, guess=None):
    """Primal-dual active-set sweeps for :func:`bound_qp`, from the bounds ``guess`` holds,
    or without one from the bounds with c_i > 0 held (the sign of the unconstrained
    minimiser for a diagonal H).

    A guess whose equalities are dependent on its free variables (its held bounds take
    every row of a free piece) is mended by :func:`_spanning` and the sweeps go on. They
    stop after ``max_sweeps`` or, with ``stop_early``, when fewer bounds are violated than
    a third of the free variables.

    Returns (solution, guesses, sweeps, factored): solution (x, u_eq, u_bound, held) if a
    sweep changed nothing, else None and guesses, each the positions in ``bounded`` held in
    a sweep with the fewest violations: the one of all sweeps first, then, if a guess was
    mended, the one before the first mending (the dual method's start without mending);
    factored: the held bounds of the last sweep and its factorisation of the free block."""
    n = len(c)
    is_bound = np.zeros(n, dtype=bool)
    is_bound[bounded] = True
    if guess is None:
        held = is_bound & (c > 0)
    else:
        held = np.zeros(n, dtype=bool)
        held[bounded[np.asarray(guess, dtype=bool)]] = True
    best, fewest, sweep, unmended, factored = held, np.inf, 0, None, None
    for sweep in range(1, max_sweeps + 1):
        x, u_eq, factor = _minimiser_on(H, c, E, e, ~held)
        if x is None:                    # a piece's equalities dependent on the free rows
            unmended = best if unmended is None else unmended
            held = _spanning(E, held)
            x, u_eq, factor = _minimiser_on(H, c, E, e, ~held)
        factored = (held, factor)
        if x is None:
            break
        u = np.zeros(n)                  # H x - c = E^T u_eq - u on the held bounds
        u[held] = c[held] + E[:, held].T @ u_eq - H[held] @ x
        # the dual test to rounding only (the dual method keeps u >= 0 exactly): in the
        # nearly singular H of dependent rows a pull of 1e-11 |c| is a force of 1e-2 |x|
        force = max(np.abs(c).max(initial=0.0), np.abs(H @ x).max(initial=0.0), 1e-300)
        rises = ~held & is_bound & (x > tol * max(np.abs(x).max(initial=0.0), 1e-300))
        pulls = held & (u < -np.sqrt(n) * np.finfo(float).eps * force)
        violations = int(rises.sum() + pulls.sum())
        if violations == 0:
            return (x, u_eq, u[bounded], held[bounded]), None, sweep, factored
        if violations < fewest:
            best, fewest = held, violations
        if stop_early and violations < np.count_nonzero(~held) / 3:
            break       # a sweep's factorisation costs about f/3 dual steps: they finish cheaper
        held = (held & ~pulls) | rises
    guesses = [best] + ([unmended] if unmended is not None and not np.array_equal(unmended, best) else [])
    return None, [np.flatnonzero(g[bounded]) for g in guesses], sweep, factored


def _minimiser_on(H, c, E, e, free):
    """The minimiser of 1/2 x^T H x - c^T x on E x = e with x = 0 off ``free``, the
    equalities' multipliers and the factorisation of H on ``free`` (scipy's cho_factor);
    x and the multipliers None if the equalities are dependent on ``free``."""
    x = np.zeros(len(c))
    factor = sla.cho_factor(H[np.ix_(free, free)], lower=True, check_finite=False)
    Ef = E[:, free]
    Z = sla.cho_solve(factor, np.column_stack([c[free], Ef.T]), check_finite=False)
    if not len(e):
        x[free] = Z[:, 0]
        return x, np.zeros(0), factor
    coupling = Ef @ Z[:, 1:]             # E_f H_ff^-1 E_f^T, positive definite iff E_f has full rank
    eig = np.linalg.eigvalsh(coupling)
    if not eig[0] > 1e-12 * max(eig[-1], 1e-300):
        return None, None, factor
    u_eq = np.linalg.solve(coupling, e - Ef @ Z[:, 0])
    x[free] = Z[:, 0] + Z[:, 1:] @ u_eq
    return x, u_eq, factor


def _spanning(E, held):
    """``held`` with the fewest bounds freed that make the equalities E independent on the
    free variables (E full row rank): the held columns that add most to the span of the
    free ones, by a pivoted QR of their parts outside it. A guess whose held bounds
    take every row of a free piece leaves that piece's equalities without a column."""
    free = ~held
    U, s, _ = np.linalg.svd(E[:, free], full_matrices=False)
    rank = int(np.count_nonzero(s > 1e-8 * max(s.max(initial=0.0), 1e-300)))
    candidates = np.flatnonzero(held)
    missing = E.shape[0] - rank
    if missing <= 0 or not len(candidates):
        return held
    outside = E[:, candidates] - U[:, :rank] @ (U[:, :rank].T @ E[:, candidates])
    _, _, order = sla.qr(outside, mode="economic", pivoting=True, check_finite=False)
    held = held.copy()
    held[candidates[order[:missing]]] = False
    return held
