"""Shared fixtures: small meshes that build in milliseconds; the environment of child processes."""
import os

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


def two_region_bar_mesh(maxh=0.25):
    """[0,2]x[0,1] with regions 'soft' (x < 1) and 'stiff' (x > 1) bonded along x = 1."""
    geo = SplineGeometry()
    pts = [geo.AppendPoint(*p) for p in [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]]
    geo.Append(["line", pts[0], pts[1]], leftdomain=1, rightdomain=0, bc="bottom")
    geo.Append(["line", pts[1], pts[2]], leftdomain=2, rightdomain=0, bc="bottom")
    geo.Append(["line", pts[2], pts[3]], leftdomain=2, rightdomain=0, bc="right")
    geo.Append(["line", pts[3], pts[4]], leftdomain=2, rightdomain=0, bc="top")
    geo.Append(["line", pts[4], pts[5]], leftdomain=1, rightdomain=0, bc="top")
    geo.Append(["line", pts[5], pts[0]], leftdomain=1, rightdomain=0, bc="left")
    geo.Append(["line", pts[1], pts[4]], leftdomain=1, rightdomain=2, bc="interface")
    geo.SetMaterial(1, "soft")
    geo.SetMaterial(2, "stiff")
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def child_env(**extra):
    """The environment for a child Python process: this one's, with a relative PYTHONPATH
    made absolute (the child may run in another folder), plus ``extra``.

    Nothing is added to the path: an installed ngfracture must be found as installed (the
    repository root on the path would import the uncompiled source tree instead), and an
    in-place build is found through the caller's own PYTHONPATH.
    """
    env = dict(os.environ, **extra)
    paths = [os.path.abspath(p) for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    if paths:
        env["PYTHONPATH"] = os.pathsep.join(paths)
    return env
