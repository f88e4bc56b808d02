#ifndef NGFRACTURE_CRACK_SPLIT3D_HPP
#define NGFRACTURE_CRACK_SPLIT3D_HPP

// Node splitting of a tetrahedral mesh (the crack engine in 3D). Plain arrays in the
// reference configuration; knows nothing of netgen.
//
// The topology lives only in the tetrahedron -> vertex table: two tetrahedra are joined
// across a face iff they share its three vertex ids. The star of a vertex v is the set of
// tetrahedra holding v; its link is the surface made of the faces opposite v, in which a
// star tetrahedron is a link triangle and a face (v, a, b) a link edge (a, b). A link edge
// held by two star tetrahedra is an interior face; one held by a single tetrahedron is a
// boundary face (free surface or crack lip). Splitting v cuts a set of interior link edges
// (they become crack faces, both lips) and gives every connected part of the star its own
// copy of v.
//
// A front edge is an edge (v, a) whose tetrahedra around it end at two coincident crack
// faces (v, a, b) and (v, a, b'), b and b' copies of one point: the crack ends there. In
// v's link, a is then a "slit end": two boundary link edges at a whose far vertices are
// distinct copies of one point.

#include <array>
#include <vector>
#include <cstdint>

namespace ngfracture
{
  // Bit flags of what happened at one processed vertex (the record's "flags").
  enum Split3dFlag : int
    {
      SPLIT3_CUT      = 1,     // new crack faces through v, the star in two connected sides
      SPLIT3_PINCHED  = 2,     // the star was already in pieces: one copy per piece, no faces
      SPLIT3_SURFACE  = 4,     // v had free-surface faces (not crack)
      SPLIT3_CRACK    = 8,     // v had crack faces
      SPLIT3_FRONT    = 16,    // v had front edges (v on a crack front)
      SPLIT3_CLOSED   = 32,    // every front edge through v was closed by the new faces
      SPLIT3_MOVED    = 64,    // a part of a side disconnected from its main part changed side
      SPLIT3_FAR      = 128,   // a vertex of the new faces fell apart and was split per piece
      SPLIT3_NONE     = 256,   // nothing split
      SPLIT3_EMPTY    = 512,   // refused: every star tetrahedron on one side of the plane
      SPLIT3_ENCLOSED = 1024,  // refused: a side touches none of v's boundary faces
                               // (the new faces would close a cone around v)
      SPLIT3_DANGLING = 2048,  // refused: the new faces would end at a new front edge through v
      SPLIT3_POCKET   = 8192,  // refused: a side of the cut would be a piece of the mesh
                               // smaller than the star (a pocket closed by earlier cracks)
      SPLIT3_ALIGNED  = 4096   // refused (rule 2a): v on a surface, not on a front, and one of
                               // its boundary faces is better aligned with the crack plane
                               // than every interior face at v
    };

  class TetSplitter
  {
  public:
    // points: nv x 3, tets: ne x 4 (positively oriented), faces: nf x 3 boundary triangles
    // (outward), face_bc: nf boundary numbers; crack_bc: the boundary number of new faces.
    TetSplitter (const double * points, int nv, const int * tets, int ne,
                 const int * faces, const int * face_bc, int nf, int crack_bc);

    // Process vertices in the given order; dirs[3*i..3*i+2] is the opening direction of
    // order[i]. Vertex numbers refer to the mesh as split so far. first_only: stop after the
    // first vertex that splits anything. skip_neighbours: a vertex that shares an edge (of
    // the mesh as split so far) with a vertex split earlier in this run, or with a copy of
    // one, is skipped (not processed, listed in skipped).
    void Run (const int * order, const double * dirs, int n, bool first_only = false,
              bool skip_neighbours = false);

    // Output faces (nf_out x 3) in the current vertex numbers: the input faces in their
    // order, then the new crack faces in creation order (two lips each, outward).
    std::vector<int> Faces () const;

    int nv0, ne, crack_bc;
    std::vector<double> points;     // 3 * nv (grows)
    std::vector<int> tets;          // 4 * ne, current vertex ids
    std::vector<int> parent;        // vertex -> vertex of the input mesh
    std::vector<int> face_tet;      // owner tetrahedron of every face
    std::vector<int8_t> face_loc;   // 3 local indices in the owner per face
    std::vector<int> face_bc;       // boundary number per face

    // record, one entry per processed vertex
    std::vector<int> rec_vertex, rec_flags, rec_faces, rec_fronts_before, rec_fronts_after;
    std::vector<int> rec_new_begin, rec_new;   // vertices created while processing entry i
    std::vector<int> skipped;                  // vertices skipped by skip_neighbours, in order

    int NV () const { return int(parent.size()); }

    // Vertices (current numbers) whose star is in more than one piece through shared faces.
    std::vector<int> Pinched ();

  private:
    std::vector<int> star_off, star_data;      // input vertex -> tetrahedra (CSR)
    std::vector<std::vector<int>> star_mod;    // replaced stars (touched and new vertices)
    std::vector<char> modified;
    std::vector<int> tet_bc;                   // 4 * ne: bc of the face opposite local k (0: none)

    // the link of the vertex being examined
    struct LinkEdge { int a, b, i, c; };       // far vertices a < b, star entry i, opposite local c
    int lv = -1;
    std::vector<int> S;                        // star tetrahedra (ascending)
    std::vector<LinkEdge> le;                  // 3 per star entry, sorted by (a, b)
    std::vector<int> partner;                  // per link edge: the other link edge of the face (-1: boundary)

    const int * StarBegin (int v) const;
    int StarSize (int v) const;
    int Local (int t, int v) const;
    void BuildLink (int v);
    // components of the star entries with label == side (side < 0: all), through interior link
    // edges between entries of equal label; comp per entry (-1: other side); returns count
    int Components (const std::vector<int> & label, int side, std::vector<int> & comp) const;
    // link vertices a (with the part's label) that are slit ends in the star cut by label
    // (pairs: the two boundary link edges of each slit end)
    std::vector<long long> SlitEnds (const std::vector<int> & label,
                                     std::vector<std::array<int,2>> * pairs) const;
    // |cos| of the angle between n and the normal of link edge e's face, signed by the
    // face's outward normal (of its star tetrahedron)
    double FaceAlignment (int e, const double * n) const;
    // the solid angle of the star at lv (2 pi on a flat surface, 3 pi on a right-angle
    // re-entrant edge, 4 pi inside)
    double StarSolidAngle () const;
    void SeedLips (const std::vector<std::array<int,2>> & pairs, const double * n, std::vector<int> & side) const;
    // give each label (0 .. ngroups-1) of the current link its own copy of lv, the group
    // holding the smallest tetrahedron keeping lv
    void SplitGroups (const std::vector<int> & label, int ngroups);
    bool SplitPieces (int w);
    // v shares an edge with a vertex whose input vertex is marked in split_input
    bool NextToSplit (int v, const std::vector<char> & split_input) const;
    int ProcessVertex (int v, const double * n, int & nfaces, int & before, int & after);
    double Anchor (const double * n, const std::vector<std::array<int,2>> & pairs) const;
    int Classify (const double * n, double offset, std::vector<int> & side) const;
    void CutSides (const double * n, double offset, const std::vector<std::array<int,2>> & pairs,
                   std::vector<int> & side) const;
    bool Connect (std::vector<int> & side) const;
    bool ClosedCrackVertex (int a) const;
    bool CrackEdge (int p, int q) const;
    bool SmallPiece (const std::vector<int> & side) const;
    int ChooseSides (const double * n, double offset, const std::vector<std::array<int,2>> & pairs,
                     const std::vector<long long> & slit, std::vector<int> & side, int & after, bool & moved) const;
    int RefuseReason (const std::vector<int> & side, const std::vector<long long> & before,
                      int & after) const;
    void AddFace (int t, int c);
  };

  // Fragment number of every tetrahedron: components through shared faces (three equal
  // vertex ids), numbered by their smallest tetrahedron. Returns the count.
  int TetComponents (const int * tets, int ne, int nv, std::vector<int> & fragment);
}

#endif
