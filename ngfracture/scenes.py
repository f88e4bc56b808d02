"""The paper's scenes (section 4.2) as functions that return a Scene.

Each is short on purpose: copy one, change the geometry, material or loading, and
pass it to :class:`ngfracture.run.simulation.Simulation`.

* :func:`plate`: a square glass plate with small notches on the top and bottom edges,
  pulled apart by gliding conditions on the left and right sides.
* :func:`disk`: a brittle disk with a hole around a softer, separate core whose inner
  boundary expands; contact passes the expansion on; radial cracks grow from the hole
  while the outer ring stays whole.
* :func:`disintegration`: the same disk expanded further, until it falls apart.
* :func:`beam`: a notched beam in three-point bending; its crack grows one event per load
  step at its critical load, through the peak of the load-displacement curve.

Every scene judges cracks at a critical distance ``radius`` (docs/criterion.md);
``radius=None`` selects the paper's one-ring criterion.
"""
import math

import ngsolve as ng
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters, Pnt

from .mechanics.materials import StVenantKirchhoff
from .run.scene import Scene
from .fracture.strength import scene_strength

#: the paper's glass: E = 5 GPa, nu = 0.18, critical principal strain 1.3817e-4
GLASS = dict(E=5e9, nu=0.18, critical=1.3817e-4)

#: radii of the disk's hole and of the core ring's inside (the disk's radius is 1)
HOLE, CORE_INNER = 0.25, 0.125
#: expansion of the core's inside that first cracks the glass disk: the hole's hoop strain
#: u_r / r reaches the critical strain at u_r(hole) ~ critical * hole, and the softer core
#: ring is squeezed too, about 1.5 times that at its inside
FIRST_CRACK = 1.5 * GLASS["critical"] * HOLE

#: critical distances of the scenes' glass (docs/criterion.md): the material length over which
#: the crack criterion judges the stress. A material constant (with E and the critical strain
#: it sets the toughness K_c = E critical sqrt(2 pi r)); each scene's value keeps its default
#: mesh fine enough (h <= r/4 where the plate's crack runs, h <= r/2 in the disks)
PLATE_RADIUS, DISK_RADIUS, DISINTEGRATION_RADIUS = 0.04, 0.12, 0.16

#: the load parameters, for Scene.load_description and the command line's --help
PLATE_LOAD = "total extension of the unit plate (length; equals the mean strain)"
DISK_LOAD = "radial displacement of the core's inner boundary (length; the disk's radius is 1)"


def _positive(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def notched_plate_mesh(maxh=0.034, width=1.0, height=1.0, notch_depth=0.04, notch_width=0.02,
                       notch_maxh=None, notch_zone=0.0, path_maxh=None):
    """A rectangle with a V-notch in the middle of the top and of the bottom edge.

    Boundaries: ``left``, ``right``, ``top``, ``bottom`` (the notches belong to top and
    bottom); region ``plate``. Near the notch tips the mesh size is ``notch_maxh``
    (default: a quarter of the notch depth, at most maxh), within ``notch_zone`` of each
    tip; along the line from tip to tip (where the crack runs) it is at most ``path_maxh``.

    Parameters
    ----------
    maxh : float
        Mesh size away from the notches.
    width, height : float
        The rectangle.
    notch_depth, notch_width : float
        Depth and opening of each V-notch.
    notch_maxh : float, optional
        Mesh size at the notch tips.
    notch_zone : float
        Radius of the disks around the tips meshed with ``notch_maxh`` (0: only the tips
        and the notch flanks; a critical-distance criterion needs about twice its radius).
    path_maxh : float, optional
        Mesh size along the segment between the tips.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite positive number, or notches that do not fit.
    """
    for name, v in (("maxh", maxh), ("width", width), ("height", height), ("notch_depth", notch_depth),
                    ("notch_width", notch_width)):
        _positive(name, v)
    if notch_depth >= height / 2 or notch_width >= width:
        raise ValueError(f"the notches (depth {notch_depth}, width {notch_width}) do not fit "
                         f"the {width} x {height} plate")
    hn = min(maxh, notch_depth / 4) if notch_maxh is None else _positive("notch_maxh", notch_maxh)
    geo = SplineGeometry()
    c, w = width / 2, notch_width / 2
    corners = [(0, 0), (c - w, 0), (c, notch_depth), (c + w, 0), (width, 0), (width, height),
               (c + w, height), (c, height - notch_depth), (c - w, height), (0, height)]
    tips = {2, 7}
    pts = [geo.AppendPoint(x, y, maxh=hn) if i in tips else geo.AppendPoint(x, y)
           for i, (x, y) in enumerate(corners)]
    names = ["bottom"] * 4 + ["right"] + ["top"] * 4 + ["left"]
    for i, bc in enumerate(names):
        near_tip = i in (1, 2, 6, 7)
        geo.Append(["line", pts[i], pts[(i + 1) % len(pts)]], bc=bc, leftdomain=1, rightdomain=0,
                   **({"maxh": hn} if near_tip else {}))
    geo.SetMaterial(1, "plate")
    mp = MeshingParameters(maxh=maxh)
    if notch_zone < 0 or not math.isfinite(notch_zone):
        raise ValueError(f"notch_zone must be a finite number >= 0, got {notch_zone!r}")
    n = int(math.ceil(notch_zone / hn))
    for tip_y in (notch_depth, height - notch_depth):
        for i in range(-n, n + 1):         # a grid of size restrictions fills the disk
            for j in range(-n, n + 1):
                if (i * i + j * j) * hn * hn <= notch_zone ** 2:
                    mp.RestrictH(x=c + i * hn, y=tip_y + j * hn, z=0, h=hn)
    if path_maxh is not None:
        mp.RestrictHLine(p1=Pnt(c, notch_depth, 0), p2=Pnt(c, height - notch_depth, 0),
                         maxh=_positive("path_maxh", path_maxh))
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def plate(maxh=0.034, strain_max=1e-3, dx=None, material=None, critical=GLASS["critical"],
          E=GLASS["E"], nu=GLASS["nu"], notch_maxh=None, radius=PLATE_RADIUS,
          weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """The plate under tension of paper section 4.2 (Fig. 8).

    A 1 x 1 plate of glass (E = 5 GPa, nu = 0.18, plane stress, St Venant-Kirchhoff)
    with a notch of depth 0.04 in the middle of the top and bottom edges. The left and
    right sides glide: u_x = -x/2 and +x/2, u_y free (the one rigid mode this leaves,
    vertical translation, is held by a multiplier row). x is the total extension.

    Parameters
    ----------
    maxh : float
        Mesh size; the default gives triangles of area about 0.0005 as in the paper
        (minimum angle about 30 degrees from netgen's quality meshing).
    strain_max : float
        Final mean strain x / width (the run stops earlier once broken through).
    dx : float, optional
        First increment of x; default a tenth of the uncracked failure extension.
    material : Material, optional
        Replaces the St Venant-Kirchhoff material of ``E`` and ``nu``.
    critical : float
        Critical principal strain (the mean strength of a random one).
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio of the plate (plane stress).
    notch_maxh : float, optional
        Mesh size at the notch tips; default a quarter of the notch depth (one-ring
        criterion) or radius / 4 (critical distance), at most maxh.
    radius : float or None
        Critical distance of the crack criterion (docs/criterion.md, default 0.04); the
        mesh is at most radius / 4 within 2 radius of the tips and along the line between
        them, where the crack runs. None: the paper's one-ring nodal strain (mesh
        dependent: its crack patterns change with maxh).
    weibull_m, weibull_scale, weibull_area, seed
        Random strength, see :func:`ngfracture.fracture.strength.scene_strength`: a Weibull
        modulus (None: uniform strength), the scale (default: mean = ``critical``), the
        reference area of the size effect, the seed (default 0).

    Returns
    -------
    Scene
    """
    maxh, strain_max = _positive("maxh", maxh), _positive("strain_max", strain_max)
    if radius is None:
        mesh = notched_plate_mesh(maxh, notch_maxh=notch_maxh)
    else:
        radius = _positive("radius", radius)
        # r/4 where the crack runs: at r/2 the measure of a moving tip scatters from one
        # tip vertex to the next and side cracks start (docs/criterion.md)
        fine = min(maxh, radius / 4)
        notch_maxh = fine if notch_maxh is None else _positive("notch_maxh", notch_maxh)
        mesh = notched_plate_mesh(maxh, notch_maxh=notch_maxh, notch_zone=2 * radius, path_maxh=fine)
    material = material if material is not None else StVenantKirchhoff(E, nu, plane="stress")
    dx = _positive("dx", dx) if dx is not None else critical / 10
    strength, strength_parameters = scene_strength(mesh, ["plate"], critical, weibull_m, weibull_scale,
                                                   weibull_area, seed)

    def apply_load(prob, x):
        prob.add_dirichlet("left", -x / 2, component="x")
        prob.add_dirichlet("right", x / 2, component="x")

    return Scene(name="plate", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=strain_max, dx=dx, contact_tol=1e-3 * maxh, stop_when_unloaded=True,
                 radius=radius, load_description=PLATE_LOAD,
                 parameters={"maxh": maxh, "strain_max": strain_max, "dx": dx, "critical": critical,
                             "notch_maxh": notch_maxh, "radius": radius,
                             "E": material.E, "nu": material.nu, "model": type(material).__name__,
                             "notch_depth": 0.04, "notch_width": 0.02, **strength_parameters},
                 strength=strength)


def cored_disk_mesh(maxh=0.06, radius=1.0, hole=0.25, core_inner=0.125):
    """A disk with a hole, and a core ring filling the hole, as two separate bodies.

    Regions ``disk`` (hole < r < radius) and ``core`` (core_inner < r < hole). The two
    share no vertex: the interface circle is meshed once and the core gets its own copies
    of the interface vertices (:func:`ngfracture.geometry.meshio.separate_region`), so contact
    alone couples them. Boundaries: ``outer``, ``hole`` (the disk's side of the
    interface), ``core_surface`` (the core's side), ``core_inner``.

    Parameters
    ----------
    maxh : float
        Mesh size.
    radius, hole, core_inner : float
        Outer radius of the disk, radius of its hole (= the core's outer radius), inner
        radius of the core ring.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        A size that is not a finite positive number, or radii out of order.
    """
    from .geometry.meshio import separate_region
    for name, v in (("maxh", maxh), ("radius", radius), ("hole", hole), ("core_inner", core_inner)):
        _positive(name, v)
    if not core_inner < hole < radius:
        raise ValueError(f"need core_inner < hole < radius, got {core_inner}, {hole}, {radius}")
    geo = SplineGeometry()
    geo.AddCircle((0, 0), radius, leftdomain=1, rightdomain=0, bc="outer")
    geo.AddCircle((0, 0), hole, leftdomain=2, rightdomain=1, bc="hole")
    geo.AddCircle((0, 0), core_inner, leftdomain=0, rightdomain=2, bc="core_inner")
    geo.SetMaterial(1, "disk")
    geo.SetMaterial(2, "core")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    return separate_region(mesh, "core", boundary="hole", region_boundary="core_surface")


def disk(maxh=0.06, expansion=None, dx=None, core_stiffness=0.1, name="disk", confined=True,
         E=GLASS["E"], nu=GLASS["nu"], critical=GLASS["critical"], core_nu=0.3, radius=DISK_RADIUS,
         weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """A brittle disk with a hole around an expanding softer core (paper Fig. 9).

    The disk (radius 1, hole radius 0.25) is the paper's glass (St Venant-Kirchhoff,
    plane strain); the core ring (radii 0.125 to 0.25) is ``core_stiffness`` times as stiff
    and never cracks. The core's inner boundary moves radially outward by x; frictionless
    contact passes the expansion on to the disk, which sits in a rigid ring (``confined``:
    its outer boundary is held). Free modes (rotations of pieces) are held by multiplier
    rows; without the ring all rigid modes of the disk's pieces are (see
    :func:`disintegration`). By default x runs to 50 times the expansion that first cracks the intact disk:
    radial cracks grow from the hole and stop inside (the ring confines them); with the
    one-ring criterion the inner part breaks into grains, with a critical distance
    (``radius``) the radial cracks stay apart; the outer part stays whole.

    Parameters
    ----------
    maxh : float
        Mesh size (the paper gives none for the disk; 0.06 makes about 2000 triangles and
        a run of about a minute on one core).
    expansion : float, optional
        Final radial displacement of the core's inner boundary.
    dx : float, optional
        First increment of x.
    core_stiffness : float
        Young's modulus of the core relative to the disk's (> 0).
    name : str
    confined : bool
        Hold the disk's outer boundary (a rigid ring); False leaves it free.
    E, nu, critical : float
        Young's modulus (Pa), Poisson's ratio and critical principal strain of the disk
        (plane strain); the default expansion and dx scale with ``critical``.
    core_nu : float
        Poisson's ratio of the core.
    radius : float or None
        Critical distance of the disk's glass (docs/criterion.md, default 0.12): radial
        cracks from the hole, the same cracked zone at maxh 0.06 and 0.03. Cracks may run
        anywhere in the disk, so the whole mesh is made at most radius / 2. None: the
        paper's one-ring criterion (the comminuted zone of the paper's Fig. 9, grains at
        the mesh scale).
    weibull_m, weibull_scale, weibull_area, seed
        Random strength of the disk (the core never cracks), see :func:`plate`.

    Returns
    -------
    Scene
    """
    maxh, core_stiffness = _positive("maxh", maxh), _positive("core_stiffness", core_stiffness)
    if radius is not None:
        radius = _positive("radius", radius)
        maxh = min(maxh, radius / 2)      # h <= r/2 wherever a crack may run
    hole, core_inner, c = HOLE, CORE_INNER, _positive("critical", critical)
    first_crack = 1.5 * c * HOLE     # as FIRST_CRACK, for this critical strain
    expansion = _positive("expansion", expansion) if expansion is not None else 50 * first_crack
    dx = _positive("dx", dx) if dx is not None else first_crack / 5
    glass = StVenantKirchhoff(E, nu, plane="strain")
    core = StVenantKirchhoff(core_stiffness * E, core_nu, plane="strain")

    def apply_load(prob, x):
        prob.add_dirichlet("core_inner", ng.CF((x * ng.x / core_inner, x * ng.y / core_inner)))
        if confined:
            prob.add_dirichlet("outer", (0.0, 0.0))

    mesh = cored_disk_mesh(maxh, 1.0, hole, core_inner)
    strength, strength_parameters = scene_strength(mesh, ["disk"], c, weibull_m, weibull_scale, weibull_area, seed)
    return Scene(name=name, mesh=mesh,
                 material={"disk": glass, "core": core}, critical={"disk": c}, apply_load=apply_load,
                 load_max=expansion, dx=dx, contact_tol=1e-3 * maxh, contact=True,
                 radius=radius, load_description=DISK_LOAD,
                 control={"max_new_cracks": 8}, fix_free_modes=True if confined else "all",
                 parameters={"maxh": maxh, "expansion": expansion, "dx": dx, "critical": c,
                             "confined": confined, "radius": radius,
                             "E": glass.E, "nu": glass.nu, "core_E": core.E, "core_nu": core.nu,
                             "disk_radius": 1.0, "hole": hole, "core_inner": core_inner, **strength_parameters},
                 strength=strength)


def disintegration(maxh=0.08, expansion=None, dx=None, core_stiffness=0.1, E=GLASS["E"], nu=GLASS["nu"],
                   critical=GLASS["critical"], core_nu=0.3, radius=DISINTEGRATION_RADIUS,
                   weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """The disk scene free outside, expanded until it falls apart (paper Fig. 10).

    Without the confining ring, radial cracks run through to the outside; the pieces
    are held on all their rigid modes by multiplier rows (the paper pins two points
    each), so the core keeps pushing them and they break further. Three times the final
    expansion of :func:`disk`.

    Why all modes (``Scene.fix_free_modes = "all"``): held only on the modes contact
    leaves free, a piece that the core pushes outward has no equilibrium with compressive
    contact (nothing resists the push). Measured when the disk first split in two (maxh
    0.08, x = 0.0017269): every active set balanced the half-disks with adhesive
    multipliers (+5.6e4 against -9.5e4), the primal-dual update released them, the next
    set held a half only weakly (smallest singular value of the contact rows on its modes
    0.03 of the largest) and the solve blew up (inverted elements) or modified Newton
    crawled (0.74 per iteration). Held on all modes, the same solve converges in 11
    rounds with compressive multipliers only.

    Parameters
    ----------
    maxh : float
        Mesh size. Coarser than :func:`disk`'s by default (0.08, about 1000 triangles), as
        the paper ran this case "using a coarse initial mesh": 101 steps and 7 disk pieces;
        with the one-ring criterion 116 steps, the core and 30 disk pieces
        (docs/verification.md; run times in docs/performance.md).
    expansion, dx, core_stiffness, E, nu, critical, core_nu, radius, weibull_m, weibull_scale, weibull_area, seed
        As for :func:`disk` (default radius 0.16; None: the paper's criterion, Fig. 10).

    Returns
    -------
    Scene
    """
    expansion = expansion if expansion is not None else 150 * (1.5 * _positive("critical", critical) * HOLE)
    return disk(maxh, expansion, dx, core_stiffness, name="disintegration", confined=False, E=E, nu=nu,
                critical=critical, core_nu=core_nu, radius=radius,
                weibull_m=weibull_m, weibull_scale=weibull_scale, weibull_area=weibull_area, seed=seed)


#: the scenes of ``python -m ngfracture run``


BEAM_LOAD = "downward displacement of the loading pad on the beam's top (length; the beam's height is 1)"


def senb_factor(alpha):
    """The SENB geometry factor f(a/W) of a beam of span 4W (Srawley 1976; 0.5 % for any a/W).

    K_I = P S / (B W^(3/2)) f(a/W) for the load P at mid-span, the span S = 4 W.

    Parameters
    ----------
    alpha : float
        a / W in [0, 1).

    Returns
    -------
    float
    """
    a = float(alpha)
    return (3 * math.sqrt(a) * (1.99 - a * (1 - a) * (2.15 - 3.93 * a + 2.7 * a * a))
            / (2 * (1 + 2 * a) * (1 - a) ** 1.5))


def notched_beam_mesh(maxh=0.1, fine=0.01, notch=0.3, span=4.0, overhang=0.2, pad=0.05):
    """A beam of height 1 with a V-notch in the middle of its bottom edge (three-point bending).

    Boundaries: ``support_left``, ``support_right`` (short segments of width ``pad`` at the
    supports), ``load`` (the pad at mid-span on top), ``notch``, ``surface`` (the rest).
    Regions: ``ligament`` (a band of width 1 around the notch, where cracks may run) and
    ``beam``. The mesh is ``fine`` along the line above the notch and around its tip.

    Parameters
    ----------
    maxh, fine : float
        Mesh size, and the size along the crack's path.
    notch : float
        Notch depth a / W (its opening is a tenth of ``fine`` ... a fifth of the depth).
    span, overhang, pad : float
        Distance between the supports, the beam beyond them, the width of supports and pad.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        Sizes that are not finite positive numbers, or a notch that does not fit.
    """
    for name, v in (("maxh", maxh), ("fine", fine), ("notch", notch), ("span", span), ("pad", pad)):
        _positive(name, v)
    if not notch < 0.8:
        raise ValueError(f"notch must be a / W < 0.8, got {notch!r}")
    length = span + 2 * overhang
    c, w, half = length / 2, min(0.2 * notch, 0.01), 0.5
    geo = SplineGeometry()
    pts = [(0, 0), (overhang - pad / 2, 0), (overhang + pad / 2, 0), (c - half, 0), (c - w / 2, 0), (c, notch),
           (c + w / 2, 0), (c + half, 0), (length - overhang - pad / 2, 0), (length - overhang + pad / 2, 0),
           (length, 0), (length, 1), (c + half, 1), (c + pad / 2, 1), (c - pad / 2, 1), (c - half, 1), (0, 1)]
    P = [geo.AppendPoint(x, y, maxh=fine) if (x, y) == (c, notch) else geo.AppendPoint(x, y) for x, y in pts]
    # (start, end, boundary, region on the left): the ligament band is region 2
    edges = [(0, 1, "surface", 1), (1, 2, "support_left", 1), (2, 3, "surface", 1), (3, 4, "surface", 2),
             (4, 5, "notch", 2), (5, 6, "notch", 2), (6, 7, "surface", 2), (7, 8, "surface", 1),
             (8, 9, "support_right", 1), (9, 10, "surface", 1), (10, 11, "surface", 1), (11, 12, "surface", 1),
             (12, 13, "surface", 2), (13, 14, "load", 2), (14, 15, "surface", 2), (15, 16, "surface", 1),
             (16, 0, "surface", 1)]
    for a, b, name, left in edges:
        geo.Append(["line", P[a], P[b]], bc=name, leftdomain=left, rightdomain=0)
    geo.Append(["line", P[3], P[15]], bc="band", leftdomain=1, rightdomain=2)
    geo.Append(["line", P[7], P[12]], bc="band", leftdomain=2, rightdomain=1)
    geo.SetMaterial(1, "beam")
    geo.SetMaterial(2, "ligament")
    mp = MeshingParameters(maxh=maxh)
    mp.RestrictHLine(p1=Pnt(c, notch, 0), p2=Pnt(c, 1, 0), maxh=fine)
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def beam(maxh=0.1, radius=0.04, notch=0.3, deflection_max=None, dx=None, E=GLASS["E"], nu=GLASS["nu"],
         critical=GLASS["critical"]):
    """A notched glass beam in three-point bending (SENB), pressed down at mid-span.

    Span 4, height 1, a V-notch of depth ``notch`` under the load; the beam rests on two
    short supports (u_y = 0, the left one also u_x = 0) and a pad on its top is moved
    down by x. Cracks may run in the band of width 1 above the notch (the rest never
    cracks: no spurious cracks at the supports and the pad). The crack grows one event per
    load step at the load that makes it critical (StepControl growth "critical"), so the
    load-displacement curve (force_displacement.png) is followed through its peak and its
    descending branch; its peak is the LEFM load P = K_c W^(3/2) / (S f(a/W)) with the
    criterion's toughness K_c = E critical sqrt(2 pi radius) (:func:`senb_factor`).

    Parameters
    ----------
    maxh : float
        Mesh size away from the crack's path (radius / 4 along it).
    radius : float
        Critical distance.
    notch : float
        Notch depth a / W.
    deflection_max : float, optional
        The final deflection; default eight times the LEFM deflection at the peak by beam theory.
    dx : float, optional
        First increment; default an eighth of that deflection.
    E, nu, critical : float
        The glass (St Venant-Kirchhoff, plane stress) and its critical strain.

    Returns
    -------
    Scene
    """
    maxh, radius = _positive("maxh", maxh), _positive("radius", radius)
    fine = min(maxh, radius / 4)
    mesh = notched_beam_mesh(maxh, fine, notch)
    material = StVenantKirchhoff(E, nu, plane="stress")
    peak = E * critical * math.sqrt(2 * math.pi * radius) / (4 * senb_factor(notch))
    # beam theory: delta = P S^3 / (48 E I), I = 1/12; the notch and shear add to it
    deflection = 16 * peak / E
    deflection_max = 8 * deflection if deflection_max is None else _positive("deflection_max", deflection_max)
    dx = deflection / 8 if dx is None else _positive("dx", dx)

    def apply_load(prob, x):
        prob.add_dirichlet("support_left", (0.0, 0.0))
        prob.add_dirichlet("support_right", 0.0, component="y")
        prob.add_dirichlet("load", -x, component="y")

    return Scene(name="beam", mesh=mesh, material=material, critical={"ligament": critical}, apply_load=apply_load,
                 load_max=deflection_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius,
                 load_description=BEAM_LOAD, control={"growth": "critical", "max_steps": 1000},
                 parameters={"maxh": maxh, "radius": radius, "notch": notch, "deflection_max": deflection_max, "dx": dx,
                             "E": E, "nu": nu, "critical": critical, "lefm_peak_load": peak})


SCENES = {"plate": plate, "disk": disk, "disintegration": disintegration, "beam": beam}
#: what the load parameter x of each scene is (Scene.load_description)
LOAD_DESCRIPTIONS = {"plate": PLATE_LOAD, "disk": DISK_LOAD, "disintegration": DISK_LOAD, "beam": BEAM_LOAD}
