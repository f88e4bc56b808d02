"""Contact between the coincident lips of a crack inside one body (3D, docs/contact.md "Crack lips in 3D").

A structured unit cube (8 cells a side, 6 tets a cell) gets a planar crack that does not
cut it through: its faces on a plane are doubled in numpy, the vertices inside the crack
given a copy on one side, the front (where the crack faces meet faces of the plane that
are not cracked) left whole. Both lips are on one fragment, so only the lip rows
(:func:`ngfracture.contact.rows3d.lip_rows`) and the self-contact detection of
:func:`ngfracture.contact.collision3d.detect_penetrations_3d` can hold them.

1. The crack z = 1/2, |x - 1/2|, |y - 1/2| <= 1/4, under uniaxial compression along z
   (u_z = 0 below, -D on top, the rigid modes in x and y held at two corners with the exact
   values): the exact solution is uniaxial stress, linear, in the P1 space, and satisfies
   every lip row (the lips stay closed and carry sigma_zz); the solve must give it
   (relative 1e-8) and the force of the rows at every lip vertex over its consistent nodal
   area on the crack must be -sigma_zz (relative 1e-8): a closed crack transmits the
   stress exactly.
2. The same block pulled: the lips open, no row is active, every lip pair opens (n . jump
   >= 0) and the field differs from the uncracked one by the crack's opening.
3. A crack on the plane z = x (45 degrees), |x - 1/2|, |y - 1/2| <= 1/4, the bottom clamped,
   the top moved by (D, 0, -D): compression and shear on the crack, frictionless. The
   lips slide (tangential jump a sizeable part of D), no slave vertex (the copies) is
   deeper than 1e-10 of the cube's size in the other lip (exact detection), a master
   vertex (one row per pair: the lower lip is not a slave) no deeper than the slide times
   the sine of the largest angle between the deformed faces of the upper lip, every
   multiplier is compressive and the rows' force at every lip vertex along its own
   outward normal pushes it back (compressive), none pulling.
4. bar3d at the --quick sizes of benchmarks/solid.py: a run with contact (the lips get rows
   once cracked) breaks in two with the steps, split vertices and crack faces of a run
   without, the displacements equal to 1e-8 (slow: two runs, about 20 s).
"""
import dataclasses
import math

import numpy as np
import pytest

import ngfracture as nf

from ngfracture.contact.active_set3d import fixed_rows_3d
from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.rows3d import lip_rows
from ngfracture.geometry.solid import nodal_areas
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import SolidArrays, solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

E, NU, D = 1.0, 0.25, 1e-3
N = 8
GRID = np.linspace(0.0, 1.0, N + 1)


def planar_crack(arrays, distance, inside):
    """The mesh with its interior faces on the plane distance(x) = 0 and inside(centroid) cracked.

    distance must be exactly 0 on the plane's vertices (grid points); a vertex on the
    plane gets a copy for the tets on the positive side iff every interior face of the
    plane at it is cracked (the others, at the front, stay whole). Returns the arrays and
    the parent vertex of every vertex. A cracked face whose vertices are all on the front
    is not opened (it stays an interior face)."""
    X, T = arrays.points, arrays.tets
    local = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    tf = np.sort(T[:, local].reshape(-1, 3), axis=1)
    owner = np.repeat(np.arange(len(T)), 4)
    on = np.all(distance(X[tf]) == 0.0, axis=1)
    keys, inverse, counts = np.unique(tf[on], axis=0, return_inverse=True, return_counts=True)
    interior = counts == 2
    centroid = X[keys].mean(axis=1)
    cracked = interior & inside(centroid)
    # the tet below (negative side) of every cracked face
    own = owner[on]
    side = distance(X[T[own]].mean(axis=1))
    below = np.zeros(len(keys), dtype=np.int64)
    below[inverse.ravel()[side < 0]] = own[side < 0]
    plane_faces = keys[interior]
    split = np.setdiff1d(np.unique(keys[cracked]), np.unique(keys[interior & ~cracked]))
    copy = np.full(len(X), -1)
    copy[split] = len(X) + np.arange(len(split))
    upper = distance(X[T].mean(axis=1)) > 0
    tets = T.copy()
    sub = tets[upper]
    sub = np.where(copy[sub] >= 0, copy[sub], sub)
    tets[upper] = sub
    faces = arrays.faces.copy()
    fside = distance(X[faces].mean(axis=1)) > 0
    fs = faces[fside]
    faces[fside] = np.where(copy[fs] >= 0, copy[fs], fs)
    # lower lip: outward = towards the positive side; upper lip: reversed, on the copies
    # a cracked face with no split vertex lies between front vertices: it stays whole
    cracked &= np.isin(keys, split).any(axis=1)
    lower = keys[cracked]
    tb = T[below[cracked]]
    apex = X[tb].sum(axis=1) - X[lower].sum(axis=1)           # the lower tet's fourth vertex
    n = np.cross(X[lower[:, 1]] - X[lower[:, 0]], X[lower[:, 2]] - X[lower[:, 0]])
    flip = np.einsum("ij,ij->i", n, apex - X[lower[:, 0]]) > 0
    lower[flip] = lower[flip][:, ::-1]
    up = lower[:, ::-1]
    up = np.where(copy[up] >= 0, copy[up], up)
    names = list(arrays.bc_names) + ["crack"]
    crack_bc = len(names)
    parent = np.concatenate([np.arange(len(X)), split])
    a = SolidArrays(points=X[parent], tets=tets, regions=arrays.regions, region_names=list(arrays.region_names),
                    faces=np.vstack([faces, lower, up]),
                    face_bc=np.concatenate([arrays.face_bc, np.full(2 * len(lower), crack_bc)]), bc_names=names)
    assert len(plane_faces) > len(lower) > 0
    return a, parent


def flat_crack():
    return planar_crack(box_mesh(GRID, GRID, GRID), lambda p: p[..., 2] - 0.5,
                        lambda c: (np.abs(c[:, 0] - 0.5) < 0.25) & (np.abs(c[:, 1] - 0.5) < 0.25))


def inclined_crack():
    return planar_crack(box_mesh(GRID, GRID, GRID), lambda p: p[..., 2] - p[..., 0],
                        lambda c: (np.abs(c[:, 0] - 0.5) < 0.25) & (np.abs(c[:, 1] - 0.5) < 0.25))


def vertex_at(X, q):
    i = int(np.flatnonzero(np.all(X == q, axis=1))[0])
    return i


def uniaxial_problem(arrays, top):
    """u_z = 0 on zmin, top on zmax; u_x = u_y = 0 at the origin, u_y = 0 at (1, 0, 0)."""
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("zmin", 0.0, component="z")
    prob.add_dirichlet("zmax", top, component="z")
    o, a = vertex_at(arrays.points, [0.0, 0.0, 0.0]), vertex_at(arrays.points, [1.0, 0.0, 0.0])
    prob.add_point_constraint(o, 0.0, component="x")
    prob.add_point_constraint(o, 0.0, component="y")
    prob.add_point_constraint(a, 0.0, component="y")
    return prob


def contact_solve(prob):
    result = ContactSolver(prob, tol=1e-3 / N).solve()
    assert result.converged, (result.reason, result.status.message if result.status else "")
    return result


def lip_forces(result, nv):
    """The force of the active rows at every vertex, (nv, 3) (P1 layout of the rows)."""
    if result.constraints is None or len(result.constraints) == 0:
        return np.zeros((nv, 3))
    return -(result.constraints.C.T @ result.multipliers).reshape(3, nv).T


def crack_faces(arrays):
    return arrays.faces[arrays.face_bc == arrays.bc_names.index("crack") + 1]


def test_lip_rows_pair_every_copy_on_its_own_fragment():
    a, parent = flat_crack()
    nv0 = len(parent) - np.count_nonzero(parent != np.arange(len(parent)))
    copies = np.flatnonzero(np.arange(len(parent)) >= nv0)
    assert len(copies) == 9                               # the 3 x 3 vertices inside the crack
    rows = lip_rows(a.points, a.faces, np.zeros(len(a.points), dtype=np.int64))
    # one row per pair: the copy (higher number) the slave, on a face of the lower lip at its parent
    assert np.array_equal(rows.slave, copies)
    assert np.all(np.any(rows.master == parent[copies][:, None], axis=1))
    assert np.array_equal(rows.normal, np.tile([0.0, 0.0, 1.0], (len(rows), 1)))
    assert np.all(rows.g == 0.0)
    # the closed lips are not detected (closed seams), a lip pushed through the other is
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, np.zeros(len(a.tets), dtype=np.int64))
    assert len(pen) == 0 and pen.stats["closed_seams"] == 18
    U = np.zeros_like(a.points)
    U[copies, 2] = -1e-4                                  # the upper lip's inner vertices sink
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, np.zeros(len(a.tets), dtype=np.int64), U)
    # both lips: the copies in the lower lip's tets, their parents in the upper lip's
    assert pen.vertex.tolist() == sorted(parent[copies].tolist() + copies.tolist())
    assert np.all(pen.fragment == 0) and np.all(pen.twin[pen.vertex >= copies[0]] == parent[copies])
    down = pen.vertex >= copies[0]
    assert np.allclose(pen.gap[down], -1e-4, rtol=0, atol=1e-15)
    assert np.array_equal(pen.normal[down], np.tile([0.0, 0.0, 1.0], (len(copies), 1)))
    assert np.all((pen.gap[~down] < 0) & (pen.gap[~down] >= -1e-4 - 1e-15)) and np.all(pen.normal[~down, 2] < 0)
    # the fixed rows of a solve have them (one fragment: no twin rows across fragments)
    fixed, keys = fixed_rows_3d(a.points, a.tets, a.faces, np.zeros(len(a.tets), dtype=np.int64))
    assert len(fixed) == 9 and len(set(keys)) == 9


def test_closed_crack_transmits_uniform_compression_exactly():
    a, parent = flat_crack()
    prob = uniaxial_problem(a, -D)
    result = contact_solve(prob)
    U = vertex_displacement(prob.u)
    X = a.points
    exact = np.column_stack([NU * D * X[:, 0], NU * D * X[:, 1], -D * X[:, 2]])
    err = np.abs(U - exact).max() / D
    # the uncracked block, same loads
    ref = uniaxial_problem(box_mesh(GRID, GRID, GRID), -D)
    ref.solve()
    err_ref = np.abs(U - vertex_displacement(ref.u)[parent]).max() / D
    C = crack_faces(a)
    area = nodal_areas(X, C)
    lips = np.unique(C)
    inner = lips[np.isin(lips, np.flatnonzero(parent != np.arange(len(parent))))
                 | np.isin(lips, parent[parent != np.arange(len(parent))])]
    f = lip_forces(result, len(X))
    normal = np.where(np.arange(len(X)) >= len(X) - 9, -1.0, 1.0)   # lower lip outward +z, upper -z
    pressure = -f[inner, 2] * normal[inner] / area[inner]          # pushing back into its own side
    print(f"\nclosed crack: |u - exact| / D {err:.2g}, |u - uncracked| / D {err_ref:.2g}, "
          f"pressure / (E D) {pressure.min() / (E * D):.15f} ... {pressure.max() / (E * D):.15f}, "
          f"rounds {result.rounds}, rows {len(result.constraints)}")
    assert err <= 1e-8 and err_ref <= 1e-8
    assert len(inner) == 18
    assert np.abs(pressure / (E * D) - 1.0).max() <= 1e-8
    assert np.abs(f[inner, :2]).max() <= 1e-8 * E * D * area[inner].min()
    assert np.all(result.multipliers <= 0.0)


def test_open_crack_under_tension_has_no_active_row():
    a, parent = flat_crack()
    prob = uniaxial_problem(a, D)
    result = contact_solve(prob)
    U = vertex_displacement(prob.u)
    ref = uniaxial_problem(box_mesh(GRID, GRID, GRID), D)
    ref.solve()
    diff = np.abs(U - vertex_displacement(ref.u)[parent]).max() / D
    copies = np.flatnonzero(parent != np.arange(len(parent)))
    opening = U[copies, 2] - U[parent[copies], 2]
    print(f"\nopen crack: rows {0 if result.constraints is None else len(result.constraints)}, opening / D "
          f"{opening.min() / D:.3g} ... {opening.max() / D:.3g}, |u - uncracked| / D {diff:.3g}, rounds {result.rounds}")
    assert result.constraints is None or len(result.constraints) == 0
    assert np.all(opening > 0)
    assert diff >= 0.5 * opening.max() / D
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, np.zeros(len(a.tets), dtype=np.int64), U)
    assert len(pen) == 0


def test_inclined_crack_slides_without_penetration():
    a, parent = inclined_crack()
    X = a.points
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("zmin", 0.0)
    for comp, value in (("x", D), ("y", 0.0), ("z", -D)):
        prob.add_dirichlet("zmax", value, component=comp)
    result = contact_solve(prob)
    U = vertex_displacement(prob.u)
    copies = np.flatnonzero(parent != np.arange(len(parent)))
    n = np.array([-1.0, 0.0, 1.0]) / math.sqrt(2.0)        # outward normal of the lower lip (below z = x)
    jump = U[copies] - U[parent[copies]]                     # upper lip minus lower lip
    normal_jump = jump @ n
    slide = np.linalg.norm(jump - np.outer(normal_jump, n), axis=1)
    pen = detect_penetrations_3d(X, a.tets, a.faces, np.zeros(len(a.tets), dtype=np.int64), U)
    slaves = pen.vertex >= copies[0]                         # the copies: slaves of the lip rows
    depth = float(max(0.0, -pen.gap[slaves].min(initial=0.0)))
    depth_master = float(max(0.0, -pen.gap[~slaves].min(initial=0.0)))
    # one row per pair: a master vertex can sink into the slave lip where that lip kinks, by
    # at most the slide times the sine of the largest angle between two of its faces
    C = crack_faces(a)
    upper = C[np.all(np.isin(C, copies) | ~np.isin(C, parent[copies]), axis=1) & np.isin(C, copies).any(axis=1)]
    x = X + U
    nrm = np.cross(x[upper[:, 1]] - x[upper[:, 0]], x[upper[:, 2]] - x[upper[:, 0]])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    kink = math.sqrt(max(0.0, 1.0 - (nrm @ nrm.T).min() ** 2))
    f = lip_forces(result, len(X))
    lower = parent[copies]
    push_lower = -(f[lower] @ n)                             # >= 0: pushed back below the crack
    push_upper = f[copies] @ n                               # >= 0: pushed back above
    scale = np.abs(result.multipliers).max()
    print(f"\ninclined crack: slide / D {slide.min() / D:.3g} ... {slide.max() / D:.3g}, normal jump / D "
          f"{normal_jump.min() / D:.2g} ... {normal_jump.max() / D:.2g}, deepest slave {depth:.2g}, "
          f"master {depth_master:.2g} (bound {slide.max() * kink:.2g}, kink {kink:.2g}), "
          f"multipliers {result.multipliers.min():.3g} ... {result.multipliers.max():.3g}, rounds {result.rounds}, "
          f"active {len(result.constraints)}")
    assert slide.max() >= 0.1 * D
    assert depth <= 1e-10 * math.sqrt(3.0)
    assert depth_master <= slide.max() * kink
    assert np.all(normal_jump >= -1e-10)
    assert np.all(result.multipliers <= 1e-10 * scale)
    assert np.all(push_lower >= -1e-10 * scale) and np.all(push_upper >= -1e-10 * scale)
    assert push_lower.max() > 0


def bar_run(tmp_path, contact):
    """The smallest bar3d that breaks across its notch (benchmarks/solid.py --quick sizes)."""
    scene = dataclasses.replace(nf.scenes.bar3d(maxh=0.4, fine=0.1, radius=0.2, thickness=0.25), contact=True)
    result = nf.Simulation(scene, out=tmp_path / contact, pictures="none", contact=contact).run()
    a = result.problem.arrays
    C = crack_faces(a)
    return result, a, np.unique(np.sort(a.points[C].reshape(len(C), -1), axis=1), axis=0)


@pytest.mark.slow
def test_bar3d_breaks_in_two_with_the_crack_of_a_run_without_contact(tmp_path):
    # two bar runs and their meshes: about 20 s
    with_contact, a, crack = bar_run(tmp_path, "auto")
    without, b, crack_never = bar_run(tmp_path, "never")
    s, t = with_contact.summary, without.summary
    print(f"\nbar3d: {s['n_steps']} steps, {s['n_split_vertices']} split vertices, {len(crack)} distinct crack "
          f"faces; wall {s['timings']['wall']:.2f} s with contact, {t['timings']['wall']:.2f} s without")
    assert with_contact.reason == without.reason == "broken"
    assert s["n_fragments"] == t["n_fragments"] == 2
    assert s["n_steps"] == t["n_steps"] and s["n_split_vertices"] == t["n_split_vertices"]
    assert np.array_equal(a.points, b.points) and np.array_equal(crack, crack_never)
    U, V = (vertex_displacement(r.problem.u) for r in (with_contact, without))
    assert np.abs(U - V).max() <= 1e-8 * np.abs(V).max()
