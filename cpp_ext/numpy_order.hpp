// Vector arithmetic in numpy's orders of operations, for kernels that must give what a
// numpy computation gives bit for bit (compiled without fma contraction): np.cross
// a1 b2 - a2 b1, ..., np.linalg.norm over three entries (a0 + a1) + a2, einsum "ij,ij->i"
// ((a0 + a2) + a1) + 0.0 (einsum sums into a +0.0: a -0.0 sum comes out +0.0).
#ifndef NGFRACTURE_NUMPY_ORDER_HPP
#define NGFRACTURE_NUMPY_ORDER_HPP
#include <cmath>
#include <cstdint>

namespace ngfracture
{
  inline void NumpyCross (const double * a, const double * b, double * c)
  {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  }

  inline double EinsumDot (const double * a, const double * b)
  {
    return ((a[0] * b[0] + a[2] * b[2]) + a[1] * b[1]) + 0.0;
  }

  inline double NumpyNorm (const double * a)
  {
    return std::sqrt((a[0] * a[0] + a[1] * a[1]) + a[2] * a[2]);
  }

  // twice the area vector of the triangle of vertices tri in the points P (np.cross of
  // its edges from corner 0)
  inline void AreaVector (const double * P, const int64_t * tri, double * c)
  {
    const double * p0 = P + 3 * tri[0], * p1 = P + 3 * tri[1], * p2 = P + 3 * tri[2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++)
      {
        e1[k] = p1[k] - p0[k];
        e2[k] = p2[k] - p0[k];
      }
    NumpyCross(e1, e2, c);
  }
}
#endif
