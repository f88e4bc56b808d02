"""Ensembles on dask.distributed: the result does not depend on the workers, on a worker killed
mid-sample, or on the command being killed and rerun; bad input is refused before any file.

Samples are a coarse random-strength plate (maxh 0.15, 14 steps, no contact rows: the pieces only
separate), a few seconds each.
"""
import functools
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import child_env

from ngfracture import scenes
from ngfracture.studies.ensemble import Ensemble, comparable_report
from ngfracture.studies.statistics import fit_fragment_sizes, fragment_size_statistics

FACTORY = functools.partial(scenes.plate, maxh=0.15, weibull_m=8)
OPTIONS = dict(control={"max_steps": 14}, contact="never", progress=False)
#: the same ensemble from the command line
CLI_ARGS = ["ensemble", "plate", "--samples", "3", "--set", "weibull_m=8", "--set", "maxh=0.15", "--steps", "14",
            "--contact", "never", "--workers", "1", "--quiet"]
SEEDS = [0, 1, 2]


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("reference")
    report = Ensemble(FACTORY, SEEDS, out=out, workers=1, **OPTIONS).run()
    assert report["execution"]["status"]["run"] == [0, 1, 2]
    assert json.loads((out / "ensemble.json").read_text()) == json.loads(json.dumps(report))
    return report


def test_reference_ensemble_is_complete(reference):
    assert [s["seed"] for s in reference["samples"]] == SEEDS
    assert all(s["ok"] and s["steps"] == 14 for s in reference["samples"])
    # the seeds give different fields, so different runs
    assert len({s["peak_load"] for s in reference["samples"]}) == 3
    assert reference["fragment_sizes"]["count"] == sum(s["fragments"] for s in reference["samples"])
    assert set(reference["pictures"]) == {"fragment_sizes", "fragment_counts", "peak_loads"}


def test_one_and_two_workers_give_the_same_ensemble(reference, tmp_path):
    report = Ensemble(FACTORY, SEEDS, out=tmp_path, workers=2, **OPTIONS).run()
    assert report["execution"]["workers"] == 2
    assert comparable_report(report) == comparable_report(reference)


def killing_factory(marker):
    """FACTORY, whose scenes SIGKILL the worker that first builds a problem on a cracked mesh
    (once: the first to create ``marker``). A closure: dask pickles it by value."""
    def factory(seed):
        scene = FACTORY(seed=seed)
        load = scene.apply_load

        def apply_load(prob, x):
            if "crack" in prob.mesh.GetBoundaries():
                try:
                    os.close(os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
                except FileExistsError:
                    pass
                else:
                    os.kill(os.getpid(), signal.SIGKILL)
            load(prob, x)
        scene.apply_load = apply_load
        return scene
    return factory


def test_a_killed_worker_has_its_sample_resumed_to_the_same_result(reference, tmp_path):
    """A worker process is SIGKILLed in the middle of the step of a sample's first crack; dask
    reschedules the sample, which resumes from its checkpoint."""
    marker = tmp_path / "killed"
    report = Ensemble(killing_factory(str(marker)), SEEDS, out=tmp_path / "ens", workers=2, **OPTIONS).run()
    assert marker.exists()
    assert len(report["execution"]["status"]["resumed"]) == 1
    assert comparable_report(report) == comparable_report(reference)


CHILD = """
import sys
from ngfracture.cli import main
if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
"""


def test_a_killed_command_reruns_without_rerunning_finished_samples(reference, tmp_path, capsys):
    """``ngfracture ensemble`` killed (with its cluster) after the first sample; the rerun skips it,
    resumes or runs the others, and gives the reference ensemble."""
    from ngfracture.cli import main
    out = tmp_path / "ens"
    # in tmp_path: "python -c" puts its working folder first on the path
    child = subprocess.Popen([sys.executable, "-c", CHILD, *CLI_ARGS, "--out", str(out)], start_new_session=True,
                             cwd=tmp_path, env=child_env(OMP_NUM_THREADS="1"))
    first = out / "sample_0000" / "summary.json"
    deadline = time.monotonic() + 240
    while not first.exists() and child.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    os.killpg(child.pid, signal.SIGKILL)     # the command and its cluster's processes
    child.wait()
    assert first.exists() and not (out / "ensemble.json").exists()
    stamp = first.stat().st_mtime_ns
    assert main(CLI_ARGS + ["--out", str(out)]) == 0
    report = json.loads((out / "ensemble.json").read_text())
    assert 0 in report["execution"]["status"]["skipped"]
    assert first.stat().st_mtime_ns == stamp
    assert comparable_report(report) == comparable_report(reference)
    assert "3 of 3 samples finished" in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["--samples", "0"], "--samples: must be >= 1"),
    (["--samples", "2"], "--set weibull_m=8"),
    (["--samples", "2", "--set", "weibull_m=8", "--set", "nonsense=1"], "unknown scene parameter 'nonsense'"),
    (["--samples", "2", "--set", "weibull_m=8", "--set", "seed=4"], "--seed S"),
    (["--samples", "2", "--set", "weibull_m=0"], "weibull_m must be a finite number > 0"),
    (["--samples", "2", "--set", "weibull_m=8", "--scheduler", "tcp://127.0.0.1:1"], "cannot reach the dask scheduler"),
])
def test_command_line_bad_input_is_refused_before_any_file(tmp_path, capsys, args, message):
    from ngfracture.cli import main
    out = tmp_path / "ens"
    with pytest.raises(SystemExit) as exit_:
        main(["ensemble", "plate", "--set", "maxh=0.3", *args, "--out", str(out)])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("scene, message", [
    (str(Path(__file__).resolve().parent.parent / "examples" / "beam_scene.py"), "takes no seed parameter"),
    ("no_such_scene", "unknown scene 'no_such_scene'"),
])
def test_command_line_refuses_a_scene_without_seed(tmp_path, capsys, scene, message):
    from ngfracture.cli import main
    out = tmp_path / "ens"
    with pytest.raises(SystemExit) as exit_:
        main(["ensemble", scene, "--samples", "2", "--out", str(out)])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_bad_input_is_refused_before_any_file(tmp_path):
    out = tmp_path / "ens"
    with pytest.raises(ValueError, match="no seeds"):
        Ensemble(FACTORY, [], out=out)
    with pytest.raises(ValueError, match="repeat"):
        Ensemble(FACTORY, [1, 1], out=out)
    with pytest.raises(ValueError, match="takes no seed parameter"):
        Ensemble(lambda maxh=0.2: scenes.plate(maxh=maxh, radius=None), [0], out=out)
    with pytest.raises(ValueError, match="seed has no effect without weibull_m"):
        Ensemble(functools.partial(scenes.plate, maxh=0.2), [0], out=out)
    with pytest.raises(ValueError, match="workers"):
        Ensemble(FACTORY, [0], out=out, workers=0)
    assert not out.exists()


def test_a_folder_of_another_ensemble_is_refused(reference, tmp_path):
    out = tmp_path / "ens"
    out.mkdir()
    (out / "ensemble_request.json").write_text(json.dumps({"format": "ngfracture-ensemble", "seeds": [7]}))
    with pytest.raises(FileExistsError, match="another"):
        Ensemble(FACTORY, SEEDS, out=out, **OPTIONS)
    assert sorted(p.name for p in out.iterdir()) == ["ensemble_request.json"]


def test_bootstrap_interval_covers_a_known_mean_and_is_deterministic():
    """Exponential fragment areas of mean 1, 40 samples of 25: the 95 % interval of the mean is
    about +-3.2 % wide (1.96 / sqrt(1000)); it contains 1, the same bits on a second call; the
    exponential family is chosen and its scale is the sample mean (its ML estimate)."""
    rng = np.random.Generator(np.random.PCG64(1))
    areas = [rng.exponential(1.0, 25) for _ in range(40)]
    a = fragment_size_statistics(areas, seed=3, replicates=400)
    b = fragment_size_statistics(areas, seed=3, replicates=400)
    assert a == b
    lo, hi = a["mean_interval"]
    assert lo < 1.0 < hi and hi - lo < 2 * 1.96 * 1.5 / np.sqrt(1000)
    assert a["ecdf"]["lower"][-1] == a["ecdf"]["cdf"][-1] == 1.0
    fit = fit_fragment_sizes(np.concatenate(areas))
    assert fit["families"]["exponential"]["parameters"]["scale"] == pytest.approx(np.concatenate(areas).mean())
    assert fit["families"]["weibull"]["parameters"]["modulus"] == pytest.approx(1.0, abs=0.1)
    assert fit["families"]["exponential"]["ks_pvalue"] > 0.05


@pytest.mark.slow
def test_a_refined_ensemble_is_the_same_on_one_and_two_workers(tmp_path):
    """Refinement ahead of the tips (Scene.refine) carries each sample's random strength to
    the refined vertices deterministically: the workers do not change the ensemble."""
    factory = functools.partial(scenes.plate, maxh=0.15, weibull_m=8, refine=True)
    # to the first cracks (step 5, the mesh refined from 4.4k to 21k triangles); the
    # relaxations after it split for minutes: cracks start in many places of a random field
    options = {**OPTIONS, "control": {"max_steps": 5}}
    one, two = (Ensemble(factory, [0, 1], out=tmp_path / str(n), workers=n, **options).run() for n in (1, 2))
    assert all(s["ok"] and s["split_vertices"] > 0 for s in one["samples"])
    assert comparable_report(one) == comparable_report(two)
