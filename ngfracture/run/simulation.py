"""Quasi-static fracture simulations under load control (paper section 4.2, made robust).

One load step, from an accepted state (mesh, displacement, load parameter x)::

    1. x_try = x + dx; solve at x_try (modified Newton; contact once there are cracks
       or separate bodies; free fragments held on their rigid modes);
    2. find the overstrained vertices and split them (one crack pass);
       if the pass split more than ``max_new_cracks`` vertices and dx can still be
       cut: go back to the saved state and retry with dx * cut;
    3. relax at fixed x_try: solve on the split mesh, split again, until a pass
       splits nothing (the energy release through crack formation);
    4. accept: write the step, checkpoint, x = x_try; after ``grow_after`` steps in a
       row without a crack, dx = min(dx * grow, dx_max).

A failed solve (diverged, NaN, singular, inverted element, contact set that does not
settle) sends the step back to the saved state: an increment solve that started from
the tangent kept from the step before is made again with a tangent of its own; with
modified Newton, the next retry solves the same attempt with full Newton (the tangent
factorised at the start of a solve can be too far from the state that new contact rows
impose: measured on the disk, Newton diverged with the saved tangent and converged with
fresh ones); then a failure of the
increment solve is retried with the same target in twice as many Newton load steps (the
load path does not change), a failure at fixed load after a split with dx * cut; after ``max_retries``
failures the run stops with the last good state written and a reason.  The run ends when x reaches the scene's ``load_max``, after ``max_steps``
steps, or, for scenes that ask for it, once the body is broken through: no fragment
connects boundaries that the prescribed displacements move against each other
(loadpath.py; pieces that only push on each other by contact, such as the interlocking
halves of the plate, do not count), or the elastic energy has fallen below
``unloaded_fraction`` of its peak after cracks appeared.

Where the paper is vague, we chose:

* A "crack" in the step-control rule is a split vertex (a new crack-face node) of the
  first pass after the increment; cracks that run at fixed load during relaxation
  are the physical answer to that load and are not limited.
* The criterion is the paper's nodal principal strain (Green-Lagrange, averaged from
  the elements around a vertex) or, for a scene with a critical distance, the
  nonlocal opening stress over E of docs/criterion.md, against a critical strain per material region;
  regions without a critical strain never crack.  Vertices are compared by their
  strain divided by their critical strain, so one pass serves several materials.
* Every accepted state goes through the checkpoint's mesh representation (arrays and
  back) whether or not it is written, so a resumed run continues from bitwise the
  same mesh and displacement as the uninterrupted one.
* The factorised tangent of a step's last solve starts the next step's increment solve
  (modified Newton, same mesh, at least ``KEEP_MIN_DOFS`` factorised dofs) while that
  solve contracted by ``KEEP_MAX_CONTRACTION`` or better: the paper's modified Newton
  factorises at every load step, and a tangent from a few load steps back converges in as
  many iterations on glass strains (docs/solvers.md, path 7). The displacement it was
  assembled at is in the checkpoint, so a resumed run factorises the same tangent again.
* External work is the trapezoidal sum of reaction forces times the increments of
  the prescribed displacements; relaxation at fixed load does no work, so
  work - elastic energy is the energy released by cracking.
"""
import math
import numbers
import time
import warnings
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Callable

import numpy as np

from . import checkpoint
from ..linalg import bordered as split_factor
from ..contact.solver import ContactSolver, fragment_overlap_area
from ..fracture.crack import (GROWTH_RULES, PAPER_RULES, StrainCriterion, element_strain, equivalent_strain,
                    nonlocal_opening, split_by_tensor, transfer_vertex_field)
from ..fracture.fragments import FragmentStatistics
from ..linalg.kkt import EliminatedFactor, SingularSystem, single_threaded_blas
from .loadpath import load_path_cut, prescribed_increment
from ..mechanics.materials import Material
from ..geometry.meshio import MeshArrays, mesh_from_arrays, mesh_to_arrays
from ..mechanics.problem import ElasticProblem
from ..mechanics.newton import SavedTangent

#: wall time per phase; "linear" (factorisations and triangular solves) and "assembly"
#: (NGSolve's residual and tangent assembly) are parts of "solve"
PHASES = ("solve", "linear", "assembly", "strain", "split", "rebuild", "collision", "contact", "output")

#: a step's factorised tangent starts the next step's solve from this many factorised dofs
#: on; below, a factorisation costs a few solves (the bordered factors' threshold) ...
KEEP_MIN_DOFS = split_factor.MIN_BASE_DOFS

#: ... and while its last solve contracted by this ratio or better (its increments fell by
#: 1e3 or more per iteration): at most one iteration more than a fresh tangent at tol
#: 1e-10, where a factorisation costs 15 to 30 solves (the plate at 2.9k and 31k dofs)
KEEP_MAX_CONTRACTION = 1e-3


@dataclass
class Scene:
    """Everything that defines a fracture simulation except the step control.

    Parameters
    ----------
    name : str
        Shown in outputs and stored in checkpoints (a resume must match it).
    mesh : ngsolve.Mesh
        The undamaged body (or bodies) in the reference configuration.
    material : Material or dict of str -> Material
        One material, or one per material region.
    critical : float or dict of str -> float
        Critical principal strain (> 0), or one per region; a region missing from the
        dict (or given None) never cracks.
    apply_load : callable(problem, x)
        Adds the constraints (and loads) for the deformation parameter ``x`` to a fresh
        ElasticProblem on the current mesh. Boundary names survive cracking; crack faces
        are named ``crack``.
    load_max : float
        The deformation parameter at which the run ends (> 0).
    dx : float
        First increment of x (> 0).
    contact_tol : float
        Precision threshold of collision detection and contact selection (a length).
    contact : bool
        Solve with contact from the start (separate bodies); otherwise contact starts
        with the first crack.
    stop_when_unloaded : bool
        End the run once the body is broken through: no fragment is deformed by the
        prescribed displacements any more although they deform the body (each piece
        follows its share of them rigidly, see loadpath.py), or the elastic energy has
        fallen below ``unloaded_fraction`` of its peak after cracks appeared.
    parameters : dict
        The numbers that define the scene, copied into summary.json.
    control : dict
        StepControl settings this scene needs (e.g. more cracks per increment where
        many start at once by symmetry); explicit StepControl arguments override them.
    fix_free_modes : True or "all"
        How pieces without Dirichlet support are held (``NewtonSolver``): True, on the
        rigid modes that contact leaves free; "all", on all their rigid modes (the paper's
        pinned fragments), for scenes where contact pushes pieces that nothing else holds.
    radius : float or dict of str -> float, optional
        Critical distance of the crack criterion (docs/criterion.md), or one per region;
        None: the paper's one-ring nodal strain.
    strength : numpy.ndarray, optional
        Critical strain per vertex of ``mesh`` (a random field, :mod:`ngfracture.fracture.strength`);
        it replaces the region's critical strain at the vertices of regions that can
        crack. The copies of a split vertex inherit its strength.
    load_description : str
        What the load parameter x is, with its unit (e.g. "total extension of the plate
        (length)"); shown by ``ngfracture scenes`` and written to summary.json.
    """
    name: str
    mesh: object
    material: object
    critical: object
    apply_load: Callable
    load_max: float
    dx: float
    contact_tol: float
    contact: bool = False
    stop_when_unloaded: bool = False
    parameters: dict = field(default_factory=dict)
    control: dict = field(default_factory=dict)
    fix_free_modes: object = True
    radius: object = None
    strength: object = None
    load_description: str = ""

    def validate(self):
        """Check every field before any work.

        Returns
        -------
        dict of str -> float or None
            The critical strain of every region of the mesh (None: never cracks).

        Raises
        ------
        ValueError
            Naming the first bad field (a non-positive load or increment, an unknown
            region, a bad critical strain, no region that can crack, a bad material).
            What ``apply_load`` adds is checked by :class:`Simulation` before any work.
        """
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Scene.name must be a non-empty string, got {self.name!r}")
        for key in ("load_max", "dx", "contact_tol"):
            v = getattr(self, key)
            low_ok = v >= 0 if key == "contact_tol" else v > 0
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not low_ok:
                raise ValueError(f"Scene {self.name!r}: {key} must be a finite number "
                                 f"{'>= 0' if key == 'contact_tol' else '> 0'}, got {v!r}")
        if not callable(self.apply_load):
            raise ValueError(f"Scene {self.name!r}: apply_load must be callable(problem, x)")
        regions = set(self.mesh.GetMaterials())
        crit = self.critical if isinstance(self.critical, dict) else {r: self.critical for r in regions}
        for region, c in crit.items():
            if region not in regions:
                raise ValueError(f"Scene {self.name!r}: critical strain given for region {region!r}, "
                                 f"which is not in the mesh; its regions are {sorted(regions)}")
            if c is not None and (isinstance(c, bool) or not isinstance(c, (int, float))
                                  or not math.isfinite(c) or c <= 0):
                raise ValueError(f"Scene {self.name!r}: critical strain of region {region!r} must be a "
                                 f"finite number > 0 (or None: never cracks), got {c!r}")
        if not any(c is not None for c in crit.values()):
            raise ValueError(f"Scene {self.name!r}: no region can crack (every critical strain is None)")
        if self.fix_free_modes not in (True, "all"):
            raise ValueError(f"Scene {self.name!r}: fix_free_modes must be True or 'all', got {self.fix_free_modes!r}")
        if not isinstance(self.material, (Material, dict)):
            raise ValueError(f"Scene {self.name!r}: material must be a Material or a dict of them")
        radii = self.radius.items() if isinstance(self.radius, dict) else [("all", self.radius)]
        for region, r in radii:
            if r is not None and (isinstance(r, bool) or not isinstance(r, (int, float))
                                  or not math.isfinite(r) or r <= 0):
                raise ValueError(f"Scene {self.name!r}: critical distance (radius) of region {region!r} "
                                 f"must be a finite number > 0 or None, got {r!r}")
        if self.strength is not None:
            s = np.asarray(self.strength)
            if s.shape != (self.mesh.nv,) or not np.issubdtype(s.dtype, np.floating) \
                    or not np.all(np.isfinite(s)) or not np.all(s > 0):
                raise ValueError(f"Scene {self.name!r}: strength must be {self.mesh.nv} finite floats > 0 "
                                 f"(one per vertex), got shape {s.shape}")
        return crit


@dataclass(init=False)
class StepControl:
    """Adaptive load increments (paper 4.2): cut on too many cracks or a failure, grow when quiet.

    Parameters
    ----------
    max_new_cracks : int
        Split vertices allowed in the first crack pass after an increment (paper: 2).
    cut : float
        dx is multiplied by this after too many cracks or a failed solve (0 < cut < 1).
    grow : float
        dx is multiplied by this after ``grow_after`` crack-free steps in a row (> 1).
    grow_after : int
    dx_min, dx_max : float or None
        Bounds of dx; default ``dx / 64`` and ``8 dx`` of the scene's first dx.
    max_steps : int
        Accepted steps at most.
    max_retries : int
        Failed attempts in a row before the run stops.
    max_relax_passes : int
        Crack passes at fixed load at most (a bound, not a tuning knob).
    method : {"modified", "full"}
        Newton variant (paper: modified, tangent factorised once per load step; kept for
        the next step while it contracts as well, see the module docstring). A step
        whose modified Newton solve fails is retried with full Newton first.
    tol : float
        Newton tolerance of eq. 7.
    maxit : int
        Newton iterations per solve.
    unloaded_fraction : float
        See Scene.stop_when_unloaded.
    split : {"spread", "all", "one"}
        Which overstrained vertices one crack pass splits: "all" (the paper's literal
        rule) or, by default, "spread": in decreasing order of overstrain, skipping the
        vertices next to one split earlier in the pass; they are judged again after the
        next equilibrium, which the split has changed, instead of on their strain from
        before it. "one": only the most overstrained vertex that splits anything, every
        other one judged again after the next equilibrium (one event at a time; more
        passes; docs/criterion.md); the default for a scene with a critical distance
        (``Scene.radius``) unless the scene's or the user's control sets it.

    **settings
        The fields above by name (keyword only); the others take their defaults. Only
        these count as set (``explicit``): a Simulation starts from the scene's
        ``control`` and overrides just those.

    Raises
    ------
    TypeError
        An unknown field name.
    """
    max_new_cracks: int = 2
    cut: float = 0.5
    grow: float = 1.5
    grow_after: int = 2
    dx_min: float = None
    dx_max: float = None
    max_steps: int = 200
    max_retries: int = 6
    max_relax_passes: int = 500
    method: str = "modified"
    tol: float = 1e-10
    maxit: int = 60
    unloaded_fraction: float = 1e-3
    split: str = "spread"

    def __init__(self, **settings):
        names = [f.name for f in fields(self)]
        unknown = sorted(set(settings) - set(names))
        if unknown:
            raise TypeError(f"StepControl got unknown option(s) {unknown}; the options are {names}")
        for f in fields(self):
            setattr(self, f.name, settings.get(f.name, f.default))
        #: the names given to the constructor: what overrides a scene's defaults
        self.explicit = frozenset(settings)

    def over(self, defaults):
        """This control laid over a scene's defaults: the fields set here win, the rest stay.

        Parameters
        ----------
        defaults : dict
            A scene's ``control`` (StepControl field -> value).

        Returns
        -------
        StepControl
            A new object; neither this one nor ``defaults`` is changed.
        """
        return StepControl(**{**defaults, **{k: getattr(self, k) for k in self.explicit}})

    def resolved(self, dx):
        """A checked copy with the default bounds of dx filled in from the first increment.

        Parameters
        ----------
        dx : float
            The scene's first increment.

        Returns
        -------
        StepControl
            A new object (this one is not changed), ``dx_min`` and ``dx_max`` set.

        Raises
        ------
        ValueError
            Naming the first field out of range.
        """
        settings = asdict(self)
        settings["dx_min"], settings["dx_max"] = self._dx_bounds(dx)
        control = StepControl(**settings)
        control.validate(dx)
        return control

    def _dx_bounds(self, dx):
        """(dx_min, dx_max): the set bounds, or the defaults dx / 64 and 8 dx."""
        return (self.dx_min if self.dx_min is not None else dx / 64,
                self.dx_max if self.dx_max is not None else 8 * dx)

    def validate(self, dx):
        """Check every field (the bounds of dx, if None, as :meth:`resolved` fills them in).

        Parameters
        ----------
        dx : float
            The scene's first increment.

        Raises
        ------
        ValueError
            Naming the first field out of range.
        """
        dx_min, dx_max = self._dx_bounds(dx)

        def number(v):
            return not isinstance(v, bool) and isinstance(v, numbers.Real) and math.isfinite(v)

        def integer(v):
            return not isinstance(v, bool) and isinstance(v, numbers.Integral)

        checks = [("max_new_cracks", integer(self.max_new_cracks) and self.max_new_cracks >= 0),
                  ("cut", number(self.cut) and 0 < self.cut < 1),
                  ("grow", number(self.grow) and self.grow >= 1),
                  ("grow_after", integer(self.grow_after) and self.grow_after >= 1),
                  ("dx_min", number(dx_min) and 0 < dx_min <= dx),
                  ("dx_max", number(dx_max) and dx_max >= dx),
                  ("max_steps", integer(self.max_steps) and self.max_steps >= 1),
                  ("max_retries", integer(self.max_retries) and self.max_retries >= 0),
                  ("max_relax_passes", integer(self.max_relax_passes) and self.max_relax_passes >= 1),
                  ("method", self.method in ("modified", "full")),
                  ("tol", number(self.tol) and 0 < self.tol < 1),
                  ("maxit", integer(self.maxit) and self.maxit >= 1),
                  ("unloaded_fraction", number(self.unloaded_fraction) and 0 < self.unloaded_fraction < 1),
                  ("split", self.split in ("spread", "all", "one"))]
        for name, ok in checks:
            if not ok:
                raise ValueError(f"StepControl.{name} = {getattr(self, name)!r} is out of range")


class StepFailed(Exception):
    """A solve inside a step failed.

    Parameters
    ----------
    reason : str
        The solver's reason (nan, diverged, inverted_element, singular, active_set,
        penetration, ...).
    phase : {"increment", "relaxation"}
        The solve of the increment, or one at fixed load after a split.
    message : str
    from_kept : bool
        The increment solve started from the tangent kept from the step before.
    """

    def __init__(self, reason, phase, message, from_kept=False):
        super().__init__(f"{reason} ({phase}): {message}")
        self.reason, self.phase, self.message, self.from_kept = reason, phase, message, from_kept


@dataclass
class State:
    """An accepted state: everything a resume needs.

    Parameters
    ----------
    arrays : MeshArrays
        The mesh.
    u : numpy.ndarray
        The P1 displacement vector in VectorH1 layout.
    x, dx : float
        The load parameter and the next increment.
    step, quiet : int
        Steps accepted, and crack-free steps in a row.
    work : float
        External work so far.
    reactions, fixed_values, fixed_dofs : numpy.ndarray
        Reactions, prescribed values and numbers of the fixed dofs, for the work of the
        next increment.
    peak_energy : float
        Largest elastic energy so far.
    history : list of dict
        One record per accepted step.
    strength : numpy.ndarray or None
        Critical strain per vertex (None: the regions' uniform ones).
    contact_keys : list of tuple
        Keys of the active contact rows at this state: the first contact solve of the next
        step starts from them (ContactSolver.solve, ``warm``).
    tangent_state : numpy.ndarray or None
        The displacement the factorised tangent kept for the next step was assembled at
        (None: the next step factorises its own).
    tangent : solver.SavedTangent or None
        That factorisation, if this process made it (not in checkpoints: a resumed run
        makes it again from ``tangent_state``).
    """
    arrays: MeshArrays
    u: np.ndarray            # P1 displacement vector, VectorH1 layout
    x: float
    dx: float
    step: int
    quiet: int               # crack-free steps in a row
    work: float              # external work so far
    reactions: np.ndarray    # reaction at the fixed dofs, for the work of the next step
    fixed_values: np.ndarray
    fixed_dofs: np.ndarray
    peak_energy: float
    history: list            # one dict per accepted step
    strength: np.ndarray = None
    contact_keys: list = field(default_factory=list)
    tangent_state: np.ndarray = None
    tangent: object = field(default=None, repr=False, compare=False)


def round_trip(mesh):
    """The mesh through its checkpoint representation (arrays and back).

    Parameters
    ----------
    mesh : ngsolve.Mesh

    Returns
    -------
    (MeshArrays, ngsolve.Mesh)
        The arrays and the mesh rebuilt from them, as a resumed run rebuilds it.
    """
    arrays = mesh_to_arrays(mesh)
    return arrays, mesh_from_arrays(arrays)


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
        "auto": contact from the first crack on (or from the start for separate bodies);
        "never": no contact rows at all (faster where pieces only separate; the summary's
        ``max_overlap_area`` still measures any overlap).

    Raises
    ------
    ValueError
        A bad scene, step control or option, before any work.
    FileExistsError
        ``out`` holds results and neither ``force`` nor ``resume`` is given.
    checkpoint.CheckpointError
        ``resume`` with a damaged, foreign or mismatching checkpoint.
    """

    def __init__(self, scene, control=None, out=None, force=False, resume=False, pictures="final",
                 checkpoint_every=1, progress=None, contact="auto"):
        self.scene = scene
        self.critical = scene.validate()
        # the user's control overrides only the fields it sets; neither object is changed
        user = control if control is not None else StepControl()
        control = user.over(scene.control)
        if scene.radius is not None and "split" not in control.explicit:
            # cracks judged at a critical distance grow one event at a time (docs/criterion.md)
            control = control.over({"split": "one"})
        self.control = control.resolved(scene.dx)
        self._method = self.control.method      # the Newton variant of the current attempt
        if pictures not in ("final", "every", "none"):
            raise ValueError(f"pictures must be 'final', 'every' or 'none', got {pictures!r}")
        if contact not in ("auto", "never"):
            raise ValueError(f"contact must be 'auto' or 'never', got {contact!r}")
        self.contact = contact
        if force and resume:
            raise ValueError("force and resume exclude each other")
        if isinstance(checkpoint_every, bool) or not isinstance(checkpoint_every, int) or checkpoint_every < 1:
            raise ValueError(f"checkpoint_every must be an integer >= 1, got {checkpoint_every!r}")
        self.out = Path(out) if out is not None else None
        self.force, self.resume, self.pictures = force, resume, pictures
        self.checkpoint_every = checkpoint_every
        self.progress = progress
        self.timings = dict.fromkeys(PHASES, 0.0)
        self.writer = None
        self._resumed_state = None
        #: wall seconds of the run before a resume (from the checkpoint): summaries cover it all
        self._wall_before = 0.0
        #: math.fsum of the triangle areas; splitting keeps every triangle and coordinate,
        #: so the final area must equal it to the last bit
        self.area_initial = FragmentStatistics(scene.mesh).total_area
        self._check_load()              # before the output folder is touched
        if self.out is not None:
            self._prepare_output()

    def _check_load(self):
        """Build the problem at x = 0, at the first increment and at the final load: the scene's materials,
        regions and the boundaries its ``apply_load`` names are checked before any work.

        Raises
        ------
        ValueError
            Naming the scene, the load and what was wrong.
        """
        for x in (0.0, float(self.scene.dx), float(self.scene.load_max)):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")   # mesh quality: the run's own problems warn
                    prob = ElasticProblem(self.scene.mesh, self.scene.material, order=1)
                self.scene.apply_load(prob, x)
                prob.assemble_constraints()
            except Exception as exc:
                raise ValueError(f"Scene {self.scene.name!r}: the problem at load x = {x:g} cannot be "
                                 f"built: {type(exc).__name__}: {exc}") from exc

    # -- output folder ---------------------------------------------------------------------
    OWN_PATTERNS = ("step_*.vtu", "cracks_*.vtp", "results.pvd", "cracks.pvd", "checkpoint_*.npz",
                    "summary.json", "final.png", "step_*.png", "fragment_sizes.png",
                    ".checkpoint_*.tmp", ".tmp_ngf_*")

    @classmethod
    def check_output(cls, out, force=False, resume=False, option_names=("force", "resume")):
        """Refuse an output folder before any work; returns the files of ours in it.

        Parameters
        ----------
        out : path
            The output folder (need not exist).
        force, resume : bool
            As for :class:`Simulation`.
        option_names : (str, str)
            How the refusal names the two options (the CLI passes "--force", "--resume").

        Returns
        -------
        list of pathlib.Path
            The files in ``out`` that ngfracture writes (what ``force`` removes).

        Raises
        ------
        FileExistsError
            ``out`` is not a folder, or holds results and neither force nor resume is given.
        checkpoint.CheckpointError
            ``resume`` and ``out`` has no checkpoint.
        """
        out = Path(out)
        if out.exists() and not out.is_dir():
            raise FileExistsError(f"output folder {out} exists and is not a folder")
        own = sorted({p for pat in cls.OWN_PATTERNS for p in out.glob(pat)}) if out.exists() else []
        if resume and not checkpoint.list_checkpoints(out):
            raise checkpoint.CheckpointError(f"{out}: no checkpoint to resume from")
        if own and not (force or resume):
            raise FileExistsError(f"output folder {out} already holds results ({own[0].name}, ...); "
                                  f"use {option_names[0]} to replace them or {option_names[1]} to continue")
        return own

    def _prepare_output(self):
        from ..output.vtk import TimeSeriesWriter
        own = self.check_output(self.out, self.force, self.resume)
        if self.resume:
            arrays, header = checkpoint.latest(self.out)
            self._resumed_state = self._state_from_checkpoint(arrays, header)
            self.writer = TimeSeriesWriter(self.out, resume=True, last_step=self._resumed_state.step)
            for p in self.out.glob("step_*.png"):   # pictures of steps after the checkpoint
                if int(p.stem.split("_")[1]) > self._resumed_state.step:
                    p.unlink()
            for p in self.out.glob(".checkpoint_*.tmp"):   # a checkpoint write that was killed
                p.unlink()
            return
        self.out.mkdir(parents=True, exist_ok=True)
        for p in own:
            p.unlink()
        self.writer = TimeSeriesWriter(self.out)

    # -- the physics of one configuration ------------------------------------------------------
    def _problem(self, mesh, x, u=None, check_mesh=True, triangle_piece=None):
        t0 = time.perf_counter()
        prob = ElasticProblem(mesh, self.scene.material, order=1, check_mesh=check_mesh,
                              triangle_piece=triangle_piece)
        self.scene.apply_load(prob, x)
        if u is not None:
            prob.u.vec.FV().NumPy()[:] = u
        self.timings["rebuild"] += time.perf_counter() - t0
        return prob

    def _needs_contact(self, mesh):
        if self.contact == "never":
            return False
        return self.scene.contact or "crack" in mesh.GetBoundaries()

    def _equilibrium(self, prob, phase, substeps=1, warm=(), lineage=None, start=None):
        """Solve in ``substeps`` load steps; returns (the keys of the active contact rows,
        the solver.SavedTangent the solve ended with).

        ``warm``: the active contact keys of the solve before (ContactSolver.solve).
        ``lineage``: the mesh was split from a solved one (split_factor.py).
        ``start``: a factorised tangent of this mesh to start from (State.tangent).
        Raises StepFailed(reason, phase) if the solve does not converge.
        """
        c = self.control
        options = dict(method=self._method, tol=c.tol, maxit=c.maxit, load_steps=substeps)
        if self._needs_contact(prob.mesh):
            solver = ContactSolver(prob, tol=self.scene.contact_tol,   # its tol: detection threshold
                                   fix_free_modes=self.scene.fix_free_modes)
            solver.options.update(options)                              # Newton's tol, method, maxit
            result = solver.solve(warm=warm, lineage=lineage, start=start)
            self.timings["solve"] += result.timings["solve"]
            self.timings["contact"] += result.timings["contact"] - result.timings.get("collision", 0.0)
            self.timings["collision"] += result.timings.get("collision", 0.0)
            self.timings["linear"] += result.timings.get("linear", 0.0)
            self.timings["assembly"] += result.timings.get("assembly", 0.0)
            status = result.status
            self._iterations += status.iterations
            self._notes.extend(n for n in result.notes if n not in self._notes)
            if not result.converged:
                if result.reason == "penetration":
                    message = (f"contact rows still penetrate by {result.max_penetration:.3g} after "
                               f"{result.updates} re-linearisations")
                elif result.reason == "active_set":
                    message = f"contact active set did not settle in {result.rounds} rounds"
                else:
                    message = status.message
                raise StepFailed(result.reason, phase, message)
            return result.active_keys, result.tangent
        t0 = time.perf_counter()
        tangent = start.kept() if start is not None else SavedTangent(lineage)
        status = prob.solve(fix_free_modes=self.scene.fix_free_modes, tangent=tangent, **options)
        self.timings["solve"] += time.perf_counter() - t0
        for part, seconds in status.phase_seconds().items():
            self.timings[part] += seconds
        self._iterations += status.iterations
        self._notes.extend(n for n in status.notes if n not in self._notes)
        if not status.converged:
            raise StepFailed(status.reason, phase, status.message)
        return [], tangent

    def _normalised_strain(self, prob, strength=None):
        """Vertex strain tensors divided by the vertex's critical strain (0: cannot crack).

        ``strength`` (per vertex) replaces the regions' critical strains where they crack.
        """
        t0 = time.perf_counter()
        mesh = prob.mesh
        arrays = prob.arrays
        names = arrays.region_names
        inv = np.array([0.0] + [1.0 / self.critical[n] if self.critical.get(n) is not None else 0.0
                                for n in names])
        # a vertex takes the smallest critical strain of its triangles (the weakest material)
        scale = np.zeros(mesh.nv)
        np.maximum.at(scale, arrays.triangles.ravel(), np.repeat(inv[arrays.regions], 3))
        if self.scene.radius is None:
            if strength is not None:
                scale = np.where(scale > 0, 1.0 / strength, 0.0)
            tensors = StrainCriterion(1.0).vertex_tensor(mesh, prob.u) * scale[:, None]
        else:
            # stress / (E critical) per triangle, judged at the critical distance
            strain = equivalent_strain(mesh, element_strain(mesh, prob.u), self.scene.material)
            radii = self.scene.radius if isinstance(self.scene.radius, dict) else dict.fromkeys(names, self.scene.radius)
            r_region = np.array([0.0] + [radii.get(n) or 0.0 for n in names])
            radius = np.zeros(mesh.nv)
            np.maximum.at(radius, arrays.triangles.ravel(), np.repeat(r_region[arrays.regions], 3))
            tensors = nonlocal_opening(mesh, strain * inv[arrays.regions][:, None], radius * (scale > 0))
            if strength is not None:
                # the vertex's random strength replaces its region's critical strain
                tensors *= np.where(scale > 0, 1.0 / (strength * np.where(scale > 0, scale, 1.0)), 0.0)[:, None]
        self.timings["strain"] += time.perf_counter() - t0
        return tensors

    def _crack_pass(self, prob, strength=None, tangent=None):
        """One splitting pass; returns (new problem or None, number of split vertices, strength,
        the new mesh's split_factor.Lineage from ``tangent``, the last solve's, or None)."""
        tensors = self._normalised_strain(prob, strength)
        t0 = time.perf_counter()
        # cracks judged at a critical distance grow from their tips (docs/criterion.md)
        rules = PAPER_RULES if self.scene.radius is None else GROWTH_RULES
        res = split_by_tensor(prob.mesh, tensors, 1.0, skip_neighbours=self.control.split == "spread",
                              first_only=self.control.split == "one", rules=rules,
                              check_mesh=False)   # checked when made, or split from a checked mesh
        self.timings["split"] += time.perf_counter() - t0 - sum(res.timings.get(k, 0.0) for k in ("netgen", "ngsolve_mesh"))
        self.timings["rebuild"] += res.timings.get("netgen", 0.0) + res.timings.get("ngsolve_mesh", 0.0)
        if res.nsplit == 0:
            return None, 0, strength, None
        self._split_positions.append(res.record["position"][np.diff(res.record["new_offsets"]) > 0])
        # P1: the displacement is a vertex field (component-major), copied through the split
        u = transfer_vertex_field(prob.u.vec.FV().NumPy().reshape(2, -1).T, res).T.reshape(-1)
        if strength is not None:
            strength = transfer_vertex_field(strength, res)    # copies inherit the vertex's strength
        inherited = split_factor.lineage(tangent.factor, tangent.state, res.parent) if tangent is not None else None
        # the engine split a checked mesh and keeps it valid
        return (self._problem(res.mesh, self._x_try, u, check_mesh=False, triangle_piece=res.fragment),
                res.nsplit, strength, inherited)

    # -- one load step ----------------------------------------------------------------------------
    def _attempt(self, state, dx, substeps=1, keep=True):
        """Try the step x + dx from an accepted state; returns (problem, first-pass cracks, total cracks,
        vertex strength, active contact keys, the solver.SavedTangent of the last solve).

        ``keep``: start from the tangent the state keeps (if any, modified Newton).
        Raises StepFailed on a failed solve and returns None for too many cracks.
        """
        self._x_try = state.x + dx
        self._split_positions = []      # per pass: reference positions of the vertices split
        prob = self._problem(self._mesh, self._x_try, state.u)
        start = self._kept_tangent(state, prob) if keep and self._method == "modified" else None
        try:
            keys, tangent = self._equilibrium(prob, "increment", substeps, warm=state.contact_keys, start=start)
        except StepFailed as err:
            err.from_kept = start is not None
            raise
        self._dwork = self._increment_work(state, prob)
        new_prob, first, strength, inherited = self._crack_pass(prob, state.strength, tangent)
        c = self.control
        if first > c.max_new_cracks and dx * c.cut >= c.dx_min:
            return None
        total, passes = first, 0
        while new_prob is not None:
            passes += 1
            if passes > c.max_relax_passes:
                raise StepFailed("relaxation", "relaxation", f"cracks still grow after {c.max_relax_passes} passes at fixed load")
            prob = new_prob
            keys, tangent = self._equilibrium(prob, "relaxation", warm=keys, lineage=inherited)
            if (self.scene.stop_when_unloaded and prob.fragments()[0] > 1
                    and self._cut_through(prob.arrays, prob.mesh, prob.assemble_constraints())):
                break     # the run ends with this step: no crack in the separated pieces
            new_prob, n, strength, inherited = self._crack_pass(prob, strength, tangent)
            total += n
        return prob, first, total, strength, keys, tangent

    def _kept_tangent(self, state, prob):
        """The factorised tangent the state keeps for ``prob`` (its mesh), or None.

        None also where the increment fixes other dofs than the tangent was factorised for
        (the solve would not use it). A resumed run factorises it again at the displacement
        it was assembled at, once per state.
        """
        if state.tangent_state is None:
            return None
        rows = prob.assemble_constraints()
        if not np.array_equal(rows.fixed_dofs, state.fixed_dofs):
            return None
        if state.tangent is None:
            t0 = time.perf_counter()
            try:
                state.tangent = SavedTangent.assembled_at(prob, state.tangent_state, rows)
            except SingularSystem as err:
                raise StepFailed("singular", "increment", f"the kept tangent: {err}", from_kept=True) from None
            finally:
                for phase in ("solve", "linear"):
                    self.timings[phase] += time.perf_counter() - t0
        return state.tangent

    def _tangent_to_keep(self, tangent, fixed_dofs):
        """What the accepted state keeps of the last solve's tangent (see the module
        docstring); ``fixed_dofs``: the accepted state's, which a kept tangent was factorised
        for (a resumed run factorises it again for them)."""
        factor = tangent.factor if tangent is not None else None
        if (self._method != "modified" or not isinstance(factor, EliminatedFactor) or factor.linear_solver != "direct"
                or tangent.state is None or tangent.contraction is None
                or tangent.contraction > KEEP_MAX_CONTRACTION
                or np.count_nonzero(factor.factor_free) < KEEP_MIN_DOFS
                or not np.array_equal(tangent.fixed_dofs, fixed_dofs)):
            return None
        return tangent.kept()

    @staticmethod
    def _increment_work(state, prob):
        """Work of the reactions over the increment just solved (trapezoid rule).

        The increment is solved on the mesh of the accepted state, so its fixed dofs have
        the numbers they had there (cracks come later, at fixed load: they do no work).
        """
        rows = prob.assemble_constraints()
        pos = np.searchsorted(rows.fixed_dofs, state.fixed_dofs)
        pos = np.minimum(pos, max(len(rows.fixed_dofs) - 1, 0))
        same = (rows.fixed_dofs[pos] == state.fixed_dofs) if len(rows.fixed_dofs) else np.zeros(0, bool)
        r_new = -prob.out_of_balance()[rows.fixed_dofs[pos[same]]]
        dg = rows.fixed_values[pos[same]] - state.fixed_values[same]
        return float(0.5 * np.dot(state.reactions[same] + r_new, dg))

    def _accept(self, state, dx, prob, first, total, strength, contact_keys, tangent):
        arrays, mesh = round_trip(prob.mesh)
        u = prob.u.vec.FV().NumPy().copy()
        # the solve ended at u (kept by the problem, no assembly); the round trip keeps the dof numbers
        out_of_balance = prob.out_of_balance()
        prob = self._problem(mesh, self._x_try, u)   # the state as a resume would see it
        rows = prob.assemble_constraints()
        reactions = -out_of_balance[rows.fixed_dofs]   # for the work of the next increment
        dwork = self._dwork
        energy = float(prob.energy())
        stats = FragmentStatistics(mesh)
        crack_len = crack_length(arrays)
        # a step that cracked keeps its (possibly cut) increment; quiet steps may grow it
        quiet = state.quiet + 1 if total == 0 else 0
        new_dx = dx
        if quiet >= self.control.grow_after:
            new_dx, quiet = min(dx * self.control.grow, self.control.dx_max), 0
        record = {"step": state.step + 1, "x": self._x_try, "dx": dx, "new_cracks_first_pass": int(first),
                  "split_vertices": int(total), "elastic_energy": energy, "external_work": state.work + dwork,
                  "released_energy": state.work + dwork - energy, "crack_length": crack_len,
                  "fragments": int(stats.count), "newton_iterations": int(self._iterations),
                  "retries": int(self._retries), "failures": list(self._failures),
                  "substeps": int(self._substeps), "method": self._method, "relax_passes": max(len(self._split_positions) - 1, 0),
                  "notes": list(self._notes)}
        if first and not any(h["split_vertices"] for h in state.history):
            # where cracking began: the vertices split by the first pass that split any
            record["initiation"] = self._split_positions[0].tolist()
        new = State(arrays=arrays, u=u, x=self._x_try, dx=new_dx, step=state.step + 1, quiet=quiet,
                    work=state.work + dwork, reactions=reactions, fixed_values=rows.fixed_values.copy(),
                    fixed_dofs=rows.fixed_dofs.copy(), peak_energy=max(state.peak_energy, energy),
                    history=state.history + [record], strength=strength, contact_keys=contact_keys)
        kept = self._tangent_to_keep(tangent, new.fixed_dofs)
        if kept is not None:
            new.tangent_state, new.tangent = kept.state, kept
        return new, prob, mesh, stats

    # -- the run ----------------------------------------------------------------------------------
    def _initial_state(self):
        arrays, mesh = round_trip(self.scene.mesh)
        prob = self._problem(mesh, 0.0)
        rows = prob.assemble_constraints()
        return State(arrays=arrays, u=np.zeros(prob.fes.ndof), x=0.0, dx=float(self.scene.dx), step=0,
                     quiet=0, work=0.0, reactions=np.zeros(len(rows.fixed_dofs)),
                     fixed_values=rows.fixed_values.copy(), fixed_dofs=rows.fixed_dofs.copy(),
                     peak_energy=0.0, history=[],
                     strength=None if self.scene.strength is None else np.array(self.scene.strength, dtype=float))

    def _step(self, state, dx):
        """Attempts of one step until one is accepted: (attempt, dx, None) or (None, dx, last failure).

        Too many cracks: dx * cut. A failed increment solve that started from the tangent the
        state keeps: the same attempt with a tangent of its own (recorded in the notes). A
        failed solve with modified Newton: the same attempt with full Newton (from then on
        for this step). A failed solve of the increment: the same target in twice
        as many substeps (load steps of the Newton solver, no crack pass between them), so
        a passing trouble does not change the load path. A failed solve at fixed load
        (relaxation on a split mesh): dx * cut, substeps reset. Every attempt starts from
        the saved state: nothing of a failed attempt is kept.
        """
        c = self.control
        self._retries, self._failures, substeps = 0, [], 1
        self._method = c.method
        keep = True
        notes = []
        while True:
            self._iterations, self._notes = 0, list(notes)
            try:
                attempt = self._attempt(state, dx, substeps, keep)
            except StepFailed as err:
                self._retries += 1
                self._failures.append(err.reason)
                if err.from_kept:
                    # the same attempt with its own tangent, not counted against max_retries
                    keep = False
                    notes.append(f"the tangent kept from the step before failed ({err.reason}); "
                                 "the step factorised its own")
                    continue
                if self._retries - (not keep) > c.max_retries:
                    return None, dx, err
                if self._method == "modified":
                    self._method = "full"           # the same attempt with fresh tangents
                elif err.phase == "increment":
                    substeps *= 2
                elif dx * c.cut >= c.dx_min:
                    dx, substeps = dx * c.cut, 1
                else:
                    return None, dx, err
                continue
            if attempt is None:            # too many cracks at once: smaller increment
                dx *= c.cut
                continue
            self._substeps = substeps
            return attempt, dx, None

    @single_threaded_blas()
    def run(self):
        """Run to the end.

        Returns
        -------
        RunResult
            ``ok``, ``reason``, ``message``, the ``summary`` (also in summary.json), the
            last accepted problem and state. A failed run is a result with ``ok`` False,
            not an exception; the last good state is written.
        """
        t_start = time.perf_counter() - self._wall_before   # a resumed run counts the earlier part
        if self._resumed_state is not None:
            state = self._resumed_state
            self._mesh = mesh_from_arrays(state.arrays)
        else:
            state = self._initial_state()
            self._mesh = mesh_from_arrays(state.arrays)
            if self.writer is not None:
                self._write_step(state, self._problem(self._mesh, 0.0, state.u), FragmentStatistics(self._mesh))
                self._checkpoint(state, time.perf_counter() - t_start)
        area_initial = self.area_initial
        reason, message = "load_max", "reached the final load"
        c = self.control
        prob, stats = None, None
        while True:
            if state.x >= self.scene.load_max * (1 - 1e-12):
                break
            if state.step >= c.max_steps:
                reason, message = "max_steps", f"stopped after {c.max_steps} steps"
                break
            broken = self._broken(state) if self.scene.stop_when_unloaded and state.history else ""
            if broken:
                reason, message = "broken", broken
                break
            remaining = self.scene.load_max - state.x
            # no sliver of a last step: a remainder below dx_min joins this one
            dx = remaining if remaining - state.dx < c.dx_min else state.dx
            attempt, dx, failure = self._step(state, dx)
            if attempt is None:
                reason = "failed"
                message = (f"step {state.step + 1} at x = {state.x + dx:.6g} failed {self._retries} time(s); "
                           f"last reason {failure.reason}: {failure.message}")
                break
            state, prob, self._mesh, stats = self._accept(state, dx, *attempt)
            if self.writer is not None:
                self._write_step(state, prob, stats)
                if state.step % self.checkpoint_every == 0:
                    self._checkpoint(state, time.perf_counter() - t_start)
            if self.progress is not None:
                self.progress({"step": state.step, "x": state.x, "load_max": self.scene.load_max,
                               "split_vertices": sum(h["split_vertices"] for h in state.history),
                               "fragments": state.history[-1]["fragments"], "seconds": time.perf_counter() - t_start})
        if prob is None:
            prob = self._problem(self._mesh, state.x, state.u)
            stats = FragmentStatistics(self._mesh)
        if self.writer is not None and state.step % self.checkpoint_every != 0:
            self._checkpoint(state, time.perf_counter() - t_start)
        summary = self._summary(state, prob, stats, area_initial, reason, message,
                                time.perf_counter() - t_start)
        if self.out is not None:
            self._final_outputs(state, prob, stats, summary)
        return RunResult(ok=reason in ("load_max", "max_steps", "broken"), reason=reason, message=message,
                         summary=summary, problem=prob, state=state)

    def _broken(self, state):
        """Why the accepted state is broken through (Scene.stop_when_unloaded), or ""."""
        last = state.history[-1]
        if last["fragments"] > 1 and self._cut_through(state.arrays, self._mesh, state):
            return "the body is broken through (no fragment connects boundaries the load moves apart)"
        if last["crack_length"] > 0 and last["elastic_energy"] < self.control.unloaded_fraction * state.peak_energy:
            return "the body is broken through (elastic energy released)"
        return ""

    def _cut_through(self, arrays, mesh, loaded):
        """True when no fragment of the mesh connects boundaries the load moves apart.

        ``arrays``: the mesh's arrays; ``loaded``: the fixed dofs and values at the load
        (constraint rows or a State).
        """
        # the prescribed values at x against those at 0, on this mesh
        unloaded = self._problem(mesh, 0.0).assemble_constraints()
        dofs, increment = prescribed_increment(unloaded.fixed_dofs, unloaded.fixed_values,
                                               loaded.fixed_dofs, loaded.fixed_values)
        return load_path_cut(arrays.points, arrays.triangles, dofs, increment)

    def _summary(self, state, prob, stats, area_initial, reason, message, wall):
        hist = state.history
        overlap = fragment_overlap_area(prob) if stats.count > 1 or self.scene.contact else 0.0
        return {
            "scene": self.scene.name, "parameters": self.scene.parameters,
            "load_description": self.scene.load_description,
            "control": {k: v for k, v in asdict(self.control).items()},
            "reason": reason, "message": message,
            "n_steps": state.step, "load": state.x,
            "n_split_vertices": int(sum(h["split_vertices"] for h in hist)),
            "crack_length": crack_length(state.arrays),
            "n_fragments": int(stats.count), "fragment_areas": stats.areas.tolist(),
            "area_initial": area_initial, "area_final": stats.total_area,
            "max_overlap_area": overlap,
            "n_vertices": int(prob.mesh.nv), "n_triangles": int(prob.mesh.ne),
            "crack_initiation": next((h["initiation"] for h in hist if "initiation" in h), []),
            "energy": [{k: h[k] for k in ("step", "x", "elastic_energy", "external_work", "released_energy")}
                       for h in hist],
            "newton_iterations": [h["newton_iterations"] for h in hist],
            # departures from the plain path of the solvers (see ContactResult.notes)
            "notes": [{"step": h["step"], "note": n} for h in hist for n in h.get("notes", [])],
            "history": hist,
            "timings": {**{k: round(v, 6) for k, v in self.timings.items()}, "wall": round(wall, 6)},
        }

    # -- files ---------------------------------------------------------------------------------------
    def _write_step(self, state, prob, stats):
        t0 = time.perf_counter()
        self.writer.write(state.step, state.x, prob.mesh, prob.u, stats.fragment)
        if self.pictures == "every":
            from ..output.vtk import picture_scale, render_png
            render_png(prob.mesh, prob.u, stats.fragment, self.out / f"step_{state.step:06d}.png",
                       scale=picture_scale(state.arrays.points, state.u))
        self.timings["output"] += time.perf_counter() - t0

    def _checkpoint(self, state, wall):
        t0 = time.perf_counter()
        arrays = {**state.arrays.as_dict(), "u": state.u, "reactions": state.reactions,
                  "fixed_values": state.fixed_values, "fixed_dofs": state.fixed_dofs}
        if state.strength is not None:
            arrays["strength"] = state.strength
        if state.tangent_state is not None:
            arrays["tangent_state"] = state.tangent_state
        meta = {"scene": self.scene.name, "parameters": self.scene.parameters,
                "x": state.x, "dx": state.dx, "step": state.step, "quiet": state.quiet, "work": state.work,
                "peak_energy": state.peak_energy, "history": state.history,
                "contact_keys": [list(k) for k in state.contact_keys],
                "area_initial": self.area_initial,
                "control": self._path_options(),
                "timings": {**self.timings, "wall": wall}}
        checkpoint.write(self.out, state.step, arrays, meta)
        self.timings["output"] += time.perf_counter() - t0

    def _state_from_checkpoint(self, arrays, header):
        meta = header.get("meta", header)
        if meta.get("scene") != self.scene.name or meta.get("parameters") != _jsonish(self.scene.parameters):
            raise checkpoint.CheckpointError(
                f"{self.out}: the checkpoint is of scene {meta.get('scene')!r} with parameters "
                f"{meta.get('parameters')!r}, not {self.scene.name!r} with {self.scene.parameters!r}")
        saved, now = meta.get("control"), _jsonish(self._path_options())
        if saved is not None and saved != now:
            name = next(k for k in sorted(set(saved) | set(now)) if saved.get(k) != now.get(k))
            raise checkpoint.CheckpointError(
                f"{self.out}: the checkpoint was written with {name} = {saved.get(name)!r}, this run has "
                f"{now.get(name)!r}; resume with the options of the interrupted run (only max_steps may differ)")
        self.area_initial = meta["area_initial"]
        timings = dict(meta.get("timings", {}))
        self._wall_before = float(timings.pop("wall", 0.0))
        self.timings.update(timings)
        return State(arrays=MeshArrays.from_dict(arrays), u=arrays["u"], x=meta["x"], dx=meta["dx"],
                     step=meta["step"], quiet=meta["quiet"], work=meta["work"], reactions=arrays["reactions"],
                     fixed_values=arrays["fixed_values"], fixed_dofs=arrays["fixed_dofs"],
                     peak_energy=meta["peak_energy"], history=meta["history"], strength=arrays.get("strength"),
                     contact_keys=[tuple(k) for k in meta.get("contact_keys", [])],
                     tangent_state=arrays.get("tangent_state"))

    def _path_options(self):
        """The options that decide the load path: a resumed run must have the same ones.

        ``max_steps`` only says where to stop (a run may be resumed to go further);
        pictures and the checkpoint interval do not touch the result.
        """
        return {**{k: v for k, v in asdict(self.control).items() if k != "max_steps"}, "contact": self.contact}

    def _final_outputs(self, state, prob, stats, summary):
        from ..output.vtk import final_pictures, picture_scale, write_summary
        t0 = time.perf_counter()
        pictures = {}
        if self.pictures != "none":     # ours: a resumed run redraws them
            pictures = final_pictures(self.out, prob.mesh, prob.u, stats,
                                      picture_scale(state.arrays.points, state.u))
        seconds = time.perf_counter() - t0
        self.timings["output"] += seconds
        summary["timings"]["output"] = round(self.timings["output"], 6)
        summary["timings"]["wall"] = round(summary["timings"]["wall"] + seconds, 6)   # the pictures too
        summary["pictures"] = pictures
        write_summary(self.out / "summary.json", summary, force=True)


def _jsonish(obj):
    """obj as it comes back from a JSON round trip (tuples -> lists)."""
    import json
    return json.loads(json.dumps(obj))


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


def crack_length(arrays):
    """Length of the crack in the reference configuration: half the crack-face length.

    Parameters
    ----------
    arrays : MeshArrays
        A mesh whose crack faces are the boundary segments named ``crack``.

    Returns
    -------
    float
    """
    if "crack" not in arrays.bc_names:
        return 0.0
    segs = arrays.boundary_segments("crack")
    if len(segs) == 0:
        return 0.0
    d = arrays.points[segs[:, 0]] - arrays.points[segs[:, 1]]
    return 0.5 * math.fsum(np.hypot(d[:, 0], d[:, 1]))
