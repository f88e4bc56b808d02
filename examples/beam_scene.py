"""Tutorial 5's scene as a scene file: a glass beam pressed down through a steel pad.

A beam 2 x 0.5 of glass rests on two supports (gliding: u_y = 0 only) and is pressed
down in the middle of its top edge through a stiff steel pad that never cracks; the
bottom edge is stretched and cracks from below. The load parameter x is the downward
displacement of the pad's top (a length).

Run it from the command line, with any parameter changed by ``--set``::

    ngfracture run examples/beam_scene.py --set E_glass=60e9 --set critical=1.5e-4

The command line calls ``scene(**params)``; every parameter has a default.
"""
import ngsolve as ng
from netgen.geom2d import SplineGeometry

import ngfracture as nf
from ngfracture import Scene


def beam_mesh(maxh):
    """The beam (region ``glass``) with the pad (region ``steel``) bonded on top."""
    geo = SplineGeometry()
    pts = [geo.AppendPoint(*p) for p in [(0, 0), (0.1, 0), (0.2, 0), (1.8, 0), (1.9, 0), (2, 0), (2, 0.5),
                                         (1.1, 0.5), (0.9, 0.5), (0, 0.5), (0.9, 0.6), (1.1, 0.6)]]
    lines = [(0, 1, "bottom", 1, 0), (1, 2, "support_left", 1, 0), (2, 3, "bottom", 1, 0),
             (3, 4, "support_right", 1, 0), (4, 5, "bottom", 1, 0), (5, 6, "side", 1, 0),
             (6, 7, "top", 1, 0), (7, 8, "pad_contact", 1, 2), (8, 9, "top", 1, 0), (9, 0, "side", 1, 0),
             (8, 10, "pad_side", 0, 2), (10, 11, "pad_top", 0, 2), (11, 7, "pad_side", 0, 2)]
    for a, b, name, left, right in lines:
        geo.Append(["line", pts[a], pts[b]], bc=name, leftdomain=left, rightdomain=right)
    geo.SetMaterial(1, "glass")
    geo.SetMaterial(2, "steel")
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def scene(maxh=0.06, E_glass=70e9, nu_glass=0.22, E_steel=200e9, nu_steel=0.3, critical=2e-4,
          load_max=2e-3, dx=5e-5, contact_tol=1e-5):
    """The beam of tutorial 5.

    Parameters
    ----------
    maxh : float
        Mesh size.
    E_glass, nu_glass : float
        The beam's St Venant-Kirchhoff material (plane stress).
    E_steel, nu_steel : float
        The pad's linear-elastic material (plane stress); the pad never cracks.
    critical : float
        Critical principal strain of the glass.
    load_max : float
        Final downward displacement of the pad's top (a length).
    dx : float
        First increment of the load.
    contact_tol : float
        Precision threshold of collision detection (a length).

    Returns
    -------
    Scene
    """
    materials = {"glass": nf.StVenantKirchhoff(E=E_glass, nu=nu_glass, plane="stress"),
                 "steel": nf.LinearElastic(E=E_steel, nu=nu_steel, plane="stress")}

    def apply_load(problem, x):
        problem.add_dirichlet(["support_left", "support_right"], 0.0, component="y")
        problem.add_dirichlet("pad_top", (0.0, -x))

    return Scene(name="beam", mesh=beam_mesh(maxh), material=materials, critical={"glass": critical},
                 apply_load=apply_load, load_max=load_max, dx=dx, contact_tol=contact_tol,
                 stop_when_unloaded=True,
                 load_description="downward displacement of the pad's top (length)",
                 parameters={"maxh": maxh, "E_glass": E_glass, "nu_glass": nu_glass, "E_steel": E_steel,
                             "nu_steel": nu_steel, "critical": critical, "load_max": load_max, "dx": dx})
