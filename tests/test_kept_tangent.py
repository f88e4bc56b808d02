"""The factorised tangent a load step keeps for the next one (run.tangents.KEEP_MIN_DOFS).

A step's increment solve starts from the factorisation of the step before when that one
contracted well: the same cracks as fresh factorisations to the Newton tolerance, one
factorisation less per step that starts from it, the same result after a resume, and a
kept tangent that fails is replaced by a fresh one and recorded.
"""
import json
from dataclasses import replace

import numpy as np
import pyvista as pv

from ngfracture import scenes
from ngfracture.run import checkpoint
from ngfracture.linalg import factor as factor_module
from ngfracture.run import tangents
from ngfracture.linalg.factor import EliminatedFactor
from ngfracture import Simulation, StepControl
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.run.state import load_state, save_state


def counted_run(monkeypatch, scene, keep, **options):
    """Run ``scene``; returns (result, factorisations, accepted steps started from a kept tangent)."""
    count = {"factorisations": 0}
    factorise = EliminatedFactor.factorise

    def counting_factorise(self):
        count["factorisations"] += not self.factorised
        factorise(self)

    with monkeypatch.context() as patch:
        if not keep:
            patch.setattr(tangents, "KEEP_MIN_DOFS", 10 ** 12)
        patch.setattr(EliminatedFactor, "factorise", counting_factorise)
        result = Simulation(scene, pictures="none", **options).run()
    return result, count["factorisations"], sum(h["kept_tangent"] for h in result.summary["history"])


def final_displacement(result):
    return result.problem.u.vec.FV().NumPy().copy()


def test_kept_tangent_gives_the_cracks_of_fresh_ones_with_one_factorisation_less_per_step(monkeypatch):
    kept, n_kept_factor, n_started_kept = counted_run(monkeypatch, scenes.plate(), keep=True)
    fresh, n_fresh_factor, n_fresh_started = counted_run(monkeypatch, scenes.plate(), keep=False)
    a, b = kept.summary, fresh.summary
    assert kept.ok and fresh.ok and n_fresh_started == 0
    assert n_started_kept >= 1                       # the default plate has 2.9k factorised dofs
    assert n_kept_factor == n_fresh_factor - n_started_kept
    for key in ("n_steps", "n_split_vertices", "n_fragments", "reason"):
        assert a[key] == b[key], key
    # the results of the same Newton tolerance (1e-10 of the first increment)
    assert abs(a["crack_length"] - b["crack_length"]) <= 1e-9 * b["crack_length"]
    u, u_ref = final_displacement(kept), final_displacement(fresh)
    assert np.linalg.norm(u - u_ref) <= 1e-9 * np.linalg.norm(u_ref)
    # KEEP_MAX_CONTRACTION: at most one iteration more per step started from a kept tangent
    assert sum(a["newton_iterations"]) <= sum(b["newton_iterations"]) + n_started_kept
    assert not a["notes"]


def test_resume_factorises_the_kept_tangent_again_and_equals_the_uninterrupted_run(monkeypatch, tmp_path):
    """On a small plate, with the thresholds lowered: the kept tangent and the supernodal
    solve, whose rounding depends on the blocks it is given."""
    monkeypatch.setattr(tangents, "KEEP_MIN_DOFS", 0)
    monkeypatch.setattr(factor_module, "SUPERNODAL_MIN_DOFS", 0)
    scene = lambda: scenes.plate(maxh=0.06, radius=None)
    full, part = tmp_path / "full", tmp_path / "part"
    Simulation(scene(), out=full, pictures="none").run()
    first = Simulation(scene(), StepControl(max_steps=3), out=part, pictures="none").run()
    assert first.reason == "max_steps"
    arrays, _ = checkpoint.latest(part)
    assert "tangent_state" in arrays                 # the resumed run starts from a kept tangent
    Simulation(scene(), out=part, resume=True, pictures="none").run()
    a, b = (json.loads((d / "summary.json").read_text()) for d in (part, full))
    for key in b:
        if key not in ("timings", "control"):
            assert a[key] == b[key], key
    for n in range(b["n_steps"] + 1):
        ga, gb = pv.read(part / f"step_{n:06d}.vtu"), pv.read(full / f"step_{n:06d}.vtu")
        for name in gb.point_data:
            assert np.array_equal(ga.point_data[name], gb.point_data[name]), (n, name)


def test_a_kept_tangent_that_fails_is_replaced_by_a_fresh_one_and_recorded(monkeypatch):
    """Even with no retries allowed: the fresh tangent is not a retry of the step."""
    scene = lambda: scenes.plate(maxh=0.06, radius=None)
    control = StepControl(max_retries=0)
    fresh, _, _ = counted_run(monkeypatch, scene(), keep=False, control=control)
    monkeypatch.setattr(tangents, "KEEP_MIN_DOFS", 0)
    kept_tangent = tangents.kept_tangent

    def halved(state, prob, timings):
        """The kept tangent with half its stiffness: modified Newton oscillates and fails."""
        tangent = kept_tangent(state, prob, timings)
        if tangent is None:
            return None
        bad = tangent.kept()
        bad.factor = EliminatedFactor(0.5 * tangent.factor.K, tangent.fixed_dofs, tangent.support.pins)
        return bad

    monkeypatch.setattr(tangents, "kept_tangent", halved)
    result = Simulation(scene(), control, pictures="none").run()
    assert result.ok
    noted = [n for n in result.summary["notes"] if "the tangent kept from the step before failed" in n["note"]]
    assert noted
    for record in result.summary["history"]:
        assert (record["retries"] > 0) == any(n["step"] == record["step"] for n in noted)
    # every step solved with its own tangent in the end: the fresh run's result, bit for bit
    for key in ("n_steps", "n_split_vertices", "n_fragments", "crack_length", "fragment_areas"):
        assert result.summary[key] == fresh.summary[key], key
    assert np.array_equal(final_displacement(result), final_displacement(fresh))



class _Timings:
    def add(self, phase, seconds):
        pass


def test_a_kept_tangent_is_factorised_again_by_the_solver_that_made_it(tmp_path):
    """3D "auto" takes SuperLU for a tangent with many general rows (linalg.iterative): a
    kept tangent factorised with a solve's contact rows is factorised again, after a
    resume, without them (the problem's own rows). The checkpoint names the solver, and
    the tangent is factorised again by it, whichever the problem's own rows would choose."""
    scene = scenes.blocks3d()
    Simulation(scene, StepControl(max_steps=1), out=tmp_path, pictures="none").run()
    state, _ = load_state(tmp_path)
    prob = ElasticProblem(state.mesh, scene.material)
    scene.apply_load(prob, state.x)
    assert prob.assemble_constraints().C.shape[0] == 0            # no general rows of its own
    state.tangent_state = state.u
    assert tangents.kept_tangent(state, prob, _Timings()).factor.inverse == "sparsecholesky"
    for inverse in ("superlu", "sparsecholesky"):
        state.tangent, state.tangent_inverse = None, inverse
        save_state(tmp_path, replace(state, step=state.step + 1), {})
        again, _ = load_state(tmp_path)
        assert again.tangent_inverse == inverse and again.tangent is None
        assert tangents.kept_tangent(again, prob, _Timings()).factor.inverse == inverse
