"""What the stages of a load step produce, as small records.

A load step (:mod:`ngfracture.run.step`) is a chain of stages, each returning a record::

    equilibrium -> Equilibrium      a converged solve
    crack pass  -> CrackPass        the vertices one pass split, and the split problem
    attempt     -> Attempt          the increment, its crack passes and relaxation
                 | TooManyCracks    the first pass split more than the step control allows
    step        -> StepOutcome      the attempts until one is accepted (StepLog) or all failed
    accept      -> AcceptedStep     the new State and its history record

A failed solve raises :class:`StepFailed`, which the step catches and retries.
"""
from dataclasses import dataclass, field

import numpy as np

__all__ = ["merged_notes", "StepFailed", "Equilibrium", "CrackPass", "Attempt", "Relaxation", "TooManyCracks", "StepLog",
           "StepOutcome", "AcceptedStep"]


def merged_notes(notes, more):
    """``notes`` followed by those of ``more`` that are not in it yet, in order.

    Parameters
    ----------
    notes, more : list of str

    Returns
    -------
    list of str
    """
    out = list(notes)
    out.extend(n for n in more if n not in out)
    return out


class StepFailed(Exception):
    """A solve inside a step failed.

    Parameters
    ----------
    reason : str
        The solver's reason (nan, diverged, inverted_element, singular, active_set,
        penetration, ...).
    phase : {"increment", "relaxation", "invariant"}
        The solve of the increment, one at fixed load after a split, or the check of the
        attempt's result (:mod:`ngfracture.run.invariants`).
    message : str
    from_kept : bool
        The increment solve started from the tangent kept from the step before.
    details : str
        More for the record (the traceback of an unexpected error), or "".
    """

    def __init__(self, reason, phase, message, from_kept=False, details=""):
        super().__init__(f"{reason} ({phase}): {message}")
        self.reason, self.phase, self.message, self.from_kept = reason, phase, message, from_kept
        self.details = details


@dataclass(frozen=True)
class Equilibrium:
    """A converged solve of one problem.

    Parameters
    ----------
    contact_keys : list of tuple
        The active contact rows at the solution (empty without contact).
    tangent : SavedTangent
        The factorised tangent the solve ended with.
    iterations : int
        Newton iterations.
    notes : list of str
        The solvers' departures from their plain path.
    """
    contact_keys: list
    tangent: object
    iterations: int
    notes: list


@dataclass(frozen=True)
class CrackPass:
    """One splitting pass on an equilibrium.

    Parameters
    ----------
    problem : ElasticProblem or None
        The problem on the split mesh, with the displacement carried over; None when the
        pass split nothing.
    n_split : int
        Vertices created.
    strength : numpy.ndarray or None
        The critical strain per vertex on the new mesh (copies inherit it).
    lineage : object or None
        The factorisation the split mesh's solves start from (linalg.bordered.Lineage).
    positions : numpy.ndarray
        Reference positions (k, 2) of the vertices that split.
    overstrain : float
        The largest overstrain of the equilibrium it judged (a vertex splits above 1).
    refused : dict
        Of a pass that split nothing: its overstrained vertices counted by the splitting
        rule that refused them (the engines' ``refusals``); empty when none was refused.
    refused_vertices : numpy.ndarray
        Those vertices (the engines' ``refused``), ascending.
    """
    problem: object
    n_split: int
    strength: object
    lineage: object
    positions: np.ndarray
    overstrain: float
    refused: dict = field(default_factory=dict)
    refused_vertices: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def refusal_note(self):
        """The note of a pass that left overstrained vertices unsplit (None if it did not):
        their cracks stop on the splitting rules, not on the criterion.

        Returns
        -------
        str or None
        """
        if not self.refused:
            return None
        n, rules = self._refused_in_words()
        return (f"{n} {'vertex stays' if n == 1 else 'vertices stay'} overstrained (up to {self.overstrain:.4g}) "
                f"where no splitting rule cuts them ({rules}): cracks stop there on the rules, not on the criterion")

    def left_out_note(self, x):
        """The note of the refused vertices that a critical load's search leaves out.

        Parameters
        ----------
        x : float
            The load this pass judged.

        Returns
        -------
        str
        """
        n, rules = self._refused_in_words()
        return (f"{n} {'vertex' if n == 1 else 'vertices'} overstrained at x = {x:.6g} (up to {self.overstrain:.4g}) "
                f"split by no rule ({rules}): left out of the search for the critical load")

    def _refused_in_words(self):
        """(how many vertices were refused, "rule: count, ..."), for the notes."""
        return sum(self.refused.values()), ", ".join(f"{name}: {count}" for name, count in self.refused.items())


@dataclass
class Attempt:
    """The step x -> x + dx tried from an accepted state, relaxed until no vertex splits.

    Parameters
    ----------
    problem : ElasticProblem
        The equilibrium at the end (on the mesh of the last split).
    x : float
        The load parameter reached.
    first_cracks, total_cracks : int
        Vertices split by the first pass, and by all passes.
    strength : numpy.ndarray or None
        Critical strain per vertex of the final mesh.
    contact_keys : list of tuple
        Active contact rows at the end.
    tangent : SavedTangent
        The factorised tangent of the last solve.
    work : float
        External work over the increment (trapezoid rule on the reactions).
    split_positions : list of numpy.ndarray
        Per pass that split: the reference positions of its vertices.
    iterations : int
        Newton iterations of all solves.
    notes : list of str
        The solvers' departures from their plain path.
    kept_tangent : bool
        The increment solve started from the tangent kept from the step before.
    broken_through : bool
        The relaxation stopped because the body came apart (Scene.stop_when_unloaded): no
        crack pass judged the separated pieces.
    lost_support : str
        Why a loaded piece has lost its support ("" if none): the run ends with this step.
    overlap : float
        Overlap area between the pieces at the end (:mod:`ngfracture.run.invariants`).
    area : float or None
        The reference area of the final mesh (changed only by refinement; None: the scene's).
    overstrain : float
        The largest overstrain of the equilibrium the first pass judged (above 1 it splits;
        below, the load over it is the load at which the body would start to crack).
    """
    problem: object
    x: float
    first_cracks: int
    total_cracks: int
    strength: object
    contact_keys: list
    tangent: object
    work: float
    split_positions: list
    iterations: int
    notes: list
    kept_tangent: bool = False
    broken_through: bool = False
    lost_support: str = ""
    overlap: float = 0.0
    area: float = None
    overstrain: float = 0.0


@dataclass
class Relaxation:
    """The crack passes and equilibria of an attempt at fixed load.

    Parameters
    ----------
    problem : ElasticProblem
        The last equilibrium (or, with ``lost_support``, the state right after the split).
    strength : numpy.ndarray or None
    contact_keys : list of tuple
    tangent : SavedTangent
    splits : int
        Vertices split by the passes after the first.
    work : float
        Work of the dead loads on the opening cracks.
    positions : list of numpy.ndarray
        Per pass that split: the reference positions of its vertices.
    iterations : int
    notes : list of str
    broken_through : bool
        Stopped where the body came apart (Scene.stop_when_unloaded).
    lost_support : str
        Stopped where a loaded piece lost its support: why ("" otherwise).
    area : float
        The reference area of the problem's mesh (changed only by refinement).
    """
    problem: object
    strength: object
    contact_keys: list
    tangent: object
    splits: int
    work: float
    positions: list
    iterations: int
    notes: list
    broken_through: bool
    lost_support: str
    area: float


@dataclass(frozen=True)
class TooManyCracks:
    """The first pass of an attempt split more vertices than ``StepControl.max_new_cracks``.

    Parameters
    ----------
    first_cracks : int
    """
    first_cracks: int


@dataclass
class StepLog:
    """How a step got to its accepted attempt.

    Parameters
    ----------
    retries : int
        Failed attempts.
    failures : list of str
        Their reasons.
    substeps : int
        Newton load steps of the accepted increment solve.
    method : str
        Newton variant of the accepted attempt ("modified", "full" or "rescue", see
        :mod:`ngfracture.run.retries`).
    notes : list of str
        Departures from the plain path (a kept tangent that failed, ...).
    kept_tangent : bool
        The accepted increment solve started from the tangent kept from the step before.
    cut_modified : bool
        A failed relaxation was retried with dx * cut and modified Newton
        (``LoadStep.cuts_before_full``): done at most once per step.
    """
    retries: int = 0
    failures: list = field(default_factory=list)
    substeps: int = 1
    method: str = "modified"
    notes: list = field(default_factory=list)
    kept_tangent: bool = False
    cut_modified: bool = False


@dataclass
class StepOutcome:
    """The result of one load step: an accepted attempt, or the last failure.

    Parameters
    ----------
    attempt : Attempt or None
        None when every retry failed.
    dx : float
        The increment of the attempt (cut by retries).
    log : StepLog
    failure : StepFailed or None
        The last failure when ``attempt`` is None.
    """
    attempt: object
    dx: float
    log: StepLog
    failure: object = None


@dataclass
class AcceptedStep:
    """An accepted step, as a run reports it to ``Simulation.run(on_step=...)``.

    Parameters
    ----------
    state : State
        The new accepted state (its ``mesh`` and ``history`` included).
    record : dict
        Its history record (``state.history[-1]``).
    problem : ElasticProblem
        The problem on the accepted state, as a resumed run would build it.
    fragments : FragmentStatistics
        Fragments of the accepted mesh.
    attempt : Attempt
        The attempt that was accepted.
    """
    state: object
    record: dict
    problem: object
    fragments: object
    attempt: object
