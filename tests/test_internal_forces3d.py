"""The C++ internal-force and tangent kernels on P1 tetrahedra against NGSolve.

ElasticProblem takes the residual and the tangent of P1 tetrahedra from
``_ngfracture.InternalForces`` and ``_ngfracture.TangentStiffness`` (the kernels of
tests/test_internal_forces.py, dispatched on the elements' width) instead of NGSolve's
Apply and AssembleLinearization of the compiled energy. Both come from the same energy:
they must agree to rounding for every law, several regions and external loads, with
NGSolve's sparsity pattern, and the tangent must be the derivative of the forces.
"""
import functools

import numpy as np
import ngsolve as ng
import pytest
from netgen.occ import Box, Glue, OCCGeometry, Pnt, Z

import ngfracture as nf
from ngfracture import _ngfracture as _C
from ngfracture.linalg.sparse import to_scipy
from ngfracture.mechanics.problem import ElasticProblem

LAWS = [nf.LinearElastic, nf.StVenantKirchhoff, nf.NeoHookean]


@functools.lru_cache(maxsize=None)
def block(maxh=0.35):
    """A 1 x 1 x 1 cube (region "a") glued to a 1 x 1 x 0.5 slab on top (region "b")."""
    lower = Box(Pnt(0, 0, 0), Pnt(1, 1, 1))
    lower.mat("a")
    upper = Box(Pnt(0, 0, 1), Pnt(1, 1, 1.5))
    upper.mat("b")
    upper.faces.Max(Z).name = "top"
    return ng.Mesh(OCCGeometry(Glue([lower, upper])).GenerateMesh(maxh=maxh))


def random_state(prob, size, seed=0):
    prob.u.vec.FV().NumPy()[:] = size * np.random.default_rng(seed).standard_normal(prob.fes.ndof)


def apply_residual(prob):
    """External minus internal forces by NGSolve's Apply of the energy form."""
    res = prob.u.vec.CreateVector()
    prob.form.Apply(prob.u.vec, res)
    return -res.FV().NumPy().copy()


def linearisation(prob):
    """NGSolve's tangent: AssembleLinearization of the energy form."""
    prob.form.AssembleLinearization(prob.u.vec)
    return to_scipy(prob.form.mat)


def test_block_mesh_is_a_two_region_tet_mesh():
    mesh = block()
    assert mesh.dim == 3 and 100 < mesh.ne < 2000 and sorted(set(mesh.GetMaterials())) == ["a", "b"]


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("size", [1e-5, 5e-3])
def test_kernel_equals_apply(law, size):
    """Strains of about 5e-5 and 2.5e-2 (h = 0.35); neo-Hooke's automatic derivative loses
    digits like 1 / strain in mu (F - F^-T), which the kernel expands in H (as in 2D)."""
    prob = ElasticProblem(block(), law(E=7.0, nu=0.3))
    random_state(prob, size)
    prob.load_factor.Set(0.7)
    kernel = prob.out_of_balance()
    assert prob._kernel_data() is not None
    reference = apply_residual(prob)
    tol = 1e-13 * (max(1.0, 1e-3 / size) if law is nf.NeoHookean else 1.0)
    assert np.linalg.norm(kernel - reference) <= tol * np.linalg.norm(reference)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("size", [1e-6, 5e-3])
def test_tangent_kernel_equals_linearisation(law, size):
    """Same sparsity pattern (every pair of dofs of a tetrahedron, columns sorted), same
    entries to rounding of the largest entry."""
    prob = ElasticProblem(block(), law(E=7.0, nu=0.3))
    random_state(prob, size, seed=1)
    K = prob.tangent()
    reference = linearisation(prob)
    assert K.shape == (3 * prob.mesh.nv, 3 * prob.mesh.nv)
    assert np.array_equal(K.indptr, reference.indptr) and np.array_equal(K.indices, reference.indices)
    assert abs(K - reference).max() <= 1e-14 * abs(reference).max()


def test_regions_loads_and_the_tangent_as_derivative_of_the_forces():
    """Two regions of different laws, a body force and a traction at a load factor that is
    not 1: forces equal to Apply, tangent equal to the linearisation, and K v is the
    directional derivative of the kernel's forces (central differences: error O(eps^2),
    eps^2 = 1e-12 relative to the strain squared)."""
    prob = ElasticProblem(block(), {"a": nf.StVenantKirchhoff(5e9, 0.18), "b": nf.NeoHookean(1e9, 0.3)})
    prob.add_body_force(ng.CF((1e6 * ng.y, -2e6, 3e5 * ng.z)))
    prob.add_traction("top", ng.CF((3e6 * ng.x, 1e6, -2e6)))
    random_state(prob, 1e-2, seed=3)
    prob.load_factor.Set(0.37)
    reference = apply_residual(prob)
    kernel = prob.out_of_balance()
    assert np.linalg.norm(kernel - reference) <= 1e-13 * np.linalg.norm(reference)
    K = prob.tangent()
    assert abs(K - linearisation(prob)).max() <= 1e-14 * abs(K).max()
    kind, mu, lam, _ = prob._kernel_data()
    assert sorted(set(kind.tolist())) == [1, 2]
    u = prob.u.vec.FV().NumPy().copy()
    v = np.random.default_rng(5).standard_normal(u.size)
    eps = 1e-6

    def forces(w):
        return _C.InternalForces(prob._points, prob._elements, w, kind, mu, lam)
    difference = (forces(u + eps * v) - forces(u - eps * v)) / (2 * eps)
    assert np.linalg.norm(difference - K @ v) <= 1e-8 * np.linalg.norm(K @ v)


def test_rigid_motion_has_no_forces():
    """A finite rotation with a translation: zero stress for the objective laws, so the
    forces vanish to rounding of the stiffness times the displacement."""
    prob = ElasticProblem(block(), nf.NeoHookean(1.0, 0.3))
    c, s = np.cos(0.4), np.sin(0.4)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    P = prob._points
    prob.u.vec.FV().NumPy()[:] = (P @ R.T - P + [0.1, -0.2, 0.3]).T.ravel()
    kind, mu, lam, _ = prob._kernel_data()
    f = _C.InternalForces(P, prob._elements, prob.u.vec.FV().NumPy(), kind, mu, lam)
    assert np.abs(f).max() <= 1e-14 * abs(prob.tangent()).max()


def test_second_order_and_user_laws_use_ngsolve():
    class Own(nf.StVenantKirchhoff):
        kernel = None
    assert ElasticProblem(block(), Own(1.0, 0.3))._kernel_data() is None
    prob = ElasticProblem(block(0.6), nf.StVenantKirchhoff(1.0, 0.3), order=2)
    random_state(prob, 1e-3)
    assert prob._kernel_data() is None
    assert np.array_equal(prob.out_of_balance(), apply_residual(prob))


def test_inverted_neo_hooke_tetrahedron_gives_nan():
    prob = ElasticProblem(block(), nf.NeoHookean(1.0, 0.3))
    n = prob.mesh.nv
    prob.u.vec.FV().NumPy()[:n] = -2.0 * prob._points[:, 0]   # x -> -x: every element inverted
    assert np.isnan(prob.out_of_balance()).any()


def test_kernel_refuses_mismatched_widths_and_sizes():
    pts, tets = np.eye(4, 3), np.array([[0, 1, 2, 3]], dtype=np.int32)
    one, law = np.ones(1), np.array([1], dtype=np.int32)
    with pytest.raises(Exception, match="3 nv"):
        _C.InternalForces(pts, tets, np.zeros(8), law, one, one)
    with pytest.raises(Exception, match="width"):
        _C.InternalForces(pts[:, :2], tets, np.zeros(8), law, one, one)
    with pytest.raises(Exception, match="width"):
        _C.TangentStiffness(pts, tets[:, :3], np.zeros(12), law, one, one)
    with pytest.raises(Exception, match="out of range"):
        _C.TangentStiffness(pts, tets + 1, np.zeros(12), law, one, one)
    with pytest.raises(Exception, match="one entry per element"):
        _C.InternalForces(pts, tets, np.zeros(12), np.array([1, 1], dtype=np.int32), one, one)
