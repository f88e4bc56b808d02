// Rows between copies of a point (copies3d.hpp), in numpy's orders of
// operations (numpy_order.hpp; np.mean of two (g0 + g1) / 2).
#include "copies3d.hpp"
#include "numpy_order.hpp"
#include <algorithm>
#include <cmath>
#include <limits>

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

    // The unit normals of a wedge's two faces fw at x (ok: neither squeezed flat) and the
    // side of the corner of its second face off the edge (e0, e1) to the first's plane:
    // the wedge is convex or flat where it is <= 0, reflex where it is > 0.
    bool WedgeNormals (const double * x, const int64_t * faces, const int64_t * fw, int64_t e0, int64_t e1,
                       double unit[2][3], double & corner)
    {
      bool ok = true;
      for (int k = 0; k < 2; k++)
        {
          double n[3];
          AreaVector(x, faces + 3 * fw[k], n);
          double length = NumpyNorm(n);
          ok = ok && length > 0;                        // a face squeezed flat has no plane
          double scale = length > 0 ? length : 1.0;
          for (int c = 0; c < 3; c++)
            unit[k][c] = n[c] / scale;
        }
      const int64_t * second = faces + 3 * fw[1];
      double d[3];
      Difference(x, (second[0] + second[1] + second[2]) - (e0 + e1), e0, d);
      corner = EinsumDot(unit[0], d);
      return ok;
    }

    // The angle (radians) by which a wedge's corner may lie behind a plane and still count
    // as in front of it: faces of two wedges on one plane in the reference configuration
    // (two pieces' faces on a flat outer surface, on the plane of a crack through the
    // line) turn apart by the strains and the pieces' relative rotation.
    constexpr double kOnPlane = 1e-2;

    // Whether the corners off edge (e0, e1) of the two faces fw lie in front of the plane
    // through x_e0 with unit normal n, or behind it by at most kOnPlane of their distance.
    bool CornersInFront (const double * x, const int64_t * faces, const int64_t * fw, int64_t e0, int64_t e1,
                         const double * n)
    {
      for (int k = 0; k < 2; k++)
        {
          const int64_t * f = faces + 3 * fw[k];
          double d[3];
          Difference(x, (f[0] + f[1] + f[2]) - (e0 + e1), e0, d);
          double side = EinsumDot(n, d);
          if (side < 0 && side < -kOnPlane * NumpyNorm(d))
            return false;
        }
      return true;
    }

    // min over s in [0, 1] of max over the candidates c with use[c] of G[c](s) = (1 - s)
    // G[c][0] + s G[c][1]: a convex piecewise linear function, lowest at an end or where
    // two of the lines cross.
    double LowestOfMax (const double G[4][2], const bool use[4])
    {
      auto at = [&] (double s)
        {
          double high = -std::numeric_limits<double>::infinity();
          for (int c = 0; c < 4; c++)
            if (use[c])
              high = std::max(high, G[c][0] + s * (G[c][1] - G[c][0]));
          return high;
        };
      double lowest = std::min(at(0.0), at(1.0));
      for (int c = 0; c < 4; c++)
        for (int k = c + 1; k < 4; k++)
          {
            if (!use[c] || !use[k])
              continue;
            double h0 = G[c][0] - G[k][0], h1 = G[c][1] - G[k][1];
            if ((h0 < 0 && h1 > 0) || (h0 > 0 && h1 < 0))
              lowest = std::min(lowest, at(h0 / (h0 - h1)));
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
                    const int64_t * fb, const int64_t * fa, double tol, std::vector<int64_t> & pair,
                    std::vector<int64_t> & nearer, std::vector<double> & gap)
  {
    pair.clear();
    nearer.clear();
    gap.clear();
    for (int64_t p = 0; p < m; p++)
      {
        const int64_t * ea = a + 2 * p, * eb = b + 2 * p;
        double unit[4][3], G[4][2], d[3], corner_b, corner_a;
        bool ok_b = WedgeNormals(x, faces, fb + 2 * p, eb[0], eb[1], unit, corner_b);
        bool ok_a = WedgeNormals(x, faces, fa + 2 * p, ea[0], ea[1], unit + 2, corner_a);
        bool convex_b = corner_b <= 0, convex_a = corner_a <= 0;
        // G[k]: a's ends to B's face k, G[2 + k]: b's ends to A's face k (gaps from the copy)
        for (int e = 0; e < 2; e++)
          {
            Difference(x, ea[e], eb[e], d);
            for (int k = 0; k < 2; k++)
              G[k][e] = EinsumDot(unit[k], d);
            Difference(x, eb[e], ea[e], d);
            for (int k = 2; k < 4; k++)
              G[k][e] = EinsumDot(unit[k], d);
          }
        double middle[2] = { (G[0][0] + G[0][1]) / 2.0, (G[1][0] + G[1][1]) / 2.0 };
        int near = middle[1] > middle[0] ? 1 : 0;          // np.argmax: the first largest
        // the midpoint behind both of B's planes: out through the one it is less deep
        // behind, where that plane has A's wedge in front of it (else it separates nothing)
        bool inside = convex_b && ok_b && std::max(middle[0], middle[1]) < -tol
          && CornersInFront(x, faces, fa + 2 * p, ea[0], ea[1], unit[near]);
        if (!inside && convex_b && convex_a && ok_b && ok_a)
          {
            // the planes that can separate the wedges: B's faces with A's wedge in front,
            // A's faces with B's in front; a point of the edge where every one of them
            // reads a gap below -tol is inside
            bool use[4];
            for (int k = 0; k < 2; k++)
              {
                use[k] = CornersInFront(x, faces, fa + 2 * p, ea[0], ea[1], unit[k]);
                use[2 + k] = CornersInFront(x, faces, fb + 2 * p, eb[0], eb[1], unit[2 + k]);
              }
            if ((use[0] || use[1] || use[2] || use[3]) && LowestOfMax(G, use) < -tol)
              {
                // the plane whose deepest end behind it is least deep: the rows that move
                // the edges apart by the least
                inside = true;
                double best = std::numeric_limits<double>::infinity();
                for (int c = 0; c < 4; c++)
                  if (use[c] && std::max(-G[c][0], -G[c][1]) < best)
                    {
                      best = std::max(-G[c][0], -G[c][1]);
                      near = c;
                    }
              }
          }
        if (inside)
          {
            pair.push_back(p);
            nearer.push_back(near);
            gap.push_back(G[near][0]);
            gap.push_back(G[near][1]);
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
        double unit[2][3], g[2][2], d[3], corner;
        // reflex: the corner of B's second face off the edge strictly in front of the
        // first's plane (WedgeInside's test of a convex or flat wedge, negated)
        if (!WedgeNormals(x, faces, fb + 2 * p, b[2 * p], b[2 * p + 1], unit, corner) || !(corner > 0))
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
