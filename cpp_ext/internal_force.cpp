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

  // --- tetrahedra: the same laws with 3x3 H, P and a 9x9 tangent (A[3 i + j][3 k + l]) ---

  // Cofactor matrix of H (cof H = det H H^-T), its determinant and its second invariant
  // i2 = ((tr H)^2 - tr(H^2)) / 2 (the sum of the principal 2x2 minors).
  static void Cofactor3 (const double H[3][3], double C[3][3], double & det, double & i2)
  {
    C[0][0] = H[1][1] * H[2][2] - H[1][2] * H[2][1];
    C[0][1] = H[1][2] * H[2][0] - H[1][0] * H[2][2];
    C[0][2] = H[1][0] * H[2][1] - H[1][1] * H[2][0];
    C[1][0] = H[0][2] * H[2][1] - H[0][1] * H[2][2];
    C[1][1] = H[0][0] * H[2][2] - H[0][2] * H[2][0];
    C[1][2] = H[0][1] * H[2][0] - H[0][0] * H[2][1];
    C[2][0] = H[0][1] * H[1][2] - H[0][2] * H[1][1];
    C[2][1] = H[0][2] * H[1][0] - H[0][0] * H[1][2];
    C[2][2] = H[0][0] * H[1][1] - H[0][1] * H[1][0];
    det = H[0][0] * C[0][0] + H[0][1] * C[0][1] + H[0][2] * C[0][2];
    i2 = C[0][0] + C[1][1] + C[2][2];
  }

  // J - 1 = tr H + i2(H) + det H (no cancellation at small strain), ln J (NaN where J <= 0)
  // and G = F^-T = cof(F) / J with cof(I + H) = (1 + tr H) I - H^T + cof H.
  static double InverseTranspose3 (const double H[3][3], double G[3][3], double & Jm1, double & logJ,
                                   double C[3][3], double & i2det)
  {
    double det, i2;
    Cofactor3(H, C, det, i2);
    double tr = H[0][0] + H[1][1] + H[2][2];
    i2det = i2 + det;
    Jm1 = tr + i2det;
    double J = 1 + Jm1;
    logJ = J > 0 ? std::log1p(Jm1) : std::nan("");
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        G[i][j] = ((i == j ? 1 + tr : 0.0) - H[j][i] + C[i][j]) / J;
    return J;
  }

  // St Venant-Kirchhoff: S = 2 mu E + lam tr(E) I, E = (H + H^T + H^T H) / 2.
  static void SecondPiolaSvk (double mu, double lam, const double H[3][3], double S[3][3])
  {
    double E[3][3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        E[i][j] = 0.5 * (H[i][j] + H[j][i] + H[0][i] * H[0][j] + H[1][i] * H[1][j] + H[2][i] * H[2][j]);
    double tr = E[0][0] + E[1][1] + E[2][2];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        S[i][j] = 2 * mu * E[i][j] + (i == j ? lam * tr : 0.0);
  }

  static void FirstPiola (MaterialKind kind, double mu, double lam, const double H[3][3], double P[3][3])
  {
    switch (kind)
      {
      case MaterialKind::Linear:
        {
          double tr = H[0][0] + H[1][1] + H[2][2];
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
              P[i][j] = mu * (H[i][j] + H[j][i]) + (i == j ? lam * tr : 0.0);
          return;
        }
      case MaterialKind::StVenantKirchhoff:
        {
          double S[3][3];   // P = (I + H) S
          SecondPiolaSvk(mu, lam, H, S);
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
              P[i][j] = S[i][j] + H[i][0] * S[0][j] + H[i][1] * S[1][j] + H[i][2] * S[2][j];
          return;
        }
      case MaterialKind::NeoHookean:
        {
          // P = mu (F - F^-T) + lam ln J F^-T, F - F^-T = (J F - cof F) / J
          //   = ((i2 + det H) I + H + H^T + (J - 1) H - cof H) / J: no cancellation at small strain
          double G[3][3], C[3][3], Jm1, logJ, i2det;
          double J = InverseTranspose3(H, G, Jm1, logJ, C, i2det);
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
              {
                double D = ((i == j ? i2det : 0.0) + H[i][j] + H[j][i] + Jm1 * H[i][j] - C[i][j]) / J;
                P[i][j] = mu * D + lam * logJ * G[i][j];
              }
          return;
        }
      }
    throw ngcore::Exception("ngfracture.InternalForces: unknown material kind");
  }

  static void PiolaTangent (MaterialKind kind, double mu, double lam, const double H[3][3], double A[9][9])
  {
    auto d = [] (int a, int b) { return a == b ? 1.0 : 0.0; };
    switch (kind)
      {
      case MaterialKind::Linear:
        for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++)
          for (int k = 0; k < 3; k++) for (int l = 0; l < 3; l++)
            A[3 * i + j][3 * k + l] = mu * (d(i, k) * d(j, l) + d(i, l) * d(j, k)) + lam * d(i, j) * d(k, l);
        return;
      case MaterialKind::StVenantKirchhoff:
        {
          // dP_ij/dF_kl = delta_ik S_lj + mu (F_il F_kj + delta_jl (F F^T)_ik) + lam F_ij F_kl
          double S[3][3], F[3][3], FFt[3][3];
          SecondPiolaSvk(mu, lam, H, S);
          for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
              F[i][j] = (i == j ? 1.0 : 0.0) + H[i][j];
          for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
              FFt[i][k] = F[i][0] * F[k][0] + F[i][1] * F[k][1] + F[i][2] * F[k][2];
          for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) for (int l = 0; l < 3; l++)
              A[3 * i + j][3 * k + l] = d(i, k) * S[l][j] + mu * (F[i][l] * F[k][j] + d(j, l) * FFt[i][k])
                                        + lam * F[i][j] * F[k][l];
          return;
        }
      case MaterialKind::NeoHookean:
        {
          // dP_ij/dF_kl = mu delta_ik delta_jl + (mu - lam ln J) G_il G_kj + lam G_ij G_kl, G = F^-T
          double G[3][3], C[3][3], Jm1, logJ, i2det;
          InverseTranspose3(H, G, Jm1, logJ, C, i2det);
          for (int i = 0; i < 3; i++) for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) for (int l = 0; l < 3; l++)
              A[3 * i + j][3 * k + l] = mu * d(i, k) * d(j, l) + (mu - lam * logJ) * G[i][l] * G[k][j]
                                        + lam * G[i][j] * G[k][l];
          return;
        }
      }
    throw ngcore::Exception("ngfracture.TangentStiffness: unknown material kind");
  }

  // Gradients of the barycentric coordinates of tetrahedron v (g[a][j]), and six times its
  // signed volume: with the edges e_i = x_i - x_0, grad lambda_1 = e_2 x e_3 / det, and cyclic.
  static double BarycentricGradients (FlatMatrix<double> points, const int v[4], double g[4][3])
  {
    double e[3][3];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        e[i][j] = points(v[i + 1], j) - points(v[0], j);
    for (int i = 0; i < 3; i++)
      {
        const double * p = e[(i + 1) % 3], * q = e[(i + 2) % 3];
        g[i + 1][0] = p[1] * q[2] - p[2] * q[1];
        g[i + 1][1] = p[2] * q[0] - p[0] * q[2];
        g[i + 1][2] = p[0] * q[1] - p[1] * q[0];
      }
    double det = e[0][0] * g[1][0] + e[0][1] * g[1][1] + e[0][2] * g[1][2];
    for (int a = 1; a < 4; a++)
      for (int j = 0; j < 3; j++)
        g[a][j] /= det;
    for (int j = 0; j < 3; j++)
      g[0][j] = -(g[1][j] + g[2][j] + g[3][j]);
    return det;
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

  // Vertices v, barycentric gradients g and displacement gradient H = grad u of simplex e
  // (D = 2: triangle, D = 3: tetrahedron); returns its area or volume.
  template <int D>
  static double ElementState (FlatMatrix<double> points, FlatMatrix<int> elements, FlatVector<double> u,
                              size_t e, int v[D + 1], double g[D + 1][D], double H[D][D])
  {
    size_t nv = points.Height();
    for (int a = 0; a <= D; a++)
      v[a] = elements(e, a);
    double measure = D == 2 ? 0.5 * std::fabs(BarycentricGradients(points, v, g))
                            : std::fabs(BarycentricGradients(points, v, g)) / 6.0;
    for (int i = 0; i < D; i++)
      for (int j = 0; j < D; j++)
        H[i][j] = 0.0;
    for (int a = 0; a <= D; a++)
      for (int i = 0; i < D; i++)
        for (int j = 0; j < D; j++)
          H[i][j] += u(i * nv + v[a]) * g[a][j];
    return measure;
  }

  // Checks the arrays; returns the dimension (2: triangles, 3: tetrahedra).
  static int CheckKernelInput (const char * name, FlatMatrix<double> points, FlatMatrix<int> elements,
                               size_t nu, FlatVector<int> kind, FlatVector<double> mu,
                               FlatVector<double> lam)
  {
    size_t nv = points.Height(), ne = elements.Height();
    std::string fn = std::string("ngfracture.") + name;
    int dim = points.Width();
    if (!((dim == 2 && elements.Width() == 3) || (dim == 3 && elements.Width() == 4)))
      throw ngcore::Exception(fn + ": points must be nv x 2 with triangles ne x 3, or nv x 3 with "
                              "tetrahedra ne x 4; got points of width " + ngcore::ToString(points.Width()) +
                              " and elements of width " + ngcore::ToString(elements.Width()));
    if (nu != size_t(dim) * nv)
      throw ngcore::Exception(fn + ": u must have " + ngcore::ToString(dim) + " nv = " +
                              ngcore::ToString(dim * nv) + " entries, got " + ngcore::ToString(nu));
    if (kind.Size() != ne || mu.Size() != ne || lam.Size() != ne)
      throw ngcore::Exception(fn + ": kind, mu and lam need one entry per element (triangle or tetrahedron)");
    for (size_t e = 0; e < ne; e++)
      for (int k = 0; k <= dim; k++)
        if (elements(e, k) < 0 || size_t(elements(e, k)) >= nv)
          throw ngcore::Exception(fn + ": element " + ngcore::ToString(e) +
                                  " has a vertex number out of range");
    return dim;
  }

  // The CSR pattern of D components on the vertex graph of the elements: row (c, v) holds
  // the columns (0, w), ..., (D-1, w) for w in the sorted neighbours of v (itself included),
  // so every row is sorted. neighbours[start[v]:start[v+1]] is that list.
  template <int D>
  static void VertexPattern (size_t nv, FlatMatrix<int> elements, Array<int> & start, Array<int> & neighbours,
                             Array<int> & indptr, Array<int> & indices)
  {
    size_t ne = elements.Height();
    Array<int> count(nv + 1);
    count = 0;
    for (size_t e = 0; e < ne; e++)
      for (int a = 0; a <= D; a++)
        count[elements(e, a) + 1] += D;
    for (size_t v = 0; v < nv; v++)
      count[v + 1] += count[v] + 1;
    Array<int> fill(nv);
    neighbours.SetSize(count[nv]);
    for (size_t v = 0; v < nv; v++)
      {
        neighbours[count[v]] = v;
        fill[v] = count[v] + 1;
      }
    for (size_t e = 0; e < ne; e++)
      for (int a = 0; a <= D; a++)
        for (int b = 0; b <= D; b++)
          if (a != b)
            neighbours[fill[elements(e, a)]++] = elements(e, b);
    start.SetSize(nv + 1);     // compressed: sorted, duplicates removed
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
    indptr.SetSize(D * nv + 1);
    indptr[0] = 0;
    for (int c = 0; c < D; c++)
      for (size_t v = 0; v < nv; v++)
        {
          size_t row = c * nv + v;
          indptr[row + 1] = indptr[row] + D * (start[v + 1] - start[v]);
        }
    indices.SetSize(indptr[D * nv]);
    for (int c = 0; c < D; c++)
      for (size_t v = 0; v < nv; v++)
        {
          int deg = start[v + 1] - start[v], at = indptr[c * nv + v];
          for (int k = 0; k < D; k++)
            for (int n = 0; n < deg; n++)
              indices[at + k * deg + n] = k * nv + neighbours[start[v] + n];
        }
  }

  template <int D>
  static void TangentStiffnessD (FlatMatrix<double> points, FlatMatrix<int> elements, FlatVector<double> u,
                                 FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                                 Array<int> & indptr, Array<int> & indices, Array<double> & data)
  {
    size_t nv = points.Height(), ne = elements.Height();
    Array<int> start, neighbours;
    VertexPattern<D>(nv, elements, start, neighbours, indptr, indices);
    data.SetSize(indptr[D * nv]);
    data = 0.0;
    for (size_t e = 0; e < ne; e++)
      {
        int v[D + 1];
        double g[D + 1][D], H[D][D];
        double measure = ElementState<D>(points, elements, u, e, v, g, H);
        double A[D * D][D * D];
        PiolaTangent(MaterialKind(kind(e)), mu(e), lam(e), H, A);
        if constexpr (D == 3)
          {
            // factored: AG_b[ij][k] = sum_l A_ijkl g_bl once per b, then sum_j g_aj AG_b[ij][k]
            // (750 products per tetrahedron instead of 2600)
            double AG[D + 1][D * D][D];
            for (int b = 0; b <= D; b++)
              for (int ij = 0; ij < D * D; ij++)
                for (int k = 0; k < D; k++)
                  AG[b][ij][k] = measure * (A[ij][D * k] * g[b][0] + A[ij][D * k + 1] * g[b][1]
                                            + A[ij][D * k + 2] * g[b][2]);
            for (int a = 0; a <= D; a++)
              {
                int deg = start[v[a] + 1] - start[v[a]];
                const int * nb = &neighbours[start[v[a]]];
                double * row[D];
                for (int i = 0; i < D; i++)
                  row[i] = &data[indptr[i * nv + v[a]]];
                for (int b = 0; b <= D; b++)
                  {
                    int pos = std::lower_bound(nb, nb + deg, v[b]) - nb;
                    for (int i = 0; i < D; i++)
                      for (int k = 0; k < D; k++)
                        row[i][k * deg + pos] += g[a][0] * AG[b][D * i][k] + g[a][1] * AG[b][D * i + 1][k]
                                                 + g[a][2] * AG[b][D * i + 2][k];
                  }
              }
          }
        else
          for (int a = 0; a <= D; a++)
            {
              int deg = start[v[a] + 1] - start[v[a]];
              const int * nb = &neighbours[start[v[a]]];
              for (int b = 0; b <= D; b++)
                {
                  int pos = std::lower_bound(nb, nb + deg, v[b]) - nb;
                  for (int i = 0; i < D; i++)
                    for (int k = 0; k < D; k++)
                      {
                        double s = 0;
                        for (int j = 0; j < D; j++)
                          for (int l = 0; l < D; l++)
                            s += A[D * i + j][D * k + l] * g[a][j] * g[b][l];
                        data[indptr[i * nv + v[a]] + k * deg + pos] += measure * s;
                      }
                }
            }
      }
  }

  template <int D>
  static void InternalForcesD (FlatMatrix<double> points, FlatMatrix<int> elements, FlatVector<double> u,
                               FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                               FlatVector<double> f)
  {
    size_t nv = points.Height(), ne = elements.Height();
    f = 0.0;
    for (size_t e = 0; e < ne; e++)
      {
        int v[D + 1];
        double g[D + 1][D], H[D][D];
        double measure = ElementState<D>(points, elements, u, e, v, g, H);
        double P[D][D];
        FirstPiola(MaterialKind(kind(e)), mu(e), lam(e), H, P);
        for (int a = 0; a <= D; a++)
          for (int i = 0; i < D; i++)
            {
              double s = P[i][0] * g[a][0];
              for (int j = 1; j < D; j++)
                s += P[i][j] * g[a][j];
              f(i * nv + v[a]) += measure * s;
            }
      }
  }

  void TangentStiffness (FlatMatrix<double> points, FlatMatrix<int> elements, FlatVector<double> u,
                         FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                         Array<int> & indptr, Array<int> & indices, Array<double> & data)
  {
    if (CheckKernelInput("TangentStiffness", points, elements, u.Size(), kind, mu, lam) == 2)
      TangentStiffnessD<2>(points, elements, u, kind, mu, lam, indptr, indices, data);
    else
      TangentStiffnessD<3>(points, elements, u, kind, mu, lam, indptr, indices, data);
  }

  void InternalForces (FlatMatrix<double> points, FlatMatrix<int> elements, FlatVector<double> u,
                       FlatVector<int> kind, FlatVector<double> mu, FlatVector<double> lam,
                       FlatVector<double> f)
  {
    int dim = CheckKernelInput("InternalForces", points, elements, u.Size(), kind, mu, lam);
    if (f.Size() != size_t(dim) * points.Height())
      throw ngcore::Exception("ngfracture.InternalForces: f must have " + ngcore::ToString(dim) + " nv = " +
                              ngcore::ToString(dim * points.Height()) + " entries, got " +
                              ngcore::ToString(f.Size()));
    if (dim == 2)
      InternalForcesD<2>(points, elements, u, kind, mu, lam, f);
    else
      InternalForcesD<3>(points, elements, u, kind, mu, lam, f);
  }
}
