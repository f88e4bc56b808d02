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
takes dx * cut with modified Newton, once per step, and then goes on as above. A
full-Newton contact solve there factorises at every iteration and builds the Schur
complement of all contact rows from each factor: on the default sphere (about 1350 rows)
a relaxation took 271 s of CPU with full Newton against 20 s with modified Newton, and
the contact set that failed to settle settled at the smaller step.

A tangent kept from the step before that fails is not a retry of this kind: the step
makes the same attempt with a tangent of its own (``LoadStep.step``).
"""

__all__ = ["next_retry"]


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
        log.method = "full"           # the same attempt with fresh tangents
        return dx
    if phase == "increment":
        log.substeps *= 2
        return dx
    if can_cut:
        log.substeps = 1
        return dx * control.cut
    return None
