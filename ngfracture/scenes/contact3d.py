"""A 3D contact scene: two blocks meshed apart, one pressed on the other (no cracks).

The contact patch test run as a scene: the lower block [0, w]^2 x [0, h] and the upper
block [0, w]^2 x [h, 2h], one linear elastic material, meshed with different structured
grids in the interface plane (3 x 3 cells below, an uneven 4 x 4 above), touching on z = h.
The lower face glides on z = 0, the upper face is pushed down by x and glides too. The
rigid modes this leaves (translations in x and y, rotation about z) are held at two
corners of each block with the values of the exact solution, so they do not stress it: the
exact solution is uniaxial stress sigma_zz = -E x / (2 h), linear in the coordinates, so the
P1 solution with two-pass node-to-face rows (docs/contact.md, "Contact in 3D runs") is it to
rounding and the contact pressure is uniform.
"""
import numpy as np

from ..geometry.solid import merge_bodies, solid_mesh
from ..geometry.structured import box_mesh
from ..mechanics.materials import LinearElastic
from ..run.scene import Scene
from .common import GLASS, positive

__all__ = ["BLOCKS_LOAD", "two_blocks_mesh", "blocks3d"]

#: the load parameter of blocks3d
BLOCKS_LOAD = "downward displacement of the upper block's top face (length)"
#: interface grids of the two blocks, as fractions of the width: non-matching
LOWER_CELLS = np.linspace(0.0, 1.0, 4)
UPPER_CELLS = np.array([0.0, 0.2, 0.45, 0.7, 1.0])


def two_blocks_mesh(width=1.0, height=1.0):
    """The two blocks of :func:`blocks3d` as one tetrahedral mesh of two regions (no shared vertex).

    Parameters
    ----------
    width, height : float
        The blocks' square cross-section side and the height of each (> 0).

    Returns
    -------
    SolidArrays
        Regions ``lower`` and ``upper``; boundaries those of
        :func:`ngfracture.geometry.structured.box_mesh` prefixed by ``lower_`` and ``upper_``.

    Raises
    ------
    ValueError
        A size that is not a finite number > 0.
    """
    w, h = positive("width", width), positive("height", height)
    lower = box_mesh(w * LOWER_CELLS, w * LOWER_CELLS, [0.0, h / 2, h])
    upper = box_mesh(w * UPPER_CELLS, w * UPPER_CELLS, [h, 1.5 * h, 2 * h])
    return merge_bodies([("lower", lower), ("upper", upper)])


def blocks3d(displacement=1e-3, steps=4, width=1.0, height=1.0, E=GLASS["E"], nu=GLASS["nu"]):
    """A block pressed on another of the same cross-section, non-matching meshes (3D contact).

    Parameters
    ----------
    displacement : float
        Final downward displacement of the upper block's top face (load_max).
    steps : int
        Load steps of equal size (dx = displacement / steps).
    width, height : float
        Cross-section side and height of each block.
    E, nu : float
        Young's modulus and Poisson's ratio of the linear elastic material.

    Returns
    -------
    Scene
        Contact from the start; the critical strain (ten times the largest strain of the
        run, x / (2 h)) is never reached, so nothing cracks; critical distance w / 4.

    Raises
    ------
    ValueError
        A size that is not a finite number > 0, or ``steps`` not an integer >= 1.
    """
    D = positive("displacement", displacement)
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ValueError(f"steps must be an integer >= 1, got {steps!r}")
    arrays = two_blocks_mesh(width, height)
    X = arrays.points
    w, h = float(width), float(height)
    # two corners of each block hold the rigid modes: u_x = u_y = 0 at (0, 0, z), u_y = 0 at (w, 0, z)
    holds = [[_vertex_at(X, [0.0, 0.0, z]), _vertex_at(X, [w, 0.0, z])] for z in (0.0, 2 * h)]

    def apply_load(prob, x):
        prob.add_dirichlet("lower_zmin", 0.0, component="z")
        prob.add_dirichlet("upper_zmax", -x, component="z")
        for v0, v1 in holds:
            prob.add_point_constraint(v0, 0.0, component="x")
            prob.add_point_constraint(v0, 0.0, component="y")
            prob.add_point_constraint(v1, 0.0, component="y")

    return Scene(name="blocks3d", mesh=solid_mesh(arrays), material=LinearElastic(E=E, nu=nu),
                 critical=10 * D / (2 * h), radius=w / 4,
                 apply_load=apply_load, load_max=D, dx=D / steps, contact_tol=1e-3 * w / 4, contact=True,
                 load_description=BLOCKS_LOAD,
                 parameters={"displacement": D, "steps": steps, "width": w, "height": h, "E": E, "nu": nu})


def _vertex_at(X, q):
    """The vertex at the point q exactly."""
    i = int(np.argmin(np.linalg.norm(X - np.asarray(q), axis=1)))
    if not np.array_equal(X[i], q):
        raise ValueError(f"no vertex at {q}")
    return i
