"""Elasticity on tetrahedral meshes: the same ElasticProblem, materials and constraints as 2D.

A homogeneous deformation lies in the P1 space and satisfies equilibrium exactly, so the
solution of a bar stretched between two gliding ends is the exact one to rounding, for
the linear model and for St Venant-Kirchhoff (whose lateral contraction follows from
S_22 = 0 in closed form); the reaction equals the exact stress times the section.
"""
import functools
import math

import numpy as np
import ngsolve as ng
import pytest
from netgen.csg import CSGeometry, OrthoBrick, Plane, Pnt, Vec

from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.meshcheck import MeshError, validate_mesh
from ngfracture.geometry.solid import SolidArrays, solid_mesh, solid_to_arrays, total_volume
from ngfracture.mechanics.materials import LinearElastic, NeoHookean, StVenantKirchhoff
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.mechanics.resultants import boundary_resultants
from ngfracture.mechanics.rigid import piece_modes

E, NU, STRETCH = 3.0, 0.25, 2e-3


@functools.lru_cache(maxsize=None)
def bar(maxh=0.3):
    """A 2 x 1 x 1 bar, ends named left (x = 0) and right (x = 2), sides named side."""
    geo = CSGeometry()
    body = (OrthoBrick(Pnt(-1, 0, 0), Pnt(3, 1, 1)).bc("side") * Plane(Pnt(0, 0, 0), Vec(-1, 0, 0)).bc("left")
            * Plane(Pnt(2, 0, 0), Vec(1, 0, 0)).bc("right"))
    geo.Add(body.mat("glass"))
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def stretched(mesh, material):
    """The bar pulled by STRETCH at its right end, both ends gliding, rigid modes held at three vertices."""
    prob = ElasticProblem(mesh, material)
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", STRETCH, component="x")
    P = prob.arrays.points
    near = [int(np.argmin(np.linalg.norm(P - q, axis=1))) for q in ([0, 0, 0], [0, 1, 0], [0, 0, 1])]
    prob.add_point_constraint(near[0], 0.0, component="y")
    prob.add_point_constraint(near[0], 0.0, component="z")
    prob.add_point_constraint(near[1], 0.0, component="z")
    prob.add_point_constraint(near[2], 0.0, component="y")
    status = prob.solve(method="full")
    assert status.converged, status.message
    return prob


def test_arrays_round_trip_keeps_names_orientation_and_volume():
    mesh = bar()
    a = solid_to_arrays(mesh)
    x = a.points[a.tets]
    det = np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))
    assert np.all(det > 0)
    y = a.points[a.faces]
    normals = np.cross(y[:, 1] - y[:, 0], y[:, 2] - y[:, 0])
    assert np.all(np.einsum("ij,ij->i", y.mean(axis=1) - [1.0, 0.5, 0.5], normals) > 0)   # convex body: out
    assert total_volume(a.points, a.tets) == pytest.approx(2.0, rel=1e-14)
    b = solid_to_arrays(solid_mesh(a))
    for name in ("points", "tets", "regions", "faces", "face_bc"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert b.bc_names == a.bc_names and b.region_names == ["glass"]
    assert math.fsum(b.boundary_faces("left").shape) and sorted(set(b.bc_names)) == ["left", "right", "side"]


def test_a_bad_solid_mesh_is_named():
    a = solid_to_arrays(bar())
    flipped = SolidArrays(a.points, a.tets.copy(), a.regions, a.region_names, a.faces, a.face_bc, a.bc_names)
    flipped.tets[7, [2, 3]] = flipped.tets[7, [3, 2]]
    with pytest.raises(MeshError, match="tetrahedron 7 .* negatively oriented"):
        validate_mesh(flipped)
    flat = SolidArrays(a.points.copy(), a.tets, a.regions, a.region_names, a.faces, a.face_bc, a.bc_names)
    flat.points[a.tets[3, 3]] = flat.points[a.tets[3, 0]]
    with pytest.raises(MeshError, match="zero volume"):
        validate_mesh(flat)


def test_linear_bar_is_exact_and_its_reaction_is_the_stress_times_the_section():
    prob = stretched(bar(), LinearElastic(E=E, nu=NU))
    P, U = prob.arrays.points, vertex_displacement(prob.u)
    strain = STRETCH / 2
    exact = np.column_stack([strain * P[:, 0], -NU * strain * P[:, 1], -NU * strain * P[:, 2]])
    assert np.abs(U - exact).max() <= 1e-13 * STRETCH
    force = boundary_resultants(prob, prob.out_of_balance())["right"]["force"]
    assert force[0] == pytest.approx(E * strain * 1.0, rel=1e-12)
    assert abs(force[1]) + abs(force[2]) <= 1e-12 * force[0]
    assert prob.energy() == pytest.approx(0.5 * E * strain ** 2 * 2.0, rel=1e-12)


def test_st_venant_kirchhoff_bar_matches_the_closed_form_stretch():
    prob = stretched(bar(), StVenantKirchhoff(E=E, nu=NU))
    mat = prob.materials["glass"]
    lam, mu = mat.lam, mat.mu
    a = STRETCH / 2                                        # axial displacement gradient
    e1 = ((1 + a) ** 2 - 1) / 2
    e2 = -lam * e1 / (2 * lam + 2 * mu)                    # S_22 = S_33 = 0
    b = math.sqrt(1 + 2 * e2) - 1
    P, U = prob.arrays.points, vertex_displacement(prob.u)
    exact = np.column_stack([a * P[:, 0], b * P[:, 1], b * P[:, 2]])
    assert np.abs(U - exact).max() <= 1e-10 * STRETCH
    S11 = (lam + 2 * mu) * e1 + 2 * lam * e2
    force = boundary_resultants(prob, prob.out_of_balance())["right"]["force"][0]
    assert force == pytest.approx((1 + a) * S11 * 1.0, rel=1e-9)          # P11 times the reference section
    assert np.all(prob.min_det_F() == pytest.approx((1 + a) * (1 + b) ** 2, rel=1e-12))


def test_neo_hooke_agrees_with_linear_at_small_strain():
    lin = vertex_displacement(stretched(bar(), LinearElastic(E=E, nu=NU)).u)
    neo = vertex_displacement(stretched(bar(), NeoHookean(E=E, nu=NU)).u)
    # the difference is second order in the strain (1e-3): relative 1e-3 up to a factor of a few
    assert np.abs(neo - lin).max() <= 5 * 1e-3 * np.abs(lin).max()


def test_six_rigid_modes_and_a_floating_body_is_named():
    x = np.random.default_rng(0).random((5, 3))
    dofs, M = piece_modes(x, np.arange(5), 5)
    assert M.shape == (15, 6) and np.linalg.matrix_rank(M) == 6
    # a rigid motion's displacement gradient is skew: the columns are infinitesimal rigid motions
    for j in range(6):
        U = M[:, j].reshape(3, 5).T
        G = np.linalg.lstsq(np.column_stack([x, np.ones(5)]), U, rcond=None)[0][:3].T
        assert np.abs(G + G.T).max() <= 1e-12
    prob = ElasticProblem(bar(0.5), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("left", 0.0, component="x")
    status = prob.solve()
    # x = 0 on one face holds the x translation and the rotations about y and z
    assert not status.converged and "floating body: 3 rigid-body mode(s)" in status.message


def test_3d_refuses_plane_stress_and_pressure():
    with pytest.raises(ValueError, match="plane='strain'"):
        ElasticProblem(bar(0.5), LinearElastic(E=E, nu=NU, plane="stress"))
    prob = ElasticProblem(bar(0.5), LinearElastic(E=E, nu=NU))
    with pytest.raises(ValueError, match="on 2D meshes; use add_traction"):
        prob.add_pressure("right", 1.0)
    with pytest.raises(ValueError, match="component must be"):
        prob.add_dirichlet("left", 0.0, component="w")
