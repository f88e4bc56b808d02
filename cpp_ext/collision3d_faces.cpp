// The master faces of the 3D collision detection: the face each hit vertex is pushed
// back through (collision3d_parts.hpp).
#include "collision3d_parts.hpp"

namespace ngfracture
{
  using detect3d::Sub;
  using detect3d::Dot;
  using detect3d::Dist2;

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
}

namespace ngfracture::detect3d
{
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

  namespace
  {
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
    // other side of a crack or of an interface of bodies meshed apart); with `on` >= 0, one
    // on fragment `on` (ffrag: the fragment of every boundary face).
    bool IsLip (const TetMesh3 & m, const Copies & copies, const VertexFaces & vfaces, int32_t f,
                const std::vector<int32_t> & ffrag, int32_t on)
    {
      const int32_t * T = m.faces + 3*f;
      const std::array<int32_t,3> pts = copies.FacePoints(T);
      int32_t g = copies.group[T[0]];
      for (int64_t s = copies.start[g]; s < copies.start[g+1]; s++)
        for (int64_t i = vfaces.start[copies.members[s]]; i < vfaces.start[copies.members[s]+1]; i++)
          {
            int32_t h = vfaces.at[i];
            if (h != f && (on < 0 || ffrag[h] == on) && copies.FacePoints(m.faces + 3*h) == pts) return true;
          }
      return false;
    }
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
    // (IsLip; with `lips_on` >= 0, lips whose other side is on that fragment), and only one
    // that v is behind is returned (see the caller). With `tet`
    // null, the candidates are the faces at t of every tetrahedron that v is behind
    // (lips only with `lips_of`; see the caller).
    int32_t SeparatingFace (const TetMesh3 & m, const VertexFaces & vfaces, const Topology & topo,
                            int32_t v, int32_t t, const int32_t * tet, double & depth,
                            const Copies * lips_of, int32_t lips_on)
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
          if (lips_only ? !IsLip(m, *lips_of, vfaces, f, topo.ffrag, lips_on) : (tet && !StarOnSide(m, topo, v, nref, 1.0))) continue;
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

  namespace
  {
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
