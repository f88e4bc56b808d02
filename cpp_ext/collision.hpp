#ifndef NGFRACTURE_COLLISION_HPP
#define NGFRACTURE_COLLISION_HPP
// Collision detection between triangles of a (fractured) 2D mesh, on plain arrays.
//
// Broad phase: uniform grid of square bins, candidate triangles binned by centroid,
// each occupied bin swept against itself and a complete half-stencil of neighbours.
// Narrow phase: the paper's 6 vertex-in-triangle and 9 edge-edge tests with exact
// orientation predicates, completed by an exact separating-axis test for degenerate
// (touching, collinear) configurations.

#include <cstdint>
#include <vector>
#include <array>

namespace ngfracture
{
  struct TriangleSoup
  {
    const double * x;        // nv x 2 current vertex coordinates, row major
    const int32_t * tris;    // nt x 3 vertex indices
    int64_t nv, nt;
  };

  // Bounding-box candidate pairs (i < j, sorted) among triangles with candidate[i] != 0:
  // boxes inflated by tol/2 on every side overlap (closed intervals), and the pair is
  // not excluded as mesh neighbours (same fragment and a shared vertex index).
  // fragment may be null (then every triangle is in fragment 0).
  // If narrow is true, only pairs that pass TrianglesCollide are returned.
  std::vector<std::array<int32_t,2>>
  CollisionPairs (const TriangleSoup & soup, const uint8_t * candidate,
                  const int32_t * fragment, double tol, bool narrow,
                  double * bin_size_out = nullptr);

  // Exact: the open interiors of the two triangles intersect. Degenerate (zero-area)
  // triangles have no interior.
  bool InteriorsOverlap (const double * p[3], const double * q[3]);

  // Narrow phase: interiors overlap, or (tol > 0) the distance between the closed
  // triangles is at most tol (floating point).
  bool TrianglesCollide (const double * p[3], const double * q[3], double tol);

  // One node-to-segment contact constraint (selection rules 1-4 of the paper).
  struct ContactCandidate
  {
    int32_t slave, a, c;      // slave vertex, master edge a -> c (master on its left)
    int32_t master_tri, slave_tri, pair;
    double xi;                // projection x'_b = xi x_a + (1 - xi) x_c  (eq. 13)
    double n[2];              // outward unit normal of the master edge (towards the slave)
    double dist;              // signed distance (x_b - x'_b) . n, negative = penetration
    double angle;             // rule 3 angle between master edge and slave edges
  };

  std::vector<ContactCandidate>
  SelectContacts (const TriangleSoup & soup, const uint8_t * boundary_edge_mask,
                  const int32_t * pairs, int64_t npairs, double tol, double angle_tol,
                  double xi_snap);
}

#endif
