"""Outputs of a 3D run: VTK files of tetrahedra and crack faces read back by VTK (pyvista), the
time series of 3D steps, final.png of the shaded surface.

The test mesh is two structured boxes [0,1]^2 x [0,1] and [0,1]^2 x [1,2] (cubes of 6
tetrahedra) on separate vertices: a body cracked through at z = 1, whose two lips are
coincident faces named "crack" on bitwise-equal vertex copies, and two fragments. Exact
values: the volume 2, the crack area 2 (two lips of area 1), the strain of a linear
displacement field.
"""
import colorsys
import itertools
import os
import struct
import types
import xml.etree.ElementTree as ET

import numpy as np
import ngsolve
import pytest
import pyvista as pv

from ngfracture import output
from ngfracture.geometry.solid import SolidArrays, solid_mesh, total_volume
from ngfracture.output import solid_pictures, solid_vtk, vtkxml


def box(n, z0):
    """Points and positively oriented tetrahedra of [0,1]^2 x [z0, z0+1] in n^3 cubes."""
    g = np.linspace(0.0, 1.0, n + 1)
    x, y, z = np.meshgrid(g, g, g + z0, indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    index = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    tets = []
    for i, j, k in itertools.product(range(n), repeat=3):
        for perm in itertools.permutations(range(3)):     # Kuhn's 6 tetrahedra along the diagonal
            corner, path = np.array([i, j, k]), [index[i, j, k]]
            for axis in perm:
                corner[axis] += 1
                path.append(index[tuple(corner)])
            tets.append(path)
    tets = np.array(tets, dtype=np.int64)
    x = points[tets]
    det = np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))
    tets[det < 0] = tets[det < 0][:, [0, 1, 3, 2]]
    return points, tets


def boundary(tets):
    """Faces used by one tetrahedron, outward (counted in a dict: independent of the package)."""
    count = {}
    for t in tets.tolist():
        for f in ([t[1], t[2], t[3]], [t[0], t[3], t[2]], [t[0], t[1], t[3]], [t[0], t[2], t[1]]):
            count.setdefault(tuple(sorted(f)), []).append(f)
    return np.array([fs[0] for fs in count.values() if len(fs) == 1], dtype=np.int64)


def two_boxes(n=2):
    """Two boxes stacked on separate vertices; faces at z = 1 named crack (bc 2)."""
    pa, ta = box(n, 0.0)
    pb, tb = box(n, 1.0)
    points, tets = np.vstack([pa, pb]), np.vstack([ta, tb + len(pa)])
    faces = boundary(tets)
    on_cut = np.all(points[faces][:, :, 2] == 1.0, axis=1)
    arrays = SolidArrays(points, tets, np.r_[np.ones(len(ta), int), 2 * np.ones(len(tb), int)],
                         ["lower", "upper"], faces, np.where(on_cut, 2, 1), ["outer", "crack"])
    fragment = np.r_[np.zeros(len(ta), np.int64), np.ones(len(tb), np.int64)]
    return arrays, fragment


A = np.array([[1e-3, 2e-3, 0.0], [0.0, -5e-4, 1e-3], [3e-3, 0.0, 2e-3]])


def displacement(arrays, fragment, lift=0.1):
    """A linear field plus a lift of the upper box (opens the crack by ``lift``)."""
    U = arrays.points @ A.T
    vertex_fragment = np.zeros(len(arrays.points), np.int64)
    vertex_fragment[arrays.tets.ravel()] = np.repeat(fragment, 4)
    U[:, 2] += lift * vertex_fragment
    return U


@pytest.fixture(scope="module")
def cracked():
    arrays, fragment = two_boxes(2)
    return arrays, fragment, displacement(arrays, fragment)


def test_written_vtu_reads_back_exactly(cracked, tmp_path):
    arrays, fragment, U = cracked
    _, points, cells = solid_vtk.solid_fields(arrays, U, fragment, cell_data={"mine": np.arange(len(arrays.tets))})
    path = tmp_path / "a.vtu"
    path.write_bytes(vtkxml.unstructured_grid(arrays.points, arrays.tets, points, cells,
                                              {"region_names": arrays.region_names}, cell_type=vtkxml.VTK_TETRA))
    g = pv.read(path)
    assert np.array_equal(g.points, arrays.points)
    assert np.array_equal(g.cells.reshape(-1, 5)[:, 1:], arrays.tets) and np.all(g.cells.reshape(-1, 5)[:, 0] == 4)
    assert np.all(g.celltypes == 10) and g.n_cells == 96
    assert np.array_equal(g.point_data["displacement"], U)
    assert np.array_equal(g.cell_data["fragment"], fragment)
    assert np.array_equal(g.cell_data["region"], arrays.regions - 1)
    assert np.array_equal(g.cell_data["mine"], np.arange(len(arrays.tets)))
    assert list(g.field_data["region_names"]) == ["lower", "upper"]
    # volume by VTK (compute_cell_sizes) against the exact 2 and the package's fsum
    volume = g.compute_cell_sizes(length=False, area=False, volume=True).cell_data["Volume"]
    assert np.all(volume > 0)
    assert abs(volume.sum() - 2.0) <= 1e-12 * 2.0 and abs(total_volume(arrays.points, arrays.tets) - 2.0) <= 1e-15
    # the strain of u = A x (+ a rigid lift) is exact on every tetrahedron
    green = 0.5 * (A + A.T + A.T @ A)
    assert np.abs(g.cell_data["strain"].reshape(-1, 3, 3) - green).max() <= 1e-15
    assert np.allclose(g.cell_data["principal_strain"], np.linalg.eigvalsh(green)[-1], rtol=0, atol=1e-15)
    d = g.cell_data["principal_direction"]
    assert np.allclose(np.einsum("ij,jk,ik->i", d, green, d), np.linalg.eigvalsh(green)[-1], rtol=0, atol=1e-15)
    linear = solid_vtk.solid_strain(arrays.points, arrays.tets, U, "linear")
    assert np.abs(linear - 0.5 * (A + A.T)).max() <= 1e-15


def test_crack_faces_as_triangles_open_under_warp(cracked, tmp_path):
    arrays, fragment, U = cracked
    pts, tris, pdata = solid_vtk.solid_crack_fields(arrays, U)
    path = tmp_path / "c.vtp"
    path.write_bytes(vtkxml.poly_triangles(pts, tris, pdata))
    c = pv.read(path)
    crack = arrays.boundary_faces("crack")
    assert c.n_cells == len(crack) == 16 and c.n_lines == 0 and c.is_all_triangles
    assert np.array_equal(c.point_data["vertex"][c.regular_faces], crack)
    assert np.array_equal(c.point_data["displacement"], U[c.point_data["vertex"]])
    x = arrays.points[crack]
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1).sum()
    vtk_area = c.compute_cell_sizes(length=False, area=True, volume=False).cell_data["Area"].sum()
    assert abs(vtk_area - area) <= 1e-12 * area and abs(area - 2.0) <= 1e-15
    # ParaView's Warp By Vector opens the crack by the lift: the lips 0.1 apart along z
    warped = c.warp_by_vector("displacement")
    gap = warped.points[:, 2] - (c.points @ A.T)[:, 2] - 1.0
    lower = c.point_data["vertex"] < len(arrays.points) // 2
    assert np.allclose(gap[lower], 0.0, atol=1e-15) and np.allclose(gap[~lower], 0.1, atol=1e-15)
    # an uncracked body: an empty file
    one = SolidArrays(*box(1, 0.0), np.ones(6, int), ["solid"], np.zeros((0, 3), int), np.zeros(0, int), [])
    path.write_bytes(vtkxml.poly_triangles(*solid_vtk.solid_crack_fields(one)))
    assert pv.read(path).n_points == 0


def test_pyvista_objects_equal_the_files(cracked, tmp_path):
    arrays, fragment, U = cracked
    g = output.to_pyvista(arrays, U, fragment)           # dispatched on the dimension
    assert isinstance(g, pv.UnstructuredGrid) and np.all(g.celltypes == pv.CellType.TETRA)
    c = output.cracks_to_pyvista(arrays, U)
    assert isinstance(c, pv.PolyData) and c.n_cells == 16
    w = output.TimeSeriesWriter(tmp_path / "run")
    vtu, vtp = w.write(0, 0.0, arrays, U, fragment)
    for mine, read in ((g, pv.read(vtu)), (c, pv.read(vtp))):
        assert np.array_equal(mine.points, read.points)
        assert mine.array_names == read.array_names
        for name in mine.point_data.keys():
            assert np.array_equal(mine.point_data[name], read.point_data[name]), name
        for name in mine.cell_data.keys():
            assert np.array_equal(mine.cell_data[name], read.cell_data[name]), name


@pytest.mark.parametrize("compression", ["zlib", "lz4", None])
def test_time_series_of_an_ngsolve_mesh(cracked, tmp_path, compression):
    arrays, fragment, U = cracked
    mesh = solid_mesh(arrays)
    fes = ngsolve.VectorH1(mesh, order=1)
    gf = ngsolve.GridFunction(fes)
    gf.vec.FV().NumPy()[:] = U.T.ravel()                 # component-blocked dofs
    w = output.TimeSeriesWriter(tmp_path / "run", compression=compression)
    for step in (0, 1, 3):
        w.write(step, 0.5 * step, mesh, gf if step == 3 else step * U, fragment)
    collection = [(float(d.get("timestep")), d.get("file"))
                  for d in ET.parse(tmp_path / "run" / "results.pvd").getroot().iter("DataSet")]
    assert collection == [(0.0, "step_000000.vtu"), (0.5, "step_000001.vtu"), (1.5, "step_000003.vtu")]
    assert sorted(os.listdir(tmp_path / "run")) == sorted(
        ["results.pvd", "cracks.pvd"] + [f"step_{s:06d}.vtu" for s in (0, 1, 3)]
        + [f"cracks_{s:06d}.vtp" for s in (0, 1, 3)])
    reader = pv.get_reader(tmp_path / "run" / "results.pvd")
    assert reader.time_values == [0.0, 0.5, 1.5]
    reader.set_active_time_value(1.5)
    g = reader.read()[0]
    assert np.all(g.celltypes == 10) and np.array_equal(g.point_data["displacement"], U)
    assert np.array_equal(g.cells.reshape(-1, 5)[:, 1:], arrays.tets)      # netgen's round trip keeps the order
    c = pv.read(tmp_path / "run" / "cracks_000003.vtp")
    assert c.n_cells == 16 and np.array_equal(c.point_data["displacement"], U[c.point_data["vertex"]])


def test_bad_3d_input_is_named(cracked, tmp_path):
    arrays, fragment, U = cracked
    w = output.TimeSeriesWriter(tmp_path / "run")
    with pytest.raises(ValueError, match=r"fragment must be 96 integers \(one per tetrahedron\)"):
        w.write(0, 0.0, arrays, U, fragment[:-1])
    with pytest.raises(ValueError, match=r"displacement has shape \(54, 2\)"):
        w.write(0, 0.0, arrays, U[:, :2], fragment)
    with pytest.raises(ValueError, match="NaN or inf"):
        w.write(0, 0.0, arrays, np.full_like(U, np.nan), fragment)
    with pytest.raises(ValueError, match="strain must be one of"):
        w.write(0, 0.0, arrays, U, fragment, strain="log")
    flat = SolidArrays(arrays.points, arrays.tets[:, [0, 1, 3, 2]], arrays.regions, arrays.region_names,
                       arrays.faces, arrays.face_bc, arrays.bc_names)
    with pytest.raises(ValueError, match=r"tetrahedron 0 .* not > 0"):
        w.write(0, 0.0, flat, U, fragment)
    assert w.steps == [] and sorted(os.listdir(tmp_path / "run")) == []


def png_size(path):
    data = open(path, "rb").read(24)
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def hue(hex_colour):
    return colorsys.rgb_to_hsv(*(int(hex_colour[i:i + 2], 16) / 255 for i in (1, 3, 5)))[0]


def test_final_png_shows_both_fragments(cracked, tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    arrays, fragment, U = cracked
    scale = output.picture_scale(arrays.points, U)
    p = output.render_png(solid_mesh(arrays), U, fragment, tmp_path / "final.png", window_size=(320, 240),
                          scale=scale)
    assert png_size(p) == (320, 240)
    from PIL import Image
    rgb = np.asarray(Image.open(p).convert("RGB")).reshape(-1, 3) / 255.0
    body = rgb[np.any(rgb < 0.98, axis=1)]                     # not the white background
    assert len(body) > 0.2 * len(rgb)
    hsv = np.array([colorsys.rgb_to_hsv(*c) for c in np.unique(body, axis=0)])
    # shading scales a face's RGB, which keeps its hue: both fragments' hues are there
    for colour in output.FRAGMENT_COLOURS[:2]:
        assert np.any((np.abs(hsv[:, 0] - hue(colour)) < 0.02) & (hsv[:, 1] > 0.5)), colour
    with pytest.raises(FileExistsError):
        output.render_png(arrays, U, fragment, p)
    with pytest.raises(ValueError, match="95 fragment numbers for 96 tetrahedra"):
        output.render_png(arrays, U, fragment[:-1], tmp_path / "x.png")


def test_final_pictures_of_a_3d_run(cracked, tmp_path):
    arrays, fragment, U = cracked
    stats = types.SimpleNamespace(fragment=fragment, count=2, areas=np.array([1.0, 1.0]))
    scale = output.picture_scale(arrays.points, U)
    pictures = output.final_pictures(tmp_path, solid_mesh(arrays), U, stats, scale)
    assert pictures == {"final": "final.png", "displacement_scale": scale}
    assert png_size(tmp_path / "final.png") == (1200, 900) and os.listdir(tmp_path) == ["final.png"]


def test_render_failure_is_a_render_error(cracked, tmp_path, monkeypatch):
    import PIL.Image

    def broken(self, *args, **kwargs):
        raise OSError("disk full")
    monkeypatch.setattr(PIL.Image.Image, "save", broken)
    arrays, fragment, U = cracked
    with pytest.raises(output.RenderError, match="x.png.*OSError: disk full"):
        output.render_png(arrays, U, fragment, tmp_path / "x.png")
    assert os.listdir(tmp_path) == []


def test_surface_faces_are_the_boundary_outward(cracked):
    arrays, _, _ = cracked
    faces, owner = solid_pictures.surface_faces(arrays.tets, len(arrays.points))
    expected = boundary(arrays.tets)
    assert sorted(map(tuple, faces.tolist())) == sorted(map(tuple, expected.tolist()))
    # outward: the face normal points away from its tetrahedron's fourth vertex
    x = arrays.points
    n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    centre = x[arrays.tets[owner]].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", n, x[faces[:, 0]] - centre) > 0)
    # restricted to the tetrahedra on the boundary faces' vertices: the same faces
    on_boundary = np.zeros(len(x), dtype=bool)
    on_boundary[arrays.faces.ravel()] = True
    fast, fast_owner = solid_pictures.surface_faces(arrays.tets, len(x), on_boundary)
    assert np.array_equal(fast, faces) and np.array_equal(fast_owner, owner)
    frame = solid_pictures.view_frame()
    assert np.allclose(frame @ frame.T, np.eye(3), atol=1e-15) and np.allclose(np.cross(frame[0], frame[1]), frame[2])
