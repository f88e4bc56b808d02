// Boundary edges of different fragments (or of the two lips of one crack) that cross.
#include "edge_crossings3d.hpp"
#include "predicates.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace ngfracture
{
  namespace
  {
    // A spatial hash of boxes: the cells (i, j, k) of size h from origin that each box
    // overlaps, bucketed by a hash of the cell (a counting sort). An entry holds its cell
    // and its box's first cell, so that a scan of a bucket reads it alone: entries of
    // other cells in the bucket (hash collisions) are told apart by their cell. It also
    // holds its item's group (the swept edge's fragment), which rejects most entries first.
    struct BoxHash
    {
      struct Entry
      {
        int32_t cell[3];               // the cell of this entry
        int32_t item;
        int32_t first[3];              // the item's first cell along x, y, z
        int32_t group;                 // the item's group (Fill's ``group``)
      };
      double origin[3] = { 0, 0, 0 }, h = 0;
      int shift = 64;
      std::vector<int64_t> start;      // bucket b holds entries[start[b] .. start[b+1])
      std::vector<Entry> entries;

      int32_t Cell (double v, int d) const { return int32_t(std::floor((v - origin[d]) / h)); }
      size_t Bucket (int64_t i, int64_t j, int64_t k) const
      {
        uint64_t m = uint64_t(i) * 0x9E3779B97F4A7C15ull ^ uint64_t(j) * 0xC2B2AE3D27D4EB4Full
          ^ uint64_t(k) * 0x165667B19E3779F9ull;
        return size_t((m * 0xD6E8FEB86659FD93ull) >> shift);
      }
      template <typename F> static void Cells (const int32_t * r, F && f)
      {
        for (int32_t i = r[0]; i <= r[3]; i++)
          for (int32_t j = r[1]; j <= r[4]; j++)
            for (int32_t k = r[2]; k <= r[5]; k++)
              f(i, j, k);
      }
      // first and last cell along x, y, z of the box lo..hi
      void Range (const double * lo, const double * hi, int32_t * r) const
      {
        for (int d = 0; d < 3; d++) { r[d] = Cell(lo[d], d); r[3+d] = Cell(hi[d], d); }
      }

      // The cells of boxes lo..hi: cell size the mean largest extent of a box, at least
      // 2^-20 of the boxes' span, doubled while the boxes would fill more than 32 n + 2^20
      // cells; range gets every box's first and last cell along x, y, z. Returns false
      // (nothing to hash) when every box is a point.
      bool Measure (const std::vector<double> & lo, const std::vector<double> & hi, std::vector<int32_t> & range)
      {
        size_t n = lo.size() / 3;
        double top[3] = { -INFINITY, -INFINITY, -INFINITY }, extent = 0;
        std::fill(origin, origin + 3, INFINITY);
        for (size_t t = 0; t < n; t++)
          {
            double m = 0;
            for (int d = 0; d < 3; d++)
              {
                origin[d] = std::min(origin[d], lo[3*t+d]);
                top[d] = std::max(top[d], hi[3*t+d]);
                m = std::max(m, hi[3*t+d] - lo[3*t+d]);
              }
            extent += m;
          }
        h = n ? extent / double(n) : 0;
        if (!(h > 0) || !std::isfinite(h)) { h = 0; return false; }
        for (int d = 0; d < 3; d++) h = std::max(h, (top[d] - origin[d]) / double(1 << 20));
        range.resize(6 * n);
        // boxes far larger than the mean would fill too many cells: coarser cells then
        for (bool fits = false; !fits; h *= fits ? 1.0 : 2.0)
          {
            int64_t count = 0;
            for (size_t t = 0; t < n; t++)
              {
                Range(&lo[3*t], &hi[3*t], &range[6*t]);
                int32_t * r = &range[6*t];
                count += int64_t(r[3] - r[0] + 1) * (r[4] - r[1] + 1) * (r[5] - r[2] + 1);
              }
            fits = count <= 32 * int64_t(n) + (int64_t(1) << 20);
          }
        return true;
      }

      // hashes items 0 .. n-1 with cell ranges `range` (6 each, in this grid's cells) and
      // groups `group`
      void Fill (const std::vector<int32_t> & range, const std::vector<int32_t> & group, size_t n)
      {
        int64_t count = 0;
        for (size_t t = 0; t < n; t++)
          {
            const int32_t * r = &range[6*t];
            count += int64_t(r[3] - r[0] + 1) * (r[4] - r[1] + 1) * (r[5] - r[2] + 1);
          }
        int bits = 4;
        while ((int64_t(1) << bits) < count) bits++;
        shift = 64 - bits;
        start.assign((size_t(1) << bits) + 1, 0);
        for (size_t t = 0; t < n; t++)
          Cells(&range[6*t], [&] (int32_t i, int32_t j, int32_t k) { start[Bucket(i, j, k) + 1]++; });
        for (size_t b = 1; b < start.size(); b++) start[b] += start[b-1];
        entries.resize(size_t(count));
        std::vector<int64_t> fill(start.begin(), start.end() - 1);
        for (size_t t = 0; t < n; t++)
          {
            const int32_t * r = &range[6*t];
            Cells(r, [&] (int32_t i, int32_t j, int32_t k)
              { entries[fill[Bucket(i, j, k)]++] = Entry { { i, j, k }, int32_t(t), { r[0], r[1], r[2] }, group[t] }; });
          }
      }
    };

    // The edges a detection sweeps at x: neither both ends on closed lips nor an end to
    // skip (those counted in st), with their fragments, boxes (lo then hi) and cells in grid.
    struct Swept { std::vector<int32_t> edge, own, range; std::vector<double> box; };

    Swept SweptEdges (const std::vector<int32_t> & edges, const std::vector<int32_t> & face_fragment,
                      const std::vector<int32_t> & edge_faces, const std::vector<int64_t> & edge_face_ptr,
                      const double * x, const std::vector<char> & closed, const uint8_t * skip,
                      const BoxHash & grid, EdgeCrossingStats & st)
    {
      Swept sw;
      int64_t ne = int64_t(edges.size() / 2);
      for (int32_t e = 0; e < ne; e++)
        {
          const int32_t u = edges[2*e], w = edges[2*e+1];
          if (closed[u] && closed[w]) { st.closed_edges++; continue; }
          if (skip && (skip[u] || skip[w])) { st.skipped_edges++; continue; }
          const double * p = x + 3*u, * q = x + 3*w;
          double b[6];
          for (int d = 0; d < 3; d++) { b[d] = std::min(p[d], q[d]); b[3+d] = std::max(p[d], q[d]); }
          sw.edge.push_back(e);
          sw.own.push_back(face_fragment[edge_faces[edge_face_ptr[e]]]);
          sw.box.insert(sw.box.end(), b, b + 6);
          sw.range.resize(sw.range.size() + 6);
          grid.Range(b, b + 3, &sw.range[sw.range.size() - 6]);
        }
      return sw;
    }

  }

  bool EdgeCrossingDetector3::Shares (const int32_t * f, int32_t v) const
  {
    int32_t p = point_[v];
    return point_[f[0]] == p || point_[f[1]] == p || point_[f[2]] == p;
  }

  bool SegmentPiercesTriangle (const double * p, const double * q, const double * a, const double * b,
                               const double * c)
  {
    // an endpoint at a corner (a closed lip's copy) lies on the plane: no exact predicate needed
    for (const double * v : { a, b, c })
      if ((p[0] == v[0] && p[1] == v[1] && p[2] == v[2]) || (q[0] == v[0] && q[1] == v[1] && q[2] == v[2]))
        return false;
    int o = Orient3dSign(a, b, c, p);
    if (o == 0 || Orient3dSign(a, b, c, q) != -o) return false;
    int s = Orient3dSign(p, q, a, b);
    return s != 0 && Orient3dSign(p, q, b, c) == s && Orient3dSign(p, q, c, a) == s;
  }

  EdgeCrossingDetector3::EdgeCrossingDetector3 (int64_t nv, const int32_t * faces, int64_t nf,
                                                const int32_t * face_fragment, const int32_t * point,
                                                bool across)
    : nv_(nv), nf_(nf), across_(across), faces_(faces, faces + 3 * nf),
      fragment_(face_fragment, face_fragment + nf), point_(point, point + nv)
  {
    std::vector<int32_t> owner(nv, -1);          // the face that first claimed every vertex
    for (int64_t f = 0; f < nf; f++)
      for (int k = 0; k < 3; k++)
        {
          int32_t v = faces[3*f+k];
          if (v < 0 || v >= nv)
            throw std::invalid_argument("faces: face " + std::to_string(f) + " has vertex number " + std::to_string(v)
                                        + ", not in [0, " + std::to_string(nv) + ")");
          if (v == faces[3*f+(k+1)%3])
            throw std::invalid_argument("faces: face " + std::to_string(f) + " repeats vertex " + std::to_string(v));
          int32_t o = owner[v];
          if (o < 0) owner[v] = int32_t(f);
          else if (face_fragment[o] != face_fragment[f])
            throw std::invalid_argument("face_fragment: vertex " + std::to_string(v) + " is on face " + std::to_string(o)
                                        + " of fragment " + std::to_string(face_fragment[o]) + " and on face "
                                        + std::to_string(f) + " of fragment " + std::to_string(face_fragment[f]));
        }
    // every (edge key, face slot 3 f + k), sorted: the edges in lexicographic order, the
    // faces at each edge increasing. A counting sort by the edge's lower vertex (slots in
    // increasing order), then a stable insertion sort of every vertex's few slots by the
    // higher vertex (many: std::stable_sort): the order of std::sort of the pairs (key,
    // slot), which are distinct
    std::vector<std::pair<uint64_t, int64_t>> slots(3 * nf);
    {
      std::vector<int64_t> start(nv + 1, 0);
      for (int64_t i = 0; i < 3 * nf; i++)
        start[std::min(faces[i], faces[i - i % 3 + (i % 3 + 1) % 3]) + 1]++;
      for (int64_t v = 0; v < nv; v++) start[v+1] += start[v];
      std::vector<int64_t> fill(start.begin(), start.end() - 1);
      for (int64_t f = 0; f < nf; f++)
        for (int k = 0; k < 3; k++)
          {
            uint64_t u = uint32_t(faces[3*f+k]), w = uint32_t(faces[3*f+(k+1)%3]);
            slots[fill[std::min(u, w)]++] = { (std::min(u, w) << 32) | std::max(u, w), 3*f+k };
          }
      auto by_key = [] (const std::pair<uint64_t, int64_t> & x, const std::pair<uint64_t, int64_t> & y)
        { return x.first < y.first; };
      for (int64_t v = 0; v < nv; v++)
        if (start[v+1] - start[v] > 64)
          std::stable_sort(slots.begin() + start[v], slots.begin() + start[v+1], by_key);
        else for (int64_t i = start[v] + 1; i < start[v+1]; i++)
          {
            auto x = slots[i];
            int64_t j = i;
            for (; j > start[v] && x.first < slots[j-1].first; j--) slots[j] = slots[j-1];
            slots[j] = x;
          }
    }
    face_edges_.resize(3 * nf);
    edge_faces_.resize(3 * nf);
    edge_face_ptr_.push_back(0);
    for (size_t s = 0; s < slots.size(); s++)
      {
        if (s == 0 || slots[s].first != slots[s-1].first)
          {
            if (s) edge_face_ptr_.push_back(int64_t(s));
            edges_.push_back(int32_t(slots[s].first >> 32));
            edges_.push_back(int32_t(slots[s].first & 0xffffffffu));
          }
        face_edges_[slots[s].second] = int32_t(edges_.size() / 2 - 1);
        edge_faces_[s] = int32_t(slots[s].second / 3);
      }
    if (!slots.empty()) edge_face_ptr_.push_back(int64_t(slots.size()));
    // the vertices of every point (copies together), by a counting sort of the point ids
    int32_t np = 0;
    for (int32_t p : point_) np = std::max(np, p + 1);
    point_start_.assign(np + 1, 0);
    for (int32_t p : point_) if (p >= 0) point_start_[p + 1]++;
    for (int32_t p = 0; p < np; p++) point_start_[p + 1] += point_start_[p];
    point_vertices_.resize(point_start_[np]);
    std::vector<int64_t> fill(point_start_.begin(), point_start_.end() - 1);
    for (int64_t v = 0; v < nv_; v++) if (point_[v] >= 0) point_vertices_[fill[point_[v]]++] = int32_t(v);
  }

  std::vector<char> EdgeCrossingDetector3::Closed (const double * x) const
  {
    // a vertex at the current position of another vertex of its point, bitwise: a closed lip
    std::vector<char> closed(nv_, 0);
    for (size_t p = 0; p + 1 < point_start_.size(); p++)
      for (int64_t i = point_start_[p]; i < point_start_[p+1]; i++)
        for (int64_t j = i + 1; j < point_start_[p+1]; j++)
          {
            const double * a = x + 3 * point_vertices_[i], * b = x + 3 * point_vertices_[j];
            if (a[0] == b[0] && a[1] == b[1] && a[2] == b[2])
              closed[point_vertices_[i]] = closed[point_vertices_[j]] = 1;
          }
    return closed;
  }

  bool EdgeCrossingDetector3::Pierces (const double * x, int32_t e, int32_t f) const
  {
    int32_t p = edges_[2*e], q = edges_[2*e+1];
    const int32_t * t = &faces_[3*f];
    if (Shares(t, p) || Shares(t, q)) return false;
    return SegmentPiercesTriangle(x + 3*p, x + 3*q, x + 3*t[0], x + 3*t[1], x + 3*t[2]);
  }

  // a pierces f, a face at b: does b pierce a face g at a, g of another fragment than f or
  // sharing no point with it
  bool EdgeCrossingDetector3::Interlock (const double * x, int32_t a, int32_t f, int32_t b) const
  {
    const int32_t * tf = &faces_[3*f];
    for (int64_t s = edge_face_ptr_[a]; s < edge_face_ptr_[a+1]; s++)
      {
        int32_t g = edge_faces_[s];
        const int32_t * tg = &faces_[3*g];
        bool apart = fragment_[g] != fragment_[f]
          || !(Shares(tf, tg[0]) || Shares(tf, tg[1]) || Shares(tf, tg[2]));
        if (apart && Pierces(x, b, g)) return true;
      }
    return false;
  }

  std::vector<int32_t> EdgeCrossingDetector3::Detect (const double * x, EdgeCrossingStats * stats,
                                                      const uint8_t * skip) const
  {
    EdgeCrossingStats st;
    std::vector<int32_t> out;
    std::vector<double> lo(3 * nf_), hi(3 * nf_);
    for (int64_t f = 0; f < nf_; f++)
      for (int d = 0; d < 3; d++)
        {
          double a = x[3*faces_[3*f]+d], b = x[3*faces_[3*f+1]+d], c = x[3*faces_[3*f+2]+d];
          lo[3*f+d] = std::min({ a, b, c });
          hi[3*f+d] = std::max({ a, b, c });
        }
    // the cells are the faces' (size and origin from their boxes); the edges swept are
    // hashed and every face visits its cells: each (edge, face) pair is tested in the
    // first cell both boxes' ranges share, as a sweep of the edges over the faces would
    BoxHash grid;
    std::vector<int32_t> frange;
    if (!grid.Measure(lo, hi, frange)) { if (stats) *stats = st; return out; }
    st.cell = grid.h;
    std::vector<std::pair<int32_t, int32_t>> pierces;   // (edge, face)
    // an interlocking pair is found from the sweep of either edge (a pierces a face at b and
    // b one at a): an edge whose two ends lie on closed lips is left to the other edge
    std::vector<char> closed = Closed(x);
    const Swept sw = SweptEdges(edges_, fragment_, edge_faces_, edge_face_ptr_, x, closed, skip, grid, st);
    const std::vector<int32_t> & swept = sw.edge, & own = sw.own;
    const std::vector<double> & ebox = sw.box;
    if (swept.empty()) { if (stats) *stats = st; return out; }
    grid.Fill(sw.range, own, swept.size());
    for (int32_t f = 0; f < int32_t(nf_); f++)
      {
        const int32_t * r = &frange[6*f];
        const int32_t * t = &faces_[3*f];
        const int32_t frag = fragment_[f];
        BoxHash::Cells(r, [&] (int32_t i, int32_t j, int32_t k)
          {
            size_t bucket = grid.Bucket(i, j, k);
            for (int64_t s = grid.start[bucket]; s < grid.start[bucket+1]; s++)
              {
                const BoxHash::Entry & en = grid.entries[s];
                // with across_ an edge of the face's own fragment is no pair (tested first:
                // most entries); this cell, and the first cell both boxes' ranges share
                if ((across_ && en.group == frag)
                    || en.cell[0] != i || en.cell[1] != j || en.cell[2] != k
                    || std::max(r[0], en.first[0]) != i || std::max(r[1], en.first[1]) != j
                    || std::max(r[2], en.first[2]) != k)
                  continue;
                const int32_t a = en.item, e = swept[a];
                const int32_t u = edges_[2*e], w = edges_[2*e+1];
                if (Shares(t, u) || Shares(t, w)) continue;
                st.box_tests++;
                const double * elo = &ebox[6*a], * ehi = elo + 3;
                bool overlap = true;              // strict: a pierce point lies inside both boxes
                for (int d = 0; d < 3; d++)
                  overlap &= elo[d] < hi[3*f+d] && lo[3*f+d] < ehi[d];
                if (!overlap) continue;
                st.exact_tests++;
                if (SegmentPiercesTriangle(x + 3*u, x + 3*w, x + 3*t[0], x + 3*t[1], x + 3*t[2]))
                  pierces.emplace_back(e, f);
              }
          });
      }
    st.pierces = int64_t(pierces.size());
    std::vector<uint64_t> pairs;
    for (auto [a, f] : pierces)
      for (int k = 0; k < 3; k++)
        {
          int32_t b = face_edges_[3*f+k];
          if (Interlock(x, a, f, b))
            pairs.push_back((uint64_t(std::min(a, b)) << 32) | uint64_t(std::max(a, b)));
        }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    for (uint64_t c : pairs)
      {
        out.push_back(int32_t(c >> 32));
        out.push_back(int32_t(c & 0xffffffffu));
      }
    if (stats) *stats = st;
    return out;
  }
}
