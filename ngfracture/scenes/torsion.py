"""A curved crack surface in 3D: a glass shaft twisted about its axis breaks along a helicoid.

A circular shaft in torsion is in pure shear: tau = G theta r / L on the planes normal and
parallel to the axis, largest at the surface r = R. The largest principal stress, tau, acts
at 45 degrees to the axis along the helix ``e_x + e_phi``, so a brittle shaft (chalk, glass)
cracks across it: the crack surface's normal makes 45 degrees with the axis where it starts
on the surface, and turns with the angle phi around the axis, the crack winds around the
shaft as a helicoid instead of running across a cross-section.

The shaft (radius R along the x axis, from x = 0 to x = L, OCC cylinder) has a small
hemispherical pit at mid-length on its surface (a sphere of radius ``pit`` centred on the
surface at (L/2, 0, R)): the flaw where the one crack starts. A pit is isotropic, so it
chooses where the crack starts, not its direction: the 45 degrees come from the load. A
circumferential notch would favour a crack across the section (mode III at its root, which
breaks up into a factory roof); a slot would impose the plane. In pure shear a spherical
cavity raises the largest principal stress about twofold, so the crack starts there at
about half the twist that would crack the smooth surface.

Loads: the end x = 0 is fixed (all components), the end x = L turned rigidly by the angle
theta = x, the load parameter: u = (R(theta) - I) (0, y, z), an exact rotation (the
materials are geometrically nonlinear; a linearised rotation would strain the end by
theta^2 / 2). A circular shaft does not warp, so fixing the ends leaves the torsion field
exact: the end conditions are those of the torsion solution itself.
"""
import math

import numpy as np
import netgen.meshing as nm
from netgen.occ import X, Z, Cylinder, OCCGeometry, Pnt, Sphere
import ngsolve as ng

from ..fracture.strength import scene_strength
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import GLASS, positive
from .solids import FRONT_CONTROL

__all__ = ["shaft_mesh", "shaft3d", "SHAFT_LOAD", "SHAFT_RADIUS", "twisted_end"]

#: what the load parameter of the shaft is
SHAFT_LOAD = "twist angle of the end x = L about the shaft's axis (radians; the end x = 0 is fixed)"
#: the shaft's critical distance: its default mesh is r/2 in the band where the crack runs
SHAFT_RADIUS = 0.2
FLAW = "hole"


def shaft_mesh(maxh, fine, radius=0.5, length=2.0, pit=0.12, band=None):
    """A circular shaft with a hemispherical surface pit at mid-length, meshed by netgen's OCC.

    The shaft is the cylinder of ``radius`` about the x axis from x = 0 to x = ``length``,
    less the ball of radius ``pit`` centred on its surface at (length/2, 0, radius).
    Boundaries: ``left`` (x = 0), ``right`` (x = length), ``notch`` (the pit) and ``side``;
    region ``glass``. The mesh is ``fine`` within ``band`` of mid-length, ``maxh``
    elsewhere.

    Parameters
    ----------
    maxh, fine : float
        Mesh sizes away from and near mid-length (> 0).
    radius, length : float
        The shaft's radius and length (> 0).
    pit : float
        Radius of the pit (> 0, less than half the radius).
    band : float, optional
        Half-width of the fine zone; default 1.6 radius (a helicoid at 45 degrees runs half
        a turn, pi radius along the axis, about the pit).

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite number > 0, a pit of half the radius or more, or a
        band longer than the shaft.
    """
    maxh, fine = positive("maxh", maxh), positive("fine", fine)
    R, L, a = positive("radius", radius), positive("length", length), positive("pit", pit)
    band = 1.6 * R if band is None else positive("band", band)
    if a >= R / 2:
        raise ValueError(f"the pit's radius {a} must be less than half the shaft's radius {R}")
    if band >= L / 2:
        raise ValueError(f"the fine band's half-width {band} must be less than half the length {L}")
    shaft = Cylinder(Pnt(0, 0, 0), X, r=R, h=L)
    for f in shaft.faces:
        f.name = "side"
    shaft.faces.Min(X).name = "left"
    shaft.faces.Max(X).name = "right"
    if FLAW == "hole":
        ball = Cylinder(Pnt(L / 2, 0, R - 2 * a), Z, r=a / 2.5, h=3 * a)
    else:
        ball = Sphere(Pnt(L / 2, 0, R), a)
    for f in ball.faces:
        f.name = "notch"
    body = shaft - ball
    body.mat("glass")
    mp = nm.MeshingParameters(maxh=maxh)
    ticks = np.arange(-R, R + fine / 2, fine)
    for x in np.arange(L / 2 - band, L / 2 + band + fine / 2, fine):
        for y in ticks:
            for z in ticks:
                if y * y + z * z <= (R + fine) ** 2:
                    mp.RestrictH(x=float(x), y=float(y), z=float(z), h=fine)
    if FLAW == "hole":
        for z in np.arange(R - 2.5 * a, R + fine / 2, a / 4):
            for t in np.linspace(0, 2 * np.pi, 12, endpoint=False):
                mp.RestrictH(x=L / 2 + a / 2 * np.cos(t), y=a / 2 * np.sin(t), z=z, h=a / 2)
    return ng.Mesh(OCCGeometry(body).GenerateMesh(mp=mp))


def twisted_end(theta):
    """The displacement of a rigid rotation by ``theta`` about the x axis, (R(theta) - I) x.

    Parameters
    ----------
    theta : float
        Angle (radians), counter-clockwise seen from +x.

    Returns
    -------
    ngsolve.CoefficientFunction
        Three components: (0, (cos - 1) y - sin z, sin y + (cos - 1) z).
    """
    c1, s = -2.0 * math.sin(theta / 2) ** 2, math.sin(theta)     # cos - 1 without cancellation
    return ng.CF((0.0, c1 * ng.y - s * ng.z, s * ng.y + c1 * ng.z))


def shaft3d(maxh=0.25, fine=None, radius=SHAFT_RADIUS, shaft_radius=0.5, length=2.0, pit=0.12, twist_max=None,
            dx=None, material=None, critical=GLASS["critical"], E=GLASS["E"], nu=GLASS["nu"], weibull_m=None,
            weibull_scale=None, weibull_area=None, seed=None):
    """A glass shaft twisted about its axis: one crack along a helicoid (3D).

    The shaft of :func:`shaft_mesh` (radius ``shaft_radius``, ``length``, a pit of radius
    ``pit`` at mid-length), glass (St Venant-Kirchhoff, E = 5 GPa, nu = 0.18). The end
    x = 0 is fixed, the end x = ``length`` turned by the load x, an angle in radians, about
    the axis (:func:`twisted_end`). The smooth shaft's surface reaches the critical stress
    at theta_c = 2 (1 + nu) critical length / shaft_radius (sigma_1 / E = tau / E =
    theta R / (2 (1 + nu) L)); the pit starts the crack earlier.

    Parameters
    ----------
    maxh : float
        Mesh size away from mid-length.
    fine : float, optional
        Mesh size within 1.6 shaft radii of mid-length; default radius / 2.
    radius : float
        Critical distance of the crack criterion.
    shaft_radius, length, pit : float
        The shaft's radius, length, and the pit's radius.
    twist_max : float, optional
        Final twist (the run stops once the shaft is broken); default 3 theta_c.
    dx : float, optional
        First increment; default theta_c / 5.
    material : Material, optional
        Replaces the St Venant-Kirchhoff material of ``E`` and ``nu``.
    critical : float
        Critical principal strain.
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio.
    weibull_m, weibull_scale, weibull_area, seed
        Random strength, see :func:`ngfracture.fracture.strength.scene_strength`.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        A parameter that is not a finite number > 0, or a pit or fine band that does not fit.
    """
    maxh, radius = positive("maxh", maxh), positive("radius", radius)
    R, L = positive("shaft_radius", shaft_radius), positive("length", length)
    fine = radius / 2 if fine is None else positive("fine", fine)
    mesh = shaft_mesh(maxh, fine, radius=R, length=L, pit=pit)
    material = material if material is not None else StVenantKirchhoff(E, nu)
    theta_c = 2 * (1 + material.nu) * positive("critical", critical) * L / R
    twist_max = 3 * theta_c if twist_max is None else positive("twist_max", twist_max)
    dx = theta_c / 5 if dx is None else positive("dx", dx)
    strength, strength_parameters = scene_strength(mesh, ["glass"], critical, weibull_m, weibull_scale,
                                                   weibull_area, seed)

    def apply_load(prob, x):
        prob.add_dirichlet("left", 0.0)
        prob.add_dirichlet("right", twisted_end(x))

    return Scene(name="shaft3d", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=twist_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius,
                 load_description=SHAFT_LOAD, control=FRONT_CONTROL,
                 parameters={"maxh": maxh, "fine": fine, "radius": radius, "shaft_radius": R, "length": L,
                             "pit": pit, "twist_max": twist_max, "dx": dx, "theta_c": theta_c, "critical": critical,
                             "E": material.E, "nu": material.nu, "model": type(material).__name__,
                             **strength_parameters},
                 strength=strength)
