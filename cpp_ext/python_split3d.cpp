// Python bindings of node splitting on tetrahedral meshes (crack_split3d).
#include <python_comp.hpp>
#include "numpy_arrays.hpp"
#include "crack_split3d.hpp"

namespace py = pybind11;
using namespace ngfracture;

namespace
{
  using darray = py::array_t<double, py::array::c_style | py::array::forcecast>;
  using iarray = py::array_t<int, py::array::c_style | py::array::forcecast>;


  void CheckShape (const char * fn, const char * name, py::array & a, int ndim, py::ssize_t width, py::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != width) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " must have shape (" +
                                  (rows >= 0 ? std::to_string(rows) : std::string("n")) +
                                  (ndim == 2 ? ", " + std::to_string(width) : std::string(",")) + ")");
  }

  // a splitter with zero points for the purely topological queries
  TetSplitter Topology (const char * fn, iarray & tets, int nv)
  {
    CheckShape(fn, "tets", tets, 2, 4);
    if (nv < 0) throw std::invalid_argument(std::string("ngfracture.") + fn + ": nv must be >= 0");
    std::vector<double> zero(3*size_t(nv), 0.0);
    return TetSplitter(zero.data(), nv, tets.data(), int(tets.shape(0)), nullptr, nullptr, 0, 1);
  }
}

void ExportSplit3d (py::module & m)
{
  py::dict flags;
  flags["cut"] = int(SPLIT3_CUT); flags["pinched"] = int(SPLIT3_PINCHED);
  flags["surface"] = int(SPLIT3_SURFACE); flags["crack"] = int(SPLIT3_CRACK);
  flags["front"] = int(SPLIT3_FRONT); flags["closed"] = int(SPLIT3_CLOSED);
  flags["moved"] = int(SPLIT3_MOVED); flags["far"] = int(SPLIT3_FAR); flags["none"] = int(SPLIT3_NONE);
  flags["empty"] = int(SPLIT3_EMPTY); flags["enclosed"] = int(SPLIT3_ENCLOSED);
  flags["dangling"] = int(SPLIT3_DANGLING); flags["aligned"] = int(SPLIT3_ALIGNED);
  flags["pocket"] = int(SPLIT3_POCKET);
  m.attr("SPLIT3D_FLAGS") = flags;   // bit flags of Split3dVertices' record "flags"

  m.def("Split3dVertices",
        [] (darray points, iarray tets, iarray faces, iarray face_bc, int crack_bc, iarray vertices,
            darray directions, bool first_only, bool skip_neighbours)
        {
          CheckShape("Split3dVertices", "points", points, 2, 3);
          CheckShape("Split3dVertices", "tets", tets, 2, 4);
          CheckShape("Split3dVertices", "faces", faces, 2, 3);
          CheckShape("Split3dVertices", "face_bc", face_bc, 1, 0, faces.shape(0));
          CheckShape("Split3dVertices", "vertices", vertices, 1, 0);
          CheckShape("Split3dVertices", "directions", directions, 2, 3, vertices.shape(0));
          if (crack_bc < 1)
            throw std::invalid_argument("ngfracture.Split3dVertices: crack_bc must be >= 1, got " + std::to_string(crack_bc));
          std::unique_ptr<TetSplitter> sp;
          {
            py::gil_scoped_release release;
            sp = std::make_unique<TetSplitter>(points.data(), int(points.shape(0)), tets.data(), int(tets.shape(0)),
                                               faces.data(), face_bc.data(), int(faces.shape(0)), crack_bc);
            sp->Run(vertices.data(), directions.data(), int(vertices.shape(0)), first_only, skip_neighbours);
          }
          py::dict rec;
          rec["vertex"] = ToNumpy(sp->rec_vertex);
          rec["flags"] = ToNumpy(sp->rec_flags);
          rec["faces"] = ToNumpy(sp->rec_faces);
          rec["fronts_before"] = ToNumpy(sp->rec_fronts_before);
          rec["fronts_after"] = ToNumpy(sp->rec_fronts_after);
          rec["new_offsets"] = ToNumpy(sp->rec_new_begin);
          rec["new_vertices"] = ToNumpy(sp->rec_new);
          py::dict r;
          r["points"] = ToNumpy(sp->points, 3);
          r["tets"] = ToNumpy(sp->tets, 4);
          r["faces"] = ToNumpy(sp->Faces(), 3);
          r["face_bc"] = ToNumpy(sp->face_bc);
          r["parent"] = ToNumpy(sp->parent);
          r["record"] = rec;
          r["skipped"] = ToNumpy(sp->skipped);
          return r;
        },
        py::arg("points"), py::arg("tets"), py::arg("faces"), py::arg("face_bc"), py::arg("crack_bc"),
        py::arg("vertices"), py::arg("directions"), py::arg("first_only") = false, py::arg("skip_neighbours") = false,
        R"doc(Split vertices of a tetrahedral mesh one after the other (docs/solid.md).

Parameters
----------
points : numpy.ndarray
    Shape (nv, 3), reference coordinates.
tets : numpy.ndarray of int
    Shape (ne, 4), positively oriented tetrahedra.
faces : numpy.ndarray of int
    Shape (nf, 3), boundary triangles, outward.
face_bc : numpy.ndarray of int
    Shape (nf,), boundary number per face.
crack_bc : int
    Boundary number (>= 1) of the new crack faces; faces with it count as crack faces.
vertices : numpy.ndarray of int
    Vertices to process in this order (numbers of the mesh as split so far).
directions : numpy.ndarray
    Shape (len(vertices), 3), the opening direction of each.
first_only : bool
    Stop after the first vertex that splits anything.
skip_neighbours : bool
    Skip a vertex that shares an edge of the mesh as split so far with a vertex split
    earlier in the call or with a copy of one (the 2D "spread" pass).

Returns
-------
dict
    points, tets, faces, face_bc of the new mesh (input faces first, then the new crack
    faces, two lips each), parent (vertex of the input mesh of every vertex), record
    (vertex, flags, faces, fronts_before, fronts_after, new_offsets, new_vertices) of the
    processed vertices, skipped (the vertices skipped by skip_neighbours, in order).

Raises
------
ValueError
    Bad shapes, vertex numbers out of range, a face of no tetrahedron, a zero direction.
)doc");

  m.def("TetComponents",
        [] (iarray tets, int nv)
        {
          CheckShape("TetComponents", "tets", tets, 2, 4);
          std::vector<int> frag;
          int n;
          {
            py::gil_scoped_release release;
            n = TetComponents(tets.data(), int(tets.shape(0)), nv, frag);
          }
          return py::make_tuple(n, ToNumpy(frag));
        },
        py::arg("tets"), py::arg("nv"),
        R"doc(Fragments of a tetrahedral mesh: components through shared faces.

Parameters
----------
tets : numpy.ndarray of int
    Shape (ne, 4).
nv : int
    Number of vertices.

Returns
-------
(int, numpy.ndarray)
    The count and the fragment of every tetrahedron, numbered by its smallest tetrahedron.

Raises
------
ValueError
    Bad shape or a vertex number outside [0, nv).
)doc");

  m.def("Split3dPinched",
        [] (iarray tets, int nv)
        {
          TetSplitter sp = Topology("Split3dPinched", tets, nv);
          std::vector<int> out;
          {
            py::gil_scoped_release release;
            out = sp.Pinched();
          }
          return ToNumpy(out);
        },
        py::arg("tets"), py::arg("nv"),
        R"doc(Vertices whose star is in more than one piece (tetrahedra joined through shared faces).

Parameters
----------
tets : numpy.ndarray of int
    Shape (ne, 4).
nv : int
    Number of vertices.

Returns
-------
numpy.ndarray of int
    The pinched vertices, increasing.

Raises
------
ValueError
    Bad shape or a vertex number outside [0, nv).
)doc");
}
