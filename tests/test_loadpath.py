"""A body is broken through when no fragment is strained by the prescribed displacements."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ngfracture import scenes
from ngfracture.run.loadpath import deformed_fragments, load_path_cut, prescribed_increment
from ngfracture import Simulation

# two unit squares, [0,1]^2 and [1,2]x[0,1], each of two triangles; `joined` shares the
# vertices at x = 1, `apart` has its own copies of them (a crack along x = 1)
SQUARES = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], float)
JOINED = np.array([[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]])
APART_POINTS = np.vstack([SQUARES, [[1, 0], [1, 1]]])          # vertices 6, 7 copy 1, 2
APART = np.array([[0, 1, 2], [0, 2, 3], [6, 4, 5], [6, 5, 7]])


def pulled(d=1e-4):
    """x dofs of the left side (x = 0: vertices 0, 3) at -d/2, of the right (x = 2: 4, 5) at +d/2."""
    dofs = np.array([0, 3, 4, 5])
    return dofs, np.array([-d / 2, -d / 2, d / 2, d / 2])


def test_increment_is_the_change_of_the_values_on_the_dofs_fixed_at_both_loads():
    dofs, inc = prescribed_increment(np.array([1, 4, 7]), np.array([0.0, 1.0, 2.0]),
                                     np.array([4, 7, 9]), np.array([3.0, 5.0, 6.0]))
    assert dofs.tolist() == [4, 7] and inc.tolist() == [2.0, 3.0]


def test_a_joined_body_pulled_apart_is_loaded_through():
    dofs, inc = pulled()
    piece, deformed = deformed_fragments(SQUARES, JOINED, dofs, inc)
    assert deformed.tolist() == [True]
    assert not load_path_cut(SQUARES, JOINED, dofs, inc)


def test_pieces_that_each_touch_one_pulled_side_are_cut():
    dofs, inc = pulled()
    piece, deformed = deformed_fragments(APART_POINTS, APART, dofs, inc)
    assert len(deformed) == 2 and not deformed.any()     # each follows its side by a translation
    assert load_path_cut(APART_POINTS, APART, dofs, inc)


def test_a_rigid_motion_loads_nothing():
    """An infinitesimal rotation w (-y, x) plus a translation prescribed on both sides of the
    joined body: exactly a rigid motion, so no fragment is strained and the body is not
    loaded by its prescribed displacements at all (no cut either)."""
    w, t = 3e-5, np.array([1e-4, -2e-4])
    verts = np.array([0, 3, 4, 5])
    motion = t + w * np.column_stack([-SQUARES[verts, 1], SQUARES[verts, 0]])
    dofs = np.concatenate([verts, 6 + verts])
    inc = np.concatenate([motion[:, 0], motion[:, 1]])
    _, deformed = deformed_fragments(SQUARES, JOINED, dofs, inc)
    assert not deformed.any()
    assert not load_path_cut(SQUARES, JOINED, dofs, inc)
    assert not load_path_cut(APART_POINTS, APART, np.concatenate([verts, 8 + verts]), inc)


def test_one_piece_still_carrying_the_load_keeps_the_body_whole():
    """A chip off the left side (a third, separate triangle fixed on the left) does not break
    a body whose main piece still joins both pulled sides."""
    points = np.vstack([SQUARES, [[0, 1.5], [0, 2], [0.5, 2]]])
    triangles = np.vstack([JOINED, [[6, 8, 7]]])
    dofs = np.array([0, 3, 4, 5, 6, 7])
    inc = np.array([-1, -1, 1, 1, -1, -1]) * 5e-5
    _, deformed = deformed_fragments(points, triangles, dofs, inc)
    assert deformed.tolist() == [True, False]
    assert not load_path_cut(points, triangles, dofs, inc)


def test_dofs_that_are_not_vertex_dofs_are_refused():
    with pytest.raises(ValueError, match="P1 vertex dofs"):
        deformed_fragments(SQUARES, JOINED, np.array([12]), np.array([1.0]))


def _joins_left_and_right(arrays):
    """Whether some fragment holds a vertex of the left and one of the right boundary."""
    T = arrays.triangles
    nv = len(arrays.points)
    graph = sp.coo_matrix((np.ones(2 * len(T)), (np.r_[T[:, 0], T[:, 1]], np.r_[T[:, 1], T[:, 2]])), shape=(nv, nv))
    _, piece = connected_components(graph, directed=False)
    left = set(piece[arrays.boundary_segments("left").ravel()].tolist())
    right = set(piece[arrays.boundary_segments("right").ravel()].tolist())
    return bool(left & right)


def test_plate_run_ends_as_broken_when_the_crack_separates_the_pulled_sides():
    """The coarse plate: the run ends within 3 steps of the first step whose fragments no
    longer join the left and right sides (the interlocking halves would keep it loaded),
    and not before that step; the step that separates them stops its crack passes there
    (no pass judges the separated pieces)."""
    steps = []
    result = Simulation(scenes.plate(maxh=0.06, radius=None), pictures="none").run(on_step=steps.append)
    assert result.reason == "broken", result.message
    assert "no fragment connects" in result.message
    joined = [_joins_left_and_right(s.state.arrays) for s in steps]
    separated = joined.index(False) + 1            # the first step without a joining fragment
    assert all(joined[:separated - 1])
    assert separated <= result.state.step <= separated + 3
    assert steps[separated - 1].attempt.broken_through
    assert not any(s.attempt.broken_through for s in steps[:separated - 1])


def test_apply_load_on_a_missing_boundary_is_refused_before_any_work(tmp_path):
    scene = scenes.plate(maxh=0.1, radius=None)
    scene.apply_load = lambda prob, x: prob.add_dirichlet("rigth", x, component="x")
    with pytest.raises(ValueError, match="'rigth'"):
        Simulation(scene, out=tmp_path / "never")
    assert not (tmp_path / "never").exists()
