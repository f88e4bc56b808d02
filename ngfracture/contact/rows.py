"""Node-to-segment contact constraints and redundancy removal (paper section 3.2).

Pipeline for one (predicted) configuration::

    pairs = collision.detect_collisions(X, U, tris, boundary_edges=E, tol=tol)
    cs = select_contacts(X, U, tris, E, pairs, tol=tol)       # rules 1-4, eq. 13/14
    keep = independent_rows(cs.C, fixed_dofs=dirichlet_dofs)  # pivoted QR
    C, g = cs.C[keep], cs.g[keep]

or :func:`contact_constraints` for all of it. Where two lips coincide in the reference
configuration (crack faces, split interfaces) ContactSolver uses the node-to-node rows of
:mod:`ngfracture.contact.seams` instead: there rules 1-4 have no stable answer.

Dof layout: component-blocked, as NGSolve's P1 ``VectorH1``: the dof of component ``comp``
(0 = x, 1 = y) of vertex ``v`` is ``comp * nv + v`` (x dofs 0..nv-1, then y dofs nv..2nv-1).

Gap and sign convention: for slave vertex b and master boundary edge (a, c) (master
triangle on the left of a -> c), with xi and the outward unit normal n of the master edge
frozen at the predicted configuration x = X + U (eq. 13),

    g_N(u) = n . ( (X_b + u_b) - xi (X_a + u_a) - (1 - xi) (X_c + u_c) ) = C u + g,

the signed distance of the slave node from the master segment: positive = separated,
negative = penetration (the paper's "distance is negative in case of penetration"). This
is eq. 14 with the paper's n taken as the master's *inward* normal. C is (m, 2 nv), u the
total displacement in the layout above, g = C-row applied to the reference coordinates.
The non-penetration condition is g_N >= 0; an active constraint imposes C u + g = 0. For a
Newton increment du from u_k use C du = -(C u_k + g). With eq. 12 written as
[[K, G^T, C^T], [G, 0, 0], [C, 0, 0]] [u; lambda_D; lambda_c] = [f; b; -g], compressive
contact gives lambda_c <= 0 (the paper's p_N <= 0, tested); lambda_c > 0 is adhesive and
the row is to be released by the active-set loop. For any rigid translation of the
whole configuration C u is unchanged, and for translations of the slave relative to the
master C u + g is the exact signed distance.

Selection rules (per colliding pair, see ``SelectContacts`` in cpp_ext/collision.cpp):

1. per pair and direction (master, slave) at most one constraint, hence at most two per
   pair and each element at most once as master and once as slave;
2. the master segment is a boundary/crack edge of the master triangle; a slave
   candidate is a vertex of the other triangle (not an end of the segment) whose
   projection lies on the segment (up to tol / |segment|, then clamped: node-to-node for
   xi = 0 or 1) and whose signed distance d satisfies -height < d <= tol, height being
   the master's height over that edge (deeper nodes have gone past the element; the node
   need not lie inside the master itself: it may sit in a neighbour that touches the
   boundary only at a vertex, which is not a candidate element), and the master edge's
   normal faces the slave body's boundary normal at the node (their dot product is
   negative; the slave normal is the sum of the normals of the slave triangle's boundary
   edges at the node, if it has any). A node's distance to
   the master is that of its nearest way out, the largest d over the master's boundary
   edges; the node with the smallest distance (deepest penetration) wins;
3. nodes equally deep within the precision threshold (at least 1e-12 of the element
   size) are ranked: nodes not yet in contact first (our addition: a node is in contact
   once it is the slave of an earlier constraint, or the partner end of an earlier
   (near, within xi_snap) node-to-node constraint; where a mesh meets the other body in
   one triangle pair per cell, rule 1 would otherwise always pick the same end of each
   cell and leave the last node of the interface free), then by the angle between the
   master segment and the node's two edges in the slave triangle, smallest first; the
   chosen angle must be <= angle_tol (the default pi/2 only ranks, it rejects nothing);
4. otherwise no constraint.

Identical constraints (same slave, a, c) found through different pairs are merged.

Threshold: with tol = 0 only pairs whose interiors overlap produce rows, so a contact
closed by a solve (gap 0) is no longer detected at the next linearisation. For repeated
detect-and-solve loops use tol > 0 (0.1 h worked in the tests); the rows with a positive
gap it adds are what the active set must release when their multiplier is adhesive.
"""
from dataclasses import dataclass
import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, reverse_cuthill_mckee

from .. import _ngfracture as _ext
from .collision import (_as_array, _check_tol, _check_tris, boundary_edge_mask,
                        current_coordinates, detect_collisions)

__all__ = ["ContactConstraints", "select_contacts", "gap_rows", "independent_rows",
           "contact_constraints"]


@dataclass
class ContactConstraints:
    """Node-to-segment constraints, one entry per row of C.

    Parameters
    ----------
    slave, a, c : numpy.ndarray of int, shape (m,)
        Slave vertex and master edge a -> c.
    master_tri, slave_tri, pair : numpy.ndarray of int, shape (m,)
        Master and slave triangle, index of the colliding pair that produced the row.
    xi : numpy.ndarray, shape (m,)
        Projection parameter of eq. 13 (x'_b = xi x_a + (1 - xi) x_c), in [0, 1].
    normal : numpy.ndarray, shape (m, 2)
        Outward unit normal of the master edge at the predicted configuration.
    dist : numpy.ndarray, shape (m,)
        Signed distance at the predicted configuration (negative = penetration).
    angle : numpy.ndarray, shape (m,)
        Rule-3 angle (radians) between master edge and slave edges.
    g : numpy.ndarray, shape (m,)
        Constant part: C u + g is the linearised signed gap.
    nv : int
        Number of vertices (C has 2 nv columns).

    Attributes
    ----------
    C : scipy.sparse.csr_matrix, shape (m, 2 nv)
        Gap rows (component-blocked dofs), :func:`gap_rows` of slave, a, c, xi and normal;
        built at first use and kept. Selecting and stacking rows never touches it: the
        contact rounds select and stack rows tens of times per solve and use few of the
        matrices.
    """
    slave: np.ndarray
    a: np.ndarray
    c: np.ndarray
    master_tri: np.ndarray
    slave_tri: np.ndarray
    pair: np.ndarray
    xi: np.ndarray
    normal: np.ndarray
    dist: np.ndarray
    angle: np.ndarray
    g: np.ndarray
    nv: int

    def __len__(self):
        return len(self.g)

    @functools.cached_property
    def C(self):
        """The gap rows as a sparse matrix, shape (m, 2 nv), built at first use (see the class)."""
        return _gap_matrix(self.slave, self.a, self.c, self.xi, self.normal, self.nv)

    @classmethod
    def stack(cls, parts):
        """The rows of several ContactConstraints (same number of dofs), in order.

        Parameters
        ----------
        parts : sequence of ContactConstraints
            At least one; all with the same number of columns in C.

        Returns
        -------
        ContactConstraints
            The rows of ``parts[0]``, then those of ``parts[1]``, ...

        Raises
        ------
        ValueError
            Parts of meshes with different numbers of vertices.
        """
        nv = parts[0].nv
        if any(p.nv != nv for p in parts):
            raise ValueError(f"ContactConstraints.stack: rows of meshes with {sorted(set(p.nv for p in parts))} vertices")
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in _ROW_FIELDS), nv=nv)

    def subset(self, rows):
        """The constraints ``rows`` (an index array or boolean mask), C and g included.

        Parameters
        ----------
        rows : array_like of int or bool
            Row indices (in the order wanted) or a mask of shape (m,).

        Returns
        -------
        ContactConstraints
            New arrays holding the selected rows.
        """
        rows = np.asarray(rows)
        if rows.dtype != bool:
            rows = rows.astype(np.int64)
        return ContactConstraints(*(getattr(self, f)[rows] for f in _ROW_FIELDS), nv=self.nv)


def _no_constraints(nv):
    e = np.zeros(0, dtype=np.int32)
    f = np.zeros(0)
    return ContactConstraints(slave=e, a=e, c=e, master_tri=e, slave_tri=e, pair=e, xi=f,
                              normal=np.zeros((0, 2)), dist=f, angle=f, g=f, nv=nv)


#: the per-row arrays of ContactConstraints, in constructor order
_ROW_FIELDS = ("slave", "a", "c", "master_tri", "slave_tri", "pair", "xi", "normal", "dist", "angle", "g")


def gap_rows(coords, slave, a, c, xi, normal):
    """Rows of the linearised gap (eq. 14): C u + g = n . (x_b - xi x_a - (1 - xi) x_c).

    Parameters
    ----------
    coords : array_like, shape (nv, 2)
        Reference vertex coordinates X.
    slave, a, c : array_like of int, shape (m,)
        Slave vertex and master edge end points.
    xi : array_like, shape (m,)
        Weight of x_a in the projection point.
    normal : array_like, shape (m, 2)
        Unit normals (outward from the master, towards the slave).

    Returns
    -------
    C : scipy.sparse.csr_matrix, shape (m, 2 nv)
        Component-blocked dofs: dof(v, comp) = comp * nv + v.
    g : numpy.ndarray, shape (m,)
        n . (X_b - xi X_a - (1 - xi) X_c).

    Raises
    ------
    ValueError
        On inconsistent shapes or indices out of range.
    """
    X = current_coordinates(coords)
    nv = X.shape[0]
    slave, a, c = (np.asarray(v, dtype=np.int64).ravel() for v in (slave, a, c))
    xi = np.asarray(xi, dtype=np.float64).ravel()
    n = _as_array(normal, "normal", np.float64, 2)
    m = len(slave)
    if not (len(a) == len(c) == len(xi) == n.shape[0] == m):
        raise ValueError("slave, a, c, xi and normal must have the same length")
    if not (np.isfinite(xi).all() and np.isfinite(n).all()):
        raise ValueError("xi and normal must be finite")
    for name, v in (("slave", slave), ("a", a), ("c", c)):
        if m and (v.min() < 0 or v.max() >= nv):
            raise ValueError(f"{name} holds vertex indices outside [0, {nv})")
    return _gap_matrix(slave, a, c, xi, n, nv), _gap_offset(X, slave, a, c, xi, n)


def _gap_weights(xi):
    return np.stack([np.ones(len(xi)), -xi, xi - 1.0], axis=1)     # weights of b, a, c


def _gap_matrix(slave, a, c, xi, n, nv):
    """C of :func:`gap_rows`, for arrays already checked."""
    m = len(slave)
    w = _gap_weights(xi)
    verts = np.stack([slave, a, c], axis=1).astype(np.int64)
    rows = np.repeat(np.arange(m), 6)
    cols = np.concatenate([verts, verts + nv], axis=1).ravel()  # x dofs, then y dofs
    vals = np.concatenate([w * n[:, :1], w * n[:, 1:]], axis=1).ravel()
    C = sp.csr_matrix((vals, (rows, cols)), shape=(m, 2 * nv))
    C.eliminate_zeros()                                          # xi = 0 or 1: node-to-node
    return C


def _gap_offset(X, slave, a, c, xi, n):
    """g of :func:`gap_rows`, for arrays already checked."""
    verts = np.stack([slave, a, c], axis=1)
    pos = np.einsum("ij,ijk->ik", _gap_weights(xi), X[verts])      # X_b - xi X_a - (1-xi) X_c
    return np.einsum("ij,ij->i", pos, n)


def select_contacts(coords, displacement, tris, boundary_edges, pairs, tol=0.0,
                    angle_tol=np.pi / 2, xi_snap=1e-2):
    """Node-to-segment constraints for colliding pairs by the paper's rules 1-4.

    Parameters
    ----------
    coords, displacement : array_like, shape (nv, 2)
        Reference coordinates and the predicted displacement (without contact); n and
        xi are frozen at coords + displacement.
    tris : array_like, shape (nt, 3)
        Triangles, counter-clockwise in the reference configuration.
    boundary_edges : array_like, shape (ne, 2)
        Directed boundary / crack edges with their triangle on the left.
    pairs : array_like of int, shape (k, 2)
        Colliding pairs, e.g. from :func:`ngfracture.contact.collision.detect_collisions`.
    tol : float
        Precision threshold (a length, >= 0): the largest signed distance of a slave.
    angle_tol : float
        Largest rule-3 angle, in [0, pi/2].
    xi_snap : float
        Projections within xi_snap (a fraction of the segment length, in [0, 0.5)) of
        an end of the segment are snapped to it: node-to-node (xi = 0 or 1). This leaves
        g at the predicted state unchanged (the projection point moves along the
        segment, perpendicular to n) and turns the two opposite rows between nearly
        coincident crack-lip nodes into exact duplicates. Without it they are
        near-duplicates, with singular values spread down to 1e-16 (measured on the
        benchmark scene), which no rank threshold separates cleanly; with 1e-3 the kept
        rows still had sigma_min 1e-10 and multipliers of 1e9 in a repeated
        detect-and-solve loop, with 1e-2 the loop converged (see
        test_repeated_linearised_solves_converge). 0 disables it.

    Returns
    -------
    ContactConstraints
        In pair order; for each pair first the first triangle as master.

    Raises
    ------
    ValueError
        On wrong shapes, non-finite input, indices out of range, tol < 0 or angle_tol
        outside [0, pi/2].
    """
    tol = _check_tol(tol)
    if not np.isscalar(angle_tol) or not (0 <= angle_tol <= np.pi / 2):
        raise ValueError(f"angle_tol must be in [0, pi/2], got {angle_tol!r}")
    if not np.isscalar(xi_snap) or not (0 <= xi_snap < 0.5):
        raise ValueError(f"xi_snap must be in [0, 0.5), got {xi_snap!r}")
    X = current_coordinates(coords)
    x = current_coordinates(coords, displacement)
    T = _check_tris(tris, x.shape[0])
    P = _as_array(pairs, "pairs", np.int32, 2)
    if P.size and (P.min() < 0 or P.max() >= T.shape[0]):
        raise ValueError(f"pairs holds triangle indices outside [0, {T.shape[0]})")
    if np.any(P[:, 0] == P[:, 1]):
        raise ValueError("pairs must pair two different triangles")
    if P.shape[0] == 0:
        ids, geo = np.zeros((0, 6), np.int32), np.zeros((0, 5))
    else:
        mask = boundary_edge_mask(T, boundary_edges, x.shape[0])
        ids, geo = _ext.SelectContacts(x, T, mask.view(np.uint8), P, tol, float(angle_tol),
                                       float(xi_snap))
    # The same node-segment constraint can come from several pairs: keep the first.
    key = ids[:, :3].astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    first.sort()
    ids, geo = ids[first], geo[first].copy()
    xi = geo[:, 0]
    xi[xi < xi_snap] = 0.0
    xi[xi > 1.0 - xi_snap] = 1.0
    return ContactConstraints(
        slave=ids[:, 0], a=ids[:, 1], c=ids[:, 2], master_tri=ids[:, 3],
        slave_tri=ids[:, 4], pair=ids[:, 5], xi=geo[:, 0], normal=geo[:, 1:3].copy(),
        dist=geo[:, 3], angle=geo[:, 4],
        g=_gap_offset(X, ids[:, 0], ids[:, 1], ids[:, 2], geo[:, 0], geo[:, 1:3]), nv=X.shape[0])


def _unit_rows(M):
    """(row, column, value) of the nonzeros of a CSR matrix, each row scaled to unit norm."""
    row = np.repeat(np.arange(M.shape[0], dtype=np.int64), np.diff(M.indptr))
    nz = M.data != 0
    row, col, val = row[nz], M.indices[nz].astype(np.int64), M.data[nz]
    norms = np.sqrt(np.bincount(row, weights=val * val, minlength=M.shape[0]))
    return row, col, val / norms[row]


def independent_rows(C, fixed_dofs=None, G=None, rtol=1e-8, method="auto", dense_limit=256):
    """A maximal set of rows of C, linearly independent and independent of the Dirichlet rows.

    Rows are scaled to unit norm, columns fixed by Dirichlet conditions are eliminated
    (``fixed_dofs``) or the span of general Dirichlet rows ``G`` is projected out, and a
    column-pivoted QR of the remaining C^T decides (C++: Businger-Golub pivoting on a
    modified Gram-Schmidt QR with reorthogonalisation; single-threaded on purpose, as
    threaded LAPACK on these small blocks was 10 to 50 times slower on a loaded machine).
    The work splits into the connected components of the rows' sparsity graph (rows
    sharing a dof, through C or G), each a dense QR restricted to its nonzero columns;
    single rows need no QR. Exact duplicates, the three-body node-to-node redundancy of
    the paper's Fig. 5 and rows implied by the Dirichlet rows are all removed this way.
    Cost per component: O(k r n) for k rows, rank r, n columns.

    Parameters
    ----------
    C : scipy.sparse matrix or array_like, shape (m, ndof)
        Constraint rows.
    fixed_dofs : array_like of int, optional
        Dofs fixed by Dirichlet conditions (rows e_d of the Dirichlet block).
    G : scipy.sparse matrix or array_like, shape (p, ndof), optional
        General Dirichlet / multi-point rows that are kept in any case.
    rtol : float
        Rank threshold on |R_kk| for unit-norm rows: a row within rtol (relative) of the
        span of the kept rows is dropped; its constraint then holds up to about rtol
        times the displacement. Smaller values keep nearly dependent rows and make the
        multipliers blow up like 1 / sigma_min.
    method : {"auto", "pivoted", "banded"}
        "pivoted": the column-pivoted QR on every component. "banded": for components
        without G rows, a sparse alternative: greedy selection in reverse Cuthill-McKee
        order by a banded Givens QR of C^T (|R_jj| > rtol keeps row j). It is not
        pivoted and not rank-revealing: every kept row is > rtol away from the span of
        the rows kept before it, yet the kept set can be nearly singular when singular
        values are spread below ~1e-8 (measured: sigma_min 4e-16 at rtol 1e-10 on
        unsnapped near-duplicate rows; with xi_snap both methods agree). Fine for
        exact duplicates and Fig. 5 cycles. "auto": pivoted for components of at most
        dense_limit rows, banded above (the pivoted QR costs O(k r n) per component:
        14 s for one 1285-row component).
    dense_limit : int
        Component size up to which "auto" uses the pivoted QR.

    Returns
    -------
    numpy.ndarray of int64
        Indices of the kept rows, ascending. Pivoting picks the largest residual and,
        among residuals equal to 1e-12 relative, the lowest index: duplicates keep their
        first occurrence.

    Raises
    ------
    ValueError
        On shapes that do not match, dof indices out of range, non-finite entries or
        rtol <= 0.
    """
    C = sp.csr_matrix(C, dtype=np.float64)
    m, ndof = C.shape
    if not np.isfinite(C.data).all():
        raise ValueError("C contains NaN or inf")
    if not (np.isscalar(rtol) and np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol must be a positive number, got {rtol!r}")
    if G is not None:
        G = sp.csr_matrix(G, dtype=np.float64)
        if G.shape[1] != ndof:
            raise ValueError(f"G must have {ndof} columns like C, got {G.shape[1]}")
        if not np.isfinite(G.data).all():
            raise ValueError("G contains NaN or inf")
    if fixed_dofs is not None:
        fixed = np.asarray(fixed_dofs, dtype=np.int64).ravel()
        if fixed.size and (fixed.min() < 0 or fixed.max() >= ndof):
            raise ValueError(f"fixed_dofs holds dofs outside [0, {ndof})")
    if method not in ("auto", "pivoted", "banded"):
        raise ValueError(f"method must be 'auto', 'pivoted' or 'banded', got {method!r}")
    if m == 0:
        return np.zeros(0, dtype=np.int64)

    # Plain arrays instead of scipy operations: each of those costs a millisecond of
    # overhead, and this runs in every contact round (measured: 16 ms a call on a
    # 2k-triangle plate, now a few). Rows scaled to unit norm, fixed dofs dropped,
    # columns renumbered to the ones the rows touch.
    C = C.copy()
    C.sum_duplicates()
    row, col, val = _unit_rows(C)
    if fixed_dofs is not None and fixed.size:
        is_fixed = np.zeros(ndof, dtype=bool)
        is_fixed[fixed] = True
        keep = ~is_fixed[col]
        row, col, val = row[keep], col[keep], val[keep]               # eliminate fixed dofs
    if G is not None and G.shape[0]:
        G = G.copy()
        G.sum_duplicates()
        grow, gcol, gval = _unit_rows(G)
        p = G.shape[0]
    else:
        grow = gcol = np.zeros(0, dtype=np.int64)
        gval = np.zeros(0)
        p = 0
    used, cols = np.unique(np.concatenate([col, gcol]), return_inverse=True)
    col, gcol = cols[:len(col)], cols[len(col):]
    n = len(used)

    # Components of the bipartite graph rows (C then G) -- dofs.
    nodes = m + p + n
    graph = sp.csr_matrix((np.ones(len(col) + len(gcol), dtype=np.int8),
                           (np.concatenate([row, m + grow]), m + p + np.concatenate([col, gcol]))),
                          shape=(nodes, nodes))
    _, labels = connected_components(graph, directed=False)
    lab_c, lab_g = labels[:m], labels[m:m + p]

    # Rows that vanished after eliminating fixed dofs depend on the Dirichlet rows.
    rem_norm = np.sqrt(np.bincount(row, weights=val * val, minlength=m))
    alive = np.flatnonzero(rem_norm > rtol)
    Ca = sp.csr_matrix((val, (row, col)), shape=(m, n))[alive]
    Ca.sort_indices()
    Gn = sp.csr_matrix((gval, (grow, gcol)), shape=(p, n))
    Gn.sort_indices()
    if _clearly_independent(Ca, Gn, rtol, lab_c[alive], lab_g):
        return alive.astype(np.int64)
    position = np.zeros(len(alive), dtype=np.int64)
    if method != "pivoted" and len(alive):
        # processing order for the banded QR: reverse Cuthill-McKee of the row graph
        pattern = Ca.copy()
        pattern.data = np.ones_like(pattern.data)
        order = reverse_cuthill_mckee(sp.csr_matrix(pattern @ pattern.T), symmetric_mode=True)
        position[order] = np.arange(len(alive))
    code = {"auto": 0, "pivoted": 1, "banded": 2}[method]
    kept = _ext.IndependentRowsSparse(
        n, Ca.indptr.astype(np.int64), Ca.indices.astype(np.int32), Ca.data,
        lab_c[alive].astype(np.int32), position, Gn.indptr.astype(np.int64),
        Gn.indices.astype(np.int32), Gn.data, lab_g.astype(np.int32), float(rtol), code,
        int(dense_limit))
    return alive[kept].astype(np.int64)


def _clearly_independent(C, G, rtol, labels_c, labels_g, limit=1500):
    """True if every row of [G; C] is farther than rtol from the span of all the others.

    Then any QR of the rows, pivoted or not, has |R_kk| >= sigma_min > rtol and keeps them
    all, so the pivoted QR can be skipped: a Cholesky factorisation of the Gram matrix
    minus (rtol^2 + rounding) I succeeds when sigma_min^2 exceeds that shift. The usual
    case in a contact round (measured on the disintegrating disk: 165 rows in one
    component joined by 84 hold rows over 1714 dofs, 0.33 s of pivoted QR a call, 45 % of
    the run; the Cholesky of the 249 x 249 Gram matrix takes milliseconds). Rows with a
    dependence fall through to the QR, which decides which to drop. Tried only where the
    QR would cost more (sum over the components of rows^2 x columns above rows^3 of the
    test: many small components, as along the cuts of benchmarks/contact.py, are cheap to
    QR, and there a failed test only added time), not above ``limit`` rows, and not where
    rtol^2 is within ten times the rounding of the test.
    """
    M = sp.vstack([G, C]).tocsr()
    k = M.shape[0]
    if k == 0 or k > limit:
        return k == 0
    labels = np.concatenate([labels_g, labels_c]).astype(np.int64)
    rows_per = np.bincount(labels).astype(float)
    pairs = np.unique(np.repeat(labels, np.diff(M.indptr)) * M.shape[1] + M.indices)
    columns_per = np.bincount(pairs // M.shape[1], minlength=len(rows_per))
    if np.sum(rows_per ** 2 * columns_per) < float(k) ** 3:
        return False
    gram = (M @ M.T).toarray()
    # backward error of forming and factorising the Gram matrix: a few k eps |Gram|
    rounding = 4 * k * np.finfo(float).eps * np.abs(gram).sum(axis=1).max()
    if rtol ** 2 < 10 * rounding:
        return False
    gram[np.diag_indices(k)] -= rtol ** 2 + rounding
    try:
        sla.cholesky(gram, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        return False
    return True


def contact_constraints(coords, displacement, tris, boundary_edges, fragment=None,
                        candidates=None, tol=0.0, angle_tol=np.pi / 2, xi_snap=1e-2,
                        fixed_dofs=None, G=None, rtol=1e-8):
    """Collision detection, contact selection, gap rows and redundancy removal in one call.

    Parameters
    ----------
    coords, displacement : array_like, shape (nv, 2)
        Reference coordinates and predicted displacement (without contact).
    tris : array_like, shape (nt, 3)
        Triangles, counter-clockwise in the reference configuration.
    boundary_edges : array_like, shape (ne, 2)
        Directed boundary / crack edges with their triangle on the left.
    fragment : array_like of int, shape (nt,), optional
        Fragment id per triangle.
    candidates : numpy.ndarray of bool, shape (nt,), optional
        Triangles taking part; by default those with a boundary edge.
    tol, angle_tol, xi_snap :
        Precision threshold, rule-3 angle and end snapping, see :func:`select_contacts`.
    fixed_dofs, G, rtol :
        Dirichlet information and rank threshold, see :func:`independent_rows`.

    Returns
    -------
    ContactConstraints
        The kept, independent constraints; ``C`` (m x 2 nv CSR) and ``g`` go next to the
        Dirichlet rows of the KKT system (eq. 12).
    """
    pairs = detect_collisions(coords, displacement, tris, candidates=candidates,
                              boundary_edges=boundary_edges, fragment=fragment, tol=tol)
    if len(pairs) == 0:
        return _no_constraints(np.shape(coords)[0])     # no work without collisions
    cs = select_contacts(coords, displacement, tris, boundary_edges, pairs, tol=tol,
                         angle_tol=angle_tol, xi_snap=xi_snap)
    if len(cs) == 0:
        return cs
    keep = independent_rows(cs.C, fixed_dofs=fixed_dofs, G=G, rtol=rtol)
    return cs.subset(keep)
