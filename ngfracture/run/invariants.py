"""What every accepted step keeps: area to the last bit, no inverted triangle, no overlap.

A load step's attempt is judged before it is accepted (:meth:`ngfracture.run.step.LoadStep.step`);
one that breaks an invariant is not accepted but retried as a failed solve is (full Newton,
then a smaller increment), and when the retries run out the run ends with the invariant,
the step and the size of the violation in its reason.

* **Area** (volume in 3D): splitting copies vertices and renumbers triangles, it never
  moves a coordinate, so ``math.fsum`` of the reference triangle areas (tetrahedron
  volumes) equals the scene's to the last bit.
* **No inverted triangle**: every triangle of the deformed configuration keeps a positive
  area (for P1, det F > 0). The nonlinear models' Newton solves check det F at every
  iterate; the linear model has no such notion, so this is where an inverted triangle
  of a linear run is found.
* **No overlap**: the deformed pieces (fragments, and the two lips of a crack) overlap by
  at most :data:`OVERLAP_TOL` of the body's area, measured exactly by
  :func:`ngfracture.contact.overlap.fragment_overlap_area`. Contact keeps penetration
  below 1e-10 of its detection threshold, a length; the overlap of the polygonal lips that
  remains is of second order in that (the scenes end with 1e-16 of the area or less,
  docs/verification.md). A 2D run without contact (``contact="never"``) is held to the
  same bound: pieces that only separate never overlap. A 3D run without contact rows
  (``contact="never"`` or ``Scene.contact`` False) records the deepest vertex in another
  piece and notes it (``step.UNHELD_NOTE``), not enforced: no row holds the pieces apart
  (:meth:`ngfracture.run.step.LoadStep.check`). In 3D with contact two things are
  checked: that no boundary vertex of a piece lies deeper than :data:`OVERLAP_TOL` of the
  body's diameter (the diagonal of its bounding box) inside another piece, or a lip vertex
  deeper in the other lip of its own crack, by
  :func:`ngfracture.contact.collision3d.detect_penetrations_3d`
  (exact predicates; the largest depth is what the step records as its overlap), and that
  the volume shared by tetrahedra of different fragments is at most :data:`OVERLAP_TOL` of
  the body's volume (:func:`overlap_volume_3d`, exact clipping): faces can cross with no
  vertex inside another piece, which node-to-face rows do not hold (docs/solid.md,
  "Overlap in the free run"). This is checked where a 3D run solves with contact
  (``Scene.contact`` True, :meth:`ngfracture.run.step.LoadStep.needs_contact`); the
  written files are measured the same way by
  :func:`ngfracture.output.overlap3d.vtu_overlap_volume`.

The checks cost a few percent of a run (docs/performance.md): the overlap is measured only
where there are cracks or separate bodies.
"""
from dataclasses import dataclass

import numpy as np

from ..contact.collision3d import detect_penetrations_3d
from ..contact.overlap import fragment_overlap_area
from ..output.overlap3d import fragment_overlap_volume
from ..fracture.strain import vertex_displacement
from ..fracture.fragments import FragmentStatistics

__all__ = ["OVERLAP_TOL", "Violation", "check_state", "depth_limit_3d", "penetration_depth_3d", "overlap_volume_3d"]

#: overlap accepted between pieces, relative to the body's area
OVERLAP_TOL = 1e-10


@dataclass(frozen=True)
class Violation:
    """An invariant an attempt breaks.

    Parameters
    ----------
    invariant : {"area", "inverted_element", "overlap"}
    size : float
        How much: the area difference, the smallest det F, or the overlap (the area in 2D;
        in 3D the deepest vertex's depth or the overlap volume).
    message : str
        Says what, where and how much, against which tolerance.
    """
    invariant: str
    size: float
    message: str


def check_state(problem, area_initial, with_overlap):
    """The first invariant a solved problem breaks, or None.

    Parameters
    ----------
    problem : ElasticProblem
        The equilibrium at the end of an attempt.
    area_initial : float
        ``math.fsum`` of the scene's reference triangle areas.
    with_overlap : bool
        Measure the overlap (there are cracks or separate bodies).

    Returns
    -------
    violation : Violation or None
    overlap : float
        The overlap area (0 when not measured), for the step's record.
    """
    area = FragmentStatistics(problem.mesh).total_area
    if area != area_initial:
        return Violation("area", area - area_initial,
                         f"the reference area is {area!r}, not {area_initial!r}"), 0.0
    det_f = problem.min_det_F()          # P1: deformed over reference area, per triangle
    worst = int(np.argmin(det_f))
    if not det_f[worst] > 0:
        return Violation("inverted_element", float(det_f[worst]),
                         f"{'tetrahedron' if problem.dim == 3 else 'triangle'} {worst} is inverted in the deformed configuration (det F "
                         f"{det_f[worst]:.3g})"), 0.0
    if problem.dim == 3:
        depth = penetration_depth_3d(problem) if with_overlap else 0.0
        limit = depth_limit_3d(problem)
        if not depth <= limit:
            return Violation("overlap", depth,
                             f"a vertex lies {depth:.3g} deep in another piece ({depth * OVERLAP_TOL / limit:.2g} "
                             f"of the body's diameter; at most {OVERLAP_TOL:g} of it is accepted)"), depth
        volume = overlap_volume_3d(problem) if with_overlap else 0.0
        if not volume <= OVERLAP_TOL * area_initial:
            return Violation("overlap", volume,
                             f"fragments overlap by {volume:.3g} ({volume / area_initial:.2g} of the volume; at "
                             f"most {OVERLAP_TOL:g} of it is accepted) with no vertex inside another piece: "
                             f"faces crossing"), depth
        return None, depth
    overlap = fragment_overlap_area(problem) if with_overlap else 0.0
    if not overlap <= OVERLAP_TOL * area_initial:
        return Violation("overlap", overlap,
                         f"pieces overlap by {overlap:.3g} ({overlap / area_initial:.2g} of the area; "
                         f"at most {OVERLAP_TOL:g} of it is accepted)"), overlap
    return None, overlap


def overlap_volume_3d(problem):
    """The volume shared by tetrahedra of different fragments, in the deformed configuration.

    Parameters
    ----------
    problem : ElasticProblem
        A problem on a tetrahedral mesh, at its current displacement.

    Returns
    -------
    float
        :func:`ngfracture.output.overlap3d.fragment_overlap_volume` (exact clipping, C++),
        the fragments being the mesh's connected pieces.
    """
    tets = problem.arrays.tets
    _, piece = problem.fragments()
    points = problem.arrays.points + vertex_displacement(problem.u)
    return fragment_overlap_volume(points, tets, piece[tets[:, 0]], body_volume=0.0).volume


def depth_limit_3d(problem):
    """The depth a vertex may lie inside another piece: ``OVERLAP_TOL`` of the body's diameter
    (the diagonal of the reference points' bounding box).

    Parameters
    ----------
    problem : ElasticProblem

    Returns
    -------
    float
    """
    P = problem.arrays.points
    return OVERLAP_TOL * float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))


def penetration_depth_3d(problem):
    """The deepest boundary vertex of a piece inside another piece, on a tetrahedral mesh.

    Parameters
    ----------
    problem : ElasticProblem
        A problem on a tetrahedral mesh, at its current displacement.

    Returns
    -------
    float
        max(0, -gap) over the pairs of :func:`ngfracture.contact.collision3d.detect_penetrations_3d`
        (the distance to the master face; crack lips of one piece included); 0 with no pair.

    Raises
    ------
    ValueError
        If the problem is not three-dimensional.
    """
    if problem.dim != 3:
        raise ValueError(f"penetration_depth_3d needs a tetrahedral mesh, got dimension {problem.dim}")
    a = problem.arrays
    _, piece = problem.fragments()
    pen = detect_penetrations_3d(a.points, a.tets, a.faces, piece[a.tets[:, 0]],
                                 displacement=vertex_displacement(problem.u))
    return float(max(0.0, -pen.gap.min(initial=0.0)))
