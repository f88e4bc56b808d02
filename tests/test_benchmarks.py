"""Every benchmark takes ``--json FILE``, refuses an existing FILE before any work, and writes JSON."""
import json
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import child_env

ROOT = Path(__file__).resolve().parent.parent
BENCHMARKS = ["contact", "crack", "ensemble", "lshape", "meshcheck", "objectivity", "scenes", "schur"]


def run_benchmark(name, *args):
    return subprocess.run([sys.executable, str(ROOT / "benchmarks" / f"{name}.py"), *args],
                          capture_output=True, text=True, env=child_env(OMP_NUM_THREADS="1"), timeout=600)


@pytest.mark.parametrize("name", BENCHMARKS)
def test_existing_json_file_refused_untouched(name, tmp_path):
    target = tmp_path / "result.json"
    target.write_text("earlier result")
    r = run_benchmark(name, "--json", str(target))
    assert r.returncode == 2, r.stderr
    assert f"{target} exists; pass --force" in r.stderr
    assert target.read_text() == "earlier result"


def test_json_file_written_and_forced(tmp_path):
    target = tmp_path / "out" / "meshcheck.json"  # a missing folder is created
    for extra in ([], ["--force"]):
        r = run_benchmark("meshcheck", "--sizes", "2000", "--repeat", "1", "--threads", "1",
                          "--json", str(target), *extra)
        assert r.returncode == 0, r.stderr
        assert r.stdout == ""  # the JSON goes to the file, not to stdout
        (case,) = json.loads(target.read_text())["cases"]
        assert set(case) == {"ntri", "t_check", "t_check_cracked", "t_solve", "ratio"}


def test_schur_benchmark_builds_the_same_complement_both_ways(tmp_path):
    target = tmp_path / "schur.json"
    r = run_benchmark("schur", "--factors", "1", "--json", str(target))
    assert r.returncode == 0, r.stderr
    (case,) = json.loads(target.read_text())["cases"]
    assert case["rows"] > 10 and case["relative_difference"] < 1e-13     # rounding of two solves


@pytest.mark.parametrize("args, message", [(["--adaptive", "0"], "--adaptive must be a mesh size > 0"),
                                           (["--scenes", "disk", "--adaptive", "0.1"],
                                            "--adaptive: scene 'disk' has no refine parameter")])
def test_scenes_benchmark_refuses_a_bad_adaptive_case_before_any_run(args, message, tmp_path):
    r = run_benchmark("scenes", *args, "--json", str(tmp_path / "scenes.json"))
    assert r.returncode == 2 and message in r.stderr
    assert not (tmp_path / "scenes.json").exists()


def test_scenes_benchmark_puts_the_adaptive_run_beside_the_uniform_one(tmp_path):
    target = tmp_path / "scenes.json"
    r = run_benchmark("scenes", "--scenes", "plate", "--factors", "1", "--adaptive", "0.1", "--steps", "2",
                      "--json", str(target))
    assert r.returncode == 0, r.stderr
    result = json.loads(target.read_text())
    uniform, adaptive = result["cases"]
    assert uniform["factor"] == 1 and adaptive["adaptive_maxh"] == 0.1
    # the coarse start refines its notch tips to r/4 before the first step
    assert adaptive["ntri_end"] > adaptive["ntri"] and uniform["ntri_end"] == uniform["ntri"]
    pair = result["adaptive"]["plate"]
    assert pair["uniform_factor"] == 1 and pair["wall_ratio"] == adaptive["phases"]["wall"] / uniform["phases"]["wall"]
    assert pair["initiation_ratio"] is None          # two steps below the first crack
