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
    kept, settled = active.choose(cand, want, kept, 1, lambda rows, idx, released=None: None)
    assert not settled and len(kept) > 100
    lam = -np.ones(len(kept))
    lam[0] = 1.0                                      # tensile
    active.record(cand.keys, kept, lam, 1.0)
    last = np.unique(active.codec.codes_of(list(active.multipliers)))
    cand = active.update(U, {"collision": 0.0})
    want, kept2, _ = active.primal_dual(cand)
    codes = cand.keys.codes
    assert len(np.setdiff1d(last, codes[kept2])) == 1          # the update releases the tensile row

    def complementarity(rows, idx, released=None):
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

    def complementarity(rows, idx, released=None):
        calls.append(set(codes[idx].tolist()))
        return B if codes[F] in calls[-1] else A

    exact = active.pdas_rounds + 1
    active.choose(cand, A, A, exact, lambda rows, idx, released=None: A)                     # A imposed
    active.record(cand.keys, A, -np.ones(len(A)), 1.0)
    chosen, settled = active.choose(cand, np.append(A, F), np.append(A, F), exact + 1, complementarity)
    assert not settled and np.array_equal(np.sort(chosen), np.sort(B))        # F wanted: B
    active.record(cand.keys, chosen, -np.ones(len(chosen)), 1.0)
    calls.clear()
    chosen, settled = active.choose(cand, A, A, exact + 2, complementarity)   # G released, F not wanted
    assert len(calls) == 2 and codes[F] not in calls[0] and codes[F] in calls[1]
    assert settled and np.array_equal(np.sort(chosen), np.sort(B))


def test_a_warm_solve_asks_the_complementarity_problem_from_its_second_round():
    """A solve from the rows of the solve before (``warm``): with ``warm_exact`` the
    second round's set is the complementarity problem's, and its candidates hold a row
    wanted in the first round that was neither imposed (dropped, as a row dependent on the
    others is) nor wanted now: released rows it depended on would let it sink unseen
    (the default sphere: 1e-4 deep). Without ``warm_exact`` the primal-dual update
    chooses the second round's set."""
    geometry, U = overlapping_geometry()
    cold = ActiveSet3d(geometry, 1e-12)
    cand = cold.update(U, {"collision": 0.0})
    _, kept, _ = cold.primal_dual(cand)
    warm = [cand.keys[i] for i in kept.tolist()]
    for warm_exact in (False, True):
        active = ActiveSet3d(geometry, 1e-12, warm=warm, warm_exact=warm_exact)
        assert active.pdas_rounds == (1 if warm_exact else 6)
        cand = active.update(U, {"collision": 0.0})
        want, kept, _ = active.primal_dual(cand)
        codes = cand.keys.codes
        dropped = kept[-1]                       # wanted in round 1, not imposed
        imposed, settled = active.choose(cand, want, kept[:-1], 1, lambda rows, idx, released=None: None)
        assert not settled and not active.exact
        active.record(cand.keys, imposed, -np.ones(len(imposed)), 1.0)
        cand = active.update(U, {"collision": 0.0})
        calls = []

        def complementarity(rows, idx, released=None):
            calls.append(codes[idx])
            return idx[np.isin(codes[idx], codes[imposed])]

        released = imposed[1:]                   # the update releases a row
        chosen, settled = active.choose(cand, released, released, 2, complementarity)
        assert active.exact == warm_exact and len(calls) == int(warm_exact)
        if not warm_exact:
            assert not settled and np.array_equal(chosen, released)
        else:
            assert codes[dropped] in calls[0] and settled
            assert np.array_equal(np.sort(codes[chosen]), np.sort(codes[imposed]))


def test_a_row_the_complementarity_problem_released_stays_a_candidate():
    """Found rows stay candidates while active or found again; once the complementarity
    problem chooses, every row wanted or imposed in the solve stays one: a row it released
    and that is no longer found is still there for the next problem, which can then see
    the penetration its release lets happen (the coarse confined sphere at x = 2.37e-3: a
    2-cycle of 14 rounds). Before that choice, the plain rule holds."""
    geometry, U = overlapping_geometry()
    for exact in (False, True):
        active = ActiveSet3d(geometry, 1e-12)
        cand = active.update(U, {"collision": 0.0})
        want, kept, _ = active.primal_dual(cand)
        codes = cand.keys.codes
        fixed = len(active.seam_keys)
        found = want[want >= fixed]
        assert len(found) > 10
        chosen = np.setdiff1d(kept, found[:5])                   # five found rows released
        round_number = active.pdas_rounds + 1 if exact else 1
        active.choose(cand, want, kept, round_number, lambda rows, idx, released=None: chosen)
        assert active.exact == exact                             # round 1: the update chooses
        active.record(cand.keys, chosen, -np.ones(len(chosen)), 1.0)
        cand = active.update(np.zeros_like(U), {"collision": 0.0})   # the blocks apart: nothing found
        now = set(cand.keys.codes.tolist())
        assert set(codes[chosen].tolist()) <= now
        assert all((c in now) == exact for c in codes[found[:5]].tolist())


def test_rows_frozen_at_another_set_get_an_update_at_a_new_set():
    """Rows stop being re-linearised every round when that stops reducing the penetration
    at a settled set; the fixed point of updates then decides. When the set changes after
    that, the frozen rows overlap to second order in the motion to the new solution: the
    first judgement of the new set is an update, not a failure against the penetration of
    the old set."""
    geometry, U = overlapping_geometry()
    active = ActiveSet3d(geometry, 1e-12)
    cand = active.update(U, {"collision": 0.0})
    want, kept, other = active.primal_dual(cand)
    active.choose(cand, want, kept, 1, lambda rows, idx, released=None: None)
    active.record(cand.keys, kept, -np.ones(len(kept)), 1.0)
    active.moving, active.last_penetration = False, 1e-15       # frozen at a set of tiny overlap
    subset = kept[1:]
    chosen, settled = active.choose(cand, subset, subset, 2, lambda rows, idx, released=None: None)
    assert not settled
    verdict, penetration, _ = active.settle(cand, other, U)
    assert penetration > 1e-3 and verdict == "update"
