"""K^+ by conjugate gradients with an algebraic multigrid preconditioner, and the choice of
the linear solver of a 3D problem (docs/solvers.md, "Iterative solve in 3D").

:class:`AMGFactor` is a K^+ for problems whose sparse Cholesky factor does not fit in memory:
the stiffness without fixed dofs and pins, K_ff, is solved by preconditioned CG, one right-hand
side after the other. The preconditioner is one V-cycle of smoothed-aggregation AMG (pyamg)
built once per matrix (its "factorisation"), with the rigid-body modes as near-null space:
elasticity's smooth error is made of local rigid motions, which aggregation of the
translations alone would not represent (6 modes in 3D, 3 in 2D, taken at the configuration
the tangent refers to). The hierarchy is made on K with the dofs left out of K_ff decoupled
(their rows and columns replaced by the diagonal) and the dofs ordered vertex by vertex, so
that aggregation keeps a vertex's components together (blocks of ``dim``).

Accuracy: CG stops when the true residual |b - K_ff x| is at most ``CG_RTOL`` (1e-12) of
|b|, checked by a fresh product (the recursive residual drifts). That is a backward error
below Newton's increment tolerance (1e-10): a linear problem's first residual is at the
tolerance's rounding level, so it stops after one iteration as with a direct solve, and
modified Newton's contraction per iteration gains a term of at most the condition number
times 1e-12. The general rows stay exact Lagrange multipliers: the Schur complement is
made through this K^+ as through a factorisation, and the KKT solve refines its residual
(linalg.kkt; each refinement gains a factor 1e-12). A CG that does not get there in
``CG_MAXITER`` iterations (a singular or indefinite K_ff: a free rigid mode) raises
:class:`SingularSystem` with the iteration count and the residual reached; it never
returns numbers it has not checked.

:func:`make_factor` chooses between this and a factorisation (:func:`choose_inverse`): in
3D, "auto" takes NGSolve's sparse Cholesky when its predicted memory
(:func:`cholesky_bytes`, fitted to measurements) fits in ``MEMORY_BUDGET`` of the
machine's memory, the iterative solve above it.
"""
import os
import time

import numpy as np
import pyamg
import scipy.sparse as sp

from ..mechanics.rigid import piece_modes
from .factor import EliminatedFactor, FactorBase, SingularSystem
from .sparse import to_scipy

#: CG stops at this relative residual |b - K_ff x| / |b| (true residual): below Newton's
#: increment tolerance 1e-10 with a margin of 100 (module docstring)
CG_RTOL = 1e-12

#: CG iterations at most per right-hand side; AMG-preconditioned CG on the 3D bars takes
#: 20 to 60 (docs/solvers.md), so this many mean a singular or indefinite K_ff
CG_MAXITER = 1000

#: the fraction of the machine's memory that a sparse Cholesky factor may take before
#: "auto" solves 3D problems iteratively: the factorisation's peak, with the mesh, the
#: tangent, the crack engine's arrays and the run's other copies beside it, and a shared
#: machine (docs/solvers.md, "Iterative solve in 3D")
MEMORY_BUDGET = 0.25

#: NGSolve's sparse Cholesky on 3D P1 elasticity: peak memory growth of the factorisation
#: ~ CHOLESKY_BYTES_COEFFICIENT * n ** CHOLESKY_BYTES_EXPONENT for n factorised dofs,
#: least squares on the 3D bars of benchmarks/linear3d.py, 14k to 105k dofs (docs/solvers.md;
#: steeper than the asymptotic n^(4/3) of nested dissection in this range, so it errs on the
#: side of the iterative solve)
CHOLESKY_BYTES_COEFFICIENT = 22.1
CHOLESKY_BYTES_EXPONENT = 1.55

#: in 3D, "auto" factorises a tangent with many general rows (contact, ties) by SuperLU up
#: to this many factorised dofs: its rows then take the augmented matrix or the sparse Schur
#: complement instead of one Cholesky solve per row (linalg.factor). Measured up to here
#: (26k dofs). docs/solvers.md, "Tangents with many rows in 3D"
SUPERLU_ROWS_MAX_DOFS = 26000

#: ... with at least this many general rows per factorised dof (fewer: SuperLU's slower
#: factorisation does not pay back; break-even about 0.004 at 7554 dofs, 0.0048 at 25959).
#: docs/solvers.md, "Tangents with many rows in 3D"
SUPERLU_ROWS_PER_DOF = 0.0075

#: the inverses this module adds: "amg" (CG with AMG; see INVERSES of mechanics.newton)
ITERATIVE_INVERSES = ("amg",)


def problem_inverse(inverse, dim):
    """The direct solver a problem in ``dim`` dimensions asks for when no memory limit is in
    play: "auto" in 3D is NGSolve's sparse Cholesky at every size (a tetrahedral stiffness
    fills SuperLU's factors several times faster: factorisation 2.7 s against 11.2 s at 26k
    dofs; docs/solvers.md, "SuperLU or Cholesky"); any other choice, and "auto" in 2D, is
    passed on.

    Parameters
    ----------
    inverse : str
        The solver asked for (see INVERSES of mechanics.newton).
    dim : int
        The mesh's dimension.

    Returns
    -------
    str
    """
    return "sparsecholesky" if inverse == "auto" and dim == 3 else inverse


def cholesky_bytes(n):
    """The predicted peak memory (bytes) of NGSolve's sparse Cholesky factorisation of a 3D P1
    stiffness with ``n`` factorised dofs (``CHOLESKY_BYTES_COEFFICIENT``,
    ``CHOLESKY_BYTES_EXPONENT``).

    Parameters
    ----------
    n : int
        Factorised dofs.

    Returns
    -------
    float
    """
    return CHOLESKY_BYTES_COEFFICIENT * float(n) ** CHOLESKY_BYTES_EXPONENT


def memory_budget(fraction=None):
    """The bytes a factorisation may take: ``fraction`` (default ``MEMORY_BUDGET``) of the
    machine's physical memory.

    Parameters
    ----------
    fraction : float, optional
        In (0, 1].

    Returns
    -------
    float

    Raises
    ------
    ValueError
        If ``fraction`` is not in (0, 1].
    """
    fraction = MEMORY_BUDGET if fraction is None else fraction
    if not 0 < fraction <= 1:
        raise ValueError(f"the memory budget fraction must be in (0, 1], got {fraction!r}")
    return fraction * os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


def choose_inverse(inverse, dim, n, budget=None, rows=0):
    """The linear solver of a problem and why: (inverse, record).

    In 3D, "auto" is "sparsecholesky" while :func:`cholesky_bytes` of ``n`` fits in
    ``budget``, else "amg"; but "superlu" for a tangent with ``rows`` >=
    ``SUPERLU_ROWS_PER_DOF`` * n general rows and ``n`` <= ``SUPERLU_ROWS_MAX_DOFS``. Any
    other choice, and "auto" in 2D, is :func:`problem_inverse`'s.

    Parameters
    ----------
    inverse : str
        The solver asked for.
    dim : int
        The mesh's dimension.
    n : int
        Factorised dofs.
    budget : float, optional
        Bytes; default :func:`memory_budget`.
    rows : int
        The general rows of the first linear system the tangent is factorised for (the
        later ones of a kept tangent, contact rounds and modified Newton, have about as many).

    Returns
    -------
    inverse : str
    record : dict
        ``solver`` (the inverse), ``reason`` ("asked", "auto" or "auto, many rows"),
        ``dofs`` (n) and, where "auto" chose by memory in 3D, ``predicted_bytes`` and
        ``budget_bytes``.
    """
    record = {"solver": inverse, "reason": "asked", "dofs": int(n)}
    many_rows = 0 < rows and SUPERLU_ROWS_PER_DOF * n <= rows and n <= SUPERLU_ROWS_MAX_DOFS
    if inverse == "auto" and dim == 3 and many_rows:
        record.update(solver="superlu", reason="auto, many rows")
        return "superlu", record
    if inverse == "auto" and dim == 3:
        budget = memory_budget() if budget is None else float(budget)
        predicted = cholesky_bytes(n)
        inverse = "sparsecholesky" if predicted <= budget else "amg"
        record.update(solver=inverse, reason="auto", predicted_bytes=predicted, budget_bytes=budget)
        return inverse, record
    inverse = problem_inverse(inverse, dim)
    record["solver"] = inverse
    return inverse, record


def make_factor(K, fixed_dofs, pins, linear_solver="direct", inverse="auto", dim=2, points=None,
                pattern=None, budget=None, rows=0, one_system=False):
    """K^+ of a tangent: an :class:`AMGFactor` or a :class:`linalg.factor.EliminatedFactor`,
    as :func:`choose_inverse` decides (only for ``linear_solver="direct"``).

    Parameters
    ----------
    K : scipy.sparse matrix or ngsolve.SparseMatrix
        Tangent on all dofs.
    fixed_dofs, pins : array_like of int
        As for EliminatedFactor.
    linear_solver : {"direct", "gmres"}
    inverse : str
        "auto", "amg" or a direct solver (INVERSES of mechanics.newton).
    dim : int
        The mesh's dimension.
    points : numpy.ndarray, shape (nv, dim), optional
        Vertex positions for the rigid modes of "amg" (needed there).
    pattern : ngsolve.la.SparseMatrixd, optional
        For NGSolve's factorisation (EliminatedFactor).
    budget : float, optional
        Bytes, for "auto" (default :func:`memory_budget`).
    rows : int
        For "auto": the general rows of the first system the tangent is factorised for
        (:func:`choose_inverse`).
    one_system : bool
        The tangent is factorised for the solves of one system (a full-Newton iterate):
        in 3D its Schur complement is built from the rows, not from K^-1 on their dofs,
        which pays only where a factorisation meets many sets of re-linearised rows
        (docs/solvers.md, "Sparse Schur complement").

    Returns
    -------
    AMGFactor or EliminatedFactor
        With ``choice``, the record of :func:`choose_inverse`.

    Raises
    ------
    ValueError
        Unknown ``linear_solver``, or "amg" without ``points``.
    """
    if linear_solver == "direct":
        ndof = K.shape[0] if sp.issparse(K) else K.height
        left_out = np.union1d(np.asarray(fixed_dofs, dtype=np.int64),
                              np.zeros(0, dtype=np.int64) if pins is None else np.asarray(pins, dtype=np.int64))
        inverse, record = choose_inverse(inverse, dim, ndof - left_out.size, budget, rows)
    else:
        record = {"solver": linear_solver, "reason": "asked"}
    if inverse == "amg":
        if points is None:
            raise ValueError("inverse='amg' needs the vertex positions (points) for the rigid modes")
        factor = AMGFactor(K, fixed_dofs, pins, points)
    else:
        # 3D contact rows are re-linearised at every round: S from K^-1 on their dofs where the
        # factorisation serves the rounds; for one system from the rows (they touch about three
        # times as many dofs as they are: by dofs 2.7 times the CPU of by rows on the sphere)
        factor = EliminatedFactor(K, fixed_dofs, pins, linear_solver, inverse, pattern=pattern,
                                  schur_by_dofs=dim == 3 and not one_system, grouped_products=dim == 3)
    factor.choice = record
    return factor


class AMGFactor(FactorBase):
    """K^+ by CG with a smoothed-aggregation AMG preconditioner (see the module docstring).

    The same interface as :class:`linalg.factor.EliminatedFactor` for the constrained solves
    (linalg.kkt): ``solve``, ``factorise``, the Schur columns and the corrected modes of
    FactorBase; no augmented matrix and no sparse Schur complement.

    Parameters
    ----------
    K : scipy.sparse matrix or ngsolve.SparseMatrix
        Symmetric tangent on all dofs, component-blocked (dof = c * n + v).
    fixed_dofs, pins : array_like of int
        Dofs left out of K_ff (pins None for none).
    points : numpy.ndarray, shape (nv, dim)
        Vertex positions of the rigid modes (the configuration K refers to), nv <= n.
    rtol : float
        CG's relative residual (default ``CG_RTOL``).
    maxiter : int
        CG iterations at most per right-hand side (default ``CG_MAXITER``).

    Attributes
    ----------
    seconds : float
        Time in the hierarchy and the CG solves so far.
    iterations : list of int
        CG iterations of every right-hand side solved.

    Raises
    ------
    ValueError
        If ``points`` does not fit K's dofs, or ``rtol`` / ``maxiter`` are out of range.
    """

    def __init__(self, K, fixed_dofs, pins, points, rtol=CG_RTOL, maxiter=CG_MAXITER):
        t0 = time.perf_counter()
        super().__init__()
        self.K = to_scipy(K)
        self.ndof = self.K.shape[0]
        points = np.asarray(points, dtype=float)
        if points.ndim != 2 or points.shape[1] not in (2, 3) or self.ndof % points.shape[1]:
            raise ValueError(f"points must be (nv, 2) or (nv, 3) dividing the {self.ndof} dofs, got {points.shape}")
        if points.shape[0] > self.ndof // points.shape[1]:
            raise ValueError(f"points has {points.shape[0]} vertices, more than the {self.ndof} dofs hold")
        if not 0 < rtol < 1 or int(maxiter) < 1:
            raise ValueError(f"rtol must be in (0, 1) and maxiter >= 1, got {rtol!r}, {maxiter!r}")
        self.dim, self.points = points.shape[1], points
        self.fixed_dofs = np.asarray(fixed_dofs, dtype=np.int64)
        self.pins = np.zeros(0, dtype=np.int64) if pins is None else np.asarray(pins, dtype=np.int64)
        self.free = np.ones(self.ndof, dtype=bool)
        self.free[self.fixed_dofs] = False
        self.factor_free = self.free.copy()
        self.factor_free[self.pins] = False
        self.linear_solver, self.inverse = "direct", "amg"
        self.rtol, self.maxiter = float(rtol), int(maxiter)
        self.iterations = []
        self._ml = None
        self.seconds = time.perf_counter() - t0

    #: no sparse triangular Schur complement (linalg.factor.SPARSE_SCHUR_MIN_DOFS): the
    #: constrained solves keep the columns K^+ C^T
    sparse_schur = False

    @property
    def factorised(self):
        """True once the AMG hierarchy is made."""
        return self._ml is not None

    def factorise(self):
        """Make the AMG hierarchy of K_ff, if not yet done.

        Raises
        ------
        SingularSystem
            If pyamg cannot build it (a zero or non-finite diagonal).
        """
        if self._ml is not None:
            return
        t0 = time.perf_counter()
        n, d = self.ndof // self.dim, self.dim
        keep = self.factor_free
        self._Kff = self.K[keep][:, keep].tocsr()
        diag = self.K.diagonal()
        if not np.all(np.isfinite(diag)) or np.any(diag[keep] <= 0):
            raise SingularSystem("the stiffness has a zero, negative or non-finite diagonal entry on a free dof")
        mask = sp.diags(keep.astype(float))
        A = mask @ self.K @ mask + sp.diags(np.where(keep, 0.0, np.where(diag > 0, diag, 1.0)))
        # vertex-major order: dof c*n + v -> d*v + c
        order = (np.arange(d)[None, :] * n + np.arange(n)[:, None]).ravel()
        A = A.tocsr()[order][:, order].tobsr(blocksize=(d, d))
        _, modes = piece_modes(self.points, np.arange(self.points.shape[0]), n)
        B = np.zeros((self.ndof, modes.shape[1]))
        B[np.concatenate([c * n + np.arange(self.points.shape[0]) for c in range(d)])] = modes
        B[~keep] = 0.0
        self._order = order
        self._ml = pyamg.smoothed_aggregation_solver(A, B=B[order], strength=("symmetric", {"theta": 0.0}))
        self._cycle = self._ml.aspreconditioner(cycle="V")
        self.seconds += time.perf_counter() - t0

    def _precondition(self, r):
        """One V-cycle on r (K_ff's dofs), zero elsewhere."""
        full = np.zeros(self.ndof)
        full[self.factor_free] = r
        z = np.empty(self.ndof)
        z[self._order] = self._cycle @ full[self._order]
        return z[self.factor_free]

    def cg(self, b):
        """x = K_ff^-1 b by preconditioned CG to the relative residual ``rtol``.

        Parameters
        ----------
        b : numpy.ndarray, shape (n,)
            Right-hand side on the factorised dofs, in their order.

        Returns
        -------
        numpy.ndarray, shape (n,)

        Raises
        ------
        SingularSystem
            If the true residual does not reach ``rtol`` |b| in ``maxiter`` iterations, or CG
            meets a direction of non-positive curvature (K_ff singular or indefinite); the
            message names the iterations and the residual.
        """
        self.factorise()
        bnorm = np.linalg.norm(b)
        x = np.zeros_like(b)
        if bnorm == 0.0:
            self.iterations.append(0)
            return x
        r = b.copy()
        z = self._precondition(r)
        p, rz = z.copy(), float(r @ z)
        for it in range(1, self.maxiter + 1):
            Ap = self._Kff @ p
            curvature = float(p @ Ap)
            if not curvature > 0:
                return self._failed(it, np.linalg.norm(b - self._Kff @ x) / bnorm, "non-positive curvature")
            alpha = rz / curvature
            x += alpha * p
            r -= alpha * Ap
            if np.linalg.norm(r) <= self.rtol * bnorm:
                r = b - self._Kff @ x          # the true residual decides
                if np.linalg.norm(r) <= self.rtol * bnorm:
                    self.iterations.append(it)
                    return x
            z = self._precondition(r)
            rz_new = float(r @ z)
            p = z + (rz_new / rz) * p
            rz = rz_new
        return self._failed(self.maxiter, np.linalg.norm(b - self._Kff @ x) / bnorm, "no convergence")

    def _failed(self, iterations, residual, why):
        raise SingularSystem(f"CG with AMG did not reach the relative residual {self.rtol:.0e} ({why}): "
                             f"{iterations} iterations, relative residual {residual:.2e}: the stiffness "
                             f"is singular or indefinite (a floating body?)")

    #: one CG solve per column: a column does not depend on the block (FactorBase)
    columns_independent = True

    def solve(self, B):
        """X = K^+ B, one CG solve per column.

        Parameters
        ----------
        B : numpy.ndarray, shape (ndof,) or (ndof, m)
            Right-hand side(s); entries at fixed dofs and pins are ignored.

        Returns
        -------
        numpy.ndarray, same shape as B
            Zero at fixed dofs and pins.

        Raises
        ------
        SingularSystem
            From :meth:`cg`.
        """
        t0 = time.perf_counter()
        single = B.ndim == 1
        B = B[:, None] if single else B
        X = np.zeros(B.shape)
        for j in range(B.shape[1]):
            X[self.factor_free, j] = self.cg(np.ascontiguousarray(B[self.factor_free, j], dtype=float))
        self.seconds += time.perf_counter() - t0
        return X[:, 0] if single else X
