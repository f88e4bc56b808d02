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

from ..geometry.meshio import boundary_only

__all__ = ["CrackGraph", "crack_graph"]


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
    """
    points: np.ndarray
    degree: np.ndarray
    tips: np.ndarray
    mouths: np.ndarray
    junctions: np.ndarray
    branches: list

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


def crack_graph(arrays, crack="crack"):
    """The crack graph of a mesh (see the module docstring).

    Parameters
    ----------
    arrays : MeshArrays
    crack : str
        The crack faces' boundary name.

    Returns
    -------
    CrackGraph
    """
    X = arrays.points
    seg = arrays.boundary_segments(crack) if crack in arrays.bc_names else np.zeros((0, 2), dtype=np.int64)
    if len(seg) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return CrackGraph(np.zeros((0, 2)), empty, empty, empty, empty, [])
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
    return CrackGraph(points, degree, tips, mouths, junctions, _branches(points, edges, kind))


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
