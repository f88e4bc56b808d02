#ifndef NGFRACTURE_COLLISION3D_PARTS_HPP
#define NGFRACTURE_COLLISION3D_PARTS_HPP
// The parts of the 3D collision detection (collision3d.hpp) shared by its three sources:
// collision3d.cpp (topology, the grid of boundary vertices, the detection of a mesh),
// collision3d_sweep.cpp (the sweep of the tetrahedra over that grid) and
// collision3d_faces.cpp (the master face of every hit). Internal: not part of the
// module's interface.
#include "collision3d.hpp"
#include "predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace ngfracture::detect3d
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
    inline bool InClosedTet (const double * x, const int32_t * t, const double * p, int s)
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
    inline double Dist2 (const double * p, const double * a, const double * b, const double * c,
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

    // A boundary vertex in the grid, with what the sweep tests first, in the order of the
    // grid's items: a tetrahedron reads the vertices of a cell from consecutive memory.
    struct GridPoint
    {
      double p[3];
      int32_t v;
      int32_t frag;        // the vertex's fragment
      bool lip;            // a copy of its point on its own fragment (D.lip)
    };

    // The boundary faces at every vertex (CSR: faces at[start[v] .. start[v+1]), increasing).
    struct VertexFaces
    {
      std::vector<int64_t> start;
      std::vector<int32_t> at;
    };

    // The hits (vertex, fragment, tetrahedron) of the boundary vertices of grid g (``points``,
    // its items slot by slot) in the tetrahedra of other fragments, and of lip vertices in
    // their own fragment's (collision3d_sweep.cpp).
    std::vector<Hit> SweepTets (const TetMesh3 & m, const Copies & copies, const std::vector<int32_t> & vfrag,
                                const std::vector<int64_t> & frag_tets, const HashGrid & g, const std::vector<GridPoint> & points,
                                Decided & decided, Collision3Stats & st);

    // The boundary faces at every vertex (collision3d_faces.cpp, as the rest below).
    VertexFaces MakeVertexFaces (const TetMesh3 & m);

    // The partner faces of v on fragment F (faces at a copy of v opposing one of v's own).
    void PartnerFaces (const TetMesh3 & m, const Copies & copies, const Derived & D,
                       const VertexFaces & vfaces, int32_t v, int32_t F, std::vector<int32_t> & out,
                       std::vector<std::pair<int32_t,int32_t>> & own);

    // The face at copy t that v crossed into tetrahedron `tet` (or, `tet` null, into t's star).
    int32_t SeparatingFace (const TetMesh3 & m, const VertexFaces & vfaces, const Topology & topo,
                            int32_t v, int32_t t, const int32_t * tet, double & depth,
                            const Copies * lips_of = nullptr, int32_t lips_on = -1);

    // Whether tetrahedron `tet` has a boundary face at vertex t.
    bool HasBoundaryFaceAt (const TetMesh3 & m, const VertexFaces & vfaces, int32_t t, const int32_t * tet);

    // The master face of fragment F for vertex v (touched, else nearest): false if F has none.
    bool MasterFace (const TetMesh3 & m, const Derived & D, const HashGrid & fg, int32_t v, int32_t F,
                     const std::vector<int32_t> & partners, Penetration3 & out);
}

#endif
