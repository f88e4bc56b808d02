"""Resolution where the crack is: refinement ahead of crack tips during a run (Scene.refine).

The critical-distance criterion judges the stress at distance r from a tip; it converges
when the triangles there are small against r. A scene with ``refine`` starts from a
coarse mesh, and every equilibrium the crack engine is about to judge is first refined
around the places that can crack:

* every sharp tip (crack tips and sharp notch tips, :func:`ngfracture.geometry.refine.sharp_vertices`),
* every triangle whose local overstrain (``Criterion.element_overstrain``) has reached
  :data:`REFINE_AT` and differs from a neighbour's by :data:`REFINE_JUMP` or more: a stress
  concentration on its way to cracking that the mesh does not resolve (a hole's edge, a
  blunt notch, a bent surface). A body stressed near its strength but uniformly (the
  plate's ligament) is not refined: there the mesh reads the field right already,

to the target edge length h within ``REFINE_RADIUS`` r of them once a triangle within
``REFINE_REACH`` r is too long (Scene.refinement), and the equilibrium is solved again on
the refined mesh at the same load. Only then does the
crack pass split. A crack growing at fixed load is refined after each split, so its tip
always advances into refined material.

What carries over: the displacement and the per-vertex strength by the refinement's
prolongation (exact for the P1 displacement); boundary names, regions and crack faces.
The reference area changes only by the rounding of boundary midpoints (at most
AREA_ROUNDING of it, checked), and the area invariant holds to the last bit from one
refinement to the next. Work of dead loads while the refined body settles at fixed load is
counted as at any fixed-load solve; the elastic energy a finer mesh releases (it is
softer) is part of the released energy.
"""
from typing import NamedTuple

import numpy as np

from ..fracture.fragments import FragmentStatistics
from ..fracture.strain import principal
from ..geometry.refine import AREA_ROUNDING, refine_near, sharp_vertices
from ..mechanics.resultants import load_vector, work_of_forces

__all__ = ["REFINE_AT", "MAX_REFINEMENTS", "Refined", "refine_initial", "refine_equilibrium"]

#: a vertex whose criterion measure reaches this fraction of cracking is refined around
#: (with the crack tips and sharp notch tips): it may crack at the next equilibrium, and it
#: must be judged on a mesh that resolves r. A body loaded near its strength but below
#: this (the plate's ligament at 0.7 while a crack grows) is left as it is
REFINE_AT = 0.9
#: ... and reaches this fraction of the largest measure: under a load step that overshoots
#: (a whole ligament above its strength, its notch tip far above) the vertices that may
#: split next are the most overstrained ones, one per pass (StepControl split "one"); a
#: coarse mesh reads a concentration low by less than this
REFINE_NEAR_MAX = 0.8
#: refinements of one equilibrium at most (each may reveal a new hot spot to refine around)
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


def _centres(stepper, prob, strength, timings):
    """Where to refine: the sharp tips (crack tips, notch tips), and the vertices whose
    criterion measure has reached REFINE_AT and REFINE_NEAR_MAX of the largest."""
    arrays = prob.arrays
    with timings.timed("strain"):
        tensors = stepper.criterion.overstrain(prob.mesh, prob.u, strength, arrays=arrays)
    measure = principal(tensors)[0]
    hot = measure >= max(REFINE_AT, REFINE_NEAR_MAX * measure.max(initial=0.0))
    import os
    if os.environ.get("NGF_GEOMETRIC_ONLY"):
        hot[:] = False
    points = arrays.points
    return np.concatenate([points[sharp_vertices(arrays)], points[hot]])


def _transferred(refinement, prob, strength):
    """The displacement vector and the strength on the refined mesh."""
    nv = prob.mesh.nv
    U = prob.u.vec.FV().NumPy().reshape(2, -1)[:, :nv].T
    u = refinement.transfer(U).T.reshape(-1)
    return u, (None if strength is None else refinement.transfer(strength))


def refine_initial(stepper, mesh, strength, timings):
    """The scene's mesh refined around its sharp tips (no load yet), or as it is.

    Parameters
    ----------
    stepper : LoadStep
    mesh : ngsolve.Mesh
    strength : numpy.ndarray or None
    timings : Timings

    Returns
    -------
    (ngsolve.Mesh, numpy.ndarray or None)
    """
    spec = stepper.scene.refinement()
    if spec is None:
        return mesh, strength
    h, radius, _ = spec
    prob = stepper.problem(mesh, 0.0, timings)
    with timings.timed("refine"):
        ref = refine_near(mesh, prob.arrays.points[sharp_vertices(prob.arrays)], radius, h, arrays=prob.arrays)
    if ref is None:
        return mesh, strength
    return ref.mesh, (None if strength is None else ref.transfer(strength))


def refine_equilibrium(stepper, prob, eq, x, strength, area, method, timings):
    """Refine an equilibrium around its tips and hot spots and solve it again there.

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
    method : {"modified", "full"}
    timings : Timings

    Returns
    -------
    Refined

    Raises
    ------
    StepFailed
        The solve on the refined mesh failed.
    ValueError
        A refinement changed the area by more than rounding.
    """
    spec = stepper.scene.refinement()
    work, iterations, count = 0.0, 0, 0
    if spec is None:
        return Refined(prob, eq, strength, area, work, iterations, count)
    h, radius, reach = spec
    for _ in range(MAX_REFINEMENTS):
        centres = _centres(stepper, prob, strength, timings)
        with timings.timed("refine"):
            ref = refine_near(prob.mesh, centres, radius, h, reach, arrays=prob.arrays)
        if ref is None:
            break
        u, strength = _transferred(ref, prob, strength)
        new = stepper.problem(ref.mesh, x, timings, u)
        refined_area = FragmentStatistics(ref.mesh).total_area
        if abs(refined_area - area) > AREA_ROUNDING * area:
            raise ValueError(f"a refinement changed the reference area from {area!r} to {refined_area!r}")
        eq = stepper.equilibrium(new, "relaxation", method, timings)
        if new.loads:        # the dead loads work while the refined body settles
            forces = load_vector(new)
            work += work_of_forces(forces, forces, u, new.u.vec.FV().NumPy())
        prob, area, iterations, count = new, refined_area, iterations + eq.iterations, count + 1
    return Refined(prob, eq, strength, area, work, iterations, count)
