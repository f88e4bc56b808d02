"""The state of a run between load steps, and how it is checkpointed and read back.

Every accepted state goes through the checkpoint's mesh representation (:func:`round_trip`)
whether or not it is written, so a resumed run continues from bitwise the same mesh and
displacement as the uninterrupted one.
"""
import json
import math
from dataclasses import dataclass, field

import numpy as np

from . import checkpoint
from ..geometry.meshio import MeshArrays, mesh_from_arrays, mesh_to_arrays
from ..geometry.solid import SolidArrays, crack_area

__all__ = ["State", "round_trip", "crack_length", "crack_extent", "json_round_trip", "save_state", "load_state"]


@dataclass
class State:
    """An accepted state: everything a resume needs.

    Parameters
    ----------
    arrays : MeshArrays
        The mesh.
    u : numpy.ndarray
        The P1 displacement vector in VectorH1 layout.
    x, dx : float
        The load parameter and the next increment.
    step, quiet : int
        Steps accepted, and crack-free steps in a row.
    work : float
        External work so far.
    reactions, fixed_values, fixed_dofs : numpy.ndarray
        Reactions, prescribed values and numbers of the fixed dofs, for the work of the
        next increment.
    peak_energy : float
        Largest elastic energy so far.
    history : list of dict
        One record per accepted step.
    strength : numpy.ndarray or None
        Critical strain per vertex (None: the regions' uniform ones).
    contact_keys : list of tuple
        Keys of the active contact rows at this state: the first contact solve of the next
        step starts from them (ContactSolver.solve, ``warm``).
    tangent_state : numpy.ndarray or None
        The displacement the factorised tangent kept for the next step was assembled at
        (None: the next step factorises its own).
    tangent : SavedTangent or None
        That factorisation, if this process made it (not in checkpoints: a resumed run
        makes it again from ``tangent_state``).
    tangent_inverse : str or None
        The direct solver that factorised it ("auto" chooses by the rows of the solve that
        made it, which a resumed run does not have): the resumed run factorises with it.
    mesh : ngsolve.Mesh or None
        The mesh built from ``arrays`` (not in checkpoints: made again from the arrays).
    external : numpy.ndarray or None
        The dead loads' nodal forces at this state (None: the scene has none), for their
        work over the next increment.
    area : float or None
        The reference area of the mesh (the area invariant's reference: the scene's, or
        that of the last refinement, Scene.refine).
    """
    arrays: MeshArrays
    u: np.ndarray            # P1 displacement vector, VectorH1 layout
    x: float
    dx: float
    step: int
    quiet: int               # crack-free steps in a row
    work: float              # external work so far
    reactions: np.ndarray    # reaction at the fixed dofs, for the work of the next step
    fixed_values: np.ndarray
    fixed_dofs: np.ndarray
    peak_energy: float
    history: list            # one dict per accepted step
    strength: np.ndarray = None
    contact_keys: list = field(default_factory=list)
    tangent_state: np.ndarray = None
    tangent_inverse: str = None
    tangent: object = field(default=None, repr=False, compare=False)
    mesh: object = field(default=None, repr=False, compare=False)
    external: np.ndarray = None
    area: float = None


def round_trip(mesh):
    """The mesh through its checkpoint representation (arrays and back).

    Parameters
    ----------
    mesh : ngsolve.Mesh

    Returns
    -------
    (MeshArrays, ngsolve.Mesh)
        The arrays and the mesh rebuilt from them, as a resumed run rebuilds it.
    """
    arrays = mesh_to_arrays(mesh)
    return arrays, mesh_from_arrays(arrays)


def crack_extent(arrays):
    """The crack's extent for a step's record: its length in 2D, its area in 3D.

    Parameters
    ----------
    arrays : MeshArrays or SolidArrays

    Returns
    -------
    (str, float)
        ``("crack_length", length)`` or ``("crack_area", area)``.
    """
    if arrays.dim == 3:
        return "crack_area", crack_area(arrays)
    return "crack_length", crack_length(arrays)


def crack_length(arrays):
    """Length of the crack in the reference configuration: half the crack-face length.

    Parameters
    ----------
    arrays : MeshArrays
        A mesh whose crack faces are the boundary segments named ``crack``.

    Returns
    -------
    float
    """
    if "crack" not in arrays.bc_names:
        return 0.0
    segs = arrays.boundary_segments("crack")
    if len(segs) == 0:
        return 0.0
    d = arrays.points[segs[:, 0]] - arrays.points[segs[:, 1]]
    return 0.5 * math.fsum(np.hypot(d[:, 0], d[:, 1]))


def json_round_trip(obj):
    """``obj`` as it comes back from a JSON round trip (tuples become lists).

    Parameters
    ----------
    obj : object
        JSON-serialisable.

    Returns
    -------
    object
    """
    return json.loads(json.dumps(obj))


def save_state(folder, state, run):
    """Write a checkpoint of an accepted state (atomic, verified on reading).

    Parameters
    ----------
    folder : pathlib.Path
        The run's output folder.
    state : State
    run : dict
        What the run adds to the state's metadata: scene name and parameters, the initial
        area, the options that decide the load path, timings (JSON-serialisable).

    Returns
    -------
    pathlib.Path
        The checkpoint file.
    """
    arrays = {**state.arrays.as_dict(), "u": state.u, "reactions": state.reactions,
              "fixed_values": state.fixed_values, "fixed_dofs": state.fixed_dofs}
    if state.strength is not None:
        arrays["strength"] = state.strength
    if state.tangent_state is not None:
        arrays["tangent_state"] = state.tangent_state
    if state.external is not None:
        arrays["external"] = state.external
    meta = {"x": state.x, "dx": state.dx, "step": state.step, "quiet": state.quiet, "work": state.work,
            "peak_energy": state.peak_energy, "history": state.history,
            "contact_keys": [list(k) for k in state.contact_keys], "area": state.area,
            "tangent_inverse": state.tangent_inverse, **run}
    return checkpoint.write(folder, state.step, arrays, meta)


def load_state(folder):
    """The state of the newest valid checkpoint in a folder, with its mesh.

    Parameters
    ----------
    folder : str or pathlib.Path

    Returns
    -------
    state : State
        ``mesh`` built from its arrays; no factorised tangent (a resumed run makes it again).
    run : dict
        The metadata :func:`save_state` was given (scene, parameters, ...).

    Raises
    ------
    checkpoint.CheckpointError
        No checkpoint, or none that can be trusted.
    """
    arrays, header = checkpoint.latest(folder)
    meta = dict(header.get("meta", header))
    kind = SolidArrays if "mesh_tets" in arrays else MeshArrays
    state = State(arrays=kind.from_dict(arrays), u=arrays["u"], x=meta.pop("x"), dx=meta.pop("dx"),
                  step=meta.pop("step"), quiet=meta.pop("quiet"), work=meta.pop("work"),
                  reactions=arrays["reactions"], fixed_values=arrays["fixed_values"],
                  fixed_dofs=arrays["fixed_dofs"], peak_energy=meta.pop("peak_energy"),
                  history=meta.pop("history"), strength=arrays.get("strength"),
                  contact_keys=[tuple(k) for k in meta.pop("contact_keys", [])],
                  tangent_state=arrays.get("tangent_state"), external=arrays.get("external"),
                  area=meta.pop("area", None), tangent_inverse=meta.pop("tangent_inverse", None))
    state.mesh = mesh_from_arrays(state.arrays)
    return state, meta
