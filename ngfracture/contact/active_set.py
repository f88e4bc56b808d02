"""The active set of a contact solve: candidate rows, their keys, and the set chosen among them.

:class:`ActiveSet` holds the state that the rounds of one :class:`~ngfracture.contact.solver.ContactSolver`
solve share; the solver runs the rounds (update the candidates, choose, judge, impose, solve).

Candidates (eq. 13, 14), each identified by a key (its nodes and facet):

- across seams, where two lips coincide in the reference configuration (crack faces from
  node splitting, interfaces from ``meshio.separate_region``), node-to-node rows between
  twins, built once at the first configuration of the solve (:mod:`ngfracture.contact.seams`);
- elsewhere, node-to-segment rows of the paper's rules 1-4 (:mod:`ngfracture.contact.rows`)
  found at the current configuration; a row stays a candidate while it is active or found
  again, and rows of a twin against its own seam are left out.

On coincident lips every node is at once a slave of the other lip and an end of its master
segments, and rounding decides which rows rules 1-4 give; with rows identified by keys the
candidate set of a seam is the same in every round, and the set update can settle.

Every round re-linearises the candidates at the configuration of the last solve, so the
update judges the gaps of that configuration and set and geometry settle together. A row
whose gap there is the same to a hundredth of ``penetration_tol`` under both linearisations
keeps its old one, bit for bit, and with it its cached Schur column
(``linalg.factor.FactorBase.columns``): lips that do not move cost no solve.

The choice is the primal-dual active set (semismooth Newton for the complementarity
function min(-lambda, g) of eq. 8, Hintermueller-Ito-Kunisch): an active row stays while
its multiplier compresses (lambda <= 0 up to rounding, as the paper's p_N <= 0); an
inactive row enters when its linearised gap is below -``penetration_tol``. Rows that depend
on others are dropped by the pivoted QR (:func:`ngfracture.contact.redundancy.independent_rows`).
The update converges when the response of the gaps to the contact forces, S = C K^-1 C^T,
is an M-matrix; nearly parallel rows at a kink are far from it, and the update cycles. When
it revisits a set, or has not settled after ``pdas_rounds`` rounds, the set is the exact
solution of the linear complementarity problem of the linearisation instead: one solution
for S positive definite, found in finitely many steps, at the cost of a dense problem on
the candidates, so only where the cheap update fails.

A set that equals the one of the last solve has settled for its rows as linearised; their
gaps re-linearised at that solution are the true ones. Where they still penetrate, the set
is solved again with those rows (an update). Where re-linearising every round stops
reducing the penetration at a settled set (rows sliding over a kink), the rows stay as they
are from then on and the plain fixed point of updates decides, which fails with reason
"penetration" when it does not contract.

Keys as integers. The set operations of a round (which rows have multipliers, whether the
chosen set is the last one or one imposed before, which rows were ever imposed) work on
one int64 code per key: equal codes for equal keys within one active set. Keys given as a
:class:`RowKeys` (the 3D candidates) carry their codes; for a plain list of tuples the
active set numbers the keys in the order it meets them. The multipliers dictionary of
tuples is made from the codes only when read (the solver reads it once, at convergence),
so a round costs no Python work per row.
"""
import time
from dataclasses import dataclass

import numpy as np

from .collision import detect_collisions
from .intsets import isin_ints, union_ints, unique_ints
from .redundancy import independent_rows
from .row_keys import RowKeys
from .rows import ContactConstraints, no_constraints, reachable, relinearise_node_to_segment, select_contacts
from .seams import KINK_ANGLE, seam_constraints

__all__ = ["Geometry", "Candidates", "ActiveSet", "max_penetration", "refreshed"]


@dataclass(frozen=True)
class Geometry:
    """What the rounds of a contact solve on one mesh share.

    Parameters
    ----------
    arrays : ngfracture.geometry.meshio.MeshArrays
        The mesh with its boundary and crack segments only (``meshio.boundary_only``).
    fragment : numpy.ndarray of int, shape (nt,)
        Fragment id per triangle.
    seams : ngfracture.contact.seams.Seams
        The coincident lips of the mesh.
    fixed : numpy.ndarray of int
        Dofs fixed by Dirichlet conditions, in the layout of the rows (comp * nv + v).
    holds : scipy.sparse.csr_matrix or None
        General rows kept in any case, in that layout: those holding the pieces on all
        their rigid modes (``fix_free_modes`` "all") and the problem's own general rows
        (None without either): contact rows dependent on them are dropped.
    """
    arrays: object
    fragment: np.ndarray
    seams: object
    fixed: np.ndarray
    holds: object = None


@dataclass
class Candidates:
    """The candidate rows of one round (made by :meth:`ActiveSet.update`).

    Parameters
    ----------
    rows : ngfracture.contact.rows.ContactConstraints or ngfracture.contact.mixed_rows.MixedRows
        Seam rows first, then node-to-segment rows (3D: node-to-face rows, then edge rows).
    keys : list of tuple or RowKeys
        The key of every row: ("s", lower twin, higher twin, kind) for seam rows,
        ("n", slave, a, c) for node-to-segment rows (3D: ("f", slave, master vertices
        sorted) and ("e", edge a, edge b), as :class:`RowKeys`).
    gap : numpy.ndarray, shape (len(rows),)
        The linearised gaps C u + g at the configuration of the round.
    relinearised : ngfracture.contact.rows.ContactConstraints or None
        The leading rows of ``rows`` (all but the node-to-segment rows found new in this
        round; 3D: of its node-to-face rows) linearised at the configuration of the round,
        where that was done when the round began; None where it was not.
    """
    rows: ContactConstraints
    keys: list
    gap: np.ndarray
    relinearised: object = None


def max_penetration(gap, rows):
    """The largest penetration among some rows.

    Parameters
    ----------
    gap : numpy.ndarray
        Linearised gaps (negative: penetration).
    rows : numpy.ndarray of int
        The rows that count.

    Returns
    -------
    float
        max(0, -min gap[rows]); 0 for no rows.
    """
    return float(max(0.0, -gap[rows].min(initial=0.0)))


def refreshed(old, fresh, U, limit):
    """The rows of ``fresh``, except where a row of ``old`` gives the same gap at U.

    Rows whose gaps at U under the two linearisations differ by at most ``limit`` keep
    their old linearisation, bit for bit, and with it their cached Schur column
    (``linalg.factor.FactorBase.columns``). Rows of lips that did not move are all of these; the
    final test of a settled set judges freshly linearised rows whatever was kept.

    Parameters
    ----------
    old, fresh : ContactConstraints, NodeToFaceRows, EdgeRows or MixedRows (contact.rows, rows3d, ...)
        The same rows (same order, same keys) in two linearisations.
    U : numpy.ndarray, shape (nv, 2) or (nv, 3)
        Vertex displacements.
    limit : float
        Largest difference of the two gaps (a length) that keeps the old row.

    Returns
    -------
    ngfracture.contact.rows.ContactConstraints
        The rows in the order of ``old``; ``old`` or ``fresh`` itself where all rows
        come from one of them.
    """
    u = U.T.ravel()
    drift = np.abs((fresh.C @ u + fresh.g) - (old.C @ u + old.g))
    keep = drift <= limit
    if keep.all():
        return old
    if not keep.any():
        return fresh
    kept, renewed = np.flatnonzero(keep), np.flatnonzero(~keep)
    rows = type(old).stack([old.subset(kept), fresh.subset(renewed)])
    return rows.subset(np.argsort(np.concatenate([kept, renewed])))


class ActiveSet:
    """The candidate contact rows of one solve, the multipliers of its last solve, and the
    bookkeeping of its rounds (see the module docstring).

    Parameters
    ----------
    geometry : Geometry
        The mesh, its seams and its fixed dofs.
    tol : float
        Detection threshold (a length) of the node-to-segment rows.
    penetration_tol : float
        Penetration depth (a length) that makes an inactive row enter, and that a settled
        set may leave.
    kink_angle : float
        Seam facets meeting at a larger angle (radians) get a row each at their node.
    rank_tol : float
        Rank threshold of :func:`~ngfracture.contact.redundancy.independent_rows`.
    pdas_rounds : int
        Rounds of the primal-dual update before the complementarity problem chooses.
    max_updates : int
        Re-linearisations of a settled set at most.
    warm : iterable of tuple, optional
        Keys of rows that enter the first choice as active. Non-empty: the solve starts
        from them instead of a solve without contact rows, so the first round has no solve
        before it and cannot settle.
    warm_exact : bool
        With ``warm`` rows: the complementarity problem chooses from the second round on, every
        row wanted in the solve among its candidates (docs/contact.md, warm increment solves).

    Attributes
    ----------
    multipliers : dict
        Key -> multiplier (<= 0: compressive; rounding noise set to 0) of every row
        imposed in the last solve.
    updates : int
        Re-linearisations of a settled set so far.
    """

    def __init__(self, geometry, tol, penetration_tol, kink_angle=KINK_ANGLE, rank_tol=1e-5, pdas_rounds=6,
                 max_updates=10, warm=(), warm_exact=False):
        self.geometry, self.rank_tol, self.max_updates = geometry, rank_tol, max_updates
        self.tol, self.penetration_tol, self.kink_angle = tol, penetration_tol, kink_angle
        self.warm = set(warm)                   # judged as active in the first choice only
        self.warm_exact = bool(warm_exact and self.warm)
        self.pdas_rounds = min(pdas_rounds, 1) if self.warm_exact else pdas_rounds
        self.solved = not self.warm             # the multipliers belong to a solve
        self.seam_rows, self.seam_keys = None, []
        self.matched = None                     # vertices with a seam row
        self.n2s, self.n2s_keys = no_constraints(len(geometry.arrays.points)), []
        self._ids = {}                          # key -> code, for keys given as tuples
        self._mult_codes = np.zeros(0, dtype=np.int64)   # codes of the last solve's rows, sorted
        self._mult_values = np.zeros(0)                  # their multipliers
        self._multipliers = {}                  # the dictionary, or (keys, kept, values) to make it from
        self.imposed = set()                    # every set imposed so far (sorted codes as bytes)
        self.tried = np.zeros(0, dtype=np.int64)         # codes of every row imposed so far, sorted
        self.wanted = np.zeros(0, dtype=np.int64)        # codes of every row wanted so far, sorted
        self.exact = False                      # the complementarity problem chooses the set
        self.released = None                    # codes of the rows the last one released, sorted
        self.force_scale = 0.0                  # the largest force of any solve so far
        self.moving = True                      # rows re-linearised every round
        self.last_penetration = np.inf          # at the last re-linearisation of a settled set
        self.updates = 0

    @property
    def multipliers(self):
        """Key -> multiplier of every row imposed in the last solve (dict, made when read)."""
        if isinstance(self._multipliers, tuple):
            keys, kept, values = self._multipliers
            self._multipliers = {keys[i]: x for i, x in zip(kept.tolist(), values.tolist())}
        return self._multipliers

    def _key_codes(self, keys):
        """The int64 code of every key given as a tuple: numbered in the order met."""
        ids = self._ids
        return np.fromiter((ids.setdefault(k, len(ids)) for k in keys), dtype=np.int64, count=len(keys))

    def _codes(self, keys):
        """The int64 code of every key (see the module docstring)."""
        if isinstance(keys, RowKeys):
            return keys.codes
        return self._key_codes(keys)

    def _has_multiplier(self, codes):
        """Per code: whether its row has a multiplier, and the multiplier (0 where not)."""
        if not len(self._mult_codes):
            return np.zeros(len(codes), dtype=bool), np.zeros(len(codes))
        at = np.minimum(np.searchsorted(self._mult_codes, codes), len(self._mult_codes) - 1)
        return self._mult_codes[at] == codes, self._mult_values[at]

    def update(self, U, timings):
        """The candidate rows at X + U, the configuration of the last solve.

        The first call builds the seam rows, frozen for the solve from then on; later calls
        re-linearise every candidate at U (while the rows move, see the module docstring).
        Node-to-segment rows found at U join; rows of the last update stay while they are
        active or found again, with the linearisation they have.

        Parameters
        ----------
        U : numpy.ndarray, shape (nv, 2)
            Vertex displacements.
        timings : dict
            Its "collision" entry gets the seconds of the collision detection.

        Returns
        -------
        Candidates
        """
        X = self.geometry.arrays.points
        relinearised = None
        if self.seam_rows is None:
            self.seam_rows, k = seam_constraints(self.geometry.seams, X, U, kink_angle=self.kink_angle)
            self.seam_keys = [("s",) + tuple(r) for r in k.tolist()]
            self.matched = np.zeros(len(X), dtype=bool)
            self.matched[self.seam_rows.slave] = self.matched[self.seam_rows.a] = True
        elif self.moving:
            # the gaps the set update judges are those of this configuration, to second
            # order in the last step
            old = ContactConstraints.stack([self.seam_rows, self.n2s])
            relinearised = self._relinearised(old, U)
            self.seam_rows, self.n2s = self._split(refreshed(old, relinearised, U, 0.01 * self.penetration_tol))
        found, found_keys = self._node_to_segment(U, timings)
        known, found_set = set(self.n2s_keys), set(found_keys)
        retained = [i for i, k in enumerate(self.n2s_keys) if k in self.multipliers or k in found_set]
        new = [i for i, k in enumerate(found_keys) if k not in known]
        self.n2s = ContactConstraints.stack([self.n2s.subset(retained), found.subset(new)])
        self.n2s_keys = [self.n2s_keys[i] for i in retained] + [found_keys[i] for i in new]
        rows = ContactConstraints.stack([self.seam_rows, self.n2s])
        if relinearised is not None:
            n_seam = len(self.seam_keys)
            relinearised = relinearised.subset(np.concatenate([np.arange(n_seam),
                                                               n_seam + np.array(retained, dtype=np.int64)]))
        return Candidates(rows, self.seam_keys + self.n2s_keys, rows.C @ U.T.ravel() + rows.g, relinearised)

    def primal_dual(self, candidates):
        """The rows the primal-dual update wants active, and an independent set of them.

        An active row stays while its multiplier compresses (<= 0), an inactive one enters
        when it penetrates by more than ``penetration_tol`` (or, in the first choice, when
        it is warm).

        Parameters
        ----------
        candidates : Candidates
            The candidates of this round.

        Returns
        -------
        want : numpy.ndarray of int
            The rows wanted active (indices into the candidates).
        kept : numpy.ndarray of int
            An independent subset of them (with the fixed dofs and holds), in order.
        other : numpy.ndarray of int
            All rows but the wanted ones that depend on the kept ones: those whose
            penetration counts.
        """
        codes = self._codes(candidates.keys)
        has, lam = self._has_multiplier(codes)
        enter = candidates.gap < -self.penetration_tol
        if self.warm:
            enter |= isin_ints(codes, self._key_codes(list(self.warm)))
        want = np.where(has, lam <= 0.0, enter)
        self.warm = set()        # a warm row that the solve releases is judged like any other
        want = np.flatnonzero(want)
        kept = self._independent(candidates.rows, want)
        dependent = np.zeros(len(candidates.keys), dtype=bool)
        dependent[want] = True
        dependent[kept] = False
        return want, kept, np.flatnonzero(~dependent)

    def choose(self, candidates, want, kept, round_number, complementarity):
        """The rows to impose next, and whether they are the set of the last solve.

        A set that has not settled is replaced by the closed rows of the complementarity
        problem when the update revisits a set, when ``round_number`` is past
        ``pdas_rounds``, and in every round after the first such choice. Then the set is
        settled when those closed rows are the rows of the last solve, whatever the signs of
        that solve's multipliers of dependent rows.

        Parameters
        ----------
        candidates : Candidates
            The candidates of this round.
        want, kept : numpy.ndarray of int
            From :meth:`primal_dual`.
        round_number : int
            The round of the solve, from 1.
        complementarity : callable
            ``complementarity(rows, indices, released)``: the indices (among those given) of
            the rows closed in the solution of the linear complementarity problem of
            ``rows[indices]``, or None where it could not be solved (then the primal-dual
            choice stands); ``released`` (bool per index) is the guess its solve starts from.

        Returns
        -------
        kept : numpy.ndarray of int
            The rows to impose (indices into the candidates), independent.
        settled : bool
            True if they are the rows imposed in the last solve.
        """
        codes = self._codes(candidates.keys)
        kept_codes = unique_ints(codes[kept])
        settled = self.solved and np.array_equal(kept_codes, self._mult_codes)
        self.wanted = union_ints(self.wanted, codes[want])
        if not settled and (self.exact or round_number > self.pdas_rounds
                            or kept_codes.tobytes() in self.imposed):
            self.exact = True
            choice = self._exact_choice(candidates, codes, want, complementarity)
            if choice is not None and not np.array_equal(choice[1], self._mult_codes) \
                    and choice[1].tobytes() in self.imposed:
                # a cycle: a vertex sliding over a master vertex is held by one face in one
                # set and by two others in the next, and the face the first set lets it
                # penetrate is wanted only at that set's state; every row wanted in the
                # solve becomes a candidate
                self.tried = union_ints(self.tried, self.wanted)
                choice = self._exact_choice(candidates, codes, want, complementarity) or choice
            if choice is not None:
                kept, kept_codes = choice
                # the exact solution keeps the last set: settled. Dependent rows share
                # their force in many ways; the share the solve's independent subset gave
                # can tension a row that the complementarity problem compresses, and the
                # update would release it and take it back, round after round
                settled = self.solved and np.array_equal(kept_codes, self._mult_codes)
        if not settled:
            # the contraction is judged at one set only: rows frozen at another set's solution
            # overlap to second order in the motion to this one, and their first update is
            # judged afresh
            self.last_penetration = np.inf
        self.imposed.add(kept_codes.tobytes())
        self.tried = union_ints(self.tried, kept_codes)
        return kept, settled

    def _exact_choice(self, candidates, codes, want, complementarity):
        """The closed rows of the complementarity problem of the wanted and tried rows (``warm_exact``:
        all wanted so far), made independent, and their sorted codes; None where it is not solved."""
        tried = np.flatnonzero(isin_ints(codes, union_ints(self.tried, self.wanted) if self.warm_exact else self.tried))
        indices = union_ints(want, tried)
        # the problem's start: the rows the problem before released (rounds meet almost the
        # same problem, and a start at its solution takes one sweep instead of the dual
        # method's steps), before the first one the rows the last solve did not impose
        released = (isin_ints(codes[indices], self.released) if self.released is not None
                    else ~isin_ints(codes[indices], self._mult_codes))
        closed = complementarity(candidates.rows, indices, released)
        if closed is None:
            return None
        self.released = unique_ints(codes[np.setdiff1d(indices, closed)])
        # closed rows that depend on others hold with them; as equalities they would make
        # the system singular
        kept = self._independent(candidates.rows, closed)
        return kept, unique_ints(codes[kept])

    def settle(self, candidates, other, U):
        """Judge a settled set by its candidates re-linearised at X + U.

        Parameters
        ----------
        candidates : Candidates
            The candidates of this round.
        other : numpy.ndarray of int
            The rows whose penetration counts (from :meth:`primal_dual`).
        U : numpy.ndarray, shape (nv, 2)
            The displacements of the last solve.

        Returns
        -------
        verdict : str
            "converged": no row penetrates by more than ``penetration_tol``; "update":
            solve the set again with the rows linearised at U; "penetration": the
            re-linearisations do not converge to a state without overlap (or
            ``max_updates`` of them did not), a failure that a smaller step cures.
        penetration : float
            The largest penetration of those rows at U.
        candidates : Candidates
            For "update", the candidates linearised at U (see :func:`refreshed`), with
            their fresh gaps; else the candidates given.
        """
        fresh = self._fresh_rows(candidates, U)
        gap = fresh.C @ U.T.ravel() + fresh.g
        penetration = max_penetration(gap, other)
        if penetration <= self.penetration_tol:
            return "converged", penetration, candidates
        if self.moving and penetration >= self.last_penetration and self.updates < self.max_updates:
            # re-linearising every round goes round in circles at this set: the rows stay
            # as linearised now, and the plain fixed point of updates decides
            self.moving = False
        elif self.updates == self.max_updates or penetration >= self.last_penetration:
            return "penetration", penetration, candidates
        self.last_penetration = penetration
        self.updates += 1
        # a geometric fixed point: the overlap falls from second to fourth order in the step
        rows = refreshed(candidates.rows, fresh, U, 0.01 * self.penetration_tol)
        self._keep_rows(rows)
        return "update", penetration, Candidates(rows, candidates.keys, gap)

    def record(self, keys, kept, multipliers, support_force):
        """Keep the multipliers of a solve of the rows ``kept``.

        A multiplier within 1e-10 of the largest force that the rows or the supports
        carried in any solve so far counts as zero: a set that lets the pieces drift apart
        carries no force at all, and its multipliers are rounding noise of either sign.

        Parameters
        ----------
        keys : list of tuple or RowKeys
            The keys of the candidates.
        kept : numpy.ndarray of int
            The rows imposed (indices into ``keys``).
        multipliers : numpy.ndarray
            Their multipliers.
        support_force : float
            The norm of the reaction at the fixed dofs.

        Returns
        -------
        int
            Rows released: multipliers adhesive (> 0) beyond rounding.
        """
        self.force_scale = max(self.force_scale, float(np.abs(multipliers).max(initial=0.0)), support_force)
        rounded = np.where(np.abs(multipliers) <= 1e-10 * self.force_scale, 0.0, multipliers)
        kept = np.asarray(kept, dtype=np.int64)
        codes = self._codes(keys)[kept]
        # a key met twice keeps its last multiplier, as a dictionary does
        self._mult_codes, last = np.unique(codes[::-1], return_index=True)
        self._mult_values = rounded[::-1][last]
        self._multipliers = (keys, kept, rounded)
        if not isinstance(keys, RowKeys):       # a list may change after the call
            self._multipliers = self.multipliers
        self.solved = True
        return int(np.count_nonzero(rounded > 0))

    def _independent(self, rows, indices):
        """The indices of an independent subset of rows[indices], with the fixed dofs and holds."""
        if not len(indices):
            return indices
        C = rows.C[indices]
        return indices[independent_rows(C, fixed_dofs=self.geometry.fixed, G=self._holds_for(C), rtol=self.rank_tol)]

    def _holds_for(self, C):
        """The rows kept in any case that the independence of the rows ``C`` is judged with."""
        return self.geometry.holds

    def _keep_rows(self, rows):
        """Keep the candidate rows ``rows`` (re-linearised) for the next update."""
        self.seam_rows, self.n2s = self._split(rows)

    def _split(self, rows):
        """Candidate rows as (seam rows, node-to-segment rows)."""
        n_seam = len(self.seam_keys)
        return rows.subset(np.arange(n_seam)), rows.subset(np.arange(n_seam, len(rows)))

    def _fresh_rows(self, candidates, U):
        """The candidate rows re-linearised at X + U, in their order (what settle judges)."""
        if candidates.relinearised is None:
            return self._relinearised(candidates.rows, U)
        # a row re-linearised twice at one U is the same, bit for bit: only the rows
        # found new in this round are not re-linearised yet
        n = len(candidates.relinearised)
        new = candidates.rows.subset(np.arange(n, len(candidates.rows)))
        return ContactConstraints.stack([candidates.relinearised,
                                         relinearise_node_to_segment(new, self.geometry.arrays.points, U)])

    def _relinearised(self, rows, U):
        """The candidate rows (seam rows first) linearised at X + U, in the same order."""
        X = self.geometry.arrays.points
        # both sides of every diagonal pair: the side chosen at the first update is found by key
        fresh_seams, k = seam_constraints(self.geometry.seams, X, U, kink_angle=self.kink_angle, choose=False)
        where = {("s",) + tuple(r): i for i, r in enumerate(k.tolist())}
        # a seam row whose twins slid too far for a fresh one keeps its old linearisation
        present = [i for i, key in enumerate(self.seam_keys) if key in where]
        missing = [i for i, key in enumerate(self.seam_keys) if key not in where]
        seam_rows = ContactConstraints.stack([
            fresh_seams.subset(np.array([where[self.seam_keys[i]] for i in present], dtype=np.int64)),
            rows.subset(np.array(missing, dtype=np.int64))])
        seam_rows = seam_rows.subset(np.argsort(np.array(present + missing, dtype=np.int64)))
        n2s = relinearise_node_to_segment(rows.subset(np.arange(len(self.seam_keys), len(rows))), X, U)
        return ContactConstraints.stack([seam_rows, n2s])

    def _node_to_segment(self, U, timings):
        """Rules 1-4 rows at X + U that the seams do not cover, with their keys."""
        X, T, E = self.geometry.arrays.points, self.geometry.arrays.triangles, self.geometry.arrays.segments
        t0 = time.perf_counter()
        pairs = detect_collisions(X, U, T, boundary_edges=E, fragment=self.geometry.fragment, tol=self.tol)
        timings["collision"] += time.perf_counter() - t0
        if len(pairs) == 0:
            return no_constraints(len(X)), []
        cs = select_contacts(X, U, T, E, pairs, tol=self.tol)
        keep = reachable(cs, U, self.tol)
        # a twin of a seam talks to the other lip through its seam rows only
        seams = self.geometry.seams
        cid = seams.copy_id
        seam_edge = np.array([(min(a, c), max(a, c)) in seams.seam_edge
                              for a, c in zip(cs.a.tolist(), cs.c.tolist())], dtype=bool)
        own = (cid[cs.a] == cid[cs.slave]) | (cid[cs.c] == cid[cs.slave])
        keep &= ~(self.matched[cs.slave] & (seam_edge | own))
        cs = cs.subset(np.flatnonzero(keep))
        keys = [("n",) + k for k in zip(cs.slave.tolist(), cs.a.tolist(), cs.c.tolist())]
        return cs, keys
