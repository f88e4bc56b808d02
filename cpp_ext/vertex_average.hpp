#ifndef NGFRACTURE_VERTEX_AVERAGE_HPP
#define NGFRACTURE_VERTEX_AVERAGE_HPP

#include <comp.hpp>

namespace ngfracture
{
  // Area of every surface element of a 2D mesh, in reference coordinates.
  ngstd::Array<double> ElementAreas (const ngcomp::MeshAccess & ma);

  // Area-weighted average of per-element values at every vertex:
  //   v_avg[i] = sum_{T ni i} |T| v[T] / sum_{T ni i} |T|.
  // values is ne x ncomp (row-major), the result nv x ncomp.
  void VertexAverage (const ngcomp::MeshAccess & ma,
                      ngbla::FlatMatrix<double> values,
                      ngbla::FlatMatrix<double> result);
}

#endif
