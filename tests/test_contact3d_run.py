"""Contact in 3D runs: the blocks3d scene (the contact patch test through Scene and Simulation).

Two blocks of one linear elastic material, meshed apart with non-matching grids, the upper
pushed down by x (see ngfracture.scenes.contact3d). The exact solution is uniaxial stress
sigma_zz = -E x / (2 h), linear, in the P1 space; with two-pass node-to-face rows the run
must reproduce it to rounding at every step: the contact force at every interface node
(the out-of-balance of the body's internal forces there, which only the contact rows
balance) over the node's consistent nodal area is E x / (2 h), pushing each block away
from the other, to 1e-8 relative. Each step ends without a penetrating vertex, and the
volume is the scene's to the last bit.
"""
import math

import numpy as np
import pytest

from ngfracture.contact.active_set3d import fixed_rows_3d
from ngfracture.geometry.solid import nodal_areas
from ngfracture.geometry.solid import total_volume
from ngfracture.run.invariants import penetration_depth_3d
from ngfracture.run.scene import Scene
from ngfracture.run.simulation import Simulation
from ngfracture.scenes import SCENES, blocks3d, two_blocks_mesh
from ngfracture.scenes.common import GLASS

E, NU = GLASS["E"], GLASS["nu"]


def interface_forces(prob):
    """(vertex, z force of the contact rows, consistent nodal area, block sign) at the interface.

    The sign is +1 for the upper block (pushed up), -1 for the lower one."""
    a = prob.arrays
    X = a.points
    n = prob.fes.ndof // 3
    f = -prob.out_of_balance()                 # internal minus external: the constraints' forces
    out = []
    for name, sign in (("upper_zmin", 1.0), ("lower_zmax", -1.0)):
        faces = a.faces[a.face_bc == a.bc_names.index(name) + 1]
        area = nodal_areas(X, faces)
        for v in np.unique(faces):
            out.append((v, f[2 * n + v], f[v], f[n + v], area[v], sign))
    return out


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    steps = []

    def on_step(accepted):
        prob = accepted.problem
        steps.append((accepted.state.x, interface_forces(prob), penetration_depth_3d(prob),
                      total_volume(prob.arrays.points, prob.arrays.tets), accepted.record))

    result = Simulation(blocks3d(), out=tmp_path_factory.mktemp("blocks3d"), pictures="none").run(on_step=on_step)
    return result, steps


def test_blocks3d_ends_at_load_max(run):
    result, steps = run
    assert result.ok and result.reason == "load_max", result.message
    assert steps[-1][0] == blocks3d().load_max
    assert len(steps) >= 2


def test_every_step_transmits_the_uniform_pressure(run):
    _, steps = run
    for x, forces, _, _, _ in steps:
        p = E * x / 2.0                           # |sigma_zz| with h = 1
        assert len(forces) == 16 + 25             # 4 x 4 lower and 5 x 5 upper interface vertices
        for v, fz, fx, fy, area, sign in forces:
            assert abs(fz / area - sign * p) <= 1e-8 * p, (x, v, fz / area, sign * p)
            assert abs(fx) <= 1e-8 * p * area and abs(fy) <= 1e-8 * p * area, (x, v, fx, fy)


def test_no_penetration_and_volume_to_the_last_bit(run):
    _, steps = run
    a = two_blocks_mesh()
    volume = total_volume(a.points, a.tets)
    assert volume == 2.0
    diameter = math.sqrt(1 + 1 + 4)
    for x, _, depth, vol, record in steps:
        assert vol == volume
        assert depth <= 1e-10 * diameter, (x, depth)
        assert record["overlap_area"] == depth


def test_fixed_rows_are_the_touching_pairs_and_twins_of_both_passes():
    a = two_blocks_mesh()
    rows, keys = fixed_rows_3d(a.points, a.tets, a.faces, a.regions - 1)
    assert len(set(keys)) == len(keys) == len(rows)
    interface = set(np.flatnonzero(a.points[:, 2] == 1.0).tolist())
    assert set(rows.slave.tolist()) == interface               # every interface vertex a slave
    assert np.all(np.abs(rows.normal[:, 2]) == 1.0)
    assert np.all(rows.g == 0.0)


def test_scene_is_registered_and_3d_refine_still_refused():
    assert SCENES["blocks3d"] is blocks3d
    s = blocks3d()
    with pytest.raises(ValueError, match="refine"):
        Scene(name="x", mesh=s.mesh, material=s.material, critical=s.critical, apply_load=s.apply_load,
              load_max=s.load_max, dx=s.dx, contact_tol=s.contact_tol, contact=True, radius=s.radius,
              refine=True).validate()
    with pytest.raises(ValueError, match="steps"):
        blocks3d(steps=0)
    with pytest.raises(ValueError, match="displacement"):
        blocks3d(displacement=-1.0)


@pytest.mark.parametrize("fix", [True, "all"])
def test_contact_solver_holds_the_free_modes_of_3d_pieces(fix):
    """Without the corner holds the in-plane rigid modes of both blocks are free: the solver
    holds them (fix_free_modes True: the modes contact leaves free; "all": all six modes of
    every piece, contact rows dependent on them dropped), and the pressure is still exact."""
    from ngfracture.contact.solver import ContactSolver
    from ngfracture.geometry.solid import solid_mesh
    from ngfracture.mechanics.materials import LinearElastic
    from ngfracture.mechanics.problem import ElasticProblem
    a = two_blocks_mesh()
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=3.0, nu=0.25))
    prob.add_dirichlet("lower_zmin", 0.0, component="z")
    prob.add_dirichlet("upper_zmax", -1e-3, component="z")
    result = ContactSolver(prob, tol=1e-4, fix_free_modes=fix, method="full").solve()
    assert result.converged, result.reason
    assert all(k[0] == "f" for k in result.active_keys) and np.all(result.multipliers <= 0.0)
    p = 3.0 * 1e-3 / 2
    for v, fz, fx, fy, area, sign in interface_forces(prob):
        assert abs(fz / area - sign * p) <= 1e-8 * p, (v, fz / area)


def test_the_invariant_finds_faces_crossing_with_no_vertex_inside():
    """Two unit cubes of one grid cell each, the upper turned 45 degrees about the vertical
    axis and moved down by 0.01: no vertex of either lies inside the other (the turned
    corners stick out past the lower cube's sides, the lower corners past the turned
    square's edges), yet they share the octagon of the two squares (2 (sqrt 2 - 1) = 0.828)
    times 0.01. check_state refuses it by the overlap volume."""
    from ngfracture.geometry.solid import merge_bodies, solid_mesh
    from ngfracture.geometry.structured import box_mesh
    from ngfracture.mechanics.materials import LinearElastic
    from ngfracture.mechanics.problem import ElasticProblem
    from ngfracture.run.invariants import check_state, overlap_volume_3d
    a = merge_bodies([("lower", box_mesh([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])),
                      ("upper", box_mesh([0.0, 1.0], [0.0, 1.0], [1.0, 2.0]))])
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=3.0, nu=0.25))
    n = prob.fes.ndof // 3
    upper = np.unique(a.tets[a.regions == 2])
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
    x, y = a.points[upper, 0] - 0.5, a.points[upper, 1] - 0.5
    u = prob.u.vec.FV().NumPy()
    u[upper], u[n + upper], u[2 * n + upper] = c * x - s * y - x, s * x + c * y - y, -0.01
    assert penetration_depth_3d(prob) == 0.0
    assert overlap_volume_3d(prob) == pytest.approx(0.01 * 2 * (math.sqrt(2) - 1), rel=1e-12)
    violation, depth = check_state(prob, total_volume(a.points, a.tets), True)
    assert violation is not None and violation.invariant == "overlap" and depth == 0.0
    assert "faces crossing" in violation.message


def test_the_invariant_finds_a_penetrating_vertex():
    """Upper block moved down by 0.01 rigidly, no contact: its lower face is 0.01 deep in the
    lower block (and the lower block's top face 0.01 deep in it), which check_state refuses."""
    from ngfracture.geometry.solid import solid_mesh
    from ngfracture.mechanics.materials import LinearElastic
    from ngfracture.mechanics.problem import ElasticProblem
    from ngfracture.run.invariants import check_state
    a = two_blocks_mesh()
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=3.0, nu=0.25))
    n = prob.fes.ndof // 3
    upper = np.unique(a.tets[a.regions == 2])
    prob.u.vec.FV().NumPy()[2 * n + upper] = -0.01
    assert penetration_depth_3d(prob) == pytest.approx(0.01, rel=1e-12)
    violation, depth = check_state(prob, total_volume(a.points, a.tets), True)
    assert violation is not None and violation.invariant == "overlap" and depth == violation.size
    assert check_state(prob, total_volume(a.points, a.tets), False) == (None, 0.0)
    with pytest.raises(ValueError, match="dimension"):
        from ngfracture.scenes import plate
        penetration_depth_3d(ElasticProblem(plate(maxh=0.2).mesh, LinearElastic(E=3.0, nu=0.25)))
