"""When the complementarity problem chooses the set: settling and cycles.

Rows that depend on each other (a vertex pressed on several faces at a junction of
cracks) share their force in many ways. The solve with an independent subset of them can
give one row a tensile multiplier where the exact solution of the linearised contact
problem (:meth:`ContactSolver._complementarity`) compresses every row. The primal-dual
update releases that row, the complementarity problem closes it again, and the set went
round in a cycle (the coarse confined sphere at x = 2.62e-3: 20 rounds without settling).
:meth:`ActiveSet.choose` settles a set that the complementarity problem keeps; where the
problem's choice is a set imposed before (a cycle), it solves it again with every row
wanted in the solve as a candidate.
"""
import numpy as np

from ngfracture.contact.active_set3d import ActiveSet3d

from blocks3d import block_geometry, overlapping_blocks


def overlapping_geometry():
    """A cube of 2 x 2 x 2 blocks, each expanded about its centroid: every lip overlaps."""
    arrays, piece, _, U = overlapping_blocks(5, 2, 0.08)
    return block_geometry(arrays, piece), U


def solved_with_one_tensile_row(exact_choice):
    """An active set after one solve whose first row pulls, and its next round's choice:
    past the primal-dual rounds, the complementarity problem returning the last set (or
    nothing, ``exact_choice`` False)."""
    geometry, U = overlapping_geometry()
    active = ActiveSet3d(geometry, 1e-12)
    cand = active.update(U, {"collision": 0.0})
    want, kept, _ = active.primal_dual(cand)
    kept, settled = active.choose(cand, want, kept, 1, lambda rows, idx: None)
    assert not settled and len(kept) > 100
    lam = -np.ones(len(kept))
    lam[0] = 1.0                                      # tensile
    active.record(cand.keys, kept, lam, 1.0)
    last = np.unique(active.codec.codes_of(list(active.multipliers)))
    cand = active.update(U, {"collision": 0.0})
    want, kept2, _ = active.primal_dual(cand)
    codes = cand.keys.codes
    assert len(np.setdiff1d(last, codes[kept2])) == 1          # the update releases the tensile row

    def complementarity(rows, idx):
        return idx[np.isin(codes[idx], last)] if exact_choice else None

    chosen, settled = active.choose(cand, want, kept2, active.pdas_rounds + 1, complementarity)
    return last, np.unique(codes[chosen]), settled


def test_the_set_the_complementarity_problem_keeps_is_settled():
    last, chosen, settled = solved_with_one_tensile_row(exact_choice=True)
    assert settled and np.array_equal(chosen, last)


def test_without_an_exact_solution_the_update_releases_the_tensile_row():
    last, chosen, settled = solved_with_one_tensile_row(exact_choice=False)
    assert not settled and len(np.setdiff1d(last, chosen)) == 1


def test_a_cycle_makes_every_wanted_row_a_candidate():
    """A vertex sliding over a master vertex: set A lets it penetrate face F (F wanted at A's
    state, never imposed), and the problem chooses B = A + G. At B's state F is not wanted,
    the update releases G, and without F the problem chooses A again, a set imposed
    before. The choice must be solved again with every row wanted in the solve: it then
    keeps B, settled."""
    geometry, U = overlapping_geometry()
    active = ActiveSet3d(geometry, 1e-12)
    cand = active.update(U, {"collision": 0.0})
    _, kept, _ = active.primal_dual(cand)
    codes = cand.keys.codes
    A, G, F = kept[:-2], kept[-2], kept[-1]
    B = np.append(A, G)
    calls = []

    def complementarity(rows, idx):
        calls.append(set(codes[idx].tolist()))
        return B if codes[F] in calls[-1] else A

    exact = active.pdas_rounds + 1
    active.choose(cand, A, A, exact, lambda rows, idx: A)                     # A imposed
    active.record(cand.keys, A, -np.ones(len(A)), 1.0)
    chosen, settled = active.choose(cand, np.append(A, F), np.append(A, F), exact + 1, complementarity)
    assert not settled and np.array_equal(np.sort(chosen), np.sort(B))        # F wanted: B
    active.record(cand.keys, chosen, -np.ones(len(chosen)), 1.0)
    calls.clear()
    chosen, settled = active.choose(cand, A, A, exact + 2, complementarity)   # G released, F not wanted
    assert len(calls) == 2 and codes[F] not in calls[0] and codes[F] in calls[1]
    assert settled and np.array_equal(np.sort(chosen), np.sort(B))
