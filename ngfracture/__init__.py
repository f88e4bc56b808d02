"""ngfracture: brittle fracture and fragmentation by node splitting, for NGSolve.

Submodules
----------
materials    hyperelastic energies (linear, St Venant-Kirchhoff, neo-Hookean)
constraints  Dirichlet, gliding and point constraints (Lagrange multiplier rows)
kkt          the constrained linear solve (elimination + Schur complement)
solver       modified and full Newton-Raphson with a status that says why it stopped
problem      ElasticProblem: mesh, material, constraints, solve
rigid        rigid-body modes of the pieces and how the constraints hold them
checkpoint   atomic, verified checkpoints
crack        nodal strain criterion and node splitting with a netgen rebuild (C++ engine)
collision    exact orient2d, grid broad phase and exact narrow phase on numpy arrays
contact      node-to-segment contact rows (selection rules, gap linearisation) and
             redundancy removal by rank-revealing QR
seams        node-to-node contact rows across coincident lips (cracks, split interfaces)
lshape       the L-shape manufactured solution of the paper (section 4.1), meshes, errors
verify       convergence studies against exact solutions
cli          the command line, python -m ngfracture
meshio       meshes as arrays and back; separate bodies merged into one mesh or
             one region detached from the others
meshcheck    is a mesh fit for use: bad meshes are a MeshError naming the culprit, slivers a warning
contact_solver  equilibrium with unilateral contact: active set around the Newton solver
output       VTK time series, crack edges, headless PNG, fragment-size plot, summary JSON
fragments    fragment statistics (count, areas, centroids)
strength     random strength: a Weibull critical strain per vertex, weakest-link size effect
ensemble     many seeds of a scene on dask.distributed, resumable, ensemble.json
statistics   pooled fragment sizes with bootstrap intervals, distribution fits, ensemble plots
"""
import ngsolve  # load NGSolve's shared libraries before the compiled add-on

try:
    from ._ngfracture import ElementAreas, VertexAverage
except ImportError as _exc:
    import os as _os
    import sys as _sys
    _message = (f"ngfracture: the compiled extension is missing in {_os.path.dirname(__file__)}: this is "
                f"the uncompiled source tree (e.g. run from the repository root, where it shadows the "
                f"installed package); run from another folder, or build in place with tools/dev_build.sh")
    if _sys.argv[:1] == ["-m"]:      # python -m ngfracture: one line, not a traceback
        raise SystemExit(_message) from None
    raise ImportError(_message) from _exc
from .meshcheck import MeshError, MeshQualityWarning, validate_mesh
from .materials import LinearElastic, NeoHookean, StVenantKirchhoff, lame_parameters, make_material
from .problem import ElasticProblem
from .solver import SolveStatus

__version__ = "0.1.0"
