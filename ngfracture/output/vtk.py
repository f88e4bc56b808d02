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

Tetrahedral meshes (3D) have their own module, :mod:`ngfracture.output.solid_vtk`;
``to_pyvista`` and ``cracks_to_pyvista`` pass them on to it (:func:`is_tetrahedral`).
"""
import numpy as np
import ngsolve

from ..fracture.strain import element_strain, principal, vertex_displacement, vertex_strain
from ..geometry.meshio import check_mesh, mesh_to_arrays
from ..geometry.solid import SolidArrays

__all__ = ["is_tetrahedral", "vertex_arrays", "displacement_values", "to_pyvista", "cracks_to_pyvista", "mesh_fields",
           "crack_fields", "region_names"]


def is_tetrahedral(mesh):
    """True for a 3D mesh: SolidArrays or an ngsolve.Mesh of dimension 3.

    The outputs take 3D meshes through the same functions as 2D ones and pass them on to
    :mod:`ngfracture.output.solid_vtk` and :mod:`ngfracture.output.solid_pictures`.

    Parameters
    ----------
    mesh : object

    Returns
    -------
    bool
        False for anything else (a 2D mesh, or what is no mesh: the 2D checks name it).
    """
    return isinstance(mesh, SolidArrays) or (isinstance(mesh, ngsolve.Mesh) and mesh.dim == 3)


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


def add_user_data(data, extra, n, where):
    """Add the caller's arrays to point or cell data, checked to have one row per point / cell.

    Parameters
    ----------
    data : dict of str -> numpy.ndarray
        Point or cell arrays, extended in place.
    extra : dict of str -> array_like or None
        The caller's arrays.
    n : int
        The number of points / cells.
    where : str
        ``"point_data"`` or ``"cell_data"``, for the message.

    Raises
    ------
    ValueError
        An array without ``n`` rows.
    """
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
        2D triangle mesh, reference configuration. A 3D mesh (or SolidArrays) gives
        :func:`ngfracture.output.solid_vtk.solid_to_pyvista`.
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
    if is_tetrahedral(mesh):
        from .solid_vtk import vtk_solid_mesh
        return pv.wrap(vtk_solid_mesh(mesh, u, fragment, strain, point_data, cell_data, arrays))
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
    fill_vtk(grid, a.points, a.triangles, points, cells, region_names(a))
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
    add_user_data(points, point_data, nv, "point_data")
    add_user_data(cells, cell_data, ne, "cell_data")
    return a, points, cells


def fill_vtk(data, points, cells, point_data, cell_data, region_names=None):
    """Fill a VTK data set with points, cells of one kind, point and cell arrays.

    The first point and cell arrays are the active scalars (what ParaView colours by at
    first).

    Parameters
    ----------
    data : vtkUnstructuredGrid or vtkPolyData
        Filled in place. A grid takes triangles (3 columns) or tetrahedra (4); poly data
        lines (2) or triangles (3, as polygons).
    points : numpy.ndarray, shape (n, 2) or (n, 3)
        Coordinates (z = 0 if two columns).
    cells : numpy.ndarray of int, shape (m, corners)
        0-based point numbers.
    point_data, cell_data : dict of str -> numpy.ndarray
        Arrays by name (bool as UInt8).
    region_names : list of str, optional
        The field data ``region_names``.

    Raises
    ------
    ValueError
        A number of corners the data set does not take.
    """
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import VTK_ID_TYPE, vtkPoints, vtkStringArray
    from vtkmodules.vtkCommonDataModel import VTK_TETRA, VTK_TRIANGLE, vtkCellArray, vtkPolyData

    def array(name, values):
        v = np.ascontiguousarray(values)
        arr = numpy_to_vtk(v.astype(np.uint8) if v.dtype == bool else v, deep=True)
        arr.SetName(name)
        return arr

    corners = cells.shape[1]
    poly = isinstance(data, vtkPolyData)
    if corners not in ((2, 3) if poly else (3, 4)):
        raise ValueError(f"ngfracture.output.vtk: {type(data).__name__} takes no cells of {corners} corners")
    pts = vtkPoints()
    xyz = points if points.shape[1] == 3 else _pad3(points)
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(xyz, dtype=np.float64), deep=True))
    data.SetPoints(pts)
    offsets = np.arange(0, corners * len(cells) + 1, corners, dtype=np.int64)
    cell_array = vtkCellArray()
    cell_array.SetData(numpy_to_vtk(offsets, deep=True, array_type=VTK_ID_TYPE),
                       numpy_to_vtk(np.ascontiguousarray(cells, dtype=np.int64).ravel(), deep=True,
                                    array_type=VTK_ID_TYPE))
    if not poly:
        data.SetCells(VTK_TRIANGLE if corners == 3 else VTK_TETRA, cell_array)
    elif corners == 3:
        data.SetPolys(cell_array)
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
        2D triangle mesh, reference configuration. A 3D mesh (or SolidArrays) gives
        :func:`ngfracture.output.solid_vtk.solid_cracks_to_pyvista`.
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
    if is_tetrahedral(mesh):
        from .solid_vtk import vtk_solid_cracks
        return pv.wrap(vtk_solid_cracks(mesh, u, boundary, arrays))
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
        fill_vtk(poly, points, lines, point_data, {})
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
