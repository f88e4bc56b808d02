"""The overlap between fragments measured from the files 3D runs write, independently of the
contact code (ngfracture.output.overlap3d): at every written step at most 1e-10 of the body's
volume (tests/overlap3d_util.py).

blocks3d: two blocks pressed on each other (contact rows from the start); bar3d: a notched bar
broken in two by a crack whose lips separate.
"""
import json

import numpy as np
import pytest
from overlap3d_util import check_run_overlap

from ngfracture import Simulation, scenes
from ngfracture.output.overlap3d import fragment_overlap_volume, read_step_vtu

#: the coarse bar of tests/test_solid_resume.py
COARSE = {"maxh": 0.4, "radius": 0.2, "thickness": 0.25}


def test_every_step_of_blocks3d_keeps_the_blocks_apart(tmp_path):
    Simulation(scenes.blocks3d(), out=tmp_path, pictures="none").run()
    found = check_run_overlap(tmp_path)
    assert len(found) == 5
    assert all(ov.body_volume == 2.0 for ov in found.values())
    # the measure sees overlap where there is some: the upper block moved down by 1e-3 more
    X, U, T, f = read_step_vtu(tmp_path / "step_000004.vtu")
    upper = np.unique(T[f == f.max()])
    U[upper, 2] -= 1e-3
    moved = fragment_overlap_volume(X + U, T, f)
    # uniaxial stress D E / 2 (exact in P1, to the contact rows' 1e-8): both blocks' sides
    # stretch by nu D / 2, the interface's deformed area is (1 + nu D / 2)^2, the overlap 1e-3 times it
    D, nu = 1e-3, scenes.blocks3d().material.nu
    assert moved.volume == pytest.approx((1 + nu * D / 2) ** 2 * 1e-3, rel=1e-8)


@pytest.mark.slow
def test_every_step_of_a_broken_bar3d_keeps_its_halves_apart(tmp_path):
    result = Simulation(scenes.bar3d(**COARSE), out=tmp_path, pictures="none").run()
    assert result.reason == "broken"
    summary = json.loads((tmp_path / "summary.json").read_text())
    found = check_run_overlap(tmp_path)
    last = found[f"step_{summary['n_steps']:06d}.vtu"]
    assert summary["n_fragments"] == 2 and last.candidates > 0
