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
# # Fragmentation with contact: a disk around an expanding core
#
# The paper's second fracture test (section 4.2, Fig. 9): a brittle disk with a hole
# holds a softer core that expands. The core is a separate body; contact alone passes
# its expansion on to the disk. Radial cracks grow from the hole; with the paper's crack
# criterion the inner part of the disk breaks into grains (the comminuted zone), with the
# scene's default, a critical distance, the radial cracks stay apart; the outer part
# stays whole.
#
# It illustrates how to:
#
# - build two bodies that touch along a curve (`meshio.separate_region`),
# - see contact at work: the core pushes the disk through multiplier rows,
# - run the scene and count the fragments,
# - read fragment statistics and the fragment-size distribution.

# %%
from pathlib import Path

import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import matplotlib.tri as mtri
import numpy as np

import ngfracture as nf
from ngfracture import scenes
from ngfracture.contact.solver import ContactSolver
from ngfracture.fracture import vertex_displacement
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.output.pictures import plot_fragment_sizes
from ngfracture import Simulation

# %% [markdown]
# ## Two bodies
#
# `scenes.cored_disk_mesh` meshes the disk and the core together, so the interface
# circle is meshed once, and then gives the core its own copies of the interface
# vertices: two bodies whose boundaries (`hole` on the disk, `core_surface` on the
# core) lie on top of each other. Nothing couples them but contact.

# %%
mesh = scenes.cored_disk_mesh(maxh=0.1)
P = mesh.ngmesh.Coordinates()[:, :2]
T = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3] - 1
region = mesh.ngmesh.Elements2D().NumPy()["index"]
print(mesh.ne, "triangles; regions", mesh.GetMaterials(), "; boundaries", sorted(set(mesh.GetBoundaries())))
_, pieces = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3)).fragments()
print("separate pieces:", len(set(pieces)))

fig, ax = plt.subplots(figsize=(4, 4))
ax.tripcolor(mtri.Triangulation(P[:, 0], P[:, 1], T), facecolors=region, cmap="Pastel1", edgecolors="k", lw=0.2)
ax.set_aspect("equal")
ax.set_title("disk (glass) and core (10 times softer)")
plt.show()

# %% [markdown]
# ## Contact passes the load on
#
# Expand the core's inner boundary by 1e-5 (below the first crack) and solve with a
# `ContactSolver`: an active set of node-to-node rows across the touching circles. The
# multipliers are the contact forces (negative: compression); their sum, projected on
# the radial direction, is the force the core exerts on the disk.

# %%
scene = scenes.disk(maxh=0.1, radius=None)   # the mesh above (a critical distance refines it)
prob = nf.ElasticProblem(scene.mesh, scene.material)
scene.apply_load(prob, 1e-5)
result = ContactSolver(prob, tol=scene.contact_tol).solve()
print(result.reason, "after", result.rounds, "rounds;", len(result.constraints), "active rows")
assert result.converged and np.all(result.multipliers <= 0)

U = vertex_displacement(prob.u)
r = np.hypot(P[:, 0], P[:, 1])
disk_vertices = np.unique(T[region == 1])
ur = np.einsum("ij,ij->i", U, P / r[:, None])
fig, ax = plt.subplots(figsize=(5, 3))
ax.plot(r[disk_vertices], ur[disk_vertices], ".", label="disk")
core_vertices = np.unique(T[region == 2])
ax.plot(r[core_vertices], ur[core_vertices], ".", label="core")
ax.set_xlabel("radius")
ax.set_ylabel("radial displacement")
ax.legend()
plt.show()

# %% [markdown]
# ## The simulation
#
# The core expands step by step; cracks start at the hole. This run uses the paper's
# criterion (`radius=None`: the strain around one vertex), whose grains show the paper's
# comminuted zone; a coarse mesh and a moderate expansion keep it short.

# %%
out = Path("out") / "disk"
scene = scenes.disk(maxh=0.1, expansion=30 * scenes.FIRST_CRACK, radius=None)
run = Simulation(scene, out=out, force=True).run()
s = run.summary
print(run.reason, "|", s["n_steps"], "steps,", s["n_split_vertices"], "split vertices,",
      s["n_fragments"], "fragments, overlap", s["max_overlap_area"])
assert run.ok and s["area_final"] == s["area_initial"]

# %% [markdown]
# ## Fragments
#
# `FragmentStatistics` gives the pieces' areas and centroids: the core, the disk and
# whatever broke off. On this coarse mesh the radial cracks from the hole are a few
# elements long and few grains come loose.

# %%
stats = FragmentStatistics(run.problem.mesh)
print(stats.summary())
print("fragment areas:", np.round(np.sort(stats.areas)[::-1], 4).tolist())
print("centroid radii:", np.round(np.hypot(*stats.centroids.T), 3).tolist())
assert abs(stats.total_area - s["area_initial"]) <= 1e-14 * s["area_initial"]
fig, ax = plt.subplots(figsize=(5, 4.5))
ax.imshow(plt.imread(out / "final.png"))
ax.axis("off")
plt.show()

# %% [markdown]
# ## The default: a critical distance
#
# The paper's grains are as small as the mesh allows: their number grows when the mesh
# is refined (docs/verification.md). `ngfracture run disk` judges cracks at a critical
# distance r = 0.12 instead (maxh 0.06, the expansion 50 times the first-crack
# estimate; run times in docs/performance.md): radial cracks grow from the hole and stop
# inside the ring, and a mesh twice as fine gives the same cracked zone
# (docs/criterion.md). The picture below is that run's
# `final.png` (made by `tools/readme_pictures.py`). Under it, the distribution of the
# coarse run's fragment areas, which `plot_fragment_sizes` draws for any run:

# %%
picture = Path("..") / "docs" / "disk.png"
if picture.exists():   # in a source checkout
    fig, ax = plt.subplots(figsize=(5, 4.5))
    ax.imshow(plt.imread(picture))
    ax.axis("off")
    plt.show()
plot_fragment_sizes(stats.areas, out / "sizes.png", force=True)
fig, ax = plt.subplots(figsize=(8, 3.5))
ax.imshow(plt.imread(out / "sizes.png"))
ax.axis("off")
plt.show()
