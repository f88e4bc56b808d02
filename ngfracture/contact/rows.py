"""Node-to-segment contact constraints (paper section 3.2): selection, gap linearisation.

Pipeline for one (predicted) configuration::

    pairs = collision.detect_collisions(X, U, tris, boundary_edges=E, tol=tol)
    cs = select_contacts(X, U, tris, E, pairs, tol=tol)       # rules 1-4, eq. 13/14
    keep = independent_rows(cs.C, fixed_dofs=dirichlet_dofs)  # pivoted QR (redundancy.py)
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
from typing import ClassVar

import numpy as np
import scipy.sparse as sp

from .. import _ngfracture as _ext
from .collision import (as_array, boundary_edge_mask, check_tol, check_tris, current_coordinates,
                        detect_collisions)
from .redundancy import independent_rows

__all__ = ["take_rows", "ContactConstraints", "no_constraints", "select_contacts", "gap_rows", "gap_offset",
           "relinearise_node_to_segment", "reachable", "independent_rows",
           "contact_constraints"]


class RowTable:
    """What the contact row sets share (2D :class:`ContactConstraints`, 3D
    ``rows3d.NodeToFaceRows``): per-row arrays named by the class's ``FIELDS`` in
    constructor order, then ``nv``; ``len``, stacking and selecting rows.
    """
    FIELDS = ()

    def __len__(self):
        return len(self.g)

    @classmethod
    def stack(cls, parts):
        """The rows of several row sets of one mesh, in order.

        Parameters
        ----------
        parts : sequence of RowTable
            At least one, of this class.

        Returns
        -------
        RowTable
            The rows of ``parts[0]``, then those of ``parts[1]``, ...

        Raises
        ------
        ValueError
            Parts of meshes with different numbers of vertices.
        """
        nv = parts[0].nv
        if any(p.nv != nv for p in parts):
            raise ValueError(f"{cls.__name__}.stack: rows of meshes with {sorted(set(p.nv for p in parts))} vertices")
        return cls(*(np.concatenate([getattr(p, f) for p in parts]) for f in cls.FIELDS), nv=nv)

    def subset(self, rows):
        """The rows ``rows`` (an index array or boolean mask).

        Parameters
        ----------
        rows : array_like of int or bool
            Row indices (in the order wanted) or a mask of shape (m,).

        Returns
        -------
        RowTable
            New arrays holding the selected rows.
        """
        rows = np.asarray(rows)
        if rows.dtype != bool:
            rows = rows.astype(np.int64)
        return type(self)(*(take_rows(getattr(self, f), rows) for f in self.FIELDS), nv=self.nv)


def take_rows(a, rows):
    """``a[rows]`` for an index array or a boolean mask ``rows`` over the first axis.

    The same array as ``a[rows]`` (values, dtype, shape, errors); for arrays of two or
    more dimensions by ``numpy.take`` / ``numpy.compress`` along the first axis, which
    copy whole rows, where numpy's fancy indexing copies a (m, 3) array row by row through
    its general iterator (about four times the time).

    Parameters
    ----------
    a : numpy.ndarray
    rows : array_like of int or bool
        Row indices of any shape (negative ones count from the end), or a mask of shape
        (len(a),).

    Returns
    -------
    numpy.ndarray
        A new array, of shape ``rows.shape + a.shape[1:]`` for indices.

    Raises
    ------
    IndexError
        An index outside the rows, or a mask of another length (as ``a[rows]``).
    """
    rows = np.asarray(rows)
    if a.ndim < 2 or rows.ndim == 0:
        return a[rows]
    if rows.dtype == bool:
        if rows.shape != a.shape[:1]:
            return a[rows]              # numpy's error
        return np.compress(rows, a, axis=0)
    if not np.issubdtype(rows.dtype, np.integer):
        return a[rows]                  # numpy's error
    return np.take(a, rows, axis=0)


@dataclass
class ContactConstraints(RowTable):
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
    FIELDS: ClassVar[tuple] = ("slave", "a", "c", "master_tri", "slave_tri", "pair", "xi", "normal", "dist",
                               "angle", "g")

    @functools.cached_property
    def C(self):
        """The gap rows as a sparse matrix, shape (m, 2 nv), built at first use (see the class)."""
        return _gap_matrix(self.slave, self.a, self.c, self.xi, self.normal, self.nv)


def no_constraints(nv):
    """No rows, for a mesh of nv vertices.

    Parameters
    ----------
    nv : int
        Number of vertices (C has 2 nv columns).

    Returns
    -------
    ContactConstraints
        Zero rows, with arrays of the types :func:`select_contacts` gives.
    """
    e = np.zeros(0, dtype=np.int32)
    f = np.zeros(0)
    return ContactConstraints(slave=e, a=e, c=e, master_tri=e, slave_tri=e, pair=e, xi=f,
                              normal=np.zeros((0, 2)), dist=f, angle=f, g=f, nv=nv)


#: the per-row arrays of ContactConstraints, in constructor order


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
    n = as_array(normal, "normal", np.float64, 2)
    m = len(slave)
    if not (len(a) == len(c) == len(xi) == n.shape[0] == m):
        raise ValueError("slave, a, c, xi and normal must have the same length")
    if not (np.isfinite(xi).all() and np.isfinite(n).all()):
        raise ValueError("xi and normal must be finite")
    for name, v in (("slave", slave), ("a", a), ("c", c)):
        if m and (v.min() < 0 or v.max() >= nv):
            raise ValueError(f"{name} holds vertex indices outside [0, {nv})")
    return _gap_matrix(slave, a, c, xi, n, nv), gap_offset(X, slave, a, c, xi, n)


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


def gap_offset(X, slave, a, c, xi, n):
    """g of :func:`gap_rows` (the gap at u = 0), for arrays already checked.

    Parameters
    ----------
    X : numpy.ndarray, shape (nv, 2)
        Reference vertex coordinates.
    slave, a, c : numpy.ndarray of int, shape (m,)
        Slave vertex and master edge end points.
    xi : numpy.ndarray, shape (m,)
        Weight of x_a in the projection point.
    n : numpy.ndarray, shape (m, 2)
        Unit normals.

    Returns
    -------
    numpy.ndarray, shape (m,)
        n . (X_b - xi X_a - (1 - xi) X_c).
    """
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
        near-duplicates with singular values spread down to rounding, which no rank
        threshold separates cleanly (the values compared are in ``docs/contact.md``; see
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
    tol = check_tol(tol)
    if not np.isscalar(angle_tol) or not (0 <= angle_tol <= np.pi / 2):
        raise ValueError(f"angle_tol must be in [0, pi/2], got {angle_tol!r}")
    if not np.isscalar(xi_snap) or not (0 <= xi_snap < 0.5):
        raise ValueError(f"xi_snap must be in [0, 0.5), got {xi_snap!r}")
    X = current_coordinates(coords)
    x = current_coordinates(coords, displacement)
    T = check_tris(tris, x.shape[0])
    P = as_array(pairs, "pairs", np.int32, 2)
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
        g=gap_offset(X, ids[:, 0], ids[:, 1], ids[:, 2], geo[:, 0], geo[:, 1:3]), nv=X.shape[0])


#: a master edge shorter than this fraction of its reference length counts as squeezed to a
#: point (relinearise_node_to_segment): below it its direction is rounding
DEGENERATE_EDGE = 1e-8


def relinearise_node_to_segment(cs, X, U):
    """The rows of cs with normal and projection of the master edge at X + U (eq. 13, 14).

    Rows snapped to a node (xi = 0 or 1) stay node-to-node; the normal keeps its side. A
    master edge squeezed below ``DEGENERATE_EDGE`` of its reference length keeps its
    previous normal and xi (a node-to-point row).

    Parameters
    ----------
    cs : ContactConstraints
        Node-to-segment rows (slave, master edge a -> c, previous xi and normal).
    X, U : numpy.ndarray, shape (nv, 2)
        Reference vertex coordinates and vertex displacements (current = X + U).

    Returns
    -------
    ContactConstraints
        The same rows in the same order, with xi (clipped to [0, 1]), unit normal, dist
        (signed distance at X + U), C and g recomputed; slave, a, c, triangles, pair and
        angle kept. ``cs`` itself when it is empty.
    """
    if len(cs) == 0:
        return cs
    x = X + U
    e = x[cs.c] - x[cs.a]
    length2 = np.einsum("ij,ij->i", e, e)
    # a master edge squeezed to (nearly) a point has no direction of its own: it keeps the
    # normal and projection it had, a node-to-point row (finite: never NaN rows)
    reference2 = np.einsum("ij,ij->i", X[cs.c] - X[cs.a], X[cs.c] - X[cs.a])
    degenerate = ~(length2 > DEGENERATE_EDGE ** 2 * reference2)
    safe2 = np.where(degenerate, 1.0, length2)
    n = np.column_stack([e[:, 1], -e[:, 0]]) / np.sqrt(safe2)[:, None]
    n *= np.where(np.einsum("ij,ij->i", n, cs.normal) < 0, -1.0, 1.0)[:, None]
    n[degenerate] = cs.normal[degenerate]
    t = np.einsum("ij,ij->i", x[cs.slave] - x[cs.a], e) / safe2
    xi = np.where((cs.xi == 0.0) | (cs.xi == 1.0) | degenerate, cs.xi, np.clip(1.0 - t, 0.0, 1.0))
    dist = np.einsum("ij,ij->i", x[cs.slave] - xi[:, None] * x[cs.a] - (1 - xi)[:, None] * x[cs.c], n)
    return ContactConstraints(cs.slave, cs.a, cs.c, cs.master_tri, cs.slave_tri, cs.pair, xi, n,
                              dist, cs.angle, gap_offset(X, cs.slave, cs.a, cs.c, xi, n), nv=len(X))


def reachable(cs, U, tol):
    """Rows whose penetration the motion can explain.

    The reference mesh has no overlap, so a slave node cannot be deeper behind a master
    segment than it has moved relative to that segment (plus the threshold). Deeper
    "penetrations" come from picking the wrong way out near crack tips and corners;
    imposing them would tear the mesh (inverted elements), so they are dropped.

    Parameters
    ----------
    cs : ContactConstraints
        Candidate rows, with ``dist`` at the current configuration.
    U : numpy.ndarray, shape (nv, 2)
        Vertex displacements.
    tol : float
        Detection threshold (a length) added to the relative motion.

    Returns
    -------
    numpy.ndarray of bool, shape (len(cs),)
        True where -dist <= |u_slave - xi u_a - (1 - xi) u_c| + tol.
    """
    if len(cs) == 0:
        return np.zeros(0, dtype=bool)
    xi = cs.xi[:, None]
    rel = U[cs.slave] - xi * U[cs.a] - (1.0 - xi) * U[cs.c]
    return -cs.dist <= np.linalg.norm(rel, axis=1) + tol


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
        return no_constraints(np.shape(coords)[0])     # no work without collisions
    cs = select_contacts(coords, displacement, tris, boundary_edges, pairs, tol=tol,
                         angle_tol=angle_tol, xi_snap=xi_snap)
    if len(cs) == 0:
        return cs
    keep = independent_rows(cs.C, fixed_dofs=fixed_dofs, G=G, rtol=rtol)
    return cs.subset(keep)
