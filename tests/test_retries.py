"""The retries of a failed load step (ngfracture/run/retries.py, docs/design.md "Retries").

The ladder itself: modified Newton fails, then full Newton at the same increment, then
twice as many Newton load steps of the increment or dx * cut at fixed load; on a
tetrahedral mesh with contact a failed relaxation first takes dx * cut with modified
Newton, and "rescue" stands for full Newton (modified Newton, full Newton only for a
solve that fails with it). Then runs: the coarse confined sphere whose first relaxation of the run is made
to fail (the contact solve's "active_set" reason) is retried from the saved state with dx
* cut and modified Newton; the steps before are the undisturbed run's bit for bit, and
every accepted step keeps the reference volume to the last bit and leaves no vertex in
another piece (``invariant_util.check_accepted_3d``). Where dx cannot be cut, the same
failure twice (the modified attempt's relaxation and the rescue attempt's modified try)
ends in the rescue attempt at the same dx, that one solve with full Newton and noted.
"""
import pytest

import ngfracture as nf
import ngfracture.run.step as step_module
from invariant_util import check_accepted_3d, reference_volume
from ngfracture.geometry.solid import solid_to_arrays
from ngfracture.run.records import StepFailed, StepLog
from ngfracture.run.retries import next_retry
from ngfracture.scenes.spheres import SPHERE_CONTROL

CONTROL = nf.StepControl().resolved(1.0)       # cut 0.5, dx_min 1/64


def ladder(phases, cut_first, dx=1.0):
    """(dx, method, substeps) of the attempts after failures in the given phases."""
    log, steps = StepLog(), []
    for phase in phases:
        dx = next_retry(log, phase, dx, CONTROL, cut_first)
        steps.append(None if dx is None else (dx, log.method, log.substeps))
        if dx is None:
            break
    return steps


def test_a_failed_relaxation_first_takes_full_newton_on_triangles():
    assert ladder(["relaxation"] * 3, cut_first=False) == [(1.0, "full", 1), (0.5, "full", 1), (0.25, "full", 1)]


def test_a_failed_relaxation_with_contact_on_tetrahedra_first_cuts_dx_with_modified_newton():
    assert ladder(["relaxation"] * 4, cut_first=True) == [(0.5, "modified", 1), (0.5, "rescue", 1),
                                                          (0.25, "rescue", 1), (0.125, "rescue", 1)]


@pytest.mark.parametrize("cut_first, full", [(False, "full"), (True, "rescue")])
def test_a_failed_increment_takes_full_newton_then_more_load_steps(cut_first, full):
    assert ladder(["increment"] * 3, cut_first) == [(1.0, full, 1), (1.0, full, 2), (1.0, full, 4)]


def test_the_ladder_ends_where_dx_cannot_be_cut():
    assert ladder(["relaxation"] * 2, cut_first=True, dx=CONTROL.dx_min * 1.5) == [
        (CONTROL.dx_min * 1.5, "rescue", 1), None]


def test_a_cut_relaxation_of_the_sphere_is_solved_with_modified_newton_and_keeps_the_invariants(tmp_path,
                                                                                                 monkeypatch):
    def run(out, fail=False):
        scene = nf.scenes.sphere3d(maxh=0.4, fine=0.15)
        reference = solid_to_arrays(scene.mesh)
        volume = reference_volume(reference.points, reference.tets)
        injected, overlaps = [], []
        contact_equilibrium = step_module.LoadStep._contact_equilibrium

        def failing(self, prob, phase, *args):
            if fail and phase == "relaxation" and not injected:
                injected.append(phase)
                raise StepFailed("active_set", phase, "injected: contact active set did not settle")
            return contact_equilibrium(self, prob, phase, *args)

        monkeypatch.setattr(step_module.LoadStep, "_contact_equilibrium", failing)
        result = nf.Simulation(scene, nf.StepControl(max_steps=4), out=out, pictures="none").run(
            on_step=lambda step: overlaps.append(check_accepted_3d(step, volume)))
        monkeypatch.undo()
        return result, injected, overlaps

    ref, _, _ = run(tmp_path / "ref")
    history = ref.summary["history"]
    k = next(i for i, h in enumerate(history) if h["relax_passes"])     # the first step that relaxes
    result, injected, overlaps = run(tmp_path / "cut", fail=True)     # the first relaxation fails
    assert injected == ["relaxation"] and result.ok, result.message
    hist = result.summary["history"]
    assert hist[:k] == history[:k]
    cut = SPHERE_CONTROL.get("cut", nf.StepControl().cut)
    assert hist[k]["failures"] == ["active_set"] and hist[k]["retries"] == 1
    assert hist[k]["method"] == "modified"
    assert hist[k]["dx"] == history[k]["dx"] * cut
    assert hist[k]["x"] == history[k - 1]["x"] + history[k]["dx"] * cut
    assert len(overlaps) == len(hist)


def test_a_relaxation_that_fails_where_dx_cannot_be_cut_is_rescued_by_full_newton_for_that_solve(tmp_path,
                                                                                                  monkeypatch):
    scene = nf.scenes.sphere3d(maxh=0.4, fine=0.15)
    reference = solid_to_arrays(scene.mesh)
    volume = reference_volume(reference.points, reference.tets)
    control = nf.StepControl(max_steps=4, dx_min=scene.dx)          # no cut below the scene's first dx
    contact_equilibrium = step_module.LoadStep._contact_equilibrium
    methods = []

    def run(out, fail=0):
        def failing(self, prob, phase, options, *args):
            if phase == "relaxation":
                methods.append(options["method"])
                if options["method"] == "modified" and methods.count("modified") <= fail:
                    raise StepFailed("active_set", phase, "injected: contact active set did not settle")
            return contact_equilibrium(self, prob, phase, options, *args)

        methods.clear()
        monkeypatch.setattr(step_module.LoadStep, "_contact_equilibrium", failing)
        overlaps = []
        result = nf.Simulation(scene, control, out=out, pictures="none").run(
            on_step=lambda step: overlaps.append(check_accepted_3d(step, volume)))
        monkeypatch.undo()
        return result, overlaps

    ref, _ = run(tmp_path / "ref")
    history = ref.summary["history"]
    k = next(i for i, h in enumerate(history) if h["relax_passes"])     # the first step that relaxes
    result, overlaps = run(tmp_path / "rescue", fail=2)
    assert result.ok, result.message
    # the modified attempt, the rescue attempt's modified try, then full Newton for that solve only
    assert methods[:3] == ["modified", "modified", "full"] and "full" not in methods[3:]
    hist = result.summary["history"]
    assert hist[:k] == history[:k]
    assert hist[k]["failures"] == ["active_set"] and hist[k]["retries"] == 1 and hist[k]["method"] == "rescue"
    assert hist[k]["dx"] == history[k]["dx"]
    assert any("solved with full Newton" in note for note in hist[k]["notes"])
    assert len(overlaps) == len(hist)
