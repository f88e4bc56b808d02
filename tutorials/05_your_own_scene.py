# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Your own scene
#
# A `Scene` is everything ngfracture needs to simulate fracture on a body of your
# own: a netgen mesh with named boundaries, materials per region, a critical strain
# per region, and a function that prescribes the load for a load parameter x.
#
# It illustrates how to:
#
# - build a netgen geometry with named boundaries and two material regions,
# - choose materials and critical strains per region (a region may never crack),
# - write `apply_load(problem, x)` with gliding and full Dirichlet conditions,
# - run it, and read the outputs with PyVista and `FragmentStatistics`.
#
# The body: a glass beam, 2 x 0.5, resting on two supports (gliding: $u_y = 0$ only)
# and pressed down in the middle of its top edge through a stiff steel pad that never
# cracks. The bottom edge is stretched and cracks from below.

# %%
import json
from pathlib import Path

import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import ngsolve as ng
import numpy as np
import pyvista as pv
from netgen.geom2d import SplineGeometry

import ngfracture as nf
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture import Scene, Simulation, StepControl

# %% [markdown]
# ## Geometry and mesh
#
# Points and lines with boundary names; the pad is region 2 on top of the beam
# (region 1), sharing the line between them, so the two are bonded. The supports
# are short pieces of the bottom edge with names of their own.

# %%
geo = SplineGeometry()
pts = [geo.AppendPoint(*p) for p in [(0, 0), (0.1, 0), (0.2, 0), (1.8, 0), (1.9, 0), (2, 0), (2, 0.5),
                                     (1.1, 0.5), (0.9, 0.5), (0, 0.5), (0.9, 0.6), (1.1, 0.6)]]
lines = [(0, 1, "bottom", 1, 0), (1, 2, "support_left", 1, 0), (2, 3, "bottom", 1, 0),
         (3, 4, "support_right", 1, 0), (4, 5, "bottom", 1, 0), (5, 6, "side", 1, 0),
         (6, 7, "top", 1, 0), (7, 8, "pad_contact", 1, 2), (8, 9, "top", 1, 0), (9, 0, "side", 1, 0),
         (8, 10, "pad_side", 0, 2), (10, 11, "pad_top", 0, 2), (11, 7, "pad_side", 0, 2)]
for a, b, name, left, right in lines:
    geo.Append(["line", pts[a], pts[b]], bc=name, leftdomain=left, rightdomain=right)
geo.SetMaterial(1, "glass")
geo.SetMaterial(2, "steel")
mesh = ng.Mesh(geo.GenerateMesh(maxh=0.06))
print(mesh.ne, "triangles; regions", mesh.GetMaterials(), "; boundaries", sorted(set(mesh.GetBoundaries())))

# %% [markdown]
# ## Materials, critical strains, load
#
# Any ngfracture material per region; `critical` names the regions that can crack
# (the steel pad is missing from it, so it never does). The load parameter x is the
# downward displacement of the pad's top; the supports glide ($u_y = 0$, $u_x$ free).
# The beam's horizontal translation is left free on purpose: ngfracture holds it with
# a multiplier row on the unheld rigid mode (and does the same for every fragment that
# breaks off).
#
# This scene cracks by the paper's one-ring criterion (neither `radius` nor `toughness`),
# so `Simulation` warns that its cracks depend on the mesh (`MeshDependentCriterion`).
# `Scene(..., radius=r)` judges the stress at a critical distance r instead, as the
# built-in scenes do, and `Scene(..., toughness=K_c)` takes r from a fracture toughness,
# r = (K_c / (E critical))^2 / (2 pi) (docs/criterion.md): then the mesh should be at most
# r/4 where cracks run, and the results converge under refinement.

# %%
materials = {"glass": nf.StVenantKirchhoff(E=70e9, nu=0.22, plane="stress"),
             "steel": nf.LinearElastic(E=200e9, nu=0.3, plane="stress")}


def apply_load(problem, x):
    problem.add_dirichlet(["support_left", "support_right"], 0.0, component="y")
    problem.add_dirichlet("pad_top", (0.0, -x))


scene = Scene(name="beam", mesh=mesh, material=materials, critical={"glass": 2e-4},
              apply_load=apply_load, load_max=2e-3, dx=5e-5, contact_tol=1e-5,
              stop_when_unloaded=True, parameters={"maxh": 0.06, "E_glass": 70e9, "critical": 2e-4})

# %% [markdown]
# ## Run
#
# Bad input is refused before any work (try `critical={"glas": 2e-4}`). The run
# writes into `out/beam`; `force=True` replaces an earlier run there.

# %%
out = Path("out") / "beam"
run = Simulation(scene, StepControl(max_new_cracks=4), out=out, force=True).run()
summary = json.loads((out / "summary.json").read_text())
print(run.reason, "|", summary["n_steps"], "steps,", summary["n_split_vertices"], "split vertices,",
      summary["n_fragments"], "fragments, crack length", round(summary["crack_length"], 3))
assert run.ok and summary["n_split_vertices"] > 0
assert summary["area_final"] == summary["area_initial"]

# %% [markdown]
# The cracks start at the bottom edge between the supports, where bending stretches
# the beam most, and run up toward the pad.

# %%
start = np.array(summary["crack_initiation"])
print("first cracked vertices:", start.round(3).tolist())
assert np.all(start[:, 1] < 0.1) and np.all(np.abs(start[:, 0] - 1.0) < 0.5)

# %% [markdown]
# ## Reading the output with PyVista
#
# `results.pvd` is a time series; the last step holds the cracked mesh with the
# displacement, strains, region and fragment per triangle. Crack faces are in
# `cracks.pvd`. Everything is plain VTK: no NGSolve is needed to read it.

# %%
reader = pv.get_reader(str(out / "results.pvd"))
reader.set_active_time_point(len(reader.time_values) - 1)
grid = reader.read()[0]
print("point data:", list(grid.point_data), "\ncell data:", list(grid.cell_data))

warped = grid.warp_by_vector("displacement", factor=20)
xy = warped.points[:, :2]
tris = warped.cells.reshape(-1, 4)[:, 1:]
fig, ax = plt.subplots(figsize=(8, 3))
ax.tripcolor(xy[:, 0], xy[:, 1], tris, facecolors=grid.cell_data["principal_strain"], cmap="magma")
ax.set_aspect("equal")
ax.set_title("principal strain on the deformed beam (displacements x 20)")
plt.show()

# %% [markdown]
# ## Fragments
#
# `FragmentStatistics` counts the pieces and measures their areas (in the reference
# configuration: they add up to the beam's area to rounding).

# %%
stats = FragmentStatistics(run.problem.mesh)
print(stats.summary())
assert abs(stats.total_area - summary["area_initial"]) <= 1e-14 * summary["area_initial"]

# %% [markdown]
# ## The same scene from the command line
#
# `examples/beam_scene.py` holds this scene as a function `scene(**params)` whose
# parameters all have defaults. The command line runs it and sets any parameter:
#
# ```
# ngfracture run examples/beam_scene.py --set E_glass=60e9 --set critical=1.5e-4 --max-new-cracks 4
# ```
#
# `--progress json` prints one JSON object per accepted step (step, load, splits,
# fragments, seconds), and `ngfracture render out/beam_scene` redraws the pictures.
