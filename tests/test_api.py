"""The public API: what ``import ngfracture as nf`` gives, and a scene's criterion from a
critical distance, a toughness, or neither (the paper's mesh-dependent one-ring strain)."""
import math
import warnings

import pytest

import ngfracture as nf
from ngfracture.fracture import critical_distance, toughness
from ngfracture.run.simulation import MeshDependentCriterion


def test_the_top_level_is_the_public_api():
    for name in ("Simulation", "Scene", "StepControl", "scenes", "Ensemble", "ElasticProblem",
                 "LinearElastic", "StVenantKirchhoff", "NeoHookean"):
        assert name in nf.__all__ and hasattr(nf, name), name
    # no C++ kernels and no imported third-party modules at the top level
    assert not {"ElementAreas", "VertexAverage", "ngsolve", "np"} & set(dir(nf))
    assert all(not n.startswith("_") or n == "__version__" for n in nf.__all__)


def test_a_toughness_gives_the_critical_distance_of_the_point_method():
    """K_c = E eps_c sqrt(2 pi r): a scene with the toughness of radius r judges at r."""
    r = 0.04
    E, critical = nf.scenes.GLASS["E"], nf.scenes.GLASS["critical"]
    scene = nf.scenes.plate(maxh=0.1, radius=None)
    scene.toughness = toughness(critical, r, E)
    radii = scene.validate().radius
    assert radii == {"plate": pytest.approx(r, rel=1e-14)}
    assert critical_distance(critical, scene.toughness, E) == pytest.approx(r, rel=1e-14)


def test_a_toughness_run_equals_the_run_with_its_critical_distance():
    r = 0.04
    E, critical = nf.scenes.GLASS["E"], nf.scenes.GLASS["critical"]
    by_radius = nf.scenes.plate(maxh=0.06, radius=r)
    by_toughness = nf.scenes.plate(maxh=0.06, radius=r)      # the same mesh (refined for r)
    by_toughness.radius, by_toughness.toughness = None, toughness(critical, r, E)
    a = nf.Simulation(by_radius, pictures="none").run().summary
    b = nf.Simulation(by_toughness, pictures="none").run().summary
    assert b["criterion"]["kind"] == "critical_distance"
    assert b["criterion"]["radius"]["plate"] == pytest.approx(r, rel=1e-14)
    for key in ("reason", "n_steps", "n_split_vertices", "n_fragments"):
        assert a[key] == b[key], key
    assert math.isclose(a["crack_length"], b["crack_length"], rel_tol=1e-9)


def test_radius_and_toughness_together_or_for_a_region_that_never_cracks_are_refused():
    scene = nf.scenes.plate(maxh=0.1)
    scene.toughness = 1e6
    with pytest.raises(ValueError, match="not both"):
        scene.validate()
    scene.radius, scene.critical = None, {"plate": None}
    with pytest.raises(ValueError, match="no region can crack"):
        scene.validate()
    scene.critical, scene.toughness = nf.scenes.GLASS["critical"], {"nowhere": 1e6}
    with pytest.raises(ValueError, match="region 'nowhere'"):
        scene.validate()


def test_a_scene_without_a_critical_distance_warns_once_and_says_so_in_the_summary():
    scene = nf.scenes.plate(maxh=0.1, radius=None)
    with pytest.warns(MeshDependentCriterion, match="depend on the mesh"):
        sim = nf.Simulation(scene, nf.StepControl(max_steps=1), pictures="none")
    with warnings.catch_warnings():
        warnings.simplefilter("error")              # run() does not warn again
        summary = sim.run().summary
    assert summary["criterion"]["kind"] == "one_ring"
    assert "depend on the mesh" in summary["criterion"]["note"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")              # a critical distance: no warning
        nf.Simulation(nf.scenes.plate(maxh=0.1), nf.StepControl(max_steps=1), pictures="none")


def test_a_run_reports_every_accepted_step_as_data():
    steps = []
    result = nf.Simulation(nf.scenes.plate(maxh=0.1), nf.StepControl(max_steps=3),
                           pictures="none").run(on_step=steps.append)
    assert [s.state.step for s in steps] == [1, 2, 3]
    assert [s.record for s in steps] == result.state.history
    assert steps[-1].state is result.state
    for s in steps:
        assert s.problem.mesh.nv == len(s.state.arrays.points) and s.fragments.count >= 1
