"""The step control: adaptive load increments (paper section 4.2)."""
import math
import numbers
from dataclasses import asdict, dataclass, fields

__all__ = ["StepControl"]


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
    inverse : str
        The solver of K^+ (mechanics.newton.INVERSES): "auto" (2D: SuperLU or sparse
        Cholesky by size; 3D: sparse Cholesky while its predicted memory fits the budget,
        CG with AMG above, linalg.iterative), "amg" to force the iterative solve, or a
        direct solver by name.
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

    growth : {"fixed", "critical"}
        How a crack grows within a load step. "fixed" (the paper's): at the step's load,
        pass after pass until nothing splits, the unstable part of a crack's growth in one
        step. "critical": one split event per load step, at the load that makes the crack
        just critical (found by a few equilibria, lowered where the grown crack is critical
        below the step's load): the load-displacement curve through its peak, its
        descending branch and snap-back, a crack passing a hole resolved event by event;
        ``max_new_cracks`` does not apply. A scene loaded by tractions or body forces
        (force control) cracks at its critical load in either mode; with "fixed" the crack
        then runs on at that load, as it does under a dead load.

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
    inverse: str = "auto"
    unloaded_fraction: float = 1e-3
    split: str = "spread"
    growth: str = "fixed"

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
        from ..mechanics.newton import INVERSES     # here: the control is read before any solver
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
                  ("inverse", self.inverse in INVERSES),
                  ("unloaded_fraction", number(self.unloaded_fraction) and 0 < self.unloaded_fraction < 1),
                  ("split", self.split in ("spread", "all", "one")),
                  ("growth", self.growth in ("fixed", "critical"))]
        for name, ok in checks:
            if not ok:
                raise ValueError(f"StepControl.{name} = {getattr(self, name)!r} is out of range")
