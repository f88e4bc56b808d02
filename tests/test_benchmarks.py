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
