"""The twisted shaft (scenes/torsion.py, docs/solid.md "A curved crack: torsion").

Fast: the scene builds (a hollow shaft by default), and the first load step's stress is the torsion field
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
    with pytest.raises(ValueError, match="hole"):
        scenes.shaft_mesh(0.3, 0.15, hole=0.3)
    with pytest.raises(ValueError, match="bore"):
        scenes.shaft_mesh(0.3, 0.15, bore=0.45)
    with pytest.raises(ValueError, match="maxh"):
        scenes.shaft3d(maxh=-1.0)


def test_the_twisted_end_is_an_exact_rotation():
    theta = 0.3
    cf = scenes.torsion.twisted_end(theta)
    import ngsolve as ng
    mesh = ng.Mesh(scenes.shaft_mesh(0.4, 0.4).ngmesh)
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


# ---- the run, read back from its files ---------------------------------------------------

VTK_TETRA = 10


def tet_dets(points, tets):
    x0 = points[tets[:, 0]]
    return np.einsum("ij,ij->i", np.cross(points[tets[:, 1]] - x0, points[tets[:, 2]] - x0), points[tets[:, 3]] - x0)


def crack_faces(path):
    """Area, unit normal and centroid of the crack faces of a cracks_*.vtp (both lips)."""
    import pyvista as pv
    c = pv.read(path)
    F = np.asarray(c.faces).reshape(-1, 4)[:, 1:]
    Q = np.asarray(c.points, dtype=float)
    cr = np.cross(Q[F[:, 1]] - Q[F[:, 0]], Q[F[:, 2]] - Q[F[:, 0]])
    area = np.linalg.norm(cr, axis=1) / 2
    return area, cr / (2 * area[:, None]), Q[F].mean(axis=1)


def mean_normal(area, local):
    """The principal axis of the area-weighted orientation tensor sum(a n n^T) (normals have no sign)."""
    w, v = np.linalg.eigh(np.einsum("i,ij,ik->jk", area, local, local))
    return v[:, -1] * np.sign(v[np.argmax(np.abs(v[:, -1])), -1])


def helicoid_angles(area, normal, centroid, outer, bins):
    """The mean normal of the crack faces near the outer surface, per sector of phi.

    Returns the angle between the axis and the mean normal over all of them (in the local
    frame e_x, e_phi, e_r of each face, where the helicoid's normal is constant), and per
    sector of phi (rad) the global mean normal's angle with e_phi, and its own direction.
    """
    r, phi, e_r, e_phi = cylindrical(centroid)
    near = r > outer
    local = np.stack([normal[:, 0], np.einsum("ij,ij->i", normal, e_phi), np.einsum("ij,ij->i", normal, e_r)], 1)
    m = mean_normal(area[near], local[near])
    axis_angle = math.degrees(math.acos(min(1.0, abs(m[0]))))
    sectors = []
    for lo, hi in zip(bins[:-1], bins[1:]):
        s = near & (phi >= lo) & (phi < hi)
        if area[s].sum() < 0.02:
            continue
        g = mean_normal(area[s], normal[s])
        mid = (lo + hi) / 2
        tangential = np.array([0.0, -math.sin(mid), math.cos(mid)])
        sectors.append((mid, g, math.degrees(math.acos(min(1.0, abs(g[1:] @ tangential[1:]) /
                                                            max(np.linalg.norm(g[1:]), 1e-300))))))
    return axis_angle, sectors


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    from ngfracture import Simulation
    out = tmp_path_factory.mktemp("shaft") / "run"
    scene = scenes.shaft3d()
    result = Simulation(scene, out=out, pictures="none").run()
    return scene, result, out


@pytest.mark.slow
def test_the_run_keeps_volume_and_orientation(run):
    import pyvista as pv
    from pathlib import Path
    from ngfracture.geometry.solid import solid_to_arrays
    scene, result, out = run
    initial = solid_to_arrays(scene.mesh)
    v0 = math.fsum(tet_dets(np.asarray(initial.points), np.asarray(initial.tets)) / 6)
    for f in sorted(Path(out).glob("step_*.vtu")):
        g = pv.read(f)
        tets = np.asarray(g.cells_dict[VTK_TETRA])
        P = np.asarray(g.points, dtype=float)
        assert math.fsum(tet_dets(P, tets) / 6) == v0, f"{f.name}: the volume changed"
        assert np.all(tet_dets(P + np.asarray(g.point_data["displacement"], dtype=float), tets) > 0), f.name


@pytest.mark.slow
def test_the_crack_is_a_helicoid(run):
    """Near the outer surface the crack's mean normal makes 45 degrees with the axis, and per
    sector of phi it follows (e_x + e_phi) / sqrt(2): it turns with phi around the axis.

    Tolerances: the faces are tet faces within h of the crack surface; over a sector of the
    crack trace (length l = pi R / 4 sqrt(2) = 0.28 at R = 0.5) their mean plane tilts by up to
    atan(h / l) = 20 degrees at h = 0.1; over the whole trace (all sectors together) by
    atan(h / (2 pi R sqrt 2)) = 2.3 degrees, to which the field's change by the crack adds.
    """
    from pathlib import Path
    scene, result, out = run
    area, normal, centroid = crack_faces(sorted(Path(out).glob("cracks_*.vtp"))[-1])
    h = scene.parameters["fine"]
    axis_angle, sectors = helicoid_angles(area, normal, centroid, R - h, np.linspace(-np.pi, np.pi, 9))
    tilt = math.degrees(math.atan(h / (math.pi * R / (4 * math.sqrt(2)))))
    print(f"\nshaft3d run: {result.reason}, {result.summary['n_steps']} steps; mean normal at {axis_angle:.1f} "
          f"degrees to the axis; per sector of phi (degrees): " +
          ", ".join(f"{math.degrees(mid):.0f}: {ang:.1f}" for mid, _, ang in sectors))
    assert axis_angle == pytest.approx(45.0, abs=10.0)
    assert len(sectors) >= 6                            # the crack winds around the shaft
    for mid, g, ang in sectors:
        helix = np.array([1.0, -math.sin(mid), math.cos(mid)]) / math.sqrt(2)
        assert math.degrees(math.acos(min(1.0, abs(g @ helix)))) < tilt + 15.0, (math.degrees(mid), g)
