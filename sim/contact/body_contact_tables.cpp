#include "sim/contact/body_contact_tables.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace softtled {

namespace {

// Triangle f's box at rest (X: 3 per node, interleaved), inflated by `inflate` on every side.
void triangle_box_at_rest(const BodyContactTables& t, const std::vector<double>& X, int f, double inflate, double b[6]) {
  for (int k = 0; k < 3; ++k) b[k] = INFINITY, b[3 + k] = -INFINITY;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      const double x = X[3 * std::size_t(t.tri[3 * f + c]) + k];
      b[k] = std::min(b[k], x - inflate);
      b[3 + k] = std::max(b[3 + k], x + inflate);
    }
}

// The shallowest depth, per body, at which a surface node lies behind a boundary triangle
// of its own body at rest, within that body's tolerance, its foot inside the triangle, and
// facing it (some triangle around the node opposed to it, body_contact.h: opposed): the
// top face of a plate thinner than the tolerance over its bottom face. INFINITY where none.
// Candidates from a hash grid of the mean edge over the triangles' boxes.
std::vector<double> facing_depth_at_rest(const BodyContactTables& t, const std::vector<double>& X, double cell) {
  std::vector<double> depth(t.nbody, INFINITY);
  const double inv_h = 1.0 / cell;
  // (as min_body_gap's: a hash collision only brings another cell's triangle to the exact test)
  auto key = [](long long ix, long long iy, long long iz) { return grid_bucket(ix, iy, iz, 0, 0xffffffffu); };
  std::unordered_map<unsigned, std::vector<int>> grid;
  for (int f = 0; f < t.ntri(); ++f) {
    double b[6];
    triangle_box_at_rest(t, X, f, t.body_tol[t.tri_body[f]], b);
    if (!grid_box(b, inv_h)) continue;
    for (long long ix = grid_cell(b[0], inv_h); ix <= grid_cell(b[3], inv_h); ++ix)
      for (long long iy = grid_cell(b[1], inv_h); iy <= grid_cell(b[4], inv_h); ++iy)
        for (long long iz = grid_cell(b[2], inv_h); iz <= grid_cell(b[5], inv_h); ++iz) grid[key(ix, iy, iz)].push_back(f);
  }
  std::vector<double> around;
  for (std::size_t s = 0; s < t.surf.size(); ++s) {
    const int p = t.surf[s], body = t.node_body[p];
    const double* xp = &X[3 * std::size_t(p)];
    const auto it = grid.find(key(grid_cell(xp[0], inv_h), grid_cell(xp[1], inv_h), grid_cell(xp[2], inv_h)));
    if (it == grid.end()) continue;
    crosses_around(t, s, X.data(), around);
    for (int f : it->second) {
      const int* v = &t.tri[3 * f];
      if (t.tri_body[f] != body || on_triangle(p, v[0], v[1], v[2])) continue;
      const double *xa = &X[3 * std::size_t(v[0])], *xb = &X[3 * std::size_t(v[1])], *xc = &X[3 * std::size_t(v[2])];
      TriangleProjection<double> tp;
      if (!project_onto_triangle(xp, xa, xb, xc, -t.body_tol[body], tp) || !(tp.d < 0)) continue;
      double cross[3];
      triangle_cross(xa, xb, xc, cross);
      if (faces_some(cross, around.data(), int(around.size() / 3))) depth[body] = std::min(depth[body], -tp.d);
    }
  }
  return depth;
}

}  // namespace

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
  std::vector<double> body_sum(t.nbody, 0.0);
  std::vector<int> body_tris(t.nbody, 0);
  for (int f = 0; f < nt; ++f) {
    const int b = t.tri_body[f] = t.node_body[t.tri[3 * f]];
    ++body_tris[b];
    for (int e = 0; e < 3; ++e) {
      const int a = t.tri[3 * f + e], c = t.tri[3 * f + (e + 1) % 3];
      const double* p = &m.X[3 * a];
      const double* q = &m.X[3 * c];
      const double l = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
      longest = std::max(longest, l);
      sum += l;
      body_sum[b] += l;
    }
  }
  t.body_tol.assign(t.nbody, 0.0);
  for (int b = 0; b < t.nbody; ++b) t.body_tol[b] = 0.1 * body_sum[b] / (3.0 * std::max(1, body_tris[b]));
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
  t.cell = sum > 0 ? 0.5 * (longest + mean) : 1.0;
  // A body thinner than its tolerance would be in contact with itself at rest: its top
  // nodes, behind its bottom face within the tolerance, pushed through it (a 0.4 mm plate
  // of 5 mm elements under contact.self collapsed in the first step). Such a body's
  // tolerance is half its shallowest facing depth at rest (a node deeper than that is on
  // the other side of the thin part), which also holds for its pairs with other bodies.
  const std::vector<double> depth = facing_depth_at_rest(t, m.X, mean > 0 ? mean : 1.0);
  for (int b = 0; b < t.nbody; ++b) t.body_tol[b] = std::min(t.body_tol[b], 0.5 * depth[b]);
  return t;
}

int fullest_bucket_at_rest(const BodyContactTables& t, const std::vector<double>& X, unsigned buckets) {
  std::vector<int> count(buckets, 0);
  std::vector<unsigned> seen;
  const double inv_h = 1.0 / t.cell;
  for (int f = 0; f < t.ntri(); ++f) {
    double b[6];
    triangle_box_at_rest(t, X, f, triangle_inflation_of(t.body_tol[t.tri_body[f]]), b);
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
