"""Work of the 3D contact rounds done once and reused gives the results of doing it again.

- The detection's sweep skips the cells whose vertices are all decided for the
  fragments there (closed lips, ``cpp_ext/collision3d_sweep.cpp`` ClosedCells): a third block
  pushed through closed lips must still find every pair there (brute force over all pairs).
- ``NodeToFaceRows.subset`` and ``stack`` carry the rows of a built ``C``: equal, array by
  array, to the ``C`` built from the selected rows.
- ``ActiveSet3d._fresh_rows`` takes the rows ``update`` re-linearised at the same U: equal,
  field by field and in ``C``, to re-linearising every candidate.
"""
import numpy as np

from ngfracture.contact.active_set3d import ActiveSet3d
from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.copies3d import two_sided_rows
from ngfracture.contact.edge_rows3d import relinearise_edge_rows
from ngfracture.contact.mixed_rows import MixedRows
from ngfracture.contact.rows3d import NodeToFaceRows, relinearise_node_to_face

from blocks3d import assert_same_rows, block_geometry, overlapping_blocks
from detection3d_util import MasterReference, brute_force_pairs

CELLS, PIECES = 4, 2


def test_a_block_pushed_through_closed_lips_finds_every_pair():
    """Seven blocks still (their lips closed: every cell on them is closed for its blocks),
    block 7 pushed 0.3 of a block into the others: its tetrahedra sweep those cells, and the
    pairs, tetrahedra, closed seams and master faces must be the brute force's."""
    arrays, piece, vf, _ = overlapping_blocks(CELLS, PIECES, 0.0)
    X, T, F = arrays.points, arrays.tets, arrays.faces
    U = np.zeros_like(X)
    U[vf == 7] = -0.3 / PIECES
    pen = detect_penetrations_3d(X, T, F, piece, displacement=U)
    vertex, fragment, tet, closed = brute_force_pairs(X, T, F, piece, U)
    assert pen.stats["closed_seams"] == closed > 50
    assert np.array_equal(pen.vertex, vertex) and np.array_equal(pen.fragment, fragment)
    assert np.array_equal(pen.tet, tet)
    # vertices on the closed lips among the still blocks (a copy on another still block at
    # the same current point), found in block 7
    still_fragments = {}
    for v in np.flatnonzero(vf != 7):
        still_fragments.setdefault(X[v].tobytes(), set()).add(vf[v])
    in_seven = pen.vertex[pen.fragment == 7]
    on_closed = [v for v in in_seven if len(still_fragments[X[v].tobytes()]) >= 2]
    assert len(on_closed) >= 10
    MasterReference(X, U, T, F, piece).check(pen, 1e-12 / CELLS)


def test_subset_and_stack_carry_the_gap_rows():
    arrays, piece, _, U = overlapping_blocks(CELLS, PIECES, 0.2 / CELLS * PIECES, noise=0.05 / CELLS)
    rows = ActiveSet3d(block_geometry(arrays, piece), 1e-12).update(U, {"collision": 0.0}).rows.parts[0]
    assert len(rows) > 100
    plain = NodeToFaceRows(*(getattr(rows, f) for f in NodeToFaceRows.FIELDS), nv=rows.nv)
    built = NodeToFaceRows(*(getattr(rows, f) for f in NodeToFaceRows.FIELDS), nv=rows.nv)
    built.C                                              # built: carried by subset and stack
    pick = np.r_[np.arange(0, len(rows), 3), 5, 5, 1]    # with a repeat, out of order
    mask = np.arange(len(rows)) % 4 == 1
    for carried, fresh in ((built.subset(pick), plain.subset(pick)), (built.subset(mask), plain.subset(mask)),
                           (built.subset(np.zeros(0, dtype=np.int64)), plain.subset(np.zeros(0, dtype=np.int64))),
                           (NodeToFaceRows.stack([built.subset(pick), built.subset(mask)]),
                            NodeToFaceRows.stack([plain.subset(pick), plain.subset(mask)])),
                           (NodeToFaceRows.stack([built.subset(mask)]), NodeToFaceRows.stack([plain.subset(mask)]))):
        assert "C" in carried.__dict__ and "C" not in fresh.__dict__
        assert_same_rows(carried, fresh)


def test_settling_takes_the_update_s_relinearisation():
    """Round 2 at a displacement that moves every row (re-linearised by the update) and
    finds new ones: the rows settle judges are those of re-linearising every candidate
    (rows at a copy on the tighter side of their pair, copies3d.two_sided_rows)."""
    arrays, piece, _, U = overlapping_blocks(CELLS, PIECES, 0.2 / CELLS * PIECES, noise=0.05 / CELLS)
    active = ActiveSet3d(block_geometry(arrays, piece), 1e-12)
    cand = active.update(U, {"collision": 0.0})
    want, kept, _ = active.primal_dual(cand)
    active.record(cand.keys, kept, -np.ones(len(kept)), 1.0)
    U2 = 1.3 * U + np.random.default_rng(1).normal(scale=0.02 / CELLS, size=U.shape)
    cand = active.update(U2, {"collision": 0.0})
    assert cand.relinearised is not None and 0 < len(cand.relinearised) < len(cand.rows)
    reused = active._fresh_rows(cand, U2)
    faces, edges = cand.rows.parts
    fresh = relinearise_node_to_face(faces, arrays.points, U2)
    assert_same_rows(reused, MixedRows([two_sided_rows(fresh, arrays.points, U2, active.setup.copy_index),
                                        relinearise_edge_rows(edges, arrays.points, U2)], cand.rows.kind))
