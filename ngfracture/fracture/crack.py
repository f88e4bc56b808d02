"""Crack formation by node splitting (paper section 3), on top of the C++ engine.

One crack pass reads top to bottom::

    tensors = criterion.vertex_tensor(mesh, u)          # nodal strain (or stress)
    values, directions = principal(tensors)             # largest principal value + direction
    order = select(values, criterion.critical)          # overstrained, deterministic order
    result = split_vertices(mesh, order, directions[order])   # split + netgen rebuild
    u_new = transfer(u, result)                         # exact copy through the vertex map

``crack_step`` does all of it; ``split_by_tensor`` starts from a user-supplied vertex
tensor field (hand-made cases, other criteria).

Conventions
-----------
* Splitting happens in the reference configuration. A new vertex is a copy of its parent
  (same coordinates, same field values); triangles keep their number, order, orientation
  and region; only their vertex numbers change. New boundary edges get the boundary name
  ``crack``; existing boundary names and materials survive.
* Nodal strain: the strain of the P1 interpolant of the vertex displacements on every
  triangle, averaged at each vertex with the triangle areas as weights
  (sum |T| E_T / sum |T| over the triangles T around the vertex). For order >= 2 fields the
  element value is the element mean of E(u) (computed by NGSolve), averaged the same way.
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
  flank is often the best edge).
* Rules 1b/2b and "never two pieces joined by a single vertex": after the cut, the far end
  of every cut edge is split if its fan fell apart (it was on the boundary, on a crack face
  or a crack tip). Only the processed vertex and those far ends change their fans.
* Which piece keeps the old vertex number: the fan holding the smallest triangle number.
  New vertices are numbered from nv on, in creation order.
* Fragments: connected components of triangles through shared vertices (the same as
  through shared edges, since no two pieces touch at a single vertex), numbered by their
  smallest triangle.
"""
from dataclasses import dataclass, field
import math
import time

import numpy as np
import ngsolve

from .. import _ngfracture as _C
from ..geometry.meshcheck import validate_mesh
from ..geometry.meshio import ngsolve_mesh

__all__ = [
    "RULE_1", "RULE_1A", "RULE_1B", "RULE_2", "RULE_2A", "RULE_2B", "RULE_2C", "RULE_TIP", "RULE_TIP1",
    "RULE_NONE", "SplitRules", "PAPER_RULES", "GROWTH_RULES",
    "StrainCriterion", "SplitResult", "vertex_displacement", "element_strain", "vertex_strain",
    "equivalent_strain", "nonlocal_opening", "toughness", "critical_distance", "principal",
    "select", "split_vertices", "transfer", "transfer_vertex_field", "split_by_tensor",
    "crack_step", "rule_names",
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

_RULE_NAMES = [(RULE_1, "1"), (RULE_1A, "1a"), (RULE_1B, "1b"), (RULE_2, "2"),
               (RULE_2A, "2a"), (RULE_2B, "2b"), (RULE_TIP, "tip"), (RULE_NONE, "none"), (RULE_2C, "2c"),
               (RULE_TIP1, "tip1")]


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

    Raises
    ------
    ValueError
        An ``enter_angle`` outside [0, pi/2).
    """
    enter_angle: float = 0.0
    single_edge_tips: bool = False

    def __post_init__(self):
        if not (isinstance(self.enter_angle, (int, float)) and 0 <= self.enter_angle < math.pi / 2):
            raise ValueError(f"ngfracture.fracture.crack: enter_angle must be in [0, pi/2) radians, got {self.enter_angle!r}")


PAPER_RULES = SplitRules()
# The critical-distance criterion's: 30 degrees lets a crack along the bisector of a V-notch
# (flank 14 degrees off in the plate) enter the body, and keeps out a crack line along a
# straight boundary, whose interior edges are 45 degrees or more off on netgen's meshes.
GROWTH_RULES = SplitRules(enter_angle=math.radians(30.0), single_edge_tips=True)


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
    return [name for bit, name in _RULE_NAMES if int(flags) & bit]


def _check_critical(critical, what="critical strain"):
    try:
        c = float(critical)
    except (TypeError, ValueError):
        raise ValueError(f"ngfracture.fracture.crack: {what} must be a number, got {critical!r}") from None
    if not math.isfinite(c) or c <= 0:
        raise ValueError(f"ngfracture.fracture.crack: {what} must be finite and > 0, got {critical!r}")
    return c


def _check_mesh(mesh):
    if not isinstance(mesh, ngsolve.Mesh):
        raise TypeError(f"ngfracture.fracture.crack: expected an ngsolve.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2:
        raise ValueError(f"ngfracture.fracture.crack: the mesh must be 2D, it has dimension {mesh.dim}")


def _field_order(gf):
    fes = gf.space
    if not isinstance(fes, ngsolve.VectorH1) or fes.mesh.dim != 2:
        raise TypeError("ngfracture.fracture.crack: the displacement must be a GridFunction on a 2D "
                        f"ngsolve.VectorH1 space, got {type(fes).__name__}")
    return fes.globalorder


def vertex_displacement(u):
    """Vertex values of a displacement field.

    Parameters
    ----------
    u : ngsolve.GridFunction or numpy.ndarray
        A GridFunction on ``VectorH1`` (vertex dofs are nodal values for every order), or an
        array of shape (nv, 2) that is returned as a float copy.

    Returns
    -------
    numpy.ndarray
        Shape (nv, 2).

    Raises
    ------
    TypeError
        If u is neither.
    """
    if isinstance(u, ngsolve.GridFunction):
        _field_order(u)
        nv = u.space.mesh.nv
        v = u.vec.FV().NumPy()
        return v.reshape(2, -1)[:, :nv].T.copy()   # component-blocked dofs, vertices first
    a = np.array(u, dtype=float)
    if a.ndim != 2 or a.shape[1] != 2:
        raise TypeError(f"ngfracture.fracture.crack: vertex displacement must have shape (nv, 2), got {a.shape}")
    return a


def _vertex_values(mesh, u):
    """The displacement's vertex values (nv, 2), checked to fit the mesh and to be finite."""
    U = vertex_displacement(u)
    if U.shape[0] != mesh.nv:
        raise ValueError(f"ngfracture.fracture.crack: displacement has {U.shape[0]} vertex values, "
                         f"the mesh has {mesh.nv} vertices")
    if not np.all(np.isfinite(U)):
        raise ValueError("ngfracture.fracture.crack: displacement has NaN or inf values")
    return U


def element_strain(mesh, u, measure="green"):
    """Strain of every triangle (the P1 gradient, or the element mean for order >= 2).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh (reference configuration).
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement: a ``VectorH1`` GridFunction of any order, or vertex values (nv, 2).
        For order 1 and for arrays the element strain is that of the P1 interpolant of
        the vertex values (C++); for order >= 2 it is the element mean of E(u).
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H)/2 or small strain (H + H^T)/2, H = grad u.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 3), rows (xx, yy, xy).

    Raises
    ------
    ValueError
        Non-2D mesh, unknown measure or a field that does not fit the mesh.
    """
    _check_mesh(mesh)
    if measure not in ("green", "linear"):
        raise ValueError(f"ngfracture.fracture.crack: measure must be 'green' or 'linear', got {measure!r}")
    if isinstance(u, ngsolve.GridFunction) and _field_order(u) > 1:
        if u.space.mesh.nv != mesh.nv or u.space.mesh.ne != mesh.ne:
            raise ValueError("ngfracture.fracture.crack: the displacement lives on another mesh")
        H = ngsolve.Grad(u)
        E = 0.5 * (H + H.trans)
        if measure == "green":
            E = E + 0.5 * H.trans * H
        area = ngsolve.Integrate(ngsolve.CF(1), mesh, element_wise=True).NumPy()
        comps = [E[0, 0], E[1, 1], E[0, 1]]
        return np.column_stack([ngsolve.Integrate(c, mesh, element_wise=True).NumPy() / area
                                for c in comps])
    return _C.CrackElementStrain(mesh, _vertex_values(mesh, u), measure)


def vertex_strain(mesh, u, measure="green"):
    """Nodal strain tensor: area-weighted average of the element strains around each vertex.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh (reference configuration).
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement, see :func:`element_strain`.
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H)/2 or small strain (H + H^T)/2, H = grad u.

    Returns
    -------
    numpy.ndarray
        Shape (nv, 3), rows (xx, yy, xy).

    Raises
    ------
    ValueError
        Non-2D mesh, unknown measure or a field that does not fit the mesh.
    """
    _check_mesh(mesh)
    if isinstance(u, ngsolve.GridFunction) and _field_order(u) > 1:
        return _C.VertexAverage(mesh, element_strain(mesh, u, measure))
    if measure not in ("green", "linear"):
        raise ValueError(f"ngfracture.fracture.crack: measure must be 'green' or 'linear', got {measure!r}")
    return _C.CrackVertexStrain(mesh, _vertex_values(mesh, u), measure)


def equivalent_strain(mesh, strain, material):
    """Stress divided by Young's modulus, per triangle: the strain a uniaxial test would show.

    For a 2D material with Lame parameters (lambda, mu) of its plane reduction,
    ``(lambda tr(E) I + 2 mu E) / E_young``. Under uniaxial stress it equals the principal
    strain along the load, so a critical strain keeps its meaning; its opening component
    is the hoop stress of the maximum-hoop-stress rule (docs/criterion.md). For
    St Venant-Kirchhoff and linear materials this is the (second Piola-Kirchhoff) stress
    over E exactly.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh.
    strain : numpy.ndarray
        Shape (ne, 3), element strains (xx, yy, xy).
    material : Material or dict of str -> Material
        One material, or one per region of the mesh.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 3).

    Raises
    ------
    ValueError
        If a region of the mesh has no material or the shape is wrong.
    """
    e = np.asarray(strain, dtype=float)
    if e.shape != (mesh.ne, 3):
        raise ValueError(f"ngfracture.fracture.crack: element strains must have shape ({mesh.ne}, 3), got {e.shape}")
    names = list(mesh.GetMaterials())
    mats = material if isinstance(material, dict) else {n: material for n in names}
    missing = [n for n in names if n not in mats]
    if missing:
        raise ValueError(f"ngfracture.fracture.crack: no material for regions {missing}")
    region = mesh.ngmesh.Elements2D().NumPy()["index"].astype(int) - 1   # netgen counts regions from 1
    lam = np.array([mats[n].lam / mats[n].E for n in names])[region]
    two_mu = np.array([2 * mats[n].mu / mats[n].E for n in names])[region]
    trace = e[:, 0] + e[:, 1]
    out = two_mu[:, None] * e
    out[:, :2] += (lam * trace)[:, None]
    return out


def nonlocal_opening(mesh, element_tensors, radius, ndir=72):
    """Critical-distance measure of every vertex from element tensors (docs/criterion.md).

    The element tensors are averaged at the vertices (area weights) and interpolated
    linearly; from every vertex, rays of length ``radius`` in ``ndir`` directions are walked
    through the mesh (a ray that meets the boundary or a crack face before its end is judged
    up to it; a direction that points out of the body does not count); a ray's value is the
    smallest opening component n.T.n (n perpendicular to the ray) along it, the vertex's
    value the largest over the rays (refined by a parabola). Only hot spots are judged:
    every sharp tip (a crack tip or a notch tip, corner angle of at least 300 degrees), and
    a vertex with no sharp tip within 27/16 ``radius`` and the largest nodal principal
    value within ``radius``; the others get 0.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration.
    element_tensors : numpy.ndarray
        Shape (ne, 3), rows (xx, yy, xy).
    radius : float or numpy.ndarray
        Critical distance (> 0), or one per vertex (<= 0: the vertex gets 0).
    ndir : int
        Number of ray directions (>= 8).

    Returns
    -------
    numpy.ndarray
        Shape (nv, 3): ``value * n n^T`` per vertex, so :func:`principal` returns the value
        and the opening direction n (the crack runs perpendicular to n).

    Raises
    ------
    ValueError
        Bad shapes, a non-finite radius or field, too few directions.
    """
    _check_mesh(mesh)
    t = np.asarray(element_tensors, dtype=float)
    if t.shape != (mesh.ne, 3):
        raise ValueError(f"ngfracture.fracture.crack: element tensors must have shape ({mesh.ne}, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("ngfracture.fracture.crack: element tensors have NaN or inf values")
    if np.ndim(radius) == 0:
        r = np.full(mesh.nv, _check_critical(radius, "critical distance"))
    else:
        r = np.asarray(radius, dtype=float)
        if r.shape != (mesh.nv,) or not np.all(np.isfinite(r)):
            raise ValueError(f"ngfracture.fracture.crack: radius must be a number or {mesh.nv} finite values")
    if isinstance(ndir, bool) or not isinstance(ndir, (int, np.integer)) or ndir < 8:
        raise ValueError(f"ngfracture.fracture.crack: ndir must be an integer >= 8, got {ndir!r}")
    nodal = _C.VertexAverage(mesh, t)
    return _C.CrackNonlocalOpening(mesh, nodal, r, int(ndir))


def toughness(critical, radius, E):
    """Fracture toughness K_c of the critical-distance criterion: ``E critical sqrt(2 pi radius)``.

    A straight crack under mode I starts to grow when the stress at distance r ahead of its
    tip, ``K_I / sqrt(2 pi r)`` (the singular field), reaches ``E * critical``
    (docs/criterion.md).

    Parameters
    ----------
    critical : float
        Critical strain (> 0).
    radius : float
        Critical distance r (> 0).
    E : float
        Young's modulus (> 0).

    Returns
    -------
    float
        K_c (stress times square root of length).
    """
    c = _check_critical(critical)
    r = _check_critical(radius, "critical distance")
    return _check_critical(E, "Young's modulus") * c * math.sqrt(2 * math.pi * r)


def critical_distance(critical, toughness, E):
    """Critical distance r for a given fracture toughness: ``(K_c / (E critical))^2 / (2 pi)``.

    The inverse of :func:`toughness`.

    Parameters
    ----------
    critical : float
        Critical strain (> 0).
    toughness : float
        K_c (> 0).
    E : float
        Young's modulus (> 0).

    Returns
    -------
    float
        r.
    """
    c = _check_critical(critical)
    k = _check_critical(toughness, "toughness")
    return (k / (_check_critical(E, "Young's modulus") * c)) ** 2 / (2 * math.pi)


def principal(tensors):
    """Largest principal value and its unit direction of symmetric 2x2 tensors.

    Parameters
    ----------
    tensors : numpy.ndarray
        Shape (n, 3), rows (xx, yy, xy).

    Returns
    -------
    values : numpy.ndarray
        Shape (n,).
    directions : numpy.ndarray
        Shape (n, 2), angle in (-pi/2, pi/2]; an isotropic tensor gets (1, 0).

    Raises
    ------
    ValueError
        If tensors is not of shape (n, 3) or holds NaN or inf.
    """
    t = np.asarray(tensors, dtype=float)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"ngfracture.fracture.crack: tensors must have shape (n, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("ngfracture.fracture.crack: tensor field has NaN or inf values")
    return _C.CrackPrincipal(t)


def select(values, critical):
    """Overstrained vertices in processing order.

    Parameters
    ----------
    values : numpy.ndarray
        Principal value per vertex.
    critical : float
        Threshold (> 0): a vertex is overstrained when its value is strictly larger.

    Returns
    -------
    numpy.ndarray
        Vertex numbers by decreasing value, ties by increasing vertex number.

    Raises
    ------
    ValueError
        If critical is not a finite number > 0.
    """
    c = _check_critical(critical)
    return _C.CrackSelect(np.asarray(values, dtype=float), c)


class StrainCriterion:
    """Principal strain above a critical strain: one-ring (the paper's) or critical distance.

    A criterion is any object with ``critical`` and ``vertex_tensor(mesh, u)`` returning a
    symmetric tensor per vertex (rows xx, yy, xy); a stress criterion fits the same slot by
    returning the nodal stress and a critical stress.

    With ``radius=None`` the tensor is the nodal strain (:func:`vertex_strain`), averaged
    over the triangles around the vertex: mesh dependent at notches and crack tips, where
    the strain is singular. With a critical distance ``radius`` it is the nonlocal measure of
    :func:`nonlocal_opening` (docs/criterion.md): the opening strain (or, given a material,
    the opening stress over E) judged along rays of length ``radius``, which gives a
    mesh-independent initiation load and the maximum-hoop-stress crack direction; its
    fracture toughness is :func:`toughness`.

    Parameters
    ----------
    critical : float
        Critical principal strain, finite and > 0.
    measure : {'green', 'linear'}
        Green-Lagrange for the nonlinear models, small strain for the linear one.
    radius : float, optional
        Critical distance r (> 0); None: the one-ring average.
    material : Material or dict of str -> Material, optional
        With a radius: judge the stress over E (:func:`equivalent_strain`) instead of the
        strain, as the maximum hoop stress rule does.
    ndir : int
        Ray directions of the nonlocal measure.

    Raises
    ------
    ValueError
        If critical or radius is not a number > 0 or the measure is unknown.
    """

    def __init__(self, critical, measure="green", radius=None, material=None, ndir=72):
        self.critical = _check_critical(critical)
        if measure not in ("green", "linear"):
            raise ValueError(f"ngfracture.fracture.crack: measure must be 'green' or 'linear', got {measure!r}")
        self.measure = measure
        self.radius = None if radius is None else _check_critical(radius, "critical distance")
        self.material = material
        self.ndir = ndir

    def vertex_tensor(self, mesh, u):
        """Tensor per vertex whose largest principal value is compared with ``critical``.

        Parameters
        ----------
        mesh : ngsolve.Mesh
            2D triangle mesh (reference configuration).
        u : ngsolve.GridFunction or numpy.ndarray
            Displacement (``VectorH1``) or vertex values (nv, 2).

        Returns
        -------
        numpy.ndarray
            Shape (nv, 3), rows (xx, yy, xy): the nodal strain (radius None) or the
            rank-one nonlocal tensor of :func:`nonlocal_opening`.
        """
        if self.radius is None:
            return vertex_strain(mesh, u, self.measure)
        strain = element_strain(mesh, u, self.measure)
        if self.material is not None:
            strain = equivalent_strain(mesh, strain, self.material)
        return nonlocal_opening(mesh, strain, self.radius, self.ndir)

    def __repr__(self):
        return (f"StrainCriterion(critical={self.critical!r}, measure={self.measure!r}, "
                f"radius={self.radius!r})")


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


def split_vertices(mesh, vertices, directions, crack_name="crack", skip_neighbours=False, rules=PAPER_RULES):
    """Split vertices along the edges most orthogonal to given directions (rules 1-2b).

    The mesh itself is not checked here (crack_step and split_by_tensor run
    meshcheck.validate_mesh first); the engine keeps a valid mesh valid.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D mesh of linear triangles, reference configuration.
    vertices : array_like of int
        Vertices to process, in this order (see :func:`select`).
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
    _check_mesh(mesh)
    v = np.ascontiguousarray(vertices, dtype=np.int32).reshape(-1)
    d = np.ascontiguousarray(directions, dtype=float)
    if d.ndim != 2 or d.shape != (len(v), 2):
        raise ValueError(f"ngfracture.fracture.crack: directions must have shape ({len(v)}, 2), got {d.shape}")
    if len(v) and (v.min() < 0 or v.max() >= mesh.nv):
        raise ValueError(f"ngfracture.fracture.crack: vertex numbers must be in [0, {mesh.nv})")
    if len(np.unique(v)) != len(v):
        raise ValueError("ngfracture.fracture.crack: a vertex appears twice in the processing order")
    if not np.all(np.isfinite(d)) or np.any(np.all(d == 0, axis=1)):
        raise ValueError("ngfracture.fracture.crack: directions must be finite and nonzero")
    if not isinstance(rules, SplitRules):
        raise TypeError(f"ngfracture.fracture.crack: rules must be a SplitRules, got {type(rules).__name__}")
    r = _C.CrackSplit(mesh.ngmesh, v, d, crack_name, bool(skip_neighbours), float(rules.enter_angle),
                      bool(rules.single_edge_tips))
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
        raise ValueError(f"ngfracture.fracture.crack: field has {a.shape[0]} rows, the old mesh has "
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
    p = _field_order(u)
    if p > 2:   # refused even when nothing split: the same call must not depend on the data
        raise NotImplementedError("ngfracture.fracture.crack.transfer: order >= 3 is not supported "
                                  "(edge dof orientation changes with the vertex numbers)")
    if result.mesh is u.space.mesh:
        return u                      # nothing was split: the field is already there
    if u.space.mesh.nv != result.record["nv_old"]:
        raise ValueError("ngfracture.fracture.crack.transfer: the field is not on the split mesh")
    fes = ngsolve.VectorH1(result.mesh, order=p)
    gf = ngsolve.GridFunction(fes)
    if p == 1:
        old = u.vec.FV().NumPy().reshape(2, -1)
        gf.vec.FV().NumPy()[:] = old[:, result.parent].reshape(-1)
    else:
        gf.vec.FV().NumPy()[:] = _C.CrackTransferElementDofs(u.space, fes, u.vec.FV().NumPy())
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
    _check_mesh(mesh)
    c = _check_critical(critical)
    t = np.asarray(tensors, dtype=float)
    if t.shape != (mesh.nv, 3):
        raise ValueError(f"ngfracture.fracture.crack: tensor field must have shape ({mesh.nv}, 3), got {t.shape}")
    if check_mesh:
        validate_mesh(mesh)
    return _split_pass(mesh, t, c, crack_name, skip_neighbours, first_only, rules)


def _split_pass(mesh, tensors, critical, crack_name, skip_neighbours=False, first_only=False, rules=PAPER_RULES):
    values, dirs = principal(tensors)
    order = _C.CrackSelect(values, critical)
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
    """One crack pass: nodal strain, overstrained vertices, splitting, field transfer.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The reference mesh u lives on.
    u : ngsolve.GridFunction
        Displacement on ``VectorH1(mesh, order<=2)``.
    critical : float, optional
        Critical principal strain (> 0); ignored when ``criterion`` is given.
    measure : {'green', 'linear'}
        Strain measure for the default :class:`StrainCriterion`.
    criterion : object, optional
        Anything with ``critical`` and ``vertex_tensor(mesh, u)``.
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
    _check_mesh(mesh)
    if criterion is None:
        if critical is None:
            raise ValueError("ngfracture.fracture.crack: give a critical strain or a criterion")
        criterion = StrainCriterion(critical, measure)
    if isinstance(u, ngsolve.GridFunction):
        if _field_order(u) > 2:
            raise NotImplementedError("ngfracture.fracture.crack: displacement order >= 3 is not supported")
        if u.space.mesh.nv != mesh.nv or u.space.mesh.ne != mesh.ne:
            raise ValueError("ngfracture.fracture.crack: the displacement does not live on this mesh")
    else:
        raise TypeError("ngfracture.fracture.crack.crack_step: u must be an ngsolve.GridFunction; "
                        "use split_by_tensor for plain arrays")
    c = _check_critical(criterion.critical)
    validate_mesh(mesh)
    tensors = np.asarray(criterion.vertex_tensor(mesh, u), dtype=float)
    if tensors.shape != (mesh.nv, 3):
        raise ValueError(f"ngfracture.fracture.crack: the criterion's tensor field must have shape ({mesh.nv}, 3), "
                         f"got {tensors.shape}")
    res = _split_pass(mesh, tensors, c, crack_name)
    return res.mesh, transfer(u, res), res
