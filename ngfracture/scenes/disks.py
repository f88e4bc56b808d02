"""The disk around an expanding core (paper section 4.2, Figs. 9 and 10)."""
import ngsolve as ng
from netgen.geom2d import SplineGeometry

from ..fracture.strength import scene_strength
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import CORE_INNER, DISINTEGRATION_RADIUS, DISK_LOAD, DISK_RADIUS, GLASS, HOLE, positive


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
    from ..geometry.meshio import separate_region
    for name, v in (("maxh", maxh), ("radius", radius), ("hole", hole), ("core_inner", core_inner)):
        positive(name, v)
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
    maxh, core_stiffness = positive("maxh", maxh), positive("core_stiffness", core_stiffness)
    if radius is not None:
        radius = positive("radius", radius)
        maxh = min(maxh, radius / 2)      # h <= r/2 wherever a crack may run
    hole, core_inner, c = HOLE, CORE_INNER, positive("critical", critical)
    first_crack = 1.5 * c * HOLE     # as FIRST_CRACK, for this critical strain
    expansion = positive("expansion", expansion) if expansion is not None else 50 * first_crack
    dx = positive("dx", dx) if dx is not None else first_crack / 5
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
    expansion = expansion if expansion is not None else 150 * (1.5 * positive("critical", critical) * HOLE)
    return disk(maxh, expansion, dx, core_stiffness, name="disintegration", confined=False, E=E, nu=nu,
                critical=critical, core_nu=core_nu, radius=radius,
                weibull_m=weibull_m, weibull_scale=weibull_scale, weibull_area=weibull_area, seed=seed)

