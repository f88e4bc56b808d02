"""A fracture simulation under load control: the scene, the load step, the run, its files.

scene         ``Scene``: mesh, materials, critical strains and distances, load, contact
control       ``StepControl``: adaptive load increments (paper section 4.2)
records       what the stages of a load step return (Equilibrium, CrackPass, Attempt, ...)
step          ``LoadStep``: one load step, stage by stage (increment, crack passes, retries)
tangents      which factorised tangent a step starts from
state         ``State`` between steps, its checkpoints
simulation    ``Simulation``: the run from the first step to the end, summary
files         the files of a run: output-folder rules, time series, checkpoints, pictures
checkpoint    atomic, verified checkpoint files
timings       wall time per phase
loadpath      when the body is broken through (no piece carries the load any more)
scene_source  scenes from a file or a package function, with their parameters
"""
