"""The boundary's copy arrays made once per mesh (ngfracture.contact.kinks3d.CopyIndex) and the
integer set helpers: every result equal, bit for bit, to the plain computation.

The body is a fragmented box (blocks of a cube, every cut-plane vertex copied once per
block) with a crack inside one block (three copies meet where it reaches a cut plane), so
the lip rows, the rows at three copies and the rows between fragments are all there.
"""
import numpy as np
import pytest

from ngfracture.contact.junctions3d import fragment_pair_rows
from ngfracture.contact.kinks3d import (CopyIndex, face_point_keys, isin_ints, partner_faces, point_ids,
                                        unique_ints)
from ngfracture.contact.rows3d import fragment_twin_rows, lip_rows
from ngfracture.geometry.pieces import fragmented_box


def body():
    """A box of 2 x 2 x 1 blocks, 4 cells per edge, blocks 0 and 1 one fragment (the cut
    between them a crack inside it): points, faces and the fragment of every vertex."""
    a, piece = fragmented_box(4, (2, 2, 1))
    fragment = np.where(piece == 1, 0, piece)
    vf = np.full(len(a.points), -1, dtype=np.int64)
    vf[a.tets.ravel()] = np.repeat(fragment, 4)
    return a.points, a.faces.astype(np.int64), vf


def assert_rows_equal(a, b):
    assert len(a) == len(b) and a.nv == b.nv
    for field in a.FIELDS:
        x, y = np.asarray(getattr(a, field)), np.asarray(getattr(b, field))
        assert x.dtype == y.dtype and x.shape == y.shape, field
        assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), field      # bit for bit (signed zeros too)


def test_unique_and_isin_of_integers_are_numpys():
    rng = np.random.default_rng(7)
    for n, high in [(0, 5), (1, 5), (50, 10), (2000, 10 ** 12), (3000, 40)]:
        a = rng.integers(-high, high, size=n)
        b = rng.integers(-high, high, size=n // 2 + 1)
        assert np.array_equal(unique_ints(a), np.unique(a)) and unique_ints(a).dtype == np.unique(a).dtype
        assert np.array_equal(isin_ints(a, b), np.isin(a, b))
        assert np.array_equal(isin_ints(a, np.zeros(0, dtype=np.int64)), np.zeros(n, dtype=bool))


def test_face_point_keys_by_codes_are_the_row_numbering():
    points, faces, _ = body()
    pid = point_ids(points, faces)
    _, reference = np.unique(np.sort(pid[faces], axis=1), axis=0, return_inverse=True)
    assert np.array_equal(face_point_keys(faces, pid), reference.ravel())


def test_index_holds_the_plain_arrays():
    points, faces, _ = body()
    index = CopyIndex(points, faces)
    assert np.array_equal(index.point, point_ids(points, faces))
    assert np.array_equal(index.face_key, face_point_keys(faces, index.point))
    assert np.array_equal(index.copies, np.bincount(index.point[index.point >= 0]))
    assert np.array_equal(index.incident, np.sort(faces.ravel()))
    p = points[faces]
    assert np.array_equal(index.area2, np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))
    # every face's run of its key in the sorted keys: what searchsorted finds
    start = np.searchsorted(index.key_sorted, index.face_key)
    assert np.array_equal(index.key_start, start)
    assert np.array_equal(index.key_count, np.searchsorted(index.key_sorted, index.face_key, side="right") - start)
    assert index.key_count.min() == 1 and index.key_count.max() == 2        # outer faces once, lips twice
    # its arrays are copies: changing the caller's arrays afterwards does not reach it
    before = index.faces.copy()
    faces[0] = faces[1]
    assert np.array_equal(index.faces, before)


@pytest.mark.parametrize("all_pairs", [False, True])
def test_partner_faces_with_the_index_are_those_without(all_pairs):
    points, faces, _ = body()
    index = CopyIndex(points, faces)
    pid = index.point
    on = np.flatnonzero(pid >= 0)
    s, t = np.meshgrid(on, on, indexing="ij")
    same = pid[s] == pid[t]
    s, t = s[same], t[same]
    assert len(s) > len(on)                       # there are copies
    plain = partner_faces(points, faces, s, t, all_pairs=all_pairs)
    indexed = partner_faces(points, faces, s, t, all_pairs=all_pairs, index=index)
    assert len(plain[0]) > 0
    for x, y in zip(plain, indexed):
        assert np.array_equal(x, y)


def test_rows_with_the_index_are_those_without():
    points, faces, vf = body()
    index = CopyIndex(points, faces)
    for rows in (fragment_pair_rows, fragment_twin_rows, lip_rows):
        plain = rows(points, faces, vf)
        assert_rows_equal(plain, rows(points, faces, vf, index=index))
    assert len(fragment_pair_rows(points, faces, vf)) > 0 and len(lip_rows(points, faces, vf)) > 0


def test_the_index_unit_normals_are_those_computed_for_any_set_of_faces():
    """The rows at copies take a face's unit normal from the index (computed over all
    faces): equal, bit for bit, to the normal computed for any subset of faces."""
    a, _ = fragmented_box(4, 2)
    X = a.points - 1e-3 * a.points ** 2        # coordinates that round
    index = CopyIndex(X, a.faces)
    rng = np.random.default_rng(0)
    for k in (1, 2, 7, 100, len(a.faces)):
        face = rng.choice(len(a.faces), size=k)
        p = X[a.faces[face]]
        area2 = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        plain = area2 / np.linalg.norm(area2, axis=1)[:, None]
        assert np.array_equal(plain.view(np.int64), index.unit[face].view(np.int64)), k
