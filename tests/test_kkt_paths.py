"""The constrained solve (kkt.ConstrainedSolver) against a direct solve of the whole KKT system.

The solver eliminates the fixed dofs and solves the general rows either through the
factorised augmented matrix (the default for the direct solvers) or through the Schur
complement with pins and corrected rigid modes (kept for the contact complementarity
problem). Both must give the solution of

    [ K  B^T ] [du ]   [r]
    [ B  0   ] [lam] = [b]      B = [unit rows of the fixed dofs; C],

assembled whole and handed to a sparse LU, to 1e-10 relative, on cracked plates in
contact: four fragments pressed against each other across the seams, and the small
fragments at the crack junction held by contact alone (free rigid modes: pins, and a
tangent that does not vanish on their rotation under finite strain), or by contact and
rows holding their modes.
"""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import ngfracture as nf
from ngfracture.contact.solver import ContactSolver
from ngfracture.linalg import factor as factor_module, kkt as kkt_module, sparse_schur as sparse_schur_module
from ngfracture.linalg.factor import SingularSystem
from ngfracture.linalg.kkt import ConstrainedSolver
from ngfracture.linalg.sparse import to_scipy
from ngfracture.mechanics.newton import NewtonSolver

from test_contact_fractured import crack_bands, plate_mesh

H = 0.1


def cross_cracked_pressed():
    """Two crossing cracks, four fragments pressed together from all sides (finite strain)."""
    res = crack_bands(plate_mesh(H), [(0, 1.0), (1, 0.5)], 0.6 * H)
    prob = nf.ElasticProblem(res.mesh, nf.StVenantKirchhoff(1.0, 0.3, plane="stress"))
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", -1e-3, component="x")
    prob.add_dirichlet("bottom", 0.0, component="y")
    prob.add_dirichlet("top", -1e-3, component="y")
    return prob, dict(fix_free_modes=False)


def cross_cracked_held():
    """The same, with every free rigid mode of the small fragments at the junction held by a row."""
    prob, _ = cross_cracked_pressed()
    return prob, dict(fix_free_modes="all")


@pytest.fixture(scope="module", params=[cross_cracked_pressed, cross_cracked_held], ids=["cross", "cross_held"])
def contact_state(request):
    """A converged contact solve: the problem, its assembled rows (holds included) and support."""
    prob, options = request.param()
    result = ContactSolver(prob, tol=0.1 * H, **options).solve()
    assert result.converged, result.reason
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    if options["fix_free_modes"]:
        rows = NewtonSolver(prob, fix_free_modes=options["fix_free_modes"])._hold_free_modes(rows, support)
    return prob, rows, support, result


def random_kkt_load(ndof, rows, seed):
    """A random right-hand side of the eliminated KKT system: (r, du_fixed, h), zero force at
    the fixed dofs."""
    free = np.ones(ndof, dtype=bool)
    free[rows.fixed_dofs] = False
    rng = np.random.default_rng(seed)
    r = np.where(free, rng.standard_normal(ndof), 0.0)
    du_fixed = np.zeros(ndof)
    du_fixed[rows.fixed_dofs] = 1e-3 * rng.standard_normal(rows.fixed_dofs.size)
    h = 1e-3 * rng.standard_normal(rows.C.shape[0])
    return r, du_fixed, h


def whole_kkt_solution(K, rows, r, du_fixed, h):
    """du and the multipliers of the general rows from one sparse LU of the whole system."""
    ndof, nfix = K.shape[0], rows.fixed_dofs.size
    E = sp.csr_matrix((np.ones(nfix), (np.arange(nfix), rows.fixed_dofs)), shape=(nfix, ndof))
    B = sp.vstack([E, rows.C])
    kkt = sp.bmat([[K, B.T], [B, None]]).tocsc()
    x = spla.spsolve(kkt, np.concatenate([r, du_fixed[rows.fixed_dofs], h]))
    return x[:ndof], x[ndof + nfix:]


def kkt_forward_tolerance(K, rows):
    """The relative forward error two backward-stable solves of the whole KKT system may
    differ by: 2 sqrt(n) cond_2 eps (the multipliers, large where the rows press, take
    most of it; their last bits depend on the BLAS kernels of the machine)."""
    ndof, nfix = K.shape[0], rows.fixed_dofs.size
    E = sp.csr_matrix((np.ones(nfix), (np.arange(nfix), rows.fixed_dofs)), shape=(nfix, ndof))
    B = sp.vstack([E, rows.C])
    kkt = sp.bmat([[K, B.T], [B, None]]).toarray()
    return 2 * np.sqrt(len(kkt)) * np.linalg.cond(kkt) * np.finfo(float).eps


def assert_equal_to_whole_kkt(du, lam, du_ref, lam_ref, tol):
    """du to 1e-10; the stacked (du, lam) to the forward-error bound ``tol``."""
    assert np.linalg.norm(du - du_ref) <= 1e-10 * np.linalg.norm(du_ref)
    x, x_ref = np.concatenate([du, lam]), np.concatenate([du_ref, lam_ref])
    assert np.linalg.norm(x - x_ref) <= tol * np.linalg.norm(x_ref)


@pytest.mark.parametrize("path, inverse, sparse_schur, coarse_cholesky",
                         [("augmented", "superlu", False, False), ("schur", "superlu", False, False),
                          ("schur", "superlu", True, False), ("schur", "sparsecholesky", False, False),
                          ("schur", "superlu", False, True)])
def test_constrained_solve_equals_whole_kkt_solve(contact_state, path, inverse, sparse_schur, coarse_cholesky,
                                                  monkeypatch):
    """sparse_schur: the Schur complement from sparse triangular solves (the path of large
    meshes, forced here on a small one), no kept columns. coarse_cholesky: the coarse
    problem through the Cholesky factor of S (the path of thousands of rows, forced)."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0 if sparse_schur else 10 ** 9)
    monkeypatch.setattr(kkt_module, "COARSE_CHOLESKY_MIN_ROWS", 0 if coarse_cholesky else 10 ** 9)
    prob, rows, support, result = contact_state
    n_contact = len(result.multipliers)
    assert n_contact > 0 and np.any(result.multipliers < 0)     # pieces pressed together
    K = prob.tangent()
    Ks = to_scipy(K)
    r, du_fixed, h = random_kkt_load(prob.fes.ndof, rows, seed=11)
    kkt = ConstrainedSolver(K, rows.fixed_dofs, rows.C, inverse=inverse, modes=support.modes, pins=support.pins,
                            path=path)
    assert kkt.path == path and (kkt.path == "schur" and kkt._Z is None) == sparse_schur
    du, lam = kkt.solve(r, du_fixed, h)
    du_ref, lam_ref = whole_kkt_solution(Ks, rows, r, du_fixed, h)
    assert_equal_to_whole_kkt(du, lam, du_ref, lam_ref, kkt_forward_tolerance(Ks, rows))


def test_first_solve_made_with_the_columns_saves_a_solve_and_equals_whole_kkt_solve(contact_state, monkeypatch):
    """``first``: the first solve's K^+ q joins the block of the Schur columns; the same
    solution as the whole KKT system (1e-10), one solve of the factorisation less."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 10 ** 9)
    prob, rows, support, result = contact_state
    K = to_scipy(prob.tangent())
    ndof = prob.fes.ndof
    r, du_fixed, h = random_kkt_load(ndof, rows, seed=3)
    du_ref, lam_ref = whole_kkt_solution(K, rows, r, du_fixed, h)
    calls = {}
    for first in (None, (r, du_fixed)):
        factor = factor_module.EliminatedFactor(K, rows.fixed_dofs, support.pins)
        solve, count = factor.solve, []
        factor.solve = lambda B, solve=solve, count=count: count.append(B.shape) or solve(B)
        kkt = ConstrainedSolver(None, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                                factor=factor, path="schur", first=first)
        du, lam = kkt.solve(r, du_fixed, h)
        assert np.linalg.norm(du - du_ref) <= 1e-10 * np.linalg.norm(du_ref)
        assert np.linalg.norm(lam - lam_ref) <= 1e-10 * np.linalg.norm(lam_ref)
        calls[first is not None] = count
    assert len(calls[True]) == len(calls[False]) - 1
    assert (ndof, rows.C.shape[0] + 1) in calls[True]           # the columns and q in one block


def test_sparse_schur_complement_and_complementarity_equal_the_columns(contact_state, monkeypatch):
    """C K^+ C^T from the sparse triangular solves equals C (K^+ C^T) from full solves to
    rounding (1e-13 of its largest entry), and the complementarity problem chooses the same
    rows with the same multipliers (1e-10), rows met in the last call taken from the cache
    (no triangular solve)."""
    prob, rows, support, result = contact_state
    K = prob.tangent()
    ndof = prob.fes.ndof
    rng = np.random.default_rng(5)
    r = np.where(np.isin(np.arange(ndof), rows.fixed_dofs), 0.0, rng.standard_normal(ndof))
    h = 1e-3 * rng.standard_normal(rows.C.shape[0])
    solved = {}
    for sparse_schur in (False, True):
        monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0 if sparse_schur else 10 ** 9)
        factor = factor_module.EliminatedFactor(K, rows.fixed_dofs, support.pins)
        uni = ConstrainedSolver(None, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                                factor=factor, dependent_rows=True)
        contact = np.arange(len(result.multipliers))     # the hold rows stay equalities
        solved[sparse_schur] = (uni._S, uni.solve_unilateral(r, np.zeros(ndof), h, contact))
        if sparse_schur:     # again, half of the rows known: no solve, the same matrix to rounding
            half = rows.C.shape[0] // 2
            solves = []
            monkeypatch.setattr(sparse_schur_module, "reach_solves",
                                lambda *a, _f=sparse_schur_module.reach_solves: solves.append(a[3].shape[0]) or _f(*a))
            again = factor.schur(rows.C[:half])
            assert solves == []
            whole = factor.schur(rows.C)
            assert solves == [rows.C.shape[0] - half]
            assert np.abs(again - whole[:half, :half]).max() <= 1e-14 * np.abs(whole).max()
    (S0, (du0, lam0, act0, _)), (S1, (du1, lam1, act1, _)) = solved[False], solved[True]
    assert np.abs(S1 - S0).max() <= 1e-13 * np.abs(S0).max()
    assert np.array_equal(act0, act1)
    assert np.linalg.norm(lam1 - lam0) <= 1e-10 * np.linalg.norm(lam0)
    assert np.linalg.norm(du1 - du0) <= 1e-10 * np.linalg.norm(du0)


def test_the_configurations_exercise_the_rigid_modes(contact_state):
    """Free modes held through general rows, with K R != 0 (not a vacuous case)."""
    prob, rows, support, _ = contact_state
    assert support.pins.size > 0 and support.modes.shape[1] == support.pins.size
    free = np.ones(prob.fes.ndof, dtype=bool)
    free[rows.fixed_dofs] = False
    KR = to_scipy(prob.tangent()) @ support.modes
    assert np.abs(KR[free]).max() > 1e-6 * np.abs(to_scipy(prob.tangent()).diagonal()).max()
    if rows.labels[-1] == "free modes":
        assert rows.C.shape[0] > len(contact_state[3].multipliers)


def test_default_path_by_size_and_the_complementarity_path_is_schur(contact_state):
    prob, rows, support, _ = contact_state
    K = prob.tangent()
    assert ConstrainedSolver(K, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins).path == "augmented"
    assert ConstrainedSolver(K, rows.fixed_dofs, rows.C, inverse="sparsecholesky", modes=support.modes,
                             pins=support.pins).path == "schur"
    unilateral = ConstrainedSolver(K, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                                   dependent_rows=True)
    assert unilateral.path == "schur"
    with pytest.raises(ValueError, match="path"):
        ConstrainedSolver(K, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins, path="qr")


def test_a_singular_augmented_matrix_falls_back_to_the_schur_path_and_says_so(contact_state, monkeypatch):
    """The augmented LU of rows that hold a mechanism only at rounding level can be singular
    where the Schur path (pins, coarse problem) solves: "auto" falls back and records it,
    an explicit "augmented" raises."""
    prob, rows, support, _ = contact_state
    K = prob.tangent()

    def singular(self, C):
        raise factor_module.SingularSystem("augmented matrix: pivot ratio 8.67e-16")
    monkeypatch.setattr(factor_module.EliminatedFactor, "augmented", singular)
    kkt = ConstrainedSolver(K, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins)
    assert kkt.path == "schur" and "pivot ratio 8.67e-16" in kkt.fallback
    r, du_fixed, h = random_kkt_load(prob.fes.ndof, rows, seed=5)
    du, lam = kkt.solve(r, du_fixed, h)
    du_ref, lam_ref = whole_kkt_solution(to_scipy(K), rows, r, du_fixed, h)
    assert_equal_to_whole_kkt(du, lam, du_ref, lam_ref, kkt_forward_tolerance(to_scipy(K), rows))
    with pytest.raises(factor_module.SingularSystem, match="8.67e-16"):
        ConstrainedSolver(K, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins, path="augmented")
    assert ConstrainedSolver(K, rows.fixed_dofs, rows.C, inverse="sparsecholesky", modes=support.modes,
                             pins=support.pins).fallback is None


def test_a_cracking_run_takes_the_same_path_with_the_sparse_schur_complement(monkeypatch):
    """The coarse plate run to broken through, every Schur complement from the sparse
    triangular solves (forced below its size threshold) against the kept columns: the same
    steps and split vertices, and crack length, energy and the displacement of the final
    state equal to the rounding of the solves (1e-9 relative)."""
    from ngfracture import scenes
    from ngfracture import Simulation

    runs = {}
    for sparse in (False, True):
        monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0 if sparse else 10 ** 9)
        monkeypatch.setattr(factor_module, "AUGMENTED_MAX_DOFS", -1)      # every solve on the Schur path
        runs[sparse] = Simulation(scenes.plate(maxh=0.06, radius=None)).run()
    a, b = runs[False], runs[True]
    assert a.ok and b.ok and a.summary["reason"] == b.summary["reason"] == "broken"
    for key in ("n_steps", "n_split_vertices", "n_fragments"):
        assert a.summary[key] == b.summary[key], key
    assert [h["split_vertices"] for h in a.summary["history"]] == [h["split_vertices"] for h in b.summary["history"]]
    assert abs(a.summary["crack_length"] - b.summary["crack_length"]) <= 1e-9 * a.summary["crack_length"]
    ua, ub = a.state.u, b.state.u
    assert np.linalg.norm(ua - ub) <= 1e-9 * np.linalg.norm(ua)


@pytest.mark.parametrize("k", [0, 3])
def test_the_coarse_problem_through_the_cholesky_factor_of_s_is_its_lu(k, monkeypatch):
    """The equilibrated coarse problem [S -G; -G^T -A] solved through the Cholesky factor
    of S with the modes' block eliminated equals its LU solve to 1e-12 (with and without
    modes); rows that depend on each other fail the same pivot test; an S that is not
    positive definite (a row on pinned dofs alone) or nearly singular takes the LU."""
    rng = np.random.default_rng(17)
    m = 60
    B = rng.standard_normal((m, m + 20))
    S, G = B @ B.T, rng.standard_normal((m, k))
    A = np.eye(k) * 0.5
    scale = kkt_module._equilibration(S, G)
    rhs = rng.standard_normal(m + k)
    monkeypatch.setattr(kkt_module, "COARSE_CHOLESKY_MIN_ROWS", 10 ** 9)
    lu = kkt_module._coarse_factor(S, G, A, scale)
    monkeypatch.setattr(kkt_module, "COARSE_CHOLESKY_MIN_ROWS", 0)
    chol = kkt_module._coarse_factor(S, G, A, scale)
    assert lu.cholesky is None and chol.cholesky is not None
    x, reference = chol.solve(rhs), lu.solve(rhs)
    assert np.linalg.norm(x - reference) <= 1e-12 * np.linalg.norm(reference)
    dependent = np.vstack([B, B[:1]])
    S2 = dependent @ dependent.T
    G2 = np.vstack([G, G[:1]])
    for threshold in (0, 10 ** 9):
        monkeypatch.setattr(kkt_module, "COARSE_CHOLESKY_MIN_ROWS", threshold)
        with pytest.raises(SingularSystem, match="coarse pivot ratio"):
            kkt_module._coarse_factor(S2, G2, A, kkt_module._equilibration(S2, G2))
    if k:
        S3, G3 = S.copy(), G.copy()
        S3[0, :] = S3[:, 0] = 0.0            # the row reaches no factorised dof
        G3[0] = 1.0
        monkeypatch.setattr(kkt_module, "COARSE_CHOLESKY_MIN_ROWS", 0)
        assert kkt_module._coarse_factor(S3, G3, A, kkt_module._equilibration(S3, G3)).cholesky is None
        S4 = S + 1e8 * np.outer(B[:, 0], B[:, 0])     # condition beyond the Cholesky route's
        assert kkt_module._coarse_factor(S4, G, A, kkt_module._equilibration(S4, G)).cholesky is None
