// Node-to-face gap rows in 3D: the sparse gap matrix and the re-linearisation at the
// current configuration, each the numpy computation of ngfracture/contact/rows3d.py in
// the same operations and order (bit for bit; compiled without fma contraction).
#ifndef NGFRACTURE_CONTACT_ROWS3D_HPP
#define NGFRACTURE_CONTACT_ROWS3D_HPP
#include <cstdint>
#include <vector>

namespace ngfracture
{
  // CSR arrays of C (m x 3 nv): row r is n . (u_s - sum_l b_l u_l), dofs comp * nv + v,
  // columns sorted, exact zeros left out. False (arrays untouched) if a row repeats a vertex.
  bool GapMatrixCsr3 (int64_t m, int64_t nv, const int64_t * slave, const int64_t * master,
                      const double * bary, const double * normal, std::vector<int32_t> & indptr,
                      std::vector<int32_t> & indices, std::vector<double> & data);

  // g = n . (X_s - sum_l b_l X_l) of every row (rows3d._gap_offset)
  void GapOffsets3 (int64_t m, const double * X, const int64_t * slave, const int64_t * master,
                    const double * bary, const double * normal, double * g);

  // rows3d.relinearise_node_to_face: bary, normal (m x 3), dist and g (m) at x = X + U
  void RelineariseRows3 (int64_t m, const double * X, const double * x, const int64_t * slave,
                         const int64_t * master, const double * bary, const double * normal,
                         double * bary_out, double * normal_out, double * dist, double * g);
}
#endif
