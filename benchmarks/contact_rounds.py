"""Rounds and CPU of the contact solves of a run resumed for some steps, with and without a kind of row.

A copy of a run folder (``--src``, with its checkpoints) is resumed for ``--steps`` more
accepted steps (``ngfracture run SCENE --resume``) twice, in this process one after the
other: as the code is (``with``) and with the rows of an edge copy behind a face of a
reflex wedge left out (``without``: ``wedges3d.reflex_wedge_rows`` giving none), so that a
kind of row is judged on the same states by the rounds it costs or saves (docs/contact.md,
"Rows at copies found by their planes").

Reported per variant: solves, rounds (sum, per solve, largest), the reasons the solves
ended with, the CPU seconds inside the contact solves, and the run's steps, split vertices
and reason.

    cd benchmarks && PYTHONPATH=.. OMP_NUM_THREADS=1 python contact_rounds.py --src RUN --steps 35 \\
        --scene sphere3d_free --set maxh=0.4 --set fine=0.15 --json rounds.json
"""
import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

from benchmark_json import add_options, refuse_existing, write


def resumed(src, steps, scene, settings, without):
    """Resume a copy of ``src`` to ``steps`` accepted steps; the contact solves' rounds and CPU."""
    import ngfracture.contact.active_set3d as active_set3d
    import ngfracture.contact.solver as solver
    from ngfracture.cli import main
    from ngfracture.contact.rows3d import no_face_rows
    log = []
    solve, reflex = solver.ContactSolver.solve, active_set3d.reflex_wedge_rows

    def timed(self, *args, **kwargs):
        t0 = time.process_time()
        result = solve(self, *args, **kwargs)
        log.append((result.rounds, result.reason, time.process_time() - t0))
        return result

    solver.ContactSolver.solve = timed
    if without:
        active_set3d.reflex_wedge_rows = lambda pairs, U, tol, index: no_face_rows(len(index.points))
    try:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "run"
            shutil.copytree(src, out)
            sets = [a for s in settings for a in ("--set", s)]
            code = main(["run", scene, *sets, "--pictures", "none", "--out", str(out), "--resume", "--steps",
                         str(steps), "--progress", "none"])
            summary = json.loads((out / "summary.json").read_text())
    finally:
        solver.ContactSolver.solve, active_set3d.reflex_wedge_rows = solve, reflex
    rounds = [r for r, _, _ in log]
    return {"solves": len(log), "rounds": sum(rounds), "rounds_per_solve": sum(rounds) / max(len(log), 1),
            "max_rounds": max(rounds, default=0), "reasons": sorted({r for _, r, _ in log}),
            "cpu_contact_solves": sum(c for _, _, c in log), "exit": code, "n_steps": summary["n_steps"],
            "n_split_vertices": summary["n_split_vertices"], "reason": summary["reason"]}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--src", required=True, help="a run folder with checkpoints (copied, not changed)")
    p.add_argument("--steps", type=int, required=True, help="resume to this many accepted steps")
    p.add_argument("--scene", required=True, help="the run's scene")
    p.add_argument("--set", dest="settings", action="append", default=[], metavar="NAME=VALUE",
                   help="the run's scene parameters, as for ngfracture run")
    add_options(p)
    args = p.parse_args(argv)
    if not Path(args.src).is_dir():
        p.error(f"--src {args.src!r} is not a folder")
    if args.steps < 1:
        p.error(f"--steps must be >= 1, got {args.steps}")
    refuse_existing(p, args)
    cases = {}
    for name, without in (("with", False), ("without", True)):
        cases[name] = resumed(args.src, args.steps, args.scene, args.settings, without)
        print(name, json.dumps(cases[name]))
    write(args, {"src": str(args.src), "steps": args.steps, "scene": args.scene, "settings": args.settings,
                 "cases": cases})


if __name__ == "__main__":
    main()
