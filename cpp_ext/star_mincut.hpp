#ifndef NGFRACTURE_STAR_MINCUT_HPP
#define NGFRACTURE_STAR_MINCUT_HPP

// Minimum s-t cut of a small undirected graph with real capacities (the tetrahedra of a
// vertex star and their shared faces, a few dozen nodes). Edmonds-Karp: breadth-first
// augmenting paths in node and edge insertion order, so the result is deterministic.

#include <vector>

namespace ngfracture
{
  class MinCut
  {
  public:
    // n nodes 0 .. n-1, none fixed, no edges
    explicit MinCut (int n);
    // an undirected edge of capacity cap >= 0 between nodes i != j
    void AddEdge (int i, int j, double cap);
    // fix node i to the source (side 1) or the sink (side 0); a later call overrides
    void Fix (int i, int side);
    // side per node: 1 for the nodes reachable from the source in the residual graph of a
    // maximum flow (the smallest source side of a minimum cut), 0 for the others; the
    // cut's capacity in value. Both terminals must have a fixed node.
    std::vector<int> Solve (double & value);

  private:
    struct Arc { int to, rev; double cap; };
    int n;
    std::vector<int> fixed;                  // -1: free, 0: sink, 1: source
    std::vector<std::vector<Arc>> adj;       // n + 2 nodes: source n, sink n+1
    double total = 0;                        // sum of the finite capacities
    void AddArcs (int i, int j, double cij, double cji);
  };
}

#endif
