"""The crack graph of a run read from its written files, as a user would, without the engine's code.

The VTU's triangles with their coincident copies merged (the two lips of a crack coincide
in the reference configuration) leave the body's outer boundary, holes and notches as
the edges of one triangle; the VTP's crack lines, merged the same way, are the graph's
edges. A point of one crack edge is a tip inside the body and a mouth on its boundary;
a point of three or more is a junction; a branch runs between two such points."""
import math

import numpy as np
import pyvista as pv

VTK_TRIANGLE = 5


def read_crack_graph(vtu_path, vtp_path):
    """The crack graph of one written step: dict of points, degree, tips, mouths, junctions, branches."""
    body, cracks = pv.read(str(vtu_path)), pv.read(str(vtp_path))
    nb = body.n_points
    points, ids = np.unique(np.vstack([body.points[:, :2], cracks.points[:, :2]]), axis=0, return_inverse=True)
    ids = ids.reshape(-1)
    triangles = ids[:nb][body.cells_dict[VTK_TRIANGLE]]
    sides = np.sort(np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    side, count = np.unique(sides, axis=0, return_counts=True)
    on_boundary = np.zeros(len(points), dtype=bool)
    on_boundary[side[count == 1].ravel()] = True
    lines = cracks.lines.reshape(-1, 3)[:, 1:] if cracks.n_lines else np.zeros((0, 2), dtype=np.int64)
    edges = np.unique(np.sort(ids[nb:][lines], axis=1), axis=0)
    degree = np.bincount(edges.ravel(), minlength=len(points))
    kind = {}
    kind.update({int(i): "tip" for i in np.flatnonzero((degree == 1) & ~on_boundary)})
    kind.update({int(i): "mouth" for i in np.flatnonzero((degree >= 1) & on_boundary)})
    kind.update({int(i): "junction" for i in np.flatnonzero(degree >= 3)})
    return {"points": points, "degree": degree, "edges": edges,
            "tips": [i for i, k in kind.items() if k == "tip"],
            "mouths": [i for i, k in kind.items() if k == "mouth"],
            "junctions": [i for i, k in kind.items() if k == "junction"],
            "branches": _walk(points, edges, kind)}


def _walk(points, edges, kind):
    """Every path between two special points: its length and the kinds of its ends."""
    neighbours = {}
    for a, b in edges.tolist():
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    used, branches = set(), []
    for start in sorted(kind):
        for first in neighbours[start]:
            if (start, first) in used:
                continue
            path = [start, first]
            while path[-1] not in kind:
                ahead = [n for n in neighbours[path[-1]] if n != path[-2]]
                if not ahead:
                    break
                path.append(ahead[0])
            used.update(zip(path[:-1], path[1:]))
            used.update(zip(path[1:], path[:-1]))
            length = math.fsum(float(np.hypot(*(points[b] - points[a]))) for a, b in zip(path[:-1], path[1:]))
            branches.append({"length": length, "ends": sorted((kind[start], kind.get(path[-1], "tip")))})
    return branches


def final_files(folder):
    """The last step's VTU and VTP of a run's output folder."""
    from pathlib import Path
    folder = Path(folder)
    return sorted(folder.glob("step_*.vtu"))[-1], sorted(folder.glob("cracks_*.vtp"))[-1]


def side_branches(graph, shorter_than):
    """Branches from a junction to a tip shorter than a length."""
    return [b for b in graph["branches"] if b["ends"] == ["junction", "tip"] and b["length"] < shorter_than]
