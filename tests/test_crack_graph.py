"""The crack graph (ngfracture.fracture.crack_graph) on cracks made by the crack engine:
a straight crack from an edge has one mouth and one tip; a crack that forks has a junction
and its three branches add up to the crack length. The cracks are cut along internal lines
of the mesh: one lip is named ``crack``, its twin keeps the line's name; the graph takes
both lips as one crack."""
import math

import numpy as np
import ngsolve as ng
import pytest
from netgen.geom2d import SplineGeometry

from ngfracture.fracture import split_vertices
from ngfracture.fracture.crack_graph import crack_graph
from ngfracture.geometry.meshio import MeshArrays, mesh_from_arrays, mesh_to_arrays


def plate_with_lines(lines, maxh=0.05):
    """The unit square (its left edge through (0, 0.5)) with internal lines from that point
    on or from earlier lines' points (a path for the crack engine)."""
    geo = SplineGeometry()
    corners = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0.5)]
    names = ["bottom", "right", "top", "left", "left"]
    points = {c: geo.AppendPoint(*c) for c in corners}
    for i, name in enumerate(names):
        geo.Append(["line", points[corners[i]], points[corners[(i + 1) % 5]]], bc=name, leftdomain=1, rightdomain=0)
    for start, end in lines:
        for c in (start, end):
            if c not in points:
                points[c] = geo.AppendPoint(*c)
        geo.Append(["line", points[start], points[end]], leftdomain=1, rightdomain=1, bc="path", maxh=maxh / 2)
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def split_along(mesh, points, direction):
    X = mesh.ngmesh.Coordinates()[:, :2]
    order = np.array([int(np.argmin(np.hypot(*(X - p).T))) for p in points])
    return split_vertices(mesh, order, np.tile(direction, (len(order), 1))).mesh


def test_an_edge_crack_has_one_mouth_and_one_tip():
    mesh = plate_with_lines([((0, 0.5), (0.5, 0.5))])
    X = mesh.ngmesh.Coordinates()[:, :2]
    path = X[(np.abs(X[:, 1] - 0.5) < 1e-12) & (X[:, 0] < 0.5 - 1e-9)]
    cracked = split_along(mesh, path[np.argsort(path[:, 0])], (0.0, 1.0))
    arrays = mesh_to_arrays(cracked)
    g = crack_graph(arrays)
    assert (len(g.tips), len(g.mouths), len(g.junctions)) == (1, 1, 0)
    assert len(g.branches) == 1 and sorted(g.branches[0]["ends"]) == ["mouth", "tip"]
    assert math.isclose(g.branches[0]["length"], 0.5, rel_tol=1e-12)
    assert g.side_branches(1.0) == []


def test_a_forked_crack_has_a_junction_and_a_short_side_branch():
    """A crack along y = 0.5 from the left edge to x = 0.6, and a side branch from
    (0.4, 0.5) up to (0.4, 0.6): the side branch (0.1) is shorter than 0.15."""
    mesh = plate_with_lines([((0, 0.5), (0.4, 0.5)), ((0.4, 0.5), (0.6, 0.5)), ((0.4, 0.5), (0.4, 0.6))], maxh=0.05)
    X = mesh.ngmesh.Coordinates()[:, :2]
    main = X[(np.abs(X[:, 1] - 0.5) < 1e-12) & (X[:, 0] < 0.6 - 1e-9)]
    cracked = split_along(mesh, main[np.argsort(main[:, 0])], (0.0, 1.0))
    Y = cracked.ngmesh.Coordinates()[:, :2]
    side = Y[(np.abs(Y[:, 0] - 0.4) < 1e-12) & (Y[:, 1] > 0.5 + 1e-9) & (Y[:, 1] < 0.6 - 1e-9)]
    cracked = split_along(cracked, side[np.argsort(side[:, 1])], (1.0, 0.0))
    arrays = mesh_to_arrays(cracked)
    g = crack_graph(arrays)
    assert len(g.junctions) == 1 and len(g.mouths) == 1 and len(g.tips) == 2
    assert math.isclose(sum(b["length"] for b in g.branches), 0.7, rel_tol=1e-12)
    short = g.side_branches(0.15)
    assert len(short) == 1 and math.isclose(short[0]["length"], 0.1, rel_tol=1e-9)


def test_tip_sizes_read_the_triangles_at_each_tip():
    """A structured mesh of squares of side s cut into two triangles: a crack along a grid
    line from the left edge ends at an interior vertex whose triangles' longest edge is the
    diagonal s sqrt(2); the resolution a run records is that over r."""
    from ngfracture.fracture.crack_graph import tip_sizes
    n, s = 8, 1.0 / 8
    mesh = mesh_from_arrays(structured_square(n))
    X = mesh.ngmesh.Coordinates()[:, :2]
    line = np.flatnonzero((np.abs(X[:, 1] - 0.5) < 1e-12) & (X[:, 0] < 0.5 - 1e-9))
    cracked = split_vertices(mesh, line[np.argsort(X[line, 0])], np.tile([0.0, 1.0], (len(line), 1))).mesh
    points, sizes = tip_sizes(mesh_to_arrays(cracked))
    assert points.shape == (1, 2) and np.allclose(points[0], [0.5, 0.5], atol=1e-12)
    assert sizes[0] == pytest.approx(s * math.sqrt(2), rel=1e-12)


def structured_square(n):
    """The unit square in n x n squares, each cut by its rising diagonal; one boundary name."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    points = np.column_stack([i.ravel(), j.ravel()]) / n
    v = lambda a, b: a * (n + 1) + b          # noqa: E731
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a, b = a.ravel(), b.ravel()
    triangles = np.concatenate([np.column_stack([v(a, b), v(a + 1, b), v(a + 1, b + 1)]),
                                np.column_stack([v(a, b), v(a + 1, b + 1), v(a, b + 1)])])
    k = np.arange(n)
    segments = np.concatenate([np.column_stack([v(k, 0), v(k + 1, 0)]), np.column_stack([v(n, k), v(n, k + 1)]),
                               np.column_stack([v(k + 1, n), v(k, n)]), np.column_stack([v(0, k + 1), v(0, k)])])
    return MeshArrays(points=points, triangles=triangles, regions=np.ones(len(triangles), dtype=np.int64),
                      region_names=["body"], segments=segments, seg_bc=np.ones(len(segments), dtype=np.int64),
                      bc_names=["outer"])



def test_a_run_warns_once_where_its_crack_tips_lie_in_triangles_larger_than_r():
    """The plate meshed at 0.1 everywhere with r = 0.04: its cracks grow in triangles of
    2.5 r and more; each step records h / r at its tips, the run warns once."""
    import warnings
    import ngfracture as nf
    from ngfracture.fracture.crack_graph import tip_sizes
    from ngfracture.run.simulation import TIP_RESOLUTION_LIMIT, UnresolvedCrackTip
    scene = nf.scenes.plate(maxh=0.1, notch_maxh=0.1, radius=0.04)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = nf.Simulation(scene, pictures="none").run()
    unresolved = [w for w in caught if issubclass(w.category, UnresolvedCrackTip)]
    assert len(unresolved) == 1
    history = result.summary["history"]
    assert result.summary["max_tip_resolution"] == max(h["tip_resolution"] for h in history) > TIP_RESOLUTION_LIMIT
    _, sizes = tip_sizes(result.state.arrays)
    assert history[-1]["tip_resolution"] == sizes.max(initial=0.0) / 0.04


def test_tip_advances_measure_the_crack_grown_to_each_tip():
    """On the structured square (side s = 1/8): a crack from the left edge over two edges,
    then over four, and a crack of two edges started on its own inside: the first tip
    advanced by 2 s, each tip of the new crack by its length 2 s, a tip that did not move
    by 0."""
    from ngfracture.fracture.crack_graph import tip_advances
    n, s = 8, 1.0 / 8
    mesh = mesh_from_arrays(structured_square(n))
    X = mesh.ngmesh.Coordinates()[:, :2]
    on_line = lambda y, x0, x1: np.flatnonzero((np.abs(X[:, 1] - y) < 1e-12) & (X[:, 0] > x0 - 1e-9) & (X[:, 0] < x1 + 1e-9))  # noqa: E731
    down = np.tile([0.0, 1.0], (n + 1, 1))
    first = on_line(0.5, 0.0, s)                       # (0, 0.5), (s, 0.5): tip at (2s, 0.5)
    short = split_vertices(mesh, first, down[:len(first)]).mesh
    grown_line = on_line(0.5, 0.0, 3 * s)              # tip at (4s, 0.5)
    middle = on_line(0.25, 4 * s, 4 * s)               # one interior vertex: a crack of 2 s
    order = np.concatenate([grown_line, middle])
    grown = split_vertices(mesh, order, down[:len(order)]).mesh
    points, advances = tip_advances(mesh_to_arrays(short), mesh_to_arrays(grown))
    got = sorted(zip(np.round(points / s).astype(int).tolist(), advances / s))
    assert [p for p, _ in got] == [[3, 2], [4, 4], [5, 2]]
    assert np.allclose([a for _, a in got], [2, 2, 2], rtol=1e-12)
    same_points, same = tip_advances(mesh_to_arrays(grown), mesh_to_arrays(grown))
    assert len(same_points) == 3 and np.all(same == 0)
