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
                if (std::abs(xj) <= rtol) { x[j] = 0.0; continue; }   // below threshold
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
}
