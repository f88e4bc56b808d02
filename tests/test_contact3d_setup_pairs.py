"""The C++ kernels of the set-up's pairs of copies (cpp_ext/contact_setup3d.cpp) against the
numpy computations they replace, kept here as the reference: the same arrays, in the same
order, with the same dtypes, byte for byte.

Kernels: ``CopyPairs`` (kinks3d.copy_pairs), ``PartnerIncidences``
(copies3d.partner_incidences), ``DiagonalEdgePairs`` (wedges3d.diagonal_edges),
``TwoFaces`` (edge_rows3d.two_faces), ``VertexFragments`` (setup3d.vertex_fragments),
``CoveredPairs`` (junctions3d.covered_pairs), and the edge crossing detector's edges and
faces at edges (edge_crossings3d.EdgeCrossingDetector, made by a counting sort instead of
a sort of the (edge, face slot) pairs). Meshes: fragmented boxes (junctions of 4 and 8
copies; a crack inside one block, where three copies meet; bent lips), the contact
benchmark's body at 6 cells, random small cases (faces and fragments drawn at random over
points with several copies, so that runs of copies, shared keys and edges with other than
two faces occur in every combination; faces around one point with more than 64 edges,
the sorts' long buckets), empty inputs, and (slow) a cracked state of the
default sphere.
"""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ngfracture import _ngfracture as _ext
from ngfracture.contact.copies3d import partner_incidences
from ngfracture.contact.edge_crossings3d import EdgeCrossingDetector
from ngfracture.contact.edge_rows3d import two_faces
from ngfracture.contact.intsets import unique_ints
from ngfracture.contact.junctions3d import covered_pairs, fragment_pair_rows
from ngfracture.contact.kinks3d import CopyIndex, copy_pairs, expand_ranges, partner_faces
from ngfracture.contact.rows3d import NodeToFaceRows, lip_rows
from ngfracture.contact.setup3d import vertex_fragments
from ngfracture.contact.wedges3d import diagonal_edges
from ngfracture.geometry.pieces import fragmented_box

from test_contact3d_setup_kernels import BODIES, assert_same, box


# -- the numpy references ---------------------------------------------------------------

def equal_key_pairs(key):
    """Every ordered pair (i, j) of positions of a sorted array with equal values, i == j
    included: i increasing, then j."""
    first = np.searchsorted(key, key)                                      # start of each value's run
    size = np.searchsorted(key, key, side="right") - first
    return expand_ranges(first, size)


def reference_copy_pairs(index):
    """kinks3d.copy_pairs in numpy."""
    who, other = equal_key_pairs(index.group)
    return index.on[who], index.on[other]


def reference_partner_incidences(index, vertex_fragment):
    """copies3d.partner_incidences in numpy."""
    s, t = reference_copy_pairs(index)
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    ahead = (vf[s] > vf[t]) | ((vf[s] == vf[t]) & (s > t))
    return partner_faces(index.points, index.faces, s[ahead], t[ahead], all_pairs=True, one_way=False, index=index)


def reference_two_faces(edge_face_ptr, edge_faces):
    """edge_rows3d.two_faces in numpy."""
    ptr = np.asarray(edge_face_ptr, dtype=np.int64)
    faces = np.asarray(edge_faces, dtype=np.int64)
    out = np.full((len(ptr) - 1, 2), -1, dtype=np.int64)
    two = np.flatnonzero(np.diff(ptr) == 2)
    out[two] = np.sort(np.stack([faces[ptr[two]], faces[ptr[two] + 1]], axis=1), axis=1)
    return out


def reference_diagonal_edges(edges, faces_at_edge, vertex_fragment, index):
    """wedges3d.diagonal_edges in numpy: a, b ends, b's faces, edge a, edge b."""
    E = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    at = np.asarray(faces_at_edge, dtype=np.int64).reshape(-1, 2)
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    pid = index.point
    if not len(E):
        return (*(np.zeros((0, 2), np.int64) for _ in range(3)), *(np.zeros(0, np.int64) for _ in range(2)))
    P = np.sort(pid[E], axis=1)
    code = P[:, 0] * (np.int64(P.max()) + 1) + P[:, 1]
    order = np.argsort(code, kind="stable")
    a, b = (order[i] for i in equal_key_pairs(code[order]))
    other = vf[E[a, 0]] != vf[E[b, 0]]
    a, b = a[other], b[other]
    fa, fb = at[a], at[b]
    two = (fa >= 0).all(axis=1) & (fb >= 0).all(axis=1)
    key = index.face_key
    shared = (key[np.maximum(fa, 0)][:, :, None] == key[np.maximum(fb, 0)][:, None, :]).any(axis=(1, 2))
    keep = np.flatnonzero(two & ~shared)
    a, b = a[keep], b[keep]
    ends_b = E[b]
    flip = pid[ends_b[:, 0]] != pid[E[a, 0]]
    ends_b[flip] = ends_b[flip][:, ::-1]
    sort = np.lexsort((b, a))
    return E[a][sort], ends_b[sort], at[b][sort], a[sort], b[sort]


def reference_vertex_fragments(nv, tets, fragment):
    """setup3d.vertex_fragments in numpy."""
    vertex_fragment = np.full(nv, -1, dtype=np.int64)
    vertex_fragment[np.asarray(tets).ravel()] = np.repeat(np.asarray(fragment, dtype=np.int64), 4)
    return vertex_fragment


def reference_covered_pairs(points, rows, vertex_fragment):
    """junctions3d.covered_pairs in numpy (the arrays already checked)."""
    X = np.asarray(points, dtype=np.float64)
    nv = len(X)
    s, m = np.asarray(rows.slave, dtype=np.int64), np.asarray(rows.master, dtype=np.int64).reshape(-1, 3)
    vf = np.asarray(vertex_fragment).astype(np.int64)
    copy = np.all(X[m] == X[s][:, None, :], axis=2)
    has = copy.any(axis=1) & (vf[m[:, 0]] != vf[s])
    t = m[np.flatnonzero(has), copy[has].argmax(axis=1)]
    return unique_ints(np.r_[vf[m[:, 0]] * nv + s, vf[s[has]] * nv + t])


def reference_edges(faces):
    """EdgeCrossingDetector's edges, edge_face_ptr, edge_faces and face_edges in numpy: the
    (edge, face slot) pairs sorted."""
    F = np.asarray(faces, dtype=np.int64)
    E = np.sort(np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)     # slot 3 f + k
    order = np.lexsort((np.arange(len(E)), E[:, 1], E[:, 0]))
    first = np.r_[True, np.any(E[order][1:] != E[order][:-1], axis=1)] if len(E) else np.zeros(0, dtype=bool)
    number = np.cumsum(first) - 1
    face_edges = np.empty(len(E), dtype=np.int64)
    face_edges[order] = number
    ptr = np.r_[np.flatnonzero(first), len(E)] if len(E) else np.zeros(1, dtype=np.int64)
    return E[order][first], ptr.astype(np.int64), order // 3, face_edges.reshape(-1, 3)


# -- the meshes ----------------------------------------------------------------------------

def vertex_fragments_of(nv, tets):
    """The fragments of a tetrahedral mesh: its components by shared vertices, per vertex."""
    T = np.asarray(tets, dtype=np.int64)
    m = coo_matrix((np.ones(T.size), (np.repeat(np.arange(len(T)), 4), T.ravel())), shape=(len(T), nv))
    _, label = connected_components((m.T @ m).tocsr(), directed=False)
    return label.astype(np.int64)


def benchmark_body(cells=6, pieces=4):
    """The contact benchmark's fragmented cube (benchmarks/contact3d.py) at a small size."""
    arrays, piece = fragmented_box(cells, pieces)
    vf = np.full(len(arrays.points), -1, dtype=np.int64)
    vf[arrays.tets.ravel()] = np.repeat(piece, 4)
    return arrays.points, arrays.faces.astype(np.int64), vf


def random_case(seed, nv=40, points=12, nf=60, fragments=3):
    """Vertices on a few points (several copies each), random faces and fragments."""
    rng = np.random.default_rng(seed)
    P = rng.integers(0, 3, size=(points, 3)).astype(np.float64) * 0.5
    X = P[rng.integers(0, points, size=nv)]
    F = np.stack([rng.choice(nv, size=3, replace=False) for _ in range(nf)])
    vf = rng.integers(0, fragments, size=nv).astype(np.int64)
    return X, F.astype(np.int64), vf


def random_hub(seed, nv=60, nf=150):
    """Random faces that all have a copy of the lowest point (four copies): more than 64
    edges on that point, the long buckets of the kernels' sorts."""
    X, F, vf = random_case(seed, nv=nv, nf=nf)
    X[:4] = -1.0
    rng = np.random.default_rng(seed)
    F[:, 0] = rng.integers(0, 4, size=nf)
    F[:, 1:] = np.stack([rng.choice(np.arange(4, nv), size=2, replace=False) for _ in range(nf)])
    return X, F, vf


def mesh_cases():
    """(name, points, faces, vertex_fragment) of the boxes, the benchmark body and random cases."""
    cases = [(f"box{b}", *box(**b)) for b in BODIES]
    cases.append(("benchmark", *benchmark_body()))
    cases += [(f"random{seed}", *random_case(seed)) for seed in range(6)]
    cases += [(f"random_hub{seed}", *random_hub(seed)) for seed in range(2)]
    return cases


CASES = mesh_cases()


def edge_arrays(X, F, vf, index, name="mesh"):
    """The boundary edges and their faces (CSR): the edge detector's of a mesh; of random
    faces (whose vertices may lie on faces of two fragments, which the detector refuses)
    the same arrays in numpy."""
    if not name.startswith("random"):
        detector = EdgeCrossingDetector(X, F, vf[F[:, 0]], across=True, point=index.point)
        return detector.edges, detector.edge_face_ptr, detector.edge_faces
    E = np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    edges, which = np.unique(E, axis=0, return_inverse=True)
    order = np.lexsort((np.repeat(np.arange(len(F)), 3), which.ravel()))
    ptr = np.r_[0, np.cumsum(np.bincount(which.ravel(), minlength=len(edges)))]
    return edges, ptr, np.repeat(np.arange(len(F)), 3)[order]


def compare_all(X, F, vf, name):
    """The kernels of this file on faces against their references on one mesh; the counts
    compared."""
    index = CopyIndex(X, F)
    for got, want, what in zip(copy_pairs(index), reference_copy_pairs(index), ("s", "t")):
        assert_same(got, want, f"{name}: copy_pairs {what}")
    partners, reference = partner_incidences(index, vf), reference_partner_incidences(index, vf)
    for got, want, what in zip(partners, reference, ("slave", "face", "corner")):
        assert_same(got, want, f"{name}: partner_incidences {what}")
    edges, ptr, at_edge = edge_arrays(X, F, vf, index, name)
    at = two_faces(ptr, at_edge)
    assert_same(at, reference_two_faces(ptr, at_edge), f"{name}: two_faces")
    pairs = diagonal_edges(edges, at, vf, index)
    for field, want in zip(("a", "b", "b_faces", "edge_a", "edge_b"), reference_diagonal_edges(edges, at, vf, index)):
        assert_same(getattr(pairs, field), want, f"{name}: diagonal_edges {field}")
    # rows of every vertex at random faces (copies on one fragment and on others), and the
    # fixed rows at copies of a mesh
    rng = np.random.default_rng(len(F))
    face = rng.integers(0, len(F), size=4 * len(F))
    for rows in [SimpleNamespace(slave=np.sort(rng.integers(0, len(X), size=len(face))), master=F[face], nv=len(X))] + (
            [] if name.startswith("random") else
            [NodeToFaceRows.stack([fragment_pair_rows(X, F, vf, index=index), lip_rows(X, F, vf, index=index)])]):
        assert_same(covered_pairs(X, rows, vf), reference_covered_pairs(X, rows, vf), f"{name}: covered_pairs")
    return len(partners[0]), len(pairs), int(np.sum(at[:, 0] < 0))


# -- the comparisons ---------------------------------------------------------------------

@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_set_up_pair_kernels_are_the_numpy_arrays(case):
    name, X, F, vf = case
    partners, diagonal, odd_edges = compare_all(X, F, vf, name)
    if name.startswith("box") or name == "benchmark":
        assert partners > 0                            # copies on every cut
    if name == "benchmark":
        assert diagonal > 0 and odd_edges == 0         # junction lines of 4 blocks; a closed surface


def test_edge_detector_arrays_are_the_sorted_pairs():
    """The edge crossing detector's edges on every mesh of faces it takes (the random
    faces on one fragment; the faces shuffled, so that the slots of an edge come unsorted)."""
    rng = np.random.default_rng(11)
    for name, X, F, vf in CASES:
        frag = vf[F[:, 0]] if not name.startswith("random") else np.zeros(len(F), dtype=np.int64)
        for faces in (F, F[rng.permutation(len(F))]):
            detector = EdgeCrossingDetector(X, faces, frag if faces is F else np.zeros(len(F), np.int64))
            for field, want in zip(("edges", "edge_face_ptr", "edge_faces", "face_edges"), reference_edges(faces)):
                assert_same(getattr(detector, field), want, f"{name}: {field}")
    # a vertex with more than 64 edge slots (the fan of a cone): the long bucket's sort
    n = 80
    ring = np.arange(1, n + 1)
    fan = np.stack([np.zeros(n, dtype=np.int64), ring, np.roll(ring, -1)], axis=1)
    fan = fan[rng.permutation(n)]
    angle = 2 * np.pi * np.arange(n) / n
    X = np.r_[[[0.0, 0.0, 1.0]], np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], axis=1)]
    detector = EdgeCrossingDetector(X, fan, np.zeros(n, dtype=np.int64))
    for field, want in zip(("edges", "edge_face_ptr", "edge_faces", "face_edges"), reference_edges(fan)):
        assert_same(getattr(detector, field), want, f"fan: {field}")


def test_vertex_fragments_kernel_is_the_numpy_scatter():
    arrays, piece = fragmented_box(4, 2)
    rng = np.random.default_rng(2)
    tets = np.r_[arrays.tets, arrays.tets[:5]].astype(np.int64)
    fragment = rng.integers(0, 9, size=len(tets))              # a vertex in tetrahedra of several: the last one's
    nv = len(arrays.points) + 3                                 # vertices in no tetrahedron: -1
    # every memory layout (the kernel reads the strides) and int32
    for T in (tets, np.asfortranarray(tets), tets[::-1], tets[:, ::-1], tets.astype(np.int32)):
        assert_same(vertex_fragments(nv, T, fragment), reference_vertex_fragments(nv, T, fragment))
    assert_same(vertex_fragments(len(arrays.points), arrays.tets, piece),
                reference_vertex_fragments(len(arrays.points), arrays.tets, piece))
    none = np.zeros((0, 4), np.int32)
    assert_same(vertex_fragments(4, none, none[:, 0]), reference_vertex_fragments(4, none, none[:, 0]))
    with pytest.raises(ValueError, match="tets"):
        vertex_fragments(3, arrays.tets, piece)
    with pytest.raises(ValueError, match="fragment"):
        vertex_fragments(nv, tets, fragment[:-1])


def test_random_cases_meet_every_branch():
    """Over the random cases: edges with other than two faces, diagonal pairs, partner
    faces, pairs of copies on one fragment (the direction s > t)."""
    totals = np.sum([compare_all(X, F, vf, name)[:3] for name, X, F, vf in CASES if name.startswith("random")],
                    axis=0)
    assert np.all(totals > 0)


def test_empty_inputs():
    X = np.zeros((3, 3))
    F = np.zeros((0, 3), dtype=np.int64)
    vf = np.zeros(3, dtype=np.int64)
    index = CopyIndex(X, F)
    for got, want in zip(copy_pairs(index), reference_copy_pairs(index)):
        assert_same(got, want, "copy_pairs")
    for got, want in zip(partner_incidences(index, vf), reference_partner_incidences(index, vf)):
        assert_same(got, want, "partner_incidences")
    ptr, none = np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64)
    assert_same(two_faces(ptr, none), reference_two_faces(ptr, none), "two_faces")
    E = np.zeros((0, 2), dtype=np.int64)
    pairs = diagonal_edges(E, E, vf, index)
    for field, want in zip(("a", "b", "b_faces", "edge_a", "edge_b"), reference_diagonal_edges(E, E, vf, index)):
        assert_same(getattr(pairs, field), want, f"diagonal_edges {field}")


def test_kernels_name_bad_input():
    X, F, vf = box(4, 2)
    index = CopyIndex(X, F)
    with pytest.raises(ValueError, match="vertex_fragment"):
        partner_incidences(index, vf[:-1])
    with pytest.raises(ValueError, match="group is not sorted"):
        _ext.CopyPairs(index.on, index.group[::-1].copy())
    with pytest.raises(ValueError, match="incident is not sorted"):
        _ext.PartnerIncidences(index.on, index.group, index.incident[::-1].copy(), index.incidence, index.face_key,
                               vf)
    edges, ptr, at_edge = edge_arrays(X, F, vf, index)
    at = two_faces(ptr, at_edge)
    with pytest.raises(ValueError, match="faces_at_edge"):
        diagonal_edges(edges, np.where(at == at.max(), len(F), at), vf, index)
    inner = np.setdiff1d(np.arange(len(X)), F.ravel())[:1]          # a vertex on no face: no point
    with pytest.raises(ValueError, match="edges has a vertex of no point"):
        diagonal_edges(np.array([[inner[0], F[0, 0]]]), at[:1], vf, index)
    with pytest.raises(ValueError, match="edge_face_ptr"):
        two_faces(np.array([0, 3, 2]), at_edge)


@pytest.mark.slow
def test_cracked_sphere_state(tmp_path):
    """The default sphere after 3 steps (cracks through the glass, copies of three and more
    at the core's vertices): the same arrays."""
    from ngfracture.cli import main
    from ngfracture.run.state import load_state
    assert main(["run", "sphere3d", "--steps", "3", "--pictures", "none", "--out", str(tmp_path)]) == 0
    state, _ = load_state(tmp_path)
    a = state.arrays
    X, F = a.points, np.asarray(a.faces, dtype=np.int64)
    vf = vertex_fragments_of(len(X), a.tets)
    index = CopyIndex(X, F)
    assert index.copies.max() >= 3
    partners, diagonal, _ = compare_all(X, F, vf, "sphere")
    assert partners > 0
