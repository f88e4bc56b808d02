"""A scene: everything that defines a fracture simulation except the step control."""
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..fracture.criterion import Criterion, critical_distance
from ..mechanics.materials import Material

__all__ = ["Scene", "REFINE_RADIUS", "REFINE_REACH"]


def _positive_or_none(value):
    return value is None or (not isinstance(value, bool) and isinstance(value, (int, float))
                             and math.isfinite(value) and value > 0)


#: triangles within this many critical distances of a tip are refined (Scene.refine) once
#: one within REFINE_REACH r is too coarse: the tip's rays read 2 r, and the tip advances
#: REFINE_RADIUS - REFINE_REACH r into refined material before the next refinement
REFINE_RADIUS = 3.0
REFINE_REACH = 1.5
#: the refined triangles' longest edge at most this times the target h: bisection halves a
#: triangle, so their edges then lie about h on average (a netgen mesh of maxh h alike)
LONGEST_EDGE = math.sqrt(2.0)


@dataclass
class Scene:
    """Everything that defines a fracture simulation except the step control.

    Parameters
    ----------
    name : str
        Shown in outputs and stored in checkpoints (a resume must match it).
    mesh : ngsolve.Mesh
        The undamaged body (or bodies) in the reference configuration.
    material : Material or dict of str -> Material
        One material, or one per material region.
    critical : float or dict of str -> float
        Critical principal strain (> 0), or one per region; a region missing from the
        dict (or given None) never cracks.
    apply_load : callable(problem, x)
        Adds the constraints (and loads) for the deformation parameter ``x`` to a fresh
        ElasticProblem on the current mesh. Boundary names survive cracking; crack faces
        are named ``crack``.
    load_max : float
        The deformation parameter at which the run ends (> 0).
    dx : float
        First increment of x (> 0).
    contact_tol : float
        Precision threshold of collision detection and contact selection (a length).
    contact : bool
        Solve with contact from the start (separate bodies). Otherwise a 2D scene solves
        with contact from the first crack on, and a 3D scene never does: its pieces'
        overlap is measured and noted at every step (``LoadStep.needs_contact``,
        ``LoadStep.check``).
    stop_when_unloaded : bool
        End the run once the body is broken through: no fragment is deformed by the
        prescribed displacements any more although they deform the body (each piece
        follows its share of them rigidly, see loadpath.py), or the elastic energy has
        fallen below ``unloaded_fraction`` of its peak after cracks appeared.
    parameters : dict
        The numbers that define the scene, copied into summary.json.
    control : dict
        StepControl settings this scene needs (e.g. more cracks per increment where
        many start at once by symmetry); explicit StepControl arguments override them.
    fix_free_modes : True or "all"
        How pieces without Dirichlet support are held (``NewtonSolver``): True, on the
        rigid modes that contact leaves free; "all", on all their rigid modes (the paper's
        pinned fragments), for scenes where contact pushes pieces that nothing else holds.
    radius : float or dict of str -> float, optional
        Critical distance r of the crack criterion (docs/criterion.md), or one per region.
    toughness : float or dict of str -> float, optional
        Fracture toughness K_c (stress times square root of length), or one per region,
        instead of ``radius``: r = (K_c / (E critical))^2 / (2 pi) with the region's
        Young's modulus E. With neither radius nor toughness the paper's one-ring nodal
        strain decides, whose cracks depend on the mesh (a run says so).
    strength : numpy.ndarray, optional
        Critical strain per vertex of ``mesh`` (a random field, :mod:`ngfracture.fracture.strength`);
        it replaces the region's critical strain at the vertices of regions that can
        crack. The copies of a split vertex inherit its strength.
    load_description : str
        What the load parameter x is, with its unit (e.g. "total extension of the plate
        (length)"); shown by ``ngfracture scenes`` and written to summary.json.
    refine : bool or float, optional
        Refine the mesh ahead of crack tips and sharp notch tips during the run
        (:mod:`ngfracture.run.refinement`): True for a target edge length of r/4, a number
        for that length. Needs a critical distance (radius or toughness). None or False: the
        mesh changes only by cracking.
    """
    name: str
    mesh: object
    material: object
    critical: object
    apply_load: Callable
    load_max: float
    dx: float
    contact_tol: float
    contact: bool = False
    stop_when_unloaded: bool = False
    parameters: dict = field(default_factory=dict)
    control: dict = field(default_factory=dict)
    fix_free_modes: object = True
    radius: object = None
    strength: object = None
    load_description: str = ""
    toughness: object = None
    refine: object = None

    def validate(self):
        """Check every field before any work.

        Returns
        -------
        Criterion
            The scene's crack criterion (:meth:`criterion`).

        Raises
        ------
        ValueError
            Naming the first bad field (a non-positive load or increment, an unknown
            region, a bad critical strain, radius or toughness, both a radius and a
            toughness, no region that can crack, a bad material or strength, refinement
            on a 3D mesh).
            What ``apply_load`` adds is checked by :class:`Simulation` before any work.
        """
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Scene.name must be a non-empty string, got {self.name!r}")
        for key in ("load_max", "dx", "contact_tol"):
            v = getattr(self, key)
            low_ok = v >= 0 if key == "contact_tol" else v > 0
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not low_ok:
                raise ValueError(f"Scene {self.name!r}: {key} must be a finite number "
                                 f"{'>= 0' if key == 'contact_tol' else '> 0'}, got {v!r}")
        if not callable(self.apply_load):
            raise ValueError(f"Scene {self.name!r}: apply_load must be callable(problem, x)")
        if self.fix_free_modes not in (True, "all"):
            raise ValueError(f"Scene {self.name!r}: fix_free_modes must be True or 'all', got {self.fix_free_modes!r}")
        if not isinstance(self.material, (Material, dict)):
            raise ValueError(f"Scene {self.name!r}: material must be a Material or a dict of them")
        self._check_regions()
        if self.mesh.dim == 3 and self.refine is not None:
            raise ValueError(f"Scene {self.name!r}: a 3D scene cannot use refine (refinement works on 2D meshes)")
        self.refinement()
        if self.strength is not None:
            s = np.asarray(self.strength)
            if s.shape != (self.mesh.nv,) or not np.issubdtype(s.dtype, np.floating) \
                    or not np.all(np.isfinite(s)) or not np.all(s > 0):
                raise ValueError(f"Scene {self.name!r}: strength must be {self.mesh.nv} finite floats > 0 "
                                 f"(one per vertex), got shape {s.shape}")
        return self.criterion()

    def _per_region(self, value):
        regions = set(self.mesh.GetMaterials())
        return value.items() if isinstance(value, dict) else [(r, value) for r in sorted(regions)]

    def _check_regions(self):
        """The per-region fields: known regions, numbers > 0 or None, one that cracks."""
        regions = set(self.mesh.GetMaterials())
        for key, what in (("critical", "critical strain"), ("radius", "critical distance (radius)"),
                          ("toughness", "toughness")):
            for region, v in self._per_region(getattr(self, key)):
                if region not in regions:
                    raise ValueError(f"Scene {self.name!r}: {what} given for region {region!r}, which is "
                                     f"not in the mesh; its regions are {sorted(regions)}")
                if not _positive_or_none(v):
                    raise ValueError(f"Scene {self.name!r}: {what} of region {region!r} must be a finite "
                                     f"number > 0 or None, got {v!r}")
        if not any(c is not None for _, c in self._per_region(self.critical)):
            raise ValueError(f"Scene {self.name!r}: no region can crack (every critical strain is None)")
        if self.radius is not None and self.toughness is not None:
            raise ValueError(f"Scene {self.name!r}: give a critical distance (radius) or a toughness, not both "
                             f"(each determines the other through the critical strain)")

    def critical_distances(self):
        """The critical distance of every region that has one (from ``radius`` or ``toughness``).

        Returns
        -------
        float, dict of str -> float, or None
            ``radius`` as given; or, from a toughness, r = (K_c / (E critical))^2 / (2 pi)
            per region that has a critical strain and a toughness; None for neither.

        Raises
        ------
        ValueError
            A toughness for a region that never cracks.
        """
        if self.toughness is None:
            return self.radius
        critical = dict(self._per_region(self.critical))
        materials = self.material if isinstance(self.material, dict) else None
        radii = {}
        for region, k in self._per_region(self.toughness):
            if k is None:
                continue
            if critical.get(region) is None:
                raise ValueError(f"Scene {self.name!r}: toughness given for region {region!r}, which never "
                                 f"cracks (no critical strain)")
            E = (materials[region] if materials is not None else self.material).E
            radii[region] = critical_distance(critical[region], k, E)
        return radii

    def criterion(self):
        """The crack criterion of this scene: critical strains, critical distances, material.

        Returns
        -------
        Criterion
            Judging the stress over E of the scene's material at the critical distances
            (:meth:`critical_distances`), or the paper's one-ring nodal strain without any.
        """
        return Criterion(self.critical, radius=self.critical_distances(), material=self.material)

    def refinement(self):
        """The target edge length and the radius of the refinement ahead of tips, or None.

        Returns
        -------
        (float, float, float) or None
            h (r/4 for ``refine=True``, the smallest r of the regions), the radius within
            which triangles are refined around a tip and the reach that triggers it
            (REFINE_RADIUS and REFINE_REACH times the largest r).

        Raises
        ------
        ValueError
            A bad ``refine``, or refinement without a critical distance.
        """
        if self.refine is None or self.refine is False:
            return None
        if not (self.refine is True or (isinstance(self.refine, (int, float)) and math.isfinite(self.refine)
                                        and self.refine > 0)):
            raise ValueError(f"Scene {self.name!r}: refine must be True, False, None or a target edge length > 0, "
                             f"got {self.refine!r}")
        radii = self.critical_distances()
        values = [r for r in (radii.values() if isinstance(radii, dict) else [radii]) if r]
        if not values:
            raise ValueError(f"Scene {self.name!r}: refine needs the critical-distance criterion "
                             f"(a radius or a toughness): the one-ring criterion depends on the mesh")
        h = min(values) / 4 if self.refine is True else float(self.refine)
        return LONGEST_EDGE * h, REFINE_RADIUS * max(values), REFINE_REACH * max(values)

