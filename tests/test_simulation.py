"""Fracture simulations end to end: the plate scene, step control, outputs, resume."""
import json
import math

import numpy as np
import pytest
import pyvista as pv

from ngfracture import scenes
from ngfracture.run import checkpoint
from ngfracture.mechanics.materials import LinearElastic
from ngfracture import Scene, Simulation, StepControl
from ngfracture.run.state import crack_length

NOTCH_TIPS = np.array([[0.5, 0.04], [0.5, 0.96]])


@pytest.fixture(scope="module")
def plate_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("plate")
    result = Simulation(scenes.plate(radius=None), out=out, pictures="none").run()
    return out, result


def test_plate_breaks_from_the_notches_across_the_load(plate_run):
    out, result = plate_run
    assert result.ok and result.reason == "broken", result.message
    s = result.summary
    # cracking starts at the notch tips: every vertex of the first pass within 2 mesh sizes
    start = np.array(s["crack_initiation"])
    assert len(start) >= 1
    dist = np.linalg.norm(start[:, None, :] - NOTCH_TIPS[None], axis=2).min(axis=1)
    assert dist.max() < 2 * s["parameters"]["maxh"], start
    # the crack runs perpendicular to the load (x): principal axis of the crack faces
    grid = pv.read(out / f"cracks_{s['n_steps']:06d}.vtp")
    lines = grid.lines.reshape(-1, 3)[:, 1:]
    p = grid.points[:, :2] - grid["displacement"][:, :2]          # reference positions
    mid, length = 0.5 * (p[lines[:, 0]] + p[lines[:, 1]]), np.linalg.norm(p[lines[:, 0]] - p[lines[:, 1]], axis=1)
    c = mid - np.average(mid, axis=0, weights=length)
    w, v = np.linalg.eigh((c * length[:, None]).T @ c)
    axis = v[:, np.argmax(w)]
    assert math.degrees(math.acos(abs(axis[1]))) < 15.0
    # it crosses the plate: at least the height between the notch tips
    assert s["crack_length"] >= 0.92
    assert s["n_fragments"] >= 2


def test_plate_conserves_area_and_has_no_overlap(plate_run):
    _, result = plate_run
    s = result.summary
    assert s["area_final"] == s["area_initial"]          # to the last bit
    assert math.fsum(s["fragment_areas"]) == pytest.approx(s["area_initial"], rel=1e-14)
    assert s["max_overlap_area"] <= 1e-10 * s["area_initial"]


def test_plate_summary_and_files(plate_run):
    out, result = plate_run
    s = json.loads((out / "summary.json").read_text())
    for key in ("scene", "parameters", "n_steps", "n_split_vertices", "crack_length", "n_fragments",
                "fragment_areas", "area_initial", "area_final", "max_overlap_area", "energy",
                "newton_iterations", "timings"):
        assert key in s, key
    assert set(s["timings"]) >= {"solve", "strain", "split", "rebuild", "collision", "contact", "output"}
    assert len(s["newton_iterations"]) == s["n_steps"] == len(s["energy"])
    # the time series has every step, and every step file has the fields a user colours by
    reader = pv.get_reader(str(out / "results.pvd"))
    assert len(reader.time_values) == s["n_steps"] + 1
    last = pv.read(out / f"step_{s['n_steps']:06d}.vtu")
    for name in ("displacement", "nodal_strain"):
        assert name in last.point_data
    for name in ("fragment", "region", "principal_strain", "principal_direction"):
        assert name in last.cell_data
    assert len(np.unique(last.cell_data["fragment"])) == s["n_fragments"]
    assert not (out / "fragment_sizes.png").exists() and not (out / "final.png").exists()   # pictures="none"


def test_energy_bookkeeping_linear(tmp_path):
    """Before cracking, the reactions' work equals the elastic energy (trapezoid exact for linear)."""
    scene = scenes.plate(material=LinearElastic(5e9, 0.18, plane="stress"), radius=None)
    scene.load_max = 6e-5          # below the first crack
    result = Simulation(scene, pictures="none").run()
    assert result.ok and result.summary["n_split_vertices"] == 0
    for e in result.summary["energy"]:
        assert e["external_work"] == pytest.approx(e["elastic_energy"], rel=1e-9)


def test_energy_released_by_cracking_is_positive(plate_run):
    _, result = plate_run
    energy = result.summary["energy"]
    assert all(e["released_energy"] >= -1e-9 * e["external_work"] for e in energy)
    assert energy[-1]["released_energy"] > 0.5 * energy[-1]["external_work"]   # broken: most of it released


def test_small_plate_run_leaves_no_overlap():
    """Contact rows re-linearised at the solution: the broken pieces of the driver's plate
    do not overlap (before: 1.6e-9 of the area on the default plate)."""
    result = Simulation(scenes.plate(maxh=0.06, radius=None), pictures="none").run()
    s = result.summary
    assert result.ok and s["n_fragments"] >= 2
    assert s["max_overlap_area"] < 1e-10 * s["area_initial"]


def test_too_many_cracks_cut_the_increment():
    """max_new_cracks = 0: every increment that cracks is retried with dx * cut down to dx_min."""
    scene = scenes.plate(maxh=0.06, radius=None)
    control = StepControl(max_new_cracks=0, dx_min=scene.dx / 16)
    result = Simulation(scene, control).run()
    assert result.ok
    cracked = [h for h in result.summary["history"] if h["split_vertices"]]
    # the first step that cracked was taken with an increment that could not be cut further
    assert control.dx_min <= cracked[0]["dx"] < control.dx_min / control.cut


def test_quiet_steps_grow_the_increment():
    """After grow_after crack-free steps in a row dx grows by grow, up to dx_max (paper 4.2)."""
    scene = scenes.plate(maxh=0.1, critical=1.0, dx=1e-5, radius=None)   # uncrackable: every step is quiet
    control = StepControl(grow=1.5, grow_after=2, dx_max=2 * scene.dx, max_steps=5)
    result = Simulation(scene, control, pictures="none").run()
    hist = result.summary["history"]
    assert all(h["split_vertices"] == 0 for h in hist)
    dx = [h["dx"] for h in hist]
    assert dx == pytest.approx([scene.dx, scene.dx, 1.5 * scene.dx, 1.5 * scene.dx, 2 * scene.dx], rel=1e-15)


def test_resume_with_other_options_is_refused_and_keeps_the_files(tmp_path):
    """Options that change the load path must be those of the interrupted run; max_steps may grow."""
    Simulation(scenes.plate(maxh=0.1, radius=None), StepControl(max_steps=1), out=tmp_path, pictures="none").run()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(checkpoint.CheckpointError, match="cut = 0.5, this run has 0.25"):
        Simulation(scenes.plate(maxh=0.1, radius=None), StepControl(cut=0.25), out=tmp_path, resume=True)
    with pytest.raises(checkpoint.CheckpointError, match="contact = 'auto', this run has 'never'"):
        Simulation(scenes.plate(maxh=0.1, radius=None), out=tmp_path, resume=True, contact="never")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    again = Simulation(scenes.plate(maxh=0.1, radius=None), StepControl(max_steps=2), out=tmp_path, resume=True,
                       pictures="none").run()
    assert again.summary["n_steps"] == 2


def test_resume_equals_uninterrupted(tmp_path):
    scene = lambda: scenes.plate(maxh=0.06, radius=None)
    full = tmp_path / "full"
    part = tmp_path / "part"
    Simulation(scene(), out=full, pictures="none").run()
    first = Simulation(scene(), StepControl(max_steps=3), out=part, pictures="none").run()
    assert first.reason == "max_steps"
    Simulation(scene(), out=part, resume=True, pictures="none").run()
    a, b = (json.loads((d / "summary.json").read_text()) for d in (part, full))
    for key in b:
        if key not in ("timings", "control"):
            assert a[key] == b[key], key
    for n in range(b["n_steps"] + 1):       # every step, those before the interruption too
        ga, gb = pv.read(part / f"step_{n:06d}.vtu"), pv.read(full / f"step_{n:06d}.vtu")
        assert np.array_equal(ga.points, gb.points), n
        for name in gb.point_data:
            assert np.array_equal(ga.point_data[name], gb.point_data[name]), (n, name)
        for name in gb.cell_data:
            assert np.array_equal(ga.cell_data[name], gb.cell_data[name]), (n, name)


def test_existing_results_are_refused_and_kept(tmp_path):
    Simulation(scenes.plate(maxh=0.06, radius=None), StepControl(max_steps=1), out=tmp_path, pictures="none").run()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(FileExistsError, match="already holds results"):
        Simulation(scenes.plate(maxh=0.06, radius=None), out=tmp_path)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_resume_of_another_scene_is_refused(tmp_path):
    Simulation(scenes.plate(maxh=0.06, radius=None), StepControl(max_steps=1), out=tmp_path, pictures="none").run()
    with pytest.raises(checkpoint.CheckpointError, match="parameters"):
        Simulation(scenes.plate(maxh=0.05, radius=None), out=tmp_path, resume=True)


def test_bad_scene_is_named_before_any_work(tmp_path):
    scene = scenes.plate(maxh=0.06, radius=None)
    scene.critical = {"glass": 1e-4}
    with pytest.raises(ValueError, match="'glass'"):
        Simulation(scene, out=tmp_path / "never")
    assert not (tmp_path / "never").exists()
    scene = scenes.plate(maxh=0.06, radius=None)
    scene.dx = -1.0
    with pytest.raises(ValueError, match="dx"):
        Simulation(scene)
    with pytest.raises(ValueError, match="cut"):
        Simulation(scenes.plate(maxh=0.06, radius=None), StepControl(cut=1.5))


def test_failed_steps_stop_cleanly_with_the_last_good_state(tmp_path):
    """A load that makes every solve fail (NaN body force from x > limit): retries, then a clean stop."""
    base = scenes.plate(maxh=0.06, radius=None)
    limit = 2.5 * base.dx

    def apply_load(prob, x):
        base.apply_load(prob, x)
        if x > limit:
            prob.add_body_force((float("nan"), 0.0))

    scene = Scene(name="faulty", mesh=base.mesh, material=base.material, critical=base.critical,
                  apply_load=apply_load, load_max=base.load_max, dx=base.dx, contact_tol=base.contact_tol)
    result = Simulation(scene, StepControl(max_retries=3), out=tmp_path, pictures="none").run()
    assert not result.ok and result.reason == "failed"
    assert "nan" in result.message
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["reason"] == "failed" and s["load"] <= limit
    assert s["n_steps"] == result.state.step >= 2
    # the last good state is resumable
    arrays, header = checkpoint.latest(tmp_path)
    assert header["meta"]["step"] == s["n_steps"]


def test_crack_length_of_a_straight_cut():
    from ngfracture.geometry.meshio import MeshArrays
    pts = np.array([[0, 0], [0, 1], [0, 0], [0, 1.0]])
    a = MeshArrays(pts, np.zeros((0, 3), int), np.zeros(0, int), ["r"], np.array([[0, 1], [3, 2]]),
                   np.array([1, 1]), ["crack"])
    assert crack_length(a) == 1.0


def test_resuming_a_finished_run_redraws_its_final_outputs(tmp_path):
    """A run killed while writing its final files resumes from the last checkpoint and redraws them."""
    control = lambda: StepControl(max_steps=2)
    first = Simulation(scenes.plate(maxh=0.1, radius=None), control(), out=tmp_path).run()
    assert first.reason == "max_steps"
    # the phases are disjoint parts of the wall time, the final pictures included
    t = json.loads((tmp_path / "summary.json").read_text())["timings"]
    phases = ("solve", "strain", "split", "rebuild", "collision", "contact", "checks", "output")
    assert sum(t[k] for k in phases) <= t["wall"] + 1e-5
    (tmp_path / "summary.json").unlink()                 # as if killed before the summary
    again = Simulation(scenes.plate(maxh=0.1, radius=None), control(), out=tmp_path, resume=True).run()
    assert again.reason == "max_steps" and again.summary["n_steps"] == 2
    assert (tmp_path / "summary.json").exists()
    assert again.summary["history"] == first.summary["history"]
