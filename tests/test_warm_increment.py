"""Which 3D contact solves of a run let the complementarity problem choose from their second
round (``ContactSolver(warm_exact=...)``, docs/contact.md, "Rounds of a warm increment solve").

A load step's increment solve starts from the rows of the accepted state on the same mesh:
it chooses exactly from its second round. A relaxation solve starts from the rows of the
equilibrium a crack pass split: a row there can hold a vertex on the plane of a face that
no longer bounds it, and the primal-dual rounds decide as before (the slow bar test,
``tests/test_contact3d_mouth.py``, breaks in its first cracking step only so).

The coarse confined sphere, four steps: steps 3 and 4 crack, so both kinds of solve occur
with warm rows; every accepted step must also keep the reference volume and leave no
vertex in another piece (``invariant_util.check_accepted_3d``).
"""
import ngfracture as nf
import ngfracture.run.step as step_module
from invariant_util import check_accepted_3d, reference_volume
from ngfracture.contact.solver import ContactSolver
from ngfracture.geometry.solid import solid_to_arrays


def test_increment_solves_choose_exactly_from_warm_rows_and_relaxations_do_not(tmp_path, monkeypatch):
    solves, phases = [], []
    contact_equilibrium = step_module.LoadStep._contact_equilibrium

    def with_phase(self, prob, phase, *args):
        phases.append(phase)
        return contact_equilibrium(self, prob, phase, *args)

    class Recording(ContactSolver):
        def solve(self, warm=(), lineage=None, start=None):
            result = super().solve(warm=warm, lineage=lineage, start=start)
            solves.append((phases[-1] == "relaxation", len(tuple(warm)) > 0, self.warm_exact, result.converged))
            return result

    monkeypatch.setattr(step_module.LoadStep, "_contact_equilibrium", with_phase)
    monkeypatch.setattr(step_module, "ContactSolver", Recording)
    scene = nf.scenes.sphere3d(maxh=0.4, fine=0.15)
    reference = solid_to_arrays(scene.mesh)
    volume = reference_volume(reference.points, reference.tets)
    overlaps = []
    result = nf.Simulation(scene, nf.StepControl(max_steps=4), out=tmp_path, pictures="none").run(
        on_step=lambda step: overlaps.append(check_accepted_3d(step, volume)))
    assert result.summary["n_steps"] == 4 and result.summary["n_split_vertices"] > 0
    increments = [s for s in solves if not s[0]]
    relaxations = [s for s in solves if s[0]]
    # both kinds met warm rows (a relaxation always has the rows of the pass before)
    assert any(warm for _, warm, _, _ in increments) and relaxations
    assert all(exact is True for _, _, exact, _ in increments)
    assert all(exact is False for _, _, exact, _ in relaxations)
    assert all(converged for *_, converged in solves)
    assert len(overlaps) == 4
