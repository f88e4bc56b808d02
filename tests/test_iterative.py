"""K^+ by CG with AMG (linalg.iterative): the same solutions and multipliers as the direct
factorisation, the same cracks in a 3D run, the automatic choice and its record, and a
singular stiffness reported, never solved.

Tolerances from theory: CG stops at a true relative residual of CG_RTOL = 1e-12, so its
solution's relative error is at most cond(K_ff) * 1e-12 (the direct solve's is
cond(K_ff) * eps, negligible beside it); cond(K_ff) is computed densely on the small mesh.
The KKT solve refines both to a residual of 1e-13 of its scale, so the two KKT solutions
differ by at most cond * 2e-13 in the displacements and, through the Schur complement,
in the multipliers (cond(S) <= cond(K_ff) * cond(C C^T), 1 here: one row).
"""
import numpy as np
import pytest
import scipy.sparse as sp

import ngfracture as nf
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.linalg import iterative
from ngfracture.linalg.factor import EliminatedFactor, SingularSystem
from ngfracture.linalg.iterative import CG_RTOL, AMGFactor, choose_inverse, cholesky_bytes, make_factor
from ngfracture.linalg.kkt import ConstrainedSolver
from ngfracture.mechanics.materials import StVenantKirchhoff


def _box(k=3):
    arrays = box_mesh(np.linspace(0, 4, 4 * k + 1), np.linspace(0, 1, k + 1), np.linspace(0, 1, k + 1))
    return nf.ElasticProblem(solid_mesh(arrays), StVenantKirchhoff(5e9, 0.18))


def _held_box():
    """Clamped at x = 0, gliding (u_x given) at x = 4, and one general row tying u_y of two
    far corners."""
    prob = _box()
    prob.add_dirichlet("xmin", 0.0)
    prob.add_dirichlet("xmax", 1e-3, component="x")
    rows = prob.assemble_constraints()
    n = prob.fes.ndof // 3
    P = prob.arrays.points
    a, b = (int(np.argmin(np.linalg.norm(P - q, axis=1))) for q in ([4, 1, 1], [2, 0, 1]))
    C = sp.csr_matrix(([1.0, -1.0], ([0, 0], [n + a, n + b])), shape=(1, prob.fes.ndof))
    return prob, rows, C


def _condition(K, keep):
    w = np.linalg.eigvalsh(K[keep][:, keep].toarray())
    return w[-1] / w[0]


def test_cg_solve_and_multipliers_agree_with_the_direct_solve():
    prob, rows, C = _held_box()
    K = prob.tangent()
    direct = EliminatedFactor(K, rows.fixed_dofs, None, inverse="sparsecholesky")
    amg = AMGFactor(K, rows.fixed_dofs, None, prob.arrays.points)
    cond = _condition(direct.K, direct.factor_free)
    assert 1e2 < cond < 1e5          # the bound below is then meaningful and not trivial
    b = np.random.default_rng(1).standard_normal(prob.fes.ndof)
    x, y = amg.solve(b), direct.solve(b)
    error = np.linalg.norm(x - y) / np.linalg.norm(y)
    assert error <= cond * CG_RTOL, (error, cond)
    assert 0 < amg.iterations[-1] <= 40
    residual = np.linalg.norm((amg.K @ x - b)[amg.factor_free]) / np.linalg.norm(b[amg.factor_free])
    assert residual <= CG_RTOL
    # the KKT solve: Dirichlet + gliding eliminated, the tie as a multiplier row
    r = np.zeros(prob.fes.ndof)
    du_fixed = np.zeros(prob.fes.ndof)
    du_fixed[rows.fixed_dofs] = rows.fixed_values
    h = np.array([2e-5])
    du_a, lam_a = ConstrainedSolver(None, rows.fixed_dofs, C, factor=amg).solve(r, du_fixed, h)
    du_d, lam_d = ConstrainedSolver(None, rows.fixed_dofs, C, factor=direct).solve(r, du_fixed, h)
    assert np.linalg.norm(du_a - du_d) <= cond * 2e-13 * np.linalg.norm(du_d)
    assert abs(lam_a[0] - lam_d[0]) <= cond * 2e-13 * abs(lam_d[0])
    assert abs((C @ du_a)[0] - h[0]) <= 1e-13 * np.abs(C).sum(axis=1).max() * np.abs(du_a).max() + 1e-13 * abs(h[0])


def test_a_singular_stiffness_raises_naming_iterations_and_residual():
    prob = _box(2)
    prob.add_dirichlet("xmin", 0.0, component="x")     # y, z translations and the x rotation free
    rows = prob.assemble_constraints()
    amg = AMGFactor(prob.tangent(), rows.fixed_dofs, None, prob.arrays.points, maxiter=150)
    b = np.random.default_rng(2).standard_normal(prob.fes.ndof)
    with pytest.raises(SingularSystem, match=r"\d+ iterations, relative residual \d\.\d+e[-+]\d+"):
        amg.solve(b)


def test_the_choice_follows_the_memory_budget():
    n = 100000
    assert choose_inverse("auto", 2, n) == ("auto", {"solver": "auto", "reason": "asked", "dofs": n})
    assert choose_inverse("amg", 3, n)[0] == "amg"
    inverse, record = choose_inverse("auto", 3, n, budget=0.5 * cholesky_bytes(n))
    assert inverse == "amg" and record["reason"] == "auto"
    assert record["predicted_bytes"] == cholesky_bytes(n) > record["budget_bytes"]
    assert choose_inverse("auto", 3, n, budget=2 * cholesky_bytes(n))[0] == "sparsecholesky"
    prob, rows, _ = _held_box()
    assert isinstance(make_factor(prob.tangent(), rows.fixed_dofs, None, dim=3, points=prob.arrays.points,
                                  budget=1.0), AMGFactor)
    with pytest.raises(ValueError, match="points"):
        make_factor(prob.tangent(), rows.fixed_dofs, None, inverse="amg", dim=3)


def _bar_run(monkeypatch=None, **control):
    scene = nf.scenes.bar3d(maxh=0.4, radius=0.2, thickness=0.25)
    return nf.Simulation(scene, nf.StepControl(**control)).run()


def test_a_3d_run_on_the_iterative_solver_cracks_as_the_direct_one(monkeypatch):
    direct = _bar_run()
    monkeypatch.setattr(iterative, "MEMORY_BUDGET", 1e-12)     # below any prediction: "auto" takes amg
    amg = _bar_run()
    record = amg.summary["timings"]["linear_solver"]
    assert set(record) == {"amg"} and record["amg"]["last"]["reason"] == "auto"
    assert record["amg"]["last"]["predicted_bytes"] > record["amg"]["last"]["budget_bytes"]
    assert set(direct.summary["timings"]["linear_solver"]) == {"sparsecholesky"}
    assert amg.reason == direct.reason == "broken"
    for key in ("n_steps", "n_split_vertices", "n_fragments"):
        assert amg.summary[key] == direct.summary[key], key
    assert [h["split_vertices"] for h in amg.state.history] == [h["split_vertices"] for h in direct.state.history]
    assert np.array_equal(amg.state.arrays.tets, direct.state.arrays.tets)
