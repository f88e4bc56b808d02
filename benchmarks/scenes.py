"""Benchmark of whole fracture simulations: wall time per phase, at three resolutions.

For each scene (plate, disk) and each refinement factor f (default 1, 4, 16: the paper's
resolution and f times more triangles, maxh / sqrt(f)) one simulation runs to its end,
writing its outputs into a temporary folder (no pictures). Reported per case:

  ntri, nsteps, n_split_vertices, n_fragments
  phases       seconds per phase of Simulation (solve, strain, split, rebuild, collision,
               contact, output) and wall
  linear       seconds in factorisations and triangular solves (part of "solve")
  assembly     seconds in NGSolve's residual and tangent assembly (part of "solve")
  outside_solve_share    1 - solve / wall: everything outside the Newton solves (assembly,
               factorisation, triangular solves, residuals): crack criterion, splitting,
               rebuilding, collision, contact rows, output. The floor's reading.
  outside_fe_share       1 - (linear + assembly) / wall: everything but NGSolve's finite
               element work (counts the Python of the Newton and KKT loops as overhead)
  outside_linear_share   1 - linear / wall: everything but factorisations and triangular
               solves (strictest: it counts the residual assembly as overhead)
  t_plain      one linear-elastic factorise + solve of plain NGSolve on the initial mesh,
               measured in the same run (the baseline)
  wall_over_plain        wall / t_plain

Writes JSON {"cases": [...]} (stdout, or the file of --json FILE). Floors: the plate at
f = 1 under 60 s, and outside_solve_share under 0.3 (see docs/verification.md for the
measured figures and why this share is the one the floor is read as). The modules the run loads on first use (pyvista,
matplotlib) are imported before the first case, as NGSolve itself is: a once-per-process
cost that would otherwise land in the first case's "output" phase only.

Usage: python benchmarks/scenes.py [--scenes plate disk] [--factors 1 4 16] [--steps N] [--json FILE [--force]]
"""
import argparse
import json
import math
import sys
import tempfile
import time

import ngsolve

import benchmark_json
from ngfracture import scenes
from ngfracture.simulation import Simulation, StepControl


def plain_solve(mesh, E=5e9, nu=0.18):
    """One plain-NGSolve linear-elastic solve with the whole boundary clamped: the baseline."""
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    fes = ngsolve.VectorH1(mesh, order=1, dirichlet=".*")
    u, v = fes.TnT()
    eps = lambda w: ngsolve.Sym(ngsolve.Grad(w))
    a = ngsolve.BilinearForm(fes, symmetric=True)
    a += (2 * mu * ngsolve.InnerProduct(eps(u), eps(v)) + lam * ngsolve.div(u) * ngsolve.div(v)) * ngsolve.dx
    f = ngsolve.LinearForm(ngsolve.CF((1.0, 0.0)) * v * ngsolve.dx)
    gfu = ngsolve.GridFunction(fes)
    t0 = time.perf_counter()
    a.Assemble()
    f.Assemble()
    gfu.vec.data = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") * f.vec
    return time.perf_counter() - t0


def run_case(name, factor, steps=None):
    base = scenes.SCENES[name]()
    scene = scenes.SCENES[name](maxh=base.parameters["maxh"] / math.sqrt(factor))
    t_plain = min(plain_solve(scene.mesh) for _ in range(2))
    control = StepControl(**{**scene.control, "max_steps": steps}) if steps else None
    with tempfile.TemporaryDirectory() as out:
        result = Simulation(scene, control, out=out, pictures="none").run()
    s = result.summary
    wall = s["timings"]["wall"]
    linear = s["timings"].get("linear", float("nan"))
    assembly = s["timings"].get("assembly", float("nan"))
    return {"scene": name, "factor": factor, "ntri": scene.mesh.ne, "reason": result.reason, "max_steps": steps,
            "nsteps": s["n_steps"], "n_split_vertices": s["n_split_vertices"],
            "n_fragments": s["n_fragments"], "phases": s["timings"], "linear": linear,
            "assembly": assembly, "outside_solve_share": 1.0 - s["timings"]["solve"] / wall,
            "outside_fe_share": 1.0 - (linear + assembly) / wall,
            "outside_linear_share": 1.0 - linear / wall, "t_plain": t_plain,
            "wall_over_plain": wall / t_plain}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", default=["plate", "disk"], choices=sorted(scenes.SCENES))
    p.add_argument("--factors", nargs="+", type=int, default=[1, 4, 16])
    p.add_argument("--steps", type=int, default=None,
                   help="stop every run after this many steps (for the finest meshes; the "
                        "shares are then those of the first steps)")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    benchmark_json.refuse_existing(p, args)   # before hours of runs
    import pyvista, matplotlib.figure  # noqa: F401  (see the module docstring)
    cases = []
    for name in args.scenes:
        for f in args.factors:
            cases.append(run_case(name, f, args.steps))
            print(json.dumps(cases[-1]), file=sys.stderr)
    benchmark_json.write(args, {"cases": cases})
    return 0


if __name__ == "__main__":
    sys.exit(main())
