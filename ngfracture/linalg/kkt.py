"""The constrained linear solve of the paper's eq. 3 / eq. 12.

    [ K  C^T ] [du ]   [r]
    [ C  0   ] [lam] = [h]      plus fixed dofs du_c given (single-dof rows).

How it is solved (docs/solvers.md says why): the single-dof rows are eliminated exactly,
and the symmetric positive definite block K_ff is factorised (linalg.factor) and kept for
every solve until the tangent changes (modified Newton). General rows (contact, holds of
free modes) take one of two paths.

The augmented path, for a tangent factorised for one solve on a small K_ff
(``EliminatedFactor.augmented_pays``): the augmented matrix

    [ K_ff   C_f^T D ]
    [ D C_f  0       ]      D: every row scaled to the mean diagonal of K_ff

is LU-factorised once per tangent and row set (SuperLU, symmetric ordering, threshold
pivoting): one sparse factorisation instead of one triangular solve per row for the
Schur complement, and no pins, since the rows hold the free rigid modes. The first solve
of each augmented factorisation must solve its own system (backward error below 1e-6); a
nearly singular matrix is reported, not solved.

The Schur-complement path, for everything else: kept tangents, larger K_ff, and the
contact complementarity problem (:meth:`ConstrainedSolver.solve_unilateral`), which needs
S = C K^+ C^T itself; ``path="schur"`` asks for it.

Pieces held only by general rows (a fragment in contact, a free fragment whose
rigid modes are fixed by multiplier rows) leave K_ff singular.  Their free rigid
modes R are known (rigid.py): K is factorised with one extra pin per mode (K^+),
and the modes come back through a coarse problem, as in FETI:

    u_f = K^+ (q - C_f^T lam) + R alpha,   C_f u_f = h,   R^T (q - C_f^T lam) = 0,

i.e. [S  -G; -G^T 0] [lam; alpha] = [C_f K^+ q - h; -R^T q] with G = C_f R.
That is exact only when K R = 0, i.e. for pieces free of initial stress. A piece that
carries loads (a fragment pressed by contact) has K R != 0 for its rotation under
finite strain: the internal forces f turn with the piece, K R_rot = J f (the
geometric stiffness). The modes are therefore replaced by their corrections

    Rt = R - K^+ K R   (Rt = R at the pins, K Rt = 0 at the other free dofs),

and with A = Rt^T K Rt (the stiffness of the modes, zero when K R = 0) the coarse
problem [S  -Gt; -Gt^T  -A] [lam; alpha] = [C_f K^+ q - h; -Rt^T q], Gt = C_f Rt, solves
the KKT system exactly for any K that is regular without the pins (a Schur complement
on the pins; R need not even be exact rigid modes, only resolved by the pins).
Without the correction, modified Newton on pressed pieces contracts poorly and full Newton
diverges (docs/solvers.md, "Corrected modes").

Failures are reported, never returned as numbers: a factorisation that produces
NaN/inf or does not solve its own system is ``SingularSystem``.
"""
import time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .factor import EliminatedFactor, SingularSystem
from .qp import bound_qp


class ConstrainedSolver:
    """Solves the eliminated KKT system for many right-hand sides.

    Parameters
    ----------
    K : scipy.sparse matrix, ngsolve.SparseMatrix or None
        Tangent stiffness on all dofs (None allowed when ``factor`` is given).
    fixed_dofs : numpy.ndarray of int
        Dofs fixed by single-dof rows (eliminated).
    C : scipy.sparse matrix, shape (m, ndof)
        General constraint rows (may have m = 0).
    linear_solver : {"direct", "gmres"}
        "direct": a sparse direct factorisation of K_ff (``inverse``).
        "gmres": the paper's ILU-preconditioned GMRES (slow; for comparison).
    inverse : str
        Direct solver for "direct": "auto" (default: see ``factor.SUPERLU_MAX_DOFS``), "superlu"
        (scipy's SuperLU) or an NGSolve solver ("sparsecholesky", "umfpack", "pardiso").
    gmres_tol : float
        Relative residual at which GMRES stops ("gmres" only).
    modes, pins : optional
        Free rigid modes, scipy.sparse (ndof, k), and one pinned dof per mode, array of
        int (k,); see rigid.Support. None: no free modes, no pins.
    factor : EliminatedFactor, optional
        A factorisation of K for the same fixed dofs and pins to reuse (then K, the
        solver options and the factorisation cost nothing here).
    dependent_rows : bool
        Allow linearly dependent general rows; then only :meth:`solve_unilateral` works
        (inequalities that are dependent as vectors are still distinct constraints).
    path : {"auto", "augmented", "schur"}
        How the general rows are solved (see the module docstring): "augmented" one LU of
        the augmented matrix (:meth:`EliminatedFactor.augmented`), "schur" the Schur
        complement with pins and corrected modes. "auto" (default): "augmented" where the
        factor says it pays (:attr:`EliminatedFactor.augmented_pays`), with general rows
        and without ``dependent_rows``, else "schur".
    first : (numpy.ndarray, numpy.ndarray), optional
        (r, du_fixed) of the first :meth:`solve`, if the caller knows them: where the Schur
        columns K^+ C^T are solved here, that solve's K^+ q is solved in the same block.

    Attributes
    ----------
    path : str
        The path chosen ("augmented" or "schur").
    fallback : str or None
        Why the path "auto" chose left the augmented matrix for the Schur complement (its
        factorisation was singular), else None.

    Raises
    ------
    SingularSystem
        If K_ff or the Schur complement is singular: free rigid modes but no general
        rows, general rows (nearly) dependent or leaving a mode free (coarse pivot ratio
        <= 1e-12), or a failed factorisation or solve of K_ff (see EliminatedFactor).
    ValueError
        If ``factor`` was made for other fixed dofs or pins, or (without ``factor``) if
        ``linear_solver`` is unknown, or if ``path`` is unknown, or "augmented" without
        general rows, with ``dependent_rows`` or with "gmres".
    """

    def __init__(self, K, fixed_dofs, C, linear_solver="direct", inverse="auto", gmres_tol=1e-12,
                 modes=None, pins=None, factor=None, dependent_rows=False, path="auto", first=None):
        if factor is None:
            factor = EliminatedFactor(K, fixed_dofs, pins, linear_solver, inverse, gmres_tol)
        elif not factor.matches(np.asarray(fixed_dofs, dtype=np.int64),
                                np.zeros(0, dtype=np.int64) if pins is None else np.asarray(pins, dtype=np.int64)):
            raise ValueError("the factorisation to reuse was made for other fixed dofs or pins")
        self.factor = factor
        self.K, self.ndof, self.free = factor.K, factor.ndof, factor.free
        self.C = sp.csr_matrix(C)
        self.m = self.C.shape[0]
        # kept: every solve and its refinement use them (thousands of solves per run);
        # |C| at its first use (abs() sorts C's indices in place, which would change the
        # order of the sums in the Schur columns)
        self._Ct, self._C_abs = self.C.T, None
        # all vectors below are full length: zero at fixed dofs (R, Z) and pins (Z)
        self._R = (sp.csr_matrix(modes) if modes is not None and modes.shape[1]
                   else sp.csr_matrix((self.ndof, 0)))
        self.k = self._R.shape[1]
        if self.k and not self.m:
            raise SingularSystem(f"{self.k} rigid-body mode(s) are held by no constraint (floating body)")
        self.path = _chosen_path(path, factor, self.m, dependent_rows)
        self._checked = False     # the augmented path checks the residual of its first solve
        self._first = None        # (q, K^+ q) of the first solve, solved with the columns
        self.fallback = None      # why the augmented path chosen by "auto" gave way to the Schur path
        if self.path == "augmented":
            try:
                self._augmented = factor.augmented(self.C)
                return
            except SingularSystem as err:
                if path != "auto":
                    raise
                # rows that hold a mechanism only at rounding level (a shattered body):
                # the Schur path's pins and coarse problem resolve what the LU's pivots cannot
                self.path, self.fallback = "schur", f"augmented matrix singular ({err}); Schur complement instead"
        factor.factorise()        # here, outside a TaskManager (see EliminatedFactor.factorise)
        if self.m:
            self._R, A = factor.corrected_modes(self._R)
            self._Rt = self._R.T
            self._Z, S, self._first = self._schur_complement(first)
            if not np.array_equal(S, S.T):    # exactly symmetric where U = D L^T: no copies of m^2
                S = 0.5 * (S + S.T)
            G = (self.C @ self._R).toarray()
            self._S, self._G = S, G       # kept for solve_unilateral
            self._scale = _equilibration(S, G)
            self._coarse = None if dependent_rows else _coarse_factor(S, G, A, self._scale)

    def _schur_complement(self, first):
        """(Z, S, first): the kept columns Z = K^+ C^T (None where the factor builds S by
        sparse triangular solves: then the displacement correction takes one more solve per
        solve), S = C K^+ C^T, and (q, K^+ q) of the first solve where it was solved in one
        block with the columns (else None)."""
        factor = self.factor
        if not factor.keeps_columns(self.m):
            return None, factor.schur(self.C), None
        if first is None:
            Z = factor.columns(self.C)
            return Z, self.C @ Z, None
        q = self._load(*first)
        Z, X = factor.columns_and_solve(self.C, q[:, None])
        return Z, self.C @ Z, (q.copy(), X[:, 0])

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

        Raises
        ------
        SingularSystem
            If made with ``dependent_rows=True`` (no coarse factorisation), if the
            factorised stiffness fails (see :meth:`EliminatedFactor.solve`), or on the
            augmented path if the first solve leaves a backward error of 1e-6 or more.
        """
        if self.m and self.path == "schur" and self._coarse is None:
            raise SingularSystem("made with dependent_rows=True: only solve_unilateral is available")
        du, lam, q = self._solve_once(r, du_fixed, h)
        if self.m:
            # Iterative refinement: the Schur complement through K^+ and the coarse problem
            # of the modes is not backward stable when pieces hang on contact and hold rows
            # (docs/solvers.md, "Iterative refinement"); a K product per solve decides
            # whether a step is needed. Without kept columns the correction K^+ C^T lam is a
            # fresh solve, not the columns S was made from: the rows hold to the rounding of
            # two different solves, which the tighter target asks for.
            target = 1e-14 if self.path == "schur" and self._Z is None else 1e-13
            for refinement in range(self.REFINEMENTS + 1):
                res, res_rows, force_scale, row_scale = self._residual(r, h, du, lam)
                error = max(np.linalg.norm(res) / force_scale, np.linalg.norm(res_rows) / row_scale)
                if error <= target or refinement == self.REFINEMENTS:
                    break
                ddu, dlam, _ = self._solve_once(res, np.zeros_like(du), res_rows)
                du, lam = du + ddu, lam + dlam
            if self.path == "augmented" and not self._checked:
                self._check_backward_error(r, q, h, du, lam, res, res_rows)
                self._checked = True
        return du, lam

    def _check_backward_error(self, r, q, h, du, lam, res, res_rows):
        """Raise SingularSystem unless the residuals (res, res_rows) of a solve are a backward
        error below 1e-6: a nearly singular augmented matrix can pass the pivot test and
        return finite garbage. Measured against |K| |du|, |C^T| |lam|, |C| |du|, the
        rounding of the products (docs/solvers.md, "Augmented matrix")."""
        free = self.free
        Kabs = abs(self.factor.free_block) @ np.abs(du[free])
        force_size = (np.linalg.norm(Kabs) + np.linalg.norm((abs(self.C.T) @ np.abs(lam))[free])
                      + np.linalg.norm(r[free]) + np.linalg.norm(q[free]))
        rows_size = np.linalg.norm(h) + np.linalg.norm(self._C_abs @ np.abs(du))
        error = max(np.linalg.norm(res) / max(force_size, 1e-300), np.linalg.norm(res_rows) / max(rows_size, 1e-300))
        if not error < 1e-6:
            raise SingularSystem(f"the constrained system is singular or too badly conditioned "
                                 f"(relative residual {error:.1e})")

    def load_norm(self, r, du_fixed):
        """The size of a solve's load on the free dofs: the out-of-balance force plus the
        pull of the prescribed increments, q = r - K du_fixed, as :meth:`solve` moves it over.

        Parameters
        ----------
        r, du_fixed : numpy.ndarray (ndof,)
            As for :meth:`solve`.

        Returns
        -------
        float
            The Euclidean norm of q on the free dofs.
        """
        return float(np.linalg.norm(self._load(r, du_fixed)[self.free]))

    #: refinement steps at most per solve (each: one K product and one solve with K^+)
    REFINEMENTS = 2

    def _solve_once(self, r, du_fixed, h):
        """One pass of the eliminated solve: (du, lam, the load q of :meth:`_unconstrained`)."""
        if self.path == "augmented":
            return self._solve_augmented(r, du_fixed, h)
        q, du = self._unconstrained(r, du_fixed)
        lam = np.zeros(self.m)
        if self.m:
            rhs = np.concatenate([self.C @ du - h, -(self._Rt @ q)])
            sol = self._scale * self._coarse.solve(self._scale * rhs)
            lam, alpha = sol[:self.m], sol[self.m:]
            du -= self._correction(lam)
            du += self._R @ alpha
        return du, lam, q

    def _solve_augmented(self, r, du_fixed, h):
        """One solve with the factorised augmented matrix (see EliminatedFactor.augmented)."""
        t0 = time.perf_counter()
        q = self._load(r, du_fixed)
        lu, row_scale = self._augmented
        rhs = np.concatenate([q[self.free], row_scale * (h - self.C @ du_fixed)])
        x = lu.solve(rhs)
        if not np.all(np.isfinite(x)):
            raise SingularSystem("the factorised augmented matrix produced NaN/inf")
        du = du_fixed.copy()
        nfree = rhs.size - self.m
        du[self.free] = x[:nfree]
        self.factor.seconds += time.perf_counter() - t0
        return du, row_scale * x[nfree:], q

    def _residual(self, r, h, du, lam):
        """Residuals of the free rows and of the general rows, each with its size scale.

        The rows' scale is that of the rounding of C du, |C| |du| (entrywise absolute
        values), not |C du|: rows already satisfied have C du and h near zero, and measured
        against those the rounding of the product would look like an error and ask for
        refinements that change nothing (docs/solvers.md, "Iterative refinement")."""
        Kdu = self.K @ du
        Ct_lam = self._Ct @ lam
        free = self.free
        res = np.where(free, r - Kdu - Ct_lam, 0.0)
        Cdu = self.C @ du
        force_scale = (np.linalg.norm(r[free]) + np.linalg.norm(Kdu[free]) + np.linalg.norm(Ct_lam[free]))
        if self._C_abs is None:
            self._C_abs = abs(self.C)
        row_scale = np.linalg.norm(h) + np.linalg.norm(self._C_abs @ np.abs(du))
        return res, h - Cdu, max(force_scale, 1e-300), max(row_scale, 1e-300)

    def _correction(self, lam):
        """K^+ C^T lam: from the kept columns, or by a solve where none are kept."""
        return self._Z @ lam if self._Z is not None else self.factor.solve(self._Ct @ lam)

    def _load(self, r, du_fixed):
        """The load q = r - K du_fixed: the prescribed increments moved over."""
        return r - self.K @ du_fixed if np.any(du_fixed) else r

    def _unconstrained(self, r, du_fixed):
        """The load q with the prescribed increments moved over, and du = du_fixed + K^+ q."""
        q = self._load(r, du_fixed)
        first, self._first = self._first, None
        if first is not None and np.array_equal(q, first[0]):
            return q, du_fixed + first[1]         # solved with the columns
        return q, du_fixed + self.factor.solve(q)

    def solve_unilateral(self, r, du_fixed, h, unilateral, released=None):
        """Solve with some general rows as inequalities: a linear complementarity problem.

        Rows i in ``unilateral`` hold as C_i du >= h_i with lam_i <= 0 and
        lam_i (C_i du - h_i) = 0 (frictionless contact: h = -gap, lam compressive); the
        others as in :meth:`solve`. In multipliers this is the dual problem of FETI
        contact (Dostal):

            min 1/2 lam^T S lam - b^T lam   s.t.  G^T lam = R^T q,  lam_i <= 0 (i unilateral)

        with b = C (du_fixed + K^+ q) - h, solved exactly by :func:`ngfracture.linalg.qp.bound_qp`
        (the dual active-set method, from a primal-dual guess of the working set when
        there are many candidate rows); S is positive definite on the null space of G^T
        when the rows are independent and the free modes held, as the constructor checks.
        With ``dependent_rows`` S is only semidefinite: 1e-10 (relative to its unit
        diagonal after equilibration) is added to it, which picks the smallest multipliers
        and lets the gaps miss by about 1e-10 of the displacement scale.
        The modes are the corrected ones (Rt, Gt) but their stiffness A is left out: exact
        when K R = 0; for pressed pieces an approximation, used to choose the active set,
        which :meth:`solve` then imposes exactly.

        Parameters
        ----------
        r, du_fixed, h
            As for :meth:`solve`.
        unilateral : numpy.ndarray of int or bool
            The rows that are inequalities.
        released : numpy.ndarray of bool, optional
            Per unilateral row, whether it is guessed released: the QP's start (``bound_qp``'s
            ``guess``: the same answer, in fewer steps from a good guess).

        Returns
        -------
        du : numpy.ndarray (ndof,)
        lam : numpy.ndarray (m,)
            Exactly 0 for the released unilateral rows.
        closed : numpy.ndarray of bool (m,)
            The rows that hold with equality, C_i du = h_i: the equalities and the unilateral
            rows that are not released. A closed row may carry no force (lam_i = 0): it
            touches, and still fixes the position of a piece that no force holds.
        fallback : str
            Empty, or why the QP's updated factorisation gave way to the QR of its working
            set (:attr:`ngfracture.linalg.qp.BoundQP.fallback`): for the caller's record.

        Raises
        ------
        ValueError
            If the solver was built on the augmented path (no Schur complement).
        """
        if self.path != "schur":
            raise ValueError("solve_unilateral needs the Schur complement: build with path='schur' or dependent_rows=True")

        q, du = self._unconstrained(r, du_fixed)
        if not self.m:
            return du, np.zeros(0), np.zeros(0, dtype=bool), ""
        bounded = np.zeros(self.m, dtype=bool)
        bounded[unilateral] = True
        b = self.C @ du - h
        # in the equilibrated variables y = lam / d of the constructor (unit diagonal),
        # with H = S + G G^T: the same minimiser on G^T lam = R^T q, and positive definite
        d, gscale = self._scale[:self.m], self._scale[self.m:]
        Gs = d[:, None] * self._G * gscale[None, :]
        H = d[:, None] * self._S * d[None, :] + Gs @ Gs.T
        if self._coarse is None:
            H[np.diag_indices(self.m)] += 1e-10
        e = gscale * (self._R.T @ q)
        bounded_rows = np.flatnonzero(bounded)
        answer = bound_qp(H, d * b + Gs @ e, Gs.T, e, bounded_rows,
                          guess=_released_on(bounded_rows, unilateral, released, self.m))
        y, alpha = answer.x, answer.u_eq
        released = np.zeros(self.m, dtype=bool)
        released[bounded_rows[answer.held]] = True
        y[released] = 0.0                        # released rows carry exactly nothing
        lam = d * y
        du -= self._correction(lam)
        du += self._R @ (gscale * alpha)
        return du, lam, ~released, answer.fallback


def _released_on(bounded_rows, unilateral, released, m):
    """``released`` (per unilateral row, in the order of ``unilateral``) on the bounded rows
    of :meth:`ConstrainedSolver.solve_unilateral`, or None without one."""
    if released is None:
        return None
    on_rows = np.zeros(m, dtype=bool)
    on_rows[unilateral] = released
    return on_rows[bounded_rows]


def _chosen_path(path, factor, m, dependent_rows):
    """The path of a ConstrainedSolver: ``path``, or for "auto" the one ``factor`` favours."""
    if path not in ("auto", "augmented", "schur"):
        raise ValueError(f"path must be 'auto', 'augmented' or 'schur', got {path!r}")
    if path == "auto":
        path = "augmented" if m and factor.augmented_pays and not dependent_rows else "schur"
    if path == "augmented" and (dependent_rows or not m or factor.linear_solver != "direct"):
        raise ValueError("the augmented path needs independent general rows and a direct solver")
    return path


def _equilibration(S, G):
    """The scale of the coarse problem's unknowns: S to unit diagonal, the columns of G to
    unit norm after that, so that its pivot test does not depend on units (S ~ 1/E while
    G ~ 1; docs/solvers.md, "Coarse problem")."""
    d = np.diag(S)
    d = np.where(d > 0, 1.0 / np.sqrt(np.where(d > 0, d, 1.0)), 1.0)
    gn = np.linalg.norm(d[:, None] * G, axis=0)
    return np.concatenate([d, np.where(gn > 0, 1.0 / np.where(gn > 0, gn, 1.0), 1.0)])


#: general rows from which the coarse problem is factorised through the Cholesky factor of S
#: (thousands of 3D contact rows: half the work of an LU); below, one LU of the whole (the
#: numbers the 2D references were made with)
COARSE_CHOLESKY_MIN_ROWS = 1000
#: ... where the pivots of S's Cholesky factor stay above this fraction of the largest: the
#: elimination of the modes' block through a nearly singular S (rows whose stiffness the
#: modes carry) loses what the LU's pivoting keeps
COARSE_CHOLESKY_PIVOT_RATIO = 1e-6


def _coarse_factor(S, G, A, scale):
    """The equilibrated coarse problem M = [S  -G; -G^T  -A] factorised (:class:`_CoarseFactor`).

    Raises SingularSystem if a pivot is below 1e-12 of the largest: general rows (nearly)
    dependent, or leaving a rigid mode free."""
    m = S.shape[0]
    factor = _CoarseFactor.by_cholesky(S, G, A, scale) if m >= COARSE_CHOLESKY_MIN_ROWS else None
    if factor is None:
        coarse = np.block([[S, -G], [-G.T, -A]])
        M = scale[:, None] * coarse * scale[None, :]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sla.LinAlgWarning)   # judged by the pivots below
            lu = sla.lu_factor(M)
        factor = _CoarseFactor(lu, None, None, np.abs(np.diag(lu[0])))
    pivots = factor.pivots
    if not np.all(np.isfinite(pivots)) or pivots.min() <= 1e-12 * pivots.max():
        raise SingularSystem(f"the {m} general constraint rows are (nearly) linearly dependent "
                             f"or leave rigid modes free: coarse pivot ratio {pivots.min() / pivots.max():.2e}")
    return factor


class _CoarseFactor:
    """A factorisation of the equilibrated coarse problem M = [M_s  -M_g; -M_g^T  -M_a].

    Either one LU of M (``lu``), or the Cholesky factor L of M_s with the block of the
    modes eliminated: Y = L^-1 M_g and T = M_a + Y^T Y (k x k, by LU), then
    y = -T^-1 (b + Y^T L^-1 a) and x = L^-T (L^-1 a + Y y) for the right-hand side (a, b).
    ``pivots``: those of the LU, or diag(L)^2 and the pivots of T's LU (the pivots of
    the same elimination), for the singularity test of :func:`_coarse_factor`.
    """

    def __init__(self, lu, cholesky, modes, pivots):
        self.lu, self.cholesky, self.modes, self.pivots = lu, cholesky, modes, pivots

    @classmethod
    def by_cholesky(cls, S, G, A, scale):
        """The Cholesky route for the coarse problem of :func:`_coarse_factor`, its blocks
        equilibrated one by one (the entries of M, without M), or None where M_s is not
        positive definite (a row on pinned dofs alone has a zero diagonal there) or nearly
        singular (``COARSE_CHOLESKY_PIVOT_RATIO``): the LU of the whole pivots through it."""
        m = S.shape[0]
        s, g = scale[:m], scale[m:]
        try:
            L = sla.cholesky(s[:, None] * S * s[None, :], lower=True, check_finite=False)
        except np.linalg.LinAlgError:
            return None
        d = np.diag(L) ** 2
        if not d.min() >= COARSE_CHOLESKY_PIVOT_RATIO * d.max():
            return None
        Y = sla.solve_triangular(L, s[:, None] * G * g[None, :], lower=True, check_finite=False)   # -M_g
        T = g[:, None] * A * g[None, :] + Y.T @ Y                                                # -M_a + Y^T Y
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sla.LinAlgWarning)   # judged by the pivots
            lu_T = sla.lu_factor(T) if len(T) else (T, np.zeros(0, dtype=np.int32))
        pivots = np.concatenate([d, np.abs(np.diag(lu_T[0]))])
        return cls(None, L, (Y, lu_T), pivots)

    def solve(self, rhs):
        """M^-1 rhs for a vector of length m + k."""
        if self.lu is not None:
            return sla.lu_solve(self.lu, rhs)
        L, (Y, lu_T) = self.cholesky, self.modes
        m = L.shape[0]
        z = sla.solve_triangular(L, rhs[:m], lower=True, check_finite=False)
        y = -sla.lu_solve(lu_T, rhs[m:] + Y.T @ z) if len(Y.T) else np.zeros(0)
        x = sla.solve_triangular(L, z + Y @ y, lower=True, trans="T", check_finite=False)
        return np.concatenate([x, y])
