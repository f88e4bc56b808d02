"""A tetrahedral mesh and its fields as VTK data: the 3D counterpart of :mod:`ngfracture.output.vtk`.

``solid_to_pyvista`` and ``solid_cracks_to_pyvista`` give VTK objects (pyvista);
``solid_fields`` and ``solid_crack_fields`` the same content as numpy arrays, which
:class:`ngfracture.output.timeseries.TimeSeriesWriter` writes with
:mod:`ngfracture.output.vtkxml`. A mesh is an ``ngsolve.Mesh`` of dimension 3 or
:class:`ngfracture.geometry.solid.SolidArrays`.

The mesh has shared vertices (one VTK point per mesh vertex) in the reference
configuration, one ``VTK_TETRA`` (10) per tetrahedron in element order. Point data
``displacement`` (nv, 3): ParaView's *Warp By Vector* gives the deformed configuration.
Cell data ``region`` (0-based material region; names in the field data ``region_names``),
``fragment``, ``strain`` (the 3x3 tensor as VTK's 9 components, row by row),
``principal_strain`` (the largest principal value) and ``principal_direction`` (its unit
vector, the sign chosen so that its largest component is positive). The strain is that
of the P1 interpolant of the vertex displacements, constant per tetrahedron:
H = grad u from the edge vectors (H (x_k - x_0) = u_k - u_0), Green-Lagrange
E = (H + H^T + H^T H) / 2 by default, or the linear (H + H^T) / 2.

The crack faces (boundary faces named ``crack``) are triangles (VTK polygons) of a
separate poly data set with their own copy of the vertices, the vertices' mesh numbers
(point data ``vertex``) and their ``displacement``, so the same *Warp By Vector* opens the
crack: the two lips are coincident triangles on distinct vertex copies, which separate
when the displacement does.
"""
import numpy as np
import ngsolve

from ..geometry.solid import SolidArrays, is_solid, solid_to_arrays, tet_volumes
from .vtk import add_user_data, fill_vtk, region_names

__all__ = ["solid_arrays", "solid_displacement", "solid_strain", "largest_principal", "solid_fields",
           "solid_crack_fields", "solid_to_pyvista", "solid_cracks_to_pyvista", "vtk_solid_mesh",
           "vtk_solid_cracks"]

#: strain measures of :func:`solid_strain`
STRAIN_MEASURES = ("green", "linear")


def solid_arrays(mesh):
    """The SolidArrays of a 3D mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh, netgen.meshing.Mesh or SolidArrays
        A tetrahedral mesh; SolidArrays are returned as they are.

    Returns
    -------
    SolidArrays

    Raises
    ------
    ValueError
        Not a 3D mesh.
    """
    if isinstance(mesh, SolidArrays):
        return mesh
    if not is_solid(mesh):
        raise ValueError("ngfracture.output.solid_vtk: the mesh must be 3D (tetrahedra)")
    return solid_to_arrays(mesh)


def solid_displacement(arrays, u):
    """The vertex displacements (nv, 3) of a field on a tetrahedral mesh, checked.

    Parameters
    ----------
    arrays : SolidArrays
        The mesh.
    u : ngsolve.GridFunction or array_like
        Displacement on a 3D ``VectorH1`` space (its vertex dofs, for every order), or
        vertex values (nv, 3).

    Returns
    -------
    numpy.ndarray, shape (nv, 3)
        A float copy.

    Raises
    ------
    ValueError
        Another space or shape, another number of vertices, NaN or inf values.
    """
    nv = len(arrays.points)
    if isinstance(u, ngsolve.GridFunction):
        fes = u.space
        if not isinstance(fes, ngsolve.VectorH1) or fes.mesh.dim != 3:
            raise ValueError("ngfracture.output.solid_vtk: the displacement must be a GridFunction on a 3D "
                             f"ngsolve.VectorH1 space, got {type(fes).__name__}")
        # component-blocked dofs, vertex dofs first in each block
        U = u.vec.FV().NumPy().reshape(3, -1)[:, :fes.mesh.nv].T.copy()
    else:
        U = np.array(u, dtype=float)
    if U.shape != (nv, 3):
        raise ValueError(f"ngfracture.output.solid_vtk: displacement has shape {U.shape}, the mesh needs "
                         f"({nv}, 3)")
    if not np.all(np.isfinite(U)):
        raise ValueError("ngfracture.output.solid_vtk: displacement has NaN or inf values")
    return U


def solid_strain(points, tets, U, measure="green"):
    """The strain of the P1 displacement on every tetrahedron.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates.
    tets : numpy.ndarray of int, shape (ne, 4)
        Positively oriented tetrahedra.
    U : numpy.ndarray, shape (nv, 3)
        Vertex displacements.
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H) / 2 or linear (H + H^T) / 2 of H = grad u.

    Returns
    -------
    numpy.ndarray, shape (ne, 3, 3)
        Symmetric tensors.

    Raises
    ------
    ValueError
        An unknown measure, or a tetrahedron of volume <= 0 (named).
    """
    if measure not in STRAIN_MEASURES:
        raise ValueError(f"ngfracture.output.solid_vtk: strain must be one of {STRAIN_MEASURES} or None, "
                         f"got {measure!r}")
    tets = np.asarray(tets, dtype=np.int64)
    vol = tet_volumes(points, tets)
    if np.any(~(vol > 0)):
        k = int(np.flatnonzero(~(vol > 0))[0])
        raise ValueError(f"ngfracture.output.solid_vtk: tetrahedron {k} {tets[k].tolist()} has volume "
                         f"{vol[k]!r}, not > 0")
    X = np.asarray(points, dtype=float)
    D = X[tets[:, 1:]] - X[tets[:, :1]]      # rows: edge vectors x_k - x_0
    dU = U[tets[:, 1:]] - U[tets[:, :1]]     # rows: u_k - u_0
    # H e_k = du_k for the three edges: D H^T = dU
    H = np.linalg.solve(D, dU).transpose(0, 2, 1)
    E = 0.5 * (H + H.transpose(0, 2, 1))
    if measure == "green":
        E += 0.5 * np.einsum("nki,nkj->nij", H, H)
    return E


def largest_principal(E):
    """The largest principal value of symmetric 3x3 tensors and its direction.

    Parameters
    ----------
    E : numpy.ndarray, shape (n, 3, 3)
        Symmetric tensors.

    Returns
    -------
    values : numpy.ndarray, shape (n,)
    directions : numpy.ndarray, shape (n, 3)
        Unit vectors, signed so that the component of largest magnitude is positive.
    """
    w, v = np.linalg.eigh(E)
    d = v[:, :, -1]
    big = d[np.arange(len(d)), np.abs(d).argmax(axis=1)] if len(d) else np.zeros(0)
    return w[:, -1].copy(), d * np.where(big < 0, -1.0, 1.0)[:, None]


def solid_fields(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None, arrays=None):
    """The mesh arrays and the point and cell arrays of :func:`solid_to_pyvista`, checked.

    Parameters
    ----------
    mesh, u, fragment, strain, point_data, cell_data, arrays
        As for :func:`solid_to_pyvista`.

    Returns
    -------
    arrays : SolidArrays
    points, cells : dict of str -> numpy.ndarray
        Point and cell arrays by name.

    Raises
    ------
    ValueError
        Arrays that do not fit the mesh, an unknown strain measure.
    """
    a = arrays if arrays is not None else solid_arrays(mesh)
    ne, nv = len(a.tets), len(a.points)
    cells, points = {"region": np.asarray(a.regions) - 1}, {}    # 0-based index into region_names
    if fragment is not None:
        f = np.asarray(fragment)
        if f.shape != (ne,) or not np.issubdtype(f.dtype, np.integer):
            raise ValueError(f"ngfracture.output.solid_vtk: fragment must be {ne} integers (one per "
                             f"tetrahedron), got shape {f.shape} dtype {f.dtype}")
        cells["fragment"] = f
    if u is not None:
        U = solid_displacement(a, u)
        points["displacement"] = U
        if strain is not None:
            E = solid_strain(a.points, a.tets, U, strain)
            val, d = largest_principal(E)
            cells["strain"] = E.reshape(ne, 9)
            cells["principal_strain"] = val
            cells["principal_direction"] = d
    add_user_data(points, point_data, nv, "point_data")
    add_user_data(cells, cell_data, ne, "cell_data")
    return a, points, cells


def solid_crack_fields(mesh, u=None, boundary="crack", arrays=None):
    """The crack faces' points, their triangles in the points' numbering, and point data.

    Parameters
    ----------
    mesh, u, boundary, arrays
        As for :func:`solid_cracks_to_pyvista`.

    Returns
    -------
    points : numpy.ndarray, shape (k, 3)
    triangles : numpy.ndarray of int, shape (m, 3)
        Oriented as the mesh's faces (normals out of the body).
    point_data : dict of str -> numpy.ndarray
        ``vertex`` (mesh vertex numbers) and, with ``u``, ``displacement``.

    Raises
    ------
    ValueError
        A displacement that does not fit the mesh.
    """
    a = arrays if arrays is not None else solid_arrays(mesh)
    faces = a.boundary_faces(boundary)
    if len(faces) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), {}
    used, local = np.unique(faces, return_inverse=True)
    points = {"vertex": used.astype(np.int64)}
    if u is not None:
        points["displacement"] = solid_displacement(a, u)[used]
    return np.asarray(a.points, dtype=float)[used], local.reshape(faces.shape).astype(np.int64), points


def solid_to_pyvista(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None,
                     arrays=None):
    """The tetrahedral mesh as a shared-vertex ``pyvista.UnstructuredGrid`` with result fields.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays
        3D tetrahedral mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray, optional
        Displacement; point data ``displacement`` (nv, 3), float64.
    fragment : array_like of int, optional
        Fragment id per tetrahedron (cell data ``fragment``).
    strain : {'green', 'linear', None}
        Strain measure for the strain fields (needs ``u``); None writes none.
    point_data, cell_data : dict of str -> array_like, optional
        Further arrays (nv or ne rows).
    arrays : SolidArrays, optional
        Reuse arrays already extracted with :func:`solid_arrays`.

    Returns
    -------
    pyvista.UnstructuredGrid
        One VTK_TETRA per tetrahedron; field data ``region_names``. See the module
        docstring for the arrays.
    """
    import pyvista as pv
    return pv.wrap(vtk_solid_mesh(mesh, u, fragment, strain, point_data, cell_data, arrays))


def vtk_solid_mesh(mesh, u=None, fragment=None, strain="green", point_data=None, cell_data=None,
                   arrays=None):
    """The vtkUnstructuredGrid of :func:`solid_to_pyvista` (plain VTK, without pyvista).

    Parameters
    ----------
    mesh, u, fragment, strain, point_data, cell_data, arrays
        As for :func:`solid_to_pyvista`.

    Returns
    -------
    vtkUnstructuredGrid
    """
    a, points, cells = solid_fields(mesh, u, fragment, strain, point_data, cell_data, arrays)
    from vtkmodules.vtkCommonDataModel import vtkUnstructuredGrid
    grid = vtkUnstructuredGrid()
    fill_vtk(grid, np.asarray(a.points, dtype=float), np.asarray(a.tets, dtype=np.int64), points, cells,
             region_names(a))
    return grid


def solid_cracks_to_pyvista(mesh, u=None, boundary="crack", arrays=None):
    """The crack faces (boundary faces named ``boundary``) as triangles.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays
        3D tetrahedral mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray, optional
        Displacement; point data ``displacement`` (k, 3).
    boundary : str
        Boundary name of the crack faces.
    arrays : SolidArrays, optional
        Reuse arrays already extracted with :func:`solid_arrays`.

    Returns
    -------
    pyvista.PolyData
        One triangle per face (both lips of a crack: coincident triangles on distinct
        points); only the vertices of those faces, their mesh numbers in point data
        ``vertex``. Empty (no points, no cells) when nothing has cracked.
    """
    import pyvista as pv
    return pv.wrap(vtk_solid_cracks(mesh, u, boundary, arrays))


def vtk_solid_cracks(mesh, u=None, boundary="crack", arrays=None):
    """The vtkPolyData of :func:`solid_cracks_to_pyvista` (plain VTK).

    Parameters
    ----------
    mesh, u, boundary, arrays
        As for :func:`solid_cracks_to_pyvista`.

    Returns
    -------
    vtkPolyData
    """
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    poly = vtkPolyData()
    points, triangles, point_data = solid_crack_fields(mesh, u, boundary, arrays)
    if len(triangles):
        fill_vtk(poly, points, triangles, point_data, {})
    return poly
