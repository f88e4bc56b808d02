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
}
#endif
