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
# # Nonlinear elasticity with Lagrange-multiplier constraints
#
# A rectangular plate is stretched by gliding conditions on its left and right edges,
# as in the fracture test of the paper (section 4.2), but without cracks. ngfracture
# solves the geometrically nonlinear equilibrium with the modified Newton-Raphson
# scheme of the paper (eq. 3 to 7); the constraints are Lagrange-multiplier rows.
#
# It illustrates how to:
#
# - build a plate with named boundaries in netgen and set up an `ElasticProblem`,
# - compare the linear, St Venant-Kirchhoff and neo-Hooke models,
# - prescribe gliding conditions (`ux` given, `uy` free) and a point constraint,
# - apply the load in steps and read the `SolveStatus`,
# - compare modified and full Newton through the increment history of eq. 7,
# - recognise a failed solve (a floating body, an inverted element),
# - draw the deformed plate with matplotlib.

# %%
import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import matplotlib.tri as mtri
import ngsolve as ng
import numpy as np
from netgen.geom2d import SplineGeometry

import ngfracture as nf

# %% [markdown]
# ## Problem definition
#
# The plate is $[0, 2] \times [0, 1]$ with a circular hole of radius 0.2 in its
# centre (unit thickness, plane strain). `AddRectangle` and `AddCircle` name the
# edges, and constraints refer to these names.

# %%
L, H = 2.0, 1.0
geo = SplineGeometry()
geo.AddRectangle((0, 0), (L, H), bcs=["bottom", "right", "top", "left"])
geo.AddCircle((L / 2, H / 2), 0.2, leftdomain=0, rightdomain=1, bc="hole")
mesh = ng.Mesh(geo.GenerateMesh(maxh=0.1))
print(mesh.nv, "vertices,", mesh.ne, "triangles, boundaries", sorted(set(mesh.GetBoundaries())))

# %% [markdown]
# The boundary conditions are the paper's gliding conditions: on the left edge
# $u_x = 0$, on the right edge $u_x = d$, and $u_y$ is free on both. They fix the
# horizontal translation and the rotation; the vertical translation is fixed by one
# point constraint, $u_y = 0$ at the vertex in the lower left corner.
#
# `setup` builds the same problem for any material and stretch.

# %%
corner = int(np.argmin(np.linalg.norm(mesh.ngmesh.Coordinates()[:, :2], axis=1)))
E, nu = 1.0, 0.3  # a soft material in arbitrary units: only strains matter here


def setup(material, stretch, order=1):
    """The plate stretched by ``stretch * L`` with gliding ends and one point constraint."""
    prob = nf.ElasticProblem(mesh, material, order=order)
    prob.add_dirichlet("left", 0.0, component="x")
    prob.add_dirichlet("right", stretch * L, component="x")
    prob.add_point_constraint(corner, 0.0, component="y")
    return prob


materials = {
    "linear": nf.LinearElastic(E, nu),
    "St Venant-Kirchhoff": nf.StVenantKirchhoff(E, nu),
    "neo-Hooke": nf.NeoHookean(E, nu),
}

# %% [markdown]
# ## Solve
#
# `solve` brings the problem from its current state to the prescribed values in
# `load_steps` equal increments and returns a `SolveStatus`. It never raises on a
# failed solve: `status.converged` and `status.reason` say how it ended.
#
# We use full Newton (`method="full"`) and three load steps here; the next section
# compares it with the paper's modified Newton.
#
# At a small stretch (0.01 %) the three models agree; at 30 % they do not. We
# compare the lateral contraction (the vertical displacement of the top edge, read
# above the hole) and the stored energy.


# %%
def contraction(prob):
    """Vertical displacement of the top edge above the hole."""
    return prob.u(mesh(L / 2, H))[1]


results = {}
for stretch in (1e-4, 0.3):
    for name, material in materials.items():
        prob = setup(material, stretch)
        status = prob.solve(method="full", load_steps=3)
        assert status.converged, status.message
        results[name, stretch] = (contraction(prob), prob.energy(), status)
        print(f"stretch {stretch:6.4f} {name:20s} {status.reason}, {status.iterations:3d} iterations, "
              f"top moves {contraction(prob):+.4e}, energy {prob.energy():.4e}")

# %% [markdown]
# The status carries more than the verdict: the number of load steps and Newton
# iterations, the histories of eq. 7 and of the out-of-balance force, and the time
# spent in each phase.

# %%
status = results["neo-Hooke", 0.3][2]
print("steps", status.steps, "iterations", status.iterations)
print(f"last relative increment {status.increment_history[-1]:.1e}, "
      f"last out-of-balance force {status.residual_history[-1]:.1e}")
print("timings (s):", {phase: round(t, 4) for phase, t in status.timings.items()})

# %% [markdown]
# At 0.01 % stretch the models differ by terms of the order of the strain; at 30 % the
# contraction differs by tens of per cent between the models. The linear model needs
# one iteration per load step, the nonlinear ones several.

# %%
small = [results[name, 1e-4][0] for name in materials]
large = [results[name, 0.3][0] for name in materials]
assert np.ptp(small) < 1e-3 * np.max(np.abs(small))
assert np.ptp(large) > 0.05 * np.max(np.abs(large))
assert results["linear", 0.3][2].iterations == 3  # one per load step

# %% [markdown]
# ### Modified against full Newton
#
# Modified Newton (the paper's choice) factorises the tangent once per load step and
# reuses it; its increments shrink linearly. Full Newton refactorises at every iterate
# and converges quadratically. `increment_history` is the ratio
# $\|\Delta u^{(k)}\| / \|\Delta u^{(0)}\|$ of eq. 7, the quantity the solver stops on
# (tolerance `tol=1e-10`). Modified Newton also stops one iteration early when the
# contraction $\rho = \|\Delta u^{(k)}\| / \|\Delta u^{(k-1)}\|$ says that the error of
# its iterate, $\rho / (1 - \rho)\,\|\Delta u^{(k)}\|$, is already below the tolerance.
# Here: neo-Hooke, 5 % stretch in one load step.

# %%
histories = {}
for method in ("modified", "full"):
    prob = setup(materials["neo-Hooke"], 0.05)
    status = prob.solve(method=method, load_steps=1)
    assert status.converged, status.message
    histories[method] = status.increment_history
    print(f"{method:8s}: {status.iterations} iterations, "
          f"factorisation {status.timings['factorize']:.3f} s")

fig, ax = plt.subplots(figsize=(5, 3.5))
for method, hist in histories.items():
    ax.semilogy(range(1, len(hist) + 1), hist, "o-", label=f"{method} Newton")
ax.axhline(1e-10, color="k", ls=":", lw=1, label="tol (eq. 7)")
ax.set_xlabel("iteration k")
ax.set_ylabel(r"$\|\Delta u^{(k)}\| / \|\Delta u^{(0)}\|$")
ax.set_title("neo-Hooke, 5 % stretch in one load step")
ax.legend()
fig.tight_layout()

# %% [markdown]
# Full Newton needs fewer iterations, and near the end each ratio is at most about
# the square of the one before (quadratic convergence); modified Newton's ratios fall
# by a roughly constant factor per iteration (linear convergence).

# %%
full, modified = np.array(histories["full"]), np.array(histories["modified"])
assert len(full) < len(modified)
assert full[-1] < 1e-10
# modified Newton ends below the tolerance, or with an error estimate below it
rho = modified[-1] / modified[-2]
assert modified[-1] < 1e-10 or rho / (1 - rho) * modified[-1] < 1e-10
# quadratic: the last step of full Newton squares (up to a constant) the one before
assert full[-1] < 10 * full[-2] ** 2
# linear: modified Newton's contraction factors stay roughly constant
factors = modified[2:] / modified[1:-1]
print("modified Newton, ratio of successive increments:", np.round(factors, 2))
assert np.all(factors < 0.9)

# %% [markdown]
# ### What a failure looks like
#
# Modified Newton pays for its single factorisation with a smaller radius of
# convergence. St Venant-Kirchhoff at 30 % stretch in three load steps does not
# converge with it: the increments grow and the solve stops with `"diverged"`
# (full Newton solved the same problem above). More load steps are the remedy.

# %%
prob = setup(materials["St Venant-Kirchhoff"], 0.3)
status = prob.solve(method="modified", load_steps=3)
print(status.converged, status.reason, "|", status.message)
assert status.reason in ("diverged", "max_iterations"), status.reason
status = prob.solve(method="modified", load_steps=5)
print(status.converged, status.reason, status.iterations, "iterations")
assert status.converged, status.message

# %% [markdown]
#
# Without the point constraint nothing holds the plate vertically: it is a floating
# body and the constrained system is singular. The solver checks the rigid-body
# modes before it factorises anything and says which piece floats.

# %%
prob = nf.ElasticProblem(mesh, materials["neo-Hooke"])
prob.add_dirichlet("left", 0.0, component="x")
prob.add_dirichlet("right", 0.1, component="x")
status = prob.solve()
print(status.converged, status.reason)
print(status.message)
assert not status.converged and status.reason == "singular"
assert "floating body" in status.message

# %% [markdown]
# Pushing the right edge beyond the left one in a single step would fold the
# elements over: the nonlinear models check $\det F > 0$ after every iterate and
# stop with `"inverted_element"`. The displacement is then the last converged
# state, here the undeformed plate.

# %%
prob = setup(materials["neo-Hooke"], -1.2)
status = prob.solve(load_steps=1)
print(status.converged, status.reason)
print(status.message)
assert status.reason == "inverted_element", status.reason
assert np.all(prob.u.vec.FV().NumPy() == 0.0)

# %% [markdown]
# ## Post-processing
#
# `prob.u` is an NGSolve `GridFunction` and `prob.stress()` a `CoefficientFunction`
# of the Cauchy stress, so everything NGSolve offers applies. Here we draw the plate
# deformed by the 30 % stretch with matplotlib, coloured by $\sigma_{xx}$ at the
# element centroids.

# %%
prob = setup(materials["neo-Hooke"], 0.3)
assert prob.solve(method="full", load_steps=3).converged
xy = mesh.ngmesh.Coordinates()[:, :2]
u = prob.u.vec.FV().NumPy().reshape(2, -1)[:, : mesh.nv].T  # vertex values (order 1)
tris = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ng.VOL)])
centroids = xy[tris].mean(axis=1)
sxx = prob.stress()[0](mesh(centroids[:, 0], centroids[:, 1])).ravel()

fig, ax = plt.subplots(figsize=(7, 3))
ax.triplot(mtri.Triangulation(xy[:, 0], xy[:, 1], tris), color="0.8", lw=0.4)
deformed = mtri.Triangulation(xy[:, 0] + u[:, 0], xy[:, 1] + u[:, 1], tris)
pc = ax.tripcolor(deformed, facecolors=sxx, edgecolors="k", linewidth=0.1)
fig.colorbar(pc, ax=ax, label=r"Cauchy $\sigma_{xx}$")
ax.set_aspect("equal")
ax.set_title("neo-Hooke plate at 30 % stretch (grey: reference)")
fig.tight_layout()

# %% [markdown]
# The hole concentrates the stress above and below it (a factor of about 3 in
# linear elasticity for an infinite plate); the deformed plate is as long as
# prescribed.

# %%
assert abs((xy[:, 0] + u[:, 0]).max() - 1.3 * L) < 1e-12
print(f"sigma_xx: median {np.median(sxx):.4f}, max {sxx.max():.4f}")
assert sxx.max() > 2 * np.median(sxx)
