"""The crack graph (ngfracture.fracture.crack_graph) on cracks made by the crack engine:
a straight crack from an edge has one mouth and one tip; a crack that forks has a junction
and its three branches add up to the crack length. The cracks are cut along internal lines
of the mesh: one lip is named ``crack``, its twin keeps the line's name; the graph takes
both lips as one crack."""
import math

import numpy as np
import ngsolve as ng
from netgen.geom2d import SplineGeometry

from ngfracture.fracture import split_vertices
from ngfracture.fracture.crack_graph import crack_graph
from ngfracture.geometry.meshio import mesh_to_arrays


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
