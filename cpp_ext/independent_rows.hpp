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
  // Returns the picked rows of A in pivot order. Works on the supports of the vectors
  // (rows of a contact component have a few nonzeros): the same floating-point operations
  // as IndependentRowsDense on the nonzeros, so the same pivots bit for bit.
  std::vector<int32_t> IndependentRows (const double * A, int64_t k, int64_t n,
                                        const double * G, int64_t p, double rtol);

  // The same QR on dense vectors, O(k r n): the reference IndependentRows must equal.
  std::vector<int32_t> IndependentRowsDense (const double * A, int64_t k, int64_t n,
                                             const double * G, int64_t p, double rtol);

  // Sparse alternative for large components: greedy sequential selection in the given
  // column order by a banded Givens QR of the n x k matrix A^T (CSR: one row per dof,
  // column indices in the chosen order, entries of unit-norm constraint rows). Column j
  // is kept iff its distance from the span of the kept columns before it exceeds rtol
  // (|R_jj| > rtol); intermediate pivots at round-off level (64 eps) are dropped rather
  // than used as pivots. (Dropping at rtol instead perturbs A by rtol-sized entries and
  // lets dependent columns pass the rtol test.) Cost O(n W^2) with W the largest
  // column span of a row (small after a reverse Cuthill-McKee ordering).
  std::vector<int32_t> IndependentColumnsBanded (const int64_t * indptr, const int32_t * indices,
                                                 const double * data, int64_t n, int64_t k,
                                                 double rtol);

  // Both selections applied per connected component of the rows of a CSR matrix C
  // (m x ndof, unit-norm rows, Dirichlet columns already eliminated) together with the
  // rows of G (p x ndof, always kept). label[i] / glabel[i] give the component of each
  // row, position[i] the processing order of the C rows (e.g. reverse Cuthill-McKee).
  // method: 0 auto (pivoted up to dense_limit rows or when G rows are present, banded
  // above), 1 pivoted, 2 banded (pivoted where G rows are present). A component to be
  // pivoted with at least gram_min rows is first tested by a Cholesky factorisation of
  // its Gram matrix: where that proves every row farther than rtol from the span of the
  // others, all are kept without the QR (the QR would keep them all).
  // Returns the kept rows of C, ascending.
  std::vector<int32_t> IndependentRowsSparse (int64_t m, int64_t ndof,
                                              const int64_t * indptr, const int32_t * indices,
                                              const double * data, const int32_t * label,
                                              const int64_t * position,
                                              int64_t p, const int64_t * gindptr,
                                              const int32_t * gindices, const double * gdata,
                                              const int32_t * glabel,
                                              double rtol, int method, int64_t dense_limit,
                                              int64_t gram_min);
}
#endif
