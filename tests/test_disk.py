"""The disk around an expanding core (paper Fig. 9, 10): comminuted zone, intact ring, disintegration."""
import math

import numpy as np
import pytest

from ngfracture import scenes
from ngfracture.fracture.fragments import FragmentStatistics
from ngfracture.geometry.meshio import mesh_to_arrays
from ngfracture import Simulation



def encircles_origin(triangles, points, members):
    """Whether the triangles ``members`` (one connected piece) contain a loop around (0, 0).

    Lift the polar angle of the triangle centroids along a spanning tree of the piece
    (neighbours share an edge); the piece winds around the origin exactly when two
    neighbours end up with lifted angles about 2 pi apart.
    """
    members = np.asarray(members)
    index = -np.ones(len(triangles), dtype=np.int64)
    index[members] = np.arange(len(members))
    c = points[triangles[members]].mean(axis=1)
    theta = np.arctan2(c[:, 1], c[:, 0])
    edges = {}
    for k, t in enumerate(triangles[members]):
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges.setdefault((min(a, b), max(a, b)), []).append(k)
    neighbours = [[] for _ in members]
    for ks in edges.values():
        if len(ks) == 2:
            neighbours[ks[0]].append(ks[1])
            neighbours[ks[1]].append(ks[0])
    lifted = np.full(len(members), np.nan)
    lifted[0] = theta[0]
    stack = [0]
    while stack:
        k = stack.pop()
        for j in neighbours[k]:
            step = (theta[j] - theta[k] + math.pi) % (2 * math.pi) - math.pi
            if np.isnan(lifted[j]):
                lifted[j] = lifted[k] + step
                stack.append(j)
            elif abs(lifted[j] - (lifted[k] + step)) > math.pi:
                return True
    return False


def disk_pieces(result):
    """The final fragments of a disk run, its mesh arrays, and the fragments made of disk only."""
    stats = FragmentStatistics(result.problem.mesh)
    a = result.state.arrays
    disk_region = a.region_names.index("disk") + 1
    on_disk = [f for f in stats.ids if np.all(a.regions[stats.fragment == f] == disk_region)]
    return stats, a, on_disk


def test_encircling_check_on_a_ring_and_a_c_shape():
    from ngfracture.scenes import cored_disk_mesh
    a = mesh_to_arrays(cored_disk_mesh(maxh=0.2))
    disk = np.flatnonzero(a.regions == a.region_names.index("disk") + 1)
    assert encircles_origin(a.triangles, a.points, disk)
    c = a.points[a.triangles[disk]].mean(axis=1)
    cut = disk[~((c[:, 0] > 0) & (np.abs(c[:, 1]) < 0.15))]      # a wedge removed: a C
    assert not encircles_origin(a.triangles, a.points, cut)


#: the default resolution (slow: 13 minutes on a busy machine) and a coarse one for the
#: fast suite (about a minute: 48 steps, 107 split vertices, 16 fragments); the required
#: "more than 20 grains" is for the default scene, the coarse mesh has room for fewer
DISK_CASES = [pytest.param((0.12, 10), id="coarse"),
              pytest.param((0.06, 20), id="default", marks=pytest.mark.slow)]


@pytest.fixture(scope="module", params=DISK_CASES)
def disk_run(request):
    maxh, min_grains = request.param
    return Simulation(scenes.disk(maxh=maxh, radius=None), pictures="none").run(), min_grains


def test_disk_contact_leaves_no_overlap(disk_run):
    """Measured at maxh 0.06: 2.2e-16 (8.2e-7 without the diagonal rows at four-way
    junctions, all of it in 38 triangle pairs across their diagonals)."""
    s = disk_run[0].summary
    assert s["max_overlap_area"] <= 1e-10 * s["area_initial"]


def test_disk_comminuted_zone_and_intact_ring(disk_run):
    """The comminuted zone of the paper's Fig. 9: more than 20 grains (the scene's
    requirement at its default mesh), and an intact outer ring (one piece that
    holds the whole outer boundary and still goes around the hole, so every grain lies
    inside it).

    Measured at maxh 0.06: 77 steps, 232 split vertices, 27 grains (docs/verification.md).
    Where the grains lie inside the ring (around the hole, along the radial cracks) is not
    checked: no theory bounds their radius.
    """
    result, min_grains = disk_run
    assert result.ok and result.reason == "load_max", result.message
    s = result.summary
    assert s["area_final"] == s["area_initial"]
    stats, a, on_disk = disk_pieces(result)
    ring = max(on_disk, key=lambda f: stats.areas[np.searchsorted(stats.ids, f)])
    grains = [f for f in on_disk if f != ring]
    assert len(grains) > min_grains, len(grains)
    # the outer ring is one piece: every triangle on the outer boundary belongs to it ...
    outer = a.segments[a.seg_bc == a.bc_names.index("outer") + 1]
    on_outer = np.flatnonzero(np.isin(a.triangles, outer).sum(axis=1) >= 2)
    assert len(on_outer) >= len(outer) and np.all(stats.fragment[on_outer] == ring)
    # ... and it still goes around the hole
    assert encircles_origin(a.triangles, a.points, np.flatnonzero(stats.fragment == ring))


def test_disintegration_falls_apart_on_a_coarse_mesh():
    """The fast variant of the command ``ngfracture run disintegration``: maxh 0.2 and the
    disk's final expansion (a third of the scene's). Measured: 45 steps, 75 split vertices,
    14 disk pieces, overlap 1.2e-15, 38 s. Without the confining ring the radial cracks
    run through to the outside: the disk falls apart, no piece goes around the hole."""
    scene = scenes.disintegration(maxh=0.2, expansion=50 * scenes.FIRST_CRACK, radius=None)
    assert scene.name == "disintegration" and scene.fix_free_modes == "all"
    result = Simulation(scene, pictures="none").run()
    assert result.ok and result.reason == "load_max", result.message
    s = result.summary
    assert s["max_overlap_area"] <= 1e-10 * s["area_initial"]
    stats, a, on_disk = disk_pieces(result)
    assert len(on_disk) >= 2
    assert not any(encircles_origin(a.triangles, a.points, np.flatnonzero(stats.fragment == f)) for f in on_disk)
    assert s["area_final"] == s["area_initial"]


@pytest.mark.slow
@pytest.mark.parametrize("maxh", [0.08, 0.06])
def test_disintegration_many_disjoint_fragments(maxh):
    """The one-ring disintegration at maxh 0.08 (the scene's default, the paper's "coarse
    initial mesh") and 0.06 (the disk's resolution): more than 20 disjoint disk pieces,
    none around the hole, areas summing to the initial one (measured figures:
    docs/verification.md, "Whole simulations"). It needs the diagonal rows at four-way
    junctions (ngfracture.contact.seams; without them 0.08 stops at step 75, x = 0.00457,
    with 19 disk pieces), up to ten re-linearisations per contact solve (with five, step
    106 fails with penetration 8.1e-15 against 8e-15, still contracting by 20 per update)
    and the iterative refinement of the KKT solves (without it 0.06 fails at step 33)."""
    result = Simulation(scenes.disintegration(maxh=maxh, radius=None), pictures="none").run()
    assert result.ok and result.reason == "load_max", result.message
    s = result.summary
    assert s["max_overlap_area"] <= 1e-10 * s["area_initial"]
    stats, a, on_disk = disk_pieces(result)
    assert len(on_disk) > 20
    # no piece of the disk goes around the hole
    assert not any(encircles_origin(a.triangles, a.points, np.flatnonzero(stats.fragment == f)) for f in on_disk)
    assert math.fsum(s["fragment_areas"]) == pytest.approx(s["area_initial"], rel=1e-14)
    assert s["area_final"] == s["area_initial"]


def crack_lines(arrays):
    """The cracks of a mesh as lines: the crack faces' segments joined where they share a
    reference point (the two faces of a crack coincide there). Returns a list of point sets,
    one per connected crack."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    seg = arrays.boundary_segments("crack")
    points, ids = np.unique(arrays.points[seg.ravel()], axis=0, return_inverse=True)
    ends = ids.reshape(-1, 2)
    graph = coo_matrix((np.ones(len(ends)), (ends[:, 0], ends[:, 1])), shape=(len(points),) * 2)
    count, label = connected_components(graph, directed=False)
    return [points[label == k] for k in range(count)]


@pytest.mark.slow
def test_disk_with_a_critical_distance_gives_the_same_cracked_zone_on_two_meshes():
    """``disk(radius=0.12)`` on its default mesh (h = r/2) and at half the mesh size
    (h = r/4): radial cracks from the hole that end inside the disk, a total crack length
    and a radius of the cracked zone (the farthest crack tip) within 15 % of each other (the
    objectivity bound of the plate, docs/criterion.md). The one-ring criterion's grains
    multiply when the mesh is refined instead (docs/verification.md). The number of radial
    cracks is not a converged quantity (cracks that start next to each other may merge).
    Measured: docs/criterion.md ("Measured: the disk scenes")."""
    runs = []
    for maxh in (0.06, 0.03):
        scene = scenes.disk(maxh=maxh, radius=0.12)
        assert scene.radius == 0.12
        result = Simulation(scene, pictures="none").run()
        assert result.ok and result.reason == "load_max", result.message
        s = result.summary
        assert s["max_overlap_area"] <= 1e-10 * s["area_initial"]
        assert s["area_final"] == s["area_initial"]
        lines = crack_lines(result.state.arrays)
        assert len(lines) >= 3
        for line in lines:
            assert np.hypot(*line.T).min() == pytest.approx(scenes.HOLE, abs=1e-9)
        zone = max(np.hypot(*line.T).max() for line in lines)
        assert zone < 1 - 0.12
        runs.append((s["crack_length"], zone))
    (length_coarse, zone_coarse), (length_fine, zone_fine) = runs
    assert abs(length_fine - length_coarse) <= 0.15 * length_fine
    assert abs(zone_fine - zone_coarse) <= 0.15 * zone_fine
