#include "crack_rebuild.hpp"

namespace ngfracture
{
  using namespace netgen;

  MeshArrays ExtractArrays (const Mesh & mesh)
  {
    if (mesh.GetDimension() != 2)
      throw ngcore::Exception("ngfracture: the mesh must be 2D, it has dimension " +
                              ngcore::ToString(mesh.GetDimension()));
    if (mesh.GetNE() != 0)
      throw ngcore::Exception("ngfracture: the 2D mesh has volume elements");
    MeshArrays a;
    a.nv = int(mesh.GetNP());
    a.ne = int(mesh.GetNSE());
    a.ns = int(mesh.GetNSeg());
    a.points.resize(2*size_t(a.nv));
    for (int i = 0; i < a.nv; i++)
      {
        const auto & p = mesh[PointIndex::FromNr0(i)];
        a.points[2*i] = p(0); a.points[2*i+1] = p(1);
      }
    a.trigs.resize(3*size_t(a.ne));
    for (int e = 0; e < a.ne; e++)
      {
        const auto & el = mesh[SurfaceElementIndex::FromNr0(e)];
        if (el.GetType() != TRIG)
          throw ngcore::Exception("ngfracture: element " + ngcore::ToString(e) +
                                  " is not a linear triangle (curved or quad meshes are not supported)");
        for (int k = 0; k < 3; k++) a.trigs[3*e+k] = el[k].Nr0();
      }
    a.segs.resize(2*size_t(a.ns));
    for (int s = 0; s < a.ns; s++)
      {
        const auto & seg = mesh.LineSegment(SegmentIndex::FromNr0(s));
        a.segs[2*s] = seg[0].Nr0(); a.segs[2*s+1] = seg[1].Nr0();
      }
    return a;
  }

  std::shared_ptr<Mesh> RebuildMesh (const Mesh & old, const CrackSplitter & split,
                                     const std::string & crack_name)
  {
    auto m = std::make_shared<Mesh>();
    m->SetDimension(2);
    m->Regions<0>() = old.Regions<0>();
    m->Regions<1>() = old.Regions<1>();
    m->Regions<2>() = old.Regions<2>();
    m->Regions<3>() = old.Regions<3>();

    int nv = split.NV();
    for (int i = 0; i < nv; i++)
      {
        const MeshPoint & p = old[PointIndex::FromNr0(split.parent[i])];
        m->AddPoint(Point<3>(split.points[2*size_t(i)], split.points[2*size_t(i)+1], p(2)),
                    p.GetLayer(), p.Type());
      }

    for (int e = 0; e < split.ne; e++)
      {
        Element2d el(TRIG);
        el.SetIndex(old[SurfaceElementIndex::FromNr0(e)].GetIndex());
        for (int k = 0; k < 3; k++)
          el[k] = PointIndex::FromNr0(split.trigs[3*size_t(e)+k]);
        m->AddSurfaceElement(el);
      }

    int ns = int(split.segs_new.size()/2);
    for (int s = 0; s < ns; s++)
      {
        Segment seg = old.LineSegment(SegmentIndex::FromNr0(s));
        seg[0] = PointIndex::FromNr0(split.segs_new[2*s]);
        seg[1] = PointIndex::FromNr0(split.segs_new[2*s+1]);
        m->AddSegment(seg);
      }

    if (!split.crack_segs.empty())
      {
        // reuse the crack region of an earlier split, else add one
        EdgeRegionIndex cidx = EdgeRegionIndex::INVALID;
        for (auto i : m->Regions<1>().Range())
          if (m->Regions<1>()[i].HasName() && m->Regions<1>()[i].GetName() == crack_name)
            { cidx = i; break; }
        if (!cidx.IsValid())
          {
            EdgeRegion er(int(m->Regions<1>().Size()) + 1);
            er.SetName(crack_name);
            cidx = m->AddEdgeDescriptor(er);
          }
        for (size_t c = 0; c < split.crack_segs.size()/2; c++)
          {
            Segment seg;
            seg[0] = PointIndex::FromNr0(split.crack_segs[2*c]);
            seg[1] = PointIndex::FromNr0(split.crack_segs[2*c+1]);
            seg.SetIndex(cidx);
            m->AddSegment(seg);
          }
      }

    // point regions (0-d elements) stay on the original vertex ids
    m->pointelements = old.pointelements;
    return m;
  }
}
