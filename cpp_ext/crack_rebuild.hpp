#ifndef NGFRACTURE_CRACK_REBUILD_HPP
#define NGFRACTURE_CRACK_REBUILD_HPP

// Netgen mesh <-> plain arrays for the splitter, and the rebuild of a netgen mesh
// after a split: regions (materials, boundary names) are copied, triangles keep their
// order, orientation and region, new vertices copy their parent point, input segments
// are remapped and the new boundary edges get their own segments in region `crack_name`.

#include <meshing.hpp>
#include <memory>
#include <string>
#include <vector>
#include "crack_split.hpp"

namespace ngfracture
{
  struct MeshArrays
  {
    int nv = 0, ne = 0, ns = 0;
    std::vector<double> points;   // nv x 2
    std::vector<int> trigs;       // ne x 3, 0-based
    std::vector<int> segs;        // ns x 2, 0-based
  };

  // Throws if the mesh is not 2D or has elements other than triangles.
  MeshArrays ExtractArrays (const netgen::Mesh & mesh);

  std::shared_ptr<netgen::Mesh> RebuildMesh (const netgen::Mesh & old, const CrackSplitter & split,
                                             const std::string & crack_name);
}

#endif
