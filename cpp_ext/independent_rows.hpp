#ifndef NGFRACTURE_INDEPENDENT_ROWS_HPP
#define NGFRACTURE_INDEPENDENT_ROWS_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // Column-pivoted Gram-Schmidt QR (Businger-Golub pivoting, modified Gram-Schmidt with
  // one reorthogonalisation) of the rows of the dense k x n matrix A, after the span of
  // the p x n rows G (always kept) has been projected out. Rows are picked by largest
  // residual norm relative to their own norm; among residuals within a factor 1 - 1e-12
  // of the largest the lowest index wins, so exact and near duplicates keep their first
  // occurrence. Stops when no relative residual exceeds rtol.
  // Returns the picked rows of A in pivot order.
  std::vector<int32_t> IndependentRows (const double * A, int64_t k, int64_t n,
                                        const double * G, int64_t p, double rtol);
}
#endif
