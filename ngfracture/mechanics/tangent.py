"""A factorised tangent kept for further solves: contact rounds, crack passes, load steps.

The Newton solver (mechanics.newton) takes its factorisation from a :class:`SavedTangent`
or leaves its own there; docs/solvers.md (items 6 and 7) says when one is carried on.
"""
import numpy as np

from . import rigid
from ..linalg.bordered import BorderedFactor
from ..linalg.factor import EliminatedFactor
from ..linalg.iterative import make_factor


class SavedTangent:
    """A factorised tangent kept for further solves at the same load (contact rounds).

    The paper's modified Newton factorises the tangent once per load step; a contact
    round, which only changes the general rows, is not a new load step. A solve given an
    empty SavedTangent leaves its last factorisation here (modified Newton, or any method
    on a linear model, whose tangent is constant); a solve given a filled one for the same
    fixed dofs uses it instead of assembling and factorising, and rebuilds only the Schur
    complement of its general rows (the augmented factorisation of linalg.kkt is for fresh
    tangents, which are solved once). Its rigid modes and pins stay those of the
    configuration the tangent was assembled at (linalg.kkt corrects them for K R != 0).

    A SavedTangent made with a ``lineage`` (the problem's mesh was split from a solved one,
    linalg.bordered) starts with the factorisation of the mesh before the split, bordered
    by the split's dofs, where the fixed dofs and pins carry over. One made by
    :meth:`kept` or :meth:`assembled_at` starts with a factorisation of the same mesh from
    an earlier state (a load step before, run.simulation).

    Parameters
    ----------
    lineage : linalg.bordered.Lineage, optional

    Attributes
    ----------
    fixed_dofs : numpy.ndarray or None
    support : rigid.Support or None
    factor : linalg.factor.EliminatedFactor, linalg.bordered.BorderedFactor or None
    state : numpy.ndarray or None
        The displacement the EliminatedFactor's tangent was assembled at.
    residual : (numpy.ndarray, float, numpy.ndarray) or None
        (u, load factor, out-of-balance there) at the end of the last solve: the next solve
        at the same state starts from it without assembling it again.
    contraction : float or None
        How fast the converged modified-Newton solves with this tangent contracted: the
        largest ratio of the last two increments over those that took three iterations or
        more (None: no such solve yet; a solve of fewer iterations gives no estimate).
    lineage : linalg.bordered.Lineage or None
    """

    def __init__(self, lineage=None):
        self.fixed_dofs = self.support = self.factor = self.state = self.residual = None
        self.contraction = None
        self.lineage = lineage

    def forget(self):
        """Empty it, lineage included: the next solve factorises its own tangent."""
        self.__init__()

    def kept(self):
        """A new SavedTangent with this one's factorisation, for solves at another load.

        Returns
        -------
        SavedTangent
            The same fixed dofs, support, factorisation (an EliminatedFactor without the
            results kept from its solves, ``without_caches``) and state; no residual, no
            contraction, no lineage.
        """
        other = SavedTangent()
        other.fixed_dofs, other.support, other.state = self.fixed_dofs, self.support, self.state
        other.factor = self.factor.without_caches() if isinstance(self.factor, EliminatedFactor) else self.factor
        return other

    @classmethod
    def assembled_at(cls, problem, state, rows, inverse="auto"):
        """The factorised tangent of ``problem`` at the displacement ``state``, as a solve
        that started there with these rows would have made it (its support taken at
        ``state``, the direct solver ``inverse``): the same factorisation bit for bit.

        Parameters
        ----------
        problem : ElasticProblem
        state : numpy.ndarray
            A displacement of the problem's space.
        rows : ConstraintRows
            Constraints with the fixed dofs it is factorised for (and, for "auto", as many
            general rows as the solve had).
        inverse : str
            The direct solver (as for linalg.iterative.make_factor).

        Returns
        -------
        SavedTangent

        Raises
        ------
        SingularSystem
            If the factorisation fails.
        """
        support = problem.support(rows, state)
        saved = cls()
        saved.fixed_dofs, saved.support, saved.state = rows.fixed_dofs, support, np.array(state, dtype=float)
        saved.factor = make_factor(problem.tangent(state), rows.fixed_dofs, support.pins, inverse=inverse,
                                   dim=problem.dim, points=problem.arrays.points,
                                   pattern=problem.tangent_pattern(), rows=rows.C.shape[0])
        saved.factor.factorise()
        return saved

    def carry_over(self, problem, fixed_dofs, support):
        """Take the bordered factorisation of the lineage for this solve, if it applies.

        The support's pins are replaced by the base's where these resolve the same modes
        about as well (the pivoted QR of rigid.analyse_support chooses among equally good
        dofs by rounding: a translation's pin wanders from split to split).

        Parameters
        ----------
        problem : ElasticProblem
        fixed_dofs : numpy.ndarray of int
        support : rigid.Support
            Of the solve on ``problem``.

        Returns
        -------
        bool
            True if a factorisation and the support to solve with are now saved for
            these fixed dofs.
        """
        if self.factor is not None or self.lineage is None:
            return False
        support = base_pins(support, self.lineage.base, problem.fes.ndof, problem.dim)
        factor = BorderedFactor.build(self.lineage, problem, fixed_dofs, support.pins)
        if factor is None:
            return False
        self.fixed_dofs, self.support, self.factor = fixed_dofs, support, factor
        return True

    def holds(self, fixed_dofs):
        """True if a tangent is saved and it was factorised for exactly these fixed dofs.

        Parameters
        ----------
        fixed_dofs : numpy.ndarray of int
            Fixed dofs of the solve that wants to reuse it (compared in order).

        Returns
        -------
        bool
            False for an empty SavedTangent.
        """
        return self.fixed_dofs is not None and np.array_equal(self.fixed_dofs, fixed_dofs)


def base_pins(support, base, ndof, dim):
    """``support`` with the base factorisation's pins, where they serve as well.

    The base's pins are carried to the split mesh (same vertices and components) and taken
    if they resolve its modes within a factor 10 of its own pins' smallest singular value.

    Parameters
    ----------
    support : rigid.Support
        Of a solve on the split mesh.
    base : linalg.factor.EliminatedFactor
        The factorisation of the mesh the chain of splits started from.
    ndof : int
        Dofs of the split mesh.
    dim : int
        Dofs per vertex (the mesh's dimension; component-major numbering).

    Returns
    -------
    rigid.Support
        ``support`` itself, or the same modes with the base's pins.
    """
    nvb, nv = base.ndof // dim, ndof // dim
    pins = base.pins // nvb * nv + base.pins % nvb
    if len(pins) != len(support.pins) or np.array_equal(pins, support.pins) or not len(pins):
        return support
    own = np.linalg.svd(support.modes[support.pins].toarray(), compute_uv=False)
    other = np.linalg.svd(support.modes[pins].toarray(), compute_uv=False)
    return rigid.Support(support.modes, pins, support.unheld) if other.min() >= 0.1 * own.min() else support
