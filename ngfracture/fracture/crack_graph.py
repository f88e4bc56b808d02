"""The cracks of a mesh as a graph: tips, junctions, mouths and the branches between them.

The crack faces (boundary segments named ``crack``) come in pairs of lips that coincide in
the reference configuration; merged by their reference points they are a graph whose
edges are crack segments. A point of degree 1 is a *tip* (the crack ends inside the body)
unless it lies on another boundary (a *mouth*: the crack reaches a free surface, a notch
or a hole); a point of degree 3 or more is a *junction*. A *branch* is a path between two
such points; a short branch that ends in a tip is a side branch.
"""
import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..geometry.meshcheck import cross_and_longest
from ..geometry.meshio import boundary_only

__all__ = ["CrackGraph", "crack_graph", "tip_sizes", "tip_advances"]


@dataclass
class CrackGraph:
    """The crack graph of a mesh.

    Parameters
    ----------
    points : numpy.ndarray (k, 2)
        The graph's points (reference coordinates).
    degree : numpy.ndarray (k,)
        Crack segments at each point.
    tips, mouths, junctions : numpy.ndarray of int
        Indices into ``points``.
    branches : list of dict
        ``{"length", "ends": (kind, kind)}`` per branch, kinds "tip", "mouth", "junction".
    vertex_point : numpy.ndarray (nv,)
        The point of every mesh vertex (the copies of a split vertex share it).
    edges : numpy.ndarray (m, 2)
        The crack segments as pairs of points (both lips: one edge).
    """
    points: np.ndarray
    degree: np.ndarray
    tips: np.ndarray
    mouths: np.ndarray
    junctions: np.ndarray
    branches: list
    vertex_point: np.ndarray = None
    edges: np.ndarray = None

    def side_branches(self, shorter_than):
        """Branches from a junction to a tip shorter than a length.

        Parameters
        ----------
        shorter_than : float

        Returns
        -------
        list of dict
        """
        return [b for b in self.branches if sorted(b["ends"]) == ["junction", "tip"] and b["length"] < shorter_than]

    def summary(self):
        """Counts and branch lengths, for summary.json.

        Returns
        -------
        dict
        """
        return {"tips": int(len(self.tips)), "mouths": int(len(self.mouths)), "junctions": int(len(self.junctions)),
                "branches": [{"length": b["length"], "ends": list(b["ends"])} for b in self.branches]}


def crack_graph(arrays, crack="crack", branches=True):
    """The crack graph of a mesh (see the module docstring).

    Parameters
    ----------
    arrays : MeshArrays
    crack : str
        The crack faces' boundary name.
    branches : bool
        Walk the branches (False: ``branches`` is empty; the points and their kinds only).

    Returns
    -------
    CrackGraph
    """
    X = arrays.points
    seg = arrays.boundary_segments(crack) if crack in arrays.bc_names else np.zeros((0, 2), dtype=np.int64)
    if len(seg) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return CrackGraph(np.zeros((0, 2)), empty, empty, empty, empty, [], np.arange(len(X)),
                          np.zeros((0, 2), dtype=np.int64))
    points, ids = np.unique(X, axis=0, return_inverse=True)       # twins merge: same reference point
    ids = ids.reshape(-1)
    edges = np.unique(np.sort(ids[seg], axis=1), axis=0)          # both lips: one edge
    degree = np.bincount(edges.ravel(), minlength=len(points))
    # the other boundaries: true boundary segments (not bonded interfaces) that are no crack edge
    outer = np.sort(ids[boundary_only(arrays).segments], axis=1)
    key = len(points)
    outer = outer[~np.isin(outer @ np.array([key, 1]), edges @ np.array([key, 1]))]
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[outer.ravel()] = True
    tips = np.flatnonzero((degree == 1) & ~on_boundary)
    mouths = np.flatnonzero((degree >= 1) & on_boundary & (degree <= 2))
    junctions = np.flatnonzero(degree >= 3)
    kind = {int(i): "tip" for i in tips} | {int(i): "mouth" for i in mouths} | {int(i): "junction" for i in junctions}
    walked = _branches(points, edges, kind) if branches else []
    return CrackGraph(points, degree, tips, mouths, junctions, walked, ids, edges)


def _branches(points, edges, kind):
    """Walk from every special point along its edges to the next special point."""
    neighbours = {}
    for a, b in edges.tolist():
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    seen, branches = set(), []
    for start in sorted(kind):
        for first in neighbours.get(start, []):
            if (start, first) in seen:
                continue
            path, prev, here = [start], start, first
            while here not in kind:
                path.append(here)
                nxt = [n for n in neighbours[here] if n != prev]
                if not nxt:
                    break
                prev, here = here, nxt[0]
            path.append(here)
            seen.update({(path[i], path[i + 1]) for i in range(len(path) - 1)})
            seen.update({(path[i + 1], path[i]) for i in range(len(path) - 1)})
            length = math.fsum(float(np.hypot(*(points[path[i + 1]] - points[path[i]]))) for i in range(len(path) - 1))
            branches.append({"length": length, "ends": (kind[start], kind.get(here, "tip"))})
    return branches


def tip_sizes(arrays, crack="crack", graph=None):
    """The crack tips and the size of the triangles at each: how finely the mesh resolves them.

    Parameters
    ----------
    arrays : MeshArrays
    crack : str
    graph : CrackGraph, optional
        The mesh's crack graph, if the caller has it (the branches are not needed).

    Returns
    -------
    (numpy.ndarray (k, 2), numpy.ndarray (k,))
        The tips' reference points and the longest edge of the triangles touching each.
    """
    graph = crack_graph(arrays, crack, branches=False) if graph is None else graph
    if len(graph.tips) == 0:
        return np.zeros((0, 2)), np.zeros(0)
    t = arrays.triangles
    longest = np.sqrt(cross_and_longest(arrays.points, t)[1])
    at_point = np.zeros(len(graph.points))
    corner_point = graph.vertex_point[t]                           # (ne, 3) points of the corners
    for k in range(3):
        np.maximum.at(at_point, corner_point[:, k], longest)
    return graph.points[graph.tips], at_point[graph.tips]


def tip_advances(before, after, crack="crack", graph=None):
    """How far the crack grew to each tip between two meshes of one run.

    The crack edges of ``after`` that ``before`` lacks (matched by their reference points)
    fall into connected pieces; a tip at the end of such a piece advanced by its length (a
    crack that started in between: both its tips by its whole length), any other by 0.

    Parameters
    ----------
    before, after : MeshArrays
    crack : str
    graph : CrackGraph, optional
        The crack graph of ``after``, if the caller has it.

    Returns
    -------
    (numpy.ndarray (k, 2), numpy.ndarray (k,))
        The tips of ``after`` and their advances.
    """
    new_graph = crack_graph(after, crack, branches=False) if graph is None else graph
    old_graph = crack_graph(before, crack, branches=False)
    tips = new_graph.tips
    if len(tips) == 0:
        return np.zeros((0, 2)), np.zeros(0)
    # both graphs' points in one numbering
    common = np.unique(np.concatenate([old_graph.points, new_graph.points]), axis=0, return_inverse=True)[1]
    common = common.reshape(-1)
    old_id, new_id = common[:len(old_graph.points)], common[len(old_graph.points):]
    n = common.max() + 1
    old_keys = np.sort(old_id[old_graph.edges], axis=1) @ np.array([n, 1])
    keys = np.sort(new_id[new_graph.edges], axis=1) @ np.array([n, 1])
    grown = new_graph.edges[~np.isin(keys, old_keys)]
    advance = np.zeros(len(tips))
    if len(grown):
        npts = len(new_graph.points)
        graph = sp.coo_matrix((np.ones(len(grown)), (grown[:, 0], grown[:, 1])), shape=(npts, npts))
        _, piece = connected_components(graph, directed=False)
        d = new_graph.points[grown[:, 0]] - new_graph.points[grown[:, 1]]
        length = np.bincount(piece[grown[:, 0]], weights=np.hypot(d[:, 0], d[:, 1]), minlength=piece.max() + 1)
        touched = np.zeros(npts, dtype=bool)
        touched[grown.ravel()] = True
        advance = np.where(touched[tips], length[piece[tips]], 0.0)
    return new_graph.points[tips], advance

