#include "sim/contact/body_contact_tables.h"

#include <algorithm>
#include <cmath>

namespace softtled {

BodyContactTables build_body_contact_tables(const TetMesh& m) {
  BodyContactTables t;
  t.nnode = m.nnode();
  t.nbody = m.nbody();
  t.node_body = m.node_body.empty() ? std::vector<int>(t.nnode, 0) : m.node_body;
  t.surf = m.surface_nodes;
  t.tri = m.boundary_tri;
  const int nt = m.nbtri();
  t.tri_body.resize(nt);
  std::vector<std::vector<int>> nb(t.nnode);
  double longest = 0, sum = 0;
  for (int f = 0; f < nt; ++f) {
    t.tri_body[f] = t.node_body[t.tri[3 * f]];
    for (int e = 0; e < 3; ++e) {
      const int a = t.tri[3 * f + e], b = t.tri[3 * f + (e + 1) % 3];
      nb[a].push_back(b);
      nb[b].push_back(a);
      const double* p = &m.X[3 * a];
      const double* q = &m.X[3 * b];
      const double l = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
      longest = std::max(longest, l);
      sum += l;
    }
  }
  t.ring_start.assign(t.nnode + 1, 0);
  for (int i = 0; i < t.nnode; ++i) {
    std::sort(nb[i].begin(), nb[i].end());
    nb[i].erase(std::unique(nb[i].begin(), nb[i].end()), nb[i].end());
    t.ring_start[i + 1] = t.ring_start[i] + int(nb[i].size());
    t.ring.insert(t.ring.end(), nb[i].begin(), nb[i].end());
  }
  const double mean = sum / (3.0 * std::max(1, nt));
  t.tol = 0.1 * mean;
  t.cell = sum > 0 ? 0.5 * (longest + mean) : 1.0;
  return t;
}

}  // namespace softtled
