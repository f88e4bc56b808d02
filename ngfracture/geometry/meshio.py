"""2D meshes as plain arrays and back, and separate bodies merged into one mesh.

Checkpoints store a mesh as arrays; scenes with several bodies (a disk and its core)
either mesh each body with netgen and merge them into one mesh whose bodies share no
vertex (``merge_meshes``), or mesh them together as regions of one netgen mesh and give
one region its own copies of the interface vertices (``separate_region``): the bodies
then share no vertex but their interface nodes coincide, so only contact couples them.  Building goes through netgen's bulk
``AddPoints`` / ``AddElements`` (vectorised, no per-element Python loop).

Arrays (all 0-based):

    points     (nv, 2) float    reference coordinates
    triangles  (ne, 3) int      counter-clockwise
    regions    (ne,)   int      material region number, 1-based into region_names
    segments   (ns, 2) int      boundary edges, the domain on their left
    seg_bc     (ns,)   int      boundary number, 1-based into bc_names
"""
from dataclasses import dataclass

import netgen.meshing as nm
import ngsolve as ng
import numpy as np

from .solid import SolidArrays, solid_mesh, solid_to_arrays


#: from this many triangles on a netgen mesh's topology is built in NGSolve's task manager
#: (as ElasticProblem builds its space from PARALLEL_MIN_DOFS // 2): the same numbering,
#: in 17 ms instead of 28 ms at 31k triangles (two threads); below it starting the task
#: manager costs more than it saves
PARALLEL_MIN_TRIANGLES = 10000


def ngsolve_mesh(ngmesh, ntriangles):
    """``ngsolve.Mesh(ngmesh)``, built in NGSolve's task manager for a big mesh.

    Parameters
    ----------
    ngmesh : netgen.meshing.Mesh
    ntriangles : int
        Its number of triangles (or an estimate): decides the task manager.

    Returns
    -------
    ngsolve.Mesh
    """
    if ntriangles < PARALLEL_MIN_TRIANGLES:
        return ng.Mesh(ngmesh)
    with ng.TaskManager():
        return ng.Mesh(ngmesh)


@dataclass
class MeshArrays:
    """A 2D triangle mesh as plain arrays (see the module docstring).

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 2)
        Reference coordinates.
    triangles : numpy.ndarray of int, shape (ne, 3)
        Vertex numbers (0-based), counter-clockwise.
    regions : numpy.ndarray of int, shape (ne,)
        Material region of every triangle, 1-based into ``region_names``.
    region_names : list of str
        Material names.
    segments : numpy.ndarray of int, shape (ns, 2)
        Boundary edges (0-based vertex numbers), the domain on their left.
    seg_bc : numpy.ndarray of int, shape (ns,)
        Boundary number of every segment, 1-based into ``bc_names``.
    bc_names : list of str
        Boundary names.
    """
    points: np.ndarray
    triangles: np.ndarray
    regions: np.ndarray
    region_names: list
    segments: np.ndarray
    seg_bc: np.ndarray
    bc_names: list

    dim = 2

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
        return {prefix + "points": self.points, prefix + "triangles": self.triangles,
                prefix + "regions": self.regions, prefix + "segments": self.segments,
                prefix + "seg_bc": self.seg_bc,
                prefix + "region_names": np.array("\n".join(self.region_names)),
                prefix + "bc_names": np.array("\n".join(self.bc_names))}

    def boundary_segments(self, name):
        """The segments of the boundary called ``name``.

        Parameters
        ----------
        name : str
            Boundary name; several boundary numbers may carry it.

        Returns
        -------
        numpy.ndarray of int, shape (m, 2)
            Empty if there is no such boundary.
        """
        ids = [i for i, n in enumerate(self.bc_names, start=1) if n == name]
        return self.segments[np.isin(self.seg_bc, ids)]

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
        MeshArrays
            The arrays of ``d`` themselves (not copies).
        """
        return cls(d[prefix + "points"], d[prefix + "triangles"], d[prefix + "regions"],
                   str(d[prefix + "region_names"]).split("\n"), d[prefix + "segments"],
                   d[prefix + "seg_bc"], str(d[prefix + "bc_names"]).split("\n"))


def simplex_measures(x, elements):
    """Twice the signed area of every triangle, or six times the signed volume of every
    tetrahedron (positive for the orientations of MeshArrays and SolidArrays).

    Parameters
    ----------
    x : numpy.ndarray, shape (nv, 2) or (nv, 3)
        Vertex positions.
    elements : numpy.ndarray of int, shape (ne, 3) or (ne, 4)

    Returns
    -------
    numpy.ndarray, shape (ne,)
    """
    if x.shape[1] == 3:
        e = x[np.asarray(elements)]
        a, b, c = e[:, 1] - e[:, 0], e[:, 2] - e[:, 0], e[:, 3] - e[:, 0]
        return np.einsum("ij,ij->i", a, np.cross(b, c))
    # gathers from contiguous coordinate and vertex columns: four times faster than rows of x
    X, Y = np.ascontiguousarray(x[:, 0]), np.ascontiguousarray(x[:, 1])
    a, b, c = np.ascontiguousarray(np.asarray(elements).T)
    xa, ya = X[a], Y[a]
    return (X[b] - xa) * (Y[c] - ya) - (Y[b] - ya) * (X[c] - xa)


def mesh_to_arrays(mesh):
    """The arrays of an NGSolve (or netgen) 2D triangle mesh (3D: ``solid.solid_to_arrays``).

    Parameters
    ----------
    mesh : ngsolve.Mesh or netgen.meshing.Mesh
        2D mesh of triangles, or 3D mesh of tetrahedra.

    Returns
    -------
    MeshArrays or SolidArrays
        New arrays (0-based vertex numbers), elements and segments (faces) in mesh order.

    Raises
    ------
    ValueError
        If the mesh is 1D or holds elements other than triangles (tetrahedra).
    """
    ngmesh = mesh.ngmesh if isinstance(mesh, ng.Mesh) else mesh
    if ngmesh.dim == 3:
        return solid_to_arrays(ngmesh)
    if ngmesh.dim != 2:
        raise ValueError(f"mesh_to_arrays needs a 2D mesh, this one has dimension {ngmesh.dim}")
    els = ngmesh.Elements2D().NumPy()
    nodes = els["nodes"]
    if nodes.shape[1] > 3 and np.any(nodes[:, 3] != 0):
        raise ValueError("mesh_to_arrays: only triangles are supported (the mesh has quadrilaterals)")
    segs = ngmesh.Elements1D().NumPy()
    nregions = int(els["index"].max()) if len(els) else 0
    nbc = int(segs["index"].max()) if len(segs) else 0
    return MeshArrays(
        points=ngmesh.Coordinates()[:, :2].copy(),
        triangles=nodes[:, :3].astype(np.int64) - 1,
        regions=els["index"].astype(np.int64),
        region_names=[ngmesh.GetMaterial(i) for i in range(1, nregions + 1)],
        segments=segs["nodes"][:, :2].astype(np.int64) - 1,
        seg_bc=segs["index"].astype(np.int64),
        bc_names=[ngmesh.GetBCName(i) for i in range(nbc)])


def mesh_from_arrays(arrays):
    """An NGSolve mesh from MeshArrays (vertex i is point i, elements in the given order).

    Parameters
    ----------
    arrays : MeshArrays or SolidArrays
        The mesh; boundary names and material names are kept (3D: ``solid.solid_mesh``).

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        On inconsistent shapes or out-of-range indices.
    """
    if isinstance(arrays, SolidArrays):
        return solid_mesh(arrays)
    a = arrays
    pts = np.asarray(a.points, dtype=float)
    tris = np.asarray(a.triangles, dtype=np.int64)
    nv = pts.shape[0]
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
        raise ValueError("mesh_from_arrays: points must be a finite (nv, 2) array")
    if tris.ndim != 2 or tris.shape[1] != 3 or tris.size == 0:
        raise ValueError("mesh_from_arrays: triangles must be a non-empty (ne, 3) array")
    if tris.min() < 0 or tris.max() >= nv:
        raise ValueError(f"mesh_from_arrays: triangle vertex numbers must lie in [0, {nv})")
    regions = np.asarray(a.regions, dtype=np.int64)
    if regions.shape != (tris.shape[0],) or regions.min() < 1 or regions.max() > len(a.region_names):
        raise ValueError("mesh_from_arrays: regions must give a 1-based region number per triangle")
    segs = np.asarray(a.segments, dtype=np.int64).reshape(-1, 2)
    seg_bc = np.asarray(a.seg_bc, dtype=np.int64).reshape(-1)
    if seg_bc.shape[0] != segs.shape[0] or (segs.size and (segs.min() < 0 or segs.max() >= nv)):
        raise ValueError("mesh_from_arrays: segments and seg_bc do not fit the points")
    if seg_bc.size and (seg_bc.min() < 1 or seg_bc.max() > len(a.bc_names)):
        raise ValueError("mesh_from_arrays: seg_bc must be 1-based numbers into bc_names")

    m = nm.Mesh(dim=2)
    m.AddPoints(np.ascontiguousarray(np.column_stack([pts, np.zeros(nv)])))
    for r, name in enumerate(a.region_names, start=1):
        m.Add(nm.FaceDescriptor(bc=1, domin=r, surfnr=1))
        m.SetMaterial(r, name)
    # one bulk call per run of equal regions keeps the element order exactly
    starts = np.flatnonzero(np.r_[True, regions[1:] != regions[:-1]])
    for s, e in zip(starts, np.r_[starts[1:], regions.size]):
        m.AddElements(dim=2, index=int(regions[s]), data=np.ascontiguousarray(tris[s:e].astype(np.int32)), base=0)
    starts = np.flatnonzero(np.r_[True, seg_bc[1:] != seg_bc[:-1]]) if seg_bc.size else []
    for s, e in zip(starts, np.r_[starts[1:], seg_bc.size] if seg_bc.size else []):
        m.AddElements(dim=1, index=int(seg_bc[s]), data=np.ascontiguousarray(segs[s:e].astype(np.int32)), base=0)
    for b, name in enumerate(a.bc_names, start=1):
        m.SetBCName(b - 1, name)
    return ngsolve_mesh(m, len(tris))


def merge_meshes(*meshes):
    """One mesh holding several bodies that share no vertex (only contact couples them).

    Region and boundary names are merged by name: equal names become one region or
    one boundary.  Elements keep the order of the inputs, body after body.

    Parameters
    ----------
    *meshes : ngsolve.Mesh
        The bodies, 2D triangle meshes; vertices are numbered body after body.

    Returns
    -------
    ngsolve.Mesh
    """
    parts = [mesh_to_arrays(m) for m in meshes]
    region_names, bc_names = [], []
    pts, tris, regs, segs, sbc = [], [], [], [], []
    offset = 0
    for p in parts:
        for n in p.region_names:
            if n not in region_names:
                region_names.append(n)
        for n in p.bc_names:
            if n not in bc_names:
                bc_names.append(n)
        rmap = np.array([0] + [region_names.index(n) + 1 for n in p.region_names])
        bmap = np.array([0] + [bc_names.index(n) + 1 for n in p.bc_names])
        pts.append(p.points)
        tris.append(p.triangles + offset)
        regs.append(rmap[p.regions])
        segs.append(p.segments + offset)
        sbc.append(bmap[p.seg_bc])
        offset += p.points.shape[0]
    return mesh_from_arrays(MeshArrays(np.vstack(pts), np.vstack(tris), np.concatenate(regs),
                                       region_names, np.vstack(segs), np.concatenate(sbc), bc_names))


def _half_edge_membership(triangles, segments):
    """For each segment (p, q): is (p, q), is (q, p) a counter-clockwise triangle edge."""
    T = np.asarray(triangles, dtype=np.int64)
    S = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    n = int(max(T.max(initial=-1), S.max(initial=-1))) + 1
    # only triangles at a segment's vertex can hold it: a few, not the whole mesh, to sort
    on_segment = np.zeros(n, dtype=bool)
    on_segment[S.ravel()] = True
    T = T[on_segment[T].any(axis=1)]
    half = np.unique(T[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2) @ np.array([n, 1]))
    return np.isin(S @ np.array([n, 1]), half), np.isin(S[:, ::-1] @ np.array([n, 1]), half)


def orient_segments(triangles, segments):
    """Segments turned so that their triangle lies on their left.

    netgen orients the boundary of a hole (and an interface segment) with the domain on
    its right; the contact code needs the convention of the module docstring.

    Parameters
    ----------
    triangles : numpy.ndarray of int, shape (ne, 3)
        Counter-clockwise triangles.
    segments : numpy.ndarray of int, shape (ns, 2)
        Boundary segments in either orientation.

    Returns
    -------
    numpy.ndarray of int, shape (ns, 2)
        A copy; segments whose reverse is a triangle edge are reversed, the others kept.
    """
    S = np.array(segments, dtype=np.int64).reshape(-1, 2)
    forward, backward = _half_edge_membership(triangles, S)
    flip = backward & ~forward
    S[flip] = S[flip, ::-1]
    return S


def boundary_only(arrays):
    """The arrays with only the segments on the boundary of the triangles, oriented.

    Interface segments between bonded regions (an edge of two triangles) are dropped,
    boundary segments turned to have their triangle on the left (:func:`orient_segments`):
    what collision detection and contact expect.

    Parameters
    ----------
    arrays : MeshArrays
        A mesh whose segments may include interface segments or either orientation.

    Returns
    -------
    MeshArrays
        A new object sharing points and triangles.
    """
    forward, backward = _half_edge_membership(arrays.triangles, arrays.segments)
    keep = forward ^ backward
    S = np.asarray(arrays.segments, dtype=np.int64).reshape(-1, 2)
    S = np.where(forward[:, None], S, S[:, ::-1])[keep]
    return MeshArrays(arrays.points, arrays.triangles, arrays.regions, arrays.region_names, S,
                      np.asarray(arrays.seg_bc)[keep], arrays.bc_names)


def separate_region(mesh, region, boundary="interface", region_boundary=None):
    """The mesh with the triangles of ``region`` detached from the rest.

    Every vertex that a triangle of ``region`` shares with a triangle of another region
    gets a copy (same coordinates, numbered from nv on in increasing order of the
    original) used by the ``region`` triangles only. The edges the two sides shared
    become boundary on both sides: segments named ``boundary`` on the other side and
    ``region_boundary`` (default ``region + "_surface"``) on the region's side, each
    with its own triangle on the left. Segments that lay on those edges (netgen's
    interface segments) are replaced; all other segments are turned to have their
    triangle on the left (:func:`orient_segments`). Triangles keep their order.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh with counter-clockwise triangles.
    region : str
        Material name of the body to detach.
    boundary, region_boundary : str
        Names of the new boundaries on the two sides.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        If the mesh has no region ``region`` or it touches no other region.
    """
    a = mesh_to_arrays(mesh)
    region_boundary = region_boundary or f"{region}_surface"
    ids = [i for i, name in enumerate(a.region_names, start=1) if name == region]
    if not ids:
        raise ValueError(f"separate_region: no region {region!r}; the regions are {a.region_names}")
    inside = np.isin(a.regions, ids)
    T, nv = a.triangles, a.points.shape[0]
    shared = np.intersect1d(T[inside].ravel(), T[~inside].ravel())
    if shared.size == 0:
        raise ValueError(f"separate_region: region {region!r} shares no vertex with another region")
    copy = np.arange(nv)
    copy[shared] = nv + np.arange(shared.size)
    tris = T.copy()
    tris[inside] = copy[T[inside]]

    def half_edges(t):                        # directed edges, their triangle on the left
        return t[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    h_in, h_out = half_edges(T[inside]), half_edges(T[~inside])
    key_out = set(zip(h_out[:, 0].tolist(), h_out[:, 1].tolist()))
    common = np.array([(p, q) in key_out for p, q in zip(h_in[:, 1].tolist(), h_in[:, 0].tolist())],
                      dtype=bool)
    edges = h_in[common]                      # region side, original numbering
    drop = set(map(tuple, np.sort(edges, axis=1).tolist()))
    old = np.array([tuple(s) not in drop for s in np.sort(a.segments, axis=1).tolist()], dtype=bool)
    names = list(a.bc_names)
    for name in (boundary, region_boundary):
        if name not in names:
            names.append(name)
    # the region's own boundary segments use its copies
    own = set(map(tuple, np.sort(h_in, axis=1).tolist()))
    kept = a.segments[old]
    mine = np.array([tuple(e) in own for e in np.sort(kept, axis=1).tolist()], dtype=bool)
    kept = np.where(mine[:, None], copy[kept], kept)
    segments = np.vstack([orient_segments(tris, kept), edges[:, ::-1], copy[edges]])
    seg_bc = np.concatenate([a.seg_bc[old], np.full(len(edges), names.index(boundary) + 1),
                             np.full(len(edges), names.index(region_boundary) + 1)])
    return mesh_from_arrays(MeshArrays(np.vstack([a.points, a.points[shared]]), tris, a.regions,
                                       a.region_names, segments, seg_bc, names))


def check_mesh(mesh):
    """Raise ValueError unless mesh is a non-empty 2D NGSolve mesh.

    Parameters
    ----------
    mesh : object
        The object to check.

    Raises
    ------
    ValueError
        If mesh is not an ``ngsolve.Mesh``, is not 2D or has no elements.
    """
    if not isinstance(mesh, ng.Mesh):
        raise ValueError(f"mesh must be an ngsolve.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2:
        raise ValueError(f"ngfracture works on 2D meshes; this mesh has dimension {mesh.dim}")
    if mesh.ne == 0:
        raise ValueError("the mesh has no elements")


def element_vertices(mesh):
    """Vertex numbers of every triangle, 0-based.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D mesh.

    Returns
    -------
    numpy.ndarray of int64, shape (ne, 3)
        In element order.

    Raises
    ------
    ValueError
        If the mesh has quadrilaterals.
    """
    nodes = mesh.ngmesh.Elements2D().NumPy()["nodes"]
    if nodes.shape[1] > 3 and np.any(nodes[:, 3] != 0):
        raise ValueError("only triangular meshes are supported (the mesh has quadrilaterals)")
    return nodes[:, :3].astype(np.int64) - 1
