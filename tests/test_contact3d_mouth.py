"""Contact at a crack's mouth on the notch of bar3d (docs/contact.md, "Contact in 3D runs", the bar).

netgen orients a surface element from its face descriptor's inner to its outer domain, so
the faces of the slot that ``notched_bar_mesh`` subtracts from its box point into the glass;
``solid_to_arrays`` turns every boundary face out of its tetrahedron
(:func:`ngfracture.geometry.solid.outward_faces`).

1. Every boundary face of the bar's arrays has the opposite vertex of its tetrahedron behind
   it (exact ``orient3d``), the notch's faces included; ``outward_faces`` turns a face given
   in the other order and leaves a face between two tetrahedra alone.
2. bar3d(maxh=0.25) with contact, up to four steps: the crack starts at the slot's root
   in step 3 and breaks the bar in two, as without contact; no step retried, and every
   accepted step keeps the invariants of ``invariant_util.check_accepted_3d`` (reference
   volume to the last bit, no inverted tetrahedron, overlap between pieces at most 1e-10
   of the volume) and no vertex deeper than 1e-10 of the bar's diameter in a piece (exact
   detection). With the notch's faces pointing in, the reflex-wedge rows at the mouth
   took the root faces at the other copy for faces of a reflex wedge, and the active set
   of step 3 cycled until the solve failed (slow: about a minute alone).
"""
import math

import numpy as np
import pytest

import ngfracture as nf
from invariant_util import check_accepted_3d, pieces, reference_volume
from ngfracture.contact.collision3d import detect_penetrations_3d, orient3d
from ngfracture.geometry.solid import OUTWARD_FACES, solid_to_arrays


def behind(arrays):
    """orient3d of every boundary face with the fourth vertex of its tetrahedron (+1: behind
    the face); OUTWARD_FACES only finds that vertex (face k is opposite vertex k)."""
    T, F = arrays.tets, arrays.faces
    own = T[:, OUTWARD_FACES].reshape(-1, 3)
    opposite = T.reshape(-1)
    where = {tuple(sorted(f)): i for i, f in enumerate(own.tolist())}
    at = np.array([where[tuple(sorted(f))] for f in F.tolist()])
    X = arrays.points
    return orient3d(X[F[:, 0]], X[F[:, 1]], X[F[:, 2]], X[opposite[at]])


def test_every_face_of_the_notched_bar_points_out_of_its_tetrahedron():
    a = solid_to_arrays(nf.scenes.notched_bar_mesh(0.25, 0.05, notch=0.4))
    notch = np.asarray(a.bc_names)[a.face_bc - 1] == "notch"
    assert notch.sum() > 0
    assert np.all(behind(a) == 1)


def test_outward_faces_turns_a_face_in_the_other_order_and_keeps_an_interface():
    from ngfracture.geometry.solid import outward_faces
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])          # sharing face (1, 2, 3)
    assert outward_faces(tets, [[0, 2, 1], [3, 1, 4]]).tolist() == [[0, 2, 1], [3, 1, 4]]
    assert outward_faces(tets, [[0, 1, 2], [2, 0, 1], [4, 1, 3]]).tolist() == [[0, 2, 1], [2, 1, 0], [4, 3, 1]]
    assert outward_faces(tets, [[1, 2, 3], [1, 3, 2]]).tolist() == [[1, 2, 3], [1, 3, 2]]


@pytest.mark.slow
def test_bar_with_contact_cracks_at_the_notch_without_a_retry(tmp_path):
    scene = nf.scenes.bar3d(maxh=0.25)
    scene.contact = True
    reference = solid_to_arrays(scene.mesh)
    volume = reference_volume(reference.points, reference.tets)
    diameter = math.sqrt(2.0 ** 2 + 1.0 + 0.5 ** 2)
    records = []

    def check(step):
        a = step.state.arrays
        nv = len(a.points)
        overlap = check_accepted_3d(step, volume)
        U = np.asarray(step.state.u).reshape(3, -1)[:, :nv].T
        pen = detect_penetrations_3d(a.points, a.tets, a.faces, pieces(a.tets, nv)[a.tets[:, 0]], U)
        records.append((step.record, max(0.0, -float(np.min(pen.gap, initial=0.0))), overlap))

    result = nf.Simulation(scene, nf.StepControl(max_steps=4), out=tmp_path, pictures="none").run(on_step=check)
    print("\n" + "\n".join(f"step {r['step']}: split {r['split_vertices']}, retries {r['retries']}, deepest {d:.2e}, "
                           f"overlap {o:.2e}" for r, d, o in records))
    # it breaks through in its first cracking step, as without contact
    assert result.reason == "broken" and result.summary["n_fragments"] == 2
    assert [r["split_vertices"] > 0 for r, _, _ in records] == [False, False, True]
    for record, depth, _ in records:
        assert record["retries"] == 0, record["failures"]
        assert depth <= 1e-10 * diameter
