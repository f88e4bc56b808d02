"""Sparse linear algebra of the constrained solves.

sparse      scipy and NGSolve sparse matrices, the thread settings of the solves
factor      K^+: the factorisations of the stiffness (SuperLU, sparse Cholesky, GMRES), thresholds
iterative   K^+ by CG with algebraic multigrid (3D above the memory budget); the choice of solver
triangular  the C++ triangular solves with SuperLU's factors (supernodal, sparse reach)
kkt         the KKT solve of paper eq. 3 / 12: elimination, Schur complement, augmented matrix
bordered    a factorisation carried across the vertex splits of crack passes
qp          the exact convex QP of the contact complementarity problem
"""
