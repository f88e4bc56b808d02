"""The command line ``ngfracture run``: bad input is refused, the success path writes results.

Bad input exits with status 2 and a message that names the offending option or folder,
without a traceback and without writing or changing any file. The cases run in process
through ``main`` (a traceback would be an exception other than SystemExit); one runs as a
real process as well.
"""
import json
import subprocess
import sys

import pytest
from conftest import child_env

from ngfracture import cli, scenes
from ngfracture.cli import main
from ngfracture import Scene

SMALL = ["--maxh", "0.1", "--quiet", "--pictures", "none"]
OPTIONS = ["--maxh", "--steps", "--load-max", "--out", "--force", "--resume", "--pictures", "--contact",
           "--quiet", "--set", "--max-new-cracks", "--method", "--tol", "--maxit", "--cut", "--grow",
           "--grow-after", "--dx-min", "--dx-max", "--max-retries", "--split", "--checkpoint-every",
           "--threads", "--progress"]
#: what summary.json holds at least (docs/design.md, "Outputs")
SUMMARY_KEYS = ["scene", "parameters", "n_steps", "n_split_vertices", "crack_length", "n_fragments",
                "fragment_areas", "area_initial", "area_final", "max_overlap_area", "energy",
                "newton_iterations", "timings"]
PHASES = ["solve", "strain", "split", "rebuild", "collision", "contact", "output"]


def snapshot(root):
    """Every file and folder below root with its bytes (None for folders)."""
    return {str(p.relative_to(root)): (None if p.is_dir() else p.read_bytes()) for p in root.rglob("*")}


def refused(argv, capsys):
    """Run main(argv); it must exit with status 2. Returns stderr."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.fixture(scope="module")
def plate_results(tmp_path_factory):
    """A short plate run with checkpoints: (folder, its snapshot)."""
    out = tmp_path_factory.mktemp("cli") / "plate"
    assert main(["run", "plate", *SMALL, "--steps", "2", "--out", str(out)]) == 0
    return out, snapshot(out.parent)


@pytest.mark.parametrize("args,message", [
    (["run", "plat"], "unknown scene 'plat': the built-in scenes are bar3d, beam, blocks3d, disintegration, disk, holed_beam, plate, plate3d, shaft3d"),
    (["run", "plate", "--set", "E"], "'E': expected NAME=VALUE"),
    (["run", "plate", "--set", "young=1"], "unknown scene parameter 'young'; the known ones are: maxh,"),
    (["run", "plate", "--set", "E=soft"], "E=soft: expected a number"),
    (["run", "plate", "--max-new-cracks", "-1"], "argument --max-new-cracks: must be >= 0"),
    (["run", "plate", "--method", "newton"], "argument --method: invalid choice: 'newton'"),
    (["run", "plate", "--tol", "2"], "StepControl.tol = 2.0 is out of range"),
    (["run", "plate", "--threads", "0"], "argument --threads: must be >= 1"),
    (["run", "plate", "--checkpoint-every", "0"], "argument --checkpoint-every: must be >= 1"),
    (["run", "plate", "--progress", "xml"], "argument --progress: invalid choice: 'xml'"),
    (["run", "nowhere/scene.py"], "scene file 'nowhere/scene.py' does not exist"),
    (["run", "plate", "--maxh", "-0.1"], "argument --maxh: must be a finite number > 0"),
    (["run", "plate", "--maxh", "0"], "argument --maxh: must be a finite number > 0"),
    (["run", "plate", "--maxh", "nan"], "argument --maxh: must be a finite number > 0"),
    (["run", "plate", "--steps", "0"], "argument --steps: must be >= 1"),
    (["run", "plate", "--load-max", "-0.001"], "argument --load-max: must be a finite number > 0"),
    # argparse takes "-1e-3" for an option; the message still names --load-max
    (["run", "plate", "--load-max", "-1e-3"], "argument --load-max: expected one argument"),
    (["run", "plate", "--force", "--resume"], "--force and --resume exclude each other"),
])
def test_bad_option_is_refused_before_any_file(args, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)                 # the default output folder would be out/plate
    err = refused([*args, "--out", str(tmp_path / "o")] if len(args) > 2 else args, capsys)
    assert message in err
    assert snapshot(tmp_path) == {}


def test_unknown_scene_in_a_real_process(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "ngfracture", "run", "plat", "--out", "o"],
                          capture_output=True, text=True, cwd=tmp_path, env=child_env())
    assert proc.returncode == 2
    assert "unknown scene 'plat'" in proc.stderr and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def no_meshing(monkeypatch):
    """Scenes that fail the test if built: a refusal must come before any work."""
    def never(maxh=None):
        """Must not be called."""
        raise AssertionError("the scene was built before the refusal")
    for name in list(scenes.SCENES):
        monkeypatch.setitem(scenes.SCENES, name, never)


def test_folder_with_results_is_kept_byte_for_byte(plate_results, capsys, no_meshing):
    out, before = plate_results
    err = refused(["run", "plate", *SMALL, "--out", str(out)], capsys)
    assert str(out) in err and "already holds results" in err and "use --force to replace them or --resume to continue" in err
    assert snapshot(out.parent) == before


def test_resume_without_checkpoint(tmp_path, capsys, no_meshing):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "notes.txt").write_text("mine")
    before = snapshot(tmp_path)
    err = refused(["run", "plate", *SMALL, "--resume", "--out", str(empty)], capsys)
    assert "no checkpoint" in err and str(empty) in err
    missing = tmp_path / "missing"
    err = refused(["run", "plate", *SMALL, "--resume", "--out", str(missing)], capsys)
    assert "no checkpoint" in err and str(missing) in err
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("args,differs", [
    (["disk", "--maxh", "0.3"], "'plate'"),                 # another scene
    (["plate", "--maxh", "0.12"], "'maxh': 0.12"),          # another mesh size
    (["plate", "--maxh", "0.1", "--load-max", "5e-4"], "'load_max': 0.0005"),
])
def test_resume_of_another_scene_or_parameters(plate_results, args, differs, capsys):
    out, before = plate_results
    err = refused(["run", *args, "--quiet", "--pictures", "none", "--resume", "--out", str(out)], capsys)
    assert "checkpoint is of scene 'plate'" in err and differs in err
    assert snapshot(out.parent) == before


def test_out_is_a_regular_file(tmp_path, capsys, no_meshing):
    target = tmp_path / "results"
    target.write_bytes(b"not a folder")
    err = refused(["run", "plate", *SMALL, "--out", str(target)], capsys)
    assert str(target) in err and "not a folder" in err
    assert snapshot(tmp_path) == {"results": b"not a folder"}


def test_help_mentions_every_option(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for option in OPTIONS:
        assert option in text, option
    for scene in scenes.SCENES:
        assert scene in text
    assert "Exit status 0" in text


def test_success_writes_results_and_summary(tmp_path):
    # the command of the README with --steps 12 (the full run, 49 steps, takes 19 s here)
    proc = subprocess.run([sys.executable, "-m", "ngfracture", "run", "plate", "--maxh", "0.1", "--out", "res",
                           "--quiet", "--pictures", "none", "--steps", "12"],
                          capture_output=True, text=True, cwd=tmp_path, env=child_env())
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "res"
    for name in ("results.pvd", "cracks.pvd", "summary.json"):
        assert (out / name).stat().st_size > 0, name
    s = json.loads((out / "summary.json").read_text())
    for key in SUMMARY_KEYS:
        assert key in s, key
    assert set(PHASES) <= set(s["timings"])
    assert s["scene"] == "plate" and s["parameters"]["maxh"] == 0.1
    assert s["reason"] == "max_steps" and s["n_steps"] == 12
    assert s["n_split_vertices"] > 0 and s["crack_length"] > 0     # the notches cracked
    assert s["area_final"] == s["area_initial"]
    assert len(s["energy"]) == len(s["newton_iterations"]) == s["n_steps"]
    assert not (out / "final.png").exists()                        # --pictures none
    assert f"{s['n_steps']} steps" in proc.stdout


def test_failed_run_exits_1_with_the_last_good_state(tmp_path, capsys, monkeypatch):
    def faulty_plate(maxh=0.034):
        """The plate with a NaN body force beyond 2.5 dx."""
        base = scenes.plate(maxh=maxh, radius=None)

        def apply_load(prob, x):          # every solve beyond 2.5 dx gets a NaN body force
            base.apply_load(prob, x)
            if x > 2.5 * base.dx:
                prob.add_body_force((float("nan"), 0.0))

        return Scene(name="plate", mesh=base.mesh, material=base.material, critical=base.critical,
                     apply_load=apply_load, load_max=base.load_max, dx=base.dx, contact_tol=base.contact_tol,
                     parameters=base.parameters)

    monkeypatch.setitem(scenes.SCENES, "plate", faulty_plate)
    out = tmp_path / "o"
    assert main(["run", "plate", *SMALL, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "ngfracture run: failed: step 3" in err and "nan" in err and "Traceback" not in err
    s = json.loads((out / "summary.json").read_text())
    assert s["reason"] == "failed" and s["n_steps"] == 2          # the last good state
    assert (out / "checkpoint_000002.npz").exists()


def test_the_scenes_own_max_steps_holds_unless_steps_is_given(tmp_path, monkeypatch):
    """Measured before: --steps defaulted to 200 and overrode a scene's max_steps (the beam's
    1000)."""
    def plate_of_three_steps(maxh=0.034):
        """The plate, three steps at most."""
        scene = scenes.plate(maxh=maxh, radius=None)
        scene.control = {**scene.control, "max_steps": 3}
        return scene

    monkeypatch.setitem(scenes.SCENES, "plate", plate_of_three_steps)
    for extra, steps in (([], 3), (["--steps", "2"], 2)):
        out = tmp_path / str(steps)
        assert main(["run", "plate", *SMALL, "--out", str(out), *extra]) == 0
        s = json.loads((out / "summary.json").read_text())
        assert s["reason"] == "max_steps" and s["n_steps"] == steps and s["control"]["max_steps"] == steps


def test_a_run_with_notes_says_so_in_its_closing_lines(tmp_path, capsys):
    """A departure from the plain path is in summary.json; the closing lines say how many
    there are and repeat the last (the coarse sphere's eighth step leaves vertices no
    splitting rule cuts: docs/solid.md, "Refused vertices in runs")."""
    out = tmp_path / "o"
    assert main(["run", "sphere3d", "--set", "maxh=0.4", "--set", "fine=0.15", "--steps", "8", "--quiet",
                 "--pictures", "none", "--out", str(out)]) == 0
    notes = json.loads((out / "summary.json").read_text())["notes"]
    assert notes and "overstrained (up to" in notes[-1]["note"] and "where no splitting rule cuts" in notes[-1]["note"]
    line = f'{len(notes)} notes in summary.json ("notes"), the last of step {notes[-1]["step"]}: {notes[-1]["note"]}'
    assert line in capsys.readouterr().out.splitlines()


if __name__ == "__main__":
    raise SystemExit(pytest.main([__file__, "-q"]))


def test_progress_bar_shows_the_load_reached():
    from ngfracture.cli import progress_bar
    info = {"x": 2.5e-4, "load_max": 1e-3, "step": 7, "split_vertices": 12, "fragments": 2, "seconds": 3.25}
    line = progress_bar(info, width=20)
    assert line.startswith("[" + "#" * 5 + "." * 15 + "]  25%")
    assert "step    7" in line and "split vertices     12" in line and "fragments    2" in line and "3.2 s" in line
    assert progress_bar({**info, "x": 2e-3}).startswith("[" + "#" * 20 + "] 100%")   # clipped
