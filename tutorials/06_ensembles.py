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
# # Random strength and ensembles: fragment statistics with confidence
#
# Glass breaks at flaws whose strength is random. One run with a uniform critical
# strain gives one crack pattern; a fragmentation study wants the distribution of
# fragment sizes and its spread. Here each vertex gets a critical strain drawn from a
# Weibull distribution, many seeds of the same scene run as an ensemble on
# `dask.distributed`, and the fragments of all runs are pooled into statistics with
# bootstrap confidence intervals.
#
# It illustrates how to:
#
# - draw a Weibull strength field and check it against the distribution,
# - see the weakest-link size effect,
# - run an ensemble of seeds on a local dask cluster (`Ensemble(...).run()`),
# - read `ensemble.json`: per-sample results, fragment-size statistics, the fit.

# %%
import functools
import json
import math
import shutil
from pathlib import Path

import matplotlib.pyplot as plt  # inline in Jupyter; Agg (no window) in a headless script
import numpy as np

from ngfracture import scenes
from ngfracture.fracture import strength
from ngfracture.studies.ensemble import Ensemble

# %% [markdown]
# ## A Weibull strength field
#
# `scenes.plate(weibull_m=8, seed=1)` draws one critical strain per vertex, in vertex
# order, from the PCG64 stream of the seed. Its scale defaults to the value whose mean
# is the uniform critical strain of the glass (1.38e-4), so the two are compared at the
# same mean strength. The same seed gives the same field bit for bit (the scene records
# a digest of it).

# %%
scene = scenes.plate(maxh=0.1, weibull_m=8, seed=1, radius=None)
p = scene.parameters
print({k: p[k] for k in ("weibull_m", "weibull_scale", "seed", "strength_min", "strength_mean", "strength_digest")})
assert scenes.plate(maxh=0.1, weibull_m=8, seed=1, radius=None).strength.tobytes() == scene.strength.tobytes()

draws = strength.weibull_strength(20_000, 8, p["weibull_scale"], seed=1)
s = np.linspace(draws.min(), draws.max(), 200)
m, lam = 8, p["weibull_scale"]
pdf = m / lam * (s / lam) ** (m - 1) * np.exp(-(s / lam) ** m)
fig, ax = plt.subplots(figsize=(5, 3))
ax.hist(draws, bins=60, density=True, alpha=0.6, label="20000 draws")
ax.plot(s, pdf, "k", label="Weibull m = 8")
ax.axvline(scenes.GLASS["critical"], color="r", linestyle="--", label="uniform critical strain")
ax.set_xlabel("critical strain")
ax.legend(fontsize=8)
plt.show()
assert abs(draws.mean() / strength.weibull_mean(m, lam) - 1) < 0.01

# %% [markdown]
# ## The weakest link
#
# If a reference area fails with Weibull(m, scale), an area k times larger survives
# only when all k pieces do: its strength is Weibull with scale `scale k^(-1/m)`. Given a
# reference area (`weibull_area`), every vertex's scale follows its tributary area, and
# the weakest of k vertices is as strong as one vertex of k times the area.

# %%
a_ref, n = 0.001, 40_000
one = strength.weibull_strength(n, m, 1.0, seed=2, areas=np.full(n, a_ref), reference_area=a_ref)
for k in (1, 4, 16):
    weakest = one.reshape(-1, k).min(axis=1).mean()
    theory = strength.weibull_mean(m, k ** (-1 / m))
    print(f"area {k:2d} x reference: mean strength {weakest:.4f}, theory {theory:.4f}")
    assert abs(weakest / theory - 1) < 0.02

# %% [markdown]
# ## An ensemble on dask
#
# `Ensemble(scene_factory, seeds, out=...)` runs the scene for every seed, each an
# ordinary simulation in `out/sample_NNNN/` with its checkpoints, on a `LocalCluster`
# of two single-threaded worker processes (pass `run(client)` to use any dask cluster).
# Rerunning skips finished samples and resumes interrupted ones. The plate here is
# coarse (maxh 0.15), judged by the paper's criterion (`radius=None`: with the default
# critical distance every sample breaks into the same two halves, and the mesh would be
# refined along the crack line) and solved without contact rows (its pieces only
# separate) to keep the notebook short; the command line does the same with
# `ngfracture ensemble plate --samples 6 --set weibull_m=8 --set maxh=0.15 --set radius=none --contact never`.

# %%
out = Path("out") / "plate_ensemble"
shutil.rmtree(out, ignore_errors=True)   # a fresh ensemble each time the notebook runs
factory = functools.partial(scenes.plate, maxh=0.15, weibull_m=8, radius=None)
report = Ensemble(factory, seeds=range(6), out=out, workers=2, contact="never", progress=False).run()
print(f"{report['finished']} of {len(report['samples'])} samples finished")
for r in report["samples"]:
    print(f"seed {r['seed']}: {r['reason']:8s} {r['steps']:3d} steps, {r['split_vertices']:3d} split vertices, "
          f"{r['fragments']} fragments, crack length {r['crack_length']:.3f}, peak load {r['peak_load']:.4g}")
assert json.loads((out / "ensemble.json").read_text())["seeds"] == list(range(6))

# %% [markdown]
# ## Statistics
#
# The fragments of all finished samples are pooled. The intervals come from a bootstrap
# over samples (the fragments of one run are not independent, the runs are). The
# fragment-size distribution is fitted by maximum likelihood with a lognormal, a
# Weibull and an exponential law; the one with the smallest AIC is reported with its
# Kolmogorov-Smirnov distance. The peak load is the largest 2 W / x (elastic energy,
# load parameter): the force on the plate's sides, by Clapeyron's theorem.

# %%
sizes, fit = report["fragment_sizes"], report["fit"]
print(f"{sizes['count']} fragments, mean area {sizes['mean']:.4f} "
      f"(95% interval {sizes['mean_interval'][0]:.4f} to {sizes['mean_interval'][1]:.4f})")
print("median area", round(sizes["quantiles"]["0.5"], 4), "interval", np.round(sizes["quantile_intervals"]["0.5"], 4))
print("fit:", fit.get("family") or fit.get("reason"))
if fit.get("family"):
    best = fit["families"][fit["family"]]
    print("  parameters", best["parameters"], "KS distance", round(best["ks_statistic"], 3))
peaks = report["peak_load"]
print(f"peak load {peaks['mean']:.4g} +- {peaks['std']:.2g} (95% interval of the mean "
      f"{peaks['mean_interval'][0]:.4g} to {peaks['mean_interval'][1]:.4g})")
assert sizes["count"] == sum(r["fragments"] for r in report["samples"] if r["ok"])
assert math.isclose(sum(sizes["ecdf"]["cdf"][-1:]), 1.0)

fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
for ax, name in zip(axes, ("fragment_sizes", "fragment_counts", "peak_loads")):
    ax.imshow(plt.imread(out / report["pictures"][name]))
    ax.axis("off")
plt.show()

# %% [markdown]
# ## Larger ensembles
#
# `ngfracture ensemble disk --samples 16 --set weibull_m=8 --set maxh=0.12 --workers 2`
# runs the disk around the expanding core for 16 seeds; on a cluster, start a dask
# scheduler and workers with one thread each (dask-jobqueue, `dask-ssh`, Kubernetes) and
# pass `--scheduler tcp://HOST:8786`. docs/ensembles.md explains the choices.
