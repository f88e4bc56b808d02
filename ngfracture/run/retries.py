"""The retries of a failed load step: which attempt comes next (docs/design.md, "Retries").

Every attempt starts from the saved state. After a failed solve:

1. modified Newton: the same attempt with full Newton, from then on for the step (the
   tangent factorised at the start of a solve can be too far from the state that new
   contact rows impose);
2. a failure of the increment solve: the same target in twice as many Newton load steps,
   so a passing trouble does not change the load path;
3. a failure at fixed load after a split: dx * cut, substeps reset;
4. no smaller dx within ``dx_min``: the step gives up.

On a tetrahedral mesh with contact, a failure at fixed load with modified Newton first
takes dx * cut with modified Newton, once per step, and then goes on as above, with
"rescue" for full Newton: modified Newton for every solve, and full Newton only for a
solve that fails with it (:func:`rescued`, called by ``LoadStep.equilibrium``). A full-Newton contact solve there
factorises at every iteration and builds the Schur complement of all contact rows from
each factor: on the default sphere (about 1350 rows) a relaxation took 271 s of CPU with
full Newton against 20 s with modified Newton, and the contact set that failed to settle
settled at the smaller step. Where dx cannot be cut, an attempt all in full Newton
repeats every solve of the step at that cost: step 66 of the default sphere took 2.5 to
3 s a relaxation with modified Newton and 30 to 40 s with full Newton, every one but the
failing one on the same rounds (docs/design.md, "Retries").

A tangent kept from the step before that fails is not a retry of this kind: the step
makes the same attempt with a tangent of its own (``LoadStep.step``).
"""

from ..mechanics.newton import rewinder
from .records import Equilibrium, StepFailed, merged_notes

__all__ = ["next_retry", "rescued"]


def next_retry(log, phase, dx, control, cut_first):
    """The increment of the next attempt after a failure, or None where the step gives up.

    Parameters
    ----------
    log : StepLog
        The step's log; its ``method``, ``substeps`` and ``cut_modified`` are set for the
        next attempt.
    phase : {"increment", "relaxation", "invariant"}
        Where the attempt failed (``StepFailed.phase``).
    dx : float
        The increment of the failed attempt.
    control : StepControl
        Its ``cut`` and ``dx_min``.
    cut_first : bool
        A failure at fixed load with modified Newton takes dx * cut before full Newton
        (a tetrahedral mesh with contact).

    Returns
    -------
    float or None
    """
    can_cut = dx * control.cut >= control.dx_min
    if log.method == "modified" and cut_first and phase == "relaxation" and not log.cut_modified and can_cut:
        log.substeps, log.cut_modified = 1, True
        return dx * control.cut
    if log.method == "modified":
        log.method = "rescue" if cut_first else "full"     # the same attempt with fresh tangents
        return dx
    if phase == "increment":
        log.substeps *= 2
        return dx
    if can_cut:
        log.substeps = 1
        return dx * control.cut
    return None


def rescued(solve, prob, phase):
    """The equilibrium of a solve of a "rescue" attempt: modified Newton, and where that
    fails, full Newton from the same start (noted).

    Parameters
    ----------
    solve : callable
        ``solve(method)`` with method "modified" or "full": the Equilibrium of ``prob``,
        or StepFailed.
    prob : ElasticProblem
        The problem ``solve`` solves; its displacement and load factor are restored before
        the full-Newton solve.
    phase : {"increment", "relaxation"}
        For the note.

    Returns
    -------
    Equilibrium

    Raises
    ------
    StepFailed
        The full-Newton solve failed too.
    """
    rewind = rewinder(prob)
    try:
        return solve("modified")
    except StepFailed as err:
        rewind()
        eq = solve("full")
        note = f"a {phase} solve that failed with modified Newton ({err.reason}) was solved with full Newton"
        return Equilibrium(eq.contact_keys, eq.tangent, eq.iterations, merged_notes(eq.notes, [note]))
