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
# # Fragmentation in 3D: a glass sphere around an expanding core
#
# The paper's free disk (Fig. 10) as a sphere: a glass sphere with a spherical hole holds
# a softer core shell whose inner surface moves outward. The core is a separate body;
# contact alone passes its expansion on to the glass. Cracks start at the hole, run out to
# the free outer surface, and the sphere falls apart into pieces that the core keeps
# pushing apart.
#
# It illustrates how to:
#
# - build the scene and compare its first step with the exact two-shell solution,
# - run a 3D fragmentation with contact between the pieces,
# - read the fragment statistics (volumes, counts, centroids) and their distribution,
# - check from the written files alone that the pieces do not overlap.

# %%
from pathlib import Path

import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import numpy as np

from ngfracture import Simulation, scenes
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.output.overlap3d import vtu_overlap_volume
from ngfracture.output.pictures import plot_fragment_sizes

# %% [markdown]
# ## The scene
#
# `scenes.sphere3d_free()`: a glass sphere of radius 1 (E = 5 GPa, nu = 0.18, St
# Venant-Kirchhoff) with a hole of radius 0.25 around a core shell (radii 0.125 to 0.25,
# ten times softer). Glass and core are meshed as one body and then split along the
# interface, so the two surfaces `hole` and `core_surface` lie on top of each other with
# bitwise equal vertices. A coarse mesh keeps this notebook within a few minutes;
# `ngfracture run sphere3d_free` runs the default one.

# %%
MESH = {"maxh": 0.4, "fine": 0.15}
scene = scenes.sphere3d_free(**MESH)
mesh = scene.mesh
print(mesh.ne, "tetrahedra,", mesh.nv, "vertices; regions", sorted(set(mesh.GetMaterials())),
      "; boundaries", sorted(set(mesh.GetBoundaries())))
print("load: x =", scene.load_description, "from", f"{scene.dx:.3g}", "to", f"{scene.load_max:.3g}")

# %% [markdown]
# ## The exact solution before the first crack
#
# Before anything cracks the problem is a pair of thick spherical shells:
# `u_r = A r + B / r^2` in each, `u_r(0.125) = x`, `u_r` and `sigma_rr` continuous at the
# interface, `sigma_rr(1) = 0` outside (`scenes.shells_exact`). The hoop stress is largest
# at the hole; the criterion reads it at the critical distance r from the hole
# (`scenes.sphere_first_crack` gives the expansion at which the exact field first reaches
# the strength there).

# %%
exact = scenes.shells_exact(1e-3, confined=False)   # callables of one radius
r = np.linspace(0.125, 1.0, 200)
fig, ax = plt.subplots(1, 2, figsize=(9, 3))
ax[0].plot(r, [exact["u"](t) / 1e-3 for t in r])
ax[0].set_xlabel("r")
ax[0].set_ylabel("u_r / x")
ax[1].plot(r, [exact["stt"](t) / 1e6 for t in r], label="hoop")
ax[1].plot(r, [exact["srr"](t) / 1e6 for t in r], label="radial")
ax[1].set_xlabel("r")
ax[1].set_ylabel("stress at x = 1e-3 (MPa)")
ax[1].legend()
for a in ax:
    a.axvline(0.25, color="grey", lw=0.5)
plt.tight_layout()
plt.show()
print("first crack of the exact field at x =", f"{scenes.sphere_first_crack(radius=scene.radius, confined=False):.4g}")

# %% [markdown]
# ## The run
#
# `Simulation` runs it as in 2D: load steps, crack passes that split overstrained
# vertices, contact between every pair of pieces (collision detection with exact
# orientation predicates, node-to-face rows, an active set), and the end once the load
# range is done. Each piece is held on its six rigid modes by multiplier rows, so the
# pieces stay where the core pushes them.

# %%
out = Path("out") / "sphere3d_free"
run = Simulation(scene, out=out, force=True).run()
s = run.summary
print(run.reason, "|", s["n_steps"], "steps,", s["n_split_vertices"], "split vertices,",
      s["n_fragments"], "fragments, crack area", round(s["crack_area"], 3))
assert run.ok
print("volume before and after, bit for bit:", s["volume_initial"], s["volume_final"])
assert s["volume_final"] == s["volume_initial"]   # splitting never changes a tetrahedron

# %% [markdown]
# ## Fragments
#
# `FragmentStatistics` gives the pieces' volumes (the same class as in 2D, where they are
# areas) and centroids. The core is one piece; the glass is the rest.

# %%
stats = FragmentStatistics(run.problem.mesh)
print(stats.summary())
print("fragment volumes:", np.round(np.sort(stats.volumes)[::-1], 4).tolist())
print("centroid radii:", np.round(np.linalg.norm(stats.centroids, axis=1), 3).tolist())
assert abs(stats.total_volume - s["volume_initial"]) <= 1e-14 * s["volume_initial"]
plot_fragment_sizes(stats.volumes, out / "sizes.png", force=True, title="Fragment volumes")
fig, ax = plt.subplots(figsize=(8, 3.5))
ax.imshow(plt.imread(out / "sizes.png"))
ax.axis("off")
plt.show()

# %% [markdown]
# ## No overlap, measured from the files
#
# Every step writes `step_N.vtu` (tetrahedra with displacement and fragment number).
# `vtu_overlap_volume` reads one back and measures the volume in which two fragments
# overlap in the deformed configuration, by exact clipping of tetrahedra, independently of
# the contact code. Node-to-face contact keeps it at rounding.

# %%
for path in sorted(out.glob("step_*.vtu")):
    overlap = vtu_overlap_volume(path)
    print(path.name, f"overlap / volume = {overlap.relative:.1e}")
    assert overlap.volume <= 1e-10 * overlap.body_volume

# %% [markdown]
# `final.png` shows the deformed pieces (displacements magnified). In ParaView open
# `results.pvd` and `cracks.pvd`, apply *Warp By Vector* (`displacement`) and colour by
# `fragment`.

# %%
fig, ax = plt.subplots(figsize=(6, 4.5))
ax.imshow(plt.imread(out / "final.png"))
ax.axis("off")
plt.show()

# %% [markdown]
# ## Ensembles
#
# With a random strength per vertex (`--set weibull_m=8`), every seed breaks the sphere
# differently; `ngfracture ensemble sphere3d_free --samples 8 --set weibull_m=8 --workers 2`
# runs the seeds on dask and pools the fragment volumes into statistics with confidence
# bands, as tutorial 06 does in 2D.
