"""The factorisation carried across 3D vertex splits (linalg.bordered.BorderedFactor).

A block of tetrahedra pressed from all sides is solved and factorised (the base, with the
3D contact solves' Schur complement from K^-1 on the rows' dofs, ``schur_by_dofs``); a
crack is nucleated at an interior vertex and grown by two more vertices in a second pass.
On both split meshes the bordered solve is a direct solve of the system with the split
mesh's tangent K~ at the base state carried over, so it must equal a sparse LU of the
whole KKT system [K~ B^T; B 0] to 1e-10 (rounding), with general rows across the crack
(the jumps of the new vertices against their parents, as contact rows are) and rows on
base vertices. The second pass keeps the first one's columns Z = A^-1 B where B's are
unchanged, and E^T K~ E is the base tangent (every tetrahedron keeps its element matrix).
Along a run (the coarse confined sphere, its crack passes carried by run/solid_pass.py)
the bordered KKT solves with the contact and stick rows have backward errors of rounding
size, and the run ends with the same cracks as with every split mesh factorised afresh.
"""
import types

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ngfracture import ElasticProblem, Simulation, StepControl, StVenantKirchhoff
from ngfracture.fracture.split3d import split_by_tensor_3d
from ngfracture.geometry.solid import solid_mesh
from ngfracture.linalg import bordered
from ngfracture.linalg import factor as factor_module
from ngfracture.linalg.factor import EliminatedFactor
from ngfracture.linalg.kkt import ConstrainedSolver
from ngfracture.mechanics.tangent import base_pins
from ngfracture.scenes import sphere3d

from bordered_util import check_random_solve
from split3d_util import cube_bar
from test_kkt_paths import kkt_forward_tolerance, whole_kkt_solution

N = 4     # cubes along each side: 125 vertices, 375 dofs


@pytest.fixture(autouse=True)
def small_meshes_carry_their_factorisation(monkeypatch):
    """Below bordered.MIN_BASE_DOFS a split mesh is factorised afresh: lowered here, and the
    sparse Schur path (the 3D contact solves') forced on this small mesh."""
    monkeypatch.setattr(bordered, "MIN_BASE_DOFS", 0)
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0)
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_ROWS", 0)


def pressed(arrays, u=None):
    """The block pressed by 1 % on every side (no free rigid mode), at displacement ``u``."""
    prob = ElasticProblem(solid_mesh(arrays), StVenantKirchhoff(1.0, 0.3))
    for c, side in enumerate("xyz"):
        prob.add_dirichlet(f"{side}min", 0.0, component=side)
        prob.add_dirichlet(f"{side}max", -0.01 * N, component=side)
    if u is not None:
        prob.u.vec.FV().NumPy()[:] = u
    return prob


def opening(arrays, vertices):
    """An overstrain tensor field that splits ``vertices`` (points) across the plane x = N/2."""
    t = np.zeros((len(arrays.points), 6))
    for rank, point in enumerate(vertices):
        v = int(np.argmin(np.linalg.norm(arrays.points - point, axis=1)))
        t[v, 0] = 3.0 - 0.1 * rank
    return t


def lifted(u, parent):
    """A vertex field (component-major, 3 components) copied through the parent map."""
    return u.reshape(3, -1)[:, parent].reshape(-1)


def split(arrays, vertices, u):
    res = split_by_tensor_3d(arrays, opening(arrays, vertices), 1.0, mode="all")
    assert res.nsplit >= 1
    return res, pressed(res.arrays, lifted(u, res.parent))


def jump_rows(prob, parent, nvb, seed):
    """General rows: each new vertex's jump against its parent along a random direction (as
    a contact row across the crack) and a few random rows on base vertices."""
    nv = prob.fes.ndof // 3
    rng = np.random.default_rng(seed)
    rows, cols, vals = [], [], []
    new = np.arange(nvb, nv)
    for i, v in enumerate(new):
        n = rng.standard_normal(3)
        for c in range(3):
            rows += [i, i]
            cols += [c * nv + v, c * nv + parent[v]]
            vals += [n[c], -n[c]]
    for i in range(len(new), len(new) + 4):
        v = rng.choice(nvb, 3, replace=False)
        for c in range(3):
            rows += [i] * 3
            cols += list(c * nv + v)
            vals += list(rng.standard_normal(3))
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(new) + 4, 3 * nv))


def check_against_whole_kkt(prob, factor, C, seed):
    """The bordered factor's plain solve against spsolve of K~, and its KKT solve (sparse
    Schur path) against the whole system, both to 1e-10."""
    rows0 = prob.assemble_constraints()
    rows = types.SimpleNamespace(fixed_dofs=rows0.fixed_dofs, C=C)
    rng = np.random.default_rng(seed)
    ndof = prob.fes.ndof
    b = np.where(factor.factor_free, rng.standard_normal(ndof), 0.0)
    x = factor.solve(b)
    F = factor.factor_free
    x_ref = spla.spsolve(factor.K[F][:, F].tocsc(), b[F])
    assert np.linalg.norm(x[F] - x_ref) <= 1e-10 * np.linalg.norm(x_ref)
    assert np.all(x[~F] == 0.0)
    kkt = ConstrainedSolver(None, rows.fixed_dofs, C, pins=factor.pins, factor=factor, path="schur")
    assert kkt._Z is None                                   # S from the base's K^-1 on the rows' dofs
    r = np.where(factor.free, rng.standard_normal(ndof), 0.0)
    du_fixed = np.zeros(ndof)
    du_fixed[rows.fixed_dofs] = 1e-3 * rng.standard_normal(rows.fixed_dofs.size)
    h = 1e-3 * rng.standard_normal(C.shape[0])
    du, lam = kkt.solve(r, du_fixed, h)
    du_ref, lam_ref = whole_kkt_solution(factor.K, rows, r, du_fixed, h)
    assert np.linalg.norm(du - du_ref) <= 1e-10 * np.linalg.norm(du_ref)
    assert np.linalg.norm(lam - lam_ref) <= 1e-10 * np.linalg.norm(lam_ref)


@pytest.fixture(scope="module")
def chain():
    """The base (solved, factorised at its state), a first split (one interior vertex) and a
    second (two neighbours on the same plane)."""
    arrays = cube_bar(N, N, N)
    base = pressed(arrays)
    assert base.solve(method="full").converged
    rows = base.assemble_constraints()
    support = base.support(rows)
    assert len(support.pins) == 0
    state = base.u.vec.FV().NumPy().copy()
    factor = EliminatedFactor(base.tangent(), rows.fixed_dofs, support.pins, schur_by_dofs=True)
    factor.solve(np.ones(base.fes.ndof))                   # factorised and checked, as after a solve
    mid = N / 2
    first, prob1 = split(arrays, [(mid, mid, mid)], state)
    second, prob2 = split(first.arrays, [(mid, mid - 1, mid), (mid, mid + 1, mid)], prob1.u.vec.FV().NumPy())
    return types.SimpleNamespace(base=base, factor=factor, state=state, first=first, prob1=prob1,
                                 second=second, prob2=prob2)


def bordered_factor(lineage, prob):
    rows = prob.assemble_constraints()
    support = base_pins(prob.support(rows), lineage.base, prob.fes.ndof, prob.dim)
    factor = bordered.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins)
    assert factor is not None
    return factor


def test_bordered_solves_of_two_3d_splits_equal_whole_kkt_solves(chain):
    nv0 = chain.base.fes.ndof // 3
    lineage1 = bordered.lineage(chain.factor, chain.state, chain.first.parent)
    f1 = bordered_factor(lineage1, chain.prob1)
    assert len(f1._border) == 3 * chain.first.nsplit
    check_against_whole_kkt(chain.prob1, f1, jump_rows(chain.prob1, chain.first.parent, nv0, 1), seed=2)
    lineage2 = bordered.lineage(f1, None, chain.second.parent)
    assert lineage2.base is chain.factor and np.array_equal(lineage2.parent[:nv0], np.arange(nv0))
    f2 = bordered_factor(lineage2, chain.prob2)
    assert len(f2._border) == 3 * (chain.first.nsplit + chain.second.nsplit)
    # the first pass's columns carried over where its column of B is unchanged (not next to the new vertices)
    assert f2.z_columns.buffer is f1.z_columns.buffer
    assert len(f2.z_columns.unsolved) < len(f2._border)
    check_against_whole_kkt(chain.prob2, f2, jump_rows(chain.prob2, lineage2.parent, nv0, 3), seed=4)


def test_tangent_of_the_3d_split_mesh_at_the_carried_state_is_the_base_tangent(chain):
    """E^T K~ E equals the base tangent to the rounding of the sums."""
    lineage = bordered.lineage(chain.factor, chain.state, chain.first.parent)
    factor = bordered_factor(lineage, chain.prob1)
    base = chain.factor
    A = base.K[base.factor_free][:, base.factor_free]
    KF = factor.K[factor._dofs][:, factor._dofs]
    assert abs(factor._Et @ KF @ factor._Et.T - A).max() <= 1e-14 * abs(A).max()


COARSE_SPHERE = dict(maxh=0.4, fine=0.15)   # tests/test_sphere3d.py's coarse mesh: 1.1k dofs


@pytest.mark.parametrize("against_fresh", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_every_tenth_bordered_solve_of_a_coarse_sphere_run_solves_its_kkt_system(against_fresh, monkeypatch):
    """The confined sphere on the coarse mesh for three steps (14 split vertices; its
    crack passes carried by bordered factors, run/solid_pass.py, with the contact rows
    across the cracks and the stick rows of the interface): every tenth constrained solver
    built on a bordered factor solves a random system [K~ B^T; B 0] with a backward error
    of rounding size (1e-12 of |K~| |du| + |B^T| |lam| + |r|, row by row 1e-12 of
    |B| |du| + |h|). With ``against_fresh`` (slow: a dense condition number) the 11th (a
    chain of several passes) also equals the solve of a fresh factorisation of K~ with the
    same rows to the forward error two backward-stable solves may differ by
    (test_kkt_paths.kkt_forward_tolerance)."""
    checked, compared = [], []
    original = ConstrainedSolver.__init__

    def checking_init(self, K, fixed_dofs, C, *args, **kwargs):
        original(self, K, fixed_dofs, C, *args, **kwargs)
        if not isinstance(self.factor, bordered.BorderedFactor):
            return
        checked.append(len(self.factor._border))
        if (len(checked) - 1) % 10 or getattr(self, "_coarse", None) is None:
            return
        assert self._Z is None                               # the base's K^-1 on the rows' dofs
        r, du_fixed, h, du, lam = check_random_solve(self, fixed_dofs, len(checked))
        if not against_fresh or len(checked) != 11:
            return
        compared.append(len(self.factor._border))
        K, fixed = self.factor.K, np.asarray(fixed_dofs)
        fresh = EliminatedFactor(K, fixed, self.factor.pins, schur_by_dofs=True)
        other = ConstrainedSolver(None, fixed, self.C, modes=kwargs.get("modes"), pins=self.factor.pins,
                                  factor=fresh, path="schur")
        du2, lam2 = other.solve(r, du_fixed, h)
        tol = kkt_forward_tolerance(K, types.SimpleNamespace(fixed_dofs=fixed, C=self.C))
        x, x_ref = np.concatenate([du, lam]), np.concatenate([du2, lam2])
        assert np.linalg.norm(x - x_ref) <= tol * np.linalg.norm(x_ref)

    monkeypatch.setattr(ConstrainedSolver, "__init__", checking_init)
    result = Simulation(sphere3d(**COARSE_SPHERE), StepControl(max_steps=3), pictures="none").run()
    assert result.ok and result.summary["n_steps"] == 3 and result.summary["n_split_vertices"] > 0
    assert len(checked) >= 11 and max(checked) >= 3 * 10        # chains of splits, not single ones
    assert compared[0] > 3 if against_fresh else not compared


@pytest.mark.slow
def test_a_coarse_sphere_run_through_bordered_factors_ends_as_with_fresh_factorisations(monkeypatch):
    """Six steps of the coarse confined sphere (64 split vertices), once with every split
    mesh factorised afresh: the same split vertices step by step, the same fragments and
    crack area, the volume of both the initial one to the last bit, and final
    displacements equal to the tolerance of the Newton solves (1e-9 of the largest)."""
    runs = {}
    for carried in (True, False):
        if not carried:
            monkeypatch.setattr(bordered.BorderedFactor, "build", classmethod(lambda cls, *args: None))
        runs[carried] = Simulation(sphere3d(**COARSE_SPHERE), StepControl(max_steps=6), pictures="none").run()
    a, b = runs[True].summary, runs[False].summary
    assert runs[True].ok and runs[False].ok
    assert [h["split_vertices"] for h in a["history"]] == [h["split_vertices"] for h in b["history"]]
    assert a["n_split_vertices"] > 30 and a["n_fragments"] == b["n_fragments"]
    assert a["volume_final"] == a["volume_initial"] and b["volume_final"] == b["volume_initial"]
    assert sum(v["factorisations"] for v in a["timings"]["linear_solver"].values()) < \
        sum(v["factorisations"] for v in b["timings"]["linear_solver"].values())
    assert abs(a["crack_area"] - b["crack_area"]) <= 1e-12 * b["crack_area"]
    ua, ub = runs[True].problem.u.vec.FV().NumPy(), runs[False].problem.u.vec.FV().NumPy()
    assert np.max(np.abs(ua - ub)) <= 1e-9 * np.max(np.abs(ub))
