"""Splitting rules of the paper (section 3) on hand-made meshes, one per rule, and
cracks that split again: tips, branching, T-junctions, crossings, reaching the boundary."""
import dataclasses

import numpy as np
import pytest
import ngsolve

from ngfracture._ngfracture import ElementAreas
from ngfracture import fracture
from crack_util import grid_mesh, vid, fan_mesh, check_invariants, coords, mesh_from_arrays

X = [[1.0, 0.0]]   # maximum strain along x: cracks want to run along y
Y = [[0.0, 1.0]]


def split1(mesh, v, d):
    res = fracture.split_vertices(mesh, [v], d)
    check_invariants(mesh, res)
    return res


def edge_set(res, i=0):
    r = res.record
    e = r["edges"][r["edge_offsets"][i]:r["edge_offsets"][i + 1]]
    return {tuple(int(x) for x in row) for row in e}


def crack_length(mesh):
    return ngsolve.Integrate(1, mesh, ngsolve.BND, definedon=mesh.Boundaries("crack"))


def test_rule_1_interior_vertex_two_edges():
    m = grid_mesh(4, 4)
    c = vid(4, 2, 2)
    res = split1(m, c, X)
    assert res.record["rule"][0] == fracture.RULE_1
    assert edge_set(res) == {(c, vid(4, 2, 1)), (c, vid(4, 2, 3))}
    assert res.mesh.nv == m.nv + 1
    assert res.nfragments == 1
    # two crack faces per split edge, each of length 1
    assert crack_length(res.mesh) == pytest.approx(4.0, rel=1e-14)


def test_rule_1_regular_fan():
    m = fan_mesh([30, 90, 150, 210, 270, 330])
    res = split1(m, 0, X)
    assert res.record["rule"][0] == fracture.RULE_1
    assert edge_set(res) == {(0, 2), (0, 5)}          # the ring vertices at 90 and 270 degrees


def test_rule_1a_edges_of_one_triangle_replaced():
    # best edge at 95 deg; the best one on the other side (255 deg) bounds the same
    # obtuse triangle, so rule 1a takes the next one (290 deg)
    m = fan_mesh([95, 255, 290, 340, 30, 60])
    res = split1(m, 0, X)
    assert res.record["rule"][0] == fracture.RULE_1 | fracture.RULE_1A
    assert edge_set(res) == {(0, 1), (0, 3)}
    assert res.mesh.nv == m.nv + 1


def test_rule_1b_far_ends_on_boundary_split_too():
    m = fan_mesh([30, 90, 150, 210, 270, 330], outer=False)
    res = split1(m, 0, X)
    assert res.record["rule"][0] == fracture.RULE_1 | fracture.RULE_1B
    assert edge_set(res) == {(0, 2), (0, 5)}
    assert res.mesh.nv == m.nv + 3                    # the centre and both far ends
    assert res.nfragments == 2                        # cut through: no single-vertex joint
    assert crack_length(res.mesh) == pytest.approx(4.0, rel=1e-14)


def test_rule_2_boundary_vertex_interior_edge():
    m = grid_mesh(4, 4)
    v = vid(4, 2, 0)
    res = split1(m, v, X)
    assert res.record["rule"][0] == fracture.RULE_2
    assert edge_set(res) == {(v, vid(4, 2, 1))}
    assert res.mesh.nv == m.nv + 1
    assert crack_length(res.mesh) == pytest.approx(2.0, rel=1e-14)


def test_rule_2a_best_edge_on_boundary_no_split():
    m = grid_mesh(4, 4)
    v = vid(4, 2, 0)
    res = split1(m, v, Y)                             # crack would run along the boundary
    assert res.record["rule"][0] == fracture.RULE_2 | fracture.RULE_2A
    assert len(res.record["edges"]) == 0
    assert res.mesh.nv == m.nv
    assert "crack" not in res.mesh.GetBoundaries()


def test_rule_2b_far_end_on_boundary():
    m = grid_mesh(4, 1)
    v = vid(4, 2, 0)
    res = split1(m, v, X)
    assert res.record["rule"][0] == fracture.RULE_2 | fracture.RULE_2B
    assert edge_set(res) == {(v, vid(4, 2, 1))}
    assert res.mesh.nv == m.nv + 2
    assert res.nfragments == 2
    assert crack_length(res.mesh) == pytest.approx(2.0, rel=1e-14)


def test_tip_propagates_to_boundary():
    m = grid_mesh(4, 4)
    res = split1(m, vid(4, 2, 2), X)
    tip = vid(4, 2, 3)
    res2 = split1(res.mesh, tip, X)
    # the tip's fan is open only along the crack: rule 1 with the crack as one edge;
    # the far end is on the boundary, so the crack reaches it
    assert res2.record["rule"][0] == fracture.RULE_1 | fracture.RULE_TIP | fracture.RULE_1B
    assert edge_set(res2) == {(tip, vid(4, 2, 4))}
    assert res2.nfragments == 1
    res3 = split1(res2.mesh, vid(4, 2, 1), X)
    assert res3.record["rule"][0] == fracture.RULE_1 | fracture.RULE_TIP | fracture.RULE_1B
    assert res3.nfragments == 2
    assert crack_length(res3.mesh) == pytest.approx(8.0, rel=1e-14)


def test_branching_at_tip():
    # a tip loaded at 45 degrees: both chosen edges are new, the fan falls in three
    m = grid_mesh(6, 6)
    res = split1(m, vid(6, 3, 3), X)
    tip = vid(6, 3, 4)
    d = np.array([[1.0, -1.0]]) / np.sqrt(2)         # crack direction along the diagonal
    res2 = split1(res.mesh, tip, d)
    assert res2.record["rule"][0] & fracture.RULE_TIP
    assert edge_set(res2) == {(tip, vid(6, 4, 5)), (tip, vid(6, 2, 3))}
    assert res2.mesh.nv == res.mesh.nv + 2
    assert res2.nfragments == 1


def test_t_junction_and_crossing_cracks():
    n = 6
    m = grid_mesh(n, n)
    col = [vid(n, 3, j) for j in range(n + 1)]
    res = fracture.split_vertices(m, col, X * len(col))
    check_invariants(m, res)
    assert res.nfragments == 2
    assert crack_length(res.mesh) == pytest.approx(2 * n, rel=1e-14)
    # a horizontal crack from the left boundary meets the vertical one: T-junction
    left = [vid(n, i, 3) for i in range(0, 4)]
    res2 = fracture.split_vertices(res.mesh, left, Y * len(left))
    check_invariants(res.mesh, res2)
    assert res2.nfragments == 3
    # continue on the right: the cracks cross
    right = [vid(n, i, 3) for i in range(3, n + 1)]
    res3 = fracture.split_vertices(res2.mesh, right, Y * len(right))
    check_invariants(res2.mesh, res3)
    assert res3.nfragments == 4
    assert crack_length(res3.mesh) == pytest.approx(4 * n, rel=1e-14)
    # each quarter has the area n^2 / 4
    areas = np.bincount(res3.fragment, weights=np.abs(ElementAreas(res3.mesh)))
    assert np.allclose(areas, n * n / 4, rtol=1e-14)


def test_rule_flags_match_the_engine():
    from ngfracture import _ngfracture
    assert _ngfracture.CRACK_RULES == {name: bit for bit, name in fracture.RULE_NAMES}


def test_copies_split_again():
    # a vertex created by a split is a vertex like any other: split the copy of a
    # crack-face vertex across the crack (rule 2 on the crack surface)
    n = 6
    m = grid_mesh(n, n)
    col = [vid(n, 3, j) for j in range(n + 1)]
    res = fracture.split_vertices(m, col, X * len(col))
    mid = vid(n, 3, 3)
    copies = res.record["new_vertices"]
    copy = int(copies[np.flatnonzero(res.parent[copies] == mid)[0]])
    assert copy >= m.nv
    res2 = split1(res.mesh, copy, Y)
    assert res2.record["rule"][0] & fracture.RULE_2
    assert len(res2.record["edges"]) == 1
    assert res2.nfragments == 2
    e = tuple(res2.record["edges"][0])
    P = coords(res2.mesh)
    assert P[e[1], 1] == P[e[0], 1]                  # the new cut runs along x


def test_boundary_names_and_materials_survive():
    m = grid_mesh(4, 4)
    res = split1(m, vid(4, 2, 2), X)
    assert res.mesh.GetBoundaries() == ("outer", "crack")
    assert res.mesh.GetMaterials() == ("solid",)
    assert ngsolve.Integrate(1, res.mesh, ngsolve.BND, definedon=res.mesh.Boundaries("outer")) \
        == pytest.approx(16.0, rel=1e-14)
    # a second pass reuses the crack region instead of adding another
    res2 = split1(res.mesh, vid(4, 1, 2), Y)
    assert res2.mesh.GetBoundaries() == ("outer", "crack")


def test_crack_normals_point_out_of_the_material():
    # divergence theorem on each side of the crack: int_Omega div F = int_bnd F.n with
    # F = (x, 0) gives the area if the crack normals are outward
    m = grid_mesh(4, 4)
    res = fracture.split_vertices(m, [vid(4, 2, j) for j in range(5)], X * 5)
    mesh = res.mesh
    n = ngsolve.specialcf.normal(2)
    # fragment number as a P1 field: every vertex lies in exactly one fragment
    T = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3] - 1
    vf = np.zeros(mesh.nv)
    vf[T.ravel()] = np.repeat(res.fragment, 3)
    frag = ngsolve.GridFunction(ngsolve.H1(mesh, order=1))
    frag.vec.FV().NumPy()[:] = vf
    for f in range(res.nfragments):
        ind = ngsolve.IfPos(frag - f + 0.5, 1, 0) * ngsolve.IfPos(f + 0.5 - frag, 1, 0)
        area = ngsolve.Integrate(ind, mesh)
        flux = ngsolve.Integrate(ind * ngsolve.x * n[0], mesh, ngsolve.BND)
        assert area == pytest.approx(8.0, rel=1e-12)
        assert flux == pytest.approx(area, rel=1e-12)


if __name__ == "__main__":
    import pytest as _pytest
    raise SystemExit(_pytest.main([__file__, "-q"]))


def test_first_only_splits_the_first_vertex_that_splits():
    """One event per pass: the order's leading vertices that split nothing (rule 2a) are
    passed over, the first one that splits is split, nothing after it."""
    m = grid_mesh(4, 4)
    nv = m.nv
    tensors = np.zeros((nv, 3))
    edge, inner, other = vid(4, 2, 0), vid(4, 2, 2), vid(4, 1, 1)
    tensors[edge] = [0.0, 3.0, 0.0]      # largest, but along the boundary: rule 2a
    tensors[inner] = [2.0, 0.0, 0.0]     # next: splits (rule 1)
    tensors[other] = [1.5, 0.0, 0.0]     # overstrained too, left for the next pass
    res = fracture.split_by_tensor(m, tensors, 1.0, first_only=True)
    check_invariants(m, res)
    assert list(res.record["vertex"]) == [edge, inner]
    assert res.record["rule"][0] == fracture.RULE_2 | fracture.RULE_2A and res.record["rule"][1] & fracture.RULE_1
    def cut(r):          # the processed vertices that cut edges
        return set(r.record["vertex"][np.diff(r.record["edge_offsets"]) > 0].tolist())
    assert cut(res) == {inner} and np.array_equal(res.record["principal"], [3.0, 2.0])
    assert res.refusals == {"2 2a": 1}      # the overstrained vertex the rules refused
    every = fracture.split_by_tensor(m, tensors, 1.0)
    assert set(every.record["vertex"]) == {edge, inner, other} and cut(every) == {inner, other}
    # nothing splittable: the whole order processed, nothing split, the same mesh
    none = fracture.split_by_tensor(m, np.where(np.arange(nv)[:, None] == edge, tensors, 0.0), 1.0, first_only=True)
    assert none.nsplit == 0 and none.mesh is m


@pytest.mark.parametrize("enter_deg, rule", [(0.0, fracture.RULE_2 | fracture.RULE_2A), (24.0, fracture.RULE_2 | fracture.RULE_2A),
                                             (30.0, fracture.RULE_2 | fracture.RULE_2C)])
def test_rule_2c_a_crack_from_a_corner_enters_the_body(enter_deg, rule):
    """Corner (0, 0) of the grid: a crack line at 20 degrees to the bottom edge. The best
    edge is that boundary edge (20 degrees off); the only interior edge, the diagonal, is
    25 degrees off: cut (rule 2c) when enter_angle allows 25 degrees, else nothing (2a)."""
    m = grid_mesh(4, 4)
    v = vid(4, 0, 0)
    a = np.radians(20.0)
    res = fracture.split_vertices(m, [v], [[-np.sin(a), np.cos(a)]], rules=fracture.SplitRules(enter_angle=np.radians(enter_deg)))
    check_invariants(m, res)
    assert res.record["rule"][0] == rule
    if rule & fracture.RULE_2C:
        assert edge_set(res) == {(v, vid(4, 1, 1))} and res.mesh.nv == m.nv + 1
        assert crack_length(res.mesh) == pytest.approx(2 * np.sqrt(2.0), rel=1e-14)   # both faces
        assert fracture.rule_names(res.record["rule"][0]) == ["2", "2c"]
    else:
        assert res.mesh.nv == m.nv


def test_rule_2c_keeps_a_crack_line_along_the_boundary_out():
    """On a straight edge, a crack line along the boundary has its best interior edge 45
    degrees off (the grid) or more: nothing is split for any enter_angle below that."""
    m = grid_mesh(4, 4)
    res = fracture.split_vertices(m, [vid(4, 2, 0)], Y, rules=fracture.SplitRules(enter_angle=np.radians(44.0)))
    assert res.record["rule"][0] == fracture.RULE_2 | fracture.RULE_2A and res.mesh.nv == m.nv
    with pytest.raises(ValueError, match="enter_angle"):
        fracture.SplitRules(enter_angle=np.pi / 2)
    with pytest.raises(TypeError, match="rules must be a SplitRules"):
        fracture.split_vertices(m, [vid(4, 2, 0)], Y, rules="growth")


def test_single_edge_tip_grows_without_forking():
    """The tip of test_branching_at_tip under the growth rules: one edge, the grid diagonal
    along the half of the crack line away from the crack (the paper's rule 1 forks there)."""
    m = grid_mesh(6, 6)
    res = split1(m, vid(6, 3, 3), X)
    tip = vid(6, 3, 4)
    d = np.array([[1.0, -1.0]]) / np.sqrt(2)
    res2 = fracture.split_vertices(res.mesh, [tip], d, rules=fracture.GROWTH_RULES)
    check_invariants(res.mesh, res2)
    assert res2.record["rule"][0] == fracture.RULE_TIP | fracture.RULE_TIP1
    assert fracture.rule_names(res2.record["rule"][0]) == ["tip", "tip1"]
    assert edge_set(res2) == {(tip, vid(6, 4, 5))}
    assert res2.mesh.nv == res.mesh.nv + 1 and res2.nfragments == 1
    assert crack_length(res2.mesh) == pytest.approx(4.0 + 2 * np.sqrt(2.0), rel=1e-14)
    # the same crack line with the other orientation of the direction: the same edge
    res3 = fracture.split_vertices(res.mesh, [tip], -d, rules=fracture.GROWTH_RULES)
    assert edge_set(res3) == {(tip, vid(6, 4, 5))}


def test_single_edge_tip_reaches_the_boundary():
    """A tip one edge from the boundary grows through to it: the far end splits (rule 1b)
    and the body falls in two, as under the paper's rules."""
    m = grid_mesh(4, 4)
    res = split1(m, vid(4, 2, 2), X)
    res2 = fracture.split_vertices(res.mesh, [vid(4, 2, 3)], X, rules=fracture.GROWTH_RULES)
    assert res2.record["rule"][0] == fracture.RULE_TIP | fracture.RULE_TIP1 | fracture.RULE_1B
    assert edge_set(res2) == {(vid(4, 2, 3), vid(4, 2, 4))}
    res3 = fracture.split_vertices(res2.mesh, [vid(4, 2, 1)], X, rules=fracture.GROWTH_RULES)
    assert res3.nfragments == 2
    assert crack_length(res3.mesh) == pytest.approx(8.0, rel=1e-14)


def grown_crack(rules, degrees, splits=20):
    """A crack from the left edge of a grid (edges at 0, 45 and 90 degrees) grown tip by tip
    with its line at ``degrees``: its tip positions, the first one where it left the edge."""
    m = grid_mesh(30, 40)
    res = fracture.split_vertices(m, [vid(30, 0, 10)], Y, rules=rules)
    theta = np.radians(degrees)
    d = np.array([[-np.sin(theta), np.cos(theta)]])          # the largest strain, across the line
    tip = res.record["edges"][0][1]
    path = [coords(res.mesh)[tip]]
    for _ in range(splits):
        res = fracture.split_vertices(res.mesh, [tip], d, rules=rules)
        assert res.record["rule"][0] & fracture.RULE_TIP1 and res.nfragments == 1
        tip = res.record["edges"][0][1]
        path.append(coords(res.mesh)[tip])
    return np.array(path)


@pytest.mark.parametrize("degrees", [10.0, 20.0, 30.0])
def test_an_aimed_tip_zigzags_about_its_line_where_the_mesh_has_no_edge_along_it(degrees):
    """Tips aimed from k = 4 lip edges behind (AIMED_GROWTH_RULES, of runs refined ahead of
    their tips): each new tip is the candidate end nearest the line drawn from the crack
    k edges back, less than an edge off it, so the crack's direction keeps within atan(1 / (k + 1)) (11.3 degrees) of the line. Aimed
    from the tip itself, every tip takes the grid direction nearest the line, and the
    crack leaves the line at that direction's angle (10, 20 and 15 degrees here)."""
    theta = np.radians(degrees)
    offset = lambda path: np.abs((path - path[0]) @ np.array([np.sin(theta), -np.cos(theta)]))
    aimed = grown_crack(fracture.AIMED_GROWTH_RULES, degrees)
    k = fracture.AIMED_GROWTH_RULES.aim_edges
    assert k == 4
    chord = aimed[-1] - aimed[0]
    assert abs(np.degrees(np.arctan2(chord[1], chord[0])) - degrees) <= np.degrees(np.arctan(1 / (k + 1)))
    unaimed = grown_crack(fracture.GROWTH_RULES, degrees)
    assert dataclasses.replace(fracture.AIMED_GROWTH_RULES, aim_edges=0) == fracture.GROWTH_RULES
    nearest = min(abs(degrees), abs(45.0 - degrees))                      # the grid direction nearest the line
    assert offset(unaimed)[-1] == pytest.approx(20 * np.sin(np.radians(nearest)) * (1 if degrees < 22.5 else np.sqrt(2)),
                                                rel=1e-12)
    with pytest.raises(ValueError, match="aim_edges must be an integer >= 0"):
        fracture.SplitRules(aim_edges=-1)


def test_rule_2d_a_concave_corner_with_a_coarse_fan_starts_its_crack_on_the_nearest_edge():
    """A corner whose body spans 270 degrees (boundary edges at 0 and 270 degrees,
    interior edges at 60, 150 and 210): a crack line at 100 degrees. Its best edge is the
    boundary edge at 270 (10 degrees off the line's other half, which points out of the
    body); no interior edge lies within 30 degrees (rule 2c cuts nothing). The half at 100
    degrees points into the body, 100 and 170 degrees off the boundary edges: the edge
    nearest it (60 degrees, 40 off) is cut; its far end lies on the boundary and splits too
    (rule 2b: the fan is cut through). With enter_angle 0 (the paper's rules) nothing."""
    angles = np.radians([0.0, 60.0, 150.0, 210.0, 270.0])
    points = np.vstack([[0.0, 0.0], np.column_stack([np.cos(angles), np.sin(angles)])])
    m = mesh_from_arrays(points, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]])
    a = np.radians(100.0)
    direction = [[-np.sin(a), np.cos(a)]]
    res = fracture.split_vertices(m, [0], direction, rules=fracture.GROWTH_RULES)
    check_invariants(m, res)
    assert fracture.rule_names(res.record["rule"][0]) == ["2", "2b", "2d"]
    assert edge_set(res) == {(0, 2)} and res.mesh.nv == m.nv + 2
    assert crack_length(res.mesh) == pytest.approx(2.0, rel=1e-14)       # both faces of the unit edge
    paper = fracture.split_vertices(m, [0], direction, rules=fracture.PAPER_RULES)
    assert paper.record["rule"][0] == fracture.RULE_2 | fracture.RULE_2A and paper.mesh.nv == m.nv
