"""What the tests of bordered factors in 2D and 3D share: a random constrained solve
checked for a backward error of rounding size."""
import numpy as np


def check_random_solve(solver, fixed_dofs, seed):
    """Solve a random system [K~ B^T; B 0] with ``solver`` (a ConstrainedSolver) and assert
    a backward error of rounding size: 1e-12 of |K~| |du| + |B^T| |lam| + |r| on the free
    dofs, row by row 1e-12 of |B| |du| + |h|, and the fixed dofs' values exactly.

    Parameters
    ----------
    solver : ngfracture.linalg.kkt.ConstrainedSolver
    fixed_dofs : array_like of int
    seed : int
        Of the random right-hand side (r on the free dofs, 1e-6 scaled values on the fixed
        dofs and the rows, drawn in that order).

    Returns
    -------
    r, du_fixed, h, du, lam : numpy.ndarray
        The right-hand side and the solution.
    """
    rng = np.random.default_rng(seed)
    K, ndof, free = solver.factor.K, solver.ndof, solver.free
    fixed = np.asarray(fixed_dofs)
    r = np.where(free, rng.standard_normal(ndof), 0.0)
    du_fixed = np.zeros(ndof)
    du_fixed[fixed] = 1e-6 * rng.standard_normal(len(fixed))
    h = 1e-6 * rng.standard_normal(solver.m)
    du, lam = solver.solve(r, du_fixed, h)
    force = (K @ du + solver.C.T @ lam - r)[free]
    force_scale = (abs(K) @ np.abs(du) + abs(solver.C.T) @ np.abs(lam) + np.abs(r))[free]
    assert np.linalg.norm(force) <= 1e-12 * np.linalg.norm(force_scale)
    assert np.array_equal(du[~free], du_fixed[~free])
    rows = solver.C @ du - h
    assert np.all(np.abs(rows) <= 1e-12 * (abs(solver.C) @ np.abs(du) + np.abs(h)))
    return r, du_fixed, h, du, lam
