"""Frictionless contact between the pieces (paper section 3.2).

collision  exact orient2d, grid broad phase, exact narrow phase
rows       node-to-segment contact rows (selection rules, gap linearisation) and the
           removal of redundant rows
seams      node-to-node rows across coincident lips (crack faces, split interfaces)
solver     equilibrium with unilateral contact: an active set around the Newton solver
"""
