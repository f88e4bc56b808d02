#include "vertex_average.hpp"

namespace ngfracture
{
  using namespace ngcomp;

  Array<double> ElementAreas (const MeshAccess & ma)
  {
    size_t ne = ma.GetNE(VOL);
    Array<double> areas(ne);
    for (size_t e = 0; e < ne; e++)
      {
        auto verts = ma.GetElement(ElementId(VOL, e)).Vertices();
        if (verts.Size() != 3)
          throw Exception("ngfracture: element " + ToString(e) + " has " +
                          ToString(verts.Size()) + " vertices; only triangles are supported");
        auto p0 = ma.GetPoint<2>(verts[0]);
        auto p1 = ma.GetPoint<2>(verts[1]);
        auto p2 = ma.GetPoint<2>(verts[2]);
        areas[e] = 0.5 * ((p1(0)-p0(0))*(p2(1)-p0(1)) - (p2(0)-p0(0))*(p1(1)-p0(1)));
      }
    return areas;
  }

  void VertexAverage (const MeshAccess & ma, FlatMatrix<double> values, FlatMatrix<double> result)
  {
    size_t ne = ma.GetNE(VOL), nv = ma.GetNV();
    if (values.Height() != ne)
      throw Exception("ngfracture.VertexAverage: values has " + ToString(values.Height()) +
                      " rows, the mesh has " + ToString(ne) + " elements");
    if (result.Height() != nv || result.Width() != values.Width())
      throw Exception("ngfracture.VertexAverage: result has the wrong shape");

    Array<double> areas = ElementAreas(ma);
    Array<double> weight(nv);
    weight = 0.0;
    result = 0.0;
    // Serial on purpose: the sum order, and so the last bit, never depends on threads.
    for (size_t e = 0; e < ne; e++)
      {
        double a = fabs(areas[e]);
        for (auto v : ma.GetElement(ElementId(VOL, e)).Vertices())
          {
            weight[v] += a;
            result.Row(v) += a * values.Row(e);
          }
      }
    for (size_t v = 0; v < nv; v++)
      if (weight[v] > 0)
        result.Row(v) /= weight[v];
  }
}
