// Sparse triangular solves with sparse right-hand sides (Gilbert-Peierls), for the Schur
// complement C K^-1 C^T of constraint rows with a few nonzeros each.
#include "sparse_triangular.hpp"
#include <stdexcept>
#include <string>

namespace ngfracture
{
  void SparseLowerSolve (int64_t n, const int64_t * lp, const int32_t * li, const double * lx,
                         bool unit_diagonal, int64_t m, const int64_t * bp, const int32_t * bi,
                         const double * bx, std::vector<int64_t> & xp, std::vector<int32_t> & xi,
                         std::vector<double> & xx)
  {
    std::vector<double> diag(n, 1.0);
    if (!unit_diagonal)
      {
        std::vector<char> found(n, 0);
        for (int64_t j = 0; j < n; j++)
          for (int64_t p = lp[j]; p < lp[j+1]; p++)
            if (li[p] == j) { diag[j] = lx[p]; found[j] = 1; }
        for (int64_t j = 0; j < n; j++)
          if (!found[j] || diag[j] == 0.0)
            throw std::runtime_error("SparseLowerSolve: zero or missing diagonal in column " + std::to_string(j));
      }
    std::vector<double> x(n, 0.0);
    std::vector<int64_t> mark(n, -1);         // column of B that last reached a row
    std::vector<int32_t> order;               // reach of the current column, reverse postorder
    std::vector<int32_t> stack_node;          // depth-first search: node and next child position
    std::vector<int64_t> stack_pos;
    xp.assign(1, 0);
    xi.clear();
    xx.clear();
    for (int64_t k = 0; k < m; k++)
      {
        // symbolic: rows reachable from the nonzeros of b_k, in postorder
        order.clear();
        for (int64_t q = bp[k]; q < bp[k+1]; q++)
          {
            int32_t start = bi[q];
            if (start < 0 || start >= n)
              throw std::runtime_error("SparseLowerSolve: right-hand side row out of range");
            if (mark[start] == k) continue;
            mark[start] = k;
            stack_node.assign(1, start);
            stack_pos.assign(1, lp[start]);
            while (!stack_node.empty())
              {
                int32_t j = stack_node.back();
                int64_t & p = stack_pos.back();
                bool descended = false;
                for (; p < lp[j+1]; p++)
                  {
                    int32_t i = li[p];
                    if (i <= j || mark[i] == k) continue;
                    mark[i] = k;
                    p++;
                    stack_node.push_back(i);
                    stack_pos.push_back(lp[i]);
                    descended = true;
                    break;
                  }
                if (!descended)
                  {
                    order.push_back(j);
                    stack_node.pop_back();
                    stack_pos.pop_back();
                  }
              }
          }
        // numeric: scatter b_k, eliminate in topological order (reverse postorder)
        for (int64_t q = bp[k]; q < bp[k+1]; q++)
          x[bi[q]] += bx[q];
        for (auto it = order.rbegin(); it != order.rend(); ++it)
          {
            int32_t j = *it;
            double xj = x[j] / diag[j];
            x[j] = xj;
            if (xj == 0.0) continue;
            for (int64_t p = lp[j]; p < lp[j+1]; p++)
              if (li[p] > j)
                x[li[p]] -= lx[p] * xj;
          }
        for (auto it = order.rbegin(); it != order.rend(); ++it)
          {
            xi.push_back(*it);
            xx.push_back(x[*it]);
            x[*it] = 0.0;
          }
        xp.push_back(int64_t(xi.size()));
      }
  }
}
