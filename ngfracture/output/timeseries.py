"""VTK time series for ParaView and PyVista: one file per step and ``.pvd`` collections.

    writer = TimeSeriesWriter("out/run")                       # refuses a folder with results
    writer.write(step, load, mesh, u, fragment=stats.fragment)  # step_000012.vtu + cracks_000012.vtp

Files of a :class:`TimeSeriesWriter` folder
-------------------------------------------
``step_NNNNNN.vtu``
    The mesh, its displacement, strain, regions and fragments (:mod:`ngfracture.output.vtk`;
    tetrahedra of a 3D mesh: :mod:`ngfracture.output.solid_vtk`).
``cracks_NNNNNN.vtp``
    The crack faces with their displacement: line cells in 2D, triangles in 3D.
``results.pvd``, ``cracks.pvd``
    Collections listing the steps with time = load parameter; open these in ParaView
    (File > Open) or ``pyvista.get_reader``. Rewritten atomically after every step.
"""
import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from . import vtkxml
from .atomic import TEMPORARY_PREFIX, fsync_folder, write_bytes, write_file
from .solid_vtk import solid_arrays, solid_crack_fields, solid_fields, vtk_solid_cracks, vtk_solid_mesh
from .vtk import crack_fields, is_tetrahedral, mesh_fields, region_names, vertex_arrays, vtk_cracks, vtk_mesh

__all__ = ["TimeSeriesWriter", "COMPRESSIONS"]


#: compressions of the binary VTK arrays: lz4 through VTK's writer (its setter, used by
#: save_vtk), the others written by :mod:`ngfracture.output.vtkxml` (no VTK import, no setter)
COMPRESSIONS = {"lz4": "SetCompressorTypeToLZ4", "zlib": None, "lzma": None, None: None}


def _save_vtk(obj, path, compression):
    """Save a vtkUnstructuredGrid (.vtu) or vtkPolyData (.vtp) with VTK's binary writer, atomically."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter
    path = Path(path)
    writer = vtkXMLUnstructuredGridWriter() if path.suffix == ".vtu" else vtkXMLPolyDataWriter()
    writer.SetDataModeToBinary()
    getattr(writer, COMPRESSIONS[compression])()
    writer.SetInputData(obj)

    def produce(tmp):
        writer.SetFileName(str(tmp))
        if writer.Write() != 1:
            raise OSError(f"ngfracture.output.timeseries: VTK could not write {path.name}")
    write_file(path, produce, force=True, sync=False)


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
        if compression not in COMPRESSIONS:
            raise ValueError(f"TimeSeriesWriter: compression must be one of {list(COMPRESSIONS)}, got {compression!r}")
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
            fsync_folder(self.folder)

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
            if (m and int(m.group(1) or m.group(2)) not in keep) or name.startswith(TEMPORARY_PREFIX):
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
        write_bytes(self.folder / self.PVD, self._collection(self._name), force=True)
        write_bytes(self.folder / self.CRACK_PVD, self._collection(self._crack_name), force=True)

    def _write_plane(self, vtu, vtp, fields, crack_boundary):
        """The files of a step of a 2D mesh: triangles, crack faces as lines."""
        mesh, u = fields[:2]
        a = vertex_arrays(mesh)
        if self.compression == "lz4":
            _save_vtk(vtk_mesh(*fields, arrays=a), vtu, self.compression)
            _save_vtk(vtk_cracks(mesh, u, crack_boundary, arrays=a), vtp, self.compression)
            return
        _, points, cells = mesh_fields(*fields, arrays=a)
        grid = vtkxml.unstructured_grid(a.points, a.triangles, points, cells,
                                        {"region_names": region_names(a)}, self.compression)
        write_bytes(vtu, grid, force=True, sync=False)
        lines = vtkxml.poly_lines(*crack_fields(mesh, u, crack_boundary, a), self.compression)
        write_bytes(vtp, lines, force=True, sync=False)

    def _write_solid(self, vtu, vtp, fields, crack_boundary):
        """The files of a step of a 3D mesh: tetrahedra, crack faces as triangles."""
        mesh, u = fields[:2]
        a = solid_arrays(mesh)
        if self.compression == "lz4":
            _save_vtk(vtk_solid_mesh(*fields, arrays=a), vtu, self.compression)
            _save_vtk(vtk_solid_cracks(mesh, u, crack_boundary, arrays=a), vtp, self.compression)
            return
        _, points, cells = solid_fields(*fields, arrays=a)
        grid = vtkxml.unstructured_grid(a.points, a.tets, points, cells, {"region_names": region_names(a)},
                                        self.compression, cell_type=vtkxml.VTK_TETRA)
        write_bytes(vtu, grid, force=True, sync=False)
        faces = vtkxml.poly_triangles(*solid_crack_fields(mesh, u, crack_boundary, a), self.compression)
        write_bytes(vtp, faces, force=True, sync=False)

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
            As for :func:`to_pyvista`: a 2D mesh, or a 3D one (``ngsolve.Mesh`` of
            dimension 3 or SolidArrays; ``fragment`` per tetrahedron) as for
            :func:`ngfracture.output.solid_vtk.solid_to_pyvista`.
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
        vtu, vtp = self.folder / self._name(step), self.folder / self._crack_name(step)
        for p in (vtu, vtp):
            if p.exists():   # a file the collection does not list: never overwrite it silently
                raise FileExistsError(f"TimeSeriesWriter.write: {p} exists but is not in the collection")
        fields = (mesh, u, fragment, strain, point_data, cell_data)
        if is_tetrahedral(mesh):
            self._write_solid(vtu, vtp, fields, crack_boundary)
        else:
            self._write_plane(vtu, vtp, fields, crack_boundary)
        self.steps.append((step, time))
        self._write_collections()
        return vtu, vtp
