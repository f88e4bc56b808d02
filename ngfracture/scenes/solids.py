"""The 3D scenes: a notched bar in tension (one crack plane across its ligament) and the
paper's notched plate extruded to a thickness."""
import numpy as np
from netgen.csg import CSGeometry, OrthoBrick, Plane, Pnt, Vec
import netgen.meshing as nm
from netgen.occ import X, OCCGeometry, WorkPlane
import ngsolve as ng

from ..fracture.strength import scene_strength
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import BAR_LOAD, BAR_RADIUS, GLASS, PLATE_LOAD, PLATE_RADIUS, positive

__all__ = ["notched_bar_mesh", "bar3d", "extruded_plate_mesh", "plate3d", "hold_gliding_ends", "corner_vertices",
           "FRONT_SPLITS", "SPLIT_3D"]

#: the first pass of a load step may split this many front vertices before the step is cut
FRONT_SPLITS = 1000
#: the split mode of the 3D scenes' crack passes (docs/solid.md, "Crack passes in 3D")
SPLIT_3D = "spread"
#: the step control of the 3D scenes: a front is many vertices that a load step overstresses
#: together; each pass advances those that share no edge (docs/solid.md, "Crack passes in 3D")
FRONT_CONTROL = {"split": SPLIT_3D, "max_new_cracks": FRONT_SPLITS}


def notched_bar_mesh(maxh, fine, length=2.0, width=1.0, thickness=0.5, notch=0.2, notch_width=0.02):
    """A bar with a through-thickness edge notch at mid-length, meshed by netgen.

    The bar spans x in [0, length], y in [0, width], z in [0, thickness]; the notch, a slot
    of ``notch_width`` across x = length/2, runs from y = 0 to y = ``notch`` through the
    whole thickness. Boundaries: ``left`` (x = 0), ``right`` (x = length), ``notch`` (the
    slot's faces) and ``side``; region ``glass``. The mesh is ``fine`` within two ``fine``
    of the mid-plane x = length/2 (where the crack runs), ``maxh`` elsewhere.

    Parameters
    ----------
    maxh, fine : float
        Mesh sizes away from and at the crack plane (> 0).
    length, width, thickness, notch, notch_width : float
        The bar's dimensions (> 0; notch < width, notch_width < length).

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite number > 0, or a notch as deep as the bar.
    """
    maxh, fine = positive("maxh", maxh), positive("fine", fine)
    L, W, T = positive("length", length), positive("width", width), positive("thickness", thickness)
    a, w = positive("notch", notch), positive("notch_width", notch_width)
    if a >= W or w >= L:
        raise ValueError(f"the notch ({a} deep, {w} wide) must be shallower than the width {W} and narrower "
                         f"than the length {L}")
    geo = CSGeometry()
    # a brick larger than the bar cut by named planes: a plane on a brick's face would not name it
    box = (OrthoBrick(Pnt(-1, -1, -1), Pnt(L + 1, W + 1, T + 1)).bc("side")
           * Plane(Pnt(0, 0, 0), Vec(-1, 0, 0)).bc("left") * Plane(Pnt(L, 0, 0), Vec(1, 0, 0)).bc("right")
           * Plane(Pnt(0, 0, 0), Vec(0, -1, 0)).bc("side") * Plane(Pnt(0, W, 0), Vec(0, 1, 0)).bc("side")
           * Plane(Pnt(0, 0, 0), Vec(0, 0, -1)).bc("side") * Plane(Pnt(0, 0, T), Vec(0, 0, 1)).bc("side"))
    slot = OrthoBrick(Pnt(L / 2 - w / 2, -1, -1), Pnt(L / 2 + w / 2, a, T + 1)).bc("notch")
    geo.Add((box - slot).mat("glass"))
    mp = nm.MeshingParameters(maxh=maxh)
    for y in np.arange(0.0, W + fine / 2, fine):
        for z in np.arange(0.0, T + fine / 2, fine):
            for x in (L / 2 - 2 * fine, L / 2, L / 2 + 2 * fine):
                mp.RestrictH(x=x, y=y, z=z, h=fine)
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def bar3d(maxh=0.15, fine=None, strain_max=2e-3, dx=None, material=None, critical=GLASS["critical"],
          E=GLASS["E"], nu=GLASS["nu"], radius=BAR_RADIUS, notch=0.4, thickness=0.5, length=2.0,
          weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """A notched glass bar pulled along its axis: one crack across the ligament (3D).

    A ``length`` x 1 x ``thickness`` bar of glass (St Venant-Kirchhoff, E = 5 GPa, nu = 0.18)
    with a through-thickness edge notch of depth ``notch`` at mid-length. Both ends glide:
    u_x = 0 at x = 0 and u_x = x at x = ``length``, the other components free; the three rigid modes this
    leaves (translations in y and z, rotation about the axis) are held at two corners of
    the left end. x is the extension of the bar.

    Parameters
    ----------
    maxh : float
        Mesh size away from the crack plane.
    fine : float, optional
        Mesh size within two of it of the mid-plane; default radius / 2.
    strain_max : float
        Final mean strain x / length (the run stops once the bar is broken through).
    dx : float, optional
        First increment of x; default a fifth of the critical extension of the unnotched bar.
    material : Material, optional
        Replaces the St Venant-Kirchhoff material of ``E`` and ``nu``.
    critical : float
        Critical principal strain.
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio.
    radius : float
        Critical distance of the crack criterion.
    notch, thickness, length : float
        Notch depth, bar thickness and length (the width is 1). The default notch, 0.4 deep,
        starts the crack at 30 % of the unnotched bar's strength: with a shallower one the
        halves, whose gliding ends keep them from turning, crack in bending while the first
        crack runs at the higher load (docs/solid.md, "The scenes").
    weibull_m, weibull_scale, weibull_area, seed
        Random strength, see :func:`ngfracture.fracture.strength.scene_strength` (in 3D the
        size effect's reference is a volume): a Weibull modulus (None: uniform strength),
        the scale (default: mean = ``critical``), the reference volume, the seed (default 0).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        A parameter that is not a finite number > 0.
    """
    maxh, strain_max = positive("maxh", maxh), positive("strain_max", strain_max)
    radius = positive("radius", radius)
    fine = radius / 2 if fine is None else positive("fine", fine)
    mesh = notched_bar_mesh(maxh, fine, thickness=thickness, notch=notch, length=length)
    material = material if material is not None else StVenantKirchhoff(E, nu)
    length = positive("length", length)
    dx = positive("dx", dx) if dx is not None else length * critical / 5
    corners = corner_vertices(mesh, [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    strength, strength_parameters = scene_strength(mesh, ["glass"], critical, weibull_m, weibull_scale,
                                                   weibull_area, seed)

    def apply_load(prob, x):
        prob.add_dirichlet("left", 0.0, component="x")
        prob.add_dirichlet("right", x, component="x")
        hold_gliding_ends(prob, corners)

    return Scene(name="bar3d", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=length * strain_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True,
                 radius=radius, load_description=BAR_LOAD,
                 control=FRONT_CONTROL,
                 parameters={"maxh": maxh, "fine": fine, "strain_max": strain_max, "dx": dx, "critical": critical,
                             "radius": radius, "E": material.E, "nu": material.nu, "model": type(material).__name__,
                             "notch_depth": notch, "thickness": thickness, "length": length,
                             **strength_parameters},
                 strength=strength)


def hold_gliding_ends(prob, corners):
    """Hold the rigid modes that ends gliding along x leave free (translations in y and z,
    rotation about x) at two corners of the left end, without stressing the body.

    Parameters
    ----------
    prob : ElasticProblem
    corners : sequence of int
        Two vertices of the left end, apart in y (:func:`corner_vertices`).
    """
    prob.add_point_constraint(corners[0], 0.0, component="y")
    prob.add_point_constraint(corners[0], 0.0, component="z")
    prob.add_point_constraint(corners[1], 0.0, component="z")


def corner_vertices(mesh, points):
    """The vertices nearest the given points (corners of the mesh).

    Parameters
    ----------
    mesh : ngsolve.Mesh
    points : sequence of (float, float, float)

    Returns
    -------
    list of int
    """
    P = mesh.ngmesh.Coordinates()
    return [int(np.argmin(np.linalg.norm(P - q, axis=1))) for q in points]


def extruded_plate_mesh(maxh, fine, thickness, width=1.0, height=1.0, notch_depth=0.04, notch_width=0.02):
    """The paper's V-notched plate (``plates.notched_plate_mesh``) extruded along z, by netgen's OCC.

    Boundaries ``left`` (x = 0), ``right`` (x = width) and ``side`` (the rest: top and bottom
    with their notches, the faces z = 0 and z = thickness); region ``plate``. The mesh is
    ``fine`` on the plane x = width / 2 between the notch tips (where the crack runs),
    ``maxh`` elsewhere.

    Parameters
    ----------
    maxh, fine, thickness : float
        Mesh sizes away from and on the crack's plane, the plate's thickness (> 0).
    width, height, notch_depth, notch_width : float
        As for the 2D plate.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite number > 0, or notches that do not fit.
    """
    maxh, fine, T = positive("maxh", maxh), positive("fine", fine), positive("thickness", thickness)
    W, H, d, w = (positive(n, v) for n, v in (("width", width), ("height", height), ("notch_depth", notch_depth),
                                              ("notch_width", notch_width)))
    if d >= H / 2 or w >= W:
        raise ValueError(f"the notches (depth {d}, width {w}) do not fit the {W} x {H} plate")
    c = W / 2
    corners = [(0, 0), (c - w / 2, 0), (c, d), (c + w / 2, 0), (W, 0), (W, H), (c + w / 2, H), (c, H - d),
               (c - w / 2, H), (0, H)]
    wp = WorkPlane()
    wp.MoveTo(*corners[0])
    for p in corners[1:]:
        wp.LineTo(*p)
    solid = wp.Close().Face().Extrude(T)
    for f in solid.faces:
        f.name = "side"
    solid.faces.Min(X).name = "left"
    solid.faces.Max(X).name = "right"
    solid.mat("plate")
    mp = nm.MeshingParameters(maxh=maxh)
    for y in np.arange(d, H - d + fine / 2, fine):
        for z in np.arange(0.0, T + fine / 2, fine):
            mp.RestrictH(x=c, y=y, z=z, h=fine)
    return ng.Mesh(OCCGeometry(solid).GenerateMesh(mp=mp))


def plate3d(maxh=0.1, fine=None, thickness=0.2, strain_max=1e-3, dx=None, material=None, critical=GLASS["critical"],
            E=GLASS["E"], nu=GLASS["nu"], radius=PLATE_RADIUS):
    """The paper's notched plate (Fig. 8) extruded to a thickness, on tetrahedra.

    The plate of :func:`ngfracture.scenes.plate` (1 x 1, V-notches 0.04 deep in the middle
    of the top and bottom edges, glass, St Venant-Kirchhoff) as a 3D body of ``thickness``:
    the left and right faces glide apart, u_x = -x/2 and +x/2; the three rigid modes this
    leaves (translations in y and z, rotation about x) are held at two corners of the left
    face. A thin plate is near plane stress, a thick one near plane strain in its middle.

    Parameters
    ----------
    maxh : float
        Mesh size away from the crack's plane.
    fine : float, optional
        Mesh size on the plane between the notch tips; default radius / 2.
    thickness : float
        Along z.
    strain_max : float
        Final mean strain x (the run stops once the plate is broken through).
    dx : float, optional
        First increment; default a tenth of the critical strain.
    material : Material, optional
        Replaces the St Venant-Kirchhoff material of ``E`` and ``nu``.
    critical : float
        Critical principal strain.
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio.
    radius : float
        Critical distance of the crack criterion (the 2D plate's by default).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        A parameter that is not a finite number > 0.
    """
    maxh, strain_max, radius = positive("maxh", maxh), positive("strain_max", strain_max), positive("radius", radius)
    fine = radius / 2 if fine is None else positive("fine", fine)
    mesh = extruded_plate_mesh(maxh, fine, thickness)
    material = material if material is not None else StVenantKirchhoff(E, nu)
    dx = positive("dx", dx) if dx is not None else critical / 10
    corners = corner_vertices(mesh, [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])

    def apply_load(prob, x):
        prob.add_dirichlet("left", -x / 2, component="x")
        prob.add_dirichlet("right", x / 2, component="x")
        hold_gliding_ends(prob, corners)

    return Scene(name="plate3d", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=strain_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius,
                 load_description=PLATE_LOAD, control=FRONT_CONTROL,
                 parameters={"maxh": maxh, "fine": fine, "thickness": thickness, "strain_max": strain_max, "dx": dx,
                             "critical": critical, "radius": radius, "E": material.E, "nu": material.nu,
                             "model": type(material).__name__, "notch_depth": 0.04, "notch_width": 0.02})
