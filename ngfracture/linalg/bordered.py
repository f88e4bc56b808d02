"""K^+ of a split mesh from the factorisation of the mesh it was split from.

A crack pass splits a vertex and the equilibrium at the same load is solved again on the
new mesh: its tangent differs from the one factorised before the pass only by the border
of the split. Let the split mesh's displacement be written as

    u = E x + J d,

x on the dofs of the mesh the chain of splits started from (the base: E copies every
vertex's parent, so a new vertex moves with the vertex it was split from) and d the jump
of every new vertex against its parent (J puts it on the new vertex). With the new mesh's
tangent K~ taken at the base state carried over (every element, triangle or
tetrahedron, keeps its vertices' displacements, so its element matrix is the base's), the
system in (x, d) is

    [ A    B ] [x]   [E^T b]        A = E^T K~ E = the base tangent (factorised),
    [ B^T  D ] [d] = [J^T b],       B = E^T K~ J, D = J^T K~ J,

and eliminating d needs only Z = A^-1 B (a column per free dof of a new vertex, kept from
one pass to the next) and the small dense S_d = D - B^T Z: one base solve per solve. The
columns a pass adds are solved in one block with the first right-hand side it meets. General
rows C become C E and C J, and C K~^+ C^T = (C E) A^-1 (C E)^T + W S_d^-1 W^T with
W = (C E) Z - C J: the base's sparse Schur complement plus a rank-m term. In 3D that is
the base's K^-1 on the rows' dofs (factor.EliminatedFactor ``schur_by_dofs``), kept on the
base along the chain: C E puts a new vertex's entries on its parent's dofs, so a pass adds
few dofs to it and rebuilds nothing.

Modified Newton iterates with K~ (the tangent of the base state) as it iterates with the
tangent of the start of its load step; the residual is the new mesh's own. A border
larger than :func:`border_capacity` dofs, fixed dofs or pins that do not carry over (a new
fragment, a split on a constrained boundary with a free parent) take a fresh
factorisation instead (:func:`BorderedFactor.build` returns None), as does a small mesh
(``MIN_BASE_DOFS``), where a factorisation is cheaper than the bookkeeping. A border that
its first solve finds singular (S_d; no case is known where build accepts one) makes the
solve start again with the split mesh's own factorisation (mechanics.newton.NewtonSolver.solve,
recorded in its notes).
"""
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .factor import EliminatedFactor, FactorBase, SingularSystem

#: below this many factorised dofs a split mesh is factorised afresh: a factorisation costs
#: about as much as the bordered solves' bookkeeping, and a fresh tangent saves Newton
#: iterations where contact moves pieces far. docs/solvers.md, "Bordered factorisation"
MIN_BASE_DOFS = 2500

#: free dofs of the vertices created since the base factorisation beyond which a split mesh
#: is factorised afresh: every solve costs n x m more for Z d (see docs/performance.md) ...
MAX_BORDER = 240

#: ... and Z (n x m) is kept below this many entries (64 MB): 240 columns up to 35k base dofs
MAX_BORDER_ENTRIES = 8_000_000


def border_capacity(n_base):
    """The largest border kept for a base of ``n_base`` factorised dofs.

    Parameters
    ----------
    n_base : int

    Returns
    -------
    int
        ``MAX_BORDER``, or fewer where Z would exceed ``MAX_BORDER_ENTRIES`` (at least 16).
    """
    return max(16, min(MAX_BORDER, MAX_BORDER_ENTRIES // max(n_base, 1)))


@dataclass
class Lineage:
    """What a mesh split from a factorised one inherits.

    Parameters
    ----------
    base, state, parent, columns
        The attributes below.

    Attributes
    ----------
    base : factor.EliminatedFactor
        The factorisation of the mesh the chain of splits started from.
    state : numpy.ndarray
        The base mesh's displacement at which that tangent was assembled.
    parent : numpy.ndarray of int
        For every vertex of the split mesh, the base vertex it copies (itself for base vertices).
    columns : BorderColumns or None
        Z of the mesh before.
    """
    base: EliminatedFactor
    state: np.ndarray
    parent: np.ndarray
    columns: object = None


@dataclass
class BorderColumns:
    """Z = A^-1 B of a chain of splits, one column per border dof.

    New vertices have higher numbers and a border is ordered by (vertex, component), so the
    border of the next mesh starts with this one's dofs: its columns are updated in the same
    buffer, solved again only where their column of B changed, and the new ones appended.
    A neighbour's split leaves a column as it was: E^T sums the new vertex's couplings with
    both copies of the neighbour into the same base dofs, and each element keeps its element
    matrix. A chain has one buffer; only its latest factor may solve
    (``chain["latest"]`` is that factor's ``generation``; an earlier one refuses), and only
    the latest factor's columns are carried on (a factor built twice from one lineage, a
    contact solve's second start, leaves its parent's columns stale: the next one starts a
    buffer of its own).

    Parameters
    ----------
    keys, column_keys, buffer, chain, generation, unsolved
        The attributes below.

    Attributes
    ----------
    keys : list of (int, int)
        (vertex, component) of every column.
    column_keys : list of bytes
        The column of B it was solved for (indices and values).
    buffer : numpy.ndarray, shape (n, capacity), Fortran order
        Columns 0 .. len(keys) - 1 are Z.
    chain : dict
        Shared by the chain: {"latest": generation of its latest factor, "made": number of
        factors made}.
    generation : int
    unsolved : list of int
        Columns whose Z is not in the buffer yet (BorderedFactor solves them with its first
        right-hand side).
    """
    keys: list
    column_keys: list
    buffer: np.ndarray = field(repr=False)
    chain: dict = field(default_factory=lambda: {"latest": 0, "made": 1})
    generation: int = 0
    unsolved: list = field(default_factory=list)


def lineage(factor, state, parent):
    """What the mesh split from one solved with ``factor`` inherits (None: nothing to carry).

    Parameters
    ----------
    factor : factor.EliminatedFactor, BorderedFactor or None
        The factorisation the last solve on the mesh before the split used.
    state : numpy.ndarray or None
        For an EliminatedFactor, the displacement its tangent was assembled at.
    parent : numpy.ndarray of int
        ``split.SplitResult.parent``: for every vertex of the split mesh, the vertex it copies.

    Returns
    -------
    Lineage or None
    """
    if isinstance(factor, BorderedFactor):
        return Lineage(factor.base, factor.base_state, factor.parent[parent], factor.z_columns)
    if isinstance(factor, EliminatedFactor) and factor.linear_solver == "direct" and state is not None:
        return Lineage(factor, np.asarray(state), np.asarray(parent, dtype=np.int64))
    return None


def _sparse_times_rows(A, Z):
    """A @ Z for a CSR matrix A and a dense Z in any memory order: the rows of Z that A
    reads, weighted and summed (scipy's product copies all of Z first); a matrix with an
    empty row takes scipy's product."""
    if A.shape[0] == 0:
        return np.zeros((0, Z.shape[1]))
    if np.any(np.diff(A.indptr) == 0):
        return A @ np.ascontiguousarray(Z)
    return np.add.reduceat(Z[A.indices] * A.data[:, None], A.indptr[:-1], axis=0)


def _lifted(state, parent, dim):
    """The base state on the split mesh: every vertex takes its parent's displacement
    (``dim`` components, component-major)."""
    return state.reshape(dim, -1)[:, parent].reshape(-1)


class BorderedFactor(FactorBase):
    """K~^+ of a split mesh through the factorisation of its base (see the module docstring).

    Made by :meth:`build`. The interface of factor.EliminatedFactor that kkt.ConstrainedSolver
    uses: ``solve``, ``columns``, ``schur`` (when the base has the sparse Schur path),
    ``corrected_modes``, ``matches``.

    Parameters
    ----------
    lineage : Lineage
    K : scipy.sparse.csr_matrix
        The split mesh's tangent at the base state carried over (K~).
    fixed_dofs, pins : numpy.ndarray of int
        Of the solve on the split mesh.
    free, factor_free : numpy.ndarray of bool
        Dofs not fixed; neither fixed nor pinned.
    base_dof : numpy.ndarray of int
        For every dof of the split mesh, the base dof it copies.
    """

    linear_solver = "direct"
    factorised = True

    @classmethod
    def build(cls, lineage, problem, fixed_dofs, pins):
        """The bordered factor of ``problem``'s mesh, or None where it does not apply.

        Parameters
        ----------
        lineage : Lineage
        problem : ElasticProblem
            On the split mesh (its vertices: those of the base, then the new ones), 2D or
            3D: ``problem.dim`` dofs per vertex, component-major.
        fixed_dofs, pins : numpy.ndarray of int
            Of the solve on the split mesh.

        Returns
        -------
        BorderedFactor or None
            None if the base has fewer than ``MIN_BASE_DOFS`` factorised dofs, the fixed
            dofs or pins do not carry over from the base, or the border exceeds
            :func:`border_capacity` dofs.
        """
        base = lineage.base
        n_base = np.count_nonzero(base.factor_free)
        if n_base < MIN_BASE_DOFS:
            return None
        dim = problem.dim
        nv, nvb = problem.fes.ndof // dim, base.ndof // dim
        parent = lineage.parent
        if (len(parent) != nv or nv < nvb or base.ndof != dim * nvb
                or not np.array_equal(parent[:nvb], np.arange(nvb))):
            return None
        fixed_dofs = np.asarray(fixed_dofs, dtype=np.int64)
        pins = np.asarray(pins, dtype=np.int64)
        free = np.ones(dim * nv, dtype=bool)
        free[fixed_dofs] = False
        factor_free = free.copy()
        factor_free[pins] = False
        # base vertices keep their constraints and pins; a new vertex is free only where its parent is
        old = (np.arange(dim)[:, None] * nv + np.arange(nvb)).reshape(-1)
        if (not np.array_equal(free[old], base.free) or not np.array_equal(factor_free[old], base.factor_free)):
            return None
        base_dof = np.repeat(np.arange(dim), nv) * nvb + np.tile(parent, dim)
        new_vertex = np.tile(np.arange(nv) >= nvb, dim)
        if (np.any(factor_free & ~base.factor_free[base_dof]) or np.any(~free & base.free[base_dof])
                or np.any(free & ~factor_free & new_vertex)):
            return None
        if np.count_nonzero(factor_free) - n_base > border_capacity(n_base):
            return None
        K = problem.tangent(_lifted(lineage.state, parent, dim))
        return cls(lineage, K, fixed_dofs, pins, free, factor_free, base_dof)

    def __init__(self, lineage, K, fixed_dofs, pins, free, factor_free, base_dof):
        t0 = time.perf_counter()
        base = self.base = lineage.base
        self.base_state, self.parent = lineage.state, lineage.parent
        self.K, self.ndof = K, K.shape[0]
        self.fixed_dofs, self.pins, self.free, self.factor_free = fixed_dofs, pins, free, factor_free
        self.inverse = base.inverse
        super().__init__()
        nv = len(self.parent)
        nvb = base.ndof // (self.ndof // nv)
        n_base = np.count_nonzero(base.factor_free)
        position = -np.ones(base.ndof, dtype=np.int64)
        position[base.factor_free] = np.arange(n_base)
        self._dofs = np.flatnonzero(factor_free)                 # F: the factorised dofs
        self._x = position[base_dof[self._dofs]]                 # the base position each copies
        # positions in F of the new vertices' dofs, ordered by (vertex, component)
        border = np.flatnonzero(self._dofs % nv >= nvb)
        vertex, component = self._dofs[border] % nv, self._dofs[border] // nv
        self._border = border[np.lexsort((component, vertex))]
        border_dofs = self._dofs[self._border]
        self._Et = sp.csr_matrix((np.ones(len(self._dofs)), (self._x, np.arange(len(self._dofs)))),
                                 shape=(n_base, len(self._dofs)))                     # E^T
        # K~ restricted to the factorised dofs, rows of the border: B^T = J^T K~ E and D
        border_rows = K[border_dofs][:, self._dofs]
        # sorted: a column is recognised by its indices and values, and a sparse product's
        # rows come in any order
        self._Bt = (border_rows @ self._Et.T).tocsr()
        self._Bt.sort_indices()
        D = border_rows[:, self._border].toarray()
        keys = list(zip((border_dofs % nv).tolist(), (border_dofs // nv).tolist()))
        self.z_columns = self._border_columns(lineage.columns, keys, n_base)
        self._Z = self.z_columns.buffer[:, :len(keys)]
        self._D = D
        self._Sd = None           # factorised S_d, made with the columns of Z (_base_solve)
        self.seconds = time.perf_counter() - t0

    def _border_columns(self, carried, keys, n_base):
        """Z = A^-1 B for this border: the chain's columns where B's are unchanged (see
        BorderColumns), the others marked unsolved."""
        Bt = self._Bt
        column_keys = [Bt.indices[s:e].tobytes() + Bt.data[s:e].tobytes() for s, e in zip(Bt.indptr[:-1], Bt.indptr[1:])]
        m = len(keys)
        current = carried is not None and carried.chain["latest"] == carried.generation
        old = len(carried.keys) if current else 0
        if old and carried.keys == keys[:old] and carried.buffer.shape[1] >= m:
            columns = BorderColumns(keys, column_keys, carried.buffer, carried.chain, carried.chain["made"])
            carried.chain["made"] += 1
            unsolved = set(carried.unsolved)
            solve = [i for i in range(old) if i in unsolved or carried.column_keys[i] != column_keys[i]]
            solve += list(range(old, m))
        else:
            buffer = np.zeros((n_base, max(border_capacity(n_base), m)), order="F")   # Z: its first columns
            columns = BorderColumns(keys, column_keys, buffer)
            known = dict(zip(zip(carried.keys, carried.column_keys), range(old))) if old else {}
            solve = []
            for i, key in enumerate(zip(keys, column_keys)):
                if key in known and known[key] not in carried.unsolved:
                    buffer[:, i] = carried.buffer[:, known[key]]
                else:
                    solve.append(i)
        columns.chain["latest"] = columns.generation
        columns.unsolved = solve
        return columns

    def _base_solve(self, rhs):
        """A^-1 rhs (n_base, k); the first call solves the unsolved columns of Z in the same
        block and factorises S_d.

        Raises
        ------
        SingularSystem
            If S_d is singular (a floating piece), or from the base's solve.
        """
        if self._Sd is not None or not len(self._border):
            return self.base.solve_factorised(rhs)
        unsolved = self.z_columns.unsolved
        X = self.base.solve_factorised(np.hstack([self._Bt[unsolved].T.toarray(), rhs]))
        self._Z[:, unsolved] = X[:, :len(unsolved)]
        self.z_columns.unsolved = []
        m = len(self._border)
        Sd = self._D - _sparse_times_rows(self._Bt, self._Z)
        Sd = sla.lu_factor(0.5 * (Sd + Sd.T))
        pivots = np.abs(np.diag(Sd[0]))
        if not np.all(np.isfinite(pivots)) or pivots.min() <= 1e-13 * pivots.max():
            raise SingularSystem(f"the border of {m} split dofs is singular (pivot ratio "
                                 f"{pivots.min() / max(pivots.max(), 1e-300):.1e}): a floating piece?")
        self._Sd = Sd
        return X[:, len(unsolved):]

    @property
    def sparse_schur(self):
        """True if the base takes the sparse Schur complement (then so does this factor)."""
        return self.base.sparse_schur

    def factorise(self):
        """Nothing to do: the base is factorised."""

    def solve(self, B):
        """X = K~^+ B for a full-length right-hand side (ndof,) or a block (ndof, k).

        Entries of B at fixed dofs and pins are ignored; X is zero there. The first solve
        with a nonzero right-hand side must solve its own system (relative residual below
        1e-6), as factor.EliminatedFactor's does.

        Parameters
        ----------
        B : numpy.ndarray, shape (ndof,) or (ndof, k)

        Returns
        -------
        numpy.ndarray
            Same shape as B.

        Raises
        ------
        SingularSystem
            If the solution has NaN/inf, the first solve does not solve its system or the
            border is singular.
        RuntimeError
            If a later mesh of the chain has been factorised (the columns are its own now).
        """
        t0 = time.perf_counter()
        self._check_latest()
        single = B.ndim == 1
        B = B[:, None] if single else B
        X = np.zeros(B.shape)
        if B.shape[1]:
            bF = B[self._dofs]
            x = self._base_solve(self._Et @ bF)
            if len(self._border):
                d = sla.lu_solve(self._Sd, bF[self._border] - self._Bt @ x)
                x -= self._Z @ d                  # on the base dofs, then copied out once
                XF = x[self._x]
                XF[self._border] += d
            else:
                XF = x[self._x]
            X[self._dofs] = XF
            if not np.all(np.isfinite(X)):
                raise SingularSystem("the bordered factorisation produced NaN/inf")
            self.check_solution(B, X)
        self.seconds += time.perf_counter() - t0
        return X[:, 0] if single else X

    def _check_latest(self):
        if self.z_columns.chain["latest"] != self.z_columns.generation:
            raise RuntimeError("a bordered factor of an earlier mesh of a chain of splits: its columns "
                               "were overwritten by a later mesh's")

    def schur(self, C):
        """S = C K~^+ C^T (m, m): the base's sparse Schur complement of C E plus W S_d^-1 W^T.

        Parameters
        ----------
        C : scipy.sparse matrix, shape (m, ndof)
            Constraint rows of the split mesh.

        Returns
        -------
        numpy.ndarray, shape (m, m)

        Raises
        ------
        ValueError
            If the base has no sparse Schur path (:attr:`sparse_schur` is False).
        SingularSystem
            From the base's sparse triangular solves, or if the border is singular.
        RuntimeError
            If a later mesh of the chain has been factorised (as :meth:`solve`).
        """
        t0 = time.perf_counter()
        self._check_latest()
        base = self.base
        CF = sp.csr_matrix(C)[:, self._dofs]
        Cx = (CF @ self._Et.T).tocsr()
        base_dofs = np.flatnonzero(base.factor_free)
        Cx_base = sp.csr_matrix((Cx.data, base_dofs[Cx.indices], Cx.indptr), shape=(Cx.shape[0], base.ndof))
        S = base.schur(Cx_base)
        if len(self._border):
            self._base_solve(np.zeros((self._Et.shape[0], 0)))     # Z and S_d, if not yet made
            W = _sparse_times_rows(Cx, self._Z) - CF[:, self._border].toarray()
            S = S + W @ sla.lu_solve(self._Sd, W.T)
        self.seconds += time.perf_counter() - t0
        return S
