// Python binding of the dual active-set method on sign bounds (bound_dual.hpp).
// Low level: ngfracture/linalg/qp.py (bound_qp) prepares the input and is the documented API.
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "bound_dual.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using BArr = py::array_t<int8_t, py::array::c_style | py::array::forcecast>;

  void Check (bool ok, const char * what)
  {
    if (!ok)
      throw std::invalid_argument(std::string("ngfracture.BoundDualActiveSet: ") + what);
  }
}

void ExportQp (py::module & m)
{
  m.def("BoundDualActiveSet",
        [] (DArr H, DArr c, DArr E, DArr e, BArr bounded, DArr norm, DArr extra, BArr held, DArr L0, double tol,
            double data, double growth_limit, int max_steps)
        {
          py::ssize_t n = c.ndim() == 1 ? c.shape(0) : -1;
          Check(n >= 0 && H.ndim() == 2 && H.shape(0) == n && H.shape(1) == n, "H must be n x n, c of length n");
          Check(E.ndim() == 2 && E.shape(1) == n && e.ndim() == 1 && e.shape(0) == E.shape(0),
                "E must be p x n, e of length p");
          Check(bounded.ndim() == 1 && bounded.shape(0) == n && norm.ndim() == 1 && norm.shape(0) == n
                && extra.ndim() == 1 && extra.shape(0) == n && held.ndim() == 1 && held.shape(0) == n,
                "bounded, norm, extra and held must have length n");
          py::ssize_t f = 0;
          for (py::ssize_t i = 0; i < n; i++)
          {
            Check(!held.data()[i] || bounded.data()[i], "a held variable is not bounded");
            f += held.data()[i] ? 0 : 1;
          }
          Check(L0.ndim() == 2 && L0.shape(0) == f && L0.shape(1) == f, "L0 must be f x f, f the free variables");
          BoundQpData qp;
          qp.n = int(n);
          qp.p = int(E.shape(0));
          qp.H = H.data(); qp.c = c.data(); qp.E = E.data(); qp.e = e.data();
          qp.bounded = bounded.data(); qp.norm = norm.data(); qp.extra = extra.data();
          qp.level = tol; qp.data = data; qp.growth_limit = growth_limit; qp.max_steps = max_steps;
          BoundDualAnswer a;
          {
            py::gil_scoped_release release;
            a = BoundDualActiveSet(qp, held.data(), L0.data());
          }
          return py::make_tuple(ToNumpy(a.x), ToNumpy(a.mu), ToNumpy(a.u), ToNumpy(a.held), a.entered,
                                a.dropped, int(a.status), a.reason);
        },
        py::arg("H"), py::arg("c"), py::arg("E"), py::arg("e"), py::arg("bounded"), py::arg("norm"),
        py::arg("extra"), py::arg("held"), py::arg("L0"), py::arg("tol"), py::arg("data"), py::arg("growth_limit"),
        py::arg("max_steps"),
        R"doc(Goldfarb-Idnani dual steps for min 1/2 x^T H x - c^T x, E x = e, x_i <= 0 (bounded i).

Parameters
----------
H, c, E, e : numpy.ndarray
    (n, n) symmetric positive definite, (n,), (p, n), (p,).
bounded : numpy.ndarray of int8 (n,)
norm : numpy.ndarray (n,)
    |L^-1 e_i| for H = L L^T, a bound's length in the metric of H, of the held variables
    of the start; 0 for the free ones, whose lengths are computed from L0 where needed.
extra : numpy.ndarray (n,)
    For a free variable of the start at position r: |L^-1 e_i|^2 - |L0^-1 e_r|^2.
held : numpy.ndarray of int8 (n,)
    The start's held bounds (a subset of ``bounded``).
L0 : numpy.ndarray (f, f)
    Lower Cholesky factor of H over the variables not held, in increasing order.
tol, data, growth_limit, max_steps
    As ngfracture.linalg.qp.convex_qp: a bound is missed when x_i / norm_i exceeds tol
    times the larger of data and |x|_H.

Returns
-------
(x, mu, u, held, entered, dropped, status, reason)
    H x - c = E^T mu - u; status 0 solved, 1 infeasible, 2 failed (rounding: reason).

Raises
------
ValueError
    If a shape does not fit or a held variable is not bounded.
)doc");
}
