#include "sim/io/body_split.h"

#include <algorithm>

namespace softtled {

BodyRange body_range(const TetMesh& m, int b) {
  BodyRange r;
  if (m.node_body.empty()) {
    r.node_end = m.nnode();
    r.tet_end = m.ntet();
    return r;
  }
  // node_body and tet_body are sorted (bodies in order), so each body is one run.
  const auto nb = std::equal_range(m.node_body.begin(), m.node_body.end(), b);
  const auto tb = std::equal_range(m.tet_body.begin(), m.tet_body.end(), b);
  r.node_begin = int(nb.first - m.node_body.begin());
  r.node_end = int(nb.second - m.node_body.begin());
  r.tet_begin = int(tb.first - m.tet_body.begin());
  r.tet_end = int(tb.second - m.tet_body.begin());
  return r;
}

TetMesh body_mesh(const TetMesh& m, int b) {
  const BodyRange r = body_range(m, b);
  const int off = r.node_begin;
  auto inside = [&](int v) { return v >= r.node_begin && v < r.node_end; };
  TetMesh p;
  p.X.assign(m.X.begin() + 3 * std::size_t(r.node_begin), m.X.begin() + 3 * std::size_t(r.node_end));
  p.tet.reserve(4 * std::size_t(r.ntet()));
  for (int i = 4 * r.tet_begin; i < 4 * r.tet_end; ++i) p.tet.push_back(m.tet[i] - off);
  // Boundary triangles never join two bodies: the first vertex says whose a triangle is.
  for (int f = 0; f < m.nbtri(); ++f)
    if (inside(m.boundary_tri[3 * f]))
      for (int k = 0; k < 3; ++k) p.boundary_tri.push_back(m.boundary_tri[3 * f + k] - off);
  for (int v : m.surface_nodes)
    if (inside(v)) p.surface_nodes.push_back(v - off);
  if (!m.rho_scale.empty()) p.rho_scale.assign(m.rho_scale.begin() + r.tet_begin, m.rho_scale.begin() + r.tet_end);
  if (!m.E_scale.empty()) p.E_scale.assign(m.E_scale.begin() + r.tet_begin, m.E_scale.begin() + r.tet_end);
  return p;
}

HostState body_state(const TetMesh& m, const HostState& s, int b) {
  const BodyRange r = body_range(m, b);
  const std::size_t n = std::size_t(m.nnode()), nb = std::size_t(r.nnode());
  HostState p;
  p.u.resize(3 * nb);
  p.du.resize(3 * nb);
  for (int k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < nb; ++i) {
      p.u[k * nb + i] = s.u[k * n + r.node_begin + i];
      p.du[k * nb + i] = s.du[k * n + r.node_begin + i];
    }
  p.contact.assign(s.contact.begin() + r.node_begin, s.contact.begin() + r.node_end);
  return p;
}

}  // namespace softtled
