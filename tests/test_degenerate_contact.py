"""Contact rows on degenerate configurations: a master segment squeezed to a point, lips
that close on themselves, and an unexpected error inside a step. Never NaN rows; what
cannot be solved is a failure with a reason and the last good state."""
import numpy as np
import pytest

import ngfracture as nf
from ngfracture.contact import collision
from ngfracture.contact import rows as contact
from ngfracture.contact.seams import find_seams, seam_constraints
from test_contact_rows import E2, T2, X2


def test_a_master_segment_squeezed_to_a_point_keeps_its_normal_and_gives_a_finite_row():
    """The row of slave 3 against edge 0 -> 1, found at the reference configuration; then
    node 1 is moved onto node 0: the edge has no direction of its own any more."""
    pairs = collision.detect_collisions(X2, None, T2, boundary_edges=E2)
    cs = contact.select_contacts(X2, None, T2, E2, pairs)
    assert (cs.slave[0], cs.a[0], cs.c[0]) == (3, 0, 1)
    U = np.zeros_like(X2)
    U[1] = X2[0] - X2[1]                               # x_c = x_a: zero length
    fresh = contact.relinearise_node_to_segment(cs, X2, U)
    assert np.all(np.isfinite(fresh.C.toarray())) and np.all(np.isfinite(fresh.g))
    np.testing.assert_array_equal(fresh.normal, cs.normal)
    assert fresh.xi[0] == cs.xi[0]
    # the gap is the slave's distance along the kept normal from the squeezed point
    x = X2 + U
    assert fresh.dist[0] == pytest.approx(float((x[3] - x[0]) @ cs.normal[0]), abs=1e-15)
    # the linearised gap is exact at the configuration it was made at
    assert fresh.C @ U.T.ravel() + fresh.g == pytest.approx(fresh.dist, abs=1e-15)


def test_lips_closed_on_themselves_give_finite_seam_rows():
    """A straight crack's two lips, then every vertex of both lips moved to one point."""
    X = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [1.0, 0.0]])   # lip 0-1 and its twin 2-3
    segments = np.array([[0, 1], [3, 2]])                             # opposite directions
    seams = find_seams(X, segments)
    assert len(seams) == 1
    U = -X + np.array([0.5, 0.0])                                     # all at (0.5, 0)
    rows, keys = seam_constraints(seams, X, U)
    assert len(rows) > 0
    assert np.all(np.isfinite(rows.normal)) and np.all(np.isfinite(rows.C.toarray()))
    assert np.all(np.isfinite(rows.g))


def test_an_unexpected_error_in_a_step_ends_the_run_with_its_reason_and_the_last_good_state(monkeypatch, tmp_path):
    """An exception inside a crack pass (here injected into the split) is a failed attempt:
    retried, then the run ends failed with the exception named and its traceback in the
    summary, and the last accepted state written."""
    from ngfracture.run import step as step_module

    def broken_split(*args, **kwargs):
        raise ValueError("C contains NaN or inf")
    monkeypatch.setattr(step_module, "split_by_tensor", broken_split)
    result = nf.Simulation(nf.scenes.plate(maxh=0.1), nf.StepControl(max_retries=2), out=tmp_path,
                           pictures="none").run()
    assert result.reason == "failed"
    failure = result.summary["failure"]
    assert failure["reason"] == "exception" and "ValueError: C contains NaN or inf" in failure["message"]
    assert "broken_split" in failure["details"]
    assert (tmp_path / "summary.json").exists() and (tmp_path / f"checkpoint_{result.state.step:06d}.npz").exists()
