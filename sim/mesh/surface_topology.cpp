#include "sim/mesh/surface_topology.h"

namespace softtled {

SurfaceTopology build_surface_topology(const TetMesh& m) {
  SurfaceTopology s;
  s.node = m.surface_nodes;
  std::vector<int> local(m.nnode(), -1);
  for (int v = 0; v < int(s.node.size()); ++v) local[s.node[v]] = v;
  s.tri.resize(m.boundary_tri.size());
  for (std::size_t j = 0; j < m.boundary_tri.size(); ++j) s.tri[j] = local[m.boundary_tri[j]];
  const int nv = int(s.node.size()), nt = int(s.tri.size() / 3);
  s.vtri_start.assign(nv + 1, 0);
  for (int j : s.tri) ++s.vtri_start[j + 1];
  for (int v = 0; v < nv; ++v) s.vtri_start[v + 1] += s.vtri_start[v];
  s.vtri.resize(3 * nt);
  std::vector<int> fill(s.vtri_start.begin(), s.vtri_start.end() - 1);
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) s.vtri[fill[s.tri[3 * t + k]]++] = t;
  return s;
}

}  // namespace softtled
