"""Rows at a copy hold both vertices of their pair (``copies3d.two_sided_rows``; docs/contact.md,
"Points of several copies").

A row of slave s on face f at its copy t is n_f . (x_s - x_t) >= 0; the coincident face f'
at s gives t's condition, -n_f' . (x_s - x_t) >= 0. Once the lips slide by d and the faces
turn apart by an angle a, the two differ by about |d| a, and a row on f alone lets t
through the plane of f' by that much. The row takes the normal of the tighter one.

1. The rule on one pair of coincident triangles (exact numbers): the reversed condition
   tighter -> the row's normal is -n_f' and its gap -n_f' . d; looser -> the row unchanged.
2. Lips that slide far (D = 1e-2, ten times the other lip tests, so that slip x angle is
   well above the bound): the inclined crack of ``test_contact3d_lips`` (two copies per
   point) and the three-lip junction of ``test_contact3d_crack_junction`` (three copies of
   a point on one fragment, the mechanism of the coarse confined sphere's step 37). Every
   vertex of both lips, slave or master, no deeper than 1e-10 of the cube's size (exact
   detection); before the rule the master side was 1.4e-9 (inclined) and 8.5e-9
   (junction) deep. Every multiplier compressive, the lips slide.
"""
import math

import numpy as np

from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.copies3d import two_sided_rows
from ngfracture.contact.kinks3d import CopyIndex
from ngfracture.contact.rows3d import NodeToFaceRows, relinearise_node_to_face
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.solid import solid_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

import test_contact3d_crack_junction as junction
import test_contact3d_lips as lips

D = 1e-2                  # ten times the lip tests' load: slip x angle above the bound
SIZE_TOL = 1e-10          # penetration accepted, of the cube's size (1; the diagonal sqrt 3)


def pair_of_lips(tilt):
    """Two coincident right triangles (lower face f at t = 0 outward +z, upper face f' at
    s = 3 outward -z), the upper one slid by (-h, -h, 0) and its far corner b' lifted by
    ``tilt``: the points, faces, displacement and the lip row of s on f (projected at t)."""
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] * 2)
    F = np.array([[0, 1, 2], [3, 5, 4]])
    h = 1e-3
    U = np.zeros_like(X)
    U[3:] = [-h, -h, 0.0]
    U[5, 2] = tilt
    row = NodeToFaceRows(slave=np.array([3]), master=F[:1].copy(), face=np.array([0]), bary=np.array([[1.0, 0, 0]]),
                         normal=np.array([[0.0, 0, 1]]), dist=np.zeros(1), g=np.zeros(1), nv=len(X))
    return X, F, U, row


def test_the_row_takes_the_tighter_of_the_two_conditions():
    for tilt in (-1e-2, 1e-2):
        X, F, U, row = pair_of_lips(tilt)
        fresh = relinearise_node_to_face(row, X, U)
        out = two_sided_rows(fresh, X, U, CopyIndex(X, F))
        x = X + U
        d = x[3] - x[0]
        m = np.cross(x[5] - x[3], x[4] - x[3])
        m = -m / np.linalg.norm(m)                       # -n_f': t's condition is m . d >= 0
        assert fresh.dist[0] == 0.0                      # s on f's plane (z = 0)
        if tilt < 0:
            # f' tilts down at b', towards t: t behind f''s plane by h sqrt(2)-ish times the slope
            assert m @ d < -1e-6
            assert np.array_equal(out.normal[0], m) and out.dist[0] == m @ d
            assert np.array_equal(out.bary, fresh.bary) and out.g[0] == 0.0
            assert out.C @ U.T.ravel() + out.g == m @ d    # the row's gap at U: C u + g
        else:
            assert m @ d > 1e-6 and out is fresh


def slide_depths(arrays, U, slaves):
    """The deepest slave and master vertex (exact detection, one fragment)."""
    pen = detect_penetrations_3d(arrays.points, arrays.tets, arrays.faces, np.zeros(len(arrays.tets), np.int64), U)
    s = np.isin(pen.vertex, slaves)
    return max(0.0, -float(pen.gap[s].min(initial=0.0))), max(0.0, -float(pen.gap[~s].min(initial=0.0)))


def solved(arrays, moves, clamp):
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=1.0, nu=0.25))
    prob.add_dirichlet(clamp, 0.0)
    for boundary, comp, value in moves:
        prob.add_dirichlet(boundary, value, component=comp)
    result = ContactSolver(prob, tol=1e-3 / 8).solve()
    assert result.converged, (result.reason, result.status.message if result.status else "")
    return result, vertex_displacement(prob.u)


def test_inclined_lips_sliding_far_keep_both_sides_out():
    a, parent = lips.inclined_crack()
    result, U = solved(a, [("zmax", "x", D), ("zmax", "y", 0.0), ("zmax", "z", -D)], "zmin")
    copies = np.flatnonzero(parent != np.arange(len(parent)))
    n = np.array([-1.0, 0.0, 1.0]) / math.sqrt(2.0)
    jump = U[copies] - U[parent[copies]]
    slide = np.linalg.norm(jump - np.outer(jump @ n, n), axis=1)
    slave, master = slide_depths(a, U, copies)
    scale = np.abs(result.multipliers).max()
    print(f"\ninclined, D = {D}: slide / D {slide.max() / D:.3g}, deepest slave {slave:.2g}, master {master:.2g}, "
          f"rows {len(result.constraints)}, rounds {result.rounds}")
    assert slide.max() >= 0.1 * D
    assert slave <= SIZE_TOL * math.sqrt(3.0) and master <= SIZE_TOL * math.sqrt(3.0)
    assert np.all(result.multipliers <= 1e-10 * scale)


def test_junction_lips_sliding_far_keep_every_copy_out():
    a = junction.junction_cube()
    result, U = solved(a, [("xmax", "x", -D), ("xmax", "y", D), ("xmax", "z", D)], "xmin")
    copies = junction.junction_copies(a)
    X = a.points
    jumps = [np.linalg.norm((U[i] - U[j])[1:]) for p in np.unique(X[copies], axis=0)
             for i in copies[np.all(X[copies] == p, axis=1)] for j in copies[np.all(X[copies] == p, axis=1)] if i < j]
    depth = junction.deepest(a, U)
    scale = np.abs(result.multipliers).max()
    print(f"\njunction, D = {D}: largest tangential jump / D {max(jumps) / D:.3g}, deepest {depth:.2g}, rows "
          f"{len(result.constraints)}, rounds {result.rounds}")
    assert max(jumps) >= 1e-2 * D
    assert depth <= SIZE_TOL
    assert np.all(result.multipliers <= 1e-8 * scale)
