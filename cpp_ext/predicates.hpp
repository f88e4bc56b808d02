#ifndef NGFRACTURE_PREDICATES_HPP
#define NGFRACTURE_PREDICATES_HPP
// Robust 2D and 3D orientation predicates, exact for IEEE doubles.
//
// orient2d(a, b, c) is the sign of det [a-c, b-c] = twice the signed area of (a, b, c):
// +1 if c, a, b ... i.e. (a, b, c) is counter-clockwise, -1 clockwise, 0 collinear.
// Adaptive in the style of Shewchuk (1997): a floating-point filter with a proven
// error bound decides almost every call; only near-degenerate inputs fall through to
// exact expansion arithmetic (error-free transformations TwoSum / TwoProduct).
// Exact as long as no product overflows or underflows (|coordinates| in about
// [1e-150, 1e150], or zero), the usual limit of floating-point expansion predicates.
// This file must be compiled without -ffast-math and with -ffp-contract=off.

namespace ngfracture
{
  // Sign (-1, 0, +1) of the orientation of (a, b, c); exact.
  int Orient2dSign (const double * a, const double * b, const double * c);

  // Same sign, computed by the exact expansion only (no filter); for tests.
  int Orient2dExactSign (const double * a, const double * b, const double * c);

  // orient3d(a, b, c, d): sign (-1, 0, +1) of det [a-d, b-d, c-d] (rows) = -det [b-a, c-a, d-a]:
  // positive if d lies below the plane of a, b, c seen with a, b, c counter-clockwise from
  // above, 0 iff the four points are coplanar. A positively oriented tetrahedron
  // (det[x1-x0, x2-x0, x3-x0] > 0, the mesh convention) has orient3d(x0, x1, x2, x3) < 0.
  // Same adaptive scheme as orient2d: filter with Shewchuk's bound, then exact
  // differences, then the fully exact expansion of the 24 triple products.
  int Orient3dSign (const double * a, const double * b, const double * c, const double * d);

  // Same sign, computed by the exact expansion only (no filter); for tests.
  int Orient3dExactSign (const double * a, const double * b, const double * c, const double * d);

  // Plain floating-point determinant (not robust); for comparison in tests.
  inline double Orient2dFast (const double * a, const double * b, const double * c)
  {
    return (a[0]-c[0])*(b[1]-c[1]) - (a[1]-c[1])*(b[0]-c[0]);
  }
}

#endif
