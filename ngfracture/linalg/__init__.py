"""Sparse linear algebra of the constrained solves.

kkt       the KKT solve of paper eq. 3 / 12: elimination, Schur complement, augmented matrix
bordered  a factorisation carried across the vertex splits of crack passes
qp        the exact convex QP of the contact complementarity problem
"""
