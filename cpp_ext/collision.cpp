// Collision detection (paper section 3.1) and contact selection (section 3.2, rules 1-4).
#include "collision.hpp"
#include "predicates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <unordered_map>

namespace ngfracture
{
  namespace
  {
    // Strictly inside a counter-clockwise triangle.
    inline bool StrictlyInside (const double * t[3], const double * v)
    {
      return Orient2dSign(t[0], t[1], v) > 0 && Orient2dSign(t[1], t[2], v) > 0
        && Orient2dSign(t[2], t[0], v) > 0;
    }

    // Segments (p0,p1) and (q0,q1) cross at a single point interior to both.
    inline bool ProperCrossing (const double * p0, const double * p1,
                                const double * q0, const double * q1)
    {
      int s1 = Orient2dSign(p0, p1, q0), s2 = Orient2dSign(p0, p1, q1);
      if (s1 * s2 >= 0) return false;
      int s3 = Orient2dSign(q0, q1, p0), s4 = Orient2dSign(q0, q1, p1);
      return s3 * s4 < 0;
    }

    // The edge line (e0,e1) of a CCW triangle weakly separates it from triangle o:
    // no vertex of o lies strictly on the inner side.
    inline bool Separates (const double * e0, const double * e1, const double * o[3])
    {
      return Orient2dSign(e0, e1, o[0]) <= 0 && Orient2dSign(e0, e1, o[1]) <= 0
        && Orient2dSign(e0, e1, o[2]) <= 0;
    }

    inline double PointSegmentDistance (const double * p, const double * a, const double * b)
    {
      double dx = b[0]-a[0], dy = b[1]-a[1];
      double px = p[0]-a[0], py = p[1]-a[1];
      double l2 = dx*dx + dy*dy;
      double t = l2 > 0 ? std::clamp((px*dx + py*dy) / l2, 0.0, 1.0) : 0.0;
      double rx = px - t*dx, ry = py - t*dy;
      return std::sqrt(rx*rx + ry*ry);
    }
  }

  bool InteriorsOverlap (const double * p_in[3], const double * q_in[3])
  {
    int op = Orient2dSign(p_in[0], p_in[1], p_in[2]);
    int oq = Orient2dSign(q_in[0], q_in[1], q_in[2]);
    if (op == 0 || oq == 0) return false;          // no interior
    // Work on counter-clockwise copies: elements may be inverted in the current state.
    const double * p[3] = { p_in[0], op > 0 ? p_in[1] : p_in[2], op > 0 ? p_in[2] : p_in[1] };
    const double * q[3] = { q_in[0], oq > 0 ? q_in[1] : q_in[2], oq > 0 ? q_in[2] : q_in[1] };

    // The paper's 6 vertex-in-triangle tests decide most overlaps at once.
    for (int i = 0; i < 3; i++)
      if (StrictlyInside(p, q[i]) || StrictlyInside(q, p[i])) return true;
    // The 9 edge-edge tests catch crossings without a vertex inside.
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        if (ProperCrossing(p[i], p[(i+1)%3], q[j], q[(j+1)%3])) return true;
    // Left: degenerate contacts (vertices on edges, collinear edges, identical
    // triangles) that strict tests cannot classify. Two convex polygons have disjoint
    // interiors iff one of their edge lines weakly separates them (separating axis
    // theorem); with exact signs this decides every remaining case.
    for (int i = 0; i < 3; i++)
      if (Separates(p[i], p[(i+1)%3], q) || Separates(q[i], q[(i+1)%3], p)) return false;
    return true;
  }

  bool TrianglesCollide (const double * p[3], const double * q[3], double tol)
  {
    if (InteriorsOverlap(p, q)) return true;
    if (!(tol > 0)) return false;
    // A flat triangle may lie inside the other one: distance zero.
    for (int swap = 0; swap < 2; swap++)
      {
        const double ** t = swap ? q : p, ** o = swap ? p : q;
        int ot = Orient2dSign(t[0], t[1], t[2]);
        if (ot != 0)
          for (int i = 0; i < 3; i++)
            if (ot * Orient2dSign(t[0], t[1], o[i]) >= 0 && ot * Orient2dSign(t[1], t[2], o[i]) >= 0
                && ot * Orient2dSign(t[2], t[0], o[i]) >= 0)
              return true;
      }
    // Disjoint interiors, neither inside the other: the distance is attained between a
    // vertex and an edge.
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        if (PointSegmentDistance(p[i], q[j], q[(j+1)%3]) <= tol
            || PointSegmentDistance(q[i], p[j], p[(j+1)%3]) <= tol)
          return true;
    return false;
  }

  std::vector<std::array<int32_t,2>>
  CollisionPairs (const TriangleSoup & soup, const uint8_t * candidate,
                  const int32_t * fragment, double tol, bool narrow, double * bin_size_out)
  {
    std::vector<std::array<int32_t,2>> pairs;
    if (bin_size_out) *bin_size_out = 0;
    std::vector<int32_t> cand;
    for (int64_t i = 0; i < soup.nt; i++)
      if (candidate[i]) cand.push_back(int32_t(i));
    size_t n = cand.size();
    if (n < 2) return pairs;                        // no work without candidates

    const double * x = soup.x;
    const int32_t * T = soup.tris;
    double half = 0.5 * std::max(tol, 0.0);
    std::vector<double> box(4*n), cen(2*n);
    double extent = 0;
    double cmin[2] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
    double cmax[2] = { -cmin[0], -cmin[1] };
    for (size_t k = 0; k < n; k++)
      {
        const int32_t * t = T + 3*cand[k];
        for (int d = 0; d < 2; d++)
          {
            double v0 = x[2*t[0]+d], v1 = x[2*t[1]+d], v2 = x[2*t[2]+d];
            double lo = std::min({v0, v1, v2}) - half, hi = std::max({v0, v1, v2}) + half;
            box[4*k+d] = lo; box[4*k+2+d] = hi;
            extent = std::max(extent, hi - lo);
            double c = (v0 + v1 + v2) / 3.0;
            cen[2*k+d] = c;
            cmin[d] = std::min(cmin[d], c); cmax[d] = std::max(cmax[d], c);
          }
      }
    // Bin size: if two (inflated) boxes of extent <= W overlap, their centroids differ
    // by at most 2W per axis, so with h >= 2W the centroid bins differ by at most one
    // in each direction and the 3x3 neighbourhood is complete. The factor 1 + 1e-9
    // absorbs rounding of centroids and of (c - cmin) / h.
    double h = 2.0 * extent * (1.0 + 1e-9);
    double range = std::max(cmax[0] - cmin[0], cmax[1] - cmin[1]);
    if (!(h > 0)) h = 1.0;
    // Keep bin indices in 31 bits; coarser bins stay correct, only slower.
    h = std::max(h, range / double(1 << 30));
    if (bin_size_out) *bin_size_out = h;

    // Bins by hashing (ix, iy): memory and time linear in the number of candidates,
    // whatever the extent of the domain.
    auto key = [] (int64_t ix, int64_t iy) { return (uint64_t(ix) << 32) | uint64_t(uint32_t(iy)); };
    std::unordered_map<uint64_t, int32_t> bin_of;
    bin_of.reserve(2*n);
    std::vector<int32_t> bin(n), bix, biy;
    for (size_t k = 0; k < n; k++)
      {
        int64_t ix = int64_t(std::floor((cen[2*k] - cmin[0]) / h));
        int64_t iy = int64_t(std::floor((cen[2*k+1] - cmin[1]) / h));
        auto [it, fresh] = bin_of.try_emplace(key(ix, iy), int32_t(bix.size()));
        if (fresh) { bix.push_back(int32_t(ix)); biy.push_back(int32_t(iy)); }
        bin[k] = it->second;
      }
    size_t nb = bix.size();
    std::vector<int32_t> start(nb+1, 0), members(n);
    for (size_t k = 0; k < n; k++) start[bin[k]+1]++;
    for (size_t b = 0; b < nb; b++) start[b+1] += start[b];
    {
      std::vector<int32_t> fill(start.begin(), start.end()-1);
      for (size_t k = 0; k < n; k++) members[fill[bin[k]]++] = int32_t(k);
    }

    auto test = [&] (int32_t k, int32_t l)
    {
      if (box[4*k] > box[4*l+2] || box[4*l] > box[4*k+2]
          || box[4*k+1] > box[4*l+3] || box[4*l+1] > box[4*k+3]) return;
      int32_t i = cand[k], j = cand[l];
      const int32_t * ti = T + 3*i, * tj = T + 3*j;
      // Mesh neighbours touch by construction: adjacency is not overlap.
      if (!fragment || fragment[i] == fragment[j])
        for (int a = 0; a < 3; a++)
          for (int b = 0; b < 3; b++)
            if (ti[a] == tj[b]) return;
      if (narrow)
        {
          const double * p[3] = { x + 2*ti[0], x + 2*ti[1], x + 2*ti[2] };
          const double * q[3] = { x + 2*tj[0], x + 2*tj[1], x + 2*tj[2] };
          if (!TrianglesCollide(p, q, tol)) return;
        }
      pairs.push_back({ std::min(i, j), std::max(i, j) });
    };

    // Sweep: each bin against itself and the half-stencil right, lower, lower-right
    // and upper-right. The paper's three neighbours miss the anti-diagonal pairs
    // (centroids in bins (ix, iy) and (ix+1, iy-1)); with the fourth, every unordered
    // pair of neighbouring bins is visited exactly once.
    static const int off[4][2] = { {1, 0}, {0, 1}, {1, 1}, {1, -1} };
    for (size_t b = 0; b < nb; b++)
      {
        for (int32_t s = start[b]; s < start[b+1]; s++)
          for (int32_t t = s+1; t < start[b+1]; t++)
            test(members[s], members[t]);
        for (auto & o : off)
          {
            auto it = bin_of.find(key(int64_t(bix[b]) + o[0], int64_t(biy[b]) + o[1]));
            if (it == bin_of.end()) continue;
            int32_t nb2 = it->second;
            for (int32_t s = start[b]; s < start[b+1]; s++)
              for (int32_t t = start[nb2]; t < start[nb2+1]; t++)
                test(members[s], members[t]);
          }
      }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
  }

  std::vector<ContactCandidate>
  SelectContacts (const TriangleSoup & soup, const uint8_t * bmask,
                  const int32_t * pairs, int64_t npairs, double tol, double angle_tol,
                  double xi_snap)
  {
    std::vector<ContactCandidate> out;
    const double * x = soup.x;
    const int32_t * T = soup.tris;
    // Slaves already constrained by an earlier pair: among equally deep nodes the others
    // go first, so that a corner triangle with two penetrating nodes (which meets only one
    // triangle of the other body) still gets both constrained across its pairs.
    std::vector<char> used(soup.nv, 0);
    for (int64_t pi = 0; pi < npairs; pi++)
      for (int dir = 0; dir < 2; dir++)
        {
          // Rule 1: per overlapping pair at most one constraint with each element as
          // master, hence at most two per pair.
          int32_t M = pairs[2*pi + dir], S = pairs[2*pi + 1 - dir];
          const int32_t * tm = T + 3*M, * ts = T + 3*S;
          // Outward unit normals of the master's edges (reference orientation: the
          // master is on the left of t[k] -> t[k+1]; an element inverted in the current
          // state would get inward normals, but inversion is the elasticity's failure,
          // not a contact configuration).
          double nrm[3][2], len[3];
          for (int k = 0; k < 3; k++)
            {
              const double * xa = x + 2*tm[k], * xc = x + 2*tm[(k+1)%3];
              double d0 = xc[0]-xa[0], d1 = xc[1]-xa[1];
              len[k] = std::sqrt(d0*d0 + d1*d1);
              nrm[k][0] = len[k] > 0 ? d1/len[k] : 0.0;
              nrm[k][1] = len[k] > 0 ? -d0/len[k] : 0.0;
            }
          double scale = std::max({len[0], len[1], len[2]});
          ContactCandidate cand[3];
          int ncand = 0;
          for (int m = 0; m < 3; m++)
            {
              int32_t b = ts[m];
              const double * xb = x + 2*b;
              // Rule 2: master segments are boundary (or crack) edges; the node's
              // distance to the master is that of its nearest way out through one of
              // them (largest signed distance among edges it projects onto).
              // Outward boundary normal of the slave body at b (sum over the slave's
              // boundary edges at b): a master edge must face it. Without this a node at
              // the corner of an overlap picks the outer edge it lies on (gap 0).
              double ns[2] = { 0.0, 0.0 };
              for (int e : { m, (m+2)%3 })
                if (bmask[3*S + e])
                  {
                    const double * p0 = x + 2*ts[e], * p1 = x + 2*ts[(e+1)%3];
                    double l = std::hypot(p1[0]-p0[0], p1[1]-p0[1]);
                    if (l > 0) { ns[0] += (p1[1]-p0[1])/l; ns[1] += -(p1[0]-p0[0])/l; }
                  }
              int kbest = -1; double dbest = 0, xibest = 0;
              for (int k = 0; k < 3; k++)
                {
                  if (!bmask[3*M + k] || !(len[k] > 0)) continue;
                  if (nrm[k][0]*ns[0] + nrm[k][1]*ns[1] >= 0 && (ns[0] != 0 || ns[1] != 0))
                    continue;
                  int32_t a = tm[k], c = tm[(k+1)%3];
                  if (b == a || b == c) continue;
                  const double * xa = x + 2*a, * xc = x + 2*c;
                  // eq. 13: x'_b = xi x_a + (1 - xi) x_c, (x'_b - x_b) . (x_a - x_c) = 0
                  double xi = ((xb[0]-xc[0])*(xa[0]-xc[0]) + (xb[1]-xc[1])*(xa[1]-xc[1]))
                    / (len[k]*len[k]);
                  double slack = tol / len[k];
                  if (xi < -slack || xi > 1.0 + slack) continue;
                  double dist = (xb[0]-xa[0])*nrm[k][0] + (xb[1]-xa[1])*nrm[k][1];
                  // Deeper than the master's height over this edge: the node has gone
                  // past the element, this edge is not its way out. (A node may sit in
                  // a neighbour of the master that touches the boundary only at a vertex:
                  // no need to lie inside the master itself.)
                  const double * xo = x + 2*tm[(k+2)%3];
                  double height = -((xo[0]-xa[0])*nrm[k][0] + (xo[1]-xa[1])*nrm[k][1]);
                  if (dist <= -std::abs(height) * (1.0 - 1e-9)) continue;
                  if (kbest < 0 || dist > dbest)
                    { kbest = k; dbest = dist; xibest = std::clamp(xi, 0.0, 1.0); }
                }
              if (kbest < 0 || dbest > tol) continue;   // threshold: negative = penetration
              auto & cc = cand[ncand++];
              cc.slave = b; cc.a = tm[kbest]; cc.c = tm[(kbest+1)%3];
              cc.master_tri = M; cc.slave_tri = S; cc.pair = int32_t(pi);
              cc.xi = xibest; cc.n[0] = nrm[kbest][0]; cc.n[1] = nrm[kbest][1];
              cc.dist = dbest;
              // Rule 3 angle: between the master segment and the slave's two edges at b.
              double angle = M_PI;
              for (int e = 1; e <= 2; e++)
                {
                  const double * xe = x + 2*ts[(m+e)%3];
                  double v[2] = { xe[0]-xb[0], xe[1]-xb[1] };
                  double lv = std::sqrt(v[0]*v[0] + v[1]*v[1]);
                  if (!(lv > 0)) continue;
                  // |v . t| with t the unit tangent (n rotated back)
                  double cs = std::min(1.0, std::abs(-v[0]*cc.n[1] + v[1]*cc.n[0]) / lv);
                  angle = std::min(angle, std::acos(cs));
                }
              cc.angle = angle;
            }
          if (ncand == 0) continue;                     // rule 4
          // Rule 2: the nearest (most penetrating) node. Rule 3: nodes equally near,
          // within the precision threshold (at least 1e-12 of the element size), are
          // ranked: not yet constrained first, then by angle, then by depth; the chosen
          // angle must not exceed angle_tol.
          double dmin = cand[0].dist;
          for (int i = 1; i < ncand; i++) dmin = std::min(dmin, cand[i].dist);
          double window = std::max(tol, 1e-12 * scale);
          int best = -1;
          auto key = [&] (int i) { return std::make_tuple(used[cand[i].slave], cand[i].angle, cand[i].dist); };
          for (int i = 0; i < ncand; i++)
            {
              if (cand[i].dist > dmin + window) continue;
              if (best < 0 || key(i) < key(best)) best = i;
            }
          if (cand[best].angle > angle_tol) continue;   // rule 3 threshold, then rule 4
          auto & cb = cand[best];
          used[cb.slave] = 1;
          // A (near) node-to-node constraint also covers the partner node: the other
          // direction of the pair then prefers a node not yet in contact.
          if (cb.xi <= xi_snap) used[cb.c] = 1;
          if (cb.xi >= 1.0 - xi_snap) used[cb.a] = 1;
          out.push_back(cb);
        }
    return out;
  }
}
