"""The crack criterion: which vertices are overstrained, how much, and in which direction.

One object, :class:`Criterion`, holds everything that decides where a crack starts and
grows: a critical strain per material region (regions without one never crack), a
critical distance per region or none, the material whose stress is judged, and, at each
evaluation, an optional critical strain per vertex (a random strength field). It returns
the *overstrain* tensor of every vertex, scaled so that a vertex cracks when its largest
principal value exceeds 1, with the direction across which it opens.

* Without a critical distance (``radius=None``), the paper's criterion: the nodal
  principal strain, averaged over the triangles around the vertex (one ring). It depends
  on the mesh at notches and crack tips, where the strain is singular.
* With a critical distance r: the opening stress over E judged along rays of length r from
  every stress concentration (:func:`nonlocal_opening`, docs/criterion.md); the crack
  initiation load and direction converge under refinement, and the criterion's fracture
  toughness is ``K_c = E critical sqrt(2 pi r)`` (:func:`toughness`).

A vertex takes the smallest critical strain (and the largest critical distance) of the
triangles around it: the weakest material decides.
"""
import math

import numpy as np

from .. import _ngfracture as _ext
from ..geometry.meshio import mesh_to_arrays
from ..mechanics.materials import Material
from ..geometry.solid import solid_to_arrays
from .solid_criterion import overstrain_3d
from .strain import check_mesh_2d, check_positive, element_strain, equivalent_strain, vertex_displacement, vertex_strain

__all__ = ["Criterion", "nonlocal_opening", "toughness", "critical_distance", "select"]


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
    check_mesh_2d(mesh)
    t = np.asarray(element_tensors, dtype=float)
    if t.shape != (mesh.ne, 3):
        raise ValueError(f"ngfracture.fracture.criterion: element tensors must have shape ({mesh.ne}, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("ngfracture.fracture.criterion: element tensors have NaN or inf values")
    if np.ndim(radius) == 0:
        r = np.full(mesh.nv, check_positive(radius, "critical distance"))
    else:
        r = np.asarray(radius, dtype=float)
        if r.shape != (mesh.nv,) or not np.all(np.isfinite(r)):
            raise ValueError(f"ngfracture.fracture.criterion: radius must be a number or {mesh.nv} finite values")
    if isinstance(ndir, bool) or not isinstance(ndir, (int, np.integer)) or ndir < 8:
        raise ValueError(f"ngfracture.fracture.criterion: ndir must be an integer >= 8, got {ndir!r}")
    nodal = _ext.VertexAverage(mesh, t)
    return _ext.CrackNonlocalOpening(mesh, nodal, r, int(ndir))


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
    c = check_positive(critical)
    r = check_positive(radius, "critical distance")
    return check_positive(E, "Young's modulus") * c * math.sqrt(2 * math.pi * r)


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
    c = check_positive(critical)
    k = check_positive(toughness, "toughness")
    return (k / (check_positive(E, "Young's modulus") * c)) ** 2 / (2 * math.pi)


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
    c = check_positive(critical)
    return _ext.CrackSelect(np.asarray(values, dtype=float), c)


def _per_region(value, names, what):
    """{region: value or None} from one value or a dict; unknown regions are an error."""
    if not isinstance(value, dict):
        return dict.fromkeys(names, value)
    unknown = sorted(set(value) - set(names))
    if unknown:
        raise ValueError(f"ngfracture.fracture.criterion: {what} given for region(s) {unknown}, which are "
                         f"not in the mesh; its regions are {sorted(names)}")
    return {n: value.get(n) for n in names}


class Criterion:
    """Where cracks start and grow: critical strain and critical distance per region.

    Parameters
    ----------
    critical : float or dict of str -> float
        Critical principal strain (> 0), or one per material region; a region missing
        from the dict (or given None) never cracks.
    radius : float or dict of str -> float, optional
        Critical distance r (> 0), or one per region; None (everywhere): the paper's
        one-ring nodal strain.
    material : Material or dict of str -> Material, optional
        With a radius: the stress over E of this material is judged (the maximum hoop
        stress rule, :func:`ngfracture.fracture.strain.equivalent_strain`); None: the strain.
    measure : {"green", "linear"}
        Green-Lagrange or small strain.
    ndir : int
        Ray directions of the critical-distance measure (>= 8).

    Raises
    ------
    ValueError
        A critical strain or radius that is not a finite number > 0 (or None), an
        unknown measure, no region that can crack.
    """

    def __init__(self, critical, radius=None, material=None, measure="green", ndir=72):
        for name, value in self._items(critical):
            if value is not None:
                check_positive(value, f"critical strain of region {name!r}" if name else "critical strain")
        if not any(v is not None for _, v in self._items(critical)):
            raise ValueError("ngfracture.fracture.criterion: no region can crack (every critical strain is None)")
        for name, value in self._items(radius):
            if value is not None:
                check_positive(value, f"critical distance of region {name!r}" if name else "critical distance")
        if measure not in ("green", "linear"):
            raise ValueError(f"ngfracture.fracture.criterion: measure must be 'green' or 'linear', got {measure!r}")
        if material is not None and not isinstance(material, (Material, dict)):
            raise ValueError("ngfracture.fracture.criterion: material must be a Material or a dict of them")
        self.critical, self.radius, self.material = critical, radius, material
        self.measure, self.ndir = measure, ndir

    @staticmethod
    def _items(value):
        return value.items() if isinstance(value, dict) else [("", value)]

    @property
    def one_ring(self):
        """True without any critical distance: the paper's mesh-dependent nodal strain."""
        return all(v is None for _, v in self._items(self.radius))

    @property
    def smallest_radius(self):
        """The smallest critical distance of the regions (None: the one-ring criterion)."""
        values = [v for _, v in self._items(self.radius) if v is not None]
        return min(values) if values else None

    def overstrain(self, mesh, u, strength=None, arrays=None):
        """The overstrain tensor of every vertex: a vertex cracks when its largest
        principal value exceeds 1, across the principal direction.

        Parameters
        ----------
        mesh : ngsolve.Mesh
            2D triangle mesh or 3D tetrahedral mesh, reference configuration.
        u : ngsolve.GridFunction or numpy.ndarray
            Displacement (``VectorH1``) or its vertex values (nv, 2) or (nv, 3).
        strength : numpy.ndarray, optional
            Critical strain per vertex; it replaces the region's at the vertices that can
            crack.
        arrays : MeshArrays or SolidArrays, optional
            The mesh as arrays, if the caller has them (else made here).

        Returns
        -------
        numpy.ndarray
            Shape (nv, 3), rows (xx, yy, xy); in 3D (nv, 6), rows (xx, yy, zz, yz, xz, xy);
            zero at vertices that cannot crack.

        Raises
        ------
        ValueError
            A critical strain or radius for a region the mesh does not have, bad fields.
        """
        if mesh.dim == 3:
            return self._overstrain_3d(mesh, u, strength, arrays)
        check_mesh_2d(mesh)
        arrays = mesh_to_arrays(mesh) if arrays is None else arrays
        names = arrays.region_names
        critical = _per_region(self.critical, names, "critical strain")
        inv = np.array([0.0] + [1.0 / critical[n] if critical.get(n) is not None else 0.0 for n in names])
        # a vertex takes the smallest critical strain of its triangles (the weakest material)
        scale = np.zeros(mesh.nv)
        np.maximum.at(scale, arrays.triangles.ravel(), np.repeat(inv[arrays.regions], 3))
        if self.one_ring:
            if strength is not None:
                scale = np.where(scale > 0, 1.0 / strength, 0.0)
            return vertex_strain(mesh, u, self.measure) * scale[:, None]
        strain = element_strain(mesh, u, self.measure)
        if self.material is not None:
            strain = equivalent_strain(mesh, strain, self.material)     # stress / E per triangle
        radii = _per_region(self.radius, names, "critical distance")
        r_region = np.array([0.0] + [radii.get(n) or 0.0 for n in names])
        radius = np.zeros(mesh.nv)
        np.maximum.at(radius, arrays.triangles.ravel(), np.repeat(r_region[arrays.regions], 3))
        tensors = nonlocal_opening(mesh, strain * inv[arrays.regions][:, None], radius * (scale > 0), self.ndir)
        if strength is not None:
            # the vertex's random strength replaces its region's critical strain
            tensors *= np.where(scale > 0, 1.0 / (strength * np.where(scale > 0, scale, 1.0)), 0.0)[:, None]
        return tensors

    def _overstrain_3d(self, mesh, u, strength, arrays):
        """:meth:`overstrain` on a tetrahedral mesh (:func:`.solid_criterion.overstrain_3d`)."""
        arrays = solid_to_arrays(mesh) if arrays is None else arrays
        E = nu = None
        if self.material is not None:      # the stress over E of the material, as in 2D
            m = self.material
            E = {n: v.E for n, v in m.items()} if isinstance(m, dict) else m.E
            nu = {n: v.nu for n, v in m.items()} if isinstance(m, dict) else m.nu
        radius = None if self.one_ring else self.radius
        return overstrain_3d(arrays, vertex_displacement(u), self.critical, radius, E, nu, strength, self.measure)

    def describe(self):
        """What the criterion is, for summaries: kind, critical strains, critical distances.

        Returns
        -------
        dict
            ``kind`` ("critical_distance" or "one_ring"), ``critical``, ``radius`` and, for
            the one-ring criterion, a ``note`` that its cracks depend on the mesh.
        """
        out = {"kind": "one_ring" if self.one_ring else "critical_distance",
               "critical": self.critical, "radius": None if self.one_ring else self.radius}
        if self.one_ring:
            out["note"] = ONE_RING_NOTE
        return out

    def __repr__(self):
        return f"Criterion(critical={self.critical!r}, radius={self.radius!r}, measure={self.measure!r})"


#: why a run with the paper's criterion says so (a warning and summary.json)
ONE_RING_NOTE = ("no critical distance or toughness given: the paper's one-ring nodal strain decides, "
                 "whose crack initiation and extent depend on the mesh (docs/criterion.md)")
