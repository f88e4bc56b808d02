// Python bindings of ngfracture's C++ kernels: module ngfracture._ngfracture.
#include <python_comp.hpp>
#include "vertex_average.hpp"

namespace py = pybind11;
using namespace ngfracture;

void ExportCrack (py::module & m);   // python_crack.cpp
void ExportCollision (py::module & m);  // python_collision.cpp

static void ExportVertexAverage (py::module & m)
{
  m.def("ElementAreas",
        [] (shared_ptr<ngcomp::MeshAccess> mesh)
        {
          auto areas = ElementAreas(*mesh);
          py::array_t<double> out(areas.Size());
          auto buf = out.mutable_data();
          for (size_t i = 0; i < areas.Size(); i++) buf[i] = areas[i];
          return out;
        },
        py::arg("mesh"),
        R"doc(Signed area of every triangle of a 2D mesh (reference configuration).

Parameters
----------
mesh : ngsolve.Mesh
    A 2D mesh of triangles.

Returns
-------
numpy.ndarray
    One area per element, positive for counter-clockwise triangles.
)doc");

  m.def("VertexAverage",
        [] (shared_ptr<ngcomp::MeshAccess> mesh,
            py::array_t<double, py::array::c_style | py::array::forcecast> values)
        {
          if (values.ndim() != 2)
            throw Exception("ngfracture.VertexAverage: values must be a 2D array (elements x components)");
          size_t ne = values.shape(0), nc = values.shape(1);
          py::array_t<double> out({ size_t(mesh->GetNV()), nc });
          FlatMatrix<double> vals(ne, nc, const_cast<double*>(values.data()));
          FlatMatrix<double> res(mesh->GetNV(), nc, out.mutable_data());
          VertexAverage(*mesh, vals, res);
          return out;
        },
        py::arg("mesh"), py::arg("values"),
        R"doc(Area-weighted average of per-element values at every vertex.

Parameters
----------
mesh : ngsolve.Mesh
    A 2D mesh of triangles.
values : numpy.ndarray
    Shape (number of elements, number of components).

Returns
-------
numpy.ndarray
    Shape (number of vertices, number of components); vertex i holds
    sum |T| v_T / sum |T| over the triangles T that contain it.

Raises
------
RuntimeError
    If the shape of values does not match the mesh.
)doc");
}

PYBIND11_MODULE(_ngfracture, m)
{
  m.doc() = "ngfracture's C++ kernels (vertex averaging, crack splitting, collision detection).";
  ExportVertexAverage(m);
  ExportCrack(m);
  ExportCollision(m);
}
