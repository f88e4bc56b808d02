// Adaptive exact orient2d: written for ngfracture from the published algorithms
// (Dekker/Knuth error-free transformations, Shewchuk's expansion arithmetic).
#include "predicates.hpp"
#include <cmath>

namespace ngfracture
{
  namespace
  {
    // x + y == a + b exactly, |y| <= ulp(x)/2 (Knuth TwoSum, no precondition on |a|, |b|).
    inline void TwoSum (double a, double b, double & x, double & y)
    {
      x = a + b;
      double bv = x - a;
      double av = x - bv;
      y = (a - av) + (b - bv);
    }

    // x + y == a - b exactly.
    inline void TwoDiff (double a, double b, double & x, double & y)
    {
      x = a - b;
      double bv = a - x;
      double av = x + bv;
      y = (a - av) + (bv - b);
    }

    // x + y == a * b exactly (barring underflow); fma gives the rounding error.
    inline void TwoProd (double a, double b, double & x, double & y)
    {
      x = a * b;
      y = std::fma(a, b, -x);
    }

    // h = e + b for a nonoverlapping expansion e (increasing magnitude), zero
    // components dropped. Returns the length of h; h may alias e.
    inline int GrowExpansion (int elen, const double * e, double b, double * h)
    {
      double q = b;
      int hlen = 0;
      for (int i = 0; i < elen; i++)
        {
          double qnew, hh;
          TwoSum(q, e[i], qnew, hh);
          q = qnew;
          if (hh != 0.0) h[hlen++] = hh;
        }
      if (q != 0.0 || hlen == 0) h[hlen++] = q;
      return hlen;
    }

    // Sign of the value of an expansion: that of its largest (last nonzero) component.
    inline int ExpansionSign (int len, const double * e)
    {
      double top = e[len-1];
      return (top > 0) - (top < 0);
    }

    // Sign of a sum of n doubles, exactly.
    inline int ExactSumSign (int n, const double * terms)
    {
      double e[16];
      int len = 0;
      for (int i = 0; i < n; i++)
        len = GrowExpansion(len, e, terms[i], e);
      return ExpansionSign(len, e);
    }

    // Exact det of six products: ax*by - ax*cy - cx*by - ay*bx + ay*cx + cy*bx
    // (the expansion of (ax-cx)(by-cy) - (ay-cy)(bx-cx); the cx*cy terms cancel).
    int FullExactSign (const double * a, const double * b, const double * c)
    {
      double t[12];
      TwoProd( a[0], b[1], t[0], t[1]);
      TwoProd(-a[0], c[1], t[2], t[3]);
      TwoProd(-c[0], b[1], t[4], t[5]);
      TwoProd(-a[1], b[0], t[6], t[7]);
      TwoProd( a[1], c[0], t[8], t[9]);
      TwoProd( c[1], b[0], t[10], t[11]);
      return ExactSumSign(12, t);
    }

    constexpr double kEps = 0x1p-53;                     // half an ulp of 1
    constexpr double kErrBoundA = (3.0 + 16.0 * kEps) * kEps;  // Shewchuk's ccwerrboundA
  }

  int Orient2dExactSign (const double * a, const double * b, const double * c)
  {
    return FullExactSign(a, b, c);
  }

  int Orient2dSign (const double * a, const double * b, const double * c)
  {
    // Stage A: floating-point filter with a rigorous relative error bound.
    double detleft = (a[0] - c[0]) * (b[1] - c[1]);
    double detright = (a[1] - c[1]) * (b[0] - c[0]);
    double det = detleft - detright;
    double detsum;
    if (detleft > 0.0)
      {
        if (detright <= 0.0) return (det > 0) - (det < 0);   // no cancellation possible
        detsum = detleft + detright;
      }
    else if (detleft < 0.0)
      {
        if (detright >= 0.0) return (det > 0) - (det < 0);
        detsum = -detleft - detright;
      }
    else
      return (det > 0) - (det < 0);
    double errbound = kErrBoundA * detsum;
    if (det > errbound) return 1;
    if (-det > errbound) return -1;

    // Stage B: if the coordinate differences were exact, the determinant of the rounded
    // differences is the true one; evaluate it exactly from four product components.
    double acx, acxt, bcx, bcxt, acy, acyt, bcy, bcyt;
    TwoDiff(a[0], c[0], acx, acxt);
    TwoDiff(b[0], c[0], bcx, bcxt);
    TwoDiff(a[1], c[1], acy, acyt);
    TwoDiff(b[1], c[1], bcy, bcyt);
    if (acxt == 0.0 && bcxt == 0.0 && acyt == 0.0 && bcyt == 0.0)
      {
        double t[4];
        TwoProd(acx, bcy, t[0], t[1]);
        TwoProd(-acy, bcx, t[2], t[3]);
        return ExactSumSign(4, t);
      }
    // Stage C: fully exact evaluation.
    return FullExactSign(a, b, c);
  }
}
