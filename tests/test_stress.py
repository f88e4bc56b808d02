"""Stress suite without the simulation driver: each case asserts a number.

Covered elsewhere: near-incompressible nu = 0.49/0.499/0.4999 and a stiffness contrast of
1e6 (test_solver.py), 2000 coincident contact rows of rank r (test_contact_rows.py).
"""
import math
import re
import warnings

import ngsolve as ng
import numpy as np
import pytest

import ngfracture as nf
from ngfracture import fracture
from ngfracture.fracture import vertex_displacement
from ngfracture.linalg.sparse import to_scipy
from ngfracture.geometry.meshcheck import MeshQualityWarning
from ngfracture.geometry.meshio import MeshArrays, merge_meshes, mesh_from_arrays
from conftest import square_mesh


def sliver_square(aspect):
    """The unit square in four triangles; triangle 2 = (0, 4, 2) is a sliver of the given aspect.

    Vertex 4 lies sqrt(2)/aspect below the diagonal from vertex 0 to vertex 2, so triangle 2
    has longest edge sqrt(2) and height sqrt(2)/aspect.
    """
    d = 1.0 / aspect
    P = np.array([(0, 0), (1, 0), (1, 1), (0, 1), (0.5 + d, 0.5 - d)])
    T = np.array([(0, 1, 4), (1, 2, 4), (0, 4, 2), (0, 2, 3)])
    S = np.array([(0, 1), (1, 2), (2, 3), (3, 0)])
    return mesh_from_arrays(MeshArrays(P, T, np.ones(4, dtype=np.int64), ["solid"], S,
                                       np.arange(1, 5), ["bottom", "right", "top", "left"]))


def uniaxial_problem(mesh, traction=1e-3, nu=0.25):
    """Plane-stress bar: gliding on the left, traction on the right; exact P1 solution
    u = t/E (x, -nu y) with E = 1."""
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, nu, plane="stress"))
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_point_constraint(0, 0.0, component="y")
    prob.add_traction("right", (traction, 0.0))
    P = mesh.ngmesh.Coordinates()[:, :2]
    return prob, traction * np.column_stack([P[:, 0], -nu * P[:, 1]])


def test_sliver_warns_with_its_number_and_solves():
    with pytest.warns(MeshQualityWarning, match=re.escape("worst: triangle 2 (vertices 0, 4, 2, aspect ratio 1.00e+06)")):
        prob, exact = uniaxial_problem(sliver_square(1e6))
    assert np.all(np.isfinite(to_scipy(prob.tangent()).data))
    status = prob.solve()
    assert status.converged, status.message
    # measured 6.6e-11: the rounding error grows with the conditioning (aspect * eps)
    err = np.abs(vertex_displacement(prob.u) - exact).max() / 1e-3
    assert err < 1e-8


@pytest.mark.parametrize("aspect", [1e9, 1e12, 1e14])
def test_near_degenerate_triangle_warns_and_never_returns_garbage(aspect):
    """Measured: 1e9 ends in max_iterations (increments stall at 1e9 eps), 1e12 and 1e14 in singular
    (the factorisation fails its own residual check); the tangent stays finite throughout."""
    with pytest.warns(MeshQualityWarning, match=re.escape(f"triangle 2 (vertices 0, 4, 2, aspect ratio {aspect:.2e})")):
        prob, exact = uniaxial_problem(sliver_square(aspect))
    assert np.all(np.isfinite(to_scipy(prob.tangent()).data))
    status = prob.solve()
    U = vertex_displacement(prob.u)
    assert np.all(np.isfinite(U))
    if status.converged:
        assert np.abs(U - exact).max() / 1e-3 < 1e-2
    else:
        assert status.reason in ("max_iterations", "singular"), status.message
        assert np.all(U == 0.0)                      # the last converged state, not an iterate


def test_good_meshes_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshQualityWarning)
        nf.ElasticProblem(square_mesh(0.1), nf.LinearElastic(1.0, 0.3))
        nf.ElasticProblem(sliver_square(1e2), nf.LinearElastic(1.0, 0.3))   # aspect 100: below 1e3


def fifty_triangles_and_a_square():
    """A unit square plus 50 single free triangles from 0.3 down to 1e-3 in size (x > 1.5)."""
    n = 50
    sizes = np.geomspace(0.3, 1e-3, n)
    corner = np.column_stack([1.5 + 0.4 * (np.arange(n) % 10), 0.4 * (np.arange(n) // 10)])
    P = np.concatenate([corner, corner + np.column_stack([sizes, 0 * sizes]),
                        corner + np.column_stack([0.3 * sizes, sizes])])
    i = np.arange(n)
    T = np.column_stack([i, i + n, i + 2 * n])
    S = np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]])
    pieces = mesh_from_arrays(MeshArrays(P, T, np.ones(n, dtype=np.int64), ["default"], S,
                                         np.ones(3 * n, dtype=np.int64), ["crack"]))
    return merge_meshes(square_mesh(0.25), pieces)


@pytest.mark.parametrize("cls", [nf.LinearElastic, nf.StVenantKirchhoff])
def test_fifty_one_triangle_fragments_at_once(cls):
    mesh = fifty_triangles_and_a_square()
    prob = nf.ElasticProblem(mesh, cls(1.0, 0.3))
    assert prob.fragments()[0] == 51
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_dirichlet("right", (0.05, 0.01))
    status = prob.solve()
    assert status.reason == "singular" and "150 rigid-body mode(s)" in status.message
    status = prob.solve(fix_free_modes=True)
    assert status.converged, status.message
    U = vertex_displacement(prob.u)
    free = mesh.ngmesh.Coordinates()[:, 0] > 1.4
    assert free.sum() == 150
    assert np.all(np.isfinite(U)) and np.abs(U).max() < 0.1   # twice the largest prescribed value
    assert np.abs(U[free]).max() < 1e-12
    E = prob.strain()
    free_strain = math.sqrt(ng.Integrate(ng.IfPos(ng.x - 1.4, 1, 0) * ng.InnerProduct(E, E), mesh, order=2))
    body_strain = math.sqrt(ng.Integrate(ng.IfPos(1.4 - ng.x, 1, 0) * ng.InnerProduct(E, E), mesh, order=2))
    assert free_strain < 1e-12 and body_strain > 0.01


def test_vertices_a_rounding_error_from_the_threshold_split_in_one_order():
    """Principal values c(1 + 1e-15) (twice: a tie), the next double above c, c itself and
    c(1 - 1e-15): only the first three split, by decreasing value, ties by vertex number."""
    mesh = square_mesh(0.25)
    c = 1e-3
    P = mesh.ngmesh.Coordinates()[:, :2]
    # interior vertices far apart, so that one split does not touch another's fan
    targets = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75), (0.5, 0.5)]
    v = [int(np.argmin(np.hypot(*(P - t).T))) for t in targets]
    values = [c * (1 + 1e-15), np.nextafter(c, 1.0), c * (1 + 1e-15), c, c * (1 - 1e-15)]
    assert values[1] < values[0] and len(set(v)) == 5
    tensors = np.zeros((mesh.nv, 3))
    tensors[v, 0] = values                           # uniaxial: principal value = xx exactly
    runs = [fracture.split_by_tensor(mesh, tensors, c) for _ in range(3)]
    first, second = sorted([v[0], v[2]])
    assert runs[0].record["vertex"].tolist() == [first, second, v[1]]
    assert runs[0].record["principal"].tolist() == [values[0], values[2], values[1]]
    assert runs[0].nsplit >= 3
    for r in runs[1:]:
        assert r.record.keys() == runs[0].record.keys()
        for key in r.record:
            assert np.array_equal(r.record[key], runs[0].record[key]), key
        assert np.array_equal(r.parent, runs[0].parent)


if __name__ == "__main__":
    raise SystemExit(pytest.main([__file__, "-q"]))
