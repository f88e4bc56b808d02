"""A tetrahedral mesh cut into pieces along the faces between them: a fragmented body.

:func:`separate_pieces` gives every vertex one copy per piece whose tetrahedra hold it
(bitwise-equal coordinates), so tetrahedra of different pieces no longer share a face, and
adds the faces between pieces as crack lips (boundary name ``crack``, two coincident faces,
each oriented out of its tetrahedron): the mesh of a body broken into those pieces, with
the lips closed, as the node splitting leaves a crack (docs/solid.md, "Node splitting in
3D"). It is the 3D form of the cut of ``benchmarks/contact.py`` and the fragmented body of
``benchmarks/contact3d.py``.

:func:`fragmented_box` is a structured box (:func:`~ngfracture.geometry.structured.box_mesh`,
6 tets per cell) cut by grid planes into ``pieces`` x ``pieces`` x ``pieces`` blocks: every
lip is exactly on a plane and its two faces match vertex for vertex, so a compression of
the box closes every lip at every vertex (a node-to-node contact on all of them, junctions
of 4 pieces along the lines and of 8 at the points where planes cross).

Everything is vectorised numpy; numbering is deterministic: the copies of a vertex are
numbered in the order of (vertex, piece), the input faces keep their order and the lips
follow in the order of their tetrahedra.
"""
import numpy as np

from .solid import OUTWARD_FACES, SolidArrays, face_keys
from .structured import box_mesh

__all__ = ["separate_pieces", "fragmented_box"]

#: vertex numbers up to this bound keep a face's key (three numbers) within int64
MAX_VERTICES = 2**21


def separate_pieces(arrays, piece, crack="crack"):
    """The mesh with every vertex copied per piece and the faces between pieces as lips.

    Parameters
    ----------
    arrays : SolidArrays
        A conforming mesh (every face in at most two tetrahedra).
    piece : array_like of int, shape (ne,)
        The piece of every tetrahedron (any integers; a piece need not be connected).
    crack : str
        The boundary name of the new faces.

    Returns
    -------
    SolidArrays
        Vertices numbered by (input vertex, piece) (a vertex in no tetrahedron is dropped),
        tetrahedra in the input order with their regions, the input boundary faces in their
        order, then the lips (both of every face between two pieces, in the order of their
        tetrahedra); ``bc_names`` the input's plus ``crack`` where it is new.
    parent : numpy.ndarray of int, shape (nv_new,)
        The input vertex of every vertex.

    Raises
    ------
    ValueError
        If ``piece`` does not hold one integer per tetrahedron, a face is in more than two
        tetrahedra, the input's faces are not exactly its boundary faces, or the cut mesh
        would have ``MAX_VERTICES`` vertices or more.
    """
    T = np.asarray(arrays.tets, dtype=np.int64)
    nv, ne = len(arrays.points), len(T)
    piece = np.asarray(piece)
    if piece.shape != (ne,) or (ne and not np.issubdtype(piece.dtype, np.integer)):
        raise ValueError(f"piece must be integers of shape ({ne},), got {piece.dtype} {piece.shape}")
    _, piece = np.unique(piece, return_inverse=True)
    npiece = int(piece.max(initial=-1)) + 1
    key = T * npiece + piece.reshape(-1, 1)
    uniq, inverse = np.unique(key.ravel(), return_inverse=True)
    parent = uniq // max(npiece, 1)
    tets = inverse.reshape(T.shape)
    # every face of every tetrahedron, outward; a face of one tetrahedron only is a boundary face
    tri = tets[:, OUTWARD_FACES].reshape(-1, 3)
    old = T[:, OUTWARD_FACES].reshape(-1, 3)
    new_keys, old_keys = face_keys(tri, len(parent)), face_keys(old, nv)
    _, new_inv, new_count = np.unique(new_keys, return_inverse=True, return_counts=True)
    _, old_inv, old_count = np.unique(old_keys, return_inverse=True, return_counts=True)
    if old_count.size and old_count.max() > 2:
        raise ValueError("separate_pieces: a face is in more than two tetrahedra (the mesh is not conforming)")
    if max(nv, len(parent)) >= MAX_VERTICES:
        raise ValueError(f"separate_pieces: {max(nv, len(parent))} vertices, at most {MAX_VERTICES - 1}")
    single = new_count[new_inv.ravel()] == 1
    inner = old_count[old_inv.ravel()] == 2
    lips = np.flatnonzero(single & inner)
    # the input's boundary faces: the face of its one tetrahedron with the same vertices
    outer = np.flatnonzero(single & ~inner)
    F = np.asarray(arrays.faces, dtype=np.int64).reshape(-1, 3)
    order = np.argsort(old_keys[outer], kind="stable")
    wanted = face_keys(F, nv)
    at = np.searchsorted(old_keys[outer][order], wanted)
    if len(F) != len(outer) or (len(F) and np.any(old_keys[outer][order][np.minimum(at, len(outer) - 1)] != wanted)):
        raise ValueError(f"separate_pieces: the input's {len(F)} faces are not its {len(outer)} boundary faces")
    faces = np.concatenate([tri[outer[order[at]]], tri[lips]])
    names = list(arrays.bc_names)
    if crack not in names:
        names.append(crack)
    face_bc = np.concatenate([np.asarray(arrays.face_bc, dtype=np.int64).reshape(-1),
                              np.full(len(lips), names.index(crack) + 1, dtype=np.int64)])
    out = SolidArrays(points=np.asarray(arrays.points, dtype=float)[parent], tets=tets,
                      regions=np.asarray(arrays.regions).copy(), region_names=list(arrays.region_names),
                      faces=faces, face_bc=face_bc, bc_names=names)
    return out, parent


def fragmented_box(cells, pieces, size=1.0):
    """A cube of ``cells``^3 structured cells cut by grid planes into ``pieces``^3 blocks.

    Parameters
    ----------
    cells : int
        Cells along every edge (6 tetrahedra each: 6 cells^3 tetrahedra).
    pieces : int
        Blocks along every edge (2 <= pieces <= cells); the cuts are the grid planes
        nearest to ``i size / pieces``, i = 1 ... pieces - 1 (blocks differ by at most one
        cell where ``pieces`` does not divide ``cells``).
    size : float
        The cube's edge; it spans [0, size]^3.

    Returns
    -------
    arrays : SolidArrays
        Boundary names ``xmin`` ... ``zmax`` (the cube's faces) and ``crack`` (the lips),
        one region ``body``.
    piece : numpy.ndarray of int, shape (ne,)
        The block of every tetrahedron, ``(i * pieces + j) * pieces + k`` for the block
        i, j, k along x, y, z.

    Raises
    ------
    ValueError
        If ``cells`` or ``pieces`` is not an integer, ``pieces`` not in [2, cells], or
        ``size`` not a finite number > 0.
    """
    counts = tuple(pieces) if isinstance(pieces, (tuple, list)) else (pieces,) * 3
    for name, value in (("cells", cells),) + tuple(("pieces", c) for c in counts):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"fragmented_box: {name} must be an integer, got {value!r}")
    if len(counts) != 3 or not all(1 <= c <= cells for c in counts) or max(counts) < 2:
        raise ValueError(f"fragmented_box: pieces must be one or three integers in [1, cells = {cells}], "
                         f"not all 1, got {pieces!r}")
    if isinstance(size, bool) or not (np.isscalar(size) and np.isfinite(size) and size > 0):
        raise ValueError(f"fragmented_box: size must be a finite number > 0, got {size!r}")
    grid = np.linspace(0.0, float(size), cells + 1)
    box = box_mesh(grid, grid, grid)
    centre = box.points[box.tets].mean(axis=1)
    block = [np.searchsorted(grid[np.rint(np.arange(1, c) * cells / c).astype(np.int64)], centre[:, d], side="right")
             for d, c in enumerate(counts)]                         # the block along x, y, z
    piece = (block[0] * counts[1] + block[1]) * counts[2] + block[2]
    arrays, _ = separate_pieces(box, piece)
    return arrays, piece
