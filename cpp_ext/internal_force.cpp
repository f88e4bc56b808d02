#include "internal_force.hpp"
#include <algorithm>
#include <cmath>

namespace ngfracture
{
  using namespace ngbla;

  // St Venant-Kirchhoff: S = 2 mu E + lam tr(E) I with E = (H + H^T + H^T H) / 2, written in
  // H so that nothing cancels at small strain.
  static void SecondPiolaSvk (double mu, double lam, const double H[2][2], double S[2][2])
  {
    double E00 = H[0][0] + 0.5 * (H[0][0] * H[0][0] + H[1][0] * H[1][0]);
    double E11 = H[1][1] + 0.5 * (H[0][1] * H[0][1] + H[1][1] * H[1][1]);
    double E01 = 0.5 * (H[0][1] + H[1][0] + H[0][0] * H[0][1] + H[1][0] * H[1][1]);
    double tr = E00 + E11;
    S[0][0] = 2 * mu * E00 + lam * tr;
    S[1][1] = 2 * mu * E11 + lam * tr;
    S[0][1] = S[1][0] = 2 * mu * E01;
  }

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
          // P = (I + H) S
          double S[2][2];
          SecondPiolaSvk(mu, lam, H, S);
          double S00 = S[0][0], S11 = S[1][1], S01 = S[0][1];
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

  // Material tangent A_ijkl = dP_ij / dH_kl (A[2 i + j][2 k + l]) of the law's P(H).
  static void PiolaTangent (MaterialKind kind, double mu, double lam, const double H[2][2],
                            double A[4][4])
  {
    auto d = [] (int a, int b) { return a == b ? 1.0 : 0.0; };
    switch (kind)
      {
      case MaterialKind::Linear:
        for (int i = 0; i < 2; i++) for (int j = 0; j < 2; j++)
          for (int k = 0; k < 2; k++) for (int l = 0; l < 2; l++)
            A[2 * i + j][2 * k + l] = mu * (d(i, k) * d(j, l) + d(i, l) * d(j, k)) + lam * d(i, j) * d(k, l);
        return;
      case MaterialKind::StVenantKirchhoff:
        {
          // dP_ij/dF_kl = delta_ik S_lj + mu (F_il F_kj + delta_jl (F F^T)_ik) + lam F_ij F_kl
          double S[2][2];
          SecondPiolaSvk(mu, lam, H, S);
          double F[2][2] = { { 1 + H[0][0], H[0][1] }, { H[1][0], 1 + H[1][1] } };
          double FFt[2][2];
          for (int i = 0; i < 2; i++) for (int k = 0; k < 2; k++)
            FFt[i][k] = F[i][0] * F[k][0] + F[i][1] * F[k][1];
          for (int i = 0; i < 2; i++) for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) for (int l = 0; l < 2; l++)
              A[2 * i + j][2 * k + l] = d(i, k) * S[l][j] + mu * (F[i][l] * F[k][j] + d(j, l) * FFt[i][k])
                                        + lam * F[i][j] * F[k][l];
          return;
        }
      case MaterialKind::NeoHookean:
        {
          // dP_ij/dF_kl = mu delta_ik delta_jl + (mu - lam ln J) G_il G_kj + lam G_ij G_kl, G = F^-T
          double Jm1 = H[0][0] + H[1][1] + H[0][0] * H[1][1] - H[0][1] * H[1][0], J = 1 + Jm1;
          double logJ = J > 0 ? std::log1p(Jm1) : std::nan("");
          double G[2][2] = { { (1 + H[1][1]) / J, -H[1][0] / J }, { -H[0][1] / J, (1 + H[0][0]) / J } };
          for (int i = 0; i < 2; i++) for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) for (int l = 0; l < 2; l++)
              A[2 * i + j][2 * k + l] = mu * d(i, k) * d(j, l) + (mu - lam * logJ) * G[i][l] * G[k][j]
                                        + lam * G[i][j] * G[k][l];
          return;
        }
      }
    throw ngcore::Exception("ngfracture.TangentStiffness: unknown material kind");
  }

  // Gradients of the barycentric coordinates of triangle e (g[a][j]), and twice its signed area.
  static double BarycentricGradients (FlatMatrix<double> points, const int v[3], double g[3][2])
  {
    double xa = points(v[0], 0), ya = points(v[0], 1);
    double xb = points(v[1], 0), yb = points(v[1], 1);
    double xc = points(v[2], 0), yc = points(v[2], 1);
    double d = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya);
    g[0][0] = (yb - yc) / d; g[0][1] = (xc - xb) / d;
    g[1][0] = (yc - ya) / d; g[1][1] = (xa - xc) / d;
    g[2][0] = (ya - yb) / d; g[2][1] = (xb - xa) / d;
    return d;
  }

  // Vertices v, barycentric gradients g and displacement gradient H = grad u of triangle e;
  // returns its area.
  static double ElementState (FlatMatrix<double> points, FlatMatrix<int> triangles, FlatVector<double> u,
                              size_t e, int v[3], double g[3][2], double H[2][2])
  {
    size_t nv = points.Height();
    for (int a = 0; a < 3; a++)
      v[a] = triangles(e, a);
    double area = 0.5 * std::fabs(BarycentricGradients(points, v, g));
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2; j++)
        H[i][j] = 0.0;
    for (int a = 0; a < 3; a++)
      for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
          H[i][j] += u(i * nv + v[a]) * g[a][j];
    return area;
  }

  static void CheckKernelInput (const char * name, FlatMatrix<double> points, FlatMatrix<int> triangles,
                                size_t nu, FlatVector<int> kind, FlatVector<double> mu,
                                FlatVector<double> lam)
  {
    size_t nv = points.Height(), ne = triangles.Height();
    std::string fn = std::string("ngfracture.") + name;
    if (points.Width() != 2 || triangles.Width() != 3)
      throw ngcore::Exception(fn + ": points must be nv x 2 and triangles ne x 3");
    if (nu != 2 * nv)
      throw ngcore::Exception(fn + ": u must have 2 nv = " + ngcore::ToString(2 * nv) +
                              " entries, got " + ngcore::ToString(nu));
    if (kind.Size() != ne || mu.Size() != ne || lam.Size() != ne)
      throw ngcore::Exception(fn + ": kind, mu and lam need one entry per triangle");
    for (size_t e = 0; e < ne; e++)
      for (int k = 0; k < 3; k++)
        if (triangles(e, k) < 0 || size_t(triangles(e, k)) >= nv)
          throw ngcore::Exception(fn + ": triangle " + ngcore::ToString(e) +
                                  " has a vertex number out of range");
  }

  void TangentStiffness (FlatMatrix<double> points, FlatMatrix<int> triangles, FlatVector<double> u,
                         FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                         Array<int> & indptr, Array<int> & indices, Array<double> & data)
  {
    CheckKernelInput("TangentStiffness", points, triangles, u.Size(), kind, mu, lam);
    size_t nv = points.Height(), ne = triangles.Height();
    // the neighbours of every vertex (itself included), sorted: row (c, v) holds the columns
    // (0, w) then (1, w) for w in that list, so every row is sorted
    Array<int> count(nv + 1);
    count = 0;
    for (size_t e = 0; e < ne; e++)
      for (int a = 0; a < 3; a++)
        count[triangles(e, a) + 1] += 3;
    for (size_t v = 0; v < nv; v++)
      count[v + 1] += count[v] + 1;
    Array<int> fill(nv), neighbours(count[nv]);
    for (size_t v = 0; v < nv; v++)
      {
        neighbours[count[v]] = v;
        fill[v] = count[v] + 1;
      }
    for (size_t e = 0; e < ne; e++)
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
          if (a != b)
            neighbours[fill[triangles(e, a)]++] = triangles(e, b);
    Array<int> start(nv + 1);     // compressed: sorted, duplicates removed
    start[0] = 0;
    size_t kept = 0;
    for (size_t v = 0; v < nv; v++)
      {
        int * first = &neighbours[count[v]], * last = &neighbours[0] + fill[v];
        std::sort(first, last);
        last = std::unique(first, last);
        for (int * p = first; p < last; p++)
          neighbours[kept++] = *p;
        start[v + 1] = kept;
      }
    indptr.SetSize(2 * nv + 1);
    indptr[0] = 0;
    for (int c = 0; c < 2; c++)
      for (size_t v = 0; v < nv; v++)
        {
          size_t row = c * nv + v;
          indptr[row + 1] = indptr[row] + 2 * (start[v + 1] - start[v]);
        }
    indices.SetSize(indptr[2 * nv]);
    for (int c = 0; c < 2; c++)
      for (size_t v = 0; v < nv; v++)
        {
          int deg = start[v + 1] - start[v], at = indptr[c * nv + v];
          for (int k = 0; k < 2; k++)
            for (int n = 0; n < deg; n++)
              indices[at + k * deg + n] = k * nv + neighbours[start[v] + n];
        }
    data.SetSize(indptr[2 * nv]);
    data = 0.0;
    for (size_t e = 0; e < ne; e++)
      {
        int v[3];
        double g[3][2], H[2][2];
        double area = ElementState(points, triangles, u, e, v, g, H);
        double A[4][4];
        PiolaTangent(MaterialKind(kind(e)), mu(e), lam(e), H, A);
        for (int a = 0; a < 3; a++)
          {
            int deg = start[v[a] + 1] - start[v[a]];
            const int * nb = &neighbours[start[v[a]]];
            for (int b = 0; b < 3; b++)
              {
                int pos = std::lower_bound(nb, nb + deg, v[b]) - nb;
                for (int i = 0; i < 2; i++)
                  for (int k = 0; k < 2; k++)
                    {
                      double s = 0;
                      for (int j = 0; j < 2; j++)
                        for (int l = 0; l < 2; l++)
                          s += A[2 * i + j][2 * k + l] * g[a][j] * g[b][l];
                      data[indptr[i * nv + v[a]] + k * deg + pos] += area * s;
                    }
              }
          }
      }
  }

  void InternalForces (FlatMatrix<double> points, FlatMatrix<int> triangles, FlatVector<double> u,
                       FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                       FlatVector<double> f)
  {
    CheckKernelInput("InternalForces", points, triangles, u.Size(), kind, mu, lam);
    size_t nv = points.Height(), ne = triangles.Height();
    if (f.Size() != 2 * nv)
      throw ngcore::Exception("ngfracture.InternalForces: f must have 2 nv = " + ngcore::ToString(2 * nv) +
                              " entries, got " + ngcore::ToString(f.Size()));
    f = 0.0;
    for (size_t e = 0; e < ne; e++)
      {
        int v[3];
        double g[3][2], H[2][2];
        double area = ElementState(points, triangles, u, e, v, g, H);
        double P[2][2];
        FirstPiola(MaterialKind(kind(e)), mu(e), lam(e), H, P);
        for (int a = 0; a < 3; a++)
          for (int i = 0; i < 2; i++)
            f(i * nv + v[a]) += area * (P[i][0] * g[a][0] + P[i][1] * g[a][1]);
      }
  }
}
