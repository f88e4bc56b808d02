"""A warm start's row at a pair of copies that the scene's own rows tie (``ActiveSet3d``).

The sphere ties every core vertex to its glass copy by two stick rows (a general row on
exactly the two vertices each). The third, normal, direction is held by a contact row at
the copy, and where the interface bends at the point that row can be one on a face at the
glass copy that no fixed row has: a found row. The next solve starts from the keys of the
rows imposed (the warm start), and a found row at a copy is rebuilt from its key in the
first round, or it is missing: the pair then has no normal row in that round and the core
vertex sinks into the glass until the detection finds it again (measured on the default
sphere's step 40, resumed from step 39: 8.1e-4 deep after the first round of every solve).
The rows at copies found by their planes are left out at tied pairs (more rows there would
depend on the tie), but the warm rows are the rows the solve before imposed beside the tie.

Three blocks around a line (``sector_blocks``): A on [0, 60] degrees, C on [60, 120], B on
[120, 360]. s is A's copy of a point of the line, t B's; a hold ties their x motion. A warm
key names s's row on B's face at 120 degrees (shared with C: no fixed row of s has it).
A moved by eps (1, 1/2), out of every block: that row's gap is
n . (x_s - x_t) = unit(30) . eps (1, 1/2) = (sqrt 3 / 2 + 1/4) eps, with or without the
tie, and the first choice imposes it (a warm row).
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ngfracture.contact.active_set import Geometry
from ngfracture.contact.active_set3d import ActiveSet3d
from ngfracture.contact.setup3d import MeshSetup3d
from sector_blocks import sector_blocks, unit

H = 0.5
EPS = 1e-3


@pytest.fixture(scope="module")
def blocks():
    arrays, fragment = sector_blocks(2, [0.0, H])                # A 0, C 1, B 2
    return arrays, fragment, MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)


def pair_and_face(arrays, setup):
    """s (A's copy of the line's point at z = 0), t (B's), and B's face at 120 degrees at t."""
    X, vf = arrays.points, setup.vertex_fragment
    at = np.flatnonzero(np.all(X == 0.0, axis=1))
    s, t = at[vf[at] == 0][0], at[vf[at] == 2][0]
    F = arrays.faces
    e0, e1 = X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]
    n = np.cross(e0, e1)
    n /= np.linalg.norm(n, axis=1)[:, None]
    face = np.flatnonzero(np.any(F == t, axis=1) & (n @ unit(30) > 1 - 1e-12))
    assert len(face) == 1
    return s, t, face[0]


def active_set(arrays, fragment, s, t, warm, tie):
    nv = len(arrays.points)
    holds = None
    if tie:
        holds = sp.csr_matrix((np.array([1.0, -1.0]), (np.zeros(2, dtype=np.int64), np.array([s, t]))),
                              shape=(1, 3 * nv))
    geometry = Geometry(arrays=arrays, fragment=fragment, seams=None, fixed=np.zeros(0, dtype=np.int64),
                        holds=holds)
    return ActiveSet3d(geometry, 1e-12, copy_tol=1e-9, warm=warm)


def moved(arrays, setup, d):
    U = np.zeros_like(arrays.points)
    U[setup.vertex_fragment == 0, :2] = d
    return U


@pytest.mark.parametrize("tie", [False, True])
def test_warm_row_at_a_copy_is_a_first_round_candidate(blocks, tie):
    arrays, fragment, setup = blocks
    s, t, face = pair_and_face(arrays, setup)
    key = ("f", int(s)) + tuple(sorted(int(v) for v in arrays.faces[face]))
    assert key not in set(setup.keys)                             # no fixed row has it
    active = active_set(arrays, fragment, s, t, [key], tie)
    if tie:
        assert active.tied.tolist() == [min(s, t) * len(arrays.points) + max(s, t)]
    U = moved(arrays, setup, EPS * np.array([1.0, 0.5]))
    candidates = active.update(U, {"collision": 0.0})
    keys = list(candidates.keys)
    assert key in keys
    i = keys.index(key)
    assert abs(candidates.gap[i] - (np.sqrt(3) / 2 + 0.25) * EPS) < 1e-12 * EPS
    want, _, _ = active.primal_dual(candidates)
    assert i in set(want.tolist())                                 # warm: imposed in the first choice

