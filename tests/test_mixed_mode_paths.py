"""Mixed-mode crack paths against linear elastic fracture mechanics.

* An edge crack inclined at 45 degrees in a strip pulled apart (gliding grips): the crack
  kinks and turns perpendicular to the load.
* A beam in three-point bending with its notch off the load's line: the crack curves
  towards the load.

The reference is the path of the maximum hoop stress criterion with SIFs from an
independent solve at each increment (:mod:`ngfracture.studies.lefm_path`); the
simulation's crack (critical distance r, the mesh r/4 within 5 r of the reference path)
follows it within a mean distance of 2 r, as one crack (no junction, one tip at most).

* The built-in ``holed_beam``: the offset notch with a hole beside the path; the crack
  passes the hole, drawn towards it, and keeps one tip.

The inclined crack and the offset notch run twice: meshed fine where the reference says
the crack runs, and from a coarse mesh (maxh 0.1 = 5 r, the crack's own path meshed coarse
too) refined ahead of the tip as it grows (Scene.refine, r/4): the same bound without
knowing the path.

The crack graph is read from the run's last VTU and VTP files (:mod:`vtk_crack_util`)."""
import math

import numpy as np
import pytest

import ngfracture as nf
from ngfracture.studies.lefm_path import cracked_polygon, edge_crack_path
from vtk_crack_util import final_files, read_crack_graph, side_branches

E, NU, EPS, R = 1e9, 0.3, 1e-3, 0.02
WIDTH, HEIGHT = 1.0, 2.0


#: the LEFM references by case: a test that runs twice (band, refined) computes one
REFERENCES = {}


def lefm_reference(case, *args, **kwargs):
    """edge_crack_path(*args, **kwargs), computed once per case."""
    if case not in REFERENCES:
        REFERENCES[case] = edge_crack_path(*args, **kwargs)
    return REFERENCES[case]


def grips(prob, x=1e-3):
    prob.add_dirichlet("bottom", 0.0, component="y")
    prob.add_dirichlet("top", x, component="y")


def distance_to_polyline(points, polyline):
    """The distance of each point to a polyline."""
    a, b = polyline[:-1], polyline[1:]
    d = b - a
    t = np.clip(((points[:, None, :] - a) * d).sum(-1) / (d * d).sum(-1), 0, 1)
    nearest = a + t[..., None] * d
    return np.hypot(*(points[:, None, :] - nearest).transpose(2, 0, 1)).min(axis=1)


def band(path, r):
    """Local mesh sizes r/4 within 5 r of a polyline."""
    sizes = []
    for a, b in zip(path[:-1], path[1:]):
        for s in np.arange(0, 1, r / (2 * np.linalg.norm(b - a))):
            p = a + s * (b - a)
            sizes += [(p[0] + i * r / 2, p[1] + j * r / 2, r / 4) for i in range(-10, 11, 2) for j in range(-10, 11, 2)]
    return sizes


def simulated_path(scene, start, out):
    """The crack a scene grows from ``start``: its points past the start, its graph, the result."""
    result = nf.Simulation(scene, out=out, pictures="none").run()
    graph = read_crack_graph(*final_files(out))
    on_crack = graph["points"][graph["degree"] > 0]
    grown = on_crack[distance_to_polyline(on_crack, start) > 1e-9]
    return grown, graph, result


def band_scene(corners, names, start, reference, apply_load, load_max, refine=False):
    """The body with its edge crack, meshed at r/4 within 5 r of the reference path, or
    (refine) at 0.1 everywhere and refined ahead of the tip during the run."""
    mesh = cracked_polygon(corners, names, start, 0.1, 0.1) if refine else \
        cracked_polygon(corners, names, start, 0.1, R / 4, band(reference, R))
    return nf.Scene(name="mixed", mesh=mesh, material=nf.LinearElastic(E, NU, plane="stress"), critical=EPS,
                    apply_load=apply_load, load_max=load_max, dx=load_max / 32, contact_tol=1e-6, radius=R,
                    stop_when_unloaded=True, refine=refine or None)


def check_one_crack(grown, graph, r):
    """A crack of more than 20 points with at most one tip, no junction and no short side branch."""
    assert len(grown) > 20
    assert len(graph["junctions"]) == 0 and len(graph["tips"]) <= 1 and not side_branches(graph, r)


@pytest.mark.slow
@pytest.mark.parametrize("refine", [False, True], ids=["band", "refined"])
def test_an_inclined_edge_crack_follows_the_maximum_hoop_stress_path(tmp_path, refine):
    start = np.array([[0.0, 1.0], [0.2 * math.cos(math.pi / 4), 1.0 + 0.2 * math.sin(math.pi / 4)]])
    corners = [(0.0, 0.0), (WIDTH, 0.0), (WIDTH, HEIGHT), (0.0, HEIGHT), tuple(start[0])]
    names = ["bottom", "right", "top", "left", "left"]
    reference = lefm_reference("inclined", corners, names, start, grips, E, NU, da=0.02, steps=60, maxh=0.1,
                               h_tip=0.002)
    assert len(reference.points) > 20
    scene = band_scene(corners, names, start, reference.points, lambda prob, x: grips(prob, x), 4 * EPS, refine)
    grown, graph, result = simulated_path(scene, start, tmp_path / "out")
    distance = distance_to_polyline(grown, reference.points)
    print(f"inclined ({'refined' if refine else 'band'}): mean distance {distance.mean() / R:.3f} r, max {distance.max() / R:.3f} r, {len(grown)} points, "
          f"tips {len(graph['tips'])}, junctions {len(graph['junctions'])}, {result.reason}")
    check_one_crack(grown, graph, R)
    assert distance.mean() < 2 * R


def beam_outline(mouth, pad=0.05, span=(0.2, 3.8), length=4.0, height=1.0):
    """A beam in three-point bending: supports at ``span`` under it, the pad at mid-span on top."""
    s0, s1 = span
    corners = [(0.0, 0.0), (s0 - pad, 0.0), (s0 + pad, 0.0), (mouth, 0.0), (s1 - pad, 0.0), (s1 + pad, 0.0),
               (length, 0.0), (length, height), (length / 2 + pad, height), (length / 2 - pad, height), (0.0, height)]
    names = ["bottom", "support_left", "bottom", "bottom", "support_right", "bottom", "right", "top", "load", "top",
             "left"]
    return corners, names


def three_point_bending(prob, x=1e-3):
    prob.add_dirichlet("support_left", (0.0, 0.0))
    prob.add_dirichlet("support_right", 0.0, component="y")
    prob.add_dirichlet("load", -x, component="y")


@pytest.mark.slow
@pytest.mark.parametrize("refine", [False, True], ids=["band", "refined"])
def test_an_offset_notch_in_three_point_bending_curves_to_the_load_as_lefm_says(tmp_path, refine):
    corners, names = beam_outline(mouth=1.5)
    start = np.array([[1.5, 0.0], [1.5, 0.2]])
    reference = lefm_reference("offset", corners, names, start, three_point_bending, E, NU, da=0.02, steps=60,
                               maxh=0.1, h_tip=0.002)
    assert len(reference.points) > 20
    scene = band_scene(corners, names, start, reference.points, lambda prob, x: three_point_bending(prob, x), 4e-3,
                       refine)
    grown, graph, result = simulated_path(scene, start, tmp_path / "out")
    grown = grown[grown[:, 1] <= reference.points[:, 1].max()]      # as far as the reference goes
    distance = distance_to_polyline(grown, reference.points)
    print(f"offset notch ({'refined' if refine else 'band'}): mean distance {distance.mean() / R:.3f} r, max {distance.max() / R:.3f} r, "
          f"{len(grown)} points, tips {len(graph['tips'])}, junctions {len(graph['junctions'])}, {result.reason}, "
          f"reference from {reference.points[1]} to {reference.points[-1]}")
    check_one_crack(grown, graph, R)
    assert distance.mean() < 2 * R


@pytest.mark.slow
def test_a_crack_passing_a_hole_keeps_one_tip_and_the_lefm_path(tmp_path):
    scene = nf.scenes.holed_beam()
    p, pad, mid = scene.parameters, 0.05, 2.2
    mouth = mid - p["notch_offset"]
    corners = [(0.0, 0.0), (0.2 - pad / 2, 0.0), (0.2 + pad / 2, 0.0), (mouth, 0.0), (4.2 - pad / 2, 0.0),
               (4.2 + pad / 2, 0.0), (4.4, 0.0), (4.4, 1.0), (mid + pad / 2, 1.0), (mid - pad / 2, 1.0), (0.0, 1.0)]
    names = ["bottom", "support_left", "bottom", "bottom", "support_right", "bottom", "right", "top", "load", "top",
             "left"]
    holes = [(x + mid, y, radius) for x, y, radius in p["holes"]]
    start = np.array([[mouth, 0.0], [mouth, p["notch"]]])
    reference = lefm_reference("holed", corners, names, start, three_point_bending, p["E"], p["nu"], da=0.02,
                               steps=60, maxh=0.1, h_tip=0.002, holes=holes)
    assert len(reference.points) > 20
    grown, graph, result = simulated_path(scene, start, tmp_path / "out")
    grown = grown[grown[:, 1] <= reference.points[:, 1].max()]
    distance = distance_to_polyline(grown, reference.points)
    hole_distance = min(np.hypot(*(grown - hole[:2]).T).min() - hole[2] for hole in np.array(holes))
    print(f"holed beam: mean distance {distance.mean() / scene.radius:.3f} r, max {distance.max() / scene.radius:.3f} "
          f"r, closest to the hole {hole_distance:.3f}, {len(grown)} points, tips {len(graph['tips'])}, "
          f"junctions {len(graph['junctions'])}, {result.reason}")
    check_one_crack(grown, graph, scene.radius)
    assert distance.mean() < 2 * scene.radius
