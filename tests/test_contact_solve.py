"""Contact between pieces: the patch test, Kuhn-Tucker conditions, separation, no overlap."""
import numpy as np
import ngsolve as ng
import pytest

import ngfracture as nf
from ngfracture.contact.overlap import fragment_overlap_area, overlap_area
from ngfracture.contact.solver import ContactSolver
from ngfracture.geometry.meshio import MeshArrays, mesh_from_arrays, mesh_to_arrays
from conftest import square_mesh


def stacked_blocks(maxh=0.2):
    """Two unit blocks stacked at y = 1 with matching interface nodes, sharing no vertex.

    The upper block is the mirror image (y -> 2 - y) of the lower one, so the nodes of the
    interface coincide and node-to-node contact can reproduce a uniform pressure exactly.
    """
    low = mesh_to_arrays(square_mesh(maxh))
    nv = low.points.shape[0]
    up_pts = np.column_stack([low.points[:, 0], 2.0 - low.points[:, 1]])
    names = low.bc_names + ["upper_" + b for b in low.bc_names]
    arrays = MeshArrays(
        points=np.vstack([low.points, up_pts]),
        triangles=np.vstack([low.triangles, low.triangles[:, ::-1] + nv]),   # mirrored: reverse to stay CCW
        regions=np.concatenate([low.regions, low.regions]), region_names=low.region_names,
        segments=np.vstack([low.segments, low.segments[:, ::-1] + nv]),
        seg_bc=np.concatenate([low.seg_bc, low.seg_bc + len(low.bc_names)]), bc_names=names)
    return mesh_from_arrays(arrays)


def pressed_blocks(d=1e-3, E=1.0, nu=0.3, maxh=0.2):
    mesh = stacked_blocks(maxh)
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(E, nu, plane="stress"))
    pts = mesh.ngmesh.Coordinates()[:, :2]
    prob.add_dirichlet("bottom", 0.0, component="y")
    prob.add_dirichlet("upper_bottom", -d, component="y")      # the mirrored bottom is the top, y = 2
    prob.add_point_constraint(int(np.flatnonzero((pts[:, 0] == 0) & (pts[:, 1] == 0))[0]), 0.0, component="x")
    prob.add_point_constraint(int(np.flatnonzero((pts[:, 0] == 0) & (pts[:, 1] == 2))[0]), 0.0, component="x")
    return mesh, prob


def test_contact_patch_test_uniform_pressure():
    d, E = 1e-3, 1.0
    mesh, prob = pressed_blocks(d, E)
    h = 0.2
    result = ContactSolver(prob, tol=0.1 * h).solve()
    assert result.converged, (result.reason, result.status.message)
    cs, lam = result.constraints, result.multipliers
    assert len(cs) > 0 and np.all(lam <= 0)
    # uniaxial stress: sigma_yy = -E d / 2 over the height 2; the multipliers carry it all
    p = E * d / 2
    assert abs(-lam.sum() - p * 1.0) < 1e-10 * p
    # uniform pressure: each node's multiplier is p times its tributary length
    # (forces summed per interface position: a corner row at zero gap may carry ~0)
    x = mesh.ngmesh.Coordinates()[cs.slave, 0]
    xs, where = np.unique(x, return_inverse=True)
    force = np.bincount(where, weights=-lam)
    trib = np.diff(np.concatenate([[xs[0]], 0.5 * (xs[1:] + xs[:-1]), [xs[-1]]]))
    assert xs[0] == 0.0 and xs[-1] == 1.0
    assert np.allclose(force / trib, p, rtol=1e-8, atol=0)
    # Kuhn-Tucker: no penetration, complementarity
    u = prob.u.vec.FV().NumPy()
    from ngfracture.contact.solver import space_columns
    gap = space_columns(cs.C, mesh.nv, prob.fes.ndof // 2) @ u + cs.g
    assert gap.min() >= -1e-10 * h
    assert np.abs(lam * gap).max() < 1e-10
    # the exact solution: u_y = -d/2 * y in both blocks
    uex = ng.CF((0.3 * d / 2 * ng.x, -d / 2 * ng.y))
    assert np.sqrt(ng.Integrate((prob.u - uex) ** 2, mesh)) < 1e-10 * d
    assert fragment_overlap_area(prob) < 1e-10 * 2.0


def test_pulled_apart_blocks_separate():
    """Blocks first pressed, then pulled apart: every row turns adhesive and is released."""
    d = 1e-3
    mesh, prob = pressed_blocks(d)
    assert ContactSolver(prob, tol=0.02).solve().converged
    prob.constraints.dirichlet.pop(1)
    prob.add_dirichlet("upper_bottom", +d, component="y")
    result = ContactSolver(prob, tol=0.02).solve()
    assert result.converged, result.reason
    # no row carries force (rows left at zero gap carry rounding only)
    assert np.abs(result.multipliers).max(initial=0.0) < 1e-12 * d
    # both blocks stress-free: the upper one just moved up by d
    strain = ng.Integrate(ng.InnerProduct(prob.strain(), prob.strain()), mesh)
    assert strain < 1e-24


def test_no_contact_work_for_one_uncracked_body(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("left", (0, 0))
    prob.add_dirichlet("right", (0.01, 0))
    result = ContactSolver(prob, tol=0.01).solve()
    assert result.converged and result.rounds == 0 and result.timings["contact"] == 0.0


def test_overlap_area_of_two_triangles():
    x = np.array([[0, 0], [1, 0], [0, 1], [0.5, 0], [1.5, 0], [0.5, 1]], dtype=float)
    tris = np.array([[0, 1, 2], [3, 4, 5]])
    # intersection: the triangle (0.5,0), (1,0), (0.5,0.5), area 1/8
    assert overlap_area(x, tris, np.array([[0, 1]])) == pytest.approx(0.125, rel=1e-15)



def test_unsettled_active_set_is_a_reason_not_a_result():
    """One round cannot confirm the set: the solver says so instead of claiming convergence."""
    mesh, prob = pressed_blocks()
    result = ContactSolver(prob, tol=0.02, max_rounds=1).solve()
    assert not result.converged and result.reason == "active_set"
    assert result.rounds == 1 and len(result.history) == 1
