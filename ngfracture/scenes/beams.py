"""Beams in three-point bending: the notched beam (SENB) and a beam with an offset notch and a hole."""
import math

import ngsolve as ng
from netgen.geom2d import SplineGeometry
from netgen.meshing import MeshingParameters, Pnt

from ..mechanics.materials import StVenantKirchhoff
from ..run.scene import Scene
from .common import BEAM_LOAD, GLASS, positive


def senb_factor(alpha):
    """The SENB geometry factor f(a/W) of a beam of span 4W (Srawley 1976; 0.5 % for any a/W).

    K_I = P S / (B W^(3/2)) f(a/W) for the load P at mid-span, the span S = 4 W.

    Parameters
    ----------
    alpha : float
        a / W in [0, 1).

    Returns
    -------
    float
    """
    a = float(alpha)
    return (3 * math.sqrt(a) * (1.99 - a * (1 - a) * (2.15 - 3.93 * a + 2.7 * a * a))
            / (2 * (1 + 2 * a) * (1 - a) ** 1.5))


def notched_beam_mesh(maxh=0.1, fine=0.01, notch=0.3, span=4.0, overhang=0.2, pad=0.05):
    """A beam of height 1 with a V-notch in the middle of its bottom edge (three-point bending).

    Boundaries: ``support_left``, ``support_right`` (short segments of width ``pad`` at the
    supports), ``load`` (the pad at mid-span on top), ``notch``, ``surface`` (the rest).
    Regions: ``ligament`` (a band of width 1 around the notch, where cracks may run) and
    ``beam``. The mesh is ``fine`` along the line above the notch and around its tip.

    Parameters
    ----------
    maxh, fine : float
        Mesh size, and the size along the crack's path.
    notch : float
        Notch depth a / W (its opening is a tenth of ``fine`` ... a fifth of the depth).
    span, overhang, pad : float
        Distance between the supports, the beam beyond them, the width of supports and pad.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        Sizes that are not finite positive numbers, or a notch that does not fit.
    """
    for name, v in (("maxh", maxh), ("fine", fine), ("notch", notch), ("span", span), ("pad", pad)):
        positive(name, v)
    if not notch < 0.8:
        raise ValueError(f"notch must be a / W < 0.8, got {notch!r}")
    length = span + 2 * overhang
    c, w, half = length / 2, min(0.2 * notch, 0.01), 0.5
    geo = SplineGeometry()
    pts = [(0, 0), (overhang - pad / 2, 0), (overhang + pad / 2, 0), (c - half, 0), (c - w / 2, 0), (c, notch),
           (c + w / 2, 0), (c + half, 0), (length - overhang - pad / 2, 0), (length - overhang + pad / 2, 0),
           (length, 0), (length, 1), (c + half, 1), (c + pad / 2, 1), (c - pad / 2, 1), (c - half, 1), (0, 1)]
    P = [geo.AppendPoint(x, y, maxh=fine) if (x, y) == (c, notch) else geo.AppendPoint(x, y) for x, y in pts]
    # (start, end, boundary, region on the left): the ligament band is region 2
    edges = [(0, 1, "surface", 1), (1, 2, "support_left", 1), (2, 3, "surface", 1), (3, 4, "surface", 2),
             (4, 5, "notch", 2), (5, 6, "notch", 2), (6, 7, "surface", 2), (7, 8, "surface", 1),
             (8, 9, "support_right", 1), (9, 10, "surface", 1), (10, 11, "surface", 1), (11, 12, "surface", 1),
             (12, 13, "surface", 2), (13, 14, "load", 2), (14, 15, "surface", 2), (15, 16, "surface", 1),
             (16, 0, "surface", 1)]
    for a, b, name, left in edges:
        geo.Append(["line", P[a], P[b]], bc=name, leftdomain=left, rightdomain=0)
    geo.Append(["line", P[3], P[15]], bc="band", leftdomain=1, rightdomain=2)
    geo.Append(["line", P[7], P[12]], bc="band", leftdomain=2, rightdomain=1)
    geo.SetMaterial(1, "beam")
    geo.SetMaterial(2, "ligament")
    mp = MeshingParameters(maxh=maxh)
    mp.RestrictHLine(p1=Pnt(c, notch, 0), p2=Pnt(c, 1, 0), maxh=fine)
    return ng.Mesh(geo.GenerateMesh(mp=mp))


def beam(maxh=0.1, radius=0.04, notch=0.3, deflection_max=None, dx=None, E=GLASS["E"], nu=GLASS["nu"],
         critical=GLASS["critical"]):
    """A notched glass beam in three-point bending (SENB), pressed down at mid-span.

    Span 4, height 1, a V-notch of depth ``notch`` under the load; the beam rests on two
    short supports (u_y = 0, the left one also u_x = 0) and a pad on its top is moved
    down by x. Cracks may run in the band of width 1 above the notch (the rest never
    cracks: no spurious cracks at the supports and the pad). The crack grows one event per
    load step at the load that makes it critical (StepControl growth "critical"), so the
    load-displacement curve (force_displacement.png) is followed through its peak and its
    descending branch; its peak is the LEFM load P = K_c W^(3/2) / (S f(a/W)) with the
    criterion's toughness K_c = E critical sqrt(2 pi radius) (:func:`senb_factor`).

    Parameters
    ----------
    maxh : float
        Mesh size away from the crack's path (radius / 4 along it).
    radius : float
        Critical distance.
    notch : float
        Notch depth a / W.
    deflection_max : float, optional
        The final deflection; default eight times the LEFM deflection at the peak by beam theory.
    dx : float, optional
        First increment; default an eighth of that deflection.
    E, nu, critical : float
        The glass (St Venant-Kirchhoff, plane stress) and its critical strain.

    Returns
    -------
    Scene
    """
    maxh, radius = positive("maxh", maxh), positive("radius", radius)
    fine = min(maxh, radius / 4)
    mesh = notched_beam_mesh(maxh, fine, notch)
    material = StVenantKirchhoff(E, nu, plane="stress")
    peak = E * critical * math.sqrt(2 * math.pi * radius) / (4 * senb_factor(notch))
    deflection_max, dx = _pad_travel(peak, E, deflection_max, dx)

    return Scene(name="beam", mesh=mesh, material=material, critical={"ligament": critical},
                 apply_load=three_point_bending,
                 load_max=deflection_max, dx=dx, contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius,
                 load_description=BEAM_LOAD, control={"growth": "critical", "max_steps": 1000},
                 parameters={"maxh": maxh, "radius": radius, "notch": notch, "deflection_max": deflection_max, "dx": dx,
                             "E": E, "nu": nu, "critical": critical, "lefm_peak_load": peak})


def holed_beam_mesh(maxh=0.1, fine=0.01, notch=0.2, notch_offset=0.5, holes=((-0.22, 0.5, 0.08),), span=4.0,
                    overhang=0.2, pad=0.05):
    """A beam of height 1 with a V-notch off mid-span and holes, for three-point bending.

    Boundaries as :func:`notched_beam_mesh`, and ``hole``. Regions: ``band`` (between the
    notch and the pad, meshed at ``fine``: where a crack from the notch runs) and ``beam``.

    Parameters
    ----------
    maxh, fine : float
        Mesh size, and the size in the band.
    notch : float
        Notch depth a / W.
    notch_offset : float
        Distance of the notch from mid-span (to the left).
    holes : sequence of (x, y, radius)
        Holes, x measured from mid-span; each lies wholly inside the band or wholly outside it.
    span, overhang, pad : float
        As :func:`notched_beam_mesh`.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        Sizes that are not finite positive numbers, a notch or a hole that does not fit.
    """
    for name, v in (("maxh", maxh), ("fine", fine), ("notch", notch), ("span", span), ("pad", pad)):
        positive(name, v)
    c = span / 2 + overhang
    mouth = c - float(notch_offset)
    if not (notch < 0.8 and overhang + 0.3 <= mouth <= c):
        raise ValueError(f"notch must be a / W < 0.8 and notch_offset in [0, {span / 2 - 0.3}], got {notch!r}, "
                         f"{notch_offset!r}")
    w = min(0.2 * notch, 0.01)
    # the band: 0.3 wide at the notch, from left of the notch to right of the pad at the top
    bl, br, tl, tr = mouth - 0.15, mouth + 0.15, mouth - 0.05, c + 0.15
    geo = SplineGeometry()
    pts = [(0, 0), (overhang - pad / 2, 0), (overhang + pad / 2, 0), (bl, 0), (mouth - w / 2, 0), (mouth, notch),
           (mouth + w / 2, 0), (br, 0), (c + span / 2 - pad / 2, 0), (c + span / 2 + pad / 2, 0), (2 * c, 0),
           (2 * c, 1), (tr, 1), (c + pad / 2, 1), (c - pad / 2, 1), (tl, 1), (0, 1)]
    P = [geo.AppendPoint(x, y) for x, y in pts]
    names = ["surface", "support_left", "surface", "surface", "notch", "notch", "surface", "surface", "support_right",
             "surface", "surface", "surface", "surface", "load", "surface", "surface", "surface"]
    in_band = {3, 4, 5, 6, 12, 13, 14}
    for i, name in enumerate(names):
        geo.Append(["line", P[i], P[(i + 1) % len(P)]], bc=name, leftdomain=2 if i in in_band else 1, rightdomain=0)
    geo.Append(["line", P[3], P[15]], bc="band", leftdomain=1, rightdomain=2)
    geo.Append(["line", P[7], P[12]], bc="band", leftdomain=2, rightdomain=1)
    for k, hole in enumerate(holes):
        x, y, r = float(hole[0]) + c, float(hole[1]), positive(f"holes[{k}] radius", hole[2])
        left, right = bl + (tl - bl) * y, br + (tr - br) * y          # the band's sides at height y
        inside = left + r < x < right - r
        if not (r < y < 1 - r and r < x < 2 * c - r) or not (inside or x + r < left or x - r > right) \
                or (inside and y - r < notch + 0.05):
            raise ValueError(f"holes[{k}] = {tuple(hole)} does not lie inside the beam, clear of the notch and of "
                             f"the band's sides (x {left - c:.3f} .. {right - c:.3f} from mid-span at y = {y})")
        for j, other in enumerate(holes[:k]):
            if math.hypot(x - c - float(other[0]), y - float(other[1])) <= r + float(other[2]):
                raise ValueError(f"holes[{k}] = {tuple(hole)} overlaps holes[{j}] = {tuple(other)}")
        geo.AddCircle((x, y), r, leftdomain=0, rightdomain=2 if inside else 1, bc="hole")
    geo.SetMaterial(1, "beam")
    geo.SetMaterial(2, "band")
    geo.SetDomainMaxH(2, fine)
    return ng.Mesh(geo.GenerateMesh(mp=MeshingParameters(maxh=maxh)))


def holed_beam(maxh=0.1, fine=None, radius=0.04, notch=0.2, notch_offset=0.5, holes=((-0.22, 0.5, 0.08),),
               deflection_max=None, dx=None, E=GLASS["E"], nu=GLASS["nu"], critical=GLASS["critical"]):
    """A glass beam in three-point bending with its notch off mid-span and a hole beside the crack's path.

    The beam of :func:`beam` (span 4, height 1, pressed down at mid-span by x), with the
    notch ``notch_offset`` to the left of the load: the crack grows in mixed mode and curves
    towards the pad, past the hole (by default 0.13 from the path that LEFM predicts). It
    may run anywhere in the band between the notch and the pad (:func:`holed_beam_mesh`),
    meshed at ``fine``; the hole may crack too. The crack grows one split per equilibrium at
    the step's load (StepControl growth "fixed", split "one"): in a body that stays linear
    elastic the order of the overstrained vertices does not change with the load's size, so
    this grows the same path as growth "critical" (one event per load step at its critical
    load, as :func:`beam`: the load-displacement curve through the peak) at a fifth of the
    cost (docs/criterion.md, "Crack paths in bending and past holes").

    Parameters
    ----------
    maxh : float
        Mesh size outside the band.
    fine : float, optional
        Mesh size in the band; default radius / 4.
    radius : float
        Critical distance.
    notch, notch_offset, holes
        As :func:`holed_beam_mesh`.
    deflection_max : float, optional
        The final deflection; default eight times the peak's by beam theory (the SENB load
        of :func:`beam` raised by the lower bending moment at the notch).
    dx : float, optional
        First increment; default an eighth of the peak's deflection.
    E, nu, critical : float
        The glass (St Venant-Kirchhoff, plane stress) and its critical strain.

    Returns
    -------
    Scene
    """
    maxh, radius = positive("maxh", maxh), positive("radius", radius)
    fine = min(maxh, radius / 4) if fine is None else positive("fine", fine)
    mesh = holed_beam_mesh(maxh, fine, notch, notch_offset, holes)
    peak = E * critical * math.sqrt(2 * math.pi * radius) / (4 * senb_factor(notch)) * 2 / (2 - notch_offset)
    deflection_max, dx = _pad_travel(peak, E, deflection_max, dx)
    return Scene(name="holed_beam", mesh=mesh, material=StVenantKirchhoff(E, nu, plane="stress"),
                 critical={"band": critical}, apply_load=three_point_bending, load_max=deflection_max, dx=dx,
                 contact_tol=1e-3 * fine, stop_when_unloaded=True, radius=radius, load_description=BEAM_LOAD,
                 control={"growth": "fixed", "max_steps": 1000},
                 parameters={"maxh": maxh, "fine": fine, "radius": radius, "notch": notch,
                             "notch_offset": notch_offset, "holes": [list(h) for h in holes],
                             "deflection_max": deflection_max, "dx": dx, "E": E, "nu": nu, "critical": critical})


def _pad_travel(peak, E, deflection_max, dx):
    """The final deflection (default eight times the peak load's) and the first increment
    (default an eighth of the peak's) of a beam of span 4 and height 1 in three-point bending."""
    # beam theory: delta = P S^3 / (48 E I), I = 1/12; the notch and shear add to it
    deflection = 16 * peak / E
    deflection_max = 8 * deflection if deflection_max is None else positive("deflection_max", deflection_max)
    dx = deflection / 8 if dx is None else positive("dx", dx)
    return deflection_max, dx


def three_point_bending(prob, x):
    """The supports and the pad of :func:`beam` and :func:`holed_beam`: the pad moved down by x.

    Parameters
    ----------
    prob : ElasticProblem
    x : float
        The pad's downward displacement.
    """
    prob.add_dirichlet("support_left", (0.0, 0.0))
    prob.add_dirichlet("support_right", 0.0, component="y")
    prob.add_dirichlet("load", -x, component="y")

