"""The picture of a 3D run without a display: the deformed pieces' surface, shaded (Pillow).

    render_png(mesh3d, u, fragment, "out/run/final.png", scale=picture_scale(points, U))

:func:`render_solid_png` draws what :func:`ngfracture.output.pictures.render_png` draws in
2D, for tetrahedra: the boundary surface of the deformed configuration (displacement times
``scale``, the magnification of :func:`ngfracture.output.pictures.picture_scale`), each
face in the colour of its fragment (:data:`ngfracture.output.pictures.FRAGMENT_COLOURS`).

The surface is every face of the tetrahedra that no other tetrahedron shares, oriented out
of its tetrahedron (looked for among the faces whose three vertices are vertices of the
mesh's boundary faces), so the lips of a crack (faces on distinct vertex copies) are
surface and an opened crack shows its two faces; crack faces (boundary ``crack``) are drawn in a
darker tone of their fragment's colour. The view is orthographic and fixed: the viewer
looks from the direction (cos e cos a, cos e sin a, sin e) with azimuth a = 30 degrees and
elevation e = 25 degrees, z up on the picture. Faces turned away from the viewer are left
out (the surface is closed and oriented), the others shaded by Lambert's law from a fixed
light from a little above and left of the viewer (intensity 0.35 + 0.65 max(0, n . l)) and
painted back to front by the mean depth of their corners (the painter's algorithm). The
projection, culling, shading and depth sort are numpy on all faces at once; Pillow's
``ImageDraw.polygon`` draws the sorted faces one by one (docs/solid.md gives the time per
face). Like the 2D picture it is drawn at twice the size and reduced (antialiasing).
"""
import io
import math
from pathlib import Path

import numpy as np

from ..geometry.solid import face_keys
from .atomic import write_bytes
from .pictures import FRAGMENT_COLOURS, SUPERSAMPLING, RenderError, picture_pixels
from .solid_vtk import solid_arrays, solid_displacement

__all__ = ["surface_faces", "view_frame", "render_solid_png", "VIEW_AZIMUTH", "VIEW_ELEVATION"]

#: the fixed view of :func:`render_solid_png`, degrees
VIEW_AZIMUTH, VIEW_ELEVATION = 30.0, 25.0

#: the faces of a positively oriented tetrahedron (0, 1, 2, 3), normals out of it
_TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])

#: light direction in the view frame (right, up, towards the viewer), normalised where used
_LIGHT = np.array([-0.2, 0.45, 0.87])

#: colour factor of crack faces (a darker tone of the fragment's colour)
_CRACK_TONE = 0.6


def surface_faces(tets, nv, on_boundary=None):
    """The faces of tetrahedra that no other tetrahedron shares, oriented out of theirs.

    Parameters
    ----------
    tets : numpy.ndarray of int, shape (ne, 4)
        Positively oriented tetrahedra.
    nv : int
        Number of vertices (> every vertex number).
    on_boundary : numpy.ndarray of bool, shape (nv,), optional
        The vertices of the boundary faces, if known: only faces of three such vertices
        are looked at (every tetrahedron holding such a face has these three vertices,
        so the count of a face among them is its count among all). 25x faster on a
        structured box of 4.5 million tetrahedra.

    Returns
    -------
    faces : numpy.ndarray of int, shape (m, 3)
        (x1 - x0) x (x2 - x0) points out of the tetrahedron.
    owner : numpy.ndarray of int, shape (m,)
        The tetrahedron of every face.
    """
    tets = np.asarray(tets, dtype=np.int64)
    owner = np.arange(len(tets))
    if on_boundary is not None:
        owner = np.flatnonzero(on_boundary[tets].sum(axis=1) >= 3)
    faces = tets[owner][:, _TET_FACES].reshape(-1, 3)
    owner = np.repeat(owner, 4)
    if on_boundary is not None:
        keep = on_boundary[faces].all(axis=1)
        faces, owner = faces[keep], owner[keep]
    _, inverse, counts = np.unique(face_keys(faces, nv), return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    return faces[once], owner[once]


def view_frame(azimuth=VIEW_AZIMUTH, elevation=VIEW_ELEVATION):
    """The orthonormal frame of a view: right, up and towards the viewer.

    Parameters
    ----------
    azimuth, elevation : float
        Degrees; the viewer looks from (cos e cos a, cos e sin a, sin e).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Rows right, up, towards the viewer (a right-handed frame: right x up = towards).
    """
    a, e = math.radians(azimuth), math.radians(elevation)
    return np.array([[-math.sin(a), math.cos(a), 0.0],
                     [-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)],
                     [math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)]])


def _painted_faces(X, faces, base, frame):
    """Visible faces back to front and their shaded colours (0-255 integers)."""
    V = X @ frame.T                        # view coordinates: right, up, depth towards the viewer
    P = V[faces]                           # (m, 3 corners, 3)
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    length = np.linalg.norm(n, axis=1)
    visible = n[:, 2] > 0                  # facing the viewer (degenerate faces drop out too)
    light = _LIGHT / np.linalg.norm(_LIGHT)
    lambert = np.maximum(0.0, n[visible] @ light / length[visible])
    colour = np.clip(np.rint(base[visible] * (0.35 + 0.65 * lambert)[:, None]), 0, 255).astype(np.int64)
    order = np.argsort(P[visible][:, :, 2].mean(axis=1), kind="stable")     # far first
    return np.flatnonzero(visible)[order], colour[order], V


def _base_colours(a, faces, owner, fragment, crack_boundary):
    """The RGB of every surface face: its fragment's colour, darker on crack faces."""
    table = np.array([[int(c[i:i + 2], 16) for i in (1, 3, 5)] for c in FRAGMENT_COLOURS], dtype=float)
    base = table[fragment[owner] % len(table)]
    crack = a.boundary_faces(crack_boundary)
    if len(crack):
        nv = len(a.points)
        base[np.isin(face_keys(faces, nv), face_keys(crack, nv))] *= _CRACK_TONE
    return base


def render_solid_png(mesh, u, fragment, path, window_size=(1200, 900), scale=1.0, crack_boundary="crack",
                     force=False, azimuth=VIEW_AZIMUTH, elevation=VIEW_ELEVATION):
    """A PNG of the deformed tetrahedral mesh's surface, coloured by fragment and shaded.

    Parameters
    ----------
    mesh : ngsolve.Mesh or SolidArrays
        3D tetrahedral mesh, reference configuration.
    u : ngsolve.GridFunction or numpy.ndarray or None
        Displacement (nv, 3) (None: the reference configuration).
    fragment : array_like of int
        Fragment id per tetrahedron; 20 colours, cycled.
    path : str or pathlib.Path
        The PNG file; its folder must exist.
    window_size : (int, int)
        Width and height in pixels.
    scale : float
        Displacement magnification.
    crack_boundary : str
        Boundary name of the crack faces (drawn darker).
    force : bool
        Overwrite an existing file.
    azimuth, elevation : float
        The view, degrees (see :func:`view_frame`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    RenderError
        Pillow failed to draw or encode the picture (the message says how).
    ValueError
        ``fragment`` does not have one entry per tetrahedron, or a bad displacement.
    FileExistsError
        ``path`` exists and not ``force``.
    """
    path = Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"render_png: {path} exists; pass force=True to overwrite it")
    a = solid_arrays(mesh)
    fragment = np.asarray(fragment, dtype=np.int64).ravel()
    if fragment.shape != (len(a.tets),):
        raise ValueError(f"render_png: {fragment.size} fragment numbers for {len(a.tets)} tetrahedra")
    X = np.asarray(a.points, dtype=float)
    if u is not None:
        X = X + scale * solid_displacement(a, u)
    on_boundary = None
    if len(a.faces):
        on_boundary = np.zeros(len(X), dtype=bool)
        on_boundary[np.asarray(a.faces, dtype=np.int64).ravel()] = True
    faces, owner = surface_faces(a.tets, len(X), on_boundary)
    drawn, colour, V = _painted_faces(X, faces, _base_colours(a, faces, owner, fragment, crack_boundary),
                                      view_frame(azimuth, elevation))
    width, height = (int(w) for w in window_size)
    ss = SUPERSAMPLING
    pixels = picture_pixels(V[:, :2], width, height)
    try:
        from PIL import Image, ImageDraw
        image = Image.new("RGB", (ss * width, ss * height), "white")
        draw = ImageDraw.Draw(image)
        # outlines in the face colour: no white seams between the faces
        for corners, rgb in zip(pixels[faces[drawn]].reshape(-1, 6).tolist(), map(tuple, colour.tolist())):
            draw.polygon(corners, fill=rgb, outline=rgb)
        buf = io.BytesIO()
        image.reduce(ss).save(buf, format="PNG")
    except Exception as e:
        raise RenderError(f"ngfracture.output.solid_pictures: Pillow could not draw {path.name} "
                          f"({type(e).__name__}: {e})") from e
    write_bytes(path, buf.getvalue(), force)
    return path
