#ifndef NGFRACTURE_EDGE_CROSSINGS3D_HPP
#define NGFRACTURE_EDGE_CROSSINGS3D_HPP
// Boundary edges of the fragments of a tetrahedral mesh that interlock (cross), on plain
// arrays (ngfracture/contact/edge_crossings3d.py documents the rules).
//
// Edge e pierces face f: f shares no point with e (copies of a vertex at its reference
// point count as that vertex), e's endpoints lie strictly on opposite sides of f's plane
// and e's line passes strictly inside f (exact orient3d, no tolerance). Edges a and b
// interlock: a pierces a face f at b, b pierces a face g at a, and f, g are of different
// fragments or share no point.
//
// Search: cells of the mean largest extent of a boundary face's bounding box; the boxes
// of the edges swept are hashed into them and every face visits the cells its box
// overlaps (fewer entries than hashing every face); a pair (edge, face) is tested once,
// in the first grid cell the two boxes share, after a strict box test; then the exact
// pierce test; for every piercing (a, f), the three edges b of f against the faces at a.
// An interlocking pair is found from the sweep of either of its edges, so an edge whose
// two ends lie bitwise at the current position of a copy (on closed lips) is not swept: a
// pair of two such edges (two closed lips crossing each other) is not found.

#include <cstdint>
#include <vector>

namespace ngfracture
{
  // Exact: the segment pq pierces the triangle abc (p, q strictly on opposite sides of its
  // plane, the line pq strictly inside it). Geometry only: shared vertices are not checked.
  bool SegmentPiercesTriangle (const double * p, const double * q, const double * a, const double * b,
                               const double * c);

  struct EdgeCrossingStats
  {
    double cell = 0;                 // grid cell size (0: nothing searched)
    int64_t box_tests = 0;           // (edge, face) pairs in a common first cell, no shared vertex
    int64_t exact_tests = 0;         // pairs past the strict box test (exact pierce tests)
    int64_t pierces = 0;             // (edge, face) pairs that pierce
    int64_t closed_edges = 0;        // edges not swept: both ends bitwise at a copy's position
    int64_t skipped_edges = 0;       // edges not swept: an end among the vertices to skip
  };

  // The boundary edges of a set of boundary triangles, the faces at every edge, and the
  // pairs of edges that interlock at given current coordinates. The constructor copies
  // what it needs (so it cannot go stale) and throws std::invalid_argument naming the
  // array on a vertex number out of range, a face that repeats a vertex, or a vertex on
  // faces of two fragments.
  class EdgeCrossingDetector3
  {
  public:
    // point: per vertex the number of its reference point (copies share it; a face "shares"
    // a vertex of an edge where it has a vertex at the same point); across: only faces of
    // other fragments than the edge's
    EdgeCrossingDetector3 (int64_t nv, const int32_t * faces, int64_t nf, const int32_t * face_fragment,
                           const int32_t * point, bool across);

    int64_t NumVertices () const { return nv_; }
    // nE x 2 vertex numbers, each row increasing, rows in lexicographic order
    const std::vector<int32_t> & Edges () const { return edges_; }
    // the faces at edge e: edge_faces_[edge_face_ptr_[e] .. edge_face_ptr_[e+1]), increasing
    const std::vector<int64_t> & EdgeFacePtr () const { return edge_face_ptr_; }
    const std::vector<int32_t> & EdgeFaces () const { return edge_faces_; }
    // nf x 3: the edges (f0, f1), (f1, f2), (f2, f0) of every face
    const std::vector<int32_t> & FaceEdges () const { return face_edges_; }

    // m x 2 edge numbers (i < j) of the interlocking pairs at current coordinates x
    // (nv x 3), unique, in lexicographic order; skip (nv, or null): vertices whose edges
    // are not swept. A pair is found from either edge's sweep; one of two edges not swept
    // (at skip vertices, or with both ends on closed lips) is not found.
    std::vector<int32_t> Detect (const double * x, EdgeCrossingStats * stats, const uint8_t * skip = nullptr) const;

  private:
    bool Shares (const int32_t * f, int32_t v) const;
    std::vector<char> Closed (const double * x) const;
    bool Pierces (const double * x, int32_t e, int32_t f) const;
    bool Interlock (const double * x, int32_t a, int32_t f, int32_t b) const;

    int64_t nv_, nf_;
    bool across_;
    std::vector<int32_t> faces_, fragment_, point_;
    // the boundary vertices grouped by point: point_vertices_[point_start_[p] .. point_start_[p+1])
    std::vector<int64_t> point_start_;
    std::vector<int32_t> point_vertices_;
    std::vector<int32_t> edges_, edge_faces_, face_edges_;
    std::vector<int64_t> edge_face_ptr_;
  };
}

#endif
