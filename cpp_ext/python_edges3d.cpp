// Python bindings of the crossing boundary edges between fragments (edge_crossings3d.hpp).
// Low level: ngfracture/contact/edge_crossings3d.py validates the input and is the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "edge_crossings3d.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using IArr = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;

  void CheckShape (const char * name, const py::array & a, int ndim, py::ssize_t cols, py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.EdgeCrossingDetector3d: ") + name + " has the wrong shape");
  }

  // rows of two ints as an (m, 2) int64 array
  py::array_t<int64_t> Pairs (const std::vector<int32_t> & v)
  {
    std::vector<int64_t> w(v.begin(), v.end());
    py::array_t<int64_t> out({ py::ssize_t(w.size() / 2), py::ssize_t(2) });
    std::copy(w.begin(), w.end(), out.mutable_data());
    return out;
  }
}

void ExportEdges3d (py::module & m)
{
  py::class_<EdgeCrossingDetector3>(m, "EdgeCrossingDetector3d",
                                    "Boundary edges of the fragments and the pairs of them that interlock; "
                                    "the edges and the faces at them made once, on copies of the arrays.")
    .def(py::init([] (int64_t nv, IArr faces, IArr face_fragment, IArr point, bool across)
                  {
                    CheckShape("faces", faces, 2, 3);
                    CheckShape("face_fragment", face_fragment, 1, 0, faces.shape(0));
                    CheckShape("point", point, 1, 0, nv);
                    py::gil_scoped_release release;
                    return std::make_unique<EdgeCrossingDetector3>(nv, faces.data(), faces.shape(0),
                                                                   face_fragment.data(), point.data(), across);
                  }),
         py::arg("nv"), py::arg("faces"), py::arg("face_fragment"), py::arg("point"), py::arg("across"))
    .def_property_readonly("edges", [] (const EdgeCrossingDetector3 & d) { return Pairs(d.Edges()); },
                           "(nE, 2) int64: the boundary edges, rows increasing, in lexicographic order.")
    .def_property_readonly("edge_face_ptr", [] (const EdgeCrossingDetector3 & d) { return ToNumpy(d.EdgeFacePtr()); },
                           "(nE + 1,) int64: CSR pointers of the faces at every edge.")
    .def_property_readonly("edge_faces", [] (const EdgeCrossingDetector3 & d)
                           {
                             const auto & f = d.EdgeFaces();
                             return ToNumpy(std::vector<int64_t>(f.begin(), f.end()));
                           },
                           "int64: the faces at every edge, increasing within an edge.")
    .def_property_readonly("face_edges", [] (const EdgeCrossingDetector3 & d)
                           {
                             const auto & f = d.FaceEdges();
                             return ToNumpy(std::vector<int64_t>(f.begin(), f.end()), 3);
                           },
                           "(nf, 3) int64: the edges (f0, f1), (f1, f2), (f2, f0) of every face.")
    .def("detect", [] (const EdgeCrossingDetector3 & d, DArr x, py::object skip)
         {
           CheckShape("current points", x, 2, 3, d.NumVertices());
           py::array_t<uint8_t, py::array::c_style | py::array::forcecast> mask;
           if (!skip.is_none())
             {
               mask = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(skip);
               if (!mask) throw std::invalid_argument("ngfracture.EdgeCrossingDetector3d: skip is not an array");
               CheckShape("skip", mask, 1, 0, d.NumVertices());
             }
           const uint8_t * skipped = skip.is_none() ? nullptr : mask.data();
           EdgeCrossingStats st;
           std::vector<int32_t> pairs;
           {
             py::gil_scoped_release release;
             pairs = d.Detect(x.data(), &st, skipped);
           }
           py::dict stats;
           stats["cell"] = st.cell; stats["box_tests"] = st.box_tests;
           stats["exact_tests"] = st.exact_tests; stats["pierces"] = st.pierces;
           stats["closed_edges"] = st.closed_edges; stats["skipped_edges"] = st.skipped_edges;
           return py::make_tuple(Pairs(pairs), stats);
         }, py::arg("x"), py::arg("skip") = py::none(),
         R"doc(The interlocking pairs of edges at current points x (nv, 3).

Returns
-------
(pairs, stats)
    pairs (m, 2) int64, i < j, unique, lexicographic; stats dict: cell, box_tests,
    exact_tests, pierces, closed_edges, skipped_edges.)doc");

  m.def("SegmentPiercesTriangle",
        [] (DArr p, DArr q, DArr a, DArr b, DArr c)
        {
          for (auto * v : { &p, &q, &a, &b, &c })
            CheckShape("point", *v, 1, 0, 3);
          return SegmentPiercesTriangle(p.data(), q.data(), a.data(), b.data(), c.data());
        },
        py::arg("p"), py::arg("q"), py::arg("a"), py::arg("b"), py::arg("c"),
        "Exact: segment pq pierces triangle abc (p, q strictly on opposite sides, the line strictly inside).");
}
