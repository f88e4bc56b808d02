"""3D runs are reproducible: a resumed run equals the uninterrupted one bit for bit, in
process and after SIGKILL during a checkpoint write, and an ensemble of a 3D scene, with
and without contact, gives the same report on one and on two dask workers."""
import json

import numpy as np
import pytest
import pyvista as pv

from ngfracture import Simulation, StepControl, scenes

#: a coarse bar (1.3k tetrahedra, r larger than the mesh: its crack wanders, but it cracks in a
#: few seconds, which is what reproducibility needs)
COARSE = {"maxh": 0.4, "radius": 0.2, "thickness": 0.25}


def compare(a, b):
    """Summaries (but the timings) and every step's files equal, bit for bit."""
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for key in sb:
        if key not in ("timings", "control"):
            assert sa[key] == sb[key], key
    for n in range(sb["n_steps"] + 1):
        for name in (f"step_{n:06d}.vtu", f"cracks_{n:06d}.vtp"):
            ga, gb = pv.read(a / name), pv.read(b / name)
            assert np.array_equal(ga.points, gb.points), name
            for k in gb.point_data:
                assert np.array_equal(ga.point_data[k], gb.point_data[k]), (name, k)
            for k in gb.cell_data:
                assert np.array_equal(ga.cell_data[k], gb.cell_data[k]), (name, k)


def test_a_resumed_3d_run_equals_the_uninterrupted_one(tmp_path):
    full, part = tmp_path / "full", tmp_path / "part"
    done = Simulation(scenes.bar3d(**COARSE), out=full, pictures="none").run()
    assert done.reason == "broken" and done.summary["n_split_vertices"] > 0
    stop = max(done.summary["n_steps"] - 1, 1)     # interrupted after a step that cracked
    first = Simulation(scenes.bar3d(**COARSE), StepControl(max_steps=stop), out=part, pictures="none").run()
    assert first.reason == "max_steps"
    Simulation(scenes.bar3d(**COARSE), out=part, resume=True, pictures="none").run()
    compare(part, full)


@pytest.mark.slow
def test_a_3d_ensemble_is_the_same_on_one_and_two_workers(tmp_path):
    """Random strength per vertex of a tetrahedral mesh (a quarter of each tet's volume per
    vertex for the size effect), two seeds on dask: the workers do not change the ensemble."""
    import functools

    from ngfracture.studies.ensemble import Ensemble, comparable_report
    factory = functools.partial(scenes.bar3d, weibull_m=8, **COARSE)
    options = dict(control={"max_steps": 8}, progress=False)
    one, two = (Ensemble(factory, [0, 1], out=tmp_path / str(n), workers=n, **options).run() for n in (1, 2))
    assert all(s["ok"] and s["split_vertices"] > 0 for s in one["samples"])
    assert one["samples"][0]["fragments"] >= 1 and "fragment_volumes" in one["samples"][0]
    assert comparable_report(one) == comparable_report(two)


def contact_bar3d_factory():
    """bar3d of random strength solved with contact from the start (``Scene.contact``). A
    closure: dask pickles it by value."""
    def factory(seed):
        import dataclasses
        return dataclasses.replace(scenes.bar3d(weibull_m=8, seed=seed, **COARSE), contact=True)
    return factory


@pytest.mark.slow
def test_a_3d_contact_ensemble_is_the_same_on_one_and_two_workers(tmp_path):
    """The contact solver on tetrahedra (ActiveSet3d) in every step of every sample: the
    workers do not change the ensemble, and no written step has fragments that overlap."""
    from overlap3d_util import check_run_overlap

    from ngfracture.studies.ensemble import Ensemble, comparable_report
    options = dict(control={"max_steps": 8}, progress=False)
    one, two = (Ensemble(contact_bar3d_factory(), [0, 1], out=tmp_path / str(n), workers=n, **options).run()
                for n in (1, 2))
    assert all(s["ok"] and s["split_vertices"] > 0 for s in one["samples"])
    assert comparable_report(one) == comparable_report(two)
    assert one["fragment_counts"]["mean"] >= 1 and one["fragment_sizes"]["count"] >= 2
    for n in (1, 2):
        for sample in sorted((tmp_path / str(n)).glob("sample_*")):
            check_run_overlap(sample)
