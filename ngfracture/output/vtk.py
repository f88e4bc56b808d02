"""A mesh and its fields as VTK data for ParaView and PyVista.

``to_pyvista`` and ``cracks_to_pyvista`` give VTK objects (pyvista); ``mesh_fields`` and
``crack_fields`` the same content as numpy arrays, which :mod:`ngfracture.output.timeseries`
writes with :mod:`ngfracture.output.vtkxml`.

The mesh has shared vertices (one VTK point per mesh vertex, z = 0) in the reference
configuration. Point data ``displacement`` (3-vector, z = 0: ParaView's *Warp By Vector*
gives the deformed configuration) and, with a strain measure, ``nodal_strain`` (the crack
criterion's vertex tensor), ``nodal_principal_strain``, ``nodal_principal_direction``. Cell
data ``region`` (0-based material region; names in the field data ``region_names``),
``fragment``, ``strain`` (3x3 tensor, in-plane components, zz = 0), ``principal_strain`` and
``principal_direction`` (unit 3-vector, z = 0). Strains are those of the P1 interpolant of
the vertex displacements (element-wise constant, Green-Lagrange by default,
:func:`ngfracture.fracture.strain.element_strain`), the quantity the crack criterion
averages at the vertices.

The crack faces are line cells (the boundary segments named ``crack``) with their own copy
of the vertices and their ``displacement``, so the same *Warp By Vector* applies: a
separate data set rather than line cells in the triangles' one, where mixed cells would
break cell data (every line would need a fragment and a strain) and filters like
*Threshold*.
"""
import numpy as np

from ..fracture.strain import element_strain, principal, vertex_displacement, vertex_strain
from ..geometry.meshio import check_mesh, mesh_to_arrays

__all__ = ["vertex_arrays", "displacement_values", "to_pyvista", "cracks_to_pyvista", "mesh_fields",
           "crack_fields", "region_names"]


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


def displacement_values(mesh, u):
    """The vertex displacements (nv, 2) of a field, checked to fit the mesh and be finite.

    Parameters
    ----------
    mesh : ngsolve.Mesh
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement (``VectorH1``) or vertex values (nv, 2).

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ValueError
        Another number of vertices, or NaN or inf values.
    """
    U = vertex_displacement(u)
    if U.shape != (mesh.nv, 2):
        raise ValueError(f"ngfracture.output.vtk: displacement has {U.shape[0]} vertex values, "
                         f"the mesh has {mesh.nv} vertices")
    if not np.all(np.isfinite(U)):
        raise ValueError("ngfracture.output.vtk: displacement has NaN or inf values")
    return U


def _pad3(a):
    return np.column_stack([a, np.zeros(len(a))])


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
    return pv.wrap(vtk_mesh(mesh, u, fragment, strain, point_data, cell_data, arrays))


def vtk_mesh(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None, arrays=None):
    """The vtkUnstructuredGrid of :func:`to_pyvista` (plain VTK, without pyvista).

    Parameters
    ----------
    mesh, u, fragment, strain, point_data, cell_data, arrays
        As for :func:`to_pyvista`.

    Returns
    -------
    vtkUnstructuredGrid
    """
    a, points, cells = mesh_fields(mesh, u, fragment, strain, point_data, cell_data, arrays)
    from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
    grid = vtkUnstructuredGrid()
    _fill_vtk(grid, a.points, a.triangles, points, cells, region_names(a))
    return grid


def region_names(a):
    """The material region names of mesh arrays, for the field data (never empty).

    Parameters
    ----------
    a : MeshArrays

    Returns
    -------
    list of str
    """
    return a.region_names if a.region_names else [""]


def mesh_fields(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None, arrays=None):
    """The mesh arrays and the point and cell arrays of :func:`to_pyvista`, checked.

    Parameters
    ----------
    mesh, u, fragment, strain, point_data, cell_data, arrays
        As for :func:`to_pyvista`.

    Returns
    -------
    arrays : MeshArrays
    points, cells : dict of str -> numpy.ndarray
        Point and cell arrays by name.

    Raises
    ------
    ValueError
        Arrays that do not fit the mesh.
    """
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
        U = displacement_values(mesh, u)
        points["displacement"] = _pad3(U)
        if strain is not None:
            E = element_strain(mesh, U, strain)
            val, d = principal(E)
            cells["strain"] = _tensor9(E)
            cells["principal_strain"] = val
            cells["principal_direction"] = _pad3(d)
            En = vertex_strain(mesh, U, strain)
            val, d = principal(En)
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
    return pv.wrap(vtk_cracks(mesh, u, boundary, arrays))


def vtk_cracks(mesh, u=None, boundary="crack", arrays=None):
    """The vtkPolyData of :func:`cracks_to_pyvista` (plain VTK, see :func:`vtk_mesh`).

    Parameters
    ----------
    mesh, u, boundary, arrays
        As for :func:`cracks_to_pyvista`.

    Returns
    -------
    vtkPolyData
    """
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    poly = vtkPolyData()
    points, lines, point_data = crack_fields(mesh, u, boundary, arrays)
    if len(lines):
        _fill_vtk(poly, points, lines, point_data, {})
    return poly


def crack_fields(mesh, u=None, boundary="crack", arrays=None):
    """The crack faces' points, their segments in the points' numbering, and point data.

    Parameters
    ----------
    mesh, u, boundary, arrays
        As for :func:`cracks_to_pyvista`.

    Returns
    -------
    points : numpy.ndarray (k, 2)
    lines : numpy.ndarray (m, 2)
    point_data : dict of str -> numpy.ndarray
    """
    a = arrays if arrays is not None else vertex_arrays(mesh)
    seg = a.boundary_segments(boundary)
    if len(seg) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2), dtype=np.int64), {}
    used, local = np.unique(seg, return_inverse=True)
    points = {"vertex": used}
    if u is not None:
        points["displacement"] = _pad3(displacement_values(mesh, u)[used])
    return a.points[used], local.reshape(seg.shape), points
