"""Random 3D scenes for stress tests: boxes with spherical holes and a slot under random loads.

The 3D counterpart of :mod:`ngfracture.studies.random_scenes`: nobody wrote these bodies
by hand, so the crack passes in 3D, the contact of the pieces they make and the free
pieces' rigid modes meet cases their authors did not look at:

    params = draw(seed)            # plain numbers and strings, reproducible from the seed
    result = Simulation(scene(**params)).run()

:func:`scene` is an ordinary scene function, so a case can be replayed from the command
line: ``ngfracture run ngfracture.studies.random_solids:scene --set length=1.4 ...``.
:func:`draw` mixes ordinary cases with the extremes of the 2D draw (a mesh four times
coarser than the critical distance, a critical distance of the body's size, nu = 0.499, a
critical strain of 0.3, loads 40 times past the first crack).
``benchmarks/random_scenes.py --solids`` runs many and tallies how each ended;
``tests/test_random_solids.py`` runs a few.
"""
import math

import numpy as np
import ngsolve as ng
from netgen.occ import X, Y, Z, Box, OCCGeometry, Pnt, Sphere

from ..run.scene import Scene
from ..scenes.common import positive
from ..scenes.solids import FRONT_CONTROL, corner_vertices, hold_gliding_ends
from .random_scenes import MODELS, draw_extreme, parse_holes

__all__ = ["LOADS", "draw", "scene"]

#: the loads, all by prescribed displacement; x is a nominal strain
LOADS = ("tension", "shear", "triaxial", "mixed")


def _spheres(rng, size, count):
    """Up to ``count`` spherical holes that keep clear of the faces and of each other."""
    short = min(size)
    holes = []
    for _ in range(50 * count):
        if len(holes) == count:
            break
        r = rng.uniform(0.08, 0.2) * short
        c = [rng.uniform(r + 0.15 * short, s - r - 0.15 * short) for s in size]
        if all(math.dist(c, h[:3]) > r + h[3] + 0.1 * short for h in holes):
            holes.append((*c, r))
    return ",".join(":".join(f"{v:.4f}" for v in h) for h in holes)


def draw(seed, coarse=False):
    """The parameters of a random 3D scene.

    Parameters
    ----------
    seed : int
    coarse : bool
        Coarse meshes, about a thousand tetrahedra (840 to 1900 in the draws of
        docs/verification.md; fast samples).

    Returns
    -------
    dict
        Keyword arguments of :func:`scene` (numbers and strings), plus ``seed`` and
        ``extreme`` (the extreme drawn, or "").
    """
    rng = np.random.default_rng(seed)
    size = (rng.uniform(1.0, 2.0), rng.uniform(0.6, 1.2), rng.uniform(0.5, 1.0))
    short = min(size)
    radius = short * rng.uniform(0.05, 0.12)
    p = dict(length=round(size[0], 4), width=round(size[1], 4), height=round(size[2], 4),
             holes=_spheres(rng, size, int(rng.integers(0, 3))),
             notch=round(float(rng.uniform(0.1, 0.25) * size[2]), 4) if rng.random() < 0.5 else 0.0,
             notch_x=round(float(rng.uniform(0.3, 0.7) * size[0]), 4),
             load=str(rng.choice(LOADS)), model=str(rng.choice(list(MODELS))),
             E=float(10 ** rng.uniform(8, 11)), nu=round(float(rng.uniform(0.0, 0.45)), 3),
             critical=float(10 ** rng.uniform(-4, -2)), radius=round(radius, 5),
             maxh=round(radius * rng.uniform(0.7, 1.5), 5), overload=round(float(rng.uniform(1.5, 4.0)), 3),
             angle=round(float(rng.uniform(0, 180)), 2))
    extreme = draw_extreme(rng, p, short, huge_cells=4)
    p["maxh"] = max(p["maxh"], short / (4 if coarse else 8))     # hundreds or thousands of tetrahedra
    return {**p, "seed": int(seed), "extreme": extreme}


def _mesh(size, holes, notch, notch_x, maxh):
    """The box [0, L] x [0, W] x [0, H] (faces left/right at x, front/back at y, bottom/top
    at z), its spherical holes (``hole``) and a slot across the bottom at ``notch_x``
    (``notch``, ``notch`` deep and a quarter of that wide)."""
    L, W, H = size
    body = Box(Pnt(0, 0, 0), Pnt(L, W, H))
    for axis, low, high in ((X, "left", "right"), (Y, "front", "back"), (Z, "bottom", "top")):
        body.faces.Min(axis).name = low
        body.faces.Max(axis).name = high
    for x, y, z, r in holes:
        sphere = Sphere(Pnt(x, y, z), r)
        sphere.faces.name = "hole"
        body = body - sphere
    if notch > 0:
        slot = Box(Pnt(notch_x - notch / 8, -W, -H), Pnt(notch_x + notch / 8, 2 * W, notch))
        slot.faces.name = "notch"
        body = body - slot
    body.mat("body")
    return ng.Mesh(OCCGeometry(body).GenerateMesh(maxh=maxh))


def _check(length, width, height, holes, notch, notch_x, maxh, radius, critical, overload):
    """ValueError naming the first parameter that makes no body or no load."""
    for name, value in (("length", length), ("width", width), ("height", height), ("maxh", maxh),
                        ("radius", radius), ("critical", critical), ("overload", overload)):
        positive(name, value)
    if not 0 <= notch < height:
        raise ValueError(f"notch must be in [0, height = {height}), got {notch!r}")
    if notch > 0 and not notch / 8 < notch_x < length - notch / 8:
        raise ValueError(f"notch_x must put the slot inside (0, length = {length}), got {notch_x!r}")
    for x, y, z, r in holes:
        if not (r < x < length - r and r < y < width - r and r < z < height - r):
            raise ValueError(f"the hole {x}:{y}:{z}:{r} does not lie inside the box")


def _displacement_load(load, size, corners, angle):
    """``apply_load(prob, x)`` of a load (see :func:`scene`) on the box of ``size``; ``corners``
    the vertices at (0, 0, 0) and (0, W, 0)."""
    length, width, height = size
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))

    def apply_load(prob, x):
        if load in ("tension", "triaxial"):
            prob.add_dirichlet("left", 0.0, component="x")
            prob.add_dirichlet("right", x * length, component="x")
        if load == "tension":
            hold_gliding_ends(prob, corners)
        if load == "triaxial":
            prob.add_dirichlet("front", 0.0, component="y")
            prob.add_dirichlet("back", x * width, component="y")
            prob.add_dirichlet("bottom", 0.0, component="z")
            prob.add_dirichlet("top", x * height, component="z")
        if load in ("shear", "mixed"):
            prob.add_dirichlet("bottom", (0.0, 0.0, 0.0))
            top = (x * height, 0.0, 0.0) if load == "shear" else (c * x * height, 0.0, s * x * height)
            prob.add_dirichlet("top", top)

    return apply_load


def scene(length=1.5, width=1.0, height=0.8, holes="", notch=0.0, notch_x=0.75, load="tension", model="svk",
          E=1e9, nu=0.3, critical=1e-3, radius=0.08, maxh=0.1, overload=3.0, angle=45.0, contact=True, seed=0,
          extreme=""):
    """A box with spherical holes and an optional slot across its bottom under a displacement load.

    Parameters
    ----------
    length, width, height : float
        The box [0, length] x [0, width] x [0, height].
    holes : str
        Spherical holes ``"x:y:z:r,x:y:z:r"`` (boundary ``hole``), empty for none.
    notch : float
        Depth of a slot through the width in the bottom face at x = ``notch_x`` (a quarter
        of its depth wide); 0 for none.
    notch_x : float
    load : {"tension", "shear", "triaxial", "mixed"}
        tension: the right face pulled along x, the left held in x (both glide; the rigid
        modes this leaves held at two corners of the left face); shear: the top moved
        along x over the fixed bottom; triaxial: every pair of opposite faces pulled apart
        along its normal (gliding); mixed: the top moved at ``angle`` degrees from x in
        the x-z plane over the fixed bottom. x is the nominal strain.
    model : {"linear", "svk", "neohooke"}
    E, nu : float
    critical : float
        Critical principal strain.
    radius : float
        Critical distance.
    maxh : float
        Mesh size.
    overload : float
        The final load in units of the critical strain.
    angle : float
        Direction of the mixed load, degrees.
    contact : bool
        Contact rows between the pieces from the start (``Scene.contact``); without them a
        3D run lets pressed pieces overlap and notes it.
    seed : int
        Recorded only (the draw's seed).
    extreme : str
        Recorded only (the draw's extreme).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        An unknown load or model, or a parameter that makes no body (named), before any
        mesh is made.
    """
    if load not in LOADS:
        raise ValueError(f"load must be one of {LOADS}, got {load!r}")
    if model not in MODELS:
        raise ValueError(f"model must be one of {sorted(MODELS)}, got {model!r}")
    spheres = parse_holes(holes, dim=3)
    _check(length, width, height, spheres, notch, notch_x, maxh, radius, critical, overload)
    material = MODELS[model](E, nu)
    mesh = _mesh((length, width, height), spheres, notch, notch_x, maxh)
    corners = corner_vertices(mesh, [[0.0, 0.0, 0.0], [0.0, width, 0.0]])
    apply_load = _displacement_load(load, (length, width, height), corners, angle)
    parameters = dict(length=length, width=width, height=height, holes=holes, notch=notch, notch_x=notch_x,
                      load=load, model=model, E=E, nu=nu, critical=critical, radius=radius, maxh=maxh,
                      overload=overload, angle=angle, contact=contact, seed=seed, extreme=extreme)
    return Scene(name="random_solid", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=overload * critical, dx=critical / 4, contact_tol=1e-3 * maxh, contact=bool(contact),
                 stop_when_unloaded=True,
                 radius=radius, parameters=parameters, control={**FRONT_CONTROL, "max_steps": 30},
                 load_description="nominal strain of the box")
