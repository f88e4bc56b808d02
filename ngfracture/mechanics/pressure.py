"""Pressure on named boundaries: a load that follows the deformed surface.

A pressure p (> 0 pushes into the body) on a boundary segment a -> b (the body on its
left) of current length L and outward normal n gives the nodal forces

    f_a = f_b = -p L n / 2 = (p / 2) Q (x_b - x_a),   Q = [[0, -1], [1, 0]],

linear in the current positions. Its stiffness -df/dx is constant; on a closed chain of
segments (a hole, the two lips of a crack) it is symmetric and the pressure conservative
(its potential is p times the enclosed area); at the ends of an open chain its
antisymmetric part does not cancel. The tangent takes the symmetric part: exact on closed
chains, and for open ones what the symmetric solvers can factorise (the residual is
exact, so the solution is). The linear model takes the pressure on the reference
configuration (a dead load, as its small-strain theory has it).

Crack faces inherit the pressure of the boundary they grow from (a fluid-filled hole
fills its cracks): the crack faces connected, through the vertices the crack segments
share, to a vertex of the pressurised boundary carry its pressure. Both lips of a crack
meet at its tip, and a crack's mouth copies lie on the boundary it started from, so a
crack from a pressurised hole is pressurised along its whole length, its branches with it,
and a crack that nucleates elsewhere joins once it links to the hole.
"""
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..geometry.meshio import orient_segments

__all__ = ["oriented_segments", "connected_crack_segments", "check_no_overlap", "pressure_forces", "pressure_stiffness", "total_pressure_forces"]


def oriented_segments(arrays, boundary, crack_faces=False, crack_name="crack"):
    """The segments of a boundary, each turned so that its triangle lies on its left.

    Parameters
    ----------
    arrays : MeshArrays
    boundary : str
    crack_faces : bool
        With the crack faces connected to the boundary (:func:`connected_crack_segments`).
    crack_name : str

    Returns
    -------
    numpy.ndarray (m, 2)
    """
    segments = arrays.boundary_segments(boundary)
    if crack_faces and boundary != crack_name:
        segments = np.concatenate([segments, connected_crack_segments(arrays, segments, crack_name)])
    return orient_segments(arrays.triangles, segments)


def connected_crack_segments(arrays, segments, crack_name="crack"):
    """The crack-face segments connected through shared vertices to a vertex of ``segments``.

    Parameters
    ----------
    arrays : MeshArrays
    segments : numpy.ndarray (m, 2)
        The segments of a boundary.
    crack_name : str

    Returns
    -------
    numpy.ndarray (k, 2)
        Empty when no crack touches them.
    """
    crack = arrays.boundary_segments(crack_name)
    if len(crack) == 0 or len(segments) == 0:
        return np.zeros((0, 2), dtype=crack.dtype)
    nv = len(arrays.points)
    graph = sp.coo_matrix((np.ones(len(crack)), (crack[:, 0], crack[:, 1])), shape=(nv, nv))
    _, label = connected_components(graph, directed=False)
    touched = np.zeros(label.max() + 1, dtype=bool)
    touched[label[np.unique(segments)]] = True
    # a vertex no crack segment holds is a component of its own: it marks nothing else
    return crack[touched[label[crack[:, 0]]]]


def check_no_overlap(pressures, boundary, segments):
    """Refuse a pressure on segments that another pressure already loads.

    Parameters
    ----------
    pressures : sequence of (str, float, numpy.ndarray)
        The pressures so far (boundary, p, segments).
    boundary : str
    segments : numpy.ndarray (m, 2)

    Returns
    -------
    numpy.ndarray (m, 2)
        ``segments``.

    Raises
    ------
    ValueError
        Naming both boundaries (a crack face inherits the pressure of a boundary it is
        connected to: name one of them, or pass crack_faces=False).
    """
    new = {tuple(e) for e in np.sort(segments, axis=1).tolist()}
    for other, _, seg in pressures:
        if new.intersection(tuple(e) for e in np.sort(seg, axis=1).tolist()):
            raise ValueError(f"the pressure on {boundary!r} would load segments the pressure on {other!r} "
                             f"loads already (crack faces carry the pressure of the boundary they are "
                             f"connected to); give one pressure, or crack_faces=False")
    return segments


def pressure_forces(x, segments, p, ndof):
    """Nodal forces of a pressure on segments at the positions x.

    Parameters
    ----------
    x : numpy.ndarray (nv, 2)
        Current (or reference) vertex positions.
    segments : numpy.ndarray (m, 2)
        Vertex pairs a -> b, the body on the left.
    p : float
        The pressure (> 0 pushes into the body).
    ndof : int
        Length of the result (P1 VectorH1 layout: component c of vertex v at c * ndof/2 + v).

    Returns
    -------
    numpy.ndarray (ndof,)
    """
    out = np.zeros(ndof)
    if len(segments) == 0 or p == 0:
        return out
    n = ndof // 2
    a, b = segments[:, 0], segments[:, 1]
    d = x[b] - x[a]
    f = 0.5 * p * np.column_stack([-d[:, 1], d[:, 0]])       # (p / 2) Q (x_b - x_a)
    for c in (0, 1):
        np.add.at(out, c * n + a, f[:, c])
        np.add.at(out, c * n + b, f[:, c])
    return out


def pressure_stiffness(segments, p, ndof):
    """The symmetric part of the pressure's stiffness -df/dx (constant, see the module docstring).

    Parameters
    ----------
    segments : numpy.ndarray (m, 2)
    p : float
    ndof : int

    Returns
    -------
    scipy.sparse.csr_matrix (ndof, ndof)
        Blocks -(p/2) Q at (a, b) and (p/2) Q at (b, a): entries (ax, by) = p/2,
        (ay, bx) = -p/2 and their transposes.
    """
    n = ndof // 2
    a, b = segments[:, 0], segments[:, 1]
    h = 0.5 * p * np.ones(len(segments))
    rows = np.concatenate([a, n + a, n + b, b])
    cols = np.concatenate([n + b, b, a, n + a])
    vals = np.concatenate([h, -h, h, -h])
    return sp.csr_matrix((vals, (rows, cols)), shape=(ndof, ndof))


def total_pressure_forces(problem, u=None):
    """The nodal forces of every pressure of a problem, fully applied.

    Parameters
    ----------
    problem : ElasticProblem
    u : numpy.ndarray, optional
        A displacement instead of the current one.

    Returns
    -------
    numpy.ndarray (ndof,)
        At ``problem.pressure_positions(u)``: the current positions, the reference ones for
        the linear model.
    """
    ndof = problem.fes.ndof
    out = np.zeros(ndof)
    pressures = problem.pressures()
    if pressures:
        x = problem.pressure_positions(u)
        for _, p, segments in pressures:
            out += pressure_forces(x, segments, p, ndof)
    return out
