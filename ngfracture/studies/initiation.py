"""The initiation load of a scene: where and at which load its criterion first reaches 1.

``initiation_load(scene, x)`` solves the scene's uncracked problem at one load ``x`` (its
mesh, material and ``apply_load``), judges it with the scene's own criterion
(``Scene.criterion().overstrain``, the function a crack pass calls, 2D or 3D) and returns
``x / m``, m the largest overstrain. Under linear elasticity the overstrain is linear in
the load, so ``x / m`` is the load at which it reaches 1 exactly. With St Venant-Kirchhoff
(the scenes' material) the Green-Lagrange strain adds terms of the order of the strain
itself: at a strain of 1e-4 they move the estimate by about 1e-4 of itself (measured on
``bar3d`` at x = 1e-5: 6e-6 against ``LinearElastic`` of the same E and nu), which is why ``x``
defaults to a small load. It is the load at which a run's first crack pass would split,
without the run: the quantity whose convergence under refinement docs/solid.md
("Convergence of initiation in 3D") measures.
"""
from dataclasses import dataclass

import numpy as np

from ..fracture.strain import principal
from ..mechanics.problem import ElasticProblem

__all__ = ["Initiation", "initiation_load"]


@dataclass
class Initiation:
    """The initiation estimate of one scene.

    Parameters
    ----------
    load : float
        x / largest overstrain: the load at which the criterion reaches 1.
    vertex : int
        The vertex that reaches it first.
    position : numpy.ndarray
        Its coordinates.
    direction : numpy.ndarray
        Its opening direction (unit vector).
    overstrain : numpy.ndarray
        The largest principal overstrain per vertex at the solved load.

    Returns
    -------
    Initiation

    Raises
    ------
    TypeError
        A missing field.
    """
    load: float
    vertex: int
    position: np.ndarray
    direction: np.ndarray
    overstrain: np.ndarray


def initiation_load(scene, x=None):
    """The load at which a scene's criterion first reaches 1, from one solve at load x.

    Parameters
    ----------
    scene : Scene
        Its mesh, material, ``apply_load``, critical strain and critical distance are used.
    x : float, optional
        The load solved for (default: the scene's first increment ``scene.dx``); small, so
        that a nonlinear material is in its linear range.

    Returns
    -------
    Initiation

    Raises
    ------
    ValueError
        A load that is not a finite number > 0, a solve that does not converge, or a
        criterion that is 0 everywhere at that load (nothing loaded).
    """
    x = float(scene.dx if x is None else x)
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"initiation_load: the load x must be a finite number > 0, got {x!r}")
    prob = ElasticProblem(scene.mesh, scene.material)
    scene.apply_load(prob, x)
    status = prob.solve()
    if not status.converged:
        raise ValueError(f"initiation_load: scene {scene.name!r} at x = {x}: the solve did not converge "
                         f"({status.message})")
    strength = None if scene.strength is None else np.array(scene.strength, dtype=float)
    tensors = scene.criterion().overstrain(prob.mesh, prob.u, strength, arrays=prob.arrays)
    values, directions = principal(tensors)
    best = int(np.argmax(values))
    if not values[best] > 0:
        raise ValueError(f"initiation_load: scene {scene.name!r} at x = {x}: the criterion is 0 everywhere")
    points = np.asarray(prob.arrays.points)
    return Initiation(x / float(values[best]), best, points[best].copy(), directions[best].copy(), values)
