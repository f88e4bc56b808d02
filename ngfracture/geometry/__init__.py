"""Meshes as data: arrays and back, and what makes a mesh fit for use.

meshio     meshes as numpy arrays (``MeshArrays``) and back to netgen/NGSolve meshes;
           separate bodies merged into one mesh, one region detached from the others
meshcheck  ``validate_mesh``: a bad mesh is a ``MeshError`` naming the culprit, slivers a warning
"""
