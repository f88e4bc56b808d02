"""geometry.pieces: a mesh cut into pieces (the fragmented body of benchmarks/contact3d.py),
and contact.rows3d.fragment_twin_rows, the twin rows of all fragments in one pass."""
import math

import numpy as np
import pytest

from ngfracture.contact.rows3d import NodeToFaceRows, fragment_twin_rows, twin_rows
from ngfracture.fracture.fragments import fragment_ids
from ngfracture.geometry.pieces import fragmented_box, separate_pieces
from ngfracture.geometry.solid import crack_area, solid_mesh, solid_to_arrays, tet_volumes, total_volume
from ngfracture.geometry.structured import box_mesh
from ngfracture.scenes import two_blocks_mesh


def _areas(points, faces):
    x = points[faces]
    return np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])


@pytest.mark.parametrize("cells, pieces", [(6, 2), (7, 3), (5, (1, 2, 3))])
def test_fragmented_box_is_its_blocks(cells, pieces):
    """Volume, orientation and points exact; one fragment per block; every cut plane two
    lips of its full area, coincident, opposite, on the plane; outer faces unchanged."""
    a, piece = fragmented_box(cells, pieces)
    counts = pieces if isinstance(pieces, tuple) else (pieces,) * 3
    box = box_mesh(*(np.linspace(0, 1, cells + 1),) * 3)
    assert len(a.tets) == 6 * cells ** 3 and np.all(tet_volumes(a.points, a.tets) > 0)
    assert total_volume(a.points, a.tets) == total_volume(box.points, box.tets)
    assert np.array_equal(a.regions, box.regions)
    frag = fragment_ids(a)
    n = len(np.unique(frag))
    assert n == np.prod(counts) == len(np.unique(piece))
    # fragments are the blocks: a fragment holds one block's tets
    assert len(set(zip(frag.tolist(), piece.tolist()))) == n
    # every vertex on a cut has one bitwise-equal copy per block around it, nothing else moved
    _, count = np.unique(a.points, axis=0, return_counts=True)
    assert count.max() == 2 ** sum(c > 1 for c in counts)
    lips = a.boundary_faces("crack")
    planes = sum(c - 1 for c in counts)
    assert math.isclose(crack_area(a), planes, rel_tol=1e-13)
    area = _areas(a.points, lips)
    axis = np.argmax(np.abs(area), axis=1)
    assert np.all(np.abs(area[np.arange(len(area)), axis]) == np.linalg.norm(area, axis=1))
    coord = a.points[lips][np.arange(len(lips)), :, axis]      # every lip on a grid plane
    assert np.all(coord == coord[:, :1])
    # lips pair up: same points, opposite normals, faces of tets of different blocks
    key = np.array([sorted(map(tuple, a.points[f])) for f in lips]).reshape(len(lips), -1)
    _, inv, c = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    assert np.all(c == 2)
    order = np.argsort(inv.ravel(), kind="stable")
    assert np.all(area[order[0::2]] == -area[order[1::2]])
    # outward: the tet's fourth vertex lies behind every boundary face
    for faces in (lips, a.faces):
        x = a.points
        centre = x[a.tets].mean(axis=1)
        from ngfracture.geometry.pieces import OUTWARD_FACES
        all_faces = np.sort(a.tets[:, OUTWARD_FACES].reshape(-1, 3), axis=1)
        lookup = {tuple(f): i // 4 for i, f in enumerate(all_faces.tolist())}
        tet = np.array([lookup[tuple(sorted(f))] for f in faces.tolist()])
        n_out = _areas(x, faces)
        assert np.all(np.einsum("ij,ij->i", n_out, centre[tet] - x[faces[:, 0]]) < 0)
    # the outer faces are the box's, in its order, with their names
    outer = a.face_bc != a.bc_names.index("crack") + 1
    assert np.array_equal(a.points[a.faces[outer]], box.points[box.faces])
    assert np.array_equal(a.face_bc[outer], box.face_bc) and a.bc_names[:6] == box.bc_names


def test_separate_pieces_round_trip_and_parents():
    """A round trip through NGSolve keeps the cut mesh; parent maps copies to
    the input vertex; one piece changes nothing but the names list."""
    box = box_mesh([0, 0.5, 1], [0, 1], [0, 0.3, 1])
    piece = (box.points[box.tets].mean(axis=1)[:, 0] > 0.5).astype(int)
    a, parent = separate_pieces(box, piece)
    assert np.array_equal(a.points, box.points[parent])
    assert np.array_equal(parent[a.tets], box.tets)
    back = solid_to_arrays(solid_mesh(a))
    assert np.array_equal(back.tets, a.tets) and np.array_equal(back.faces, a.faces)
    same, parent1 = separate_pieces(box, np.zeros(len(box.tets), dtype=int))
    assert np.array_equal(same.tets, box.tets) and np.array_equal(same.faces, box.faces)
    assert np.array_equal(parent1, np.arange(len(box.points)))


def test_separate_pieces_refuses_bad_input():
    box = box_mesh([0, 1], [0, 1], [0, 1])
    with pytest.raises(ValueError, match="piece"):
        separate_pieces(box, np.zeros(3, dtype=int))
    with pytest.raises(ValueError, match="piece"):
        separate_pieces(box, np.zeros(len(box.tets)))
    broken = box_mesh([0, 1], [0, 1], [0, 1])
    broken.faces, broken.face_bc = broken.faces[1:], broken.face_bc[1:]
    with pytest.raises(ValueError, match="boundary faces"):
        separate_pieces(broken, np.zeros(len(broken.tets), dtype=int))
    for bad in (dict(cells=4, pieces=5), dict(cells=4, pieces=1), dict(cells=4.0, pieces=2),
                dict(cells=4, pieces=(1, 1, 1)), dict(cells=4, pieces=2, size=-1.0)):
        with pytest.raises(ValueError, match="fragmented_box"):
            fragmented_box(**bad)


@pytest.mark.parametrize("mesh", ["box", "blocks"])
def test_fragment_twin_rows_equal_the_rows_per_fragment(mesh):
    """One pass over all fragments gives the rows of a twin_rows call per fragment, stacked
    in fragment order, bit for bit."""
    if mesh == "box":
        a, _ = fragmented_box(5, (2, 2, 3))
    else:
        a = two_blocks_mesh()
    frag = fragment_ids(a)
    vf = np.full(len(a.points), -1)
    vf[a.tets.ravel()] = np.repeat(frag, 4)
    fast = fragment_twin_rows(a.points, a.faces, vf)
    slow = NodeToFaceRows.stack([twin_rows(a.points, a.faces, vf == f) for f in np.unique(frag)])
    assert len(fast) == len(slow) > 0
    for name in NodeToFaceRows.FIELDS:
        assert np.array_equal(getattr(fast, name), getattr(slow, name)), name
    assert (fast.C != slow.C).nnz == 0
    with pytest.raises(ValueError, match="vertex_fragment"):
        fragment_twin_rows(a.points, a.faces, vf[:-1])
