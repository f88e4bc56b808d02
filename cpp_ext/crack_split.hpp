#ifndef NGFRACTURE_CRACK_SPLIT_HPP
#define NGFRACTURE_CRACK_SPLIT_HPP

// Node splitting of a 2D triangle mesh (paper section 3, rules 1, 1a, 1b, 2, 2a, 2b).
// Works on plain arrays in the reference configuration; knows nothing of netgen.
//
// The topology lives only in the triangle -> vertex table: two triangles are joined
// across an edge iff they share both its vertex ids. Splitting a vertex w gives every
// edge-connected group ("fan") of the triangles around w its own copy of w. Cutting an
// edge (v,x) is done by splitting v with the edge removed from v's fan, then re-checking
// x: if x's fan falls apart too (x on the boundary or on a crack surface), x is split as
// well (rules 1b and 2b). Because every vertex whose fan changed is re-checked, two
// pieces are never left joined by a single vertex.

#include <vector>
#include <cstdint>

namespace ngfracture
{
  // Bit flags of what happened at one processed vertex (the split record's "rule").
  enum SplitRule : int
    {
      RULE_1      = 1,    // interior vertex: two edges cut
      RULE_1A     = 2,    // the second edge shared a triangle with the first: replaced
      RULE_1B     = 4,    // a far end on the boundary / a crack surface was split too
      RULE_2      = 8,    // boundary vertex: one interior edge cut
      RULE_2A     = 16,   // boundary vertex whose best edge is a boundary edge: no split
      RULE_2B     = 32,   // far end of the rule-2 edge split too
      RULE_TIP    = 64,   // crack tip (open fan closing on itself): handled by rule 1
      RULE_NONE   = 128,  // nothing split (no admissible edge, pinched or isolated vertex)
      RULE_2C     = 256,  // boundary vertex whose best edge is a boundary edge: the best
                          // interior edge within enter_angle of the crack line cut instead
      RULE_TIP1   = 512,  // crack tip extended by one edge, the one nearest the crack line
                          // ahead of the tip (single_edge_tips)
      RULE_2D     = 1024  // boundary vertex whose best edge is a boundary edge and no interior
                          // edge within enter_angle: the half of the crack line into the body,
                          // enter_angle or more off both boundary edges, enters on the interior
                          // edge nearest it (a concave corner whose fan is coarse)
    };

  class CrackSplitter
  {
  public:
    // points: nv x 2 (row-major), trigs: ne x 3 (0-based), segs: ns x 2 boundary
    // segments of the input mesh (0-based, may be empty).
    CrackSplitter (const double * points, int nv, const int * trigs, int ne,
                   const int * segs, int ns);

    // Process vertices in the given order; dirs[2*i], dirs[2*i+1] is the maximum strain
    // direction of order[i]. Vertices created during the pass are not processed.
    // skip_neighbours: a vertex that shares a triangle with one split earlier in this
    // pass is skipped (its strain predates that split; it is judged again next pass).
    // enter_angle (radians, 0: the paper's rule 2a): a boundary vertex whose best edge is a
    // boundary edge cuts its best interior edge if that lies within enter_angle of the
    // crack line (the crack enters the body, rule 2c), else nothing (rule 2a).
    // single_edge_tips: a crack tip cuts one edge, the interior edge nearest the half of the
    // crack line that points away from the crack (rule tip1), instead of two (rule 1):
    // a crack grows from its tip and does not fork there.
    void Run (const int * order, const double * dirs, int n, bool skip_neighbours = false,
              double enter_angle = 0.0, bool single_edge_tips = false);

    // With single_edge_tips: a tip aims along the crack line drawn through the crack's point
    // up to aim_edges lip edges behind it (AimAnchor; 0 or 1: the edge nearest the line's
    // direction). On a mesh whose edges take few directions (refined by bisection) the
    // nearest direction can be the same one tip after tip, and the crack drifts off the
    // line at that edge's angle; aimed from behind, the tip takes the edge that ends
    // nearest the line, and the crack zigzags about it.
    int aim_edges = 0;

    // After Run: segments of the new mesh and the fragments.
    void Finish ();

    int nv0, ne;
    std::vector<double> points;          // 2 * nv (grows)
    std::vector<int> trigs;              // 3 * ne, new vertex ids
    std::vector<int> parent;             // new vertex -> vertex of the input mesh
    std::vector<int> segs0;              // input segments
    std::vector<int> seg_trig, seg_loc;  // owner triangle (-1: none) and local indices (2 per segment) of each input segment

    // record, one entry per processed vertex
    std::vector<int> rec_vertex, rec_rule;
    std::vector<int> rec_edge_begin;     // rec_edges[2*rec_edge_begin[i] ...] up to the next
    std::vector<int> rec_edges;          // cut edges (v, x) in the numbering at cut time
    std::vector<int> rec_new_begin, rec_new;  // vertices created while processing entry i

    // after Finish
    std::vector<int> segs_new;           // remapped input segments (ns x 2)
    std::vector<int> crack_segs;         // new boundary edges (m x 2), triangle on the left
    std::vector<int> crack_seg_trig;     // the triangle of each crack segment
    std::vector<int> fragment;           // per triangle, fragment number (by smallest triangle)
    int nfragments = 0;

    int NV () const { return int(parent.size()); }

  private:
    std::vector<int> star_off, star_data;      // input vertex -> triangles (CSR)
    std::vector<std::vector<int>> star_mod;    // replaced stars (touched and new vertices)
    std::vector<char> modified;

    struct Edge { int x; int count; int t[2]; double score; double side; bool virt; int x2; };
    std::vector<Edge> edges;                   // scratch
    std::vector<int> scratch_comp;

    const int * StarBegin (int v) const;
    int StarSize (int v) const;
    int Local (int t, int v) const
    { const int * T = &trigs[3*t]; return T[0] == v ? 0 : (T[1] == v ? 1 : 2); }

    void CollectEdges (int v, const double * t);
    // Fan components of w's triangles with the edges (w, cut[i]) removed; labels per star entry.
    int Components (int w, const int * cut, int ncut, std::vector<int> & label) const;
    bool SplitAt (int w, const int * cut, int ncut);   // cut: far vertices of removed edges
    void ProcessVertex (int v, const double * dir, double enter_angle, bool single_edge_tips);
    bool ShareTriangle (int v, const Edge & a, const Edge & b) const;
    // the interior edge of the collected ones nearest the half-line sign * t (-1: none)
    int NearestInterior (double sign) const;
    // true if the direction d from v points into one of v's triangles (or along its sides)
    bool IntoFan (int v, const double * d) const;
    // the crack's point 2 to aim_edges lip edges behind the tip v, whose lips start with the
    // twins a and b (as far as the lips stay twins and the tip lies within one tip edge of
    // the line through the point along h; false: not even the second point)
    bool AimAnchor (int v, int a, int b, const double * h, double * anchor) const;
    // the boundary neighbour of cur other than prev (-1: cur is not on a plain boundary)
    int NextOnBoundary (int cur, int prev) const;
    // of v's interior edges less than 45 degrees off the half-line direction h, the one
    // whose far end lies nearest the line through anchor along h (-1: none)
    int NearestToLine (int v, const double * anchor, const double * h) const;
  };
}

#endif
