"""A vertex pushed along a crack lip's plane past the crack's front edge (``contact/clipped3d.py``;
docs/contact.md, "A vertex past a crack front").

The block [0, 1] x [-1/2, 1/2]^2 (4 cells a side, 384 tets) has a crack on the plane y = 0
for x < 1/2, z > 0, opened in numpy: it reaches the face x = 0, and its front edge z = 0
reaches that face at P = 0. A tip, one tetrahedron meshed apart (its own piece), lies
outside the block with its vertex s on the plane y = 0 at P + (-5, 0, 2) 1e-4, its axis
(1, 0.4, 0) (so that its normal opposes the normal -y of the lip of the half y > 0, the
face the detection takes as s's master), 1 long, its base of radius 0.05 moved by
D = (8, 1, -4) 1e-4; the block is clamped at x = 1; E = 1, nu = 0.25.

Moved rigidly, s lies at P + (3, 1, -2) 1e-4: inside the block, below the front (z < 0),
1e-4 behind the lip's plane; the nearest point of the lip triangle is on the front edge,
at the distance sqrt(5) 1e-4, the detected depth. The row on the lip reads only the plane's
1e-4: once it holds s on the plane, s sits 2e-4 ahead of the front inside the block and no
row sees it (the contact solve without the node-to-edge rows ends there, "converged", s
2e-4 deep). With them the solve ends with no vertex deeper than its ``penetration_tol``.

The dumped state of the coarse free sphere (``data/front_overlap.npz``: X, T, F, the piece
of every vertex, U of the attempt of x = 2.660e-3 that failed on overlap) has the same
mechanism: vertex 319 of piece 0 on the plane of a lip of a crack inside piece 3 (its
found row at its copy 859 reads 6.2e-9 there) and 7.17e-7 from the lip triangle, past
the front edge 143-859; its node-to-edge row must read that depth.
"""
import os

import numpy as np
import pytest

from ngfracture.contact.active_set import Geometry
from ngfracture.contact.active_set3d import ActiveSet3d
from ngfracture.contact.clipped3d import node_edge_rows, unseen_pairs
from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.edge_rows3d import relinearise_edge_rows
from ngfracture.contact.setup3d import FaceKeys
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import SolidArrays, merge_bodies, solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

from test_contact3d_crack_junction import opened, plane_faces

S0 = 1e-4 * np.array([-5.0, 0.0, 2.0])          # the tip's vertex
D = 1e-4 * np.array([8.0, 1.0, -4.0])           # the motion of its base
AXIS = np.array([1.0, 0.4, 0.0])
DUMP = os.path.join(os.path.dirname(__file__), "data", "front_overlap.npz")


def cracked_block():
    """The block with the crack y = 0, x < 1/2, z > 0 (front: z = 0 and x = 1/2)."""
    a = box_mesh(np.linspace(0.0, 1.0, 5), np.linspace(-0.5, 0.5, 5), np.linspace(-0.5, 0.5, 5))
    return opened(a, plane_faces(a, 1, 0.0, lambda c: (c[:, 2] > 0) & (c[:, 0] < 0.5)),
                  lambda p: (p[..., 0] == 0.5) | (p[..., 2] == 0.0))


def tip(s0, axis, length=1.0, radius=0.05):
    """One tetrahedron with its vertex 0 at s0, its base (boundary "base") ``length`` back along ``axis``."""
    axis = axis / np.linalg.norm(axis)
    u = np.cross(axis, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    c = s0 - length * axis
    P = np.array([s0] + [c + radius * (np.cos(t) * u + np.sin(t) * w) for t in (0, 2 * np.pi / 3, 4 * np.pi / 3)])
    T = np.array([[0, 1, 2, 3]])
    if np.dot(P[1] - P[0], np.cross(P[2] - P[0], P[3] - P[0])) < 0:
        T = np.array([[0, 2, 1, 3]])
    F = []
    for k in range(4):
        f = [int(v) for v in T[0] if v != T[0, k]]
        if np.dot(np.cross(P[f[1]] - P[f[0]], P[f[2]] - P[f[0]]), P[f[0]] - P[T[0, k]]) < 0:
            f = f[::-1]
        F.append(f)
    F = np.array(F)
    return SolidArrays(points=P, tets=T, regions=np.ones(1, dtype=np.int64), region_names=["tip"], faces=F,
                       face_bc=np.where(np.any(F == 0, axis=1), 2, 1), bc_names=["base", "side"])


def make_body(scale=1.0):
    """The block and the tip, its vertex at ``scale`` S0; and the tip's vertex."""
    a = merge_bodies([("block", cracked_block()), ("tip", tip(scale * S0, AXIS))])
    return a, len(a.points) - 4


@pytest.fixture(scope="module")
def body():
    return make_body()


def rigid(a, s):
    """The tip moved by D, the block at rest."""
    U = np.zeros_like(a.points)
    U[s:] = D
    return U


def candidates_of(a, s, U):
    """The gaps at U of the candidate rows of the tip's vertex in a contact solve's first round."""
    active = ActiveSet3d(Geometry(arrays=a, fragment=(a.regions - 1).astype(np.int64), seams=None,
                                  fixed=np.zeros(0, dtype=np.int64)), 1e-13)
    candidates = active.update(U, {"collision": 0.0})
    gaps = candidates.rows.C @ U.T.ravel() + candidates.rows.g
    return {k: g for k, g in zip(candidates.keys, gaps) if k[1] == s}


def test_past_the_front_on_the_lip_plane_only_the_node_to_edge_row_reads_the_depth(body):
    a, s = body
    X = a.points
    piece = (a.regions - 1).astype(np.int64)
    U = rigid(a, s)
    pen = detect_penetrations_3d(X, a.tets, a.faces, piece, U)
    assert len(pen) == 1 and pen.vertex[0] == s
    face = a.faces[pen.face[0]]
    assert np.all(X[face, 1] == 0.0) and np.all(X[face, 2] >= 0.0)           # a lip face above the front
    assert np.allclose(pen.normal[0], [0.0, -1.0, 0.0])
    assert np.min(pen.bary[0]) == 0.0                                         # clipped to the front edge
    assert abs(pen.gap[0] + np.sqrt(5.0) * 1e-4) <= 1e-15
    lip = ("f", s, *sorted(face.tolist()))
    # the lip's row reads the plane's 1e-4 of the depth: it moves s, nothing else is needed yet
    assert candidates_of(a, s, U) == {lip: pytest.approx(-1e-4, abs=1e-15)}
    # held on the lip's plane, s is 2e-4 below the front: the lip's row reads 0, the
    # node-to-edge row the depth, along the line to the front edge (z = 0)
    U[s, 1] -= 1e-4
    pen = detect_penetrations_3d(X, a.tets, a.faces, piece, U)
    assert len(pen) == 1 and a.faces[pen.face[0]].tolist() == face.tolist() and pen.gap[0] == pytest.approx(-2e-4)
    mine = candidates_of(a, s, U)
    edge = [k for k in mine if k[0] == "n"]
    assert len(mine) == 2 and len(edge) == 1 and abs(mine[lip]) <= 1e-18
    assert np.all(X[list(edge[0][2:]), 1:] == 0.0)                            # the front edge
    assert abs(mine[edge[0]] - pen.gap[0]) <= 1e-18
    rows = node_edge_rows(X, a.faces, pen, unseen_pairs(pen, a.faces, (), X, U, _vf(a), 1e-13), U)
    assert np.allclose(rows.normal[0], [0.0, 0.0, 1.0], atol=1e-12)


def _vf(a):
    """The piece of every vertex."""
    vf = np.full(len(a.points), -1, dtype=np.int64)
    vf[a.tets.ravel()] = np.repeat(a.regions - 1, 4)
    return vf


@pytest.mark.parametrize("scale", [1.0, 100.0])
def test_the_solve_holds_the_tip_out_of_the_block(scale):
    """At 100 times the motion the lips turn while the tip is pushed back, and a pair found
    deep again takes the new detection's direction (keeping the old one ends 1.6e-10 deep)."""
    a, s = make_body(scale)
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=1.0, nu=0.25))
    prob.add_dirichlet("block_xmax", 0.0)
    for comp, value in zip("xyz", scale * D):
        prob.add_dirichlet("tip_base", float(value), component=comp)
    solver = ContactSolver(prob, tol=1e-3)
    result = solver.solve()
    U = vertex_displacement(prob.u)
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, (a.regions - 1).astype(np.int64), U)
    deepest = max(0.0, -float(np.min(pen.gap, initial=0.0)))
    x = a.points + U
    print(f"\nscale {scale}: rounds {result.rounds}, deepest {deepest:.3g} (penetration_tol "
          f"{solver.penetration_tol:.3g}), tip at {x[s]}")
    assert result.converged, result.reason
    assert deepest <= solver.penetration_tol
    assert x[s, 0] > 2e-4 * scale                  # the tip stays in the crack's plane, not pushed back out


def test_relinearisation_keeps_the_direction(body):
    a, s = body
    X = a.points
    U = rigid(a, s)
    U[s, 1] -= 1e-4
    pen = detect_penetrations_3d(X, a.tets, a.faces, (a.regions - 1).astype(np.int64), U)
    rows = node_edge_rows(X, a.faces, pen, np.arange(1), U)
    V = U.copy()
    V[s] += [1e-5, 2e-5, 3e-4]                      # past the edge, off the plane
    again = relinearise_edge_rows(rows, X, V)
    assert np.array_equal(again.normal, rows.normal) and np.array_equal(again.st, rows.st)
    p = (1 - rows.st[0, 1]) * (X + V)[rows.edge_b[0, 0]] + rows.st[0, 1] * (X + V)[rows.edge_b[0, 1]]
    assert again.dist[0] == pytest.approx(rows.normal[0] @ ((X + V)[s] - p), abs=1e-18)


def test_keys_of_node_to_edge_rows():
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    edges = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
    codec = FaceKeys(F, edges)
    keys = [("n", 3, 1, 2), ("n", 0, 2, 2), ("e", 0, 1, 2, 3), ("f", 3, 0, 1, 2), ("n", 2, 0, 3)]
    codes = codec.codes_of(keys)
    assert codec.decode(codes) == keys
    assert np.array_equal(codec.is_node_edge(codes), [True, True, False, False, True])
    assert len(set(codes.tolist())) == 5 and -1 not in codes
    assert codec.codes_of([("n", 3, 2, 1), ("n", 4, 0, 1)]).tolist() == [-1, -1]   # no edge (2, 1); no vertex 4


def test_dumped_sphere_state_gets_the_row_at_its_depth():
    z = np.load(DUMP)
    X, T, F, piece, U = z["X"], z["T"], z["F"], z["piece"], z["U"]
    arrays = SolidArrays(points=X, tets=T, regions=np.ones(len(T), dtype=np.int64), region_names=["glass"], faces=F,
                         face_bc=np.zeros(len(F), dtype=np.int64), bc_names=["surface"])
    active = ActiveSet3d(Geometry(arrays=arrays, fragment=piece[T[:, 0]], seams=None,
                                  fixed=np.zeros(0, dtype=np.int64)), 1e-12, copy_tol=1e-9)
    candidates = active.update(U, {"collision": 0.0})
    pen = active.setup.detector.detect(U)
    deep = int(np.argmin(pen.gap))
    assert pen.vertex[deep] == 319 and pen.fragment[deep] == 3 and pen.gap[deep] == pytest.approx(-7.17e-7, rel=1e-3)
    keys = list(candidates.keys)
    gaps = candidates.rows.C @ U.T.ravel() + candidates.rows.g
    mine = {k: g for k, g in zip(keys, gaps) if k[1] == 319}
    assert set(mine) == {("f", 319, 143, 745, 859), ("n", 319, 143, 859)}
    assert mine[("f", 319, 143, 745, 859)] > pen.gap[deep] + 1e-7                 # the lip's row: its plane
    assert abs(mine[("n", 319, 143, 859)] - pen.gap[deep]) <= 1e-12
    assert sum(k[0] == "n" for k in keys) == 1
