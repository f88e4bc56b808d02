"""Benchmark of whole fracture simulations: wall time per phase, in solve-equivalents.

For each scene and each refinement factor f (default 1, 4, 16: the scene's default mesh
and f times more triangles, maxh / sqrt(f)) one simulation runs to its end (a plate ends
once it is broken through), writing its outputs into a temporary folder (no pictures).
Reported per case:

  radius, ntri, nsteps, reason, n_split_vertices, n_fragments
  phases       seconds per phase of Simulation (solve, linear, assembly, strain, split,
               rebuild, collision, contact, output) and wall
  t_unit       one factorisation plus one solve of the uncracked configuration's tangent
               (the scene's mesh and constraints at the first increment, NGSolve's sparse
               Cholesky, one thread), measured in the same process: the mean of the best of
               three before the run (t_unit_before) and the best of three after it
               (t_unit_after), so that a shared machine's change of speed during the run
               moves the unit with it
  solve_equivalents      wall / t_unit: the run in units of one linear solve of its own
               size, a figure that does not depend on the machine's speed
  seconds_per_step, solve_equivalents_per_step
  checks_share           checks / wall: the invariants judged before every step is accepted
  outside_solve_share    1 - solve / wall: everything outside the Newton solves (crack
               criterion, splitting, rebuilding, collision, contact rows, output)
  outside_fe_share       1 - (linear + assembly) / wall: everything but NGSolve's finite
               element work and the linear algebra
  outside_linear_share   1 - linear / wall: everything but factorisations and triangular
               solves (it counts the residual assembly as overhead)

and per scene run at two or more factors:

  growth       the exponent p of the least-squares fit seconds_per_step ~ ntri^p over
               the factors (and of wall, of wall per split vertex and of t_unit ~ ntri^p),
               with the cases it was fitted to

Writes JSON {"cases": [...], "growth": {...}} (stdout, or the file of --json FILE). Targets: cost per step grows at
most like N^1.2 between the 1x, 4x and 16x plate; the 16x plate (about 31k triangles)
runs until broken in at most 150 solve-equivalents; the holed beam (``--scenes holed_beam
--factors 1 4``: its band meshed at r/4 and r/8) in at most 400 solve-equivalents at 4x. The modules the run loads on first
use (pyvista, matplotlib) are imported before the first case, as NGSolve itself is: a
once-per-process cost that would otherwise land in the first case's "output" phase only.

Usage: python benchmarks/scenes.py [--scenes plate disk] [--factors 1 4 16] [--steps N] [--one-ring]
       [--json FILE [--force]]
"""
import argparse
import json
import math
import sys
import tempfile
import time

import numpy as np
import ngsolve

import benchmark_json
from ngfracture import scenes
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture import Simulation, StepControl


def unit_solve(scene):
    """Seconds of one factorisation and one solve of the scene's uncracked tangent (best of 3).

    The tangent at u = 0 with the constraints of the first increment; the dofs they fix
    and one pin per rigid mode they leave free are left out, as the simulation does. Plain
    NGSolve: the energy form's own linearisation and NGSolve's matrix.
    """
    prob = ElasticProblem(scene.mesh, scene.material, order=1)
    scene.apply_load(prob, scene.dx)
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    prob.form.AssembleLinearization(prob.u.vec)
    K = prob.form.mat
    free = ngsolve.BitArray(prob.fes.ndof)
    free.Set()
    for d in np.concatenate([rows.fixed_dofs, support.pins]).tolist():
        free.Clear(int(d))
    rhs = K.CreateColVector()
    rhs.FV().NumPy()[:] = 1.0
    x = K.CreateColVector()
    best = math.inf
    before = ngsolve.GetNumThreads()
    ngsolve.SetNumThreads(1)          # as the simulation factorises (kkt.reproducible_threads)
    try:
        for _ in range(3):
            t0 = time.perf_counter()
            inverse = K.Inverse(free, inverse="sparsecholesky")
            x.data = inverse * rhs
            best = min(best, time.perf_counter() - t0)
    finally:
        ngsolve.SetNumThreads(before)
    return best


def run_case(name, factor, steps=None, one_ring=False):
    criterion = {"radius": None} if one_ring else {}
    base = scenes.SCENES[name](**criterion)
    # every mesh size the scene declares shrinks by sqrt(factor): maxh, and the band's where it has one
    sizes = {k: base.parameters[k] / math.sqrt(factor) for k in ("maxh", "fine") if k in base.parameters}
    scene = scenes.SCENES[name](**sizes, **criterion)
    t_unit_before = unit_solve(scene)
    control = StepControl(**{**scene.control, "max_steps": steps}) if steps else None
    with tempfile.TemporaryDirectory() as out:
        result = Simulation(scene, control, out=out, pictures="none").run()
    t_unit_after = unit_solve(scene)
    t_unit = 0.5 * (t_unit_before + t_unit_after)
    s = result.summary
    wall = s["timings"]["wall"]
    linear = s["timings"].get("linear", float("nan"))
    assembly = s["timings"].get("assembly", float("nan"))
    nsteps = max(s["n_steps"], 1)
    return {"scene": name, "factor": factor, "radius": scene.radius, "ntri": scene.mesh.ne,
            "reason": result.reason, "max_steps": steps,
            "nsteps": s["n_steps"], "n_split_vertices": s["n_split_vertices"],
            "n_fragments": s["n_fragments"], "phases": s["timings"], "linear": linear,
            "assembly": assembly, "t_unit": t_unit, "t_unit_before": t_unit_before,
            "t_unit_after": t_unit_after, "solve_equivalents": wall / t_unit,
            "seconds_per_step": wall / nsteps, "solve_equivalents_per_step": wall / t_unit / nsteps,
            "outside_solve_share": 1.0 - s["timings"]["solve"] / wall,
            "checks_share": s["timings"].get("checks", 0.0) / wall,     # the invariants of every step
            "outside_fe_share": 1.0 - (linear + assembly) / wall,
            "outside_linear_share": 1.0 - linear / wall}


def growth(cases):
    """Per scene with two or more factors: fitted exponents of cost per step and of wall against ntri."""
    fits = {}
    for name in dict.fromkeys(c["scene"] for c in cases):
        mine = [c for c in cases if c["scene"] == name]
        if len({c["ntri"] for c in mine}) < 2:
            continue
        logn = np.log([c["ntri"] for c in mine])
        exponent = lambda values: float(np.polyfit(logn, np.log(values), 1)[0])
        fits[name] = {"factors": [c["factor"] for c in mine], "ntri": [c["ntri"] for c in mine],
                      "seconds_per_step_exponent": exponent([c["seconds_per_step"] for c in mine]),
                      # a finer band splits more vertices per crack length: the cost of one split
                      "seconds_per_split_exponent": exponent([c["phases"]["wall"] / max(c["n_split_vertices"], 1)
                                                              for c in mine]),
                      "wall_exponent": exponent([c["phases"]["wall"] for c in mine]),
                      "t_unit_exponent": exponent([c["t_unit"] for c in mine])}
    return fits


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", default=["plate", "disk"], choices=sorted(scenes.SCENES))
    p.add_argument("--factors", nargs="+", type=int, default=[1, 4, 16])
    p.add_argument("--steps", type=int, default=None,
                   help="stop every run after this many steps (for the finest meshes; the "
                        "shares are then those of the first steps)")
    p.add_argument("--one-ring", action="store_true",
                   help="the paper's one-ring criterion (radius=None) instead of the scenes' critical distance")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    benchmark_json.refuse_existing(p, args)   # before hours of runs
    import pyvista, matplotlib.figure  # noqa: F401  (see the module docstring)
    cases = []
    for name in args.scenes:
        for f in args.factors:
            cases.append(run_case(name, f, args.steps, args.one_ring))
            print(json.dumps(cases[-1]), file=sys.stderr)
    benchmark_json.write(args, {"cases": cases, "growth": growth(cases)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
