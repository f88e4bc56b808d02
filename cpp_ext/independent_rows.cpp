// Rank-revealing selection of independent constraint rows (small dense blocks).
#include "independent_rows.hpp"
#include <algorithm>
#include <cmath>
#include <vector>

namespace ngfracture
{
  namespace
  {
    inline double Dot (const double * a, const double * b, int64_t n)
    {
      double s = 0;
      for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
      return s;
    }
    inline void Axpy (double alpha, const double * x, double * y, int64_t n)
    {
      for (int64_t i = 0; i < n; i++) y[i] += alpha * x[i];
    }
    // v -= Q Q^T v, twice ("twice is enough" for orthogonality to working precision).
    void Orthogonalise (const std::vector<double> & Q, int64_t nq, int64_t n, double * v)
    {
      for (int pass = 0; pass < 2; pass++)
        for (int64_t j = 0; j < nq; j++)
          Axpy(-Dot(&Q[j*n], v, n), &Q[j*n], v, n);
    }
  }

  namespace
  {
    // The vectors of the pivoted QR: values dense over the component's columns, each with
    // its support, the sorted columns where it may be nonzero (a superset of its nonzeros).
    // A dot product over the support of one factor adds the nonzero terms of the dense
    // dot product in the same order, and skips terms that are exact zeros; adding a zero
    // changes a sum at most in the sign of a zero. So every value below is bit for bit the
    // one of IndependentRowsDense, at a cost proportional to the supports.
    struct SupportQR
    {
      int64_t n = 0, nq = 0;                     // columns, basis vectors
      std::vector<double> Q;                     // orthonormal basis, row by row (dense)
      std::vector<std::vector<int32_t>> qsupp;   // support of every basis vector (the first nq)
      std::vector<std::vector<int32_t>> colq;    // basis vectors whose support holds a column
      std::vector<char> mark;                    // per basis vector: to visit in this pass
      std::vector<int32_t> merged, fresh;

      // an empty basis over n columns; the vectors keep their memory from the last use
      void Reset (int64_t n_)
      {
        n = n_; nq = 0;
        if (int64_t(colq.size()) < n) colq.resize(n);
        for (int64_t c = 0; c < n; c++) colq[c].clear();
      }

      static double Dot (const double * a, const std::vector<int32_t> & supp, const double * b)
      {
        double s = 0;
        for (int32_t c : supp) s += a[c] * b[c];
        return s;
      }

      // supp := supp | add (both sorted); the columns new to supp go to fresh.
      void Merge (std::vector<int32_t> & supp, const std::vector<int32_t> & add,
                  std::vector<int32_t> & fresh)
      {
        merged.clear();
        size_t a = 0, b = 0;
        while (a < supp.size() || b < add.size())
          {
            if (b == add.size() || (a < supp.size() && supp[a] < add[b])) merged.push_back(supp[a++]);
            else if (a == supp.size() || add[b] < supp[a]) { fresh.push_back(add[b]); merged.push_back(add[b++]); }
            else { merged.push_back(supp[a++]); b++; }
          }
        supp.swap(merged);
      }

      // v -= q_j (q_j . v) for every basis vector in order, twice: the dense
      // Orthogonalise, visiting only the basis vectors that meet v's support.
      void Orthogonalise (double * v, std::vector<int32_t> & supp)
      {
        for (int pass = 0; pass < 2; pass++)
          {
            mark.assign(nq, 0);
            for (int32_t c : supp)
              for (int32_t j : colq[c]) mark[j] = 1;
            for (int64_t j = 0; j < nq; j++)
              {
                if (!mark[j]) continue;
                const double * q = &Q[j*n];
                double alpha = -Dot(q, qsupp[j], v);
                if (alpha == 0.0) continue;          // adds zeros only
                for (int32_t c : qsupp[j]) v[c] += alpha * q[c];
                fresh.clear();
                Merge(supp, qsupp[j], fresh);
                for (int32_t c : fresh)
                  for (int32_t jj : colq[c]) mark[jj] = 1;   // later vectors meeting v now
              }
          }
      }

      // Append v / |v| (v orthogonalised, its norm r) to the basis.
      void Append (const double * v, const std::vector<int32_t> & supp, double r)
      {
        int64_t j = nq++;
        if (int64_t(Q.size()) < nq * n) Q.resize(nq * n);
        double * q = &Q[j*n];
        std::fill(q, q + n, 0.0);
        for (int32_t c : supp) q[c] = v[c] / r;
        if (int64_t(qsupp.size()) < nq) qsupp.resize(nq);
        qsupp[j] = supp;
        for (int32_t c : supp) colq[c].push_back(int32_t(j));
      }
    };

    // The pivot: the first active row whose residual is within 1e-12 of the largest, best
    // (the first of near ties, so that rounding does not decide between equal rows).
    int64_t FirstPivot (const std::vector<char> & active, const std::vector<double> & res, double best)
    {
      for (size_t i = 0; i < active.size(); i++)
        if (active[i] && res[i] >= best * (1.0 - 1e-12)) return int64_t(i);
      return -1;
    }

    // supp := the columns c < n where v[c] != 0, increasing
    void Support (const double * v, int64_t n, std::vector<int32_t> & supp)
    {
      supp.clear();
      for (int64_t c = 0; c < n; c++)
        if (v[c] != 0.0) supp.push_back(int32_t(c));
    }

    // The memory of IndependentRows, kept from one component to the next (a component's
    // vectors are small and many: allocating them each time cost as much as the QR).
    struct QRWork
    {
      SupportQR qr;
      std::vector<double> v, R, norm0, res;
      std::vector<std::vector<int32_t>> supp, colrows;
      std::vector<char> active;
      std::vector<int32_t> touched, fresh;
      std::vector<int64_t> stamp;
    };

    // vs[0 .. n) cleared (their memory kept)
    void ClearFirst (std::vector<std::vector<int32_t>> & vs, int64_t n)
    {
      if (int64_t(vs.size()) < n) vs.resize(n);
      for (int64_t i = 0; i < n; i++) vs[i].clear();
    }

    std::vector<int32_t> IndependentRowsIn (QRWork & w, const double * A, int64_t k, int64_t n,
                                            const double * G, int64_t p, double rtol)
    {
      SupportQR & qr = w.qr;
      qr.Reset(n);
      std::vector<double> & v = w.v;
      v.resize(n);
      std::vector<int32_t> & vsupp = w.fresh;
      for (int64_t i = 0; i < p; i++)
        {
          std::copy(G + i*n, G + (i+1)*n, v.begin());
          Support(v.data(), n, vsupp);
          double n0 = std::sqrt(SupportQR::Dot(v.data(), vsupp, v.data()));
          if (!(n0 > 0)) continue;
          qr.Orthogonalise(v.data(), vsupp);
          double r = std::sqrt(SupportQR::Dot(v.data(), vsupp, v.data()));
          if (r > rtol * n0) qr.Append(v.data(), vsupp, r);
        }
      // Residuals of the rows of A with the Dirichlet span removed.
      std::vector<double> & R = w.R, & norm0 = w.norm0, & res = w.res;
      R.assign(A, A + k*n);
      norm0.assign(k, 0.0);
      res.assign(k, 0.0);
      ClearFirst(w.supp, k);
      ClearFirst(w.colrows, n);
      auto & supp = w.supp;
      auto & colrows = w.colrows;
      std::vector<char> & active = w.active;
      active.assign(k, 1);
      for (int64_t i = 0; i < k; i++)
        {
          Support(&R[i*n], n, supp[i]);
          norm0[i] = std::sqrt(SupportQR::Dot(&R[i*n], supp[i], &R[i*n]));
          if (!(norm0[i] > 0)) { active[i] = 0; continue; }
          qr.Orthogonalise(&R[i*n], supp[i]);
          res[i] = std::sqrt(SupportQR::Dot(&R[i*n], supp[i], &R[i*n])) / norm0[i];
          for (int32_t c : supp[i]) colrows[c].push_back(int32_t(i));
        }
      std::vector<int32_t> picked;
      std::vector<int32_t> & touched = w.touched, & fresh = w.fresh;
      std::vector<int64_t> & stamp = w.stamp;
      stamp.assign(k, -1);
      while (true)
        {
          double best = 0;
          for (int64_t i = 0; i < k; i++)
            if (active[i]) best = std::max(best, res[i]);
          if (!(best > rtol)) break;
          int64_t j = FirstPivot(active, res, best);
          active[j] = 0;
          picked.push_back(int32_t(j));
          double * q = &R[j*n];
          qr.Orthogonalise(q, supp[j]);               // re-orthogonalise the pivot
          double r = std::sqrt(SupportQR::Dot(q, supp[j], q));
          int64_t jq = qr.nq;
          qr.Append(q, supp[j], r);
          const double * qq = &qr.Q[jq*n];
          const auto & qs = qr.qsupp[jq];
          // the active rows meeting q's support; the others change by zeros only
          touched.clear();
          for (int32_t c : qs)
            for (int32_t i : colrows[c])
              if (active[i] && stamp[i] != jq) { stamp[i] = jq; touched.push_back(i); }
          for (int32_t i : touched)
            {
              double * ri = &R[int64_t(i)*n];
              double alpha = -SupportQR::Dot(qq, qs, ri);
              if (alpha == 0.0) continue;
              for (int32_t c : qs) ri[c] += alpha * qq[c];
              fresh.clear();
              qr.Merge(supp[i], qs, fresh);
              for (int32_t c : fresh) colrows[c].push_back(i);
              res[i] = std::sqrt(SupportQR::Dot(ri, supp[i], ri)) / norm0[i];
            }
        }
      return picked;
    }
  }

  std::vector<int32_t> IndependentRows (const double * A, int64_t k, int64_t n,
                                        const double * G, int64_t p, double rtol)
  {
    QRWork w;
    return IndependentRowsIn(w, A, k, n, G, p, rtol);
  }

  std::vector<int32_t> IndependentRowsDense (const double * A, int64_t k, int64_t n,
                                        const double * G, int64_t p, double rtol)
  {
    std::vector<double> Q;              // orthonormal basis, row by row
    int64_t nq = 0;
    std::vector<double> v(n);
    for (int64_t i = 0; i < p; i++)
      {
        std::copy(G + i*n, G + (i+1)*n, v.begin());
        double n0 = std::sqrt(Dot(v.data(), v.data(), n));
        if (!(n0 > 0)) continue;
        Orthogonalise(Q, nq, n, v.data());
        double r = std::sqrt(Dot(v.data(), v.data(), n));
        if (r > rtol * n0)
          {
            for (auto & x : v) x /= r;
            Q.insert(Q.end(), v.begin(), v.end());
            nq++;
          }
      }
    // Residuals of the rows of A with the Dirichlet span removed.
    std::vector<double> R(A, A + k*n), norm0(k), res(k);
    std::vector<char> active(k, 1);
    for (int64_t i = 0; i < k; i++)
      {
        norm0[i] = std::sqrt(Dot(&R[i*n], &R[i*n], n));
        if (!(norm0[i] > 0)) { active[i] = 0; continue; }
        Orthogonalise(Q, nq, n, &R[i*n]);
      }
    std::vector<int32_t> picked;
    while (true)
      {
        double best = 0;
        for (int64_t i = 0; i < k; i++)
          if (active[i])
            {
              res[i] = std::sqrt(Dot(&R[i*n], &R[i*n], n)) / norm0[i];
              best = std::max(best, res[i]);
            }
        if (!(best > rtol)) break;
        int64_t j = FirstPivot(active, res, best);
        active[j] = 0;
        picked.push_back(int32_t(j));
        double * q = &R[j*n];
        Orthogonalise(Q, nq, n, q);                  // re-orthogonalise the pivot
        double r = std::sqrt(Dot(q, q, n));
        for (int64_t i = 0; i < n; i++) q[i] /= r;
        Q.insert(Q.end(), q, q + n);
        const double * qq = &Q[nq*n];
        nq++;
        for (int64_t i = 0; i < k; i++)
          if (active[i])
            Axpy(-Dot(qq, &R[i*n], n), qq, &R[i*n], n);
      }
    return picked;
  }

  std::vector<int32_t> IndependentColumnsBanded (const int64_t * indptr, const int32_t * indices,
                                                 const double * data, int64_t n, int64_t k,
                                                 double rtol)
  {
    // Band width W: with rows spanning at most W columns, R keeps upper bandwidth W.
    int64_t W = 1;
    for (int64_t i = 0; i < n; i++)
      if (indptr[i+1] > indptr[i])
        {
          int32_t lo = indices[indptr[i]], hi = lo;
          for (int64_t t = indptr[i]; t < indptr[i+1]; t++)
            { lo = std::min(lo, indices[t]); hi = std::max(hi, indices[t]); }
          W = std::max<int64_t>(W, hi - lo + 1);
        }
    const double drop = 64 * 2.220446049250313e-16;   // rows have unit norm
    std::vector<double> R(k * W, 0.0);          // R(j, j + d) at R[j*W + d]
    std::vector<char> filled(k, 0);
    std::vector<double> x(k + W, 0.0);          // work row, dense over a moving window
    for (int64_t i = 0; i < n; i++)
      {
        if (indptr[i+1] == indptr[i]) continue;
        int64_t lo = k, hi = -1;
        for (int64_t t = indptr[i]; t < indptr[i+1]; t++)
          {
            x[indices[t]] += data[t];
            lo = std::min<int64_t>(lo, indices[t]); hi = std::max<int64_t>(hi, indices[t]);
          }
        for (int64_t j = lo; j <= hi && j < k; j++)
          {
            double xj = x[j];
            if (xj == 0.0) continue;
            double * r = &R[j*W];
            if (!filled[j])
              {
                // Round-off, not a pivot: dropping it perturbs A far below rtol.
                if (std::abs(xj) <= drop) { x[j] = 0.0; continue; }
                for (int64_t d = 0; d < W && j + d <= hi; d++) { r[d] = x[j+d]; x[j+d] = 0.0; }
                filled[j] = 1;
                break;
              }
            // Givens rotation zeroing x_j against R_jj.
            double rjj = r[0], h = std::hypot(rjj, xj);
            double c = rjj / h, sn = xj / h;
            r[0] = h; x[j] = 0.0;
            int64_t end = std::min<int64_t>(W, k - j);
            for (int64_t d = 1; d < end; d++)
              {
                double a = r[d], b = x[j+d];
                r[d] = c*a + sn*b;
                x[j+d] = -sn*a + c*b;
              }
            hi = std::max<int64_t>(hi, j + end - 1);
          }
        for (int64_t j = lo; j <= hi && j < k; j++) x[j] = 0.0;   // clear remainders
      }
    std::vector<int32_t> kept;
    for (int64_t j = 0; j < k; j++)
      if (filled[j] && std::abs(R[j*W]) > rtol) kept.push_back(int32_t(j));
    return kept;
  }

  namespace
  {
    // True if every row of a component (unit-norm rows of C and G, columns numbered
    // 0 .. nc-1 by colmap) is farther than rtol from the span of the others: then every
    // QR, pivoted or not, keeps them all (|R_kk| >= sigma_min > rtol), and the QR is not
    // needed. Shown by a Cholesky factorisation of the Gram matrix minus
    // (rtol^2 + rounding) I in the rows' order, stored as an envelope (row i from its
    // first neighbour): it succeeds when sigma_min^2 exceeds the shift. rounding bounds
    // the backward error of forming and factorising the Gram matrix (4 k eps times its
    // largest absolute row sum, as redundancy._clearly_independent); not tried where
    // rtol^2 is within ten times it.
    struct RowRef { const int64_t * indptr; const int32_t * indices; const double * data; int32_t row; };

    bool ClearlyIndependent (const std::vector<RowRef> & rows, const std::vector<int32_t> & colmap,
                             int64_t nc, double rtol)
    {
      int64_t k = int64_t(rows.size());
      // rows meeting every local column, in order
      std::vector<int64_t> cstart(nc + 1, 0);
      auto entries = [&] (int64_t i, auto && f)
      {
        const RowRef & r = rows[i];
        for (int64_t t = r.indptr[r.row]; t < r.indptr[r.row+1]; t++) f(colmap[r.indices[t]], r.data[t]);
      };
      for (int64_t i = 0; i < k; i++) entries(i, [&] (int32_t c, double) { cstart[c+1]++; });
      for (int64_t c = 0; c < nc; c++) cstart[c+1] += cstart[c];
      std::vector<int32_t> crow(cstart[nc]);
      std::vector<double> cval(cstart[nc]);
      {
        std::vector<int64_t> fill(cstart.begin(), cstart.end() - 1);
        for (int64_t i = 0; i < k; i++)
          entries(i, [&] (int32_t c, double v) { crow[fill[c]] = int32_t(i); cval[fill[c]++] = v; });
      }
      // envelope of the lower triangle: row i holds columns first[i] .. i
      std::vector<int64_t> first(k), start(k + 1, 0);
      for (int64_t i = 0; i < k; i++)
        {
          first[i] = i;
          entries(i, [&] (int32_t c, double) { first[i] = std::min<int64_t>(first[i], crow[cstart[c]]); });
          start[i+1] = start[i] + (i - first[i] + 1);
        }
      std::vector<double> L(start[k], 0.0);
      for (int64_t i = 0; i < k; i++)
        entries(i, [&] (int32_t c, double v)
          {
            for (int64_t t = cstart[c]; t < cstart[c+1] && crow[t] <= i; t++)
              L[start[i] + crow[t] - first[i]] += v * cval[t];
          });
      double rowsum = 0;
      std::vector<double> absum(k, 0.0);
      for (int64_t i = 0; i < k; i++)
        for (int64_t j = first[i]; j <= i; j++)
          {
            double a = std::abs(L[start[i] + j - first[i]]);
            absum[i] += a;
            if (j < i) absum[j] += a;
          }
      for (int64_t i = 0; i < k; i++) rowsum = std::max(rowsum, absum[i]);
      double rounding = 4.0 * double(k) * 2.220446049250313e-16 * rowsum;
      if (rtol * rtol < 10.0 * rounding) return false;
      double shift = rtol * rtol + rounding;
      for (int64_t i = 0; i < k; i++)
        {
          double * li = &L[start[i] - first[i]];         // li[j] = L(i, j)
          for (int64_t j = first[i]; j < i; j++)
            {
              const double * lj = &L[start[j] - first[j]];
              double s = li[j];
              for (int64_t t = std::max(first[i], first[j]); t < j; t++) s -= li[t] * lj[t];
              li[j] = s / lj[j];
            }
          double d = li[i] - shift;
          for (int64_t t = first[i]; t < i; t++) d -= li[t] * li[t];
          if (!(d > 0)) return false;
          li[i] = std::sqrt(d);
        }
      return true;
    }
  }

  std::vector<int32_t> IndependentRowsSparse (int64_t m, int64_t ndof,
                                              const int64_t * indptr, const int32_t * indices,
                                              const double * data, const int32_t * label,
                                              const int64_t * position,
                                              int64_t p, const int64_t * gindptr,
                                              const int32_t * gindices, const double * gdata,
                                              const int32_t * glabel,
                                              double rtol, int method, int64_t dense_limit,
                                              int64_t gram_min)
  {
    std::vector<int32_t> kept;
    if (m == 0) return kept;
    // Group the C rows by component (in processing order) and the G rows likewise.
    std::vector<int32_t> rows(m);
    for (int64_t i = 0; i < m; i++) rows[i] = int32_t(i);
    std::sort(rows.begin(), rows.end(), [&] (int32_t a, int32_t b)
              {
                if (label[a] != label[b]) return label[a] < label[b];
                return position[a] != position[b] ? position[a] < position[b] : a < b;
              });
    std::vector<int32_t> grows(p);
    for (int64_t i = 0; i < p; i++) grows[i] = int32_t(i);
    std::sort(grows.begin(), grows.end(), [&] (int32_t a, int32_t b)
              { return glabel[a] != glabel[b] ? glabel[a] < glabel[b] : a < b; });

    std::vector<int32_t> colmap(ndof, -1), cols;
    QRWork work;                                  // the pivoted QR's memory, for every component
    std::vector<double> A, Gd;
    size_t gpos = 0;
    for (size_t s0 = 0; s0 < rows.size(); )
      {
        size_t s1 = s0;
        int32_t lab = label[rows[s0]];
        while (s1 < rows.size() && label[rows[s1]] == lab) s1++;
        while (gpos < grows.size() && glabel[grows[gpos]] < lab) gpos++;
        size_t g0 = gpos, g1 = gpos;
        while (g1 < grows.size() && glabel[grows[g1]] == lab) g1++;
        int64_t k = s1 - s0, pg = g1 - g0;

        cols.clear();
        auto addcols = [&] (const int64_t * ip, const int32_t * ix, int32_t r)
        {
          for (int64_t t = ip[r]; t < ip[r+1]; t++)
            if (colmap[ix[t]] < 0) { colmap[ix[t]] = int32_t(cols.size()); cols.push_back(ix[t]); }
        };
        for (size_t s = s0; s < s1; s++) addcols(indptr, indices, rows[s]);
        for (size_t s = g0; s < g1; s++) addcols(gindptr, gindices, grows[s]);
        int64_t nc = cols.size();

        bool banded = (method == 2 || (method == 0 && k > dense_limit)) && pg == 0;
        auto members = [&] ()
        {
          std::vector<RowRef> refs;
          for (size_t s = g0; s < g1; s++) refs.push_back({ gindptr, gindices, gdata, grows[s] });
          for (size_t s = s0; s < s1; s++) refs.push_back({ indptr, indices, data, rows[s] });
          return refs;
        };
        if (k == 1 && pg == 0)
          {
            // A single row: independent iff it did not vanish.
            double nrm = 0;
            for (int64_t t = indptr[rows[s0]]; t < indptr[rows[s0]+1]; t++)
              nrm += data[t] * data[t];
            if (std::sqrt(nrm) > rtol) kept.push_back(rows[s0]);
          }
        else if (banded)
          {
            // A^T in CSR: one row per local column, entries (position in group, value).
            std::vector<int64_t> tp(nc + 1, 0);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                tp[colmap[indices[t]] + 1]++;
            for (int64_t c = 0; c < nc; c++) tp[c+1] += tp[c];
            std::vector<int32_t> ti(tp[nc]);
            std::vector<double> tv(tp[nc]);
            std::vector<int64_t> fill(tp.begin(), tp.end() - 1);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                {
                  int64_t at = fill[colmap[indices[t]]]++;
                  ti[at] = int32_t(s - s0);
                  tv[at] = data[t];
                }
            for (int32_t j : IndependentColumnsBanded(tp.data(), ti.data(), tv.data(), nc, k, rtol))
              kept.push_back(rows[s0 + j]);
          }
        else if (k >= gram_min && ClearlyIndependent(members(), colmap, nc, rtol))
          {
            for (size_t s = s0; s < s1; s++) kept.push_back(rows[s]);
          }
        else
          {
            // Pivoting prefers the lowest index among equal residuals: input order.
            std::sort(rows.begin() + s0, rows.begin() + s1);
            A.assign(k * nc, 0.0);
            Gd.assign(pg * nc, 0.0);
            for (size_t s = s0; s < s1; s++)
              for (int64_t t = indptr[rows[s]]; t < indptr[rows[s]+1]; t++)
                A[(s - s0) * nc + colmap[indices[t]]] += data[t];
            for (size_t s = g0; s < g1; s++)
              for (int64_t t = gindptr[grows[s]]; t < gindptr[grows[s]+1]; t++)
                Gd[(s - g0) * nc + colmap[gindices[t]]] += gdata[t];
            for (int32_t j : IndependentRowsIn(work, A.data(), k, nc, Gd.data(), pg, rtol))
              kept.push_back(rows[s0 + j]);
          }
        for (int32_t c : cols) colmap[c] = -1;
        s0 = s1;
      }
    std::sort(kept.begin(), kept.end());
    return kept;
  }
}
