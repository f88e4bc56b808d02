"""The load-displacement curve of a run: ``force_displacement.csv`` and ``force_displacement.png``.

Every accepted step's history record holds the resultants of the loaded boundaries
(``boundaries``: force and mean displacement per boundary, mechanics/resultants.py); the
CSV has one row per step, the load parameter and, per boundary, Fx, Fy, ux, uy (with Fz and
uz in 3D).
"""
import csv
import io

import numpy as np

from .atomic import write_bytes

__all__ = ["curve_columns", "write_force_displacement_csv", "plot_force_displacement"]


def curve_columns(history):
    """The columns of the curve: step, x, and per boundary its force and displacement.

    Parameters
    ----------
    history : list of dict
        A run's history records (with ``boundaries``; records without count as empty).

    Returns
    -------
    dict of str -> numpy.ndarray
        ``step``, ``x``, and ``<boundary>_Fx``, ``_Fy``, ``_ux``, ``_uy`` (3D: ``_Fx``, ``_Fy``,
        ``_Fz``, ``_ux``, ``_uy``, ``_uz``; NaN where a step lacks the boundary), in the order of
        the boundary names.
    """
    names = sorted({name for h in history for name in h.get("boundaries", {})})
    # 2 components in 2D, 3 in 3D
    d = max((len(b["force"]) for h in history for b in h.get("boundaries", {}).values()), default=2)
    cols = {"step": np.array([h["step"] for h in history], dtype=float),
            "x": np.array([h["x"] for h in history], dtype=float)}
    for name in names:
        values = np.array([h.get("boundaries", {}).get(name, {}).get("force", [np.nan] * d)
                           + h.get("boundaries", {}).get(name, {}).get("displacement", [np.nan] * d)
                           for h in history], dtype=float).reshape(len(history), 2 * d)
        labels = [f"F{c}" for c in "xyz"[:d]] + [f"u{c}" for c in "xyz"[:d]]
        for k, label in enumerate(labels):
            cols[f"{name}_{label}"] = values[:, k]
    return cols


def write_force_displacement_csv(path, history):
    """Write the curve as CSV (atomically).

    Parameters
    ----------
    path : str or pathlib.Path
    history : list of dict

    Returns
    -------
    pathlib.Path
    """
    cols = curve_columns(history)
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(list(cols))
    for i in range(len(cols["step"])):
        writer.writerow([int(cols["step"][i])] + [repr(float(c[i])) for c in list(cols.values())[1:]])
    return write_bytes(path, buf.getvalue().encode(), force=True)


def plot_force_displacement(path, history, load_description=""):
    """Plot each loaded boundary's force against its displacement, in the direction it is loaded.

    The direction of a boundary is that of its largest force over the run; a curve with the
    force along it against the displacement along it (snap-back shows as a turn to smaller
    displacements).

    Parameters
    ----------
    path : str or pathlib.Path
    history : list of dict
    load_description : str
        Shown under the title.

    Returns
    -------
    pathlib.Path or None
        None when no boundary carries a load.
    """
    cols = curve_columns(history)
    names = sorted({k.rsplit("_", 1)[0] for k in cols if k.endswith("_Fx")})
    if not names or not len(cols["step"]):
        return None
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure       # no pyplot: no global backend, no display
    fig = Figure(figsize=(6.4, 4.4))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    for name in names:
        axes = [c for c in "xyz" if f"{name}_F{c}" in cols]
        F = np.column_stack([cols[f"{name}_F{c}"] for c in axes])
        u = np.column_stack([cols[f"{name}_u{c}"] for c in axes])
        peak = np.nanargmax(np.linalg.norm(F, axis=1))
        d = F[peak] / max(np.linalg.norm(F[peak]), 1e-300)
        ax.plot(np.r_[0.0, u @ d], np.r_[0.0, F @ d], ".-", label=name)
    ax.set_xlabel("mean displacement of the boundary along its force")
    ax.set_ylabel("force on the boundary (reaction or load)")
    ax.set_title("load-displacement" + (f"\n{load_description}" if load_description else ""), fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return write_bytes(path, buf.getvalue(), force=True)
