// Adaptive exact orient2d: written for ngfracture from the published algorithms
// (Dekker/Knuth error-free transformations, Shewchuk's expansion arithmetic).
#include "predicates.hpp"
#include <algorithm>
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
    constexpr double kErrBound3A = (7.0 + 56.0 * kEps) * kEps; // Shewchuk's o3derrboundA

    // sign * x * y * z as four doubles summing to it exactly (barring under/overflow).
    inline void TripleProduct (double x, double y, double z, double * t)
    {
      double p, q;
      TwoProd(x, y, p, q);
      TwoProd(p, z, t[0], t[1]);
      TwoProd(q, z, t[2], t[3]);
    }

    // Sign of a sum of n <= 96 doubles, exactly.
    int LongExactSumSign (int n, const double * terms)
    {
      double e[96];
      int len = 0;
      for (int i = 0; i < n; i++)
        len = GrowExpansion(len, e, terms[i], e);
      return ExpansionSign(len, e);
    }

    // The six signed permutation products of det [u; v; w] (3 x 3, rows), 24 doubles.
    inline void DetTerms3 (const double * u, const double * v, const double * w, double * t)
    {
      TripleProduct( u[0], v[1], w[2], t + 0);
      TripleProduct(-u[0], v[2], w[1], t + 4);
      TripleProduct(-u[1], v[0], w[2], t + 8);
      TripleProduct( u[1], v[2], w[0], t + 12);
      TripleProduct( u[2], v[0], w[1], t + 16);
      TripleProduct(-u[2], v[1], w[0], t + 20);
    }

    // Exact det [a-d; b-d; c-d] = det [[a, 1]; [b, 1]; [c, 1]; [d, 1]] (4 x 4): the 24
    // permutation products of the 4 x 4 matrix, each a product of three coordinates.
    int FullExact3Sign (const double * a, const double * b, const double * c, const double * d)
    {
      const double * rows[4] = { a, b, c, d };
      int perm[4] = { 0, 1, 2, 3 };
      double t[96];
      int n = 0;
      do
        {
          int inversions = 0;
          for (int i = 0; i < 4; i++)
            for (int j = i+1; j < 4; j++)
              inversions += perm[i] > perm[j];
          double f[3];
          int k = 0;
          for (int r = 0; r < 4; r++)
            if (perm[r] != 3) f[k++] = rows[r][perm[r]];    // column 3 holds the ones
          TripleProduct(inversions % 2 ? -f[0] : f[0], f[1], f[2], t + n);
          n += 4;
        }
      while (std::next_permutation(perm, perm + 4));
      return LongExactSumSign(n, t);
    }
  }

  int Orient3dExactSign (const double * a, const double * b, const double * c, const double * d)
  {
    return FullExact3Sign(a, b, c, d);
  }

  int Orient3dSign (const double * a, const double * b, const double * c, const double * d)
  {
    // Stage A: floating-point filter; the bound is relative to the permanent.
    double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
    double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
    double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
    double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
    double cdxady = cdx * ady, adxcdy = adx * cdy;
    double adxbdy = adx * bdy, bdxady = bdx * ady;
    double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz)
      + (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz)
      + (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
    double errbound = kErrBound3A * permanent;
    if (det > errbound) return 1;
    if (-det > errbound) return -1;
    if (permanent == 0.0) return 0;       // every product vanished exactly: det is 0

    // Stage B: exact differences make det [rounded differences] the true one.
    double u[3], v[3], w[3], tail[9];
    for (int k = 0; k < 3; k++)
      {
        TwoDiff(a[k], d[k], u[k], tail[k]);
        TwoDiff(b[k], d[k], v[k], tail[3+k]);
        TwoDiff(c[k], d[k], w[k], tail[6+k]);
      }
    if (std::all_of(tail, tail + 9, [] (double e) { return e == 0.0; }))
      {
        double t[24];
        DetTerms3(u, v, w, t);
        return LongExactSumSign(24, t);
      }
    // Stage C: fully exact evaluation.
    return FullExact3Sign(a, b, c, d);
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
