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

  // copies3d.found_rows_at_copies in place on copies of the rows' arrays (m rows): a row
  // whose face has a corner at the slave's point (point[] >= 0) is at a copy; in the other
  // direction than the fixed rows' (the slave on the lower fragment, on one fragment the
  // lower vertex) it becomes the copy's row on the face at the slave on the same points
  // (PartnerAt) where there is one; then projected at the copy (bary 1 there, g 0) with
  // the face's unit normal. master is faces[face] for every row.
  void FoundRowsAtCopies (int64_t m, const int64_t * faces, const int64_t * point, const int64_t * vf,
                          const int64_t * key_order, const int64_t * key_start, const int64_t * key_count,
                          const double * unit, int64_t * slave, int64_t * master, int64_t * face, double * bary,
                          double * normal, double * g, uint8_t * at_copy);

  // The mesh's boundary as copies3d.folded_rows_at_copies reads it (kinks3d.CopyIndex).
  struct FoldInput
  {
    int64_t nv, nf;
    const int64_t * faces;         // nf x 3
    const int64_t * point;         // nv: the point of every vertex, -1 off the boundary
    const int64_t * copies;        // the number of copies of every point
    const int64_t * vf;            // nv: the fragment of every vertex
    const int64_t * incident;      // 3 nf, sorted: the vertex of every incidence
    const int64_t * incidence;     // 3 nf: its slot 3 f + corner in the faces
    const int64_t * face_key;      // nf
    const int64_t * vertex_keys;   // n_keys, sorted: v (nf + 1) + face_key of every incidence
    int64_t n_keys;
    const double * unit;           // nf x 3: the faces' unit normals
  };

  // copies3d.folded_rows_at_copies before its rows: for every pair (s, t) of a picked
  // row's slave and the copy it is projected at, at a point of two copies on different
  // fragments and not tied (``tied``: sorted codes min nv + max), the faces f at t with
  // a face of f's key at s and a unit normal off every picked row's normal of the pair
  // (1 - n_f . n > kink): (slave, face, corner of t), by pair code s nv + t, then slot.
  void FoldedIncidences (const FoldInput & in, int64_t m, const uint8_t * pick, const int64_t * slave,
                         const int64_t * master, const double * bary, const double * normal, const int64_t * tied,
                         int64_t n_tied, double kink, std::vector<int64_t> & out_slave,
                         std::vector<int64_t> & out_face, std::vector<int64_t> & out_corner);

  // The partner incidences (slave s, face f, corner of s's copy t in f) at x: the gap
  // n_f . (x_s - x_t) with f's unit normal at x (0 where the copies meet or f is squeezed
  // flat). hit: every incidence of a pair (s, t) with some gap below -tol, increasing;
  // gap: their gaps.
  void BehindPartnerGaps (int64_t m, int64_t nv, const double * x, const int64_t * faces, const int64_t * slave,
                          const int64_t * face, const int64_t * corner, double tol, std::vector<int64_t> & hit,
                          std::vector<double> & gap);

  // The diagonal edge pairs (a on A, b on B, b's faces fb, a's faces fa) at x whose wedges
  // overlap deeper than tol somewhere along the edge. Where the midpoint of a lies behind
  // both planes of B's convex (or flat) wedge that deep: nearer the face it is less deep
  // behind (0 or 1, the first on a tie). Else, both wedges convex: the planes that can
  // separate them (B's face k, 0 or 1, with A's wedge in front of it; A's face k, 2 + k,
  // with B's in front), each reading its gap (a's ends to B's face, b's ends to A's face,
  // from the copies; linear along the edge), inside where all read below -tol at one
  // point; nearer the one whose deepest end behind it is least deep (the first on a tie).
  // pair: their numbers, increasing; gap: the two ends' gaps to the nearer face (2 per pair).
  void WedgeInside (int64_t m, const double * x, const int64_t * faces, const int64_t * a, const int64_t * b,
                    const int64_t * fb, const int64_t * fa, double tol, std::vector<int64_t> & pair,
                    std::vector<int64_t> & nearer, std::vector<double> & gap);

  // The pairs of copies of a boundary edge (a, b, b's faces fb, partner: whether b's face
  // k is coincident with a face at a; wedges3d.edge_copies) at x whose B wedge at b is
  // reflex (the corner of fb[1] off the edge strictly in front of fb[0]'s plane) and an
  // end of a lies behind the plane of a face of b that is no partner face deeper than
  // tol (gap n_k . (x_a_e - x_b_e), unit normals at x; no rows where a face is squeezed
  // flat). pair: their numbers, increasing; gap: g[k][e] for k, e in 0, 1 (4 per pair).
  void ReflexWedgeGaps (int64_t m, const double * x, const int64_t * faces, const int64_t * a, const int64_t * b,
                        const int64_t * fb, const uint8_t * partner, double tol, std::vector<int64_t> & pair,
                        std::vector<double> & gap);
}
#endif
