"""Contact solves on fragmented bodies where several fragments meet (3D, docs/contact.md,
"Junctions of fragments in 3D").

The body is ``fragmented_box(cells, pieces)``: the unit cube of structured cells cut by grid
planes into blocks, closed lips, junctions of 4 copies along the lines where two cut planes
cross and of 8 where three do. E = 1, nu = 0.25.

1. Hydrostatic compression: every face of the cube glides (u_n = 0 on the min faces, -e on
   the max faces, e = 1e-3), the blocks not at a face held on their free rigid modes by the
   solver. The prediction (no rows) leaves the blocks unloaded and moved; the exact
   solution is u = -e x, in the P1 space, with every lip closed and pressed by the
   hydrostatic pressure 3 K e (K = E / (3 (1 - 2 nu))). The solve must settle without the
   complementarity problem, in at most one round per block along the longest row of blocks
   (the contact front crosses one lip per round from the glide faces inwards, the last
   round confirms), give u = -e x to 1e-8 relative, every multiplier compressive up to
   the precision asked of the field (1e-8 of the largest: rows that carry no force at the
   exact solution have multipliers of rounding size, measured 3.6e-10 of it), the largest the pressure times the nodal area h^2 of a
   lip vertex (one row per pair of copies carries the whole nodal force), and no vertex of
   any block inside another (detection at the solution, 1e-10 of the size).
2. Frictionless sliding: two blocks on top of each other (pieces (1, 1, 2), interface
   z = 1/2), nu = 0 so that uniaxial stress is exact on free sides. The lower block glides
   on x, y and z faces; the upper block's x sides are free, its y sides glide, its top is
   moved by (s, 0, -e). Exact: u = -e z e_z everywhere plus the rigid slide s e_x of the
   upper block, which slides along the closed lip without friction. The solve must find it
   (1e-8 relative) with no vertex deeper than 1e-10 of the size in the other block.
"""
import numpy as np
import pytest

from ngfracture.contact.collision3d import detect_penetrations_3d
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture.strain import vertex_displacement
from ngfracture.geometry.pieces import fragmented_box
from ngfracture.geometry.solid import SolidArrays, solid_mesh
from ngfracture.mechanics.materials import LinearElastic
from ngfracture.mechanics.problem import ElasticProblem

STRAIN = 1e-3
SIZE_TOL = 1e-10          # penetration accepted, of the cube's size (1)


def compressed(cells, pieces, nu=0.25):
    """The fragmented cube with glide conditions: hydrostatic compression STRAIN."""
    arrays, piece = fragmented_box(cells, pieces)
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=1.0, nu=nu))
    for c in "xyz":
        prob.add_dirichlet(f"{c}min", 0.0, component=c)
        prob.add_dirichlet(f"{c}max", -STRAIN, component=c)
    return prob, arrays, piece


def deepest(arrays, piece, U):
    """The deepest penetration of any boundary vertex into another block at X + U (>= 0)."""
    pen = detect_penetrations_3d(arrays.points, arrays.tets, arrays.faces, piece, displacement=U)
    return max(0.0, -float(np.min(pen.gap, initial=0.0)))


@pytest.mark.parametrize("cells, pieces", [(4, (2, 2, 2)), (6, (3, 3, 1)), (6, (2, 2, 3))])
def test_hydrostatic_compression_settles_exactly(cells, pieces):
    prob, arrays, piece = compressed(cells, pieces)
    result = ContactSolver(prob, tol=1e-3 / cells).solve()
    assert result.converged, (result.reason, result.history)
    assert result.lcp == 0
    assert result.rounds <= max(pieces), result.history
    U = vertex_displacement(prob.u)
    X = arrays.points
    assert np.abs(U + STRAIN * X).max() <= 1e-8 * STRAIN
    lam = np.asarray(result.multipliers)
    assert len(lam) and lam.max() <= 1e-8 * np.abs(lam).max()
    pressure = 3 * (1.0 / (3 * (1 - 2 * 0.25))) * STRAIN
    h = 1.0 / cells
    assert abs(-lam.min() / (pressure * h * h) - 1) <= 1e-8
    assert deepest(arrays, piece, U) <= SIZE_TOL
    print(f"{pieces}: {len(arrays.tets)} tets, {result.rounds} rounds, {len(lam)} rows, "
          f"err {np.abs(U + STRAIN * X).max() / STRAIN:.2e}")


def sliding_blocks(cells, slide):
    """Two blocks (interface z = 1/2): the lower one glides, the upper one's top is moved by (slide, 0, -e)."""
    arrays, piece = fragmented_box(cells, (1, 1, 2))
    vertex_piece = np.zeros(len(arrays.points), dtype=np.int64)
    vertex_piece[arrays.tets.ravel()] = np.repeat(piece, 4)
    names = list(arrays.bc_names) + ["free"]
    face_bc = np.asarray(arrays.face_bc).copy()
    upper = vertex_piece[arrays.faces[:, 0]] == 1
    for name in ("xmin", "xmax"):
        face_bc[upper & (face_bc == names.index(name) + 1)] = len(names)
    arrays = SolidArrays(points=arrays.points, tets=arrays.tets, regions=arrays.regions,
                         region_names=arrays.region_names, faces=arrays.faces, face_bc=face_bc, bc_names=names)
    prob = ElasticProblem(solid_mesh(arrays), LinearElastic(E=1.0, nu=0.0))
    for name in ("xmin", "xmax"):
        prob.add_dirichlet(name, 0.0, component="x")
    for name in ("ymin", "ymax"):
        prob.add_dirichlet(name, 0.0, component="y")
    prob.add_dirichlet("zmin", 0.0, component="z")
    prob.add_dirichlet("zmax", -STRAIN, component="z")
    prob.add_dirichlet("zmax", slide, component="x")
    return prob, arrays, piece, vertex_piece


@pytest.mark.parametrize("slide", [1e-3, 0.05])
def test_blocks_slide_without_friction(slide):
    cells = 4
    prob, arrays, piece, vertex_piece = sliding_blocks(cells, slide)
    result = ContactSolver(prob, tol=1e-3 / cells).solve()
    assert result.converged, (result.reason, result.history)
    U = vertex_displacement(prob.u)
    X = arrays.points
    exact = np.zeros_like(X)
    exact[:, 2] = -STRAIN * X[:, 2]
    exact[vertex_piece == 1, 0] = slide
    assert np.abs(U - exact).max() <= 1e-8 * max(slide, STRAIN)
    lam = np.asarray(result.multipliers)
    assert lam.max() <= 1e-8 * np.abs(lam).max()
    assert deepest(arrays, piece, U) <= SIZE_TOL
    print(f"slide {slide}: {result.rounds} rounds, {len(lam)} rows, "
          f"err {np.abs(U - exact).max() / max(slide, STRAIN):.2e}")
