"""The critical-distance crack criterion (docs/criterion.md) against theory.

All cases are linear elastic: the measure is linear in the load, so the initiation load
is the critical strain over the largest measure at unit load.
"""
import math

import numpy as np
import pytest
import ngsolve as ng

from ngfracture.fracture import Criterion, critical_distance, nonlocal_opening, principal, toughness
from critical_distance_util import centre_crack_mesh, plate_initiation, solve_linear, tada_centre_crack
from ngfracture.mechanics.materials import LinearElastic
from ngfracture import _ngfracture as _C

E, NU, CRITICAL = 1.0, 0.25, 1e-3


def _largest(mesh, u, radius, material):
    crit = Criterion(CRITICAL, radius=radius, material=material, measure="linear")
    values, dirs = principal(crit.overstrain(mesh, u))
    k = int(np.argmax(values))
    return k, CRITICAL * values[k], dirs[k]


def test_toughness_and_distance_are_inverse():
    """K_c = E eps_c sqrt(2 pi r) (the point method on sigma_yy = K / sqrt(2 pi r))."""
    kc = toughness(CRITICAL, 0.01, 2.0)
    assert kc == pytest.approx(2.0 * CRITICAL * math.sqrt(2 * math.pi * 0.01), rel=1e-15)
    assert critical_distance(CRITICAL, kc, 2.0) == pytest.approx(0.01, rel=1e-14)
    with pytest.raises(ValueError, match="critical distance"):
        Criterion(CRITICAL, radius=-1.0)


def test_uniform_stress_gives_the_principal_value():
    """Under a uniform stress every ray sees the same tensor: the measure is its largest
    principal value (over E) and its direction, as for the one-ring criterion."""
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.1))
    mat = LinearElastic(E, NU, plane="stress")
    # uniaxial stress sigma along (cos 30, sin 30): strain known in closed form
    t = math.radians(30)
    n = np.array([math.cos(t), math.sin(t)])
    sig = np.outer(n, n)
    eps = ((1 + NU) * sig - NU * np.trace(sig) * np.eye(2)) / E
    u = ng.GridFunction(ng.VectorH1(mesh, order=1))
    u.Set(ng.CF((eps[0, 0] * ng.x + eps[0, 1] * ng.y, eps[1, 0] * ng.x + eps[1, 1] * ng.y)))
    crit = Criterion(CRITICAL, radius=0.15, material=mat, measure="linear")
    tensors = CRITICAL * crit.overstrain(mesh, u)
    values, dirs = principal(tensors)
    on_boundary = np.zeros(mesh.nv, bool)
    for el in mesh.Elements(ng.BND):
        on_boundary[[v.nr for v in el.vertices]] = True
    # interior: every crack direction is open (at a corner only those into the body are)
    hot = (values > 0) & ~on_boundary
    assert hot.any()
    # 72 directions refined by a parabola: the value within (1 - cos 2.5 deg) of 1
    assert np.all(np.abs(values[hot] - 1.0) < 1 - math.cos(math.radians(2.5)))
    assert np.all(np.abs(np.abs(dirs[hot] @ n) - 1) < 1e-3)


@pytest.fixture(scope="module")
def plate_levels():
    r = 0.02
    return r, [plate_initiation(r / k, r, notch_zone=2 * r)[0] for k in (2, 4, 8)]


def test_plate_initiation_converges(plate_levels):
    """Notch-tip h = r/2, r/4, r/8: the first-crack extension of the two finest differ by
    at most 3 % (the one-ring criterion's falls by 1/sqrt(2) per halving)."""
    r, x = plate_levels
    assert abs(x[2] - x[1]) / x[2] <= 0.03, x


@pytest.mark.parametrize("a", [0.1, 0.2])
def test_centre_crack_starts_at_the_lefm_load(a):
    """A centre crack 2a in a 1 x 2 plate under tension sigma: the crack starts when
    K_I = sigma sqrt(pi a) F(a/b) (Tada's handbook factor) reaches K_c = E eps_c sqrt(2 pi r).
    r = a / 20: the non-singular terms shift the load by about 3.6 % (docs/criterion.md);
    the tolerance is 10 %."""
    r = a / 20
    mesh, tip, _ = centre_crack_mesh(a, tip_h=r / 4, b=0.5, height=1.0)
    mat = LinearElastic(E, NU, plane="stress")
    u = _tension(mesh, mat)
    k, value, _ = _largest(mesh, u, r, mat)
    P = mesh.ngmesh.Coordinates()[:, :2]
    assert min(np.hypot(*(P[k] - [a, 0])), np.hypot(*(P[k] + [a, 0]))) < r, P[k]
    sigma_init = CRITICAL / value
    sigma_lefm = toughness(CRITICAL, r, E) / (math.sqrt(math.pi * a) * tada_centre_crack(a, 0.5))
    assert abs(sigma_init / sigma_lefm - 1) <= 0.10, (sigma_init, sigma_lefm)


def _tension(mesh, mat):
    """Traction 1 on top and bottom; rigid modes held by three point constraints on the
    symmetry lines (they carry no force: the load is self-equilibrated and symmetric)."""
    P = mesh.ngmesh.Coordinates()[:, :2]
    fes = ng.VectorH1(mesh, order=1)
    free = fes.FreeDofs()
    nv = mesh.nv
    left = int(np.argmin(np.hypot(P[:, 0] + 0.5, P[:, 1])))
    right = int(np.argmin(np.hypot(P[:, 0] - 0.5, P[:, 1])))
    bottom = int(np.argmin(np.hypot(P[:, 0], P[:, 1] + 1.0)))
    for dof in (left + nv, right + nv, bottom):      # y at the side midpoints, x at bottom centre
        free.Clear(dof)
    u, v = fes.TnT()
    eps = lambda w: ng.Sym(ng.Grad(w))
    a = ng.BilinearForm(fes, symmetric=True)
    a += (2 * mat.mu * ng.InnerProduct(eps(u), eps(v)) + mat.lam * ng.Trace(eps(u)) * ng.Trace(eps(v))) * ng.dx
    f = ng.LinearForm(fes)
    f += v[1] * ng.ds("top") - v[1] * ng.ds("bottom")
    a.Assemble()
    f.Assemble()
    gfu = ng.GridFunction(fes)
    gfu.vec.data = a.mat.Inverse(free, inverse="sparsecholesky") * f.vec
    return gfu


def _shear(mesh, gamma=1e-3):
    """Pure shear on the outer boundary: u = gamma (y, x) / 2 (pure mode II at the tips)."""
    mat = LinearElastic(E, NU, plane="stress")
    u = solve_linear(mesh, mat, "top|bottom|left|right", ng.CF((gamma * ng.y / 2, gamma * ng.x / 2)))
    return mat, u


def _line_angle(n):
    """Angle (degrees, in (-90, 90]) of the crack line, perpendicular to the opening n."""
    angle = math.degrees(math.atan2(-n[0], n[1]))
    return angle - 180 if angle > 90 else (angle + 180 if angle <= -90 else angle)


@pytest.fixture(scope="module")
def crack_r40():
    """Centre crack a = 0.1 in a 1 x 2 plate, r = a/40, h = r/4 in disks of radius 2r."""
    a = 0.1
    r = a / 40
    mesh, tip, other = centre_crack_mesh(a, tip_h=r / 4, b=0.5, height=1.0, zone=2 * r)
    return a, r, mesh


def _right_tip_direction(mesh, u, mat, a, r):
    crit = Criterion(CRITICAL, radius=r, material=mat, measure="linear")
    values, dirs = principal(crit.overstrain(mesh, u))
    P = mesh.ngmesh.Coordinates()[:, :2]
    k = int(np.argmax(np.where(P[:, 0] > 0, values, -np.inf)))
    # the crack starts at the tip or a crack-face vertex next to it
    assert np.hypot(*(P[k] - [a, 0])) < r / 2, P[k]
    return _line_angle(dirs[k])


def _westergaard_kink(a, r):
    """Angle of the largest hoop stress at distance r from the tip of a Griffith crack under
    remote shear (Westergaard's exact field, Z = tau z / sqrt(z^2 - a^2))."""
    th = np.radians(np.linspace(-120, -20, 100001))
    z = a + r * np.exp(1j * th)
    s = np.sqrt(z - a) * np.sqrt(z + a)
    Z, dZ = z / s, (s - z * z / s) / (s * s)
    y = z.imag
    sxx, syy, sxy = 2 * Z.imag + y * dZ.real, -y * dZ.real, Z.real - y * dZ.imag
    hoop = np.sin(th) ** 2 * sxx + np.cos(th) ** 2 * syy - 2 * np.sin(th) * np.cos(th) * sxy
    return math.degrees(th[np.argmax(hoop)])


def test_mode_two_kinks_at_the_maximum_hoop_stress_angle(crack_r40):
    """Pure mode II (K_II > 0 at the right tip): the crack kinks by -70.5 degrees
    (tan(theta/2) = -1/sqrt(2), maximum hoop stress of the singular field), within 5 degrees;
    and within 3 degrees of the exact field's hoop-stress maximum at distance r (-68.3 at
    r = a/40: the non-singular terms)."""
    a, r, mesh = crack_r40
    mat, u = _shear(mesh)
    angle = _right_tip_direction(mesh, u, mat, a, r)
    theory = 2 * math.degrees(math.atan(-1 / math.sqrt(2)))
    assert abs(angle - theory) <= 5.0, angle
    assert abs(angle - _westergaard_kink(a, r)) <= 3.0, (angle, _westergaard_kink(a, r))


def test_mode_one_grows_straight(crack_r40):
    """Pure mode I: the crack continues along its own line, within 5 degrees."""
    a, r, mesh = crack_r40
    mat = LinearElastic(E, NU, plane="stress")
    angle = _right_tip_direction(mesh, _tension(mesh, mat), mat, a, r)
    assert abs(angle) <= 5.0, angle


def test_scene_radius_is_checked_before_any_work():
    """A bad critical distance is named by Scene.validate (Simulation's first call)."""
    from ngfracture import scenes
    scene = scenes.plate(maxh=0.1, radius=None)
    scene.radius = -0.01
    with pytest.raises(ValueError, match="critical distance"):
        scene.validate()
    scene.radius = {"plate": float("nan")}
    with pytest.raises(ValueError, match="region 'plate'"):
        scene.validate()
    with pytest.raises(ValueError, match="radius"):
        scenes.plate(maxh=0.1, radius=0.0)


def test_a_critical_distance_scene_splits_one_vertex_per_pass_unless_told_otherwise():
    from ngfracture import scenes
    from ngfracture import Simulation, StepControl
    assert Simulation(scenes.plate(maxh=0.1, radius=None)).control.split == "spread"
    assert Simulation(scenes.plate(maxh=0.1, radius=0.05)).control.split == "one"
    assert Simulation(scenes.plate(maxh=0.1, radius=0.05), StepControl(split="spread")).control.split == "spread"
    scene = scenes.plate(maxh=0.1, radius=0.05)
    scene.control = {"split": "all"}
    assert Simulation(scene).control.split == "all"


def test_crack_tips_lead_their_zone(crack_r40):
    """Under mode I the two crack tips carry the largest measure."""
    a, r, mesh = crack_r40
    mat = LinearElastic(E, NU, plane="stress")
    crit = Criterion(CRITICAL, radius=r, material=mat, measure="linear")
    values, _ = principal(crit.overstrain(mesh, _tension(mesh, mat)))
    P = mesh.ngmesh.Coordinates()[:, :2]
    tips = np.flatnonzero(np.minimum(np.hypot(*(P - [a, 0]).T), np.hypot(*(P + [a, 0]).T)) == 0)
    assert len(tips) == 2 and int(np.argmax(values)) in tips


@pytest.mark.parametrize("distance, judged", [(1.5, False), (1.8, True)])
def test_a_hot_spot_within_27_16_r_of_a_tip_is_not_judged(crack_r40, distance, judged):
    """A sharp tip leads every vertex within 27/16 r, (3 sqrt(3)/4)^2 r: the largest angular
    factor of the mode-I opening stress across lines parallel to the crack, squared
    (docs/criterion.md). Uniform opening stress with a bump of 1.5 on the triangles around
    one vertex w at 60 degrees from the crack line: w leads its disk of radius r by its local
    value, and is judged only outside the tip's zone."""
    a, r, mesh = crack_r40
    P = mesh.ngmesh.Coordinates()[:, :2]
    target = [a + distance * r / 2, distance * r * math.sqrt(3) / 2]
    w = int(np.argmin(np.hypot(*(P - target).T)))
    d = np.hypot(*(P[w] - [a, 0]))
    assert (d > 27 / 16 * r) == judged and abs(d / r - distance) < 0.1
    T = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ng.VOL)])
    tensors = np.tile([0.0, 1.0, 0.0], (mesh.ne, 1))
    tensors[np.any(T == w, axis=1), 1] = 1.5
    values, _ = principal(nonlocal_opening(mesh, tensors, r))
    # judged: the smallest opening stress along the best ray of length r, the uniform 1
    assert values[w] == (pytest.approx(1.0, rel=1e-4) if judged else 0.0)


def test_plate_breaks_along_one_crack_from_notch_to_notch():
    """The default plate (critical distance r = 0.04, the paper's mesh size, h = r/4 along
    the line between the notch tips): broken through into two halves, with a total crack
    length within 15 % of the 0.92 from notch tip to notch tip (the required bound; a crack
    along mesh edges zigzags by about 3 %). The one-ring criterion gives 2.85 here."""
    from ngfracture import scenes
    from ngfracture import Simulation
    scene = scenes.plate()
    assert scene.radius == scenes.PLATE_RADIUS == 0.04
    result = Simulation(scene, pictures="none").run()
    assert result.reason == "broken", result.message
    assert result.summary["n_fragments"] == 2
    assert 0.92 <= result.summary["crack_length"] <= 1.15 * 0.92


@pytest.mark.parametrize("ligament, expected", [(1.0, 1 - 1.6 / 2), (3.0, 1 - 1.6 / 3)])
def test_a_ligament_thinner_than_2r_ahead_of_a_tip_is_judged_on_its_net_section(ligament, expected):
    """A crack tip at distance t from a free edge, opening stress falling linearly from 1 at
    the tip to -0.6 at the edge (a ligament in tension and bending). For t < 2r the tip is
    judged over the ligament's near half, where a linear profile has its mean: the
    net-section stress 1 - 0.8 = 0.2, whatever the bending (the point method at r alone would
    see the compressed side). For t > 2r it is the point method: the value at r, 1 - 1.6 r/t."""
    r, a = 0.02, 0.2
    t = ligament * r
    mesh, tip, _ = centre_crack_mesh(a, r / 8, b=a + t, height=0.3, maxh=0.05, zone=2.5 * r)
    x = mesh.ngmesh.Coordinates()[:, 0]
    ahead = x >= a - 1e-12
    # nodal field, linear on every triangle ahead of the tip; behind it compressed
    nodal = np.zeros((mesh.nv, 3))
    nodal[:, 1] = np.where(ahead, 1 - 1.6 * (x - a) / t, -1.0)
    values, dirs = principal(_C.CrackNonlocalOpening(mesh, nodal, np.full(mesh.nv, r), 72))
    assert values[tip] == pytest.approx(expected, abs=2e-3)
    assert abs(dirs[tip][1]) == pytest.approx(1.0, abs=1e-3)     # opening vertical: a crack straight ahead
