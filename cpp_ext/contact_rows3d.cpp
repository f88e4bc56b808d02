// Node-to-face gap rows in 3D (contact_rows3d.hpp). The sums are numpy's orders:
// np.linalg.norm and sum over 3 entries (a0 + a1) + a2, einsum "ij,ij->i"
// ((a0 + a2) + a1) + 0.0, einsum "ij,ijk->ik" ((b0 P0 + b1 P1) + b2 P2) + 0.0 (einsum
// sums into a +0.0: a -0.0 sum comes out +0.0); np.cross a1 b2 - a2 b1, ...
#include "contact_rows3d.hpp"
#include "numpy_order.hpp"
#include <cmath>

namespace ngfracture
{
  namespace
  {
    // sum_l b_l P[tri_l] (einsum "ij,ijk->ik")
    void Combination (const double * P, const int64_t * tri, const double * b, double * out)
    {
      for (int k = 0; k < 3; k++)
        out[k] = ((b[0] * P[3 * tri[0] + k] + b[1] * P[3 * tri[1] + k]) + b[2] * P[3 * tri[2] + k]) + 0.0;
    }

    // barycentrics of q's projection on the face: signed sub-areas along fn over the area
    void Barycentrics (const double * x, const int64_t * tri, const double * q, const double * fn,
                       double scale, double * b)
    {
      for (int l = 0; l < 3; l++)
        {
          const double * a = x + 3 * tri[(l + 1) % 3], * c = x + 3 * tri[(l + 2) % 3];
          double u[3], v[3], w[3];
          for (int k = 0; k < 3; k++)
            {
              u[k] = a[k] - q[k];
              v[k] = c[k] - q[k];
            }
          NumpyCross(u, v, w);
          b[l] = EinsumDot(w, fn) / scale;
        }
      for (int l = 0; l < 3; l++)
        b[l] = b[l] > 0.0 ? b[l] : 0.0;                   // np.clip(b, 0, None): -0.0 -> 0.0
      double sum = (b[0] + b[1]) + b[2];
      double d = sum > 0 ? sum : 1.0;
      for (int l = 0; l < 3; l++)
        b[l] /= d;
    }
  }

  bool GapMatrixCsr3 (int64_t m, int64_t nv, const int64_t * slave, const int64_t * master,
                      const double * bary, const double * normal, std::vector<int32_t> & indptr,
                      std::vector<int32_t> & indices, std::vector<double> & data)
  {
    for (int64_t r = 0; r < m; r++)
      {
        int64_t v[4] = { slave[r], master[3 * r], master[3 * r + 1], master[3 * r + 2] };
        for (int i = 0; i < 4; i++)
          for (int j = i + 1; j < 4; j++)
            if (v[i] == v[j])
              return false;
      }
    indptr.assign(1, 0);
    indices.clear();
    data.clear();
    indices.reserve(12 * m);
    data.reserve(12 * m);
    for (int64_t r = 0; r < m; r++)
      {
        int64_t v[4] = { slave[r], master[3 * r], master[3 * r + 1], master[3 * r + 2] };
        double w[4] = { 1.0, -bary[3 * r], -bary[3 * r + 1], -bary[3 * r + 2] };
        for (int i = 1; i < 4; i++)                      // insertion sort of the distinct vertices
          for (int j = i; j > 0 && v[j - 1] > v[j]; j--)
            {
              std::swap(v[j - 1], v[j]);
              std::swap(w[j - 1], w[j]);
            }
        for (int comp = 0; comp < 3; comp++)
          for (int i = 0; i < 4; i++)
            {
              double value = w[i] * normal[3 * r + comp];
              if (value != 0.0)
                {
                  indices.push_back(int32_t(v[i] + comp * nv));
                  data.push_back(value);
                }
            }
        indptr.push_back(int32_t(indices.size()));
      }
    return true;
  }

  void GapOffsets3 (int64_t m, const double * X, const int64_t * slave, const int64_t * master,
                    const double * bary, const double * normal, double * g)
  {
    for (int64_t r = 0; r < m; r++)
      {
        double proj[3], d[3];
        const double * Q = X + 3 * slave[r];
        Combination(X, master + 3 * r, bary + 3 * r, proj);
        for (int k = 0; k < 3; k++)
          d[k] = Q[k] - proj[k];
        g[r] = EinsumDot(d, normal + 3 * r);
      }
  }

  void RelineariseRows3 (int64_t m, const double * X, const double * x, const int64_t * slave,
                         const int64_t * master, const double * bary, const double * normal,
                         double * bary_out, double * normal_out, double * dist, double * g)
  {
    for (int64_t r = 0; r < m; r++)
      {
        const int64_t * tri = master + 3 * r;
        const double * old_b = bary + 3 * r, * old_n = normal + 3 * r;
        const double * q = x + 3 * slave[r], * Q = X + 3 * slave[r];
        double area2[3], area0[3], fn[3];
        AreaVector(x, tri, area2);
        AreaVector(X, tri, area0);
        double length = NumpyNorm(area2), reference = NumpyNorm(area0);
        bool degenerate = !(length > 1e-16 * reference);
        double scale = degenerate ? 1.0 : length;
        for (int k = 0; k < 3; k++)
          fn[k] = area2[k] / scale;
        double * b = bary_out + 3 * r, * n = normal_out + 3 * r;
        Barycentrics(x, tri, q, fn, scale, b);
        double side = EinsumDot(fn, old_n) < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 3; k++)
          n[k] = degenerate ? old_n[k] : fn[k] * side;
        int top = 0;                                      // np.argmax: the first largest
        for (int l = 1; l < 3; l++)
          if (old_b[l] > old_b[top])
            top = l;
        const double * corner = X + 3 * tri[top];
        bool keep = degenerate || (old_b[top] == 1.0 && corner[0] == Q[0] && corner[1] == Q[1]
                                   && corner[2] == Q[2]);
        if (keep)
          for (int l = 0; l < 3; l++)
            b[l] = old_b[l];
        double proj[3], d[3];
        Combination(x, tri, b, proj);
        for (int k = 0; k < 3; k++)
          d[k] = q[k] - proj[k];
        dist[r] = EinsumDot(d, n);
      }
    GapOffsets3(m, X, slave, master, bary_out, normal_out, g);
  }
}
