"""A 3D scene's run with its split meshes solved through the bordered factorisation against
the same run with every split mesh factorised afresh.

Runs ``python -m ngfracture run SCENE --steps N`` twice, one run after the other, each in a
process of its own (one thread): once as it is (crack passes carry the factorisation of the
mesh their chain started from, ``linalg/bordered.py``) and once with
``BorderedFactor.build`` returning None (every split mesh factorised afresh, the baseline).
Reports the CPU seconds of both, their ratio, the factorisations and split vertices of each
(from the runs' ``summary.json``), and whether the two runs end on the same mesh (points,
tetrahedra and faces equal) with the largest difference of their displacements. With
``--resume DIR`` both start from a copy of the run folder DIR (its newest checkpoint) and
run to step N.

Run:  PYTHONPATH=. OMP_NUM_THREADS=1 python benchmarks/bordered3d.py [--scene sphere3d]
      [--steps 8] [--resume DIR] [--json FILE [--force]]
"""
import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmark_json  # noqa: E402

#: the baseline's process: the CLI with the bordered factorisation switched off
FRESH = ("import sys\n"
         "from ngfracture.linalg import bordered\n"
         "bordered.BorderedFactor.build = classmethod(lambda cls, *args: None)\n"
         "from ngfracture.cli import main\n"
         "sys.exit(main(sys.argv[1:]))\n")


def run_once(scene, steps, out, fresh, resume):
    """One run in a child process; returns its CPU seconds (user + system)."""
    argv = ["run", scene, "--steps", str(steps), "--out", str(out), "--pictures", "none",
            "--progress", "none", "--threads", "1"]
    if resume:
        argv.append("--resume")
    cmd = [sys.executable, "-c", FRESH] if fresh else [sys.executable, "-m", "ngfracture"]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd + argv, check=True, env=env, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def newest_checkpoint(out):
    """The arrays of the newest checkpoint of a run folder."""
    return np.load(sorted(Path(out).glob("checkpoint_*.npz"))[-1], allow_pickle=False)


def summary_of(out):
    """Steps, split vertices, factorisations (of the whole run, resumed or not), Newton
    iterations, whether the volume is the initial one to the last bit and the largest
    overlap of the run's steps, from its summary.json."""
    s = json.loads((Path(out) / "summary.json").read_text())
    solvers = s["timings"].get("linear_solver", {})
    overlaps = [h["overlap_area"] for h in s["history"] if h.get("overlap_area") is not None]
    return {"steps": s["n_steps"], "split_vertices": s["n_split_vertices"], "reason": s["reason"],
            "factorisations": sum(v.get("factorisations", 0) for v in solvers.values()),
            "newton_iterations": sum(s["newton_iterations"]),
            "volume_equal": s["volume_initial"] == s["volume_final"],
            "max_overlap": max(overlaps, default=None)}


def compare(a, b):
    """Same mesh (points, tetrahedra, faces) and the largest displacement difference."""
    A, B = newest_checkpoint(a), newest_checkpoint(b)
    same = all(np.array_equal(A[k], B[k]) for k in ("a_mesh_points", "a_mesh_tets", "a_mesh_faces"))
    du = float(np.max(np.abs(A["a_u"] - B["a_u"]))) if same else None
    return {"same_mesh": same, "max_u_difference": du, "max_u": float(np.max(np.abs(B["a_u"])))}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="sphere3d")
    p.add_argument("--steps", type=int, default=8, help="accepted load steps to run to (default 8)")
    p.add_argument("--resume", metavar="DIR", help="start both runs from a copy of this run folder")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    benchmark_json.refuse_existing(p, args)
    result = {"scene": args.scene, "steps": args.steps, "resume": args.resume}
    with tempfile.TemporaryDirectory() as tmp:
        outs = {}
        for name in ("bordered", "fresh"):
            out = Path(tmp) / name
            if args.resume:
                shutil.copytree(args.resume, out)
            outs[name] = out
            cpu = run_once(args.scene, args.steps, out, name == "fresh", bool(args.resume))
            result[name] = {"cpu_seconds": cpu, **summary_of(out)}
        result["fresh_over_bordered"] = result["fresh"]["cpu_seconds"] / result["bordered"]["cpu_seconds"]
        result.update(compare(outs["bordered"], outs["fresh"]))
    benchmark_json.write(args, result)


if __name__ == "__main__":
    main()
