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
        self._solvers = {}        # solver -> [factorisations, the last choice record]

    def count_factorisations(self, records):
        """Count the factorisations of K^+ a solve made, by solver.

        Parameters
        ----------
        records : list of dict
            SolveStatus.factorisations (linalg.iterative.choose_inverse's records).
        """
        for record in records:
            entry = self._solvers.setdefault(record["solver"], [0, None])
            entry[0] += 1
            entry[1] = record

    def restore_factorisations(self, record):
        """Continue the counts of :meth:`factorisation_record` from a checkpoint's.

        Parameters
        ----------
        record : dict
            What :meth:`factorisation_record` returned (empty for none).
        """
        self._solvers = {solver: [int(entry["factorisations"]), dict(entry["last"])]
                         for solver, entry in record.items()}

    def factorisation_record(self):
        """Which solvers made K^+ and why: summary.json's ``timings["linear_solver"]`` (a resumed
        run continues the counts of its checkpoint, :meth:`restore_factorisations`).

        Returns
        -------
        dict
            solver -> {"factorisations": count, "last": the choice record of its last one:
            ``reason`` "auto" or "asked", ``dofs``, and for "auto" in 3D
            ``predicted_bytes`` (sparse Cholesky) and ``budget_bytes``}.
        """
        return {solver: {"factorisations": count, "last": dict(record)}
                for solver, (count, record) in sorted(self._solvers.items())}

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
