#ifndef NGFRACTURE_SUPERNODAL_SOLVE_HPP
#define NGFRACTURE_SUPERNODAL_SOLVE_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // Solves with a symmetric factorisation P A P^T = L D L^T (L unit lower triangular, D
  // diagonal) for dense right-hand sides, L kept in supernodes: runs of columns with the
  // same pattern below their diagonal block, packed as dense column-major panels. One solve
  // reads every panel twice (L, then L^T) with one row index per panel row instead of one
  // per entry, and updates the solution through contiguous gathers and scatters.
  class SupernodalLDL
  {
  public:
    // L: n x n CSC (column j holds the unit diagonal, optional, and the entries below it;
    // rows sorted within a column); d: D; perm: x = A^-1 b is z = L^-T D^-1 L^-1 (b permuted:
    // row i of b goes to row perm[i]), x[i] = z[perm[i]].
    SupernodalLDL (int64_t n, const int64_t * lp, const int32_t * li, const double * lx,
                   const double * d, const int64_t * perm);
    // X = A^-1 B for k right-hand sides, B and X n x k column-major (may be the same array).
    void Solve (int64_t k, const double * B, double * X) const;
    // Y = L^-1 B for a sparse B (n x m CSC, rows already permuted): per column, only the
    // supernodes its nonzeros reach, in increasing order (the reach found supernode by
    // supernode, a heap of the next ones). Output CSC (yp, yi, yx), every row of every
    // supernode reached, rows increasing within a column. The columns go to up to
    // ``threads`` threads in contiguous ranges; a column's numbers do not depend on it.
    void ForwardSparse (int64_t m, const int64_t * bp, const int32_t * bi, const double * bx,
                        std::vector<int64_t> & yp, std::vector<int32_t> & yi, std::vector<double> & yx,
                        int threads = 1) const;
    int64_t Order () const { return n_; }
    int64_t Supernodes () const { return int64_t(first_.size()) - 1; }
    int64_t StoredEntries () const { return int64_t(values_.size()); }

  private:
    void SolveBlock (int64_t k, const double * B, double * X) const;
    // ForwardSparse's columns k0 .. k1 - 1 (yp from 0)
    void ForwardRange (int64_t k0, int64_t k1, const int64_t * bp, const int32_t * bi, const double * bx,
                       std::vector<int64_t> & yp, std::vector<int32_t> & yi, std::vector<double> & yx) const;
    // L y = b on supernode s (z indexed by column): its diagonal block, then the rows
    // below it; acc: room for the rows below
    void ForwardSupernode (int64_t s, double * z, double * acc) const;
    int64_t n_;
    std::vector<int64_t> first_;     // first column of supernode s (first_[S] = n)
    std::vector<int64_t> rowstart_;  // its rows: rows_[rowstart_[s] .. rowstart_[s+1])
    std::vector<int32_t> rows_;      // the diagonal block's columns first, then the rows below
    std::vector<int64_t> valstart_;  // its panel: values_[valstart_[s] ...], column-major
    std::vector<double> values_;
    std::vector<double> inv_d_;
    std::vector<int64_t> perm_;
    std::vector<int32_t> supernode_;  // the supernode of every column
  };
}
#endif
