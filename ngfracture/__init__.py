"""ngfracture: brittle fracture and fragmentation by node splitting, for NGSolve.

    import ngfracture as nf
    result = nf.Simulation(nf.scenes.plate(), nf.StepControl(), out="out/plate").run()

The public API is what this module exports (``__all__``); the packages below hold the
layers, each module one concept (docs/design.md has the full module map):

geometry   meshes as arrays and back, mesh validation
mechanics  materials, constraints, ``ElasticProblem``, Newton's method, rigid modes
linalg     the KKT solve, factorisations, the bordered factor, the contact QP
fracture   the crack criterion, node splitting, random strength, fragments
contact    collision detection, contact rows, seams, the active-set contact solve
run        ``Scene``, ``StepControl``, the load step, ``Simulation``, checkpoints
output     VTK time series, pictures, summaries, atomic files
studies    ensembles on dask, fragment statistics, convergence studies
scenes     the paper's scenes (plate, disk, disintegration)
cli        the ``ngfracture`` command
"""
import ngsolve as _ngsolve  # noqa: F401  (loads NGSolve's shared libraries before the compiled add-on)

try:
    from . import _ngfracture as _ext  # noqa: F401
except ImportError as _exc:
    import os as _os
    import sys as _sys
    _message = (f"ngfracture: the compiled extension is missing in {_os.path.dirname(__file__)}: this is "
                f"the uncompiled source tree (e.g. run from the repository root, where it shadows the "
                f"installed package); run from another folder, or build in place with tools/dev_build.sh")
    if _sys.argv[:1] == ["-m"]:      # python -m ngfracture: one line, not a traceback
        raise SystemExit(_message) from None
    raise ImportError(_message) from _exc

from .geometry.meshcheck import MeshError, MeshQualityWarning, validate_mesh
from .mechanics.materials import LinearElastic, NeoHookean, StVenantKirchhoff, lame_parameters, make_material
from .mechanics.problem import ElasticProblem
from .mechanics.newton import SolveStatus
from .run.simulation import RunResult, Scene, Simulation, StepControl
from .studies.ensemble import Ensemble
from . import scenes

__version__ = "0.1.0"

__all__ = ["Simulation", "Scene", "StepControl", "RunResult", "scenes", "Ensemble",
           "ElasticProblem", "SolveStatus", "LinearElastic", "StVenantKirchhoff", "NeoHookean",
           "make_material", "lame_parameters", "validate_mesh", "MeshError", "MeshQualityWarning",
           "__version__"]
