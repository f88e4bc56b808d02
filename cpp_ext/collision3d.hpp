#ifndef NGFRACTURE_COLLISION3D_HPP
#define NGFRACTURE_COLLISION3D_HPP
// Collision detection between the fragments of a (fractured) tetrahedral mesh, on plain
// arrays: which boundary vertices of one fragment lie in the closed volume of another,
// and the master boundary triangle each one faces (ngfracture/contact/collision3d.py
// documents the rules).
//
// Search: a hashed uniform grid of the boundary vertices, swept by the bounding box of
// every tetrahedron; exact point-in-tetrahedron tests with orient3d. Master faces: a
// hashed grid of the boundary triangles, searched ring by ring around the vertex.

#include <cstdint>
#include <memory>
#include <vector>

namespace ngfracture
{
  struct TetMesh3
  {
    const double * X;          // nv x 3 reference coordinates (for twins)
    const double * x;          // nv x 3 current coordinates
    const int32_t * tets;      // ne x 4
    const int32_t * faces;     // nf x 3 boundary triangles, outward
    const int32_t * fragment;  // ne, fragment per tetrahedron
    int64_t nv, ne, nf;
  };

  struct Penetration3
  {
    int32_t vertex;            // slave: a boundary vertex
    int32_t fragment;          // the fragment whose closed volume holds it
    int32_t tet;               // smallest tetrahedron of that fragment holding it (closed)
    int32_t face;              // master face: nearest boundary face of the fragment facing it
    int32_t twin;              // copy of the vertex on that fragment (same reference point), or -1
    double proj[3];            // nearest point of the master face
    double bary[3];            // proj = sum bary[k] x[face[k]]
    double normal[3];          // unit outward normal of the master face
    double gap;                // -|x_v - proj|; exactly 0 when the vertex lies on the face
  };

  struct Collision3Stats
  {
    double cell = 0;           // grid cell size
    int64_t boundary_vertices = 0, box_tests = 0, exact_tests = 0, closed_seams = 0;
  };

  // Every (boundary vertex, other fragment) pair with the vertex in the fragment's closed
  // volume, and every (lip vertex, own fragment) pair with the vertex in a closed
  // tetrahedron of its own fragment that is not at the vertex (a lip vertex: one with a
  // copy on its own fragment, i.e. a lip of a crack that does not cut the fragment
  // through), except closed seams (the vertex's twin on that fragment at the same current
  // point), sorted by (vertex, fragment). Throws std::invalid_argument on inconsistent input.
  std::vector<Penetration3> DetectPenetrations3 (const TetMesh3 & mesh, Collision3Stats * stats);

  // DetectPenetrations3 for one mesh at many current positions: the work that depends on
  // the connectivity and the reference points only (fragment of every vertex and face,
  // boundary vertices, tetrahedra at every vertex, copies, lip flags) is done once, on a
  // copy of the mesh's arrays, so it cannot go stale. Detect(x) returns what
  // DetectPenetrations3 returns for the mesh at x, bit for bit.
  class PenetrationDetector3
  {
  public:
    explicit PenetrationDetector3 (const TetMesh3 & mesh);   // mesh.x is not used
    ~PenetrationDetector3 ();
    PenetrationDetector3 (const PenetrationDetector3 &) = delete;
    PenetrationDetector3 & operator= (const PenetrationDetector3 &) = delete;
    int64_t NumVertices () const;
    std::vector<Penetration3> Detect (const double * x, Collision3Stats * stats) const;
  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
  };

  // Exact: p lies in the closed triangle (a, b, c) (coplanar and inside); false for a
  // degenerate triangle.
  bool PointInClosedTriangle3 (const double * p, const double * a, const double * b, const double * c);

  // Nearest point of the closed triangle (a, b, c) to p, as barycentric coordinates (floating point).
  void ClosestPointOnTriangle3 (const double * p, const double * a, const double * b, const double * c,
                                double * bary);
}

#endif
