// Python bindings of the rows between copies of a point (copies3d.hpp).
// Low level: ngfracture/contact/copies3d.py and wedges3d.py make the arrays and are the
// documented API; the bindings check shapes and vertex and face numbers.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "binding_checks.hpp"
#include "copies3d.hpp"

namespace py = pybind11;
using namespace ngfracture;
using namespace ngfracture::bindings;

namespace
{
  // every face's run of faces on its points, [key_start, key_start + key_count), inside
  // key_order (nf entries)
  void CheckKeyRuns (const char * fn, const LArr & key_start, const LArr & key_count, int64_t nf)
  {
    for (int64_t f = 0; f < nf; f++)
      if (key_start.data()[f] < 0 || key_count.data()[f] < 0 || key_start.data()[f] + key_count.data()[f] > nf)
        throw std::invalid_argument(std::string("ngfracture.") + fn + ": key_start and key_count of face "
                                    + std::to_string(f) + " leave key_order");
  }

  // both faces fw[p] (m x 2) of every pair hold both ends of edge[p] (m x 2); `name` the
  // edge's name in the message ("a" or "b": the array <name>_faces)
  void CheckFacesHoldEdges (const char * fn, const LArr & faces, const LArr & fw, const LArr & edge,
                            const std::string & name)
  {
    for (py::ssize_t p = 0; p < edge.shape(0); p++)
      for (int k = 0; k < 2; k++)
        {
          const int64_t * f = faces.data() + 3 * fw.data()[2 * p + k];
          for (int e = 0; e < 2; e++)
            {
              int64_t v = edge.data()[2 * p + e];
              if (f[0] != v && f[1] != v && f[2] != v)
                throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + "_faces["
                                            + std::to_string(p) + ", " + std::to_string(k)
                                            + "] does not hold edge " + name);
            }
        }
  }
}

void ExportCopies3d (py::module & m)
{
  m.def("PartnerAt",
        [] (LArr faces, LArr key_order, LArr key_start, LArr key_count, LArr face, LArr vertex)
        {
          const char * fn = "PartnerAt";
          Check(fn, "faces", faces, 2, 3);
          int64_t nf = faces.shape(0);
          Check(fn, "key_order", key_order, 1, 0, nf);
          Check(fn, "key_start", key_start, 1, 0, nf);
          Check(fn, "key_count", key_count, 1, 0, nf);
          Check(fn, "face", face, 1, 0);
          Check(fn, "vertex", vertex, 1, 0, face.shape(0));
          CheckRange(fn, "key_order", key_order, nf);
          CheckRange(fn, "face", face, nf);
          CheckKeyRuns(fn, key_start, key_count, nf);
          py::array_t<int64_t> out(face.shape(0));
          {
            py::gil_scoped_release release;
            PartnerAt(face.shape(0), faces.data(), key_order.data(), key_start.data(), key_count.data(), face.data(),
                      vertex.data(), out.mutable_data());
          }
          return out;
        },
        py::arg("faces"), py::arg("key_order"), py::arg("key_start"), py::arg("key_count"), py::arg("face"),
        py::arg("vertex"),
        R"doc(For every (face, vertex): the face on the same three points with the vertex as a corner, or -1.

Returns
-------
numpy.ndarray of int64
    The first such face in key order (copies3d._partner_at's numpy loop).
)doc");

  m.def("FoundRowsAtCopies",
        [] (LArr faces, LArr point, LArr vertex_fragment, LArr key_order, LArr key_start, LArr key_count, DArr unit,
            LArr slave, LArr master, LArr face, DArr bary, DArr normal, DArr g)
        {
          const char * fn = "FoundRowsAtCopies";
          Check(fn, "faces", faces, 2, 3);
          int64_t nf = faces.shape(0), nv = point.shape(0), m = slave.shape(0);
          Check(fn, "point", point, 1, 0);
          Check(fn, "vertex_fragment", vertex_fragment, 1, 0, nv);
          Check(fn, "key_order", key_order, 1, 0, nf);
          Check(fn, "key_start", key_start, 1, 0, nf);
          Check(fn, "key_count", key_count, 1, 0, nf);
          Check(fn, "unit", unit, 2, 3, nf);
          Check(fn, "slave", slave, 1, 0);
          Check(fn, "master", master, 2, 3, m);
          Check(fn, "face", face, 1, 0, m);
          Check(fn, "bary", bary, 2, 3, m);
          Check(fn, "normal", normal, 2, 3, m);
          Check(fn, "g", g, 1, 0, m);
          CheckRange(fn, "faces", faces, nv);
          CheckRange(fn, "key_order", key_order, nf);
          CheckRange(fn, "slave", slave, nv);
          CheckRange(fn, "master", master, nv);
          CheckRange(fn, "face", face, nf);
          CheckKeyRuns(fn, key_start, key_count, nf);
          // the outputs: copies of the rows' arrays, changed in place
          LArr S(m), M({ m, int64_t(3) }), Fc(m);
          DArr B({ m, int64_t(3) }), N({ m, int64_t(3) }), G(m);
          py::array_t<bool> at(m);
          std::copy(slave.data(), slave.data() + m, S.mutable_data());
          std::copy(master.data(), master.data() + 3 * m, M.mutable_data());
          std::copy(face.data(), face.data() + m, Fc.mutable_data());
          std::copy(bary.data(), bary.data() + 3 * m, B.mutable_data());
          std::copy(normal.data(), normal.data() + 3 * m, N.mutable_data());
          std::copy(g.data(), g.data() + m, G.mutable_data());
          {
            py::gil_scoped_release release;
            FoundRowsAtCopies(m, faces.data(), point.data(), vertex_fragment.data(), key_order.data(),
                              key_start.data(), key_count.data(), unit.data(), S.mutable_data(), M.mutable_data(),
                              Fc.mutable_data(), B.mutable_data(), N.mutable_data(), G.mutable_data(),
                              reinterpret_cast<uint8_t *>(at.mutable_data()));
          }
          return py::make_tuple(S, M, Fc, B, N, G, at);
        },
        py::arg("faces"), py::arg("point"), py::arg("vertex_fragment"), py::arg("key_order"), py::arg("key_start"),
        py::arg("key_count"), py::arg("unit"), py::arg("slave"), py::arg("master"), py::arg("face"), py::arg("bary"),
        py::arg("normal"), py::arg("g"),
        R"doc(The rows of copies3d.found_rows_at_copies (new arrays) and which are at a copy.

Returns
-------
tuple
    slave, master, face, bary, normal, g and at_copy (bool), bit for bit the numpy
    computation.
)doc");

  m.def("FoldedIncidences",
        [] (LArr faces, LArr point, LArr copies, LArr vertex_fragment, LArr incident, LArr incidence, LArr face_key,
            LArr vertex_keys, DArr unit, py::array_t<bool, py::array::c_style | py::array::forcecast> pick,
            LArr slave, LArr master, DArr bary, DArr normal, LArr tied, double kink)
        {
          const char * fn = "FoldedIncidences";
          Check(fn, "faces", faces, 2, 3);
          int64_t nf = faces.shape(0), nv = point.shape(0), m = slave.shape(0);
          Check(fn, "point", point, 1, 0);
          Check(fn, "copies", copies, 1, 0);
          Check(fn, "vertex_fragment", vertex_fragment, 1, 0, nv);
          Check(fn, "incident", incident, 1, 0, 3 * nf);
          Check(fn, "incidence", incidence, 1, 0, 3 * nf);
          Check(fn, "face_key", face_key, 1, 0, nf);
          Check(fn, "vertex_keys", vertex_keys, 1, 0);
          Check(fn, "unit", unit, 2, 3, nf);
          Check(fn, "pick", pick, 1, 0, m);
          Check(fn, "slave", slave, 1, 0);
          Check(fn, "master", master, 2, 3, m);
          Check(fn, "bary", bary, 2, 3, m);
          Check(fn, "normal", normal, 2, 3, m);
          Check(fn, "tied", tied, 1, 0);
          CheckRange(fn, "faces", faces, nv);
          for (int64_t v = 0; v < nv; v++)
            if (point.data()[v] < -1 || point.data()[v] >= copies.shape(0))
              throw std::invalid_argument("ngfracture.FoldedIncidences: point has an entry outside [-1, "
                                          + std::to_string(copies.shape(0)) + ")");
          CheckSorted(fn, "incident", incident);
          CheckSorted(fn, "vertex_keys", vertex_keys);
          CheckSorted(fn, "tied", tied);
          CheckRange(fn, "incident", incident, nv);
          CheckRange(fn, "incidence", incidence, 3 * nf);
          CheckRange(fn, "slave", slave, nv);
          CheckRange(fn, "master", master, nv);
          FoldInput in { nv, nf, faces.data(), point.data(), copies.data(), vertex_fragment.data(), incident.data(),
                         incidence.data(), face_key.data(), vertex_keys.data(), vertex_keys.shape(0), unit.data() };
          std::vector<int64_t> s, f, c;
          {
            py::gil_scoped_release release;
            FoldedIncidences(in, m, reinterpret_cast<const uint8_t *>(pick.data()), slave.data(), master.data(),
                             bary.data(), normal.data(), tied.data(), tied.shape(0), kink, s, f, c);
          }
          return py::make_tuple(ToNumpy(s), ToNumpy(f), ToNumpy(c));
        },
        py::arg("faces"), py::arg("point"), py::arg("copies"), py::arg("vertex_fragment"), py::arg("incident"),
        py::arg("incidence"), py::arg("face_key"), py::arg("vertex_keys"), py::arg("unit"), py::arg("pick"),
        py::arg("slave"), py::arg("master"), py::arg("bary"), py::arg("normal"), py::arg("tied"), py::arg("kink"),
        R"doc(The incidences of copies3d.folded_rows_at_copies: its rows' slaves, faces and corners.

Returns
-------
slave, face, corner : numpy.ndarray of int64
    By pair code, then the faces' incidence order at the copy.
)doc");

  m.def("BehindPartnerGaps",
        [] (DArr x, LArr faces, LArr slave, LArr face, LArr corner, double tol)
        {
          const char * fn = "BehindPartnerGaps";
          Check(fn, "x", x, 2, 3);
          Check(fn, "faces", faces, 2, 3);
          Check(fn, "slave", slave, 1, 0);
          Check(fn, "face", face, 1, 0, slave.shape(0));
          Check(fn, "corner", corner, 1, 0, slave.shape(0));
          int64_t nv = x.shape(0);
          CheckRange(fn, "faces", faces, nv);
          CheckRange(fn, "slave", slave, nv);
          CheckRange(fn, "face", face, faces.shape(0));
          CheckRange(fn, "corner", corner, 3);
          std::vector<int64_t> hit;
          std::vector<double> gap;
          {
            py::gil_scoped_release release;
            BehindPartnerGaps(slave.shape(0), nv, x.data(), faces.data(), slave.data(), face.data(), corner.data(),
                              tol, hit, gap);
          }
          return py::make_tuple(ToNumpy(hit), ToNumpy(gap));
        },
        py::arg("x"), py::arg("faces"), py::arg("slave"), py::arg("face"), py::arg("corner"), py::arg("tol"),
        R"doc(The partner incidences of the pairs of copies behind a partner face's plane deeper than tol.

Returns
-------
hit : numpy.ndarray of int64
    Every incidence of a pair (slave, copy) with a gap below -tol, increasing.
gap : numpy.ndarray
    Their gaps n_f . (x_s - x_t) at x (0 where the copies meet), bit for bit the numpy
    computation of copies3d.behind_partner_rows.
)doc");

  m.def("WedgeInside",
        [] (DArr x, LArr faces, LArr a, LArr b, LArr b_faces, LArr a_faces, double tol)
        {
          const char * fn = "WedgeInside";
          Check(fn, "x", x, 2, 3);
          Check(fn, "faces", faces, 2, 3);
          Check(fn, "a", a, 2, 2);
          Check(fn, "b", b, 2, 2, a.shape(0));
          Check(fn, "b_faces", b_faces, 2, 2, a.shape(0));
          Check(fn, "a_faces", a_faces, 2, 2, a.shape(0));
          int64_t nv = x.shape(0), nf = faces.shape(0);
          CheckRange(fn, "faces", faces, nv);
          CheckRange(fn, "a", a, nv);
          CheckRange(fn, "b", b, nv);
          CheckRange(fn, "b_faces", b_faces, nf);
          CheckRange(fn, "a_faces", a_faces, nf);
          CheckFacesHoldEdges(fn, faces, b_faces, b, "b");
          CheckFacesHoldEdges(fn, faces, a_faces, a, "a");
          std::vector<int64_t> pair, nearer;
          std::vector<double> gap;
          {
            py::gil_scoped_release release;
            WedgeInside(a.shape(0), x.data(), faces.data(), a.data(), b.data(), b_faces.data(), a_faces.data(), tol,
                        pair, nearer, gap);
          }
          py::array_t<double> G = ToNumpy(gap, 2);
          if (gap.empty())
            G = py::array_t<double>(std::vector<py::ssize_t>{ 0, 2 });
          return py::make_tuple(ToNumpy(pair), ToNumpy(nearer), G);
        },
        py::arg("x"), py::arg("faces"), py::arg("a"), py::arg("b"), py::arg("b_faces"), py::arg("a_faces"),
        py::arg("tol"),
        R"doc(The diagonal edge pairs whose wedges overlap deeper than tol somewhere along the edge.

Returns
-------
pair : numpy.ndarray of int64
    The pairs inside, increasing.
nearer : numpy.ndarray of int64
    The face whose rows hold them apart: 0 or 1 one of B's (a's ends its slaves), 2 or 3
    one of A's (b's ends its slaves).
gap : numpy.ndarray, shape (k, 2)
    The gaps of the slaves to that face's plane at x, bit for bit the numpy computation
    of wedges3d.wedge_rows.
)doc");

  m.def("ReflexWedgeGaps",
        [] (DArr x, LArr faces, LArr a, LArr b, LArr b_faces, py::array_t<bool, py::array::c_style | py::array::forcecast> partner,
            double tol)
        {
          const char * fn = "ReflexWedgeGaps";
          Check(fn, "x", x, 2, 3);
          Check(fn, "faces", faces, 2, 3);
          Check(fn, "a", a, 2, 2);
          Check(fn, "b", b, 2, 2, a.shape(0));
          Check(fn, "b_faces", b_faces, 2, 2, a.shape(0));
          if (partner.ndim() != 2 || partner.shape(0) != a.shape(0) || partner.shape(1) != 2)
            throw std::invalid_argument("ngfracture.ReflexWedgeGaps: partner must have shape (m, 2) like a");
          int64_t nv = x.shape(0), nf = faces.shape(0);
          CheckRange(fn, "faces", faces, nv);
          CheckRange(fn, "a", a, nv);
          CheckRange(fn, "b", b, nv);
          CheckRange(fn, "b_faces", b_faces, nf);
          CheckFacesHoldEdges(fn, faces, b_faces, b, "b");
          std::vector<int64_t> pair;
          std::vector<double> gap;
          {
            py::gil_scoped_release release;
            ReflexWedgeGaps(a.shape(0), x.data(), faces.data(), a.data(), b.data(), b_faces.data(),
                            reinterpret_cast<const uint8_t *>(partner.data()), tol, pair, gap);
          }
          py::array_t<double> G = ToNumpy(gap, 4);
          if (gap.empty())
            G = py::array_t<double>(std::vector<py::ssize_t>{ 0, 4 });
          return py::make_tuple(ToNumpy(pair), G);
        },
        py::arg("x"), py::arg("faces"), py::arg("a"), py::arg("b"), py::arg("b_faces"), py::arg("partner"),
        py::arg("tol"),
        R"doc(The pairs of copies of an edge whose a lies behind a non-partner face of B's reflex wedge deeper than tol.

Returns
-------
pair : numpy.ndarray of int64
    The pairs hit, increasing.
gap : numpy.ndarray, shape (k, 4)
    The gaps n_k . (x_a_e - x_b_e) of a's ends to the planes of b's two faces at x, in
    the order (k, e) = (0, 0), (0, 1), (1, 0), (1, 1).
)doc");
}
