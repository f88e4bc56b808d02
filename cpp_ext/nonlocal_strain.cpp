#include "nonlocal_strain.hpp"
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace ngfracture
{
  using namespace ngcomp;

  namespace
  {
    struct Mesh2
    {
      std::vector<double> x, y;                     // vertex coordinates
      std::vector<std::array<int,3>> tri;           // counter-clockwise triangles
      std::vector<std::array<int,3>> nb;            // neighbour across the edge opposite local vertex i (-1: boundary)
      std::vector<int> vt_begin, vt;                // vertex -> triangles (CSR)
    };

    Mesh2 Extract (const MeshAccess & ma)
    {
      Mesh2 m;
      size_t nv = ma.GetNV(), ne = ma.GetNE(VOL);
      m.x.resize(nv); m.y.resize(nv);
      for (size_t v = 0; v < nv; v++)
        {
          auto p = ma.GetPoint<2>(v);
          m.x[v] = p(0); m.y[v] = p(1);
        }
      m.tri.resize(ne);
      std::vector<int> count(nv + 1, 0);
      for (size_t e = 0; e < ne; e++)
        {
          auto verts = ma.GetElement(ElementId(VOL, e)).Vertices();
          if (verts.Size() != 3)
            throw Exception("ngfracture.NonlocalOpening: element " + ToString(e) + " is not a triangle");
          std::array<int,3> t = { int(verts[0]), int(verts[1]), int(verts[2]) };
          double area = (m.x[t[1]]-m.x[t[0]])*(m.y[t[2]]-m.y[t[0]]) - (m.x[t[2]]-m.x[t[0]])*(m.y[t[1]]-m.y[t[0]]);
          if (area < 0) std::swap(t[1], t[2]);
          m.tri[e] = t;
          for (int v : t) count[v+1]++;
        }
      for (size_t v = 0; v < nv; v++) count[v+1] += count[v];
      m.vt_begin = count;
      m.vt.resize(count[nv]);
      std::vector<int> fill(count.begin(), count.end() - 1);
      for (size_t e = 0; e < ne; e++)
        for (int v : m.tri[e]) m.vt[fill[v]++] = int(e);
      // neighbours: the other triangle holding both ends of an edge (shared vertex numbers:
      // crack faces have their own vertices, so a crack is a boundary here)
      m.nb.resize(ne);
      for (size_t e = 0; e < ne; e++)
        for (int i = 0; i < 3; i++)
          {
            int a = m.tri[e][(i+1)%3], b = m.tri[e][(i+2)%3];
            int other = -1;
            for (int k = m.vt_begin[a]; k < m.vt_begin[a+1]; k++)
              {
                int f = m.vt[k];
                if (f == int(e)) continue;
                auto & g = m.tri[f];
                if (g[0] == b || g[1] == b || g[2] == b) { other = f; break; }
              }
            m.nb[e][i] = other;
          }
      return m;
    }

    // Barycentric coordinates of (px, py) in triangle t.
    std::array<double,3> Bary (const Mesh2 & m, int t, double px, double py)
    {
      auto & v = m.tri[t];
      double x0 = m.x[v[0]], y0 = m.y[v[0]], x1 = m.x[v[1]], y1 = m.y[v[1]], x2 = m.x[v[2]], y2 = m.y[v[2]];
      double det = (x1-x0)*(y2-y0) - (x2-x0)*(y1-y0);
      double l1 = ((px-x0)*(y2-y0) - (x2-x0)*(py-y0)) / det;
      double l2 = ((x1-x0)*(py-y0) - (px-x0)*(y1-y0)) / det;
      return { 1.0 - l1 - l2, l1, l2 };
    }

    // Opening component n.T.n of the interpolated nodal tensor at barycentric point lam of t.
    double Opening (const Mesh2 & m, FlatMatrix<double> T, int t, const std::array<double,3> & lam,
                    double nx, double ny)
    {
      double xx = 0, yy = 0, xy = 0;
      for (int i = 0; i < 3; i++)
        {
          int v = m.tri[t][i];
          xx += lam[i] * T(v,0); yy += lam[i] * T(v,1); xy += lam[i] * T(v,2);
        }
      return nx*nx*xx + ny*ny*yy + 2*nx*ny*xy;
    }

    // Smallest opening value along the segment of length l from vertex v in direction
    // (dx, dy). l = r, or up to the boundary (a free surface, a crack face) when the ray
    // meets it first. From a sharp tip (tip = true) the walk looks on to 2r, and a ray that
    // meets the boundary at a distance s < 2r is judged over l = s/2: a section thinner than
    // 2r ahead of a tip is judged on its near half. For a linear stress profile (a ligament
    // in tension and bending) the value at s/2 is the net-section stress, which the bending
    // part cannot hide; a tip's segment still reaches its first edge crossing or r,
    // whichever is nearer. The vertex's own value only interpolates inside the first
    // triangle. samples: scratch space. False if the direction points out of the body at v
    // (or the walk does not end).
    bool RayMinimum (const Mesh2 & m, FlatMatrix<double> T, int v, double dx, double dy, double r,
                     bool tip, std::vector<std::pair<double,double>> & samples, double & result)
    {
      const double px = m.x[v], py = m.y[v];
      const double reach = tip ? 2 * r : r;
      const double qx = px + reach*dx, qy = py + reach*dy;
      const double nx = -dy, ny = dx;
      // the triangle of v's fan whose corner at v holds the direction
      int t = -1;
      for (int k = m.vt_begin[v]; k < m.vt_begin[v+1] && t < 0; k++)
        {
          int f = m.vt[k];
          auto & g = m.tri[f];
          int i = g[0] == v ? 0 : (g[1] == v ? 1 : 2);
          int b = g[(i+1)%3], c = g[(i+2)%3];
          double bx = m.x[b]-px, by = m.y[b]-py, cx = m.x[c]-px, cy = m.y[c]-py;
          // counter-clockwise (v, b, c): d lies between b - v and c - v
          if (bx*dy - by*dx >= 0 && dx*cy - dy*cx >= 0) t = f;
        }
      if (t < 0) return false;
      // samples (distance, opening) at the start, the edge crossings and the end of the
      // walk; the field is linear between two consecutive ones (they bound one triangle)
      samples.clear();
      samples.emplace_back(0.0, Opening(m, T, t, Bary(m, t, px, py), nx, ny));
      double surface = std::numeric_limits<double>::infinity();
      // excluded edges: for the first triangle the two through v, later the entry edge
      int entered_from = -1;
      int steps_left = 100000;
      while (true)
        {
          if (steps_left-- <= 0) return false;
          auto l0 = Bary(m, t, px, py), l1 = Bary(m, t, qx, qy);
          double t_out = std::numeric_limits<double>::infinity();
          int exit_edge = -1;
          for (int i = 0; i < 3; i++)
            {
              if (entered_from < 0 && m.tri[t][i] != v) continue;          // first triangle: only the edge opposite v
              if (entered_from >= 0 && m.nb[t][i] == entered_from) continue;
              double dl = l1[i] - l0[i];
              if (dl >= 0) continue;
              double s = -l0[i] / dl;
              if (s < t_out) { t_out = s; exit_edge = i; }
            }
          if (exit_edge < 0 || t_out >= 1.0)
            {
              samples.emplace_back(reach, Opening(m, T, t, l1, nx, ny));
              break;
            }
          std::array<double,3> lx;
          for (int i = 0; i < 3; i++) lx[i] = l0[i] + t_out * (l1[i] - l0[i]);
          samples.emplace_back(t_out * reach, Opening(m, T, t, lx, nx, ny));
          int next = m.nb[t][exit_edge];
          if (next < 0) { surface = t_out * reach; break; }
          entered_from = t;
          t = next;
        }
      // a thin section's segment still reaches the first edge crossing (or r)
      const double length = tip ? std::max(std::min(r, 0.5 * surface), std::min(r, samples[1].first))
                                : std::min(r, surface);
      double best = std::numeric_limits<double>::infinity();
      for (size_t k = 1; k < samples.size(); k++)    // the start (v's own value) only interpolates
        {
          auto [d, val] = samples[k];
          if (d <= length) { best = std::min(best, val); continue; }
          // the end of the segment lies between samples k-1 and k
          auto [d0, v0] = samples[k-1];
          double w = (length - d0) / (d - d0);
          best = std::min(best, v0 + w * (val - v0));
          break;
        }
      result = best;
      return true;
    }
  }

  namespace
  {
    // Largest principal value of the nodal tensor at every vertex.
    double LocalValue (FlatMatrix<double> T, int v)
    {
      return 0.5*(T(v,0)+T(v,1)) + hypot(0.5*(T(v,0)-T(v,1)), T(v,2));
    }

    // Sharp tips: boundary vertices whose corner angle inside the body is at least
    // SHARP_ANGLE, crack tips (360 degrees) and sharp notch tips. Their strain is singular,
    // they are the stress concentrations from which the critical distance is measured.
    constexpr double SHARP_ANGLE = 300.0 * M_PI / 180.0;

    std::vector<char> SharpTips (const Mesh2 & m)
    {
      size_t nv = m.x.size();
      std::vector<double> angle(nv, 0.0);
      std::vector<char> boundary(nv, 0);
      for (size_t e = 0; e < m.tri.size(); e++)
        for (int i = 0; i < 3; i++)
          {
            int a = m.tri[e][i], b = m.tri[e][(i+1)%3], c = m.tri[e][(i+2)%3];
            double bx = m.x[b]-m.x[a], by = m.y[b]-m.y[a], cx = m.x[c]-m.x[a], cy = m.y[c]-m.y[a];
            angle[a] += std::atan2(bx*cy - by*cx, bx*cx + by*cy);
            if (m.nb[e][i] < 0) { boundary[b] = 1; boundary[c] = 1; }
          }
      std::vector<char> sharp(nv, 0);
      for (size_t v = 0; v < nv; v++)
        sharp[v] = boundary[v] && angle[v] >= SHARP_ANGLE;
      return sharp;
    }

    // A sharp tip's own field reaches farther than r: the opening stress of the mode-I
    // singular field across a line parallel to the crack is largest at 60 degrees from it,
    // 3 sqrt(3)/4 times its value straight ahead at the same distance, so a vertex within
    // (3 sqrt(3)/4)^2 r = 27/16 r of the tip can see more than the tip's own measure. That
    // is the tip's field seen from the side, not a concentration of its own.
    constexpr double TIP_ZONE = 27.0 / 16.0;

    // v is a hot spot when it is a sharp tip, or when no sharp tip lies within TIP_ZONE r
    // and v leads every vertex within distance r, both counted among the vertices the mesh
    // connects to v inside those disks: the larger local value leads, ties to the smaller
    // vertex number. Every sharp tip is judged (each is a stress concentration of its own,
    // and one that cannot split must not silence another); the one-ring value of a vertex
    // near a tip is an average over the singular field, not the field's size.
    bool HotSpot (const Mesh2 & m, FlatMatrix<double> T, const std::vector<char> & sharp, int v, double r,
                  std::vector<int> & mark, std::vector<int> & queue)
    {
      if (sharp[v]) return true;
      const double lv = LocalValue(T, v);
      const double r2 = r * r;
      const double zone2 = TIP_ZONE * TIP_ZONE * r2;
      queue.clear();
      queue.push_back(v);
      mark[v] = v;
      for (size_t q = 0; q < queue.size(); q++)
        {
          int w = queue[q];
          for (int k = m.vt_begin[w]; k < m.vt_begin[w+1]; k++)
            for (int u : m.tri[m.vt[k]])
              {
                if (mark[u] == v) continue;
                mark[u] = v;
                double dx = m.x[u]-m.x[v], dy = m.y[u]-m.y[v];
                double d2 = dx*dx + dy*dy;
                if (d2 > zone2) continue;
                if (sharp[u]) return false;
                if (d2 <= r2)
                  {
                    double lu = LocalValue(T, u);
                    if (lu > lv || (lu == lv && u < v)) return false;
                  }
                queue.push_back(u);
              }
        }
      return true;
    }
  }

  void NonlocalOpening (const MeshAccess & ma, FlatMatrix<double> T, FlatVector<double> radius,
                        int ndir, FlatMatrix<double> result)
  {
    size_t nv = ma.GetNV();
    if (T.Height() != nv || T.Width() != 3)
      throw Exception("ngfracture.NonlocalOpening: tensors must be nv x 3 = " + ToString(nv) + " x 3");
    if (radius.Size() != nv)
      throw Exception("ngfracture.NonlocalOpening: radius must have one entry per vertex");
    if (result.Height() != nv || result.Width() != 3)
      throw Exception("ngfracture.NonlocalOpening: result must be nv x 3");
    if (ndir < 8)
      throw Exception("ngfracture.NonlocalOpening: need at least 8 directions");
    Mesh2 m = Extract(ma);
    const double dtheta = 2 * M_PI / ndir;
    std::vector<double> value(ndir);
    std::vector<char> ok(ndir);
    std::vector<int> mark(nv, -1), queue;
    std::vector<std::pair<double,double>> samples;
    const std::vector<char> sharp = SharpTips(m);
    // Serial: deterministic, and a few ms per 10k vertices at r = 4h.
    for (size_t v = 0; v < nv; v++)
      {
        result(v,0) = result(v,1) = result(v,2) = 0.0;
        if (!(radius[v] > 0) || m.vt_begin[v] == m.vt_begin[v+1]) continue;
        if (!HotSpot(m, T, sharp, int(v), radius[v], mark, queue)) continue;
        int kbest = -1;
        for (int k = 0; k < ndir; k++)
          {
            // half-step offset: no ray starts exactly along the x axis, where meshes
            // of straight cracks have their edges
            double th = (k + 0.5) * dtheta;
            ok[k] = RayMinimum(m, T, int(v), cos(th), sin(th), radius[v], sharp[v], samples, value[k]);
            if (ok[k] && (kbest < 0 || value[k] > value[kbest])) kbest = k;
          }
        if (kbest < 0) continue;
        // parabola through the best direction and its neighbours: the angle and value of
        // the maximum between the sampled directions
        double th = (kbest + 0.5) * dtheta, val = value[kbest];
        int km = (kbest + ndir - 1) % ndir, kp = (kbest + 1) % ndir;
        if (ok[km] && ok[kp])
          {
            double a = value[km], b = value[kbest], c = value[kp];
            double curv = a - 2*b + c;
            if (curv < 0)
              {
                double delta = std::clamp(0.5 * (a - c) / curv, -0.5, 0.5);
                th += delta * dtheta;
                val = b - 0.25 * (a - c) * delta;
              }
          }
        double nx = -sin(th), ny = cos(th);   // opening direction: perpendicular to the ray
        result(v,0) = val * nx * nx;
        result(v,1) = val * ny * ny;
        result(v,2) = val * nx * ny;
      }
  }
}
