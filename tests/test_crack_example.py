"""The crack example runs headless and writes a VTK file that matches the cracked mesh."""
import os
import sys

import numpy as np
import ngsolve

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "examples"))
import crack_plate  # noqa: E402

from ngfracture.fracture.fragments import FragmentStatistics  # noqa: E402


def test_crack_plate_example(tmp_path):
    mesh, u, history, path, result = crack_plate.main(str(tmp_path), maxh=0.06, critical=6.5e-3,
                                                      max_passes=6)
    assert os.path.exists(path)
    import pyvista as pv
    g = pv.read(path)
    assert g.n_points == mesh.nv and g.n_cells == mesh.ne
    assert np.array_equal(np.asarray(g.point_data["displacement"])[:, :2],
                          u.vec.FV().NumPy().reshape(2, -1)[:, :mesh.nv].T)
    assert sum(history) > 0                        # cracks opened at the hole
    L = ngsolve.Integrate(1, mesh, ngsolve.BND, definedon=mesh.Boundaries("crack"))
    assert L > 0.1
    # reference area is conserved to the last bit: splitting keeps every triangle and
    # coordinate, so the math.fsum of the triangle areas is the uncracked plate's
    before = FragmentStatistics(crack_plate.plate_with_hole(0.06)).total_area
    assert FragmentStatistics(mesh).total_area == before
    assert mesh.ne == crack_plate.plate_with_hole(0.06).ne
    # the polygonal hole is inscribed in the circle: area a little above 1 - pi r^2
    assert 0 < before - (1 - np.pi * 0.01) < 2e-3


if __name__ == "__main__":
    import pytest as _pytest
    raise SystemExit(_pytest.main([__file__, "-q"]))
