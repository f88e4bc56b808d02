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
"""
import numpy as np
import scipy.sparse as sp

from ..geometry.meshio import orient_segments

__all__ = ["oriented_segments", "pressure_forces", "pressure_stiffness", "total_pressure_forces"]


def oriented_segments(arrays, boundary):
    """The segments of a boundary, each turned so that its triangle lies on its left.

    Parameters
    ----------
    arrays : MeshArrays
    boundary : str

    Returns
    -------
    numpy.ndarray (m, 2)
    """
    return orient_segments(arrays.triangles, arrays.boundary_segments(boundary))


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
