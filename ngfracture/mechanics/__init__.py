"""Geometrically nonlinear elasticity with Lagrange-multiplier constraints.

materials    linear, St Venant-Kirchhoff and neo-Hooke energies for NGSolve's ``Variation``
constraints  Dirichlet, gliding and point constraints, general rows ``C u = g``
problem      ``ElasticProblem``: mesh, material(s), constraints, loads, solve
newton       modified and full Newton-Raphson (paper eq. 3-7) with a ``SolveStatus``
rigid        rigid-body modes of the pieces and how the constraints hold them
"""
