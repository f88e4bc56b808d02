// Rows between copies of a point (copies3d.hpp), in numpy's orders of
// operations (numpy_order.hpp; np.mean of two (g0 + g1) / 2).
#include "copies3d.hpp"
#include "numpy_order.hpp"
#include <algorithm>
#include <cmath>

namespace ngfracture
{
  namespace
  {
    // x_p - x_q
    void Difference (const double * x, int64_t p, int64_t q, double * d)
    {
      for (int k = 0; k < 3; k++)
        d[k] = x[3 * p + k] - x[3 * q + k];
    }

    // min over s in [0, 1] of max(g[0](s), g[1](s)), g[k](s) = (1 - s) g[k][0] + s g[k][1]: the
    // deepest that a point of edge a lies behind both planes of B's wedge (a convex piecewise
    // linear function: at an end, or where the two gaps cross)
    double LowestAlongEdge (const double g[2][2])
    {
      double lowest = std::min(std::max(g[0][0], g[1][0]), std::max(g[0][1], g[1][1]));
      double h0 = g[0][0] - g[1][0], h1 = g[0][1] - g[1][1];
      if ((h0 < 0 && h1 > 0) || (h0 > 0 && h1 < 0))
        {
          double s = h0 / (h0 - h1);
          lowest = std::min(lowest, g[0][0] + s * (g[0][1] - g[0][0]));
        }
      return lowest;
    }
  }

  void PartnerAt (int64_t m, const int64_t * faces, const int64_t * key_order, const int64_t * key_start,
                  const int64_t * key_count, const int64_t * face, const int64_t * vertex, int64_t * out)
  {
    for (int64_t i = 0; i < m; i++)
      {
        out[i] = -1;
        for (int64_t k = 0; k < key_count[face[i]]; k++)
          {
            int64_t cand = key_order[key_start[face[i]] + k];
            const int64_t * tri = faces + 3 * cand;
            if (tri[0] == vertex[i] || tri[1] == vertex[i] || tri[2] == vertex[i])
              {
                out[i] = cand;
                break;
              }
          }
      }
  }

  void FoundRowsAtCopies (int64_t m, const int64_t * faces, const int64_t * point, const int64_t * vf,
                          const int64_t * key_order, const int64_t * key_start, const int64_t * key_count,
                          const double * unit, int64_t * slave, int64_t * master, int64_t * face, double * bary,
                          double * normal, double * g, uint8_t * at_copy)
  {
    for (int64_t i = 0; i < m; i++)
      {
        int64_t s = slave[i], ps = point[s], * tri = master + 3 * i;
        int corner = -1;                                  // the first corner at the slave's point
        for (int k = 0; k < 3 && corner < 0; k++)
          if (point[tri[k]] == ps)
            corner = k;
        at_copy[i] = corner >= 0 && ps >= 0;
        if (!at_copy[i])
          {
            std::copy(faces + 3 * face[i], faces + 3 * face[i] + 3, tri);
            continue;
          }
        int64_t copy = tri[corner];
        if (vf[s] < vf[copy] || (vf[s] == vf[copy] && s < copy))
          {
            int64_t partner;
            PartnerAt(1, faces, key_order, key_start, key_count, face + i, &s, &partner);
            if (partner >= 0)
              {
                slave[i] = copy;
                copy = s;
                face[i] = partner;
              }
          }
        std::copy(faces + 3 * face[i], faces + 3 * face[i] + 3, tri);
        for (int k = 0; k < 3; k++)
          {
            normal[3 * i + k] = unit[3 * face[i] + k];
            bary[3 * i + k] = tri[k] == copy ? 1.0 : 0.0;
          }
        g[i] = 0.0;
      }
  }

  void FoldedIncidences (const FoldInput & in, int64_t m, const uint8_t * pick, const int64_t * slave,
                         const int64_t * master, const double * bary, const double * normal, const int64_t * tied,
                         int64_t n_tied, double kink, std::vector<int64_t> & out_slave,
                         std::vector<int64_t> & out_face, std::vector<int64_t> & out_corner)
  {
    out_slave.clear();
    out_face.clear();
    out_corner.clear();
    std::vector<std::pair<int64_t, int64_t>> picked;     // (s nv + t, row), stable by code below
    for (int64_t i = 0; i < m; i++)
      {
        if (!pick[i])
          continue;
        const double * b = bary + 3 * i;
        int top = 0;                                      // np.argmax: the first largest
        for (int l = 1; l < 3; l++)
          if (b[l] > b[top])
            top = l;
        int64_t s = slave[i], t = master[3 * i + top], p = in.point[s];
        if (p < 0 || in.copies[p] != 2 || in.vf[s] == in.vf[t])
          continue;
        int64_t tie = std::min(s, t) * in.nv + std::max(s, t);
        if (n_tied && std::binary_search(tied, tied + n_tied, tie))
          continue;
        picked.emplace_back(s * in.nv + t, i);
      }
    std::stable_sort(picked.begin(), picked.end(), [] (const auto & a, const auto & b) { return a.first < b.first; });
    const int64_t nk = in.nf + 1;
    for (size_t lo = 0; lo < picked.size();)
      {
        size_t hi = lo;
        while (hi < picked.size() && picked[hi].first == picked[lo].first)
          hi++;
        int64_t s = picked[lo].first / in.nv, t = picked[lo].first % in.nv;
        const int64_t * first = std::lower_bound(in.incident, in.incident + 3 * in.nf, t);
        const int64_t * last = std::upper_bound(first, in.incident + 3 * in.nf, t);
        for (const int64_t * q = first; q < last; q++)
          {
            int64_t slot = in.incidence[q - in.incident], f = slot / 3;
            if (!std::binary_search(in.vertex_keys, in.vertex_keys + in.n_keys, s * nk + in.face_key[f]))
              continue;                                   // no face of f's key at s
            const double * u = in.unit + 3 * f;
            bool parallel = false;
            for (size_t j = lo; j < hi && !parallel; j++)
              {
                const double * n = normal + 3 * picked[j].second;
                parallel = 1.0 - ((u[0] * n[0] + u[1] * n[1]) + u[2] * n[2]) <= kink;
              }
            if (parallel)
              continue;
            out_slave.push_back(s);
            out_face.push_back(f);
            out_corner.push_back(slot % 3);
          }
        lo = hi;
      }
  }

  void BehindPartnerGaps (int64_t m, int64_t nv, const double * x, const int64_t * faces, const int64_t * slave,
                          const int64_t * face, const int64_t * corner, double tol, std::vector<int64_t> & hit,
                          std::vector<double> & gap)
  {
    std::vector<double> all(m, 0.0);
    std::vector<int64_t> deep;                            // codes s nv + t of the pairs hit
    for (int64_t i = 0; i < m; i++)
      {
        const int64_t * tri = faces + 3 * face[i];
        int64_t s = slave[i], t = tri[corner[i]];
        double d[3], area[3];
        Difference(x, s, t, d);
        if (x[3 * s] == x[3 * t] && x[3 * s + 1] == x[3 * t + 1] && x[3 * s + 2] == x[3 * t + 2])
          continue;                                       // copies that meet are behind no plane
        AreaVector(x, tri, area);
        double length = NumpyNorm(area);
        all[i] = length > 0 ? EinsumDot(area, d) / length : 0.0;
        if (all[i] < -tol)
          deep.push_back(s * nv + t);
      }
    std::sort(deep.begin(), deep.end());
    deep.erase(std::unique(deep.begin(), deep.end()), deep.end());
    hit.clear();
    gap.clear();
    if (deep.empty())
      return;
    for (int64_t i = 0; i < m; i++)
      {
        int64_t code = slave[i] * nv + faces[3 * face[i] + corner[i]];
        if (std::binary_search(deep.begin(), deep.end(), code))
          {
            hit.push_back(i);
            gap.push_back(all[i]);
          }
      }
  }

  void WedgeInside (int64_t m, const double * x, const int64_t * faces, const int64_t * a, const int64_t * b,
                    const int64_t * fb, double tol, std::vector<int64_t> & pair, std::vector<int64_t> & nearer,
                    std::vector<double> & gap)
  {
    pair.clear();
    nearer.clear();
    gap.clear();
    for (int64_t p = 0; p < m; p++)
      {
        double unit[2][3], g[2][2], middle[2];
        bool ok = true;
        for (int k = 0; k < 2; k++)
          {
            double n[3];
            AreaVector(x, faces + 3 * fb[2 * p + k], n);
            double length = NumpyNorm(n);
            ok = ok && length > 0;                        // a face squeezed flat has no plane
            double scale = length > 0 ? length : 1.0;
            for (int c = 0; c < 3; c++)
              unit[k][c] = n[c] / scale;
          }
        // the corner of B's second face off the edge: B's wedge is convex (or flat) where
        // it lies behind (or on) the first's plane
        const int64_t * second = faces + 3 * fb[2 * p + 1];
        int64_t third = (second[0] + second[1] + second[2]) - (b[2 * p] + b[2 * p + 1]);
        double d[3];
        Difference(x, third, b[2 * p], d);
        bool convex = EinsumDot(unit[0], d) <= 0;
        for (int k = 0; k < 2; k++)
          {
            for (int e = 0; e < 2; e++)
              {
                Difference(x, a[2 * p + e], b[2 * p + e], d);
                g[k][e] = EinsumDot(unit[k], d);
              }
            middle[k] = (g[k][0] + g[k][1]) / 2.0;
          }
        int near = middle[1] > middle[0] ? 1 : 0;          // np.argmax: the first largest
        bool inside = std::max(middle[0], middle[1]) < -tol;
        if (!inside && convex && ok && LowestAlongEdge(g) < -tol)
          {
            // a part of the edge off its middle inside: the face whose plane the deepest end
            // behind it is least deep behind (out through it the edge needs the least motion)
            inside = true;
            near = std::max(-g[1][0], -g[1][1]) < std::max(-g[0][0], -g[0][1]) ? 1 : 0;
          }
        if (convex && inside && ok)
          {
            pair.push_back(p);
            nearer.push_back(near);
            gap.push_back(g[near][0]);
            gap.push_back(g[near][1]);
          }
      }
  }

  void ReflexWedgeGaps (int64_t m, const double * x, const int64_t * faces, const int64_t * a, const int64_t * b,
                        const int64_t * fb, const uint8_t * partner, double tol, std::vector<int64_t> & pair,
                        std::vector<double> & gap)
  {
    pair.clear();
    gap.clear();
    for (int64_t p = 0; p < m; p++)
      {
        double unit[2][3], g[2][2];
        bool ok = true;
        for (int k = 0; k < 2; k++)
          {
            double n[3];
            AreaVector(x, faces + 3 * fb[2 * p + k], n);
            double length = NumpyNorm(n);
            ok = ok && length > 0;                        // a face squeezed flat has no plane
            double scale = length > 0 ? length : 1.0;
            for (int c = 0; c < 3; c++)
              unit[k][c] = n[c] / scale;
          }
        if (!ok)
          continue;
        // reflex: the corner of B's second face off the edge strictly in front of the
        // first's plane (WedgeInside's test of a convex or flat wedge, negated)
        const int64_t * second = faces + 3 * fb[2 * p + 1];
        int64_t third = (second[0] + second[1] + second[2]) - (b[2 * p] + b[2 * p + 1]);
        double d[3];
        Difference(x, third, b[2 * p], d);
        if (!(EinsumDot(unit[0], d) > 0))
          continue;
        double least = 0.0;
        for (int k = 0; k < 2; k++)
          for (int e = 0; e < 2; e++)
            {
              Difference(x, a[2 * p + e], b[2 * p + e], d);
              g[k][e] = EinsumDot(unit[k], d);
              if (!partner[2 * p + k])
                least = std::min(least, g[k][e]);
            }
        if (least < -tol)
          {
            pair.push_back(p);
            gap.insert(gap.end(), { g[0][0], g[0][1], g[1][0], g[1][1] });
          }
      }
  }
}
