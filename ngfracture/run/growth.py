"""How a crack grows within a load step: at fixed load, or one event at its critical load.

``StepControl.growth = "fixed"`` (the paper's): after the increment, crack passes and
equilibria at the step's load until a pass splits nothing (:func:`relax`): the unstable
part of a crack's growth happens within one step. ``"critical"``: one split event per
step, at the load where the most overstrained vertex is just critical (:func:`critical_load`),
below the step's load where the grown crack is critical there: the load-displacement
curve through its peak, its descending branch and snap-back, event by event.

Both stop where the body comes apart (Scene.stop_when_unloaded) and where a loaded piece
has lost its support (force control: no equilibrium exists). Under the dead loads of a
force-controlled scene a solve at fixed load that fails after a split for want of an
equilibrium (:data:`NO_EQUILIBRIUM`) is taken as that: the crack runs on unstably, and the
run ends broken at that load with the cracked state.
"""

import numpy as np

from ..fracture.strain import principal
from ..mechanics.resultants import load_vector, unsupported_pieces, work_of_forces
from .records import Relaxation, StepFailed, merged_notes
from .refinement import refine_equilibrium

__all__ = ["NO_EQUILIBRIUM", "CRITICAL_MARGIN", "CRITICAL_ITERATIONS", "max_overstrain", "critical_event", "critical_load",
           "relax"]

#: failures of a solve at fixed load that, under a scene's dead loads, mean there is no
#: equilibrium: the crack runs on (force control)
NO_EQUILIBRIUM = ("max_iterations", "diverged", "singular")

#: growth resolved in load (StepControl.growth = "critical"): a crack advances at the load
#: where its most overstrained vertex reaches 1 to 1 + 2 CRITICAL_MARGIN of its strength ...
CRITICAL_MARGIN = 1e-3
#: ... found in at most this many equilibria (the overstrain is about linear in the load: 2 to 4
#: where it is continuous; bisection-like where another vertex takes over)
CRITICAL_ITERATIONS = 40


def max_overstrain(stepper, mesh, u, strength, arrays, timings, skip=None):
    """The largest overstrain of a displacement's vertices (a vertex cracks above 1).

    Parameters
    ----------
    stepper : LoadStep
    mesh : ngsolve.Mesh
    u : ngsolve.GridFunction or numpy.ndarray
        The displacement, or its vertex values (nv, dim).
    strength : numpy.ndarray or None
    arrays : MeshArrays
        The mesh as arrays.
    timings : Timings
    skip : numpy.ndarray, optional
        Vertices left out (those no splitting rule cuts).

    Returns
    -------
    float
    """
    with timings.timed("strain"):
        tensors = stepper.criterion.overstrain(mesh, u, strength, arrays=arrays)
        values = principal(tensors)[0]
        if skip is not None:
            values[skip] = 0.0
        return float(values.max(initial=0.0))


def critical_event(stepper, state, dx, method, timings, substeps=1, keep=True):
    """The next crack event of a step with growth resolved in load, and its load.

    Where the accepted state is itself overstrained (the crack it grew is critical at a lower
    load), the event's load is sought below the state's; else the increment x + dx is
    solved and, where it overstrains a vertex, the load is brought back to the critical
    one. Where the critical vertex splits nothing (no rule cuts it: the end of a clamped
    edge, a pocket between crack sheets), the event is sought again without it, at the
    critical load of the vertices that remain (noted); where the pass splits nothing and
    refuses no new vertex, the step takes its whole increment and splits what the
    fixed-load pass splits there.

    Parameters
    ----------
    stepper : LoadStep
    state : State
    dx : float
    method : {"modified", "full", "rescue"}
    timings : Timings
    substeps : int
    keep : bool

    Returns
    -------
    x : float
    prob : ElasticProblem
    eq : Equilibrium
    crack : CrackPass or None
        The event's pass (None: the caller's pass at x, which splits nothing or is the fallback).
    start : SavedTangent or None
        The kept tangent the increment solve started from.
    iterations : int
    notes : list of str
    """
    U = state.u.reshape(state.mesh.dim, -1)[:, :state.mesh.nv].T
    skip, notes, iterations, x_try = np.zeros(0, dtype=np.int64), [], 0, None
    while True:
        m_state = max_overstrain(stepper, state.mesh, U, state.strength, state.arrays, timings, skip) if state.step else 0.0
        if x_try != (state.x if m_state >= 1.0 else state.x + dx):
            x_try = state.x if m_state >= 1.0 else state.x + dx
            prob, eq, start = stepper.increment(state, x_try, method, timings, substeps, keep)
            iterations += eq.iterations
            if x_try == state.x:
                # the state is overstrained: where only by vertices no rule cuts, its own pass
                # says so, without a search below its load
                own = stepper.crack_pass(prob, x_try, state.strength, eq.tangent, timings)
                if own.n_split == 0 and np.setdiff1d(own.refused_vertices, skip).size:
                    skip, notes = np.union1d(skip, own.refused_vertices), merged_notes(notes, [own.left_out_note(x_try)])
                    continue
        x, pc, ec, more = critical_load(stepper, state, x_try, prob, eq, method, timings, skip)
        iterations += more
        if pc is prob:            # x_try overstrains nothing (but vertices no rule cuts): a quiet
            return x_try, prob, eq, None, start, iterations, eq.notes   # increment, whose pass notes them
        crack = stepper.crack_pass(pc, x, state.strength, ec.tangent, timings)
        if crack.n_split:
            return x, pc, ec, crack, start, iterations, merged_notes(ec.notes, notes)
        if np.setdiff1d(crack.refused_vertices, skip).size == 0:
            break
        # the critical vertex splits by no rule (a clamped corner, a pocket): the event is
        # the next vertex's, at its own critical load
        skip, notes = np.union1d(skip, crack.refused_vertices), merged_notes(notes, [crack.left_out_note(x)])
    note = (f"the pass at the critical load x = {x:.6g} split nothing: the step took its whole increment "
            f"(growth at fixed load)")
    if x_try != state.x + dx:
        prob, eq, _ = stepper.increment(state, state.x + dx, method, timings, substeps, keep=False)
        iterations += eq.iterations
    return state.x + dx, prob, eq, None, start, iterations, merged_notes(eq.notes, notes + [note])


def critical_load(stepper, state, x_try, prob, eq, method, timings, skip=None):
    """Growth resolved in load: the load at which the most overstrained vertex is just critical.

    Where the increment's equilibrium at ``x_try`` overstrains a vertex, the load is
    moved to x_c with an overstrain in [1, 1 + 2 CRITICAL_MARGIN] (a secant on the load,
    bracketed once both sides are known): the crack advances by one event at the load
    that makes it critical, below the state's own load where the grown crack is already
    critical there (the curve's descending branch and snap-back).

    Parameters
    ----------
    stepper : LoadStep
    state : State
    x_try : float
    prob : ElasticProblem
        The increment's equilibrium at x_try.
    eq : Equilibrium
    method : {"modified", "full", "rescue"}
    timings : Timings
    skip : numpy.ndarray, optional
        Vertices whose overstrain does not count (no splitting rule cuts them).

    Returns
    -------
    (float, ElasticProblem, Equilibrium, int)
        The load, its equilibrium, and the Newton iterations spent on finding it.

    Raises
    ------
    StepFailed
        "critical_load": no load within CRITICAL_ITERATIONS makes the crack just critical.
    """
    m = max_overstrain(stepper, prob.mesh, prob.u, state.strength, prob.arrays, timings, skip)
    if m <= 1.0:
        return x_try, prob, eq, 0
    target = 1.0 + CRITICAL_MARGIN
    lo, hi = None, (x_try, m - target, prob, eq)      # (load, overstrain - target, problem, equilibrium)
    side, iterations = 0, 0
    for _ in range(CRITICAL_ITERATIONS):
        if lo is None:        # the overstrain grows about in proportion to the load
            x = hi[0] * target / (hi[1] + target)
        else:                 # regula falsi in the bracket (Illinois: a kept end's value halves)
            x = (lo[0] * hi[1] - hi[0] * lo[1]) / (hi[1] - lo[1])
        prob = stepper.problem(state.mesh, x, timings, state.u)
        eq = stepper.equilibrium(prob, "increment", method, timings, warm=state.contact_keys)
        iterations += eq.iterations
        m = max_overstrain(stepper, prob.mesh, prob.u, state.strength, prob.arrays, timings, skip)
        if 1.0 <= m <= 1.0 + 2 * CRITICAL_MARGIN:
            return x, prob, eq, iterations
        if m > 1.0:
            hi = (x, m - target, prob, eq)
            if side > 0 and lo is not None:
                lo = (lo[0], 0.5 * lo[1])
            side = 1
        else:
            lo = (x, m - target)
            if side < 0:
                hi = (hi[0], 0.5 * hi[1], hi[2], hi[3])
            side = -1
        if lo is not None and hi[0] - lo[0] <= 1e-9 * abs(hi[0]):
            # the overstrain jumps across 1 here (another vertex takes over): crack at the
            # lowest load known to overstrain
            return hi[0], hi[2], hi[3], iterations
    raise StepFailed("critical_load", "increment", f"no load made the crack just critical in "
                     f"{CRITICAL_ITERATIONS} solves (overstrain {m:.6g} at x = {x:.6g})")


def relax(stepper, prob, crack, eq, x, area, method, timings):
    """Crack passes and equilibria at fixed load x until a pass splits nothing.

    It stops early where the body comes apart (Scene.stop_when_unloaded), and where a
    loaded piece has lost its support (force control: no equilibrium exists; the state
    is the one right after the split, :func:`ngfracture.mechanics.resultants.unsupported_pieces`).

    Parameters
    ----------
    stepper : LoadStep
    prob : ElasticProblem
        The equilibrium the first pass split.
    crack : CrackPass
        The first pass of the attempt.
    eq : Equilibrium
        The equilibrium it split.
    x : float
    area : float
        The reference area of the split mesh (the area invariant's).
    method : {"modified", "full", "rescue"}
    timings : Timings

    Returns
    -------
    Relaxation

    Raises
    ------
    StepFailed
        A solve failed, or cracks still grow after ``max_relax_passes`` passes.
    """
    c = stepper.control
    strength, work, positions, iterations, notes = crack.strength, 0.0, [], 0, []
    splits, passes, broken, lost = 0, 0, False, ""
    while crack.problem is not None:
        positions.append(crack.positions)
        passes += 1
        if passes > c.max_relax_passes:
            raise StepFailed("relaxation", "relaxation", f"cracks still grow after {c.max_relax_passes} passes at fixed load")
        prob, strength = crack.problem, crack.strength
        carried = prob.u.vec.FV().NumPy().copy() if prob.loads else None
        try:
            eq = stepper.equilibrium(prob, "relaxation", method, timings, warm=eq.contact_keys, lineage=crack.lineage)
            lost = unsupported_pieces(prob)
            if not lost:     # the next pass judges the new tips on refined material (Scene.refine)
                refined = refine_equilibrium(stepper, prob, eq, x, strength, area, method, timings)
        except StepFailed as err:
            lost = unsupported_pieces(prob, contact_holds=False)
            if not lost and stepper.dead_loads and err.reason in NO_EQUILIBRIUM:
                # dead loads on a body whose crack grew at this load and which has no
                # equilibrium: the crack runs on unstably (force control), a fracture
                lost = (f"no equilibrium after the crack grew at this load ({err.reason}: {err.message}): "
                        f"under these loads it runs on unstably")
            if not lost:
                raise
        if lost:        # force control: the cracked state at this load ends the run
            prob.u.vec.FV().NumPy()[:] = carried
            break
        if prob.loads:    # at fixed load the dead loads work on the opening crack
            forces = load_vector(prob)
            work += work_of_forces(forces, forces, carried, prob.u.vec.FV().NumPy())
        iterations, notes = iterations + eq.iterations, merged_notes(notes, eq.notes)
        prob, eq, strength, area = refined.problem, refined.equilibrium, refined.strength, refined.area
        work, iterations = work + refined.work, iterations + refined.iterations
        if (stepper.scene.stop_when_unloaded and prob.fragments()[0] > 1
                and stepper.cut_through(prob.arrays, prob.mesh, prob.assemble_constraints(), timings)):
            broken = True
            break     # the run ends with this step: no crack in the separated pieces
        if c.growth == "critical":
            break         # one event per load step: the next step finds the next critical load
        crack = stepper.crack_pass(prob, x, strength, eq.tangent, timings)
        splits += crack.n_split
    refused = crack.refusal_note() if crack.problem is None else None
    if refused:
        notes = merged_notes(notes, [refused])
    # after a lost support the last factorisation is of another mesh: nothing to keep
    return Relaxation(prob, strength, eq.contact_keys, None if lost else eq.tangent, splits, work, positions,
                      iterations, notes, broken, lost, area)
