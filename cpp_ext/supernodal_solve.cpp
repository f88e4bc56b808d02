// Triangular solves with a symmetric factorisation L D L^T kept in supernodes (see the header).
#include "supernodal_solve.hpp"

#include <thread>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace ngfracture
{
  SupernodalLDL::SupernodalLDL (int64_t n, const int64_t * lp, const int32_t * li, const double * lx,
                                const double * d, const int64_t * perm)
    : n_(n)
  {
    if (n < 0 || lp[0] != 0)
      throw std::invalid_argument("SupernodalLDL: L must be CSC with lp[0] = 0");
    for (int64_t j = 0; j < n; j++)        // all of them before any entry is read: lp[n] bounds li
      if (lp[j+1] < lp[j])
        throw std::invalid_argument("SupernodalLDL: column pointers must not decrease");
    // below[j]: the first entry of column j strictly below the diagonal
    std::vector<int64_t> below(n);
    for (int64_t j = 0; j < n; j++)
      {
        int64_t p = lp[j];
        if (p < lp[j+1] && li[p] == j) p++;           // the stored unit diagonal
        below[j] = p;
        for (int64_t q = p; q < lp[j+1]; q++)
          if (li[q] <= j || li[q] >= n || (q > p && li[q] <= li[q-1]))
            throw std::invalid_argument("SupernodalLDL: column " + std::to_string(j) +
                                     " must hold rows below its diagonal, sorted");
        if (d[j] == 0.0 || !std::isfinite(d[j]))
          throw std::invalid_argument("SupernodalLDL: zero or non-finite pivot " + std::to_string(j));
      }
    // column j + 1 continues the supernode of column j when its pattern below the diagonal
    // is column j's without row j + 1
    first_.push_back(0);
    for (int64_t j = 0; j + 1 < n; j++)
      {
        int64_t a = below[j], la = lp[j+1] - a;
        int64_t b = below[j+1], lb = lp[j+2] - b;
        bool same = la == lb + 1 && la > 0 && li[a] == j + 1;
        for (int64_t q = 0; same && q < lb; q++)
          same = li[a + 1 + q] == li[b + q];
        if (!same)
          first_.push_back(j + 1);
      }
    if (n > 0) first_.push_back(n);
    int64_t S = int64_t(first_.size()) - 1;
    rowstart_.assign(1, 0);
    valstart_.assign(1, 0);
    for (int64_t s = 0; s < S; s++)
      {
        int64_t f = first_[s], c = first_[s+1] - f, last = f + c - 1;
        int64_t r = c + (lp[last+1] - below[last]);
        for (int64_t t = 0; t < c; t++)
          rows_.push_back(int32_t(f + t));
        for (int64_t q = below[last]; q < lp[last+1]; q++)
          rows_.push_back(li[q]);
        rowstart_.push_back(int64_t(rows_.size()));
        int64_t at = int64_t(values_.size());
        values_.resize(at + r * c, 0.0);
        for (int64_t t = 0; t < c; t++)          // column f + t fills panel rows t + 1 .. r - 1
          {
            int64_t q = below[f + t];
            for (int64_t i = t + 1; i < r; i++, q++)
              values_[at + t * r + i] = lx[q];
          }
        valstart_.push_back(int64_t(values_.size()));
      }
    inv_d_.resize(n);
    perm_.assign(perm, perm + n);
    std::vector<char> seen(n, 0);
    for (int64_t i = 0; i < n; i++)
      {
        inv_d_[i] = 1.0 / d[i];
        if (perm_[i] < 0 || perm_[i] >= n || seen[perm_[i]])
          throw std::invalid_argument("SupernodalLDL: perm is not a permutation of 0 .. n-1");
        seen[perm_[i]] = 1;
      }
    supernode_.resize(n);
    for (int64_t t = 0; t < S; t++)
      for (int64_t j = first_[t]; j < first_[t+1]; j++)
        supernode_[j] = int32_t(t);
  }

  void SupernodalLDL::ForwardSupernode (int64_t s, double * z, double * acc) const
  {
    int64_t f = first_[s], c = first_[s+1] - f;
    int64_t r = rowstart_[s+1] - rowstart_[s], m = r - c;
    const int32_t * rows = rows_.data() + rowstart_[s] + c;
    const double * P = values_.data() + valstart_[s];
    double * zf = z + f;
    for (int64_t t = 0; t < c; t++)
      {
        const double * pc = P + t * r;
        double zt = zf[t];
        for (int64_t i = t + 1; i < c; i++)
          zf[i] -= pc[i] * zt;
      }
    for (int64_t i = 0; i < m; i++) acc[i] = 0.0;
    for (int64_t t = 0; t < c; t++)
      {
        const double * pc = P + t * r + c;
        double zt = zf[t];
        for (int64_t i = 0; i < m; i++)
          acc[i] += pc[i] * zt;
      }
    for (int64_t i = 0; i < m; i++)
      z[rows[i]] -= acc[i];
  }

  void SupernodalLDL::ForwardSparse (int64_t m, const int64_t * bp, const int32_t * bi, const double * bx,
                                     std::vector<int64_t> & yp, std::vector<int32_t> & yi,
                                     std::vector<double> & yx, int threads) const
  {
    for (int64_t q = 0; q < (m > 0 ? bp[m] : 0); q++)
      if (bi[q] < 0 || bi[q] >= n_)
        throw std::invalid_argument("SupernodalLDL.forward_sparse: right-hand side row out of range");
    // the columns in contiguous ranges, one per thread and at least kColumnsPerThread
    // each (fewer are cheaper than starting a thread): a column's numbers are the same
    // whichever range holds it
    constexpr int64_t kColumnsPerThread = 64;
    int64_t count = std::max<int64_t>(1, std::min<int64_t>(threads, m / kColumnsPerThread + 1));
    std::vector<std::vector<int64_t>> ps(count);
    std::vector<std::vector<int32_t>> is(count);
    std::vector<std::vector<double>> xs(count);
    std::vector<std::thread> pool;
    for (int64_t t = 1; t < count; t++)
      pool.emplace_back([&, t] { ForwardRange(m * t / count, m * (t + 1) / count, bp, bi, bx, ps[t], is[t], xs[t]); });
    ForwardRange(0, m / count, bp, bi, bx, ps[0], is[0], xs[0]);
    for (auto & thread : pool)
      thread.join();
    yp.assign(1, 0);
    yi.clear();
    yx.clear();
    for (int64_t t = 0; t < count; t++)
      {
        int64_t base = int64_t(yi.size());
        for (size_t k = 1; k < ps[t].size(); k++)
          yp.push_back(base + ps[t][k]);
        yi.insert(yi.end(), is[t].begin(), is[t].end());
        yx.insert(yx.end(), xs[t].begin(), xs[t].end());
      }
  }

  void SupernodalLDL::ForwardRange (int64_t k0, int64_t k1, const int64_t * bp, const int32_t * bi,
                                    const double * bx, std::vector<int64_t> & yp, std::vector<int32_t> & yi,
                                    std::vector<double> & yx) const
  {
    int64_t n = n_;
    std::vector<double> z(n, 0.0), acc(n);
    std::vector<int64_t> mark(first_.size(), -1);     // the column that last reached a supernode
    std::vector<int32_t> next, done;                  // min-heap of supernodes to solve; solved
    yp.assign(1, 0);
    auto reach = [&] (int32_t s, int64_t k)
      {
        if (mark[s] == k) return;
        mark[s] = k;
        next.push_back(s);
        std::push_heap(next.begin(), next.end(), std::greater<int32_t>());
      };
    for (int64_t k = k0; k < k1; k++)
      {
        for (int64_t q = bp[k]; q < bp[k+1]; q++)
          {
            z[bi[q]] += bx[q];
            reach(supernode_[bi[q]], k);
          }
        done.clear();
        while (!next.empty())
          {
            std::pop_heap(next.begin(), next.end(), std::greater<int32_t>());
            int32_t s = next.back();
            next.pop_back();
            done.push_back(s);
            ForwardSupernode(s, z.data(), acc.data());
            const int32_t * below = rows_.data() + rowstart_[s] + (first_[s+1] - first_[s]);
            for (const int32_t * row = below; row < rows_.data() + rowstart_[s+1]; row++)
              reach(supernode_[*row], k);
          }
        for (int32_t s : done)                        // increasing: popped from a min-heap
          for (int64_t j = first_[s]; j < first_[s+1]; j++)
            {
              yi.push_back(int32_t(j));
              yx.push_back(z[j]);
              z[j] = 0.0;
            }
        yp.push_back(int64_t(yi.size()));
      }
  }

  void SupernodalLDL::Solve (int64_t k, const double * B, double * X) const
  {
    if (k > 1)
      {
        SolveBlock(k, B, X);
        return;
      }
    int64_t n = n_, S = int64_t(first_.size()) - 1;
    std::vector<double> z(n), work(n);
    for (int64_t col = 0; col < k; col++)
      {
        const double * b = B + col * n;
        double * x = X + col * n;
        for (int64_t i = 0; i < n; i++)
          z[perm_[i]] = b[i];
        // L y = P b, supernode by supernode
        for (int64_t s = 0; s < S; s++)
          ForwardSupernode(s, z.data(), work.data());
        for (int64_t i = 0; i < n; i++)
          z[i] *= inv_d_[i];
        // L^T z = D^-1 y, supernodes in reverse
        for (int64_t s = S - 1; s >= 0; s--)
          {
            int64_t f = first_[s], c = first_[s+1] - f;
            int64_t r = rowstart_[s+1] - rowstart_[s], m = r - c;
            const int32_t * rows = rows_.data() + rowstart_[s] + c;
            const double * P = values_.data() + valstart_[s];
            double * zf = z.data() + f;
            double * g = work.data();
            for (int64_t i = 0; i < m; i++)
              g[i] = z[rows[i]];
            for (int64_t t = c - 1; t >= 0; t--)
              {
                const double * pc = P + t * r;
                // four partial sums in a fixed order: vectorised, and the same on every run
                double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
                int64_t i = 0;
                for (; i + 4 <= m; i += 4)
                  {
                    a0 += pc[c + i] * g[i];
                    a1 += pc[c + i + 1] * g[i + 1];
                    a2 += pc[c + i + 2] * g[i + 2];
                    a3 += pc[c + i + 3] * g[i + 3];
                  }
                for (; i < m; i++)
                  a0 += pc[c + i] * g[i];
                double sum = (a0 + a1) + (a2 + a3);
                for (int64_t j = t + 1; j < c; j++)
                  sum += pc[j] * zf[j];
                zf[t] -= sum;
              }
          }
        for (int64_t i = 0; i < n; i++)
          x[i] = z[perm_[i]];
      }
  }

  // K right-hand sides at once, interleaved (row i's K values side by side): every panel is
  // read once per solve direction for all of them; K is fixed at compile time so that the
  // loops over the right-hand sides unroll
  template <int K>
  static void SolveInterleaved (int64_t n, const std::vector<int64_t> & first, const std::vector<int64_t> & rowstart,
                                const std::vector<int32_t> & rows_all, const std::vector<int64_t> & valstart,
                                const std::vector<double> & values, const std::vector<double> & inv_d,
                                const std::vector<int64_t> & perm, const double * B, double * X)
  {
    int64_t S = int64_t(first.size()) - 1;
    std::vector<double> z(n * K), work(n * K);
    for (int j = 0; j < K; j++)
      for (int64_t i = 0; i < n; i++)
        z[perm[i] * K + j] = B[j * n + i];
    for (int64_t s = 0; s < S; s++)
      {
        int64_t f = first[s], c = first[s+1] - f;
        int64_t r = rowstart[s+1] - rowstart[s], m = r - c;
        const int32_t * rows = rows_all.data() + rowstart[s] + c;
        const double * P = values.data() + valstart[s];
        double * zf = z.data() + f * K;
        for (int64_t t = 0; t < c; t++)
          {
            const double * pc = P + t * r;
            double zt[K];
            for (int j = 0; j < K; j++) zt[j] = zf[t * K + j];
            for (int64_t i = t + 1; i < c; i++)
              for (int j = 0; j < K; j++)
                zf[i * K + j] -= pc[i] * zt[j];
          }
        double * acc = work.data();
        for (int64_t i = 0; i < m * K; i++) acc[i] = 0.0;
        for (int64_t t = 0; t < c; t++)
          {
            const double * pc = P + t * r + c;
            double zt[K];
            for (int j = 0; j < K; j++) zt[j] = zf[t * K + j];
            for (int64_t i = 0; i < m; i++)
              for (int j = 0; j < K; j++)
                acc[i * K + j] += pc[i] * zt[j];
          }
        for (int64_t i = 0; i < m; i++)
          for (int j = 0; j < K; j++)
            z[rows[i] * K + j] -= acc[i * K + j];
      }
    for (int64_t i = 0; i < n; i++)
      for (int j = 0; j < K; j++)
        z[i * K + j] *= inv_d[i];
    for (int64_t s = S - 1; s >= 0; s--)
      {
        int64_t f = first[s], c = first[s+1] - f;
        int64_t r = rowstart[s+1] - rowstart[s], m = r - c;
        const int32_t * rows = rows_all.data() + rowstart[s] + c;
        const double * P = values.data() + valstart[s];
        double * zf = z.data() + f * K;
        double * g = work.data();
        for (int64_t i = 0; i < m; i++)
          for (int j = 0; j < K; j++)
            g[i * K + j] = z[rows[i] * K + j];
        for (int64_t t = c - 1; t >= 0; t--)
          {
            const double * pc = P + t * r;
            double sum[K] = {};
            for (int64_t i = 0; i < m; i++)
              for (int j = 0; j < K; j++)
                sum[j] += pc[c + i] * g[i * K + j];
            for (int64_t i = t + 1; i < c; i++)
              for (int j = 0; j < K; j++)
                sum[j] += pc[i] * zf[i * K + j];
            for (int j = 0; j < K; j++)
              zf[t * K + j] -= sum[j];
          }
      }
    for (int j = 0; j < K; j++)
      for (int64_t i = 0; i < n; i++)
        X[j * n + i] = z[perm[i] * K + j];
  }

  // the columns in groups of four (then two, then one)
  void SupernodalLDL::SolveBlock (int64_t k, const double * B, double * X) const
  {
    int64_t n = n_, j = 0;
    for (; j + 4 <= k; j += 4)
      SolveInterleaved<4>(n, first_, rowstart_, rows_, valstart_, values_, inv_d_, perm_, B + j * n, X + j * n);
    for (; j + 2 <= k; j += 2)
      SolveInterleaved<2>(n, first_, rowstart_, rows_, valstart_, values_, inv_d_, perm_, B + j * n, X + j * n);
    if (j < k)
      Solve(1, B + j * n, X + j * n);
  }
}
