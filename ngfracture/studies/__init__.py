"""Studies made of many runs or solves: ensembles and verification.

ensemble    many seeds of a scene on dask.distributed, resumable, ``ensemble.json``
statistics  pooled fragment sizes with bootstrap intervals, distribution fits, plots
lshape      the L-shape manufactured solution of the paper (section 4.1), meshes, errors
verify      convergence studies against exact solutions
random_scenes  random scenes for stress tests (rectangles, holes, a notch, random loads)
"""
