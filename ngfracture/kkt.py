"""The constrained linear solve of the paper's eq. 3 / eq. 12.

    [ K  C^T ] [du ]   [r]
    [ C  0   ] [lam] = [h]      plus fixed dofs du_c given (single-dof rows).

How it is solved (chosen by measurement, see README): the single-dof rows are
eliminated exactly, the symmetric positive definite block K_ff is factorised once
(NGSolve's sparse Cholesky by default), and the general rows go through the Schur
complement S = C_f K_ff^-1 C_f^T, a small dense matrix.  The factorisation is kept
and reused by every solve until the tangent changes (modified Newton).

Failures are reported, never returned as numbers: a factorisation that produces
NaN/inf or does not solve its own system is ``SingularSystem``.
"""
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


class ConstrainedSolver:
    """Factorises the eliminated KKT system once; solves it for many right-hand sides.

    Parameters
    ----------
    K : ngsolve.SparseMatrix
        Tangent stiffness on all dofs.
    freedofs : ngsolve.BitArray
        Dofs not fixed by single-dof rows.
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

    def __init__(self, K, freedofs, C, linear_solver="direct", inverse="sparsecholesky", gmres_tol=1e-12):
        if linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {linear_solver!r}")
        self.K = K
        self.freedofs = freedofs
        self.free = np.array(freedofs, dtype=bool)
        self.ndof = K.height
        self.linear_solver = linear_solver
        self.gmres_tol = gmres_tol
        self._tmp = K.CreateColVector()
        if linear_solver == "direct":
            self._inv = K.Inverse(freedofs, inverse=inverse)
            self._checked = False
        else:
            Kff = to_scipy(K)[self.free][:, self.free].tocsc()
            self._Kff = Kff
            try:
                ilu = spla.spilu(Kff, drop_tol=1e-5, fill_factor=20, permc_spec="MMD_AT_PLUS_A")
            except RuntimeError as err:
                raise SingularSystem(f"ILU factorisation failed: {err}") from None
            self._precond = spla.LinearOperator(Kff.shape, ilu.solve)
        self.C = sp.csr_matrix(C)
        self.m = self.C.shape[0]
        if self.m:
            Cf = self.C[:, self.free]
            self._Cf = Cf
            Z = np.column_stack([self._solve_free(np.asarray(Cf[i].todense()).ravel()) for i in range(self.m)])
            self._Z = Z
            S = Cf @ Z
            S = 0.5 * (S + S.T)
            try:
                self._S = sla.cho_factor(S)
            except np.linalg.LinAlgError:
                raise SingularSystem(f"the {self.m} general constraint rows are linearly dependent "
                                     "(remove redundant rows before the solve)") from None
            pivots = np.diag(self._S[0]) ** 2
            if pivots.min() <= 1e-12 * pivots.max():
                raise SingularSystem(f"the {self.m} general constraint rows are (nearly) linearly dependent: "
                                     f"Schur complement pivot ratio {pivots.min() / pivots.max():.2e}")

    def _solve_free(self, rhs_free):
        """x_f = K_ff^-1 rhs_f, with a check that the factorisation solves its own system."""
        if self.linear_solver == "gmres":
            x, info = spla.gmres(self._Kff, rhs_free, M=self._precond, rtol=self.gmres_tol,
                                 atol=0.0, restart=200, maxiter=50)
            if info != 0 or not np.all(np.isfinite(x)):
                raise SingularSystem(f"GMRES did not converge (info={info})")
            return x
        full = np.zeros(self.ndof)
        full[self.free] = rhs_free
        self._tmp.FV().NumPy()[:] = full
        x = (self._inv * self._tmp).Evaluate()
        xf = x.FV().NumPy()[self.free].copy()
        if not np.all(np.isfinite(xf)):
            raise SingularSystem("the factorised stiffness produced NaN/inf: singular (a floating body?)")
        if not self._checked and np.any(rhs_free):
            # One residual check per factorisation: sparse Cholesky of a singular or
            # indefinite matrix can return finite garbage.
            x.FV().NumPy()[~self.free] = 0.0
            r = (self.K * x).Evaluate().FV().NumPy()[self.free] - rhs_free
            rel = np.linalg.norm(r) / np.linalg.norm(rhs_free)
            if not rel < 1e-6:
                raise SingularSystem(f"the factorised stiffness does not solve its system (relative residual {rel:.1e}): singular or indefinite")
            self._checked = True
        return xf

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
        x0 = self._solve_free(q[self.free])
        du = du_fixed.copy()
        lam = np.zeros(self.m)
        if self.m:
            rhs = self._Cf @ x0 - (h - self.C[:, ~self.free] @ du_fixed[~self.free])
            lam = sla.cho_solve(self._S, rhs)
            x0 = x0 - self._Z @ lam
        du[self.free] = x0
        return du, lam
