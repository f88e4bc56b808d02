#ifndef NGFRACTURE_INTERNAL_FORCE_HPP
#define NGFRACTURE_INTERNAL_FORCE_HPP

#include <bla.hpp>

namespace ngfracture
{
  // Material laws of the internal-force kernel (ngfracture.materials).
  enum class MaterialKind { Linear = 0, StVenantKirchhoff = 1, NeoHookean = 2 };

  // Internal nodal forces of P1 triangles, f_a = sum_T |T| P(H_T) grad N_a, H = grad u.
  // points: nv x 2 (reference), triangles: ne x 3, u and f: 2 nv, component-major
  // (NGSolve's VectorH1 order 1 layout: x of every vertex, then y); kind, mu, lam per
  // element. f is overwritten. Serial: the sum order, and so the last bit, is fixed.
  void InternalForces (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> triangles,
                       ngbla::FlatVector<double> u, ngbla::FlatVector<int> kind,
                       ngbla::FlatVector<double> mu, ngbla::FlatVector<double> lam,
                       ngbla::FlatVector<double> f);

  // Tangent stiffness df/du of the same P1 triangles and laws, as a CSR matrix (2 nv x 2 nv,
  // component-major dofs): every pair of vertices of a triangle couples in both components,
  // columns sorted in every row, structural zeros kept. Serial, element order: the last bit is fixed.
  void TangentStiffness (ngbla::FlatMatrix<double> points, ngbla::FlatMatrix<int> triangles,
                         ngbla::FlatVector<double> u, ngbla::FlatVector<int> kind,
                         ngbla::FlatVector<double> mu, ngbla::FlatVector<double> lam,
                         ngcore::Array<int> & indptr, ngcore::Array<int> & indices,
                         ngcore::Array<double> & data);
}

#endif
