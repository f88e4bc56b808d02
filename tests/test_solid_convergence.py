"""The initiation load of the 3D critical-distance criterion converges under refinement near the front.

The issue's check: the initiation load changes by at most 3 % between the two finest of four
refinements near the notch or crack front (docs/solid.md, "Convergence of initiation in 3D").
The point method judges the stress at the critical distance r from the front, a quantity of
the continuum that the mesh approaches as h / r -> 0 (docs/criterion.md's 2D table: 0.7 %
and 0.5 % over the last two halvings); the bound is the issue's 3 %.

* The plane-strain bar of tests/test_solid_lefm.py (structured graded box, through edge
  crack opened on mesh faces, front on mesh edges, linear material): h = r/2, r/3, r/4, r/6
  (slow: 12 s).
* The scene ``bar3d`` on netgen meshes (a notch slot 0.4 deep, 0.02 wide, r = 0.08, its root corners
  re-entrant edges of 270 degrees), thinned to 0.1 to stay small: ``fine`` = r/2 ... r/5 (and
  r/6, r/8 in the slow case), the scene's own material and criterion
  (``studies.initiation.initiation_load``). Also checked: the small-strain scaling of the St
  Venant-Kirchhoff estimate against LinearElastic at the coarsest level (6e-6 measured; bound 1e-3,
  above the Green-Lagrange terms, of the order of the strain, below 1e-4 at x = 1e-5), and
  that the load is reached at the notch root, across the notch plane.
"""
import numpy as np
import pytest
from test_solid_lefm import RADIUS, cracked_bar, initiation_3d

import ngfracture as nf
from ngfracture.scenes import bar3d
from ngfracture.scenes.common import BAR_RADIUS
from ngfracture.studies.initiation import initiation_load

#: the bound on the change between the two finest of four levels
BOUND = 0.03
#: bar3d's notch depth
NOTCH = 0.4


def changes(loads):
    """Relative change of every level against the one before it."""
    loads = np.asarray(loads)
    return np.abs(np.diff(loads)) / loads[1:]


def bar_levels(divisions, thickness=0.1, maxh=0.25):
    """Initiation of bar3d(fine = r / k) for every k with the scene's material; at the coarsest
    level also with linear elasticity of the same E and nu."""
    rows = []
    for k in divisions:
        scene = bar3d(maxh=maxh, fine=BAR_RADIUS / k, thickness=thickness, notch=NOTCH)
        svk = initiation_load(scene, 1e-5)
        linear = None
        if k == divisions[0]:
            scene.material = nf.LinearElastic(scene.material.E, scene.material.nu)
            linear = initiation_load(scene, 1e-5).load
        rows.append((k, len(scene.mesh.ngmesh.Elements3D()), svk, linear))
    return rows


def check_bar(rows):
    loads = [r[2].load for r in rows]
    for k, ne, init, linear in rows:
        print(f"bar3d thickness 0.1, fine = r/{k}: {ne} tets, x_c {init.load:.5e} (linear {linear}) "
              f"at {np.round(init.position, 4)}, direction {np.round(init.direction, 3)}")
    print("changes between levels:", np.round(changes(loads), 4))
    assert changes(loads)[-1] <= BOUND
    assert abs(rows[0][2].load / rows[0][3] - 1) <= 1e-3
    for _, _, init, _ in rows:
        # the notch root (x = 1 +- 0.01, y = NOTCH), opening across the notch plane
        assert abs(init.position[0] - 1.0) <= 0.0101 and abs(init.position[1] - NOTCH) <= 1e-9
        assert abs(init.direction[0]) >= np.cos(np.radians(10))


def test_bar3d_initiation_converges_near_the_notch_front():
    check_bar(bar_levels([2, 3, 4, 5]))


@pytest.mark.slow
def test_bar3d_initiation_converges_to_r_over_8():
    check_bar(bar_levels([2, 3, 4, 5, 6, 8]))


@pytest.mark.slow
def test_plane_strain_bar_initiation_converges():
    loads = []
    for k in (2, 3, 4, 6):
        x_c, values, _, front = initiation_3d(cracked_bar(RADIUS / k, np.array([0.0, 0.05, 0.1])), True)
        assert values.argmax() in front
        loads.append(x_c)
    print("plane-strain bar, h = r/2, r/3, r/4, r/6: x_c", " ".join(f"{x:.5e}" for x in loads),
          "changes", np.round(changes(loads), 4))
    assert changes(loads)[-1] <= BOUND
