// Python bindings of the collision kernels (orient2d, broad + narrow phase, contact
// selection). Low level: ngfracture/collision.py and contact.py validate the input
// and are the documented API.
#include <python_comp.hpp>
#include "collision.hpp"
#include "predicates.hpp"
#include "independent_rows.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using DArr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using IArr = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
  using BArr = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;

  void CheckShape (const py::array & a, size_t cols, const char * name)
  {
    if (a.ndim() != 2 || size_t(a.shape(1)) != cols)
      throw py::value_error(std::string("ngfracture: ") + name + " must have shape (n, "
                            + std::to_string(cols) + ")");
  }

  TriangleSoup MakeSoup (const DArr & x, const IArr & tris)
  {
    CheckShape(x, 2, "x");
    CheckShape(tris, 3, "tris");
    TriangleSoup s { x.data(), tris.data(), x.shape(0), tris.shape(0) };
    for (int64_t i = 0; i < 3*s.nt; i++)
      if (s.tris[i] < 0 || s.tris[i] >= s.nv)
        throw py::value_error("ngfracture: tris holds a vertex index out of range");
    return s;
  }
}

void ExportCollision (py::module & m)
{
  m.def("Orient2d",
        [] (DArr a, DArr b, DArr c, bool exact_only)
        {
          CheckShape(a, 2, "a"); CheckShape(b, 2, "b"); CheckShape(c, 2, "c");
          if (a.shape(0) != b.shape(0) || a.shape(0) != c.shape(0))
            throw py::value_error("ngfracture.Orient2d: a, b, c must have the same length");
          size_t n = a.shape(0);
          py::array_t<int8_t> out(n);
          auto o = out.mutable_data();
          const double * pa = a.data(), * pb = b.data(), * pc = c.data();
          {
            py::gil_scoped_release release;
            for (size_t i = 0; i < n; i++)
              o[i] = int8_t(exact_only ? Orient2dExactSign(pa+2*i, pb+2*i, pc+2*i)
                                       : Orient2dSign(pa+2*i, pb+2*i, pc+2*i));
          }
          return out;
        },
        py::arg("a"), py::arg("b"), py::arg("c"), py::arg("exact_only") = false,
        "Exact sign of orient2d for rows of (n, 2) arrays a, b, c (+1 counter-clockwise).");

  m.def("CollisionPairs",
        [] (DArr x, IArr tris, BArr candidate, py::object fragment, double tol, bool narrow)
        {
          auto soup = MakeSoup(x, tris);
          if (candidate.ndim() != 1 || candidate.shape(0) != soup.nt)
            throw py::value_error("ngfracture.CollisionPairs: candidate must have shape (nt,)");
          IArr frag;
          const int32_t * pf = nullptr;
          if (!fragment.is_none())
            {
              frag = fragment.cast<IArr>();
              if (frag.ndim() != 1 || frag.shape(0) != soup.nt)
                throw py::value_error("ngfracture.CollisionPairs: fragment must have shape (nt,)");
              pf = frag.data();
            }
          std::vector<std::array<int32_t,2>> pairs;
          double h = 0;
          {
            py::gil_scoped_release release;
            pairs = CollisionPairs(soup, candidate.data(), pf, tol, narrow, &h);
          }
          py::array_t<int32_t> out({ py::ssize_t(pairs.size()), py::ssize_t(2) });
          if (!pairs.empty())
            std::copy(&pairs[0][0], &pairs[0][0] + 2*pairs.size(), out.mutable_data());
          return py::make_tuple(out, h);
        },
        py::arg("x"), py::arg("tris"), py::arg("candidate"), py::arg("fragment") = py::none(),
        py::arg("tol") = 0.0, py::arg("narrow") = true,
        "Sorted colliding (narrow=True) or box-overlapping pairs i < j, and the bin size.");

  m.def("TrianglesCollide",
        [] (DArr x, IArr tris, IArr pairs, double tol)
        {
          auto soup = MakeSoup(x, tris);
          CheckShape(pairs, 2, "pairs");
          size_t np = pairs.shape(0);
          const int32_t * pp = pairs.data();
          for (size_t i = 0; i < 2*np; i++)
            if (pp[i] < 0 || pp[i] >= soup.nt)
              throw py::value_error("ngfracture.TrianglesCollide: pair index out of range");
          py::array_t<bool> out(np);
          auto o = out.mutable_data();
          {
            py::gil_scoped_release release;
            for (size_t k = 0; k < np; k++)
              {
                const int32_t * ti = soup.tris + 3*pp[2*k], * tj = soup.tris + 3*pp[2*k+1];
                const double * p[3] = { soup.x + 2*ti[0], soup.x + 2*ti[1], soup.x + 2*ti[2] };
                const double * q[3] = { soup.x + 2*tj[0], soup.x + 2*tj[1], soup.x + 2*tj[2] };
                o[k] = TrianglesCollide(p, q, tol);
              }
          }
          return out;
        },
        py::arg("x"), py::arg("tris"), py::arg("pairs"), py::arg("tol") = 0.0,
        "Narrow phase for each pair: interiors overlap or distance <= tol (tol > 0).");

  m.def("SelectContacts",
        [] (DArr x, IArr tris, BArr bmask, IArr pairs, double tol, double angle_tol,
            double xi_snap)
        {
          auto soup = MakeSoup(x, tris);
          CheckShape(bmask, 3, "boundary_edge_mask");
          if (bmask.shape(0) != soup.nt)
            throw py::value_error("ngfracture.SelectContacts: boundary_edge_mask must have shape (nt, 3)");
          CheckShape(pairs, 2, "pairs");
          int64_t np = pairs.shape(0);
          for (int64_t i = 0; i < 2*np; i++)
            if (pairs.data()[i] < 0 || pairs.data()[i] >= soup.nt)
              throw py::value_error("ngfracture.SelectContacts: pair index out of range");
          std::vector<ContactCandidate> cc;
          {
            py::gil_scoped_release release;
            cc = SelectContacts(soup, bmask.data(), pairs.data(), np, tol, angle_tol, xi_snap);
          }
          py::ssize_t k = cc.size();
          py::array_t<int32_t> ids({ k, py::ssize_t(6) });
          py::array_t<double> geo({ k, py::ssize_t(5) });
          auto pi = ids.mutable_data(); auto pg = geo.mutable_data();
          for (py::ssize_t r = 0; r < k; r++)
            {
              auto & c = cc[r];
              int32_t iv[6] = { c.slave, c.a, c.c, c.master_tri, c.slave_tri, c.pair };
              double gv[5] = { c.xi, c.n[0], c.n[1], c.dist, c.angle };
              std::copy(iv, iv+6, pi + 6*r);
              std::copy(gv, gv+5, pg + 5*r);
            }
          return py::make_tuple(ids, geo);
        },
        py::arg("x"), py::arg("tris"), py::arg("boundary_edge_mask"), py::arg("pairs"),
        py::arg("tol") = 0.0, py::arg("angle_tol") = 1.5707963267948966, py::arg("xi_snap") = 0.0,
        "Node-to-segment constraints by rules 1-4: ids (slave, a, c, master_tri, slave_tri, pair)"
        " and geometry (xi, nx, ny, dist, angle) per constraint.");

  m.def("IndependentRows",
        [] (DArr A, DArr G, double rtol, bool dense)
        {
          if (A.ndim() != 2 || G.ndim() != 2 || (G.shape(0) > 0 && G.shape(1) != A.shape(1)))
            throw py::value_error("ngfracture.IndependentRows: A (k, n) and G (p, n) expected");
          std::vector<int32_t> picked;
          {
            py::gil_scoped_release release;
            picked = (dense ? IndependentRowsDense : IndependentRows)(A.data(), A.shape(0), A.shape(1),
                                                                      G.data(), G.shape(0), rtol);
          }
          py::array_t<int32_t> out(picked.size());
          std::copy(picked.begin(), picked.end(), out.mutable_data());
          return out;
        },
        py::arg("A"), py::arg("G"), py::arg("rtol") = 1e-8, py::arg("dense") = false,
        "Rows of dense A independent of each other and of the rows of G (pivot order); "
        "dense=True: the reference QR on dense vectors (same pivots, bit for bit).");

  m.def("IndependentColumnsBanded",
        [] (py::array_t<int64_t, py::array::c_style | py::array::forcecast> indptr,
            IArr indices, DArr data, int64_t k, double rtol)
        {
          int64_t n = indptr.shape(0) - 1;
          if (n < 0 || indices.shape(0) != data.shape(0)
              || indptr.data()[n] != indices.shape(0))
            throw py::value_error("ngfracture.IndependentColumnsBanded: inconsistent CSR arrays");
          for (int64_t t = 0; t < indices.shape(0); t++)
            if (indices.data()[t] < 0 || indices.data()[t] >= k)
              throw py::value_error("ngfracture.IndependentColumnsBanded: column out of range");
          std::vector<int32_t> kept;
          {
            py::gil_scoped_release release;
            kept = IndependentColumnsBanded(indptr.data(), indices.data(), data.data(), n, k, rtol);
          }
          py::array_t<int32_t> out(kept.size());
          std::copy(kept.begin(), kept.end(), out.mutable_data());
          return out;
        },
        py::arg("indptr"), py::arg("indices"), py::arg("data"), py::arg("k"),
        py::arg("rtol") = 1e-8,
        "Greedy independent columns of the CSR matrix A^T (n x k) by banded Givens QR.");

  m.def("IndependentRowsSparse",
        [] (int64_t ndof, py::array_t<int64_t, py::array::c_style | py::array::forcecast> indptr,
            IArr indices, DArr data, IArr label,
            py::array_t<int64_t, py::array::c_style | py::array::forcecast> position,
            py::array_t<int64_t, py::array::c_style | py::array::forcecast> gindptr,
            IArr gindices, DArr gdata, IArr glabel, double rtol, int method, int64_t dense_limit,
            int64_t gram_min)
        {
          int64_t m = indptr.shape(0) - 1, p = gindptr.shape(0) - 1;
          if (m < 0 || p < 0 || label.shape(0) != m || position.shape(0) != m
              || glabel.shape(0) != p || indptr.data()[m] != indices.shape(0)
              || gindptr.data()[p] != gindices.shape(0)
              || indices.shape(0) != data.shape(0) || gindices.shape(0) != gdata.shape(0))
            throw py::value_error("ngfracture.IndependentRowsSparse: inconsistent arrays");
          for (int64_t t = 0; t < indices.shape(0); t++)
            if (indices.data()[t] < 0 || indices.data()[t] >= ndof)
              throw py::value_error("ngfracture.IndependentRowsSparse: column out of range");
          for (int64_t t = 0; t < gindices.shape(0); t++)
            if (gindices.data()[t] < 0 || gindices.data()[t] >= ndof)
              throw py::value_error("ngfracture.IndependentRowsSparse: column out of range");
          std::vector<int32_t> kept;
          {
            py::gil_scoped_release release;
            kept = IndependentRowsSparse(m, ndof, indptr.data(), indices.data(), data.data(),
                                         label.data(), position.data(), p, gindptr.data(),
                                         gindices.data(), gdata.data(), glabel.data(),
                                         rtol, method, dense_limit, gram_min);
          }
          py::array_t<int64_t> out(kept.size());
          std::copy(kept.begin(), kept.end(), out.mutable_data());
          return out;
        },
        py::arg("ndof"), py::arg("indptr"), py::arg("indices"), py::arg("data"), py::arg("label"),
        py::arg("position"), py::arg("gindptr"), py::arg("gindices"), py::arg("gdata"),
        py::arg("glabel"), py::arg("rtol"), py::arg("method"), py::arg("dense_limit"), py::arg("gram_min"),
        "Independent rows per connected component (see independent_rows.hpp).");
}
