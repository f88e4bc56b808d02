// Rank-revealing selection of independent constraint rows (small dense blocks).
#include "independent_rows.hpp"
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
}
