"""Writing results: VTK time series for ParaView/PyVista, PNG pictures, plots, JSON summaries.

    writer = TimeSeriesWriter("out/run")                       # refuses a folder with results
    writer.write(step, load, mesh, u, fragment=result.fragment)   # step_000012.vtu + cracks_000012.vtp
    render_png(mesh, u, result.fragment, "out/run/final.png")
    write_summary("out/run/summary.json", {"fragments": stats.count})

Files of a :class:`TimeSeriesWriter` folder
-------------------------------------------
``step_NNNNNN.vtu``
    The mesh with shared vertices (one VTK point per mesh vertex, z = 0), reference
    coordinates. Point data ``displacement`` (3-vector, z = 0: ParaView's *Warp By Vector*
    gives the deformed configuration) and, with a strain measure, ``nodal_strain`` (the
    crack criterion's vertex tensor), ``nodal_principal_strain``, ``nodal_principal_direction``.
    Cell data ``region`` (0-based material region; names in the field data
    ``region_names``), ``fragment``, ``strain`` (3x3 tensor, in-plane components, zz = 0),
    ``principal_strain`` and ``principal_direction`` (unit 3-vector, z = 0).
``cracks_NNNNNN.vtp``
    The crack faces as line cells (the boundary segments named ``crack``), with their own
    copy of the vertices and their ``displacement``, so the same *Warp By Vector* applies.
    A separate file rather than line cells in the .vtu: mixed cells would break cell data
    (every line would need a fragment and a strain) and filters like *Threshold*.
``results.pvd``, ``cracks.pvd``
    Collections listing the steps with time = load parameter; open these in ParaView
    (File > Open) or ``pyvista.get_reader``. Rewritten atomically after every step.

Strains are those of the P1 interpolant of the vertex displacements (element-wise constant,
Green-Lagrange by default), the same quantity the crack criterion averages at the vertices.
"""
import io
import json
import math
import os
import re
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..fracture import crack
from . import vtkxml
from ..geometry.meshio import mesh_to_arrays
from ..mechanics.problem import check_mesh

__all__ = ["vertex_arrays", "element_strain", "to_pyvista", "cracks_to_pyvista",
           "TimeSeriesWriter", "RenderError", "render_png", "plot_fragment_sizes", "final_pictures",
           "SIZES_MIN_FRAGMENTS", "write_summary"]


# -- arrays ---------------------------------------------------------------------------------

def vertex_arrays(mesh):
    """Reference coordinates, triangles, regions and named boundary segments of a mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh.

    Returns
    -------
    ngfracture.geometry.meshio.MeshArrays
        Regions and boundary numbers are 1-based into their name lists; crack faces are
        ``arrays.boundary_segments("crack")``.

    Raises
    ------
    ValueError
        Not a 2D NGSolve triangle mesh.
    """
    check_mesh(mesh)
    return mesh_to_arrays(mesh)


def _displacement(mesh, u):
    U = crack.vertex_displacement(u)
    if U.shape != (mesh.nv, 2):
        raise ValueError(f"ngfracture.output.vtk: displacement has {U.shape[0]} vertex values, "
                         f"the mesh has {mesh.nv} vertices")
    if not np.all(np.isfinite(U)):
        raise ValueError("ngfracture.output.vtk: displacement has NaN or inf values")
    return U


def _pad3(a):
    return np.column_stack([a, np.zeros(len(a))])


def element_strain(mesh, u, measure="green", arrays=None):
    """Strain of the P1 interpolant of the vertex displacements, one tensor per triangle.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement (``VectorH1``) or vertex values (nv, 2).
    measure : {'green', 'linear'}
        (H + H^T + H^T H)/2 or (H + H^T)/2 with H = grad u.
    arrays : MeshArrays, optional
        Reuse arrays already extracted with :func:`vertex_arrays`.

    Returns
    -------
    numpy.ndarray
        (ne, 3), rows (xx, yy, xy), xy the tensor shear.

    Raises
    ------
    ValueError
        Unknown measure, or a displacement that does not fit the mesh.
    """
    if measure not in ("green", "linear"):
        raise ValueError(f"ngfracture.output.vtk: measure must be 'green' or 'linear', got {measure!r}")
    a = arrays if arrays is not None else vertex_arrays(mesh)
    U = _displacement(mesh, u)
    X, T = a.points, a.triangles
    D = np.stack([X[T[:, 1]] - X[T[:, 0]], X[T[:, 2]] - X[T[:, 0]]], axis=2)   # columns: edges
    DU = np.stack([U[T[:, 1]] - U[T[:, 0]], U[T[:, 2]] - U[T[:, 0]]], axis=2)
    # H D = DU  <=>  D^T H^T = DU^T
    H = np.linalg.solve(np.transpose(D, (0, 2, 1)), np.transpose(DU, (0, 2, 1))).transpose(0, 2, 1)
    E = 0.5 * (H + np.transpose(H, (0, 2, 1)))
    if measure == "green":
        E = E + 0.5 * np.einsum("eki,ekj->eij", H, H)
    return np.column_stack([E[:, 0, 0], E[:, 1, 1], E[:, 0, 1]])


def _tensor9(t):
    """(n, 3) rows (xx, yy, xy) as VTK's 9-component tensors (zz = 0)."""
    out = np.zeros((len(t), 9))
    out[:, 0], out[:, 4], out[:, 1], out[:, 3] = t[:, 0], t[:, 1], t[:, 2], t[:, 2]
    return out


def _add_user_data(data, extra, n, where):
    for name, values in (extra or {}).items():
        v = np.asarray(values)
        if v.shape[:1] != (n,):
            raise ValueError(f"ngfracture.output.vtk: {where} array {name!r} has shape {v.shape}, "
                             f"expected {n} rows")
        data[name] = v


def to_pyvista(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None,
               arrays=None):
    """The mesh as a shared-vertex ``pyvista.UnstructuredGrid`` with result fields.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray, optional
        Displacement; point data ``displacement`` as 3-vectors (z = 0), float64.
    fragment : array_like of int, optional
        Fragment id per triangle (cell data ``fragment``).
    strain : {'green', 'linear', None}
        Strain measure for the strain fields (needs ``u``); None writes none.
    point_data, cell_data : dict of str -> array_like, optional
        Further arrays (nv or ne rows), e.g. a stress evaluated by the caller.
    arrays : MeshArrays, optional
        Reuse arrays already extracted with :func:`vertex_arrays`.

    Returns
    -------
    pyvista.UnstructuredGrid
        Points (nv, 3) with z = 0, one VTK_TRIANGLE per element in element order. Field
        data ``region_names``. See the module docstring for the arrays.

    Raises
    ------
    ValueError
        Arrays whose length does not fit the mesh, non-finite displacement.
    """
    import pyvista as pv
    return pv.wrap(_vtk_mesh(mesh, u, fragment, strain, point_data, cell_data, arrays))


def _vtk_mesh(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None, arrays=None):
    """The vtkUnstructuredGrid of :func:`to_pyvista` (plain VTK, without pyvista)."""
    a, points, cells = _mesh_fields(mesh, u, fragment, strain, point_data, cell_data, arrays)
    from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
    grid = vtkUnstructuredGrid()
    _fill_vtk(grid, a.points, a.triangles, points, cells, _region_names(a))
    return grid


def _region_names(a):
    return a.region_names if a.region_names else [""]


def _mesh_fields(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None, arrays=None):
    """The mesh arrays and the point and cell arrays of :func:`to_pyvista`, checked."""
    a = arrays if arrays is not None else vertex_arrays(mesh)
    ne, nv = len(a.triangles), len(a.points)
    cells, points = {}, {}
    cells["region"] = a.regions - 1     # 0-based index into region_names
    if fragment is not None:
        f = np.asarray(fragment)
        if f.shape != (ne,) or not np.issubdtype(f.dtype, np.integer):
            raise ValueError(f"ngfracture.output.vtk: fragment must be {ne} integers (one per "
                             f"triangle), got shape {f.shape} dtype {f.dtype}")
        cells["fragment"] = f
    if u is not None:
        U = _displacement(mesh, u)
        points["displacement"] = _pad3(U)
        if strain is not None:
            E = element_strain(mesh, U, strain, a)
            val, d = crack.principal(E)
            cells["strain"] = _tensor9(E)
            cells["principal_strain"] = val
            cells["principal_direction"] = _pad3(d)
            En = crack.vertex_strain(mesh, U, strain)
            val, d = crack.principal(En)
            points["nodal_strain"] = _tensor9(En)
            points["nodal_principal_strain"] = val
            points["nodal_principal_direction"] = _pad3(d)
    _add_user_data(points, point_data, nv, "point_data")
    _add_user_data(cells, cell_data, ne, "cell_data")
    return a, points, cells


def _fill_vtk(data, points, cells, point_data, cell_data, region_names=None):
    """Points (z = 0), cells of one kind (triangles: 3 columns, lines: 2), arrays and the
    field data ``region_names`` into a vtkUnstructuredGrid or vtkPolyData. The first point
    and cell arrays are the active scalars (what ParaView colours by at first)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import VTK_ID_TYPE, vtkPoints, vtkStringArray
    from vtkmodules.vtkCommonDataModel import VTK_TRIANGLE, vtkCellArray

    def array(name, values):
        v = np.ascontiguousarray(values)
        arr = numpy_to_vtk(v.astype(np.uint8) if v.dtype == bool else v, deep=True)
        arr.SetName(name)
        return arr

    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(_pad3(points), dtype=np.float64), deep=True))
    data.SetPoints(pts)
    corners = cells.shape[1]
    offsets = np.arange(0, corners * len(cells) + 1, corners, dtype=np.int64)
    cell_array = vtkCellArray()
    cell_array.SetData(numpy_to_vtk(offsets, deep=True, array_type=VTK_ID_TYPE),
                       numpy_to_vtk(np.ascontiguousarray(cells, dtype=np.int64).ravel(), deep=True,
                                    array_type=VTK_ID_TYPE))
    if corners == 3:
        data.SetCells(VTK_TRIANGLE, cell_array)
    else:
        data.SetLines(cell_array)
    for attributes, arrays in ((data.GetPointData(), point_data), (data.GetCellData(), cell_data)):
        for i, (name, values) in enumerate(arrays.items()):
            attributes.AddArray(array(name, values))
            if i == 0:
                attributes.SetActiveScalars(name)
    if region_names is not None:
        names = vtkStringArray()
        names.SetName("region_names")
        for n in region_names:
            names.InsertNextValue(n)
        data.GetFieldData().AddArray(names)


def cracks_to_pyvista(mesh, u=None, boundary="crack", arrays=None):
    """The crack faces (boundary segments named ``boundary``) as line cells.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray, optional
        Displacement; point data ``displacement`` (3-vectors, z = 0).
    boundary : str
        Boundary name of the crack faces.
    arrays : MeshArrays, optional
        Reuse arrays already extracted with :func:`vertex_arrays`.

    Returns
    -------
    pyvista.PolyData
        One line per segment (both faces of a crack: two lines on the same reference
        points); only the vertices on those segments, their mesh numbers in point data
        ``vertex``. Empty (no points, no lines) when nothing has cracked.

    Raises
    ------
    ValueError
        Not a 2D triangle mesh, or a displacement that does not fit it.
    """
    import pyvista as pv
    return pv.wrap(_vtk_cracks(mesh, u, boundary, arrays))


def _vtk_cracks(mesh, u=None, boundary="crack", arrays=None):
    """The vtkPolyData of :func:`cracks_to_pyvista` (plain VTK, see :func:`_vtk_mesh`)."""
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    poly = vtkPolyData()
    points, lines, point_data = _crack_fields(mesh, u, boundary, arrays)
    if len(lines):
        _fill_vtk(poly, points, lines, point_data, {})
    return poly


def _crack_fields(mesh, u=None, boundary="crack", arrays=None):
    """The crack faces' points, their segments in the points' numbering, and point data."""
    a = arrays if arrays is not None else vertex_arrays(mesh)
    seg = a.boundary_segments(boundary)
    if len(seg) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64), {}
    used, local = np.unique(seg, return_inverse=True)
    points = {"vertex": used}
    if u is not None:
        points["displacement"] = _pad3(_displacement(mesh, u)[used])
    return a.points[used], local.reshape(seg.shape), points


# -- atomic files ---------------------------------------------------------------------------

def _fsync_dir(folder):
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _atomic_bytes(path, data, force, sync=True):
    """Write bytes to path through a temp file in its folder; refuse an existing path unless
    force. ``sync``: the file and the folder are synced (False for a time series' step
    files: the collection written after them syncs the folder)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=".tmp_ngf_", suffix=path.suffix, dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            if sync:
                fh.flush()
                os.fsync(fh.fileno())
        _publish(tmp, path, force, sync)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _publish(tmp, path, force, sync=True):
    """Rename tmp to path; without force, a link that fails if path exists (no race)."""
    if force:
        os.replace(tmp, path)
    else:
        try:
            os.link(tmp, path)
        except FileExistsError:
            raise FileExistsError(f"ngfracture.output.vtk: {path} exists; pass force=True to overwrite it") from None
        os.unlink(tmp)
    if sync:
        _fsync_dir(Path(path).parent)


#: compressions of the binary VTK arrays: lz4 through VTK's writer (its setter, used by
#: _save_vtk), the others written by :mod:`ngfracture.output.vtkxml` (no VTK import, no setter)
_COMPRESSIONS = {"lz4": "SetCompressorTypeToLZ4", "zlib": None, "lzma": None, None: None}


def _save_vtk(obj, path, compression):
    """Save a vtkUnstructuredGrid (.vtu) or vtkPolyData (.vtp), binary, through a temp
    file in the same folder, then rename."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter
    path = Path(path)
    writer = vtkXMLUnstructuredGridWriter() if path.suffix == ".vtu" else vtkXMLPolyDataWriter()
    writer.SetDataModeToBinary()
    getattr(writer, _COMPRESSIONS[compression])()
    writer.SetInputData(obj)
    fd, tmp = tempfile.mkstemp(prefix=".tmp_ngf_", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        writer.SetFileName(tmp)
        if writer.Write() != 1:
            raise OSError(f"ngfracture.output.vtk: VTK could not write {path.name}")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# -- time series ----------------------------------------------------------------------------

class TimeSeriesWriter:
    """VTK files per step plus ``.pvd`` collections (time = load parameter) in one folder.

    Parameters
    ----------
    folder : str or pathlib.Path
        Created if missing.
    force : bool
        If the folder already holds results of a writer, delete them (only the files this
        class writes: ``step_*.vtu``, ``cracks_*.vtp``, ``results.pvd``, ``cracks.pvd``,
        ``.tmp_ngf_*``) instead of refusing.
    resume : bool
        Continue the series in the folder: keep the steps up to ``last_step`` (all if None),
        delete this writer's files of later steps, continue the collections.
    last_step : int, optional
        With ``resume``: the last step to keep (e.g. the step of the checkpoint resumed from).
    compression : {'zlib', 'lzma', 'lz4', None}
        Compression of the binary VTK arrays (lossless). zlib (level 1) by default, written
        by :mod:`ngfracture.output.vtkxml` without importing VTK; lzma for the smallest files; lz4
        goes through VTK's writer (ParaView >= 5.5 reads it); None writes the raw bytes.

    Attributes
    ----------
    steps : list of (int, float)
        (step, time) of every step in the collection.

    Raises
    ------
    FileExistsError
        The folder holds results and neither ``force`` nor ``resume`` is given.
    FileNotFoundError
        ``resume`` on a folder without ``results.pvd``, or a step file it lists is missing.
    ValueError
        ``force`` together with ``resume``; ``last_step`` without ``resume``; an unknown
        ``compression``; with
        ``resume``, a ``results.pvd`` that is not valid XML or lists foreign files.
    """

    PVD = "results.pvd"
    CRACK_PVD = "cracks.pvd"
    _OWN = re.compile(r"^(step_\d{6}\.vtu|cracks_\d{6}\.vtp|results\.pvd|cracks\.pvd|\.tmp_ngf_.*)$")
    _STEP = re.compile(r"^(?:step_(\d{6})\.vtu|cracks_(\d{6})\.vtp)$")

    def __init__(self, folder, force=False, resume=False, last_step=None, compression="zlib"):
        if force and resume:
            raise ValueError("TimeSeriesWriter: force=True deletes results, resume=True keeps them; choose one")
        if last_step is not None and not resume:
            raise ValueError("TimeSeriesWriter: last_step is only meaningful with resume=True")
        if compression not in _COMPRESSIONS:
            raise ValueError(f"TimeSeriesWriter: compression must be one of {list(_COMPRESSIONS)}, got {compression!r}")
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.compression = compression
        self.steps = []
        own = sorted(p for p in os.listdir(self.folder) if self._OWN.match(p))
        if resume:
            self._resume(own, last_step)
        elif own:
            if not force:
                raise FileExistsError(
                    f"TimeSeriesWriter: {self.folder} already holds results ({own[0]}, {len(own)} "
                    "file(s)); pass force=True to delete them or resume=True to continue")
            for name in own:
                os.unlink(self.folder / name)
            _fsync_dir(self.folder)

    def _resume(self, own, last_step):
        pvd = self.folder / self.PVD
        if not pvd.exists():
            raise FileNotFoundError(f"TimeSeriesWriter: nothing to resume, {pvd} does not exist")
        for step, time, _ in self._read_pvd(pvd):
            if last_step is None or step <= last_step:
                for name in (self._name(step), self._crack_name(step)):
                    if not (self.folder / name).exists():
                        raise FileNotFoundError(f"TimeSeriesWriter: {pvd} lists step {step} but "
                                                f"{self.folder / name} is missing")
                self.steps.append((step, time))
        keep = {s for s, _ in self.steps}
        for name in own:
            m = self._STEP.match(name)
            # later steps (and temp files of a killed run) go; the collections are rewritten
            if (m and int(m.group(1) or m.group(2)) not in keep) or name.startswith(".tmp_ngf_"):
                os.unlink(self.folder / name)
        self._write_collections()

    def _read_pvd(self, pvd):
        try:
            root = ET.parse(pvd).getroot()
        except ET.ParseError as e:
            raise ValueError(f"TimeSeriesWriter: {pvd} is not valid XML ({e})") from None
        out = []
        for ds in root.iter("DataSet"):
            m = re.match(r"^step_(\d{6})\.vtu$", ds.get("file", ""))
            if not m:
                raise ValueError(f"TimeSeriesWriter: {pvd} lists {ds.get('file')!r}, not a file of this writer")
            out.append((int(m.group(1)), float(ds.get("timestep")), ds.get("file")))
        return out

    @staticmethod
    def _name(step):
        return f"step_{step:06d}.vtu"

    @staticmethod
    def _crack_name(step):
        return f"cracks_{step:06d}.vtp"

    def _collection(self, name_of):
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
                 "  <Collection>"]
        # repr: the shortest string that reads back as the same float
        lines += [f'    <DataSet timestep="{t!r}" group="" part="0" file="{name_of(s)}"/>'
                  for s, t in self.steps]
        lines += ["  </Collection>", "</VTKFile>", ""]
        return "\n".join(lines).encode()

    def _write_collections(self):
        _atomic_bytes(self.folder / self.PVD, self._collection(self._name), force=True)
        _atomic_bytes(self.folder / self.CRACK_PVD, self._collection(self._crack_name), force=True)

    def write(self, step, time, mesh, u=None, fragment=None, strain="green", point_data=None,
              cell_data=None, crack_boundary="crack"):
        """Write one step and update the collections.

        Parameters
        ----------
        step : int
            Step number (>= 0), larger than every step already written.
        time : float
            The load parameter: the time value in the collections.
        mesh, u, fragment, strain, point_data, cell_data
            As for :func:`to_pyvista`.
        crack_boundary : str
            Boundary name of the crack faces.

        Returns
        -------
        (pathlib.Path, pathlib.Path)
            The .vtu and .vtp written.

        Raises
        ------
        ValueError
            A step not larger than the last one (it would overwrite), a step beyond 6
            digits, a non-finite time, or arrays that do not fit the mesh.
        FileExistsError
            A file of this step exists although the collection does not list it.
        """
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)) or not 0 <= step <= 999999:
            raise ValueError(f"TimeSeriesWriter.write: step must be an integer in [0, 999999], got {step!r}")
        step = int(step)
        if self.steps and step <= self.steps[-1][0]:
            raise ValueError(f"TimeSeriesWriter.write: step {step} is not after the last written "
                             f"step {self.steps[-1][0]}; steps must increase (no silent overwrite)")
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"TimeSeriesWriter.write: time must be finite, got {time!r}")
        a = vertex_arrays(mesh)
        vtu, vtp = self.folder / self._name(step), self.folder / self._crack_name(step)
        for p in (vtu, vtp):
            if p.exists():   # a file the collection does not list: never overwrite it silently
                raise FileExistsError(f"TimeSeriesWriter.write: {p} exists but is not in the collection")
        if self.compression == "lz4":
            _save_vtk(_vtk_mesh(mesh, u, fragment, strain, point_data, cell_data, arrays=a), vtu,
                      self.compression)
            _save_vtk(_vtk_cracks(mesh, u, crack_boundary, arrays=a), vtp, self.compression)
        else:
            _, points, cells = _mesh_fields(mesh, u, fragment, strain, point_data, cell_data, arrays=a)
            grid = vtkxml.unstructured_grid(a.points, a.triangles, points, cells,
                                            {"region_names": _region_names(a)}, self.compression)
            _atomic_bytes(vtu, grid, force=True, sync=False)
            lines = vtkxml.poly_lines(*_crack_fields(mesh, u, crack_boundary, a), self.compression)
            _atomic_bytes(vtp, lines, force=True, sync=False)
        self.steps.append((step, time))
        self._write_collections()
        return vtu, vtp


# -- pictures -------------------------------------------------------------------------------

class RenderError(RuntimeError):
    """A picture could not be drawn; the message says why."""


#: render_png draws at this multiple of the picture's size and reduces (antialiasing)
_SUPERSAMPLING = 2

_FRAGMENT_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                     "#7f7f7f", "#bcbd22", "#17becf", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896",
                     "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7", "#dbdb8d", "#9edae5"]


def picture_scale(points, u):
    """Magnification that shows the largest displacement as 2% of the body's size.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 2)
        Reference coordinates.
    u : numpy.ndarray
        Displacement values (any shape).

    Returns
    -------
    float
        1 when nothing moves.
    """
    size = float(np.ptp(np.asarray(points), axis=0).max())
    umax = float(np.abs(u).max(initial=0.0))
    return 0.02 * size / umax if umax > 0 else 1.0


def render_png(mesh, u, fragment, path, window_size=(1200, 900), scale=1.0, crack_boundary="crack",
               line_width=2.0, force=False):
    """A PNG of the deformed configuration coloured by fragment, crack faces drawn in black.

    Drawn with Pillow as a raster of the triangles (no plotting library, no display, no
    OpenGL; the VTK files are for ParaView and PyVista).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray or None
        Displacement (None: the reference configuration).
    fragment : array_like of int
        Fragment id per triangle; 20 colours, cycled.
    path : str or pathlib.Path
        The PNG file; its folder must exist.
    window_size : (int, int)
        Width and height in pixels.
    scale : float
        Displacement magnification.
    crack_boundary : str
        Boundary name of the crack faces.
    line_width : float
        Width of the crack lines in pixels.
    force : bool
        Overwrite an existing file.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    RenderError
        Pillow failed to draw or encode the picture (the message says how).
    ValueError
        ``fragment`` does not have one entry per triangle, or a bad displacement.
    FileExistsError
        ``path`` exists and not ``force``.
    """
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"render_png: {path} exists; pass force=True to overwrite it")
    a = vertex_arrays(mesh)
    fragment = np.asarray(fragment, dtype=np.int64).ravel()
    if fragment.shape != (len(a.triangles),):
        raise ValueError(f"render_png: {fragment.size} fragment numbers for {len(a.triangles)} triangles")
    U = np.zeros((mesh.nv, 2)) if u is None else _displacement(mesh, u)
    X = a.points + scale * U
    width, height = (int(w) for w in window_size)
    try:
        from PIL import Image, ImageDraw
        # drawn at twice the size and reduced: smooth edges without an antialiasing rasteriser
        ss = _SUPERSAMPLING
        lo, hi = X.min(axis=0), X.max(axis=0)
        span = np.maximum(hi - lo, 1e-300)
        zoom = ss * 0.96 * min(width / span[0], height / span[1])     # 2 % margins, equal aspect
        centre = 0.5 * (lo + hi)
        pixels = np.column_stack([ss * width / 2 + zoom * (X[:, 0] - centre[0]),
                                  ss * height / 2 - zoom * (X[:, 1] - centre[1])])
        image = Image.new("RGB", (ss * width, ss * height), "white")
        draw = ImageDraw.Draw(image)
        colours = [_FRAGMENT_COLOURS[f % len(_FRAGMENT_COLOURS)] for f in fragment.tolist()]
        # outlines in the face colour: no white seams between triangles of one fragment
        for corners, colour in zip(pixels[a.triangles].tolist(), colours):
            draw.polygon([tuple(p) for p in corners], fill=colour, outline=colour)
        pen = max(1, round(ss * line_width))
        for (x0, y0), (x1, y1) in ((pixels[s0], pixels[s1]) for s0, s1 in a.boundary_segments(crack_boundary)):
            draw.line([(x0, y0), (x1, y1)], fill="black", width=pen)
        buf = io.BytesIO()
        image.reduce(ss).save(buf, format="PNG")
    except Exception as e:
        raise RenderError(f"ngfracture.output.vtk: Pillow could not draw {path.name} "
                          f"({type(e).__name__}: {e})") from e
    _atomic_bytes(path, buf.getvalue(), force)
    return path


def fragment_size_bins(areas):
    """Logarithmic bin edges that hold every area: 5 to 50 bins, about sqrt(n).

    Parameters
    ----------
    areas : numpy.ndarray
        Fragment areas, finite and > 0, at least one.

    Returns
    -------
    numpy.ndarray
        Increasing edges; the first is the smallest area and the last the largest exactly
        (``10 ** log10(a)`` can miss ``a`` by a rounding and drop that fragment from the
        histogram: one set in three of random areas lost one), or a bin around a single size.
    """
    lo, hi = float(areas.min()), float(areas.max())
    if hi <= lo * (1 + 1e-12):          # one size only: a bin around it
        lo, hi = lo / 1.5, hi * 1.5
    bins = np.logspace(np.log10(lo), np.log10(hi), max(5, min(50, int(np.sqrt(areas.size)) + 1)))
    bins[0], bins[-1] = lo, hi
    return bins


def plot_fragment_sizes(areas, path, force=False, title="Fragment-size distribution"):
    """Histogram and cumulative distribution of fragment areas (matplotlib, Agg).

    Left: number of fragments per logarithmic area bin. Right: fraction of fragments with
    area >= A (the complementary cumulative distribution). Axes whose values span a decade
    or more are logarithmic.

    Parameters
    ----------
    areas : array_like
        Fragment areas, all finite and > 0 (e.g. ``FragmentStatistics.areas``).
    path : str or pathlib.Path
        Image file (format from the suffix: .png, .pdf, .svg).
    force : bool
        Overwrite an existing file.
    title : str
        Figure title; the number of fragments is appended.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        No areas, or an area that is not finite and positive.
    FileExistsError
        ``path`` exists and not ``force``.
    """
    from matplotlib.figure import Figure   # no pyplot: no global backend, no display
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.ticker import LogFormatter, NullFormatter
    A = np.asarray(areas, dtype=float).ravel()
    if A.size == 0:
        raise ValueError("plot_fragment_sizes: no fragment areas")
    if not np.all(np.isfinite(A) & (A > 0)):
        raise ValueError(f"plot_fragment_sizes: areas must be finite and > 0; {np.sum(~(np.isfinite(A) & (A > 0)))} are not")
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"plot_fragment_sizes: {path} exists; pass force=True to overwrite it")
    bins = fragment_size_bins(A)
    fig = Figure(figsize=(9, 4))
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(1, 2)
    # fixed margins: the constrained layout engine took 2 s of a 20 s plate run
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.13, top=0.88, wspace=0.3)
    ax1.hist(A, bins=bins, color="tab:blue", edgecolor="black", linewidth=0.5)
    ax1.set_xlabel("fragment area")
    ax1.set_ylabel("number of fragments")
    s = np.sort(A)
    fraction = 1.0 - np.arange(A.size) / A.size
    ax2.step(s, fraction, where="post", color="tab:red")
    ax2.set_xlabel("fragment area A")
    ax2.set_ylabel("fraction of fragments with area >= A")
    # log axes where the values span a decade or more, with plain tick labels ("0.001"):
    # matplotlib's default "10^-3" goes through its TeX parser, which took longer than the
    # rest of the figure; a log axis over less than a decade would have no labelled tick
    for ax, which, values in ((ax1, "x", bins), (ax2, "x", s), (ax2, "y", fraction)):
        if values.max() >= 10 * values.min():
            axis = ax.xaxis if which == "x" else ax.yaxis
            ax.set_xscale("log") if which == "x" else ax.set_yscale("log")
            axis.set_major_formatter(LogFormatter())
            axis.set_minor_formatter(NullFormatter())
    fig.suptitle(f"{title} ({A.size} fragments)")
    buf = io.BytesIO()
    fig.savefig(buf, format=path.suffix.lstrip(".") or "png", dpi=120)
    _atomic_bytes(path, buf.getvalue(), force)
    return path


# -- JSON summary ---------------------------------------------------------------------------

def _jsonable(obj, where):
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if isinstance(k, np.generic):
                k = k.item()
            if not isinstance(k, (str, int, float, bool)) and k is not None:
                raise TypeError(f"write_summary: key {where}[{k!r}] is a {type(k).__name__}, not a JSON key")
            out[k] = _jsonable(v, f"{where}[{k!r}]")
        return out
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist(), where)
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, float) and not math.isfinite(obj):
        raise ValueError(f"write_summary: {where} is {obj!r}, which JSON cannot hold")
    if obj is None or isinstance(obj, (str, int, float, bool)):
        return obj
    raise TypeError(f"write_summary: {where} is a {type(obj).__name__}, which JSON cannot hold")


#: fewer fragments than this: no fragment_sizes.png at the end of a run (a distribution of
#: one to four pieces says nothing that summary.json's fragment_areas does not)
SIZES_MIN_FRAGMENTS = 5


def final_pictures(folder, mesh, u, stats, scale, sizes_min_fragments=SIZES_MIN_FRAGMENTS):
    """Draw a run's ``final.png`` and, for enough fragments, ``fragment_sizes.png`` into ``folder``.

    A picture that cannot be drawn is a fact of the output, not a failed run: the returned
    record says why final.png is missing. Both files are replaced; a fragment_sizes.png
    left from before is removed when none is drawn.

    Parameters
    ----------
    folder : path
        The run's output folder.
    mesh, u
        The mesh and displacement, as for :func:`render_png`.
    stats : FragmentStatistics
        Fragment per triangle and fragment areas.
    scale : float
        Displacement magnification (:func:`picture_scale`).
    sizes_min_fragments : int
        Draw fragment_sizes.png from this many fragments on (1: always).

    Returns
    -------
    dict
        ``{"final": "final.png", "displacement_scale": scale}`` or ``{"final_error": reason}``,
        and ``"fragment_sizes": "fragment_sizes.png"`` if drawn (the ``pictures`` of
        summary.json).
    """
    folder = Path(folder)
    try:
        render_png(mesh, u, stats.fragment, folder / "final.png", scale=scale, force=True)
        pictures = {"final": "final.png", "displacement_scale": scale}
    except RenderError as err:
        pictures = {"final_error": str(err)}
    sizes = folder / "fragment_sizes.png"
    if stats.count >= sizes_min_fragments:
        plot_fragment_sizes(stats.areas, sizes, force=True)
        pictures["fragment_sizes"] = sizes.name
    elif sizes.exists():
        sizes.unlink()
    return pictures


def write_summary(path, summary, force=False):
    """Write a dict as JSON atomically (temp file, fsync, rename), numpy types converted.

    Parameters
    ----------
    path : str or pathlib.Path
        The JSON file; its folder must exist.
    summary : dict
        Values: numbers, strings, bools, None, lists, dicts, numpy scalars and arrays,
        paths.
    force : bool
        Overwrite an existing file.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and not ``force`` (also when it appears while writing).
    ValueError
        A NaN or infinite number (named by its key path).
    TypeError
        ``summary`` is not a dict, or a value or key JSON cannot hold (named by its key
        path).
    """
    if not isinstance(summary, dict):
        raise TypeError(f"write_summary: summary must be a dict, got {type(summary).__name__}")
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"write_summary: {path} exists; pass force=True to overwrite it")
    text = json.dumps(_jsonable(summary, "summary"), indent=2, allow_nan=False) + "\n"
    _atomic_bytes(path, text.encode(), force)
    return path
