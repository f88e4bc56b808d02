"""Hyperelastic materials, as strain-energy densities for NGSolve.

Every material maps the displacement gradient ``H = grad u`` (a 2x2
CoefficientFunction, 3x3 on a 3D mesh) to a strain-energy density per unit reference
area (unit thickness; per unit volume in 3D).  NGSolve differentiates the energy twice,
which gives the residual and the consistent tangent of the Newton solver.  On a 3D mesh
the material is the 3D one: plane strain's Lame parameters are the 3D ones, plane stress
is refused.

Plane strain uses the Lame parameters of the 3D material.  Plane stress uses
``lambda* = 2 lambda mu / (lambda + 2 mu)``: exact for the linear and the
St Venant-Kirchhoff models (their stress is linear in the strain, so the
condition S33 = 0 eliminates E33 exactly); for neo-Hooke it is the usual
reduction that is exact in the small-strain limit (documented choice: the
exact plane-stress neo-Hooke needs a local solve for F33).
"""
import math
import numbers

import ngsolve as ng

PLANES = ("strain", "stress")


def lame_parameters(E, nu, plane="strain"):
    """Lame parameters (lambda, mu) of a 2D model from Young's modulus and Poisson's ratio.

    Parameters
    ----------
    E : float
        Young's modulus, finite and > 0.
    nu : float
        Poisson's ratio, finite, -1 < nu < 0.5.
    plane : {"strain", "stress"}
        The 2D reduction.

    Returns
    -------
    (float, float)
        lambda and mu of the 2D model.

    Raises
    ------
    ValueError
        If a parameter is not finite or out of range, or plane is unknown.
    """
    for name, value in (("E", E), ("nu", nu)):
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ValueError(f"material parameter {name} must be a number, got {value!r}")
        if not math.isfinite(value):
            raise ValueError(f"material parameter {name} must be finite, got {value!r}")
    if E <= 0:
        raise ValueError(f"Young's modulus E must be > 0, got {E!r}")
    if not -1.0 < nu < 0.5:
        raise ValueError(f"Poisson's ratio nu must satisfy -1 < nu < 0.5, got {nu!r}")
    if plane not in PLANES:
        raise ValueError(f"plane must be one of {PLANES}, got {plane!r}")
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    return lam, mu


def green_lagrange(H):
    """Green-Lagrange strain (H + H^T + H^T H)/2; this form keeps digits at tiny strains.

    Parameters
    ----------
    H : ngsolve.CoefficientFunction
        Displacement gradient grad u, 2x2.

    Returns
    -------
    ngsolve.CoefficientFunction
        The symmetric 2x2 strain E = (F^T F - I)/2 with F = I + H.
    """
    return 0.5 * (H + H.trans + H.trans * H)


def small_strain(H):
    """Linearised strain (H + H^T)/2.

    Parameters
    ----------
    H : ngsolve.CoefficientFunction
        Displacement gradient grad u, 2x2.

    Returns
    -------
    ngsolve.CoefficientFunction
        The symmetric 2x2 small strain.
    """
    return 0.5 * (H + H.trans)


class Material:
    """Base class: a 2D hyperelastic material with validated parameters.

    Parameters
    ----------
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio (-1 < nu < 0.5).
    plane : {"strain", "stress"}
        2D reduction, plane strain by default.

    Raises
    ------
    ValueError
        On NaN/inf values, E <= 0, nu out of (-1, 0.5) or an unknown plane.
    """

    #: name used in outputs and on the command line
    name = "material"
    #: False for the linear model: it has no notion of an inverted element
    geometrically_nonlinear = True
    #: the law's number in the C++ internal-force kernel (``_ngfracture.InternalForces``);
    #: None: the residual comes from NGSolve's Apply of the energy (a user's own law)
    kernel = None

    def __init__(self, E, nu, plane="strain"):
        self.lam, self.mu = lame_parameters(E, nu, plane)
        self.E, self.nu, self.plane = float(E), float(nu), plane

    def __repr__(self):
        return f"{type(self).__name__}(E={self.E!r}, nu={self.nu!r}, plane={self.plane!r})"

    def strain(self, H):
        """The strain measure of the model (Green-Lagrange unless linear).

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Symmetric 2x2 strain.
        """
        return green_lagrange(H)

    def energy(self, H):
        """Strain-energy density as a CoefficientFunction of H = grad u.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2 (a trial function's gradient for assembly).

        Returns
        -------
        ngsolve.CoefficientFunction
            Scalar energy per unit reference area (unit thickness).

        Raises
        ------
        NotImplementedError
            Always, in the base class: every model defines its energy.
        """
        raise NotImplementedError

    def first_piola(self, H):
        """First Piola-Kirchhoff stress P = dW/dF.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            2x2 stress (force per unit reference length, unit thickness).

        Raises
        ------
        NotImplementedError
            Always, in the base class: every model defines its stress.
        """
        raise NotImplementedError

    def cauchy_stress(self, H):
        """Cauchy stress sigma = P F^T / det F (equal to P for the linear model).

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Symmetric 2x2 true stress in the current configuration.
        """
        F = ng.Id(H.dims[0]) + H
        return (1.0 / ng.Det(F)) * self.first_piola(H) * F.trans


class LinearElastic(Material):
    """Linear (small-strain) elasticity: W = mu eps:eps + lambda/2 (tr eps)^2.

    Not objective: a large rigid rotation produces strain.

    Parameters
    ----------
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio (-1 < nu < 0.5).
    plane : {"strain", "stress"}
        2D reduction, plane strain by default.

    Raises
    ------
    ValueError
        On NaN/inf values, E <= 0, nu out of (-1, 0.5) or an unknown plane.
    """

    name = "linear"
    geometrically_nonlinear = False
    kernel = 0

    def strain(self, H):
        """The small strain (H + H^T)/2.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Symmetric 2x2 strain.
        """
        return small_strain(H)

    def energy(self, H):
        """Strain-energy density mu eps:eps + lambda/2 (tr eps)^2.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Scalar energy per unit reference area.
        """
        eps = small_strain(H)
        return self.mu * ng.InnerProduct(eps, eps) + 0.5 * self.lam * ng.Trace(eps) ** 2

    def first_piola(self, H):
        """Stress 2 mu eps + lambda tr(eps) I (no distinction of stress measures).

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            2x2 stress.
        """
        eps = small_strain(H)
        return 2 * self.mu * eps + self.lam * ng.Trace(eps) * ng.Id(H.dims[0])

    def cauchy_stress(self, H):
        """The linear stress, the same as :meth:`first_piola` (no division by det F).

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Symmetric 2x2 stress.
        """
        return self.first_piola(H)


class StVenantKirchhoff(Material):
    """St Venant-Kirchhoff: W = mu E:E + lambda/2 (tr E)^2 with the Green-Lagrange strain E.

    Parameters
    ----------
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio (-1 < nu < 0.5).
    plane : {"strain", "stress"}
        2D reduction, plane strain by default.

    Raises
    ------
    ValueError
        On NaN/inf values, E <= 0, nu out of (-1, 0.5) or an unknown plane.
    """

    name = "svk"
    kernel = 1

    def energy(self, H):
        """Strain-energy density mu E:E + lambda/2 (tr E)^2.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Scalar energy per unit reference area.
        """
        Egl = green_lagrange(H)
        return self.mu * ng.InnerProduct(Egl, Egl) + 0.5 * self.lam * ng.Trace(Egl) ** 2

    def first_piola(self, H):
        """First Piola-Kirchhoff stress P = F S, S = 2 mu E + lambda tr(E) I.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            2x2 stress per unit reference length.
        """
        Egl = green_lagrange(H)
        S = 2 * self.mu * Egl + self.lam * ng.Trace(Egl) * ng.Id(H.dims[0])
        return (ng.Id(H.dims[0]) + H) * S


class NeoHookean(Material):
    """Compressible neo-Hooke: W = mu/2 (tr C - 2) - mu ln J + lambda/2 (ln J)^2.

    Undefined for det F <= 0: the solver reports such a state as an inverted element.

    Parameters
    ----------
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio (-1 < nu < 0.5).
    plane : {"strain", "stress"}
        2D reduction, plane strain by default.

    Raises
    ------
    ValueError
        On NaN/inf values, E <= 0, nu out of (-1, 0.5) or an unknown plane.
    """

    name = "neohooke"
    kernel = 2

    def energy(self, H):
        """Strain-energy density mu/2 (tr C - 2) - mu ln J + lambda/2 (ln J)^2.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            Scalar energy per unit reference area; not finite where det F <= 0.
        """
        F = ng.Id(H.dims[0]) + H
        J = ng.Det(F)
        # tr C - d = 2 tr H + H:H (d the dimension), written so that it keeps digits at tiny strains
        trC_minus_2 = 2 * ng.Trace(H) + ng.InnerProduct(H, H)
        return 0.5 * self.mu * trC_minus_2 - self.mu * ng.log(J) + 0.5 * self.lam * ng.log(J) ** 2

    def first_piola(self, H):
        """First Piola-Kirchhoff stress P = mu (F - F^-T) + lambda ln J F^-T.

        Parameters
        ----------
        H : ngsolve.CoefficientFunction
            Displacement gradient grad u, 2x2.

        Returns
        -------
        ngsolve.CoefficientFunction
            2x2 stress per unit reference length; undefined where det F <= 0.
        """
        F = ng.Id(H.dims[0]) + H
        J = ng.Det(F)
        FinvT = ng.Inv(F).trans
        return self.mu * (F - FinvT) + self.lam * ng.log(J) * FinvT


MATERIALS = {cls.name: cls for cls in (LinearElastic, StVenantKirchhoff, NeoHookean)}


def make_material(name, E, nu, plane="strain"):
    """A material by its short name: "linear", "svk" or "neohooke".

    Parameters
    ----------
    name : {"linear", "svk", "neohooke"}
        LinearElastic, StVenantKirchhoff or NeoHookean (the keys of ``MATERIALS``).
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio (-1 < nu < 0.5).
    plane : {"strain", "stress"}
        2D reduction.

    Returns
    -------
    Material
        A new instance of the named model.

    Raises
    ------
    ValueError
        If the name is unknown or a parameter is invalid.
    """
    if name not in MATERIALS:
        raise ValueError(f"unknown material model {name!r}; choose one of {sorted(MATERIALS)}")
    return MATERIALS[name](E, nu, plane)


def region_materials(mesh, material):
    """{region name: Material} for every material region of the mesh.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The mesh whose regions (``mesh.GetMaterials()``) need a material.
    material : Material or dict of str -> Material
        One material for all regions, or one per region.

    Returns
    -------
    dict of str -> Material
        Every region of the mesh mapped to its material.

    Raises
    ------
    ValueError
        If a value is not a Material, a region has none, or a name is not a region; on a 3D
        mesh, a material in plane stress.
    """
    regions = set(mesh.GetMaterials())
    given = [material] if isinstance(material, Material) else material.values() if isinstance(material, dict) else []
    if mesh.dim == 3 and any(isinstance(m, Material) and m.plane != "strain" for m in given):
        raise ValueError("a 3D mesh needs materials with plane='strain' (the 3D Lame parameters); "
                         "plane stress is a 2D reduction")
    if isinstance(material, Material):
        return {name: material for name in sorted(regions)}
    if not isinstance(material, dict):
        raise ValueError(f"material must be a ngfracture Material or a dict of them, got {type(material).__name__}")
    for name, m in material.items():
        if name not in regions:
            raise ValueError(f"material region {name!r} does not exist in the mesh; its regions are {sorted(regions)}")
        if not isinstance(m, Material):
            raise ValueError(f"material for region {name!r} must be a ngfracture Material, got {type(m).__name__}")
    missing = sorted(regions - set(material))
    if missing:
        raise ValueError(f"material region(s) {missing} have no material")
    return dict(material)
