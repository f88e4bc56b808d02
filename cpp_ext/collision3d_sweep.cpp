// The sweep of the 3D collision detection: every tetrahedron's box over the grid of
// boundary vertices, with exact point-in-tetrahedron tests (collision3d_parts.hpp).
#include "collision3d_parts.hpp"

#include <cstring>

namespace ngfracture::detect3d
{
  namespace
  {
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
}
