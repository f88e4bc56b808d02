"""Small dense strictly convex quadratic programs, solved exactly in finitely many steps.

    minimise 1/2 x^T H x - c^T x   subject to   A_eq x = b_eq,   A_in x >= b_in

by the dual active-set method of Goldfarb and Idnani (Math. Programming 27, 1983). It
starts at the unconstrained minimiser and adds one violated constraint at a time; every
step raises the dual objective, so no working set repeats and the method ends after
finitely many steps (unlike the primal-dual active set, which can cycle when the
constraint response is not an M-matrix). No feasible start is needed.

Used by the contact solver for the linear complementarity problem of one linearisation
(:meth:`ngfracture.linalg.kkt.ConstrainedSolver.solve_unilateral`): a few hundred unknowns. The
QR factorisation of the working set is updated by Givens rotations when a constraint
enters or leaves (scipy.linalg.qr_insert / qr_delete), O(n k) per step for k active
constraints, instead of a factorisation per step (docs/solvers.md, "The contact QP").
"""
import numpy as np
import scipy.linalg as sla

__all__ = ["QPError", "Infeasible", "convex_qp", "GROWTH_LIMIT"]

#: the iterate's size in the metric of H may exceed the data's (the unconstrained minimiser's
#: and the constraints' offsets) by this factor at most: beyond it rounding in a nearly
#: singular H drives the dual steps, and the loop's stopping level (relative to the iterate)
#: would accept any miss (measured: an H of condition 2e11 reached 1e157)
GROWTH_LIMIT = 1e8


class QPError(ValueError):
    """No solution of the QP was found."""


class Infeasible(QPError):
    """The constraints of the QP have no common point."""


def convex_qp(H, c, A_eq, b_eq, A_in, b_in, tol=1e-12, max_steps=None):
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
        A constraint counts as violated when it misses by more than tol times the largest
        of |c|, |b| and |x| in the metric of H (a relative rounding threshold).
    max_steps : int, optional
        Safety stop (default 10 (n + p + q) + 100).

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
        If max_steps did not suffice (rounding; the method is finite in exact arithmetic),
        or the iterate grew beyond GROWTH_LIMIT times the data (a nearly singular H).
    """
    H = np.asarray(H, dtype=float)
    n = H.shape[0]
    A = np.vstack([np.asarray(A_eq, dtype=float).reshape(-1, n), np.asarray(A_in, dtype=float).reshape(-1, n)])
    b = np.concatenate([np.asarray(b_eq, dtype=float).ravel(), np.asarray(b_in, dtype=float).ravel()])
    p = len(b) - len(np.asarray(b_in).ravel())
    L = sla.cholesky(H, lower=True)
    x = sla.cho_solve((L, True), c)
    # in the metric of H: constraint j is the vector L^-1 a_j, the step z = L^-T w
    N = sla.solve_triangular(L, A.T, lower=True)
    norm = np.maximum(np.linalg.norm(N, axis=0), 1e-300)
    sign = np.ones(len(b))              # equalities are entered from the side they miss
    active, u = [], []
    Q, R = np.zeros((n, 0)), np.zeros((0, 0))   # thin QR of the active columns sign_j N[:, j]
    # the data's size in the metric of H (the unconstrained minimiser's, the constraints' offsets)
    data = max(np.abs(b / norm).max(initial=0.0), np.linalg.norm(sla.solve_triangular(L, c, lower=True)))
    size = np.linalg.norm(L.T @ x)      # the iterate's
    max_steps = 10 * (n + len(b)) + 100 if max_steps is None else max_steps
    for _ in range(max_steps):
        s = (A @ x - b) / norm          # signed misses, scaled to the metric of H
        level = tol * max(data, size, 1e-300)
        todo = [j for j in range(p) if j not in active]
        if todo:
            j_new = todo[0]
            sign[j_new] = -1.0 if s[j_new] > 0 else 1.0
        else:
            miss = np.where(np.isin(np.arange(len(b)), active), np.inf, s)
            miss[:p] = np.inf
            j_new = int(np.argmin(miss)) if len(miss) else -1
            if j_new < 0 or miss[j_new] >= -level:
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


def _enter(j_new, n_new, miss_new, x, u, active, Q, R, L, p):
    """Dual steps until constraint ``j_new`` (its vector n_new in the metric of H, its miss)
    enters the working set, dropping the inequalities whose multipliers reach zero on the
    way. ``active`` is changed in place; returns the new (x, u, Q, R).

    Raises Infeasible if the constraint cannot hold together with the working set."""
    u_new = 0.0
    while True:
        if active:
            projection = Q.T @ n_new
            r = sla.solve_triangular(R, projection)
            w = n_new - Q @ projection
        else:
            r, w = np.zeros(0), n_new
        # the largest dual step before an active inequality's multiplier reaches zero
        t_dual, k_drop = np.inf, -1
        for k, (j, uk, rk) in enumerate(zip(active, u, r)):
            if j >= p and rk > 0 and uk / rk < t_dual:
                t_dual, k_drop = uk / rk, k
        ww = float(w @ w)
        t_full = -miss_new / ww if ww > (1e-14 * np.linalg.norm(n_new)) ** 2 else np.inf
        t = min(t_dual, t_full)
        if not np.isfinite(t):
            raise Infeasible(f"constraint {j_new} cannot hold together with the working set")
        if np.isfinite(t_full):
            x = x + t * sla.solve_triangular(L.T, w, lower=False)
            miss_new += t * ww
        u = [uk - t * rk for uk, rk in zip(u, r)]
        u_new += t
        if t == t_full:
            Q, R = _append_column(Q, R, n_new)
            active.append(j_new)
            u.append(u_new)
            return x, u, Q, R
        Q, R = sla.qr_delete(Q, R, k_drop, 1, which="col", check_finite=False)
        del active[k_drop], u[k_drop]


def _append_column(Q, R, column):
    """The thin QR factorisation of [Q R, column] (column independent of Q's span)."""
    if Q.shape[1] == 0:
        size = np.linalg.norm(column)
        return (column / size)[:, None], np.array([[size]])
    return sla.qr_insert(Q, R, column, Q.shape[1], which="col", check_finite=False)
