"""A crack pass on a tetrahedral mesh: the 3D counterpart of ``LoadStep.crack_pass``.

The overstrain tensors come from the scene's criterion (``Criterion.overstrain``, which
judges tetrahedra in 3D); the 3D engine (:mod:`ngfracture.fracture.split3d`) splits them
as ``StepControl.split`` says: "one" (the most overstressed vertex that splits anything),
"spread" (in decreasing order, skipping those that share an edge with a vertex split
earlier in the pass; the 3D scenes' default, docs/solid.md "Crack passes in 3D") or "all";
the displacement and the strength are copied to the new vertices
through the parent map, exactly. The split mesh inherits the factorisation of the
equilibrium (``linalg.bordered.lineage``: the 3D engine appends the new vertices, numbered
after the old ones, and keeps every tetrahedron's element matrix at the state carried
over), as a 2D crack pass does.
"""
import time

import numpy as np

from ..fracture.split import transfer_vertex_field
from ..linalg import bordered
from ..fracture.split3d import split_by_tensor_3d
from ..geometry.solid import solid_mesh
from .records import CrackPass

__all__ = ["solid_crack_pass"]


def solid_crack_pass(stepper, prob, x, strength, tensors, largest, tangent, timings):
    """Split the overstressed vertices of a 3D equilibrium.

    Parameters
    ----------
    stepper : LoadStep
        Builds the scene's problem on the split mesh.
    prob : ElasticProblem
        The equilibrium, on a tetrahedral mesh.
    x : float
        Its load parameter.
    strength : numpy.ndarray or None
        Critical strain per vertex.
    tensors : numpy.ndarray
        Overstrain per vertex, shape (nv, 6).
    largest : float
        Their largest principal value (for the record).
    tangent : SavedTangent or None
        The tangent the equilibrium ended with: the split mesh's solves start from it.
    timings : Timings

    Returns
    -------
    CrackPass
    """
    t0 = time.perf_counter()
    res = split_by_tensor_3d(prob.arrays, tensors, 1.0, mode=stepper.control.split)
    timings.add("split", time.perf_counter() - t0)
    if res.nsplit == 0:
        return CrackPass(None, 0, strength, None, np.zeros((0, 3)), largest, res.refusals, res.refused)
    made = np.diff(res.record["new_offsets"]) > 0
    positions = prob.arrays.points[res.record["vertex"][made]]
    # P1: the displacement is a vertex field (component-major), copied through the split
    u = transfer_vertex_field(prob.u.vec.FV().NumPy().reshape(3, -1).T, res).T.reshape(-1)
    if strength is not None:
        strength = transfer_vertex_field(strength, res)    # copies inherit the vertex's strength
    inherited = bordered.lineage(tangent.factor, tangent.state, res.parent) if tangent is not None else None
    with timings.timed("rebuild"):
        mesh = solid_mesh(res.arrays)
    split = stepper.problem(mesh, x, timings, u, check_mesh=False)
    return CrackPass(split, res.nsplit, strength, inherited, positions, largest)
