#ifndef NGFRACTURE_NONLOCAL_STRAIN3D_HPP
#define NGFRACTURE_NONLOCAL_STRAIN3D_HPP

// The crack criterion on tetrahedral meshes (docs/solid.md, "The criterion in 3D"): the
// 3D counterpart of nonlocal_strain.hpp, on plain arrays (SolidArrays: points nv x 3,
// positively oriented tets ne x 4). Symmetric tensors are stored as 6 components
// (xx, yy, zz, yz, xz, xy).
//
// * VertexAverage3D: the volume-weighted mean of element values at every vertex (the
//   paper's one-ring nodal value).
// * SharpVertices3D: the vertices of the boundary edges whose inside dihedral angle (the
//   sum of the dihedral angles of the tets around the edge) is at least 260 degrees: notch
//   fronts and re-entrant edges of 270 degrees or more, and crack fronts (360 degrees: the two lips are separate boundary faces), with
//   the unit tangent of the front at each of them.
// * NonlocalOpening3D: the critical-distance measure. From every hot spot, rays of length r
//   are walked through the tets (a boundary face, e.g. a crack lip, ends a ray; a direction
//   that points out of the body does not count), the nodal tensors interpolated linearly.
//   A ray's opening direction n is the largest eigenvector of the tensor at its end point
//   restricted to the plane normal to the ray; its value the smallest n.T.n along it; the
//   vertex keeps the largest value over its rays and returns value * n n^T. A sharp vertex
//   casts its rays in the plane normal to its front (nplane directions; the distance r is
//   measured from the front, as in 2D), any other hot spot over the sphere (ndir Fibonacci
//   directions). The best ray is refined once: its direction projected onto the plane
//   normal to the principal direction at its end point (exact for a uniform field).
//   Hot spots, the 27/16 r zones and the thin-section rule are those of the 2D criterion.

#include <comp.hpp>
#include <array>
#include <vector>

namespace ngfracture
{
  // Volume-weighted average of element values (ne x nc) at the vertices (nv x nc); a vertex
  // of no tet gets 0. Throws on a tet vertex out of range.
  void VertexAverage3D (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> tets,
                        ngbla::FlatMatrix<double> values, ngbla::FlatMatrix<double> result);

  // Sharp vertices (increasing numbers) and their unit front tangents (3 per vertex).
  void SharpVertices3D (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> tets,
                        std::vector<int> & vertices, std::vector<double> & tangents);

  // tensors: nv x 6 nodal field; radius: nv (<= 0: vertex not judged); ndir: directions over
  // the sphere (>= 8); nplane: directions in a front's normal plane (>= 8); result: nv x 6.
  void NonlocalOpening3D (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> tets,
                          ngbla::FlatMatrix<double> tensors, ngbla::FlatVector<double> radius,
                          int ndir, int nplane, ngbla::FlatMatrix<double> result);
}

#endif
