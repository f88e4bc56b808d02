// Python bindings of the crack engine: nodal strain, selection, node splitting + rebuild.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include <chrono>
#include "vertex_average.hpp"
#include "crack_strain.hpp"
#include "crack_split.hpp"
#include "crack_rebuild.hpp"
#include "nonlocal_strain.hpp"

namespace py = pybind11;
using namespace ngfracture;
using namespace ngcomp;

namespace
{
  using darray = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using iarray = py::array_t<int, py::array::c_style | py::array::forcecast>;


  StrainMeasure ParseMeasure (const std::string & s)
  {
    if (s == "linear") return StrainMeasure::Linear;
    if (s == "green") return StrainMeasure::GreenLagrange;
    throw Exception("ngfracture: strain measure must be 'linear' or 'green', got '" + s + "'");
  }

  double Seconds (std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b)
  { return std::chrono::duration<double>(b - a).count(); }
}

void ExportCrack (py::module & m)
{
  py::dict rules;
  rules["1"] = int(RULE_1); rules["1a"] = int(RULE_1A); rules["1b"] = int(RULE_1B);
  rules["2"] = int(RULE_2); rules["2a"] = int(RULE_2A); rules["2b"] = int(RULE_2B);
  rules["tip"] = int(RULE_TIP); rules["none"] = int(RULE_NONE); rules["2c"] = int(RULE_2C);
  rules["tip1"] = int(RULE_TIP1); rules["2d"] = int(RULE_2D);
  m.attr("CRACK_RULES") = rules;   // bit flags of the split record's "rule" entries

  m.def("CrackElementStrain",
        [] (shared_ptr<ngcomp::MeshAccess> mesh, darray u, std::string measure)
        {
          if (u.ndim() != 2 || u.shape(1) != 2 || size_t(u.shape(0)) != mesh->GetNV())
            throw Exception("ngfracture.CrackElementStrain: u must have shape (nv, 2) = (" +
                            ToString(mesh->GetNV()) + ", 2)");
          auto sm = ParseMeasure(measure);
          py::array_t<double> out({ size_t(mesh->GetNE(VOL)), size_t(3) });
          FlatMatrix<double> U(mesh->GetNV(), 2, const_cast<double*>(u.data()));
          FlatMatrix<double> S(mesh->GetNE(VOL), 3, out.mutable_data());
          ElementStrainP1(*mesh, U, sm, S);
          return out;
        },
        py::arg("mesh"), py::arg("u"), py::arg("measure") = "green",
        R"doc(Strain of every triangle from vertex displacements (P1 interpolant).

Parameters
----------
mesh : ngsolve.Mesh
    2D triangle mesh, reference configuration.
u : numpy.ndarray
    Shape (nv, 2), displacement at every vertex.
measure : str
    'green' for (H + H^T + H^T H)/2, 'linear' for (H + H^T)/2, H = grad u.

Returns
-------
numpy.ndarray
    Shape (ne, 3): (xx, yy, xy) tensor components per element.
)doc");

  m.def("CrackVertexStrain",
        [] (shared_ptr<ngcomp::MeshAccess> mesh, darray u, std::string measure)
        {
          if (u.ndim() != 2 || u.shape(1) != 2 || size_t(u.shape(0)) != mesh->GetNV())
            throw Exception("ngfracture.CrackVertexStrain: u must have shape (nv, 2) = (" +
                            ToString(mesh->GetNV()) + ", 2)");
          auto sm = ParseMeasure(measure);
          size_t ne = mesh->GetNE(VOL), nv = mesh->GetNV();
          Matrix<double> es(ne, 3);
          FlatMatrix<double> U(nv, 2, const_cast<double*>(u.data()));
          ElementStrainP1(*mesh, U, sm, es);
          py::array_t<double> out({ nv, size_t(3) });
          FlatMatrix<double> res(nv, 3, out.mutable_data());
          VertexAverage(*mesh, es, res);
          return out;
        },
        py::arg("mesh"), py::arg("u"), py::arg("measure") = "green",
        R"doc(Nodal strain: area-weighted average of the P1 element strains around each vertex.

Parameters
----------
mesh : ngsolve.Mesh
u : numpy.ndarray
    Shape (nv, 2).
measure : str
    'green' or 'linear'.

Returns
-------
numpy.ndarray
    Shape (nv, 3): (xx, yy, xy) per vertex.
)doc");

  m.def("CrackNonlocalOpening",
        [] (shared_ptr<ngcomp::MeshAccess> mesh, darray tensors, darray radius, int ndir)
        {
          size_t nv = mesh->GetNV();
          if (tensors.ndim() != 2 || size_t(tensors.shape(0)) != nv || tensors.shape(1) != 3)
            throw Exception("ngfracture.CrackNonlocalOpening: tensors must have shape (nv, 3) = (" +
                            ToString(nv) + ", 3)");
          if (radius.ndim() != 1 || size_t(radius.shape(0)) != nv)
            throw Exception("ngfracture.CrackNonlocalOpening: radius must have shape (nv,) = (" +
                            ToString(nv) + ",)");
          py::array_t<double> out({ nv, size_t(3) });
          FlatMatrix<double> T(nv, 3, const_cast<double*>(tensors.data()));
          FlatVector<double> R(nv, const_cast<double*>(radius.data()));
          FlatMatrix<double> res(nv, 3, out.mutable_data());
          NonlocalOpening(*mesh, T, R, ndir, res);
          return out;
        },
        py::arg("mesh"), py::arg("tensors"), py::arg("radius"), py::arg("ndir") = 72,
        R"doc(Critical-distance opening measure of every vertex (docs/criterion.md).

Low-level: use ngfracture.crack.StrainCriterion(critical, radius=r).

Parameters
----------
mesh : ngsolve.Mesh
    2D triangle mesh, reference configuration.
tensors : numpy.ndarray
    Shape (nv, 3), nodal tensor field (xx, yy, xy), interpolated linearly on triangles.
radius : numpy.ndarray
    Shape (nv,), critical distance of every vertex (<= 0: not evaluated).
ndir : int
    Number of ray directions (>= 8).

Returns
-------
numpy.ndarray
    Shape (nv, 3): value * n n^T, value the largest over the rays of the smallest opening
    component along the ray (length radius), n the opening direction of the best ray.
)doc");

  m.def("CrackPrincipal",
        [] (darray t)
        {
          if (t.ndim() != 2 || t.shape(1) != 3)
            throw Exception("ngfracture.CrackPrincipal: tensors must have shape (n, 3)");
          size_t n = t.shape(0);
          py::array_t<double> vals(n), dirs({ n, size_t(2) });
          FlatMatrix<double> T(n, 3, const_cast<double*>(t.data()));
          FlatVector<double> V(n, vals.mutable_data());
          FlatMatrix<double> D(n, 2, dirs.mutable_data());
          PrincipalMax(T, V, D);
          return py::make_tuple(vals, dirs);
        },
        py::arg("tensors"),
        R"doc(Largest principal value and its unit direction of symmetric 2x2 tensors.

Parameters
----------
tensors : numpy.ndarray
    Shape (n, 3), rows (xx, yy, xy).

Returns
-------
(numpy.ndarray, numpy.ndarray)
    Values, shape (n,), and directions, shape (n, 2); an isotropic tensor gets (1, 0).
)doc");

  m.def("CrackSelect",
        [] (darray values, double critical)
        {
          if (values.ndim() != 1)
            throw Exception("ngfracture.CrackSelect: values must be 1D");
          FlatVector<double> V(values.shape(0), const_cast<double*>(values.data()));
          auto sel = SelectAbove(V, critical);
          py::array_t<int> out(sel.Size());
          for (size_t i = 0; i < sel.Size(); i++) out.mutable_data()[i] = sel[i];
          return out;
        },
        py::arg("values"), py::arg("critical"),
        R"doc(Indices with value > critical, by decreasing value, ties by increasing index.)doc");

  m.def("CrackSplit",
        [] (shared_ptr<netgen::Mesh> ngmesh, iarray vertices, darray directions, std::string crack_name,
            bool skip_neighbours, double enter_angle, bool single_edge_tips, int aim_edges)
        {
          auto t0 = std::chrono::steady_clock::now();
          MeshArrays a = ExtractArrays(*ngmesh);
          size_t n = vertices.ndim() == 1 ? vertices.shape(0) : 0;
          if (vertices.ndim() != 1)
            throw Exception("ngfracture.CrackSplit: vertices must be a 1D integer array");
          if (directions.ndim() != 2 || size_t(directions.shape(0)) != n || directions.shape(1) != 2)
            throw Exception("ngfracture.CrackSplit: directions must have shape (len(vertices), 2) = (" +
                            ToString(n) + ", 2)");
          CrackSplitter split(a.points.data(), a.nv, a.trigs.data(), a.ne, a.segs.data(), a.ns);
          if (!(enter_angle >= 0 && enter_angle < M_PI / 2))
            throw Exception("ngfracture.CrackSplit: enter_angle must be in [0, pi/2), got " + ToString(enter_angle));
          if (aim_edges < 0)
            throw Exception("ngfracture.CrackSplit: aim_edges must be >= 0, got " + ToString(aim_edges));
          split.aim_edges = aim_edges;
          split.Run(vertices.data(), directions.data(), int(n), skip_neighbours, enter_angle, single_edge_tips);
          split.Finish();
          auto t1 = std::chrono::steady_clock::now();
          auto newmesh = RebuildMesh(*ngmesh, split, crack_name);
          auto t2 = std::chrono::steady_clock::now();

          py::dict rec;
          rec["vertex"] = ToNumpy(split.rec_vertex);
          rec["rule"] = ToNumpy(split.rec_rule);
          std::vector<int> eoff = split.rec_edge_begin; eoff.push_back(int(split.rec_edges.size()/2));
          std::vector<int> noff = split.rec_new_begin; noff.push_back(int(split.rec_new.size()));
          rec["edge_offsets"] = ToNumpy(eoff);
          rec["edges"] = ToNumpy(split.rec_edges, 2);
          rec["new_offsets"] = ToNumpy(noff);
          rec["new_vertices"] = ToNumpy(split.rec_new);
          py::dict res;
          res["ngmesh"] = newmesh;
          res["record"] = rec;
          res["parent"] = ToNumpy(split.parent);
          res["trigs"] = ToNumpy(split.trigs, 3);
          res["crack_segments"] = ToNumpy(split.crack_segs, 2);
          res["fragment"] = ToNumpy(split.fragment);
          res["nfragments"] = split.nfragments;
          res["t_split"] = Seconds(t0, t1);
          res["t_netgen"] = Seconds(t1, t2);
          return res;
        },
        py::arg("ngmesh"), py::arg("vertices"), py::arg("directions"), py::arg("crack_name") = "crack",
        py::arg("skip_neighbours") = false, py::arg("enter_angle") = 0.0, py::arg("single_edge_tips") = false,
        py::arg("aim_edges") = 0,
        R"doc(Split vertices of a 2D netgen mesh along the edges most orthogonal to a direction.

Low-level: use ngfracture.crack.split_vertices.

Parameters
----------
ngmesh : netgen.meshing.Mesh
    2D mesh of linear triangles (reference configuration).
vertices : numpy.ndarray
    Vertex numbers (0-based) in processing order.
directions : numpy.ndarray
    Shape (len(vertices), 2), maximum strain direction of each vertex.
crack_name : str
    Boundary name of the new boundary segments.
skip_neighbours : bool
    Skip a vertex that shares a triangle with a vertex split earlier in this pass.
enter_angle : float
    Radians in [0, pi/2); 0: the paper's rule 2a. Else a boundary vertex whose best edge is
    a boundary edge cuts its best interior edge if that is within enter_angle of the crack
    line (rule 2c).
single_edge_tips : bool
    A crack tip cuts one edge, the interior edge nearest the half of the crack line away
    from the crack (rule tip1), instead of two (rule 1).

Returns
-------
dict
    ngmesh (the new netgen mesh), parent (new vertex -> old vertex), record (dict of
    arrays), trigs, crack_segments, fragment (per triangle), nfragments, t_split, t_netgen.
)doc");

  m.def("CrackTransferElementDofs",
        [] (shared_ptr<FESpace> fes_old, shared_ptr<FESpace> fes_new, darray vold)
        {
          size_t ne = fes_old->GetMeshAccess()->GetNE(VOL);
          if (fes_new->GetMeshAccess()->GetNE(VOL) != ne)
            throw Exception("ngfracture.CrackTransferElementDofs: the meshes have different element counts");
          if (vold.ndim() != 1 || size_t(vold.shape(0)) != fes_old->GetNDof())
            throw Exception("ngfracture.CrackTransferElementDofs: vector length does not match the old space");
          py::array_t<double> out(fes_new->GetNDof());
          double * dst = out.mutable_data();
          const double * src = vold.data();
          std::fill(dst, dst + fes_new->GetNDof(), 0.0);
          Array<DofId> dold, dnew;
          for (size_t e = 0; e < ne; e++)
            {
              fes_old->GetDofNrs(ElementId(VOL, e), dold);
              fes_new->GetDofNrs(ElementId(VOL, e), dnew);
              if (dold.Size() != dnew.Size())
                throw Exception("ngfracture.CrackTransferElementDofs: element " + ToString(e) +
                                " has a different number of dofs");
              for (size_t i = 0; i < dold.Size(); i++)
                if (IsRegularDof(dold[i]) && IsRegularDof(dnew[i]))
                  dst[dnew[i]] = src[dold[i]];
            }
          return out;
        },
        py::arg("fes_old"), py::arg("fes_new"), py::arg("vec_old"),
        R"doc(Copy every element's dofs from an old to a split mesh (same elements, same order).

Exact for H1-type spaces of order <= 2, whose local dofs do not depend on the global
vertex numbers.

Parameters
----------
fes_old, fes_new : ngsolve.FESpace
vec_old : numpy.ndarray

Returns
-------
numpy.ndarray
    The vector on fes_new.
)doc");
}
