"""3D tetrahedral meshes as plain arrays and back.

The 3D counterpart of ``meshio``: checkpoints, the crack engine and the outputs of a 3D
run read and write a tetrahedral mesh as arrays; a mesh goes back to netgen and NGSolve
through netgen's bulk ``AddPoints`` / ``AddElements`` (no per-element Python loop).

Arrays (all 0-based):

    points     (nv, 3) float    reference coordinates
    tets       (ne, 4) int      positively oriented: det[x1-x0, x2-x0, x3-x0] > 0
    regions    (ne,)   int      material region number, 1-based into region_names
    faces      (nf, 3) int      boundary triangles, (x1-x0) x (x2-x0) pointing out of the body
    face_bc    (nf,)   int      boundary number, 1-based into bc_names

netgen orders a tetrahedron's vertices the other way round (negative determinant); the
conversions swap its last two vertices both ways, so a round trip keeps netgen's order.
Crack faces are boundary faces named ``crack``: the two lips of a crack are coincident
faces whose vertices are copies (bitwise equal points) of each other.
"""
import math
from dataclasses import dataclass

import netgen.meshing as nm
import ngsolve as ng
import numpy as np

__all__ = ["SolidArrays", "solid_to_arrays", "outward_faces", "face_keys", "solid_mesh", "tet_volumes", "total_volume", "is_solid",
           "crack_area", "merge_bodies", "nodal_areas"]

#: from this many tetrahedra NGSolve builds a mesh's topology in its task manager
PARALLEL_MIN_TETS = 20000

#: the faces of a positively oriented tetrahedron (local vertex numbers), each with
#: (x1-x0) x (x2-x0) pointing out of it
OUTWARD_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


@dataclass
class SolidArrays:
    """A 3D tetrahedral mesh as plain arrays (see the module docstring).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
        Reference coordinates.
    tets : numpy.ndarray of int, shape (ne, 4)
        Vertex numbers (0-based), positively oriented.
    regions : numpy.ndarray of int, shape (ne,)
        Material region of every tetrahedron, 1-based into ``region_names``.
    region_names : list of str
        Material names.
    faces : numpy.ndarray of int, shape (nf, 3)
        Boundary triangles (0-based vertex numbers), normals pointing out of the body.
    face_bc : numpy.ndarray of int, shape (nf,)
        Boundary number of every face, 1-based into ``bc_names``.
    bc_names : list of str
        Boundary names.
    """
    points: np.ndarray
    tets: np.ndarray
    regions: np.ndarray
    region_names: list
    faces: np.ndarray
    face_bc: np.ndarray
    bc_names: list

    dim = 3

    def as_dict(self, prefix="mesh_"):
        """Arrays for a checkpoint (names are stored as one '\\n'-joined string each).

        Parameters
        ----------
        prefix : str
            Prepended to every key, so that several meshes fit in one checkpoint.

        Returns
        -------
        dict of str -> numpy.ndarray
            Read back by :meth:`from_dict` with the same prefix.
        """
        return {prefix + "points": self.points, prefix + "tets": self.tets,
                prefix + "regions": self.regions, prefix + "faces": self.faces,
                prefix + "face_bc": self.face_bc,
                prefix + "region_names": np.array("\n".join(self.region_names)),
                prefix + "bc_names": np.array("\n".join(self.bc_names))}

    @classmethod
    def from_dict(cls, d, prefix="mesh_"):
        """The arrays stored by :meth:`as_dict`.

        Parameters
        ----------
        d : mapping of str -> numpy.ndarray
            E.g. the arrays of a checkpoint.
        prefix : str
            The prefix given to :meth:`as_dict`.

        Returns
        -------
        SolidArrays
            The arrays of ``d`` themselves (not copies).
        """
        return cls(d[prefix + "points"], d[prefix + "tets"], d[prefix + "regions"],
                   str(d[prefix + "region_names"]).split("\n"), d[prefix + "faces"],
                   d[prefix + "face_bc"], str(d[prefix + "bc_names"]).split("\n"))

    def boundary_faces(self, name):
        """The faces of the boundary called ``name``.

        Parameters
        ----------
        name : str
            Boundary name; several boundary numbers may carry it.

        Returns
        -------
        numpy.ndarray of int, shape (m, 3)
            Empty if there is no such boundary.
        """
        ids = [i for i, n in enumerate(self.bc_names, start=1) if n == name]
        return self.faces[np.isin(self.face_bc, ids)]


def is_solid(mesh):
    """True for a 3D mesh (ngsolve.Mesh, netgen mesh or SolidArrays).

    Parameters
    ----------
    mesh : ngsolve.Mesh, netgen.meshing.Mesh or SolidArrays

    Returns
    -------
    bool
    """
    if isinstance(mesh, SolidArrays):
        return True
    return (mesh.ngmesh if isinstance(mesh, ng.Mesh) else mesh).dim == 3


def solid_to_arrays(mesh):
    """The arrays of an NGSolve (or netgen) tetrahedral mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh or netgen.meshing.Mesh
        3D mesh of linear tetrahedra.

    Returns
    -------
    SolidArrays
        New arrays, elements and faces in mesh order.

    Raises
    ------
    ValueError
        If the mesh is not 3D or holds elements other than tetrahedra.
    """
    ngmesh = mesh.ngmesh if isinstance(mesh, ng.Mesh) else mesh
    if ngmesh.dim != 3:
        raise ValueError(f"solid_to_arrays needs a 3D mesh, this one has dimension {ngmesh.dim}")
    els = ngmesh.Elements3D().NumPy()
    nodes = els["nodes"]
    if nodes.shape[1] > 4 and np.any(nodes[:, 4:] != 0):
        raise ValueError("solid_to_arrays: only linear tetrahedra are supported (the mesh has other elements)")
    faces = ngmesh.Elements2D().NumPy()
    fnodes = faces["nodes"]
    if fnodes.shape[1] > 3 and np.any(fnodes[:, 3:] != 0):
        raise ValueError("solid_to_arrays: only triangular boundary faces are supported")
    nregions = int(els["index"].max()) if len(els) else 0
    # a surface element's index is its face descriptor; the descriptor's bc number names it
    nfd = int(faces["index"].max()) if len(faces) else 0
    fd_bc = np.array([0] + [ngmesh.FaceDescriptor(i).bc for i in range(1, nfd + 1)], dtype=np.int64)
    bc_names = [ngmesh.GetBCName(i) for i in range(int(fd_bc.max(initial=0)))]
    tets = nodes[:, [0, 1, 3, 2]].astype(np.int64) - 1
    return SolidArrays(
        points=ngmesh.Coordinates()[:, :3].copy(),
        tets=tets,
        regions=els["index"].astype(np.int64),
        region_names=[ngmesh.GetMaterial(i) for i in range(1, nregions + 1)],
        faces=outward_faces(tets, fnodes[:, :3].astype(np.int64) - 1),
        face_bc=fd_bc[faces["index"]],
        bc_names=bc_names)


def outward_faces(tets, faces):
    """``faces`` with every face of exactly one tetrahedron turned out of it.

    netgen orients a surface element from its face descriptor's inner to its outer domain:
    out of the body on the faces of the solid it was cut from, into the body on the faces
    of a solid subtracted from it (the notch of ``scenes.notched_bar_mesh``). The outward
    order follows from the tetrahedron's (positive) orientation alone: no coordinates, no
    rounding. A face between two tetrahedra (an interface of two regions) keeps its order.

    Parameters
    ----------
    tets : numpy.ndarray of int, shape (ne, 4)
        Positively oriented tetrahedra.
    faces : numpy.ndarray of int, shape (nf, 3)
        Triangles on faces of the tetrahedra.

    Returns
    -------
    numpy.ndarray of int64, shape (nf, 3)
        The faces, those in the order of the other orientation with their last two
        vertices swapped.

    Raises
    ------
    ValueError
        If a face is no face of any tetrahedron.
    """
    tets = np.asarray(tets, dtype=np.int64).reshape(-1, 4)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    own = tets[:, OUTWARD_FACES].reshape(-1, 3)
    tri = np.vstack([own, faces])
    _, inverse = np.unique(face_keys(tri, int(tri.max(initial=-1)) + 1), return_inverse=True)
    inverse = inverse.ravel()
    # per face, its tetrahedron's own order where exactly one tetrahedron has it
    tets_at = np.bincount(inverse[:len(own)], minlength=int(inverse.max(initial=-1)) + 1)
    at = np.full(len(tets_at), -1, dtype=np.int64)
    at[inverse[:len(own)]] = np.arange(len(own))
    count = tets_at[inverse[len(own):]]
    if np.any(count == 0):
        raise ValueError(f"faces: face {int(np.argmin(count))} is no face of any tetrahedron")
    one = np.flatnonzero(count == 1)
    mine = own[at[inverse[len(own) + one]]]
    f = faces[one]
    same = ((mine == f).all(axis=1) | (mine == f[:, [1, 2, 0]]).all(axis=1) | (mine == f[:, [2, 0, 1]]).all(axis=1))
    out = faces.copy()
    out[one[~same]] = f[~same][:, [0, 2, 1]]
    return out


def face_keys(faces, nv):
    """One key per face, equal for faces on the same three vertices (of ``nv``).

    Parameters
    ----------
    faces : array_like of int, shape (nf, 3)
    nv : int
        A bound of the vertex numbers.

    Returns
    -------
    numpy.ndarray, shape (nf,)
        int64 while nv^3 fits in it (nv < 2**21), else a structured record of the sorted
        three numbers; either sorts and compares as the vertex sets.
    """
    f = np.sort(np.asarray(faces, dtype=np.int64).reshape(-1, 3), axis=1)
    if nv < 2**21:
        return (f[:, 0] * nv + f[:, 1]) * nv + f[:, 2]
    return np.ascontiguousarray(f).view([("a", np.int64), ("b", np.int64), ("c", np.int64)]).ravel()


def _check_arrays(a):
    pts = np.asarray(a.points, dtype=float)
    tets = np.asarray(a.tets, dtype=np.int64)
    nv = pts.shape[0]
    if pts.ndim != 2 or pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
        raise ValueError("solid_mesh: points must be a finite (nv, 3) array")
    if tets.ndim != 2 or tets.shape[1] != 4 or tets.size == 0:
        raise ValueError("solid_mesh: tets must be a non-empty (ne, 4) array")
    if tets.min() < 0 or tets.max() >= nv:
        raise ValueError(f"solid_mesh: tetrahedron vertex numbers must lie in [0, {nv})")
    regions = np.asarray(a.regions, dtype=np.int64)
    if regions.shape != (tets.shape[0],) or regions.min() < 1 or regions.max() > len(a.region_names):
        raise ValueError("solid_mesh: regions must give a 1-based region number per tetrahedron")
    faces = np.asarray(a.faces, dtype=np.int64).reshape(-1, 3)
    face_bc = np.asarray(a.face_bc, dtype=np.int64).reshape(-1)
    if face_bc.shape[0] != faces.shape[0] or (faces.size and (faces.min() < 0 or faces.max() >= nv)):
        raise ValueError("solid_mesh: faces and face_bc do not fit the points")
    if face_bc.size and (face_bc.min() < 1 or face_bc.max() > len(a.bc_names)):
        raise ValueError("solid_mesh: face_bc must be 1-based numbers into bc_names")
    return pts, tets, regions, faces, face_bc


def _add_runs(m, dim, index_of, data):
    # one bulk call per run of equal indices keeps the element order exactly
    if not index_of.size:
        return
    starts = np.flatnonzero(np.r_[True, index_of[1:] != index_of[:-1]])
    for s, e in zip(starts, np.r_[starts[1:], index_of.size]):
        m.AddElements(dim=dim, index=int(index_of[s]), data=np.ascontiguousarray(data[s:e].astype(np.int32)), base=0)


def solid_mesh(arrays):
    """An NGSolve mesh from SolidArrays (vertex i is point i, elements in the given order).

    Parameters
    ----------
    arrays : SolidArrays
        The mesh; boundary and material names are kept.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        On inconsistent shapes or out-of-range indices.
    """
    pts, tets, regions, faces, face_bc = _check_arrays(arrays)
    m = nm.Mesh(dim=3)
    m.AddPoints(np.ascontiguousarray(pts))
    for r, name in enumerate(arrays.region_names, start=1):
        m.SetMaterial(r, name)
    # one face descriptor per boundary name: bc number b, the body inside
    for b, name in enumerate(arrays.bc_names, start=1):
        m.Add(nm.FaceDescriptor(bc=b, domin=1, domout=0, surfnr=b))
        m.SetBCName(b - 1, name)
    _add_runs(m, 3, regions, tets[:, [0, 1, 3, 2]])
    _add_runs(m, 2, face_bc, faces)
    if len(tets) < PARALLEL_MIN_TETS:
        return ng.Mesh(m)
    with ng.TaskManager():
        return ng.Mesh(m)


def tet_volumes(points, tets):
    """Signed volume of every tetrahedron (positive for the orientation of SolidArrays).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
    tets : numpy.ndarray of int, shape (ne, 4)

    Returns
    -------
    numpy.ndarray, shape (ne,)
    """
    x = np.asarray(points, dtype=float)[np.asarray(tets)]
    a, b, c = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0


def total_volume(points, tets):
    """The body's volume, summed exactly rounded (``math.fsum``): equal to the last bit for
    any order of the same tetrahedra.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 3)
    tets : numpy.ndarray of int, shape (ne, 4)

    Returns
    -------
    float
    """
    return math.fsum(tet_volumes(points, tets))


def crack_area(arrays, name="crack"):
    """The crack's area in the reference configuration: half the area of its faces (both lips).

    Parameters
    ----------
    arrays : SolidArrays
    name : str
        The crack faces' boundary name.

    Returns
    -------
    float
    """
    faces = arrays.boundary_faces(name)
    if len(faces) == 0:
        return 0.0
    x = np.asarray(arrays.points, dtype=float)[faces]
    return 0.25 * math.fsum(np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1))


def nodal_areas(points, faces):
    """Consistent nodal areas of a triangulated surface: the integral of each vertex's hat function.

    The tributary area by which a nodal contact force is a pressure.

    Parameters
    ----------
    points : array_like, shape (nv, 3)
        Vertex coordinates.
    faces : array_like of int, shape (nf, 3)
        The surface's triangles.

    Returns
    -------
    numpy.ndarray, shape (nv,)
        A third of the area of every face at the vertex, summed (0 off the surface).

    Raises
    ------
    ValueError
        On wrong shapes, non-finite coordinates or vertex numbers out of range.
    """
    X = np.asarray(points, dtype=np.float64)
    F = np.asarray(faces)
    if X.ndim != 2 or X.shape[1] != 3 or not np.isfinite(X).all():
        raise ValueError(f"points must be finite coordinates of shape (nv, 3), got {X.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or (F.size and not np.issubdtype(F.dtype, np.integer)):
        raise ValueError(f"faces must be integers of shape (nf, 3), got {F.dtype} {F.shape}")
    if F.size and (F.min() < 0 or F.max() >= len(X)):
        raise ValueError(f"faces hold vertex numbers outside [0, {len(X)})")
    p = X[F]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    out = np.zeros(len(X))
    np.add.at(out, F.ravel(), np.repeat(area / 3.0, 3))
    return out


def merge_bodies(bodies):
    """Bodies meshed apart as one mesh: a region per body, boundary names prefixed by its name.

    The vertices are not joined (coincident points stay two vertices), as contact between
    bodies meshed apart needs (docs/contact.md, "Contact in 3D runs").

    Parameters
    ----------
    bodies : sequence of (str, SolidArrays)
        Name and mesh of every body, in order; a body's own regions are merged into one.

    Returns
    -------
    SolidArrays
        Region k + 1 is body k (named by it); boundary ``b`` of body ``name`` is
        ``name + "_" + b``.

    Raises
    ------
    ValueError
        Without bodies.
    """
    if not bodies:
        raise ValueError("merge_bodies: no bodies")
    offsets = np.cumsum([0] + [len(a.points) for _, a in bodies])
    bc_offsets = np.cumsum([0] + [len(a.bc_names) for _, a in bodies])
    return SolidArrays(
        points=np.concatenate([a.points for _, a in bodies]),
        tets=np.concatenate([a.tets + o for (_, a), o in zip(bodies, offsets)]),
        regions=np.concatenate([np.full(len(a.tets), k + 1) for k, (_, a) in enumerate(bodies)]),
        region_names=[name for name, _ in bodies],
        faces=np.concatenate([a.faces + o for (_, a), o in zip(bodies, offsets)]),
        face_bc=np.concatenate([a.face_bc + o for (_, a), o in zip(bodies, bc_offsets)]),
        bc_names=[f"{name}_{b}" for name, a in bodies for b in a.bc_names])
