"""K^+: the factorisations of the stiffness that the constrained solves (linalg.kkt) use.

K^+ is the tangent stiffness without the fixed dofs and one pin per free rigid mode,
factorised once for many solves. :class:`EliminatedFactor` makes it (SuperLU, NGSolve's
sparse Cholesky, or the paper's ILU-preconditioned GMRES), with the Schur complements
and the augmented matrix of general rows; :class:`FactorBase` is what it shares with the
factorisation carried across crack passes (linalg.bordered). The size thresholds below
choose among these; docs/solvers.md says why. A factorisation that produces NaN/inf or
does not solve its own system raises :class:`SingularSystem`; it never returns numbers.
"""
import copy
import time

import numpy as np
import ngsolve as ng
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .kept import KeptColumns, row_keys
from .sparse import reproducible_threads, to_ngsolve, to_scipy
from .sparse_schur import schur_of
from .triangular import factor_arrays, supernodal_solver

#: the linear solvers of the Newton step: a sparse direct factorisation, or the paper's
#: ILU-preconditioned GMRES (slow; for comparison)
LINEAR_SOLVERS = ("direct", "gmres")

#: inverse="auto": SuperLU up to this many factorised dofs (faster solves for the many of
#: contact rounds), sparse Cholesky above (less fill). docs/solvers.md, "SuperLU or Cholesky"
SUPERLU_MAX_DOFS = 40000

#: from this many factorised dofs on, solves with SuperLU's factors go through the supernodal
#: L D L^T solver (its making pays back in a few dozen solves). docs/solvers.md, "Supernodal solves"
SUPERNODAL_MIN_DOFS = 2500

#: from this many factorised dofs on (SuperLU), the Schur complement is built by sparse
#: triangular solves, not from columns K^+ C^T. docs/solvers.md, "Sparse Schur complement"
SPARSE_SCHUR_MIN_DOFS = 5000

#: ... and from this many general rows on: fewer rows keep their columns K^+ C^T, after
#: which a KKT solve takes one solve instead of two. docs/solvers.md, "Sparse Schur complement"
SPARSE_SCHUR_MIN_ROWS = 9

#: up to this many free dofs a fresh tangent with general rows is factorised as the
#: augmented matrix (SuperLU), whose fill grows fast above. docs/solvers.md, "Augmented matrix"
AUGMENTED_MAX_DOFS = 5000


class SingularSystem(RuntimeError):
    """The KKT system is singular or too badly conditioned to trust its solution."""


class FactorBase:
    """What every K^+ shares: the rows it was made for, the corrected modes, Schur columns,
    the residual check of its first solve, the choice of path for general rows.

    A subclass calls this constructor, sets ``K`` (scipy CSR, all dofs), ``ndof``,
    ``fixed_dofs``, ``pins``, ``free`` (not fixed), ``factor_free`` (neither fixed nor
    pinned), ``inverse``, ``linear_solver``, and defines ``solve(B)`` and ``sparse_schur``.
    """

    #: True if a block solve gives every column bit for bit as that column solved alone
    #: (then every column met is kept, :meth:`columns_and_solve`)
    columns_independent = False

    def __init__(self):
        self._columns = KeptColumns()     # K^+ c of the rows met (columns_and_solve)
        self._checked = False     # the first solve checks its residual (check_solution)

    def check_solution(self, B, X):
        """Check once per factorisation that X = K^+ B solves its system (its largest column;
        a B zero on the factorised dofs leaves it to the next call): sparse Cholesky of a
        singular or indefinite matrix can return finite garbage.

        Parameters
        ----------
        B, X : numpy.ndarray, shape (ndof, k)
            Right-hand sides and the solutions of :meth:`solve`.

        Raises
        ------
        SingularSystem
            If the relative residual is 1e-6 or more (or not a number).
        """
        if self._checked:
            return
        j = int(np.argmax(np.abs(B[self.factor_free]).sum(axis=0)))
        b = B[self.factor_free, j]
        if not np.any(b):
            return
        r = (self.K @ X[:, j])[self.factor_free] - b
        rel = np.linalg.norm(r) / np.linalg.norm(b)
        if not rel < 1e-6:
            raise SingularSystem(f"the factorised stiffness does not solve its system (relative residual {rel:.1e}): singular or indefinite")
        self._checked = True

    def matches(self, fixed_dofs, pins):
        """True if this factorisation leaves out exactly these fixed dofs and pins.

        Parameters
        ----------
        fixed_dofs, pins : numpy.ndarray of int
            Compared element by element, in order, with those of the constructor (after its
            conversion to int64; pins=None became an empty array there, so pass an empty
            array, not None, for "no pins").

        Returns
        -------
        bool
        """
        return np.array_equal(self.fixed_dofs, fixed_dofs) and np.array_equal(self.pins, pins)

    def corrected_modes(self, R):
        """The modes corrected for the stiffness they meet, Rt = R - K^+ K R, and A = Rt^T K Rt.

        Rt equals R at the pins and K Rt vanishes at the other free dofs; A is the
        stiffness of the modes (zero when K R = 0: then Rt = R). See linalg.kkt.
        A mode whose K R is within the rounding of the product (64 eps |K| |R| entry by
        entry: a translation, which every element matrix annihilates) is taken as it is,
        without a solve. The result for the last R is kept (contact rounds reuse the
        factorisation).

        Parameters
        ----------
        R : scipy.sparse matrix, shape (ndof, k)
            Modes, zero at fixed dofs, resolved by the pins.

        Returns
        -------
        Rt : scipy.sparse.csr_matrix, shape (ndof, k)
            Zero at fixed dofs.
        A : numpy.ndarray, shape (k, k)
            Symmetric.
        """
        R = sp.csr_matrix(R)
        key = R.indptr.tobytes() + R.indices.tobytes() + R.data.tobytes()
        cached = getattr(self, "_modes", None)
        if cached is not None and cached[0] == key:
            return cached[1], cached[2]
        dense = R.toarray()
        KR = self.K @ dense
        KR[~self.free] = 0.0
        K = sp.csr_matrix(self.K)
        K_abs = sp.csr_matrix((np.abs(K.data), K.indices, K.indptr), shape=K.shape)   # |K|, no index copies
        rounding = 64 * np.finfo(float).eps * (K_abs @ np.abs(dense))
        stiff = np.flatnonzero(np.any(np.abs(KR) > rounding, axis=0))
        if len(stiff):
            Rt = dense.copy()
            Rt[:, stiff] -= self.solve(KR[:, stiff])
            KRt = self.K @ Rt
            Rt_sparse = sp.csr_matrix(Rt)
        else:
            Rt, KRt = dense, KR          # every mode as it is: K Rt is K R (only free rows count)
            Rt_sparse = R.copy()
            Rt_sparse.eliminate_zeros()  # as the conversion from the dense array would
        A = Rt[self.free].T @ KRt[self.free]
        A = 0.5 * (A + A.T)
        self._modes = (key, Rt_sparse, A)
        return Rt_sparse, A

    def columns(self, C):
        """Z = K^+ C^T (ndof, m); rows met before (bitwise) are not solved again (linalg.kept).

        Parameters
        ----------
        C : scipy.sparse matrix or array_like, shape (m, ndof)
            Constraint rows.

        Returns
        -------
        numpy.ndarray, shape (ndof, m)
            Column i is K^+ C_i^T, zero at fixed dofs and pins. Raises SingularSystem as
            :meth:`solve`.
        """
        return self.columns_and_solve(C, np.zeros((self.ndof, 0)))[0]

    def columns_and_solve(self, C, B):
        """:meth:`columns` of C and K^+ B, solved in one block: a block of right-hand sides
        costs much less than as many single solves (memory-bound triangular solves).

        Parameters
        ----------
        C : scipy.sparse matrix or array_like, shape (m, ndof)
            Constraint rows.
        B : numpy.ndarray, shape (ndof, k)
            Right-hand sides, as for ``solve``.

        Returns
        -------
        Z : numpy.ndarray, shape (ndof, m)
        X : numpy.ndarray, shape (ndof, k)

        Raises
        ------
        SingularSystem
            From :meth:`solve`.
        """
        C = sp.csr_matrix(C)
        keys = row_keys(C)
        Z = np.zeros((self.ndof, len(keys)))
        new = self._columns.fill(keys, Z)
        X = B
        if new or B.shape[1]:
            solved = self.solve(np.hstack([C[new].T.toarray(), B]))
            Z[:, new], X = solved[:, :len(new)], solved[:, len(new):]
        self._columns.keep(keys, Z, self.columns_independent)
        return Z, X

    @property
    def augmented_pays(self):
        """True if a fresh tangent with general rows is best solved as the augmented matrix:
        a direct SuperLU factorisation with at most ``AUGMENTED_MAX_DOFS`` free dofs."""
        return (self.linear_solver == "direct" and self.inverse == "superlu"
                and np.count_nonzero(self.free) <= AUGMENTED_MAX_DOFS)

    def keeps_columns(self, m):
        """Whether a Schur complement keeps the columns K^+ C^T (else :meth:`schur` makes it).

        Parameters
        ----------
        m : int
            The number of general rows.

        Returns
        -------
        bool
            False where ``sparse_schur`` and m >= ``SPARSE_SCHUR_MIN_ROWS``."""
        return not (self.sparse_schur and m >= SPARSE_SCHUR_MIN_ROWS)


class EliminatedFactor(FactorBase):
    """K^+: the stiffness without fixed dofs and pins, factorised once, for many solves.

    Kept between the constrained solves of one load (contact rounds, modified Newton).
    The direct factorisation of K_ff is made at first need (:meth:`factorise`): a solver on
    the augmented path factorises K with its rows instead (:meth:`augmented`, which keeps
    the factorisation of the last rows). For the Schur path it keeps K^+ c of the rows
    c met (:meth:`columns`): rows kept from one round to the next cost no solve.

    Parameters
    ----------
    K : scipy.sparse matrix or ngsolve.SparseMatrix
        Tangent stiffness on all dofs (an NGSolve matrix is copied to scipy CSR; a scipy one is
        kept as given: do not change it while in use).
    fixed_dofs, pins : array_like of int
        Dofs left out of the factorisation: those fixed by single-dof rows, and one pin per
        free rigid mode (``rigid.Support.pins``; None for none).
    linear_solver, inverse, gmres_tol
        See ConstrainedSolver. ``inverse`` is used only by "direct", ``gmres_tol`` (the
        relative residual GMRES must reach) only by "gmres".
    pattern : ngsolve.la.SparseMatrixd, optional
        An NGSolve matrix of K's sparsity pattern, for NGSolve's factorisation (to_ngsolve).
    schur_by_dofs : bool
        :meth:`schur` through K^-1 on the rows' dofs (``linalg.sparse_schur.DofSchur``).
    grouped_products : bool
        Else its products by groups of the factor's rows (3D; ``sparse_schur.SparseSchur``).

    Attributes
    ----------
    seconds : float
        Time spent factorising and in triangular solves (or GMRES) so far.

    Raises
    ------
    ValueError
        If ``linear_solver`` is not one of ``LINEAR_SOLVERS``.
    SingularSystem
        If the incomplete LU factorisation of "gmres" fails. A singular K under "direct"
        is found only by the first :meth:`solve`.
    """

    def __init__(self, K, fixed_dofs, pins=None, linear_solver="direct", inverse="auto",
                 gmres_tol=1e-12, pattern=None, schur_by_dofs=False, grouped_products=False):
        if linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {linear_solver!r}")
        t0 = time.perf_counter()
        super().__init__()
        self.K = to_scipy(K)      # products with K: scipy's CSR product
        self._ngsolve_pattern = K if isinstance(K, ng.la.SparseMatrixd) else pattern
        self.ndof = self.K.shape[0]
        self.fixed_dofs = np.asarray(fixed_dofs, dtype=np.int64)
        self.pins = np.zeros(0, dtype=np.int64) if pins is None else np.asarray(pins, dtype=np.int64)
        self.free = np.ones(self.ndof, dtype=bool)
        self.free[self.fixed_dofs] = False
        self.factor_free = self.free.copy()
        self.factor_free[self.pins] = False
        self.linear_solver = linear_solver
        self.gmres_tol = gmres_tol
        self._tmp = ng.BaseVector(self.ndof)     # NGSolve's solvers work on its vectors
        self._sparse, self._schur_kind = None, "dofs" if schur_by_dofs else ("grouped" if grouped_products else "rows")
        self._triangles = None    # the factors' arrays for the C++ triangular solves (factor_arrays)
        self._lu = None
        self._ldl = None          # the supernodal L D L^T solver of the factors (SUPERNODAL_MIN_DOFS)
        self._free_block = None   # K on all free dofs (pins included), scipy CSC (free_block)
        if inverse == "auto":
            inverse = "superlu" if np.count_nonzero(self.factor_free) <= SUPERLU_MAX_DOFS else "sparsecholesky"
        self.inverse = inverse
        self._inv = None
        self._augmented = None    # (row key, factorised augmented matrix) of the last rows
        if linear_solver == "gmres":
            Kff = self._factorised_block()
            self._Kff = Kff
            try:
                ilu = spla.spilu(Kff, drop_tol=1e-5, fill_factor=20, permc_spec="MMD_AT_PLUS_A")
            except RuntimeError as err:
                raise SingularSystem(f"ILU factorisation failed: {err}") from None
            self._precond = spla.LinearOperator(Kff.shape, ilu.solve)
        self.seconds = time.perf_counter() - t0

    def without_caches(self):
        """The same factorisation, with only the kept columns of column-by-column solves.

        It solves as a factor made afresh of the same matrix would, bit for bit, so that a
        factorisation carried to another load step (mechanics.tangent.SavedTangent.kept)
        solves as the one a resumed run makes again (:attr:`columns_independent`).

        Returns
        -------
        EliminatedFactor
            Sharing the matrix and its factorisation (both read only).
        """
        other = copy.copy(self)
        other._columns = self._columns.copy() if self.columns_independent else KeptColumns()
        other._sparse, other._augmented, other._checked = None, None, False
        other.__dict__.pop("_modes", None)
        return other

    @property
    def columns_independent(self):
        """True unless SuperLU factorised K_ff, whose supernodal block solves round a column
        differently in another block (NGSolve's do not; GMRES solves column by column)."""
        return self.linear_solver == "gmres" or self.inverse != "superlu"

    @property
    def factorised(self):
        """True once K_ff is factorised (the direct solvers factorise at first need)."""
        return self.linear_solver == "gmres" or self._lu is not None or self._inv is not None

    def factorise(self):
        """Factorise K_ff now, if not yet done (a no-op for "gmres" and when done).

        The direct factorisation is made at first need: a ConstrainedSolver that solves
        through the augmented matrix (:meth:`augmented`) never needs it. Call this outside
        an NGSolve TaskManager (the factorisation runs on one thread, see
        :func:`reproducible_threads`); ConstrainedSolver does so when it builds.

        Raises
        ------
        SingularSystem
            If SuperLU finds K_ff exactly singular.
        """
        if self.factorised:
            return
        t0 = time.perf_counter()
        if self.inverse == "superlu":
            Kff = self._factorised_block()
            try:
                # symmetric ordering, diagonal pivots unless one is 100 times below its column
                self._lu = spla.splu(Kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01,
                                     options={"SymmetricMode": True})
            except RuntimeError as err:
                raise SingularSystem(f"the sparse LU factorisation failed: {err}") from None
        else:
            factor_dofs = ng.BitArray(self.ndof)
            factor_dofs.Set()
            for d in np.flatnonzero(~self.factor_free).tolist():
                factor_dofs.Clear(d)
            with reproducible_threads():
                self._inv = to_ngsolve(self.K, self._ngsolve_pattern).Inverse(factor_dofs, inverse=self.inverse)
                self._ngsolve_pattern = None     # not kept alive with the factor
        self.seconds += time.perf_counter() - t0

    def _factorised_block(self):
        """K on the factorised dofs (without fixed dofs and pins), scipy CSC."""
        return to_scipy(self.K)[self.factor_free][:, self.factor_free].tocsc()

    @property
    def free_block(self):
        """K on all free dofs (pins included), scipy CSC: made at first need, then kept."""
        if self._free_block is None:
            self._free_block = to_scipy(self.K)[self.free][:, self.free].tocsc()
        return self._free_block

    def augmented(self, C):
        """The augmented matrix [[K_ff, C_f^T D], [D C_f, 0]] of rows C, LU-factorised.

        K_ff is K on all free dofs (pins included: the rows hold the free modes, so the
        augmented matrix is regular without pins and corrected modes). D scales every row
        to the mean diagonal of K_ff, so that the pivots of the multiplier block are of the
        size of those of K (multiplier = D times the unknown). SuperLU with a symmetric
        ordering and threshold pivoting: the zero block needs off-diagonal pivots. The
        factorisation of the last rows is kept (a solver rebuilt for the same rows reuses it).

        Parameters
        ----------
        C : scipy.sparse matrix, shape (m, ndof)
            General rows, m >= 1.

        Returns
        -------
        lu : scipy.sparse.linalg.SuperLU
            Factorisation of the augmented matrix of size n_free + m (free dofs in order,
            then the rows).
        row_scale : numpy.ndarray (m,)
            D.

        Raises
        ------
        SingularSystem
            If the augmented matrix is singular or nearly so (pivot ratio <= 1e-13): rows
            (nearly) linearly dependent, leaving rigid modes free, or a singular K.
        """
        C = sp.csr_matrix(C)
        key = C.indptr.tobytes() + C.indices.tobytes() + C.data.tobytes()
        if self._augmented is not None and self._augmented[0] == key:
            return self._augmented[1]
        t0 = time.perf_counter()
        Kff = self.free_block
        Cf = C[:, self.free]
        size = float(np.abs(Kff.diagonal()).mean())
        norms = np.sqrt(np.asarray(Cf.multiply(Cf).sum(axis=1)).ravel())
        row_scale = size / np.where(norms > 0, norms, 1.0)
        DC = sp.diags(row_scale) @ Cf
        A = sp.bmat([[Kff, DC.T], [DC, None]], format="csc")
        m = C.shape[0]
        message = (f"the {m} general constraint rows are (nearly) linearly dependent or leave rigid "
                   f"modes free (or the stiffness is singular)")
        try:
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.1,
                           options={"SymmetricMode": True})
        except RuntimeError as err:
            raise SingularSystem(f"{message}: {err}") from None
        pivots = np.abs(lu.U.diagonal())
        if not np.all(np.isfinite(pivots)) or pivots.min() <= 1e-13 * pivots.max():
            raise SingularSystem(f"{message}: pivot ratio {pivots.min() / pivots.max():.2e}")
        self._augmented = (key, (lu, row_scale))
        self.seconds += time.perf_counter() - t0
        return lu, row_scale

    def solve(self, B):
        """X = K^+ B for a full-length right-hand side (ndof,) or a block (ndof, m).

        Entries of B at fixed dofs and pins are ignored; X is zero there. Checked: the
        factorisation must solve its own system.

        Parameters
        ----------
        B : numpy.ndarray, shape (ndof,) or (ndof, m)
            Right-hand side(s) in NGSolve's dof layout (forces); m may be 0.

        Returns
        -------
        numpy.ndarray, same shape as B
            The solution(s) (displacements), float64.

        Raises
        ------
        SingularSystem
            "gmres": if GMRES does not converge for a column or gives NaN/inf. "direct": if
            the solution has NaN/inf, or if the first solve with a nonzero right-hand side
            on the factorised dofs leaves a relative residual of 1e-6 or more in its largest
            column (sparse Cholesky of a singular or indefinite matrix can return finite
            garbage; checked once per factorisation).
        """
        t0 = time.perf_counter()
        single = B.ndim == 1
        B = B[:, None] if single else B
        X = np.zeros(B.shape)
        if B.shape[1] == 0:
            return X[:, 0] if single else X
        if self.linear_solver == "gmres":
            for j in range(B.shape[1]):
                x, info = spla.gmres(self._Kff, B[self.factor_free, j], M=self._precond, rtol=self.gmres_tol,
                                     atol=0.0, restart=200, maxiter=50)
                if info != 0 or not np.all(np.isfinite(x)):
                    raise SingularSystem(f"GMRES did not converge (info={info})")
                X[self.factor_free, j] = x
        else:
            self.factorise()
            self._direct_solve(B, X)
            if not np.all(np.isfinite(X)):
                raise SingularSystem("the factorised stiffness produced NaN/inf: singular (a floating body?)")
            self.check_solution(B, X)
        self.seconds += time.perf_counter() - t0
        return X[:, 0] if single else X

    def _direct_solve(self, B, X):
        """X[factor_free] = K_ff^-1 B[factor_free] with the direct factorisation."""
        if self._lu is not None:
            X[self.factor_free] = self._superlu_solve(B[self.factor_free])
        else:
            # one multi-vector solve instead of a Python loop over columns
            rhs = ng.MultiVector(self._tmp, B.shape[1])
            for j in range(B.shape[1]):
                rhs[j].FV().NumPy()[:] = B[:, j]
            out = ng.MultiVector(self._tmp, B.shape[1])
            out[:] = self._inv * rhs
            for j in range(B.shape[1]):
                X[:, j] = out[j].FV().NumPy()

    def solve_factorised(self, b):
        """K_ff^-1 b on the factorised dofs only: the solve of :meth:`solve` without the
        full-length copies, for a caller that has checked the factorisation through
        :meth:`solve` (linalg.bordered.BorderedFactor).

        Parameters
        ----------
        b : numpy.ndarray, shape (n,) or (n, k)
            Right-hand side(s) on the factorised dofs, in their order (n of them).

        Returns
        -------
        numpy.ndarray
            Same shape as b.

        Raises
        ------
        SingularSystem
            If the solution has NaN/inf.
        """
        if self._lu is not None:
            x = self._superlu_solve(b)
        else:
            B = np.zeros((self.ndof,) + b.shape[1:])
            B[self.factor_free] = b
            x = self.solve(B)[self.factor_free]
        if not np.all(np.isfinite(x)):
            raise SingularSystem("the factorised stiffness produced NaN/inf: singular (a floating body?)")
        return x

    def _superlu_solve(self, b):
        """K_ff^-1 b with SuperLU's factors: through the supernodal L D L^T solver where it
        applies (``SUPERNODAL_MIN_DOFS``, every pivot diagonal), else SuperLU's own solve."""
        ldl = self._supernodal()
        return self._lu.solve(np.asfortranarray(b)) if ldl is None else ldl.solve(b)

    def _supernodal(self):
        """The factors' supernodal L D L^T solver (made at first need), or None (SUPERNODAL_MIN_DOFS)."""
        if self._ldl is None:
            ldl = None
            if self._lu.shape[0] >= SUPERNODAL_MIN_DOFS:
                try:
                    ldl = supernodal_solver(self._lu, self._factor_arrays())
                except ValueError as err:      # a zero or non-finite pivot: K_ff is singular
                    raise SingularSystem(f"the sparse LU factors cannot be solved with: {err}") from None
            self._ldl = False if ldl is None else ldl
        return None if self._ldl is False else self._ldl

    @property
    def sparse_schur(self):
        """True if :meth:`schur` takes the sparse triangular solves (SuperLU, from
        ``SPARSE_SCHUR_MIN_DOFS`` factorised dofs on); the Schur path then keeps no columns."""
        return (self.linear_solver == "direct" and self.inverse == "superlu"
                and np.count_nonzero(self.factor_free) >= SPARSE_SCHUR_MIN_DOFS)

    def schur(self, C):
        """S = C K^+ C^T (m, m) by sparse triangular solves with SuperLU's factors
        (:class:`linalg.sparse_schur.SparseSchur`): the rows met in the last call are not
        solved again (recognised as in :meth:`columns`), nor their entries of S computed
        again; with ``schur_by_dofs`` from K^+ on the rows' dofs, kept (``DofSchur``).
        Entries of C at fixed dofs and pins are ignored, as K^+ is zero there.

        Parameters
        ----------
        C : scipy.sparse matrix, shape (m, ndof)
            Constraint rows.

        Returns
        -------
        numpy.ndarray, shape (m, m)

        Raises
        ------
        ValueError
            If the factorisation is not SuperLU's (:attr:`sparse_schur` is False).
        SingularSystem
            If the factorisation fails, or a pivot of U is zero.
        """
        if self.linear_solver != "direct" or self.inverse != "superlu":
            raise ValueError("EliminatedFactor.schur needs the SuperLU factorisation")
        self.factorise()
        t0 = time.perf_counter()
        if self._sparse is None:
            index = -np.ones(self.ndof, dtype=np.int64)
            index[self.factor_free] = np.arange(self._lu.shape[0])          # dof -> row of K_ff
            self._sparse = schur_of(self._schur_kind, self._lu, self._factor_arrays(), self._supernodal(), index)
        try:
            S = self._sparse.complement(C)
        except (RuntimeError, ValueError) as err:
            raise SingularSystem(f"sparse triangular solve failed: {err}") from None
        if not np.all(np.isfinite(S)):
            raise SingularSystem("the sparse triangular solves produced NaN/inf: singular (a floating body?)")
        self.seconds += time.perf_counter() - t0
        return S

    def _factor_arrays(self):
        """:func:`factor_arrays` of the SuperLU factorisation, made once."""
        if self._triangles is None:
            self._triangles = factor_arrays(self._lu)
        return self._triangles
