// Python bindings of the 3D collision kernels (orient3d, penetrations between fragments).
// Low level: ngfracture/contact/collision3d.py validates the input and is the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "collision3d.hpp"
#include "predicates.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using IArr = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;

  void Check (const char * fn, const char * name, const py::array & a, int ndim, py::ssize_t cols,
              py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has the wrong shape");
  }

  // (ids (k, 5), geometry (k, 10), stats) of the penetrations, as DetectPenetrations3d returns them
  py::tuple PenetrationTuple (const std::vector<Penetration3> & pen, const Collision3Stats & st)
  {
    std::vector<int32_t> ids;
    std::vector<double> geo;
    for (auto & p : pen)
      {
        ids.insert(ids.end(), { p.vertex, p.fragment, p.tet, p.face, p.twin });
        geo.insert(geo.end(), p.proj, p.proj + 3);
        geo.insert(geo.end(), p.bary, p.bary + 3);
        geo.insert(geo.end(), p.normal, p.normal + 3);
        geo.push_back(p.gap);
      }
    py::dict stats;
    stats["cell"] = st.cell; stats["boundary_vertices"] = st.boundary_vertices;
    stats["box_tests"] = st.box_tests; stats["exact_tests"] = st.exact_tests;
    stats["closed_seams"] = st.closed_seams;
    auto I = ToNumpy(ids, 5);
    auto G = ToNumpy(geo, 10);
    return py::make_tuple(I.reshape({ py::ssize_t(pen.size()), py::ssize_t(5) }),
                          G.reshape({ py::ssize_t(pen.size()), py::ssize_t(10) }), stats);
  }
}

void ExportCollision3d (py::module & m)
{
  py::class_<PenetrationDetector3>(m, "PenetrationDetector3d",
                                   "DetectPenetrations3d for one mesh at many current positions: "
                                   "the connectivity's work done once, on copies of the arrays.")
    .def(py::init([] (DArr X, IArr tets, IArr faces, IArr fragment)
                  {
                    Check("PenetrationDetector3d", "points", X, 2, 3);
                    Check("PenetrationDetector3d", "tets", tets, 2, 4);
                    Check("PenetrationDetector3d", "faces", faces, 2, 3);
                    Check("PenetrationDetector3d", "fragment", fragment, 1, 0, tets.shape(0));
                    TetMesh3 mesh { X.data(), X.data(), tets.data(), faces.data(), fragment.data(),
                                    X.shape(0), tets.shape(0), faces.shape(0) };
                    py::gil_scoped_release release;
                    return std::make_unique<PenetrationDetector3>(mesh);
                  }),
         py::arg("points"), py::arg("tets"), py::arg("faces"), py::arg("fragment"))
    .def("detect",
         [] (const PenetrationDetector3 & self, DArr x)
         {
           Check("PenetrationDetector3d.detect", "current", x, 2, 3, self.NumVertices());
           std::vector<Penetration3> pen;
           Collision3Stats st;
           {
             py::gil_scoped_release release;
             pen = self.Detect(x.data(), &st);
           }
           return PenetrationTuple(pen, st);
         },
         py::arg("current"),
         "(ids, geometry, stats) of DetectPenetrations3d at the current coordinates (nv, 3).");

  m.def("Orient3d",
        [] (DArr a, DArr b, DArr c, DArr d, bool exact_only)
        {
          for (auto [arr, name] : { std::pair<DArr*, const char*>{ &a, "a" }, { &b, "b" }, { &c, "c" }, { &d, "d" } })
            Check("Orient3d", name, *arr, 2, 3, a.shape(0));
          size_t n = a.shape(0);
          py::array_t<int8_t> out(n);
          auto o = out.mutable_data();
          const double * pa = a.data(), * pb = b.data(), * pc = c.data(), * pd = d.data();
          {
            py::gil_scoped_release release;
            for (size_t i = 0; i < n; i++)
              o[i] = int8_t(exact_only ? Orient3dExactSign(pa+3*i, pb+3*i, pc+3*i, pd+3*i)
                                       : Orient3dSign(pa+3*i, pb+3*i, pc+3*i, pd+3*i));
          }
          return out;
        },
        py::arg("a"), py::arg("b"), py::arg("c"), py::arg("d"), py::arg("exact_only") = false,
        R"doc(Exact sign of det[a-d, b-d, c-d] for rows of (n, 3) arrays.

Parameters
----------
a, b, c, d : numpy.ndarray
    Shape (n, 3), points.
exact_only : bool
    Skip the floating-point filter (the exact expansion for every row; for tests).

Returns
-------
numpy.ndarray of int8
    Shape (n,): +1, 0 (coplanar) or -1; a positively oriented tetrahedron gives -1.

Raises
------
ValueError
    If a shape is not (n, 3) with the same n.
)doc");

  m.def("DetectPenetrations3d",
        [] (DArr X, DArr x, IArr tets, IArr faces, IArr fragment)
        {
          Check("DetectPenetrations3d", "points", X, 2, 3);
          Check("DetectPenetrations3d", "current", x, 2, 3, X.shape(0));
          Check("DetectPenetrations3d", "tets", tets, 2, 4);
          Check("DetectPenetrations3d", "faces", faces, 2, 3);
          Check("DetectPenetrations3d", "fragment", fragment, 1, 0, tets.shape(0));
          TetMesh3 mesh { X.data(), x.data(), tets.data(), faces.data(), fragment.data(),
                          X.shape(0), tets.shape(0), faces.shape(0) };
          std::vector<Penetration3> pen;
          Collision3Stats st;
          {
            py::gil_scoped_release release;
            pen = DetectPenetrations3(mesh, &st);
          }
          return PenetrationTuple(pen, st);
        },
        py::arg("points"), py::arg("current"), py::arg("tets"), py::arg("faces"), py::arg("fragment"),
        R"doc(Boundary vertices in the closed volume of another fragment, with their master faces.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3), reference coordinates (twins: bitwise-equal points).
current : numpy.ndarray
    Shape (nv, 3), current coordinates.
tets : numpy.ndarray of int32
    Shape (ne, 4).
faces : numpy.ndarray of int32
    Shape (nf, 3), boundary triangles, outward.
fragment : numpy.ndarray of int32
    Shape (ne,), fragment per tetrahedron.

Returns
-------
(ids, geometry, stats)
    ids (k, 5): vertex, fragment, tet, face, twin; geometry (k, 10): projection (3),
    barycentrics (3), unit face normal (3), gap; stats: dict of search counts.

Raises
------
ValueError
    On wrong shapes, indices out of range, a face of no tetrahedron, or a vertex in two
    fragments.
)doc");
}
