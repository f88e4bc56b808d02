"""Bad input is a clear error that names the offending thing, raised before any work.

Meshes (meshcheck.py), critical strains and constraints.  Material parameters are in
test_materials_constraints.py.
"""
import re

import netgen.meshing as nm
import ngsolve as ng
import numpy as np
import pytest

import ngfracture as nf
from ngfracture import fracture
from ngfracture.geometry.meshcheck import MeshError, validate_mesh
from ngfracture.geometry.meshio import MeshArrays, merge_meshes, mesh_from_arrays
from conftest import square_mesh


def arrays(points, triangles, segments=(), bc_names=("outer",)):
    """MeshArrays with one region and all segments on boundary 1."""
    segments = np.array(segments, dtype=np.int64).reshape(-1, 2)
    return MeshArrays(np.array(points, dtype=float), np.array(triangles, dtype=np.int64),
                      np.ones(len(triangles), dtype=np.int64), ["solid"], segments,
                      np.ones(len(segments), dtype=np.int64), list(bc_names))


# the unit square cut into four triangles around its centre (vertex 4), boundary 'outer'
SQUARE_P = [(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]
SQUARE_T = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
SQUARE_S = [(0, 1), (1, 2), (2, 3), (3, 0)]


def two_halves(interface_segments):
    """[0,2]x[0,1] as two unit squares that do not share their interface vertices.

    Vertices 2 and 9 coincide at (1, 0.5), inside the interface; 1/5 and 3/8 at its ends.
    """
    P = [(0, 0), (1, 0), (1, 0.5), (1, 1), (0, 1), (1, 0), (2, 0), (2, 1), (1, 1), (1, 0.5)]
    T = [(0, 1, 2), (0, 2, 4), (4, 2, 3), (5, 6, 9), (9, 6, 7), (9, 7, 8)]
    S = [(0, 1), (5, 6), (6, 7), (7, 8), (3, 4), (4, 0)]
    if interface_segments:
        S += [(1, 2), (2, 3), (8, 9), (9, 5)]
    return mesh_from_arrays(arrays(P, T, S))


def test_the_good_square_passes():
    a = validate_mesh(mesh_from_arrays(arrays(SQUARE_P, SQUARE_T, SQUARE_S)))
    assert a.triangles.shape == (4, 3) and a.points.shape == (5, 2)


BAD_MESHES = {
    "unused vertex": (SQUARE_P + [(2, 2)], SQUARE_T, SQUARE_S,
                      "vertex 5 at (2, 2) belongs to no triangle"),
    "zero area": (SQUARE_P + [(2, 0)], SQUARE_T + [(0, 1, 5)], SQUARE_S,
                  "triangle 4 (vertices 0, 1, 5) has zero area"),
    "zero area, rounding": (SQUARE_P + [(0.1, 0.1 + 1e-17)], SQUARE_T + [(0, 4, 5)], SQUARE_S,
                            "triangle 4 (vertices 0, 4, 5) has zero area"),
    "clockwise": (SQUARE_P, [(0, 1, 4), (1, 2, 4), (2, 4, 3), (3, 0, 4)], SQUARE_S,
                  "triangle 2 (vertices 2, 4, 3) is clockwise"),
    "edge in three triangles": (SQUARE_P + [(0.5, -0.5), (0.5, 0.2)], SQUARE_T + [(0, 5, 1), (0, 1, 6)], SQUARE_S,
                                "edge (0, 1) is shared by 3 triangles"),
    "bow-tie": ([(0, 0), (1, 0), (0, 1), (-1, 0), (0, -1)], [(0, 1, 2), (0, 3, 4)], [],
                "vertex 0 at (0, 0) is a bow-tie (non-manifold): its triangles form 2 fans"),
}


@pytest.mark.parametrize("case", sorted(BAD_MESHES))
def test_bad_mesh_is_named(case):
    P, T, S, message = BAD_MESHES[case]
    mesh = mesh_from_arrays(arrays(P, T, S))
    with pytest.raises(MeshError, match="^mesh: " + re.escape(message)):
        validate_mesh(mesh)


def test_coincident_vertices_inside_a_body_are_an_error():
    with pytest.raises(MeshError, match=re.escape("vertices 2 and 9 coincide at (1, 0.5) and are not both "
                                                  "on boundary segments")):
        validate_mesh(two_halves(interface_segments=False))


def test_coincident_vertices_on_boundaries_are_accepted():
    """Touching bodies (segments on both faces), merged meshes and crack lips share points."""
    validate_mesh(two_halves(interface_segments=True))
    body = square_mesh(0.5)
    merged = merge_meshes(body, body)            # two identical squares on top of each other
    assert merged.nv == 2 * body.nv
    validate_mesh(merged)
    # a crack pass: the lips coincide in the reference configuration
    mesh = square_mesh(0.2)
    u = ng.GridFunction(ng.VectorH1(mesh))
    u.Set(ng.CF((1e-3 * ng.x * ng.x, 0)))
    new_mesh, _, res = fracture.crack_step(mesh, u, critical=1e-3 * 0.9, measure="linear")
    assert res.nsplit > 0
    P = new_mesh.ngmesh.Coordinates()[:, :2]
    assert len(np.unique(P, axis=0)) < new_mesh.nv      # copies sit on their parents
    validate_mesh(new_mesh)


def test_empty_mesh_and_no_triangles():
    with pytest.raises(MeshError, match=r"^mesh: the mesh is empty \(no vertices\)"):
        validate_mesh(ng.Mesh(nm.Mesh(dim=2)))
    m = nm.Mesh(dim=2)
    m.AddPoints(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]))
    with pytest.raises(MeshError, match="^mesh: the mesh has 3 vertices but no triangles"):
        validate_mesh(ng.Mesh(m))


def test_3d_points_in_2d_arrays_are_refused():
    from netgen.csg import unit_cube
    # a 3D mesh is checked as one (tests/test_solid_mechanics.py)
    assert validate_mesh(ng.Mesh(unit_cube.GenerateMesh(maxh=0.5))).dim == 3
    a = arrays(SQUARE_P, SQUARE_T, SQUARE_S)
    a.points = np.column_stack([a.points, np.zeros(5)])
    with pytest.raises(MeshError, match=r"points must have 2 coordinates \(a 2D mesh\), got shape \(5, 3\)"):
        validate_mesh(a)


def test_bad_arrays_are_named():
    a = arrays(SQUARE_P, SQUARE_T, SQUARE_S)
    a.points[3] = (np.nan, 1.0)
    with pytest.raises(MeshError, match=r"vertex 3 has coordinates \[nan, 1.0\]"):
        validate_mesh(a)
    a = arrays(SQUARE_P, [(0, 1, 4), (1, 2, 7)], SQUARE_S)
    with pytest.raises(MeshError, match=r"triangle 1 has vertices \[1, 2, 7\], outside \[0, 5\)"):
        validate_mesh(a)


def bow_tie_mesh():
    P, T, S, _ = BAD_MESHES["bow-tie"]
    return mesh_from_arrays(arrays(P, T, S))


def test_entry_points_refuse_a_bad_mesh():
    mesh = bow_tie_mesh()
    with pytest.raises(MeshError, match="vertex 0 .* bow-tie"):
        nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    u = ng.GridFunction(ng.VectorH1(mesh))
    with pytest.raises(MeshError, match="vertex 0 .* bow-tie"):
        fracture.crack_step(mesh, u, 1e-3)
    with pytest.raises(MeshError, match="vertex 0 .* bow-tie"):
        fracture.split_by_tensor(mesh, np.zeros((mesh.nv, 3)), 1e-3)
    assert issubclass(MeshError, ValueError)


# ---------------------------------------------------------------- critical strain
BAD_CRITICAL = [0.0, -1e-3, float("nan"), float("inf"), float("-inf")]


@pytest.mark.parametrize("bad", BAD_CRITICAL)
def test_bad_critical_strain_is_named(bad):
    mesh = square_mesh(0.5)
    message = re.escape(f"critical strain must be finite and > 0, got {bad!r}")
    with pytest.raises(ValueError, match=message):
        fracture.Criterion(bad)
    with pytest.raises(ValueError, match=message):
        fracture.split_by_tensor(mesh, np.zeros((mesh.nv, 3)), bad)
    u = ng.GridFunction(ng.VectorH1(mesh))
    with pytest.raises(ValueError, match=message):
        fracture.crack_step(mesh, u, bad)


def test_a_criterion_with_nan_overstrain_is_refused_before_any_split():
    class Broken:
        def overstrain(self, mesh, u):
            return np.full((mesh.nv, 3), np.nan)

    mesh = square_mesh(0.5)
    with pytest.raises(ValueError, match="NaN"):
        fracture.crack_step(mesh, ng.GridFunction(ng.VectorH1(mesh)), criterion=Broken())


# ---------------------------------------------------------------- constraints
def test_unknown_boundary_lists_the_existing_ones(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    known = re.escape("its boundaries are ['bottom', 'left', 'right', 'top']")
    with pytest.raises(ValueError, match="boundary 'Left' does not exist in the mesh; " + known):
        prob.add_dirichlet("Left", (0.0, 0.0))
    with pytest.raises(ValueError, match="boundary 'rigth' does not exist in the mesh; " + known):
        prob.add_traction("rigth", (1.0, 0.0))
    assert prob.constraints.dirichlet == [] and prob._loads == []


def test_conflicting_point_and_dirichlet_values_name_both(square):
    prob = nf.ElasticProblem(square, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet("left", (0.0, 0.0))
    prob.add_point_constraint(0, (0.0, 0.5))      # vertex 0 is (0, 0), on 'left'
    n = prob.fes.ndof // 2
    with pytest.raises(ValueError, match=re.escape(f"conflicting constraint values on dof {n}: 0.0 from "
                                                   "Dirichlet on left and 0.5 from point constraint at vertex 0")):
        prob.solve()
    assert np.all(prob.u.vec.FV().NumPy() == 0.0)


def test_constraints_that_leave_no_free_dof_are_an_error():
    names = ["bottom", "right", "top", "left"]
    a = arrays(SQUARE_P[:4], [(0, 1, 2), (0, 2, 3)], SQUARE_S, bc_names=names)
    a.seg_bc = np.array([1, 2, 3, 4])
    mesh = mesh_from_arrays(a)                   # four vertices, all on the boundary
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet(["bottom", "top"], (0.1, 0.0))
    prob.add_point_constraint(1, (0.1, 0.0))
    with pytest.raises(ValueError, match=re.escape("the constraints leave no free dof: Dirichlet on bottom, top; "
                                                   "point constraint at vertex 1 prescribe all 8 dofs, "
                                                   "there is nothing to solve for")):
        prob.solve()
    assert np.all(prob.u.vec.FV().NumPy() == 0.0)
    # one component free: solvable, a rigid translation
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    prob.add_dirichlet(["bottom", "top"], 0.1, component="x")
    prob.add_point_constraint(0, 0.0, component="y")
    assert prob.solve().converged
    assert np.allclose(prob.u.vec.FV().NumPy(), [0.1] * 4 + [0.0] * 4, atol=1e-14)


if __name__ == "__main__":
    raise SystemExit(pytest.main([__file__, "-q"]))


@pytest.mark.parametrize("holes, message", [
    (((0.0, 0.1, 0.2),), "holes[0] = (0.0, 0.1, 0.2) does not lie inside the beam"),     # cuts the bottom edge
    (((-0.3, 0.5, 0.2), (-0.12, 0.5, 0.08)), "holes[0] = (-0.3, 0.5, 0.2) does not lie"),  # across the band's side
    (((-0.22, 0.5, 0.08), (-0.12, 0.5, 0.08)), "holes[1] = (-0.12, 0.5, 0.08) does not lie"),
    (((-0.5, 0.22, 0.05),), "clear of the notch"),                                        # on the notch's tip
    (((-0.22, 0.5, -1.0),), "holes[0] radius must be a finite number > 0"),
    (((-0.22, 0.5, 0.08), (-0.22, 0.62, 0.05)), "holes[1] = (-0.22, 0.62, 0.05) overlaps holes[0]"),
])
def test_holed_beam_names_a_hole_that_does_not_fit(holes, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        nf.scenes.holed_beam(holes=holes)
