"""The C++ kernels of the mesh-only set-up of 3D contact (cpp_ext/contact_setup3d.cpp) against
the numpy computations they replace, kept here as the reference: the same arrays, in the
same order, with the same dtypes, byte for byte (signed zeros included).

Kernels: ``SortedTripleRanks`` (setup3d.FaceKeys), ``CopyIndexArrays`` (kinks3d.CopyIndex),
``FragmentPairEntries`` (junctions3d.fragment_pair_rows). Bodies: fragmented boxes (junctions
of 4 and 8 copies; a crack inside one block, where three copies meet), also with the points
moved (copies moved alike, so they stay bitwise equal) so that the lips bend and the mean
normals, scores and kinks are not those of planes.
"""
import numpy as np
import pytest

from ngfracture.contact.intsets import unique_ints
from ngfracture.contact.junctions3d import fragment_pair_rows
from ngfracture.contact.kinks3d import KINK, CopyIndex, expand_ranges, face_point_keys, point_groups
from ngfracture.contact.rows3d import NodeToFaceRows, face_gap_rows, fragment_twin_rows, no_face_rows
from ngfracture import _ngfracture as ext
from ngfracture.contact.setup3d import FaceKeys, MeshSetup3d
from ngfracture.geometry.pieces import fragmented_box


def box(cells, pieces, crack=False, bend=0.0):
    """Points, faces (int64) and vertex fragments of a fragmented box; ``crack``: blocks 0 and
    1 one fragment (their cut a crack inside it); ``bend``: every point moved by up to that
    share of a cell, a smooth function of the point (copies stay bitwise equal)."""
    a, piece = fragmented_box(cells, pieces)
    fragment = np.where(piece == 1, 0, piece) if crack else piece
    vf = np.full(len(a.points), -1, dtype=np.int64)
    vf[a.tets.ravel()] = np.repeat(fragment, 4)
    X = a.points.copy()
    if bend:
        h = 1.0 / cells
        X = X + bend * h * np.sin(np.pi * (3.0 * X[:, [1, 2, 0]] + 2.0 * X[:, [2, 0, 1]]))
    return X, a.faces.astype(np.int64), vf


BODIES = [dict(cells=4, pieces=(2, 2, 1), crack=True), dict(cells=6, pieces=3),
          dict(cells=6, pieces=3, bend=0.3), dict(cells=4, pieces=(2, 2, 1), crack=True, bend=0.3)]


def assert_same(x, y, name=""):
    x, y = np.asarray(x), np.asarray(y)
    assert x.dtype == y.dtype and x.shape == y.shape, name
    assert np.ascontiguousarray(x).tobytes() == np.ascontiguousarray(y).tobytes(), name


# -- the numpy references ---------------------------------------------------------------

def reference_face_keys(faces):
    """setup3d.FaceKeys's triples and face_set, in numpy."""
    S = np.sort(np.asarray(faces).astype(np.int64), axis=1)
    order = np.lexsort((S[:, 2], S[:, 1], S[:, 0]))
    S = S[order]
    first = np.r_[True, np.any(S[1:] != S[:-1], axis=1)] if len(S) else np.zeros(0, dtype=bool)
    face_set = np.empty(len(S), dtype=np.int64)
    face_set[order] = np.cumsum(first) - 1
    return S[first], face_set


def reference_copy_index(points, faces):
    """kinks3d.CopyIndex's arrays, in numpy."""
    points = np.array(points, dtype=np.float64)
    faces = np.array(faces, dtype=np.int64).reshape(-1, 3)
    on, group = point_groups(points, faces)
    point = np.full(len(points), -1, dtype=np.int64)
    point[on] = group
    face_key = face_point_keys(faces, point)
    key_order = np.argsort(face_key, kind="stable")
    flat = faces.ravel()
    incidence = np.argsort(flat, kind="stable")
    p = points[faces]
    area2 = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    unit = area2 / np.linalg.norm(area2, axis=1)[:, None]
    nk = len(faces) + 1
    return dict(on=on, group=group, point=point, copies=np.bincount(group, minlength=1), face_key=face_key,
                key_order=key_order, key_sorted=face_key[key_order], incidence=incidence,
                incident=flat[incidence], area2=area2, unit=unit,
                vertex_keys=unique_ints((flat * nk + np.repeat(face_key, 3))[incidence]))


def reference_fragment_pair_rows(X, F, vf, index):
    """junctions3d.fragment_pair_rows in numpy (the arrays already checked)."""
    nv = len(X)
    pid = index.point
    ff = vf[F[:, 0]] if len(F) else np.zeros(0, dtype=np.int64)
    order, group = index.key_order, index.key_sorted
    first = np.searchsorted(group, group)
    who, other = expand_ranges(first, np.searchsorted(group, group, side="right") - first)
    a, b = order[who], order[other]
    keep = ff[a] != ff[b]
    a, b = a[keep], b[keep]
    matched = np.zeros(nv, dtype=bool)
    matched[F[a].ravel()] = True
    several = np.zeros(nv, dtype=bool)
    on = np.flatnonzero(pid >= 0)
    for p in np.unique(pid[on]):
        at = on[pid[on] == p]
        several[at] = len(np.unique(vf[at])) > 1
    fallback = no_face_rows(nv)
    if np.any(several & ~matched):
        fallback = fragment_twin_rows(X, F, vf, index=index)
        fallback = fallback.subset(np.flatnonzero(~matched[fallback.slave]))
    one_way = ff[a] > ff[b]
    a, b = a[one_way], b[one_way]
    if not len(a):
        return fallback, 0
    same = pid[F[b]][:, :, None] == pid[F[a]][:, None, :]
    slave = F[a][np.arange(len(a))[:, None], same.argmax(axis=2)].ravel()
    face = np.repeat(b, 3)
    k = np.tile(np.arange(3), len(b))
    area2, unit = index.area2, index.unit
    copy = F[face, k]
    group = np.argsort(slave * nv + copy, kind="stable")
    slave, face, k, copy = slave[group], face[group], k[group], copy[group]
    start = np.r_[True, (slave[1:] != slave[:-1]) | (copy[1:] != copy[:-1])]
    owner = np.cumsum(start) - 1
    mean = np.stack([np.bincount(owner, weights=area2[face, d], minlength=owner[-1] + 1) for d in range(3)], axis=1)
    score = np.einsum("ij,ij->i", unit[face], mean[owner])
    best = np.lexsort((face, -score, owner))
    best = best[np.r_[True, owner[best][1:] != owner[best][:-1]]]
    chosen = np.empty(owner[-1] + 1, dtype=np.int64)
    chosen[owner[best]] = face[best]
    bend = 1.0 - np.einsum("ij,ij->i", unit[face], unit[chosen[owner]]) > KINK
    keep = np.zeros(len(face), dtype=bool)
    keep[best] = True
    keep |= bend & (index.copies[pid[slave]] >= 3)
    slave, face, k = slave[keep], face[keep], k[keep]
    order = np.lexsort((face, ff[face], slave, vf[slave]))
    slave, face, k = slave[order], face[order], k[order]
    bary = np.zeros((len(slave), 3))
    bary[np.arange(len(slave)), k] = 1.0
    master, normal = F[face], unit[face]
    _, g = face_gap_rows(X, slave, master, bary, normal)
    rows = NodeToFaceRows(slave=slave, master=master, face=face, bary=bary, normal=normal, dist=g.copy(), g=g, nv=nv)
    return NodeToFaceRows.stack([rows, fallback]) if len(fallback) else rows, bend.sum()


# -- the comparisons ---------------------------------------------------------------------

@pytest.mark.parametrize("body", BODIES)
def test_face_keys_kernel_is_the_numpy_numbering(body):
    _, faces, _ = box(**body)
    triples, face_set = reference_face_keys(faces)
    codec = FaceKeys(faces)
    assert_same(codec.triples, triples, "triples")
    assert_same(codec.face_set, face_set, "face_set")
    # the faces in another order and with repeated vertex sets (the faces twice)
    rng = np.random.default_rng(3)
    shuffled = np.concatenate([faces, faces[:, ::-1]])[rng.permutation(2 * len(faces))]
    codec, (triples, face_set) = FaceKeys(shuffled), reference_face_keys(shuffled)
    assert len(triples) < len(shuffled)
    assert_same(codec.triples, triples, "triples, shuffled")
    assert_same(codec.face_set, face_set, "face_set, shuffled")
    empty = FaceKeys(np.zeros((0, 3), dtype=np.int32))
    assert_same(empty.triples, reference_face_keys(np.zeros((0, 3), dtype=np.int32))[0])


@pytest.mark.parametrize("body", BODIES)
def test_copy_index_kernel_is_the_numpy_index(body):
    points, faces, _ = box(**body)
    reference = reference_copy_index(points, faces)
    index = CopyIndex(points, faces)
    assert reference["copies"].max() >= (3 if body.get("crack") else 8)
    for name, value in reference.items():
        assert_same(getattr(index, name), value, name)
    # signed zeros in the coordinates (-0.0 and 0.0 are one point) and faces in another order
    moved = points - 0.5
    moved[moved == 0.0] = -0.0
    moved[::2][moved[::2] == 0.0] = 0.0
    rng = np.random.default_rng(5)
    shuffled = faces[rng.permutation(len(faces))]
    reference, index = reference_copy_index(moved, shuffled), CopyIndex(moved, shuffled)
    for name, value in reference.items():
        assert_same(getattr(index, name), value, name)


def test_copy_index_names_bad_input():
    points, faces, _ = box(4, 2)
    bad = points.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        CopyIndex(bad, faces)
    with pytest.raises(ValueError, match="faces"):
        CopyIndex(points, np.where(faces == faces.max(), len(points), faces))


@pytest.mark.parametrize("body", BODIES)
def test_fragment_pair_kernel_is_the_numpy_rows(body):
    X, F, vf = box(**body)
    index = CopyIndex(X, F)
    reference, bends = reference_fragment_pair_rows(X, F, vf, index)
    rows = fragment_pair_rows(X, F, vf, index=index)
    assert len(rows) > 0 and len(rows) == len(reference)
    if body.get("bend"):
        assert bends > 0                          # the bent lips have faces off the chosen plane
    for field in rows.FIELDS:
        assert_same(getattr(rows, field), getattr(reference, field), field)


def test_edge_pair_kernels_name_a_face_out_of_range():
    """faces_at_edge holds face numbers or -1 (an edge with one face): -1 and nf - 1 pass,
    -2, nf and the extremes of int64 are named with the range [-1, nf)."""
    a, piece = fragmented_box(4, 2)
    setup = MeshSetup3d(a.points, a.tets, a.faces, np.asarray(piece, dtype=np.int64))
    E, at, index = setup.edge_detector.edges, setup.faces_at_edge, setup.copy_index
    nf = len(index.face_key)
    calls = {"DiagonalEdgePairs": lambda at: ext.DiagonalEdgePairs(E, at, setup.vertex_fragment, index.point,
                                                                   index.face_key),
             "EdgeCopyPairs": lambda at: ext.EdgeCopyPairs(E, at, index.point, index.face_key)}
    for name, call in calls.items():
        for good in (-1, nf - 1):
            edited = at.copy()
            edited[0, 1] = good
            call(edited)
        for bad in (-2, nf, np.iinfo(np.int64).max, np.iinfo(np.int64).min):
            edited = at.copy()
            edited[0, 1] = bad
            with pytest.raises(ValueError, match=rf"ngfracture\.{name}: faces_at_edge has an entry outside \[-1, {nf}\)"):
                call(edited)
