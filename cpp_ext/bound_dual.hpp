// The dual active-set method of Goldfarb and Idnani for a QP whose inequalities are sign
// bounds, with the factorisation of the free block updated instead of the QR of the
// working set (ngfracture/linalg/qp.py, bound_qp).
//
//     minimise 1/2 x^T H x - c^T x   subject to   E x = e,   x_i <= 0 for bounded i
//
// A held bound fixes x_i = 0, so the working set only removes variables: the minimiser on
// the free variables F needs the Cholesky factor of H_FF, which loses a row and column when
// a bound enters (a rank-one update, Givens rotations) and gains one when a bound leaves.
// Each step costs O(f^2 + f k) for f free variables and k held bounds, against O(n k) and a
// copy of the n x k orthogonal factor for the QR of the working set's vectors.
#ifndef NGFRACTURE_BOUND_DUAL_HPP
#define NGFRACTURE_BOUND_DUAL_HPP
#include <cstdint>
#include <string>
#include <vector>

namespace ngfracture
{
  struct BoundQpData
  {
    int n = 0, p = 0;
    const double * H = nullptr;        // n x n, row-major, symmetric positive definite
    const double * c = nullptr;        // n
    const double * E = nullptr;        // p x n, row-major
    const double * e = nullptr;        // p
    const int8_t * bounded = nullptr;  // n: x_i <= 0 applies
    const double * norm = nullptr;     // n: |L^-1 e_i| (H = L L^T), a bound's length in the metric of H,
                                       // of the held variables of the start; 0 for the free ones
    const double * extra = nullptr;    // n: for a free variable of the start at position r,
                                       // |L^-1 e_i|^2 - |L0^-1 e_r|^2 (the held ones' share)
    double level = 0.0;                // tol: a bound is missed when x_i / norm_i > tol max(data, |x|_H)
    double data = 0.0;                 // the data's size in the metric of H
    double growth_limit = 1e8;         // |x|_H may exceed data by this factor at most
    int max_steps = 0;                 // bounds entered at most
  };

  enum class BoundDualStatus { solved = 0, infeasible = 1, failed = 2 };

  struct BoundDualAnswer
  {
    std::vector<double> x, mu, u;      // x; multipliers of E; of the bounds (0 where free)
    std::vector<int8_t> held;          // the final working set
    int entered = 0, dropped = 0;      // bounds that entered, that left on the way
    BoundDualStatus status = BoundDualStatus::failed;
    std::string reason;                // why, when not solved
  };

  // The method from the S-pair of ``held0`` (held bounds with negative multipliers at the
  // minimiser on the others are freed, all at once, until none is left). L0: the lower
  // Cholesky factor of H over the variables not in held0, in increasing order, row-major;
  // a free variable's length in the metric of H is computed from it when a step needs it.
  BoundDualAnswer BoundDualActiveSet (const BoundQpData & qp, const int8_t * held0, const double * L0);
}
#endif
