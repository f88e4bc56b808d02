// Python bindings of the crack criterion on tetrahedral meshes (nonlocal_strain3d.hpp).
#include <python_comp.hpp>
#include "nonlocal_strain3d.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using darray = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using iarray = py::array_t<int, py::array::c_style | py::array::forcecast>;

  // points (nv, 3) and tets (ne, 4) as ngbla views; the arrays must outlive them.
  struct Solid
  {
    FlatMatrix<double> points;
    FlatMatrix<int> tets;
    Solid (const char * who, darray & p, iarray & t)
      : points(p.ndim() == 2 ? p.shape(0) : 0, p.ndim() == 2 ? p.shape(1) : 0, const_cast<double*>(p.data())),
        tets(t.ndim() == 2 ? t.shape(0) : 0, t.ndim() == 2 ? t.shape(1) : 0, const_cast<int*>(t.data()))
    {
      if (p.ndim() != 2 || p.shape(1) != 3)
        throw py::value_error(std::string("ngfracture.") + who + ": points must have shape (nv, 3)");
      if (t.ndim() != 2 || t.shape(1) != 4)
        throw py::value_error(std::string("ngfracture.") + who + ": tets must have shape (ne, 4)");
    }
  };
}

void ExportCriterion3D (py::module & m)
{
  m.def("SolidVertexAverage",
        [] (darray points, iarray tets, darray values)
        {
          Solid s("SolidVertexAverage", points, tets);
          if (values.ndim() != 2 || size_t(values.shape(0)) != s.tets.Height())
            throw py::value_error("ngfracture.SolidVertexAverage: values must have shape (ne, ncomp), ne = " +
                                  std::to_string(s.tets.Height()));
          size_t nv = s.points.Height(), nc = values.shape(1);
          py::array_t<double> out({ nv, nc });
          FlatMatrix<double> vals(values.shape(0), nc, const_cast<double*>(values.data()));
          FlatMatrix<double> res(nv, nc, out.mutable_data());
          {
            py::gil_scoped_release release;
            VertexAverage3D(s.points, s.tets, vals, res);
          }
          return out;
        },
        py::arg("points"), py::arg("tets"), py::arg("values"),
        R"doc(Volume-weighted average of element values at every vertex of a tet mesh.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3).
tets : numpy.ndarray of int
    Shape (ne, 4).
values : numpy.ndarray
    Shape (ne, ncomp).

Returns
-------
numpy.ndarray
    Shape (nv, ncomp): sum |T| v_T / sum |T| over the tets T of each vertex (0 for a vertex
    of no tet).

Raises
------
ValueError
    Bad shapes.
RuntimeError
    A tet vertex out of range.
)doc");

  m.def("SolidSharpVertices",
        [] (darray points, iarray tets)
        {
          Solid s("SolidSharpVertices", points, tets);
          std::vector<int> verts;
          std::vector<double> tangents;
          {
            py::gil_scoped_release release;
            SharpVertices3D(s.points, s.tets, verts, tangents);
          }
          py::array_t<int> v(verts.size());
          std::copy(verts.begin(), verts.end(), v.mutable_data());
          py::array_t<double> t({ verts.size(), size_t(3) });
          std::copy(tangents.begin(), tangents.end(), t.mutable_data());
          return py::make_tuple(v, t);
        },
        py::arg("points"), py::arg("tets"),
        R"doc(Sharp vertices of a tet mesh and the unit tangents of their fronts.

A vertex is sharp when it lies on a boundary edge whose inside dihedral angle (the sum of
the dihedral angles of the tets around the edge) is at least 300 degrees: a crack front
(360 degrees, the lips being separate boundary faces) or a sharp notch front.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3).
tets : numpy.ndarray of int
    Shape (ne, 4), positively oriented.

Returns
-------
(numpy.ndarray, numpy.ndarray)
    The sharp vertices (increasing) and their front tangents, shape (k, 3).

Raises
------
ValueError
    Bad shapes.
RuntimeError
    A vertex out of range, a tet that is not positively oriented, a face of three tets.
)doc");

  m.def("SolidNonlocalOpening",
        [] (darray points, iarray tets, darray tensors, darray radius, int ndir, int nplane)
        {
          Solid s("SolidNonlocalOpening", points, tets);
          size_t nv = s.points.Height();
          if (tensors.ndim() != 2 || size_t(tensors.shape(0)) != nv || tensors.shape(1) != 6)
            throw py::value_error("ngfracture.SolidNonlocalOpening: tensors must have shape (nv, 6) = (" +
                                  std::to_string(nv) + ", 6)");
          if (radius.ndim() != 1 || size_t(radius.shape(0)) != nv)
            throw py::value_error("ngfracture.SolidNonlocalOpening: radius must have shape (nv,) = (" +
                                  std::to_string(nv) + ",)");
          py::array_t<double> out({ nv, size_t(6) });
          FlatMatrix<double> T(nv, 6, const_cast<double*>(tensors.data()));
          FlatVector<double> R(nv, const_cast<double*>(radius.data()));
          FlatMatrix<double> res(nv, 6, out.mutable_data());
          {
            py::gil_scoped_release release;
            NonlocalOpening3D(s.points, s.tets, T, R, ndir, nplane, res);
          }
          return out;
        },
        py::arg("points"), py::arg("tets"), py::arg("tensors"), py::arg("radius"), py::arg("ndir"),
        py::arg("nplane"),
        R"doc(Critical-distance opening measure of every vertex of a tet mesh (docs/solid.md).

Low-level: use ngfracture.fracture.solid_criterion.nonlocal_opening_3d.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3).
tets : numpy.ndarray of int
    Shape (ne, 4), positively oriented.
tensors : numpy.ndarray
    Shape (nv, 6), nodal tensors (xx, yy, zz, yz, xz, xy), interpolated linearly in the tets.
radius : numpy.ndarray
    Shape (nv,), the critical distance of every vertex (<= 0: not judged).
ndir : int
    Ray directions over the sphere (Fibonacci set) of a hot spot that is not sharp (>= 8).
nplane : int
    Ray directions in the plane normal to the front of a sharp vertex (>= 8).

Returns
-------
numpy.ndarray
    Shape (nv, 6): value * n n^T, the largest over the rays of the smallest opening n.T.n
    along the ray (n from the ray's end point), 0 where the vertex is not judged.

Raises
------
ValueError
    Bad shapes.
RuntimeError
    Too few directions, a vertex out of range, a tet not positively oriented.
)doc");
}
