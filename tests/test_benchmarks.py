"""Every benchmark takes ``--json FILE``, refuses an existing FILE before any work, and writes JSON."""
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import child_env

ROOT = Path(__file__).resolve().parent.parent
BENCHMARKS = ["contact", "contact_qp", "contact3d", "contact3d_cracking", "crack", "edges3d", "ensemble",
              "linear3d", "lshape", "meshcheck", "objectivity", "random_scenes", "scenes", "schur",
              "sphere3d", "solid"]


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


def test_solid_benchmark_breaks_the_small_bar_and_reports_positive_ratios(tmp_path):
    target = tmp_path / "solid.json"
    r = run_benchmark("solid", "--quick", "--json", str(target))
    assert r.returncode == 0, r.stderr
    result = json.loads(target.read_text())
    (case,) = result["cases"]
    assert case["reason"] == "broken" and case["fragments"] == 2
    assert case["dofs"] == 3 * case["vertices"] and case["tets"] > case["vertices"]
    assert case["solver"] == "sparsecholesky"     # 3D: linalg.iterative.problem_inverse
    assert case["crack_passes"] >= case["steps"] >= 1
    for key in ("wall", "t_unit", "solve_equivalents", "crack_work_ratio", "crack_work_per_pass_ratio",
                "crack_area_ratio", "projected_area_ratio", "rss_peak_gib"):
        assert math.isfinite(case[key]) and case[key] > 0, key
    # the crack work is part of the run, and one pass's share of it part of the whole
    assert case["crack_work"] < case["wall"]
    assert case["crack_work_per_pass_ratio"] * case["crack_passes"] == \
        pytest.approx(case["crack_work_ratio"], rel=1e-12)
    # the two fragments hold the two ends: every line along x through the ligament meets the
    # crack, so its projection covers the ligament; |n_x| <= 1: the area is at least that
    assert case["crack_area_ratio"] >= case["projected_area_ratio"] * (1 - 1e-12)
    assert case["projected_area_ratio"] >= 1 - 1e-12
    assert case["rss_peak_gib"] >= case["rss_import_gib"]
    assert result["growth"] is None               # one size: nothing to fit
    assert set(result["targets"]) == {"crack_work_per_pass_ratio_at_200k", "crack_work_per_pass_exponent",
                                      "solve_equivalents_at_100k", "rss_peak_gib_at_500k"}


def test_solid_benchmark_refuses_a_bad_size_before_any_run(tmp_path):
    r = run_benchmark("solid", "--sizes", "0.25/-1", "--json", str(tmp_path / "solid.json"))
    assert r.returncode == 2 and "a size is MAXH/FINE or FINE with numbers > 0" in r.stderr


@pytest.mark.parametrize("args, message", [(["--set", "maxh"], "--set needs NAME=VALUE"),
                                           (["--vary", "fine", "--set", "fine=0.1"], "exclude each other"),
                                           (["--set", "width=1"], "scene 'sphere3d' takes no width"),
                                           (["--steps", "0"], "--steps must be at least 1")])
def test_contact3d_scene_options_refused_before_any_run(args, message, tmp_path):
    target = tmp_path / "contact3d.json"
    r = run_benchmark("contact3d", "--scene", "sphere3d", *args, "--json", str(target))
    assert r.returncode == 2 and message in r.stderr, r.stderr
    assert not target.exists()


def test_contact3d_scene_sizes_vary_the_named_parameter():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import contact3d
    sizes = contact3d.scene_sizes("sphere3d", [0.15, 0.1], "fine", contact3d.parsed_settings(["maxh=0.4"]))
    assert sizes == [{"maxh": 0.4, "fine": 0.15}, {"maxh": 0.4, "fine": 0.1}]
    # the default maxh times the factors, exactly
    assert [s["maxh"] for s in contact3d.scene_sizes("sphere3d", None)] == [0.25 * f for f in contact3d.SCENE_FACTORS]
    records = [{"step": 1, "split_vertices": 0, "seconds": 1.0}, {"step": 2, "split_vertices": 3, "seconds": 2.5},
               {"step": 3, "split_vertices": 9, "seconds": 4.0}]
    assert contact3d.first_crack(records) == (2, 2.5) and contact3d.first_crack(records[:1]) == (None, None)


@pytest.mark.slow
def test_contact3d_scene_run_stops_at_its_first_crack(tmp_path):
    target = tmp_path / "contact3d.json"
    r = run_benchmark("contact3d", "--scene", "sphere3d", "--vary", "fine", "--values", "0.15", "--set", "maxh=0.4",
                      "--until-crack", "--repeat", "1", "--json", str(target))
    assert r.returncode == 0, r.stderr
    (case,) = json.loads(target.read_text())["cases"]
    k = case["first_crack_step"]
    assert case["reason"] == "first_crack" and case["steps"] == k == len(case["step_seconds"])
    assert case["split_vertices"][:k - 1] == [0] * (k - 1) and case["split_vertices"][k - 1] > 0
    assert case["seconds_to_first_crack"] == case["step_seconds"][-1] <= case["wall"]
    assert case["solve_equivalents_to_first_crack"] == case["seconds_to_first_crack"] / case["t_unit"]


def test_random_solids_benchmark_checks_every_step_of_a_broken_box(tmp_path):
    # seed 3 is a coarse box that breaks into pieces within 8 steps: the benchmark's own
    # checks (volume to the last bit, no inverted tetrahedron, overlap between pieces at
    # most 1e-10 of the volume, from the arrays, not from the contact code) see pieces
    target = tmp_path / "random3d.json"
    r = run_benchmark("random_scenes", "--solids", "--cases", "1", "--seed", "3", "--workers", "1",
                      "--max-steps", "8", "--timeout", "500", "--json", str(target))
    assert r.returncode == 0, r.stderr
    result = json.loads(target.read_text())
    (record,) = result["records"]
    assert record["reason"] in ("broken", "load_max", "max_steps"), record
    assert record["fragments"] >= 2 and record["violations"] == []
    assert result["silent_violations"] == 0 and result["to_replay"] == []
