"""Quasi-static fracture simulations under load control (paper section 4.2, made robust).

    import ngfracture as nf
    result = nf.Simulation(nf.scenes.plate(), nf.StepControl(), out="out/plate").run()

A run repeats load steps (:mod:`ngfracture.run.step`) from the scene's undamaged state
until x reaches the scene's ``load_max``, after ``max_steps`` steps, or, for scenes that
ask for it, once the body is broken through: no fragment connects boundaries that the
prescribed displacements move against each other (loadpath.py; pieces that only push on
each other by contact, such as the interlocking halves of the plate, do not count), or
the elastic energy has fallen below ``unloaded_fraction`` of its peak after cracks
appeared. A step that fails after all retries ends the run with the last good state
written and a reason.
"""
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..contact.overlap import fragment_overlap_area
from ..contact.redundancy import independent_rows
from ..fracture.criterion import ONE_RING_NOTE
from ..fracture.crack_graph import crack_graph
from ..fracture.fragments import FragmentStatistics
from ..linalg.sparse import single_threaded_blas
from ..mechanics.problem import ElasticProblem
from . import checkpoint
from .control import StepControl
from .files import RunFiles, check_folder, read_resumable
from .heap import kept_heap
from .scene import Scene
from ..geometry.solid import crack_area
from .state import crack_length
from .step import LoadStep
from .timings import Timings

__all__ = ["Simulation", "RunResult", "Scene", "StepControl", "MeshDependentCriterion", "LinearAtLargeStrain",
           "UnresolvedCrackTip", "TIP_RESOLUTION_LIMIT",
           "LINEAR_STRAIN_LIMIT"]

#: critical strains above this in a linear-elastic region draw a warning: the linear model
#: is not frame invariant (a rigid rotation by t strains it by about t^2 / 2), so where
#: pieces strain or turn this much its stresses are an artefact (docs/limitations.md)
LINEAR_STRAIN_LIMIT = 0.01


class MeshDependentCriterion(UserWarning):
    """A scene without a critical distance or toughness: its cracks depend on the mesh."""


class LinearAtLargeStrain(UserWarning):
    """A linear-elastic region that cracks only at strains where the linear model is not valid."""


class UnresolvedCrackTip(UserWarning):
    """A crack tip in triangles larger than TIP_RESOLUTION_LIMIT times the critical distance."""


#: h / r at a crack tip (h the longest edge of its triangles) above which the point at r from
#: the tip lies in the tip's own triangles: the measure reads the ring's average, not the
#: field at r, and cracks in such triangles branch (docs/criterion.md, "Resolution")
TIP_RESOLUTION_LIMIT = 1.0


class Simulation:
    """A fracture simulation under load control, with outputs and checkpoints.

    Parameters
    ----------
    scene : Scene
    control : StepControl, optional
    out : path, optional
        Output folder: VTK time series, checkpoints, summary.json, pictures. None: no files.
    force : bool
        Replace earlier results in ``out`` (only files this code writes are removed).
    resume : bool
        Continue from the newest checkpoint in ``out``.
    pictures : {"final", "every", "none"}
        PNG of the final state (and the fragment-size plot when the body ends in
        ``output.SIZES_MIN_FRAGMENTS`` pieces or more), of every step too, or no picture
        at all.
    checkpoint_every : int
        Write a checkpoint after every this many accepted steps (and at the end).
    progress : callable(dict), optional
        Called after every accepted step with a dict: step, x, load_max, split_vertices,
        fragments, seconds.
    contact : {"auto", "never"}
        "auto": in 2D contact from the first crack on (or from the start for separate
        bodies); in 3D where the scene asks for it (``Scene.contact``: from the start, crack
        lips included), else the overlap is measured and noted at every step
        (:meth:`LoadStep.check`); "never": no contact rows at all (faster where pieces only
        separate; the summary's ``max_overlap_area`` still measures any overlap).

    Attributes
    ----------
    timings : Timings
        Wall seconds per phase of the last :meth:`run`.

    Raises
    ------
    ValueError
        A bad scene, step control or option, before any work.
    FileExistsError
        ``out`` holds results and neither ``force`` nor ``resume`` is given.
    checkpoint.CheckpointError
        ``resume`` with a damaged, foreign or mismatching checkpoint.

    Warns
    -----
    MeshDependentCriterion
        The scene has neither a critical distance nor a toughness (the paper's one-ring
        criterion decides; summary.json says so too).
    LinearAtLargeStrain
        A linear-elastic region with a critical strain above ``LINEAR_STRAIN_LIMIT``.
    """

    def __init__(self, scene, control=None, out=None, force=False, resume=False, pictures="final",
                 checkpoint_every=1, progress=None, contact="auto"):
        if not isinstance(scene, Scene):
            raise ValueError(f"Simulation needs a Scene, got {type(scene).__name__}")
        self.scene = scene
        self.criterion = scene.validate()
        # the user's control overrides only the fields it sets; neither object is changed
        user = control if control is not None else StepControl()
        control = user.over(scene.control)
        if not self.criterion.one_ring and "split" not in control.explicit:
            # cracks judged at a critical distance grow one event at a time (docs/criterion.md)
            control = control.over({"split": "one"})
        self.control = control.resolved(scene.dx)
        if pictures not in ("final", "every", "none"):
            raise ValueError(f"pictures must be 'final', 'every' or 'none', got {pictures!r}")
        if contact not in ("auto", "never"):
            raise ValueError(f"contact must be 'auto' or 'never', got {contact!r}")
        if force and resume:
            raise ValueError("force and resume exclude each other")
        if isinstance(checkpoint_every, bool) or not isinstance(checkpoint_every, int) or checkpoint_every < 1:
            raise ValueError(f"checkpoint_every must be an integer >= 1, got {checkpoint_every!r}")
        self.contact = contact
        self.out = Path(out) if out is not None else None
        self.force, self.resume, self.pictures = force, resume, pictures
        self.checkpoint_every = checkpoint_every
        self.progress = progress
        self.timings = Timings()
        #: the scene loads by tractions, body forces or pressures (force control), found by the check
        self.dead_loads = self._check_load()      # before the output folder is touched
        if self.out is not None:
            check_folder(self.out, force, resume)
            if resume:
                read_resumable(self.out, self._identity())
        if self.criterion.one_ring:
            warnings.warn(f"Scene {scene.name!r}: {ONE_RING_NOTE}", MeshDependentCriterion, stacklevel=2)
        for region in _linear_at_large_strain(scene):
            warnings.warn(f"Scene {scene.name!r}: region {region!r} is linear elastic and cracks only above a "
                          f"strain of {LINEAR_STRAIN_LIMIT:g}, where the linear model is not frame invariant "
                          f"(rotations strain it); use StVenantKirchhoff or NeoHookean", LinearAtLargeStrain,
                          stacklevel=2)

    def _check_load(self):
        """Build the problem at x = 0, at the first increment and at the final load: the scene's materials,
        regions and the boundaries its ``apply_load`` names are checked before any work. Returns
        whether the problem at the first increment has loads other than prescribed displacements."""
        dead_loads, dependent = False, ""
        for x in (0.0, float(self.scene.dx), float(self.scene.load_max)):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")   # mesh quality: the run's own problems warn
                    prob = ElasticProblem(self.scene.mesh, self.scene.material, order=1)
                self.scene.apply_load(prob, x)
                rows = prob.assemble_constraints()
                if x == float(self.scene.dx):
                    dead_loads, dependent = bool(prob.loads), dependent_rows(prob, rows)
            except Exception as exc:
                raise ValueError(f"Scene {self.scene.name!r}: the problem at load x = {x:g} cannot be "
                                 f"built: {type(exc).__name__}: {exc}") from exc
            if dependent:
                raise ValueError(f"Scene {self.scene.name!r}: at load x = {x:g}, {dependent}: every solve "
                                 f"would be singular; leave them out of apply_load")
        return dead_loads

    def _identity(self):
        """What a checkpoint must match to be resumed by this run.

        ``max_steps`` only says where to stop (a run may be resumed to go further);
        pictures and the checkpoint interval do not touch the result.
        """
        options = {**{k: v for k, v in asdict(self.control).items() if k != "max_steps"}, "contact": self.contact}
        return {"scene": self.scene.name, "parameters": self.scene.parameters, "control": options}

    def _start(self, stepper, area_initial, t0):
        """The first state of the run and its files: (state, files, wall seconds before).

        A resumed run continues from its newest checkpoint (the timings and wall time of
        the earlier part included); a new one writes its state at x = 0.
        """
        if self.resume:
            state, run = read_resumable(self.out, self._identity())
            timings = dict(run.get("timings", {}))
            wall_before = float(timings.pop("wall", 0.0))
            self.timings.restore_factorisations(timings.pop("linear_solver", {}))
            self.timings.update(timings)
            if run["area_initial"] != area_initial:
                raise checkpoint.CheckpointError(f"{self.out}: the checkpoint's initial area {run['area_initial']!r} "
                                                 f"is not the scene's {area_initial!r}")
            if state.area is None:        # a checkpoint of an unrefined run
                state.area = area_initial
            return state, RunFiles.resume(self.out, state.step, self.pictures), wall_before
        state = stepper.initial_state(self.timings)
        files = None
        if self.out is not None:
            files = RunFiles.create(self.out, self.pictures)
            prob = stepper.problem(state.mesh, 0.0, self.timings, state.u)
            files.write_step(state, prob, FragmentStatistics(state.mesh), self.timings)
            files.write_checkpoint(state, self._checkpoint_meta(area_initial, time.perf_counter() - t0), self.timings)
        return state, files, 0.0

    def _checkpoint_meta(self, area_initial, wall):
        identity = self._identity()
        return {"scene": identity["scene"], "parameters": identity["parameters"], "area_initial": area_initial,
                "control": identity["control"],
                "timings": {**self.timings, "wall": wall, "linear_solver": self.timings.factorisation_record()}}

    @single_threaded_blas()
    @kept_heap()
    def run(self, on_step=None):
        """Run to the end (freed memory kept for the run's next allocations, run/heap.py).

        Parameters
        ----------
        on_step : callable(AcceptedStep), optional
            Called with every accepted step (its state, history record, problem,
            fragments and the attempt that was accepted), after its files are written.

        Returns
        -------
        RunResult
            ``ok``, ``reason``, ``message``, the ``summary`` (also in summary.json), the
            last accepted problem and state. A failed run is a result with ``ok`` False,
            not an exception; the last good state is written.
        """
        self.timings = Timings()
        t0 = time.perf_counter()
        #: math.fsum of the triangle areas; splitting keeps every triangle and coordinate,
        #: so the area of every accepted state equals it to the last bit
        area_initial = FragmentStatistics(self.scene.mesh).total_area
        stepper = LoadStep(self.scene, self.control, self.criterion, self.contact, area_initial, self.dead_loads)
        state, files, wall_before = self._start(stepper, area_initial, t0)
        t_start = t0 - wall_before   # a resumed run counts the earlier part
        reason, message, prob, stats, failure = "load_max", "reached the final load", None, None, None
        while True:
            reason, message = self._ending(stepper, state) or (reason, message)
            if reason != "load_max" or state.x >= self.scene.load_max * (1 - 1e-12):
                break
            remaining = self.scene.load_max - state.x
            # no sliver of a last step: a remainder below dx_min joins this one
            dx = remaining if remaining - state.dx < self.control.dx_min else state.dx
            outcome = stepper.step(state, dx, self.timings)
            if outcome.attempt is None:
                reason, err = "failed", outcome.failure
                message = (f"step {state.step + 1} at x = {state.x + outcome.dx:.6g} failed {outcome.log.retries} "
                           f"time(s); last reason {err.reason}: {err.message}")
                failure = {"step": state.step + 1, "x": state.x + outcome.dx, "retries": outcome.log.retries,
                           "reason": err.reason, "phase": err.phase, "message": err.message,
                           **({"details": err.details} if err.details else {})}
                break
            accepted = stepper.accept(state, outcome, self.timings)
            state, prob, stats = accepted.state, accepted.problem, accepted.fragments
            if files is not None:
                files.write_step(state, prob, stats, self.timings)
                if state.step % self.checkpoint_every == 0:
                    files.write_checkpoint(state, self._checkpoint_meta(area_initial, time.perf_counter() - t_start),
                                           self.timings)
            self._report(accepted, t_start, on_step)
            resolution = accepted.record.get("tip_resolution", 0.0)
            if resolution > TIP_RESOLUTION_LIMIT and not any(h.get("tip_resolution", 0.0) > TIP_RESOLUTION_LIMIT
                                                             for h in state.history[:-1]):
                warnings.warn(f"Scene {self.scene.name!r}, step {state.step}: a crack tip lies in triangles of "
                              f"{resolution:.3g} times the critical distance (more than {TIP_RESOLUTION_LIMIT}); "
                              f"the criterion does not resolve the stress there and cracks may branch: refine "
                              f"the mesh where cracks run, or ahead of the tips during the run "
                              f"(Scene(refine=True))", UnresolvedCrackTip, stacklevel=3)
        if prob is None:
            prob = stepper.problem(state.mesh, state.x, self.timings, state.u)
            stats = FragmentStatistics(state.mesh)
        if files is not None and state.step % self.checkpoint_every != 0:
            files.write_checkpoint(state, self._checkpoint_meta(area_initial, time.perf_counter() - t_start),
                                   self.timings)
        summary = self._summary(state, prob, stats, area_initial, reason, message, time.perf_counter() - t_start)
        if failure is not None:
            summary["failure"] = failure       # what failed last, machine-readable
        if files is not None:
            files.write_final(state, prob, stats, summary, self.timings)
        return RunResult(ok=reason in ("load_max", "max_steps", "broken"), reason=reason, message=message,
                         summary=summary, problem=prob, state=state)

    def _ending(self, stepper, state):
        """(reason, message) when the run ends before another step (step limit, broken), else None."""
        if state.x >= self.scene.load_max * (1 - 1e-12):
            return None
        if state.history and state.history[-1].get("lost_support"):
            return "broken", f"at x = {state.x:.6g}: {state.history[-1]['lost_support']}"
        if state.step >= self.control.max_steps:
            return "max_steps", f"stopped after {self.control.max_steps} steps"
        broken = stepper.broken(state, self.timings) if self.scene.stop_when_unloaded and state.history else ""
        return ("broken", broken) if broken else None

    def _report(self, accepted, t_start, on_step):
        """Tell the caller about an accepted step (progress dict, on_step record)."""
        state = accepted.state
        if self.progress is not None:
            self.progress({"step": state.step, "x": state.x, "load_max": self.scene.load_max,
                           "split_vertices": sum(h["split_vertices"] for h in state.history),
                           "fragments": state.history[-1]["fragments"], "seconds": time.perf_counter() - t_start,
                           "boundaries": accepted.record["boundaries"]})
        if on_step is not None:
            on_step(accepted)

    def _extent(self, state, prob, stats, area_initial):
        """The summary's cracks, fragments and mesh size: lengths and areas, or areas and volumes in 3D."""
        if prob.dim == 3:
            return {"crack_area": crack_area(state.arrays), "n_fragments": int(stats.count),
                    "fragment_volumes": stats.areas.tolist(), "volume_initial": area_initial,
                    "volume_final": stats.total_area, "n_vertices": int(prob.mesh.nv), "n_tetrahedra": int(prob.mesh.ne)}
        hist = state.history
        overlap = fragment_overlap_area(prob) if stats.count > 1 or self.scene.contact else 0.0
        return {"crack_length": crack_length(state.arrays), "crack_graph": crack_graph(state.arrays).summary(),
                "max_tip_resolution": max((h.get("tip_resolution", 0.0) for h in hist), default=0.0),
                "n_fragments": int(stats.count), "fragment_areas": stats.areas.tolist(),
                "area_initial": area_initial, "area_final": stats.total_area,
                "max_overlap_area": overlap,
                "n_vertices": int(prob.mesh.nv), "n_triangles": int(prob.mesh.ne)}

    def _summary(self, state, prob, stats, area_initial, reason, message, wall):
        hist = state.history
        return {
            "scene": self.scene.name, "parameters": self.scene.parameters,
            "load_description": self.scene.load_description,
            "criterion": self.criterion.describe(),
            "control": {k: v for k, v in asdict(self.control).items()},
            "reason": reason, "message": message,
            "n_steps": state.step, "load": state.x,
            "n_split_vertices": int(sum(h["split_vertices"] for h in hist)),
            **self._extent(state, prob, stats, area_initial),
            "crack_initiation": next((h["initiation"] for h in hist if "initiation" in h), []),
            "energy": [{k: h[k] for k in ("step", "x", "elastic_energy", "external_work", "released_energy")}
                       for h in hist],
            "newton_iterations": [h["newton_iterations"] for h in hist],
            # departures from the plain path of the solvers (see ContactResult.notes)
            "notes": [{"step": h["step"], "note": n} for h in hist for n in h.get("notes", [])],
            "history": hist,
            # and which solver made K^+ how often and why (linalg.iterative.choose_inverse)
            "timings": {**{k: round(v, 6) for k, v in self.timings.items()}, "wall": round(wall, 6),
                        "linear_solver": self.timings.factorisation_record()},
        }


def dependent_rows(prob, rows):
    """Which general constraint rows of a problem depend linearly on the others or on its
    single-dof rows, in words ("" where none does).

    Parameters
    ----------
    prob : ElasticProblem
    rows : ConstraintRows
        ``prob.assemble_constraints()``.

    Returns
    -------
    str
        E.g. "12 of its 120 general constraint rows (stick: 12; rows 3, 7, ...) depend on the
        others or on the Dirichlet conditions".
    """
    m = rows.C.shape[0]
    if m == 0:
        return ""
    # rtol far below the redundancy removal's: only rows that no solve could impose
    dropped = np.setdiff1d(np.arange(m), independent_rows(rows.C, rows.fixed_dofs, rtol=1e-10))
    if dropped.size == 0:
        return ""
    blocks = prob.constraints.rows
    labels = np.repeat([label for _, _, label in blocks], [C.shape[0] for C, _, _ in blocks])[dropped]
    counts = ", ".join(f"{name}: {int(np.sum(labels == name))}" for name in dict.fromkeys(labels))
    listed = ", ".join(str(i) for i in dropped[:8]) + (", ..." if dropped.size > 8 else "")
    return (f"{dropped.size} of its {m} general constraint rows ({counts}; rows {listed}) depend on the "
            f"others or on the Dirichlet conditions")


def _linear_at_large_strain(scene):
    """The regions of a scene with a linear material and a critical strain above the limit."""
    from ..mechanics.materials import LinearElastic, region_materials
    materials = region_materials(scene.mesh, scene.material)
    critical = scene.critical if isinstance(scene.critical, dict) else dict.fromkeys(materials, scene.critical)
    return [r for r, m in materials.items() if isinstance(m, LinearElastic)
            and critical.get(r) is not None and critical[r] > LINEAR_STRAIN_LIMIT]


@dataclass
class RunResult:
    """How a simulation ended.

    Parameters
    ----------
    ok : bool
        True when the run reached its end (final load, step limit, broken through).
    reason : str
        "load_max", "max_steps", "broken" or "failed".
    message : str
    summary : dict
        What summary.json holds.
    problem : ElasticProblem
        The last accepted state.
    state : State
    """
    ok: bool
    reason: str
    message: str
    summary: dict
    problem: object
    state: object

    def __bool__(self):
        return self.ok
