"""The confined sphere (``scenes.sphere3d``) in CPU seconds and solve-equivalents per load step.

Each case runs ``sphere3d`` at one ``fine`` (the mesh size at the hole and in the core;
default 0.15, 0.106 and 0.075: the default mesh and two coarsenings, each about half the
tetrahedra of the next) from the start, or, with ``--resume DIR``, from the newest
checkpoint of the run folder DIR (a default-mesh run, copied into a temporary folder
first: DIR is not written). A case stops after ``--steps`` accepted steps (from where it
started), or once its CPU time passes ``--cpu-limit`` seconds (the step under way is
finished), or at the scene's end.

Reported per case:

  fine, tets, dofs, start_step, steps, reason
  t_unit, cpu_t_unit   one sparse factorisation + solve of the sphere's linear elasticity
                       with the solver the run picks (as benchmarks/solid.py ``unit_solve``),
                       wall and CPU seconds, best of ``--repeat``, the mean of the
                       measurements before and after the run
  step, x_over_xc, split_vertices, fragments, retries, relax_passes   per accepted step
                       (x_c the exact first crack, ``spheres.sphere_first_crack``: 1.187e-3)
  step_wall, step_cpu  seconds of every accepted step (wall, and CPU of this process:
                       one thread, so the CPU time is the run's own on a shared machine)
  step_factorisations  factorisations of K_ff per step (benchmarks/contact3d.py ``LinalgCounts``)
  cpu, solve_equivalents        the whole case's CPU seconds, and over cpu_t_unit
  solve_equivalents_per_step    their mean per accepted step

and over the cases run from the start with the same number of steps: the least-squares
exponents p of value ~ tets^p of cpu, cpu_t_unit and solve_equivalents (``growth``;
None for fewer than two such cases).

Usage: PYTHONPATH=. OMP_NUM_THREADS=1 python benchmarks/sphere3d.py [--fine 0.15 0.106 0.075]
       [--steps N] [--cpu-limit SECONDS] [--resume DIR] [--repeat 2] [--json FILE [--force]]
"""
import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import benchmark_json
from contact3d import LinalgCounts, unit_solve

#: the default fine values: the default mesh (0.075) and two coarsenings
DEFAULT_FINE = [0.15, 0.106, 0.075]
#: steps per case by default (from the start: past the first cracked steps)
DEFAULT_STEPS = 8


class Stop(Exception):
    """Raised by the progress callback when a case has run its steps or its CPU budget."""


def cpu_unit(scene, repeat):
    """(wall, CPU, solver) of the best of ``repeat`` unit solves of the first increment's
    linear elasticity: benchmarks/contact3d.py ``unit_solve`` (one factorisation and one
    solve, one thread)."""
    from ngfracture.mechanics.problem import ElasticProblem
    prob = ElasticProblem(scene.mesh, scene.material, order=1)
    scene.apply_load(prob, scene.dx)
    return unit_solve(prob, repeat)


def run_case(fine, steps, cpu_limit, resume, repeat):
    """One case (see the module docstring): a dict of its numbers."""
    from ngfracture import Simulation, scenes
    from ngfracture.run.control import StepControl
    scene = scenes.SCENES["sphere3d"](fine=fine)
    x_c = scene.parameters["first_crack_exact"]
    wall0, cpu0_unit, solver = cpu_unit(scene, repeat)
    records, start = [], {}

    def progress(record):        # then ``accepted``, which may stop the run
        now = time.process_time()
        records.append({"step": record["step"], "x_over_xc": record["x"] / x_c,
                        "split_vertices": record["split_vertices"], "fragments": record["fragments"],
                        "wall": time.perf_counter() - start["wall"], "cpu": now - start["cpu"],
                        "factorisations": counts.factorisations})

    def accepted(step):
        records[-1].update(retries=step.record["retries"], relax_passes=step.record["relax_passes"])
        print(json.dumps(records[-1]), file=sys.stderr, flush=True)
        if (steps is not None and len(records) >= steps) or (cpu_limit is not None and records[-1]["cpu"] >= cpu_limit):
            raise Stop

    with tempfile.TemporaryDirectory() as tmp, LinalgCounts() as counts:
        out = Path(tmp) / "run"
        if resume is not None:
            shutil.copytree(resume, out)
        control = StepControl(max_steps=100000)
        simulation = Simulation(scene, control=control, out=out, resume=resume is not None, pictures="none",
                                progress=progress)
        start.update(wall=time.perf_counter(), cpu=time.process_time())
        try:
            reason = simulation.run(on_step=accepted).reason
        except Stop:
            reason = "stopped"
    wall1, cpu1_unit, _ = cpu_unit(scene, repeat)
    return summary(fine, scene, records, reason, 0.5 * (wall0 + wall1), 0.5 * (cpu0_unit + cpu1_unit), solver)


def summary(fine, scene, records, reason, t_unit, cpu_t_unit, solver):
    """The case's dict from its records (cumulative seconds and split vertices)."""
    wall = np.diff([0.0] + [r["wall"] for r in records])
    cpu = np.diff([0.0] + [r["cpu"] for r in records])
    fact = np.diff([0] + [r["factorisations"] for r in records])
    total = float(cpu.sum())
    steps = [r["step"] for r in records]
    return {"fine": fine, "tets": scene.mesh.ne, "dofs": 3 * scene.mesh.nv, "solver": solver,
            "start_step": steps[0] - 1 if steps else None, "steps": len(records), "reason": reason,
            "t_unit": t_unit, "cpu_t_unit": cpu_t_unit, "step": steps,
            "x_over_xc": [r["x_over_xc"] for r in records], "split_vertices": [r["split_vertices"] for r in records],
            "fragments": [r["fragments"] for r in records],
            "retries": [r.get("retries") for r in records], "relax_passes": [r.get("relax_passes") for r in records],
            "step_wall": wall.tolist(), "step_cpu": cpu.tolist(), "step_factorisations": fact.tolist(),
            "cpu": total, "solve_equivalents": total / cpu_t_unit,
            "solve_equivalents_per_step": total / cpu_t_unit / max(len(records), 1)}


def growth(cases):
    """Least-squares exponents of cpu, cpu_t_unit and solve_equivalents against tets over the
    cases run from the start with the same number of steps, or None."""
    fresh = [c for c in cases if c["start_step"] == 0]
    if len(fresh) < 2 or len({c["steps"] for c in fresh}) != 1:
        return None
    x = np.log([c["tets"] for c in fresh])
    return {"tets": [c["tets"] for c in fresh],
            **{key: float(np.polyfit(x, np.log([c[key] for c in fresh]), 1)[0])
               for key in ("cpu", "cpu_t_unit", "solve_equivalents")}}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fine", nargs="+", type=float, default=None,
                   help=f"the cases' fine (default {DEFAULT_FINE}; with --resume the run's own, 0.075)")
    p.add_argument("--steps", type=int, default=None,
                   help=f"accepted steps per case (default {DEFAULT_STEPS} without --cpu-limit)")
    p.add_argument("--cpu-limit", type=float, default=None, help="stop a case once its CPU seconds pass this")
    p.add_argument("--resume", default=None, metavar="DIR",
                   help="start from the newest checkpoint of this sphere3d run folder (copied, not written)")
    p.add_argument("--repeat", type=int, default=2, help="unit solves: best of this many (default 2)")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    if args.repeat < 1:
        p.error("--repeat must be at least 1")
    if args.steps is not None and args.steps < 1:
        p.error("--steps must be at least 1")
    if args.cpu_limit is not None and not args.cpu_limit > 0:
        p.error("--cpu-limit must be positive")
    if args.resume is not None and not Path(args.resume, "results.pvd").is_file():
        p.error(f"--resume {args.resume}: not a run folder (no results.pvd)")
    benchmark_json.refuse_existing(p, args)
    fine = args.fine or ([0.075] if args.resume else DEFAULT_FINE)
    steps = args.steps if args.steps is not None or args.cpu_limit is not None else DEFAULT_STEPS
    cases = []
    for f in fine:
        cases.append(run_case(f, steps, args.cpu_limit, args.resume, args.repeat))
        print(json.dumps({k: v for k, v in cases[-1].items() if not isinstance(v, list)}), file=sys.stderr,
              flush=True)
    benchmark_json.write(args, {"cases": cases, "growth": growth(cases)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
