// Rows between copies of a point, the passes of every round: the numpy computations of
// ngfracture/contact/copies3d.py (_partner_at, behind_partner_rows) and wedges3d.wedge_rows
// in the same operations and order, bit for bit (compiled without fma contraction).
#ifndef NGFRACTURE_COPIES3D_HPP
#define NGFRACTURE_COPIES3D_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // For every (face f, vertex v): the first face in key order on f's three points with v
  // as a corner, or -1. The faces on f's points are key_order[key_start[f] ..
  // key_start[f] + key_count[f]).
  void PartnerAt (int64_t m, const int64_t * faces, const int64_t * key_order, const int64_t * key_start,
                  const int64_t * key_count, const int64_t * face, const int64_t * vertex, int64_t * out);

  // The partner incidences (slave s, face f, corner of s's copy t in f) at x: the gap
  // n_f . (x_s - x_t) with f's unit normal at x (0 where the copies meet or f is squeezed
  // flat). hit: every incidence of a pair (s, t) with some gap below -tol, increasing;
  // gap: their gaps.
  void BehindPartnerGaps (int64_t m, int64_t nv, const double * x, const int64_t * faces, const int64_t * slave,
                          const int64_t * face, const int64_t * corner, double tol, std::vector<int64_t> & hit,
                          std::vector<double> & gap);

  // The diagonal edge pairs (a on A, b on B, b's faces fb) at x whose midpoint of a lies
  // behind both planes of B's convex (or flat) wedge deeper than tol. pair: their
  // numbers, increasing; nearer: the less deep face (0 or 1, the first on a tie); gap:
  // the gaps of a's two ends to that face (2 per pair).
  void WedgeInside (int64_t m, const double * x, const int64_t * faces, const int64_t * a, const int64_t * b,
                    const int64_t * fb, double tol, std::vector<int64_t> & pair, std::vector<int64_t> & nearer,
                    std::vector<double> & gap);
}
#endif
