"""The command line with your own scene: files and functions, --set, --progress json,
--version, scenes, render, and the one-line message of the uncompiled source tree."""
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import ngsolve as ng
import pytest
from conftest import child_env

import ngfracture
from ngfracture import scenes
from ngfracture.output import pictures
from ngfracture.run import simulation
from ngfracture.cli import main, progress_json
from ngfracture.run.scene_source import scene_parameters

ROOT = Path(__file__).resolve().parents[1]
BEAM = str(ROOT / "examples" / "beam_scene.py")
QUIET = ["--pictures", "none", "--progress", "none"]


def summary(out):
    return json.loads((Path(out) / "summary.json").read_text())


@pytest.fixture(scope="module")
def beam_run(tmp_path_factory):
    """Tutorial 5's beam from its scene file, with JSON progress: (folder, stdout lines)."""
    out = tmp_path_factory.mktemp("beam") / "beam"
    proc = subprocess.run([sys.executable, "-m", "ngfracture", "run", BEAM, "--set", "maxh=0.1",
                           "--set", "E_glass=6e10", "--steps", "6", "--progress", "json", "--pictures", "none",
                           "--max-new-cracks", "4", "--out", str(out)],
                          capture_output=True, text=True, cwd=out.parent, env=child_env())
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    return out, proc.stdout.splitlines(), proc.stderr


def test_scene_file_runs_with_its_parameters(beam_run):
    out, _, stderr = beam_run
    s = summary(out)
    assert s["scene"] == "beam" and s["parameters"]["maxh"] == 0.1 and s["parameters"]["E_glass"] == 6e10
    assert s["control"]["max_new_cracks"] == 4 and s["control"]["max_steps"] == 6
    assert s["load_description"] == "downward displacement of the pad's top (length)"
    assert s["n_steps"] == 6 and s["area_final"] == s["area_initial"]
    assert "beam: 6 steps" in stderr          # the closing lines leave stdout to the JSON


def test_json_progress_is_one_object_per_accepted_step(beam_run):
    out, lines, _ = beam_run
    s = summary(out)
    records = [json.loads(line) for line in lines]
    assert [r["step"] for r in records] == list(range(1, s["n_steps"] + 1))
    assert all(set(r) == {"step", "load", "load_max", "splits", "fragments", "seconds", "forces"} for r in records)
    # the forces of every record are those of the step's history record
    assert [r["forces"] for r in records] == [h["boundaries"] for h in s["history"]]
    # the load of every record is the accepted x of that step, bit for bit
    assert [r["load"] for r in records] == [h["x"] for h in s["history"]]
    splits = [r["splits"] for r in records]
    assert splits == [sum(h["split_vertices"] for h in s["history"][:k + 1]) for k in range(len(records))]
    assert records[-1]["fragments"] == s["n_fragments"]
    assert all(b["seconds"] >= a["seconds"] for a, b in zip(records, records[1:]))


def test_progress_json_line():
    forces = {"top": {"force": [0.0, 2.5], "displacement": [0.0, 1e-3]}}
    info = {"step": 3, "x": 0.25, "load_max": 1.0, "split_vertices": 7, "fragments": 2, "seconds": 1.23456,
            "boundaries": forces}
    assert json.loads(progress_json(info)) == {"step": 3, "load": 0.25, "load_max": 1.0, "splits": 7,
                                               "fragments": 2, "seconds": 1.235, "forces": forces}


def test_module_function_and_set_reach_the_builtin_scene(tmp_path, capsys):
    out = tmp_path / "p"
    assert main(["run", "ngfracture.scenes:plate", "--set", "maxh=0.1", "--set", "E=1e9", "--set", "nu=0.25",
                 "--set", "critical=2e-4", "--steps", "1", "--method", "full", "--tol", "1e-9",
                 "--checkpoint-every", "3", *QUIET, "--out", str(out)]) == 0
    s = summary(out)
    assert (s["parameters"]["E"], s["parameters"]["nu"], s["parameters"]["critical"]) == (1e9, 0.25, 2e-4)
    assert s["control"]["method"] == "full" and s["control"]["tol"] == 1e-9
    assert s["history"][0]["dx"] == 2e-4 / 10       # the plate's dx follows its critical strain
    assert s["load_description"] == scenes.PLATE_LOAD


def test_the_disks_own_step_control_stays_under_cli_options(tmp_path, monkeypatch):
    """Was: any StepControl from the command line replaced the disk's max_new_cracks 8 by 2."""
    seen = {}

    def stop(self):
        seen["control"] = self.control
        raise RuntimeError("stopped before the run")
    monkeypatch.setattr(simulation.Simulation, "run", stop)
    assert main(["run", "disk", "--set", "maxh=0.3", "--steps", "1", "--tol", "1e-9", *QUIET,
                 "--out", str(tmp_path / "d")]) == 1
    assert seen["control"].max_new_cracks == 8 and seen["control"].tol == 1e-9


def test_threads_are_those_of_the_task_manager_in_the_run(tmp_path, monkeypatch):
    seen = {}
    with ng.TaskManager():        # outside one, GetNumThreads is 1
        before = ng.GetNumThreads()

    def stop(self):
        with ng.TaskManager():
            seen["threads"] = ng.GetNumThreads()
        raise RuntimeError("stopped before the run")
    monkeypatch.setattr(simulation.Simulation, "run", stop)
    wanted = 2 if before != 2 else 3
    try:
        assert main(["run", "plate", "--maxh", "0.1", "--threads", str(wanted), *QUIET,
                     "--out", str(tmp_path / "t")]) == 1
    finally:
        ng.SetNumThreads(before)
    assert seen["threads"] == wanted


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"ngfracture {ngfracture.__version__}"


def test_scenes_lists_every_parameter_with_its_default(capsys):
    assert main(["scenes"]) == 0
    text = capsys.readouterr().out
    for name, func in scenes.SCENES.items():
        assert f"{name}: " in text and scenes.LOAD_DESCRIPTIONS[name] in text
        block = text.split(f"{name}: ", 1)[1]
        for pname, default in scene_parameters(func).items():
            shown = "(the scene's)" if default is None else repr(default)
            assert f"--set {pname}={shown}" in block, (name, pname)


def test_render_redraws_the_pictures_of_a_run(tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["run", "plate", "--maxh", "0.1", "--steps", "3", *QUIET, "--out", str(out)]) == 0
    assert not (out / "final.png").exists()
    capsys.readouterr()
    assert main(["render", str(out)]) == 0
    assert (out / "final.png").stat().st_size > 0 and (out / "fragment_sizes.png").stat().st_size > 0
    assert "of step 3" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:
        main(["render", str(tmp_path / "none")])
    assert exc.value.code == 2


def test_a_failed_final_picture_is_printed(tmp_path, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise pictures.RenderError("no OpenGL here")
    monkeypatch.setattr(pictures, "render_png", broken)
    out = tmp_path / "f"
    assert main(["run", "plate", "--maxh", "0.1", "--steps", "1", "--progress", "none", "--out", str(out)]) == 0
    assert "final.png was not drawn: no OpenGL here" in capsys.readouterr().err
    assert summary(out)["pictures"]["final_error"] == "no OpenGL here"


def test_uncompiled_source_tree_says_so_in_one_line(tmp_path):
    shutil.copytree(ROOT / "ngfracture", tmp_path / "ngfracture",
                    ignore=shutil.ignore_patterns("*.so", "*.pyd", "__pycache__"))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-m", "ngfracture", "--help"], capture_output=True, text=True,
                          cwd=tmp_path, env=env)
    assert proc.returncode == 1 and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr
    assert "the compiled extension is missing" in lines[0] and "uncompiled source tree" in lines[0]
