"""The 3D contact set-up made once per mesh (``contact/setup3d.py``) gives the results of
making it afresh, bit for bit, and is never taken for other arrays.

- ``ContactSolver`` with ``setups``: a solve on a second problem of the same mesh takes the
  set-up of the first (no new one made) and gives the displacement, active keys,
  multipliers and imposed rows of a solve that makes its own, bit for bit;
- ``ActiveSet3d``'s three rounds on overlapping blocks (lips, junctions of 4 and 8 copies):
  candidates, keys, gaps, chosen rows and settling equal with and without a reused set-up,
  and the set-up's fixed rows unchanged by the solve;
- ``MeshSetups`` makes a new set-up where one bit of the arrays differs;
- a run (blocks3d, through ``run.step.LoadStep``) makes one set-up for its mesh, and its
  accepted displacements equal those of a run making one per solve, bit for bit.
"""
import dataclasses

import numpy as np
import pytest

from ngfracture.contact.active_set3d import ActiveSet3d
from ngfracture.contact.setup3d import MeshSetup3d, MeshSetups
from ngfracture.contact.solver import ContactSolver
from ngfracture.geometry.solid import solid_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.scenes import two_blocks_mesh

from blocks3d import assert_same_rows, block_geometry, overlapping_blocks

CELLS, PIECES = 4, 2


def _blocks_problem(mesh, top):
    prob = ElasticProblem(mesh, LinearElastic(E=3.0, nu=0.25))
    prob.add_dirichlet("lower_zmin", 0.0, component="z")
    prob.add_dirichlet("upper_zmax", top, component="z")
    return prob


def _solve(prob, setups):
    result = ContactSolver(prob, tol=1e-4, method="full", setups=setups).solve()
    assert result.converged, result.reason
    return result


def test_a_later_solve_on_the_mesh_takes_the_set_up_and_equals_a_fresh_one():
    mesh = solid_mesh(two_blocks_mesh())
    setups = MeshSetups()
    _solve(_blocks_problem(mesh, -1e-3), setups)               # the first solve makes it
    assert setups.made == 1
    cached_prob, fresh_prob = _blocks_problem(mesh, -2e-3), _blocks_problem(mesh, -2e-3)
    assert cached_prob.arrays is not fresh_prob.arrays          # arrays made per problem
    cached, fresh = _solve(cached_prob, setups), _solve(fresh_prob, None)
    assert setups.made == 1                                     # reused, not made again
    assert len(fresh.active_keys) > 20 and cached.active_keys == fresh.active_keys
    assert cached.rounds == fresh.rounds
    assert np.array_equal(cached.multipliers, fresh.multipliers)
    assert_same_rows(cached.constraints, fresh.constraints)
    assert np.array_equal(cached_prob.u.vec.FV().NumPy(), fresh_prob.u.vec.FV().NumPy())


def _rounds(geometry, U, setups):
    """The benchmark's two rounds (benchmarks/contact3d.py): at U, then at 0 (lips closed);
    and a third at 0, where the set of the second settles."""
    active = ActiveSet3d(geometry, 1e-12, setups=setups)
    out = []
    for rnd, u in ((1, U), (2, np.zeros_like(U)), (3, np.zeros_like(U))):
        candidates = active.update(u, {"collision": 0.0})
        want, kept, other = active.primal_dual(candidates)
        kept, settled = active.choose(candidates, want, kept, rnd, lambda rows, indices: None)
        verdict = active.settle(candidates, other, u)[0] if settled else None
        out.append((candidates, want, kept, other, settled, verdict))
        active.record(candidates.keys, kept, -np.ones(len(kept)), 1.0)
    return out, active.multipliers


def test_active_set_rounds_with_a_reused_set_up_equal_fresh_ones():
    arrays, piece, _, U = overlapping_blocks(CELLS, PIECES, 0.2 / CELLS * PIECES, noise=0.02 / CELLS)
    setups = MeshSetups()
    first, _ = _rounds(block_geometry(arrays, piece), U, setups)
    setup = setups.setup(arrays.points, arrays.tets, arrays.faces, piece)
    rows_before = setup.rows.subset(np.arange(len(setup.rows)))
    # another copy of the arrays, bitwise equal: the set-up is reused
    copy = dataclasses.replace(arrays, points=arrays.points.copy(), tets=arrays.tets.copy(),
                               faces=arrays.faces.copy())
    reused, mult_reused = _rounds(block_geometry(copy, piece.copy()), U, setups)
    fresh, mult_fresh = _rounds(block_geometry(arrays, piece), U, None)
    assert setups.made == 1 and setups.setup(copy.points, copy.tets, copy.faces, piece) is setup
    assert len(fresh[0][0].keys) > 100 and first[2][4] and fresh[2][4]      # settled in round 3
    for a, b in zip(reused, fresh):
        assert_same_rows(a[0].rows, b[0].rows)
        assert np.array_equal(a[0].keys.codes, b[0].keys.codes)
        assert np.array_equal(a[0].gap, b[0].gap)
        for i in (1, 2, 3):
            assert np.array_equal(a[i], b[i])
        assert a[4:] == b[4:]
    assert mult_reused == mult_fresh
    assert_same_rows(setup.rows, rows_before)                         # the solve left the set-up alone


@pytest.mark.parametrize("change", ["point", "negative_zero", "tet", "fragment", "dtype"])
def test_a_set_up_is_made_again_where_one_bit_of_the_arrays_differs(change):
    arrays, piece, _, _ = overlapping_blocks(2, 2, 0.0)
    X, T, F, frag = arrays.points.copy(), arrays.tets.copy(), arrays.faces.copy(), piece.copy()
    setups = MeshSetups()
    setup = setups.setup(X, T, F, frag)
    assert setups.setup(X.copy(), T.copy(), F.copy(), frag.copy()) is setup
    if change == "point":
        X[5, 1] = np.nextafter(X[5, 1], 2.0)
    elif change == "negative_zero":
        zero = np.flatnonzero(X[:, 0] == 0.0)[0]
        X[zero, 0] = -0.0
    elif change == "tet":
        i, j = np.flatnonzero(frag == frag[0])[:2]
        T[[i, j]] = T[[j, i]]               # the same mesh, two tetrahedra of a block swapped
    elif change == "fragment":
        frag[:] = np.where(frag == 0, 1, np.where(frag == 1, 0, frag))    # blocks 0 and 1 renumbered
    else:
        T = T.astype(np.int32) if T.dtype != np.int32 else T.astype(np.int64)
    again = setups.setup(X, T, F, frag)
    assert again is not setup and setups.made == 2
    assert not setup.fits(X, T, F, frag) and again.fits(X, T, F, frag)


def test_the_set_up_copies_its_arrays():
    arrays, piece, _, _ = overlapping_blocks(2, 2, 0.0)
    X = arrays.points.copy()
    setup = MeshSetup3d(X, arrays.tets, arrays.faces, piece)
    X[0, 0] += 1.0
    assert not setup.fits(X, arrays.tets, arrays.faces, piece)
    assert np.array_equal(setup.points, arrays.points)


def test_a_run_with_the_set_up_cache_equals_one_without(tmp_path, monkeypatch):
    """blocks3d through LoadStep: its solves on the one mesh share a set-up, and every
    accepted displacement equals, bit for bit, that of a run making one per solve."""
    from ngfracture.contact import setup3d
    from ngfracture.run.simulation import Simulation
    from ngfracture.scenes import blocks3d
    made, asked = [], []
    cached = setup3d.MeshSetups.setup

    def counted(self, *arrays):
        before = self.made
        out = cached(self, *arrays)
        asked.append(1)
        made.append(self.made - before)
        return out

    def run(folder):
        steps = []
        Simulation(blocks3d(), out=tmp_path / folder, pictures="none").run(
            on_step=lambda accepted: steps.append(accepted.problem.u.vec.FV().NumPy().copy()))
        return steps

    monkeypatch.setattr(setup3d.MeshSetups, "setup", counted)
    with_cache = run("cached")
    assert len(asked) >= 4 and sum(made) == 1          # one mesh: one set-up for every solve
    monkeypatch.setattr(setup3d.MeshSetups, "setup", lambda self, *arrays: setup3d.MeshSetup3d(*arrays))
    without = run("fresh")
    assert len(with_cache) == len(without) >= 4
    for a, b in zip(with_cache, without):
        assert np.array_equal(a, b)
