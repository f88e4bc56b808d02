"""Random strength (ngfracture.fracture.strength): Weibull moments, weakest-link size effect, reproducibility,
and a random field carried through splits and a resume."""
import math

import numpy as np
import pytest

from ngfracture import scenes
from ngfracture.fracture import strength
from ngfracture import Simulation, StepControl


@pytest.mark.parametrize("m", [3.0, 6.0])
def test_weibull_moments_of_1e5_draws(m):
    """Mean and variance of 1e5 draws within 1 % of scale Gamma(1+1/m) and its variance.

    Relative standard errors at n = 1e5: mean 0.11 % (m = 3) and 0.06 % (m = 6); variance
    sqrt((kurtosis - 1) / n) = 0.42 % and 0.45 %, so 1 % is more than 2 of them.
    """
    scale = 2.5e-4
    s = strength.weibull_strength(100_000, m, scale, seed=12345)
    mean, var = strength.weibull_mean(m, scale), strength.weibull_variance(m, scale)
    print(f"m={m}: mean error {s.mean() / mean - 1:.2e}, variance error {s.var() / var - 1:.2e}")
    assert abs(s.mean() / mean - 1) < 0.01
    assert abs(s.var() / var - 1) < 0.01
    assert np.all(s > 0) and np.all(np.isfinite(s))


def test_weakest_link_size_effect_of_the_mean_strength():
    """Scale of area A: scale (A_ref / A)^(1/m); the weakest of k vertices of area a has the strength
    of one area k a; means within 5 % of theory."""
    m, scale, a_ref = 6.0, 1.0, 0.01
    n, k = 60_000, 8
    a = 0.04                                    # four reference areas per vertex
    s = strength.weibull_strength(n, m, scale, seed=7, areas=np.full(n, a), reference_area=a_ref)
    expected = strength.weibull_mean(m, scale * (a_ref / a) ** (1 / m))
    assert abs(s.mean() / expected - 1) < 0.05
    weakest = s.reshape(-1, k).min(axis=1)      # patches of k vertices, area k a
    expected_patch = strength.weibull_mean(m, scale * (a_ref / (k * a)) ** (1 / m))
    assert abs(weakest.mean() / expected_patch - 1) < 0.05
    # the size effect itself: the patch is weaker than one vertex by k^(1/m)
    assert abs(s.mean() / weakest.mean() / k ** (1 / m) - 1) < 0.05


def test_same_seed_same_field_bit_for_bit_and_pcg64_stream_pinned():
    a = strength.weibull_strength(1000, 8.0, 1e-4, seed=3)
    b = strength.weibull_strength(1000, 8.0, 1e-4, seed=3)
    c = strength.weibull_strength(1000, 8.0, 1e-4, seed=4)
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)
    # the uniforms are PCG64's raw stream (its published algorithm, the same everywhere)
    raw = np.random.PCG64(3).random_raw(1)
    v = (int(raw[0]) >> 12) * 2.0 ** -52 + 2.0 ** -53
    assert a[0] == 1e-4 * math.pow(-math.log(v), 1 / 8.0)


def test_bad_weibull_parameters_are_refused():
    with pytest.raises(ValueError, match="weibull_m"):
        strength.weibull_strength(10, 0.0, 1.0, seed=0)
    with pytest.raises(ValueError, match="seed"):
        strength.weibull_strength(10, 2.0, 1.0, seed=-1)
    with pytest.raises(ValueError, match="reference area"):
        strength.weibull_strength(10, 2.0, 1.0, seed=0, reference_area=1.0)
    with pytest.raises(ValueError, match="seed has no effect without weibull_m"):
        scenes.plate(maxh=0.2, seed=3, radius=None)


def test_plate_scene_records_the_field_and_the_default_keeps_the_mean():
    """Default scale: the mean strength is the uniform critical strain (within the sampling error
    of the plate's vertices, 3 standard errors)."""
    sc = scenes.plate(maxh=0.1, weibull_m=8, seed=5, radius=None)
    p = sc.parameters
    assert p["seed"] == 5 and p["weibull_m"] == 8.0 and p["weibull_area"] is None
    assert p["strength_digest"] == strength.field_digest(sc.strength)
    assert math.isclose(strength.weibull_mean(8, p["weibull_scale"]), scenes.GLASS["critical"], rel_tol=1e-12)
    sd = math.sqrt(strength.weibull_variance(8, p["weibull_scale"]) / sc.mesh.nv)
    assert abs(sc.strength.mean() - scenes.GLASS["critical"]) < 3 * sd
    assert scenes.plate(maxh=0.1, radius=None).strength is None       # uniform by default


def test_split_copies_inherit_the_strength_and_a_resume_is_bitwise(tmp_path):
    """A random-strength plate: the split mesh's field is its vertex's; a run stopped and resumed
    ends with the same mesh, displacement and strength bit for bit."""
    scene = lambda: scenes.plate(maxh=0.15, weibull_m=8, seed=2, radius=None)
    control = dict(max_steps=14)
    full = Simulation(scene(), control=StepControl(**control), contact="never").run()
    st = full.state
    assert full.summary["n_split_vertices"] > 0
    nv0 = scene().mesh.nv
    assert np.array_equal(st.strength[:nv0], scene().strength)
    # every copy sits where a vertex of the initial mesh sat, and has its strength
    p0 = st.arrays.points[:nv0]
    for i in range(nv0, len(st.strength)):
        j = np.flatnonzero(np.all(p0 == st.arrays.points[i], axis=1))
        assert len(j) == 1 and st.strength[i] == st.strength[j[0]]
    out = tmp_path / "run"
    Simulation(scene(), control=StepControl(**{**control, "max_steps": 8}), out=out, pictures="none",
               contact="never").run()
    resumed = Simulation(scene(), control=StepControl(**control), out=out, resume=True, pictures="none",
                         contact="never").run()
    assert resumed.state.strength.tobytes() == st.strength.tobytes()
    assert resumed.state.u.tobytes() == st.u.tobytes()
    assert resumed.state.arrays.points.tobytes() == st.arrays.points.tobytes()
