"""VTK XML files written without VTK (ngfracture.output.vtkxml), read back by VTK's own readers
(through PyVista): every array bit for bit, with its VTK type, for every compression; arrays
larger than one compressed block (32 KiB) and ending in a partial block; empty files."""
import numpy as np
import pytest
import pyvista as pv

from ngfracture.output import vtkxml


def grid(n=60):
    """An n x n grid of points, two triangles per square: 7200 triangles for n = 61."""
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 2, n), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel()])
    v = np.arange(n * n).reshape(n, n)
    a, b, c, d = v[:-1, :-1].ravel(), v[1:, :-1].ravel(), v[1:, 1:].ravel(), v[:-1, 1:].ravel()
    return points, np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])


@pytest.mark.parametrize("compression", [None, "zlib", "lzma"])
def test_unstructured_grid_reads_back_bit_for_bit(tmp_path, compression):
    points, tris = grid(61)
    rng = np.random.default_rng(1)
    point_data = {"displacement": rng.standard_normal((len(points), 3)),     # 88 KB: three blocks
                  "flag": rng.random(len(points)) < 0.5,
                  "single": rng.standard_normal(len(points)).astype(np.float32)}
    cell_data = {"region": np.arange(len(tris), dtype=np.int64) % 3,
                 "fragment": (np.arange(len(tris)) % 7).astype(np.int32),
                 "tensor": rng.standard_normal((len(tris), 9))}
    path = tmp_path / "a.vtu"
    path.write_bytes(vtkxml.unstructured_grid(points, tris, point_data, cell_data,
                                              {"region_names": ["glass", "", "core"]}, compression))
    g = pv.read(path)
    assert g.n_points == len(points) and g.n_cells == len(tris)
    assert np.array_equal(g.points[:, :2], points) and np.all(g.points[:, 2] == 0)
    assert np.all(g.celltypes == pv.CellType.TRIANGLE)
    assert np.array_equal(g.cells.reshape(-1, 4)[:, 1:], tris)
    assert np.array_equal(g.point_data["flag"], point_data["flag"].astype(np.uint8))
    for data, expected in ((g.point_data, point_data), (g.cell_data, cell_data)):
        assert list(data) == list(expected)
        for name, values in expected.items():
            assert np.array_equal(data[name], values), name
            assert data[name].dtype == (np.uint8 if values.dtype == bool else values.dtype), name
    assert g.point_data.active_scalars_name == "displacement" and g.cell_data.active_scalars_name == "region"
    assert list(g.field_data["region_names"]) == ["glass", "", "core"]


@pytest.mark.parametrize("compression", [None, "zlib", "lzma"])
def test_poly_lines_read_back_and_an_empty_file_is_empty(tmp_path, compression):
    points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    lines = np.array([[0, 1], [1, 2], [2, 0]])
    path = tmp_path / "c.vtp"
    path.write_bytes(vtkxml.poly_lines(points, lines, {"vertex": np.array([4, 7, 9])}, compression))
    c = pv.read(path)
    assert c.n_points == 3 and c.n_lines == 3 and c.n_cells == 3 and c.n_verts == 0
    assert np.array_equal(c.lines.reshape(-1, 3)[:, 1:], lines)
    assert np.array_equal(c.point_data["vertex"], [4, 7, 9])
    path.write_bytes(vtkxml.poly_lines(np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64), {}, compression))
    empty = pv.read(path)
    assert empty.n_points == 0 and empty.n_cells == 0


def test_bad_input_is_refused():
    points, tris = grid(3)
    with pytest.raises(ValueError, match="compression must be one of.*'gzip'"):
        vtkxml.unstructured_grid(points, tris, compression="gzip")
    with pytest.raises(ValueError, match=r"cells must have shape \(m, 3\)"):
        vtkxml.unstructured_grid(points, tris[:, :2])
    with pytest.raises(ValueError, match=r"points must have shape"):
        vtkxml.poly_lines(np.zeros(4), np.zeros((0, 2), dtype=int))
    with pytest.raises(ValueError, match="CellData array 'f' has 3 rows, expected 8"):
        vtkxml.unstructured_grid(points, tris, cell_data={"f": np.zeros(3)})
    with pytest.raises(ValueError, match="control characters"):
        vtkxml.unstructured_grid(points, tris, {"a\nb": np.zeros(len(points))})
    with pytest.raises(TypeError, match="complex128 have no VTK type"):
        vtkxml.unstructured_grid(points, tris, {"z": np.zeros(len(points), dtype=complex)})
