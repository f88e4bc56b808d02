"""One load step, from an accepted state (mesh, displacement, load parameter x).

    1. x_try = x + dx; solve at x_try (modified Newton; contact once there are cracks
       or separate bodies; free fragments held on their rigid modes);
    2. find the overstrained vertices and split them (one crack pass);
       if the pass split more than ``max_new_cracks`` vertices and dx can still be
       cut: go back to the saved state and retry with dx * cut;
    3. relax at fixed x_try: solve on the split mesh, split again, until a pass
       splits nothing (the energy release through crack formation);
    4. accept: the new state and its history record; after ``grow_after`` steps in a
       row without a crack, dx = min(dx * grow, dx_max).

Each stage returns a record (:mod:`ngfracture.run.records`); a failed solve raises
``StepFailed`` and sends the step back to the saved state: an increment solve that started
from the tangent kept from the step before is made again with a tangent of its own; the
other retries follow :mod:`ngfracture.run.retries` (full Newton, more Newton load steps,
dx * cut) until ``max_retries``.

Where the paper is vague:

* A "crack" in the step-control rule is a split vertex (a new crack-face node) of the
  first pass after the increment; cracks that run at fixed load during relaxation
  are the physical answer to that load and are not limited.
* External work is the trapezoidal sum of reaction forces times the increments of
  the prescribed displacements; relaxation at fixed load does no work, so
  work - elastic energy is the energy released by cracking.
"""
import time
import traceback

import numpy as np

from ..contact.setup3d import MeshSetups
from ..contact.solver import ContactSolver
from ..fracture.crack_graph import crack_graph, tip_advances, tip_sizes
from ..fracture.fragments import FragmentStatistics
from ..fracture.split import AIMED_GROWTH_RULES, GROWTH_RULES, PAPER_RULES, split_by_tensor, transfer_vertex_field
from ..fracture.strain import principal
from ..linalg import bordered
from ..mechanics.tangent import SavedTangent
from ..mechanics.problem import ElasticProblem
from ..mechanics.resultants import boundary_resultants, load_vector, reaction_work, work_of_forces
from .loadpath import load_path_cut, prescribed_increment
from .invariants import check_state, depth_limit_3d, penetration_depth_3d
from .records import (AcceptedStep, Attempt, CrackPass, Equilibrium, StepFailed, StepLog, StepOutcome, TooManyCracks,
                      merged_notes)
from .solid_pass import solid_crack_pass
from .state import State, crack_extent, round_trip
from . import tangents
from .growth import critical_event, relax
from .refinement import refine_equilibrium, refine_initial
from .retries import next_retry, rescued

__all__ = ["LoadStep", "UNHELD_NOTE"]

#: the note of a 3D step whose pieces overlap in a run without contact rows (LoadStep.check)
UNHELD_NOTE = ("pieces overlap: the scene solves without contact rows (Scene.contact is False), and the "
               "step's deepest vertex in another piece is its overlap")


class LoadStep:
    """The stages of a load step for one scene, criterion and step control.

    Holds only its configuration, and the cache of the 3D contact set-up of the last mesh
    solved (``contact_setups``, :class:`~ngfracture.contact.setup3d.MeshSetups`: a load
    step on the same mesh reuses it; results do not depend on it); every stage takes what
    it works on as arguments and returns a record.

    Parameters
    ----------
    scene : Scene
    control : StepControl
        Resolved (``StepControl.resolved``).
    criterion : Criterion
        The scene's crack criterion.
    contact : {"auto", "never"}
        See :class:`ngfracture.run.simulation.Simulation`.
    area_initial : float
        ``math.fsum`` of the scene's reference triangle areas (the area invariant).
    dead_loads : bool
        The scene loads by tractions, body forces or pressures (force control), not only by
        prescribed displacements.
    """

    def __init__(self, scene, control, criterion, contact, area_initial, dead_loads=False):
        self.scene, self.control, self.criterion, self.contact = scene, control, criterion, contact
        self.area_initial, self.dead_loads = area_initial, dead_loads
        self.contact_setups = MeshSetups()

    # -- the physics of one configuration ------------------------------------------------------
    def problem(self, mesh, x, timings, u=None, check_mesh=True, triangle_piece=None):
        """The scene's problem on a mesh at load x, with a displacement.

        Parameters
        ----------
        mesh : ngsolve.Mesh
        x : float
            The load parameter.
        timings : Timings
        u : numpy.ndarray, optional
            P1 displacement vector (VectorH1 layout).
        check_mesh : bool
            Validate the mesh (False for meshes the crack engine made from checked ones).
        triangle_piece : numpy.ndarray, optional
            Fragment per triangle, if known.

        Returns
        -------
        ElasticProblem
        """
        with timings.timed("rebuild"):
            prob = ElasticProblem(mesh, self.scene.material, order=1, check_mesh=check_mesh,
                                  triangle_piece=triangle_piece)
            self.scene.apply_load(prob, x)
            if u is not None:
                prob.u.vec.FV().NumPy()[:] = u
        return prob

    def needs_contact(self, mesh):
        """True when a solve on this mesh needs contact rows.

        Parameters
        ----------
        mesh : ngsolve.Mesh

        Returns
        -------
        bool
        """
        if self.contact == "never":
            return False
        if mesh.dim == 3:
            # 3D: contact (crack lips included) where the scene asks for it: on a tetrahedral
            # mesh whose pieces only separate a contact solve costs from a few percent (1.3k
            # tets) to more than 12 times the run (bar3d(maxh=0.25), its crack's mouth at the
            # slot root; docs/contact.md, "Contact in 3D runs"); without it the overlap is
            # measured and noted (:meth:`check`)
            return bool(self.scene.contact)
        return self.scene.contact or "crack" in mesh.GetBoundaries()

    def equilibrium(self, prob, phase, method, timings, substeps=1, warm=(), lineage=None, start=None):
        """Solve ``prob`` in ``substeps`` load steps, with contact where the mesh needs it.

        Parameters
        ----------
        prob : ElasticProblem
        phase : {"increment", "relaxation"}
        method : {"modified", "full", "rescue"}
            "rescue": :func:`ngfracture.run.retries.rescued`.
        timings : Timings
        substeps : int
        warm : iterable of tuple
            The active contact keys of the solve before (ContactSolver.solve).
        lineage : object, optional
            The mesh was split from a solved one (linalg.bordered).
        start : SavedTangent, optional
            A factorised tangent of this mesh to start from (State.tangent).

        Returns
        -------
        Equilibrium

        Raises
        ------
        StepFailed
            The solve did not converge.
        """
        if method == "rescue":
            return rescued(lambda newton: self.equilibrium(prob, phase, newton, timings, substeps, warm, lineage,
                                                           start if newton == "modified" else None), prob, phase)
        c = self.control
        options = dict(method=method, tol=c.tol, maxit=c.maxit, inverse=c.inverse, load_steps=substeps)
        if self.needs_contact(prob.mesh):
            return self._contact_equilibrium(prob, phase, options, timings, warm, lineage, start)
        t0 = time.perf_counter()
        tangent = start.kept() if start is not None else SavedTangent(lineage)
        status = prob.solve(fix_free_modes=self.scene.fix_free_modes, tangent=tangent, **options)
        timings.add("solve", time.perf_counter() - t0)
        for part, seconds in status.phase_seconds().items():
            timings.add(part, seconds)
        timings.count_factorisations(status.factorisations)
        if not status.converged:
            raise StepFailed(status.reason, phase, status.message)
        return Equilibrium([], tangent, status.iterations, merged_notes([], status.notes))

    def _contact_equilibrium(self, prob, phase, options, timings, warm, lineage, start):
        """:meth:`equilibrium` with an active set of contact rows."""
        # the complementarity choice from a warm set of the same mesh only: warm rows carried
        # over a crack pass can hold a vertex on the plane of a face that no longer bounds it
        # (docs/contact.md, "Rounds of a warm increment solve")
        solver = ContactSolver(prob, tol=self.scene.contact_tol,   # its tol: detection threshold
                               fix_free_modes=self.scene.fix_free_modes, setups=self.contact_setups,
                               warm_exact=None if phase == "increment" else False)
        solver.options.update(options)                              # Newton's tol, method, maxit
        result = solver.solve(warm=warm, lineage=lineage, start=start)
        collision = result.timings.get("collision", 0.0)
        timings.add("solve", result.timings["solve"])
        timings.add("contact", result.timings["contact"] - collision)
        timings.add("collision", collision)
        timings.add("linear", result.timings.get("linear", 0.0))
        timings.add("assembly", result.timings.get("assembly", 0.0))
        timings.count_factorisations(result.factorisations)
        if not result.converged:
            if result.reason == "penetration":
                message = (f"contact rows still penetrate by {result.max_penetration:.3g} after "
                           f"{result.updates} re-linearisations")
            elif result.reason == "active_set":
                message = f"contact active set did not settle in {result.rounds} rounds"
            else:
                message = result.status.message
            raise StepFailed(result.reason, phase, message)
        return Equilibrium(result.active_keys, result.tangent, result.status.iterations,
                           merged_notes([], result.notes))

    def crack_pass(self, prob, x, strength, tangent, timings):
        """One splitting pass on an equilibrium.

        Parameters
        ----------
        prob : ElasticProblem
            The equilibrium.
        x : float
            Its load parameter (the split problem's).
        strength : numpy.ndarray or None
            Critical strain per vertex.
        tangent : SavedTangent or None
            The tangent the equilibrium ended with: the split mesh's solves start from it.
        timings : Timings

        Returns
        -------
        CrackPass
        """
        with timings.timed("strain"):
            tensors = self.criterion.overstrain(prob.mesh, prob.u, strength, arrays=prob.arrays)
            largest = float(principal(tensors)[0].max(initial=0.0))
        if prob.dim == 3:
            return solid_crack_pass(self, prob, x, strength, tensors, largest, tangent, timings)
        t0 = time.perf_counter()
        # cracks judged at a critical distance grow from their tips (docs/criterion.md)
        if self.criterion.one_ring:
            rules = PAPER_RULES
        else:       # bisection's few edge directions need aimed tips (AIMED_GROWTH_RULES)
            rules = AIMED_GROWTH_RULES if self.scene.refinement() is not None else GROWTH_RULES
        res = split_by_tensor(prob.mesh, tensors, 1.0, skip_neighbours=self.control.split == "spread",
                              first_only=self.control.split == "one", rules=rules,
                              check_mesh=False)   # checked when made, or split from a checked mesh
        rebuild = res.timings.get("netgen", 0.0) + res.timings.get("ngsolve_mesh", 0.0)
        timings.add("split", time.perf_counter() - t0 - rebuild)
        timings.add("rebuild", rebuild)
        if res.nsplit == 0:
            return CrackPass(None, 0, strength, None, np.zeros((0, 2)), largest, res.refusals, res.refused)
        positions = res.record["position"][np.diff(res.record["new_offsets"]) > 0]
        # P1: the displacement is a vertex field (component-major), copied through the split
        u = transfer_vertex_field(prob.u.vec.FV().NumPy().reshape(2, -1).T, res).T.reshape(-1)
        if strength is not None:
            strength = transfer_vertex_field(strength, res)    # copies inherit the vertex's strength
        inherited = bordered.lineage(tangent.factor, tangent.state, res.parent) if tangent is not None else None
        # the engine split a checked mesh and keeps it valid
        split = self.problem(res.mesh, x, timings, u, check_mesh=False, triangle_piece=res.fragment)
        return CrackPass(split, res.nsplit, strength, inherited, positions, largest)

    # -- one load step ----------------------------------------------------------------------------
    def attempt(self, state, dx, method, timings, substeps=1, keep=True):
        """Try the step x + dx from an accepted state and relax it at fixed load.

        Parameters
        ----------
        state : State
        dx : float
        method : {"modified", "full", "rescue"}
        timings : Timings
        substeps : int
            Newton load steps of the increment solve.
        keep : bool
            Start from the tangent the state keeps (if any, modified Newton).

        Returns
        -------
        Attempt or TooManyCracks

        Raises
        ------
        StepFailed
            A solve failed (``from_kept`` when the increment solve started from the kept tangent).
        """
        c = self.control
        if c.growth == "critical" or self.dead_loads:
            # force control cracks at its critical load (and runs on there unless "critical")
            x, prob, eq, crack, start, iterations, notes = critical_event(self, state, dx, method, timings,
                                                                         substeps, keep)
        else:
            x = state.x + dx
            prob, eq, start = self.increment(state, x, method, timings, substeps, keep)
            crack, iterations, notes = None, eq.iterations, eq.notes
        work = reaction_work(prob, state.fixed_dofs, state.fixed_values, state.reactions)
        if prob.loads:        # the dead loads' work over the increment (same mesh, same dofs)
            forces = load_vector(prob)
            before = state.external if state.external is not None else np.zeros_like(forces)
            work += work_of_forces(before, forces, state.u, prob.u.vec.FV().NumPy())
        area = state.area
        if crack is None:
            # judged on material refined around the sharp tips (Scene.refine)
            refined = refine_equilibrium(self, prob, eq, x, state.strength, area, method, timings)
            prob, eq, area = refined.problem, refined.equilibrium, refined.area
            work, iterations = work + refined.work, iterations + refined.iterations
            crack = self.crack_pass(prob, x, refined.strength, eq.tangent, timings)
            if c.growth == "fixed" and crack.n_split > c.max_new_cracks and dx * c.cut >= c.dx_min:
                return TooManyCracks(crack.n_split)
        relaxed = relax(self, prob, crack, eq, x, area, method, timings)
        return Attempt(relaxed.problem, x, crack.n_split, crack.n_split + relaxed.splits, relaxed.strength,
                       relaxed.contact_keys, relaxed.tangent, work + relaxed.work, relaxed.positions,
                       iterations + relaxed.iterations, merged_notes(notes, relaxed.notes), start is not None,
                       relaxed.broken_through, relaxed.lost_support, area=relaxed.area,
                       overstrain=crack.overstrain)

    def increment(self, state, x, method, timings, substeps=1, keep=True):
        """The increment's problem at x on the state's mesh and its equilibrium.

        Parameters
        ----------
        state : State
        x : float
        method : {"modified", "full", "rescue"}
        timings : Timings
        substeps : int
        keep : bool
            Start from the tangent the state keeps (modified Newton).

        Returns
        -------
        (ElasticProblem, Equilibrium, SavedTangent or None)
            The problem, its equilibrium, and the kept tangent it started from.

        Raises
        ------
        StepFailed
            The solve failed (``from_kept`` when it started from the kept tangent).
        """
        prob = self.problem(state.mesh, x, timings, state.u)
        start = tangents.kept_tangent(state, prob, timings) if keep and method == "modified" else None
        try:
            eq = self.equilibrium(prob, "increment", method, timings, substeps, warm=state.contact_keys, start=start)
        except StepFailed as err:
            err.from_kept = start is not None
            raise
        return prob, eq, start

    def step(self, state, dx, timings):
        """Attempts of one step until one is accepted, or the last failure.

        Too many cracks: dx * cut. A failed increment solve that started from the tangent
        the state keeps: the same attempt with a tangent of its own (recorded in the notes,
        not counted against ``max_retries``). Other failures: the next attempt of
        :func:`ngfracture.run.retries.next_retry` (full Newton, twice as many substeps of
        the increment, or dx * cut; on a tetrahedral mesh with contact a failed relaxation
        first takes dx * cut with modified Newton, :meth:`cuts_before_full`). Every attempt
        starts from the saved state: nothing of a failed attempt is kept.

        Parameters
        ----------
        state : State
        dx : float
        timings : Timings

        Returns
        -------
        StepOutcome
        """
        c = self.control
        log = StepLog(method=c.method)
        keep = True
        while True:
            try:
                attempt = self._checked_attempt(state, dx, log, timings, keep)
            except StepFailed as err:
                log.retries += 1
                log.failures.append(err.reason)
                if err.from_kept:
                    # the same attempt with its own tangent, not counted against max_retries
                    keep = False
                    log.notes.append(f"the tangent kept from the step before failed ({err.reason}); "
                                     "the step factorised its own")
                    continue
                if log.retries - (not keep) > c.max_retries:
                    return StepOutcome(None, dx, log, err)
                dx_next = next_retry(log, err.phase, dx, c, self.cuts_before_full(state.mesh))
                if dx_next is None:
                    return StepOutcome(None, dx, log, err)
                dx = dx_next
                continue
            if isinstance(attempt, TooManyCracks):     # too many cracks at once: smaller increment
                dx *= c.cut
                continue
            log.kept_tangent = attempt.kept_tangent
            log.notes = merged_notes(log.notes, attempt.notes)
            return StepOutcome(attempt, dx, log)

    def cuts_before_full(self, mesh):
        """True where a relaxation that failed with modified Newton is retried with dx * cut
        before full Newton (:mod:`ngfracture.run.retries`): a tetrahedral mesh with contact.

        Parameters
        ----------
        mesh : ngsolve.Mesh
            The state's mesh.

        Returns
        -------
        bool
        """
        return mesh.dim == 3 and self.needs_contact(mesh)

    def _checked_attempt(self, state, dx, log, timings, keep):
        """:meth:`attempt` and :meth:`check`; an unexpected error in them is a failed attempt
        (reason "exception", its type, message and traceback recorded), not a lost run."""
        try:
            attempt = self.attempt(state, dx, log.method, timings, log.substeps, keep)
            if not isinstance(attempt, TooManyCracks):
                attempt.overlap, notes = self.check(attempt.problem, attempt.area, timings)
                attempt.notes = merged_notes(attempt.notes, notes)
            return attempt
        except StepFailed:
            raise
        except Exception as exc:     # noqa: BLE001 - recorded with its traceback, then retried
            raise StepFailed("exception", "relaxation", f"{type(exc).__name__}: {exc}",
                             details=traceback.format_exc()) from exc

    def check(self, prob, area, timings):
        """The invariants of an attempt's result (:mod:`ngfracture.run.invariants`).

        Parameters
        ----------
        prob : ElasticProblem
            The equilibrium at the end of the attempt.
        area : float
            The reference area its mesh must have to the last bit.
        timings : Timings

        Returns
        -------
        overlap : float
            The overlap area between the pieces (0 where nothing can overlap); in 3D the
            deepest vertex's depth in another piece.
        notes : list of str
            :data:`UNHELD_NOTE` where the pieces of a 3D run without contact rows overlap
            by more than the invariant accepts (measured, not enforced: no row holds them).

        Raises
        ------
        StepFailed
            Naming the invariant broken (phase "invariant").
        """
        with timings.timed("checks"):
            pieces = self.scene.contact or "crack" in prob.mesh.GetBoundaries() or prob.fragments()[0] > 1
            unheld = pieces and prob.dim == 3 and not self.needs_contact(prob.mesh)
            violation, overlap = check_state(prob, area, pieces and not unheld)
            if violation is None and unheld:
                overlap = penetration_depth_3d(prob)
        if violation is not None:
            raise StepFailed(violation.invariant, "invariant", violation.message)
        return overlap, [UNHELD_NOTE] if unheld and overlap > depth_limit_3d(prob) else []

    def accept(self, state, outcome, timings):
        """The accepted state of a step and its history record.

        Parameters
        ----------
        state : State
            The state the step started from.
        outcome : StepOutcome
            With an accepted attempt.
        timings : Timings

        Returns
        -------
        AcceptedStep
        """
        attempt, dx, log = outcome.attempt, outcome.dx, outcome.log
        arrays, mesh = round_trip(attempt.problem.mesh)
        u = attempt.problem.u.vec.FV().NumPy().copy()
        # the solve ended at u (kept by the problem, no assembly); the round trip keeps the dof numbers
        out_of_balance = attempt.problem.out_of_balance()
        prob = self.problem(mesh, attempt.x, timings, u)   # the state as a resume would see it
        rows = prob.assemble_constraints()
        energy = float(prob.energy())
        stats = FragmentStatistics(mesh)
        work = state.work + attempt.work
        # a step that cracked keeps its (possibly cut) increment; quiet steps may grow it
        quiet = state.quiet + 1 if attempt.total_cracks == 0 else 0
        new_dx = dx
        if quiet >= self.control.grow_after:
            new_dx, quiet = min(dx * self.control.grow, self.control.dx_max), 0
        record = self._record(state, attempt, dx, log, energy, work, crack_extent(arrays), stats.count)
        record["boundaries"] = boundary_resultants(prob, out_of_balance)
        r, flat = self.criterion.smallest_radius, arrays.dim == 2      # the crack graph is 2D
        graph = crack_graph(arrays, branches=False) if flat and (attempt.total_cracks or r is not None) else None
        if attempt.total_cracks and flat:      # each tip's advance over the step (reference length)
            points, advances = tip_advances(state.arrays, arrays, graph=graph)
            record["tips"] = [{"position": p, "advanced": a} for p, a in zip(points.tolist(), advances.tolist())]
        if r is not None and flat:
            # how finely the mesh resolves the criterion at the crack tips (h / r)
            _, sizes = tip_sizes(arrays, graph=graph)
            record["tip_resolution"] = float(sizes.max(initial=0.0) / r)
        if attempt.lost_support:
            record["lost_support"] = attempt.lost_support
        new = State(arrays=arrays, u=u, x=attempt.x, dx=new_dx, step=state.step + 1, quiet=quiet, work=work,
                    reactions=-out_of_balance[rows.fixed_dofs], fixed_values=rows.fixed_values.copy(),
                    fixed_dofs=rows.fixed_dofs.copy(), peak_energy=max(state.peak_energy, energy),
                    history=state.history + [record], strength=attempt.strength,
                    contact_keys=attempt.contact_keys, mesh=mesh, area=attempt.area,
                    external=load_vector(prob) if prob.loads else None)
        kept = tangents.tangent_to_keep(attempt.tangent, log.method, new.fixed_dofs)
        if kept is not None:
            new.tangent_state, new.tangent, new.tangent_inverse = kept.state, kept, kept.factor.inverse
        return AcceptedStep(new, record, prob, stats, attempt)

    @staticmethod
    def _record(state, attempt, dx, log, energy, work, extent, fragments):
        """The history record of an accepted step."""
        record = {"step": state.step + 1, "x": attempt.x, "dx": dx, "new_cracks_first_pass": int(attempt.first_cracks),
                  "split_vertices": int(attempt.total_cracks), "elastic_energy": energy, "external_work": work,
                  "released_energy": work - energy, extent[0]: extent[1],
                  "fragments": int(fragments), "newton_iterations": int(attempt.iterations),
                  "retries": int(log.retries), "failures": list(log.failures),
                  "substeps": int(log.substeps), "method": log.method,
                  "relax_passes": max(len(attempt.split_positions) - 1, 0), "notes": list(log.notes),
                  "kept_tangent": bool(log.kept_tangent), "overlap_area": float(attempt.overlap),
                  "triangles": int(attempt.problem.mesh.ne),      # changes only by refinement (Scene.refine)
                  "overstrain": attempt.overstrain}
        if attempt.first_cracks and not any(h["split_vertices"] for h in state.history):
            # where cracking began: the vertices split by the first pass that split any
            record["initiation"] = attempt.split_positions[0].tolist()
        return record

    # -- the end of a run -----------------------------------------------------------------------
    def initial_state(self, timings):
        """The state at x = 0: the scene's mesh through the checkpoint representation.

        Parameters
        ----------
        timings : Timings

        Returns
        -------
        State
        """
        strength = None if self.scene.strength is None else np.array(self.scene.strength, dtype=float)
        mesh, strength, area = refine_initial(self, self.scene.mesh, strength, self.area_initial, timings)
        arrays, mesh = round_trip(mesh)
        prob = self.problem(mesh, 0.0, timings)
        rows = prob.assemble_constraints()
        return State(arrays=arrays, u=np.zeros(prob.fes.ndof), x=0.0, dx=float(self.scene.dx), step=0, area=area,
                     external=load_vector(prob) if prob.loads else None,
                     quiet=0, work=0.0, reactions=np.zeros(len(rows.fixed_dofs)),
                     fixed_values=rows.fixed_values.copy(), fixed_dofs=rows.fixed_dofs.copy(),
                     peak_energy=0.0, history=[], strength=strength, mesh=mesh)

    def broken(self, state, timings):
        """Why an accepted state is broken through (Scene.stop_when_unloaded), or "".

        Parameters
        ----------
        state : State
        timings : Timings

        Returns
        -------
        str
        """
        last = state.history[-1]
        if last["fragments"] > 1 and self.cut_through(state.arrays, state.mesh, state, timings):
            return "the body is broken through (no fragment connects boundaries the load moves apart)"
        if last.get("crack_length", last.get("crack_area")) > 0 and last["elastic_energy"] < self.control.unloaded_fraction * state.peak_energy:
            return "the body is broken through (elastic energy released)"
        return ""

    def cut_through(self, arrays, mesh, loaded, timings):
        """True when no fragment of the mesh connects boundaries the load moves apart.

        Parameters
        ----------
        arrays : MeshArrays
            The mesh's arrays.
        mesh : ngsolve.Mesh
        loaded : ConstraintRows or State
            The fixed dofs and values at the load.
        timings : Timings

        Returns
        -------
        bool
        """
        # the prescribed values at x against those at 0, on this mesh
        unloaded = self.problem(mesh, 0.0, timings).assemble_constraints()
        dofs, increment = prescribed_increment(unloaded.fixed_dofs, unloaded.fixed_values,
                                               loaded.fixed_dofs, loaded.fixed_values)
        return load_path_cut(arrays.points, arrays.tets if arrays.dim == 3 else arrays.triangles, dofs, increment)

