"""Shared fixtures: small meshes that build in milliseconds."""
import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import SplineGeometry, unit_square


def square_mesh(maxh=0.25):
    """Unit square with boundaries bottom, right, top, left."""
    return ng.Mesh(unit_square.GenerateMesh(maxh=maxh))


def distorted_square_mesh(maxh=0.25, amount=0.3, seed=0):
    """Unit square whose interior vertices are moved randomly (still valid triangles)."""
    mesh = square_mesh(maxh)
    ngmesh = mesh.ngmesh
    coords = ngmesh.Coordinates()
    rng = np.random.default_rng(seed)
    pts = coords[:, :2].copy()
    interior = (pts[:, 0] > 1e-12) & (pts[:, 0] < 1 - 1e-12) & (pts[:, 1] > 1e-12) & (pts[:, 1] < 1 - 1e-12)
    pts[interior] += amount * maxh * (rng.random((interior.sum(), 2)) - 0.5)
    coords[:, :2] = pts
    return ng.Mesh(ngmesh)


@pytest.fixture
def square():
    return square_mesh()


@pytest.fixture
def distorted():
    return distorted_square_mesh()


def two_squares_mesh(maxh=0.3):
    """Two disjoint unit squares (x in [0,1] and [2,3]) with boundaries named a* and b*."""
    geo = SplineGeometry()
    geo.AddRectangle((0, 0), (1, 1), bcs=["a_bottom", "a_right", "a_top", "a_left"])
    geo.AddRectangle((2, 0), (3, 1), bcs=["b_bottom", "b_right", "b_top", "b_left"])
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))
