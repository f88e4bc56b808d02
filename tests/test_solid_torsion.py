"""The twisted shaft (scenes/torsion.py, docs/solid.md "A curved crack: torsion").

Fast: the scene builds, and the first load step's stress is the torsion field
tau = G theta r / L (the shear on planes normal to the axis along e_phi, the only stress
of the exact solution). The P1 stress is constant per tet and the torsion field linear in
r, so each tet's shear divided by its centroid's radius is G theta / L up to the faceting
of the cylinder (its polygonal sections are stiffer or softer by O(h^2 / R^2)) and the
interpolation of the quadratic displacement (O(h^2) in the strain's mean over a tet).
"""
import math

import numpy as np
import pytest

from ngfracture import scenes
from ngfracture.fracture.solid_criterion import stress_over_E, tet_strain
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.mechanics.problem import ElasticProblem

R, L = 0.5, 2.0


def cylindrical(centroids):
    """Radius and the unit vectors e_r, e_phi about the x axis at the given points."""
    r = np.hypot(centroids[:, 1], centroids[:, 2])
    phi = np.arctan2(centroids[:, 2], centroids[:, 1])
    zero = np.zeros_like(phi)
    e_r = np.stack([zero, np.cos(phi), np.sin(phi)], axis=1)
    e_phi = np.stack([zero, -np.sin(phi), np.cos(phi)], axis=1)
    return r, phi, e_r, e_phi


@pytest.fixture(scope="module")
def first_step():
    scene = scenes.shaft3d()
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, scene.dx)
    status = prob.solve()
    assert status.converged, status.message
    return scene, prob


def test_the_scene_is_registered_and_checked():
    assert scenes.SCENES["shaft3d"] is scenes.shaft3d
    assert "twist" in scenes.LOAD_DESCRIPTIONS["shaft3d"]
    with pytest.raises(ValueError, match="pit"):
        scenes.shaft_mesh(0.3, 0.15, pit=0.3)
    with pytest.raises(ValueError, match="maxh"):
        scenes.shaft3d(maxh=-1.0)


def test_the_twisted_end_is_an_exact_rotation():
    theta = 0.3
    cf = scenes.torsion.twisted_end(theta)
    import ngsolve as ng
    mesh = ng.Mesh(scenes.shaft_mesh(0.4, 0.4, pit=0.1).ngmesh)
    p = (1.0, 0.2, -0.3)
    u = np.array(cf(mesh(*p)))
    c, s = math.cos(theta), math.sin(theta)
    assert np.allclose(u, [0.0, c * p[1] - s * p[2] - p[1], s * p[1] + c * p[2] - p[2]], rtol=0, atol=1e-15)


def test_first_step_is_the_torsion_field(first_step):
    scene, prob = first_step
    arrays = prob.arrays
    P, T = np.asarray(arrays.points), np.asarray(arrays.tets)
    S = stress_over_E(tet_strain(arrays, vertex_displacement(prob.u), "linear"), scene.material.E,
                      scene.material.nu)
    C = P[T].mean(axis=1)
    r, _, e_r, e_phi = cylindrical(C)
    # sigma . e_x . e_phi: the (xy, xz) components (rows xx, yy, zz, yz, xz, xy)
    tau = S[:, 5] * e_phi[:, 1] + S[:, 4] * e_phi[:, 2]
    theta, nu = scene.dx, scene.material.nu
    exact_slope = theta / (2 * (1 + nu) * L)          # tau / E over r: G theta / (E L)
    fine = scene.parameters["fine"]
    # away from the pit (the fine band's middle) and from the clamped ends' corners
    away = (np.abs(C[:, 0] - L / 2) > 0.5) & (C[:, 0] > 0.3) & (C[:, 0] < L - 0.3) & (r > 0.1)
    V = np.abs(np.einsum("ij,ij->i", np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]),
                         P[T[:, 3]] - P[T[:, 0]])) / 6
    slope = math.fsum(V[away] * tau[away] * r[away]) / math.fsum(V[away] * r[away] ** 2)
    surface = slope * R / (exact_slope * R)
    # the other stresses vanish in the exact solution
    other = np.abs(S[away][:, [0, 1, 2, 3]]).max() / (exact_slope * R)
    radial = np.einsum("ij,ij->i", S[away][:, [5, 4]], e_r[away][:, [1, 2]])
    h2 = (scene.parameters["maxh"] / R) ** 2
    print(f"\nshaft3d: {len(T)} tets; surface shear / G theta R / L = {surface:.5f}; largest other stress "
          f"{other:.4f}, largest tau_xr {np.abs(radial).max() / (exact_slope * R):.4f} of it; (maxh/R)^2 = {h2:.3f}, "
          f"fine {fine}")
    assert surface == pytest.approx(1.0, abs=h2 / 4)
