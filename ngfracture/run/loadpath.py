"""Is the body still loaded through? Fragments against the prescribed displacements.

A fragment carries stress from the prescribed displacements only if they ask it to
deform: if its fixed dofs move by a rigid motion (a translation plus a small rotation
of the fragment), the fragment follows without strain. A body whose prescribed
displacements deform it as a whole (the plate pulled apart at its left and right sides)
is broken through when no fragment is deformed by them any more: the crack has cut
every path of material between the boundaries that pull against each other, whatever
the pieces still push on each other by contact (interlocking crack faces).

The prescribed motion is read from the constraints a scene adds, at two load values
(:func:`prescribed_increment`), so no scene has to name its loaded boundaries. Only
single-dof rows (Dirichlet, gliding and point constraints) count: tractions and body
forces load a body without a prescribed motion, and this rule says nothing about them.

Reference coordinates are used for the rigid motion: the prescribed increments of a
rigid motion are exact there to first order, and glass strains are 1e-4.
"""
import numpy as np

from ..mechanics import rigid

__all__ = ["prescribed_increment", "deformed_fragments", "load_path_cut"]

#: a fixed dof moves rigidly with its fragment if the best rigid motion misses its
#: prescribed increment by less than this fraction of the largest increment (the values
#: come from NGSolve's Set(), exact at vertices to rounding)
RIGID_TOL = 1e-8


def prescribed_increment(dofs_a, values_a, dofs_b, values_b):
    """The dofs fixed at two load values and how much their prescribed values change.

    Parameters
    ----------
    dofs_a, values_a : numpy.ndarray
        Fixed dofs (ascending, as ``ConstraintRows.fixed_dofs``) and their prescribed
        values at load a.
    dofs_b, values_b : numpy.ndarray
        The same at load b, on the same mesh.

    Returns
    -------
    dofs : numpy.ndarray of int64
        The dofs fixed at both loads (ascending).
    increment : numpy.ndarray
        Their value at b minus their value at a.
    """
    dofs, ia, ib = np.intersect1d(dofs_a, dofs_b, assume_unique=True, return_indices=True)
    return dofs.astype(np.int64), np.asarray(values_b)[ib] - np.asarray(values_a)[ia]


def _rigid_misfit(points, vertex, component, increment):
    """Largest miss of the least-squares rigid motion (reference coordinates) on these fixed dofs."""
    centred = points[vertex] - points[vertex].mean(axis=0)   # conditions the rotation columns
    d = points.shape[1]
    A = np.zeros((len(vertex), rigid.rigid_mode_count(d)))
    for c in range(d):
        A[component == c, c] = 1.0
    # infinitesimal rotation about axis a: component b moves by -x_c, component c by x_b
    axes = [(0, 1)] if d == 2 else [(1, 2), (2, 0), (0, 1)]
    for j, (b, c) in enumerate(axes, start=d):
        A[:, j] = np.where(component == b, -centred[:, c], np.where(component == c, centred[:, b], 0.0))
    coef = np.linalg.lstsq(A, increment, rcond=None)[0]
    return float(np.max(np.abs(A @ coef - increment), initial=0.0))


def deformed_fragments(points, triangles, dofs, increment):
    """Fragments whose prescribed increments are not a rigid motion of the fragment.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 2) or (nv, 3)
        Reference coordinates of the vertices.
    triangles : numpy.ndarray of int, shape (ne, 3) or (ne, 4)
        Vertex numbers of the triangles (tetrahedra in 3D, 0-based).
    dofs, increment : numpy.ndarray
        Fixed dofs of the P1 VectorH1 space on this mesh (component c of vertex i is
        dof ``c * nv + i``) and the change of their prescribed values
        (:func:`prescribed_increment`).

    Returns
    -------
    piece : numpy.ndarray of int, shape (nv,)
        Fragment of every vertex (connected through elements).
    deformed : numpy.ndarray of bool, shape (number of fragments,)
        True for a fragment that the prescribed increments strain.

    Raises
    ------
    ValueError
        If a dof is not a vertex dof of a P1 space on this mesh.
    """
    nv, d = points.shape
    dofs = np.asarray(dofs, dtype=np.int64)
    if dofs.size and (dofs.min() < 0 or dofs.max() >= d * nv):
        raise ValueError(f"fixed dofs must be P1 vertex dofs (0 .. {d * nv - 1}) of the {nv}-vertex mesh")
    count, piece = rigid.pieces(np.asarray(triangles), nv)
    deformed = np.zeros(count, dtype=bool)
    vertex, component = dofs % nv, dofs // nv
    tol = RIGID_TOL * float(np.max(np.abs(increment), initial=0.0))
    if tol == 0.0:
        return piece, deformed        # nothing moves: nothing is deformed
    owner = piece[vertex]
    for f in np.unique(owner):        # fragments with fixed dofs: few, each a small fit
        on = owner == f
        deformed[f] = _rigid_misfit(points, vertex[on], component[on], increment[on]) > tol
    return piece, deformed


def load_path_cut(points, triangles, dofs, increment):
    """True when the prescribed increments deform the body but none of its fragments.

    The body is loaded by its prescribed displacements if they are not one rigid motion
    of all of it; it is broken through when, on top of that, every fragment follows its
    own share of them rigidly (no fragment connects boundaries that move against each
    other). False for a body that prescribed displacements do not load at all.

    Parameters
    ----------
    points, triangles, dofs, increment
        As for :func:`deformed_fragments`.

    Returns
    -------
    bool
    """
    piece, deformed = deformed_fragments(points, triangles, dofs, increment)
    if deformed.any() or len(dofs) == 0:
        return False
    nv = len(points)
    tol = RIGID_TOL * float(np.max(np.abs(increment), initial=0.0))
    return _rigid_misfit(points, dofs % nv, dofs // nv, increment) > tol
