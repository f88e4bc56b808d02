"""ngfracture: brittle fracture and fragmentation by node splitting, for NGSolve.

Submodules
----------
materials    hyperelastic energies (linear, St Venant-Kirchhoff, neo-Hookean)
constraints  Dirichlet, gliding and point constraints (Lagrange multipliers)
kkt          the constrained linear solve (elimination + Schur complement)
solver       modified and full Newton-Raphson with a status that says why it stopped
lshape       the L-shape manufactured solution of the paper (section 4.1)
verify       convergence studies against exact solutions
collision    exact orient2d, grid broad phase and exact narrow phase on numpy arrays
contact      node-to-segment contact rows (selection rules, gap linearisation) and
             redundancy removal by rank-revealing QR
"""
import ngsolve  # load NGSolve's shared libraries before the compiled add-on

from ._ngfracture import ElementAreas, VertexAverage

__version__ = "0.1.0"
