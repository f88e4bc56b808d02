// Overlap volume between the fragments of a tetrahedral mesh (see tet_overlap.hpp).
#include "tet_overlap.hpp"
#include "predicates.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

namespace ngfracture
{
  namespace
  {
    using P3 = std::array<double, 3>;

    P3 Sub (const P3 & a, const P3 & b) { return { a[0]-b[0], a[1]-b[1], a[2]-b[2] }; }
    P3 Cross (const P3 & a, const P3 & b)
    {
      return { a[1]*b[2] - a[2]*b[1], a[2]*b[0] - a[0]*b[2], a[0]*b[1] - a[1]*b[0] };
    }
    double Dot (const P3 & a, const P3 & b) { return a[0]*b[0] + a[1]*b[1] + a[2]*b[2]; }
    P3 Load (const double * p) { return { p[0], p[1], p[2] }; }

    // distances to a clipping plane below SNAP times |n| times the polyhedron's reach count as 0
    constexpr double SNAP = 32 * DBL_EPSILON;

    // outward faces of a positively oriented tetrahedron (face k opposite vertex k)
    constexpr int FACE[4][3] = { { 1, 2, 3 }, { 0, 3, 2 }, { 0, 1, 3 }, { 0, 2, 1 } };

    // A convex polyhedron: points (the first four are tetrahedron a's, ``orig`` >= 0) and
    // faces as vertex lists, counter-clockwise seen from outside.
    struct Poly
    {
      std::vector<P3> pts;
      std::vector<int> orig;
      std::vector<std::vector<int>> faces;
    };

    // Exact sign of the side of p to the face plane (i, j, l) of t: +1 outside (away from
    // the opposite vertex k), 0 on the plane, -1 inside.
    int ExactSide (const double * const t[4], int k, const double * p)
    {
      const int * f = FACE[k];
      int sk = Orient3dSign(t[f[0]], t[f[1]], t[f[2]], t[k]);
      return -sk * Orient3dSign(t[f[0]], t[f[1]], t[f[2]], p);
    }

    // Every point of ``pts`` outside or on the face plane k of t: the tetrahedra are separated.
    bool Separated (const double * const t[4], int k, const double * const pts[4])
    {
      for (int m = 0; m < 4; m++)
        if (ExactSide(t, k, pts[m]) < 0)
          return false;
      return true;
    }

    // The cap closing a cut: the on-plane vertices, counter-clockwise about the outward normal n.
    std::vector<int> Cap (const Poly & P, const std::vector<int> & on, const P3 & n)
    {
      P3 c { 0, 0, 0 };
      for (int v : on)
        for (int d = 0; d < 3; d++)
          c[d] += P.pts[v][d] / on.size();
      int axis = 0;
      for (int d = 1; d < 3; d++)
        if (std::abs(n[d]) < std::abs(n[axis]))
          axis = d;
      P3 ax { 0, 0, 0 };
      ax[axis] = 1.0;
      P3 e1 = Cross(n, ax);
      P3 e2 = Cross(n, e1);                 // e1 x e2 = |n|^2 n: counter-clockwise about n
      std::vector<std::pair<double, int>> ang;
      for (int v : on)
      {
        P3 d = Sub(P.pts[v], c);
        ang.emplace_back(std::atan2(Dot(d, e2), Dot(d, e1)), v);
      }
      std::sort(ang.begin(), ang.end());
      std::vector<int> cap;
      for (auto & a : ang)
        cap.push_back(a.second);
      return cap;
    }

    // Clips P by the outward half-space of face k of tetrahedron t; false when nothing is left.
    bool Clip (Poly & P, const double * const t[4], int k)
    {
      const int * fv = FACE[k];
      P3 q = Load(t[fv[0]]);
      int sk = Orient3dSign(t[fv[0]], t[fv[1]], t[fv[2]], t[k]);
      P3 n = Cross(Sub(Load(t[fv[1]]), q), Sub(Load(t[fv[2]]), q));
      for (int d = 0; d < 3; d++)
        n[d] *= sk;                         // outward
      std::vector<char> used(P.pts.size(), 0);
      for (auto & f : P.faces)
        for (int v : f)
          used[v] = 1;
      std::vector<double> s(P.pts.size(), 0.0);
      double reach = 0;
      for (size_t v = 0; v < P.pts.size(); v++)
        if (used[v])
          reach = std::max(reach, std::sqrt(Dot(Sub(P.pts[v], q), Sub(P.pts[v], q))));
      // below the rounding of n.(p - q): on the plane, so that a face lying in it is not cut
      // in pieces by noise (its kept part and the cap would then cover it twice)
      double tol = SNAP * std::sqrt(Dot(n, n)) * reach;
      bool out = false, in = false;
      for (size_t v = 0; v < P.pts.size(); v++)
      {
        if (!used[v]) continue;
        double val = Dot(n, Sub(P.pts[v], q));
        if (P.orig[v] >= 0 && ExactSide(t, k, P.pts[v].data()) == 0)
          val = 0;
        if (std::abs(val) <= tol)
          val = 0;
        s[v] = val;
        out |= val > 0;
        in |= val < 0;
      }
      if (!in) return false;
      if (!out) return true;
      std::map<std::pair<int, int>, int> cut;
      auto cutVertex = [&] (int a, int b)
      {
        int lo = std::min(a, b), hi = std::max(a, b);
        auto it = cut.find({ lo, hi });
        if (it != cut.end()) return it->second;
        double w = s[lo] / (s[lo] - s[hi]);
        P3 p;
        for (int d = 0; d < 3; d++)
          p[d] = P.pts[lo][d] + w * (P.pts[hi][d] - P.pts[lo][d]);
        P.pts.push_back(p);
        P.orig.push_back(-1);
        s.push_back(0.0);
        int id = int(P.pts.size()) - 1;
        cut[{ lo, hi }] = id;
        return id;
      };
      std::vector<std::vector<int>> faces;
      for (auto & f : P.faces)
      {
        std::vector<int> g;
        for (size_t e = 0; e < f.size(); e++)
        {
          int a = f[e], b = f[(e + 1) % f.size()];
          if (s[a] <= 0) g.push_back(a);
          if ((s[a] < 0 && s[b] > 0) || (s[a] > 0 && s[b] < 0)) g.push_back(cutVertex(a, b));
        }
        if (g.size() >= 3) faces.push_back(std::move(g));
      }
      std::vector<int> on;
      for (auto & f : faces)
        for (int v : f)
          if (s[v] == 0) on.push_back(v);
      std::sort(on.begin(), on.end());
      on.erase(std::unique(on.begin(), on.end()), on.end());
      if (on.size() >= 3) faces.push_back(Cap(P, on, n));
      P.faces = std::move(faces);
      return P.faces.size() >= 4;
    }

    double Volume (const Poly & P)
    {
      P3 r { 0, 0, 0 };
      for (int d = 0; d < 3; d++)
        r[d] = P.pts[P.faces[0][0]][d];
      double v = 0;
      for (auto & f : P.faces)
      {
        P3 a = Sub(P.pts[f[0]], r);
        for (size_t i = 1; i + 1 < f.size(); i++)
          v += Dot(a, Cross(Sub(P.pts[f[i]], r), Sub(P.pts[f[i+1]], r)));
      }
      return std::max(v / 6.0, 0.0);
    }
  }

  double TetIntersectionVolume (const double * const a_in[4], const double * const b_in[4])
  {
    const double * a[4] = { a_in[0], a_in[1], a_in[2], a_in[3] };
    const double * b[4] = { b_in[0], b_in[1], b_in[2], b_in[3] };
    for (auto t : { a, b })
      if (Orient3dSign(t[0], t[1], t[2], t[3]) == 0)
        return 0.0;
    if (Orient3dSign(a[0], a[1], a[2], a[3]) > 0) std::swap(a[1], a[2]);    // positively oriented
    if (Orient3dSign(b[0], b[1], b[2], b[3]) > 0) std::swap(b[1], b[2]);
    for (int k = 0; k < 4; k++)
      if (Separated(a, k, b) || Separated(b, k, a))
        return 0.0;
    Poly P;
    for (int k = 0; k < 4; k++)
    {
      P.pts.push_back(Load(a[k]));
      P.orig.push_back(k);
      P.faces.push_back({ FACE[k][0], FACE[k][1], FACE[k][2] });
    }
    for (int k = 0; k < 4; k++)
      if (!Clip(P, b, k))
        return 0.0;
    return Volume(P);
  }

  namespace
  {
    // Bounding boxes of the tetrahedra and the grid cells each covers.
    struct Boxes
    {
      std::vector<double> lo, hi;                  // ne x 3
      std::vector<std::array<int64_t, 6>> range;   // first and last cell along x, y, z
      double h = 0;                                // cell size (0: nothing to search)
    };

    Boxes MakeBoxes (const double * x, const int32_t * tets, int64_t ne)
    {
      Boxes b;
      b.lo.resize(3 * ne);
      b.hi.resize(3 * ne);
      double origin[3] = { INFINITY, INFINITY, INFINITY }, extent = 0;
      for (int64_t e = 0; e < ne; e++)
      {
        double m = 0;
        for (int d = 0; d < 3; d++)
        {
          double lo = INFINITY, hi = -INFINITY;
          for (int k = 0; k < 4; k++)
          {
            double c = x[3 * tets[4 * e + k] + d];
            lo = std::min(lo, c);
            hi = std::max(hi, c);
          }
          b.lo[3 * e + d] = lo;
          b.hi[3 * e + d] = hi;
          origin[d] = std::min(origin[d], lo);
          m = std::max(m, hi - lo);
        }
        extent += m;
      }
      double h = extent / ne;
      if (!(h > 0) || !std::isfinite(h)) return b;
      for (int d = 0; d < 3; d++)                  // at most 2^20 cells along an axis
        for (int64_t e = 0; e < ne; e++)
          h = std::max(h, (b.hi[3 * e + d] - origin[d]) / double(1 << 20));
      b.h = h;
      b.range.resize(ne);
      for (int64_t e = 0; e < ne; e++)
        for (int d = 0; d < 3; d++)
        {
          b.range[e][d] = int64_t(std::floor((b.lo[3 * e + d] - origin[d]) / h));
          b.range[e][3 + d] = int64_t(std::floor((b.hi[3 * e + d] - origin[d]) / h));
        }
      return b;
    }
  }

  TetOverlap FragmentOverlap3 (const double * x, int64_t nv, const int32_t * tets, int64_t ne,
                               const int32_t * fragment)
  {
    TetOverlap res;
    for (int64_t i = 0; i < 4 * ne; i++)
      if (tets[i] < 0 || tets[i] >= nv)
        throw std::invalid_argument("FragmentOverlap3: tetrahedron " + std::to_string(i / 4) + " has vertex number "
                                    + std::to_string(tets[i]) + ", not in [0, " + std::to_string(nv) + ")");
    if (ne < 2) return res;
    Boxes B = MakeBoxes(x, tets, ne);
    if (B.h == 0) return res;
    res.cell = B.h;
    const auto & lo = B.lo, & hi = B.hi;
    const auto & range = B.range;
    std::vector<std::tuple<int64_t, int64_t, int64_t, int32_t>> entries;
    for (int64_t e = 0; e < ne; e++)
      for (int64_t i = range[e][0]; i <= range[e][3]; i++)
        for (int64_t j = range[e][1]; j <= range[e][4]; j++)
          for (int64_t k = range[e][2]; k <= range[e][5]; k++)
            entries.emplace_back(i, j, k, int32_t(e));
    std::sort(entries.begin(), entries.end());
    std::vector<std::tuple<int32_t, int32_t, double>> found;
    for (size_t r0 = 0, r1; r0 < entries.size(); r0 = r1)
    {
      auto [ci, cj, ck, _] = entries[r0];
      for (r1 = r0 + 1; r1 < entries.size() && std::get<0>(entries[r1]) == ci && std::get<1>(entries[r1]) == cj
                        && std::get<2>(entries[r1]) == ck; r1++) {}
      int64_t cell[3] = { ci, cj, ck };
      for (size_t p = r0; p < r1; p++)
        for (size_t q = p + 1; q < r1; q++)
        {
          int32_t s = std::get<3>(entries[p]), t = std::get<3>(entries[q]);      // s < t (sorted)
          if (fragment[s] == fragment[t]) continue;
          bool overlap = true, first = true;
          for (int d = 0; d < 3; d++)
          {
            overlap &= lo[3 * s + d] < hi[3 * t + d] && lo[3 * t + d] < hi[3 * s + d];
            first &= std::max(range[s][d], range[t][d]) == cell[d];
          }
          if (!overlap || !first) continue;
          res.candidates++;
          const double * a[4], * b[4];
          for (int k = 0; k < 4; k++)
          {
            a[k] = x + 3 * tets[4 * s + k];
            b[k] = x + 3 * tets[4 * t + k];
          }
          double v = TetIntersectionVolume(a, b);
          if (v > 0) found.emplace_back(s, t, v);
        }
    }
    std::sort(found.begin(), found.end());
    for (auto & [s, t, v] : found)
    {
      res.first.push_back(s);
      res.second.push_back(t);
      res.volume.push_back(v);
      res.total += v;
    }
    return res;
  }
}
