// Python bindings of ngfracture's C++ kernels: module ngfracture._ngfracture.
#include <python_comp.hpp>
#include "vertex_average.hpp"
#include "internal_force.hpp"
#include "sparse_triangular.hpp"
#include "rows_product.hpp"
#include "supernodal_solve.hpp"

namespace py = pybind11;
using namespace ngfracture;

void ExportCrack (py::module & m);   // python_crack.cpp
void ExportCollision (py::module & m);  // python_collision.cpp
void ExportCollision3d (py::module & m);  // python_collision3d.cpp
void ExportSplit3d (py::module & m);   // python_split3d.cpp
void ExportCriterion3D (py::module & m);  // python_criterion3d.cpp
void ExportOverlap3d (py::module & m);  // python_overlap3d.cpp
void ExportSetup3d (py::module & m);  // python_setup3d.cpp
void ExportEdges3d (py::module & m);  // python_edges3d.cpp
void ExportCopies3d (py::module & m);  // python_copies3d.cpp
void ExportQp (py::module & m);  // python_qp.cpp

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Ints = py::array_t<int, py::array::c_style | py::array::forcecast>;

// The arrays of the element kernels (mesh, displacement, law per triangle) as ngbla views;
// the numpy arrays must outlive it.
struct KernelInput
{
  FlatMatrix<double> points;
  FlatMatrix<int> triangles;
  FlatVector<double> u, mu, lam;
  FlatVector<int> kind;

  KernelInput (const char * name, Doubles & p, Ints & t, Doubles & uu, Ints & k, Doubles & m, Doubles & l)
    : points(p.ndim() == 2 ? p.shape(0) : 0, p.ndim() == 2 ? p.shape(1) : 0, const_cast<double*>(p.data())),
      triangles(t.ndim() == 2 ? t.shape(0) : 0, t.ndim() == 2 ? t.shape(1) : 0, const_cast<int*>(t.data())),
      u(uu.shape(0), const_cast<double*>(uu.data())), mu(m.shape(0), const_cast<double*>(m.data())),
      lam(l.shape(0), const_cast<double*>(l.data())), kind(k.shape(0), const_cast<int*>(k.data()))
  {
    if (p.ndim() != 2 || t.ndim() != 2 || uu.ndim() != 1 || k.ndim() != 1 || m.ndim() != 1 || l.ndim() != 1)
      throw Exception(std::string("ngfracture.") + name + ": points and elements must be 2D arrays, "
                      "u, kind, mu and lam 1D");
  }
};

static void ExportInternalForces (py::module & m)
{
  m.def("InternalForces",
        [] (Doubles points, Ints elements, Doubles u, Ints kind, Doubles mu, Doubles lam)
        {
          KernelInput in("InternalForces", points, elements, u, kind, mu, lam);
          py::array_t<double> out(u.shape(0));
          FlatVector<double> F(out.shape(0), out.mutable_data());
          {
            py::gil_scoped_release release;
            InternalForces(in.points, in.triangles, in.u, in.kind, in.mu, in.lam, F);
          }
          return out;
        },
        py::arg("points"), py::arg("elements"), py::arg("u"), py::arg("kind"), py::arg("mu"), py::arg("lam"),
        R"doc(Internal nodal forces of P1 triangles or tetrahedra: f_a = sum_T |T| P(grad u) grad N_a.

Parameters
----------
points : numpy.ndarray
    Shape (nv, d), reference coordinates; d = 2 (triangles) or 3 (tetrahedra).
elements : numpy.ndarray of int
    Shape (ne, d + 1), vertex numbers (the width must match the points').
u : numpy.ndarray
    Shape (d nv,): x components of every vertex, then y, then z (VectorH1 order 1 layout).
kind : numpy.ndarray of int
    Per element: 0 linear, 1 St Venant-Kirchhoff, 2 neo-Hooke.
mu, lam : numpy.ndarray
    Per element, the Lame parameters (of the 2D reduction on triangles, the 3D ones on
    tetrahedra).

Returns
-------
numpy.ndarray
    Shape (d nv,), the gradient of the strain energy (NaN where a neo-Hooke element has
    det F <= 0).

Raises
------
Exception
    On widths that are not (2, 3) or (3, 4), a u of the wrong size, per-element arrays of
    the wrong length, or a vertex number out of range.
)doc");
}

static void ExportTangentStiffness (py::module & m)
{
  m.def("TangentStiffness",
        [] (Doubles points, Ints elements, Doubles u, Ints kind, Doubles mu, Doubles lam)
        {
          KernelInput in("TangentStiffness", points, elements, u, kind, mu, lam);
          Array<int> indptr, indices;
          Array<double> data;
          {
            py::gil_scoped_release release;
            TangentStiffness(in.points, in.triangles, in.u, in.kind, in.mu, in.lam, indptr, indices, data);
          }
          auto copy = [] (auto & a)
            {
              using T = std::decay_t<decltype(a[0])>;
              py::array_t<T> out(a.Size());
              std::copy(a.begin(), a.end(), out.mutable_data());
              return out;
            };
          return py::make_tuple(copy(data), copy(indices), copy(indptr));
        },
        py::arg("points"), py::arg("elements"), py::arg("u"), py::arg("kind"), py::arg("mu"), py::arg("lam"),
        R"doc(Tangent stiffness of P1 triangles or tetrahedra, df/du of InternalForces, as CSR arrays.

K_(a i),(b k) = sum_T |T| dP_ij/dH_kl grad_j N_a grad_l N_b, H = grad u. Every pair of
vertices of an element couples in all components (the sparsity of NGSolve's VectorH1
order 1 matrix); columns are sorted in every row and structural zeros kept.

Parameters
----------
points, elements, u, kind, mu, lam
    As for InternalForces.

Returns
-------
(data, indices, indptr) : tuple of numpy.ndarray
    The CSR arrays of the d nv x d nv matrix (component-major dofs), for
    ``scipy.sparse.csr_matrix((data, indices, indptr))``.

Raises
------
Exception
    As InternalForces.
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

static void ExportSparseTriangular (py::module & m)
{
  using I64 = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  using I32 = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  using F64 = py::array_t<double, py::array::c_style | py::array::forcecast>;
  m.def("SparseLowerSolve",
        [] (int64_t n, I64 lp, I32 li, F64 lx, bool unit_diagonal, I64 bp, I32 bi, F64 bx)
        {
          if (lp.ndim() != 1 || lp.shape(0) != n + 1 || li.shape(0) < lp.data()[n] || lx.shape(0) < lp.data()[n])
            throw Exception("ngfracture.SparseLowerSolve: L must be CSC of an n x n matrix");
          if (bp.ndim() != 1 || bp.shape(0) < 1 || bi.shape(0) < bp.data()[bp.shape(0) - 1]
              || bx.shape(0) < bp.data()[bp.shape(0) - 1])
            throw Exception("ngfracture.SparseLowerSolve: B must be CSC with n rows");
          std::vector<int64_t> xp;
          std::vector<int32_t> xi;
          std::vector<double> xx;
          {
            py::gil_scoped_release release;
            SparseLowerSolve(n, lp.data(), li.data(), lx.data(), unit_diagonal, bp.shape(0) - 1,
                             bp.data(), bi.data(), bx.data(), xp, xi, xx);
          }
          return py::make_tuple(py::array_t<int64_t>(xp.size(), xp.data()),
                                py::array_t<int32_t>(xi.size(), xi.data()),
                                py::array_t<double>(xx.size(), xx.data()));
        },
        py::arg("n"), py::arg("lp"), py::arg("li"), py::arg("lx"), py::arg("unit_diagonal"),
        py::arg("bp"), py::arg("bi"), py::arg("bx"),
        R"doc(X = L^-1 B for sparse lower-triangular L and sparse B (both CSC), Gilbert-Peierls.

Parameters
----------
n : int
    Order of L.
lp, li, lx : numpy.ndarray
    CSC of L (int64 pointers, int32 rows, values); each column holds its diagonal (unless
    unit_diagonal) and entries below it.
unit_diagonal : bool
    L[j, j] = 1 (a stored diagonal is ignored).
bp, bi, bx : numpy.ndarray
    CSC of B (n rows).

Returns
-------
(xp, xi, xx)
    CSC of X; the rows of a column are its reach in L (topological order, unsorted), zeros
    that cancel exactly included.)doc");
}

static void ExportRowsProduct (py::module & m)
{
  using I64 = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  using I32 = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  using F64 = py::array_t<double, py::array::c_style | py::array::forcecast>;
  m.def("RowsProduct", [] (I64 cp, I32 ci, F64 cx, F64 G, int threads)
        {
          if (G.ndim() != 2 || G.shape(0) != G.shape(1))
            throw py::value_error("ngfracture.RowsProduct: G must be square");
          int64_t p = G.shape(0), m = cp.shape(0) - 1;
          if (cp.ndim() != 1 || m < 0 || ci.shape(0) < cp.data()[m] || cx.shape(0) < cp.data()[m])
            throw py::value_error("ngfracture.RowsProduct: C must be CSR (cp of m + 1 pointers)");
          for (int64_t k = 0; k < cp.data()[m]; k++)
            if (ci.data()[k] < 0 || ci.data()[k] >= p)
              throw py::value_error("ngfracture.RowsProduct: a column of C is outside G");
          F64 S(std::vector<py::ssize_t>{m, m});
          {
            py::gil_scoped_release release;
            RowsProduct(m, p, cp.data(), ci.data(), cx.data(), G.data(), S.mutable_data(), std::max(1, threads));
          }
          return S;
        }, py::arg("cp"), py::arg("ci"), py::arg("cx"), py::arg("G"), py::arg("threads") = 1,
        R"doc(S = C G C^T for sparse rows C (CSR: cp, ci, cx) and a dense symmetric G, exactly
symmetric and the same to the last bit on any number of threads.

Returns
-------
numpy.ndarray, shape (m, m))doc");
}

static void ExportAddLowerBlock (py::module & m)
{
  using I64 = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  using F64C = py::array_t<double, py::array::c_style>;     // S is changed in place: never a copy (noconvert)
  using F64F = py::array_t<double, py::array::f_style | py::array::forcecast>;
  m.def("AddLowerBlock", [] (F64C S, I64 at, F64F B)
        {
          if (S.ndim() != 2 || S.shape(0) != S.shape(1) || !S.writeable())
            throw py::value_error("ngfracture.AddLowerBlock: S must be a square, writeable, C-ordered float64 array");
          int64_t n = S.shape(0), k = at.shape(0);
          if (at.ndim() != 1 || B.ndim() != 2 || B.shape(0) != k || B.shape(1) != k)
            throw py::value_error("ngfracture.AddLowerBlock: B must be k x k (Fortran-ordered) for k places");
          for (int64_t i = 0; i < k; i++)
            if (at.data()[i] < 0 || at.data()[i] >= n || (i && at.data()[i] <= at.data()[i - 1]))
              throw py::value_error("ngfracture.AddLowerBlock: the places must increase within S");
          {
            py::gil_scoped_release release;
            AddLowerBlock(n, S.mutable_data(), k, at.data(), B.data());
          }
        }, py::arg("S").noconvert(), py::arg("at"), py::arg("B"),
        R"doc(S[at[i], at[j]] += B[j, i] for i <= j: the lower triangle of a symmetric block
(Fortran-ordered, as BLAS syrk leaves it) into the upper triangle of S, in place.)doc");
}

static void ExportSupernodalLDL (py::module & m)
{
  using I64 = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
  using I32 = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  using F64 = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using F64F = py::array_t<double, py::array::f_style | py::array::forcecast>;
  py::class_<SupernodalLDL>(m, "SupernodalLDL", R"doc(Solves with P A P^T = L D L^T, L kept in supernodes.

Parameters
----------
n : int
    Order.
lp, li, lx : numpy.ndarray
    CSC of the unit lower-triangular L (int64 pointers, int32 rows sorted within each
    column, values); a stored unit diagonal is skipped.
d : numpy.ndarray
    The diagonal D (nonzero).
perm : numpy.ndarray of int64
    Row i of a right-hand side goes to row perm[i] of the permuted system, and x[i] is
    row perm[i] of its solution.)doc")
    .def(py::init([] (int64_t n, I64 lp, I32 li, F64 lx, F64 d, I64 perm)
                  {
                    if (n < 0 || lp.ndim() != 1 || lp.shape(0) != n + 1 || d.shape(0) != n || perm.shape(0) != n)
                      throw py::value_error("ngfracture.SupernodalLDL: lp needs n + 1 entries, d and perm n");
                    int64_t nnz = n ? lp.data()[n] : 0;
                    if (li.shape(0) < nnz || lx.shape(0) < nnz)
                      throw py::value_error("ngfracture.SupernodalLDL: li and lx need lp[n] entries");
                    py::gil_scoped_release release;
                    return new SupernodalLDL(n, lp.data(), li.data(), lx.data(), d.data(), perm.data());
                  }),
         py::arg("n"), py::arg("lp"), py::arg("li"), py::arg("lx"), py::arg("d"), py::arg("perm"))
    .def("solve", [] (const SupernodalLDL & self, F64F b)
         {
           int64_t n = self.Order();
           if (!(b.ndim() == 1 || b.ndim() == 2) || b.shape(0) != n)
             throw py::value_error("ngfracture.SupernodalLDL.solve: b must have n = " + std::to_string(n) + " rows");
           int64_t k = b.ndim() == 1 ? 1 : b.shape(1);
           F64F x(b.ndim() == 1 ? std::vector<py::ssize_t>{n} : std::vector<py::ssize_t>{n, py::ssize_t(k)});
           const double * in = b.data();
           double * out = x.mutable_data();
           {
             py::gil_scoped_release release;
             self.Solve(k, in, out);
           }
           return x;
         }, py::arg("b"), "X = A^-1 B for a vector (n,) or a block (n, k); a new Fortran-ordered array.")
    .def("forward_sparse", [] (const SupernodalLDL & self, I64 bp, I32 bi, F64 bx, int threads)
         {
           if (bp.ndim() != 1 || bp.shape(0) < 1 || bi.shape(0) < bp.data()[bp.shape(0) - 1]
               || bx.shape(0) < bp.data()[bp.shape(0) - 1])
             throw py::value_error("ngfracture.SupernodalLDL.forward_sparse: B must be CSC");
           std::vector<int64_t> yp;
           std::vector<int32_t> yi;
           std::vector<double> yx;
           {
             py::gil_scoped_release release;
             self.ForwardSparse(bp.shape(0) - 1, bp.data(), bi.data(), bx.data(), yp, yi, yx, std::max(1, threads));
           }
           return py::make_tuple(py::array_t<int64_t>(yp.size(), yp.data()),
                                 py::array_t<int32_t>(yi.size(), yi.data()),
                                 py::array_t<double>(yx.size(), yx.data()));
         }, py::arg("bp"), py::arg("bi"), py::arg("bx"), py::arg("threads") = 1,
         R"doc(Y = L^-1 B for a sparse B (CSC, n rows, already permuted), through the supernodes
its nonzeros reach only; its columns on up to ``threads`` threads, the same numbers.

Returns
-------
(yp, yi, yx)
    CSC of Y: every row of every supernode a column reaches, increasing.)doc")
    .def_property_readonly("supernodes", &SupernodalLDL::Supernodes, "Number of supernodes.")
    .def_property_readonly("stored_entries", &SupernodalLDL::StoredEntries,
                           "Entries of the panels (the diagonal blocks' upper parts included).");
}

PYBIND11_MODULE(_ngfracture, m)
{
  m.doc() = "ngfracture's C++ kernels (vertex averaging, crack splitting, collision detection).";
  ExportVertexAverage(m);
  ExportInternalForces(m);
  ExportTangentStiffness(m);
  ExportSparseTriangular(m);
  ExportSupernodalLDL(m);
  ExportRowsProduct(m);
  ExportAddLowerBlock(m);
  ExportCrack(m);
  ExportCollision(m);
  ExportCollision3d(m);
  ExportSplit3d(m);
  ExportCriterion3D(m);
  ExportOverlap3d(m);
  ExportSetup3d(m);
  ExportEdges3d(m);
  ExportCopies3d(m);
  ExportQp(m);
}
