"""One threshold for "a rigid mode is held": the solver's holds and the floating-body check agree."""
import numpy as np
import pytest
import scipy.sparse as sp

import ngfracture as nf
from ngfracture.mechanics import rigid
from conftest import square_mesh


def test_numerical_rank_is_relative_with_a_floor_of_one():
    assert rigid.numerical_rank([]) == 0
    assert rigid.numerical_rank([2.0, 1e-9, 1e-11]) == 2          # relative to 2: 2e-10
    assert rigid.numerical_rank([1e-12]) == 0                       # a tiny hold is no hold
    assert rigid.numerical_rank([1e-3, 2e-10]) == 2                 # floor 1: 1e-10 absolute


@pytest.mark.parametrize("weight,held", [(1.0, 1), (1e-6, 1), (1e-12, 0)])
def test_solver_holds_and_floating_body_check_agree(weight, held):
    """A free square with one general row on its x translation of the given weight: both
    tests count the same held modes (the relative test alone called weight 1e-12 held)."""
    mesh = square_mesh(0.5)
    prob = nf.ElasticProblem(mesh, nf.LinearElastic(1.0, 0.3))
    n = prob.fes.ndof // 2
    row = np.zeros((1, prob.fes.ndof))
    row[0, :mesh.nv] = weight / mesh.nv          # the mean x displacement, scaled
    prob.constraints.add_rows(sp.csr_matrix(row), np.zeros(1), label="test")
    rows = prob.assemble_constraints()
    support = prob.support(rows)
    assert support.modes.shape[1] == 3              # no single-dof row: all three modes free
    extra = rigid.unheld_mode_rows(rows.C, support.modes)
    assert extra.shape[0] == 3 - held               # the solver holds the rest by rows
    message = prob.floating_bodies(rows, support)
    assert (message != "") and f"{3 - held} rigid-body mode(s) are held by no constraint" in message
