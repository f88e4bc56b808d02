"""Cracks from interior surfaces of a tetrahedral mesh: the faces open into two lips.

:func:`open_internal_surface` turns a set of interior faces (an OCC face glued into a box, the
faces of a structured mesh on a plane) into a crack by node splitting: every vertex of the
surface that is not on its front is duplicated (bitwise-equal coordinates), the copy going
to the tets on the side the faces' normals point to, and both lips become boundary faces
named ``crack``, oriented out of the body. The front is the part of the surface's rim that
lies inside the body (the rim's edges that are not edges of boundary faces): its vertices
stay shared, and the two lips meet there. Where the rim lies on the body's boundary (a
through crack meeting the outer faces) the rim's vertices are duplicated too, so the crack
opens at the surface. Tets keep their vertices' coordinates, so every volume is unchanged to
the last bit.

Vectorised numpy and scipy's connected components; no per-element Python loop.
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .solid import SolidArrays

__all__ = ["open_internal_surface"]

_WHO = "ngfracture.geometry.internal_crack"


def _keys(tri, nv):
    """One int64 key per triangle, independent of its vertex order."""
    s = np.sort(tri, axis=1).astype(np.int64)
    return (s[:, 0] * nv + s[:, 1]) * nv + s[:, 2]


def _tet_faces(tets, nv):
    """Keys of the 4 faces of every tet (face i opposite local vertex i), shape (ne, 4)."""
    opp = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    return _keys(tets[:, opp].reshape(-1, 3), nv).reshape(-1, 4)


def _check(arrays, faces):
    if not isinstance(arrays, SolidArrays):
        raise ValueError(f"{_WHO}: expected SolidArrays, got {type(arrays).__name__}")
    pts = np.asarray(arrays.points, dtype=float)
    tets = np.asarray(arrays.tets, dtype=np.int64)
    nv = len(pts)
    if nv >= 2 ** 21:
        raise ValueError(f"{_WHO}: at most {2 ** 21 - 1} vertices, the mesh has {nv}")
    F = np.asarray(faces, dtype=np.int64)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise ValueError(f"{_WHO}: faces must be a non-empty (m, 3) array, got shape {F.shape}")
    if F.min() < 0 or F.max() >= nv:
        raise ValueError(f"{_WHO}: face vertex numbers must lie in [0, {nv})")
    return pts, tets, F


def _face_tets(tets, F, nv):
    """The two tets of every face and its local face index in each: (m, 2) tets, (m, 2) slots."""
    tf = _tet_faces(tets, nv).ravel()
    order = np.argsort(tf, kind="stable")
    fk = _keys(F, nv)
    lo = np.searchsorted(tf[order], fk, side="left")
    hi = np.searchsorted(tf[order], fk, side="right")
    bad = np.flatnonzero(hi - lo != 2)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{_WHO}: face {i} {F[i].tolist()} is not an interior face of the mesh "
                         f"(it belongs to {int(hi[i] - lo[i])} tets, an interior face to 2)")
    slots = order[np.stack([lo, lo + 1], axis=1)]
    return slots // 4, slots % 4


def _check_orientation(F):
    """Every edge shared by two faces is run both ways (one side of the surface is 'plus')."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    und = np.sort(e, axis=1)
    _, inv, counts = np.unique(und, axis=0, return_inverse=True, return_counts=True)
    if counts.max() > 2:
        raise ValueError(f"{_WHO}: the edge {und[np.argmax(counts[inv])].tolist()} belongs to more than two faces")
    _, dcounts = np.unique(e, axis=0, return_counts=True)
    if dcounts.max() > 1:
        raise ValueError(f"{_WHO}: the faces are not consistently oriented (an edge is run the same way twice)")
    return und[counts[inv] == 1]                   # the rim: edges of one face


def _front_vertices(rim, arrays, nv, crack_keys):
    """Vertices of the rim edges that are not edges of boundary faces (inside the body); the
    surface's own faces, if the mesh lists them among its boundary faces, do not count."""
    bf = np.asarray(arrays.faces, dtype=np.int64).reshape(-1, 3)
    bf = bf[~np.isin(_keys(bf, nv), crack_keys)]
    be = np.sort(np.concatenate([bf[:, [0, 1]], bf[:, [1, 2]], bf[:, [2, 0]]]), axis=1)
    bkeys = np.unique(be[:, 0] * nv + be[:, 1])
    inside = ~np.isin(rim[:, 0] * nv + rim[:, 1], bkeys)
    return np.unique(rim[inside])


def _plus_tets(pts, tets, F, ftets, fslots):
    """Of the two tets of every face, the one its normal points into: (m,) plus, (m,) minus."""
    n = np.cross(pts[F[:, 1]] - pts[F[:, 0]], pts[F[:, 2]] - pts[F[:, 0]])
    apex = pts[tets[ftets[:, 0], fslots[:, 0]]]
    first_plus = np.einsum("ij,ij->i", apex - pts[F[:, 0]], n) > 0
    plus = np.where(first_plus, ftets[:, 0], ftets[:, 1])
    minus = np.where(first_plus, ftets[:, 1], ftets[:, 0])
    return plus, minus


def _side_components(tets, nv, dup_mask, crack_keys):
    """Connected components of the (tet, vertex) slots of duplicated vertices, joined across
    the tet faces that are not crack faces: each duplicated vertex's tets fall into sides."""
    ne = len(tets)
    tf = _tet_faces(tets, nv).ravel()
    order = np.argsort(tf, kind="stable")
    s = tf[order]
    pair = np.flatnonzero(s[1:] == s[:-1])
    a, b = order[pair], order[pair + 1]                  # slots 4 t + face index of shared faces
    keep = ~np.isin(s[pair], crack_keys)
    a, b = a[keep], b[keep]
    ta, fa, tb = a // 4, a % 4, b // 4
    rows, cols = [], []
    for k in range(1, 4):                                # the face's three vertices in tet a
        la = (fa + k) % 4
        v = tets[ta, la]
        lb = np.argmax(tets[tb] == v[:, None], axis=1)
        m = dup_mask[v]
        rows.append(4 * ta[m] + la[m])
        cols.append(4 * tb[m] + lb[m])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    g = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(4 * ne, 4 * ne))
    return connected_components(g, directed=False)[1]


def open_internal_surface(arrays, faces, crack_name="crack"):
    """Open interior faces of a tetrahedral mesh into a crack (module docstring).

    Parameters
    ----------
    arrays : SolidArrays
        The mesh; ``faces`` are interior faces of it (each shared by two tets). Boundary
        faces that coincide with them (an internal OCC face) are dropped.
    faces : numpy.ndarray of int
        Shape (m, 3), consistently oriented (every edge shared by two of them run both ways);
        the copies of the vertices go to the side the normals point to.
    crack_name : str
        The boundary name of both lips.

    Returns
    -------
    SolidArrays
        New arrays: the copies appended to the points (bitwise equal), the tets on the plus
        side renumbered, the lips added as boundary faces named ``crack_name``.

    Raises
    ------
    ValueError
        A face that is not an interior face, faces not consistently oriented, a face with
        all three vertices on the front (it cannot open), a vertex whose tets the surface
        does not separate into two sides.
    """
    pts, tets, F = _check(arrays, faces)
    nv = len(pts)
    ftets, fslots = _face_tets(tets, F, nv)
    rim = _check_orientation(F)
    crack_keys = _keys(F, nv)
    front = _front_vertices(rim, arrays, nv, crack_keys)
    surface = np.unique(F)
    dup = np.setdiff1d(surface, front)
    dup_mask = np.zeros(nv, bool)
    dup_mask[dup] = True
    stuck = np.flatnonzero(~dup_mask[F].any(axis=1))
    if stuck.size:
        raise ValueError(f"{_WHO}: face {int(stuck[0])} {F[stuck[0]].tolist()} has all its vertices on the "
                         "front and cannot open")
    comp = _side_components(tets, nv, dup_mask, crack_keys)
    plus, minus = _plus_tets(pts, tets, F, ftets, fslots)
    # the side of each duplicated vertex: the component of its slot in the plus tets
    side = np.full(nv, -1, dtype=np.int64)
    fv = F.ravel()
    slot_plus = 4 * np.repeat(plus, 3) + np.argmax(tets[np.repeat(plus, 3)] == fv[:, None], axis=1)
    slot_minus = 4 * np.repeat(minus, 3) + np.argmax(tets[np.repeat(minus, 3)] == fv[:, None], axis=1)
    m = dup_mask[fv]
    side[fv[m]] = comp[slot_plus[m]]
    if np.any(side[fv[m]] != comp[slot_plus[m]]) or np.any(comp[slot_minus[m]] == side[fv[m]]):
        v = int(fv[m][np.flatnonzero((side[fv[m]] != comp[slot_plus[m]]) | (comp[slot_minus[m]] == side[fv[m]]))[0]])
        raise ValueError(f"{_WHO}: the surface does not separate the tets of vertex {v} into two sides")
    copy_of = np.full(nv, -1, dtype=np.int64)
    copy_of[dup] = nv + np.arange(len(dup))
    flat = tets.ravel()
    moved = dup_mask[flat] & (comp == side[flat])
    new_tets = flat.copy()
    new_tets[moved] = copy_of[flat[moved]]
    new_tets = new_tets.reshape(-1, 4)
    return _assemble(arrays, pts, tets, new_tets, F, copy_of, crack_keys, crack_name)


def _assemble(arrays, pts, tets, new_tets, F, copy_of, crack_keys, crack_name):
    """The new SolidArrays: boundary faces renumbered through their tets, the lips added."""
    nv = len(pts)
    bf = np.asarray(arrays.faces, dtype=np.int64).reshape(-1, 3)
    bc = np.asarray(arrays.face_bc, dtype=np.int64).reshape(-1)
    keep = ~np.isin(_keys(bf, nv), crack_keys)
    bf, bc = bf[keep], bc[keep]
    if len(bf):
        # every remaining boundary face takes the vertices of its (one) tet
        tf = _tet_faces(tets, nv).ravel()
        order = np.argsort(tf, kind="stable")
        pos = np.searchsorted(tf[order], _keys(bf, nv))
        if np.any(pos >= len(tf)) or np.any(tf[order][np.minimum(pos, len(tf) - 1)] != _keys(bf, nv)):
            raise ValueError(f"{_WHO}: a boundary face is not a face of any tet")
        owner = order[pos] // 4
        local = np.argmax(tets[owner][:, None, :] == bf[:, :, None], axis=2)
        bf = new_tets[owner[:, None], local]
    names = list(arrays.bc_names)
    if crack_name not in names:
        names.append(crack_name)
    cid = names.index(crack_name) + 1
    plus_lip = np.where(copy_of[F] >= 0, copy_of[F], F)[:, [0, 2, 1]]
    faces = np.concatenate([bf, F, plus_lip])
    face_bc = np.concatenate([bc, np.full(2 * len(F), cid, dtype=np.int64)])
    points = np.concatenate([pts, pts[copy_of >= 0][np.argsort(copy_of[copy_of >= 0])]])
    return SolidArrays(points=points, tets=new_tets, regions=np.asarray(arrays.regions).copy(),
                       region_names=list(arrays.region_names), faces=faces, face_bc=face_bc, bc_names=names)
