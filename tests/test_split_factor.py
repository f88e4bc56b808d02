"""The factorisation carried across vertex splits (linalg.bordered.BorderedFactor, imported here as split_factor).

After a crack pass the KKT system of the split mesh is solved through the factorisation of
the mesh before the pass, bordered by the new vertices' dofs. With the split mesh's
tangent K~ taken at the base state carried over, the bordered solve is a direct solve of
that system: it must equal a sparse LU of the whole KKT system

    [ K~  B^T ] [du ]   [r]
    [ B   0   ] [lam] = [h]      B = [unit rows of the fixed dofs; C]

to 1e-10 on a cracked configuration in contact (rows across the crack faces), solve its
systems to rounding along a whole simulation (pins, rows holding a free mode, chains of
splits whose columns Z are carried over), and a run through it must end with the same
cracks as a run that factorises every split mesh afresh.
"""
import numpy as np
import pytest

import ngfracture as nf
from ngfracture.linalg import factor as factor_module
from ngfracture import _ngfracture, scenes
from ngfracture.linalg import bordered as split_factor
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture import split_by_tensor
from ngfracture.linalg.factor import EliminatedFactor
from ngfracture.linalg.kkt import ConstrainedSolver
from ngfracture import Simulation
from ngfracture.mechanics.tangent import base_pins

from bordered_util import check_random_solve
from test_contact_fractured import crack_bands, plate_mesh
from test_kkt_paths import random_kkt_load, whole_kkt_solution

H = 0.1


@pytest.fixture(autouse=True)
def small_meshes_carry_their_factorisation(monkeypatch):
    """The meshes here are small: below split_factor.MIN_BASE_DOFS a split mesh is
    factorised afresh, so the threshold is lowered to test the bordered path on them."""
    monkeypatch.setattr(split_factor, "MIN_BASE_DOFS", 0)


def pressed(mesh):
    """Pressed from all sides: the crack faces touch (contact rows), no free rigid mode."""
    prob = nf.ElasticProblem(mesh, nf.StVenantKirchhoff(1.0, 0.3, plane="stress"))
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", -1e-3, component="x")
    prob.add_dirichlet("bottom", 0.0, component="y")
    prob.add_dirichlet("top", -1e-3, component="y")
    return prob


def branch(mesh, x=0.5, top=0.8):
    """A vertical crack branch from the horizontal crack's upper face up to y = top."""
    pts = mesh.ngmesh.Coordinates()[:, :2]
    t = np.zeros((mesh.nv, 3))
    near = (np.abs(pts[:, 0] - x) < 0.45 * H) & (pts[:, 1] > 0.5 - 1e-9) & (pts[:, 1] < top)
    t[near, 0] = 2.0 - np.abs(pts[near, 0] - x) / (0.45 * H)
    return split_by_tensor(mesh, t, 1.0)


@pytest.fixture(scope="module")
def split_in_contact():
    """A horizontal crack pressed shut (the base, factorised at its contact state), then a
    crack branch split from its upper face (no new piece): the split mesh, with its contact
    rows, and the lineage."""
    base_mesh = crack_bands(plate_mesh(H), [(1, 0.5)], 0.6 * H).mesh
    base = pressed(base_mesh)
    assert ContactSolver(base, tol=0.1 * H).solve().converged
    rows0 = base.assemble_constraints()
    support0 = base.support(rows0)
    factor = EliminatedFactor(base.tangent(), rows0.fixed_dofs, support0.pins)
    factor.solve(np.ones(base.fes.ndof))          # factorised and checked, as after a solve
    state = base.u.vec.FV().NumPy().copy()
    res = branch(base_mesh)
    assert res.nsplit == 5 and res.nfragments == 1
    prob = pressed(res.mesh)
    prob.u.vec.FV().NumPy()[:] = state.reshape(2, -1)[:, res.parent].reshape(-1)
    result = ContactSolver(prob, tol=0.1 * H).solve()
    assert result.converged and len(result.multipliers) > 0 and np.any(result.multipliers < 0)
    return prob, split_factor.lineage(factor, state, res.parent)


@pytest.mark.parametrize("sparse_schur, inverse", [(False, "superlu"), (True, "superlu"), (False, "supernodal"),
                                                  (False, "sparsecholesky")])
def test_bordered_solve_equals_whole_kkt_solve_in_contact(split_in_contact, sparse_schur, inverse, monkeypatch):
    """Both Schur paths on a SuperLU base: the kept columns, and the sparse Schur complement
    of the base plus the border's rank-m term (forced on this small mesh); SuperLU's factors
    solved by the supernodal L D L^T solver (the plates' path, forced here); and a base
    factorised by NGSolve's sparse Cholesky (the large meshes' solver)."""
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_DOFS", 0 if sparse_schur else 10 ** 9)
    monkeypatch.setattr(factor_module, "SPARSE_SCHUR_MIN_ROWS", 0)
    prob, lineage = split_in_contact
    if inverse != "superlu":
        monkeypatch.setattr(factor_module, "SUPERNODAL_MIN_DOFS", 0)
        base = lineage.base
        other = EliminatedFactor(base.K, base.fixed_dofs, base.pins,
                                 inverse="superlu" if inverse == "supernodal" else inverse)
        other.solve(np.ones(base.ndof))
        assert (inverse == "supernodal") == isinstance(other._ldl, _ngfracture.SupernodalLDL)
        lineage = split_factor.Lineage(other, lineage.state, lineage.parent)
    else:
        assert lineage.base._ldl is False                 # below SUPERNODAL_MIN_DOFS: SuperLU's solve
    rows = prob.assemble_constraints()
    support = base_pins(prob.support(rows), lineage.base, prob.fes.ndof, prob.dim)
    factor = split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins)
    assert factor is not None and len(factor._border) > 0
    assert rows.C.shape[0] > 0
    kkt = ConstrainedSolver(None, rows.fixed_dofs, rows.C, modes=support.modes, pins=support.pins,
                            factor=factor, path="schur")
    assert (kkt._Z is None) == sparse_schur
    r, du_fixed, h = random_kkt_load(prob.fes.ndof, rows, seed=3)
    du, lam = kkt.solve(r, du_fixed, h)
    du_ref, lam_ref = whole_kkt_solution(factor.K, rows, r, du_fixed, h)
    assert np.linalg.norm(du - du_ref) <= 1e-10 * np.linalg.norm(du_ref)
    assert np.linalg.norm(lam - lam_ref) <= 1e-10 * np.linalg.norm(lam_ref)


def test_tangent_of_the_split_mesh_at_the_carried_state_is_the_base_tangent(split_in_contact):
    """E^T K~ E equals the base tangent (each triangle keeps its element matrix) to the
    rounding of the sums."""
    prob, lineage = split_in_contact
    rows = prob.assemble_constraints()
    support = base_pins(prob.support(rows), lineage.base, prob.fes.ndof, prob.dim)
    factor = split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins)
    base = lineage.base
    A = base.K[base.factor_free][:, base.factor_free]
    KF = factor.K[factor._dofs][:, factor._dofs]
    EtKE = factor._Et @ KF @ factor._Et.T
    assert abs(EtKE - A).max() <= 1e-14 * abs(A).max()


def test_small_mesh_border_beyond_capacity_or_new_fragment_takes_a_fresh_factorisation(split_in_contact,
                                                                                      monkeypatch):
    prob, lineage = split_in_contact
    rows = prob.assemble_constraints()
    support = base_pins(prob.support(rows), lineage.base, prob.fes.ndof, prob.dim)
    assert split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins) is not None
    monkeypatch.setattr(split_factor, "MIN_BASE_DOFS", np.count_nonzero(lineage.base.factor_free) + 1)
    assert split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins) is None
    monkeypatch.setattr(split_factor, "MIN_BASE_DOFS", 0)
    monkeypatch.setattr(split_factor, "border_capacity", lambda n: 2)
    assert split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins) is None
    monkeypatch.setattr(split_factor, "border_capacity", lambda n: 240)
    other_pins = np.setdiff1d(np.arange(prob.fes.ndof), rows.fixed_dofs)[:1]   # a pin the base does not have
    assert split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, other_pins) is None


def test_every_bordered_solve_of_a_plate_run_solves_its_kkt_system(monkeypatch):
    """The default plate (critical distance) on a coarser mesh: every tenth constrained
    solver built on a bordered factor during the run (a pin and the row holding the plate's
    free mode, later contact rows; columns carried along chains of splits) solves a random
    system [K~ B^T; B 0] with a backward error of rounding size (1e-12 of |K~| |du| +
    |B^T| |lam| + |r|, row by row 1e-12 of |B| |du| + |h|). The forward error is no test
    here: the mode the row holds meets only the geometric stiffness (K R about 1e-5 of K),
    and random loads along it are ill-conditioned (1e-7 between two exact solvers)."""
    checked = []
    original = ConstrainedSolver.__init__

    def checking_init(self, K, fixed_dofs, C, *args, **kwargs):
        original(self, K, fixed_dofs, C, *args, **kwargs)
        if not isinstance(self.factor, split_factor.BorderedFactor):
            return
        checked.append(len(self.factor._border))
        if len(checked) % 10 or self.path != "schur" or getattr(self, "_coarse", None) is None:
            return
        check_random_solve(self, fixed_dofs, len(checked))

    monkeypatch.setattr(ConstrainedSolver, "__init__", checking_init)
    result = Simulation(scenes.plate(maxh=0.05)).run()
    assert result.ok and result.summary["reason"] == "broken"
    assert len(checked) >= 20 and max(checked) >= 20      # chains of splits, not single ones


def test_a_run_through_bordered_factors_ends_as_with_fresh_factorisations(monkeypatch):
    """The default plate on a coarser mesh, once with every split mesh factorised afresh:
    the same steps, split vertices and fragments, and crack length and final displacement
    equal to the tolerance of the Newton solves (1e-9 relative)."""
    runs = {}
    for carried in (True, False):
        if not carried:
            monkeypatch.setattr(split_factor.BorderedFactor, "build", classmethod(lambda cls, *args: None))
        runs[carried] = Simulation(scenes.plate(maxh=0.05)).run()
    a, b = runs[True], runs[False]
    assert a.ok and b.ok and a.summary["reason"] == b.summary["reason"] == "broken"
    for key in ("n_steps", "n_split_vertices", "n_fragments"):
        assert a.summary[key] == b.summary[key], key
    assert [h["split_vertices"] for h in a.summary["history"]] == [h["split_vertices"] for h in b.summary["history"]]
    assert abs(a.summary["crack_length"] - b.summary["crack_length"]) <= 1e-9 * a.summary["crack_length"]
    assert np.linalg.norm(a.state.u - b.state.u) <= 1e-9 * np.linalg.norm(a.state.u)


def test_a_chain_solves_each_column_of_z_once_and_every_column_is_that_of_its_border(monkeypatch):
    """Along the default plate on a coarser mesh: within a chain of splits every border dof's
    column of Z = A^-1 B is solved once (a neighbour's split leaves its column of B as it
    was, bit for bit, so the carried column is kept), and in every bordered factor, once it
    has solved, A Z = B holds to rounding (1e-12 of |A| |Z|) for all its columns, the carried
    ones included."""
    solved = {}          # chain -> border dofs whose column was solved, in order
    factors = []
    original = split_factor.BorderedFactor._base_solve

    def recording(self, rhs):
        unsolved = [self.z_columns.keys[i] for i in self.z_columns.unsolved] if self._Sd is None else []
        x = original(self, rhs)
        solved.setdefault(id(self.z_columns.chain), []).extend(unsolved)
        if unsolved:
            factors.append(self)
        return x

    monkeypatch.setattr(split_factor.BorderedFactor, "_base_solve", recording)
    original_init = ConstrainedSolver.__init__
    checked = []

    def checking_init(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        factor = self.factor
        if not isinstance(factor, split_factor.BorderedFactor) or factor._Sd is None or len(factors) % 3:
            return
        base = factor.base
        A = base.K[base.factor_free][:, base.factor_free]
        Z, B = factor._Z, factor._Bt.T.toarray()
        assert np.linalg.norm(A @ Z - B) <= 1e-12 * np.linalg.norm(abs(A) @ np.abs(Z))
        checked.append(Z.shape[1])

    monkeypatch.setattr(ConstrainedSolver, "__init__", checking_init)
    result = Simulation(scenes.plate(maxh=0.05)).run()
    assert result.ok and result.summary["reason"] == "broken"
    assert len(checked) >= 5 and max(checked) >= 20
    for keys in solved.values():
        assert len(keys) == len(set(keys))
    assert max(len(keys) for keys in solved.values()) >= 20


def test_a_singular_border_gives_way_to_a_fresh_factorisation_and_is_recorded(monkeypatch):
    """Every bordered factor made to report a singular border at its first solve: each
    relaxation is solved again with the split mesh's own factorisation, the run ends as a
    run with fresh factorisations (the same split vertices, crack length to 1e-9), and the
    summary records the fallback."""
    def singular(self, rhs):
        raise factor_module.SingularSystem("the border of 2 split dofs is singular (forced)")

    runs = {}
    monkeypatch.setattr(split_factor.BorderedFactor, "_base_solve", singular)
    runs["fallback"] = Simulation(scenes.plate(maxh=0.05)).run()
    monkeypatch.setattr(split_factor.BorderedFactor, "build", classmethod(lambda cls, *args: None))
    runs["fresh"] = Simulation(scenes.plate(maxh=0.05)).run()
    a, b = runs["fallback"], runs["fresh"]
    assert a.ok and a.summary["reason"] == b.summary["reason"] == "broken"
    assert a.summary["n_split_vertices"] == b.summary["n_split_vertices"]
    assert abs(a.summary["crack_length"] - b.summary["crack_length"]) <= 1e-9 * b.summary["crack_length"]
    assert any("carried across a crack pass was singular" in n["note"] for n in a.summary["notes"])
    assert not any("carried across" in n["note"] for n in b.summary["notes"])


def test_two_factors_built_from_one_lineage_do_not_share_columns(split_in_contact):
    """A factor built twice from one lineage (a contact solve's second start) does not
    reuse the columns the first one may have overwritten: it starts a buffer of its own,
    and both solve their system (relative residual of K~ x = b on the factorised dofs to
    1e-10) in either order."""
    prob, lineage = split_in_contact
    rows = prob.assemble_constraints()
    support = base_pins(prob.support(rows), lineage.base, prob.fes.ndof, prob.dim)
    first = split_factor.BorderedFactor.build(lineage, prob, rows.fixed_dofs, support.pins)
    first.solve(np.ones(prob.fes.ndof))
    same_mesh = split_factor.lineage(first, None, np.arange(prob.mesh.nv))
    a = split_factor.BorderedFactor.build(same_mesh, prob, rows.fixed_dofs, support.pins)
    b = split_factor.BorderedFactor.build(same_mesh, prob, rows.fixed_dofs, support.pins)
    assert a.z_columns.buffer is first.z_columns.buffer and b.z_columns.buffer is not a.z_columns.buffer
    rng = np.random.default_rng(5)
    for factor in (b, a, b):
        rhs = rng.standard_normal(prob.fes.ndof)
        x = factor.solve(rhs)
        F = factor.factor_free
        assert np.linalg.norm((factor.K @ x - rhs)[F]) <= 1e-10 * np.linalg.norm(rhs[F])
