"""Benchmark of 3D contact work on a fragmented body against one factorisation + solve.

Body (``ngfracture.geometry.pieces.fragmented_box``): the unit cube, ``cells``^3 structured
cells of 6 tetrahedra, cut by grid planes into ``pieces``^3 blocks (default 4^3 = 64
fragments, 9 cut planes); every vertex on a cut has one copy per block, bitwise equal, and
the cut faces are crack lips (boundary ``crack``), as the node splitting leaves them. The
cube's faces glide (u_n prescribed: a hydrostatic compression e = 1e-3), so the blocks at
the surface are held and the inner ones float (pins and rigid modes, as a run has them).
Sizes (``--cells``): 15, 20, 26 cells: 20250, 48000, 105456 tetrahedra.

Configurations. The solution is the hydrostatic compression u = -e x (the P1 solution of
the closed body, twins staying bitwise together). The prediction, the state a solve's
first round judges, is that with every block also expanded about its own centroid by
1 + delta, delta chosen so that two neighbouring blocks overlap by 0.2 h (h = 1 / cells)
across their common lip: every lip penetrates at every vertex, with junctions of 4 blocks
along the lines and of 8 where cut planes cross (the 2D benchmark's configuration,
benchmarks/contact.py). The contact work of a contact solve (``ContactSolver``'s
"contact" timing: detection, rows, primal-dual choice and redundancy removal, settling) is
run by the solver's own active set (``ActiveSet3d``) over the two rounds of the shortest
solve, without the Newton solves between them (their cost is the unit):

  round 1  the set-up of the solve's active set (``ActiveSet3d``: the keys' codec and the
           detection's work on the mesh alone, ``PenetrationDetector3d``), then
           at the prediction: the fixed rows (the reference detection and the twin rows of
           every block), the detection and its rows, the primal-dual choice
           (``independent_rows``: redundancy), and every chosen row recorded as pressing;
  round 2  at the solution: every candidate re-linearised, the detection (closed lips: no
           pair), the choice (the set of round 1 again: settled) and the settling (every
           candidate re-linearised and judged: converged).

A real contact solve has 2 to 10 such rounds (docs/contact.md); the report gives each
round's seconds, so the work of a longer solve follows. The full ``ContactSolver`` on these
bodies does not settle (docs/contact.md, "Contact work in 3D"): the rounds of a solve that
converges are not there to be timed at 100k tetrahedra.

Reported per size (seconds are the best of ``--repeat``):

  tets, vertices, fragments, lip_faces, dofs
  t_round1, t_round2   the contact work of each round (round 1 with t_setup, the active
                       set's set-up); t_collision the detection within both (without the
                       set-up); t_rows the rows (fixed rows, found rows, re-linearisation);
                       t_choice the primal-dual choices (with the QR); t_settle the settling
  contact_work         t_round1 + t_round2
  candidates, wanted, active_rows   rows of round 2: candidates, rows the update wants,
                       independent rows kept (the rows a solve imposes)
  t_unit               one sparse Cholesky factorisation + solve of the body's linear
                       elasticity (the fixed dofs eliminated, one pin per free rigid mode of
                       the floating blocks: what a contact round factorises), one thread,
                       best of ``--repeat``, measured before and after the contact work
                       (their mean)
  ratio                contact_work / t_unit (the issue's target: at most 0.15 at 100k)
  ratio_per_round      contact_work / 2 / t_unit
  later_*              the same for a later solve on the mesh (every load step without a
                       new crack): the active set's set-up, the mesh's work alone and the
                       fixed rows (``contact.setup3d.MeshSetup3d``), taken from the
                       ``MeshSetups`` an earlier solve filled (not timed); the chosen rows
                       are checked equal to the first solve's; later_ratio,
                       later_cpu_ratio
  cpu_contact_work, cpu_t_unit, cpu_ratio   the same in CPU seconds of this process
                       (``time.process_time``; one thread): on a shared machine the wall
                       clock also counts the time other jobs take the core, the CPU time not.
                       The repeat kept is the one of least CPU time

and over the sizes: the least-squares exponents p of value ~ tets^p for contact_work,
t_unit and ratio (wall and CPU).

``--scene NAME`` runs a registered scene instead (``ngfracture.scenes.SCENES``): at the
three ``--maxh`` values (default the scene's own maxh times 1, 0.7, 0.5: each about 3 times
the tetrahedra of the one before) when the scene takes ``maxh``, else once at its defaults.
Every run is a ``Simulation`` without pictures in a temporary folder; reported are its
phases (summary.json "timings": "collision", "contact" (the rest of the contact work),
"solve", wall), t_unit (benchmarks/solid.py ``unit_solve`` of the scene's problem),
solve_equivalents = wall / t_unit, contact_ratio = (collision + contact) / t_unit, and
their growth exponents over the sizes. ``--vary NAME --values V ...`` varies another size
parameter instead of maxh (the sphere scenes' mesh is set by ``fine`` near the hole), with
``--set NAME=VALUE`` fixing others; ``--steps N`` stops every run after N accepted steps,
``--until-crack`` after its first cracked step (the run is left there, reason "first_crack",
its wall the seconds to that step).
``--inverse NAME`` runs them with that direct solver (``StepControl.inverse``). Every case
also reports, per accepted step and cumulative, its wall and CPU seconds (``step_seconds``,
``step_cpu_seconds``) and the linear algebra's counts (``LinalgCounts``: ``step_factorisations``
of K_ff, ``step_augmented`` augmented matrices, ``step_columns`` Schur columns solved,
``step_schur_seconds``, ``step_factorise_seconds``; ``totals`` at the end, and one line per
step on stderr as it is accepted), its split vertices, the first step that splits a vertex (``first_crack_step``), the seconds up to and
including it (``seconds_to_first_crack``) and those over t_unit
(``solve_equivalents_to_first_crack``, None without a crack), with its growth exponent.

Usage: PYTHONPATH=. OMP_NUM_THREADS=1 python benchmarks/contact3d.py [--quick]
       [--cells 15 20 26] [--pieces 4] [--repeat 2] [--scene NAME [--maxh H ...]
       [--vary NAME --values V ...] [--set NAME=VALUE ...] [--steps N] [--until-crack] [--inverse NAME]]
       [--json FILE [--force]]
"""
import argparse
import inspect
import json
import math
import sys
import tempfile
import time

import numpy as np

import benchmark_json

#: cells per edge of the default sizes: 20250, 48000 and 105456 tetrahedra
DEFAULT_CELLS = [15, 20, 26]
#: --quick: one small body (a few seconds)
QUICK_CELLS = [8]
#: the issue's target: contact work at most this share of one factorisation + solve at 100k
TARGET_RATIO = 0.15
#: hydrostatic strain of the glide conditions
STRAIN = 1e-3
#: overlap of two neighbouring blocks across their lip, in cells
OVERLAP = 0.2
#: --scene: maxh factors of the three sizes
SCENE_FACTORS = (1.0, 0.7, 0.5)


def compressed_body(cells, pieces):
    """The fragmented cube as an ElasticProblem with glide conditions, and its arrays."""
    from ngfracture.geometry.pieces import fragmented_box
    from ngfracture.geometry.solid import solid_mesh
    from ngfracture.mechanics.materials import LinearElastic
    from ngfracture.mechanics.problem import ElasticProblem
    arrays, _ = fragmented_box(cells, pieces)
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=1.0, nu=0.25))
    for c in "xyz":
        prob.add_dirichlet(f"{c}min", 0.0, component=c)
        prob.add_dirichlet(f"{c}max", -STRAIN, component=c)
    return prob, arrays


def contact_geometry(prob):
    """The active set's geometry of the problem (as ContactSolver makes it in 3D)."""
    from ngfracture.contact.active_set import Geometry
    _, comp = prob.fragments()
    nv, n = prob.mesh.nv, prob.fes.ndof // 3
    fixed = prob.assemble_constraints().fixed_dofs
    v, c = fixed % n, fixed // n
    return Geometry(arrays=prob.arrays, fragment=comp[prob.arrays.tets[:, 0]], seams=None,
                    fixed=(c * nv + v)[v < nv], holds=None)


def expanded(arrays, fragment, cells, pieces):
    """Every block expanded about its centroid: neighbours overlap by OVERLAP cells."""
    X = arrays.points
    vertex_fragment = np.zeros(len(X), dtype=np.int64)
    vertex_fragment[arrays.tets.ravel()] = np.repeat(fragment, 4)
    count = np.bincount(vertex_fragment)
    centre = np.stack([np.bincount(vertex_fragment, weights=X[:, d]) / count for d in range(3)], axis=1)
    delta = OVERLAP / cells * pieces          # block size 1 / pieces
    return delta * (X - centre[vertex_fragment])


def no_complementarity(rows, indices):
    """The complementarity problem is a solve's (its cost is not contact work): not solved."""
    return None


def contact_rounds(geometry, U_predicted, U_solution, penetration_tol, setups=None):
    """The contact work of a two-round solve (module docstring): seconds per part and rows;
    with ``setups`` (a ``MeshSetups`` holding this mesh's set-up) a later solve on the mesh."""
    from ngfracture.contact.active_set3d import ActiveSet3d
    timings = {"collision": 0.0}
    parts = dict.fromkeys(("rows", "choice", "settle"), 0.0)
    t0 = time.perf_counter()
    active = ActiveSet3d(geometry, penetration_tol, setups=setups)
    t_setup = time.perf_counter() - t0
    rounds = []
    for rnd, u in ((1, U_predicted), (2, U_solution)):
        t0 = time.perf_counter()
        collision0 = timings["collision"]
        candidates = active.update(u, timings)
        t1 = time.perf_counter()
        want, kept, other = active.primal_dual(candidates)
        kept, settled = active.choose(candidates, want, kept, rnd, no_complementarity)
        t2 = time.perf_counter()
        if settled:
            active.settle(candidates, other, u)
        t3 = time.perf_counter()
        parts["rows"] += (t1 - t0) - (timings["collision"] - collision0)
        parts["choice"] += t2 - t1
        parts["settle"] += t3 - t2
        rounds.append(t3 - t0)
        # every chosen row presses (a solve's multipliers; the solve itself is not timed)
        active.record(candidates.keys, kept, -np.ones(len(kept)), 1.0)
    return {"t_round1": t_setup + rounds[0], "t_round2": rounds[1], "t_setup": t_setup,
            "t_collision": timings["collision"],
            **{f"t_{k}": v for k, v in parts.items()}, "settled": bool(settled),
            "candidates": len(candidates.keys), "wanted": int(len(want)), "active_rows": int(len(kept))}


def unit_solve(prob, repeat):
    """Best of ``repeat`` seconds (wall and CPU) of one sparse Cholesky factorisation + solve
    of the body, and the solver's name."""
    import ngsolve
    from ngfracture.linalg.factor import EliminatedFactor
    from ngfracture.linalg.iterative import problem_inverse
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    prob.form.AssembleLinearization(prob.u.vec)
    K = prob.form.mat
    rhs = np.ones(K.height)
    best, cpu, solver = math.inf, math.inf, None
    before = ngsolve.GetNumThreads()
    ngsolve.SetNumThreads(1)
    try:
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            factor = EliminatedFactor(K, rows.fixed_dofs, support.pins, inverse=problem_inverse("auto", 3))
            factor.factorise()
            x = factor.solve(rhs)
            best, cpu = min(best, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
            solver = factor.inverse
            assert np.all(np.isfinite(x))
            del factor
    finally:
        ngsolve.SetNumThreads(before)
    return best, cpu, solver


def best_rounds(geometry, cells, pieces, repeat, setups):
    """The best (least CPU) of ``repeat`` runs of :func:`contact_rounds` on the body."""
    arrays = geometry.arrays
    U = expanded(arrays, geometry.fragment, cells, pieces)
    best = None
    for _ in range(repeat):
        solution = -STRAIN * arrays.points
        c0 = time.process_time()
        work = contact_rounds(geometry, solution + U, solution, 1e-10 * (1.0 / cells), setups)
        work["cpu_contact_work"] = time.process_time() - c0
        work["contact_work"] = work["t_round1"] + work["t_round2"]
        if best is None or work["cpu_contact_work"] < best["cpu_contact_work"]:
            best = work
    return best


def run_case(cells, pieces, repeat):
    """One size of the fragmented body: contact work of a first and a later solve on the
    mesh, unit and ratios."""
    from ngfracture.contact.setup3d import MeshSetups
    prob, arrays = compressed_body(cells, pieces)
    geometry = contact_geometry(prob)
    t_before, cpu_before, solver = unit_solve(prob, repeat)
    best = best_rounds(geometry, cells, pieces, repeat, None)
    # a later solve on the mesh: the set-up made by an earlier solve (not timed) is reused
    setups = MeshSetups()
    a = geometry.arrays
    setups.setup(a.points, a.tets, a.faces, geometry.fragment)
    later = best_rounds(geometry, cells, pieces, repeat, setups)
    if setups.made != 1 or any(later[k] != best[k] for k in ("candidates", "wanted", "active_rows", "settled")):
        raise RuntimeError("the later solve did not reuse the set-up or chose other rows")
    t_after, cpu_after, _ = unit_solve(prob, repeat)
    t_unit, cpu_unit = 0.5 * (t_before + t_after), 0.5 * (cpu_before + cpu_after)
    best.update({f"later_{k}": later[k] for k in ("t_round1", "t_round2", "t_setup", "t_collision", "t_rows",
                                                   "t_choice", "t_settle", "contact_work", "cpu_contact_work")})
    best.update(later_ratio=later["contact_work"] / t_unit, later_cpu_ratio=later["cpu_contact_work"] / cpu_unit)
    lips = int(np.count_nonzero(arrays.face_bc == arrays.bc_names.index("crack") + 1))
    return {"cells": cells, "pieces": pieces, "tets": len(arrays.tets), "vertices": len(arrays.points),
            "fragments": int(prob.fragments()[0]), "lip_faces": lips, "dofs": 3 * len(arrays.points), **best,
            "t_unit": t_unit, "t_unit_before": t_before, "t_unit_after": t_after, "solver": solver,
            "ratio": best["contact_work"] / t_unit, "ratio_per_round": best["contact_work"] / 2 / t_unit,
            "cpu_t_unit": cpu_unit, "cpu_ratio": best["cpu_contact_work"] / cpu_unit}


def exponents(cases, keys):
    """Least-squares exponents p of value ~ tets^p (None with fewer than two sizes)."""
    if len({c["tets"] for c in cases}) < 2:
        return None
    logn = np.log([c["tets"] for c in cases])
    return {"tets": [c["tets"] for c in cases],
            **{f"{k}_exponent": float(np.polyfit(logn, np.log([max(c[k], 1e-300) for c in cases]), 1)[0])
               for k in keys}}


def scene_sizes(name, maxh, vary="maxh", fixed=None):
    """The keyword arguments of every size of a registered scene: values of the parameter
    ``vary`` (``maxh``: the given ones, else the default times SCENE_FACTORS), each with the
    ``fixed`` ones (a dict), or only those where the scene does not take ``vary``."""
    from ngfracture import scenes
    if name not in scenes.SCENES:
        raise ValueError(f"unknown scene {name!r}; registered: {', '.join(sorted(scenes.SCENES))}")
    fixed = dict(fixed or {})
    parameters = inspect.signature(scenes.SCENES[name]).parameters
    for key in (*fixed, vary):
        if key not in parameters and (key != vary or maxh):
            raise ValueError(f"scene {name!r} takes no {key}")
    if vary in fixed:
        raise ValueError(f"--set {vary} and --vary {vary} exclude each other")
    parameter = parameters.get(vary)
    if parameter is None:
        return [fixed]
    if maxh:
        return [{**fixed, vary: h} for h in maxh]
    if not isinstance(parameter.default, (int, float)) or isinstance(parameter.default, bool):
        raise ValueError(f"scene {name!r} has no default {vary}: give the values")
    return [{**fixed, vary: parameter.default * f} for f in SCENE_FACTORS]


def parsed_settings(items):
    """``NAME=VALUE`` strings as a dict, the values read as JSON where they parse (numbers,
    true/false, null), else kept as strings."""
    out = {}
    for item in items or ():
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ValueError(f"--set needs NAME=VALUE, got {item!r}")
        try:
            out[name] = json.loads(value)
        except json.JSONDecodeError:
            out[name] = value
    return out


def first_crack(records):
    """(step, cumulative seconds) of the first accepted step that split a vertex, from the
    progress records of a run; (None, None) without one."""
    for r in records:
        if r["split_vertices"] > 0:
            return r["step"], r["seconds"]
    return None, None


class LinalgCounts:
    """Counts of the linear algebra of a run, by wrapping linalg.factor's methods while in use
    (``with LinalgCounts() as counts``): ``factorisations`` (direct factorisations of K_ff),
    ``augmented`` (augmented matrices factorised), ``columns`` (Schur columns K^+ c solved,
    by column solves or sparse triangular solves), ``schur_seconds`` (seconds building
    Schur columns), ``factorise_seconds``. The wrappers are removed on leaving."""

    def __enter__(self):
        from ngfracture.linalg import factor, sparse_schur
        self.factorisations = self.augmented = self.columns = 0
        self.schur_seconds = self.factorise_seconds = 0.0
        self._saved = [(factor.EliminatedFactor, "factorise"), (factor.EliminatedFactor, "augmented"),
                       (factor.FactorBase, "columns_and_solve"), (factor.EliminatedFactor, "schur"),
                       (sparse_schur, "reach_solves")]
        self._saved = [(owner, name, getattr(owner, name)) for owner, name in self._saved]
        counts = self
        originals = {name: f for _, name, f in self._saved}

        def factorise(fac):
            t0, fresh = time.perf_counter(), not fac.factorised
            originals["factorise"](fac)
            counts.factorisations += fresh
            counts.factorise_seconds += time.perf_counter() - t0

        def augmented(fac, C):
            cached = fac._augmented
            out = originals["augmented"](fac, C)
            counts.augmented += fac._augmented is not cached
            return out

        block = []          # the right-hand sides besides the rows of the columns_and_solve under way

        def columns_and_solve(fac, C, B):
            t0 = time.perf_counter()
            block.append(B.shape[1])
            try:
                Z, X = originals["columns_and_solve"](fac, C, B)
            finally:
                block.pop()
            counts.schur_seconds += time.perf_counter() - t0
            return Z, X

        def schur(fac, C):
            t0 = time.perf_counter()
            S = originals["schur"](fac, C)
            counts.schur_seconds += time.perf_counter() - t0
            return S

        def reach_solves(lu, arrays, index, C, *supernodal):
            counts.columns += C.shape[0]
            return originals["reach_solves"](lu, arrays, index, C, *supernodal)

        solve = factor.EliminatedFactor.solve

        def counted_solve(fac, B):
            if block:
                counts.columns += B.shape[1] - block[-1]
                block[-1] = B.shape[1]      # a further solve (the residual check) adds nothing
            return solve(fac, B)

        self._saved.append((factor.EliminatedFactor, "solve", solve))
        for owner, name, f in [(factor.EliminatedFactor, "factorise", factorise),
                               (factor.EliminatedFactor, "augmented", augmented),
                               (factor.FactorBase, "columns_and_solve", columns_and_solve),
                               (factor.EliminatedFactor, "schur", schur), (sparse_schur, "reach_solves", reach_solves),
                               (factor.EliminatedFactor, "solve", counted_solve)]:
            setattr(owner, name, f)
        return self

    def __exit__(self, *exc):
        for owner, name, f in self._saved:
            setattr(owner, name, f)
        return False

    def snapshot(self):
        """The counts so far, a dict."""
        return {"factorisations": self.factorisations, "augmented": self.augmented, "columns": self.columns,
                "schur_seconds": self.schur_seconds, "factorise_seconds": self.factorise_seconds}


class FirstCrack(Exception):
    """Raised by the progress callback of a run stopped at its first cracked step."""


def run_scene(name, kwargs, repeat, steps=None, until_crack=False, inverse=None):
    """One run of a registered scene (at most ``steps`` accepted steps, or up to and including
    its first cracked step with ``until_crack``; reason "first_crack" then; with the step
    control's ``inverse`` if given): its contact phases, wall, unit, the time to its first
    cracked step and the linear algebra's counts (:class:`LinalgCounts`) per step."""
    from ngfracture import Simulation, scenes
    from ngfracture.run.control import StepControl
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    import solid
    scene = scenes.SCENES[name](**kwargs)
    t_before, solver = solid.unit_solve(scene, repeat=repeat)
    records = []

    def progress(record):
        records.append({**record, **counts.snapshot(), "cpu_seconds": time.process_time() - cpu0})
        print(json.dumps({k: records[-1][k] for k in ("step", "seconds", "cpu_seconds", "split_vertices",
                                                      *counts.snapshot())}), file=sys.stderr, flush=True)
        if until_crack and record["split_vertices"] > 0:
            raise FirstCrack

    options = {"max_steps": steps} if steps is not None else {}
    if inverse is not None:
        options["inverse"] = inverse
    control = StepControl(**options) if options else None
    with tempfile.TemporaryDirectory() as out, LinalgCounts() as counts:
        simulation = Simulation(scene, control=control, out=out, pictures="none", progress=progress)
        t0, cpu0 = time.perf_counter(), time.process_time()
        try:
            result = simulation.run()
            reason, n_steps, wall = result.reason, result.summary["n_steps"], result.summary["timings"]["wall"]
            message = result.message
        except FirstCrack:
            reason, n_steps, wall, message = "first_crack", records[-1]["step"], time.perf_counter() - t0, None
    t_after, _ = solid.unit_solve(scene, repeat=repeat)
    t_unit = 0.5 * (t_before + t_after)
    timings = simulation.timings
    contact = timings["collision"] + timings["contact"]
    crack_step, crack_seconds = first_crack(records)
    return {"scene": name, **kwargs, "tets": scene.mesh.ne, "vertices": scene.mesh.nv, "reason": reason,
            "message": message, "steps": n_steps, "collision": timings["collision"], "contact": timings["contact"],
            "solve": timings["solve"], "wall": wall, "t_unit": t_unit, "solver": solver,
            "solve_equivalents": wall / t_unit, "contact_ratio": contact / t_unit,
            "step_seconds": [r["seconds"] for r in records], "split_vertices": [r["split_vertices"] for r in records],
            **{f"step_{key}": [r[key] for r in records] for key in (*counts.snapshot(), "cpu_seconds")},
            "totals": counts.snapshot(), "first_crack_step": crack_step, "seconds_to_first_crack": crack_seconds,
            "solve_equivalents_to_first_crack": None if crack_seconds is None else crack_seconds / t_unit}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cells", nargs="+", type=int, default=None, help=f"cells per edge (default {DEFAULT_CELLS})")
    p.add_argument("--pieces", type=int, default=4, help="blocks per edge (default 4: 64 fragments)")
    p.add_argument("--repeat", type=int, default=2, help="best of this many (default 2)")
    p.add_argument("--quick", action="store_true", help=f"one small body ({QUICK_CELLS[0]} cells per edge)")
    p.add_argument("--scene", help="run this registered scene instead (at three --maxh if it takes maxh)")
    p.add_argument("--maxh", "--values", nargs="+", type=float, default=None, dest="maxh",
                   help="the scene's sizes: values of --vary (with --scene)")
    p.add_argument("--vary", default="maxh", help="the size parameter of the scene's cases (default maxh)")
    p.add_argument("--set", action="append", default=None, metavar="NAME=VALUE",
                   help="a scene parameter fixed in every case (repeatable)")
    p.add_argument("--steps", type=int, default=None, help="stop every scene run after this many accepted steps")
    p.add_argument("--until-crack", action="store_true",
                   help="stop every scene run after its first step that splits a vertex")
    p.add_argument("--inverse", default=None, help="the scene runs' direct solver (StepControl.inverse)")
    benchmark_json.add_options(p)
    args = p.parse_args(argv)
    if args.repeat < 1:
        p.error("--repeat must be at least 1")
    if args.steps is not None and args.steps < 1:
        p.error("--steps must be at least 1")
    benchmark_json.refuse_existing(p, args)
    if args.scene is not None:
        try:
            sizes = scene_sizes(args.scene, args.maxh, args.vary, parsed_settings(args.set))
        except ValueError as exc:
            p.error(str(exc))
        cases = []
        for kwargs in sizes:
            cases.append(run_scene(args.scene, kwargs, args.repeat, args.steps, args.until_crack, args.inverse))
            print(json.dumps(cases[-1]), file=sys.stderr, flush=True)
        growth = exponents(cases, ("wall", "t_unit", "solve_equivalents", "contact_ratio"))
        cracked = [c for c in cases if c["first_crack_step"] is not None]
        if growth is not None:
            first = exponents(cracked, ("seconds_to_first_crack", "solve_equivalents_to_first_crack"))
            growth.update({k: v for k, v in (first or {}).items() if k != "tets"})
        benchmark_json.write(args, {"scene": args.scene, "cases": cases, "growth": growth})
        return 0
    cells = args.cells or (QUICK_CELLS if args.quick else DEFAULT_CELLS)
    cases = []
    for n in cells:
        cases.append(run_case(n, args.pieces, args.repeat))
        print(json.dumps(cases[-1]), file=sys.stderr, flush=True)
    growth = exponents(cases, ("contact_work", "t_unit", "ratio", "cpu_contact_work", "cpu_t_unit", "cpu_ratio",
                               "later_contact_work", "later_ratio", "later_cpu_ratio"))
    near = min(cases, key=lambda c: abs(math.log(c["tets"] / 1e5)))
    target = {"target": TARGET_RATIO, "tets": near["tets"], "ratio": near["ratio"], "cpu_ratio": near["cpu_ratio"],
              "later_ratio": near["later_ratio"], "later_cpu_ratio": near["later_cpu_ratio"]}
    benchmark_json.write(args, {"cases": cases, "growth": growth, "target_at_100k": target})
    return 0


if __name__ == "__main__":
    sys.exit(main())
