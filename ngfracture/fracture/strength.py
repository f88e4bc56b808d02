"""Random strength: a critical strain per vertex drawn from a Weibull distribution.

Brittle materials break at flaws whose strength is random. A vertex ``i`` of the
initial mesh gets the critical strain

    s_i = scale_i * (-ln V_i) ** (1 / m),    V_i uniform in (0, 1),

a Weibull variable with modulus ``m`` and scale ``scale_i``: P(s_i <= s) =
1 - exp(-(s / scale_i)^m).

Weakest link (size effect). If a reference area ``A_ref`` of the material fails with
Weibull(m, scale), an area A made of A / A_ref independent such pieces survives a strain
s when all pieces do: P_surv(A, s) = P_surv(A_ref, s)^(A / A_ref) = exp(-(A / A_ref)
(s / scale)^m), again Weibull with modulus m and scale ``scale * (A_ref / A)^(1/m)``.
A vertex stands for its tributary area (a third of the area of the triangles around it
in the regions that can crack), so with a reference area

    scale_i = scale * (A_ref / A_i) ** (1 / m),

and the field is mesh-consistent in the weakest-link sense: the weakest vertex of a
patch has the strength distribution of the patch's whole area. Without a reference
area every vertex has the same scale (no size effect: a finer mesh then has more, and
so weaker, weakest links).

Reproducibility. The uniforms come from the raw 64-bit stream of PCG64 seeded with
``seed`` (``numpy.random.PCG64(seed).random_raw``), which is integer arithmetic defined
by the algorithm, the same on every machine and numpy version: the top 52 bits k give
V = (k + 1/2) 2^-52, exactly representable and strictly inside (0, 1), so no strength is
0 or infinite. One draw per vertex, in the vertex order of the initial mesh. The
transform uses Python's ``math.log`` and ``math.pow`` (the C library, one value at a
time) rather than numpy's vectorised loops, whose SIMD variants depend on the CPU.
:func:`field_digest` gives a SHA-256 of the field's bytes; the scenes record it, so two
runs can be checked to have used the same field.
"""
import hashlib
import math

import numpy as np

from ..geometry.solid import tet_volumes

__all__ = ["weibull_mean", "weibull_variance", "tributary_areas", "weibull_strength", "field_digest",
           "check_weibull"]


def _positive(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def check_weibull(m, scale, seed, reference_area=None):
    """Check the parameters of a Weibull field before any work.

    Parameters
    ----------
    m : float
        Weibull modulus (> 0).
    scale : float
        Scale (> 0), the strength of the reference area at P_f = 1 - 1/e.
    seed : int
        Seed (an integer >= 0).
    reference_area : float, optional
        Reference area of the size effect (> 0).

    Returns
    -------
    (float, float, int, float or None)
        The parameters as numbers.

    Raises
    ------
    ValueError
        Naming the first bad parameter.
    """
    m, scale = _positive("weibull_m", m), _positive("weibull_scale", scale)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer >= 0, got {seed!r}")
    if reference_area is not None:
        reference_area = _positive("weibull_area", reference_area)
    return m, scale, int(seed), reference_area


def weibull_mean(m, scale):
    """Mean of a Weibull(m, scale) variable: scale * Gamma(1 + 1/m).

    Parameters
    ----------
    m, scale : float

    Returns
    -------
    float
    """
    return scale * math.gamma(1 + 1 / m)


def weibull_variance(m, scale):
    """Variance of a Weibull(m, scale) variable: scale^2 (Gamma(1 + 2/m) - Gamma(1 + 1/m)^2).

    Parameters
    ----------
    m, scale : float

    Returns
    -------
    float
    """
    return scale ** 2 * (math.gamma(1 + 2 / m) - math.gamma(1 + 1 / m) ** 2)


def tributary_areas(arrays, regions=None):
    """A third of the area of the triangles around each vertex (3D: a quarter of the volume
    of the tetrahedra; the size effect's areas are then volumes).

    Parameters
    ----------
    arrays : ngfracture.geometry.meshio.MeshArrays or SolidArrays
    regions : iterable of str, optional
        Count only the triangles (tetrahedra) of these material regions (default all).

    Returns
    -------
    numpy.ndarray, shape (nv,)
        0 for a vertex without a counted triangle.
    """
    p = arrays.points
    if arrays.dim == 3:
        t = arrays.tets
        area = np.abs(tet_volumes(p, t))
    else:
        t = arrays.triangles
        d1, d2 = p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]
        area = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    if regions is not None:
        wanted = [i for i, n in enumerate(arrays.region_names, start=1) if n in set(regions)]
        area = np.where(np.isin(arrays.regions, wanted), area, 0.0)
    out = np.zeros(len(p))
    k = t.shape[1]
    np.add.at(out, t.ravel(), np.repeat(area / k, k))    # unbuffered, in index order: deterministic
    return out


def weibull_strength(n, m, scale, seed, areas=None, reference_area=None):
    """Draw n Weibull strengths, one per vertex, in vertex order.

    Parameters
    ----------
    n : int
        Number of vertices.
    m : float
        Weibull modulus (> 0).
    scale : float
        Scale of the reference area (> 0).
    seed : int
        Seed of the PCG64 stream (>= 0).
    areas : numpy.ndarray, shape (n,), optional
        Tributary area of every vertex; needed with ``reference_area``. A vertex of area
        0 (no triangle that can crack) gets the reference scale; it never cracks anyway.
    reference_area : float, optional
        Area whose strength has scale ``scale`` (see the module docstring); None: no size
        effect.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Finite strengths > 0.

    Raises
    ------
    ValueError
        A bad parameter, or areas of the wrong shape.
    """
    m, scale, seed, reference_area = check_weibull(m, scale, seed, reference_area)
    raw = np.random.PCG64(seed).random_raw(int(n))
    v = ((raw >> np.uint64(12)).astype(np.float64) + 0.5) * 2.0 ** -52   # exact, in (0, 1)
    inv_m = 1.0 / m
    scales = np.full(int(n), scale)
    if reference_area is not None:
        a = np.asarray(areas, dtype=float) if areas is not None else None
        if a is None or a.shape != (int(n),):
            raise ValueError(f"weibull_strength: a reference area needs the tributary area of all {n} vertices")
        scales = np.array([scale * math.pow(reference_area / ai, inv_m) if ai > 0 else scale for ai in a.tolist()])
    return np.array([si * math.pow(-math.log(vi), inv_m) for si, vi in zip(scales.tolist(), v.tolist())])


def field_digest(values):
    """SHA-256 (hex, first 16 characters) of a float64 field's bytes.

    Parameters
    ----------
    values : numpy.ndarray

    Returns
    -------
    str
    """
    return hashlib.sha256(np.ascontiguousarray(values, dtype=np.float64).tobytes()).hexdigest()[:16]


def scene_strength(mesh, regions, critical, weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """The strength field of a scene and the parameters that describe it.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The scene's initial mesh.
    regions : list of str
        The material regions that can crack (their triangles make the tributary areas).
    critical : float
        The uniform critical strain, the default mean strength.
    weibull_m : float, optional
        Weibull modulus; None: uniform strength ``critical`` (no field).
    weibull_scale : float, optional
        Scale at the reference area; default ``critical / Gamma(1 + 1/m)``, so that the
        mean strength (of the reference area) is the uniform critical strain.
    weibull_area : float, optional
        Reference area of the size effect; None: none.
    seed : int, optional
        Seed of the field (default 0).

    Returns
    -------
    (numpy.ndarray or None, dict)
        The critical strain per vertex of ``mesh`` (None: uniform), and the parameters
        for summary.json: weibull_m, weibull_scale, weibull_area, seed, strength_min,
        strength_mean and strength_digest (:func:`field_digest`).

    Raises
    ------
    ValueError
        A bad parameter, or Weibull parameters or a seed without ``weibull_m``.
    """
    if weibull_m is None:
        given = [k for k, v in (("weibull_scale", weibull_scale), ("weibull_area", weibull_area),
                                ("seed", seed)) if v is not None]
        if given:
            raise ValueError(f"{given[0]} has no effect without weibull_m (the strength is uniform); "
                             f"set weibull_m to draw a random strength")
        return None, {}
    m = _positive("weibull_m", weibull_m)
    scale = critical / math.gamma(1 + 1 / m) if weibull_scale is None else weibull_scale
    seed = 0 if seed is None else seed
    m, scale, seed, area = check_weibull(m, scale, seed, weibull_area)
    from ..geometry.meshio import mesh_to_arrays
    arrays = mesh_to_arrays(mesh)
    areas = tributary_areas(arrays, regions)
    field = weibull_strength(len(arrays.points), m, scale, seed, areas, area)
    cracking = areas > 0
    return field, {"weibull_m": m, "weibull_scale": scale, "weibull_area": area, "seed": seed,
                   "strength_min": float(field[cracking].min()), "strength_mean": float(field[cracking].mean()),
                   "strength_digest": field_digest(field)}
