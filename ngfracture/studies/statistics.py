"""Statistics of an ensemble of runs: fragment sizes, counts and peak loads, with confidence.

* Pooled fragment sizes: every fragment of every finished sample, in sample order.
  Count, mean, quantiles and the empirical cumulative distribution (ECDF) on a
  logarithmic grid of areas.
* Confidence: a percentile bootstrap over *samples*, not over fragments. The fragments
  of one run are not independent (they tile the body: one large piece leaves less room
  for others), the runs are; resampling whole runs keeps that dependence. The
  replicates come from a seeded PCG64 stream, so the intervals are the same bit for bit
  on a rerun.
* Fit of the fragment-size distribution by maximum likelihood, three families with
  the origin fixed at 0: lognormal (sequential random breakage, Kolmogorov's
  fragmentation theorem), Weibull (the Mott/Grady family of random-flaw fragmentation;
  it contains the exponential of Poisson fragmentation, modulus 1) and exponential.
  The chosen family has the smallest AIC (2 parameters for lognormal and Weibull, 1 for
  the exponential); every family's log-likelihood, AIC and Kolmogorov-Smirnov distance
  to the data with its p-value are reported. The p-value treats the fitted parameters as
  known, so it is optimistic (Lilliefors); read it as a distance, not a test.
"""
import math

import numpy as np

__all__ = ["QUANTILES", "fragment_size_statistics", "fit_fragment_sizes", "summary_with_interval",
           "plot_ensemble"]

#: the quantiles reported for the pooled fragment areas
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)


def _percentile_interval(replicates, level):
    a = (1 - level) / 2
    return np.quantile(replicates, [a, 1 - a], axis=0)


def summary_with_interval(values, seed=0, replicates=1000, level=0.95):
    """Mean and standard deviation of per-sample values, with a bootstrap interval of the mean.

    Parameters
    ----------
    values : array_like
        One number per sample (fragment counts, peak loads).
    seed : int
        Seed of the bootstrap stream.
    replicates : int
        Bootstrap replicates.
    level : float
        Confidence level of the interval.

    Returns
    -------
    dict
        n, mean, std (ddof 1, 0 for one value), min, max, mean_interval [lo, hi].
    """
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return {"n": 0}
    rng = np.random.Generator(np.random.PCG64(seed))
    means = v[rng.integers(0, v.size, size=(replicates, v.size))].mean(axis=1)
    lo, hi = _percentile_interval(means, level)
    return {"n": int(v.size), "mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0,
            "min": float(v.min()), "max": float(v.max()), "mean_interval": [float(lo), float(hi)]}


def fragment_size_statistics(areas_per_sample, seed=0, replicates=1000, level=0.95, grid_points=60):
    """Pooled fragment-size statistics with bootstrap intervals over samples.

    Parameters
    ----------
    areas_per_sample : list of array_like
        The fragment areas of every sample (finite, > 0).
    seed : int
        Seed of the bootstrap stream (PCG64).
    replicates : int
        Bootstrap replicates (>= 1).
    level : float
        Confidence level of the intervals (0 < level < 1).
    grid_points : int
        Points of the logarithmic area grid of the ECDF.

    Returns
    -------
    dict
        count, samples, mean, quantiles {q: value}, their intervals, and ``ecdf``:
        {area: grid, cdf: fraction of fragments with area <= grid value, lower, upper}.
        ``{"count": 0}`` without fragments.

    Raises
    ------
    ValueError
        An area that is not finite and > 0, or bad bootstrap settings.
    """
    if not (isinstance(replicates, int) and replicates >= 1 and 0 < level < 1):
        raise ValueError(f"fragment_size_statistics: need replicates >= 1 and 0 < level < 1, "
                         f"got {replicates!r}, {level!r}")
    samples = [np.asarray(a, dtype=float).ravel() for a in areas_per_sample]
    pooled = np.concatenate(samples) if samples else np.zeros(0)
    if pooled.size == 0:
        return {"count": 0, "samples": len(samples)}
    if not np.all(np.isfinite(pooled) & (pooled > 0)):
        raise ValueError("fragment_size_statistics: fragment areas must be finite and > 0")
    lo, hi = float(pooled.min()), float(pooled.max())
    grid = np.geomspace(lo, hi, grid_points) if hi > lo else np.array([lo])
    grid[0], grid[-1] = lo, hi      # geomspace can miss the ends by a rounding

    def estimates(values):
        s = np.sort(values)
        return (values.mean(), np.quantile(values, QUANTILES),
                np.searchsorted(s, grid, side="right") / s.size)

    mean, quant, cdf = estimates(pooled)
    rng = np.random.Generator(np.random.PCG64(seed))
    picks = rng.integers(0, len(samples), size=(replicates, len(samples)))
    boot_mean, boot_q, boot_cdf = [], [], []
    for pick in picks:
        values = np.concatenate([samples[i] for i in pick])
        if values.size == 0:        # replicate made of samples without fragments
            continue
        m, q, c = estimates(values)
        boot_mean.append(m)
        boot_q.append(q)
        boot_cdf.append(c)
    mean_iv = _percentile_interval(np.array(boot_mean), level)
    q_iv = _percentile_interval(np.array(boot_q), level)
    cdf_iv = _percentile_interval(np.array(boot_cdf), level)
    return {
        "count": int(pooled.size), "samples": len(samples), "level": level, "replicates": replicates,
        "mean": float(mean), "mean_interval": mean_iv.tolist(),
        "quantiles": {f"{q:g}": float(v) for q, v in zip(QUANTILES, quant)},
        "quantile_intervals": {f"{q:g}": [float(q_iv[0, i]), float(q_iv[1, i])] for i, q in enumerate(QUANTILES)},
        "ecdf": {"area": grid.tolist(), "cdf": cdf.tolist(), "lower": cdf_iv[0].tolist(),
                 "upper": cdf_iv[1].tolist()},
    }


def _ks(values, cdf):
    from scipy import stats
    res = stats.kstest(values, cdf)
    return float(res.statistic), float(res.pvalue)


def fit_fragment_sizes(areas):
    """Maximum-likelihood fits of the fragment-size distribution (see the module docstring).

    Parameters
    ----------
    areas : array_like
        Pooled fragment areas (finite, > 0).

    Returns
    -------
    dict
        ``family`` (the smallest AIC, or None with a ``reason`` when there are fewer than
        3 fragments or a single size) and ``families``: per family its parameters,
        log_likelihood, aic, ks_statistic and ks_pvalue.
    """
    from scipy import stats
    a = np.asarray(areas, dtype=float).ravel()
    if a.size < 3 or np.all(a == a[0]):
        return {"family": None, "reason": f"{a.size} fragment(s) of {len(np.unique(a))} size(s): nothing to fit"}
    logs = np.log(a)
    mu, sigma = float(logs.mean()), float(logs.std())            # closed-form lognormal MLE
    ll_logn = float(np.sum(stats.norm.logpdf(logs, mu, sigma) - logs))
    scale_exp = float(a.mean())                                  # closed-form exponential MLE
    ll_exp = float(np.sum(stats.expon.logpdf(a, scale=scale_exp)))
    k, _, lam = stats.weibull_min.fit(a, floc=0)
    ll_wb = float(np.sum(stats.weibull_min.logpdf(a, k, 0, lam)))
    fams = {
        "lognormal": ({"mu": mu, "sigma": sigma}, ll_logn, 2,
                      lambda x: stats.lognorm.cdf(x, sigma, scale=math.exp(mu))),
        "weibull": ({"modulus": float(k), "scale": float(lam)}, ll_wb, 2,
                    lambda x: stats.weibull_min.cdf(x, k, scale=lam)),
        "exponential": ({"scale": scale_exp}, ll_exp, 1, lambda x: stats.expon.cdf(x, scale=scale_exp)),
    }
    out = {}
    for name, (params, ll, npar, cdf) in fams.items():
        d, p = _ks(a, cdf)
        out[name] = {"parameters": params, "log_likelihood": ll, "aic": 2 * npar - 2 * ll,
                     "ks_statistic": d, "ks_pvalue": p}
    best = min(out, key=lambda n: out[n]["aic"])
    return {"family": best, "criterion": "smallest AIC", "count": int(a.size), "families": out}


def fitted_survival(fit, area):
    """P(A > area) of the chosen fitted family.

    Parameters
    ----------
    fit : dict
        From :func:`fit_fragment_sizes`.
    area : numpy.ndarray

    Returns
    -------
    numpy.ndarray or None
        None when nothing was fitted.
    """
    from scipy import stats
    if not fit.get("family"):
        return None
    p = fit["families"][fit["family"]]["parameters"]
    if fit["family"] == "lognormal":
        return stats.lognorm.sf(area, p["sigma"], scale=math.exp(p["mu"]))
    if fit["family"] == "weibull":
        return stats.weibull_min.sf(area, p["modulus"], scale=p["scale"])
    return stats.expon.sf(area, scale=p["scale"])


def _figure(size=(6, 4)):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure      # no pyplot: no global backend, no display
    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig


def plot_ensemble(report, folder):
    """The ensemble's three pictures (PNG, headless Agg).

    ``fragment_sizes.png``: fraction of fragments with area > A (volume > V for samples of a
    3D scene, which report ``fragment_volumes``), log-log, pooled, with the bootstrap band
    and the fitted family; ``fragment_counts.png``: histogram of the
    fragments per sample; ``peak_loads.png``: the peak load of every sample.

    Parameters
    ----------
    report : dict
        The content of ensemble.json (samples, fragment_sizes, fit).
    folder : pathlib.Path
        Where the PNGs go (overwritten: they are the ensemble's).

    Returns
    -------
    dict of str -> str
        Picture name -> file name.
    """
    from ..output.atomic import write_bytes
    import io
    done = [s for s in report["samples"] if s.get("ok")]
    pictures = {}

    def save(fig, name):
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
        write_bytes(folder / name, buf.getvalue(), force=True)
        pictures[name.split(".")[0]] = name

    sizes = report["fragment_sizes"]
    if sizes.get("count", 0) > 0:
        fig = _figure()
        ax = fig.subplots()
        e = sizes["ecdf"]
        area = np.array(e["area"])
        ccdf = 1 - np.array(e["cdf"])
        lower, upper = 1 - np.array(e["upper"]), 1 - np.array(e["lower"])
        floor = 0.5 / sizes["count"]        # log axis: show 0 as half a fragment's weight
        ax.fill_between(area, np.maximum(lower, floor), np.maximum(upper, floor), step="post",
                        color="tab:blue", alpha=0.25, label=f"{sizes['level']:.0%} bootstrap band")
        ax.step(area, np.maximum(ccdf, floor), where="post", color="tab:blue", label="pooled samples")
        sf = fitted_survival(report["fit"], area)
        if sf is not None:
            ax.plot(area, np.maximum(sf, floor), "k--", label=f"{report['fit']['family']} fit (ML)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        measure, sym = ("volume", "V") if any("fragment_volumes" in s for s in done) else ("area", "A")
        ax.set_xlabel(f"fragment {measure} {sym}")
        ax.set_ylabel(f"fraction of fragments with {measure} > {sym}")
        ax.set_title(f"{sizes['count']} fragments of {sizes['samples']} samples")
        ax.legend(fontsize=8)
        fig.subplots_adjust(left=0.14, right=0.97, bottom=0.13, top=0.9)
        save(fig, "fragment_sizes.png")
    if done:
        counts = np.array([s["fragments"] for s in done])
        fig = _figure()
        ax = fig.subplots()
        ax.hist(counts, bins=np.arange(counts.min(), counts.max() + 2) - 0.5, color="tab:green",
                edgecolor="black", linewidth=0.5)
        from matplotlib.ticker import MaxNLocator
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("fragments per sample")
        ax.set_ylabel("samples")
        fig.subplots_adjust(left=0.12, right=0.97, bottom=0.13, top=0.95)
        save(fig, "fragment_counts.png")
        fig = _figure()
        ax = fig.subplots()
        peaks = np.array([s["peak_load"] for s in done])
        ax.plot([s["seed"] for s in done], peaks, "o", color="tab:red")
        ax.axhline(peaks.mean(), color="k", linestyle="--", linewidth=0.8, label="mean")
        ax.set_xlabel("seed")
        ax.set_ylabel("peak load 2 W / x")
        ax.legend(fontsize=8)
        fig.subplots_adjust(left=0.16, right=0.97, bottom=0.13, top=0.95)
        save(fig, "peak_loads.png")
    return pictures
