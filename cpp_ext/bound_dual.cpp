// Goldfarb-Idnani dual steps on sign bounds with an updated Cholesky factor of the free block
// (bound_dual.hpp). The choices (the bound to enter, the step lengths, the ties) are those of
// convex_qp in ngfracture/linalg/qp.py, so that both walk through the same working sets.
#include "bound_dual.hpp"
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace ngfracture
{
  namespace
  {
    constexpr double inf = std::numeric_limits<double>::infinity();

    // The allocator of the n x n buffers (70 MB each at 3000 rows), on transparent huge
    // pages where the kernel offers them for the asking (madvise mode, as numpy asks for
    // its arrays): a page fault per 2 MB instead of per 4 kB. With 4 kB pages the two
    // buffers of a solve took 35000 faults, and a late round of the default sphere more
    // system time than its dual steps.
    template <typename T>
    struct LargeAllocator
    {
      using value_type = T;
      LargeAllocator () = default;
      template <typename U> LargeAllocator (const LargeAllocator<U> &) { }

      T * allocate (size_t n)
      {
        constexpr size_t huge = size_t(2) << 20;
        size_t bytes = n * sizeof(T);
        void * p = nullptr;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        if (bytes >= 2 * huge)
        {
          if (posix_memalign(&p, huge, bytes) != 0)
            throw std::bad_alloc();
          madvise(p, bytes, MADV_HUGEPAGE);     // a hint: refused, the pages stay small
          return static_cast<T *>(p);
        }
#endif
        if (!(p = std::malloc(bytes > 0 ? bytes : 1)))
          throw std::bad_alloc();
        return static_cast<T *>(p);
      }

      void deallocate (T * p, size_t) { std::free(p); }
    };

    template <typename T, typename U>
    bool operator== (const LargeAllocator<T> &, const LargeAllocator<U> &) { return true; }
    template <typename T, typename U>
    bool operator!= (const LargeAllocator<T> &, const LargeAllocator<U> &) { return false; }

    using LargeBuffer = std::vector<double, LargeAllocator<double>>;

    // a . b over n entries with eight partial sums, which the compiler keeps in vector
    // registers (a single running sum may not be reordered)
    double Dot (const double * a, const double * b, int n)
    {
      double part[8] = { 0, 0, 0, 0, 0, 0, 0, 0 };
      int i = 0;
      for (; i + 8 <= n; i += 8)
        for (int l = 0; l < 8; l++)
          part[l] += a[i + l] * b[i + l];
      double s = ((part[0] + part[4]) + (part[1] + part[5])) + ((part[2] + part[6]) + (part[3] + part[7]));
      for (; i < n; i++)
        s += a[i] * b[i];
      return s;
    }

    // H with its rows and columns in slots: the free variables in the first slots, the held
    // ones after them, so that H_AF is one contiguous block (its product streams through
    // k f entries instead of k rows of n)
    class SlotMatrix
    {
    public:
      SlotMatrix (const BoundQpData & qp, const std::vector<int8_t> & held)
        : n_(qp.n), H_(size_t(qp.n) * qp.n), slot_(qp.n), var_(qp.n)
      {
        int next = 0;
        for (int pass = 0; pass < 2; pass++)
        {
          for (int i = 0; i < n_; i++)
            if (bool(held[i]) == bool(pass))
            {
              slot_[i] = next;
              var_[next++] = i;
            }
          free_ = pass == 0 ? next : free_;
        }
        for (int a = 0; a < n_; a++)
          for (int b = 0; b < n_; b++)
            H_[size_t(a) * n_ + b] = qp.H[size_t(var_[a]) * n_ + var_[b]];
      }

      int Slot (int i) const { return slot_[i]; }
      const double * Row (int i) const { return &H_[size_t(slot_[i]) * n_]; }

      void Hold (int i) { Swap(slot_[i], free_ - 1); free_--; }
      void Release (int i) { Swap(slot_[i], free_); free_++; }

    private:
      void Swap (int a, int b)
      {
        if (a == b)
          return;
        std::swap_ranges(&H_[size_t(a) * n_], &H_[size_t(a + 1) * n_], &H_[size_t(b) * n_]);
        for (int r = 0; r < n_; r++)
          std::swap(H_[size_t(r) * n_ + a], H_[size_t(r) * n_ + b]);
        std::swap(var_[a], var_[b]);
        slot_[var_[a]] = a;
        slot_[var_[b]] = b;
      }

      int n_, free_ = 0;
      LargeBuffer H_;
      std::vector<int> slot_, var_;
    };

    // The Cholesky factor L of H_FF (column-major, leading dimension n) and W = L^-1 E_F^T
    // (column-major, leading dimension n) for the ordered free variables F, with the thin QR
    // of W.
    class FreeFactor
    {
    public:
      FreeFactor (const BoundQpData & qp)
        : qp_(qp), n_(qp.n), p_(qp.p), L_(size_t(qp.n) * qp.n), W_(size_t(qp.n) * qp.p),
          Q_(size_t(qp.n) * qp.p), R_(size_t(qp.p) * qp.p) { }

      int Size () const { return int(free_.size()); }
      const std::vector<int> & Free () const { return free_; }

      void Start (const std::vector<int> & free, const double * L0)
      {
        free_ = free;
        int f = Size();
        constexpr int tile = 64;          // the transposing copy by tiles that stay in cache
        for (int i0 = 0; i0 < f; i0 += tile)
          for (int j0 = 0; j0 <= i0; j0 += tile)
            for (int j = j0; j < std::min(j0 + tile, f); j++)
              for (int i = std::max(i0, j); i < std::min(i0 + tile, f); i++)
                Lij(i, j) = L0[size_t(i) * f + j];
        for (int q = 0; q < p_; q++)
          for (int r = 0; r < f; r++)
            Wiq(r, q) = qp_.E[size_t(q) * n_ + free_[r]];
        ForwardColumns();
      }

      // L Y = B in place for W's p columns: Forward on each, panel by panel of L's columns,
      // so that L streams from memory once instead of once per column (each entry takes
      // the same operations in the same order as in Forward)
      void ForwardColumns ()
      {
        int f = Size();
        constexpr int panel = 32;
        for (int j0 = 0; j0 < f; j0 += panel)
          for (int q = 0; q < p_; q++)
          {
            double * w = &Wiq(0, q);
            for (int j = j0; j < std::min(j0 + panel, f); j++)
            {
              const double * col = &L_[size_t(j) * n_];
              double wj = w[j] /= col[j];
              for (int i = j + 1; i < f; i++)
                w[i] -= col[i] * wj;
            }
          }
      }

      // L y = b in place, b zero before ``from``
      void Forward (double * b, int from) const
      {
        int f = Size();
        for (int j = from; j < f; j++)
        {
          const double * col = &L_[size_t(j) * n_];
          double bj = b[j] /= col[j];
          for (int i = j + 1; i < f; i++)
            b[i] -= col[i] * bj;
        }
      }

      // L^T y = b in place
      void Backward (double * b) const
      {
        for (int j = Size() - 1; j >= 0; j--)
        {
          const double * col = &L_[size_t(j) * n_];
          b[j] = (b[j] - Dot(col + j + 1, b + j + 1, Size() - j - 1)) / col[j];
        }
      }

      // variable i joins F at its end; false if H_FF would lose definiteness to rounding
      bool Append (int i)
      {
        int f = Size();
        std::vector<double> l(f);
        for (int r = 0; r < f; r++)
          l[r] = qp_.H[size_t(i) * n_ + free_[r]];
        Forward(l.data(), 0);
        double hii = qp_.H[size_t(i) * n_ + i], d2 = hii;
        for (int r = 0; r < f; r++)
          d2 -= l[r] * l[r];
        if (!(d2 > 1e-14 * hii))
          return false;
        double d = std::sqrt(d2);
        for (int r = 0; r < f; r++)
          Lij(f, r) = l[r];
        Lij(f, f) = d;
        for (int q = 0; q < p_; q++)
          Wiq(f, q) = (qp_.E[size_t(q) * n_ + i] - Dot(&Wiq(0, q), l.data(), f)) / d;
        free_.push_back(i);
        return true;
      }

      // the variable at position k leaves F: its row and column go, and the trailing block
      // takes the rank-one update L33 L33^T + l32 l32^T by Givens rotations, which W's rows
      // follow (the product L W = E_F^T is kept)
      void Remove (int k)
      {
        int f = Size(), m = f - 1 - k;
        std::vector<double> x(m), w2(p_);
        for (int q = 0; q < p_; q++)
          w2[q] = Wiq(k, q);
        for (int i = 0; i < m; i++)
          x[i] = Lij(k + 1 + i, k);
        for (int j = 0; j < k; j++)
          for (int i = k; i < f - 1; i++)
            Lij(i, j) = Lij(i + 1, j);
        for (int j = k; j < f - 1; j++)
          for (int i = j; i < f - 1; i++)
            Lij(i, j) = Lij(i + 1, j + 1);
        for (int q = 0; q < p_; q++)
          std::copy(&Wiq(k + 1, q), &Wiq(f, q), &Wiq(k, q));
        free_.erase(free_.begin() + k);
        for (int i = 0; i < m; i++)
        {
          double * col = &L_[size_t(k + i) * n_];
          double a = col[k + i], b = x[i], r = std::hypot(a, b), cs = a / r, sn = b / r;
          col[k + i] = r;
          for (int j = i + 1; j < m; j++)
          {
            double lj = col[k + j];
            col[k + j] = cs * lj + sn * x[j];
            x[j] = -sn * lj + cs * x[j];
          }
          for (int q = 0; q < p_; q++)
          {
            double & w = Wiq(k + i, q), a1 = w;
            w = cs * a1 + sn * w2[q];
            w2[q] = -sn * a1 + cs * w2[q];
          }
        }
      }

      // the thin QR of W by Gram-Schmidt with reorthogonalisation; false if its columns are
      // dependent (the equalities on the free variables)
      bool FactorW ()
      {
        int f = Size();
        std::fill(R_.begin(), R_.end(), 0.0);
        std::vector<double> coefficients(p_);
        double largest = 0.0;
        for (int q = 0; q < p_; q++)
        {
          double * v = &Q_[size_t(q) * n_];
          std::copy(&Wiq(0, q), &Wiq(f, q), v);
          ProjectOff(v, q, coefficients.data());
          for (int s = 0; s < q; s++)
            R_[size_t(s) * p_ + q] = coefficients[s];
          double size = std::sqrt(Dot(v, v, f));
          largest = std::max(largest, size);
          if (!(size > 1e-10 * largest))
            return false;
          R_[size_t(q) * p_ + q] = size;
          for (int r = 0; r < f; r++)
            v[r] /= size;
        }
        return true;
      }

      // y minus its projection on the range of W, in place, and mu with W mu that projection
      void Project (double * y, double * mu) const
      {
        ProjectOff(y, p_, mu);          // the coefficients z = Q^T y, then R mu = z
        SolveR(mu);
      }

      // W^T b
      void WT (const double * b, double * out) const
      {
        for (int q = 0; q < p_; q++)
          out[q] = Dot(&W_[size_t(q) * n_], b, Size());
      }

      // R^-1 R^-T b in place: (W^T W)^-1 b
      void NormalSolve (double * b) const
      {
        for (int q = 0; q < p_; q++)
        {
          double s = b[q];
          for (int t = 0; t < q; t++)
            s -= R_[size_t(t) * p_ + q] * b[t];
          b[q] = s / R_[size_t(q) * p_ + q];
        }
        SolveR(b);
      }

      // W mu added to b
      void AddW (const double * mu, double * b) const
      {
        for (int q = 0; q < p_; q++)
          for (int r = 0; r < Size(); r++)
            b[r] += W_[size_t(q) * n_ + r] * mu[q];
      }

    private:
      // v minus its projection on Q's first ``columns`` columns (Gram-Schmidt twice), in
      // place; the coefficients Q^T v of the original v
      void ProjectOff (double * v, int columns, double * coefficients) const
      {
        int f = Size();
        std::fill(coefficients, coefficients + columns, 0.0);
        for (int pass = 0; pass < 2; pass++)
          for (int q = 0; q < columns; q++)
          {
            const double * u = &Q_[size_t(q) * n_];
            double d = Dot(u, v, f);
            coefficients[q] += d;
            for (int r = 0; r < f; r++)
              v[r] -= d * u[r];
          }
      }

      // R x = b in place (R upper triangular)
      void SolveR (double * b) const
      {
        for (int q = p_ - 1; q >= 0; q--)
        {
          double s = b[q];
          for (int t = q + 1; t < p_; t++)
            s -= R_[size_t(q) * p_ + t] * b[t];
          b[q] = s / R_[size_t(q) * p_ + q];
        }
      }

      double & Lij (int i, int j) { return L_[size_t(j) * n_ + i]; }
      double & Wiq (int i, int q) { return W_[size_t(q) * n_ + i]; }

      const BoundQpData & qp_;
      int n_, p_;
      std::vector<int> free_;
      LargeBuffer L_, W_, Q_, R_;
    };

    // The bounds' lengths in the metric of H, |L^-1 e_i| = sqrt((H^-1)_ii): given for the
    // start's held variables; for a free one at position r of the start, |L0^-1 e_r|^2 plus
    // qp.extra[i], computed when first needed ((f - r)^2 / 2 flops; the method considers a few
    // bounds of thousands)
    class BoundLengths
    {
    public:
      BoundLengths (const BoundQpData & qp, const int8_t * held0, const double * L0)
        : qp_(qp), L0_(L0), length_(qp.norm, qp.norm + qp.n), at_(qp.n, -1)
      {
        for (int i = 0; i < qp.n; i++)
          if (!held0[i])
            at_[i] = f0_++;
      }

      // a lower bound of the length, with the diagonal entry of L0^-1 alone (shrunk so that
      // rounding keeps it below the length computed)
      double Floor (int i) const
      {
        if (length_[i] > 0.0 || at_[i] < 0)
          return length_[i];
        double d = L0_[size_t(at_[i]) * f0_ + at_[i]];
        return (1.0 - 1e-12) * std::sqrt(1.0 / (d * d) + qp_.extra[i]);
      }

      double Of (int i)
      {
        if (length_[i] > 0.0 || at_[i] < 0)
          return std::max(length_[i], 1e-300);
        int r = at_[i], m = f0_ - r;
        std::vector<double> y(m);         // L0^-1 e_r, from row r on
        double sum = 0.0;
        for (int t = 0; t < m; t++)
        {
          const double * row = L0_ + size_t(r + t) * f0_ + r;
          y[t] = ((t == 0 ? 1.0 : 0.0) - Dot(row, y.data(), t)) / row[t];
          sum += y[t] * y[t];
        }
        length_[i] = std::max(std::sqrt(sum + qp_.extra[i]), 1e-300);
        return length_[i];
      }

    private:
      const BoundQpData & qp_;
      const double * L0_;
      std::vector<double> length_;
      std::vector<int> at_;
      int f0_ = 0;
    };

    // The state of the method: x, the equalities' multipliers, the held bounds in the order
    // they entered with their multipliers.
    struct DualState
    {
      std::vector<double> x, mu, u;
      std::vector<int> active;
      std::vector<int8_t> held;
    };

    // the multipliers of the held bounds: u_A = c_A + E_A^T mu - H_AF x_F
    void HeldMultipliers (const BoundQpData & qp, const FreeFactor & F, DualState & s)
    {
      for (int i : s.active)
      {
        double v = qp.c[i];
        for (int q = 0; q < qp.p; q++)
          v += qp.E[size_t(q) * qp.n + i] * s.mu[q];
        const double * h = qp.H + size_t(i) * qp.n;
        for (int j : F.Free())
          v -= h[j] * s.x[j];
        s.u[i] = v;
      }
    }

    // the minimiser on F with E x = e: x_F = L^-T (g + W mu), g = L^-1 c_F, W^T W mu = e - W^T g
    void MinimiserOnFree (const BoundQpData & qp, const FreeFactor & F, DualState & s)
    {
      int f = F.Size();
      std::vector<double> g(f), rhs(qp.p);
      for (int r = 0; r < f; r++)
        g[r] = qp.c[F.Free()[r]];
      F.Forward(g.data(), 0);
      F.WT(g.data(), rhs.data());
      for (int q = 0; q < qp.p; q++)
        s.mu[q] = qp.e[q] - rhs[q];
      F.NormalSolve(s.mu.data());
      F.AddW(s.mu.data(), g.data());
      F.Backward(g.data());
      std::fill(s.x.begin(), s.x.end(), 0.0);
      for (int r = 0; r < f; r++)
        s.x[F.Free()[r]] = g[r];
    }

    // Goldfarb and Idnani's S-pair from held0: free the held bounds whose multipliers come
    // out negative, all at once, until none does (convex_qp's _warm_start)
    bool StartPair (const BoundQpData & qp, const int8_t * held0, const double * L0, FreeFactor & F,
                    DualState & s, std::string & reason)
    {
      std::vector<int> free;
      for (int i = 0; i < qp.n; i++)
        if (held0[i])
        {
          s.active.push_back(i);
          s.held[i] = 1;
        }
        else
          free.push_back(i);
      F.Start(free, L0);
      for (int round = 0; round <= qp.n; round++)
      {
        if (!F.FactorW())
        {
          reason = "the equalities are dependent on the free variables of the start";
          return false;
        }
        MinimiserOnFree(qp, F, s);
        HeldMultipliers(qp, F, s);
        std::vector<int> kept;
        for (int i : s.active)
          if (s.u[i] < 0.0)
          {
            s.held[i] = 0;
            s.u[i] = 0.0;
            if (!F.Append(i))
            {
              reason = "H lost definiteness to rounding on the free variables of the start";
              return false;
            }
          }
          else
            kept.push_back(i);
        if (kept.size() == s.active.size())
          return true;
        s.active = kept;
      }
      reason = "no start from the given working set";
      return false;
    }

    // |x|_H^2 = x_F^T (c_F + E_F^T mu) = c^T x + mu^T e at a minimiser on F
    double SizeInH (const BoundQpData & qp, const DualState & s)
    {
      double v = 0.0;
      for (int i = 0; i < qp.n; i++)
        v += qp.c[i] * s.x[i];
      for (int q = 0; q < qp.p; q++)
        v += s.mu[q] * qp.e[q];
      return std::sqrt(std::max(v, 0.0));
    }

    // the free bound missed most in the metric of H, if by more than the level (relative
    // to the data and the iterate's size |x|_H); -1 for none
    int NextBound (const BoundQpData & qp, const DualState & s, double size, BoundLengths & lengths)
    {
      double level = qp.level * std::max({ qp.data, size, 1e-300 });
      int best = -1;
      double most = level;
      for (int i = 0; i < qp.n; i++)
      {
        // the lower bound of the length first: most bounds are missed by too little
        if (!qp.bounded[i] || s.held[i] || !(s.x[i] > 0.0) || !(s.x[i] / lengths.Floor(i) > most))
          continue;
        double miss = s.x[i] / lengths.Of(i);
        if (miss > most)
        {
          most = miss;
          best = i;
        }
      }
      return best;
    }

    // the response to a unit force down on the free variable at position k: y = -dx_F and
    // dmu; returns w.w, w = L^-1 e_k - W dmu (dx_F = -L^-T w, the variable moves by -w.w)
    double UnitResponse (const FreeFactor & F, int k, std::vector<double> & y, std::vector<double> & dmu)
    {
      int f = F.Size();
      std::fill(y.begin(), y.begin() + f, 0.0);
      y[k] = 1.0;
      F.Forward(y.data(), k);
      F.Project(y.data(), dmu.data());
      double ww = Dot(y.data(), y.data(), f);
      F.Backward(y.data());
      return ww;
    }

    // dual steps until bound j holds, freeing the held bounds whose multipliers reach zero
    BoundDualStatus Enter (const BoundQpData & qp, int j, double length, FreeFactor & F, SlotMatrix & slots,
                           DualState & s, int & dropped, std::string & reason)
    {
      double force = 0.0;                 // the multiplier of j while it is pushed down
      std::vector<double> y(qp.n), by_slot(qp.n), dmu(qp.p), du(s.active.size());
      while (true)
      {
        int f = F.Size();
        int k = int(std::find(F.Free().begin(), F.Free().end(), j) - F.Free().begin());
        double ww = UnitResponse(F, k, y, dmu);
        for (int r = 0; r < f; r++)
          by_slot[slots.Slot(F.Free()[r])] = y[r];
        du.assign(s.active.size(), 0.0);
        int k_drop = -1;
        double t_dual = inf;
        for (size_t a = 0; a < s.active.size(); a++)
        {
          int i = s.active[a];
          double v = Dot(slots.Row(i), by_slot.data(), f);
          for (int q = 0; q < qp.p; q++)
            v += qp.E[size_t(q) * qp.n + i] * dmu[q];
          du[a] = v;
          if (v < 0.0)
          {
            double ratio = s.u[i] / -v;
            if (ratio < t_dual)
            {
              t_dual = ratio;
              k_drop = int(a);
            }
          }
        }
        double t_full = ww > std::pow(1e-14 * length, 2) ? s.x[j] / ww : inf;
        double t = std::min(t_dual, t_full);
        if (!std::isfinite(t))
        {
          reason = "bound " + std::to_string(j) + " cannot hold together with the working set";
          return BoundDualStatus::infeasible;
        }
        if (std::isfinite(t_full))
          for (int r = 0; r < f; r++)
            s.x[F.Free()[r]] -= t * y[r];
        for (int q = 0; q < qp.p; q++)
          s.mu[q] += t * dmu[q];
        for (size_t a = 0; a < s.active.size(); a++)
          s.u[s.active[a]] += t * du[a];
        force += t;
        if (t == t_full)
        {
          s.x[j] = 0.0;
          F.Remove(k);
          slots.Hold(j);
          s.active.push_back(j);
          s.held[j] = 1;
          s.u[j] = force;
          if (F.FactorW())
            return BoundDualStatus::solved;
          reason = "the equalities became dependent on the free variables";
          return BoundDualStatus::failed;
        }
        int i = s.active[k_drop];
        s.active.erase(s.active.begin() + k_drop);
        s.held[i] = 0;
        s.u[i] = 0.0;
        dropped++;
        slots.Release(i);
        if (!F.Append(i) || !F.FactorW())
        {
          reason = "H lost definiteness to rounding on the free variables";
          return BoundDualStatus::failed;
        }
      }
    }
  }

  BoundDualAnswer BoundDualActiveSet (const BoundQpData & qp, const int8_t * held0, const double * L0)
  {
    BoundDualAnswer answer;
    FreeFactor F(qp);
    DualState s{ std::vector<double>(qp.n, 0.0), std::vector<double>(qp.p, 0.0),
                 std::vector<double>(qp.n, 0.0), {}, std::vector<int8_t>(qp.n, 0) };
    if (StartPair(qp, held0, L0, F, s, answer.reason))
    {
      SlotMatrix slots(qp, s.held);
      BoundLengths lengths(qp, held0, L0);
      answer.reason = "no solution in " + std::to_string(qp.max_steps) + " steps";
      double size = SizeInH(qp, s);
      for (int step = 0; step < qp.max_steps; step++)
      {
        int j = NextBound(qp, s, size, lengths);
        if (j < 0)
        {
          answer.status = BoundDualStatus::solved;
          answer.reason.clear();
          break;
        }
        answer.entered++;
        BoundDualStatus entered = Enter(qp, j, lengths.Of(j), F, slots, s, answer.dropped, answer.reason);
        if (entered != BoundDualStatus::solved)
        {
          answer.status = entered;
          break;
        }
        size = SizeInH(qp, s);
        if (!(size <= qp.growth_limit * std::max(qp.data, 1e-300)))
        {
          answer.reason = "the iterate grew beyond the growth limit (H nearly singular)";
          break;
        }
      }
    }
    answer.x = std::move(s.x);
    answer.mu = std::move(s.mu);
    answer.u = std::move(s.u);
    answer.held = std::move(s.held);
    return answer;
  }
}
