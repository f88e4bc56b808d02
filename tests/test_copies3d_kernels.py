"""The C++ kernels of the rows between copies of a point against their numpy reference, bit for bit.

``copies3d.behind_partner_rows`` (``BehindPartnerGaps``), ``wedges3d.wedge_rows``
(``WedgeInside``), ``copies3d.found_rows_at_copies`` (``FoundRowsAtCopies``),
``copies3d.folded_rows_at_copies`` (``FoldedIncidences``), ``wedges3d.reflex_wedge_rows``
(``ReflexWedgeGaps``) with its pairs ``wedges3d.edge_copies`` (``EdgeCopyPairs``) and the
partner face of a (face, vertex) that found rows at copies and their re-linearisation
look up (``PartnerAt``) compute in C++ what the numpy code below
computes, every round of every 3D contact solve; the rows they make must be the same to the last bit (gaps and their
zeros, the order of the rows), on configurations where many rows fire: a body cut into
2 x 2 x 2 blocks (junction lines of four blocks, a point of eight) whose vertices are
moved at random by up to a fifth of the element size, some pairs of copies left
together (gap exactly 0), some faces squeezed flat (no plane); for the reflex-wedge rows,
whose wedges of 90 degrees there never fire, three blocks around a line with a wedge of
240 degrees (``sector_blocks``) moved the same way.
"""
import numpy as np
import pytest

from ngfracture import _ngfracture as ext
from ngfracture.contact.copies3d import behind_partner_rows, folded_rows_at_copies, found_rows_at_copies, rows_at_copy
from ngfracture.contact.intsets import isin_ints, unique_ints
from ngfracture.contact.kinks3d import KINK, expand_ranges, partner_faces
from ngfracture.contact.rows3d import NodeToFaceRows, no_face_rows, node_to_face_rows
from ngfracture.contact.setup3d import MeshSetup3d
from ngfracture.contact.wedges3d import edge_copies, reflex_wedge_rows, wedge_rows
from ngfracture.geometry.pieces import fragmented_box
from sector_blocks import sector_blocks

CELLS, PIECES = 4, 2


def reference_partner_at(index, face, vertex):
    """The numpy loop of copies3d._partner_at: the first face in key order on the face's points with the vertex."""
    F, order = index.faces, index.key_order
    start, count = index.key_start[face], index.key_count[face]
    out = np.full(len(face), -1, dtype=np.int64)
    for shift in range(int(count.max(initial=0))):
        slot = np.minimum(start + shift, len(order) - 1)
        cand = order[slot]
        hit = (shift < count) & (out < 0) & np.any(F[cand] == vertex[:, None], axis=1)
        out[hit] = cand[hit]
    return out


def reference_found_rows_at_copies(rows, vertex_fragment, index):
    """The numpy computation of copies3d.found_rows_at_copies."""
    F = index.faces
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    pid = index.point
    same = pid[rows.master] == pid[rows.slave][:, None]
    at_copy = same.any(axis=1) & (pid[rows.slave] >= 0)
    slave, face, normal = rows.slave.copy(), rows.face.copy(), rows.normal.copy()
    copy = rows.master[np.arange(len(rows)), same.argmax(axis=1)]
    reverse = at_copy & ((vf[slave] < vf[copy]) | ((vf[slave] == vf[copy]) & (slave < copy)))
    r = np.flatnonzero(reverse)
    partner = reference_partner_at(index, face[r], slave[r])
    r, partner = r[partner >= 0], partner[partner >= 0]
    slave[r], copy[r], face[r] = copy[r], slave[r], partner
    master = F[face]
    normal[at_copy] = index.unit[face[at_copy]]
    bary = rows.bary.copy()
    bary[at_copy] = (master[at_copy] == copy[at_copy, None]).astype(np.float64)
    g = rows.g.copy()
    g[at_copy] = 0.0
    return NodeToFaceRows(slave=slave, master=master, face=face, bary=bary, normal=normal, dist=rows.dist.copy(),
                          g=g, nv=rows.nv), at_copy


def reference_folded_rows_at_copies(rows, pick, vertex_fragment, tied, index):
    """The numpy computation of copies3d.folded_rows_at_copies."""
    X, F = index.points, index.faces
    nv = rows.nv
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    pid = index.point
    s = rows.slave
    t = rows.master[np.arange(len(rows)), np.argmax(rows.bary, axis=1)]
    two = index.copies[np.maximum(pid[s], 0)] == 2
    ok = np.asarray(pick, dtype=bool) & two & (pid[s] >= 0) & (vf[s] != vf[t])
    if tied is not None and len(tied):
        ok &= ~isin_ints(np.minimum(s, t) * nv + np.maximum(s, t), tied)
    r = np.flatnonzero(ok)
    s, t = s[r], t[r]
    code = s * nv + t
    pair = unique_ints(code)
    slave, face, corner = partner_faces(X, F, pair // nv, pair % nv, all_pairs=True, one_way=False, index=index)
    master = F[face]
    normal = index.unit[face]
    order = np.argsort(code, kind="stable")
    incidence_code = slave * nv + master[np.arange(len(face)), corner]
    start = np.searchsorted(code[order], incidence_code)
    incidence, slot = expand_ranges(start, np.searchsorted(code[order], incidence_code, side="right") - start)
    picked = r[order[slot]]
    parallel = 1.0 - np.sum(normal[incidence] * rows.normal[picked], axis=1) <= KINK
    keep = np.ones(len(face), dtype=bool)
    keep[incidence[parallel]] = False
    return rows_at_copy(slave[keep], face[keep], corner[keep], np.zeros(int(keep.sum())), index)


def reference_plane_gaps(x, faces, face, slave, copy):
    """n_f . (x_s - x_t) with the faces' unit normals at x; 0 on a face squeezed flat."""
    tri = x[faces[face]]
    area = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(area, axis=1)
    return np.where(length > 0, np.einsum("ij,ij->i", area, x[slave] - x[copy]) / np.where(length > 0, length, 1.0),
                    0.0)


def reference_behind_partner_rows(partners, displacement, tol, index):
    """The numpy computation of copies3d.behind_partner_rows."""
    slave, face, corner = partners
    X, F = index.points, index.faces
    nv = len(X)
    x = X + np.asarray(displacement, dtype=np.float64)
    copy = F[face, corner]
    gap = np.zeros(len(slave))
    apart = np.flatnonzero(np.any(x[slave] != x[copy], axis=1))
    gap[apart] = reference_plane_gaps(x, F, face[apart], slave[apart], copy[apart])
    pair = slave * nv + copy
    hit = np.flatnonzero(isin_ints(pair, unique_ints(pair[gap < -tol])))
    if not len(hit):
        return no_face_rows(nv)
    return rows_at_copy(slave[hit], face[hit], corner[hit], gap[hit], index)


def reference_wedge_normals(x, F, fw, edge):
    """Unit normals of a wedge's two faces per pair, whether neither is squeezed flat, and
    the side of the second face's corner off the edge to the first's plane (convex or
    flat where <= 0, reflex where > 0)."""
    normals, ok = [], np.ones(len(fw), dtype=bool)
    for k in range(2):
        tri = x[F[fw[:, k]]]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1)
        ok &= length > 0
        normals.append(n / np.where(length > 0, length, 1.0)[:, None])
    third = F[fw[:, 1]].sum(axis=1) - edge.sum(axis=1)
    return normals, ok, np.einsum("ij,ij->i", normals[0], x[third] - x[edge[:, 0]])


def reference_corners_in_front(x, F, fw, edge, n):
    """Both faces' corners off the edge in front of the plane through the edge's first end
    with normal n, or behind it by at most 1e-2 of their distance."""
    front = np.ones(len(fw), dtype=bool)
    for k in range(2):
        d = x[F[fw[:, k]].sum(axis=1) - edge.sum(axis=1)] - x[edge[:, 0]]
        side = np.einsum("ij,ij->i", n, d)
        front &= ~((side < 0) & (side < -1e-2 * np.linalg.norm(d, axis=1)))
    return front


def reference_lowest_of_max(G, use):
    """Per pair the lowest over s in [0, 1] of the largest G[c](s) of the used candidates."""
    def at(s):
        line = G[:, :, 0] + s[:, None] * (G[:, :, 1] - G[:, :, 0])
        return np.where(use, line, -np.inf).max(axis=1)
    m = len(G)
    lowest = np.minimum(at(np.zeros(m)), at(np.ones(m)))
    for c in range(4):
        for k in range(c + 1, 4):
            h0, h1 = G[:, c, 0] - G[:, k, 0], G[:, c, 1] - G[:, k, 1]
            cross = use[:, c] & use[:, k] & (((h0 < 0) & (h1 > 0)) | ((h0 > 0) & (h1 < 0)))
            s = h0 / np.where(cross, h0 - h1, 1.0)
            lowest = np.where(cross, np.minimum(lowest, at(s)), lowest)
    return lowest


def reference_wedge_rows(pairs, displacement, tol, index, vertex_fragment):
    """The numpy computation of wedges3d.wedge_rows."""
    X, F = index.points, index.faces
    nv = len(X)
    x = X + np.asarray(displacement, dtype=np.float64)
    a, b, fb, fa = pairs.a, pairs.b, pairs.b_faces, pairs.a_faces
    nb, ok_b, corner_b = reference_wedge_normals(x, F, fb, b)
    na, ok_a, corner_a = reference_wedge_normals(x, F, fa, a)
    convex_b, convex_a = corner_b <= 0, corner_a <= 0
    normals = nb + na
    # G[:, c, e]: a's ends to B's faces (c = 0, 1), b's ends to A's faces (c = 2, 3)
    G = np.stack([np.stack([np.einsum("ij,ij->i", normals[c], x[a[:, e]] - x[b[:, e]] if c < 2 else x[b[:, e]] - x[a[:, e]])
                            for e in range(2)], axis=1) for c in range(4)], axis=1)
    middle = G[:, :2].mean(axis=2)
    nearer = np.argmax(middle, axis=1)
    use = np.stack([reference_corners_in_front(x, F, fa, a, normals[0]), reference_corners_in_front(x, F, fa, a, normals[1]),
                    reference_corners_in_front(x, F, fb, b, normals[2]), reference_corners_in_front(x, F, fb, b, normals[3])],
                   axis=1)
    by_middle = convex_b & ok_b & (middle.max(axis=1) < -tol) & use[np.arange(len(a)), nearer]
    both = ~by_middle & convex_b & convex_a & ok_b & ok_a & use.any(axis=1)
    other = both & (reference_lowest_of_max(G, use) < -tol)
    deepest = np.where(use, np.max(-G, axis=2), np.inf)
    nearer = np.where(other, np.argmin(deepest, axis=1), nearer)
    inside = by_middle | other
    vf = np.asarray(vertex_fragment, dtype=np.int64)
    n = np.int64(max(int(pairs.edge_a.max(initial=0)), int(pairs.edge_b.max(initial=0))) + 1)
    code, reverse = pairs.edge_a * n + pairs.edge_b, pairs.edge_b * n + pairs.edge_a
    inside &= ~(inside & isin_ints(reverse, code[inside]) & (vf[pairs.a[:, 0]] < vf[pairs.b[:, 0]]))
    chosen = G[np.arange(len(a)), nearer]
    pair, end = np.nonzero(inside[:, None] & (chosen < 0))
    if not len(pair):
        return no_face_rows(nv)
    k = nearer[pair]
    on_b = k < 2
    slave = np.where(on_b, a[pair, end], b[pair, end])
    copy = np.where(on_b, b[pair, end], a[pair, end])
    face = np.where(on_b, fb[pair, k % 2], fa[pair, k % 2])
    corner = np.argmax(F[face] == copy[:, None], axis=1)
    return rows_at_copy(slave, face, corner, chosen[pair, end], index)


def reference_edge_copies(edges, faces_at_edge, index):
    """The numpy loop of wedges3d.edge_copies: (a, ends of b in a's order, b's faces, partner flags)."""
    E, at, pid, key = edges, faces_at_edge, index.point, index.face_key
    points = np.sort(pid[E], axis=1)
    a, ends, faces, partner = [], [], [], []
    for ea in range(len(E)):
        if (at[ea] < 0).any():
            continue
        for eb in np.flatnonzero((points == points[ea]).all(axis=1)):
            if eb == ea or (at[eb] < 0).any():
                continue
            shared = np.isin(key[at[eb]], key[at[ea]])
            if shared.all():
                continue
            a.append(E[ea])
            ends.append(E[eb, ::-1] if pid[E[eb, 0]] != pid[E[ea, 0]] else E[eb])
            faces.append(at[eb])
            partner.append(shared)
    return tuple(np.array(v).reshape(-1, 2) for v in (a, ends, faces, partner))


def reference_reflex_wedge_rows(pairs, displacement, tol, index):
    """The numpy computation of wedges3d.reflex_wedge_rows."""
    X, F = index.points, index.faces
    nv = len(X)
    x = X + np.asarray(displacement, dtype=np.float64)
    a, b, fb = pairs.a, pairs.b, pairs.b_faces
    normals, ok, corner = reference_wedge_normals(x, F, fb, b)
    reflex = corner > 0
    gap = np.stack([np.stack([np.einsum("ij,ij->i", normals[k], x[a[:, e]] - x[b[:, e]]) for e in range(2)], axis=1)
                    for k in range(2)], axis=1)                              # (pair, face, end)
    least = np.where(pairs.partner[:, :, None], 0.0, gap).min(axis=(1, 2))
    hit = np.flatnonzero(ok & reflex & (np.minimum(least, 0.0) < -tol))
    pair, side, end = np.nonzero(~pairs.partner[hit][:, :, None] & np.ones((1, 1, 2), dtype=bool))
    if not len(pair):
        return no_face_rows(nv)
    p = hit[pair]
    face = fb[p, side]
    corner = np.argmax(F[face] == b[p, end][:, None], axis=1)
    return rows_at_copy(a[p, end], face, corner, gap[p, side, end], index)


@pytest.fixture(scope="module")
def blocks():
    """The blocks with every cut plane bent by 0.2 along grid lines a quarter in (faces turned by 11 degrees
    there, more than KINK: the folded rows have faces to add); copies stay bitwise equal."""
    arrays, piece = fragmented_box(CELLS, PIECES)
    P = arrays.points
    bend = 0.2 * np.abs(P - 0.25)                      # along grid lines off the junctions
    arrays.points = P + np.stack([bend[:, 1] + bend[:, 2], bend[:, 0] + bend[:, 2], bend[:, 0] + bend[:, 1]], axis=1)
    return arrays, MeshSetup3d(arrays.points, arrays.tets, arrays.faces, np.asarray(piece, dtype=np.int64))


def configurations(arrays, setup, seed):
    """Random displacements up to h / 5, with pairs of copies left together and faces squeezed flat."""
    rng = np.random.default_rng(seed)
    X = arrays.points
    U = rng.uniform(-0.2, 0.2, X.shape) / CELLS
    index = setup.copy_index
    slave, face, corner = setup.partners
    together = rng.choice(len(slave), len(slave) // 4, replace=False)          # copies that meet
    copy = index.faces[face[together], corner[together]]
    U[slave[together]] = U[copy]
    squeezed = index.faces[rng.choice(len(index.faces), 5, replace=False)]     # a face flat: all on one point
    for tri in squeezed:
        U[tri] = X[tri[0]] + U[tri[0]] - X[tri]
    return U


def same_rows(a, b):
    """Equal fields, floats to the last bit (the sign of zeros too)."""
    def bits(v):
        return v.view(np.int64) if v.dtype == np.float64 else v
    return len(a) == len(b) and all(np.array_equal(bits(getattr(a, f)), bits(getattr(b, f))) for f in type(a).FIELDS)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("tol", [0.0, 1e-3, 1e-2])
def test_behind_partner_rows_equal_their_numpy_reference(blocks, seed, tol):
    arrays, setup = blocks
    U = configurations(arrays, setup, seed)
    rows = behind_partner_rows(setup.partners, U, tol, setup.copy_index)
    reference = reference_behind_partner_rows(setup.partners, U, tol, setup.copy_index)
    assert len(reference) > 0
    assert same_rows(rows, reference)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("tol", [0.0, 1e-3])
def test_wedge_rows_equal_their_numpy_reference(blocks, seed, tol):
    arrays, setup = blocks
    U = configurations(arrays, setup, seed)
    args = setup.diagonal_edges, U, tol, setup.copy_index, setup.vertex_fragment
    rows, reference = wedge_rows(*args), reference_wedge_rows(*args)
    assert len(reference) > 0
    assert same_rows(rows, reference)


def test_edge_copies_equal_their_numpy_reference(blocks):
    _, setup = blocks
    pairs = setup.edge_copies
    a, ends, faces, partner = reference_edge_copies(setup.edge_detector.edges, setup.faces_at_edge, setup.copy_index)
    assert len(a) > 0 and partner.any() and not partner.all(axis=1).any()
    assert np.array_equal(pairs.a, a) and np.array_equal(pairs.b, ends)
    assert np.array_equal(pairs.b_faces, faces) and np.array_equal(pairs.partner, partner)
    assert pairs.a.dtype == pairs.b.dtype == pairs.b_faces.dtype == np.int64 and pairs.partner.dtype == bool
    none = edge_copies(np.zeros((0, 2), np.int64), np.zeros((0, 2), np.int64), setup.copy_index)
    assert len(none) == 0 and none.partner.shape == (0, 2)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("tol", [0.0, 1e-3])
def test_reflex_wedge_rows_equal_their_numpy_reference(seed, tol):
    # the fragmented box's wedges are of 90 degrees: three blocks with one of 240 instead
    arrays, fragment = sector_blocks(CELLS // 2, np.linspace(0.0, 0.5, CELLS + 1))
    setup = MeshSetup3d(arrays.points, arrays.tets, arrays.faces, fragment)
    U = configurations(arrays, setup, seed)
    args = setup.edge_copies, U, tol, setup.copy_index
    rows, reference = reflex_wedge_rows(*args), reference_reflex_wedge_rows(*args)
    assert len(reference) > 0
    assert same_rows(rows, reference)


def test_partner_at_equals_its_numpy_reference(blocks):
    _, setup = blocks
    index = setup.copy_index
    slave, face, corner = setup.partners
    rng = np.random.default_rng(3)
    # every partner incidence's face with its slave (a partner face at the slave) and with
    # its copy (the face itself), and random (face, boundary vertex) pairs (mostly none)
    face = np.concatenate([face, face, rng.integers(0, len(index.faces), 2000)])
    vertex = np.concatenate([slave, index.faces[setup.partners[1], corner], rng.choice(index.on, 2000)])
    found = ext.PartnerAt(index.faces, index.key_order, index.key_start, index.key_count, face, vertex)
    assert np.array_equal(found, reference_partner_at(index, face, vertex))
    m = len(slave)
    assert (found[:m] >= 0).all() and np.array_equal(found[m:2 * m], setup.partners[1])
    assert (found[2 * m:] < 0).any()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_found_rows_at_copies_equal_their_numpy_reference(blocks, seed):
    arrays, setup = blocks
    U = configurations(arrays, setup, seed)
    U[setup.vertex_fragment == seed % 2] += 0.2 / CELLS            # blocks pushed into their neighbours
    index = setup.copy_index
    detected = node_to_face_rows(arrays.points, arrays.faces, setup.detector.detect(U))
    rows, at_copy = found_rows_at_copies(arrays.points, arrays.faces, detected, setup.vertex_fragment, index=index)
    reference, reference_at = reference_found_rows_at_copies(detected, setup.vertex_fragment, index)
    # rows at a copy in both directions, and rows elsewhere
    assert 0 < reference_at.sum() < len(reference_at)
    assert not np.array_equal(rows.slave, detected.slave)
    assert np.array_equal(at_copy, reference_at) and same_rows(rows, reference)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_folded_rows_equal_their_numpy_reference(blocks, seed):
    arrays, setup = blocks
    U = configurations(arrays, setup, seed)
    U[setup.vertex_fragment == 0] += 0.2 / CELLS                  # a block pushed into its neighbours
    index = setup.copy_index
    found, at_copy = found_rows_at_copies(arrays.points, arrays.faces,
                                          node_to_face_rows(arrays.points, arrays.faces, setup.detector.detect(U)),
                                          setup.vertex_fragment, index=index)
    pick = at_copy & (found.dist < 0)
    assert pick.sum() > 10
    s = found.slave
    t = found.master[np.arange(len(found)), np.argmax(found.bary, axis=1)]
    codes = unique_ints(np.minimum(s, t) * len(arrays.points) + np.maximum(s, t))
    some = np.sort(np.random.default_rng(seed).choice(codes, len(codes) // 3, replace=False))
    for tied in (None, some):
        args = found, pick, setup.vertex_fragment
        rows = folded_rows_at_copies(arrays.points, arrays.faces, *args, tied=tied, index=index)
        reference = reference_folded_rows_at_copies(*args, tied, index)
        assert len(reference) > 0
        assert same_rows(rows, reference)


def test_no_rows_where_nothing_moved(blocks):
    arrays, setup = blocks
    U = np.zeros_like(arrays.points)
    assert len(behind_partner_rows(setup.partners, U, 0.0, setup.copy_index)) == 0
    assert len(wedge_rows(setup.diagonal_edges, U, 0.0, setup.copy_index, setup.vertex_fragment)) == 0
    assert len(reflex_wedge_rows(setup.edge_copies, U, 0.0, setup.copy_index)) == 0


def test_bad_input_names_the_argument(blocks):
    arrays, setup = blocks
    x, F = arrays.points, setup.copy_index.faces
    slave, face, corner = setup.partners
    with pytest.raises(ValueError, match="slave has an entry outside"):
        ext.BehindPartnerGaps(x, F, slave + len(x), face, corner, 0.0)
    # the range check's edges: -1, nv and the extremes of int64 out, nv - 1 in
    for bad in (-1, len(x), np.iinfo(np.int64).max, np.iinfo(np.int64).min):
        wrong = slave.copy()
        wrong[-1] = bad
        with pytest.raises(ValueError, match=rf"slave has an entry outside \[0, {len(x)}\)"):
            ext.BehindPartnerGaps(x, F, wrong, face, corner, 0.0)
    last = slave.copy()
    last[-1] = len(x) - 1
    ext.BehindPartnerGaps(x, F, last, face, corner, 0.0)
    with pytest.raises(ValueError, match="corner has the wrong shape"):
        ext.BehindPartnerGaps(x, F, slave, face, corner[:-1], 0.0)
    d = setup.diagonal_edges
    other = d.b_faces.copy()
    other[0, 1] = next(f for f in range(len(F)) if not set(d.b[0]) <= set(F[f]))
    with pytest.raises(ValueError, match=r"b_faces\[0, 1\] does not hold edge b"):
        ext.WedgeInside(x, F, d.a, d.b, other, d.a_faces, 0.0)
    other = d.a_faces.copy()
    other[0, 0] = next(f for f in range(len(F)) if not set(d.a[0]) <= set(F[f]))
    with pytest.raises(ValueError, match=r"a_faces\[0, 0\] does not hold edge a"):
        ext.WedgeInside(x, F, d.a, d.b, d.b_faces, other, 0.0)
    e = setup.edge_copies
    with pytest.raises(ValueError, match="partner must have shape"):
        ext.ReflexWedgeGaps(x, F, e.a, e.b, e.b_faces, e.partner[:-1], 0.0)
    other = e.b_faces.copy()
    other[0, 0] = next(f for f in range(len(F)) if not set(e.b[0]) <= set(F[f]))
    with pytest.raises(ValueError, match=r"b_faces\[0, 0\] does not hold edge b"):
        ext.ReflexWedgeGaps(x, F, e.a, e.b, other, e.partner, 0.0)
