"""A curved crack surface in 3D: a glass shaft twisted about its axis breaks along a helicoid.

A circular shaft in torsion is in pure shear: tau = G theta r / L on the planes normal and
parallel to the axis, largest at the surface r = R. The largest principal stress, tau, acts
at 45 degrees to the axis along the helix ``e_x + e_phi``, so a brittle shaft (chalk, glass)
cracks across it: the crack surface's normal makes 45 degrees with the axis where it starts
on the surface, and turns with the angle phi around the axis, the crack winds around the
shaft as a helicoid instead of running across a cross-section.

The shaft (radius R along the x axis, from x = 0 to x = L, OCC cylinders) is hollow by
default (a bore of radius 0.6 R) and has a radial hole at mid-length through its
wall: the flaw where the crack starts. A hole is isotropic in the plane of the wall, so it
chooses where the crack starts, not its direction: in pure shear its wall carries four times
the shear at +-45 degrees, and the two cracks from there lie on one helix. A circumferential
notch would favour a crack across the section (mode III at its root); a slot would impose
the plane.

Why hollow, and why r < h (docs/solid.md, "A curved crack: torsion"): on a mesh that runs in
about a minute (h = R / 5) the torsion stress falls by a fifth over one element inward. In a
solid shaft a crack from the surface then spreads along the surface instead of cutting inward
(measured: a crack area of 0.9 with 0.6 of it in the outer fifth of the radius after four
minutes, unbroken), and a critical distance of r >= 2 h (0.2 for h = 0.1, r / R = 0.4)
makes the glass notch-insensitive: the hole never starts a crack before the whole surface is
critical. The wall of the tube (0.2 = 2 h) is nearly uniformly stressed, and r = h / 2 judges
near the element scale (the paper's one-ring criterion, mesh dependent): the crack from the
hole runs unstably at 0.9 theta_c.

Loads: the end x = 0 is fixed (all components), the end x = L turned rigidly by the angle
theta = x, the load parameter: u = (R(theta) - I) (0, y, z), an exact rotation (the
materials are geometrically nonlinear; a linearised rotation would strain the end by
theta^2 / 2). A circular shaft does not warp, so fixing the ends leaves the torsion field
exact: the end conditions are those of the torsion solution itself.
"""
import math

import numpy as np
import netgen.meshing as nm
from netgen.occ import X, Z, Cylinder, OCCGeometry, Pnt
import ngsolve as ng

from ..fracture.strength import scene_strength
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import GLASS, positive
from .solids import FRONT_CONTROL

__all__ = ["shaft_mesh", "shaft3d", "SHAFT_LOAD", "SHAFT_RADIUS", "SHAFT_CONTROL", "twisted_end"]

#: what the load parameter of the shaft is
SHAFT_LOAD = "twist angle of the end x = L about the shaft's axis (radians; the end x = 0 is fixed)"
#: the shaft's critical distance: its default mesh is r/2 in the band where the crack runs
SHAFT_RADIUS = 0.05
#: the 3D scenes' control, with a step cut when more than 30 vertices crack in its first pass:
#: a step past the twist that cracks the whole surface is cut instead of cracking it all over
SHAFT_CONTROL = {**FRONT_CONTROL, "max_new_cracks": 30}


def shaft_mesh(maxh, fine, radius=0.5, length=2.0, bore=0.3, hole=0.048, depth=0.24, band=None):
    """A shaft (hollow if ``bore`` > 0) with a radial blind hole at mid-length, by netgen's OCC.

    The shaft is the cylinder of ``radius`` about the x axis from x = 0 to x = ``length``,
    less the coaxial bore of radius ``bore`` and the radial hole of radius ``hole`` drilled
    along z from the surface at (length/2, 0, radius) to the depth ``depth`` (through the
    wall when it reaches the bore). Boundaries: ``left`` (x = 0), ``right`` (x = length),
    ``notch`` (the hole) and ``side``; region ``glass``. The mesh is ``fine`` within
    ``band`` of mid-length, hole / 2 around the hole, ``maxh`` elsewhere.

    Parameters
    ----------
    maxh, fine : float
        Mesh sizes away from and near mid-length (> 0).
    radius, length : float
        The shaft's radius and length (> 0).
    bore : float
        Radius of the bore (0: a solid shaft; less than radius - depth / 2).
    hole, depth : float
        Radius and depth of the hole (> 0, depth < radius, hole < depth).
    band : float, optional
        Half-width of the fine zone; default 1.6 radius (a helicoid at 45 degrees runs half
        a turn, pi radius along the axis, about the hole).

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite number > 0, a hole or bore that does not fit, or a band
        longer than the shaft.
    """
    maxh, fine = positive("maxh", maxh), positive("fine", fine)
    R, L = positive("radius", radius), positive("length", length)
    a, d = positive("hole", hole), positive("depth", depth)
    band = 1.6 * R if band is None else positive("band", band)
    if isinstance(bore, bool) or not isinstance(bore, (int, float)) or not 0 <= bore < R - d / 2:
        raise ValueError(f"the bore's radius must be a number in [0, radius - depth/2) = [0, {R - d / 2}), "
                         f"got {bore!r}")
    if d >= R or a >= d:
        raise ValueError(f"the hole (radius {a}, depth {d}) must be shallower than the radius {R} and deeper than wide")
    if band >= L / 2:
        raise ValueError(f"the fine band's half-width {band} must be less than half the length {L}")
    shaft = Cylinder(Pnt(0, 0, 0), X, r=R, h=L)
    for f in shaft.faces:
        f.name = "side"
    shaft.faces.Min(X).name = "left"
    shaft.faces.Max(X).name = "right"
    drill = Cylinder(Pnt(L / 2, 0, R - d), Z, r=a, h=d + R)
    for f in drill.faces:
        f.name = "notch"
    body = shaft - drill
    if bore > 0:
        inner = Cylinder(Pnt(-1, 0, 0), X, r=bore, h=L + 2)
        for f in inner.faces:
            f.name = "side"
        body = body - inner
    body.mat("glass")
    mp = nm.MeshingParameters(maxh=maxh)
    ticks = np.arange(-R, R + fine / 2, fine)
    for x in np.arange(L / 2 - band, L / 2 + band + fine / 2, fine):
        for y in ticks:
            for z in ticks:
                if bore - fine <= math.hypot(y, z) <= R + fine:
                    mp.RestrictH(x=float(x), y=float(y), z=float(z), h=fine)
    for z in np.arange(R - d - a, R + a / 2, a / 2):
        for t in np.linspace(0, 2 * np.pi, 12, endpoint=False):
            mp.RestrictH(x=L / 2 + 1.25 * a * np.cos(t), y=1.25 * a * np.sin(t), z=float(z), h=1.25 * a)
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


def shaft3d(maxh=0.25, fine=0.1, radius=SHAFT_RADIUS, shaft_radius=0.5, length=2.0, bore=0.3, hole=0.048,
            depth=0.24, twist_max=None, dx=None, material=None, critical=GLASS["critical"], E=GLASS["E"],
            nu=GLASS["nu"], weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """A glass shaft twisted about its axis: a crack along a helicoid (3D).

    The shaft of :func:`shaft_mesh` (radius ``shaft_radius``, ``length``, a bore of radius
    ``bore``, a radial hole of radius ``hole`` and ``depth`` at mid-length), glass (St
    Venant-Kirchhoff, E = 5 GPa, nu = 0.18). The end x = 0 is fixed, the end x = ``length``
    turned by the load x, an angle in radians, about the axis (:func:`twisted_end`). The
    shaft's surface away from the hole reaches the critical stress at theta_c =
    2 (1 + nu) critical length / shaft_radius (sigma_1 / E = tau / E = theta R / (2 (1 + nu) L));
    the hole starts the crack earlier.

    Parameters
    ----------
    maxh : float
        Mesh size away from mid-length.
    fine : float
        Mesh size within 1.6 shaft radii of mid-length.
    radius : float
        Critical distance of the crack criterion.
    shaft_radius, length, bore, hole, depth : float
        The shaft's radius and length, the bore's radius (0: solid), the hole's radius and depth.
    twist_max : float, optional
        Final twist (the run stops once the shaft is broken); default 3 theta_c.
    dx : float, optional
        First increment; default 0.18 theta_c, which puts the fourth step at 0.9 theta_c,
        below the load that cracks the whole surface (docs/solid.md).
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
        A parameter that is not a finite number > 0, or a hole, bore or fine band that does
        not fit.
    """
    maxh, radius, fine = positive("maxh", maxh), positive("radius", radius), positive("fine", fine)
    R, L = positive("shaft_radius", shaft_radius), positive("length", length)
    mesh = shaft_mesh(maxh, fine, radius=R, length=L, bore=bore, hole=hole, depth=depth)
    material = material if material is not None else StVenantKirchhoff(E, nu)
    theta_c = 2 * (1 + material.nu) * positive("critical", critical) * L / R
    twist_max = 3 * theta_c if twist_max is None else positive("twist_max", twist_max)
    dx = 0.18 * theta_c if dx is None else positive("dx", dx)
    strength, strength_parameters = scene_strength(mesh, ["glass"], critical, weibull_m, weibull_scale,
                                                   weibull_area, seed)

    def apply_load(prob, x):
        prob.add_dirichlet("left", 0.0)
        prob.add_dirichlet("right", twisted_end(x))

    return Scene(name="shaft3d", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=twist_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius,
                 load_description=SHAFT_LOAD, control=SHAFT_CONTROL,
                 parameters={"maxh": maxh, "fine": fine, "radius": radius, "shaft_radius": R, "length": L,
                             "bore": bore, "hole": hole, "depth": depth, "twist_max": twist_max, "dx": dx,
                             "theta_c": theta_c, "critical": critical, "E": material.E, "nu": material.nu,
                             "model": type(material).__name__, **strength_parameters},
                 strength=strength)
