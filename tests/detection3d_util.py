"""A brute-force reference of the 3D detection (``cpp_ext/collision3d*.cpp``).

Pairs: every (boundary vertex, tetrahedron) tested with the exact ``orient3d``, a vertex
against the tetrahedra of the other fragments, and a lip vertex (a copy of its point on
its own fragment) against those of its own fragment not at it; a pair whose vertex sits
on its twin (its first copy on the fragment, other than itself) is a closed seam; the
holding tetrahedron of a pair is the smallest. Master faces (collision3d's docstring): in
a tetrahedron at a copy t of the vertex, the face of that tetrahedron at t with the
vertex's reference star outside its plane that the vertex is least deep behind; if none
passes and two or more copies of the point lie on the fragment, the lip of that
tetrahedron at t the vertex is least deep behind if it is behind one (t the only copy
there: a lip whose other side is on the fragment too, a crack of it ending at t); else, where that tetrahedron has no
boundary face at t and three copies lie on the fragment, the lip at t (of any tetrahedron)
that the vertex is least deep behind; else the nearest face of the fragment
opposing the vertex's normal or coincident with one of its faces (partner faces). Import with ``PYTHONPATH=.:tests``.
"""
from collections import Counter, defaultdict

import numpy as np

from ngfracture.contact.collision3d import orient3d


def vertex_fragments(T, piece, nv):
    """The fragment of every vertex (-1: in no tetrahedron)."""
    vf = np.full(nv, -1)
    vf[T.ravel()] = np.repeat(piece, 4)
    return vf


def closest_distance(p, A, B, C):
    """Distance from p to every triangle (A, B, C): the plane's foot if inside, else the nearest edge."""
    n = np.cross(B - A, C - A)
    n /= np.linalg.norm(n, axis=1)[:, None]
    foot = p - np.einsum("ij,ij->i", p - A, n)[:, None] * n
    inside = np.all([np.einsum("ij,ij->i", np.cross(Q - P, foot - P), n) >= 0
                     for P, Q in ((A, B), (B, C), (C, A))], axis=0)
    best = np.linalg.norm(p - foot, axis=1)
    edges = []
    for P, Q in ((A, B), (B, C), (C, A)):
        e = Q - P
        t = np.clip(np.einsum("ij,ij->i", p - P, e) / np.einsum("ij,ij->i", e, e), 0.0, 1.0)
        edges.append(np.linalg.norm(p - (P + t[:, None] * e), axis=1))
    return np.where(inside, best, np.min(edges, axis=0))


def brute_force_pairs(X, T, F, piece, U):
    """The pairs of the detection, by exact tests of every (boundary vertex, tetrahedron).

    Parameters
    ----------
    X : numpy.ndarray, shape (nv, 3)
        Reference points (copies bitwise equal).
    T, F : numpy.ndarray of int
        Tetrahedra (ne, 4) and boundary faces (nf, 3).
    piece : numpy.ndarray of int, shape (ne,)
        The fragment of every tetrahedron.
    U : numpy.ndarray, shape (nv, 3)
        Displacement.

    Returns
    -------
    vertex, fragment, tet : numpy.ndarray of int
        The pairs that are no closed seam, sorted by (vertex, fragment), each with the
        smallest tetrahedron holding it.
    closed : int
        The number of closed seams (distinct pairs).
    """
    x = X + U
    vf = vertex_fragments(T, piece, len(X))
    bv = np.unique(F)
    copies = defaultdict(list)                          # (point, fragment): copies, increasing
    for u in bv.tolist():
        copies[(tuple(X[u]), int(vf[u]))].append(u)
    lip = np.zeros(len(X), dtype=bool)
    lip[[u for c in copies.values() if len(c) > 1 for u in c]] = True
    v, t = np.repeat(bv, len(T)), np.tile(np.arange(len(T)), len(bv))
    lo, hi = x[T].min(axis=1), x[T].max(axis=1)
    in_box = np.all((x[v] >= lo[t]) & (x[v] <= hi[t]), axis=1)
    v, t = v[in_box], t[in_box]
    allowed = (vf[v] != piece[t]) | (lip[v] & np.all(T[t] != v[:, None], axis=1))
    v, t = v[allowed], t[allowed]
    corners = [x[T[t, k]] for k in range(4)]
    s = orient3d(*corners).astype(int)
    inside = s != 0
    for k in range(4):
        w = list(corners)
        w[k] = x[v]
        inside &= orient3d(*w) * s >= 0
    v, t = v[inside], t[inside]

    def twin(a, f):
        return next((u for u in copies.get((tuple(X[a]), f), []) if u != a), -1)

    tw = np.array([twin(a, f) for a, f in zip(v.tolist(), piece[t].tolist())], dtype=np.int64)
    closed = (tw >= 0) & np.all(x[v] == x[np.maximum(tw, 0)], axis=1)
    n_closed = len(np.unique(v[closed] * len(T) + piece[t[closed]]))
    v, t = v[~closed], t[~closed]
    order = np.lexsort((t, piece[t], v))
    v, t = v[order], t[order]
    first = np.r_[True, (v[1:] != v[:-1]) | (piece[t][1:] != piece[t][:-1])]
    return v[first], piece[t][first], t[first], n_closed


class MasterReference:
    """The master face of the detection's pairs, by the rules of the module docstring.

    Parameters
    ----------
    X, U : numpy.ndarray, shape (nv, 3)
        Reference points and displacement.
    T, F : numpy.ndarray of int
        Tetrahedra and boundary faces.
    piece : numpy.ndarray of int, shape (ne,)
        The fragment of every tetrahedron.
    """

    def __init__(self, X, U, T, F, piece):
        self.X, self.x, self.T, self.F = X, X + U, T, F
        self.vf = vertex_fragments(T, piece, len(X))
        x = self.x
        self.area2 = np.cross(x[F[:, 1]] - x[F[:, 0]], x[F[:, 2]] - x[F[:, 0]])
        self.ref2 = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
        self.vnormal = np.zeros((len(X), 3))
        np.add.at(self.vnormal, F.ravel(), np.repeat(self.area2, 3, axis=0))
        self.points = [frozenset(map(tuple, X[f])) for f in F]
        self.points_count = Counter(self.points)        # a lip: another face on its three points

    def at_copy(self, a, f, tet):
        """The master face of pair (a, f) held by tetrahedron ``tet`` (its four vertices) at a copy.

        Returns
        -------
        (face, gap, by_lip) or None
            The face, the gap (minus the depth behind it, 0 in front) and whether the lip
            rule chose it; None where the tetrahedron is at no copy of ``a`` or no face
            there decides (the nearest face rule applies).
        """
        X, T, F = self.X, self.T, self.F
        t = [u for u in tet if u != a and np.array_equal(X[u], X[a])]
        if not t:
            return None
        at = np.flatnonzero(np.all(np.isin(F, tet), axis=1) & np.any(F == t[0], axis=1))
        n = self.ref2[at] / np.linalg.norm(self.ref2[at], axis=1)[:, None]
        e = X[np.unique(T[np.any(T == a, axis=1)])] - X[a]
        sep = at[np.all(n @ e.T >= -1e-9 * np.linalg.norm(e, axis=1), axis=1)]
        by_lip = False
        on_block = int(np.count_nonzero(np.all(X == X[a], axis=1) & (self.vf == f)))
        if not len(sep):
            # two or more copies on the fragment: its lips at t; t the only one: the lips at
            # t whose other side is on the fragment too (a crack of it ending at t)
            lips = at[[self.points_count[self.points[g]] > 1 and (on_block >= 2 or self.lip_on(g, f)) for g in at]]
            if len(lips) and self.signed(a, t[0], lips).max() < 0:
                sep, by_lip = lips, True
        if not len(sep) and not len(at) and on_block >= 3:
            # a tetrahedron with no boundary face at the copy, three copies on the fragment:
            # the lips at the copy that a is behind, least deep
            star = np.flatnonzero(np.any(F == t[0], axis=1))
            star = star[[self.points_count[self.points[g]] > 1 for g in star]]
            behind_of = self.signed(a, t[0], star) < 0
            if not behind_of.any():
                return None
            sep = star[behind_of]
        if not len(sep):
            return None
        signed = self.signed(a, t[0], sep)
        return int(sep[np.lexsort((sep, -signed))[0]]), -max(0.0, -signed.max()), by_lip

    def lip_on(self, g, f):
        """Whether another boundary face of fragment ``f`` lies on the three points of face ``g``."""
        return any(h != g and self.points[h] == self.points[g] and self.vf[self.F[h, 0]] == f
                   for h in range(len(self.F)))

    def signed(self, a, t, faces):
        """Signed distances of a from the planes through copy t with the faces' current normals."""
        n = self.area2[faces] / np.linalg.norm(self.area2[faces], axis=1)[:, None]
        return np.einsum("ij,j->i", n, self.x[a] - self.x[t])

    def nearest(self, a, f):
        """The candidate faces of fragment f for the nearest face rule, and their distances from a."""
        X, F = self.X, self.F
        mine = {self.points[g] for g in np.flatnonzero(np.any(F == a, axis=1))}
        partner = np.array([self.points[g] in mine and bool(np.any(np.all(X[F[g]] == X[a], axis=1)))
                            for g in range(len(F))])
        cand = np.flatnonzero((self.vf[F[:, 0]] == f) & ((self.area2 @ self.vnormal[a] < 0) | partner)
                              & np.all(F != a, axis=1))
        x = self.x
        return cand, closest_distance(x[a][None, :], x[F[cand, 0]], x[F[cand, 1]], x[F[cand, 2]])

    def check(self, pen, tol):
        """Assert the master face and gap of every pair of ``pen`` (gaps to ``tol``).

        Returns
        -------
        crossed, behind : int
            The pairs decided at a copy, and those of them by the lip rule.
        """
        crossed = behind = 0
        for i in range(len(pen)):
            a, f = int(pen.vertex[i]), int(pen.fragment[i])
            ref = self.at_copy(a, f, self.T[pen.tet[i]])
            if ref is not None:
                crossed += 1
                behind += ref[2]
                assert pen.face[i] == ref[0]
                assert abs(pen.gap[i] - ref[1]) <= tol
                continue
            cand, d = self.nearest(a, f)
            assert pen.face[i] in cand
            assert abs(-pen.gap[i] - d.min()) <= tol
            assert d[cand == pen.face[i]][0] <= d.min() + tol
        return crossed, behind
