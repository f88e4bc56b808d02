#ifndef NGFRACTURE_INTERNAL_FORCE_HPP
#define NGFRACTURE_INTERNAL_FORCE_HPP

#include <bla.hpp>

namespace ngfracture
{
  // Material laws of the internal-force kernel (ngfracture.materials).
  enum class MaterialKind { Linear = 0, StVenantKirchhoff = 1, NeoHookean = 2 };

  // Internal nodal forces of P1 simplices, f_a = sum_T |T| P(H_T) grad N_a, H = grad u.
  // points: nv x D (reference), elements: ne x (D + 1), D = 2 (triangles) or 3 (tetrahedra),
  // dispatched on the widths; u and f: D nv, component-major (NGSolve's VectorH1 order 1
  // layout: x of every vertex, then y, then z); kind, mu, lam per element (the Lame parameters
  // of the 2D reduction, or the 3D ones). f is overwritten. Serial: the sum order, and so the
  // last bit, is fixed.
  void InternalForces (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> elements,
                       ngbla::FlatVector<double> u, ngbla::FlatVector<int> kind,
                       ngbla::FlatVector<double> mu, ngbla::FlatVector<double> lam,
                       ngbla::FlatVector<double> f);

  // Tangent stiffness df/du of the same P1 simplices and laws, as a CSR matrix (D nv x D nv,
  // component-major dofs): every pair of vertices of an element couples in all components,
  // columns sorted in every row, structural zeros kept. Serial, element order: the last bit is fixed.
  void TangentStiffness (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> elements,
                         ngbla::FlatVector<double> u, ngbla::FlatVector<int> kind,
                         ngbla::FlatVector<double> mu, ngbla::FlatVector<double> lam,
                         ngcore::Array<int> & indptr, ngcore::Array<int> & indices,
                         ngcore::Array<double> & data);
}

#endif
