"""The initiation load of the 3D critical-distance criterion converges under refinement near the front.

The issue's check: the initiation load changes by at most 3 % between the two finest of four
refinements near the notch or crack front (docs/solid.md, "Convergence of initiation in 3D").
The point method judges the stress at the critical distance r from the front, a quantity of
the continuum that the mesh approaches as h / r -> 0 (docs/criterion.md's 2D table: 0.7 %
and 0.5 % over the last two halvings); the bound is the issue's 3 %.

* The plane-strain bar of tests/test_solid_lefm.py (structured graded box, through edge
  crack opened on mesh faces, front on mesh edges, linear material): h = r/2, r/3, r/4, r/6
  (12 s).
* ``studies.initiation.initiation_load`` on the scene ``bar3d``: the small-strain scaling of
  its St Venant-Kirchhoff estimate against LinearElastic of the same E and nu (bound 1e-3,
  above the Green-Lagrange terms, of the order of the strain, below 1e-4 at x = 1e-5).
  bar3d's slot notch does not converge (its root corners, re-entrant edges of 270 degrees,
  are judged over the sphere: docs/solid.md, "Convergence of initiation in 3D"), so it is
  not a convergence check here.
"""
import numpy as np
import pytest
from test_solid_lefm import RADIUS, cracked_bar, initiation_3d

import ngfracture as nf
from ngfracture.scenes import bar3d
from ngfracture.scenes.common import BAR_RADIUS
from ngfracture.studies.initiation import initiation_load

#: the issue's bound on the change between the two finest levels
BOUND = 0.03


def changes(loads):
    """Relative change of every level against the one before it."""
    loads = np.asarray(loads)
    return np.abs(np.diff(loads)) / loads[1:]


def test_initiation_load_of_the_scene_material_scales_as_linear_elasticity():
    scene = bar3d(maxh=0.25, fine=BAR_RADIUS / 2, thickness=0.1)
    svk = initiation_load(scene, 1e-5)
    scene.material = nf.LinearElastic(scene.material.E, scene.material.nu)
    linear = initiation_load(scene, 1e-5)
    print(f"bar3d thickness 0.1, fine = r/2: x_c {svk.load:.5e} (linear {linear.load:.5e})")
    assert svk.load == pytest.approx(linear.load, rel=1e-3)


def test_plane_strain_bar_initiation_converges():
    loads = []
    for k in (2, 3, 4, 6):
        x_c, values, _, front = initiation_3d(cracked_bar(RADIUS / k, np.array([0.0, 0.05, 0.1])), True)
        assert values.argmax() in front
        loads.append(x_c)
    print("plane-strain bar, h = r/2, r/3, r/4, r/6: x_c", " ".join(f"{x:.5e}" for x in loads),
          "changes", np.round(changes(loads), 4))
    assert changes(loads)[-1] <= BOUND
