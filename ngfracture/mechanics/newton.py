"""Modified and full Newton-Raphson for the constrained equilibrium (paper eq. 3 to 7).

One load step, from the converged state u^t to the prescribed values b:

    K(u^t) factorised once (modified Newton) or at every iterate (full Newton)
    du^(k) solves  [K C^T; G 0] [du; lam] = [R - F(u^(k-1)); b - G u^(k-1)]   (eq. 3, 6)
    u^(k) = u^(k-1) + du^(k)                                                (eq. 4)
    stop when |du^(k)| < tol |du^(0)|                                       (eq. 7)

A solve never returns garbage silently: it ends with a SolveStatus whose reason is
one of REASONS, and on failure the problem's displacement is restored to the last
converged state.
"""
import numbers
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import rigid
from .constraints import ConstraintRows
from ..linalg.bordered import BorderedFactor
from ..linalg.factor import LINEAR_SOLVERS, SingularSystem
from ..linalg.iterative import ITERATIVE_INVERSES, make_factor
from ..linalg.kkt import ConstrainedSolver
from ..linalg.sparse import single_threaded_blas

METHODS = ("modified", "full")
#: solvers of K^+: "auto", scipy's "superlu", an NGSolve inverse (one not compiled into the
#: installed NGSolve still fails at the first factorisation, naming itself), or "amg" (CG
#: with algebraic multigrid, linalg.iterative; "auto" takes it in 3D above the memory budget)
INVERSES = ("auto", "superlu", "sparsecholesky", "umfpack", "pardiso", "pardisospd", "mumps",
            "masterinverse") + ITERATIVE_INVERSES


def check_solve_options(options):
    """Check the Newton options a caller passes on (method, tol, maxit, linear_solver, inverse).

    Parameters
    ----------
    options : dict
        Any of ``method``, ``tol``, ``maxit``, ``linear_solver``, ``inverse``,
        ``load_steps``; other keys are not looked at.

    Raises
    ------
    ValueError
        Naming the first bad option and the values it takes.
    """
    if "method" in options and options["method"] not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {options['method']!r}")
    tol = options.get("tol", 0.5)
    if isinstance(tol, bool) or not isinstance(tol, numbers.Real) or not 0 < tol < 1:
        raise ValueError(f"tol must be in (0, 1), got {tol!r}")
    for name in ("maxit", "load_steps"):
        v = options.get(name, 1)
        if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < 1:
            raise ValueError(f"{name} must be a positive integer, got {v!r}")
    if options.get("linear_solver", "direct") not in LINEAR_SOLVERS:
        raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {options['linear_solver']!r}")
    if options.get("inverse", "auto") not in INVERSES:
        raise ValueError(f"inverse must be one of {INVERSES}, got {options['inverse']!r}")
REASONS = ("converged", "max_iterations", "diverged", "nan", "singular", "inverted_element")


@dataclass
class SolveStatus:
    """How a solve ended.

    A solve starts from the defaults and fills it in; it is true when converged.

    Parameters
    ----------
    converged, reason, message, iterations, steps, increment_history, residual_history
        Initial values of the attributes of the same names (below).
    timings, multipliers, first_increment, notes, factorisations
        Likewise; by default a dict of zeros for the five phases, an empty array, 0 and
        empty lists.

    Attributes
    ----------
    converged : bool
    reason : str
        One of "converged", "max_iterations", "diverged", "nan", "singular",
        "inverted_element".
    message : str
        Human-readable detail (which body floats, which element inverted, ...).
    iterations : int
        Newton iterations over all load steps.
    steps : int
        Load steps completed.
    increment_history : list of float
        |du^(k)| / |du^(0)| of every iteration (eq. 7), all steps in order.
    residual_history : list of float
        Euclidean norm of the free out-of-balance force after every iteration.
    timings : dict
        Seconds per phase: assemble, factorize (with the Schur complement), solve,
        residual, checks.
    multipliers : numpy.ndarray
        Lagrange multipliers of the general rows at the end (the forces -C^T lam
        they exert on the dofs); empty without general rows.
    first_increment : float
        Euclidean norm of the first increment du^(0) (0 before any iteration).
    notes : list of str
        Fallbacks the solve took (a carried factorisation given up for a fresh one).
    factorisations : list of dict
        The solver choice (linalg.iterative.choose_inverse's record) of every K^+ the solve
        made, in order.
    """
    converged: bool = False
    reason: str = "max_iterations"
    message: str = ""
    iterations: int = 0
    steps: int = 0
    increment_history: list = field(default_factory=list)
    residual_history: list = field(default_factory=list)
    timings: dict = field(default_factory=lambda: dict.fromkeys(
        ("assemble", "factorize", "solve", "residual", "checks"), 0.0))
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0))
    first_increment: float = 0.0
    notes: list = field(default_factory=list)
    factorisations: list = field(default_factory=list)

    def __bool__(self):
        return self.converged

    def phase_seconds(self):
        """Seconds in "linear" (factorisations, triangular solves) and "assembly" (residuals,
        tangents): the parts of a solve that Simulation and ContactSolver report.

        Returns
        -------
        dict
            {"linear": float, "assembly": float}
        """
        t = self.timings
        return {"linear": t["factorize"] + t["solve"], "assembly": t["residual"] + t["assemble"]}

    def fail(self, reason, message):
        """Record a failure: converged becomes False, reason and message are set.

        Parameters
        ----------
        reason : str
            One of REASONS other than "converged" (not checked).
        message : str
            Human-readable detail.

        Returns
        -------
        SolveStatus
            This status (changed in place), so that ``return status.fail(...)`` works.
        """
        self.converged, self.reason, self.message = False, reason, message
        return self


def rewinder(prob):
    """A function that puts the displacement and load factor of ``prob`` back as they are
    now: a solve that failed is tried again from the same start.

    Parameters
    ----------
    prob : ElasticProblem

    Returns
    -------
    callable
        ``rewind()``, without arguments.
    """
    u, load = prob.u.vec.FV().NumPy().copy(), prob.load_factor.Get()

    def rewind():
        prob.u.vec.FV().NumPy()[:] = u
        prob.load_factor.Set(load)
    return rewind


class _Timer:
    def __init__(self, timings, phase):
        self.timings, self.phase = timings, phase

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        self.timings[self.phase] += time.perf_counter() - self.t0


class NewtonSolver:
    """Newton-Raphson with Lagrange-multiplier constraints for an ElasticProblem.

    Parameters
    ----------
    problem : ElasticProblem
    method : {"modified", "full"}
        "modified" (the paper's choice) factorises the tangent once per load step;
        "full" at every iterate (quadratic convergence).
    tol : float
        Relative increment tolerance of eq. 7. An increment that has stopped falling
        (not below the smallest of the three before it) below 1e3 tol counts as
        converged too: rounding, not the method, sets that floor. Modified Newton, from
        the third iteration on, also stops when the error estimate of the iterate from the
        contraction of the last two increments, rho / (1 - rho) |du^(k)| with
        rho = |du^(k)| / |du^(k-1)| < 1/2, is below tol |du^(0)|: the increment eq. 7 would
        wait for is already below the tolerance (the first ratio is no estimate: it
        compares the nonlinear correction with the linear response).
    increment_scale : float, optional
        A reference for |du^(0)| in eq. 7: the solve compares increments with the larger
        of its own first increment and this. A solve that corrects another one at the same
        load (a contact round with changed rows) is as accurate as the step it corrects
        when its increments fall below tol times the step's first increment; measured
        against its own tiny first increment it would solve the correction to rounding.
    maxit : int
        Maximum iterations per load step.
    linear_solver : {"direct", "gmres"}
    inverse : str
        Solver of K^+ (INVERSES): "auto", "superlu", an NGSolve name (see
        linalg.kkt.ConstrainedSolver) or "amg"; chosen per factorisation by
        linalg.iterative.make_factor (3D "auto": sparse Cholesky within the memory budget,
        "amg" above; SuperLU for a full-Newton tangent with many general rows).
    divergence_factor : float
        An increment this many times larger than the first one means divergence.
    fix_free_modes : bool or "all"
        True: fix the rigid modes that no constraint holds (free fragments) by multiplier
        rows that stop them from drifting; otherwise such a body is reported as floating.
        "all": fix every rigid mode that the single-dof rows leave free, also those that
        general rows (contact) hold: every piece without Dirichlet support is held like the
        paper's pinned fragments, and contact presses it against its hold.
    tangent : tangent.SavedTangent, optional
        Reuse its factorisation, or leave this solve's in it (see mechanics.tangent).

    Raises
    ------
    ValueError
        If ``method`` is not in METHODS, ``tol`` not a number in (0, 1), ``maxit`` not a
        positive integer, ``fix_free_modes`` not False, True or "all", ``linear_solver``
        not in LINEAR_SOLVERS or ``inverse`` not in INVERSES.
    """

    def __init__(self, problem, method="modified", tol=1e-10, maxit=50, linear_solver="direct",
                 inverse="auto", divergence_factor=1e4, fix_free_modes=False, tangent=None,
                 increment_scale=None):
        if fix_free_modes not in (False, True, "all"):
            raise ValueError(f"fix_free_modes must be False, True or 'all', got {fix_free_modes!r}")
        check_solve_options(dict(method=method, tol=tol, maxit=maxit, linear_solver=linear_solver,
                                 inverse=inverse))
        self.problem = problem
        self.method, self.tol, self.maxit = method, float(tol), maxit
        self.linear_solver, self.inverse = linear_solver, inverse
        self.divergence_factor = divergence_factor
        self.fix_free_modes = fix_free_modes
        self.tangent = tangent
        if increment_scale is not None and not (np.isfinite(increment_scale) and increment_scale >= 0):
            raise ValueError(f"increment_scale must be a finite number >= 0, got {increment_scale!r}")
        self.increment_scale = increment_scale or 0.0

    @single_threaded_blas()
    def solve(self, load_steps=1):
        """Bring the problem from its current state to the prescribed constraint values.

        The prescribed values (and external loads) are reached in ``load_steps`` equal
        increments from the current state.

        Parameters
        ----------
        load_steps : int
            Number of equal increments (>= 1) of the load factor, the fixed dof values and
            the right-hand sides of the general rows.

        Returns
        -------
        SolveStatus
            Failures (floating body, singular system, NaN, divergence, inverted element,
            no convergence) are reported here, not raised; on failure the displacement and
            the load factor are those of the last converged load step. A solve through a
            factorisation carried across a crack pass (linalg.bordered.BorderedFactor) that
            finds it singular is made again with the split mesh's own factorisation,
            recorded in ``notes``.

        Raises
        ------
        ValueError
            If ``load_steps`` is not a positive integer, or if the constructor's
            ``linear_solver`` is unknown (raised at the first factorisation).
        """
        status = self._solve(load_steps)
        saved = self.tangent
        if status.reason == "singular" and saved is not None and isinstance(saved.factor, BorderedFactor):
            failed = status
            saved.forget()
            status = self._solve(load_steps)
            status.iterations += failed.iterations
            for phase, seconds in failed.timings.items():
                status.timings[phase] += seconds
            status.notes.append("a factorisation carried across a crack pass was singular; the split "
                                "mesh was solved with its own factorisation")
        return status

    def _solve(self, load_steps):
        """The solve of :meth:`solve` with the tangent it is given."""
        if isinstance(load_steps, bool) or not isinstance(load_steps, int) or load_steps < 1:
            raise ValueError(f"load_steps must be a positive integer, got {load_steps!r}")
        prob = self.problem
        status = SolveStatus()
        saved = self.tangent
        # a saved tangent is valid for every iterate of modified Newton; full Newton needs
        # the tangent of each iterate unless the model is linear
        reusable = saved is not None and (self.method == "modified" or not prob.nonlinear)
        with _Timer(status.timings, "checks"):
            rows = prob.assemble_constraints()
            reuse = reusable and saved.holds(rows.fixed_dofs)
            support = saved.support if reuse else prob.support(rows)
            if reusable and not reuse and saved.carry_over(prob, rows.fixed_dofs, support):
                reuse, support = True, saved.support
            # rows that hold the free modes leave none floating: checked only without them
            floating = "" if self.fix_free_modes else prob.floating_bodies(rows, support)
            if self.fix_free_modes:
                rows = self._hold_free_modes(rows, support)
        if floating:
            return status.fail("singular", floating)
        u = prob.u.vec.FV().NumPy()
        start_fixed = u[rows.fixed_dofs].copy()
        start_rows = rows.C @ u
        start_load = prob.load_factor.Get()
        for step in range(1, load_steps + 1):
            t = step / load_steps
            prob.load_factor.Set(start_load + t * (1.0 - start_load))
            target_fixed = start_fixed + t * (rows.fixed_values - start_fixed)
            target_rows = start_rows + t * (rows.g - start_rows)
            start = u.copy()
            factor = self._load_step(rows, support, target_fixed, target_rows, status,
                                     saved.factor if reuse else None)
            if reusable and not reuse and factor is not None:
                saved.fixed_dofs, saved.support, saved.factor, saved.state = rows.fixed_dofs, support, factor, start
            if not status.converged:
                u[:] = start  # the last converged state, never a failed iterate
                prob.load_factor.Set(start_load + (step - 1) / load_steps * (1.0 - start_load))
                status.message = f"load step {step} of {load_steps}: {status.message}"
                return status
            status.steps = step
        return status

    def unilateral_multipliers(self, unilateral, released=None):
        """Multipliers of one linearised step in which some general rows are inequalities.

        The step of the first Newton iteration from the current state to the prescribed
        values (with the saved tangent if it holds, as :meth:`solve` would use it), with the
        general rows ``unilateral`` (indices into the assembled general rows) as C du >= h,
        lam <= 0, complementary: a linear complementarity problem solved exactly
        (:meth:`linalg.kkt.ConstrainedSolver.solve_unilateral`). The state is not changed. The
        rows may be linearly dependent (distinct inequalities can be dependent vectors);
        the closed ones then hold together, and a caller imposing them as equalities
        should keep an independent subset.

        Parameters
        ----------
        unilateral : numpy.ndarray of int
            Indices of the unilateral rows among the assembled general rows (with
            ``fix_free_modes``, the rows appended for free modes stay equalities).
        released : numpy.ndarray of bool, optional
            Per unilateral row, whether it is guessed released: the start of the solve
            (``ConstrainedSolver.solve_unilateral``).

        Returns
        -------
        lam : numpy.ndarray
            Multipliers of the assembled general rows (0 for released unilateral rows).
        closed : numpy.ndarray of bool
            The rows that hold with equality (see ConstrainedSolver.solve_unilateral).
        fallback : str
            Empty, or why the QP solver fell back (see ConstrainedSolver.solve_unilateral).

        Raises
        ------
        SingularSystem
            An unheld free mode or a singular stiffness.
        qp.QPError
            If the complementarity problem is not solved (see :func:`ngfracture.linalg.qp.bound_qp`).
        """
        prob = self.problem
        rows = prob.assemble_constraints()
        m = rows.C.shape[0]
        saved = self.tangent
        reuse = (saved is not None and saved.factor is not None and saved.holds(rows.fixed_dofs)
                 and (self.method == "modified" or not prob.nonlinear))
        support = saved.support if reuse else prob.support(rows)
        if self.fix_free_modes:
            rows = self._hold_free_modes(rows, support)
        factor = saved.factor if reuse else self._factor(prob.tangent(), rows, support)
        kkt = ConstrainedSolver(None, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                                factor=factor, dependent_rows=True)
        u = prob.u.vec.FV().NumPy()
        du_fixed = np.zeros(u.size)
        du_fixed[rows.fixed_dofs] = rows.fixed_values - u[rows.fixed_dofs]
        with prob.threads():
            _, lam, closed, fallback = kkt.solve_unilateral(self._out_of_balance(), du_fixed,
                                                            rows.g - rows.C @ u, unilateral, released)
        return lam[:m], closed[:m], fallback

    def _out_of_balance(self):
        """The out-of-balance force, taken from the saved tangent if u is where it was left."""
        saved = self.tangent
        u = self.problem.u.vec.FV().NumPy()
        if (saved is not None and saved.residual is not None and np.array_equal(saved.residual[0], u)
                and saved.residual[1] == self.problem.load_factor.Get()):
            return saved.residual[2].copy()
        return self.problem.out_of_balance()

    def _hold_free_modes(self, rows, support):
        """Append rows n^T du = 0 for every rigid mode n that nothing holds (or every free one)."""
        if self.fix_free_modes == "all":
            extra = support.modes.T.tocsr()
        else:
            extra = rigid.unheld_mode_rows(rows.C, support.modes)
        if extra.shape[0] == 0:
            return rows
        u = self.problem.u.vec.FV().NumPy()
        return ConstraintRows(rows.fixed_dofs, rows.fixed_values, sp.vstack([rows.C, extra]).tocsr(),
                              np.concatenate([rows.g, extra @ u]), rows.labels + ["free modes"])

    def _load_step(self, rows, support, target_fixed, target_rows, status, factor=None):
        """One load step (eq. 3 to 7): iterate until :meth:`_converged` or a failure, which
        ``status`` records; returns the last factorisation (None if the step failed)."""
        prob = self.problem
        u = prob.u.vec.FV().NumPy()
        free = np.ones(u.size, dtype=bool)
        free[rows.fixed_dofs] = False
        du_fixed = np.zeros(u.size)
        given, kkt = factor, None
        du0, prev, growing = None, np.inf, 0
        with _Timer(status.timings, "residual"):
            r = self._out_of_balance()
        for k in range(self.maxit):
            if not np.all(np.isfinite(r)):
                status.fail("nan", f"the residual is NaN/inf at iteration {k}")
                return None
            du_fixed[:] = 0.0
            du_fixed[rows.fixed_dofs] = target_fixed - u[rows.fixed_dofs]   # eq. 6
            h = target_rows - rows.C @ u
            try:
                if kkt is None or (self.method == "full" and given is None):
                    kkt, factor = self._linear_system(rows, support, given, (r, du_fixed), status.timings)
                    if given is None:
                        status.factorisations.append(factor.choice)
                    if kkt.fallback:
                        status.notes.append(f"iteration {k}: {kkt.fallback}")
                with _Timer(status.timings, "solve"), prob.threads():
                    du, status.multipliers = kkt.solve(r, du_fixed, h)
            except SingularSystem as err:
                status.fail("singular", str(err))
                return None
            if k == 0:
                # the force scale of the step: out-of-balance plus the pull of the prescribed values
                force_scale = kkt.load_norm(r, du_fixed)
            if not np.all(np.isfinite(du)):
                status.fail("nan", f"the increment is NaN/inf at iteration {k}")
                return None
            u += du
            status.iterations += 1
            norm = float(np.linalg.norm(du))
            if du0 is None:
                status.first_increment = status.first_increment or norm
                du0 = max(norm, self.increment_scale)
            ratio = norm / du0 if du0 > 0 else 0.0
            status.increment_history.append(ratio)
            with _Timer(status.timings, "residual"):
                r = prob.out_of_balance()
            # out-of-balance with the constraint forces of the general rows included
            status.residual_history.append(float(np.linalg.norm((r - rows.C.T @ status.multipliers)[free])))
            with _Timer(status.timings, "checks"):
                inverted = prob.inverted_elements() if prob.nonlinear else None
            if inverted:
                status.fail("inverted_element", inverted)
                return None
            if self._converged(status, k, norm, prev, force_scale, r):
                return factor
            if not np.isfinite(ratio) or ratio > self.divergence_factor:
                status.fail("diverged", f"increment grew to {ratio:.2e} times the first one")
                return None
            growing = growing + 1 if norm >= prev else 0
            prev = norm
            if growing >= 5:
                status.fail("diverged", "the increment grew for 5 iterations in a row")
                return None
        status.fail("max_iterations", f"no convergence in {self.maxit} iterations "
                                      f"(last relative increment {status.increment_history[-1]:.2e})")

    def _linear_system(self, rows, support, given, first, timings):
        """(ConstrainedSolver, factorisation) of an iteration: on ``given``, or on a fresh
        factorisation of the tangent at the current iterate.

        A tangent factorised for one solve (full Newton) takes its rows into one
        factorisation of the augmented matrix; one kept over iterations and contact rounds
        builds Schur columns once and reuses them (docs/solvers.md). Raises SingularSystem."""
        factor = given
        if given is None:
            with _Timer(timings, "assemble"):
                K = self.problem.tangent()
            # not inside prob.threads(): the factorisation runs on one thread (linalg.factor)
            with _Timer(timings, "factorize"):
                factor = self._factor(K, rows, support)
        path = "auto" if self.method == "full" and given is None else "schur"
        with _Timer(timings, "factorize"):
            kkt = ConstrainedSolver(None, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                                    factor=factor, path=path, first=first)
        return kkt, factor

    def _factor(self, K, rows, support):
        """A fresh K^+ of the tangent K for the general rows of ``rows``
        (linalg.iterative.make_factor); full Newton on a nonlinear model factorises it for
        one system."""
        prob = self.problem
        return make_factor(K, rows.fixed_dofs, support.pins, self.linear_solver, self.inverse, dim=prob.dim,
                           points=prob.arrays.points, pattern=prob.tangent_pattern(),
                           rows=rows.C.shape[0], one_system=self.method == "full" and prob.nonlinear)

    def _converged(self, status, k, norm, prev, force_scale, r):
        """Whether iterate k (increment ``norm``, the one before ``prev``) ends the load step:
        eq. 7 or one of the stops of the class docstring. If so, ``status`` and the saved
        tangent record it (with the out-of-balance ``r`` at the converged state)."""
        prob = self.problem
        u = prob.u.vec.FV().NumPy()
        hist = status.increment_history
        ratio = hist[-1]
        # eq. 7; for the linear model one step is exact, and a residual at rounding level
        # proves it without a second solve
        exact = not prob.nonlinear and status.residual_history[-1] <= self.tol * force_scale
        # below the rounding of u itself eq. 7 cannot improve (an already converged start)
        rounding = norm <= 64 * np.finfo(float).eps * np.linalg.norm(u)
        # a stall at the rounding floor: the increment has stopped falling, three orders
        # below anything physical (docs/solvers.md, "Newton's stopping rules")
        stalled = ratio < 1e3 * self.tol and len(hist) >= 4 and ratio >= min(hist[-4:-1])
        # modified Newton contracts linearly: the last ratio estimates the next ones
        rho = norm / prev if self.method == "modified" and k >= 2 and prev > 0 else 1.0
        contracted = rho < 0.5 and rho / (1.0 - rho) * ratio < self.tol
        if not (ratio < self.tol or norm == 0.0 or exact or rounding or stalled or contracted):
            return False
        status.converged, status.reason = True, "converged"
        status.message = f"stalled at relative increment {ratio:.1e}" if stalled and ratio >= self.tol else ""
        if self.tangent is not None:
            self.tangent.residual = (u.copy(), prob.load_factor.Get(), r)
            if self.method == "modified" and k >= 2:
                self.tangent.contraction = max(self.tangent.contraction or 0.0, rho)
        return True
