"""The L-shape manufactured solution of the paper (section 4.1, eq. 15).

Domain: the L-shape ``(-1, 1)^2`` minus ``[0, 1] x [-1, 0]``, with the
reentrant corner (interior angle ``2 omega = 3 pi / 2``) at the origin.  The
two edges that meet at the corner are the boundary ``"reentrant"``, the other
four edges are ``"outer"``.

Exact solution (eq. 15), in polar coordinates ``(r, theta)`` about the corner,
with ``theta`` measured from the bisector of the reentrant angle
(``theta = phi - 3 pi / 4``, ``phi`` the ordinary polar angle, so
``|theta| < omega`` in the domain)::

    u_r     = r^a / (2 mu) [-(a+1) cos((a+1) theta) + (C2 - (a+1)) C1 cos((a-1) theta)]
    u_theta = r^a / (2 mu) [ (a+1) sin((a+1) theta) + (C2 + a - 1) C1 sin((a-1) theta)]

``a = alpha`` solves ``alpha sin(2 omega) + sin(2 omega alpha) = 0``,
``C1 = -cos((alpha+1) omega) / cos((alpha-1) omega)`` and
``C2 = 2 (lambda + 2 mu) / (lambda + mu)``.  This is the symmetric (mode I)
corner singularity: ``div sigma = 0`` and ``sigma n = 0`` on the reentrant
edges (with the ordinary polar angle it is *not* traction-free there).  The
displacement is in ``H^{1+alpha-eps}`` only, ``sigma ~ r^(alpha-1)``.

Meshes
------
``mesh_hierarchy(levels, h0, gamma=1)``: a netgen mesh generated with
``maxh = h0`` refined ``level`` times (each refinement splits every triangle
into four), so ``h = h_coarse / 2^level``; netgen's maxh is a target, the
coarse mesh for ``h0 = 0.5`` has longest edge 0.72.

``mesh_hierarchy(levels, h0, gamma > 1)``: the same meshes mapped by ``x -> x rho^(gamma-1)`` with
``rho = max(|x|, |y|)``.  The L-shape is ``{rho <= 1}`` minus a quadrant, so
the map keeps every boundary edge on its line (rays through the corner and the
lines ``rho = 1``); the mesh size near the corner becomes
``h(r) ~ h r^(1 - 1/gamma)``.  Interpolation theory for a ``r^alpha`` singularity
gives the optimal energy rate ``h^p`` (``p`` the order) for
``gamma >= p / alpha``; we take ``gamma = 2`` for ``p = 1`` (``1/alpha = 1.84``)
and ``gamma = 4`` for ``p = 2`` (``2/alpha = 3.67``), see ``default_grading``.
The map stretches radially ``gamma`` times more than tangentially, so element
aspect ratios grow by a factor of about ``gamma`` at most.
"""
import math

import netgen.geom2d
import ngsolve as ng
import numpy as np

from ..mechanics.materials import lame_parameters

OMEGA = 3.0 * math.pi / 4.0
"""Half of the reentrant interior angle 3 pi / 2."""

BOUNDARIES = ("reentrant", "outer")


def singular_exponent(omega=OMEGA):
    """The exponent alpha of the mode-I corner singularity.

    Parameters
    ----------
    omega : float
        Half of the interior angle at the corner, ``pi/2 < omega < pi``.

    Returns
    -------
    float
        The root of ``alpha sin(2 omega) + sin(2 omega alpha) = 0`` in (0, 1), to
        full double precision (0.544483736782... for omega = 3 pi / 4).

    Raises
    ------
    ValueError
        If omega is not in (pi/2, pi) (then there is no singular root in (0, 1)).
    """
    from scipy.optimize import brentq   # here: scipy.optimize costs 0.2 s of every command's start

    if not math.pi / 2 < omega < math.pi:
        raise ValueError(f"omega must lie in (pi/2, pi), got {omega!r}")
    f = lambda a: a * math.sin(2.0 * omega) + math.sin(2.0 * omega * a)
    # f > 0 just above 0 (f'(0) = sin(2 omega) + 2 omega > 0) and f(1) = sin 2w + sin 2w < 0.
    return brentq(f, 1e-3, 1.0, xtol=1e-16, rtol=4.0 * np.finfo(float).eps, maxiter=200)


def constants(lam, mu, omega=OMEGA):
    """alpha, C1 and C2 of eq. 15.

    Parameters
    ----------
    lam, mu : float
        Lame parameters of the 2D model.
    omega : float
        Half of the reentrant angle.

    Returns
    -------
    (float, float, float)
        ``(alpha, C1, C2)`` with ``C1 = -cos((alpha+1) omega) / cos((alpha-1) omega)``
        and ``C2 = 2 (lambda + 2 mu) / (lambda + mu)``.
    """
    a = singular_exponent(omega)
    c1 = -math.cos((a + 1.0) * omega) / math.cos((a - 1.0) * omega)
    c2 = 2.0 * (lam + 2.0 * mu) / (lam + mu)
    return a, c1, c2


class LShapeSolution:
    """Exact displacement and stress of eq. 15 as NGSolve CoefficientFunctions.

    Parameters
    ----------
    E : float
        Young's modulus.
    nu : float
        Poisson's ratio.
    plane : {"strain", "stress"}
        2D reduction; it sets lambda and hence C2.

    Raises
    ------
    ValueError
        On invalid material parameters (``ngfracture.mechanics.materials.lame_parameters``).

    Attributes
    ----------
    lam, mu, alpha, C1, C2 : float
        Parameters of the solution.
    u : CoefficientFunction
        Displacement (2-vector).
    sigma : CoefficientFunction
        Cauchy stress (2x2), from the closed-form polar strains.
    """

    def __init__(self, E=1e5, nu=0.3, plane="strain"):
        self.E, self.nu, self.plane = E, nu, plane
        self.lam, self.mu = lame_parameters(E, nu, plane)
        self.alpha, self.C1, self.C2 = constants(self.lam, self.mu)
        self.u, self.sigma = self._build()

    def _build(self):
        a, c1, c2, lam, mu = self.alpha, self.C1, self.C2, self.lam, self.mu
        x, y = ng.x, ng.y
        beta = 3.0 * math.pi / 4.0  # direction of the bisector
        cb, sb = math.cos(beta), math.sin(beta)
        r = ng.sqrt(x * x + y * y)
        # Angle from the bisector: the branch cut of atan2 then points into the
        # removed quadrant (phi = -pi/4), never through the domain.
        th = ng.atan2(-sb * x + cb * y, cb * x + sb * y)
        # cos and sin of the ordinary polar angle phi = theta + beta; not x/r, so that
        # u is finite (zero) at the corner itself (Set(..., dual=True) evaluates there).
        cp, sp = ng.cos(th + beta), ng.sin(th + beta)
        ap, am = a + 1.0, a - 1.0
        kp, km = (c2 - ap) * c1, (c2 + am) * c1
        f = -ap * ng.cos(ap * th) + kp * ng.cos(am * th)
        g = ap * ng.sin(ap * th) + km * ng.sin(am * th)
        df = ap * ap * ng.sin(ap * th) - kp * am * ng.sin(am * th)
        dg = ap * ap * ng.cos(ap * th) + km * am * ng.cos(am * th)
        s = 1.0 / (2.0 * mu)
        ra = r**a
        ur, ut = s * ra * f, s * ra * g
        u = ng.CF((cp * ur - sp * ut, sp * ur + cp * ut))
        # Polar strains of u = r^a (f, g) / (2 mu):
        # e_rr = u_r,r ; e_tt = (u_r + u_t,theta) / r ; e_rt = (u_r,theta / r + u_t,r - u_t / r) / 2
        ram1 = r**am
        err = s * a * ram1 * f
        ett = s * ram1 * (f + dg)
        ert = 0.5 * s * ram1 * (df + am * g)
        tr = err + ett
        srr = lam * tr + 2.0 * mu * err
        stt = lam * tr + 2.0 * mu * ett
        srt = 2.0 * mu * ert
        # Rotate to Cartesian: sigma = Q sigma_polar Q^T, Q = [e_r | e_theta].
        sxx = cp * cp * srr - 2.0 * cp * sp * srt + sp * sp * stt
        syy = sp * sp * srr + 2.0 * cp * sp * srt + cp * cp * stt
        sxy = cp * sp * (srr - stt) + (cp * cp - sp * sp) * srt
        sigma = ng.CF((sxx, sxy, sxy, syy), dims=(2, 2))
        return u, sigma

    def stress_of(self, v):
        """Linear-elastic stress ``lambda tr(eps) I + 2 mu eps`` with this solution's Lame parameters.

        Parameters
        ----------
        v : ngsolve.GridFunction, trial/test function or CoefficientFunction
            A displacement (anything with ``ng.Grad``).

        Returns
        -------
        ngsolve.CoefficientFunction
            2x2 stress.
        """
        return linear_stress(v, self.lam, self.mu)


def linear_stress(v, lam, mu):
    """Linear-elastic Cauchy stress ``lambda tr(eps) I + 2 mu eps`` of a displacement.

    Parameters
    ----------
    v : ngsolve.GridFunction, trial/test function or CoefficientFunction
        A displacement (anything with ``ng.Grad``).
    lam, mu : float
        Lame parameters of the 2D model.

    Returns
    -------
    ngsolve.CoefficientFunction
        2x2 stress, eps = sym(grad v).
    """
    eps = ng.Sym(ng.Grad(v))
    return lam * ng.Trace(eps) * ng.Id(2) + 2.0 * mu * eps


def geometry():
    """The L-shape as a netgen 2D spline geometry.

    Returns
    -------
    netgen.geom2d.SplineGeometry
        Counter-clockwise polygon (0,0), (1,0), (1,1), (-1,1), (-1,-1), (0,-1);
        edges at the corner named ``"reentrant"``, the others ``"outer"``.
    """
    geo = netgen.geom2d.SplineGeometry()
    pts = [(0, 0), (1, 0), (1, 1), (-1, 1), (-1, -1), (0, -1)]
    names = ["reentrant", "outer", "outer", "outer", "outer", "reentrant"]
    ids = [geo.AppendPoint(*p) for p in pts]
    for i, name in enumerate(names):
        geo.Append(["line", ids[i], ids[(i + 1) % len(ids)]], bc=name, leftdomain=1, rightdomain=0)
    return geo


def default_grading(order):
    """Grading exponent gamma for a mesh of polynomial order ``order``.

    ``gamma >= order / alpha`` (alpha = 0.5445) restores the energy rate
    ``h^order``; we round ``order / alpha`` up to the next integer: 2 for
    ``order = 1``, 4 for ``order = 2``, and ``ceil(order / alpha)`` beyond.

    Parameters
    ----------
    order : int
        Polynomial order, >= 1.

    Returns
    -------
    float
        gamma.

    Raises
    ------
    ValueError
        If order is not an integer >= 1.
    """
    check_int("order", order, 1)
    return float(math.ceil(order / singular_exponent()))


def check_int(name, value, minimum):
    """Refuse anything but an integer >= ``minimum`` (bools too), naming it.

    Parameters
    ----------
    name : str
        The value's name in the message.
    value : object
    minimum : int

    Raises
    ------
    ValueError
        Not an integer, or below ``minimum``.
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")


def _check_h0(h0):
    if not (isinstance(h0, (int, float)) and math.isfinite(h0) and 0.0 < h0 <= 2.0):
        raise ValueError(f"coarse mesh size h0 must be a number in (0, 2], got {h0!r}")


def grade(ngmesh, gamma):
    """Map the points of a netgen L-shape mesh in place by ``x -> x rho^(gamma-1)``.

    Parameters
    ----------
    ngmesh : netgen.meshing.Mesh
        A mesh of the L-shape (modified in place).
    gamma : float
        Grading exponent, >= 1 (1 leaves the mesh unchanged).

    Raises
    ------
    ValueError
        If gamma < 1 or not finite.
    """
    if not (isinstance(gamma, (int, float)) and math.isfinite(gamma) and gamma >= 1.0):
        raise ValueError(f"grading exponent gamma must be a finite number >= 1, got {gamma!r}")
    xy = ngmesh.Coordinates()  # writable view into the mesh
    rho = np.max(np.abs(xy), axis=1)
    xy[:] = xy * (rho ** (gamma - 1.0))[:, None]


def mesh_hierarchy(levels, h0=0.5, gamma=1.0):
    """Yield the meshes of levels 0 .. levels-1 of the L-shape.

    Level ``l`` is the coarse netgen mesh (max edge ``h0``) refined ``l`` times
    uniformly, then graded with ``gamma`` (``gamma = 1``: uniform).

    Parameters
    ----------
    levels : int
        Number of meshes, >= 1.
    h0 : float
        Maximal edge length of the coarse mesh, in (0, 2].
    gamma : float
        Grading exponent, >= 1.

    Yields
    ------
    ngsolve.Mesh
        The mesh of each level, coarse to fine.

    Raises
    ------
    ValueError
        On bad ``levels``, ``h0`` or ``gamma``.
    """
    check_int("levels", levels, 1)
    _check_h0(h0)
    if not (isinstance(gamma, (int, float)) and math.isfinite(gamma) and gamma >= 1.0):
        raise ValueError(f"grading exponent gamma must be a finite number >= 1, got {gamma!r}")
    ngmesh = geometry().GenerateMesh(maxh=h0)
    for level in range(levels):
        if level > 0:
            ngmesh.Refine()  # the uniform (unmapped) mesh is refined, then copied and mapped
        m = ngmesh.Copy()
        if gamma != 1.0:
            grade(m, gamma)
        yield ng.Mesh(m)


def lshape_mesh(level=0, h0=0.5, gamma=1.0):
    """The L-shape mesh of one level (see ``mesh_hierarchy``).

    Parameters
    ----------
    level : int
        Number of uniform refinements of the coarse mesh, >= 0.
    h0 : float
        Maximal edge length of the coarse mesh.
    gamma : float
        Grading exponent (1: uniform).

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    ValueError
        On bad ``level``, ``h0`` or ``gamma``.
    """
    check_int("level", level, 0)
    mesh = None
    for mesh in mesh_hierarchy(level + 1, h0, gamma):
        pass
    return mesh


def max_edge_length(mesh):
    """Largest edge length of a 2D ngsolve mesh (the ``h`` of the convergence tables).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D mesh.

    Returns
    -------
    float
        The longest edge, in the units of the coordinates.
    """
    xy = np.array([v.point for v in mesh.vertices])
    ev = np.array([[v.nr for v in e.vertices] for e in mesh.edges])
    return float(np.max(np.linalg.norm(xy[ev[:, 0]] - xy[ev[:, 1]], axis=1)))


def relative_errors(mesh, uh, sol, order):
    """Relative L2 and energy-norm errors of a discrete displacement.

    The energy error uses ``|u - uh|_a^2 = a(u,u) - 2 a(u,uh) + a(uh,uh)``
    with ``a(u, v) = int_dOmega sigma(u) n . v ds`` for the exact ``u``
    (``div sigma(u) = 0``), so the singular volume integrand at the corner is
    never sampled; ``a(uh, uh)`` is a polynomial integral done exactly.  The L2
    error uses quadrature of order ``2 order + 6``.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        The L-shape mesh of ``uh``.
    uh : ngsolve.GridFunction
        Discrete displacement (VectorH1).
    sol : LShapeSolution
        The exact solution, whose Lame parameters define ``a``.
    order : int
        Polynomial order of ``uh`` (sets the quadrature orders).

    Returns
    -------
    (float, float)
        ``(rel_l2, rel_energy)``: ``||u-uh||_L2 / ||u||_L2`` and ``|u-uh|_a / |u|_a``.
    """
    n = ng.specialcf.normal(2)
    tn = sol.sigma * n
    qb = 2 * order + 10  # smooth integrand on the outer edges, zero on the reentrant ones
    auu = ng.Integrate(ng.InnerProduct(tn, sol.u), mesh, ng.BND, order=qb)
    auh = ng.Integrate(ng.InnerProduct(tn, uh), mesh, ng.BND, order=qb)
    ahh = ng.Integrate(ng.InnerProduct(sol.stress_of(uh), ng.Sym(ng.Grad(uh))), mesh, order=2 * order)
    e2 = auu - 2.0 * auh + ahh
    # e2 is a difference of O(1) terms: rounding can leave it slightly negative at tiny errors.
    rel_energy = math.sqrt(max(e2, 0.0) / auu)
    diff = sol.u - uh
    q = 2 * order + 6
    l2 = ng.Integrate(ng.InnerProduct(diff, diff), mesh, order=q)
    l2u = ng.Integrate(ng.InnerProduct(sol.u, sol.u), mesh, order=q)
    return math.sqrt(l2 / l2u), rel_energy
