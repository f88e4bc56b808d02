"""Random scenes (ngfracture.studies.random_scenes): every accepted step keeps its
invariants, checked independently of the engine (tests/invariant_util.py), and a run
ends with load_max, broken, max_steps, or a reason that names what failed.

The fast sample is a handful of coarse scenes; ``benchmarks/random_scenes.py`` runs many.
"""
import numpy as np
import pytest

import ngfracture as nf
from invariant_util import check_accepted, reference_area
from ngfracture.geometry.meshio import mesh_to_arrays
from ngfracture.run.invariants import OVERLAP_TOL
from ngfracture.run.simulation import LinearAtLargeStrain
from ngfracture.studies import random_scenes

ENDINGS = {"load_max", "broken", "max_steps"}


def run_checked(params, max_steps=None):
    scene = random_scenes.scene(**params)
    arrays = mesh_to_arrays(scene.mesh)
    area = reference_area(arrays.points, arrays.triangles)
    control = nf.StepControl(max_steps=max_steps) if max_steps else None
    steps = []
    result = nf.Simulation(scene, control, pictures="none").run(
        on_step=lambda s: steps.append(check_accepted(s, area)))
    return result, steps, area


def test_the_overlapping_biaxial_rectangle_is_retried_or_ends_with_a_reason():
    """Linear elastic, critical strain 0.3, plane strain, biaxial stretch to 0.58: its
    fragments overlapped by 1.5e-4 in an accepted step when overlap was not checked."""
    params = dict(width=2.38, height=1.39, load="biaxial", model="linear", plane="strain", E=1e9, nu=0.39,
                  critical=0.3, radius=0.11, maxh=0.085, overload=0.58 / 0.3)
    with pytest.warns(LinearAtLargeStrain):
        result, steps, area = run_checked(params)
    s = result.summary
    assert result.reason in ENDINGS or s["failure"]["reason"] in ("overlap", "inverted_element"), result.message
    assert all(h["overlap_area"] <= OVERLAP_TOL * area for h in s["history"])
    assert s["area_final"] == s["area_initial"] == area


@pytest.mark.parametrize("seed", [3, 11, 17, 23])
def test_a_random_scene_keeps_its_invariants_or_says_why(seed):
    params = random_scenes.draw(seed, coarse=True)
    result, steps, area = run_checked(params, max_steps=12)
    s = result.summary
    assert result.reason in ENDINGS or (result.reason == "failed" and s["failure"]["reason"]), result.message
    assert len(steps) == s["n_steps"]
    assert s["area_final"] == area and s["max_overlap_area"] <= OVERLAP_TOL * area


def test_the_generator_is_reproducible_and_covers_its_extremes():
    assert random_scenes.draw(5) == random_scenes.draw(5)
    drawn = [random_scenes.draw(seed) for seed in range(60)]
    assert {p["extreme"] for p in drawn} >= set(random_scenes.EXTREMES)
    assert {p["load"] for p in drawn} == set(random_scenes.LOADS)
    assert {p["model"] for p in drawn} == set(random_scenes.MODELS)
    assert {len(random_scenes.parse_holes(p["holes"])) for p in drawn} == {0, 1, 2, 3}
    assert np.mean([p["notch"] > 0 for p in drawn]) > 0.2


def test_a_step_whose_pieces_overlap_is_not_accepted_and_the_run_says_which_invariant():
    """Two squares, the left one pushed through the right one without contact rows: no
    increment avoids the overlap, so the run ends failed, naming the overlap and its size,
    with the last good state (before the squares touch) as its result."""
    from conftest import two_squares_mesh

    def apply_load(prob, x):
        prob.add_dirichlet("a_left", (x, 0.0))
        prob.add_dirichlet("b_right", (0.0, 0.0))

    scene = nf.Scene(name="push", mesh=two_squares_mesh(0.5), material=nf.StVenantKirchhoff(1e9, 0.3),
                     critical=1.0, apply_load=apply_load, load_max=1.5, dx=0.25, contact_tol=1e-4, contact=True,
                     radius=0.5)
    result = nf.Simulation(scene, contact="never", pictures="none").run()
    assert result.reason == "failed"
    failure = result.summary["failure"]
    assert failure["reason"] == "overlap" and failure["phase"] == "invariant"
    assert "pieces overlap by" in failure["message"] and "of the area" in failure["message"]
    assert result.state.x <= 1.0 and result.summary["max_overlap_area"] <= OVERLAP_TOL * 2.0


def test_holes_are_parsed_in_two_and_three_dimensions():
    assert random_scenes.parse_holes("0.1:0.2:0.05,0.5:0.5:0.1") == [(0.1, 0.2, 0.05), (0.5, 0.5, 0.1)]
    assert random_scenes.parse_holes("0.1:0.2:0.3:0.05", dim=3) == [(0.1, 0.2, 0.3, 0.05)]
    assert random_scenes.parse_holes("") == []
    for text, dim, message in (("0.1:0.2", 2, "a hole must be x:y:r"), ("0.1:0.2:0.3:0.4", 2, "a hole must be x:y:r"),
                               ("0.1:0.2:0.3", 3, "a spherical hole must be x:y:z:r"),
                               ("0.1:0.2:0", 2, "radius must be > 0"), ("0.1:0.2:0.1", 4, "dim must be 2 or 3")):
        with pytest.raises(ValueError, match=message):
            random_scenes.parse_holes(text, dim=dim)
