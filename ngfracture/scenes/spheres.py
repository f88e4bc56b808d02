"""The paper's disk scenes (section 4.2, Figs. 9 and 10) as spheres, on tetrahedra.

A glass sphere of radius 1 with a spherical hole of radius 0.25 around a softer core shell
(radii 0.125 to 0.25), the two meshed apart: netgen meshes both as one body of two regions
(CSG spheres), so the interface sphere is one surface mesh, and the core then gets its own
copies of the interface vertices (:func:`cored_sphere_mesh`). The two faceted surfaces
coincide exactly, as the 2D disk's interface circles do: bodies meshed separately would
overlap or gap by the chord error of their facets (h^2 / (8 * 0.25), about 3e-3 for
h = 0.075), a hundred times the displacements of the run. Contact alone couples them.

The twin rows of 3D contact hold a vertex against one face at its twin; on the faceted
sphere a vertex sliding along that face's plane enters the neighbouring faces, so
``apply_load`` also ties the tangential motion of every interface vertex of the core to its
glass twin (:func:`stick_rows`); the exact solution has no slip.

The core's inner surface moves radially by x (``u = x X / 0.125``, a CoefficientFunction
Dirichlet value); in :func:`sphere3d` the sphere's outer surface is held (a rigid shell),
in :func:`sphere3d_free` it is free and every piece is held on its six rigid modes
(``fix_free_modes="all"``, the 2D disintegration's reason).

The exact linear-elastic solution before cracks (:func:`shells_exact`): in each shell
``u_r = A r + B / r^2``, with ``sigma_rr = k A - m B / r^3``, ``sigma_tt = k A + m B / (2 r^3)``,
``k = E / (1 - 2 nu)``, ``m = 2 E / (1 + nu)``; conditions ``u_r(0.125) = x``, ``u_r`` and
``sigma_rr`` continuous at 0.25 (contact, compressive), ``u_r(1) = 0`` (confined) or
``sigma_rr(1) = 0`` (free). The criterion of a vertex on the hole (docs/criterion.md) takes the
smallest hoop stress over E along a ray of length r; the hoop stress falls with the distance
from the centre and a ray may not enter the hole, so the best ray is tangent to the hole and
ends at ``rho = sqrt(0.25^2 + r^2)``: the exact measure is ``sigma_tt(rho) / E``, linear in x
(:func:`sphere_first_crack`). The default load steps scale with that first-crack expansion.
"""
import math

import numpy as np
import ngsolve as ng
import netgen.meshing as nm
from netgen.csg import CSGeometry, Pnt, Sphere
import scipy.sparse as sp

from ..fracture.strength import scene_strength
from ..geometry.solid import SolidArrays, solid_mesh, solid_to_arrays
from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import CORE_INNER, GLASS, HOLE, positive
from .solids import FRONT_CONTROL

__all__ = ["SPHERE_LOAD", "SPHERE_RADIUS", "SPHERE_FREE_RADIUS", "SPHERE_CONTROL", "cored_sphere_mesh", "separate_core", "stick_rows", "shells_exact",
           "sphere_first_crack", "sphere3d", "sphere3d_free"]

#: the load parameter of the sphere scenes
SPHERE_LOAD = "radial displacement of the core's inner surface (length; the sphere's radius is 1)"
#: critical distance of the sphere's glass; the default mesh is r / 2 around the hole
SPHERE_RADIUS = 0.15
#: critical distance of the free sphere's glass (the 2D disintegration's ratio to the disk's)
SPHERE_FREE_RADIUS = 0.2
#: the core's copies of the interface vertices are moved towards the centre by this fraction
#: of their radius (module docstring: why the two surfaces are not bitwise twins)
INTERFACE_GAP = 0.0
#: the step control of the sphere scenes: the 3D fronts' spread passes, and a step is cut when its
#: first pass splits more than 8 vertices (the 2D disk's number): the hole is stressed alike
#: all round, and a step past the first crack would crack all of it at once
SPHERE_CONTROL = {**FRONT_CONTROL, "max_new_cracks": 8}
#: the outward faces of a positively oriented tetrahedron (0, 1, 2, 3)
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def cored_sphere_mesh(maxh=0.25, fine=0.075, band=0.25, radius=1.0, hole=HOLE, core_inner=CORE_INNER):
    """A sphere with a spherical hole and a core shell filling the hole, as two separate bodies.

    Regions ``glass`` (hole < |X| < radius) and ``core`` (core_inner < |X| < hole). netgen
    (CSG) meshes them as one body, so the interface is one surface mesh; then every core
    tetrahedron's vertex on the interface is replaced by a copy (same coordinates, numbered
    from nv on in increasing order of the original). The boundary faces are recomputed from
    the tetrahedra (the faces of one tetrahedron only, oriented out of it) and named by the
    region of their tetrahedron and their distance from the centre: ``outer`` and ``hole``
    (the glass's), ``core_surface`` and ``core_inner`` (the core's); ``hole`` and
    ``core_surface`` are coincident faces with bitwise-equal vertices.

    Parameters
    ----------
    maxh : float
        Mesh size away from the hole.
    fine : float
        Mesh size within ``band`` of the hole, in the core and on the hole.
    band : float
        Width of the fine zone outside the hole (>= 0).
    radius, hole, core_inner : float
        Radii of the sphere, the hole (the core's outside) and the core's inside.

    Returns
    -------
    SolidArrays

    Raises
    ------
    ValueError
        A size that is not a finite number > 0 (band >= 0), or radii out of order.
    """
    for name, v in (("maxh", maxh), ("fine", fine), ("radius", radius), ("hole", hole), ("core_inner", core_inner)):
        positive(name, v)
    if isinstance(band, bool) or not isinstance(band, (int, float)) or not 0 <= band < math.inf:
        raise ValueError(f"band must be a finite number >= 0, got {band!r}")
    if not core_inner < hole < radius:
        raise ValueError(f"need core_inner < hole < radius, got {core_inner}, {hole}, {radius}")
    geo = CSGeometry()
    outer, hole_s = Sphere(Pnt(0, 0, 0), radius).bc("outer"), Sphere(Pnt(0, 0, 0), hole).bc("hole")
    geo.Add((outer - hole_s).mat("glass"))
    geo.Add((hole_s - Sphere(Pnt(0, 0, 0), core_inner).bc("core_inner")).mat("core"))
    mp = nm.MeshingParameters(maxh=maxh)
    for rr in np.arange(core_inner, min(hole + band, radius) + 1e-12, fine):
        n = max(8, int(4 * math.pi * rr * rr / fine ** 2))        # a Fibonacci set of points at spacing ~ fine
        k = np.arange(n) + 0.5
        phi, theta = np.arccos(1 - 2 * k / n), math.pi * (1 + math.sqrt(5)) * k
        for p in zip(np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)):
            mp.RestrictH(x=rr * p[0], y=rr * p[1], z=rr * p[2], h=fine)
    return separate_core(solid_to_arrays(geo.GenerateMesh(mp=mp)), radius, hole, core_inner)


def separate_core(a, radius=1.0, hole=HOLE, core_inner=CORE_INNER):
    """The arrays of a glass-and-core mesh with the core detached (see :func:`cored_sphere_mesh`).

    Parameters
    ----------
    a : SolidArrays
        Regions ``glass`` and ``core`` sharing the interface vertices.
    radius, hole, core_inner : float
        The radii the boundary faces are named by.

    Returns
    -------
    SolidArrays
        The same points (followed by the copies), tetrahedra in order and regions; faces
        recomputed and named ``outer``, ``hole``, ``core_surface``, ``core_inner``.

    Raises
    ------
    ValueError
        Without both regions, or if they share no vertex.
    """
    if sorted(a.region_names) != ["core", "glass"]:
        raise ValueError(f"separate_core: need regions 'glass' and 'core', got {a.region_names}")
    core = a.regions == a.region_names.index("core") + 1
    shared = np.intersect1d(a.tets[core].ravel(), a.tets[~core].ravel())
    if shared.size == 0:
        raise ValueError("separate_core: the core shares no vertex with the glass")
    nv = len(a.points)
    copy = np.arange(nv)
    copy[shared] = nv + np.arange(shared.size)
    tets = a.tets.copy()
    tets[core] = copy[a.tets[core]]
    points = np.concatenate([a.points, a.points[shared] * (1.0 - INTERFACE_GAP)])
    faces = tets[:, TET_FACES].reshape(-1, 3)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    own = counts[inverse.ravel()] == 1                     # faces of one tetrahedron only: the boundary
    faces, in_core = faces[own], np.repeat(core, 4)[own]
    r = np.linalg.norm(points[faces].mean(axis=1), axis=1)
    names = ["outer", "hole", "core_surface", "core_inner"]
    bc = np.where(in_core, np.where(r > (hole + core_inner) / 2, 3, 4), np.where(r > (hole + radius) / 2, 1, 2))
    order = np.argsort(bc, kind="stable")
    return SolidArrays(points=points, tets=tets, regions=a.regions.copy(), region_names=list(a.region_names),
                       faces=faces[order], face_bc=bc[order], bc_names=names)


def shells_exact(x, E=GLASS["E"], nu=GLASS["nu"], core_E=0.1 * GLASS["E"], core_nu=0.3, radius=1.0,
                 hole=HOLE, core_inner=CORE_INNER, confined=True):
    """The linear-elastic solution of the two concentric shells (see the module docstring).

    Parameters
    ----------
    x : float
        Radial displacement of the core's inner surface.
    E, nu, core_E, core_nu : float
        The glass's and the core's Young's modulus and Poisson's ratio.
    radius, hole, core_inner : float
        Radii of the sphere, the interface and the core's inside.
    confined : bool
        ``u_r = 0`` at the outer surface (True) or ``sigma_rr = 0`` there.

    Returns
    -------
    dict
        ``"core"`` and ``"glass"``: (A, B) of ``u_r = A r + B / r^2``; ``"u"``, ``"srr"``,
        ``"stt"``: callables (r) -> u_r, sigma_rr, sigma_tt, each region by r.
    """
    k1, m1 = core_E / (1 - 2 * core_nu), 2 * core_E / (1 + core_nu)
    k2, m2 = E / (1 - 2 * nu), 2 * E / (1 + nu)
    a, b, c = core_inner, hole, radius
    M = np.array([[a, 1 / a ** 2, 0, 0],
                  [b, 1 / b ** 2, -b, -1 / b ** 2],
                  [k1, -m1 / b ** 3, -k2, m2 / b ** 3],
                  [0, 0, c, 1 / c ** 2] if confined else [0, 0, k2, -m2 / c ** 3]])
    A1, B1, A2, B2 = np.linalg.solve(M, [x, 0.0, 0.0, 0.0])
    coef = {"core": (A1, B1, k1, m1), "glass": (A2, B2, k2, m2)}

    def pick(r):
        return coef["core"] if r < b else coef["glass"]

    def u(r):
        A, B, _, _ = pick(r)
        return A * r + B / r ** 2

    def srr(r):
        A, B, k, m = pick(r)
        return k * A - m * B / r ** 3

    def stt(r):
        A, B, k, m = pick(r)
        return k * A + m * B / (2 * r ** 3)
    return {"core": (A1, B1), "glass": (A2, B2), "u": u, "srr": srr, "stt": stt}


def sphere_first_crack(radius=SPHERE_RADIUS, critical=GLASS["critical"], **shells):
    """The expansion x at which the exact solution first reaches the criterion at the hole.

    The criterion at a point of the hole is the hoop stress over E at the end of a ray of
    length ``radius`` tangent to the hole, ``sigma_tt(sqrt(hole^2 + radius^2)) / E`` (module
    docstring); linear in x.

    Parameters
    ----------
    radius : float
        Critical distance.
    critical : float
        Critical principal strain.
    **shells
        Passed to :func:`shells_exact` (E, nu, core_E, core_nu, the radii, confined).

    Returns
    -------
    float
    """
    sol = shells_exact(1.0, **shells)
    hole, E = shells.get("hole", HOLE), shells.get("E", GLASS["E"])
    return critical / (sol["stt"](math.hypot(hole, positive("radius", radius))) / E)


def sphere3d(maxh=0.25, fine=None, band=None, expansion=None, dx=None, core_stiffness=0.1, name="sphere3d",
             confined=True, E=GLASS["E"], nu=GLASS["nu"], critical=GLASS["critical"], core_nu=0.3,
             radius=SPHERE_RADIUS, weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """A glass sphere with a hole around an expanding softer core shell (paper Fig. 9 in 3D).

    The sphere (radius 1, hole 0.25) is the paper's glass (St Venant-Kirchhoff); the core
    shell (radii 0.125 to 0.25) is ``core_stiffness`` times as stiff and never cracks. The
    core's inner surface moves radially outward by x; frictionless contact passes the
    expansion on to the glass, whose outer surface is held (a rigid shell) when
    ``confined``; the interface sticks tangentially (:func:`stick_rows`). Radial cracks grow
    from the hole and cut pieces off (docs/solid.md, "The sphere scenes").

    Parameters
    ----------
    maxh : float
        Mesh size away from the hole.
    fine : float, optional
        Mesh size in the core, on the hole and within ``band`` of it; default radius / 2.
    band : float, optional
        Width of the fine zone outside the hole; default 2 radius (the crack surfaces
        grow about that far at the default expansion).
    expansion : float, optional
        Final x; default 3 times :func:`sphere_first_crack` of the scene.
    dx : float, optional
        First increment of x; default 0.4 times the first-crack expansion.
    core_stiffness : float
        Young's modulus of the core relative to the glass's (> 0).
    name : str
    confined : bool
        Hold the outer surface (True) or leave it free (see :func:`sphere3d_free`).
    E, nu, critical : float
        Young's modulus (Pa), Poisson's ratio and critical principal strain of the glass.
    core_nu : float
        Poisson's ratio of the core.
    radius : float
        Critical distance of the glass (docs/criterion.md).
    weibull_m, weibull_scale, weibull_area, seed
        Random strength of the glass (the core never cracks), see
        :func:`ngfracture.fracture.strength.scene_strength`.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        A parameter that is not a finite number > 0.
    """
    maxh, core_stiffness = positive("maxh", maxh), positive("core_stiffness", core_stiffness)
    radius, c = positive("radius", radius), positive("critical", critical)
    fine = radius / 2 if fine is None else positive("fine", fine)
    band = 2 * radius if band is None else band
    glass = StVenantKirchhoff(E, nu)
    core = StVenantKirchhoff(core_stiffness * E, core_nu)
    x_c = sphere_first_crack(radius, c, E=glass.E, nu=glass.nu, core_E=core.E, core_nu=core.nu, confined=confined)
    expansion = positive("expansion", expansion) if expansion is not None else 3 * x_c
    dx = positive("dx", dx) if dx is not None else 0.4 * x_c
    arrays = cored_sphere_mesh(maxh, fine, band)
    mesh = solid_mesh(arrays)

    def apply_load(prob, x):
        prob.add_dirichlet("core_inner", ng.CF((x * ng.x / CORE_INNER, x * ng.y / CORE_INNER,
                                                x * ng.z / CORE_INNER)))
        if confined:
            prob.add_dirichlet("outer", 0.0)
        C = stick_rows(prob.arrays, prob.fes.ndof // 3)
        prob.constraints.add_rows(C, np.zeros(C.shape[0]), label="stick")

    strength, strength_parameters = scene_strength(mesh, ["glass"], c, weibull_m, weibull_scale, weibull_area, seed)
    return Scene(name=name, mesh=mesh, material={"glass": glass, "core": core}, critical={"glass": c},
                 apply_load=apply_load, load_max=expansion, dx=dx, contact_tol=1e-3 * fine, contact=True,
                 radius=radius, load_description=SPHERE_LOAD, control=SPHERE_CONTROL,
                 fix_free_modes=True if confined else "all",
                 parameters={"maxh": maxh, "fine": fine, "band": band, "expansion": expansion, "dx": dx,
                             "critical": c, "confined": confined, "radius": radius, "first_crack_exact": x_c,
                             "E": glass.E, "nu": glass.nu, "core_E": core.E, "core_nu": core.nu,
                             "sphere_radius": 1.0, "hole": HOLE, "core_inner": CORE_INNER,
                             "tets": int(len(arrays.tets)), **strength_parameters},
                 strength=strength)


def sphere3d_free(maxh=0.3, fine=None, band=None, expansion=None, dx=None, core_stiffness=0.1, E=GLASS["E"],
                  nu=GLASS["nu"], critical=GLASS["critical"], core_nu=0.3, radius=SPHERE_FREE_RADIUS,
                  weibull_m=None, weibull_scale=None, weibull_area=None, seed=None):
    """The sphere scene free outside, expanded until it falls apart (paper Fig. 10 in 3D).

    Without the rigid shell the radial cracks run through to the outer surface; every piece
    is held on its six rigid modes by multiplier rows (``fix_free_modes="all"``, as the 2D
    :func:`ngfracture.scenes.disintegration`), so the core keeps pushing the pieces apart.

    Parameters
    ----------
    maxh, fine, band, expansion, dx, core_stiffness, E, nu, critical, core_nu, radius, weibull_m, weibull_scale, weibull_area, seed
        As for :func:`sphere3d` (coarser by default: maxh 0.3, radius 0.2; the default
        expansion 3 times the free sphere's first-crack expansion).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        A parameter that is not a finite number > 0.
    """
    return sphere3d(maxh, fine, band, expansion, dx, core_stiffness, name="sphere3d_free", confined=False, E=E,
                    nu=nu, critical=critical, core_nu=core_nu, radius=radius, weibull_m=weibull_m,
                    weibull_scale=weibull_scale, weibull_area=weibull_area, seed=seed)


def stick_rows(arrays, n):
    """Rows that tie the tangential displacement of the core's interface vertices to the glass.

    Every vertex of ``core_surface`` and the glass vertex at the same reference point move
    alike in the two directions normal to the position vector: ``t_k . (u_s - u_t) = 0``.
    The normal direction is left to contact. Where a crack split the glass vertex (several
    glass vertices on the hole at the point) the core vertex is tied to the smallest-
    numbered of them and held against the others by contact: untied, it was pinned by
    contact rows in the fans of hole faces of both lip copies, which as the crack opened
    held it against both and the active set cycled (docs/solid.md, "The sphere scenes").

    Parameters
    ----------
    arrays : SolidArrays
        The current mesh (``core_surface`` and ``hole`` faces, maybe split).
    n : int
        Dofs per component of the space (component c of vertex v is dof c n + v).

    Returns
    -------
    scipy.sparse.csr_matrix, shape (2 m, 3 n)

    Raises
    ------
    ValueError
        A core interface vertex without a glass vertex at its point.
    """
    core = np.unique(arrays.boundary_faces("core_surface"))
    glass = np.unique(arrays.boundary_faces("hole"))
    X = np.asarray(arrays.points)
    keys = {}
    for v in glass:
        k = X[v].tobytes()
        keys.setdefault(k, v)
    twin = np.array([keys.get(X[s].tobytes(), -1) for s in core], dtype=np.int64)
    if np.any(twin < 0):
        raise ValueError(f"stick_rows: core vertex {int(core[np.argmax(twin < 0)])} has no glass vertex at its point")
    e = X[core] / np.linalg.norm(X[core], axis=1)[:, None]
    a = np.where(np.abs(e[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(e, a)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(e, t1)
    rows, cols, vals = [], [], []
    for k, t in enumerate((t1, t2)):
        r = 2 * np.arange(len(core)) + k
        for c in range(3):
            rows += [r, r]
            cols += [c * n + core, c * n + twin]
            vals += [t[:, c], -t[:, c]]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(2 * len(core), 3 * n))
