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
  std::vector<int> surf_index(t.nnode, -1);
  for (std::size_t k = 0; k < t.surf.size(); ++k) surf_index[t.surf[k]] = int(k);
  t.surf_tri_start.assign(t.surf.size() + 1, 0);
  for (int v : t.tri) ++t.surf_tri_start[surf_index[v] + 1];
  for (std::size_t k = 0; k < t.surf.size(); ++k) t.surf_tri_start[k + 1] += t.surf_tri_start[k];
  t.surf_tri.resize(t.tri.size());
  std::vector<int> fill(t.surf_tri_start.begin(), t.surf_tri_start.end() - 1);
  for (int f = 0; f < nt; ++f)  // in triangle order: each list ascending
    for (int c = 0; c < 3; ++c) t.surf_tri[fill[surf_index[t.tri[3 * f + c]]]++] = f;
  const double mean = sum / (3.0 * std::max(1, nt));
  t.tol = 0.1 * mean;
  t.cell = sum > 0 ? 0.5 * (longest + mean) : 1.0;
  return t;
}

int fullest_bucket_at_rest(const BodyContactTables& t, const std::vector<double>& X, unsigned buckets, double inflate) {
  std::vector<int> count(buckets, 0);
  std::vector<unsigned> seen;
  const double inv_h = 1.0 / t.cell;
  for (int f = 0; f < t.ntri(); ++f) {
    double b[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) {
        const double x = X[3 * std::size_t(t.tri[3 * f + c]) + k];
        b[k] = std::min(b[k], x - inflate);
        b[3 + k] = std::max(b[3 + k], x + inflate);
      }
    if (!grid_box(b, inv_h)) continue;
    seen.clear();
    for (long long ix = grid_cell(b[0], inv_h); ix <= grid_cell(b[3], inv_h); ++ix)
      for (long long iy = grid_cell(b[1], inv_h); iy <= grid_cell(b[4], inv_h); ++iy)
        for (long long iz = grid_cell(b[2], inv_h); iz <= grid_cell(b[5], inv_h); ++iz) {
          const unsigned h = grid_bucket(ix, iy, iz, t.tri_body[f], buckets - 1);
          if (std::find(seen.begin(), seen.end(), h) == seen.end()) seen.push_back(h), ++count[h];
        }
  }
  return count.empty() ? 0 : *std::max_element(count.begin(), count.end());
}

}  // namespace softtled
