"""Output layer: VTK time series, crack edges, resume/force, JSON summary, PNG, fragment statistics."""
import json
import math
import os
import struct
import xml.etree.ElementTree as ET

import numpy as np
import ngsolve
import pytest
import pyvista as pv

from ngfracture import fracture
from ngfracture import output
from ngfracture.fracture.fragments import FragmentStatistics, fragment_ids
from crack_util import grid_mesh, mesh_from_arrays, coords


@pytest.fixture(scope="module")
def cracked():
    """A 6 x 4 grid pulled along x above the threshold: vertical cracks, several fragments."""
    mesh = grid_mesh(6, 4)
    res = fracture.split_by_tensor(mesh, np.tile([1.0, 0.0, 0.0], (mesh.nv, 1)), 0.5)
    assert res.nfragments > 2 and len(res.crack_segments) > 0
    return res


def displacement(res, step=1):
    """Stretch plus a rigid shift per fragment, so the pieces separate (1e-3 x is not exact in float32)."""
    X = coords(res.mesh)
    T = res.mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3].astype(np.int64) - 1
    vfrag = np.zeros(res.mesh.nv, dtype=int)
    vfrag[T.ravel()] = np.repeat(res.fragment, 3)
    U = np.column_stack([1e-3 * X[:, 0] + 0.3 * vfrag, 1e-3 / 3 * X[:, 1]])
    return step * U


def read_pvd(path):
    return [(float(d.get("timestep")), d.get("file")) for d in ET.parse(path).getroot().iter("DataSet")]


def n_crack_segments(mesh):
    names = mesh.GetBoundaries()
    idx = mesh.ngmesh.Elements1D().NumPy()["index"]
    return int(sum(names[i - 1] == "crack" for i in idx))


def write_series(folder, res, steps=(0, 1, 2), **kw):
    w = output.TimeSeriesWriter(folder, **kw)
    for k in steps:
        w.write(k, 0.25 * k + 0.1, res.mesh, displacement(res, k), fragment=res.fragment)
    return w


def test_vertex_arrays(cracked):
    a = output.vertex_arrays(cracked.mesh)
    assert a.points.shape == (cracked.mesh.nv, 2) and a.triangles.shape == (cracked.mesh.ne, 3)
    assert a.region_names == ["solid"] and np.all(a.regions == 1)   # 1-based (meshio.MeshArrays)
    cs = a.boundary_segments("crack")
    assert len(cs) == n_crack_segments(cracked.mesh) == len(cracked.crack_segments)
    # the same oriented segments as the crack engine reported
    assert set(map(tuple, cs.tolist())) == set(map(tuple, cracked.crack_segments.tolist()))
    assert len(a.boundary_segments("no such boundary")) == 0


def test_series_round_trip(cracked, tmp_path):
    res, mesh = cracked, cracked.mesh
    write_series(tmp_path, res)
    entries = read_pvd(tmp_path / "results.pvd")
    assert entries == [(0.1, "step_000000.vtu"), (0.35, "step_000001.vtu"), (0.6, "step_000002.vtu")]
    assert [f for _, f in read_pvd(tmp_path / "cracks.pvd")] == [f"cracks_00000{k}.vtp" for k in range(3)]
    for t, f in entries:
        assert (tmp_path / f).exists()
    g = pv.read(tmp_path / "step_000002.vtu")
    assert g.n_points == mesh.nv and g.n_cells == mesh.ne
    assert np.all(g.celltypes == pv.CellType.TRIANGLE)
    U = displacement(res, 2)
    d = g.point_data["displacement"]
    assert d.dtype == np.float64 and np.array_equal(d[:, :2], U) and np.all(d[:, 2] == 0)
    assert np.array_equal(g.points[:, :2], coords(mesh)) and np.all(g.points[:, 2] == 0)
    T = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3].astype(np.int64) - 1
    assert np.array_equal(g.cells.reshape(-1, 4)[:, 1:], T)
    assert np.array_equal(g.cell_data["fragment"], res.fragment)
    assert np.all(g.cell_data["region"] == 0) and list(g.field_data["region_names"]) == ["solid"]
    # a uniform stretch within each fragment: exact element strain, principal along x
    exx = 2e-3 + 0.5 * (2e-3) ** 2
    assert np.allclose(g.cell_data["strain"][:, 0], exx, rtol=1e-12, atol=0)
    assert np.allclose(g.cell_data["principal_strain"], exx, rtol=1e-12, atol=0)
    assert np.allclose(np.abs(g.cell_data["principal_direction"]), [1, 0, 0], atol=1e-12)
    assert g.point_data["nodal_strain"].shape == (mesh.nv, 9)
    c = pv.read(tmp_path / "cracks_000002.vtp")
    assert c.n_cells == n_crack_segments(mesh) == len(res.crack_segments)
    assert c.n_verts == 0 and c.n_lines == c.n_cells
    assert np.array_equal(c.point_data["displacement"][:, :2], U[c.point_data["vertex"]])


@pytest.mark.parametrize("compression", ["lz4", "zlib", "lzma", None])
def test_every_compression_reads_back_as_to_pyvista(cracked, tmp_path, compression):
    """The files hold exactly the arrays of to_pyvista, whatever the (lossless) compression."""
    res = cracked
    write_series(tmp_path, res, steps=(1,), compression=compression)
    g = pv.read(tmp_path / "step_000001.vtu")
    ref = output.to_pyvista(res.mesh, displacement(res, 1), fragment=res.fragment)
    for data, expected in ((g.point_data, ref.point_data), (g.cell_data, ref.cell_data)):
        assert list(data) == list(expected)
        for name in expected:
            assert np.array_equal(data[name], expected[name]), name
    assert g.point_data.active_scalars_name == "displacement" and g.cell_data.active_scalars_name == "region"


def test_unknown_compression_refused_before_any_file(tmp_path):
    with pytest.raises(ValueError, match="compression must be one of.*'gzip'"):
        output.TimeSeriesWriter(tmp_path / "out", compression="gzip")
    assert not (tmp_path / "out").exists()


def test_uncracked_mesh_writes_empty_crack_file(tmp_path):
    mesh = grid_mesh(2, 2)
    output.TimeSeriesWriter(tmp_path).write(0, 0.0, mesh, np.zeros((mesh.nv, 2)))
    c = pv.read(tmp_path / "cracks_000000.vtp")
    assert c.n_cells == 0 and c.n_points == 0


def test_refuses_existing_results_and_force_removes_only_own(cracked, tmp_path):
    write_series(tmp_path, cracked)
    (tmp_path / "notes.txt").write_text("keep me")
    with pytest.raises(FileExistsError, match="already holds results"):
        output.TimeSeriesWriter(tmp_path)
    w = output.TimeSeriesWriter(tmp_path, force=True)
    assert sorted(os.listdir(tmp_path)) == ["notes.txt"]
    assert w.steps == []
    with pytest.raises(ValueError, match="choose one"):
        output.TimeSeriesWriter(tmp_path, force=True, resume=True)


def test_steps_must_increase(cracked, tmp_path):
    w = write_series(tmp_path, cracked, steps=(0, 1))
    before = (tmp_path / "step_000001.vtu").read_bytes()
    with pytest.raises(ValueError, match="not after the last written step 1"):
        w.write(1, 9.0, cracked.mesh, displacement(cracked, 5))
    assert (tmp_path / "step_000001.vtu").read_bytes() == before
    with pytest.raises(ValueError, match="finite"):
        w.write(2, float("nan"), cracked.mesh)


def test_resume(cracked, tmp_path):
    write_series(tmp_path, cracked)
    (tmp_path / ".tmp_ngf_killed.vtu").write_bytes(b"half a file")     # a run killed mid-write
    w = output.TimeSeriesWriter(tmp_path, resume=True, last_step=1)
    assert not (tmp_path / ".tmp_ngf_killed.vtu").exists()
    assert w.steps == [(0, 0.1), (1, 0.35)]
    assert not (tmp_path / "step_000002.vtu").exists() and not (tmp_path / "cracks_000002.vtp").exists()
    assert [f for _, f in read_pvd(tmp_path / "results.pvd")] == ["step_000000.vtu", "step_000001.vtu"]
    w.write(2, 0.7, cracked.mesh, displacement(cracked, 7), fragment=cracked.fragment)
    w.write(3, 0.9, cracked.mesh, displacement(cracked, 8), fragment=cracked.fragment)
    assert read_pvd(tmp_path / "results.pvd") == [(0.1, "step_000000.vtu"), (0.35, "step_000001.vtu"),
                                                  (0.7, "step_000002.vtu"), (0.9, "step_000003.vtu")]
    g = pv.read(tmp_path / "step_000002.vtu")
    assert np.array_equal(g.point_data["displacement"][:, :2], displacement(cracked, 7))
    # resume without last_step keeps everything
    assert output.TimeSeriesWriter(tmp_path, resume=True).steps[-1] == (3, 0.9)
    # a listed file that vanished is an error, not a silent gap
    os.unlink(tmp_path / "step_000001.vtu")
    with pytest.raises(FileNotFoundError, match="step_000001.vtu is missing"):
        output.TimeSeriesWriter(tmp_path, resume=True)
    with pytest.raises(FileNotFoundError, match="nothing to resume"):
        output.TimeSeriesWriter(tmp_path / "empty", resume=True)


def test_to_pyvista_checks_lengths(cracked):
    with pytest.raises(ValueError, match=f"fragment must be {cracked.mesh.ne} integers"):
        output.to_pyvista(cracked.mesh, fragment=np.zeros(3, dtype=int))
    with pytest.raises(ValueError, match="'stress' has shape"):
        output.to_pyvista(cracked.mesh, cell_data={"stress": np.zeros(5)})
    with pytest.raises(ValueError, match="vertex values"):
        output.to_pyvista(cracked.mesh, u=np.zeros((4, 2)))


def test_two_regions_and_gridfunction(tmp_path):
    from conftest import two_region_bar_mesh
    mesh = two_region_bar_mesh(0.5)
    gf = ngsolve.GridFunction(ngsolve.VectorH1(mesh, order=2))
    gf.Set(ngsolve.CF((0.01 * ngsolve.x, 0)))
    g = output.to_pyvista(mesh, gf)
    idx = mesh.ngmesh.Elements2D().NumPy()["index"] - 1
    assert np.array_equal(g.cell_data["region"], idx)
    assert list(g.field_data["region_names"]) == list(mesh.GetMaterials()) == ["soft", "stiff"]
    assert np.allclose(g.point_data["displacement"][:, 0], 0.01 * g.points[:, 0], atol=1e-15)
    assert np.allclose(g.cell_data["strain"][:, 0], 0.01 + 0.5e-4, rtol=1e-12)


def test_summary(tmp_path):
    p = tmp_path / "summary.json"
    s = {"fragments": np.int64(7), "areas": np.array([0.5, 0.25]), "ok": np.bool_(True),
         "nested": {"t": np.float32(0.5), "path": tmp_path}, "name": "run"}
    output.write_json(p, s)
    back = json.loads(p.read_text())
    assert back == {"fragments": 7, "areas": [0.5, 0.25], "ok": True,
                    "nested": {"t": 0.5, "path": str(tmp_path)}, "name": "run"}
    with pytest.raises(FileExistsError, match="force=True"):
        output.write_json(p, {"other": 1})
    assert json.loads(p.read_text())["fragments"] == 7
    output.write_json(p, {"other": 1}, force=True)
    assert json.loads(p.read_text()) == {"other": 1}
    with pytest.raises(ValueError, match=r"bad.json\['x'\]\[1\] is nan"):
        output.write_json(tmp_path / "bad.json", {"x": [1.0, float("nan")]})
    with pytest.raises(TypeError, match=r"bad.json\['f'\] is a builtin_function"):
        output.write_json(tmp_path / "bad.json", {"f": len})
    assert not (tmp_path / "bad.json").exists()
    assert sorted(os.listdir(tmp_path)) == ["summary.json"]      # no temp files left


def png_size(path):
    data = open(path, "rb").read(24)
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_render_png(cracked, tmp_path):
    # no skip: a machine that cannot render headless must fail here with the reason
    p = tmp_path / "frag.png"
    output.render_png(cracked.mesh, displacement(cracked), cracked.fragment, p, window_size=(320, 240))
    assert png_size(p) == (320, 240)
    import matplotlib.image
    img = matplotlib.image.imread(p)
    assert img.shape[:2] == (240, 320)
    assert img[..., :3].reshape(-1, 3).var(axis=0).sum() > 0
    # several fragment colours besides the white background and the black lines
    colours = np.unique((img[..., :3] * 255).round().astype(int).reshape(-1, 3), axis=0)
    assert len(colours) >= 4
    with pytest.raises(FileExistsError):
        output.render_png(cracked.mesh, None, cracked.fragment, p)
    assert sorted(os.listdir(tmp_path)) == ["frag.png"]


def test_render_png_needs_no_display_or_opengl(monkeypatch, tmp_path, cracked):
    """A bare headless machine (no display, no OpenGL libraries) still gets its picture."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    p = output.render_png(cracked.mesh, None, cracked.fragment, tmp_path / "x.png", window_size=(200, 100))
    assert png_size(p) == (200, 100)


def test_render_failure_is_named_and_leaves_no_file(monkeypatch, tmp_path, cracked):
    import PIL.Image

    def broken(self, *args, **kwargs):
        raise OSError("disk full")
    monkeypatch.setattr(PIL.Image.Image, "save", broken)
    with pytest.raises(output.RenderError, match="x.png.*OSError: disk full"):
        output.render_png(cracked.mesh, None, cracked.fragment, tmp_path / "x.png")
    assert os.listdir(tmp_path) == []
    with pytest.raises(ValueError, match="fragment numbers"):
        output.render_png(cracked.mesh, None, cracked.fragment[:-1], tmp_path / "x.png")


def test_plot_fragment_sizes(tmp_path):
    p = output.plot_fragment_sizes([0.5, 0.01, 0.02, 1e-4, 0.3], tmp_path / "sizes.png")
    assert png_size(p)[0] > 100
    output.plot_fragment_sizes([2.0], tmp_path / "one.png")     # a single size still plots
    with pytest.raises(ValueError, match="finite and > 0"):
        output.plot_fragment_sizes([1.0, 0.0], tmp_path / "bad.png")
    with pytest.raises(FileExistsError):
        output.plot_fragment_sizes([1.0], p)


def test_fragment_statistics(cracked):
    mesh = cracked.mesh
    st = FragmentStatistics(mesh, cracked.fragment)
    assert st.count == cracked.nfragments
    domain = ngsolve.Integrate(1, mesh)
    assert abs(math.fsum(st.areas) - domain) <= 1e-14 * domain
    assert st.total_area == 24.0                       # 6 x 4 grid of unit cells, exact
    assert np.array_equal(fragment_ids(mesh), cracked.fragment)
    # fragments are full columns: centroids at y = 2, areas sum per column
    assert np.allclose(st.centroids[:, 1], 2.0, rtol=0, atol=1e-14)
    assert st.ntriangles.sum() == mesh.ne
    U = displacement(cracked)
    st2 = FragmentStatistics(mesh, cracked.fragment, u=U)
    moved = st2.deformed_centroids - st2.centroids
    assert np.allclose(moved[:, 0], 1e-3 * st.centroids[:, 0] + 0.3 * st.ids, atol=1e-14)
    with pytest.raises(ValueError, match="one per triangle"):
        FragmentStatistics(mesh, cracked.fragment[:-1])


def test_single_triangle_fragment():
    # a unit square (two triangles) and a lone triangle of area 1/2 far away
    P = [(0, 0), (1, 0), (1, 1), (0, 1), (3, 0), (4, 0), (3, 1)]
    mesh = mesh_from_arrays(P, [[0, 1, 2], [0, 2, 3], [4, 5, 6]])
    st = FragmentStatistics(mesh)
    assert st.count == 2
    assert list(st.areas) == [1.0, 0.5] and list(st.ntriangles) == [2, 1]
    assert np.allclose(st.centroids[1], [10 / 3, 1 / 3], rtol=0, atol=1e-15)
    assert st.total_area == 1.5 and st.summary()["single_triangle_fragments"] == 1
    # labels need not be consecutive
    st = FragmentStatistics(mesh, np.array([7, 7, 3]))
    assert list(st.ids) == [3, 7] and list(st.areas) == [0.5, 1.0]


def test_fragment_size_bins_hold_every_fragment():
    """The histogram counts every fragment: np.logspace's end points can miss the smallest
    or largest area by a rounding (before: one random set in three lost a fragment)."""
    rng = np.random.default_rng(7)
    for _ in range(1000):
        A = 10.0 ** rng.uniform(-8, 0, rng.integers(1, 200))
        counts, _ = np.histogram(A, output.fragment_size_bins(A))
        assert counts.sum() == A.size
