"""Which factorised tangent a load step starts from (modified Newton across load steps).

The paper's modified Newton factorises the tangent once per load step. A step's last
factorised tangent starts the next step's increment solve (same mesh, at least
``KEEP_MIN_DOFS`` factorised dofs) while that solve contracted by ``KEEP_MAX_CONTRACTION``
or better: a tangent from a few load steps back converges in as many iterations on glass
strains (docs/solvers.md). The displacement it was assembled at is in the checkpoint, so a
resumed run factorises the same tangent again.
"""
import time

import numpy as np

from ..linalg import bordered
from ..linalg.factor import EliminatedFactor, SingularSystem
from ..mechanics.tangent import SavedTangent
from .records import StepFailed

__all__ = ["KEEP_MIN_DOFS", "KEEP_MAX_CONTRACTION", "kept_tangent", "tangent_to_keep"]

#: a step's factorised tangent starts the next step's solve from this many factorised dofs
#: on; below, a factorisation costs a few solves (the bordered factors' threshold) ...
KEEP_MIN_DOFS = bordered.MIN_BASE_DOFS

#: ... and while its last solve contracted by this ratio or better (its increments fell by
#: 1e3 or more per iteration): at most one iteration more than a fresh tangent at tol
#: 1e-10, where a factorisation costs 15 to 30 solves (docs/solvers.md)
KEEP_MAX_CONTRACTION = 1e-3


def kept_tangent(state, problem, timings):
    """The factorised tangent an accepted state keeps for ``problem`` (its mesh), or None.

    None also where the increment fixes other dofs than the tangent was factorised for
    (the solve would not use it). A resumed run factorises it again at the displacement
    it was assembled at, once per state (kept in ``state.tangent``).

    Parameters
    ----------
    state : State
    problem : ElasticProblem
        The increment's problem on the state's mesh.
    timings : Timings

    Returns
    -------
    SavedTangent or None

    Raises
    ------
    StepFailed
        "singular": the tangent cannot be factorised again (``from_kept``).
    """
    if state.tangent_state is None:
        return None
    rows = problem.assemble_constraints()
    if not np.array_equal(rows.fixed_dofs, state.fixed_dofs):
        return None
    if state.tangent is None:
        t0 = time.perf_counter()
        try:
            state.tangent = SavedTangent.assembled_at(problem, state.tangent_state, rows,
                                                      state.tangent_inverse or "auto")
        except SingularSystem as err:
            raise StepFailed("singular", "increment", f"the kept tangent: {err}", from_kept=True) from None
        finally:
            for phase in ("solve", "linear"):
                timings.add(phase, time.perf_counter() - t0)
    return state.tangent


def tangent_to_keep(tangent, method, fixed_dofs):
    """What an accepted state keeps of its last solve's tangent, or None.

    Parameters
    ----------
    tangent : SavedTangent or None
        The tangent the step's last solve ended with.
    method : str
        The Newton variant of the step ("modified" keeps tangents).
    fixed_dofs : numpy.ndarray
        The accepted state's fixed dofs, which a kept tangent was factorised for (a
        resumed run factorises it again for them).

    Returns
    -------
    SavedTangent or None
    """
    factor = tangent.factor if tangent is not None else None
    if (method != "modified" or not isinstance(factor, EliminatedFactor) or factor.linear_solver != "direct"
            or tangent.state is None or tangent.contraction is None
            or tangent.contraction > KEEP_MAX_CONTRACTION
            or np.count_nonzero(factor.factor_free) < KEEP_MIN_DOFS
            or not np.array_equal(tangent.fixed_dofs, fixed_dofs)):
        return None
    return tangent.kept()
