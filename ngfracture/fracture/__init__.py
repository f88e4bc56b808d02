"""Cracks by node splitting (paper section 3).

strain     fields of a displacement: vertex values, element and nodal strain, stress over E,
           principal values (the triangle kernels)
criterion  ``Criterion``: critical strain and distance per region, the overstrain of every
           vertex; the critical-distance measure, toughness and critical distance
split      node splitting by the paper's rules with a netgen rebuild, exact field transfer
crack_graph  the cracks as a graph: tips, mouths, junctions, branches
strength   random strength: a Weibull critical strain per vertex, weakest-link size effect
fragments  fragment statistics (count, areas, centroids)

The names of ``strain``, ``criterion`` and ``split`` are re-exported here.
"""
from .strain import *      # noqa: F401,F403
from .criterion import *   # noqa: F401,F403
from .split import *       # noqa: F401,F403
from . import criterion as _criterion, split as _split, strain as _strain

__all__ = list(_strain.__all__) + list(_criterion.__all__) + list(_split.__all__)
