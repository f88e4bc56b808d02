"""Wall time of a run per phase."""
import time
from contextlib import contextmanager

__all__ = ["PHASES", "Timings"]

#: wall time per phase; "linear" (factorisations and triangular solves) and "assembly"
#: (NGSolve's residual and tangent assembly) are parts of "solve"; "checks": the invariants
#: of every attempt (run/invariants.py)
PHASES = ("solve", "linear", "assembly", "strain", "split", "rebuild", "refine", "collision", "contact", "checks",
          "output")


class Timings(dict):
    """Seconds per phase (:data:`PHASES`), added to by the stages of a load step.

    Parameters
    ----------
    seconds : dict of str -> float, optional
        Seconds to start from (a resumed run's earlier part).
    """

    def __init__(self, seconds=None):
        super().__init__(dict.fromkeys(PHASES, 0.0))
        self.update(seconds or {})

    def add(self, phase, seconds):
        """Add seconds to a phase.

        Parameters
        ----------
        phase : str
        seconds : float
        """
        self[phase] += seconds

    @contextmanager
    def timed(self, *phases):
        """The wall time of the ``with`` block, added to every phase named.

        Parameters
        ----------
        *phases : str

        Yields
        ------
        None
        """
        t0 = time.perf_counter()
        try:
            yield
        finally:
            seconds = time.perf_counter() - t0
            for phase in phases:
                self[phase] += seconds
