"""The L-shape manufactured solution (paper section 4.1, eq. 15) and its convergence rates.

Ladder: constants to 12 digits; the exact solution is traction-free on the
reentrant edges and in equilibrium; the exact stress is the stress of the exact
displacement; the energy-error functional agrees with quadrature where the
corner is resolved; then fitted rates against theory (energy: alpha in h on
uniform meshes, order p on graded meshes; L2: 2 alpha with traction-free
reentrant edges, >= 1 in every variant).  Runnable as a script (prints the tables).
"""
import math

import ngsolve as ng
import numpy as np
import pytest

from ngfracture.studies import lshape
from ngfracture.studies.verify import fit_rate, lshape_study, solve_ngfracture, solve_plain, time_to_error

ALPHA_REF = 0.544483736782  # 12 digits, NGSOLVE_NOTES.md (root of sin(3 pi a / 2) = a)
C1_REF = 1.841364331171


@pytest.fixture(scope="module")
def sol():
    return lshape.LShapeSolution(E=1e5, nu=0.3, plane="strain")


def _grad_cf(u):
    x, y = ng.x, ng.y
    return ng.CF((u[0].Diff(x), u[0].Diff(y), u[1].Diff(x), u[1].Diff(y)), dims=(2, 2))


def test_constants(sol):
    assert abs(sol.alpha - ALPHA_REF) < 1e-12
    assert abs(sol.C1 - C1_REF) < 1e-12
    w = lshape.OMEGA
    assert abs(sol.alpha * math.sin(2 * w) + math.sin(2 * w * sol.alpha)) < 4e-16
    # C2 = 2 (lambda + 2 mu) / (lambda + mu) = 4 (1 - nu) in plane strain, 4 / (1 + nu) in plane stress
    assert abs(sol.C2 - 4 * (1 - 0.3)) < 1e-14
    assert abs(lshape.LShapeSolution(1e5, 0.3, "stress").C2 - 4 / 1.3) < 1e-14


def test_traction_free_on_reentrant_edges(sol):
    # At the Gauss points of the boundary edges of a graded mesh (down to r ~ 3e-6).
    # Mapped points keep y = 0 / x = 0 exactly; a point search (mesh(x, y)) may not,
    # and an angle off by 1e-16 / r would then show up as a spurious traction.
    mesh = lshape.lshape_mesh(2, gamma=4.0)
    pts = mesh.MapToAllElements(ng.IntegrationRule(ng.SEGM, 20), ng.BND)
    X, Y = ng.x(pts).ravel(), ng.y(pts).ravel()
    S = sol.sigma(pts).reshape(-1, 2, 2)
    on_x_axis = (Y == 0) & (X > 0)  # outward normal -e_y
    on_y_axis = (X == 0) & (Y < 0)  # outward normal +e_x
    assert on_x_axis.sum() >= 40 and on_y_axis.sum() >= 40
    assert np.hypot(X, Y)[on_x_axis].min() < 1e-5
    tn = np.concatenate([-S[on_x_axis][:, :, 1], S[on_y_axis][:, :, 0]])
    outer = np.abs(np.maximum(np.abs(X), np.abs(Y)) - 1) < 1e-14
    assert outer.sum() > 100
    max_outer = np.abs(S[outer]).max()
    assert np.linalg.norm(tn, axis=1).max() / max_outer < 1e-12
    # Not a trivial zero: the stress itself blows up like r^(alpha-1) along those edges.
    s_small = np.abs(sol.sigma(mesh(1e-4, 0.0))).max()
    s_one = np.abs(sol.sigma(mesh(1.0, 0.0))).max()
    assert abs(math.log(s_small / s_one) / math.log(1e-4) - (sol.alpha - 1)) < 1e-6


def test_stress_is_stress_of_displacement(sol):
    # The closed-form polar stress against NGSolve's symbolic derivative of u.
    mesh = lshape.lshape_mesh(0)
    eps = ng.Sym(_grad_cf(sol.u))
    sd = sol.lam * ng.Trace(eps) * ng.Id(2) + 2 * sol.mu * eps
    rng = np.random.default_rng(1)
    pts = rng.uniform(-1, 1, (200, 2))
    pts = pts[~((pts[:, 0] > 0) & (pts[:, 1] < 0))]
    for p in pts:
        a, b = np.array(sol.sigma(mesh(*p))), np.array(sd(mesh(*p)))
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max()


def test_equilibrium_weak_residual(sol):
    # int sigma : eps(v) dx - int sigma n . v ds = -int div(sigma) . v dx must vanish for
    # every P3 test function whose support stays away from the corner (r >= 0.3).
    mesh = lshape.lshape_mesh(1)
    fes = ng.VectorH1(mesh, order=3)
    v = fes.TestFunction()
    n = ng.specialcf.normal(2)
    vol = ng.LinearForm(ng.InnerProduct(sol.sigma, ng.Sym(ng.Grad(v))) * ng.dx(bonus_intorder=12))
    bnd = ng.LinearForm(ng.InnerProduct(sol.sigma * n, v) * ng.ds(bonus_intorder=12))
    vol.Assemble()
    bnd.Assemble()
    away = np.ones(fes.ndof, bool)
    for el in mesh.Elements(ng.VOL):
        if min(np.hypot(*mesh.vertices[p.nr].point) for p in el.vertices) < 0.3:
            away[list(fes.GetDofNrs(el))] = False
    assert away.sum() > fes.ndof // 2
    res = vol.vec.FV().NumPy() - bnd.vec.FV().NumPy()
    scale = np.abs(vol.vec.FV().NumPy()[away]).max()
    assert np.abs(res[away]).max() < 1e-10 * scale


def test_meshes():
    levels = list(lshape.mesh_hierarchy(3, h0=0.5))
    assert set(levels[0].GetBoundaries()) == {"reentrant", "outer"}
    h = [lshape.max_edge_length(m) for m in levels]
    assert h[0] < 1.5 * 0.5  # netgen's maxh is a target, not a bound
    for k in range(2):
        assert abs(h[k + 1] / h[k] - 0.5) < 1e-12  # red refinement halves every edge
        assert levels[k + 1].ne == 4 * levels[k].ne
    graded = lshape.lshape_mesh(2, h0=0.5, gamma=4.0)
    assert graded.nv == levels[2].nv
    for m in (levels[2], graded):
        assert abs(ng.Integrate(1, m) - 3.0) < 1e-12  # the map keeps the domain
        # every boundary vertex stays on the boundary of the L
        for el in m.Elements(ng.BND):
            for p in el.vertices:
                x, y = m.vertices[p.nr].point
                on_outer = abs(max(abs(x), abs(y)) - 1) < 1e-14
                on_reentrant = (abs(y) < 1e-14 and x >= 0) or (abs(x) < 1e-14 and y <= 0)
                assert on_outer or on_reentrant
    # grading concentrates vertices at the corner
    def near(m):
        return sum(1 for p in m.vertices if np.hypot(*p.point) < 0.1)
    assert near(graded) > 5 * near(levels[2])


def test_bad_input():
    with pytest.raises(ValueError, match="levels"):
        lshape_study(1, -1)
    with pytest.raises(ValueError, match="order"):
        lshape_study(0, 3)
    with pytest.raises(ValueError, match="variant"):
        lshape_study(1, 3, variant="neumann")
    with pytest.raises(ValueError, match="mesh"):
        lshape_study(1, 3, mesh="adaptive")
    with pytest.raises(ValueError, match="model"):
        lshape_study(1, 3, model="mooney")
    with pytest.raises(ValueError, match="gamma"):
        lshape.grade(lshape.geometry().GenerateMesh(maxh=1.0), 0.5)
    with pytest.raises(ValueError, match="nu"):
        lshape.LShapeSolution(E=1.0, nu=0.5)


def test_energy_error_against_quadrature(sol):
    # Where the corner is resolved (graded, gamma = 4) the plain quadrature of
    # |u - uh|_a converges to the boundary-integral value, from below.
    mesh = lshape.lshape_mesh(3, gamma=4.0)
    uh = solve_plain(mesh, 1, sol, "dirichlet")
    _, rel_energy = lshape.relative_errors(mesh, uh, sol, 1)
    e_ex = ng.Sym(_grad_cf(sol.u))
    de = e_ex - ng.Sym(ng.Grad(uh))
    num = ng.Integrate(ng.InnerProduct(sol.sigma - sol.stress_of(uh), de), mesh, order=12)
    den = ng.Integrate(ng.InnerProduct(sol.sigma, e_ex), mesh, order=12)
    quad = math.sqrt(num / den)
    assert quad <= rel_energy
    assert (rel_energy - quad) / rel_energy < 1e-5


def _table(res):
    print(f"\norder {res['order']} {res['variant']} {res['mesh']}")
    for r in res["levels"]:
        print(f"  {r['level']} {r['ndof']:7d} h={r['h']:.4f} L2={r['rel_l2']:.4e} E={r['rel_energy']:.4e}")
    print("  rates", res["rates"])


@pytest.mark.parametrize("variant", ["dirichlet", "traction-free"])
@pytest.mark.parametrize("order", [1, 2])
def test_uniform_rates(order, variant):
    # 6 meshes (5 refinements) of h0 = 0.5: 23k dofs for P1, 91k for P2, about 2 s each.
    res = lshape_study(order, 6, variant=variant, mesh="uniform")
    _table(res)
    alpha = res["alpha"]
    assert abs(res["rates"]["energy"] - alpha) < 0.05
    assert res["rates"]["l2"] >= 1.0
    if variant == "traction-free":
        assert abs(res["rates"]["l2"] - 2 * alpha) < 0.1  # Aubin-Nitsche: h^(2 alpha)
    errs = [r["rel_energy"] for r in res["levels"]]
    assert all(b < a for a, b in zip(errs, errs[1:]))


@pytest.mark.parametrize("order", [1, 2])
def test_graded_rates(order):
    # Graded meshes restore the optimal rate: energy error ~ ndof^(-p/2).
    res = lshape_study(order, 6, variant="dirichlet", mesh="graded")
    _table(res)
    rate_ndof = -2 * fit_rate([r["ndof"] for r in res["levels"]], [r["rel_energy"] for r in res["levels"]])
    assert rate_ndof > order - 0.15
    assert res["rates"]["energy"] > order - 0.15


def test_set_versus_nodal_data(sol):
    # The docstring of ngfracture.studies.verify: Set() and nodal (dual) Dirichlet data change the
    # L2 error, not the energy rate alpha.
    e = {False: [], True: []}
    h = []
    for level, mesh in enumerate(lshape.mesh_hierarchy(6)):
        if level < 3:
            continue
        h.append(lshape.max_edge_length(mesh))
        for dual in e:
            e[dual].append(lshape.relative_errors(mesh, solve_plain(mesh, 1, sol, dual=dual), sol, 1))
    for dual in e:
        assert abs(fit_rate(h, [x[1] for x in e[dual]]) - sol.alpha) < 0.05
    for a, b in zip(e[False], e[True]):
        assert abs(a[1] / b[1] - 1) < 0.2
        assert not math.isclose(a[0], b[0], rel_tol=0.2)  # the L2 errors do differ


@pytest.mark.parametrize("variant", ["dirichlet", "traction-free"])
@pytest.mark.parametrize("order", [1, 2])
def test_ngfracture_matches_plain_solve(sol, order, variant):
    # Same space, same Set() data, same linear problem: the solutions agree to rounding.
    mesh = lshape.lshape_mesh(2)
    a = solve_plain(mesh, order, sol, variant)
    b = solve_ngfracture(mesh, order, sol, variant)
    d = a.vec.CreateVector()
    d.data = a.vec - b.vec
    assert d.Norm() < 1e-10 * a.vec.Norm()


def test_hyperelastic_models_approach_linear(sol):
    # Eq. 15 is linear-elastic; at E = 1e5 the strains are ~1e-5, so the model error of
    # St Venant-Kirchhoff is far below the discretisation error of a coarse mesh.
    mesh = lshape.lshape_mesh(2)
    lin = lshape.relative_errors(mesh, solve_ngfracture(mesh, 1, sol), sol, 1)
    svk = lshape.relative_errors(mesh, solve_ngfracture(mesh, 1, sol, model="svk"), sol, 1)
    assert abs(svk[0] / lin[0] - 1) < 1e-2
    assert abs(svk[1] / lin[1] - 1) < 1e-3
    with pytest.raises(ValueError, match="solver='ngfracture'"):
        lshape_study(1, 2, model="svk", solver="plain")


def test_time_to_error_interpolation():
    # Runs on an exact power law err = 2 t^-0.5: interpolation and extrapolation are exact.
    t = np.array([0.1, 0.4, 1.6, 6.4])
    e = 2 * t**-0.5
    for target in (3.0, 2.0, 1.2):
        sec, extra = time_to_error(t, e, target)
        assert abs(sec / (2 / target) ** 2 - 1) < 1e-12 and not extra
    for target in (0.1, 10.0):
        sec, extra = time_to_error(t, e, target)
        assert abs(sec / (2 / target) ** 2 - 1) < 1e-12 and extra
    with pytest.raises(ValueError, match="decrease"):
        time_to_error([1, 2], [1e-2, 2e-2], 1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["dirichlet", "traction-free"])
@pytest.mark.parametrize("order,levels", [(1, 8), (2, 7)])
def test_uniform_rates_fine(order, levels, variant):
    # Up to 370k dofs: the rates closer to the asymptotic ones.
    res = lshape_study(order, levels, variant=variant, mesh="uniform")
    _table(res)
    alpha = res["alpha"]
    assert abs(res["rates"]["energy"] - alpha) < 0.02
    assert res["rates"]["l2"] >= 1.0
    if variant == "traction-free":
        assert abs(res["rates"]["l2"] - 2 * alpha) < 0.05


if __name__ == "__main__":
    for variant in ("dirichlet", "traction-free"):
        for order in (1, 2):
            test_uniform_rates(order, variant)
