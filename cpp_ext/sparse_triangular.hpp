#ifndef NGFRACTURE_SPARSE_TRIANGULAR_HPP
#define NGFRACTURE_SPARSE_TRIANGULAR_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // X = L^-1 B for a sparse lower-triangular L (n x n, CSC: column j holds its diagonal,
  // if not unit, and entries below it) and a sparse right-hand side B (n x m, CSC).
  // Gilbert-Peierls: per column of B, the nonzero pattern of the solution is the set of
  // rows reachable from the nonzeros of b in the graph of L (edge j -> i for L[i, j] != 0),
  // found by depth-first search and solved in topological order. The cost is the number
  // of entries of L in the columns reached, not nnz(L): a right-hand side with a few
  // nonzeros (a contact row) touches the path to the root of the elimination tree only.
  // unit_diagonal: L[j, j] = 1 is assumed (and any stored diagonal entry ignored).
  // Output CSC (xp, xi, xx), rows of each column in topological order (unsorted).
  void SparseLowerSolve (int64_t n, const int64_t * lp, const int32_t * li, const double * lx,
                         bool unit_diagonal, int64_t m, const int64_t * bp, const int32_t * bi,
                         const double * bx, std::vector<int64_t> & xp, std::vector<int32_t> & xi,
                         std::vector<double> & xx);
}
#endif
