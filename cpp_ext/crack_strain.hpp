#ifndef NGFRACTURE_CRACK_STRAIN_HPP
#define NGFRACTURE_CRACK_STRAIN_HPP

// Nodal strain for the crack criterion (paper section 3): per-element strain of the
// P1 interpolant of the vertex displacements, area-weighted average at the vertices,
// largest principal value and its direction, and the ordered set of overstrained vertices.

#include <comp.hpp>

namespace ngfracture
{
  enum class StrainMeasure { Linear, GreenLagrange };

  // Strain of every triangle from the vertex displacements u (nv x 2), computed with
  // the constant gradient H of the P1 interpolant in reference coordinates.
  //   linear:          eps = (H + H^T) / 2
  //   Green-Lagrange:  E   = (H + H^T + H^T H) / 2   (not (F^T F - I)/2: that loses digits)
  // Result: ne x 3, columns (xx, yy, xy) (tensor component, not engineering shear).
  void ElementStrainP1 (const ngcomp::MeshAccess & ma, ngbla::FlatMatrix<double> u,
                        StrainMeasure measure, ngbla::FlatMatrix<double> strain);

  // Largest eigenvalue of each symmetric tensor (rows (xx, yy, xy)) and its unit
  // eigenvector, oriented with angle in (-pi/2, pi/2]. An isotropic tensor has no
  // principal direction; it gets (1, 0) so the result is still deterministic.
  void PrincipalMax (ngbla::FlatMatrix<double> tensors, ngbla::FlatVector<double> values,
                     ngbla::FlatMatrix<double> directions);

  // Indices with values[i] > critical, by decreasing value, ties by increasing index.
  ngstd::Array<int> SelectAbove (ngbla::FlatVector<double> values, double critical);
}

#endif
