"""Random scenes for stress tests: rectangles with holes and a notch under random loads.

Nobody wrote these scenes by hand, so they meet the code where its authors did not look:

    params = draw(seed)            # plain numbers and strings, reproducible from the seed
    result = Simulation(scene(**params)).run()

:func:`scene` is an ordinary scene function, so a case can be replayed from the command
line: ``ngfracture run ngfracture.studies.random_scenes:scene --set width=2.38 ...``.
:func:`draw` mixes ordinary cases with extremes: a mesh four times coarser than the
critical distance, a critical distance of the body's size, nu = 0.499 in plane strain,
a critical strain of 0.3, loads 40 times past the first crack.
``benchmarks/random_scenes.py`` runs many and tallies how each ended;
``tests/test_random_scenes.py`` runs a few in every test run.
"""
import math

import numpy as np
import ngsolve as ng
from netgen.geom2d import SplineGeometry

from ..mechanics.materials import LinearElastic, NeoHookean, StVenantKirchhoff
from ..run.scene import Scene

__all__ = ["LOADS", "MODELS", "EXTREMES", "draw", "draw_extreme", "scene", "parse_holes"]

#: the loads, all by prescribed displacement; x is a nominal strain
LOADS = ("tension", "shear", "biaxial", "mixed")
MODELS = {"linear": LinearElastic, "svk": StVenantKirchhoff, "neohooke": NeoHookean}
#: the extremes draw() puts into about a third of the cases
EXTREMES = ("coarse_mesh", "huge_radius", "incompressible", "large_critical", "overload")


def _holes(rng, width, height, count):
    """Up to ``count`` holes that keep clear of the edges and of each other."""
    holes = []
    short = min(width, height)
    for _ in range(50 * count):
        if len(holes) == count:
            break
        r = rng.uniform(0.05, 0.18) * short
        x, y = rng.uniform(r + 0.15 * short, width - r - 0.15 * short), rng.uniform(r + 0.15 * short, height - r - 0.15 * short)
        if all(math.hypot(x - a, y - b) > r + c + 0.1 * short for a, b, c in holes):
            holes.append((x, y, r))
    return ",".join(f"{x:.4f}:{y:.4f}:{r:.4f}" for x, y, r in holes)


def draw(seed, coarse=False):
    """The parameters of a random scene.

    Parameters
    ----------
    seed : int
    coarse : bool
        Meshes of at most a few hundred triangles (fast samples).

    Returns
    -------
    dict
        Keyword arguments of :func:`scene` (numbers and strings), plus ``seed`` and
        ``extreme`` (the extreme drawn, or "").
    """
    rng = np.random.default_rng(seed)
    width, height = rng.uniform(1.0, 2.5), rng.uniform(0.6, 1.5)
    short = min(width, height)
    radius = short * rng.uniform(0.03, 0.1)
    p = dict(width=round(width, 4), height=round(height, 4),
             holes=_holes(rng, width, height, int(rng.integers(0, 4))),
             notch=round(float(rng.uniform(0.05, 0.15) * height), 4) if rng.random() < 0.5 else 0.0,
             notch_x=round(float(rng.uniform(0.3, 0.7) * width), 4),
             load=str(rng.choice(LOADS)), model=str(rng.choice(list(MODELS))),
             plane=str(rng.choice(["stress", "strain"])),
             E=float(10 ** rng.uniform(8, 11)), nu=round(float(rng.uniform(0.0, 0.45)), 3),
             critical=float(10 ** rng.uniform(-4, -2)), radius=round(radius, 5),
             maxh=round(radius * rng.uniform(0.5, 1.5), 5), overload=round(float(rng.uniform(1.5, 4.0)), 3),
             angle=round(float(rng.uniform(0, 180)), 2))
    extreme = draw_extreme(rng, p, short, huge_cells=6)
    p["maxh"] = max(p["maxh"], short / (12 if coarse else 40))   # a few hundred or thousand triangles
    return {**p, "seed": int(seed), "extreme": extreme}


def draw_extreme(rng, p, short, huge_cells):
    """Draw the extreme of about a third of the cases and apply it to the parameters ``p``
    (changed in place): a mesh four times coarser than the critical distance, a critical
    distance of the body's ``short`` size (on ``huge_cells`` elements across it), nu = 0.499
    (in plane strain where ``p`` has a plane), a critical strain of 0.3, 40 times the load.

    Parameters
    ----------
    rng : numpy.random.Generator
    p : dict
        A draw's parameters (``maxh``, ``radius``, ``nu``, ``critical``, ``overload``).
    short : float
        The body's shortest side.
    huge_cells : int

    Returns
    -------
    str
        The extreme drawn (one of :data:`EXTREMES`), or "".
    """
    extreme = str(rng.choice(EXTREMES)) if rng.random() < 1 / 3 else ""
    if extreme == "coarse_mesh":
        p["maxh"] = round(4 * p["radius"], 5)
    elif extreme == "huge_radius":
        p["radius"], p["maxh"] = round(short, 5), round(short / huge_cells, 5)
    elif extreme == "incompressible":
        p["nu"] = 0.499
        if "plane" in p:
            p["plane"] = "strain"
    elif extreme == "large_critical":
        p["critical"] = 0.3
    elif extreme == "overload":
        p["overload"] = 40.0
    return extreme


def parse_holes(holes, dim=2):
    """Holes from their text form ``"x:y:r,x:y:r"`` (circles) or, with ``dim=3``,
    ``"x:y:z:r,x:y:z:r"`` (spheres).

    Parameters
    ----------
    holes : str
        Empty for none.
    dim : {2, 3}
        The coordinates of a centre.

    Returns
    -------
    list of tuple of float
        The centre's coordinates and the radius of every hole.

    Raises
    ------
    ValueError
        A hole that is not ``dim + 1`` numbers with r > 0, or ``dim`` not 2 or 3.
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    form = ":".join("xyz"[:dim]) + ":r"
    kind = "a hole" if dim == 2 else "a spherical hole"
    out = []
    for item in filter(None, holes.split(",")):
        try:
            values = tuple(float(v) for v in item.split(":"))
        except ValueError:
            values = ()
        if len(values) != dim + 1:
            raise ValueError(f"{kind} must be {form}, got {item!r}")
        if not values[-1] > 0:
            raise ValueError(f"a hole's radius must be > 0, got {item!r}")
        out.append(values)
    return out


def _mesh(width, height, holes, notch, notch_x, maxh):
    """The rectangle, its holes (boundary ``hole``) and a V-notch in the bottom edge."""
    geo = SplineGeometry()
    bottom = [(0, 0)]
    if notch > 0:
        w = notch / 2
        bottom += [(notch_x - w, 0), (notch_x, notch), (notch_x + w, 0)]
    corners = bottom + [(width, 0), (width, height), (0, height)]
    pts = [geo.AppendPoint(x, y) for x, y in corners]
    names = ["bottom"] * (len(bottom)) + ["right", "top", "left"]
    for i, name in enumerate(names):
        geo.Append(["line", pts[i], pts[(i + 1) % len(pts)]], bc=name, leftdomain=1, rightdomain=0)
    for x, y, r in holes:
        geo.AddCircle((x, y), r, leftdomain=0, rightdomain=1, bc="hole")
    geo.SetMaterial(1, "body")
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def scene(width=2.0, height=1.0, holes="", notch=0.0, notch_x=1.0, load="tension", model="svk", plane="stress",
          E=1e9, nu=0.3, critical=1e-3, radius=0.05, maxh=0.05, overload=3.0, angle=45.0, seed=0, extreme=""):
    """A rectangle with holes and an optional bottom-edge notch under a displacement load.

    Parameters
    ----------
    width, height : float
        The rectangle [0, width] x [0, height].
    holes : str
        Holes ``"x:y:r,x:y:r"`` (boundary ``hole``), empty for none.
    notch : float
        Depth (= width) of a V-notch in the bottom edge at ``notch_x``; 0 for none.
    notch_x : float
    load : {"tension", "shear", "biaxial", "mixed"}
        tension: the right edge pulled along x, the left held in x; shear: the top moved
        along x over the fixed bottom; biaxial: tension in x and y; mixed: the top moved at
        ``angle`` degrees over the fixed bottom. x is the nominal strain.
    model : {"linear", "svk", "neohooke"}
    plane : {"stress", "strain"}
    E, nu : float
    critical : float
        Critical principal strain.
    radius : float
        Critical distance.
    maxh : float
        Mesh size.
    overload : float
        The final load in units of the critical strain (where a uniform body would crack).
    angle : float
        Direction of the mixed load, degrees.
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
        An unknown load or model, or a bad number.
    """
    if load not in LOADS:
        raise ValueError(f"load must be one of {LOADS}, got {load!r}")
    if model not in MODELS:
        raise ValueError(f"model must be one of {sorted(MODELS)}, got {model!r}")
    material = MODELS[model](E, nu, plane=plane)
    mesh = _mesh(width, height, parse_holes(holes), notch, notch_x, maxh)
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))

    def apply_load(prob, x):
        if load in ("tension", "biaxial"):
            prob.add_dirichlet("left", 0.0, component="x")
            prob.add_dirichlet("right", x * width, component="x")
        if load == "biaxial":
            prob.add_dirichlet("bottom", 0.0, component="y")
            prob.add_dirichlet("top", x * height, component="y")
        if load in ("shear", "mixed"):
            prob.add_dirichlet("bottom", (0.0, 0.0))
            prob.add_dirichlet("top", (x * height, 0.0) if load == "shear" else (c * x * height, s * x * height))

    parameters = dict(width=width, height=height, holes=holes, notch=notch, notch_x=notch_x, load=load,
                      model=model, plane=plane, E=E, nu=nu, critical=critical, radius=radius, maxh=maxh,
                      overload=overload, angle=angle, seed=seed, extreme=extreme)
    return Scene(name="random", mesh=mesh, material=material, critical=critical, apply_load=apply_load,
                 load_max=overload * critical, dx=critical / 4, contact_tol=1e-3 * maxh, stop_when_unloaded=True,
                 radius=radius, parameters=parameters, control={"max_steps": 40},
                 load_description="nominal strain of the rectangle")
