"""A run killed with SIGKILL at any moment resumes to the result of an uninterrupted run.

The runs are real processes (``python -c`` calling the CLI's ``main``) killed with
SIGKILL. One case kills during a checkpoint write: the child announces the write on
stdout from inside ``os.replace`` (wrapped in the atomic writer, for checkpoint files
only) and sleeps there; the kill lands between the fsync'ed temporary file and the rename.
The sweep over random moments is marked ``kill_sweep``: a plain ``pytest`` leaves it out,
the README's test command (and so CI) runs it.
"""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import pyvista as pv
from overlap3d_util import check_run_overlap

ARGS = ["run", "plate", "--maxh", "0.06", "--quiet", "--pictures", "none"]
#: the notched bar on tetrahedra, coarse
BAR3D_ARGS = ["run", "bar3d", "--maxh", "0.4", "--set", "radius=0.2", "--set", "thickness=0.25", "--quiet",
              "--pictures", "none"]
#: the 3D contact scene: two blocks meshed apart, pressed on each other (contact rows from the start)
BLOCKS3D_ARGS = ["run", "blocks3d", "--quiet", "--pictures", "none"]
#: the plate from a coarse start, refined ahead of its crack tips (Scene.refine) in every step
REFINED_ARGS = ["run", "plate", "--maxh", "0.1", "--set", "refine=true", "--quiet", "--pictures", "none"]

CHILD = """
import os, sys, time
from ngfracture.output import atomic
from ngfracture.cli import main
real = os.replace
slow = int(sys.argv[1])
class Replace:
    calls = 0
def replace(src, dst):
    if "checkpoint_" in os.path.basename(dst):
        Replace.calls += 1
        if Replace.calls == slow:
            print("WRITING", flush=True)
            time.sleep(30)
    return real(src, dst)
if slow > 0:
    atomic.os = type(os)("os_wrapped")
    atomic.os.__dict__.update(os.__dict__)
    atomic.os.replace = replace
sys.exit(main(sys.argv[2:]))
"""


def _env():
    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in env["PYTHONPATH"].split(os.pathsep))
    return env


def _start(out, cwd, slow=0, resume=False, args=ARGS):
    cmd = [sys.executable, "-c", CHILD, str(slow), *args, "--out", str(out)] + (["--resume"] if resume else [])
    return subprocess.Popen(cmd, cwd=cwd, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _finish(proc):
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    return out


def _compare(a, b):
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for key in sb:
        if key not in ("timings",):
            assert sa[key] == sb[key], key
    # every step's files, not only the last: a resumed run rewrites none of them differently
    names = sorted(p.name for pattern in ("step_*.vtu", "cracks_*.vtp") for p in b.glob(pattern))
    assert names == sorted(p.name for pattern in ("step_*.vtu", "cracks_*.vtp") for p in a.glob(pattern))
    assert len(names) == 2 * (sb["n_steps"] + 1)
    for name in names:
        ga, gb = pv.read(a / name), pv.read(b / name)
        assert np.array_equal(ga.points, gb.points), name
        for k in gb.point_data:
            assert np.array_equal(ga.point_data[k], gb.point_data[k]), (name, k)
        for k in gb.cell_data:
            assert np.array_equal(ga.cell_data[k], gb.cell_data[k]), (name, k)
    ra, rb = pv.get_reader(str(a / "results.pvd")), pv.get_reader(str(b / "results.pvd"))
    assert ra.time_values == rb.time_values


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    d = tmp_path_factory.mktemp("reference")
    _finish(_start(d / "run", d))
    return d / "run"


def test_kill_during_a_checkpoint_write_resumes_to_the_same_result(reference, tmp_path):
    out = tmp_path / "run"
    proc = _start(out, tmp_path, slow=3)        # inside the write of the third checkpoint
    line = proc.stdout.readline()
    assert line.strip() == "WRITING", proc.stderr.read()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert any(p.name.startswith(".tmp_ngf_") for p in out.iterdir())   # the half-done write
    _finish(_start(out, tmp_path, resume=True))
    assert not any(p.name.startswith(".tmp_ngf_") for p in out.iterdir())
    _compare(out, reference)


@pytest.mark.slow
def test_a_refined_run_killed_during_a_checkpoint_write_resumes_to_the_same_result(tmp_path):
    reference = tmp_path / "reference"
    _finish(_start(reference, tmp_path, args=REFINED_ARGS))
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["history"][-1]["triangles"] > summary["history"][0]["triangles"] > 0    # it refined
    out = tmp_path / "run"
    proc = _start(out, tmp_path, slow=4, args=REFINED_ARGS)      # the fourth checkpoint: the mesh refined at the tips
    assert proc.stdout.readline().strip() == "WRITING", proc.stderr.read()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    _finish(_start(out, tmp_path, resume=True, args=REFINED_ARGS))
    _compare(out, reference)


@pytest.mark.kill_sweep
@pytest.mark.parametrize("seed", range(5))
def test_kill_at_a_random_moment_resumes_to_the_same_result(reference, tmp_path, seed):
    total = json.loads((reference / "summary.json").read_text())["timings"]["wall"]
    delay = 1.5 + np.random.default_rng(seed).random() * total     # interpreter start-up ~1.5 s
    out = tmp_path / "run"
    proc = _start(out, tmp_path)
    time.sleep(delay)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    if not (out.exists() and any(p.name.startswith("checkpoint_") for p in out.iterdir())):
        # killed before the first checkpoint: a resume is refused clearly, a fresh run works
        proc = _start(out, tmp_path, resume=True)
        _, err = proc.communicate(timeout=600)
        assert proc.returncode == 2 and "no checkpoint" in err, err
        _finish(subprocess.Popen([sys.executable, "-c", CHILD, "0", *ARGS, "--out", str(out), "--force"],
                                 cwd=tmp_path, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True))
    else:
        _finish(_start(out, tmp_path, resume=True))
    _compare(out, reference)


@pytest.mark.slow
def test_a_3d_run_killed_during_a_checkpoint_write_resumes_to_the_same_result(tmp_path):
    reference = tmp_path / "reference"
    _finish(_start(reference, tmp_path, args=BAR3D_ARGS))
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["n_split_vertices"] > 0 and summary["n_tetrahedra"] > 0
    out = tmp_path / "run"
    proc = _start(out, tmp_path, slow=2, args=BAR3D_ARGS)
    assert proc.stdout.readline().strip() == "WRITING", proc.stderr.read()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    _finish(_start(out, tmp_path, resume=True, args=BAR3D_ARGS))
    _compare(out, reference)
    check_run_overlap(out)                   # every written step: the halves do not overlap


@pytest.mark.slow
def test_a_3d_contact_run_killed_during_a_checkpoint_write_resumes_to_the_same_result(tmp_path):
    reference = tmp_path / "reference"
    _finish(_start(reference, tmp_path, args=BLOCKS3D_ARGS))
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["reason"] == "load_max" and summary["n_fragments"] == 2
    out = tmp_path / "run"
    proc = _start(out, tmp_path, slow=2, args=BLOCKS3D_ARGS)
    assert proc.stdout.readline().strip() == "WRITING", proc.stderr.read()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    _finish(_start(out, tmp_path, resume=True, args=BLOCKS3D_ARGS))
    _compare(out, reference)
    check_run_overlap(out)
