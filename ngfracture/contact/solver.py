"""Equilibrium with frictionless unilateral contact between pieces (paper eq. 8-14).

A primal-dual active set around the Newton solver, in the paper's predict-and-correct
manner:

    1. solve without contact rows (free pieces held on their rigid modes): the prediction;
       a solve given the active rows of the solve before (``warm``: the previous crack pass
       or load step) imposes those instead and skips the prediction;
    2. candidate rows (eq. 13, 14), each identified by a key (its nodes and facet):
       - across seams, where two lips coincide in the reference configuration (crack
         faces from node splitting, interfaces from ``meshio.separate_region``),
         node-to-node rows between twins, chosen once at the prediction
         (:mod:`ngfracture.contact.seams`: one row per straight node, one per facet at a kink);
       - elsewhere, node-to-segment rows of the paper's rules 1-4 (:mod:`ngfracture.contact.rows`)
         found at the current configuration; a row stays a candidate while it is active
         or found again, rows of a twin against its own seam are left out;
       every candidate is re-linearised at the configuration of the last solve, so the
       set update judges the gaps of that configuration;
    3. active set update, for every candidate row (semismooth Newton for the
       complementarity function min(-lambda, g) of eq. 8, Hintermueller-Ito-Kunisch):
       an active row stays while its multiplier compresses (lambda <= 0 up to rounding,
       compression is lambda <= 0 as the paper's p_N <= 0); an inactive row enters when
       its linearised gap is below -``penetration_tol``. Rows that depend on others are
       dropped by the pivoted QR (``contact.independent_rows``);
    4. if the set equals the one of the last solve and no row penetrates by more than
       ``penetration_tol``, stop; a settled set that still penetrates is solved again with
       its rows linearised here (an update; at most ``max_updates``); if the update of 3
       revisits a set imposed before, or has not settled after ``pdas_rounds`` rounds,
       replace it by the exact solution of the linear complementarity problem of the
       linearisation (:meth:`ContactSolver._complementarity`); impose the set as
       equalities C u + g = 0 (eq. 12), solve, and go to 2.

Why keys: the active set used to be re-selected from scratch at every linearisation. On
coincident lips every node is at once a slave of the other lip and an end of its master
segments, both lips offer masters with different normals, and rounding decides; the choice
flipped between rounds and the set cycled (measured: 20 rounds, 27 to 31 rows in a cycle of
4, on a plate cracked across). With rows identified by their nodes (and facet) the candidate
set is fixed for a seam, and the primal-dual update settles in a few rounds (measured: 2 to 7).

Why re-linearise every round: with each row frozen where it was found until the set settled,
a settled set was only the start of a fixed point of updates (re-linearise, solve, look
again), each of which could change the set again; on pieces that move by a good part of the
detection threshold in a step this took 12 to 14 solves per contact solve (the
disintegrating disk) and gave up on a pinwheel of four quarters sliding by a tenth of the
mesh size. Re-linearised every round, set and geometry settle together: 5 to 7 solves on the
disk, and the pinwheel converges up to a third of the mesh size (tests/test_contact_fractured.py).
A row whose gap at the new configuration is the same to a hundredth of ``penetration_tol``
under both linearisations keeps its old one, bit for bit, and with it its cached column of
the Schur complement: the lips that did not move cost no solve (:func:`_refreshed`).
Where re-linearising stops reducing the penetration at a settled set (rows sliding over a
kink), the rows are frozen from then on and the plain fixed point of updates decides, and
fails with reason "penetration" when it does not contract.

Why the complementarity problem: the primal-dual update converges when the response of
the gaps to the contact forces, S = C K^-1 C^T, is an M-matrix; nearly parallel rows at a
kink (two facet rows of one node pair) are far from it, and it cycled (measured on the disk
scene at maxh 0.1: period 4 between 58 and 63 rows, multipliers -1.86e6 and +1.83e6 on two
rows of one node pair). The complementarity problem with S positive definite has one
solution, found in finitely many steps (:mod:`ngfracture.linalg.qp`); it costs a dense QP on the
candidate rows, so it is used only where the cheap update fails.

At the end the Kuhn-Tucker conditions of eq. 8 hold to the solver tolerance for the rows
linearised at the solution: g_N >= -``penetration_tol``, lambda <= 0, lambda g_N = 0 (active
rows have g_N = 0, inactive ones carry no force). What overlap remains is that of the
polygonal lips between the rows' nodes, of second order in the last update.
"""
import math
import numbers
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import rows as contact
from .collision import detect_collisions
from ..fracture.crack import vertex_displacement
from ..geometry.meshio import boundary_only
from .seams import KINK_ANGLE, find_seams, seam_constraints
from ..linalg.kkt import SingularSystem, single_threaded_blas
from ..linalg.qp import QPError
from ..mechanics.newton import NewtonSolver, SavedTangent, SolveStatus, check_solve_options

LABEL = "contact"


@dataclass
class ContactResult:
    """How a contact solve ended.

    Made by :meth:`ContactSolver.solve` (true when converged).

    Parameters
    ----------
    status : SolveStatus or None
        Initial status; ContactSolver.solve passes None and then stores the status of
        every Newton solve in turn.
    converged, reason, rounds, constraints, multipliers, released, max_penetration
        Initial values of the attributes of the same names (below).
    timings, history, updates, lcp, notes, active_keys, tangent
        Likewise; by default zero timings for the four phases, an empty history, 0, 0, no
        notes, no keys, no tangent.

    Attributes
    ----------
    status : SolveStatus
        The last Newton solve (its reason says why a failure happened).
    converged : bool
    reason : str
        "converged", a Newton reason, "active_set" if the set did not settle, or
        "penetration" if the rows, re-linearised at a settled set, still penetrate by more
        than ``penetration_tol`` when a re-linearisation did not reduce the penetration or
        after ``max_updates`` of them (``max_penetration`` says how much).
    rounds : int
        Detect-and-solve rounds.
    constraints : contact.ContactConstraints
        The active constraints at the end: seam rows (master_tri = -1, a = c the master
        twin, slave its twin) and node-to-segment rows.
    multipliers : numpy.ndarray
        Their multipliers (<= 0: compressive).
    released : int
        Rows released as adhesive over all rounds.
    max_penetration : float
        Largest penetration (-g_N of the linearised gap, >= 0) among the candidate rows
        at the end, rows implied by the active ones excepted.
    timings : dict
        Seconds: "contact" all contact work (detection, row selection, assembly, QR),
        "collision" the detection part of it, "solve" the Newton solves, "linear" the
        factorisations and triangular solves within them, "assembly" the residual and
        tangent assembly within them.
    history : list of (int, float)
        Active rows and max_penetration at the start of every round.
    updates : int
        Re-linearisations of the rows at a settled solution (see ContactSolver).
    lcp : int
        Rounds whose set was chosen by the complementarity problem (after a cycle).
    notes : list of str
        Every departure from the plain path, one sentence each: a complementarity
        problem that could not be solved (the primal-dual update went on instead), or
        ``fix_free_modes=False`` that contact turned into True.
    active_keys : list of tuple
        Sorted keys of the active rows of a converged solve: ("s", lower twin, higher
        twin, kind) for seam rows, ("n", slave, a, c) for node-to-segment rows. The next
        solve can start from them (``ContactSolver.solve(warm=...)``).
    tangent : solver.SavedTangent or None
        The factorisation the solve ended with (the lineage of a mesh split from this
        one, split_factor.lineage).
    """
    status: SolveStatus
    converged: bool = False
    reason: str = ""
    rounds: int = 0
    constraints: object = None
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0))
    released: int = 0
    max_penetration: float = 0.0
    timings: dict = field(default_factory=lambda: dict.fromkeys(("contact", "collision", "solve", "linear", "assembly"), 0.0))
    history: list = field(default_factory=list)
    updates: int = 0
    lcp: int = 0
    notes: list = field(default_factory=list)
    active_keys: list = field(default_factory=list)
    tangent: object = None

    def __bool__(self):
        return self.converged


def _refreshed(old, fresh, U, limit):
    """The rows of ``fresh`` (re-linearised at U), except where the gap at U of the row in
    ``old`` (same order, same keys) differs from the fresh one by at most ``limit``: those
    keep their old linearisation, bit for bit, and with it their cached Schur column
    (kkt.EliminatedFactor.columns). Rows of lips that did not move are all of these; the
    final test of a settled set judges freshly linearised rows whatever was kept."""
    u = U.T.ravel()
    drift = np.abs((fresh.C @ u + fresh.g) - (old.C @ u + old.g))
    keep = drift <= limit
    if keep.all():
        return old
    if not keep.any():
        return fresh
    kept, renewed = np.flatnonzero(keep), np.flatnonzero(~keep)
    rows = contact.ContactConstraints.stack([old.subset(kept), fresh.subset(renewed)])
    return rows.subset(np.argsort(np.concatenate([kept, renewed])))


def _space_columns(C, nv, n):
    """Map contact columns comp*nv + v (P1 layout) to the space's comp*n + v."""
    C = sp.csr_matrix(C)
    cols = C.indices
    mapped = np.where(cols < nv, cols, cols - nv + n)
    return sp.csr_matrix((C.data, mapped, C.indptr), shape=(C.shape[0], 2 * n))


class ContactSolver:
    """Newton solves with an active set of seam and node-to-segment contact constraints.

    Parameters
    ----------
    problem : ElasticProblem
    tol : float
        Precision threshold of the detection (a length): pairs closer than tol count,
        and slave nodes within tol of a master segment can get a constraint.
    penetration_tol : float, optional
        Penetration depth accepted at the end (a length); None: 1e-10 * tol.
    max_rounds : int
        Detect-and-solve rounds before giving up with reason "active_set".
    rank_tol : float
        Rows closer than this (relative) to the span of the kept rows are dropped as
        redundant. Measured on cracked plates: near-duplicate lip rows at 1e-6 made the
        Schur complement so ill-conditioned (1e12) that Newton stalled at 5e-10.
    max_updates : int
        Solves of a settled active set again at most. A row linearised at the last solve
        (eq. 13/14) still lets the next solution overlap to second order in that solve's
        motion (measured 1.6e-9 of the area on the plate scene, from a free one-triangle
        fragment sliding along its seams). When the gaps at the solution penetrate by more
        than penetration_tol, the set is solved again with its rows linearised there (same
        rows, current normals and projections). This fixed point contracts fast where the
        step is small enough (measured: a factor 20 to 500 per update on the
        disintegration disk). Once the rows are frozen (see the module docstring), an
        update that does not reduce the penetration, or ``max_updates`` of them, end the
        solve with reason "penetration".
    kink_angle : float
        Seam facets meeting at a larger angle (radians, in the reference configuration)
        get a row each at their common node (see :mod:`ngfracture.contact.seams`). The default
        (1e-6) keeps every kink: the exact non-penetration of the polygonal lips. A large
        value (pi) gives one row with the mean normal per node: overlap first order in
        the slip (measured 100 to 1100 times more on a zigzag crack), and a body held only by
        contact on a faceted circle then has a nearly free rotation (measured: the
        Newton solve did not converge).
    pdas_rounds : int
        Rounds of the primal-dual update before the set is chosen by the complementarity
        problem (also chosen so at once when the update revisits a set). Measured: the update
        settles in 2 to 7 rounds where it converges; on kinked lips pressed obliquely it
        wandered for 20 rounds.
    **solve_options
        Passed to ``problem.solve`` (method, tol, maxit, ...); ``fix_free_modes`` is True
        (free pieces are held on the rigid modes contact leaves free) unless given as "all"
        (held on all their rigid modes: contact rows dependent on those holds are dropped
        too; False is turned into True and recorded in ``ContactResult.notes``: a piece
        that only contact holds has free modes whenever it loses contact), and ``tangent``
        is chosen by :meth:`solve`.

    Raises
    ------
    ValueError
        Naming the first bad argument: ``tol`` NaN, infinite or negative; ``max_rounds``,
        ``max_updates`` or ``pdas_rounds`` not an integer (>= 1, >= 0, >= 0);
        ``rank_tol`` not in (0, 1); ``kink_angle`` not in [0, pi]; ``fix_free_modes`` not
        False, True or "all"; an unknown ``method``, ``linear_solver`` or ``inverse``.
    """

    def __init__(self, problem, tol, penetration_tol=None, max_rounds=20, rank_tol=1e-5, max_updates=10,
                 kink_angle=KINK_ANGLE, pdas_rounds=6, **solve_options):
        if not np.isfinite(tol) or tol < 0:
            raise ValueError(f"contact detection tol must be finite and >= 0, got {tol!r}")
        for name, value, low in (("max_rounds", max_rounds, 1), ("max_updates", max_updates, 0),
                                 ("pdas_rounds", pdas_rounds, 0)):
            if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
                raise ValueError(f"ContactSolver {name} must be an integer >= {low}, got {value!r}")
        if isinstance(rank_tol, bool) or not isinstance(rank_tol, numbers.Real) or not 0 < rank_tol < 1:
            raise ValueError(f"ContactSolver rank_tol must be a number in (0, 1), got {rank_tol!r}")
        if isinstance(kink_angle, bool) or not isinstance(kink_angle, numbers.Real) \
                or not 0 <= kink_angle <= math.pi:
            raise ValueError(f"ContactSolver kink_angle must be an angle in [0, pi] (radians), got {kink_angle!r}")
        fix = solve_options.get("fix_free_modes", True)
        if fix not in (False, True, "all"):
            raise ValueError(f"fix_free_modes must be False, True or 'all', got {fix!r}")
        check_solve_options(solve_options)
        #: departures from the plain path known at construction, copied into every result
        self._notes = (["fix_free_modes=False was turned into True: with contact, free pieces are "
                        "held on the rigid modes contact leaves free"] if fix is False else [])
        self.problem = problem
        self.tol = float(tol)
        self.penetration_tol = 1e-10 * max(self.tol, 1e-300) if penetration_tol is None else penetration_tol
        self.max_rounds = max_rounds
        self.rank_tol = rank_tol
        self.max_updates = max_updates
        self.kink_angle = kink_angle
        self.pdas_rounds = pdas_rounds
        self.options = dict(solve_options)
        self.options["fix_free_modes"] = "all" if self.options.get("fix_free_modes") == "all" else True

    def _geometry(self):
        """Mesh arrays, fragment per triangle, and the fixed dofs (all, and in the P1 layout).

        None of it changes while the problem is solved on one mesh: computed once per solve.
        """
        prob = self.problem
        arrays = boundary_only(prob.arrays)   # no bonded-interface segments
        _, comp = prob.fragments()
        fragment = comp[arrays.triangles[:, 0]]
        nv, n = prob.mesh.nv, prob.fes.ndof // 2
        fixed = prob.assemble_constraints().fixed_dofs
        v, c = fixed % n, fixed // n
        return arrays, fragment, fixed, (c * nv + v)[v < nv]

    def _held_modes(self):
        """With fix_free_modes "all", the rows that hold the pieces, in the P1 layout (else None).

        Contact rows dependent on them would make the solve singular (a small piece with
        more contact rows than deformation modes)."""
        if self.options["fix_free_modes"] != "all":
            return None
        prob = self.problem
        modes = prob.support(prob.assemble_constraints()).modes.T.tocoo()
        nv, n = prob.mesh.nv, prob.fes.ndof // 2
        v, c = modes.col % n, modes.col // n
        keep = v < nv          # the modes live on the vertex dofs
        return sp.csr_matrix((modes.data[keep], (modes.row[keep], (c * nv + v)[keep])), shape=(modes.shape[0], 2 * nv))

    def _relinearised(self, pool, n_seam, seam_keys, seams, X, U):
        """The rows of pool (seam rows first) linearised at X + U, in the same order."""
        # both sides of every diagonal pair: the side chosen at the prediction is found by key
        fresh_seams, k = seam_constraints(seams, X, U, kink_angle=self.kink_angle, choose=False)
        where = {("s",) + tuple(r): i for i, r in enumerate(k.tolist())}
        # a seam row whose twins slid too far for a fresh one keeps its old linearisation
        present = [i for i, key in enumerate(seam_keys) if key in where]
        missing = [i for i, key in enumerate(seam_keys) if key not in where]
        seam_rows = contact.ContactConstraints.stack([
            fresh_seams.subset(np.array([where[seam_keys[i]] for i in present], dtype=np.int64)),
            pool.subset(np.array(missing, dtype=np.int64))])
        seam_rows = seam_rows.subset(np.argsort(np.array(present + missing, dtype=np.int64)))
        n2s = relinearise_node_to_segment(pool.subset(np.arange(n_seam, len(pool))), X, U)
        return contact.ContactConstraints.stack([seam_rows, n2s])

    def _contact_offset(self):
        offset = 0
        for C, _, label in self.problem.constraints.rows:
            if label == LABEL:
                return offset
            offset += C.shape[0]
        return offset

    def _node_to_segment(self, arrays, fragment, U, seams, matched, timings):
        """Rules 1-4 rows at X + U that the seams do not cover, with their keys."""
        X, T, E = arrays.points, arrays.triangles, arrays.segments
        t0 = time.perf_counter()
        pairs = detect_collisions(X, U, T, boundary_edges=E, fragment=fragment, tol=self.tol)
        timings["collision"] += time.perf_counter() - t0
        if len(pairs) == 0:
            return contact._no_constraints(len(X)), []
        cs = contact.select_contacts(X, U, T, E, pairs, tol=self.tol)
        keep = reachable(cs, U, self.tol)
        # a twin of a seam talks to the other lip through its seam rows only
        cid = seams.copy_id
        seam_edge = np.array([(min(a, c), max(a, c)) in seams.seam_edge
                              for a, c in zip(cs.a.tolist(), cs.c.tolist())], dtype=bool)
        own = (cid[cs.a] == cid[cs.slave]) | (cid[cs.c] == cid[cs.slave])
        keep &= ~(matched[cs.slave] & (seam_edge | own))
        cs = cs.subset(np.flatnonzero(keep))
        keys = [("n",) + k for k in zip(cs.slave.tolist(), cs.a.tolist(), cs.c.tolist())]
        return cs, keys

    def _complementarity(self, pool, candidates, fixed, nv, n, tangent, result):
        """The candidate rows closed in the exact solution of the linearised contact problem.

        With the tangent of the Newton solves the gaps respond linearly to the contact
        forces, g(lam) = q - S lam (S = C K^-1 C^T through the same constrained solver, so
        single-dof rows and the coarse problem of free modes count): a linear
        complementarity problem, which the dual active-set method solves in finitely many
        steps (see :meth:`kkt.ConstrainedSolver.solve_unilateral`). Candidates may be linearly
        dependent: at a junction five rows bound the relative motion of three copies (4
        dofs), and dropping one as dependent would drop its inequality (measured: it came
        back penetrated by 4e-6 and the set cycled). Returns pool indices, an independent
        set, or None if the problem cannot be solved (then the primal-dual update goes on).
        """
        t0 = time.perf_counter()
        prob = self.problem
        prob.constraints.clear_rows(LABEL)
        prob.constraints.add_rows(_space_columns(pool.C[candidates], nv, n), -pool.g[candidates], label=LABEL)
        offset = self._contact_offset()
        options = {k: v for k, v in self.options.items() if k != "load_steps"}
        try:
            _, closed = NewtonSolver(prob, tangent=tangent, **options).unilateral_multipliers(
                np.arange(offset, offset + len(candidates)))
        except (SingularSystem, QPError, np.linalg.LinAlgError, ValueError) as exc:
            # recorded: the set then comes from the primal-dual update, not the exact solution
            result.notes.append(f"complementarity problem of {len(candidates)} candidate rows not solved "
                                f"({type(exc).__name__}: {exc}); the primal-dual update chose the set")
            return None
        finally:
            prob.constraints.clear_rows(LABEL)
            result.timings["solve"] += time.perf_counter() - t0
        result.lcp += 1
        # the rows that press and those that touch without force: the latter place pieces
        # that no force holds where the solution has them (else their modes are frozen);
        # dependent ones hold with the others, as equalities they would make K singular
        choice = candidates[closed[offset:offset + len(candidates)]]
        return choice[contact.independent_rows(pool.C[choice], fixed_dofs=fixed, G=self._holds,
                                               rtol=self.rank_tol)] if len(choice) else choice

    def _newton(self, result, tangent, increment_scale=None):
        """One Newton solve with the current rows; later rounds pass the first solve's first
        increment (they correct that solve: eq. 7 is judged against the step, not the correction)."""
        t0 = time.perf_counter()
        status = self.problem.solve(tangent=tangent, increment_scale=increment_scale, **self.options)
        result.status = status
        result.notes.extend(n for n in status.notes if n not in result.notes)
        result.timings["solve"] += time.perf_counter() - t0
        for part, seconds in status.phase_seconds().items():
            result.timings[part] += seconds
        return status

    @single_threaded_blas()
    def solve(self, warm=(), lineage=None, start=None):
        """Solve for equilibrium with contact.

        The problem's rows labelled "contact" are replaced by the active set of each round
        and are those of the last solve at the end; the displacement is the solution of
        the last converged Newton solve.

        Parameters
        ----------
        warm : iterable of tuple, optional
            Keys of rows to start from (``ContactResult.active_keys`` of the solve before,
            on this mesh or on the mesh a crack pass split from it: old vertices keep their
            numbers). They enter the first round as active rows, linearised at the current
            state, and the prediction without contact rows is skipped. Only the path
            changes: the set still has to settle and pass the same tests. A warm start that
            fails is followed by the plain path from the same start (recorded in
            ``notes``). Empty: the plain predict-and-correct path.
        lineage : split_factor.Lineage, optional
            The problem's mesh was split from a solved one: its solves start from that
            factorisation, bordered by the split (see solver.SavedTangent).
        start : solver.SavedTangent, optional
            A factorised tangent of this mesh to start from (the solve before at another
            load, simulation.py); each start takes it afresh (``SavedTangent.kept``).

        Returns
        -------
        ContactResult
            Converged, or reason: the Newton reason of a failed solve, "active_set" when
            ``max_rounds`` rounds passed without a settled set, "penetration" when the
            settled rows still overlap and re-linearising them stopped contracting. Failures
            are not raised.
        """
        prob = self.problem
        uncracked = prob.fragments()[0] == 1 and "crack" not in prob.mesh.GetBoundaries()
        warm = set() if uncracked else set(warm)
        if not warm:
            return self._solve(warm, uncracked, lineage, start)
        u, load = prob.u.vec.FV().NumPy().copy(), prob.load_factor.Get()
        result = self._solve(warm, uncracked, lineage, start)
        if result.converged:
            return result
        # rows of the pass before can hold a shattered piece in a nearly singular way
        # (measured: a plate at critical strain 1e-12); the plain path decides then
        prob.u.vec.FV().NumPy()[:] = u
        prob.load_factor.Set(load)
        plain = self._solve(set(), uncracked, lineage, start)
        plain.notes.append(f"the warm start from {len(warm)} contact rows failed ({result.reason}); "
                           "solved from the prediction without rows")
        for phase, seconds in result.timings.items():
            plain.timings[phase] = plain.timings.get(phase, 0.0) + seconds
        return plain

    def _solve(self, warm, uncracked, lineage, start):
        """The solve of :meth:`solve` from the given warm keys (a set, maybe empty)."""
        prob = self.problem
        prob.constraints.clear_rows(LABEL)
        # the rounds are at the load of the prediction: they reuse its factorised tangent
        tangent = start.kept() if start is not None else SavedTangent(lineage)
        result = ContactResult(None, notes=list(self._notes), tangent=tangent)
        scale = None        # the first increment of the first solve
        if not warm:
            status = self._newton(result, tangent)
            scale = status.first_increment
            if not status.converged:
                result.reason = status.reason
                return result
            if uncracked:
                # one uncracked body cannot touch itself: no collision work at all
                result.converged, result.reason = True, "converged"
                return result
        t0 = time.perf_counter()
        arrays, fragment, fixed_all, fixed = self._geometry()
        self._holds = self._held_modes()
        seams = find_seams(arrays.points, arrays.segments)
        nv, n = prob.mesh.nv, prob.fes.ndof // 2
        result.timings["contact"] += time.perf_counter() - t0
        seam_rows, seam_keys = None, []
        n2s, n2s_keys = contact._no_constraints(nv), []
        lam = {}     # the rows imposed in the last solve (by key) and their multipliers
        imposed = set()                         # every set imposed so far
        tried = set()                           # every row imposed so far
        exact = False                           # the complementarity problem chooses the set
        force_scale = 0.0                       # the largest force of any round so far
        last_penetration = np.inf               # at the last re-linearisation
        moving = True        # rows re-linearised every round (until that stops contracting)
        for rnd in range(1, self.max_rounds + 1):
            result.rounds = rnd
            t0 = time.perf_counter()
            U = vertex_displacement(prob.u)
            at_U = None      # the rows of the last round, all linearised at U (when made)
            if seam_rows is None:
                # built once, at the predicted configuration, and frozen for this solve
                seam_rows, k = seam_constraints(seams, arrays.points, U, kink_angle=self.kink_angle)
                seam_keys = [("s",) + tuple(r) for r in k.tolist()]
                matched = np.zeros(nv, dtype=bool)
                matched[seam_rows.slave] = matched[seam_rows.a] = True
            elif moving and result.status is not None:
                # every row at the configuration just solved: the gaps the set update
                # judges are those of this configuration, to second order in the last step
                old = contact.ContactConstraints.stack([seam_rows, n2s])
                at_U = self._relinearised(old, len(seam_keys), seam_keys, seams, arrays.points, U)
                fresh = _refreshed(old, at_U, U, 0.01 * self.penetration_tol)
                seam_rows = fresh.subset(np.arange(len(seam_keys)))
                n2s = fresh.subset(np.arange(len(seam_keys), len(fresh)))
            # node-to-segment rows: a row keeps the linearisation it was found with while
            # it is active or detected again; new ones are linearised here
            found, found_keys = self._node_to_segment(arrays, fragment, U, seams, matched, result.timings)
            known, found_set = set(n2s_keys), set(found_keys)
            old = [i for i, k in enumerate(n2s_keys) if k in lam or k in found_set]
            new = [i for i, k in enumerate(found_keys) if k not in known]
            n2s = contact.ContactConstraints.stack([n2s.subset(old), found.subset(new)])
            n2s_keys = [n2s_keys[i] for i in old] + [found_keys[i] for i in new]
            pool = contact.ContactConstraints.stack([seam_rows, n2s])
            keys = seam_keys + n2s_keys
            gap = pool.C @ U.T.ravel() + pool.g
            # primal-dual active set: an active row stays while it pushes (lambda <= 0),
            # an inactive one enters when its node penetrates
            want = np.array([(lam[k] <= 0.0) if k in lam else (g < -self.penetration_tol or k in warm)
                             for k, g in zip(keys, gap)], dtype=bool)
            warm = set()     # a warm row that the solve releases is judged like any other
            want = np.flatnonzero(want)
            kept = want[contact.independent_rows(pool.C[want], fixed_dofs=fixed, G=self._holds, rtol=self.rank_tol)] \
                if want.size else want
            dependent = np.setdiff1d(want, kept)
            other = np.setdiff1d(np.arange(len(keys)), dependent)
            penetration = float(max(0.0, -gap[other].min(initial=0.0)))
            result.history.append((len(kept), penetration))
            result.timings["contact"] += time.perf_counter() - t0
            # settled: the set of the last solve again (none yet when started warm)
            settled = result.status is not None and set(keys[i] for i in kept) == set(lam)
            if moving and not settled:
                last_penetration = np.inf     # the contraction is judged at one set only
            if not settled and (exact or rnd > self.pdas_rounds or frozenset(keys[i] for i in kept) in imposed):
                # the update revisits a set: it cycles (rows with a response that is no
                # M-matrix, e.g. nearly parallel rows at a kink). From here on the set is
                # the exact solution of the complementarity problem of the linearisation.
                exact = True
                # candidates: the rows the update wants and every row imposed before
                candidates = np.union1d(want, np.array([i for i, k in enumerate(keys) if k in tried], dtype=np.int64))
                choice = self._complementarity(pool, candidates, fixed, nv, n, tangent, result)
                if choice is not None and set(keys[i] for i in choice) != set(lam):
                    kept = choice
            imposed.add(frozenset(keys[i] for i in kept))
            tried.update(keys[i] for i in kept)
            if settled:
                # settled for the rows as linearised; re-linearised at the solution, their
                # gaps are the true ones of this configuration
                t0 = time.perf_counter()
                if at_U is None:
                    fresh = self._relinearised(pool, len(seam_keys), seam_keys, seams, arrays.points, U)
                else:
                    # the rows of the last round were re-linearised at this U when the round
                    # began (a row re-linearised twice at one U is the same, bit for bit):
                    # only the rows found in this round are new
                    fresh = contact.ContactConstraints.stack([
                        at_U.subset(np.concatenate([np.arange(len(seam_keys)),
                                                    len(seam_keys) + np.array(old, dtype=np.int64)])),
                        relinearise_node_to_segment(found.subset(new), arrays.points, U)])
                gap = fresh.C @ U.T.ravel() + fresh.g
                penetration = float(max(0.0, -gap[other].min(initial=0.0)))
                result.timings["contact"] += time.perf_counter() - t0
                result.max_penetration = penetration
                if penetration <= self.penetration_tol:
                    result.converged, result.reason = True, "converged"
                    result.active_keys = sorted(lam)
                    return result
                if moving and penetration >= last_penetration and result.updates < self.max_updates:
                    # re-linearising every round went round in circles at this set: from
                    # here on the rows stay as linearised now, and the plain fixed point of
                    # updates at a settled set decides (and fails when it does not contract)
                    moving = False
                elif result.updates == self.max_updates or penetration >= last_penetration:
                    # the linearisations do not converge to a state without overlap (large
                    # relative motion for one solve): a failure, which a caller cures with
                    # a smaller step, not an overlap passed off as a solution
                    result.reason = "penetration"
                    return result
                last_penetration = penetration
                # a geometric fixed point: solve again with the rows linearised here
                # (the overlap falls from second to fourth order in the displacement)
                result.updates += 1
                pool = _refreshed(pool, fresh, U, 0.01 * self.penetration_tol)
                seam_rows = pool.subset(np.arange(len(seam_keys)))
                n2s = pool.subset(np.arange(len(seam_keys), len(keys)))
            cs = pool.subset(kept)
            cs.dist = gap[kept]
            prob.constraints.clear_rows(LABEL)
            if len(cs):
                # active: the linearised gap closes, C u + g = 0
                prob.constraints.add_rows(_space_columns(cs.C, nv, n), -cs.g, label=LABEL)
            status = self._newton(result, tangent, scale)
            scale = status.first_increment if scale is None else scale
            if not status.converged:
                result.reason = status.reason
                return result
            offset = self._contact_offset()
            multipliers = status.multipliers[offset:offset + len(cs)]
            # adhesive beyond rounding: relative to the largest force the constraints carried
            # in any round of this solve. A set that lets the pieces drift apart carries no
            # force at all; its multipliers are rounding noise of either sign, and measured
            # against themselves they made the set cycle (tutorial 5's broken beam).
            r = tangent.residual[2]     # the out-of-balance where the solve ended
            force_scale = max(force_scale, float(np.abs(multipliers).max(initial=0.0)),
                              float(np.linalg.norm(r[fixed_all])))
            rounded = np.where(np.abs(multipliers) <= 1e-10 * force_scale, 0.0, multipliers)
            result.released += int(np.count_nonzero(rounded > 0))
            lam = {keys[i]: x for i, x in zip(kept.tolist(), rounded.tolist())}
            result.constraints, result.multipliers = cs, multipliers
            result.max_penetration = penetration
        result.reason = "active_set"
        return result


def relinearise_node_to_segment(cs, X, U):
    """The rows of cs with normal and projection of the master edge at X + U (eq. 13, 14).

    Rows snapped to a node (xi = 0 or 1) stay node-to-node; the normal keeps its side.

    Parameters
    ----------
    cs : contact.ContactConstraints
        Node-to-segment rows (slave, master edge a -> c, previous xi and normal).
    X, U : numpy.ndarray, shape (nv, 2)
        Reference vertex coordinates and vertex displacements (current = X + U).

    Returns
    -------
    contact.ContactConstraints
        The same rows in the same order, with xi (clipped to [0, 1]), unit normal, dist
        (signed distance at X + U), C and g recomputed; slave, a, c, triangles, pair and
        angle kept. ``cs`` itself when it is empty.
    """
    if len(cs) == 0:
        return cs
    x = X + U
    e = x[cs.c] - x[cs.a]
    length2 = np.einsum("ij,ij->i", e, e)
    n = np.column_stack([e[:, 1], -e[:, 0]]) / np.sqrt(length2)[:, None]
    n *= np.where(np.einsum("ij,ij->i", n, cs.normal) < 0, -1.0, 1.0)[:, None]
    t = np.einsum("ij,ij->i", x[cs.slave] - x[cs.a], e) / length2
    xi = np.where((cs.xi == 0.0) | (cs.xi == 1.0), cs.xi, np.clip(1.0 - t, 0.0, 1.0))
    dist = np.einsum("ij,ij->i", x[cs.slave] - xi[:, None] * x[cs.a] - (1 - xi)[:, None] * x[cs.c], n)
    return contact.ContactConstraints(cs.slave, cs.a, cs.c, cs.master_tri, cs.slave_tri, cs.pair, xi, n,
                                      dist, cs.angle, contact._gap_offset(X, cs.slave, cs.a, cs.c, xi, n),
                                      nv=len(X))


def reachable(cs, U, tol):
    """Rows whose penetration the motion can explain.

    The reference mesh has no overlap, so a slave node cannot be deeper behind a master
    segment than it has moved relative to that segment (plus the threshold).  Deeper
    "penetrations" come from picking the wrong way out near crack tips and corners;
    imposing them would tear the mesh (measured: inverted elements), so they are dropped.

    Parameters
    ----------
    cs : contact.ContactConstraints
        Candidate rows, with ``dist`` at the current configuration.
    U : numpy.ndarray, shape (nv, 2)
        Vertex displacements.
    tol : float
        Detection threshold (a length) added to the relative motion.

    Returns
    -------
    numpy.ndarray of bool, shape (len(cs),)
        True where -dist <= |u_slave - xi u_a - (1 - xi) u_c| + tol.
    """
    if len(cs) == 0:
        return np.zeros(0, dtype=bool)
    xi = cs.xi[:, None]
    rel = U[cs.slave] - xi * U[cs.a] - (1.0 - xi) * U[cs.c]
    return -cs.dist <= np.linalg.norm(rel, axis=1) + tol


def overlap_area(x, triangles, pairs):
    """Total area of the intersections of the given triangle pairs (convex clipping).

    Parameters
    ----------
    x : numpy.ndarray (nv, 2)
        Current vertex positions.
    triangles : numpy.ndarray (ne, 3)
        Counter-clockwise triangles.
    pairs : numpy.ndarray (k, 2)
        Triangle pairs to intersect.

    Returns
    -------
    float
    """
    total = 0.0
    for i, j in np.asarray(pairs, dtype=np.int64).reshape(-1, 2):
        # relative to a vertex of the pair: areas from coordinates far from the origin
        # would carry the rounding of their products (2e-8 at 1e4), not of the overlap
        origin = x[triangles[j][0]]
        poly = [tuple(p) for p in x[triangles[i]] - origin]
        clip = x[triangles[j]] - origin
        if _signed_area(clip) < 0:
            clip = clip[::-1]
        for k in range(3):
            a, b = clip[k], clip[(k + 1) % 3]
            poly = _clip_half_plane(poly, a, b)
            if not poly:
                break
        if len(poly) >= 3:
            total += abs(_signed_area(np.array(poly)))
    return total


def _signed_area(p):
    p = np.asarray(p)
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def _clip_half_plane(poly, a, b):
    """Sutherland-Hodgman: the part of poly left of the directed line a -> b."""
    def side(p):
        return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    out = []
    for k in range(len(poly)):
        p, q = poly[k], poly[(k + 1) % len(poly)]
        sp_, sq = side(p), side(q)
        if sp_ >= 0:
            out.append(p)
        if sp_ * sq < 0:
            t = sp_ / (sp_ - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def fragment_overlap_area(problem):
    """Total overlap area between triangles of the current configuration (0 if none).

    Pairs are those of ``detect_collisions`` with tol = 0 on the true boundary segments
    (interiors overlapping; mesh neighbours in one fragment excepted), their intersection
    areas summed by :func:`overlap_area`.

    Parameters
    ----------
    problem : ElasticProblem
        Its mesh, fragments and displacement; only the vertex values of the displacement
        count (straight-sided triangles).

    Returns
    -------
    float
        Area, in the square of the mesh's length unit.
    """
    arrays = boundary_only(problem.arrays)
    U = vertex_displacement(problem.u)
    _, comp = problem.fragments()
    fragment = comp[arrays.triangles[:, 0]]
    pairs = detect_collisions(arrays.points, U, arrays.triangles, boundary_edges=arrays.segments,
                              fragment=fragment, tol=0.0)
    if len(pairs) == 0:
        return 0.0
    return overlap_area(arrays.points + U, arrays.triangles, pairs)
