"""Frictionless contact between the pieces (paper section 3.2).

collision   exact orient2d, grid broad phase, exact narrow phase of triangle pairs
rows        node-to-segment contact rows: selection rules 1-4, gap linearisation (eq. 13/14)
            and re-linearisation
redundancy  removal of redundant rows (pivoted QR, Gram-matrix shortcut)
seams       node-to-node rows across coincident lips (crack faces, split interfaces)
active_set  the candidate rows of a contact solve, their keys, and the choice among them
solver      equilibrium with unilateral contact: the rounds of the active set around Newton
overlap     overlap area between the triangles of the current configuration
"""
