"""What the loads do and what the supports carry: load vectors, work, boundary resultants.

A run's energy balance (external work = elastic energy + released energy) counts the work
of every load: prescribed displacements (their reactions, run/step.py) and the dead loads
of :meth:`ElasticProblem.add_traction` and ``add_body_force`` (:func:`load_vector`, summed
by the trapezoid rule over each increment and at fixed load over each crack pass). The
resultants of :func:`boundary_resultants` are the points of a load-displacement curve.
"""
import math

import numpy as np
import ngsolve as ng

from ..fracture.strain import vertex_displacement
from .pressure import pressure_forces

__all__ = ["load_vector", "work_of_forces", "reaction_work", "boundary_resultants", "unsupported_pieces"]


def load_vector(problem, boundary=None):
    """The external nodal forces of the problem's loads, fully applied (pressures at the current configuration).

    A solve ramps the loads up with ``problem.load_factor`` from 0 to 1; a solved state
    carries them whole, which is what this returns.

    Parameters
    ----------
    problem : ElasticProblem
    boundary : str, optional
        Only the tractions on this boundary.

    Returns
    -------
    numpy.ndarray (ndof,)
        Zero when there are no such loads.
    """
    loads = [(k, cf, r) for k, cf, r in problem.loads if boundary is None or r == boundary]
    out = np.zeros(problem.fes.ndof)
    x = problem.pressure_positions()     # the current configuration (the reference one if linear)
    for region, p, segments in problem.pressures():
        if boundary is None or region == boundary:
            out += pressure_forces(x, segments, p, problem.fes.ndof)
    dead = [(k, cf, r) for k, cf, r in loads if k != "pressure"]
    if not dead:
        return out
    v = problem.fes.TestFunction()
    f = ng.LinearForm(problem.fes)
    for kind, cf, region in dead:
        f += (cf * v) * (ng.dx if kind == "volume" else ng.ds(region))
    with problem.threads():
        f.Assemble()
    return out + f.vec.FV().NumPy()


def work_of_forces(f_start, f_end, u_start, u_end):
    """Work of nodal forces over a displacement increment (trapezoid rule).

    Parameters
    ----------
    f_start, f_end : numpy.ndarray
        The forces at the start and the end (equal for a change at fixed load).
    u_start, u_end : numpy.ndarray
        The displacements, in the same dof numbering.

    Returns
    -------
    float
    """
    return float(0.5 * np.dot(f_start + f_end, u_end - u_start))


def reaction_work(problem, fixed_dofs, fixed_values, reactions):
    """Work of the reactions over an increment just solved (trapezoid rule).

    The increment is solved on the mesh of the state it starts from, so its fixed dofs
    have the numbers they had there (cracks come later, at fixed load: they do no work);
    dofs fixed at only one of the two ends do no work of their own.

    Parameters
    ----------
    problem : ElasticProblem
        The solved increment.
    fixed_dofs, fixed_values, reactions : numpy.ndarray
        The fixed dofs (sorted), their values and their reactions at the start.

    Returns
    -------
    float
    """
    rows = problem.assemble_constraints()
    pos = np.searchsorted(rows.fixed_dofs, fixed_dofs)
    pos = np.minimum(pos, max(len(rows.fixed_dofs) - 1, 0))
    same = (rows.fixed_dofs[pos] == fixed_dofs) if len(rows.fixed_dofs) else np.zeros(0, bool)
    r_new = -problem.out_of_balance()[rows.fixed_dofs[pos[same]]]
    dg = rows.fixed_values[pos[same]] - fixed_values[same]
    return float(0.5 * np.dot(reactions[same] + r_new, dg))


def _boundary_dofs(problem, name):
    """Scalar (vertex) dofs of a boundary, its segments (faces in 3D), and the length (area)
    of each."""
    X = problem.arrays.points
    if problem.dim == 3:
        faces = problem.arrays.boundary_faces(name)
        x = X[faces]
        size = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
        return np.unique(faces), faces, size
    segments = problem.arrays.boundary_segments(name)
    return np.unique(segments), segments, np.hypot(*(X[segments[:, 1]] - X[segments[:, 0]]).T)


def boundary_resultants(problem, out_of_balance):
    """Force and mean displacement of every boundary with a prescribed displacement or a traction.

    The force on a boundary with prescribed displacement is the sum of the reactions at
    its fixed dofs (a corner shared by two such boundaries counts for both); on a boundary
    with a traction, the resultant of the traction. The displacement is the mean over the
    boundary's length (area in 3D) of the P1 displacement.

    Parameters
    ----------
    problem : ElasticProblem
        A solved P1 problem.
    out_of_balance : numpy.ndarray
        ``problem.out_of_balance()`` at its solution (minus the reactions at fixed dofs).

    Returns
    -------
    dict of str -> dict
        ``{"force": [Fx, Fy(, Fz)], "displacement": [ux, uy(, uz)]}`` per boundary name, sorted.
    """
    rows = problem.assemble_constraints()
    fixed = np.zeros(problem.fes.ndof, dtype=bool)
    fixed[rows.fixed_dofs] = True
    d = problem.dim
    n = problem.fes.ndof // d
    U = vertex_displacement(problem.u)
    names = {name for cond in problem.constraints.dirichlet for name in cond.boundaries}
    loaded = {r for kind, _, r in problem.loads if kind in ("boundary", "pressure")}
    out = {}
    for name in sorted(names | loaded):
        dofs, cells, size = _boundary_dofs(problem, name)
        if name in loaded:
            f = load_vector(problem, name)
            force = [math.fsum(f[c * n + dofs]) for c in range(d)]
        else:
            force = [-math.fsum(out_of_balance[c * n + dofs][fixed[c * n + dofs]]) for c in range(d)]
        mid = U[cells].mean(axis=1)
        mean = (size @ mid) / max(size.sum(), 1e-300)
        out[name] = {"force": [float(v) for v in force], "displacement": [float(v) for v in mean]}
    return out


def unsupported_pieces(problem, contact_holds=True):
    """The pieces whose loads nothing holds: no equilibrium exists for them.

    A piece without fixed dofs is in equilibrium only if its loads do no work on its free
    rigid modes (zero resultant along a free translation, zero moment along a free
    rotation), or if contact rows (the problem's general rows) touch it and may hold it.
    Under force control a crack that cuts a loaded piece off its supports leaves such a
    piece; a solve would fail on it, or the holds of free modes would carry its load.

    Parameters
    ----------
    problem : ElasticProblem
        With its constraints (and any contact rows) as solved.
    contact_holds : bool
        Count a piece that general rows (contact) touch as held. False after a solve that
        failed: contact only pushes, and a piece its loads pull away is not held by it.

    Returns
    -------
    str
        Names the first such piece and its unbalanced load, or "" when every loaded piece
        is held.
    """
    if not problem.loads:
        return ""
    forces = load_vector(problem)
    rows = problem.assemble_constraints()
    modes = problem.support(rows).modes.tocsc()
    if modes.shape[1] == 0 or not np.any(forces):
        return ""
    nv, n = problem.mesh.nv, problem.fes.ndof // problem.dim
    _, piece = problem.fragments()
    touched = np.unique(rows.C.tocoo().col % n) if rows.C.nnz and contact_holds else np.zeros(0, dtype=np.int64)
    held = set(piece[touched[touched < nv]].tolist())
    for j in range(modes.shape[1]):
        col = modes[:, j]
        vertices = col.indices % n
        which = int(piece[vertices[vertices < nv][0]]) if np.any(vertices < nv) else -1
        if which in held:
            continue
        work = float(col.data @ forces[col.indices])
        scale = np.linalg.norm(forces[col.indices]) * np.linalg.norm(col.data)
        if abs(work) > 1e-8 * scale:
            return (f"piece {which} carries loads (work {work:.3g} on one of its rigid modes) but nothing "
                    f"holds it: it has lost its support")
    return ""
