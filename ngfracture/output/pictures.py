"""Pictures of a run without a display: the deformed pieces (Pillow), the fragment sizes (matplotlib).

The pieces of a 3D run are drawn by :mod:`ngfracture.output.solid_pictures`; ``render_png``
and ``final_pictures`` take both.

    render_png(mesh, u, stats.fragment, "out/run/final.png")
    plot_fragment_sizes(stats.areas, "out/run/fragment_sizes.png")
"""
import io
from pathlib import Path

import numpy as np

from .atomic import write_bytes
from .vtk import displacement_values, is_tetrahedral, vertex_arrays

__all__ = ["RenderError", "picture_scale", "render_png", "fragment_size_bins", "plot_fragment_sizes",
           "final_pictures", "SIZES_MIN_FRAGMENTS", "FRAGMENT_COLOURS", "SUPERSAMPLING",
           "picture_pixels"]


class RenderError(RuntimeError):
    """A picture could not be drawn; the message says why."""


#: render_png draws at this multiple of the picture's size and reduces (antialiasing)
SUPERSAMPLING = 2


#: the colours of fragments 0, 1, 2, ... (cycled)
FRAGMENT_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                    "#7f7f7f", "#bcbd22", "#17becf", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896",
                    "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7", "#dbdb8d", "#9edae5"]


def picture_scale(points, u):
    """Magnification that shows the largest displacement as 2% of the body's size.

    Parameters
    ----------
    points : numpy.ndarray, shape (nv, 2)
        Reference coordinates.
    u : numpy.ndarray
        Displacement values (any shape).

    Returns
    -------
    float
        1 when nothing moves.
    """
    size = float(np.ptp(np.asarray(points), axis=0).max())
    umax = float(np.abs(u).max(initial=0.0))
    return 0.02 * size / umax if umax > 0 else 1.0


def picture_pixels(xy, width, height):
    """Pixel coordinates of points fitted into a picture drawn at ``SUPERSAMPLING`` times its size.

    Parameters
    ----------
    xy : numpy.ndarray, shape (n, 2)
        Coordinates on the picture's plane (x right, y up).
    width, height : int
        The picture's size in pixels (before supersampling).

    Returns
    -------
    numpy.ndarray, shape (n, 2)
        Pixel x, y (y down) on the supersampled canvas: the points' bounding box centred,
        equal aspect, 2 % margins.
    """
    ss = SUPERSAMPLING
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = np.maximum(hi - lo, 1e-300)
    zoom = ss * 0.96 * min(width / span[0], height / span[1])     # 2 % margins, equal aspect
    centre = 0.5 * (lo + hi)
    return np.column_stack([ss * width / 2 + zoom * (xy[:, 0] - centre[0]),
                            ss * height / 2 - zoom * (xy[:, 1] - centre[1])])


def render_png(mesh, u, fragment, path, window_size=(1200, 900), scale=1.0, crack_boundary="crack",
               line_width=2.0, force=False):
    """A PNG of the deformed configuration coloured by fragment, crack faces drawn in black.

    Drawn with Pillow as a raster of the triangles (no plotting library, no display, no
    OpenGL; the VTK files are for ParaView and PyVista).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh, reference configuration (3D: :func:`.solid_pictures.render_solid_png`).
    u : ngsolve.GridFunction or numpy.ndarray or None
        Displacement (None: the reference configuration).
    fragment : array_like of int
        Fragment id per triangle; 20 colours, cycled.
    path : str or pathlib.Path
        The PNG file; its folder must exist.
    window_size : (int, int)
        Width and height in pixels.
    scale : float
        Displacement magnification.
    crack_boundary : str
        Boundary name of the crack faces.
    line_width : float
        Width of the crack lines in pixels.
    force : bool
        Overwrite an existing file.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    RenderError
        Pillow failed to draw or encode the picture (the message says how).
    ValueError
        ``fragment`` does not have one entry per triangle, or a bad displacement.
    FileExistsError
        ``path`` exists and not ``force``.
    """
    if is_tetrahedral(mesh):
        from .solid_pictures import render_solid_png
        return render_solid_png(mesh, u, fragment, path, window_size, scale, crack_boundary, force)
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"render_png: {path} exists; pass force=True to overwrite it")
    a = vertex_arrays(mesh)
    fragment = np.asarray(fragment, dtype=np.int64).ravel()
    if fragment.shape != (len(a.triangles),):
        raise ValueError(f"render_png: {fragment.size} fragment numbers for {len(a.triangles)} triangles")
    U = np.zeros((mesh.nv, 2)) if u is None else displacement_values(mesh, u)
    X = a.points + scale * U
    width, height = (int(w) for w in window_size)
    try:
        from PIL import Image, ImageDraw
        # drawn at twice the size and reduced: smooth edges without an antialiasing rasteriser
        ss = SUPERSAMPLING
        pixels = picture_pixels(X, width, height)
        image = Image.new("RGB", (ss * width, ss * height), "white")
        draw = ImageDraw.Draw(image)
        colours = [FRAGMENT_COLOURS[f % len(FRAGMENT_COLOURS)] for f in fragment.tolist()]
        # outlines in the face colour: no white seams between triangles of one fragment
        for corners, colour in zip(pixels[a.triangles].tolist(), colours):
            draw.polygon([tuple(p) for p in corners], fill=colour, outline=colour)
        pen = max(1, round(ss * line_width))
        for (x0, y0), (x1, y1) in ((pixels[s0], pixels[s1]) for s0, s1 in a.boundary_segments(crack_boundary)):
            draw.line([(x0, y0), (x1, y1)], fill="black", width=pen)
        buf = io.BytesIO()
        image.reduce(ss).save(buf, format="PNG")
    except Exception as e:
        raise RenderError(f"ngfracture.output.pictures: Pillow could not draw {path.name} "
                          f"({type(e).__name__}: {e})") from e
    write_bytes(path, buf.getvalue(), force)
    return path


def fragment_size_bins(areas):
    """Logarithmic bin edges that hold every area: 5 to 50 bins, about sqrt(n).

    Parameters
    ----------
    areas : numpy.ndarray
        Fragment areas, finite and > 0, at least one.

    Returns
    -------
    numpy.ndarray
        Increasing edges; the first is the smallest area and the last the largest exactly
        (``10 ** log10(a)`` can miss ``a`` by a rounding and drop that fragment from the
        histogram: one set in three of random areas lost one), or a bin around a single size.
    """
    lo, hi = float(areas.min()), float(areas.max())
    if hi <= lo * (1 + 1e-12):          # one size only: a bin around it
        lo, hi = lo / 1.5, hi * 1.5
    bins = np.logspace(np.log10(lo), np.log10(hi), max(5, min(50, int(np.sqrt(areas.size)) + 1)))
    bins[0], bins[-1] = lo, hi
    return bins


def plot_fragment_sizes(areas, path, force=False, title="Fragment-size distribution"):
    """Histogram and cumulative distribution of fragment areas (matplotlib, Agg).

    Left: number of fragments per logarithmic area bin. Right: fraction of fragments with
    area >= A (the complementary cumulative distribution). Axes whose values span a decade
    or more are logarithmic.

    Parameters
    ----------
    areas : array_like
        Fragment areas, all finite and > 0 (e.g. ``FragmentStatistics.areas``).
    path : str or pathlib.Path
        Image file (format from the suffix: .png, .pdf, .svg).
    force : bool
        Overwrite an existing file.
    title : str
        Figure title; the number of fragments is appended.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        No areas, or an area that is not finite and positive.
    FileExistsError
        ``path`` exists and not ``force``.
    """
    from matplotlib.figure import Figure   # no pyplot: no global backend, no display
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.ticker import LogFormatter, NullFormatter
    A = np.asarray(areas, dtype=float).ravel()
    if A.size == 0:
        raise ValueError("plot_fragment_sizes: no fragment areas")
    if not np.all(np.isfinite(A) & (A > 0)):
        raise ValueError(f"plot_fragment_sizes: areas must be finite and > 0; {np.sum(~(np.isfinite(A) & (A > 0)))} are not")
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"plot_fragment_sizes: {path} exists; pass force=True to overwrite it")
    bins = fragment_size_bins(A)
    fig = Figure(figsize=(9, 4))
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(1, 2)
    # fixed margins: the constrained layout engine took 2 s of a 20 s plate run
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.13, top=0.88, wspace=0.3)
    ax1.hist(A, bins=bins, color="tab:blue", edgecolor="black", linewidth=0.5)
    ax1.set_xlabel("fragment area")
    ax1.set_ylabel("number of fragments")
    s = np.sort(A)
    fraction = 1.0 - np.arange(A.size) / A.size
    ax2.step(s, fraction, where="post", color="tab:red")
    ax2.set_xlabel("fragment area A")
    ax2.set_ylabel("fraction of fragments with area >= A")
    # log axes where the values span a decade or more, with plain tick labels ("0.001"):
    # matplotlib's default "10^-3" goes through its TeX parser, which took longer than the
    # rest of the figure; a log axis over less than a decade would have no labelled tick
    for ax, which, values in ((ax1, "x", bins), (ax2, "x", s), (ax2, "y", fraction)):
        if values.max() >= 10 * values.min():
            axis = ax.xaxis if which == "x" else ax.yaxis
            ax.set_xscale("log") if which == "x" else ax.set_yscale("log")
            axis.set_major_formatter(LogFormatter())
            axis.set_minor_formatter(NullFormatter())
    fig.suptitle(f"{title} ({A.size} fragments)")
    buf = io.BytesIO()
    fig.savefig(buf, format=path.suffix.lstrip(".") or "png", dpi=120)
    write_bytes(path, buf.getvalue(), force)
    return path


#: fewer fragments than this: no fragment_sizes.png at the end of a run (a distribution of
#: one to four pieces says nothing that summary.json's fragment_areas does not)
SIZES_MIN_FRAGMENTS = 5


def final_pictures(folder, mesh, u, stats, scale, sizes_min_fragments=SIZES_MIN_FRAGMENTS):
    """Draw a run's ``final.png`` and, for enough fragments, ``fragment_sizes.png`` into ``folder``.

    A picture that cannot be drawn is a fact of the output, not a failed run: the returned
    record says why final.png is missing. Both files are replaced; a fragment_sizes.png
    left from before is removed when none is drawn.

    Parameters
    ----------
    folder : path
        The run's output folder.
    mesh, u
        The mesh and displacement, as for :func:`render_png`.
    stats : FragmentStatistics
        Fragment per triangle and fragment areas.
    scale : float
        Displacement magnification (:func:`picture_scale`).
    sizes_min_fragments : int
        Draw fragment_sizes.png from this many fragments on (1: always).

    Returns
    -------
    dict
        ``{"final": "final.png", "displacement_scale": scale}`` or ``{"final_error": reason}``,
        and ``"fragment_sizes": "fragment_sizes.png"`` if drawn (the ``pictures`` of
        summary.json).
    """
    folder = Path(folder)
    try:
        render_png(mesh, u, stats.fragment, folder / "final.png", scale=scale, force=True)
        pictures = {"final": "final.png", "displacement_scale": scale}
    except RenderError as err:
        pictures = {"final_error": str(err)}
    sizes = folder / "fragment_sizes.png"
    if stats.count >= sizes_min_fragments:
        plot_fragment_sizes(stats.areas, sizes, force=True)
        pictures["fragment_sizes"] = sizes.name
    elif sizes.exists():
        sizes.unlink()
    return pictures
