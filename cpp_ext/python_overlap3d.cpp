// Python bindings of the overlap volume between tetrahedra (tet_overlap.hpp).
// Low level: ngfracture/output/overlap3d.py validates the input and is the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "tet_overlap.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using IArr = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;

  void CheckShape (const char * fn, const char * name, const py::array & a, int ndim, py::ssize_t cols,
                   py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has the wrong shape");
  }
}

void ExportOverlap3d (py::module & m)
{
  m.def("TetIntersectionVolume",
        [] (DArr a, DArr b)
        {
          CheckShape("TetIntersectionVolume", "a", a, 2, 3, 4);
          CheckShape("TetIntersectionVolume", "b", b, 2, 3, 4);
          const double * pa[4], * pb[4];
          for (int k = 0; k < 4; k++)
          {
            pa[k] = a.data() + 3 * k;
            pb[k] = b.data() + 3 * k;
          }
          return TetIntersectionVolume(pa, pb);
        },
        py::arg("a"), py::arg("b"),
        R"doc(Volume of the intersection of two tetrahedra.

Parameters
----------
a, b : numpy.ndarray
    Shape (4, 3): the corners of each tetrahedron, either orientation.

Returns
-------
float
    The volume of the convex intersection (clipping of a by b's four half-spaces); 0 for a
    degenerate tetrahedron and, exactly, for tetrahedra separated by a plane through a face
    of one of them.

Raises
------
ValueError
    If a shape is not (4, 3).
)doc");

  m.def("FragmentOverlap3",
        [] (DArr x, IArr tets, IArr fragment)
        {
          CheckShape("FragmentOverlap3", "points", x, 2, 3);
          CheckShape("FragmentOverlap3", "tets", tets, 2, 4);
          CheckShape("FragmentOverlap3", "fragment", fragment, 1, 0, tets.shape(0));
          TetOverlap r;
          {
            py::gil_scoped_release release;
            r = FragmentOverlap3(x.data(), x.shape(0), tets.data(), tets.shape(0), fragment.data());
          }
          py::dict out;
          out["first"] = ToNumpy(r.first);
          out["second"] = ToNumpy(r.second);
          out["volume"] = ToNumpy(r.volume);
          out["total"] = r.total;
          out["candidates"] = r.candidates;
          out["cell"] = r.cell;
          return out;
        },
        py::arg("points"), py::arg("tets"), py::arg("fragment"),
        R"doc(Pairs of tetrahedra of different fragments that overlap, and their intersection volumes.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3), coordinates (the deformed configuration).
tets : numpy.ndarray
    Shape (ne, 4), vertex numbers.
fragment : numpy.ndarray
    Shape (ne,), fragment label of every tetrahedron.

Returns
-------
dict
    ``first``, ``second`` (int32, first < second, sorted) and ``volume`` (float64) of every
    pair with a positive intersection volume; ``total`` their sum in that order;
    ``candidates`` the pairs of different fragments whose bounding boxes overlap; ``cell``
    the grid cell size of the search.

Raises
------
ValueError
    A shape that does not fit, or a vertex number out of range.
)doc");
}
