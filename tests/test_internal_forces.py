"""The C++ internal-force and tangent kernels against NGSolve's Apply and linearisation.

ElasticProblem.out_of_balance takes the residual of P1 meshes from
``_ngfracture.InternalForces`` (one evaluation of the first Piola-Kirchhoff stress per
triangle) instead of NGSolve's Apply of the compiled energy (its gradient by automatic
differentiation), and ElasticProblem.tangent the stiffness from
``_ngfracture.TangentStiffness`` instead of NGSolve's AssembleLinearization (its second
derivative). Both pairs come from the same energy: they must agree to rounding for every
law, both 2D reductions, several regions and the external loads.
"""
import numpy as np
import ngsolve as ng
import pytest
import scipy.sparse as sp

import ngfracture as nf
from ngfracture import _ngfracture as _C
from ngfracture.linalg.sparse import to_scipy
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.scenes import cored_disk_mesh

from conftest import square_mesh

LAWS = [nf.LinearElastic, nf.StVenantKirchhoff, nf.NeoHookean]


def apply_residual(prob):
    """External minus internal forces by NGSolve's Apply of the energy form."""
    res = prob.u.vec.CreateVector()
    prob.form.Apply(prob.u.vec, res)
    return -res.FV().NumPy().copy()


def random_state(prob, size, seed=0):
    prob.u.vec.FV().NumPy()[:] = size * np.random.default_rng(seed).standard_normal(prob.fes.ndof)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("plane", ["strain", "stress"])
@pytest.mark.parametrize("size", [1e-5, 5e-3])
def test_kernel_equals_apply(law, plane, size):
    prob = ElasticProblem(square_mesh(0.1), law(E=7.0, nu=0.3, plane=plane))
    random_state(prob, size)
    prob.load_factor.Set(0.7)
    kernel = prob.out_of_balance()
    reference = apply_residual(prob)
    # neo-Hooke's gradient mu (F - F^-T) cancels in the energy's automatic derivative: its
    # relative rounding grows like 1 / strain (the kernel expands it in H and does not cancel)
    tol = 1e-13 * (max(1.0, 1e-3 / size) if law is nf.NeoHookean else 1.0)
    assert np.linalg.norm(kernel - reference) <= tol * np.linalg.norm(reference)


def linearisation(prob):
    """NGSolve's tangent: AssembleLinearization of the energy form."""
    prob.form.AssembleLinearization(prob.u.vec)
    return to_scipy(prob.form.mat)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("size", [1e-6, 5e-3])
def test_tangent_kernel_equals_linearisation(law, size):
    """Same sparsity pattern, same entries to rounding (of the largest entry), at strains of
    about 1e-5 and 5e-2 (h = 0.1)."""
    prob = ElasticProblem(square_mesh(0.1), law(E=7.0, nu=0.3, plane="stress"))
    random_state(prob, size)
    K = prob.tangent()
    reference = linearisation(prob)
    assert np.array_equal(K.indptr, reference.indptr) and np.array_equal(K.indices, reference.indices)
    assert abs(K - reference).max() <= 1e-14 * abs(reference).max()


def test_tangent_kernel_with_regions_is_the_derivative_of_the_internal_forces():
    """Two regions of different laws: equal to NGSolve's linearisation, and K v is the
    directional derivative of the kernel's internal forces (central differences, whose
    error is O(eps^2) with eps^2 = 1e-12 of the strain squared)."""
    mesh = cored_disk_mesh(0.2, 1.0, 0.25, 0.125)
    prob = ElasticProblem(mesh, {"disk": nf.StVenantKirchhoff(5e9, 0.18), "core": nf.NeoHookean(1e9, 0.3)})
    random_state(prob, 1e-2, seed=4)
    K = prob.tangent()
    assert abs(K - linearisation(prob)).max() <= 1e-14 * abs(K).max()
    kind, mu, lam, _ = prob._kernel_data()
    u = prob.u.vec.FV().NumPy().copy()
    v = np.random.default_rng(5).standard_normal(u.size)
    eps = 1e-6

    def forces(w):
        return _C.InternalForces(prob._points, prob._elements, w, kind, mu, lam)
    difference = (forces(u + eps * v) - forces(u - eps * v)) / (2 * eps)
    assert np.linalg.norm(difference - K @ v) <= 1e-8 * np.linalg.norm(K @ v)


def test_tangent_of_second_order_and_linear_models():
    """Order 2 takes NGSolve's linearisation; the linear model's stiffness is made once."""
    prob = ElasticProblem(square_mesh(0.25), nf.StVenantKirchhoff(1.0, 0.3), order=2)
    random_state(prob, 1e-3)
    K = prob.tangent()
    assert sp.isspmatrix_csr(K) and (K != linearisation(prob)).nnz == 0
    linear = ElasticProblem(square_mesh(0.25), nf.LinearElastic(1.0, 0.3))
    assert linear.tangent() is linear.tangent()


def test_kernel_with_regions_and_loads_equals_apply():
    """Two regions of different laws (the disk's glass and a neo-Hooke core), a body force
    and a traction, at a load factor that is not 1."""
    mesh = cored_disk_mesh(0.2, 1.0, 0.25, 0.125)
    prob = ElasticProblem(mesh, {"disk": nf.StVenantKirchhoff(5e9, 0.18), "core": nf.NeoHookean(1e9, 0.3)})
    prob.add_body_force(ng.CF((1e6 * ng.y, -2e6)))
    prob.add_traction("outer", ng.CF((3e6 * ng.x, 1e6)))
    random_state(prob, 1e-4, seed=3)
    prob.load_factor.Set(0.37)
    kernel = prob.out_of_balance()
    assert prob._kernel_data() is not None
    reference = apply_residual(prob)
    assert np.linalg.norm(kernel - reference) <= 1e-12 * np.linalg.norm(reference)


def test_second_order_uses_apply():
    prob = ElasticProblem(square_mesh(0.25), nf.StVenantKirchhoff(1.0, 0.3), order=2)
    random_state(prob, 1e-3)
    assert prob._kernel_data() is None
    assert np.array_equal(prob.out_of_balance(), apply_residual(prob))


def test_inverted_neo_hooke_element_gives_nan_as_the_energy_does():
    prob = ElasticProblem(square_mesh(0.5), nf.NeoHookean(1.0, 0.3))
    pts = prob.mesh.ngmesh.Coordinates()[:, :2]
    n = prob.fes.ndof // 2
    u = prob.u.vec.FV().NumPy()
    u[:n] = -2.0 * pts[:, 0]           # x -> -x: every element inverted
    assert np.isnan(prob.out_of_balance()).any()


def test_kernel_refuses_bad_shapes():
    pts, tris = np.zeros((3, 2)), np.array([[0, 1, 2]], dtype=np.int32)
    one = np.ones(1)
    with pytest.raises(Exception, match="2 nv"):
        _C.InternalForces(pts, tris, np.zeros(5), np.array([1], dtype=np.int32), one, one)
    with pytest.raises(Exception, match="out of range"):
        _C.InternalForces(pts, np.array([[0, 1, 3]], dtype=np.int32), np.zeros(6), np.array([1], dtype=np.int32), one, one)
    with pytest.raises(Exception, match="one entry per element"):
        _C.InternalForces(pts, tris, np.zeros(6), np.array([1, 1], dtype=np.int32), one, one)
    with pytest.raises(Exception, match="one entry per element"):
        _C.TangentStiffness(pts, tris, np.zeros(6), np.array([1, 1], dtype=np.int32), one, one)
    with pytest.raises(Exception, match="2 nv"):
        _C.TangentStiffness(pts, tris, np.zeros(5), np.array([1], dtype=np.int32), one, one)
