"""The nonlinear elasticity core against exact solutions and theory."""
import math

import ngsolve as ng
import numpy as np
import pytest
import scipy.sparse as sp

import ngfracture as nf
from ngfracture.linalg.sparse import to_scipy
from ngfracture.mechanics import materials
from conftest import distorted_square_mesh, square_mesh, two_squares_mesh

ALL_BOUNDARIES = ["bottom", "right", "top", "left"]
NONLINEAR = [nf.StVenantKirchhoff, nf.NeoHookean]


def l2(cf, mesh, order=6):
    return math.sqrt(ng.Integrate(ng.InnerProduct(cf, cf), mesh, order=order))


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("cls", NONLINEAR + [nf.LinearElastic])
def test_patch_test_finite_stretch_and_shear(cls, order):
    """A homogeneous deformation F = A solves every model without body force: reproduced exactly."""
    mesh = distorted_square_mesh(maxh=0.25, amount=0.4)
    A = ((1.2, 0.3), (-0.1, 0.9))
    uex = ng.CF(((A[0][0] - 1) * ng.x + A[0][1] * ng.y, A[1][0] * ng.x + (A[1][1] - 1) * ng.y))
    prob = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3), order=order)
    prob.add_dirichlet(ALL_BOUNDARIES, uex)
    status = prob.solve(method="full", load_steps=2)
    assert status.converged, status.message
    assert l2(prob.u - uex, mesh) < 1e-10 * l2(uex, mesh)


@pytest.mark.parametrize("angle", [30, 90, 180])
@pytest.mark.parametrize("cls", NONLINEAR)
def test_objectivity_rigid_rotation(cls, angle):
    """Rotation imposed as Dirichlet data: zero Green-Lagrange strain and zero energy."""
    mesh = distorted_square_mesh(maxh=0.3, amount=0.3)
    theta = ng.Parameter(0.0)
    # rotation about the centre of the square
    X, Y = ng.x - 0.5, ng.y - 0.5
    rot = ng.CF((ng.cos(theta) * X - ng.sin(theta) * Y - X, ng.sin(theta) * X + ng.cos(theta) * Y - Y))
    E = 1.0
    prob = nf.ElasticProblem(mesh, cls(E=E, nu=0.3), order=1)
    prob.add_dirichlet(ALL_BOUNDARIES, rot)
    steps = angle // 15
    for k in range(1, steps + 1):
        theta.Set(math.radians(angle) * k / steps)
        status = prob.solve(method="full")
        assert status.converged, status.message
    strain = l2(prob.strain(), mesh)
    assert strain < 1e-10
    assert abs(prob.energy()) < 1e-10 * E


def test_linear_model_is_not_objective():
    """Documented: the linear model strains under a large rotation, eps = (cos t - 1) I."""
    mesh = square_mesh(0.3)
    t = math.radians(90)
    X, Y = ng.x - 0.5, ng.y - 0.5
    rot = ng.CF((math.cos(t) * X - math.sin(t) * Y - X, math.sin(t) * X + math.cos(t) * Y - Y))
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet(ALL_BOUNDARIES, rot)
    assert prob.solve().converged
    expected = abs(math.cos(t) - 1) * math.sqrt(2)   # |(cos t - 1) I|_F over unit area
    assert l2(prob.strain(), mesh) == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("cls", NONLINEAR)
def test_taylor_consistent_tangent(cls):
    """|r(u + e v) - r(u) - e K(u) v| decays like e^2 (second-order remainder)."""
    mesh = distorted_square_mesh(maxh=0.3)
    prob = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3), order=2)
    rng = np.random.default_rng(1)
    u0 = 0.05 * rng.standard_normal(prob.fes.ndof)
    v = rng.standard_normal(prob.fes.ndof)
    vec = prob.u.vec
    vec.FV().NumPy()[:] = u0
    K = to_scipy(prob.tangent())
    r0 = prob.out_of_balance()
    remainders = []
    for eps in [1e-2, 5e-3, 2.5e-3, 1.25e-3]:
        vec.FV().NumPy()[:] = u0 + eps * v
        r = prob.out_of_balance()
        # out_of_balance is minus the internal force: r(u+ev) = r(u) - e K v + O(e^2)
        remainders.append(np.linalg.norm(r - r0 + eps * (K @ v)))
    rates = np.log2(np.array(remainders[:-1]) / np.array(remainders[1:]))
    assert np.all(np.abs(rates - 2.0) < 0.1), rates


@pytest.mark.parametrize("cls", NONLINEAR + [nf.LinearElastic])
def test_out_of_balance_at_the_same_state_is_kept_not_reassembled(cls, monkeypatch):
    """Asked twice at one displacement and load factor, the residual is the kept one (bitwise,
    no second assembly); a changed displacement or load factor gives the residual of the new state."""
    applied = []      # assemblies: NGSolve's Apply or the C++ kernel of P1 meshes
    apply = ng.BilinearForm.Apply
    monkeypatch.setattr(ng.BilinearForm, "Apply", lambda form, *args: applied.append(1) or apply(form, *args))
    import ngfracture.mechanics.problem
    kernel = ngfracture.mechanics.problem._ext.InternalForces
    monkeypatch.setattr(ngfracture.mechanics.problem, "_ext", type("C", (), {
        "InternalForces": staticmethod(lambda *args: applied.append(1) or kernel(*args)),
        "TangentStiffness": ngfracture.mechanics.problem._ext.TangentStiffness}))
    mesh = distorted_square_mesh(maxh=0.3)
    prob = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3))
    prob.add_body_force((0.3, -0.2))
    prob.load_factor.Set(1.0)
    u = prob.u.vec.FV().NumPy()
    u[:] = 0.01 * np.random.default_rng(2).standard_normal(u.size)
    first = prob.out_of_balance()
    first[:] = 0.0                                   # a copy: the kept residual is untouched
    again = prob.out_of_balance()
    if prob.nonlinear:
        assert len(applied) == 1
    fresh = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3))
    fresh.add_body_force((0.3, -0.2))
    fresh.load_factor.Set(1.0)
    fresh.u.vec.FV().NumPy()[:] = u
    assert np.array_equal(again, fresh.out_of_balance())
    u[3] += 1e-3                                     # another state: assembled again
    fresh.u.vec.FV().NumPy()[3] += 1e-3
    assert np.array_equal(prob.out_of_balance(), fresh.out_of_balance())
    prob.load_factor.Set(0.5)
    fresh.load_factor.Set(0.5)
    changed = prob.out_of_balance()
    assert np.array_equal(changed, fresh.out_of_balance())
    assert not np.array_equal(changed, again)


def stretch_problem(cls, stretch=0.25):
    mesh = square_mesh(0.2)
    prob = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (stretch, 0.2 * stretch))
    return prob


@pytest.mark.parametrize("cls", NONLINEAR)
def test_full_newton_converges_quadratically(cls):
    prob = stretch_problem(cls)
    status = prob.solve(method="full", tol=1e-12)
    assert status.converged, status.message
    e = np.array([x for x in status.increment_history if x > 1e-13])
    assert len(e) >= 4
    # order estimate p = log(e_{k+1}/e_k) / log(e_k/e_{k-1}) over the last iterations
    p = np.log(e[2:] / e[1:-1]) / np.log(e[1:-1] / e[:-2])
    assert p[-1] > 1.8, (e, p)


@pytest.mark.parametrize("cls", NONLINEAR)
def test_modified_newton_contracts_each_iteration(cls):
    prob = stretch_problem(cls, stretch=0.1)
    status = prob.solve(method="modified", tol=1e-10)
    assert status.converged, status.message
    e = np.array(status.increment_history)
    factors = e[1:] / e[:-1]
    assert np.all(factors < 0.5), factors
    # linear (not quadratic) convergence: the contraction factor settles to a constant
    assert factors[-1] == pytest.approx(factors[-2], rel=0.5)
    assert status.iterations > 4


def test_modified_and_full_newton_agree():
    a, b = stretch_problem(nf.StVenantKirchhoff, 0.1), stretch_problem(nf.StVenantKirchhoff, 0.1)
    assert a.solve(method="modified", tol=1e-12).converged
    assert b.solve(method="full", tol=1e-12).converged
    ua, ub = a.u.vec.FV().NumPy(), b.u.vec.FV().NumPy()
    assert np.linalg.norm(ua - ub) < 1e-10 * np.linalg.norm(ua)


def test_small_load_limit_svk_matches_linear_to_second_order():
    """|u_svk - u_lin| = O(load^2): the fitted exponent is 2."""
    mesh = square_mesh(0.2)
    diffs, loads = [], [1e-2, 1e-3, 1e-4]
    for s in loads:
        sols = []
        for cls in (nf.LinearElastic, nf.StVenantKirchhoff):
            prob = nf.ElasticProblem(mesh, cls(E=1.0, nu=0.3), order=2)
            prob.add_dirichlet("left", (0.0, 0.0))
            prob.add_dirichlet("right", (s, 0.5 * s))
            assert prob.solve(method="full", tol=1e-13).converged
            sols.append(prob.u.vec.FV().NumPy().copy())
        diffs.append(np.linalg.norm(sols[0] - sols[1]))
    slope = np.polyfit(np.log(loads), np.log(diffs), 1)[0]
    assert abs(slope - 2.0) < 0.05, (diffs, slope)


def test_load_steps_reach_the_same_state():
    a, b = stretch_problem(nf.NeoHookean), stretch_problem(nf.NeoHookean)
    sa, sb = a.solve(load_steps=1, tol=1e-12), b.solve(load_steps=4, tol=1e-12)
    assert sa.converged and sb.converged and sb.steps == 4
    ua, ub = a.u.vec.FV().NumPy(), b.u.vec.FV().NumPy()
    assert np.linalg.norm(ua - ub) < 1e-9 * np.linalg.norm(ua)


def test_gmres_option_agrees_with_direct():
    a, b = stretch_problem(nf.StVenantKirchhoff, 0.1), stretch_problem(nf.StVenantKirchhoff, 0.1)
    assert a.solve(tol=1e-11).converged
    sb = b.solve(tol=1e-11, linear_solver="gmres")
    assert sb.converged, sb.message
    ua, ub = a.u.vec.FV().NumPy(), b.u.vec.FV().NumPy()
    assert np.linalg.norm(ua - ub) < 1e-8 * np.linalg.norm(ua)


@pytest.mark.parametrize("inverse", ["superlu", "sparsecholesky"])
def test_direct_solvers_agree(inverse):
    """SuperLU (the default up to factor.SUPERLU_MAX_DOFS) and NGSolve's sparse Cholesky solve
    the same Newton steps: the converged states agree to the tolerance of eq. 7."""
    a, b = stretch_problem(nf.StVenantKirchhoff, 0.1), stretch_problem(nf.StVenantKirchhoff, 0.1)
    assert a.solve(tol=1e-11, inverse="umfpack").converged
    sb = b.solve(tol=1e-11, inverse=inverse)
    assert sb.converged, sb.message
    ua, ub = a.u.vec.FV().NumPy(), b.u.vec.FV().NumPy()
    assert np.linalg.norm(ua - ub) < 1e-10 * np.linalg.norm(ua)


def test_auto_inverse_picks_by_size(monkeypatch):
    from ngfracture.linalg import factor
    prob = stretch_problem(nf.StVenantKirchhoff, 0.1)
    K = prob.tangent()
    assert factor.EliminatedFactor(K, []).inverse == "superlu"
    monkeypatch.setattr(factor, "SUPERLU_MAX_DOFS", prob.fes.ndof - 1)
    assert factor.EliminatedFactor(K, []).inverse == "sparsecholesky"


def test_singular_stiffness_is_reported_by_superlu():
    """A stiffness with a free rigid mode, factorised without a pin: reported, not solved."""
    from ngfracture.linalg import factor
    prob = stretch_problem(nf.LinearElastic, 0.1)
    K = prob.tangent()
    with pytest.raises(factor.SingularSystem):
        f = factor.EliminatedFactor(K, [], inverse="superlu")      # all dofs free: three rigid modes
        f.solve(np.random.default_rng(0).standard_normal(prob.fes.ndof))


def test_body_force_and_traction_balance():
    """Clamped bar under a traction: the reaction equals the applied load (linear, exact in total)."""
    mesh = square_mesh(0.25)
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_traction("right", (0.01, 0.002))
    prob.add_body_force((0.0, -0.003))
    status = prob.solve()
    assert status.converged, status.message
    r = prob.out_of_balance()
    n = prob.fes.ndof // 2
    reaction = [-r[:n].sum(), -r[n:].sum()]   # internal forces at the clamped dofs
    assert reaction[0] == pytest.approx(-0.01, abs=1e-12)
    assert reaction[1] == pytest.approx(-0.002 + 0.003, abs=1e-12)


# -- failures are reasons, never garbage ---------------------------------------------------

def test_floating_body_is_reported_not_solved(square):
    prob = nf.ElasticProblem(square, nf.StVenantKirchhoff(1.0, 0.3))
    prob.add_point_constraint(0, (0.0, 0.0))       # translation fixed, rotation free
    status = prob.solve()
    assert not status.converged and status.reason == "singular"
    assert "floating body: 1 rigid-body mode(s) are held by no constraint" in status.message
    assert np.all(prob.u.vec.FV().NumPy() == 0.0)


def test_second_free_body_is_named():
    mesh = two_squares_mesh()
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("a_left", (0.0, 0.0))
    prob.add_dirichlet("a_right", (0.1, 0.0))
    status = prob.solve()
    assert status.reason == "singular" and "3 rigid-body mode(s) are held by no constraint" in status.message


def test_general_rows_on_a_supported_body(square):
    """Multiplier rows through the Schur complement: tie the mean ux of the right edge to 0.01."""
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3, plane="stress"))
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_point_constraint(0, 0.0, component="y")
    n = prob.fes.ndof // 2
    right = np.flatnonzero(np.abs(square.ngmesh.Coordinates()[:, 0] - 1.0) < 1e-12)
    C = np.zeros((1, prob.fes.ndof))
    C[0, right] = 1.0 / right.size
    prob.constraints.add_rows(sp.csr_matrix(C), [0.01], label="mean")
    status = prob.solve()
    assert status.converged, status.message
    u = prob.u.vec.FV().NumPy()
    assert abs(C @ u - 0.01)[0] < 1e-15
    # reference: the whole saddle-point system handed to a sparse LU
    rows = prob.assemble_constraints()
    K = to_scipy(prob.tangent())
    G = sp.csr_matrix((np.ones(rows.fixed_dofs.size), (np.arange(rows.fixed_dofs.size), rows.fixed_dofs)),
                      shape=(rows.fixed_dofs.size, prob.fes.ndof))
    B = sp.vstack([G, sp.csr_matrix(C)])
    whole = sp.bmat([[K, B.T], [B, None]]).tocsc()
    rhs = np.concatenate([np.zeros(prob.fes.ndof), rows.fixed_values, [0.01]])
    ref = sp.linalg.spsolve(whole, rhs)
    assert np.linalg.norm(u - ref[:prob.fes.ndof]) < 1e-12 * np.linalg.norm(ref)
    # the multiplier of the general row is the same as in the whole saddle-point system
    assert status.multipliers[0] == pytest.approx(ref[-1], rel=1e-10)


@pytest.mark.parametrize("cls", [nf.LinearElastic, nf.StVenantKirchhoff])
def test_free_body_held_by_rigid_mode_rows(square, cls):
    """Self-equilibrated tractions on a free square; three multiplier rows fix its rigid modes."""
    sigma = 1e-3
    prob = nf.ElasticProblem(square, cls(1.0, 0.3, plane="stress"))
    prob.add_traction("right", (sigma, 0.0))
    prob.add_traction("left", (-sigma, 0.0))
    n, nv = prob.fes.ndof // 2, square.nv
    x = square.ngmesh.Coordinates()[:, :2] - 0.5
    C = np.zeros((3, prob.fes.ndof))
    C[0, :nv] = 1.0
    C[1, n:n + nv] = 1.0
    C[2, :nv], C[2, n:n + nv] = -x[:, 1], x[:, 0]
    prob.constraints.add_rows(sp.csr_matrix(C), np.zeros(3), label="rigid")
    status = prob.solve(tol=1e-12)
    assert status.converged, status.message
    u = prob.u.vec.FV().NumPy()
    assert np.abs(C @ u).max() < 1e-13
    # the load is self-equilibrated: the rigid-mode rows carry no force (linear exactly;
    # SVK: the dead tractions equilibrate in the reference configuration only up to O(sigma^2))
    assert np.abs(status.multipliers).max() < (1e-14 if cls is nf.LinearElastic else sigma ** 2)
    # uniaxial stress: the linear strain is diag(sigma, -nu sigma)/E exactly; SVK to O(sigma^2)
    eps = ng.CF((sigma, 0, 0, -0.3 * sigma), dims=(2, 2))
    tol = 1e-12 if cls is nf.LinearElastic else 10 * sigma ** 2
    assert l2(materials.small_strain(ng.Grad(prob.u)) - eps, square) < tol


def test_dependent_general_rows_are_reported(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    row = np.zeros(prob.fes.ndof)
    row[5] = 1.0
    prob.constraints.add_rows(sp.csr_matrix(np.vstack([row, 2 * row])), np.zeros(2))
    status = prob.solve()
    assert status.reason == "singular" and "dependent" in status.message


def test_nan_load_is_reported(square):
    prob = nf.ElasticProblem(square, nf.StVenantKirchhoff(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_body_force((ng.sqrt(ng.x - 2.0), 0.0))   # NaN everywhere in the domain
    status = prob.solve()
    assert status.reason == "nan" and not status.converged
    assert np.all(np.isfinite(prob.u.vec.FV().NumPy()))


def test_inverted_element_is_reported_and_state_restored(square):
    prob = nf.ElasticProblem(square, nf.NeoHookean(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (-0.1, 0.0))
    assert prob.solve().converged
    before = prob.u.vec.FV().NumPy().copy()
    prob.constraints.dirichlet.pop()
    prob.add_dirichlet("right", (-1.5, 0.0))      # squeezes the square through itself
    status = prob.solve(method="full")
    assert not status.converged and status.reason in ("inverted_element", "nan")
    assert np.array_equal(prob.u.vec.FV().NumPy(), before)


def test_modified_newton_divergence_is_reported():
    """A 25% stretch in one step from the linear tangent: SVK stiffens, modified Newton diverges."""
    prob = stretch_problem(nf.StVenantKirchhoff, stretch=0.25)
    status = prob.solve(method="modified")
    assert status.reason == "diverged" and not status.converged
    assert np.all(prob.u.vec.FV().NumPy() == 0.0)


def test_max_iterations_is_reported():
    prob = stretch_problem(nf.StVenantKirchhoff, stretch=0.1)
    status = prob.solve(method="modified", maxit=2)
    assert status.reason == "max_iterations" and not status.converged
    assert np.all(prob.u.vec.FV().NumPy() == 0.0)


@pytest.mark.parametrize("contrast", [1.0, 1e3, 1e6])
def test_bonded_regions_in_series_match_the_exact_solution(contrast):
    """Two materials in series under a prescribed stretch (nu = 0: uniaxial, exact for P1)."""
    from conftest import two_region_bar_mesh
    mesh = two_region_bar_mesh()
    E1, E2, d = 1.0, contrast, 1e-3
    mats = {"soft": nf.LinearElastic(E1, 0.0), "stiff": nf.LinearElastic(E2, 0.0)}
    prob = nf.ElasticProblem(mesh, mats)
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", d, component="x")
    prob.add_point_constraint(0, 0.0, component="y")
    status = prob.solve()
    assert status.converged, status.message
    sigma = d / (1.0 / E1 + 1.0 / E2)
    uex = ng.CF((ng.IfPos(ng.x - 1, sigma / E1 + sigma / E2 * (ng.x - 1), sigma / E1 * ng.x), 0))
    assert l2(prob.u - uex, mesh) < 1e-8 * l2(uex, mesh)


def test_region_materials_are_validated():
    from conftest import two_region_bar_mesh
    mesh = two_region_bar_mesh()
    with pytest.raises(ValueError, match=r"\['stiff'\] have no material"):
        nf.ElasticProblem(mesh, {"soft": nf.LinearElastic(1.0, 0.0)})
    with pytest.raises(ValueError, match="'steel' does not exist"):
        nf.ElasticProblem(mesh, {"soft": nf.LinearElastic(1.0, 0.0), "stiff": nf.LinearElastic(1.0, 0.0),
                                 "steel": nf.LinearElastic(1.0, 0.0)})


def free_pieces_mesh():
    """A unit square, a single free triangle and a free chunk (three bodies, no shared vertex)."""
    from netgen.geom2d import SplineGeometry
    from ngfracture.geometry.meshio import MeshArrays, merge_meshes, mesh_from_arrays
    tri = mesh_from_arrays(MeshArrays(np.array([[2.0, 0.0], [2.3, 0.0], [2.0, 0.3]]), np.array([[0, 1, 2]]),
                                      np.array([1]), ["default"], np.array([[0, 1], [1, 2], [2, 0]]),
                                      np.array([1, 1, 1]), ["crack"]))
    geo = SplineGeometry()
    geo.AddRectangle((3, 0), (3.5, 0.5), bc="crack")
    chunk = ng.Mesh(geo.GenerateMesh(maxh=0.2))
    return merge_meshes(square_mesh(0.25), tri, chunk)


@pytest.mark.parametrize("cls", [nf.LinearElastic, nf.StVenantKirchhoff, nf.NeoHookean])
def test_free_fragments_get_their_rigid_modes_fixed(cls):
    mesh = free_pieces_mesh()
    prob = nf.ElasticProblem(mesh, cls(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (0.05, 0.01))
    assert prob.solve().reason == "singular"          # reported by default ...
    status = prob.solve(fix_free_modes=True)            # ... held on request
    assert status.converged, status.message
    u = prob.u.vec.FV().NumPy()
    n = prob.fes.ndof // 2
    free_vertices = np.flatnonzero(mesh.ngmesh.Coordinates()[:, 0] > 1.5)
    assert free_vertices.size >= 3 + 4
    # nothing loads the free pieces: they neither move nor strain, and nothing is garbage
    assert np.all(np.isfinite(u)) and np.abs(u).max() < 1.0
    assert np.abs(u[free_vertices]).max() < 1e-12 and np.abs(u[n + free_vertices]).max() < 1e-12
    strain = l2(prob.strain(), mesh, order=4)
    assert strain > 0.01   # the square is stretched
    free_strain = math.sqrt(ng.Integrate(ng.IfPos(ng.x - 1.5, 1, 0) *
                                         ng.InnerProduct(prob.strain(), prob.strain()), mesh, order=4))
    assert free_strain < 1e-12


@pytest.mark.parametrize("nu", [0.49, 0.499, 0.4999])
@pytest.mark.parametrize("cls", NONLINEAR)
def test_near_incompressible_converges_or_says_why(cls, nu):
    """Locking makes the discrete problem stiff, never garbage: converged with finite u, or a reason."""
    mesh = square_mesh(0.2)
    prob = nf.ElasticProblem(mesh, cls(1.0, nu))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (0.05, 0.0))
    status = prob.solve(method="full", load_steps=2)
    u = prob.u.vec.FV().NumPy()
    assert np.all(np.isfinite(u))
    if not status.converged:
        # measured: neo-Hooke at 0.4999, a full Newton iterate inverts elements (lambda/mu = 5000)
        assert status.reason == "inverted_element" and np.all(u == 0.0)
        return
    # equilibrium to the solver tolerance: out-of-balance tiny against the reactions
    r = prob.out_of_balance()
    fixed = prob.assemble_constraints().fixed_dofs
    free = np.ones(r.size, dtype=bool)
    free[fixed] = False
    assert np.linalg.norm(r[free]) < 1e-8 * np.linalg.norm(r[fixed])


def test_a_3d_mesh_with_a_2d_reduction_is_refused():
    from netgen.csg import unit_cube
    mesh3d = ng.Mesh(unit_cube.GenerateMesh(maxh=0.5))
    with pytest.raises(ValueError, match="plane stress is a 2D reduction"):
        nf.ElasticProblem(mesh3d, nf.LinearElastic(1.0, 0.3, plane="stress"))
    assert nf.ElasticProblem(mesh3d, nf.LinearElastic(1.0, 0.3)).dim == 3


@pytest.mark.parametrize("noise, converges", [(1e-9, True), (1e-5, False)])
def test_stall_at_the_rounding_floor(noise, converges, monkeypatch):
    """A residual with noise of relative size `noise` (as rounding in a badly conditioned
    contact solve): full Newton stalls at about that relative increment. Below 1e3 tol the
    stall counts as converged and the state is the clean solution to about the noise;
    above, it is max_iterations as before."""
    clean = stretch_problem(nf.StVenantKirchhoff, stretch=0.1)
    assert clean.solve(method="full", tol=1e-12).converged
    prob = stretch_problem(nf.StVenantKirchhoff, stretch=0.1)
    true_residual = prob.out_of_balance
    reactions = clean.out_of_balance()          # the force scale: the reactions of the solution
    scale = np.linalg.norm(reactions) / math.sqrt(reactions.size)
    calls = []

    def noisy():
        calls.append(1)
        r = true_residual()
        return r + noise * scale * np.random.default_rng(len(calls)).standard_normal(r.size)
    monkeypatch.setattr(prob, "out_of_balance", noisy)
    status = prob.solve(method="full", tol=1e-10, maxit=30)
    if converges:
        assert status.converged and status.message.startswith("stalled"), status.increment_history
        assert 1e-10 <= status.increment_history[-1] < 1e-7
        u, u0 = prob.u.vec.FV().NumPy(), clean.u.vec.FV().NumPy()
        assert np.abs(u - u0).max() <= 1e3 * noise * np.abs(u0).max()
    else:
        assert status.reason == "max_iterations", (status.reason, status.increment_history)
