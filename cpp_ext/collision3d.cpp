// Collision detection between fragments of a tetrahedral mesh (3D analogue of collision.cpp).
#include "collision3d.hpp"
#include "predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

namespace ngfracture
{
  namespace
  {
    // A uniform grid: items sorted by cell key, each occupied cell a range. Up to
    // kDenseCells cells the ranges are an array over all cells (a lookup is an index),
    // beyond that a hash map of the occupied cells.
    constexpr int64_t kDenseCells = int64_t(1) << 22;
    struct HashGrid
    {
      double origin[3], h;
      int64_t span;                                   // cells per axis that may be occupied
      std::vector<int32_t> items;
      std::unordered_map<uint64_t, std::pair<int32_t,int32_t>> range;
      std::vector<int32_t> first;                     // dense: cell c holds items[first[c] .. first[c+1])

      bool Dense () const { return span <= 161 && span * span * span <= kDenseCells; }
      int64_t Linear (int64_t i, int64_t j, int64_t k) const { return (i * span + j) * span + k; }

      int64_t Cell (double v, int d) const { return int64_t(std::floor((v - origin[d]) / h)); }
      static uint64_t Key (int64_t i, int64_t j, int64_t k)
      { return (uint64_t(i) << 42) | (uint64_t(j) << 21) | uint64_t(k); }
      bool Valid (int64_t i) const { return i >= 0 && i < span; }

      // items with closed boxes lo..hi (3 doubles each per item), in every cell they overlap;
      // within a cell in increasing item order
      void Build (const std::vector<double> & lo, const std::vector<double> & hi)
      {
        size_t n = lo.size() / 3;
        range.clear();
        first.clear();
        auto cells = [&] (size_t t, auto && f)
          {
            int64_t a[3], b[3];
            for (int d = 0; d < 3; d++) { a[d] = Cell(lo[3*t+d], d); b[d] = Cell(hi[3*t+d], d); }
            for (int64_t i = a[0]; i <= b[0]; i++)
              for (int64_t j = a[1]; j <= b[1]; j++)
                for (int64_t k = a[2]; k <= b[2]; k++)
                  f(i, j, k);
          };
        if (Dense ())
          {
            // counting sort over all cells; cells outside the grid are never visited: every
            // item's cells clipped to the grid once (the same cells in the same order)
            std::vector<int32_t> clip(6 * n);
            for (size_t t = 0; t < n; t++)
              for (int d = 0; d < 3; d++)
                {
                  clip[6*t+d] = int32_t(std::clamp<int64_t>(Cell(lo[3*t+d], d), 0, span));
                  clip[6*t+3+d] = int32_t(std::clamp<int64_t>(Cell(hi[3*t+d], d), -1, span - 1));
                }
            auto clipped = [&] (size_t t, auto && f)
              {
                const int32_t * r = &clip[6*t];
                for (int64_t i = r[0]; i <= r[3]; i++)
                  for (int64_t j = r[1]; j <= r[4]; j++)
                    for (int64_t k = r[2]; k <= r[5]; k++)
                      f(Linear(i, j, k));
              };
            first.assign(size_t(span * span * span) + 1, 0);
            for (size_t t = 0; t < n; t++)
              clipped(t, [&] (int64_t c) { first[c + 1]++; });
            for (size_t c = 1; c < first.size(); c++) first[c] += first[c-1];
            items.resize(first.back());
            std::vector<int32_t> fill(first.begin(), first.end() - 1);
            for (size_t t = 0; t < n; t++)
              clipped(t, [&] (int64_t c) { items[fill[c]++] = int32_t(t); });
            return;
          }
        std::vector<std::pair<uint64_t,int32_t>> keyed;
        for (size_t t = 0; t < n; t++)
          cells(t, [&] (int64_t i, int64_t j, int64_t k) { keyed.push_back({ Key(i, j, k), int32_t(t) }); });
        std::sort(keyed.begin(), keyed.end());
        items.resize(keyed.size());
        range.reserve(keyed.size());
        for (size_t s = 0; s < keyed.size(); s++)
          {
            items[s] = keyed[s].second;
            auto [it, fresh] = range.try_emplace(keyed[s].first, int32_t(s), int32_t(s));
            it->second.second = int32_t(s + 1);
          }
      }

      // the slots s of cell (i, j, k): f(s) for items[s]
      template <typename F> void VisitSlots (int64_t i, int64_t j, int64_t k, F && f) const
      {
        if (!Valid(i) || !Valid(j) || !Valid(k)) return;
        if (!first.empty())
          {
            int64_t c = Linear(i, j, k);
            for (int32_t s = first[c]; s < first[c+1]; s++) f(s);
            return;
          }
        auto it = range.find(Key(i, j, k));
        if (it == range.end()) return;
        for (int32_t s = it->second.first; s < it->second.second; s++) f(s);
      }

      template <typename F> void Visit (int64_t i, int64_t j, int64_t k, F && f) const
      {
        if (!Valid(i) || !Valid(j) || !Valid(k)) return;
        if (!first.empty())
          {
            int64_t c = Linear(i, j, k);
            for (int32_t s = first[c]; s < first[c+1]; s++) f(items[s]);
            return;
          }
        auto it = range.find(Key(i, j, k));
        if (it == range.end()) return;
        for (int32_t s = it->second.first; s < it->second.second; s++) f(items[s]);
      }
    };

    inline void Sub (const double * a, const double * b, double * r)
    { r[0] = a[0]-b[0]; r[1] = a[1]-b[1]; r[2] = a[2]-b[2]; }
    inline double Dot (const double * a, const double * b) { return a[0]*b[0] + a[1]*b[1] + a[2]*b[2]; }
    inline void Cross (const double * a, const double * b, double * r)
    { r[0] = a[1]*b[2]-a[2]*b[1]; r[1] = a[2]*b[0]-a[0]*b[2]; r[2] = a[0]*b[1]-a[1]*b[0]; }

    // p in the closed tetrahedron t (any orientation; false if flat), exactly
    // p in the closed tetrahedron t whose own orientation sign is s (0: flat, holds nothing)
    bool InClosedTet (const double * x, const int32_t * t, const double * p, int s)
    {
      const double * v[4] = { x + 3*t[0], x + 3*t[1], x + 3*t[2], x + 3*t[3] };
      if (s == 0) return false;
      for (int i = 0; i < 4; i++)
        {
          const double * w[4] = { v[0], v[1], v[2], v[3] };
          w[i] = p;
          if (Orient3dSign(w[0], w[1], w[2], w[3]) * s < 0) return false;
        }
      return true;
    }

    // squared distance from p to the triangle point with barycentrics bary
    double Dist2 (const double * p, const double * a, const double * b, const double * c,
                  const double * bary, double * q)
    {
      double d2 = 0;
      for (int k = 0; k < 3; k++)
        {
          q[k] = bary[0]*a[k] + bary[1]*b[k] + bary[2]*c[k];
          d2 += (p[k]-q[k]) * (p[k]-q[k]);
        }
      return d2;
    }
  }

  bool PointInClosedTriangle3 (const double * p, const double * a, const double * b, const double * c)
  {
    if (Orient3dSign(a, b, c, p) != 0) return false;
    // Coplanar: dropping a coordinate keeps every orientation sign, for a projection
    // in which the triangle is not degenerate.
    for (int drop = 0; drop < 3; drop++)
      {
        int u = (drop + 1) % 3, v = (drop + 2) % 3;
        double pa[2] = { a[u], a[v] }, pb[2] = { b[u], b[v] }, pc[2] = { c[u], c[v] }, pp[2] = { p[u], p[v] };
        int o = Orient2dSign(pa, pb, pc);
        if (o == 0) continue;
        return o * Orient2dSign(pa, pb, pp) >= 0 && o * Orient2dSign(pb, pc, pp) >= 0
          && o * Orient2dSign(pc, pa, pp) >= 0;
      }
    return false;
  }

  void ClosestPointOnTriangle3 (const double * p, const double * a, const double * b, const double * c,
                                double * bary)
  {
    // The projection onto the plane (normal equations in the edge basis) if it falls in
    // the triangle; else the nearest point of one of the three edges.
    double e0[3], e1[3], r[3];
    Sub(b, a, e0); Sub(c, a, e1); Sub(p, a, r);
    double g00 = Dot(e0, e0), g01 = Dot(e0, e1), g11 = Dot(e1, e1);
    double r0 = Dot(r, e0), r1 = Dot(r, e1);
    double det = g00*g11 - g01*g01;
    if (det > 0)
      {
        double s = (g11*r0 - g01*r1) / det, t = (g00*r1 - g01*r0) / det;
        if (s >= 0 && t >= 0 && s + t <= 1)
          { bary[0] = 1 - s - t; bary[1] = s; bary[2] = t; return; }
      }
    const double * V[3] = { a, b, c };
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; k++)
      {
        const double * u = V[k], * w = V[(k+1)%3];
        double e[3], q[3];
        Sub(w, u, e); Sub(p, u, q);
        double l2 = Dot(e, e);
        double t = l2 > 0 ? std::clamp(Dot(q, e) / l2, 0.0, 1.0) : 0.0;
        double cand[3] = { 0, 0, 0 }, pt[3];
        cand[k] = 1 - t; cand[(k+1)%3] = t;
        double d2 = Dist2(p, a, b, c, cand, pt);
        if (d2 < best) { best = d2; std::copy(cand, cand + 3, bary); }
      }
  }

  namespace
  {
    [[noreturn]] void Bad (const std::string & what) { throw std::invalid_argument("ngfracture.DetectPenetrations3d: " + what); }

    // What the search needs besides the arrays and does not move: fragment per vertex and
    // per face, the boundary vertices, the tetrahedra at every vertex (checked here), and
    // (MakeTopology) the copies of every boundary vertex and the lip flags.
    struct Topology
    {
      std::vector<int32_t> vfrag, ffrag, bverts;
      std::vector<uint8_t> lip;    // the vertex has a copy on its own fragment (a lip of a crack inside it)
      std::vector<int64_t> start, at;     // the tetrahedra at vertex v: at[start[v] .. start[v+1])
      std::vector<int64_t> frag_tets;     // tetrahedra per fragment (empty: a fragment number < 0 or > ne)
    };

    // What the search needs at the current positions: the topology, the boundary vertices'
    // (area-weighted) outward normals, unit face normals, the faces' boxes.
    struct Derived
    {
      const std::vector<int32_t> & vfrag, & ffrag, & bverts;
      const std::vector<uint8_t> & lip;
      std::vector<double> vnormal, fnormal;
      std::vector<double> flo, fhi;       // boxes of the boundary faces (current positions)
    };

    void DeriveTopology (const TetMesh3 & m, Topology & D)
    {
      D.vfrag.assign(m.nv, -1);
      for (int64_t t = 0; t < m.ne; t++)
        for (int k = 0; k < 4; k++)
          {
            int32_t v = m.tets[4*t+k], f = m.fragment[t];
            if (v < 0 || v >= m.nv) Bad("tets[" + std::to_string(t) + "] holds a vertex out of range");
            if (D.vfrag[v] >= 0 && D.vfrag[v] != f)
              Bad("vertex " + std::to_string(v) + " belongs to tetrahedra of fragments " + std::to_string(D.vfrag[v])
                  + " and " + std::to_string(f) + " (fragments must not share vertices)");
            D.vfrag[v] = f;
          }
      // a face's fragment is its vertices' (fragments share no vertex); it must be a face
      // of a tetrahedron: one of the tetrahedra at its first vertex holds all three
      std::vector<int64_t> & start = D.start, & at = D.at;
      start.assign(m.nv + 1, 0);
      for (int64_t t = 0; t < m.ne; t++)
        for (int k = 0; k < 4; k++) start[m.tets[4*t+k] + 1]++;
      for (int64_t v = 0; v < m.nv; v++) start[v+1] += start[v];
      at.resize(start[m.nv]);
      {
        std::vector<int64_t> fill(start.begin(), start.end() - 1);
        for (int64_t t = 0; t < m.ne; t++)
          for (int k = 0; k < 4; k++) at[fill[m.tets[4*t+k]]++] = t;
      }
      D.frag_tets.clear();
      int32_t nfrag = 0;
      bool counted = true;
      for (int64_t t = 0; t < m.ne && counted; t++)
        {
          counted = m.fragment[t] >= 0 && m.fragment[t] <= m.ne;
          if (counted) nfrag = std::max(nfrag, m.fragment[t] + 1);
        }
      if (counted)
        {
          D.frag_tets.assign(nfrag, 0);
          for (int64_t t = 0; t < m.ne; t++) D.frag_tets[m.fragment[t]]++;
        }
      D.ffrag.assign(m.nf, -1);
      for (int64_t f = 0; f < m.nf; f++)
        {
          const int32_t * F = m.faces + 3*f;
          for (int k = 0; k < 3; k++)
            if (F[k] < 0 || F[k] >= m.nv) Bad("faces[" + std::to_string(f) + "] holds a vertex out of range");
          for (int64_t s = start[F[0]]; s < start[F[0]+1] && D.ffrag[f] < 0; s++)
            {
              const int32_t * T = m.tets + 4*at[s];
              // the tetrahedra at F[0] that lack F[1] or F[2] (most) are not counted
              auto has = [T] (int32_t w) { return T[0] == w || T[1] == w || T[2] == w || T[3] == w; };
              if (!has(F[1]) || !has(F[2])) continue;
              int held = 0;
              for (int k = 0; k < 3; k++)
                held += (T[0] == F[k]) + (T[1] == F[k]) + (T[2] == F[k]) + (T[3] == F[k]);
              if (held == 3 && F[0] != F[1] && F[1] != F[2] && F[0] != F[2]) D.ffrag[f] = m.fragment[at[s]];
            }
        }
      std::vector<uint8_t> onb(m.nv, 0);
      for (int64_t f = 0; f < m.nf; f++)
        {
          if (D.ffrag[f] < 0) Bad("faces[" + std::to_string(f) + "] is not a face of any tetrahedron");
          for (int k = 0; k < 3; k++) onb[m.faces[3*f+k]] = 1;
        }
      D.bverts.clear();
      for (int64_t v = 0; v < m.nv; v++)
        if (onb[v]) D.bverts.push_back(int32_t(v));
    }

    // The normals of Derived at the current positions.
    void DeriveNormals (const TetMesh3 & m, Derived & D)
    {
      D.vnormal.assign(3*m.nv, 0.0);
      D.fnormal.assign(3*m.nf, 0.0);
      for (int64_t f = 0; f < m.nf; f++)
        {
          const int32_t * F = m.faces + 3*f;
          double e0[3], e1[3], n[3];
          Sub(m.x + 3*F[1], m.x + 3*F[0], e0); Sub(m.x + 3*F[2], m.x + 3*F[0], e1); Cross(e0, e1, n);
          double len = std::sqrt(Dot(n, n));
          for (int d = 0; d < 3; d++) D.fnormal[3*f+d] = len > 0 ? n[d] / len : 0.0;
          for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) D.vnormal[3*F[k]+d] += n[d];
        }
    }

    // The grid geometry: origin at the low corner of the boundary vertices, cell size the
    // mean largest extent of a tetrahedron (coarser if needed to keep 21 bits per axis).
    void SetupGrid (const TetMesh3 & m, const Derived & D, HashGrid & g)
    {
      double lo[3], hi[3];
      for (int d = 0; d < 3; d++) { lo[d] = std::numeric_limits<double>::infinity(); hi[d] = -lo[d]; }
      for (int32_t v : D.bverts)
        for (int d = 0; d < 3; d++)
          { lo[d] = std::min(lo[d], m.x[3*v+d]); hi[d] = std::max(hi[d], m.x[3*v+d]); }
      double ext = 0;
      for (int64_t t = 0; t < m.ne; t++)
        {
          double e = 0;
          for (int d = 0; d < 3; d++)
            {
              double a = m.x[3*m.tets[4*t]+d], b = a;
              for (int k = 1; k < 4; k++) { a = std::min(a, m.x[3*m.tets[4*t+k]+d]); b = std::max(b, m.x[3*m.tets[4*t+k]+d]); }
              e = std::max(e, b - a);
            }
          ext += e;
        }
      double range = std::max({ hi[0]-lo[0], hi[1]-lo[1], hi[2]-lo[2] });
      g.h = m.ne ? ext / double(m.ne) : 1.0;
      if (!(g.h > 0)) g.h = range > 0 ? range : 1.0;
      g.h = std::max(g.h, range / double((1 << 20)));
      std::copy(lo, lo + 3, g.origin);
      g.span = int64_t(std::floor(range / g.h)) + 2;
    }

    struct BitsHash
    {
      size_t operator() (const std::array<uint64_t,3> & k) const
      { return size_t(k[0] * 0x9E3779B97F4A7C15ull ^ (k[1] + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull ^ k[2]); }
    };
    std::array<uint64_t,3> Bits (const double * p)
    {
      std::array<uint64_t,3> k;
      std::memcpy(k.data(), p, 3 * sizeof(double));
      return k;
    }

    using Hit = std::tuple<int32_t,int32_t,int32_t>;   // vertex, fragment, tet

    // The pairs (vertex, fragment) decided in a sweep: up to four fragments per vertex in
    // place (filled in order), more in a hash set.
    class Decided
    {
      static constexpr int32_t kFree = std::numeric_limits<int32_t>::min();
      std::vector<std::array<int32_t,4>> slot_;
      std::unordered_set<uint64_t> more_;
      static uint64_t Key (int32_t v, int32_t F) { return (uint64_t(uint32_t(v)) << 32) | uint32_t(F); }
    public:
      explicit Decided (int64_t nv) : slot_(size_t(nv), { kFree, kFree, kFree, kFree }) { }
      bool Has (int32_t v, int32_t F) const
      {
        const auto & s = slot_[v];
        for (int i = 0; i < 4; i++)
          {
            if (s[i] == F) return true;
            if (s[i] == kFree) return false;
          }
        return more_.count(Key(v, F)) > 0;
      }
      void Insert (int32_t v, int32_t F)        // (v, F) not in the set
      {
        auto & s = slot_[v];
        for (int i = 0; i < 4; i++)
          if (s[i] == kFree) { s[i] = F; return; }
        more_.insert(Key(v, F));
      }
    };

    // The copies of every boundary vertex (bitwise-equal reference points), increasing.
    struct Copies
    {
      std::vector<int32_t> group;          // per vertex: its group, -1 off the boundary
      std::vector<int64_t> start;          // group g: members[start[g] .. start[g+1])
      std::vector<int32_t> members;

      // v's first copy on fragment F (-1: none); vfrag the fragment of every vertex
      int32_t Twin (const std::vector<int32_t> & vfrag, int32_t v, int32_t F) const
      {
        int32_t g = group[v];
        for (int64_t s = start[g]; s < start[g+1]; s++)
          if (members[s] != v && vfrag[members[s]] == F) return members[s];
        return -1;
      }

      // the copies of v's point on fragment F, v included
      int64_t CountOn (const std::vector<int32_t> & vfrag, int32_t v, int32_t F) const
      {
        int64_t n = 0;
        int32_t g = group[v];
        for (int64_t s = start[g]; s < start[g+1]; s++) n += vfrag[members[s]] == F;
        return n;
      }

      // the points of boundary face T (its vertices' groups), sorted
      std::array<int32_t,3> FacePoints (const int32_t * T) const
      {
        std::array<int32_t,3> p { group[T[0]], group[T[1]], group[T[2]] };
        std::sort(p.begin(), p.end());
        return p;
      }
    };

    Copies MakeCopies (const TetMesh3 & m, const Topology & D)
    {
      std::unordered_map<std::array<uint64_t,3>, int32_t, BitsHash> index;
      Copies c;
      c.group.assign(m.nv, -1);
      std::vector<int64_t> count;
      for (int32_t v : D.bverts)
        {
          auto [it, fresh] = index.try_emplace(Bits(m.X + 3*v), int32_t(count.size()));
          if (fresh) count.push_back(0);
          c.group[v] = it->second;
          count[it->second]++;
        }
      c.start.assign(count.size() + 1, 0);
      for (size_t g = 0; g < count.size(); g++) c.start[g+1] = c.start[g] + count[g];
      c.members.resize(D.bverts.size());
      std::vector<int64_t> fill(c.start.begin(), c.start.end() - 1);
      for (int32_t v : D.bverts) c.members[fill[c.group[v]]++] = v;      // bverts increasing
      return c;
    }

    // A boundary vertex in the grid, with what the sweep tests first, in the order of the
    // grid's items: a tetrahedron reads the vertices of a cell from consecutive memory.
    struct GridPoint
    {
      double p[3];
      int32_t v;
      int32_t frag;        // the vertex's fragment
      bool lip;            // a copy of its point on its own fragment (D.lip)
    };

    // The closed cells of a dense grid: cells whose vertices are of at most 8 fragments,
    // none a lip vertex, and every vertex decided (DecideClosedSeams) for every one of
    // those fragments but its own. A tetrahedron of one of those fragments finds no pair
    // there (the sweep's test rejects every vertex before its exact test: its own, or
    // decided; ``decided`` only grows), so it skips the cell. ``closed_set[c]`` is the
    // number of cell c's fragments in ``sets`` (padded with -1), or -1 for a cell that is
    // empty or not closed.
    void ClosedCells (const HashGrid & g, const std::vector<GridPoint> & points, const Decided & decided,
                      std::vector<int32_t> & closed_set, std::vector<std::array<int32_t,8>> & sets)
    {
      closed_set.assign(g.first.size() - 1, -1);
      for (size_t c = 0; c + 1 < g.first.size(); c++)
        {
          int32_t s0 = g.first[c], s1 = g.first[c+1];
          if (s0 == s1) continue;
          std::array<int32_t,8> frags;
          frags.fill(-1);
          int n = 0;
          bool closed = true;
          for (int32_t s = s0; s < s1 && closed; s++)
            {
              closed = !points[s].lip;
              int32_t F = points[s].frag;
              if (std::find(frags.begin(), frags.begin() + n, F) != frags.begin() + n) continue;
              if (n == 8) closed = false;
              else frags[n++] = F;
            }
          for (int32_t s = s0; s < s1 && closed; s++)
            for (int i = 0; i < n && closed; i++)
              closed = frags[i] == points[s].frag || decided.Has(points[s].v, frags[i]);
          if (!closed) continue;
          closed_set[c] = int32_t(sets.size());
          sets.push_back(frags);
        }
    }

    // hits sorted by (vertex, fragment, tet), as std::sort sorts them: a counting sort by
    // vertex, then an insertion sort of every vertex's few hits (std::sort past 64; the
    // pairs (vertex, fragment) are distinct, so the order is the same whatever the method)
    void SortHits (std::vector<Hit> & hits, int64_t nv)
    {
      if (hits.empty()) return;
      std::vector<int32_t> start(nv + 1, 0);
      for (const Hit & h : hits) start[std::get<0>(h) + 1]++;
      for (int64_t v = 0; v < nv; v++) start[v+1] += start[v];
      std::vector<Hit> sorted(hits.size());
      {
        std::vector<int32_t> fill(start.begin(), start.end() - 1);
        for (const Hit & h : hits) sorted[fill[std::get<0>(h)]++] = h;
      }
      for (int64_t v = 0; v < nv; v++)
        if (start[v+1] - start[v] > 64)
          std::sort(sorted.begin() + start[v], sorted.begin() + start[v+1]);
        else for (int32_t i = start[v] + 1; i < start[v+1]; i++)
          {
            Hit x = sorted[i];
            int32_t j = i;
            for (; j > start[v] && x < sorted[j-1]; j--) sorted[j] = sorted[j-1];
            sorted[j] = x;
          }
      hits.swap(sorted);
    }

    // The closed blocks of 2 x 2 x 2 cells of a dense grid (block (I, J, K) holds cells
    // (2I .. 2I+1, 2J .. 2J+1, 2K .. 2K+1)): a tetrahedron of fragment F whose cells all
    // lie in blocks closed for F finds nothing in them (each of their non-empty cells is
    // closed with F among its fragments, ClosedCells), and is not swept cell by cell.
    struct ClosedBlocks
    {
      int64_t span2 = 0;                       // blocks per axis (none: no closed cells)
      // per block: -2 if its cells are empty, the number in ``sets`` of the fragments every
      // non-empty cell of the block has in its set (padded with -1), or -1 where a
      // non-empty cell is not closed or no fragment is in every set
      std::vector<int32_t> block_set;
      std::vector<std::array<int32_t,8>> sets;

      ClosedBlocks () = default;
      ClosedBlocks (const HashGrid & g, const std::vector<int32_t> & closed_set,
                    const std::vector<std::array<int32_t,8>> & cell_sets)
        : span2((g.span + 1) / 2), block_set(size_t(span2 * span2 * span2), -2)
      {
        for (int64_t b = 0; b < int64_t(block_set.size()); b++)
          {
            int64_t I = b / (span2 * span2), J = b / span2 % span2, K = b % span2;
            std::array<int32_t,8> common;
            int32_t & out = block_set[b];
            for (int64_t i = 2*I; i < std::min(2*I + 2, g.span) && out != -1; i++)
              for (int64_t j = 2*J; j < std::min(2*J + 2, g.span) && out != -1; j++)
                for (int64_t k = 2*K; k < std::min(2*K + 2, g.span) && out != -1; k++)
                  {
                    int64_t c = g.Linear(i, j, k);
                    if (g.first[c] == g.first[c+1]) continue;
                    int32_t e = closed_set[c];
                    if (e < 0) { out = -1; break; }
                    if (out == -2) { common = cell_sets[e]; out = 0; continue; }
                    // common := common and cell_sets[e], in common's order
                    int n = 0;
                    for (int32_t F : common)
                      if (F >= 0 && std::find(cell_sets[e].begin(), cell_sets[e].end(), F) != cell_sets[e].end())
                        common[n++] = F;
                    std::fill(common.begin() + n, common.end(), -1);
                    if (n == 0) out = -1;
                  }
            if (out == 0) { out = int32_t(sets.size()); sets.push_back(common); }
          }
      }

      // every block that cells a[d] .. b[d] (not empty) lie in is closed for F
      bool Hold (const int64_t * a, const int64_t * b, int32_t F) const
      {
        // the blocks' range once (cells are >= 0 here: a shift, not a signed division)
        const int64_t I0 = a[0] >> 1, I1 = b[0] >> 1, J0 = a[1] >> 1, J1 = b[1] >> 1, K0 = a[2] >> 1, K1 = b[2] >> 1;
        for (int64_t I = I0; I <= I1; I++)
          for (int64_t J = J0; J <= J1; J++)
            for (int64_t K = K0; K <= K1; K++)
              {
                int32_t e = block_set[(I * span2 + J) * span2 + K];
                if (e == -2) continue;
                if (e < 0 || std::find(sets[e].begin(), sets[e].end(), F) == sets[e].end()) return false;
              }
        return true;
      }
    };

    // every vertex's cell along x, y, z, clamped to [-1, span]: Cell is monotone, so a
    // tetrahedron's cells are those from its vertices' least to their largest
    std::vector<int32_t> VertexCells (const TetMesh3 & m, const HashGrid & g)
    {
      std::vector<int32_t> vcell(3 * m.nv);
      for (int64_t v = 0; v < m.nv; v++)
        for (int d = 0; d < 3; d++)
          vcell[3*v+d] = int32_t(std::clamp<int64_t>(g.Cell(m.x[3*v+d], d), -1, g.span));
      return vcell;
    }

    // The fragments whose tetrahedra find nothing at x (dense grid with closed cells):
    // every non-empty cell of the fragment's box of cells (its vertices' cells, clamped to
    // the grid; every tetrahedron of it sweeps only cells in there) is closed with the
    // fragment among its fragments (ClosedCells), so the sweep skips each of those cells
    // for each of its tetrahedra. A fragment whose box has more cells than four per
    // tetrahedron is not checked (a check dearer than its sweep; it is swept tetrahedron
    // by tetrahedron).
    // ``tets`` the tetrahedra per fragment (Topology::frag_tets; empty: none is skipped).
    std::vector<uint8_t> ClosedFragments (const TetMesh3 & m, const HashGrid & g, const std::vector<int32_t> & vfrag,
                                          const std::vector<int64_t> & tets, const std::vector<int32_t> & vcell,
                                          const std::vector<int32_t> & closed_set,
                                          const std::vector<std::array<int32_t,8>> & sets)
    {
      const int32_t nfrag = int32_t(tets.size());
      if (closed_set.empty() || nfrag == 0) return {};
      std::vector<std::array<int32_t,6>> box(nfrag, { INT32_MAX, INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN, INT32_MIN });
      for (int64_t v = 0; v < m.nv; v++)
        {
          int32_t F = vfrag[v];
          if (F < 0) continue;
          for (int d = 0; d < 3; d++)
            {
              box[F][d] = std::min(box[F][d], vcell[3*v+d]);
              box[F][3+d] = std::max(box[F][3+d], vcell[3*v+d]);
            }
        }
      std::vector<uint8_t> closed(nfrag, 0);
      for (int32_t F = 0; F < nfrag; F++)
        {
          if (tets[F] == 0) continue;
          int64_t a[3], b[3], cells = 1;
          for (int d = 0; d < 3; d++)
            {
              a[d] = std::max<int64_t>(box[F][d], 0);
              b[d] = std::min<int64_t>(box[F][3+d], g.span - 1);
              cells *= std::max<int64_t>(b[d] - a[d] + 1, 0);
            }
          if (cells > 4 * tets[F]) continue;
          bool all = true;
          for (int64_t i = a[0]; i <= b[0] && all; i++)
            for (int64_t j = a[1]; j <= b[1] && all; j++)
              for (int64_t k = a[2]; k <= b[2] && all; k++)
                {
                  int64_t c = g.Linear(i, j, k);
                  if (g.first[c] == g.first[c+1]) continue;
                  int32_t e = closed_set[c];
                  all = e >= 0 && std::find(sets[e].begin(), sets[e].end(), F) != sets[e].end();
                }
          closed[F] = all;
        }
      return closed;
    }

    // Every (boundary vertex, tetrahedron of another fragment) with the vertex in the
    // closed tetrahedron, and (lip vertex, tetrahedron of its own fragment not at the
    // vertex): each tetrahedron's box swept over the vertex grid. A pair found in a
    // tetrahedron is decided and not tested again: a pair whose vertex sits on its twin of
    // that fragment (a closed seam, or a closed lip) is no hit, only counted; any other is
    // a hit in that tetrahedron, the smallest that holds it (the sweep goes in increasing
    // order). The twin is looked up only for a pair found. Pairs in ``decided`` are not
    // tested (DecideClosedSeams). ``points`` are the grid's items (GridPoint, slot by slot).
    std::vector<Hit> SweepTets (const TetMesh3 & m, const Copies & copies, const std::vector<int32_t> & vfrag,
                                const std::vector<int64_t> & frag_tets, const HashGrid & g, const std::vector<GridPoint> & points,
                                Decided & decided, Collision3Stats & st)
    {
      std::vector<Hit> hits;
      int64_t closed = 0, box_tests = 0;
      // dense grid: the cells that hold no pair of a tetrahedron of any of their vertices'
      // fragments (ClosedCells)
      std::vector<int32_t> closed_set;
      std::vector<std::array<int32_t,8>> sets;
      if (!g.first.empty()) ClosedCells(g, points, decided, closed_set, sets);
      const ClosedBlocks blocks = closed_set.empty() ? ClosedBlocks() : ClosedBlocks(g, closed_set, sets);
      const std::vector<int32_t> vcell = VertexCells(m, g);
      const std::vector<uint8_t> skip = ClosedFragments(m, g, vfrag, frag_tets, vcell, closed_set, sets);
      for (int64_t t = 0; t < m.ne; t++)
        {
          const int32_t * T = m.tets + 4*t;
          const int32_t F = m.fragment[t];
          if (!skip.empty() && skip[F]) continue;
          int orientation = 2;                              // not computed yet
          int64_t a[3], b[3];
          for (int d = 0; d < 3; d++)
            {
              int32_t c0 = vcell[3*T[0]+d], c1 = vcell[3*T[1]+d], c2 = vcell[3*T[2]+d], c3 = vcell[3*T[3]+d];
              a[d] = std::max(std::min(std::min(c0, c1), std::min(c2, c3)), 0);
              b[d] = std::min<int64_t>(std::max(std::max(c0, c1), std::max(c2, c3)), g.span - 1);
            }
          if (a[0] > b[0] || a[1] > b[1] || a[2] > b[2]) continue;                    // no cell
          if (!closed_set.empty() && blocks.Hold(a, b, F)) continue;
          double lo[3], hi[3];
          for (int d = 0; d < 3; d++)
            {
              lo[d] = hi[d] = m.x[3*T[0]+d];
              for (int k = 1; k < 4; k++) { lo[d] = std::min(lo[d], m.x[3*T[k]+d]); hi[d] = std::max(hi[d], m.x[3*T[k]+d]); }
            }
          // inlined at both calls: it runs once per box test, most of a prediction's sweep
          auto test = [&] (int32_t slot) __attribute__((always_inline))
                  {
                    box_tests++;
                    const GridPoint & q = points[slot];
                    const int32_t v = q.v;
                    if (q.frag == F)
                      {
                        // self-contact across a crack: a lip vertex in a tetrahedron of
                        // its own fragment that is not one of its own
                        if (!q.lip || T[0] == v || T[1] == v || T[2] == v || T[3] == v) return;
                      }
                    const double * p = q.p;
                    if (p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2])
                      return;
                    if (decided.Has(v, F)) return;
                    st.exact_tests++;
                    if (orientation == 2)
                      orientation = Orient3dSign(m.x + 3*T[0], m.x + 3*T[1], m.x + 3*T[2], m.x + 3*T[3]);
                    if (!InClosedTet(m.x, T, p, orientation)) return;
                    decided.Insert(v, F);
                    int32_t twin = copies.Twin(vfrag, v, F);
                    bool seam = twin >= 0 && std::memcmp(p, m.x + 3*twin, 3 * sizeof(double)) == 0;
                    if (seam) closed++;
                    else hits.emplace_back(v, F, int32_t(t));
                  };
          for (int64_t i = a[0]; i <= b[0]; i++)
            for (int64_t j = a[1]; j <= b[1]; j++)
              for (int64_t k = a[2]; k <= b[2]; k++)
                {
                  if (closed_set.empty()) { g.VisitSlots(i, j, k, test); continue; }
                  int64_t c = g.Linear(i, j, k);
                  int32_t e = closed_set[c];
                  if (e >= 0 && std::find(sets[e].begin(), sets[e].end(), F) != sets[e].end()) continue;
                  for (int32_t slot = g.first[c]; slot < g.first[c+1]; slot++) test(slot);
                }
        }
      st.box_tests += box_tests;
      st.closed_seams = closed;
      SortHits(hits, m.nv);
      return hits;
    }

    // The boundary faces at every vertex (CSR: faces at[start[v] .. start[v+1]), increasing).
    struct VertexFaces
    {
      std::vector<int64_t> start;
      std::vector<int32_t> at;
    };

    VertexFaces MakeVertexFaces (const TetMesh3 & m)
    {
      VertexFaces vf;
      vf.start.assign(m.nv + 1, 0);
      for (int64_t i = 0; i < 3*m.nf; i++) vf.start[m.faces[i] + 1]++;
      for (int64_t v = 0; v < m.nv; v++) vf.start[v+1] += vf.start[v];
      vf.at.resize(vf.start[m.nv]);
      std::vector<int64_t> fill(vf.start.begin(), vf.start.end() - 1);
      for (int64_t f = 0; f < m.nf; f++)
        for (int k = 0; k < 3; k++) vf.at[fill[m.faces[3*f+k]]++] = int32_t(f);
      return vf;
    }

    // The partner faces of v on fragment F: the faces at a copy t of v on F (t != v) whose
    // three points are those of a face at v (the other side of one of v's own faces: a
    // crack lip or an interface), sorted. A partner face opposes one of v's own faces
    // exactly, though not always v's averaged normal: where several cracks meet, a copy's
    // wedge can be bounded by faces that the averaged normal of a neighbouring copy does
    // not oppose, and v, in that wedge, is nearest to them.
    // ``own`` is scratch space (the other two points of every face at v).
    void PartnerFaces (const TetMesh3 & m, const Copies & copies, const Derived & D,
                       const VertexFaces & vfaces, int32_t v, int32_t F, std::vector<int32_t> & out,
                       std::vector<std::pair<int32_t,int32_t>> & own)
    {
      out.clear();
      const auto & grp = copies.group;
      auto others = [&] (int32_t f, int32_t c, int32_t & a, int32_t & b)
        {
          const int32_t * T = m.faces + 3*f;
          int k = T[0] == c ? 0 : (T[1] == c ? 1 : 2);
          a = grp[T[(k+1)%3]]; b = grp[T[(k+2)%3]];
          if (a > b) std::swap(a, b);
        };
      own.clear();
      for (int64_t j = vfaces.start[v]; j < vfaces.start[v+1]; j++)
        {
          int32_t c, d;
          others(vfaces.at[j], v, c, d);
          own.emplace_back(c, d);
        }
      int32_t g = grp[v];
      for (int64_t s = copies.start[g]; s < copies.start[g+1]; s++)
        {
          int32_t t = copies.members[s];
          if (t == v || D.vfrag[t] != F) continue;
          for (int64_t i = vfaces.start[t]; i < vfaces.start[t+1]; i++)
            {
              int32_t f = vfaces.at[i], a, b;
              others(f, t, a, b);
              for (const auto & [c, d] : own)
                if (a == c && b == d) { out.push_back(f); break; }
            }
        }
      std::sort(out.begin(), out.end());
    }

    // Every vertex w of the reference star of c (the vertices of the tetrahedra at c,
    // Topology::at) on the side `sign` of the plane through X_c with normal n
    // (sign * n . (X_w - X_c) >= -1e-9 |X_w - X_c|: the star's own face vertices lie on it
    // up to rounding; the length is needed only where the product is negative).
    bool StarOnSide (const TetMesh3 & m, const Topology & topo, int32_t c, const double * n, double sign)
    {
      for (int64_t i = topo.start[c]; i < topo.start[c+1]; i++)
        for (int k = 0; k < 4; k++)
          {
            double e[3];
            Sub(m.X + 3*m.tets[4*topo.at[i]+k], m.X + 3*c, e);
            double side = sign * Dot(n, e);
            if (side < 0 && side < -1e-9 * std::sqrt(Dot(e, e))) return false;
          }
      return true;
    }

    // Whether boundary face f is a lip: another boundary face lies on its three points (the
    // other side of a crack or of an interface of bodies meshed apart).
    bool IsLip (const TetMesh3 & m, const Copies & copies, const VertexFaces & vfaces, int32_t f)
    {
      const int32_t * T = m.faces + 3*f;
      const std::array<int32_t,3> pts = copies.FacePoints(T);
      int32_t g = copies.group[T[0]];
      for (int64_t s = copies.start[g]; s < copies.start[g+1]; s++)
        for (int64_t i = vfaces.start[copies.members[s]]; i < vfaces.start[copies.members[s]+1]; i++)
          {
            int32_t h = vfaces.at[i];
            if (h != f && copies.FacePoints(m.faces + 3*h) == pts) return true;
          }
      return false;
    }

    // v in the tetrahedron `tet` at its copy t: of the boundary faces of that tetrahedron
    // at t whose plane has v's reference star on its outer side (faces v's wedge can have
    // crossed into that tetrahedron: the lip between them, or where several cracks meet
    // the lip of t towards a third copy that v slid past; not a face of t that v's wedge
    // lies across, such as the side face that the edge of a lip pushed across a crack
    // lies on), the one v is least deep behind at the current positions; -1 if none.
    // `depth` gets max(0, -signed distance). Faces of t elsewhere are not candidates: t's
    // wedge can be reflex, and v outside one of its planes may still be inside it.
    // With `lips_of` (the copies), the candidates are instead the lips among those faces
    // (IsLip), and only one that v is behind is returned (see the caller). With `tet`
    // null, the candidates are the faces at t of every tetrahedron that v is behind
    // (lips only with `lips_of`; see the caller).
    int32_t SeparatingFace (const TetMesh3 & m, const VertexFaces & vfaces, const Topology & topo,
                            int32_t v, int32_t t, const int32_t * tet, double & depth,
                            const Copies * lips_of = nullptr)
    {
      bool lips_only = lips_of != nullptr;
      bool behind_only = lips_only || tet == nullptr;
      int32_t best = -1;
      double best_s = -std::numeric_limits<double>::infinity();
      auto in_tet = [&] (int32_t w) { return !tet || tet[0] == w || tet[1] == w || tet[2] == w || tet[3] == w; };
      for (int64_t i = vfaces.start[t]; i < vfaces.start[t+1]; i++)
        {
          int32_t f = vfaces.at[i];
          const int32_t * T = m.faces + 3*f;
          if (!in_tet(T[0]) || !in_tet(T[1]) || !in_tet(T[2])) continue;
          double e0[3], e1[3], n[3], nref[3];
          Sub(m.X + 3*T[1], m.X + 3*T[0], e0); Sub(m.X + 3*T[2], m.X + 3*T[0], e1); Cross(e0, e1, nref);
          double len = std::sqrt(Dot(nref, nref));
          if (!(len > 0)) continue;
          for (int d = 0; d < 3; d++) nref[d] /= len;
          Sub(m.x + 3*T[1], m.x + 3*T[0], e0); Sub(m.x + 3*T[2], m.x + 3*T[0], e1); Cross(e0, e1, n);
          len = std::sqrt(Dot(n, n));
          if (!(len > 0)) continue;
          double r[3];
          Sub(m.x + 3*v, m.x + 3*t, r);
          double s = Dot(n, r) / len;
          if (!tet && !(s < 0)) continue;              // the whole star: faces v is behind
          if (!(s > best_s || (s == best_s && f < best))) continue;
          // the tests on the mesh last: they decide only for a face that would be the best
          if (lips_only ? !IsLip(m, *lips_of, vfaces, f) : (tet && !StarOnSide(m, topo, v, nref, 1.0))) continue;
          best_s = s; best = f;
        }
      if (behind_only && !(best_s < 0)) best = -1;
      depth = best >= 0 ? std::max(0.0, -best_s) : 0.0;
      return best;
    }

    // Whether tetrahedron `tet` has a boundary face at vertex t.
    bool HasBoundaryFaceAt (const TetMesh3 & m, const VertexFaces & vfaces, int32_t t, const int32_t * tet)
    {
      auto in_tet = [&] (int32_t w) { return tet[0] == w || tet[1] == w || tet[2] == w || tet[3] == w; };
      for (int64_t i = vfaces.start[t]; i < vfaces.start[t+1]; i++)
        {
          const int32_t * T = m.faces + 3*vfaces.at[i];
          if (in_tet(T[0]) && in_tet(T[1]) && in_tet(T[2])) return true;
        }
      return false;
    }

    inline bool IsPartner (const std::vector<int32_t> & partners, int32_t f)
    { return !partners.empty() && std::binary_search(partners.begin(), partners.end(), f); }

    // A face at v is never v's master (only possible on v's own fragment, self-contact).
    inline bool AtVertex (const int32_t * T, int32_t v) { return T[0] == v || T[1] == v || T[2] == v; }

    // Master face, step 1: a face of F that holds v exactly (closed triangle) and whose
    // normal does not point along v's (dot <= 0): v touches it, gap 0. Such a face is
    // in v's own cell. Returns the smallest such face number or -1.
    int32_t TouchedFace (const TetMesh3 & m, const Derived & D, const HashGrid & fg, int32_t v, int32_t F,
                         const std::vector<int32_t> & partners)
    {
      const double * p = m.x + 3*v;
      int32_t found = -1;
      fg.Visit(fg.Cell(p[0], 0), fg.Cell(p[1], 1), fg.Cell(p[2], 2), [&] (int32_t f)
        {
          if (D.ffrag[f] != F || (found >= 0 && f > found)) return;
          // a point of the closed triangle lies in its closed box (exactly: the box of
          // its corners): one outside is not held, without the exact predicates
          for (int d = 0; d < 3; d++)
            if (p[d] < D.flo[3*f+d] || p[d] > D.fhi[3*f+d]) return;
          if (!(Dot(&D.fnormal[3*f], &D.vnormal[3*v]) <= 0) && !IsPartner(partners, f)) return;
          const int32_t * T = m.faces + 3*f;
          if (AtVertex(T, v)) return;
          if (PointInClosedTriangle3(p, m.x + 3*T[0], m.x + 3*T[1], m.x + 3*T[2])) found = f;
        });
      return found;
    }

    // Step 2: the nearest face of F opposing v (normal dot < 0), or of any orientation if
    // none does, ring by ring of cells around v; ties to the smaller face number.
    int32_t NearestFace (const TetMesh3 & m, const Derived & D, const HashGrid & fg, int32_t v, int32_t F,
                         bool opposing, const std::vector<int32_t> & partners, double * bary_out)
    {
      const double * p = m.x + 3*v;
      int64_t c[3] = { fg.Cell(p[0], 0), fg.Cell(p[1], 1), fg.Cell(p[2], 2) };
      double best = std::numeric_limits<double>::infinity();
      int32_t bf = -1;
      // the distance from p to the walls of its own cell (less a margin for rounding): after
      // ring r every face not seen is farther than r h + wall from p
      double wall = std::numeric_limits<double>::infinity();
      for (int d = 0; d < 3; d++)
        {
          double f = (p[d] - fg.origin[d]) / fg.h - double(c[d]);
          wall = std::min({ wall, f * fg.h, (1.0 - f) * fg.h });
        }
      wall = std::max(0.0, wall - 1e-6 * fg.h);
      auto consider = [&] (int32_t f)
        {
          if (D.ffrag[f] != F) return;
          if (opposing && !(Dot(&D.fnormal[3*f], &D.vnormal[3*v]) < 0) && !IsPartner(partners, f)) return;
          // a face whose box is farther than the best is not nearer (a margin for rounding
          // keeps the ties, which go to the smaller face number)
          double box2 = 0;
          for (int d = 0; d < 3; d++)
            {
              double e = std::max({ D.flo[3*f+d] - p[d], p[d] - D.fhi[3*f+d], 0.0 });
              box2 += e * e;
            }
          if (box2 > best * (1.0 + 1e-9)) return;
          const int32_t * T = m.faces + 3*f;
          if (AtVertex(T, v)) return;
          const double * a = m.x + 3*T[0], * b = m.x + 3*T[1], * cc = m.x + 3*T[2];
          double bary[3], q[3];
          ClosestPointOnTriangle3(p, a, b, cc, bary);
          double d2 = Dist2(p, a, b, cc, bary, q);
          if (d2 < best || (d2 == best && f < bf)) { best = d2; bf = f; std::copy(bary, bary + 3, bary_out); }
        };
      // the distance from p to cell i along axis d
      auto axis_gap = [&] (int64_t i, int d)
        {
          double lo = fg.origin[d] + double(i) * fg.h;
          return std::max({ lo - p[d], p[d] - (lo + fg.h), 0.0 });
        };
      for (int64_t r = 0; r <= fg.span; r++)
        {
          // the shell of cells at Chebyshev distance r, clipped to the grid; a cell farther
          // from p than the best face holds no nearer face (a face's nearest point lies in a
          // cell it is hashed to), so it is not visited (1e-6 h covers the rounding of the
          // cell bounds, 1e-9 relative keeps the ties)
          for (int64_t i = std::max<int64_t>(c[0]-r, 0); i <= std::min(c[0]+r, fg.span-1); i++)
            for (int64_t j = std::max<int64_t>(c[1]-r, 0); j <= std::min(c[1]+r, fg.span-1); j++)
              {
                bool side = std::abs(i-c[0]) == r || std::abs(j-c[1]) == r;
                int64_t step = side || r == 0 ? 1 : 2*r;
                double gij = axis_gap(i, 0) * axis_gap(i, 0) + axis_gap(j, 1) * axis_gap(j, 1);
                for (int64_t k = c[2]-r; k <= c[2]+r; k += step)
                  {
                    if (bf >= 0)
                      {
                        double lb = std::sqrt(gij + axis_gap(k, 2) * axis_gap(k, 2)) - 1e-6 * fg.h;
                        if (lb > 0 && lb * lb > best * (1.0 + 1e-9)) continue;
                      }
                    fg.Visit(i, j, k, consider);
                  }
              }
          // faces not seen yet lie beyond distance r h, and beyond r h + wall (strictly:
          // no tie with a face not seen)
          double reach = double(r) * fg.h + wall;
          if (bf >= 0 && (best <= (double(r) * fg.h) * (double(r) * fg.h) || best < reach * reach)) break;
        }
      return bf;
    }

    bool MasterFace (const TetMesh3 & m, const Derived & D, const HashGrid & fg, int32_t v, int32_t F,
                     const std::vector<int32_t> & partners, Penetration3 & out)
    {
      const double * p = m.x + 3*v;
      int32_t f = TouchedFace(m, D, fg, v, F, partners);
      const int32_t * T = nullptr;
      if (f >= 0)
        {
          T = m.faces + 3*f;
          ClosestPointOnTriangle3(p, m.x + 3*T[0], m.x + 3*T[1], m.x + 3*T[2], out.bary);
          std::copy(p, p + 3, out.proj);
          out.gap = 0.0;
        }
      else
        {
          f = NearestFace(m, D, fg, v, F, true, partners, out.bary);
          if (f < 0) f = NearestFace(m, D, fg, v, F, false, partners, out.bary);
          if (f < 0) return false;
          T = m.faces + 3*f;
          double d2 = Dist2(p, m.x + 3*T[0], m.x + 3*T[1], m.x + 3*T[2], out.bary, out.proj);
          out.gap = -std::sqrt(d2);
        }
      out.face = f;
      std::copy(&D.fnormal[3*f], &D.fnormal[3*f] + 3, out.normal);
      return true;
    }

  }

  namespace
  {
    // The topology of a mesh, its copies and lip flags (all from the connectivity and the
    // reference points).
    void MakeTopology (const TetMesh3 & m, Topology & T, Copies & copies)
    {
      DeriveTopology(m, T);
      copies = MakeCopies(m, T);
      T.lip.assign(m.nv, 0);           // two copies of a point on one fragment: the lips of a crack inside it
      for (size_t g = 0; g + 1 < copies.start.size(); g++)
        for (int64_t i = copies.start[g]; i < copies.start[g+1]; i++)
          for (int64_t j = i + 1; j < copies.start[g+1]; j++)
            {
              int32_t a = copies.members[i], b = copies.members[j];
              if (T.vfrag[a] == T.vfrag[b]) T.lip[a] = T.lip[b] = 1;
            }
    }

    // The closed seams, decided before the sweep: a pair (v, F) whose vertex sits at the
    // current point of its twin on F (v's first copy there, Copies::Twin). The sweep finds
    // such a pair in a tetrahedron of F at the twin (v is a corner of it, so in its closed
    // volume and box), unless every tetrahedron there is flat, and counts it as a closed
    // seam whichever tetrahedron it finds it in: here it is counted and decided without the
    // exact tests of all the tetrahedra around it. Pairs whose twin has only flat
    // tetrahedra are left to the sweep.
    int64_t DecideClosedSeams (const TetMesh3 & m, const Topology & T, const Copies & copies, Decided & decided)
    {
      int64_t closed = 0;
      for (int32_t v : T.bverts)
        {
          int32_t g = copies.group[v];
          for (int64_t s = copies.start[g]; s < copies.start[g+1]; s++)
            {
              int32_t w = copies.members[s], F = T.vfrag[w];
              if (w == v || copies.Twin(T.vfrag, v, F) != w) continue;      // first copy on F only
              if (std::memcmp(m.x + 3*v, m.x + 3*w, 3 * sizeof(double)) != 0) continue;
              bool solid = false;
              for (int64_t a = T.start[w]; a < T.start[w+1] && !solid; a++)
                {
                  const int32_t * t = m.tets + 4*T.at[a];
                  solid = t[0] != v && t[1] != v && t[2] != v && t[3] != v
                    && Orient3dSign(m.x + 3*t[0], m.x + 3*t[1], m.x + 3*t[2], m.x + 3*t[3]) != 0;
                }
              if (!solid) continue;
              decided.Insert(v, F);
              closed++;
            }
        }
      return closed;
    }

    // The boundary faces at every vertex (MakeVertexFaces): from the connectivity alone,
    // made once per mesh by a detector.
    struct Incidence
    {
      VertexFaces vfaces;
    };

    // `incidence` the mesh's (made here, if there is a hit, when null)
    std::vector<Penetration3> Detect (const TetMesh3 & m, const Topology & T, const Copies & copies,
                                      Collision3Stats * stats, const Incidence * incidence = nullptr)
    {
      Collision3Stats st;
      Derived D { T.vfrag, T.ffrag, T.bverts, T.lip, {}, {}, {}, {} };
      DeriveNormals(m, D);
      st.boundary_vertices = int64_t(D.bverts.size());
      std::vector<Penetration3> out;
      if (D.bverts.empty() || m.ne == 0) { if (stats) *stats = st; return out; }
      HashGrid vg;
      SetupGrid(m, D, vg);
      st.cell = vg.h;
      std::vector<double> lo(3*D.bverts.size()), hi;
      for (size_t s = 0; s < D.bverts.size(); s++)
        std::copy(m.x + 3*D.bverts[s], m.x + 3*D.bverts[s] + 3, &lo[3*s]);
      vg.Build(lo, lo);
      std::vector<GridPoint> points(vg.items.size());
      for (size_t s = 0; s < vg.items.size(); s++)
        {
          int32_t v = D.bverts[vg.items[s]];
          vg.items[s] = v;                                   // grid items: vertex numbers
          GridPoint & q = points[s];
          std::copy(m.x + 3*v, m.x + 3*v + 3, q.p);
          q.v = v; q.frag = D.vfrag[v]; q.lip = D.lip[v] != 0;
        }
      Decided decided(m.nv);
      int64_t closed = DecideClosedSeams(m, T, copies, decided);
      std::vector<Hit> hits = SweepTets(m, copies, D.vfrag, T.frag_tets, vg, points, decided, st);
      st.closed_seams += closed;
      if (hits.empty()) { if (stats) *stats = st; return out; }

      HashGrid fg = vg;                                    // same cells, boundary faces
      lo.assign(3*m.nf, 0.0); hi.assign(3*m.nf, 0.0);
      for (int64_t f = 0; f < m.nf; f++)
        for (int d = 0; d < 3; d++)
          {
            double a = m.x[3*m.faces[3*f]+d], b = m.x[3*m.faces[3*f+1]+d], c = m.x[3*m.faces[3*f+2]+d];
            lo[3*f+d] = std::min({a, b, c}); hi[3*f+d] = std::max({a, b, c});
          }
      fg.items.clear(); fg.range.clear();
      fg.Build(lo, hi);
      D.flo = std::move(lo); D.fhi = std::move(hi);

      Incidence own;
      if (!incidence)
        {
          own = Incidence { MakeVertexFaces(m) };
          incidence = &own;
        }
      const VertexFaces & vfaces = incidence->vfaces;
      std::vector<int32_t> partners;                       // of the hit at hand
      std::vector<std::pair<int32_t,int32_t>> scratch;
      for (size_t s = 0; s < hits.size(); s++)
        {
          auto [v, F, t] = hits[s];
          if (s > 0 && std::get<0>(hits[s-1]) == v && std::get<1>(hits[s-1]) == F) continue;
          Penetration3 pen;
          pen.vertex = v; pen.fragment = F; pen.tet = t;
          pen.twin = copies.Twin(D.vfrag, v, F);             // closed seams were left out by the sweep
          // v in the star of a copy t (the holding tetrahedron is at t): the face at t
          // it crossed, if there is one
          int32_t t_copy = -1;
          for (int k = 0; k < 4 && pen.twin >= 0; k++)
            {
              int32_t w = m.tets[4*t + k];
              if (w != v && copies.group[w] == copies.group[v]) t_copy = w;
            }
          double depth = 0;
          int32_t sep = t_copy >= 0 ? SeparatingFace(m, vfaces, T, v, t_copy, m.tets + 4*t, depth) : -1;
          // none, and two or more copies of the point on F (a crack inside F, or cracks
          // meeting inside F): v's wedge can lie across the plane of the lip it crossed
          // into t's wedge; that lip still separates v if v is behind it (the nearest face
          // of F may be the coincident lip of another copy, v in front of it)
          if (sep < 0 && t_copy >= 0 && copies.CountOn(D.vfrag, v, F) >= 2)
            sep = SeparatingFace(m, vfaces, T, v, t_copy, m.tets + 4*t, depth, &copies);
          // none, three or more copies on F, and the holding tetrahedron has no face on the
          // boundary at t: v slid past the faces of the tetrahedra at t deeper into t's star
          // where several cracks meet; the lip at t that v is least deep behind (the
          // nearest face of F may be one v is in front of, whose row does not hold it)
          if (sep < 0 && t_copy >= 0 && copies.CountOn(D.vfrag, v, F) >= 3
              && !HasBoundaryFaceAt(m, vfaces, t_copy, m.tets + 4*t))
            sep = SeparatingFace(m, vfaces, T, v, t_copy, nullptr, depth, &copies);
          if (sep >= 0)
            {
              const int32_t * T = m.faces + 3*sep;
              ClosestPointOnTriangle3(m.x + 3*v, m.x + 3*T[0], m.x + 3*T[1], m.x + 3*T[2], pen.bary);
              for (int d = 0; d < 3; d++)
                pen.proj[d] = pen.bary[0]*m.x[3*T[0]+d] + pen.bary[1]*m.x[3*T[1]+d] + pen.bary[2]*m.x[3*T[2]+d];
              pen.face = sep;
              std::copy(&D.fnormal[3*sep], &D.fnormal[3*sep] + 3, pen.normal);
              pen.gap = -depth;
              out.push_back(pen);
              continue;
            }
          partners.clear();
          if (pen.twin >= 0) PartnerFaces(m, copies, D, vfaces, v, F, partners, scratch);
          if (!MasterFace(m, D, fg, v, F, partners, pen)) continue;
          out.push_back(pen);
        }
      if (stats) *stats = st;
      return out;
    }
  }

  std::vector<Penetration3> DetectPenetrations3 (const TetMesh3 & m, Collision3Stats * stats)
  {
    Topology T;
    Copies copies;
    MakeTopology(m, T, copies);
    return Detect(m, T, copies, stats);
  }

  struct PenetrationDetector3::Impl
  {
    std::vector<double> X;
    std::vector<int32_t> tets, faces, fragment;
    int64_t nv, ne, nf;
    Topology T;
    Copies copies;
    Incidence incidence;

    TetMesh3 Mesh (const double * x) const
    { return TetMesh3 { X.data(), x, tets.data(), faces.data(), fragment.data(), nv, ne, nf }; }
  };

  PenetrationDetector3::PenetrationDetector3 (const TetMesh3 & m)
    : impl_(std::make_unique<Impl>())
  {
    Impl & I = *impl_;
    I.X.assign(m.X, m.X + 3*m.nv);
    I.tets.assign(m.tets, m.tets + 4*m.ne);
    I.faces.assign(m.faces, m.faces + 3*m.nf);
    I.fragment.assign(m.fragment, m.fragment + m.ne);
    I.nv = m.nv; I.ne = m.ne; I.nf = m.nf;
    MakeTopology(I.Mesh(I.X.data()), I.T, I.copies);
    I.incidence = Incidence { MakeVertexFaces(I.Mesh(I.X.data())) };
  }

  PenetrationDetector3::~PenetrationDetector3 () = default;

  int64_t PenetrationDetector3::NumVertices () const { return impl_->nv; }

  std::vector<Penetration3> PenetrationDetector3::Detect (const double * x, Collision3Stats * stats) const
  {
    return ngfracture::Detect(impl_->Mesh(x), impl_->T, impl_->copies, stats, &impl_->incidence);
  }
}
