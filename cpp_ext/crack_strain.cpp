#include "crack_strain.hpp"
#include <algorithm>

namespace ngfracture
{
  using namespace ngcomp;

  void ElementStrainP1 (const MeshAccess & ma, FlatMatrix<double> u,
                        StrainMeasure measure, FlatMatrix<double> strain)
  {
    size_t ne = ma.GetNE(VOL), nv = ma.GetNV();
    if (u.Height() != nv || u.Width() != 2)
      throw Exception("ngfracture.ElementStrainP1: displacement must be nv x 2 = " +
                      ToString(nv) + " x 2, got " + ToString(u.Height()) + " x " + ToString(u.Width()));
    if (strain.Height() != ne || strain.Width() != 3)
      throw Exception("ngfracture.ElementStrainP1: result must be ne x 3");
    bool green = measure == StrainMeasure::GreenLagrange;
    // Serial: a few ms at 500k triangles, and exceptions stay on the calling thread.
    for (size_t e = 0; e < ne; e++)
      {
        auto verts = ma.GetElement(ElementId(VOL, e)).Vertices();
        if (verts.Size() != 3)
          throw Exception("ngfracture: element " + ToString(e) + " is not a triangle");
        auto p0 = ma.GetPoint<2>(verts[0]);
        auto p1 = ma.GetPoint<2>(verts[1]);
        auto p2 = ma.GetPoint<2>(verts[2]);
        // J = [p1-p0, p2-p0], D = [u1-u0, u2-u0], H = D J^{-1}
        double j00 = p1(0)-p0(0), j01 = p2(0)-p0(0);
        double j10 = p1(1)-p0(1), j11 = p2(1)-p0(1);
        double det = j00*j11 - j01*j10;
        double i00 =  j11/det, i01 = -j01/det, i10 = -j10/det, i11 = j00/det;
        double d00 = u(verts[1],0)-u(verts[0],0), d01 = u(verts[2],0)-u(verts[0],0);
        double d10 = u(verts[1],1)-u(verts[0],1), d11 = u(verts[2],1)-u(verts[0],1);
        double h00 = d00*i00 + d01*i10, h01 = d00*i01 + d01*i11;
        double h10 = d10*i00 + d11*i10, h11 = d10*i01 + d11*i11;
        double exx = h00, eyy = h11, exy = 0.5*(h01+h10);
        if (green)
          {
            // (H^T H)_ij = sum_k H_ki H_kj
            exx += 0.5*(h00*h00 + h10*h10);
            eyy += 0.5*(h01*h01 + h11*h11);
            exy += 0.5*(h00*h01 + h10*h11);
          }
        strain(e,0) = exx; strain(e,1) = eyy; strain(e,2) = exy;
      }
  }

  void PrincipalMax (FlatMatrix<double> t, FlatVector<double> values, FlatMatrix<double> dirs)
  {
    size_t n = t.Height();
    if (t.Width() != 3 || values.Size() != n || dirs.Height() != n || dirs.Width() != 2)
      throw Exception("ngfracture.PrincipalMax: tensors must be n x 3");
    for (size_t i = 0; i < n; i++)
      {
        double a = t(i,0), b = t(i,1), c = t(i,2);
        double half = 0.5*(a-b);
        values[i] = 0.5*(a+b) + hypot(half, c);
        double theta = 0.5*atan2(2*c, a-b);   // atan2(0,0) = 0: isotropic -> (1,0)
        dirs(i,0) = cos(theta);
        dirs(i,1) = sin(theta);
      }
  }

  Array<int> SelectAbove (FlatVector<double> values, double critical)
  {
    Array<int> sel;
    for (size_t i = 0; i < values.Size(); i++)
      if (values[i] > critical) sel.Append(int(i));
    std::sort(sel.begin(), sel.end(), [&] (int a, int b)
              {
                if (values[a] != values[b]) return values[a] > values[b];
                return a < b;
              });
    return sel;
  }
}
