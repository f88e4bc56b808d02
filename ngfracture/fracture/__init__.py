"""Cracks by node splitting (paper section 3).

crack      the crack criteria and node splitting with a netgen rebuild (C++ engine)
strength   random strength: a Weibull critical strain per vertex, weakest-link size effect
fragments  fragment statistics (count, areas, centroids)
"""
