"""Node-to-face contact rows in 3D (ngfracture.contact.rows3d) and the contact patch test.

Patch test: two blocks of one linear elastic material, the lower [0,1]^2 x [0,1] and the
upper [0,1]^2 x [1,2], meshed with different grids in the interface plane (3 x 3 cells
below, an uneven 4 x 4 above), touching on z = 1. The lower face is fixed in z, the upper
face pushed down by D; x and y are held at two vertices of each block with the values of
the exact solution (translations and the rotation about z, stress-free). The exact solution
is uniaxial stress sigma_zz = -E D / 2, u = (nu D/2 x, nu D/2 y, -D/2 z), linear, so it lies
in the P1 space and satisfies every node-to-face row of the flat interface. With rows of both
passes (every interface vertex a slave) the solve must reproduce it to rounding, and the
force of the rows at every interface node over its consistent nodal area must be the exact
traction (sigma_zz along the normal of the node's block);
with one pass it does not (equilibrium of the master nodes fails, see rows3d's docstring),
which the last patch test checks. The active set is that of the 2D solver
(ActiveSet.primal_dual and record), fed with the 3D rows.
"""
import math

import numpy as np
import pytest

from ngfracture.contact.active_set import ActiveSet, Candidates, Geometry
from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.rows3d import (NodeToFaceRows, face_gap_rows, no_face_rows, node_to_face_rows,
                                       relinearise_node_to_face, twin_rows)
from ngfracture.contact.solver import space_columns_3d
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import merge_bodies, nodal_areas, solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

E, NU, D = 3.0, 0.25, 1e-3
LOWER_GRID = np.linspace(0.0, 1.0, 4)
UPPER_GRID = np.array([0.0, 0.2, 0.45, 0.7, 1.0])


def two_blocks(lift=0.0):
    """The lower and upper block merged into one mesh of two regions (no shared vertices).

    Boundary names are those of box_mesh prefixed by "lower_" / "upper_"."""
    lower = box_mesh(LOWER_GRID, LOWER_GRID, [0.0, 0.5, 1.0])
    upper = box_mesh(UPPER_GRID, UPPER_GRID, [1.0 + lift, 1.5, 2.0])
    return merge_bodies([("lower", lower), ("upper", upper)])


def exact_u(X):
    return np.column_stack([NU * D / 2 * X[:, 0], NU * D / 2 * X[:, 1], -D / 2 * X[:, 2]])


def vertex_at(X, q):
    i = int(np.argmin(np.linalg.norm(X - q, axis=1)))
    assert np.array_equal(X[i], q)
    return i


def impose(prob, rows):
    prob.constraints.clear_rows("contact")
    if len(rows):
        n = prob.fes.ndof // 3
        prob.constraints.add_rows(space_columns_3d(rows.C, rows.nv, n), -rows.g, label="contact")


def contact_offset(prob):
    offset = 0
    for C, _, label in prob.constraints.rows:
        if label == "contact":
            return offset
        offset += C.shape[0]
    return offset


def patch_test(two_pass):
    """The patch test solved by the active set's primal-dual update (see the module docstring).

    two_pass: both blocks' interface vertices are slaves (else the upper block's only)."""
    a = two_blocks()
    X = a.points
    fragment = a.regions - 1
    upper = np.zeros(len(X), dtype=bool)
    upper[a.tets[fragment == 1].ravel()] = True
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("lower_zmin", 0.0, component="z")
    prob.add_dirichlet("upper_zmax", -D, component="z")
    for z in (0.0, 2.0):
        v0, v1 = vertex_at(X, [0.0, 0.0, z]), vertex_at(X, [1.0, 0.0, z])
        prob.add_point_constraint(v0, 0.0, component="x")
        prob.add_point_constraint(v0, 0.0, component="y")
        prob.add_point_constraint(v1, 0.0, component="y")
    status = prob.solve(method="full")                        # the prediction, without rows
    assert status.converged, status.message
    U = vertex_displacement(prob.u)
    # candidates: the pairs touching in the reference configuration (exactly, gap 0) and
    # those penetrating at the prediction. The detection has no precision threshold: at the
    # prediction the perimeter nodes of the interface have moved out by rounding (1e-18)
    # and are not in the lower block; found at the reference, they stay candidates.
    # The corners of the interface are points of both blocks: twins, left out by the
    # detection as closed seams; twin_rows gives them their rows.
    slave = np.ones(len(X), dtype=bool) if two_pass else upper
    touching = NodeToFaceRows.stack([
        node_to_face_rows(X, a.faces, detect_penetrations_3d(X, a.tets, a.faces, fragment), slave=slave),
        twin_rows(X, a.faces, upper)] + ([twin_rows(X, a.faces, ~upper)] if two_pass else []))
    found = node_to_face_rows(X, a.faces, detect_penetrations_3d(X, a.tets, a.faces, fragment, displacement=U),
                              slave=slave)
    known = set(touching.keys())
    rows = NodeToFaceRows.stack([touching, found.subset([k not in known for k in found.keys()])])
    keys = rows.keys()
    fixed = prob.assemble_constraints().fixed_dofs
    n = prob.fes.ndof // 3
    active = ActiveSet(Geometry(arrays=a, fragment=fragment, seams=None, fixed=(fixed // n) * len(X) + fixed % n),
                       tol=0.0, penetration_tol=1e-12)
    history = []
    for _ in range(6):
        gap = rows.C @ U.T.ravel() + rows.g
        want, kept, _ = active.primal_dual(Candidates(rows, keys, gap))
        if active.solved and set(keys[i] for i in kept) == set(active.multipliers):
            break
        impose(prob, rows.subset(kept))
        status = prob.solve(method="full")
        assert status.converged, status.message
        lam = status.multipliers[contact_offset(prob):][:len(kept)]
        history.append((len(kept), active.record(keys, kept, lam, 0.0)))
        U = vertex_displacement(prob.u)
    else:
        raise AssertionError(f"the active set did not settle: {history}")
    lam = np.array([active.multipliers.get(k, 0.0) for k in keys])    # 0: not imposed
    return a, upper, rows, U, lam, history


def test_two_pass_patch_test_transmits_the_exact_uniform_pressure():
    a, upper, rows, U, lam, history = patch_test(two_pass=True)
    X = a.points
    interface = X[:, 2] == 1.0
    assert len(rows) == 25 + 16                                           # corners by twin_rows, both ways
    assert len(history) == 1 and history[0][1] == 0                       # one round, nothing released
    assert history[0][0] == 25 + 16 - 4                                   # reversed corner rows: dependent
    assert np.all(np.abs(rows.normal[:, 2]) == 1.0) and np.all(rows.g == 0.0)
    assert np.all(lam <= 0)                                               # compressive
    # the force the rows put on every interface node, over its consistent nodal area
    force = -(rows.C.T @ lam).reshape(3, -1)
    names = [a.bc_names.index(b) + 1 for b in ("upper_zmin", "lower_zmax")]
    area = nodal_areas(X, a.faces[np.isin(a.face_bc, names)])
    assert np.array_equal(area > 0, interface) and math.fsum(area) == pytest.approx(2.0, rel=1e-14)
    sigma_zz = -E * D / 2
    side = np.where(upper, 1.0, -1.0)                                      # outward normal of the other block
    pressure = -side[interface] * force[2, interface] / area[interface]
    assert np.max(np.abs(pressure / sigma_zz - 1.0)) <= 1e-8
    assert np.max(np.abs(force[:2])) == 0.0                               # frictionless, flat: no shear
    assert np.max(np.abs(U - exact_u(X))) <= 1e-8 * D
    gap = rows.C @ U.T.ravel() + rows.g
    assert gap.min() >= -1e-12
    # the configuration itself: no interface vertex of either block inside the other
    pen = detect_penetrations_3d(X, a.tets, a.faces, a.regions - 1, displacement=U)
    assert pen.gap.min(initial=0.0) >= -1e-12


def test_single_pass_fails_the_patch_test_on_non_matching_meshes():
    """Taylor and Papadopoulos' observation: one pass transmits the slave forces to the
    master nodes by the barycentrics, which is not the master's consistent load of a uniform
    pressure unless the meshes match; the exact field satisfies every row but not equilibrium."""
    a, upper, rows, U, lam, history = patch_test(two_pass=False)
    X = a.points
    assert sorted(rows.slave.tolist()) == np.flatnonzero(upper & (X[:, 2] == 1.0)).tolist()
    assert len(history) == 1 and np.all(lam < 0)
    area = nodal_areas(X, a.faces[a.face_bc == a.bc_names.index("upper_zmin") + 1])
    pressure = lam / area[rows.slave]
    assert np.max(np.abs(pressure / (-E * D / 2) - 1.0)) > 1e-2                # measured 0.49
    assert np.max(np.abs(U - exact_u(X))) > 1e-2 * D                          # measured 3.4e-2 D


def test_rows_measure_the_signed_distance_and_ignore_translations():
    a = two_blocks(lift=0.0)
    X = a.points
    fragment = a.regions - 1
    pen = detect_penetrations_3d(X, a.tets, a.faces, fragment)
    rows = node_to_face_rows(X, a.faces, pen)
    assert len(rows) == 16 + 25 - 8 and np.all(rows.dist == 0.0)          # both sides touch; corners are twins
    t = np.random.default_rng(1).normal(size=3)
    # a translation of everything: C u = 0 up to rounding
    u = np.tile(t, (len(X), 1))
    assert np.max(np.abs(rows.C @ u.T.ravel())) <= 1e-14 * np.linalg.norm(t)
    # the upper block lifted by s: every row, either side the slave, separates by s
    s = 0.01
    u = np.zeros_like(X)
    u[a.tets[fragment == 1].ravel(), 2] = s
    assert np.count_nonzero(rows.normal[:, 2] == -1.0) == 16 - 4 and np.count_nonzero(rows.normal[:, 2] == 1.0) == 25 - 4
    assert np.allclose(rows.C @ u.T.ravel() + rows.g, s, rtol=0, atol=1e-15)


def test_rows_match_the_detected_gaps_and_relinearise_to_themselves():
    a = two_blocks()
    X = a.points
    fragment = a.regions - 1
    U = np.zeros_like(X)
    upper = np.unique(a.tets[fragment == 1])
    U[upper] = [0.013, -0.021, -0.25]                                    # the upper block pushed in by 1/4
    pen = detect_penetrations_3d(X, a.tets, a.faces, fragment, displacement=U)
    rows = node_to_face_rows(X, a.faces, pen)
    assert len(rows) > 0
    gap = rows.C @ U.T.ravel() + rows.g
    assert np.allclose(gap, pen.gap, rtol=0, atol=1e-14)
    again = relinearise_node_to_face(rows, X, U)
    assert np.allclose(again.bary, rows.bary, rtol=0, atol=1e-14)
    assert np.allclose(again.normal, rows.normal, rtol=0, atol=1e-15)
    assert np.allclose(again.dist, pen.gap, rtol=0, atol=1e-14)
    C, g = face_gap_rows(X, rows.slave, rows.master, rows.bary, rows.normal)
    assert (C != rows.C).nnz == 0 and np.array_equal(g, rows.g)
    both = NodeToFaceRows.stack([rows.subset([0]), no_face_rows(len(X)), rows.subset(np.arange(1, len(rows)))])
    assert (both.C != rows.C).nnz == 0 and both.keys() == rows.keys()


def test_twins_get_rows_on_the_other_side():
    a = two_blocks()
    X = a.points
    upper = np.zeros(len(X), dtype=bool)
    upper[a.tets[a.regions == 2].ravel()] = True
    for side, normal in ((upper, 1.0), (~upper, -1.0)):
        rows = twin_rows(X, a.faces, side)
        corners = np.flatnonzero(side & (X[:, 2] == 1.0) & np.isin(X[:, 0], [0, 1]) & np.isin(X[:, 1], [0, 1]))
        assert rows.slave.tolist() == corners.tolist()                     # the four corners, sorted
        assert np.all(rows.normal == [0.0, 0.0, normal]) and np.all(rows.g == 0.0)
        twin = rows.master[rows.bary == 1.0]
        assert np.all(np.sort(rows.bary, axis=1) == [0.0, 0.0, 1.0]) and not side[twin].any()
        assert np.array_equal(X[twin], X[rows.slave])
    assert len(twin_rows(X, a.faces, np.zeros(len(X), dtype=bool))) == 0


def test_bad_input_is_named():
    a = two_blocks()
    X = a.points
    with pytest.raises(ValueError, match="master"):
        face_gap_rows(X, [0], [[0, 1, len(X)]], [[1, 0, 0]], [[0, 0, 1]])
    with pytest.raises(ValueError, match="normal"):
        face_gap_rows(X, [0], [[0, 1, 2]], [[1, 0, 0]], [[0, 0, np.nan]])
    pen = detect_penetrations_3d(X, a.tets, a.faces, a.regions - 1)
    with pytest.raises(ValueError, match="slave"):
        node_to_face_rows(X, a.faces, pen, slave=np.ones(3, dtype=bool))
    with pytest.raises(ValueError, match="space_columns_3d"):
        space_columns_3d(node_to_face_rows(X, a.faces, pen).C, len(X) + 1, len(X) + 1)
    with pytest.raises(ValueError, match="slave"):
        twin_rows(X, a.faces, np.ones(len(X)))
    with pytest.raises(ValueError, match="NodeToFaceRows.stack"):
        NodeToFaceRows.stack([no_face_rows(3), no_face_rows(4)])
