"""The detection's lip rule at points of two or more copies on one fragment (docs/contact.md,
"Points of several copies"; ``SeparatingFace(..., lips_only)`` in cpp_ext/collision3d_faces.cpp).

The body is the junction cube of ``test_contact3d_crack_junction.py``: two cracks inside
one fragment meet along the line x = y = 1/2, z > 1/2, where every point has three copies
on that fragment: W0 in the half x < 1/2, W1 and W2 in the quarters x > 1/2 below and
above y = 1/2. The copy of W0 is moved slightly into a tetrahedron of W1 or W2 at the
copy t there whose boundary faces at t all have W0's reference star across their plane
(the lip y = 1/2, and the free top face at the top point): no face passes the star test,
and the master must be the lip of that tetrahedron at t the vertex is least deep behind,
the gap minus the exact distance to that lip's plane. The nearest face (the rule
without the lip fallback) is another one, on the plane x = 1/2 (at z = 3/4 half as deep);
at the top the free face is nearer than the lip (a rule over every face of the
tetrahedron would take it). The whole detection must equal the brute-force reference of
``detection3d_util`` (the rules of collision3d's docstring).

The same with the plane x = 1/2 cut through the whole cube (``cut_cube``): W0 is a piece
of its own, and the points of the line have two copies on the other piece (the lips of the
crack y = 1/2 inside it); the rule is the same there.

Deeper in the star: the copy moved into a tetrahedron at t with no face on the boundary
gets the boundary face at t it is least deep behind, where the nearest face rule takes
one it is deeper behind.
"""
from fractions import Fraction

import numpy as np
import pytest

from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.rows3d import node_to_face_rows
from ngfracture.geometry.structured import box_mesh

from detection3d_util import MasterReference, brute_force_pairs
from test_contact3d_crack_junction import GRID, N, junction_cube, opened, plane_faces, wedge_labels

H = 1.0 / N                 # the cell size
EPS = 1e-3                  # the vertex moves by about EPS cells


def copies_of(X, z):
    """The copies of the junction point at height z."""
    return np.flatnonzero(np.all(X == [0.5, 0.5, z], axis=1))


def faces_at(F, tet, t):
    """The boundary faces of tetrahedron ``tet`` (its vertices) at vertex t."""
    return np.flatnonzero(np.all(np.isin(F, tet), axis=1) & np.any(F == t, axis=1))


def star_passes(X, T, F, v, face):
    """Whether v's reference star lies on the outer side of the face's reference plane."""
    n = np.cross(X[F[face, 1]] - X[F[face, 0]], X[F[face, 2]] - X[F[face, 0]])
    e = X[np.unique(T[np.any(T == v, axis=1)])] - X[v]
    return bool(np.all(e @ n >= -1e-9 * np.linalg.norm(n) * np.linalg.norm(e, axis=1)))


def exact_signed(x, face, p):
    """Signed distance of p from the plane of the face's (current) points, from exact products."""
    A, B, C = (np.array([Fraction(float(c)) for c in x[k]]) for k in face)
    n = np.cross(B - A, C - A)
    r = np.array([Fraction(float(c)) for c in p]) - A
    s = float(n @ r) / float(n @ n) ** 0.5
    return s


# (height of the point, wedge of the holding tetrahedron, weights of its three edges from
# the point): the vertex moves to P + EPS sum_k w_k (X_k - P), inside that tetrahedron
CASES = {"inner point": (0.75, 1, (0.4, 0.1, 0.1)), "top point": (1.0, 2, (0.1, 0.1, 0.3))}


def cut_cube():
    """The junction cube's cracks with the plane x = 1/2 cut through the whole cube: the half
    x < 1/2 is piece 1, the half x > 1/2 (with the crack y = 1/2 inside it) piece 0."""
    a = box_mesh(GRID, GRID, GRID)
    a = opened(a, plane_faces(a, 0, 0.5, lambda c: np.ones(len(c), bool)), lambda p: np.zeros(p.shape[:-1], bool))
    return opened(a, plane_faces(a, 1, 0.5, lambda c: (c[:, 2] > 0.5) & (c[:, 0] > 0.5) & (c[:, 0] < 0.75)),
                  lambda p: (p[..., 0] == 0.75) | (p[..., 2] == 0.5))


# the body and its piece per tetrahedron: three copies of the line's points on one piece, or
# two on the piece x > 1/2 and one on the piece x < 1/2
BODIES = {"one piece": (junction_cube, lambda a, labels: np.zeros(len(a.tets), np.int64)),
          "cut through": (cut_cube, lambda a, labels: (labels == 0).astype(np.int64))}


def holding_tet(a, labels, v, t, wedge):
    """The tetrahedron of ``wedge`` at copy t whose boundary faces at t all fail v's star
    test and include a lip; asserts there is one."""
    X, T, F = a.points, a.tets, a.faces
    for k in np.flatnonzero(np.any(T == t, axis=1) & (labels == wedge)):
        at = faces_at(F, T[k], t)
        if len(at) and not any(star_passes(X, T, F, v, f) for f in at):
            return int(k), at
    raise AssertionError(f"no tetrahedron of wedge {wedge} at copy {t} fails the star test")


@pytest.mark.parametrize("body", sorted(BODIES))
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_master_is_the_lip_the_vertex_is_least_deep_behind(case, body):
    z, wedge, weights = CASES[case]
    make, pieces = BODIES[body]
    a = make()
    X, T, F = a.points, a.tets, a.faces
    labels = wedge_labels(a)
    piece = pieces(a, labels)
    copies = copies_of(X, z)
    side = [set(labels[np.any(T == c, axis=1)].tolist()) for c in copies]
    assert len(copies) == 3 and sorted(map(tuple, side)) == [(0,), (1,), (2,)]
    v, t = (int(copies[side.index({w})]) for w in (0, wedge))
    k, at = holding_tet(a, labels, v, t, wedge)
    others = [u for u in T[k] if u != t]
    U = np.zeros_like(X)
    U[v] = EPS * sum(w * (X[u] - X[t]) for w, u in zip(weights, others))
    x = X + U
    ref = MasterReference(X, U, T, F, piece)
    lips = [f for f in at if ref.points_count[ref.points[f]] > 1]
    assert len(lips) == 1 and len(at) == (1 if z < 1 else 2)
    lip = lips[0]
    depth = -exact_signed(x, F[lip], x[v])
    assert np.isclose(depth, EPS * H * (weights[0] if z < 1 else weights[2]), rtol=1e-9)
    if z == 1.0:                       # the free top face is nearer: only lips are candidates
        top = next(f for f in at if f != lip)
        assert 0.0 < -exact_signed(x, F[top], x[v]) < depth / 2

    pen = detect_penetrations_3d(X, T, F, piece, displacement=U)
    i = np.flatnonzero(pen.vertex == v)
    assert len(i) == 1
    i = int(i[0])
    assert pen.fragment[i] == 0 and pen.tet[i] == k and pen.twin[i] >= 0
    assert pen.face[i] == lip
    assert abs(-pen.gap[i] - depth) <= 1e-15 * depth
    # the nearest face rule (without the lip fallback) would take a face on the plane x = 1/2
    cand, d = ref.nearest(v, 0)
    assert np.all(X[F[cand[d == d.min()]], 0] == 0.5) and abs(d.min() - depth) > 0.2 * depth

    # the brute-force reference: the same pairs, the same master faces, the same key
    assert ref.at_copy(v, 0, T[k]) == (lip, pytest.approx(-depth, rel=1e-15), True)
    vertex, fragment, tet, closed = brute_force_pairs(X, T, F, piece, U)
    assert np.array_equal(pen.vertex, vertex) and np.array_equal(pen.fragment, fragment)
    assert np.array_equal(pen.tet, tet) and pen.stats["closed_seams"] == closed
    crossed, behind = ref.check(pen, 1e-15)
    assert behind == 1
    key = node_to_face_rows(X, F, pen).keys()[i]
    assert key == ("f", v, *sorted(F[lip].tolist()))
    print(f"\n{case}, {body}: {len(pen)} pairs, {crossed} at a copy, {behind} by the lip rule; depth {depth:.6g} "
          f"(detected - exact {-pen.gap[i] - depth:.3g}), nearest face {d.min():.6g}, {closed} closed seams")


def test_deep_in_the_star_the_master_is_the_face_at_the_copy_least_deep_behind():
    """The copy of W0 at the inner point moved into a tetrahedron of W2 at the copy t there
    with no face on the boundary (past the faces of the tetrahedra the rules above look
    at): the master is the boundary face at t that the vertex is least deep behind, here
    W2's lip on y = 1/2 (the vertex nearer to it than to W2's lip on x = 1/2). The nearest
    face rule takes only faces opposing the vertex's normal or coincident with its faces
    (the lips on x = 1/2): a face the vertex is deeper behind."""
    a = junction_cube()
    X, T, F = a.points, a.tets, a.faces
    labels = wedge_labels(a)
    copies = copies_of(X, 0.75)
    side = [set(labels[np.any(T == c, axis=1)].tolist()) for c in copies]
    v, t = (int(copies[side.index({w})]) for w in (0, 2))
    found = None
    for k in np.flatnonzero(np.any(T == t, axis=1) & (labels == 2)):
        if len(faces_at(F, T[k], t)):
            continue
        direction = sum(X[u] - X[t] for u in T[k] if u != t)
        if abs(direction[1]) < abs(direction[0]):              # nearer to y = 1/2 than to x = 1/2
            found = int(k), direction
            break
    assert found is not None
    k, direction = found
    U = np.zeros_like(X)
    U[v] = EPS * 0.2 * direction
    x = X + U
    at_t = np.flatnonzero(np.any(F == t, axis=1))
    signed = np.array([exact_signed(x, F[f], x[v]) for f in at_t])
    behind = at_t[signed < 0]
    best = behind[np.argmax(signed[signed < 0])]
    assert np.all(np.abs(X[F[best], 1] - 0.5) == 0) and np.any(np.abs(X[F[behind], 0] - 0.5) == 0)

    pen = detect_penetrations_3d(X, T, F, np.zeros(len(T), np.int64), displacement=U)
    i = int(np.flatnonzero(pen.vertex == v)[0])
    assert pen.tet[i] == k and pen.face[i] == best
    assert abs(pen.gap[i] - signed[at_t == best][0]) <= 1e-15 * abs(pen.gap[i])
    ref = MasterReference(X, U, T, F, np.zeros(len(T), np.int64))
    cand, d = ref.nearest(v, 0)
    assert best not in cand                                   # the rule without it takes another face
    ref.check(pen, 1e-15)


# the corner of the crack of cut_cube on the cut: the crack's front z = 1/2 meets the cut
# there, and the piece x > 1/2 has one copy of the point, at which both lips end
FRONT_CORNER = 0.5


@pytest.mark.parametrize("weights", [(0.3, 0.2, 0.1), (0.1, 0.1, 0.4)])
def test_a_copy_past_a_crack_front_at_its_copy_is_held_by_the_lip_it_is_behind(weights):
    """The copy v of piece 1 at the corner of cut_cube's crack moved into a tetrahedron of
    the piece x > 1/2 above the crack, at the piece's copy t there, whose boundary faces at
    t are lips of the crack (no face on x = 1/2): v's reference star lies across their
    plane, and t is the piece's only copy of the point (the crack's front passes through
    it). The master is the lip v is least deep behind (the upper lip: the way back into
    the slit), not the nearest face the vertex's normal opposes (here a face of the cut;
    in the random box of docs/contact.md the coincident lower lip, which v was in front of)."""
    z = FRONT_CORNER
    a = cut_cube()
    X, T, F = a.points, a.tets, a.faces
    labels = wedge_labels(a)
    piece = (labels == 0).astype(np.int64)
    copies = copies_of(X, z)
    side = [set(labels[np.any(T == c, axis=1)].tolist()) for c in copies]
    assert sorted(map(tuple, side)) == [(0,), (1, 2)]      # one copy on each piece: t at the front
    v, t = (int(copies[[0 in s for s in side].index(want)]) for want in (True, False))
    k, at = holding_tet(a, labels, v, t, 2)
    ref = MasterReference(X, np.zeros_like(X), T, F, piece)
    assert all(ref.points_count[ref.points[f]] == 2 and X[F[f], 1].tolist() == [0.5] * 3 for f in at)
    others = [u for u in T[k] if u != t]
    U = np.zeros_like(X)
    U[v] = EPS * sum(w * (X[u] - X[t]) for w, u in zip(weights, others))
    x = X + U
    signed = np.array([exact_signed(x, F[f], x[v]) for f in at])
    assert np.all(signed < 0)
    lip = int(at[np.argmax(signed)])

    pen = detect_penetrations_3d(X, T, F, piece, displacement=U)
    i = np.flatnonzero(pen.vertex == v)
    assert len(i) == 1
    i = int(i[0])
    assert pen.fragment[i] == 0 and pen.tet[i] == k and pen.twin[i] == t
    assert pen.face[i] == lip
    assert abs(pen.gap[i] - signed.max()) <= 1e-15 * abs(pen.gap[i])
    # without the rule the nearest face the vertex's normal opposes is the master: another face
    ref = MasterReference(X, U, T, F, piece)
    cand, d = ref.nearest(v, 0)
    assert lip not in cand[d == d.min()]

    assert ref.at_copy(v, 0, T[k]) == (lip, pytest.approx(signed.max(), rel=1e-15), True)
    vertex, fragment, tet, closed = brute_force_pairs(X, T, F, piece, U)
    assert np.array_equal(pen.vertex, vertex) and np.array_equal(pen.fragment, fragment)
    assert np.array_equal(pen.tet, tet) and pen.stats["closed_seams"] == closed
    assert ref.check(pen, 1e-15)[1] == 1
