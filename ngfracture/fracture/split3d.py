"""Node splitting on tetrahedral meshes: the crack engine in 3D (``cpp_ext/crack_split3d.cpp``).

One pass reads::

    values, directions = principal_3d(tensors)          # largest principal value + direction
    result = split_by_tensor_3d(arrays, tensors, mode="spread")   # overstressed, no two neighbours
    u_new = split.transfer_vertex_field(u, result)       # exact copy through the parent map
    mesh = solid_mesh(result.arrays)                     # netgen / NGSolve rebuild

Conventions (as in 2D, ``split.py``)
-----------------------------------
* Splitting happens in the reference configuration: a new vertex is a bitwise copy of its
  parent. Tetrahedra keep their number, order, orientation and region; only vertex numbers
  change, so every tetrahedron keeps its volume to the last bit. New vertices are numbered
  from nv on, in creation order; a split vertex keeps its number on the side holding its
  smallest tetrahedron.
* The input faces keep their order (vertex numbers follow their tetrahedron); the new crack
  faces follow, two lips per face, each oriented out of its tetrahedron, with the boundary
  name ``crack`` (added to ``bc_names`` if absent).
* Vertices are processed in the given order and later vertices see the earlier splits.
  ``split_by_tensor_3d`` orders overstressed vertices by decreasing principal value, ties
  by increasing vertex number; tensors are rows (xx, yy, zz, yz, xz, xy). Its ``mode`` is
  ``StepControl.split``'s: "one" stops after the first vertex that splits anything;
  "spread" skips a vertex that shares an edge of the mesh as split so far with a vertex
  split earlier in the pass or a copy of one (C++ ``skip_neighbours``; judged again after
  the next equilibrium); "all" processes every overstressed vertex.

Rules (docs/solid.md, "Node splitting in 3D")
--------------------------------------------
Two tetrahedra are joined across a face iff they share its three vertex numbers; crack
faces are where they no longer do. The star of a vertex v is split in two sides by a
minimum cut (C++ ``MinCut``) of its tetrahedra through its interior faces, each face
costing its area times ``1 + 5 max(|d_a|, |d_b|) / h`` (d_a, d_b: distances of its far
vertices, the next front vertices, from the plane normal to the opening direction n; h:
the mean edge length at v), ten times more if it would make a crack branch; tetrahedra
wholly on one side of the plane, tetrahedra holding a crack face aligned with the plane
and the lips at front edges are fixed to their sides. The plane passes through v, or on a
front at the mean level of the crack faces around v, so the crack continues at its own
level. A part of a side that is disconnected from the side's largest part (ties: the part
of the smaller tetrahedron) changes side, the minus side first, so both sides are
connected; a refused cut falls back to the sides by centroid. The faces between the sides
become crack faces. On a crack front (front edges through v) the existing crack faces are
already cuts, and the new faces meet them where the front edges were: the front moves to
the far edges of the new faces (flag ``closed``). Then:

* pinched: a star already in pieces (crack faces all around) gets one copy per piece,
  without new faces;
* refused (``none``): a side is empty (``empty``), by the plane or after the cut; v lies on
  a boundary (free surface or crack) and a side touches none of v's boundary faces, so that
  the new faces would close a cone around v (``enclosed``); the new faces would end inside
  the body at an edge through v that was not a front edge (``dangling``); a side would be a
  piece of the mesh smaller than the star, a pocket closed by earlier cracks (``pocket``);
* far vertices: every vertex of the new faces whose star fell apart is split per piece
  (``far``): no two pieces are ever joined by a single vertex or a single edge;
* fronts meeting a free surface, two fronts meeting, a crack meeting another (junction,
  T-intersection) need no rule of their own: each is the same side split of the star with
  the existing crack and free-surface faces as cuts; the flags record which case it was
  (``surface``, ``crack``, ``front``, ``closed``).

A front edge is an edge held by two crack faces whose third vertices are distinct copies of
one point (the two lips meet there): :func:`front_edges_3d`.
"""
import math
from collections import Counter
from dataclasses import dataclass, replace

import numpy as np

from .. import _ngfracture as _ext
from ..geometry.solid import SolidArrays
from .solid_criterion import principal_3d

__all__ = ["SPLIT3D_FLAGS", "SPLIT_MODES", "Split3dResult", "split_vertices_3d",
           "split_by_tensor_3d", "front_edges_3d",
           "pinched_vertices_3d", "flag_names_3d", "REFUSALS_3D"]

#: bit flags of the record's "flags" entries, by name (cpp_ext/crack_split3d.hpp)
SPLIT3D_FLAGS = dict(_ext.SPLIT3D_FLAGS)
#: the flags that say why a vertex split nothing (docs/solid.md, "Refusals")
REFUSALS_3D = ("empty", "enclosed", "dangling", "aligned", "pocket")


def flag_names_3d(flags):
    """Names of the flags set in one record entry, e.g. ``['cut', 'front', 'closed']``.

    Parameters
    ----------
    flags : int
        An entry of ``record["flags"]``.

    Returns
    -------
    list of str
        In increasing bit order.
    """
    return [name for name, bit in sorted(SPLIT3D_FLAGS.items(), key=lambda x: x[1]) if int(flags) & bit]


@dataclass
class Split3dResult:
    """Outcome of one splitting pass on a tetrahedral mesh.

    Parameters
    ----------
    arrays : SolidArrays
        The new mesh (the same tetrahedra in the same order, more vertices, more faces).
    parent : numpy.ndarray
        Shape (nv_new,): the vertex of the old mesh every vertex copies.
    record : dict
        Per processed vertex (numpy arrays): ``vertex``, ``flags`` (:func:`flag_names_3d`),
        ``faces`` (new crack faces, lips counted once), ``fronts_before`` / ``fronts_after``
        (front edges through the vertex and its copies), ``new_vertices`` with
        ``new_offsets`` (vertices created at entry i are
        ``new_vertices[new_offsets[i]:new_offsets[i+1]]``), ``direction``, ``nv_old``.
    """
    arrays: SolidArrays
    parent: np.ndarray
    record: dict

    @property
    def nsplit(self):
        """Number of vertices created."""
        return len(self.parent) - int(self.record["nv_old"])

    @property
    def refused(self):
        """The processed vertices that changed nothing (flag ``none``), ascending."""
        return np.sort(self.record["vertex"][(self.record["flags"] & SPLIT3D_FLAGS["none"]) != 0]).astype(np.int64)

    @property
    def refusals(self):
        """The processed vertices that changed nothing (flag ``none``), counted by the rule
        that refused them (``REFUSALS_3D``; "none" where no rule is named).

        Returns
        -------
        dict
            Rule names to counts, sorted by name.
        """
        refused = (self.record["flags"] & SPLIT3D_FLAGS["none"]) != 0
        names = (" ".join(n for n in flag_names_3d(f) if n in REFUSALS_3D) or "none" for f in self.record["flags"][refused])
        return dict(sorted(Counter(names).items()))


def _crack_bc(arrays, crack_name):
    names = list(arrays.bc_names)
    if crack_name not in names:
        names.append(crack_name)
    return names.index(crack_name) + 1, names


def split_vertices_3d(arrays, vertices, directions, crack_name="crack", first_only=False, skip_neighbours=False):
    """Split vertices one after the other across their opening directions.

    Parameters
    ----------
    arrays : SolidArrays
        Tetrahedral mesh, reference configuration.
    vertices : array_like of int
        Vertices to process, in this order; numbers of the mesh as split so far (a vertex
        split earlier in the pass is its copy that kept the number).
    directions : array_like
        Shape (len(vertices), 3): the opening direction of each (any length > 0).
    crack_name : str
        Boundary name of the crack faces (new and existing).
    first_only : bool
        Stop after the first vertex that splits anything.
    skip_neighbours : bool
        Skip a vertex that shares an edge of the mesh as split so far with a vertex split
        earlier in the pass, or with a copy of one (the "spread" pass): its strain predates
        that split; it is judged again after the next equilibrium.

    Returns
    -------
    Split3dResult
        ``result.arrays`` is the input itself when nothing was split; ``record["skipped"]``
        lists the vertices skipped (not processed) by ``skip_neighbours``.

    Raises
    ------
    ValueError
        Bad shapes, vertex numbers out of range or repeated, zero or non-finite directions,
        a boundary face that is no face of a tetrahedron.
    """
    if not isinstance(arrays, SolidArrays):
        raise ValueError(f"ngfracture.fracture.split3d: arrays must be SolidArrays, got {type(arrays).__name__}")
    v = np.ascontiguousarray(vertices, dtype=np.int32).reshape(-1)
    d = np.ascontiguousarray(directions, dtype=float)
    if d.shape != (len(v), 3):
        raise ValueError(f"ngfracture.fracture.split3d: directions must have shape ({len(v)}, 3), got {d.shape}")
    if len(np.unique(v)) != len(v):
        raise ValueError("ngfracture.fracture.split3d: a vertex appears twice in the processing order")
    bc, names = _crack_bc(arrays, crack_name)
    r = _ext.Split3dVertices(np.asarray(arrays.points, dtype=float), np.asarray(arrays.tets), np.asarray(arrays.faces),
                             np.asarray(arrays.face_bc), bc, v, d, bool(first_only), bool(skip_neighbours))
    rec = {k: np.asarray(x) for k, x in dict(r["record"]).items()}
    nv = len(arrays.points)
    processed = np.isin(v, rec["vertex"])
    rec["direction"] = d[processed].copy()
    rec["skipped"] = np.asarray(r["skipped"], dtype=np.int64)
    rec["nv_old"] = nv
    if len(r["parent"]) == nv:
        return Split3dResult(arrays, np.arange(nv), rec)
    new = replace(arrays, points=r["points"], tets=r["tets"].astype(np.int64), faces=r["faces"].astype(np.int64),
                  face_bc=r["face_bc"].astype(np.int64), bc_names=names)
    return Split3dResult(new, r["parent"].astype(np.int64), rec)


#: the split modes of a pass, as ``StepControl.split``
SPLIT_MODES = ("one", "spread", "all")


def split_by_tensor_3d(arrays, tensors, critical=1.0, mode="one", crack_name="crack"):
    """One splitting pass from a vertex tensor field.

    Parameters
    ----------
    arrays : SolidArrays
        Tetrahedral mesh, reference configuration.
    tensors : numpy.ndarray
        Shape (nv, 6), rows (xx, yy, zz, yz, xz, xy), e.g. an overstrain (> 1 cracks).
    critical : float
        Finite, > 0: vertices whose largest principal value exceeds it are overstressed.
    mode : {"one", "spread", "all"}
        Which overstressed vertices the pass splits, in decreasing order of principal value
        (``StepControl.split``): "one" only the first that splits anything (the vertices
        before it, which split nothing, are in the record); "spread" every one that shares
        no edge with a vertex split earlier in the pass (``record["skipped"]`` lists the
        others); "all" every one.
    crack_name : str
        Boundary name of the crack faces.

    Returns
    -------
    Split3dResult
        The record also holds ``principal`` (values of the processed vertices).

    Raises
    ------
    ValueError
        Wrong tensor shape, NaN values, critical <= 0 or not finite, an unknown mode.
    """
    c = float(critical)
    if not (math.isfinite(c) and c > 0):
        raise ValueError(f"ngfracture.fracture.split3d: critical must be finite and > 0, got {critical!r}")
    if mode not in SPLIT_MODES:
        raise ValueError(f"ngfracture.fracture.split3d: mode must be one of {SPLIT_MODES}, got {mode!r}")
    t = np.asarray(tensors, dtype=float)
    if t.shape != (len(arrays.points), 6):
        raise ValueError(f"ngfracture.fracture.split3d: tensors must have shape ({len(arrays.points)}, 6), got {t.shape}")
    values, dirs = principal_3d(t)
    over = np.flatnonzero(values > c)
    order = over[np.lexsort((over, -values[over]))]
    res = split_vertices_3d(arrays, order, dirs[order], crack_name, first_only=mode == "one",
                            skip_neighbours=mode == "spread")
    res.record["principal"] = values[res.record["vertex"]]
    return res


def front_edges_3d(arrays, crack_name="crack"):
    """The crack front: edges held by two crack faces whose third vertices are distinct
    copies of one point (the lips meet there).

    Parameters
    ----------
    arrays : SolidArrays
    crack_name : str
        Boundary name of the crack faces.

    Returns
    -------
    numpy.ndarray of int, shape (k, 2)
        Edges (smaller vertex first), sorted, each once.
    """
    f = arrays.boundary_faces(crack_name)
    if not len(f):
        return np.zeros((0, 2), dtype=np.int64)
    e = np.concatenate([f[:, [0, 1, 2]], f[:, [1, 2, 0]], f[:, [2, 0, 1]]])
    p, q, r = np.minimum(e[:, 0], e[:, 1]), np.maximum(e[:, 0], e[:, 1]), e[:, 2]
    x = np.asarray(arrays.points)[r]
    o = np.lexsort((r, x[:, 2], x[:, 1], x[:, 0], q, p))
    same = ((p[o][1:] == p[o][:-1]) & (q[o][1:] == q[o][:-1]) & np.all(x[o][1:] == x[o][:-1], axis=1)
            & (r[o][1:] != r[o][:-1]))
    k = o[1:][same]
    return np.unique(np.column_stack([p[k], q[k]]), axis=0).reshape(-1, 2)


def pinched_vertices_3d(arrays):
    """Vertices whose star is in more than one piece through shared faces.

    Parameters
    ----------
    arrays : SolidArrays

    Returns
    -------
    numpy.ndarray of int
        Increasing; empty after every pass of the splitter.

    Raises
    ------
    ValueError
        A tetrahedron vertex number out of range.
    """
    return np.asarray(_ext.Split3dPinched(np.asarray(arrays.tets), len(arrays.points)), dtype=np.int64)
