"""Linear constraints on the displacement: the rows G u = b of the paper's eq. 3.

Two kinds of rows are kept apart because they are solved differently (see linalg/kkt.py):

* single-dof rows ``u[dof] = value``: Dirichlet and gliding conditions on named
  boundaries and point constraints on single vertices.  They are eliminated
  exactly from the KKT system; their multipliers are the reaction forces.
* general rows ``C u = g``: anything that couples several dofs (contact,
  rigid-body modes of free fragments, inclined gliding).  They stay Lagrange
  multipliers, solved through a Schur complement on the small multiplier block.

Dof layout (NGSolve's VectorH1): component c of scalar dof i is ``c * n + i`` with
n the number of scalar dofs; scalar dof i < number of vertices is vertex i.
"""
from dataclasses import dataclass, field

import numpy as np
import ngsolve as ng
import scipy.sparse as sp

COMPONENT_NAMES = {"x": 0, "y": 1, "z": 2}


def _components(component, dim=2):
    """The components a condition prescribes: all for None, else the one named (0/'x', 1/'y', 2/'z')."""
    if component is None:
        return tuple(range(dim))
    c = COMPONENT_NAMES.get(component, component) if isinstance(component, str) else component
    if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or not 0 <= c < dim:
        names = ", ".join(f"{i}/{n!r}" for n, i in list(COMPONENT_NAMES.items())[:dim])
        raise ValueError(f"component must be None (all) or one of {names}, got {component!r}")
    return (int(c),)


def _dirichlet_value(value, comps, dim=2):
    """A Dirichlet value, checked: a dim-vector CoefficientFunction (a CF given; gliding: a
    scalar CF in one component), or a constant vector (a number or a dim-vector; gliding: the
    other entries 0)."""
    if isinstance(value, ng.CoefficientFunction):
        if value.dim == 1:
            if len(comps) != 1:
                raise ValueError("a scalar value needs a component (gliding); give a vector for all components")
            return ng.CF(tuple(value if c == comps[0] else 0 for c in range(dim)))
        if value.dim != dim:
            raise ValueError(f"a Dirichlet value must have 1 or {dim} components, this CoefficientFunction has {value.dim}")
        return value
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"a Dirichlet value must be finite, got {value!r}")
    if arr.ndim == 0:
        out = np.full(dim, float(arr)) if len(comps) != 1 else np.zeros(dim)
        out[list(comps)] = float(arr)
        return out
    if arr.shape != (dim,):
        raise ValueError(f"a Dirichlet value must be a number or a vector of {dim}, got {value!r}")
    return arr.copy()


@dataclass(eq=False)    # value may be an array
class Dirichlet:
    """Prescribed displacement on named boundaries (component=None: all; one component: gliding).

    Parameters
    ----------
    boundaries : tuple of str
        Boundary names of the mesh.
    value : ngsolve.CoefficientFunction or numpy.ndarray
        The prescribed displacement: a CoefficientFunction with one component per space
        dimension, or a constant vector (shape (dim,)).
    component : None, 0/'x', 1/'y' or 2/'z'
        None prescribes all components, otherwise only that one.
    """
    boundaries: tuple
    value: object
    component: object = None


@dataclass
class PointConstraint:
    """Prescribed displacement of one vertex.

    Parameters
    ----------
    vertex : int
        Vertex number (0-based).
    value : tuple of float
        Prescribed displacement, one entry per space dimension.
    component : None, 0/'x', 1/'y' or 2/'z'
        None prescribes all components, otherwise only that one.
    """
    vertex: int
    value: tuple
    component: object = None


@dataclass
class ConstraintRows:
    """The assembled constraints: fixed dofs with target values, plus general rows C u = g.

    Parameters
    ----------
    fixed_dofs : numpy.ndarray of int64, shape (k,)
        Dofs prescribed by single-dof rows, ascending.
    fixed_values : numpy.ndarray, shape (k,)
        Their prescribed values.
    C : scipy.sparse.csr_matrix, shape (m, ndof)
        General constraint rows.
    g : numpy.ndarray, shape (m,)
        Right-hand side of the general rows.
    labels : list of str
        Label of every block of rows added with ``ConstraintSet.add_rows``, in order.
    """
    fixed_dofs: np.ndarray
    fixed_values: np.ndarray
    C: sp.csr_matrix
    g: np.ndarray
    labels: list = field(default_factory=list)

    @property
    def n_rows(self):
        """Total number of constraint rows: single-dof plus general."""
        return len(self.fixed_dofs) + self.C.shape[0]


class ConstraintSet:
    """The constraints of one elasticity problem on a VectorH1 space.

    Parameters
    ----------
    fes : ngsolve.VectorH1
        The displacement space.
    arrays : meshio.MeshArrays, optional
        The mesh's arrays: a first-order space then reads the dofs of a boundary from its
        segments instead of NGSolve's boundary elements.
    """

    def __init__(self, fes, arrays=None):
        self.fes = fes
        self.mesh = fes.mesh
        self.dim = fes.mesh.dim
        self._arrays = arrays
        self.dirichlet = []
        self.points = []
        self.rows = []  # (C, g, label)
        self._dofs_on = {}  # boundary names -> scalar dofs: the space never changes, assembly repeats

    # -- adding constraints (validated at once, before any assembly) ----------------
    def add_dirichlet(self, boundaries, value=0.0, component=None):
        """Prescribe the displacement on one or more named boundaries.

        Parameters
        ----------
        boundaries : str or sequence of str
            Boundary names of the mesh; every name must exist.
        value : float, pair, or ngsolve.CoefficientFunction
            Prescribed displacement: a vector (one entry per dimension), a number (every
            component prescribed takes it), or a scalar CoefficientFunction with ``component``.
        component : None, 0/'x', 1/'y' or 2/'z'
            None prescribes all components; one of them only that one (gliding).

        Raises
        ------
        ValueError
            If a boundary name matches nothing, or the value or component is invalid.
        """
        names = (boundaries,) if isinstance(boundaries, str) else tuple(boundaries)
        if not names:
            raise ValueError("add_dirichlet needs at least one boundary name")
        known = set(self.mesh.GetBoundaries())
        for name in names:
            if not isinstance(name, str) or name not in known:
                raise ValueError(f"boundary {name!r} does not exist in the mesh; its boundaries are {sorted(known)}")
        comps = _components(component, self.dim)
        self.dirichlet.append(Dirichlet(names, _dirichlet_value(value, comps, self.dim), component))

    def add_point(self, vertex, value=0.0, component=None):
        """Prescribe the displacement of a single vertex.

        Parameters
        ----------
        vertex : int
            Vertex number (NGSolve numbering, 0-based).
        value : float or tuple of float
            Prescribed displacement (a number: every prescribed component takes it).
        component : None, 0/'x', 1/'y' or 2/'z'

        Raises
        ------
        ValueError
            If the vertex does not exist or the value is invalid.
        """
        if isinstance(vertex, bool) or not isinstance(vertex, (int, np.integer)) or not 0 <= vertex < self.mesh.nv:
            raise ValueError(f"vertex {vertex!r} does not exist; the mesh has {self.mesh.nv} vertices")
        _components(component, self.dim)
        d = self.dim
        arr = np.broadcast_to(np.asarray(value, dtype=float), (d,)) if np.ndim(value) == 0 else np.asarray(value, float)
        if arr.shape != (d,) or not np.all(np.isfinite(arr)):
            raise ValueError(f"point constraint value must be a finite number or a vector of {d}, got {value!r}")
        self.points.append(PointConstraint(int(vertex), tuple(arr), component))

    def add_rows(self, C, g, label="rows"):
        """Add general constraint rows C u = g (kept as Lagrange multipliers).

        Parameters
        ----------
        C : scipy.sparse matrix or array_like, shape (m, ndof)
            The rows, one column per dof of the space.
        g : array_like, shape (m,)
            Right-hand side.
        label : str
            Name of this block of rows (for messages and ``clear_rows``).

        Raises
        ------
        ValueError
            If the shapes do not match the space or values are not finite.
        """
        C = sp.csr_matrix(C, dtype=float)
        g = np.asarray(g, dtype=float).reshape(-1)
        if C.shape[1] != self.fes.ndof or C.shape[0] != g.size:
            raise ValueError(f"constraint rows {label!r}: C is {C.shape}, g has {g.size} entries, the space has {self.fes.ndof} dofs")
        if not (np.all(np.isfinite(C.data)) and np.all(np.isfinite(g))):
            raise ValueError(f"constraint rows {label!r} contain NaN or inf")
        self.rows.append((C, g, label))

    def clear_rows(self, label=None):
        """Remove general rows (all, or those with the given label).

        Parameters
        ----------
        label : str, optional
            Remove only the blocks added with this label; None removes every block.
        """
        self.rows = [r for r in self.rows if label is not None and r[2] != label]

    # -- assembly -------------------------------------------------------------------
    def assemble(self):
        """The constraint rows for the current mesh.

        Returns
        -------
        ConstraintRows

        Raises
        ------
        ValueError
            If two conditions prescribe different values on one dof, or the single-dof
            rows prescribe every dof (nothing left to solve for).
        """
        n = self.fes.ndof // self.dim
        pieces = []   # (dofs, values, source), merged below
        work = None
        for cond in self.dirichlet:
            scalar_dofs = self._boundary_dofs(cond.boundaries, n)
            source = f"Dirichlet on {', '.join(cond.boundaries)}"
            if isinstance(cond.value, np.ndarray):
                # a constant: its value at the vertex dofs, zero at the higher-order ones (what
                # Set() gives, without the projection's rounding)
                vertex = scalar_dofs < self.mesh.nv
                for c in _components(cond.component, self.dim):
                    pieces.append((c * n + scalar_dofs, np.where(vertex, cond.value[c], 0.0), source))
                continue
            if work is None:
                work = ng.GridFunction(self.fes)
            region = self.mesh.Boundaries("|".join(cond.boundaries))
            work.vec[:] = 0.0
            # NGSolve's Set() on the boundary: nodal at vertices, projection for edge dofs
            work.Set(cond.value, ng.BND, definedon=region)
            data = work.vec.FV().NumPy()
            for c in _components(cond.component, self.dim):
                dofs = c * n + scalar_dofs
                if not np.all(np.isfinite(data[dofs])):
                    raise ValueError(f"{source}: the prescribed value is NaN or inf on the boundary")
                pieces.append((dofs, data[dofs].copy(), source))
        for pc in self.points:
            for c in _components(pc.component, self.dim):
                pieces.append((np.array([c * n + pc.vertex]), np.array([pc.value[c]]),
                               f"point constraint at vertex {pc.vertex}"))
        # values that agree to rounding (NGSolve's Set() leaves ~1e-17 at corners) are one value
        scale = max([float(np.max(np.abs(v), initial=0.0)) for _, v, _ in pieces] + [1e-300])
        values = {}
        for dofs, vals, source in pieces:
            self._merge(values, dofs, vals, source, 1e-10 * scale)
        dofs = np.array(sorted(values), dtype=np.int64)
        if dofs.size == self.fes.ndof:
            sources = list(dict.fromkeys(source for _, _, source in pieces))
            named = "; ".join(sources[:5]) + (f"; and {len(sources) - 5} more" if len(sources) > 5 else "")
            raise ValueError(f"the constraints leave no free dof: {named} prescribe all "
                             f"{dofs.size} dofs, there is nothing to solve for")
        vals = np.array([values[d][0] for d in dofs], dtype=float)
        if self.rows:
            C = sp.vstack([r[0] for r in self.rows]).tocsr()
            g = np.concatenate([r[1] for r in self.rows])
        else:
            C = sp.csr_matrix((0, self.fes.ndof))
            g = np.zeros(0)
        return ConstraintRows(dofs, vals, C, g, [r[2] for r in self.rows])

    def _boundary_dofs(self, names, n):
        """Scalar dof numbers on the named boundaries (x half of the space's dofs).

        First order with the mesh arrays: the vertices of the boundary's segments. Otherwise
        read from NGSolve's boundary elements (converting the space's BitArray to numpy
        iterates over every dof: 0.13 s at 360k dofs).
        """
        key = tuple(sorted(set(names)))
        if key not in self._dofs_on:
            a = self._arrays
            if a is not None and self.fes.globalorder == 1:
                # first order: the dofs are the vertices of the boundary's segments (faces in 3D)
                of = a.boundary_faces if self.dim == 3 else a.boundary_segments
                segments = np.concatenate([of(name).reshape(-1) for name in key])
                self._dofs_on[key] = np.unique(segments.astype(np.int64))
            else:
                names = set(key)
                dofs = [d for el in self.fes.Elements(ng.BND) if el.mat in names for d in el.dofs if 0 <= d < n]
                self._dofs_on[key] = np.unique(np.array(dofs, dtype=np.int64))
        return self._dofs_on[key]

    @staticmethod
    def _merge(values, dofs, vals, source, tol):
        for d, v in zip(dofs.tolist(), vals.tolist()):
            if d in values:
                old, old_source = values[d]
                if abs(old - v) > tol:
                    raise ValueError(f"conflicting constraint values on dof {d}: {old!r} from {old_source} "
                                     f"and {v!r} from {source}")
            else:
                values[d] = (v, source)
