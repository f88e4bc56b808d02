"""Contact where three crack lips meet along a line that reaches the surface (3D, docs/contact.md,
"Crack lips in 3D": points of three or more copies).

A structured unit cube (8 cells a side, 3072 tets) gets two cracks opened in numpy
(``open_internal_surface``), both in the upper half z > 1/2 and reaching the free top z = 1:
the plane x = 1/2 for |y - 1/2| < 1/4, and the branch y = 1/2 for 1/2 < x < 3/4 on its
positive side. Along the line x = y = 1/2, z > 1/2 the three lips meet: every point there
has three copies (the half x < 1/2 and the two quarters of x > 1/2), and the top point is a
multi-crack point on the free surface, as where the sphere scene's cracks meet its hole.
Nothing is cut through: every lip is on the one fragment, so only the lip rows, their
partner-face rows and the self-contact detection hold the lips. E = 1, nu = 0.25, D = 1e-3.

1. Biaxial compression (u_x = 0 on x = 0, -D on x = 1; u_y = 0 on y = 0, -D on y = 1;
   u_z = 0 on z = 0, top free): the uncracked block's field u = (-D x, -D y, e_z z),
   e_z = 2 lambda D / (lambda + 2 mu), is linear, in the P1 space, keeps every lip closed and
   pressed (sigma_xx = sigma_yy < 0 on both crack planes, no shear), so the solve must
   return it (1e-8 of D), every multiplier compressive, and no copy inside another's
   wedge (detection, 1e-10 of the size).
2. Shear and compression (the face x = 0 clamped, x = 1 moved by (-D, D, D), the rest
   free): the lips slide along each other at the junction; no closed form. The solve must
   converge with every multiplier compressive, the lips must slide (the largest tangential
   jump at a junction copy at least 1e-2 D, so the case is not the closed one), no vertex
   deeper than 1e-10 of the size in its own fragment (exact detection, depth to the faces
   at the copies coincident with the vertex's own faces included), and the overlap volume
   of the tets of the three wedges (labelled by side of the two crack planes), measured by
   exact clipping independently of the contact code (``ngfracture.output.overlap3d``), at
   most what node-to-face rows leave: the faces of lips that slid by s over each other
   while turning by an angle k apart cross by at most s sin k over the crack's area.
3. The found rows at copies (``contact/copies3d.py``): the lower-numbered lip copies of the
   plane x = 1/2 pushed by 1e-4 into the other lip are found 1e-4 deep on a face at their
   copy, and become the rows of the higher copies (the fixed rows' direction) on the
   coincident faces at the pushed vertices, projected there, reference normal, g = 0.
"""
import math

import numpy as np

from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.copies3d import found_rows_at_copies
from ngfracture.contact.rows3d import node_to_face_rows
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.internal_crack import open_internal_surface
from ngfracture.geometry.solid import solid_mesh
from ngfracture.geometry.structured import box_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem
from ngfracture.output.overlap3d import fragment_overlap_volume

E, NU, D = 1.0, 0.25, 1e-3
N = 8
GRID = np.linspace(0.0, 1.0, N + 1)
SIZE_TOL = 1e-10          # penetration and overlap accepted, of the cube's size and volume (1)


def plane_faces(arrays, axis, value, inside):
    """Interior faces on the plane X[axis] = value whose centroid passes ``inside``, oriented to +axis."""
    X, T = arrays.points, arrays.tets
    local = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    tf = T[:, local].reshape(-1, 3)
    on = np.all(X[tf][:, :, axis] == value, axis=1)
    keys, counts = np.unique(np.sort(tf[on], axis=1), axis=0, return_counts=True)
    F = keys[(counts == 2) & inside(X[keys].mean(axis=1))]
    n = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    flip = n[:, axis] < 0
    F[flip] = F[flip][:, ::-1]
    return F


def opened(arrays, faces, front):
    """``arrays`` with ``faces`` opened, but those with all three vertices on the front (they cannot open)."""
    return open_internal_surface(arrays, faces[~np.all(front(arrays.points[faces]), axis=1)])


def junction_cube():
    """The cube with the two cracks of the module docstring."""
    a = box_mesh(GRID, GRID, GRID)
    a = opened(a, plane_faces(a, 0, 0.5, lambda c: (c[:, 2] > 0.5) & (np.abs(c[:, 1] - 0.5) < 0.25)),
               lambda p: (np.abs(p[..., 1] - 0.5) == 0.25) | (p[..., 2] == 0.5))
    return opened(a, plane_faces(a, 1, 0.5, lambda c: (c[:, 2] > 0.5) & (c[:, 0] > 0.5) & (c[:, 0] < 0.75)),
                  lambda p: (p[..., 0] == 0.75) | (p[..., 2] == 0.5))


def wedge_labels(arrays):
    """Per tet: which side of the two crack planes its centroid is on (0: x < 1/2, 1 and 2: x > 1/2 below
    and above y = 1/2)."""
    c = arrays.points[arrays.tets].mean(axis=1)
    return np.where(c[:, 0] < 0.5, 0, np.where(c[:, 1] < 0.5, 1, 2))


def junction_copies(arrays):
    """The vertices at points with three copies."""
    _, point, count = np.unique(arrays.points, axis=0, return_inverse=True, return_counts=True)
    return np.flatnonzero(count[point.ravel()] >= 3)


def solve(prob):
    result = ContactSolver(prob, tol=1e-3 / N).solve()
    assert result.converged, (result.reason, result.status.message if result.status else "")
    return result


def deepest(arrays, U):
    pen = detect_penetrations_3d(arrays.points, arrays.tets, arrays.faces, np.zeros(len(arrays.tets), np.int64), U)
    return max(0.0, -float(np.min(pen.gap, initial=0.0)))


def test_junction_cube_has_three_copies_on_the_line_to_the_surface():
    a = junction_cube()
    P = a.points[junction_copies(a)]
    assert len(P) == 12                                    # 4 points, 3 copies each
    assert np.all((P[:, 0] == 0.5) & (P[:, 1] == 0.5) & (P[:, 2] > 0.5)) and P[:, 2].max() == 1.0


def test_biaxial_compression_keeps_the_uncracked_field():
    a = junction_cube()
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=E, nu=NU))
    for c in "xy":
        prob.add_dirichlet(f"{c}min", 0.0, component=c)
        prob.add_dirichlet(f"{c}max", -D, component=c)
    prob.add_dirichlet("zmin", 0.0, component="z")
    result = solve(prob)
    U = vertex_displacement(prob.u)
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    X = a.points
    exact = np.column_stack([-D * X[:, 0], -D * X[:, 1], 2 * lam * D / (lam + 2 * mu) * X[:, 2]])
    err = np.abs(U - exact).max() / D
    depth = deepest(a, U)
    print(f"\nbiaxial: |u - uncracked| / D {err:.2g}, rows {len(result.constraints)}, rounds {result.rounds}, "
          f"multipliers {result.multipliers.min():.3g} ... {result.multipliers.max():.3g}, deepest {depth:.2g}")
    assert err <= 1e-8
    assert np.all(result.multipliers <= 1e-8 * np.abs(result.multipliers).max())
    assert depth <= SIZE_TOL


def test_shear_slides_the_junction_without_penetration():
    a = junction_cube()
    prob = ElasticProblem(solid_mesh(a), LinearElastic(E=E, nu=NU))
    prob.add_dirichlet("xmin", 0.0)
    for comp, value in (("x", -D), ("y", D), ("z", D)):
        prob.add_dirichlet("xmax", value, component=comp)
    result = solve(prob)
    U = vertex_displacement(prob.u)
    X = a.points
    copies = junction_copies(a)
    # the tangential jumps between the copies of a junction point (normal of the plane x = 1/2)
    jumps = []
    for p in np.unique(X[copies], axis=0):
        c = copies[np.all(X[copies] == p, axis=1)]
        jumps += [np.linalg.norm((U[i] - U[j])[1:]) for i in c for j in c if i < j]
    depth = deepest(a, U)
    overlap = fragment_overlap_volume(X + U, a.tets, wedge_labels(a), body_volume=1.0)
    # node-to-face rows keep the vertices out; the faces of two lips that slid by s over each
    # other while turning by an angle k can still cross, by at most s sin k over the crack's area
    C = a.faces[a.face_bc == a.bc_names.index("crack") + 1]
    p = (X + U)[C]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = 0.5 * np.linalg.norm(n, axis=1)
    n /= 2 * area[:, None]
    lips = [np.abs(n[:, axis]) > 0.5 for axis in (0, 1)]                 # the faces of either crack plane
    kink = max(math.sqrt(max(0.0, 1.0 - np.min(np.abs(n[m] @ n[m].T)) ** 2)) for m in lips)
    bound = max(jumps) * kink * area.sum() / 2                             # both lips' faces counted in area
    scale = np.abs(result.multipliers).max()
    print(f"\nshear: largest tangential jump at the junction / D {max(jumps) / D:.3g}, rows "
          f"{len(result.constraints)}, rounds {result.rounds}, multipliers {result.multipliers.min():.3g} ... "
          f"{result.multipliers.max():.3g}, deepest {depth:.2g}, overlap {overlap.volume:.2g} (bound {bound:.2g})")
    assert max(jumps) >= 1e-2 * D
    assert np.all(result.multipliers <= 1e-8 * scale)
    assert depth <= SIZE_TOL
    assert overlap.volume <= bound


def test_found_rows_at_copies_take_the_fixed_rows_direction():
    """A lip vertex of the lower-numbered copy pushed into the other lip's wedge is found
    with its master face at the copy; the row is the other copy's (the fixed rows' slave)
    on the coincident face at the pushed vertex, projected there, with the face's reference
    normal and g = 0 (contact/copies3d.py)."""
    a = junction_cube()
    X = a.points
    _, point, count = np.unique(X, axis=0, return_inverse=True, return_counts=True)
    point = point.ravel()
    two = np.flatnonzero((count[point] == 2) & (X[:, 0] == 0.5))            # lip copies of the plane x = 1/2
    low = two[np.array([np.count_nonzero(point[two] == point[v]) == 2 and v == two[point[two] == point[v]].min()
                        for v in two])]
    U = np.zeros_like(X)
    U[low, 0] = 1e-4                                                        # into the copies' side x > 1/2
    zero = np.zeros(len(a.tets), np.int64)
    pen = detect_penetrations_3d(X, a.tets, a.faces, zero, U)
    mine = np.isin(pen.vertex, low)
    assert np.count_nonzero(mine) == len(low) and np.allclose(pen.gap[mine], -1e-4, rtol=1e-12, atol=0)
    rows, at_copy = found_rows_at_copies(X, a.faces, node_to_face_rows(X, a.faces, pen), np.zeros(len(X), np.int64))
    assert np.all(at_copy[mine])
    r = rows.subset(np.flatnonzero(mine))
    high = np.array([two[(point[two] == point[v]) & (two != v)][0] for v in pen.vertex[mine]])
    assert np.array_equal(r.slave, high)                                    # the higher copy the slave
    assert np.all(np.any(r.master == pen.vertex[mine][:, None], axis=1))   # on a face at the pushed vertex
    assert np.array_equal(r.normal, np.tile([1.0, 0.0, 0.0], (len(r), 1))) and np.all(r.g == 0.0)
    assert np.array_equal(np.sort(r.bary, axis=1), np.tile([0.0, 0.0, 1.0], (len(r), 1)))
    assert np.allclose(r.C @ U.T.ravel() + r.g, -1e-4, rtol=1e-12, atol=0)
