"""Schur columns kept for the life of a factorisation (linalg.factor), the solver of a 3D
tangent made for one linear system (linalg.iterative.choose_inverse), and the thread count
that linalg.sparse.reproducible_threads restores.

Exact checks: a kept column must be bit for bit the column a fresh factorisation of the
same matrix solves (NGSolve's sparse Cholesky solves a block column by column), and a
factorisation must solve no column it has met before.
"""
import ngsolve as ng
import numpy as np
import scipy.sparse as sp

import ngfracture as nf
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.linalg import kept
from ngfracture.linalg.factor import EliminatedFactor
from ngfracture.linalg.iterative import SUPERLU_ROWS_MAX_DOFS, SUPERLU_ROWS_PER_DOF, choose_inverse
from ngfracture.linalg.sparse import forget_thread_count, reproducible_threads
from ngfracture.mechanics.materials import StVenantKirchhoff


def _clamped_box():
    """A 3D bar clamped at x = 0: (K, fixed dofs, ndof)."""
    arrays = box_mesh(np.linspace(0, 4, 13), np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    prob = nf.ElasticProblem(solid_mesh(arrays), StVenantKirchhoff(5e9, 0.18))
    prob.add_dirichlet("xmin", 0.0)
    rows = prob.assemble_constraints()
    return prob.tangent(), rows.fixed_dofs, prob.fes.ndof


def _rows(ndof, seed, m=6):
    """m rows tying two dofs each (like stick rows: a few nonzeros, distinct values)."""
    rng = np.random.default_rng(seed)
    cols = rng.choice(np.arange(ndof // 2, ndof), size=(m, 2), replace=False)
    return sp.csr_matrix((rng.uniform(0.5, 1.5, 2 * m) * np.tile([1.0, -1.0], m),
                          (np.repeat(np.arange(m), 2), cols.ravel())), shape=(m, ndof))


class _SolveCount:
    """Counts the right-hand sides EliminatedFactor.solve is given (monkeypatched)."""

    def __init__(self, monkeypatch):
        self.columns = 0
        solve = EliminatedFactor.solve

        def counted(factor, B):
            self.columns += 1 if B.ndim == 1 else B.shape[1]
            return solve(factor, B)

        monkeypatch.setattr(EliminatedFactor, "solve", counted)


def test_cholesky_columns_are_kept_over_calls_and_equal_fresh_ones(monkeypatch):
    K, fixed, ndof = _clamped_box()
    A, B = _rows(ndof, 1), _rows(ndof, 2)
    fresh = EliminatedFactor(K, fixed, inverse="sparsecholesky").columns(A)
    count = _SolveCount(monkeypatch)
    factor = EliminatedFactor(K, fixed, inverse="sparsecholesky")
    assert factor.columns_independent
    first = factor.columns(A)
    factor.columns(B)                       # other rows in between
    again = factor.columns(sp.vstack([B[:2], A]).tocsr())
    assert count.columns == 12              # A and B once each: 6 + 6
    assert np.array_equal(first, fresh) and np.array_equal(again[:, 2:], fresh)
    # carried to another load step: the columns stay, still those of a fresh factor
    carried = factor.without_caches()
    assert np.array_equal(carried.columns(A), fresh) and count.columns == 12


def test_superlu_keeps_only_the_last_rows(monkeypatch):
    K, fixed, ndof = _clamped_box()
    A, B = _rows(ndof, 1), _rows(ndof, 2)
    count = _SolveCount(monkeypatch)
    factor = EliminatedFactor(K, fixed, inverse="superlu")
    assert not factor.columns_independent
    factor.columns(A)
    factor.columns(A)
    assert count.columns == 6
    factor.columns(B)
    factor.columns(A)                       # dropped by the call with B: solved again
    assert count.columns == 18
    factor.without_caches().columns(A)      # a carried SuperLU factor starts without columns
    assert count.columns == 24


def test_kept_columns_are_bounded(monkeypatch):
    K, fixed, ndof = _clamped_box()
    monkeypatch.setattr(kept, "KEPT_COLUMNS_BYTES", 8 * ndof * 8)    # room for 8 columns
    count = _SolveCount(monkeypatch)
    factor = EliminatedFactor(K, fixed, inverse="sparsecholesky")
    A, B = _rows(ndof, 1), _rows(ndof, 2)
    factor.columns(A)
    factor.columns(B)                       # 12 met, 8 kept: the last 2 of A and all of B
    assert count.columns == 12
    factor.columns(A[4:])
    factor.columns(B)
    assert count.columns == 12
    factor.columns(A[:4])
    assert count.columns == 16


def test_a_3d_tangent_with_many_rows_takes_superlu():
    n = SUPERLU_ROWS_MAX_DOFS
    rows = int(np.ceil(SUPERLU_ROWS_PER_DOF * n))
    inverse, record = choose_inverse("auto", 3, n, budget=1e12, rows=rows)
    assert inverse == "superlu" and record == {"solver": "superlu", "reason": "auto, many rows", "dofs": n}
    assert choose_inverse("auto", 3, n, budget=1e12, rows=rows - 1)[0] == "sparsecholesky"
    assert choose_inverse("auto", 3, 100, budget=1e12, rows=1)[0] == "superlu"
    assert choose_inverse("auto", 3, n + 1, budget=1e12, rows=10 ** 4)[0] == "sparsecholesky"
    assert choose_inverse("auto", 3, n, budget=1e12)[0] == "sparsecholesky"        # no general rows
    assert choose_inverse("auto", 2, n, rows=10 ** 4)[0] == "auto"                  # 2D: its own rule
    assert choose_inverse("sparsecholesky", 3, n, rows=10 ** 4)[0] == "sparsecholesky"


def test_reproducible_threads_restores_the_count():
    before = ng.GetNumThreads()
    with ng.TaskManager():
        outer = ng.GetNumThreads()
    try:
        ng.SetNumThreads(3)
        forget_thread_count()
        for _ in range(2):                  # the second call uses the count kept by the first
            with reproducible_threads():
                with ng.TaskManager():
                    assert ng.GetNumThreads() == 1
            with ng.TaskManager():
                assert ng.GetNumThreads() == 3
    finally:
        ng.SetNumThreads(outer)
        forget_thread_count()
    assert ng.GetNumThreads() == before
