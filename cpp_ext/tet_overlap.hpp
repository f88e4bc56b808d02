#ifndef NGFRACTURE_TET_OVERLAP_HPP
#define NGFRACTURE_TET_OVERLAP_HPP
// The overlap volume between the fragments of a tetrahedral mesh, on plain arrays
// (ngfracture/output/overlap3d.py documents the rules).
//
// Narrow phase: the intersection of two tetrahedra is convex; one tetrahedron, as a
// polyhedron of outward faces, is clipped by the four half-spaces of the other
// (Sutherland-Hodgman per face, the cut closed by a cap polygon ordered by angle), and the
// volume of what remains is the divergence-theorem sum over its faces. Exact predicates
// (orient3d) decide the side of the original vertices, so that two tetrahedra separated by
// a plane holding a face of one of them (bodies that touch) give exactly 0.
// Broad phase: a uniform grid of the tetrahedra's bounding boxes; a pair is tested once,
// in the first grid cell its two boxes share, and only when the boxes overlap with
// positive volume and the fragments differ.

#include <cstdint>
#include <vector>

namespace ngfracture
{
  // Volume of the intersection of the tetrahedra a (4 points of 3 doubles, a[k] the k-th)
  // and b; either orientation; 0 for a degenerate tetrahedron and for tetrahedra separated
  // by a plane through a face of one of them (exactly).
  double TetIntersectionVolume (const double * const a[4], const double * const b[4]);

  struct TetOverlap
  {
    std::vector<int32_t> first, second;   // pairs of tetrahedra (first < second) with volume > 0
    std::vector<double> volume;           // their intersection volumes
    double total = 0;                     // sum of ``volume`` in pair order
    int64_t candidates = 0;               // pairs whose boxes overlap, of different fragments
    double cell = 0;                      // grid cell size
  };

  // Every pair of tetrahedra of different fragments whose intersection has positive
  // volume, sorted by (first, second). x: nv x 3 coordinates, tets: ne x 4 vertex numbers,
  // fragment: ne labels. Throws std::invalid_argument on a vertex number out of range.
  TetOverlap FragmentOverlap3 (const double * x, int64_t nv, const int32_t * tets, int64_t ne,
                               const int32_t * fragment);
}

#endif
