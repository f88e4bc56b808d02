"""Resolution where the crack is: refinement ahead of crack tips during a run (Scene.refine).

The critical-distance criterion judges the stress at distance r from a tip; it converges
when the triangles there are small against r. A scene with ``refine`` starts from a
coarse mesh, and every equilibrium the crack engine is about to judge is first refined
around its sharp tips (crack tips and sharp notch tips,
:func:`ngfracture.geometry.refine.sharp_vertices`) to the target edge length within
``REFINE_RADIUS`` r of them, once a triangle within ``REFINE_REACH`` r is too long
(Scene.refinement); the equilibrium is solved again on the refined mesh at the same load,
and only then does the crack pass split. A crack growing at fixed load is refined after
each split, so its tip always advances into refined material.

Only the tips: the criterion's measure at a point of a smooth field is read right by a
coarse mesh, and a measure-based indicator refines the whole body where the field is
near-uniform (the plate at its first crack: the notch tip at 1.07 of its strength, the
rest of the plate at 0.96). A smooth concentration (a hole) is judged at the initial
mesh's resolution until it cracks; its crack's tips are refined from then on.

What carries over: the displacement and the per-vertex strength by the refinement's
prolongation (exact for the P1 displacement); boundary names, regions and crack faces.
The reference area changes only by the rounding of boundary midpoints (at most
AREA_ROUNDING of it, checked), and the area invariant holds to the last bit from one
refinement to the next. Work of dead loads while the refined body settles at fixed load is
counted as at any fixed-load solve; the elastic energy a finer mesh releases (it is
softer) is part of the released energy.
"""
from typing import NamedTuple

from ..geometry.meshio import mesh_to_arrays
from ..geometry.refine import refine_near, sharp_vertices
from ..mechanics.resultants import load_vector, work_of_forces

__all__ = ["MAX_REFINEMENTS", "Refined", "refine_initial", "refine_equilibrium"]

#: refinements of one equilibrium at most (a refinement that needs another is a bisection
#: closure that reached the zone of a second tip)
MAX_REFINEMENTS = 4


class Refined(NamedTuple):
    """An equilibrium after refinement (the same objects when nothing was refined)."""
    problem: object
    equilibrium: object
    strength: object
    area: float
    work: float
    iterations: int
    refinements: int


def _centres(arrays):
    """Where to refine: the sharp tips (crack tips, notch tips)."""
    return arrays.points[sharp_vertices(arrays)]


def _transferred(refinement, prob, strength):
    """The displacement vector and the strength on the refined mesh."""
    nv = prob.mesh.nv
    U = prob.u.vec.FV().NumPy().reshape(2, -1)[:, :nv].T
    u = refinement.transfer(U).T.reshape(-1)
    return u, (None if strength is None else refinement.transfer(strength))


def refine_initial(stepper, mesh, strength, area, timings):
    """The scene's mesh refined around its sharp tips (no load yet), or as it is.

    Parameters
    ----------
    stepper : LoadStep
    mesh : ngsolve.Mesh
    strength : numpy.ndarray or None
    area : float
        The mesh's reference area.
    timings : Timings

    Returns
    -------
    (ngsolve.Mesh, numpy.ndarray or None, float)
        The mesh, the strength on it and its reference area.
    """
    spec = stepper.scene.refinement()
    if spec is None:
        return mesh, strength, area
    h, radius, _ = spec
    with timings.timed("refine"):
        arrays = mesh_to_arrays(mesh)
        ref = refine_near(mesh, _centres(arrays), radius, h, arrays=arrays)
    if ref is None:
        return mesh, strength, area
    return ref.mesh, (None if strength is None else ref.transfer(strength)), ref.area


def refine_equilibrium(stepper, prob, eq, x, strength, area, method, timings):
    """Refine an equilibrium around its sharp tips and solve it again there.

    Parameters
    ----------
    stepper : LoadStep
    prob : ElasticProblem
        Solved at x.
    eq : Equilibrium
    x : float
    strength : numpy.ndarray or None
    area : float
        The reference area of prob's mesh (the area invariant's reference).
    method : {"modified", "full", "rescue"}
    timings : Timings

    Returns
    -------
    Refined

    Raises
    ------
    StepFailed
        The solve on the refined mesh failed.
    ValueError
        A refinement changed the area by more than rounding (:func:`refine_near`).
    """
    spec = stepper.scene.refinement()
    work, iterations, count = 0.0, 0, 0
    if spec is None:
        return Refined(prob, eq, strength, area, work, iterations, count)
    h, radius, reach = spec
    for _ in range(MAX_REFINEMENTS):
        with timings.timed("refine"):
            ref = refine_near(prob.mesh, _centres(prob.arrays), radius, h, reach, arrays=prob.arrays)
        if ref is None:
            break
        u, strength = _transferred(ref, prob, strength)
        new = stepper.problem(ref.mesh, x, timings, u)
        eq = stepper.equilibrium(new, "relaxation", method, timings)
        if new.loads:        # the dead loads work while the refined body settles
            forces = load_vector(new)
            work += work_of_forces(forces, forces, u, new.u.vec.FV().NumPy())
        prob, area, iterations, count = new, ref.area, iterations + eq.iterations, count + 1
    return Refined(prob, eq, strength, area, work, iterations, count)
