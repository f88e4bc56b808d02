"""Material parameters and constraint input are validated before any assembly."""
import math
import re

import ngsolve as ng
import numpy as np
import pytest

import ngfracture as nf
from conftest import square_mesh


NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize("E, nu, message", [
    (NAN, 0.3, "material parameter E must be finite, got nan"),
    (INF, 0.3, "material parameter E must be finite, got inf"),
    (-INF, 0.3, "material parameter E must be finite, got -inf"),
    (1.0, NAN, "material parameter nu must be finite, got nan"),
    (1.0, INF, "material parameter nu must be finite, got inf"),
    (0.0, 0.3, "Young's modulus E must be > 0, got 0.0"),
    (-1.0, 0.3, "Young's modulus E must be > 0, got -1.0"),
    (1.0, 0.5, "Poisson's ratio nu must satisfy -1 < nu < 0.5, got 0.5"),
    (1.0, 0.7, "Poisson's ratio nu must satisfy -1 < nu < 0.5, got 0.7"),
    (1.0, -1.0, "Poisson's ratio nu must satisfy -1 < nu < 0.5, got -1.0"),
    (1.0, -1.5, "Poisson's ratio nu must satisfy -1 < nu < 0.5, got -1.5"),
    ("1", 0.3, "material parameter E must be a number, got '1'"),
    (1.0, None, "material parameter nu must be a number, got None"),
])
@pytest.mark.parametrize("plane", ["strain", "stress"])
@pytest.mark.parametrize("cls", [nf.LinearElastic, nf.StVenantKirchhoff, nf.NeoHookean])
def test_invalid_material_parameters_are_rejected(cls, plane, E, nu, message):
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        cls(E, nu, plane=plane)


def test_numpy_numbers_are_valid_parameters():
    m = nf.NeoHookean(np.int64(5), np.float32(0.25), plane="stress")
    assert (m.E, m.nu) == (5.0, 0.25)


def test_lame_parameters_plane_strain_and_stress():
    E, nu = 5e9, 0.18
    lam, mu = nf.lame_parameters(E, nu, "strain")
    assert mu == pytest.approx(E / (2 * (1 + nu)), rel=1e-15)
    assert lam == pytest.approx(E * nu / ((1 + nu) * (1 - 2 * nu)), rel=1e-15)
    lam_s, mu_s = nf.lame_parameters(E, nu, "stress")
    assert mu_s == mu
    assert lam_s == pytest.approx(E * nu / (1 - nu ** 2), rel=1e-14)
    with pytest.raises(ValueError, match="plane"):
        nf.lame_parameters(E, nu, "axisymmetric")


def test_unknown_boundary_is_an_error_not_zero_constraints(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    with pytest.raises(ValueError, match="'lefft' does not exist"):
        prob.add_dirichlet(["left", "lefft"], (0, 0))
    assert prob.constraints.dirichlet == []


def test_conflicting_values_on_one_dof_are_an_error(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("bottom", (0.1, 0.0))   # the corner (0,0) gets ux = 0 and ux = 0.1
    with pytest.raises(ValueError, match="conflicting constraint values on dof"):
        prob.solve()


def test_agreeing_values_at_a_corner_are_accepted(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    shift = ng.CF((0.1 * ng.x, 0.2 * ng.y))
    prob.add_dirichlet("left", shift)
    prob.add_dirichlet("bottom", shift)
    assert prob.solve().converged


def test_bad_point_constraint_and_component(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    with pytest.raises(ValueError, match="vertex 10000 does not exist"):
        prob.add_point_constraint(10000)
    with pytest.raises(ValueError, match="component"):
        prob.add_dirichlet("left", 0.0, component="z")
    with pytest.raises(ValueError, match="finite"):
        prob.add_dirichlet("left", (math.nan, 0.0))


def test_bad_problem_arguments():
    mesh = square_mesh()
    with pytest.raises(ValueError, match="order"):
        nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3), order=0)
    with pytest.raises(ValueError, match="material"):
        nf.ElasticProblem(mesh, "steel")
    with pytest.raises(ValueError, match="ngsolve.Mesh"):
        nf.ElasticProblem(mesh.ngmesh, nf.LinearElastic(1.0, 0.3))
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    with pytest.raises(ValueError, match="method"):
        prob.solve(method="quasi")
    with pytest.raises(ValueError, match="load_steps"):
        prob.solve(load_steps=0)


def test_gliding_prescribes_one_component_only(square):
    """Gliding on left and right (ux prescribed, uy free) plus one pinned uy: uniaxial stretch."""
    E, nu, d = 100.0, 0.25, 1e-3
    prob = nf.ElasticProblem(square, nf.LinearElastic(E, nu, plane="stress"))
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", d, component="x")
    prob.add_point_constraint(0, 0.0, component="y")
    status = prob.solve()
    assert status.converged, status.message
    # exact plane-stress uniaxial solution: ux = d x, uy = -nu d (y - y0)
    err = ng.Integrate((prob.u - ng.CF((d * ng.x, -nu * d * ng.y))) ** 2, square) ** 0.5
    assert err < 1e-12 * d
