"""A crack from a concave corner starts there, at its critical load.

The L-shaped panel (Winkler's test, 500 mm scaled to 1): the leg's foot clamped, the arm's
end pulled up by a traction on a short pad (force control). The re-entrant corner is the
strongest concentration; netgen meshes a 270 degree corner with few triangles, here none
of its interior edges within 30 degrees of the crack line, so the crack enters on the edge
nearest the crack line's half into the body (rule 2d). Without that rule the corner split
nothing, the step took its whole increment (six times the critical load) and the panel
cracked in four places at once.
"""
import ngsolve as ng
import pytest
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters

import ngfracture as nf
from ngfracture.fracture.strain import principal
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.run.growth import CRITICAL_MARGIN

FINE, RADIUS, CRITICAL = 0.015, 0.04, 1e-4


def l_panel():
    geo = SplineGeometry()
    corners = [(0, 0), (0.5, 0), (0.5, 0.5), (0.93, 0.5), (0.95, 0.5), (1, 0.5), (1, 1), (0, 1)]
    names = ["foot", "leg", "arm_bottom", "pad", "arm_bottom", "arm_end", "top", "left"]
    points = [geo.AppendPoint(*p) for p in corners]
    for i, name in enumerate(names):
        geo.Append(["line", points[i], points[(i + 1) % len(points)]], bc=name)
    mp = MeshingParameters(maxh=0.05)
    for i in range(int(1 / FINE) + 1):
        for j in range(int(1 / FINE) + 1):
            mp.RestrictH(x=i * FINE, y=j * FINE, z=0, h=FINE)
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def pull(prob, x):
    prob.add_dirichlet("foot", (0.0, 0.0))
    prob.add_traction("pad", (0.0, x))


def test_a_concave_corner_cracks_first_at_its_critical_load():
    mesh = l_panel()
    material = nf.LinearElastic(25.85e9, 0.18, plane="stress")
    scene = nf.Scene(name="l_panel", mesh=mesh, material=material, critical=CRITICAL, apply_load=pull,
                     load_max=2e9, dx=5e7, contact_tol=1e-3 * FINE, radius=RADIUS, stop_when_unloaded=True)
    # linear elasticity: the criterion's measure grows in proportion to the load
    prob = ElasticProblem(mesh, material)
    pull(prob, 1.0)
    assert prob.solve(fix_free_modes=True).converged
    measure = principal(scene.criterion().overstrain(mesh, prob.u, arrays=prob.arrays))[0]
    corner = prob.arrays.points[measure.argmax()]
    assert tuple(corner) == (0.5, 0.5)
    critical_load = 1.0 / measure.max()
    result = nf.Simulation(scene, nf.StepControl(max_steps=1), pictures="none").run()
    (step,) = result.summary["history"]
    assert step["split_vertices"] > 0 and not step["notes"], step["notes"]
    assert step["x"] == pytest.approx(critical_load * (1 + CRITICAL_MARGIN), rel=1.5 * CRITICAL_MARGIN)
    first = step["tips"][0]["position"] if step["tips"] else None
    assert first is not None and abs(first[0] - 0.5) + abs(first[1] - 0.5) < 2 * FINE
