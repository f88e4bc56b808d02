"""Fracture under force, and the load-displacement curve through its peak (LEFM checks).

* Edge-cracked strip (SENT) under an end traction: the crack starts at the LEFM load of
  Tada's geometry factor with the criterion's toughness K_c = E eps_c sqrt(2 pi r), and
  the run ends broken at that load: under a dead load the crack runs on through the
  ligament at fixed load, and the loaded end comes off (two fragments).
* Notched beam in three-point bending (SENB, growth resolved in load): the peak of the
  load-displacement curve is the LEFM load of the SENB factor, and past the peak the
  force follows the LEFM load of the grown crack, one split event per step.
"""
import csv
import math

import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters, Pnt

import ngfracture as nf
from ngfracture.scenes import senb_factor

E, NU, EPS = 1e9, 0.3, 1e-3


def tada_sent(alpha):
    """Tada's geometry factor of a single edge crack in a strip under tension (0.5 % for a/W < 0.6)."""
    return 0.265 * (1 - alpha) ** 4 + (0.857 + 0.265 * alpha) / (1 - alpha) ** 1.5


def sent_scene(a=0.3, r=0.02, h=0.005, height=3.0, band=0.1):
    """Strip of width 1, a slit-like V-notch of depth a at mid-height, clamped bottom,
    traction E x on top; the mesh is h = r/4 in a band of half-width ``band`` (5 r) along
    the ligament, where the crack runs: the criterion reads the stress at r from the tip,
    which triangles larger than r do not resolve (a crack that leaves the band for
    triangles of 0.1 = 5 r sprouts side branches there)."""
    geo = SplineGeometry()
    c = height / 2
    corners = [(0, 0), (1, 0), (1, height), (0, height), (0, c + 0.004), (a, c), (0, c - 0.004)]
    names = ["bottom", "right", "top", "left", "notch", "notch", "left"]
    pts = [geo.AppendPoint(x, y, maxh=h) if (x, y) == (a, c) else geo.AppendPoint(x, y) for x, y in corners]
    for i, name in enumerate(names):
        geo.Append(["line", pts[i], pts[(i + 1) % len(pts)]], bc=name, **({"maxh": h} if name == "notch" else {}))
    mp = MeshingParameters(maxh=0.1)
    for y in np.arange(c - band, c + band + 1e-9, 2 * h):
        mp.RestrictHLine(p1=Pnt(a - r, y, 0), p2=Pnt(1, y, 0), maxh=h)

    def apply_load(prob, x):
        prob.add_dirichlet("bottom", (0.0, 0.0))
        prob.add_traction("top", (0.0, E * x))

    x_lefm = EPS * math.sqrt(2 * r / a) / tada_sent(a)       # sigma sqrt(pi a) F = E eps sqrt(2 pi r)
    scene = nf.Scene(name="sent", mesh=ng.Mesh(geo.GenerateMesh(mp=mp)), material=nf.LinearElastic(E, NU, plane="stress"),
                     critical=EPS, apply_load=apply_load, load_max=2 * x_lefm, dx=x_lefm / 4, contact_tol=1e-6, radius=r)
    return scene, x_lefm


def test_an_edge_cracked_strip_under_traction_breaks_at_the_lefm_load():
    scene, x_lefm = sent_scene()
    steps = []
    result = nf.Simulation(scene, pictures="none").run(on_step=steps.append)
    first = next(s for s in steps if s.record["split_vertices"])
    assert abs(first.state.x / x_lefm - 1) <= 0.05, first.state.x / x_lefm
    assert result.reason == "broken", result.message
    assert result.state.x == first.state.x             # no equilibrium at that load any more
    assert "lost its support" in result.message        # the crack ran through: the top came off
    assert result.summary["n_fragments"] == 2
    piece = result.problem.fragments()[1]                # per vertex
    top, bottom = (set(piece[np.unique(result.problem.arrays.boundary_segments(name))]) for name in ("top", "bottom"))
    assert len(top) == len(bottom) == 1 and top != bottom     # the loaded end is apart from the clamped one
    assert result.summary["area_final"] == result.summary["area_initial"]


@pytest.fixture(scope="module")
def senb(tmp_path_factory):
    out = tmp_path_factory.mktemp("senb")
    scene = nf.scenes.beam(radius=0.02, maxh=0.1)
    return scene, nf.Simulation(scene, out=out).run(), out


def test_the_senb_peak_is_the_lefm_load(senb):
    scene, result, _ = senb
    history = result.summary["history"]
    force = np.array([-h["boundaries"]["load"]["force"][1] for h in history])
    assert abs(force.max() / scene.parameters["lefm_peak_load"] - 1) <= 0.10, force.max()
    assert all(h["split_vertices"] <= 1 for h in history)          # one event per step
    assert history[int(np.argmax(force))]["split_vertices"] == 1    # the peak is a crack event


def test_past_the_peak_the_force_follows_the_lefm_load_of_the_grown_crack(senb):
    scene, result, out = senb
    p = scene.parameters
    kc = p["E"] * p["critical"] * math.sqrt(2 * math.pi * p["radius"])
    ratios = [(-h["boundaries"]["load"]["force"][1]) / (kc / (4 * senb_factor(p["notch"] + h["crack_length"])))
              for h in result.summary["history"] if h["split_vertices"] and h["crack_length"] <= 0.15]
    assert len(ratios) >= 10
    assert all(abs(r - 1) <= 0.15 for r in ratios), ratios
    # snap-back: past the peak the crack grows at deflections below the peak's, which
    # displacement control with growth at fixed load would jump over
    force = [-h["boundaries"]["load"]["force"][1] for h in result.summary["history"]]
    x = [h["x"] for h in result.summary["history"]]
    peak = int(np.argmax(force))
    assert min(x[peak + 1:]) < x[peak]
    rows = list(csv.reader((out / "force_displacement.csv").open()))
    assert "load_Fy" in rows[0] and len(rows) == 1 + result.summary["n_steps"]


def test_a_bar_on_tetrahedra_under_an_end_traction_breaks_at_its_critical_load():
    """Force control in 3D: the notched bar of ``bar3d`` pulled by a traction on its right end
    cracks at the load where its most overstrained vertex is just critical (the overstrain
    grows in proportion to the load to 1e-4: St Venant-Kirchhoff at strains of 1e-4), and
    under the dead load the crack runs on through the ligament: the run ends broken at that
    load. Before, the critical load's search read the displacement as a 2D one and every
    step after the first failed."""
    from ngfracture.run.growth import CRITICAL_MARGIN
    from ngfracture.scenes.solids import corner_vertices, hold_gliding_ends
    bar = nf.scenes.bar3d(maxh=0.4, radius=0.2, thickness=0.25)
    corners = corner_vertices(bar.mesh, [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])

    def pull(prob, x):
        prob.add_dirichlet("left", 0.0, component="x")
        prob.add_traction("right", (x, 0.0, 0.0))
        hold_gliding_ends(prob, corners)

    scene = nf.Scene(name="bar3d_traction", mesh=bar.mesh, material=bar.material, critical=bar.critical,
                     apply_load=pull, load_max=1e7, dx=2.5e5, contact_tol=bar.contact_tol, stop_when_unloaded=True,
                     radius=bar.radius, control=bar.control)
    result = nf.Simulation(scene, pictures="none").run()
    first, cracked = result.summary["history"][:2]
    assert first["split_vertices"] == 0 and cracked["split_vertices"] > 0
    critical_load = first["x"] / first["overstrain"]
    assert cracked["x"] == pytest.approx(critical_load * (1 + CRITICAL_MARGIN), rel=1.5 * CRITICAL_MARGIN)
    assert result.reason == "broken" and result.summary["load"] == cracked["x"]
