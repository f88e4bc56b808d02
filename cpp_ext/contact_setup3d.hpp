// The mesh-only set-up of 3D contact (ngfracture/contact/setup3d.py): the face keys, the
// boundary's copy index (kinks3d.CopyIndex) and the matched-face entries of
// junctions3d.fragment_pair_rows, each the numpy computation's arrays in the same order,
// bit for bit (the floating-point sums in numpy's order; compiled without fma contraction).
#ifndef NGFRACTURE_CONTACT_SETUP3D_HPP
#define NGFRACTURE_CONTACT_SETUP3D_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // Rows (m x 3) of integers in [0, bound): every row sorted (S), the rows' stable order by
  // their sorted triples (order), the rank of every row's triple among the distinct ones
  // (rank), and the number of distinct triples.
  int64_t SortedTripleRanks (int64_t m, const int64_t * rows, int64_t bound, std::vector<int64_t> & S,
                             std::vector<int64_t> & order, std::vector<int64_t> & rank);

  // kinks3d.point_groups: the boundary vertices (on faces) sorted stably by point, and
  // the number of each one's point (points finite)
  void PointGroups3 (int64_t nv, const double * X, int64_t nf, const int64_t * faces,
                     std::vector<int64_t> & on, std::vector<int64_t> & group);

  // the stable argsort of faces.ravel() (entries in [0, nv))
  void FaceIncidence (int64_t nv, int64_t nf, const int64_t * faces, std::vector<int64_t> & incidence);

  // area normals cross(p1 - p0, p2 - p0) and unit normals area / norm, as numpy
  void FaceNormals3 (const double * X, int64_t nf, const int64_t * faces, double * area2, double * unit);

  // sorted unique codes v (nf + 1) + face_key[f] of the incidences (vertex v, face f)
  void VertexFaceKeys (int64_t nf, const int64_t * faces, const int64_t * incidence, const int64_t * face_key,
                       std::vector<int64_t> & keys);

  // The rows across matched faces of junctions3d.fragment_pair_rows before their gaps:
  // slave, master face and the master copy's corner, in the function's final order, and
  // whether each vertex lies on a face matched to a face of another fragment.
  struct PairEntriesInput
  {
    int64_t nv, nf;
    const int64_t * faces;       // nf x 3
    const int64_t * vf;          // nv: fragment per vertex
    const int64_t * pid;         // nv: point per vertex
    const int64_t * key_order;   // nf
    const int64_t * key_sorted;  // nf
    const double * area2;        // nf x 3
    const double * unit;         // nf x 3
    const int64_t * copies;      // points: copies of each point
    double kink;
  };
  void FragmentPairEntries (const PairEntriesInput & in, std::vector<int64_t> & slave, std::vector<int64_t> & face,
                            std::vector<int64_t> & corner, std::vector<uint8_t> & matched);

  // kinks3d.copy_pairs: every ordered pair (on[i], on[j]) of positions with equal group
  // (group sorted), i increasing, then j (i == j included)
  void CopyPairs (int64_t n, const int64_t * on, const int64_t * group, std::vector<int64_t> & s,
                  std::vector<int64_t> & t);

  // copies3d.partner_incidences: for every pair (s, t) of copy_pairs in the fixed rows'
  // direction (vf[s] > vf[t], on one fragment s > t), every face f at t (by incidence
  // order) whose key is that of a face at s (partner_faces' test of vertex_keys): slave s,
  // face f, t's corner in f.
  struct PartnerInput
  {
    int64_t nv, nf, n_on;
    const int64_t * on;           // n_on: boundary vertices by point
    const int64_t * group;        // n_on: their points, sorted
    const int64_t * incident;     // 3 nf: faces.ravel()[incidence], sorted
    const int64_t * incidence;    // 3 nf: the stable argsort of faces.ravel()
    const int64_t * face_key;     // nf
    const int64_t * vf;           // nv
  };
  void PartnerIncidences (const PartnerInput & in, std::vector<int64_t> & slave, std::vector<int64_t> & face,
                          std::vector<int64_t> & corner);

  // wedges3d.diagonal_edges: the ordered pairs (a, b) of boundary edges on the same two
  // points (pid >= 0 at every end), on different fragments, both with two faces, no face
  // key of a's faces equal to one of b's; sorted by a, then b. ends_b: b's ends in the
  // order of a's points.
  void DiagonalEdgePairs (int64_t nE, const int64_t * E, const int64_t * at, const int64_t * vf,
                          const int64_t * pid, int64_t n_points, const int64_t * face_key,
                          std::vector<int64_t> & a, std::vector<int64_t> & b, std::vector<int64_t> & ends_b);

  // wedges3d.edge_copies: the ordered pairs (a, b) of distinct boundary edges on the same
  // two points (pid >= 0 at every end), on any fragments, both with two faces, with a
  // face of b whose key is none of a's faces' (a face of b that is no partner face of a);
  // sorted by a, then b. ends_b: b's ends in the order of a's points; partner (2 per
  // pair): whether b's face k has the key of one of a's faces.
  void EdgeCopyPairs (int64_t nE, const int64_t * E, const int64_t * at, const int64_t * pid, int64_t n_points,
                      const int64_t * face_key, std::vector<int64_t> & a, std::vector<int64_t> & b,
                      std::vector<int64_t> & ends_b, std::vector<uint8_t> & partner);

  // setup3d.vertex_fragments: per vertex the fragment of the last tetrahedron at it, or -1;
  // corner k of tetrahedron e at tets[e * row + k * col]
  void VertexFragments (int64_t nv, int64_t ne, const int64_t * tets, int64_t row, int64_t col,
                        const int64_t * fragment, int64_t * out);

  // junctions3d.covered_pairs: the sorted distinct codes vf[master 0] nv + s of every row
  // and vf[s] nv + t of every row whose master has a copy t of s (bitwise-equal point, the
  // first such corner) on another fragment than s
  void CoveredPairs (int64_t nv, const double * X, const int64_t * vf, int64_t m, const int64_t * slave,
                     const int64_t * master, std::vector<int64_t> & codes);

  // edge_rows3d.two_faces: per edge the two faces of its CSR range, increasing, or -1, -1
  void TwoFaces (int64_t nE, const int64_t * ptr, const int64_t * faces, int64_t * out);
}
#endif
