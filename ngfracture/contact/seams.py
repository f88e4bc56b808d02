"""Contact across coincident lips: crack faces made by node splitting, split interfaces.

Where the crack engine splits a vertex, or :func:`ngfracture.geometry.meshio.separate_region`
gives a body its own copies of the interface vertices, two boundary edges lie on top of
each other in the reference configuration: a *seam facet*, edge (p, q) of side A (its
triangle on the left) and edge (q2, p2) of side B with X[p2] = X[p], X[q2] = X[q]. Across a
seam every lip node has a twin at the same reference point, and the two lips were one
edge, so the contact normal is that edge's normal, defined on both sides alike.

Node-to-segment selection (paper rules 1-4, :mod:`ngfracture.contact.rows`) is ill-posed there:
at zero gap every lip node is at once a slave of the other lip and an end of its master
segments, both lips offer a master with a different normal (at a kink), and which one wins
depends on rounding in the predicted configuration. The choice flips from one linearisation
to the next and the active set cycles (``docs/contact.md``). Across a seam we therefore use
node-to-node rows between twins, identified by the node pair and the facet, so the set of
candidate rows is the same in every round of a solve:

* one row per facet end: g = n_f . (x_b2 - x_b) >= 0 for twins b, b2 (b the lower
  vertex number), n_f the unit normal of facet f pointing from b's lip to b2's. At a straight node the rows of its
  two facets coincide and become one row with the mean normal. At a kink (reference facet
  normals more than ``kink_angle`` apart) both rows stay: together they are the exact
  non-penetration condition of the two polygonal lips for small relative motion (the twin
  must stay in the cone of the convex side), and the active set releases one of them when
  the node slides along the other facet (its multiplier turns adhesive). One averaged row
  would let a kink slide into the other lip by |slip| sin(angle / 2).
* n_f is the mean of the two lips' edge directions, rotated, at the configuration where
  the rows are built (the predicted configuration, as the paper's eq. 13/14), and is frozen
  for the rest of the solve.
* a row is used while its twins still face each other: tangential slip at most
  ``slip`` times the facet length. Beyond that (large sliding) the node is left to the
  node-to-segment selection.

For small displacements this is the classical node-to-node contact of matching meshes: it
transmits a uniform pressure exactly (patch test) and converges like the P1 solution.

Junctions: where a point is split into three or more copies (cracks meet, a crack reaches
a split interface), each copy owns a wedge of the full angle around the point, and a copy
pair shares at most one facet. For small relative motion r = x_j - x_i of two copies, r
must stay outside wedge i and -r outside wedge j; the facet rows above state that only in
part (the overlap they leave is all at three-copy points, ``docs/contact.md``). Where one
wedge of a pair is reflex (wider than
pi), the other copy must stay in its complement, a convex cone: one row per edge of the
reflex wedge (exact; the edges shared as facets already have their row), identified by
(copy, copy, edge) and built at the prediction like the facet rows.

Two convex wedges without a shared facet (the diagonal of a four-way junction): r must
stay outside the cone K = W_i - W_j (convex, narrower than pi, because the wedges were
disjoint), i.e. beyond one of K's two edges. That is not convex. At the prediction we
take the edge of K with the larger signed distance of r (the least penetration if r is
inside K): one row, frozen for the solve like the other seam rows and identified by
(copy, copy, side of K) so that re-linearisation keeps the choice. Exact while r stays
on that side; the pieces may slide along the chosen edge both ways and separate freely
(`tests/test_seams.py`: shear along a crack through a cross junction in either
direction). One row across the separating line of widest margin (a normal anywhere
between K's edge normals) would not do: one strictly between them blocks sliding along
either crack one way (``docs/contact.md``).
"""
from dataclasses import dataclass, field

import numpy as np

from .rows import ContactConstraints, gap_offset

__all__ = ["Seams", "find_seams", "seam_constraints", "point_ids", "KINK_ANGLE", "SLIP"]

#: facets meeting at a larger angle (radians) get a row each at their common node
KINK_ANGLE = 1e-6
#: key kinds of the rows of a diagonal pair: the right edge of K, and the left one is one less
DIAGONAL_RIGHT = -(2 ** 40)
#: rows are used while the tangential slip of the twins is below this fraction of the facet
SLIP = 0.5


@dataclass
class Seams:
    """Coincident boundary edges of a mesh.

    Parameters
    ----------
    facets : numpy.ndarray of int, shape (k, 4)
        (p, q, p2, q2): segment p -> q of side A (domain on its left) lies on segment
        q2 -> p2 of side B; X[p2] = X[p], X[q2] = X[q]. Each facet appears once.
    copy_id : numpy.ndarray of int, shape (nv,)
        Vertices with the same id share their reference point bitwise (twins, and the
        copies of a split junction vertex).
    seam_edge : set of (int, int)
        Both lips' edges as sorted vertex pairs.
    edge_rows : numpy.ndarray of int, shape (k, 4)
        (owner, other, tail, head): at a junction, copy ``other`` stays outside boundary
        segment tail -> head of the reflex wedge of copy ``owner`` (owner is tail or head).
    diagonal : numpy.ndarray of int, shape (k, 6)
        (i, j, out_i, in_i, out_j, in_j): copies i < j with convex wedges and no shared
        facet, with the far ends of their outgoing and incoming boundary segments.
    """
    facets: np.ndarray
    copy_id: np.ndarray
    seam_edge: set
    edge_rows: np.ndarray = field(default_factory=lambda: np.zeros((0, 4), dtype=np.int64))
    diagonal: np.ndarray = field(default_factory=lambda: np.zeros((0, 6), dtype=np.int64))

    def __len__(self):
        return len(self.facets)


def find_seams(points, segments):
    """The seam facets among directed boundary segments (exact coincidence of end points).

    Parameters
    ----------
    points : array_like, shape (nv, 2)
        Reference coordinates.
    segments : array_like of int, shape (ns, 2)
        Boundary and crack edges, the domain on their left.

    Returns
    -------
    Seams
        Every pair of coincident segments once; no facets if there is none.
    """
    X = np.ascontiguousarray(points, dtype=np.float64)
    S = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    copy_id = point_ids(X)
    n = int(copy_id.max(initial=-1)) + 1
    a = b = np.zeros(0, dtype=np.int64)
    if len(S):
        # segment a lies on segment b reversed: b's key is a's key with the ends swapped
        fwd = copy_id[S[:, 0]] * n + copy_id[S[:, 1]]
        rev = copy_id[S[:, 1]] * n + copy_id[S[:, 0]]
        order = np.argsort(fwd, kind="stable")
        pos = np.minimum(np.searchsorted(fwd[order], rev), len(S) - 1)
        a = np.flatnonzero(fwd[order][pos] == rev)
        b = order[pos[a]]
    # listed once, and a different edge (an interior edge would share both ends)
    keep = (a < b) & ~((S[a, 0] == S[b, 1]) & (S[a, 1] == S[b, 0]))
    a, b = a[keep], b[keep]
    facets = np.column_stack([S[a, 0], S[a, 1], S[b, 1], S[b, 0]])
    edges = np.sort(np.vstack([S[a], S[b]]), axis=1) if len(a) else np.zeros((0, 2), np.int64)
    edge_rows, diagonal = _junctions(X, S, copy_id, facets)
    return Seams(facets=facets, copy_id=copy_id, seam_edge=set(map(tuple, edges.tolist())),
                 edge_rows=edge_rows, diagonal=diagonal)


def point_ids(X):
    """Number of every point among the distinct points, in lexicographic (x, y) order.

    The inverse of ``np.unique(X, axis=0, return_inverse=True)``, by one lexsort (np.unique
    sorts rows as records, which is slower); -0.0 and 0.0 are one point.

    Parameters
    ----------
    X : numpy.ndarray, shape (nv, 2)
        Points.

    Returns
    -------
    numpy.ndarray of int64, shape (nv,)
        Equal for bitwise equal points (up to the sign of zero), numbered from 0.
    """
    order = np.lexsort((X[:, 1], X[:, 0]))
    Xs = X[order]
    new = np.ones(len(X), dtype=np.int64)
    new[1:] = np.any(Xs[1:] != Xs[:-1], axis=1)
    ids = np.empty(len(X), dtype=np.int64)
    ids[order] = np.cumsum(new) - 1
    return ids


def _copy_pairs(copy_id, candidates):
    """All pairs (i < j) of the candidate vertices with the same copy id."""
    order = candidates[np.lexsort((candidates, copy_id[candidates]))]
    pairs = []
    for d in range(1, len(order)):
        same = copy_id[order[d:]] == copy_id[order[:-d]]
        if not same.any():
            break            # sorted by id: no group has more than d members
        pairs.append(np.column_stack([order[:-d][same], order[d:][same]]))
    return np.vstack(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


def _junctions(X, S, copy_id, facets):
    """The ``edge_rows`` and ``diagonal`` of :class:`Seams`, see the module notes."""
    nv = len(X)
    none = np.zeros((0, 4), dtype=np.int64), np.zeros((0, 6), dtype=np.int64)
    if len(S) == 0:
        return none
    # the wedge of a copy lies between its one outgoing and one incoming boundary segment
    out_end, in_start = np.full(nv, -1), np.full(nv, -1)
    out_end[S[:, 0]], in_start[S[:, 1]] = S[:, 1], S[:, 0]
    simple = (np.bincount(S[:, 0], minlength=nv) == 1) & (np.bincount(S[:, 1], minlength=nv) == 1)
    counts = np.bincount(copy_id)
    P = _copy_pairs(copy_id, np.flatnonzero(simple & (counts[copy_id] >= 2)))
    if len(P) == 0:
        return none
    # the copy across each vertex's outgoing / incoming segment, where that is a facet
    out_twin, in_twin = np.full(nv, -1), np.full(nv, -1)
    p, q, p2, q2 = facets.T
    out_twin[p], in_twin[q], in_twin[p2], out_twin[q2] = p2, q2, p, q
    reflex = np.zeros(nv, dtype=bool)
    copies = np.unique(P)
    reflex[copies] = _wedge_width(X, copies, out_end, in_start) > np.pi + KINK_ANGLE
    rows = []
    for owner, other in (P.T, P[:, ::-1].T):
        r = reflex[owner]
        o, t = owner[r], other[r]
        rows.append(np.column_stack([o, t, o, out_end[o]])[out_twin[o] != t])
        rows.append(np.column_stack([o, t, in_start[o], o])[in_twin[o] != t])
    i, j = P.T
    apart = ~reflex[i] & ~reflex[j] & (out_twin[i] != j) & (in_twin[i] != j)
    i, j = i[apart], j[apart]
    diagonal = np.column_stack([i, j, out_end[i], in_start[i], out_end[j], in_start[j]])
    return np.vstack(rows).astype(np.int64), diagonal.astype(np.int64)


def _wedge_width(x, v, out_end, in_start):
    """Counter-clockwise angle (0, 2 pi] of the wedges of vertices v (one segment out, one in)."""
    a = x[out_end[v]] - x[v]
    b = x[in_start[v]] - x[v]
    width = np.mod(np.arctan2(b[:, 1], b[:, 0]) - np.arctan2(a[:, 1], a[:, 0]), 2 * np.pi)
    return np.where(width == 0.0, 2 * np.pi, width)


def seam_constraints(seams, points, displacement, kink_angle=KINK_ANGLE, slip=SLIP, choose=True):
    """Node-to-node rows across the seams, linearised at points + displacement.

    Parameters
    ----------
    seams : Seams
        From :func:`find_seams` on the reference mesh.
    points, displacement : array_like, shape (nv, 2)
        Reference coordinates and the (predicted) displacement.
    kink_angle : float
        Facets whose reference normals differ by more get a row each at their node.
    slip : float
        Rows whose twins slid tangentially by more than ``slip`` times the facet length
        are left out.
    choose : bool
        Pick the edge of each diagonal pair at this configuration (the prediction). False
        gives the rows of both edges, for re-linearising rows chosen before (by key).

    Returns
    -------
    rows : ContactConstraints
        Facet rows: a = c = the lower-numbered twin (master), slave = the other, normal
        from the master's lip towards the slave's. Junction rows: master the owner of the
        reflex wedge. xi = 1, dist the gap at the given configuration; master_tri,
        slave_tri and pair are -1.
    keys : numpy.ndarray of int, shape (m, 3)
        (lower vertex, higher vertex, kind) identifying each row: kind is the facet, -1 for
        the merged row of a straight node, -3 - v for the edge row of the reflex wedge's
        edge ending in v, DIAGONAL_RIGHT (- 1) for the right (left) edge of a diagonal pair.
        A diagonal pair's edge is named by its side of K, not by a vertex: where two
        segments are collinear, which of them bounds K flips with rounding. The same seams
        give the same keys in every configuration.
    """
    X = np.asarray(points, dtype=np.float64)
    x = X + np.asarray(displacement, dtype=np.float64)
    parts = [_facet_rows(seams, X, x, kink_angle, slip), _edge_rows(seams, X, x, slip),
             _diagonal_rows(seams, X, x, slip, choose)]
    master, slave, key3, normal = (np.concatenate([part[k] for part in parts]) for k in range(4))
    keys = np.column_stack([np.minimum(master, slave), np.maximum(master, slave), key3]).astype(np.int64)
    return _rows(X, x, master, slave, normal.reshape(-1, 2)), keys


def _facet_rows(seams, X, x, kink_angle, slip):
    """Rows at the facet ends: (master, slave, facet or -1, normal), master the lower twin."""
    F = seams.facets
    # every facet end with distinct twins: (b, b2, facet)
    ends = np.vstack([np.column_stack([F[:, 0], F[:, 2], np.arange(len(F))]),
                      np.column_stack([F[:, 1], F[:, 3], np.arange(len(F))])])
    ends = ends[ends[:, 0] != ends[:, 1]]
    if len(ends) == 0:
        e = np.zeros(0, dtype=np.int64)
        return e, e, e, np.zeros((0, 2))
    p, q, p2, q2 = F.T
    n_ref = _outward(X[q] - X[p])
    length = np.linalg.norm(n_ref, axis=1)
    n_ref /= length[:, None]
    # the current facets' mean normal; where both lips are squeezed to a point, the reference one
    n_cur = _unit_or(_outward((x[q] - x[p]) + (x[q2] - x[p2])), n_ref)
    # orient every end as (low vertex, high vertex) so both facets of a node pair agree
    b, b2, f = ends.T
    sign = np.where(b < b2, 1.0, -1.0)
    lo, hi = np.minimum(b, b2), np.maximum(b, b2)
    nr, nc, ln = n_ref[f] * sign[:, None], n_cur[f] * sign[:, None], length[f]
    order = np.lexsort((f, hi, lo))
    lo, hi, f, nr, nc, ln = lo[order], hi[order], f[order], nr[order], nc[order], ln[order]
    # straight nodes: the two facets of one pair with (nearly) equal reference normals merge
    same = np.zeros(len(lo), dtype=bool)
    same[1:] = (lo[1:] == lo[:-1]) & (hi[1:] == hi[:-1]) & \
        (np.einsum("ij,ij->i", nr[1:], nr[:-1]) >= np.cos(kink_angle))
    first = ~same
    merged = np.zeros(len(lo), dtype=bool)
    merged[:-1] = same[1:]
    group = np.cumsum(first) - 1
    normal = np.zeros((first.sum(), 2))
    np.add.at(normal, group, nc)
    normal = _unit_or(normal, nr[first])         # opposite facet normals cancel: the first's
    size = np.full(first.sum(), np.inf)
    np.minimum.at(size, group, ln)
    lo, hi = lo[first], hi[first]
    facet = np.where(merged[first], -1, f[first])
    ok = _facing(x, lo, hi, normal, slip * size)
    return lo[ok], hi[ok], facet[ok], normal[ok]


def _edge_rows(seams, X, x, slip):
    """Junction rows of a reflex wedge: the other copy outside the edge tail -> head."""
    owner, other, tail, head = seams.edge_rows.T
    normal = _unit(_outward(x[head] - x[tail]))
    far = np.where(tail == owner, head, tail)
    ok = _facing(x, owner, other, normal, slip * np.linalg.norm(X[head] - X[tail], axis=1))
    return owner[ok], other[ok], -3 - far[ok], normal[ok]


def _diagonal_rows(seams, X, x, slip, choose):
    """Rows of the diagonal pairs: copy j outside one edge of the cone K = W_i - W_j."""
    i, j, out_i, in_i, out_j, in_j = seams.diagonal.T
    m = len(i)
    # K is spanned by the four edge directions of the two wedges (those of W_j reversed)
    apex = np.concatenate([i, i, j, j])
    far = np.concatenate([out_i, in_i, out_j, in_j])
    e = _unit((x[far] - x[apex]) * np.repeat([1.0, 1.0, -1.0, -1.0], m)[:, None]).reshape(4, m, 2)
    # a direction inside K: the sum of the bisectors of W_i and -W_j
    d = e[0] + e[1] + e[2] + e[3]
    turn = np.arctan2(d[:, 0] * e[..., 1] - d[:, 1] * e[..., 0], np.einsum("ij,kij->ki", d, e))
    right, left = np.argmin(turn, axis=0), np.argmax(turn, axis=0)
    cols = np.arange(m)
    e_right, e_left = e[right, cols], e[left, cols]
    # outward normals of K: clockwise of its right edge, counter-clockwise of its left one
    normal = np.concatenate([_outward(e_right), -_outward(e_left)])
    edge = np.concatenate([right, left])
    ii, jj, cols, side = np.tile(i, 2), np.tile(j, 2), np.tile(cols, 2), np.repeat([0, 1], m)
    pick = np.ones(2 * m, dtype=bool)
    if choose:
        # the edge the relative position is farther outside of (or less inside)
        margin = np.einsum("ij,ij->i", x[jj] - x[ii], normal).reshape(2, m)
        pick = np.concatenate([margin[0] >= margin[1], margin[0] < margin[1]])
    ii, jj, cols, side, normal, edge = ii[pick], jj[pick], cols[pick], side[pick], normal[pick], edge[pick]
    v, w = apex.reshape(4, m)[edge, cols], far.reshape(4, m)[edge, cols]
    ok = _facing(x, ii, jj, normal, slip * np.linalg.norm(X[w] - X[v], axis=1))
    # i < j (pairs are listed so): i is the master, the normal points from i to j
    return ii[ok], jj[ok], DIAGONAL_RIGHT - side[ok], normal[ok]


def _unit(v):
    """Rows of v scaled to unit length (zero rows stay zero)."""
    return v / np.maximum(np.linalg.norm(v, axis=1), 1e-300)[:, None]


def _unit_or(v, fallback):
    """Rows of v scaled to unit length; rows of (nearly) zero length take ``fallback``'s."""
    norm = np.linalg.norm(v, axis=1)
    small = ~(norm > 1e-12 * np.maximum(np.abs(v).max(initial=0.0), 1e-300))
    out = v / np.where(small, 1.0, norm)[:, None]
    out[small] = fallback[small]
    return out


def _outward(v):
    """The normal of segments v with the domain on their left (v rotated clockwise)."""
    return np.column_stack([v[:, 1], -v[:, 0]])


def _facing(x, master, slave, normal, reach):
    """Rows whose nodes slid tangentially by at most reach (still facing each other)."""
    rel = x[slave] - x[master]
    return np.abs(rel[:, 0] * normal[:, 1] - rel[:, 1] * normal[:, 0]) <= reach


def _rows(X, x, master, slave, normal):
    m = len(slave)
    normal = np.asarray(normal, float).reshape(-1, 2)
    slave, master = np.asarray(slave, np.int64), np.asarray(master, np.int64)
    none = np.full(m, -1, dtype=np.int64)
    dist = np.einsum("ij,ij->i", x[slave] - x[master], normal) if m else np.zeros(0)
    return ContactConstraints(slave=slave, a=master, c=master, master_tri=none, slave_tri=none,
                              pair=none, xi=np.ones(m), normal=normal, dist=dist, angle=np.zeros(m),
                              g=gap_offset(X, slave, master, master, np.ones(m), normal), nv=len(X))
