"""Rigid-body modes of the pieces of a mesh and how the constraints hold them.

A piece (connected component) whose rigid-body modes are not all fixed by
single-dof rows makes the eliminated stiffness K_ff singular.  If general rows
(contact, rigid-mode rows) fix the remaining modes, the KKT system is still
regular; linalg/kkt.py then factorises K with a few extra "pins" (one dof per unheld
mode) and restores the modes through a small coarse problem.  If nothing fixes
them, the body floats and the solve is refused with a message naming it.

All modes are the infinitesimal rigid motions at the current configuration; for
NGSolve's hierarchical H1 basis they live on the vertex dofs only.
"""
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

#: singular values up to this times max(largest, 1) count as zero (see numerical_rank)
RANK_RTOL = 1e-10


def numerical_rank(s, rtol=RANK_RTOL):
    """How many rigid modes a set of rows holds, from the singular values of rows x modes.

    One threshold for every "is this mode held" test (:func:`analyse_support`,
    :func:`unheld_mode_rows`, ``ElasticProblem.floating_bodies``), so that the solver
    never adds a hold that the floating-body check then calls missing, or the reverse.
    It is relative to the largest singular value, with a floor of 1 under it: the modes
    have entries of order 1 (coordinates relative to the piece's size, see
    :func:`piece_modes`) and the rows unit coefficients (single dofs, unit normals,
    interpolation weights), so a held mode has a singular value of order 1. Rows whose
    largest singular value is itself tiny (a contact row nearly orthogonal to the only
    mode it touches, 1e-12) hold nothing that a solve can use, and a purely relative test
    would count them.

    Parameters
    ----------
    s : array_like
        Singular values (any order; empty: rank 0).
    rtol : float
        The threshold.

    Returns
    -------
    int
    """
    s = np.asarray(s, dtype=float)
    return int(np.sum(s > rtol * max(s.max(initial=0.0), 1.0)))


def pieces(elements, nv):
    """Connected components of a triangle or tetrahedral mesh (through shared vertices).

    Parameters
    ----------
    elements : numpy.ndarray of int, shape (ne, 3) or (ne, 4)
        Triangle or tetrahedron vertex numbers.
    nv : int
        Number of vertices (a vertex in no triangle is a piece of its own).

    Returns
    -------
    count : int
        Number of pieces.
    piece : numpy.ndarray of int, shape (nv,)
        Piece id of every vertex.
    """
    # a chain of edges through an element's vertices connects them
    k = elements.shape[1]
    rows = np.concatenate([elements[:, j] for j in range(k - 1)])
    cols = np.concatenate([elements[:, j + 1] for j in range(k - 1)])
    graph = sp.coo_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(nv, nv))
    return connected_components(graph, directed=False)


def pieces_of_triangles(elements, nv, triangle_piece):
    """:func:`pieces` from a known piece number of every triangle (any numbering).

    The same count and numbering as :func:`pieces` (pieces numbered in the order of their
    smallest vertex, as scipy's connected_components does) without building the graph: a
    split mesh's fragments come from the crack engine.

    Parameters
    ----------
    elements : numpy.ndarray of int, shape (ne, 3)
    nv : int
    triangle_piece : numpy.ndarray of int, shape (ne,)
        The connected component of every triangle.

    Returns
    -------
    (int, numpy.ndarray) or None
        As :func:`pieces`; None if a vertex is in no triangle (a piece of its own there).

    Raises
    ------
    ValueError
        If ``triangle_piece`` does not have one entry per triangle, or gives two triangles
        that share a vertex different pieces.
    """
    elements = np.asarray(elements)
    tp = np.asarray(triangle_piece, dtype=np.int64)
    if tp.shape != (len(elements),):
        raise ValueError(f"triangle_piece must have one entry per triangle ({len(elements)}), got shape {tp.shape}")
    piece = np.full(nv, -1, dtype=np.int64)
    piece[elements.ravel()] = np.repeat(tp, elements.shape[1])
    if np.any(piece[elements] != tp[:, None]):
        raise ValueError("triangle_piece gives triangles that share a vertex different pieces")
    if nv and piece.min() < 0:
        return None
    # the piece of vertex 0 first, then that of the first vertex not in it, ...
    labels, first = np.unique(piece, return_index=True)
    rank = np.empty(len(labels), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(labels))
    renumber = np.zeros(labels.max(initial=-1) + 1, dtype=np.int64)
    renumber[labels] = rank
    return len(labels), renumber[piece].astype(np.int32)


def piece_modes(x, verts, n):
    """The rigid modes of one piece (3 in 2D, 6 in 3D) as dense columns over its vertex dofs.

    Parameters
    ----------
    x : numpy.ndarray, shape (nv, d)
        Vertex positions at which the modes are taken (d = 2 or 3).
    verts : numpy.ndarray of int, shape (k,)
        The vertices of the piece.
    n : int
        Scalar dofs per component (dof = c*n + v).

    Returns
    -------
    dofs : numpy.ndarray of int, shape (d k,)
        The x dofs, then the y dofs (then the z dofs) of verts.
    M : numpy.ndarray, shape (d k, 3) or (d k, 6)
        The translations, then the rotations about the centroid (about z in 2D; about x, y
        and z in 3D), scaled by the piece size for conditioning.
    """
    p = x[verts]
    rel = (p - p.mean(axis=0)) / max(np.ptp(p, axis=0).max(), 1e-300)
    k, d = verts.size, x.shape[1]
    M = np.zeros((d * k, rigid_mode_count(d)))
    for c in range(d):
        M[c * k:(c + 1) * k, c] = 1.0
    # a rotation about axis a moves component b by -rel_c and component c by rel_b
    axes = [(2, 0, 1)] if d == 2 else [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
    for j, (_, b, c) in enumerate(axes, start=d):
        M[b * k:(b + 1) * k, j] = -rel[:, c]
        M[c * k:(c + 1) * k, j] = rel[:, b]
    return np.concatenate([c * n + verts for c in range(d)]), M


def rigid_mode_count(dim):
    """The number of rigid modes of a free body: 3 in 2D, 6 in 3D.

    Parameters
    ----------
    dim : int
        2 or 3.

    Returns
    -------
    int
    """
    return dim * (dim + 1) // 2


@dataclass
class Support:
    """How the single-dof rows hold every piece.

    Parameters
    ----------
    modes : scipy.sparse.csc_matrix (ndof, k)
        Rigid modes that the single-dof rows leave free (zero on fixed dofs).
    pins : numpy.ndarray (k,)
        One free dof per such mode; pinning them makes K_ff regular.
    unheld : list of (int, int)
        (piece, number of free modes) of every piece with free modes.
    """
    modes: sp.csc_matrix
    pins: np.ndarray
    unheld: list


def analyse_support(x, elements, n, ndof, fixed_dofs, components=None):
    """Find the rigid modes left free by the single-dof rows, piece by piece.

    Parameters
    ----------
    x : numpy.ndarray (nv, 2)
        Current vertex positions.
    elements : numpy.ndarray (ne, 3)
        Triangle vertex numbers.
    n : int
        Scalar dofs per component (dof = c*n + v).
    ndof : int
        Number of dofs of the space.
    fixed_dofs : numpy.ndarray
        Dofs fixed by single-dof rows.
    components : (int, numpy.ndarray), optional
        :func:`pieces` of the mesh, if the caller has them.

    Returns
    -------
    Support
        The free modes of all pieces, their pins and the pieces they belong to.
    """
    nv = x.shape[0]
    ncomp, comp = components if components is not None else pieces(elements, nv)
    fixed = np.zeros(ndof, dtype=bool)
    fixed[fixed_dofs] = True
    order = np.argsort(comp, kind="stable")
    bounds = np.searchsorted(comp[order], np.arange(ncomp + 1))
    cols, pins, unheld = [], [], []
    for p in range(ncomp):
        verts = order[bounds[p]:bounds[p + 1]]
        dofs, M = piece_modes(x, verts, n)
        held = M[fixed[dofs]]
        # modes in the null space of the fixed rows: what the single-dof rows leave free
        if held.shape[0]:
            # reduce to at most 3x3 first: the full V of the SVD is then cheap
            _, s, vt = np.linalg.svd(np.linalg.qr(held, mode="r"), full_matrices=True)
            rank = numerical_rank(s)
            free_modes = vt[rank:].T
        else:
            free_modes = np.eye(M.shape[1])
        if free_modes.shape[1] == 0:
            continue
        N = M @ free_modes
        N[fixed[dofs]] = 0.0   # exactly zero there (they are, up to rounding)
        # pin the dofs that best resolve these modes (column-pivoted QR)
        _, _, piv = sla.qr(N.T, pivoting=True, mode="economic")
        pins.extend(dofs[piv[:N.shape[1]]].tolist())
        # one column per mode, built at the end: a sparse matrix per column cost 50 ms per
        # call with 20 pieces (scipy's construction overhead)
        for j in range(N.shape[1]):
            cols.append((dofs, N[:, j]))
        unheld.append((p, N.shape[1]))
    if cols:
        # column j holds its piece's dofs in increasing order: the CSC arrays directly
        row, data = (np.concatenate(part) for part in zip(*cols))
        indptr = np.concatenate([[0], np.cumsum([len(dofs) for dofs, _ in cols])])
        modes = sp.csc_matrix((data, row, indptr), shape=(ndof, len(cols)))
    else:
        modes = sp.csc_matrix((ndof, 0))
    return Support(modes, np.array(pins, dtype=np.int64), unheld)


def _groups(link):
    """Connected components of a symmetric boolean adjacency (k, k), numbered like scipy's
    connected_components (by smallest member); a search over the dense rows for a few
    dozen nodes, where scipy's call costs a millisecond."""
    k = link.shape[0]
    if k > 64:
        return connected_components(sp.csr_matrix(link) + sp.identity(k), directed=False)
    group = np.full(k, -1, dtype=np.int32)
    count = 0
    for start in range(k):
        if group[start] >= 0:
            continue
        group[start] = count
        frontier = [start]
        while frontier:
            reached = np.flatnonzero(link[frontier].any(axis=0) & (group < 0))
            group[reached] = count
            frontier = reached.tolist()
        count += 1
    return count, group


def unheld_mode_rows(C, modes, rtol=RANK_RTOL):
    """Rows that fix exactly the rigid modes that neither single-dof nor general rows hold.

    Parameters
    ----------
    C : scipy.sparse matrix (m, ndof)
        General constraint rows.
    modes : scipy.sparse matrix (ndof, k)
        Rigid modes left free by the single-dof rows (Support.modes).
    rtol : float
        Singular-value threshold for "held" (:func:`numerical_rank`).

    Returns
    -------
    scipy.sparse.csr_matrix (k', ndof)
        One row n^T per unheld mode n (a rigid mode, so its multiplier exerts no
        stress on the piece: it only stops the piece from drifting).
    """
    k = modes.shape[1]
    ndof = modes.shape[0]
    if k == 0:
        return sp.csr_matrix((0, ndof))
    # dense: m x k is small (rows times three modes per free piece), and slicing it per
    # group is much cheaper than slicing a sparse matrix
    G = (sp.csr_matrix(C) @ modes).toarray() if C.shape[0] else np.zeros((0, k))
    # modes coupled through rows form groups; each group is a small dense problem
    ngroups, group = _groups(np.abs(G).T @ np.abs(G) != 0.0)
    rows = []
    for gidx in range(ngroups):
        cols = np.flatnonzero(group == gidx)
        sub = G[:, cols]
        touched = np.flatnonzero(np.any(sub != 0.0, axis=1))
        if touched.size:
            dense = sub[touched]
            _, s, vt = np.linalg.svd(np.linalg.qr(dense, mode="r") if dense.shape[0] > cols.size else dense,
                                     full_matrices=True)
            rank = numerical_rank(s, rtol)
            null = vt[rank:].T
        else:
            null = np.eye(cols.size)
        if null.shape[1]:
            rows.append((modes[:, cols] @ sp.csr_matrix(null)).T.tocsr())
    return sp.vstack(rows).tocsr() if rows else sp.csr_matrix((0, ndof))
