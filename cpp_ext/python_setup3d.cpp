// Python bindings of the mesh-only set-up of 3D contact (contact_setup3d.hpp).
// Low level: ngfracture/contact/setup3d.py, kinks3d.py and junctions3d.py validate the
// input, keep the numpy computations as the reference and are the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "contact_setup3d.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using LArr = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;

  void Check (const char * fn, const char * name, const py::array & a, int ndim, py::ssize_t cols,
              py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has the wrong shape");
  }

  // every entry of a in [0, bound)
  void CheckRange (const char * fn, const char * name, const LArr & a, int64_t bound)
  {
    const int64_t * p = a.data();
    for (py::ssize_t i = 0; i < a.size(); i++)
      if (p[i] < 0 || p[i] >= bound)
        throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has an entry outside [0, "
                                    + std::to_string(bound) + ")");
  }
}

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
          for (py::ssize_t i = 0; i < faces.size(); i++)
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
}
