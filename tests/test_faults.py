"""Steps made to fail on purpose are retried from the saved state; nothing leaks.

A fault is injected through the scene's ``apply_load`` the first time the problem of a
chosen load is built: a NaN body force (the solve reports ``nan``), a body force that
squashes the plate through itself (``inverted_element``), or a 20% stretch of the free
edges in one step, beyond what modified Newton follows (``diverged``; measured).
"""
import numpy as np
import pytest

from ngfracture import scenes
from ngfracture.geometry.meshio import mesh_to_arrays
from ngfracture import Scene, Simulation, StepControl
from ngfracture.mechanics.newton import REASONS

FAULTS = {"nan": (float("nan"), 0.0), "inverted": (0.0, 6e9), "diverged": 0.1}


def faulty_scene(base, x_fault, fault, on_split_mesh=False, times=1):
    """base with a fault injected at load x_fault (on split meshes there, if asked), the
    first ``times`` times the problem of that load is built."""
    state = {"done": False, "nv": None, "count": 0}

    def apply_load(prob, x):
        base.apply_load(prob, x)
        if state["done"] or x != x_fault:
            return
        if state["nv"] is None:
            state["nv"] = prob.mesh.nv
        if on_split_mesh and prob.mesh.nv == state["nv"]:
            return
        if fault == "diverged":
            prob.add_dirichlet("top", FAULTS[fault], component="y")
            prob.add_dirichlet("bottom", -FAULTS[fault], component="y")
        else:
            prob.add_body_force(FAULTS[fault])
        state["count"] += 1
        state["done"] = state["count"] == times

    scene = Scene(name=base.name, mesh=base.mesh, material=base.material, critical=base.critical,
                  apply_load=apply_load, load_max=base.load_max, dx=base.dx,
                  contact_tol=base.contact_tol, stop_when_unloaded=base.stop_when_unloaded,
                  parameters=base.parameters)
    return scene, state


@pytest.fixture(scope="module")
def undisturbed():
    return Simulation(scenes.plate(maxh=0.06, radius=None)).run()


@pytest.mark.parametrize("fault", ["nan", "inverted", "diverged"])
def test_failed_increment_is_retried_and_the_result_is_unchanged(undisturbed, fault):
    ref = undisturbed.summary
    k = next(i for i, h in enumerate(ref["history"]) if h["split_vertices"])   # the step that cracks
    x_fault = ref["history"][k]["x"]
    scene, injected = faulty_scene(scenes.plate(maxh=0.06, radius=None), x_fault, fault)
    result = Simulation(scene).run()
    assert injected["done"] and result.ok, result.message
    s = result.summary
    failed = s["history"][k]
    # retried once, with full Newton (the modified Newton solve met the fault)
    assert failed["retries"] == 1 and failed["method"] == "full" and failed["substeps"] == 1
    assert all(h["method"] == "modified" for h in s["history"] if not h["failures"])
    expected = {"nan": "nan", "inverted": "inverted_element", "diverged": "diverged"}[fault]
    assert failed["failures"] == [expected] and expected in REASONS
    # the same load path, the same cracks: topology bitwise, fields to the Newton tolerance
    for key in ("n_steps", "n_split_vertices", "n_fragments", "crack_length", "fragment_areas", "area_final"):
        assert s[key] == ref[key], key
    a, b = result.state, undisturbed.state
    assert np.array_equal(a.arrays.triangles, b.arrays.triangles)
    assert np.array_equal(a.arrays.points, b.arrays.points)
    assert np.abs(a.u - b.u).max() <= 1e-8 * np.abs(b.u).max()


def test_failed_relaxation_leaks_no_split(undisturbed):
    ref = undisturbed.summary
    k = next(i for i, h in enumerate(ref["history"]) if h["split_vertices"])
    x_fault = ref["history"][k]["x"]
    base = scenes.plate(maxh=0.06, radius=None)
    scene, injected = faulty_scene(base, x_fault, "nan", on_split_mesh=True)
    result = Simulation(scene).run()
    assert injected["done"] and result.ok, result.message
    hist = result.summary["history"]
    # the step that met the fault was retried from the saved state (with full Newton)
    retried = [h for h in hist if h["failures"]]
    assert len(retried) == 1 and retried[0]["failures"] == ["nan"] and retried[0]["method"] == "full"
    # every vertex of the final mesh is either original or a split the history accounts for
    nv0 = len(mesh_to_arrays(base.mesh).points)
    assert len(result.state.arrays.points) - nv0 == sum(h["split_vertices"] for h in hist)
    assert result.summary["area_final"] == result.summary["area_initial"]


def test_failed_full_newton_retry_doubles_the_substeps_on_the_same_path(undisturbed):
    """The increment fails with modified and with full Newton: the third attempt solves the
    same target in two Newton load steps, and the run equals the undisturbed one."""
    ref = undisturbed.summary
    k = next(i for i, h in enumerate(ref["history"]) if h["split_vertices"])
    scene, injected = faulty_scene(scenes.plate(maxh=0.06, radius=None), ref["history"][k]["x"], "nan", times=2)
    result = Simulation(scene).run()
    assert injected["count"] == 2 and result.ok, result.message
    s = result.summary
    failed = s["history"][k]
    assert failed["failures"] == ["nan", "nan"] and failed["retries"] == 2
    assert failed["method"] == "full" and failed["substeps"] == 2 and failed["x"] == ref["history"][k]["x"]
    for key in ("n_steps", "n_split_vertices", "n_fragments", "crack_length", "fragment_areas", "area_final"):
        assert s[key] == ref[key], key
    assert [h["x"] for h in s["history"]] == [h["x"] for h in ref["history"]]
    a, b = result.state, undisturbed.state
    assert np.array_equal(a.arrays.triangles, b.arrays.triangles)
    assert np.array_equal(a.arrays.points, b.arrays.points)
    assert np.abs(a.u - b.u).max() <= 1e-8 * np.abs(b.u).max()


def test_failed_relaxation_cuts_dx_and_keeps_the_path_before(undisturbed):
    """A relaxation fails with modified and with full Newton: the step is retried from the
    saved state with dx * cut. Up to that step the run is the undisturbed one, bit for
    bit; the cut step starts from the same state at x + cut dx; nothing of the failed
    attempts leaks (every vertex is an original or a split the history counts; the
    reference area is kept to the last bit)."""
    ref = undisturbed.summary
    k = next(i for i, h in enumerate(ref["history"]) if h["split_vertices"])
    base = scenes.plate(maxh=0.06, radius=None)
    scene, injected = faulty_scene(base, ref["history"][k]["x"], "nan", on_split_mesh=True, times=2)
    result = Simulation(scene).run()
    assert injected["count"] == 2 and result.ok, result.message
    hist = result.summary["history"]
    assert hist[:k] == ref["history"][:k]
    cut = StepControl().cut          # the plate sets no cut of its own
    assert hist[k]["failures"] == ["nan", "nan"] and hist[k]["retries"] == 2
    assert hist[k]["dx"] == ref["history"][k]["dx"] * cut
    assert hist[k]["x"] == ref["history"][k - 1]["x"] + ref["history"][k]["dx"] * cut
    nv0 = len(mesh_to_arrays(base.mesh).points)
    assert len(result.state.arrays.points) - nv0 == sum(h["split_vertices"] for h in hist)
    assert result.summary["area_final"] == result.summary["area_initial"]
    assert result.summary["reason"] == ref["reason"]


def test_retries_exhausted_stop_cleanly(tmp_path):
    base = scenes.plate(maxh=0.06, radius=None)

    def apply_load(prob, x):                       # every solve beyond 2 dx fails
        base.apply_load(prob, x)
        if x > 2.5 * base.dx:
            prob.add_body_force(FAULTS["nan"])

    scene = Scene(name="faulty", mesh=base.mesh, material=base.material, critical=base.critical,
                  apply_load=apply_load, load_max=base.load_max, dx=base.dx, contact_tol=base.contact_tol)
    result = Simulation(scene, StepControl(max_retries=3), out=tmp_path, pictures="none").run()
    assert not result.ok and result.reason == "failed"
    assert "failed 4 time(s)" in result.message and "nan" in result.message
