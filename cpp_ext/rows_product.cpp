#include "rows_product.hpp"

#include <algorithm>
#include <thread>
#include <vector>

namespace ngfracture
{
  namespace
  {
    constexpr int64_t kBlockRows = 16;   // rows a thread takes at a time (interleaved)

    // the rows i of R = T C^T in blocks first, first + stride, ... of kBlockRows each
    void RowsOfBlocks (int64_t m, int64_t p, const int64_t * cp, const int32_t * ci, const double * cx,
                       const double * G, double * S, int64_t first, int64_t stride)
    {
      std::vector<double> t(p);
      for (int64_t start = first * kBlockRows; start < m; start += stride * kBlockRows)
        for (int64_t i = start; i < std::min(m, start + kBlockRows); i++)
          {
            std::fill(t.begin(), t.end(), 0.0);
            for (int64_t k = cp[i]; k < cp[i + 1]; k++)
              {
                const double c = cx[k];
                const double * row = G + int64_t(ci[k]) * p;
                for (int64_t a = 0; a < p; a++)
                  t[a] += c * row[a];
              }
            for (int64_t j = 0; j < m; j++)
              {
                double s = 0.0;
                for (int64_t l = cp[j]; l < cp[j + 1]; l++)
                  s += cx[l] * t[ci[l]];
                S[i * m + j] = s;
              }
          }
    }
  }

  void RowsProduct (int64_t m, int64_t p, const int64_t * cp, const int32_t * ci, const double * cx,
                    const double * G, double * S, int threads)
  {
    const int64_t blocks = (m + kBlockRows - 1) / kBlockRows;
    const int64_t count = std::max<int64_t>(1, std::min<int64_t>(threads, blocks));
    std::vector<std::thread> pool;
    for (int64_t w = 1; w < count; w++)
      pool.emplace_back(RowsOfBlocks, m, p, cp, ci, cx, G, S, w, count);
    RowsOfBlocks(m, p, cp, ci, cx, G, S, 0, count);
    for (auto & thread : pool)
      thread.join();
    // (R + R^T) / 2: an entry depends on its two rows alone, not on their places in C
    constexpr int64_t tile = 64;      // tiles: the column-wise reads stay in the cache
    for (int64_t i0 = 0; i0 < m; i0 += tile)
      for (int64_t j0 = i0; j0 < m; j0 += tile)
        for (int64_t i = i0; i < std::min(m, i0 + tile); i++)
          for (int64_t j = std::max(j0, i + 1); j < std::min(m, j0 + tile); j++)
            S[i * m + j] = S[j * m + i] = 0.5 * (S[i * m + j] + S[j * m + i]);
  }

  void AddLowerBlock (int64_t n, double * S, int64_t k, const int64_t * at, const double * B)
  {
    // column i of B (contiguous) is row at[i] of S, its columns at[j] increasing
    for (int64_t i = 0; i < k; i++)
      {
        double * row = S + at[i] * n;
        const double * column = B + i * k;
        for (int64_t j = i; j < k; j++)
          row[at[j]] += column[j];
      }
  }
}
