"""Meshes to arrays and back, exactly; separate bodies merged without shared vertices."""
import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import SplineGeometry

from ngfracture._ngfracture import ElementAreas
from ngfracture.contact.collision import boundary_edge_mask
from ngfracture.geometry.meshio import (MeshArrays, merge_meshes, mesh_from_arrays, mesh_to_arrays,
                             separate_region)
from conftest import square_mesh, two_region_bar_mesh


def test_roundtrip_is_exact():
    mesh = two_region_bar_mesh(0.2)
    a = mesh_to_arrays(mesh)
    b = mesh_to_arrays(mesh_from_arrays(a))
    for f in ("points", "triangles", "regions", "segments", "seg_bc"):
        assert np.array_equal(getattr(a, f), getattr(b, f)), f
    assert a.region_names == b.region_names == ["soft", "stiff"]
    assert a.bc_names == b.bc_names
    again = mesh_from_arrays(MeshArrays.from_dict(a.as_dict()))
    assert np.array_equal(ElementAreas(again), ElementAreas(mesh))
    assert ng.Integrate(ng.CF(1), again, definedon=again.Boundaries("interface")) == pytest.approx(1.0, rel=1e-14)


def test_merged_bodies_share_no_vertex():
    a = square_mesh(0.3)
    geo = SplineGeometry()
    geo.AddRectangle((0, 1), (1, 2), bcs=["bottom", "right", "top2", "left"])
    geo.SetMaterial(1, "upper")
    b = ng.Mesh(geo.GenerateMesh(maxh=0.3))
    m = merge_meshes(a, b)
    assert m.nv == a.nv + b.nv and m.ne == a.ne + b.ne
    assert set(m.GetMaterials()) == {"default", "upper"}
    assert set(m.GetBoundaries()) == {"bottom", "right", "top", "left", "top2"}
    assert ng.Integrate(ng.CF(1), m) == pytest.approx(2.0, rel=1e-14)
    # two pieces: their vertex sets are disjoint
    from ngfracture.mechanics.rigid import pieces
    ncomp, _ = pieces(mesh_to_arrays(m).triangles, m.nv)
    assert ncomp == 2


def test_bad_arrays_are_refused():
    a = mesh_to_arrays(square_mesh(0.5))
    bad = MeshArrays(a.points, a.triangles + 1000, a.regions, a.region_names, a.segments, a.seg_bc, a.bc_names)
    with pytest.raises(ValueError, match="triangle vertex numbers"):
        mesh_from_arrays(bad)
    bad = MeshArrays(a.points * np.nan, a.triangles, a.regions, a.region_names, a.segments, a.seg_bc, a.bc_names)
    with pytest.raises(ValueError, match="finite"):
        mesh_from_arrays(bad)


def test_separate_region_detaches_a_body_with_coincident_copies():
    """The stiff half of the bar gets its own copies of the x = 1 vertices (the interface
    ends on the outer boundary: the stiff side's top and bottom segments use the copies)."""
    mesh = two_region_bar_mesh(0.25)
    a = mesh_to_arrays(mesh)
    on_x1 = np.flatnonzero(a.points[:, 0] == 1.0)
    s = separate_region(mesh, "stiff")
    b = mesh_to_arrays(s)
    assert s.nv == mesh.nv + len(on_x1) and s.ne == mesh.ne
    assert np.array_equal(b.points[mesh.nv:], a.points[on_x1])
    assert np.array_equal(b.regions, a.regions)
    stiff = b.regions == b.region_names.index("stiff") + 1
    assert not set(b.triangles[stiff].ravel()) & set(b.triangles[~stiff].ravel())
    # both sides are boundary: the same edges reversed, each with its triangle on the left
    iface, surf = b.boundary_segments("interface"), b.boundary_segments("stiff_surface")
    assert len(iface) == len(surf) == len(on_x1) - 1
    assert np.all(b.points[iface][:, :, 0] == 1.0)
    assert sorted(map(tuple, b.points[iface].reshape(-1, 4).tolist())) == \
        sorted(map(tuple, b.points[surf[:, ::-1]].reshape(-1, 4).tolist()))
    assert boundary_edge_mask(b.triangles, b.segments).sum() == len(b.segments)
    assert np.array_equal(ElementAreas(s), ElementAreas(mesh))
    with pytest.raises(ValueError, match="no region"):
        separate_region(mesh, "glass")
