"""Benchmark of the detection of crossing boundary edges against the node-to-face detection.

``ngfracture.contact.edge_crossings3d.EdgeCrossingDetector.detect`` (pairs of boundary
edges of fragments that interlock) is timed against
``ngfracture.contact.collision3d.PenetrationDetector3d.detect`` (boundary vertices in
another fragment), the detection every round of a 3D contact solve runs, on the same
configuration in the same run: the ratio is the cost the edge search adds to a round's
detection.

Bodies. ``--cells N``: the fragmented cube of benchmarks/contact3d.py
(``ngfracture.geometry.pieces.fragmented_box``, N^3 cells of 6 tetrahedra, ``--pieces``^3
blocks, the lips coincident faces on bitwise-equal copies) in two configurations: ``rest``
(every lip closed: nothing found) and ``expanded`` (every block expanded about its
centroid so that neighbours overlap by 0.2 cells across their lips, the prediction of
benchmarks/contact3d.py). ``--npz FILE``: a saved state (arrays ``points``, ``tets``,
``faces``, ``piece`` per vertex, ``U``), e.g. a sphere run's state where an overlap check
failed.

Reported per case (seconds the best of ``--repeat``): tets, faces, edges, pairs (edge pairs
found), penetrations (node-to-face pairs found), t_edges, t_penetrations, ratio =
t_edges / t_penetrations, t_setup_edges and t_setup_penetrations (the detectors'
construction, once per mesh), and the edge search's counts (cell, box_tests, exact_tests,
pierces).
"""
import argparse
import time

import numpy as np

from benchmark_json import add_options, refuse_existing, write
from ngfracture.contact.collision3d import PenetrationDetector3d
from ngfracture.contact.edge_crossings3d import EdgeCrossingDetector

#: overlap of two neighbouring blocks across their lip, in cells (benchmarks/contact3d.py)
OVERLAP = 0.2


def face_fragments(tets, faces, fragment):
    """The fragment of every boundary face: that of the tetrahedron holding it."""
    tet_faces = np.sort(tets[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    keys = np.sort(faces, axis=1)
    n = int(tet_faces.max()) + 1
    code = (tet_faces[:, 0].astype(np.int64) * n + tet_faces[:, 1]) * n + tet_faces[:, 2]
    order = np.argsort(code, kind="stable")
    key = (keys[:, 0].astype(np.int64) * n + keys[:, 1]) * n + keys[:, 2]
    at = order[np.searchsorted(code[order], key)]
    if not np.array_equal(code[at], key):
        raise ValueError("faces: a boundary face is no face of a tetrahedron")
    return np.asarray(fragment)[at // 4]


def best(repeat, f):
    """(least seconds of ``repeat`` calls of f, its last result)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def measure(X, tets, faces, fragment, U, repeat):
    """The timings and counts of one configuration."""
    ff = face_fragments(tets, faces, fragment)
    t_setup_e, edges = best(repeat, lambda: EdgeCrossingDetector(X, faces, ff))
    t_setup_p, pen = best(repeat, lambda: PenetrationDetector3d(X, tets, faces, fragment))
    t_e, (pairs, stats) = best(repeat, lambda: edges.detect_counted(U))
    t_p, found = best(repeat, lambda: pen.detect(U))
    return {"tets": len(tets), "faces": len(faces), "edges": len(edges.edges), "pairs": len(pairs),
            "penetrations": len(found), "t_edges": t_e, "t_penetrations": t_p, "ratio": t_e / t_p,
            "t_setup_edges": t_setup_e, "t_setup_penetrations": t_setup_p, **stats}


def box_cases(cells, pieces, repeat):
    """The fragmented cube at rest and expanded."""
    from ngfracture.geometry.pieces import fragmented_box
    arrays, piece = fragmented_box(cells, pieces)
    X, tets = arrays.points, arrays.tets
    vf = np.zeros(len(X), dtype=np.int64)
    vf[tets.ravel()] = np.repeat(piece, 4)
    count = np.bincount(vf)
    centre = np.stack([np.bincount(vf, weights=X[:, d]) / count for d in range(3)], axis=1)
    U = OVERLAP / cells * pieces * (X - centre[vf])
    out = []
    for name, u in (("rest", np.zeros_like(X)), ("expanded", U)):
        out.append({"case": f"box{cells}_{name}", "cells": cells, "pieces": pieces,
                    **measure(X, tets, arrays.faces, piece, u, repeat)})
    return out


def npz_case(path, repeat):
    """A saved state (points, tets, faces, piece per vertex, U)."""
    d = np.load(path)
    tets = d["tets"]
    return {"case": str(path), **measure(d["points"], tets, d["faces"], d["piece"][tets[:, 0]], d["U"], repeat)}


def main(argv=None):
    """Run the cases and write the JSON."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cells", nargs="*", type=int, default=[26], help="cells per edge of the cube (default 26)")
    p.add_argument("--pieces", type=int, default=4, help="blocks per edge (default 4)")
    p.add_argument("--npz", nargs="*", default=[], help="saved states to time as well")
    p.add_argument("--repeat", type=int, default=5, help="repeats, the best kept (default 5)")
    add_options(p)
    args = p.parse_args(argv)
    refuse_existing(p, args)
    cases = []
    for n in args.cells:
        cases += box_cases(n, args.pieces, args.repeat)
    cases += [npz_case(f, args.repeat) for f in args.npz]
    write(args, {"cases": cases})


if __name__ == "__main__":
    main()
