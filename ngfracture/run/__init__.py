"""A fracture simulation under load control: scenes, the load step, checkpoints.

simulation    ``Scene``, ``StepControl`` and ``Simulation``, the load-stepping driver
checkpoint    atomic, verified checkpoints
loadpath      when the body is broken through (no piece carries the load any more)
scene_source  scenes from a file or a package function, with their parameters
"""
