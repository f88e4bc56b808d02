"""The notched plate under tension (paper section 4.2, Fig. 8)."""
import math

import ngsolve as ng
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters, Pnt

from ..fracture.strength import scene_strength
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import GLASS, PLATE_LOAD, PLATE_RADIUS, positive


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
        positive(name, v)
    if notch_depth >= height / 2 or notch_width >= width:
        raise ValueError(f"the notches (depth {notch_depth}, width {notch_width}) do not fit "
                         f"the {width} x {height} plate")
    hn = min(maxh, notch_depth / 4) if notch_maxh is None else positive("notch_maxh", notch_maxh)
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
                         maxh=positive("path_maxh", path_maxh))
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def plate(maxh=0.034, strain_max=1e-3, dx=None, material=None, critical=GLASS["critical"],
          E=GLASS["E"], nu=GLASS["nu"], notch_maxh=None, radius=PLATE_RADIUS,
          weibull_m=None, weibull_scale=None, weibull_area=None, seed=None, refine=False):
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
        criterion), radius / 4 (critical distance), at most maxh, or radius / 8 (refine).
    radius : float or None
        Critical distance of the crack criterion (docs/criterion.md, default 0.04); the
        mesh is at most radius / 4 within 2 radius of the tips and along the line between
        them, where the crack runs. None: the paper's one-ring nodal strain (mesh
        dependent: its crack patterns change with maxh).
    refine : bool
        Refine ahead of the crack tips during the run (Scene.refine, radius / 4): the mesh
        is ``maxh`` but for the notch tips, ``notch_maxh`` (default radius / 8) within 3
        radius of them, instead of fine along the whole line between them.
    weibull_m, weibull_scale, weibull_area, seed
        Random strength, see :func:`ngfracture.fracture.strength.scene_strength`: a Weibull
        modulus (None: uniform strength), the scale (default: mean = ``critical``), the
        reference area of the size effect, the seed (default 0).

    Returns
    -------
    Scene
    """
    maxh, strain_max = positive("maxh", maxh), positive("strain_max", strain_max)
    if radius is None:
        mesh = notched_plate_mesh(maxh, notch_maxh=notch_maxh)
    else:
        radius = positive("radius", radius)
        # r/4 where the crack runs: at r/2 the measure of a moving tip scatters from one
        # tip vertex to the next and side cracks start (docs/criterion.md)
        fine = min(maxh, radius / 4)
        if refine:
            # the notch tips at r/8 by netgen (the initiation load within 0.3 % of the uniform
            # 64x plate's; 1.2 % at r/4); ahead of the crack tips by refinement
            notch_maxh = radius / 8 if notch_maxh is None else positive("notch_maxh", notch_maxh)
            mesh = notched_plate_mesh(maxh, notch_maxh=notch_maxh, notch_zone=3 * radius)
        else:
            notch_maxh = fine if notch_maxh is None else positive("notch_maxh", notch_maxh)
            mesh = notched_plate_mesh(maxh, notch_maxh=notch_maxh, notch_zone=2 * radius, path_maxh=fine)
    material = material if material is not None else StVenantKirchhoff(E, nu, plane="stress")
    dx = positive("dx", dx) if dx is not None else critical / 10
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
                             "notch_depth": 0.04, "notch_width": 0.02, "refine": bool(refine),
                             **strength_parameters},
                 strength=strength, refine=bool(refine) or None)

