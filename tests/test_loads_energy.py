"""The work of every kind of load, reaction forces and the load-displacement curve.

On an uncracked linear body the external work equals the elastic energy (the trapezoid
rule is exact for forces and displacements linear in the load); the boundary resultants
balance (the reaction of the support equals minus the applied load); after cracking the
released energy W - U is what cracking dissipated, never negative.
"""
import csv

import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import SplineGeometry

import ngfracture as nf

E, NU = 1e9, 0.3


def strip_mesh(maxh=0.25, notch=0.0, width=1.0, height=2.0):
    """The strip; with ``notch`` > 0 a V-notch of that depth (opening 0.02) in its left edge
    at mid-height, refined to maxh / 4 at its tip."""
    geo = SplineGeometry()
    corners = [(0, 0), (width, 0), (width, height), (0, height)]
    names = ["bottom", "right", "top", "left"]
    if notch > 0:
        corners += [(0, height / 2 + 0.01), (notch, height / 2), (0, height / 2 - 0.01)]
        names += ["left", "left", "left"]
    pts = [geo.AppendPoint(x, y, maxh=maxh / 4) if (x, y) == (notch, height / 2) else geo.AppendPoint(x, y)
           for x, y in corners]
    for i, name in enumerate(names):
        geo.Append(["line", pts[i], pts[(i + 1) % len(pts)]], bc=name)
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def strip_scene(load, critical=5e-3, radius=0.1, maxh=0.25, notch=0.0):
    """A 1 x 2 strip, bottom clamped, loaded on top (or by its weight) in proportion to x."""
    def apply_load(prob, x):
        prob.add_dirichlet("bottom", (0.0, 0.0))
        if load == "traction":
            prob.add_traction("top", (0.2 * E * x, E * x))
        elif load == "body":
            prob.add_body_force((0.0, E * x))
        elif load == "displacement":
            prob.add_dirichlet("top", (0.0, 2.0 * x))

    return nf.Scene(name=f"strip-{load}", mesh=strip_mesh(maxh, notch), material=nf.LinearElastic(E, NU, plane="stress"),
                    critical=critical, apply_load=apply_load, load_max=1e-3, dx=2.5e-4, contact_tol=1e-6,
                    radius=radius)


@pytest.mark.parametrize("load", ["traction", "body", "displacement"])
def test_external_work_equals_elastic_energy_on_an_uncracked_linear_body(load):
    result = nf.Simulation(strip_scene(load), pictures="none").run()
    assert result.reason == "load_max" and result.summary["n_split_vertices"] == 0
    for h in result.summary["history"]:
        assert h["external_work"] == pytest.approx(h["elastic_energy"], rel=1e-8), h["step"]
        assert h["elastic_energy"] > 0


def test_the_support_carries_the_traction_and_the_curve_is_written(tmp_path):
    result = nf.Simulation(strip_scene("traction"), out=tmp_path).run()
    for h in result.summary["history"]:
        top, bottom = h["boundaries"]["top"], h["boundaries"]["bottom"]
        applied = np.array([0.2 * E * h["x"], E * h["x"]]) * 1.0       # traction times the width 1
        np.testing.assert_allclose(top["force"], applied, rtol=1e-12)
        np.testing.assert_allclose(np.add(top["force"], bottom["force"]), 0.0, atol=1e-9 * abs(applied[1]))
        assert bottom["displacement"] == [0.0, 0.0] and top["displacement"][1] > 0
    rows = list(csv.reader((tmp_path / "force_displacement.csv").open()))
    assert rows[0][:2] == ["step", "x"] and "top_Fy" in rows[0] and len(rows) == 1 + result.summary["n_steps"]
    assert (tmp_path / "force_displacement.png").stat().st_size > 0
    assert result.summary["pictures"]["force_displacement"] == "force_displacement.png"


def test_released_energy_after_cracking_under_traction_is_never_negative():
    """An edge-notched strip pulled by a traction until it cracks: W = U + released, and
    the released energy grows from 0 (cracks only dissipate)."""
    scene = strip_scene("traction", critical=2e-4, radius=0.05, maxh=0.1, notch=0.3)
    scene.load_max = 4e-4
    scene.dx = 5e-5
    result = nf.Simulation(scene, nf.StepControl(max_steps=30), pictures="none").run()
    history = result.summary["history"]
    assert any(h["split_vertices"] for h in history), result.message
    scale = max(h["external_work"] for h in history)
    released = [h["released_energy"] for h in history]
    for h in history:
        assert h["external_work"] == pytest.approx(h["elastic_energy"] + h["released_energy"], abs=1e-12 * scale)
    assert min(released) >= -1e-8 * scale
    assert all(b >= a - 1e-8 * scale for a, b in zip(released, released[1:]))
