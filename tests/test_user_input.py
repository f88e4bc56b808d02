"""Input checked before any work, nothing lost; options overridden only where set; no silent path."""
import math
import os

import numpy as np
import pytest

from ngfracture import scenes
from ngfracture.contact import solver as contact_solver
from ngfracture.contact.solver import ContactSolver
from ngfracture.linalg.qp import QPError
from ngfracture import Scene, Simulation, StepControl
from ngfracture.run.timings import PHASES
from ngfracture.mechanics.newton import NewtonSolver
from test_contact_solve import pressed_blocks


def with_load(base, apply_load, **changes):
    fields = dict(name=base.name, mesh=base.mesh, material=base.material, critical=base.critical,
                  apply_load=apply_load, load_max=base.load_max, dx=base.dx, contact_tol=base.contact_tol,
                  parameters=base.parameters)
    return Scene(**{**fields, **changes})


def snapshot(root):
    return {str(p.relative_to(root)): (None if p.is_dir() else p.read_bytes()) for p in root.rglob("*")}


@pytest.fixture(scope="module")
def coarse_plate():
    return scenes.plate(maxh=0.1, radius=None)


@pytest.fixture(scope="module")
def earlier_results(tmp_path_factory, coarse_plate):
    out = tmp_path_factory.mktemp("earlier") / "run"
    Simulation(coarse_plate, StepControl(max_steps=1), out=out, pictures="none").run()
    return out


@pytest.mark.parametrize("case,message", [
    ("boundary", "boundary 'side' does not exist in the mesh; its boundaries are"),
    ("late_boundary", "the problem at load x = 1.3817e-05 cannot be built"),
    ("raises", "KeyError"),
])
def test_a_bad_load_is_refused_before_the_folder_is_touched(case, message, coarse_plate, earlier_results):
    """Measured before: a missing boundary passed Simulation(...), and with force=True the
    earlier results were already deleted when run() raised."""
    def apply_load(prob, x):
        if case == "boundary" or (case == "late_boundary" and x > 0):
            prob.add_dirichlet("side", 0.0)
        if case == "raises":
            raise KeyError("no such load")
        coarse_plate.apply_load(prob, x)

    before = snapshot(earlier_results)
    with pytest.raises(ValueError) as exc:
        Simulation(with_load(coarse_plate, apply_load), out=earlier_results, force=True)
    assert message in str(exc.value) and "Scene 'plate'" in str(exc.value)
    assert snapshot(earlier_results) == before            # nothing deleted, nothing written


def tied_plate(coarse_plate, kinds):
    """The coarse plate with general rows: "tie" (two free dofs equal), "again" (that row
    repeated), "fixed" (a row on a dof the plate's Dirichlet conditions fix)."""
    def apply_load(prob, x):
        coarse_plate.apply_load(prob, x)
        n = prob.fes.ndof
        fixed = prob.assemble_constraints().fixed_dofs
        free = np.setdiff1d(np.arange(n), fixed)
        for kind in kinds:
            row = np.zeros((1, n))
            if kind == "fixed":
                row[0, fixed[0]] = 1.0
            else:
                row[0, free[0]], row[0, free[5]] = 1.0, -1.0
            prob.constraints.add_rows(row, [0.0], label=kind)
    return with_load(coarse_plate, apply_load)


def test_dependent_constraint_rows_are_refused_before_the_folder_is_touched(coarse_plate, earlier_results):
    """Measured before: rows repeating others passed the check, and every attempt of the
    first step then failed as singular, cutting dx seven times."""
    before = snapshot(earlier_results)
    with pytest.raises(ValueError) as exc:
        Simulation(tied_plate(coarse_plate, ["tie", "again", "fixed"]), out=earlier_results, force=True)
    message = str(exc.value)
    assert "Scene 'plate'" in message and "2 of its 3 general constraint rows (again: 1, fixed: 1; rows 1, 2)" in message
    assert snapshot(earlier_results) == before
    # one tie is independent of the Dirichlet rows: accepted
    Simulation(tied_plate(coarse_plate, ["tie"]))


def test_a_bad_material_region_is_refused_before_the_folder_is_touched(coarse_plate, earlier_results):
    from ngfracture.mechanics.materials import LinearElastic
    scene = with_load(coarse_plate, coarse_plate.apply_load, material={"glass": LinearElastic(1.0, 0.3)})
    before = snapshot(earlier_results)
    with pytest.raises(ValueError, match="material region 'glass' does not exist in the mesh"):
        Simulation(scene, out=earlier_results, force=True)
    assert snapshot(earlier_results) == before


def test_user_control_overrides_only_what_it_sets():
    disk = scenes.disk(maxh=0.3, radius=None)
    assert disk.control == {"max_new_cracks": 8}
    user = StepControl(max_steps=3, tol=1e-9)
    sim = Simulation(disk, user)
    assert sim.control.max_new_cracks == 8                  # the scene's default stays (was 2)
    assert sim.control.max_steps == 3 and sim.control.tol == 1e-9
    assert StepControl(max_new_cracks=2).over(disk.control).max_new_cracks == 2   # explicit wins
    # neither the user's object nor the scene's dict is changed
    assert user.dx_min is None and user.dx_max is None and user.explicit == {"max_steps", "tol"}
    assert disk.control == {"max_new_cracks": 8}
    assert sim.control.dx_min == disk.dx / 64 and sim.control.dx_max == 8 * disk.dx


def test_validate_does_not_mutate():
    control = StepControl()
    control.validate(1e-3)
    assert control.dx_min is None and control.dx_max is None
    with pytest.raises(ValueError, match=r"StepControl.max_steps = 2.5 is out of range"):
        StepControl(max_steps=2.5).validate(1e-3)
    with pytest.raises(TypeError, match="unknown option"):
        StepControl(max_new_crack=3)


@pytest.mark.parametrize("option,value,message", [
    ("max_rounds", 0, "max_rounds must be an integer >= 1"),
    ("max_rounds", 2.5, "max_rounds must be an integer >= 1"),
    ("max_updates", -1, "max_updates must be an integer >= 0"),
    ("pdas_rounds", True, "pdas_rounds must be an integer >= 0"),
    ("rank_tol", 0.0, "rank_tol must be a number in (0, 1)"),
    ("rank_tol", float("nan"), "rank_tol must be a number in (0, 1)"),
    ("kink_angle", -0.1, "kink_angle must be an angle in [0, pi]"),
    ("kink_angle", 4.0, "kink_angle must be an angle in [0, pi]"),
    ("linear_solver", "cg", "linear_solver must be one of ('direct', 'gmres')"),
    ("inverse", "superLU", "inverse must be one of ("),
    ("method", "newton", "method must be one of ('modified', 'full')"),
    ("fix_free_modes", "some", "fix_free_modes must be False, True or 'all'"),
    ("warm_exact", "yes", "warm_exact must be None, False or True"),
])
def test_contact_solver_options_are_checked_at_construction(option, value, message):
    _, prob = pressed_blocks()
    with pytest.raises(ValueError) as exc:
        ContactSolver(prob, tol=0.02, **{option: value})
    assert message in str(exc.value)


@pytest.mark.parametrize("option,value", [("linear_solver", "cg"), ("inverse", "cholesky")])
def test_newton_solver_names_are_checked_at_construction(option, value):
    _, prob = pressed_blocks()
    with pytest.raises(ValueError, match=option + " must be one of"):
        NewtonSolver(prob, **{option: value})


def test_fix_free_modes_false_with_contact_is_a_recorded_note():
    _, prob = pressed_blocks()
    result = ContactSolver(prob, tol=0.02, fix_free_modes=False).solve()
    assert result.converged
    assert result.notes == ["fix_free_modes=False was turned into True: with contact, free pieces are "
                            "held on the rigid modes contact leaves free"]
    _, prob = pressed_blocks()
    assert ContactSolver(prob, tol=0.02).solve().notes == []


def test_a_complementarity_problem_that_raises_is_a_recorded_note(monkeypatch):
    # pdas_rounds=0: the first unsettled round asks the complementarity problem for the set
    _, prob = pressed_blocks()
    exact = ContactSolver(prob, tol=0.02, pdas_rounds=0).solve()
    assert exact.converged and exact.lcp >= 1 and exact.notes == []

    def fails(self, rows, released=None):
        raise QPError("made to fail")
    monkeypatch.setattr(contact_solver.NewtonSolver, "unilateral_multipliers", fails)
    _, prob = pressed_blocks()
    result = ContactSolver(prob, tol=0.02, pdas_rounds=0).solve()
    assert result.lcp == 0 and len(result.notes) >= 1
    assert all(n.startswith("complementarity problem of ") and "QPError: made to fail" in n
               and n.endswith("the primal-dual update chose the set") for n in result.notes)
    # the fallback reaches the same contact solution as the exact choice
    assert result.converged
    assert abs(result.multipliers.sum() - exact.multipliers.sum()) <= 1e-10 * abs(exact.multipliers.sum())


def test_solver_notes_reach_history_and_summary(monkeypatch, tmp_path):
    """A note of a contact solve is in its step's history and in summary['notes']."""
    import ngfracture.run.step as step_module

    class Noting(ContactSolver):
        def solve(self, warm=(), lineage=None, start=None):
            result = super().solve(warm, lineage, start)
            result.notes.append("a note")
            return result
    monkeypatch.setattr(step_module, "ContactSolver", Noting)
    scene = scenes.disk(maxh=0.3, radius=None)             # separate bodies: contact from the first step
    result = Simulation(scene, StepControl(max_steps=2), out=tmp_path, pictures="none").run()
    s = result.summary
    assert [h["notes"] for h in s["history"]] == [["a note"], ["a note"]]
    assert s["notes"] == [{"step": 1, "note": "a note"}, {"step": 2, "note": "a note"}]


def test_timings_of_a_resumed_run_cover_the_whole_run(tmp_path, coarse_plate):
    """The wall time of a resumed run includes the part before the interruption: it is at
    least the sum of the disjoint phases, which the checkpoint accumulates over the run."""
    Simulation(coarse_plate, StepControl(max_steps=6), out=tmp_path, pictures="none").run()
    first = __import__("json").loads((tmp_path / "summary.json").read_text())
    resumed = Simulation(coarse_plate, StepControl(max_steps=7), out=tmp_path, pictures="none",
                         resume=True).run().summary
    disjoint = ("solve", "strain", "split", "rebuild", "refine", "collision", "contact", "checks", "output")
    assert set(disjoint) | {"linear", "assembly"} == set(PHASES)
    t = resumed["timings"]
    assert t["wall"] >= math.fsum(t[k] for k in disjoint)
    assert t["wall"] > first["timings"]["wall"] - first["timings"]["output"]
    assert t["solve"] >= first["timings"]["solve"]


def test_a_temporary_file_of_a_killed_write_is_ours(tmp_path, coarse_plate):
    """A run killed while a VTK collection was written leaves ``.tmp_ngf_*``; with force it
    goes like every file of ours (an ensemble reruns such a sample that way), without
    force the run is refused, naming it, before anything is written."""
    out = tmp_path / "run"
    out.mkdir()
    (out / ".tmp_ngf_abc.pvd").write_text("<partial")
    with pytest.raises(FileExistsError, match=r"\.tmp_ngf_abc\.pvd"):
        Simulation(coarse_plate, StepControl(max_steps=1), out=out, pictures="none")
    assert sorted(os.listdir(out)) == [".tmp_ngf_abc.pvd"]
    result = Simulation(coarse_plate, StepControl(max_steps=1), out=out, force=True, pictures="none").run()
    assert result.ok and not (out / ".tmp_ngf_abc.pvd").exists()
