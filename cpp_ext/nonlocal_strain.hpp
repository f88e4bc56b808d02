#ifndef NGFRACTURE_NONLOCAL_STRAIN_HPP
#define NGFRACTURE_NONLOCAL_STRAIN_HPP

// Critical-distance crack measure (docs/criterion.md): for every vertex and every one of
// ndir directions d, walk straight from the vertex through the triangles to the distance
// r, and take the smallest opening component n.T.n (n perpendicular to d) of the nodal
// tensor field T (interpolated linearly) at every edge crossing and at the end point:
// the whole segment of length r must be overstressed for a crack to run along it. The
// vertex keeps the largest value over the directions and its opening direction n.
//
// Only hot spots are judged: every sharp tip (boundary vertex with a corner angle of at
// least 300 degrees: a crack tip, a sharp notch), and a vertex with no sharp tip within
// 27/16 r whose local (nodal) principal value is the largest among the vertices within
// distance r connected to it (ties: smaller number).
// The critical distance is measured from the stress concentration, as in the theory of
// critical distances; the other vertices of its zone get 0 (they are judged once they lead).
//
// The walk goes through shared edges only: a ray that meets the boundary (an outer edge,
// a notch flank, a crack face) before r ends there (a crack along it would run through to
// that surface), so a vertex never sees the material across a crack; a direction that
// points out of the body at the vertex does not count. From a sharp tip the walk looks on
// to 2r: a ray that meets the boundary at s < 2r is judged over its first s/2, so a
// ligament thinner than 2r ahead of a tip is judged on its near half (for a linear stress
// profile, the net-section stress). Cost: ndir * (r/h + 1) triangle steps per vertex,
// twice that for a sharp tip.

#include <comp.hpp>

namespace ngfracture
{
  // tensors: nv x 3 nodal field (xx, yy, xy); radius: nv (<= 0: vertex not evaluated);
  // result: nv x 3, the rank-one tensor value * n n^T of each vertex (0 if it is no hot spot
  // or no direction reaches r inside the body).
  void NonlocalOpening (const ngcomp::MeshAccess & ma, ngbla::FlatMatrix<double> tensors,
                        ngbla::FlatVector<double> radius, int ndir,
                        ngbla::FlatMatrix<double> result);
}

#endif
