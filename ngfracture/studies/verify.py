"""Convergence studies against exact solutions (the L-shape of the paper, section 4.1).

``lshape_study`` solves the L-shape problem on a sequence of uniform or graded
meshes, measures relative L2 and energy-norm errors against eq. 15 and fits
the rates.  Two boundary-value problems share the exact solution:

``"dirichlet"``
    exact displacement on the whole boundary;
``"traction-free"``
    exact displacement on the outer edges, zero traction (natural) on the two
    reentrant edges, where the exact solution is traction-free.

Dirichlet data are put on the boundary dofs with NGSolve's ``Set(uex, BND)``,
a local L2 projection on the boundary edges whose vertex values are averaged
between neighbouring edges: it is *not* nodal interpolation.  With Dirichlet
data on the whole boundary the L2 error depends on this choice.  Measured
(uniform, h0 = 0.5, levels 3-5): for order 1 the L2 error with ``Set()`` is
0.66 to 0.55 times the one with ``Set(..., dual=True)`` (exact vertex values,
i.e. nodal interpolation for order 1), fitted L2 rate 1.42 against 1.30; for
order 2 it is 1.38 to 1.43 times larger (dual: vertex values and edge moments
exact).  Energy errors differ by at most 20% and their rate is alpha in both
cases (``solve_plain(..., dual=True)`` reproduces this; a test checks it).

The solvers: ``"plain"`` is a textbook NGSolve linear-elasticity solve (the
baseline of the benchmark), ``"ngfracture"`` goes through
``ngfracture.ElasticProblem``.
"""
import math
import time

import ngsolve as ng
import numpy as np

from . import lshape

VARIANTS = ("dirichlet", "traction-free")
MESHES = ("uniform", "graded")
MODELS = ("linear", "svk", "neohooke")
SOLVERS = ("plain", "ngfracture")
DEFAULT_SOLVER = "ngfracture"


def dirichlet_boundaries(variant):
    """Names of the boundaries carrying Dirichlet data in a variant, as a regex for NGSolve.

    Parameters
    ----------
    variant : {"dirichlet", "traction-free"}
        Boundary-value problem.

    Returns
    -------
    str
        ``"outer|reentrant"`` or ``"outer"``.

    Raises
    ------
    ValueError
        On an unknown variant.
    """
    if variant == "dirichlet":
        return "outer|reentrant"
    if variant == "traction-free":
        return "outer"
    raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")


def solve_plain(mesh, order, sol, variant="dirichlet", dual=False):
    """Plain NGSolve linear-elasticity solve of the L-shape problem (the baseline).

    ``BilinearForm`` of linear elasticity, ``gfu.Set(uex, BND)`` on the
    Dirichlet boundaries, sparse Cholesky on the free dofs, all inside
    ``TaskManager``.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        An L-shape mesh.
    order : int
        Polynomial order of the VectorH1 space.
    sol : lshape.LShapeSolution
        Exact solution (Dirichlet data and Lame parameters).
    variant : {"dirichlet", "traction-free"}
        Boundary-value problem.
    dual : bool
        Use ``Set(..., dual=True)`` (vertex values exact: nodal interpolation
        for order 1) instead of the default local L2 projection.

    Returns
    -------
    ngsolve.GridFunction
        The discrete displacement.
    """
    bnd = dirichlet_boundaries(variant)
    with ng.TaskManager():
        fes = ng.VectorH1(mesh, order=order, dirichlet=bnd)
        u, v = fes.TnT()
        a = ng.BilinearForm(fes, symmetric=True)
        a += ng.InnerProduct(sol.stress_of(u), ng.Sym(ng.Grad(v))) * ng.dx
        a.Assemble()
        gfu = ng.GridFunction(fes)
        gfu.Set(sol.u, ng.BND, definedon=mesh.Boundaries(bnd), dual=dual)
        inv = a.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky")
        res = (-a.mat * gfu.vec).Evaluate()
        gfu.vec.data += inv * res
    return gfu


def solve_ngfracture(mesh, order, sol, variant="dirichlet", model="linear", return_status=False):
    """The L-shape problem solved through ``ngfracture.ElasticProblem``.

    Modified Newton (the paper's scheme): for the linear model it converges in
    one iteration with the factorisation of the first.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        An L-shape mesh.
    order : int
        Polynomial order of the VectorH1 space.
    sol : lshape.LShapeSolution
        Exact solution (Dirichlet data and material parameters).
    variant : {"dirichlet", "traction-free"}
        Boundary-value problem.
    model : {"linear", "svk", "neohooke"}
        Material model (``ngfracture.make_material`` names).  Eq. 15 is exact
        for "linear" only; the hyperelastic models approach it in the
        small-strain limit (see ``lshape_study``).
    return_status : bool
        Also return the ``SolveStatus`` (iterations, timings per phase).

    Returns
    -------
    ngsolve.GridFunction or (ngsolve.GridFunction, SolveStatus)
        ``prob.u``, with the status if ``return_status``.

    Raises
    ------
    RuntimeError
        If the solve did not converge.
    """
    from ..mechanics.materials import make_material
    from ..mechanics.problem import ElasticProblem

    bnd = dirichlet_boundaries(variant)
    prob = ElasticProblem(mesh, make_material(model, sol.E, sol.nu, sol.plane), order=order)
    prob.add_dirichlet(bnd.split("|"), value=sol.u)
    status = prob.solve(method="modified", load_steps=1, tol=1e-10, maxit=30)
    if not status.converged:
        raise RuntimeError(f"ngfracture solve did not converge ({status.reason}) "
                           f"on a mesh with {mesh.nv} vertices, order {order}")
    return (prob.u, status) if return_status else prob.u


def fit_rate(h, err, last=3):
    """Rate ``k`` of ``err ~ h^k`` fitted by least squares in log-log over the last points.

    Parameters
    ----------
    h, err : sequence of float
        Mesh sizes and errors, coarse to fine.
    last : int
        Number of finest points used (all if fewer are given).

    Returns
    -------
    float or None
        The slope of ``np.polyfit(log h, log err, 1)``; None with fewer than two
        points or a non-positive error.
    """
    h, err = np.asarray(h, float)[-last:], np.asarray(err, float)[-last:]
    if len(h) < 2 or np.any(err <= 0) or np.any(h <= 0):
        return None
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


def _checked_study(order, levels, variant, model, mesh, gamma, solver):
    """The options of :func:`lshape_study` checked; returns the grading exponent to use."""
    lshape.check_int("order", order, 1)
    lshape.check_int("levels", levels, 2)
    dirichlet_boundaries(variant)
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if mesh not in MESHES:
        raise ValueError(f"mesh must be one of {MESHES}, got {mesh!r}")
    if solver not in SOLVERS:
        raise ValueError(f"solver must be one of {SOLVERS}, got {solver!r}")
    if solver == "plain" and model != "linear":
        raise ValueError(f"the plain NGSolve solve is linear elasticity only; model {model!r} "
                         "needs solver='ngfracture'")
    if mesh == "uniform":
        if gamma is not None and gamma != 1.0:
            raise ValueError("gamma is only used with mesh='graded'")
        gamma = 1.0
    elif gamma is None:
        gamma = lshape.default_grading(order)
    return gamma


def lshape_study(order, levels, variant="dirichlet", model="linear", mesh="uniform",
                 E=1e5, nu=0.3, h0=0.5, gamma=None, solver=DEFAULT_SOLVER, plane="strain"):
    """Convergence study of the L-shape problem (paper section 4.1, eq. 15).

    Parameters
    ----------
    order : int
        Polynomial order, >= 1.
    levels : int
        Number of meshes, >= 2: the coarse mesh and ``levels - 1`` uniform refinements.
    variant : {"dirichlet", "traction-free"}
        Dirichlet data on the whole boundary, or traction-free reentrant edges.
    model : {"linear", "svk", "neohooke"}
        Material model.  Eq. 15 is a linear-elastic solution: for the
        hyperelastic models the errors include a model error of the order of
        the strains, which scale like 1/E (relative L2 floor about 5e-6 at
        E = 1e5); they need ``solver="ngfracture"``.
    mesh : {"uniform", "graded"}
        Uniform refinements, or the same meshes graded toward the corner.
    E, nu : float
        Young's modulus and Poisson's ratio.
    h0 : float
        Maximal edge length of the coarse mesh.
    gamma : float, optional
        Grading exponent for ``mesh="graded"``; default ``lshape.default_grading(order)``.
    solver : {"plain", "ngfracture"}
        Plain NGSolve solve, or ``ngfracture.ElasticProblem``.
    plane : {"strain", "stress"}
        2D reduction.

    Returns
    -------
    dict
        ``{"problem": "lshape", "variant", "order", "model", "mesh", "gamma", "solver",
        "E", "nu", "alpha", "levels": [{"level", "ndof", "nverts", "h", "rel_l2",
        "rel_energy", "time_s"}, ...], "rates": {"l2", "energy"}}``.  ``h`` is the
        largest edge length, ``time_s`` the wall time of the solve (space, assembly,
        boundary data, factorisation), rates are fitted over the finest three levels.

    Raises
    ------
    ValueError
        On an unknown option or an out-of-range number.
    RuntimeError
        If ``solver="ngfracture"`` and the elasticity core is unavailable or fails.
    """
    gamma = _checked_study(order, levels, variant, model, mesh, gamma, solver)
    sol = lshape.LShapeSolution(E, nu, plane)
    rows = []
    for level, m in enumerate(lshape.mesh_hierarchy(levels, h0, gamma)):
        t0 = time.perf_counter()
        if solver == "plain":
            uh = solve_plain(m, order, sol, variant)
        else:
            uh = solve_ngfracture(m, order, sol, variant, model)
        elapsed = time.perf_counter() - t0
        rel_l2, rel_energy = lshape.relative_errors(m, uh, sol, order)
        rows.append({"level": level, "ndof": uh.space.ndof, "nverts": m.nv,
                     "h": lshape.max_edge_length(m), "rel_l2": rel_l2,
                     "rel_energy": rel_energy, "time_s": elapsed})
    h = [r["h"] for r in rows]
    return {"problem": "lshape", "variant": variant, "order": order, "model": model,
            "mesh": mesh, "gamma": gamma, "solver": solver, "E": E, "nu": nu,
            "alpha": sol.alpha, "levels": rows,
            "rates": {"l2": fit_rate(h, [r["rel_l2"] for r in rows]),
                      "energy": fit_rate(h, [r["rel_energy"] for r in rows])}}


def time_to_error(times, errors, target):
    """Time at which a sequence of runs reaches an error, by log-log interpolation.

    Between the two consecutive runs whose errors bracket ``target``,
    ``log t`` is interpolated linearly in ``log err``.  If no pair brackets it,
    the line through the two finest runs (target below every error) or the two
    coarsest runs (target above every error) is extrapolated.

    Parameters
    ----------
    times, errors : sequence of float
        Wall times and errors of the runs, coarse to fine (errors decreasing); > 0.
    target : float
        The error to reach, > 0.

    Returns
    -------
    (float, bool)
        The time, and whether it was extrapolated.

    Raises
    ------
    ValueError
        With fewer than two runs, non-positive values, or errors that do not decrease.
    """
    t = np.asarray(times, float)
    e = np.asarray(errors, float)
    if len(t) < 2 or len(t) != len(e):
        raise ValueError("time_to_error needs at least two runs with one time and one error each")
    if np.any(t <= 0) or np.any(e <= 0) or not target > 0:
        raise ValueError("times, errors and the target must be > 0")
    if np.any(np.diff(e) >= 0):
        raise ValueError(f"errors must decrease from run to run, got {list(e)}")
    lt, le, lg = np.log(t), np.log(e), math.log(target)
    for i in range(len(e) - 1):
        if e[i] >= target >= e[i + 1]:
            i0, extrapolated = i, False
            break
    else:
        i0, extrapolated = (len(e) - 2, True) if target < e[-1] else (0, True)
    s = (lg - le[i0]) / (le[i0 + 1] - le[i0])
    return float(math.exp(lt[i0] + s * (lt[i0 + 1] - lt[i0]))), extrapolated
