// The mesh-only set-up of 3D contact (contact_setup3d.hpp). Sorts are counting sorts by a
// vertex number with stable insertion sorts of the small buckets (the stable orders of
// numpy's argsort / lexsort); the sums are numpy's orders: np.cross a1 b2 - a2 b1, ...,
// np.linalg.norm (a0 + a1) + a2, einsum "ij,ij->i" ((a0 + a2) + a1) + 0.0, np.bincount's
// weights added in order to 0.0.
#include "contact_setup3d.hpp"
#include <algorithm>
#include <cmath>

namespace ngfracture
{
  namespace
  {
    // stable counting sort of the items 0..m-1 by key[item] in [0, bound)
    std::vector<int64_t> CountingOrder (int64_t m, int64_t bound, const std::vector<int64_t> & key,
                                        std::vector<int64_t> & start)
    {
      start.assign(bound + 1, 0);
      for (int64_t i = 0; i < m; i++)
        start[key[i] + 1]++;
      for (int64_t b = 0; b < bound; b++)
        start[b + 1] += start[b];
      std::vector<int64_t> pos(start.begin(), start.end() - 1), order(m);
      for (int64_t i = 0; i < m; i++)
        order[pos[key[i]]++] = i;
      return order;
    }

    // stable insertion sort of order[lo, hi) by less(a, b)
    template <typename Less>
    void InsertionSort (std::vector<int64_t> & order, int64_t lo, int64_t hi, Less less)
    {
      for (int64_t i = lo + 1; i < hi; i++)
        {
          int64_t x = order[i], j = i;
          for (; j > lo && less(x, order[j - 1]); j--)
            order[j] = order[j - 1];
          order[j] = x;
        }
    }

    double Dot (const double * a, const double * b)       // einsum "ij,ij->i"
    {
      return ((a[0] * b[0] + a[2] * b[2]) + a[1] * b[1]) + 0.0;
    }

    // numpy's order of a float key: numbers ascending, NaN last
    bool KeyLess (double x, double y)
    {
      return x < y || (!std::isnan(x) && std::isnan(y));
    }
  }

  int64_t SortedTripleRanks (int64_t m, const int64_t * rows, int64_t bound, std::vector<int64_t> & S,
                             std::vector<int64_t> & order, std::vector<int64_t> & rank)
  {
    S.assign(rows, rows + 3 * m);
    for (int64_t i = 0; i < m; i++)
      {
        int64_t * s = S.data() + 3 * i;
        if (s[0] > s[1]) std::swap(s[0], s[1]);
        if (s[1] > s[2]) std::swap(s[1], s[2]);
        if (s[0] > s[1]) std::swap(s[0], s[1]);
      }
    std::vector<int64_t> first(m), start;
    for (int64_t i = 0; i < m; i++)
      first[i] = S[3 * i];
    order = CountingOrder(m, bound, first, start);
    for (int64_t b = 0; b < bound; b++)
      if (start[b + 1] - start[b] > 1)
        InsertionSort(order, start[b], start[b + 1], [&S] (int64_t x, int64_t y)
                      { return S[3 * x + 1] < S[3 * y + 1] || (S[3 * x + 1] == S[3 * y + 1] && S[3 * x + 2] < S[3 * y + 2]); });
    rank.assign(m, 0);
    int64_t r = -1;
    for (int64_t i = 0; i < m; i++)
      {
        int64_t x = order[i], y = i ? order[i - 1] : -1;
        if (!i || S[3 * x] != S[3 * y] || S[3 * x + 1] != S[3 * y + 1] || S[3 * x + 2] != S[3 * y + 2])
          r++;
        rank[x] = r;
      }
    return r + 1;
  }

  void PointGroups3 (int64_t nv, const double * X, int64_t nf, const int64_t * faces,
                     std::vector<int64_t> & on, std::vector<int64_t> & group)
  {
    std::vector<char> used(nv, 0);
    for (int64_t i = 0; i < 3 * nf; i++)
      used[faces[i]] = 1;
    on.clear();
    for (int64_t v = 0; v < nv; v++)
      if (used[v])
        on.push_back(v);
    std::stable_sort(on.begin(), on.end(), [X] (int64_t a, int64_t b)
                     {
                       const double * p = X + 3 * a, * q = X + 3 * b;
                       if (p[0] != q[0]) return p[0] < q[0];
                       if (p[1] != q[1]) return p[1] < q[1];
                       return p[2] < q[2];
                     });
    group.assign(on.size(), 0);
    for (size_t i = 1; i < on.size(); i++)
      {
        const double * p = X + 3 * on[i], * q = X + 3 * on[i - 1];
        group[i] = group[i - 1] + (p[0] != q[0] || p[1] != q[1] || p[2] != q[2]);
      }
  }

  void FaceIncidence (int64_t nv, int64_t nf, const int64_t * faces, std::vector<int64_t> & incidence)
  {
    std::vector<int64_t> key(faces, faces + 3 * nf), start;
    incidence = CountingOrder(3 * nf, nv, key, start);
  }

  void FaceNormals3 (const double * X, int64_t nf, const int64_t * faces, double * area2, double * unit)
  {
    for (int64_t f = 0; f < nf; f++)
      {
        const double * p0 = X + 3 * faces[3 * f], * p1 = X + 3 * faces[3 * f + 1], * p2 = X + 3 * faces[3 * f + 2];
        double a[3], b[3];
        for (int k = 0; k < 3; k++)
          {
            a[k] = p1[k] - p0[k];
            b[k] = p2[k] - p0[k];
          }
        double * c = area2 + 3 * f;
        c[0] = a[1] * b[2] - a[2] * b[1];
        c[1] = a[2] * b[0] - a[0] * b[2];
        c[2] = a[0] * b[1] - a[1] * b[0];
        double n = std::sqrt((c[0] * c[0] + c[1] * c[1]) + c[2] * c[2]);
        for (int k = 0; k < 3; k++)
          unit[3 * f + k] = c[k] / n;
      }
  }

  void VertexFaceKeys (int64_t nf, const int64_t * faces, const int64_t * incidence, const int64_t * face_key,
                       std::vector<int64_t> & keys)
  {
    keys.clear();
    int64_t nk = nf + 1;
    std::vector<int64_t> run;
    for (int64_t i = 0; i < 3 * nf;)
      {
        int64_t v = faces[incidence[i]];
        run.clear();
        for (; i < 3 * nf && faces[incidence[i]] == v; i++)
          run.push_back(face_key[incidence[i] / 3]);
        std::sort(run.begin(), run.end());
        for (size_t j = 0; j < run.size(); j++)
          if (!j || run[j] != run[j - 1])
            keys.push_back(v * nk + run[j]);
      }
  }

  void FragmentPairEntries (const PairEntriesInput & in, std::vector<int64_t> & slave, std::vector<int64_t> & face,
                            std::vector<int64_t> & corner, std::vector<uint8_t> & matched)
  {
    const int64_t nv = in.nv, nf = in.nf, * F = in.faces;
    std::vector<int64_t> ff(nf);
    for (int64_t f = 0; f < nf; f++)
      ff[f] = in.vf[F[3 * f]];
    // matched faces (a, b) on different fragments, by a's then b's position in key order
    matched.assign(nv, 0);
    std::vector<int64_t> es, ec, eb, ek;          // entries: slave, master copy, face b, corner k
    for (int64_t lo = 0; lo < nf;)
      {
        int64_t hi = lo;
        while (hi < nf && in.key_sorted[hi] == in.key_sorted[lo])
          hi++;
        for (int64_t i = lo; i < hi; i++)
          for (int64_t j = lo; j < hi; j++)
            {
              int64_t a = in.key_order[i], b = in.key_order[j];
              if (ff[a] == ff[b])
                continue;
              for (int k = 0; k < 3; k++)
                matched[F[3 * a + k]] = 1;
              if (ff[a] < ff[b])
                continue;
              for (int k = 0; k < 3; k++)       // the copy on face a of b's corner k
                {
                  int64_t t = F[3 * b + k], s = F[3 * a];
                  for (int l = 0; l < 3; l++)
                    if (in.pid[F[3 * a + l]] == in.pid[t])
                      {
                        s = F[3 * a + l];
                        break;
                      }
                  es.push_back(s);
                  ec.push_back(t);
                  eb.push_back(b);
                  ek.push_back(k);
                }
            }
        lo = hi;
      }
    int64_t m = es.size();
    // by (slave, master copy), stable
    std::vector<int64_t> start;
    std::vector<int64_t> order = CountingOrder(m, nv, es, start);
    for (int64_t v = 0; v < nv; v++)
      if (start[v + 1] - start[v] > 1)
        InsertionSort(order, start[v], start[v + 1], [&ec] (int64_t x, int64_t y) { return ec[x] < ec[y]; });
    // per (slave, copy): the area-weighted mean normal, the best face, the faces off its plane
    std::vector<uint8_t> keep(m, 0);
    for (int64_t lo = 0; lo < m;)
      {
        int64_t hi = lo, first = order[lo];
        while (hi < m && es[order[hi]] == es[first] && ec[order[hi]] == ec[first])
          hi++;
        double mean[3] = { 0.0, 0.0, 0.0 };
        for (int64_t i = lo; i < hi; i++)
          for (int d = 0; d < 3; d++)
            mean[d] += in.area2[3 * eb[order[i]] + d];
        int64_t best = lo;
        double best_key = -Dot(in.unit + 3 * eb[order[lo]], mean);
        for (int64_t i = lo + 1; i < hi; i++)
          {
            double key = -Dot(in.unit + 3 * eb[order[i]], mean);
            if (KeyLess(key, best_key) || (!KeyLess(best_key, key) && eb[order[i]] < eb[order[best]]))
              {
                best = i;
                best_key = key;
              }
          }
        const double * chosen = in.unit + 3 * eb[order[best]];
        for (int64_t i = lo; i < hi; i++)
          {
            int64_t e = order[i];
            bool bend = 1.0 - Dot(in.unit + 3 * eb[e], chosen) > in.kink;
            keep[i] = i == best || (bend && in.copies[in.pid[es[e]]] >= 3);
          }
        lo = hi;
      }
    std::vector<int64_t> kept;
    for (int64_t i = 0; i < m; i++)
      if (keep[i])
        kept.push_back(order[i]);
    // by (slave's fragment, slave, master's fragment, face), stable: the slaves' runs (sorted
    // by slave) by fragment, then every run by (master's fragment, face)
    std::vector<int64_t> run_start;
    for (size_t i = 0; i < kept.size(); i++)
      if (!i || es[kept[i]] != es[kept[i - 1]])
        run_start.push_back(i);
    int64_t runs = run_start.size();
    run_start.push_back(kept.size());
    std::vector<int64_t> run_order(runs);
    for (int64_t r = 0; r < runs; r++)
      run_order[r] = r;
    std::stable_sort(run_order.begin(), run_order.end(), [&] (int64_t x, int64_t y)
                     { return in.vf[es[kept[run_start[x]]]] < in.vf[es[kept[run_start[y]]]]; });
    slave.clear();
    face.clear();
    corner.clear();
    for (int64_t r : run_order)
      {
        InsertionSort(kept, run_start[r], run_start[r + 1], [&] (int64_t x, int64_t y)
                      { return ff[eb[x]] < ff[eb[y]] || (ff[eb[x]] == ff[eb[y]] && eb[x] < eb[y]); });
        for (int64_t i = run_start[r]; i < run_start[r + 1]; i++)
          {
            slave.push_back(es[kept[i]]);
            face.push_back(eb[kept[i]]);
            corner.push_back(ek[kept[i]]);
          }
      }
  }

  void CopyPairs (int64_t n, const int64_t * on, const int64_t * group, std::vector<int64_t> & s,
                  std::vector<int64_t> & t)
  {
    s.clear();
    t.clear();
    for (int64_t lo = 0; lo < n;)
      {
        int64_t hi = lo;
        while (hi < n && group[hi] == group[lo])
          hi++;
        for (int64_t i = lo; i < hi; i++)
          for (int64_t j = lo; j < hi; j++)
            {
              s.push_back(on[i]);
              t.push_back(on[j]);
            }
        lo = hi;
      }
  }

  void PartnerIncidences (const PartnerInput & in, std::vector<int64_t> & slave, std::vector<int64_t> & face,
                          std::vector<int64_t> & corner)
  {
    slave.clear();
    face.clear();
    corner.clear();
    // where every vertex's incidences begin in ``incident`` (sorted)
    std::vector<int64_t> first(in.nv + 1, 0);
    for (int64_t i = 0; i < 3 * in.nf; i++)
      first[in.incident[i] + 1]++;
    for (int64_t v = 0; v < in.nv; v++)
      first[v + 1] += first[v];
    // a face f at t is coincident with a face at s where s has a face of f's key
    std::vector<int64_t> at_s;
    for (int64_t lo = 0; lo < in.n_on;)
      {
        int64_t hi = lo;
        while (hi < in.n_on && in.group[hi] == in.group[lo])
          hi++;
        for (int64_t i = lo; i < hi; i++)
          {
            int64_t s = in.on[i];
            at_s.clear();
            for (int64_t p = first[s]; p < first[s + 1]; p++)
              at_s.push_back(in.face_key[in.incidence[p] / 3]);
            for (int64_t j = lo; j < hi; j++)
              {
                int64_t t = in.on[j];
                if (!(in.vf[s] > in.vf[t] || (in.vf[s] == in.vf[t] && s > t)))
                  continue;
                for (int64_t p = first[t]; p < first[t + 1]; p++)
                  {
                    int64_t slot = in.incidence[p], f = slot / 3;
                    if (std::find(at_s.begin(), at_s.end(), in.face_key[f]) != at_s.end())
                      {
                        slave.push_back(s);
                        face.push_back(f);
                        corner.push_back(slot % 3);
                      }
                  }
              }
          }
        lo = hi;
      }
  }

  namespace
  {
    // The boundary edges by their sorted pair of points (stable) and every run of equal
    // pairs: order, the run of every edge and where every run begins (one past the last).
    struct EdgeRuns
    {
      std::vector<int64_t> order, run_of, run_start;
    };

    EdgeRuns EdgesByPoints (int64_t nE, const int64_t * E, const int64_t * pid, int64_t n_points)
    {
      EdgeRuns r;
      std::vector<int64_t> p0(nE), p1(nE), start;
      for (int64_t e = 0; e < nE; e++)
        {
          int64_t x = pid[E[2 * e]], y = pid[E[2 * e + 1]];
          p0[e] = std::min(x, y);
          p1[e] = std::max(x, y);
        }
      r.order = CountingOrder(nE, n_points, p0, start);
      auto higher = [&p1] (int64_t x, int64_t y) { return p1[x] < p1[y]; };
      for (int64_t q = 0; q < n_points; q++)
        if (start[q + 1] - start[q] > 64)
          std::stable_sort(r.order.begin() + start[q], r.order.begin() + start[q + 1], higher);
        else if (start[q + 1] - start[q] > 1)
          InsertionSort(r.order, start[q], start[q + 1], higher);
      r.run_of.resize(nE);
      for (int64_t i = 0; i < nE; i++)
        {
          if (!i || p0[r.order[i]] != p0[r.order[i - 1]] || p1[r.order[i]] != p1[r.order[i - 1]])
            r.run_start.push_back(i);
          r.run_of[r.order[i]] = r.run_start.size() - 1;
        }
      r.run_start.push_back(nE);
      return r;
    }

    // b's ends in the order of a's points
    void PushEndsInOrder (const int64_t * E, const int64_t * pid, int64_t ea, int64_t eb, std::vector<int64_t> & ends_b)
    {
      bool flip = pid[E[2 * eb]] != pid[E[2 * ea]];
      ends_b.push_back(E[2 * eb + (flip ? 1 : 0)]);
      ends_b.push_back(E[2 * eb + (flip ? 0 : 1)]);
    }
  }

  // Every ordered pair (ea, eb) of distinct edges on the same two points, each with two
  // faces, eb increasing within ea (a stable run of EdgesByPoints): the loop of
  // DiagonalEdgePairs and EdgeCopyPairs, which differ in the pairs they keep
  template <class Visit>
  void ForEdgeCopyPairs (int64_t nE, const int64_t * E, const int64_t * at, const int64_t * pid,
                         int64_t n_points, Visit visit)
  {
    EdgeRuns runs = EdgesByPoints(nE, E, pid, n_points);
    for (int64_t ea = 0; ea < nE; ea++)
      {
        const int64_t * fa = at + 2 * ea;
        if (fa[0] < 0 || fa[1] < 0)
          continue;
        int64_t r = runs.run_of[ea];
        for (int64_t i = runs.run_start[r]; i < runs.run_start[r + 1]; i++)
          {
            int64_t eb = runs.order[i];
            const int64_t * fb = at + 2 * eb;
            if (eb != ea && fb[0] >= 0 && fb[1] >= 0)
              visit(ea, eb, fa, fb);
          }
      }
  }

  void DiagonalEdgePairs (int64_t nE, const int64_t * E, const int64_t * at, const int64_t * vf,
                          const int64_t * pid, int64_t n_points, const int64_t * face_key,
                          std::vector<int64_t> & a, std::vector<int64_t> & b, std::vector<int64_t> & ends_b)
  {
    a.clear();
    b.clear();
    ends_b.clear();
    ForEdgeCopyPairs(nE, E, at, pid, n_points, [&] (int64_t ea, int64_t eb, const int64_t * fa, const int64_t * fb)
      {
        if (vf[E[2 * ea]] == vf[E[2 * eb]])
          return;
        bool shared = false;
        for (int k = 0; k < 2; k++)
          for (int l = 0; l < 2; l++)
            shared = shared || face_key[fa[k]] == face_key[fb[l]];
        if (shared)
          return;
        a.push_back(ea);
        b.push_back(eb);
        PushEndsInOrder(E, pid, ea, eb, ends_b);
      });
  }

  void EdgeCopyPairs (int64_t nE, const int64_t * E, const int64_t * at, const int64_t * pid, int64_t n_points,
                      const int64_t * face_key, std::vector<int64_t> & a, std::vector<int64_t> & b,
                      std::vector<int64_t> & ends_b, std::vector<uint8_t> & partner)
  {
    a.clear();
    b.clear();
    ends_b.clear();
    partner.clear();
    ForEdgeCopyPairs(nE, E, at, pid, n_points, [&] (int64_t ea, int64_t eb, const int64_t * fa, const int64_t * fb)
      {
        uint8_t shared[2];
        for (int l = 0; l < 2; l++)
          shared[l] = face_key[fb[l]] == face_key[fa[0]] || face_key[fb[l]] == face_key[fa[1]];
        if (shared[0] && shared[1])
          return;                                         // the partner-face rows are the whole condition
        a.push_back(ea);
        b.push_back(eb);
        PushEndsInOrder(E, pid, ea, eb, ends_b);
        partner.push_back(shared[0]);
        partner.push_back(shared[1]);
      });
  }

  void VertexFragments (int64_t nv, int64_t ne, const int64_t * tets, int64_t row, int64_t col,
                        const int64_t * fragment, int64_t * out)
  {
    std::fill(out, out + nv, int64_t(-1));
    for (int64_t e = 0; e < ne; e++)
      for (int k = 0; k < 4; k++)
        out[tets[e * row + k * col]] = fragment[e];
  }

  void CoveredPairs (int64_t nv, const double * X, const int64_t * vf, int64_t m, const int64_t * slave,
                     const int64_t * master, std::vector<int64_t> & codes)
  {
    codes.clear();
    codes.reserve(2 * m);
    for (int64_t r = 0; r < m; r++)
      codes.push_back(vf[master[3 * r]] * nv + slave[r]);
    for (int64_t r = 0; r < m; r++)
      {
        int64_t s = slave[r];
        if (vf[master[3 * r]] == vf[s])
          continue;
        const double * p = X + 3 * s;
        for (int c = 0; c < 3; c++)
          {
            const double * q = X + 3 * master[3 * r + c];
            if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2])
              {
                codes.push_back(vf[s] * nv + master[3 * r + c]);
                break;
              }
          }
      }
    std::sort(codes.begin(), codes.end());
    codes.erase(std::unique(codes.begin(), codes.end()), codes.end());
  }

  void TwoFaces (int64_t nE, const int64_t * ptr, const int64_t * faces, int64_t * out)
  {
    for (int64_t e = 0; e < nE; e++)
      {
        out[2 * e] = out[2 * e + 1] = -1;
        if (ptr[e + 1] - ptr[e] == 2)
          {
            int64_t x = faces[ptr[e]], y = faces[ptr[e] + 1];
            out[2 * e] = std::min(x, y);
            out[2 * e + 1] = std::max(x, y);
          }
      }
  }
}
