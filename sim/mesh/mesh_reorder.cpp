#include "sim/mesh/mesh_reorder.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace softtled {
namespace {

// 21 bits per axis interleaved into a 63-bit Morton key.
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

struct Box {
  double lo[3], scale[3];
  std::uint64_t key(const double x[3]) const {
    std::uint64_t k = 0;
    for (int a = 0; a < 3; ++a) {
      double q = (x[a] - lo[a]) * scale[a];
      q = std::min(std::max(q, 0.0), double((1 << 21) - 1));
      k |= spread_bits(std::uint64_t(q)) << a;
    }
    return k;
  }
};

std::vector<int> sorted_by_key(const std::vector<std::uint64_t>& key) {
  std::vector<int> order(key.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

}  // namespace

MeshPermutation identity_order(const TetMesh& m) {
  MeshPermutation p;
  p.node_new.resize(m.nnode());
  std::iota(p.node_new.begin(), p.node_new.end(), 0);
  p.node_old = p.node_new;
  p.tet_old.resize(m.ntet());
  std::iota(p.tet_old.begin(), p.tet_old.end(), 0);
  return p;
}

MeshPermutation spatial_order(const TetMesh& m) {
  const int n = m.nnode(), ne = m.ntet();
  Box box;
  double hi[3];
  for (int a = 0; a < 3; ++a) box.lo[a] = hi[a] = n ? m.X[a] : 0.0;
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = std::min(box.lo[a], m.X[3 * i + a]);
      hi[a] = std::max(hi[a], m.X[3 * i + a]);
    }
  double ext = 0;
  for (int a = 0; a < 3; ++a) ext = std::max(ext, hi[a] - box.lo[a]);
  for (int a = 0; a < 3; ++a) box.scale[a] = ext > 0 ? double((1 << 21) - 1) / ext : 0.0;

  std::vector<std::uint64_t> key(n);
  for (int i = 0; i < n; ++i) key[i] = box.key(&m.X[3 * i]);
  MeshPermutation p;
  p.node_old = sorted_by_key(key);
  p.node_new.resize(n);
  for (int i = 0; i < n; ++i) p.node_new[p.node_old[i]] = i;

  key.resize(ne);
  for (int e = 0; e < ne; ++e) {
    double c[3] = {0, 0, 0};
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) c[k] += 0.25 * m.X[3 * m.tet[4 * e + a] + k];
    key[e] = box.key(c);
  }
  p.tet_old = sorted_by_key(key);
  return p;
}

TetMesh permute_mesh(const TetMesh& m, const MeshPermutation& p) {
  TetMesh r;
  const int n = m.nnode(), ne = m.ntet();
  r.X.resize(m.X.size());
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) r.X[3 * i + k] = m.X[3 * p.node_old[i] + k];
  r.tet.resize(m.tet.size());
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < 4; ++a) r.tet[4 * e + a] = p.node_new[m.tet[4 * p.tet_old[e] + a]];
  r.boundary_tri.resize(m.boundary_tri.size());
  for (std::size_t j = 0; j < m.boundary_tri.size(); ++j) r.boundary_tri[j] = p.node_new[m.boundary_tri[j]];
  r.surface_nodes.resize(m.surface_nodes.size());
  for (std::size_t j = 0; j < m.surface_nodes.size(); ++j) r.surface_nodes[j] = p.node_new[m.surface_nodes[j]];
  std::sort(r.surface_nodes.begin(), r.surface_nodes.end());
  if (!m.node_body.empty()) {
    r.node_body.resize(n);
    for (int i = 0; i < n; ++i) r.node_body[i] = m.node_body[p.node_old[i]];
  }
  auto per_tet = [&](const auto& src, auto& dst) {
    if (src.empty()) return;
    dst.resize(ne);
    for (int e = 0; e < ne; ++e) dst[e] = src[p.tet_old[e]];
  };
  per_tet(m.tet_body, r.tet_body);
  per_tet(m.rho_scale, r.rho_scale);
  per_tet(m.E_scale, r.E_scale);
  r.per_body_law = m.per_body_law;
  return r;
}

}  // namespace softtled
