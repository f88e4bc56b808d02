"""Hertz contact in 3D: a sphere pressed on a flat block, node-to-face rows of both passes.

Setup (a quarter model, symmetry planes x = 0 and y = 0 with u_x = 0 / u_y = 0 there):

- the block [0, L]^2 x [-L, 0], its bottom clamped;
- the "sphere": the box [0, L]^2 x [0, L] whose bottom face is mapped onto the sphere of
  radius R touching the block at the origin, z -> z + f(r) (1 - z / L) with
  f(r) = R - sqrt(R^2 - r^2) (the top stays flat); its top is pushed down by delta;
- one linear elastic material for both, so Hertz's effective modulus is
  E* = E / (2 (1 - nu^2)) and R* = R.

Meshes are structured (:func:`ngfracture.geometry.structured.box_mesh`, graded tensor grids:
uniform cells of h up to 1.3 a_target from the contact point, then growing by 1.5 per
cell), different in the two bodies (block h = a_target / 10, sphere h = a_target / 9),
meshed apart and merged (no shared vertices; the two vertices at the origin are twins).

Candidates. Hertz starts from a point contact: at the reference configuration only the
origin touches. The candidates are the pairs the detection finds with the sphere moved
down rigidly by a search distance s = 2 delta (the nodes within 2 sqrt(R delta) of the
axis, about 2 a), as rows of :func:`ngfracture.contact.rows3d.node_to_face_rows` at the
reference coordinates: their gaps g > 0 are the reference distances. Every vertex of the
two contact surfaces (the block's top, the sphere's bottom) is a slave (two passes, which
pass the patch test; one pass does not); vertices of the symmetry planes below the block's
top that the moved sphere reaches (its bottom reaches z = -2 delta) are not, and rows whose
master is not a face of the other contact surface are dropped: where the search distance
exceeds the cell size, vertices of the sphere's symmetry faces sink more than a cell into
the block and the detection gives some of them the block's symmetry faces as masters
(normals along x or y), rows that would hold the sphere sideways against the symmetry
planes (measured at a_t / 13: 19 such rows, the centre lifted off).
The rows are not re-linearised: delta / R = 2.5e-3, the normals turn by at most a / R.

Active set: the primal-dual update of :class:`ngfracture.contact.active_set.ActiveSet`,
as the patch test of tests/test_contact3d.py runs it, started from the sphere translated
by -delta / 2 (equal bodies share the approach; the set then enters about the Hertz zone
instead of twice its area, 4 rounds instead of 9 at a / 7); the update decides the set.

Measurements, for the force F the rows carry (4 x the quarter's):

- contact radius: half-way between the largest radius of a slave node whose row is active
  and the smallest radius of a candidate slave whose gap at the solution exceeds h^2 / R
  (h the larger fine cell size). Both surfaces are piecewise linear on different meshes: in
  the contact zone the sphere's vertices are active on the block's faces and the block's
  vertices sit within the chord error (about h^2 / (8 R), measured 1e-6 to 5e-6 at a / 10)
  off the sphere's faces, neither active nor open. The discrete contact edge lies in the
  bracket, so the estimate is within h / 2 of it (measured bracket at a / h = 10.4 and 9.4:
0.980 to 1.022 a_H). Against
  a_H = (3 F R / (4 E*))^(1/3): the issue's 5 %;
- peak pressure: the force of all rows at the origin's vertex over its consistent nodal
  area, for each body, and their mean, against p0 = 3 F / (2 pi a_H^2): the issue's 10 %.
  With two passes the rows split the interface force between the two surfaces' nodes; the
  patch test makes each side's nodal force its consistent load of a uniform pressure, not
  of a varying one. At the origin the two rows are one row reversed (the twins at the
  contact point); the redundancy removal keeps the block's, and the sphere's centre vertex
  gets that row's force only. Measured at a / h = 10.4 (block) and 9.4 (sphere): block
  +6.5 %, sphere -14 %, mean -3.8 %; the per-side values approach Hertz from both sides as
  h falls (a / h = 4, 7, 10: block +23, +10, +6.5 %; sphere -31, -19, -14 %), the mean stays
  within 5 %. The mean and the block's value are asserted; the sphere's is printed.

Hertz's half-space theory is compared through the measured F, so the bodies' bulk
compliance (finite size L = 8 a_target) does not enter the check, only the finite size's
effect on the contact stresses (order (a / L)^2).
"""
import math
from dataclasses import replace

import numpy as np
import pytest

from ngfracture.contact.active_set import ActiveSet, Candidates, Geometry
from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.rows3d import node_to_face_rows
from ngfracture.contact.solver import space_columns_3d
from ngfracture.geometry.solid import nodal_areas
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import merge_bodies, solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

E, NU, R = 1.0, 0.3, 1.0
A_TARGET = 0.05                     # Hertz's a for the prescribed approach, a^2 = R delta
DELTA = A_TARGET ** 2 / R
L = 8 * A_TARGET
E_STAR = E / (2 * (1 - NU ** 2))


def graded(h, fine, length, growth=1.5):
    """0, h, 2h, ... up to ``fine``, then cells growing by ``growth`` up to ``length`` (the last point)."""
    x = list(np.arange(0.0, fine + 0.5 * h, h))
    while x[-1] < length:
        h *= growth
        x.append(x[-1] + h)
    x[-1] = length if x[-2] < length else x[-1]
    return np.array(x)


def hertz_bodies(h_block, h_sphere):
    """The block (region 1, fragment 0) and the sphere (region 2, fragment 1), merged.

    Boundary names: box_mesh's prefixed by "block_" / "sphere_"."""
    gb, gs = graded(h_block, 1.3 * A_TARGET, L), graded(h_sphere, 1.3 * A_TARGET, L)
    block = box_mesh(gb, gb, -gb[::-1])
    sphere = box_mesh(gs, gs, gs)
    P = sphere.points.copy()
    r2 = P[:, 0] ** 2 + P[:, 1] ** 2
    P[:, 2] += (R - np.sqrt(R ** 2 - r2)) * (1.0 - P[:, 2] / L)
    P[P[:, 2] == 0.0, 2] = 0.0                    # no -0.0
    sphere = replace(sphere, points=P)
    return merge_bodies([("block", block), ("sphere", sphere)])


def contact_offset(prob):
    offset = 0
    for C, _, label in prob.constraints.rows:
        if label == "contact":
            return offset
        offset += C.shape[0]
    return offset


def solve_hertz(h_block, h_sphere, rounds=12):
    """The Hertz problem solved by the primal-dual active set; see the module docstring.

    Returns the arrays, sphere mask, rows, displacement, multipliers (0: not imposed) and
    the history [(rows imposed, rows released)] of the rounds."""
    a = hertz_bodies(h_block, h_sphere)
    X = a.points
    fragment = a.regions - 1
    sphere = np.zeros(len(X), dtype=bool)
    sphere[a.tets[fragment == 1].ravel()] = True
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("block_zmin", 0.0)
    prob.add_dirichlet("sphere_zmax", -DELTA, component="z")
    prob.add_dirichlet(["block_xmin", "sphere_xmin"], 0.0, component="x")
    prob.add_dirichlet(["block_ymin", "sphere_ymin"], 0.0, component="y")
    search = np.zeros_like(X)
    search[sphere, 2] = -2 * DELTA
    surface = np.isin(a.face_bc, [a.bc_names.index(b) + 1 for b in ("block_zmax", "sphere_zmin")])
    contact = np.zeros(len(X), dtype=bool)                 # the block's top, the sphere's bottom
    contact[a.faces[surface]] = True
    pen = detect_penetrations_3d(X, a.tets, a.faces, fragment, displacement=search)
    rows = node_to_face_rows(X, a.faces, pen, slave=contact)
    rows = rows.subset(surface[rows.face])                 # masters on the other contact surface only
    keys = rows.keys()
    U = np.zeros_like(X)
    U[sphere, 2] = -DELTA / 2                      # the first guess: half the approach
    fixed = prob.assemble_constraints().fixed_dofs
    n = prob.fes.ndof // 3
    active = ActiveSet(Geometry(arrays=a, fragment=fragment, seams=None, fixed=(fixed // n) * len(X) + fixed % n),
                       tol=0.0, penetration_tol=1e-12)
    history = []
    for _ in range(rounds):
        gap = rows.C @ U.T.ravel() + rows.g
        want, kept, _ = active.primal_dual(Candidates(rows, keys, gap))
        if active.solved and history and set(keys[i] for i in kept) == set(active.multipliers):
            break
        prob.constraints.clear_rows("contact")
        sub = rows.subset(kept)
        prob.constraints.add_rows(space_columns_3d(sub.C, sub.nv, n), -sub.g, label="contact")
        status = prob.solve(method="full")
        assert status.converged, status.message
        lam = status.multipliers[contact_offset(prob):][:len(kept)]
        history.append((len(kept), active.record(keys, kept, lam, 0.0)))
        U = vertex_displacement(prob.u)
    else:
        raise AssertionError(f"the active set did not settle: {history}")
    lam = np.array([active.multipliers.get(k, 0.0) for k in keys])
    return a, sphere, rows, U, lam, history, prob


def measure(a, sphere, rows, U, lam, h):
    """Force, contact radius (bracket and estimate) and centre pressure of both bodies.

    h: the larger fine cell size; gaps below h^2 / R are the chord error of two
    piecewise linear surfaces of curvature below 1 / R, not an opening."""
    X = a.points
    force = -(rows.C.T @ lam).reshape(3, -1)
    F_block, F_sphere = -4 * math.fsum(force[2, ~sphere]), 4 * math.fsum(force[2, sphere])
    r = np.hypot(X[rows.slave, 0], X[rows.slave, 1])
    gap = rows.C @ U.T.ravel() + rows.g
    on, open_ = lam < 0, gap > h ** 2 / R
    a_in, a_out = r[on].max(), r[open_].min()
    centre = {}
    for name, side, sign in (("block", ~sphere, -1.0), ("sphere", sphere, 1.0)):
        surface = a.faces[a.face_bc == a.bc_names.index(("block_zmax", "sphere_zmin")[name == "sphere"]) + 1]
        area = nodal_areas(X, surface)
        v = int(np.flatnonzero(side & np.all(X == 0.0, axis=1))[0])
        centre[name] = sign * force[2, v] / area[v]
    return dict(p0_mean=0.5 * (centre['block'] + centre['sphere']), F=F_block, F_sphere=F_sphere, a_in=a_in, a_out=a_out, a=0.5 * (a_in + a_out), p0=centre)


def hertz(F):
    """Hertz's contact radius and peak pressure for the force F (sphere R on a flat, E*)."""
    a = (3 * F * R / (4 * E_STAR)) ** (1 / 3)
    return a, 3 * F / (2 * math.pi * a ** 2)


def support_force(a, prob, name):
    """The z force of the support on the quarter's boundary ``name``: the sum of K u there."""
    n = prob.fes.ndof // 3
    verts = np.unique(a.faces[a.face_bc == a.bc_names.index(name) + 1])
    return math.fsum(-prob.out_of_balance()[2 * n + verts])        # out of balance: -K u


def test_coarse_hertz_rows_are_in_equilibrium_with_the_supports():
    """A coarse mesh (a spans 4 elements, below the issue's 8): no Hertz check, but the
    invariants that hold at any mesh: the rows' forces on the two bodies are equal and
    opposite, equal to the support reactions (static equilibrium of each quarter body, to
    the solver's tolerance), compressive, and the solution satisfies every candidate row."""
    a, sphere, rows, U, lam, history, prob = solve_hertz(A_TARGET / 4, A_TARGET / 3)
    m = measure(a, sphere, rows, U, lam, A_TARGET / 3)
    top, bottom = support_force(a, prob, "sphere_zmax"), support_force(a, prob, "block_zmin")
    print(f"\ncoarse Hertz: rounds {history}, F = {m['F']:.6e}, supports {4 * top:.6e} {4 * bottom:.6e}")
    assert m["F"] > 0 and m["F_sphere"] == pytest.approx(m["F"], rel=1e-12)
    assert -4 * top == pytest.approx(m["F"], rel=1e-8) and 4 * bottom == pytest.approx(m["F"], rel=1e-8)
    assert np.all(lam <= 0) and np.any(lam < 0)
    gap = rows.C @ U.T.ravel() + rows.g
    assert gap.min() >= -1e-12
    assert np.all(np.abs(gap[lam < 0]) <= 1e-12)


@pytest.mark.slow
def test_hertz_contact_radius_and_peak_pressure():
    h_block, h_sphere = A_TARGET / 10, A_TARGET / 9
    a, sphere, rows, U, lam, history, _ = solve_hertz(h_block, h_sphere)
    m = measure(a, sphere, rows, U, lam, max(h_block, h_sphere))
    a_h, p0_h = hertz(m["F"])
    print(f"\nHertz 3D: rounds {history}, candidates {len(rows)}, active {np.count_nonzero(lam < 0)}")
    print(f"F = {m['F']:.6e} (sphere side {m['F_sphere']:.6e}), Hertz delta(F) = {a_h ** 2 / R:.4e} vs {DELTA:.4e}")
    print(f"a: active up to {m['a_in']:.5f}, inactive from {m['a_out']:.5f}, estimate {m['a']:.5f}, "
          f"Hertz {a_h:.5f}, ratio {m['a'] / a_h:.4f}; a / h = {m['a'] / h_block:.2f}, {m['a'] / h_sphere:.2f}")
    print(f"p0: block {m['p0']['block']:.5f}, sphere {m['p0']['sphere']:.5f}, Hertz {p0_h:.5f}, "
          f"ratios {m['p0']['block'] / p0_h:.4f}, {m['p0']['sphere'] / p0_h:.4f}, mean {m['p0_mean'] / p0_h:.4f}")
    assert m["F"] > 0 and m["F_sphere"] == pytest.approx(m["F"], rel=1e-10)     # the rows are in equilibrium
    assert np.all(lam <= 0)
    assert min(m["a"] / h_block, m["a"] / h_sphere) >= 8                        # a spans at least 8 elements
    assert m["a_out"] > m["a_in"]                                               # one contact edge
    assert abs(m["a"] / a_h - 1) <= 0.05
    # peak pressure: the mean of the two bodies' nodal pressures at the contact point (the
    # two-pass rows split the force between the surfaces; see the module docstring), and
    # the block's alone; the sphere's alone is printed, 14 % low at this mesh (docs/contact.md)
    assert abs(m["p0_mean"] / p0_h - 1) <= 0.10
    assert abs(m["p0"]["block"] / p0_h - 1) <= 0.10
    # no vertex of either body inside the other beyond the faceted surfaces' resolution h^2 / R
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, a.regions - 1, displacement=U)
    print(f"deepest penetration at the solution: {-pen.gap.min(initial=0.0):.3e} (h^2 / R = {h_sphere ** 2 / R:.3e})")
    assert pen.gap.min(initial=0.0) >= -h_sphere ** 2 / R
