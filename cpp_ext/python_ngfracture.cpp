// Python bindings of ngfracture's C++ kernels: module ngfracture._ngfracture.
#include <python_comp.hpp>
#include "vertex_average.hpp"
#include "internal_force.hpp"

namespace py = pybind11;
using namespace ngfracture;

void ExportCrack (py::module & m);   // python_crack.cpp
void ExportCollision (py::module & m);  // python_collision.cpp

static void ExportInternalForces (py::module & m)
{
  m.def("InternalForces",
        [] (py::array_t<double, py::array::c_style | py::array::forcecast> points,
            py::array_t<int, py::array::c_style | py::array::forcecast> triangles,
            py::array_t<double, py::array::c_style | py::array::forcecast> u,
            py::array_t<int, py::array::c_style | py::array::forcecast> kind,
            py::array_t<double, py::array::c_style | py::array::forcecast> mu,
            py::array_t<double, py::array::c_style | py::array::forcecast> lam)
        {
          if (points.ndim() != 2 || triangles.ndim() != 2 || u.ndim() != 1 || kind.ndim() != 1 ||
              mu.ndim() != 1 || lam.ndim() != 1)
            throw Exception("ngfracture.InternalForces: points and triangles must be 2D arrays, "
                            "u, kind, mu and lam 1D");
          size_t nv = points.shape(0), ne = triangles.shape(0);
          py::array_t<double> out(u.shape(0));
          FlatMatrix<double> P(nv, points.shape(1), const_cast<double*>(points.data()));
          FlatMatrix<int> T(ne, triangles.shape(1), const_cast<int*>(triangles.data()));
          FlatVector<double> U(u.shape(0), const_cast<double*>(u.data()));
          FlatVector<int> K(kind.shape(0), const_cast<int*>(kind.data()));
          FlatVector<double> M(mu.shape(0), const_cast<double*>(mu.data()));
          FlatVector<double> L(lam.shape(0), const_cast<double*>(lam.data()));
          FlatVector<double> F(out.shape(0), out.mutable_data());
          {
            py::gil_scoped_release release;
            InternalForces(P, T, U, K, M, L, F);
          }
          return out;
        },
        py::arg("points"), py::arg("triangles"), py::arg("u"), py::arg("kind"), py::arg("mu"), py::arg("lam"),
        R"doc(Internal nodal forces of P1 triangles: f_a = sum_T |T| P(grad u) grad N_a.

Parameters
----------
points : numpy.ndarray
    Shape (nv, 2), reference coordinates.
triangles : numpy.ndarray of int
    Shape (ne, 3), vertex numbers.
u : numpy.ndarray
    Shape (2 nv,): x components of every vertex, then y (VectorH1 order 1 layout).
kind : numpy.ndarray of int
    Per triangle: 0 linear, 1 St Venant-Kirchhoff, 2 neo-Hooke.
mu, lam : numpy.ndarray
    Per triangle, the Lame parameters of its 2D reduction.

Returns
-------
numpy.ndarray
    Shape (2 nv,), the gradient of the strain energy (NaN where a neo-Hooke element has
    det F <= 0).
)doc");
}

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
  ExportInternalForces(m);
  ExportCrack(m);
  ExportCollision(m);
}
