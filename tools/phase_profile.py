"""Exclusive wall and CPU seconds per phase and counts per load step of a run.

Wraps the functions that make up a load step (factorisations, Schur complements, KKT
solves, assembly, contact detection and rows, the active-set choice, the crack pass,
output) with timers that charge time to the innermost phase on a stack, so the phases
add up to the step's time; counts factorisations, Newton solves and iterations, contact
solves and rounds, complementarity problems and crack passes. Prints one JSON line per
accepted step to stderr and writes them all to ``--profile FILE`` at the end.

    PYTHONPATH=. OMP_NUM_THREADS=1 python tools/phase_profile.py --profile p.json -- \
        run sphere3d --pictures none --progress none --out DIR

Measurement only: results are those of the plain run (no numerics change).
"""
import functools
import json
import sys
import time

PHASES = []
_stack = ["other"]
_wall = {}
_cpu = {}
_count = {}
_last = [time.perf_counter(), time.process_time()]


def _charge():
    w, c = time.perf_counter(), time.process_time()
    top = _stack[-1]
    _wall[top] = _wall.get(top, 0.0) + w - _last[0]
    _cpu[top] = _cpu.get(top, 0.0) + c - _last[1]
    _last[0], _last[1] = w, c


def wrap(owner, name, phase, count=None, when=None):
    """Charge the time of ``owner.name`` (exclusive of nested wrapped calls) to ``phase``."""
    original = getattr(owner, name)
    if isinstance(original, (staticmethod, classmethod)):
        raise TypeError(name)

    @functools.wraps(original)
    def timed(*args, **kwargs):
        if count is not None and (when is None or when(*args, **kwargs)):
            _count[count] = _count.get(count, 0) + 1
        _charge()
        _stack.append(phase)
        try:
            return original(*args, **kwargs)
        finally:
            _charge()
            _stack.pop()

    setattr(owner, name, timed)
    if phase not in PHASES:
        PHASES.append(phase)


def install():
    """Wrap the phases' functions (module names as imported by their callers)."""
    from ngfracture.linalg import factor, kkt, iterative, qp
    from ngfracture.linalg import sparse_schur
    from ngfracture.mechanics import problem, newton
    from ngfracture.contact import solver, active_set, active_set3d, setup3d, collision3d, edge_crossings3d
    from ngfracture.fracture import criterion
    from ngfracture.run import step, solid_pass, files, simulation, growth, tangents

    wrap(factor.EliminatedFactor, "factorise", "factorisation", "factorisations",
         when=lambda self: not self.factorised)
    wrap(newton.NewtonSolver, "_factor", "factorisation")            # make_factor: K_ff, pattern
    wrap(factor.EliminatedFactor, "schur", "schur")
    wrap(sparse_schur.DofSchur, "complement", "schur product")
    wrap(sparse_schur.SparseSchur, "complement", "schur G", "schur_G")
    wrap(factor.FactorBase, "columns_and_solve", "schur")
    wrap(factor.FactorBase, "corrected_modes", "schur")
    wrap(kkt.ConstrainedSolver, "__init__", "schur", "kkt_builds")
    wrap(kkt.ConstrainedSolver, "solve", "row solves", "kkt_solves")
    wrap(kkt.ConstrainedSolver, "solve_unilateral", "complementarity", "complementarity")
    wrap(factor.EliminatedFactor, "solve", "triangular solves", "factor_solves")
    wrap(problem.ElasticProblem, "tangent", "assembly", "tangents")
    wrap(problem.ElasticProblem, "out_of_balance", "assembly", "residuals")
    wrap(problem.ElasticProblem, "inverted_elements", "newton checks")
    wrap(problem.ElasticProblem, "support", "newton checks")
    wrap(problem.ElasticProblem, "floating_bodies", "newton checks")
    wrap(problem.ElasticProblem, "assemble_constraints", "newton checks")
    wrap(newton.NewtonSolver, "solve", "newton other", "newton_solves")
    wrap(newton.NewtonSolver, "_hold_free_modes", "newton checks")
    wrap(solver.ContactSolver, "solve", "contact other", "contact_solves")
    wrap(solver.ContactSolver, "_geometry", "contact setup")
    wrap(solver.ContactSolver, "_impose", "contact rows")
    wrap(setup3d.MeshSetups, "setup", "contact setup")
    wrap(active_set3d.ActiveSet3d, "update", "contact rows", "rounds")
    wrap(collision3d.PenetrationDetector3d, "detect", "detection")
    wrap(edge_crossings3d.EdgeCrossingDetector, "detect", "detection")
    wrap(active_set.ActiveSet, "primal_dual", "choice")
    wrap(active_set.ActiveSet, "choose", "choice")
    wrap(active_set.ActiveSet, "settle", "choice")
    wrap(active_set.ActiveSet, "record", "choice")
    wrap(active_set, "independent_rows", "QR")
    wrap(active_set3d, "holds_on_columns", "QR")
    wrap(kkt, "bound_qp", "complementarity qp")
    wrap(criterion.Criterion, "overstrain", "criterion")
    wrap(step.LoadStep, "crack_pass", "crack other", "crack_passes")
    wrap(solid_pass, "split_by_tensor_3d", "split")
    wrap(solid_pass, "solid_mesh", "netgen mesh")
    wrap(step.LoadStep, "problem", "problem build", "problems")
    wrap(problem.ElasticProblem, "__init__", "problem init")
    wrap(step.LoadStep, "check", "checks")
    wrap(step.LoadStep, "accept", "accept")
    wrap(step.LoadStep, "cut_through", "cut through")
    wrap(tangents, "kept_tangent", "kept tangent")
    wrap(files.RunFiles, "write_step", "output")
    wrap(files.RunFiles, "write_checkpoint", "output")
    del iterative, qp, growth
    return simulation


def main():
    argv = sys.argv[1:]
    out = None
    if argv[:1] == ["--profile"]:
        out, argv = argv[1], argv[2:]
    if argv[:1] == ["--"]:
        argv = argv[1:]
    simulation = install()
    steps = []
    before = [dict(), dict(), dict(), time.perf_counter(), time.process_time()]
    report = simulation.Simulation._report

    def reported(self, accepted, t_start, on_step):
        _charge()
        w, c = time.perf_counter(), time.process_time()
        record = {"step": accepted.state.step, "x": accepted.state.x, "wall": w - before[3], "cpu": c - before[4],
                  "split_vertices": accepted.record["split_vertices"],
                  "relax_passes": accepted.record["relax_passes"],
                  "retries": accepted.record["retries"],
                  "wall_phases": {k: v - before[0].get(k, 0.0) for k, v in _wall.items()},
                  "cpu_phases": {k: v - before[1].get(k, 0.0) for k, v in _cpu.items()},
                  "counts": {k: v - before[2].get(k, 0) for k, v in _count.items()}}
        steps.append(record)
        print(json.dumps(record), file=sys.stderr, flush=True)
        before[:] = [dict(_wall), dict(_cpu), dict(_count), w, c]
        if out:
            with open(out, "w") as f:
                json.dump(steps, f)
        return report(self, accepted, t_start, on_step)

    simulation.Simulation._report = reported
    from ngfracture.cli import main as cli_main
    try:
        return cli_main(argv)
    finally:
        if out:
            with open(out, "w") as f:
                json.dump(steps, f)


if __name__ == "__main__":
    sys.exit(main())
