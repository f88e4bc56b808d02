"""Crack formation by node splitting (paper section 3), on top of the C++ engine.

One crack pass reads top to bottom::

    tensors = criterion.overstrain(mesh, u)             # criterion.py: > 1 cracks
    values, directions = principal(tensors)             # largest principal value + direction
    order = select(values, 1.0)                         # overstrained, deterministic order
    result = split_vertices(mesh, order, directions[order])   # split + netgen rebuild
    u_new = transfer(u, result)                         # exact copy through the vertex map

``crack_step`` does all of it; ``split_by_tensor`` starts from a user-supplied vertex
tensor field (hand-made cases, other criteria). The engine splits triangle meshes
(``cpp_ext/crack_split.cpp``); :func:`ngfracture.fracture.strain.check_mesh_2d` refuses others.

Conventions
-----------
* Splitting happens in the reference configuration. A new vertex is a copy of its parent
  (same coordinates, same field values); triangles keep their number, order, orientation
  and region; only their vertex numbers change. New boundary edges get the boundary name
  ``crack``; existing boundary names and materials survive.
* Order of processing in one pass: by decreasing principal value, ties by increasing vertex
  number. The directions are those of the strain before the pass; vertices created during
  the pass are not processed again in that pass.
* Tensors are stored as rows (xx, yy, xy), xy the tensor (not engineering) shear.

Rules as implemented (paper section 3; decisions where the paper is silent)
-------------------------------------------------------------------------
* Angle of an edge: the angle between the edge (as a line) and the line orthogonal to the
  maximum strain direction, in the reference configuration. Ties: smaller far-end vertex
  number. An isotropic tensor has direction (1, 0).
* Interior vertex (rule 1): the first edge is the best one; the second is the best edge on
  the other side of the line through the vertex along the maximum strain direction (a
  crack runs through the vertex; two edges on one side would cut out a wedge). Rule 1a:
  if these two edges bound one triangle, the second is replaced by the next best edge on
  that side that does not; if the other side has none, the best edge not sharing a
  triangle with the first; if there is none either, nothing is split (flag ``none``).
* Crack tip: a vertex whose fan is open only along one crack (its two boundary edges end
  in copies of one vertex, bitwise equal points) is treated as interior with the crack as
  one already-cut edge; usually the crack is the first edge and one new edge is cut
  (propagation), otherwise two new edges are cut (branching).
* Boundary vertex (rule 2, also on crack faces): the best edge among all its edges; if it
  is a boundary edge nothing is split (rule 2a), else it is cut.
* Growth rules (``SplitRules``, used with the critical-distance criterion): a crack tip
  cuts one edge, the interior edge nearest the half of the crack line away from the crack
  (rule tip1: a crack grows from its tip, it does not fork there); a boundary vertex
  whose best edge is a boundary edge cuts its best interior edge if that lies within
  ``enter_angle`` of the crack line (rule 2c: a crack starts at a V-notch tip, whose
  flank is often the best edge); where none is, but one half of the crack line points
  into the body ``enter_angle`` or more off both boundary edges, it cuts the interior edge
  nearest that half (rule 2d: a concave corner whose fan is coarser than the angle; a
  crack line along a straight boundary still splits nothing).
* Rules 1b/2b and "never two pieces joined by a single vertex": after the cut, the far end
  of every cut edge is split if its fan fell apart (it was on the boundary, on a crack face
  or a crack tip). Only the processed vertex and those far ends change their fans.
* Which piece keeps the old vertex number: the fan holding the smallest triangle number.
  New vertices are numbered from nv on, in creation order.
* Fragments: connected components of triangles through shared vertices (the same as
  through shared edges, since no two pieces touch at a single vertex), numbered by their
  smallest triangle.
"""
import math
import time
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import ngsolve

from .. import _ngfracture as _ext
from ..geometry.meshcheck import validate_mesh
from ..geometry.meshio import ngsolve_mesh
from .criterion import Criterion
from .strain import check_mesh_2d, check_positive, displacement_order, principal

__all__ = [
    "RULE_1", "RULE_1A", "RULE_1B", "RULE_2", "RULE_2A", "RULE_2B", "RULE_2C", "RULE_2D", "RULE_TIP", "RULE_TIP1",
    "RULE_NONE", "RULE_NAMES", "SplitRules", "PAPER_RULES", "GROWTH_RULES", "AIMED_GROWTH_RULES", "SplitResult", "split_vertices",
    "transfer", "transfer_vertex_field", "split_by_tensor", "crack_step", "rule_names",
]


# Bit flags of the record's "rule" entry (cpp_ext/crack_split.hpp).
RULE_1 = 1       # interior vertex: two edges cut
RULE_1A = 2      # the two best edges bounded one triangle: the second one was replaced
RULE_1B = 4      # a far end on the boundary or a crack surface was split as well
RULE_2 = 8       # boundary vertex: one interior edge cut
RULE_2A = 16     # boundary vertex whose best edge is a boundary edge: nothing split
RULE_2B = 32     # the far end of the rule-2 edge was split as well
RULE_TIP = 64    # crack tip (fan open only along a crack): treated by rule 1
RULE_NONE = 128  # nothing split (no admissible edge pair, isolated or pinched vertex)
RULE_2C = 256    # boundary vertex whose best edge is a boundary edge: the crack entered the body (enter_angle)
RULE_TIP1 = 512  # crack tip extended by one edge (single_edge_tips)
RULE_2D = 1024   # boundary vertex, no interior edge within enter_angle: the crack entered on the edge nearest its half-line into the body

RULE_NAMES = [(RULE_1, "1"), (RULE_1A, "1a"), (RULE_1B, "1b"), (RULE_2, "2"),
               (RULE_2A, "2a"), (RULE_2B, "2b"), (RULE_TIP, "tip"), (RULE_NONE, "none"), (RULE_2C, "2c"),
               (RULE_TIP1, "tip1"), (RULE_2D, "2d")]


@dataclass(frozen=True)
class SplitRules:
    """Which edges a pass cuts at crack tips and boundary vertices.

    Parameters
    ----------
    enter_angle : float
        Radians in [0, pi/2). 0: the paper's rule 2a. Else a boundary vertex whose best
        edge is a boundary edge cuts its best interior edge if that lies within
        ``enter_angle`` of the crack line (rule 2c).
    single_edge_tips : bool
        A crack tip cuts one edge, ahead of the crack (rule tip1), instead of two (rule 1).
    aim_edges : int
        With ``single_edge_tips``: the tip cuts the edge, less than 45 degrees off the
        crack line, whose far end lies nearest the crack line drawn through the crack's
        point up to ``aim_edges`` lip edges behind the tip (as far back as the tip lies
        within one tip edge of that line; 0, 1, or not even the second point within it:
        the edge nearest the line's direction). The crack zigzags about its line instead
        of running along the one mesh direction nearest it, which on a mesh refined by
        bisection can be the same for many tips.

    Raises
    ------
    ValueError
        An ``enter_angle`` outside [0, pi/2), a negative ``aim_edges``.
    """
    enter_angle: float = 0.0
    single_edge_tips: bool = False
    aim_edges: int = 0

    def __post_init__(self):
        if not (isinstance(self.enter_angle, (int, float)) and 0 <= self.enter_angle < math.pi / 2):
            raise ValueError(f"ngfracture.fracture.split: enter_angle must be in [0, pi/2) radians, got {self.enter_angle!r}")
        if not (isinstance(self.aim_edges, int) and self.aim_edges >= 0):
            raise ValueError(f"ngfracture.fracture.split: aim_edges must be an integer >= 0, got {self.aim_edges!r}")


PAPER_RULES = SplitRules()
# The critical-distance criterion's: 30 degrees lets a crack along the bisector of a V-notch
# (flank 14 degrees off in the plate) enter the body, and keeps out a crack line along a
# straight boundary, whose interior edges are 45 degrees or more off on netgen's meshes.
GROWTH_RULES = SplitRules(enter_angle=math.radians(30.0), single_edge_tips=True)
# Runs refined ahead of the tips (Scene.refine): a tip aims from up to 4 lip edges behind
# it. Bisection gives the refined triangles the few edge directions of each coarse one,
# and the nearest to the crack line can be the same, 20 degrees off it, tip after tip;
# aimed, the crack's direction keeps within atan(1/5) = 11 degrees of the line
# (docs/criterion.md, "Aiming the tip").
AIMED_GROWTH_RULES = SplitRules(enter_angle=math.radians(30.0), single_edge_tips=True, aim_edges=4)


def rule_names(flags):
    """Names of the rules set in one record flag, e.g. ``['1', '1b']``.

    Parameters
    ----------
    flags : int
        An entry of ``record["rule"]`` (bit flags ``RULE_*``).

    Returns
    -------
    list of str
        The names ("1", "1a", "1b", "2", "2a", "2b", "tip", "none") in that order.
    """
    return [name for bit, name in RULE_NAMES if int(flags) & bit]


@dataclass
class SplitResult:
    """Outcome of one splitting pass.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The new mesh (same triangles in the same order, more vertices).
    parent : numpy.ndarray
        For every new vertex, the vertex of the old mesh it copies (identity for old ones).
    record : dict
        Plain arrays describing the pass, see :func:`split_vertices`.
    fragment : numpy.ndarray
        Fragment (connected component) number of every triangle, numbered by first triangle.
    nfragments : int
        Number of fragments.
    crack_segments : numpy.ndarray
        (m, 2) vertex pairs of the boundary segments added in region ``crack``.
    timings : dict
        Seconds spent in the C++ split, the netgen rebuild and ``ngsolve.Mesh``.
    """
    mesh: object
    parent: np.ndarray
    record: dict
    fragment: np.ndarray
    nfragments: int
    crack_segments: np.ndarray
    timings: dict = field(default_factory=dict)

    @property
    def nsplit(self):
        """Number of vertices created."""
        return len(self.parent) - int(self.record["nv_old"])

    @property
    def refused(self):
        """The processed vertices that cut no edge (rules 2a, none), ascending."""
        return np.sort(self.record["vertex"][np.diff(self.record["edge_offsets"]) == 0]).astype(np.int64)

    @property
    def refusals(self):
        """The processed vertices that cut no edge, counted by their rules ("2 2a", "none").

        Returns
        -------
        dict
            Rule names (:func:`rule_names`, joined by spaces) to counts, sorted by name.
        """
        cut = np.diff(self.record["edge_offsets"]) > 0
        return dict(sorted(Counter(" ".join(rule_names(r)) for r in self.record["rule"][~cut]).items()))


def split_vertices(mesh, vertices, directions, crack_name="crack", skip_neighbours=False, rules=PAPER_RULES):
    """Split vertices along the edges most orthogonal to given directions (rules 1-2b).

    The mesh itself is not checked here (crack_step and split_by_tensor run
    meshcheck.validate_mesh first); the engine keeps a valid mesh valid.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D mesh of linear triangles, reference configuration.
    vertices : array_like of int
        Vertices to process, in this order (see :func:`ngfracture.fracture.criterion.select`).
    directions : array_like
        Shape (len(vertices), 2): maximum strain direction of each vertex (any length > 0).
    crack_name : str
        Boundary name of the new crack faces.
    skip_neighbours : bool
        Skip a vertex that shares a triangle with a vertex split earlier in the pass: its
        strain predates that split, which relieves it; it is judged again after the
        next equilibrium. (False: every listed vertex is processed, the paper's pass.)
    rules : SplitRules
        ``PAPER_RULES`` (rules 1-2b) or ``GROWTH_RULES`` (single-edge tips, rule 2c).

    Returns
    -------
    SplitResult
        ``mesh`` is the input mesh itself when no vertex was split; ``record`` lists
        only the vertices processed.
        ``record`` holds numpy arrays: ``vertex`` (processed vertices), ``rule`` (bit
        flags, :func:`rule_names`), ``position`` (their coordinates), ``direction``,
        ``edges`` (k, 2) cut edges (processed vertex, far end) in the numbering at cut time,
        ``edge_offsets`` (edges of entry i are ``edges[edge_offsets[i]:edge_offsets[i+1]]``),
        ``new_vertices`` with ``new_offsets`` likewise, ``nv_old``.

    Raises
    ------
    ValueError
        Bad shapes, vertex numbers out of range, zero or non-finite directions, non-2D mesh.
    """
    check_mesh_2d(mesh)
    v = np.ascontiguousarray(vertices, dtype=np.int32).reshape(-1)
    d = np.ascontiguousarray(directions, dtype=float)
    if d.ndim != 2 or d.shape != (len(v), 2):
        raise ValueError(f"ngfracture.fracture.split: directions must have shape ({len(v)}, 2), got {d.shape}")
    if len(v) and (v.min() < 0 or v.max() >= mesh.nv):
        raise ValueError(f"ngfracture.fracture.split: vertex numbers must be in [0, {mesh.nv})")
    if len(np.unique(v)) != len(v):
        raise ValueError("ngfracture.fracture.split: a vertex appears twice in the processing order")
    if not np.all(np.isfinite(d)) or np.any(np.all(d == 0, axis=1)):
        raise ValueError("ngfracture.fracture.split: directions must be finite and nonzero")
    if not isinstance(rules, SplitRules):
        raise TypeError(f"ngfracture.fracture.split: rules must be a SplitRules, got {type(rules).__name__}")
    r = _ext.CrackSplit(mesh.ngmesh, v, d, crack_name, bool(skip_neighbours), float(rules.enter_angle),
                      bool(rules.single_edge_tips), int(rules.aim_edges))
    t0 = time.perf_counter()
    # nothing split: keep the very same mesh, so callers keep their spaces and factorisations
    newmesh = mesh if len(r["parent"]) == mesh.nv else ngsolve_mesh(r["ngmesh"], mesh.ne)
    t_mesh = time.perf_counter() - t0
    rec = dict(r["record"])
    coords = mesh.ngmesh.Coordinates()
    rec["position"] = coords[rec["vertex"], :2].copy() if len(rec["vertex"]) else np.zeros((0, 2))
    rec["direction"] = d.copy()
    rec["nv_old"] = mesh.nv
    return SplitResult(mesh=newmesh, parent=r["parent"], record=rec, fragment=r["fragment"],
                       nfragments=r["nfragments"], crack_segments=r["crack_segments"],
                       timings={"split": r["t_split"], "netgen": r["t_netgen"], "ngsolve_mesh": t_mesh})


def transfer_vertex_field(values, result):
    """Carry a vertex field to the split mesh: ``values[parent]`` (exact, no interpolation).

    Parameters
    ----------
    values : numpy.ndarray
        Shape (nv_old, ...).
    result : SplitResult
        The pass that made the new mesh.

    Returns
    -------
    numpy.ndarray
        Shape (nv_new, ...).

    Raises
    ------
    ValueError
        If values does not have one row per vertex of the old mesh.
    """
    a = np.asarray(values)
    if a.shape[0] != result.record["nv_old"]:
        raise ValueError(f"ngfracture.fracture.split: field has {a.shape[0]} rows, the old mesh has "
                         f"{result.record['nv_old']} vertices")
    return a[result.parent]


def transfer(u, result):
    """Carry a displacement GridFunction to the split mesh, exactly.

    Order 1: vertex values copied through the vertex map. Order 2: every element's dofs are
    copied (triangles keep number and vertex order, quadratic edge dofs have no
    orientation). Order >= 3 is refused: edge dofs change sign when a split renumbers an edge.

    Parameters
    ----------
    u : ngsolve.GridFunction
        On ``VectorH1(old_mesh, order=p)``, p <= 2.
    result : SplitResult
        The pass that split ``old_mesh``.

    Returns
    -------
    ngsolve.GridFunction
        u itself if nothing was split, else a new GridFunction
        on ``VectorH1(result.mesh, order=p)`` (no Dirichlet flags: the caller's
        constraints are rebuilt for the new mesh anyway).

    Raises
    ------
    NotImplementedError
        For order >= 3.
    ValueError
        If u does not live on the mesh that was split.
    TypeError
        If u is not on a 2D ``VectorH1`` space.
    """
    p = displacement_order(u)
    if p > 2:   # refused even when nothing split: the same call must not depend on the data
        raise NotImplementedError("ngfracture.fracture.split.transfer: order >= 3 is not supported "
                                  "(edge dof orientation changes with the vertex numbers)")
    if result.mesh is u.space.mesh:
        return u                      # nothing was split: the field is already there
    if u.space.mesh.nv != result.record["nv_old"]:
        raise ValueError("ngfracture.fracture.split.transfer: the field is not on the split mesh")
    fes = ngsolve.VectorH1(result.mesh, order=p)
    gf = ngsolve.GridFunction(fes)
    if p == 1:
        old = u.vec.FV().NumPy().reshape(2, -1)
        gf.vec.FV().NumPy()[:] = old[:, result.parent].reshape(-1)
    else:
        gf.vec.FV().NumPy()[:] = _ext.CrackTransferElementDofs(u.space, fes, u.vec.FV().NumPy())
    return gf


def split_by_tensor(mesh, tensors, critical, crack_name="crack", skip_neighbours=False, first_only=False,
                    rules=PAPER_RULES, check_mesh=True):
    """One splitting pass from a vertex tensor field supplied by the caller.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    tensors : numpy.ndarray
        Shape (nv, 3), rows (xx, yy, xy), e.g. a nodal strain or stress.
    critical : float
        Finite, > 0; vertices whose largest principal value exceeds it are split.
    crack_name : str
        Boundary name of the new crack faces.
    skip_neighbours : bool
        See :func:`split_vertices`.
    first_only : bool
        Split only the first vertex of the order that splits anything (one event per pass:
        every other vertex is judged again after the next equilibrium); the vertices before
        it, which split nothing (rules 2a, none), are in the record.
    rules : SplitRules
        See :func:`split_vertices`.
    check_mesh : bool
        False skips meshcheck.validate_mesh, for a caller that has checked this mesh
        (an ElasticProblem on it has).

    Returns
    -------
    SplitResult
        The record also holds ``principal`` (values of the processed vertices).

    Raises
    ------
    ValueError
        Wrong tensor shape, NaN values, critical <= 0 or NaN, non-2D mesh; ``MeshError``
        (a ValueError) on a bad mesh (meshcheck.py).
    TypeError
        If mesh is not an ``ngsolve.Mesh``.
    """
    check_mesh_2d(mesh)
    c = check_positive(critical)
    t = np.asarray(tensors, dtype=float)
    if t.shape != (mesh.nv, 3):
        raise ValueError(f"ngfracture.fracture.split: tensor field must have shape ({mesh.nv}, 3), got {t.shape}")
    if check_mesh:
        validate_mesh(mesh)
    return _split_pass(mesh, t, c, crack_name, skip_neighbours, first_only, rules)


def _split_pass(mesh, tensors, critical, crack_name, skip_neighbours=False, first_only=False, rules=PAPER_RULES):
    values, dirs = principal(tensors)
    order = _ext.CrackSelect(values, critical)
    if first_only:
        # the engine processes a whole order: find the first vertex that splits alone
        for k in range(len(order)):
            alone = split_vertices(mesh, order[k:k + 1], dirs[order[k:k + 1]], crack_name, rules=rules)
            if alone.nsplit:
                if k == 0:      # usually the most overstrained vertex: the pass is this split
                    alone.record["principal"] = values[order[:1]]
                    return alone
                order = order[:k + 1]    # again, with the vertices before it in the record
                break
    res = split_vertices(mesh, order, dirs[order], crack_name, skip_neighbours, rules)
    res.record["principal"] = values[order]
    return res


def crack_step(mesh, u, critical=None, measure="green", criterion=None, crack_name="crack"):
    """One crack pass: overstrain, overstrained vertices, splitting, field transfer.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The reference mesh u lives on.
    u : ngsolve.GridFunction
        Displacement on ``VectorH1(mesh, order<=2)``.
    critical : float, optional
        Critical principal strain (> 0) of the paper's one-ring nodal strain; ignored when
        ``criterion`` is given.
    measure : {'green', 'linear'}
        Strain measure of that default criterion.
    criterion : Criterion, optional
        Or anything with ``overstrain(mesh, u)`` returning a tensor per vertex whose
        largest principal value exceeds 1 where a vertex cracks.
    crack_name : str
        Boundary name of the new crack faces.

    Returns
    -------
    new_mesh : ngsolve.Mesh
        The split mesh (the input mesh itself if nothing was split).
    new_u : ngsolve.GridFunction
        u carried exactly through the vertex map.
    result : SplitResult
        Record of the pass (``result.record``), fragments, timings.

    Raises
    ------
    ValueError, TypeError
        Bad mesh (``MeshError``, see meshcheck.py), field or threshold, neither critical
        nor criterion given, or a criterion tensor field of the wrong shape; before any
        splitting.
    NotImplementedError
        For a displacement of order >= 3.
    """
    check_mesh_2d(mesh)
    if criterion is None:
        if critical is None:
            raise ValueError("ngfracture.fracture.split: give a critical strain or a criterion")
        criterion = Criterion(critical, measure=measure)
    if isinstance(u, ngsolve.GridFunction):
        if displacement_order(u) > 2:
            raise NotImplementedError("ngfracture.fracture.split: displacement order >= 3 is not supported")
        if u.space.mesh.nv != mesh.nv or u.space.mesh.ne != mesh.ne:
            raise ValueError("ngfracture.fracture.split: the displacement does not live on this mesh")
    else:
        raise TypeError("ngfracture.fracture.split.crack_step: u must be an ngsolve.GridFunction; "
                        "use split_by_tensor for plain arrays")
    validate_mesh(mesh)
    tensors = np.asarray(criterion.overstrain(mesh, u), dtype=float)
    if tensors.shape != (mesh.nv, 3):
        raise ValueError(f"ngfracture.fracture.split: the criterion's tensor field must have shape ({mesh.nv}, 3), "
                         f"got {tensors.shape}")
    res = _split_pass(mesh, tensors, 1.0, crack_name)
    return res.mesh, transfer(u, res), res
