#include "internal_force.hpp"
#include <cmath>

namespace ngfracture
{
  using namespace ngbla;

  // First Piola-Kirchhoff stress P(H) of one element, H = grad u (2x2, row i = component).
  static void FirstPiola (MaterialKind kind, double mu, double lam, const double H[2][2],
                          double P[2][2])
  {
    switch (kind)
      {
      case MaterialKind::Linear:
        {
          double e01 = 0.5 * (H[0][1] + H[1][0]);
          double tr = H[0][0] + H[1][1];
          P[0][0] = 2 * mu * H[0][0] + lam * tr;
          P[1][1] = 2 * mu * H[1][1] + lam * tr;
          P[0][1] = P[1][0] = 2 * mu * e01;
          return;
        }
      case MaterialKind::StVenantKirchhoff:
        {
          // E = (H + H^T + H^T H) / 2, S = 2 mu E + lam tr(E) I, P = (I + H) S
          double E00 = H[0][0] + 0.5 * (H[0][0] * H[0][0] + H[1][0] * H[1][0]);
          double E11 = H[1][1] + 0.5 * (H[0][1] * H[0][1] + H[1][1] * H[1][1]);
          double E01 = 0.5 * (H[0][1] + H[1][0] + H[0][0] * H[0][1] + H[1][0] * H[1][1]);
          double tr = E00 + E11;
          double S00 = 2 * mu * E00 + lam * tr, S11 = 2 * mu * E11 + lam * tr, S01 = 2 * mu * E01;
          double F00 = 1 + H[0][0], F01 = H[0][1], F10 = H[1][0], F11 = 1 + H[1][1];
          P[0][0] = F00 * S00 + F01 * S01;
          P[0][1] = F00 * S01 + F01 * S11;
          P[1][0] = F10 * S00 + F11 * S01;
          P[1][1] = F10 * S01 + F11 * S11;
          return;
        }
      case MaterialKind::NeoHookean:
        {
          // P = mu (F - F^-T) + lam ln J F^-T; NaN where J <= 0, as the energy is.
          // F - F^-T = (J F - cof F) / J, expanded in H so that nothing cancels at small
          // strain (J - 1 = tr H + det H, ln J = log1p of it)
          double tr = H[0][0] + H[1][1], det = H[0][0] * H[1][1] - H[0][1] * H[1][0];
          double Jm1 = tr + det, J = 1 + Jm1;
          double logJ = J > 0 ? std::log1p(Jm1) : std::nan("");
          double F00 = 1 + H[0][0], F01 = H[0][1], F10 = H[1][0], F11 = 1 + H[1][1];
          double G00 = F11 / J, G01 = -F10 / J, G10 = -F01 / J, G11 = F00 / J;   // F^-T
          double D00 = (H[0][0] + Jm1 + H[0][0] * Jm1 - H[1][1]) / J;   // (F - F^-T)_00
          double D11 = (H[1][1] + Jm1 + H[1][1] * Jm1 - H[0][0]) / J;
          double D01 = (H[0][1] * J + H[1][0]) / J;
          double D10 = (H[1][0] * J + H[0][1]) / J;
          P[0][0] = mu * D00 + lam * logJ * G00;
          P[0][1] = mu * D01 + lam * logJ * G01;
          P[1][0] = mu * D10 + lam * logJ * G10;
          P[1][1] = mu * D11 + lam * logJ * G11;
          return;
        }
      }
    throw ngcore::Exception("ngfracture.InternalForces: unknown material kind");
  }

  void InternalForces (FlatMatrix<double> points, FlatMatrix<int> triangles, FlatVector<double> u,
                       FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                       FlatVector<double> f)
  {
    size_t nv = points.Height(), ne = triangles.Height();
    if (points.Width() != 2 || triangles.Width() != 3)
      throw ngcore::Exception("ngfracture.InternalForces: points must be nv x 2 and triangles ne x 3");
    if (u.Size() != 2 * nv || f.Size() != 2 * nv)
      throw ngcore::Exception("ngfracture.InternalForces: u and f must have 2 nv = " + ngcore::ToString(2 * nv) +
                              " entries, got " + ngcore::ToString(u.Size()) + " and " + ngcore::ToString(f.Size()));
    if (kind.Size() != ne || mu.Size() != ne || lam.Size() != ne)
      throw ngcore::Exception("ngfracture.InternalForces: kind, mu and lam need one entry per triangle");
    for (size_t e = 0; e < ne; e++)
      for (int k = 0; k < 3; k++)
        if (triangles(e, k) < 0 || size_t(triangles(e, k)) >= nv)
          throw ngcore::Exception("ngfracture.InternalForces: triangle " + ngcore::ToString(e) +
                                  " has a vertex number out of range");
    f = 0.0;
    for (size_t e = 0; e < ne; e++)
      {
        int v[3] = { triangles(e, 0), triangles(e, 1), triangles(e, 2) };
        double xa = points(v[0], 0), ya = points(v[0], 1);
        double xb = points(v[1], 0), yb = points(v[1], 1);
        double xc = points(v[2], 0), yc = points(v[2], 1);
        double d = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya);   // twice the signed area
        // gradients of the barycentric coordinates
        double g[3][2] = { { (yb - yc) / d, (xc - xb) / d },
                           { (yc - ya) / d, (xa - xc) / d },
                           { (ya - yb) / d, (xb - xa) / d } };
        double H[2][2] = { { 0, 0 }, { 0, 0 } };
        for (int a = 0; a < 3; a++)
          for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2; j++)
              H[i][j] += u(i * nv + v[a]) * g[a][j];
        double P[2][2];
        FirstPiola(MaterialKind(kind(e)), mu(e), lam(e), H, P);
        double area = 0.5 * std::fabs(d);
        for (int a = 0; a < 3; a++)
          for (int i = 0; i < 2; i++)
            f(i * nv + v[a]) += area * (P[i][0] * g[a][0] + P[i][1] * g[a][1]);
      }
  }
}
