"""The cost of contact in the cracking 3D scenes: with contact rows from the first crack against none.

    python benchmarks/contact3d_cracking.py --json out/contact3d_cracking.json
    python benchmarks/contact3d_cracking.py --cases bar3d_coarse random_1 --json out/quick.json

Every case runs twice, each run in a process of its own (``--timeout`` seconds at most),
"never" first and then "contact", case after case (on a shared machine the two runs of a
case are close in time). "never": ``Simulation(contact="never")``, no contact rows (the
default of a 3D scene with ``Scene.contact`` False, bar3d, plate3d, shaft3d); "contact":
the scene with ``Scene.contact=True`` and ``contact="auto"``. Every case is a single body,
which solves without collision work until it cracks (``ContactSolver.solve``): contact
from the start is contact from the first crack. The random boxes are
``ngfracture.studies.random_solids.draw(seed, coarse=True)``. Reported per run:

  cpu_seconds        the process's CPU seconds for the run (time.process_time), without
                     the checks below
  reason, failure, steps, split_vertices, crack_area, fragments
  deepest            the largest ``overlap_area`` of the history: in 3D the deepest
                     boundary vertex of a piece inside another piece
  max_overlap_volume the largest overlap volume between fragments over the accepted
                     steps (tests/invariant_util.py ``check_accepted_3d``, exact clipping),
                     with ``violations`` (the steps whose overlap passes 1e-10 of the volume)
  max_rows           the most active contact rows of an accepted step

and per case ``cpu_ratio``: the "contact" run's CPU seconds over the "never" run's.
"""
import argparse
import dataclasses
import json
import subprocess
import sys
import time
import warnings
from pathlib import Path

import benchmark_json

HERE = Path(__file__).resolve().parent
CASES = ["bar3d_coarse", "bar3d_0.25", "bar3d_default", "plate3d_default", "plate3d_0.2", "shaft3d_default",
         "random_1", "random_2", "random_3"]


def make_scene(case, contact):
    """The scene of a case name, with ``Scene.contact`` set to ``contact``."""
    import ngfracture as nf
    from ngfracture.studies import random_solids
    if case.startswith("random_"):
        params = random_solids.draw(int(case.split("_")[1]), coarse=True)
        return random_solids.scene(**{**params, "contact": contact})
    name, mesh = case.rsplit("_", 1)
    factory = getattr(nf.scenes, name)
    if mesh == "coarse":
        scene = factory(maxh=0.4, radius=0.2, thickness=0.25)     # tests/test_solid_resume.py's bar
    else:
        scene = factory() if mesh == "default" else factory(maxh=float(mesh))
    return dataclasses.replace(scene, contact=contact)


def one_run(case, mode):
    """Run one case ("never" or "contact") in this process; returns its record."""
    import tempfile
    sys.path.insert(0, str(HERE.parent / "tests"))
    warnings.simplefilter("ignore")
    import ngfracture as nf
    from invariant_util import check_accepted_3d, reference_volume
    from ngfracture.geometry.solid import solid_to_arrays

    scene = make_scene(case, mode == "contact")
    a = solid_to_arrays(scene.mesh)
    volume = reference_volume(a.points, a.tets)
    checks, overlaps, violations, rows = [0.0], [], [], []

    def on_step(step):
        c = time.process_time()
        try:
            overlaps.append(check_accepted_3d(step, volume))
        except AssertionError as err:
            violations.append(str(err))
        rows.append(len(step.attempt.contact_keys))
        checks[0] += time.process_time() - c

    c0 = time.process_time()
    with tempfile.TemporaryDirectory() as out:
        result = nf.Simulation(scene, out=out, pictures="none",
                               contact="auto" if mode == "contact" else "never").run(on_step=on_step)
    cpu = time.process_time() - c0 - checks[0]
    s = result.summary
    return {"case": case, "mode": mode, "tets": int(scene.mesh.ne), "cpu_seconds": cpu, "reason": result.reason,
            "failure": s.get("failure"), "steps": s["n_steps"], "split_vertices": s["n_split_vertices"],
            "crack_area": s["crack_area"], "fragments": s["n_fragments"],
            "deepest": max((h["overlap_area"] for h in s["history"]), default=0.0),
            "max_overlap_volume": max(overlaps, default=0.0), "violations": violations,
            "max_rows": max(rows, default=0)}


def run_case(case, mode, timeout):
    """One run in a child process, with a time limit."""
    cmd = [sys.executable, __file__, "--one", case, mode]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"case": case, "mode": mode, "reason": "timeout", "seconds": timeout}
    if proc.returncode != 0:
        return {"case": case, "mode": mode, "reason": "crashed", "message": proc.stderr.strip().splitlines()[-1:]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", default=CASES, choices=CASES)
    parser.add_argument("--timeout", type=float, default=1500.0, help="seconds per run")
    parser.add_argument("--one", nargs=2, default=None, help=argparse.SUPPRESS)
    benchmark_json.add_options(parser)
    args = parser.parse_args()
    if args.one is not None:
        print(json.dumps(one_run(*args.one), default=float))
        return 0
    if not args.timeout > 0:
        parser.error(f"--timeout must be positive, got {args.timeout}")
    benchmark_json.refuse_existing(parser, args)
    cases = []
    for case in args.cases:
        never, contact = (run_case(case, mode, args.timeout) for mode in ("never", "contact"))
        timed = "cpu_seconds" in contact and "cpu_seconds" in never
        cases.append({"case": case, "never": never, "contact": contact,
                      "cpu_ratio": contact["cpu_seconds"] / never["cpu_seconds"] if timed else None})
    benchmark_json.write(args, {"cases": cases})
    return 0


if __name__ == "__main__":
    sys.exit(main())
