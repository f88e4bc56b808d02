"""The constrained linear solve of the paper's eq. 3 / eq. 12.

    [ K  C^T ] [du ]   [r]
    [ C  0   ] [lam] = [h]      plus fixed dofs du_c given (single-dof rows).

How it is solved (chosen by measurement, see README): the single-dof rows are
eliminated exactly, the symmetric positive definite block K_ff is factorised once
(NGSolve's sparse Cholesky by default), and the general rows go through the Schur
complement S = C_f K_ff^-1 C_f^T, a small dense matrix.  The factorisation is kept
and reused by every solve until the tangent changes (modified Newton).

Pieces held only by general rows (a fragment in contact, a free fragment whose
rigid modes are fixed by multiplier rows) leave K_ff singular.  Their free rigid
modes R are known (rigid.py): K is factorised with one extra pin per mode (K^+),
and the modes come back through a coarse problem, as in FETI:

    u_f = K^+ (q - C_f^T lam) + R alpha,   C_f u_f = h,   R^T (q - C_f^T lam) = 0,

i.e. [S  -G; -G^T 0] [lam; alpha] = [C_f K^+ q - h; -R^T q] with G = C_f R.
This is exact when K R = 0, i.e. for pieces free of initial stress.

Failures are reported, never returned as numbers: a factorisation that produces
NaN/inf or does not solve its own system is ``SingularSystem``.
"""
import contextlib
import warnings

import numpy as np
import ngsolve as ng
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

LINEAR_SOLVERS = ("direct", "gmres")


class SingularSystem(RuntimeError):
    """The KKT system is singular or too badly conditioned to trust its solution."""


def to_scipy(mat):
    """An NGSolve sparse matrix as a scipy CSR matrix (a copy)."""
    vals, cols, rows = mat.CSR()
    return sp.csr_matrix((np.array(vals), np.array(cols), np.array(rows)), shape=(mat.height, mat.width))


@contextlib.contextmanager
def reproducible_threads():
    """One NGSolve thread while factorising, for results that repeat to the last bit.

    NGSolve's sparse Cholesky factorises in parallel with a summation order that varies
    between runs: two factorisations of the same matrix gave solutions differing in the
    last bit (3e-16 relative), enough to change a crack pattern or a resumed run. With one
    thread it is bitwise reproducible; on the 2-core machine it was not slower
    (1.87-1.90 s against 1.89-2.13 s at 145k P1 dofs). Must be entered outside a
    TaskManager context (its thread count is fixed when it starts).
    """
    before = ng.GetNumThreads()
    ng.SetNumThreads(1)
    try:
        yield
    finally:
        ng.SetNumThreads(before)


class ConstrainedSolver:
    """Factorises the eliminated KKT system once; solves it for many right-hand sides.

    Parameters
    ----------
    K : ngsolve.SparseMatrix
        Tangent stiffness on all dofs.
    fixed_dofs : numpy.ndarray
        Dofs fixed by single-dof rows (eliminated).
    C : scipy.sparse matrix, shape (m, ndof)
        General constraint rows (may have m = 0).
    linear_solver : {"direct", "gmres"}
        "direct": sparse Cholesky of K_ff (``inverse`` names NGSolve's solver).
        "gmres": the paper's ILU-preconditioned GMRES (slow; for comparison).
    inverse : str
        NGSolve direct solver for "direct" ("sparsecholesky", "umfpack", "pardiso").

    Raises
    ------
    SingularSystem
        If K_ff or the Schur complement is singular.
    """

    def __init__(self, K, fixed_dofs, C, linear_solver="direct", inverse="sparsecholesky", gmres_tol=1e-12,
                 modes=None, pins=None):
        if linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {linear_solver!r}")
        self.K = K
        self.ndof = K.height
        pins = np.zeros(0, dtype=np.int64) if pins is None else np.asarray(pins, dtype=np.int64)
        self.free = np.ones(self.ndof, dtype=bool)
        self.free[fixed_dofs] = False
        self.factor_free = self.free.copy()
        self.factor_free[pins] = False
        factor_dofs = ng.BitArray(self.ndof)
        factor_dofs.Set()
        for d in np.flatnonzero(~self.factor_free).tolist():
            factor_dofs.Clear(d)
        self.linear_solver = linear_solver
        self.gmres_tol = gmres_tol
        self._tmp = K.CreateColVector()
        if linear_solver == "direct":
            with reproducible_threads():
                self._inv = K.Inverse(factor_dofs, inverse=inverse)
            self._checked = False
        else:
            Kff = to_scipy(K)[self.factor_free][:, self.factor_free].tocsc()
            self._Kff = Kff
            try:
                ilu = spla.spilu(Kff, drop_tol=1e-5, fill_factor=20, permc_spec="MMD_AT_PLUS_A")
            except RuntimeError as err:
                raise SingularSystem(f"ILU factorisation failed: {err}") from None
            self._precond = spla.LinearOperator(Kff.shape, ilu.solve)
        self.C = sp.csr_matrix(C)
        self.m = self.C.shape[0]
        self._R = (sp.csr_matrix(modes)[self.free] if modes is not None and modes.shape[1]
                   else sp.csr_matrix((int(self.free.sum()), 0)))
        self.k = self._R.shape[1]
        if self.k and not self.m:
            raise SingularSystem(f"{self.k} rigid-body mode(s) are held by no constraint (floating body)")
        if self.m:
            Cf = self.C[:, self.free]
            self._Cf = Cf
            self._Z = np.column_stack([self._solve_free(np.asarray(Cf[i].todense()).ravel())
                                       for i in range(self.m)])
            S = Cf @ self._Z
            S = 0.5 * (S + S.T)
            G = (Cf @ self._R).toarray()
            coarse = np.block([[S, -G], [-G.T, np.zeros((self.k, self.k))]])
            # equilibrate, so that the pivot test does not depend on units: S ~ 1/E while
            # G ~ 1 (measured: E = 5e9 made a regular system look singular, ratio 3e-13)
            d = np.diag(S)
            d = np.where(d > 0, 1.0 / np.sqrt(np.where(d > 0, d, 1.0)), 1.0)
            gn = np.linalg.norm(d[:, None] * G, axis=0)
            self._scale = np.concatenate([d, np.where(gn > 0, 1.0 / np.where(gn > 0, gn, 1.0), 1.0)])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", sla.LinAlgWarning)   # judged by the pivots below
                self._coarse = sla.lu_factor(self._scale[:, None] * coarse * self._scale[None, :])
            pivots = np.abs(np.diag(self._coarse[0]))
            if not np.all(np.isfinite(pivots)) or pivots.min() <= 1e-12 * pivots.max():
                raise SingularSystem(f"the {self.m} general constraint rows are (nearly) linearly dependent "
                                     f"or leave rigid modes free: coarse pivot ratio {pivots.min() / pivots.max():.2e}")

    def _solve_free(self, rhs_free):
        """x_f = K^+ rhs_f (pinned dofs get 0), checked: the factorisation must solve its own system."""
        rhs = rhs_free[self.factor_free[self.free]]
        if self.linear_solver == "gmres":
            x, info = spla.gmres(self._Kff, rhs, M=self._precond, rtol=self.gmres_tol,
                                 atol=0.0, restart=200, maxiter=50)
            if info != 0 or not np.all(np.isfinite(x)):
                raise SingularSystem(f"GMRES did not converge (info={info})")
        else:
            full = np.zeros(self.ndof)
            full[self.factor_free] = rhs
            self._tmp.FV().NumPy()[:] = full
            xv = (self._inv * self._tmp).Evaluate()
            x = xv.FV().NumPy()[self.factor_free].copy()
            if not np.all(np.isfinite(x)):
                raise SingularSystem("the factorised stiffness produced NaN/inf: singular (a floating body?)")
            if not self._checked and np.any(rhs):
                # One residual check per factorisation: sparse Cholesky of a singular or
                # indefinite matrix can return finite garbage.
                xv.FV().NumPy()[~self.factor_free] = 0.0
                r = (self.K * xv).Evaluate().FV().NumPy()[self.factor_free] - rhs
                rel = np.linalg.norm(r) / np.linalg.norm(rhs)
                if not rel < 1e-6:
                    raise SingularSystem(f"the factorised stiffness does not solve its system (relative residual {rel:.1e}): singular or indefinite")
                self._checked = True
        out = np.zeros(rhs_free.size)
        out[self.factor_free[self.free]] = x
        return out

    def solve(self, r, du_fixed, h):
        """Solve the eliminated KKT system.

        Parameters
        ----------
        r : numpy.ndarray (ndof,)
            Out-of-balance force (external minus internal).
        du_fixed : numpy.ndarray (ndof,)
            Prescribed increments at the fixed dofs (zero elsewhere).
        h : numpy.ndarray (m,)
            Right-hand side of the general rows, C du = h.

        Returns
        -------
        du : numpy.ndarray (ndof,)
        lam : numpy.ndarray (m,)
            Multipliers of the general rows.
        """
        self._tmp.FV().NumPy()[:] = du_fixed
        q = r - (self.K * self._tmp).Evaluate().FV().NumPy()
        self.last_load_norm = float(np.linalg.norm(q[self.free]))
        qf = q[self.free]
        x0 = self._solve_free(qf)
        du = du_fixed.copy()
        lam = np.zeros(self.m)
        if self.m:
            hf = h - self.C[:, ~self.free] @ du_fixed[~self.free]
            rhs = np.concatenate([self._Cf @ x0 - hf, -(self._R.T @ qf)])
            sol = self._scale * sla.lu_solve(self._coarse, self._scale * rhs)
            lam, alpha = sol[:self.m], sol[self.m:]
            x0 = x0 - self._Z @ lam + self._R @ alpha
        du[self.free] = x0
        return du, lam
