"""The solves that are skipped must not cost accuracy.

Three economies of the Newton and contact solves, each checked against the tolerance it
claims to meet:

* the contraction stop: modified Newton stops when the error estimate of its iterate,
  rho / (1 - rho) |du^(k)|, is below tol |du^(0)| (the iterate is as accurate as eq. 7
  promises, one increment earlier);
* the increment scale: a solve that corrects another one (a contact round) measures its
  increments against the corrected step's first increment;
* the warm start: a contact solve starts from the active rows of the solve before.
"""
import numpy as np
import pytest

import ngfracture as nf
from ngfracture.contact.solver import ContactSolver
from ngfracture.mechanics.newton import NewtonSolver, rewinder

from conftest import square_mesh
from test_contact_solve import pressed_blocks


def stretched(stretch=0.1):
    prob = nf.ElasticProblem(square_mesh(0.2), nf.StVenantKirchhoff(E=1.0, nu=0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (stretch, 0.2 * stretch))
    return prob


def exact(stretch=0.1):
    """The same problem solved by full Newton to rounding."""
    prob = stretched(stretch)
    assert prob.solve(method="full", tol=1e-14).converged
    return prob.u.vec.FV().NumPy().copy()


def test_a_rewound_problem_solves_again_to_the_same_bits():
    """A retry starts where the failed solve started: the displacement and the load factor."""
    prob = stretched()
    prob.load_factor.Set(0.25)
    start = prob.u.vec.FV().NumPy().copy()
    rewind = rewinder(prob)
    assert prob.solve(method="full", tol=1e-12).converged
    first = prob.u.vec.FV().NumPy().copy()
    assert prob.load_factor.Get() == 1.0 and np.abs(first - start).max() > 1e-3
    rewind()
    assert prob.load_factor.Get() == 0.25 and np.array_equal(prob.u.vec.FV().NumPy(), start)
    assert prob.solve(method="full", tol=1e-12).converged
    assert np.array_equal(prob.u.vec.FV().NumPy(), first)


@pytest.mark.parametrize("tol", [1e-4, 1e-6, 1e-8])
def test_contraction_stop_meets_the_tolerance(tol):
    u_ref = exact()
    prob = stretched()
    status = prob.solve(method="modified", tol=tol)
    assert status.converged, status.message
    error = np.linalg.norm(prob.u.vec.FV().NumPy() - u_ref)
    # the tolerance of eq. 7: the iterate is within tol of the first increment
    assert error <= tol * status.first_increment, (error, status.increment_history)


def test_contraction_stop_saves_the_increment_eq7_waits_for():
    """Stretch 0.1 contracts by about 0.06 per iteration: the last increment above tol is
    followed by one about 16 times smaller, which the estimate foresees."""
    tol = 1e-8
    prob = stretched()
    hist = prob.solve(method="modified", tol=tol).increment_history
    rho = hist[-1] / hist[-2]
    if hist[-1] >= tol:
        # stopped by the estimate: it must have been below the tolerance
        assert rho / (1 - rho) * hist[-1] < tol
    # without the estimate (tol on the increment alone) one more iteration: the count it
    # saves is at most one, and eq. 7 alone never stops earlier
    plain = eq7_iterations(hist, tol)
    assert len(hist) in (plain, plain - 1)


def eq7_iterations(hist, tol):
    """Iterations eq. 7 alone needs, extrapolating the contraction beyond the recorded ones."""
    h = list(hist)
    while h[-1] >= tol:
        h.append(h[-1] * h[-1] / h[-2])
    return next(i for i, x in enumerate(h) if x < tol) + 1


def test_increment_scale_judges_a_correction_against_the_step():
    """A correction from a nearly converged state: against its own first increment it would
    iterate to rounding; against the step's first increment it stops as soon as it is
    within tol of the step, and the result is as accurate."""
    u_ref = exact()
    step = stretched()
    status = step.solve(method="modified", tol=1e-3)       # a rough solve to correct
    scale = status.first_increment
    tol = 1e-6
    plain, scaled = stretched(), stretched()
    for prob in (plain, scaled):
        prob.u.vec.FV().NumPy()[:] = step.u.vec.FV().NumPy()
    a = plain.solve(method="modified", tol=tol)
    b = scaled.solve(method="modified", tol=tol, increment_scale=scale)
    assert a.converged and b.converged
    assert b.iterations < a.iterations
    for prob in (plain, scaled):
        assert np.linalg.norm(prob.u.vec.FV().NumPy() - u_ref) <= tol * scale


@pytest.mark.parametrize("bad", [-1.0, np.nan, np.inf])
def test_bad_increment_scale_is_refused(bad):
    with pytest.raises(ValueError, match="increment_scale"):
        NewtonSolver(stretched(), increment_scale=bad)


def counting_solves(prob):
    """Count the Newton solves of one problem (wraps its solve method)."""
    calls = []
    solve = prob.solve

    def counted(**options):
        calls.append(options)
        return solve(**options)
    prob.solve = counted
    return calls


def test_warm_contact_solve_reaches_the_cold_solution_with_fewer_solves():
    d, h = 1e-3, 0.2
    mesh, cold = pressed_blocks(d)
    cold_solves = counting_solves(cold)
    first = ContactSolver(cold, tol=0.1 * h).solve()
    assert first.converged and first.active_keys
    _, warm = pressed_blocks(d)
    warm_solves = counting_solves(warm)
    again = ContactSolver(warm, tol=0.1 * h).solve(warm=first.active_keys)
    assert again.converged, again.reason
    assert again.active_keys == first.active_keys
    u_cold, u_warm = cold.u.vec.FV().NumPy(), warm.u.vec.FV().NumPy()
    # the same KKT solution (a linear model: to rounding)
    assert np.linalg.norm(u_warm - u_cold) <= 1e-12 * np.linalg.norm(u_cold)
    assert np.allclose(again.multipliers, first.multipliers, rtol=1e-10, atol=1e-14 * d)
    # no prediction without rows: the solve with the right rows is the only one
    assert len(cold_solves) == 2 and len(warm_solves) == 1


def test_warm_rows_that_pull_are_released():
    """Warm rows from a pressed state on blocks pulled apart: they pull, and go."""
    d = 1e-3
    _, pressed = pressed_blocks(d)
    keys = ContactSolver(pressed, tol=0.02).solve().active_keys
    mesh, prob = pressed_blocks(d)
    prob.constraints.dirichlet.pop(1)
    prob.add_dirichlet("upper_bottom", +d, component="y")
    result = ContactSolver(prob, tol=0.02).solve(warm=keys)
    assert result.converged, result.reason
    assert np.abs(result.multipliers).max(initial=0.0) < 1e-12 * d
    assert result.released > 0
    # the blocks separate: the upper one moved up by d, no row presses, no overlap
    uy = prob.u.vec.FV().NumPy()[prob.fes.ndof // 2: prob.fes.ndof // 2 + mesh.nv]
    top = mesh.ngmesh.Coordinates()[:, 1] > 1.0
    assert np.allclose(uy[top], d, rtol=1e-10)


def test_unknown_warm_keys_are_ignored():
    d = 1e-3
    _, cold = pressed_blocks(d)
    first = ContactSolver(cold, tol=0.02).solve()
    _, prob = pressed_blocks(d)
    result = ContactSolver(prob, tol=0.02).solve(warm=[("n", 10 ** 6, 0, 1), ("s", 0, 10 ** 6, -1)])
    assert result.converged and result.active_keys == first.active_keys
    assert np.linalg.norm(prob.u.vec.FV().NumPy() - cold.u.vec.FV().NumPy()) \
        <= 1e-12 * np.linalg.norm(cold.u.vec.FV().NumPy())
