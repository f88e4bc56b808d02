// Python bindings of the mesh-only set-up of 3D contact (contact_setup3d.hpp).
// Low level: ngfracture/contact/setup3d.py, kinks3d.py and junctions3d.py validate the
// input, keep the numpy computations as the reference and are the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "binding_checks.hpp"
#include "contact_setup3d.hpp"

namespace py = pybind11;
using namespace ngfracture;
using namespace ngfracture::bindings;

void ExportSetup3d (py::module & m)
{
  m.def("SortedTripleRanks",
        [] (LArr rows, int64_t bound)
        {
          Check("SortedTripleRanks", "rows", rows, 2, 3);
          CheckRange("SortedTripleRanks", "rows", rows, bound);
          int64_t n = rows.shape(0);
          std::vector<int64_t> S, order, rank, triples;
          {
            py::gil_scoped_release release;
            int64_t k = SortedTripleRanks(n, rows.data(), bound, S, order, rank);
            triples.reserve(3 * k);
            for (int64_t i = 0; i < n; i++)
              if (!i || rank[order[i]] != rank[order[i - 1]])
                triples.insert(triples.end(), S.begin() + 3 * order[i], S.begin() + 3 * order[i] + 3);
          }
          py::array_t<int64_t> T = ToNumpy(triples, 3);
          if (triples.empty())
            T = py::array_t<int64_t>(std::vector<py::ssize_t>{ 0, 3 });
          return py::make_tuple(ToNumpy(order), ToNumpy(rank), T);
        },
        py::arg("rows"), py::arg("bound"),
        R"doc(Rows of three integers in [0, bound) numbered by their sorted triples.

Returns
-------
order : numpy.ndarray of int64
    The rows' stable order by sorted triple (``np.lexsort`` of the sorted rows).
rank : numpy.ndarray of int64
    The number of every row's sorted triple among the distinct ones, in that order.
triples : numpy.ndarray of int64, shape (k, 3)
    The distinct sorted triples, in order.
)doc");

  m.def("CopyIndexArrays",
        [] (DArr points, LArr faces)
        {
          Check("CopyIndexArrays", "points", points, 2, 3);
          Check("CopyIndexArrays", "faces", faces, 2, 3);
          int64_t nv = points.shape(0), nf = faces.shape(0);
          CheckRange("CopyIndexArrays", "faces", faces, nv);
          std::vector<int64_t> on, group, order, rank, S, incidence, keys;
          py::array_t<double> area2({ nf, int64_t(3) }), unit({ nf, int64_t(3) });
          double * pa = area2.mutable_data(), * pu = unit.mutable_data();
          {
            py::gil_scoped_release release;
            const int64_t * F = faces.data();
            PointGroups3(nv, points.data(), nf, F, on, group);
            std::vector<int64_t> point(nv, -1), pf(3 * nf);
            for (size_t i = 0; i < on.size(); i++)
              point[on[i]] = group[i];
            for (int64_t i = 0; i < 3 * nf; i++)
              pf[i] = point[F[i]];
            int64_t bound = group.empty() ? 0 : group.back() + 1;
            SortedTripleRanks(nf, pf.data(), bound, S, order, rank);
            FaceIncidence(nv, nf, F, incidence);
            FaceNormals3(points.data(), nf, F, pa, pu);
            VertexFaceKeys(nf, F, incidence.data(), rank.data(), keys);
          }
          return py::make_tuple(ToNumpy(on), ToNumpy(group), ToNumpy(rank), ToNumpy(order), ToNumpy(incidence),
                                area2, unit, ToNumpy(keys));
        },
        py::arg("points"), py::arg("faces"),
        R"doc(The arrays of kinks3d.CopyIndex (points finite).

Returns
-------
tuple
    on, group, face_key, key_order, incidence, area2, unit, vertex_keys: bit for bit
    those of the numpy computation.
)doc");

  m.def("FragmentPairEntries",
        [] (LArr faces, LArr vf, LArr pid, LArr key_order, LArr key_sorted, DArr area2, DArr unit, LArr copies,
            double kink)
        {
          Check("FragmentPairEntries", "faces", faces, 2, 3);
          int64_t nf = faces.shape(0), nv = vf.shape(0);
          Check("FragmentPairEntries", "vertex_fragment", vf, 1, 0);
          Check("FragmentPairEntries", "point", pid, 1, 0, nv);
          Check("FragmentPairEntries", "key_order", key_order, 1, 0, nf);
          Check("FragmentPairEntries", "key_sorted", key_sorted, 1, 0, nf);
          Check("FragmentPairEntries", "area2", area2, 2, 3, nf);
          Check("FragmentPairEntries", "unit", unit, 2, 3, nf);
          Check("FragmentPairEntries", "copies", copies, 1, 0);
          CheckRange("FragmentPairEntries", "faces", faces, nv);
          CheckRange("FragmentPairEntries", "key_order", key_order, nf);
          for (py::ssize_t i = 0, n_faces = faces.size(); i < n_faces; i++)
            if (pid.data()[faces.data()[i]] < 0 || pid.data()[faces.data()[i]] >= copies.shape(0))
              throw std::invalid_argument("ngfracture.FragmentPairEntries: a face's vertex has no point");
          PairEntriesInput in { nv, nf, faces.data(), vf.data(), pid.data(), key_order.data(), key_sorted.data(),
                                area2.data(), unit.data(), copies.data(), kink };
          std::vector<int64_t> slave, face, corner;
          std::vector<uint8_t> matched;
          {
            py::gil_scoped_release release;
            FragmentPairEntries(in, slave, face, corner, matched);
          }
          py::array_t<bool> M(nv);
          std::copy(matched.begin(), matched.end(), M.mutable_data());
          return py::make_tuple(ToNumpy(slave), ToNumpy(face), ToNumpy(corner), M);
        },
        py::arg("faces"), py::arg("vertex_fragment"), py::arg("point"), py::arg("key_order"), py::arg("key_sorted"),
        py::arg("area2"), py::arg("unit"), py::arg("copies"), py::arg("kink"),
        R"doc(The rows across matched faces of junctions3d.fragment_pair_rows, before their gaps.

Returns
-------
slave, face, corner : numpy.ndarray of int64
    The rows' slave, master face and the master copy's corner, in the function's order.
matched : numpy.ndarray of bool, shape (nv,)
    Whether a vertex lies on a face matched to a face of another fragment.
)doc");

  m.def("CopyPairs",
        [] (LArr on, LArr group)
        {
          Check("CopyPairs", "on", on, 1, 0);
          Check("CopyPairs", "group", group, 1, 0, on.shape(0));
          CheckSorted("CopyPairs", "group", group);
          std::vector<int64_t> s, t;
          {
            py::gil_scoped_release release;
            CopyPairs(on.shape(0), on.data(), group.data(), s, t);
          }
          return py::make_tuple(ToNumpy(s), ToNumpy(t));
        },
        py::arg("on"), py::arg("group"),
        R"doc(Every ordered pair of entries of ``on`` with equal ``group`` (sorted), kinks3d.copy_pairs.

Returns
-------
s, t : numpy.ndarray of int64
    ``on[i], on[j]`` for every i, then every j of i's run of equal group (i == j included).
)doc");

  m.def("PartnerIncidences",
        [] (LArr on, LArr group, LArr incident, LArr incidence, LArr face_key, LArr vf)
        {
          const char * fn = "PartnerIncidences";
          Check(fn, "vertex_fragment", vf, 1, 0);
          Check(fn, "face_key", face_key, 1, 0);
          int64_t nv = vf.shape(0), nf = face_key.shape(0);
          Check(fn, "on", on, 1, 0);
          Check(fn, "group", group, 1, 0, on.shape(0));
          Check(fn, "incident", incident, 1, 0, 3 * nf);
          Check(fn, "incidence", incidence, 1, 0, 3 * nf);
          CheckRange(fn, "on", on, nv);
          CheckRange(fn, "incident", incident, nv);
          CheckRange(fn, "incidence", incidence, 3 * nf);
          CheckSorted(fn, "group", group);
          CheckSorted(fn, "incident", incident);
          PartnerInput in { nv, nf, on.shape(0), on.data(), group.data(), incident.data(), incidence.data(),
                            face_key.data(), vf.data() };
          std::vector<int64_t> slave, face, corner;
          {
            py::gil_scoped_release release;
            PartnerIncidences(in, slave, face, corner);
          }
          return py::make_tuple(ToNumpy(slave), ToNumpy(face), ToNumpy(corner));
        },
        py::arg("on"), py::arg("group"), py::arg("incident"), py::arg("incidence"), py::arg("face_key"),
        py::arg("vertex_fragment"),
        R"doc(copies3d.partner_incidences from the arrays of a kinks3d.CopyIndex.

Returns
-------
slave, face, corner : numpy.ndarray of int64
    Per pair of copies (s, t) in the fixed rows' direction (copy_pairs' order), every face
    at t (incidence order) coincident with a face at s, and t's corner in it.
)doc");

  m.def("DiagonalEdgePairs",
        [] (LArr edges, LArr at, LArr vf, LArr pid, LArr face_key)
        {
          const char * fn = "DiagonalEdgePairs";
          Check(fn, "edges", edges, 2, 2);
          int64_t nE = edges.shape(0), nv = vf.shape(0), nf = face_key.shape(0);
          Check(fn, "faces_at_edge", at, 2, 2, nE);
          Check(fn, "vertex_fragment", vf, 1, 0);
          Check(fn, "point", pid, 1, 0, nv);
          Check(fn, "face_key", face_key, 1, 0);
          CheckRange(fn, "edges", edges, nv);
          CheckRange(fn, "faces_at_edge", at, nf, -1);
          const int64_t n_points = PointCount(fn, "edges", edges, pid);
          std::vector<int64_t> a, b, ends_b;
          {
            py::gil_scoped_release release;
            DiagonalEdgePairs(nE, edges.data(), at.data(), vf.data(), pid.data(), n_points, face_key.data(), a, b,
                              ends_b);
          }
          py::array_t<int64_t> B = ToNumpy(ends_b, 2);
          if (ends_b.empty())
            B = py::array_t<int64_t>(std::vector<py::ssize_t>{ 0, 2 });
          return py::make_tuple(ToNumpy(a), ToNumpy(b), B);
        },
        py::arg("edges"), py::arg("faces_at_edge"), py::arg("vertex_fragment"), py::arg("point"),
        py::arg("face_key"),
        R"doc(The pairs of wedges3d.diagonal_edges.

Returns
-------
a, b : numpy.ndarray of int64
    The edges a and b of every pair, sorted by a, then b.
ends_b : numpy.ndarray of int64, shape (m, 2)
    b's ends, the one at a's first end's point first.
)doc");

  m.def("EdgeCopyPairs",
        [] (LArr edges, LArr at, LArr pid, LArr face_key)
        {
          const char * fn = "EdgeCopyPairs";
          Check(fn, "edges", edges, 2, 2);
          int64_t nE = edges.shape(0), nf = face_key.shape(0);
          Check(fn, "faces_at_edge", at, 2, 2, nE);
          Check(fn, "point", pid, 1, 0);
          Check(fn, "face_key", face_key, 1, 0);
          CheckRange(fn, "edges", edges, pid.shape(0));
          CheckRange(fn, "faces_at_edge", at, nf, -1);
          const int64_t n_points = PointCount(fn, "edges", edges, pid);
          std::vector<int64_t> a, b, ends_b;
          std::vector<uint8_t> partner;
          {
            py::gil_scoped_release release;
            EdgeCopyPairs(nE, edges.data(), at.data(), pid.data(), n_points, face_key.data(), a, b, ends_b, partner);
          }
          py::array_t<int64_t> B = ToNumpy(ends_b, 2);
          py::array_t<bool> P(std::vector<py::ssize_t>{ py::ssize_t(a.size()), 2 });
          std::copy(partner.begin(), partner.end(), reinterpret_cast<uint8_t *>(P.mutable_data()));
          if (ends_b.empty())
            B = py::array_t<int64_t>(std::vector<py::ssize_t>{ 0, 2 });
          return py::make_tuple(ToNumpy(a), ToNumpy(b), B, P);
        },
        py::arg("edges"), py::arg("faces_at_edge"), py::arg("point"), py::arg("face_key"),
        R"doc(The pairs of wedges3d.edge_copies.

Returns
-------
a, b : numpy.ndarray of int64
    The edges a and b of every pair, sorted by a, then b.
ends_b : numpy.ndarray of int64, shape (m, 2)
    b's ends, the one at a's first end's point first.
partner : numpy.ndarray of bool, shape (m, 2)
    Whether b's face k (faces_at_edge[b, k]) is coincident with a face at a.
)doc");

  m.def("VertexFragments",
        [] (int64_t nv, py::array_t<int64_t, py::array::forcecast> tets, LArr fragment)
        {
          // tets in any memory layout (a mesh's arrays are often column-major): no copy
          Check("VertexFragments", "tets", tets, 2, 4);
          Check("VertexFragments", "fragment", fragment, 1, 0, tets.shape(0));
          if (nv < 0)
            throw std::invalid_argument("ngfracture.VertexFragments: nv must be >= 0");
          int64_t ne = tets.shape(0), row = tets.strides(0) / int64_t(sizeof(int64_t)),
            col = tets.strides(1) / int64_t(sizeof(int64_t));
          if (tets.strides(0) % int64_t(sizeof(int64_t)) || tets.strides(1) % int64_t(sizeof(int64_t)))
            throw std::invalid_argument("ngfracture.VertexFragments: tets is not aligned to its items");
          const int64_t * T = tets.data();
          for (int64_t e = 0; e < ne; e++)
            for (int k = 0; k < 4; k++)
              if (T[e * row + k * col] < 0 || T[e * row + k * col] >= nv)
                throw std::invalid_argument("ngfracture.VertexFragments: tets has an entry outside [0, "
                                            + std::to_string(nv) + ")");
          py::array_t<int64_t> out(nv);
          int64_t * po = out.mutable_data();
          {
            py::gil_scoped_release release;
            VertexFragments(nv, ne, T, row, col, fragment.data(), po);
          }
          return out;
        },
        py::arg("nv"), py::arg("tets"), py::arg("fragment"),
        R"doc(setup3d.vertex_fragments: the fragment of every vertex (of the last tetrahedron at it), -1 in none.)doc");

  m.def("CoveredPairs",
        [] (DArr points, LArr vf, LArr slave, LArr master)
        {
          Check("CoveredPairs", "points", points, 2, 3);
          int64_t nv = points.shape(0);
          Check("CoveredPairs", "vertex_fragment", vf, 1, 0, nv);
          Check("CoveredPairs", "slave", slave, 1, 0);
          Check("CoveredPairs", "master", master, 2, 3, slave.shape(0));
          CheckRange("CoveredPairs", "slave", slave, nv);
          CheckRange("CoveredPairs", "master", master, nv);
          std::vector<int64_t> codes;
          {
            py::gil_scoped_release release;
            CoveredPairs(nv, points.data(), vf.data(), slave.shape(0), slave.data(), master.data(), codes);
          }
          return ToNumpy(codes);
        },
        py::arg("points"), py::arg("vertex_fragment"), py::arg("slave"), py::arg("master"),
        R"doc(junctions3d.covered_pairs of rows given by their slaves and masters: the codes, sorted, unique.)doc");

  m.def("TwoFaces",
        [] (LArr ptr, LArr faces)
        {
          Check("TwoFaces", "edge_face_ptr", ptr, 1, 0);
          Check("TwoFaces", "edge_faces", faces, 1, 0);
          int64_t n = ptr.shape(0), m = faces.shape(0);
          if (n < 1 || ptr.data()[0] < 0 || ptr.data()[n - 1] > m)
            throw std::invalid_argument("ngfracture.TwoFaces: edge_face_ptr must start at 0 or more and end at "
                                        "len(edge_faces) or less");
          CheckSorted("TwoFaces", "edge_face_ptr", ptr);
          py::array_t<int64_t> out({ n - 1, int64_t(2) });
          int64_t * po = out.mutable_data();
          {
            py::gil_scoped_release release;
            TwoFaces(n - 1, ptr.data(), faces.data(), po);
          }
          return out;
        },
        py::arg("edge_face_ptr"), py::arg("edge_faces"),
        R"doc(edge_rows3d.two_faces: the two faces at every edge, increasing; -1, -1 at an edge with other than two.)doc");
}
