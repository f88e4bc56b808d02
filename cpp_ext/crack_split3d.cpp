#include "crack_split3d.hpp"
#include "star_mincut.hpp"
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <string>

namespace ngfracture
{
  namespace
  {
    // the face opposite local vertex c, in the order whose normal points out of a
    // positively oriented tetrahedron
    const int OUT[4][3] = { { 1, 2, 3 }, { 0, 3, 2 }, { 0, 1, 3 }, { 0, 2, 1 } };

    // The minimum cut of a star (docs/solid.md, "Node splitting in 3D"). Capacity of an
    // interior face (v, a, b): area * (1 + CUT_ALPHA * max(|d_a|, |d_b|) / h), d the
    // distance from the plane, h the mean edge length at v: the new front vertices a, b
    // (split next) stay near the plane. A face that would make the crack branch (a
    // vertex of it inside an existing crack, with no front edge, or an edge of it on
    // crack faces other than a front edge's two lips) costs CUT_BRANCH times more.
    // Tetrahedra holding a crack face with |cos(normal, n)| >= CUT_FIX_COS are fixed to
    // the side the face puts them on.
    const double CUT_ALPHA = 5.0;
    const double CUT_BRANCH = 10.0;
    const double CUT_FIX_COS = 0.2;

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
    bool SameCycle (const int8_t * l, const int * o)
    {
      for (int r = 0; r < 3; r++)
        if (l[0] == o[r] && l[1] == o[(r+1)%3] && l[2] == o[(r+2)%3]) return true;
      return false;
    }
    const long long LOW = 0xffffffffLL;
  }

  TetSplitter :: TetSplitter (const double * apoints, int anv, const int * atets, int ane,
                              const int * faces, const int * afbc, int nf, int acrack_bc)
    : nv0(anv), ne(ane), crack_bc(acrack_bc), points(apoints, apoints + 3*size_t(anv)),
      tets(atets, atets + 4*size_t(ane))
  {
    for (size_t i = 0; i < tets.size(); i++)
      if (tets[i] < 0 || tets[i] >= nv0)
        throw std::invalid_argument("ngfracture: tetrahedron " + std::to_string(i/4) + " has vertex " +
                                    std::to_string(tets[i]) + " outside [0, " + std::to_string(nv0) + ")");
    parent.resize(nv0);
    std::iota(parent.begin(), parent.end(), 0);
    modified.assign(nv0, 0);
    star_mod.resize(nv0);
    star_off.assign(nv0+1, 0);
    for (int v : tets) star_off[v+1]++;
    for (int v = 0; v < nv0; v++) star_off[v+1] += star_off[v];
    star_data.resize(tets.size());
    std::vector<int> fill(star_off.begin(), star_off.end()-1);
    for (int t = 0; t < ne; t++)
      for (int k = 0; k < 4; k++) star_data[fill[tets[4*t+k]]++] = t;

    // the owner of every face: a tetrahedron holding its three vertices, the one it points
    // out of if there are two (an interface)
    tet_bc.assign(4*size_t(ne), 0);
    face_tet.assign(nf, -1);
    face_loc.assign(3*size_t(nf), -1);
    face_bc.assign(afbc, afbc + nf);
    for (int f = 0; f < nf; f++)
      {
        const int * F = faces + 3*size_t(f);
        for (int j = 0; j < 3; j++)
          if (F[j] < 0 || F[j] >= nv0)
            throw std::invalid_argument("ngfracture: face " + std::to_string(f) + " has vertex " +
                                        std::to_string(F[j]) + " outside [0, " + std::to_string(nv0) + ")");
        int owner_c = -1;
        for (int s = star_off[F[0]]; s < star_off[F[0]+1]; s++)
          {
            int t = star_data[s];
            int8_t l[3];
            for (int j = 0; j < 3; j++) { l[j] = -1; for (int k = 0; k < 4; k++) if (tets[4*t+k] == F[j]) l[j] = int8_t(k); }
            if (l[1] < 0 || l[2] < 0) continue;
            int c = 6 - l[0] - l[1] - l[2];
            bool out = SameCycle(l, OUT[c]);
            if (face_tet[f] < 0 || out)
              {
                face_tet[f] = t; owner_c = c;
                std::copy(l, l+3, &face_loc[3*size_t(f)]);
              }
            if (out) break;
          }
        if (face_tet[f] < 0)
          throw std::invalid_argument("ngfracture: boundary face " + std::to_string(f) +
                                      " is not a face of any tetrahedron");
        tet_bc[4*size_t(face_tet[f]) + owner_c] = face_bc[f];
      }
  }

  const int * TetSplitter :: StarBegin (int v) const
  { return modified[v] ? star_mod[v].data() : star_data.data() + star_off[v]; }

  int TetSplitter :: StarSize (int v) const
  { return modified[v] ? int(star_mod[v].size()) : star_off[v+1] - star_off[v]; }

  int TetSplitter :: Local (int t, int v) const
  {
    const int * T = &tets[4*size_t(t)];
    for (int k = 0; k < 4; k++) if (T[k] == v) return k;
    throw std::logic_error("ngfracture: vertex not in its star's tetrahedron");
  }

  void TetSplitter :: BuildLink (int v)
  {
    lv = v;
    S.assign(StarBegin(v), StarBegin(v) + StarSize(v));
    le.clear();
    for (int i = 0; i < int(S.size()); i++)
      {
        const int * T = &tets[4*size_t(S[i])];
        int kv = Local(S[i], v);
        for (int c = 0; c < 4; c++)
          {
            if (c == kv) continue;
            int ab[2], n = 0;
            for (int k = 0; k < 4; k++) if (k != kv && k != c) ab[n++] = T[k];
            le.push_back({ std::min(ab[0], ab[1]), std::max(ab[0], ab[1]), i, c });
          }
      }
    std::sort(le.begin(), le.end(), [] (const LinkEdge & x, const LinkEdge & y)
              { return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.i < y.i); });
    partner.assign(le.size(), -1);
    for (size_t k = 0; k + 1 < le.size(); k++)
      if (le[k].a == le[k+1].a && le[k].b == le[k+1].b)
        { partner[k] = int(k+1); partner[k+1] = int(k); k++; }
  }

  int TetSplitter :: Components (const std::vector<int> & label, int side, std::vector<int> & comp) const
  {
    int m = int(S.size());
    std::vector<int> uf(m);
    std::iota(uf.begin(), uf.end(), 0);
    for (size_t e = 0; e < le.size(); e++)
      {
        int p = partner[e];
        if (p < int(e)) continue;
        int i = le[e].i, j = le[p].i;
        if (side < 0 || (label[i] == side && label[j] == side)) Unite(uf, i, j);
      }
    comp.assign(m, -1);
    std::vector<int> root(m, -1);
    int nc = 0;
    for (int i = 0; i < m; i++)      // numbered in the order of their smallest tetrahedron
      {
        if (side >= 0 && label[i] != side) continue;
        int r = Find(uf, i);
        if (root[r] < 0) root[r] = nc++;
        comp[i] = root[r];
      }
    return nc;
  }

  std::vector<long long> TetSplitter :: SlitEnds (const std::vector<int> & label,
                                                 std::vector<std::array<int,2>> * pairs) const
  {
    // (part, a, b, link edge) for the boundary link edges of every part, both directions
    std::vector<std::array<int,4>> h;
    for (size_t e = 0; e < le.size(); e++)
      {
        int p = partner[e], part = label[le[e].i];
        if (p >= 0 && label[le[p].i] == part) continue;
        h.push_back({ part, le[e].a, le[e].b, int(e) });
        h.push_back({ part, le[e].b, le[e].a, int(e) });
      }
    std::sort(h.begin(), h.end());
    std::vector<long long> ends;
    for (size_t s = 0; s < h.size(); )
      {
        size_t e = s;
        while (e < h.size() && h[e][0] == h[s][0] && h[e][1] == h[s][1]) e++;
        bool slit = false;
        for (size_t x = s; x < e && !slit; x++)
          for (size_t y = x+1; y < e && !slit; y++)
            if (h[x][2] != h[y][2] &&
                std::memcmp(&points[3*size_t(h[x][2])], &points[3*size_t(h[y][2])], 3*sizeof(double)) == 0)
              {
                slit = true;
                if (pairs) pairs->push_back({ h[x][3], h[y][3] });
              }
        if (slit) ends.push_back((long long)(h[s][0]) << 32 | h[s][1]);
        s = e;
      }
    return ends;
  }

  double TetSplitter :: FaceAlignment (int e, const double * n) const
  {
    const int * T = &tets[4*size_t(S[le[e].i])];
    const double * x[3];
    for (int j = 0; j < 3; j++) x[j] = &points[3*size_t(T[OUT[le[e].c][j]])];
    double u[3], w[3], c[3];
    for (int d = 0; d < 3; d++) { u[d] = x[1][d] - x[0][d]; w[d] = x[2][d] - x[0][d]; }
    c[0] = u[1]*w[2] - u[2]*w[1]; c[1] = u[2]*w[0] - u[0]*w[2]; c[2] = u[0]*w[1] - u[1]*w[0];
    double len = std::sqrt(c[0]*c[0] + c[1]*c[1] + c[2]*c[2]) * std::sqrt(n[0]*n[0] + n[1]*n[1] + n[2]*n[2]);
    return len > 0 ? (c[0]*n[0] + c[1]*n[1] + c[2]*n[2]) / len : 0.0;
  }

  double TetSplitter :: StarSolidAngle () const
  {
    const double * o = &points[3*size_t(lv)];
    double sum = 0;
    for (int t : S)
      {
        double a[3][3], len[3];
        int j = 0;
        for (int k = 0; k < 4; k++)
          {
            int w = tets[4*size_t(t)+k];
            if (w == lv) continue;
            for (int d = 0; d < 3; d++) a[j][d] = points[3*size_t(w)+d] - o[d];
            len[j] = std::sqrt(a[j][0]*a[j][0] + a[j][1]*a[j][1] + a[j][2]*a[j][2]);
            j++;
          }
        double det = a[0][0] * (a[1][1]*a[2][2] - a[1][2]*a[2][1]) - a[0][1] * (a[1][0]*a[2][2] - a[1][2]*a[2][0])
                     + a[0][2] * (a[1][0]*a[2][1] - a[1][1]*a[2][0]);
        auto dot = [&] (int p, int q) { return a[p][0]*a[q][0] + a[p][1]*a[q][1] + a[p][2]*a[q][2]; };
        // Van Oosterom and Strackee: tan(Omega / 2) = |det| / (l0 l1 l2 + (a0.a1) l2 + (a0.a2) l1 + (a1.a2) l0)
        double den = len[0]*len[1]*len[2] + dot(0, 1) * len[2] + dot(0, 2) * len[1] + dot(1, 2) * len[0];
        sum += 2 * std::atan2(std::abs(det), den);
      }
    return sum;
  }

  void TetSplitter :: SeedLips (const std::vector<std::array<int,2>> & pairs, const double * n,
                                std::vector<int> & side) const
  {
    // the two lips at a front edge go to opposite sides: the tetrahedron whose lip points
    // along n (it lies below the crack) to the minus side; ties: the smaller tetrahedron
    for (auto & pr : pairs)
      {
        double s = FaceAlignment(pr[0], n);
        int i0 = le[pr[0]].i, i1 = le[pr[1]].i;
        bool first_below = s > 0 || (s == 0 && S[i0] < S[i1]);
        side[i0] = first_below ? 0 : 1;
        side[i1] = first_below ? 1 : 0;
      }
  }

  void TetSplitter :: SplitGroups (const std::vector<int> & label, int ngroups)
  {
    std::vector<std::vector<int>> groups(ngroups);
    for (size_t i = 0; i < S.size(); i++) groups[label[i]].push_back(S[i]);
    for (int g = 1; g < ngroups; g++)
      {
        int nw = NV();
        parent.push_back(parent[lv]);
        for (int d = 0; d < 3; d++) points.push_back(points[3*size_t(lv)+d]);
        modified.push_back(1);
        for (int t : groups[g]) tets[4*size_t(t) + Local(t, lv)] = nw;
        star_mod.push_back(std::move(groups[g]));
        rec_new.push_back(nw);
      }
    star_mod[lv] = std::move(groups[0]);
    modified[lv] = 1;
  }

  bool TetSplitter :: SplitPieces (int w)
  {
    BuildLink(w);
    std::vector<int> comp;
    int nc = Components({}, -1, comp);
    if (nc <= 1) return false;
    SplitGroups(comp, nc);
    return true;
  }

  double TetSplitter :: Anchor (const double * n, const std::vector<std::array<int,2>> & pairs) const
  {
    // signed offset (along unit n) of the plane of the cut
    double nn = std::sqrt(n[0]*n[0] + n[1]*n[1] + n[2]*n[2]);
    auto dot = [&] (const double * y) { return (y[0]*n[0] + y[1]*n[1] + y[2]*n[2]) / nn; };
    if (pairs.empty()) return dot(&points[3*size_t(lv)]);
    // on a front: the mean offset of the crack faces in the stars of v and its link
    // vertices, weighted by their area projected on the plane (the crack continues at the
    // level of the crack around it, not at the level of the front vertex)
    std::vector<int> verts = { lv };
    for (auto & e : le) { verts.push_back(e.a); verts.push_back(e.b); }
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    std::vector<long long> keys;
    for (int w : verts)
      for (const int * t = StarBegin(w); t != StarBegin(w) + StarSize(w); t++)
        for (int c = 0; c < 4; c++)
          if (tet_bc[4*size_t(*t) + c] == crack_bc) keys.push_back(4LL * *t + c);
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    double sw = 0, sd = 0;
    for (long long k : keys)
      {
        const int * T = &tets[4*size_t(k/4)];
        int c = int(k % 4);
        const double * x[3];
        for (int j = 0; j < 3; j++) x[j] = &points[3*size_t(T[OUT[c][j]])];
        double u[3], w[3], cr[3], cen[3];
        for (int d = 0; d < 3; d++) { u[d] = x[1][d] - x[0][d]; w[d] = x[2][d] - x[0][d]; cen[d] = (x[0][d] + x[1][d] + x[2][d]) / 3; }
        cr[0] = u[1]*w[2] - u[2]*w[1]; cr[1] = u[2]*w[0] - u[0]*w[2]; cr[2] = u[0]*w[1] - u[1]*w[0];
        double wt = std::abs(cr[0]*n[0] + cr[1]*n[1] + cr[2]*n[2]) / nn;   // projected area
        sw += wt; sd += wt * dot(cen);
      }
    return sw > 0 ? sd / sw : dot(&points[3*size_t(lv)]);
  }

  int TetSplitter :: Classify (const double * n, double offset, std::vector<int> & side) const
  {
    // the side of the plane (x . n = offset) that holds the tetrahedron's centroid
    double nn = std::sqrt(n[0]*n[0] + n[1]*n[1] + n[2]*n[2]);
    int n1 = 0;
    side.assign(S.size(), 0);
    for (size_t i = 0; i < S.size(); i++)
      {
        double d = 0;
        for (int k = 0; k < 4; k++)
          {
            const double * y = &points[3*size_t(tets[4*size_t(S[i])+k])];
            d += (y[0]*n[0] + y[1]*n[1] + y[2]*n[2]) / nn - offset;
          }
        side[i] = d > 0;
        n1 += side[i];
      }
    return n1;
  }

  void TetSplitter :: CutSides (const double * n, double offset, const std::vector<std::array<int,2>> & pairs,
                                std::vector<int> & side) const
  {
    std::vector<int> lverts;
    for (auto & e : le) { lverts.push_back(e.a); lverts.push_back(e.b); }
    std::sort(lverts.begin(), lverts.end());
    lverts.erase(std::unique(lverts.begin(), lverts.end()), lverts.end());
    std::vector<char> closed(lverts.size(), 0);
    for (size_t k = 0; k < lverts.size(); k++) closed[k] = ClosedCrackVertex(lverts[k]);
    auto is_closed = [&] (int w) { return closed[std::lower_bound(lverts.begin(), lverts.end(), w) - lverts.begin()] != 0; };
    double nn = std::sqrt(n[0]*n[0] + n[1]*n[1] + n[2]*n[2]);
    auto dist = [&] (int w) { const double * y = &points[3*size_t(w)];
                              return (y[0]*n[0] + y[1]*n[1] + y[2]*n[2]) / nn - offset; };
    int m = int(S.size());
    const double * xv = &points[3*size_t(lv)];
    double h = 0;
    for (auto & e : le)
      for (int w : { e.a, e.b })
        {
          const double * y = &points[3*size_t(w)];
          h += std::sqrt((y[0]-xv[0])*(y[0]-xv[0]) + (y[1]-xv[1])*(y[1]-xv[1]) + (y[2]-xv[2])*(y[2]-xv[2]));
        }
    h /= 2.0 * le.size();
    const double tol = 1e-12 * h;
    MinCut g(m);
    // terminals: tetrahedra wholly on one side (their vertices other than v)
    std::vector<double> cen(m, 0.0);
    int kv_plus = -1, kv_minus = -1;
    bool plus = false, minus = false;
    for (int i = 0; i < m; i++)
      {
        double lo = 0, hi = 0;
        for (int k = 0; k < 4; k++)
          {
            int w = tets[4*size_t(S[i])+k];
            double d = dist(w);
            cen[i] += d;
            if (w == lv) continue;
            if (std::abs(d) <= tol) d = 0;
            lo = std::min(lo, d); hi = std::max(hi, d);
          }
        if (lo == 0 && hi > 0) { g.Fix(i, 1); plus = true; }
        else if (hi == 0 && lo < 0) { g.Fix(i, 0); minus = true; }
        if (kv_plus < 0 || cen[i] > cen[kv_plus]) kv_plus = i;
        if (kv_minus < 0 || cen[i] < cen[kv_minus]) kv_minus = i;
      }
    if (!plus) g.Fix(kv_plus, 1);
    if (!minus) g.Fix(kv_minus, 0);
    // tetrahedra holding a crack face well aligned with the plane: on the side the face
    // puts them (below the crack if its outward normal points along n)
    for (int i = 0; i < m; i++)
        for (int c = 0; c < 4; c++)
          if (tet_bc[4*size_t(S[i]) + c] == crack_bc)
            {
              const int * T = &tets[4*size_t(S[i])];
              const double * x[3];
              for (int j = 0; j < 3; j++) x[j] = &points[3*size_t(T[OUT[c][j]])];
              double u[3], w[3], cr[3];
              for (int d = 0; d < 3; d++) { u[d] = x[1][d] - x[0][d]; w[d] = x[2][d] - x[0][d]; }
              cr[0] = u[1]*w[2] - u[2]*w[1]; cr[1] = u[2]*w[0] - u[0]*w[2]; cr[2] = u[0]*w[1] - u[1]*w[0];
              double cs = (cr[0]*n[0] + cr[1]*n[1] + cr[2]*n[2]) / (std::sqrt(cr[0]*cr[0] + cr[1]*cr[1] + cr[2]*cr[2]) * nn);
              if (std::abs(cs) >= CUT_FIX_COS) g.Fix(i, cs > 0 ? 0 : 1);
            }
    // the lips at front edges: fixed to opposite sides
    std::vector<int> lips(m, -1);
    SeedLips(pairs, n, lips);
    for (int i = 0; i < m; i++) if (lips[i] >= 0) g.Fix(i, lips[i]);
    // interior faces at v: area, growing with the distance of their far vertices from the plane
    for (size_t e = 0; e < le.size(); e++)
      {
        int p = partner[e];
        if (p < int(e)) continue;
        const int * T = &tets[4*size_t(S[le[e].i])];
        const double * x[3];
        for (int j = 0; j < 3; j++) x[j] = &points[3*size_t(T[OUT[le[e].c][j]])];
        double u[3], w[3], cr[3];
        for (int d = 0; d < 3; d++) { u[d] = x[1][d] - x[0][d]; w[d] = x[2][d] - x[0][d]; }
        cr[0] = u[1]*w[2] - u[2]*w[1]; cr[1] = u[2]*w[0] - u[0]*w[2]; cr[2] = u[0]*w[1] - u[1]*w[0];
        double area = 0.5 * std::sqrt(cr[0]*cr[0] + cr[1]*cr[1] + cr[2]*cr[2]);
        double da = std::abs(dist(le[e].a)), db = std::abs(dist(le[e].b));
        double cap = area * (1 + CUT_ALPHA * std::max(da, db) / h);
        if ((is_closed(le[e].a) || is_closed(le[e].b) || CrackEdge(le[e].a, le[e].b) ||
                              CrackEdge(lv, le[e].a) || CrackEdge(lv, le[e].b)))
          cap *= CUT_BRANCH;
        g.AddEdge(le[e].i, le[p].i, cap);
      }
    double value;
    side = g.Solve(value);
  }

  bool TetSplitter :: ClosedCrackVertex (int a) const
  {
    // crack faces at a as (x, y, face) for both edges (a, x) of every face (a, x, y)
    std::vector<std::array<int,3>> h;
    const int * st = StarBegin(a);
    for (int s = 0; s < StarSize(a); s++)
      {
        const int * T = &tets[4*size_t(st[s])];
        for (int c = 0; c < 4; c++)
          {
            if (T[c] == a || tet_bc[4*size_t(st[s]) + c] != crack_bc) continue;
            int xy[2], k = 0;
            for (int j = 0; j < 4; j++) if (j != c && T[j] != a) xy[k++] = T[j];
            h.push_back({ xy[0], xy[1], 0 });
            h.push_back({ xy[1], xy[0], 0 });
          }
      }
    if (h.empty()) return false;
    std::sort(h.begin(), h.end());
    // a front edge (a, x): two crack faces whose third vertices are distinct copies of one point
    for (size_t s = 0; s < h.size(); )
      {
        size_t e = s;
        while (e < h.size() && h[e][0] == h[s][0]) e++;
        for (size_t x = s; x < e; x++)
          for (size_t y = x+1; y < e; y++)
            if (h[x][1] != h[y][1] &&
                std::memcmp(&points[3*size_t(h[x][1])], &points[3*size_t(h[y][1])], 3*sizeof(double)) == 0)
              return false;
        s = e;
      }
    return true;
  }

  bool TetSplitter :: CrackEdge (int p, int q) const
  {
    // crack faces (p, q, x): true if there is one and they are not exactly the two lips of
    // a front edge (third vertices distinct copies of one point)
    int third[3], k = 0;
    const int * st = StarBegin(p);
    for (int s = 0; s < StarSize(p); s++)
      {
        const int * T = &tets[4*size_t(st[s])];
        int kp = -1, kq = -1;
        for (int j = 0; j < 4; j++) { if (T[j] == p) kp = j; if (T[j] == q) kq = j; }
        if (kq < 0) continue;
        for (int c = 0; c < 4; c++)
          if (c != kp && c != kq && tet_bc[4*size_t(st[s]) + c] == crack_bc)
            {
              if (k == 2) return true;
              third[k++] = T[6 - kp - kq - c];
            }
      }
    if (k != 2) return k > 0;
    return third[0] == third[1] ||
      std::memcmp(&points[3*size_t(third[0])], &points[3*size_t(third[1])], 3*sizeof(double)) != 0;
  }

  bool TetSplitter :: SmallPiece (const std::vector<int> & side) const
  {
    // the faces between the sides, blocked; a side whose tetrahedra reach fewer than
    // |star| tetrahedra of the mesh through unblocked shared faces is a pocket
    std::vector<long long> blocked;
    for (size_t e = 0; e < le.size(); e++)
      {
        int p = partner[e];
        if (p >= 0 && side[le[e].i] != side[le[p].i]) blocked.push_back(4LL * S[le[e].i] + le[e].c);
      }
    std::sort(blocked.begin(), blocked.end());
    size_t limit = S.size();
    for (int s = 0; s < 2; s++)
      {
        int start = -1;
        for (size_t i = 0; i < S.size() && start < 0; i++) if (side[i] == s) start = S[i];
        if (start < 0) continue;
        std::vector<int> seen = { start };
        for (size_t q = 0; q < seen.size() && seen.size() < limit; q++)
          {
            int t = seen[q];
            const int * T = &tets[4*size_t(t)];
            for (int c = 0; c < 4; c++)
              {
                if (std::binary_search(blocked.begin(), blocked.end(), 4LL * t + c)) continue;
                int x[3];
                for (int j = 0; j < 3; j++) x[j] = T[OUT[c][j]];
                const int * st = StarBegin(x[0]);
                for (int k = 0; k < StarSize(x[0]); k++)
                  {
                    int u = st[k];
                    if (u == t) continue;
                    const int * U = &tets[4*size_t(u)];
                    int hit = 0;
                    for (int j = 0; j < 4; j++) hit += (U[j] == x[1]) + (U[j] == x[2]);
                    if (hit < 2) continue;
                    if (std::find(seen.begin(), seen.end(), u) == seen.end()) seen.push_back(u);
                    break;
                  }
              }
          }
        if (seen.size() < limit) return true;
      }
    return false;
  }

  bool TetSplitter :: Connect (std::vector<int> & side) const
  {
    // both sides connected: a part cut off from its side's largest part changes side
    int m = int(S.size());
    bool moved = false;
    std::vector<int> comp;
    for (int s = 0; s < 2; s++)
      {
        int k = Components(side, s, comp);
        if (k <= 1) continue;
        std::vector<int> count(k, 0);
        for (int i = 0; i < m; i++) if (comp[i] >= 0) count[comp[i]]++;
        int main = int(std::max_element(count.begin(), count.end()) - count.begin());   // first of the largest
        for (int i = 0; i < m; i++) if (comp[i] >= 0 && comp[i] != main) side[i] = 1 - s;
        moved = true;
      }
    return moved;
  }

  int TetSplitter :: RefuseReason (const std::vector<int> & side, const std::vector<long long> & before,
                                   int & after) const
  {
    // both sides hold tetrahedra: the cut and Connect can move every tetrahedron to one
    // side, which would leave a copy of v in no tetrahedron
    long long n1 = std::count(side.begin(), side.end(), 1);
    if (n1 == 0 || n1 == (long long)side.size()) return SPLIT3_EMPTY;
    // on v's boundary (free surface or crack), both sides reach it: the new faces do not
    // close a cone around v
    bool boundary = false, reach[2] = { false, false };
    for (size_t e = 0; e < le.size(); e++)
      if (partner[e] < 0) { boundary = true; reach[side[le[e].i]] = true; }
    if (boundary && !(reach[0] && reach[1])) return SPLIT3_ENCLOSED;
    auto ends = SlitEnds(side, nullptr);
    after = int(ends.size());
    for (long long k : ends)
      {
        bool old = false;
        for (long long b : before) old = old || ((b & LOW) == (k & LOW));
        if (!old) return SPLIT3_DANGLING;
      }
    return 0;
  }

  void TetSplitter :: AddFace (int t, int c)
  {
    face_tet.push_back(t);
    for (int j = 0; j < 3; j++) face_loc.push_back(int8_t(OUT[c][j]));
    face_bc.push_back(crack_bc);
    tet_bc[4*size_t(t) + c] = crack_bc;
  }

  int TetSplitter :: ChooseSides (const double * n, double offset, const std::vector<std::array<int,2>> & pairs,
                                  const std::vector<long long> & slit, std::vector<int> & side,
                                  int & after, bool & moved) const
  {
    // the minimum cut first, the centroid sides (given in side) if the cut is refused;
    // each made connected, then checked against the refusals
    std::vector<int> centroid = side;
    CutSides(n, offset, pairs, side);
    int refuse = 0;
    for (int attempt = 0; attempt < 2; attempt++)
      {
        if (attempt) side = centroid;
        moved = Connect(side);
        refuse = RefuseReason(side, slit, after);
        if (!refuse && SmallPiece(side)) refuse = SPLIT3_POCKET;
        if (!refuse) break;
      }
    return refuse;
  }

  int TetSplitter :: ProcessVertex (int v, const double * n, int & nfaces, int & before, int & after)
  {
    nfaces = before = after = 0;
    BuildLink(v);
    int m = int(S.size());
    if (m == 0) return SPLIT3_NONE;
    std::vector<int> comp, side;
    int nc = Components({}, -1, comp);
    if (nc > 1) { SplitGroups(comp, nc); return SPLIT3_PINCHED; }
    int flags = 0;
    for (size_t e = 0; e < le.size(); e++)
      if (partner[e] < 0)
        flags |= tet_bc[4*size_t(S[le[e].i]) + le[e].c] == crack_bc ? SPLIT3_CRACK : SPLIT3_SURFACE;
    std::vector<std::array<int,2>> pairs;
    auto slit = SlitEnds(std::vector<int>(m, 0), &pairs);
    before = after = int(slit.size());
    if (before) flags |= SPLIT3_FRONT;
    else if (flags)
      {
        // on a surface (free or crack) away from fronts: if a boundary face at v is better
        // aligned with the crack plane than every interior face, nothing is split (rule 2a):
        // the crack would peel the surface. Not at a re-entrant edge or corner (the star's
        // solid angle above 2 pi by more than a curved surface's): there the plane along one
        // of its faces runs on into the body, as a crack from a slot's root corner does
        bool reentrant = StarSolidAngle() > 2.25 * M_PI;
        double best_in = -1, best_bnd = -1;
        for (size_t e = 0; e < le.size(); e++)
          {
            if (partner[e] >= 0 && partner[e] < int(e)) continue;
            double al = std::abs(FaceAlignment(int(e), n));
            (partner[e] < 0 ? best_bnd : best_in) = std::max(partner[e] < 0 ? best_bnd : best_in, al);
          }
        if (best_bnd > best_in && !reentrant) return flags | SPLIT3_NONE | SPLIT3_ALIGNED;
      }
    double offset = Anchor(n, pairs);
    Classify(n, offset, side);
    SeedLips(pairs, n, side);
    int n1 = int(std::count(side.begin(), side.end(), 1));
    if (n1 == 0 || n1 == m) return flags | SPLIT3_NONE | SPLIT3_EMPTY;
    bool moved = false;
    int refuse = ChooseSides(n, offset, pairs, slit, side, after, moved);
    if (moved) flags |= SPLIT3_MOVED;
    if (refuse) { after = before; return flags | SPLIT3_NONE | refuse; }
    // the faces between the sides become crack faces, both lips; the side of the smallest
    // tetrahedron (entry 0) first
    std::vector<int> far;
    for (size_t e = 0; e < le.size(); e++)
      {
        int p = partner[e];
        if (p < int(e) || side[le[e].i] == side[le[p].i]) continue;
        int first = side[le[e].i] == side[0] ? int(e) : p, second = first == int(e) ? p : int(e);
        AddFace(S[le[first].i], le[first].c);
        AddFace(S[le[second].i], le[second].c);
        far.push_back(le[e].a); far.push_back(le[e].b);
        nfaces++;
      }
    std::vector<int> label(m);
    for (int i = 0; i < m; i++) label[i] = side[i] != side[0];
    SplitGroups(label, 2);
    flags |= SPLIT3_CUT;
    if (before && !after) flags |= SPLIT3_CLOSED;
    // a vertex of the new faces whose star fell apart is split per piece
    std::sort(far.begin(), far.end());
    far.erase(std::unique(far.begin(), far.end()), far.end());
    for (int w : far)
      if (SplitPieces(w)) flags |= SPLIT3_FAR;
    return flags;
  }

  bool TetSplitter :: NextToSplit (int v, const std::vector<char> & split_input) const
  {
    // the vertices of v's tetrahedra are the vertices sharing an edge with v; a copy of a
    // split vertex has the same input vertex (parent)
    const int * st = StarBegin(v);
    for (int s = 0; s < StarSize(v); s++)
      for (int k = 0; k < 4; k++)
        {
          int w = tets[4*size_t(st[s]) + k];
          if (w != v && split_input[parent[w]]) return true;
        }
    return false;
  }

  void TetSplitter :: Run (const int * order, const double * dirs, int n, bool first_only, bool skip_neighbours)
  {
    std::vector<char> split_input(skip_neighbours ? nv0 : 0, 0);   // input vertices split in this run
    for (int k = 0; k < n; k++)
      {
        int v = order[k];
        if (v < 0 || v >= NV())
          throw std::invalid_argument("ngfracture: vertex " + std::to_string(v) + " (entry " + std::to_string(k) +
                                      ") outside [0, " + std::to_string(NV()) + ")");
        const double * d = dirs + 3*size_t(k);
        if (!(std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2])) || (d[0] == 0 && d[1] == 0 && d[2] == 0))
          throw std::invalid_argument("ngfracture: the direction of vertex " + std::to_string(v) +
                                      " (entry " + std::to_string(k) + ") is zero or not finite");
        if (skip_neighbours && NextToSplit(v, split_input)) { skipped.push_back(v); continue; }
        rec_vertex.push_back(v);
        rec_new_begin.push_back(int(rec_new.size()));
        int nf, before, after;
        int flags = ProcessVertex(v, d, nf, before, after);
        rec_flags.push_back(flags);
        rec_faces.push_back(nf);
        rec_fronts_before.push_back(before);
        rec_fronts_after.push_back(after);
        bool split = (flags & (SPLIT3_CUT | SPLIT3_PINCHED)) != 0;
        if (skip_neighbours && split) split_input[parent[v]] = 1;
        if (first_only && split) break;
      }
    rec_new_begin.push_back(int(rec_new.size()));
  }

  std::vector<int> TetSplitter :: Faces () const
  {
    std::vector<int> out(3*face_tet.size());
    for (size_t f = 0; f < face_tet.size(); f++)
      for (int j = 0; j < 3; j++)
        out[3*f+j] = tets[4*size_t(face_tet[f]) + face_loc[3*f+j]];
    return out;
  }

  std::vector<int> TetSplitter :: Pinched ()
  {
    std::vector<int> out, comp;
    for (int v = 0; v < NV(); v++)
      {
        BuildLink(v);
        if (!S.empty() && Components({}, -1, comp) > 1) out.push_back(v);
      }
    return out;
  }

  int TetComponents (const int * tets, int ne, int nv, std::vector<int> & fragment)
  {
    std::vector<std::array<int,4>> keys;
    keys.reserve(4*size_t(ne));
    for (int t = 0; t < ne; t++)
      for (int c = 0; c < 4; c++)
        {
          std::array<int,4> k;
          int n = 0;
          for (int j = 0; j < 4; j++)
            if (j != c)
              {
                int x = tets[4*size_t(t)+j];
                if (x < 0 || x >= nv)
                  throw std::invalid_argument("ngfracture: tetrahedron " + std::to_string(t) + " has vertex " +
                                              std::to_string(x) + " outside [0, " + std::to_string(nv) + ")");
                k[n++] = x;
              }
          std::sort(k.begin(), k.begin()+3);
          k[3] = t;
          keys.push_back(k);
        }
    std::sort(keys.begin(), keys.end());
    std::vector<int> uf(ne);
    std::iota(uf.begin(), uf.end(), 0);
    for (size_t i = 0; i + 1 < keys.size(); i++)
      if (keys[i][0] == keys[i+1][0] && keys[i][1] == keys[i+1][1] && keys[i][2] == keys[i+1][2])
        Unite(uf, keys[i][3], keys[i+1][3]);
    fragment.assign(ne, -1);
    std::vector<int> root(ne, -1);
    int nc = 0;
    for (int t = 0; t < ne; t++)
      {
        int r = Find(uf, t);
        if (root[r] < 0) root[r] = nc++;
        fragment[t] = root[r];
      }
    return nc;
  }
}
