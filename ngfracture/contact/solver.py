"""Equilibrium with frictionless unilateral contact between pieces (paper eq. 8-14).

An active set around the Newton solver, in the paper's predict-and-correct manner:

1. solve without contact rows (free pieces held on their rigid modes): the prediction.
   A solve given the active rows of the solve before (``warm``: the previous crack pass
   or load step) imposes those instead and skips the prediction;
2. update the candidate rows at the configuration of the last solve and choose the active
   set among them (:class:`~ngfracture.contact.active_set.ActiveSet`: seam and
   node-to-segment rows identified by keys, the primal-dual update, and the linear
   complementarity problem where that cycles, solved here through the factorised
   tangent of the Newton solves);
3. if the set is the one of the last solve, judge it by its rows re-linearised at that
   solution: converged when none penetrates by more than ``penetration_tol``; else solve
   again with the rows linearised there (an update, at most ``max_updates``), or fail with
   reason "penetration" when the updates do not contract;
4. impose the set as equalities C u + g = 0 (eq. 12), solve, and go to 2.

At the end the Kuhn-Tucker conditions of eq. 8 hold to the solver tolerance for the rows
linearised at the solution: g_N >= -``penetration_tol``, lambda <= 0, lambda g_N = 0 (active
rows have g_N = 0, inactive ones carry no force). What overlap remains is that of the
polygonal lips between the rows' nodes, of second order in the last update. The
measurements behind these choices are in ``docs/contact.md``.

On a tetrahedral mesh (``problem.dim == 3``) the same rounds run with
:class:`~ngfracture.contact.active_set3d.ActiveSet3d` (node-to-face rows,
:mod:`ngfracture.contact.rows3d`, and edge-to-edge rows, :mod:`ngfracture.contact.edge_rows3d`),
rows in the three-component layout and six held rigid modes per free piece; ``tol`` then
only sets the default ``penetration_tol``, the depth of a crossing of two edges that
makes an edge row, max(``EDGE_TOL`` tol, ``penetration_tol``), and the depth behind a
plane at a copy of a point that makes a row there, max(``COPY_TOL`` tol,
``penetration_tol``); ``kink_angle`` has no role (docs/contact.md, "Contact in 3D runs",
"Edge-to-edge rows in 3D", "Rows at copies found by their planes").
"""
import functools
import math
import numbers
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .active_set import ActiveSet, Geometry, max_penetration
from .active_set3d import ActiveSet3d
from ..fracture.strain import vertex_displacement
from ..geometry.meshio import boundary_only
from .seams import KINK_ANGLE, find_seams
from ..linalg.factor import SingularSystem
from ..linalg.sparse import single_threaded_blas
from ..linalg.qp import QPError
from ..mechanics.newton import NewtonSolver, SolveStatus, check_solve_options, rewinder
from ..mechanics.tangent import SavedTangent

__all__ = ["ContactResult", "ContactSolver", "space_columns", "space_columns_3d", "LABEL", "PENETRATION_FRACTION"]

#: edges crossing by less than this fraction of ``tol`` (or ``penetration_tol``, the larger) get
#: no edge-to-edge row (3D; docs/contact.md, "Edge-to-edge rows in 3D")
EDGE_TOL = 1e-3

#: a copy behind a partner face at its copy, or a junction edge in a diagonal neighbour's
#: wedge, by less than this fraction of ``tol`` (or ``penetration_tol``, the larger) gets no
#: row of its own (3D; docs/contact.md, "Rows at copies found by their planes")
COPY_TOL = 1e-4

#: the default ``penetration_tol`` as a fraction of ``tol``, on triangles and on tetrahedra. In
#: 3D a point where several crack lips meet keeps penetrations of about 1e-12 that no
#: re-linearisation removes: a row at a copy holds its pair on one of two coincident faces,
#: and once the lips slide by d and the faces turn apart by an angle a the other face's
#: condition differs by |d| a; each update switches to the other face (docs/contact.md,
#: "Contact in 3D runs")
PENETRATION_FRACTION = {2: 1e-10, 3: 1e-7}

#: label of the problem's constraint rows that the contact solve owns
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
    timings, history, updates, lcp, notes, active_keys, tangent, factorisations
        Likewise; by default zero timings for the four phases, an empty history, 0, 0, no
        notes, no keys, no tangent, no factorisations.

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
    constraints : ngfracture.contact.rows.ContactConstraints
        The active constraints at the end: seam rows (master_tri = -1, a = c the master
        twin, slave its twin) and node-to-segment rows (3D: a
        :class:`~ngfracture.contact.mixed_rows.MixedRows` of node-to-face and edge rows).
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
        Re-linearisations of the rows at a settled solution (see ``max_updates`` of
        ContactSolver).
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
    tangent : ngfracture.mechanics.tangent.SavedTangent or None
        The factorisation the solve ended with (the lineage of a mesh split from this
        one, ``linalg.bordered.lineage``).
    factorisations : list of dict
        The solver choice of every K^+ its Newton solves made (SolveStatus.factorisations).
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
    factorisations: list = field(default_factory=list)

    def __bool__(self):
        return self.converged


class ContactSolver:
    """Newton solves with an active set of seam and node-to-segment contact constraints.

    Parameters
    ----------
    problem : ElasticProblem
    tol : float
        Precision threshold of the detection (a length): pairs closer than tol count,
        and slave nodes within tol of a master segment can get a constraint.
    penetration_tol : float, optional
        Penetration depth accepted at the end (a length); None: ``PENETRATION_FRACTION``
        times tol (1e-10 on triangles, 1e-7 on tetrahedra).
    max_rounds : int
        Detect-and-solve rounds before giving up with reason "active_set".
    rank_tol : float
        Rows closer than this (relative) to the span of the kept rows are dropped as
        redundant. A smaller value keeps near-duplicate lip rows, which make the Schur
        complement so ill-conditioned that Newton stalls.
    max_updates : int
        Solves of a settled active set again at most. A row linearised at the last solve
        (eq. 13/14) still lets the next solution overlap to second order in that solve's
        motion. When the gaps at the solution penetrate by more than penetration_tol, the
        set is solved again with its rows linearised there (same rows, current normals and
        projections); this fixed point contracts fast where the step is small enough. Once
        the rows are frozen (see :mod:`ngfracture.contact.active_set`), an update that does
        not reduce the penetration, or ``max_updates`` of them, end the solve with reason
        "penetration".
    kink_angle : float
        Seam facets meeting at a larger angle (radians, in the reference configuration)
        get a row each at their common node (see :mod:`ngfracture.contact.seams`). The
        default (1e-6) keeps every kink: the exact non-penetration of the polygonal lips. A
        large value (pi) gives one row with the mean normal per node: overlap first order
        in the slip, and a body held only by contact on a faceted circle then has a nearly
        free rotation, on which Newton does not converge.
    pdas_rounds : int
        Rounds of the primal-dual update before the set is chosen by the complementarity
        problem (also chosen so at once when the update revisits a set). Where the update
        converges, it settles within a few rounds (``docs/contact.md``).
    warm_exact : bool or None
        A warm-started solve lets the complementarity problem choose from its second round,
        with every row wanted in the solve among its candidates (ActiveSet's
        ``warm_exact``). For warm rows of a solve on the same mesh: rows carried over a crack
        pass can hold a vertex on the plane of a face that no longer bounds it, and a run's
        relaxation solves pass False (``run/step.py``). None (default): on tetrahedral
        meshes, where it takes the default sphere's increment solves from 10 to 12 rounds to
        6 or 7 (``docs/contact.md``, "Rounds of a warm increment solve"); triangular meshes
        keep the primal-dual rounds (not measured there).
    setups : ngfracture.contact.setup3d.MeshSetups, optional
        In 3D, the set-up of the mesh (fixed rows, detector, copy index) from an earlier
        solve on the same arrays, and where this solve's is kept for the next; without it
        each solve makes its own. Results do not depend on it.
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
        ``max_updates`` or ``pdas_rounds`` not an integer (>= 1, >= 0, >= 0); ``warm_exact``
        not None, False or True;
        ``rank_tol`` not in (0, 1); ``kink_angle`` not in [0, pi]; ``fix_free_modes`` not
        False, True or "all"; an unknown ``method``, ``linear_solver`` or ``inverse``.
    """

    def __init__(self, problem, tol, penetration_tol=None, max_rounds=20, rank_tol=1e-5, max_updates=10,
                 kink_angle=KINK_ANGLE, pdas_rounds=6, warm_exact=None, setups=None, **solve_options):
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
        if warm_exact not in (None, False, True):
            raise ValueError(f"ContactSolver warm_exact must be None, False or True, got {warm_exact!r}")
        fix = solve_options.get("fix_free_modes", True)
        if fix not in (False, True, "all"):
            raise ValueError(f"fix_free_modes must be False, True or 'all', got {fix!r}")
        check_solve_options(solve_options)
        #: departures from the plain path known at construction, copied into every result
        self._notes = (["fix_free_modes=False was turned into True: with contact, free pieces are "
                        "held on the rigid modes contact leaves free"] if fix is False else [])
        self.problem = problem
        self.tol = float(tol)
        self.penetration_tol = (PENETRATION_FRACTION[problem.dim] * max(self.tol, 1e-300) if penetration_tol is None
                                else penetration_tol)
        self.max_rounds = max_rounds
        self.rank_tol = rank_tol
        self.max_updates = max_updates
        self.kink_angle = kink_angle
        self.pdas_rounds = pdas_rounds
        self.warm_exact = problem.dim == 3 if warm_exact is None else warm_exact
        self.setups = setups
        self.options = dict(solve_options)
        self.options["fix_free_modes"] = "all" if self.options.get("fix_free_modes") == "all" else True

    def _geometry(self):
        """The geometry of the rounds, and the fixed dofs in the space's layout.

        None of it changes while the problem is solved on one mesh: computed once per solve.
        In 3D the arrays are the problem's tetrahedral mesh (its faces are the boundary and
        crack faces), the fragment is given per tetrahedron and there are no 2D seams.
        """
        prob = self.problem
        dim = prob.dim
        _, comp = prob.fragments()
        nv, n = prob.mesh.nv, prob.fes.ndof // dim
        fixed = prob.assemble_constraints().fixed_dofs
        v, c = fixed % n, fixed // n
        holds = self._rows_kept_in_any_case()
        if dim == 3:
            arrays = prob.arrays
            geometry = Geometry(arrays=arrays, fragment=comp[arrays.tets[:, 0]], seams=None,
                                fixed=(c * nv + v)[v < nv], holds=holds)
            return geometry, fixed
        arrays = boundary_only(prob.arrays)   # no bonded-interface segments
        geometry = Geometry(arrays=arrays, fragment=comp[arrays.triangles[:, 0]],
                            seams=find_seams(arrays.points, arrays.segments), fixed=(c * nv + v)[v < nv],
                            holds=holds)
        return geometry, fixed

    def _rows_kept_in_any_case(self):
        """The general rows that contact rows must be independent of, in the P1 layout (or None).

        With fix_free_modes "all", the rows that hold the pieces; and the problem's own
        general rows (the sphere scenes' stick rows). Contact rows dependent on them would
        make the solve singular: a small piece with more contact rows than deformation
        modes; at a point of three copies (a core vertex tied tangentially to one glass
        copy, the other glass copy with a row on every partner face) six rows on the six
        relative dofs of the copies whose normals leave one direction free."""
        prob = self.problem
        dim = prob.dim
        nv, n = prob.mesh.nv, prob.fes.ndof // dim
        blocks = []
        if self.options["fix_free_modes"] == "all":
            blocks.append(prob.support(prob.assemble_constraints()).modes.T.tocoo())
        blocks += [sp.coo_matrix(C) for C, _, label in prob.constraints.rows if label != LABEL]
        if not blocks:
            return None
        rows = sp.vstack(blocks).tocoo()
        v, c = rows.col % n, rows.col // n
        keep = v < nv          # the modes and the scenes' rows live on the vertex dofs
        return sp.csr_matrix((rows.data[keep], (rows.row[keep], (c * nv + v)[keep])), shape=(rows.shape[0], dim * nv))

    def _active_set(self, geometry, warm):
        """The active set of a solve: ActiveSet on triangles, ActiveSet3d on tetrahedra."""
        options = dict(rank_tol=self.rank_tol, pdas_rounds=self.pdas_rounds, max_updates=self.max_updates, warm=warm,
                       warm_exact=self.warm_exact)
        if self.problem.dim == 3:
            return ActiveSet3d(geometry, self.penetration_tol, setups=self.setups,
                               edge_tol=max(EDGE_TOL * self.tol, self.penetration_tol),
                               copy_tol=max(COPY_TOL * self.tol, self.penetration_tol), **options)
        return ActiveSet(geometry, self.tol, self.penetration_tol, kink_angle=self.kink_angle, **options)

    def _columns(self, C):
        """Rows in the P1 layout moved to the space's layout (2 or 3 components)."""
        prob = self.problem
        if prob.dim == 3:
            return space_columns_3d(C, prob.mesh.nv, prob.fes.ndof // 3)
        return space_columns(C, prob.mesh.nv, prob.fes.ndof // 2)

    def _contact_offset(self):
        offset = 0
        for C, _, label in self.problem.constraints.rows:
            if label == LABEL:
                return offset
            offset += C.shape[0]
        return offset

    def _impose(self, rows):
        """Make ``rows`` (P1 layout) the problem's contact rows, as equalities C u + g = 0."""
        prob = self.problem
        prob.constraints.clear_rows(LABEL)
        if len(rows):
            prob.constraints.add_rows(self._columns(rows.C), -rows.g, label=LABEL)

    def _complementarity(self, rows, candidates, released, tangent, result):
        """The candidate rows closed in the exact solution of the linearised contact problem.

        With the tangent of the Newton solves the gaps respond linearly to the contact
        forces, g(lam) = q - S lam (S = C K^-1 C^T through the same constrained solver, so
        single-dof rows and the coarse problem of free modes count): a linear
        complementarity problem, which the dual active-set method solves in finitely many
        steps (see :meth:`kkt.ConstrainedSolver.solve_unilateral`). Candidates may be
        linearly dependent: at a junction five rows bound the relative motion of three
        copies (4 dofs), and dropping one as dependent would drop its inequality. Closed
        rows are those that press and those that touch without force: the latter place
        pieces that no force holds where the solution has them (else their modes are
        frozen). ``released`` (bool per candidate) is the guess the problem's solve starts
        from. Returns indices among ``candidates`` (of ``rows``), or None if the problem
        cannot be solved (recorded in ``result.notes``; the primal-dual update goes on).
        """
        t0 = time.perf_counter()
        prob = self.problem
        prob.constraints.clear_rows(LABEL)
        prob.constraints.add_rows(self._columns(rows.C[candidates]), -rows.g[candidates], label=LABEL)
        offset = self._contact_offset()
        options = {k: v for k, v in self.options.items() if k != "load_steps"}
        try:
            _, closed, fallback = NewtonSolver(prob, tangent=tangent, **options).unilateral_multipliers(
                np.arange(offset, offset + len(candidates)), released)
        except (SingularSystem, QPError, np.linalg.LinAlgError, ValueError) as exc:
            # recorded: the set then comes from the primal-dual update, not the exact solution
            result.notes.append(f"complementarity problem of {len(candidates)} candidate rows not solved "
                                f"({type(exc).__name__}: {exc}); the primal-dual update chose the set")
            return None
        finally:
            prob.constraints.clear_rows(LABEL)
            result.timings["solve"] += time.perf_counter() - t0
        result.lcp += 1
        if fallback:
            result.notes.append(f"complementarity problem of {len(candidates)} candidate rows: {fallback}")
        return candidates[closed[offset:offset + len(candidates)]]

    def _newton(self, result, tangent, increment_scale=None):
        """One Newton solve with the current rows, recorded in ``result``; later rounds pass
        the first solve's first increment (see :meth:`_rounds`)."""
        t0 = time.perf_counter()
        status = self.problem.solve(tangent=tangent, increment_scale=increment_scale, **self.options)
        result.status = status
        result.factorisations.extend(status.factorisations)
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
        lineage : ngfracture.linalg.bordered.Lineage, optional
            The problem's mesh was split from a solved one: its solves start from that
            factorisation, bordered by the split (see mechanics.tangent.SavedTangent).
        start : ngfracture.mechanics.tangent.SavedTangent, optional
            A factorised tangent of this mesh to start from (the solve before at another
            load, run/tangents.py); each start takes it afresh (``SavedTangent.kept``).

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
        rewind = rewinder(prob)
        result = self._solve(warm, uncracked, lineage, start)
        if result.converged:
            return result
        # rows of the pass before can hold a shattered piece in a nearly singular way
        # (docs/contact.md); the plain path decides then
        rewind()
        plain = self._solve(set(), uncracked, lineage, start)
        plain.notes.append(f"the warm start from {len(warm)} contact rows failed ({result.reason}); "
                           "solved from the prediction without rows")
        for phase, seconds in result.timings.items():
            plain.timings[phase] = plain.timings.get(phase, 0.0) + seconds
        plain.factorisations[:0] = result.factorisations
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
        geometry, fixed = self._geometry()
        active = self._active_set(geometry, warm)
        result.timings["contact"] += time.perf_counter() - t0
        return self._rounds(active, result, tangent, scale, fixed)

    def _rounds(self, active, result, tangent, scale, fixed):
        """The rounds of :meth:`_solve`: update the candidates, choose, judge, impose, solve.

        ``scale`` is the first increment of the first solve (None before it: later solves
        correct that one, and eq. 7 is judged against the step, not the correction);
        ``fixed`` are the fixed dofs, whose reactions are a force scale of the multipliers.
        """
        prob = self.problem
        complementarity = functools.partial(self._complementarity, tangent=tangent, result=result)
        for rnd in range(1, self.max_rounds + 1):
            result.rounds = rnd
            t0 = time.perf_counter()
            U = vertex_displacement(prob.u)
            candidates = active.update(U, result.timings)
            want, kept, other = active.primal_dual(candidates)
            penetration = max_penetration(candidates.gap, other)
            result.history.append((len(kept), penetration))
            result.timings["contact"] += time.perf_counter() - t0
            kept, settled = active.choose(candidates, want, kept, rnd, complementarity)
            if settled:
                t0 = time.perf_counter()
                verdict, penetration, candidates = active.settle(candidates, other, U)
                result.timings["contact"] += time.perf_counter() - t0
                result.max_penetration, result.updates = penetration, active.updates
                if verdict != "update":
                    if verdict == "converged":
                        result.converged, result.active_keys = True, sorted(active.multipliers)
                    result.reason = verdict
                    return result
            cs = candidates.rows.subset(kept)
            cs.dist = candidates.gap[kept]
            self._impose(cs)
            status = self._newton(result, tangent, scale)
            scale = status.first_increment if scale is None else scale
            if not status.converged:
                result.reason = status.reason
                return result
            offset = self._contact_offset()
            multipliers = status.multipliers[offset:offset + len(cs)]
            reaction = float(np.linalg.norm(tangent.residual[2][fixed]))  # out-of-balance where the solve ended
            result.released += active.record(candidates.keys, kept, multipliers, reaction)
            result.constraints, result.multipliers = cs, multipliers
            result.max_penetration = penetration
        result.reason = "active_set"
        return result


def space_columns(C, nv, n):
    """Contact rows with their columns moved from the P1 layout to the space's layout.

    Parameters
    ----------
    C : scipy.sparse matrix, shape (m, 2 nv)
        Rows in the P1 layout: the dof of component comp of vertex v is comp * nv + v.
    nv : int
        Number of vertices.
    n : int
        Dofs per component of the space (``fes.ndof // 2``; n >= nv, the vertex dofs first).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (m, 2 n)
        The same rows, column comp * nv + v moved to comp * n + v.
    """
    C = sp.csr_matrix(C)
    cols = C.indices
    mapped = np.where(cols < nv, cols, cols - nv + n)
    return sp.csr_matrix((C.data, mapped, C.indptr), shape=(C.shape[0], 2 * n))


def space_columns_3d(C, nv, n):
    """Rows with their columns moved from the P1 layout (comp * nv + v) to the space's (comp * n + v).

    Parameters
    ----------
    C : scipy.sparse matrix, shape (m, 3 nv)
        Rows in the P1 layout.
    nv : int
        Number of vertices.
    n : int
        Dofs per component of the space (``fes.ndof // 3``; n >= nv, the vertex dofs first).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (m, 3 n)

    Raises
    ------
    ValueError
        If C does not have 3 nv columns or n < nv.
    """
    C = sp.csr_matrix(C)
    if C.shape[1] != 3 * nv or n < nv:
        raise ValueError(f"space_columns_3d: C has {C.shape[1]} columns, expected 3 nv = {3 * nv} (n = {n})")
    comp, v = np.divmod(C.indices, nv)
    return sp.csr_matrix((C.data, comp * n + v, C.indptr), shape=(C.shape[0], 3 * n))
