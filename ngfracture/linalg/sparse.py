"""Sparse matrices between NGSolve and scipy, and the thread settings of the solves.

The solves take NGSolve's matrices into scipy (:func:`to_scipy`) and scipy's into NGSolve
for its direct solvers (:func:`to_ngsolve`). Their dense algebra runs on one BLAS thread
(:func:`single_threaded_blas`) and NGSolve's factorisations on one thread
(:func:`reproducible_threads`), for speed on small matrices and for results that repeat to
the last bit; the measurements are in docs/solvers.md ("Threads").
"""
import contextlib

import numpy as np
import ngsolve as ng
import scipy.sparse as sp
from pyngcore import Array_D_S, Array_I_S


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


def to_ngsolve(mat, pattern=None):
    """A scipy sparse matrix as an NGSolve sparse matrix (for NGSolve's direct solvers).

    Parameters
    ----------
    mat : scipy.sparse matrix
        Real, square or not.
    pattern : ngsolve.la.SparseMatrixd, optional
        An NGSolve matrix that ``mat`` was copied from (:func:`to_scipy`): when its
        sparsity pattern is still ``mat``'s, the new matrix is made from that pattern and
        gets ``mat``'s values (the same matrix as without it, made 4 times faster).

    Returns
    -------
    ngsolve.la.SparseMatrixd
        The same entries (duplicates summed).
    """
    if isinstance(pattern, ng.la.SparseMatrixd) and sp.isspmatrix_csr(mat):
        _, cols, rows = pattern.CSR()
        if np.array_equal(np.asarray(rows), mat.indptr) and np.array_equal(np.asarray(cols), mat.indices):
            out = pattern.CreateMatrix()
            values = out.AsVector().FV().NumPy()
            if values.shape == mat.data.shape:
                values[:] = mat.data
                return out
    coo = sp.coo_matrix(mat)
    return ng.la.SparseMatrixd.CreateFromCOO(_ngcore_array(Array_I_S, coo.row), _ngcore_array(Array_I_S, coo.col),
                                             _ngcore_array(Array_D_S, coo.data), coo.shape[0], coo.shape[1])


def _ngcore_array(kind, values):
    """``values`` as the pyngcore array ``kind`` that CreateFromCOO takes, filled by one copy
    into its buffer: given numpy arrays, the binding converts them element by element, which
    took longer than the factorisation of the matrix (docs/solvers.md, "Matrices into
    NGSolve"). The same entries either way, so the same matrix."""
    arr = kind(len(values))
    view = np.asarray(arr)
    if view.shape != values.shape:     # no buffer view of the array: the binding converts
        return values
    view[:] = values
    return arr


_blas = None     # threadpoolctl's view of the loaded BLAS libraries, made at first use


@contextlib.contextmanager
def single_threaded_blas():
    """One BLAS thread for the small dense algebra of the solves (usable as a decorator).

    Schur complements, the QP of the contact solve, the Gram and rank tests are dense
    matrices of a few hundred rows, where OpenBLAS' threads only wait for each other, and
    on a busy machine much longer (docs/solvers.md, "Threads"). One thread also makes the
    dense results independent of the core count. The previous limits are restored on
    leaving (threadpoolctl, which finds numpy's and scipy's BLAS).

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


#: the thread count a TaskManager starts with, read at the first reproducible_threads
_ngsolve_threads = None


def forget_thread_count():
    """Let the next :func:`reproducible_threads` read the thread count again (after a
    ``ngsolve.SetNumThreads`` outside a TaskManager)."""
    global _ngsolve_threads
    _ngsolve_threads = None


@contextlib.contextmanager
def reproducible_threads():
    """One NGSolve thread while factorising, for results that repeat to the last bit.

    NGSolve's sparse Cholesky factorises in parallel with a summation order that varies
    between runs, so that two factorisations of the same matrix can give solutions that
    differ in the last bit, enough to change a crack pattern or a resumed run; with one
    thread it is bitwise reproducible, and no slower on two cores (docs/solvers.md,
    "Threads"). Must be entered outside a TaskManager context (its thread count is fixed
    when it starts).

    Outside a TaskManager ``ngsolve.GetNumThreads()`` is 1 whatever ``SetNumThreads`` set;
    the count a TaskManager starts with, the one to restore, is read inside one at the first
    call and kept for the process: starting a TaskManager costs about 5 ms, 3 s over the
    400 factorisations of a sphere run (docs/solvers.md, "Threads"). A program that
    changes the count with ``ngsolve.SetNumThreads`` after that first call must call
    :func:`forget_thread_count` for it to be restored.

    Yields
    ------
    None
        The body of the ``with`` block runs with ``ngsolve.SetNumThreads(1)``; the previous
        thread count is restored on leaving it, also when it raises.
    """
    global _ngsolve_threads
    before = ng.GetNumThreads()
    if before == 1:
        if _ngsolve_threads is None:
            with ng.TaskManager():
                _ngsolve_threads = ng.GetNumThreads()
        before = _ngsolve_threads
    ng.SetNumThreads(1)
    try:
        yield
    finally:
        ng.SetNumThreads(before)
