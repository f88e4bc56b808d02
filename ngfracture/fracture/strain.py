"""Fields of a displacement on a triangle mesh: vertex values, strain, stress over E.

The quantities the crack criterion and the outputs share, for the P1 interpolant of the
vertex displacements (or the element mean for order >= 2 fields). Tensors are stored as
rows (xx, yy, xy), xy the tensor (not engineering) shear. Nodal values are area-weighted
averages of the element values around each vertex (sum |T| E_T / sum |T|).

These are the 2D (triangle) kernels of the fracture layer; :func:`check_mesh_2d` refuses
other meshes by name.
"""
import math

import numpy as np
import ngsolve

from .. import _ngfracture as _ext

__all__ = ["check_positive", "check_mesh_2d", "displacement_order", "vertex_displacement",
           "element_strain", "vertex_strain", "equivalent_strain", "principal"]


def check_positive(critical, what="critical strain"):
    """A finite number > 0 as a float, or a ValueError naming ``what``.

    Parameters
    ----------
    critical : object
        The value to check.
    what : str
        Its name in the error message.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        If it is not a number, not finite or not > 0.
    """
    try:
        c = float(critical)
    except (TypeError, ValueError):
        raise ValueError(f"ngfracture.fracture.strain: {what} must be a number, got {critical!r}") from None
    if not math.isfinite(c) or c <= 0:
        raise ValueError(f"ngfracture.fracture.strain: {what} must be finite and > 0, got {critical!r}")
    return c


def check_mesh_2d(mesh):
    """Refuse anything but a 2D ``ngsolve.Mesh`` (the kernels here are for triangles).

    Parameters
    ----------
    mesh : object

    Raises
    ------
    TypeError
        If it is not an ``ngsolve.Mesh``.
    ValueError
        If its dimension is not 2.
    """
    if not isinstance(mesh, ngsolve.Mesh):
        raise TypeError(f"ngfracture.fracture.strain: expected an ngsolve.Mesh, got {type(mesh).__name__}")
    if mesh.dim != 2:
        raise ValueError(f"ngfracture.fracture.strain: the mesh must be 2D, it has dimension {mesh.dim}")


def displacement_order(gf):
    """The polynomial order of a displacement GridFunction on a 2D ``VectorH1`` space.

    Parameters
    ----------
    gf : ngsolve.GridFunction

    Returns
    -------
    int

    Raises
    ------
    TypeError
        If its space is not a 2D ``VectorH1``.
    """
    fes = gf.space
    if not isinstance(fes, ngsolve.VectorH1) or fes.mesh.dim != 2:
        raise TypeError("ngfracture.fracture.strain: the displacement must be a GridFunction on a 2D "
                        f"ngsolve.VectorH1 space, got {type(fes).__name__}")
    return fes.globalorder


def vertex_displacement(u):
    """Vertex values of a displacement field.

    Parameters
    ----------
    u : ngsolve.GridFunction or numpy.ndarray
        A GridFunction on ``VectorH1`` of a 2D or 3D mesh (vertex dofs are nodal values for
        every order), or an array of shape (nv, 2) or (nv, 3) that is returned as a float copy.

    Returns
    -------
    numpy.ndarray
        Shape (nv, dim).

    Raises
    ------
    TypeError
        If u is neither.
    """
    if isinstance(u, ngsolve.GridFunction):
        if not isinstance(u.space, ngsolve.VectorH1):
            raise TypeError("ngfracture.fracture.strain: the displacement must be a GridFunction on an "
                            f"ngsolve.VectorH1 space, got {type(u.space).__name__}")
        dim, nv = u.space.mesh.dim, u.space.mesh.nv
        v = u.vec.FV().NumPy()
        return v.reshape(dim, -1)[:, :nv].T.copy()   # component-blocked dofs, vertices first
    a = np.array(u, dtype=float)
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise TypeError(f"ngfracture.fracture.strain: vertex displacement must have shape (nv, 2) or (nv, 3), got {a.shape}")
    return a


def _vertex_values(mesh, u):
    """The displacement's vertex values (nv, dim), checked to fit the mesh and to be finite."""
    U = vertex_displacement(u)
    if U.shape != (mesh.nv, mesh.dim):
        raise ValueError(f"ngfracture.fracture.strain: displacement has {U.shape[0]} vertex values of {U.shape[1]} "
                         f"components, the mesh has {mesh.nv} vertices in {mesh.dim}D")
    if not np.all(np.isfinite(U)):
        raise ValueError("ngfracture.fracture.strain: displacement has NaN or inf values")
    return U


def element_strain(mesh, u, measure="green"):
    """Strain of every triangle (the P1 gradient, or the element mean for order >= 2).

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh (reference configuration).
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement: a ``VectorH1`` GridFunction of any order, or vertex values (nv, 2).
        For order 1 and for arrays the element strain is that of the P1 interpolant of
        the vertex values (C++); for order >= 2 it is the element mean of E(u).
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H)/2 or small strain (H + H^T)/2, H = grad u.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 3), rows (xx, yy, xy).

    Raises
    ------
    ValueError
        Non-2D mesh, unknown measure or a field that does not fit the mesh.
    """
    check_mesh_2d(mesh)
    if measure not in ("green", "linear"):
        raise ValueError(f"ngfracture.fracture.strain: measure must be 'green' or 'linear', got {measure!r}")
    if isinstance(u, ngsolve.GridFunction) and displacement_order(u) > 1:
        if u.space.mesh.nv != mesh.nv or u.space.mesh.ne != mesh.ne:
            raise ValueError("ngfracture.fracture.strain: the displacement lives on another mesh")
        H = ngsolve.Grad(u)
        E = 0.5 * (H + H.trans)
        if measure == "green":
            E = E + 0.5 * H.trans * H
        area = ngsolve.Integrate(ngsolve.CF(1), mesh, element_wise=True).NumPy()
        comps = [E[0, 0], E[1, 1], E[0, 1]]
        return np.column_stack([ngsolve.Integrate(c, mesh, element_wise=True).NumPy() / area
                                for c in comps])
    return _ext.CrackElementStrain(mesh, _vertex_values(mesh, u), measure)


def vertex_strain(mesh, u, measure="green"):
    """Nodal strain tensor: area-weighted average of the element strains around each vertex.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh (reference configuration).
    u : ngsolve.GridFunction or numpy.ndarray
        Displacement, see :func:`element_strain`.
    measure : {'green', 'linear'}
        Green-Lagrange (H + H^T + H^T H)/2 or small strain (H + H^T)/2, H = grad u.

    Returns
    -------
    numpy.ndarray
        Shape (nv, 3), rows (xx, yy, xy).

    Raises
    ------
    ValueError
        Non-2D mesh, unknown measure or a field that does not fit the mesh.
    """
    check_mesh_2d(mesh)
    if isinstance(u, ngsolve.GridFunction) and displacement_order(u) > 1:
        return _ext.VertexAverage(mesh, element_strain(mesh, u, measure))
    if measure not in ("green", "linear"):
        raise ValueError(f"ngfracture.fracture.strain: measure must be 'green' or 'linear', got {measure!r}")
    return _ext.CrackVertexStrain(mesh, _vertex_values(mesh, u), measure)


def equivalent_strain(mesh, strain, material):
    """Stress divided by Young's modulus, per triangle: the strain a uniaxial test would show.

    For a 2D material with Lame parameters (lambda, mu) of its plane reduction,
    ``(lambda tr(E) I + 2 mu E) / E_young``. Under uniaxial stress it equals the principal
    strain along the load, so a critical strain keeps its meaning; its opening component
    is the hoop stress of the maximum-hoop-stress rule (docs/criterion.md). For
    St Venant-Kirchhoff and linear materials this is the (second Piola-Kirchhoff) stress
    over E exactly.

    Parameters
    ----------
    mesh : ngsolve.Mesh
        2D triangle mesh.
    strain : numpy.ndarray
        Shape (ne, 3), element strains (xx, yy, xy).
    material : Material or dict of str -> Material
        One material, or one per region of the mesh.

    Returns
    -------
    numpy.ndarray
        Shape (ne, 3).

    Raises
    ------
    ValueError
        If a region of the mesh has no material or the shape is wrong.
    """
    e = np.asarray(strain, dtype=float)
    if e.shape != (mesh.ne, 3):
        raise ValueError(f"ngfracture.fracture.strain: element strains must have shape ({mesh.ne}, 3), got {e.shape}")
    names = list(mesh.GetMaterials())
    mats = material if isinstance(material, dict) else {n: material for n in names}
    missing = [n for n in names if n not in mats]
    if missing:
        raise ValueError(f"ngfracture.fracture.strain: no material for regions {missing}")
    region = mesh.ngmesh.Elements2D().NumPy()["index"].astype(int) - 1   # netgen counts regions from 1
    lam = np.array([mats[n].lam / mats[n].E for n in names])[region]
    two_mu = np.array([2 * mats[n].mu / mats[n].E for n in names])[region]
    trace = e[:, 0] + e[:, 1]
    out = two_mu[:, None] * e
    out[:, :2] += (lam * trace)[:, None]
    return out


def principal(tensors):
    """Largest principal value and its unit direction of symmetric 2x2 tensors (3x3: shape
    (n, 6), :func:`.solid_criterion.principal_3d`).

    Parameters
    ----------
    tensors : numpy.ndarray
        Shape (n, 3), rows (xx, yy, xy).

    Returns
    -------
    values : numpy.ndarray
        Shape (n,).
    directions : numpy.ndarray
        Shape (n, 2), angle in (-pi/2, pi/2]; an isotropic tensor gets (1, 0).

    Raises
    ------
    ValueError
        If tensors is not of shape (n, 3) or holds NaN or inf.
    """
    t = np.asarray(tensors, dtype=float)
    if t.ndim == 2 and t.shape[1] == 6:
        from .solid_criterion import principal_3d     # it imports this module
        return principal_3d(t)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"ngfracture.fracture.strain: tensors must have shape (n, 3), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("ngfracture.fracture.strain: tensor field has NaN or inf values")
    return _ext.CrackPrincipal(t)
