#ifndef NGFRACTURE_ROWS_PRODUCT_HPP
#define NGFRACTURE_ROWS_PRODUCT_HPP
#include <cstdint>

namespace ngfracture
{
  // S = C G C^T for sparse rows C (m x p, CSR: cp, ci, cx) and a dense symmetric G (p x p,
  // row-major). Row i of T = C G is the sum of the rows of G at the entries of row i of C
  // (G symmetric: its row is its column), in the order of those entries; R[i][j] is the
  // sum over the entries of row j of C[j, l] T[i, l], in their order, and S = (R + R^T) / 2:
  // exactly symmetric, and an entry depends on its two rows alone, not on their places in
  // C (a subset of the rows in another order has the same entries, bit for bit). The rows
  // i are dealt to `threads` threads in interleaved blocks, and every entry is the same sum
  // whichever thread makes it, so S does not depend on the number of threads. S: m x m,
  // row-major.
  void RowsProduct (int64_t m, int64_t p, const int64_t * cp, const int32_t * ci, const double * cx,
                    const double * G, double * S, int threads);

  // S[at[i], at[j]] += B[j, i] for i <= j < k: the lower triangle of a symmetric k x k block
  // (column-major, as BLAS syrk leaves it) added into the upper triangle of S (n x n,
  // row-major) at the increasing places `at`. Each entry of S gets one addition, so the
  // sum over blocks added in a fixed order is the same whatever else runs.
  void AddLowerBlock (int64_t n, double * S, int64_t k, const int64_t * at, const double * B);
}
#endif
