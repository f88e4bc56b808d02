"""Crack initiation in 3D against linear elastic fracture mechanics.

A bar 2 long, 1 wide, with a through-thickness edge crack of depth a = 0.2 at mid-length,
pulled by its gliding ends (u_x = 0 and u_x = x), is cracked when the criterion's measure at
its front reaches the critical strain: the critical-distance criterion's toughness is
K_c = E critical sqrt(2 pi r) (docs/criterion.md, docs/solid.md), so the initiation load is
x_c = K_c / K_I(x = 1). K_I is computed independently of the criterion: by displacement
correlation on a fine 2D mesh of the same bar in plane strain (``studies.lefm_path``; a
plane-strain body is a plane-stress body of E / (1 - nu^2), nu / (1 - nu)).

* With u_z = 0 on both faces the 3D bar is exactly in plane strain. Against LEFM the
  criterion differs by its discretisation error (h / (4 r), 6 % at h = r/4) and by the
  stress terms beyond K at r = a / 10 (the 2D criterion on the same bar reads 11 % above
  K / sqrt(2 pi r) at r = a / 5 and 8 % at a / 10, measured): the bound is the issue's 10 %.
  Against the 2D criterion on the same bar in plane strain, which the 3D one must reproduce,
  the bound is 3 % (the two discretisations: h / (4 r) each, measured 1 %).
* A thick bar with free faces (thickness = width) is in plane strain near its mid-plane;
  there the front's largest measure is within 10 % of the plane-strain load as well (slow).
"""
import math

import numpy as np
import pytest
from criterion3d_util import graded, plane_faces

import ngfracture as nf
from ngfracture.fracture.criterion import Criterion, toughness
from ngfracture.fracture.strain import principal
from ngfracture.geometry.internal_crack import open_internal_surface
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.studies.lefm_path import cracked_polygon, edge_crack_path

E, NU, CRITICAL, RADIUS, DEPTH = 5e9, 0.18, 1.3817e-4, 0.02, 0.2
#: the graded grid's fine zone about the crack front (3 r)
CORE = 0.06


def axis(low, high, centre, h, core):
    """Grid coordinates on [low, high], spacing h within core of centre, graded outside."""
    g = centre + graded(max(centre - low, high - centre), h, core)
    g = g[(g > low + 0.5 * h) & (g < high - 0.5 * h)]
    return np.concatenate([[low], g, [high]])


def cracked_bar(h, zs):
    """The bar with its edge crack opened (crack on x = 1, 0 <= y <= DEPTH, front at y = DEPTH)."""
    box = box_mesh(axis(0.0, 2.0, 1.0, h, CORE), axis(0.0, 1.0, DEPTH, h, CORE), zs)
    faces = plane_faces(box, 0, 1.0, lambda p: p[:, 1] <= DEPTH)
    return open_internal_surface(box, faces)


def initiation_3d(arrays, plane_strain):
    """x / (the largest overstrain on the front) at x = 1e-4, linear material."""
    mesh = solid_mesh(arrays)
    material = nf.LinearElastic(E, NU)
    prob = ElasticProblem(mesh, material)
    prob.add_dirichlet("xmin", 0.0, component="x")
    prob.add_dirichlet("xmax", 1e-4, component="x")
    P = prob.arrays.points
    corner = [int(np.argmin(np.linalg.norm(P - q, axis=1))) for q in ([0, 0, 0], [0, 1, 0])]
    prob.add_point_constraint(corner[0], 0.0, component="y")
    if plane_strain:
        prob.add_dirichlet(["zmin", "zmax"], 0.0, component="z")
    else:
        prob.add_point_constraint(corner[0], 0.0, component="z")
        prob.add_point_constraint(corner[1], 0.0, component="z")
    status = prob.solve()
    assert status.converged, status.message
    values, directions = principal(Criterion(CRITICAL, radius=RADIUS, material=material).overstrain(mesh, prob.u))
    front = np.flatnonzero(np.isclose(P[:, 0], 1.0) & np.isclose(P[:, 1], DEPTH))
    best = front[np.argmax(values[front])]
    return 1e-4 / values.max(), values, directions[best], front


def initiation_lefm():
    """x_c of plane-strain LEFM: K_c over K_I at unit load, by displacement correlation in 2D."""
    def load(prob):
        prob.add_dirichlet("left", 0.0, component="x")
        prob.add_dirichlet("right", 1.0, component="x")
    corners = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]
    path = edge_crack_path(corners, ["bottom", "bottom", "right", "top", "left"], [(1.0, 0.0), (1.0, DEPTH)],
                           load, E / (1 - NU ** 2), NU / (1 - NU), da=0.01, steps=1, maxh=0.1, h_tip=0.002)
    return toughness(CRITICAL, RADIUS, E) / path.k1[0]


def initiation_2d():
    """x_c of the 2D criterion on the same bar in plane strain (a fine netgen mesh at the front)."""
    h = RADIUS / 8
    around = [(1 + i * h, DEPTH + j * h, h) for i in range(-24, 25, 3) for j in range(-24, 25, 3)]
    corners = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]
    mesh = cracked_polygon(corners, ["bottom", "bottom", "right", "top", "left"],
                           np.array([(1.0, 0.0), (1.0, DEPTH)]), 0.1, h, around)
    material = nf.LinearElastic(E, NU, plane="strain")
    prob = ElasticProblem(mesh, material)
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", 1e-4, component="x")
    status = prob.solve(fix_free_modes=True)
    assert status.converged, status.message
    values, _ = principal(Criterion(CRITICAL, radius=RADIUS, material=material).overstrain(mesh, prob.u))
    return 1e-4 / values.max()


def test_plane_strain_bar_starts_to_crack_at_the_lefm_load():
    x_lefm, x_2d = initiation_lefm(), initiation_2d()
    x_3d, values, direction, front = initiation_3d(cracked_bar(RADIUS / 4, np.array([0.0, 0.05, 0.1])), True)
    ratio = x_3d / x_lefm
    print(f"plane strain: x_c 3D {x_3d:.5e}, 2D criterion {x_2d:.5e}, LEFM {x_lefm:.5e}: 3D / LEFM {ratio:.4f}, "
          f"3D / 2D {x_3d / x_2d:.4f}; opening direction {direction}")
    assert abs(ratio - 1) <= 0.10
    assert abs(x_3d / x_2d - 1) <= 0.03
    # the front is where it starts, across the crack plane; through the thickness the field is
    # uniform, the measure within its discretisation error h / (4 r) (the tets differ along z)
    assert values.argmax() in front
    assert abs(direction[0]) >= math.cos(math.radians(10))
    assert np.ptp(values[front]) <= 0.25 * (RADIUS / 4) / RADIUS * values[front].max()


@pytest.mark.slow
def test_thick_bar_starts_to_crack_within_ten_percent_of_plane_strain():
    x_lefm = initiation_lefm()
    x_3d, values, _, front = initiation_3d(cracked_bar(RADIUS / 4, np.linspace(0.0, 1.0, 11)), False)
    print(f"thick bar: x_c 3D {x_3d:.5e}, LEFM {x_lefm:.5e}, ratio {x_3d / x_lefm:.4f}")
    assert values.argmax() in front
    assert abs(x_3d / x_lefm - 1) <= 0.10
