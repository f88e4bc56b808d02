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
# # Verification on the L-shape: a corner singularity
#
# Section 4.1 of the paper verifies the finite element code with a manufactured
# solution on an L-shaped body: the mode-I singular solution at the reentrant corner
# (eq. 15). Its stress grows like $r^{\alpha - 1}$ with $\alpha \approx 0.5445$, so
# on uniform meshes the energy error falls only like $h^{\alpha}$; meshes graded
# toward the corner restore the optimal rate $h^1$ for linear elements.
#
# It illustrates how to:
#
# - evaluate the exact solution of eq. 15 as an NGSolve `CoefficientFunction`,
# - build uniform and graded mesh hierarchies of the L-shape,
# - run a convergence study with `ngfracture.studies.verify.lshape_study` and read its rates,
# - plot errors against the number of dofs and against the solve time,
# - run the same study from the command line.

# %%
import subprocess
import sys

import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import matplotlib.tri as mtri
import ngsolve as ng
import numpy as np

from ngfracture.studies import lshape
from ngfracture.studies import verify

# %% [markdown]
# ## Problem definition
#
# The domain is $(-1, 1)^2$ minus the quadrant $[0, 1] \times [-1, 0]$, with the
# reentrant corner at the origin. Its two edges at the corner are the boundary
# `"reentrant"`, the other four `"outer"`. The exponent $\alpha$ solves
# $\alpha \sin 2\omega + \sin 2\omega\alpha = 0$ with $\omega = 3\pi/4$.

# %%
alpha = lshape.singular_exponent()
print(f"alpha = {alpha:.12f}")
assert abs(alpha - 0.544483737) < 1e-9  # the value quoted in the paper

sol = lshape.LShapeSolution(E=1e5, nu=0.3, plane="strain")
print(f"lambda = {sol.lam:.4g}, mu = {sol.mu:.4g}, C1 = {sol.C1:.6f}, C2 = {sol.C2:.6f}")

# %% [markdown]
# `sol.u` and `sol.sigma` are `CoefficientFunction`s. The exact solution is
# traction-free on the reentrant edges: $\sigma n = 0$ there. We check that on the
# edge $y = 0$, $x > 0$ (normal $(0, -1)$), where $\sigma_{xy} = \sigma_{yy} = 0$.

# %%
mesh0 = lshape.lshape_mesh(level=0)
xs = np.linspace(0.1, 0.9, 5)
sig = sol.sigma(mesh0(xs, np.zeros_like(xs))).reshape(-1, 2, 2)
print("sigma_xy, sigma_yy on the reentrant edge:", np.abs(sig[:, 1, :]).max())
assert np.abs(sig[:, 1, :]).max() < 1e-8 * np.abs(sig).max()

# %% [markdown]
# Two mesh hierarchies: uniform refinements of a netgen mesh, and the same meshes
# mapped by $x \mapsto x\,\rho^{\gamma - 1}$, $\rho = \max(|x|, |y|)$, which grades
# them toward the corner ($\gamma = 2$ for order 1). Coloured by $|u|$:

# %%
fig, axes = plt.subplots(1, 2, figsize=(8, 4))
for ax, gamma in zip(axes, (1.0, lshape.default_grading(1))):
    m = lshape.lshape_mesh(level=2, gamma=gamma)
    xy = m.ngmesh.Coordinates()[:, :2]
    tris = np.array([[v.nr for v in el.vertices] for el in m.Elements(ng.VOL)])
    c = xy[tris].mean(axis=1)  # |u| at the element centroids
    umag = ng.Norm(sol.u)(m(c[:, 0], c[:, 1])).ravel()
    tri = mtri.Triangulation(xy[:, 0], xy[:, 1], tris)
    pc = ax.tripcolor(tri, facecolors=umag)
    ax.triplot(tri, color="k", lw=0.3)
    ax.set_aspect("equal")
    ax.set_title(f"gamma = {gamma:g}, {m.nv} vertices")
fig.colorbar(pc, ax=axes, label="|u| (exact)")

# %% [markdown]
# ## Solve
#
# `lshape_study` solves the problem with `ngfracture.ElasticProblem` (linear model,
# exact Dirichlet data on the whole boundary) on `levels` meshes, measures the
# relative $L^2$ and energy-norm errors against eq. 15 and fits the rates
# $k$ in $\text{err} \sim h^k$ over the finest three levels.

# %%
studies = {kind: verify.lshape_study(order=1, levels=6, mesh=kind) for kind in ("uniform", "graded")}
for kind, res in studies.items():
    print(f"{kind}:")
    print(f"{'ndof':>7} {'h':>8} {'rel L2':>10} {'rel energy':>10}")
    for r in res["levels"]:
        print(f"{r['ndof']:7d} {r['h']:8.4f} {r['rel_l2']:10.3e} {r['rel_energy']:10.3e}")
    print(f"rates: L2 {res['rates']['l2']:.3f}, energy {res['rates']['energy']:.3f}\n")

# %% [markdown]
# On uniform meshes the energy rate is $\alpha$ (the $H^{1+\alpha}$ regularity of the
# solution); on the graded meshes it is the optimal 1 for linear elements, and the
# $L^2$ rate doubles to 2.

# %%
uniform, graded = studies["uniform"]["rates"], studies["graded"]["rates"]
assert abs(uniform["energy"] - alpha) < 0.03
assert graded["energy"] > 0.9
assert graded["l2"] > 1.8 and uniform["l2"] < graded["l2"]

# %% [markdown]
# ## Post-processing
#
# The paper plots errors against the number of vertices (Fig. 6b). With $N$ dofs,
# $h \sim N^{-1/2}$, so a rate $k$ in $h$ is a slope $-k/2$ against $N$.

# %%
fig, ax = plt.subplots(figsize=(6, 4.5))
for kind, style in (("uniform", "o-"), ("graded", "s--")):
    lv = studies[kind]["levels"]
    ndof = [r["ndof"] for r in lv]
    ax.loglog(ndof, [r["rel_l2"] for r in lv], style, label=f"{kind}, L2")
    ax.loglog(ndof, [r["rel_energy"] for r in lv], style, mfc="none", label=f"{kind}, energy")
n = np.array([ndof[1], ndof[-1]], dtype=float)
for k, ls in ((alpha, ":"), (1.0, "-."), (2.0, "--")):
    ax.loglog(n, 0.5 * (n / n[0]) ** (-k / 2), "k", ls=ls, lw=1, label=f"h^{k:.4g}")
ax.set_xlabel("number of dofs")
ax.set_ylabel("relative error")
ax.set_title("L-shape, order 1")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8, ncol=2)
fig.tight_layout()

# %% [markdown]
# What counts in practice is the cost of an accuracy. Here: the solve time against
# the $L^2$ error (wall time; it varies from machine to machine, and the coarsest
# levels measure overheads), and the dofs needed for a relative $L^2$ error of
# $10^{-3}$.

# %%
fig, ax = plt.subplots(figsize=(5, 3.5))
for kind, style in (("uniform", "o-"), ("graded", "s--")):
    lv = studies[kind]["levels"]
    ax.loglog([r["rel_l2"] for r in lv], [r["time_s"] for r in lv], style, label=kind)
ax.invert_xaxis()
ax.set_xlabel("relative L2 error")
ax.set_ylabel("solve time (s)")
ax.legend()
fig.tight_layout()

needed = {kind: min(r["ndof"] for r in res["levels"] if r["rel_l2"] < 1e-3) for kind, res in studies.items()}
print("dofs for a relative L2 error below 1e-3:", needed)
assert needed["graded"] < needed["uniform"]

# %% [markdown]
# ## The same from the command line
#
# `python -m ngfracture verify lshape` (or the installed script `ngfracture`) runs
# `lshape_study` and prints the table; `--json FILE` also writes it to a file:
#
# ```bash
# python -m ngfracture verify lshape --order 1 --levels 6 --mesh graded --json out/lshape.json
# ```
#
# `--help` lists the options (order, variant with traction-free reentrant edges,
# material model, grading exponent, E, nu). Run from any folder but the repository
# root, where `python -m` would import the uncompiled source tree.

# %%
cmd = [sys.executable, "-m", "ngfracture", "verify", "lshape", "--order", "1", "--levels", "4", "--mesh", "graded"]
run = subprocess.run(cmd, capture_output=True, text=True)
print(run.stdout or run.stderr)
assert run.returncode == 0 and "rates over the finest three levels" in run.stdout
