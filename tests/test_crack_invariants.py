"""Exact invariants after every split, on random and adversarial cases."""
import numpy as np
import pytest
import ngsolve
from netgen.geom2d import SplineGeometry, unit_square

from ngfracture import fracture
from crack_util import check_invariants, grid_mesh, coords


def netgen_square(maxh):
    return ngsolve.Mesh(unit_square.GenerateMesh(maxh=maxh))


def two_materials(maxh):
    """Two unit squares side by side, materials 'a' and 'b', an interface segment."""
    geo = SplineGeometry()
    p = [geo.AppendPoint(*xy) for xy in [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]]
    for a, b, l, r, bc in [(0, 1, 1, 0, "bottom"), (1, 2, 2, 0, "bottom"), (2, 3, 2, 0, "right"),
                           (3, 4, 2, 0, "top"), (4, 5, 1, 0, "top"), (5, 0, 1, 0, "left"),
                           (1, 4, 1, 2, "interface")]:
        geo.Append(["line", p[a], p[b]], leftdomain=l, rightdomain=r, bc=bc)
    geo.SetMaterial(1, "a")
    geo.SetMaterial(2, "b")
    return ngsolve.Mesh(geo.GenerateMesh(maxh=maxh))


def random_directions(rng, n):
    phi = rng.uniform(0, np.pi, n)
    return np.column_stack([np.cos(phi), np.sin(phi)])


def run_single_splits(mesh, nsteps, rng):
    """Split one random vertex at a time (copies included), checking after each."""
    for _ in range(nsteps):
        v = int(rng.integers(mesh.nv))
        res = fracture.split_vertices(mesh, [v], random_directions(rng, 1))
        check_invariants(mesh, res)
        mesh = res.mesh
    return mesh


def run_passes(mesh, npass, per_pass, rng):
    for _ in range(npass):
        v = rng.choice(mesh.nv, size=min(per_pass, mesh.nv), replace=False)
        res = fracture.split_vertices(mesh, v, random_directions(rng, len(v)))
        check_invariants(mesh, res)
        mesh = res.mesh
    return mesh


def test_random_single_splits_small():
    rng = np.random.default_rng(1)
    mesh = netgen_square(0.06)
    out = run_single_splits(mesh, 150, rng)
    assert out.nv > mesh.nv + 100


def test_random_passes_small():
    rng = np.random.default_rng(2)
    mesh = netgen_square(0.04)
    out = run_passes(mesh, 8, 100, rng)
    assert out.nv > mesh.nv + 300


def test_every_vertex_same_direction_then_perpendicular():
    # adversarial: all vertices at once, ties everywhere, then again crosswise
    for mesh in (grid_mesh(12, 12), netgen_square(0.08)):
        n = mesh.nv
        res = fracture.split_vertices(mesh, np.arange(n), np.tile([1.0, 0.0], (n, 1)))
        check_invariants(mesh, res)
        res2 = fracture.split_vertices(res.mesh, np.arange(res.mesh.nv), np.tile([0.0, 1.0], (res.mesh.nv, 1)))
        check_invariants(res.mesh, res2)
        assert res2.nfragments > res.nfragments > 1


def test_grid_shatters_into_single_triangles_at_most():
    # repeated all-vertex passes in three directions end with every triangle free
    mesh = grid_mesh(6, 6)
    rng = np.random.default_rng(3)
    for d in [[1, 0], [0, 1], [1, -1], [1, 1], [1, 0], [0, 1]]:
        res = fracture.split_vertices(mesh, rng.permutation(mesh.nv), np.tile(d, (mesh.nv, 1)) * 1.0)
        check_invariants(mesh, res)
        mesh = res.mesh
    assert res.nfragments <= mesh.ne
    assert mesh.nv <= 3 * mesh.ne


def test_two_materials_interface():
    rng = np.random.default_rng(4)
    mesh = two_materials(0.15)
    assert mesh.GetMaterials() == ("a", "b")
    out = run_passes(mesh, 5, 40, rng)
    assert out.GetMaterials() == ("a", "b")
    assert {"bottom", "right", "top", "left", "interface", "crack"} <= set(out.GetBoundaries())
    # the material areas do not change
    for mat in ("a", "b"):
        assert ngsolve.Integrate(1, out, definedon=out.Materials(mat)) == pytest.approx(1.0, rel=1e-12)


def test_determinism():
    rng = np.random.default_rng(5)
    mesh = netgen_square(0.05)
    v = rng.choice(mesh.nv, size=200, replace=False)
    d = random_directions(rng, 200)
    r1 = fracture.split_vertices(mesh, v, d)
    r2 = fracture.split_vertices(mesh, v, d)
    assert r1.record.keys() == r2.record.keys()
    for k in r1.record:
        assert np.array_equal(r1.record[k], r2.record[k]), k
    assert np.array_equal(r1.parent, r2.parent)
    assert np.array_equal(r1.crack_segments, r2.crack_segments)
    assert np.array_equal(coords(r1.mesh), coords(r2.mesh))


def test_cracked_mesh_assembles_solves_and_saves(tmp_path):
    # -div grad u + u = 1 with natural conditions on every boundary (crack faces included)
    # has u = 1 on every fragment: an exact check that the cracked mesh is a valid FE mesh
    rng = np.random.default_rng(9)
    mesh = run_passes(netgen_square(0.08), 4, 60, rng)
    fes = ngsolve.H1(mesh, order=2)
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(ngsolve.grad(u) * ngsolve.grad(v) * ngsolve.dx + u * v * ngsolve.dx).Assemble()
    f = ngsolve.LinearForm(v * ngsolve.dx).Assemble()
    gf = ngsolve.GridFunction(fes)
    gf.vec.data = a.mat.Inverse(inverse="sparsecholesky") * f.vec
    assert np.abs(gf.vec.FV().NumPy()[:mesh.nv] - 1).max() < 1e-10
    # netgen's own file format round trip keeps names, elements and the crack segments
    from netgen.meshing import Mesh as NGMesh
    path = str(tmp_path / "cracked.vol")
    mesh.ngmesh.Save(path)
    back = NGMesh()
    back.Load(path)
    m2 = ngsolve.Mesh(back)
    assert (m2.nv, m2.ne) == (mesh.nv, mesh.ne)
    assert m2.GetBoundaries() == mesh.GetBoundaries()
    L = lambda m: ngsolve.Integrate(1, m, ngsolve.BND, definedon=m.Boundaries("crack"))
    assert L(m2) == pytest.approx(L(mesh), rel=1e-14)


@pytest.mark.slow
def test_thousands_of_random_splits_10k_triangles():
    rng = np.random.default_rng(6)
    mesh = netgen_square(0.015)
    assert 9000 < mesh.ne < 12000, mesh.ne
    mesh1 = run_single_splits(mesh, 1500, rng)
    mesh2 = run_passes(mesh1, 10, 300, rng)
    assert mesh2.nv >= mesh.nv + 2000


if __name__ == "__main__":
    import pytest as _pytest
    raise SystemExit(_pytest.main([__file__, "-q"]))


def test_pieces_from_the_engines_fragments_equal_the_graph_search():
    """rigid.pieces_of_triangles on the crack engine's fragments gives the very count and
    numbering of rigid.pieces (connected components of the vertex graph) on shattered meshes,
    returns None for a vertex in no triangle and refuses labels that are not per triangle
    or split a piece."""
    from ngfracture.mechanics import rigid
    rng = np.random.default_rng(7)
    mesh = netgen_square(0.08)
    checked = 0
    for d in [[1, 0], [0, 1], [1, -1], [1, 1]]:
        order = rng.permutation(mesh.nv)[: mesh.nv // 2]
        res = fracture.split_vertices(mesh, order, np.tile(d, (len(order), 1)) * 1.0)
        mesh = res.mesh
        T = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3].astype(np.int64) - 1
        count, piece = rigid.pieces(T, mesh.nv)
        fast = rigid.pieces_of_triangles(T, mesh.nv, res.fragment)
        assert fast[0] == count == res.nfragments
        assert np.array_equal(fast[1], piece) and fast[1].dtype == piece.dtype
        checked += count > 1
    assert checked >= 3
    assert rigid.pieces_of_triangles(T, mesh.nv + 1, res.fragment) is None
    with pytest.raises(ValueError, match="one entry per triangle"):
        rigid.pieces_of_triangles(T, mesh.nv, res.fragment[1:])
    with pytest.raises(ValueError, match="share a vertex different pieces"):
        rigid.pieces_of_triangles(T, mesh.nv, np.arange(len(T)))
