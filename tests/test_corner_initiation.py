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
import numpy as np
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


@pytest.mark.parametrize("radius", [RADIUS, 0.1])
def test_a_concave_corner_cracks_first_at_its_critical_load(radius):
    """At radius 0.1 (Winkler's concrete: (K_c / f_t)^2 / (2 pi) = 0.054 m on the 0.5 m
    panel) the end of the clamped foot is more overstrained than the concave corner, 1.27
    times, and no rule cuts it (its crack line runs along the clamp, rule 2a): the event is
    the corner's, at its own critical load, and the step notes the vertex left out. Before,
    the step took its whole increment (3.5 times the corner's critical load) and cracked
    in many places at once."""
    mesh = l_panel()
    material = nf.LinearElastic(25.85e9, 0.18, plane="stress")
    scene = nf.Scene(name="l_panel", mesh=mesh, material=material, critical=CRITICAL, apply_load=pull,
                     load_max=2e9, dx=5e7, contact_tol=1e-3 * FINE, radius=radius, stop_when_unloaded=True)
    # linear elasticity: the criterion's measure grows in proportion to the load
    prob = ElasticProblem(mesh, material)
    pull(prob, 1.0)
    assert prob.solve(fix_free_modes=True).converged
    measure = principal(scene.criterion().overstrain(mesh, prob.u, arrays=prob.arrays))[0]
    points = prob.arrays.points
    corner, clamp_end = (int(np.flatnonzero(np.all(points == p, axis=1))[0]) for p in ((0.5, 0.5), (0.5, 0.0)))
    assert measure.argmax() == (corner if radius == RADIUS else clamp_end)
    critical_load = 1.0 / measure[corner]
    result = nf.Simulation(scene, nf.StepControl(max_steps=1), pictures="none").run()
    (step,) = result.summary["history"]
    assert step["split_vertices"] > 0
    if radius == RADIUS:
        assert not step["notes"], step["notes"]
    else:
        (note,) = step["notes"]
        assert note.startswith("1 vertex overstrained at x = ") and "split by no rule (2 2a: 1): left out" in note
    assert step["x"] == pytest.approx(critical_load * (1 + CRITICAL_MARGIN), rel=1.5 * CRITICAL_MARGIN)
    # the crack runs from the corner (at radius 0.1 on into the leg at the same load: force control)
    assert any(abs(t["position"][0] - 0.5) + abs(t["position"][1] - 0.5) < 2 * FINE for t in step["tips"]), step["tips"]
