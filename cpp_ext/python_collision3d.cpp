// Python bindings of the 3D collision kernels (orient3d, penetrations between fragments).
// Low level: ngfracture/contact/collision3d.py validates the input and is the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "collision3d.hpp"
#include "predicates.hpp"
#include "contact_rows3d.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using IArr = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  using LArr = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;

  void Check (const char * fn, const char * name, const py::array & a, int ndim, py::ssize_t cols,
              py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has the wrong shape");
  }

  // every slave and master vertex in [0, nv)
  void CheckVertices (const char * fn, const py::array_t<int64_t> & slave, const py::array_t<int64_t> & master,
                      int64_t nv)
  {
    for (py::ssize_t r = 0; r < slave.shape(0); r++)
      {
        bool bad = slave.data()[r] < 0 || slave.data()[r] >= nv;
        for (int l = 0; l < 3; l++)
          bad |= master.data()[3 * r + l] < 0 || master.data()[3 * r + l] >= nv;
        if (bad)
          throw std::invalid_argument(std::string("ngfracture.") + fn + ": row " + std::to_string(r)
                                      + " has a vertex outside [0, nv)");
      }
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

  m.def("GapMatrixCsr3d",
        [] (LArr slave, LArr master, DArr bary, DArr normal, int64_t nv) -> py::object
        {
          py::ssize_t rows = slave.shape(0);
          Check("GapMatrixCsr3d", "slave", slave, 1, 0);
          Check("GapMatrixCsr3d", "master", master, 2, 3, rows);
          Check("GapMatrixCsr3d", "bary", bary, 2, 3, rows);
          Check("GapMatrixCsr3d", "normal", normal, 2, 3, rows);
          if (3 * nv >= (int64_t(1) << 31) || 12 * int64_t(rows) >= (int64_t(1) << 31))
            throw std::invalid_argument("ngfracture.GapMatrixCsr3d: too many columns or nonzeros for int32");
          std::vector<int32_t> indptr, indices;
          std::vector<double> data;
          bool distinct;
          {
            py::gil_scoped_release release;
            distinct = GapMatrixCsr3(rows, nv, slave.data(), master.data(), bary.data(), normal.data(),
                                     indptr, indices, data);
          }
          if (!distinct)
            return py::none();
          return py::make_tuple(ToNumpy(data), ToNumpy(indices), ToNumpy(indptr));
        },
        py::arg("slave"), py::arg("master"), py::arg("bary"), py::arg("normal"), py::arg("nv"),
        R"doc(CSR arrays of the node-to-face gap rows (rows3d.face_gap_rows' C), columns sorted.

Row r is n_r . (u_s - sum_l b_l u_l) over the dofs comp * nv + v; exact zeros are left
out. Bit for bit the numpy assembly of ngfracture/contact/rows3d.py.

Returns
-------
tuple or None
    (data, indices int32, indptr int32); None if a row repeats a vertex (duplicates to sum).

Raises
------
ValueError
    On shapes that do not match, or sizes beyond int32 indices.
)doc");

  m.def("GapOffsets3d",
        [] (DArr X, LArr slave, LArr master, DArr bary, DArr normal)
        {
          py::ssize_t rows = slave.shape(0);
          Check("GapOffsets3d", "points", X, 2, 3);
          Check("GapOffsets3d", "slave", slave, 1, 0);
          Check("GapOffsets3d", "master", master, 2, 3, rows);
          Check("GapOffsets3d", "bary", bary, 2, 3, rows);
          Check("GapOffsets3d", "normal", normal, 2, 3, rows);
          CheckVertices("GapOffsets3d", slave, master, X.shape(0));
          py::array_t<double> g(rows);
          double * pg = g.mutable_data();
          {
            py::gil_scoped_release release;
            GapOffsets3(rows, X.data(), slave.data(), master.data(), bary.data(), normal.data(), pg);
          }
          return g;
        },
        py::arg("points"), py::arg("slave"), py::arg("master"), py::arg("bary"), py::arg("normal"),
        R"doc(The gaps g = n . (X_s - sum_l b_l X_l) of node-to-face rows (rows3d._gap_offset).

Bit for bit the numpy computation (einsum's order of the sums).

Raises
------
ValueError
    On shapes that do not match or vertices out of range.
)doc");

  m.def("RelineariseRows3d",
        [] (DArr X, DArr x, LArr slave, LArr master, DArr bary, DArr normal)
        {
          py::ssize_t rows = slave.shape(0);
          Check("RelineariseRows3d", "points", X, 2, 3);
          Check("RelineariseRows3d", "current", x, 2, 3, X.shape(0));
          Check("RelineariseRows3d", "slave", slave, 1, 0);
          Check("RelineariseRows3d", "master", master, 2, 3, rows);
          Check("RelineariseRows3d", "bary", bary, 2, 3, rows);
          Check("RelineariseRows3d", "normal", normal, 2, 3, rows);
          CheckVertices("RelineariseRows3d", slave, master, X.shape(0));
          py::array_t<double> b({ rows, py::ssize_t(3) }), n({ rows, py::ssize_t(3) }), dist(rows), g(rows);
          double * pb = b.mutable_data(), * pn = n.mutable_data(), * pd = dist.mutable_data(), * pg = g.mutable_data();
          {
            py::gil_scoped_release release;
            RelineariseRows3(rows, X.data(), x.data(), slave.data(), master.data(), bary.data(), normal.data(),
                             pb, pn, pd, pg);
          }
          return py::make_tuple(b, n, dist, g);
        },
        py::arg("points"), py::arg("current"), py::arg("slave"), py::arg("master"), py::arg("bary"),
        py::arg("normal"),
        R"doc(Node-to-face rows re-linearised at the current points (rows3d.relinearise_node_to_face).

Bit for bit the numpy computation: the master face's normal (keeping its side) and the
slave's projection clipped to the face, kept where the face is squeezed below 1e-16 of its
reference area or the row is anchored at a copy of the slave.

Returns
-------
tuple
    (bary (m, 3), normal (m, 3), dist (m,), g (m,)).

Raises
------
ValueError
    On shapes that do not match or vertices out of range.
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
