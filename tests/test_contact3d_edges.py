"""Edge-to-edge contact rows (``contact/edge_rows3d.py``) and their place in the 3D active set.

- The row's gap is the signed distance of the two edges' lines, linearised exactly to first
  order: for a small motion du the linearisation's error is of second order in du.
- Two crossed ridges: a block with a roof along x under a block with an inverted roof along
  y, meshed so that no vertex lies where the ridges meet, pressed together. Without contact
  the ridges pass through each other with no vertex inside the other block; node-to-face
  rows cannot see it. With contact the solve converges with the ridges touching: the
  overlap volume measured from the deformed tetrahedra (exact clipping, independent of the
  contact code) is zero up to rounding, the load goes through edge rows (their multipliers
  compressive) and the force they carry is the reaction of the supports (equilibrium).
- Keys of edge rows: codes and tuples map onto each other.
- ``MixedRows``: selecting and stacking rows of two kinds gives the rows of the kinds
  selected one by one.
"""
import numpy as np
import pytest

from ngfracture.contact.edge_rows3d import EdgeRows, edge_rows, relinearise_edge_rows
from ngfracture.contact.mixed_rows import MixedRows
from ngfracture.contact.setup3d import MeshSetup3d
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import merge_bodies, solid_mesh, tet_volumes
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.mechanics.resultants import boundary_resultants
from ngfracture.output.overlap3d import fragment_overlap_volume

RISE = 0.1          # height of the roofs
GAP = 1e-3          # initial distance of the ridges


def roof(arrays, height, along_y, base, sign):
    """``arrays`` with z moved by sign * height * (1 - |2 c - 1|) * (z - base) / thickness
    (c the x or y coordinate): a roof (sign +1, top face) or an inverted roof (sign -1,
    bottom face) whose ridge lies on the grid line c = 1/2."""
    P = arrays.points.copy()
    c = P[:, 1] if along_y else P[:, 0]
    z = P[:, 2]
    weight = (z - base) / (z.max() - base) if sign > 0 else (z.max() - z) / (z.max() - base)
    P[:, 2] = z + sign * height * (1.0 - np.abs(2.0 * c - 1.0)) * weight
    arrays.points = P
    return arrays


def crossed_ridges():
    """A block with a ridge along x (at y = 1/2, 3 cells along x) under one with a ridge
    along y (at x = 1/2, 3 cells along y), GAP apart: no vertex where the ridges cross."""
    odd, even = np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.0, 5)
    lower = roof(box_mesh(odd, even, [0.0, 0.25, 0.5]), RISE, True, 0.0, +1)
    base = 0.5 + 2 * RISE + GAP                    # the upper ridge at 0.5 + RISE + GAP
    upper = roof(box_mesh(even, odd, [base, base + 0.25, base + 0.5]), RISE, False, base, -1)
    return merge_bodies([("lower", lower), ("upper", upper)])


def pressed(arrays, D, contact):
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=1.0, nu=0.25))
    prob.add_dirichlet("lower_zmin", 0.0)
    prob.add_dirichlet("upper_zmax", -D, component="z")
    prob.add_dirichlet("upper_zmax", 0.0, component="x")
    prob.add_dirichlet("upper_zmax", 0.0, component="y")
    if contact:
        result = ContactSolver(prob, tol=1e-3 * 0.25, method="full").solve()
        assert result.converged, result.reason
    else:
        assert prob.solve().converged
        result = None
    return prob, result


def overlap(prob, arrays):
    U = vertex_displacement(prob.u)
    frag = (arrays.regions - 1).astype(np.int64)
    return fragment_overlap_volume(arrays.points + U, arrays.tets, frag).volume


def test_gap_linearisation_is_exact_to_first_order():
    rng = np.random.default_rng(3)
    X = np.array([[0.0, 0.5, 0.0], [1.0, 0.5, 0.0], [0.5, 0.0, -0.1], [0.5, 1.0, -0.1]])
    edges = np.array([[0, 1], [2, 3]])
    U = rng.normal(scale=1e-2, size=X.shape)
    rows = relinearise_edge_rows(EdgeRows(edges[:1], edges[1:], np.array([[0.5, 0.5]]), np.array([[0.0, 0.0, 1.0]]),
                                          np.zeros(1), np.zeros(1), nv=4), X, U)
    def exact(u):
        x = X + u
        da, db = x[1] - x[0], x[3] - x[2]
        n = np.cross(da, db) / np.linalg.norm(np.cross(da, db))
        return np.dot(n, x[0] - x[2]) * np.sign(np.dot(n, rows.normal[0]))
    assert rows.dist[0] == pytest.approx(exact(U), abs=1e-15)
    errors = []
    for h in (1e-3, 1e-4):
        du = rng.normal(size=X.shape) * h
        linear = rows.C @ (U + du).T.ravel() + rows.g
        errors.append(abs(linear[0] - exact(U + du)))
    assert errors[1] < 2e-2 * errors[0] + 1e-15            # second order: 1e-2 for 1/10 the step


def test_crossed_ridges_pass_through_each_other_without_contact():
    arrays = crossed_ridges()
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, arrays.regions - 1)
    prob, _ = pressed(arrays, 0.02, contact=False)
    U = vertex_displacement(prob.u)
    assert not np.any(setup.detector.detect(U).penetrating)            # no vertex inside
    assert overlap(prob, arrays) > 1e-8                                 # but the ridges cross


def test_crossed_ridges_touch_through_edge_rows():
    arrays = crossed_ridges()
    prob, result = pressed(arrays, 0.02, contact=True)
    volume = float(np.sum(tet_volumes(arrays.points, arrays.tets)))
    assert overlap(prob, arrays) <= 1e-12 * volume
    keys = [k for k in result.active_keys if k[0] == "e"]
    assert keys                                                        # held by edge rows
    edge = result.constraints.kind == 1
    lam = result.multipliers[edge]
    assert np.all(lam < 0)                                             # compressive
    # the force of the rows on the upper block's ridge, -lambda n on edge a (or b), is the
    # load: the vertical reaction of the lower block's support (equilibrium)
    assert np.all(result.constraints.kind == 1)                        # no vertex touches
    rows = result.constraints.parts[1]
    force_z = float(np.sum(lam * rows.normal[:, 2]))
    resultants = boundary_resultants(prob, prob.out_of_balance())
    lower, upper = resultants["lower_zmin"]["force"][2], resultants["upper_zmax"]["force"][2]
    assert lower > 0 and abs(lower + upper) <= 1e-8 * lower
    assert abs(abs(force_z) - lower) <= 1e-8 * lower


def test_edge_keys_round_trip():
    arrays = crossed_ridges()
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, arrays.regions - 1)
    codec, E = setup.codec, setup.edge_detector.edges
    pairs = np.array([[0, 5], [3, 17], [2, len(E) - 1]])
    codes = codec.edge_codes(pairs)
    keys = codec.decode(codes)
    rows = EdgeRows(E[pairs[:, 0]], E[pairs[:, 1]], np.zeros((3, 2)), np.zeros((3, 3)), np.zeros(3), np.zeros(3),
                    nv=len(arrays.points))
    assert keys == [("e", *E[i], *E[j]) for i, j in pairs] == rows.keys()
    assert np.array_equal(codec.codes_of(keys), codes) and np.all(codes < -1)
    assert codec.codes_of([("e", -5, -4, 0, 1)])[0] == -1               # no such edges


def test_mixed_rows_select_and_stack_like_their_parts():
    arrays = crossed_ridges()
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, arrays.regions - 1)
    faces = setup.rows
    X = arrays.points
    E = setup.edge_detector.edges
    rng = np.random.default_rng(0)
    pairs = np.sort(rng.choice(len(E), size=(6, 2), replace=False), axis=1)
    edges = EdgeRows(E[pairs[:, 0]], E[pairs[:, 1]], rng.uniform(size=(6, 2)), np.tile([0.0, 0.0, 1.0], (6, 1)),
                     np.zeros(6), np.zeros(6), nv=len(X))
    mixed = MixedRows([faces, edges])
    pick = np.r_[len(faces) + 2, 0, len(faces), 3, 3, len(faces) + 5]
    sub = mixed.subset(pick)
    full = np.vstack([faces.C.toarray(), edges.C.toarray()])
    assert np.array_equal(sub.C.toarray(), full[pick])
    assert np.array_equal(sub.g, np.concatenate([faces.g, edges.g])[pick])
    both = MixedRows.stack([sub, mixed.subset(pick[::-1])])
    assert np.array_equal(both.C.toarray(), full[np.r_[pick, pick[::-1]]])
    assert np.array_equal(both.kind, (np.r_[pick, pick[::-1]] >= len(faces)).astype(np.int8))


def test_edge_faces_are_the_two_faces_of_every_edge():
    arrays = crossed_ridges()
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, arrays.regions - 1)
    E, F = setup.edge_detector.edges, arrays.faces
    at = setup.faces_at_edge
    for e, (f, g) in zip(E, at):
        assert f < g and set(e) <= set(F[f]) and set(e) <= set(F[g])
    assert len(edge_rows(arrays.points, F, E, at, np.zeros((0, 2), dtype=np.int64), np.zeros_like(arrays.points))[0]) == 0


def test_no_key_and_a_wrong_mask_are_refused():
    arrays = crossed_ridges()
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, arrays.regions - 1)
    with pytest.raises(ValueError, match="no pair of edges"):
        setup.codec.decode(np.array([-1]))
    E = setup.edge_detector.edges
    edges = EdgeRows(E[:3], E[3:6], np.full((3, 2), 0.5), np.tile([0.0, 0.0, 1.0], (3, 1)), np.zeros(3), np.zeros(3),
                     nv=len(arrays.points))
    mixed = MixedRows([setup.rows, edges])
    assert len(mixed) == 3 + len(setup.rows)
    with pytest.raises(ValueError, match="mask"):
        mixed.subset(np.ones(len(mixed) - 1, dtype=bool))
