"""Command line of ngfracture: ``python -m ngfracture <command> ...``.

Commands
--------
run      a fracture simulation of a built-in scene, a scene file or a scene function
         (``run plate ...``, ``run path/to/scene.py --set E=7e10``)
scenes   the built-in scenes with their parameters and defaults
render   redraw the pictures of a finished or interrupted run
verify   convergence studies against exact solutions (``verify lshape ...``)
ensemble many seeds of a scene with random strength on dask (``ensemble disk --samples 16``)

Each command is one ``_add_<command>(subparsers)`` function that registers its
parser and sets ``func``.
"""
import argparse
import json
import math
import os
import re
import sys

import numpy as np

from . import __version__


def _int_at_least(minimum):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        return value
    return parse


def _positive_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return value


#: StepControl options of ``run``: (field, type, help); --steps is max_steps
CONTROL_OPTIONS = [
    ("max_new_cracks", "int0", "split vertices allowed in the first crack pass after an increment "
                               "before dx is cut (the scene's default, else 2)"),
    ("method", ("modified", "full"), "Newton variant: modified (tangent at most once per load step, the paper's) "
                                     "or full"),
    ("tol", "float", "Newton tolerance (relative increment, paper eq. 7; default 1e-10)"),
    ("maxit", "int1", "Newton iterations per solve (default 60)"),
    ("inverse", ("auto", "amg", "sparsecholesky", "superlu"),
     "solver of the stiffness: auto (default; in 3D sparse Cholesky while its predicted memory fits the "
     "budget, else amg), amg (CG with algebraic multigrid), or a direct factorisation"),
    ("cut", "float", "dx is multiplied by this after too many cracks or a failure (default 0.5)"),
    ("grow", "float", "dx is multiplied by this after --grow-after quiet steps (default 1.5)"),
    ("grow_after", "int1", "crack-free steps in a row before dx grows (default 2)"),
    ("dx_min", "float", "smallest increment (default: the scene's dx / 64)"),
    ("dx_max", "float", "largest increment (default: 8 times the scene's dx)"),
    ("max_retries", "int0", "failed attempts in a row before the run stops (default 6)"),
    ("split", ("spread", "all", "one"), "which overstrained vertices a crack pass splits (default: spread; one for a scene with a critical distance)"),
]


def _scene_help():
    from . import scenes
    from .run.scene_source import format_parameters
    lines = [f"{name}: {_plain(func.__doc__.splitlines()[0].rstrip('.'))} (load: "
             f"{scenes.LOAD_DESCRIPTIONS[name]}; parameters {format_parameters(func)})"
             for name, func in sorted(scenes.SCENES.items())]
    return ("a built-in scene, a file path/to/scene.py that defines scene(**params) returning a "
            "Scene, or package.module:function. " + "; ".join(lines))


def _add_run(subparsers):
    p = subparsers.add_parser(
        "run", help="a fracture simulation of a built-in scene or your own",
        description="Run a quasi-static fracture simulation under load control (paper section "
                    "4.2): increase the prescribed deformation step by step, split overstrained "
                    "vertices, relax at fixed load until no new crack appears. Writes a VTK time "
                    "series (results.pvd, cracks.pvd), checkpoints, summary.json, final.png and "
                    "fragment_sizes.png into the output folder. The scene, its parameters and "
                    "the options are checked before the output folder is touched. Exit status 0 "
                    "when the run ends normally, 1 when a step fails after all retries (the last "
                    "good state is written), 2 on bad input.")
    p.add_argument("scene", metavar="SCENE", help=_scene_help())
    p.add_argument("--set", dest="assignments", metavar="NAME=VALUE", action="append", default=[],
                   help="a parameter of the scene function, e.g. --set E=7e10 --set critical=2e-4 "
                        "(repeatable; VALUE is converted by the type of the default; "
                        "'ngfracture scenes' lists the built-in scenes' parameters)")
    p.add_argument("--maxh", type=_positive_float, default=None,
                   help="mesh size, short for --set maxh=H (default: the scene's)")
    p.add_argument("--steps", type=_int_at_least(1), default=None,
                   help="at most this many accepted load steps (default: the scene's, else 200)")
    p.add_argument("--load-max", type=_positive_float, default=None,
                   help="final value of the load parameter x (default: the scene's). plate: "
                        "x is the total extension of the unit plate (length; the mean strain); "
                        "disk, disintegration: x is the radial displacement of the core's inner "
                        "boundary (length; disk radius 1); your own scene: its load_description")
    for name, kind, text in CONTROL_OPTIONS:
        flag = "--" + name.replace("_", "-")
        if isinstance(kind, tuple):
            p.add_argument(flag, dest=name, choices=kind, default=None, help=text)
        else:
            parse = {"int0": _int_at_least(0), "int1": _int_at_least(1), "float": _positive_float}[kind]
            p.add_argument(flag, dest=name, type=parse, default=None, help=text)
    p.add_argument("--checkpoint-every", type=_int_at_least(1), default=1,
                   help="write a checkpoint after every N accepted steps (and at the end; default 1)")
    p.add_argument("--threads", type=_int_at_least(1), default=None,
                   help="threads of NGSolve's task manager, for this process (assembly of problems from 20000 dofs "
                        "on; factorisations run on one thread for bitwise repeatable results)")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="output folder (default out/NAME, NAME the scene's name or the file's "
                        "stem); refused if it holds results, unless --force or --resume")
    p.add_argument("--force", action="store_true",
                   help="replace the results in DIR (only files ngfracture writes are removed)")
    p.add_argument("--resume", action="store_true",
                   help="continue the run in DIR from its newest checkpoint; the result equals "
                        "an uninterrupted run")
    p.add_argument("--pictures", choices=["final", "every", "none"], default="final",
                   help="PNG of the final state and the fragment-size plot (default), also of every "
                        "step, or no pictures")
    p.add_argument("--contact", choices=["auto", "never"], default="auto",
                   help="auto: in 2D contact from the first crack on (from the start for separate "
                        "bodies), in 3D where the scene asks for it (Scene.contact); never: no contact "
                        "rows (overlap is still measured)")
    p.add_argument("--progress", choices=["auto", "bar", "json", "none"], default="auto",
                   help="bar: a progress line on stderr (auto: when stderr is a terminal); json: one "
                        "JSON object per accepted step on stdout (step, load, splits, fragments, "
                        "seconds; the closing lines then go to stderr); none")
    p.add_argument("--quiet", action="store_true", help="no progress (same as --progress none)")
    p.set_defaults(func=_run_run)


def progress_bar(info, width=20):
    """One line: a bar of the load reached, the step, split vertices, fragments, seconds.

    Parameters
    ----------
    info : dict
        As passed to ``Simulation(progress=...)``: step, x, load_max, split_vertices,
        fragments, seconds.
    width : int
        Characters of the bar.

    Returns
    -------
    str
        Without a line end; the bar is full from x >= load_max on.
    """
    done = min(max(info["x"] / info["load_max"], 0.0), 1.0) if info["load_max"] > 0 else 0.0
    filled = int(done * width)
    return (f"[{'#' * filled}{'.' * (width - filled)}] {100 * done:3.0f}%  step {info['step']:4d}  "
            f"split vertices {info['split_vertices']:6d}  fragments {info['fragments']:4d}  "
            f"{info['seconds']:7.1f} s")


def _plain(text):
    """Docstring text without Sphinx roles (":func:`disk`" -> "disk") for --help."""
    return re.sub(r":\w+:`([^`]*)`", r"\1", text)


def _progress_line(info):
    sys.stderr.write("\r" + progress_bar(info))
    sys.stderr.flush()


def progress_json(info):
    """The JSON line of ``--progress json`` for one accepted step.

    Parameters
    ----------
    info : dict
        As passed to ``Simulation(progress=...)``.

    Returns
    -------
    str
        One JSON object: step, load (x), load_max, splits (split vertices so far),
        fragments, seconds (wall time of the run so far), and forces: the force and mean
        displacement of every loaded boundary (as in ``force_displacement.csv``).
    """
    return json.dumps({"step": info["step"], "load": info["x"], "load_max": info["load_max"],
                       "splits": info["split_vertices"], "fragments": info["fragments"],
                       "seconds": round(info["seconds"], 3), "forces": info.get("boundaries", {})})


def _print_json_progress(info):
    print(progress_json(info), flush=True)


def _default_out(spec):
    from .run.scene_source import builtin_scenes
    if spec in builtin_scenes():
        return os.path.join("out", spec)
    if spec.endswith(".py"):
        return os.path.join("out", os.path.splitext(os.path.basename(spec))[0])
    return os.path.join("out", spec.rpartition(":")[2] or "scene")


def _run_run(args):
    from .run.files import check_folder
    from .run.scene_source import build_scene, load_scene_function, parse_assignments
    from .run.simulation import Simulation, StepControl

    if args.force and args.resume:
        raise ValueError("--force and --resume exclude each other")
    # bad input before any work and before the output folder is looked at twice
    make_scene = load_scene_function(args.scene)
    assignments = list(args.assignments) + ([f"maxh={args.maxh!r}"] if args.maxh is not None else [])
    params = parse_assignments(assignments, make_scene)
    settings = {name: getattr(args, name) for name, _, _ in CONTROL_OPTIONS if getattr(args, name) is not None}
    if args.steps is not None:        # else the scene's own max_steps, if it has one
        settings["max_steps"] = args.steps
    control = StepControl(**settings)
    out = args.out if args.out is not None else _default_out(args.scene)
    check_folder(out, force=args.force, resume=args.resume,     # before meshing
                 option_names=("--force", "--resume"))
    scene = build_scene(make_scene, args.scene, params)
    if args.load_max is not None:
        scene.load_max = args.load_max
        scene.parameters["load_max"] = args.load_max
    mode = "none" if args.quiet else args.progress
    if mode == "auto":
        mode = "bar" if sys.stderr.isatty() else "none"
    report = {"bar": _progress_line, "json": _print_json_progress, "none": None}[mode]
    if args.threads is not None:
        import ngsolve
        ngsolve.SetNumThreads(args.threads)      # for every TaskManager of this process
    sim = Simulation(scene, control, out=out, force=args.force, resume=args.resume,
                     pictures=args.pictures, contact=args.contact, progress=report,
                     checkpoint_every=args.checkpoint_every)
    result = sim.run()
    if mode == "bar":
        sys.stderr.write("\n")
    closing = sys.stderr if mode == "json" else sys.stdout    # stdout stays JSON lines only
    s = result.summary
    crack = f"crack length {s['crack_length']:.4g}" if "crack_length" in s else f"crack area {s['crack_area']:.4g}"
    print(f"{scene.name}: {s['n_steps']} steps, {s['n_split_vertices']} split vertices, {crack}, "
          f"{s['n_fragments']} fragments, {s['timings']['wall']:.1f} s; "
          f"{result.reason}: {result.message}", file=closing)
    if s.get("notes"):     # departures from the plain path (docs/command_line.md): say that there are some
        last = s["notes"][-1]
        print(f"{len(s['notes'])} note{'s' if len(s['notes']) > 1 else ''} in summary.json (\"notes\"), "
              f"the last of step {last['step']}: "
              f"{last['note']}", file=closing)
    if s.get("pictures", {}).get("final_error"):
        print(f"final.png was not drawn: {s['pictures']['final_error']}", file=sys.stderr)
    files = ["results.pvd", "cracks.pvd", "summary.json"] + sorted(
        v for k, v in s.get("pictures", {}).items() if k in ("final", "fragment_sizes"))
    print(f"results in {out}/ ({', '.join(files)})", file=closing)
    if not result.ok:
        raise RuntimeError(result.message)
    return 0


def _add_scenes(subparsers):
    p = subparsers.add_parser(
        "scenes", help="list the built-in scenes with their parameters and defaults",
        description="List the built-in scenes: what each is, its load parameter, and every "
                    "parameter that 'run SCENE --set NAME=VALUE' accepts, with its default.")
    p.set_defaults(func=_run_scenes)


def _run_scenes(args):
    import inspect

    from . import scenes
    from .run.scene_source import scene_parameters
    for name, func in sorted(scenes.SCENES.items()):
        print(f"{name}: {_plain(func.__doc__.splitlines()[0].rstrip('.'))}")
        print(f"  load x: {scenes.LOAD_DESCRIPTIONS[name]}")
        for pname, default in scene_parameters(func).items():
            shown = "(required)" if default is inspect.Parameter.empty else \
                ("(the scene's)" if default is None else repr(default))
            print(f"  --set {pname}={shown}")
    return 0


def _add_render(subparsers):
    p = subparsers.add_parser(
        "render", help="redraw the pictures of a finished or interrupted run",
        description="Redraw final.png and fragment_sizes.png of the run in DIR from its newest "
                    "checkpoint (the end of a finished run, the last saved step of an "
                    "interrupted one). Only these two files are replaced.")
    p.add_argument("dir", metavar="DIR", help="the output folder of a run")
    p.set_defaults(func=_run_render)


def _run_render(args):
    from .fracture.fragments import FragmentStatistics
    from .output.pictures import final_pictures, picture_scale
    from .run.state import load_state

    folder = args.dir
    if not os.path.isdir(folder):
        raise ValueError(f"{folder} is not a folder")
    state, _ = load_state(folder)
    # the checkpoint's vector is in VectorH1 layout: components blocked, vertex dofs first
    u = np.asarray(state.u).reshape(state.mesh.dim, -1)[:, :state.mesh.nv].T
    stats = FragmentStatistics(state.mesh)
    scale = picture_scale(state.arrays.points, u)      # as the run draws it
    pictures = final_pictures(folder, state.mesh, u, stats, scale, sizes_min_fragments=1)   # asked for: both
    if "final_error" in pictures:
        print(f"final.png was not drawn: {pictures['final_error']}", file=sys.stderr)
        return 1
    print(f"{folder}/: final.png and fragment_sizes.png of step {state.step} (load {state.x:.6g}, "
          f"{stats.count} fragments)")
    return 0


def _add_verify(subparsers):
    from .studies import verify

    p = subparsers.add_parser(
        "verify", help="convergence study against an exact solution",
        description="Solve a problem with a known exact solution on a sequence of meshes, "
                    "report relative L2 and energy-norm errors per level and the rates fitted "
                    "by least squares in log-log over the finest three levels.")
    p.add_argument("problem", choices=["lshape"],
                   help="lshape: the L-shaped domain with the corner singularity of the paper "
                        "(section 4.1, eq. 15)")
    p.add_argument("--order", type=_int_at_least(1), default=1,
                   help="polynomial order of the displacement space (default 1)")
    p.add_argument("--levels", type=_int_at_least(2), default=6,
                   help="number of meshes: the coarse mesh and LEVELS-1 uniform refinements, "
                        "h = h_coarse/2^level (default 6)")
    p.add_argument("--variant", choices=verify.VARIANTS, default="dirichlet",
                   help="dirichlet: exact displacement on the whole boundary; traction-free: "
                        "free reentrant edges, exact displacement elsewhere (default dirichlet)")
    p.add_argument("--model", choices=verify.MODELS, default="linear",
                   help="material model; the exact solution is linear-elastic (default linear)")
    p.add_argument("--mesh", choices=verify.MESHES, default="uniform",
                   help="uniform refinements, or the same meshes graded toward the corner "
                        "(default uniform)")
    p.add_argument("--gamma", type=_positive_float, default=None,
                   help="grading exponent (>= 1) for --mesh graded; default 2 for order 1, "
                        "4 for order 2, ceil(order/alpha) in general")
    p.add_argument("--h0", type=_positive_float, default=0.5,
                   help="target edge length (netgen maxh) of the coarse mesh, at most 2 (default 0.5)")
    p.add_argument("--E", type=_positive_float, default=1e5, help="Young's modulus (default 1e5)")
    p.add_argument("--nu", type=float, default=0.3,
                   help="Poisson's ratio, -1 < nu < 0.5 (default 0.3; plane strain)")
    p.add_argument("--solver", choices=verify.SOLVERS, default=verify.DEFAULT_SOLVER,
                   help="ngfracture: through ngfracture.ElasticProblem; plain: a textbook "
                        f"NGSolve solve (default {verify.DEFAULT_SOLVER})")
    p.add_argument("--json", metavar="FILE", default=None,
                   help="write the results as JSON to FILE (atomically); refused if FILE "
                        "exists, unless --force")
    p.add_argument("--force", action="store_true", help="overwrite an existing --json file")
    p.set_defaults(func=_run_verify)


def _run_verify(args):
    from .studies import verify

    if args.json is not None and os.path.exists(args.json) and not args.force:
        raise FileExistsError(f"{args.json} exists; pass --force to overwrite it")
    if args.gamma is not None and args.mesh != "graded":
        raise ValueError("--gamma needs --mesh graded")
    res = verify.lshape_study(args.order, args.levels, variant=args.variant, model=args.model,
                              mesh=args.mesh, E=args.E, nu=args.nu, h0=args.h0,
                              gamma=args.gamma, solver=args.solver)
    print(f"lshape, order {res['order']}, {res['variant']}, {res['mesh']} mesh, "
          f"solver {res['solver']}, alpha = {res['alpha']:.6f}")
    print(f"{'level':>5} {'ndof':>9} {'nverts':>8} {'h':>10} {'rel_l2':>11} {'rel_energy':>11} "
          f"{'time_s':>8}")
    for r in res["levels"]:
        print(f"{r['level']:5d} {r['ndof']:9d} {r['nverts']:8d} {r['h']:10.4g} {r['rel_l2']:11.4e} "
              f"{r['rel_energy']:11.4e} {r['time_s']:8.3f}")
    rates = res["rates"]
    print(f"rates over the finest three levels: L2 {rates['l2']:.3f}, energy {rates['energy']:.3f}")
    if args.json is not None:
        from .output.atomic import write_json
        write_json(args.json, res, force=args.force, make_folder=True)
    return 0


def _add_ensemble(subparsers):
    from . import scenes

    p = subparsers.add_parser(
        "ensemble", help="many seeds of a scene with random strength, and their statistics",
        description="Run N samples of a scene, seeds S, S+1, ..., S+N-1, each an ordinary run in "
                    "DIR/sample_NNNN/, on dask.distributed: a local cluster of K single-threaded "
                    "worker processes, or the scheduler at ADDRESS (any dask cluster). Writes "
                    "DIR/ensemble.json (per-sample results, fragment-size statistics with bootstrap "
                    "intervals, a fit of the fragment-size distribution) and three PNGs. A rerun "
                    "skips finished samples and resumes interrupted ones. The scene needs a random "
                    "strength: --set weibull_m=M. Exit status 0 when every sample ends normally, "
                    "1 when one fails, 2 on bad input.")
    p.add_argument("scene", metavar="SCENE",
                   help=f"a built-in scene ({', '.join(sorted(scenes.SCENES))}), a file path/to/scene.py "
                        f"defining scene(**params), or package.module:function; it needs a seed parameter")
    p.add_argument("--samples", type=_int_at_least(1), required=True, help="number of samples N (>= 1)")
    p.add_argument("--seed", type=_int_at_least(0), default=0, help="seed of the first sample (default 0)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a scene parameter, e.g. --set weibull_m=8 --set maxh=0.12 (repeatable)")
    p.add_argument("--out", metavar="DIR", default=None, help="output folder (default out/SCENE_ensemble)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="address of a running dask scheduler, e.g. tcp://host:8786")
    where.add_argument("--workers", type=_int_at_least(1), default=2,
                       help="worker processes of the local cluster (default 2)")
    p.add_argument("--steps", type=_int_at_least(1), default=None,
                   help="at most this many steps per sample (default: the scene's, else 200)")
    p.add_argument("--contact", choices=["auto", "never"], default="auto", help="as for run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run_ensemble)


def _run_ensemble(args):
    from .studies.ensemble import Ensemble, SceneFactory
    from .run.scene_source import load_scene_function, parse_assignments, scene_parameters

    function = load_scene_function(args.scene)
    accepted = scene_parameters(function)
    overrides = parse_assignments(args.set, function)
    if "seed" not in accepted:
        raise ValueError(f"scene {args.scene} takes no seed parameter: its samples would not differ")
    if "seed" in overrides:
        raise ValueError("give the first seed with --seed S, not --set seed=...")
    if "weibull_m" in accepted and overrides.get("weibull_m", accepted["weibull_m"]) is None:
        raise ValueError(f"the samples of scene {args.scene} differ only by a random strength: "
                         f"set its Weibull modulus, e.g. --set weibull_m=8")
    name = os.path.splitext(os.path.basename(args.scene.replace(":", "_")))[0]
    out = args.out if args.out is not None else os.path.join("out", f"{name}_ensemble")
    ensemble = Ensemble(SceneFactory(args.scene, overrides),           # checks the scene, writes nothing
                        list(range(args.seed, args.seed + args.samples)), out=out,
                        control={} if args.steps is None else {"max_steps": args.steps},
                        contact=args.contact, workers=args.workers,
                        progress=not args.quiet)
    client = None
    if args.scheduler is not None:
        from distributed import Client
        try:
            client = Client(args.scheduler, timeout="5s")
        except (OSError, ValueError) as err:
            raise ValueError(f"cannot reach the dask scheduler at {args.scheduler}: {err}") from None
    try:
        report = ensemble.run(client)
    finally:
        if client is not None:
            client.close()
    counts, peaks, fit = report["fragment_counts"], report["peak_load"], report["fit"]
    print(f"{report['scene']}: {report['finished']} of {len(report['samples'])} samples finished")
    if counts.get("n"):
        print(f"fragments per sample {counts['mean']:.3g} (95% interval {counts['mean_interval'][0]:.3g} to "
              f"{counts['mean_interval'][1]:.3g}); peak load {peaks['mean']:.4g} +- {peaks['std']:.2g}; "
              f"fragment sizes: {fit.get('family') or fit.get('reason')}")
    print(f"results in {out}/ (ensemble.json, {', '.join(sorted(report['pictures'].values()))})")
    if report["not_finished"]:
        raise RuntimeError(f"samples {report['not_finished']} did not finish (see their summary.json)")
    return 0


def build_parser():
    """The argument parser of ``python -m ngfracture``.

    Returns
    -------
    argparse.ArgumentParser
    """
    parser = argparse.ArgumentParser(
        prog="ngfracture",
        description="ngfracture: brittle fracture by node splitting, an NGSolve plugin.")
    parser.add_argument("--version", action="version", version=f"ngfracture {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    _add_run(subparsers)
    _add_scenes(subparsers)
    _add_render(subparsers)
    _add_verify(subparsers)
    _add_ensemble(subparsers)
    return parser


def main(argv=None):
    """Entry point of ``python -m ngfracture`` and the ``ngfracture`` script.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        Exit status: 0 on success, 2 on bad input, 1 on a failed computation.
    """
    from .run.checkpoint import CheckpointError

    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileExistsError, CheckpointError) as exc:
        parser.exit(2, f"{parser.prog} {args.command}: error: {exc}\n")
    except RuntimeError as exc:
        print(f"{parser.prog} {args.command}: failed: {exc}", file=sys.stderr)
        return 1
