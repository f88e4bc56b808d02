"""Many random scenes (ngfracture.studies.random_scenes): how each ended, and any invariant broken.

    python benchmarks/random_scenes.py --cases 40 --seed 1 --json out/random.json
    python benchmarks/random_scenes.py --solids --cases 20 --seed 1 --json out/random3d.json

``--solids`` draws the coarse 3D scenes of ngfracture.studies.random_solids (boxes with
spherical holes and a slot, 840 to 1900 tetrahedra) and checks every accepted step as the
2D cases are checked (tests/invariant_util.py, ``check_accepted_3d``): the reference volume
to the last bit, no inverted tetrahedron and the overlap between fragments (exact
intersections of the deformed tetrahedra, ngfracture.output.overlap3d) at most 1e-10 of
the volume. A 3D record has the case's CPU seconds (``cpu_seconds``), and a case
stopped by ``--timeout`` how far it got (``reached``: accepted steps, load, fragments, CPU
seconds at its last accepted step).

Every case runs in its own process (``--timeout`` seconds at most) with every accepted step
checked independently of the engine (tests/invariant_util.py: reference area with
math.fsum, deformed triangle areas, overlap by rasterisation). The JSON tallies the
endings (load_max, broken, max_steps, failed with its reason, timeout, crashed) and lists
every case that broke an invariant or crashed with its parameters, so that it can be
replayed: ``ngfracture run ngfracture.studies.random_scenes:scene --set ...``.
"""
import argparse
import collections
import json
import subprocess
import sys
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import benchmark_json

HERE = Path(__file__).resolve().parent


def one_case(seed, max_steps):
    """Run one case in this process; returns its record."""
    sys.path.insert(0, str(HERE.parent / "tests"))
    warnings.simplefilter("ignore")
    import ngfracture as nf
    from invariant_util import check_accepted, reference_area
    from ngfracture.geometry.meshio import mesh_to_arrays
    from ngfracture.studies import random_scenes

    params = random_scenes.draw(seed)
    record = {"seed": seed, "params": params}
    t0 = time.perf_counter()
    scene = random_scenes.scene(**params)
    arrays = mesh_to_arrays(scene.mesh)
    area = reference_area(arrays.points, arrays.triangles)
    violations = []

    def check(step):
        try:
            check_accepted(step, area)
        except AssertionError as err:
            violations.append({"step": step.state.step, "check": str(err)})

    result = nf.Simulation(scene, nf.StepControl(max_steps=max_steps), pictures="none").run(on_step=check)
    s = result.summary
    record.update(reason=result.reason, message=result.message, failure=s.get("failure"), steps=s["n_steps"],
                  triangles=scene.mesh.ne, fragments=s["n_fragments"], seconds=time.perf_counter() - t0,
                  area_kept=s["area_final"] == area, max_overlap_area=s["max_overlap_area"],
                  violations=violations)
    return record


def one_solid_case(seed, max_steps):
    """Run one 3D case in this process; returns its record."""
    sys.path.insert(0, str(HERE.parent / "tests"))
    warnings.simplefilter("ignore")
    import ngfracture as nf
    from invariant_util import check_accepted_3d, reference_volume
    from ngfracture.geometry.solid import solid_to_arrays
    from ngfracture.studies import random_solids

    params = random_solids.draw(seed, coarse=True)      # contact rows from the start: hundreds of tetrahedra
    record = {"seed": seed, "params": params}
    t0, c0 = time.perf_counter(), time.process_time()
    scene = random_solids.scene(**params)
    reference = solid_to_arrays(scene.mesh)
    volume = reference_volume(reference.points, reference.tets)
    violations = []

    def check(step):
        try:
            check_accepted_3d(step, volume)
        except AssertionError as err:
            violations.append({"step": step.state.step, "check": str(err)})
        # how far the case got, for a case stopped by the time limit (run_case)
        print(json.dumps({"progress": {"steps": step.state.step, "x": step.state.x,
                                       "fragments": step.problem.fragments()[0],
                                       "cpu_seconds": time.process_time() - c0}}), flush=True)

    result = nf.Simulation(scene, nf.StepControl(max_steps=max_steps), pictures="none").run(on_step=check)
    s = result.summary
    record.update(reason=result.reason, message=result.message, failure=s.get("failure"), steps=s["n_steps"],
                  tetrahedra=scene.mesh.ne, fragments=s["n_fragments"], seconds=time.perf_counter() - t0,
                  cpu_seconds=time.process_time() - c0, violations=violations)
    return record


def run_case(seed, max_steps, timeout, solids=False):
    """One case in a child process, with a time limit."""
    cmd = [sys.executable, __file__, "--one", str(seed), "--max-steps", str(max_steps)] + (["--solids"] if solids else [])
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as stopped:
        out = stopped.stdout.decode() if isinstance(stopped.stdout, bytes) else stopped.stdout or ""
        progress = [json.loads(line)["progress"] for line in out.splitlines() if line.startswith('{"progress"')]
        return {"seed": seed, "reason": "timeout", "seconds": timeout, "reached": progress[-1] if progress else None}
    if proc.returncode != 0:
        return {"seed": seed, "reason": "crashed", "message": proc.stderr.strip().splitlines()[-1:]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def tally(records):
    """Endings counted, and the cases to replay."""
    endings = collections.Counter(r["reason"] if r["reason"] != "failed" else f"failed:{r['failure']['reason']}"
                                  for r in records)
    bad = [r for r in records if r["reason"] in ("crashed", "timeout") or r.get("violations")
           or (r["reason"] != "failed" and r.get("area_kept") is False)]
    silent = [r for r in bad if r.get("violations") and r["reason"] in ("load_max", "broken", "max_steps")]
    return {"endings": dict(sorted(endings.items())), "cases": len(records), "to_replay": bad,
            "silent_violations": len(silent)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seed", type=int, default=1, help="the first seed (seeds S, S+1, ...)")
    parser.add_argument("--max-steps", type=int, default=40)
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per case")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--solids", action="store_true", help="the 3D scenes of ngfracture.studies.random_solids")
    parser.add_argument("--one", type=int, default=None, help=argparse.SUPPRESS)
    benchmark_json.add_options(parser)
    args = parser.parse_args()
    if args.one is not None:
        case = one_solid_case if args.solids else one_case
        print(json.dumps(case(args.one, args.max_steps), default=float))
        return 0
    benchmark_json.refuse_existing(parser, args)
    t0 = time.perf_counter()
    seeds = range(args.seed, args.seed + args.cases)
    with ThreadPoolExecutor(args.workers) as pool:
        records = list(pool.map(lambda s: run_case(s, args.max_steps, args.timeout, args.solids), seeds))
    result = {"seed": args.seed, "max_steps": args.max_steps, "solids": args.solids, "wall_seconds": time.perf_counter() - t0,
              **tally(records), "records": records}
    benchmark_json.write(args, result)
    return 1 if result["silent_violations"] else 0


if __name__ == "__main__":
    sys.exit(main())
