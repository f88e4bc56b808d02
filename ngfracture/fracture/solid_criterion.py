"""The crack criterion on tetrahedral meshes: strain, stress over E and the critical-distance measure.

The 3D counterpart of :mod:`ngfracture.fracture.strain` and :mod:`ngfracture.fracture.criterion`
for meshes given as :class:`ngfracture.geometry.solid.SolidArrays`. Symmetric tensors are rows
of 6 components ``(xx, yy, zz, yz, xz, xy)`` (tensor, not engineering, shear).

* :func:`tet_strain`: the strain of the P1 interpolant of vertex displacements, per tet.
* :func:`stress_over_E`: 3D Hooke's stress divided by Young's modulus (the strain a uniaxial
  test would show; its opening component is the maximum hoop stress rule's).
* :func:`nonlocal_opening_3d`: the critical-distance measure (docs/solid.md, "The criterion
  in 3D"): from every hot spot, rays of length r walked through the tets; a sharp vertex (a
  crack or notch front, :func:`sharp_vertices_3d`) casts its rays in the plane normal to its
  front, so that r is measured from the front as in 2D; any other hot spot over the sphere.
* :func:`overstrain_3d`: :meth:`ngfracture.fracture.criterion.Criterion.overstrain` in 3D:
  a vertex cracks when its largest principal value exceeds 1, across its direction.

The loops over tets and vertices run in C++ (``cpp_ext/nonlocal_strain3d.cpp``); the element
strain is vectorised numpy.
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.spatial import cKDTree

from .. import _ngfracture as _ext
from ..geometry.solid import SolidArrays
from .strain import check_positive

__all__ = ["NDIR", "NPLANE", "tet_strain", "stress_over_E", "principal_3d", "sharp_vertices_3d",
           "nonlocal_opening_3d", "front_directions_3d", "overstrain_3d"]

#: ray directions over the sphere (Fibonacci set) of a hot spot that is not sharp (docs/solid.md)
NDIR = 256
#: ray directions in the plane normal to the front of a sharp vertex (the 2D criterion's 72)
NPLANE = 72

_WHO = "ngfracture.fracture.solid_criterion"


def _mesh(arrays):
    """points (nv, 3) float and tets (ne, 4) int32 of SolidArrays, checked."""
    if not isinstance(arrays, SolidArrays):
        raise ValueError(f"{_WHO}: expected SolidArrays, got {type(arrays).__name__}")
    pts = np.ascontiguousarray(arrays.points, dtype=float)
    tets = np.asarray(arrays.tets)
    if pts.ndim != 2 or pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
        raise ValueError(f"{_WHO}: points must be a finite (nv, 3) array, got shape {pts.shape}")
    if tets.ndim != 2 or tets.shape[1] != 4 or tets.size == 0:
        raise ValueError(f"{_WHO}: tets must be a non-empty (ne, 4) array, got shape {tets.shape}")
    if tets.min() < 0 or tets.max() >= len(pts):
        raise ValueError(f"{_WHO}: tet vertex numbers must lie in [0, {len(pts)})")
    return pts, np.ascontiguousarray(tets, dtype=np.int32)


def _voigt(M):
    """(n, 3, 3) symmetric -> (n, 6) rows (xx, yy, zz, yz, xz, xy)."""
    return np.stack([M[:, 0, 0], M[:, 1, 1], M[:, 2, 2], M[:, 1, 2], M[:, 0, 2], M[:, 0, 1]], axis=1)


def _matrix(t):
    """(n, 6) -> (n, 3, 3) symmetric."""
    xx, yy, zz, yz, xz, xy = t.T
    return np.stack([np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1), np.stack([xz, yz, zz], -1)], 1)


def tet_strain(arrays, u_vertex, measure="green"):
    """Strain of every tet: that of the P1 interpolant of the vertex displacements.

    Parameters
    ----------
    arrays : SolidArrays
        The mesh (reference configuration).
    u_vertex : numpy.ndarray
        Shape (nv, 3), vertex displacements.
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H)/2 or small strain (H + H^T)/2, H = grad u.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 6), rows (xx, yy, zz, yz, xz, xy).

    Raises
    ------
    ValueError
        Unknown measure, a displacement that does not fit the mesh or is not finite, a
        degenerate tet.
    """
    pts, tets = _mesh(arrays)
    if measure not in ("green", "linear"):
        raise ValueError(f"{_WHO}: measure must be 'green' or 'linear', got {measure!r}")
    u = np.asarray(u_vertex, dtype=float)
    if u.shape != pts.shape or not np.all(np.isfinite(u)):
        raise ValueError(f"{_WHO}: u_vertex must be a finite array of shape {pts.shape}, got {u.shape}")
    X, U = pts[tets], u[tets]
    D = (X[:, 1:] - X[:, :1]).transpose(0, 2, 1)        # columns x_i - x_0
    G = (U[:, 1:] - U[:, :1]).transpose(0, 2, 1)
    det = np.linalg.det(D)
    if not np.all(det > 0):
        raise ValueError(f"{_WHO}: tet {int(np.flatnonzero(~(det > 0))[0])} is degenerate or inverted")
    H = np.linalg.solve(D.transpose(0, 2, 1), G.transpose(0, 2, 1)).transpose(0, 2, 1)   # H D = G
    E = 0.5 * (H + H.transpose(0, 2, 1))
    if measure == "green":
        E = E + 0.5 * np.einsum("nki,nkj->nij", H, H)
    return _voigt(E)


def stress_over_E(strain, E, nu):
    """3D Hooke's stress divided by Young's modulus: ``(lambda tr(e) I + 2 mu e) / E``.

    Under uniaxial stress it equals the strain along the load, so a critical strain keeps its
    meaning (docs/criterion.md). E cancels; it is checked and may differ per element.

    Parameters
    ----------
    strain : numpy.ndarray
        Shape (ne, 6), rows (xx, yy, zz, yz, xz, xy).
    E : float or numpy.ndarray
        Young's modulus (> 0), one or one per element.
    nu : float or numpy.ndarray
        Poisson's ratio in (-1, 0.5), one or one per element.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 6).

    Raises
    ------
    ValueError
        Bad shapes, E <= 0, nu out of (-1, 0.5), values that are not finite.
    """
    e = np.asarray(strain, dtype=float)
    if e.ndim != 2 or e.shape[1] != 6 or not np.all(np.isfinite(e)):
        raise ValueError(f"{_WHO}: strain must be a finite (ne, 6) array, got shape {e.shape}")
    Ev = np.broadcast_to(np.asarray(E, dtype=float), (len(e),)) if np.ndim(E) <= 1 else None
    nuv = np.broadcast_to(np.asarray(nu, dtype=float), (len(e),)) if np.ndim(nu) <= 1 else None
    if Ev is None or np.ndim(E) == 1 and np.shape(E) != (len(e),) or not np.all(Ev > 0) or not np.all(np.isfinite(Ev)):
        raise ValueError(f"{_WHO}: E must be > 0, one value or one per element ({len(e)}), got {E!r}")
    if nuv is None or np.ndim(nu) == 1 and np.shape(nu) != (len(e),) or not np.all((nuv > -1) & (nuv < 0.5)):
        raise ValueError(f"{_WHO}: nu must lie in (-1, 0.5), one value or one per element ({len(e)}), got {nu!r}")
    lam = nuv / ((1 + nuv) * (1 - 2 * nuv))          # lambda / E
    two_mu = 1 / (1 + nuv)                           # 2 mu / E
    out = two_mu[:, None] * e
    out[:, :3] += (lam * e[:, :3].sum(axis=1))[:, None]
    return out


def principal_3d(tensors):
    """Largest principal value and its unit direction of symmetric 3x3 tensors.

    Parameters
    ----------
    tensors : numpy.ndarray
        Shape (n, 6), rows (xx, yy, zz, yz, xz, xy).

    Returns
    -------
    values : numpy.ndarray
        Shape (n,).
    directions : numpy.ndarray
        Shape (n, 3), unit vectors whose component of largest magnitude is positive (the
        first of equal ones).

    Raises
    ------
    ValueError
        If tensors is not of shape (n, 6) or holds NaN or inf.
    """
    t = np.asarray(tensors, dtype=float)
    if t.ndim != 2 or t.shape[1] != 6 or not np.all(np.isfinite(t)):
        raise ValueError(f"{_WHO}: tensors must be a finite (n, 6) array, got shape {t.shape}")
    w, v = np.linalg.eigh(_matrix(t))
    values, dirs = w[:, -1], v[:, :, -1]
    big = np.argmax(np.abs(dirs), axis=1)
    dirs = dirs * np.where(dirs[np.arange(len(dirs)), big] < 0, -1.0, 1.0)[:, None]
    return values, dirs


def sharp_vertices_3d(arrays):
    """The sharp vertices: on a boundary edge whose inside dihedral angle is at least 260 degrees.

    A crack front edge (the two lips meet there; its tets' dihedral angles sum to 360
    degrees), a sharp notch front and a re-entrant edge of 270 degrees or more (a slot's
    root corners); the stress concentrations from which the critical distance is measured
    (docs/solid.md, "Convergence of initiation in 3D").

    Parameters
    ----------
    arrays : SolidArrays
        The mesh; crack lips are separate boundary faces (their vertices are copies).

    Returns
    -------
    numpy.ndarray of int
        Vertex numbers, increasing.

    Raises
    ------
    ValueError
        A mesh that is not SolidArrays or has bad shapes, a tet that is not positively
        oriented, a face shared by three tets.
    """
    pts, tets = _mesh(arrays)
    try:
        vertices, _ = _ext.SolidSharpVertices(pts, tets)
    except RuntimeError as err:
        raise ValueError(str(err)) from None
    return vertices.astype(np.int64)


def _radius_per_vertex(radius, nv):
    if np.ndim(radius) == 0:
        return np.full(nv, check_positive(radius, "critical distance"))
    r = np.asarray(radius, dtype=float)
    if r.shape != (nv,) or not np.all(np.isfinite(r)):
        raise ValueError(f"{_WHO}: radius must be a number or {nv} finite values")
    return r


def _check_count(value, name):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 8:
        raise ValueError(f"{_WHO}: {name} must be an integer >= 8, got {value!r}")
    return int(value)


def nonlocal_opening_3d(arrays, element_tensors, radius, ndir=NDIR, nplane=NPLANE):
    """Critical-distance measure of every vertex from element tensors (docs/solid.md).

    The element tensors are averaged at the vertices (volume weights) and interpolated
    linearly. From every hot spot, rays of length ``radius`` are walked through the tets (a
    boundary face, e.g. a crack lip, ends a ray; a direction pointing out of the body does
    not count); a ray's opening direction n is the largest eigenvector of the tensor at its
    end point restricted to the plane normal to the ray, its value the smallest n.T.n along
    it, the vertex's value the largest over its rays (the best refined once towards the
    plane normal to its end point's principal direction). A sharp vertex casts ``nplane``
    rays in the plane normal to its front and is always judged, looking on to 2 r (thin
    sections are judged over their near half); a vertex with no sharp vertex within
    27/16 ``radius`` and the largest nodal principal value within ``radius`` casts ``ndir``
    rays over the sphere; the others get 0. The sharp vertices within ``radius`` of each
    other share one opening direction (:func:`front_directions_3d`).

    Parameters
    ----------
    arrays : SolidArrays
        The mesh (reference configuration).
    element_tensors : numpy.ndarray
        Shape (ne, 6), rows (xx, yy, zz, yz, xz, xy).
    radius : float or numpy.ndarray
        Critical distance (> 0), or one per vertex (<= 0: the vertex gets 0).
    ndir : int
        Directions over the sphere (>= 8).
    nplane : int
        Directions in a front's normal plane (>= 8).

    Returns
    -------
    numpy.ndarray
        Shape (nv, 6): ``value * n n^T`` per vertex; :func:`principal_3d` returns the value
        and the opening direction n.

    Raises
    ------
    ValueError
        Bad shapes, non-finite values, too few directions, a tet that is not positively
        oriented.
    """
    pts, tets = _mesh(arrays)
    t = np.ascontiguousarray(element_tensors, dtype=float)
    if t.shape != (len(tets), 6) or not np.all(np.isfinite(t)):
        raise ValueError(f"{_WHO}: element tensors must be a finite array of shape ({len(tets)}, 6), got {t.shape}")
    r = _radius_per_vertex(radius, len(pts))
    ndir, nplane = _check_count(ndir, "ndir"), _check_count(nplane, "nplane")
    nodal = _ext.SolidVertexAverage(pts, tets, t)
    try:
        tensors = _ext.SolidNonlocalOpening(pts, tets, nodal, r, ndir, nplane)
        sharp, _ = _ext.SolidSharpVertices(pts, tets)
    except RuntimeError as err:
        raise ValueError(str(err)) from None
    return front_directions_3d(pts, tensors, np.asarray(sharp, dtype=np.int64), r)


def front_directions_3d(points, tensors, sharp, radius):
    """The opening direction of a front, common to its sharp vertices within the critical distance.

    A sharp vertex keeps its value and takes as opening direction the principal direction
    of the sum of the tensors ``max(value, 0) n n^T`` of the sharp vertices within its
    ``radius`` (Euclidean distance, itself included). The measure's direction at one front
    vertex is that of a flat maximum (the hoop stress is flat about the crack plane) and
    scatters by 10 to 20 degrees from vertex to vertex, up to 60; split across these
    directions, a front advances in facets tilted against each other that fold over the
    crack (docs/solid.md, "Crack passes in 3D"). The direction in which a front opens
    varies along it on the scale of the critical distance, as the stress that opens it.

    Parameters
    ----------
    points : numpy.ndarray
        Shape (nv, 3).
    tensors : numpy.ndarray
        Shape (nv, 6), ``value * n n^T`` per vertex (rows xx, yy, zz, yz, xz, xy).
    sharp : numpy.ndarray of int
        The sharp vertices (:func:`sharp_vertices_3d`).
    radius : numpy.ndarray
        Shape (nv,), the critical distance per vertex.

    Returns
    -------
    numpy.ndarray
        Shape (nv, 6): the tensors, those of the sharp vertices with a value > 0 turned to
        the common direction.

    Raises
    ------
    ValueError
        Bad shapes or vertex numbers.
    """
    pts = np.asarray(points, dtype=float)
    t = np.array(tensors, dtype=float)
    sharp = np.asarray(sharp, dtype=np.int64)
    r = np.asarray(radius, dtype=float)
    if t.shape != (len(pts), 6) or r.shape != (len(pts),) or (len(sharp) and (sharp.min() < 0 or sharp.max() >= len(pts))):
        raise ValueError(f"{_WHO}: front_directions_3d needs tensors ({len(pts)}, 6), radius ({len(pts)},) and "
                         f"sharp vertices in [0, {len(pts)})")
    if len(sharp) < 2:
        return t
    values, dirs = principal_3d(t[sharp])
    w = np.maximum(values, 0.0)
    tree = cKDTree(pts[sharp])
    pairs = tree.query_pairs(float(r[sharp].max()), output_type="ndarray").reshape(-1, 2)
    d = np.linalg.norm(pts[sharp][pairs[:, 0]] - pts[sharp][pairs[:, 1]], axis=1)
    k = np.arange(len(sharp))
    rows = np.concatenate([k, pairs[:, 0], pairs[:, 1]])
    cols = np.concatenate([k, pairs[:, 1], pairs[:, 0]])
    near = np.concatenate([np.ones(len(k), bool), d <= r[sharp][pairs[:, 0]], d <= r[sharp][pairs[:, 1]]])
    A = coo_matrix((np.ones(int(near.sum())), (rows[near], cols[near])), shape=(len(k), len(k))).tocsr()
    total = A @ (w[:, None] * _voigt(np.einsum("ki,kj->kij", dirs, dirs)))
    _, common = principal_3d(total)
    turn = values > 0
    t[sharp[turn]] = values[turn, None] * _voigt(np.einsum("ki,kj->kij", common[turn], common[turn]))
    return t


def _per_region(value, arrays, what, optional):
    """One value per region (index 0 unused) from a number or a dict region name -> value."""
    names = arrays.region_names
    if isinstance(value, dict):
        unknown = sorted(set(value) - set(names))
        if unknown:
            raise ValueError(f"{_WHO}: {what} given for region(s) {unknown}, which are not in the mesh; "
                             f"its regions are {sorted(names)}")
        values = [value.get(n) for n in names]
    else:
        values = [value] * len(names)
    out = np.zeros(len(names) + 1)
    for i, (n, v) in enumerate(zip(names, values), start=1):
        if v is None and optional:
            continue
        out[i] = check_positive(v, f"{what} of region {n!r}")
    return out


def _vertex_max(arrays, per_tet):
    out = np.zeros(len(arrays.points))
    np.maximum.at(out, np.asarray(arrays.tets).ravel(), np.repeat(per_tet, 4))
    return out


def _material(value, arrays, what):
    """E or nu per element from a number, a dict region -> value or an (ne,) array."""
    if isinstance(value, dict):
        missing = [n for n in arrays.region_names if value.get(n) is None]
        if missing:
            raise ValueError(f"{_WHO}: no {what} for region(s) {missing}")
        per_region = np.array([0.0] + [float(value[n]) for n in arrays.region_names])
        return per_region[np.asarray(arrays.regions)]
    return value


def overstrain_3d(arrays, u_vertex, critical, radius=None, E=None, nu=None, strength=None, measure="green"):
    """The overstrain tensor of every vertex: it cracks where the largest principal value exceeds 1.

    The 3D :meth:`ngfracture.fracture.criterion.Criterion.overstrain`. A vertex takes the
    smallest critical strain and the largest critical distance of its tets. Without a radius,
    the paper's one-ring nodal strain (volume-weighted mean of its tets' strains); with one,
    the critical-distance measure :func:`nonlocal_opening_3d` of the strain, or of the stress
    over E when E and nu are given.

    Parameters
    ----------
    arrays : SolidArrays
        The mesh (reference configuration).
    u_vertex : numpy.ndarray
        Shape (nv, 3), vertex displacements.
    critical : float or dict of str -> float
        Critical strain (> 0), or one per region (a region missing or None never cracks).
    radius : float or dict of str -> float, optional
        Critical distance (> 0), or one per region; None: the one-ring nodal strain.
    E, nu : float, dict of str -> float or numpy.ndarray, optional
        Young's modulus and Poisson's ratio (one, per region or per tet): judge the stress
        over E instead of the strain (both or neither).
    strength : numpy.ndarray, optional
        Critical strain per vertex (> 0); it replaces the regions' at the vertices that can
        crack.
    measure : {'green', 'linear'}
        Strain measure.

    Returns
    -------
    numpy.ndarray
        Shape (nv, 6), rows (xx, yy, zz, yz, xz, xy); zero at vertices that cannot crack.

    Raises
    ------
    ValueError
        Values for unknown regions, a critical strain or radius that is not > 0, E without
        nu (or the reverse), bad fields.
    """
    pts, tets = _mesh(arrays)
    regions = np.asarray(arrays.regions)
    inv_region = _per_region(critical, arrays, "critical strain", optional=True)
    inv_region[inv_region > 0] = 1.0 / inv_region[inv_region > 0]
    if not np.any(inv_region > 0):
        raise ValueError(f"{_WHO}: no region can crack (every critical strain is None)")
    scale = _vertex_max(arrays, inv_region[regions])         # 1 / the smallest critical strain
    if strength is not None:
        s = np.asarray(strength, dtype=float)
        if s.shape != (len(pts),) or not np.all(np.isfinite(s)) or not np.all(s > 0):
            raise ValueError(f"{_WHO}: strength must be {len(pts)} finite values > 0")
        vertex_scale = np.where(scale > 0, 1.0 / s, 0.0)
    else:
        vertex_scale = scale
    if (E is None) != (nu is None):
        raise ValueError(f"{_WHO}: give both E and nu, or neither")
    strain = tet_strain(arrays, u_vertex, measure)
    if radius is None:
        return _ext.SolidVertexAverage(pts, tets, strain) * vertex_scale[:, None]
    if E is not None:
        strain = stress_over_E(strain, _material(E, arrays, "E"), _material(nu, arrays, "nu"))
    r_vertex = _vertex_max(arrays, _per_region(radius, arrays, "critical distance", optional=True)[regions])
    tensors = nonlocal_opening_3d(arrays, strain * inv_region[regions][:, None], r_vertex * (scale > 0))
    if strength is not None:
        tensors *= np.where(scale > 0, vertex_scale / np.where(scale > 0, scale, 1.0), 0.0)[:, None]
    return tensors
