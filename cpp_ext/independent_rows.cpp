// Rank-revealing selection of independent constraint rows (small dense blocks).
#include "independent_rows.hpp"
#include <algorithm>
#include <cmath>
#include <vector>

namespace ngfracture
{
  namespace
  {
    inline double Dot (const double * a, const double * b, int64_t n)
    {
      double s = 0;
      for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
      return s;
    }
    inline void Axpy (double alpha, const double * x, double * y, int64_t n)
    {
      for (int64_t i = 0; i < n; i++) y[i] += alpha * x[i];
    }
    // v -= Q Q^T v, twice ("twice is enough" for orthogonality to working precision).
    void Orthogonalise (const std::vector<double> & Q, int64_t nq, int64_t n, double * v)
    {
      for (int pass = 0; pass < 2; pass++)
        for (int64_t j = 0; j < nq; j++)
          Axpy(-Dot(&Q[j*n], v, n), &Q[j*n], v, n);
    }
  }

  std::vector<int32_t> IndependentRows (const double * A, int64_t k, int64_t n,
                                        const double * G, int64_t p, double rtol)
  {
    std::vector<double> Q;              // orthonormal basis, row by row
    int64_t nq = 0;
    std::vector<double> v(n);
    for (int64_t i = 0; i < p; i++)
      {
        std::copy(G + i*n, G + (i+1)*n, v.begin());
        double n0 = std::sqrt(Dot(v.data(), v.data(), n));
        if (!(n0 > 0)) continue;
        Orthogonalise(Q, nq, n, v.data());
        double r = std::sqrt(Dot(v.data(), v.data(), n));
        if (r > rtol * n0)
          {
            for (auto & x : v) x /= r;
            Q.insert(Q.end(), v.begin(), v.end());
            nq++;
          }
      }
    // Residuals of the rows of A with the Dirichlet span removed.
    std::vector<double> R(A, A + k*n), norm0(k), res(k);
    std::vector<char> active(k, 1);
    for (int64_t i = 0; i < k; i++)
      {
        norm0[i] = std::sqrt(Dot(&R[i*n], &R[i*n], n));
        if (!(norm0[i] > 0)) { active[i] = 0; continue; }
        Orthogonalise(Q, nq, n, &R[i*n]);
      }
    std::vector<int32_t> picked;
    while (true)
      {
        double best = 0;
        for (int64_t i = 0; i < k; i++)
          if (active[i])
            {
              res[i] = std::sqrt(Dot(&R[i*n], &R[i*n], n)) / norm0[i];
              best = std::max(best, res[i]);
            }
        if (!(best > rtol)) break;
        int64_t j = -1;
        for (int64_t i = 0; i < k && j < 0; i++)
          if (active[i] && res[i] >= best * (1.0 - 1e-12)) j = i;
        active[j] = 0;
        picked.push_back(int32_t(j));
        double * q = &R[j*n];
        Orthogonalise(Q, nq, n, q);                  // re-orthogonalise the pivot
        double r = std::sqrt(Dot(q, q, n));
        for (int64_t i = 0; i < n; i++) q[i] /= r;
        Q.insert(Q.end(), q, q + n);
        const double * qq = &Q[nq*n];
        nq++;
        for (int64_t i = 0; i < k; i++)
          if (active[i])
            Axpy(-Dot(qq, &R[i*n], n), qq, &R[i*n], n);
      }
    return picked;
  }

  std::vector<int32_t> IndependentColumnsBanded (const int64_t * indptr, const int32_t * indices,
                                                 const double * data, int64_t n, int64_t k,
                                                 double rtol)
  {
    // Band width W: with rows spanning at most W columns, R keeps upper bandwidth W.
    int64_t W = 1;
    for (int64_t i = 0; i < n; i++)
      if (indptr[i+1] > indptr[i])
        {
          int32_t lo = indices[indptr[i]], hi = lo;
          for (int64_t t = indptr[i]; t < indptr[i+1]; t++)
            { lo = std::min(lo, indices[t]); hi = std::max(hi, indices[t]); }
          W = std::max<int64_t>(W, hi - lo + 1);
        }
    const double drop = 64 * 2.220446049250313e-16;   // rows have unit norm
    std::vector<double> R(k * W, 0.0);          // R(j, j + d) at R[j*W + d]
    std::vector<char> filled(k, 0);
    std::vector<double> x(k + W, 0.0);          // work row, dense over a moving window
    for (int64_t i = 0; i < n; i++)
      {
        if (indptr[i+1] == indptr[i]) continue;
        int64_t lo = k, hi = -1;
        for (int64_t t = indptr[i]; t < indptr[i+1]; t++)
          {
            x[indices[t]] += data[t];
            lo = std::min<int64_t>(lo, indices[t]); hi = std::max<int64_t>(hi, indices[t]);
          }
        for (int64_t j = lo; j <= hi && j < k; j++)
          {
            double xj = x[j];
            if (xj == 0.0) continue;
            double * r = &R[j*W];
            if (!filled[j])
              {
                // Round-off, not a pivot: dropping it perturbs A far below rtol.
                if (std::abs(xj) <= drop) { x[j] = 0.0; continue; }
                for (int64_t d = 0; d < W && j + d <= hi; d++) { r[d] = x[j+d]; x[j+d] = 0.0; }
                filled[j] = 1;
                break;
              }
            // Givens rotation zeroing x_j against R_jj.
            double rjj = r[0], h = std::hypot(rjj, xj);
            double c = rjj / h, sn = xj / h;
            r[0] = h; x[j] = 0.0;
            int64_t end = std::min<int64_t>(W, k - j);
            for (int64_t d = 1; d < end; d++)
              {
                double a = r[d], b = x[j+d];
                r[d] = c*a + sn*b;
                x[j+d] = -sn*a + c*b;
              }
            hi = std::max<int64_t>(hi, j + end - 1);
          }
        for (int64_t j = lo; j <= hi && j < k; j++) x[j] = 0.0;   // clear remainders
      }
    std::vector<int32_t> kept;
    for (int64_t j = 0; j < k; j++)
      if (filled[j] && std::abs(R[j*W]) > rtol) kept.push_back(int32_t(j));
    return kept;
  }

  std::vector<int32_t> IndependentRowsSparse (int64_t m, int64_t ndof,
                                              const int64_t * indptr, const int32_t * indices,
                                              const double * data, const int32_t * label,
                                              const int64_t * position,
                                              int64_t p, const int64_t * gindptr,
                                              const int32_t * gindices, const double * gdata,
                                              const int32_t * glabel,
                                              double rtol, int method, int64_t dense_limit)
  {
    std::vector<int32_t> kept;
    if (m == 0) return kept;
    // Group the C rows by component (in processing order) and the G rows likewise.
    std::vector<int32_t> rows(m);
    for (int64_t i = 0; i < m; i++) rows[i] = int32_t(i);
    std::sort(rows.begin(), rows.end(), [&] (int32_t a, int32_t b)
              {
                if (label[a] != label[b]) return label[a] < label[b];
                return position[a] != position[b] ? position[a] < position[b] : a < b;
              });
    std::vector<int32_t> grows(p);
    for (int64_t i = 0; i < p; i++) grows[i] = int32_t(i);
    std::sort(grows.begin(), grows.end(), [&] (int32_t a, int32_t b)
              { return glabel[a] != glabel[b] ? glabel[a] < glabel[b] : a < b; });

    std::vector<int32_t> colmap(ndof, -1), cols;
    size_t gpos = 0;
    for (size_t s0 = 0; s0 < rows.size(); )
      {
        size_t s1 = s0;
        int32_t lab = label[rows[s0]];
        while (s1 < rows.size() && label[rows[s1]] == lab) s1++;
        while (gpos < grows.size() && glabel[grows[gpos]] < lab) gpos++;
        size_t g0 = gpos, g1 = gpos;
        while (g1 < grows.size() && glabel[grows[g1]] == lab) g1++;
        int64_t k = s1 - s0, pg = g1 - g0;

        cols.clear();
        auto addcols = [&] (const int64_t * ip, const int32_t * ix, int32_t r)
        {
          for (int64_t t = ip[r]; t < ip[r+1]; t++)
            if (colmap[ix[t]] < 0) { colmap[ix[t]] = int32_t(cols.size()); cols.push_back(ix[t]); }
        };
        for (size_t s = s0; s < s1; s++) addcols(indptr, indices, rows[s]);
        for (size_t s = g0; s < g1; s++) addcols(gindptr, gindices, grows[s]);
        int64_t nc = cols.size();

        bool banded = (method == 2 || (method == 0 && k > dense_limit)) && pg == 0;
        if (k == 1 && pg == 0)
          {
            // A single row: independent iff it did not vanish.
            double nrm = 0;
            for (int64_t t = indptr[rows[s0]]; t < indptr[rows[s0]+1]; t++)
              nrm += data[t] * data[t];
            if (std::sqrt(nrm) > rtol) kept.push_back(rows[s0]);
          }
        else if (banded)
          {
            // A^T in CSR: one row per local column, entries (position in group, value).
            std::vector<int64_t> tp(nc + 1, 0);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                tp[colmap[indices[t]] + 1]++;
            for (int64_t c = 0; c < nc; c++) tp[c+1] += tp[c];
            std::vector<int32_t> ti(tp[nc]);
            std::vector<double> tv(tp[nc]);
            std::vector<int64_t> fill(tp.begin(), tp.end() - 1);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                {
                  int64_t at = fill[colmap[indices[t]]]++;
                  ti[at] = int32_t(s - s0);
                  tv[at] = data[t];
                }
            for (int32_t j : IndependentColumnsBanded(tp.data(), ti.data(), tv.data(), nc, k, rtol))
              kept.push_back(rows[s0 + j]);
          }
        else
          {
            // Pivoting prefers the lowest index among equal residuals: input order.
            std::sort(rows.begin() + s0, rows.begin() + s1);
            std::vector<double> A(k * nc, 0.0), Gd(pg * nc, 0.0);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                A[(s - s0) * nc + colmap[indices[t]]] += data[t];
            for (size_t s = g0; s < g1; s++)
              for (int64_t t = gindptr[grows[s]]; t < gindptr[grows[s]+1]; t++)
                Gd[(s - g0) * nc + colmap[gindices[t]]] += gdata[t];
            for (int32_t j : IndependentRows(A.data(), k, nc, Gd.data(), pg, rtol))
              kept.push_back(rows[s0 + j]);
          }
        for (int32_t c : cols) colmap[c] = -1;
        s0 = s1;
      }
    std::sort(kept.begin(), kept.end());
    return kept;
  }
}
