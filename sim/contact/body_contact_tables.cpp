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
  double longest = 0, sum = 0;
  for (int f = 0; f < nt; ++f) {
    t.tri_body[f] = t.node_body[t.tri[3 * f]];
    for (int e = 0; e < 3; ++e) {
      const int a = t.tri[3 * f + e], b = t.tri[3 * f + (e + 1) % 3];
      const double* p = &m.X[3 * a];
      const double* q = &m.X[3 * b];
      const double l = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
      longest = std::max(longest, l);
      sum += l;
    }
  }
  const double mean = sum / (3.0 * std::max(1, nt));
  t.tol = 0.1 * mean;
  t.cell = sum > 0 ? 0.5 * (longest + mean) : 1.0;
  return t;
}

}  // namespace softtled
