// Collision detection between fragments of a tetrahedral mesh (3D analogue of collision.cpp):
// the mesh's topology and copies, the grid of its boundary vertices, and the detection that
// calls the sweep (collision3d_sweep.cpp) and the master faces (collision3d_faces.cpp).
#include "collision3d.hpp"
#include "collision3d_parts.hpp"
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
  // the detection's own parts (those shared with the sweep and the faces: collision3d_parts.hpp)
  namespace detect3d
  {
  namespace
  {
    [[noreturn]] void Bad (const std::string & what) { throw std::invalid_argument("ngfracture.DetectPenetrations3d: " + what); }

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

    // The row of hit (v, F, t): the face at a copy that v crossed, if there is one, else
    // v's master face of F (false if F has none). `partners`, `scratch`: space for PartnerFaces.
    bool HitPenetration (const TetMesh3 & m, const Topology & T, const Copies & copies, const Derived & D,
                         const HashGrid & fg, const VertexFaces & vfaces, int32_t v, int32_t F, int32_t t,
                         std::vector<int32_t> & partners, std::vector<std::pair<int32_t,int32_t>> & scratch,
                         Penetration3 & pen)
    {
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
      int64_t on_F = t_copy >= 0 ? copies.CountOn(D.vfrag, v, F) : 0;
      // none: the lips of the holding tetrahedron at t, the one v is least deep behind if
      // it is behind one. With two or more copies of the point on F (a crack inside F, or
      // cracks meeting inside F) every lip: v's wedge can lie across the plane of the lip
      // it crossed into t's wedge, and the nearest face of F may be the coincident lip of
      // another copy, v in front of it. With t the only copy on F, the lips whose other
      // side is on F too: a crack of F ends at t (its front passes through the point), and
      // v can have slid into the crack's slit and on across its other lip, whose plane has
      // v's wedge on its inner side (the nearest face of F can then be the coincident
      // lip, v in front of it); a seam between pieces keeps the nearest face
      if (sep < 0 && t_copy >= 0)
        sep = SeparatingFace(m, vfaces, T, v, t_copy, m.tets + 4*t, depth, &copies, on_F >= 2 ? -1 : F);
      // none, three or more copies on F, and the holding tetrahedron has no face on the
      // boundary at t: v slid past the faces of the tetrahedra at t deeper into t's star
      // where several cracks meet; the lip at t that v is least deep behind (the
      // nearest face of F may be one v is in front of, whose row does not hold it)
      if (sep < 0 && t_copy >= 0 && on_F >= 3
          && !HasBoundaryFaceAt(m, vfaces, t_copy, m.tets + 4*t))
        sep = SeparatingFace(m, vfaces, T, v, t_copy, nullptr, depth, &copies);
      if (sep >= 0)
        {
          const int32_t * S = m.faces + 3*sep;
          ClosestPointOnTriangle3(m.x + 3*v, m.x + 3*S[0], m.x + 3*S[1], m.x + 3*S[2], pen.bary);
          for (int d = 0; d < 3; d++)
            pen.proj[d] = pen.bary[0]*m.x[3*S[0]+d] + pen.bary[1]*m.x[3*S[1]+d] + pen.bary[2]*m.x[3*S[2]+d];
          pen.face = sep;
          std::copy(&D.fnormal[3*sep], &D.fnormal[3*sep] + 3, pen.normal);
          pen.gap = -depth;
          return true;
        }
      partners.clear();
      if (pen.twin >= 0) PartnerFaces(m, copies, D, vfaces, v, F, partners, scratch);
      return MasterFace(m, D, fg, v, F, partners, pen);
    }

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
          if (HitPenetration(m, T, copies, D, fg, vfaces, v, F, t, partners, scratch, pen)) out.push_back(pen);
        }
      if (stats) *stats = st;
      return out;
    }
  }  // namespace
  }  // namespace detect3d

  std::vector<Penetration3> DetectPenetrations3 (const TetMesh3 & m, Collision3Stats * stats)
  {
    detect3d::Topology T;
    detect3d::Copies copies;
    detect3d::MakeTopology(m, T, copies);
    return detect3d::Detect(m, T, copies, stats);
  }

  struct PenetrationDetector3::Impl
  {
    std::vector<double> X;
    std::vector<int32_t> tets, faces, fragment;
    int64_t nv, ne, nf;
    detect3d::Topology T;
    detect3d::Copies copies;
    detect3d::Incidence incidence;

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
    detect3d::MakeTopology(I.Mesh(I.X.data()), I.T, I.copies);
    I.incidence = detect3d::Incidence { detect3d::MakeVertexFaces(I.Mesh(I.X.data())) };
  }

  PenetrationDetector3::~PenetrationDetector3 () = default;

  int64_t PenetrationDetector3::NumVertices () const { return impl_->nv; }

  std::vector<Penetration3> PenetrationDetector3::Detect (const double * x, Collision3Stats * stats) const
  {
    return detect3d::Detect(impl_->Mesh(x), impl_->T, impl_->copies, stats, &impl_->incidence);
  }
}
