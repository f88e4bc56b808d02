#include "star_mincut.hpp"
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ngfracture
{
  MinCut :: MinCut (int an) : n(an), fixed(an, -1), adj(an + 2)
  {
    if (an < 0) throw std::invalid_argument("ngfracture: MinCut needs n >= 0 nodes");
  }

  void MinCut :: AddArcs (int i, int j, double cij, double cji)
  {
    adj[i].push_back({ j, int(adj[j].size()), cij });
    adj[j].push_back({ i, int(adj[i].size()) - 1, cji });
  }

  void MinCut :: AddEdge (int i, int j, double cap)
  {
    if (i < 0 || i >= n || j < 0 || j >= n || i == j)
      throw std::invalid_argument("ngfracture: MinCut edge (" + std::to_string(i) + ", " + std::to_string(j) +
                                  ") is not between two distinct nodes of [0, " + std::to_string(n) + ")");
    if (!(cap >= 0) || !std::isfinite(cap))
      throw std::invalid_argument("ngfracture: MinCut edge (" + std::to_string(i) + ", " + std::to_string(j) +
                                  ") has capacity " + std::to_string(cap));
    AddArcs(i, j, cap, cap);
    total += cap;
  }

  void MinCut :: Fix (int i, int side)
  {
    if (i < 0 || i >= n || (side != 0 && side != 1))
      throw std::invalid_argument("ngfracture: MinCut cannot fix node " + std::to_string(i) + " to side " +
                                  std::to_string(side));
    fixed[i] = side;
  }

  std::vector<int> MinCut :: Solve (double & value)
  {
    const double INF = std::numeric_limits<double>::infinity();
    const int s = n, t = n + 1;
    for (int i = 0; i < n; i++)
      if (fixed[i] == 1) AddArcs(s, i, INF, 0.0);
      else if (fixed[i] == 0) AddArcs(i, t, INF, 0.0);
    // residuals below tol count as saturated (rounding of the augmentations)
    const double tol = 1e-12 * total;
    value = 0;
    std::vector<int> from_node(n + 2), from_arc(n + 2);
    for (;;)
      {
        std::fill(from_node.begin(), from_node.end(), -1);
        from_node[s] = s;
        std::vector<int> queue = { s };
        for (size_t q = 0; q < queue.size() && from_node[t] < 0; q++)
          {
            int u = queue[q];
            for (int k = 0; k < int(adj[u].size()); k++)
              {
                const Arc & a = adj[u][k];
                if (a.cap > tol && from_node[a.to] < 0)
                  { from_node[a.to] = u; from_arc[a.to] = k; queue.push_back(a.to); }
              }
          }
        if (from_node[t] < 0) break;
        double f = INF;
        for (int v = t; v != s; v = from_node[v]) f = std::min(f, adj[from_node[v]][from_arc[v]].cap);
        if (!(f < INF)) throw std::logic_error("ngfracture: MinCut path of infinite capacity");
        for (int v = t; v != s; v = from_node[v])
          {
            Arc & a = adj[from_node[v]][from_arc[v]];
            a.cap -= f;
            adj[v][a.rev].cap += f;
          }
        value += f;
      }
    std::vector<int> side(n, 0);
    for (int i = 0; i < n; i++) side[i] = from_node[i] >= 0;
    return side;
  }
}
