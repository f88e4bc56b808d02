#include "nonlocal_strain3d.hpp"
#include <algorithm>
#include <cmath>
#include <limits>

namespace ngfracture
{
  using namespace ngcomp;

  namespace
  {
    using V3 = std::array<double,3>;
    using S6 = std::array<double,6>;    // xx yy zz yz xz xy

    V3 Sub (const V3 & a, const V3 & b) { return { a[0]-b[0], a[1]-b[1], a[2]-b[2] }; }
    double Dot (const V3 & a, const V3 & b) { return a[0]*b[0] + a[1]*b[1] + a[2]*b[2]; }
    V3 Cross (const V3 & a, const V3 & b)
    { return { a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0] }; }
    double Norm (const V3 & a) { return std::sqrt(Dot(a, a)); }
    V3 Scaled (const V3 & a, double s) { return { s*a[0], s*a[1], s*a[2] }; }

    // n^T S n
    double Quad (const S6 & S, const V3 & n)
    {
      return S[0]*n[0]*n[0] + S[1]*n[1]*n[1] + S[2]*n[2]*n[2]
        + 2 * (S[3]*n[1]*n[2] + S[4]*n[0]*n[2] + S[5]*n[0]*n[1]);
    }

    // a^T S b
    double Bilinear (const S6 & S, const V3 & a, const V3 & b)
    {
      V3 Sb = { S[0]*b[0] + S[5]*b[1] + S[4]*b[2], S[5]*b[0] + S[1]*b[1] + S[3]*b[2],
                S[4]*b[0] + S[3]*b[1] + S[2]*b[2] };
      return Dot(a, Sb);
    }

    // The largest eigenvalue of a symmetric 3x3 tensor and its unit eigenvector (cyclic
    // Jacobi rotations: accurate to rounding, deterministic); the eigenvector's component of
    // largest magnitude is positive.
    double LargestEigen (const S6 & S, V3 & vec)
    {
      double a[3][3] = { { S[0], S[5], S[4] }, { S[5], S[1], S[3] }, { S[4], S[3], S[2] } };
      double v[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
      for (int sweep = 0; sweep < 50; sweep++)
        {
          double off = a[0][1]*a[0][1] + a[0][2]*a[0][2] + a[1][2]*a[1][2];
          double diag = a[0][0]*a[0][0] + a[1][1]*a[1][1] + a[2][2]*a[2][2];
          if (off == 0 || off <= 1e-36 * diag) break;
          for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++)
              {
                if (a[p][q] == 0) continue;
                double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta*theta + 1));
                double c = 1 / std::sqrt(t*t + 1), s = t * c;
                for (int k = 0; k < 3; k++)      // A <- A P (columns p, q)
                  {
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c*akp - s*akq; a[k][q] = s*akp + c*akq;
                  }
                for (int k = 0; k < 3; k++)      // A <- P^T A (rows p, q)
                  {
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c*apk - s*aqk; a[q][k] = s*apk + c*aqk;
                  }
                for (int k = 0; k < 3; k++)      // V <- V P
                  {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c*vkp - s*vkq; v[k][q] = s*vkp + c*vkq;
                  }
              }
        }
      int best = 0;
      for (int k = 1; k < 3; k++)
        if (a[k][k] > a[best][best]) best = k;
      vec = { v[0][best], v[1][best], v[2][best] };
      int big = 0;
      for (int k = 1; k < 3; k++)
        if (std::fabs(vec[k]) > std::fabs(vec[big])) big = k;
      if (vec[big] < 0) vec = Scaled(vec, -1.0);
      return a[best][best];
    }

    // An orthonormal basis (e1, e2) of the plane normal to the unit vector d: e1 across the
    // coordinate axis along which d has its smallest component (deterministic).
    void PlaneBasis (const V3 & d, V3 & e1, V3 & e2)
    {
      int k = 0;
      for (int i = 1; i < 3; i++)
        if (std::fabs(d[i]) < std::fabs(d[k])) k = i;
      V3 axis = { 0, 0, 0 };
      axis[k] = 1;
      e1 = Cross(d, axis);
      e1 = Scaled(e1, 1 / Norm(e1));
      e2 = Cross(d, e1);
    }

    // The largest eigenvector of S restricted to the plane normal to the unit vector d.
    V3 PlaneOpening (const S6 & S, const V3 & d)
    {
      V3 e1, e2;
      PlaneBasis(d, e1, e2);
      double a11 = Quad(S, e1), a22 = Quad(S, e2), a12 = Bilinear(S, e1, e2);
      double phi = 0.5 * std::atan2(2 * a12, a11 - a22);
      double c = std::cos(phi), s = std::sin(phi);
      return { c*e1[0] + s*e2[0], c*e1[1] + s*e2[1], c*e1[2] + s*e2[2] };
    }

    struct TetMesh
    {
      std::vector<V3> x;
      std::vector<std::array<int,4>> tet;
      std::vector<std::array<int,4>> nb;     // neighbour across the face opposite local vertex i (-1: boundary)
      std::vector<int> vt_begin, vt;         // vertex -> tets
      std::vector<int> vv_begin, vv;         // vertex -> vertices sharing an edge (sorted)
    };

    double Volume6 (const TetMesh & m, const std::array<int,4> & t)
    {
      return Dot(Sub(m.x[t[1]], m.x[t[0]]), Cross(Sub(m.x[t[2]], m.x[t[0]]), Sub(m.x[t[3]], m.x[t[0]])));
    }

    void Neighbours (TetMesh & m)
    {
      size_t ne = m.tet.size();
      std::vector<std::array<int,4>> keys(4 * ne);     // sorted face vertices, then 4 e + i
      for (size_t e = 0; e < ne; e++)
        for (int i = 0; i < 4; i++)
          {
            std::array<int,3> f = { m.tet[e][(i+1)%4], m.tet[e][(i+2)%4], m.tet[e][(i+3)%4] };
            std::sort(f.begin(), f.end());
            keys[4*e+i] = { f[0], f[1], f[2], int(4*e+i) };
          }
      std::sort(keys.begin(), keys.end());
      m.nb.assign(ne, { -1, -1, -1, -1 });
      for (size_t k = 0; k < keys.size(); )
        {
          size_t j = k + 1;
          while (j < keys.size() && keys[j][0] == keys[k][0] && keys[j][1] == keys[k][1] && keys[j][2] == keys[k][2]) j++;
          if (j - k > 2)
            throw Exception("ngfracture.NonlocalOpening3D: the face (" + ToString(keys[k][0]) + ", " +
                            ToString(keys[k][1]) + ", " + ToString(keys[k][2]) + ") belongs to more than two tets");
          if (j - k == 2)
            {
              int a = keys[k][3], b = keys[k+1][3];
              m.nb[a/4][a%4] = b/4;
              m.nb[b/4][b%4] = a/4;
            }
          k = j;
        }
    }

    void Adjacency (TetMesh & m, size_t nv)
    {
      size_t ne = m.tet.size();
      std::vector<int> count(nv + 1, 0);
      for (auto & t : m.tet)
        for (int v : t) count[v+1]++;
      for (size_t v = 0; v < nv; v++) count[v+1] += count[v];
      m.vt_begin = count;
      m.vt.resize(count[nv]);
      std::vector<int> fill(count.begin(), count.end() - 1);
      for (size_t e = 0; e < ne; e++)
        for (int v : m.tet[e]) m.vt[fill[v]++] = int(e);
      m.vv_begin.assign(nv + 1, 0);
      m.vv.clear();
      std::vector<int> list;
      for (size_t v = 0; v < nv; v++)
        {
          list.clear();
          for (int k = m.vt_begin[v]; k < m.vt_begin[v+1]; k++)
            for (int u : m.tet[m.vt[k]])
              if (u != int(v)) list.push_back(u);
          std::sort(list.begin(), list.end());
          list.erase(std::unique(list.begin(), list.end()), list.end());
          m.vv.insert(m.vv.end(), list.begin(), list.end());
          m.vv_begin[v+1] = int(m.vv.size());
        }
    }

    TetMesh Build (FlatMatrix<double> points, FlatMatrix<int> tets, const char * who, bool topology)
    {
      size_t nv = points.Height(), ne = tets.Height();
      if (points.Width() != 3)
        throw Exception(std::string("ngfracture.") + who + ": points must have shape (nv, 3)");
      if (tets.Width() != 4)
        throw Exception(std::string("ngfracture.") + who + ": tets must have shape (ne, 4)");
      TetMesh m;
      m.x.resize(nv);
      for (size_t v = 0; v < nv; v++) m.x[v] = { points(v,0), points(v,1), points(v,2) };
      m.tet.resize(ne);
      for (size_t e = 0; e < ne; e++)
        for (int i = 0; i < 4; i++)
          {
            int v = tets(e,i);
            if (v < 0 || size_t(v) >= nv)
              throw Exception(std::string("ngfracture.") + who + ": tet " + ToString(e) + " has vertex " +
                              ToString(v) + " out of [0, " + ToString(nv) + ")");
            m.tet[e][i] = v;
          }
      if (!topology) return m;
      for (size_t e = 0; e < ne; e++)
        if (!(Volume6(m, m.tet[e]) > 0))
          throw Exception(std::string("ngfracture.") + who + ": tet " + ToString(e) +
                          " is not positively oriented (volume <= 0)");
      Neighbours(m);
      Adjacency(m, nv);
      return m;
    }

    // Position of the undirected edge (a, b) in m.vv (from its smaller vertex).
    int EdgeIndex (const TetMesh & m, int a, int b)
    {
      if (a > b) std::swap(a, b);
      auto first = m.vv.begin() + m.vv_begin[a], last = m.vv.begin() + m.vv_begin[a+1];
      return int(std::lower_bound(first, last, b) - m.vv.begin());
    }

    // Dihedral angle at the edge (a, b) of the tet (a, b, c, d).
    double Dihedral (const V3 & a, const V3 & b, const V3 & c, const V3 & d)
    {
      V3 e = Sub(b, a);
      e = Scaled(e, 1 / Norm(e));
      V3 u = Sub(c, a), w = Sub(d, a);
      u = Sub(u, Scaled(e, Dot(u, e)));
      w = Sub(w, Scaled(e, Dot(w, e)));
      return std::atan2(Norm(Cross(u, w)), Dot(u, w));
    }

    // 260 degrees: every re-entrant edge of 270 degrees or more (the root corners of a slot,
    // a step, an L-section) is a front, whose rays lie in its normal plane; a ray along a
    // singular edge sees its stress at the mesh's distance from it, and the initiation load
    // of bar3d's slot did not converge (docs/solid.md, "Convergence of initiation in 3D").
    // The meshed edges of a concave curved surface stay near 180 degrees.
    constexpr double SHARP_ANGLE = 260.0 * M_PI / 180.0;
    // A crack front: the two lips meet at the edge, its tets' dihedral angles sum to 360
    // degrees (up to rounding; no geometric edge of a body comes within 10 degrees of it).
    constexpr double FRONT_ANGLE = 350.0 * M_PI / 180.0;
    // Sharp's marks: a re-entrant edge of the body's geometry, a crack front
    constexpr char REENTRANT = 1, FRONT = 2;
    constexpr int TET_EDGES[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };

    // Sharp vertices and their front tangents: the boundary edges whose tets' dihedral
    // angles sum to at least 260 degrees, and at each of their vertices the front's
    // direction: along its one sharp edge, the chord between the far ends of two, the
    // principal axis of the sharp edges' directions for more.
    void Sharp (const TetMesh & m, std::vector<char> & sharp, std::vector<V3> & tangent)
    {
      size_t nv = m.x.size();
      std::vector<double> angle(m.vv.size(), 0.0);
      std::vector<char> boundary(m.vv.size(), 0);
      for (size_t e = 0; e < m.tet.size(); e++)
        {
          auto & t = m.tet[e];
          for (auto & ed : TET_EDGES)
            {
              int i = ed[0], j = ed[1], k = -1, l = -1;
              for (int q = 0; q < 4; q++)
                if (q != i && q != j) { if (k < 0) k = q; else l = q; }
              angle[EdgeIndex(m, t[i], t[j])] += Dihedral(m.x[t[i]], m.x[t[j]], m.x[t[k]], m.x[t[l]]);
            }
          for (int f = 0; f < 4; f++)
            if (m.nb[e][f] < 0)
              for (int i = 0; i < 4; i++)
                for (int j = i + 1; j < 4; j++)
                  if (i != f && j != f) boundary[EdgeIndex(m, t[i], t[j])] = 1;
        }
      std::vector<std::vector<int>> ends(nv);
      std::vector<char> front(nv, 0);
      for (size_t a = 0; a < nv; a++)
        for (int k = m.vv_begin[a]; k < m.vv_begin[a+1]; k++)
          if (m.vv[k] > int(a) && boundary[k] && angle[k] >= SHARP_ANGLE)
            {
              ends[a].push_back(m.vv[k]);
              ends[m.vv[k]].push_back(int(a));
              if (angle[k] >= FRONT_ANGLE) front[a] = front[m.vv[k]] = 1;
            }
      sharp.assign(nv, 0);
      tangent.assign(nv, { 0, 0, 0 });
      for (size_t v = 0; v < nv; v++)
        {
          auto & E = ends[v];
          if (E.empty()) continue;
          sharp[v] = front[v] ? FRONT : REENTRANT;
          V3 t;
          if (E.size() == 1) t = Sub(m.x[E[0]], m.x[v]);
          else if (E.size() == 2) t = Sub(m.x[E[1]], m.x[E[0]]);
          else
            {
              S6 M = { 0, 0, 0, 0, 0, 0 };
              for (int u : E)
                {
                  V3 d = Sub(m.x[u], m.x[v]);
                  d = Scaled(d, 1 / Norm(d));
                  M[0] += d[0]*d[0]; M[1] += d[1]*d[1]; M[2] += d[2]*d[2];
                  M[3] += d[1]*d[2]; M[4] += d[0]*d[2]; M[5] += d[0]*d[1];
                }
              LargestEigen(M, t);
            }
          double n = Norm(t);
          tangent[v] = n > 0 ? Scaled(t, 1 / n) : V3{ 0, 0, 0 };
        }
    }
  }

  void VertexAverage3D (FlatMatrix<double> points, FlatMatrix<int> tets, FlatMatrix<double> values,
                        FlatMatrix<double> result)
  {
    TetMesh m = Build(points, tets, "VertexAverage3D", false);
    size_t nv = m.x.size(), ne = m.tet.size(), nc = values.Width();
    if (values.Height() != ne)
      throw Exception("ngfracture.VertexAverage3D: values has " + ToString(values.Height()) +
                      " rows, the mesh has " + ToString(ne) + " tets");
    if (result.Height() != nv || result.Width() != nc)
      throw Exception("ngfracture.VertexAverage3D: result has the wrong shape");
    std::vector<double> weight(nv, 0.0);
    result = 0.0;
    // serial: the sum order, and so the last bit, never depends on threads
    for (size_t e = 0; e < ne; e++)
      {
        double w = std::fabs(Volume6(m, m.tet[e])) / 6.0;
        for (int v : m.tet[e])
          {
            weight[v] += w;
            for (size_t c = 0; c < nc; c++) result(v,c) += w * values(e,c);
          }
      }
    for (size_t v = 0; v < nv; v++)
      if (weight[v] > 0)
        for (size_t c = 0; c < nc; c++) result(v,c) /= weight[v];
  }

  void SharpVertices3D (FlatMatrix<double> points, FlatMatrix<int> tets, std::vector<int> & vertices,
                        std::vector<double> & tangents)
  {
    TetMesh m = Build(points, tets, "SharpVertices3D", true);
    std::vector<char> sharp;
    std::vector<V3> tangent;
    Sharp(m, sharp, tangent);
    vertices.clear();
    tangents.clear();
    for (size_t v = 0; v < sharp.size(); v++)
      if (sharp[v])
        {
          vertices.push_back(int(v));
          tangents.insert(tangents.end(), tangent[v].begin(), tangent[v].end());
        }
  }

  namespace
  {
    // Gradients of the barycentric coordinates of tet t, and the coordinates of point p.
    void Barycentric (const TetMesh & m, int t, const V3 & p, std::array<V3,4> & grad, std::array<double,4> & lam)
    {
      auto & v = m.tet[t];
      V3 a = Sub(m.x[v[1]], m.x[v[0]]), b = Sub(m.x[v[2]], m.x[v[0]]), c = Sub(m.x[v[3]], m.x[v[0]]);
      double det = Dot(a, Cross(b, c));
      grad[1] = Scaled(Cross(b, c), 1 / det);
      grad[2] = Scaled(Cross(c, a), 1 / det);
      grad[3] = Scaled(Cross(a, b), 1 / det);
      grad[0] = Scaled({ grad[1][0]+grad[2][0]+grad[3][0], grad[1][1]+grad[2][1]+grad[3][1],
                         grad[1][2]+grad[2][2]+grad[3][2] }, -1.0);
      V3 q = Sub(p, m.x[v[0]]);
      lam[1] = Dot(grad[1], q); lam[2] = Dot(grad[2], q); lam[3] = Dot(grad[3], q);
      lam[0] = 1 - lam[1] - lam[2] - lam[3];
    }

    S6 Interpolate (const TetMesh & m, FlatMatrix<double> T, int t, const std::array<double,4> & lam)
    {
      S6 S = { 0, 0, 0, 0, 0, 0 };
      for (int i = 0; i < 4; i++)
        for (int c = 0; c < 6; c++) S[c] += lam[i] * T(m.tet[t][i], c);
      return S;
    }

    struct Sample { double s; S6 S; };

    struct RayValue
    {
      double value;      // smallest n.T.n along the judged segment
      V3 n;              // opening direction (from the segment's end point)
      S6 end;            // the tensor at the segment's end point
    };

    // A ray within 1e-9 radians of a face's plane runs along the face: it neither leaves a
    // tet through it nor counts as pointing out of the body (a ray along a boundary face is
    // judged as in exact arithmetic, whatever the rounding of a rotated mesh).
    constexpr double ALONG_FACE = 1e-9;

    // Walk from vertex v along the unit direction d up to `reach` (or a boundary face):
    // the tensor at the start, at every face crossing and at the end. False if d points out
    // of the body at v (no tet of v's star holds d in its cone at v) or the walk does not end.
    bool Walk (const TetMesh & m, FlatMatrix<double> T, int v, const V3 & d, double reach,
               std::vector<Sample> & samples, double & surface)
    {
      const V3 p = m.x[v];
      std::array<V3,4> grad;
      std::array<double,4> lam;
      int t = -1;
      for (int k = m.vt_begin[v]; k < m.vt_begin[v+1] && t < 0; k++)
        {
          int f = m.vt[k];
          Barycentric(m, f, p, grad, lam);
          bool inside = true;
          for (int j = 0; j < 4; j++)
            if (m.tet[f][j] != v && Dot(grad[j], d) < -ALONG_FACE * Norm(grad[j])) inside = false;
          if (inside) t = f;
        }
      if (t < 0) return false;
      samples.clear();
      S6 S0;
      for (int c = 0; c < 6; c++) S0[c] = T(v, c);
      samples.push_back({ 0.0, S0 });
      surface = std::numeric_limits<double>::infinity();
      int prev = -1;
      for (int steps = 0; ; steps++)
        {
          if (steps > 1000000) return false;
          Barycentric(m, t, p, grad, lam);
          double s_out = std::numeric_limits<double>::infinity();
          int exit = -1;
          std::array<double,4> g;
          for (int j = 0; j < 4; j++)
            {
              g[j] = Dot(grad[j], d);
              if (prev < 0 ? m.tet[t][j] != v : m.nb[t][j] == prev) continue;   // first tet: the face opposite v
              if (g[j] >= -ALONG_FACE * Norm(grad[j])) continue;     // along the face, or into the tet
              double s = -lam[j] / g[j];
              if (s < s_out) { s_out = s; exit = j; }
            }
          if (exit < 0 || s_out >= reach)
            {
              std::array<double,4> l;
              for (int j = 0; j < 4; j++) l[j] = lam[j] + reach * g[j];
              samples.push_back({ reach, Interpolate(m, T, t, l) });
              return true;
            }
          s_out = std::max(s_out, samples.back().s);
          std::array<double,4> l;
          for (int j = 0; j < 4; j++) l[j] = lam[j] + s_out * g[j];
          samples.push_back({ s_out, Interpolate(m, T, t, l) });
          int next = m.nb[t][exit];
          if (next < 0) { surface = s_out; return true; }
          prev = t;
          t = next;
        }
    }

    // The value of one ray (docs/solid.md): the segment is r long, or up to the boundary
    // when the ray meets it first; from a sharp vertex (tip) the walk looks on to 2r and a
    // ray that meets the boundary at s < 2r is judged over s/2 (thin sections), but at least
    // up to its first face crossing or r. n is the largest eigenvector of the tensor at the
    // segment's end restricted to the plane normal to d; the value the smallest n.T.n at the
    // crossings and the end (the field is linear between them); the start (the vertex's own
    // value) only interpolates.
    bool Ray (const TetMesh & m, FlatMatrix<double> T, int v, const V3 & d, double r, bool tip,
              std::vector<Sample> & samples, RayValue & out)
    {
      double surface;
      if (!Walk(m, T, v, d, tip ? 2 * r : r, samples, surface)) return false;
      const double length = tip ? std::max(std::min(r, 0.5 * surface), std::min(r, samples[1].s))
                                : std::min(r, surface);
      size_t k = 1;
      while (k + 1 < samples.size() && samples[k].s < length) k++;
      // the end of the segment lies between samples k-1 and k
      const Sample & a = samples[k-1], & b = samples[k];
      double w = b.s > a.s ? std::clamp((length - a.s) / (b.s - a.s), 0.0, 1.0) : 1.0;
      for (int c = 0; c < 6; c++) out.end[c] = a.S[c] + w * (b.S[c] - a.S[c]);
      out.n = PlaneOpening(out.end, d);
      out.value = Quad(out.end, out.n);
      for (size_t q = 1; q < k; q++)
        out.value = std::min(out.value, Quad(samples[q].S, out.n));
      return true;
    }

    // The sharp tip's zone: a vertex within 27/16 r of a sharp vertex sees the tip's field
    // from the side (the mode-I opening stress across planes parallel to the crack peaks at
    // 60 degrees, 3 sqrt(3)/4 times the value straight ahead), not a concentration of its own.
    constexpr double TIP_ZONE = 27.0 / 16.0;

    // v is judged when it is on a crack front; on a re-entrant edge, when no crack front lies
    // within TIP_ZONE r (a crack grown from a notch's root takes over from the notch: the
    // slot's other root corner, a slot's width from the crack, would otherwise start a
    // parallel crack beside it) and no other re-entrant edge within r lies behind it along
    // its opening direction (the two root corners of a slot narrower than r are one front at
    // the scale r: the corner on the minus side of the opening direction, the same one all
    // along the slot, starts the crack); elsewhere, when no sharp vertex lies within
    // TIP_ZONE r and v leads every vertex within r (largest nodal principal value; ties:
    // smaller number), all among the vertices the mesh's edges connect to v inside those balls.
    bool HotSpot (const TetMesh & m, const std::vector<double> & local, const std::vector<V3> & dir,
                  const std::vector<char> & sharp, const std::vector<V3> & tangent,
                  int v, double r, std::vector<int> & mark, std::vector<int> & queue)
    {
      if (sharp[v] == FRONT) return true;
      const double lv = local[v], r2 = r * r, zone2 = TIP_ZONE * TIP_ZONE * r2;
      queue.clear();
      queue.push_back(v);
      mark[v] = v;
      for (size_t q = 0; q < queue.size(); q++)
        {
          int w = queue[q];
          for (int k = m.vv_begin[w]; k < m.vv_begin[w+1]; k++)
            {
              int u = m.vv[k];
              if (mark[u] == v) continue;
              mark[u] = v;
              V3 dx = Sub(m.x[u], m.x[v]);
              double d2 = Dot(dx, dx);
              if (d2 > zone2) continue;
              if (sharp[u] == FRONT || (sharp[u] && !sharp[v])) return false;
              if (sharp[v] == REENTRANT && sharp[u] == REENTRANT && d2 <= r2)
                {
                  // off v's edge line by more than a tenth of r, and behind v along n
                  V3 off = Sub(dx, Scaled(tangent[v], Dot(dx, tangent[v])));
                  if (Dot(off, off) > 0.01 * r2 && Dot(dx, dir[v]) < -0.1 * r) return false;
                }
              if (!sharp[v] && d2 <= r2 && (local[u] > lv || (local[u] == lv && u < v))) return false;
              queue.push_back(u);
            }
        }
      return true;
    }

    std::vector<V3> Fibonacci (int n)
    {
      const double golden = M_PI * (3.0 - std::sqrt(5.0));
      std::vector<V3> dirs(n);
      for (int k = 0; k < n; k++)
        {
          double z = 1.0 - (2.0 * k + 1.0) / n, rho = std::sqrt(std::max(0.0, 1 - z*z));
          dirs[k] = { rho * std::cos(k * golden), rho * std::sin(k * golden), z };
        }
      return dirs;
    }

    // The best ray of vertex v over its candidate directions (spacing `spacing` radians),
    // then refined: a compass search about it (the neighbouring directions at the spacing,
    // halved six times; within the front's normal plane for a sharp vertex), and the ray in
    // the plane normal to the principal direction at the best ray's end point (for a sharp
    // vertex, also normal to its front), each taken when it is better. False: no ray counts.
    bool BestRay (const TetMesh & m, FlatMatrix<double> T, int v, double r, bool tip, const V3 & tangent,
                  const std::vector<V3> & dirs, double spacing, std::vector<Sample> & samples, RayValue & best)
    {
      bool found = false;
      V3 dbest = { 0, 0, 0 };
      RayValue rv;
      for (auto & d : dirs)
        if (Ray(m, T, v, d, r, tip, samples, rv) && (!found || rv.value > best.value))
          { best = rv; dbest = d; found = true; }
      if (!found) return false;
      auto tryRay = [&] (V3 d)
        {
          d = Scaled(d, 1 / Norm(d));
          if (Ray(m, T, v, d, r, tip, samples, rv) && rv.value > best.value)
            { best = rv; dbest = d; return true; }
          return false;
        };
      double delta = spacing;
      for (int level = 0; level < 6; level++, delta *= 0.5)
        for (int moves = 0; moves < 4; moves++)
          {
            V3 e1, e2;
            if (tip) { e1 = Cross(tangent, dbest); e2 = { 0, 0, 0 }; }
            else PlaneBasis(dbest, e1, e2);
            const V3 d0 = dbest;
            double step = std::tan(delta);
            bool moved = false;
            for (const V3 & e : { e1, Scaled(e1, -1.0), e2, Scaled(e2, -1.0) })
              if (Norm(e) > 0)
                moved |= tryRay({ d0[0] + step*e[0], d0[1] + step*e[1], d0[2] + step*e[2] });
            if (!moved) break;
          }
      V3 np;
      LargestEigen(best.end, np);
      V3 d2 = tip ? Cross(tangent, np) : Sub(dbest, Scaled(np, Dot(dbest, np)));
      if (Norm(d2) > 1e-8)
        tryRay(Scaled(d2, Dot(d2, dbest) < 0 ? -1.0 : 1.0));
      return true;
    }
  }

  void NonlocalOpening3D (FlatMatrix<double> points, FlatMatrix<int> tets, FlatMatrix<double> T,
                          FlatVector<double> radius, int ndir, int nplane, FlatMatrix<double> result)
  {
    TetMesh m = Build(points, tets, "NonlocalOpening3D", true);
    size_t nv = m.x.size();
    if (T.Height() != nv || T.Width() != 6)
      throw Exception("ngfracture.NonlocalOpening3D: tensors must be nv x 6 = " + ToString(nv) + " x 6");
    if (radius.Size() != nv)
      throw Exception("ngfracture.NonlocalOpening3D: radius must have one entry per vertex");
    if (result.Height() != nv || result.Width() != 6)
      throw Exception("ngfracture.NonlocalOpening3D: result must be nv x 6");
    if (ndir < 8 || nplane < 8)
      throw Exception("ngfracture.NonlocalOpening3D: ndir and nplane must be at least 8");
    std::vector<char> sharp;
    std::vector<V3> tangent;
    Sharp(m, sharp, tangent);
    std::vector<double> local(nv);
    std::vector<V3> dir(nv);
    V3 tmp;
    for (size_t v = 0; v < nv; v++)
      {
        S6 S;
        for (int c = 0; c < 6; c++) S[c] = T(v, c);
        local[v] = LargestEigen(S, tmp);
        dir[v] = tmp;
      }
    const std::vector<V3> sphere = Fibonacci(ndir);
    std::vector<V3> plane(nplane);
    std::vector<int> mark(nv, -1), queue;
    std::vector<Sample> samples;
    // serial: deterministic
    for (size_t v = 0; v < nv; v++)
      {
        for (int c = 0; c < 6; c++) result(v, c) = 0.0;
        if (!(radius[v] > 0) || m.vt_begin[v] == m.vt_begin[v+1]) continue;
        if (!HotSpot(m, local, dir, sharp, tangent, int(v), radius[v], mark, queue)) continue;
        bool tip = sharp[v] && Norm(tangent[v]) > 0;
        if (tip)
          {
            // half-step offsets in the front's normal plane, as in 2D
            V3 e1, e2;
            PlaneBasis(tangent[v], e1, e2);
            for (int k = 0; k < nplane; k++)
              {
                double th = (k + 0.5) * 2 * M_PI / nplane, c = std::cos(th), s = std::sin(th);
                plane[k] = { c*e1[0] + s*e2[0], c*e1[1] + s*e2[1], c*e1[2] + s*e2[2] };
              }
          }
        RayValue best;
        if (!BestRay(m, T, int(v), radius[v], sharp[v], tangent[v], tip ? plane : sphere,
                     tip ? 2 * M_PI / nplane : std::sqrt(4 * M_PI / ndir), samples, best))
          continue;
        const V3 & n = best.n;
        double val = best.value;
        result(v,0) = val * n[0]*n[0]; result(v,1) = val * n[1]*n[1]; result(v,2) = val * n[2]*n[2];
        result(v,3) = val * n[1]*n[2]; result(v,4) = val * n[0]*n[2]; result(v,5) = val * n[0]*n[1];
      }
  }
}
