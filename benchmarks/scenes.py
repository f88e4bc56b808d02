"""Benchmark of whole fracture simulations: wall time per phase, in solve-equivalents.

For each scene and each refinement factor f (default 1, 4, 16: the scene's default mesh
and f times more triangles, maxh / sqrt(f)) one simulation runs to its end (a plate ends
once it is broken through), writing its outputs into a temporary folder (no pictures).
Reported per case:

  radius, ntri (at the start), ntri_end, nsteps, reason, n_split_vertices, n_fragments,
  initiation   the load at which the first vertex reaches its strength (the last uncracked
               step's load over its largest overstrain), crack_length at the end
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

With ``--adaptive MAXH`` each scene also runs from mesh size MAXH with refinement ahead of
its crack tips (``refine=True``, docs/criterion.md "Refinement ahead of the tips"), and

  adaptive     per scene: its initiation and crack length over the finest uniform case's,
               its wall time over that case's, its triangles at the start and the end

The plate's target: from maxh 0.1, the answer of the 64x plate (``--factors 64``, 124k
triangles) within 1 % (initiation) and 5 % (crack length) in at most 1/5 of its wall time.

Writes JSON {"cases": [...], "growth": {...}, "adaptive": {...}} (stdout, or the file of --json FILE). Targets: cost per step grows at
most like N^1.2 between the 1x, 4x and 16x plate; the 16x plate (about 31k triangles)
runs until broken in at most 150 solve-equivalents; the holed beam (``--scenes holed_beam
--factors 1 4``: its band meshed at r/4 and r/8) in at most 400 solve-equivalents at 4x. The modules the run loads on first
use (pyvista, matplotlib) are imported before the first case, as NGSolve itself is: a
once-per-process cost that would otherwise land in the first case's "output" phase only.

Usage: python benchmarks/scenes.py [--scenes plate disk] [--factors 1 4 16] [--steps N] [--one-ring]
       [--adaptive MAXH] [--json FILE [--force]]
"""
import argparse
import inspect
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


def run_case(name, factor, steps=None, one_ring=False, adaptive=None):
    """One simulation of a scene to its end: its phases, its unit solve and its answer.

    factor shrinks every mesh size the scene declares by sqrt(factor); adaptive (a maxh)
    instead starts from that mesh size and refines ahead of the crack tips (refine=True).
    """
    criterion = {"radius": None} if one_ring else {}
    base = scenes.SCENES[name](**criterion)
    if adaptive is not None:
        scene = scenes.SCENES[name](maxh=adaptive, refine=True, **criterion)
    else:
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
    return {"scene": name, "factor": None if adaptive is not None else factor, "adaptive_maxh": adaptive,
            "radius": scene.radius, "ntri": scene.mesh.ne, "ntri_end": s["history"][-1]["triangles"],
            "reason": result.reason, "max_steps": steps, "initiation": initiation(s["history"]),
            "crack_length": s["history"][-1]["crack_length"],
            "nsteps": s["n_steps"], "n_split_vertices": s["n_split_vertices"],
            "n_fragments": s["n_fragments"], "phases": s["timings"], "linear": linear,
            "assembly": assembly, "t_unit": t_unit, "t_unit_before": t_unit_before,
            "t_unit_after": t_unit_after, "solve_equivalents": wall / t_unit,
            "seconds_per_step": wall / nsteps, "solve_equivalents_per_step": wall / t_unit / nsteps,
            "outside_solve_share": 1.0 - s["timings"]["solve"] / wall,
            "checks_share": s["timings"].get("checks", 0.0) / wall,     # the invariants of every step
            "outside_fe_share": 1.0 - (linear + assembly) / wall,
            "outside_linear_share": 1.0 - linear / wall}


def initiation(history):
    """The load at which the first vertex reaches its strength: the last uncracked step's
    load over its largest overstrain (the measure grows with the load in proportion, up to
    the geometric nonlinearity's share, of the order of the strain); None if it never cracked."""
    first = next((i for i, h in enumerate(history) if h["split_vertices"]), None)
    if first is None:
        return None
    h = history[first - 1] if first > 0 else history[first]
    return h["x"] / h["overstrain"]


def side_by_side(cases):
    """Per scene with an adaptive case: its answer and cost against the finest uniform case."""
    pairs = {}
    for c in cases:
        if c["adaptive_maxh"] is None:
            continue
        uniform = [u for u in cases if u["scene"] == c["scene"] and u["adaptive_maxh"] is None]
        if not uniform:
            continue
        fine = max(uniform, key=lambda u: u["ntri"])
        ratio = lambda key: (c[key] / fine[key]) if c[key] is not None and fine[key] else None
        pairs[c["scene"]] = {"adaptive_maxh": c["adaptive_maxh"], "uniform_factor": fine["factor"],
                             "ntri_uniform": fine["ntri"], "ntri_adaptive_start": c["ntri"],
                             "ntri_adaptive_end": c["ntri_end"],
                             "initiation_ratio": ratio("initiation"), "crack_length_ratio": ratio("crack_length"),
                             "wall_ratio": c["phases"]["wall"] / fine["phases"]["wall"],
                             # the adaptive run in units of the uniform run's own solve
                             "solve_equivalents_of_uniform_unit": c["phases"]["wall"] / fine["t_unit"],
                             "reasons": [fine["reason"], c["reason"]],
                             "fragments": [fine["n_fragments"], c["n_fragments"]]}
    return pairs


def growth(cases):
    """Per scene with two or more factors: fitted exponents of cost per step and of wall against ntri."""
    fits = {}
    for name in dict.fromkeys(c["scene"] for c in cases):
        mine = [c for c in cases if c["scene"] == name and c["adaptive_maxh"] is None]
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


def refuse_adaptive(parser, args):
    """--adaptive needs a positive size and scenes that take ``refine`` (before any run)."""
    if not (math.isfinite(args.adaptive) and args.adaptive > 0):
        parser.error(f"--adaptive must be a mesh size > 0, got {args.adaptive!r}")
    for name in args.scenes:
        if "refine" not in inspect.signature(scenes.SCENES[name]).parameters:
            parser.error(f"--adaptive: scene {name!r} has no refine parameter")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", default=["plate", "disk"], choices=sorted(scenes.SCENES))
    p.add_argument("--factors", nargs="+", type=int, default=[1, 4, 16])
    p.add_argument("--steps", type=int, default=None,
                   help="stop every run after this many steps (for the finest meshes; the "
                        "shares are then those of the first steps)")
    p.add_argument("--one-ring", action="store_true",
                   help="the paper's one-ring criterion (radius=None) instead of the scenes' critical distance")
    p.add_argument("--adaptive", type=float, default=None, metavar="MAXH",
                   help="also run each scene from mesh size MAXH with refinement ahead of the crack tips "
                        "(refine=True), side by side with the finest uniform case")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    benchmark_json.refuse_existing(p, args)   # before hours of runs
    if args.adaptive is not None:
        refuse_adaptive(p, args)
    import pyvista, matplotlib.figure  # noqa: F401  (see the module docstring)
    cases = []
    for name in args.scenes:
        for f in args.factors:
            cases.append(run_case(name, f, args.steps, args.one_ring))
            print(json.dumps(cases[-1]), file=sys.stderr)
        if args.adaptive is not None:
            cases.append(run_case(name, None, args.steps, args.one_ring, adaptive=args.adaptive))
            print(json.dumps(cases[-1]), file=sys.stderr)
    benchmark_json.write(args, {"cases": cases, "growth": growth(cases), "adaptive": side_by_side(cases)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
