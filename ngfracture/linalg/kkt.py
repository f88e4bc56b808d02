"""The constrained linear solve of the paper's eq. 3 / eq. 12.

    [ K  C^T ] [du ]   [r]
    [ C  0   ] [lam] = [h]      plus fixed dofs du_c given (single-dof rows).

How it is solved (chosen by measurement, see docs/solvers.md): the single-dof rows are
eliminated exactly. Without general rows the symmetric positive definite block K_ff is
factorised (SuperLU up to ``SUPERLU_MAX_DOFS`` dofs, NGSolve's sparse Cholesky above) and
kept for every solve until the tangent changes (modified Newton). With general rows
(contact, holds of free modes) on a SuperLU-sized K_ff the augmented matrix

    [ K_ff   C_f^T D ]
    [ D C_f  0       ]      D: every row scaled to the mean diagonal of K_ff

is LU-factorised once per tangent and row set (SuperLU, symmetric ordering, threshold
pivoting): one sparse factorisation instead of one triangular solve per row for the
Schur complement, and no pins, since the rows hold the free rigid modes (measured on the
disk scene's steps 64 to 68: 118 s against 184 s, the same cracks). The first solve of
each augmented factorisation must solve its own system (backward error below 1e-6); a
nearly singular matrix is reported, not solved. Above ``AUGMENTED_MAX_DOFS`` SuperLU's
fill makes the augmented matrix dearer than a factorisation of K_ff plus the Schur
columns, so the Schur path below is taken there.

The Schur-complement path below is kept for the contact complementarity problem
(:meth:`ConstrainedSolver.solve_unilateral`), which needs S = C K^+ C^T itself, and can
be asked for with ``path="schur"``.

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
Measured on the disintegrating disk (two half-disks and a one-triangle fragment held by
contact): with R instead of Rt, modified Newton contracted by only 0.74 per iteration
and stopped at 60 iterations, and full Newton diverged.

Failures are reported, never returned as numbers: a factorisation that produces
NaN/inf or does not solve its own system is ``SingularSystem``.
"""
import contextlib
import copy
import time
import warnings

import numpy as np
import ngsolve as ng
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import _ngfracture as _ext

LINEAR_SOLVERS = ("direct", "gmres")


class SingularSystem(RuntimeError):
    """The KKT system is singular or too badly conditioned to trust its solution."""


def to_scipy(mat):
    """A sparse matrix as a scipy CSR matrix.

    Parameters
    ----------
    mat : ngsolve.SparseMatrix or scipy.sparse matrix
        A real sparse matrix; an NGSolve one is copied (``mat.CSR()`` gives its values,
        column indices and row pointers), a scipy CSR one returned as it is.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (mat.height, mat.width)
        The same entries, including explicitly stored zeros; an NGSolve matrix's arrays
        are copied, so later changes to ``mat`` do not show in it.
    """
    if sp.issparse(mat):
        return sp.csr_matrix(mat)
    vals, cols, rows = mat.CSR()
    return sp.csr_matrix((np.array(vals), np.array(cols), np.array(rows)), shape=(mat.height, mat.width))


def to_ngsolve(mat):
    """A scipy sparse matrix as an NGSolve sparse matrix (for NGSolve's direct solvers).

    Parameters
    ----------
    mat : scipy.sparse matrix
        Real, square or not.

    Returns
    -------
    ngsolve.la.SparseMatrixd
        The same entries (duplicates summed).
    """
    coo = sp.coo_matrix(mat)
    return ng.la.SparseMatrixd.CreateFromCOO(coo.row.astype(np.int64), coo.col.astype(np.int64),
                                             coo.data, coo.shape[0], coo.shape[1])


_blas = None     # threadpoolctl's view of the loaded BLAS libraries, made at first use


@contextlib.contextmanager
def single_threaded_blas():
    """One BLAS thread for the small dense algebra of the solves (usable as a decorator).

    Schur complements, the QP of the contact solve, the Gram and rank tests are dense
    matrices of a few hundred rows, where OpenBLAS' threads only wait for each other, and
    on a busy machine much longer: measured on the 2-core machine with other jobs running,
    0.025 s against 0.002 s for the SVD of a 250 x 90 matrix, 0.034 against 0.0026 s for
    the LU of 250 x 250, and a late step of the disintegrating disk 10.0 s against 4.3 s.
    One thread also makes the dense results independent of the core count. The previous
    limits are restored on leaving (threadpoolctl, which finds numpy's and scipy's BLAS).

    Yields
    ------
    None
        The body runs with every loaded BLAS limited to one thread.
    """
    global _blas
    if _blas is None:
        from threadpoolctl import ThreadpoolController
        _blas = ThreadpoolController()
    with _blas.limit(limits=1, user_api="blas"):
        yield


@contextlib.contextmanager
def reproducible_threads():
    """One NGSolve thread while factorising, for results that repeat to the last bit.

    NGSolve's sparse Cholesky factorises in parallel with a summation order that varies
    between runs: two factorisations of the same matrix gave solutions differing in the
    last bit (3e-16 relative), enough to change a crack pattern or a resumed run. With one
    thread it is bitwise reproducible; on the 2-core machine it was not slower
    (1.87-1.90 s against 1.89-2.13 s at 145k P1 dofs). Must be entered outside a
    TaskManager context (its thread count is fixed when it starts).

    Yields
    ------
    None
        The body of the ``with`` block runs with ``ngsolve.SetNumThreads(1)``; the previous
        thread count is restored on leaving it, also when it raises.
    """
    before = ng.GetNumThreads()
    ng.SetNumThreads(1)
    try:
        yield
    finally:
        ng.SetNumThreads(before)


#: up to this many factorised dofs inverse="auto" takes scipy's SuperLU, above it NGSolve's
#: sparse Cholesky. Measured on the disk's stiffness, one thread, factorisation / one solve
#: of a block of 50 right-hand sides, per right-hand side:
#:   2042 dofs: NGSolve 7.6 ms / 0.33 ms, SuperLU 8.0 ms / 0.12 ms;
#:   7870 dofs: 23 ms / 1.8 ms against 54 ms / 0.9 ms; 117208 dofs: 0.77 s / 88 ms against 2.2 s / 23 ms.
#: Contact makes one solve per row for each factorisation (Schur columns, computed again
#: in every contact round), so SuperLU wins where there are many: at the paper's resolution
#: both ways (the disk's steps 64 to 75: 171 s against 239 s, the same cracks), and on the
#: plate's tangent at 31478 dofs a block of 100 right-hand sides takes 0.55 s against 1.08 s
#: (factorisation 0.30 s against 0.19 s: SuperLU pays off from about 20 solves per
#: factorisation, and a contact round makes more). Above 40000 dofs SuperLU's fill grows
#: faster than NGSolve's (117208 dofs: factorisation 2.2 s against 0.77 s).
SUPERLU_MAX_DOFS = 40000

#: from this many factorised dofs on, the triangular solves with SuperLU's factors go through
#: ``_ngfracture.SupernodalLDL`` (L D L^T with L in dense supernodal panels, made once per
#: factorisation), where every pivot was diagonal: one right-hand side 0.12 against 0.43 ms
#: at 2.9k dofs, 1.6 against 4.2 ms at 16k, 5.7 against 10.3 ms at 31k (the plate's
#: tangents); making it costs 5, 30 and 90 to 190 ms, paid back within a few dozen solves.
#: Below, factorisations serve few solves each (contact rounds of the disks, full Newton)
#: and SuperLU's own solve stays
SUPERNODAL_MIN_DOFS = 2500

#: from this many factorised dofs on (SuperLU), the Schur complement C K^-1 C^T is built by
#: triangular solves that follow only the reach of each row's few nonzeros in the factors
#: (EliminatedFactor.schur) instead of full solves for K^-1 C^T. Measured on the notched
#: plate (benchmarks/schur.py, 68 to 149 contact-like rows): 2216 dofs 5.3 against 11 ms,
#: 8210 dofs 48 against 96 ms, 31716 dofs 0.18 against 0.66 s. Below, the default scenes
#: keep the columns (and their results bit for bit); the path costs one more solve per
#: KKT solve.
SPARSE_SCHUR_MIN_DOFS = 5000

#: ... and from this many general rows on: fewer rows take their columns K^+ C^T (one block
#: solve for the rows, kept), after which a KKT solve and each refinement take one solve
#: instead of two (the plate splitting at 31k dofs holds one free mode by one row)
SPARSE_SCHUR_MIN_ROWS = 9

#: up to this many free dofs a fresh tangent with general rows is factorised as the
#: augmented matrix (SuperLU); above, SuperLU's fill of the augmented matrix grows fast
#: (plate at 8210 dofs, 100 rows: 1.9 s against 0.25 s for K_ff plus 1.8 s for the columns)
AUGMENTED_MAX_DOFS = 5000


class FactorBase:
    """What every K^+ shares: the rows it was made for, the corrected modes, Schur columns,
    the residual check of its first solve.

    A subclass sets ``K`` (scipy CSR, all dofs), ``ndof``, ``fixed_dofs``, ``pins``, ``free``
    (not fixed), ``factor_free`` (neither fixed nor pinned), ``_columns`` ({}),
    ``_checked`` (False) and defines ``solve(B)``.
    """

    def _check(self, B, X):
        """One residual check per factorisation: sparse Cholesky of a singular or
        indefinite matrix can return finite garbage."""
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
        stiffness of the modes (zero when K R = 0: then Rt = R). See the module docstring.
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
        """Z = K^+ C^T (ndof, m); rows met in the last call are not solved again.

        A row is recognised by its stored column indices and values (bitwise); the cache
        keeps only the rows of the latest call.

        Parameters
        ----------
        C : scipy.sparse matrix or array_like, shape (m, ndof)
            Constraint rows.

        Returns
        -------
        numpy.ndarray, shape (ndof, m)
            Column i is K^+ C_i^T, zero at fixed dofs and pins.

        Raises
        ------
        SingularSystem
            From :meth:`solve`, if the rows not cached need a solve and it fails.
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
        keys = [C.indices[s:e].tobytes() + C.data[s:e].tobytes() for s, e in zip(C.indptr[:-1], C.indptr[1:])]
        Z = np.zeros((self.ndof, len(keys)))
        new = []
        for i, key in enumerate(keys):
            if key in self._columns:
                Z[:, i] = self._columns[key]
            else:
                new.append(i)
        X = B
        if new or B.shape[1]:
            solved = self.solve(np.hstack([C[new].T.toarray(), B]))
            Z[:, new], X = solved[:, :len(new)], solved[:, len(new):]
        self._columns = {key: Z[:, i] for i, key in enumerate(keys)}
        return Z, X


class EliminatedFactor(FactorBase):
    """K^+: the stiffness without fixed dofs and pins, factorised once, for many solves.

    Kept between the constrained solves of one load (contact rounds, modified Newton).
    The direct factorisation of K_ff is made at first need (:meth:`factorise`): a solver on
    the augmented path factorises K with its rows instead (:meth:`augmented`, which keeps
    the factorisation of the last rows). For the Schur path it remembers K^+ c for the
    rows c of the last Schur complement, so rows kept from one round to the next cost no
    solve.

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
                 gmres_tol=1e-12):
        if linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {linear_solver!r}")
        t0 = time.perf_counter()
        self.K = to_scipy(K)      # products with K: scipy's CSR product
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
        self._columns = {}        # row key -> K^+ row^T, for the rows of the last Schur complement
        self._reach = {}          # row key -> its sparse triangular solves (schur), last rows
        self._triangles = None    # the factors' arrays for the C++ triangular solves (factor_arrays)
        self._lu = None
        self._ldl = None          # the supernodal L D L^T solver of the factors (SUPERNODAL_MIN_DOFS)
        self._free_block = None   # K on all free dofs (pins included), scipy CSC, made at first need
        self._checked = False     # direct solvers: the first solve checks its residual
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
        """The same factorisation, with none of the results kept from its solves.

        It solves as a factor made afresh of the same matrix would, bit for bit: which rows
        a block solve meets decides the block's rounding, so a factorisation carried to
        another load step (solver.SavedTangent.kept) starts with no kept columns, as the
        one a resumed run makes again.

        Returns
        -------
        EliminatedFactor
            Sharing the matrix and its factorisation (both read only).
        """
        other = copy.copy(self)
        other._columns, other._reach, other._augmented, other._checked = {}, {}, None, False
        other.__dict__.pop("_modes", None)
        return other

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
                self._inv = to_ngsolve(self.K).Inverse(factor_dofs, inverse=self.inverse)
        self.seconds += time.perf_counter() - t0

    def _factorised_block(self):
        """K on the factorised dofs (without fixed dofs and pins), scipy CSC."""
        return to_scipy(self.K)[self.factor_free][:, self.factor_free].tocsc()

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
        if self._free_block is None:
            self._free_block = to_scipy(self.K)[self.free][:, self.free].tocsc()
        Kff = self._free_block
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
            if not self._checked:
                self._check(B, X)
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
        :meth:`solve` (split_factor.BorderedFactor).

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
        if self._ldl is None:
            n = self._lu.shape[0]
            lower, _, pivots = self._factor_arrays() if n >= SUPERNODAL_MIN_DOFS else (None, None, None)
            if pivots is None:
                self._ldl = False
            else:
                try:
                    self._ldl = _ext.SupernodalLDL(n, *lower, pivots, self._lu.perm_r.astype(np.int64))
                except ValueError as err:      # a zero or non-finite pivot: K_ff is singular
                    raise SingularSystem(f"the sparse LU factors cannot be solved with: {err}") from None
        if self._ldl is False:
            return self._lu.solve(np.asfortranarray(b))
        return self._ldl.solve(b)

    @property
    def sparse_schur(self):
        """True if :meth:`schur` takes the sparse triangular solves (SuperLU, from
        ``SPARSE_SCHUR_MIN_DOFS`` factorised dofs on); the Schur path then keeps no columns."""
        return (self.linear_solver == "direct" and self.inverse == "superlu"
                and np.count_nonzero(self.factor_free) >= SPARSE_SCHUR_MIN_DOFS)

    def schur(self, C):
        """S = C K^+ C^T (m, m) by sparse triangular solves; rows met in the last call are
        not solved again (recognised as in :meth:`columns`).

        With the SuperLU factors Pr K_ff Pc = L U: S = X^T Y, Y = L^-1 Pr C^T and
        X = U^-T Pc^T C^T, each column a Gilbert-Peierls solve over the reach of the row's
        nonzeros (``_ngfracture.SparseLowerSolve``); where every pivot was diagonal
        (Pr = Pc^T) the symmetric K_ff has U = D L^T and X = D^-1 Y (one solve per row).
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
        C = sp.csr_matrix(C)
        keys = [C.indices[s:e].tobytes() + C.data[s:e].tobytes() for s, e in zip(C.indptr[:-1], C.indptr[1:])]
        new = [i for i, key in enumerate(keys) if key not in self._reach]
        fresh = dict(zip((keys[i] for i in new), self._reach_solves(C[new]))) if new else {}
        self._reach = {key: self._reach[key] if key in self._reach else fresh[key] for key in keys}
        n = self._lu.shape[0]
        Y = _sparse_columns([self._reach[key][0] for key in keys], n)
        X = _sparse_columns([self._reach[key][1] for key in keys], n)
        S = (X.T @ Y).toarray()
        if not np.all(np.isfinite(S)):
            raise SingularSystem("the sparse triangular solves produced NaN/inf: singular (a floating body?)")
        self.seconds += time.perf_counter() - t0
        return S

    def _factor_arrays(self):
        """:func:`factor_arrays` of the SuperLU factorisation, made once."""
        if self._triangles is None:
            self._triangles = factor_arrays(self._lu)
        return self._triangles

    def _reach_solves(self, C):
        """Per row of C: ((rows, values) of its column of Y, the same of X), see :meth:`schur`."""
        n = self._lu.shape[0]
        lower, upper_t, pivots = self._factor_arrays()
        index = -np.ones(self.ndof, dtype=np.int64)
        index[self.factor_free] = np.arange(n)          # dof -> row of K_ff
        B = C.tocoo()
        rows = index[B.col]
        keep = rows >= 0

        def solve(factor, perm, unit):
            lp, li, lx = factor
            rhs = sp.csc_matrix((B.data[keep], (perm[rows[keep]], B.row[keep])), shape=(n, C.shape[0]))
            try:
                return _ext.SparseLowerSolve(n, lp, li, lx, unit, rhs.indptr.astype(np.int64),
                                             rhs.indices.astype(np.int32), rhs.data)
            except RuntimeError as err:
                raise SingularSystem(f"sparse triangular solve failed: {err}") from None

        yp, yi, yx = solve(lower, self._lu.perm_r, True)
        if upper_t is None:
            xp, xi, xx = yp, yi, yx / pivots[yi]       # U = D L^T
        else:
            xp, xi, xx = solve(upper_t, self._lu.perm_c, False)
        return [((yi[yp[j]:yp[j + 1]], yx[yp[j]:yp[j + 1]]), (xi[xp[j]:xp[j + 1]], xx[xp[j]:xp[j + 1]]))
                for j in range(C.shape[0])]


def factor_arrays(lu):
    """SuperLU's factors Pr K_ff Pc = L U as the arrays of the C++ triangular solves.

    Parameters
    ----------
    lu : scipy.sparse.linalg.SuperLU

    Returns
    -------
    lower : (numpy.ndarray int64, numpy.ndarray int32, numpy.ndarray)
        L as CSC (pointers, rows sorted within each column, values; its unit diagonal stored).
    upper_t : same as lower, or None
        U^T as CSC (the CSR of U); None where every pivot was diagonal (Pr = Pc^T): the
        symmetric K_ff then has U = D L^T.
    pivots : numpy.ndarray or None
        D where U = D L^T, else None.
    """
    L = lu.L.tocsc()
    L.sort_indices()
    lower = (L.indptr.astype(np.int64), L.indices.astype(np.int32), L.data)
    if np.array_equal(lu.perm_r, lu.perm_c):
        return lower, None, lu.U.diagonal()
    Ut = lu.U.tocsr()
    return lower, (Ut.indptr.astype(np.int64), Ut.indices.astype(np.int32), Ut.data), None


def _sparse_columns(columns, n):
    """A CSC matrix (n, len(columns)) from per-column (rows, values)."""
    lengths = np.array([len(r) for r, _ in columns], dtype=np.int64)
    rows = np.concatenate([r for r, _ in columns]) if columns else np.zeros(0, np.int32)
    values = np.concatenate([v for _, v in columns]) if columns else np.zeros(0)
    return sp.csc_matrix((values, rows, np.concatenate([[0], np.cumsum(lengths)])), shape=(n, len(columns)))


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
        Direct solver for "direct": "auto" (default: see ``SUPERLU_MAX_DOFS``), "superlu"
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
        complement with pins and corrected modes. "auto" (default): "augmented" where K_ff
        is factorised by SuperLU with at most ``AUGMENTED_MAX_DOFS`` free dofs, with general rows and
        without ``dependent_rows``, else "schur".
    first : (numpy.ndarray, numpy.ndarray), optional
        (r, du_fixed) of the first :meth:`solve`, if the caller knows them: where the Schur
        columns K^+ C^T are solved here, that solve's K^+ q is solved in the same block.

    Attributes
    ----------
    path : str
        The path chosen ("augmented" or "schur").

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
        if path not in ("auto", "augmented", "schur"):
            raise ValueError(f"path must be 'auto', 'augmented' or 'schur', got {path!r}")
        if path == "auto":
            # by measurement: SuperLU's fill of the augmented matrix grows fast with size
            # (plate at 8210 dofs, 100 rows: 1.9 s against 0.25 s for NGSolve's Cholesky of
            # K_ff plus 1.8 s for 100 Schur columns, which later rounds reuse)
            small = factor.inverse == "superlu" and np.count_nonzero(factor.free) <= AUGMENTED_MAX_DOFS
            path = "augmented" if self.m and factor.linear_solver == "direct" and small and not dependent_rows else "schur"
        if path == "augmented" and (dependent_rows or not self.m or factor.linear_solver != "direct"):
            raise ValueError("the augmented path needs independent general rows and a direct solver")
        self.path = path
        self._checked = False     # the augmented path checks the residual of its first solve
        self._first = None        # (q, K^+ q) of the first solve, solved with the columns
        if path == "augmented":
            self._augmented = factor.augmented(self.C)
            return
        factor.factorise()        # here, outside a TaskManager (see EliminatedFactor.factorise)
        if self.m:
            self._R, A = factor.corrected_modes(self._R)
            self._Rt = self._R.T
            if factor.sparse_schur and self.m >= SPARSE_SCHUR_MIN_ROWS:
                # no columns: the displacement correction takes one more solve per solve
                self._Z = None
                S = factor.schur(self.C)
            elif first is not None:
                q = self._load(*first)
                self._Z, X = factor.columns_and_solve(self.C, q[:, None])
                self._first = (q.copy(), X[:, 0])
                S = self.C @ self._Z
            else:
                self._Z = factor.columns(self.C)
                S = self.C @ self._Z
            S = 0.5 * (S + S.T)
            G = (self.C @ self._R).toarray()
            self._S, self._G = S, G       # kept for solve_unilateral
            self._coarse = None
            d = np.diag(S)
            d = np.where(d > 0, 1.0 / np.sqrt(np.where(d > 0, d, 1.0)), 1.0)
            gn = np.linalg.norm(d[:, None] * G, axis=0)
            self._scale = np.concatenate([d, np.where(gn > 0, 1.0 / np.where(gn > 0, gn, 1.0), 1.0)])
            if dependent_rows:
                return
            coarse = np.block([[S, -G], [-G.T, -A]])
            # equilibrated (the scale above), so that the pivot test does not depend on units:
            # S ~ 1/E while G ~ 1 (measured: E = 5e9 made a regular system look singular,
            # ratio 3e-13)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", sla.LinAlgWarning)   # judged by the pivots below
                self._coarse = sla.lu_factor(self._scale[:, None] * coarse * self._scale[None, :])
            pivots = np.abs(np.diag(self._coarse[0]))
            if not np.all(np.isfinite(pivots)) or pivots.min() <= 1e-12 * pivots.max():
                raise SingularSystem(f"the {self.m} general constraint rows are (nearly) linearly dependent "
                                     f"or leave rigid modes free: coarse pivot ratio {pivots.min() / pivots.max():.2e}")

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
        self.last_load_norm = float(np.linalg.norm(q[self.free]))
        if self.m:
            # Iterative refinement: the Schur complement through K^+ and the coarse problem
            # of the modes is not backward stable when pieces hang on contact and hold rows.
            # Measured on the disintegrating disk at maxh 0.06 (step 33, three pieces):
            # Newton's residual stalled at 1.5e-6 with increments of 1e-7 to 1e-6 in 60
            # iterations, full Newton and 32 substeps alike; with one refinement step it
            # converges in a few iterations. A K product per solve decides whether it is needed.
            # Without kept columns the correction K^+ C^T lam is a fresh solve, not the
            # columns S was made from, so the rows hold to the rounding of two different
            # solves: judged at 1e-13 the multipliers of held pieces came out 4e-10 off the
            # whole-KKT solution, at 1e-14 2e-13 (tests/test_kkt_paths.py).
            target = 1e-14 if self.path == "schur" and self._Z is None else 1e-13
            for refinement in range(self.REFINEMENTS + 1):
                res, res_rows, force_scale, row_scale = self._residual(r, h, du, lam)
                error = max(np.linalg.norm(res) / force_scale, np.linalg.norm(res_rows) / row_scale)
                if error <= target or refinement == self.REFINEMENTS:
                    break
                ddu, dlam, _ = self._solve_once(res, np.zeros_like(du), res_rows)
                du, lam = du + ddu, lam + dlam
            if self.path == "augmented" and not self._checked:
                # a nearly singular augmented matrix can pass the pivot test and return
                # finite garbage: its first solve must solve its own system, up to a
                # backward error (residuals against |K| |du|, |C^T| |lam|, |C| |du|: the
                # rounding of the products; measured 2e-5 of |K du| late in Newton)
                free = self.free
                Kabs = abs(self.factor._free_block) @ np.abs(du[free])
                force_size = (np.linalg.norm(Kabs) + np.linalg.norm((abs(self.C.T) @ np.abs(lam))[free])
                              + np.linalg.norm(r[free]) + np.linalg.norm(q[free]))
                rows_size = np.linalg.norm(h) + np.linalg.norm(self._C_abs @ np.abs(du))
                error = max(np.linalg.norm(res) / max(force_size, 1e-300), np.linalg.norm(res_rows) / max(rows_size, 1e-300))
                if not error < 1e-6:
                    raise SingularSystem(f"the constrained system is singular or too badly conditioned "
                                         f"(relative residual {error:.1e})")
                self._checked = True
        return du, lam

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
            sol = self._scale * sla.lu_solve(self._coarse, self._scale * rhs)
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
        against those the rounding of the product looked like an error (measured on the
        default plate: half of all solves refined twice for nothing)."""
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

    def solve_unilateral(self, r, du_fixed, h, unilateral):
        """Solve with some general rows as inequalities: a linear complementarity problem.

        Rows i in ``unilateral`` hold as C_i du >= h_i with lam_i <= 0 and
        lam_i (C_i du - h_i) = 0 (frictionless contact: h = -gap, lam compressive); the
        others as in :meth:`solve`. In multipliers this is the dual problem of FETI
        contact (Dostal):

            min 1/2 lam^T S lam - b^T lam   s.t.  G^T lam = R^T q,  lam_i <= 0 (i unilateral)

        with b = C (du_fixed + K^+ q) - h, solved exactly by the dual active-set method
        (:func:`ngfracture.linalg.qp.convex_qp`); S is positive definite on the null space of G^T
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

        Returns
        -------
        du : numpy.ndarray (ndof,)
        lam : numpy.ndarray (m,)
            Exactly 0 for the released unilateral rows.
        closed : numpy.ndarray of bool (m,)
            The rows that hold with equality, C_i du = h_i: the equalities and the unilateral
            rows that are not released. A closed row may carry no force (lam_i = 0): it
            touches, and still fixes the position of a piece that no force holds.

        Raises
        ------
        ValueError
            If the solver was built on the augmented path (no Schur complement).
        """
        from .qp import convex_qp    # only needed here

        if self.path != "schur":
            raise ValueError("solve_unilateral needs the Schur complement: build with path='schur' or dependent_rows=True")

        q, du = self._unconstrained(r, du_fixed)
        if not self.m:
            return du, np.zeros(0), np.zeros(0, dtype=bool)
        bounded = np.zeros(self.m, dtype=bool)
        bounded[unilateral] = True
        b = self.C @ du - h
        # in the equilibrated variables y = lam / d of the constructor (unit diagonal),
        # with H = S + G G^T: the same minimiser on G^T lam = R^T q, and positive definite
        d, gscale = self._scale[:self.m], self._scale[self.m:]
        Gs = d[:, None] * self._G * gscale[None, :]
        H = d[:, None] * self._S * d[None, :] + Gs @ Gs.T
        if self._coarse is None:
            H += 1e-10 * np.eye(self.m)
        e = gscale * (self._R.T @ q)
        y, alpha, _, active = convex_qp(H, d * b + Gs @ e, Gs.T, e, -np.eye(self.m)[bounded], np.zeros(bounded.sum()))
        released = np.zeros(self.m, dtype=bool)
        released[np.flatnonzero(bounded)[active]] = True
        y[released] = 0.0                        # released rows carry exactly nothing
        lam = d * y
        du -= self._correction(lam)
        du += self._R @ (gscale * alpha)
        return du, lam, ~released
