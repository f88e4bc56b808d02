#include "crack_split.hpp"
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace ngfracture
{
  namespace
  {
    int Find (std::vector<int> & uf, int i)
    {
      while (uf[i] != i) { uf[i] = uf[uf[i]]; i = uf[i]; }
      return i;
    }
    void Unite (std::vector<int> & uf, int a, int b)
    {
      a = Find(uf, a); b = Find(uf, b);
      if (a != b) { if (a < b) uf[b] = a; else uf[a] = b; }   // smaller root: deterministic
    }
  }

  CrackSplitter :: CrackSplitter (const double * apoints, int anv, const int * atrigs, int ane,
                                  const int * asegs, int ns)
    : nv0(anv), ne(ane), points(apoints, apoints + 2*size_t(anv)),
      trigs(atrigs, atrigs + 3*size_t(ane)), segs0(asegs, asegs + 2*size_t(ns))
  {
    for (size_t i = 0; i < trigs.size(); i++)
      if (trigs[i] < 0 || trigs[i] >= nv0)
        throw std::invalid_argument("ngfracture: triangle " + std::to_string(i/3) +
                                    " has vertex " + std::to_string(trigs[i]) + " outside [0, " +
                                    std::to_string(nv0) + ")");
    parent.resize(nv0);
    std::iota(parent.begin(), parent.end(), 0);
    modified.assign(nv0, 0);
    star_mod.resize(nv0);

    // vertex -> triangles, ascending triangle numbers
    star_off.assign(nv0+1, 0);
    for (int v : trigs) star_off[v+1]++;
    for (int v = 0; v < nv0; v++) star_off[v+1] += star_off[v];
    star_data.resize(trigs.size());
    std::vector<int> fill(star_off.begin(), star_off.end()-1);
    for (int t = 0; t < ne; t++)
      for (int k = 0; k < 3; k++)
        star_data[fill[trigs[3*t+k]]++] = t;

    // owner triangle of every input segment: the one with the segment in its own
    // vertex order (the domain on the segment's left for counter-clockwise triangles)
    seg_trig.assign(ns, -1);
    seg_loc.assign(2*size_t(ns), -1);
    for (int s = 0; s < ns; s++)
      {
        int p = segs0[2*s], q = segs0[2*s+1];
        if (p < 0 || p >= nv0 || q < 0 || q >= nv0)
          throw std::invalid_argument("ngfracture: segment " + std::to_string(s) + " has a vertex out of range");
        for (int i = star_off[p]; i < star_off[p+1]; i++)
          {
            int t = star_data[i];
            int kp = Local(t, p);
            int kq = -1;
            for (int k = 0; k < 3; k++) if (trigs[3*t+k] == q) kq = k;
            if (kq < 0) continue;
            bool forward = kq == (kp+1) % 3;
            if (seg_trig[s] < 0 || forward)
              { seg_trig[s] = t; seg_loc[2*s] = kp; seg_loc[2*s+1] = kq; }
            if (forward) break;
          }
      }
  }

  const int * CrackSplitter :: StarBegin (int v) const
  {
    if (modified[v]) return star_mod[v].data();
    return star_data.data() + star_off[v];
  }

  int CrackSplitter :: StarSize (int v) const
  {
    if (modified[v]) return int(star_mod[v].size());
    return star_off[v+1] - star_off[v];
  }

  int CrackSplitter :: Components (int w, const int * cut, int ncut, std::vector<int> & label) const
  {
    const int * S = StarBegin(w);
    int m = StarSize(w);
    std::vector<int> uf(m);
    std::iota(uf.begin(), uf.end(), 0);
    auto is_cut = [&] (int x) { for (int i = 0; i < ncut; i++) if (cut[i] == x) return true; return false; };
    for (int i = 0; i < m; i++)
      {
        const int * Ti = &trigs[3*S[i]];
        int ki = Local(S[i], w);
        int ai = Ti[(ki+1)%3], bi = Ti[(ki+2)%3];
        for (int j = i+1; j < m; j++)
          {
            const int * Tj = &trigs[3*S[j]];
            for (int x : { ai, bi })
              if ((Tj[0] == x || Tj[1] == x || Tj[2] == x) && !is_cut(x))
                Unite(uf, i, j);
          }
      }
    // number components in order of their first (= smallest) triangle
    label.assign(m, -1);
    std::vector<int> rootlabel(m, -1);
    int nc = 0;
    for (int i = 0; i < m; i++)
      {
        int r = Find(uf, i);
        if (rootlabel[r] < 0) rootlabel[r] = nc++;
        label[i] = rootlabel[r];
      }
    return nc;
  }

  bool CrackSplitter :: SplitAt (int w, const int * cut, int ncut)
  {
    std::vector<int> label;
    int nc = Components(w, cut, ncut, label);
    if (nc <= 1) return false;
    std::vector<int> S(StarBegin(w), StarBegin(w) + StarSize(w));
    std::vector<std::vector<int>> groups(nc);
    for (size_t i = 0; i < S.size(); i++) groups[label[i]].push_back(S[i]);
    // group 0 (holding w's smallest triangle) keeps w, the others get new vertices
    for (int c = 1; c < nc; c++)
      {
        int nw = NV();
        parent.push_back(parent[w]);
        points.push_back(points[2*size_t(w)]);
        points.push_back(points[2*size_t(w)+1]);
        modified.push_back(1);
        for (int t : groups[c]) trigs[3*t + Local(t, w)] = nw;
        star_mod.push_back(std::move(groups[c]));
      }
    star_mod[w] = std::move(groups[0]);
    modified[w] = 1;
    return true;
  }

  void CrackSplitter :: CollectEdges (int v, const double * tdir)
  {
    edges.clear();
    const int * S = StarBegin(v);
    int m = StarSize(v);
    double px = points[2*size_t(v)], py = points[2*size_t(v)+1];
    for (int i = 0; i < m; i++)
      {
        int t = S[i];
        int k = Local(t, v);
        for (int x : { trigs[3*t+(k+1)%3], trigs[3*t+(k+2)%3] })
          {
            auto it = std::find_if(edges.begin(), edges.end(), [x] (const Edge & e) { return e.x == x; });
            if (it == edges.end())
              {
                double ex = points[2*size_t(x)] - px, ey = points[2*size_t(x)+1] - py;
                double len = std::hypot(ex, ey);
                // |cos| of the angle between the edge and the line orthogonal to the
                // maximum strain: larger is better
                double dot = len > 0 ? (ex*tdir[0] + ey*tdir[1]) / len : 0;
                double score = len > 0 ? std::fabs(dot) : -1;
                edges.push_back(Edge{x, 1, {t, -1}, score, dot, false, -1});
              }
            else
              {
                if (it->count < 2) it->t[it->count] = t;
                it->count++;
              }
          }
      }
  }

  int CrackSplitter :: NearestInterior (double sign) const
  {
    // as better(), on the signed cosine with the half-line sign * t
    int best = -1;
    for (size_t i = 0; i < edges.size(); i++)
      {
        const Edge & a = edges[i];
        if (a.count == 1) continue;
        if (best < 0) { best = int(i); continue; }
        const Edge & b = edges[best];
        if (sign * a.side != sign * b.side ? sign * a.side > sign * b.side : a.x < b.x) best = int(i);
      }
    return best;
  }

  int CrackSplitter :: NextOnBoundary (int cur, int prev) const
  {
    std::vector<std::pair<int,int>> seen;     // cur's neighbours and their triangle counts
    const int * S = StarBegin(cur);
    for (int i = 0, m = StarSize(cur); i < m; i++)
      {
        int t = S[i], l = Local(t, cur);
        for (int x : { trigs[3*t+(l+1)%3], trigs[3*t+(l+2)%3] })
          {
            auto it = std::find_if(seen.begin(), seen.end(), [x] (const std::pair<int,int> & e) { return e.first == x; });
            if (it == seen.end()) seen.push_back({x, 1}); else it->second++;
          }
      }
    // boundary neighbours: the far ends of edges in one triangle; two on a plain boundary
    int next = -1, once = 0;
    for (auto & e : seen)
      if (e.second == 1) { once++; if (e.first != prev) next = e.first; }
    return once == 2 ? next : -1;
  }

  bool CrackSplitter :: AimAnchor (int v, int a, int b, const double * h, double * anchor) const
  {
    // walk both lips from the tip together: on the crack their vertices are twins (bitwise
    // equal points); where they part (the mouth, a junction) the crack behind ends. The
    // anchor goes back while the tip lies within one tip edge of the line through it: beyond,
    // the crack turns there (the criterion's direction changed), and a line from before the
    // turn would exaggerate it. False where not even the second point behind qualifies.
    double px = points[2*size_t(v)], py = points[2*size_t(v)+1];
    double reach = std::hypot(points[2*size_t(a)] - px, points[2*size_t(a)+1] - py);
    int prev_a = v, prev_b = v;
    bool found = false;
    for (int step = 1; step < aim_edges; step++)
      {
        int na = NextOnBoundary(a, prev_a), nb = NextOnBoundary(b, prev_b);
        if (na < 0 || nb < 0 || na == nb || points[2*size_t(na)] != points[2*size_t(nb)] ||
            points[2*size_t(na)+1] != points[2*size_t(nb)+1])
          break;
        double qx = points[2*size_t(na)], qy = points[2*size_t(na)+1];
        if (std::fabs((px - qx) * h[1] - (py - qy) * h[0]) > reach) break;
        anchor[0] = qx; anchor[1] = qy;
        found = true;
        prev_a = a; prev_b = b; a = na; b = nb;
      }
    return found;
  }

  int CrackSplitter :: NearestToLine (int v, const double * anchor, const double * h) const
  {
    double px = points[2*size_t(v)], py = points[2*size_t(v)+1];
    int best = -1;
    double best_dist = 0;
    for (size_t i = 0; i < edges.size(); i++)
      {
        const Edge & e = edges[i];
        if (e.count == 1) continue;
        double ex = points[2*size_t(e.x)] - px, ey = points[2*size_t(e.x)+1] - py;
        double len = std::hypot(ex, ey);
        if (!(len > 0) || (ex*h[0] + ey*h[1]) < std::sqrt(0.5) * len) continue;     // 45 degrees or more off
        double dist = std::fabs((points[2*size_t(e.x)] - anchor[0]) * h[1] - (points[2*size_t(e.x)+1] - anchor[1]) * h[0]);
        if (best < 0 || dist < best_dist || (dist == best_dist && e.x < edges[best].x))
          { best = int(i); best_dist = dist; }
      }
    return best;
  }

  bool CrackSplitter :: IntoFan (int v, const double * d) const
  {
    const int * S = StarBegin(v);
    int m = StarSize(v);
    double px = points[2*size_t(v)], py = points[2*size_t(v)+1];
    for (int i = 0; i < m; i++)
      {
        int t = S[i];
        int k = Local(t, v);
        int a = trigs[3*t+(k+1)%3], b = trigs[3*t+(k+2)%3];
        double ax = points[2*size_t(a)] - px, ay = points[2*size_t(a)+1] - py;
        double bx = points[2*size_t(b)] - px, by = points[2*size_t(b)+1] - py;
        // counter-clockwise (v, a, b): d lies between a and b
        if (ax*d[1] - ay*d[0] >= 0 && d[0]*by - d[1]*bx >= 0) return true;
      }
    return false;
  }

  bool CrackSplitter :: ShareTriangle (int v, const Edge & a, const Edge & b) const
  {
    const int * S = StarBegin(v);
    int m = StarSize(v);
    auto has = [&] (const int * T, const Edge & e)
      {
        for (int k = 0; k < 3; k++)
          if (T[k] == e.x || (e.virt && T[k] == e.x2)) return true;
        return false;
      };
    for (int i = 0; i < m; i++)
      {
        const int * T = &trigs[3*S[i]];
        if (has(T, a) && has(T, b)) return true;
      }
    return false;
  }

  void CrackSplitter :: ProcessVertex (int v, const double * dir, double enter_angle, bool single_edge_tips)
  {
    int rule = 0;
    int nv_before = NV();
    std::vector<int> cuts;
    auto finish = [&] ()
      {
        rec_vertex.push_back(v);
        rec_rule.push_back(rule);
        rec_edge_begin.push_back(int(rec_edges.size()/2));
        for (int x : cuts) { rec_edges.push_back(v); rec_edges.push_back(x); }
        rec_new_begin.push_back(int(rec_new.size()));
        for (int w = nv_before; w < NV(); w++) rec_new.push_back(w);
      };

    std::vector<int> label;
    if (StarSize(v) == 0 || Components(v, nullptr, 0, label) != 1)
      { rule = RULE_NONE; finish(); return; }   // isolated or (input) pinched vertex

    double tdir[2] = { -dir[1], dir[0] };    // orthogonal to the maximum strain
    CollectEdges(v, tdir);

    std::vector<int> bnd;
    for (size_t i = 0; i < edges.size(); i++)
      if (edges[i].count == 1) bnd.push_back(int(i));
    bool tip = false;
    if (bnd.size() == 2)
      {
        const Edge & a = edges[bnd[0]], & b = edges[bnd[1]];
        // the two crack faces at a tip end in copies of one vertex: bitwise equal points
        tip = points[2*size_t(a.x)] == points[2*size_t(b.x)] &&
              points[2*size_t(a.x)+1] == points[2*size_t(b.x)+1];
      }

    // best candidate: largest score, ties by smaller far vertex id
    auto better = [] (const Edge & a, const Edge & b)
      { return a.score != b.score ? a.score > b.score : a.x < b.x; };

    if (tip && single_edge_tips)
      {
        rule |= RULE_TIP | RULE_TIP1;
        // the half of the crack line away from the crack: opposite to the crack faces
        double sign = edges[bnd[0]].side > 0 ? -1.0 : 1.0;
        int e1 = -1;
        double norm = std::hypot(tdir[0], tdir[1]);     // the caller's direction need not be unit
        double anchor[2], h[2] = { sign * tdir[0] / norm, sign * tdir[1] / norm };
        if (aim_edges > 0 && AimAnchor(v, edges[bnd[0]].x, edges[bnd[1]].x, h, anchor))
          e1 = NearestToLine(v, anchor, h);
        if (e1 < 0) e1 = NearestInterior(sign);
        if (e1 < 0) { rule |= RULE_NONE; finish(); return; }
        cuts.push_back(edges[e1].x);
      }
    else if (bnd.empty() || tip)
      {
        rule |= RULE_1;
        std::vector<Edge> cand;
        if (tip)
          {
            rule |= RULE_TIP;
            Edge a = edges[bnd[0]], b = edges[bnd[1]];
            Edge vtx = a;
            vtx.virt = true; vtx.x = std::min(a.x, b.x); vtx.x2 = std::max(a.x, b.x);
            cand.push_back(vtx);
            for (size_t i = 0; i < edges.size(); i++)
              if (edges[i].count != 1) cand.push_back(edges[i]);
          }
        else
          cand = edges;
        int e1 = -1;
        for (size_t i = 0; i < cand.size(); i++)
          if (e1 < 0 || better(cand[i], cand[e1])) e1 = int(i);
        // The crack runs through v: the second edge is the best one on the other side of
        // the line orthogonal to t (two edges on one side would cut out a wedge).
        auto opposite = [&] (int i) { return cand[i].side * cand[e1].side < 0; };
        int e2 = -1;
        for (size_t i = 0; i < cand.size(); i++)
          if (int(i) != e1 && opposite(i) && (e2 < 0 || better(cand[i], cand[e2]))) e2 = int(i);
        if (e2 >= 0 && ShareTriangle(v, cand[e1], cand[e2]))
          {
            // rule 1a: the two edges bound one triangle; take the best edge that does not
            rule |= RULE_1A;
            e2 = -1;
            for (size_t i = 0; i < cand.size(); i++)
              if (int(i) != e1 && opposite(i) && !ShareTriangle(v, cand[e1], cand[i]) &&
                  (e2 < 0 || better(cand[i], cand[e2])))
                e2 = int(i);
          }
        if (e2 < 0)
          // nothing admissible on the other side: the best edge not sharing a triangle
          for (size_t i = 0; i < cand.size(); i++)
            if (int(i) != e1 && !ShareTriangle(v, cand[e1], cand[i]) &&
                (e2 < 0 || better(cand[i], cand[e2])))
              e2 = int(i);
        if (e2 < 0) { rule |= RULE_NONE; finish(); return; }
        for (int e : { e1, e2 })
          if (!cand[e].virt) cuts.push_back(cand[e].x);
      }
    else
      {
        rule |= RULE_2;
        int e1 = -1;
        for (size_t i = 0; i < edges.size(); i++)
          if (e1 < 0 || better(edges[i], edges[e1])) e1 = int(i);
        if (edges[e1].count == 1 && enter_angle > 0)
          {
            // the crack line runs along the boundary here, or the vertex is a corner (a
            // notch tip) whose flank is best: the crack enters the body on the best
            // interior edge if that is within enter_angle of the line
            int e2 = -1;
            for (size_t i = 0; i < edges.size(); i++)
              if (edges[i].count != 1 && (e2 < 0 || better(edges[i], edges[e2]))) e2 = int(i);
            if (e2 >= 0 && edges[e2].score >= std::cos(enter_angle)) { e1 = e2; rule |= RULE_2C; }
          }
        if (edges[e1].count == 1 && enter_angle > 0)
          {
            // rule 2d: no interior edge near the line, but one half of it points into the body
            // clear of the surface (a concave corner with a coarse fan: its crack starts there
            // on the mesh's nearest edge; along a straight boundary both halves run along it)
            double px = points[2*size_t(v)], py = points[2*size_t(v)+1];
            int e2 = -1;
            for (double sign : { 1.0, -1.0 })
              {
                double h[2] = { sign * tdir[0], sign * tdir[1] };
                bool clear = IntoFan(v, h);
                for (int b : bnd)
                  {
                    double bx = points[2*size_t(edges[b].x)] - px, by = points[2*size_t(edges[b].x)+1] - py;
                    double len = std::hypot(bx, by);
                    if (len > 0 && (bx*h[0] + by*h[1]) / len > std::cos(enter_angle)) clear = false;
                  }
                if (clear) e2 = NearestInterior(sign);
              }
            if (e2 >= 0) { e1 = e2; rule |= RULE_2D; }
          }
        if (edges[e1].count == 1) { rule |= RULE_2A; finish(); return; }   // along the boundary: no split
        cuts.push_back(edges[e1].x);
      }

    bool ok = SplitAt(v, cuts.data(), int(cuts.size()));
    if (!ok)
      throw std::logic_error("ngfracture: internal error, vertex " + std::to_string(v) + " did not split");
    for (int x : cuts)
      if (SplitAt(x, nullptr, 0))
        rule |= (rule & RULE_2) ? RULE_2B : RULE_1B;
    finish();
  }

  void CrackSplitter :: Run (const int * order, const double * dirs, int n, bool skip_neighbours,
                              double enter_angle, bool single_edge_tips)
  {
    int nv_start = NV();
    std::vector<char> waits(skip_neighbours ? nv_start : 0, 0);
    for (int i = 0; i < n; i++)
      {
        int v = order[i];
        if (v < 0 || v >= nv_start)
          throw std::invalid_argument("ngfracture: vertex " + std::to_string(v) + " out of range [0, " +
                                      std::to_string(nv_start) + ")");
        double d[2] = { dirs[2*i], dirs[2*i+1] };
        if (!std::isfinite(d[0]) || !std::isfinite(d[1]) || (d[0] == 0 && d[1] == 0))
          throw std::invalid_argument("ngfracture: direction of vertex " + std::to_string(v) +
                                      " is zero or not finite");
        if (skip_neighbours && waits[v]) continue;
        int nv_before = NV();
        ProcessVertex(v, d, enter_angle, single_edge_tips);
        if (skip_neighbours && NV() > nv_before)
          // the triangles around v in the input mesh: their vertices wait for the next pass
          for (int k = star_off[v]; k < star_off[v+1]; k++)
            for (int j = 0; j < 3; j++)
              waits[parent[trigs[3*star_data[k] + j]]] = 1;
      }
  }

  void CrackSplitter :: Finish ()
  {
    int ns = int(segs0.size()/2);
    segs_new.resize(2*size_t(ns));
    for (int s = 0; s < ns; s++)
      {
        int t = seg_trig[s];
        if (t < 0) { segs_new[2*s] = segs0[2*s]; segs_new[2*s+1] = segs0[2*s+1]; continue; }
        segs_new[2*s] = trigs[3*t + seg_loc[2*s]];
        segs_new[2*s+1] = trigs[3*t + seg_loc[2*s+1]];
      }

    // new boundary edges can only touch vertices whose fan changed
    auto key = [] (int a, int b) { if (a > b) std::swap(a, b); return (uint64_t(uint32_t(a)) << 32) | uint32_t(b); };
    std::unordered_set<uint64_t> covered;
    for (int s = 0; s < ns; s++) covered.insert(key(segs_new[2*s], segs_new[2*s+1]));
    std::vector<int> cand;   // 3*t + k: edge from local k to k+1 of triangle t
    for (int u = 0; u < NV(); u++)
      {
        if (!modified[u]) continue;
        for (int t : star_mod[u])
          {
            int k = Local(t, u);
            cand.push_back(3*t + k);
            cand.push_back(3*t + (k+2)%3);
          }
      }
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    crack_segs.clear(); crack_seg_trig.clear();
    for (int c : cand)
      {
        int t = c / 3, k = c % 3;
        int a = trigs[3*t+k], b = trigs[3*t+(k+1)%3];
        int cnt = 0;
        const int * S = StarBegin(a);
        for (int i = 0; i < StarSize(a); i++)
          {
            const int * T = &trigs[3*S[i]];
            if (T[0] == b || T[1] == b || T[2] == b) cnt++;
          }
        if (cnt != 1 || covered.count(key(a, b))) continue;
        const int * T = &trigs[3*t];
        double area2 = (points[2*T[1]]-points[2*T[0]]) * (points[2*T[2]+1]-points[2*T[0]+1])
                     - (points[2*T[2]]-points[2*T[0]]) * (points[2*T[1]+1]-points[2*T[0]+1]);
        if (area2 < 0) std::swap(a, b);   // keep the triangle on the segment's left
        crack_segs.push_back(a); crack_segs.push_back(b);
        crack_seg_trig.push_back(t);
      }

    // fragments: pieces never touch at a single vertex, so sharing a vertex is enough
    std::vector<int> uf(NV());
    std::iota(uf.begin(), uf.end(), 0);
    for (int t = 0; t < ne; t++)
      {
        Unite(uf, trigs[3*t], trigs[3*t+1]);
        Unite(uf, trigs[3*t], trigs[3*t+2]);
      }
    std::vector<int> number(NV(), -1);
    fragment.resize(ne);
    nfragments = 0;
    for (int t = 0; t < ne; t++)
      {
        int r = Find(uf, trigs[3*t]);
        if (number[r] < 0) number[r] = nfragments++;
        fragment[t] = number[r];
      }
  }
}
