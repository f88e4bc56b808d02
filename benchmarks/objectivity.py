"""Mesh objectivity of the crack criterion: one-ring strain against critical distance.

Two studies on the notched plate (``ngfracture.scenes``), each for the paper's one-ring
criterion (``radius`` null) and the critical-distance criterion (docs/criterion.md):

* ``initiation``: linear elasticity (plane stress glass), notch-tip mesh size
  h = r/2, r/4, ... (``--levels``) within 2r of the tips, maxh 0.034 elsewhere; the
  extension ``x_init`` at which the first vertex reaches the critical strain (the measure
  is linear in the load: one solve per level), its run time, and its relative error
  against the finest level of the same criterion.
* ``crack``: full simulations (``Simulation(scenes.plate(maxh, radius=...))``) at the mesh
  sizes ``--crack-maxh``: total crack length, number of fragments, run time, and the
  crack length's relative error against the finest level of the same criterion (the
  physical answer is one crack of 0.92, notch tip to notch tip).

Usage::

    PYTHONPATH=. python benchmarks/objectivity.py [--json F] [--plot F.png] [--force]
        [--radius 0.04] [--levels 3] [--crack-maxh 0.034 0.017]
        [--crack-criteria one-ring critical-distance]

Without ``--json`` the JSON goes to stdout.
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from critical_distance_util import plate_initiation   # noqa: E402  (shared with the tests)

from ngfracture import scenes   # noqa: E402
from ngfracture.cli import _int_at_least   # noqa: E402

import benchmark_json   # noqa: E402
from ngfracture import Simulation   # noqa: E402

NOTCH_TO_NOTCH = 0.92


def initiation(radius, levels):
    """x_init per notch-tip level for both criteria; errors against each one's finest level."""
    rows = []
    for criterion in (None, radius):
        part = []
        for k in range(1, levels + 1):
            h = radius / 2 ** k
            t0 = time.perf_counter()
            x, mesh, _ = plate_initiation(h, criterion, notch_zone=2 * radius)
            part.append({"criterion": "one-ring" if criterion is None else "critical distance",
                         "notch_h": h, "radius": criterion, "nv": mesh.nv, "x_init": x,
                         "seconds": time.perf_counter() - t0})
        finest = part[-1]["x_init"]
        for row in part:
            row["error_vs_finest"] = abs(row["x_init"] - finest) / finest
        rows += part
    return rows


def crack(radius, maxhs, criteria=("one-ring", "critical-distance")):
    """One plate simulation per mesh size and criterion."""
    rows = []
    chosen = {"one-ring": None, "critical-distance": radius}
    for criterion in (chosen[name] for name in criteria):
        part = []
        for maxh in maxhs:
            t0 = time.perf_counter()
            scene = scenes.plate(maxh=maxh, radius=criterion)
            result = Simulation(scene, pictures="none").run()
            s = result.summary
            part.append({"criterion": "one-ring" if criterion is None else "critical distance",
                         "maxh": maxh, "radius": criterion, "nv": scene.mesh.nv,
                         "reason": result.reason, "crack_length": s["crack_length"],
                         "n_fragments": s["n_fragments"],
                         "length_over_notch_to_notch": s["crack_length"] / NOTCH_TO_NOTCH,
                         "seconds": time.perf_counter() - t0})
        finest = part[-1]["crack_length"] if part else None
        for row in part:
            row["error_vs_finest"] = abs(row["crack_length"] - finest) / finest if finest else None
        rows += part
    return rows


def plot(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for name, style in (("one-ring", "o-"), ("critical distance", "s-")):
        rows = [r for r in result["initiation"] if r["criterion"] == name]
        axes[0].semilogx([r["notch_h"] for r in rows], [r["x_init"] for r in rows], style, label=name)
        rows = [r for r in result["crack"] if r["criterion"] == name]
        if rows:
            axes[1].semilogx([r["maxh"] for r in rows], [r["crack_length"] for r in rows], style, label=name)
    axes[0].set_xlabel("notch-tip mesh size h")
    axes[0].set_ylabel("first-crack extension x_init")
    axes[0].set_title(f"initiation (r = {result['radius']})")
    axes[1].axhline(NOTCH_TO_NOTCH, color="k", lw=0.8, ls=":", label="notch to notch")
    axes[1].set_xlabel("maxh")
    axes[1].set_ylabel("total crack length")
    axes[1].set_title("plate simulation")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    benchmark_json.save_figure(fig, path)


def _positive_float(text):
    v = float(text)
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return v


def main(argv=None):
    parser = argparse.ArgumentParser(description="Mesh objectivity of the crack criterion on the "
                                                 "notched plate: one-ring vs critical distance.")
    benchmark_json.add_options(parser, force_help="overwrite existing output files")
    parser.add_argument("--plot", metavar="FILE", help="write the refinement plot as PNG")
    parser.add_argument("--radius", type=_positive_float, default=scenes.PLATE_RADIUS,
                        help=f"critical distance r (default: the plate scene's, {scenes.PLATE_RADIUS})")
    parser.add_argument("--levels", type=_int_at_least(2), default=3,
                        help="initiation levels h = r/2 ... r/2^levels (default 3)")
    parser.add_argument("--crack-maxh", type=_positive_float, nargs="*", default=[0.034],
                        help="mesh sizes of the plate simulations (default 0.034; none: skip)")
    parser.add_argument("--crack-criteria", nargs="+", choices=("one-ring", "critical-distance"),
                        default=["one-ring", "critical-distance"],
                        help="criteria of the plate simulations (default both)")
    args = parser.parse_args(argv)
    benchmark_json.refuse_existing(parser, args, args.plot)
    result = {"problem": "notched plate", "radius": args.radius,
              "initiation": initiation(args.radius, args.levels),
              "crack": crack(args.radius, sorted(args.crack_maxh, reverse=True), args.crack_criteria)}
    benchmark_json.write(args, result)
    if args.plot:
        plot(result, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
